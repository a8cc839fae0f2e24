/*
** test_wire.c -- the D-NURBS system (sys_nurbs.h) on the review's elastic
** wire, against what a linear system allows to compute exactly: the
** matrices against direct quadrature of the curve, the equilibrium of
** K p = f, the generalised eigenvalues of (K, M) undamped and of the
** damped pencil, and the Boltzmann distribution of Monte Carlo, a Gaussian
** of covariance T K^-1.
*/
#include <criterion/criterion.h>
#include <float.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_linalg.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/dynamics.h"
#include "linewise/mc.h"
#include "linewise/quench.h"
#include "linewise/sys_nurbs.h"
#include "testutil.h"

#define MU 30.0
#define G 9.8

typedef struct {
  lw_params p;
  lw_nurbs_setup *su;
  lw_system *sys;
  lw_nurbs_state *st;
  size_t n, nf;       /* control points, free ones */
  gsl_matrix *K, *M;  /* dense, free points only (one coordinate) */
} wire;

/* The review's wire (Table 1, alpha 35, beta 10, mu 30, g 9.8, ends held),
** its degree raised by elevate and its spans cut into split
** (nurbs.elevate, nurbs.refine). */
static void wire_open_refined(wire *w, double gamma, int elevate, int split)
{
  lw_params_defaults(&w->p);
  w->p.nb_elevate = elevate;
  w->p.nb_refine = split;
  strcpy(w->p.nb_points, "-5 5  -4.17 5  -2.5 5  0 5  2.5 5  4.17 5  5 5");
  strcpy(w->p.nb_knots, "0 0 0 0 0.25 0.5 0.75 1 1 1 1");
  w->p.nb_order = 4;
  w->p.nb_alpha = 35;
  w->p.nb_beta = 10;
  w->p.nb_gauss = 10;
  w->p.nb_fixed = 1;
  w->p.dyn_rho = MU;
  w->p.dyn_gamma = gamma;
  w->p.dyn_gravity_y = -G;
  w->p.dyn_dt = 0.008;
  lw_error err = {0};
  w->su = lw_system_nurbs.setup_new(&w->p, &err);
  cr_assert_not_null(w->su, "%s", err.msg);
  w->sys = lw_system_wrap(&lw_system_nurbs, lw_system_nurbs.state_new(w->su, &w->p, 0, &err), &err);
  cr_assert_not_null(w->sys, "%s", err.msg);
  w->st = w->sys->state;
  w->n = w->su->curve->n;
  w->nf = w->su->n_free;
  /* dense copies of the free block of the bands */
  w->K = gsl_matrix_alloc(w->nf, w->nf);
  w->M = gsl_matrix_alloc(w->nf, w->nf);
  const lw_dnurbs *m = w->su->mat;
  for (size_t a = 0; a < w->nf; a++)
    for (size_t b = 0; b < w->nf; b++) {
      size_t i = w->su->free_idx[a], j = w->su->free_idx[b], lo = i < j ? i : j, d = i < j ? j - i : i - j;
      double kv = d < (size_t)m->k ? m->K[lo * (size_t)m->k + d] : 0.0;
      double mv = d < (size_t)m->k ? m->M1[lo * (size_t)m->k + d] : 0.0;
      gsl_matrix_set(w->K, a, b, kv);
      gsl_matrix_set(w->M, a, b, MU * mv);
    }
}

static void wire_open(wire *w, double gamma) { wire_open_refined(w, gamma, 0, 1); }

static void wire_close(wire *w)
{
  gsl_matrix_free(w->K);
  gsl_matrix_free(w->M);
  lw_system_free(w->sys);
  lw_system_nurbs.setup_free(w->su);
}

/* The equilibrium of K p = f with the held points where they are, by dense
** GSL Cholesky: P (2 n) gets the free points' x and y. */
static void equilibrium(const wire *w, double *P)
{
  const lw_dnurbs *m = w->su->mat;
  size_t n = w->n, k = (size_t)m->k;
  memcpy(P, w->su->curve->P, 2 * n * sizeof *P);
  gsl_matrix *L = gsl_matrix_alloc(w->nf, w->nf);
  gsl_matrix_memcpy(L, w->K);
  cr_assert_eq(gsl_linalg_cholesky_decomp1(L), 0);
  gsl_vector *r = gsl_vector_alloc(w->nf);
  for (int c = 0; c < 2; c++) {
    for (size_t a = 0; a < w->nf; a++) {
      size_t i = w->su->free_idx[a];
      double v = w->su->f[2 * i + c];
      for (size_t j = 0; j < n; j++) {
        size_t lo = i < j ? i : j, d = i < j ? j - i : i - j;
        if (w->su->pin[j] && d < k) v -= m->K[lo * k + d] * P[2 * j + c];
      }
      gsl_vector_set(r, a, v);
    }
    gsl_linalg_cholesky_svx(L, r);
    for (size_t a = 0; a < w->nf; a++) P[2 * w->su->free_idx[a] + c] = gsl_vector_get(r, a);
  }
  gsl_vector_free(r);
  gsl_matrix_free(L);
}

