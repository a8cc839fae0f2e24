/*
** init.c -- initial placement, the number of splines, stream seeds (init.h).
**
** Where a spline goes: its centre is drawn uniformly over the page, or, when
** the scene has a picture, with probability proportional to the darkness
** 1 - tone of the pixel it falls in (a pixel is chosen from the cumulative
** darkness of the rows and then along its row, the point uniformly inside
** it).  Its shape: straight at a random angle, or, when the field term is
** on, the streamline of the field through the centre, traced both ways by
** the midpoint rule in steps of segment_length with the node vectors along
** the field, so the splines start where the energy wants them.  Where the
** streamline turns too fast for its segments to be regular (lw_segment_allowed:
** near a vortex's centre, on short waves) the spline is straight along the
** field at its centre instead, so no placement is ever forbidden for its
** shape.  A draw whose spline leaves the boundary is drawn again.  With
** layers (layers.h) a spline's darkness is its layer's target's and its
** field its layer's.
**
** With energy.min_spacing d the draws also keep apart: a spline whose
** curves come within d of those of one placed before (pair samples within
** d, or else lw_bezier_near2: lines cross between samples) is drawn again,
** up to SPACING_TRIES fitting draws.  The spacing rule refuses only moves
** that add contacts (model.c), so what the placement leaves crowded --
** lines crossing where the field is noisy, as on photographs -- would stay.
** With a fixed count the draw with the fewest crowded samples is kept
** after that; where the annealer chooses the count the draw whose longest
** run of clear segments is longest is cut to that run (or left out if it
** has none), and births and grows fill the room later.
*/
#include "linewise/init.h"

#include "linewise/model.h"
#include "linewise/spacing.h"

#include <gsl/gsl_math.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Version 2: a Weyl step of the golden ratio's 2^32 fraction over the
** streams, then murmur3's 32-bit finaliser, a bijection: one stream's seeds
** never share a generator seed, and two streams' only where the seeds are
** millions apart (docs/NUMERICS.md, "Random numbers").  Version 1, runs
** begun before 2026-12-06: SplitMix64's low 32 bits, the lowest set, 2^31
** values reached at random, so seeds 89483 and 106945 drew the same numbers. */
unsigned long lw_stream_seed(unsigned long seed, unsigned long stream, int version)
{
  if (version == 1) {
    uint64_t z = (uint64_t)seed * 0x9E3779B97F4A7C15ULL + (uint64_t)stream + 1;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z ^= z >> 31;
    return (unsigned long)(z & 0xFFFFFFFFu) | 1u;
  }
  uint32_t x = (uint32_t)seed + ((uint32_t)stream + 1u) * 0x9E3779B9u;
  x ^= x >> 16;
  x *= 0x85EBCA6Bu;
  x ^= x >> 13;
  x *= 0xC2B2AE35u;
  x ^= x >> 16;
  return x;
}

/* 1 if every segment is regular for the scene. */
static int regular(const lw_scene *sc, const lw_node *nd, size_t segments)
{
  lw_samples s;
  for (size_t m = 0; m < segments; m++) {
    lw_segment_sample(&sc->quad, &nd[m], &nd[m + 1], &s);
    if (!lw_segment_allowed(sc, &nd[m], &nd[m + 1], s.length)) return 0;
  }
  return 1;
}

/* Spline nodes on the straight line through (cx, cy) along (ux, uy), with
** uniform speed (every segment regular). */
static void straight(lw_node *nd, size_t segments, double segment_length, double cx, double cy, double ux,
                     double uy)
{
  const double L = segment_length * (double)segments;
  for (size_t k = 0; k <= segments; k++) {
    double u = ((double)k / (double)segments - 0.5) * L;
    nd[k] = (lw_node){cx + u * ux, cy + u * uy, segment_length * ux / 3.0, segment_length * uy / 3.0};
  }
}

