/*
** test_rows.c -- the contract every row of the system table keeps
** (system.h), checked through the row alone on a bundled scene of each
** system and each of its trans-dimensional variants, so that a new row
** added to lw_system_types[] is held to it by adding one line here.
**
** What a driver relies on, and what is checked:
**   - a proposal changes nothing (the total before and after it agree);
**   - a commit moves the running total by exactly the dE the proposal
**     returned (with delayed acceptance: the stand-in's dE plus what
**     finish() returned), and the terms add up to the total;
**   - a from-scratch refresh agrees with the running terms (drift < 1e-9 of
**     the terms' size) after every few hundred commits of a walk that takes
**     most finite proposals, uphill too, so states far from the placement's
**     are visited;
**   - a copy evaluates the same proposal from the same stream to the same
**     bits;
**   - save then load gives the same terms, and the loaded state saves to the
**     same bytes; energy() of the saved file agrees with the refreshed terms;
**   - where there is a gradient: it matches central differences of the
**     total, and set_coords back to the start restores the energy;
**   - where there is inertia: mass_apply undoes mass_solve on the free
**     coordinates, and mass_solve gives 0 at the held ones.
**
** The tolerances: 1e-9 relative to the terms' size for sums that agree
** up to rounding (a few hundred additions of terms of that size leave about
** 1e-13).  The differences use h = 1e-4 (mm, or the particles' units)
** against 1e-4 of the gradient's largest entry: the pair term's sample
** weights are floats (pair.h), which makes its energy a step function of a
** node with steps of about 1e-9 on minimal.ini (3e-9 / 2h = 1.5e-5 of
** noise), and the truncation h^2 f''' / 6 is about 2e-5 of a near pair's
** force on flow.ini; a wrong term of the gradient is off by its own size.
*/
#include <criterion/criterion.h>
#include <criterion/parameterized.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/anneal.h"
#include "linewise/ckpt.h"
#include "linewise/state.h"
#include "linewise/sys_particles.h"
#include "linewise/sys_splines.h"
#include "linewise/system.h"
#include "testutil.h"

/* A scene of the bundled files, with overrides, and what to expect. */
typedef struct {
  const char *scene;     /* under params/ */
  const char *set[6];    /* overrides, NULL-terminated */
  long commits;          /* accepted proposals to walk */
  const char *run_scene; /* the run loop's scene where the case's own runs no chain (NULL: scene, set) */
  const char *run_set[4]; /* its overrides */
} row_case;

static const row_case cases[] = {
    {"minimal.ini", {"init.splines=8", NULL}, 3000, NULL, {NULL}},
    {"flow.ini", {"init.splines=30", NULL}, 3000, NULL, {NULL}},
    {"minimal.ini", {"init.splines=8", "moves.fixed_count=0", NULL}, 3000, NULL, {NULL}},
    {"minimal.ini", {"init.splines=8", "moves.fixed_count=0", "moves.split=0.2", "moves.join=0.2", NULL}, 3000, NULL,
     {NULL}},
    {"particles-sheet.ini", {"particles.count=19", NULL}, 3000, NULL, {NULL}},
    {"particles-grow.ini", {NULL}, 3000, NULL, {NULL}},
    {"lj13.ini", {NULL}, 3000, NULL, {NULL}},
    {"wire.ini", {NULL}, 2000, "wire-ladder.ini", {"anneal.sweeps=40000", "output.checkpoint_every=10000", NULL}},
};
#define N_CASES (sizeof cases / sizeof cases[0])

typedef struct {
  const lw_system_type *t;
  lw_params p;
  void *setup, *state, *prop;
  double weight[LW_MOVES_MAX], step[LW_MOVES_MAX], target[LW_MOVES_MAX];
  char what[160];
} row_run;

