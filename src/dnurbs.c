/* dnurbs.c -- the D-NURBS matrices, banded (dnurbs.h). */
#include "linewise/dnurbs.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_linalg.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* What one Gauss point adds: u, its weight wq, the first of the k nonzero
** rational basis functions and R as lw_nurbs_rational gives it. */
typedef void gauss_fn(void *ctx, lw_nurbs *c, double u, double wq, size_t first, const double *R);

/* Halvings toward one end of a knot span whose weights lie far apart.
** Where the weights of a span's k control points differ by a ratio q, its
** rational basis turns within about q^(-1/p) of the span's end, where a
** heavy neighbour's B-spline vanishes like (u - a)^p: Gauss points spread
** over the span stepped over the turn, and an anneal put the curve's bends
** there (a wire of weights 1e-4 read an elastic energy 18 times below its
** own, 1e10 times at 1e-12 from a state file).  So the span is cut at h/2,
** h/4, ... from the end, down to h q^(-1/p), each piece with its own Gauss
** points.  At a knot of multiplicity m a B-spline of degree d starting
** there vanishes like (u - a)^(d + 1 - m), and at a clamped end (m = d + 1)
** the second one like (u - a)^1: p = d + 1 - m, at least 1, and at most
** 3, a simple knot's in a cubic (a light end point at a clamped end, p = 1,
** read 0.58 of its energy at w = 0.01 and 3e-5 of it at 1e-4 with p = 3).
** Up to a ratio of 2 (a circle's arcs, 1.4) the span is whole, as it was:
** its energy then within 1e-7 (2.4e-6 whole at 4, 1e-1 at 100). */
#define SPAN_HALVINGS_MAX 30
static int span_halvings(const lw_nurbs *c, size_t s, int right)
{
  const size_t k = (size_t)c->order, n_knots = c->n + k;
  double lo = c->w[s + 1 - k], hi = lo;
  for (size_t i = s + 2 - k; i <= s; i++) lo = fmin(lo, c->w[i]), hi = fmax(hi, c->w[i]);
  /* the knot's multiplicity, by its equal neighbours (the knots do not
  ** decrease; every knot asked was O(n) a proposal on a refined wire) */
  const size_t at = s + (size_t)right;
  int m = 1;
  for (size_t i = at; i > 0 && c->knot[i - 1] == c->knot[at]; i--) m++;
  for (size_t i = at + 1; i < n_knots && c->knot[i] == c->knot[at]; i++) m++;
  const double q = hi / lo;
  const int p = c->pieces < 2 ? 3 : (int)k - m < 1 ? 1 : (int)k - m > 3 ? 3 : (int)k - m;
  /* pieces of h 2^-30 resolve a ratio of 1e27 (1e9 where p = 1), past which
  ** a piece's Gauss points crowd the span's end to rounding; a ratio past
  ** the doubles (a log weight of -709) made the count undefined, and spans
  ** fell out of the energy.  Where p < 3 any ratio turns the basis within
  ** the span (an order 8 curve's end weight of 0.5 read 0.99 of its energy
  ** whole) */
  if (!(q <= 0x1p90)) return SPAN_HALVINGS_MAX;
  if (!(q > (p < 3 ? 1.0 : 2.0))) return 0;
  /* (p < 3: from a ratio just over 1 as many pieces as at 2, so that the
  ** count, and the energy with it, does not step as weights near each other
  ** move: a free-weight quench stalled 1e-3 above the minimum) */
  const double r = (double)(k - 1) * (q > 2.0 ? q : 2.0);
  const int j = (int)ceil(p == 3 ? log2(cbrt(q)) : p == 2 ? log2(sqrt(r)) : log2(r));
  return j < SPAN_HALVINGS_MAX ? j : SPAN_HALVINGS_MAX;
}

int lw_dnurbs_span_pieces(const lw_nurbs *c, size_t s, double *p0, double *p1)
{
  const double a = c->knot[s], b = c->knot[s + 1], h = b - a;
  const int ja = span_halvings(c, s, 0), jb = span_halvings(c, s, 1);
  if (!ja && !jb) {
    p0[0] = a;
    p1[0] = b;
    return 1;
  }
  /* a, a + h/2^ja, ..., a + h/2, then b - h/4, ..., b - h/2^jb, b (a side
  ** of no halving one piece) */
  int n = 0;
  const int la = ja ? ja : 1, lb = jb ? jb : 1;
  for (int piece = 0; piece < la; piece++, n++) {
    p0[n] = piece ? a + ldexp(h, piece - la - 1) : a;
    p1[n] = a + ldexp(h, piece - la);
  }
  for (int back = lb - 1; back >= 0; back--, n++) {
    p0[n] = b - ldexp(h, back - lb);
    p1[n] = back ? b - ldexp(h, back - lb - 1) : b;
  }
  return n;
}

