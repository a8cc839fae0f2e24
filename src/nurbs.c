/* nurbs.c -- NURBS curves: the basis from GSL, the rational part (nurbs.h). */
#include "linewise/nurbs.h"

#include <float.h>
#include <gsl/gsl_errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

lw_status lw_nurbs_check_knots(int order, size_t n, const double *knot, size_t n_knots, lw_error *err)
{
  size_t k = (size_t)order;
  if (order < 2 || order > LW_NURBS_ORDER_MAX)
    return lw_error_set(err, LW_EINPUT, "order %d: expected 2 to %d", order, LW_NURBS_ORDER_MAX);
  if (n < k) return lw_error_set(err, LW_EINPUT, "%zu control points: order %d needs at least %d", n, order, order);
  if (n_knots != n + k)
    return lw_error_set(err, LW_EINPUT, "%zu knots: %zu control points of order %d need n + k = %zu", n_knots, n,
                        order, n + k);
  for (size_t i = 0; i < n_knots; i++)
    if (!isfinite(knot[i])) return lw_error_set(err, LW_EINPUT, "knot %zu (counting from 0) is not a finite number", i);
  for (size_t i = 0; i + 1 < n_knots; i++)
    if (knot[i + 1] < knot[i])
      return lw_error_set(err, LW_EINPUT, "knot %zu (%g) is less than knot %zu (%g): knots must not decrease (they "
                          "count from 0)", i + 1, knot[i + 1], i, knot[i]);
  for (size_t i = 1; i < k; i++)
    if (knot[i] != knot[0] || knot[n + i] != knot[n])
      return lw_error_set(err, LW_EINPUT, "not an open knot vector: the first %d and the last %d knots must be equal",
                          order, order);
  if (!(knot[n] > knot[k - 1])) return lw_error_set(err, LW_EINPUT, "the knots span an empty parameter range");
  if (n > k && (knot[k] == knot[k - 1] || knot[n - 1] == knot[n]))
    return lw_error_set(err, LW_EINPUT, "not an open knot vector: an end value is repeated more than k = %d times",
                        order);
  for (size_t i = k, run = 1; i < n; i++) {
    run = knot[i] == knot[i - 1] ? run + 1 : 1;
    if (run > k - 1) {
      while (i + 1 < n && knot[i + 1] == knot[i]) i++, run++; /* the whole run: it said 4 of 5 */
      return lw_error_set(err, LW_EINPUT, "knot %g is repeated %zu times inside: at most k - 1 = %d (the curve "
                          "would break)", knot[i], run, order - 1);
    }
  }
  return LW_OK;
}

lw_status lw_nurbs_check_knot_scale(int order, size_t n, const double *knot, lw_error *err)
{
  const size_t k = (size_t)order;
  /* as the control points: beyond, the basis's differences overflow */
  for (size_t i = 0; i < n + k; i++)
    if (!(fabs(knot[i]) <= LW_NURBS_KNOT_MAX))
      return lw_error_set(err, LW_EINPUT, "knot %zu (counting from 0) is %g: expected a number from -%g to %g", i,
                          knot[i], LW_NURBS_KNOT_MAX, LW_NURBS_KNOT_MAX);
  /* the basis divides by the spans, its derivatives by their powers: a span
  ** of 1e-100 of the range made the energy inf, one of 1e-150 NaN, and the
  ** whole run rejected every proposal */
  const double least = LW_NURBS_SPAN_MIN * (knot[n] - knot[k - 1]);
  for (size_t i = k; i <= n; i++)
    if (knot[i] > knot[i - 1] && !(knot[i] - knot[i - 1] >= least))
      return lw_error_set(err, LW_EINPUT, "the knot span [%.17g, %.17g] is %g of the parameter range: expected none "
                          "shorter than %g of it (or a repeated knot)", knot[i - 1], knot[i],
                          (knot[i] - knot[i - 1]) / (knot[n] - knot[k - 1]), LW_NURBS_SPAN_MIN);
  return LW_OK;
}

