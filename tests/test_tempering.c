/*
** test_tempering.c -- exchanges, round trips, ladder tuning, and whole
** tempering runs: thread-count independence and bit-exact resume.
**
** The statistical tests use a system whose energy distribution is known:
** d independent harmonic degrees of freedom, E = sum x_i^2 / 2.  At
** temperature T, E follows a Gamma distribution of shape d/2 and scale T.
*/
#include <criterion/criterion.h>
#include <gsl/gsl_cdf.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_sf_gamma.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/anneal.h"
#include "linewise/tempering.h"
#include "testutil.h"

/* ---- the exact swap acceptance --------------------------------------- */

typedef struct {
  double a, t1, t2; /* shape d/2, temperatures t1 < t2 */
} swap_ctx;

/*
** P(swap) = E[min(1, exp((1/t1 - 1/t2)(E1 - E2)))], E1 ~ Gamma(a, t1) at the
** cold rung, E2 ~ Gamma(a, t2) at the hot one.  For fixed E1 the inner
** integral over E2 has a closed form: where E2 <= E1 the swap is certain,
** P(a, E1/t2); where E2 > E1 the weight exp(-(1/t1 - 1/t2)(E2 - E1)) turns
** the Gamma(a, t2) density into a Gamma(a, t1) one, giving
** exp((1/t1 - 1/t2) E1) (t1/t2)^a Q(a, E1/t1).  The outer integral is done
** numerically.
*/
static double swap_integrand(double e1, void *p)
{
  const swap_ctx *c = p;
  if (e1 <= 0.0) return 0.0;
  double f1 = gsl_ran_gamma_pdf(e1, c->a, c->t1);
  /* f1 exp((1/t1 - 1/t2) e1) (t1/t2)^a is the Gamma(a, t2) density: bounded */
  double f2 = gsl_ran_gamma_pdf(e1, c->a, c->t2);
  return f1 * gsl_sf_gamma_inc_P(c->a, e1 / c->t2) + f2 * gsl_sf_gamma_inc_Q(c->a, e1 / c->t1);
}

static double exact_swap(double d, double t1, double t2)
{
  swap_ctx c = {0.5 * d, t1, t2};
  gsl_function F = {swap_integrand, &c};
  gsl_integration_workspace *w = gsl_integration_workspace_alloc(1000);
  double r, err;
  gsl_integration_qagiu(&F, 0.0, 0.0, 1e-10, 1000, w, &r, &err);
  gsl_integration_workspace_free(w);
  return r;
}

Test(tempering, exact_swap_formula_matches_brute_force_sampling)
{
  /* The closed form is checked against plain sampling of the two Gamma
  ** variables (n = 4e5: sd of the estimate < 8e-4, tolerance 5 sd). */
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 7);
  const double d = 6, t1 = 1.0, t2 = 1.6;
  double sum = 0.0;
  const int n = 400000;
  for (int i = 0; i < n; i++) {
    double e1 = gsl_ran_gamma(r, 0.5 * d, t1), e2 = gsl_ran_gamma(r, 0.5 * d, t2);
    sum += fmin(1.0, exp((1.0 / t1 - 1.0 / t2) * (e1 - e2)));
  }
  double p = exact_swap(d, t1, t2);
  cr_assert(fabs(sum / n - p) < 5 * sqrt(p * (1 - p) / n), "closed form %g, sampled %g", p, sum / n);
  /* equal temperatures always swap; far apart almost never */
  cr_assert(fabs(exact_swap(d, 1.0, 1.0 + 1e-12) - 1.0) < 1e-6);
  cr_assert(exact_swap(d, 1.0, 100.0) < 1e-3);
  gsl_rng_free(r);
}

Test(tempering, measured_swap_acceptance_agrees_with_the_exact_expectation)
{
  /* Each rung's energy is drawn afresh from its exact distribution before
  ** every exchange step, so the attempts of a pair are independent Bernoulli
  ** trials: the measured rate has the binomial sd sqrt(p (1 - p) / N).  We
  ** allow 4.5 sd per pair (3 pairs; a false alarm is ~2e-5 per run, and the
  ** seed is fixed). */
  const int R = 4;
  const double d = 8, ladder[4] = {1.0, 1.35, 1.9, 2.5};
  lw_error err;
  lw_tempering *pt = lw_tempering_new(R, ladder, 11, &err);
  cr_assert_not_null(pt);
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 3);
  double e[4];
  for (int step = 0; step < 60000; step++) {
    for (int k = 0; k < R; k++) e[k] = gsl_ran_gamma(r, 0.5 * d, ladder[k]);
    lw_tempering_exchange(pt, e, ladder, NULL);
  }
  for (int k = 0; k + 1 < R; k++) {
    double p = exact_swap(d, ladder[k], ladder[k + 1]);
    double n = (double)pt->tried[k], m = lw_tempering_acceptance(pt, k);
    cr_assert_eq(pt->tried[k], 30000ul, "pair %d tried %lu times", k, pt->tried[k]);
    cr_assert(fabs(m - p) < 4.5 * sqrt(p * (1 - p) / n), "pair %d: measured %.4f, exact %.4f", k, m, p);
  }
  gsl_rng_free(r);
  lw_tempering_free(pt);
}

/* d harmonic degrees of freedom sampled by Metropolis with unit steps. */
typedef struct {
  double x[4];
  double e;
} oscillator;

