/*
** test_anneal.c -- the Metropolis chain and whole runs: invariants of
** shared/DESIGN.md section 3, tuning, NaN handling, bit-exact resume.
*/
#include <criterion/criterion.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <time.h>
#include <unistd.h>

#include "linewise/anneal.h"
#include "linewise/init.h"
#include "linewise/mc.h"
#include "linewise/phase.h"
#include "linewise/rundir.h"
#include "testutil.h"

static lw_params every_term(void)
{
  lw_params p;
  lw_params_defaults(&p);
  p.width = 60;
  p.height = 50;
  p.margin = 2;
  p.strain = 5;
  p.bending = 0.5;
  p.potential_coef = 0.3;
  p.potential = LW_POT_RADIAL;
  p.field_coef = -0.2;
  p.field = LW_FLD_WAVES;
  p.pair = 0.05;
  p.pair_cutoff = 4;
  p.boundary_coef = 0.1;
  p.segments = 3;
  p.segment_length = 4;
  return p;
}

Test(anneal, incremental_energy_matches_recomputation_after_a_million_proposals)
{
  /* Invariant 1 of the design: every term on, 10^6 proposals of every kind
  ** at a temperature where about half are accepted. */
  lw_params p = every_term();
  p.strain_mode = LW_STRAIN_SEGMENT;
  lw_scene sc;
  lw_error err;
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_OK, "%s", err.msg);
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 2024);
  lw_splines *sp = lw_init_random(&sc, 40, 3, 4, r, &err);
  cr_assert_not_null(sp, "%s", err.msg);
  lw_model *m = lw_model_new(&sc, sp, &err);
  double w[LW_MOVE_KINDS] = {0.4, 0.4, 0.1, 0.1}, st[LW_MOVE_KINDS] = {0.3, 0.3, 0.3, 0.05},
         tg[LW_MOVE_KINDS] = {0.44, 0.44, 0.3, 0.3};
  lw_chain *c = model_chain(m, w, st, tg, 77, &err);
  c->temperature = 0.05;
  unsigned long acc = 0;
  const long N = 1000000;
  for (long k = 0; k < N; k++) {
    double u = gsl_rng_uniform(c->rng);
    int kind = 0;
    while (kind < LW_MOVE_KINDS - 1 && u >= c->cum_weight[kind]) kind++;
    acc += lw_chain_step(c, kind) == 1;
  }
  double term[LW_TERM_COUNT];
  double full = lw_energy_compute(&sc, m->sp, term, NULL);
  for (int t = 0; t < LW_TERM_COUNT; t++)
    cr_assert(fabs(m->term[t] - term[t]) <= 1e-9 * fmax(fabs(full), 1e-12),
              "%s: running %.17g, recomputed %.17g", lw_term_names[t], m->term[t], term[t]);
  cr_assert(fabs(lw_model_total(m) - full) <= 1e-9 * fabs(full));
  cr_assert(acc > N / 10 && acc < 9 * N / 10, "acceptance %lu of %ld is not a useful test", acc, N);
  cr_assert(lw_splines_finite(m->sp));
  model_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
  gsl_rng_free(r);
}

Test(anneal, pair_samples_at_their_own_nodes_keep_the_invariant)
{
  /* energy.pair_quadrature gives the pair term its own samples: the running
  ** totals must still match a recomputation, and the pair energy must be the
  ** one of those nodes (it differs from the 8-node value on bent curves). */
  lw_params p = every_term();
  p.pair_quadrature = 3;
  lw_scene sc, sc8;
  lw_error err;
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(sc.pair_quad.n, 3);
  cr_assert_eq(sc.quad.n, 8);
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 5);
  lw_splines *sp = lw_init_random(&sc, 40, 3, 4, r, &err);
  lw_model *m = lw_model_new(&sc, sp, &err);
  double w[LW_MOVE_KINDS] = {0.4, 0.4, 0.1, 0.1}, st[LW_MOVE_KINDS] = {0.3, 0.3, 0.3, 0.05},
         tg[LW_MOVE_KINDS] = {0.44, 0.44, 0.3, 0.3};
  lw_chain *c = model_chain(m, w, st, tg, 78, &err);
  c->temperature = 0.05;
  for (int k = 0; k < 200; k++) lw_chain_sweep(c);
  double term[LW_TERM_COUNT], term8[LW_TERM_COUNT];
  double full = lw_energy_compute(&sc, m->sp, term, NULL);
  for (int t = 0; t < LW_TERM_COUNT; t++)
    cr_assert(fabs(m->term[t] - term[t]) <= 1e-9 * fmax(fabs(full), 1e-12), "%s", lw_term_names[t]);
  p.pair_quadrature = 0;
  cr_assert_eq(lw_scene_init(&sc8, &p, &err), LW_OK);
  lw_energy_compute(&sc8, m->sp, term8, NULL);
  cr_assert(term[LW_TERM_PAIR] > 0 && fabs(term8[LW_TERM_PAIR] / term[LW_TERM_PAIR] - 1) > 1e-4,
            "pair energy with 3 nodes %.17g equals the 8-node one %.17g", term[LW_TERM_PAIR], term8[LW_TERM_PAIR]);
  cr_assert_eq(term8[LW_TERM_BENDING], term[LW_TERM_BENDING]);
  model_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
  lw_scene_clear(&sc8);
  gsl_rng_free(r);
}

Test(anneal, nan_proposals_are_rejected_and_counted)
{
  lw_params p = every_term();
  lw_scene sc;
  cr_assert_eq(lw_scene_init(&sc, &p, NULL), LW_OK);
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  lw_splines *sp = lw_init_random(&sc, 5, 3, 4, r, NULL);
  lw_model *m = lw_model_new(&sc, sp, NULL);
  double w[LW_MOVE_KINDS] = {1, 1, 1, 1}, st[LW_MOVE_KINDS] = {NAN, NAN, NAN, NAN}, tg[LW_MOVE_KINDS] = {.4, .4, .4, .4};
  lw_chain *c = model_chain(m, w, st, tg, 3, NULL);
  c->temperature = 1;
  double before = lw_model_total(m);
  lw_splines *copy = lw_splines_clone(m->sp);
  for (int k = 0; k < LW_MOVE_KINDS; k++)
    for (int n = 0; n < 50; n++) cr_assert_eq(lw_chain_step(c, (lw_move_kind)k), 0);
  for (int k = 0; k < LW_MOVE_KINDS; k++) {
    cr_assert_eq(c->stats[k].nan, 50, "%s: %lu NaN rejections", lw_move_names[k], c->stats[k].nan);
    cr_assert_eq(c->stats[k].accepted, 0);
  }
  cr_assert(!memcmp(copy->node, m->sp->node, copy->n_nodes * sizeof(lw_node)), "state changed");
  cr_assert_eq(lw_model_total(m), before);
  lw_splines_free(copy);
  model_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
  gsl_rng_free(r);
}

