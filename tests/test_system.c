/*
** test_system.c -- the system seam (system.h): adding a system is local.
**
** A test-only row, `gauss`, holds a few independent variables x_i with the
** energy k_i x_i^2 / 2, in two terms (even and odd i) and with two move
** kinds (one variable, or all at once, each by a Gaussian step).  At
** temperature T each x_i is exactly N(0, T / k_i).  The real Metropolis
** chain (mc.h) and the real tempering exchanges (tempering.h) drive it
** through the row alone, and must sample that distribution.
**
** Tolerances: the samples are correlated, so the standard error of a mean is
** estimated by batch means (B batches of equal length, each much longer
** than the correlation time): se = sd(batch means) / sqrt(B).  An estimate
** passes within 5 se, and se must itself be small, so the check has power.
*/
#include <criterion/criterion.h>
#include <gsl/gsl_randist.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/driver.h"
#include "linewise/mc.h"
#include "linewise/sys_particles.h"
#include "linewise/sys_splines.h"
#include "linewise/system.h"
#include "linewise/tempering.h"
#include "testutil.h"

#define NV 3
static const double stiffness[NV] = {1.0, 4.0, 0.25};

typedef struct {
  double x[NV];
  double term[2]; /* running: even i, odd i */
} gs_state;

typedef struct {
  int n, idx[NV];
  double x[NV];
  double dterm[2];
} gs_prop;

static double gs_energy(int i, double x) { return 0.5 * stiffness[i] * x * x; }

static void *gs_setup_new(const lw_params *p, lw_error *err)
{
  static int setup; /* nothing to set up; a non-NULL token */
  return &setup;
}
static void gs_setup_free(void *setup) {}
static const char *gs_note(const void *setup) { return ""; }

static void gs_sum(gs_state *s)
{
  s->term[0] = s->term[1] = 0.0;
  for (int i = 0; i < NV; i++) s->term[i % 2] += gs_energy(i, s->x[i]);
}

static void *gs_state_new(const void *setup, const lw_params *p, unsigned long seed, lw_error *err)
{
  gs_state *s = calloc(1, sizeof *s);
  if (!s) return NULL;
  for (int i = 0; i < NV; i++) s->x[i] = 1.0 + i; /* far out: the burn-in must forget it */
  gs_sum(s);
  return s;
}

static void *gs_state_copy(const void *state, lw_error *err)
{
  gs_state *s = malloc(sizeof *s);
  if (s) *s = *(const gs_state *)state;
  return s;
}

static void gs_state_free(void *state) { free(state); }

static void gs_moves(const lw_params *p, double *weight, double *step, double *target)
{
  weight[0] = 1.0, weight[1] = 0.25;
  step[0] = 1.5, step[1] = 0.5;
  target[0] = 0.4, target[1] = 0.3;
}

static size_t gs_sweep_size(const void *state) { return NV; }
static double gs_step_max(const void *state, int kind) { return 10.0; }
static void *gs_proposal_new(const void *state, lw_error *err) { return malloc(sizeof(gs_prop)); }
static void gs_proposal_free(void *prop) { free(prop); }

/* The proposal that runs out of memory (counting from 1; 0: none). */
static long gs_nomem_at, gs_proposed;

static double gs_propose(void *state, void *prop, int kind, double step, gsl_rng *rng, int *forbidden)
{
  const gs_state *s = state;
  gs_prop *p = prop;
  if (++gs_proposed == gs_nomem_at) {
    *forbidden = LW_PROPOSE_NOMEM;
    return NAN;
  }
  p->n = 0;
  p->dterm[0] = p->dterm[1] = 0.0;
  if (kind == 0) {
    p->idx[p->n++] = (int)gsl_rng_uniform_int(rng, NV);
  } else {
    for (int i = 0; i < NV; i++) p->idx[p->n++] = i;
  }
  for (int k = 0; k < p->n; k++) {
    int i = p->idx[k];
    p->x[k] = s->x[i] + gsl_ran_gaussian_ziggurat(rng, step);
    p->dterm[i % 2] += gs_energy(i, p->x[k]) - gs_energy(i, s->x[i]);
  }
  return p->dterm[0] + p->dterm[1];
}