/* 1 if the spline lies inside the frame: with the boundary term on, as the
** term allows it (its clearance too), else at its samples and nodes. */
static int fits(const lw_scene *sc, const lw_node *nd, size_t segments)
{
  lw_samples s;
  for (size_t m = 0; m < segments; m++) {
    lw_segment_sample(&sc->quad, &nd[m], &nd[m + 1], &s);
    if (sc->on[LW_TERM_BOUNDARY] && !isfinite(lw_term_boundary(&s, &sc->quad, &sc->boundary))) return 0;
    for (int q = 0; q < s.n; q++)
      if (!(lw_boundary_distance(&sc->boundary, s.x[q], s.y[q]) < 0)) return 0;
  }
  for (size_t k = 0; k <= segments; k++)
    if (!(lw_boundary_distance(&sc->boundary, nd[k].px, nd[k].py) < 0)) return 0;
  return 1;
}

double *lw_init_darkness(const lw_image *img)
{
  if (!img) return NULL;
  double *cum = malloc(((size_t)img->height + 1) * sizeof *cum);
  if (!cum) return NULL;
  cum[0] = 0.0;
  for (int j = 0; j < img->height; j++) {
    const float *t = img->tone + (size_t)j * (size_t)img->width;
    double s = 0.0;
    for (int i = 0; i < img->width; i++) s += 1.0 - t[i];
    cum[j + 1] = cum[j] + s;
  }
  return cum;
}

/* img is the picture or a layer's target, placed alike. */
void lw_init_dark_point(const lw_scene *sc, const lw_image *img, const double *cum, gsl_rng *rng, double *x,
                        double *y)
{
  double r = gsl_rng_uniform(rng) * cum[img->height];
  int lo = 0, hi = img->height - 1;
  while (lo < hi) { /* the last row j with cum[j] <= r */
    int mid = (lo + hi + 1) / 2;
    if (cum[mid] <= r) lo = mid;
    else hi = mid - 1;
  }
  /* walk the row; the last pixel with any darkness catches rounding */
  const float *t = img->tone + (size_t)lo * (size_t)img->width;
  double rest = r - cum[lo];
  int pick = -1;
  for (int i = 0; i < img->width; i++) {
    double d = 1.0 - t[i];
    if (d <= 0) continue;
    pick = i;
    if (rest < d) break;
    rest -= d;
  }
  if (pick < 0) pick = img->width / 2; /* a row of no darkness: cannot be drawn */
  const lw_image_place *pl = &sc->image_place;
  *x = pl->x0 + (pick + gsl_rng_uniform(rng)) * pl->pixel;
  *y = pl->y0 + (lo + gsl_rng_uniform(rng)) * pl->pixel;
}

/* The field's direction at (x, y) turned to agree with (dx, dy); (dx, dy)
** itself where the field vanishes. */
static void along(const lw_field *f, double x, double y, double dx, double dy, double *ux, double *uy)
{
  double vx, vy;
  lw_field_eval(f, x, y, &vx, &vy);
  double m = sqrt(vx * vx + vy * vy);
  if (!(m > 1e-12)) {
    *ux = dx;
    *uy = dy;
    return;
  }
  double s = vx * dx + vy * dy < 0 ? -1.0 / m : 1.0 / m;
  *ux = vx * s;
  *uy = vy * s;
}

/* The streamline through (cx, cy) leaving along (ux, uy): node segments/2
** sits at the centre, the others follow in steps of h forward and backward. */
static void trace(const lw_field *f, lw_node *nd, size_t segments, double h, double cx, double cy, double ux,
                  double uy)
{
  const size_t kc = segments / 2;
  nd[kc] = (lw_node){cx, cy, h * ux / 3.0, h * uy / 3.0};
  for (int dir = 1; dir >= -1; dir -= 2) {
    double px = cx, py = cy, dx = dir * ux, dy = dir * uy;
    for (long k = (long)kc + dir; k >= 0 && k <= (long)segments; k += dir) {
      double ax, ay, bx, by;
      along(f, px, py, dx, dy, &ax, &ay);
      along(f, px + 0.5 * h * ax, py + 0.5 * h * ay, ax, ay, &bx, &by);
      px += h * bx;
      py += h * by;
      along(f, px, py, bx, by, &dx, &dy);
      /* node vectors point from node 0 toward node n whichever way we walk */
      nd[k] = (lw_node){px, py, dir * h * dx / 3.0, dir * h * dy / 3.0};
    }
  }
}