/* A GSL workspace of one knot span: the k basis functions nonzero on span
** s depend only on the 2k knots t[s-k+1 .. s+k], which rational() copies
** into it.  So GSL's search for the span, a linear scan of its knots, never
** sees more than one span (O(1) rather than O(n) an evaluation), and inner
** knots may repeat (gsl_bspline_knots() takes breakpoints, which cannot). */
static lw_status attach_basis(lw_nurbs *c, lw_error *err)
{
  if (!c->ws) c->ws = gsl_bspline_alloc((size_t)c->order, 2);
  if (!c->dB) c->dB = gsl_matrix_alloc((size_t)c->order, 3);
  if (!c->ws || !c->dB) return lw_error_set(err, LW_ENOMEM, "out of memory for a NURBS basis");
  return LW_OK;
}

/* The span s in [k-1, n-1] with knot[s] <= u < knot[s+1] (the last one at
** the end of the range), by bisection. */
static size_t span_of(const lw_nurbs *c, double u)
{
  size_t lo = (size_t)c->order - 1, hi = c->n;
  if (u >= c->knot[c->n]) {
    size_t s = c->n - 1;
    while (c->knot[s] == c->knot[s + 1]) s--;
    return s;
  }
  while (hi - lo > 1) {
    size_t mid = lo + (hi - lo) / 2;
    if (u < c->knot[mid]) hi = mid;
    else lo = mid;
  }
  return lo;
}

void lw_nurbs_free(lw_nurbs *c)
{
  if (!c) return;
  if (c->ws) gsl_bspline_free(c->ws);
  if (c->dB) gsl_matrix_free(c->dB);
  free(c->knot);
  free(c->P);
  free(c->w);
  free(c);
}

static lw_nurbs *alloc_curve(int order, size_t n, lw_error *err)
{
  lw_nurbs *c = calloc(1, sizeof *c);
  if (c) {
    c->order = order;
    c->n = n;
    c->pieces = 2;
    c->knot = malloc((n + (size_t)order) * sizeof *c->knot);
    c->P = malloc(2 * n * sizeof *c->P);
    c->w = malloc(n * sizeof *c->w);
  }
  if (!c || !c->knot || !c->P || !c->w) {
    lw_nurbs_free(c);
    lw_error_set(err, LW_ENOMEM, "out of memory for a NURBS curve of %zu control points", n);
    return NULL;
  }
  return c;
}

lw_nurbs *lw_nurbs_new(int order, size_t n, const double *knot, const double *P, const double *w, lw_error *err)
{
  if (lw_nurbs_check_knots(order, n, knot, n + (size_t)(order > 0 ? order : 0), err)) return NULL;
  for (size_t i = 0; i < n; i++) {
    if (w && !(w[i] > 0.0 && isfinite(w[i])))
      return lw_error_set(err, LW_EINPUT, "weight %zu is %g: weights must be > 0 (they count from 0)", i, w[i]), NULL;
    if (!isfinite(P[2 * i]) || !isfinite(P[2 * i + 1]))
      return lw_error_set(err, LW_EINPUT, "control point %zu (counting from 0) is not finite", i), NULL;
  }
  lw_nurbs *c = alloc_curve(order, n, err);
  if (!c) return NULL;
  memcpy(c->knot, knot, (n + (size_t)order) * sizeof *knot);
  memcpy(c->P, P, 2 * n * sizeof *P);
  for (size_t i = 0; i < n; i++) c->w[i] = w ? w[i] : 1.0;
  if (attach_basis(c, err)) {
    lw_nurbs_free(c);
    return NULL;
  }
  return c;
}

lw_nurbs *lw_nurbs_copy(const lw_nurbs *c, lw_error *err)
{
  lw_nurbs *d = lw_nurbs_new(c->order, c->n, c->knot, c->P, c->w, err);
  if (d) d->pieces = c->pieces;
  return d;
}

double lw_nurbs_u0(const lw_nurbs *c) { return c->knot[c->order - 1]; }

double lw_nurbs_u1(const lw_nurbs *c) { return c->knot[c->n]; }