/* Calls at() on every Gauss point of the knot spans s0 <= s < s1 (clipped
** to the curve's spans k - 1 .. n - 1), span by span, in order; a span of
** weights far apart in pieces (span_halvings). */
static lw_status each_point(lw_nurbs *c, int gauss, size_t s0, size_t s1, gauss_fn *at, void *ctx, lw_error *err)
{
  const size_t n = c->n, k = (size_t)c->order;
  gsl_integration_glfixed_table *gl = gsl_integration_glfixed_table_alloc((size_t)gauss);
  if (!gl) return lw_error_set(err, LW_ENOMEM, "out of memory for a Gauss table of %d points", gauss);
  double R[3 * LW_NURBS_ORDER_MAX];
  for (size_t s = s0 > k - 1 ? s0 : k - 1; s < n && s < s1; s++) {
    if (!(c->knot[s + 1] > c->knot[s])) continue; /* a repeated knot: no span */
    double p0[LW_DNURBS_PIECES_MAX], p1[LW_DNURBS_PIECES_MAX];
    const int pieces = lw_dnurbs_span_pieces(c, s, p0, p1);
    for (int piece = 0; piece < pieces; piece++) {
      for (size_t q = 0; q < (size_t)gauss; q++) {
        double u, wq;
        gsl_integration_glfixed_point(p0[piece], p1[piece], q, &u, &wq, gl);
        at(ctx, c, u, wq, lw_nurbs_rational(c, u, R), R);
      }
    }
  }
  gsl_integration_glfixed_table_free(gl);
  return LW_OK;
}

void lw_dnurbs_free(lw_dnurbs *d)
{
  if (!d) return;
  free(d->K);
  free(d->M1);
  free(d->b);
  free(d);
}

static void add_matrices(void *ctx, lw_nurbs *c, double u, double wq, size_t first, const double *R)
{
  lw_dnurbs *d = ctx;
  size_t k = (size_t)d->k;
  for (size_t i = 0; i < k; i++) {
    d->b[first + i] += wq * R[i];
    for (size_t j = 0; j <= i; j++) {
      double *Kb = d->K + (first + j) * k + (i - j), *Mb = d->M1 + (first + j) * k + (i - j);
      *Kb += wq * (d->alpha * R[k + i] * R[k + j] + d->beta * R[2 * k + i] * R[2 * k + j]);
      *Mb += wq * R[i] * R[j];
    }
  }
}

lw_status lw_dnurbs_assemble(lw_dnurbs *d, lw_nurbs *c, lw_error *err)
{
  memset(d->K, 0, d->n * (size_t)d->k * sizeof *d->K);
  memset(d->M1, 0, d->n * (size_t)d->k * sizeof *d->M1);
  memset(d->b, 0, d->n * sizeof *d->b);
  return each_point(c, d->gauss, 0, c->n, add_matrices, d, err);
}

lw_dnurbs *lw_dnurbs_new(lw_nurbs *c, double alpha, double beta, int gauss, lw_error *err)
{
  const size_t n = c->n, k = (size_t)c->order;
  lw_dnurbs *d = calloc(1, sizeof *d);
  if (d) {
    d->n = n;
    d->k = c->order;
    d->alpha = alpha;
    d->beta = beta;
    d->gauss = gauss;
    d->K = malloc(n * k * sizeof *d->K);
    d->M1 = malloc(n * k * sizeof *d->M1);
    d->b = malloc(n * sizeof *d->b);
  }
  if (!d || !d->K || !d->M1 || !d->b) {
    lw_dnurbs_free(d);
    lw_error_set(err, LW_ENOMEM, "out of memory for the D-NURBS matrices of %zu control points", n);
    return NULL;
  }
  if (lw_dnurbs_assemble(d, c, err)) {
    lw_dnurbs_free(d);
    return NULL;
  }
  return d;
}

/* The energy density's coefficients, and where its integrals go. */
typedef struct {
  double alpha, beta, mug[2];
  double *out;
} density_ctx;

/* dE/ds_j = w_j dE/dw_j = int alpha c_u . r_j' + beta c_uu . r_j'' - mug . r_j du
** with r_j = w_j q_j = R_j (P_j - c), by the product rule. */
static void add_grad_s(void *ctx, lw_nurbs *c, double u, double wq, size_t first, const double *R)
{
  density_ctx *g = ctx;
  size_t k = (size_t)c->order;
  double pt[2], d1[2], d2[2];
  lw_nurbs_eval(c, u, pt, d1, d2);
  for (size_t i = 0; i < k; i++) {
    size_t j = first + i;
    double r0 = R[i], r1 = R[k + i], r2 = R[2 * k + i], acc = 0.0;
    for (int x = 0; x < 2; x++) {
      double dp = c->P[2 * j + x] - pt[x];
      double q0 = r0 * dp, q1 = r1 * dp - r0 * d1[x], q2 = r2 * dp - 2.0 * r1 * d1[x] - r0 * d2[x];
      acc += g->alpha * d1[x] * q1 + g->beta * d2[x] * q2 - g->mug[x] * q0;
    }
    g->out[j] += wq * acc;
  }
}

