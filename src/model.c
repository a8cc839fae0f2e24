/*
** model.c -- state, caches, local energy differences and commits (model.h),
** and the from-scratch energy that checks them.
*/
#include "linewise/model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Samples one segment and evaluates its length, its local terms and (if ps is
** not NULL) its pair samples, at the pair term's own nodes when it has them. */
static void segment_eval(const lw_scene *sc, const lw_node *a, const lw_node *b, uint32_t spline,
                         lw_samples *s, double *len, double *local, lw_pair_sample *ps)
{
  lw_segment_sample(&sc->quad, a, b, s);
  *len = s->length;
  for (int t = 0; t < sc->n_local; t++) local[t] = lw_term_types[sc->local[t]].segment(s, sc);
  if (!ps) return;
  lw_samples pair_s;
  const lw_samples *ss = s;
  if (sc->pair_quad.n != sc->quad.n) {
    lw_segment_sample(&sc->pair_quad, a, b, &pair_s);
    ss = &pair_s;
  }
  for (int q = 0; q < ss->n; q++)
    ps[q] = (lw_pair_sample){ss->x[q], ss->y[q], (float)ss->dx[q], (float)ss->dy[q], (float)ss->dl[q], spline,
                             (uint32_t)q};
}

#if defined(__GNUC__)
#define l_unlikely(x) __builtin_expect(!!(x), 0)
#else
#define l_unlikely(x) (x)
#endif

static lw_pair_tangent tangent_of(const lw_pair_sample *s)
{
  return (lw_pair_tangent){s->dx, s->dy};
}

/* Where the pair term looks things up: the grid, the tangents, and the
** splines' sample ranges (np samples per segment). */
typedef struct {
  const lw_cellgrid *g;
  const lw_pair_tangent *pt;
  const lw_splines *sp;
  uint32_t np;
  const lw_pair_ctx *ctx;
} pair_view;

/* Sample i at (x, y) with weight dl: the rest from its index. */
static lw_pair_sample sample_of(const pair_view *v, uint32_t i, double x, double y, float dl)
{
  return (lw_pair_sample){x, y, v->pt[i].dx, v->pt[i].dy, dl, v->sp->seg_spline[i / v->np], i % v->np};
}

/* Sample i from the grid. */
static lw_pair_sample sample_at(const pair_view *v, uint32_t i)
{
  double x, y;
  float dl;
  lw_cellgrid_get(v->g, i, &x, &y, &dl);
  return sample_of(v, i, x, y, dl);
}

/* The filter of the samples of spline i: pairs with samples of index >= from. */
static lw_pair_filter filter_of(const pair_view *v, uint32_t spline, uint32_t from)
{
  size_t g0 = lw_segment_index(v->sp, spline, 0), n = lw_splines_segments(v->sp, spline);
  return (lw_pair_filter){(uint32_t)(g0 * v->np), (uint32_t)((g0 + n) * v->np), from};
}

/* ---- near-field glue: the near-field rewrite replaces this function ----
** The walk reports as near exactly the pairs inside the kernel's element and
** exact zones (near_scale = zone_outer, pair.c) that lie within the cutoff
** (beyond it the kernel is 0), so adding lw_pair_kernel over them gives the
** energy of the kernel of pair.h, every zone included.
** Probe k is sample s[k] with its scale in P[k]. */
static double near_glue(const pair_view *v, const lw_pair_sample *const *s, const lw_pair_probe *P,
                        const lw_pair_nearlist *near, uint32_t from)
{
  double e = 0.0;
  for (size_t k = 0; k < near->n; k++) {
    const lw_pair_near *q = &near->pair[k];
    if (q->idx < from) continue;
    lw_pair_sample o = sample_of(v, q->idx, q->x, q->y, q->dl);
    e += P[q->probe].scale * lw_pair_kernel(s[q->probe], &o, v->ctx);
  }
  return e;
}

