/* strokes.c -- plotter paths and their post-pass: join, crop, drop, order,
** plot time (strokes.h). */
#include "linewise/strokes.h"

#include <gsl/gsl_poly.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/order.h"

/* ---- storage ------------------------------------------------------------ */

lw_strokes *lw_strokes_new(int n_pens, lw_error *err)
{
  if (n_pens < 1 || n_pens > LW_PLOT_PENS_MAX) {
    lw_error_set(err, LW_EINPUT, "%d pens: expected 1 to %d", n_pens, LW_PLOT_PENS_MAX);
    return NULL;
  }
  lw_strokes *s = calloc(1, sizeof *s);
  if (s) s->first = calloc(1, sizeof *s->first);
  if (!s || !s->first) {
    free(s);
    lw_error_set(err, LW_ENOMEM, "out of memory for a drawing");
    return NULL;
  }
  s->n_pens = n_pens;
  return s;
}

void lw_strokes_free(lw_strokes *s)
{
  if (!s) return;
  free(s->first);
  free(s->b);
  free(s->reversed);
  free(s->src);
  free(s->part);
  free(s);
}

/* Room for one more path of nseg segments; 0 when memory runs out. */
static int grow(lw_strokes *s, size_t nseg)
{
  if (s->n + 1 > s->cap_n) {
    size_t cap = s->cap_n ? 2 * s->cap_n : 64;
    size_t *first = realloc(s->first, (cap + 1) * sizeof *first);
    if (!first) return 0;
    s->first = first;
    unsigned char *rev = realloc(s->reversed, cap);
    if (!rev) return 0;
    s->reversed = rev;
    size_t *src = realloc(s->src, cap * sizeof *src);
    if (!src) return 0;
    s->src = src;
    unsigned *part = realloc(s->part, cap * sizeof *part);
    if (!part) return 0;
    s->part = part;
    s->cap_n = cap;
  }
  if (s->n_segs + nseg > s->cap_segs) {
    size_t cap = s->cap_segs ? 2 * s->cap_segs : 256;
    while (cap < s->n_segs + nseg) cap *= 2;
    double *b = realloc(s->b, cap * 8 * sizeof *b);
    if (!b) return 0;
    s->b = b;
    s->cap_segs = cap;
  }
  return 1;
}

/* The pen of the last path (0 when there is none). */
static int last_pen(const lw_strokes *s)
{
  int k = 0;
  while (k + 1 < s->n_pens && s->pen_first[k + 1] < s->n) k++;
  return s->n ? k : 0;
}

lw_status lw_strokes_add(lw_strokes *s, int pen, size_t src, unsigned part, int reversed, const double *b,
                         size_t nseg, lw_error *err)
{
  if (pen < last_pen(s) || pen >= s->n_pens || nseg == 0)
    return lw_error_set(err, LW_EINPUT, "a path of pen %d with %zu segments after pen %d of %d", pen + 1, nseg,
                        last_pen(s) + 1, s->n_pens);
  if (!grow(s, nseg))
    return lw_error_set(err, LW_ENOMEM, "out of memory while gathering the drawing's paths (at path %zu)", s->n + 1);
  memcpy(s->b + 8 * s->n_segs, b, 8 * nseg * sizeof *b);
  s->n_segs += nseg;
  s->reversed[s->n] = (unsigned char)(reversed != 0);
  s->src[s->n] = src;
  s->part[s->n] = part;
  s->n++;
  s->first[s->n] = s->n_segs;
  /* the pens after this one start after it */
  for (int k = pen + 1; k <= s->n_pens; k++) s->pen_first[k] = s->n;
  return LW_OK;
}

/* The pen of path k. */
static int pen_of(const lw_strokes *s, size_t k)
{
  int p = 0;
  while (p + 1 < s->n_pens && s->pen_first[p + 1] <= k) p++;
  return p;
}

static lw_status copy_path(lw_strokes *out, const lw_strokes *in, size_t k, lw_error *err)
{
  return lw_strokes_add(out, pen_of(in, k), in->src[k], in->part[k], in->reversed[k], in->b + 8 * in->first[k],
                        in->first[k + 1] - in->first[k], err);
}

/* Fails the step: frees the half-built drawing. */
static lw_strokes *fail(lw_strokes *out)
{
  lw_strokes_free(out);
  return NULL;
}