/* Fitting draws per spline while looking for room; past them the least
** crowded is kept, so a page fuller than random packing allows still fills. */
#define SPACING_TRIES 64

/* The splines placed so far: their pair samples in buckets of side >= d (a
** chained hash over the page's cells, head per cell, next per sample), and
** their segments' curves listed in the coarser cells their control boxes
** meet. */
typedef struct {
  double d2, side, x0, y0;
  long nx, ny;
  int32_t *head, *next;
  double *x, *y;
  uint8_t *layer; /* each sample's layer, when lines keep apart within layers only; else NULL */
  size_t n, cap;
  /* the placed segments' curves, in cells of side cside listing each segment
  ** whose control box meets them */
  double cside;
  long cnx, cny;
  int32_t *chead, *cnext, *centry; /* per cell, per entry; centry: the entry's segment */
  size_t cn, ccap;
  double *bez;         /* 8 a segment: its control points */
  uint8_t *seg_layer;  /* each segment's layer, with layer */
  uint32_t *seen;      /* per segment: the query that last met it */
  uint32_t query;
  size_t nseg, capseg;
} placed_lines;

static void placed_free(placed_lines *ps)
{
  free(ps->head);
  free(ps->next);
  free(ps->x);
  free(ps->y);
  free(ps->layer);
  free(ps->chead);
  free(ps->cnext);
  free(ps->centry);
  free(ps->bez);
  free(ps->seg_layer);
  free(ps->seen);
}

static int placed_init(placed_lines *ps, const lw_scene *sc, double d, size_t cap, double segment_length,
                       int by_layer)
{
  *ps = (placed_lines){.d2 = d * d, .cap = cap};
  double w = sc->width + 2 * d, h = sc->height + 2 * d;
  /* cells at least d wide, and not many more than samples (a wide page) */
  ps->side = fmax(d, sqrt(w * h / (4.0 * (double)cap + 1024.0)));
  ps->nx = (long)ceil(w / ps->side);
  ps->ny = (long)ceil(h / ps->side);
  ps->x0 = -d;
  ps->y0 = -d;
  if (cap > INT32_MAX) return 0;
  ps->head = malloc((size_t)(ps->nx * ps->ny) * sizeof *ps->head);
  ps->next = malloc((cap ? cap : 1) * sizeof *ps->next);
  ps->x = malloc((cap ? cap : 1) * sizeof *ps->x);
  ps->y = malloc((cap ? cap : 1) * sizeof *ps->y);
  ps->layer = by_layer ? malloc((cap ? cap : 1) * sizeof *ps->layer) : NULL;
  if (!ps->head || !ps->next || !ps->x || !ps->y || (by_layer && !ps->layer)) return 0;
  for (long c = 0; c < ps->nx * ps->ny; c++) ps->head[c] = -1;
  /* a segment's control box spans a few of these cells */
  const size_t segs = cap / (size_t)sc->pair_quad.n;
  ps->capseg = segs;
  ps->cside = fmax(ps->side, fmax(segment_length, sqrt(w * h / ((double)segs + 256.0))));
  ps->cnx = (long)ceil(w / ps->cside);
  ps->cny = (long)ceil(h / ps->cside);
  ps->ccap = 4 * (segs ? segs : 1);
  ps->chead = malloc((size_t)(ps->cnx * ps->cny) * sizeof *ps->chead);
  ps->cnext = malloc(ps->ccap * sizeof *ps->cnext);
  ps->centry = malloc(ps->ccap * sizeof *ps->centry);
  ps->bez = malloc(8 * (segs ? segs : 1) * sizeof *ps->bez);
  ps->seg_layer = by_layer ? malloc((segs ? segs : 1) * sizeof *ps->seg_layer) : NULL;
  ps->seen = malloc((segs ? segs : 1) * sizeof *ps->seen);
  if (!ps->chead || !ps->cnext || !ps->centry || !ps->bez || (by_layer && !ps->seg_layer) || !ps->seen) return 0;
  for (long c = 0; c < ps->cnx * ps->cny; c++) ps->chead[c] = -1;
  return 1;
}

