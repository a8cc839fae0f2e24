/*
** test_nurbs_weights.c -- nurbs.free_weights: the weights as coordinates
** s = log w of the D-NURBS row (sys_nurbs.h).  The gradient, the mass
** matrix and its derivative against finite differences of the energy and
** of the curve; the review's wire from weights != 1 under the leapfrog,
** undamped (energy kept) and damped (energy falling, weights bounded), set
** beside the review's reset of the weights to 1 after every step; Monte
** Carlo's weight move.
*/
#include <criterion/criterion.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/dynamics.h"
#include "linewise/mc.h"
#include "linewise/quench.h"
#include "linewise/sys_nurbs.h"
#include "testutil.h"

#define WEIGHTS "1 2 1 0.5 1 2 1"

typedef struct {
  lw_params p;
  lw_nurbs_setup *su;
  lw_system *sys;
  lw_nurbs_state *st;
  size_t nc; /* coordinates: 3 n */
} fwire;

/* The review's wire (test_wire.c) with free weights starting at `weights`
** (NULL: all 1), `gauss` points a span (the review's 10), each span cut
** into `refine` (nurbs.refine). */
static void fwire_open_refined(fwire *w, const char *weights, double gamma, int gauss, int refine)
{
  lw_params_defaults(&w->p);
  w->p.nb_refine = refine;
  strcpy(w->p.nb_points, "-5 5  -4.17 5  -2.5 5  0 5  2.5 5  4.17 5  5 5");
  strcpy(w->p.nb_knots, "0 0 0 0 0.25 0.5 0.75 1 1 1 1");
  if (weights) strcpy(w->p.nb_weights, weights);
  w->p.nb_order = 4;
  w->p.nb_alpha = 35;
  w->p.nb_beta = 10;
  w->p.nb_gauss = gauss;
  w->p.nb_fixed = 1;
  w->p.nb_free_weights = 1;
  w->p.dyn_rho = 30;
  w->p.dyn_gamma = gamma;
  w->p.dyn_gravity_y = -9.8;
  w->p.dyn_dt = 0.008;
  lw_error err = {0};
  w->su = lw_system_nurbs.setup_new(&w->p, &err);
  cr_assert_not_null(w->su, "%s", err.msg);
  w->sys = lw_system_wrap(&lw_system_nurbs, lw_system_nurbs.state_new(w->su, &w->p, 0, &err), &err);
  cr_assert_not_null(w->sys, "%s", err.msg);
  w->st = w->sys->state;
  w->nc = lw_system_nurbs.n_coords(w->st);
  cr_assert_eq(w->nc, 3 * w->su->curve->n);
}

static void fwire_open(fwire *w, const char *weights, double gamma, int gauss)
{
  fwire_open_refined(w, weights, gamma, gauss, 1);
}

static void fwire_close(fwire *w)
{
  lw_system_free(w->sys);
  lw_system_nurbs.setup_free(w->su);
}

/* Coordinates off the straight start: the free points moved in x and y by
** up to 0.3 m, the free log weights by up to 0.4. */
static void shaken(const fwire *w, double *x, uint64_t seed)
{
  rng_seed(seed);
  lw_system_nurbs.get_coords(w->st, x);
  for (size_t i = 0; i < w->nc; i++)
    if (!w->su->pin[i / 3]) x[i] += i % 3 == 2 ? urand(-0.4, 0.4) : urand(-0.3, 0.3);
}