static double rel_dist(const double *a, const double *b, size_t n)
{
  double d = 0.0, s = 0.0;
  for (size_t i = 0; i < n; i++) {
    d = fmax(d, fabs(a[i] - b[i]));
    s = fmax(s, fabs(b[i]));
  }
  return d / s;
}

/* ---- the matrices against the curve --------------------------------------- */

/* int over [0, 1] of what(c(u), c'(u), c''(u)) by 24-point Gauss-Legendre on
** each knot span (exact to rounding for these polynomials). */
static double integral(lw_nurbs *c, double (*what)(const double *p, const double *d1, const double *d2))
{
  gsl_integration_glfixed_table *t = gsl_integration_glfixed_table_alloc(24);
  double sum = 0.0;
  for (size_t s = (size_t)c->order - 1; s < c->n; s++)
    for (size_t q = 0; q < 24 && c->knot[s + 1] > c->knot[s]; q++) {
      double u, wq, p[2], d1[2], d2[2];
      gsl_integration_glfixed_point(c->knot[s], c->knot[s + 1], q, &u, &wq, t);
      lw_nurbs_eval(c, u, p, d1, d2);
      sum += wq * what(p, d1, d2);
    }
  gsl_integration_glfixed_table_free(t);
  return sum;
}

static double elastic_density(const double *p, const double *d1, const double *d2)
{
  return 0.5 * (35 * (d1[0] * d1[0] + d1[1] * d1[1]) + 10 * (d2[0] * d2[0] + d2[1] * d2[1]));
}
static double square(const double *p, const double *d1, const double *d2) { return p[0] * p[0] + p[1] * p[1]; }
static double height(const double *p, const double *d1, const double *d2) { return p[1]; }

Test(wire, the_banded_matrices_give_the_energies_of_the_curve)
{
  wire w;
  wire_open(&w, 0);
  rng_seed(3);
  /* random control points; also rational weights, whose matrices are those
  ** of the frozen R_i */
  for (int rational = 0; rational < 2; rational++) {
    lw_nurbs *c = w.st->c;
    for (size_t i = 0; i < w.n; i++) {
      c->P[2 * i] = urand(-5, 5), c->P[2 * i + 1] = urand(-5, 5);
      if (rational) c->w[i] = urand(0.5, 2);
    }
    lw_error err = {0};
    lw_dnurbs *m = lw_dnurbs_new(c, 35, 10, 10, &err);
    cr_assert_not_null(m);
    double *y = malloc(2 * w.n * sizeof *y);
    lw_band_apply(m->K, w.n, m->k, c->P, y);
    double el = 0, mass = 0, b = 0;
    for (size_t i = 0; i < 2 * w.n; i++) el += 0.5 * c->P[i] * y[i];
    lw_band_apply(m->M1, w.n, m->k, c->P, y);
    for (size_t i = 0; i < 2 * w.n; i++) mass += c->P[i] * y[i];
    for (size_t i = 0; i < w.n; i++) b += m->b[i] * c->P[2 * i + 1];
    /* 10 Gauss points integrate the polynomial spans exactly; the rational
    ** ones to the quadrature's accuracy */
    double tol = rational ? 1e-6 : 1e-12;
    double want = integral(c, elastic_density);
    cr_assert(fabs(el - want) < tol * want, "rational %d: 1/2 P'KP = %.15g, curve %.15g", rational, el, want);
    /* summed over differences (lw_band_energy), the same energy; and a
    ** translation by 1e3 changes its terms only by the rounding of the
    ** moved points (1e-13 of a difference), where 1/2 P'KP's products
    ** grow by 1e6 and cancel to the energy */
    double ed = lw_band_energy(m->K, w.n, m->k, c->P);
    cr_assert(fabs(ed - want) < tol * want, "rational %d: over differences %.15g, curve %.15g", rational, ed, want);
    double keep[2 * 64];
    cr_assert(2 * w.n <= 2 * 64);
    memcpy(keep, c->P, 2 * w.n * sizeof *keep);
    for (size_t i = 0; i < 2 * w.n; i++) c->P[i] += 1e3;
    double moved = lw_band_energy(m->K, w.n, m->k, c->P);
    cr_assert(fabs(moved - ed) <= 1e-12 * ed, "rational %d: translated %.17g, not %.17g", rational, moved, ed);
    memcpy(c->P, keep, 2 * w.n * sizeof *keep);
    want = integral(c, square);
    cr_assert(fabs(mass - want) < tol * want, "rational %d: P'M1P = %.15g, curve %.15g", rational, mass, want);
    want = integral(c, height);
    cr_assert(fabs(b - want) < tol * fabs(want), "rational %d: b'y = %.15g, curve %.15g", rational, b, want);
    free(y);
    lw_dnurbs_free(m);
  }
  wire_close(&w);
}

/* E_el + E_g of the curve itself (24 Gauss points), mu g = (0, -294) */
static double wire_energy(lw_nurbs *c) { return integral(c, elastic_density) + 294 * integral(c, height); }

