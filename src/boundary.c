/*
** boundary.c -- signed distance to the frame (boundary.h).
**
** Non-finite query points: a NaN or infinite coordinate gives +INFINITY for
** every bounded kind, i.e. "outside".  The boundary energy is then +infinity,
** so a step that produced a NaN node is rejected instead of poisoning the
** sums, and lw_boundary_inside is false there.  LW_BOUNDARY_NONE returns
** -INFINITY for every point, NaN included: the term is off, whatever the point.
*/
#include "linewise/boundary.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* The sign of the turn a -> b -> c. */
static int turn(double ax, double ay, double bx, double by, double cx, double cy)
{
  const double t = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
  return (t > 0) - (t < 0);
}

/* Whether c lies in the box of a and b (c on their line). */
static int within(double ax, double ay, double bx, double by, double cx, double cy)
{
  return cx >= fmin(ax, bx) && cx <= fmax(ax, bx) && cy >= fmin(ay, by) && cy <= fmax(ay, by);
}

/* Whether segments p1 p2 and p3 p4 meet (touching counts). */
static int segments_meet(const double *x, const double *y, size_t i1, size_t i2, size_t i3, size_t i4)
{
  const int d1 = turn(x[i3], y[i3], x[i4], y[i4], x[i1], y[i1]), d2 = turn(x[i3], y[i3], x[i4], y[i4], x[i2], y[i2]),
            d3 = turn(x[i1], y[i1], x[i2], y[i2], x[i3], y[i3]), d4 = turn(x[i1], y[i1], x[i2], y[i2], x[i4], y[i4]);
  if (d1 * d2 < 0 && d3 * d4 < 0) return 1;
  return (!d1 && within(x[i3], y[i3], x[i4], y[i4], x[i1], y[i1])) ||
         (!d2 && within(x[i3], y[i3], x[i4], y[i4], x[i2], y[i2])) ||
         (!d3 && within(x[i1], y[i1], x[i2], y[i2], x[i3], y[i3])) ||
         (!d4 && within(x[i1], y[i1], x[i2], y[i2], x[i4], y[i4]));
}

int lw_boundary_crossing(size_t n, const double *x, const double *y, size_t *a, size_t *b)
{
  /* the vertices that differ from the one before (a repeated vertex, or the
  ** first repeated to close the path, makes an edge of no length) */
  size_t *v = malloc((n ? n : 1) * sizeof *v), m = 0;
  if (!v) return 0;
  for (size_t i = 0; i < n; i++)
    if (!m || x[i] != x[v[m - 1]] || y[i] != y[v[m - 1]]) v[m++] = i;
  while (m > 1 && x[v[m - 1]] == x[v[0]] && y[v[m - 1]] == y[v[0]]) m--;
  int found = 0;
  for (size_t i = 0; i < m && !found; i++)
    for (size_t j = i + 2; j < m && !found; j++) {
      if (i == 0 && j == m - 1) continue; /* neighbours across the closing edge */
      if (segments_meet(x, y, v[i], v[i + 1], v[j], v[(j + 1) % m])) {
        *a = v[i];
        *b = v[j];
        found = 1;
      }
    }
  free(v);
  return found;
}