static lw_status gs_commit(void *state, void *prop)
{
  gs_state *s = state;
  const gs_prop *p = prop;
  for (int k = 0; k < p->n; k++) s->x[p->idx[k]] = p->x[k];
  s->term[0] += p->dterm[0];
  s->term[1] += p->dterm[1];
  return LW_OK;
}

static double gs_total(const void *state)
{
  const gs_state *s = state;
  return s->term[0] + s->term[1];
}

static void gs_terms(const void *state, double *term) { memcpy(term, ((const gs_state *)state)->term, 2 * sizeof *term); }
static int gs_term_on(const void *setup, int t) { return 1; }

static lw_status gs_refresh(void *state)
{
  gs_sum(state);
  return LW_OK;
}

static lw_status gs_save(const void *state, lw_ckpt_writer *w, const char *section, lw_error *err)
{
  const gs_state *s = state;
  lw_ckpt_section(w, section);
  lw_ckpt_put_numbers(w, "x", s->x, NV);
  return LW_OK;
}

static void *gs_load(const void *setup, lw_state *st, const char *section, const char *path, lw_error *err)
{
  gs_state *s = calloc(1, sizeof *s);
  if (!s) {
    lw_error_set(err, LW_ENOMEM, "out of memory");
    return NULL;
  }
  if (lw_ckpt_numbers(st->doc, section, "x", s->x, NV, -1e300, 1e300, 1, err)) {
    free(s);
    return NULL;
  }
  gs_sum(s);
  return s;
}

static void gs_set_terms(void *state, const double *term) { memcpy(((gs_state *)state)->term, term, 2 * sizeof *term); }

static double gs_energy_of(const void *setup, const lw_state *st, const char *path, double *term, lw_error *err)
{
  lw_state copy = *st;
  gs_state *s = gs_load(setup, &copy, "system gauss", path, err);
  if (!s) return NAN;
  gs_terms(s, term);
  double e = gs_total(s);
  free(s);
  return e;
}

static lw_status gs_draw(void *state, const lw_params *p, const char *dir, long sweep, lw_error *err) { return LW_OK; }

static void gs_summary(const void *state, lw_json *j)
{
  lw_json_key(j, "variables");
  lw_json_int(j, NV);
}

static void gs_describe(const void *state, int what, char *buf, size_t n)
{
  snprintf(buf, n, what == LW_DESCRIBE_SIZE ? "%d variables" : "", NV);
}

static void gs_defer(void *prop, int on) {}

static const char *const gs_move_names[] = {"one", "all"};
static const double gs_move_unit[] = {1.0, 1.0};
static const char *const gs_term_names[] = {"even", "odd"};

static const lw_system_type gauss_type = {
    .name = "gauss", .n_moves = 2, .move_names = gs_move_names, .move_unit = gs_move_unit,
    .n_terms = 2, .term_names = gs_term_names,
    .setup_new = gs_setup_new, .setup_free = gs_setup_free, .note = gs_note,
    .state_new = gs_state_new, .state_copy = gs_state_copy, .state_free = gs_state_free,
    .moves = gs_moves, .sweep_size = gs_sweep_size, .step_max = gs_step_max,
    .proposal_new = gs_proposal_new, .proposal_free = gs_proposal_free,
    .propose = gs_propose, .commit = gs_commit,
    .total = gs_total, .terms = gs_terms, .term_on = gs_term_on, .refresh = gs_refresh, .energy = gs_energy_of,
    .save = gs_save, .load = gs_load, .set_terms = gs_set_terms,
    .files = "", .draw = gs_draw, .summary = gs_summary, .describe = gs_describe,
};