Test(wire, the_weight_gradient_matches_central_differences)
{
  wire w;
  wire_open(&w, 0);
  rng_seed(5);
  lw_nurbs *c = w.st->c;
  for (size_t i = 0; i < w.n; i++) {
    c->P[2 * i] = urand(-5, 5), c->P[2 * i + 1] = urand(-5, 5);
    c->w[i] = urand(0.5, 2);
  }
  const double mug[2] = {0, -294};
  double *gw = malloc(w.n * sizeof *gw), big = 0;
  lw_error err = {0};
  /* the same 24 points as the curve's integral: only the difference's own
  ** error is left, h^2 E^(3) ~ 1e-10 and rounding eps E / h ~ 1e-11 */
  cr_assert_eq(lw_dnurbs_grad_w(c, 35, 10, mug, 24, gw, &err), LW_OK);
  for (size_t j = 0; j < w.n; j++) big = fmax(big, fabs(gw[j]));
  cr_assert(big > 1.0, "a gradient that vanishes would test nothing: %g", big);
  /* the scale gauge: sum_j w_j q_j = 0, so scaling every weight costs nothing */
  double scale = 0;
  for (size_t j = 0; j < w.n; j++) scale += c->w[j] * gw[j];
  cr_assert(fabs(scale) < 1e-10 * big, "sum w_j dE/dw_j = %g, should vanish", scale);
  for (size_t j = 0; j < w.n; j++) {
    double w0 = c->w[j], h = 1e-5 * w0;
    c->w[j] = w0 + h;
    double ep = wire_energy(c);
    c->w[j] = w0 - h;
    double em = wire_energy(c);
    c->w[j] = w0;
    double fd = (ep - em) / (2 * h);
    cr_assert(fabs(gw[j] - fd) < 1e-6 * big, "dE/dw_%zu = %.12g, central difference %.12g", j, gw[j], fd);
  }
  free(gw);
  wire_close(&w);
}

/* ---- statics and dynamics ------------------------------------------------- */

Test(wire, damped_motion_comes_to_rest_at_the_solution_of_k_p_equals_f)
{
  wire w;
  /* the lowest mode critically damped (gamma / 2 mu = omega_1 ~ 4.2 / s) */
  wire_open(&w, 250);
  double *P = malloc(2 * w.n * sizeof *P);
  equilibrium(&w, P);
  lw_error err = {0};
  lw_dynamics *d = lw_dynamics_new(&lw_system_nurbs, w.st, &w.p, &err);
  cr_assert_not_null(d, "%s", err.msg);
  for (int s = 0; s < 20000; s++) cr_assert_eq(lw_dynamics_step(d, &err), LW_OK, "%s", err.msg);
  double r = rel_dist(w.st->c->P, P, 2 * w.n);
  cr_log_info("damped wire: %.3g from the equilibrium after %g s", r, d->time);
  cr_assert_lt(r, 1e-9, "the damped wire rests %g (relative) from the solution of K p = f", r);
  /* the sag: the midpoint hangs below its ends */
  double mid[2];
  lw_nurbs_eval(w.st->c, 0.5, mid, NULL, NULL);
  cr_log_info("midpoint at %.10g", mid[1]);
  cr_assert_lt(mid[1], 4.9);
  free(P);
  lw_dynamics_free(d);
  wire_close(&w);
}

/* Generalised eigenvalues (ascending) and M-normalised vectors of (K, M). */
static void modes(const wire *w, gsl_vector *lambda, gsl_matrix *vec)
{
  gsl_matrix *A = gsl_matrix_alloc(w->nf, w->nf), *B = gsl_matrix_alloc(w->nf, w->nf);
  gsl_matrix_memcpy(A, w->K);
  gsl_matrix_memcpy(B, w->M);
  gsl_eigen_gensymmv_workspace *ws = gsl_eigen_gensymmv_alloc(w->nf);
  cr_assert_eq(gsl_eigen_gensymmv(A, B, lambda, vec, ws), 0);
  gsl_eigen_gensymmv_sort(lambda, vec, GSL_EIGEN_SORT_VAL_ASC);
  gsl_eigen_gensymmv_free(ws);
  gsl_matrix_free(A);
  gsl_matrix_free(B);
}

/* The continuous wire: E = int 1/2 alpha y'^2 + 1/2 beta y''^2 + mu g y du
** over u in [0, 1], the ends held at one height y0 and free to turn (the
** natural condition y'' = 0 there). Its equilibrium solves
** beta y'''' - alpha y'' = -mu g: with lambda^2 = alpha / beta,
**   y(1/2) = y0 - mu g / (8 alpha) + mu g / (alpha lambda^2) (1 - sech(lambda / 2)),
** and its modes are sin(j pi u) with mu omega^2 = alpha (j pi)^2 + beta (j pi)^4. */
static double continuous_midpoint(void)
{
  const double alpha = 35, beta = 10, lam = sqrt(alpha / beta);
  return 5 - MU * G / (8 * alpha) + MU * G / (alpha * lam * lam) * (1 - 1 / cosh(lam / 2));
}

static double continuous_omega(int j)
{
  const double q = j * M_PI;
  return sqrt((35 * q * q + 10 * q * q * q * q) / MU);
}

