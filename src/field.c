/*
** field.c -- grids with bilinear interpolation, analytic potentials and vector
** fields (field.h).
**
** Everything past construction runs in the annealer's inner loop: no
** allocation, one switch on the kind, and a grid lookup that cannot produce
** NaN whatever the query point (NaN and infinite coordinates are clamped onto
** the grid like any other far-away point).
**
** The analytic presets trust their parameters (scale > 0, wavelength > 0, unit
** directions): those are checked once where the scene is read, not per call.
*/
#include "linewise/field.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

lw_grid2d *lw_grid2d_new(int nx, int ny, int ncomp, double x0, double y0,
                         double hx, double hy, lw_error *err)
{
  if (nx < 1 || ny < 1) {
    lw_error_set(err, LW_EINPUT, "grid needs at least 1 node per axis (got %d x %d)", nx, ny);
    return NULL;
  }
  if (ncomp != 1 && ncomp != 2) {
    lw_error_set(err, LW_EINPUT, "grid needs 1 or 2 values per node (got %d)", ncomp);
    return NULL;
  }
  /* A NaN origin or spacing would turn every lookup into NaN. */
  if (!isfinite(x0) || !isfinite(y0)) {
    lw_error_set(err, LW_EINPUT, "grid origin (%g, %g) is not finite", x0, y0);
    return NULL;
  }
  if (!isfinite(hx) || !isfinite(hy) || hx <= 0 || hy <= 0) {
    lw_error_set(err, LW_EINPUT, "grid spacing (%g, %g) must be finite and > 0", hx, hy);
    return NULL;
  }
  /* nx * ny * ncomp in size_t, checked so a huge image cannot wrap around
  ** to a small allocation. */
  size_t count = (size_t)nx;
  if ((size_t)ny > SIZE_MAX / count) goto too_big;
  count *= (size_t)ny;
  if ((size_t)ncomp > SIZE_MAX / sizeof(double) / count) goto too_big;
  count *= (size_t)ncomp;

  lw_grid2d *g = malloc(sizeof *g);
  if (!g) goto nomem;
  g->data = calloc(count, sizeof *g->data);
  if (!g->data) {
    free(g);
    goto nomem;
  }
  g->nx = nx;
  g->ny = ny;
  g->ncomp = ncomp;
  g->x0 = x0;
  g->y0 = y0;
  g->hx = hx;
  g->hy = hy;
  return g;

too_big:
  lw_error_set(err, LW_EINPUT, "grid of %d x %d x %d values is too large", nx, ny, ncomp);
  return NULL;
nomem:
  lw_error_set(err, LW_ENOMEM, "out of memory for a %d x %d grid", nx, ny);
  return NULL;
}

void lw_grid2d_free(lw_grid2d *g)
{
  if (!g) return;
  free(g->data);
  free(g);
}

size_t lw_grid2d_sanitize(lw_grid2d *g)
{
  if (!g || !g->data) return 0;
  size_t n = (size_t)g->nx * (size_t)g->ny * (size_t)g->ncomp, bad = 0;
  for (size_t k = 0; k < n; k++) {
    if (!isfinite(g->data[k])) {
      g->data[k] = 0.0;
      bad++;
    }
  }
  return bad;
}

/* Locates coordinate x on an axis of n nodes: the cell index *i (0 <= *i <=
** n - 2, or 0 when n == 1) and the fraction *t in [0, 1] inside it.  The
** coordinate is clamped to the node range first, so points beyond the edge
** read the edge value; "!(u > 0)" also sends NaN to the first node.
** Returns 1 where x was not clamped (the value moves with x there). */
static inline int locate(double x, double x0, double h, int n, int *i, double *t)
{
  if (n < 2) {
    *i = 0;
    *t = 0.0;
    return 0;
  }
  double u = (x - x0) / h, top = (double)(n - 1);
  int inside = 1;
  if (!(u > 0.0)) {
    u = 0.0;
    inside = 0;
  } else if (u > top) {
    u = top;
    inside = 0;
  }
  int k = (int)u; /* u >= 0, so truncation is floor */
  if (k > n - 2) k = n - 2; /* u == top: last cell at t = 1 */
  *i = k;
  *t = u - (double)k;
  return inside;
}