/* Pair energy (no coefficient) of the n probes P (samples s, all of spline
** `spline`) with every grid sample of another spline whose index is at
** least `from`, each probe's pairs counted P[k].scale times. */
static lw_status probes_pair(const pair_view *v, const lw_pair_probe *P, const lw_pair_sample *const *s, size_t n,
                             uint32_t spline, uint32_t from, lw_pair_nearlist *near, double *e)
{
  lw_pair_filter f = filter_of(v, spline, from);
  near->n = 0;
  if (lw_pair_walk(v->g, v->ctx, P, n, &f, e, near) != LW_OK) return LW_ENOMEM;
  if (l_unlikely(near->n)) *e += near_glue(v, s, P, near, from);
  return LW_OK;
}

/* Every pair of samples of different splines once (j > i), the samples
** taken cell by cell, in the grid's order, which depends on positions only. */
static lw_status pair_all(const pair_view *v, double *e)
{
  lw_pair_nearlist near = {0};
  const lw_cellgrid *g = v->g;
  double sum = 0.0, t;
  for (size_t ci = 0; ci < (size_t)g->nx * (size_t)g->ny; ci++) {
    const lw_cell *c = &g->cell[ci];
    const uint32_t *idx = lw_cell_idx(c);
    for (uint32_t k = 0; k < c->n; k++) {
      lw_pair_sample s = sample_of(v, idx[k], c->x[k], lw_cell_y(c)[k], lw_cell_dl(c)[k]);
      const lw_pair_sample *only = &s;
      lw_pair_probe P = {s.x, s.y, s.dl, 1.0};
      if (probes_pair(v, &P, &only, 1, s.spline, idx[k] + 1, &near, &t) != LW_OK) {
        lw_pair_nearlist_free(&near);
        return LW_ENOMEM;
      }
      sum += t;
    }
  }
  lw_pair_nearlist_free(&near);
  *e = sum;
  return LW_OK;
}

static lw_cellgrid *grid_for(const lw_scene *sc, size_t n_samples, lw_error *err)
{
  return lw_cellgrid_new(0.0, 0.0, sc->width, sc->height, sc->pair.cutoff, n_samples, err);
}

static double strain_of_spline(const lw_scene *sc, const lw_splines *sp, const double *seg_len,
                               size_t i, double spline_len)
{
  double S = sc->coef[LW_TERM_STRAIN];
  double L0 = sp->rest_length[i];
  if (!sc->strain_per_segment) return S * lw_term_strain(spline_len, L0);
  size_t n = lw_splines_segments(sp, i), g0 = lw_segment_index(sp, i, 0);
  double l0 = L0 / (double)n, e = 0.0;
  for (size_t m = 0; m < n; m++) e += S * lw_term_strain(seg_len[g0 + m], l0);
  return e;
}

/* Puts the np pair samples ps of segment g into the grid and the tangents. */
static lw_status store_samples(lw_cellgrid *grid, lw_pair_tangent *pt, size_t g, int np, const lw_pair_sample *ps)
{
  for (int q = 0; q < np; q++) {
    size_t i = g * (size_t)np + (size_t)q;
    if (lw_cellgrid_insert(grid, (uint32_t)i, ps[q].x, ps[q].y, ps[q].dl) != LW_OK) return LW_ENOMEM;
    pt[i] = tangent_of(&ps[q]);
  }
  return LW_OK;
}

