/*
** bench.c -- what accuracy costs in time (make bench).
**
**   bench [--quick] [--only SECTION]... DOCDIR DATADIR
**
** Runs the sections below and rewrites DOCDIR/PERFORMANCE.md and
** DOCDIR/ACCURACY.md (written to a temporary name and renamed, so a failed
** run leaves the old ones), with the machine, the compiler and the date on
** top; the data behind the plots go to .dat files in DATADIR, which
** tools/bench.gp turns into .png files in DOCDIR.  --only runs the named sections and prints their
** Markdown on stdout instead (for work on one section).  --quick (or
** BENCH_QUICK=1) is a smoke run: 3 short blocks per median, smaller scenes.
**
** A section is one function and one entry in `sections`; it writes its
** Markdown into b->doc[its document].  This file holds the sections on
** throughput, scaling, the cost of each term and the oriented particles; bench-accuracy.c the
** accuracy studies, bench-regularity.c the regularity threshold and its
** cost, bench-siman.c the GSL baseline, bench-quench.c the quench, bench-kink.c what
** resolving the kernel's kink at the cutoff would buy dE.
*/
#include <gsl/gsl_math.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "benchutil.h"
#include <gsl/gsl_rng.h>

#include "linewise/anneal.h"
#include "linewise/init.h"
#include "linewise/output.h"
#include "linewise/particles.h"
#include "linewise/vec2.h"

#ifndef BENCH_CFLAGS
#define BENCH_CFLAGS "(not recorded)"
#endif

void bench_quadrature(bench_ctx *b);
void bench_cutoff(bench_ctx *b);
void bench_near(bench_ctx *b);
void bench_kink(bench_ctx *b);
void bench_guide(bench_ctx *b);
void bench_baseline(bench_ctx *b);
void bench_tempering(bench_ctx *b);
void bench_domains(bench_ctx *b);
void bench_nurbs(bench_ctx *b);
void bench_regularity(bench_ctx *b);
void bench_regularity_cost(bench_ctx *b);
void bench_order(bench_ctx *b);
void bench_tone(bench_ctx *b);
void bench_tone_accuracy(bench_ctx *b);
void bench_quench(bench_ctx *b);
void bench_splice(bench_ctx *b);
void bench_photo(bench_ctx *b);
void bench_photo_tone(bench_ctx *b);

/* ---- throughput and scaling ---------------------------------------------- */

