/*
** bench-domains.c -- the domains section of the benchmark (`bench --only
** domains`): wall-time speed-up of one replica whose sweeps are split into
** domains (domains.h), against the same split run on one thread and the
** unsplit sweep.
**
** The scaling section's 10^5-spline scene (lines 2.8 mm apart, every local
** term, with and without the pair term), then 20,000 oriented particles on a
** noisy plane, annealed at constant T by lw_anneal with [anneal] domains =
** auto.  The thread count of a split run
** changes nothing in its result, so one run is timed block by block with 1,
** 2, 4 ... threads in turn (interleaved, so a change in the machine's load
** hits them alike), and the unsplit run beside it; ratios are taken block by
** block, then the median.  Wall time, since the point is the cores.
*/
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "benchutil.h"
#include "linewise/anneal.h"
#include "linewise/domains.h"

#define DOMAIN_SPLINES 100000
#define DOMAIN_PARTICLES 20000
#define DOMAIN_PARTICLES_TEXT "20,000 particles"
#define MAX_THREADS 5 /* 1, 2, 4, 8, 16 */

typedef struct {
  lw_anneal a;
  double setup_s;
} dom_run;

/* The scenes: the splines with local terms only, with the pair term, and
** the oriented particles. */
enum { DOM_LOCAL, DOM_PAIR, DOM_PARTICLES };

static void dom_start(dom_run *r, int scene, const char *domains, const char *dir)
{
  lw_params p;
  lw_error err;
  if (scene == DOM_PARTICLES) {
    /* a noisy plane of particles with every weighted term, as the sheet */
    lw_params_defaults(&p);
    strcpy(p.system, "particles");
    p.pt_pattern = LW_PPATTERN_PLANE;
    p.pt_count = DOMAIN_PARTICLES;
    p.pt_noise = 0.1;
    p.pt_normal_noise = 10;
    p.pt_alpha_p = p.pt_alpha_n = 10;
    p.pt_alpha_c = 0.5;
    p.mix_translate = p.mix_rotate = 1.0;
    p.step_translate = 0.1;
    p.step_rotate = 5;
    p.t_start = 0.01;
  } else {
    bench_random_params(&p, DOMAIN_SPLINES, scene == DOM_PAIR, 2.8);
    p.pair_near = 0.0;
    /* as the scaling table: point and vector moves */
    p.mix_point = p.mix_vector = 0.5;
    p.mix_translate = p.mix_rotate = 0.0;
    p.t_start = 0.05;
  }
  strcpy(p.schedule, "constant");
  p.tune_sweeps = 1;
  p.sweeps = 1000000;
  p.checkpoint_every = 1000000;
  p.trace_every = 1000000;
  snprintf(p.domains, sizeof p.domains, "%s", domains);
  double t0 = bench_now();
  if (lw_anneal_start(&r->a, &p, dir, &err)) bench_die("domains", &err);
  r->setup_s = bench_now() - t0;
  /* the tuning sweep, untimed */
  if (lw_anneal_sweep(&r->a, &err)) bench_die("domains", &err);
}

/* The proposals of c's move kinds, or (outside) those refused for leaving
** their domain. */
static unsigned long proposed(const lw_chain *c, int outside)
{
  unsigned long n = 0;
  for (int k = 0; k < c->n_moves; k++) n += outside ? c->stats[k].outside : c->stats[k].proposed;
  return n;
}

/* Wall ns per proposal made over whole sweeps lasting at least `seconds`;
** *ms_sweep the wall ms per sweep. */
static double dom_block(dom_run *r, int threads, double seconds, double *ms_sweep)
{
  lw_error err;
  if (r->a.chain->domains) r->a.chain->domains->threads = threads;
  unsigned long p0 = proposed(r->a.chain, 0);
  long sweeps = 0;
  double t0 = bench_now(), t;
  do {
    if (lw_anneal_sweep(&r->a, &err)) bench_die("domains", &err);
    sweeps++;
  } while ((t = bench_now() - t0) < seconds);
  *ms_sweep = 1e3 * t / (double)sweeps;
  return 1e9 * t / (double)(proposed(r->a.chain, 0) - p0);
}

