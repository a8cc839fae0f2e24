/*
** pairref.h -- the pair energy of two curves two ways, shared by
** tests/test_pair.c and the benchmark (tools/bench-accuracy.c):
** the samples the kernel sums over, and a brute-force reference.
**
** The reference is the double integral of |r0'| |r1'| / |r0 - r1| over splines 0 and 1 of sp,
** taken over the exact Bezier curves by nested adaptive Gauss-Kronrod (GSL
** qagp) in the splines' global parameters, split at every segment boundary
** (and the outer one at quarter segments), relative tolerance ~1e-11.  It
** shares nothing with the kernel it checks but lw_segment_eval.
*/
#ifndef LINEWISE_PAIRREF_H
#define LINEWISE_PAIRREF_H

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <math.h>

#include "linewise/pair.h"
#include "linewise/spline.h"

/* All samples of spline i as the pair term sees them; returns the count. */
static inline size_t lw_pairref_samples(const lw_splines *sp, const lw_quad *q, size_t i, lw_pair_sample *out)
{
  size_t n = 0;
  for (size_t m = 0; m < lw_splines_segments(sp, i); m++) {
    size_t g = lw_segment_index(sp, i, m), k = lw_segment_node(sp, g);
    lw_samples s;
    lw_segment_sample(q, &sp->node[k], &sp->node[k + 1], &s);
    for (int j = 0; j < s.n; j++)
      out[n++] = (lw_pair_sample){s.x[j], s.y[j], (float)s.dl[j]};
  }
  return n;
}

typedef struct {
  const lw_splines *sp;
  double x, y;
  double rc; /* cutoff, 0 = none */
  gsl_integration_workspace *wi;
} lw_pairref_ctx;

/* r and r' of spline i at global parameter u in [0, segments]. */
static inline void lw_pairref_eval(const lw_splines *sp, size_t i, double u, double r[2], double d[2])
{
  size_t m = lw_splines_segments(sp, i), g = (size_t)floor(u);
  if (g >= m) g = m - 1;
  const lw_node *a = &sp->node[sp->first[i] + g];
  lw_segment_eval(a, a + 1, u - (double)g, r, d, NULL);
}

static inline double lw_pairref_inner(double t, void *p)
{
  const lw_pairref_ctx *c = p;
  double r[2], d[2];
  lw_pairref_eval(c->sp, 1, t, r, d);
  double k = 1.0 / hypot(r[0] - c->x, r[1] - c->y);
  if (c->rc > 0.0) k = k > 1.0 / c->rc ? k - 1.0 / c->rc : 0.0;
  return hypot(d[0], d[1]) * k;
}

static inline double lw_pairref_outer(double s, void *p)
{
  lw_pairref_ctx *c = p;
  double r[2], d[2], pts[65];
  lw_pairref_eval(c->sp, 0, s, r, d);
  c->x = r[0];
  c->y = r[1];
  size_t mb = lw_splines_segments(c->sp, 1);
  for (size_t k = 0; k <= mb; k++) pts[k] = (double)k;
  gsl_function F = {lw_pairref_inner, c};
  double res, err;
  gsl_integration_qagp(&F, pts, mb + 1, 0.0, 1e-12, 1000, c->wi, &res, &err);
  return res * hypot(d[0], d[1]);
}

/* The reference (no coefficient) with the kernel (1/r - 1/rc)+, rc > 0, or
** 1/r (rc = 0); splines of up to 64 segments.  Adaptive bisection finds the
** kink at the cutoff. */
static inline double lw_pairref_energy_cut(const lw_splines *sp, double rc)
{
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  lw_pairref_ctx c = {sp, 0, 0, rc, gsl_integration_workspace_alloc(1000)};
  gsl_integration_workspace *wo = gsl_integration_workspace_alloc(1000);
  size_t ma = lw_splines_segments(sp, 0), n = 0;
  double pts[257];
  for (size_t k = 0; k <= 4 * ma; k++) pts[n++] = 0.25 * (double)k;
  gsl_function F = {lw_pairref_outer, &c};
  double res, err;
  gsl_integration_qagp(&F, pts, n, 0.0, 1e-11, 1000, wo, &res, &err);
  gsl_integration_workspace_free(wo);
  gsl_integration_workspace_free(c.wi);
  gsl_set_error_handler(old);
  return res;
}

/* The reference without a cutoff. */
static inline double lw_pairref_energy(const lw_splines *sp)
{
  return lw_pairref_energy_cut(sp, 0.0);
}

#endif
