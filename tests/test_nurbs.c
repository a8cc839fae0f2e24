/*
** test_nurbs.c -- NURBS curves (nurbs.h): the GSL basis against Cox-de Boor,
** a polynomial curve against its Bezier form after knot insertion, circles
** with the standard rational weights, and refused knots and weights.
*/
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/nurbs.h"
#include "testutil.h"

/* d-th derivative of N_{i,k} at u by the Cox-de Boor recursion (0/0 = 0),
** half-open spans except the last, which is closed at the end. */
static double cox(const double *t, size_t nt, size_t i, int k, double u, int d)
{
  if (k == 1) {
    if (d > 0) return 0.0;
    double end = t[nt - 1];
    if (u == end) return t[i] < end && t[i + 1] == end ? 1.0 : 0.0;
    return t[i] <= u && u < t[i + 1] ? 1.0 : 0.0;
  }
  double a = t[i + (size_t)k - 1] - t[i], b = t[i + (size_t)k] - t[i + 1], r = 0.0;
  if (d == 0) {
    if (a > 0) r += (u - t[i]) / a * cox(t, nt, i, k - 1, u, 0);
    if (b > 0) r += (t[i + (size_t)k] - u) / b * cox(t, nt, i + 1, k - 1, u, 0);
    return r;
  }
  /* N' = (k-1) (N_{i,k-1} / a - N_{i+1,k-1} / b), differentiated d-1 more times */
  if (a > 0) r += (k - 1) / a * cox(t, nt, i, k - 1, u, d - 1);
  if (b > 0) r -= (k - 1) / b * cox(t, nt, i + 1, k - 1, u, d - 1);
  return r;
}

/* An open knot vector of n + k knots on [0, 1] with random inner knots,
** some repeated (up to k - 1 times). */
static void random_knots(size_t n, int k, double *t)
{
  size_t inner = n - (size_t)k;
  for (int j = 0; j < k; j++) {
    t[j] = 0.0;
    t[n + (size_t)j] = 1.0;
  }
  double u = 0.0;
  for (size_t j = 0; j < inner;) {
    u += urand(0.2, 1.0);
    int rep = 1 + (urand(0, 1) < 0.3 ? (int)urand(0, k - 1) : 0);
    for (int r = 0; r < rep && j < inner; r++, j++) t[(size_t)k + j] = u;
  }
  double end = u + urand(0.2, 1.0);
  for (size_t j = 0; j < inner; j++) t[(size_t)k + j] /= end;
}

Test(nurbs, the_gsl_basis_matches_cox_de_boor_with_its_derivatives)
{
  rng_seed(17);
  for (int k = 2; k <= 6; k++) {
    size_t n = (size_t)k + 6;
    double t[32], P[64], R[3 * LW_NURBS_ORDER_MAX];
    random_knots(n, k, t);
    for (size_t i = 0; i < 2 * n; i++) P[i] = urand(-1, 1);
    lw_error err;
    lw_nurbs *c = lw_nurbs_new(k, n, t, P, NULL, &err);
    cr_assert_not_null(c, "order %d: %s", k, err.msg);
    for (int s = 0; s <= 400; s++) {
      double u = s / 400.0;
      size_t first = lw_nurbs_rational(c, u, R);
      for (size_t i = 0; i < n; i++)
        for (int d = 0; d < (k > 2 ? 3 : 2); d++) {
          /* derivatives are one-sided at a knot: compare inside spans only */
          int at_knot = 0;
          for (size_t j = 0; j < n + (size_t)k; j++) at_knot |= d > 0 && fabs(u - t[j]) < 1e-12;
          if (at_knot) continue;
          double want = cox(t, n + (size_t)k, i, k, u, d);
          double got = i >= first && i < first + (size_t)k ? R[d * k + (int)(i - first)] : 0.0;
          double scale = d == 0 ? 1.0 : d == 1 ? 10.0 : 100.0;
          cr_assert(fabs(got - want) <= 1e-11 * scale * (1 + fabs(want)), "k %d, N_%zu^(%d)(%g) = %.15g, Cox-de Boor %.15g",
                    k, i, d, u, got, want);
        }
    }
    lw_nurbs_free(c);
  }
}