/* The cells of side cside that box {x0, y0, x1, y1} meets, clamped: c = {first
** column, first row, last column, last row}. */
static void curve_cells(const placed_lines *ps, const double box[4], long c[4])
{
  const double lo[2] = {box[0], box[1]}, hi[2] = {box[2], box[3]};
  const long n[2] = {ps->cnx, ps->cny};
  const double o[2] = {ps->x0, ps->y0};
  for (int k = 0; k < 2; k++) {
    double a = floor((lo[k] - o[k]) / ps->cside), b = floor((hi[k] - o[k]) / ps->cside);
    c[k] = a < 0 ? 0 : (a >= (double)n[k] ? n[k] - 1 : (long)a);
    c[k + 2] = b < 0 ? 0 : (b >= (double)n[k] ? n[k] - 1 : (long)b);
  }
}

/* How many placed segments (of the layer) come within d of the curve b. */
static size_t curve_contacts(placed_lines *ps, const double b[8], double d, int layer)
{
  double box[4];
  lw_bezier_box(b, d, box);
  long c[4];
  curve_cells(ps, box, c);
  if (++ps->query == 0) { /* wrapped: forget every earlier query */
    memset(ps->seen, 0, ps->nseg * sizeof *ps->seen);
    ps->query = 1;
  }
  const uint32_t q = ps->query;
  size_t count = 0;
  for (long y = c[1]; y <= c[3]; y++)
    for (long x = c[0]; x <= c[2]; x++)
      for (int32_t e = ps->chead[y * ps->cnx + x]; e >= 0; e = ps->cnext[e]) {
        const int32_t g = ps->centry[e];
        if (ps->seen[g] == q) continue;
        ps->seen[g] = q;
        if (ps->seg_layer && ps->seg_layer[g] != layer) continue;
        const double *o = ps->bez + 8 * (size_t)g;
        double ob[4];
        lw_bezier_box(o, 0.0, ob);
        if (lw_boxes_meet(box, ob)) count += lw_bezier_near2(b, o, d) < d * d;
      }
  return count;
}

/* 0 when out of memory for the cells' lists. */
static int curve_add(placed_lines *ps, const double b[8], int layer)
{
  if (ps->nseg == ps->capseg) return 1;
  const int32_t g = (int32_t)ps->nseg++;
  memcpy(ps->bez + 8 * (size_t)g, b, 8 * sizeof *b);
  if (ps->seg_layer) ps->seg_layer[g] = (uint8_t)layer;
  ps->seen[g] = 0;
  double box[4];
  lw_bezier_box(b, 0.0, box);
  long c[4];
  curve_cells(ps, box, c);
  for (long y = c[1]; y <= c[3]; y++)
    for (long x = c[0]; x <= c[2]; x++) {
      if (ps->cn == ps->ccap) {
        size_t cap = 2 * ps->ccap;
        if (cap > INT32_MAX) return 0;
        int32_t *nx = realloc(ps->cnext, cap * sizeof *nx);
        if (nx) ps->cnext = nx;
        int32_t *ne = realloc(ps->centry, cap * sizeof *ne);
        if (ne) ps->centry = ne;
        if (!nx || !ne) return 0;
        ps->ccap = cap;
      }
      ps->centry[ps->cn] = g;
      ps->cnext[ps->cn] = ps->chead[y * ps->cnx + x];
      ps->chead[y * ps->cnx + x] = (int32_t)ps->cn++;
    }
  return 1;
}

/* The cell of (x, y), clamped: the boundary keeps samples on the page, and
** a clamped one is only compared with more samples, never fewer. */
static void placed_cell(const placed_lines *ps, double x, double y, long *cx, long *cy)
{
  double fx = floor((x - ps->x0) / ps->side), fy = floor((y - ps->y0) / ps->side);
  *cx = fx < 0 ? 0 : (fx >= (double)ps->nx ? ps->nx - 1 : (long)fx);
  *cy = fy < 0 ? 0 : (fy >= (double)ps->ny ? ps->ny - 1 : (long)fy);
}