/* Seconds of this thread's CPU time: a shared machine's preemption does not count. */
static double thread_seconds(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Samples of other splines within the cutoff, averaged over samples. */
static double mean_neighbours(const lw_model *m)
{
  if (!m->grid) return 0.0;
  const lw_cellgrid *g = m->grid;
  size_t n = g->n_samples, step = n > 20000 ? n / 20000 : 1, count = 0, seen = 0;
  double rc2 = m->scene->pair.cutoff * m->scene->pair.cutoff;
  for (size_t i = 0; i < n; i += step, seen++) {
    double sx, sy;
    float sdl;
    lw_cellgrid_get(g, (uint32_t)i, &sx, &sy, &sdl);
    uint32_t me = m->sp->seg_spline[i / (size_t)m->scene->pair_quad.n];
    int cx, cy;
    lw_cellgrid_locate(g, sx, sy, &cx, &cy);
    for (int y = cy - 1; y <= cy + 1; y++)
      for (int x = cx - 1; x <= cx + 1; x++) {
        if (x < 0 || y < 0 || x >= g->nx || y >= g->ny) continue;
        const lw_cell *c = &g->cell[y * g->nx + x];
        for (uint32_t k = 0; k < c->n; k++) {
          double dx = c->x[k] - sx, dy = lw_cell_y(c)[k] - sy;
          uint32_t other = m->sp->seg_spline[lw_cell_idx(c)[k] / (uint32_t)m->scene->pair_quad.n];
          if (other != me && dx * dx + dy * dy < rc2) count++;
        }
      }
  }
  return seen ? (double)count / (double)seen : 0.0;
}

/* Bytes the model holds for its state, caches and grid, per segment. */
static double bytes_per_segment(const lw_model *m)
{
  const lw_splines *sp = m->sp;
  double b = sizeof *m + (double)sp->n_nodes * sizeof(lw_node) +
             (double)sp->n_splines * (2 * sizeof(size_t) + sizeof(double) + sizeof(double)) +
             (double)sp->n_segments * (sizeof(uint32_t) + sizeof(double) + sizeof *m->seg_irregular +
                                       (double)m->scene->n_local * sizeof(double));
  if (m->grid)
    b += (double)sp->n_segments *
             (sizeof *m->near_cache + sizeof *m->near_valid +
              (m->near_pid ? LW_NEAR_SLOTS * (sizeof *m->near_pid + sizeof *m->near_pval) : 0)) +
         (double)lw_cellgrid_bytes(m->grid);
  return b / (double)(sp->n_segments ? sp->n_segments : 1);
}

/* Steps are tuned at T = 0.05 for 20,000 proposals (the step of a move kind
** settles within a few hundred tuning windows), so every run is timed at its
** own acceptance. */
#define BENCH_T 0.05

static void tune_random(bench_run *r)
{
  bench_run_tune(r, 20000);
}

/* The throughput scenes: the pair term off, then near field off (the
** product rule everywhere) and near pairs within 1.5 element lengths, each at
** two densities. */
#define N_THROUGHPUT 5
static const struct {
  double spacing;    /* mm */
  int pair;
  double near_scale; /* lw_pair_ctx.near_scale */
} throughput[N_THROUGHPUT] = {{2.0, 0, 0.0}, {2.8, 1, 0.0}, {1.4, 1, 0.0}, {2.8, 1, 1.5}, {1.4, 1, 1.5}};

static void bench_throughput(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_PERFORMANCE];
  /* the scenes in sweeps; then the pair rows with the two-wide kernels, and
  ** with nodes drawn at random, all timed interleaved */
  enum { N_PAIR = N_THROUGHPUT - 1, NARROW = N_THROUGHPUT, RANDOM = N_THROUGHPUT + N_PAIR,
         N_RUNS = N_THROUGHPUT + 2 * N_PAIR };
  bench_run r[N_RUNS];
  lw_params p;
  for (int i = 0; i < N_RUNS; i++) {
    int k = i < N_THROUGHPUT ? i : (i - N_THROUGHPUT) % N_PAIR + 1;
    bench_random_params(&p, 1000, throughput[k].pair, throughput[k].spacing);
    p.pair_near = throughput[k].near_scale;
    bench_run_init(&r[i], &p, NULL, BENCH_T, NULL);
    lw_error err;
    /* the splines numbered along the page, as a run numbers them */
    if (r[i].sys->type->renumber(r[i].sys->state, &err) || lw_model_refresh(r[i].model, NULL))
      bench_die("throughput", &err);
    r[i].narrow = i >= NARROW && i < RANDOM;
    r[i].sweeps = i < RANDOM;
    tune_random(&r[i]);
  }
  double ns[N_RUNS], ratio[N_RUNS];
  bench_time_runs(b, r, N_RUNS, 0, NULL, 0, ns, ratio, NULL);
  fprintf(d, "## Throughput\n\n"
             "1000 splines of 4 segments of 5 mm at random places, traced along the field, at the stated mean\n"
             "spacing (page area / total length); every term on (radial potential, waves field,\n"
             "boundary), quadrature 8, T = %g after tuning. Near field off: the product rule for every\n"
             "pair; near 1.5: a sample pair closer than 1.5 length elements makes its two segments a near\n"
             "pair, which takes the near field (pairnear.h), the product rule the others. Lines that\n"
             "cross make near pairs, and so do neighbours running alongside closely, the near field's\n"
             "costliest case (docs/NUMERICS.md). Proposals come in sweeps, as a run makes them: the\n"
             "nodes in order, splines numbered along the page, point and vector moves half and half\n"
             "(docs/NUMERICS.md, \"Sweep order\"); the last column times the same scenes with the nodes\n"
             "drawn at random instead. The pair kernels run four lanes at a time where the processor\n"
             "has AVX2 (%s here), and the walk's scan eight where it has AVX-512 (%s here); the\n"
             "column before it times the same scene with the two-wide (SSE2) kernels, as a ratio.\n"
             "Every width gives the same bits. All runs interleaved.\n\n"
             "| scene | neighbours per sample | ns per proposal | proposals per second | x cost without pair | "
             "acceptance | bytes per segment | two-wide kernels, x time | nodes at random, proposals per second |\n"
             "|---|---|---|---|---|---|---|---|---|\n",
          BENCH_T, lw_vec_wide() ? "it has" : "it has not", lw_vec_lanes() == LW_VEC_8 ? "it has" : "it has not");
  for (int i = 0; i < N_THROUGHPUT; i++) {
    char what[96];
    if (!throughput[i].pair) snprintf(what, sizeof what, "every term but pair");
    else if (throughput[i].near_scale > 0.0)
      snprintf(what, sizeof what, "every term, pair cutoff 4 mm, lines %.1f mm apart, near %.1f",
               throughput[i].spacing, throughput[i].near_scale);
    else
      snprintf(what, sizeof what, "every term, pair cutoff 4 mm, lines %.1f mm apart, near field off",
               throughput[i].spacing);
    char nb[32] = "-", two[32] = "-", rnd[32] = "-";
    if (throughput[i].pair) {
      snprintf(nb, sizeof nb, "%.1f", mean_neighbours(r[i].model));
      snprintf(two, sizeof two, "%.2f", ratio[NARROW + i - 1] / ratio[i]);
      snprintf(rnd, sizeof rnd, "%.0f", 1e9 / ns[RANDOM + i - 1]);
    }
    fprintf(d, "| %s | %s | %.0f | %.0f | %.1f | %.2f | %.0f | %s | %s |\n", what, nb, ns[i], 1e9 / ns[i], ratio[i],
            bench_run_acceptance(&r[i]), bytes_per_segment(r[i].model), two, rnd);
  }
  /* the targets of the speed point, the near-field rows (sparse, then
  ** dense); also as the ratio to the row without the pair term, which a
  ** slow hour moves less */
  const double target[2] = {100000.0, 50000.0};
  int row[2] = {0, 0}, nr = 0;
  for (int i = 0; i < N_THROUGHPUT && nr < 2; i++)
    if (throughput[i].near_scale > 0.0) row[nr++] = i;
  fprintf(d, "\nThe speed targets, with every term on and the near field as by default, in this run:\n\n");
  for (int t = 0; t < 2; t++)
    fprintf(d, "- at about %.0f neighbours %.0f proposals a second, against %.0f: %s.\n", mean_neighbours(r[row[t]].model),
            1e9 / ns[row[t]], target[t], 1e9 / ns[row[t]] >= target[t] ? "met" : "not met");
  fprintf(d, "\nThe sample-gap and clearance checks of docs/NUMERICS.md (\"Regular segments\") took 1.07 %% of\n"
             "params/flow.ini's instructions over 40 sweeps when last measured (callgrind, 2026-12-07: the\n"
             "frame's check 0.79 %%, answering a segment whose four control points clear a convex frame\n"
             "after those four distances, 420 instructions a call; the pair gaps 0.28 %%); \"Throughput:\n"
             "earlier runs\" below has the history. Under valgrind the processor shows no AVX-512, so\n"
             "callgrind's counts are of the narrower kernels' code (the tone's splat counted 43 %% of the\n"
             "example's sweeps there, about 22 %% natively; the grid lookups and the spacing's scan, which\n"
             "wait on memory, look 3 to 4 times cheaper than they are): shares of time are perf's.\n");
  fprintf(d, "\nThe machine is shared and its speed moves by up to a fifth between runs;\n"
             "the column \"x cost without pair\" (each row's time over the row without the pair term, in\n"
             "the same blocks) moves less at a moderate load, but under a heavy one (a load of 8 on 2\n"
             "cores, a reviewer's 2026-12-07 runs) it rose by 25 to 45 %%: the pair rows suffer more from\n"
             "shared caches. That row ran at %.0f proposals a second here, at which speed\n"
             "the targets allow the near-field rows %.1f and %.1f times its cost (%.1f and %.1f measured).\n"
             "Those rows' chains decide in two stages (`anneal.delayed_acceptance`): the acceptance is\n"
             "that of both; their extra bytes a segment are mostly the pair slots. That is the model\n"
             "between sweeps: a recomputation from scratch (the set-up, and every `anneal.check_every`\n"
             "sweeps) holds the near field's sorted list of (sample, segment) pairs on top while it runs\n"
             "(measured 2026-12-05 at 100,000 splines of the Scaling scene: a peak of 514 bytes a\n"
             "segment with the near field at 1.5, 375 with it off; on params/minimal.ini's denser random\n"
             "start, 1.4 mm of line a mm^2, 865 at 50,000 splines against 361. Before the list held each\n"
             "sample's near segments once, 581 and 1,465). A start whose splines would take more than\n"
             "the machine's memory at 360 bytes a segment (the least measured) is refused before its\n"
             "placement, naming the count (`init.splines` or the one `init.coverage` works out); one that\n"
             "fits that but not the peak is told (see \"Memory\"). Where a proposal's\n"
             "time goes, and what was measured and kept or not on the way to this speed: docs/NUMERICS.md,\n"
             "\"Pair term: near field\", from \"Where the time goes\" on.\n\n",
          1e9 / ns[0], 1e9 / ns[0] / target[0], 1e9 / ns[0] / target[1], ratio[row[0]], ratio[row[1]]);
  for (int i = 0; i < N_RUNS; i++) bench_run_free(&r[i]);
}

