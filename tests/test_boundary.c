/* test_boundary.c -- signed distance to rectangle, circle and polygon frames. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "linewise/boundary.h"
#include "testutil.h"



/* ---- brute force reference -------------------------------------------- */

/* Points densely sampled on a boundary curve, no two consecutive ones more
** than `spacing` apart along it.  The distance to the nearest sample is then
** an upper bound of the true distance d and at most d + spacing/2 (the nearest
** curve point lies within spacing/2 of a sample, along a chord), so the test
** knows exactly how much slack it needs. */
typedef struct {
  size_t n;
  double *x, *y;
  double spacing;
} samples;

static void samples_free(samples *s)
{
  free(s->x);
  free(s->y);
}

/* Samples the closed polyline through (px, py) with m points per edge. */
static samples sample_polyline(size_t n, const double *px, const double *py, size_t m)
{
  samples s = {n * m, malloc(n * m * sizeof(double)), malloc(n * m * sizeof(double)), 0};
  cr_assert(s.x && s.y);
  for (size_t i = 0; i < n; i++) {
    size_t j = (i + 1) % n;
    double len = hypot(px[j] - px[i], py[j] - py[i]);
    if (len / m > s.spacing) s.spacing = len / m;
    for (size_t k = 0; k < m; k++) {
      double t = (double)k / m;
      s.x[i * m + k] = px[i] + t * (px[j] - px[i]);
      s.y[i * m + k] = py[i] + t * (py[j] - py[i]);
    }
  }
  return s;
}

static samples sample_circle(double cx, double cy, double r, size_t m)
{
  samples s = {m, malloc(m * sizeof(double)), malloc(m * sizeof(double)), 2 * M_PI * r / m};
  cr_assert(s.x && s.y);
  for (size_t k = 0; k < m; k++) {
    s.x[k] = cx + r * cos(2 * M_PI * k / m);
    s.y[k] = cy + r * sin(2 * M_PI * k / m);
  }
  return s;
}

static double nearest_sample(const samples *s, double x, double y)
{
  double best = INFINITY;
  for (size_t k = 0; k < s->n; k++) {
    double dx = x - s->x[k], dy = y - s->y[k], d2 = dx * dx + dy * dy;
    if (d2 < best) best = d2;
  }
  return sqrt(best);
}

/* Inside test independent of the library's crossing count: the winding number
** from summed angles (equal to even-odd for a simple polygon, either way
** round). */
static int winding_inside(size_t n, const double *px, const double *py, double x, double y)
{
  double sum = 0;
  for (size_t i = 0; i < n; i++) {
    size_t j = (i + 1) % n;
    double ax = px[i] - x, ay = py[i] - y, bx = px[j] - x, by = py[j] - y;
    sum += atan2(ax * by - ay * bx, ax * bx + ay * by);
  }
  return fabs(sum) > M_PI;
}

typedef int (*inside_fn)(const void *shape, double x, double y);

/* Checks d(x, y) at `count` random points of the box [x0,x1] x [y0,y1]
** against the samples (magnitude) and `inside` (sign). */
static void check_against_brute(const lw_boundary *b, const samples *s, inside_fn inside,
                                const void *shape, double x0, double y0, double x1, double y1,
                                int count, const char *what)
{
  int n_in = 0, n_out = 0;
  for (int k = 0; k < count; k++) {
    double x = urand(x0, x1), y = urand(y0, y1);
    double d = lw_boundary_distance(b, x, y), ref = nearest_sample(s, x, y);
    cr_assert(!isnan(d), "%s: NaN at (%g, %g)", what, x, y);
    cr_assert(fabs(d) <= ref + 1e-9 && fabs(d) >= ref - s->spacing / 2 - 1e-9,
              "%s: |d| = %.12g, sampled %.12g (spacing %g) at (%.12g, %.12g)", what, fabs(d), ref,
              s->spacing, x, y);
    if (fabs(d) > 1e-9) {
      int in = inside(shape, x, y);
      cr_assert_eq(d < 0, in, "%s: sign of %.12g at (%.12g, %.12g), inside %d", what, d, x, y, in);
      cr_assert_eq(lw_boundary_inside(b, x, y), in);
      n_in += in;
      n_out += !in;
    }
  }
  /* the box must actually exercise both sides */
  cr_assert(n_in > count / 20 && n_out > count / 20, "%s: %d inside, %d outside", what, n_in,
            n_out);
}