/* How crowded each segment of the spline is, in per[m]: how many of its
** pair samples have a placed sample (of its layer) within d, or where none
** has, how many placed segments its curve comes within d of.  Returns the
** sum. */
static size_t placed_crowding(placed_lines *ps, const lw_scene *sc, const lw_node *nd, size_t segments,
                              int layer, size_t *per)
{
  size_t count = 0;
  lw_samples s;
  for (size_t m = 0; m < segments; m++) {
    const size_t before = count;
    lw_segment_sample(&sc->pair_quad, &nd[m], &nd[m + 1], &s);
    for (int q = 0; q < s.n; q++) {
      long cx, cy, hit = 0;
      placed_cell(ps, s.x[q], s.y[q], &cx, &cy);
      for (long y = cy > 0 ? cy - 1 : 0; y <= cy + 1 && y < ps->ny && !hit; y++)
        for (long x = cx > 0 ? cx - 1 : 0; x <= cx + 1 && x < ps->nx && !hit; x++)
          for (int32_t e = ps->head[y * ps->nx + x]; e >= 0 && !hit; e = ps->next[e]) {
            double dx = ps->x[e] - s.x[q], dy = ps->y[e] - s.y[q];
            hit = dx * dx + dy * dy < ps->d2 && (!ps->layer || ps->layer[e] == layer);
          }
      count += (size_t)hit;
    }
    if (count == before) { /* samples apart, curves perhaps not: lines crossing between samples */
      double b[8];
      lw_segment_bezier(&nd[m], &nd[m + 1], b);
      count += curve_contacts(ps, b, sqrt(ps->d2), layer);
    }
    per[m] = count - before;
  }
  return count;
}

/* The longest run of segments none of which is crowded: its length, its
** first segment in *from. */
static size_t clear_run(const size_t *per, size_t segments, size_t *from)
{
  size_t run = 0, longest = 0;
  *from = 0;
  for (size_t m = 0; m < segments; m++) {
    run = per[m] ? 0 : run + 1;
    if (run > longest) {
      longest = run;
      *from = m + 1 - run;
    }
  }
  return longest;
}

/* The placed splines cut to their clear runs (keep[2i]: first segment,
** keep[2i + 1]: segments; 0 drops the spline), each with the rest length of
** what is left, in the placement's order; each keeps the layer its index gave
** it.  NULL and err set when out of memory. */
static lw_splines *cut_to_clear_runs(const lw_scene *sc, const lw_splines *sp, const size_t *keep,
                                     double segment_length, lw_error *err)
{
  size_t n = 0, *segs = malloc((sp->n_splines ? sp->n_splines : 1) * sizeof *segs);
  if (!segs) {
    lw_error_set(err, LW_ENOMEM, "out of memory for the placement");
    return NULL;
  }
  for (size_t i = 0; i < sp->n_splines; i++)
    if (keep[2 * i + 1]) segs[n++] = keep[2 * i + 1];
  lw_splines *cut = lw_splines_new(n, segs, err);
  free(segs);
  if (!cut) return NULL;
  if (sc->layers.n && lw_splines_layers_alloc(cut) != LW_OK) {
    lw_splines_free(cut);
    lw_error_set(err, LW_ENOMEM, "out of memory for the placement");
    return NULL;
  }
  for (size_t i = 0, k = 0; i < sp->n_splines; i++) {
    const size_t m = keep[2 * i + 1];
    if (!m) continue;
    memcpy(&cut->node[cut->first[k]], &sp->node[sp->first[i] + keep[2 * i]], (m + 1) * sizeof *cut->node);
    cut->rest_length[k] = segment_length * (double)m; /* what a birth's grows would give it */
    if (cut->layer) cut->layer[k] = (uint8_t)lw_layers_of(&sc->layers, i);
    k++;
  }
  return cut;
}

