/*
** sys_nurbs.h -- the D-NURBS system's row of the system table (system.h):
** one NURBS curve (nurbs.h) whose control points are the coordinates, with
** the energy and matrices of dnurbs.h (docs/NURBS.md).
**
** Terms: `elastic` (1/2 int alpha |c_u|^2 + beta |c_uu|^2 du) and `gravity`
** (-int mu g . c du with mu = dynamics.rho and g = dynamics.gravity_x,
** gravity_y).  Move kinds: `point` (one free control point by a uniform step
** in a square of half side `step`; [moves] step_point and target) and
** `weight` (free weights only: one free s_j = log w_j by a uniform step of
** half width `step`; nurbs.step_weight).
** nurbs.fixed control points at each end are held by Monte Carlo and the
** dynamics alike, with their weights.  Frozen weights (the default): the
** coordinates are x y of each point, the mass matrix dynamics.rho times M1,
** constant.  nurbs.free_weights = 1: x y s of each point, and the mass
** matrix depends on the curve (dnurbs.h, lw_dnurbs_mass_s).
** In state.lw: [system nurbs] with `count`, a `point = x y` line per control
** point and, with free weights, a `log_weight = s` line per control point.
** Drawings: final.svg, final.png, frames/frame-SSSSSS.png.
*/
#ifndef LINEWISE_SYS_NURBS_H
#define LINEWISE_SYS_NURBS_H

#include "linewise/dnurbs.h"
#include "linewise/system.h"

#ifdef __cplusplus
extern "C" {
#endif

extern const lw_system_type lw_system_nurbs;

/* The set-up's parts the tests and the benchmark read. */
typedef struct {
  lw_nurbs *curve;        /* the initial curve: knots, weights, points */
  lw_dnurbs *mat;         /* K, M1, b */
  unsigned char *pin;     /* n: held control points */
  double *f;              /* 2 n: the load mu g b_i */
  size_t *free_idx, n_free;
  int free_weights;       /* 1: s = log w are coordinates too */
  double *s0;             /* n: the scene's log weights (curve->w = exp(s0) then) */
  double mug[2];          /* mu g */
  double weight_inertia;  /* free weights: added to the mass of each s, per unit density */
  double weight_stiffness;/* free weights: E_w = 1/2 weight_stiffness sum s_j^2 */
  double step_max;
  double tolerance, png_scale;
  double view[4];         /* frames: x0 y0 x1 y1 */
} lw_nurbs_setup;

typedef struct {
  const lw_nurbs_setup *su;
  lw_nurbs *c;            /* c->P are the coordinates; c->w = exp(s) */
  double *s;              /* n: log weights, free weights only (else NULL) */
  lw_dnurbs *own;         /* free weights: K, M1, b at c->w (else NULL) */
  const lw_dnurbs *mat;   /* su->mat or own */
  double *f;              /* 2 n: the load mu g b_i at c->w */
  double term[3];         /* elastic, gravity, weights */
  double deviation;       /* of the last final.svg */
  size_t beziers;
} lw_nurbs_state;

/* The set-up of a curve built in memory (taken over, freed on failure; NULL
** passes through) with the other [nurbs] and [dynamics] keys of p: what the
** row's setup_new does after reading the curve's keys. */
lw_nurbs_setup *lw_nurbs_setup_new(const lw_params *p, lw_nurbs *curve, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