/* The point at t in [0, 1] of the Bezier curve of degree p on Q (de Casteljau). */
static void casteljau(const double *Q, int p, double t, double out[2])
{
  double b[2 * LW_NURBS_ORDER_MAX];
  for (int i = 0; i <= p; i++) b[2 * i] = Q[2 * i], b[2 * i + 1] = Q[2 * i + 1];
  for (int r = 1; r <= p; r++)
    for (int i = 0; i <= p - r; i++)
      for (int c = 0; c < 2; c++) b[2 * i + c] = (1 - t) * b[2 * i + c] + t * b[2 * (i + 1) + c];
  out[0] = b[0];
  out[1] = b[1];
}

Test(nurbs, a_polynomial_curve_is_its_bezier_form_after_knot_insertion)
{
  rng_seed(4);
  for (int k = 3; k <= 5; k++) {
    size_t n = 9;
    double t[32], P[32];
    random_knots(n, k, t);
    for (size_t i = 0; i < 2 * n; i++) P[i] = urand(-5, 5);
    lw_error err;
    lw_nurbs *c = lw_nurbs_new(k, n, t, P, NULL, &err), *b = lw_nurbs_copy(c, &err);
    cr_assert_not_null(b);
    /* every inner knot up to multiplicity k - 1: then each span's k control
    ** points are its Bezier points */
    for (size_t j = (size_t)k; j < n; j++) {
      if (j > (size_t)k && t[j] == t[j - 1]) continue;
      size_t m = 0;
      for (size_t i = 0; i < n + (size_t)k; i++) m += t[i] == t[j];
      for (; m < (size_t)k - 1; m++) cr_assert_eq(lw_nurbs_insert_knot(b, t[j], &err), LW_OK, "%s", err.msg);
    }
    size_t spans = (b->n - 1) / (size_t)(k - 1);
    cr_assert_eq(spans * (size_t)(k - 1) + 1, b->n, "Bezier form: %zu points for order %d", b->n, k);
    double worst = 0.0;
    for (size_t s = 0; s < spans; s++) {
      double a = b->knot[(size_t)k - 1 + s * (size_t)(k - 1)], e = b->knot[(size_t)k + s * (size_t)(k - 1)];
      cr_assert_gt(e, a);
      for (int q = 0; q <= 20; q++) {
        double tau = q / 20.0, want[2], got[2];
        casteljau(b->P + 2 * s * (size_t)(k - 1), k - 1, tau, want);
        lw_nurbs_eval(c, a + tau * (e - a), got, NULL, NULL);
        worst = fmax(worst, hypot(got[0] - want[0], got[1] - want[1]));
      }
    }
    cr_assert_lt(worst, 1e-12, "order %d: the curve is %g from its Bezier form", k, worst);
    lw_nurbs_free(c);
    lw_nurbs_free(b);
  }
}

Test(nurbs, knot_insertion_keeps_a_rational_curve)
{
  rng_seed(9);
  size_t n = 7;
  double t[16], P[14], w[7];
  random_knots(n, 4, t);
  for (size_t i = 0; i < n; i++) P[2 * i] = urand(-3, 3), P[2 * i + 1] = urand(-3, 3), w[i] = urand(0.3, 3);
  lw_error err;
  lw_nurbs *c = lw_nurbs_new(4, n, t, P, w, &err), *b = lw_nurbs_copy(c, &err);
  cr_assert_eq(lw_nurbs_insert_knot(b, 0.37, &err), LW_OK);
  cr_assert_eq(lw_nurbs_insert_knot(b, 0.61, &err), LW_OK);
  cr_assert_eq(b->n, n + 2);
  for (int q = 0; q <= 50; q++) {
    double p0[2], p1[2], d0[2], d1[2];
    lw_nurbs_eval(c, q / 50.0, p0, d0, NULL);
    lw_nurbs_eval(b, q / 50.0, p1, d1, NULL);
    cr_assert(hypot(p0[0] - p1[0], p0[1] - p1[1]) < 1e-12 && hypot(d0[0] - d1[0], d0[1] - d1[1]) < 1e-10,
              "u = %g: the curve moved by %g", q / 50.0, hypot(p0[0] - p1[0], p0[1] - p1[1]));
  }
  lw_nurbs_free(c);
  lw_nurbs_free(b);
}