Test(nurbs_weights, the_gradient_in_points_and_log_weights_matches_central_differences)
{
  fwire w;
  fwire_open(&w, WEIGHTS, 0, 10);
  lw_error err = {0};
  double x[32], g[32], xe[32];
  shaken(&w, x, 11);
  cr_assert_eq(lw_system_nurbs.set_coords(w.st, x, &err), LW_OK, "%s", err.msg);
  double e = lw_system_nurbs.gradient(w.st, g, &err), scale = 0.0;
  for (size_t i = 0; i < w.nc; i++) scale = fmax(scale, fabs(g[i]));
  for (size_t i = 0; i < w.nc; i++) {
    double h = 1e-5, ep, em;
    if (w.su->pin[i / 3]) { /* held: no force to follow */
      cr_assert_eq(g[i], 0.0, "held coordinate %zu", i);
      continue;
    }
    memcpy(xe, x, sizeof xe);
    xe[i] = x[i] + h;
    cr_assert_eq(lw_system_nurbs.set_coords(w.st, xe, &err), LW_OK);
    ep = lw_system_nurbs.total(w.st);
    xe[i] = x[i] - h;
    cr_assert_eq(lw_system_nurbs.set_coords(w.st, xe, &err), LW_OK);
    em = lw_system_nurbs.total(w.st);
    /* O(h^2) truncation and |E| eps / h rounding: both near 1e-7 of scale */
    cr_assert(fabs((ep - em) / (2 * h) - g[i]) <= 1e-6 * scale, "coordinate %zu: %.10g vs %.10g (E %g)", i,
              (ep - em) / (2 * h), g[i], e);
  }
  fwire_close(&w);
}

/* c(u) of the state's curve moved to x */
static void curve_at(fwire *w, const double *x, double u, double pt[2])
{
  lw_error err = {0};
  cr_assert_eq(lw_system_nurbs.set_coords(w->st, x, &err), LW_OK);
  lw_nurbs_eval(w->st->c, u, pt, NULL, NULL);
}

/* v' M v per unit density against int |dc/dt|^2 du with dc/dt the central
** difference of the curve along v, by 24-point Gauss on each span. */
static double kinetic_by_differences(fwire *w, const double *x, const double *v)
{
  gsl_integration_glfixed_table *t = gsl_integration_glfixed_table_alloc(24);
  const lw_nurbs *c = w->su->curve;
  double sum = 0.0, h = 1e-6, xp[32], xm[32];
  for (size_t i = 0; i < w->nc; i++) xp[i] = x[i] + h * v[i], xm[i] = x[i] - h * v[i];
  for (size_t s = (size_t)c->order - 1; s < c->n; s++)
    for (size_t q = 0; q < 24; q++) {
      double u, wq, a[2], b[2];
      gsl_integration_glfixed_point(c->knot[s], c->knot[s + 1], q, &u, &wq, t);
      curve_at(w, xp, u, a);
      curve_at(w, xm, u, b);
      double dx = (a[0] - b[0]) / (2 * h), dy = (a[1] - b[1]) / (2 * h);
      sum += wq * (dx * dx + dy * dy);
    }
  gsl_integration_glfixed_table_free(t);
  return sum;
}

static double vmv(const lw_system_type *t, void *mass, const double *x, const double *v, size_t nc)
{
  lw_error err = {0};
  double b[32], s = 0.0;
  cr_assert_eq(t->mass_at(mass, x, &err), LW_OK, "%s", err.msg);
  t->mass_apply(mass, v, b);
  for (size_t i = 0; i < nc; i++) s += v[i] * b[i];
  return s;
}