/* The k B-spline basis functions nonzero at u (clamped to the range) and
** their first and second derivatives, into c->dB; returns the first's
** index. */
static size_t basis_at(const lw_nurbs *c, double u)
{
  const size_t k = (size_t)c->order;
  double u0 = lw_nurbs_u0(c), u1 = lw_nurbs_u1(c);
  u = u < u0 ? u0 : u > u1 ? u1 : u;
  size_t first, last;
  /* the second derivative of an order-2 basis is 0; GSL wants nderiv < k there */
  size_t nd = k > 2 ? 2 : 1;
  size_t s = span_of(c, u);
  for (size_t i = 0; i < 2 * k; i++) gsl_vector_set(c->ws->knots, i, c->knot[s + 1 - k + i]);
  gsl_matrix_set_zero(c->dB);
  gsl_bspline_deriv_eval_nonzero(u, nd, c->dB, &first, &last, c->ws);
  return s + 1 - k;
}

size_t lw_nurbs_rational(const lw_nurbs *c, double u, double *R)
{
  const int k = c->order;
  size_t first = basis_at(c, u);
  double W[3] = {0.0, 0.0, 0.0};
  for (int j = 0; j < k; j++)
    for (int d = 0; d < 3; d++) W[d] += c->w[first + (size_t)j] * gsl_matrix_get(c->dB, (size_t)j, (size_t)d);
  /* R W = w N, differentiated once and twice (the quotient rule) */
  for (int j = 0; j < k; j++) {
    double wj = c->w[first + (size_t)j];
    double r = wj * gsl_matrix_get(c->dB, (size_t)j, 0) / W[0];
    double r1 = (wj * gsl_matrix_get(c->dB, (size_t)j, 1) - r * W[1]) / W[0];
    double r2 = (wj * gsl_matrix_get(c->dB, (size_t)j, 2) - 2.0 * r1 * W[1] - r * W[2]) / W[0];
    R[j] = r;
    R[k + j] = r1;
    R[2 * k + j] = r2;
  }
  return first;
}

void lw_nurbs_eval(const lw_nurbs *c, double u, double pt[2], double d1[2], double d2[2])
{
  double R[3 * LW_NURBS_ORDER_MAX];
  const int k = c->order;
  size_t first = lw_nurbs_rational(c, u, R);
  double *out[3] = {pt, d1, d2};
  for (int d = 0; d < 3; d++) {
    if (!out[d]) continue;
    out[d][0] = out[d][1] = 0.0;
    for (int j = 0; j < k; j++) {
      out[d][0] += R[d * k + j] * c->P[2 * (first + (size_t)j)];
      out[d][1] += R[d * k + j] * c->P[2 * (first + (size_t)j) + 1];
    }
  }
}

int lw_nurbs_polynomial(const lw_nurbs *c)
{
  for (size_t i = 1; i < c->n; i++)
    if (c->w[i] != c->w[0]) return 0;
  return 1;
}

