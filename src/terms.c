/*
** terms.c -- the energy terms as pure functions of a segment's samples
** (terms.h).  No allocation, no I/O, no globals: these run in the proposal
** loop of every replica at once.
*/
#include "linewise/terms.h"

#include <float.h>
#include <math.h>
#include <string.h>

double lw_term_strain(double length, double rest_length)
{
  double x = length - rest_length;
  return x * x / (rest_length * rest_length) * length;
}

double lw_term_bending(const lw_samples *s, const lw_quad *q)
{
  double sum = 0.0;
  for (int i = 0; i < s->n; i++) {
    double sp2 = s->speed[i] * s->speed[i];
    if (sp2 == 0.0) continue; /* r' = 0: numerator is 0 too; a point does not bend */
    double cross = s->dx[i] * s->ddy[i] - s->ddx[i] * s->dy[i], den = sp2 * sp2 * s->speed[i];
    /* |r'|^5 underflows on a segment of 1e-65 mm, where cross / |r'|^2 does
    ** not: the straight one's bending was 0 / 0 */
    if (den >= DBL_MIN) sum += q->w[i] * cross * cross / den;
    else if (cross != 0.0) sum += q->w[i] * (cross / sp2) * (cross / sp2) / s->speed[i];
  }
  return sum;
}

double lw_term_potential(const lw_samples *s, const lw_quad *q, const lw_potential *f)
{
  double sum = 0.0;
  for (int i = 0; i < s->n; i++) {
    if (s->dl[i] == 0.0) continue; /* no length, no contribution (even at an odd Phi) */
    sum += lw_potential_eval(f, s->x[i], s->y[i]) * s->dl[i];
  }
  return sum;
}

double lw_term_field(const lw_samples *s, const lw_quad *q, const lw_field *f, int axial)
{
  double sum = 0.0;
  for (int i = 0; i < s->n; i++) {
    double vx, vy;
    lw_field_eval(f, s->x[i], s->y[i], &vx, &vy);
    double dot = s->dx[i] * vx + s->dy[i] * vy;
    sum += q->w[i] * (axial ? fabs(dot) : dot);
  }
  return sum;
}

double lw_term_boundary(const lw_samples *s, const lw_quad *q, const lw_boundary *b)
{
  double sum = 0.0;
  for (int i = 0; i < s->n; i++) {
    double d = lw_boundary_distance(b, s->x[i], s->y[i]);
    if (!(d < 0.0)) return INFINITY; /* on or beyond the frame, or NaN: forbidden */
    sum += s->dl[i] / (d * d);
  }
  /* The whole curve, its ends (which no Gauss node reaches) and the stretches
  ** between the nodes, with room: 1/d^2 is resolved by n nodes only where the
  ** curve keeps some length elements from the frame (its pole at d = 0 then
  ** lies outside the rule's Bernstein ellipse); a bulge or an end closer than
  ** that would hide most of its energy (docs/NUMERICS.md). */
  const double x[4] = {s->end_x[0], s->hand_x[0], s->hand_x[1], s->end_x[1]};
  const double y[4] = {s->end_y[0], s->hand_y[0], s->hand_y[1], s->end_y[1]};
  if (!lw_boundary_curve_clear(b, x, y, b->clearance * s->length / s->n)) return INFINITY;
  return sum;
}

double lw_term_parametrisation(const lw_samples *s, const lw_quad *q)
{
  const double l = s->length;
  if (!(l > 0.0)) return 0.0; /* a point: every speed is 0, and so is the mean */
  double sum = 0.0;
  for (int i = 0; i < s->n; i++) {
    double d = s->speed[i] - l;
    sum += q->w[i] * d * d;
  }
  return sum / l;
}

double lw_term_load(const lw_samples *s, const double b[2])
{
  double sum = 0.0;
  for (int i = 0; i < s->n; i++) sum -= s->dl[i] * (b[0] * s->x[i] + b[1] * s->y[i]);
  return sum;
}

static double seg_bending(const lw_samples *s, const lw_term_ctx *c)
{
  return c->coef * lw_term_bending(s, c->quad);
}

static double seg_potential(const lw_samples *s, const lw_term_ctx *c)
{
  return c->coef * lw_term_potential(s, c->quad, c->data);
}

static double seg_field(const lw_samples *s, const lw_term_ctx *c)
{
  return c->coef * lw_term_field(s, c->quad, c->data, c->mode);
}