Test(nurbs_weights, the_mass_matrix_is_the_kinetic_energy_of_the_curve_and_mass_dx_its_derivative)
{
  fwire w;
  fwire_open(&w, WEIGHTS, 0, 24);
  const lw_system_type *t = &lw_system_nurbs;
  lw_error err = {0};
  void *mass = t->mass_new(w.st, &w.p, 1.0, &err);
  cr_assert_not_null(mass, "%s", err.msg);
  double x[32], v[32], d[32], xe[32];
  shaken(&w, x, 5);
  rng_seed(6);
  for (size_t i = 0; i < w.nc; i++) v[i] = w.su->pin[i / 3] ? 0.0 : urand(-1, 1);
  /* the integrand is rational: 10 Gauss points a span leave 4e-7 of it,
  ** 24 points (as the reference) rounding; the differences' error is
  ** (h |v|)^2 and eps / h, both below 1e-11 */
  double ref = kinetic_by_differences(&w, x, v), vs = 0.0;
  for (size_t i = 2; i < w.nc; i += 3) vs += v[i] * v[i];
  double m = vmv(t, mass, x, v, w.nc) - w.su->weight_inertia * vs;
  cr_assert(w.su->weight_inertia > 0.0);
  cr_assert(fabs(m - ref) <= 1e-9 * ref, "v'Mv - inertia %.12g, by differences %.12g", m, ref);
  /* mass_dx: d/dx 1/2 v' M(x) v at fixed v */
  cr_assert_eq(t->mass_at(mass, x, &err), LW_OK);
  t->mass_dx(mass, x, v, d);
  double scale = 0.0;
  for (size_t i = 0; i < w.nc; i++) scale = fmax(scale, fabs(d[i]));
  cr_assert(scale > 1e-2, "mass_dx vanishes (%g): the mass matrix does depend on the curve", scale);
  for (size_t i = 0; i < w.nc; i++) {
    double h = 1e-5;
    memcpy(xe, x, sizeof xe);
    xe[i] = x[i] + h;
    double p = vmv(t, mass, xe, v, w.nc);
    xe[i] = x[i] - h;
    double q = vmv(t, mass, xe, v, w.nc);
    cr_assert(fabs(0.25 * (p - q) / h - d[i]) <= 1e-6 * scale, "coordinate %zu: %.10g vs %.10g", i,
              0.25 * (p - q) / h, d[i]);
  }
  t->mass_free(mass);
  fwire_close(&w);
}

/* ---- the wire in motion: log weights against the review's reset ----------- */

typedef struct {
  double h0, dh;          /* H = T + E at the start, largest |H - h0| */
  double h_end;
  double s_lo, s_hi;      /* range of the free log weights */
  int stopped;            /* the step that failed, or -1 */
} motion;

/* steps of dt from rest (the weights as the scene has them); reset: the
** review's w = 1 (and wdot = 0) after every step, the motion of the points
** carried on as it is. */
static motion move_wire(fwire *w, double dt, int steps, int reset)
{
  lw_error err = {0};
  w->p.dyn_dt = dt;
  lw_dynamics *d = lw_dynamics_new(&lw_system_nurbs, w->st, &w->p, &err);
  cr_assert_not_null(d, "%s", err.msg);
  motion m = {d->energy, 0.0, d->energy, 0.0, 0.0, -1};
  double x[32];
  for (int k = 0; k < steps; k++) {
    if (lw_dynamics_step(d, &err)) {
      m.stopped = k;
      break;
    }
    if (reset) {
      lw_system_nurbs.get_coords(w->st, x);
      for (size_t i = 2; i < w->nc; i += 3) x[i] = d->pi[i] = 0.0;
      cr_assert_eq(lw_system_nurbs.set_coords(w->st, x, &err), LW_OK);
      cr_assert_eq(lw_dynamics_sync(d, &err), LW_OK, "%s", err.msg);
    }
    double h = d->energy + lw_dynamics_kinetic(d);
    m.dh = fmax(m.dh, fabs(h - m.h0));
    m.h_end = h;
    for (size_t i = 0; i < w->su->curve->n; i++)
      if (!w->su->pin[i]) m.s_lo = fmin(m.s_lo, w->st->s[i]), m.s_hi = fmax(m.s_hi, w->st->s[i]);
  }
  lw_dynamics_free(d);
  return m;
}

#define START "1 1.2 1 0.8 1 1.2 1"

