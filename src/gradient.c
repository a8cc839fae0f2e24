/*
** gradient.c -- the gradient of the energy with respect to every node
** (gradient.h): the terms' partials with respect to their samples, taken to
** the nodes through the basis tables of quad.h.
**
** Per segment the samples are linear in (p0, v0, p1, v1):
**     r_q = sum_k pos[q][k] x_k,  r'_q = sum_k d1[q][k] x_k,  r''_q = sum_k d2[q][k] x_k
** (x_0 = p0, x_1 = v0, x_2 = p1, x_3 = v1, per coordinate), and the end
** points are r(0) = p0, r(1) = p1.  So dE/dx_k = sum_q (pos[q][k] dE/dr_q +
** d1[q][k] dE/dr'_q + d2[q][k] dE/dr''_q), plus dE/dr(0) for p0 and dE/dr(1)
** for p1.  The spline term (strain) depends on the segment lengths
** l = sum_q w_q |r'_q| only: dE/dr'_q = dE/dl w_q r'_q / |r'_q|.
**
** The energies are summed in the order lw_energy_compute sums them, so the
** returned terms are bitwise the same values.
*/
#include "linewise/gradient.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/tone.h"

/* Sets every partial of g to 0 for n nodes. */
static void samples_grad_zero(lw_samples_grad *g, int n)
{
  memset(g, 0, sizeof *g);
  g->n = n;
}

void lw_segment_grad_nodes(const lw_quad *q, const lw_samples_grad *g, lw_node *ga, lw_node *gb)
{
  double ax[4] = {0}, ay[4] = {0}; /* (p0, v0, p1, v1) */
  for (int i = 0; i < g->n; i++) {
    const double *cp = q->pos[i], *c1 = q->d1[i], *c2 = q->d2[i];
    for (int k = 0; k < 4; k++) {
      ax[k] += cp[k] * g->x[i] + c1[k] * g->dx[i] + c2[k] * g->ddx[i];
      ay[k] += cp[k] * g->y[i] + c1[k] * g->dy[i] + c2[k] * g->ddy[i];
    }
  }
  ga->px += ax[0] + g->end_x[0];
  ga->py += ay[0] + g->end_y[0];
  ga->vx += ax[1];
  ga->vy += ay[1];
  gb->px += ax[2] + g->end_x[1];
  gb->py += ay[2] + g->end_y[1];
  gb->vx += ax[3];
  gb->vy += ay[3];
}

static int selected(unsigned mask, int t) { return (mask >> t) & 1u; }

/* The tone term's part of one segment's gradient (the segment from a, its
** samples s at the scene's nodes): into sg where the term samples at those
** nodes, else at its own, taken to the nodes' gradients ga and gb here. */
static void tone_grad(const lw_term_ctx *c, const int64_t *r, const lw_node *a, const lw_samples *s,
                      lw_samples_grad *sg, lw_node *ga, lw_node *gb)
{
  lw_samples own;
  lw_samples_grad own_g;
  const int apart = c->quad->n != s->n;
  if (apart) {
    lw_segment_sample(c->quad, a, a + 1, &own);
    samples_grad_zero(&own_g, own.n);
    s = &own;
    sg = &own_g;
  }
  for (int q = 0; q < s->n; q++) {
    double ex, ey, edl;
    lw_tone_sample_grad(c->data, r, c->coef, s->x[q], s->y[q], s->dl[q], &ex, &ey, &edl);
    sg->x[q] += ex;
    sg->y[q] += ey;
    if (!(s->speed[q] > 0.0)) continue; /* dl = w |r'| has no gradient at 0: a subgradient */
    double f = edl * c->quad->w[q] / s->speed[q];
    sg->dx[q] += f * s->dx[q];
    sg->dy[q] += f * s->dy[q];
  }
  if (apart) lw_segment_grad_nodes(c->quad, &own_g, ga, gb);
}

