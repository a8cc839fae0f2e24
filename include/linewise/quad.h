/*
** quad.h -- Gauss-Legendre quadrature on [0,1] with the cubic Bezier basis
** tabulated at the nodes.
**
** A segment m of a spline has Bezier control points
**     b0 = p_m, b1 = p_m + v_m, b2 = p_{m+1} - v_{m+1}, b3 = p_{m+1}
** so position and derivatives are linear in (p0, v0, p1, v1) := (p_m, v_m,
** p_{m+1}, v_{m+1}):
**     r   (s) = pos[q][0] p0 + pos[q][1] v0 + pos[q][2] p1 + pos[q][3] v1
**     r'  (s) = d1 [q][0] p0 + ...                       (d/ds, one unit per segment)
**     r'' (s) = d2 [q][0] p0 + ...
** with, in terms of the Bernstein polynomials b^3_k, b^2_k, b^1_k,
**     r   = (b3_0 + b3_1) p0 + b3_1 v0 + (b3_2 + b3_3) p1 - b3_2 v1
**     r'  = 3 [ (b2_0 - b2_1 ... ) ]  (see quad.c for the derivation)
** The nodes and weights come from GSL (gsl_integration_glfixed), for any node
** count from LW_QUAD_MIN to LW_QUAD_MAX; weights sum to 1.
**
** The element bounds e[0..n] are the partial sums of the weights.  By the
** Chebyshev-Markov-Stieltjes separation theorem node q lies in [e[q], e[q+1]],
** so each sample owns a piece of its segment; the pair term's near field uses
** these pieces (pair.h).
*/
#ifndef LINEWISE_QUAD_H
#define LINEWISE_QUAD_H

#include "linewise/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_QUAD_MIN 2
#define LW_QUAD_MAX 64

typedef struct {
  int n;                      /* number of nodes */
  double s[LW_QUAD_MAX];      /* nodes on [0,1], increasing */
  double w[LW_QUAD_MAX];      /* weights on [0,1], sum 1 */
  double e[LW_QUAD_MAX + 1];  /* element bounds: e[0]=0, e[q+1]=e[q]+w[q] */
  double spacing;             /* the widest s[q+1] - s[q] */
  double bern3[LW_QUAD_MAX][4]; /* b^3_k(s_q) = C(3,k) (1-s)^(3-k) s^k */
  double bern2[LW_QUAD_MAX][3]; /* b^2_k(s_q) */
  double bern1[LW_QUAD_MAX][2]; /* b^1_k(s_q) */
  double pos[LW_QUAD_MAX][4];   /* r   coefficients of (p0, v0, p1, v1) */
  double d1[LW_QUAD_MAX][4];    /* r'  coefficients */
  double d2[LW_QUAD_MAX][4];    /* r'' coefficients */
} lw_quad;

/* Fills q for n nodes; LW_EINPUT if n is outside [LW_QUAD_MIN, LW_QUAD_MAX]. */
lw_status lw_quad_init(lw_quad *q, int n, lw_error *err);

/* Basis coefficients of r, r', r'' at any parameter s (not only nodes). */
void lw_quad_basis(double s, double pos[4], double d1[4], double d2[4]);

#ifdef __cplusplus
}
#endif

#endif