typedef struct { double x0, y0, x1, y1; } rect;
static int rect_in(const void *p, double x, double y)
{
  const rect *r = p;
  return x > r->x0 && x < r->x1 && y > r->y0 && y < r->y1;
}
typedef struct { double cx, cy, r; } circ;
static int circ_in(const void *p, double x, double y)
{
  const circ *c = p;
  return (x - c->cx) * (x - c->cx) + (y - c->cy) * (y - c->cy) < c->r * c->r;
}
typedef struct { size_t n; const double *x, *y; } poly;
static int poly_in(const void *p, double x, double y)
{
  const poly *q = p;
  return winding_inside(q->n, q->x, q->y, x, y);
}

/* ---- tests --------------------------------------------------------------- */

Test(boundary, rect_matches_brute_force_including_corners)
{
  rng_seed(0xb0de0001);
  for (int trial = 0; trial < 5; trial++) {
    rect r = {urand(-50, 50), urand(-50, 50), 0, 0};
    r.x1 = r.x0 + urand(20, 200);
    r.y1 = r.y0 + urand(20, 200);
    lw_boundary b = {.kind = LW_BOUNDARY_RECT, .x0 = r.x0, .y0 = r.y0, .x1 = r.x1, .y1 = r.y1};
    double px[4] = {r.x0, r.x1, r.x1, r.x0}, py[4] = {r.y0, r.y0, r.y1, r.y1};
    samples s = sample_polyline(4, px, py, 4000);
    double w = r.x1 - r.x0, h = r.y1 - r.y0;
    check_against_brute(&b, &s, rect_in, &r, r.x0 - w, r.y0 - h, r.x1 + w, r.y1 + h, 1500,
                        "rect");
    samples_free(&s);

    /* outside a corner the nearest point is the corner itself */
    for (int k = 0; k < 50; k++) {
      double dx = urand(1e-3, 50), dy = urand(1e-3, 50);
      cr_assert(lw_close_rel(lw_boundary_distance(&b, r.x1 + dx, r.y0 - dy), hypot(dx, dy),
                             1e-12, 1.0));
      cr_assert(lw_close_rel(lw_boundary_distance(&b, r.x0 - dx, r.y1 + dy), hypot(dx, dy),
                             1e-12, 1.0));
    }
    /* inside: the nearest side */
    double x = urand(r.x0, r.x1), y = urand(r.y0, r.y1);
    double want = -fmin(fmin(x - r.x0, r.x1 - x), fmin(y - r.y0, r.y1 - y));
    cr_assert(lw_close_rel(lw_boundary_distance(&b, x, y), want, 1e-12, 1.0));
    /* on the boundary: 0, and not inside */
    cr_assert(lw_boundary_distance(&b, r.x0, y) == 0.0);
    cr_assert(lw_boundary_distance(&b, r.x1, r.y1) == 0.0);
    cr_assert(!lw_boundary_inside(&b, x, r.y1));
  }
}