static void metropolis_sweep(oscillator *o, double T, gsl_rng *r)
{
  for (int i = 0; i < 4; i++) {
    double old = o->x[i], nx = old + gsl_ran_gaussian(r, 1.5 * sqrt(T));
    double de = 0.5 * (nx * nx - old * old);
    if (de <= 0 || gsl_rng_uniform(r) < exp(-de / T)) {
      o->x[i] = nx;
      o->e += de;
    }
  }
}

Test(tempering, exchanges_keep_every_rung_in_its_boltzmann_distribution)
{
  /* Detailed balance of the exchange step: with Metropolis replicas and
  ** swaps of state pointers every sweep, the energy at rung k must still
  ** average d T_k / 2 (Gamma(d/2, T_k): variance d T_k^2 / 2).  Samples are
  ** correlated, so the error uses batch means (50 batches of 2000 sweeps,
  ** each much longer than the correlation time of a few sweeps); tolerance
  ** 5 standard errors per rung. */
  const int R = 4, batches = 50, per = 2000;
  const double ladder[4] = {0.5, 0.8, 1.3, 2.0};
  lw_error err;
  lw_tempering *pt = lw_tempering_new(R, ladder, 5, &err);
  oscillator osc[4] = {{{0}, 0}}, *at[4] = {&osc[0], &osc[1], &osc[2], &osc[3]};
  gsl_rng *rng[4];
  for (int k = 0; k < R; k++) {
    rng[k] = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng[k], 100 + (unsigned long)k);
  }
  double bm[4][50] = {{0}};
  int swapped[3];
  for (int s = -1000; s < batches * per; s++) {
    double e[4];
    for (int k = 0; k < R; k++) {
      metropolis_sweep(at[k], ladder[k], rng[k]);
      e[k] = at[k]->e;
    }
    lw_tempering_exchange(pt, e, ladder, swapped);
    for (int k = 0; k + 1 < R; k++)
      if (swapped[k]) {
        oscillator *t = at[k];
        at[k] = at[k + 1];
        at[k + 1] = t;
      }
    if (s >= 0)
      for (int k = 0; k < R; k++) bm[k][s / per] += at[k]->e / per;
  }
  for (int k = 0; k < R; k++) {
    double mean = 0, var = 0;
    for (int b = 0; b < batches; b++) mean += bm[k][b] / batches;
    for (int b = 0; b < batches; b++) var += (bm[k][b] - mean) * (bm[k][b] - mean) / (batches - 1);
    double se = sqrt(var / batches), want = 2.0 * ladder[k];
    cr_assert(fabs(mean - want) < 5 * se, "rung %d: <E> = %.4f +- %.4f, want %.4f", k, mean, se, want);
    gsl_rng_free(rng[k]);
  }
  /* the replicas did travel */
  cr_assert(pt->round_trips > 50, "only %lu round trips", pt->round_trips);
  lw_tempering_free(pt);
}

Test(tempering, round_trips_count_cold_hot_cold_journeys)
{
  /* The cold rung always holds the higher energy, so every attempt swaps.
  ** With two rungs, pair 0-1 is tried on even steps only: replica 0 goes
  ** up at steps 0, 4 and down at 2, 6 (trips at 2 and 6); replica 1 reaches
  ** the cold end at 0 (no trip: it never left it), the hot end at 2, the
  ** cold end again at 4 (one trip).  Eight steps: 3 round trips. */
  const double ladder[2] = {1.0, 2.0};
  lw_error err;
  lw_tempering *pt = lw_tempering_new(2, ladder, 1, &err);
  const double e[2] = {5.0, 1.0};
  for (int s = 0; s < 8; s++) lw_tempering_exchange(pt, e, ladder, NULL);
  cr_assert_eq(pt->tried[0], 4ul);
  cr_assert_eq(pt->accepted[0], 4ul);
  cr_assert_eq(pt->round_trips, 3ul);
  cr_assert_eq(pt->at[0], 0);
  lw_tempering_free(pt);
}

/* Three rungs, every swap taken (energies falling up the ladder), pairs 0-1
** on even steps and 1-2 on odd: each replica zigzags end to end in three
** steps.  Replica 0 starts cold going up; it is at the hot end after step
** 2 and cold again after 5: a trip.  Replica 1 reaches the hot end at 3 and
** the cold end at 7, replica 2 (which starts at the hot end, so starts
** nothing) the cold end at 3, then hot at 6 and cold at 9; replica 0 again
** at 11.  Twelve steps: 4 round trips.  A replica first seen at the hot
** end was labelled as coming down, and replica 2's arrival at step 3 made
** a fifth; two rungs cannot show it. */
Test(tempering, round_trips_on_three_rungs_count_whole_journeys_only)
{
  const double ladder[3] = {1.0, 2.0, 4.0}, e[3] = {5.0, 3.0, 1.0};
  lw_error err;
  lw_tempering *pt = lw_tempering_new(3, ladder, 1, &err);
  cr_assert_not_null(pt, "%s", err.msg);
  const unsigned long want[12] = {0, 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4};
  for (int s = 0; s < 12; s++) {
    lw_tempering_exchange(pt, e, ladder, NULL);
    cr_assert_eq(pt->round_trips, want[s], "after step %d: %lu round trips", s + 1, pt->round_trips);
  }
  cr_assert(pt->at[0] == 0 && pt->at[1] == 1 && pt->at[2] == 2, "the zigzag's period is 6 steps");
  lw_tempering_free(pt);
}