Test(nurbs_weights, undamped_free_weights_keep_the_energy_the_reset_to_1_does_not)
{
  fwire w;
  fwire_open(&w, START, 0, 10);
  /* 2 s at dt = 1 ms: the weights' fast modes need it (docs/NURBS.md) */
  motion m = move_wire(&w, 0.001, 2000, 0);
  fwire_close(&w);
  fwire_open(&w, START, 0, 10);
  motion r = move_wire(&w, 0.001, 2000, 1);
  fwire_close(&w);
  cr_log_info("free weights: H %g, |dH| %g, s in [%g, %g]; reset: |dH| %g, H(2 s) %g", m.h0, m.dh, m.s_lo, m.s_hi,
              r.dh, r.h_end);
  cr_assert(m.stopped < 0 && r.stopped < 0, "steps failed: %d, %d (reset)", m.stopped, r.stopped);
  /* the leapfrog's energy error is bounded, O(dt^2): measured 0.32 % */
  cr_assert_lt(m.dh, 0.01 * m.h0, "free weights: H %g changed by %g", m.h0, m.dh);
  /* kept near 1 by the spring on s (measured: w in [0.56, 1.30]); without
  ** it the middle weight falls to 1e-15 in these 2 s (docs/NURBS.md) */
  cr_assert(m.s_lo > -1.0 && m.s_hi < 1.0 && m.s_hi > m.s_lo, "s in [%g, %g]", m.s_lo, m.s_hi);
  /* the reset is no motion of a Hamiltonian: H drops to the unit weights'
  ** energy at the first step and is pumped up after (measured: x 3.3) */
  cr_assert_gt(r.dh, 0.5 * m.h0, "the reset changed H by %g only (free weights: %g)", r.dh, m.dh);
}

Test(nurbs_weights, damped_free_weights_lose_energy_and_stay_positive_and_bounded)
{
  fwire w;
  fwire_open(&w, START, 5, 10);
  motion m = move_wire(&w, 0.001, 2000, 0);
  fwire_close(&w);
  cr_log_info("damped free weights: H %g -> %g, s in [%g, %g]", m.h0, m.h_end, m.s_lo, m.s_hi);
  cr_assert_lt(m.stopped, 0, "step %d failed", m.stopped);
  cr_assert_lt(m.h_end, 0.95 * m.h0, "H %g -> %g", m.h0, m.h_end);
  cr_assert(m.s_lo > -1.0 && m.s_hi < 1.0, "s in [%g, %g]", m.s_lo, m.s_hi);
}

/* Why the two keys beyond the review: without the spring a weight
** collapses, without the weights' own inertia the straight wire has a
** singular mass matrix and not even the first step converges. */
Test(nurbs_weights, without_weight_stiffness_a_weight_collapses_without_weight_inertia_no_step_is_taken)
{
  fwire w;
  fwire_open(&w, START, 0, 10);
  w.su->weight_stiffness = 0.0;
  cr_assert_eq(lw_system_nurbs.refresh(w.st), LW_OK);
  motion m = move_wire(&w, 0.001, 2000, 0);
  fwire_close(&w);
  cr_assert_lt(m.stopped, 0, "step %d failed", m.stopped);
  cr_assert_lt(m.s_lo, -10.0, "no collapse: s in [%g, %g]", m.s_lo, m.s_hi);
  fwire_open(&w, START, 0, 10);
  w.su->weight_inertia = 0.0;
  m = move_wire(&w, 0.001, 10, 0);
  fwire_close(&w);
  cr_assert_eq(m.stopped, 0, "the first step %s", m.stopped < 0 ? "converged" : "failed later");
}

/* ---- Monte Carlo's weight move -------------------------------------------- */

Test(nurbs_weights, annealing_with_weight_moves_ends_where_the_gradient_vanishes)
{
  fwire w;
  fwire_open(&w, START, 0, 10);
  double wt[LW_MOVES_MAX], st[LW_MOVES_MAX], tg[LW_MOVES_MAX], g[32];
  w.p.step_point = 0.05;
  lw_system_nurbs.moves(&w.p, wt, st, tg);
  cr_assert_gt(wt[1], 0.0, "free weights: the weight move is on");
  lw_error err = {0};
  lw_chain *c = lw_chain_new(w.sys, wt, st, tg, 7, &err);
  cr_assert_not_null(c, "%s", err.msg);
  c->tuning = 1;
  lw_system_nurbs.gradient(w.st, g, &err);
  double g0 = 0.0, g1 = 0.0;
  for (size_t i = 0; i < w.nc; i++)
    if (!w.su->pin[i / 3]) g0 = fmax(g0, fabs(g[i]));
  int sweeps = 20000;
  for (int s = 0; s < sweeps; s++) {
    c->temperature = pow(1e-12, (double)s / (sweeps - 1));
    cr_assert_eq(lw_chain_sweep(c), LW_OK);
  }
  cr_assert_gt(c->stats[1].accepted, 100, "weight moves accepted: %lu", c->stats[1].accepted);
  double before = lw_system_total(w.sys);
  cr_assert_eq(lw_system_nurbs.refresh(w.st), LW_OK);
  cr_assert(fabs(lw_system_total(w.sys) - before) <= 1e-9 * fabs(before), "running energy drifted to %.17g from "
            "%.17g", lw_system_total(w.sys), before);
  lw_system_nurbs.gradient(w.st, g, &err);
  for (size_t i = 0; i < w.nc; i++)
    if (!w.su->pin[i / 3]) g1 = fmax(g1, fabs(g[i]));
  cr_log_info("annealed with weights: max |dE/dx| %g (start %g)", g1, g0);
  cr_assert_lt(g1, 1e-4 * g0, "max |dE/dx| %g at the end, %g at the start", g1, g0);
  lw_chain_free(c);
  fwire_close(&w);
}