/* The largest distance between two curves' points and first and second
** derivatives over 401 parameters, relative to the curve's own size (or
** absolute below 1). */
static void curve_distance(const lw_nurbs *a, const lw_nurbs *b, double d[3])
{
  double scale[3] = {0.0, 0.0, 0.0};
  d[0] = d[1] = d[2] = 0.0;
  for (int q = 0; q <= 400; q++) {
    double u = q / 400.0, p[3][2], r[3][2];
    lw_nurbs_eval(a, u, p[0], p[1], p[2]);
    lw_nurbs_eval(b, u, r[0], r[1], r[2]);
    for (int j = 0; j < 3; j++) {
      d[j] = fmax(d[j], hypot(p[j][0] - r[j][0], p[j][1] - r[j][1]));
      scale[j] = fmax(scale[j], hypot(p[j][0], p[j][1]));
    }
  }
  for (int j = 0; j < 3; j++) d[j] /= fmax(scale[j], 1.0);
}

Test(nurbs, refinement_and_elevation_keep_the_curve_and_its_continuity)
{
  /* random rational and polynomial curves of orders 2 to 6 on knots with
  ** repeats, raised by 0 to 2 and split 1 to 5: the same curve (point,
  ** first and second derivative; the derivatives of an order-2 curve jump
  ** at its knots, which each side evaluates alike), the new counts, the
  ** end points to the bit, polynomial curves still polynomial */
  rng_seed(23);
  lw_error err;
  for (int k = 2; k <= 6; k++)
    for (int e = 0; e <= 2; e++)
      for (int split = 1; split <= 5; split += 2)
        for (int rational = 0; rational <= 1; rational++) {
          size_t n = (size_t)k + 5;
          double t[32], P[64], w[32];
          random_knots(n, k, t);
          for (size_t i = 0; i < n; i++)
            P[2 * i] = urand(-3, 3), P[2 * i + 1] = urand(-3, 3), w[i] = rational ? urand(0.3, 3) : 1.0;
          lw_nurbs *c = lw_nurbs_new(k, n, t, P, w, &err), *b = lw_nurbs_copy(c, &err);
          cr_assert_not_null(b);
          cr_assert_eq(lw_nurbs_refine(b, e, split, &err), LW_OK, "%s", err.msg);
          size_t distinct = 0; /* inner knot values */
          for (size_t i = (size_t)k; i < n; i++) distinct += t[i] != t[i - 1];
          cr_assert_eq(b->order, k + e);
          cr_assert_eq(b->n, n + (size_t)e * (distinct + 1) + (distinct + 1) * (size_t)(split - 1),
                       "k %d e %d split %d: %zu points", k, e, split, b->n);
          double d[3];
          curve_distance(c, b, d);
          cr_assert(d[0] < 1e-12 && d[1] < 1e-10 && d[2] < 1e-8, "k %d e %d split %d rational %d: moved %g %g %g", k, e,
                    split, rational, d[0], d[1], d[2]);
          cr_assert(b->P[0] == P[0] && b->P[1] == P[1] && b->P[2 * b->n - 2] == P[2 * n - 2] &&
                    b->P[2 * b->n - 1] == P[2 * n - 1]);
          cr_assert_eq(lw_nurbs_polynomial(b), !rational);
          lw_nurbs_free(c);
          lw_nurbs_free(b);
        }
}

