/*
** strokes.h -- the drawing as a pen plotter sees it: paths of cubic Bezier
** segments, grouped by pen, and the post-pass that prepares them for the
** plotter (join, crop, drop, order) and estimates the plot time.
**
** A path is a chain of segments, each four control points b0 b1 b2 b3
** (8 doubles, x y pairs, mm), the end of one the start of the next.  Unlike
** a spline (spline.h) a path may turn a corner at a node: a joined path
** carries a short bridge between the strokes it joins, and a cropped piece
** ends wherever the picture's edge cuts it.  Paths are stored pen by pen
** (pen_first as in plot.h) and drawn in storage order; reversed[k] says the
** plotter draws path k from its last point to its first.  src[k] and
** part[k] name where a path came from: the spline of its first piece, and
** 0 for a whole spline or its first piece after a cut, 1, 2, ... for the
** pieces after it (final.svg's path ids, docs/FORMATS.md).
**
** The post-pass (lw_strokes_prepare) never changes the state; it reads
** the plot of the splines (pens and nothing else) and writes new paths:
**   1. join: two path ends of one pen whose points are at most `dist` apart
**      and whose directions agree within `angle` (the direction out of the
**      first end and the direction into the second) become one path, with
**      a cubic bridge from the one point to the other along both tangents
**      (control points a + t_a g/3, b - t_b g/3, g the gap; none when the
**      points coincide).  Candidates are taken shortest gap first (ties by
**      end index), an end joins at most once and no chain closes on
**      itself, so the result does not depend on the order of the input
**      beyond those ties.
**   2. crop: every path is cut where it crosses the rectangle's edges and
**      only the pieces inside are kept.  A crossing is a root in (0, 1) of
**      x(t) - x0 (and the three others) of a segment's cubic; the cubic is
**      split at the extrema of its derivative into monotone stretches,
**      each holding at most one root, found by bisection to the last bit.
**      A piece is the exact sub-curve between two roots (de Casteljau),
**      its end points clamped into the rectangle (a move of ~1e-15 mm).
**   3. drop: paths shorter than `min_length` are left out, and whatever it
**      is those shorter than LW_STROKES_DOT_MM: a dot at the files'
**      precision (the SVG's "M 50 50 C 50 50 50 50 50 50", a laser firing
**      on one spot), which plot.min_length = 0 kept.
**   4. order: each pen's paths as plot.h orders them (greedy, 2-opt).
** Join comes before crop, so a bridge never leaves the rectangle, and drop
** after both, so short pieces that join into a long path stay, and the
** slivers the crop leaves at the edge go.
**
** Plot time (lw_strokes_time): pen-down length / speed_down + pen-up travel
** / speed_up + lifts * lift_time, one lift per path (the pen goes down at
** its start and up at its end); constant speeds, no acceleration, no pen
** changes.
*/
#ifndef LINEWISE_STROKES_H
#define LINEWISE_STROKES_H

#include <stddef.h>

#include "linewise/error.h"
#include "linewise/plot.h"
#include "linewise/spline.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  size_t n;                  /* paths */
  size_t n_segs;             /* segments in all */
  size_t *first;             /* n + 1: path k is segments first[k] .. first[k+1]-1 */
  double *b;                 /* 8 per segment: b0x b0y b1x b1y b2x b2y b3x b3y, mm */
  unsigned char *reversed;   /* n: drawn from the end */
  size_t *src;               /* n: the spline of the path's first piece */
  unsigned *part;            /* n: the piece of that spline, 0 = the whole or first */
  int n_pens;
  size_t pen_first[LW_PLOT_PENS_MAX + 1];
  size_t cap_n, cap_segs;
} lw_strokes;

/* What the post-pass did, for summary.json. */
typedef struct {
  size_t lifts_before;       /* paths of the plot (one lift each) */
  size_t joins;              /* joins made */
  size_t cut;                /* paths that cross the rectangle's edge (partly kept) */
  size_t outside;            /* paths wholly outside the rectangle (left out) */
  size_t dropped;            /* paths shorter than min_length (left out) */
  size_t lifts_after;        /* paths drawn */
  double travel_before;      /* pen-up travel of the paths before ordering, mm */
  double travel_after;       /* pen-up travel as plotted, mm */
} lw_strokes_report;