double lw_energy_compute(const lw_scene *sc, const lw_splines *sp, double term[LW_TERM_COUNT],
                         lw_error *err)
{
  for (int t = 0; t < LW_TERM_COUNT; t++) term[t] = 0.0;
  const int np = sc->pair_quad.n;
  lw_samples s;
  double local[LW_TERM_COUNT];
  lw_pair_sample seg_ps[LW_QUAD_MAX];
  lw_pair_tangent *pt = NULL;
  lw_cellgrid *grid = NULL;
  size_t n = sp->n_segments * (size_t)np;
  double *seg_len = malloc((sp->n_segments ? sp->n_segments : 1) * sizeof *seg_len);
  if (!seg_len) goto nomem;
  if (sc->on[LW_TERM_PAIR]) {
    if (!(pt = malloc((n ? n : 1) * sizeof *pt))) goto nomem;
    if (!(grid = grid_for(sc, n, err))) goto fail;
  }
  for (size_t g = 0; g < sp->n_segments; g++) {
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    segment_eval(sc, a, a + 1, sp->seg_spline[g], &s, &seg_len[g], local, pt ? seg_ps : NULL);
    for (int t = 0; t < sc->n_local; t++) term[sc->local[t]] += local[t];
    if (pt && store_samples(grid, pt, g, np, seg_ps) != LW_OK) goto nomem;
  }
  if (sc->on[LW_TERM_STRAIN])
    for (size_t i = 0; i < sp->n_splines; i++) {
      double L = 0.0;
      size_t g0 = lw_segment_index(sp, i, 0), ns = lw_splines_segments(sp, i);
      for (size_t m = 0; m < ns; m++) L += seg_len[g0 + m];
      term[LW_TERM_STRAIN] += strain_of_spline(sc, sp, seg_len, i, L);
    }
  if (grid) {
    pair_view v = {grid, pt, sp, (uint32_t)np, &sc->pair};
    double e;
    if (pair_all(&v, &e) != LW_OK) goto nomem;
    term[LW_TERM_PAIR] = sc->coef[LW_TERM_PAIR] * e;
  }
  free(seg_len);
  free(pt);
  lw_cellgrid_free(grid);
  double total = 0.0;
  for (int t = 0; t < LW_TERM_COUNT; t++) total += term[t];
  return total;
nomem:
  lw_error_set(err, LW_ENOMEM, "out of memory for the energy of %zu segments (%zu pair samples)",
               sp->n_segments, n);
fail:
  free(seg_len);
  free(pt);
  lw_cellgrid_free(grid);
  return NAN;
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
  size_t ns = sp->n_segments ? sp->n_segments : 1;
  m->seg_len = malloc(ns * sizeof *m->seg_len);
  m->seg_local = malloc(ns * (size_t)(sc->n_local ? sc->n_local : 1) * sizeof *m->seg_local);
  m->spline_len = malloc((sp->n_splines ? sp->n_splines : 1) * sizeof *m->spline_len);
  if (!m->seg_len || !m->seg_local || !m->spline_len) goto nomem;
  if (sc->on[LW_TERM_PAIR]) {
    size_t n = sp->n_segments * (size_t)sc->pair_quad.n;
    if (n >= UINT32_MAX || sp->n_splines > LW_PAIR_MAX_SPLINES) {
      lw_error_set(err, LW_EINPUT, "%zu pair samples of %zu splines exceed the grid's limits "
                   "(2^32 samples, 2^26 splines)", n, sp->n_splines);
      lw_model_free(m);
      return NULL;
    }
    m->pt = malloc((n ? n : 1) * sizeof *m->pt);
    if (!m->pt) goto nomem;
    m->grid = grid_for(sc, n, err);
    if (!m->grid) {
      lw_model_free(m);
      return NULL;
    }
  }
  for (size_t i = 0; i < sp->n_splines; i++)
    if (lw_splines_segments(sp, i) > m->max_segments) m->max_segments = lw_splines_segments(sp, i);
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
  free(m->seg_local);
  free(m->spline_len);
  free(m->pt);
  lw_cellgrid_free(m->grid);
  free(m);
}

double lw_model_total(const lw_model *m)
{
  double total = 0.0;
  for (int t = 0; t < LW_TERM_COUNT; t++) total += m->term[t];
  return total;
}