lw_status lw_boundary_polygon(lw_boundary *b, size_t n, const double *x, const double *y,
                              lw_error *err)
{
  if (n < 3 || !x || !y)
    return lw_error_set(err, LW_EINPUT, "polygon needs at least 3 vertices (got %zu)", n);
  for (size_t i = 0; i < n; i++)
    if (!isfinite(x[i]) || !isfinite(y[i]))
      return lw_error_set(err, LW_EINPUT, "polygon vertex %zu (%g, %g) is not finite", i,
                          x[i], y[i]);

  /* Shoelace area about the first vertex (less cancellation for a polygon far
  ** from the origin).  "Zero" is relative to the bounding box, so collinear
  ** vertices are rejected even when rounding leaves a tiny residue. */
  double a2 = 0, xmin = x[0], xmax = x[0], ymin = y[0], ymax = y[0];
  for (size_t i = 1; i + 1 < n; i++)
    a2 += (x[i] - x[0]) * (y[i + 1] - y[0]) - (x[i + 1] - x[0]) * (y[i] - y[0]);
  for (size_t i = 1; i < n; i++) {
    xmin = fmin(xmin, x[i]);
    xmax = fmax(xmax, x[i]);
    ymin = fmin(ymin, y[i]);
    ymax = fmax(ymax, y[i]);
  }
  double w = xmax - xmin, h = ymax - ymin;
  if (!isfinite(a2) || !isfinite(w * w + h * h))
    return lw_error_set(err, LW_EINPUT, "polygon of %zu vertices spans %g x %g: its area overflows", n, w, h);
  if (!(fabs(a2) > 1e-12 * (w * w + h * h)))
    return lw_error_set(err, LW_EINPUT, "polygon of %zu vertices has zero area", n);

  if (n > SIZE_MAX / sizeof(double))
    return lw_error_set(err, LW_ENOMEM, "out of memory for a polygon of %zu vertices", n);
  double *vx = malloc(n * sizeof *vx), *vy = malloc(n * sizeof *vy);
  if (!vx || !vy) {
    free(vx);
    free(vy);
    return lw_error_set(err, LW_ENOMEM, "out of memory for a polygon of %zu vertices", n);
  }
  memcpy(vx, x, n * sizeof *vx);
  memcpy(vy, y, n * sizeof *vy);
  /* b is overwritten, not cleared: it may be uninitialised.  Nothing is
  ** touched on failure. */
  memset(b, 0, sizeof *b);
  b->kind = LW_BOUNDARY_POLYGON;
  b->n = n;
  b->vx = vx;
  b->vy = vy;
  /* convex: every turn the same way (straight runs of vertices allowed) */
  int left = 0, right = 0;
  for (size_t i = 0; i < n; i++) {
    const size_t j = (i + 1) % n, k = (i + 2) % n;
    const double turn = (x[j] - x[i]) * (y[k] - y[j]) - (y[j] - y[i]) * (x[k] - x[j]);
    left += turn > 0;
    right += turn < 0;
  }
  b->convex = !(left && right);
  return LW_OK;
}

void lw_boundary_clear(lw_boundary *b)
{
  if (!b) return;
  free(b->vx);
  free(b->vy);
  b->vx = b->vy = NULL;
  b->n = 0;
  lw_grid2d_free(b->sdt);
  b->sdt = NULL;
}

/* Exact signed distance to an axis-aligned box: q is how far the point lies
** beyond each pair of sides (negative inside).  Outside, the nearest boundary
** point is on a side (one q > 0) or a corner (both > 0): |max(q, 0)|.
** Inside, it is the nearest side: max(qx, qy). */
/* (the larger by a comparison, not fmax: a library call at -O2, 4 % of a
** run of local terms; the values are finite, lw_boundary_distance's guard) */
static double rect_distance(const lw_boundary *b, double x, double y)
{
  const double lx = b->x0 - x, hx = x - b->x1, ly = b->y0 - y, hy = y - b->y1;
  const double qx = lx > hx ? lx : hx, qy = ly > hy ? ly : hy;
  if (qx > 0 || qy > 0) {
    double ox = qx > 0 ? qx : 0, oy = qy > 0 ? qy : 0;
    return sqrt(ox * ox + oy * oy);
  }
  return qx > qy ? qx : qy;
}

static double circle_distance(const lw_boundary *b, double x, double y)
{
  double dx = x - b->cx, dy = y - b->cy;
  return sqrt(dx * dx + dy * dy) - b->radius;
}

/* Distance to the nearest edge, negated when the point is inside by the
** even-odd rule.  Both happen in one pass over the edges.  The crossing test
** counts edges that straddle the horizontal line through the point (half-open
** in y, so a vertex on that line is counted once) and cross it to the right of
** the point.  No orientation enters, so either vertex order works.  A polygon
** with no vertices (after lw_boundary_clear) has no inside: +INFINITY.
** (*ox, *oy) receives the point minus its nearest boundary point. */
static double polygon_nearest(const lw_boundary *b, double x, double y, double *ox, double *oy)
{
  const size_t n = b->n;
  *ox = *oy = 0.0;
  if (n == 0 || !b->vx || !b->vy) return INFINITY;
  const double *px = b->vx, *py = b->vy;
  double best = INFINITY;
  int inside = 0;
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    double ax = px[j], ay = py[j], ex = px[i] - ax, ey = py[i] - ay;
    double wx = x - ax, wy = y - ay;
    double ee = ex * ex + ey * ey, t = 0.0;
    /* Projection onto the edge clamped to its ends; a repeated vertex gives a
    ** zero-length edge whose distance is just the distance to the vertex. */
    if (ee > 0) {
      t = (wx * ex + wy * ey) / ee;
      t = t < 0 ? 0 : (t > 1 ? 1 : t);
    }
    double dx = wx - t * ex, dy = wy - t * ey, d2 = dx * dx + dy * dy;
    if (d2 < best) {
      best = d2;
      *ox = dx;
      *oy = dy;
    }
    if ((ay > y) != (py[i] > y)) {
      /* ey != 0 here, since the edge straddles y. */
      double xc = ax + ex * (y - ay) / ey;
      if (x < xc) inside = !inside;
    }
  }
  double d = sqrt(best);
  return inside && d > 0 ? -d : d;
}