double lw_energy_gradient(const lw_scene *sc, const lw_splines *sp, unsigned term_mask, lw_node *grad,
                          double term[LW_TERM_COUNT], lw_error *err)
{
  double e[LW_TERM_COUNT] = {0};
  memset(grad, 0, sp->n_nodes * sizeof *grad);
  /* the user term (an opaque function) has none */
  for (int t = 0; t < LW_TERM_COUNT; t++) {
    const lw_term_type *r = &lw_term_types[t];
    if (sc->on[t] && selected(term_mask, t) && !r->segment_grad && !r->spline_grad && !r->pairwise && !r->raster) {
      /* (the user term has no key: it named 'energy.user', no parameter) */
      lw_error_set(err, LW_EINPUT, "the %s term has no gradient (%s%s): the dynamics and the quench need one; "
                   "leave the term out", lw_term_names[t], t == LW_TERM_USER ? "the library's " : "energy.",
                   t == LW_TERM_USER ? "lw_scene_set_user_term" : lw_term_names[t]);
      return NAN;
    }
  }
  lw_term_ctx ctx[LW_TERM_COUNT], layer_ctx[LW_LAYERS_MAX][LW_TERM_COUNT];
  lw_scene_term_ctx(sc, ctx);
  for (int k = 0; k < sc->layers.n; k++) lw_scene_layer_ctx(sc, k, layer_ctx[k]);
  int strain = 0; /* spline terms that are on and selected */
  for (int t = 0; t < LW_TERM_COUNT; t++)
    if (lw_term_types[t].spline_grad && sc->on[t] && selected(term_mask, t)) strain = 1;
  /* The tone term: the raster of every sample first, whose residual each
  ** sample's footprint reads (tone.h, lw_tone_sample_grad). */
  int64_t *raster = NULL;
  if (sc->on[LW_TERM_TONE] && selected(term_mask, LW_TERM_TONE)) {
    e[LW_TERM_TONE] = lw_energy_raster(sc, sp, LW_TERM_TONE, &raster, err);
    if (isnan(e[LW_TERM_TONE])) return NAN;
  }
  double *seg_len = NULL, *dlen = NULL;
  if (strain) {
    size_t ns = sp->n_segments ? sp->n_segments : 1;
    seg_len = malloc(ns * sizeof *seg_len);
    dlen = calloc(ns, sizeof *dlen);
    if (!seg_len || !dlen) {
      free(seg_len);
      free(dlen);
      free(raster);
      lw_error_set(err, LW_ENOMEM, "out of memory for the gradient of %zu segments", sp->n_segments);
      return NAN;
    }
  }
  lw_samples s;
  size_t irregular = 0;
  /* the segment lengths first: the spline terms' slopes need whole splines */
  for (size_t g = 0; strain && g < sp->n_segments; g++) {
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    lw_segment_sample(&sc->quad, a, a + 1, &s);
    seg_len[g] = s.length;
  }
  for (size_t i = 0; strain && i < sp->n_splines; i++) {
    size_t g0 = lw_segment_index(sp, i, 0), ns = lw_splines_segments(sp, i);
    const double L = lw_term_spline_length(seg_len + g0, ns, NULL);
    for (int t = 0; t < LW_TERM_COUNT; t++) {
      const lw_term_type *ty = &lw_term_types[t];
      if (!ty->spline_grad || !sc->on[t] || !selected(term_mask, t)) continue;
      e[t] += ctx[t].coef * ty->spline(seg_len + g0, ns, L, sp->rest_length[i], &ctx[t]);
      ty->spline_grad(seg_len + g0, ns, L, sp->rest_length[i], &ctx[t], dlen + g0);
    }
  }
  lw_samples_grad sg;
  for (size_t g = 0; g < sp->n_segments; g++) {
    const size_t k = lw_segment_node(sp, g);
    const lw_node *a = &sp->node[k];
    lw_segment_sample(&sc->quad, a, a + 1, &s);
    irregular += !lw_segment_allowed(sc, a, a + 1, s.length);
    samples_grad_zero(&sg, s.n);
    const lw_term_ctx *c = sc->layers.n ? layer_ctx[lw_splines_layer(&sc->layers, sp, sp->seg_spline[g])] : ctx;
    for (int j = 0; j < sc->n_local; j++) {
      const int t = sc->local[j];
      if (!selected(term_mask, t)) continue;
      e[t] += lw_term_types[t].segment(&s, &c[t]);
      lw_term_types[t].segment_grad(&s, &c[t], &sg);
    }
    if (raster) {
      const lw_tone *tn = c[LW_TERM_TONE].data;
      const int layer = sc->layers.n ? lw_splines_layer(&sc->layers, sp, sp->seg_spline[g]) : 0;
      tone_grad(&c[LW_TERM_TONE], raster + (size_t)layer * (size_t)tn->w * (size_t)tn->h, a, &s, &sg, &grad[k],
                &grad[k + 1]);
    }
    if (strain)
      for (int q = 0; q < s.n; q++) {
        if (!(s.speed[q] > 0.0)) continue; /* |r'| has no gradient at 0: a subgradient */
        double f = dlen[g] * sc->quad.w[q] / s.speed[q];
        sg.dx[q] += f * s.dx[q];
        sg.dy[q] += f * s.dy[q];
      }
    lw_segment_grad_nodes(&sc->quad, &sg, &grad[k], &grad[k + 1]);
  }
  free(seg_len);
  free(dlen);
  free(raster);
  if (sc->on[LW_TERM_PAIR] && selected(term_mask, LW_TERM_PAIR)) {
    e[LW_TERM_PAIR] = lw_pair_gradient(sc, sp, grad, err);
    if (isnan(e[LW_TERM_PAIR])) {
      if (term) memcpy(term, e, sizeof e);
      return NAN;
    }
  }
  if (term) memcpy(term, e, sizeof e);
  double total = 0.0;
  for (int t = 0; t < LW_TERM_COUNT; t++) total += e[t];
  return irregular ? INFINITY : total;
}