lw_status lw_nurbs_insert_knot(lw_nurbs *c, double u, lw_error *err)
{
  const size_t k = (size_t)c->order, p = k - 1, n = c->n;
  if (!(u >= lw_nurbs_u0(c) && u < lw_nurbs_u1(c)))
    return lw_error_set(err, LW_EINPUT, "knot %g is outside the parameter range [%g, %g)", u, lw_nurbs_u0(c),
                        lw_nurbs_u1(c));
  size_t s = p; /* the span: knot[s] <= u < knot[s + 1] */
  while (s + 1 < n && c->knot[s + 1] <= u) s++;
  size_t mult = 0;
  for (size_t i = 0; i < n + k; i++) mult += c->knot[i] == u;
  if (mult + 1 > p)
    return lw_error_set(err, LW_EINPUT, "knot %g would be repeated %zu times: at most k - 1 = %zu", u, mult + 1, p);
  double *knot = malloc((n + k + 1) * sizeof *knot), *P = malloc(2 * (n + 1) * sizeof *P),
         *w = malloc((n + 1) * sizeof *w);
  if (!knot || !P || !w) {
    free(knot), free(P), free(w);
    return lw_error_set(err, LW_ENOMEM, "out of memory inserting a knot");
  }
  /* Q_i = (1 - a_i) P_{i-1} + a_i P_i on the affected points, in
  ** homogeneous coordinates (w x, w y, w) */
  for (size_t i = 0; i <= n; i++) {
    double a = i + p <= s ? 1.0 : i > s ? 0.0 : (u - c->knot[i]) / (c->knot[i + p] - c->knot[i]);
    double h[3] = {0.0, 0.0, 0.0};
    if (a > 0.0 && i < n) {
      h[0] += a * c->w[i] * c->P[2 * i];
      h[1] += a * c->w[i] * c->P[2 * i + 1];
      h[2] += a * c->w[i];
    }
    if (a < 1.0 && i > 0) {
      h[0] += (1.0 - a) * c->w[i - 1] * c->P[2 * (i - 1)];
      h[1] += (1.0 - a) * c->w[i - 1] * c->P[2 * (i - 1) + 1];
      h[2] += (1.0 - a) * c->w[i - 1];
    }
    w[i] = h[2];
    P[2 * i] = h[0] / h[2];
    P[2 * i + 1] = h[1] / h[2];
  }
  memcpy(knot, c->knot, (s + 1) * sizeof *knot);
  knot[s + 1] = u;
  memcpy(knot + s + 2, c->knot + s + 1, (n + k - s - 1) * sizeof *knot);
  free(c->knot), free(c->P), free(c->w);
  c->knot = knot;
  c->P = P;
  c->w = w;
  c->n = n + 1;
  return LW_OK;
}

/* The knot vector of lw_nurbs_refine into t (n + spans (elevate + split -
** 1) + k2 of them); returns its length. */
static size_t refined_knots(const lw_nurbs *c, size_t k2, size_t elevate, size_t split, double *t)
{
  const size_t k = (size_t)c->order, n = c->n;
  const double u1 = lw_nurbs_u1(c);
  size_t m = 0;
  double a = lw_nurbs_u0(c);
  for (size_t j = 0; j < k2; j++) t[m++] = a;
  for (size_t i = k; i <= n;) { /* knot[i] is the next value after a */
    double b = c->knot[i];
    size_t mult = 1;
    while (i + mult <= n && c->knot[i + mult] == b) mult++;
    for (size_t q = 1; q < split; q++) t[m++] = a + (b - a) * (double)q / (double)split;
    if (b == u1) break;
    for (size_t j = 0; j < mult + elevate; j++) t[m++] = b;
    a = b;
    i += mult;
  }
  for (size_t j = 0; j < k2; j++) t[m++] = u1;
  return m;
}