static double polygon_distance(const lw_boundary *b, double x, double y)
{
  double ox, oy;
  return polygon_nearest(b, x, y, &ox, &oy);
}

double lw_boundary_distance(const lw_boundary *b, double x, double y)
{
  if (b->kind == LW_BOUNDARY_NONE) return -INFINITY;
  if (!isfinite(x) || !isfinite(y)) return INFINITY;
  switch (b->kind) {
  case LW_BOUNDARY_RECT: return rect_distance(b, x, y);
  case LW_BOUNDARY_CIRCLE: return circle_distance(b, x, y);
  case LW_BOUNDARY_POLYGON: return polygon_distance(b, x, y);
  case LW_BOUNDARY_MASK: {
    /* a cleared mask has no inside */
    if (!b->sdt || b->sdt->ncomp != 1) return INFINITY;
    double d;
    lw_grid2d_eval(b->sdt, x, y, &d);
    return d;
  }
  case LW_BOUNDARY_NONE: break;
  }
  return -INFINITY;
}

double lw_boundary_distance_grad(const lw_boundary *b, double x, double y, double g[2])
{
  g[0] = g[1] = 0.0;
  double d = lw_boundary_distance(b, x, y);
  if (!isfinite(d)) return d;
  switch (b->kind) {
  case LW_BOUNDARY_RECT: {
    /* the side that rect_distance took the larger of, or the offset outside */
    double qx = fmax(b->x0 - x, x - b->x1), qy = fmax(b->y0 - y, y - b->y1);
    if (qx > 0 || qy > 0) {
      g[0] = qx > 0 ? qx / d : 0.0;
      g[1] = qy > 0 ? qy / d : 0.0;
      g[0] *= (x - b->x1 > b->x0 - x) ? 1.0 : -1.0;
      g[1] *= (y - b->y1 > b->y0 - y) ? 1.0 : -1.0;
    } else if (qx >= qy) {
      g[0] = (x - b->x1 > b->x0 - x) ? 1.0 : -1.0;
    } else {
      g[1] = (y - b->y1 > b->y0 - y) ? 1.0 : -1.0;
    }
    break;
  }
  case LW_BOUNDARY_CIRCLE: {
    double dx = x - b->cx, dy = y - b->cy, r = sqrt(dx * dx + dy * dy);
    if (r > 0.0) {
      g[0] = dx / r;
      g[1] = dy / r;
    }
    break;
  }
  case LW_BOUNDARY_POLYGON: {
    double ox, oy, e = polygon_nearest(b, x, y, &ox, &oy);
    if (e != 0.0) { /* d = +-|o|: the gradient of |o| is o / |o|, negated inside */
      g[0] = ox / e;
      g[1] = oy / e;
    }
    break;
  }
  case LW_BOUNDARY_MASK: {
    double v;
    lw_grid2d_eval_grad(b->sdt, x, y, &v, &g[0], &g[1]);
    break;
  }
  case LW_BOUNDARY_NONE:
    break;
  }
  return d;
}

double lw_boundary_mask_slope(const lw_grid2d *g)
{
  double slope = 1.0;
  for (int j = 0; j + 1 < g->ny; j++)
    for (int i = 0; i + 1 < g->nx; i++) {
      const double *v = g->data + (size_t)j * (size_t)g->nx + (size_t)i, *w = v + g->nx;
      const double gx = fmax(fabs(v[1] - v[0]), fabs(w[1] - w[0])) / g->hx;
      const double gy = fmax(fabs(w[0] - v[0]), fabs(w[1] - v[1])) / g->hy;
      slope = fmax(slope, hypot(gx, gy));
    }
  return slope;
}

