/*
** sys_nurbs.h -- the D-NURBS system's row of the system table (system.h):
** one NURBS curve (nurbs.h) whose control points are the coordinates, its
** weights frozen, with the energy and matrices of dnurbs.h (docs/NURBS.md).
**
** Terms: `elastic` (1/2 int alpha |c_u|^2 + beta |c_uu|^2 du) and `gravity`
** (-int mu g . c du with mu = dynamics.rho and g = dynamics.gravity_x,
** gravity_y).  Move kind: `point` (one free control point by a uniform step
** in a square of half side `step`; [moves] step_point and target).
** nurbs.fixed control points at each end are held by Monte Carlo and the
** dynamics alike.  The mass matrix is dynamics.rho times M1, constant.
** In state.lw: [system nurbs] with `count` and a `point = x y` line per
** control point.  Drawings: final.svg, final.png, frames/frame-SSSSSS.png.
*/
#ifndef LINEWISE_SYS_NURBS_H
#define LINEWISE_SYS_NURBS_H

#include "linewise/dnurbs.h"
#include "linewise/system.h"

extern const lw_system_type lw_system_nurbs;

/* The set-up's parts the tests and the benchmark read. */
typedef struct {
  lw_nurbs *curve;        /* the initial curve: knots, weights, points */
  lw_dnurbs *mat;         /* K, M1, b */
  unsigned char *pin;     /* n: held control points */
  double *f;              /* 2 n: the load mu g b_i */
  size_t *free_idx, n_free;
  double step_max;
  double tolerance, png_scale;
  double view[4];         /* frames: x0 y0 x1 y1 */
} lw_nurbs_setup;

typedef struct {
  const lw_nurbs_setup *su;
  lw_nurbs *c;            /* c->P are the coordinates */
  double *KP;             /* 2 n: K P, kept with the moves */
  double term[2];         /* elastic, gravity */
  double deviation;       /* of the last final.svg */
  size_t beziers;
} lw_nurbs_state;

/* The set-up of a curve built in memory (taken over, freed on failure; NULL
** passes through) with the other [nurbs] and [dynamics] keys of p: what the
** row's setup_new does after reading the curve's keys. */
lw_nurbs_setup *lw_nurbs_setup_new(const lw_params *p, lw_nurbs *curve, lw_error *err);

#endif