static void row_open(row_run *r, const row_case *c)
{
  lw_error err;
  char path[LW_PATH_MAX];
  snprintf(path, sizeof path, "%s/params/%s", lw_test_root(), c->scene);
  snprintf(r->what, sizeof r->what, "%s", c->scene);
  cr_assert_eq(lw_params_read(&r->p, path, &err), LW_OK, "%s", err.msg);
  for (int k = 0; c->set[k]; k++) {
    cr_assert_eq(lw_params_set(&r->p, c->set[k], &err), LW_OK, "%s", err.msg);
    snprintf(r->what + strlen(r->what), sizeof r->what - strlen(r->what), " %s", c->set[k]);
  }
  cr_assert_eq(lw_params_resolve(&r->p, &err), LW_OK, "%s", err.msg);
  r->t = lw_system_of(&r->p, &err);
  cr_assert_not_null(r->t, "%s: %s", r->what, err.msg);
  r->setup = r->t->setup_new(&r->p, &err);
  cr_assert_not_null(r->setup, "%s: %s", r->what, err.msg);
  r->state = r->t->state_new(r->setup, &r->p, 11, &err);
  cr_assert_not_null(r->state, "%s: %s", r->what, err.msg);
  r->prop = r->t->proposal_new(r->state, &err);
  cr_assert_not_null(r->prop, "%s: %s", r->what, err.msg);
  r->t->moves(&r->p, r->weight, r->step, r->target);
}

static void row_close(row_run *r)
{
  r->t->proposal_free(r->prop);
  r->t->state_free(r->state);
  r->t->setup_free(r->setup);
}

/* The terms' sum, their size and the running total. */
static double terms_of(const row_run *r, const void *state, double *term, double *size)
{
  r->t->terms(state, term);
  double sum = 0.0, s = 0.0;
  for (int k = 0; k < r->t->n_terms; k++) {
    sum += term[k];
    s += fabs(term[k]);
  }
  *size = fmax(s, 1.0);
  return sum;
}

static int draw_kind(const row_run *r, gsl_rng *rng)
{
  double all = 0.0;
  for (int k = 0; k < r->t->n_moves; k++) all += r->weight[k];
  double u = gsl_rng_uniform(rng) * all;
  int k = 0;
  while (k < r->t->n_moves - 1 && u >= r->weight[k]) u -= r->weight[k++];
  return k;
}

/* One proposal, from the row's propose or propose_at; dE. */
static double propose(const row_run *r, void *state, void *prop, int kind, gsl_rng *rng, int *forbidden)
{
  *forbidden = 0;
  const size_t n = r->t->sweep_size(state);
  if (r->t->propose_at && n > 0 && kind < (r->t->n_domain_moves ? r->t->n_domain_moves : r->t->n_moves)) {
    const size_t site = gsl_rng_uniform_int(rng, n);
    return r->t->propose_at(state, prop, kind, site, r->step[kind], rng, forbidden);
  }
  return r->t->propose(state, prop, kind, r->step[kind], rng, forbidden);
}

/* The walk: every finite proposal is taken with probability 1/2 (downhill
** always), delayed acceptance on for half of them where the row has it. */
static void walk(row_run *r, long commits, gsl_rng *rng)
{
  const lw_system_type *t = r->t;
  double term[LW_SYSTEM_TERMS_MAX], fresh[LW_SYSTEM_TERMS_MAX], size;
  long done = 0, tries = 0;
  while (done < commits && tries < 50 * commits) {
    tries++;
    if (t->sweep_size(r->state) == 0) break;
    const int kind = draw_kind(r, rng), defer = t->defer && gsl_rng_uniform(rng) < 0.5;
    if (t->defer) t->defer(r->prop, defer);
    const double before = t->total(r->state);
    int forbidden;
    double dE = propose(r, r->state, r->prop, kind, rng, &forbidden);
    cr_assert(t->total(r->state) == before, "%s: a proposal of kind %s changed the total", r->what,
              t->move_names[kind]);
    /* (a move whose reverse is impossible the chain never takes: the last
    ** particle's death) */
    const double lr = t->log_ratio ? t->log_ratio(r->prop) : 0.0;
    if (forbidden || !isfinite(dE) || !(lr > -INFINITY)) continue;
    if (dE > 0.0 && gsl_rng_uniform(rng) < 0.5) continue;
    if (t->finish) {
      int nomem = 0;
      const double d2 = t->finish(r->state, r->prop, &nomem);
      cr_assert_eq(nomem, 0, "%s: finish() ran out of memory", r->what);
      if (!isfinite(d2)) continue;
      cr_assert(defer || d2 == 0.0, "%s: finish() returned %g with nothing deferred", r->what, d2);
      dE += d2;
    }
    cr_assert_eq(t->commit(r->state, r->prop), LW_OK);
    if (t->sweep_end && done % 97 == 0) cr_assert_eq(t->sweep_end(r->state), LW_OK);
    done++;
    const double sum = terms_of(r, r->state, term, &size), after = t->total(r->state);
    cr_assert(fabs(after - before - dE) <= 1e-9 * size, "%s: commit %ld of kind %s moved the total by %.17g, "
              "its proposal said %.17g", r->what, done, t->move_names[kind], after - before, dE);
    cr_assert(fabs(sum - after) <= 1e-9 * size, "%s: terms add to %.17g, the total is %.17g", r->what, sum, after);
    if (done % 300 == 0 || done == commits) {
      cr_assert_eq(t->refresh(r->state), LW_OK);
      terms_of(r, r->state, fresh, &size);
      const double drift = lw_system_drift(term, fresh, t->n_terms);
      cr_assert(drift <= 1e-9, "%s: after %ld commits a refresh moved the energy by %g of its terms", r->what, done,
                drift);
    }
  }
  cr_assert(done >= commits / 2, "%s: only %ld of %ld tries committed: the walk tests little", r->what, done, tries);
}

