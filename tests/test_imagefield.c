/*
** test_imagefield.c -- fields and boundaries made from pictures: the edge
** tangent flow, the gradient, the potential grid, axial grids, and the
** signed distance transform of masks.
*/
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/boundary.h"
#include "linewise/imagefield.h"
#include "linewise/sdt.h"
#include "testutil.h"

/* A picture with tone f(x, y) at pixel centres (x, y in pixels). */
static lw_image *picture(int w, int h, double (*f)(double, double))
{
  lw_image *img = lw_image_new(w, h, 0, NULL);
  cr_assert_not_null(img);
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) img->tone[j * w + i] = (float)f(i + 0.5, j + 0.5);
  return img;
}

static const double stripe_angle = 0.5236; /* the normal of the stripes, radians */
static double stripes(double x, double y)
{
  return 0.5 + 0.5 * sin(2 * M_PI * (x * cos(stripe_angle) + y * sin(stripe_angle)) / 11.0);
}

static double rings(double x, double y)
{
  return 0.5 + 0.5 * cos(2 * M_PI * hypot(x - 80.3, y - 70.6) / 9.0);
}

static double flat(double x, double y) { return 0.6; }
static double ramp(double x, double y) { return x / 200.0; }

/* Angle between two axial directions, radians in [0, pi/2]. */
static double axial_angle(double ax, double ay, double bx, double by)
{
  double c = fabs(ax * bx + ay * by) / (hypot(ax, ay) * hypot(bx, by));
  return acos(fmin(c, 1.0));
}

Test(imagefield, etf_runs_along_straight_stripes)
{
  lw_image *img = picture(160, 140, stripes);
  lw_image_place pl = {5, 7, 0.25}; /* 4 pixels per mm */
  lw_field f = {.kind = LW_FIELD_GRID_AXIAL};
  f.grid = lw_imagefield_etf(img, &pl, 1.0, 1e-3, 0.0, NULL, NULL);
  cr_assert_not_null(f.grid);
  /* along the stripes = perpendicular to their normal */
  double tx = -sin(stripe_angle), ty = cos(stripe_angle), worst = 0;
  rng_seed(21);
  for (int k = 0; k < 400; k++) {
    double x = pl.x0 + urand(8, 32), y = pl.y0 + urand(8, 27);
    double vx, vy;
    lw_field_eval(&f, x, y, &vx, &vy);
    cr_assert(fabs(hypot(vx, vy) - 1) < 0.02, "unit length: %g", hypot(vx, vy));
    worst = fmax(worst, axial_angle(vx, vy, tx, ty));
  }
  cr_assert(worst < 1.0 * M_PI / 180, "worst angle %g degrees", worst * 180 / M_PI);
  lw_field_clear(&f);
  lw_image_free(img);
}

Test(imagefield, etf_is_tangential_on_concentric_rings)
{
  lw_image *img = picture(160, 140, rings);
  lw_image_place pl = {0, 0, 1};
  lw_field f = {.kind = LW_FIELD_GRID_AXIAL};
  f.grid = lw_imagefield_etf(img, &pl, 2.0, 1e-3, 0.0, NULL, NULL);
  cr_assert_not_null(f.grid);
  double worst = 0, mean = 0;
  rng_seed(22);
  const int n = 400;
  for (int k = 0; k < n; k++) {
    double r = urand(20, 60), a = urand(0, 2 * M_PI);
    double x = 80.3 + r * cos(a), y = 70.6 + r * sin(a), vx, vy;
    lw_field_eval(&f, x, y, &vx, &vy);
    double e = axial_angle(vx, vy, -sin(a), cos(a));
    worst = fmax(worst, e);
    mean += e / n;
  }
  /* the rings curve within the smoothing window and the Sobel operator is
  ** only nearly isotropic (measured: worst 0.6, mean 0.4 degrees) */
  cr_assert(worst < 1.5 * M_PI / 180, "worst %g degrees", worst * 180 / M_PI);
  cr_assert(mean < 0.75 * M_PI / 180, "mean %g degrees", mean * 180 / M_PI);
  lw_field_clear(&f);
  lw_image_free(img);
}

