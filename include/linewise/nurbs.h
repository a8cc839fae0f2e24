/*
** nurbs.h -- NURBS curves in the plane: order k, an open knot vector,
** control points and positive weights (docs/NURBS.md).
**
**     c(u) = sum_i N_i,k(u) w_i P_i / sum_i N_i,k(u) w_i = sum_i R_i(u) P_i
**
** The B-spline basis N_i,k and its derivatives come from GSL (gsl_bspline);
** the rational part R_i is ours.  A curve owns a GSL workspace (scratch), so
** a curve belongs to one thread; lw_nurbs_copy gives another thread its own.
*/
#ifndef LINEWISE_NURBS_H
#define LINEWISE_NURBS_H

#include <gsl/gsl_bspline.h>
#include <stddef.h>

#include "linewise/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* orders 2 (polyline) to this */
#define LW_NURBS_ORDER_MAX 8
/* The largest weight at most this many times the smallest: past it the
** matrices and final.svg's fit lose their digits (1e8 drew 0.29 from a
** curve of size 1, 1e6 at an end 1.15e-4 against svg_tolerance's 1e-4; 1e5
** keeps 1e-4 on the wire, 1e4 leaves room). */
#define LW_NURBS_WEIGHT_SPREAD 1e4
/* A scene's knots lie in [-LW_NURBS_KNOT_MAX, LW_NURBS_KNOT_MAX] (as the
** control points do), and a span of them that is not empty takes at least
** LW_NURBS_SPAN_MIN of the parameter range: the basis divides by the spans,
** and its derivatives by their powers (refinement cuts them up to 1000
** times more, far above where that overflows). */
#define LW_NURBS_KNOT_MAX 1e9
#define LW_NURBS_SPAN_MIN 1e-9
/* control points a refinement may make (a step of the wire costs 0.25 us
** a point, its matrices 200 bytes a point) */
#define LW_NURBS_REFINED_MAX 1000000

typedef struct {
  int order;      /* k: degree k - 1 */
  size_t n;       /* control points */
  double *knot;   /* n + k, open: k equal values at either end */
  double *P;      /* 2 n: x y of each control point */
  double *w;      /* n weights, > 0 */
  int pieces;     /* how a span of weights apart is cut (dnurbs.c): 2, by its knots; 1, as before 2026-12-07 */
  gsl_bspline_workspace *ws; /* the basis (scratch) */
  gsl_matrix *dB; /* k x 3 scratch: N, N', N'' of the nonzero functions */
} lw_nurbs;

/* Checks a knot vector for n control points of order k: n + k knots,
** nondecreasing, k equal values at either end and none inside repeated more
** than k - 1 times (the curve stays continuous).  LW_EINPUT with a message
** saying what is wrong (the caller names the file, line and key). */
lw_status lw_nurbs_check_knots(int order, size_t n, const double *knot, size_t n_knots, lw_error *err);

/* The same for a scene's knots (a checked vector of n + k), before any
** refinement: within LW_NURBS_KNOT_MAX, no span under LW_NURBS_SPAN_MIN. */
lw_status lw_nurbs_check_knot_scale(int order, size_t n, const double *knot, lw_error *err);

/* A curve of n control points (copied; weights NULL = all 1), checked as
** above and for weights > 0. */
lw_nurbs *lw_nurbs_new(int order, size_t n, const double *knot, const double *P, const double *w, lw_error *err);
lw_nurbs *lw_nurbs_copy(const lw_nurbs *c, lw_error *err);
void lw_nurbs_free(lw_nurbs *c);

/* The parameter range [knot[k-1], knot[n]]. */
double lw_nurbs_u0(const lw_nurbs *c);
double lw_nurbs_u1(const lw_nurbs *c);

/* The k rational basis functions that can be nonzero at u, and their first
** and second derivatives in u: R[d * k + j] is d^d R_{first+j} / du^d.
** Returns first. */
size_t lw_nurbs_rational(const lw_nurbs *c, double u, double *R);

/* The point and derivatives c(u), c'(u), c''(u) (any of them NULL). */
void lw_nurbs_eval(const lw_nurbs *c, double u, double pt[2], double d1[2], double d2[2]);

/* 1 when every weight is equal: the curve is then a polynomial spline. */
int lw_nurbs_polynomial(const lw_nurbs *c);

/* Boehm's knot insertion of u (in the parameter range, any multiplicity up
** to k - 1 after insertion), in homogeneous coordinates so that the curve
** is unchanged for rational curves too: one control point more. */
lw_status lw_nurbs_insert_knot(lw_nurbs *c, double u, lw_error *err);

/* The same curve in a richer space (h- and p-refinement): the degree
** raised by elevate, each inner knot's multiplicity with it (so the
** continuity at every knot is kept), then every knot span cut into split
** equal spans by simple knots (the curve's smoothest there).  The control
** points and weights are interpolated at the new Greville abscissae, so the
** curve is unchanged to rounding; the end points are kept to the bit and a
** polynomial curve stays one.  elevate = 0, split = 1 changes nothing;
** LW_EINPUT when the order would pass LW_NURBS_ORDER_MAX or the points
** LW_NURBS_REFINED_MAX. */
lw_status lw_nurbs_refine(lw_nurbs *c, int elevate, int split, lw_error *err);

/* The curve as cubic Beziers for SVG: each knot span by the cubic Hermite
** interpolant of its end points and end derivatives, bisected while it is
** farther than tol from the curve at 32 parameter samples (a parametric
** distance, which bounds the geometric one).  A polynomial span of degree
** <= 3 is its own Hermite cubic, so those come out exact (one Bezier a
** span, degree elevation included); rational and higher-degree spans are
** approximated.  Calls emit(B, ctx) with 4 points (8 numbers) per Bezier
** in curve order; returns the largest distance found (NaN: out of
** memory). */
double lw_nurbs_beziers(const lw_nurbs *c, double tol, void (*emit)(const double B[8], void *ctx), void *ctx);

#ifdef __cplusplus
}
#endif

#endif