typedef struct {
  double join_dist[LW_PLOT_PENS_MAX];  /* per pen, mm; 0 = no joining (a pen's width sets it) */
  double join_angle;                   /* radians, 0 .. pi */
  int crop;                            /* 1 = crop to [x0, x1] x [y0, y1] */
  double x0, y0, x1, y1;               /* the rectangle, mm */
  double min_length[LW_PLOT_PENS_MAX]; /* per pen, mm; 0 = keep all */
  lw_plot_order order;
  double home_x, home_y;               /* where each pen starts (the machine's origin), mm */
  int home_back;                       /* 1: the pen goes home after the last pen (machine files) */
} lw_strokes_options;

/* An empty drawing with n_pens pens (1 .. LW_PLOT_PENS_MAX); NULL and err on
** bad arguments or lack of memory. */
lw_strokes *lw_strokes_new(int n_pens, lw_error *err);
void lw_strokes_free(lw_strokes *s);

/* Appends a path of pen `pen` (0-based, not below the last path's pen) with
** nseg segments b[8 * nseg] (copied).  LW_ENOMEM or LW_EINPUT (bad pen). */
lw_status lw_strokes_add(lw_strokes *s, int pen, size_t src, unsigned part, int reversed, const double *b,
                         size_t nseg, lw_error *err);

/* The paths of a plot: its pens, order and directions (plot NULL: every
** spline that is not a point, pen 1, index order, forward). */
lw_strokes *lw_strokes_from_plot(const lw_splines *sp, const lw_plot *plot, lw_error *err);

/* Steps 1-3 of the post-pass on in (unchanged), into a new drawing; the
** report's counts are filled (not the travels).  directed (output.order =
** none): a join links only the end a path is drawn to with the end another
** is drawn from, so every path keeps its direction. */
lw_strokes *lw_strokes_join(const lw_strokes *in, const double *dist, double angle, int directed,
                            lw_strokes_report *rep, lw_error *err);
lw_strokes *lw_strokes_crop(const lw_strokes *in, double x0, double y0, double x1, double y1,
                            lw_strokes_report *rep, lw_error *err);
#define LW_STROKES_DOT_MM 1e-4 /* two of final.svg's last decimals (mm) */
lw_strokes *lw_strokes_drop(const lw_strokes *in, const double *min_length, lw_strokes_report *rep, lw_error *err);

/* Step 4 in place: orders each pen's paths from home (hx, hy) and sets
** their directions; rep->travel_before and travel_after are set, with the
** way home between pens, and after the last where back is 1 (the machine
** files end at home). */
lw_status lw_strokes_order(lw_strokes *s, lw_plot_order order, double hx, double hy, int back, lw_strokes_report *rep,
                           lw_error *err);

/* The whole post-pass on the plot's paths. */
lw_strokes *lw_strokes_prepare(const lw_splines *sp, const lw_plot *plot, const lw_strokes_options *o,
                               lw_strokes_report *rep, lw_error *err);

/* Length of path k, mm (Gauss-Legendre on each segment, halved until two
** levels agree to 1e-9 relative). */
double lw_strokes_length(const lw_strokes *s, size_t k);

/* The pen-down length of the drawing, mm: the sum of its path lengths. */
double lw_strokes_total_length(const lw_strokes *s);

/* Plot time in seconds (see above); travel is the pen-up travel in mm. */
double lw_strokes_time(const lw_strokes *s, double travel, double speed_down, double speed_up, double lift_time);

/* The paths of pen k (0-based): a .. z - 1. */
void lw_strokes_pen_range(const lw_strokes *s, int k, size_t *a, size_t *z);

/* Segment j (0-based) of path k in the order the plotter draws it, into
** out[8]: of a reversed path, the last stored segment first with its
** control points b3 b2 b1 b0 (the same numbers, so the same curve). */
void lw_strokes_drawn_segment(const lw_strokes *s, size_t k, size_t j, double *out);

/* The point at t in [0, 1] of the cubic b[8] into xy[2]. */
void lw_bezier_eval(const double *b, double t, double *xy);

#ifdef __cplusplus
}
#endif

#endif