/* 0 when out of memory. */
static int placed_add(placed_lines *ps, const lw_scene *sc, const lw_node *nd, size_t segments, int layer)
{
  lw_samples s;
  for (size_t m = 0; m < segments; m++) {
    double b[8];
    lw_segment_bezier(&nd[m], &nd[m + 1], b);
    if (!curve_add(ps, b, layer)) return 0;
    lw_segment_sample(&sc->pair_quad, &nd[m], &nd[m + 1], &s);
    for (int q = 0; q < s.n && ps->n < ps->cap; q++) {
      long cx, cy;
      placed_cell(ps, s.x[q], s.y[q], &cx, &cy);
      ps->x[ps->n] = s.x[q];
      ps->y[ps->n] = s.y[q];
      if (ps->layer) ps->layer[ps->n] = (uint8_t)layer;
      ps->next[ps->n] = ps->head[cy * ps->nx + cx];
      ps->head[cy * ps->nx + cx] = (int32_t)ps->n;
      ps->n++;
    }
  }
  return 1;
}

lw_splines *lw_init_random(const lw_scene *sc, size_t n, size_t segments, double segment_length,
                           gsl_rng *rng, lw_error *err)
{
  size_t *segs = calloc(n ? n : 1, sizeof *segs);
  if (!segs) {
    lw_error_set(err, LW_ENOMEM, "out of memory for %zu splines", n);
    return NULL;
  }
  for (size_t i = 0; i < n; i++) segs[i] = segments;
  lw_splines *sp = lw_splines_new(n, segs, err);
  free(segs);
  if (!sp) return NULL;
  /* with layers, each spline is placed in its layer's ink along its
  ** layer's field (layers.h); a layer's cum follows the picture's */
  const int by_layer = sc->layers.n && sc->layer[0].target, nl = by_layer ? sc->layers.n : 1;
  double *cums[LW_LAYERS_MAX] = {NULL};
  int nomem = 0;
  for (int k = 0; k < nl; k++) {
    cums[k] = lw_init_darkness(by_layer ? sc->layer[k].target : sc->image);
    nomem |= sc->image && !cums[k];
  }
  const int spaced = sc->min_spacing > 0.0 && sc->pair_quad.n > 0;
  placed_lines placed = {0};
  if (spaced)
    nomem |= !placed_init(&placed, sc, sc->min_spacing, n * segments * (size_t)sc->pair_quad.n, segment_length,
                          lw_layers_planes(&sc->layers) > 1);
  /* where the annealer chooses the count, a spline that finds no clear room
  ** is cut to the longest clear run of its best draw, or left out: the
  ** spacing rule would keep every contact it starts with (model.c), and
  ** births and grows fill what the cut leaves */
  const int cut = spaced && sc->transdim;
  lw_node *best = spaced ? malloc((segments + 1) * sizeof *best) : NULL;
  size_t *per = spaced ? malloc(segments * sizeof *per) : NULL;
  size_t *keep = cut ? malloc(2 * (n ? n : 1) * sizeof *keep) : NULL;
  nomem |= (spaced && (!best || !per)) || (cut && !keep);
  if (nomem) {
    for (int k = 0; k < nl; k++) free(cums[k]);
    placed_free(&placed);
    free(best);
    free(per);
    free(keep);
    lw_splines_free(sp);
    lw_error_set(err, LW_ENOMEM, "out of memory for the placement");
    return NULL;
  }
  const int follow = sc->on[LW_TERM_FIELD];
  const double L = segment_length * (double)segments;
  const int tries = 10000;
  size_t done = 0; /* splines placed */
  for (size_t i = 0; i < n; i++) {
    lw_node *nd = &sp->node[sp->first[i]];
    const int layer = sc->layers.n ? lw_layers_of(&sc->layers, i) : 0;
    const lw_image *img = by_layer ? sc->layer[layer].target : sc->image;
    const lw_field *field = sc->layers.n ? &sc->layer[layer].field : &sc->field;
    const double *cum = cums[by_layer ? layer : 0];
    /* a white picture has nothing to draw toward: uniform, as without one */
    const int weighted = cum && cum[img->height] > 0;
    int t, fitting = 0;
    size_t least = SIZE_MAX, longest = 0, from = 0;
    for (t = 0; t < tries; t++) {
      double cx, cy;
      if (weighted) lw_init_dark_point(sc, img, cum, rng, &cx, &cy);
      else {
        cx = gsl_rng_uniform(rng) * sc->width;
        cy = gsl_rng_uniform(rng) * sc->height;
      }
      double a = 2.0 * M_PI * gsl_rng_uniform(rng), ux = cos(a), uy = sin(a);
      if (follow) {
        along(field, cx, cy, ux, uy, &ux, &uy);
        if (!sc->field_axial) { /* a signed field is followed forward */
          double vx, vy;
          lw_field_eval(field, cx, cy, &vx, &vy);
          if (vx * ux + vy * uy < 0) {
            ux = -ux;
            uy = -uy;
          }
        }
        trace(field, nd, segments, segment_length, cx, cy, ux, uy);
        if (!regular(sc, nd, segments)) straight(nd, segments, segment_length, cx, cy, ux, uy);
      } else {
        straight(nd, segments, segment_length, cx, cy, ux, uy);
      }
      if (!fits(sc, nd, segments)) continue;
      if (!spaced) break;
      size_t crowded = placed_crowding(&placed, sc, nd, segments, layer, per), at;
      size_t run = cut ? clear_run(per, segments, &at) : 0;
      if (run > longest || (run == longest && crowded < least)) {
        least = crowded;
        longest = run;
        from = cut ? at : 0;
        memcpy(best, nd, (segments + 1) * sizeof *best);
      }
      if (crowded == 0 || ++fitting == SPACING_TRIES) break;
    }
    if (spaced && least != SIZE_MAX) {
      memcpy(nd, best, (segments + 1) * sizeof *best);
      const size_t kept = cut ? longest : segments;
      if (cut) {
        keep[2 * i] = from;
        keep[2 * i + 1] = kept;
      }
      if (!placed_add(&placed, sc, nd + from, kept, layer)) {
        lw_error_set(err, LW_ENOMEM, "out of memory for the placement");
        break;
      }
      t = 0; /* placed, if never in room */
    }
    if (t == tries) {
      char clear[128] = "";
      if (sc->boundary.clearance > 0.0)
        snprintf(clear, sizeof clear, ", or lower energy.boundary_clearance (%g length elements, %g mm here, from "
                 "every edge)", sc->boundary.clearance, sc->boundary.clearance * segment_length / (double)sc->quad.n);
      lw_error_set(err, LW_EINPUT,
                   "[init]: spline %zu of length %g mm did not fit inside the boundary in %d tries "
                   "(shorten init.segment_length or init.segments%s)", i, L, tries, clear);
      break;
    }
    sp->rest_length[i] = L;
    done++;
  }
  for (int k = 0; k < nl; k++) free(cums[k]);
  placed_free(&placed);
  free(best);
  free(per);
  int whole = done == n;
  for (size_t i = 0; cut && whole && i < n; i++) whole = keep[2 * i + 1] == segments;
  if (done < n) {
    lw_splines_free(sp);
    sp = NULL;
  } else if (!whole) {
    lw_splines *c = cut_to_clear_runs(sc, sp, keep, segment_length, err);
    lw_splines_free(sp);
    sp = c;
  } else if (sc->layers.n) {
    /* each keeps the layer it was placed in: the renumbering along the
    ** page (sys_splines.c) reorders them, and a layer taken from the new
    ** index put most lines into another pen's ink, across their own pen's */
    if (lw_splines_layers_alloc(sp) != LW_OK) {
      lw_splines_free(sp);
      sp = NULL;
      lw_error_set(err, LW_ENOMEM, "out of memory for the placement");
    } else {
      for (size_t i = 0; i < n; i++) sp->layer[i] = (uint8_t)lw_layers_of(&sc->layers, i);
    }
  }
  free(keep);
  return sp;
}