lw_status lw_dnurbs_grad_s(lw_nurbs *c, double alpha, double beta, const double mug[2], int gauss, double *gs, lw_error *err)
{
  density_ctx g = {alpha, beta, {mug[0], mug[1]}, gs};
  memset(gs, 0, c->n * sizeof *gs);
  return each_point(c, gauss, 0, c->n, add_grad_s, &g, err);
}

lw_status lw_dnurbs_grad_w(lw_nurbs *c, double alpha, double beta, const double mug[2], int gauss, double *gw, lw_error *err)
{
  lw_status s = lw_dnurbs_grad_s(c, alpha, beta, mug, gauss, gw, err);
  for (size_t j = 0; j < c->n; j++) gw[j] /= c->w[j];
  return s;
}

static void add_energy(void *ctx, lw_nurbs *c, double u, double wq, size_t first, const double *R)
{
  density_ctx *g = ctx;
  double pt[2], d1[2], d2[2];
  lw_nurbs_eval(c, u, pt, d1, d2);
  g->out[0] += wq * 0.5 * (g->alpha * (d1[0] * d1[0] + d1[1] * d1[1]) + g->beta * (d2[0] * d2[0] + d2[1] * d2[1]));
  g->out[1] -= wq * (g->mug[0] * pt[0] + g->mug[1] * pt[1]);
}

lw_status lw_dnurbs_energy_near(lw_nurbs *c, double alpha, double beta, const double mug[2], int gauss, size_t j,
                                double term[2], lw_error *err)
{
  density_ctx g = {alpha, beta, {mug[0], mug[1]}, term};
  term[0] = term[1] = 0.0;
  return each_point(c, gauss, j, j + (size_t)c->order, add_energy, &g, err);
}

double lw_band_energy(const double *K, size_t n, int k, const double *P)
{
  double e = 0.0;
  for (size_t i = 0; i < n; i++)
    for (size_t d = 1; d < (size_t)k && i + d < n; d++) {
      const double dx = P[2 * (i + d)] - P[2 * i], dy = P[2 * (i + d) + 1] - P[2 * i + 1];
      e -= K[i * (size_t)k + d] * (dx * dx + dy * dy);
    }
  return 0.5 * e;
}

typedef struct {
  const double *v;
  double *out;
} mass_ctx;

/* The columns of J = dc/dx at u for the k control points from first:
** J[3 i + a] for a = x, y (R_i e_a) and s (r_i = R_i (P_i - c)), as
** 2-vectors; c(u) into pt. */
static void jacobian(const lw_nurbs *c, size_t first, const double *R, double pt[2], double J[][2])
{
  size_t k = (size_t)c->order;
  pt[0] = pt[1] = 0.0;
  for (size_t i = 0; i < k; i++)
    for (int x = 0; x < 2; x++) pt[x] += R[i] * c->P[2 * (first + i) + x];
  for (size_t i = 0; i < k; i++) {
    J[3 * i][0] = R[i], J[3 * i][1] = 0.0;
    J[3 * i + 1][0] = 0.0, J[3 * i + 1][1] = R[i];
    for (int x = 0; x < 2; x++) J[3 * i + 2][x] = R[i] * (c->P[2 * (first + i) + x] - pt[x]);
  }
}

static void add_mass_s(void *ctx, lw_nurbs *c, double u, double wq, size_t first, const double *R)
{
  mass_ctx *m = ctx;
  size_t k3 = 3 * (size_t)c->order;
  double pt[2], J[3 * LW_NURBS_ORDER_MAX][2];
  jacobian(c, first, R, pt, J);
  for (size_t a = 0; a < k3; a++)
    for (size_t b = 0; b <= a; b++) m->out[(3 * first + b) * k3 + (a - b)] += wq * (J[a][0] * J[b][0] + J[a][1] * J[b][1]);
}

lw_status lw_dnurbs_mass_s(lw_nurbs *c, int gauss, double *M, lw_error *err)
{
  mass_ctx m = {NULL, M};
  memset(M, 0, 9 * c->n * (size_t)c->order * sizeof *M);
  return each_point(c, gauss, 0, c->n, add_mass_s, &m, err);
}

