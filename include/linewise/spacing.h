/*
** spacing.h -- how crowded a drawing is: the share of its line length that
** has a point of another stroke (spline) closer than a given distance,
** reported as summary.json's close_share with the pen width as distance;
** and how near two segments' curves come (lw_bezier_near2), for the
** spacing rule of the Monte Carlo moves (model.c).
**
** Each segment is cut into k = ceil(length / (d / 2)) pieces of equal
** parameter (at most LW_SPACING_POINTS_MAX), each piece stands for its
** midpoint with the length |r'(t)| / k, and the points are sorted into cells
** at least d wide (no more cells than points).  A point counts as close when a point of another
** spline lies within d of it.  Points are at most d / 2 apart along a
** line, so the nearest point of a line at true distance x < d is within
** sqrt(x^2 + d^2 / 16) of it: only lines between 0.968 d and d apart can be
** miscounted (as close).  The stroke's own points never count: a stroke
** that folds onto itself is not two strokes.
*/
#ifndef LINEWISE_SPACING_H
#define LINEWISE_SPACING_H

#include <stddef.h>

#include "linewise/error.h"
#include "linewise/spline.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_SPACING_POINTS_MAX 4096 /* points per segment */

/* The n cubic Bezier segments b (8 doubles each: b0 b1 b2 b3 as x y pairs,
** mm), segment k part of stroke owner[k]: *share = (length with another
** stroke within d) / (length), 0 for a drawing without length.  d > 0, mm.
** group (may be NULL: one group): segment k's group; only strokes of one
** group count as close (the pens of layers.apart = pen overlap by design).
** LW_ENOMEM, or LW_EINPUT when the points would exceed 2^32. */
lw_status lw_close_share(const double *b, const size_t *owner, const size_t *group, size_t n, double d,
                         double *share, lw_error *err);

/* The same for splines, each spline a stroke (the state before the
** plotter post-pass). */
lw_status lw_close_share_splines(const lw_splines *sp, double d, double *share, lw_error *err);

/* Whether the curves of two cubic Bezier segments a and b come within d
** (> 0) of each other: below d^2 (their least squared distance) if so, at
** least d^2 if not.  INFINITY is certain: the control points' hulls, or
** polygons of the curves with the bound on how far a curve strays from its
** polygon, keep them d apart.  Otherwise the value is a local search's (a
** distance between two points of the curves, never below the least),
** started from the polygons' nearest points; the polygons keep within
** d / 20 of the curves (at most 16 pieces: sharper bends only start it
** less well). */
double lw_bezier_near2(const double a[8], const double b[8], double d);

/* The box {x0, y0, x1, y1} of the control points of c, widened by d on
** every side: the curve's widened by d, as it lies in their convex hull. */
static inline void lw_bezier_box(const double c[8], double d, double box[4])
{
  box[0] = box[2] = c[0], box[1] = box[3] = c[1];
  for (int k = 2; k < 8; k += 2) {
    box[0] = c[k] < box[0] ? c[k] : box[0], box[2] = c[k] > box[2] ? c[k] : box[2];
    box[1] = c[k + 1] < box[1] ? c[k + 1] : box[1], box[3] = c[k + 1] > box[3] ? c[k + 1] : box[3];
  }
  box[0] -= d, box[1] -= d, box[2] += d, box[3] += d;
}

/* 1 if the boxes a and b overlap. */
static inline int lw_boxes_meet(const double a[4], const double b[4])
{
  return !(b[0] > a[2] || b[2] < a[0] || b[1] > a[3] || b[3] < a[1]);
}

#ifdef __cplusplus
}
#endif

#endif