Test(anneal, steps_tune_toward_the_target_then_freeze)
{
  lw_params p = every_term();
  p.pair = 0; /* a fast scene */
  lw_scene sc;
  cr_assert_eq(lw_scene_init(&sc, &p, NULL), LW_OK);
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  lw_splines *sp = lw_init_random(&sc, 20, 3, 4, r, NULL);
  lw_model *m = lw_model_new(&sc, sp, NULL);
  double w[LW_MOVE_KINDS] = {1, 0, 0, 0}, st[LW_MOVE_KINDS] = {5, 5, 5, 1}, tg[LW_MOVE_KINDS] = {.44, .44, .3, .3};
  lw_chain *c = model_chain(m, w, st, tg, 9, NULL);
  c->temperature = 0.02;
  c->tuning = 1;
  for (int s = 0; s < 200; s++) lw_chain_sweep(c);
  cr_assert(c->step[LW_MOVE_POINT] < 5, "a 5 mm step at T=0.02 must shrink");
  /* frozen: acceptance near the target, and the step does not move */
  c->tuning = 0;
  double frozen = c->step[LW_MOVE_POINT];
  unsigned long p0 = c->stats[0].proposed, a0 = c->stats[0].accepted;
  for (int s = 0; s < 200; s++) lw_chain_sweep(c);
  double rate = (double)(c->stats[0].accepted - a0) / (double)(c->stats[0].proposed - p0);
  cr_assert_eq(c->step[LW_MOVE_POINT], frozen);
  /* The rate of a tuned step sits near 0.44; the band is wide because the
  ** energy landscape drifts as the scene cools into its minimum. */
  cr_assert(rate > 0.25 && rate < 0.65, "acceptance %.3f after tuning", rate);
  model_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
  gsl_rng_free(r);
}

Test(anneal, greedy_at_zero_temperature_never_raises_the_energy)
{
  lw_params p = every_term();
  lw_scene sc;
  cr_assert_eq(lw_scene_init(&sc, &p, NULL), LW_OK);
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  lw_splines *sp = lw_init_random(&sc, 10, 3, 4, r, NULL);
  lw_model *m = lw_model_new(&sc, sp, NULL);
  double w[LW_MOVE_KINDS] = {1, 1, 1, 1}, st[LW_MOVE_KINDS] = {.5, .5, .5, .1}, tg[LW_MOVE_KINDS] = {.4, .4, .4, .4};
  lw_chain *c = model_chain(m, w, st, tg, 5, NULL);
  c->temperature = 0;
  double e = lw_model_total(m);
  for (int s = 0; s < 50; s++) {
    lw_chain_sweep(c);
    double e2 = lw_model_total(m);
    cr_assert(e2 <= e + 1e-12 * fabs(e), "energy rose at T=0: %.17g -> %.17g", e, e2);
    e = e2;
  }
  model_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
  gsl_rng_free(r);
}

/* ---- whole runs through the binary ------------------------------------ */

static char dir[64];

static void make_dir(void) { cr_assert_eq(lw_test_dir_make(dir, "anneal"), 0); }
static void remove_dir(void) { cr_assert_eq(lw_test_dir_remove(dir), 0); }
#define sh lw_test_sh

static const char scene[] =
  "[scene]\nwidth = 60\nheight = 50\nmargin = 2\npotential = ramp\nfield = vortex\n"
  "[init]\nsplines = 12\nsegments = 3\nsegment_length = 4\n"
  "[energy]\nstrain = 5\nbending = 0.5\npotential = 0.2\nfield = -0.1\npair = 0.05\npair_cutoff = 4\nboundary = 0.1\n"
  "[anneal]\nschedule = adaptive\nt_start = 0.5\nt_end = 0.01\nsweeps = 120\nsteps = 6\nseed = 42\ncheck_every = 7\n"
  "[output]\ncheckpoint_every = 13\ntrace_every = 5\n";

TestSuite(run, .init = make_dir, .fini = remove_dir);

/* Writes dir/s.ini: the scene above, then extra (more [output] keys). */
static void write_scene(const char *extra, char *path, size_t n)
{
  snprintf(path, n, "%s/s.ini", dir);
  FILE *f = fopen(path, "w");
  cr_assert_not_null(f);
  fputs(scene, f);
  fputs(extra, f);
  fclose(f);
}

Test(run, resume_continues_bit_exactly)
{
  const char *b = getenv("LW_BIN");
  cr_assert_not_null(b);
  FILE *f = fopen(strcat(strcpy((char[128]){0}, dir), "/s.ini"), "w");
  fputs(scene, f);
  fclose(f);
  cr_assert_eq(sh("%s run %s/s.ini --out %s/a --quiet", b, dir, dir), 0);
  /* stopped mid-step and mid-tuning, then resumed twice */
  cr_assert_eq(sh("%s run %s/s.ini --out %s/b --quiet --stop-at 47", b, dir, dir), 0);
  cr_assert_eq(sh("%s resume %s/b --quiet --stop-at 90", b, dir), 0);
  cr_assert_eq(sh("%s resume %s/b --quiet", b, dir), 0);
  const char *same[] = {"state.lw", "trace.csv", "final.svg", "final.png", "scene.ini"};
  for (int i = 0; i < 5; i++)
    cr_assert_eq(sh("cmp -s %s/a/%s %s/b/%s", dir, same[i], dir, same[i]), 0, "%s differs", same[i]);
  /* the summary agrees with a recomputation from scratch */
  cr_assert_eq(sh("%s energy %s/a > %s/e.txt", b, dir, dir), 0);
  cr_assert_eq(sh("grep -q '\"max_relative_drift\"' %s/a/summary.json", dir), 0);
  char path[128];
  snprintf(path, sizeof path, "%s/e.txt", dir);
  f = fopen(path, "r");
  char name[32];
  double total = NAN, v;
  while (fscanf(f, "%31s %lf", name, &v) == 2)
    if (!strcmp(name, "total")) total = v;
  fclose(f);
  snprintf(path, sizeof path, "%s/a/summary.json", dir);
  f = fopen(path, "r");
  char line[256];
  double stotal = NAN;
  int in_energy = 0;
  while (fgets(line, sizeof line, f)) {
    if (strstr(line, "\"energy\": {")) in_energy = 1;
    if (in_energy && sscanf(line, " \"total\": %lf", &stotal) == 1) break;
  }
  fclose(f);
  cr_assert(isfinite(total) && fabs(total - stotal) <= 1e-9 * fabs(total), "energy %.17g vs summary %.17g", total, stotal);
  /* the end's recomputation is a drift measured too: a run shorter than
  ** check_every read 0, as if its running totals had been exact (these
  ** 120 sweeps of commits leave a few ulps, so 0 here would be the bug) */
  cr_assert_eq(sh("%s run %s/s.ini --out %s/c --quiet --set anneal.check_every=1000", b, dir, dir), 0);
  snprintf(path, sizeof path, "%s/c/summary.json", dir);
  f = fopen(path, "r");
  double drift = NAN;
  while (fgets(line, sizeof line, f))
    if (sscanf(line, " \"max_relative_drift\": %lf", &drift) == 1) break;
  fclose(f);
  cr_assert(drift > 0.0 && drift < 1e-12, "max_relative_drift %g", drift);
}