/* The speed-up the last sweep allows on `threads` dedicated cores, from
** its profile (lw_domains.cell_cpu, thread CPU time, so preemption by other
** load does not count): per phase the cells go largest first to the least
** loaded thread (the dynamic schedule does about as well) and the phase
** lasts as long as its most loaded thread; the serial parts (the plan,
** the merges) run on one.  What it leaves out is what threads share:
** memory bandwidth and caches. */
static double profile_speedup(const lw_domains *d, int threads)
{
  double total = d->serial_cpu, span = d->serial_cpu;
  for (int colour = 0; colour < 4; colour++) {
    double load[16] = {0}, size[4096];
    int n = 0;
    for (int k = 0; k < d->n && n < 4096; k++) {
      int i = k % (d->nx + 1), j = k / (d->nx + 1);
      if ((i & 1) + 2 * (j & 1) == colour) size[n++] = d->cell_cpu[k];
    }
    for (int a = 0; a < n; a++) /* largest left first */
      for (int c = a + 1; c < n; c++)
        if (size[c] > size[a]) {
          double t = size[a];
          size[a] = size[c];
          size[c] = t;
        }
    for (int a = 0; a < n; a++) {
      int least = 0;
      for (int t = 1; t < threads; t++)
        if (load[t] < load[least]) least = t;
      load[least] += size[a];
      total += size[a];
    }
    double most = 0.0;
    for (int t = 0; t < threads; t++) most = load[t] > most ? load[t] : most;
    span += most;
  }
  return span > 0.0 ? total / span : 1.0;
}

static void domains_table(bench_ctx *b, int scene, const char *dir, FILE *data)
{
  static const char *const what[] = {"splines, pair off", "splines, pair on", "particles"};
  FILE *d = b->doc[BENCH_PERFORMANCE];
  int cores = (int)sysconf(_SC_NPROCESSORS_ONLN), n_th = 0, th[MAX_THREADS];
  for (int t = 1; t <= 16 && n_th < MAX_THREADS; t *= 2)
    if (t == 1 || t <= cores) th[n_th++] = t;
  char sub[LW_PATH_MAX];
  dom_run off, split;
  bench_note("domains: %s, unsplit", what[scene]);
  snprintf(sub, sizeof sub, "%s/off-%d", dir, scene);
  dom_start(&off, scene, "off", sub);
  bench_note("domains: %s, domains = auto", what[scene]);
  snprintf(sub, sizeof sub, "%s/auto-%d", dir, scene);
  dom_start(&split, scene, "auto", sub);
  lw_domains *dm = split.a.chain->domains;
  if (!dm || !(dm->cell_cpu = calloc((size_t)dm->n, sizeof *dm->cell_cpu))) {
    lw_error err = {.code = LW_EINPUT};
    snprintf(err.msg, sizeof err.msg, "domains = auto did not split the scene");
    bench_die("domains", &err);
  }
  const int reps = b->reps;
  double ns_off[BENCH_MAX_REPS], ms_off[BENCH_MAX_REPS];
  double ns[MAX_THREADS][BENCH_MAX_REPS], ms[MAX_THREADS][BENCH_MAX_REPS], est[MAX_THREADS][BENCH_MAX_REPS];
  for (int k = 0; k < reps; k++) {
    ns_off[k] = dom_block(&off, 1, b->block, &ms_off[k]);
    for (int i = 0; i < n_th; i++) {
      ns[i][k] = dom_block(&split, th[i], b->block, &ms[i][k]);
      /* the profile of a sweep on one thread: nothing shared with another */
      if (i == 0)
        for (int e = 0; e < n_th; e++) est[e][k] = profile_speedup(dm, th[e]);
    }
  }
  double frozen = dm->visits ? (double)dm->frozen / (double)dm->visits : 0.0;
  const lw_chain *c = split.a.chain;
  double outside = (double)proposed(c, 1) / (double)proposed(c, 0);
  double load = -1.0;
  FILE *la = fopen("/proc/loadavg", "r");
  if (la) {
    if (fscanf(la, "%lf", &load) != 1) load = -1.0;
    fclose(la);
  }
  static const char *const title[] = {"Local terms only (the pair term off)",
                                       "With the pair term (cutoff 4 mm, near field off)",
                                       "Oriented particles (" DOMAIN_PARTICLES_TEXT " on a noisy plane, every "
                                       "weighted term, T = 0.01; lengths in r0)"};
  fprintf(d, "%s: %d x %d domains of %.3g %s (reach %.2g %s), %.1f %% of site visits skipped (on a "
             "boundary), %.2f %% of proposals rejected for leaving their domain; set-up %.1f s; load average "
             "%.1f.\n\n",
          title[scene], dm->nx, dm->ny, dm->lx, scene == DOM_PARTICLES ? "r0" : "mm", dm->reach,
          scene == DOM_PARTICLES ? "r0" : "mm", 100.0 * frozen, 100.0 * outside, split.setup_s, load);
  fprintf(d, "| sweep | threads | ms per sweep | wall ns per proposal | speed-up over 1 thread | "
             "over the unsplit sweep | on dedicated cores, from the profile |\n|---|---|---|---|---|---|---|\n");
  double w[BENCH_MAX_REPS];
  memcpy(w, ms_off, sizeof w);
  double ms_o = bench_median(w, reps);
  memcpy(w, ns_off, sizeof w);
  fprintf(d, "| unsplit | 1 | %.0f | %.0f | | | |\n", ms_o, bench_median(w, reps));
  for (int i = 0; i < n_th; i++) {
    double q1[BENCH_MAX_REPS], qo[BENCH_MAX_REPS];
    for (int k = 0; k < reps; k++) {
      q1[k] = ns[0][k] / ns[i][k];
      qo[k] = ns_off[k] / ns[i][k];
    }
    memcpy(w, ms[i], sizeof w);
    double msm = bench_median(w, reps);
    memcpy(w, ns[i], sizeof w);
    double nsm = bench_median(w, reps);
    double s1 = bench_median(q1, reps), so = bench_median(qo, reps);
    fprintf(d, "| domains = auto | %d | %.0f | %.0f | %.2f | %.2f | %.2f |\n", th[i], msm, nsm, s1, so,
            bench_median(est[i], reps));
    fprintf(data, "%d %d %.1f %.4f %.4f\n", scene, th[i], nsm, s1, so);
  }
  fprintf(d, "\n");
  fprintf(data, "\n\n");
  lw_anneal_free(&off.a);
  lw_anneal_free(&split.a);
}