/* A geometric ladder over every pair of ends the keys accept (1e-300 to
** 1e300): t_max / t_min past the doubles made every rung but the last inf,
** and the ladder was refused.  Its rungs are t_min r^(k / (n - 1)). */
Test(tempering, a_geometric_ladder_spans_any_ends_the_keys_accept)
{
  const double ends[][2] = {{1e-300, 1e300}, {1e-10, 1e300}, {0.01, 1.0}};
  double ladder[5];
  for (int c = 0; c < 3; c++) {
    lw_tempering_geometric(ladder, 5, ends[c][0], ends[c][1]);
    cr_assert(ladder[0] == ends[c][0] && ladder[4] == ends[c][1], "case %d: the ends are not exact", c);
    const double step = (log(ends[c][1]) - log(ends[c][0])) / 4.0;
    for (int k = 1; k < 4; k++)
      cr_assert(isfinite(ladder[k]) && fabs(log(ladder[k]) - log(ends[c][0]) - k * step) < 1e-12 * (1.0 + k * step),
                "case %d rung %d: %g", c, k, ladder[k]);
    lw_error err;
    lw_tempering *pt = lw_tempering_new(5, ladder, 1, &err);
    cr_assert_not_null(pt, "%s", err.msg);
    lw_tempering_free(pt);
  }
}

Test(tempering, zero_and_equal_temperatures_are_handled)
{
  const double ladder[2] = {1.0, 2.0}, zero[2] = {0.0, 0.0}, cold0[2] = {0.0, 1.0};
  lw_error err;
  lw_tempering *pt = lw_tempering_new(2, ladder, 1, &err);
  /* both at T = 0 (a schedule brought the ladder there): the ladder's rule
  ** in the limit, the colder rung by the ladder takes the lower energy (the
  ** swap was free, and a run reported whichever state came to rung 0) */
  const double e[2] = {1.0, 3.0}, e_swapped[2] = {3.0, 1.0};
  for (int s = 0; s < 10; s += 2, pt->steps = 0) {
    cr_assert_eq(lw_tempering_exchange(pt, e, zero, NULL), 0);
    pt->steps = 0;
    cr_assert_eq(lw_tempering_exchange(pt, e_swapped, zero, NULL), 1);
  }
  /* and below 1 / DBL_MAX, where 1/T overflows on both rungs (every swap
  ** was refused: inf - inf) */
  const double tiny[2] = {1e-310, 2e-310};
  for (int s = 0; s < 10; s += 2, pt->steps = 0) {
    cr_assert_eq(lw_tempering_exchange(pt, e, tiny, NULL), 0);
    pt->steps = 0;
    cr_assert_eq(lw_tempering_exchange(pt, e_swapped, tiny, NULL), 1);
  }
  pt->steps = 0;
  /* a T = 0 rung never takes a higher energy */
  for (int s = 0; s < 10; s += 2, pt->steps = 0) cr_assert_eq(lw_tempering_exchange(pt, e, cold0, NULL), 0);
  lw_tempering_free(pt);
  double bad[2] = {1.0, 1.0};
  cr_assert_null(lw_tempering_new(2, bad, 1, &err));
  cr_assert_eq(err.code, LW_EINPUT);
}

/* Tunes a ladder of R rungs (ends and seed given) on d harmonic degrees of
** freedom, whose energies at temperature T are Gamma(d/2, T), at the
** engine's cadence for `steps` exchange steps; returns the ratio of the
** widest to the narrowest neighbour gap (1 for a geometric ladder, the equal
** one here), ends checked kept. */
static double tuned_gap_spread(int R, const double *start, double d, unsigned long seed, int steps)
{
  double ladder[LW_TEMPERING_MAX];
  memcpy(ladder, start, (size_t)R * sizeof *ladder);
  lw_error err;
  lw_tempering *pt = lw_tempering_new(R, ladder, seed, &err);
  cr_assert_not_null(pt, "%s", err.msg);
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, seed);
  for (int step = 1; step <= steps; step++) {
    double e[LW_TEMPERING_MAX];
    for (int k = 0; k < R; k++) e[k] = gsl_ran_gamma(r, 0.5 * d, pt->ladder[k]);
    lw_tempering_exchange(pt, e, pt->ladder, NULL);
    if (pt->steps % LW_TEMPERING_TUNE_EVERY == 0)
      lw_tempering_tune(pt, lw_tempering_tune_gain((long)(pt->steps / LW_TEMPERING_TUNE_EVERY)));
  }
  double lo = INFINITY, hi = 0;
  for (int k = 0; k + 1 < R; k++) {
    double q = pt->ladder[k + 1] / pt->ladder[k];
    lo = fmin(lo, q);
    hi = fmax(hi, q);
  }
  cr_log_info("seed %lu: ratios %g to %g", seed, lo, hi);
  cr_assert(pt->ladder[0] == start[0] && pt->ladder[R - 1] == start[R - 1], "the ends moved");
  gsl_rng_free(r);
  lw_tempering_free(pt);
  return hi / lo;
}

/* For identical harmonic systems the acceptance of a pair depends on the
** ratio t_k+1 / t_k only, so equal acceptance means a geometric ladder.
** Starting from a linear ladder (acceptance 0.2 at the cold end, 0.7 at the
** hot end), tuning must bring the ratios within 10% of each other and keep
** the ends. */
Test(tempering, ladder_tuning_equalises_swap_acceptance)
{
  static const double linear[5] = {1.0, 3.25, 5.5, 7.75, 10.0};
  const double spread = tuned_gap_spread(5, linear, 16, 4, 40000);
  cr_assert(spread < 1.1, "ratios %g apart", spread);
}