/* A piece of the curve: its four control points. */
typedef struct {
  double x[4], y[4];
} bezier_piece;

/* The curve's point at t = 1/2 and the two halves (de Casteljau). */
static void split_half(const bezier_piece *p, bezier_piece *l, bezier_piece *r)
{
  const double *c[2] = {p->x, p->y};
  double *lo[2] = {l->x, l->y}, *hi[2] = {r->x, r->y};
  for (int k = 0; k < 2; k++) {
    const double *q = c[k];
    const double a = 0.5 * (q[0] + q[1]), b = 0.5 * (q[1] + q[2]), e = 0.5 * (q[2] + q[3]);
    const double ab = 0.5 * (a + b), be = 0.5 * (b + e), m = 0.5 * (ab + be);
    lo[k][0] = q[0], lo[k][1] = a, lo[k][2] = ab, lo[k][3] = m;
    hi[k][0] = m, hi[k][1] = be, hi[k][2] = e, hi[k][3] = q[3];
  }
}

/* Pieces of 1e-9 mm are not split: the distance differs from their tested
** ends by less than that.  The stack holds one piece a level and the next.
** A curve that needs more than CLEAR_PIECES pieces runs alongside the
** limit within a hair (the disc test of a frame that is not convex splits
** such a curve down to pieces of that hair): it is refused, which is
** exact to far better than anything a drawing sees and keeps the cost
** bounded (a segment parallel to the frame 1e-8 mm beyond the clearance
** took 143 s before). */
#define CLEAR_TOL 1e-9
#define CLEAR_DEPTH 80
#define CLEAR_PIECES 4096

/* Where the frame is convex the signed distance is a convex function
** inside it, so over a piece whose control points lie inside, the
** distance is largest at one of them: the piece is clear exactly when
** they are, and a piece running parallel to a side is decided at once. */
static int frame_convex(const lw_boundary *b)
{
  return b->kind == LW_BOUNDARY_RECT || b->kind == LW_BOUNDARY_CIRCLE ||
         (b->kind == LW_BOUNDARY_POLYGON && b->convex);
}

/* Squared distance from (px, py) to the segment (ax, ay)-(bx, by). */
static double point_segment2(double px, double py, double ax, double ay, double bx, double by)
{
  const double ex = bx - ax, ey = by - ay, ee = ex * ex + ey * ey;
  double t = ee > 0.0 ? ((px - ax) * ex + (py - ay) * ey) / ee : 0.0;
  t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
  const double dx = px - ax - t * ex, dy = py - ay - t * ey;
  return dx * dx + dy * dy;
}

/* The distance between two segments: 0 where they cross, else the least
** of the four from an end to the other segment. */
static double segment_segment(const double a[4], const double b[4])
{
  const double d1x = a[2] - a[0], d1y = a[3] - a[1], d2x = b[2] - b[0], d2y = b[3] - b[1];
  const double s1 = d1x * (b[1] - a[1]) - d1y * (b[0] - a[0]), s2 = d1x * (b[3] - a[1]) - d1y * (b[2] - a[0]);
  const double s3 = d2x * (a[1] - b[1]) - d2y * (a[0] - b[0]), s4 = d2x * (a[3] - b[1]) - d2y * (a[2] - b[0]);
  if (((s1 < 0) != (s2 < 0)) && ((s3 < 0) != (s4 < 0))) return 0.0;
  double m = point_segment2(a[0], a[1], b[0], b[1], b[2], b[3]);
  m = fmin(m, point_segment2(a[2], a[3], b[0], b[1], b[2], b[3]));
  m = fmin(m, point_segment2(b[0], b[1], a[0], a[1], a[2], a[3]));
  m = fmin(m, point_segment2(b[2], b[3], a[0], a[1], a[2], a[3]));
  return sqrt(m);
}

