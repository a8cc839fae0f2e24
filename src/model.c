/*
** model.c -- state, caches, local energy differences and commits (model.h),
** and the from-scratch energy that checks them.
*/
#include "linewise/model.h"

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

/* Kernel sum of sample `me` (of spline `spline`) with every grid sample of
** another spline whose index exceeds `after` (-1: all).  Cells and their
** sorted entries are visited in a fixed order, so the sum depends on the
** positions only. */
static double neighbour_sum(const lw_cellgrid *g, const lw_pair_sample *all, const lw_pair_sample *me,
                            uint32_t spline, long long after, const lw_pair_ctx *ctx)
{
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
        if ((long long)c->idx[k] > after && o->spline != spline) sum += lw_pair_kernel(me, o, ctx);
      }
    }
  }
  return sum;
}

/* Pair energy (no coefficient) between the n samples `mine` of spline
** `spline` and every grid sample of another spline. */
static double pair_against(const lw_cellgrid *g, const lw_pair_sample *all, const lw_pair_sample *mine,
                           int n, uint32_t spline, const lw_pair_ctx *ctx)
{
  double sum = 0.0;
  for (int i = 0; i < n; i++) sum += neighbour_sum(g, all, &mine[i], spline, -1, ctx);
  return sum;
}

/* Every pair of samples of different splines once (j > i). */
static double pair_all(const lw_cellgrid *g, const lw_pair_sample *all, size_t n, const lw_pair_ctx *ctx)
{
  double sum = 0.0;
  for (size_t i = 0; i < n; i++) sum += neighbour_sum(g, all, &all[i], all[i].spline, (long long)i, ctx);
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
    term[LW_TERM_PAIR] = sc->coef[LW_TERM_PAIR] * pair_all(g, ps, n, &sc->pair);
    lw_cellgrid_free(g);
    free(ps);
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
    if (!m->ps) goto nomem;
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
    lw_cellgrid_clear(m->grid);
    for (size_t i = 0; i < n; i++)
      if (lw_cellgrid_insert(m->grid, (uint32_t)i, m->ps[i].x, m->ps[i].y) != LW_OK) return LW_ENOMEM;
    term[LW_TERM_PAIR] = sc->coef[LW_TERM_PAIR] * pair_all(m->grid, m->ps, n, &sc->pair);
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
    p->seg_irregular = malloc(cap * sizeof *p->seg_irregular);
  }
  if (!p || !p->node || !p->len || !p->local || !p->ps || !p->seg_irregular) {
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
  free(p->seg_irregular);
  free(p);
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
  if (m->grid && !(dE == INFINITY) && !isnan(dE)) {
    double pe = 0.0;
    for (size_t j = 0; j < p->n_seg; j++) {
      size_t g = g0 + p->seg0 + j;
      pe += pair_against(m->grid, m->ps, p->ps + j * (size_t)np, np, spline, &sc->pair);
      pe -= pair_against(m->grid, m->ps, m->ps + g * (size_t)np, np, spline, &sc->pair);
    }
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