/* At the engine's cadence (a tune every LW_TEMPERING_TUNE_EVERY exchange
** steps, about 20 attempts a pair, whose acceptance is noisy by +-0.1) the
** ladder must settle, not wander: with a fixed gain it froze wherever the
** noise left it (a harmonic wire, whose geometric ladder is the equal one,
** ended at swap rates 0.19 to 0.43).  Four rungs of d = 10 from an uneven
** start, 250 updates, five seeds: every ladder's ratios within 12 % of each
** other (measured 2026-12-05: at most 1.04 with the falling gain; 1.06 to
** 1.21 with the fixed one). */
Test(tempering, ladder_tuning_settles_at_the_engines_cadence)
{
  static const double uneven[4] = {1.0, 1.2, 1.5, 8.0};
  double worst = 0.0;
  for (unsigned long seed = 1; seed <= 5; seed++)
    worst = fmax(worst, tuned_gap_spread(4, uneven, 10, seed, 250 * LW_TEMPERING_TUNE_EVERY));
  cr_assert(worst < 1.12, "ratios up to %g apart", worst);
}

/* ---- whole runs through the binary ------------------------------------ */

static char dir[64];

static void make_dir(void) { cr_assert_eq(lw_test_dir_make(dir, "pt"), 0); }
static void remove_dir(void) { cr_assert_eq(lw_test_dir_remove(dir), 0); }
#define sh lw_test_sh

static const char scene[] =
  "[scene]\nwidth = 50\nheight = 40\nmargin = 2\n"
  "[init]\nsplines = 8\nsegments = 3\nsegment_length = 4\n"
  "[energy]\nstrain = 5\nbending = 0.5\npair = 0.05\npair_cutoff = 4\nboundary = 0.1\n"
  "[anneal]\nschedule = geometric\nt_start = 0.5\nt_end = 0.05\nsweeps = 90\nsteps = 5\nseed = 8\ncheck_every = 11\n"
  "[tempering]\nreplicas = 4\nt_min = 0.5\nt_max = 4\ntune_ladder = equal\nladder_sweeps = 40\n"
  "[output]\ncheckpoint_every = 13\ntrace_every = 4\n";

TestSuite(ptrun, .init = make_dir, .fini = remove_dir);

static void write_scene(void)
{
  char path[128];
  snprintf(path, sizeof path, "%s/s.ini", dir);
  FILE *f = fopen(path, "w");
  fputs(scene, f);
  fclose(f);
}

/* The adaptive schedule under tempering: its energy statistics are the
** coldest rung's, so Huang's rule T_b = T_{b-1} exp(-lambda T_{b-1} / sd)
** holds for that rung's own temperatures (it once took the schedule's
** temperature, t_start / t_min = 10 times the rung's, and cooled the first
** step to 0.18 where the rule gives 0.84). */
Test(ptrun, the_adaptive_schedule_cools_the_coldest_rung_by_its_own_rule)
{
  char path[128];
  snprintf(path, sizeof path, "%s/a.ini", dir);
  FILE *f = fopen(path, "w");
  fputs("[scene]\nwidth = 100\nheight = 100\nmargin = 5\n[init]\nsplines = 20\nsegments = 4\n"
        "segment_length = 8\n[energy]\nstrain = 10\nbending = 1\npair = 0.02\npair_cutoff = 6\nboundary = 0.5\n"
        "[anneal]\nschedule = adaptive\nt_start = 1\nt_end = 0.001\nsweeps = 120\nsteps = 4\nseed = 3\n"
        "[tempering]\nreplicas = 2\nt_min = 0.1\nt_max = 1\n",
        f);
  fclose(f);
  lw_params p;
  lw_error err;
  cr_assert_eq(lw_params_read(&p, path, &err), LW_OK, "%s", err.msg);
  lw_anneal a;
  snprintf(path, sizeof path, "%s/a", dir);
  cr_assert_eq(lw_anneal_start(&a, &p, path, &err), LW_OK, "%s", err.msg);
  double before = -1.0;
  while (a.block < 1) {
    before = a.chains[0]->temperature;
    cr_assert_eq(lw_anneal_sweep(&a, &err), LW_OK, "%s", err.msg);
  }
  const double after = a.chains[0]->temperature, want = before * exp(-p.lambda * before / a.prev.sd);
  cr_assert(a.prev.samples > 10 && fabs(after / want - 1.0) < 1e-12, "coldest rung %g -> %g, the rule gives %g",
            before, after, want);
  cr_assert(fabs(before - 0.1) < 1e-15, "the coldest rung began at %g, not t_min", before);
  lw_anneal_free(&a);
}

Test(ptrun, outputs_do_not_depend_on_the_thread_count)
{
  const char *b = getenv("LW_BIN");
  write_scene();
  const int threads[3] = {1, 2, 4};
  for (int i = 0; i < 3; i++)
    cr_assert_eq(sh("OMP_NUM_THREADS=%d %s run %s/s.ini --out %s/t%d --quiet", threads[i], b, dir, dir, threads[i]), 0);
  const char *same[] = {"state.lw", "replica-1.lw", "replica-3.lw", "trace.csv", "final.svg", "final.png", "ladder.ini"};
  for (int i = 1; i < 3; i++)
    for (int k = 0; k < 7; k++)
      cr_assert_eq(sh("cmp -s %s/t1/%s %s/t%d/%s", dir, same[k], dir, threads[i], same[k]), 0, "%s differs with %d threads",
                   same[k], threads[i]);
  /* the summary reports the ensemble */
  cr_assert_eq(sh("grep -q '\"swap_acceptance\"' %s/t1/summary.json", dir), 0);
  cr_assert_eq(sh("grep -q '\"round_trips\"' %s/t1/summary.json", dir), 0);
  cr_assert_eq(sh("head -1 %s/t1/trace.csv | grep -q 'replica3_energy,swap0,swap1,swap2$'", dir), 0);
}