Test(nurbs_weights, the_quench_of_a_refined_wire_alternates_the_points_solve_and_l_bfgs)
{
  /* Refined 8 times (35 points, stiffness condition 1e7), from the straight
  ** start and weights of 1.2 and 0.8.  All weights 1 is a point of the free
  ** space with no weights term, so the free minimum lies at or below the
  ** frozen one, 3193.4015741514 at this refinement (tests/test_wire.c).
  ** L-BFGS alone stalled at 3214.7 (gradient 830); each round solves for
  ** the points at the present weights (minimize), then L-BFGS moves both. */
  fwire w;
  fwire_open_refined(&w, "1 1.2 1 0.8 1 1.2 1", 0, 10, 8);
  double *x0 = malloc(w.nc * sizeof *x0), *x1 = malloc(w.nc * sizeof *x1);
  lw_system_nurbs.get_coords(w.st, x0);
  lw_quench_opts o = {.tol = 1e-6, .max_iter = 2000, .stall = 0.05};
  lw_quench_report r;
  lw_error err = {0};
  cr_assert_eq(lw_quench_run(w.sys, &o, &r, &err), LW_OK, "%s", err.msg);
  cr_log_info("free weights, refined: %s after %d rounds, %ld iterations, gradient %g, energy %.10f",
              lw_quench_end_name(r.ended), r.rounds, r.iterations, r.gradient_after, r.energy_after);
  cr_assert_geq(r.rounds, 2);
  cr_assert_lt(r.energy_after, 3193.4015741514 + 1e-4, "energy %.10f", r.energy_after);
  lw_system_nurbs.get_coords(w.st, x1);
  for (size_t i = 0; i < w.nc; i++)
    if (w.su->pin[i / 3]) cr_assert(x1[i] == x0[i], "held coordinate %zu moved", i);
  free(x0);
  free(x1);
  fwire_close(&w);
}

/* Weights far apart turn the rational basis within about q^(-1/3) of a
** span's ends, q their ratio: ten Gauss points spread over a span stepped
** over the turn, and an anneal put the curve's bends there (a wire of
** weights 1e-4 read an elastic energy 18 times below its own, 1e10 times
** at 1e-12 from a state file).  The matrices' energy against an adaptive
** integral (GSL's QAG, 61 points) of 1/2 (alpha |c_u|^2 + beta |c_uu|^2) over each
** span, weights from 2 to 1e12 apart, the middle ones light or every
** other one. */
typedef struct {
  lw_nurbs *c;
  double alpha, beta;
} elastic_ctx;

static double elastic_density(double u, void *ctx)
{
  const elastic_ctx *e = ctx;
  const size_t k = (size_t)e->c->order;
  double R[3 * LW_NURBS_ORDER_MAX], cu[2] = {0, 0}, cuu[2] = {0, 0};
  const size_t first = lw_nurbs_rational(e->c, u, R);
  for (size_t i = 0; i < k; i++)
    for (int d = 0; d < 2; d++) {
      cu[d] += R[k + i] * e->c->P[2 * (first + i) + (size_t)d];
      cuu[d] += R[2 * k + i] * e->c->P[2 * (first + i) + (size_t)d];
    }
  return 0.5 * (e->alpha * (cu[0] * cu[0] + cu[1] * cu[1]) + e->beta * (cuu[0] * cuu[0] + cuu[1] * cuu[1]));
}

