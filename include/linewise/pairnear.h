/*
** pairnear.h -- the pair term's near field: the double integral of two
** cubic segments that come close, and the correction that puts it in place
** of the product rule.
**
** The product rule (pair.h) is spectrally accurate for two segments that
** are farther apart than a few node spacings, and wrong where they come
** closer (infinite where two samples coincide).  A pair of samples closer
** than the near radius rho = min(near dm, rc) (dm: the larger of their two
** length elements) marks their two segments A and B as a near pair.  For a
** near pair the model uses
**
**     E_AB = (1 - W) P_AB + W X_AB
**
** P_AB: the product rule over all sample pairs of A x B; X_AB: the double
** integral over the exact curves (lw_pair_segments_exact); W: the largest
** of phi(r_ij / rho_ij) over the sample pairs, phi = 1 below half the near
** radius, 0 from the radius on, C2 in between.  W is a continuous function
** of the samples and vanishes exactly when no pair is near, so the energy is
** continuous however curves approach, cross or part; and where W < 1 every
** sample pair is at least rho / 2 apart, so P_AB is finite.
**
** Because the near pair is decided from whole segments, the product rule
** keeps its global (spectral) accuracy wherever it is used: nothing mixes
** element-local integrals into a Gauss sum, which is what left the previous
** scheme with an error floor.
*/
#ifndef LINEWISE_PAIRNEAR_H
#define LINEWISE_PAIRNEAR_H

#include "linewise/pair.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The double integral of |a'| |b'| (1/r - 1/rc)+ over two cubic Bezier
** segments a and b (control points x0 y0 x1 y1 x2 y2 x3 y3, mm), or of
** |a'| |b'| / r without a cutoff (cutoff <= 0).  Finite where the segments
** cross or touch, and never negative.  A continuous function of the control
** points; relative error 1e-5 or less for segments apart (without a
** cutoff; its kink adds up to ~1e-3), 1e-4 to 1e-3 where they cross or run
** alongside closely, up to 3e-3 where they touch tangentially at an end
** (pairnear.c, docs/NUMERICS.md, docs/ACCURACY.md). */
double lw_pair_segments_exact(const double a[8], const double b[8], double cutoff);

/* lw_pair_segments_exact is not symmetric: it splits A and B in turn, and
** X(a, b) and X(b, a) differ by its error (up to about 1e-3 of it where the
** curves cross or touch).  The near field takes a pair in one order
** (lw_pair_bezier_before), which flips where the first control points'
** x pass each other: a jump of that error (1e-4 of the energy in undamped
** dynamics).  So within a band of LW_PAIR_ORDER_BAND times the sum of the
** chords' L1 lengths of that crossing, both orders are taken, blended by a
** C2 weight in the gap that is 1/2 where they meet (both orders give the
** same bits there) and 1 at the band's edge. */
#define LW_PAIR_ORDER_BAND 0.02

/* The C2 ramp of every blend of the near field: t^3 (10 + t (6 t - 15)), 0
** at t = 0 and 1 at t = 1 with its first and second derivatives 0 at both,
** for t in [0, 1]; its derivative 30 t^2 (1 - t)^2 into *dt (NULL: not
** wanted).  One copy, so that the energy (pairnear.c) and its gradient
** (pairgrad.c) blend alike; pairnear.c's four-lane walk writes the same
** operations in vector form. */
static inline double lw_pair_ramp(double t, double *dt)
{
  if (dt) *dt = 30.0 * t * t * (1.0 - t) * (1.0 - t);
  return t * t * t * (10.0 + t * (6.0 * t - 15.0));
}

/* The weight of X(a, b) against X(b, a) for a pair in lw_pair_bezier_before's
** order, and its derivatives by a's and b's control points (NULL: not
** wanted); 1 outside the band. */
double lw_pair_order_weight(const double a[8], const double b[8], double dwa[8], double dwb[8]);

/* E_AB minus the product-rule terms of the sample pairs of A x B that are
** not near (those the neighbour walk adds): what the model adds for a near
** pair.  sa and sb: the n pair samples of each segment, as stored. */
double lw_pair_near_correction(const double a[8], const lw_pair_sample *sa, const double b[8],
                               const lw_pair_sample *sb, int n, const lw_pair_ctx *ctx);

/* ---- for the gradient (pairgrad.c) ----------------------------------------
** The derivative of lw_pair_segments_exact follows its computation step by
** step, so it sees the same thresholds and rules. */
typedef struct {
  double sep_lo, sep_hi;       /* pieces apart: 6 x 6 rule from sep_hi larger radii on */
  double leaf_ratio, flat_ratio;
  double leaf_band, flat_band; /* a leaf blends out up to these times its size and flatness limits */
  int stack_max;
  int cp_grid;                 /* closest points: the best of (cp_grid + 1)^2 points, then Newton */
  const double *g6_s, *g6_w;   /* Gauss-Legendre on [0, 1] */
  int g6_n;
  /* segments apart: the whole-square rules of whole_m[r] nodes, from
  ** distance / half size whole_lo[r] (blended in up to whole_hi[r]) */
  int n_whole;
  const int *whole_m;
  const double *const *whole_s, *const *whole_w;
  const double *whole_lo, *whole_hi;
} lw_pairnear_consts;

extern const lw_pairnear_consts lw_pairnear_k;

/* 1 if a comes before b in the lexicographic order of the control points:
** the order lw_pair_near_correction takes a pair in, so that its value is
** bitwise symmetric. */
int lw_pair_bezier_before(const double a[8], const double b[8]);

#ifdef __cplusplus
}
#endif

#endif
