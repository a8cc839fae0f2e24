/* test_field.c -- grids, bilinear interpolation, potentials and vector fields. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>

#include "linewise/field.h"
#include "testutil.h"


static int irand(int lo, int hi) { return lo + (int)floor(urand(0, 1) * (hi - lo + 1)); }

typedef struct { double a, b, c, d; } bilin;
static double bilin_at(const bilin *f, double x, double y)
{
  return f->a + f->b * x + f->c * y + f->d * x * y;
}
static bilin bilin_rand(void)
{
  bilin f = {urand(-10, 10), urand(-10, 10), urand(-10, 10), urand(-10, 10)};
  return f;
}
static double clampd(double v, double lo, double hi) { return v < lo ? lo : (v > hi ? hi : v); }

/* A grid with random shape, origin and spacing, component c filled with f[c]. */
static lw_grid2d *grid_of(int nx, int ny, int ncomp, const bilin *f)
{
  lw_error err;
  lw_grid2d *g = lw_grid2d_new(nx, ny, ncomp, urand(-20, 20), urand(-20, 20), urand(0.1, 5),
                               urand(0.1, 5), &err);
  cr_assert_not_null(g, "%s", err.msg);
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++)
      for (int c = 0; c < ncomp; c++)
        g->data[(j * nx + i) * ncomp + c] = bilin_at(&f[c], g->x0 + i * g->hx, g->y0 + j * g->hy);
  return g;
}

Test(field, grid_new_zeroed_and_rejects_bad_shapes)
{
  lw_error err;
  lw_grid2d *g = lw_grid2d_new(3, 4, 2, 1.5, -2.5, 0.5, 0.25, &err);
  cr_assert_not_null(g);
  cr_assert(g->nx == 3 && g->ny == 4 && g->ncomp == 2);
  cr_assert(g->x0 == 1.5 && g->y0 == -2.5 && g->hx == 0.5 && g->hy == 0.25);
  for (int k = 0; k < 24; k++) cr_assert(g->data[k] == 0.0);
  lw_grid2d_free(g);
  lw_grid2d_free(NULL);

  struct { int nx, ny, nc; double hx, hy, x0; } bad[] = {
    {0, 4, 1, 1, 1, 0}, {4, 0, 1, 1, 1, 0}, {-1, 4, 1, 1, 1, 0}, {4, 4, 0, 1, 1, 0},
    {4, 4, 3, 1, 1, 0}, {4, 4, 1, 0, 1, 0}, {4, 4, 1, 1, -1, 0}, {4, 4, 1, NAN, 1, 0},
    {4, 4, 1, 1, INFINITY, 0}, {4, 4, 1, 1, 1, NAN},
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    lw_error_clear(&err);
    cr_assert_null(lw_grid2d_new(bad[k].nx, bad[k].ny, bad[k].nc, bad[k].x0, 0, bad[k].hx,
                                 bad[k].hy, &err), "case %zu", k);
    cr_assert_eq(err.code, LW_EINPUT, "case %zu", k);
    cr_assert(err.msg[0] != '\0', "case %zu has a message", k);
  }
  /* NULL err is allowed */
  cr_assert_null(lw_grid2d_new(0, 1, 1, 0, 0, 1, 1, NULL));
}

Test(field, bilinear_reproduces_bilinear_functions_inside)
{
  rng_seed(0x5eed0001);
  for (int trial = 0; trial < 50; trial++) {
    bilin f = bilin_rand();
    lw_grid2d *g = grid_of(irand(2, 9), irand(2, 9), 1, &f);
    double xe = g->x0 + (g->nx - 1) * g->hx, ye = g->y0 + (g->ny - 1) * g->hy;
    for (int k = 0; k < 200; k++) {
      double x = urand(g->x0, xe), y = urand(g->y0, ye), v;
      lw_grid2d_eval(g, x, y, &v);
      double want = bilin_at(&f, x, y);
      cr_assert(lw_close_rel(v, want, 1e-11, 100.0), "trial %d (%.17g, %.17g): %.17g vs %.17g",
                trial, x, y, v, want);
    }
    lw_grid2d_free(g);
  }
}