/* The darkness of img (placed as the picture) over the inside, mm^2. */
static double ink_area_of(const lw_scene *sc, const lw_image *img)
{
  const lw_boundary *b = &sc->boundary;
  double sum = 0.0;
  const lw_image_place *pl = &sc->image_place;
  for (int j = 0; j < img->height; j++)
    for (int i = 0; i < img->width; i++) {
      double x = pl->x0 + (i + 0.5) * pl->pixel, y = pl->y0 + (j + 0.5) * pl->pixel;
      if (lw_boundary_distance(b, x, y) < 0) sum += 1.0 - img->tone[(size_t)j * (size_t)img->width + (size_t)i];
    }
  return sum * pl->pixel * pl->pixel;
}

double lw_init_ink_area(const lw_scene *sc)
{
  const lw_boundary *b = &sc->boundary;
  double sum = 0.0;
  if (sc->image) return ink_area_of(sc, sc->image);
  /* no picture: the area inside, counted on cells of at most 1/1024 of the
  ** page's longer side (error below the perimeter times half a cell) */
  double cell = fmax(sc->width, sc->height) / 1024.0;
  int nx = (int)ceil(sc->width / cell), ny = (int)ceil(sc->height / cell);
  double hx = sc->width / nx, hy = sc->height / ny;
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++)
      if (lw_boundary_distance(b, (i + 0.5) * hx, (j + 0.5) * hy) < 0) sum += 1.0;
  return sum * hx * hy;
}