void lw_grid2d_eval(const lw_grid2d *g, double x, double y, double *out)
{
  int i, j;
  double tx, ty;
  locate(x, g->x0, g->hx, g->nx, &i, &tx);
  locate(y, g->y0, g->hy, g->ny, &j, &ty);
  const int nc = g->ncomp;
  /* A 1-node axis has no neighbour: reuse the same node (weight 0 anyway)
  ** rather than read past the row or the array. */
  const size_t di = g->nx > 1 ? (size_t)nc : 0;
  const size_t dj = g->ny > 1 ? (size_t)g->nx * (size_t)nc : 0;
  const double *p = g->data + ((size_t)j * (size_t)g->nx + (size_t)i) * (size_t)nc;
  const double w00 = (1.0 - tx) * (1.0 - ty), w10 = tx * (1.0 - ty);
  const double w01 = (1.0 - tx) * ty, w11 = tx * ty;
  for (int c = 0; c < nc; c++)
    out[c] = w00 * p[c] + w10 * p[di + c] + w01 * p[dj + c] + w11 * p[dj + di + c];
}

/* The bilinear value as lw_grid2d_eval computes it, and its partials: in
** x, (1 - ty)(p10 - p00) + ty (p11 - p01) per unit of tx, 0 across a
** clamped edge. */
void lw_grid2d_eval_grad(const lw_grid2d *g, double x, double y, double *out, double *dx, double *dy)
{
  int i, j;
  double tx, ty;
  const int in_x = locate(x, g->x0, g->hx, g->nx, &i, &tx);
  const int in_y = locate(y, g->y0, g->hy, g->ny, &j, &ty);
  const int nc = g->ncomp;
  const size_t di = g->nx > 1 ? (size_t)nc : 0;
  const size_t dj = g->ny > 1 ? (size_t)g->nx * (size_t)nc : 0;
  const double *p = g->data + ((size_t)j * (size_t)g->nx + (size_t)i) * (size_t)nc;
  const double w00 = (1.0 - tx) * (1.0 - ty), w10 = tx * (1.0 - ty);
  const double w01 = (1.0 - tx) * ty, w11 = tx * ty;
  for (int c = 0; c < nc; c++) {
    const double p00 = p[c], p10 = p[di + c], p01 = p[dj + c], p11 = p[dj + di + c];
    out[c] = w00 * p00 + w10 * p10 + w01 * p01 + w11 * p11;
    dx[c] = in_x ? ((1.0 - ty) * (p10 - p00) + ty * (p11 - p01)) / g->hx : 0.0;
    dy[c] = in_y ? ((1.0 - tx) * (p01 - p00) + tx * (p11 - p10)) / g->hy : 0.0;
  }
}

double lw_potential_eval(const lw_potential *f, double x, double y)
{
  switch (f->kind) {
  case LW_POTENTIAL_CONSTANT:
    return f->value;
  case LW_POTENTIAL_RAMP:
    return 0.5 + 0.5 * ((x - f->cx) * f->ux + (y - f->cy) * f->uy) / f->scale;
  case LW_POTENTIAL_RADIAL: {
    /* sqrt rather than hypot: page coordinates cannot overflow a square and
    ** hypot is several times slower. */
    double dx = x - f->cx, dy = y - f->cy;
    return sqrt(dx * dx + dy * dy) / f->scale;
  }
  case LW_POTENTIAL_GRID: {
    /* A missing or mis-shaped grid reads as 0, not as out-of-bounds memory. */
    if (!f->grid || f->grid->ncomp != 1) return 0.0;
    double v;
    lw_grid2d_eval(f->grid, x, y, &v);
    return v;
  }
  }
  return 0.0;
}

/* The core's factor g(r) on a radial or vortex field, and dg/dr in *dg.
** The unit field's direction turns through pi around its centre within
** any distance d of it: on a segment passing at d, the term's integrand
** changes on the scale d, which no fixed rule resolves as d -> 0 (8 nodes
** took a 10 mm segment 0.2 mm from a vortex's centre 48 % off, and 8
** nodes on one through a signed radial centre 81 %).  Inside the core the
** field's length falls to 0 as u^3, so the integrand changes on the scale
** of the core, whatever d; smootherstep keeps v and its Jacobian
** continuous at r = a, so neither the energy nor the gradient jumps. */
static double core_factor(const lw_field *f, double r, double *dg)
{
  if (dg) *dg = 0.0;
  if (!(f->core > 0.0) || r >= f->core) return 1.0;
  const double u = r / f->core;
  if (dg) *dg = 30.0 * u * u * (1.0 - u) * (1.0 - u) / f->core;
  return u * u * u * (10.0 + u * (6.0 * u - 15.0));
}