static double seg_boundary(const lw_samples *s, const lw_term_ctx *c)
{
  return c->coef * lw_term_boundary(s, c->quad, c->data);
}

static double seg_user(const lw_samples *s, const lw_term_ctx *c)
{
  return c->coef * c->fn(s, c->quad, c->data);
}

static double seg_param(const lw_samples *s, const lw_term_ctx *c)
{
  return c->coef * lw_term_parametrisation(s, c->quad);
}

static double seg_load(const lw_samples *s, const lw_term_ctx *c)
{
  return c->coef * lw_term_load(s, c->data);
}

/* The whole spline's length against its rest length, or (mode 1) each
** segment's against an equal share of it. */
static double spline_strain(const double *seg_len, size_t n_seg, double length, double rest_length,
                            const lw_term_ctx *c)
{
  if (!c->mode) return lw_term_strain(length, rest_length);
  double l0 = rest_length / (double)n_seg, e = 0.0;
  for (size_t m = 0; m < n_seg; m++) e += lw_term_strain(seg_len[m], l0);
  return e;
}

double lw_term_block_sum(const double *seg, size_t n, size_t b0)
{
  double s = 0.0;
  for (size_t k = b0; k < n && k < b0 + LW_TERM_LEN_BLOCK; k++) s += seg[k];
  return s;
}

double lw_term_spline_length(const double *seg, size_t n, const double *blk)
{
  double L = 0.0;
  for (size_t b0 = 0; b0 < n; b0 += LW_TERM_LEN_BLOCK) L += blk ? blk[b0] : lw_term_block_sum(seg, n, b0);
  return L;
}

static double change_strain(const double *old_seg, const double *new_seg, size_t n_changed, size_t n_seg,
                            double old_len, double new_len, double rest_length, const lw_term_ctx *c)
{
  if (!c->mode) return lw_term_strain(new_len, rest_length) - lw_term_strain(old_len, rest_length);
  double l0 = rest_length / (double)n_seg, d = 0.0;
  for (size_t m = 0; m < n_changed; m++) d += lw_term_strain(new_seg[m], l0) - lw_term_strain(old_seg[m], l0);
  return d;
}

/*
** Gradients (terms.h): each adds coef * dE/d(sample) to g.  The energies
** above are sums over the nodes of w_q f(r_q, r'_q, r''_q), so each node's
** partials are those of its own summand.  With s = |r'| the length element
** w s has d(w s)/dr' = w r' / s; a node with s = 0 has no gradient of s and
** contributes 0 (a subgradient of |r'|), as it contributes 0 energy to
** bending and potential.
*/

/* bending: w c^2 / s^5 with c = x'y'' - x''y' */
static void grad_bending(const lw_samples *s, const lw_term_ctx *ctx, lw_samples_grad *g)
{
  const lw_quad *q = ctx->quad;
  for (int i = 0; i < s->n; i++) {
    double sp2 = s->speed[i] * s->speed[i];
    if (sp2 == 0.0) continue;
    double c = s->dx[i] * s->ddy[i] - s->ddx[i] * s->dy[i];
    if (c == 0.0) continue; /* straight: no gradient, also where s^-5 overflows (0 inf) */
    const double den = sp2 * sp2 * s->speed[i];
    if (!(den >= DBL_MIN)) {
      /* as the energy, through k = c / s^2, where s^5 underflows; dE/dc and
      ** dE/dr' (about 1 / s^3) overflow where s is under 1e-103, their
      ** products with r' and r'' (about 1 / s^2) do not: those, from the
      ** components over s */
      const double k = c / sp2, w = ctx->coef * q->w[i] / sp2, sp = s->speed[i];
      const double ux = s->dx[i] / sp, uy = s->dy[i] / sp, vx = s->ddx[i] / sp, vy = s->ddy[i] / sp;
      g->dx[i] += w * (2.0 * k * vy - 5.0 * k * k * ux);
      g->dy[i] += w * (-2.0 * k * vx - 5.0 * k * k * uy);
      g->ddx[i] += -w * 2.0 * k * uy;
      g->ddy[i] += w * 2.0 * k * ux;
      continue;
    }
    const double inv5 = 1.0 / den;
    const double a = ctx->coef * q->w[i] * 2.0 * c * inv5;            /* dE/dc */
    const double b = -ctx->coef * q->w[i] * 5.0 * c * c * inv5 / sp2; /* dE/dr' = b r' through s^-5 */
    g->dx[i] += a * s->ddy[i] + b * s->dx[i];
    g->dy[i] += -a * s->ddx[i] + b * s->dy[i];
    g->ddx[i] += -a * s->dy[i];
    g->ddy[i] += a * s->dx[i];
  }
}