/* The new control points solve the interpolation of the curve's
** homogeneous coordinates (w x, w y, w) at the new basis's Greville
** abscissae: the curve lies in the new space, so the interpolant is the
** curve itself, to rounding.  That collocation matrix is banded (k2 - 1 on
** either side) and totally positive, so Gaussian elimination without
** pivoting is stable (de Boor and Pinkus 1977).  A polynomial curve stays
** one: its weights are kept and only its points interpolated. */
lw_status lw_nurbs_refine(lw_nurbs *c, int elevate, int split, lw_error *err)
{
  if (elevate < 0 || split < 1)
    return lw_error_set(err, LW_EINPUT, "elevate %d and split %d: expected elevate >= 0 and split >= 1", elevate,
                        split);
  if (!elevate && split == 1) return LW_OK;
  const size_t k = (size_t)c->order, n = c->n, k2 = k + (size_t)elevate, hb = k2 - 1, wb = 2 * hb + 1;
  if (k2 > LW_NURBS_ORDER_MAX)
    return lw_error_set(err, LW_EINPUT, "order %zu raised by %d is %zu: at most %d", k, elevate, k2,
                        LW_NURBS_ORDER_MAX);
  size_t spans = 1; /* the distinct knot spans */
  for (size_t i = k; i < n; i++) spans += c->knot[i] != c->knot[i - 1];
  const double want = (double)n + (double)spans * ((double)elevate + (double)split - 1.0);
  if (want > LW_NURBS_REFINED_MAX)
    return lw_error_set(err, LW_EINPUT, "%zu control points raised by %d and split %d times would be %.0f: at most %d",
                        n, elevate, split, want, LW_NURBS_REFINED_MAX);
  const int poly = lw_nurbs_polynomial(c);
  double *t = malloc(((size_t)want + k2) * sizeof *t); /* n2 + k2 knots: want is n2 */
  lw_nurbs *d = NULL;
  double *A = NULL, *h = NULL;
  lw_status st = LW_OK;
  if (!t) goto nomem;
  size_t n2 = refined_knots(c, k2, (size_t)elevate, (size_t)split, t) - k2;
  if (!(d = alloc_curve((int)k2, n2, err))) {
    free(t);
    return LW_ENOMEM;
  }
  memcpy(d->knot, t, (n2 + k2) * sizeof *t);
  A = calloc(n2 * wb, sizeof *A);
  h = malloc(3 * n2 * sizeof *h);
  if (attach_basis(d, err) || !A || !h) goto nomem;
  for (size_t i = 0; i < n2; i++) {
    double xi = 0.0;
    for (size_t j = 1; j < k2; j++) xi += t[i + j];
    xi /= (double)(k2 - 1);
    size_t f2 = basis_at(d, xi);
    for (size_t j = 0; j < k2; j++) A[i * wb + (f2 + j + hb - i)] = gsl_matrix_get(d->dB, j, 0);
    size_t f = basis_at(c, xi);
    double *hi = h + 3 * i;
    hi[0] = hi[1] = hi[2] = 0.0;
    for (size_t j = 0; j < k; j++) {
      double nw = gsl_matrix_get(c->dB, j, 0) * (poly ? 1.0 : c->w[f + j]);
      hi[0] += nw * c->P[2 * (f + j)];
      hi[1] += nw * c->P[2 * (f + j) + 1];
      hi[2] += nw;
    }
  }
  for (size_t col = 0; col < n2; col++) {
    const double *pr = A + col * wb + hb; /* pr[j]: column col + j of row col */
    if (!(fabs(pr[0]) > 0.0)) {
      st = lw_error_set(err, LW_EINPUT, "the refined basis is singular at control point %zu", col);
      goto out;
    }
    for (size_t r = col + 1; r < n2 && r <= col + hb; r++) {
      double *rr = A + r * wb + hb - (r - col); /* rr[j]: column col + j of row r */
      double f = rr[0] / pr[0];
      for (size_t j = 0; j <= hb && col + j < n2; j++) rr[j] -= f * pr[j];
      for (int q = 0; q < 3; q++) h[3 * r + q] -= f * h[3 * col + q];
    }
  }
  for (size_t i = n2; i-- > 0;) {
    const double *ar = A + i * wb + hb;
    for (size_t j = 1; j <= hb && i + j < n2; j++)
      for (int q = 0; q < 3; q++) h[3 * i + q] -= ar[j] * h[3 * (i + j) + q];
    for (int q = 0; q < 3; q++) h[3 * i + q] /= ar[0];
  }
  for (size_t i = 0; i < n2; i++) {
    double wi = poly ? c->w[0] : h[3 * i + 2];
    d->w[i] = wi;
    d->P[2 * i] = poly ? h[3 * i] : h[3 * i] / wi;
    d->P[2 * i + 1] = poly ? h[3 * i + 1] : h[3 * i + 1] / wi;
    if (!(wi > 0.0) || !isfinite(d->P[2 * i]) || !isfinite(d->P[2 * i + 1])) {
      st = lw_error_set(err, LW_EINPUT, "the refined curve's control point %zu came out as (%g, %g) of weight %g", i,
                        d->P[2 * i], d->P[2 * i + 1], wi);
      goto out;
    }
  }
  /* an open knot vector interpolates its ends: keep them to the bit */
  memcpy(d->P, c->P, 2 * sizeof *d->P);
  memcpy(d->P + 2 * (n2 - 1), c->P + 2 * (n - 1), 2 * sizeof *d->P);
  d->w[0] = c->w[0];
  d->w[n2 - 1] = c->w[n - 1];
  lw_nurbs swap = *c;
  *c = *d;
  *d = swap;
  goto out;
nomem:
  st = lw_error_set(err, LW_ENOMEM, "out of memory refining a NURBS curve");
out:
  lw_nurbs_free(d);
  free(t), free(A), free(h);
  return st;
}