/* The matrices' elastic energy (alpha 35, beta 10, 10 Gauss points) of the
** curve of order k, n points P, its knots and weights w, its spans cut by
** rule `pieces` (nurbs.pieces), into *got; QAG's integral of the same, span
** by span, into *want. */
static void elastic_against_adaptive(int k, size_t n, const double *knot, const double *P, const double *w,
                                     int pieces, gsl_integration_workspace *ws, double *got, double *want)
{
  lw_error err = {0};
  lw_nurbs *c = lw_nurbs_new(k, n, knot, P, w, &err);
  cr_assert_not_null(c, "%s", err.msg);
  c->pieces = pieces;
  lw_dnurbs *d = lw_dnurbs_new(c, 35, 10, 10, &err);
  cr_assert_not_null(d, "%s", err.msg);
  *got = lw_band_energy(d->K, n, k, P);
  elastic_ctx ctx = {c, 35, 10};
  gsl_function f = {elastic_density, &ctx};
  *want = 0;
  for (size_t s = (size_t)k - 1; s < n; s++) {
    if (!(knot[s + 1] > knot[s])) continue; /* a repeated knot: no span */
    double part = 0, abserr = 0;
    const int st =
        gsl_integration_qag(&f, knot[s], knot[s + 1], 0, 1e-11, 4000, GSL_INTEG_GAUSS61, ws, &part, &abserr);
    cr_assert(!st || abserr < 1e-9 * fabs(part), "QAG: %s, %g +- %g", gsl_strerror(st), part, abserr);
    *want += part;
  }
  lw_dnurbs_free(d);
  lw_nurbs_free(c);
}

Test(nurbs_weights, weights_far_apart_keep_the_elastic_energy_of_the_curve)
{
  const double knot[] = {0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1};
  const double P[] = {-5, 5, -4, 6.5, -2.5, 3.5, 0, 6, 2.5, 4, 4, 6.5, 5, 5};
  static const double eps[] = {0.5, 0.25, 0.125, 1e-2, 1e-4, 1e-8, 1e-12};
  gsl_integration_workspace *ws = gsl_integration_workspace_alloc(4000);
  gsl_error_handler_t *was = gsl_set_error_handler_off();
  for (int light = 0; light < 2; light++)
    for (size_t e = 0; e < sizeof eps / sizeof *eps; e++) {
      double w[7], got, want;
      for (int i = 0; i < 7; i++) w[i] = (light ? i % 2 : i > 0 && i < 6) ? eps[e] : 1.0;
      elastic_against_adaptive(4, 7, knot, P, w, 2, ws, &got, &want);
      cr_log_info("weights %g (%s): elastic %.12g, adaptive %.12g", eps[e], light ? "every other" : "the middle",
                  got, want);
      cr_assert(fabs(got / want - 1) < 1e-6, "weights %g: %.12g against %.12g", eps[e], got, want);
    }
  gsl_set_error_handler(was);
  gsl_integration_workspace_free(ws);
  /* weights whose ratio passes the doubles (1e-320: a log weight under
  ** -709) made the pieces' count undefined, and spans fell out of the
  ** energy (58,208 read 890 on an annealed wire): every span is counted */
  double e[2];
  for (int k = 0; k < 2; k++) {
    const double w[7] = {1, k ? 1e-320 : 1e-300, 1, 1, 1, 1, 1};
    lw_error err = {0};
    lw_nurbs *c = lw_nurbs_new(4, 7, knot, P, w, &err);
    cr_assert_not_null(c, "%s", err.msg);
    lw_dnurbs *d = lw_dnurbs_new(c, 35, 10, 10, &err);
    cr_assert_not_null(d, "%s", err.msg);
    e[k] = lw_band_energy(d->K, 7, 4, P);
    lw_dnurbs_free(d);
    lw_nurbs_free(c);
  }
  cr_log_info("a weight of 1e-300: elastic %.12g; of 1e-320: %.12g", e[0], e[1]);
  cr_assert(isfinite(e[1]) && fabs(e[1] / e[0] - 1) < 1e-3, "elastic %g at 1e-320, %g at 1e-300", e[1], e[0]);
}