lw_strokes *lw_strokes_from_plot(const lw_splines *sp, const lw_plot *plot, lw_error *err)
{
  lw_strokes *s = lw_strokes_new(plot ? plot->n_pens : 1, err);
  if (!s) return NULL;
  size_t n = plot ? plot->n : sp->n_splines;
  double *b = NULL;
  size_t cap = 0;
  for (size_t k = 0; k < n; k++) {
    size_t i = plot ? plot->spline[k] : k;
    if (!plot && lw_splines_is_point(sp, i)) continue;
    size_t nseg = lw_splines_segments(sp, i);
    if (nseg > cap) {
      double *nb = realloc(b, 8 * nseg * sizeof *nb);
      if (!nb) {
        free(b);
        lw_error_set(err, LW_ENOMEM, "out of memory for spline %zu", i);
        return fail(s);
      }
      b = nb;
      cap = nseg;
    }
    for (size_t m = 0; m < nseg; m++) lw_splines_bezier(sp, i, m, b + 8 * m);
    int pen = 0;
    while (plot && pen + 1 < plot->n_pens && plot->pen_first[pen + 1] <= k) pen++;
    if (lw_strokes_add(s, pen, i, 0, plot ? plot->reversed[k] : 0, b, nseg, err)) {
      free(b);
      return fail(s);
    }
  }
  free(b);
  return s;
}

void lw_strokes_pen_range(const lw_strokes *s, int k, size_t *a, size_t *z)
{
  *a = s->pen_first[k];
  *z = k + 1 < s->n_pens ? s->pen_first[k + 1] : s->n;
}

void lw_strokes_drawn_segment(const lw_strokes *s, size_t k, size_t j, double *out)
{
  size_t a = s->first[k], n = s->first[k + 1] - a;
  if (!s->reversed[k]) {
    memcpy(out, s->b + 8 * (a + j), 8 * sizeof *out);
    return;
  }
  const double *b = s->b + 8 * (a + n - 1 - j);
  for (int c = 0; c < 4; c++) {
    out[2 * c] = b[6 - 2 * c];
    out[2 * c + 1] = b[7 - 2 * c];
  }
}

/* ---- Bezier pieces -------------------------------------------------------- */

void lw_bezier_eval(const double *b, double t, double *xy)
{
  double u = 1.0 - t;
  for (int c = 0; c < 2; c++) {
    double p01 = u * b[c] + t * b[2 + c], p12 = u * b[2 + c] + t * b[4 + c], p23 = u * b[4 + c] + t * b[6 + c];
    double q0 = u * p01 + t * p12, q1 = u * p12 + t * p23;
    xy[c] = u * q0 + t * q1;
  }
}

/* de Casteljau at t: the left half into l[8], the right into r[8] (either
** may be NULL). */
static void split(const double *b, double t, double *l, double *r)
{
  double u = 1.0 - t, out_l[8], out_r[8];
  for (int c = 0; c < 2; c++) {
    double p01 = u * b[c] + t * b[2 + c], p12 = u * b[2 + c] + t * b[4 + c], p23 = u * b[4 + c] + t * b[6 + c];
    double q0 = u * p01 + t * p12, q1 = u * p12 + t * p23, m = u * q0 + t * q1;
    out_l[c] = b[c];
    out_l[2 + c] = p01;
    out_l[4 + c] = q0;
    out_l[6 + c] = m;
    out_r[c] = m;
    out_r[2 + c] = q1;
    out_r[4 + c] = p23;
    out_r[6 + c] = b[6 + c];
  }
  if (l) memcpy(l, out_l, sizeof out_l);
  if (r) memcpy(r, out_r, sizeof out_r);
}

/* The sub-curve of b[8] between parameters t0 < t1 into out[8]. */
static void bezier_sub(const double *b, double t0, double t1, double *out)
{
  double left[8];
  if (t1 < 1.0) split(b, t1, left, NULL);
  else memcpy(left, b, sizeof left);
  if (t0 > 0.0) split(left, t0 / t1, NULL, out);
  else memcpy(out, left, sizeof left);
}

/* Derivative of the cubic at t (without the factor 3). */
static void tangent(const double *b, double t, double *d)
{
  double u = 1.0 - t;
  for (int c = 0; c < 2; c++)
    d[c] = u * u * (b[2 + c] - b[c]) + 2 * u * t * (b[4 + c] - b[2 + c]) + t * t * (b[6 + c] - b[4 + c]);
}

/* Gauss-Legendre, 5 nodes on [0, 1]: exact for polynomials of degree 9. */
static const double gl_x[5] = {0.04691007703066800, 0.23076534494715845, 0.5, 0.76923465505284155,
                               0.95308992296933200};
static const double gl_w[5] = {0.11846344252809454, 0.23931433524968324, 0.28444444444444444,
                               0.23931433524968324, 0.11846344252809454};

static double arc(const double *b, double t0, double t1)
{
  double sum = 0.0, d[2];
  for (int q = 0; q < 5; q++) {
    tangent(b, t0 + (t1 - t0) * gl_x[q], d);
    sum += gl_w[q] * hypot(d[0], d[1]);
  }
  return 3.0 * (t1 - t0) * sum;
}

/* Arc length on [t0, t1] given its one-rule estimate whole: halves until
** the halves agree with the whole (a corner or cusp gets finer steps). */
static double arc_adaptive(const double *b, double t0, double t1, double whole, int depth)
{
  double tm = 0.5 * (t0 + t1), l = arc(b, t0, tm), r = arc(b, tm, t1);
  if (depth >= 30 || fabs(l + r - whole) <= 1e-9 * fmax(l + r, 1e-12)) return l + r;
  return arc_adaptive(b, t0, tm, l, depth + 1) + arc_adaptive(b, tm, t1, r, depth + 1);
}

