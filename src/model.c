/*
** model.c -- state, caches, local energy differences and commits (model.h),
** and the from-scratch energy that checks them.
*/
#include "linewise/model.h"

#include "linewise/pairnear.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int lw_segment_allowed(const lw_scene *sc, const lw_node *a, const lw_node *b, double length)
{
  if (sc->min_speed == 0.0 && sc->regularity == 0.0) return 1;
  if (!(length > 0.0)) return 0;
  return lw_segment_check(a, b, sc->min_speed * length, sc->regularity);
}

/* Samples one segment and evaluates its length, its local terms and (if ps is
** not NULL) its pair samples, at the pair term's own nodes when it has them.
** Returns 1 if the segment is regular (lw_segment_allowed), 0 if forbidden. */
static int segment_eval(const lw_scene *sc, const lw_node *a, const lw_node *b, uint32_t spline,
                        lw_samples *s, double *len, double *local, lw_pair_sample *ps)
{
  lw_segment_sample(&sc->quad, a, b, s);
  *len = s->length;
  const int regular = lw_segment_allowed(sc, a, b, s->length);
  for (int t = 0; t < sc->n_local; t++) local[t] = lw_term_types[sc->local[t]].segment(s, sc);
  if (!ps) return regular;
  lw_samples pair_s;
  const lw_samples *ss = s;
  if (sc->pair_quad.n != sc->quad.n) {
    lw_segment_sample(&sc->pair_quad, a, b, &pair_s);
    ss = &pair_s;
  }
  for (int q = 0; q < ss->n; q++)
    ps[q] = (lw_pair_sample){ss->x[q], ss->y[q], (float)ss->dx[q], (float)ss->dy[q], (float)ss->dl[q], spline,
                             (uint32_t)q};
  return regular;
}

/* A growable list of sample indices: the near pairs a walk found. */
static lw_status near_push(lw_near_list *l, uint32_t idx)
{
  if (l->n == l->cap) {
    size_t cap = l->cap ? 2 * l->cap : 64;
    uint32_t *v = realloc(l->idx, cap * sizeof *v);
    if (!v) return LW_ENOMEM;
    l->idx = v;
    l->cap = cap;
  }
  l->idx[l->n++] = idx;
  return LW_OK;
}

/*
** Product-rule sum of sample `me` (of spline `spline`) with every grid sample
** of another spline whose index exceeds `after` (-1: all), leaving out near
** pairs (pairnear.h), whose partners go to `near` whatever their index: the
** near field replaces whole segment pairs, so the caller needs all of them.
** Cells and their sorted entries are visited in a fixed order, so the sum
** depends on the positions only.  Returns NAN if the near list cannot grow.
*/
static double neighbour_sum(const lw_cellgrid *g, const lw_pair_sample *all, const lw_pair_sample *me,
                            uint32_t spline, long long after, const lw_pair_ctx *ctx, lw_near_list *near)
{
  const double cut2 = ctx->cutoff2, inv = ctx->inv_cutoff;
  const double dl_me = me->dl;
  double sum = 0.0;
  int cx, cy;
  lw_cellgrid_locate(g, me->x, me->y, &cx, &cy);
  for (int y = cy - 1; y <= cy + 1; y++) {
    if (y < 0 || y >= g->ny) continue;
    for (int x = cx - 1; x <= cx + 1; x++) {
      if (x < 0 || x >= g->nx) continue;
      const lw_cell *c = &g->cell[(size_t)y * (size_t)g->nx + (size_t)x];
      for (uint32_t k = 0; k < c->n; k++) {
        const lw_pair_sample *o = &all[c->idx[k]];
        if (o->spline == spline) continue;
        double dx = me->x - o->x, dy = me->y - o->y, r2 = dx * dx + dy * dy;
        if (r2 >= cut2) continue;
        if (r2 < lw_pair_near_radius2(ctx, me->dl, o->dl)) {
          if (near_push(near, c->idx[k]) != LW_OK) return NAN;
        } else if ((long long)c->idx[k] > after && o->dl != 0.0f) {
          sum += dl_me * (double)o->dl * (1.0 / sqrt(r2) - inv);
        }
      }
    }
  }
  return sum;
}

/* The Bezier control points of the segment from node a to node b. */
static void node_bezier(const lw_node *a, const lw_node *b, double out[8])
{
  out[0] = a->px;
  out[1] = a->py;
  out[2] = a->px + a->vx;
  out[3] = a->py + a->vy;
  out[4] = b->px - b->vx;
  out[5] = b->py - b->vy;
  out[6] = b->px;
  out[7] = b->py;
}

