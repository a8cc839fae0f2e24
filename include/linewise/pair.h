/*
** pair.h -- the 1/r repulsion between quadrature samples of different splines.
**
**   E_pair = C * sum over pairs of segments of different splines of
**            double integral |r0'| |r1'| k(|r0 - r1|) ds1 ds0,
**   k(r) = (1/r - 1/rc)+ with a cutoff rc > 0, 1/r without (rc = 0).
**
** Far field: each sample pair (i, j) contributes dl_i dl_j k(r_ij), the Gauss
** product rule, with dl = w_q |r'_q|.  Over a pair of segments farther apart
** than a few node spacings it is spectrally accurate (without a cutoff; the
** kink of k at rc makes it converge algebraically where the cutoff cuts a
** segment).
**
** Near field (pairnear.h): a sample pair closer than the near radius
** rho = min(near dm, rc), dm = max(dl_i, dl_j), marks its two segments as a
** near pair, which takes a smooth blend of the product rule and the double
** integral over the exact curves instead.  The walk over the cell grid sums
** the far pairs and lists the near ones; the model adds the near pairs'
** corrections (model.c).  near = 0 turns the near field off (product rule
** everywhere; infinite where two samples coincide).
**
** The segment-segment integral lw_pair_segseg (straight segments, exact) is
** what the near field integrates its smallest pieces with.
*/
#ifndef LINEWISE_PAIR_H
#define LINEWISE_PAIR_H

#include <stdint.h>

#include <math.h>

#include "linewise/quad.h"

#ifdef __cplusplus
extern "C" {
#endif

/* One sample as the pair term sees it (the cell grid holds the same values
** in structure-of-arrays form, grid.h).  Positions stay double (a page of
** 1e6 mm must still resolve 1e-6 mm); the weight is float, relative 6e-8,
** far below the quadrature's own error.  The energy is defined by these
** stored values, so every sum (incremental or from scratch) sees the same
** rounding.  The near field takes the curves from their control points, so
** nothing else of a sample is kept. */
typedef struct {
  double x, y;         /* r at the node, mm */
  float dl;            /* w_q |r'_q|, mm */
} lw_pair_sample;

typedef struct {
  double cutoff;        /* rc, mm; 0 = none */
  double inv_cutoff;    /* 1/rc, or 0 */
  double cutoff2;       /* rc^2, or +inf without a cutoff */
  double near_scale;    /* near radius in length elements (pairnear.h); 0 = none */
} lw_pair_ctx;

/* Squared near radius of a sample pair, min(near_scale max(dl_a, dl_b), rc)^2:
** the walk and the near field decide with this one expression, so they agree
** to the last bit on which pairs are near. */
static inline double lw_pair_near_radius2(const lw_pair_ctx *ctx, float dla, float dlb)
{
  double r = ctx->near_scale * (double)(dla > dlb ? dla : dlb);
  if (r > ctx->cutoff && ctx->cutoff > 0.0) r = ctx->cutoff;
  return r * r;
}

void lw_pair_ctx_init(lw_pair_ctx *ctx, double cutoff, double near);

/* Exact double integral of 1/|x - y| over x on segment [a0, a1] and y on
** [b0, b1] (arc length measure, mm).  Finite for crossing or touching
** segments; +infinity only where they overlap collinearly over a positive
** length; 0 if either has zero length. */
double lw_pair_segseg(const double a0[2], const double a1[2],
                      const double b0[2], const double b1[2]);

/* The potential of the segment (0,0)-(L,0) at (x, y): the integral of
** 1/|p - q| over it, log((r0 + r1 + L) / (r0 + r1 - L)), written without
** cancellation; +inf on the segment.  What lw_pair_segseg integrates far
** segments with, and its derivative's tangential part (pairgrad.c). */
double lw_pair_seg_potential(double L, double x, double y);

#ifdef __cplusplus
}
#endif

#endif