Test(ptrun, resume_continues_the_whole_ensemble_bit_exactly)
{
  const char *b = getenv("LW_BIN");
  write_scene();
  cr_assert_eq(sh("%s run %s/s.ini --out %s/a --quiet", b, dir, dir), 0);
  /* stopped inside the ladder warm-up and again later */
  cr_assert_eq(sh("%s run %s/s.ini --out %s/b --quiet --stop-at 23", b, dir, dir), 0);
  cr_assert_eq(sh("%s resume %s/b --quiet --stop-at 61", b, dir), 0);
  cr_assert_eq(sh("%s resume %s/b --quiet", b, dir), 0);
  const char *same[] = {"state.lw", "replica-1.lw", "replica-2.lw", "replica-3.lw", "trace.csv", "final.svg", "ladder.ini"};
  for (int k = 0; k < 7; k++)
    cr_assert_eq(sh("cmp -s %s/a/%s %s/b/%s", dir, same[k], dir, same[k]), 0, "%s differs", same[k]);
  /* state.lw alone carries the ensemble: the replica files are copies for
  ** the user, and a section this release does not know is refused */
  cr_assert_eq(sh("rm %s/b/replica-*.lw && %s resume %s/b --quiet --sweeps 0", dir, b, dir), 0);
  cr_assert_eq(sh("cmp -s %s/a/replica-2.lw %s/b/replica-2.lw", dir, dir), 0);
  cr_assert_eq(sh("printf '[system particles]\\ncount = 0\\n' >> %s/b/state.lw", dir), 0);
  cr_assert_eq(sh("%s resume %s/b --quiet 2>%s/err.txt", b, dir, dir), 2);
  cr_assert_eq(sh("grep -q 'state.lw:[0-9]*: section .system particles. is unknown' %s/err.txt", dir), 0);
}

Test(ptrun, bad_ladders_are_refused_with_the_line)
{
  const char *b = getenv("LW_BIN");
  write_scene();
  cr_assert_eq(sh("printf '[tempering]\\nladder = 1 0.5 2\\n' > %s/bad.ini", dir), 0);
  cr_assert_eq(sh("%s run %s/bad.ini --out %s/x --quiet 2>%s/err.txt", b, dir, dir, dir), 2);
  cr_assert_eq(sh("grep -q 'bad.ini:2: key .tempering.ladder.: expected increasing' %s/err.txt", dir), 0);
  cr_assert_eq(sh("%s run %s/s.ini --set tempering.t_max=0.1 --out %s/x --quiet 2>%s/err.txt", b, dir, dir, dir), 2);
  cr_assert_eq(sh("grep -q 'tempering.t_max' %s/err.txt", dir), 0);
  /* a ladder against a replicas key: which one to change */
  cr_assert_eq(sh("printf '[tempering]\nreplicas = 3\nladder = 1 2 3 4\n' > %s/bad.ini", dir), 0);
  cr_assert_eq(sh("%s run %s/bad.ini --out %s/x --quiet 2>%s/err.txt", b, dir, dir, dir), 2);
  cr_assert_eq(sh("grep -q 'bad.ini:3: key .tempering.ladder.: 4 temperatures for 3 replicas: the ladder sets the "
                  "count, so expected tempering.replicas = 4 or 1 (its default)' %s/err.txt", dir), 0);
  cr_assert_neq(sh("test -e %s/x", dir), 0, "an output directory was created for bad input");
  /* replicas = 1 given to turn tempering off, under a ladder that sets the
  ** count, ran every rung unsaid */
  cr_assert_eq(sh("%s run %s/params/wire-ladder.ini --set tempering.replicas=1 --stop-at 0 --out %s/r1 2>%s/err.txt && "
                  "grep -q 'note: tempering.replicas = 1 is given, but tempering.ladder has 3 rungs and sets the count: "
                  "3 replicas run (for one chain, give tempering.ladder empty too)' %s/err.txt", b, lw_test_root(), dir,
                  dir, dir), 0);
  /* two rungs too; and no note where replicas is not given (minimal.ini has no such key) */
  cr_assert_eq(sh("%s run %s/params/minimal.ini --set tempering.replicas=1 --set 'tempering.ladder=1 2' --stop-at 0 "
                  "--out %s/r2 2>%s/err.txt && grep -q 'tempering.ladder has 2 rungs' %s/err.txt", b, lw_test_root(),
                  dir, dir, dir), 0);
  cr_assert_eq(sh("%s run %s/params/minimal.ini --set 'tempering.ladder=1 2' --stop-at 0 --out %s/r3 2>%s/err.txt && "
                  "! grep -q 'replicas = 1 is given' %s/err.txt", b, lw_test_root(), dir, dir, dir), 0);
}