lw_status lw_model_refresh(lw_model *m, double *drift)
{
  const lw_scene *sc = m->scene;
  const lw_splines *sp = m->sp;
  const int np = sc->pair_quad.n, nl = sc->n_local;
  double old_total = lw_model_total(m);
  double term[LW_TERM_COUNT] = {0};
  lw_samples s;
  lw_pair_sample seg_ps[LW_QUAD_MAX];
  if (m->grid) lw_cellgrid_clear(m->grid);
  for (size_t g = 0; g < sp->n_segments; g++) {
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    double *local = m->seg_local + g * (size_t)nl;
    segment_eval(sc, a, a + 1, sp->seg_spline[g], &s, &m->seg_len[g], local, m->grid ? seg_ps : NULL);
    for (int t = 0; t < nl; t++) term[sc->local[t]] += local[t];
    if (m->grid && store_samples(m->grid, m->pt, g, np, seg_ps) != LW_OK) return LW_ENOMEM;
  }
  for (size_t i = 0; i < sp->n_splines; i++) {
    size_t g0 = lw_segment_index(sp, i, 0), n = lw_splines_segments(sp, i);
    double L = 0.0;
    for (size_t k = 0; k < n; k++) L += m->seg_len[g0 + k];
    m->spline_len[i] = L;
    if (sc->on[LW_TERM_STRAIN]) term[LW_TERM_STRAIN] += strain_of_spline(sc, sp, m->seg_len, i, L);
  }
  if (m->grid) {
    pair_view v = {m->grid, m->pt, sp, (uint32_t)np, &sc->pair};
    double e;
    lw_cellgrid_fit(m->grid);
    if (pair_all(&v, &e) != LW_OK) return LW_ENOMEM;
    term[LW_TERM_PAIR] = sc->coef[LW_TERM_PAIR] * e;
  }
  double total = 0.0;
  for (int t = 0; t < LW_TERM_COUNT; t++) {
    m->term[t] = term[t];
    total += term[t];
  }
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
    p->ps = malloc(cap * (size_t)m->scene->pair_quad.n * sizeof *p->ps);
    p->ps_old = malloc(cap * (size_t)m->scene->pair_quad.n * sizeof *p->ps_old);
    p->probe = malloc(2 * cap * (size_t)m->scene->pair_quad.n * sizeof *p->probe);
    p->probe_sample = malloc(2 * cap * (size_t)m->scene->pair_quad.n * sizeof *p->probe_sample);
  }
  if (!p || !p->node || !p->len || !p->local || !p->ps || !p->ps_old || !p->probe || !p->probe_sample) {
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
  free(p->probe_sample);
  lw_pair_nearlist_free(&p->near);
  free(p);
}

void lw_model_pair_sample(const lw_model *m, uint32_t i, lw_pair_sample *s)
{
  pair_view v = {m->grid, m->pt, m->sp, (uint32_t)m->scene->pair_quad.n, &m->scene->pair};
  *s = sample_at(&v, i);
}

/* Node k of the spline as it would be after the proposal. */
static inline const lw_node *proposed_node(const lw_node *base, const lw_proposal *p, size_t k)
{
  return (k >= p->node0 && k < p->node0 + p->n_node) ? &p->node[k - p->node0] : &base[k];
}