/* A system of row t and a chain on it at temperature T. */
static lw_chain *row_chain(const lw_system_type *t, double T, unsigned long seed)
{
  lw_params p;
  lw_params_defaults(&p);
  lw_error err;
  void *setup = t->setup_new(&p, &err);
  lw_system *sys = lw_system_wrap(t, t->state_new(setup, &p, 0, &err), &err);
  cr_assert_not_null(sys);
  double w[LW_MOVES_MAX], st[LW_MOVES_MAX], tg[LW_MOVES_MAX];
  t->moves(&p, w, st, tg);
  lw_chain *c = lw_chain_new(sys, w, st, tg, seed, &err);
  cr_assert_not_null(c, "%s", err.msg);
  c->temperature = T;
  return c;
}

static lw_chain *gauss_chain(double T, unsigned long seed) { return row_chain(&gauss_type, T, seed); }

static void gauss_chain_free(lw_chain *c)
{
  lw_system *sys = c->sys;
  lw_chain_free(c);
  lw_system_free(sys);
}

/* x_i / sigma_i has mean 0 and x_i^2 / sigma_i^2 mean 1 at temperature T. */
static void check_gaussian(const char *what, batch_mean *m1, batch_mean *m2, double T)
{
  for (int i = 0; i < NV; i++) {
    double se1, se2;
    double mean = bm_mean(&m1[i], &se1), var = bm_mean(&m2[i], &se2);
    cr_assert(se1 < 0.01 && se2 < 0.01, "%s: x%d: standard errors %g, %g too large to test anything", what, i,
              se1, se2);
    cr_assert(fabs(mean) < 5 * se1, "%s: x%d / sigma has mean %g +- %g, expected 0", what, i, mean, se1);
    cr_assert(fabs(var - 1.0) < 5 * se2, "%s: x%d^2 / sigma^2 has mean %g +- %g, expected 1 (T = %g, k = %g)",
              what, i, var, se2, T, stiffness[i]);
  }
}

/* The chain c at temperature T after 2000 sweeps of burn-in: each x_i /
** sigma_i and its square in BATCHES batches of 20000 sweeps. */
static void sample_gaussian(lw_chain *c, double T, batch_mean *m1, batch_mean *m2)
{
  for (int s = 0; s < 2000; s++) cr_assert_eq(lw_chain_sweep(c), LW_OK);
  const long per = 20000;
  memset(m1, 0, NV * sizeof *m1);
  memset(m2, 0, NV * sizeof *m2);
  for (int i = 0; i < NV; i++) m1[i].per = m2[i].per = per;
  const gs_state *st = c->sys->state;
  for (long s = 0; s < BATCHES * per; s++) {
    lw_chain_sweep(c);
    for (int i = 0; i < NV; i++) {
      double z = st->x[i] / sqrt(T / stiffness[i]);
      bm_add(&m1[i], z);
      bm_add(&m2[i], z * z);
    }
  }
}

/* The test row with every move's dE exactly 0, as where a pair term's
** cutoff leaves a moved part no partner. */
static double flat_propose(void *state, void *prop, int kind, double step, gsl_rng *rng, int *forbidden)
{
  gs_propose(state, prop, kind, step, rng, forbidden);
  gs_prop *p = prop;
  p->dterm[0] = p->dterm[1] = 0.0;
  return 0.0;
}