/* tune_ladder = equal says when it could not do its job.  Before the run: a
** ladder_sweeps of 0 (nothing tuned), or one within moves.tune_sweeps
** (LJ13's default 200 of 2000 came out less even than its start).  After
** it: swap rates that still spread (the wire from 1 1.2 1.5 8 tuned over 40
** sweeps: 0.27 rms over 200 tries a pair, where chance gives about 0.03),
** which a long tuning does not leave (0.010); over 10 tries a pair (0.25
** rms, chance 0.14 and so up to 0.42) it cannot tell and says nothing, nor
** over one (each pair's rate 0 or 1: chance taken from each pair's own
** rate, r (1 - r) = 0, called such a ladder "too short"). */
Test(ptrun, an_equal_ladder_that_did_not_settle_is_said)
{
  const char *run = "%s run %s/params/wire-ladder.ini --threads 1 --set 'tempering.ladder=1 1.2 1.5 8' "
                    "--set tempering.replicas=4 --set tempering.tune_ladder=equal --set tempering.ladder_sweeps=%d "
                    "--set anneal.sweeps=%d --set output.checkpoint_every=100000 %s --out %s/l%d 2> %s/err.txt";
  cr_assert_eq(sh(run, lw_test_bin(), lw_test_root(), 0, 10, "--stop-at 0", dir, 0, dir), 0);
  cr_assert_eq(sh("grep -q 'note: tempering.tune_ladder = equal with ladder_sweeps = 0 tunes nothing' %s/err.txt",
                  dir), 0);
  /* the ladder moves once every 40 exchanges: with fewer in ladder_sweeps
  ** it stayed as given, ladder.ini's comment saying it was tuned; with none
  ** the freeze never came (no ladder.ini, no restart of the statistics) */
  cr_assert_eq(sh(run, lw_test_bin(), lw_test_root(), 390, 400, "--set tempering.exchange_every=10 --stop-at 0", dir,
                  390, dir), 0);
  cr_assert_eq(sh("grep -q 'note: tempering.ladder_sweeps = 390 holds 39 exchanges (exchange_every = 10), and the "
                  "ladder moves once every 40: it stays as given$' %s/err.txt", dir), 0);
  cr_assert_eq(sh(run, lw_test_bin(), lw_test_root(), 40, 100, "--set tempering.exchange_every=50", dir, 41, dir), 0);
  cr_assert_eq(sh("grep -q 'note: tempering.ladder_sweeps = 40 holds 0 exchanges (exchange_every = 50), and the "
                  "ladder moves once every 40: it stays as given, the swap statistics count from the start and no "
                  "ladder.ini is written' %s/err.txt && test ! -e %s/l41/ladder.ini", dir, dir), 0);
  /* one exchange at the last tuning sweep: the freeze comes, and ladder.ini */
  cr_assert_eq(sh(run, lw_test_bin(), lw_test_root(), 50, 60, "--set tempering.exchange_every=50", dir, 42, dir), 0);
  cr_assert_eq(sh("grep -q 'holds 1 exchange (exchange_every = 50), and the ladder moves once every 40: it stays as "
                  "given$' %s/err.txt && test -e %s/l42/ladder.ini", dir, dir), 0);
  for (int after = 2; after <= 20; after += 18) {
    cr_assert_eq(sh(run, lw_test_bin(), lw_test_root(), 40, 40 + after, "", dir, after, dir), 0);
    cr_assert_neq(sh("grep -q 'note: the swap rates' %s/err.txt", dir), 0, "%d sweeps after the freeze", after);
  }
  cr_assert_eq(sh(run, lw_test_bin(), lw_test_root(), 40, 440, "", dir, 40, dir), 0);
  cr_assert_eq(sh("grep -q 'note: tempering.ladder_sweeps = 40 ends within moves.tune_sweeps = 500' %s/err.txt && "
                  "grep -q 'note: the swap rates since the ladder froze run from .*: tempering.ladder_sweeps = 40 "
                  "was too short to equalise them' %s/err.txt", dir, dir), 0);
  cr_assert_eq(sh(run, lw_test_bin(), lw_test_root(), 10000, 16000, "", dir, 10000, dir), 0);
  cr_assert_neq(sh("grep -q 'note: .*ladder' %s/err.txt", dir), 0);
}