Test(field, bilinear_equals_node_values_at_nodes)
{
  rng_seed(0x5eed0002);
  lw_grid2d *g = lw_grid2d_new(7, 5, 1, urand(-5, 5), urand(-5, 5), urand(0.2, 3), urand(0.2, 3),
                               NULL);
  cr_assert_not_null(g);
  /* node values with no smooth structure at all */
  for (int k = 0; k < 35; k++) g->data[k] = urand(-1e3, 1e3);
  for (int j = 0; j < 5; j++)
    for (int i = 0; i < 7; i++) {
      double v;
      lw_grid2d_eval(g, g->x0 + i * g->hx, g->y0 + j * g->hy, &v);
      cr_assert(lw_close_rel(v, g->data[j * 7 + i], 1e-12, 1e3), "node (%d, %d): %.17g vs %.17g",
                i, j, v, g->data[j * 7 + i]);
    }
  lw_grid2d_free(g);
}

Test(field, bilinear_clamps_beyond_edges)
{
  rng_seed(0x5eed0003);
  bilin f = bilin_rand();
  lw_grid2d *g = grid_of(6, 4, 1, &f);
  double xe = g->x0 + 5 * g->hx, ye = g->y0 + 3 * g->hy;
  double w = xe - g->x0, h = ye - g->y0;
  for (int k = 0; k < 500; k++) {
    /* points all around the grid, most of them outside */
    double x = urand(g->x0 - 2 * w, xe + 2 * w), y = urand(g->y0 - 2 * h, ye + 2 * h), v, e;
    lw_grid2d_eval(g, x, y, &v);
    double cx = clampd(x, g->x0, xe), cy = clampd(y, g->y0, ye);
    lw_grid2d_eval(g, cx, cy, &e);
    cr_assert(lw_close_rel(v, e, 1e-12, 100.0), "(%g, %g)", x, y);
    /* and the edge value is the function's value there */
    cr_assert(lw_close_rel(v, bilin_at(&f, cx, cy), 1e-11, 100.0), "(%g, %g)", x, y);
  }
  /* far away, infinite and NaN coordinates: the nearest edge or corner, never NaN */
  double v;
  lw_grid2d_eval(g, -1e300, 1e300, &v);
  cr_assert(lw_close_rel(v, g->data[3 * 6 + 0], 1e-12, 1.0));
  lw_grid2d_eval(g, INFINITY, -INFINITY, &v);
  cr_assert(lw_close_rel(v, g->data[5], 1e-12, 1.0));
  lw_grid2d_eval(g, NAN, NAN, &v);
  cr_assert(isfinite(v));
  lw_grid2d_eval(g, NAN, ye + 1, &v);
  cr_assert(isfinite(v));
  lw_grid2d_free(g);
}

Test(field, one_node_axes_are_constant_along_that_axis)
{
  rng_seed(0x5eed0004);
  /* 1 x N: varies along y only, linearly between nodes */
  bilin f = bilin_rand();
  lw_grid2d *g = grid_of(1, 6, 1, &f);
  double ye = g->y0 + 5 * g->hy;
  for (int k = 0; k < 300; k++) {
    double x = urand(-100, 100), y = urand(g->y0 - 3, ye + 3), v;
    lw_grid2d_eval(g, x, y, &v);
    double want = bilin_at(&f, g->x0, clampd(y, g->y0, ye));
    cr_assert(lw_close_rel(v, want, 1e-11, 100.0), "1xN at (%g, %g): %.17g vs %.17g", x, y, v,
              want);
  }
  lw_grid2d_free(g);

  /* N x 1: varies along x only */
  f = bilin_rand();
  g = grid_of(5, 1, 1, &f);
  double xe = g->x0 + 4 * g->hx;
  for (int k = 0; k < 300; k++) {
    double x = urand(g->x0 - 3, xe + 3), y = urand(-100, 100), v;
    lw_grid2d_eval(g, x, y, &v);
    double want = bilin_at(&f, clampd(x, g->x0, xe), g->y0);
    cr_assert(lw_close_rel(v, want, 1e-11, 100.0), "Nx1 at (%g, %g): %.17g vs %.17g", x, y, v,
              want);
  }
  lw_grid2d_free(g);

  /* 1 x 1: one value everywhere */
  g = lw_grid2d_new(1, 1, 2, 3, 4, 1, 1, NULL);
  cr_assert_not_null(g);
  g->data[0] = urand(-5, 5);
  g->data[1] = urand(-5, 5);
  for (int k = 0; k < 50; k++) {
    double v[2];
    lw_grid2d_eval(g, urand(-50, 50), urand(-50, 50), v);
    cr_assert(v[0] == g->data[0] && v[1] == g->data[1]);
  }
  lw_grid2d_free(g);
}

