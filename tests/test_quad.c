/* test_quad.c -- Gauss-Legendre tables and the Bezier basis. */
#include <criterion/criterion.h>
#include <math.h>

#include "linewise/quad.h"
#include "linewise/spline.h"
#include "testutil.h"

Test(quad, weights_nodes_and_polynomial_exactness)
{
  for (int n = LW_QUAD_MIN; n <= LW_QUAD_MAX; n++) {
    lw_quad q;
    cr_assert_eq(lw_quad_init(&q, n, NULL), LW_OK);
    double sw = 0;
    for (int i = 0; i < n; i++) {
      sw += q.w[i];
      cr_assert(q.s[i] > 0 && q.s[i] < 1);
      if (i) cr_assert(q.s[i] > q.s[i - 1], "nodes increase");
      /* separation theorem: node inside its element */
      cr_assert(q.e[i] < q.s[i] && q.s[i] < q.e[i + 1], "n=%d node %d in its element", n, i);
    }
    cr_assert(fabs(sw - 1) < 1e-13, "n=%d weights sum %g", n, sw);
    /* exact for s^k, k <= 2n-1 (checked up to degree 20 to stay well conditioned) */
    int kmax = 2 * n - 1 < 20 ? 2 * n - 1 : 20;
    for (int k = 0; k <= kmax; k++) {
      double I = 0;
      for (int i = 0; i < n; i++) I += q.w[i] * pow(q.s[i], k);
      cr_assert(fabs(I - 1.0 / (k + 1)) < 1e-13, "n=%d k=%d", n, k);
    }
  }
}

Test(quad, rejects_bad_node_counts)
{
  lw_quad q;
  lw_error err;
  cr_assert_eq(lw_quad_init(&q, 1, &err), LW_EINPUT);
  cr_assert_eq(lw_quad_init(&q, 65, &err), LW_EINPUT);
}

Test(quad, bernstein_partition_and_derivatives_by_finite_differences)
{
  /* The seed's r'' has a sign slip in its second half; these coefficients
  ** must agree with central differences of r and r'. */
  const double h = 1e-5;
  for (double s = 0.05; s < 1; s += 0.1) {
    double p[4], d1[4], d2[4], pp[4], pm[4], t1[4], t2[4];
    lw_quad_basis(s, p, d1, d2);
    lw_quad_basis(s + h, pp, t1, t2);
    double d1p[4];
    for (int k = 0; k < 4; k++) d1p[k] = t1[k];
    lw_quad_basis(s - h, pm, t1, t2);
    for (int k = 0; k < 4; k++) {
      cr_assert(fabs((pp[k] - pm[k]) / (2 * h) - d1[k]) < 1e-8, "r' coefficient %d at %g", k, s);
      cr_assert(fabs((d1p[k] - t1[k]) / (2 * h) - d2[k]) < 1e-7, "r'' coefficient %d at %g", k, s);
    }
    /* points: p0 and p1 coefficients of r sum to 1 (affine invariance) */
    cr_assert(fabs(p[0] + p[2] - 1) < 1e-15);
  }
}

Test(quad, endpoint_tangents_are_three_v)
{
  lw_node a = {1, 2, 0.5, -0.25}, b = {4, 3, 0.1, 0.7};
  double r[2], d1[2];
  lw_segment_eval(&a, &b, 0.0, r, d1, NULL);
  cr_assert(fabs(r[0] - 1) < 1e-15 && fabs(r[1] - 2) < 1e-15);
  cr_assert(fabs(d1[0] - 1.5) < 1e-14 && fabs(d1[1] + 0.75) < 1e-14);
  lw_segment_eval(&a, &b, 1.0, r, d1, NULL);
  cr_assert(fabs(r[0] - 4) < 1e-15 && fabs(r[1] - 3) < 1e-15);
  cr_assert(fabs(d1[0] - 0.3) < 1e-14 && fabs(d1[1] - 2.1) < 1e-14);
}