/* The midpoint height of the wire's equilibrium, its four lowest angular
** frequencies (x and y move alike: one coordinate's pencil) and the
** highest. */
static void refined_wire(int elevate, int split, double *mid, double omega[4], double *omega_max, size_t *n)
{
  wire w;
  wire_open_refined(&w, 0, elevate, split);
  double *Peq = malloc(2 * w.n * sizeof *Peq), pt[2];
  equilibrium(&w, Peq);
  lw_error err;
  lw_nurbs *c = lw_nurbs_copy(w.su->curve, &err);
  memcpy(c->P, Peq, 2 * w.n * sizeof *Peq);
  lw_nurbs_eval(c, 0.5, pt, NULL, NULL);
  *mid = pt[1];
  gsl_vector *lambda = gsl_vector_alloc(w.nf);
  gsl_matrix *vec = gsl_matrix_alloc(w.nf, w.nf);
  modes(&w, lambda, vec);
  for (int j = 0; j < 4; j++) omega[j] = sqrt(gsl_vector_get(lambda, (size_t)j));
  *omega_max = sqrt(gsl_vector_get(lambda, w.nf - 1));
  *n = w.n;
  lw_nurbs_free(c);
  free(Peq);
  gsl_vector_free(lambda);
  gsl_matrix_free(vec);
  wire_close(&w);
}

Test(wire, refinement_converges_to_the_continuous_wire)
{
  /* Splitting the spans and raising the degree give nested spaces that hold
  ** the wire's curve, and the matrices are exact (10 Gauss points a span),
  ** so Rayleigh-Ritz holds: every frequency lies above the continuous one
  ** and falls with each refinement, to rounding. The eigensolver's
  ** rounding is eps lambda_max on each lambda, so the tolerance on omega_j
  ** is 100 eps (omega_max / omega_j)^2 relative. The equilibrium's midpoint
  ** converges to the closed form at the expected order. */
  const double exact_mid = continuous_midpoint();
  for (int e = 0; e <= 2; e++) {
    double prev[4] = {INFINITY, INFINITY, INFINITY, INFINITY}, prev_err = INFINITY;
    for (int split = 1; split <= 16; split *= 2) {
      double mid, omega[4], omega_max;
      size_t n;
      refined_wire(e, split, &mid, omega, &omega_max, &n);
      double err_mid = fabs(mid - exact_mid);
      cr_log_info("elevate %d split %2d: %3zu points, midpoint %.10f (off %.2e), omega %.8g %.8g %.8g %.8g "
                  "(off %.2e %.2e %.2e %.2e), max %.4g",
                  e, split, n, mid, err_mid, omega[0], omega[1], omega[2], omega[3],
                  omega[0] / continuous_omega(1) - 1, omega[1] / continuous_omega(2) - 1,
                  omega[2] / continuous_omega(3) - 1, omega[3] / continuous_omega(4) - 1, omega_max);
      for (int j = 0; j < 4; j++) {
        double tol = 100 * DBL_EPSILON * (omega_max / omega[j]) * (omega_max / omega[j]);
        cr_assert_geq(omega[j], continuous_omega(j + 1) * (1 - tol), "e %d split %d mode %d: below the continuous",
                      e, split, j + 1);
        cr_assert_leq(omega[j], prev[j] * (1 + tol), "e %d split %d mode %d: rose with refinement", e, split, j + 1);
        prev[j] = omega[j];
      }
      /* halving the spans divides the error by 2^(order of convergence):
      ** at least 2^3.5 for cubics (h^4 expected), 2^4.5 once raised; where
      ** the dense solve's rounding (about 4e-10 at 70 points, a condition of
      ** 1e8) does not decide it */
      if (split > 1 && prev_err > 1e-7)
        cr_assert_gt(prev_err / err_mid, pow(2, e ? 4.5 : 3.5), "e %d split %d: the midpoint's error went from %g to %g",
                     e, split, prev_err, err_mid);
      prev_err = err_mid;
    }
  }
}

Test(wire, the_quench_solves_the_refined_wire_and_holds_its_ends)
{
  /* From the straight start, refined 8 times (35 points, stiffness
  ** condition 1e7): the quench lands on the dense solution of K p = f with
  ** the ends where the scene holds them, converged, and its energy lies
  ** just above the continuous wire's (Ritz), 3193.40157059 (the closed
  ** form's y(u) integrated). L-BFGS alone stalled at a gradient of 379
  ** here; the system's one-step minimum (system.h, minimize) solves it. */
  wire w;
  wire_open_refined(&w, 0, 0, 8);
  double *Peq = malloc(2 * w.n * sizeof *Peq), end0[2], end1[2];
  equilibrium(&w, Peq);
  memcpy(end0, w.st->c->P, sizeof end0);
  memcpy(end1, w.st->c->P + 2 * (w.n - 1), sizeof end1);
  lw_quench_opts o = {.tol = 1e-6, .max_iter = 2000, .stall = 0.05};
  lw_quench_report r;
  lw_error err = {0};
  cr_assert_eq(lw_quench_run(w.sys, &o, &r, &err), LW_OK, "%s", err.msg);
  cr_log_info("quench: %s after %ld iterations, gradient %g, energy %.10f", lw_quench_end_name(r.ended), r.iterations,
              r.gradient_after, r.energy_after);
  cr_assert(r.converged, "ended %s at a gradient of %g", lw_quench_end_name(r.ended), r.gradient_after);
  /* the gradient before is the start's, not what the row's solve left */
  cr_assert(r.gradient_before > 1e6 * r.gradient_after, "gradient %g -> %g", r.gradient_before, r.gradient_after);
  cr_assert_lt(rel_dist(w.st->c->P, Peq, 2 * w.n), 1e-10);
  cr_assert(w.st->c->P[0] == end0[0] && w.st->c->P[1] == end0[1] && w.st->c->P[2 * w.n - 2] == end1[0] &&
            w.st->c->P[2 * w.n - 1] == end1[1], "the held ends moved");
  cr_assert(r.energy_after > 3193.40157059 - 1e-7 && r.energy_after < 3193.40157059 + 1e-5, "energy %.10f",
            r.energy_after);
  free(Peq);
  wire_close(&w);
}

