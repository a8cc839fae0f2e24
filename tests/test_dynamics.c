/*
** test_dynamics.c -- the mass matrix of splines (splmass.h) and the
** Lagrangian driver (dynamics.h) against exact behaviour.
*/
#include <criterion/criterion.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_linalg.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/quad.h"
#include "linewise/splmass.h"
#include "linewise/spline.h"
#include "testutil.h"

/* Random regular-looking splines: nodes along a wavy line with handles a
** third of the spacing, jittered. */
static lw_splines *random_splines(size_t n_splines, const size_t *segs)
{
  lw_splines *sp = lw_splines_new(n_splines, segs, NULL);
  cr_assert_not_null(sp);
  for (size_t i = 0; i < n_splines; i++)
    for (size_t k = sp->first[i]; k < sp->first[i + 1]; k++) {
      double t = (double)(k - sp->first[i]);
      lw_node *nd = &sp->node[k];
      nd->px = 10 * t + urand(-2, 2);
      nd->py = 5 * (double)i + urand(-2, 2);
      nd->vx = 10.0 / 3 + urand(-1, 1);
      nd->vy = urand(-1, 1);
    }
  return sp;
}

/* The kinetic energy (rho/2) sum_seg sum_q w_q |r'_q| |rdot_q|^2 evaluated
** from the curves: rdot is the spline whose nodes are the velocities. */
static double kinetic_direct(const lw_splines *sp, const lw_quad *q, double rho, const double *v)
{
  const lw_node *vel = (const lw_node *)v;
  double t = 0.0;
  for (size_t i = 0; i < sp->n_splines; i++)
    for (size_t k = sp->first[i]; k + 1 < sp->first[i + 1]; k++)
      for (int j = 0; j < q->n; j++) {
        double d1[2], rdot[2];
        lw_segment_eval(&sp->node[k], &sp->node[k + 1], q->s[j], NULL, d1, NULL);
        lw_segment_eval(&vel[k], &vel[k + 1], q->s[j], rdot, NULL, NULL);
        t += 0.5 * rho * q->w[j] * hypot(d1[0], d1[1]) * (rdot[0] * rdot[0] + rdot[1] * rdot[1]);
      }
  return t;
}

Test(splmass, the_matrix_gives_the_kinetic_energy_of_the_curves_and_solves_it)
{
  rng_seed(11);
  size_t segs[3] = {1, 3, 5};
  lw_splines *sp = random_splines(3, segs);
  lw_quad q;
  cr_assert_eq(lw_quad_init(&q, 6, NULL), LW_OK);
  size_t n = 4 * sp->n_nodes;
  double *x = (double *)sp->node, *v = malloc(n * sizeof *v), *b = malloc(n * sizeof *b), *back = malloc(n * sizeof *back);
  lw_error err;
  lw_spline_mass *m = lw_spline_mass_new(sp, &q, 2.5, NULL, &err);
  cr_assert_not_null(m, "%s", err.msg);
  cr_assert_eq(lw_spline_mass_at(m, x, &err), LW_OK, "%s", err.msg);
  for (int trial = 0; trial < 5; trial++) {
    for (size_t i = 0; i < n; i++) v[i] = urand(-1, 1);
    lw_spline_mass_apply(m, v, b);
    double t = 0.0;
    for (size_t i = 0; i < n; i++) t += 0.5 * v[i] * b[i];
    double want = kinetic_direct(sp, &q, 2.5, v);
    cr_assert(fabs(t - want) <= 1e-12 * want, "1/2 v'Mv = %.17g, the curves give %.17g", t, want);
    /* the band factor solves the matrix it was made from */
    lw_spline_mass_solve(m, b, back);
    for (size_t i = 0; i < n; i++) cr_assert(fabs(back[i] - v[i]) <= 1e-9 * (1 + fabs(v[i])), "coordinate %zu", i);
  }
  lw_spline_mass_free(m);
  free(v);
  free(b);
  free(back);
  lw_splines_free(sp);
}