Test(imagefield, etf_falls_back_to_field_angle_where_flat)
{
  lw_image *img = picture(40, 30, flat);
  lw_image_place pl = {0, 0, 0.5};
  lw_field f = {.kind = LW_FIELD_GRID_AXIAL};
  const double a = 1.1;
  f.grid = lw_imagefield_etf(img, &pl, 1.0, 0.01, a, NULL, NULL);
  double vx, vy;
  lw_field_eval(&f, 7.3, 9.1, &vx, &vy);
  cr_assert(fabs(vx - cos(a)) < 1e-9 && fabs(vy - sin(a)) < 1e-9, "(%g, %g)", vx, vy);
  lw_field_clear(&f);
  lw_image_free(img);
}

Test(imagefield, gradient_points_to_lighter_and_fades_where_flat)
{
  lw_image *img = picture(200, 20, ramp);
  lw_image_place pl = {0, 0, 0.5}; /* slope 1/200 per pixel = 0.01 tone per mm */
  lw_field f = {.kind = LW_FIELD_GRID};
  f.grid = lw_imagefield_gradient(img, &pl, 0.005, NULL, NULL);
  double vx, vy;
  lw_field_eval(&f, 50.2, 5.1, &vx, &vy);
  cr_assert(fabs(vx - 1) < 1e-4 && fabs(vy) < 1e-6, "(%g, %g)", vx, vy);
  lw_field_clear(&f);
  /* with the flatness threshold above the slope the length is slope / flat */
  f.grid = lw_imagefield_gradient(img, &pl, 0.04, NULL, NULL);
  lw_field_eval(&f, 50.2, 5.1, &vx, &vy);
  cr_assert(fabs(vx - 0.25) < 1e-4, "%g", vx);
  lw_field_clear(&f);
  lw_image_free(img);
}

Test(imagefield, potential_is_the_tone_and_white_beyond_the_picture)
{
  rng_seed(23);
  lw_image *img = lw_image_new(7, 5, 0, NULL);
  for (int k = 0; k < 35; k++) img->tone[k] = (float)urand(0, 1);
  lw_image_place pl = {3, 4, 2};
  lw_potential f = {.kind = LW_POTENTIAL_GRID};
  f.grid = lw_imagefield_potential(img, &pl, 1.0, 0.0, 1, 1, NULL);
  for (int j = 0; j < 5; j++)
    for (int i = 0; i < 7; i++)
      cr_assert(fabs(lw_potential_eval(&f, 3 + 2 * (i + 0.5), 4 + 2 * (j + 0.5)) - img->tone[j * 7 + i]) < 1e-7);
  cr_assert(lw_potential_eval(&f, 0, 0) == 1.0 && lw_potential_eval(&f, 100, 10) == 1.0);
  cr_assert(lw_potential_eval(&f, 3 + 14 + 1, 9) == 1.0, "a pixel beyond the right edge is white");
  lw_potential_clear(&f);
  /* scene.potential_power: Phi = tone^power, white still 1 */
  f.grid = lw_imagefield_potential(img, &pl, 3.0, 0.0, 1, 1, NULL);
  for (int j = 0; j < 5; j++)
    for (int i = 0; i < 7; i++)
      cr_assert(fabs(lw_potential_eval(&f, 3 + 2 * (i + 0.5), 4 + 2 * (j + 0.5)) - pow(img->tone[j * 7 + i], 3)) <
                1e-7);
  cr_assert(lw_potential_eval(&f, 0, 0) == 1.0);
  lw_potential_clear(&f);
  lw_image_free(img);
}