static void eval_raw(const lw_field *f, double x, double y, double *vx, double *vy)
{
  switch (f->kind) {
  case LW_FIELD_CONSTANT:
    *vx = f->ux;
    *vy = f->uy;
    return;
  case LW_FIELD_RADIAL:
  case LW_FIELD_VORTEX: {
    double dx = x - f->cx, dy = y - f->cy, r2 = dx * dx + dy * dy;
    /* The direction is undefined at the centre; 0 there keeps the energy
    ** finite and the centre a neutral point. */
    if (!(r2 > 0.0)) {
      *vx = *vy = 0.0;
      return;
    }
    double inv = core_factor(f, sqrt(r2), NULL) / sqrt(r2);
    if (f->kind == LW_FIELD_RADIAL) {
      *vx = dx * inv;
      *vy = dy * inv;
    } else {
      *vx = -dy * inv;
      *vy = dx * inv;
    }
    return;
  }
  case LW_FIELD_WAVES: {
    double k = 2.0 * M_PI / f->wavelength;
    double s = k * f->amplitude * cos(k * x); /* dy/dx of A sin(kx) */
    double inv = 1.0 / sqrt(1.0 + s * s);
    *vx = inv;
    *vy = s * inv;
    return;
  }
  case LW_FIELD_GRID: {
    if (!f->grid || f->grid->ncomp != 2) {
      *vx = *vy = 0.0;
      return;
    }
    double v[2];
    lw_grid2d_eval(f->grid, x, y, v);
    *vx = v[0];
    *vy = v[1];
    return;
  }
  case LW_FIELD_GRID_AXIAL: {
    double q[2];
    if (!f->grid || f->grid->ncomp != 2) {
      *vx = *vy = 0.0;
      return;
    }
    lw_grid2d_eval(f->grid, x, y, q);
    double m = sqrt(q[0] * q[0] + q[1] * q[1]);
    if (!(m > 0.0)) {
      *vx = *vy = 0.0;
      return;
    }
    /* Both (m + q0, q1) and (q1, m - q0) point along the half angle, with
    ** lengths sqrt(2 m (m +- q0)); the one with the larger length has no
    ** cancellation.  Scaled to length m, no trigonometry needed. */
    double hx, hy, den;
    if (q[0] >= 0.0) {
      hx = m + q[0];
      hy = q[1];
      den = m + q[0];
    } else {
      hx = q[1];
      hy = m - q[0];
      den = m - q[0];
    }
    double s = sqrt(m / (2.0 * den));
    *vx = hx * s;
    *vy = hy * s;
    return;
  }
  }
  *vx = *vy = 0.0;
}

double lw_potential_grad(const lw_potential *f, double x, double y, double g[2])
{
  g[0] = g[1] = 0.0;
  switch (f->kind) {
  case LW_POTENTIAL_CONSTANT:
    break;
  case LW_POTENTIAL_RAMP:
    g[0] = 0.5 * f->ux / f->scale;
    g[1] = 0.5 * f->uy / f->scale;
    break;
  case LW_POTENTIAL_RADIAL: {
    double dx = x - f->cx, dy = y - f->cy, r = sqrt(dx * dx + dy * dy);
    if (r > 0.0) { /* the cone's tip has no gradient: 0, a subgradient */
      g[0] = dx / (r * f->scale);
      g[1] = dy / (r * f->scale);
    }
    break;
  }
  case LW_POTENTIAL_GRID:
    if (!f->grid || f->grid->ncomp != 1) return 0.0;
    double v;
    lw_grid2d_eval_grad(f->grid, x, y, &v, &g[0], &g[1]);
    return v;
  }
  return lw_potential_eval(f, x, y);
}

/* The half-angle map of grid_axial, v = |q|^(1/2) q^(1/2) in complex
** notation (q the interpolated doubled-angle vector, |v| = |q| = m), has
** dv = v (q.dq) / (2 m^2) + conj(v) dq / (2 m): with the chain rule
** through the bilinear q(x, y) that is J.  Whichever branch lw_field_eval
** takes, J is that branch's derivative (both branches are +-v, and so
** are their derivatives). */
static void axial_jacobian(const lw_grid2d *g, double x, double y, const double v[2], double J[2][2])
{
  double q[2], qx[2], qy[2];
  lw_grid2d_eval_grad(g, x, y, q, qx, qy);
  double m2 = q[0] * q[0] + q[1] * q[1];
  if (!(m2 > 0.0)) return;
  double b = 1.0 / (2.0 * sqrt(m2)), c0 = q[0] / (2.0 * m2), c1 = q[1] / (2.0 * m2);
  /* dv/dq0 and dv/dq1 */
  double d0x = v[0] * c0 + v[0] * b, d0y = v[1] * c0 - v[1] * b;
  double d1x = v[0] * c1 + v[1] * b, d1y = v[1] * c1 + v[0] * b;
  J[0][0] = d0x * qx[0] + d1x * qx[1];
  J[0][1] = d0x * qy[0] + d1x * qy[1];
  J[1][0] = d0y * qx[0] + d1y * qx[1];
  J[1][1] = d0y * qy[0] + d1y * qy[1];
}