/* A copy proposes the same move from the same stream to the same bits. */
static void check_copy(row_run *r, gsl_rng *rng)
{
  lw_error err;
  void *copy = r->t->state_copy(r->state, &err);
  cr_assert_not_null(copy, "%s", err.msg);
  void *prop2 = r->t->proposal_new(copy, &err);
  cr_assert_not_null(prop2, "%s", err.msg);
  cr_assert(r->t->total(copy) == r->t->total(r->state), "%s: a copy's total differs", r->what);
  for (int k = 0; k < 50; k++) {
    const int kind = draw_kind(r, rng);
    gsl_rng *twin = gsl_rng_clone(rng);
    int f1, f2;
    if (r->t->defer) {
      r->t->defer(r->prop, 0);
      r->t->defer(prop2, 0);
    }
    const double a = propose(r, r->state, r->prop, kind, rng, &f1), b = propose(r, copy, prop2, kind, twin, &f2);
    gsl_rng_free(twin);
    cr_assert(f1 == f2 && (a == b || (isnan(a) && isnan(b))), "%s: kind %s: the state says %.17g (%d), its copy "
              "%.17g (%d)", r->what, r->t->move_names[kind], a, f1, b, f2);
  }
  r->t->proposal_free(prop2);
  r->t->state_free(copy);
}