/* Pixels wider than a millimetre are read through a finer grid (an odd
** number of nodes a pixel, so that the pixel centres are nodes): Phi is the
** bilinear reading between the centres as before, and the picture's edge
** pixels keep their tone out to the picture's edge, where it turns white
** within a node.  With a node a pixel a picture of one pixel 50 mm wide
** faded to white from its centre, a pyramid the anneal drew as a blob. */
Test(imagefield, a_picture_of_wide_pixels_keeps_its_tone_to_its_edge)
{
  lw_image *img = lw_image_new(1, 1, 0, NULL);
  img->tone[0] = 0.3f;
  lw_image_place pl = {10, 20, 50};
  lw_potential f = {.kind = LW_POTENTIAL_GRID};
  f.grid = lw_imagefield_potential(img, &pl, 1.0, 0.0, 1, 1, NULL);
  cr_assert_not_null(f.grid);
  cr_assert(f.grid->hx <= 1.0 && f.grid->hx > 0.9, "node spacing %g", f.grid->hx);
  for (double x = 10.5; x < 60; x += 1.0)
    for (double y = 20.5; y < 70; y += 7.0)
      cr_assert(fabs(lw_potential_eval(&f, x, y) - 0.3) < 1e-6, "Phi(%g, %g) = %g", x, y, lw_potential_eval(&f, x, y));
  cr_assert(lw_potential_eval(&f, 61, 45) == 1.0 && lw_potential_eval(&f, 35, 19) == 1.0, "white a node beyond");
  lw_potential_clear(&f);
  /* scene.potential_fine = 0 (and a run begun before it): a node a pixel */
  f.grid = lw_imagefield_potential(img, &pl, 1.0, 0.0, 1, 0, NULL);
  cr_assert(f.grid->nx == 3 && f.grid->ny == 3 && f.grid->hx == 50.0);
  cr_assert_float_eq(lw_potential_eval(&f, 10.0, 45.0), 0.65, 1e-6);
  lw_potential_clear(&f);
  lw_image_free(img);
  /* two pixels 3 mm wide, 0.2 and 0.8: 3 nodes a pixel, the centres' tones
  ** at the centres and the line between them as before; the outer halves
  ** of the pixels keep their tones */
  img = lw_image_new(2, 1, 0, NULL);
  img->tone[0] = 0.2f, img->tone[1] = 0.8f;
  pl = (lw_image_place){0, 0, 3};
  f.grid = lw_imagefield_potential(img, &pl, 1.0, 0.0, 1, 1, NULL);
  cr_assert_not_null(f.grid);
  cr_assert_float_eq(f.grid->hx, 1.0, 1e-12);
  const double at[][2] = {{1.5, 0.2}, {4.5, 0.8}, {3.0, 0.5}, {2.25, 0.35}, {0.5, 0.2}, {5.5, 0.8}};
  for (size_t q = 0; q < sizeof at / sizeof *at; q++)
    cr_assert(fabs(lw_potential_eval(&f, at[q][0], 1.5) - at[q][1]) < 1e-6, "Phi(%g) = %g", at[q][0],
              lw_potential_eval(&f, at[q][0], 1.5));
  lw_potential_clear(&f);
  /* pixels of a millimetre or less: a node a pixel, as before */
  pl.pixel = 1.0;
  f.grid = lw_imagefield_potential(img, &pl, 1.0, 0.0, 1, 1, NULL);
  cr_assert(f.grid->nx == 4 && f.grid->ny == 3 && f.grid->hx == 1.0);
  lw_potential_clear(&f);
  lw_image_free(img);
}

