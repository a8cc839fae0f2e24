/*
** boundary.h -- the frame the lines must stay inside, as a signed distance.
**
** lw_boundary_distance returns d(x, y): the Euclidean distance to the boundary
** curve, negative inside, positive outside, 0 on it (mm).  The boundary energy
** term integrates 1/d^2 inside and is +infinity where d >= 0.
**
** Kinds: rectangle [x0,x1] x [y0,y1]; circle (centre, radius); simple polygon
** (vertices in order, either orientation, closed implicitly; inside by the
** even-odd rule); mask: a signed distance grid read by bilinear interpolation
** (sdt.h builds it from a picture's mask; lookups beyond the grid read its
** outermost ring, which is outside).  LW_BOUNDARY_NONE means the term is
** off: distance -infinity.
*/
#ifndef LINEWISE_BOUNDARY_H
#define LINEWISE_BOUNDARY_H

#include <stddef.h>

#include "linewise/error.h"
#include "linewise/field.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
  LW_BOUNDARY_NONE,
  LW_BOUNDARY_RECT,
  LW_BOUNDARY_CIRCLE,
  LW_BOUNDARY_POLYGON,
  LW_BOUNDARY_MASK
} lw_boundary_kind;

typedef struct {
  lw_boundary_kind kind;
  double x0, y0, x1, y1;  /* rect, mm; x0 < x1, y0 < y1 */
  double cx, cy, radius;  /* circle, mm; radius > 0 */
  size_t n;               /* polygon: vertex count (>= 3) */
  double *vx, *vy;        /* polygon: vertices, owned */
  int convex;             /* polygon: convex (lw_boundary_curve_clear's fast test) */
  lw_grid2d *sdt;         /* mask: signed distances, mm, owned (ncomp 1) */
  double slope;           /* mask: the steepest the bilinear distance gets
                             (lw_boundary_mask_slope); the exact kinds' is 1 */
  double clearance;       /* the boundary term's: how far inside a curve must
                             stay, in its own length elements (lw_term_boundary) */
} lw_boundary;

/* Polygon from n >= 3 vertices (copied).  LW_EINPUT for fewer vertices,
** non-finite coordinates or zero area. */
/* Whether the closed polygon of n vertices crosses or touches itself: 1
** with the first pair of edges that meet, starting at vertices *a < *b
** (edges from a vertex to the next one that differs: a repeated vertex, or
** the first repeated last to close the path, is no edge); 0 where it is
** simple (or memory ran out). */
int lw_boundary_crossing(size_t n, const double *x, const double *y, size_t *a, size_t *b);

lw_status lw_boundary_polygon(lw_boundary *b, size_t n, const double *x, const double *y,
                              lw_error *err);
void lw_boundary_clear(lw_boundary *b);

double lw_boundary_distance(const lw_boundary *b, double x, double y);

/* d(x, y) as lw_boundary_distance gives it, and its gradient g (the
** boundary term's derivative, gradient.h): the unit vector away from the
** nearest boundary point (rect, circle, polygon), the bilinear gradient of
** the mask's grid; 0 where d has no gradient (the medial axis of a rect
** takes one side, a circle's centre gives 0) and for LW_BOUNDARY_NONE. */
double lw_boundary_distance_grad(const lw_boundary *b, double x, double y, double g[2]);

/* 1 if every point of the cubic Bezier curve with control points (x[k],
** y[k]) lies at least `clear` (>= 0, mm) inside: d <= -clear, and d < 0.
** Exact up to 1e-9 mm, whatever the sampling: a piece whose control points
** lie within a disc far enough inside (the distance changes by at most the
** slope times the disc's radius) is inside; otherwise it is split in two at
** its middle, whose point on the curve is tested, down to pieces of 1e-9
** mm; where the frame is convex (rect, circle, a convex polygon) a piece
** whose control points are all far enough inside is clear too (the
** distance is convex there), which decides a piece parallel to a side at
** once.  A curve needing more than 4096 pieces (one along the limit within
** a hair, in a frame that is not convex) is refused.  0 for non-finite
** input; 1 for LW_BOUNDARY_NONE. */
int lw_boundary_curve_clear(const lw_boundary *b, const double x[4], const double y[4], double clear);

/* The steepest slope of the mask's bilinear distance (>= 1 where its grid
** is a true distance): over each cell, the largest difference along x
** and along y over the spacing, combined.  What lw_boundary_curve_clear
** bounds a disc with. */
double lw_boundary_mask_slope(const lw_grid2d *sdt);

/* Is (x, y) strictly inside? (d < 0) */
int lw_boundary_inside(const lw_boundary *b, double x, double y);

#ifdef __cplusplus
}
#endif

#endif
