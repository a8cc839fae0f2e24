/* splmass.c -- the mass matrix of Bezier splines (splmass.h). */
#include "linewise/splmass.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Scalar coordinates of a spline: p_k is 2k, v_k is 2k + 1 (the matrix is
** the same for x and y).  Band storage as GSL's banded Cholesky reads it:
** row i holds the lower triangle's column i, band[i][d] = A(i + d, i). */
#define BAND 4

struct lw_spline_mass {
  const lw_splines *sp;
  const lw_quad *q;
  double rho;
  unsigned char *pinned; /* 4 per node */
  double *band;          /* 2 n_nodes rows of BAND: M, spline after spline */
  double *chol;          /* its factor */
  double *rhs;           /* 2 (largest spline's nodes) x 2 */
};

lw_spline_mass *lw_spline_mass_new(const lw_splines *sp, const lw_quad *q, double rho, const unsigned char *pinned,
                                   lw_error *err)
{
  if (q->n < 4) {
    lw_error_set(err, LW_EINPUT, "expected at least 4 nodes a segment under the dynamics, got %d: with fewer the "
                 "mass matrix (and the massless flow's damping matrix, its multiple) is singular", q->n);
    return NULL;
  }
  lw_spline_mass *m = calloc(1, sizeof *m);
  size_t most = 0;
  for (size_t i = 0; i < sp->n_splines; i++) {
    size_t n = sp->first[i + 1] - sp->first[i];
    if (n > most) most = n;
  }
  if (m) {
    m->sp = sp;
    m->q = q;
    m->rho = rho;
    m->pinned = calloc(4 * sp->n_nodes + 1, 1);
    m->band = calloc(2 * sp->n_nodes * BAND + 1, sizeof *m->band);
    m->chol = calloc(2 * sp->n_nodes * BAND + 1, sizeof *m->chol);
    m->rhs = calloc(4 * most + 1, sizeof *m->rhs);
  }
  if (!m || !m->pinned || !m->band || !m->chol || !m->rhs) {
    lw_spline_mass_free(m);
    lw_error_set(err, LW_ENOMEM, "out of memory for the mass matrix");
    return NULL;
  }
  if (pinned) memcpy(m->pinned, pinned, 4 * sp->n_nodes);
  return m;
}

void lw_spline_mass_free(lw_spline_mass *m)
{
  if (!m) return;
  free(m->pinned);
  free(m->band);
  free(m->chol);
  free(m->rhs);
  free(m);
}

int lw_spline_mass_pinned(const lw_spline_mass *m, size_t i) { return m->pinned[i]; }

/* Coordinate component c (0 x, 1 y) of scalar coordinate j of the spline
** whose first node is `first`. */
static size_t coord(size_t first, size_t j, int c) { return 4 * (first + j / 2) + 2 * (j % 2) + (size_t)c; }

/* r' at node q of the segment starting at node a (x as in splmass.h). */
static void speed_vector(const lw_quad *q, int k, const double *x, size_t a, double d[2])
{
  const double *X = x + 4 * a; /* p0 at X[0..1], v0 X[2..3], p1 X[4..5], v1 X[6..7] */
  for (int c = 0; c < 2; c++)
    d[c] = q->d1[k][0] * X[c] + q->d1[k][1] * X[2 + c] + q->d1[k][2] * X[4 + c] + q->d1[k][3] * X[6 + c];
}

lw_status lw_spline_mass_at(lw_spline_mass *m, const double *x, lw_error *err)
{
  const lw_splines *sp = m->sp;
  const lw_quad *q = m->q;
  memset(m->band, 0, 2 * sp->n_nodes * BAND * sizeof *m->band);
  for (size_t i = 0; i < sp->n_splines; i++) {
    size_t first = sp->first[i], nn = sp->first[i + 1] - first, dim = 2 * nn;
    double *B = m->band + 2 * first * BAND;
    for (size_t seg = 0; seg + 1 < nn; seg++) {
      for (int k = 0; k < q->n; k++) {
        double d[2];
        speed_vector(q, k, x, first + seg, d);
        double c = m->rho * q->w[k] * hypot(d[0], d[1]);
        for (int a = 0; a < 4; a++)
          for (int b = 0; b <= a; b++) B[(2 * seg + (size_t)b) * BAND + (size_t)(a - b)] += c * q->pos[k][a] * q->pos[k][b];
      }
    }
    /* a held coordinate: identity row and column */
    for (size_t j = 0; j < dim; j++) {
      if (!m->pinned[coord(first, j, 0)]) continue;
      for (size_t d = 1; d < BAND; d++) {
        if (j + d < dim) B[j * BAND + d] = 0.0;
        if (j >= d) B[(j - d) * BAND + d] = 0.0;
      }
      B[j * BAND] = 1.0;
    }
    double *L = m->chol + 2 * first * BAND;
    memcpy(L, B, dim * BAND * sizeof *L);
    gsl_matrix_view v = gsl_matrix_view_array(L, dim, BAND);
    lw_gsl_off();
    int bad = gsl_linalg_cholesky_band_decomp(&v.matrix);
    lw_gsl_on();
    if (bad)
      return lw_error_set(err, LW_EINPUT, "spline %zu: the mass matrix is not positive definite (a segment's speed "
                          "vanishes at a quadrature node)", i);
  }
  return LW_OK;
}

