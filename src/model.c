/*
** model.c -- state, caches, local energy differences and commits (model.h),
** and the from-scratch energy that checks them.
*/
#include "linewise/model.h"

#include "linewise/pairnear.h"
#include "linewise/spacing.h"
#include "linewise/state.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int lw_segment_allowed(const lw_scene *sc, const lw_node *a, const lw_node *b, double length)
{
  if (sc->pair_gap_max > 0.0 && !lw_segment_gaps_within(&sc->pair_quad, a, b, sc->pair_gap_max)) return 0;
  if (sc->min_speed == 0.0 && sc->regularity == 0.0) return 1;
  if (!(length > 0.0)) return 0;
  return lw_segment_check(a, b, sc->min_speed * length, sc->regularity);
}

/* Samples one segment and evaluates its length, its segment terms (contexts
** ctx) and (if ps is not NULL) its pair samples, at the pairwise term's own
** nodes pq when they differ.  Returns 1 if the segment is regular
** (lw_segment_allowed), 0 if forbidden. */
static int segment_eval(const lw_scene *sc, const lw_term_ctx *ctx, const lw_node *a, const lw_node *b,
                        lw_samples *s, double *len, double *local, const lw_quad *pq, lw_pair_sample *ps)
{
  lw_segment_sample(&sc->quad, a, b, s);
  *len = s->length;
  const int regular = lw_segment_allowed(sc, a, b, s->length);
  for (int t = 0; t < sc->n_local; t++) local[t] = lw_term_types[sc->local[t]].segment(s, &ctx[sc->local[t]]);
  if (!ps) return regular;
  lw_samples pair_s;
  const lw_samples *ss = s;
  if (pq->n != sc->quad.n) {
    lw_segment_sample(pq, a, b, &pair_s);
    ss = &pair_s;
  }
  for (int q = 0; q < ss->n; q++)
    ps[q] = (lw_pair_sample){ss->x[q], ss->y[q], (float)ss->dl[q]};
  return regular;
}

/* What a proposal returns where an allocation failed: NAN, marked as want of
** memory, not an undefined energy (the row stops the run: system.h). */
static double no_memory(lw_proposal *p)
{
  p->nomem = 1;
  return NAN;
}

/* Appends a segment number to a list.  LW_ENOMEM if it cannot grow. */
static lw_status list_push(lw_near_list *l, uint32_t v)
{
  if (l->n == l->cap) {
    size_t cap = l->cap ? 2 * l->cap : 64;
    uint32_t *nv = realloc(l->idx, cap * sizeof *nv);
    if (!nv) return LW_ENOMEM;
    l->idx = nv;
    l->cap = cap;
  }
  l->idx[l->n++] = v;
  return LW_OK;
}

/* Moves the model's serial on (lw_model.serial); returns the new one.  Moves
** in two domains may commit at once. */
static uint64_t state_changed(lw_model *m)
{
  return __atomic_add_fetch(&m->serial, 1, __ATOMIC_RELAXED);
}

/* Where the pair term looks things up: the grid, and the splines' sample
** ranges (np samples per segment). */
typedef struct {
  const lw_cellgrid *g;
  const lw_splines *sp;
  uint32_t np;
  const lw_pair_ctx *ctx;
  const lw_layers_spec *planes; /* the layers, when each is a plane of the grid; else NULL */
} pair_view;

/* The layers as planes of the pair grid (grid.h): with layers.apart = pen a
** line pairs and keeps its spacing with its own layer's lines only. */
static const lw_layers_spec *planes_of(const lw_scene *sc)
{
  return lw_layers_planes(&sc->layers) > 1 ? &sc->layers : NULL;
}

/* The grid plane of spline i's samples. */
static int plane_of(const lw_layers_spec *planes, const lw_splines *sp, size_t i)
{
  return planes ? lw_splines_layer(planes, sp, i) : 0;
}

/* Samples i0 to i0 + n - 1 of the grid. */
static void samples_at(const pair_view *v, uint32_t i0, size_t n, lw_pair_sample *out)
{
  enum { RUN = 64 };
  double x[RUN], y[RUN];
  float dl[RUN];
  for (size_t q0 = 0; q0 < n; q0 += RUN) {
    const uint32_t m = (uint32_t)(n - q0 < RUN ? n - q0 : RUN);
    lw_cellgrid_get_run(v->g, i0 + (uint32_t)q0, m, x, y, dl);
    for (uint32_t q = 0; q < m; q++) out[q0 + q] = (lw_pair_sample){x[q], y[q], dl[q]};
  }
}

/* The filter of the samples of spline i: pairs with samples of index >= from. */
static lw_pair_filter filter_of(const pair_view *v, uint32_t spline, uint32_t from)
{
  size_t g0 = lw_segment_index(v->sp, spline, 0), n = lw_splines_segments(v->sp, spline);
  return (lw_pair_filter){.lo = (uint32_t)(g0 * v->np), .hi = (uint32_t)((g0 + n) * v->np), .from = from,
                          .plane = plane_of(v->planes, v->sp, spline)};
}

/* The Bezier control points of global segment g. */
static void segment_bezier(const lw_splines *sp, size_t g, double b[8])
{
  const lw_node *a = &sp->node[lw_segment_node(sp, g)];
  lw_segment_bezier(a, a + 1, b);
}

/* Orders (lower, higher) segment pairs. */
static int cmp_pair(const void *a, const void *b)
{
  const uint32_t *x = a, *y = b;
  return x[0] != y[0] ? (x[0] > y[0]) - (x[0] < y[0]) : (x[1] > y[1]) - (x[1] < y[1]);
}

/* Adds v to the sorted list l unless it holds it already: a segment's near
** partners are few (its near sample pairs many, and repeating), so a scan
** from the end beats sorting the repeats.  LW_ENOMEM if l cannot grow. */
static lw_status set_insert(lw_near_list *l, uint32_t v)
{
  size_t k = l->n;
  while (k > 0 && l->idx[k - 1] > v) k--;
  if (k > 0 && l->idx[k - 1] == v) return LW_OK;
  if (list_push(l, v) != LW_OK) return LW_ENOMEM;
  memmove(l->idx + k + 1, l->idx + k, (l->n - 1 - k) * sizeof *l->idx);
  l->idx[k] = v;
  return LW_OK;
}

/* The near correction (pairnear.h, no coefficient) of the segment with
** control points bez and samples mine with segment gb. */
static double near_one(const pair_view *v, const double bez[8], const lw_pair_sample *mine, uint32_t gb)
{
  lw_pair_sample other[LW_QUAD_MAX];
  double b[8];
  segment_bezier(v->sp, gb, b);
  samples_at(v, gb * v->np, v->np, other);
  return lw_pair_near_correction(bez, mine, b, other, (int)v->np, v->ctx);
}

/* Appends a pair's value to out; a value that finds no memory is dropped,
** which costs only its recomputation (the pair slots are a cache). */
static void values_push(lw_near_values *out, uint32_t seg, uint32_t partner, double x)
{
  if (out->n == out->cap) {
    size_t cap = out->cap ? 2 * out->cap : 64;
    lw_near_value *nv = realloc(out->v, cap * sizeof *nv);
    if (!nv) return;
    out->v = nv;
    out->cap = cap;
  }
  out->v[out->n++] = (lw_near_value){seg, partner, x};
}

/* The near field (no coefficient) of one segment, control points bez and
** samples mine, with each segment of the sorted list `segs` (pairnear.h).
** Sums in the list's order, so the value is a function of the state.  With
** out, each pair's value goes there too, as segment self's. */
static double near_part(const pair_view *v, const double bez[8], const lw_pair_sample *mine,
                        const lw_near_list *segs, uint32_t self, lw_near_values *out)
{
  double sum = 0.0;
  for (size_t k = 0; k < segs->n; k++) {
    double x = near_one(v, bez, mine, segs->idx[k]);
    if (out) values_push(out, self, segs->idx[k], x);
    sum += x;
  }
  return sum;
}

/* ---- the pair slots (lw_model.near_pid) ------------------------------------
** A segment's slot ids are read and cleared by the commits of its partners,
** which with domains may run in two cells at once (the segment then moves in
** neither): ids are atomic and a free slot is claimed by compare-and-swap.
** Which pairs find a slot may then depend on timing, never a value: a slot
** holds what a recomputation gives, bit for bit. */

/* The slot of segment g that holds partner h, or -1 (also without slots:
** the near field off). */
static int slot_find(const lw_model *m, size_t g, uint32_t h)
{
  if (!m->near_pid) return -1;
  const uint32_t *id = m->near_pid + g * LW_NEAR_SLOTS;
  for (int k = 0; k < LW_NEAR_SLOTS; k++)
    if (__atomic_load_n(&id[k], __ATOMIC_RELAXED) == h) return k;
  return -1;
}