static void save(const row_run *r, const void *state, const char *path)
{
  lw_error err;
  lw_ckpt_writer w;
  lw_state head = {.scene = "scene.ini", .seed = 11, .sweep = 3};
  char section[64];
  snprintf(section, sizeof section, "system %s", r->t->name);
  cr_assert_eq(lw_ckpt_begin(&w, path, LW_STATE_HEADER, &err), LW_OK, "%s", err.msg);
  lw_state_put_header(&w, &head);
  cr_assert_eq(r->t->save(state, &w, section, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(lw_ckpt_commit(&w, &err), LW_OK, "%s", err.msg);
}

/* save, load, save again: the same bytes; the terms agree, and energy()
** of the file agrees with them. */
static void check_save_load(row_run *r)
{
  lw_error err;
  char dir[64], a[128], b[128], section[64];
  cr_assert_eq(lw_test_dir_make(dir, "rows"), 0);
  snprintf(a, sizeof a, "%s/a.lw", dir);
  snprintf(b, sizeof b, "%s/b.lw", dir);
  snprintf(section, sizeof section, "system %s", r->t->name);
  cr_assert_eq(r->t->refresh(r->state), LW_OK);
  double term[LW_SYSTEM_TERMS_MAX], back[LW_SYSTEM_TERMS_MAX], scratch[LW_SYSTEM_TERMS_MAX], size, s2;
  terms_of(r, r->state, term, &size);
  save(r, r->state, a);
  lw_state st = {0};
  cr_assert_eq(lw_state_read(&st, a, &err), LW_OK, "%s: %s", r->what, err.msg);
  /* (before load, which may take what lw_state_read read); err as a caller
  ** may hand it over, unset: the spline row read its code, which the energy
  ** sets only on failure, and refused a valid state under clang and -O0 */
  memset(&err, 0x5a, sizeof err);
  err.msg[sizeof err.msg - 1] = '\0';
  const double total = r->t->energy(r->setup, &st, a, scratch, &err);
  cr_assert(isfinite(total), "%s: energy(): %s", r->what, err.msg);
  for (int k = 0; k < r->t->n_terms; k++)
    cr_assert(fabs(scratch[k] - term[k]) <= 1e-9 * size, "%s: energy() gives term %s %.17g, the state %.17g",
              r->what, r->t->term_names[k], scratch[k], term[k]);
  void *loaded = r->t->load(r->setup, &st, section, a, &err);
  cr_assert_not_null(loaded, "%s: %s", r->what, err.msg);
  terms_of(r, loaded, back, &s2);
  for (int k = 0; k < r->t->n_terms; k++)
    cr_assert(fabs(back[k] - term[k]) <= 1e-12 * size, "%s: term %s is %.17g loaded, %.17g saved", r->what,
              r->t->term_names[k], back[k], term[k]);
  save(r, loaded, b);
  cr_assert_eq(lw_test_sh("cmp -s %s %s", a, b), 0, "%s: a loaded state saves to other bytes (%s, %s)", r->what, a,
               b);
  r->t->state_free(loaded);
  lw_state_clear(&st);
  lw_test_dir_remove(dir);
}

/* The gradient against central differences of the total, at a dozen
** coordinates it says move the energy, and set_coords back restores it.
** A row with a constraint (the particles' unit quaternions) takes each
** trial back onto it, so the differences are compared with g . (y+ - y-),
** the trials' own displacement: its even part (the projection's, O(h^2))
** cancels, and so the comparison stays O(h^3) as for a free coordinate. */
static void check_gradient(row_run *r, gsl_rng *rng)
{
  const lw_system_type *t = r->t;
  if (!t->gradient) return;
  lw_error err;
  const size_t n = t->n_coords(r->state);
  double *x = malloc(n * sizeof *x), *g = malloc(n * sizeof *g), *y[2] = {malloc(n * sizeof *x), malloc(n * sizeof *x)};
  cr_assert(x && g && y[0] && y[1]);
  t->get_coords(r->state, x);
  const double e0 = t->gradient(r->state, g, &err);
  cr_assert(isfinite(e0), "%s: gradient: %s", r->what, err.msg);
  cr_assert(fabs(e0 - t->total(r->state)) <= 1e-9 * fmax(fabs(e0), 1.0), "%s: gradient() says E = %.17g, total() "
            "%.17g", r->what, e0, t->total(r->state));
  double gmax = 0.0;
  for (size_t i = 0; i < n; i++) gmax = fmax(gmax, fabs(g[i]));
  cr_assert(gmax > 0.0, "%s: a zero gradient checks nothing", r->what);
  int checked = 0;
  for (int tries = 0; checked < 12 && tries < 1000; tries++) {
    const size_t i = gsl_rng_uniform_int(rng, n);
    if (g[i] == 0.0) continue;
    const double h = 1e-4;
    double e[2];
    for (int s = 0; s < 2; s++) {
      memcpy(y[s], x, n * sizeof *x);
      y[s][i] += s ? -h : h;
      if (t->constrain) t->constrain(r->state, x, y[s], NULL);
      cr_assert_eq(t->set_coords(r->state, y[s], &err), LW_OK, "%s", err.msg);
      e[s] = t->total(r->state);
    }
    if (!isfinite(e[0]) || !isfinite(e[1])) continue;
    double want = 0.0, moved = 0.0;
    for (size_t j = 0; j < n; j++) {
      want += g[j] * (y[0][j] - y[1][j]);
      moved += fabs(y[0][j] - y[1][j]);
    }
    cr_assert(fabs(e[0] - e[1] - want) <= 1e-4 * gmax * moved, "%s: coordinate %zu: the gradient says E moves by "
              "%.10g, the differences %.10g", r->what, i, want, e[0] - e[1]);
    checked++;
  }
  cr_assert_eq(t->set_coords(r->state, x, &err), LW_OK, "%s", err.msg);
  cr_assert(fabs(t->total(r->state) - e0) <= 1e-12 * fmax(fabs(e0), 1.0), "%s: back at the start E = %.17g, "
            "was %.17g", r->what, t->total(r->state), e0);
  cr_assert(checked >= 6, "%s: only %d coordinates checked", r->what, checked);
  free(x);
  free(g);
  free(y[0]);
  free(y[1]);
}

static void check_mass(row_run *r, gsl_rng *rng)
{
  const lw_system_type *t = r->t;
  if (!t->mass_new) return;
  lw_error err;
  const size_t n = t->n_coords(r->state);
  void *m = t->mass_new(r->state, &r->p, r->p.dyn_rho > 0.0 ? r->p.dyn_rho : 1.0, &err);
  cr_assert_not_null(m, "%s: %s", r->what, err.msg);
  double *x = malloc(n * sizeof *x), *b = malloc(n * sizeof *b), *v = malloc(n * sizeof *v),
         *b2 = malloc(n * sizeof *b2);
  cr_assert(x && b && v && b2);
  t->get_coords(r->state, x);
  cr_assert_eq(t->mass_at(m, x, &err), LW_OK, "%s", err.msg);
  double bmax = 0.0;
  for (size_t i = 0; i < n; i++) {
    b[i] = t->mass_pinned(m, i) ? 0.0 : gsl_rng_uniform(rng) - 0.5;
    bmax = fmax(bmax, fabs(b[i]));
  }
  t->mass_solve(m, b, v);
  t->mass_apply(m, v, b2);
  for (size_t i = 0; i < n; i++) {
    if (t->mass_pinned(m, i)) {
      cr_assert_eq(v[i], 0.0, "%s: a held coordinate %zu moves (%g)", r->what, i, v[i]);
      continue;
    }
    cr_assert(fabs(b2[i] - b[i]) <= 1e-9 * bmax, "%s: M M^-1 b at %zu: %.17g, b %.17g", r->what, i, b2[i], b[i]);
  }
  t->mass_free(m);
  free(x);
  free(b);
  free(v);
  free(b2);
}

static void check_row(const row_case *c)
{
  row_run r = {0};
  row_open(&r, c);
  lw_error err;
  cr_assert(lw_system_row_fits(r.t, &err), "%s", err.msg);
  gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(rng, 5);
  if (r.t->sweep_size(r.state) > 0 && r.t->n_moves > 0) {
    walk(&r, c->commits, rng);
    check_copy(&r, rng);
  }
  check_save_load(&r);
  check_gradient(&r, rng);
  check_mass(&r, rng);
  gsl_rng_free(rng);
  row_close(&r);
}

ParameterizedTestParameters(rows, every_row_keeps_the_contract)
{
  static int index[N_CASES];
  for (size_t k = 0; k < N_CASES; k++) index[k] = (int)k;
  return cr_make_param_array(int, index, N_CASES);
}

ParameterizedTest(int *k, rows, every_row_keeps_the_contract) { check_row(&cases[*k]); }

/* One case driven by the run loop into dir: two rungs of tempering, 24
** sweeps (or the case's run scene as it sets) on `threads` threads;
** stopped after sweep stop_at (>= 0) with a checkpoint, the run freed and
** resumed from its directory to the end. */
static void run_case(const row_case *c, const char *dir, int threads, long stop_at)
{
  lw_params p;
  lw_error err;
  char path[LW_PATH_MAX];
  snprintf(path, sizeof path, "%s/params/%s", lw_test_root(), c->run_scene ? c->run_scene : c->scene);
  cr_assert_eq(lw_params_read(&p, path, &err), LW_OK, "%s", err.msg);
  static const char *const rungs[] = {"tempering.replicas=2", "anneal.sweeps=24", "output.checkpoint_every=1000",
                                      NULL};
  const char *const *own = c->run_scene ? c->run_set : c->set, *const *run = c->run_scene ? NULL : rungs;
  for (int k = 0; own[k]; k++) cr_assert_eq(lw_params_set(&p, own[k], &err), LW_OK, "%s", err.msg);
  for (int k = 0; run && run[k]; k++) cr_assert_eq(lw_params_set(&p, run[k], &err), LW_OK, "%s", err.msg);
  cr_assert_eq(lw_params_resolve(&p, &err), LW_OK, "%s", err.msg);
  omp_set_num_threads(threads);
  lw_anneal a;
  cr_assert_eq(lw_anneal_start(&a, &p, dir, &err), LW_OK, "%s: %s", c->scene, err.msg);
  for (int part = 0; part < 2; part++) {
    while (!lw_anneal_done(&a) && (part || stop_at < 0 || a.sweep < stop_at))
      cr_assert_eq(lw_anneal_sweep(&a, &err), LW_OK, "%s: %s", c->scene, err.msg);
    if (lw_anneal_done(&a)) {
      cr_assert_eq(lw_anneal_finish(&a, &err), LW_OK, "%s: %s", c->scene, err.msg);
      lw_anneal_free(&a);
      break;
    }
    cr_assert_eq(lw_anneal_checkpoint(&a, &err), LW_OK, "%s: %s", c->scene, err.msg);
    lw_anneal_free(&a);
    cr_assert_eq(lw_anneal_resume(&a, dir, -1, &err), LW_OK, "%s: %s", c->scene, err.msg);
  }
  omp_set_num_threads(1);
}

/* What the contract above cannot see, since it drives one state: the run
** loop's invariants for every row.  The same state.lw and trace.csv on one
** thread and on two, and from a run stopped at sweep 10 and resumed.  A
** row's scratch shared by its replicas (a static array) kept the contract
** and made a run's threads differ (a helper's mutation, 2026-12-06); two
** threads find such a race only where they overlap in time: two rungs of
** 24 sweeps on two cores do for the particles (3 of 3 runs); the D-NURBS
** wire, whose case runs the dynamics, runs wire-ladder.ini's three rungs
** for 40,000 sweeps of its ten coordinates (a scratch of two numbers shared
** by the rungs was found in 8 of 8 runs, in 5 of 8 at 4,000). */
ParameterizedTestParameters(rows, every_row_runs_alike_on_any_threads_and_across_a_resume)
{
  static int index[N_CASES];
  for (size_t k = 0; k < N_CASES; k++) index[k] = (int)k;
  return cr_make_param_array(int, index, N_CASES);
}

ParameterizedTest(int *k, rows, every_row_runs_alike_on_any_threads_and_across_a_resume)
{
  char dir[64];
  cr_assert_eq(lw_test_dir_make(dir, "rows"), 0);
  char d[3][96];
  for (int v = 0; v < 3; v++) snprintf(d[v], sizeof d[v], "%s/r%d", dir, v);
  run_case(&cases[*k], d[0], 1, -1);
  run_case(&cases[*k], d[1], 2, -1);
  run_case(&cases[*k], d[2], 2, 10);
  const char *same[] = {"state.lw", "trace.csv", "replica-1.lw"}; /* the last where the row writes one */
  for (int v = 1; v < 3; v++)
    for (int f = 0; f < 3; f++)
      cr_assert_eq(lw_test_sh("test ! -e %s/%s -a ! -e %s/%s || cmp -s %s/%s %s/%s", d[0], same[f], d[v], same[f],
                              d[0], same[f], d[v], same[f]),
                   0, "%s: %s differs %s", cases[*k].scene, same[f], v == 1 ? "on two threads" : "after a resume");
  lw_test_dir_remove(dir);
}

/* Every row of the table, and every variant a scene's moves choose, is
** among the cases above: a new row of the table is checked or this fails.
** The variants are listed by hand (a row's `variant` is a function of the
** parameters, not a list): a new variant is added here. */
Test(rows, every_row_of_the_table_has_a_case)
{
  const lw_system_type *seen[N_CASES];
  for (size_t k = 0; k < N_CASES; k++) {
    row_run r = {0};
    lw_error err;
    char path[LW_PATH_MAX];
    snprintf(path, sizeof path, "%s/params/%s", lw_test_root(), cases[k].scene);
    cr_assert_eq(lw_params_read(&r.p, path, &err), LW_OK, "%s", err.msg);
    for (int j = 0; cases[k].set[j]; j++) cr_assert_eq(lw_params_set(&r.p, cases[k].set[j], &err), LW_OK);
    cr_assert_eq(lw_params_resolve(&r.p, &err), LW_OK);
    seen[k] = lw_system_of(&r.p, &err);
    cr_assert_not_null(seen[k], "%s: %s", cases[k].scene, err.msg);
  }
  for (int k = 0; lw_system_types[k]; k++) {
    int found = 0;
    for (size_t j = 0; j < N_CASES; j++) found |= !strcmp(seen[j]->name, lw_system_types[k]->name);
    cr_assert(found, "the %s system has no case in tests/test_rows.c", lw_system_types[k]->name);
  }
  const lw_system_type *variants[] = {&lw_system_splines_td, &lw_system_splines_tdj, &lw_system_particles_grow};
  for (size_t v = 0; v < sizeof variants / sizeof *variants; v++) {
    int found = 0;
    for (size_t j = 0; j < N_CASES; j++) found |= seen[j] == variants[v];
    cr_assert(found, "a variant of the %s row has no case", variants[v]->name);
  }
}