double lw_strokes_length(const lw_strokes *s, size_t k)
{
  double sum = 0.0;
  for (size_t m = s->first[k]; m < s->first[k + 1]; m++) {
    const double *b = s->b + 8 * m;
    sum += arc_adaptive(b, 0.0, 1.0, arc(b, 0.0, 1.0), 0);
  }
  return sum;
}

/* ---- join ---------------------------------------------------------------- */

/* End e of the paths: e = 2k the start of path k, 2k + 1 its end.  Its
** point and the unit direction pointing out of the path there. */
static void end_of(const lw_strokes *s, size_t base, size_t e, double *pt, double *out)
{
  size_t k = base + e / 2;
  const double *b = s->b + 8 * (e & 1 ? s->first[k + 1] - 1 : s->first[k]);
  double d[2] = {0, 0};
  if (e & 1) {
    pt[0] = b[6];
    pt[1] = b[7];
    /* the last control point that differs from the end gives the tangent */
    for (int c = 4; c >= 0 && d[0] == 0 && d[1] == 0; c -= 2) {
      d[0] = b[6] - b[c];
      d[1] = b[7] - b[c + 1];
    }
  } else {
    pt[0] = b[0];
    pt[1] = b[1];
    for (int c = 2; c <= 6 && d[0] == 0 && d[1] == 0; c += 2) {
      d[0] = b[0] - b[c];
      d[1] = b[1] - b[c + 1];
    }
  }
  double len = hypot(d[0], d[1]);
  out[0] = len > 0 ? d[0] / len : 0.0;
  out[1] = len > 0 ? d[1] / len : 0.0;
}

typedef struct {
  double d;
  size_t a, b; /* a < b */
} join_cand;

static int by_gap(const void *pa, const void *pb)
{
  const join_cand *x = pa, *y = pb;
  if (x->d != y->d) return x->d < y->d ? -1 : 1;
  if (x->a != y->a) return x->a < y->a ? -1 : 1;
  return (x->b > y->b) - (x->b < y->b);
}

/* An end in the grid of a band's cells (side: the band's reach), sorted by
** cell, x then y, ties by index. */
typedef struct {
  long long cx, cy;
  size_t e;
} cell_item;

static int by_cell(const void *pa, const void *pb)
{
  const cell_item *x = pa, *y = pb;
  if (x->cx != y->cx) return x->cx < y->cx ? -1 : 1;
  if (x->cy != y->cy) return x->cy < y->cy ? -1 : 1;
  return (x->e > y->e) - (x->e < y->e);
}

/* The cell of coordinate v from origin o at side h, held within long long
** (a band narrowed far below a page of metres: cells past it share one,
** which costs scans, not joins) */
static long long cell_of(double v, double o, double h)
{
  const double c = floor((v - o) / h);
  return (long long)fmax(-1e18, fmin(1e18, c));
}

/* The first of the n sorted items in cell (cx, cy), and in *end the item
** after its last (both n where the cell is empty). */
static size_t cell_run(const cell_item *c, size_t n, long long cx, long long cy, size_t *end)
{
  size_t lo = 0, hi = n;
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    if (c[mid].cx < cx || (c[mid].cx == cx && c[mid].cy < cy)) lo = mid + 1;
    else hi = mid;
  }
  /* (the end by halving too: a cell of n ends, as ends that coincide, was
  ** walked once for each of them) */
  size_t a = lo, b = n;
  while (a < b) {
    size_t mid = a + (b - a) / 2;
    if (c[mid].cx == cx && c[mid].cy == cy) a = mid + 1;
    else b = mid;
  }
  *end = a;
  return lo;
}

static size_t find(size_t *parent, size_t k)
{
  while (parent[k] != k) k = parent[k] = parent[parent[k]];
  return k;
}

/* Appends path k of in (forward or backward) to the segments buf. */
static void append_piece(const lw_strokes *in, size_t k, int backward, double *buf, size_t *n)
{
  size_t a = in->first[k], z = in->first[k + 1];
  for (size_t j = 0; j < z - a; j++) {
    const double *b = in->b + 8 * (backward ? z - 1 - j : a + j);
    double *o = buf + 8 * (*n)++;
    if (backward)
      for (int c = 0; c < 4; c++) {
        o[2 * c] = b[6 - 2 * c];
        o[2 * c + 1] = b[7 - 2 * c];
      }
    else memcpy(o, b, 8 * sizeof *o);
  }
}