/* potential: Phi(r) w s */
static void grad_potential(const lw_samples *s, const lw_term_ctx *ctx, lw_samples_grad *g)
{
  const lw_quad *q = ctx->quad;
  for (int i = 0; i < s->n; i++) {
    if (s->dl[i] == 0.0) continue;
    double dphi[2], phi = lw_potential_grad(ctx->data, s->x[i], s->y[i], dphi);
    double k = ctx->coef * q->w[i];
    g->x[i] += k * s->speed[i] * dphi[0];
    g->y[i] += k * s->speed[i] * dphi[1];
    g->dx[i] += k * phi * s->dx[i] / s->speed[i];
    g->dy[i] += k * phi * s->dy[i] / s->speed[i];
  }
}

/* field: w r'.v(r), or w |r'.v(r)| with the sign of r'.v (0 at r'.v = 0, a
** subgradient of the kink) */
static void grad_field(const lw_samples *s, const lw_term_ctx *ctx, lw_samples_grad *g)
{
  const lw_quad *q = ctx->quad;
  for (int i = 0; i < s->n; i++) {
    double v[2], J[2][2];
    lw_field_jacobian(ctx->data, s->x[i], s->y[i], v, J);
    double dot = s->dx[i] * v[0] + s->dy[i] * v[1];
    double k = ctx->coef * q->w[i];
    if (ctx->mode) k *= dot > 0.0 ? 1.0 : (dot < 0.0 ? -1.0 : 0.0);
    g->dx[i] += k * v[0];
    g->dy[i] += k * v[1];
    g->x[i] += k * (s->dx[i] * J[0][0] + s->dy[i] * J[1][0]);
    g->y[i] += k * (s->dx[i] * J[0][1] + s->dy[i] * J[1][1]);
  }
}

/* boundary: w s / d(r)^2 inside; +inf states have no gradient (the end
** points only gate the energy, so their partials are 0) */
static void grad_boundary(const lw_samples *s, const lw_term_ctx *ctx, lw_samples_grad *g)
{
  const lw_quad *q = ctx->quad;
  for (int i = 0; i < s->n; i++) {
    double dd[2], d = lw_boundary_distance_grad(ctx->data, s->x[i], s->y[i], dd);
    if (!(d < 0.0)) return;
    double k = ctx->coef * q->w[i] / (d * d);
    g->x[i] += -2.0 * k * s->speed[i] / d * dd[0];
    g->y[i] += -2.0 * k * s->speed[i] / d * dd[1];
    if (s->speed[i] > 0.0) {
      g->dx[i] += k * s->dx[i] / s->speed[i];
      g->dy[i] += k * s->dy[i] / s->speed[i];
    }
  }
}

/* parametrisation: D / l with D = sum w (s - l)^2, l = sum w s; with
** sum w = 1, dD/ds_k = 2 w_k (s_k - l) (the l-derivative 2 sum w (s - l)
** vanishes), so dE/ds_k = 2 w_k (s_k - l) / l - D w_k / l^2 */
static void grad_param(const lw_samples *s, const lw_term_ctx *ctx, lw_samples_grad *g)
{
  const lw_quad *q = ctx->quad;
  const double l = s->length;
  if (!(l > 0.0)) return;
  double D = 0.0;
  for (int i = 0; i < s->n; i++) {
    double d = s->speed[i] - l;
    D += q->w[i] * d * d;
  }
  for (int i = 0; i < s->n; i++) {
    if (!(s->speed[i] > 0.0)) continue;
    double dEds = ctx->coef * q->w[i] * (2.0 * (s->speed[i] - l) / l - D / (l * l));
    g->dx[i] += dEds * s->dx[i] / s->speed[i];
    g->dy[i] += dEds * s->dy[i] / s->speed[i];
  }
}

/* d/dL of (L - L0)^2 / L0^2 * L */
static double strain_slope(double length, double rest_length)
{
  double x = length - rest_length;
  return (2.0 * x * length + x * x) / (rest_length * rest_length);
}