/* A move of no energy change is taken, at T = 0 too (the greedy descent
** moves along a level: docs/NUMERICS.md, "Acceptance"), and at T > 0
** without a random draw (Metropolis draws none where x >= 0), so a hot and
** a cold chain of one seed walk the same steps.  A rule of dE < 0 rejected
** them at T = 0 and drew for each at T > 0 (a mutant the suites let by). */
Test(system, a_move_of_no_energy_change_is_taken_without_a_draw)
{
  static lw_system_type flat;
  flat = gauss_type;
  flat.name = "flat";
  flat.propose = flat_propose;
  lw_chain *hot = row_chain(&flat, 0.7, 5), *cold = row_chain(&flat, 0.0, 5);
  for (int s = 0; s < 200; s++) {
    cr_assert_eq(lw_chain_sweep(hot), LW_OK);
    cr_assert_eq(lw_chain_sweep(cold), LW_OK);
  }
  for (int k = 0; k < 2; k++) {
    cr_assert(cold->stats[k].proposed > 0 && cold->stats[k].accepted == cold->stats[k].proposed, "kind %d: %lu of %lu",
              k, cold->stats[k].accepted, cold->stats[k].proposed);
    cr_assert_eq(hot->stats[k].accepted, hot->stats[k].proposed, "kind %d", k);
  }
  const gs_state *h = hot->sys->state, *c = cold->sys->state;
  cr_assert(!memcmp(h->x, c->x, sizeof h->x), "the hot chain drew for its decisions: (%g %g %g) against (%g %g %g)",
            h->x[0], h->x[1], h->x[2], c->x[0], c->x[1], c->x[2]);
  gauss_chain_free(hot);
  gauss_chain_free(cold);
}

Test(system, the_chain_samples_a_test_row_exactly)
{
  const double T = 0.7;
  lw_chain *c = gauss_chain(T, 2024);
  batch_mean m1[NV], m2[NV];
  sample_gaussian(c, T, m1, m2);
  check_gaussian("chain", m1, m2, T);
  /* both move kinds ran under their names, and the running terms are exact */
  for (int k = 0; k < 2; k++) cr_assert(c->stats[k].accepted > 0 && c->stats[k].accepted < c->stats[k].proposed);
  double run[2], fresh[2];
  gs_terms(c->sys->state, run);
  cr_assert_eq(gauss_type.refresh(c->sys->state), LW_OK);
  gs_terms(c->sys->state, fresh);
  double drift = lw_system_drift(run, fresh, 2);
  cr_assert(drift < 1e-9, "running energy drifted by %g", drift);
  gauss_chain_free(c);
}

/* Every chain driver with its own acceptance rule (driver.h, `accept`),
** row by row of the table, so that a new rule is held to it unnamed (a rule
** sampling exp(-E / 2T) passed every test): a(x) / a(-x) = e^x, which keeps
** exp(-E/T) (docs/NUMERICS.md, "Acceptance rules"), a within [0, 1] and
** continuous at 0 (the step tuning aims at a share of a(0)), no overflow at
** the ends; and it samples the test row exactly: the same batch means as
** Metropolis (5 standard errors of 50 batches), no more moves taken than
** Metropolis's min(1, e^x) (Peskun). Barker's row, e^x / (1 + e^x), also
** to its formula. */
Test(system, every_chain_under_its_own_acceptance_rule_samples_a_test_row_exactly)
{
  const double T = 0.7;
  int rules = 0;
  for (int r = 0; lw_driver_types[r]; r++) {
    const lw_driver_type *v = lw_driver_types[r];
    if (v->kind != LW_DRIVE_CHAIN || !v->accept) continue;
    rules++;
    for (double x = -30.0; x <= 30.0; x += 0.25) {
      const double a = v->accept(x), b = v->accept(-x);
      cr_assert(a >= 0.0 && a <= 1.0, "%s: a(%g) = %g", v->name, x, a);
      cr_assert(fabs(a - exp(x) * b) <= 1e-12 * fmax(a, exp(x) * b), "%s: a(%g) / a(%g) = %.17g, not e^x", v->name, x,
                -x, a / b);
    }
    cr_assert(fabs(v->accept(1e-9) - v->accept(-1e-9)) < 1e-6, "%s: a jumps at 0", v->name);
    cr_assert(v->accept(INFINITY) <= 1.0 && v->accept(-INFINITY) == 0.0 && v->accept(-800.0) == 0.0 &&
              v->accept(800.0) <= 1.0 && v->accept(800.0) > 0.0, "%s: the rule's ends", v->name);
    lw_chain *c = gauss_chain(T, 77), *m = gauss_chain(T, 77);
    c->accept = v->accept;
    batch_mean m1[NV], m2[NV];
    sample_gaussian(c, T, m1, m2);
    check_gaussian(v->name, m1, m2, T);
    sample_gaussian(m, T, m1, m2);
    for (int k = 0; k < 2; k++) {
      const double rate = (double)c->stats[k].accepted / (double)c->stats[k].proposed,
                   rate_m = (double)m->stats[k].accepted / (double)m->stats[k].proposed;
      cr_assert(rate > 0.05 && rate <= rate_m, "%s, move %d: took %g of its proposals, Metropolis %g", v->name, k,
                rate, rate_m);
    }
    gauss_chain_free(c);
    gauss_chain_free(m);
  }
  cr_assert(rules >= 1, "no chain of its own rule in the table");
  const lw_driver_type *b = &lw_driver_barker;
  cr_assert(b->accept(INFINITY) == 1.0 && b->accept(0.0) == 0.5 && b->accept(800.0) == 1.0);
  cr_assert(fabs(b->accept(1.5) - exp(1.5) / (1.0 + exp(1.5))) < 1e-15 &&
            fabs(b->accept(-2.0) - 1.0 / (1.0 + exp(2.0))) < 1e-15);
}