/*
** Scaling, measured as a user's run anneals: each scene is a run
** (lw_anneal_start, constant temperature) and a timed block is whole sweeps
** of lw_anneal_sweep, with everything that falls due in them, which is what
** two runs that differ only in sweeps differ by (set-up and output cancel).
** The runs of one table are all in memory at once and timed interleaved,
** block by block, so that a change in the machine's load hits them alike.
*/
#define N_SCALE 4
/* A sweep of 10^6 splines with the pair term takes about a minute: three
** blocks, not the usual seven. */
#define SCALE_REPS(b) ((b)->reps < 3 ? (b)->reps : 3)
static const size_t scale_sizes[N_SCALE] = {1000, 10000, 100000, 1000000};

typedef struct {
  lw_anneal a;
  size_t nodes;
  double setup_s;    /* wall time of lw_anneal_start */
  double renumber_s; /* one renumbering and refresh (what a check adds) */
} scale_run;

static void scale_start(scale_run *r, size_t n, int pair, const char *dir)
{
  lw_params p;
  lw_error err;
  bench_random_params(&p, n, pair, 2.8);
  p.pair_near = 0.0;
  /* point and vector moves, as in the throughput table (rigid moves touch
  ** every segment of a spline and cost about twice as much a proposal) */
  p.mix_point = p.mix_vector = 0.5;
  p.mix_translate = p.mix_rotate = 0.0;
  strcpy(p.schedule, "constant");
  p.t_start = BENCH_T;
  p.tune_sweeps = 1;
  p.sweeps = 1000000;
  p.checkpoint_every = 1000000;
  p.trace_every = 1000000;
  char sub[LW_PATH_MAX];
  snprintf(sub, sizeof sub, "%s/%zu-%d", dir, n, pair);
  double t0 = bench_now();
  if (lw_anneal_start(&r->a, &p, sub, &err)) bench_die("scaling", &err);
  r->setup_s = bench_now() - t0;
  r->nodes = r->a.sys_type->sweep_size(r->a.sys->state);
  /* the tuning sweep, untimed: then the steps hold */
  if (lw_anneal_sweep(&r->a, &err)) bench_die("scaling", &err);
}

/* ns per proposal over whole sweeps lasting at least `seconds` (one at
** least), in thread CPU time: a block of a million splines lasts a minute,
** and a shared machine's preemption during it must not count against it
** (the run has one replica, so its sweeps run on this thread). */
static double scale_block(scale_run *r, double seconds)
{
  lw_error err;
  long sweeps = 0;
  double t0 = thread_seconds(), t;
  do {
    if (lw_anneal_sweep(&r->a, &err)) bench_die("scaling", &err);
    sweeps++;
  } while ((t = thread_seconds() - t0) < seconds);
  return 1e9 * t / ((double)sweeps * (double)r->nodes);
}

/* The same with the sites drawn at random, as every sweep drew them before
** issue 14: proposals of the run's chain through lw_chain_step, point and
** vector alternating, a sweep's worth at a time. */
static double random_block(scale_run *r, double seconds)
{
  lw_chain *c = r->a.chain;
  double done = 0.0, t0 = thread_seconds(), t;
  do {
    for (size_t k = 0; k < r->nodes; k++)
      if (lw_chain_step(c, (int)(k & 1)) < 0) bench_die("scaling", &(lw_error){.code = LW_ENOMEM, .msg = "commit"});
    done += (double)r->nodes;
  } while ((t = thread_seconds() - t0) < seconds);
  return 1e9 * t / done;
}

/* Median of v[0..n) and the median absolute deviation from it (v kept). */
static double median_mad(const double *v, int n, double *mad)
{
  double w[BENCH_MAX_REPS], dev[BENCH_MAX_REPS];
  memcpy(w, v, (size_t)n * sizeof *w);
  double m = bench_median(w, n);
  for (int k = 0; k < n; k++) dev[k] = fabs(v[k] - m);
  *mad = bench_median(dev, n);
  return m;
}

/* One renumbering and refresh, as a check every anneal.check_every sweeps runs them. */
static void scale_renumber(scale_run *r)
{
  lw_error err;
  double t0 = bench_now();
  if (r->a.sys_type->renumber(r->a.sys->state, &err) || r->a.sys_type->refresh(r->a.sys->state))
    bench_die("scaling", &err);
  r->renumber_s = bench_now() - t0;
}