/* Beziers deeper than this many bisections are kept as they are (and their
** distance reported): a span is then 2^-24 of its length. */
#define BEZIER_DEPTH 24
#define BEZIER_SAMPLES 32

/* The curve run backwards, c~(-u) = c(u): GSL evaluates at a knot on the
** span to its right, so the derivative at the right end of a span, which
** jumps at a knot of multiplicity k - 1, is -c~'(-b) on c~'s span to the
** right of -b. */
static lw_nurbs *reversed(const lw_nurbs *c)
{
  size_t n = c->n, k = (size_t)c->order;
  double *knot = malloc((n + k) * sizeof *knot), *P = malloc(2 * n * sizeof *P), *w = malloc(n * sizeof *w);
  lw_nurbs *r = NULL;
  if (knot && P && w) {
    for (size_t i = 0; i < n + k; i++) knot[i] = -c->knot[n + k - 1 - i];
    for (size_t i = 0; i < n; i++) {
      P[2 * i] = c->P[2 * (n - 1 - i)];
      P[2 * i + 1] = c->P[2 * (n - 1 - i) + 1];
      w[i] = c->w[n - 1 - i];
    }
    lw_error err;
    r = lw_nurbs_new(c->order, n, knot, P, w, &err);
  }
  free(knot), free(P), free(w);
  return r;
}

static double bezier_piece(const lw_nurbs *c, const lw_nurbs *rev, double a, double b, double tol, int depth,
                           void (*emit)(const double B[8], void *ctx), void *ctx)
{
  double pa[2], da[2], pb[2], db[2], B[8];
  lw_nurbs_eval(c, a, pa, da, NULL);
  lw_nurbs_eval(rev, -b, pb, db, NULL);
  db[0] = -db[0];
  db[1] = -db[1];
  double h = b - a;
  for (int q = 0; q < 2; q++) {
    B[q] = pa[q];
    B[2 + q] = pa[q] + h / 3 * da[q];
    B[4 + q] = pb[q] - h / 3 * db[q];
    B[6 + q] = pb[q];
  }
  double worst = 0.0;
  for (int s = 1; s < BEZIER_SAMPLES; s++) {
    double t = (double)s / BEZIER_SAMPLES, m = 1 - t, pt[2];
    lw_nurbs_eval(c, a + t * h, pt, NULL, NULL);
    double x = m * m * m * B[0] + 3 * m * m * t * B[2] + 3 * m * t * t * B[4] + t * t * t * B[6];
    double y = m * m * m * B[1] + 3 * m * m * t * B[3] + 3 * m * t * t * B[5] + t * t * t * B[7];
    worst = fmax(worst, hypot(x - pt[0], y - pt[1]));
  }
  if (worst <= tol || depth == BEZIER_DEPTH) {
    emit(B, ctx);
    return worst;
  }
  double mid = 0.5 * (a + b);
  double w0 = bezier_piece(c, rev, a, mid, tol, depth + 1, emit, ctx);
  return fmax(w0, bezier_piece(c, rev, mid, b, tol, depth + 1, emit, ctx));
}

double lw_nurbs_beziers(const lw_nurbs *c, double tol, void (*emit)(const double B[8], void *ctx), void *ctx)
{
  lw_nurbs *rev = reversed(c);
  if (!rev) return NAN;
  /* no closer than the evaluation's rounding: a tolerance under it split
  ** every span 2^24 times (a run drew for ever) */
  double scale = 0.0;
  for (size_t i = 0; i < 2 * c->n; i++) scale = fmax(scale, fabs(c->P[i]));
  tol = fmax(tol, 1024.0 * DBL_EPSILON * scale);
  double worst = 0.0;
  for (size_t s = (size_t)c->order - 1; s < c->n; s++)
    if (c->knot[s + 1] > c->knot[s])
      worst = fmax(worst, bezier_piece(c, rev, c->knot[s], c->knot[s + 1], tol, 0, emit, ctx));
  lw_nurbs_free(rev);
  return worst;
}