/* The first band's reach: about the spacing of the n ends (a few
** candidates each), or dist where that is smaller; lo, the ends' least x
** and y, the grid's origin. */
static double first_band(const double *pt, size_t ne, double dist, double lo[2])
{
  double hi[2] = {-HUGE_VAL, -HUGE_VAL};
  lo[0] = lo[1] = HUGE_VAL;
  for (size_t e = 0; e < ne; e++)
    for (int c = 0; c < 2; c++) {
      lo[c] = fmin(lo[c], pt[2 * e + c]);
      hi[c] = fmax(hi[c], pt[2 * e + c]);
    }
  const double w = hi[0] - lo[0], h = hi[1] - lo[1];
  /* ends along one line: their spacing along it */
  double spacing = w * h > 0 ? sqrt(w * h / (double)ne) : fmax(w, h) / (double)ne;
  return spacing > 0 && spacing < dist ? spacing : dist;
}

/* The gap between ends a and b where they may be joined in the band
** (below, reach], else -1. */
static double joinable_gap(const double *pt, const double *dir, size_t a, size_t b, double below, double reach,
                           double dist, double cos_max)
{
  const double gx = pt[2 * b] - pt[2 * a], gy = pt[2 * b + 1] - pt[2 * a + 1], d = hypot(gx, gy);
  /* out of one end, into the other: the turn is between dir[a] and -dir[b] */
  double c = -(dir[2 * a] * dir[2 * b] + dir[2 * a + 1] * dir[2 * b + 1]);
  if (d > reach || d <= below || c < cos_max) return -1.0;
  /* and the gap leads on from each end: two strokes side by side, the one
  ** starting behind where the other ends, align but would be bridged by a
  ** hook back over the ink (a tenth of the distance is let through: ends
  ** that overlap by a hair) */
  if (cos_max > -1.0 && (gx * dir[2 * a] + gy * dir[2 * a + 1] < -0.1 * dist ||
                         -(gx * dir[2 * b] + gy * dir[2 * b + 1]) < -0.1 * dist))
    return -1.0;
  return d;
}