Test(imagefield, a_blurred_potential_spreads_phi_and_keeps_its_sum)
{
  /* scene.potential_blur: one white pixel on black, power 8, blurred by 2
  ** pixels: Phi (not the tone, whose eighth power would all but vanish)
  ** spreads as a Gaussian of 2 pixels, 1 / (2 pi 4) at its centre, the same
  ** at equal distances.  The picture is blurred on its white paper: the
  ** darkness 1 - Phi summed over it and the paper around keeps its 440
  ** pixels, Phi rises across the edge without a step (the blurred step's
  ** values either side of it sum to 1) and is white from 4 sigma on.  It
  ** continued the black edge, and lines beyond a dark edge cost nothing. */
  lw_image *img = lw_image_new(21, 21, 0, NULL);
  for (int k = 0; k < 21 * 21; k++) img->tone[k] = 0.0f;
  img->tone[10 * 21 + 10] = 1.0f;
  lw_image_place pl = {0, 0, 1};
  lw_potential f = {.kind = LW_POTENTIAL_GRID};
  f.grid = lw_imagefield_potential(img, &pl, 8.0, 2.0, 1, 1, NULL);
  cr_assert_not_null(f.grid);
  double dark = 0.0;
  for (int j = -12; j < 33; j++)
    for (int i = -12; i < 33; i++) dark += 1.0 - lw_potential_eval(&f, i + 0.5, j + 0.5);
  const double centre = lw_potential_eval(&f, 10.5, 10.5);
  cr_assert(fabs(dark - 440.0) < 1e-3, "darkness %.9g", dark);
  cr_assert(fabs(centre - 1.0 / (8.0 * M_PI)) < 2e-3, "centre %.9g", centre);
  cr_assert(fabs(lw_potential_eval(&f, 12.5, 10.5) - lw_potential_eval(&f, 10.5, 8.5)) < 1e-7);
  cr_assert(lw_potential_eval(&f, 12.5, 10.5) < centre && lw_potential_eval(&f, 12.5, 10.5) > 0.1 * centre);
  cr_assert(fabs(lw_potential_eval(&f, 0.5, 10.5) + lw_potential_eval(&f, -0.5, 10.5) - 1.0) < 1e-5 &&
            lw_potential_eval(&f, 0.5, 10.5) < 0.5, "across the edge: %g and %g", lw_potential_eval(&f, 0.5, 10.5),
            lw_potential_eval(&f, -0.5, 10.5));
  for (double x = 0.5; x > -7.0; x -= 1.0)
    cr_assert(lw_potential_eval(&f, x - 1.0, 10.5) > lw_potential_eval(&f, x, 10.5), "rises beyond x = %g", x);
  cr_assert(fabs(lw_potential_eval(&f, -8.5, 10.5) - 1.0) < 1e-6 && fabs(lw_potential_eval(&f, -50, 3) - 1.0) < 1e-6 &&
            fabs(lw_potential_eval(&f, 40, 60) - 1.0) < 1e-6, "beyond the picture: %g", lw_potential_eval(&f, -50, 3));
  lw_potential_clear(&f);
  /* without the paper (scene.potential_paper = 0, runs before 2026-12-06)
  ** the blur repeats the edge and Phi continues it: black beyond */
  f.grid = lw_imagefield_potential(img, &pl, 8.0, 2.0, 0, 1, NULL);
  cr_assert_not_null(f.grid);
  cr_assert(lw_potential_eval(&f, -50, 3) < 1e-6 &&
                lw_potential_eval(&f, -0.5, 10.5) == lw_potential_eval(&f, 0.5, 10.5),
            "the edge continued: %g", lw_potential_eval(&f, -50, 3));
  cr_assert(fabs(lw_potential_eval(&f, 10.5, 10.5) - centre) < 1e-6, "the same blur inside");
  lw_potential_clear(&f);
  lw_image_free(img);
}

Test(imagefield, axial_grid_does_not_cancel_opposite_signs)
{
  /* Two nodes holding directions 10 and 190 degrees (the same axis with
  ** opposite signs) interpolate to that axis at full length; 0 and 90
  ** degrees meet at 45 with the length of their doubled-angle mean. */
  lw_field f = {.kind = LW_FIELD_GRID_AXIAL};
  f.grid = lw_grid2d_new(2, 1, 2, 0, 0, 1, 1, NULL);
  double t0 = 10 * M_PI / 180, t1 = 190 * M_PI / 180;
  f.grid->data[0] = cos(2 * t0);
  f.grid->data[1] = sin(2 * t0);
  f.grid->data[2] = cos(2 * t1);
  f.grid->data[3] = sin(2 * t1);
  double vx, vy;
  lw_field_eval(&f, 0.37, 0, &vx, &vy);
  cr_assert(fabs(hypot(vx, vy) - 1) < 1e-12 && axial_angle(vx, vy, cos(t0), sin(t0)) < 1e-7);
  f.grid->data[0] = 1;
  f.grid->data[1] = 0;
  f.grid->data[2] = -1; /* 90 degrees: doubled angle 180 */
  f.grid->data[3] = 0;
  lw_field_eval(&f, 0.5, 0, &vx, &vy);
  cr_assert(vx == 0 && vy == 0, "opposite doubled angles cancel exactly at the middle");
  lw_field_eval(&f, 0.25, 0, &vx, &vy);
  cr_assert(fabs(hypot(vx, vy) - 0.5) < 1e-12 && axial_angle(vx, vy, 1, 0) < 1e-12);
  /* every angle round trip, including the awkward ones near 90 degrees */
  for (int k = 0; k < 360; k++) {
    double t = k * M_PI / 180 + 1e-9 * k, m = 0.3 + k / 400.0;
    f.grid->data[0] = f.grid->data[2] = m * cos(2 * t);
    f.grid->data[1] = f.grid->data[3] = m * sin(2 * t);
    lw_field_eval(&f, 0.6, 0, &vx, &vy);
    cr_assert(fabs(hypot(vx, vy) - m) < 1e-12 && axial_angle(vx, vy, cos(t), sin(t)) < 1e-7, "%d degrees", k);
  }
  lw_field_clear(&f);
}