/* Starts the wire at rest at equilibrium + amp phi_k (y only), steps it and
** reads the midpoint's height relative to the equilibrium: the angular
** frequency from its zero crossings and, if decay, the decay rate from the
** logarithm of its extremes (least squares). */
static void midpoint_motion(wire *w, const double *Peq, const gsl_matrix *vec, size_t k, double dt, int steps,
                            double *omega, double *decay)
{
  double *P = malloc(2 * w->n * sizeof *P), eq[2];
  memcpy(P, Peq, 2 * w->n * sizeof *P);
  for (size_t a = 0; a < w->nf; a++) P[2 * w->su->free_idx[a] + 1] += 0.1 * gsl_matrix_get(vec, a, k);
  lw_error err = {0};
  cr_assert_eq(lw_system_nurbs.set_coords(w->st, P, &err), LW_OK);
  w->p.dyn_dt = dt;
  lw_dynamics *d = lw_dynamics_new(&lw_system_nurbs, w->st, &w->p, &err);
  cr_assert_not_null(d, "%s", err.msg);
  lw_nurbs *ceq = lw_nurbs_copy(w->st->c, &err);
  memcpy(ceq->P, Peq, 2 * w->n * sizeof *P);
  lw_nurbs_eval(ceq, 0.5, eq, NULL, NULL);
  double prev = 0, pprev = 0, first = -1, last = -1, sx = 0, sy = 0, sxx = 0, sxy = 0;
  int crossings = 0, peaks = 0;
  for (int s = 0; s <= steps; s++) {
    double mid[2];
    lw_nurbs_eval(w->st->c, 0.5, mid, NULL, NULL);
    double y = mid[1] - eq[1];
    if (s > 0 && (y > 0) != (prev > 0)) {
      double t = d->time - dt * y / (y - prev);
      if (first < 0) first = t;
      last = t;
      crossings++;
    }
    /* an extreme of |y| at the previous step: a parabola through three */
    if (s > 1 && fabs(prev) > fabs(y) && fabs(prev) >= fabs(pprev)) {
      double den = pprev - 2 * prev + y, off = den != 0 ? 0.5 * (pprev - y) / den : 0;
      double ext = prev - 0.25 * (pprev - y) * off, t = d->time - dt + off * dt;
      double ly = log(fabs(ext));
      sx += t, sy += ly, sxx += t * t, sxy += t * ly;
      peaks++;
    }
    pprev = prev;
    prev = y;
    cr_assert_eq(lw_dynamics_step(d, &err), LW_OK, "%s", err.msg);
  }
  cr_assert_geq(crossings, 10, "mode %zu: %d zero crossings, midpoint %g", k, crossings, prev);
  *omega = M_PI * (crossings - 1) / (last - first);
  *decay = -(peaks * sxy - sx * sy) / (peaks * sxx - sx * sx);
  lw_nurbs_free(ceq);
  lw_dynamics_free(d);
  free(P);
}

/* The symmetric modes move the midpoint; the others leave it (nearly) still. */
static int symmetric(const wire *w, const gsl_matrix *vec, size_t k)
{
  return fabs(gsl_matrix_get(vec, 0, k) - gsl_matrix_get(vec, w->nf - 1, k)) <
         1e-6 * fabs(gsl_matrix_get(vec, 0, k)) + 1e-6 * fabs(gsl_matrix_get(vec, w->nf / 2, k));
}

Test(wire, undamped_midpoint_frequencies_are_the_generalised_eigenvalues)
{
  wire w;
  wire_open(&w, 0);
  double *Peq = malloc(2 * w.n * sizeof *Peq);
  equilibrium(&w, Peq);
  gsl_vector *lambda = gsl_vector_alloc(w.nf);
  gsl_matrix *vec = gsl_matrix_alloc(w.nf, w.nf);
  modes(&w, lambda, vec);
  int tested = 0;
  for (size_t k = 0; k < w.nf; k++) {
    if (!symmetric(&w, vec, k)) continue;
    double omega = sqrt(gsl_vector_get(lambda, k)), measured, decay;
    /* the review's dt where the leapfrog's phase error (omega dt)^2 / 24
    ** is below 0.1 %, else a step that makes it so */
    double dt = fmin(0.008, sqrt(24 * 1e-3) / omega);
    midpoint_motion(&w, Peq, vec, k, dt, (int)(40 * 2 * M_PI / omega / dt), &measured, &decay);
    cr_log_info("mode %zu: omega %.8g from (K, M), %.8g measured (dt %g)", k, omega, measured, dt);
    cr_assert(fabs(measured / omega - 1) < 0.005, "mode %zu: omega %g measured, %g from gensymm", k, measured, omega);
    cr_assert(fabs(decay) < 1e-3 * omega, "mode %zu: undamped, yet a decay rate %g", k, decay);
    tested++;
  }
  cr_assert_geq(tested, 2, "the wire has symmetric modes");
  free(Peq);
  gsl_vector_free(lambda);
  gsl_matrix_free(vec);
  wire_close(&w);
}