/* Joins the n paths of one pen starting at path base into out.  Pairs of
** ends are joined greedily, nearest first.  A distance far past the ends'
** spacing (a pen "joined whole") would have every pair a candidate, n^2
** of them (4.7 GB at 20,000 paths); so candidates are gathered in bands of
** distance, from about the ends' spacing outward, among the ends still free: a pair
** with an end already joined could never be taken, and a band's pairs all
** come after the bands before in the nearest-first order, so the joins are
** those of one sorted list of every pair, whatever the bands' bounds.  A
** band finds its pairs in a grid of cells as wide as its reach: a sweep
** along x alone scanned every pair of hatching's ends, which share their x,
** in every band (4 to 8 times the time of one list where nothing joined). */
static lw_status join_pen(const lw_strokes *in, int pen, size_t base, size_t n, double dist, double cos_max,
                          int directed, lw_strokes_report *rep, lw_strokes *out, lw_error *err)
{
  /* directed: an end where its path is drawn from (end 2p, or 2p + 1 of a
  ** path drawn backward) joins only an end where one is drawn to */
#define DRAWN_FROM(e) (((e) & 1) == in->reversed[base + (e) / 2])
  size_t ne = 2 * n;
  double *pt = malloc((ne ? ne : 1) * 2 * sizeof *pt), *dir = malloc((ne ? ne : 1) * 2 * sizeof *dir);
  cell_item *cells = malloc((ne ? ne : 1) * sizeof *cells);
  size_t *link = malloc((ne ? ne : 1) * sizeof *link), *parent = malloc((n ? n : 1) * sizeof *parent);
  unsigned char *seen = calloc(n ? n : 1, 1);
  join_cand *cand = NULL;
  size_t n_cand = 0, cap = 0, segs = in->first[base + n] - in->first[base];
  /* a chain holds every segment of the pen and a bridge per join at most */
  double *buf = malloc(8 * (segs + n + 1) * sizeof *buf);
  lw_status s = LW_OK;
  if (!pt || !dir || !cells || !link || !parent || !seen || !buf) goto nomem;
  for (size_t e = 0; e < ne; e++) {
    end_of(in, base, e, pt + 2 * e, dir + 2 * e);
    link[e] = SIZE_MAX;
  }
  for (size_t k = 0; k < n; k++) parent[k] = k;
  /* a cell and its neighbours ahead: each pair of cells once */
  static const int ahead[5][2] = {{0, 0}, {0, 1}, {1, -1}, {1, 0}, {1, 1}};
  /* A band that finds more candidates than this is taken again, a quarter as
  ** wide (any bounds give the same joins): a cluster's ends under a first
  ** reach sized by a page that an outlier widened were 8 GB of candidates.
  ** Up to 20 times a band: ends that coincide are candidates at any width. */
  const size_t budget = 8 * ne + 1024;
  int shrunk = 0;
  double origin[2];
  for (double below = -1.0, reach = first_band(pt, ne, dist, origin), next; below < dist;
       below = reach, reach = next) {
    size_t nx = 0;
    for (size_t e = 0; e < ne; e++)
      if (link[e] == SIZE_MAX)
        cells[nx++] = (cell_item){cell_of(pt[2 * e], origin[0], reach), cell_of(pt[2 * e + 1], origin[1], reach), e};
    qsort(cells, nx, sizeof *cells, by_cell);
    n_cand = 0;
    for (size_t i = 0; i < nx; i++)
      for (int k = 0; k < 5; k++) {
        size_t z, j = cell_run(cells, nx, cells[i].cx + ahead[k][0], cells[i].cy + ahead[k][1], &z);
        for (j = k ? j : i + 1; j < z; j++) {
          size_t a = cells[i].e, b = cells[j].e;
          if (a / 2 == b / 2 || (directed && DRAWN_FROM(a) == DRAWN_FROM(b))) continue;
          const double d = joinable_gap(pt, dir, a, b, below, reach, dist, cos_max);
          if (d < 0.0) continue;
          if (n_cand == budget) {
            if (shrunk < 20) goto narrower;
            goto ties;
          }
          if (n_cand == cap) {
            cap = cap ? 2 * cap : 64;
            join_cand *nc = realloc(cand, cap * sizeof *nc);
            if (!nc) goto nomem;
            cand = nc;
          }
          cand[n_cand++] = (join_cand){d, a < b ? a : b, a < b ? b : a};
        }
      }
    shrunk = 0;
    if (n_cand) qsort(cand, n_cand, sizeof *cand, by_gap);
    for (size_t c = 0; c < n_cand; c++) {
      size_t a = cand[c].a, b = cand[c].b, ra = find(parent, a / 2), rb = find(parent, b / 2);
      if (link[a] != SIZE_MAX || link[b] != SIZE_MAX || ra == rb) continue;
      link[a] = b;
      link[b] = a;
      parent[ra] = rb;
      rep->joins++;
    }
    /* the next band twice as far, or farther while the bands find few
    ** candidates (as their count grows with the reach squared: about 4 a
    ** free end at most), so that ends no turn lets join are not scanned
    ** band after band (hatching at 30 degrees: none ever is a candidate) */
    const double grow = n_cand ? sqrt(4.0 * (double)nx / (double)n_cand) : HUGE_VAL;
    next = fmin(reach * fmax(2.0, grow), dist);
    continue;
  ties:
    /* A band narrowed 20 times (to 4^-20 of its first reach) that still
    ** holds more candidates than the budget: ends that coincide, or all but
    ** (strokes from one point: 32,000 took 3 GB of candidates).  Its pairs
    ** are taken as of one distance, in the order of their ends, which is the
    ** sorted list's order among equal distances, each end's first partner
    ** found by a scan of its cells instead of a list. */
    n_cand = 0;
    shrunk = 0;
    for (size_t a = 0; a < ne; a++) {
      if (link[a] != SIZE_MAX) continue;
      const long long cx = cell_of(pt[2 * a], origin[0], reach), cy = cell_of(pt[2 * a + 1], origin[1], reach);
      size_t best = SIZE_MAX;
      const size_t ra = find(parent, a / 2);
      for (int ox = -1; ox <= 1; ox++)
        for (int oy = -1; oy <= 1; oy++) {
          size_t z, j = cell_run(cells, nx, cx + ox, cy + oy, &z);
          for (; j < z; j++) {
            const size_t b = cells[j].e;
            if (b <= a || b >= best || a / 2 == b / 2 || link[b] != SIZE_MAX ||
                (directed && DRAWN_FROM(a) == DRAWN_FROM(b)) ||
                joinable_gap(pt, dir, a, b, below, reach, dist, cos_max) < 0.0)
              continue;
            if (ra != find(parent, b / 2)) best = b;
          }
        }
      if (best == SIZE_MAX) continue;
      link[a] = best;
      link[best] = a;
      parent[ra] = find(parent, best / 2);
      rep->joins++;
    }
    next = fmin(2.0 * reach, dist);
    continue;
  narrower:
    shrunk++;
    next = fmax(below, 0.0) + 0.25 * (reach - fmax(below, 0.0));
    reach = below; /* (the loop's step keeps below where it was) */
  }
  /* every chain is open (no cycles), so it is walked from a free end;
  ** directed, from the one its first path is drawn from (output.order =
  ** none: a signed field's lines were drawn against it) */
  for (size_t p = 0; p < n; p++) {
    const size_t from = 2 * p + in->reversed[base + p];
    if (seen[p] || (link[2 * p] != SIZE_MAX && link[2 * p + 1] != SIZE_MAX) || (directed && link[from] != SIZE_MAX))
      continue;
    size_t e_in = directed ? from : link[2 * p] == SIZE_MAX ? 2 * p : 2 * p + 1, nb = 0, q = p;
    for (;;) {
      seen[q] = 1;
      append_piece(in, base + q, (int)(e_in & 1), buf, &nb);
      size_t e_out = e_in ^ 1, next = link[e_out];
      if (next == SIZE_MAX) break;
      const double *a = pt + 2 * e_out, *z = pt + 2 * next, *ta = dir + 2 * e_out, *tz = dir + 2 * next;
      double g = hypot(z[0] - a[0], z[1] - a[1]);
      if (g > 0) {
        /* along the tangents out of the one stroke and into the other */
        double *o = buf + 8 * nb++;
        o[0] = a[0];
        o[1] = a[1];
        o[2] = a[0] + ta[0] * g / 3;
        o[3] = a[1] + ta[1] * g / 3;
        o[4] = z[0] + tz[0] * g / 3;
        o[5] = z[1] + tz[1] * g / 3;
        o[6] = z[0];
        o[7] = z[1];
      }
      q = next / 2;
      e_in = next;
    }
    if ((s = lw_strokes_add(out, pen, in->src[base + p], in->part[base + p], 0, buf, nb, err))) goto done;
  }
  goto done;
nomem:
  s = lw_error_set(err, LW_ENOMEM, "out of memory joining %zu paths", n);
done:
  free(pt);
  free(dir);
  free(cells);
  free(link);
  free(parent);
  free(seen);
  free(cand);
  free(buf);
  return s;
#undef DRAWN_FROM
}

