/*
** field.h -- the scalar potential Phi(x, y) and the vector field v(x, y) that
** the potential and field energy terms read.
**
** Both are either an analytic preset (no image needed) or samples on a regular
** grid read by bilinear interpolation.  Coordinates are scene millimetres with
** the origin at the top-left corner of the page, y pointing down (as in SVG).
**
** Presets (c = centre, mm):
**   potential constant  Phi = value
**   potential ramp      Phi = 1/2 + 1/2 (r - c).u / h, u = (cos a, sin a), h = scale
**                       (h defaults to half the page extent along u: Phi in [0,1])
**   potential radial    Phi = |r - c| / scale
**   field constant      v = (cos a, sin a)
**   field radial        v = g (r - c) / |r - c|            (0 at c)
**   field vortex        v = g (-(y - cy), x - cx) / |r - c| (0 at c; counter-clockwise
**                       on a y-up page)
**                       g = 1, or within the core radius a: g = 6u^5 - 15u^4 + 10u^3,
**                       u = |r - c| / a (C2 at a; v ~ r^3 near c, smooth there)
**   field waves         v = (1, k A cos(k x)) / |(1, k A cos(k x))|, k = 2 pi / wavelength:
**                       the tangents of the curves y = A sin(k x) + const
**   field grid_axial    a grid of directions without sign (imagefield.h's edge tangent
**                       flow): a node holds the doubled-angle vector
**                       m (cos 2t, sin 2t) of the direction t with weight m; bilinear
**                       interpolation of those, then back to the half angle, gives
**                       m (cos t, sin t) up to sign.  Interpolating the vectors
**                       themselves would cancel where neighbours differ only in
**                       their arbitrary signs.  Only the axial field energy
**                       (|r'.v|) reads it meaningfully.
** Grid values beyond the edge take the value at the nearest edge point, so a
** field is defined everywhere; grid data are sanitised on construction (a
** non-finite sample becomes 0) so no lookup returns NaN.
*/
#ifndef LINEWISE_FIELD_H
#define LINEWISE_FIELD_H

#include <stddef.h>

#include "linewise/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Samples on a regular grid: node (i, j) sits at (x0 + i hx, y0 + j hy) and
** holds ncomp values at data[(j * nx + i) * ncomp + c]. */
typedef struct {
  int nx, ny;        /* nodes per axis, >= 1 */
  int ncomp;         /* values per node: 1 (potential) or 2 (field) */
  double x0, y0;     /* position of node (0, 0), mm */
  double hx, hy;     /* node spacing, mm (> 0) */
  double *data;      /* nx * ny * ncomp values, owned */
} lw_grid2d;

/* Allocates a zeroed grid; NULL and err set on failure. */
lw_grid2d *lw_grid2d_new(int nx, int ny, int ncomp, double x0, double y0,
                         double hx, double hy, lw_error *err);
void lw_grid2d_free(lw_grid2d *g);
/* Replaces non-finite samples by 0; returns how many were replaced. */
size_t lw_grid2d_sanitize(lw_grid2d *g);
/* Bilinear interpolation of all components at (x, y) into out[ncomp]. */
void lw_grid2d_eval(const lw_grid2d *g, double x, double y, double *out);

typedef enum {
  LW_POTENTIAL_CONSTANT,
  LW_POTENTIAL_RAMP,
  LW_POTENTIAL_RADIAL,
  LW_POTENTIAL_GRID
} lw_potential_kind;

typedef struct {
  lw_potential_kind kind;
  double value;      /* constant: Phi */
  double cx, cy;     /* ramp, radial: centre, mm */
  double ux, uy;     /* ramp: unit direction */
  double scale;      /* ramp: half extent h; radial: radius, mm (> 0) */
  lw_grid2d *grid;   /* grid: owned, ncomp = 1 */
} lw_potential;

typedef enum {
  LW_FIELD_CONSTANT,
  LW_FIELD_RADIAL,
  LW_FIELD_VORTEX,
  LW_FIELD_WAVES,
  LW_FIELD_GRID,
  LW_FIELD_GRID_AXIAL
} lw_field_kind;

typedef struct {
  lw_field_kind kind;
  double ux, uy;       /* constant: unit direction */
  double cx, cy;       /* radial, vortex: centre, mm */
  double core;         /* radial, vortex: core radius a, mm (0: none) */
  double wavelength;   /* waves: mm (> 0) */
  double amplitude;    /* waves: mm */
  lw_grid2d *grid;     /* grid, grid_axial: owned, ncomp = 2 */
  int turned;          /* 1: every value is turned by the angle (cos, sin) below:
                          a hatching layer's field (layers.h) */
  double turn_c, turn_s;
} lw_field;

double lw_potential_eval(const lw_potential *f, double x, double y);
void lw_field_eval(const lw_field *f, double x, double y, double *vx, double *vy);

/* Derivatives (the gradient of the energy, gradient.h): the same values as
** the _eval functions and the derivatives of exactly those functions --
** bilinear within a cell, 0 across a clamped edge, one-sided on a cell
** line; 0 where a preset sets its value to 0 (a centre).
** lw_grid2d_eval_grad: out[c] and its partials dx[c], dy[c].
** lw_potential_grad: Phi, and g = (dPhi/dx, dPhi/dy).
** lw_field_jacobian: v, and J[i][j] = dv_i / dx_j. */
void lw_grid2d_eval_grad(const lw_grid2d *g, double x, double y, double *out, double *dx, double *dy);
double lw_potential_grad(const lw_potential *f, double x, double y, double g[2]);
void lw_field_jacobian(const lw_field *f, double x, double y, double v[2], double J[2][2]);

/* Free the grid a field owns (if any) and reset it; the struct itself is the
** caller's. */
void lw_potential_clear(lw_potential *f);
void lw_field_clear(lw_field *f);

#ifdef __cplusplus
}
#endif

#endif