Test(splmass, its_position_derivative_matches_central_differences)
{
  rng_seed(12);
  size_t segs[2] = {2, 4};
  lw_splines *sp = random_splines(2, segs);
  lw_quad q;
  cr_assert_eq(lw_quad_init(&q, 8, NULL), LW_OK);
  size_t n = 4 * sp->n_nodes;
  double *x = (double *)sp->node, *v = malloc(n * sizeof *v), *dx = malloc(n * sizeof *dx);
  for (size_t i = 0; i < n; i++) v[i] = urand(-1, 1);
  lw_spline_mass *m = lw_spline_mass_new(sp, &q, 1.7, NULL, NULL);
  cr_assert_not_null(m);
  lw_spline_mass_dx(m, x, v, dx);
  /* T(x) is smooth where |r'| > 0: the central difference errs by O(h^2)
  ** |T'''| ~ 1e-12 relative at h = 1e-6 of the coordinates' scale (10 mm),
  ** and rounding adds eps T / h ~ 1e-10; 1e-7 relative to the largest
  ** component leaves a wide margin and still catches any wrong factor. */
  double scale = 0.0;
  for (size_t i = 0; i < n; i++) scale = fmax(scale, fabs(dx[i]));
  for (size_t i = 0; i < n; i++) {
    double keep = x[i], h = 1e-5;
    x[i] = keep + h;
    double tp = kinetic_direct(sp, &q, 1.7, v);
    x[i] = keep - h;
    double tm = kinetic_direct(sp, &q, 1.7, v);
    x[i] = keep;
    double fd = (tp - tm) / (2 * h);
    cr_assert(fabs(fd - dx[i]) <= 1e-7 * scale, "coordinate %zu: analytic %.12g, central difference %.12g", i, dx[i],
              fd);
  }
  lw_spline_mass_free(m);
  free(v);
  free(dx);
  lw_splines_free(sp);
}

Test(splmass, held_coordinates_stay_held_and_the_rest_still_solve)
{
  rng_seed(13);
  size_t segs[1] = {4};
  lw_splines *sp = random_splines(1, segs);
  lw_quad q;
  cr_assert_eq(lw_quad_init(&q, 4, NULL), LW_OK);
  size_t n = 4 * sp->n_nodes;
  unsigned char *pin = calloc(n, 1);
  memset(pin, 1, 4);                      /* first node: point and vector */
  memset(pin + 4 * (sp->n_nodes - 1), 1, 2); /* last node: point only */
  double *x = (double *)sp->node, *v = malloc(n * sizeof *v), *b = malloc(n * sizeof *b), *back = malloc(n * sizeof *back);
  lw_spline_mass *m = lw_spline_mass_new(sp, &q, 1.0, pin, NULL);
  cr_assert_not_null(m);
  cr_assert_eq(lw_spline_mass_at(m, x, NULL), LW_OK);
  for (size_t i = 0; i < n; i++) v[i] = pin[i] ? 0.0 : urand(-1, 1);
  lw_spline_mass_apply(m, v, b);
  for (size_t i = 0; i < n; i++)
    if (pin[i]) b[i] = 1e3; /* ignored */
  lw_spline_mass_solve(m, b, back);
  for (size_t i = 0; i < n; i++) {
    cr_assert_eq(lw_spline_mass_pinned(m, i), pin[i]);
    if (pin[i]) cr_assert_eq(back[i], 0.0, "held coordinate %zu moved", i);
    else cr_assert(fabs(back[i] - v[i]) <= 1e-9 * (1 + fabs(v[i])), "coordinate %zu", i);
  }
  /* three nodes are too few: the matrix of a segment is singular */
  lw_quad q3;
  cr_assert_eq(lw_quad_init(&q3, 3, NULL), LW_OK);
  lw_error err;
  cr_assert_null(lw_spline_mass_new(sp, &q3, 1.0, NULL, &err));
  cr_assert(strstr(err.msg, "at least 4 quadrature nodes"), "%s", err.msg);
  lw_spline_mass_free(m);
  free(pin);
  free(v);
  free(b);
  free(back);
  lw_splines_free(sp);
}