lw_strokes *lw_strokes_join(const lw_strokes *in, const double *dist, double angle, int directed,
                            lw_strokes_report *rep, lw_error *err)
{
  lw_strokes *out = lw_strokes_new(in->n_pens, err);
  if (!out) return NULL;
  /* the smallest cosine allowed; the 1e-12 lets an exact angle through */
  double cos_max = cos(angle) - 1e-12;
  for (int k = 0; k < in->n_pens; k++) {
    size_t a = in->pen_first[k], z = k + 1 < in->n_pens ? in->pen_first[k + 1] : in->n;
    if (!(dist[k] > 0)) {
      for (size_t j = a; j < z; j++)
        if (copy_path(out, in, j, err)) return fail(out);
    } else if (join_pen(in, k, a, z - a, dist[k], cos_max, directed, rep, out, err)) {
      return fail(out);
    }
  }
  return out;
}

/* ---- crop ---------------------------------------------------------------- */

/* Value at t of the cubic with Bernstein coefficients c[4]. */
static double bern(const double *c, double t)
{
  double u = 1.0 - t, p01 = u * c[0] + t * c[1], p12 = u * c[1] + t * c[2], p23 = u * c[2] + t * c[3];
  return u * (u * p01 + t * p12) + t * (u * p12 + t * p23);
}

/* The parameters in (0, 1) where the cubic c[4] changes sign, appended to
** t[*n].  Between the zeros of its derivative it is monotone, so each such
** stretch holds at most one, found by bisection down to adjacent doubles. */
static void sign_changes(const double *c, double *t, size_t *n)
{
  double d0 = c[1] - c[0], d1 = c[2] - c[1], d2 = c[3] - c[2];
  double r[2], br[4];
  int nr = gsl_poly_solve_quadratic(d0 - 2 * d1 + d2, 2 * (d1 - d0), d0, &r[0], &r[1]);
  size_t nb = 0;
  br[nb++] = 0.0;
  for (int k = 0; k < nr; k++)
    if (r[k] > br[nb - 1] && r[k] < 1.0) br[nb++] = r[k];
  br[nb++] = 1.0;
  for (size_t k = 0; k + 1 < nb; k++) {
    double lo = br[k], hi = br[k + 1], flo = bern(c, lo), fhi = bern(c, hi);
    if (flo == 0.0) {
      if (lo > 0.0) t[(*n)++] = lo;
      continue;
    }
    if (!((flo < 0 && fhi > 0) || (flo > 0 && fhi < 0))) continue;
    for (;;) {
      double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      double fm = bern(c, mid);
      if (fm == 0.0) {
        lo = hi = mid;
        break;
      }
      if ((fm < 0) == (flo < 0)) lo = mid, flo = fm;
      else hi = mid;
    }
    t[(*n)++] = 0.5 * (lo + hi);
  }
}

static int cmp_double(const void *pa, const void *pb)
{
  double a = *(const double *)pa, b = *(const double *)pb;
  return (a > b) - (a < b);
}

typedef struct {
  double x0, y0, x1, y1;
} rect;

static int inside(const rect *r, const double *xy)
{
  return xy[0] >= r->x0 && xy[0] <= r->x1 && xy[1] >= r->y0 && xy[1] <= r->y1;
}