/* The Bezier control points of global segment g. */
static void segment_bezier(const lw_splines *sp, size_t g, double b[8])
{
  const lw_node *a = &sp->node[lw_segment_node(sp, g)];
  node_bezier(a, a + 1, b);
}

static int cmp_u64(const void *a, const void *b)
{
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return (x > y) - (x < y);
}

static int cmp_u32(const void *a, const void *b)
{
  uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
  return (x > y) - (x < y);
}

/* Sorts a list of segment numbers and drops repeats; returns the count. */
static size_t unique_u32(uint32_t *v, size_t n)
{
  qsort(v, n, sizeof *v, cmp_u32);
  size_t m = 0;
  for (size_t i = 0; i < n; i++)
    if (m == 0 || v[i] != v[m - 1]) v[m++] = v[i];
  return m;
}

/* The product-rule sum (no coefficient) of one segment's np samples `mine`
** (spline `spline`) against every sample of another spline in the grid,
** near pairs left out; `near` receives the segments of the near pairs,
** sorted, each once.  NAN if out of memory. */
static double pair_walk(const lw_cellgrid *g, const lw_pair_sample *all, const lw_pair_sample *mine, int np,
                        uint32_t spline, const lw_pair_ctx *ctx, lw_near_list *near)
{
  double sum = 0.0;
  near->n = 0;
  for (int i = 0; i < np; i++) sum += neighbour_sum(g, all, &mine[i], spline, -1, ctx, near);
  if (near->n == 0 || isnan(sum)) return sum;
  for (size_t k = 0; k < near->n; k++) near->idx[k] /= (uint32_t)np;
  near->n = unique_u32(near->idx, near->n);
  return sum;
}

/* The near field (no coefficient) of one segment, control points bez and
** samples mine, with each segment of the list `near`. */
static double pair_near_part(const lw_splines *sp, const lw_pair_sample *all, const double bez[8],
                             const lw_pair_sample *mine, int np, const lw_pair_ctx *ctx, const lw_near_list *near)
{
  double sum = 0.0;
  for (size_t k = 0; k < near->n; k++) {
    double b[8];
    segment_bezier(sp, near->idx[k], b);
    sum += lw_pair_near_correction(bez, mine, b, all + (size_t)near->idx[k] * (size_t)np, np, ctx);
  }
  return sum;
}