void lw_spline_mass_solve(const lw_spline_mass *m, const double *b, double *v)
{
  const lw_splines *sp = m->sp;
  for (size_t i = 0; i < sp->n_splines; i++) {
    size_t first = sp->first[i], dim = 2 * (sp->first[i + 1] - first);
    for (size_t j = 0; j < dim; j++)
      for (int c = 0; c < 2; c++) {
        size_t at = coord(first, j, c);
        m->rhs[2 * j + (size_t)c] = m->pinned[at] ? 0.0 : b[at];
      }
    gsl_matrix_const_view L = gsl_matrix_const_view_array(m->chol + 2 * first * BAND, dim, BAND);
    gsl_matrix_view X = gsl_matrix_view_array(m->rhs, dim, 2);
    gsl_linalg_cholesky_band_svxm(&L.matrix, &X.matrix);
    for (size_t j = 0; j < dim; j++)
      for (int c = 0; c < 2; c++) v[coord(first, j, c)] = m->rhs[2 * j + (size_t)c];
  }
}

void lw_spline_mass_apply(const lw_spline_mass *m, const double *v, double *b)
{
  const lw_splines *sp = m->sp;
  for (size_t i = 0; i < sp->n_splines; i++) {
    size_t first = sp->first[i], dim = 2 * (sp->first[i + 1] - first);
    const double *B = m->band + 2 * first * BAND;
    for (size_t j = 0; j < dim; j++)
      for (int c = 0; c < 2; c++) {
        double s = B[j * BAND] * v[coord(first, j, c)];
        for (size_t d = 1; d < BAND; d++) {
          if (j + d < dim) s += B[j * BAND + d] * v[coord(first, j + d, c)];
          if (j >= d) s += B[(j - d) * BAND + d] * v[coord(first, j - d, c)];
        }
        b[coord(first, j, c)] = s;
      }
  }
}

void lw_spline_mass_dx(const lw_spline_mass *m, const double *x, const double *v, double *out)
{
  const lw_splines *sp = m->sp;
  const lw_quad *q = m->q;
  memset(out, 0, 4 * sp->n_nodes * sizeof *out);
  for (size_t i = 0; i < sp->n_splines; i++) {
    size_t first = sp->first[i], nn = sp->first[i + 1] - first;
    for (size_t seg = 0; seg + 1 < nn; seg++) {
      size_t a = first + seg;
      const double *V = v + 4 * a;
      double *o = out + 4 * a;
      for (int k = 0; k < q->n; k++) {
        double d[2], rdot[2];
        speed_vector(q, k, x, a, d);
        for (int c = 0; c < 2; c++)
          rdot[c] = q->pos[k][0] * V[c] + q->pos[k][1] * V[2 + c] + q->pos[k][2] * V[4 + c] + q->pos[k][3] * V[6 + c];
        double speed = hypot(d[0], d[1]);
        if (!(speed > 0.0)) continue;
        /* d|r'|/dX_j = (r'/|r'|) d1[q][j] */
        double f = 0.5 * m->rho * q->w[k] * (rdot[0] * rdot[0] + rdot[1] * rdot[1]) / speed;
        for (int j = 0; j < 4; j++)
          for (int c = 0; c < 2; c++) o[2 * j + c] += f * d[c] * q->d1[k][j];
      }
    }
  }
  for (size_t i = 0; i < 4 * sp->n_nodes; i++)
    if (m->pinned[i]) out[i] = 0.0;
}