Test(boundary, circle_matches_brute_force)
{
  rng_seed(0xb0de0002);
  for (int trial = 0; trial < 5; trial++) {
    circ c = {urand(-50, 50), urand(-50, 50), urand(5, 100)};
    lw_boundary b = {.kind = LW_BOUNDARY_CIRCLE, .cx = c.cx, .cy = c.cy, .radius = c.r};
    samples s = sample_circle(c.cx, c.cy, c.r, 20000);
    check_against_brute(&b, &s, circ_in, &c, c.cx - 2 * c.r, c.cy - 2 * c.r, c.cx + 2 * c.r,
                        c.cy + 2 * c.r, 1500, "circle");
    samples_free(&s);
    cr_assert(lw_close_rel(lw_boundary_distance(&b, c.cx, c.cy), -c.r, 1e-15, 1.0));
    double a = urand(0, 2 * M_PI), t = urand(0, 3 * c.r);
    cr_assert(lw_close_rel(lw_boundary_distance(&b, c.cx + t * cos(a), c.cy + t * sin(a)),
                           t - c.r, 1e-12, c.r));
  }
}

Test(boundary, square_polygon_agrees_with_rect_either_orientation)
{
  rng_seed(0xb0de0003);
  double x0 = urand(-20, 20), y0 = urand(-20, 20), x1 = x0 + urand(10, 100),
         y1 = y0 + urand(10, 100);
  lw_boundary r = {.kind = LW_BOUNDARY_RECT, .x0 = x0, .y0 = y0, .x1 = x1, .y1 = y1};
  /* counter-clockwise and clockwise on a y-up page, starting at different corners */
  double ccw_x[4] = {x0, x1, x1, x0}, ccw_y[4] = {y0, y0, y1, y1};
  double cw_x[4] = {x1, x1, x0, x0}, cw_y[4] = {y0, y1, y1, y0};
  lw_boundary p, q;
  lw_error err;
  cr_assert_eq(lw_boundary_polygon(&p, 4, ccw_x, ccw_y, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(lw_boundary_polygon(&q, 4, cw_x, cw_y, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(p.kind, LW_BOUNDARY_POLYGON);
  cr_assert_eq(p.n, 4);
  cr_assert(p.vx != ccw_x, "vertices are copied");
  double w = x1 - x0, h = y1 - y0;
  for (int k = 0; k < 3000; k++) {
    double x = urand(x0 - w, x1 + w), y = urand(y0 - h, y1 + h);
    double dr = lw_boundary_distance(&r, x, y);
    cr_assert(lw_close_rel(lw_boundary_distance(&p, x, y), dr, 1e-12, 1.0), "ccw at (%g, %g)",
              x, y);
    cr_assert(lw_close_rel(lw_boundary_distance(&q, x, y), dr, 1e-12, 1.0), "cw at (%g, %g)",
              x, y);
  }
  lw_boundary_clear(&p);
  lw_boundary_clear(&q);
  cr_assert(p.vx == NULL && p.vy == NULL && p.n == 0);
}

Test(boundary, concave_l_shape)
{
  /* L: the unit square [1,2] x [1,2] cut out of [0,2]^2 */
  double lx[6] = {0, 2, 2, 1, 1, 0}, ly[6] = {0, 0, 1, 1, 2, 2};
  lw_boundary b;
  cr_assert_eq(lw_boundary_polygon(&b, 6, lx, ly, NULL), LW_OK);
  struct { double x, y, d; } known[] = {
    {0.5, 0.5, -0.5},             /* inside, the corner block */
    {1.5, 0.5, -0.5},             /* inside, one arm */
    {0.5, 1.5, -0.5},             /* inside, the other arm */
    {1.5, 1.5, 0.5},              /* in the notch: outside, midway between its edges */
    {1.2, 1.7, 0.2},              /* in the notch, nearer the vertical notch edge */
    {0.9, 0.9, -0.1 * 1.4142135623730951},   /* inside, nearest the reflex corner (1, 1) */
    {3, 3, 2.2360679774997898},   /* nearest the convex corners (2, 1) and (1, 2): sqrt 5 */
    {-1, -1, 1.4142135623730951},            /* beyond the corner (0, 0) */
    {1, 1, 0},                    /* the reflex vertex itself */
  };
  for (size_t k = 0; k < sizeof known / sizeof known[0]; k++) {
    double d = lw_boundary_distance(&b, known[k].x, known[k].y);
    cr_assert(fabs(d - known[k].d) < 1e-14, "(%g, %g): %.17g, want %.17g", known[k].x,
              known[k].y, d, known[k].d);
  }
  rng_seed(0xb0de0004);
  poly shape = {6, lx, ly};
  samples s = sample_polyline(6, lx, ly, 2000);
  check_against_brute(&b, &s, poly_in, &shape, -1, -1, 3, 3, 2000, "L");
  samples_free(&s);

  /* the same L clockwise */
  double rx[6], ry[6];
  for (int k = 0; k < 6; k++) {
    rx[k] = lx[5 - k];
    ry[k] = ly[5 - k];
  }
  lw_boundary c;
  cr_assert_eq(lw_boundary_polygon(&c, 6, rx, ry, NULL), LW_OK);
  for (int k = 0; k < 2000; k++) {
    double x = urand(-1, 3), y = urand(-1, 3);
    cr_assert(lw_boundary_distance(&b, x, y) == lw_boundary_distance(&c, x, y) ||
              lw_close_rel(lw_boundary_distance(&b, x, y), lw_boundary_distance(&c, x, y), 1e-14,
                           1.0));
  }
  lw_boundary_clear(&b);
  lw_boundary_clear(&c);
}

Test(boundary, random_star_polygons_match_brute_force)
{
  /* Star-shaped polygons (vertices at increasing angles, random radii) are
  ** simple and strongly concave; checked both ways round. */
  rng_seed(0xb0de0005);
  for (int trial = 0; trial < 6; trial++) {
    size_t n = 5 + (size_t)urand(0, 20);
    double *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y);
    double *rx = malloc(n * sizeof *rx), *ry = malloc(n * sizeof *ry);
    cr_assert(x && y && rx && ry);
    double cx = urand(-30, 30), cy = urand(-30, 30);
    for (size_t k = 0; k < n; k++) {
      double a = 2 * M_PI * (k + urand(0.1, 0.9)) / n, r = urand(10, 60);
      x[k] = cx + r * cos(a);
      y[k] = cy + r * sin(a);
      rx[n - 1 - k] = x[k];
      ry[n - 1 - k] = y[k];
    }
    lw_boundary b, c;
    lw_error err;
    cr_assert_eq(lw_boundary_polygon(&b, n, x, y, &err), LW_OK, "%s", err.msg);
    cr_assert_eq(lw_boundary_polygon(&c, n, rx, ry, &err), LW_OK, "%s", err.msg);
    poly shape = {n, x, y};
    samples s = sample_polyline(n, x, y, 1000);
    check_against_brute(&b, &s, poly_in, &shape, cx - 70, cy - 70, cx + 70, cy + 70, 1000,
                        "star");
    check_against_brute(&c, &s, poly_in, &shape, cx - 70, cy - 70, cx + 70, cy + 70, 1000,
                        "star reversed");
    samples_free(&s);
    for (size_t k = 0; k < n; k++)
      cr_assert(lw_boundary_distance(&b, x[k], y[k]) == 0.0, "vertex %zu on the boundary", k);
    lw_boundary_clear(&b);
    lw_boundary_clear(&c);
    free(x);
    free(y);
    free(rx);
    free(ry);
  }
}

Test(boundary, invalid_polygons_rejected)
{
  double x3[3] = {0, 1, 0}, y3[3] = {0, 0, 1};
  double colx[4] = {0, 1, 2, 3}, coly[4] = {0, 0.5, 1, 1.5};     /* collinear */
  double samex[3] = {2, 2, 2}, samey[3] = {5, 5, 5};             /* one point */
  double nanx[3] = {0, NAN, 0}, infy[3] = {0, 0, INFINITY};
  /* on y = 3x, but the shoelace sum leaves a rounding residue of ~1e-17 */
  double rndx[4] = {0.1, 0.7, 0.3, 1.3}, rndy[4] = {0.3, 2.1, 0.9, 3.9};
  double backx[4] = {0, 1, 1, 0}, backy[4] = {0, 0, 0, 0};       /* there and back */
  struct { size_t n; const double *x, *y; } bad[] = {
    {0, x3, y3}, {2, x3, y3}, {4, colx, coly}, {3, samex, samey},
    {3, nanx, y3}, {3, x3, infy}, {4, backx, backy}, {3, NULL, y3}, {4, rndx, rndy},
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    lw_boundary b = {.kind = LW_BOUNDARY_RECT, .x1 = 7, .y1 = 7};
    lw_error err;
    lw_error_clear(&err);
    cr_assert_eq(lw_boundary_polygon(&b, bad[k].n, bad[k].x, bad[k].y, &err), LW_EINPUT,
                 "case %zu", k);
    cr_assert_eq(err.code, LW_EINPUT);
    cr_assert(err.msg[0] != '\0', "case %zu has a message", k);
    cr_assert(b.kind == LW_BOUNDARY_RECT && b.x1 == 7 && b.vx == NULL, "case %zu: b untouched",
              k);
  }
  /* a polygon a scene gives must not cross itself (a bowtie was "zero
  ** area", a pentagram taken by the even-odd rule, its centre outside); a
  ** vertex on another edge counts; a repeated vertex, or the first repeated
  ** last to close the path, is no edge and crosses nothing */
  double bowx[4] = {20, 128, 128, 20}, bowy[4] = {20, 90, 20, 90};
  double starx[5] = {74, 100, 32, 116, 48}, stary[5] = {12, 90, 42, 42, 90};
  double touchx[6] = {10, 90, 50, 90, 10, 50}, touchy[6] = {10, 10, 50, 90, 90, 50};
  double closedx[5] = {10, 90, 90, 10, 10}, closedy[5] = {10, 10, 90, 90, 10};
  double twicex[5] = {10, 90, 90, 90, 10}, twicey[5] = {10, 10, 10, 90, 90};
  struct { size_t n; const double *x, *y; int crosses; size_t a, b; } shapes[] = {
    {4, bowx, bowy, 1, 0, 2}, {5, starx, stary, 1, 0, 2}, {6, touchx, touchy, 1, 1, 4},
    {5, closedx, closedy, 0, 0, 0}, {5, twicex, twicey, 0, 0, 0}, {3, x3, y3, 0, 0, 0},
  };
  for (size_t k = 0; k < sizeof shapes / sizeof shapes[0]; k++) {
    size_t a = 99, b = 99;
    cr_assert_eq(lw_boundary_crossing(shapes[k].n, shapes[k].x, shapes[k].y, &a, &b), shapes[k].crosses, "case %zu",
                 k);
    cr_assert(!shapes[k].crosses || (a == shapes[k].a && b == shapes[k].b), "case %zu: edges from %zu and %zu", k,
              a, b);
  }
  /* a polygon too large for its area in doubles is named so, not "zero area" */
  double hugex[3] = {0, 1e200, 0}, hugey[3] = {0, 0, 1e200};
  lw_boundary h;
  lw_error e;
  cr_assert_eq(lw_boundary_polygon(&h, 3, hugex, hugey, &e), LW_EINPUT);
  cr_assert(strstr(e.msg, "its area overflows"), "%s", e.msg);
  /* the valid triangle, and NULL err */
  lw_boundary b;
  cr_assert_eq(lw_boundary_polygon(&b, 3, x3, y3, NULL), LW_OK);
  cr_assert(fabs(lw_boundary_distance(&b, 0.25, 0.25) + 0.25) < 1e-15);
  cr_assert(fabs(lw_boundary_distance(&b, 1, 1) - 0.70710678118654752) < 1e-15);
  lw_boundary_clear(&b);
  cr_assert_eq(lw_boundary_polygon(&b, 2, x3, y3, NULL), LW_EINPUT);
}

Test(boundary, none_is_minus_infinity)
{
  lw_boundary b = {.kind = LW_BOUNDARY_NONE};
  rng_seed(0xb0de0006);
  for (int k = 0; k < 100; k++) {
    double d = lw_boundary_distance(&b, urand(-1e6, 1e6), urand(-1e6, 1e6));
    cr_assert(isinf(d) && d < 0);
  }
  cr_assert(isinf(lw_boundary_distance(&b, NAN, 0)) && lw_boundary_distance(&b, NAN, 0) < 0);
  cr_assert(lw_boundary_inside(&b, 1e300, -1e300));
}

Test(boundary, non_finite_points_are_outside_not_nan)
{
  double px[5] = {0, 4, 4, 2, 0}, py[5] = {0, 0, 3, 1, 3};
  lw_boundary poly_b;
  cr_assert_eq(lw_boundary_polygon(&poly_b, 5, px, py, NULL), LW_OK);
  lw_boundary shapes[3] = {
    {.kind = LW_BOUNDARY_RECT, .x0 = 0, .y0 = 0, .x1 = 10, .y1 = 5},
    {.kind = LW_BOUNDARY_CIRCLE, .cx = 1, .cy = 2, .radius = 3},
    poly_b,
  };
  double pts[][2] = {{NAN, 1}, {1, NAN}, {NAN, NAN}, {INFINITY, 1}, {1, -INFINITY},
                     {-INFINITY, INFINITY}};
  for (int s = 0; s < 3; s++)
    for (size_t k = 0; k < sizeof pts / sizeof pts[0]; k++) {
      double d = lw_boundary_distance(&shapes[s], pts[k][0], pts[k][1]);
      cr_assert(isinf(d) && d > 0, "shape %d point %zu gives %g", s, k, d);
      cr_assert(!lw_boundary_inside(&shapes[s], pts[k][0], pts[k][1]));
    }
  lw_boundary_clear(&poly_b);
  /* a cleared polygon has no inside */
  cr_assert(isinf(lw_boundary_distance(&poly_b, 1, 0.5)));
  lw_boundary_clear(&poly_b);
}

/* ---- a whole curve against the frame ---------------------------------- */

/* The least of -d over the cubic with control points (x, y), sampled at
** 20001 parameters: the curve's clearance up to the sampling (a point
** between samples is within 1/20000 of the control polygon's length of one,
** and d moves by at most that times the slope). */
static double sampled_clearance(const lw_boundary *b, const double x[4], const double y[4], double *slack)
{
  double least = INFINITY, polygon_length = 0.0;
  for (int k = 0; k < 3; k++) polygon_length += hypot(x[k + 1] - x[k], y[k + 1] - y[k]);
  for (int i = 0; i <= 20000; i++) {
    const double t = i / 20000.0, u = 1.0 - t;
    const double b0 = u * u * u, b1 = 3 * u * u * t, b2 = 3 * u * t * t, b3 = t * t * t;
    const double d = lw_boundary_distance(b, b0 * x[0] + b1 * x[1] + b2 * x[2] + b3 * x[3],
                                          b0 * y[0] + b1 * y[1] + b2 * y[2] + b3 * y[3]);
    least = fmin(least, -d);
  }
  *slack = (b->kind == LW_BOUNDARY_MASK ? b->slope : 1.0) * polygon_length / 20000.0 + 1e-9;
  return least;
}

/* Random cubics about the frame of b (its box [x0, x1] x [y0, y1]), each
** asked with a random clearance: lw_boundary_curve_clear agrees with dense
** sampling wherever the sampled margin decides, and both answers occur. */
static void check_curves(const lw_boundary *b, double x0, double y0, double x1, double y1, const char *what)
{
  int yes = 0, no = 0;
  const double size = fmax(x1 - x0, y1 - y0);
  for (int k = 0; k < 3000; k++) {
    double x[4], y[4];
    x[0] = urand(x0, x1);
    y[0] = urand(y0, y1);
    const double len = urand(0.02, 0.4) * size, turn = urand(0, 2 * M_PI);
    for (int j = 1; j < 4; j++) {
      x[j] = x[0] + len * (j / 3.0) * cos(turn) + urand(-0.3, 0.3) * len;
      y[j] = y[0] + len * (j / 3.0) * sin(turn) + urand(-0.3, 0.3) * len;
    }
    const double clear = k % 3 == 0 ? 0.0 : urand(0, 0.1) * size;
    double slack, margin = sampled_clearance(b, x, y, &slack);
    const int got = lw_boundary_curve_clear(b, x, y, clear);
    if (margin - clear > slack) {
      cr_assert(got, "%s: curve %d clears %.9g by the samples, asked %.9g, refused", what, k, margin, clear);
      yes++;
    } else if (margin < clear) {
      cr_assert(!got, "%s: curve %d comes to %.9g of the frame by the samples, asked %.9g, allowed", what, k,
                margin, clear);
      no++;
    }
  }
  cr_assert(yes > 300 && no > 300, "%s: %d clear, %d not", what, yes, no);
}

Test(boundary, a_whole_curve_is_checked_against_the_frame_of_every_kind)
{
  rng_seed(0xb0de0010);
  lw_boundary r = {.kind = LW_BOUNDARY_RECT, .x0 = 1, .y0 = 2, .x1 = 11, .y1 = 8};
  check_curves(&r, 0, 1, 12, 9, "rect");
  lw_boundary c = {.kind = LW_BOUNDARY_CIRCLE, .cx = 5, .cy = 5, .radius = 4};
  check_curves(&c, 0, 0, 10, 10, "circle");
  double lx[6] = {0, 10, 10, 4, 4, 0}, ly[6] = {0, 0, 3, 3, 10, 10};
  lw_boundary l;
  cr_assert_eq(lw_boundary_polygon(&l, 6, lx, ly, NULL), LW_OK);
  check_curves(&l, -1, -1, 11, 11, "L-shaped polygon");
  lw_boundary_clear(&l);
  /* a mask: the disc's signed distance on a coarse grid, bilinear between
  ** its nodes (its slope is 1 by construction, a little more between) */
  lw_error err;
  lw_grid2d *g = lw_grid2d_new(41, 41, 1, 0.0, 0.0, 0.25, 0.25, &err);
  cr_assert(g);
  for (int j = 0; j < 41; j++)
    for (int i = 0; i < 41; i++) g->data[j * 41 + i] = hypot(i * 0.25 - 5, j * 0.25 - 5) - 4;
  lw_boundary m = {.kind = LW_BOUNDARY_MASK, .sdt = g, .slope = lw_boundary_mask_slope(g)};
  cr_assert(m.slope >= 1.0 && m.slope < 1.5, "slope %g", m.slope);
  check_curves(&m, 0, 0, 10, 10, "mask");
  lw_boundary_clear(&m);
}

Test(boundary, a_curve_with_a_coordinate_not_finite_is_never_clear)
{
  lw_boundary r = {.kind = LW_BOUNDARY_RECT, .x0 = 0, .y0 = 0, .x1 = 10, .y1 = 10};
  double x[4] = {2, 3, 4, 5}, y[4] = {5, 5, 5, 5};
  cr_assert(lw_boundary_curve_clear(&r, x, y, 1.0));
  for (int k = 0; k < 4; k++) {
    double xs[4] = {2, 3, 4, 5};
    xs[k] = NAN;
    cr_assert(!lw_boundary_curve_clear(&r, xs, y, 1.0), "NaN at control point %d", k);
    xs[k] = INFINITY;
    cr_assert(!lw_boundary_curve_clear(&r, xs, y, 0.0), "inf at control point %d", k);
  }
  lw_boundary none = {.kind = LW_BOUNDARY_NONE};
  cr_assert(lw_boundary_curve_clear(&none, x, y, 1e9));
}

Test(boundary, a_curve_along_the_limit_is_decided_in_bounded_work, .timeout = 20)
{
  /* A straight segment parallel to a side, a hair beyond the clearance: the
  ** disc test alone split it down to pieces of that hair (143 s for one
  ** segment 1e-8 mm beyond).  On a convex frame the control points decide
  ** it exactly, on a polygon that is not the chord's distance to the edges;
  ** on a mask the work is capped and the curve refused. */
  lw_boundary r = {.kind = LW_BOUNDARY_RECT, .x0 = 0, .y0 = 0, .x1 = 100, .y1 = 100};
  const double clear = 1.125;
  for (int k = 0; k < 4; k++) {
    const double hair = k == 3 ? -1e-12 : pow(10.0, -8 - k);
    const double y[4] = {clear + hair, clear + hair, clear + hair, clear + hair}, x[4] = {10, 12, 14, 16};
    cr_assert_eq(lw_boundary_curve_clear(&r, x, y, clear), hair > 0, "hair %g", hair);
  }
  double lx[6] = {0, 100, 100, 40, 40, 0}, ly[6] = {0, 0, 30, 30, 100, 100};
  lw_boundary l;
  cr_assert_eq(lw_boundary_polygon(&l, 6, lx, ly, NULL), LW_OK);
  cr_assert(!l.convex);
  const double x[4] = {50, 55, 60, 65}, y[4] = {clear + 1e-8, clear + 1e-8, clear + 1e-8, clear + 1e-8};
  cr_assert(lw_boundary_curve_clear(&l, x, y, clear), "a hair beyond, beside a concave polygon's edge");
  const double y2[4] = {clear - 1e-8, clear - 1e-8, clear - 1e-8, clear - 1e-8};
  cr_assert(!lw_boundary_curve_clear(&l, x, y2, clear), "a hair within");
  /* and beside the concave corner's other side (x = 40, inside below),
  ** bent away from it, its ends a hair beyond the limit */
  const double bx[4] = {40 - clear - 1e-6, 40 - clear - 1, 40 - clear - 1, 40 - clear - 1e-6},
               by[4] = {60, 65, 70, 75};
  cr_assert(lw_boundary_curve_clear(&l, bx, by, clear));
  /* a mask's discs split a curve along the limit until the cap refuses it */
  lw_error err;
  lw_grid2d *g = lw_grid2d_new(101, 101, 1, 0.0, 0.0, 1.0, 1.0, &err);
  cr_assert(g);
  for (int j = 0; j < 101; j++)
    for (int i = 0; i < 101; i++) g->data[j * 101 + i] = -fmin(fmin(i, 100 - i), fmin(j, 100 - j));
  lw_boundary m = {.kind = LW_BOUNDARY_MASK, .sdt = g, .slope = lw_boundary_mask_slope(g)};
  const double my[4] = {clear + 1e-9, clear + 1e-9, clear + 1e-9, clear + 1e-9};
  cr_assert(!lw_boundary_curve_clear(&m, x, my, clear), "refused: more pieces than the cap");
  const double my2[4] = {clear + 0.01, clear + 0.01, clear + 0.01, clear + 0.01};
  cr_assert(lw_boundary_curve_clear(&m, x, my2, clear), "0.01 mm beyond is clear within the cap");
  lw_boundary_clear(&m);
  double sx[4] = {0, 10, 10, 0}, sy[4] = {0, 0, 10, 10};
  lw_boundary sq;
  cr_assert_eq(lw_boundary_polygon(&sq, 4, sx, sy, NULL), LW_OK);
  cr_assert(sq.convex);
  lw_boundary_clear(&l);
  lw_boundary_clear(&sq);
}