Test(wire, damped_decay_and_frequency_are_the_damped_eigenvalues)
{
  wire w;
  wire_open(&w, 5);
  double *Peq = malloc(2 * w.n * sizeof *Peq);
  equilibrium(&w, Peq);
  gsl_vector *lambda = gsl_vector_alloc(w.nf);
  gsl_matrix *vec = gsl_matrix_alloc(w.nf, w.nf);
  modes(&w, lambda, vec);
  /* the damped pencil M x'' + D x' + K x = 0 as a first-order system
  ** [0 I; -M^-1 K, -M^-1 D] with D = (gamma / mu) M of the same integrals */
  size_t nf = w.nf;
  gsl_matrix *A = gsl_matrix_calloc(2 * nf, 2 * nf), *MinvK = gsl_matrix_alloc(nf, nf), *L = gsl_matrix_alloc(nf, nf);
  gsl_matrix_memcpy(L, w.M);
  gsl_linalg_cholesky_decomp1(L);
  gsl_matrix_memcpy(MinvK, w.K);
  for (size_t j = 0; j < nf; j++) {
    gsl_vector_view col = gsl_matrix_column(MinvK, j);
    gsl_linalg_cholesky_svx(L, &col.vector);
  }
  for (size_t i = 0; i < nf; i++) {
    gsl_matrix_set(A, i, nf + i, 1.0);
    gsl_matrix_set(A, nf + i, nf + i, -5.0 / MU);
    for (size_t j = 0; j < nf; j++) gsl_matrix_set(A, nf + i, j, -gsl_matrix_get(MinvK, i, j));
  }
  gsl_vector_complex *ev = gsl_vector_complex_alloc(2 * nf);
  gsl_eigen_nonsymm_workspace *ws = gsl_eigen_nonsymm_alloc(2 * nf);
  cr_assert_eq(gsl_eigen_nonsymm(A, ev, ws), 0);
  int tested = 0;
  for (size_t k = 0; k < nf && tested < 2; k++) {
    if (!symmetric(&w, vec, k)) continue;
    /* the damped eigenvalue nearest the undamped i omega_k */
    double omega = sqrt(gsl_vector_get(lambda, k)), re = 0, im = 0, best = INFINITY;
    for (size_t e = 0; e < 2 * nf; e++) {
      gsl_complex z = gsl_vector_complex_get(ev, e);
      double dist = fabs(GSL_IMAG(z) - omega);
      if (dist < best) best = dist, re = GSL_REAL(z), im = GSL_IMAG(z);
    }
    double dt = fmin(0.008, sqrt(24 * 1e-3) / omega), measured, decay;
    midpoint_motion(&w, Peq, vec, k, dt, (int)(30 * 2 * M_PI / omega / dt), &measured, &decay);
    cr_log_info("mode %zu: damped eigenvalue %.8g + %.8gi; measured decay %.8g, frequency %.8g", k, re, im, decay,
                measured);
    cr_assert(fabs(decay / -re - 1) < 0.01, "mode %zu: decay rate %g measured, %g from the damped eigenvalue", k,
              decay, -re);
    cr_assert(fabs(measured / im - 1) < 0.01, "mode %zu: frequency %g measured, %g damped eigenvalue", k, measured, im);
    tested++;
  }
  cr_assert_eq(tested, 2);
  gsl_eigen_nonsymm_free(ws);
  gsl_vector_complex_free(ev);
  gsl_matrix_free(A);
  gsl_matrix_free(MinvK);
  gsl_matrix_free(L);
  free(Peq);
  gsl_vector_free(lambda);
  gsl_matrix_free(vec);
  wire_close(&w);
}

/* ---- Monte Carlo through the same row ------------------------------------- */

static lw_chain *wire_chain(wire *w, unsigned long seed)
{
  double wt[LW_MOVES_MAX], st[LW_MOVES_MAX], tg[LW_MOVES_MAX];
  w->p.step_point = 0.05;
  lw_system_nurbs.moves(&w->p, wt, st, tg);
  lw_error err = {0};
  lw_chain *c = lw_chain_new(w->sys, wt, st, tg, seed, &err);
  cr_assert_not_null(c, "%s", err.msg);
  return c;
}

