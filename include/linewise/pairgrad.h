/*
** pairgrad.h -- the pieces of the pair term's gradient (pairgrad.c) that
** stand on their own: the derivative of the exact segment-segment integral
** and of the near field's double integral of two cubic segments.
** lw_pair_gradient (gradient.h) puts them together with the far field.
**
** Each is the derivative of the function as linewise computes it
** (docs/NUMERICS.md, "Gradient of the pair term"), analytic, so a
** minimiser or an integrator sees the same function the chain sees.
** Where the energy's slope is infinite -- an end point of a near field
** leaf's chord exactly on the other chord, as where two splines pass
** through one node position -- the gradient is not finite (NaN).
*/
#ifndef LINEWISE_PAIRGRAD_H
#define LINEWISE_PAIRGRAD_H

#ifdef __cplusplus
extern "C" {
#endif

/* lw_pair_segseg(a0, a1, b0, b1), and in g its derivatives with respect to
** a0x a0y a1x a1y b0x b0y b1x b1y.  The integral is not differentiable where
** an end point lies on the other segment (the derivative grows like log of
** the distance there) nor where the segments overlap (+inf); g is then not
** finite.  g is 0 where a segment has no length. */
double lw_pair_segseg_grad(const double a0[2], const double a1[2], const double b0[2], const double b1[2],
                           double g[8]);

/* lw_pair_segments_exact(a, b, cutoff), and in ga, gb its derivatives with
** respect to the control points of a and b (x0 y0 ... x3 y3).  NaN (ga, gb
** undefined) if its workspace cannot be allocated. */
double lw_pair_segments_exact_grad(const double a[8], const double b[8], double cutoff, double ga[8],
                                   double gb[8]);

#ifdef __cplusplus
}
#endif

#endif