Test(field, two_component_grids_interpolate_each_component)
{
  rng_seed(0x5eed0005);
  for (int trial = 0; trial < 20; trial++) {
    bilin f[2] = {bilin_rand(), bilin_rand()};
    lw_grid2d *g = grid_of(irand(2, 8), irand(2, 8), 2, f);
    double xe = g->x0 + (g->nx - 1) * g->hx, ye = g->y0 + (g->ny - 1) * g->hy;
    for (int k = 0; k < 200; k++) {
      double x = urand(g->x0, xe), y = urand(g->y0, ye), v[2];
      lw_grid2d_eval(g, x, y, v);
      for (int c = 0; c < 2; c++)
        cr_assert(lw_close_rel(v[c], bilin_at(&f[c], x, y), 1e-11, 100.0),
                  "trial %d component %d", trial, c);
    }
    /* the field reads the same grid */
    lw_field fl = {.kind = LW_FIELD_GRID, .grid = g};
    double x = urand(g->x0, xe), y = urand(g->y0, ye), vx, vy;
    lw_field_eval(&fl, x, y, &vx, &vy);
    cr_assert(lw_close_rel(vx, bilin_at(&f[0], x, y), 1e-11, 100.0));
    cr_assert(lw_close_rel(vy, bilin_at(&f[1], x, y), 1e-11, 100.0));
    lw_field_clear(&fl);
    cr_assert_null(fl.grid);
  }
}

Test(field, sanitize_replaces_non_finite_and_counts)
{
  rng_seed(0x5eed0006);
  lw_grid2d *g = lw_grid2d_new(4, 3, 2, 0, 0, 1, 1, NULL);
  cr_assert_not_null(g);
  for (int k = 0; k < 24; k++) g->data[k] = urand(-3, 3);
  double keep[24];
  for (int k = 0; k < 24; k++) keep[k] = g->data[k];
  g->data[0] = NAN;
  g->data[7] = INFINITY;
  g->data[13] = -INFINITY;
  g->data[23] = -NAN;
  cr_assert_eq(lw_grid2d_sanitize(g), 4);
  for (int k = 0; k < 24; k++) {
    if (k == 0 || k == 7 || k == 13 || k == 23) cr_assert(g->data[k] == 0.0, "sample %d", k);
    else cr_assert(g->data[k] == keep[k], "sample %d untouched", k);
  }
  cr_assert_eq(lw_grid2d_sanitize(g), 0);
  cr_assert_eq(lw_grid2d_sanitize(NULL), 0);
  lw_grid2d_free(g);
}

Test(field, potential_presets_match_formulas)
{
  rng_seed(0x5eed0007);
  for (int trial = 0; trial < 20; trial++) {
    double a = urand(-M_PI, M_PI);
    lw_potential c = {.kind = LW_POTENTIAL_CONSTANT, .value = urand(-5, 5)};
    lw_potential r = {.kind = LW_POTENTIAL_RAMP, .cx = urand(0, 200), .cy = urand(0, 300),
                      .ux = cos(a), .uy = sin(a), .scale = urand(10, 200)};
    lw_potential q = {.kind = LW_POTENTIAL_RADIAL, .cx = urand(0, 200), .cy = urand(0, 300),
                      .scale = urand(10, 200)};
    for (int k = 0; k < 100; k++) {
      double x = urand(-50, 250), y = urand(-50, 350);
      cr_assert(lw_potential_eval(&c, x, y) == c.value);
      double want = 0.5 + 0.5 * ((x - r.cx) * r.ux + (y - r.cy) * r.uy) / r.scale;
      cr_assert(lw_close_rel(lw_potential_eval(&r, x, y), want, 1e-13, 1.0));
      want = hypot(x - q.cx, y - q.cy) / q.scale;
      cr_assert(lw_close_rel(lw_potential_eval(&q, x, y), want, 1e-13, 1.0));
    }
    cr_assert(lw_potential_eval(&q, q.cx, q.cy) == 0.0);
    cr_assert(lw_close_rel(lw_potential_eval(&r, r.cx, r.cy), 0.5, 1e-15, 1.0));
  }
}