void lw_model_propose(const lw_model *m, lw_proposal *p, uint32_t spline, size_t node0,
                      size_t n_node, const lw_node *nodes)
{
  const lw_scene *sc = m->scene;
  const lw_splines *sp = m->sp;
  const int np = sc->pair_quad.n, nl = sc->n_local;
  const size_t nseg = lw_splines_segments(sp, spline);
  const lw_node *base = &sp->node[sp->first[spline]];
  const size_t g0 = lw_segment_index(sp, spline, 0);

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
  int forbidden = 0, undefined = 0; /* a new local energy is +inf; a new value is NaN */
  for (size_t j = 0; j < p->n_seg; j++) {
    size_t m_loc = p->seg0 + j, g = g0 + m_loc;
    double *local = p->local + j * (size_t)nl;
    segment_eval(sc, proposed_node(base, p, m_loc), proposed_node(base, p, m_loc + 1), spline, &s,
                 &p->len[j], local, m->grid ? p->ps + j * (size_t)np : NULL);
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

  if (sc->on[LW_TERM_STRAIN]) {
    double S = sc->coef[LW_TERM_STRAIN], L0 = sp->rest_length[spline];
    if (!sc->strain_per_segment) {
      p->dterm[LW_TERM_STRAIN] = S * (lw_term_strain(p->new_spline_len, L0) -
                                      lw_term_strain(m->spline_len[spline], L0));
    } else {
      double l0 = L0 / (double)nseg;
      for (size_t j = 0; j < p->n_seg; j++)
        p->dterm[LW_TERM_STRAIN] += S * (lw_term_strain(p->len[j], l0) -
                                         lw_term_strain(m->seg_len[g0 + p->seg0 + j], l0));
    }
  }

  double dE = 0.0;
  for (int t = 0; t < LW_TERM_COUNT; t++) dE += p->dterm[t];
  /* A forbidden new state is +inf whatever the old one was: from a forbidden
  ** state the difference would be inf - inf, and NaN is kept for numerical
  ** failures (a NaN energy, counted by the chain). */
  if (forbidden && !undefined) dE = INFINITY;
  /* The pair sum is the costly part: skip it when the move is already
  ** forbidden (+inf) or undefined (NaN). */
  if (m->grid) {
    size_t first = (g0 + p->seg0) * (size_t)np, n = p->n_seg * (size_t)np;
    for (size_t k = 0; k < n; k++) lw_model_pair_sample(m, (uint32_t)(first + k), &p->ps_old[k]);
  }
  if (m->grid && !(dE == INFINITY) && !isnan(dE)) {
    /* the new samples add their pairs, the old ones take theirs away: one
    ** walk over both, each new sample next to its old self (usually in the
    ** same cell: shorter moves in the walk's sort by cell) */
    pair_view v = {m->grid, m->pt, sp, (uint32_t)np, &sc->pair};
    size_t n = p->n_seg * (size_t)np;
    for (size_t k = 0; k < 2 * n; k++) {
      const lw_pair_sample *ps_k = k & 1 ? &p->ps_old[k / 2] : &p->ps[k / 2];
      p->probe[k] = (lw_pair_probe){ps_k->x, ps_k->y, ps_k->dl, k & 1 ? -1.0 : 1.0};
      p->probe_sample[k] = ps_k;
    }
    double pe;
    if (probes_pair(&v, p->probe, p->probe_sample, 2 * n, spline, 0, &p->near, &pe) != LW_OK) pe = NAN;
    p->dterm[LW_TERM_PAIR] = sc->coef[LW_TERM_PAIR] * pe;
    dE += p->dterm[LW_TERM_PAIR];
  }
  p->dE = dE;
}

lw_status lw_model_commit(lw_model *m, const lw_proposal *p)
{
  const lw_scene *sc = m->scene;
  lw_splines *sp = m->sp;
  const int np = sc->pair_quad.n, nl = sc->n_local;
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
    for (size_t k = 0; k < n; k++) m->pt[first + k] = tangent_of(&now[k]);
  }
  memcpy(&sp->node[sp->first[p->spline] + p->node0], p->node, p->n_node * sizeof *p->node);
  int nonfinite = 0;
  for (size_t j = 0; j < p->n_seg; j++) {
    size_t g = g0 + p->seg0 + j;
    m->seg_len[g] = p->len[j];
    memcpy(m->seg_local + g * (size_t)nl, p->local + j * (size_t)nl, (size_t)nl * sizeof *m->seg_local);
  }
  /* Summed afresh in a fixed order rather than updated by += dlen, so the
  ** cached length is a function of the state alone and a resumed run sees
  ** the same value as one that never stopped. */
  size_t n = lw_splines_segments(sp, p->spline);
  double L = 0.0;
  for (size_t k = 0; k < n; k++) L += m->seg_len[g0 + k];
  m->spline_len[p->spline] = L;
  for (int t = 0; t < LW_TERM_COUNT; t++) {
    m->term[t] += p->dterm[t];
    if (!isfinite(m->term[t])) nonfinite = 1;
  }
  /* inf - inf leaves NaN in a running total: leaving a forbidden state is
  ** legal, so rebuild the totals from the caches when that happens. */
  if (nonfinite) return lw_model_refresh(m, NULL);
  return LW_OK;
}