lw_status lw_init_count(const lw_scene *sc, const lw_params *p, size_t *n, lw_error *err)
{
  /* The placed segments' pair samples within LW_PAIR_GAP_SHARE cutoffs, as
  ** every segment's must stay (lw_segment_allowed): about two length
  ** elements, within which the kink of (1/r - 1/rc)+ also falls between the
  ** samples of most pairs and the pair energy is off by more than 1e-2
  ** (docs/ACCURACY.md). */
  const double gap = sc->pair_quad.spacing * p->segment_length;
  if (sc->on[LW_TERM_PAIR] && p->pair_cutoff > 0.0 && gap > LW_PAIR_GAP_SHARE * p->pair_cutoff) {
    char at[LW_PATH_MAX + 32];
    lw_params_origin(p, lw_params_find("energy", "pair_cutoff"), at, sizeof at);
    return lw_error_set(err, LW_EINPUT,
                        "%s: key 'energy.pair_cutoff': expected at least %.4g mm (about two length elements: "
                        "the placed segments' pair samples lie up to %.4g mm apart, and a segment's must stay "
                        "within %g cutoffs), got %g mm; raise it, or the pair nodes (energy.pair_quadrature)",
                        at, gap / LW_PAIR_GAP_SHARE, gap, LW_PAIR_GAP_SHARE, p->pair_cutoff);
  }
  const lw_param_def *cov = lw_params_find("init", "coverage"), *spl = lw_params_find("init", "splines");
  char where[LW_PATH_MAX + 32];
  lw_params_origin(p, cov, where, sizeof where);
  /* a coverage beside the default count would be ignored without a word */
  if (p->coverage > 0 && p->splines > 0 && p->line[spl - lw_param_table] == 0)
    return lw_error_set(err, LW_EINPUT, "%s: key 'init.coverage': sets the number of splines only with "
                        "init.splines = 0 (its default is %s)", where, spl->def);
  if (p->splines > 0 || !(p->coverage > 0)) {
    *n = (size_t)p->splines;
    return LW_OK;
  }
  double want = p->coverage * lw_init_ink_area(sc) / (p->pen_width * p->segments * p->segment_length);
  if (sc->layers.n && sc->layer[0].target) { /* each layer's ink in its own pen (layers.h) */
    want = 0.0;
    for (int k = 0; k < sc->layers.n; k++)
      want += p->coverage * ink_area_of(sc, sc->layer[k].target) /
              (sc->layers.spec[k].pen_width * p->segments * p->segment_length);
  }
  if (!(want <= 1e8))
    return lw_error_set(err, LW_EINPUT, "%s: key 'init.coverage': %g asks for %.3g splines, more than 1e8",
                        where, p->coverage, want);
  *n = (size_t)llround(want);
  return LW_OK;
}