/* minimal.ini with `set` run whole into dir/a, and stopped after sweep
** `stop` and resumed into dir/b: whether their state.lw and trace.csv are
** the same bytes. */
static int resumes_as_it_ran(const char *set, int stop)
{
  const char *b = getenv("LW_BIN"), *root = getenv("LW_ROOT");
  cr_assert_eq(sh("%s run %s/params/minimal.ini --out %s/a %s", b, root, dir, set), 0);
  cr_assert_eq(sh("%s run %s/params/minimal.ini --out %s/b %s --stop-at %d && %s resume %s/b --quiet --threads 1", b,
                  root, dir, set, stop, b, dir), 0);
  return !sh("cmp -s %s/a/state.lw %s/b/state.lw && cmp -s %s/a/trace.csv %s/b/trace.csv", dir, dir, dir, dir);
}

/* Where a strain of 1e12 makes the running totals drift past what an early
** recomputation keeps (5e-9), when those come hangs on the largest sizes
** since the last: a resume that began them afresh skipped one the run which
** never stopped made, and its state, trace and max_drift went apart. */
Test(run, resume_keeps_the_recomputations_of_a_drifting_run)
{
  cr_assert(resumes_as_it_ran("--quiet --threads 1 --set anneal.sweeps=300 --set energy.strain=1e12 "
                              "--set anneal.check_every=1000", 137));
  cr_assert_eq(sh("grep -q '^max_drift = [1-9]' %s/a/state.lw", dir), 0, "no drift to keep: the case is gone");
}

/* A tempering run of many replicas resumes as it ran: its state.lw's lists
** (at_label, two counts a replica; ladder; size_peak) were read into 64
** places, and from 33 replicas on a run could not resume. */
Test(run, a_run_of_many_replicas_resumes_bit_exactly)
{
  cr_assert(resumes_as_it_ran("--quiet --threads 1 --set tempering.replicas=65 --set init.splines=2 "
                              "--set anneal.sweeps=20", 5));
}

/* anneal.delayed_acceptance changes a run only where the pair term has a
** near field: without one the chains are the same bit for bit; with one
** the two-stage test takes other decisions (both sample the same
** distribution: tests/test_stats.c). */
Test(run, delayed_acceptance_acts_on_the_near_field_only)
{
  const char *b = getenv("LW_BIN");
  char path[128];
  write_scene("", path, sizeof path);
  const char *off = "--set anneal.delayed_acceptance=0", *far = "--set energy.pair_near=0";
  cr_assert_eq(sh("%s run %s --out %s/a --quiet", b, path, dir), 0);
  cr_assert_eq(sh("%s run %s --out %s/b --quiet %s", b, path, dir, off), 0);
  cr_assert_eq(sh("%s run %s --out %s/c --quiet %s", b, path, dir, far), 0);
  cr_assert_eq(sh("%s run %s --out %s/d --quiet %s %s", b, path, dir, far, off), 0);
  cr_assert_neq(sh("cmp -s %s/a/trace.csv %s/b/trace.csv", dir, dir), 0, "the switch changed nothing");
  const char *same[] = {"trace.csv", "final.svg", "final.png"};
  for (int i = 0; i < 3; i++)
    cr_assert_eq(sh("cmp -s %s/c/%s %s/d/%s", dir, same[i], dir, same[i]), 0, "%s differs without a near field",
                 same[i]);
}

Test(run, bad_input_writes_nothing)
{
  const char *b = getenv("LW_BIN");
  char path[128];
  snprintf(path, sizeof path, "%s/bad.ini", dir);
  FILE *f = fopen(path, "w");
  fputs("[energy]\nbending = 1\n[anneal]\nschedule = sideways\n", f);
  fclose(f);
  cr_assert_eq(sh("%s run %s --out %s/out --quiet 2>%s/err.txt", b, path, dir, dir), 2);
  cr_assert_eq(sh("grep -q 'bad.ini:4: key .anneal.schedule.: expected one of constant|linear' %s/err.txt", dir), 0);
  cr_assert_neq(sh("test -e %s/out", dir), 0, "an output directory was created for bad input");
  cr_assert_eq(sh("%s run %s --out %s/out --set energy.pair=-2 2>%s/err.txt", b, path, dir, dir), 2);
  cr_assert_eq(sh("grep -q 'energy.pair' %s/err.txt", dir), 0);
  cr_assert_eq(sh("%s resume %s/nothing-here 2>%s/err.txt", b, dir, dir), 2);
  cr_assert_eq(sh("grep -q \"nothing-here': No such file or directory; expected the directory a run wrote\" %s/err.txt",
                  dir), 0);
  /* every move weight 0: the key set to 0 is named, and the system's other
  ** move keys (the chain's own check named neither file nor key) */
  cr_assert_eq(sh("%s run %s/params/minimal.ini --out %s/out --quiet --set moves.point=0 --set moves.vector=0 "
                  "--set moves.translate=0 --set moves.rotate=0 2>%s/err.txt", b, getenv("LW_ROOT"), dir, dir), 2);
  cr_assert_eq(sh("grep -qx \"linewise: --set: key 'moves.point': every move weight is 0 (moves.point, moves.vector, "
                  "moves.translate, moves.rotate): expected at least one above 0\" %s/err.txt", dir), 0, "%s",
               lw_test_slurp("%s/err.txt", dir));
  cr_assert_neq(sh("test -e %s/out", dir), 0, "an output directory was created for bad input");
}

/* A stop asked while a new run sets up, the run it replaces set aside: the
** new run, no sweep done, gives way and the run before is back byte for
** byte.  Asked once the first checkpoint is written, the new run stays. */
Test(run, a_stop_during_the_set_up_puts_the_run_before_back)
{
  const char *b = getenv("LW_BIN");
  char path[128], out[128];
  write_scene("", path, sizeof path);
  cr_assert_eq(sh("%s run %s --out %s/r --quiet --set anneal.sweeps=10 && cp -a %s/r %s/before", b, path, dir, dir,
                  dir), 0);
  lw_params p;
  lw_error err;
  cr_assert_eq(lw_params_read(&p, path, &err), LW_OK, "%s", err.msg);
  p.seed = 43;
  snprintf(out, sizeof out, "%s/r", dir);
  lw_anneal a;
  lw_phase_stop();
  cr_assert_eq(lw_anneal_start(&a, &p, out, &err), LW_ERUN, "the set-up went on: %s", err.msg);
  cr_assert(a.gave_way && strstr(err.msg, "stopped during the set-up"), "%s", err.msg);
  cr_assert_eq(lw_anneal_undo_start(&a), 1, "the run before did not all come back");
  lw_anneal_free(&a);
  cr_assert_eq(sh("rm -f %s/r/.lock %s/before/.lock && diff -r %s/r %s/before", dir, dir, dir, dir), 0);
  /* no run there to give way to: the stop leaves the new run whole */
  snprintf(out, sizeof out, "%s/fresh", dir);
  cr_assert_eq(lw_anneal_start(&a, &p, out, &err), LW_OK, "%s", err.msg);
  cr_assert(!a.gave_way);
  lw_anneal_free(&a);
  cr_assert_eq(sh("test -s %s/fresh/state.lw", dir), 0);
  /* a program that runs again after the stop clears it: the run then takes
  ** the place of the one before */
  lw_phase_stop_clear();
  snprintf(out, sizeof out, "%s/r", dir);
  cr_assert_eq(lw_anneal_start(&a, &p, out, &err), LW_OK, "%s", err.msg);
  cr_assert(!a.gave_way);
  lw_anneal_free(&a);
  cr_assert_eq(sh("grep -qx 'seed = 43' %s/r/state.lw", dir), 0, "the run before is still there");
  /* and, given up without a sweep, stands: the run it replaced, kept aside
  ** until a first sweep, went with the free (it stayed in r/.replaced) */
  cr_assert_eq(sh("test ! -e %s/r/.replaced", dir), 0, "the run it replaced is left aside");
}