/* A proposal a row could not evaluate for want of memory stops the chain
** (LW_ENOMEM), where its NaN was counted as an undefined energy and the run
** went on another way: the spline row's walk under memory pressure. */
Test(system, a_proposal_out_of_memory_stops_the_chain)
{
  lw_chain *c = gauss_chain(0.7, 7);
  gs_proposed = 0;
  gs_nomem_at = 3 * NV + 2;
  cr_assert_eq(lw_chain_sweep(c), LW_OK);
  cr_assert_eq(lw_chain_sweep(c), LW_OK);
  cr_assert_eq(lw_chain_sweep(c), LW_OK);
  cr_assert_eq(lw_chain_sweep(c), LW_ENOMEM);
  long proposed = 0;
  for (int k = 0; k < 2; k++) {
    cr_assert_eq(c->stats[k].nan, 0, "counted as an undefined energy");
    proposed += (long)c->stats[k].proposed;
  }
  cr_assert_eq(proposed, 3 * NV + 1, "the failed proposal counted");
  gs_nomem_at = 0;
  gauss_chain_free(c);
}

Test(system, tempering_samples_every_rung_of_a_test_row)
{
  enum { R = 4 };
  double ladder[R] = {0.25, 0.5, 1.0, 2.0};
  lw_error err;
  lw_tempering *pt = lw_tempering_new(R, ladder, 77, &err);
  cr_assert_not_null(pt);
  lw_chain *c[R];
  for (int k = 0; k < R; k++) c[k] = gauss_chain(ladder[k], 100 + (unsigned long)k);
  const long per = 10000;
  batch_mean m1[R][NV], m2[R][NV];
  memset(m1, 0, sizeof m1);
  memset(m2, 0, sizeof m2);
  for (int k = 0; k < R; k++)
    for (int i = 0; i < NV; i++) m1[k][i].per = m2[k][i].per = per;
  for (long s = -1000; s < BATCHES * per; s++) {
    double e[R], t[R];
    int swapped[R - 1];
    for (int k = 0; k < R; k++) {
      lw_chain_sweep(c[k]);
      e[k] = lw_system_total(c[k]->sys);
      t[k] = c[k]->temperature;
    }
    /* what lw_anneal does: the rungs keep their chains, the systems move */
    lw_tempering_exchange(pt, e, t, swapped);
    for (int k = 0; k + 1 < R; k++)
      if (swapped[k]) {
        lw_system *x = c[k]->sys;
        c[k]->sys = c[k + 1]->sys;
        c[k + 1]->sys = x;
      }
    if (s < 0) continue;
    for (int k = 0; k < R; k++) {
      const gs_state *st = c[k]->sys->state;
      for (int i = 0; i < NV; i++) {
        double z = st->x[i] / sqrt(ladder[k] / stiffness[i]);
        bm_add(&m1[k][i], z);
        bm_add(&m2[k][i], z * z);
      }
    }
  }
  for (int k = 0; k < R; k++) {
    char what[32];
    snprintf(what, sizeof what, "rung %d", k);
    check_gaussian(what, m1[k], m2[k], ladder[k]);
  }
  for (int k = 0; k + 1 < R; k++) cr_assert(pt->accepted[k] > 0, "rungs %d and %d never swapped", k, k + 1);
  cr_assert(pt->round_trips > 10, "%lu round trips", pt->round_trips);
  for (int k = 0; k < R; k++) gauss_chain_free(c[k]);
  lw_tempering_free(pt);
}