Test(imagefield, squared_distance_transform_is_exact)
{
  rng_seed(24);
  for (int trial = 0; trial < 5; trial++) {
    int w = 17 + trial * 5, h = 13 + trial * 3;
    unsigned char *feat = calloc((size_t)w * h, 1);
    for (int k = 0; k < w * h; k++) feat[k] = urand(0, 1) < 0.03 * (trial + 1);
    if (trial == 0) memset(feat, 0, (size_t)w * h); /* none at all */
    double *d = malloc(sizeof(double) * w * h);
    cr_assert_eq(lw_sdt_squared(feat, w, h, d, NULL), LW_OK);
    for (int j = 0; j < h; j++)
      for (int i = 0; i < w; i++) {
        double best = HUGE_VAL;
        for (int q = 0; q < h; q++)
          for (int p = 0; p < w; p++)
            if (feat[q * w + p]) best = fmin(best, (double)(p - i) * (p - i) + (double)(q - j) * (q - j));
        cr_assert(d[j * w + i] == best, "trial %d (%d, %d): %g vs %g", trial, i, j, d[j * w + i], best);
      }
    free(d);
    free(feat);
  }
}

Test(imagefield, mask_distance_matches_a_disk_and_is_outside_beyond_the_picture)
{
  const int w = 130, h = 120;
  const double cx = 64.2, cy = 58.7, R = 40.3;
  lw_image_place pl = {10, 20, 0.5};
  unsigned char *in = malloc((size_t)w * h);
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) in[j * w + i] = hypot(i + 0.5 - cx, j + 0.5 - cy) < R;
  lw_boundary b = {.kind = LW_BOUNDARY_MASK};
  b.sdt = lw_sdt_grid(in, w, h, &pl, NULL);
  cr_assert_not_null(b.sdt);
  /* the pixelised disk's edge lies within about half a pixel of the circle,
  ** so the distance agrees with |r - c| - R to better than a pixel */
  double worst = 0;
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      double x = pl.x0 + (i + 0.5) * pl.pixel, y = pl.y0 + (j + 0.5) * pl.pixel;
      double exact = (hypot(i + 0.5 - cx, j + 0.5 - cy) - R) * pl.pixel;
      worst = fmax(worst, fabs(lw_boundary_distance(&b, x, y) - exact));
    }
  cr_assert(worst < 1.0 * pl.pixel, "worst error %g px", worst / pl.pixel);
  lw_boundary_clear(&b);

  /* a mask that is inside everywhere: the zero level is the picture's
  ** edge, nothing beyond it is inside, however it is approached */
  memset(in, 1, (size_t)w * h);
  b.kind = LW_BOUNDARY_MASK;
  b.sdt = lw_sdt_grid(in, w, h, &pl, NULL);
  double x1 = pl.x0 + w * pl.pixel, y1 = pl.y0 + h * pl.pixel;
  rng_seed(25);
  for (int k = 0; k < 20000; k++) {
    double x = urand(pl.x0 - 3, x1 + 3), y = urand(pl.y0 - 3, y1 + 3);
    int inside_picture = x > pl.x0 && x < x1 && y > pl.y0 && y < y1;
    if (!inside_picture) cr_assert(lw_boundary_distance(&b, x, y) >= 0, "(%g, %g) beyond the picture", x, y);
  }
  cr_assert(lw_boundary_distance(&b, pl.x0 + 0.5 * pl.pixel, 40) < 0, "the border pixel is inside");
  cr_assert(lw_boundary_distance(&b, 1e9, -1e9) > 0 && lw_boundary_distance(&b, NAN, 3) == INFINITY);
  lw_boundary_clear(&b);
  lw_boundary_clear(&b); /* twice is harmless */
  cr_assert_eq(lw_boundary_distance(&b, 50, 50), INFINITY, "a cleared mask has no inside");

  lw_error err;
  memset(in, 0, (size_t)w * h);
  cr_assert_null(lw_sdt_grid(in, w, h, &pl, &err));
  cr_assert_eq(err.code, LW_EINPUT);
  free(in);
}
