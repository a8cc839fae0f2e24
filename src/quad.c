/*
** quad.c -- Gauss-Legendre tables and the cubic Bezier basis at the nodes.
**
** Derivation of the derivative coefficients (the seed's r'' carries a sign slip
** in its second half; this is the checked form, see tests/test_quad.c):
**   r'  = 3 [ b2_0 (b1-b0) + b2_1 (b2-b1) + b2_2 (b3-b2) ]
**       = 3 [ b2_0 v0 + b2_1 (p1 - p0 - v0 - v1) + b2_2 v1 ]
**   r'' = 6 [ b1_0 (b2 - 2 b1 + b0) + b1_1 (b3 - 2 b2 + b1) ]
**       = 6 [ b1_0 (p1 - p0 - 2 v0 - v1) + b1_1 (p0 - p1 + v0 + 2 v1) ]
*/
#include "linewise/quad.h"

#include <gsl/gsl_integration.h>

static void bernstein(double s, double b3[4], double b2[3], double b1[2])
{
  double t = 1.0 - s;
  b3[0] = t * t * t;
  b3[1] = 3.0 * t * t * s;
  b3[2] = 3.0 * t * s * s;
  b3[3] = s * s * s;
  b2[0] = t * t;
  b2[1] = 2.0 * t * s;
  b2[2] = s * s;
  b1[0] = t;
  b1[1] = s;
}

static void coefficients(const double b3[4], const double b2[3], const double b1[2],
                         double pos[4], double d1[4], double d2[4])
{
  pos[0] = b3[0] + b3[1];
  pos[1] = b3[1];
  pos[2] = b3[2] + b3[3];
  pos[3] = -b3[2];
  d1[0] = -3.0 * b2[1];
  d1[1] = 3.0 * (b2[0] - b2[1]);
  d1[2] = 3.0 * b2[1];
  d1[3] = 3.0 * (b2[2] - b2[1]);
  d2[0] = 6.0 * (b1[1] - b1[0]);
  d2[1] = 6.0 * (b1[1] - 2.0 * b1[0]);
  d2[2] = 6.0 * (b1[0] - b1[1]);
  d2[3] = 6.0 * (2.0 * b1[1] - b1[0]);
}

void lw_quad_basis(double s, double pos[4], double d1[4], double d2[4])
{
  double b3[4], b2[3], b1[2];
  bernstein(s, b3, b2, b1);
  coefficients(b3, b2, b1, pos, d1, d2);
}

/*
** GSL tabulates some orders exactly and computes the others by an iteration
** that leaves errors near 1e-11 in nodes and weights (n = 38, 61, ...).  Two
** Newton steps on the Legendre polynomial in long double bring every order to
** rounding level, so tables of all orders are equally trustworthy.
*/
static void polish(lw_quad *q)
{
  const int n = q->n;
  for (int i = 0; i < n; i++) {
    long double x = 2.0L * q->s[i] - 1.0L, dp = 1.0L;
    for (int it = 0; it < 2; it++) {
      long double p0 = 1.0L, p1 = x;
      for (int k = 2; k <= n; k++) {
        long double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1.0L);
      x -= p1 / dp;
    }
    q->s[i] = (double)(0.5L * (x + 1.0L));
    q->w[i] = (double)(1.0L / ((1.0L - x * x) * dp * dp)); /* half of 2/((1-x^2)P'^2) */
  }
}

lw_status lw_quad_init(lw_quad *q, int n, lw_error *err)
{
  if (n < LW_QUAD_MIN || n > LW_QUAD_MAX)
    return lw_error_set(err, LW_EINPUT, "quadrature: %d nodes requested, expected %d to %d",
                        n, LW_QUAD_MIN, LW_QUAD_MAX);
  gsl_integration_glfixed_table *t = gsl_integration_glfixed_table_alloc((size_t)n);
  if (!t)
    return lw_error_set(err, LW_ENOMEM, "quadrature: cannot build the %d-node table", n);
  q->n = n;
  for (int i = 0; i < n; i++) {
    double xi, wi;
    if (gsl_integration_glfixed_point(0.0, 1.0, (size_t)i, &xi, &wi, t) != 0) {
      gsl_integration_glfixed_table_free(t);
      return lw_error_set(err, LW_ERUN, "quadrature: GSL node %d of %d failed", i, n);
    }
    q->s[i] = xi;
    q->w[i] = wi;
  }
  gsl_integration_glfixed_table_free(t);
  polish(q);
  /* GSL's order of nodes is not documented as increasing; sort so samples run
  ** along the segment (the near field and the element bounds rely on it). */
  for (int i = 1; i < n; i++)
    for (int j = i; j > 0 && q->s[j - 1] > q->s[j]; j--) {
      double ts = q->s[j], tw = q->w[j];
      q->s[j] = q->s[j - 1]; q->w[j] = q->w[j - 1];
      q->s[j - 1] = ts; q->w[j - 1] = tw;
    }
  q->e[0] = 0.0;
  for (int i = 0; i < n; i++) q->e[i + 1] = q->e[i] + q->w[i];
  q->e[n] = 1.0;
  q->spacing = 0.0;
  for (int i = 1; i < n; i++) q->spacing = fmax(q->spacing, q->s[i] - q->s[i - 1]);
  for (int i = 0; i < n; i++) {
    bernstein(q->s[i], q->bern3[i], q->bern2[i], q->bern1[i]);
    coefficients(q->bern3[i], q->bern2[i], q->bern1[i], q->pos[i], q->d1[i], q->d2[i]);
  }
  return LW_OK;
}