/* A second signal ends the process at once and names the checkpoint a
** resume takes up: the one whose state.lw is committed, marked as its
** rename ends.  It was named after the replicas' files and timing.txt were
** written too, and a signal among those named the checkpoint before (the
** replica here fails to write, with state.lw of sweep 3 on disk). */
/* Starts the scene above with extra into dir/name. */
static void start_run(const char *extra, const char *name, lw_anneal *a)
{
  char path[128], out[128];
  write_scene(extra, path, sizeof path);
  static lw_params p;
  lw_error err;
  cr_assert_eq(lw_params_read(&p, path, &err), LW_OK, "%s", err.msg);
  snprintf(out, sizeof out, "%s/%s", dir, name);
  cr_assert_eq(lw_anneal_start(a, &p, out, &err), LW_OK, "%s", err.msg);
}

/* A program that embeds the library: the temperature is NAN until the first
** sweep sets it (it read 0 under t_start 0.5), and after lw_anneal_finish
** a sweep, a checkpoint or a second finish are refused (a sweep went on
** from the quenched state to sweep 21 of 20, and a second finish drew the
** files again) */
Test(run, a_finished_run_takes_no_more_sweeps)
{
  lw_anneal a;
  lw_error err;
  start_run("[anneal]\nquench = bfgs\n", "f", &a);
  cr_assert(isnan(lw_anneal_temperature(&a)), "%g", lw_anneal_temperature(&a));
  while (!lw_anneal_done(&a)) cr_assert_eq(lw_anneal_sweep(&a, &err), LW_OK, "%s", err.msg);
  cr_assert(lw_anneal_temperature(&a) > 0.0);
  cr_assert_eq(lw_anneal_finish(&a, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(sh("cp %s/f/state.lw %s/f.lw", dir, dir), 0);
  const long sweep = a.sweep;
  cr_assert_eq(lw_anneal_sweep(&a, &err), LW_EUSAGE);
  cr_assert(strstr(err.msg, "lw_anneal_sweep: the run in ") && strstr(err.msg, "has finished"), "%s", err.msg);
  cr_assert_eq(lw_anneal_checkpoint(&a, &err), LW_EUSAGE);
  cr_assert_eq(lw_anneal_finish(&a, &err), LW_EUSAGE);
  cr_assert_eq(a.sweep, sweep);
  cr_assert_eq(sh("cmp -s %s/f/state.lw %s/f.lw", dir, dir), 0, "state.lw keeps the annealed state");
  lw_anneal_free(&a);
}

Test(run, a_checkpoint_is_marked_committed_as_state_lw_is)
{
  lw_anneal a;
  lw_error err;
  start_run("[tempering]\nreplicas = 2\n", "c", &a);
  long pending;
  cr_assert_eq(lw_phase_last_commit(&pending), 0);
  cr_assert_eq(pending, -1);
  for (int k = 0; k < 3; k++) cr_assert_eq(lw_anneal_sweep(&a, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(sh("mkdir %s/c/replica-1.lw.tmp", dir), 0);
  cr_assert_neq(lw_anneal_checkpoint(&a, &err), LW_OK, "the replica's file was written");
  cr_assert_eq(lw_phase_last_commit(&pending), a.sweep);
  cr_assert_eq(pending, -1, "the commit is marked as under way after it ended");
  cr_assert_eq(sh("grep -q '^sweep = %ld$' %s/c/state.lw", a.sweep, dir), 0);
  /* a commit that fails (state.lw a folder, so the rename cannot replace
  ** it) leaves the mark at the last one made, not at this sweep */
  const long committed = a.sweep;
  cr_assert_eq(sh("rmdir %s/c/replica-1.lw.tmp && rm %s/c/state.lw && mkdir -p %s/c/state.lw/x", dir, dir, dir), 0);
  cr_assert_eq(lw_anneal_sweep(&a, &err), LW_OK, "%s", err.msg);
  cr_assert_neq(lw_anneal_checkpoint(&a, &err), LW_OK, "state.lw was replaced");
  cr_assert_eq(lw_phase_last_commit(&pending), committed, "a failed commit was marked");
  cr_assert_eq(pending, -1);
  lw_anneal_free(&a);
}

/* A disk full for a moment cut a trace row, whose stream kept the error
** while a later flush succeeded: the checkpoint counted the damaged rows,
** and the run ended 0 with a trace.csv that stats refused.  The checkpoint
** now fails, and a resume goes on from the one before. */
Test(run, a_trace_row_lost_to_a_full_disk_fails_the_checkpoint)
{
  lw_anneal a;
  lw_error err;
  start_run("", "t", &a);
  int fd = fileno(a.trace), keep = dup(fd), full = open("/dev/full", O_WRONLY);
  cr_assert(keep >= 0 && full >= 0);
  cr_assert_eq(dup2(full, fd), fd);
  for (int k = 0; k < 200; k++) fprintf(a.trace, "%d,a row that the full disk takes no byte of\n", k);
  fflush(a.trace);
  cr_assert_eq(dup2(keep, fd), fd);
  close(full);
  close(keep);
  cr_assert_eq(lw_anneal_checkpoint(&a, &err), LW_EIO, "the checkpoint counted a damaged trace");
  cr_assert(strstr(err.msg, "trace.csv: write failed"), "%s", err.msg);
  lw_anneal_free(&a);
}

/* Frames are extra files: a run that writes them (and a PDF) leaves the
** same state, trace and drawings as one that does not, and a stopped and
** resumed run writes the same frames.  The first is the start (a film of
** the whip began at sweep 5, already swinging). */
Test(run, frames_and_pdf_change_nothing_else)
{
  const char *b = getenv("LW_BIN");
  char path[128];
  write_scene("", path, sizeof path);
  const char *extra = "--set output.frames_every=40 --set output.pdf=1";
  cr_assert_eq(sh("%s run %s --out %s/a --quiet", b, path, dir), 0);
  cr_assert_eq(sh("%s run %s --out %s/c --quiet %s", b, path, dir, extra), 0);
  cr_assert_eq(sh("%s run %s --out %s/d --quiet --stop-at 47 %s", b, path, dir, extra), 0);
  cr_assert_eq(sh("%s resume %s/d --quiet", b, dir), 0);
  const char *same[] = {"state.lw", "trace.csv", "final.svg", "final.png"};
  for (int i = 0; i < 4; i++)
    cr_assert_eq(sh("cmp -s %s/a/%s %s/c/%s", dir, same[i], dir, same[i]), 0, "%s differs", same[i]);
  const char *frames[] = {"frame-000000.png", "frame-000040.png", "frame-000080.png", "frame-000120.png"};
  for (int i = 0; i < 4; i++)
    cr_assert_eq(sh("cmp -s %s/c/frames/%s %s/d/frames/%s", dir, frames[i], dir, frames[i]), 0, "%s", frames[i]);
  cr_assert_eq(sh("ls %s/c/frames | wc -l | grep -qx 4", dir), 0, "four frames");
  cr_assert_eq(sh("cmp -s %s/c/final.pdf %s/d/final.pdf && head -c 5 %s/c/final.pdf | grep -q '%%PDF-'", dir, dir, dir),
               0);
  cr_assert_neq(sh("test -e %s/a/final.pdf", dir), 0, "no PDF unless asked");
  /* timing.txt counts the drawing too: written after summary.json, never
  ** less (it held the last checkpoint's, before the drawing) */
  cr_assert_eq(sh("awk -F': ' '/\"wall_seconds\"/ { s = $2 + 0 } END { print s }' %s/c/summary.json > %s/sw && "
                  "awk -v s=\"$(cat %s/sw)\" '/^wall_seconds/ { ok = $2 >= s - 1e-6 } END { exit !ok }' "
                  "%s/c/timing.txt", dir, dir, dir, dir), 0);
  /* the summary reports the pen-up travel, ordered no longer than before */
  snprintf(path, sizeof path, "%s/c/summary.json", dir);
  FILE *f = fopen(path, "r");
  char line[256];
  double before = NAN, after = NAN;
  while (fgets(line, sizeof line, f)) {
    sscanf(line, " \"before\": %lf", &before);
    sscanf(line, " \"after\": %lf", &after);
  }
  fclose(f);
  cr_assert(isfinite(before) && isfinite(after) && after <= before && after > 0, "travel %g -> %g", before, after);
}

/* Pens from the scene file: layers in final.svg; a bad colour list stops
** the run before anything is written. */
Test(run, pens_become_layers)
{
  const char *b = getenv("LW_BIN");
  char path[128];
  write_scene("pens = 2\npen_colors = #000 #c00\npen_width = 0.5\n", path, sizeof path);
  cr_assert_eq(sh("%s run %s --out %s/p --quiet --set anneal.sweeps=5", b, path, dir), 0);
  cr_assert_eq(sh("grep -c 'inkscape:groupmode=\"layer\"' %s/p/final.svg | grep -qx 2", dir), 0);
  cr_assert_eq(sh("grep -q 'inkscape:label=\"2 pen\" id=\"pen2\"' %s/p/final.svg", dir), 0);
  cr_assert_eq(sh("grep -q 'stroke=\"#cc0000\"' %s/p/final.svg", dir), 0);
  cr_assert_eq(sh("%s run %s --out %s/q --quiet --set output.pens=3 2>%s/err.txt", b, path, dir, dir), 2);
  cr_assert_eq(sh("grep -q 's.ini:31: key .output.pen_colors.: expected 3 colours' %s/err.txt", dir), 0);
  cr_assert_neq(sh("test -e %s/q", dir), 0);
}

/* Checkpoints that take over a third of the run (and a second) are said at
** the end: a small system's study fsync'd state.lw every 100 sweeps and
** took 8 s instead of 1, without a word.  The note reads this process's
** clock (CLOCK_MONOTONIC, as anneal.c's) and the time its checkpoints took,
** the longest as long as the others on average. */
Test(anneal, checkpoints_that_take_most_of_a_run_are_said)
{
  static lw_anneal a;
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  a.wall_start = (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec - 10.0;
  a.params.checkpoint_every = 100;
  a.end_sweep = 1000;
  char note[256];
  a.ckpt_seconds = 5.0;
  a.ckpt_count = 10;
  a.ckpt_longest = 0.6;
  lw_anneal_checkpoint_note(&a, note, sizeof note);
  cr_assert(strstr(note, "writing state.lw every 100 sweeps (output.checkpoint_every) took over a third of this run's "
                   "time"), "%s", note);
  a.ckpt_seconds = 6.0;
  lw_anneal_checkpoint_note(&a, note, sizeof note);
  cr_assert(strstr(note, "took most of this run's time"), "%s", note);
  /* one write the process was stopped during (SIGSTOP, a batch system's
  ** suspend) is not the checkpoints' cost: 9 of 10 took 0.05 s */
  a.ckpt_longest = 5.55;
  lw_anneal_checkpoint_note(&a, note, sizeof note);
  cr_assert_str_eq(note, "");
  /* writes whose times vary (a loaded or network disk): their sum is the
  ** cost (the fastest one's times the count hid it) */
  a.ckpt_seconds = 9.0;
  a.ckpt_count = 1500;
  a.ckpt_longest = 0.3;
  lw_anneal_checkpoint_note(&a, note, sizeof note);
  cr_assert(strstr(note, "took most of this run's time"), "%s", note);
  a.ckpt_count = 10;
  a.ckpt_seconds = 6.0;
  a.ckpt_longest = 0.6;
  /* a run with no checkpoint between its first and last: the key is not
  ** what to change (256 rungs' replica files, each synced, were) */
  a.end_sweep = 20;
  a.n_rep = 256;
  lw_anneal_checkpoint_note(&a, note, sizeof note);
  cr_assert(strstr(note, "writing state.lw at the start and the end took most of this run's time (it and a "
                   "replica-K.lw for each rung") && !strstr(note, "checkpoint_every"), "%s", note);
  a.ckpt_seconds = 3.0; /* under a third */
  lw_anneal_checkpoint_note(&a, note, sizeof note);
  cr_assert_str_eq(note, "");
  a.wall_start += 9.5; /* a run of half a second: 0.4 s of checkpoints is no matter */
  a.ckpt_seconds = 0.4;
  lw_anneal_checkpoint_note(&a, note, sizeof note);
  cr_assert_str_eq(note, "");
}

/* Frames and samples as checkpoints: a frame a sweep of a small scene made
** a 0.3-second run take 2 minutes, unsaid.  The note names the key of each
** that took a quarter of their time or more. */
Test(anneal, frames_that_take_most_of_a_run_are_said)
{
  static lw_anneal a;
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  a.wall_start = (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec - 10.0;
  a.params.frames_every = 7;
  a.params.samples_every = 3;
  char note[512];
  a.film_seconds[0] = 8.0;
  a.film_seconds[1] = 0.5;
  lw_anneal_film_note(&a, note, sizeof note);
  cr_assert(strstr(note, "writing a frame every 7 sweeps (output.frames_every) took 80 % of this run's time: a "
                   "larger value costs less") && !strstr(note, "samples_every"), "%s", note);
  a.film_seconds[0] = 2.0;
  a.film_seconds[1] = 2.0;
  lw_anneal_film_note(&a, note, sizeof note);
  cr_assert(strstr(note, "frame every 7 sweeps (output.frames_every) took 20 %, writing a sample every 3 sweeps "
                   "(output.samples_every) took 20 % of this run's time"), "%s", note);
  a.film_seconds[1] = 1.0; /* together under a third */
  lw_anneal_film_note(&a, note, sizeof note);
  cr_assert_str_eq(note, "");
  a.params.frames_every = 1;
  a.film_seconds[0] = 8.0;
  lw_anneal_film_note(&a, note, sizeof note);
  cr_assert(strstr(note, "writing a frame every sweep (output.frames_every) took 80 %"), "%s", note);
}

/* The frames still to come, at the newest frame's size, against the disk's
** free space (a warning) or over 1 GB (a note); a run with frames that fit
** says nothing.  Sparse frame files stand in for large ones. */
Test(anneal, frames_that_fill_the_disk_are_foretold, .init = make_dir, .fini = remove_dir)
{
  static lw_anneal a;
  snprintf(a.dir, sizeof a.dir, "%s", dir);
  a.params.frames_every = 7;
  a.end_sweep = 50;
  a.pause_at = -1;
  char path[256], note[512];
  snprintf(path, sizeof path, "%s/frames", dir);
  cr_assert_eq(mkdir(path, 0755), 0);
  const unsigned char png[24] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
                                 0, 0, 1, 0, 0, 0, 1, 0};
  const struct {
    long sweep, at, bytes;
    double frames;
  } c[] = {{0, 0, 200000000, 8}, {14, 14, 100000000, 6}, {49, 49, 3000000000, 1}, {0, 0, 1000000, 8}};
  struct statvfs fs;
  for (size_t k = 0; k < sizeof c / sizeof c[0]; k++) {
    snprintf(path, sizeof path, "%s/frames/frame-%06ld.png", dir, c[k].at);
    FILE *f = fopen(path, "wb");
    cr_assert(f && fwrite(png, 1, sizeof png, f) == sizeof png && !fseek(f, c[k].bytes - 1, SEEK_SET) &&
              fputc(0, f) == 0 && !fclose(f));
    a.sweep = c[k].sweep;
    int warning;
    lw_anneal_frames_disk_note(&a, note, sizeof note, &warning);
    cr_assert_eq(statvfs(path, &fs), 0);
    const double need = c[k].frames * (double)c[k].bytes, free = (double)fs.f_bavail * (double)fs.f_frsize;
    cr_assert_eq(warning, need > free, "%s", note);
    if (need > 1e9 || need > free) {
      char want[128];
      snprintf(want, sizeof want, "the %.0f frames still to come (output.frames_every = 7) take about", c[k].frames);
      cr_assert(strstr(note, want) && strstr(note, path + strlen(dir) + 8), "%s", note);
    } else
      cr_assert_str_eq(note, "");
    cr_assert_eq(unlink(path), 0);
  }
  a.sweep = 50; /* none to come */
  lw_anneal_frames_disk_note(&a, note, sizeof note, &(int){0});
  cr_assert_str_eq(note, "");
}

/* A row whose commits do not add up its moves' dE is said at the end: the
** driver measured the drift at every check (max_relative_drift) and said
** nothing, so a new system row with a running sum of 1.01 dE ran to its
** end with a 1.5e-2 drift and exit 0.  Here the running terms are put 1 %
** off by hand, as such a row leaves them; the recomputation at the next
** check finds it (7.4e-4 of the terms' magnitudes, which partly cancel;
** within 1e-4 to 1e-2 for any seed).  An ordinary run says nothing. */
Test(run, a_running_energy_that_does_not_add_up_is_said)
{
  char path[128];
  cr_assert_eq(lw_test_write_text(dir, "s.ini", scene), 0);
  snprintf(path, sizeof path, "%s/s.ini", dir);
  lw_params p;
  lw_error err;
  cr_assert_eq(lw_params_read(&p, path, &err), LW_OK, "%s", err.msg);
  p.sweeps = 20;
  char note[512];
  for (int off = 0; off < 2; off++) {
    lw_anneal a;
    snprintf(path, sizeof path, "%s/r%d", dir, off);
    cr_assert_eq(lw_anneal_start(&a, &p, path, &err), LW_OK, "%s", err.msg);
    for (int s = 0; !lw_anneal_done(&a); s++) {
      if (off && s == 10) {
        double v[LW_SYSTEM_TERMS_MAX];
        a.sys_type->terms(a.sys->state, v);
        for (int t = 0; t < a.sys_type->n_terms; t++) v[t] *= 1.01;
        a.sys_type->set_terms(a.sys->state, v);
      }
      cr_assert_eq(lw_anneal_sweep(&a, &err), LW_OK, "%s", err.msg);
    }
    lw_anneal_drift_note(&a, note, sizeof note);
    const char *was = strstr(note, "the running energy was ");
    const double by = was ? strtod(was + strlen("the running energy was "), NULL) : 0.0;
    if (off)
      cr_assert(by > 1e-4 && by < 1e-2 && strstr(note, "splines system"), "%s", note);
    else
      cr_assert_str_eq(note, "", "an ordinary run: %s", note);
    lw_anneal_free(&a);
  }
}

/* The adaptive rule's step is the one the block's energies ask for: each
** block's sample standard deviation (n - 1) of the total, recomputed from a
** trace of every sweep (no tuning sweeps, which the rule leaves out), gives
** the next block's temperature T exp(-lambda T / sd) to the trace's ten
** digits (1e-8; the rule's own tests took the block's statistics as given,
** and an sd over n, 9 % colder steps, went by). */
Test(run, the_adaptive_rule_steps_by_each_blocks_own_spread)
{
  const char *b = getenv("LW_BIN");
  char path[128];
  write_scene("", path, sizeof path);
  cr_assert_eq(sh("%s run %s --out %s/a --quiet --set output.trace_every=1 --set moves.tune_sweeps=0 --set "
                  "anneal.t_end=0.0001", b, path, dir), 0);
  cr_assert_eq(sh("awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == \"total\") c = i; next } "
                  "{ k = int(($1 - 1) / 20); if (k != cur && n) { sd[cur] = sqrt((q - s * s / n) / (n - 1)); "
                  "n = s = q = 0 } cur = k; n++; s += $c; q += $c * $c; t[k] = $2 } "
                  "END { for (k = 0; k < 5; k++) { w = t[k] * exp(-0.7 * t[k] / sd[k]); if (w < 0.0001) w = 0.0001; "
                  "r = t[k + 1] / w - 1; if (!(r < 1e-8 && r > -1e-8)) { print k, t[k + 1], w; bad++ } } "
                  "exit !(c && bad == 0) }' %s/a/trace.csv > %s/bad.txt", dir, dir), 0, "%s",
               lw_test_slurp("%s/bad.txt", dir));
}

/* The same where the energy is large and its spread tiny: a wire of energy
** 3220 at T = 1e-5 and below spreads by 1e-5 to 1e-7, and the energies'
** sums of squares lost it to rounding (a negative variance read at the
** second step, the geometric ratio taken; then steps cooled by 0.2 % where
** the spread asked for 30 %).  The rule sums each step's energies less its
** first; the trace's 17 digits give the spread two-pass here. */
Test(run, the_adaptive_rule_reads_a_tiny_spread_of_a_large_energy)
{
  cr_assert_eq(lw_test_write_text(dir, "wire.ini", "[scene]\nsystem = nurbs\n[nurbs]\norder = 4\n"
        "points = -5 5  -4.17 5  -2.5 5  0 5  2.5 5  4.17 5  5 5\n"
        "weights = 1 1 1 1 1 1 1\nknots = 0 0 0 0 0.25 0.5 0.75 1 1 1 1\nalpha = 35\nbeta = 10\ngauss = 10\nfixed = 1\n"
        "[dynamics]\nrho = 30\ngravity_y = -9.8\n[anneal]\nschedule = adaptive\nt_start = 1e-5\nt_end = 1e-12\n"
        "steps = 10\nsweeps = 4000\nlambda = 0.7\nseed = 1\n[moves]\ntune_sweeps = 50\n[output]\n"
        "trace_every = 1\n"), 0);
  cr_assert_eq(sh("%s run %s/wire.ini --out %s/w --quiet", getenv("LW_BIN"), dir, dir), 0);
  cr_assert_eq(sh("awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == \"total\") c = i; next } "
                  "{ k = int(($1 - 1) / 400); t[k] = $2; if (($1 - 1) %% 400 >= 50) e[k, n[k]++] = $c } "
                  "END { for (k = 0; k < 9; k++) { m = 0; for (i = 0; i < n[k]; i++) m += e[k, i]; m /= n[k]; "
                  "q = 0; for (i = 0; i < n[k]; i++) q += (e[k, i] - m) ^ 2; sd = sqrt(q / (n[k] - 1)); "
                  "w = t[k] * exp(-0.7 * t[k] / sd); r = t[k + 1] / w - 1; print k, t[k], sd, t[k + 1], w; "
                  "if (!(r < 1e-6 && r > -1e-6) || (k >= 2 && !(t[k + 1] < 0.9 * t[k]))) bad++ } "
                  "exit !(c && n[8] == 350 && !bad) }' "
                  "%s/w/trace.csv > %s/steps.txt", dir, dir), 0, "%s", lw_test_slurp("%s/steps.txt", dir));
}

/* With more steps than sweeps some steps have no sweep; each still takes its
** turn of the adaptive rule, unmeasured (the geometric ratio): the rule
** cooled one ratio per sweep instead, and ended 12 times above the step it
** reached.  Every row's temperature is the geometric schedule's, to the
** rounding of a product of up to 25 ratios against a power (1e-12). */
Test(run, an_adaptive_schedule_takes_every_step_it_skips)
{
  const char *b = getenv("LW_BIN");
  char path[128];
  write_scene("", path, sizeof path);
  static const char *const sched[] = {"adaptive", "geometric"};
  for (int k = 0; k < 2; k++)
    cr_assert_eq(sh("%s run %s --out %s/%s --quiet --set anneal.schedule=%s --set anneal.sweeps=10 --set "
                    "anneal.steps=25 --set output.trace_every=1 && cut -d, -f2 %s/%s/trace.csv > %s/%s.txt", b, path,
                    dir, sched[k], sched[k], dir, sched[k], dir, sched[k]), 0);
  cr_assert_eq(sh("cd %s && paste adaptive.txt geometric.txt | awk 'NR > 1 { n++; r = $1 / $2 - 1; if (r > 1e-12 || "
                  "r < -1e-12) bad++ } END { exit !(n == 10 && bad == 0) }'", dir), 0,
               "%s", lw_test_slurp("%s/adaptive.txt", dir));
}

/* Once every line has died, a death, grow or shrink (or any move) has no
** line to act on: no proposal, counted nowhere.  Each was counted a
** rejection, so a page whose lines all died read acc_death 0.000000 in
** every later row and a death acceptance of 0.32 where 428 of 440 were
** taken.  The rows with no line left have every acceptance empty. */
Test(run, a_move_with_no_line_left_is_no_proposal)
{
  const char *b = getenv("LW_BIN");
  /* with split and join too (a join needs two lines) */
  for (int splice = 0; splice < 2; splice++) {
    cr_assert_eq(sh("%s run %s/params/minimal.ini --out %s/die%d --threads 1 --set moves.fixed_count=0 --set "
                    "energy.chem_spline=1000 --set moves.birth_spread=0.5 --set anneal.sweeps=100 --set "
                    "output.observables=1 %s 2>%s/die.txt", b, lw_test_root(), dir, splice,
                    splice ? "--set moves.split=0.2 --set moves.join=0.2" : "", dir), 0);
    /* and the empty drawing names the price that emptied it (it blamed energy.potential) */
    cr_assert_eq(sh("grep -qF 'the anneal removed every one, the price of line (energy.chem_spline 1000) being "
                    "more than' %s/die.txt", dir), 0, "%s", lw_test_slurp("%s/die.txt", dir));
    /* every acc_ column but a birth's (it is refused, counted) empty in the
    ** rows after the one of the sweep where the last line died (which has
    ** its earlier moves) */
    cr_assert_eq(sh("awk -F, 'NR == 1 { for (k = 1; k <= NF; k++) { if ($k == \"obs_count\") c = k; if ($k ~ /^acc_/ "
                    "&& $k != \"acc_birth\") acc[++na] = k } } NR > 2 && $c == 0 && last == 0 { n++; for (j = 1; j <= "
                    "na; j++) if ($acc[j] != \"\") bad++ } NR > 1 { last = $c } END { exit !(c && na >= %d && n >= 20 "
                    "&& !bad) }' %s/die%d/trace.csv", splice ? 9 : 7, dir, splice), 0, "%s",
                 lw_test_slurp("%s/die%d/trace.csv", dir, splice));
  }
}

/* A cap on the segments below the count the placed splines start with was
** raised to it without a word, and lines grew past the cap the scene set,
** with init.from too (births start at init.segments).  An unset cap, 16,
** gives way to a larger init.segments, as does the 16 a run's scene.ini
** writes (a run of that file must not be refused, and gets no note of a key
** it never set); an explicit 16 was taken for the default and raised
** without a word, where 17 was refused. */
Test(run, a_segment_cap_below_the_placed_count_is_refused)
{
  const char *b = getenv("LW_BIN");
  cr_assert_eq(sh("%s run %s/params/minimal.ini --out %s/cap --quiet --set moves.fixed_count=0 --set "
                  "moves.max_segments=3 2>%s/cap.txt; test $? -eq 2 && grep -qF \"key 'moves.max_segments': expected "
                  "at least init.segments = 4, the count placed and born splines start with, got 3\" %s/cap.txt && "
                  "! test -e %s/cap", b, lw_test_root(), dir, dir, dir, dir), 0);
  cr_assert_eq(sh("%s run %s/params/minimal.ini --out %s/cap --quiet --set moves.fixed_count=0 --set init.segments=20 "
                  "--set init.segment_length=1.5 --set anneal.sweeps=2 && %s run %s/cap/scene.ini --out %s/cap2 "
                  "--quiet && %s run %s/cap/scene.ini --out %s/cap3 --set moves.fixed_count=1 2>%s/cap.txt && "
                  "! grep -q 'no effect.*max_segments' %s/cap.txt", b, lw_test_root(), dir, b, dir, dir, b, dir, dir,
                  dir, dir), 0);
  cr_assert_eq(sh("%s run %s/params/minimal.ini --out %s/cap16 --quiet --set moves.fixed_count=0 --set "
                  "init.segments=20 --set init.segment_length=1.5 --set moves.max_segments=16 2>%s/cap.txt; test $? "
                  "-eq 2 && grep -qF 'expected at least init.segments = 20' %s/cap.txt && ! test -e %s/cap16", b,
                  lw_test_root(), dir, dir, dir, dir), 0);
  cr_assert_eq(sh("%s run %s/params/minimal.ini --out %s/from --quiet --set moves.fixed_count=0 --set "
                  "moves.max_segments=3 --set init.from=%s/cap/state.lw --set anneal.sweeps=0 2>%s/cap.txt; "
                  "test $? -eq 2 && grep -qF 'got 3' %s/cap.txt", b, lw_test_root(), dir, dir, dir, dir), 0);
}

/* Splines that die, then longer ones born into their room: the node arrays
** had room, the segments' owners did not (lw_splines_new sized them by its
** segments, and every renumbering, anneal.check_every, and every resume made
** the splines anew), and this ideal gas of births of 1 to 3 segments aborted
** with "realloc(): invalid next size" at sweep 2568 (a heap overflow, found
** by a helper's statistics of the moves).  It runs to its end, and the
** splines' own test (transdim) checks the room under AddressSanitizer. */
Test(run, births_longer_than_the_dead_stay_in_the_arrays)
{
  char path[128];
  snprintf(path, sizeof path, "%s/gas.ini", dir);
  FILE *f = fopen(path, "w");
  cr_assert_not_null(f);
  fputs("[scene]\nwidth = 60\nheight = 40\n[init]\nsplines = 3\nsegments = 2\nsegment_length = 5\n[energy]\n"
        "min_speed = 0\nregularity = 0\nchem_spline = -0.6931471805599453\n[moves]\nfixed_count = 0\npoint = 0\n"
        "vector = 0\ntranslate = 0\nrotate = 0\nbirth = 1\ndeath = 1\ngrow = 0\nshrink = 0\nbirth_spread = 0.3\n"
        "max_segments = 3\n[anneal]\nschedule = constant\nt_start = 1\nt_end = 1\nsweeps = 6000\nseed = 9\n", f);
  cr_assert_eq(fclose(f), 0);
  cr_assert_eq(sh("%s run %s/gas.ini --out %s/gas --quiet && grep -q '\"sweeps\": 6000' %s/gas/summary.json",
                  getenv("LW_BIN"), dir, dir, dir), 0);
}

static int compare_ulong(const void *a, const void *b)
{
  const unsigned long x = *(const unsigned long *)a, y = *(const unsigned long *)b;
  return (x > y) - (x < y);
}

/* Distinct seeds draw distinct numbers: every stream of a run (placement,
** chain, exchanges, 255 more rungs) of every seed in a window of 3000 gets
** its own generator seed, at both ends of the seed's range (GSL seeds 0 as
** 4357, so they count as one).  Under the seeding of runs begun before
** 2026-12-06, seeds 89483 and 106945 drew the same chain; it is kept for
** them (version 1), and a scene.ini such a run wrote, without the key,
** takes it. */
Test(run, distinct_seeds_never_share_a_streams_numbers)
{
  enum { SEEDS = 3000, STREAMS = 2 + LW_TEMPERING_MAX };
  unsigned long *g = malloc(sizeof *g * SEEDS * STREAMS);
  cr_assert_not_null(g);
  static const unsigned long from[] = {0, 4294967295ul - SEEDS + 1, 2000000000ul};
  for (size_t w = 0; w < sizeof from / sizeof *from; w++) {
    size_t n = 0;
    for (unsigned long s = from[w]; s < from[w] + SEEDS; s++)
      for (unsigned long k = 0; k < STREAMS; k++) {
        const unsigned long v = lw_stream_seed(s, k, 2);
        g[n++] = v ? v : 4357;
      }
    qsort(g, n, sizeof *g, compare_ulong);
    size_t same = 0;
    for (size_t i = 1; i < n; i++) same += g[i] == g[i - 1];
    cr_expect_eq(same, 0, "seeds from %lu: %zu generator seeds shared", from[w], same);
  }
  free(g);
  cr_expect_eq(lw_stream_seed(89483, 1, 1), lw_stream_seed(106945, 1, 1), "version 1 is not the old seeding");
  cr_expect_neq(lw_stream_seed(89483, 1, 2), lw_stream_seed(106945, 1, 2));
  static const struct {
    const char *text;
    int version;
  } file[] = {
      {LW_RUN_SCENE_HEADER "\n[anneal]\nseed = 5\n", 1},
      {LW_RUN_SCENE_HEADER "\n[anneal]\nseed = 5\nseed_version = 2\n", 2},
      {"[anneal]\nseed = 5\n", 2},
      /* a published scene.ini annotated above its header, or saved with a BOM */
      {"; data of Smith et al.\n\n" LW_RUN_SCENE_HEADER "\n[anneal]\nseed = 5\n", 1},
      {"\xEF\xBB\xBF" LW_RUN_SCENE_HEADER "\r\n[anneal]\r\nseed = 5\r\n", 1},
      /* the header below a section is a comment of the scene's own */
      {"[anneal]\n" LW_RUN_SCENE_HEADER "\nseed = 5\n", 2},
  };
  for (size_t k = 0; k < sizeof file / sizeof *file; k++) {
    char path[128];
    cr_assert_eq(lw_test_write_text(dir, "v.ini", file[k].text), 0);
    snprintf(path, sizeof path, "%s/v.ini", dir);
    lw_params p;
    lw_error err;
    cr_assert_eq(lw_params_read(&p, path, &err), LW_OK, "%s", err.msg);
    cr_expect_eq(p.seed_version, file[k].version, "%s", file[k].text);
  }
}
