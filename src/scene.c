/* scene.c -- building the scene from parameters (scene.h). */
#include "linewise/scene.h"

#include <gsl/gsl_math.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define DEG (M_PI / 180.0)

static lw_status build_polygon(lw_scene *sc, const lw_params *p, lw_error *err)
{
  const lw_param_def *d = lw_params_find("scene", "polygon");
  char where[LW_PATH_MAX + 32];
  lw_params_origin(p, d, where, sizeof where);
  size_t cap = 16, n = 0;
  double *v = malloc(cap * sizeof *v);
  if (!v) return lw_error_set(err, LW_ENOMEM, "out of memory reading the polygon");
  const char *c = p->polygon;
  for (;;) {
    char *end;
    while (*c == ' ' || *c == '\t' || *c == ',') c++;
    if (!*c) break;
    double x = strtod(c, &end);
    if (end == c || !isfinite(x)) {
      free(v);
      return lw_error_set(err, LW_EINPUT, "%s: key 'scene.polygon': expected numbers 'x y x y ...', got '%s'",
                          where, c);
    }
    if (n == cap) {
      double *nv = realloc(v, 2 * cap * sizeof *v);
      if (!nv) { free(v); return lw_error_set(err, LW_ENOMEM, "out of memory reading the polygon"); }
      v = nv;
      cap *= 2;
    }
    v[n++] = x;
    c = end;
  }
  lw_status st = LW_OK;
  if (n % 2 || n < 6) {
    st = lw_error_set(err, LW_EINPUT, "%s: key 'scene.polygon': expected at least 3 vertices as 'x y' pairs, got %zu numbers",
                      where, n);
  } else {
    double *xs = malloc(n / 2 * sizeof *xs), *ys = malloc(n / 2 * sizeof *ys);
    if (!xs || !ys) st = lw_error_set(err, LW_ENOMEM, "out of memory reading the polygon");
    else {
      for (size_t i = 0; i < n / 2; i++) { xs[i] = v[2 * i]; ys[i] = v[2 * i + 1]; }
      lw_error e2;
      st = lw_boundary_polygon(&sc->boundary, n / 2, xs, ys, &e2);
      if (st != LW_OK) lw_error_set(err, st, "%s: key 'scene.polygon': %s", where, e2.msg);
    }
    free(xs);
    free(ys);
  }
  free(v);
  return st;
}

/* The per-segment terms that are on, in term order (the order sums run in). */
static void list_local_terms(lw_scene *sc)
{
  sc->n_local = 0;
  for (int t = 0; t < LW_TERM_COUNT; t++)
    if (sc->on[t] && lw_term_types[t].segment) sc->local[sc->n_local++] = (lw_term_id)t;
}

lw_status lw_scene_set_user_term(lw_scene *sc, double coef, lw_user_term_fn fn, const void *data,
                                 lw_error *err)
{
  if (!isfinite(coef) || (coef != 0.0 && !fn))
    return lw_error_set(err, LW_EINPUT, "user term: expected a finite coefficient and a function, got %g and %s",
                        coef, fn ? "a function" : "none");
  sc->coef[LW_TERM_USER] = coef;
  sc->on[LW_TERM_USER] = coef != 0.0;
  sc->user_fn = coef != 0.0 ? fn : NULL;
  sc->user_data = coef != 0.0 ? data : NULL;
  list_local_terms(sc);
  return LW_OK;
}

