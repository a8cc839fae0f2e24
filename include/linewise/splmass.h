/*
** splmass.h -- the mass matrix of Bezier splines: the kinetic energy of the
** linewise model, section III of the seed,
**
**     T = (rho/2) sum over segments of int_0^1 |dr/dt|^2 |r'| ds,
**
** taken with the scene's Gauss rule, as every energy is.  r is linear in the
** coordinates (r = sum_k pos[q][k] X_k over the segment's X = p0 v0 p1 v1,
** quad.h), so T = 1/2 xdot' M(x) xdot with
**
**     M = rho sum_seg sum_q w_q |r'_q| phi_q phi_q'  (x) I_2,   phi_q = pos[q][.],
**
** the same scalar matrix for the x and the y components.  It couples a node
** only with its neighbours: per spline a symmetric band matrix of bandwidth 3
** over the scalar coordinates p_0 v_0 p_1 v_1 ...  It is positive definite
** when every segment has at least 4 quadrature nodes and |r'| > 0 at them
** (the cubic's four Bernstein polynomials are independent at 4 points); it
** depends on the positions through |r'|, which is where the seed's
** "Term 2" and "Term 3" come from (docs/NUMERICS.md, "Dynamics").
**
** Pinned coordinates (a pinned point holds both components of p; a pinned
** vector both of v) are held: their rows and columns are replaced by the
** identity, and a solve returns 0 there.
**
** Coordinates are the state vector of the splines row: 4 per node, px py
** vx vy, in node order.
*/
#ifndef LINEWISE_SPLMASS_H
#define LINEWISE_SPLMASS_H

#include "linewise/error.h"
#include "linewise/quad.h"
#include "linewise/spline.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lw_spline_mass lw_spline_mass;

/* The mass matrix of the splines of sp (their layout only; it must outlive
** the matrix) with density rho > 0 on the rule q (>= 4 nodes, else
** LW_EINPUT).  pinned: 1 byte per coordinate (4 per node), or NULL; a node's
** two components must agree. */
lw_spline_mass *lw_spline_mass_new(const lw_splines *sp, const lw_quad *q, double rho, const unsigned char *pinned,
                                   lw_error *err);
void lw_spline_mass_free(lw_spline_mass *m);

/* Assembles and factors M(x) (GSL's banded Cholesky).  LW_EINPUT if it is not
** positive definite (a segment whose speed vanishes at a node). */
lw_status lw_spline_mass_at(lw_spline_mass *m, const double *x, lw_error *err);

/* v = M^-1 b at the last x given to lw_spline_mass_at; 0 at pinned coordinates
** (b there is ignored).  v and b may not overlap. */
void lw_spline_mass_solve(const lw_spline_mass *m, const double *b, double *v);

/* b = M v at the last x given to lw_spline_mass_at (pinned rows: v there). */
void lw_spline_mass_apply(const lw_spline_mass *m, const double *v, double *b);

/* out = d/dx (1/2 v' M(x) v) at fixed v: the kinetic energy's dependence on
** the positions through |r'|; 0 at pinned coordinates. */
void lw_spline_mass_dx(const lw_spline_mass *m, const double *x, const double *v, double *out);

/* 1 where coordinate i is held. */
int lw_spline_mass_pinned(const lw_spline_mass *m, size_t i);

#ifdef __cplusplus
}
#endif

#endif