Test(wire, annealing_to_zero_temperature_reaches_the_equilibrium)
{
  wire w;
  wire_open(&w, 0);
  double *P = malloc(2 * w.n * sizeof *P);
  equilibrium(&w, P);
  lw_chain *c = wire_chain(&w, 11);
  c->tuning = 1;
  /* geometric cooling from T = 1 to 1e-14 */
  int sweeps = 40000;
  for (int s = 0; s < sweeps; s++) {
    c->temperature = pow(1e-14, (double)s / (sweeps - 1));
    cr_assert_eq(lw_chain_sweep(c), LW_OK);
  }
  double before = lw_system_total(w.sys);
  cr_assert_eq(lw_system_nurbs.refresh(w.st), LW_OK);
  cr_assert(fabs(lw_system_total(w.sys) - before) <= 1e-9 * fabs(before), "running energy drifted to %.17g from "
            "%.17g", lw_system_total(w.sys), before);
  double r = rel_dist(w.st->c->P, P, 2 * w.n);
  cr_log_info("annealed wire: %.3g from the equilibrium (step %g)", r, c->step[0]);
  cr_assert_lt(r, 1e-4, "annealing ends %g (relative) from the solution of K p = f", r);
  lw_chain_free(c);
  free(P);
  wire_close(&w);
}

Test(wire, at_a_fixed_temperature_the_free_points_sample_t_times_k_inverse)
{
  /* exp(-E/T) with E = 1/2 p'Kp - f'p is the Gaussian of mean p_eq and
  ** covariance T K_ff^-1 in x and in y.  With K_ff = L L', z = L'(p - p_eq)
  ** / sqrt(T) is standard normal: every z_a z_b has mean delta_ab, which
  ** tests the whole covariance.  Tolerance: 5 standard errors of batch
  ** means (50 batches of correlated samples). */
  wire w;
  wire_open(&w, 0);
  const double T = 0.01;
  size_t nf = w.nf;
  double *P = malloc(2 * w.n * sizeof *P);
  equilibrium(&w, P);
  gsl_matrix *L = gsl_matrix_alloc(nf, nf);
  gsl_matrix_memcpy(L, w.K);
  gsl_linalg_cholesky_decomp1(L);
  lw_chain *c = wire_chain(&w, 29);
  c->temperature = T;
  c->tuning = 1;
  for (int s = 0; s < 2000; s++) lw_chain_sweep(c);
  c->tuning = 0;
  long samples = lw_test_long() ? 400000 : 100000;
  size_t npair = nf * (nf + 1) / 2;
  batch_mean *m = calloc(2 * npair, sizeof *m);
  for (size_t q = 0; q < 2 * npair; q++) m[q].per = samples / BATCHES;
  double z[2][16];
  for (long s = 0; s < samples; s++) {
    lw_chain_sweep(c);
    for (int xy = 0; xy < 2; xy++)
      for (size_t a = 0; a < nf; a++) {
        /* (L' d)_a = sum_{b >= a} L_ba d_b */
        double v = 0.0;
        for (size_t b = a; b < nf; b++) {
          size_t i = w.su->free_idx[b];
          v += gsl_matrix_get(L, b, a) * (w.st->c->P[2 * i + xy] - P[2 * i + xy]);
        }
        z[xy][a] = v / sqrt(T);
      }
    for (int xy = 0, q = 0; xy < 2; xy++)
      for (size_t a = 0; a < nf; a++)
        for (size_t b = a; b < nf; b++) bm_add(&m[q++], z[xy][a] * z[xy][b]);
  }
  for (int xy = 0, q = 0; xy < 2; xy++)
    for (size_t a = 0; a < nf; a++)
      for (size_t b = a; b < nf; b++, q++) {
        double se, mean = bm_mean(&m[q], &se), want = a == b ? 1.0 : 0.0;
        cr_assert(se < 0.05, "%c: z%zu z%zu: standard error %g too large to test anything", "xy"[xy], a, b, se);
        cr_assert(fabs(mean - want) < 5 * se, "%c: <z%zu z%zu> = %g +- %g, expected %g (T K^-1)", "xy"[xy], a, b, mean,
                  se, want);
      }
  cr_log_info("covariance T K^-1 checked on %zu pairs, %ld sweeps", 2 * npair, samples);
  free(m);
  lw_chain_free(c);
  gsl_matrix_free(L);
  free(P);
  wire_close(&w);
}

/* ---- the review's implicit scheme ----------------------------------------- */