/* The stretches [t0, t1] of segment b inside r, merged where they touch,
** into run[2 * k], run[2 * k + 1]; returns their number; *whole = 1 when
** nothing of it is outside. */
static size_t inside_runs(const double *b, const rect *r, double *run, int *whole)
{
  double t[16], c[4];
  size_t n = 0;
  const double edge[4] = {r->x0, r->x1, r->y0, r->y1};
  for (int e = 0; e < 4; e++) {
    int axis = e / 2;
    for (int k = 0; k < 4; k++) c[k] = b[2 * k + axis] - edge[e];
    sign_changes(c, t + 1, &n);
  }
  /* t[0] = 0, the crossings, t[n + 1] = 1 */
  qsort(t + 1, n, sizeof *t, cmp_double);
  t[0] = 0.0;
  t[n + 1] = 1.0;
  size_t nr = 0;
  *whole = 1;
  for (size_t k = 0; k <= n; k++) {
    if (!(t[k + 1] > t[k])) continue;
    double xy[2];
    lw_bezier_eval(b, 0.5 * (t[k] + t[k + 1]), xy);
    if (!inside(r, xy)) {
      *whole = 0;
      continue;
    }
    if (nr && run[2 * nr - 1] == t[k]) run[2 * nr - 1] = t[k + 1];
    else {
      run[2 * nr] = t[k];
      run[2 * nr + 1] = t[k + 1];
      nr++;
    }
  }
  return nr;
}

static void clamp_point(const rect *r, double *xy)
{
  xy[0] = fmin(fmax(xy[0], r->x0), r->x1);
  xy[1] = fmin(fmax(xy[1], r->y0), r->y1);
}

/* Ends the piece in buf[0 .. nb) as a path of out: its ends clamped into r. */
static lw_status flush_piece(lw_strokes *out, const lw_strokes *in, size_t k, const rect *r, double *buf,
                             size_t nb, unsigned *part, lw_error *err)
{
  if (!nb) return LW_OK;
  clamp_point(r, buf);
  clamp_point(r, buf + 8 * (nb - 1) + 6);
  return lw_strokes_add(out, pen_of(in, k), in->src[k], in->part[k] + (*part)++, in->reversed[k], buf, nb, err);
}

/* Crops path k of in into out. */
static lw_status crop_path(const lw_strokes *in, size_t k, const rect *r, double *buf, lw_strokes *out,
                           lw_strokes_report *rep, lw_error *err)
{
  size_t a = in->first[k], z = in->first[k + 1], nb = 0;
  unsigned part = 0;
  int all = 1, cont = 0;
  lw_status s;
  for (size_t m = a; m < z; m++) {
    const double *b = in->b + 8 * m;
    double run[2 * 17];
    int whole;
    size_t nr = inside_runs(b, r, run, &whole);
    all &= whole;
    for (size_t j = 0; j < nr; j++) {
      /* a run from t = 0 continues the piece that reached t = 1 before */
      if (!(cont && run[2 * j] == 0.0)) {
        if ((s = flush_piece(out, in, k, r, buf, nb, &part, err))) return s;
        nb = 0;
      }
      if (run[2 * j] == 0.0 && run[2 * j + 1] == 1.0) memcpy(buf + 8 * nb, b, 8 * sizeof *buf);
      else bezier_sub(b, run[2 * j], run[2 * j + 1], buf + 8 * nb);
      nb++;
      cont = run[2 * j + 1] == 1.0;
    }
    if (!nr) cont = 0;
  }
  if (all) return copy_path(out, in, k, err);
  rep->cut += part || nb ? 1 : 0;
  rep->outside += part || nb ? 0 : 1;
  return flush_piece(out, in, k, r, buf, nb, &part, err);
}

lw_strokes *lw_strokes_crop(const lw_strokes *in, double x0, double y0, double x1, double y1,
                            lw_strokes_report *rep, lw_error *err)
{
  if (!(x0 <= x1 && y0 <= y1)) {
    lw_error_set(err, LW_EINPUT, "crop rectangle [%g, %g] x [%g, %g] is empty", x0, x1, y0, y1);
    return NULL;
  }
  lw_strokes *out = lw_strokes_new(in->n_pens, err);
  size_t longest = 0;
  for (size_t k = 0; k < in->n; k++)
    if (in->first[k + 1] - in->first[k] > longest) longest = in->first[k + 1] - in->first[k];
  double *buf = malloc(8 * (longest ? longest : 1) * sizeof *buf);
  if (!out || !buf) {
    free(buf);
    if (out) lw_error_set(err, LW_ENOMEM, "out of memory cropping %zu paths", in->n);
    return fail(out);
  }
  rect r = {x0, y0, x1, y1};
  for (size_t k = 0; k < in->n; k++)
    if (crop_path(in, k, &r, buf, out, rep, err)) {
      free(buf);
      return fail(out);
    }
  free(buf);
  return out;
}

/* ---- drop ---------------------------------------------------------------- */

lw_strokes *lw_strokes_drop(const lw_strokes *in, const double *min_length, lw_strokes_report *rep, lw_error *err)
{
  lw_strokes *out = lw_strokes_new(in->n_pens, err);
  if (!out) return NULL;
  for (int q = 0; q < in->n_pens; q++)
    for (size_t k = in->pen_first[q]; k < in->pen_first[q + 1]; k++) {
      if (lw_strokes_length(in, k) < fmax(min_length[q], LW_STROKES_DOT_MM)) {
        rep->dropped++;
        continue;
      }
      if (copy_path(out, in, k, err)) return fail(out);
    }
  return out;
}