void bench_domains(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_PERFORMANCE];
  char dir[128];
  bench_scratch_dir(dir, sizeof dir, "domains");
  fprintf(d, "## Domains: one replica on every core\n\n"
             "The scaling section's scene at %d splines, annealed at constant T = 0.05 by lw_anneal with\n"
             "`[anneal] domains = auto` (docs/NUMERICS.md, \"Domains\"): each sweep shifts the lattice of\n"
             "domains at random and runs its four sub-lattices in turn, the domains of each in parallel.\n"
             "The result does not depend on the threads, so one run is timed with 1, 2, 4 ... threads\n"
             "in turn, block by block, beside the unsplit run (wall time, %d blocks of %.2g s or one\n"
             "sweep). A split sweep skips the splines that sit on a domain boundary, so the figure of\n"
             "merit is wall time per proposal made; ms per sweep is the sweep's wall time. On a loaded\n"
             "machine the wall-time columns measure the load as much as the scheme, so the last column\n"
             "gives the speed-up on as many dedicated cores from the one-thread sweeps' profile in thread\n"
             "CPU time (each cell's time, the serial plan and merges; cells largest first to the least\n"
             "loaded thread, phase by phase); it leaves out what threads share (memory bandwidth).\n\n",
          DOMAIN_SPLINES, b->reps, b->block);
  FILE *f = bench_data(b, "domains.dat");
  domains_table(b, DOM_LOCAL, dir, f);
  domains_table(b, DOM_PAIR, dir, f);
  domains_table(b, DOM_PARTICLES, dir, f);
  fclose(f);
  bench_scratch_remove(dir);
}