/* With cv = J v = c_t, S = sum R_i sdot_i, dR_i/ds_l = R_i (delta_il - R_l)
** and dc/dP_l = R_l, dc/ds_l = r_l (docs/NUMERICS.md "Free weights"):
**   d cv / dP_l = R_l (sdot_l - S),  d cv / ds_l = R_l (V_l - cv) + (sdot_l - S) r_l,
** and d/dx (1/2 |cv|^2) = cv . d cv / dx. */
static void add_mass_s_dx(void *ctx, lw_nurbs *c, double u, double wq, size_t first, const double *R)
{
  mass_ctx m = *(mass_ctx *)ctx;
  size_t k = (size_t)c->order;
  double pt[2], J[3 * LW_NURBS_ORDER_MAX][2], cv[2] = {0.0, 0.0}, S = 0.0;
  jacobian(c, first, R, pt, J);
  const double *v = m.v + 3 * first;
  for (size_t a = 0; a < 3 * k; a++) cv[0] += J[a][0] * v[a], cv[1] += J[a][1] * v[a];
  for (size_t i = 0; i < k; i++) S += R[i] * v[3 * i + 2];
  double *out = m.out + 3 * first;
  for (size_t i = 0; i < k; i++) {
    double ds = v[3 * i + 2] - S;
    out[3 * i] += wq * cv[0] * R[i] * ds;
    out[3 * i + 1] += wq * cv[1] * R[i] * ds;
    out[3 * i + 2] += wq * (R[i] * (cv[0] * (v[3 * i] - cv[0]) + cv[1] * (v[3 * i + 1] - cv[1])) +
                            ds * (cv[0] * J[3 * i + 2][0] + cv[1] * J[3 * i + 2][1]));
  }
}

lw_status lw_dnurbs_mass_s_dx(lw_nurbs *c, int gauss, const double *v, double *out, lw_error *err)
{
  mass_ctx m = {v, out};
  memset(out, 0, 3 * c->n * sizeof *out);
  return each_point(c, gauss, 0, c->n, add_mass_s_dx, &m, err);
}

void lw_band_apply_dim(const double *A, size_t n, int k, int dim, const double *x, double *y)
{
  size_t m = (size_t)dim;
  memset(y, 0, m * n * sizeof *y);
  for (size_t j = 0; j < n; j++) {
    const double *col = A + j * (size_t)k;
    for (size_t c = 0; c < m; c++) y[m * j + c] += col[0] * x[m * j + c];
    for (size_t d = 1; d < (size_t)k && j + d < n; d++) {
      size_t i = j + d; /* A(i, j) = A(j, i) */
      for (size_t c = 0; c < m; c++) {
        y[m * i + c] += col[d] * x[m * j + c];
        y[m * j + c] += col[d] * x[m * i + c];
      }
    }
  }
}

void lw_band_apply(const double *A, size_t n, int k, const double *x, double *y) { lw_band_apply_dim(A, n, k, 2, x, y); }

lw_status lw_band_factor(const double *A, const unsigned char *pin, size_t n, int k, double *L, lw_error *err)
{
  size_t kk = (size_t)k;
  memcpy(L, A, n * kk * sizeof *L);
  for (size_t j = 0; j < n; j++) {
    if (!pin || !pin[j]) continue;
    for (size_t d = 1; d < kk; d++) {
      if (j + d < n) L[j * kk + d] = 0.0;
      if (j >= d) L[(j - d) * kk + d] = 0.0;
    }
    L[j * kk] = 1.0;
  }
  gsl_matrix_view v = gsl_matrix_view_array(L, n, kk);
  lw_gsl_off();
  int bad = gsl_linalg_cholesky_band_decomp(&v.matrix);
  lw_gsl_on();
  if (bad)
    return lw_error_set(err, LW_EINPUT, "a D-NURBS matrix of order %zu (its free coordinates) is not positive definite",
                        n);
  return LW_OK;
}

void lw_band_solve_dim(const double *L, const unsigned char *pin, size_t n, int k, int dim, const double *r, double *x)
{
  gsl_matrix_const_view v = gsl_matrix_const_view_array(L, n, (size_t)k);
  size_t m = (size_t)dim;
  for (size_t c = 0; c < m; c++) {
    gsl_vector_const_view rv = gsl_vector_const_view_array_with_stride(r + c, m, n);
    gsl_vector_view xv = gsl_vector_view_array_with_stride(x + c, m, n);
    if (r != x) gsl_vector_memcpy(&xv.vector, &rv.vector);
    for (size_t i = 0; i < n; i++)
      if (pin && pin[i]) x[m * i + c] = 0.0;
    gsl_linalg_cholesky_band_svx(&v.matrix, &xv.vector);
  }
}

void lw_band_solve(const double *L, const unsigned char *pin, size_t n, int k, const double *r, double *x)
{
  lw_band_solve_dim(L, pin, n, k, 2, r, x);
}