static void jacobian_raw(const lw_field *f, double x, double y, double v[2], double J[2][2])
{
  eval_raw(f, x, y, &v[0], &v[1]);
  J[0][0] = J[0][1] = J[1][0] = J[1][1] = 0.0;
  switch (f->kind) {
  case LW_FIELD_CONSTANT:
    return;
  case LW_FIELD_RADIAL:
  case LW_FIELD_VORTEX: {
    /* n = (r - c) / |r - c| has dn = (I - n n^T) / |r - c|; the vortex is n
    ** turned by a quarter, so its rows are radial's turned likewise. */
    double dx = x - f->cx, dy = y - f->cy, r = sqrt(dx * dx + dy * dy);
    if (!(r > 0.0)) return;
    double nx = dx / r, ny = dy / r;
    double a = (1.0 - nx * nx) / r, b = -nx * ny / r, c = (1.0 - ny * ny) / r;
    double m[2] = {nx, ny};
    if (f->kind == LW_FIELD_RADIAL) {
      J[0][0] = a;
      J[0][1] = J[1][0] = b;
      J[1][1] = c;
    } else { /* v = (-n_y, n_x) */
      J[0][0] = -b;
      J[0][1] = -c;
      J[1][0] = a;
      J[1][1] = b;
      m[0] = -ny, m[1] = nx;
    }
    /* in the core v = g(r) m: dv = g dm + m (g'(r) n)^T */
    double dg, g = core_factor(f, r, &dg);
    for (int i = 0; i < 2; i++) {
      J[i][0] = g * J[i][0] + dg * m[i] * nx;
      J[i][1] = g * J[i][1] + dg * m[i] * ny;
    }
    return;
  }
  case LW_FIELD_WAVES: {
    /* v = (1, s) / sqrt(1 + s^2), s = k A cos(k x): dv/ds = (-s, 1) (1 + s^2)^(-3/2) */
    double k = 2.0 * M_PI / f->wavelength;
    double s = k * f->amplitude * cos(k * x), ds = -k * k * f->amplitude * sin(k * x);
    double c = 1.0 / ((1.0 + s * s) * sqrt(1.0 + s * s));
    J[0][0] = -s * c * ds;
    J[1][0] = c * ds;
    return;
  }
  case LW_FIELD_GRID: {
    if (!f->grid || f->grid->ncomp != 2) return;
    double out[2], gx[2], gy[2];
    lw_grid2d_eval_grad(f->grid, x, y, out, gx, gy);
    J[0][0] = gx[0];
    J[0][1] = gy[0];
    J[1][0] = gx[1];
    J[1][1] = gy[1];
    return;
  }
  case LW_FIELD_GRID_AXIAL:
    if (!f->grid || f->grid->ncomp != 2) return;
    axial_jacobian(f->grid, x, y, v, J);
    return;
  }
}

/* A turned field (a hatching layer's, layers.h) is R v with R the turn:
** its Jacobian is R J, the rotation being constant. */
void lw_field_eval(const lw_field *f, double x, double y, double *vx, double *vy)
{
  eval_raw(f, x, y, vx, vy);
  if (!f->turned) return;
  double a = *vx, b = *vy;
  *vx = f->turn_c * a - f->turn_s * b;
  *vy = f->turn_s * a + f->turn_c * b;
}

void lw_field_jacobian(const lw_field *f, double x, double y, double v[2], double J[2][2])
{
  jacobian_raw(f, x, y, v, J);
  if (!f->turned) return;
  const double c = f->turn_c, s = f->turn_s;
  double a = v[0], b = v[1];
  v[0] = c * a - s * b;
  v[1] = s * a + c * b;
  for (int j = 0; j < 2; j++) {
    a = J[0][j];
    b = J[1][j];
    J[0][j] = c * a - s * b;
    J[1][j] = s * a + c * b;
  }
}

void lw_potential_clear(lw_potential *f)
{
  if (!f) return;
  lw_grid2d_free(f->grid);
  f->grid = NULL;
}

void lw_field_clear(lw_field *f)
{
  if (!f) return;
  lw_grid2d_free(f->grid);
  f->grid = NULL;
}
