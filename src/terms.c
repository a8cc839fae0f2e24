/*
** terms.c -- the energy terms as pure functions of a segment's samples
** (terms.h).  No allocation, no I/O, no globals: these run in the proposal
** loop of every replica at once.
*/
#include "linewise/terms.h"

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
    double cross = s->dx[i] * s->ddy[i] - s->ddx[i] * s->dy[i];
    sum += q->w[i] * cross * cross / (sp2 * sp2 * s->speed[i]);
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
  /* Gauss nodes never reach the segment ends: check the nodes themselves so
  ** no drawn end pokes out of the frame. */
  for (int e = 0; e < 2; e++)
    if (!(lw_boundary_distance(b, s->end_x[e], s->end_y[e]) < 0.0)) return INFINITY;
  double sum = 0.0;
  for (int i = 0; i < s->n; i++) {
    double d = lw_boundary_distance(b, s->x[i], s->y[i]);
    if (!(d < 0.0)) return INFINITY; /* on or beyond the frame, or NaN: forbidden */
    sum += s->dl[i] / (d * d);
  }
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

const char *const lw_term_names[LW_TERM_COUNT] = {"strain", "bending", "potential", "field",
                                                  "pair", "boundary", "user", "parametrisation", "tone"};

const lw_term_type lw_term_types[LW_TERM_COUNT] = {
  {LW_TERM_STRAIN, .spline = spline_strain},
  {LW_TERM_BENDING, .segment = seg_bending},
  {LW_TERM_POTENTIAL, .segment = seg_potential},
  {LW_TERM_FIELD, .segment = seg_field},
  {LW_TERM_PAIR, .pairwise = 1},
  {LW_TERM_BOUNDARY, .segment = seg_boundary},
  {LW_TERM_USER, .segment = seg_user},
  {LW_TERM_PARAM, .segment = seg_param},
  {LW_TERM_TONE, .raster = 1},
};
