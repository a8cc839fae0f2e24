/* dnurbs.c -- the D-NURBS matrices, banded (dnurbs.h). */
#include "linewise/dnurbs.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_linalg.h>
#include <stdlib.h>
#include <string.h>

void lw_dnurbs_free(lw_dnurbs *d)
{
  if (!d) return;
  free(d->K);
  free(d->M1);
  free(d->b);
  free(d);
}

lw_dnurbs *lw_dnurbs_new(lw_nurbs *c, double alpha, double beta, int gauss, lw_error *err)
{
  const size_t n = c->n, k = (size_t)c->order;
  lw_dnurbs *d = calloc(1, sizeof *d);
  gsl_integration_glfixed_table *gl = gsl_integration_glfixed_table_alloc((size_t)gauss);
  if (d) {
    d->n = n;
    d->k = c->order;
    d->K = calloc(n * k, sizeof *d->K);
    d->M1 = calloc(n * k, sizeof *d->M1);
    d->b = calloc(n, sizeof *d->b);
  }
  if (!d || !gl || !d->K || !d->M1 || !d->b) {
    lw_dnurbs_free(d);
    if (gl) gsl_integration_glfixed_table_free(gl);
    lw_error_set(err, LW_ENOMEM, "out of memory for the D-NURBS matrices of %zu control points", n);
    return NULL;
  }
  double R[3 * LW_NURBS_ORDER_MAX];
  for (size_t s = k - 1; s < n; s++) {
    double a = c->knot[s], bb = c->knot[s + 1];
    if (!(bb > a)) continue; /* a repeated knot: no span */
    for (size_t q = 0; q < (size_t)gauss; q++) {
      double u, wq;
      gsl_integration_glfixed_point(a, bb, q, &u, &wq, gl);
      size_t first = lw_nurbs_rational(c, u, R);
      for (size_t i = 0; i < k; i++) {
        d->b[first + i] += wq * R[i];
        for (size_t j = 0; j <= i; j++) {
          double *Kb = d->K + (first + j) * k + (i - j), *Mb = d->M1 + (first + j) * k + (i - j);
          *Kb += wq * (alpha * R[k + i] * R[k + j] + beta * R[2 * k + i] * R[2 * k + j]);
          *Mb += wq * R[i] * R[j];
        }
      }
    }
  }
  gsl_integration_glfixed_table_free(gl);
  return d;
}

lw_status lw_dnurbs_grad_w(lw_nurbs *c, double alpha, double beta, const double mug[2], int gauss, double *gw, lw_error *err)
{
  const size_t n = c->n, k = (size_t)c->order;
  gsl_integration_glfixed_table *gl = gsl_integration_glfixed_table_alloc((size_t)gauss);
  if (!gl) return lw_error_set(err, LW_ENOMEM, "out of memory for a Gauss table of %d points", gauss);
  memset(gw, 0, n * sizeof *gw);
  double R[3 * LW_NURBS_ORDER_MAX];
  for (size_t s = k - 1; s < n; s++) {
    double a = c->knot[s], bb = c->knot[s + 1];
    if (!(bb > a)) continue;
    for (size_t q = 0; q < (size_t)gauss; q++) {
      double u, wq, pt[2], d1[2], d2[2];
      gsl_integration_glfixed_point(a, bb, q, &u, &wq, gl);
      size_t first = lw_nurbs_rational(c, u, R);
      lw_nurbs_eval(c, u, pt, d1, d2);
      for (size_t i = 0; i < k; i++) {
        size_t j = first + i;
        double r0 = R[i], r1 = R[k + i], r2 = R[2 * k + i], acc = 0.0;
        for (int x = 0; x < 2; x++) {
          double dp = c->P[2 * j + x] - pt[x];
          /* q_j and its u-derivatives, times w_j (product rule on R_j (P_j - c)) */
          double q0 = r0 * dp, q1 = r1 * dp - r0 * d1[x], q2 = r2 * dp - 2.0 * r1 * d1[x] - r0 * d2[x];
          acc += alpha * d1[x] * q1 + beta * d2[x] * q2 - mug[x] * q0;
        }
        gw[j] += wq * acc / c->w[j];
      }
    }
  }
  gsl_integration_glfixed_table_free(gl);
  return LW_OK;
}

void lw_band_apply(const double *A, size_t n, int k, const double *x, double *y)
{
  memset(y, 0, 2 * n * sizeof *y);
  for (size_t j = 0; j < n; j++) {
    const double *col = A + j * (size_t)k;
    y[2 * j] += col[0] * x[2 * j];
    y[2 * j + 1] += col[0] * x[2 * j + 1];
    for (size_t d = 1; d < (size_t)k && j + d < n; d++) {
      size_t i = j + d; /* A(i, j) = A(j, i) */
      y[2 * i] += col[d] * x[2 * j];
      y[2 * i + 1] += col[d] * x[2 * j + 1];
      y[2 * j] += col[d] * x[2 * i];
      y[2 * j + 1] += col[d] * x[2 * i + 1];
    }
  }
}

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
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  int bad = gsl_linalg_cholesky_band_decomp(&v.matrix);
  gsl_set_error_handler(old);
  if (bad) return lw_error_set(err, LW_EINPUT, "a D-NURBS matrix of %zu control points is not positive definite", n);
  return LW_OK;
}

void lw_band_solve(const double *L, const unsigned char *pin, size_t n, int k, const double *r, double *x)
{
  gsl_matrix_const_view v = gsl_matrix_const_view_array(L, n, (size_t)k);
  for (size_t c = 0; c < 2; c++) {
    gsl_vector_const_view rv = gsl_vector_const_view_array_with_stride(r + c, 2, n);
    gsl_vector_view xv = gsl_vector_view_array_with_stride(x + c, 2, n);
    if (r != x) gsl_vector_memcpy(&xv.vector, &rv.vector);
    for (size_t i = 0; i < n; i++)
      if (pin && pin[i]) x[2 * i + c] = 0.0;
    gsl_linalg_cholesky_band_svx(&v.matrix, &xv.vector);
  }
}