/* A polygon's piece whose start lies inside: clear if its chord keeps
** clear + f from every edge, f how far its inner control points stand off
** the chord (the piece lies within f of it).  Then the chord crosses no
** edge, so it lies inside with its start, and every point of the piece
** keeps clear.  Exact for a flat piece beside an edge, where a concave
** frame's discs would split down to the hair it stands off the limit. */
static int polygon_piece_clear(const lw_boundary *b, const double *x, const double *y, double clear)
{
  const double chord[4] = {x[0], y[0], x[3], y[3]};
  const double f = sqrt(fmax(point_segment2(x[1], y[1], x[0], y[0], x[3], y[3]),
                             point_segment2(x[2], y[2], x[0], y[0], x[3], y[3])));
  for (size_t i = 0, j = b->n - 1; i < b->n; j = i++) {
    const double edge[4] = {b->vx[j], b->vy[j], b->vx[i], b->vy[i]};
    if (!(segment_segment(chord, edge) - f > clear)) return 0;
  }
  return 1;
}

int lw_boundary_curve_clear(const lw_boundary *b, const double x[4], const double y[4], double clear)
{
  if (b->kind == LW_BOUNDARY_NONE) return 1;
  const double slope = b->kind == LW_BOUNDARY_MASK ? b->slope : 1.0;
  /* d <= -clear and d < 0 at once (clear may be 0) */
  const double limit = clear > 0.0 ? -clear : -0.0;
#define CLEAR_OK(d) ((d) <= limit && (d) < 0.0)
  for (int k = 0; k < 4; k++) /* fmin and fmax below would pass over a NaN */
    if (!isfinite(x[k]) || !isfinite(y[k])) return 0;
  const int convex = frame_convex(b);
  if (convex) {
    /* the loop's first test, and its answer for almost every segment of a
    ** scene: the four control points clear of a convex frame hold the curve
    ** (each distance once: the frame's check was a sixth of a proposal
    ** without the pair term) */
    double d[4];
    for (int k = 0; k < 4; k++) d[k] = lw_boundary_distance(b, x[k], y[k]);
    if (!CLEAR_OK(d[0]) || !CLEAR_OK(d[3])) return 0;
    if (CLEAR_OK(fmax(fmax(d[0], d[1]), fmax(d[2], d[3])))) return 1;
  } else if (!CLEAR_OK(lw_boundary_distance(b, x[0], y[0])) || !CLEAR_OK(lw_boundary_distance(b, x[3], y[3]))) {
    return 0;
  }
  bezier_piece stack[CLEAR_DEPTH + 2];
  memcpy(stack[0].x, x, sizeof stack[0].x);
  memcpy(stack[0].y, y, sizeof stack[0].y);
  int top = 1;
  for (int pieces = 0; top > 0; pieces++) {
    if (pieces == CLEAR_PIECES) return 0;
    const bezier_piece p = stack[--top];
    /* the control points' box centre, and the disc about it holding them */
    const double cx = 0.5 * (fmin(fmin(p.x[0], p.x[1]), fmin(p.x[2], p.x[3])) +
                             fmax(fmax(p.x[0], p.x[1]), fmax(p.x[2], p.x[3])));
    const double cy = 0.5 * (fmin(fmin(p.y[0], p.y[1]), fmin(p.y[2], p.y[3])) +
                             fmax(fmax(p.y[0], p.y[1]), fmax(p.y[2], p.y[3])));
    double r2 = 0.0, far = -INFINITY;
    for (int k = 0; k < 4; k++) {
      const double dx = p.x[k] - cx, dy = p.y[k] - cy;
      r2 = fmax(r2, dx * dx + dy * dy);
      if (convex) far = fmax(far, lw_boundary_distance(b, p.x[k], p.y[k]));
    }
    const double r = sqrt(r2);
    if (convex ? CLEAR_OK(far) : CLEAR_OK(lw_boundary_distance(b, cx, cy) + slope * r)) continue;
    if (b->kind == LW_BOUNDARY_POLYGON && !convex && polygon_piece_clear(b, p.x, p.y, clear)) continue;
    bezier_piece lo, hi;
    split_half(&p, &lo, &hi);
    if (!CLEAR_OK(lw_boundary_distance(b, lo.x[3], lo.y[3]))) return 0;
    if (r < CLEAR_TOL) continue;
    if (top + 2 > CLEAR_DEPTH + 2) return 0; /* deeper than a curve within 1e15 mm needs: refused, never passed */
    stack[top++] = hi;
    stack[top++] = lo;
  }
#undef CLEAR_OK
  return 1;
}

int lw_boundary_inside(const lw_boundary *b, double x, double y)
{
  return lw_boundary_distance(b, x, y) < 0;
}