lw_status lw_scene_init(lw_scene *sc, const lw_params *p, lw_error *err)
{
  memset(sc, 0, sizeof *sc);
  sc->width = p->width;
  sc->height = p->height;
  const double coef[LW_TERM_COUNT] = {
    [LW_TERM_STRAIN] = p->strain, [LW_TERM_BENDING] = p->bending,
    [LW_TERM_POTENTIAL] = p->potential_coef, [LW_TERM_FIELD] = p->field_coef,
    [LW_TERM_PAIR] = p->pair, [LW_TERM_BOUNDARY] = p->boundary_coef,
  };
  for (int t = 0; t < LW_TERM_COUNT; t++) {
    sc->coef[t] = coef[t];
    sc->on[t] = coef[t] != 0.0;
  }
  list_local_terms(sc);
  sc->strain_per_segment = p->strain_mode == LW_STRAIN_SEGMENT;
  sc->field_axial = p->field_mode == LW_FIELDMODE_AXIAL;
  lw_status st = lw_quad_init(&sc->quad, p->quadrature, err);
  if (st) return st;
  lw_pair_ctx_init(&sc->pair, &sc->quad, p->pair_cutoff, p->pair_near);

  double cx = p->center_x >= 0 ? p->center_x : 0.5 * p->width;
  double cy = p->center_y >= 0 ? p->center_y : 0.5 * p->height;

  if (sc->on[LW_TERM_POTENTIAL]) {
    lw_potential *f = &sc->potential;
    f->cx = cx;
    f->cy = cy;
    switch (p->potential) {
    case LW_POT_CONSTANT:
      f->kind = LW_POTENTIAL_CONSTANT;
      f->value = p->potential_value;
      break;
    case LW_POT_RAMP:
      f->kind = LW_POTENTIAL_RAMP;
      f->ux = cos(p->potential_angle * DEG);
      f->uy = sin(p->potential_angle * DEG);
      /* half the page's extent along u, so Phi runs 0..1 corner to corner */
      f->scale = p->potential_scale > 0 ? p->potential_scale
                 : 0.5 * (fabs(f->ux) * p->width + fabs(f->uy) * p->height);
      break;
    case LW_POT_RADIAL:
      f->kind = LW_POTENTIAL_RADIAL;
      f->scale = p->potential_scale > 0 ? p->potential_scale : 0.5 * hypot(p->width, p->height);
      break;
    }
  }
  if (sc->on[LW_TERM_FIELD]) {
    lw_field *f = &sc->field;
    f->cx = cx;
    f->cy = cy;
    f->ux = cos(p->field_angle * DEG);
    f->uy = sin(p->field_angle * DEG);
    f->wavelength = p->field_wavelength;
    f->amplitude = p->field_amplitude;
    static const lw_field_kind kinds[] = {
      [LW_FLD_CONSTANT] = LW_FIELD_CONSTANT, [LW_FLD_RADIAL] = LW_FIELD_RADIAL,
      [LW_FLD_VORTEX] = LW_FIELD_VORTEX, [LW_FLD_WAVES] = LW_FIELD_WAVES,
    };
    f->kind = kinds[p->field];
  }

  lw_boundary *b = &sc->boundary;
  switch (p->boundary) {
  case LW_BND_RECT:
  case LW_BND_CIRCLE:
    if (2 * p->margin >= p->width || 2 * p->margin >= p->height) {
      const lw_param_def *d = lw_params_find("scene", "margin");
      char where[LW_PATH_MAX + 32];
      lw_params_origin(p, d, where, sizeof where);
      return lw_error_set(err, LW_EINPUT,
                          "%s: key 'scene.margin': expected less than half the page (%g x %g mm), got %g",
                          where, p->width, p->height, p->margin);
    }
    if (p->boundary == LW_BND_RECT) {
      b->kind = LW_BOUNDARY_RECT;
      b->x0 = p->margin;
      b->y0 = p->margin;
      b->x1 = p->width - p->margin;
      b->y1 = p->height - p->margin;
    } else {
      b->kind = LW_BOUNDARY_CIRCLE;
      b->cx = 0.5 * p->width;
      b->cy = 0.5 * p->height;
      b->radius = 0.5 * fmin(p->width, p->height) - p->margin;
    }
    break;
  case LW_BND_POLYGON:
    st = build_polygon(sc, p, err);
    if (st) return st;
    break;
  }
  return LW_OK;
}

void lw_scene_clear(lw_scene *sc)
{
  lw_potential_clear(&sc->potential);
  lw_field_clear(&sc->field);
  lw_boundary_clear(&sc->boundary);
}