static void grad_strain(const double *seg_len, size_t n_seg, double length, double rest_length,
                        const lw_term_ctx *c, double *dlen)
{
  if (!c->mode) {
    double k = c->coef * strain_slope(length, rest_length);
    for (size_t m = 0; m < n_seg; m++) dlen[m] += k;
    return;
  }
  double l0 = rest_length / (double)n_seg;
  for (size_t m = 0; m < n_seg; m++) dlen[m] += c->coef * strain_slope(seg_len[m], l0);
}

/* load: -w s b.r */
static void grad_load(const lw_samples *s, const lw_term_ctx *ctx, lw_samples_grad *g)
{
  const double *b = ctx->data;
  for (int i = 0; i < s->n; i++) {
    double k = -ctx->coef * ctx->quad->w[i];
    g->x[i] += k * s->speed[i] * b[0];
    g->y[i] += k * s->speed[i] * b[1];
    if (s->speed[i] == 0.0) continue;
    double f = k * (b[0] * s->x[i] + b[1] * s->y[i]) / s->speed[i];
    g->dx[i] += f * s->dx[i];
    g->dy[i] += f * s->dy[i];
  }
}

/* The chemical potential of one spline: data is {mu_s, mu_l}. */
static double spline_chemical(const double *seg_len, size_t n_seg, double length, double rest_length,
                              const lw_term_ctx *c)
{
  (void)seg_len, (void)n_seg, (void)rest_length;
  const double *mu = c->data;
  return mu[0] + mu[1] * length;
}

static double change_chemical(const double *old_seg, const double *new_seg, size_t n_changed, size_t n_seg,
                              double old_len, double new_len, double rest_length, const lw_term_ctx *c)
{
  (void)old_seg, (void)new_seg, (void)n_changed;
  return spline_chemical(NULL, n_seg, new_len, rest_length, c) - spline_chemical(NULL, n_seg, old_len, rest_length, c);
}

static void grad_chemical(const double *seg_len, size_t n_seg, double length, double rest_length,
                          const lw_term_ctx *c, double *dlen)
{
  (void)seg_len, (void)length, (void)rest_length;
  const double *mu = c->data;
  for (size_t m = 0; m < n_seg; m++) dlen[m] += c->coef * mu[1];
}

/* (by id: an entry left out is NULL, which tests/test_terms.c finds, where
** a list by position shifted every name after it) */
const char *const lw_term_names[LW_TERM_COUNT] = {
  [LW_TERM_STRAIN] = "strain", [LW_TERM_BENDING] = "bending", [LW_TERM_POTENTIAL] = "potential",
  [LW_TERM_FIELD] = "field", [LW_TERM_PAIR] = "pair", [LW_TERM_BOUNDARY] = "boundary", [LW_TERM_USER] = "user",
  [LW_TERM_PARAM] = "parametrisation", [LW_TERM_LOAD] = "load", [LW_TERM_TONE] = "tone",
  [LW_TERM_CHEMICAL] = "chemical",
};

const lw_term_type lw_term_types[LW_TERM_COUNT] = {
  [LW_TERM_STRAIN] = {LW_TERM_STRAIN, .spline = spline_strain, .spline_change = change_strain,
                      .spline_grad = grad_strain},
  [LW_TERM_BENDING] = {LW_TERM_BENDING, .segment = seg_bending, .segment_grad = grad_bending},
  [LW_TERM_POTENTIAL] = {LW_TERM_POTENTIAL, .segment = seg_potential, .segment_grad = grad_potential},
  [LW_TERM_FIELD] = {LW_TERM_FIELD, .segment = seg_field, .segment_grad = grad_field},
  [LW_TERM_PAIR] = {LW_TERM_PAIR, .pairwise = 1}, /* lw_pair_gradient (gradient.h) */
  [LW_TERM_BOUNDARY] = {LW_TERM_BOUNDARY, .segment = seg_boundary, .segment_grad = grad_boundary},
  [LW_TERM_USER] = {LW_TERM_USER, .segment = seg_user}, /* no gradient: the caller's function is opaque */
  [LW_TERM_PARAM] = {LW_TERM_PARAM, .segment = seg_param, .segment_grad = grad_param},
  [LW_TERM_LOAD] = {LW_TERM_LOAD, .segment = seg_load, .segment_grad = grad_load},
  [LW_TERM_TONE] = {LW_TERM_TONE, .raster = 1}, /* its gradient: lw_tone_sample_grad, summed in gradient.c */
  [LW_TERM_CHEMICAL] = {LW_TERM_CHEMICAL, .spline = spline_chemical, .spline_change = change_chemical,
                        .spline_grad = grad_chemical},
};