/* Beside a clamped end or a repeated knot a B-spline vanishes like u or u^2,
** not u^3, and the rational basis turns within h / q of the knot: the
** pieces of h q^(-1/3) stepped over it (a light end point of weight 0.01
** read 0.58 of the energy, 1e-4 a 34,000th; a heavy second point 1e4 its
** 1/34,000; a light point at a triple knot 0.58).  Against the adaptive
** integral, as above; order 3 (a quadratic's simple knots: u^2) too. */
Test(nurbs_weights, a_weight_beside_a_clamped_end_or_a_repeated_knot_keeps_the_energy)
{
  static const double simple[] = {0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1},
                      triple[] = {0, 0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1, 1},
                      quadratic[] = {0, 0, 0, 0.2, 0.4, 0.6, 0.8, 1, 1, 1};
  const double P[] = {-5, 5, -4, 6, -2.5, 4, 0, 5.5, 2.5, 4, 4, 6, 5, 5};
  static const struct {
    int order;
    const double *knot;
    double w[7];
  } cases[] = {
      {4, simple, {0.5, 1, 1, 1, 1, 1, 1}},    {4, triple, {1, 1, 1, 0.5, 1, 1, 1}},
      {4, simple, {0.01, 1, 1, 1, 1, 1, 1}},   {4, simple, {1e-4, 1, 1, 1, 1, 1, 1}},
      {4, simple, {1, 1e4, 1, 1, 1, 1, 1}},    {4, simple, {1, 1, 1e4, 1, 1, 1, 1}},
      {4, simple, {1, 1, 1, 1, 1, 1e-3, 1}},   {4, triple, {1, 1, 1, 0.01, 1, 1, 1}},
      {3, quadratic, {1, 1, 1, 1e-3, 1, 1, 1}}, {3, quadratic, {1e-3, 1, 1, 1, 1, 1, 1}},
  };
  gsl_integration_workspace *ws = gsl_integration_workspace_alloc(4000);
  gsl_error_handler_t *was = gsl_set_error_handler_off();
  for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
    double got, want;
    elastic_against_adaptive(cases[k].order, 7, cases[k].knot, P, cases[k].w, 2, ws, &got, &want);
    cr_log_info("case %zu: elastic %.12g, adaptive %.12g", k, got, want);
    cr_assert(fabs(got / want - 1) < 1e-7, "case %zu: %.12g against %.12g", k, got, want);
  }
  /* order 8, 9 points: an end weight or a middle one of 0.5, a ratio of 2,
  ** which was left whole (the end's 0.94 % low); and the rule of runs
  ** before 2026-12-07 (pieces = 1) still reads them so */
  const double knot8[17] = {0, 0, 0, 0, 0, 0, 0, 0, 0.5, 1, 1, 1, 1, 1, 1, 1, 1};
  const double P8[18] = {-5, 5, -4, 6, -3, 4, -1.5, 5.5, 0, 4, 1.5, 6, 3, 4, 4, 6, 5, 5};
  for (int k = 0; k < 3; k++) {
    double w[9] = {1, 1, 1, 1, 1, 1, 1, 1, 1}, got, want;
    w[k == 1 ? 4 : 0] = 0.5;
    elastic_against_adaptive(8, 9, knot8, P8, w, k == 2 ? 1 : 2, ws, &got, &want);
    cr_log_info("order 8, case %d: elastic %.12g, adaptive %.12g", k, got, want);
    if (k < 2) cr_assert(fabs(got / want - 1) < 1e-7, "order 8, case %d: %.12g against %.12g", k, got, want);
    else cr_assert(fabs(got / want - 1) > 1e-3, "pieces = 1 reads the whole span: %.12g against %.12g", got, want);
  }
  gsl_set_error_handler(was);
  gsl_integration_workspace_free(ws);
}