static void scaling_table(bench_ctx *b, int pair, int n, const char *dir, FILE *f)
{
  FILE *d = b->doc[BENCH_PERFORMANCE];
  const int ref = 0, reps = SCALE_REPS(b);
  scale_run r[N_SCALE];
  /* random selection beside the sweep order: for local terms only, where a
  ** sweep of 10^6 splines takes seconds, not a minute */
  const int with_random = !pair;
  double t[N_SCALE][BENCH_MAX_REPS], q[N_SCALE][BENCH_MAX_REPS];
  double tr[N_SCALE][BENCH_MAX_REPS], qr[N_SCALE][BENCH_MAX_REPS];
  for (int i = 0; i < n; i++) {
    bench_note("scaling: %zu splines, pair %s", scale_sizes[i], pair ? "on" : "off");
    scale_start(&r[i], scale_sizes[i], pair, dir);
  }
  for (int k = 0; k < reps; k++)
    for (int i = 0; i < n; i++) {
      t[i][k] = scale_block(&r[i], b->block);
      if (with_random) tr[i][k] = random_block(&r[i], b->block);
    }
  fprintf(d, "%s:\n\n"
             "| splines | segments | ns per proposal | ratio to 1000 | set-up s | ms per sweep | renumber + refresh s "
             "| bytes per segment | acceptance |%s\n|---|---|---|---|---|---|---|---|---|%s\n",
          pair ? "With the pair term (cutoff 4 mm, near field off)" : "Local terms only (the pair term off)",
          with_random ? " random selection: ns per proposal | its ratio to 1000 |" : "",
          with_random ? "---|---|" : "");
  for (int i = 0; i < n; i++) {
    for (int k = 0; k < reps; k++) {
      q[i][k] = t[i][k] / t[ref][k];
      if (with_random) qr[i][k] = tr[i][k] / tr[ref][k];
    }
    double mad, unused;
    double ns = median_mad(t[i], reps, &unused), ratio = median_mad(q[i], reps, &mad);
    scale_renumber(&r[i]);
    const lw_model *m = lw_splines_model(r[i].a.sys);
    double bps = bytes_per_segment(m);
    fprintf(d, "| %zu | %zu | %.0f | %.2f +- %.2f | %.1f | %.0f | %.2f | %.0f | %.2f |", scale_sizes[i],
            m->sp->n_segments, ns, ratio, mad, r[i].setup_s, 1e-6 * ns * (double)r[i].nodes, r[i].renumber_s, bps,
            lw_anneal_acceptance(&r[i].a));
    if (with_random) {
      double rmad, ns_r = median_mad(tr[i], reps, &unused), ratio_r = median_mad(qr[i], reps, &rmad);
      fprintf(d, " %.0f | %.2f +- %.2f |", ns_r, ratio_r, rmad);
    }
    fprintf(d, "\n");
    fprintf(f, "%d %zu %.1f %.4f %.1f\n", pair, scale_sizes[i], ns, ratio, bps);
    lw_anneal_free(&r[i].a);
  }
  fprintf(f, "\n\n");
  fprintf(d, "\n");
}

static void bench_scaling(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_PERFORMANCE];
  const int n = b->quick ? 2 : N_SCALE;
  char dir[128];
  bench_scratch_dir(dir, sizeof dir, "scale");
  fprintf(d, "## Scaling\n\n"
             "The throughput scene (lines 2.8 mm apart, every local term; with and without the pair\n"
             "term, near field off) at constant density from 10^3 to 10^%d splines, annealed as a run\n"
             "anneals (lw_anneal, constant T = %g after one tuning sweep, point and vector moves): a timed\n"
             "block is whole sweeps lasting at least %.2f s of thread CPU time (a shared machine's\n"
             "preemption does not count), with everything that falls due in them, which is what two\n"
             "runs that differ only in sweeps differ by. A proposal touches one\n"
             "spline and its neighbours only, so its cost must not grow with the scene. It did, from\n"
             "cache misses: nodes were picked at random from one big array. Sweeps now visit the\n"
             "nodes in order, forward or backward at random, and splines are numbered along a Hilbert\n"
             "curve of the page at the start and at every drift check (docs/NUMERICS.md, \"Sweep\n"
             "order\"), so consecutive proposals share grid cells and cache lines. Ratios are to 1000\n"
             "splines, block by block over %d interleaved blocks (+- the median absolute deviation):\n"
             "the median of those ratios, not the ratio of the ns column's medians, which takes each\n"
             "size's blocks alone, so the two can fall on either side of 1 where the sizes differ by\n"
             "less than the machine's drift between blocks; the ratio, measured side by side, is the\n"
             "one to read.\n"
             "Set-up: lw_anneal_start (placement, model, the first state.lw). Renumber + refresh: the\n"
             "work a drift check (every anneal.check_every = 100 sweeps by default) adds, under 1%%\n"
             "of the sweeps between two checks. Random selection (local terms): the same runs, in the\n"
             "same blocks, with proposals at nodes drawn at random (lw_chain_step), as every sweep\n"
             "made them before; the splines keep their curve numbering, which random selection\n"
             "cannot use.\n\n"
             "![ns per proposal against splines](scaling.png)\n\n",
          n + 2, BENCH_T, b->block, SCALE_REPS(b));
  FILE *f = bench_data(b, "scaling.dat");
  fprintf(f, "# pair splines ns_per_proposal ratio_to_1000 bytes_per_segment (one block per table)\n");
  scaling_table(b, 0, n, dir, f);
  scaling_table(b, 1, n, dir, f);
  fclose(f);
  bench_scratch_remove(dir);
}

/* ---- start-up of one long spline --------------------------------------- */

/*
** One spline of n segments of 2 mm traced along a vortex field on a page of
** 100 mm, so it winds round one circle hundreds of times and most of its
** samples share a few cells: the worst case for excluding a spline's own
** samples (issue 21, defect 12).  Placement and the model (samples, grid,
** the full pair sum) are timed; the pair term is on (cutoff 5 mm), so the
** model's time is the start-up the defect was about.
*/