Test(nurbs, refinement_refuses_an_order_or_a_count_past_the_largest)
{
  double t[] = {0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1}, P[12] = {0, 0, 1, 1, 2, 0, 3, 1, 4, 0, 5, 1};
  lw_error err;
  lw_nurbs *c = lw_nurbs_new(6, 6, t, P, NULL, &err);
  cr_assert_eq(lw_nurbs_refine(c, 3, 1, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "at most 8"), "%s", err.msg);
  cr_assert_eq(c->n, 6, "a refused refinement leaves the curve");
  cr_assert_eq(lw_nurbs_refine(c, 2, 1, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(c->order, 8);
  lw_nurbs_free(c);
  /* a polyline of 2000 points (1999 spans) split 1000 times would have
  ** 2000 + 1999 x 999 = 1,999,001 points: refused before anything is
  ** allocated */
  size_t n = 2000;
  double *tk = malloc((n + 2) * sizeof *tk), *pts = calloc(2 * n, sizeof *pts);
  for (size_t i = 0; i < n + 2; i++) tk[i] = i == 0 ? 0.0 : i > n ? 1.0 : (double)(i - 1) / (double)(n - 1);
  for (size_t i = 0; i < n; i++) pts[2 * i] = (double)i;
  c = lw_nurbs_new(2, n, tk, pts, NULL, &err);
  cr_assert_not_null(c, "%s", err.msg);
  cr_assert_eq(lw_nurbs_refine(c, 0, 1000, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "would be 1999001: at most 1000000"), "%s", err.msg);
  cr_assert_eq(lw_nurbs_refine(c, 0, 500, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(c->n, n + 1999 * 499);
  lw_nurbs_free(c);
  free(tk), free(pts);
}

Test(nurbs, a_circle_is_exact_with_the_standard_weights)
{
  /* nine points on a square, weights 1 and sqrt(2)/2, order 3 (quadratic),
  ** double inner knots: four exact quarter circles */
  const double r = 2.5, h = M_SQRT1_2;
  double P[18] = {r, 0, r, r, 0, r, -r, r, -r, 0, -r, -r, 0, -r, r, -r, r, 0};
  double w[9] = {1, h, 1, h, 1, h, 1, h, 1};
  double t[12] = {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1};
  lw_error err;
  lw_nurbs *c = lw_nurbs_new(3, 9, t, P, w, &err);
  cr_assert_not_null(c, "%s", err.msg);
  for (int q = 0; q <= 1000; q++) {
    double p[2], d1[2], d2[2];
    lw_nurbs_eval(c, q / 1000.0, p, d1, d2);
    cr_assert(fabs(hypot(p[0], p[1]) - r) < 1e-14 * r, "u = %g: radius %.17g", q / 1000.0, hypot(p[0], p[1]));
    /* the derivative is tangent, and curvature (x'y'' - y'x'') / |c'|^3 is 1 / r */
    cr_assert(fabs(p[0] * d1[0] + p[1] * d1[1]) < 1e-12 * r * hypot(d1[0], d1[1]));
    double kappa = (d1[0] * d2[1] - d1[1] * d2[0]) / pow(hypot(d1[0], d1[1]), 3);
    cr_assert(fabs(kappa - 1 / r) < 1e-11, "u = %g: curvature %.15g, expected %g", q / 1000.0, kappa, 1 / r);
  }
  cr_assert(!lw_nurbs_polynomial(c));
  lw_nurbs_free(c);
}

Test(nurbs, bad_knots_and_weights_are_refused_with_the_reason)
{
  double P[14] = {0}, w[7] = {1, 1, 1, 0, 1, 1, 1};
  /* the review's 12 knots for 7 control points of order 4 */
  double review[12] = {0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1, 1};
  double down[11] = {0, 0, 0, 0, 0.5, 0.25, 0.75, 1, 1, 1, 1};
  double shut[11] = {0, 0, 0, 0.1, 0.25, 0.5, 0.75, 1, 1, 1, 1};
  double good[11] = {0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1};
  lw_error err;
  cr_assert_eq(lw_nurbs_check_knots(4, 7, review, 12, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "12 knots") && strstr(err.msg, "n + k = 11"), "%s", err.msg);
  cr_assert_eq(lw_nurbs_check_knots(4, 7, down, 11, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "must not decrease"), "%s", err.msg);
  cr_assert_eq(lw_nurbs_check_knots(4, 7, shut, 11, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "open knot vector"), "%s", err.msg);
  double five[11] = {0, 0, 0, 0, 0, 0.5, 0.75, 1, 1, 1, 1};
  cr_assert_eq(lw_nurbs_check_knots(4, 7, five, 11, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "repeated more than k = 4 times"), "%s", err.msg);
  /* the whole run of an inner knot (it said 4 of 5) */
  double inner[13] = {0, 0, 0, 0, 0.5, 0.5, 0.5, 0.5, 0.5, 1, 1, 1, 1};
  cr_assert_eq(lw_nurbs_check_knots(4, 9, inner, 13, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "knot 0.5 is repeated 5 times inside: at most k - 1 = 3"), "%s", err.msg);
  /* a span of 1e-300 of the range made the energy NaN; knots of 1e300 the
  ** gravity's */
  double thin[11] = {0, 0, 0, 0, 1e-300, 0.5, 0.75, 1, 1, 1, 1};
  cr_assert_eq(lw_nurbs_check_knot_scale(4, 7, thin, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "the knot span [0, 1e-300] is 1e-300 of the parameter range: expected "
                            "none shorter than 1e-09 of it"), "%s", err.msg);
  double wide[11] = {-1e300, -1e300, -1e300, -1e300, 0, 0.5, 0.75, 1, 1, 1, 1};
  cr_assert_eq(lw_nurbs_check_knot_scale(4, 7, wide, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "knot 0 (counting from 0) is -1e+300: expected a number from -1e+09 to 1e+09"), "%s",
            err.msg);
  cr_assert_eq(lw_nurbs_check_knots(4, 7, good, 11, &err), LW_OK);
  cr_assert_null(lw_nurbs_new(4, 7, good, P, w, &err));
  cr_assert(strstr(err.msg, "weight 3 is 0"), "%s", err.msg);
  w[3] = -1;
  cr_assert_null(lw_nurbs_new(4, 7, good, P, w, &err));
  w[3] = 1;
  lw_nurbs *c = lw_nurbs_new(4, 7, good, P, w, &err);
  cr_assert_not_null(c);
  cr_assert_eq(lw_nurbs_insert_knot(c, 0.5, &err), LW_OK);
  cr_assert_eq(lw_nurbs_insert_knot(c, 0.5, &err), LW_OK);
  cr_assert_eq(lw_nurbs_insert_knot(c, 0.5, &err), LW_EINPUT, "a fourth 0.5 would break a cubic");
  lw_nurbs_free(c);
  /* the scale limits are the scene's: a span of 1e-8 refined 100 times is
  ** a curve (its copy was refused as "out of memory") */
  double fine[11] = {0, 0, 0, 0, 0.5, 0.50000001, 0.75, 1, 1, 1, 1};
  cr_assert_eq(lw_nurbs_check_knot_scale(4, 7, fine, &err), LW_OK, "%s", err.msg);
  c = lw_nurbs_new(4, 7, fine, P, NULL, &err);
  cr_assert_not_null(c, "%s", err.msg);
  cr_assert_eq(lw_nurbs_refine(c, 0, 100, &err), LW_OK, "%s", err.msg);
  lw_nurbs *copy = lw_nurbs_copy(c, &err);
  cr_assert_not_null(copy, "%s", err.msg);
  lw_nurbs_free(copy);
  lw_nurbs_free(c);
}