Test(system, a_row_saves_and_loads_its_state)
{
  lw_chain *c = gauss_chain(1.0, 5);
  for (int s = 0; s < 10; s++) lw_chain_sweep(c);
  char dir[64], path[128];
  cr_assert_eq(lw_test_dir_make(dir, "gsave"), 0);
  snprintf(path, sizeof path, "%s/state.lw", dir);
  lw_error err;
  lw_ckpt_writer w;
  cr_assert_eq(lw_ckpt_begin(&w, path, LW_STATE_HEADER, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(gauss_type.save(c->sys->state, &w, "system gauss", &err), LW_OK);
  cr_assert_eq(lw_ckpt_commit(&w, &err), LW_OK, "%s", err.msg);
  lw_state st = {.scene = "scene.ini"};
  cr_assert_eq(lw_ckpt_read(&st.doc, path, &err), LW_OK, "%s", err.msg);
  gs_state *back = gauss_type.load(NULL, &st, "system gauss", path, &err);
  cr_assert_not_null(back, "%s", err.msg);
  const gs_state *now = c->sys->state;
  for (int i = 0; i < NV; i++) cr_assert_eq(back->x[i], now->x[i], "x%d does not survive a save and load", i);
  gs_state_free(back);
  lw_state_clear(&st);
  lw_test_dir_remove(dir);
  gauss_chain_free(c);
}

Test(system, the_table_starts_with_splines_and_finds_rows_by_name)
{
  cr_assert_eq(lw_system_types[0], lw_system_find("splines"));
  cr_assert_str_eq(lw_system_types[0]->name, "splines");
  cr_assert_null(lw_system_find("gauss"), "a test row is not in the library's table");
  cr_assert_null(lw_system_find(""));
  lw_error err;
  for (int k = 0; lw_system_types[k]; k++) {
    const lw_system_type *t = lw_system_types[k];
    cr_assert(t->n_moves >= 1 && t->n_terms >= 1, "%s: %d move kinds, %d terms", t->name, t->n_moves, t->n_terms);
    cr_assert(lw_system_row_fits(t, &err), "%s: %s", t->name, err.msg);
    cr_assert(strstr(lw_system_names(), t->name));
  }
  /* and the rows a scene's moves choose */
  const lw_system_type *more[] = {&lw_system_splines_td, &lw_system_splines_tdj, &lw_system_particles_grow};
  for (size_t k = 0; k < sizeof more / sizeof more[0]; k++)
    cr_assert(lw_system_row_fits(more[k], &err), "%s: %s", more[k]->name, err.msg);
  /* a row past the arrays is refused, naming what does not fit */
  lw_system_type big = gauss_type;
  big.n_observables = LW_OBSERVABLES_MAX + 1;
  cr_assert_not(lw_system_row_fits(&big, &err));
  cr_assert(strstr(err.msg, "the gauss system's row has 2 move kinds, 2 terms and 9 observables; at most"), "%s",
            err.msg);
  /* a term named as a driver's column (trace.csv got two "total"), or two
  ** terms of one name */
  static const char *const total[] = {"total", "y"}, *const twice[] = {"x", "x"};
  lw_system_type named = gauss_type;
  named.term_names = total;
  cr_assert_not(lw_system_row_fits(&named, &err));
  cr_assert(strstr(err.msg, "the gauss system's term 'total' has the name of a column the drivers write"), "%s",
            err.msg);
  named.term_names = twice;
  cr_assert_not(lw_system_row_fits(&named, &err));
  cr_assert(strstr(err.msg, "two terms named 'x'"), "%s", err.msg);
  /* a member the drivers call without asking (a row without energy crashed
  ** `linewise energy`), or an optional one without its partners */
  lw_system_type lacking = gauss_type;
  lacking.energy = NULL;
  cr_assert_not(lw_system_row_fits(&lacking, &err));
  cr_assert(strstr(err.msg, "the gauss system's row has no energy (include/linewise/system.h"), "%s", err.msg);
  lacking = gauss_type;
  lacking.defer = gs_defer;
  cr_assert_not(lw_system_row_fits(&lacking, &err));
  cr_assert(strstr(err.msg, "has no finish beside defer"), "%s", err.msg);
}

Test(system, an_unknown_system_exits_2_naming_file_line_and_key)
{
  char dir[64];
  cr_assert_eq(lw_test_dir_make(dir, "sys"), 0);
  cr_assert_eq(lw_test_sh("printf '[scene]\\nwidth = 50\\nsystem = cloth\\n' > %s/s.ini", dir), 0);
  cr_assert_eq(lw_test_sh("%s run %s/s.ini --out %s/out --quiet 2> %s/err.txt", getenv("LW_BIN"), dir, dir, dir), 2);
  /* the names from the table, so a new row keeps this test */
  cr_assert_eq(lw_test_sh("grep -qF \"s.ini:3: key 'scene.system': expected one of %s, got 'cloth'\" %s/err.txt",
                          lw_system_names(), dir), 0);
  cr_assert_neq(lw_test_sh("test -e %s/out", dir), 0, "nothing is written for a bad scene");
  /* the energy command reads a run directory's system the same way */
  cr_assert_eq(lw_test_sh("mkdir %s/r && cp %s/s.ini %s/r/scene.ini && printf 'linewise-state 1\nscene scene.ini\n"
                          "seed 1\nsweep 0\nsplines 0\nend\n' > %s/r/state.lw", dir, dir, dir, dir), 0);
  cr_assert_eq(lw_test_sh("%s energy %s/r > %s/out.txt 2> %s/err.txt", getenv("LW_BIN"), dir, dir, dir), 2);
  cr_assert_eq(lw_test_sh("grep -q 'scene.ini:3: key .scene.system.' %s/err.txt && ! test -s %s/out.txt", dir, dir),
               0);
  lw_test_dir_remove(dir);
}

/* The drift a recomputation reports is against the terms' sizes: terms of
** +-6e10 that leave a total of 3 carry an absolute rounding near 1e-5, which
** against the total read as 3e-6 (a scene that had it reported 7e-6), and
** against the terms is 1e-16.  A real change keeps its size, and a sum that
** is not finite counts only when it changed. */
Test(system, drift_is_measured_against_the_terms_sizes)
{
  const double run[3] = {6e10, -6e10 + 3.0, 0.0}, fresh[3] = {6e10 + 1e-5, -6e10 + 3.0, 0.0};
  double d = lw_system_drift(run, fresh, 3);
  cr_assert(d > 0.0 && d < 1e-15, "drift %g", d);
  const double moved[2] = {2.0, 1.0}, was[2] = {1.0, 1.0};
  cr_assert_float_eq(lw_system_drift(was, moved, 2), 1.0 / 3.0, 1e-15);
  const double tiny_a[1] = {1e-3}, tiny_b[1] = {2e-3}; /* below 1, the scale is 1 */
  cr_assert_float_eq(lw_system_drift(tiny_a, tiny_b, 1), 1e-3, 1e-15);
  const double inf[1] = {INFINITY}, fin[1] = {1.0};
  cr_assert_eq(lw_system_drift(inf, inf, 1), 0.0);
  cr_assert(isinf(lw_system_drift(fin, inf, 1)) && isinf(lw_system_drift(inf, fin, 1)));
}