/* ladder.ini is ready to reuse as README says: LJ13's 16 rungs at 17 digits
** were 301 bytes, which --set and a scene file refused (the value then took
** the most digits that fit a scene's line, and past 26 rungs none did).  A
** list now goes on over indented lines: pasted into the scene or given to
** --set, every digit comes back. */
Test(ptrun, a_tuned_ladder_of_16_rungs_reads_back_pasted_and_through_set)
{
  cr_assert_eq(sh("%s run %s/params/lj13.ini --threads 1 --quiet --set anneal.sweeps=300 "
                  "--set tempering.tune_ladder=equal --set tempering.ladder_sweeps=200 --out %s/lj 2> %s/err.txt",
                  lw_test_bin(), lw_test_root(), dir, dir),
               0);
  cr_assert_eq(sh("sed -n '/^ladder = /,$p' %s/lj/ladder.ini > %s/lad && test $(wc -l < %s/lad) -gt 1 && "
                  "test $(cat %s/lad | wc -w) -eq 18", dir, dir, dir, dir), 0, "16 rungs over several lines");
  /* each rung with the fewest digits that read back the same double as
  ** state.lw's 17 (a writer of 16 at most passed every test) */
  cr_assert_eq(sh("awk 'FNR == NR { for (i = 1; i <= NF; i++) if ($i != \"ladder\" && $i != \"=\") a[++n] = $i; next }"
                  " /^\\[tempering\\]/ { t = 1 } t && $1 == \"ladder\" { for (i = 3; i <= NF; i++) b[++m] = $i; t = 0 }"
                  " END { if (n != 16 || m != 16) exit 1; for (i = 1; i <= n; i++) if (a[i] + 0 != b[i] + 0) exit 1 }'"
                  " %s/lad %s/lj/state.lw", dir, dir), 0, "ladder.ini's rungs are not state.lw's");
  cr_assert_eq(sh("cat %s/params/lj13.ini %s/lj/ladder.ini > %s/pasted.ini && %s run %s/pasted.ini --threads 1 "
                  "--quiet --stop-at 0 --out %s/lj2 2> %s/err.txt && sed -n '/^ladder = /,/^[a-z]/p' %s/lj2/scene.ini "
                  "| sed '$d' | cmp -s - %s/lad", lw_test_root(), dir, dir, lw_test_bin(), dir, dir, dir, dir, dir),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(sh("L=$(sed 's/^ladder = //' %s/lad | tr -s ' \n' '  ') && %s run %s/params/lj13.ini --threads 1 "
                  "--quiet --stop-at 0 --set \"tempering.ladder=${L%% }\" --out %s/lj3 2> %s/err.txt && "
                  "cmp -s %s/lj2/scene.ini %s/lj3/scene.ini", dir, lw_test_bin(), lw_test_root(), dir, dir, dir, dir),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* tempering.ladder_file reads a run's ladder.ini, found from the scene
** file's directory: the run is the one --set tempering.ladder gives, byte
** for byte, scene.ini too, which holds the ladder in the file's place, so a
** resume reads no ladder file (the one it began with is gone here) and a
** redraw from scene.ini runs.  A file that is not a
** ladder, or a ladder given twice, is refused naming the file and line at
** fault, before anything is written.  Under the dynamics, which reads no
** ladder, the key is noted and no file is needed, to run or to resume. */
Test(ptrun, a_ladder_file_runs_as_its_ladder_given_by_set)
{
  write_scene();
  const char *bin = lw_test_bin();
  cr_assert_eq(sh("%s run %s/s.ini --threads 1 --quiet --out %s/t", bin, dir, dir), 0);
  cr_assert_eq(sh("mkdir %s/sub && cp %s/t/ladder.ini %s/lad.ini && (cat %s/s.ini; printf '[tempering]\n"
                  "ladder_file = ../lad.ini\n') | sed '/^tune_ladder/d' > %s/sub/f.ini",
                  dir, dir, dir, dir, dir),
               0);
  const char *fixed = "--threads 1 --quiet --set tempering.tune_ladder=fixed --set anneal.sweeps=40";
  cr_assert_eq(sh("L=$(sed -n '/^ladder = /,$p' %s/lad.ini | sed 's/^ladder = //' | tr -s ' \n' '  ') && "
                  "%s run %s/s.ini %s --set \"tempering.ladder=${L%% }\" --out %s/set 2> %s/err.txt",
                  dir, bin, dir, fixed, dir, dir),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(sh("%s run %s/sub/f.ini %s --out %s/file 2> %s/err.txt", bin, dir, fixed, dir, dir), 0, "%s",
               lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(sh("cd %s && cmp set/trace.csv file/trace.csv && cmp set/state.lw file/state.lw && "
                  "cmp set/scene.ini file/scene.ini", dir),
               0, "the ladder file's run is not the --set ladder's");
  /* resumed without its ladder file */
  cr_assert_eq(sh("cd %s && %s run sub/f.ini %s --stop-at 20 --out r && mv lad.ini gone.ini && "
                  "%s resume r --threads 1 --quiet 2> err.txt && cmp r/trace.csv file/trace.csv && "
                  "cmp r/state.lw file/state.lw && mv gone.ini lad.ini", dir, bin, fixed, bin),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(sh("cd %s && %s run file/scene.ini --set init.from=file/state.lw --set anneal.sweeps=0 --quiet "
                  "--out redraw 2> err.txt && cmp redraw/final.svg file/final.svg", dir, bin),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  const struct {
    const char *file, *set, *says;
  } bad[] = {
    {"[tempering]\nladder = 1 2 4\n[anneal]\nsweeps = 5\n", "",
     "lad.ini:4: key 'anneal.sweeps': a ladder file holds only tempering.ladder"},
    {"; nothing\n", "", "lad.ini: no tempering.ladder in it"},
    {"[tempering]\nladder = 1 4 2 3\n", "", "lad.ini:2: key 'tempering.ladder': expected increasing positive"},
    {"[tempering]\nladder = 1 2 3 1e301\n", "", "lad.ini:2: key 'tempering.ladder': expected increasing positive "
     "temperatures up to 1e300"},
    {"[tempering]\nladder = 1 2\n", "", "lad.ini:2: key 'tempering.ladder': 2 temperatures for 4 replicas"},
    /* the word that is no number is named (said: not 2 to 256 temperatures) */
    {"[tempering]\nladder = 1 2x 4\n", "", "lad.ini:2: key 'tempering.ladder': '2x' is not a temperature; expected "
     "finite numbers"},
    /* with the scene's key that named the file, as its lines' faults have */
    {"[tempering]\nladder = 1 2 x\n", "", "f.ini:32: key 'tempering.ladder_file': "},
    {"[tempering]\nladder = 1, 2, nan, 4\n", "", "lad.ini:2: key 'tempering.ladder': 'nan' is not a temperature"},
    /* a no-break space between two numbers is named ("'1 2' is not a temperature") */
    {"[tempering]\nladder = 1\302\2402 4\n", "", "is not a temperature; expected finite numbers such as 0.5 or "
     "2e-3 (byte 2 is a no-break space"},
    /* past the 60 bytes shown too, and a long word is cut between characters
    ** (a cut é was said to be a byte that is no text) */
    {"[tempering]\nladder = 1 12345678901234567890123456789012345678901234567890123456789012345\302\2402\n", "",
     "...' is not a temperature; expected finite numbers such as 0.5 or 2e-3 (byte 66 is a no-break space"},
    {"[tempering]\nladder = 1 \303\251\303\251\303\251\303\251\303\251\303\251\303\251\303\251\303\251\303\251"
     "\303\251\303\251\303\251\303\251\303\251\303\251\303\251\303\251\303\251\303\251\303\251\303\251"
     "\303\251\303\251\303\251\303\251\303\251\303\251\303\251\303\251\303\251\303\251\303\251\303\251"
     "\303\251\303\251\303\251\303\251\303\251\303\251\n", "",
     "\303\251...' is not a temperature; expected finite numbers such as 0.5 or 2e-3\n"},
    /* values before the count: "1 2 2" was sent to replicas = 3 first */
    {"[tempering]\nladder = 1 2 2\n", "", "lad.ini:2: key 'tempering.ladder': expected increasing positive"},
    {"[tempering]\nladder = 1 2 3 4\n", "--set 'tempering.ladder=1 2 3 5'",
     "f.ini:32: key 'tempering.ladder_file': tempering.ladder is given too (--set); expected one of them"},
    {NULL, "", "f.ini:32: key 'tempering.ladder_file': cannot read '"},
    /* a picture was advised to be drawn, and a file the reader refuses had no key named */
    {"\\211PNG\\r\\n\\032\\n", "", "lad.ini: a PNG picture, not a ladder file: expected a [tempering] section"},
    {"[tempering]\\000\n", "", "f.ini:32: key 'tempering.ladder_file': "},
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    if (bad[k].file) cr_assert_eq(sh("printf '%s' > %s/lad.ini", bad[k].file, dir), 0);
    else cr_assert_eq(sh("rm %s/lad.ini", dir), 0);
    cr_assert_eq(sh("%s run %s/sub/f.ini %s %s --out %s/no 2> %s/err.txt", bin, dir, fixed, bad[k].set, dir, dir), 2,
                 "case %zu", k);
    char *msg = lw_test_slurp("%s/err.txt", dir);
    cr_assert(msg && strstr(msg, bad[k].says) && strchr(msg, '\n') && !strchr(strchr(msg, '\n') + 1, '\n'),
              "case %zu: %s", k, msg);
    free(msg);
    cr_assert_neq(sh("test -e %s/no", dir), 0, "case %zu wrote its run directory", k);
  }
  /* a rung below the smallest normal double (any above 0 is allowed) runs,
  ** and resumes (its state was refused as damaged) */
  cr_assert_eq(sh("cd %s && %s run %s/params/minimal.ini --out tiny --quiet --set anneal.sweeps=20 --stop-at 10 "
                  "--set 'tempering.ladder=1e-310 1' && %s resume tiny --quiet 2> err.txt", dir, bin, lw_test_root(),
                  bin),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* the dynamics reads no ladder: a ladder file there, missing or not, is
  ** noted and the run goes on, and its resume needs no file */
  cr_assert_eq(sh("cd %s && %s run %s/params/hanging.ini --out dn --set anneal.sweeps=4 "
                  "--set tempering.ladder_file=nope.ini 2> err.txt && "
                  "grep -q 'no effect: tempering.ladder_file' err.txt", dir, bin, lw_test_root()),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(sh("cd %s && printf '[tempering]\\nladder = 1 2\\n' > l2.ini && %s run %s/params/hanging.ini --out dy "
                  "--quiet --set anneal.sweeps=4 --set tempering.ladder_file=l2.ini 2> err.txt && rm l2.ini && "
                  "%s resume dy --quiet --sweeps 2 2> err.txt", dir, bin, lw_test_root(), bin),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* A tempering run of no sweep has no temperatures yet: its rungs said 0
** in summary.json (beside the ladder), where temperature_final was null;
** and no rate of proposals. */
Test(ptrun, a_run_of_no_sweep_gives_its_rungs_no_temperature)
{
  const char *run = "%s run %s/params/wire-ladder.ini --threads 1 --quiet --set anneal.sweeps=%d --out %s/z%d";
  for (int sweeps = 0; sweeps <= 1; sweeps++) {
    cr_assert_eq(sh(run, lw_test_bin(), lw_test_root(), sweeps, dir, sweeps), 0);
    int nulls = sh("test $(grep -c '^      \"temperature\": null,$' %s/z%d/summary.json) -eq 3 && "
                   "grep -q '^  \"temperature_final\": null,$' %s/z%d/summary.json", dir, sweeps, dir, sweeps);
    int ones = sh("grep -q '^      \"temperature\": 1,$' %s/z%d/summary.json", dir, sweeps);
    cr_assert(sweeps ? nulls != 0 && ones == 0 : nulls == 0 && ones != 0, "%d sweeps", sweeps);
    /* nor a rate: 0 / 0 read 0, which a script averaging rates counted */
    cr_assert_eq(sh("grep -q '^  \"proposals_per_second\": null,$' %s/z%d/summary.json", dir, sweeps), sweeps != 0,
                 "%d sweeps", sweeps);
  }
}