Test(field, ramp_spans_zero_to_one_over_the_page)
{
  rng_seed(0x5eed0008);
  const double W = 210, H = 297;
  for (int trial = 0; trial < 40; trial++) {
    double a = trial < 4 ? trial * M_PI / 2 : urand(-M_PI, M_PI);
    double ux = cos(a), uy = sin(a);
    lw_potential r = {.kind = LW_POTENTIAL_RAMP, .cx = W / 2, .cy = H / 2, .ux = ux, .uy = uy,
                      .scale = 0.5 * (W * fabs(ux) + H * fabs(uy))};
    double cx[4] = {0, W, 0, W}, cy[4] = {0, 0, H, H}, lo = INFINITY, hi = -INFINITY;
    for (int k = 0; k < 4; k++) {
      double v = lw_potential_eval(&r, cx[k], cy[k]);
      lo = fmin(lo, v);
      hi = fmax(hi, v);
    }
    cr_assert(fabs(lo) < 1e-12 && fabs(hi - 1) < 1e-12, "angle %g: [%.17g, %.17g]", a, lo, hi);
    /* everything on the page in between */
    for (int k = 0; k < 100; k++) {
      double v = lw_potential_eval(&r, urand(0, W), urand(0, H));
      cr_assert(v >= -1e-12 && v <= 1 + 1e-12);
    }
  }
}

Test(field, potential_grid_and_clear)
{
  rng_seed(0x5eed0009);
  bilin f = bilin_rand();
  lw_potential p = {.kind = LW_POTENTIAL_GRID, .grid = grid_of(5, 6, 1, &f)};
  for (int k = 0; k < 100; k++) {
    double x = urand(p.grid->x0, p.grid->x0 + 4 * p.grid->hx);
    double y = urand(p.grid->y0, p.grid->y0 + 5 * p.grid->hy);
    cr_assert(lw_close_rel(lw_potential_eval(&p, x, y), bilin_at(&f, x, y), 1e-11, 100.0));
  }
  lw_potential_clear(&p);
  cr_assert_null(p.grid);
  lw_potential_clear(&p); /* twice is harmless */
  /* a grid kind without a grid reads 0 rather than crashing */
  cr_assert(lw_potential_eval(&p, 1, 2) == 0.0);
  lw_field fl = {.kind = LW_FIELD_GRID};
  double vx = 1, vy = 1;
  lw_field_eval(&fl, 1, 2, &vx, &vy);
  cr_assert(vx == 0.0 && vy == 0.0);
  lw_field_clear(&fl);
  cr_assert_null(fl.grid);
}

Test(field, constant_radial_vortex_match_formulas)
{
  rng_seed(0x5eed000a);
  for (int trial = 0; trial < 20; trial++) {
    double a = urand(-M_PI, M_PI), cx = urand(0, 200), cy = urand(0, 300);
    lw_field c = {.kind = LW_FIELD_CONSTANT, .ux = cos(a), .uy = sin(a)};
    lw_field rad = {.kind = LW_FIELD_RADIAL, .cx = cx, .cy = cy};
    lw_field vor = {.kind = LW_FIELD_VORTEX, .cx = cx, .cy = cy};
    for (int k = 0; k < 200; k++) {
      double x = urand(-50, 250), y = urand(-50, 350), vx, vy, wx, wy;
      lw_field_eval(&c, x, y, &vx, &vy);
      cr_assert(vx == c.ux && vy == c.uy);

      double r = hypot(x - cx, y - cy);
      lw_field_eval(&rad, x, y, &vx, &vy);
      cr_assert(lw_close_rel(vx, (x - cx) / r, 1e-13, 1.0));
      cr_assert(lw_close_rel(vy, (y - cy) / r, 1e-13, 1.0));
      lw_field_eval(&vor, x, y, &wx, &wy);
      cr_assert(lw_close_rel(wx, -(y - cy) / r, 1e-13, 1.0));
      cr_assert(lw_close_rel(wy, (x - cx) / r, 1e-13, 1.0));
      /* unit length, perpendicular, and the vortex a quarter turn from radial
      ** (radial x vortex = +1) */
      cr_assert(fabs(hypot(vx, vy) - 1) < 1e-14);
      cr_assert(fabs(hypot(wx, wy) - 1) < 1e-14);
      cr_assert(fabs(vx * wx + vy * wy) < 1e-14);
      cr_assert(fabs(vx * wy - vy * wx - 1) < 1e-14);
    }
    double vx = 1, vy = 1;
    lw_field_eval(&rad, cx, cy, &vx, &vy);
    cr_assert(vx == 0.0 && vy == 0.0, "radial is 0 at the centre");
    vx = vy = 1;
    lw_field_eval(&vor, cx, cy, &vx, &vy);
    cr_assert(vx == 0.0 && vy == 0.0, "vortex is 0 at the centre");
  }
}