/* ---- order --------------------------------------------------------------- */

lw_status lw_strokes_order(lw_strokes *s, lw_plot_order order, double hx, double hy, int back, lw_strokes_report *rep,
                           lw_error *err)
{
  size_t n = s->n;
  lw_order_path *path = malloc((n ? n : 1) * sizeof *path);
  size_t *tour = malloc((n ? n : 1) * sizeof *tour);
  unsigned char *rev = malloc(n ? n : 1);
  lw_strokes *out = lw_strokes_new(s->n_pens, err);
  lw_status st = LW_OK;
  if (!out) {
    st = err ? err->code : LW_ENOMEM;
    goto done;
  }
  if (!path || !tour || !rev) {
    st = lw_error_set(err, LW_ENOMEM, "out of memory ordering %zu paths", n);
    goto done;
  }
  rep->travel_before = rep->travel_after = 0.0;
  /* the exits of the last pen that drew, before and after ordering: the
  ** pen goes home from there to be changed (an empty pen is skipped) */
  double was[2][2] = {{0.0, 0.0}, {0.0, 0.0}};
  int drew = 0;
  for (int k = 0; k < s->n_pens; k++) {
    size_t a = s->pen_first[k], z = k + 1 < s->n_pens ? s->pen_first[k + 1] : n;
    if (a == z) continue;
    for (size_t j = a; j < z; j++) {
      const double *b0 = s->b + 8 * s->first[j], *b1 = s->b + 8 * (s->first[j + 1] - 1);
      path[j - a] = (lw_order_path){b0[0], b0[1], b1[6], b1[7]};
    }
    double before, after;
    if ((st = lw_plot_order_paths(path, z - a, order, hx, hy, tour, rev, &before, &after, err))) goto done;
    if (drew) {
      before += hypot(was[0][0] - hx, was[0][1] - hy);
      after += hypot(was[1][0] - hx, was[1][1] - hy);
    }
    rep->travel_before += before;
    rep->travel_after += after;
    const lw_order_path *last = &path[z - a - 1], *end = &path[tour[z - a - 1]];
    was[0][0] = last->x1, was[0][1] = last->y1;
    was[1][0] = rev[z - a - 1] ? end->x0 : end->x1, was[1][1] = rev[z - a - 1] ? end->y0 : end->y1;
    drew = 1;
    for (size_t j = 0; j < z - a; j++) {
      size_t q = a + tour[j];
      if ((st = lw_strokes_add(out, k, s->src[q], s->part[q], rev[j], s->b + 8 * s->first[q],
                               s->first[q + 1] - s->first[q], err)))
        goto done;
    }
  }
  if (drew && back) {
    rep->travel_before += hypot(was[0][0] - hx, was[0][1] - hy);
    rep->travel_after += hypot(was[1][0] - hx, was[1][1] - hy);
  }
  /* the ordered drawing takes the place of the old one */
  lw_strokes tmp = *s;
  *s = *out;
  *out = tmp;
done:
  lw_strokes_free(out);
  free(path);
  free(tour);
  free(rev);
  return st;
}

/* ---- the whole post-pass --------------------------------------------------- */

lw_strokes *lw_strokes_prepare(const lw_splines *sp, const lw_plot *plot, const lw_strokes_options *o,
                               lw_strokes_report *rep, lw_error *err)
{
  memset(rep, 0, sizeof *rep);
  lw_strokes *s = lw_strokes_from_plot(sp, plot, err), *t;
  if (!s) return NULL;
  rep->lifts_before = s->n;
  int join = 0;
  for (int k = 0; k < s->n_pens; k++) join |= o->join_dist[k] > 0;
  if (join) {
    t = lw_strokes_join(s, o->join_dist, o->join_angle, o->order == LW_PLOT_ORDER_NONE, rep, err);
    lw_strokes_free(s);
    if (!(s = t)) return NULL;
  }
  if (o->crop) {
    t = lw_strokes_crop(s, o->x0, o->y0, o->x1, o->y1, rep, err);
    lw_strokes_free(s);
    if (!(s = t)) return NULL;
  }
  t = lw_strokes_drop(s, o->min_length, rep, err);
  lw_strokes_free(s);
  if (!(s = t)) return NULL;
  if (lw_strokes_order(s, o->order, o->home_x, o->home_y, o->home_back, rep, err)) return fail(s);
  rep->lifts_after = s->n;
  return s;
}

double lw_strokes_total_length(const lw_strokes *s)
{
  double sum = 0.0;
  for (size_t k = 0; k < s->n; k++) sum += lw_strokes_length(s, k);
  return sum;
}

double lw_strokes_time(const lw_strokes *s, double travel, double speed_down, double speed_up, double lift_time)
{
  return lw_strokes_total_length(s) / speed_down + travel / speed_up + (double)s->n * lift_time;
}