static void bench_startup(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_PERFORMANCE];
  const size_t sizes[3] = {1000, 10000, 100000};
  const int n = b->quick ? 2 : 3, reps = b->quick ? 1 : 3;
  fprintf(d, "## Start-up of one long spline\n\n"
             "One spline of n segments of 2 mm traced along a vortex field on a 100 mm page: it winds\n"
             "round one circle, so most of its samples share a few cells of the pair grid (cutoff\n"
             "5 mm, quadrature 8). A walk excludes the spline's own samples by a binary search in each\n"
             "cell's sorted indices (walk.h), so building the model (samples, grid, the full pair sum)\n"
             "must grow linearly with n. Before that fix the walk visited every own sample from every\n"
             "sample: 10^5 segments did not finish in 300 s. Medians of %d runs of thread CPU time (a\n"
             "shared machine preempts, which does not count); the larger models no longer fit in cache.\n\n"
             "| segments | placement s | model s | model us per segment |\n|---|---|---|---|\n",
          reps);
  for (int i = 0; i < n; i++) {
    lw_params p;
    lw_params_defaults(&p);
    p.width = p.height = 100.0;
    p.margin = 5.0;
    p.splines = 1;
    p.segments = (int)sizes[i];
    p.segment_length = 2.0;
    p.strain = 10;
    p.bending = 1;
    p.field = LW_FLD_VORTEX;
    p.field_coef = -0.1;
    p.pair = 0.02;
    p.pair_cutoff = 5.0;
    p.seed = 1;
    lw_scene sc;
    lw_error err;
    if (lw_scene_init(&sc, &p, &err)) bench_die("scene", &err);
    double tp[BENCH_MAX_REPS], tm[BENCH_MAX_REPS];
    for (int k = 0; k < reps; k++) {
      gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
      gsl_rng_set(rng, 1);
      double t0 = thread_seconds();
      lw_splines *sp = lw_init_random(&sc, 1, sizes[i], p.segment_length, rng, &err);
      double t1 = thread_seconds();
      gsl_rng_free(rng);
      if (!sp) bench_die("placement", &err);
      lw_model *m = lw_model_new(&sc, sp, &err);
      tm[k] = thread_seconds() - t1;
      tp[k] = t1 - t0;
      if (!m) bench_die("model", &err);
      lw_model_free(m);
    }
    double placed = bench_median(tp, reps), model = bench_median(tm, reps);
    fprintf(d, "| %zu | %.3f | %.3f | %.2f |\n", sizes[i], placed, model, 1e6 * model / (double)sizes[i]);
    lw_scene_clear(&sc);
  }
  fprintf(d, "\n");
}

/* ---- what each term costs ------------------------------------------------ */

static void only_terms(lw_params *p, const lw_params *all, unsigned mask)
{
  *p = *all;
  p->strain = mask & 1 ? all->strain : 0;
  p->bending = mask & 2 ? all->bending : 0;
  p->potential_coef = mask & 4 ? all->potential_coef : 0;
  p->field_coef = mask & 8 ? all->field_coef : 0;
  p->pair = mask & 16 ? all->pair : 0;
  p->boundary_coef = mask & 32 ? all->boundary_coef : 0;
}

static void bench_terms(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_PERFORMANCE];
  lw_params all;
  bench_random_params(&all, 1000, 1, 2.8);
  /* The bare strain scene names nothing else: the default potential, field
  ** and pair settings.  The "named" one sets up every other term's data
  ** (radial potential, waves field, a 4 mm cutoff) with coefficient 0, which
  ** is how a scene leaves a term off.  Both place the same lines. */
  lw_params bare;
  lw_params_defaults(&bare);
  bare.width = all.width;
  bare.height = all.height;
  bare.margin = all.margin;
  bare.splines = all.splines;
  bare.segments = all.segments;
  bare.segment_length = all.segment_length;
  bare.seed = all.seed;
  bare.strain = all.strain;
  enum { MAXC = 11 };
  struct {
    const char *name;
    lw_params p;
  } cf[MAXC];
  int n = 0;
  static const char *const names[6] = {"strain", "bending", "potential", "field", "pair", "boundary"};
  only_terms(&cf[n].p, &all, 0);
  cf[n++].name = "none (move, sampling, Metropolis)";
  for (int t = 0; t < 6; t++) {
    only_terms(&cf[n].p, &all, 1u << t);
    cf[n++].name = names[t];
  }
  only_terms(&cf[n].p, &all, 63);
  cf[n++].name = "all six";
  const int i_all = n - 1, i_bare = n;
  cf[n].name = "strain, nothing else named";
  cf[n++].p = bare;
  only_terms(&cf[n].p, &all, 1);
  cf[n++].name = "strain, the others named with coefficient 0";
  cf[n].name = "strain, nothing else named (again: the noise)";
  cf[n++].p = bare;

  bench_run r[MAXC];
  /* The same lines in every scene: placement follows the field when the
  ** field term is on, so the lines are placed once, without it, and copied;
  ** placed under the boundary term, clear of the frame as it asks (placed
  ** without it, a line too near the edge left that term infinite in the
  ** scenes with it, every commit rebuilt the whole model, and the section
  ** never ended). */
  const int i_place = 1 + 5; /* after "none": names[5], "boundary" */
  bench_run_init(&r[i_place], &cf[i_place].p, NULL, BENCH_T, NULL);
  for (int i = 0; i < n; i++) {
    if (i == i_place) continue;
    lw_splines *sp = lw_splines_clone(r[i_place].model->sp);
    if (!sp) {
      lw_error e = {.code = LW_ENOMEM, .msg = "out of memory"};
      bench_die("terms", &e);
    }
    bench_run_init(&r[i], &cf[i].p, sp, BENCH_T, NULL);
  }
  /* the same proposals for every scene */
  const double step[2] = {0.2, 0.2};
  const int nt = 4096;
  bench_trial *trials = bench_trials_new(r[0].model->sp, step, nt);
  double ev[MAXC], ratio[MAXC], spread[MAXC], ns[MAXC], unused[MAXC];
  bench_time_runs(b, r, i_all + 1, 0, trials, nt, ev, unused, NULL);
  /* The three strain scenes differ by noise alone, so they get many short
  ** blocks: finer interleaving follows changes in the machine's load. */
  bench_ctx fine = *b;
  fine.reps = BENCH_MAX_REPS;
  fine.block = b->block * b->reps / BENCH_MAX_REPS;
  bench_time_runs(&fine, r + i_bare, n - i_bare, 0, trials, nt, ev + i_bare, ratio + i_bare, spread + i_bare);
  for (int i = 0; i <= i_all; i++) tune_random(&r[i]);
  bench_time_runs(b, r, i_all + 1, 0, NULL, 0, ns, unused, NULL);
  free(trials);

  double sum = ev[0];
  for (int t = 1; t <= 6; t++) sum += ev[t] - ev[0];
  fprintf(d, "## What each term costs\n\n"
             "The 1000-spline scene with the pair term (lines 2.8 mm apart), each term alone and all\n"
             "together. Evaluation: the same %d proposals (point and vector moves of 0.2 mm) evaluated\n"
             "and never committed, which is the energy terms' own cost; extra: over the scene with no\n"
             "term at all, which still samples the two segments and sums dE. Chain: the Metropolis walk\n"
             "itself after tuning at T = %g, so acceptance, and with it the commits, differ. Its lines\n"
             "are placed with the frame alone, not traced along the field as Throughput's are, so more of\n"
             "them cross, the near field's costliest case: a pair row here costs 2 to 2.5 times\n"
             "Throughput's (a reviewer's runs, 2026-12-07), which is the table to budget a run by.\n\n"
             "| terms | ns per evaluation | extra ns | ns per chain proposal | acceptance | bytes per segment |\n"
             "|---|---|---|---|---|---|\n",
          nt, BENCH_T);
  for (int i = 0; i <= i_all; i++) {
    char extra[32] = "-";
    if (i) snprintf(extra, sizeof extra, "%.0f", ev[i] - ev[0]);
    fprintf(d, "| %s | %.0f | %s | %.0f | %.2f | %.0f |\n", cf[i].name, ev[i], extra, ns[i],
            bench_run_acceptance(&r[i]), bytes_per_segment(r[i].model));
  }
  fprintf(d, "\nNone plus the extra ns of each term alone: %.0f ns per evaluation, against %.0f with all six\n"
             "(ratio %.2f): the costs add up.\n\n",
          sum, ev[i_all], ev[i_all] / sum);
  fprintf(d, "A term the scene does not name adds nothing. The strain scene three times, evaluated in the\n"
             "same blocks: once naming nothing else, once with every other term set up (radial\n"
             "potential, waves field, pair cutoff 4 mm, near field 1.5) but with coefficient 0, and\n"
             "once more naming nothing, which shows the noise. Ratios are to the first, block by block\n"
             "over %d blocks of %.3f s (+- the median absolute deviation):\n\n"
             "| scene | ns per evaluation | ratio | bytes per segment |\n|---|---|---|---|\n",
          fine.reps, fine.block);
  for (int i = i_bare; i < n; i++)
    fprintf(d, "| %s | %.0f | %.3f +- %.3f | %.0f |\n", cf[i].name, ev[i], ratio[i], spread[i],
            bytes_per_segment(r[i].model));
  fprintf(d, "\n");
  for (int i = 0; i < n; i++) bench_run_free(&r[i]);
}