/* Within the core a of a radial or vortex field its length is
** g(u) = 6u^5 - 15u^4 + 10u^3 of u = r / a, its direction the unit field's;
** from a out it is the unit field.  g and g' meet 1 and 0 at a, so the
** field and its Jacobian are continuous there; the Jacobian is that of
** exactly this field (central differences, inside and outside the core). */
Test(field, a_core_takes_the_field_smoothly_to_zero_at_its_centre)
{
  rng_seed(0x5eed000b);
  const double a = 7.0;
  for (int kind = 0; kind < 2; kind++) {
    const lw_field f = {.kind = kind ? LW_FIELD_VORTEX : LW_FIELD_RADIAL, .cx = 30, .cy = 40, .core = a};
    const lw_field unit = {.kind = f.kind, .cx = 30, .cy = 40};
    for (int k = 0; k < 400; k++) {
      const double r = urand(0.01, 2.0 * a), t = urand(-M_PI, M_PI), x = 30 + r * cos(t), y = 40 + r * sin(t);
      double vx, vy, ux, uy;
      lw_field_eval(&f, x, y, &vx, &vy);
      lw_field_eval(&unit, x, y, &ux, &uy);
      const double u = fmin(r / a, 1.0), g = u * u * u * (10 - 15 * u + 6 * u * u);
      cr_assert(fabs(vx - g * ux) < 1e-14 && fabs(vy - g * uy) < 1e-14, "r %g: (%g, %g), want %g (%g, %g)", r, vx,
                vy, g, ux, uy);
      double v[2], J[2][2];
      lw_field_jacobian(&f, x, y, v, J);
      const double h = 1e-6;
      for (int j = 0; j < 2; j++) {
        double p[2], m[2];
        lw_field_eval(&f, x + (j == 0) * h, y + (j == 1) * h, &p[0], &p[1]);
        lw_field_eval(&f, x - (j == 0) * h, y - (j == 1) * h, &m[0], &m[1]);
        for (int i = 0; i < 2; i++)
          cr_assert(fabs(J[i][j] - (p[i] - m[i]) / (2 * h)) < 1e-6 * (1 + 1 / r), "kind %d r %g: J[%d][%d] %.10g, "
                    "differences %.10g", kind, r, i, j, J[i][j], (p[i] - m[i]) / (2 * h));
      }
    }
    /* across r = a: no step in the field nor in its Jacobian */
    double in[2], out[2], Jin[2][2], Jout[2][2];
    lw_field_jacobian(&f, 30 + a * (1 - 1e-9), 40, in, Jin);
    lw_field_jacobian(&f, 30 + a * (1 + 1e-9), 40, out, Jout);
    for (int i = 0; i < 2; i++) {
      cr_assert(fabs(in[i] - out[i]) < 1e-12);
      for (int j = 0; j < 2; j++) cr_assert(fabs(Jin[i][j] - Jout[i][j]) < 1e-8, "J[%d][%d] steps at the core", i, j);
    }
  }
}

Test(field, waves_are_tangent_to_sine_curves)
{
  rng_seed(0x5eed000b);
  for (int trial = 0; trial < 20; trial++) {
    double lambda = urand(5, 80), A = urand(-20, 20), k = 2 * M_PI / lambda;
    lw_field f = {.kind = LW_FIELD_WAVES, .wavelength = lambda, .amplitude = A};
    for (int m = 0; m < 100; m++) {
      double x = urand(-100, 300), y = urand(-100, 300), vx, vy;
      lw_field_eval(&f, x, y, &vx, &vy);
      /* central difference of y = A sin(kx) + const */
      const double h = 1e-5;
      double dydx = (A * sin(k * (x + h)) - A * sin(k * (x - h))) / (2 * h);
      double tn = hypot(1.0, dydx);
      cr_assert(fabs(hypot(vx, vy) - 1) < 1e-14, "unit");
      cr_assert(vx > 0, "points to +x");
      cr_assert(fabs(vx * dydx - vy * 1.0) / tn < 1e-8, "parallel: lambda %g A %g x %g", lambda,
                A, x);
      /* and it does not depend on y */
      double ux, uy;
      lw_field_eval(&f, x, urand(-100, 300), &ux, &uy);
      cr_assert(ux == vx && uy == vy);
    }
  }
}