Test(wire, the_review_scheme_has_its_derived_amplification_and_rests_at_the_equilibrium)
{
  /* A mode of frequency omega: (1 + h c/2 + h^2 omega^2) z^2 - 2 z + (1 - h c/2) = 0
  ** (c = gamma / mu) gives the growth z per step; the midpoint then decays
  ** at -ln|z| / h and turns at arg z / h, undamped or not. */
  for (int damped = 0; damped < 2; damped++) {
    wire w;
    wire_open(&w, damped ? 5 : 0);
    w.p.dyn_integrator = LW_INTEGRATOR_REVIEW;
    double *Peq = malloc(2 * w.n * sizeof *Peq);
    equilibrium(&w, Peq);
    gsl_vector *lambda = gsl_vector_alloc(w.nf);
    gsl_matrix *vec = gsl_matrix_alloc(w.nf, w.nf);
    modes(&w, lambda, vec);
    double h = 0.008, c = w.p.dyn_gamma / MU, omega = sqrt(gsl_vector_get(lambda, 0));
    double a = 1 + h * c / 2 + h * h * omega * omega, b = -2, cc = 1 - h * c / 2;
    double re = -b / (2 * a), im = sqrt(4 * a * cc - b * b) / (2 * a);
    double rate = -log(hypot(re, im)) / h, freq = atan2(im, re) / h, measured, decay;
    midpoint_motion(&w, Peq, vec, 0, h, 3000, &measured, &decay);
    cr_log_info("review scheme, gamma %g: decay %.8g (derived %.8g), frequency %.8g (derived %.8g, exact %.8g)",
                w.p.dyn_gamma, decay, rate, measured, freq, omega);
    cr_assert(fabs(decay / rate - 1) < 0.01, "decay %g, derived %g", decay, rate);
    cr_assert(fabs(measured / freq - 1) < 0.005, "frequency %g, derived %g", measured, freq);
    /* and it damps what the physics does not: faster than gamma / 2 mu */
    cr_assert_gt(decay, c / 2 + 0.5 * omega * omega * h * 0.9);
    free(Peq);
    gsl_vector_free(lambda);
    gsl_matrix_free(vec);
    wire_close(&w);
  }
  /* from the straight start it comes to rest at K p = f */
  wire w;
  wire_open(&w, 5);
  w.p.dyn_integrator = LW_INTEGRATOR_REVIEW;
  double *P = malloc(2 * w.n * sizeof *P);
  equilibrium(&w, P);
  lw_error err = {0};
  lw_dynamics *d = lw_dynamics_new(&lw_system_nurbs, w.st, &w.p, &err);
  cr_assert_not_null(d, "%s", err.msg);
  for (int s = 0; s < 40000; s++) cr_assert_eq(lw_dynamics_step(d, &err), LW_OK, "%s", err.msg);
  double r = rel_dist(w.st->c->P, P, 2 * w.n);
  cr_assert_lt(r, 1e-9, "the review scheme rests %g from the equilibrium", r);
  lw_dynamics_free(d);
  free(P);
  wire_close(&w);
}

Test(wire, the_review_scheme_solves_with_its_own_factor_in_one_iteration_at_any_refinement)
{
  /* (1 + h c/2) M + h^2 K is constant for frozen weights: preconditioned by
  ** its banded factor (mass_shift) the operator is the identity, so CG
  ** stops after one iteration (two where the difference quotients' rounding
  ** needs it); by M alone it needed about h omega_max, 240 at this size.
  ** The first step from rest is delta = -h^2 A^-1 grad E on the free
  ** points: checked against a dense GSL Cholesky solve. */
  wire w;
  wire_open_refined(&w, 5, 0, 16);
  cr_assert_eq(w.n, 67);
  w.p.dyn_integrator = LW_INTEGRATOR_REVIEW;
  lw_error err = {0};
  lw_dynamics *d = lw_dynamics_new(&lw_system_nurbs, w.st, &w.p, &err);
  cr_assert_not_null(d, "%s", err.msg);
  const double h = w.p.dyn_dt, c = w.p.dyn_gamma / MU;
  size_t nf = w.nf;
  double *x0 = malloc(2 * w.n * sizeof *x0), *g = malloc(2 * w.n * sizeof *g);
  memcpy(x0, w.st->c->P, 2 * w.n * sizeof *x0);
  lw_system_nurbs.gradient(w.st, g, &err);
  gsl_matrix *A = gsl_matrix_alloc(nf, nf);
  for (size_t a = 0; a < nf; a++)
    for (size_t b = 0; b < nf; b++)
      gsl_matrix_set(A, a, b, (1 + h * c / 2) * gsl_matrix_get(w.M, a, b) + h * h * gsl_matrix_get(w.K, a, b));
  cr_assert_eq(gsl_linalg_cholesky_decomp1(A), 0);
  gsl_vector *r = gsl_vector_alloc(nf);
  cr_assert_eq(lw_dynamics_step(d, &err), LW_OK, "%s", err.msg);
  double worst = 0.0, size = 0.0;
  for (int xy = 0; xy < 2; xy++) {
    for (size_t a = 0; a < nf; a++) gsl_vector_set(r, a, -h * h * g[2 * w.su->free_idx[a] + xy]);
    gsl_linalg_cholesky_svx(A, r);
    for (size_t a = 0; a < nf; a++) {
      size_t i = 2 * w.su->free_idx[a] + xy;
      worst = fmax(worst, fabs(w.st->c->P[i] - x0[i] - gsl_vector_get(r, a)));
      size = fmax(size, fabs(gsl_vector_get(r, a)));
    }
  }
  for (int s = 1; s < 200; s++) cr_assert_eq(lw_dynamics_step(d, &err), LW_OK, "%s", err.msg);
  cr_log_info("review scheme, %zu control points: first step %g off the dense solve (of %g), %d iterations a step "
              "at most", w.n, worst, size, d->iterations_max);
  cr_assert_lt(worst, 1e-9 * size, "the first step is %g off the dense solve (of %g)", worst, size);
  cr_assert_leq(d->iterations_max, 2, "%d iterations a step", d->iterations_max);
  gsl_matrix_free(A);
  gsl_vector_free(r);
  free(x0);
  free(g);
  lw_dynamics_free(d);
  wire_close(&w);
}