/* Keeps x as the value of pair (g, h) in g's slots, if one is free. */
static void slot_store(const lw_model *m, size_t g, uint32_t h, double x)
{
  if (!m->near_pid) return;
  uint32_t *id = m->near_pid + g * LW_NEAR_SLOTS;
  int k = slot_find(m, g, h);
  for (int s = 0; k < 0 && s < LW_NEAR_SLOTS; s++) {
    uint32_t none = LW_NEAR_FREE;
    if (__atomic_compare_exchange_n(&id[s], &none, h, 0, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) k = s;
  }
  if (k >= 0) m->near_pval[g * LW_NEAR_SLOTS + (size_t)k] = x;
}

/* Forgets pair (g, h) in g's slots. */
static void slot_clear(const lw_model *m, size_t g, uint32_t h)
{
  int k = slot_find(m, g, h);
  if (k >= 0) __atomic_store_n(&m->near_pid[g * LW_NEAR_SLOTS + (size_t)k], LW_NEAR_FREE, __ATOMIC_RELAXED);
}

/* Empties the slots of segments [g, g + n). */
static void slots_reset(const lw_model *m, size_t g, size_t n)
{
  if (!m->near_pid) return;
  for (size_t k = g * LW_NEAR_SLOTS; k < (g + n) * LW_NEAR_SLOTS; k++)
    __atomic_store_n(&m->near_pid[k], LW_NEAR_FREE, __ATOMIC_RELAXED);
}

/*
** Every pair of samples of different splines once (j > i) by the walk, the
** samples taken cell by cell in the grid's order, which depends on positions
** only; then every near segment pair once (the walk reports those of
** samples j > i, so of segments gb > ga), in increasing order of (lower,
** higher) segment.  With out, every near pair's value goes there too.
*/
static lw_status pair_all(const pair_view *v, double *e, lw_near_values *out)
{
  lw_pair_nearlist near = {0};
  /* pairs: (lower, higher) segment, two entries each; partners: a sample's
  ** near segments, each once (its near samples name each up to np times, and
  ** the list held and sorted was most of a large set-up's memory and a sixth
  ** of its time) */
  lw_near_list pairs = {0}, segs = {0}, partners = {0};
  const lw_cellgrid *g = v->g;
  double sum = 0.0, t;
  lw_status st = LW_OK;
  for (size_t ci = 0; ci < lw_cellgrid_cells(g) && st == LW_OK; ci++) {
    const lw_cell *c = &g->cell[ci];
    if (!c->n) continue; /* an empty cell may have no block: NULL + 0 is undefined */
    const uint32_t *idx = lw_cell_idx(c);
    for (uint32_t k = 0; k < c->n && st == LW_OK; k++) {
      uint32_t i = idx[k], ga = i / v->np;
      lw_pair_probe P = {c->x[k], lw_cell_y(c)[k], lw_cell_dl(c)[k], 1.0};
      lw_pair_filter f = filter_of(v, v->sp->seg_spline[ga], i + 1);
      near.n = 0;
      if ((st = lw_pair_walk(g, v->ctx, &P, 1, &f, &t, NULL, &near, NULL)) != LW_OK) break;
      sum += t;
      partners.n = 0;
      for (size_t q = 0; q < near.n && st == LW_OK; q++) st = set_insert(&partners, near.pair[q].idx / v->np);
      for (size_t q = 0; q < partners.n && st == LW_OK; q++)
        if (list_push(&pairs, ga) != LW_OK || list_push(&pairs, partners.idx[q]) != LW_OK) st = LW_ENOMEM;
    }
  }
  if (st == LW_OK && pairs.n) {
    /* each lower segment with its sorted partners, in increasing order */
    qsort(pairs.idx, pairs.n / 2, 2 * sizeof *pairs.idx, cmp_pair);
    lw_pair_sample sa[LW_QUAD_MAX];
    for (size_t k = 0; k < pairs.n && st == LW_OK; k += 2) {
      uint32_t ga = pairs.idx[k];
      if (k > 0 && ga == pairs.idx[k - 2]) continue;
      segs.n = 0;
      for (size_t j = k; j < pairs.n && pairs.idx[j] == ga && st == LW_OK; j += 2)
        if (segs.n == 0 || segs.idx[segs.n - 1] != pairs.idx[j + 1]) st = list_push(&segs, pairs.idx[j + 1]);
      double a[8];
      segment_bezier(v->sp, ga, a);
      samples_at(v, ga * v->np, v->np, sa);
      sum += near_part(v, a, sa, &segs, ga, out);
    }
  }
  free(pairs.idx);
  free(segs.idx);
  free(partners.idx);
  lw_pair_nearlist_free(&near);
  *e = sum;
  return st;
}

static void term_set_init(lw_term_set *ts, const lw_scene *sc)
{
  lw_scene_term_ctx(sc, ts->ctx);
  ts->n_layers = sc->layers.n;
  ts->layers = &sc->layers;
  for (int k = 0; k < ts->n_layers; k++) lw_scene_layer_ctx(sc, k, ts->layer_ctx[k]);
  ts->n_spline = 0;
  ts->n_raster = 0;
  ts->pair = -1;
  for (int t = 0; t < LW_TERM_COUNT; t++) {
    if (ts->ctx[t].coef == 0.0) continue;
    if (lw_term_types[t].spline) ts->spline[ts->n_spline++] = (lw_term_id)t;
    if (lw_term_types[t].raster) ts->raster[ts->n_raster++] = (lw_term_id)t;
    if (lw_term_types[t].pairwise && ts->pair < 0) ts->pair = t;
  }
}

/* The layer of spline i of sp, 0 without layers. */
static int layer_of(const lw_term_set *ts, const lw_splines *sp, size_t i)
{
  return ts->n_layers ? lw_splines_layer(ts->layers, sp, i) : 0;
}

/* The term contexts of a layer's splines: its own, or the scene's. */
static const lw_term_ctx *ctx_in(const lw_term_set *ts, int layer)
{
  return ts->n_layers ? ts->layer_ctx[layer] : ts->ctx;
}

static const lw_term_ctx *ctx_of(const lw_term_set *ts, const lw_splines *sp, size_t i)
{
  return ctx_in(ts, layer_of(ts, sp, i));
}

/* Where a layer's plane of a raster term's raster starts. */
static size_t plane_in(int layer, const lw_tone *t) { return (size_t)layer * (size_t)t->w * (size_t)t->h; }

/* A zeroed raster of term t: a plane a layer (every layer's is as large). */
static int64_t *raster_new(const lw_term_set *ts, int t)
{
  const lw_tone *tn = ts->ctx[t].data;
  size_t planes = ts->n_layers ? (size_t)ts->n_layers : 1;
  return calloc(planes * (size_t)tn->w * (size_t)tn->h, sizeof(int64_t));
}

/* The pairwise term's kernel settings and sample nodes. */
static const lw_pair_ctx *pair_ctx(const lw_term_ctx *c) { return c->data; }

/* With trans-dimensional moves the sample count changes, and with it the
** cells lw_cellgrid_new would choose; a fixed room keeps them a function of
** the scene (grid.h), at most 4 M cells. */
#define TRANSDIM_GRID_ROOM ((size_t)1 << 20)

static lw_cellgrid *grid_for(const lw_scene *sc, const lw_term_ctx *pair, size_t n_samples, lw_error *err)
{
  lw_cellgrid *g =
    sc->transdim ? lw_cellgrid_new_room(0.0, 0.0, sc->width, sc->height, pair_ctx(pair)->cutoff, n_samples,
                                        TRANSDIM_GRID_ROOM, err)
                 : lw_cellgrid_new(0.0, 0.0, sc->width, sc->height, pair_ctx(pair)->cutoff, n_samples, err);
  if (g && planes_of(sc) && lw_cellgrid_planes(g, sc->layers.n) != LW_OK) {
    lw_cellgrid_free(g);
    lw_error_set(err, LW_ENOMEM, "out of memory for the pair grid's %d planes", sc->layers.n);
    return NULL;
  }
  return g;
}

/* Adds the spline terms of spline i (segment lengths seg_len, length L) to term[]. */
static void spline_terms(const lw_term_set *ts, const lw_splines *sp, const double *seg_len, size_t i, double L,
                         double *term)
{
  size_t n = lw_splines_segments(sp, i), g0 = lw_segment_index(sp, i, 0);
  for (int k = 0; k < ts->n_spline; k++) {
    int t = ts->spline[k];
    term[t] += ts->ctx[t].coef * lw_term_types[t].spline(seg_len + g0, n, L, sp->rest_length[i], &ts->ctx[t]);
  }
}

/* Splats every sample of sp (at the raster term's nodes) into the plane
** of its layer of r, zeroed first, and returns the energy of raster term
** t with its coefficient.  The sum is exact (tone.h), so any order gives
** the same raster. */
static double raster_fill(const lw_term_set *ts, int t, const lw_splines *sp, int64_t *r)
{
  const lw_tone *t0 = ts->ctx[t].data;
  const size_t plane = (size_t)t0->w * (size_t)t0->h, planes = ts->n_layers ? (size_t)ts->n_layers : 1;
  lw_samples s;
  memset(r, 0, planes * plane * sizeof *r);
  for (size_t g = 0; g < sp->n_segments; g++) {
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    const int layer = layer_of(ts, sp, sp->seg_spline[g]);
    const lw_term_ctx *c = &ctx_in(ts, layer)[t];
    const lw_tone *tn = c->data;
    int64_t *rp = r + plane_in(layer, tn);
    lw_segment_sample(c->quad, a, a + 1, &s);
    for (int q = 0; q < s.n; q++) lw_tone_splat(tn, rp, 0, 0, tn->w, tn->h, s.x[q], s.y[q], s.dl[q], 1);
  }
  if (!ts->n_layers) return ts->ctx[t].coef * lw_tone_energy(t0, r);
  double e = 0.0;
  for (int k = 0; k < ts->n_layers; k++) e += lw_tone_energy(ts->layer_ctx[k][t].data, r + (size_t)k * plane);
  return ts->ctx[t].coef * e;
}

/* Grows box b over the segment from a to c: its control points bound it. */
static void raster_cover(const lw_tone *t, lw_tone_box *b, const lw_node *a, const lw_node *c)
{
  double z[8];
  lw_segment_bezier(a, c, z);
  double x0 = z[0], x1 = z[0], y0 = z[1], y1 = z[1];
  for (int k = 2; k < 8; k += 2) {
    x0 = fmin(x0, z[k]);
    x1 = fmax(x1, z[k]);
    y0 = fmin(y0, z[k + 1]);
    y1 = fmax(y1, z[k + 1]);
  }
  lw_tone_box_cover(t, b, x0, y0, x1, y1);
}

/* Splats the samples of the segment from a to c into box b with sign. */
static void raster_segment(const lw_term_ctx *c, lw_tone_box *b, const lw_node *a, const lw_node *e, int sign)
{
  lw_samples s;
  lw_segment_sample(c->quad, a, e, &s);
  for (int q = 0; q < s.n; q++) lw_tone_box_splat(c->data, b, s.x[q], s.y[q], s.dl[q], sign);
}

lw_status lw_model_check_regular(const lw_scene *sc, const lw_splines *sp, const char *path, lw_error *err)
{
  if (sc->min_speed == 0.0 && sc->regularity == 0.0 && sc->pair_gap_max == 0.0) return LW_OK;
  lw_samples s;
  for (size_t g = 0; g < sp->n_segments; g++) {
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    lw_segment_sample(&sc->quad, a, a + 1, &s);
    if (lw_segment_allowed(sc, a, a + 1, s.length)) continue;
    size_t i = sp->seg_spline[g];
    const int regular = (sc->min_speed == 0.0 && sc->regularity == 0.0) ||
                        (s.length > 0.0 && lw_segment_check(a, a + 1, sc->min_speed * s.length, sc->regularity));
    if (regular)
      return lw_error_set(err, LW_EINPUT,
                          "%s: spline %zu, segment %zu is too long for the pair cutoff: two of its pair "
                          "samples lie %.3g mm apart, more than %g of energy.pair_cutoff (%g mm), so a line "
                          "could cross it unseen; raise energy.pair_cutoff or energy.pair_quadrature",
                          path, i, g - lw_segment_index(sp, i, 0), lw_segment_widest_gap(&sc->pair_quad, a, a + 1),
                          LW_PAIR_GAP_SHARE, sc->pair_gap_max / LW_PAIR_GAP_SHARE);
    /* name the test that failed (both where the finer test is the one) */
    const double ratio = s.length > 0.0 ? lw_segment_min_speed(a, a + 1) / s.length : 0.0;
    const double rho = lw_segment_rho(a, a + 1);
    const int slow = sc->min_speed > 0.0 && ratio < sc->min_speed, fold = sc->regularity > 0.0 && rho < sc->regularity;
    char speed[160] = "", bend[128] = "";
    if (slow || !fold)
      snprintf(speed, sizeof speed, "its speed falls to %.6g of its mean (energy.min_speed = %g; the mean as %d nodes "
               "measure the length)", ratio, sc->min_speed, sc->quad.n);
    if (fold || !slow)
      snprintf(bend, sizeof bend, "its bending integrand is analytic only within rho = %.6g (energy.regularity = %g)",
               rho, sc->regularity);
    return lw_error_set(err, LW_EINPUT,
                        "%s: spline %zu, segment %zu is irregular: %s%s%s, a fold the quadrature cannot see; lower "
                        "%s to accept it", path, i, g - lw_segment_index(sp, i, 0), speed,
                        speed[0] && bend[0] ? " and " : "", bend,
                        slow && !fold ? "energy.min_speed" : fold && !slow ? "energy.regularity" : "these keys");
  }
  return LW_OK;
}

lw_status lw_model_check_layers(const lw_scene *sc, lw_splines *sp, const char *path, lw_error *err)
{
  if (!sp->layer) return LW_OK;
  if (!sc->layers.n) {
    free(sp->layer);
    sp->layer = NULL;
    return LW_OK;
  }
  for (size_t i = 0; i < sp->n_splines; i++)
    if (sp->layer[i] >= sc->layers.n)
      return lw_error_set(err, LW_EINPUT, "%s: spline %zu is of layer %d, but the scene has %d layers ([layers] names)",
                          path, i, sp->layer[i], sc->layers.n);
  return LW_OK;
}

/* The sum of the terms, +inf while a segment is irregular (forbidden). */
static double total_of(const double term[LW_TERM_COUNT], size_t irregular)
{
  double total = 0.0;
  for (int t = 0; t < LW_TERM_COUNT; t++) total += term[t];
  return irregular ? INFINITY : total;
}

/* Puts the np pair samples ps of segment g into the grid's plane `plane`. */
static lw_status store_samples(lw_cellgrid *grid, int plane, size_t g, int np, const lw_pair_sample *ps)
{
  for (int q = 0; q < np; q++) {
    size_t i = g * (size_t)np + (size_t)q;
    if (lw_cellgrid_insert_in(grid, plane, (uint32_t)i, ps[q].x, ps[q].y, ps[q].dl) != LW_OK) return LW_ENOMEM;
  }
  return LW_OK;
}

double lw_energy_compute(const lw_scene *sc, const lw_splines *sp, double term[LW_TERM_COUNT],
                         lw_error *err)
{
  for (int t = 0; t < LW_TERM_COUNT; t++) term[t] = 0.0;
  lw_term_set ts;
  term_set_init(&ts, sc);
  const lw_term_ctx *pc = ts.pair >= 0 ? &ts.ctx[ts.pair] : NULL;
  const int np = pc ? pc->quad->n : sc->quad.n;
  lw_samples s;
  double local[LW_TERM_COUNT];
  lw_pair_sample seg_ps[LW_QUAD_MAX];
  lw_cellgrid *grid = NULL;
  size_t n = sp->n_segments * (size_t)np, irregular = 0;
  double *seg_len = malloc((sp->n_segments ? sp->n_segments : 1) * sizeof *seg_len);
  if (!seg_len) goto nomem;
  if (pc && !(grid = grid_for(sc, pc, n, err))) goto fail;
  for (size_t g = 0; g < sp->n_segments; g++) {
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    irregular += !segment_eval(sc, ctx_of(&ts, sp, sp->seg_spline[g]), a, a + 1, &s, &seg_len[g], local,
                               pc ? pc->quad : NULL, grid ? seg_ps : NULL);
    for (int t = 0; t < sc->n_local; t++) term[sc->local[t]] += local[t];
    if (grid && store_samples(grid, plane_of(planes_of(sc), sp, sp->seg_spline[g]), g, np, seg_ps) != LW_OK)
      goto nomem;
  }
  if (ts.n_spline)
    for (size_t i = 0; i < sp->n_splines; i++) {
      size_t g0 = lw_segment_index(sp, i, 0), ns = lw_splines_segments(sp, i);
      spline_terms(&ts, sp, seg_len, i, lw_term_spline_length(seg_len + g0, ns, NULL), term);
    }
  if (grid) {
    pair_view v = {grid, sp, (uint32_t)np, pair_ctx(pc), planes_of(sc)};
    double e;
    if (pair_all(&v, &e, NULL) != LW_OK) goto nomem;
    term[ts.pair] = pc->coef * e;
  }
  for (int k = 0; k < ts.n_raster; k++) {
    int64_t *r = raster_new(&ts, ts.raster[k]);
    if (!r) goto nomem;
    term[ts.raster[k]] = raster_fill(&ts, ts.raster[k], sp, r);
    free(r);
  }
  free(seg_len);
  lw_cellgrid_free(grid);
  return total_of(term, irregular);
nomem:
  lw_error_set(err, LW_ENOMEM, "out of memory for the energy of %zu segments (%zu pair samples)",
               sp->n_segments, n);
fail:
  free(seg_len);
  lw_cellgrid_free(grid);
  return NAN;
}

double lw_energy_raster(const lw_scene *sc, const lw_splines *sp, int t, int64_t **out, lw_error *err)
{
  lw_term_set ts;
  term_set_init(&ts, sc);
  if (!(*out = raster_new(&ts, t))) {
    lw_error_set(err, LW_ENOMEM, "out of memory for the %s raster", lw_term_names[t]);
    return NAN;
  }
  return raster_fill(&ts, t, sp, *out);
}

/* Pair samples a segment: the pairwise term's nodes (the quadrature's when
** there is none, for sizes only). */
static int pair_nodes(const lw_model *m)
{
  return m->terms.pair >= 0 ? m->terms.ctx[m->terms.pair].quad->n : m->scene->quad.n;
}

lw_model *lw_model_new(const lw_scene *sc, lw_splines *sp, lw_error *err)
{
  lw_model *m = calloc(1, sizeof *m);
  if (!m) {
    lw_splines_free(sp);
    lw_error_set(err, LW_ENOMEM, "out of memory for the model");
    return NULL;
  }
  m->scene = sc;
  m->sp = sp;
  /* serials unique among models: a proposal's memo names model and serial */
  static uint64_t models_made;
  m->serial = __atomic_add_fetch(&models_made, 1, __ATOMIC_RELAXED) << 40;
  term_set_init(&m->terms, sc);
  size_t ns = sp->n_segments ? sp->n_segments : 1;
  m->seg_len = malloc(ns * sizeof *m->seg_len);
  m->seg_local = malloc(ns * (size_t)(sc->n_local ? sc->n_local : 1) * sizeof *m->seg_local);
  m->spline_len = malloc((sp->n_splines ? sp->n_splines : 1) * sizeof *m->spline_len);
  m->seg_irregular = calloc(ns, sizeof *m->seg_irregular);
  if (!m->seg_len || !m->seg_local || !m->spline_len || !m->seg_irregular) goto nomem;
  if (m->terms.pair >= 0) {
    size_t n = sp->n_segments * (size_t)pair_nodes(m);
    if (n >= UINT32_MAX) {
      lw_error_set(err, LW_EINPUT, "%zu pair samples of %zu splines exceed the grid's limit of 2^32 samples",
                   n, sp->n_splines);
      lw_model_free(m);
      return NULL;
    }
    m->near_cache = malloc(ns * sizeof *m->near_cache);
    m->near_valid = calloc(ns, sizeof *m->near_valid);
    if (!m->near_cache || !m->near_valid) goto nomem;
    if (sc->pair.near_scale > 0.0) {
      m->near_pid = malloc(ns * LW_NEAR_SLOTS * sizeof *m->near_pid);
      m->near_pval = malloc(ns * LW_NEAR_SLOTS * sizeof *m->near_pval);
      if (!m->near_pid || !m->near_pval) goto nomem;
    }
    slots_reset(m, 0, ns);
    m->grid = grid_for(sc, &m->terms.ctx[m->terms.pair], n, err);
    if (!m->grid) {
      lw_model_free(m);
      return NULL;
    }
  }
  for (int k = 0; k < m->terms.n_raster; k++)
    if (!(m->raster[m->terms.raster[k]] = raster_new(&m->terms, m->terms.raster[k]))) goto nomem;
  for (size_t i = 0; i < sp->n_splines; i++)
    if (lw_splines_segments(sp, i) > m->max_segments) m->max_segments = lw_splines_segments(sp, i);
  if (sc->transdim && sc->max_segments > m->max_segments) m->max_segments = sc->max_segments;
  /* (births and deaths move the segments: there the lengths are summed afresh) */
  if (!sc->transdim && m->max_segments > LW_TERM_LEN_BLOCK && !(m->seg_block = malloc(ns * sizeof *m->seg_block)))
    goto nomem;
  m->cap_seg = ns;
  m->cap_spl = sp->n_splines ? sp->n_splines : 1;
  /* with layers a layer is state, since births and deaths, and the drift
  ** checks' renumbering, move splines to other indices: placed or loaded
  ** without one, each spline keeps the one the index rule gives it now */
  if (sc->layers.n && !sp->layer) {
    if (lw_splines_layers_alloc(sp) != LW_OK) goto nomem;
    for (size_t i = 0; i < sp->n_splines; i++) sp->layer[i] = (uint8_t)lw_layers_of(&sc->layers, i);
  }
  if (!(m->slots = lw_slots_new())) goto nomem;
  if (lw_model_refresh(m, NULL) != LW_OK) goto nomem;
  return m;
nomem:
  lw_error_set(err, LW_ENOMEM, "out of memory for the model of %zu segments", sp->n_segments);
  lw_model_free(m);
  return NULL;
}

void lw_model_free(lw_model *m)
{
  if (!m) return;
  lw_splines_free(m->sp);
  free(m->seg_len);
  free(m->seg_block);
  free(m->spline_len);
  free(m->seg_local);
  free(m->seg_irregular);
  free(m->near_cache);
  free(m->near_valid);
  free(m->near_pid);
  free(m->near_pval);
  lw_cellgrid_free(m->grid);
  for (int t = 0; t < LW_TERM_COUNT; t++) free(m->raster[t]);
  lw_slots_free(m->slots);
  free(m);
}

double lw_model_total(const lw_model *m)
{
  return total_of(m->term, m->n_irregular);
}

lw_status lw_model_refresh(lw_model *m, double *drift)
{
  if (lw_model_compact(m) != LW_OK) return LW_ENOMEM;
  state_changed(m);
  const lw_scene *sc = m->scene;
  const lw_splines *sp = m->sp;
  const lw_term_set *ts = &m->terms;
  const lw_term_ctx *pc = ts->pair >= 0 ? &ts->ctx[ts->pair] : NULL;
  const int np = pair_nodes(m), nl = sc->n_local;
  double old_total = lw_model_total(m);
  double term[LW_TERM_COUNT] = {0};
  lw_samples s;
  lw_pair_sample seg_ps[LW_QUAD_MAX];
  m->n_irregular = 0;
  if (m->grid) lw_cellgrid_clear(m->grid);
  for (size_t g = 0; g < sp->n_segments; g++) {
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    double *local = m->seg_local + g * (size_t)nl;
    m->seg_irregular[g] = !segment_eval(sc, ctx_of(ts, sp, sp->seg_spline[g]), a, a + 1, &s, &m->seg_len[g], local,
                                        pc ? pc->quad : NULL, m->grid ? seg_ps : NULL);
    m->n_irregular += m->seg_irregular[g];
    for (int t = 0; t < nl; t++) term[sc->local[t]] += local[t];
    if (m->grid && store_samples(m->grid, plane_of(planes_of(sc), sp, sp->seg_spline[g]), g, np, seg_ps) != LW_OK)
      return LW_ENOMEM;
  }
  for (size_t i = 0; i < sp->n_splines; i++) {
    size_t g0 = lw_segment_index(sp, i, 0), n = lw_splines_segments(sp, i);
    for (size_t b0 = 0; m->seg_block && b0 < n; b0 += LW_TERM_LEN_BLOCK)
      m->seg_block[g0 + b0] = lw_term_block_sum(m->seg_len + g0, n, b0);
    const double L = lw_term_spline_length(m->seg_len + g0, n, m->seg_block ? m->seg_block + g0 : NULL);
    m->spline_len[i] = L;
    spline_terms(ts, sp, m->seg_len, i, L, term);
  }
  if (m->grid) {
    pair_view v = {m->grid, sp, (uint32_t)np, pair_ctx(pc), planes_of(sc)};
    double e;
    lw_near_values vals = {0};
    memset(m->near_valid, 0, sp->n_segments * sizeof *m->near_valid);
    slots_reset(m, 0, sp->n_segments);
    lw_cellgrid_fit(m->grid);
    lw_status st = pair_all(&v, &e, &vals);
    /* every pair's value warms both segments' slots */
    for (size_t k = 0; k < vals.n; k++) {
      slot_store(m, vals.v[k].seg, vals.v[k].partner, vals.v[k].value);
      slot_store(m, vals.v[k].partner, vals.v[k].seg, vals.v[k].value);
    }
    free(vals.v);
    if (st != LW_OK) return LW_ENOMEM;
    term[ts->pair] = pc->coef * e;
  }
  for (int k = 0; k < ts->n_raster; k++) {
    const int t = ts->raster[k];
    term[t] = raster_fill(ts, t, sp, m->raster[t]);
  }
  for (int t = 0; t < LW_TERM_COUNT; t++) m->term[t] = term[t];
  double total = lw_model_total(m);
  if (drift) {
    if (!isfinite(total) || !isfinite(old_total)) *drift = total == old_total ? 0.0 : INFINITY;
    else *drift = fabs(total - old_total) / fmax(fabs(total), 1.0);
  }
  return LW_OK;
}

lw_proposal *lw_proposal_new(const lw_model *m, lw_error *err)
{
  lw_proposal *p = calloc(1, sizeof *p);
  size_t cap = m->max_segments ? m->max_segments : 1;
  int nl = m->scene->n_local ? m->scene->n_local : 1;
  if (p) {
    p->cap_seg = cap;
    p->node = malloc((cap + 1) * sizeof *p->node);
    p->len = malloc(cap * sizeof *p->len);
    p->local = malloc(cap * (size_t)nl * sizeof *p->local);
    size_t ns = cap * (size_t)pair_nodes(m);
    p->ps = malloc(ns * sizeof *p->ps);
    p->ps_old = malloc(ns * sizeof *p->ps_old);
    p->probe = malloc(2 * ns * sizeof *p->probe);
    p->walked = malloc(2 * ns * sizeof *p->walked);
    p->walked_id = malloc(2 * ns * sizeof *p->walked_id);
    p->each = malloc(2 * ns * sizeof *p->each);
    p->stand = malloc(2 * ns * sizeof *p->stand);
    p->seg_sum = malloc(4 * cap * sizeof *p->seg_sum);
    p->memo.spline = UINT32_MAX;
    p->memo.ok = calloc(cap, sizeof *p->memo.ok);
    p->memo.far = malloc(cap * sizeof *p->memo.far);
    p->memo.stand = malloc(cap * sizeof *p->memo.stand);
    p->memo.partners = calloc(cap, sizeof *p->memo.partners);
    p->side = calloc(2 * cap, sizeof *p->side);
    p->near_new = malloc(cap * sizeof *p->near_new);
    p->seg_irregular = malloc(cap * sizeof *p->seg_irregular);
    for (int t = 0; t < LW_TERM_COUNT; t++) p->sum_term[t] = -0.0;
  }
  if (!p || !p->node || !p->len || !p->local || !p->ps || !p->ps_old || !p->probe || !p->walked ||
      !p->walked_id || !p->each || !p->stand || !p->seg_sum || !p->memo.ok || !p->memo.far || !p->memo.stand ||
      !p->memo.partners || !p->side || !p->near_new || !p->seg_irregular) {
    lw_proposal_free(p);
    lw_error_set(err, LW_ENOMEM, "out of memory for a proposal");
    return NULL;
  }
  return p;
}

void lw_proposal_free(lw_proposal *p)
{
  if (!p) return;
  free(p->node);
  free(p->len);
  free(p->local);
  free(p->ps);
  free(p->ps_old);
  free(p->probe);
  free(p->walked);
  free(p->walked_id);
  free(p->each);
  free(p->stand);
  free(p->seg_sum);
  for (size_t k = 0; p->memo.partners && k < p->cap_seg; k++) free(p->memo.partners[k].idx);
  free(p->memo.partners);
  for (size_t k = 0; p->side && k < 2 * p->cap_seg; k++) free(p->side[k].idx);
  free(p->side);
  free(p->memo.ok);
  free(p->memo.far);
  free(p->memo.stand);
  lw_pair_nearlist_free(&p->near);
  free(p->segs.idx);
  free(p->partners.idx);
  free(p->near_new);
  free(p->near_vals.v);
  free(p->seg_irregular);
  for (int t = 0; t < LW_TERM_COUNT; t++) lw_tone_box_free(&p->box[t]);
  free(p);
}

/* Node k of the spline as it would be after the proposal. */
static inline const lw_node *proposed_node(const lw_node *base, const lw_proposal *p, size_t k)
{
  return (k >= p->node0 && k < p->node0 + p->n_node) ? &p->node[k - p->node0] : &base[k];
}

/* p->side: the sorted segments of the near pairs of each changed segment j,
** new (2j) and old (2j + 1); probe k is new sample k/2 for even k, its old
** self for odd k, so probe / np is just that list's number. */
static lw_status side_partners(lw_proposal *p, uint32_t np)
{
  for (size_t j = 0; j < 2 * p->n_seg; j++) p->side[j].n = 0;
  uint32_t last_js = UINT32_MAX, last = 0;
  for (size_t k = 0; k < p->near.n; k++) {
    const lw_pair_near *q = &p->near.pair[k];
    const uint32_t js = 2 * (q->probe / 2 / np) + (q->probe & 1), v = q->idx / np;
    /* a probe's near pairs come cell by cell in index order, so the same
    ** partner repeats in runs: those need no search */
    if (js == last_js && v == last) continue;
    if (set_insert(&p->side[js], v) != LW_OK) return LW_ENOMEM;
    last_js = js;
    last = v;
  }
  return LW_OK;
}

static void list_swap(lw_near_list *a, lw_near_list *b)
{
  const lw_near_list t = *a;
  *a = *b;
  *b = t;
}

/* The near field of old segment g (from node a to a + 1, samples ps, near
** partners segs) from the model's cache; when that is not valid, summed
** again as near_part sums it, each pair from g's slots where one holds it. */
static double old_near(const lw_model *m, const pair_view *v, size_t g, const lw_node *a, const lw_pair_sample *ps,
                       const lw_near_list *segs)
{
  if (!m->near_valid[g]) {
    double bez[8], sum = 0.0;
    lw_segment_bezier(a, a + 1, bez);
    for (size_t k = 0; k < segs->n; k++) {
      const uint32_t h = segs->idx[k];
      const int s = slot_find(m, g, h);
      double x;
      if (s >= 0) {
        x = m->near_pval[g * LW_NEAR_SLOTS + (size_t)s];
      } else {
        x = near_one(v, bez, ps, h);
        slot_store(m, g, h, x);
      }
      sum += x;
    }
    m->near_cache[g] = sum;
    m->near_valid[g] = 1;
  }
  return m->near_cache[g];
}

/* Adds segs to p->partners (the near fields a commit invalidates). */
static lw_status add_partners(lw_proposal *p, const lw_near_list *segs)
{
  for (size_t k = 0; k < segs->n; k++)
    if (list_push(&p->partners, segs->idx[k]) != LW_OK) return LW_ENOMEM;
  return LW_OK;
}

/*
** What the first stage of delayed acceptance sees in place of a move's near
** field: the walk's near sample pairs as the product rule sums them, each
** distance held at half its near radius or more (so it stays finite where
** samples meet), new pairs added and old ones taken away.  No curve
** integrals; a function of the two states, which is all the first stage
** needs: how closely it follows the near field only sets how few of the
** moves that pass it the second stage refuses.  One near pair's term (+1):
*/
static double near_stand_in(const lw_pair_ctx *ctx, const lw_pair_probe *P, const lw_pair_near *q)
{
  const double dx = P->x - q->x, dy = P->y - q->y;
  double r2 = dx * dx + dy * dy;
  if (P->dl == 0.0f || q->dl == 0.0f || r2 >= ctx->cutoff2) return 0.0;
  const double floor2 = 0.25 * lw_pair_near_radius2(ctx, P->dl, q->dl);
  if (r2 < floor2) r2 = floor2;
  return (double)P->dl * (double)q->dl * (1.0 / sqrt(r2) - ctx->inv_cutoff);
}

/* Starts p's memo afresh for its spline in m's current state. */
static void memo_reset(lw_proposal *p, const lw_model *m)
{
  lw_far_memo *mo = &p->memo;
  mo->model = m;
  mo->spline = p->spline;
  mo->serial = __atomic_load_n(&m->serial, __ATOMIC_RELAXED);
  memset(mo->ok, 0, p->cap_seg * sizeof *mo->ok);
}

/*
** The pair part of a proposal's dE (no coefficient) comes in two steps.
** pair_walk: one walk over the new samples and their old selves gives each
** sample's far sum (with the sample's weight, +1 either side) and lists the
** near sample pairs in p->near; each changed segment's far sum and stand-in
** are summed from its samples', new less old.  pair_near_delta: the near
** field of each changed segment is added for the new side, and taken away
** for the old side from the model's cache when valid.  The near field is the
** costly part and a chain at low temperature rejects most proposals, so
** caching the old side halves it, and delayed acceptance
** (lw_model_propose_finish) leaves the new side to the proposals that pass
** a first test.  The cached value of a segment is what this code computes
** for it from the current state (the same sum in the same order), so a
** cached and a recomputed value are bitwise equal; commits invalidate every
** segment whose near field the move changed (its near partners before and
** after), kept in p->partners.
**
** The old side's walk is skipped for a segment the memo holds (lw_far_memo:
** in a sweep, the one the previous move shared): a sample's far sum and the
** order of its near pairs depend on it and the other splines' samples only
** (walk.h), so the memo's sums are bit for bit what the walk would give.
** NAN if out of memory.
*/
static double pair_walk(const lw_model *m, lw_proposal *p)
{
  const lw_scene *sc = m->scene;
  const uint32_t np = (uint32_t)sc->pair_quad.n;
  const pair_view v = {m->grid, m->sp, np, &sc->pair, planes_of(sc)};
  const size_t n = p->n_seg * np;
  lw_far_memo *mo = &p->memo;
  p->walk_done = 0;
  if (mo->model != m || mo->spline != p->spline || mo->serial != __atomic_load_n(&m->serial, __ATOMIC_RELAXED))
    memo_reset(p, m);
  /* each new sample next to its old self, the old ones of the memo's
  ** segments left out */
  size_t nw = 0;
  for (size_t k = 0; k < 2 * n; k++) {
    const lw_pair_sample *ps_k = k & 1 ? &p->ps_old[k / 2] : &p->ps[k / 2];
    p->probe[k] = (lw_pair_probe){ps_k->x, ps_k->y, ps_k->dl, 1.0};
    if ((k & 1) && mo->ok[p->seg0 + k / 2 / np]) continue;
    p->walked[nw] = p->probe[k];
    p->walked_id[nw++] = (uint32_t)k;
  }
  p->n_walked = nw;
  lw_pair_filter f = filter_of(&v, p->spline, 0);
  double all;
  p->near.n = 0;
  if (lw_pair_walk(m->grid, &sc->pair, p->walked, nw, &f, &all, p->each, &p->near, NULL) != LW_OK) {
    memo_reset(p, m);
    return no_memory(p);
  }
  /* each walked probe's sum to its number, in place: walked_id rises, and
  ** walked_id[i] >= i */
  for (size_t i = nw; i-- > 0;) p->each[p->walked_id[i]] = p->each[i];
  for (size_t k = 0; k < 2 * n; k++) p->stand[k] = 0.0;
  for (size_t k = 0; k < p->near.n; k++) {
    lw_pair_near *q = &p->near.pair[k];
    q->probe = p->walked_id[q->probe];
    p->stand[q->probe] += near_stand_in(&sc->pair, &p->probe[q->probe], q);
  }
  if (side_partners(p, np) != LW_OK) {
    memo_reset(p, m);
    return no_memory(p);
  }
  double pe = 0.0, stand = 0.0;
  p->any_near = p->near.n > 0;
  for (size_t j = 0; j < p->n_seg; j++) {
    const size_t k = p->seg0 + j;
    double *sum = p->seg_sum + 4 * j;
    for (int side = 0; side < 2; side++) {
      if (side && mo->ok[k]) {
        sum[2] = mo->far[k];
        sum[3] = mo->stand[k];
        p->any_near |= mo->partners[k].n > 0;
        continue;
      }
      double fs = 0.0, ss = 0.0;
      for (size_t q = 0; q < np; q++) {
        fs += p->each[2 * (j * np + q) + (size_t)side];
        ss += p->stand[2 * (j * np + q) + (size_t)side];
      }
      sum[2 * side] = fs;
      sum[2 * side + 1] = ss;
    }
    if (!mo->ok[k]) {
      /* the old side, for the moves to come while the state stays */
      list_swap(&mo->partners[k], &p->side[2 * j + 1]);
      mo->far[k] = sum[2];
      mo->stand[k] = sum[3];
      mo->ok[k] = 1;
    }
    pe += sum[0] - sum[2];
    stand += sum[1] - sum[3];
  }
  p->stand_in = stand;
  p->walk_done = 1;
  return pe;
}

/* pe, the walk's far sum, with the near fields added (see pair_walk). */
static double pair_near_delta(const lw_model *m, lw_proposal *p, const lw_node *base, size_t g0, double pe)
{
  const lw_scene *sc = m->scene;
  const uint32_t np = (uint32_t)sc->pair_quad.n;
  const pair_view v = {m->grid, m->sp, np, &sc->pair, planes_of(sc)};
  p->partners.n = 0;
  p->near_vals.n = 0;
  for (size_t j = 0; j < p->n_seg; j++) {
    size_t g = g0 + p->seg0 + j;
    double bez[8];
    const lw_near_list *now = &p->side[2 * j];
    lw_segment_bezier(proposed_node(base, p, p->seg0 + j), proposed_node(base, p, p->seg0 + j + 1), bez);
    p->near_new[j] = near_part(&v, bez, p->ps + j * np, now, (uint32_t)g, &p->near_vals);
    pe += p->near_new[j];
    if (add_partners(p, now) != LW_OK) return no_memory(p);
    /* the old side's partners: the memo's (pair_walk filled it) */
    const lw_near_list *old = &p->memo.partners[p->seg0 + j];
    pe -= old_near(m, &v, g, &base[p->seg0 + j], p->ps_old + j * np, old);
    if (add_partners(p, old) != LW_OK) return no_memory(p);
  }
  return pe;
}

/* The cells of the 3 x 3 around (x, y) that hold samples and whose side
** facing (x, y) is nearer than sqrt(far2) (cells are at least the cutoff,
** and so min_spacing, wide), into near; returns how many. */
static inline int facing_cells(const lw_cellgrid *g, double x, double y, double far2, const lw_cell *near[9])
{
  const double side = 1.0 / g->inv_h;
  int cx, cy, n = 0;
  lw_cellgrid_locate(g, x, y, &cx, &cy);
  const double u = x - (g->x0 + cx * side), v = y - (g->y0 + cy * side);
  const double gx[3] = {u * u, 0.0, (side - u) * (side - u)}, gy[3] = {v * v, 0.0, (side - v) * (side - v)};
  for (int j = cy > 0 ? cy - 1 : 0; j <= cy + 1 && j < g->ny; j++)
    for (int i = cx > 0 ? cx - 1 : 0; i <= cx + 1 && i < g->nx; i++) {
      const lw_cell *c = &g->cell[(size_t)j * (size_t)g->nx + (size_t)i];
      if (c->n && gx[i - cx + 1] + gy[j - cy + 1] <= far2) near[n++] = c; /* an empty cell may have no block */
    }
  return n;
}

/* 1 if sample index e is one of the moving spline's own (f's ranges). */
static inline int own_sample(const lw_pair_filter *f, uint32_t e)
{
  return (e >= f->lo && e < f->hi) || (e >= f->lo2 && e < f->hi2);
}

/* How many pairs of one of the n samples ps and a sample of another spline
** (an index outside f's ranges [lo, hi) and [lo2, hi2)) are closer than
** sqrt(d2): the 3 x 3 cells around each (cells are at least the cutoff >=
** min_spacing wide), less those whose side facing the sample is farther
** than that, with a margin for the rounding of a point's cell (most of
** them: min_spacing is a fraction of the cell).  Edge cells hold the points
** clamped from beyond the grid on their outer sides only, so the facing
** sides bound them too. */
/* The reach of a cell-face test grown for the rounding of a point's cell
** and of the face's distance: a pair at the reach itself is never pruned by
** a face that rounding put a hair too far (crowding and closes_in). */
#define CELL_FACE_SLACK (1.0 + 1e-8)

static size_t crowding(const lw_cellgrid *grid, const lw_pair_sample *ps, size_t n, const lw_pair_filter *f,
                       double d2)
{
  lw_cellgrid view;
  const lw_cellgrid *g = lw_cellgrid_plane(grid, f->plane, &view);
  const double far2 = d2 * CELL_FACE_SLACK;
  size_t count = 0;
  for (size_t k = 0; k < n; k++) {
    const lw_cell *near[9];
    const int nc = facing_cells(g, ps[k].x, ps[k].y, far2, near);
    for (int j = 0; j < nc; j++) {
      const lw_cell *c = near[j];
      const double *xs = c->x, *ys = lw_cell_y(c);
      const uint32_t *idx = lw_cell_idx(c);
      for (uint32_t e = 0; e < c->n; e++) {
        if (own_sample(f, idx[e])) continue;
        double dx = xs[e] - ps[k].x, dy = ys[e] - ps[k].y;
        count += dx * dx + dy * dy < d2;
      }
    }
  }
  return count;
}

/*
** The spacing rule between the curves.  crowding counts pairs of samples,
** and two curves can meet between them: the photo preset's pair samples lie
** up to 1.9 min_spacing apart along a line, crossing strokes passed the
** count, and on a photograph the lines touched over 4 % of their length.
** So a move that passes the count is then asked how many of the other
** strokes' segments its curves touch (come within min_spacing of:
** lw_bezier_near2), against its old curves; a move that touches more is
** refused.  From a state whose curves keep the spacing none ever comes
** closer; a crowded start only sheds contacts, as it sheds sample pairs.
*/
enum { LW_CONTACTS_MAX = 64 };

typedef struct {
  uint32_t seg[LW_CONTACTS_MAX];
  int n, full; /* full: more than LW_CONTACTS_MAX, the rest unrecorded */
} contact_set;

static void contact_add(contact_set *cs, uint32_t h)
{
  for (int k = 0; k < cs->n; k++)
    if (cs->seg[k] == h) return;
  if (cs->n < LW_CONTACTS_MAX) cs->seg[cs->n++] = h;
  else cs->full = 1;
}

/* 1 if the move touches more segments than it did (a full set: may). */
static int contacts_grew(const contact_set *now, const contact_set *before)
{
  return now->full || now->n > before->n;
}

typedef struct {
  const lw_model *m;
  const lw_cellgrid *grid; /* the plane's */
  uint32_t np;             /* pair samples a segment */
} contact_view;

/* Adds h to cs when segment h's curve comes within min_spacing of the
** curve c, whose control box widened by min_spacing is box. */
static void contact_test(const contact_view *cv, const double c[8], const double box[4], uint32_t h, contact_set *cs)
{
  double b[8];
  segment_bezier(cv->m->sp, h, b);
  double bb[4];
  lw_bezier_box(b, 0.0, bb);
  if (!lw_boxes_meet(box, bb)) return;
  const double d = cv->m->scene->min_spacing;
  if (lw_bezier_near2(c, b, d) < d * d) contact_add(cs, h);
}

/* Adds to cs the other strokes' segments (outside f) whose curves come
** within min_spacing of the curve of the segment with control points c and
** pair samples ps.  A curve is found by its samples in the cells around
** c's (the box of their cells, one wider, each cell at least the cutoff):
** every point of a curve lies within half the widest gap between its
** samples of one of them, so a curve within min_spacing of c has a sample
** in those cells while min_spacing and the two half gaps add up to no more
** than the cutoff (in the photo preset 1 + 0.95 + 0.95 pen widths against
** 3).  Each segment met is measured once (a small table of those seen;
** a collision only measures one twice). */
static void segment_contacts(const contact_view *cv, const double c[8], const lw_pair_sample *ps,
                             const lw_pair_filter *f, contact_set *cs)
{
  enum { SEEN = 128 };
  const lw_cellgrid *g = cv->grid;
  const uint32_t np = cv->np;
  int x0 = g->nx, x1 = -1, y0 = g->ny, y1 = -1;
  for (uint32_t k = 0; k < np; k++) {
    int cx, cy;
    lw_cellgrid_locate(g, ps[k].x, ps[k].y, &cx, &cy);
    x0 = cx < x0 ? cx : x0, x1 = cx > x1 ? cx : x1, y0 = cy < y0 ? cy : y0, y1 = cy > y1 ? cy : y1;
  }
  x0 = x0 > 0 ? x0 - 1 : 0, y0 = y0 > 0 ? y0 - 1 : 0;
  x1 = x1 + 1 < g->nx ? x1 + 1 : g->nx - 1, y1 = y1 + 1 < g->ny ? y1 + 1 : g->ny - 1;
  double box[4];
  lw_bezier_box(c, cv->m->scene->min_spacing, box);
  uint32_t seen[SEEN];
  memset(seen, 0xff, sizeof seen);
  for (int y = y0; y <= y1; y++)
    for (int x = x0; x <= x1; x++) {
      const lw_cell *cell = &g->cell[(size_t)y * (size_t)g->nx + (size_t)x];
      const uint32_t *idx = cell->n ? lw_cell_idx(cell) : NULL; /* an empty cell may have no block */
      for (uint32_t e = 0; e < cell->n; e++) {
        if (own_sample(f, idx[e])) continue;
        const uint32_t h = idx[e] / np;
        if (seen[h % SEEN] == h) continue;
        seen[h % SEEN] = h;
        contact_test(cv, c, box, h, cs);
      }
    }
}

static contact_view contact_view_of(const lw_model *m, const lw_pair_filter *f, lw_cellgrid *view)
{
  return (contact_view){m, lw_cellgrid_plane(m->grid, f->plane, view), (uint32_t)pair_nodes(m)};
}

#define LW_CURVE_NEWTON 4 /* Newton steps to a curve's nearest point from its sample's */

/* The distance from p to segment h's curve where it stands, by Newton's
** method on (b(t) - p) . b'(t) from the parameter t of its sample nearest
** p, in [0, 1]. */
static double curve_distance(const lw_splines *sp, size_t h, double t, double px, double py)
{
  double c[8];
  const lw_node *a = &sp->node[lw_segment_node(sp, h)];
  lw_segment_bezier(a, a + 1, c);
  /* power form, as pairnear.c: b(t) = q0 + q1 t + q2 t^2 + q3 t^3 */
  double qx[4] = {c[0] - px, 3.0 * (c[2] - c[0]), 3.0 * (c[0] - 2.0 * c[2] + c[4]), c[6] - c[0] + 3.0 * (c[2] - c[4])};
  double qy[4] = {c[1] - py, 3.0 * (c[3] - c[1]), 3.0 * (c[1] - 2.0 * c[3] + c[5]), c[7] - c[1] + 3.0 * (c[3] - c[5])};
  double x = 0.0, y = 0.0;
  for (int it = 0; it < LW_CURVE_NEWTON; it++) {
    x = qx[0] + t * (qx[1] + t * (qx[2] + t * qx[3]));
    y = qy[0] + t * (qy[1] + t * (qy[2] + t * qy[3]));
    const double dx = qx[1] + t * (2.0 * qx[2] + 3.0 * t * qx[3]), dy = qy[1] + t * (2.0 * qy[2] + 3.0 * t * qy[3]);
    const double ddx = 2.0 * qx[2] + 6.0 * t * qx[3], ddy = 2.0 * qy[2] + 6.0 * t * qy[3];
    const double f = x * dx + y * dy, fp = dx * dx + dy * dy + x * ddx + y * ddy;
    if (!(fp > 0.0)) break;
    t = fmin(1.0, fmax(0.0, t - f / fp));
  }
  x = qx[0] + t * (qx[1] + t * (qx[2] + t * qx[3]));
  y = qy[0] + t * (qy[1] + t * (qy[2] + t * qy[3]));
  return sqrt(x * x + y * y);
}

/* The curves near one check point, each once, from its sample nearest the
** point; past NEAR_CURVES of them each sample is asked at once. */
enum { NEAR_CURVES = 32 };
typedef struct {
  uint32_t seg[NEAR_CURVES];
  double t0[NEAR_CURVES], ds0[NEAR_CURVES];
  int n;
} near_curves;

/* 1 if segment h's curve, which may move by r, is one the check point at
** now (from before) comes within min_spacing + r of without moving away
** from it by more than r; t: the parameter to start Newton from. */
static int point_closes(const lw_model *m, const lw_step_margins *mg, uint32_t h, double t, const lw_pair_sample *now,
                        const lw_pair_sample *before)
{
  const double r = mg->reach[h], dc = curve_distance(m->sp, h, t, now->x, now->y);
  return dc < m->scene->min_spacing + r && dc < curve_distance(m->sp, h, t, before->x, before->y) + r;
}

/* Notes the sample of segment h at parameter t, ds (squared) from the
** check point; 1 if it must be asked at once and closes in. */
static int note_curve(const lw_model *m, const lw_step_margins *mg, near_curves *nc, uint32_t h, double t, double ds,
                      const lw_pair_sample *now, const lw_pair_sample *before)
{
  int j = 0;
  while (j < nc->n && nc->seg[j] != h) j++;
  if (j < nc->n) {
    if (ds < nc->ds0[j]) nc->ds0[j] = ds, nc->t0[j] = t;
  } else if (nc->n < NEAR_CURVES) {
    nc->seg[nc->n] = h, nc->t0[nc->n] = t, nc->ds0[nc->n] = ds;
    nc->n++;
  } else if (point_closes(m, mg, h, t, now, before)) {
    return 1;
  }
  return 0;
}

static int curves_close(const lw_model *m, const lw_step_margins *mg, const near_curves *nc, const lw_pair_sample *now,
                        const lw_pair_sample *before)
{
  for (int j = 0; j < nc->n; j++)
    if (point_closes(m, mg, nc->seg[j], nc->t0[j], now, before)) return 1;
  return 0;
}

/* A sample that may be near one of a segment's check points (closes_in):
** within its curve's reach of the points' box. */
typedef struct {
  double x, y, within;
  uint32_t idx;
  int cx, cy; /* its cell */
} crowd_candidate;

enum { CROWD_CANDIDATES = 512 };

/* The samples of other strokes within their reach (min_spacing + gap / 2 +
** reach of their segment) of the box of the n check points, from the cells
** any point's 3 x 3 holds, in the order each point's scan of its cells meets
** them (rows of cells, then entries); -1 if more than CROWD_CANDIDATES.
** Rounding is monotone, so a sample whose distance from the box is within
** is never nearer a point than within. */
static int crowd_candidates(const lw_model *m, const lw_cellgrid *g, const lw_pair_sample *pt, size_t n, double d,
                            const lw_pair_filter *f, const lw_step_margins *mg, uint32_t np, crowd_candidate *out)
{
  const double spacing = m->scene->min_spacing;
  double bx0 = INFINITY, bx1 = -INFINITY, by0 = INFINITY, by1 = -INFINITY;
  for (size_t k = 0; k < n; k++)
    bx0 = fmin(bx0, pt[k].x), bx1 = fmax(bx1, pt[k].x), by0 = fmin(by0, pt[k].y), by1 = fmax(by1, pt[k].y);
  /* every cell a point's facing test takes meets the box widened by d */
  int x0, x1, y0, y1;
  lw_cellgrid_locate(g, bx0 - d, by0 - d, &x0, &y0);
  lw_cellgrid_locate(g, bx1 + d, by1 + d, &x1, &y1);
  int count = 0;
  for (int cy = y0; cy <= y1; cy++)
    for (int cx = x0; cx <= x1; cx++) {
      const lw_cell *c = &g->cell[(size_t)cy * (size_t)g->nx + (size_t)cx];
      if (!c->n) continue; /* an empty cell may have no block */
      const double *xs = c->x, *ys = lw_cell_y(c);
      const uint32_t *idx = lw_cell_idx(c);
      for (uint32_t e = 0; e < c->n; e++) {
        if (own_sample(f, idx[e])) continue;
        const uint32_t h = idx[e] / np;
        const double within = spacing + 0.5 * mg->gap[h] + mg->reach[h];
        const double dx = fmax(0.0, fmax(bx0 - xs[e], xs[e] - bx1)), dy = fmax(0.0, fmax(by0 - ys[e], ys[e] - by1));
        if (dx * dx + dy * dy >= within * within) continue;
        if (count == CROWD_CANDIDATES) return -1;
        out[count++] = (crowd_candidate){xs[e], ys[e], within, idx[e], cx, cy};
      }
    }
  return count;
}

/* 1 if a check point moved from before[k] to now[k] comes within
** min_spacing + r of another stroke's curve without moving away from it by
** more than r, r how far that curve may move (mg->reach of its segment):
** then the two may end closer than they were, and closer than the spacing.
** The curves near a point are found by their samples: within min_spacing of
** a curve is within min_spacing + gap / 2 of one of its samples, gap the
** widest space between them (mg->gap).  The samples near the segment are
** gathered once (crowd_candidates) and each point asks them in the order of
** its own scan of the cells around it, which it falls back to when they are
** too many, so both ways decide alike.  Gathering once: the quench's cut
** d reaches as far as its farthest-moving segment, which is most of 9 cells
** a point, where each sample's own reach is far less. */
static int closes_in(const lw_model *m, const lw_pair_sample *now, const lw_pair_sample *before, size_t n,
                     const lw_pair_filter *f, double d2, const lw_step_margins *mg, uint32_t np)
{
  lw_cellgrid view;
  const lw_cellgrid *g = lw_cellgrid_plane(m->grid, f->plane, &view);
  const lw_quad *quad = m->terms.ctx[m->terms.pair].quad;
  const double far2 = d2 * CELL_FACE_SLACK, spacing = m->scene->min_spacing;
  crowd_candidate cand[CROWD_CANDIDATES];
  /* (gathered a little wider again: none that a point's own scan of its
  ** cells would find may be missing) */
  const int n_cand = crowd_candidates(m, g, now, n, sqrt(far2) * (1.0 + 1e-6), f, mg, np, cand);
  const double side = 1.0 / g->inv_h;
  for (size_t k = 0; k < n; k++) {
    near_curves nc;
    nc.n = 0;
    if (n_cand >= 0) {
      int cx, cy;
      lw_cellgrid_locate(g, now[k].x, now[k].y, &cx, &cy);
      /* facing_cells' test, cell by cell */
      const double u = now[k].x - (g->x0 + cx * side), v = now[k].y - (g->y0 + cy * side);
      const double gx[3] = {u * u, 0.0, (side - u) * (side - u)}, gy[3] = {v * v, 0.0, (side - v) * (side - v)};
      for (int e = 0; e < n_cand; e++) {
        const crowd_candidate *c = &cand[e];
        const int di = c->cx - cx + 1, dj = c->cy - cy + 1;
        if (di < 0 || di > 2 || dj < 0 || dj > 2 || gx[di] + gy[dj] > far2) continue;
        const double dx = c->x - now[k].x, dy = c->y - now[k].y, ds = dx * dx + dy * dy;
        if (ds >= c->within * c->within) continue;
        if (note_curve(m, mg, &nc, c->idx / np, quad->s[c->idx % np], ds, &now[k], &before[k])) return 1;
      }
    } else {
      const lw_cell *cells[9];
      const int ncell = facing_cells(g, now[k].x, now[k].y, far2, cells);
      for (int cj = 0; cj < ncell; cj++) {
        const lw_cell *c = cells[cj];
        const double *xs = c->x, *ys = lw_cell_y(c);
        const uint32_t *idx = lw_cell_idx(c);
        for (uint32_t e = 0; e < c->n; e++) {
          if (own_sample(f, idx[e])) continue;
          const uint32_t h = idx[e] / np;
          const double dx = xs[e] - now[k].x, dy = ys[e] - now[k].y, ds = dx * dx + dy * dy;
          const double within = spacing + 0.5 * mg->gap[h] + mg->reach[h];
          if (ds >= within * within) continue; /* ds: squared */
          if (note_curve(m, mg, &nc, h, quad->s[idx[e] % np], ds, &now[k], &before[k])) return 1;
        }
      }
    }
    if (curves_close(m, mg, &nc, &now[k], &before[k])) return 1;
  }
  return 0;
}

/* The check points of the spacing rule for a step (lw_model_segment_crowds):
** LW_CROWD_POINTS per pair sample, evenly in the segment's parameter.  The
** other curve is measured exactly; the moving one only at these points, so
** between two of them it could come closer: with two a sample a quench
** still brought sample pairs within min_spacing (tests/test_tone.c), with
** four none. */
#define LW_CROWD_POINTS 4

static size_t check_points(const lw_node *a, const lw_node *b, int np, lw_pair_sample *out)
{
  double c[8];
  lw_segment_bezier(a, b, c);
  const size_t n = (size_t)np * LW_CROWD_POINTS;
  for (size_t k = 0; k < n; k++) {
    const double t = (k + 0.5) / (double)n, u = 1.0 - t;
    const double w0 = u * u * u, w1 = 3.0 * u * u * t, w2 = 3.0 * u * t * t, w3 = t * t * t;
    out[k] = (lw_pair_sample){w0 * c[0] + w1 * c[2] + w2 * c[4] + w3 * c[6],
                              w0 * c[1] + w1 * c[3] + w2 * c[5] + w3 * c[7], 0.0f};
  }
  return n;
}

int lw_model_segment_crowds(const lw_model *m, size_t g, const lw_node *a, const lw_node *b,
                            const lw_step_margins *mg)
{
  const lw_scene *sc = m->scene;
  if (!(sc->min_spacing > 0.0) || !m->grid || m->terms.pair < 0) return 0;
  const lw_splines *sp = m->sp;
  const int np = pair_nodes(m);
  const uint32_t i = sp->seg_spline[g];
  lw_pair_sample now[LW_QUAD_MAX * LW_CROWD_POINTS], before[LW_QUAD_MAX * LW_CROWD_POINTS];
  const size_t n = check_points(a, b, np, now);
  const lw_node *o = &sp->node[lw_segment_node(sp, g)];
  check_points(o, o + 1, np, before);
  const uint32_t lo = (uint32_t)(lw_segment_index(sp, i, 0) * (size_t)np);
  const lw_pair_filter own = {.lo = lo, .hi = lo + (uint32_t)(lw_splines_segments(sp, i) * (size_t)np),
                              .plane = plane_of(planes_of(sc), sp, i)};
  /* closes_in looks one cell around a point: the cells are at least the cutoff */
  const double cut = pair_ctx(&m->terms.ctx[m->terms.pair])->cutoff;
  const double d = fmin(sc->min_spacing + 0.5 * mg->gap_max + mg->reach_max, cut);
  return closes_in(m, now, before, n, &own, d * d, mg, (uint32_t)np);
}

void lw_model_sample_gaps(const lw_model *m, double *gap)
{
  const lw_splines *sp = m->sp;
  if (!m->grid || m->terms.pair < 0) {
    for (size_t g = 0; g < sp->n_segments; g++) gap[g] = 0.0;
    return;
  }
  const int np = pair_nodes(m);
  const pair_view v = {m->grid, sp, (uint32_t)np, pair_ctx(&m->terms.ctx[m->terms.pair]), planes_of(m->scene)};
  lw_pair_sample ps[LW_QUAD_MAX];
  for (size_t g = 0; g < sp->n_segments; g++) {
    samples_at(&v, (uint32_t)(g * (size_t)np), (size_t)np, ps);
    double w = 0.0;
    for (int q = 1; q < np; q++) w = fmax(w, hypot(ps[q].x - ps[q - 1].x, ps[q].y - ps[q - 1].y));
    gap[g] = w;
  }
}

/* A raster term's part of dE (no coefficient): the affected segments' old
** samples splatted out of and their new ones into a box of changes, and
** the energy difference over the box.  NAN if the box cannot grow. */
static double raster_delta(const lw_model *m, lw_proposal *p, int t, const lw_node *base)
{
  const int layer = layer_of(&m->terms, m->sp, p->spline);
  const lw_term_ctx *c = &ctx_in(&m->terms, layer)[t];
  lw_tone_box *b = &p->box[t];
  lw_tone_box_reset(b);
  for (size_t j = 0; j < p->n_seg; j++) {
    const size_t k = p->seg0 + j;
    raster_cover(c->data, b, &base[k], &base[k + 1]);
    raster_cover(c->data, b, proposed_node(base, p, k), proposed_node(base, p, k + 1));
  }
  if (lw_tone_box_ready(b) != LW_OK) return no_memory(p);
  for (size_t j = 0; j < p->n_seg; j++) {
    const size_t k = p->seg0 + j;
    raster_segment(c, b, &base[k], &base[k + 1], -1);
    raster_segment(c, b, proposed_node(base, p, k), proposed_node(base, p, k + 1), 1);
  }
  return lw_tone_delta(c->data, m->raster[t] + plane_in(layer, c->data), b);
}

/* Whether a proposed node lies beyond what a state file holds
** (LW_STATE_COORD_MAX): such a state is forbidden, so that every state the
** chain reaches can be checkpointed and resumed (a spline free of the
** boundary would otherwise wander there by translations). */
static int beyond_state_range(const lw_node *node, size_t n)
{
  for (size_t i = 0; i < n; i++)
    if (!(fabs(node[i].px) <= LW_STATE_COORD_MAX && fabs(node[i].py) <= LW_STATE_COORD_MAX &&
          fabs(node[i].vx) <= LW_STATE_COORD_MAX && fabs(node[i].vy) <= LW_STATE_COORD_MAX))
      return 1;
  return 0;
}

void lw_model_propose(const lw_model *m, lw_proposal *p, uint32_t spline, size_t node0,
                      size_t n_node, const lw_node *nodes)
{
  const lw_scene *sc = m->scene;
  const lw_splines *sp = m->sp;
  const lw_term_set *ts = &m->terms;
  const lw_term_ctx *pc = ts->pair >= 0 ? &ts->ctx[ts->pair] : NULL;
  const int np = pair_nodes(m), nl = sc->n_local;
  const size_t nseg = lw_splines_segments(sp, spline);
  const lw_node *base = &sp->node[sp->first[spline]];
  const size_t g0 = lw_segment_index(sp, spline, 0);

  p->splice = 0;
  p->log_ratio = 0.0;
  p->spline = spline;
  p->node0 = node0;
  p->n_node = n_node;
  if (nodes && nodes != p->node) memcpy(p->node, nodes, n_node * sizeof *nodes);
  p->seg0 = node0 > 0 ? node0 - 1 : 0;
  size_t seg_end = node0 + n_node < nseg ? node0 + n_node : nseg; /* one past the last */
  p->n_seg = seg_end - p->seg0;
  for (int t = 0; t < LW_TERM_COUNT; t++) p->dterm[t] = 0.0;

  lw_samples s;
  double dlen = 0.0;
  int forbidden = beyond_state_range(p->node, n_node), undefined = 0; /* +inf new energy; a NaN value */
  int was_irregular = 0;            /* an affected segment is irregular now */
  p->irregular = 0;
  for (size_t j = 0; j < p->n_seg; j++) {
    size_t m_loc = p->seg0 + j, g = g0 + m_loc;
    double *local = p->local + j * (size_t)nl;
    p->seg_irregular[j] = !segment_eval(sc, ctx_of(ts, sp, spline), proposed_node(base, p, m_loc),
                                        proposed_node(base, p, m_loc + 1), &s, &p->len[j], local,
                                        pc ? pc->quad : NULL, m->grid ? p->ps + j * (size_t)np : NULL);
    p->irregular |= p->seg_irregular[j];
    was_irregular |= m->seg_irregular[g];
    const double *old = m->seg_local + g * (size_t)nl;
    for (int t = 0; t < nl; t++) {
      p->dterm[sc->local[t]] += local[t] - old[t];
      if (local[t] == INFINITY) forbidden = 1;
      else if (isnan(local[t])) undefined = 1;
    }
    if (isnan(p->len[j])) undefined = 1;
    dlen += p->len[j] - m->seg_len[g];
  }
  p->new_spline_len = m->spline_len[spline] + dlen;

  for (int k = 0; k < ts->n_spline; k++) {
    /* the moved segments' lengths after the move, against the cached ones */
    const int t = ts->spline[k];
    const lw_term_ctx *c = &ts->ctx[t];
    p->dterm[t] = c->coef * lw_term_types[t].spline_change(m->seg_len + g0 + p->seg0, p->len, p->n_seg, nseg,
                                                           m->spline_len[spline], p->new_spline_len,
                                                           sp->rest_length[spline], c);
  }

  double dE = 0.0;
  for (int t = 0; t < LW_TERM_COUNT; t++) dE += p->dterm[t];
  /* A forbidden new state is +inf whatever the old one was: from a forbidden
  ** state the difference would be inf - inf, and NaN is kept for numerical
  ** failures (a NaN energy, counted by the chain). */
  if ((forbidden || p->irregular) && !undefined) dE = INFINITY;
  /* Leaving an irregular state (+inf) for a regular one lowers the energy
  ** without bound, whatever the terms do (like leaving a +inf local term). */
  else if (was_irregular && !undefined) dE = -INFINITY;
  /* The pair sum is the costly part: skip it when the move is already
  ** forbidden (+inf) or undefined (NaN). */
  p->pair_done = 0;
  if (m->grid) {
    /* the old samples, from the grid: the walk's old side and a failed commit's undo */
    pair_view v = {m->grid, sp, (uint32_t)np, pair_ctx(pc), planes_of(sc)};
    size_t first = (g0 + p->seg0) * (size_t)np, n = p->n_seg * (size_t)np;
    samples_at(&v, (uint32_t)first, n, p->ps_old);
  }
  p->crowded = 0;
  p->curves_pending = 0;
  if (sc->min_spacing > 0.0 && !(dE == INFINITY) && !isnan(dE)) {
    const size_t n = p->n_seg * (size_t)np;
    const uint32_t lo = (uint32_t)(g0 * (size_t)np), hi = (uint32_t)((g0 + nseg) * (size_t)np);
    const double d2 = sc->min_spacing * sc->min_spacing;
    const lw_pair_filter own = {.lo = lo, .hi = hi, .plane = plane_of(planes_of(sc), sp, p->spline)};
    size_t now = crowding(m->grid, p->ps, n, &own, d2);
    /* the old side only when it matters: a move into free room is the rule */
    if (now > 0 && now > crowding(m->grid, p->ps_old, n, &own, d2)) {
      p->crowded = 1;
      dE = INFINITY;
    }
    /* the curves wait for lw_model_propose_finish: only a move the chain
    ** would take needs them */
    p->curves_pending = !p->crowded && !isnan(dE);
  }
  p->near_pending = 0;
  if (m->grid && !(dE == INFINITY) && !isnan(dE)) {
    double pe = pair_walk(m, p);
    /* (a move out of an irregular state, dE = -inf, is taken whatever the
    ** pair part: nothing to defer) */
    if (p->defer_near && !isnan(pe) && p->any_near && isfinite(dE)) {
      /* the near field waits for lw_model_propose_finish: a stand-in here */
      p->near_pending = 1;
      p->pe_walk = pe;
      p->dE_pre_pair = dE;
      p->dterm[ts->pair] = pc->coef * (pe + p->stand_in);
    } else {
      if (!isnan(pe)) pe = pair_near_delta(m, p, base, g0, pe);
      p->pair_done = !isnan(pe);
      p->dterm[ts->pair] = pc->coef * pe;
    }
    dE += p->dterm[ts->pair];
  }
  p->raster_done = 0;
  if (ts->n_raster && !(dE == INFINITY) && !isnan(dE)) {
    for (int k = 0; k < ts->n_raster; k++) {
      const int t = ts->raster[k];
      const double re = raster_delta(m, p, t, base);
      p->dterm[t] = ts->ctx[t].coef * re;
      dE += p->dterm[t];
    }
    p->raster_done = !isnan(dE);
  }
  p->dE = dE;
}

/* The near field a proposal left out (delayed acceptance): what it adds to dE. */
static double finish_near(const lw_model *m, lw_proposal *p)
{
  if (!p->near_pending) return 0.0;
  const lw_term_set *ts = &m->terms;
  const lw_splines *sp = m->sp;
  const double before = p->dE;
  p->near_pending = 0;
  double pe = pair_near_delta(m, p, &sp->node[sp->first[p->spline]], lw_segment_index(sp, p->spline, 0),
                              p->pe_walk);
  p->pair_done = !isnan(pe);
  p->dterm[ts->pair] = ts->ctx[ts->pair].coef * pe;
  /* the same sum in the same order as a proposal that did not wait */
  double dE = p->dE_pre_pair + p->dterm[ts->pair];
  for (int k = 0; p->raster_done && k < ts->n_raster; k++) dE += p->dterm[ts->raster[k]];
  p->dE = dE;
  return dE - before;
}


static lw_status commit_splice(lw_model *m, const lw_proposal *p);
static void splice_kept_samples(const lw_model *m, lw_proposal *p);

/* The memo after p's move, committed as serial: the moved segments hold the
** walk's new side; the spline's others keep theirs if no other change came
** between (serial - 1 is the state the move was proposed in). */
static void memo_commit(const lw_model *m, lw_proposal *p, uint64_t serial)
{
  lw_far_memo *mo = &p->memo;
  if (mo->model != m || mo->spline != p->spline || mo->serial != serial - 1) memo_reset(p, m);
  mo->serial = serial;
  for (size_t j = 0; j < p->n_seg; j++) {
    const size_t k = p->seg0 + j;
    mo->ok[k] = (unsigned char)p->walk_done;
    list_swap(&mo->partners[k], &p->side[2 * j]);
    mo->far[k] = p->seg_sum[4 * j];
    mo->stand[k] = p->seg_sum[4 * j + 1];
  }
}

/* The commit without the running totals (model.h): everything but m->term
** and m->n_irregular, whose changes go into p's own sums.  Moves only: a
** splice is committed whole by lw_model_commit. */
lw_status lw_model_commit_part(lw_model *m, lw_proposal *p)
{
  p->curves_pending = 0; /* a commit takes the move as it is */
  (void)finish_near(m, p);
  lw_splines *sp = m->sp;
  const int np = pair_nodes(m), nl = m->scene->n_local;
  const size_t g0 = lw_segment_index(sp, p->spline, 0);
  if (m->grid) {
    size_t first = (g0 + p->seg0) * (size_t)np, n = p->n_seg * (size_t)np;
    const lw_pair_sample *old = p->ps_old, *now = p->ps;
    for (size_t k = 0; k < n; k++)
      if (lw_cellgrid_move(m->grid, (uint32_t)(first + k), now[k].x, now[k].y, now[k].dl) != LW_OK) {
        /* Put the moved ones back: their old cells kept their capacity, so
        ** this cannot fail, and the model is as before the call. */
        for (size_t b = 0; b < k; b++)
          lw_cellgrid_move(m->grid, (uint32_t)(first + b), old[b].x, old[b].y, old[b].dl);
        return LW_ENOMEM;
      }
  }
  memcpy(&sp->node[sp->first[p->spline] + p->node0], p->node, p->n_node * sizeof *p->node);
  const uint64_t serial = state_changed(m);
  if (m->grid) memo_commit(m, p, serial);
  if (m->grid) {
    if (p->pair_done) {
      /* A partner may be shared with a move in another domain (domains.h):
      ** both only clear its flag, as relaxed atomic stores, and forget or
      ** rewrite their own pairs in its slots. */
      const size_t g1 = g0 + p->seg0;
      for (size_t k = 0; k < p->partners.n; k++) {
        __atomic_store_n(&m->near_valid[p->partners.idx[k]], 0, __ATOMIC_RELAXED);
        for (size_t j = 0; j < p->n_seg; j++) slot_clear(m, p->partners.idx[k], (uint32_t)(g1 + j));
      }
      slots_reset(m, g1, p->n_seg);
      for (size_t j = 0; j < p->n_seg; j++) {
        m->near_cache[g1 + j] = p->near_new[j];
        m->near_valid[g1 + j] = 1;
      }
      for (size_t k = 0; k < p->near_vals.n; k++) {
        const lw_near_value *q = &p->near_vals.v[k];
        slot_store(m, q->seg, q->partner, q->value);
        slot_store(m, q->partner, q->seg, q->value);
      }
    } else {
      /* committed without a pair evaluation: its partners are unknown */
      memset(m->near_valid, 0, sp->n_segments * sizeof *m->near_valid);
      slots_reset(m, 0, sp->n_segments);
    }
  }
  for (size_t j = 0; j < p->n_seg; j++) {
    size_t g = g0 + p->seg0 + j;
    m->seg_len[g] = p->len[j];
    memcpy(m->seg_local + g * (size_t)nl, p->local + j * (size_t)nl, (size_t)nl * sizeof *m->seg_local);
    p->sum_irregular += (long)p->seg_irregular[j] - (long)m->seg_irregular[g];
    m->seg_irregular[g] = p->seg_irregular[j];
  }
  /* summed afresh rather than updated by += dlen (spline_length) */
  const size_t n = lw_splines_segments(sp, p->spline);
  for (size_t b = p->seg0 / LW_TERM_LEN_BLOCK; m->seg_block && b * LW_TERM_LEN_BLOCK < p->seg0 + p->n_seg; b++)
    m->seg_block[g0 + b * LW_TERM_LEN_BLOCK] = lw_term_block_sum(m->seg_len + g0, n, b * LW_TERM_LEN_BLOCK);
  m->spline_len[p->spline] = lw_term_spline_length(m->seg_len + g0, n, m->seg_block ? m->seg_block + g0 : NULL);
  for (int k = 0; p->raster_done && k < m->terms.n_raster; k++) {
    const int t = m->terms.raster[k];
    const int layer = layer_of(&m->terms, sp, p->spline);
    const lw_tone *tn = ctx_in(&m->terms, layer)[t].data;
    lw_tone_apply(tn, m->raster[t] + plane_in(layer, tn), &p->box[t]);
  }
  for (int t = 0; t < LW_TERM_COUNT; t++) p->sum_term[t] += p->dterm[t];
  if (m->terms.n_raster && !p->raster_done) p->sum_stale = 1;
  return LW_OK;
}

lw_status lw_model_merge(lw_model *m, lw_proposal *p)
{
  int nonfinite = 0;
  m->n_irregular = (size_t)((long)m->n_irregular + p->sum_irregular);
  for (int t = 0; t < LW_TERM_COUNT; t++) {
    m->term[t] += p->sum_term[t];
    if (!isfinite(m->term[t])) nonfinite = 1;
    p->sum_term[t] = -0.0;
  }
  int stale = p->sum_stale;
  p->sum_irregular = 0;
  p->sum_stale = 0;
  /* inf - inf leaves NaN in a running total: leaving a forbidden state is
  ** legal, so rebuild the totals from the caches when that happens; the
  ** same when a raster was not evaluated (its changes are unknown). */
  if (nonfinite || stale) return lw_model_refresh(m, NULL);
  return LW_OK;
}

lw_status lw_model_commit(lw_model *m, lw_proposal *p)
{
  if (p->splice) {
    splice_kept_samples(m, p);
    return commit_splice(m, p);
  }
  lw_status s = lw_model_commit_part(m, p);
  return s != LW_OK ? s : lw_model_merge(m, p);
}

/* ---- trans-dimensional proposals (splices) --------------------------------
** The splines replaced (p->n_old, their samples from the grid) and the new
** ones (p->n_new, from p->node) are whole splines: every term is differenced
** over them alone, as lw_model_propose does over the segments a move
** touches.  The walk's probes are the new samples (+1) followed by the old
** ones (-1). */

/* The sorted segments of the near pairs of probes [lo, lo + np). */
static lw_status near_of_probes(const lw_proposal *p, uint32_t np, size_t lo, lw_near_list *segs)
{
  segs->n = 0;
  for (size_t k = 0; k < p->near.n; k++) {
    const lw_pair_near *q = &p->near.pair[k];
    if (q->probe < lo || q->probe >= lo + np) continue;
    if (set_insert(segs, q->idx / np) != LW_OK) return LW_ENOMEM;
  }
  return LW_OK;
}

/* The node where new segment j of a splice starts: the new splines' nodes
** lie one after the other, so a second spline's segments skip one node. */
static size_t splice_seg_node(const lw_proposal *p, size_t j)
{
  return j + (p->n_new == 2 && j + 1 >= p->new_node[0]);
}

/* 1 if a splice keeps its new segment j, its old segment o (splice_kept). */
static int kept_new(const lw_proposal *p, size_t j) { return j < 64 && p->kept_new >> j & 1; }
static int kept_old(const lw_proposal *p, size_t o) { return o < 64 && p->kept_old >> o & 1; }

/* The old splines' sample ranges, in increasing order as the walk wants
** them: what a splice's pair sums and spacing leave out. */
static lw_pair_filter old_filter(const pair_view *v, const lw_proposal *p)
{
  /* a splice's splines are all of the proposal's layer */
  if (!p->n_old) return (lw_pair_filter){.plane = v->planes ? p->layer : 0};
  lw_pair_filter f = filter_of(v, p->old[0], 0);
  if (p->n_old == 2) {
    lw_pair_filter g = filter_of(v, p->old[1], 0);
    if (g.lo < f.lo) {
      const lw_pair_filter t = f;
      f = g;
      g = t;
    }
    f.lo2 = g.lo;
    f.hi2 = g.hi;
  }
  return f;
}

/*
** The pair energy (no coefficient) of spline a (na segments from the nodes
** a, pair samples sa) with spline b, as the walk and the near field count
** it together (pair.h): every far sample pair by the product rule, and the
** near correction of every segment pair with a near sample pair.  The two
** pieces of a split and the two halves of a join are not in the grid as
** separate splines, so no walk sees their pairs.  O(na nb np^2): a splice's
** own splines only.
*/
static double pair_between(const lw_pair_ctx *ctx, uint32_t np, const lw_node *a, const lw_pair_sample *sa, size_t na,
                           const lw_node *b, const lw_pair_sample *sb, size_t nb)
{
  const double ic = ctx->inv_cutoff, rc2 = ctx->cutoff2;
  const int with_near = ctx->near_scale > 0.0;
  double far = 0.0, near = 0.0;
  for (size_t i = 0; i < na; i++)
    for (size_t j = 0; j < nb; j++) {
      const lw_pair_sample *x = sa + i * np, *y = sb + j * np;
      int is_near = 0;
      for (uint32_t q = 0; q < np; q++)
        for (uint32_t r = 0; r < np; r++) {
          const double dx = x[q].x - y[r].x, dy = x[q].y - y[r].y, r2 = dx * dx + dy * dy;
          if (with_near && r2 < lw_pair_near_radius2(ctx, x[q].dl, y[r].dl)) is_near = 1;
          else if (r2 < rc2 && x[q].dl > 0.0f && y[r].dl > 0.0f)
            far += (double)x[q].dl * (double)y[r].dl * (1.0 / sqrt(r2) - ic);
        }
      if (is_near) {
        double ba[8], bb[8];
        lw_segment_bezier(&a[i], &a[i + 1], ba);
        lw_segment_bezier(&b[j], &b[j + 1], bb);
        near += lw_pair_near_correction(ba, x, bb, y, (int)np, ctx);
      }
    }
  return far + near;
}

/* How many pairs of a sample of a (na) and one of b (nb) are closer than
** sqrt(d2): the spacing between a splice's two new or two old splines. */
static size_t crowded_pairs(const lw_pair_sample *a, size_t na, const lw_pair_sample *b, size_t nb, double d2)
{
  size_t count = 0;
  for (size_t i = 0; i < na; i++)
    for (size_t j = 0; j < nb; j++) {
      const double dx = a[i].x - b[j].x, dy = a[i].y - b[j].y;
      count += dx * dx + dy * dy < d2;
    }
  return count;
}

/* The old nodes of old spline k of a splice. */
static const lw_node *splice_old_nodes(const lw_model *m, const lw_proposal *p, int k)
{
  return &m->sp->node[m->sp->first[p->old[k]]];
}

/* What a split's two pieces have with each other, less what a join's two
** splines had: the pairs no walk of a splice sees. */
static double splice_pair_between(const lw_model *m, const lw_proposal *p, const pair_view *v)
{
  const uint32_t np = v->np;
  double pe = 0.0;
  if (p->n_new == 2) {
    const size_t n0 = p->new_node[0] - 1;
    pe += pair_between(v->ctx, np, p->node, p->ps, n0, p->node + n0 + 1, p->ps + n0 * np, p->new_node[1] - 1);
  }
  if (p->n_old == 2)
    pe -= pair_between(v->ctx, np, splice_old_nodes(m, p, 0), p->ps_old, p->old_seg[0], splice_old_nodes(m, p, 1),
                       p->ps_old + p->old_seg[0] * np, p->old_seg[1]);
  return pe;
}

/* The pair part of a splice's dE (no coefficient); NAN if out of memory.
** With one old spline its near field comes from the cache as for a move;
** with two (a join) each one's cached near field holds the other too, so
** both are summed afresh from the walk, which leaves both out, and their
** pair with each other is taken away whole. */
static double splice_pair_delta(const lw_model *m, lw_proposal *p)
{
  const lw_scene *sc = m->scene;
  const uint32_t np = (uint32_t)sc->pair_quad.n;
  const pair_view v = {m->grid, m->sp, np, &sc->pair, planes_of(sc)};
  const size_t nn = p->n_seg * np, no = p->n_old_seg * np;
  /* an inserted spline has no samples in the grid yet: nothing to leave out */
  const lw_pair_filter f = old_filter(&v, p);
  double pe;
  p->near.n = 0;
  p->partners.n = 0;
  if (!(sc->pair.near_scale > 0.0)) {
    /* without the near field a kept segment's pairs with other strokes are
    ** the same before and after (the pair term leaves a spline's own
    ** pairs out, and the splines of a splice meet in pair_between): only
    ** the segments that change are walked, one of a grow's 2 n + 1 */
    size_t n = 0;
    for (size_t j = 0; j < p->n_seg; j++)
      for (size_t q = 0; !kept_new(p, j) && q < np; q++, n++) {
        const lw_pair_sample *x = &p->ps[j * np + q];
        p->probe[n] = (lw_pair_probe){x->x, x->y, x->dl, 1.0};
      }
    for (size_t o = 0; o < p->n_old_seg; o++)
      for (size_t q = 0; !kept_old(p, o) && q < np; q++, n++) {
        const lw_pair_sample *x = &p->ps_old[o * np + q];
        p->probe[n] = (lw_pair_probe){x->x, x->y, x->dl, -1.0};
      }
    if (lw_pair_walk(m->grid, &sc->pair, p->probe, n, &f, &pe, NULL, &p->near, NULL) != LW_OK) return no_memory(p);
    for (size_t j = 0; j < p->n_seg; j++) p->near_new[j] = 0.0;
    return pe + splice_pair_between(m, p, &v);
  }
  for (size_t k = 0; k < nn; k++) p->probe[k] = (lw_pair_probe){p->ps[k].x, p->ps[k].y, p->ps[k].dl, 1.0};
  for (size_t k = 0; k < no; k++)
    p->probe[nn + k] = (lw_pair_probe){p->ps_old[k].x, p->ps_old[k].y, p->ps_old[k].dl, -1.0};
  if (lw_pair_walk(m->grid, &sc->pair, p->probe, nn + no, &f, &pe, NULL, &p->near, NULL) != LW_OK) return no_memory(p);
  for (size_t j = 0; j < p->n_seg; j++) {
    double bez[8];
    const size_t a = splice_seg_node(p, j);
    if (near_of_probes(p, np, j * np, &p->segs) != LW_OK) return no_memory(p);
    lw_segment_bezier(&p->node[a], &p->node[a + 1], bez);
    p->near_new[j] = near_part(&v, bez, p->ps + j * np, &p->segs, 0, NULL);
    pe += p->near_new[j];
    if (add_partners(p, &p->segs) != LW_OK) return no_memory(p);
  }
  for (int k = 0, o = 0; k < p->n_old; k++) {
    const size_t g0 = lw_segment_index(m->sp, p->old[k], 0);
    const lw_node *nd = splice_old_nodes(m, p, k);
    for (size_t j = 0; j < p->old_seg[k]; j++, o++) {
      const lw_pair_sample *ps = p->ps_old + (size_t)o * np;
      if (near_of_probes(p, np, nn + (size_t)o * np, &p->segs) != LW_OK) return no_memory(p);
      if (p->n_old == 1) {
        pe -= old_near(m, &v, g0 + j, &nd[j], ps, &p->segs);
      } else {
        double bez[8];
        lw_segment_bezier(&nd[j], &nd[j + 1], bez);
        pe -= near_part(&v, bez, ps, &p->segs, 0, NULL);
      }
      if (add_partners(p, &p->segs) != LW_OK) return no_memory(p);
    }
  }
  return pe + splice_pair_between(m, p, &v);
}

/* Marks in p->kept_old and p->kept_new (bit per segment, old ones numbered
** through the old splines in order) the segments a splice keeps as they
** were, the same two nodes bit for bit: a grow's or a shrink's, a split's or
** a join's pieces that keep their direction; kept_from pairs them.  Nothing
** is marked past 64 of either: those are evaluated as new. */
static void splice_kept(const lw_model *m, lw_proposal *p)
{
  const lw_node *old[64];
  size_t n = 0;
  p->kept_old = p->kept_new = 0;
  for (int k = 0; k < p->n_old; k++)
    for (size_t j = 0; j < p->old_seg[k]; j++) {
      if (n == 64) break;
      old[n++] = &splice_old_nodes(m, p, k)[j];
    }
  for (size_t j = 0; j < p->n_seg && j < 64; j++) {
    const lw_node *q = &p->node[splice_seg_node(p, j)];
    for (size_t o = 0; o < n; o++)
      if (!(p->kept_old >> o & 1) && !memcmp(old[o], q, 2 * sizeof *q)) {
        p->kept_old |= 1ull << o;
        p->kept_new |= 1ull << j;
        p->kept_from[j] = (uint8_t)o;
        break;
      }
  }
}

/* The global number of old segment o of a splice (numbered as in splice_kept). */
static size_t splice_old_segment(const lw_model *m, const lw_proposal *p, size_t o)
{
  const int k = o >= p->old_seg[0];
  return lw_segment_index(m->sp, p->old[k], 0) + (k ? o - p->old_seg[0] : o);
}

/* A raster term's part of a splice's dE (no coefficient); NAN if the box
** cannot grow.  A segment the splice keeps splats the same footprints with
** -1 and +1, which cancel exactly in fixed point (tone.h): it is neither
** covered nor splatted, and dE and the committed raster are bit for bit
** what they would be with it.  A grow then splats one segment, not the
** spline's 2 n + 1. */
static double splice_raster_delta(const lw_model *m, lw_proposal *p, int t)
{
  const lw_term_ctx *c = &ctx_in(&m->terms, p->layer)[t];
  lw_tone_box *b = &p->box[t];
  lw_tone_box_reset(b);
  for (int pass = 0; pass < 2; pass++) {
    if (pass && lw_tone_box_ready(b) != LW_OK) return no_memory(p);
    size_t o = 0;
    for (int k = 0; k < p->n_old; k++)
      for (size_t j = 0; j < p->old_seg[k]; j++, o++) {
        if (kept_old(p, o)) continue;
        const lw_node *nd = &splice_old_nodes(m, p, k)[j];
        if (pass) raster_segment(c, b, nd, nd + 1, -1);
        else raster_cover(c->data, b, nd, nd + 1);
      }
    for (size_t j = 0; j < p->n_seg; j++) {
      if (kept_new(p, j)) continue;
      const lw_node *nd = &p->node[splice_seg_node(p, j)];
      if (pass) raster_segment(c, b, nd, nd + 1, 1);
      else raster_cover(c->data, b, nd, nd + 1);
    }
  }
  return lw_tone_delta(c->data, m->raster[t] + plane_in(p->layer, c->data), b);
}

/* The pair samples of the segments a splice keeps: the old ones read from
** the grid where lw_model_propose_regroup left them out, the new ones
** copies of their old selves.  A grow or a shrink without the near field
** needs them only for the rule between the curves and the commit, which
** most proposals never reach, so they are read then. */
static void splice_kept_samples(const lw_model *m, lw_proposal *p)
{
  if (!p->kept_pending) return;
  const size_t np = (size_t)pair_nodes(m);
  const pair_view v = {m->grid, m->sp, (uint32_t)np, NULL, NULL};
  for (size_t o = 0; p->kept_pending == 2 && o < p->n_old_seg; o++)
    if (kept_old(p, o)) samples_at(&v, (uint32_t)(splice_old_segment(m, p, o) * np), np, p->ps_old + o * np);
  for (size_t j = 0; j < p->n_seg; j++)
    if (kept_new(p, j)) memcpy(p->ps + j * np, p->ps_old + p->kept_from[j] * np, np * sizeof *p->ps);
  p->kept_pending = 0;
}

/* The new splines' segments: their caches in p and their share of dterm;
** sets *forbidden and *undefined as lw_model_propose does.  A segment the
** splice keeps takes its old self's caches, bit for bit what evaluating it
** gives, and adds nothing to dterm: its old self is not taken away either
** (lw_model_propose_regroup); its pair samples come with its old self's
** (splice_kept_samples). */
static void splice_new_segments(const lw_model *m, lw_proposal *p, int *forbidden, int *undefined)
{
  const lw_scene *sc = m->scene;
  const lw_term_set *ts = &m->terms;
  const lw_term_ctx *pc = ts->pair >= 0 ? &ts->ctx[ts->pair] : NULL;
  const int np = pair_nodes(m), nl = sc->n_local;
  lw_samples s;
  p->irregular = 0;
  for (int k = 0, j = 0, a = 0; k < p->n_new; a += (int)p->new_node[k++]) {
    const int j0 = j;
    for (size_t i = 0; i + 1 < p->new_node[k]; i++, j++) {
      double *local = p->local + (size_t)j * (size_t)nl;
      const int kept = kept_new(p, (size_t)j);
      if (kept) {
        const size_t g = splice_old_segment(m, p, p->kept_from[j]);
        p->seg_irregular[j] = m->seg_irregular[g];
        p->len[j] = m->seg_len[g];
        memcpy(local, m->seg_local + g * (size_t)nl, (size_t)nl * sizeof *local);
      } else {
        p->seg_irregular[j] = !segment_eval(sc, ctx_in(ts, p->layer), &p->node[(size_t)a + i],
                                            &p->node[(size_t)a + i + 1], &s, &p->len[j], local, pc ? pc->quad : NULL,
                                            m->grid ? p->ps + (size_t)j * (size_t)np : NULL);
      }
      p->irregular |= p->seg_irregular[j];
      for (int t = 0; t < nl; t++) {
        if (!kept) p->dterm[sc->local[t]] += local[t];
        if (local[t] == INFINITY) *forbidden = 1;
        else if (isnan(local[t])) *undefined = 1;
      }
      if (isnan(p->len[j])) *undefined = 1;
    }
    p->new_len[k] = lw_term_spline_length(p->len + j0, (size_t)(j - j0), NULL);
  }
}

/* 1 if the moved segments' curves touch more segments of other strokes
** than their old curves did (the rule between the curves, above). */
static int curves_touch(const lw_model *m, const lw_proposal *p)
{
  const lw_splines *sp = m->sp;
  const uint32_t np = (uint32_t)pair_nodes(m);
  const lw_node *base = &sp->node[sp->first[p->spline]];
  const uint32_t lo = (uint32_t)(lw_segment_index(sp, p->spline, 0) * np);
  const lw_pair_filter own = {.lo = lo, .hi = lo + (uint32_t)(lw_splines_segments(sp, p->spline) * np),
                              .plane = plane_of(planes_of(m->scene), sp, p->spline)};
  lw_cellgrid view;
  const contact_view cv = contact_view_of(m, &own, &view);
  contact_set now = {.n = 0}, before = {.n = 0};
  double c[8];
  for (size_t j = 0; j < p->n_seg; j++) {
    const size_t k = p->seg0 + j;
    lw_segment_bezier(proposed_node(base, p, k), proposed_node(base, p, k + 1), c);
    segment_contacts(&cv, c, p->ps + j * np, &own, &now);
  }
  if (!now.n && !now.full) return 0; /* the old side only when the new touches */
  for (size_t j = 0; j < p->n_seg; j++) {
    const size_t k = p->seg0 + j;
    lw_segment_bezier(&base[k], &base[k + 1], c);
    segment_contacts(&cv, c, p->ps_old + j * np, &own, &before);
  }
  return contacts_grew(&now, &before);
}

/* curves_touch for a splice: its new splines' curves against its old
** ones'.  The two new splines of a split against each other are left to
** the count of samples (crowded_pairs). */
static int splice_curves_touch(const lw_model *m, const lw_proposal *p)
{
  const pair_view v = {m->grid, m->sp, (uint32_t)pair_nodes(m), NULL, planes_of(m->scene)};
  const lw_pair_filter own = old_filter(&v, p);
  lw_cellgrid view;
  const contact_view cv = contact_view_of(m, &own, &view);
  const size_t np = cv.np;
  contact_set now = {.n = 0}, before = {.n = 0};
  double c[8];
  for (size_t j = 0; j < p->n_seg; j++) {
    const size_t a = splice_seg_node(p, j);
    lw_segment_bezier(&p->node[a], &p->node[a + 1], c);
    segment_contacts(&cv, c, p->ps + j * np, &own, &now);
  }
  if (!now.n && !now.full) return 0;
  for (int k = 0, o = 0; k < p->n_old; k++) {
    const lw_node *nd = splice_old_nodes(m, p, k);
    for (size_t j = 0; j < p->old_seg[k]; j++, o++) {
      lw_segment_bezier(&nd[j], &nd[j + 1], c);
      segment_contacts(&cv, c, p->ps_old + (size_t)o * np, &own, &before);
    }
  }
  return contacts_grew(&now, &before);
}

double lw_model_propose_finish(const lw_model *m, lw_proposal *p)
{
  if (p->curves_pending) {
    p->curves_pending = 0;
    if (p->splice) splice_kept_samples(m, p);
    if (p->splice ? splice_curves_touch(m, p) : curves_touch(m, p)) {
      p->crowded = 1;
      p->near_pending = 0;
      p->dE = INFINITY;
      return INFINITY;
    }
  }
  return finish_near(m, p);
}

void lw_model_propose_regroup(const lw_model *m, lw_proposal *p, const uint32_t *old, int n_old,
                              const lw_node *nodes, const size_t *new_node, int n_new, const double *rest,
                              int layer)
{
  const lw_scene *sc = m->scene;
  const lw_splines *sp = m->sp;
  const lw_term_set *ts = &m->terms;
  const lw_term_ctx *pc = ts->pair >= 0 ? &ts->ctx[ts->pair] : NULL;
  const int np = pair_nodes(m), nl = sc->n_local;

  p->splice = 1;
  p->near_pending = 0;
  p->n_old = n_old;
  p->n_new = n_new;
  p->spline = n_old ? old[0] : (uint32_t)sp->n_splines;
  p->node0 = p->seg0 = 0;
  p->n_node = p->n_seg = p->n_old_seg = 0;
  for (int k = 0; k < n_old; k++) {
    p->old[k] = old[k];
    p->old_seg[k] = lw_splines_segments(sp, old[k]);
    p->n_old_seg += p->old_seg[k];
  }
  for (int k = 0; k < n_new; k++) {
    p->new_node[k] = new_node[k];
    p->new_rest[k] = rest[k];
    p->n_node += new_node[k];
    p->n_seg += new_node[k] - 1;
  }
  /* every spline of a splice is of one layer (a split's pieces keep the
  ** cut spline's, a join links splines of one layer, sys_splines.c), so one
  ** plane of each raster changes */
  p->layer = n_old ? layer_of(ts, sp, old[0]) : layer;
  if (nodes && nodes != p->node) memcpy(p->node, nodes, p->n_node * sizeof *nodes);
  for (int t = 0; t < LW_TERM_COUNT; t++) p->dterm[t] = 0.0;
  splice_kept(m, p);

  int forbidden = beyond_state_range(p->node, p->n_node), undefined = 0, was_irregular = 0;
  splice_new_segments(m, p, &forbidden, &undefined);
  for (int k = 0, o = 0; k < n_old; k++) {
    const size_t g0 = lw_segment_index(sp, old[k], 0);
    for (size_t j = 0; j < p->old_seg[k]; j++, o++) {
      const double *ol = m->seg_local + (g0 + j) * (size_t)nl;
      if (!kept_old(p, (size_t)o))
        for (int t = 0; t < nl; t++) p->dterm[sc->local[t]] -= ol[t];
      was_irregular |= m->seg_irregular[g0 + j];
    }
  }
  for (int q = 0; q < ts->n_spline; q++) {
    const int t = ts->spline[q];
    const lw_term_ctx *c = &ts->ctx[t];
    double (*fn)(const double *, size_t, double, double, const lw_term_ctx *) = lw_term_types[t].spline;
    for (int k = 0, j = 0; k < n_new; j += (int)new_node[k++] - 1)
      p->dterm[t] += c->coef * fn(p->len + j, new_node[k] - 1, p->new_len[k], rest[k], c);
    for (int k = 0; k < n_old; k++)
      p->dterm[t] -= c->coef * fn(m->seg_len + lw_segment_index(sp, old[k], 0), p->old_seg[k], m->spline_len[old[k]],
                                  sp->rest_length[old[k]], c);
  }
  double dE = 0.0;
  for (int t = 0; t < LW_TERM_COUNT; t++) dE += p->dterm[t];
  if ((forbidden || p->irregular) && !undefined) dE = INFINITY;
  else if (was_irregular && !undefined) dE = -INFINITY;
  p->pair_done = 0;
  const pair_view v = {m->grid, sp, (uint32_t)np, pc ? pair_ctx(pc) : NULL, planes_of(sc)};
  /* the kept segments' samples wait where only the changed ones are walked
  ** and counted (splice_pair_delta): a grow or a shrink without the near field */
  const int later = n_old == 1 && n_new == 1 && !(sc->pair.near_scale > 0.0);
  p->kept_pending = 0;
  if (m->grid && later) {
    for (size_t o = 0; o < p->n_old_seg; o++)
      if (!kept_old(p, o))
        samples_at(&v, (uint32_t)(splice_old_segment(m, p, o) * (size_t)np), (size_t)np, p->ps_old + o * (size_t)np);
    p->kept_pending = 2;
  } else if (m->grid) {
    for (size_t k = 0, o = 0; k < (size_t)n_old; k++) {
      const size_t first = lw_segment_index(sp, old[k], 0) * (size_t)np, run = p->old_seg[k] * (size_t)np;
      samples_at(&v, (uint32_t)first, run, p->ps_old + o);
      o += run;
    }
    p->kept_pending = 1;
    splice_kept_samples(m, p);
  }
  p->crowded = 0;
  p->curves_pending = 0;
  if (sc->min_spacing > 0.0 && p->n_seg && !(dE == INFINITY) && !isnan(dE)) {
    const lw_pair_filter own = old_filter(&v, p);
    const double d2 = sc->min_spacing * sc->min_spacing;
    const size_t n0 = n_new == 2 ? (new_node[0] - 1) * (size_t)np : 0, o0 = n_old == 2 ? p->old_seg[0] * (size_t)np : 0;
    /* the kept segments' pairs with other strokes count the same on both
    ** sides: left out of both, the comparison is the same */
    size_t now = 0;
    for (size_t j = 0; j < p->n_seg; j++)
      if (!kept_new(p, j)) now += crowding(m->grid, p->ps + j * (size_t)np, (size_t)np, &own, d2);
    if (n0) now += crowded_pairs(p->ps, n0, p->ps + n0, p->n_seg * (size_t)np - n0, d2);
    size_t before = 0;
    if (now > 0) {
      for (size_t o = 0; o < p->n_old_seg; o++)
        if (!kept_old(p, o)) before += crowding(m->grid, p->ps_old + o * (size_t)np, (size_t)np, &own, d2);
      if (o0) before += crowded_pairs(p->ps_old, o0, p->ps_old + o0, p->n_old_seg * (size_t)np - o0, d2);
    }
    if (now > 0 && now > before) {
      p->crowded = 1;
      dE = INFINITY;
    }
    p->curves_pending = !p->crowded && !isnan(dE);
  }
  if (m->grid && !(dE == INFINITY) && !isnan(dE)) {
    double pe = splice_pair_delta(m, p);
    p->pair_done = !isnan(pe);
    p->dterm[ts->pair] = pc->coef * pe;
    dE += p->dterm[ts->pair];
  }
  p->raster_done = 0;
  if (ts->n_raster && !(dE == INFINITY) && !isnan(dE)) {
    for (int k = 0; k < ts->n_raster; k++) {
      const int t = ts->raster[k];
      p->dterm[t] = ts->ctx[t].coef * splice_raster_delta(m, p, t);
      dE += p->dterm[t];
    }
    p->raster_done = !isnan(dE);
  }
  p->dE = dE;
}

void lw_model_propose_splice(const lw_model *m, lw_proposal *p, uint32_t at, int remove, const lw_node *nodes,
                             size_t n_new, double rest, int layer)
{
  lw_model_propose_regroup(m, p, &at, remove != 0, nodes, &n_new, n_new > 0, &rest, layer);
}

/* Room for n elements of size sz in *a (cap elements now); 0 if out of
** memory (*a unchanged). */
static int room(void *a, size_t cap, size_t n, size_t sz)
{
  if (n <= cap) return 1;
  void *q = realloc(*(void **)a, n * sz);
  if (!q) return 0;
  *(void **)a = q;
  return 1;
}

/* Room in the per-segment caches for n_seg segments and in the per-spline
** ones for n_spl splines; LW_ENOMEM leaves the model as it was (only larger). */
static lw_status cache_room(lw_model *m, size_t n_seg, size_t n_spl)
{
  const int nl = m->scene->n_local, nls = nl ? nl : 1;
  if (n_seg > m->cap_seg) {
    size_t c = m->cap_seg + m->cap_seg / 2 + 16;
    if (c < n_seg) c = n_seg;
    if (!room(&m->seg_len, m->cap_seg, c, sizeof *m->seg_len) ||
        !room(&m->seg_local, m->cap_seg * (size_t)nls, c * (size_t)nls, sizeof *m->seg_local) ||
        !room(&m->seg_irregular, m->cap_seg, c, sizeof *m->seg_irregular) ||
        (m->grid && (!room(&m->near_cache, m->cap_seg, c, sizeof *m->near_cache) ||
                     !room(&m->near_valid, m->cap_seg, c, sizeof *m->near_valid) ||
                     (m->near_pid &&
                      (!room(&m->near_pid, m->cap_seg * LW_NEAR_SLOTS, c * LW_NEAR_SLOTS, sizeof *m->near_pid) ||
                       !room(&m->near_pval, m->cap_seg * LW_NEAR_SLOTS, c * LW_NEAR_SLOTS, sizeof *m->near_pval))))))
      return LW_ENOMEM;
    m->cap_seg = c;
  }
  if (n_spl > m->cap_spl) {
    size_t c = m->cap_spl + m->cap_spl / 2 + 8;
    if (c < n_spl) c = n_spl;
    if (!room(&m->spline_len, m->cap_spl, c, sizeof *m->spline_len)) return LW_ENOMEM;
    m->cap_spl = c;
  }
  return LW_OK;
}

/*
** A splice commits in O(the segments of its splines): each replaced spline
** becomes a ghost where it is (its samples leave the grid, its caches are
** zeroed so that nothing counts it), and each new one takes a ghost slot of
** its segment count in place, or is appended (slots.h).  No other index
** moves, so the grid's keys and every cached near field of the splines not
** involved stay as they were.  An old and a new spline never have the same
** segment count (no move makes one), so a new one never takes a slot that
** the same splice left.  The near fields of two new splines (a split) hold
** each other, which the walk did not see: they are left to be recomputed.
*/
static lw_status commit_splice(lw_model *m, const lw_proposal *p)
{
  state_changed(m);
  lw_splines *sp = m->sp;
  const int np = pair_nodes(m), nl = m->scene->n_local;
  long slot[2] = {-1, -1};
  size_t n_append = 0, append_nodes = 0;
  for (int k = 0; k < p->n_new; k++) {
    /* a second new spline of the first's count takes the ghost below its */
    slot[k] = lw_slots_peek(m->slots, p->new_node[k] - 1, k == 1 && p->new_node[0] == p->new_node[1]);
    if (slot[k] < 0) {
      n_append++;
      append_nodes += p->new_node[k];
    }
  }
  const size_t n_seg = sp->n_segments + append_nodes - n_append, n_spl = sp->n_splines + n_append;
  /* every allocation first, so that running out of memory leaves the model as it was */
  if ((uint64_t)n_seg * (uint64_t)np >= UINT32_MAX) return LW_ENOMEM; /* the grid's sample indices */
  if (cache_room(m, n_seg, n_spl) != LW_OK) return LW_ENOMEM;
  for (int k = 0; k < p->n_old; k++)
    if (lw_slots_reserve(m->slots, n_spl, p->old_seg[k], (size_t)p->n_old) != LW_OK) return LW_ENOMEM;
  if (m->grid && lw_cellgrid_reserve(m->grid, n_seg * (size_t)np) != LW_OK) return LW_ENOMEM;
  if (n_append && lw_splines_reserve(sp, append_nodes, n_append) != LW_OK) return LW_ENOMEM;
  size_t appended = sp->n_splines;
  for (int k = 0, a = 0; k < p->n_new; a += (int)p->new_node[k++])
    if (slot[k] < 0) (void)lw_splines_append(sp, p->node + a, p->new_node[k], p->new_rest[k], p->layer); /* reserved */
  /* the near fields the splice changes; slots of the old segments, whose
  ** numbers new splines may take, go with them */
  if (m->grid && p->pair_done)
    for (size_t k = 0; k < p->partners.n; k++) {
      m->near_valid[p->partners.idx[k]] = 0;
      slots_reset(m, p->partners.idx[k], 1);
    }

  for (int k = 0; k < p->n_old; k++) {
    const size_t at = p->old[k], no = p->old_seg[k], g0 = lw_segment_index(sp, at, 0);
    for (size_t j = 0; j < no; j++) {
      m->n_irregular -= m->seg_irregular[g0 + j];
      m->seg_irregular[g0 + j] = 0;
      m->seg_len[g0 + j] = 0.0;
      for (int t = 0; t < nl; t++) m->seg_local[(g0 + j) * (size_t)nl + (size_t)t] = 0.0;
      if (m->grid) {
        m->near_valid[g0 + j] = 0;
        slots_reset(m, g0 + j, 1);
      }
    }
    m->spline_len[at] = 0.0;
    for (size_t i = 0; m->grid && i < no * (size_t)np; i++) lw_cellgrid_remove(m->grid, (uint32_t)(g0 * (size_t)np + i));
    lw_slots_kill(m->slots, at, no);
  }
  lw_status st = LW_OK;
  for (int k = 0, a = 0, j0 = 0; k < p->n_new; j0 += (int)p->new_node[k] - 1, a += (int)p->new_node[k++]) {
    const size_t nn = p->new_node[k] - 1, s = slot[k] >= 0 ? (size_t)slot[k] : appended++;
    if (slot[k] >= 0) {
      lw_slots_take(m->slots, nn);
      memcpy(&sp->node[sp->first[s]], p->node + a, p->new_node[k] * sizeof *p->node);
      sp->rest_length[s] = p->new_rest[k];
      if (sp->layer) sp->layer[s] = (uint8_t)p->layer;
    }
    const size_t g0 = lw_segment_index(sp, s, 0);
    memcpy(m->seg_len + g0, p->len + j0, nn * sizeof *p->len);
    memcpy(m->seg_local + g0 * (size_t)nl, p->local + (size_t)j0 * (size_t)nl, nn * (size_t)nl * sizeof *p->local);
    memcpy(m->seg_irregular + g0, p->seg_irregular + j0, nn * sizeof *p->seg_irregular);
    for (size_t j = 0; j < nn; j++) m->n_irregular += p->seg_irregular[j0 + j];
    m->spline_len[s] = p->new_len[k];
    if (nn > m->max_segments) m->max_segments = nn;
    if (m->grid) {
      for (size_t j = 0; j < nn; j++) {
        m->near_cache[g0 + j] = p->near_new[j0 + j];
        m->near_valid[g0 + j] = (uint8_t)(p->pair_done && p->n_new == 1);
      }
      slots_reset(m, g0, nn);
      if (slot[k] < 0) lw_cellgrid_extend(m->grid, nn * (size_t)np);
      for (size_t j = 0; j < nn && st == LW_OK; j++)
        st = store_samples(m->grid, planes_of(m->scene) ? p->layer : 0, g0 + j, np,
                           p->ps + ((size_t)j0 + j) * (size_t)np);
    }
  }
  if (m->grid && !p->pair_done) {
    memset(m->near_valid, 0, sp->n_segments * sizeof *m->near_valid);
    slots_reset(m, 0, sp->n_segments);
  }
  for (int k = 0; p->raster_done && k < m->terms.n_raster; k++) {
    const int t = m->terms.raster[k];
    const lw_tone *tn = ctx_in(&m->terms, p->layer)[t].data;
    lw_tone_apply(tn, m->raster[t] + plane_in(p->layer, tn), &p->box[t]);
  }
  int nonfinite = 0;
  for (int t = 0; t < LW_TERM_COUNT; t++) {
    m->term[t] += p->dterm[t];
    if (!isfinite(m->term[t])) nonfinite = 1;
  }
  /* the last spline gone: the sums over splines are exactly 0, not what the
  ** rounding of their moves left (a strain of -2e-15 in the trace); a raster
  ** term's empty page has its own energy */
  if (m->slots && m->slots->n_ghost == sp->n_splines) {
    int raster[LW_TERM_COUNT] = {0};
    for (int k = 0; k < m->terms.n_raster; k++) raster[m->terms.raster[k]] = 1;
    for (int t = 0; t < LW_TERM_COUNT; t++)
      if (!raster[t]) m->term[t] = 0.0;
  }
  if (st != LW_OK) {
    (void)lw_model_refresh(m, NULL);
    return st;
  }
  if (nonfinite || (m->terms.n_raster && !p->raster_done)) return lw_model_refresh(m, NULL);
  return LW_OK;
}

lw_status lw_model_compact(lw_model *m)
{
  if (!m->slots || !m->slots->n_ghost) return LW_OK;
  state_changed(m);
  lw_splines *sp = m->sp;
  const size_t ns = sp->n_segments, n_old = sp->n_splines;
  const int np = pair_nodes(m), nl = m->scene->n_local;
  uint32_t *to = malloc((ns ? ns : 1) * sizeof *to);
  if (!to) return LW_ENOMEM;
  size_t w = 0, ws = 0;
  for (size_t i = 0; i < n_old; i++) {
    const size_t g0 = lw_segment_index(sp, i, 0), n = lw_splines_segments(sp, i);
    const int dead = lw_slots_ghost(m->slots, i);
    for (size_t k = 0; k < n; k++) {
      const size_t g = g0 + k;
      to[g] = dead ? UINT32_MAX : (uint32_t)w;
      if (dead) continue;
      /* w <= g: the caches move down in place */
      m->seg_len[w] = m->seg_len[g];
      memmove(m->seg_local + w * (size_t)nl, m->seg_local + g * (size_t)nl, (size_t)nl * sizeof *m->seg_local);
      m->seg_irregular[w] = m->seg_irregular[g];
      if (m->grid) {
        m->near_cache[w] = m->near_cache[g];
        m->near_valid[w] = m->near_valid[g];
      }
      if (m->near_pid) {
        memmove(m->near_pid + w * LW_NEAR_SLOTS, m->near_pid + g * LW_NEAR_SLOTS, LW_NEAR_SLOTS * sizeof *m->near_pid);
        memmove(m->near_pval + w * LW_NEAR_SLOTS, m->near_pval + g * LW_NEAR_SLOTS,
                LW_NEAR_SLOTS * sizeof *m->near_pval);
      }
      w++;
    }
    if (!dead) m->spline_len[ws++] = m->spline_len[i];
  }
  /* the partners by their new numbers (a dead one has no pairs left) */
  for (size_t k = 0; m->near_pid && k < w * LW_NEAR_SLOTS; k++)
    if (m->near_pid[k] != LW_NEAR_FREE) m->near_pid[k] = to[m->near_pid[k]];
  if (m->grid) lw_cellgrid_renumber(m->grid, to, (uint32_t)np, w * (size_t)np);
  free(to);
  lw_splines_compact(sp, m->slots->ghost);
  lw_slots_clear(m->slots, n_old);
  return LW_OK;
}