/* Every pair of samples of different splines once (j > i), and every near
** segment pair once.  NAN if out of memory. */
static double pair_all(const lw_cellgrid *g, const lw_splines *sp, const lw_pair_sample *all, int np,
                       const lw_pair_ctx *ctx)
{
  size_t n = sp->n_segments * (size_t)np;
  lw_near_list near = {0}, pairs = {0};
  double sum = 0.0;
  for (size_t i = 0; i < n; i++) {
    near.n = 0;
    sum += neighbour_sum(g, all, &all[i], all[i].spline, (long long)i, ctx, &near);
    uint32_t ga = (uint32_t)(i / (size_t)np);
    /* a segment pair is listed from its lower segment, as (a, b) in two slots */
    for (size_t k = 0; k < near.n && !isnan(sum); k++) {
      uint32_t gb = near.idx[k] / (uint32_t)np;
      if (gb > ga && (near_push(&pairs, ga) != LW_OK || near_push(&pairs, gb) != LW_OK)) sum = NAN;
    }
    if (isnan(sum)) break;
  }
  if (!isnan(sum) && pairs.n) {
    /* sort (a, b) pairs as 64-bit keys, then take each once */
    size_t m = pairs.n / 2;
    uint64_t *key = malloc(m * sizeof *key);
    if (!key) sum = NAN;
    else {
      for (size_t k = 0; k < m; k++) key[k] = (uint64_t)pairs.idx[2 * k] << 32 | pairs.idx[2 * k + 1];
      qsort(key, m, sizeof *key, cmp_u64);
      for (size_t k = 0; k < m; k++) {
        if (k > 0 && key[k] == key[k - 1]) continue;
        size_t ga = (size_t)(key[k] >> 32), gb = (size_t)(key[k] & 0xffffffffu);
        double a[8], b[8];
        segment_bezier(sp, ga, a);
        segment_bezier(sp, gb, b);
        sum += lw_pair_near_correction(a, all + ga * (size_t)np, b, all + gb * (size_t)np, np, ctx);
      }
      free(key);
    }
  }
  free(near.idx);
  free(pairs.idx);
  return sum;
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

lw_status lw_model_check_regular(const lw_scene *sc, const lw_splines *sp, const char *path, lw_error *err)
{
  if (sc->min_speed == 0.0 && sc->regularity == 0.0) return LW_OK;
  lw_samples s;
  for (size_t g = 0; g < sp->n_segments; g++) {
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    lw_segment_sample(&sc->quad, a, a + 1, &s);
    if (lw_segment_allowed(sc, a, a + 1, s.length)) continue;
    size_t i = sp->seg_spline[g];
    double ratio = s.length > 0.0 ? lw_segment_min_speed(a, a + 1) / s.length : 0.0;
    return lw_error_set(err, LW_EINPUT,
                        "%s: spline %zu, segment %zu is irregular: its speed falls to %.3g of its mean "
                        "(energy.min_speed = %g) and its bending integrand is analytic within rho = %.3g "
                        "(energy.regularity = %g), a fold the quadrature cannot see; lower these keys to "
                        "accept it", path, i, g - lw_segment_index(sp, i, 0), ratio, sc->min_speed,
                        lw_segment_rho(a, a + 1), sc->regularity);
  }
  return LW_OK;
}

/* The sum of the terms, +inf while a segment is irregular (forbidden). */
static double total_of(const double term[LW_TERM_COUNT], size_t irregular)
{
  double total = 0.0;
  for (int t = 0; t < LW_TERM_COUNT; t++) total += term[t];
  return irregular ? INFINITY : total;
}

double lw_energy_compute(const lw_scene *sc, const lw_splines *sp, double term[LW_TERM_COUNT],
                         lw_error *err)
{
  for (int t = 0; t < LW_TERM_COUNT; t++) term[t] = 0.0;
  const int np = sc->pair_quad.n;
  lw_samples s;
  double local[LW_TERM_COUNT];
  lw_pair_sample *ps = NULL;
  if (sc->on[LW_TERM_PAIR]) {
    ps = malloc((sp->n_segments ? sp->n_segments : 1) * (size_t)np * sizeof *ps);
    if (!ps) {
      lw_error_set(err, LW_ENOMEM, "out of memory for %zu pair samples", sp->n_segments * (size_t)np);
      return NAN;
    }
  }
  double *seg_len = malloc((sp->n_segments ? sp->n_segments : 1) * sizeof *seg_len);
  if (!seg_len) {
    free(ps);
    lw_error_set(err, LW_ENOMEM, "out of memory for %zu segments", sp->n_segments);
    return NAN;
  }
  size_t irregular = 0;
  for (size_t g = 0; g < sp->n_segments; g++) {
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    irregular += !segment_eval(sc, a, a + 1, sp->seg_spline[g], &s, &seg_len[g], local,
                               ps ? ps + g * (size_t)np : NULL);
    for (int t = 0; t < sc->n_local; t++) term[sc->local[t]] += local[t];
  }
  if (sc->on[LW_TERM_STRAIN])
    for (size_t i = 0; i < sp->n_splines; i++) {
      double L = 0.0;
      size_t g0 = lw_segment_index(sp, i, 0), n = lw_splines_segments(sp, i);
      for (size_t m = 0; m < n; m++) L += seg_len[g0 + m];
      term[LW_TERM_STRAIN] += strain_of_spline(sc, sp, seg_len, i, L);
    }
  free(seg_len);
  if (ps) {
    size_t n = sp->n_segments * (size_t)np;
    lw_cellgrid *g = grid_for(sc, n, err);
    if (!g) {
      free(ps);
      return NAN;
    }
    for (size_t i = 0; i < n; i++)
      if (lw_cellgrid_insert(g, (uint32_t)i, ps[i].x, ps[i].y) != LW_OK) {
        lw_cellgrid_free(g);
        free(ps);
        lw_error_set(err, LW_ENOMEM, "out of memory filling the pair grid");
        return NAN;
      }
    double pe = pair_all(g, sp, ps, np, &sc->pair);
    lw_cellgrid_free(g);
    free(ps);
    if (isnan(pe)) {
      lw_error_set(err, LW_ENOMEM, "out of memory for the pair term's near field");
      return NAN;
    }
    term[LW_TERM_PAIR] = sc->coef[LW_TERM_PAIR] * pe;
  }
  return total_of(term, irregular);
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
  m->seg_irregular = calloc(ns, sizeof *m->seg_irregular);
  if (!m->seg_len || !m->seg_local || !m->spline_len || !m->seg_irregular) goto nomem;
  if (sc->on[LW_TERM_PAIR]) {
    size_t n = sp->n_segments * (size_t)sc->pair_quad.n;
    if (n >= UINT32_MAX || sp->n_splines > LW_PAIR_MAX_SPLINES) {
      lw_error_set(err, LW_EINPUT, "%zu pair samples of %zu splines exceed the grid's limits "
                   "(2^32 samples, 2^26 splines)", n, sp->n_splines);
      lw_model_free(m);
      return NULL;
    }
    m->ps = malloc((n ? n : 1) * sizeof *m->ps);
    m->near_cache = malloc(ns * sizeof *m->near_cache);
    m->near_valid = calloc(ns, sizeof *m->near_valid);
    if (!m->ps || !m->near_cache || !m->near_valid) goto nomem;
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
  free(m->seg_irregular);
  free(m->ps);
  free(m->near_cache);
  free(m->near_valid);
  lw_cellgrid_free(m->grid);
  free(m);
}

double lw_model_total(const lw_model *m)
{
  return total_of(m->term, m->n_irregular);
}

lw_status lw_model_refresh(lw_model *m, double *drift)
{
  const lw_scene *sc = m->scene;
  const lw_splines *sp = m->sp;
  const int np = sc->pair_quad.n, nl = sc->n_local;
  double old_total = lw_model_total(m);
  double term[LW_TERM_COUNT] = {0};
  lw_samples s;
  m->n_irregular = 0;
  for (size_t g = 0; g < sp->n_segments; g++) {
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    double *local = m->seg_local + g * (size_t)nl;
    m->seg_irregular[g] = !segment_eval(sc, a, a + 1, sp->seg_spline[g], &s, &m->seg_len[g], local,
                                        m->ps ? m->ps + g * (size_t)np : NULL);
    m->n_irregular += m->seg_irregular[g];
    for (int t = 0; t < nl; t++) term[sc->local[t]] += local[t];
  }
  for (size_t i = 0; i < sp->n_splines; i++) {
    size_t g0 = lw_segment_index(sp, i, 0), n = lw_splines_segments(sp, i);
    double L = 0.0;
    for (size_t k = 0; k < n; k++) L += m->seg_len[g0 + k];
    m->spline_len[i] = L;
    if (sc->on[LW_TERM_STRAIN]) term[LW_TERM_STRAIN] += strain_of_spline(sc, sp, m->seg_len, i, L);
  }
  if (m->grid) {
    size_t n = sp->n_segments * (size_t)np;
    memset(m->near_valid, 0, sp->n_segments * sizeof *m->near_valid);
    lw_cellgrid_clear(m->grid);
    for (size_t i = 0; i < n; i++)
      if (lw_cellgrid_insert(m->grid, (uint32_t)i, m->ps[i].x, m->ps[i].y) != LW_OK) return LW_ENOMEM;
    double pe = pair_all(m->grid, sp, m->ps, np, &sc->pair);
    if (isnan(pe)) return LW_ENOMEM;
    term[LW_TERM_PAIR] = sc->coef[LW_TERM_PAIR] * pe;
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
    p->ps = malloc(cap * (size_t)m->scene->pair_quad.n * sizeof *p->ps);
    p->near_new = malloc(cap * sizeof *p->near_new);
    p->seg_irregular = malloc(cap * sizeof *p->seg_irregular);
  }
  if (!p || !p->node || !p->len || !p->local || !p->ps || !p->near_new || !p->seg_irregular) {
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
  free(p->near.idx);
  free(p->partners.idx);
  free(p->near_new);
  free(p->seg_irregular);
  free(p);
}

/* Node k of the spline as it would be after the proposal. */
static inline const lw_node *proposed_node(const lw_node *base, const lw_proposal *p, size_t k)
{
  return (k >= p->node0 && k < p->node0 + p->n_node) ? &p->node[k - p->node0] : &base[k];
}

/*
** The pair part of a proposal's dE (no coefficient).  New side: the walk and
** the near field of each new segment.  Old side: the walk, and the near field
** from the model's cache when valid.  The near field is the costly part, and
** a chain at low temperature rejects most proposals, so caching the old side
** halves it.  The cached value of a segment is what this code computes for it
** from the current state (the same sum in the same order), so a cached and a
** recomputed value are bitwise equal; commits invalidate every segment whose
** near field the move changed (its near partners before and after).  The
** partners of both sides are kept in p->partners for the commit.
*/
static double pair_delta(const lw_model *m, lw_proposal *p, const lw_node *base, size_t g0)
{
  const lw_scene *sc = m->scene;
  const lw_splines *sp = m->sp;
  const int np = sc->pair_quad.n;
  double pe = 0.0;
  p->partners.n = 0;
  for (size_t j = 0; j < p->n_seg && !isnan(pe); j++) {
    size_t g = g0 + p->seg0 + j;
    double bez[8];
    node_bezier(proposed_node(base, p, p->seg0 + j), proposed_node(base, p, p->seg0 + j + 1), bez);
    const lw_pair_sample *mine = p->ps + j * (size_t)np;
    pe += pair_walk(m->grid, m->ps, mine, np, p->spline, &sc->pair, &p->near);
    p->near_new[j] = pair_near_part(sp, m->ps, bez, mine, np, &sc->pair, &p->near);
    pe += p->near_new[j];
    for (size_t k = 0; k < p->near.n; k++)
      if (near_push(&p->partners, p->near.idx[k]) != LW_OK) return NAN;
    mine = m->ps + g * (size_t)np;
    pe -= pair_walk(m->grid, m->ps, mine, np, p->spline, &sc->pair, &p->near);
    if (!m->near_valid[g]) {
      node_bezier(&base[p->seg0 + j], &base[p->seg0 + j + 1], bez);
      m->near_cache[g] = pair_near_part(sp, m->ps, bez, mine, np, &sc->pair, &p->near);
      m->near_valid[g] = 1;
    }
    pe -= m->near_cache[g];
    for (size_t k = 0; k < p->near.n; k++)
      if (near_push(&p->partners, p->near.idx[k]) != LW_OK) return NAN;
  }
  return pe;
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
  int was_irregular = 0;            /* an affected segment is irregular now */
  p->irregular = 0;
  for (size_t j = 0; j < p->n_seg; j++) {
    size_t m_loc = p->seg0 + j, g = g0 + m_loc;
    double *local = p->local + j * (size_t)nl;
    p->seg_irregular[j] = !segment_eval(sc, proposed_node(base, p, m_loc), proposed_node(base, p, m_loc + 1),
                                        spline, &s, &p->len[j], local, m->ps ? p->ps + j * (size_t)np : NULL);
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
  if ((forbidden || p->irregular) && !undefined) dE = INFINITY;
  /* Leaving an irregular state (+inf) for a regular one lowers the energy
  ** without bound, whatever the terms do (like leaving a +inf local term). */
  else if (was_irregular && !undefined) dE = -INFINITY;
  /* The pair sum is the costly part: skip it when the move is already
  ** forbidden (+inf) or undefined (NaN). */
  p->pair_done = 0;
  if (m->grid && !(dE == INFINITY) && !isnan(dE)) {
    double pe = pair_delta(m, p, base, g0);
    p->pair_done = !isnan(pe);
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
    const lw_pair_sample *old = m->ps + first;
    for (size_t k = 0; k < n; k++)
      if (lw_cellgrid_move(m->grid, (uint32_t)(first + k), old[k].x, old[k].y, p->ps[k].x, p->ps[k].y) != LW_OK) {
        /* Put the moved ones back: their old cells kept their capacity, so
        ** this cannot fail, and the model is as before the call. */
        for (size_t b = 0; b < k; b++)
          lw_cellgrid_move(m->grid, (uint32_t)(first + b), p->ps[b].x, p->ps[b].y, old[b].x, old[b].y);
        return LW_ENOMEM;
      }
  }
  memcpy(&sp->node[sp->first[p->spline] + p->node0], p->node, p->n_node * sizeof *p->node);
  if (m->grid) {
    if (p->pair_done) {
      for (size_t k = 0; k < p->partners.n; k++) m->near_valid[p->partners.idx[k]] = 0;
      for (size_t j = 0; j < p->n_seg; j++) {
        m->near_cache[g0 + p->seg0 + j] = p->near_new[j];
        m->near_valid[g0 + p->seg0 + j] = 1;
      }
    } else {
      /* committed without a pair evaluation: its partners are unknown */
      memset(m->near_valid, 0, sp->n_segments * sizeof *m->near_valid);
    }
  }
  int nonfinite = 0;
  for (size_t j = 0; j < p->n_seg; j++) {
    size_t g = g0 + p->seg0 + j;
    m->seg_len[g] = p->len[j];
    memcpy(m->seg_local + g * (size_t)nl, p->local + j * (size_t)nl, (size_t)nl * sizeof *m->seg_local);
    m->n_irregular = m->n_irregular - m->seg_irregular[g] + p->seg_irregular[j];
    m->seg_irregular[g] = p->seg_irregular[j];
    if (m->ps) memcpy(m->ps + g * (size_t)np, p->ps + j * (size_t)np, (size_t)np * sizeof *m->ps);
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