/* ---- oriented particles --------------------------------------------------- */

/* A Metropolis step of the particle system at T: kind by turns, step per kind;
** returns 1 if accepted. */
static int particle_step(lw_particles *p, lw_particles_prop *pr, gsl_rng *r, int kind, double step, double T)
{
  int forbidden;
  double dE = lw_particles_propose(p, pr, kind, step, r, &forbidden);
  if (forbidden || !(dE <= 0 || gsl_rng_uniform(r) < exp(-dE / T))) return 0;
  if (lw_particles_commit(p, pr)) bench_die("out of memory", NULL);
  return 1;
}

/* Particles other than i within the range, averaged over the particles. */
static double particle_neighbours(const lw_particles *p)
{
  double R2 = p->setup->pair.range2;
  size_t pairs = 0;
  for (size_t i = 0; i < p->n; i++)
    for (size_t j = i + 1; j < p->n; j++) {
      const double *a = p->x + 3 * i, *c = p->x + 3 * j;
      double r[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      pairs += lw_v3_dot(r, r) < R2;
    }
  return 2.0 * (double)pairs / (double)p->n;
}

#define N_PARTICLE_ROWS 3
static void bench_particles(bench_ctx *b)
{
  static const struct {
    const char *what;
    double alpha[4]; /* LJ, P, N, C */
    int weight;
  } row[N_PARTICLE_ROWS] = {{"Lennard-Jones only", {1, 0, 0, 0}, LW_PWEIGHT_POLY},
                            {"all four pair terms, weight poly", {1, 1, 1, 1}, LW_PWEIGHT_POLY},
                            {"all four pair terms, weight aniso", {1, 1, 1, 1}, LW_PWEIGHT_ANISO}};
  /* 0.7 particles per r0^3 put 12 within 1.6 r0; at T = 0.2 the particles
  ** rattle in place, so the density holds during the timing */
  const double T = 0.2, density = 0.7;
  const size_t count = b->quick ? 500 : 4000;
  FILE *d = b->doc[BENCH_PERFORMANCE];
  fprintf(d, "## Oriented particles\n\n"
             "%zu particles placed as the cloud pattern in a cube at %.1f per r0^3, which puts about 12\n"
             "within the range 1.6 r0, at T = %g, where they rattle in place: the density holds while\n"
             "timed. Steps are tuned toward 40 %% acceptance for 30 sweeps, then frozen for the timing\n"
             "(a rotation's step may reach its cap, pi, and still be accepted more often).\n"
             "Translations and rotations alternate; a proposal walks the cells around its particle that\n"
             "come within the range: a translation at its old and new place, a rotation once, and not at\n"
             "all without a weighted term (it cannot change a distance). The neighbours are counted after\n"
             "the timing. The gradient (the quench's and the dynamics' forces and torques, every pair once)\n"
             "is timed on the same state, per particle, and against a sweep (one proposal a particle).\n\n"
             "| scene | neighbours | ns per proposal | proposals per second | acceptance | gradient, ns per "
             "particle | gradient / sweep |\n"
             "|---|---|---|---|---|---|---|\n",
          count, density, T);
  for (int k = 0; k < N_PARTICLE_ROWS; k++) {
    lw_params prm;
    lw_params_defaults(&prm);
    strcpy(prm.system, "particles");
    prm.pt_pattern = LW_PPATTERN_CLOUD;
    prm.pt_count = (int)count;
    prm.pt_size = cbrt((double)count / density);
    prm.pt_weight = row[k].weight;
    prm.pt_alpha_lj = row[k].alpha[0];
    prm.pt_alpha_p = row[k].alpha[1];
    prm.pt_alpha_n = row[k].alpha[2];
    prm.pt_alpha_c = row[k].alpha[3];
    lw_error err;
    lw_particles_setup *s = lw_particles_setup_new(&prm, &err);
    lw_particles *p = s ? lw_particles_new(s, 1, NULL, &err) : NULL;
    lw_particles_prop *pr = p ? lw_particles_prop_new(p, &err) : NULL;
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    if (!pr || !r) bench_die("particles", &err);
    double step[2] = {0.1, 0.1};
    for (size_t i = 0; i < 60 * count; i++) {
      int kind = (int)(i & 1);
      /* tune by +3 % or -2 % a step, toward 40 % acceptance, within the cap */
      double f = particle_step(p, pr, r, kind, step[kind], T) ? 1.03 : 0.98;
      step[kind] = fmin(step[kind] * f, lw_particles_step_max(p, kind));
    }
    double ns[BENCH_MAX_REPS];
    unsigned long tried = 0, accepted = 0;
    for (int rep = 0; rep < b->reps; rep++) {
      double t0 = bench_now(), t;
      unsigned long n = 0;
      do {
        for (int i = 0; i < 1000; i++, n++) accepted += (unsigned long)particle_step(p, pr, r, i & 1, step[i & 1], T);
        t = bench_now() - t0;
      } while (t < b->block);
      tried += n;
      ns[rep] = 1e9 * t / (double)n;
    }
    double med = bench_median(ns, b->reps);
    size_t nc = lw_particles_n_coords(p);
    double *g = malloc(nc * sizeof *g), *c = malloc(nc * sizeof *c);
    if (!g || !c) bench_die("out of memory", NULL);
    lw_particles_get_coords(p, c);
    if (lw_particles_set_coords(p, c, &err)) bench_die("particles", &err);
    for (int rep = 0; rep < b->reps; rep++) {
      double t0 = bench_now(), t;
      unsigned long n = 0;
      do {
        if (!isfinite(lw_particles_gradient(p, g, &err))) bench_die("particles: gradient", &err);
        n++;
        t = bench_now() - t0;
      } while (t < b->block);
      ns[rep] = 1e9 * t / ((double)n * (double)p->n);
    }
    double grad = bench_median(ns, b->reps);
    free(g);
    free(c);
    fprintf(d, "| %s | %.1f | %.0f | %.0f | %.2f | %.0f | %.2f |\n", row[k].what, particle_neighbours(p), med,
            1e9 / med, (double)accepted / (double)tried, grad, grad / med);
    gsl_rng_free(r);
    lw_particles_prop_free(pr);
    lw_particles_free(p);
    lw_particles_setup_free(s);
  }
  fprintf(d, "\n");
}

/* ---- main ---------------------------------------------------------------- */

typedef struct {
  const char *name;
  bench_doc doc;
  void (*run)(bench_ctx *b);
} bench_section;

static const bench_section sections[] = {
    {"throughput", BENCH_PERFORMANCE, bench_throughput},
    {"scaling", BENCH_PERFORMANCE, bench_scaling},
    {"startup", BENCH_PERFORMANCE, bench_startup},
    {"order", BENCH_PERFORMANCE, bench_order},
    {"terms", BENCH_PERFORMANCE, bench_terms},
    {"regularity_cost", BENCH_PERFORMANCE, bench_regularity_cost},
    {"baseline", BENCH_PERFORMANCE, bench_baseline},
    {"tempering", BENCH_PERFORMANCE, bench_tempering},
    {"domains", BENCH_PERFORMANCE, bench_domains},
    {"particles", BENCH_PERFORMANCE, bench_particles},
    {"tone", BENCH_PERFORMANCE, bench_tone},
    {"nurbs", BENCH_PERFORMANCE, bench_nurbs},
    {"splice", BENCH_PERFORMANCE, bench_splice},
    {"photo", BENCH_PERFORMANCE, bench_photo},
    {"regularity", BENCH_ACCURACY, bench_regularity},
    {"quadrature", BENCH_ACCURACY, bench_quadrature},
    {"cutoff", BENCH_ACCURACY, bench_cutoff},
    {"near", BENCH_ACCURACY, bench_near},
    {"kink", BENCH_ACCURACY, bench_kink},
    {"tone_accuracy", BENCH_ACCURACY, bench_tone_accuracy},
    {"photo_tone", BENCH_ACCURACY, bench_photo_tone},
    {"guide", BENCH_ACCURACY, bench_guide},
    {"quench", BENCH_ACCURACY, bench_quench},
};
#define N_SECTIONS (int)(sizeof sections / sizeof sections[0])

static const char *const doc_file[BENCH_DOCS] = {"PERFORMANCE.md", "ACCURACY.md"};
static const char *const doc_title[BENCH_DOCS] = {"Performance", "Accuracy against time"};

static void cpu_model(char *out, size_t n)
{
  snprintf(out, n, "unknown CPU");
  FILE *f = fopen("/proc/cpuinfo", "r");
  if (!f) return;
  char line[512];
  while (fgets(line, sizeof line, f))
    if (!strncmp(line, "model name", 10)) {
      char *v = strchr(line, ':');
      if (v) {
        v += 1 + strspn(v + 1, " \t");
        v[strcspn(v, "\n")] = 0;
        snprintf(out, n, "%s", v);
      }
      break;
    }
  fclose(f);
}

static void load_average(char *out, size_t n)
{
  snprintf(out, n, "?");
  FILE *f = fopen("/proc/loadavg", "r");
  if (!f) return;
  double l1;
  if (fscanf(f, "%lf", &l1) == 1) snprintf(out, n, "%.2f", l1);
  fclose(f);
}

/* The machine, compiler and date, on top of each document. */
static void header(const bench_ctx *b, FILE *d, bench_doc which, const char *load)
{
  char cpu[256], date[32];
  cpu_model(cpu, sizeof cpu);
  time_t now = time(NULL);
  strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", gmtime(&now));
  fprintf(d, "# %s\n\n", doc_title[which]);
  fprintf(d, "Written by `make bench%s` (tools/bench.c) on %s: %s, %ld cores online, load average\n"
             "%s at the start; compiled with cc %s, flags %s.\n\n",
          b->quick ? " BENCH_QUICK=1" : "", date, cpu, sysconf(_SC_NPROCESSORS_ONLN), load, __VERSION__,
          BENCH_CFLAGS);
  fprintf(d, "Every time is the median of %d blocks of %.2f s of point and vector moves (alternating) on\n"
             "one core; runs that are compared are timed interleaved and their ratio is the median of\n"
             "the block-by-block ratios. The machine may be shared: ratios are the robust figures.\n\n",
          b->reps, b->block);
}

/* A document's "## " sections: where each begins in text (up to n), and
** where the last ends (the "---" footer, or n). */
#define MAX_SECTIONS 64
typedef struct {
  const char *at[MAX_SECTIONS + 1];
  int n;
} doc_sections;

static void split_sections(const char *text, size_t n, doc_sections *d)
{
  static const char footer[] = "\n---\nThe whole benchmark took";
  const char *end = text + n, *f = strstr(text, footer);
  if (f && f < end) end = f + 1;
  d->n = 0;
  for (const char *c = text; c < end && d->n < MAX_SECTIONS;) {
    if (!strncmp(c, "## ", 3)) d->at[d->n++] = c;
    const char *eol = strchr(c, '\n');
    c = eol ? eol + 1 : end;
  }
  d->at[d->n] = end;
}

static int same_title(const char *a, const char *b)
{
  const size_t la = strcspn(a, "\n"), lb = strcspn(b, "\n");
  return la == lb && !strncmp(a, b, la);
}

/* A section written by hand carries this line: a full run keeps it (a
** section the bench once wrote and no longer does is not kept for ever). */
#define KEPT_MARK "<!-- written by hand: make bench keeps this section -->"

/* The sections of the document at path that carry KEPT_MARK and that this
** run did not write ("## Memory"), each kept after the written section it
** followed there, into out: a full run rewrote the file and lost them. */
static void keep_hand_sections(const char *path, const char *fresh, size_t n_fresh, FILE *out)
{
  char *old = NULL;
  size_t n_old = 0;
  FILE *f = fopen(path, "r");
  if (f) {
    FILE *m = open_memstream(&old, &n_old);
    int ch;
    while (m && (ch = getc(f)) != EOF)
      if (ch != '\r') putc(ch, m); /* (a checkout's CRLF: no title matched) */
    if (m) fclose(m);
    fclose(f);
  }
  doc_sections o = {.n = 0}, w;
  if (old) split_sections(old, n_old, &o);
  split_sections(fresh, n_fresh, &w);
  /* each old section kept: after which written one (-1: before the first) */
  int after[MAX_SECTIONS], written = -1;
  for (int i = 0; i < o.n; i++) {
    int k = 0;
    while (k < w.n && !same_title(o.at[i], w.at[k])) k++;
    const char *mark = strstr(o.at[i], KEPT_MARK);
    after[i] = k < w.n || !mark || mark >= o.at[i + 1] ? -2 : written;
    if (k < w.n) written = k;
  }
  fwrite(fresh, 1, (size_t)(w.at[0] - fresh), out);
  for (int k = -1; k < w.n; k++) {
    if (k >= 0) fwrite(w.at[k], 1, (size_t)(w.at[k + 1] - w.at[k]), out);
    for (int i = 0; i < o.n; i++)
      if (after[i] == k) fwrite(o.at[i], 1, (size_t)(o.at[i + 1] - o.at[i]), out);
  }
  fwrite(w.at[w.n], 1, (size_t)(fresh + n_fresh - w.at[w.n]), out);
  free(old);
}

int main(int argc, char **argv)
{
  bench_ctx b;
  memset(&b, 0, sizeof b);
  const char *env = getenv("BENCH_QUICK");
  b.quick = env && *env && strcmp(env, "0");
  int only[N_SECTIONS], n_only = 0;
  const char *pos[2];
  int n_pos = 0;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick")) b.quick = 1;
    else if (!strcmp(argv[i], "--only") && i + 1 < argc) {
      int k = 0;
      while (k < N_SECTIONS && strcmp(sections[k].name, argv[i + 1])) k++;
      if (k == N_SECTIONS) {
        fprintf(stderr, "bench: no section '%s'\n", argv[i + 1]);
        return 2;
      }
      only[n_only++] = k;
      i++;
    } else if (argv[i][0] != '-' && n_pos < 2) pos[n_pos++] = argv[i];
    else {
      fprintf(stderr, "usage: bench [--quick] [--only SECTION]... DOCDIR DATADIR\n");
      return 2;
    }
  }
  if (n_pos != 2) {
    fprintf(stderr, "usage: bench [--quick] [--only SECTION]... DOCDIR DATADIR\n");
    return 2;
  }
  b.reps = b.quick ? 3 : 7;
  b.block = b.quick ? 0.05 : 0.25;
  b.datadir = pos[1];
  char load[32];
  load_average(load, sizeof load);

  /* The documents are kept in memory and written at the end (to a
  ** temporary name, then renamed): an interrupted run leaves the old ones. */
  char *text[BENCH_DOCS] = {NULL};
  size_t len[BENCH_DOCS] = {0};
  for (int k = 0; k < BENCH_DOCS; k++) {
    b.doc[k] = n_only ? stdout : open_memstream(&text[k], &len[k]);
    if (!b.doc[k]) bench_die("out of memory", NULL);
    if (!n_only) header(&b, b.doc[k], (bench_doc)k, load);
  }
  double t0 = bench_now();
  for (int k = 0; k < N_SECTIONS; k++) {
    int run = !n_only;
    for (int j = 0; j < n_only; j++) run |= only[j] == k;
    if (!run) continue;
    double t = bench_now();
    bench_note("%s ...", sections[k].name);
    sections[k].run(&b);
    bench_note("%s: %.0f s", sections[k].name, bench_now() - t);
  }
  for (int k = 0; k < BENCH_DOCS && !n_only; k++) {
    fprintf(b.doc[k], "---\nThe whole benchmark took %.0f s.\n", bench_now() - t0);
    fclose(b.doc[k]);
    char path[1024], tmp[1100];
    lw_error err;
    snprintf(path, sizeof path, "%s/%s", pos[0], doc_file[k]);
    FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, &err);
    if (!f) bench_die("document", &err);
    keep_hand_sections(path, text[k], len[k], f);
    if (lw_output_commit(f, tmp, path, &err)) bench_die("document", &err);
    free(text[k]);
  }
  lw_splines_free(b.ann_splines);
  return 0;
}
