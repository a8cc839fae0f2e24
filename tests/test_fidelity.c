/* test_fidelity.c -- ink rendering, blur, MSE and SSIM against a target tone. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "linewise/drawing.h"
#include "linewise/fidelity.h"
#include "testutil.h"

#define C1 (0.01 * 0.01)

/* A dark disc of radius 10 px with a soft edge, centred at (cx, cy), on a
** w x h image (darkness 0..1). */
static void disc(double *v, int w, int h, double cx, double cy)
{
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      double r = hypot(i - cx, j - cy);
      v[j * w + i] = 0.9 / (1.0 + exp(r - 10.0));
    }
}

Test(fidelity, identical_images_score_perfectly)
{
  enum { W = 40, H = 30 };
  double a[W * H], b[W * H];
  rng_seed(3);
  for (int k = 0; k < W * H; k++) a[k] = b[k] = urand(0, 1);
  lw_fidelity f;
  cr_assert_eq(lw_fidelity_compare(a, b, W, H, 1.7, 2.2, LW_FIDELITY_WHITE, &f, NULL), LW_OK);
  cr_assert_eq(f.mse, 0.0);
  cr_assert(fabs(f.ssim - 1.0) < 1e-12, "ssim %.17g", f.ssim);
}

/* SSIM falls and MSE grows as the copy moves further or gets blurrier. */
Test(fidelity, ssim_falls_with_shift_and_blur)
{
  enum { W = 64, H = 64 };
  static double ref[W * H], a[W * H], b[W * H];
  disc(ref, W, H, 32, 32);
  double last_ssim = 2, last_mse = -1;
  for (int shift = 0; shift <= 5; shift++) {
    memcpy(a, ref, sizeof a);
    disc(b, W, H, 32 + shift, 32 + 0.5 * shift);
    lw_fidelity f;
    cr_assert_eq(lw_fidelity_compare(a, b, W, H, 1, 1, LW_FIDELITY_WHITE, &f, NULL), LW_OK);
    cr_assert(f.ssim < last_ssim && f.mse > last_mse, "shift %d: ssim %g (before %g), mse %g (before %g)", shift,
              f.ssim, last_ssim, f.mse, last_mse);
    last_ssim = f.ssim;
    last_mse = f.mse;
  }
  last_ssim = 2;
  last_mse = -1;
  const double blur[] = {0, 0.5, 1, 2, 4};
  for (int k = 0; k < 5; k++) {
    memcpy(a, ref, sizeof a);
    memcpy(b, ref, sizeof b);
    cr_assert_eq(lw_fidelity_blur(b, W, H, blur[k], blur[k], 4, NULL), LW_OK);
    lw_fidelity f;
    cr_assert_eq(lw_fidelity_compare(a, b, W, H, 0, 0, LW_FIDELITY_WHITE, &f, NULL), LW_OK);
    cr_assert(f.ssim < last_ssim && f.mse > last_mse, "blur %g: ssim %g, mse %g", blur[k], f.ssim, f.mse);
    last_ssim = f.ssim;
    last_mse = f.mse;
  }
}

/* The blur's definition summed directly: each axis the Gaussian cut at
** truncate sigma and renormalised over the weights inside the raster. */
static void blur_direct(double *v, int w, int h, double s, double truncate)
{
  int r = (int)ceil(truncate * s);
  double *t = malloc(sizeof(double) * w * h);
  for (int pass = 0; pass < 2; pass++) {
    int n = pass ? h : w, lines = pass ? w : h;
    size_t step = pass ? (size_t)w : 1, line = pass ? 1 : (size_t)w;
    for (int l = 0; l < lines; l++)
      for (int i = 0; i < n; i++) {
        double sum = 0, norm = 0;
        for (int k = i - r; k <= i + r; k++)
          if (k >= 0 && k < n) {
            double g = exp(-0.5 * (k - i) * (k - i) / (s * s));
            sum += g * v[l * line + (size_t)k * step];
            norm += g;
          }
        t[l * line + (size_t)i * step] = sum / norm;
      }
    memcpy(v, t, sizeof(double) * w * h);
  }
  free(t);
}

/* Wide blurs of the score are summed at every f-th position and
** interpolated (fidelity.c): within 1e-5 of the direct sums on a disc's
** sharp rim (worst 4.4e-6) at the first sparse sigma and wider; wider than
** the raster the radius is cut and the sums stay direct. */
Test(fidelity, wide_blurs_summed_sparsely_match_the_direct_sum)
{
  enum { W = 231, H = 187 };
  static double a[W * H], b[W * H];
  const double sigmas[] = {16, 22.5, 90};
  for (int k = 0; k < 3; k++) {
    disc(a, W, H, 50, 40);
    memcpy(b, a, sizeof a);
    cr_assert_eq(lw_fidelity_blur(a, W, H, sigmas[k], sigmas[k], 4, NULL), LW_OK);
    blur_direct(b, W, H, sigmas[k], 4);
    double worst = 0;
    for (int i = 0; i < W * H; i++) worst = fmax(worst, fabs(a[i] - b[i]));
    cr_log_info("sigma %g: worst %.2e", sigmas[k], worst);
    cr_assert(worst < 1e-5, "sigma %g: %.3g off the direct sum", sigmas[k], worst);
  }
}

/* No lines against a flat tone: the blur keeps the darkness c everywhere
** (renormalised edges), so MSE = c^2 and SSIM = C1 / (c^2 + C1) (zero mean,
** zero variance on the ink side, zero variance on the target side). */
Test(fidelity, blank_render_against_flat_tone)
{
  lw_grid2d *tone = lw_grid2d_new(50, 40, 1, 0.25, 0.25, 0.5, 0.5, NULL);
  for (int k = 0; k < 50 * 40; k++) tone->data[k] = 0.6;
  lw_splines *sp = lw_splines_new(0, NULL, NULL);
  lw_fidelity f;
  lw_error err;
  cr_assert_eq(lw_fidelity_compute(sp, tone, 0.3, 1.0, &f, &err), LW_OK, "%s", err.msg);
  cr_assert(fabs(f.mse - 0.16) < 1e-12, "mse %.17g", f.mse);
  cr_assert(fabs(f.ssim - C1 / (0.16 + C1)) < 1e-12, "ssim %.17g", f.ssim);
  cr_assert_eq(f.sigma_mm, 1.0);
  lw_splines_free(sp);
  lw_grid2d_free(tone);
}

/* No lines against one black pixel in the middle of white paper: the
** blurred darkness is the normalised Gaussian g, so MSE = sum g^2 / N, and
** for sigma s pixels sum g^2 = 1 / (4 pi s^2) (the continuous integral; the
** sampled sum agrees to far better than the 4-sigma truncation, ~1e-4). */
Test(fidelity, blank_render_against_an_impulse)
{
  const int n = 121;
  const double px = 0.5, sigma_mm = 2.0, s = sigma_mm / px;
  lw_grid2d *tone = lw_grid2d_new(n, n, 1, 0, 0, px, px, NULL);
  for (int k = 0; k < n * n; k++) tone->data[k] = 1.0;
  tone->data[60 * n + 60] = 0.0;
  lw_splines *sp = lw_splines_new(0, NULL, NULL);
  lw_fidelity f;
  cr_assert_eq(lw_fidelity_compute(sp, tone, 0.3, sigma_mm, &f, NULL), LW_OK);
  double want = 1.0 / (4 * M_PI * s * s) / ((double)n * n);
  cr_assert(fabs(f.mse / want - 1) < 1e-3, "mse %.9g, expected %.9g", f.mse, want);
  lw_splines_free(sp);
  lw_grid2d_free(tone);
}

/* The rendered ink covers the stroke's area: a 40 mm line with a 0.5 mm
** pen and round caps covers 40 x 0.5 + pi 0.25^2 mm^2. */
Test(fidelity, render_conserves_ink_area)
{
  const double px = 0.25;
  lw_grid2d *tone = lw_grid2d_new(240, 80, 1, 0.5 * px, 0.5 * px, px, px, NULL);
  size_t segs[1] = {3};
  lw_splines *sp = lw_splines_new(1, segs, NULL);
  lw_test_straight(sp, 0, 7.3, 10.37, 47.3, 10.37);
  double *ink = malloc(240 * 80 * sizeof *ink);
  cr_assert_eq(lw_fidelity_render(sp, tone, 0.5, ink, NULL), LW_OK);
  double area = 0;
  for (int k = 0; k < 240 * 80; k++) {
    cr_assert(ink[k] >= 0 && ink[k] <= 1);
    area += ink[k] * px * px;
  }
  double want = 40 * 0.5 + M_PI * 0.25 * 0.25;
  cr_assert(fabs(area / want - 1) < 0.01, "ink %.6g mm^2, expected %.6g", area, want);
  /* the ink lies on the line: pixel row 41 (y 10.25..10.5) is inked, row 30 not */
  cr_assert(ink[41 * 240 + 100] > 0.4 && ink[30 * 240 + 100] == 0);
  free(ink);
  lw_splines_free(sp);
  lw_grid2d_free(tone);
}

/* On pixels far wider than the pen the ink is still the stroked area: on a
** 4 x 3 raster of 12.5 mm pixels, lines of 0.3 mm and 30 mm long, 20 of
** them 1.2 mm apart in the first two columns and 20 of them 0.45 mm apart
** (gaps of half a pen) in the third.  Rendered at the raster's own pixels
** each path's 2.4 % of a pixel rounded away in eight bits (no ink at all);
** composited as independent coverage (OVER), lines that share a fine pixel
** lose their common share. */
Test(fidelity, coarse_pixels_keep_the_ink)
{
  const double px = 12.5, pen = 0.3;
  const int w = 4, h = 3;
  lw_grid2d *tone = lw_grid2d_new(w, h, 1, 0.5 * px, 0.5 * px, px, px, NULL);
  size_t segs[40];
  for (int k = 0; k < 40; k++) segs[k] = 2;
  lw_splines *sp = lw_splines_new(40, segs, NULL);
  for (int k = 0; k < 20; k++) {
    lw_test_straight(sp, (size_t)k, 0.75 + 1.2 * k, 2.0, 0.75 + 1.2 * k, 32.0);
    lw_test_straight(sp, (size_t)(20 + k), 27.0 + 0.45 * k, 2.0, 27.0 + 0.45 * k, 32.0);
  }
  double ink[12];
  cr_assert_eq(lw_fidelity_render(sp, tone, pen, ink, NULL), LW_OK);
  const double line = 30 * pen + M_PI * 0.25 * pen * pen; /* caps included */
  double col[4] = {0, 0, 0, 0};
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) col[i] += ink[j * w + i] * px * px;
  const double want[4] = {10 * line, 10 * line, 20 * line, 0};
  for (int i = 0; i < 3; i++)
    cr_assert(fabs(col[i] / want[i] - 1) < 0.01, "column %d: ink %.6g mm^2, expected %.6g", i, col[i], want[i]);
  cr_assert(col[3] == 0);
  lw_splines_free(sp);
  lw_grid2d_free(tone);
}

/* Hatching at 2 mm with a 0.4 mm pen is a grey of darkness 0.2 once blurred
** by 1 mm (ripple damped by exp(-2 pi^2 / 4) < 1%): far closer to the flat
** 0.2 target than blank paper (MSE 0.04), and structurally alike. */
Test(fidelity, hatching_matches_its_grey)
{
  const double px = 0.2;
  const int w = 200, h = 150; /* 40 x 30 mm */
  lw_grid2d *tone = lw_grid2d_new(w, h, 1, 0.5 * px, 0.5 * px, px, px, NULL);
  for (int k = 0; k < w * h; k++) tone->data[k] = 0.8;
  const size_t n = 15;
  size_t segs[15];
  for (size_t i = 0; i < n; i++) segs[i] = 1;
  lw_splines *sp = lw_splines_new(n, segs, NULL);
  for (size_t i = 0; i < n; i++) lw_test_straight(sp, i, -5, 1 + 2.0 * (double)i, 45, 1 + 2.0 * (double)i);
  lw_fidelity f;
  cr_assert_eq(lw_fidelity_compute(sp, tone, 0.4, 1.0, &f, NULL), LW_OK);
  cr_assert(f.mse < 1e-4, "mse %g", f.mse);
  cr_assert(f.ssim > 0.95, "ssim %g", f.ssim);
  /* a pen twice as wide draws darkness 0.4 against the 0.2 target: MSE
  ** 0.2^2 in the interior.  Within about sigma of the top and bottom edges
  ** the renormalised blur sees the hatching from one side only, which
  ** darkens those rows by up to 0.03; on a raster 30 mm tall that adds a
  ** few percent (2.3% measured), hence the 5% bound. */
  lw_fidelity g;
  cr_assert_eq(lw_fidelity_compute(sp, tone, 0.8, 1.0, &g, NULL), LW_OK);
  cr_assert(fabs(g.mse / 0.04 - 1) < 0.05, "mse %g, expected 0.04", g.mse);
  lw_splines_free(sp);
  lw_grid2d_free(tone);
}

/* The target is the ink the drawing is asked for, black * (1 - tone): the
** hatching above (ink 0.2) drawn for tone 0.6 with black 0.5 (the photo
** preset's tone_ink: black is lines two pen widths apart) is what was asked,
** and against solid black (black 1, darkness 0.4) it is 0.2 short.  Paper
** counts as white at the same share of black, so the stray ink of a drawing
** does not change with black. */
Test(fidelity, the_target_is_the_ink_asked_for)
{
  const double px = 0.2;
  const int w = 200, h = 150; /* 40 x 30 mm */
  lw_grid2d *tone = lw_grid2d_new(w, h, 1, 0.5 * px, 0.5 * px, px, px, NULL);
  for (int k = 0; k < w * h; k++) tone->data[k] = 0.6;
  size_t segs[15];
  for (size_t i = 0; i < 15; i++) segs[i] = 1;
  lw_splines *sp = lw_splines_new(15, segs, NULL);
  for (size_t i = 0; i < 15; i++) lw_test_straight(sp, i, -5, 1 + 2.0 * (double)i, 45, 1 + 2.0 * (double)i);
  lw_strokes *st = lw_strokes_from_plot(sp, NULL, NULL);
  cr_assert_not_null(st);
  lw_fidelity f, g;
  cr_assert_eq(lw_fidelity_compute_strokes(st, -1, tone, 0.5, 0.4, 1.0, &f, NULL), LW_OK);
  cr_assert(f.mse < 1e-4 && f.black == 0.5, "mse %g against half ink", f.mse);
  cr_assert_eq(lw_fidelity_compute_strokes(st, -1, tone, 1.0, 0.4, 1.0, &g, NULL), LW_OK);
  cr_assert(fabs(g.mse / 0.04 - 1) < 0.05, "mse %g against solid black, expected 0.04", g.mse);
  for (int k = 0; k < w * h; k++) tone->data[k] = k % w < w / 2 ? 0.0 : 0.995;
  cr_assert_eq(lw_fidelity_compute_strokes(st, -1, tone, 0.5, 0.4, 1.0, &f, NULL), LW_OK);
  cr_assert_eq(lw_fidelity_compute_strokes(st, -1, tone, 1.0, 0.4, 1.0, &g, NULL), LW_OK);
  cr_assert(f.stray > 0.3 && f.stray == g.stray, "stray %g with black 0.5, %g with black 1", f.stray, g.stray);
  cr_assert_eq(lw_fidelity_compute_strokes(st, -1, tone, 0.0, 0.4, 1.0, &f, NULL), LW_EINPUT);
  lw_strokes_free(st);
  lw_splines_free(sp);
  lw_grid2d_free(tone);
}

/* Stray ink is the ink on paper the target leaves white for some two blur
** sigmas around: a picture black on its left half, white on its right.
** Lines in the black and 1 mm into the white beside the edge (blurred
** darkness 0.16 there at sigma 1 mm) are not stray; a line 10 mm into the
** white is, whole: with three lines of one length its share is a third. */
Test(fidelity, stray_ink_is_ink_far_inside_the_white)
{
  const double px = 0.2;
  const int w = 200, h = 150; /* 40 x 30 mm */
  lw_grid2d *tone = lw_grid2d_new(w, h, 1, 0.5 * px, 0.5 * px, px, px, NULL);
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) tone->data[j * w + i] = i < w / 2 ? 0.0 : 1.0;
  size_t segs[3] = {1, 1, 1};
  const double x[3] = {19.8, 21, 30};
  lw_splines *edge = lw_splines_new(2, segs, NULL), *all = lw_splines_new(3, segs, NULL);
  for (size_t i = 0; i < 3; i++) {
    if (i < 2) lw_test_straight(edge, i, x[i], 5, x[i], 25);
    lw_test_straight(all, i, x[i], 5, x[i], 25);
  }
  lw_fidelity f;
  cr_assert_eq(lw_fidelity_compute(edge, tone, 0.3, 1.0, &f, NULL), LW_OK);
  cr_assert(f.stray == 0, "edge lines: stray %g", f.stray);
  cr_assert_eq(lw_fidelity_compute(all, tone, 0.3, 1.0, &f, NULL), LW_OK);
  cr_assert(fabs(f.stray - 1.0 / 3) < 1e-3, "stray %g, expected 1/3", f.stray);
  lw_splines_free(edge);
  lw_splines_free(all);
  lw_grid2d_free(tone);
}

/* A w x h raster of pixels px mm wide: black where dark(x, y) of a pixel's
** centre, mm, else white. */
static lw_grid2d *marks_tone(int w, int h, double px, int (*dark)(double x, double y))
{
  lw_grid2d *tone = lw_grid2d_new(w, h, 1, 0.5 * px, 0.5 * px, px, px, NULL);
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) tone->data[j * w + i] = dark((i + 0.5) * px, (j + 0.5) * px) ? 0.0 : 1.0;
  return tone;
}

static int two_bars(double x, double y)
{
  (void)y;
  return (x > 5 && x < 5.5) || (x > 20 && x < 20.5);
}

static int block_and_bar(double x, double y)
{
  return (x > 5 && x < 35 && y > 5 && y < 35) || (x > 45 && x < 48 && y > 15 && y < 18);
}

/* Missed marks, stray ink's mirror: two dark bars 0.5 mm wide (a 0.3 mm
** pen); a line along the first alone misses the second (half the marks),
** along both none; a line 0.3 mm beside each still reaches it (all of it
** within 2 pen widths of the line's ink), one 1.5 mm off not. */
Test(fidelity, missed_marks_are_dark_pixels_no_line_came_near)
{
  const double pen = 0.3;
  lw_grid2d *tone = marks_tone(300, 200, 0.1, two_bars); /* 30 x 20 mm */
  static const struct {
    int n;
    double x[2], want;
  } cases[] = {{1, {5.25, 0}, 0.5}, {2, {5.25, 20.25}, 0.0}, {2, {4.7, 20.8}, 0.0}, {2, {3.5, 22}, 1.0}};
  for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
    size_t segs[2] = {1, 1};
    lw_splines *sp = lw_splines_new((size_t)cases[k].n, segs, NULL);
    for (int i = 0; i < cases[k].n; i++) lw_test_straight(sp, (size_t)i, cases[k].x[i], 0, cases[k].x[i], 20);
    lw_fidelity f;
    cr_assert_eq(lw_fidelity_compute(sp, tone, pen, 1.0, &f, NULL), LW_OK);
    /* (within the pixels a line's rendered width spans) */
    cr_assert(fabs(f.missed - cases[k].want) < 1e-12, "case %zu: missed %g, expected %g", k, f.missed, cases[k].want);
    lw_splines_free(sp);
  }
  lw_grid2d_free(tone);
}

/* A small mark left bare beside a large area hatched whole: a hundredth of
** the marks, but all of its square's (the worst square, 25 pen widths a
** side, names it and where); hatched too, none. */
Test(fidelity, the_worst_square_finds_a_small_mark_left_bare)
{
  const double pen = 0.3;
  lw_grid2d *tone = marks_tone(600, 400, 0.1, block_and_bar); /* 60 x 40 mm */
  for (int bar = 0; bar < 2; bar++) {
    size_t n = 61 + (size_t)(bar ? 7 : 0), segs[68];
    for (size_t i = 0; i < n; i++) segs[i] = 1;
    lw_splines *sp = lw_splines_new(n, segs, NULL);
    for (size_t i = 0; i < 61; i++) lw_test_straight(sp, i, 5 + 0.5 * (double)i, 5, 5 + 0.5 * (double)i, 35);
    for (size_t i = 61; i < n; i++) lw_test_straight(sp, i, 45 + 0.5 * (double)(i - 61), 15, 45 + 0.5 * (double)(i - 61), 18);
    lw_fidelity f;
    cr_assert_eq(lw_fidelity_compute(sp, tone, pen, 1.0, &f, NULL), LW_OK);
    if (!bar)
      cr_assert(f.missed < 0.02 && f.missed_worst == 1.0 && fabs(f.missed_at[0] - 48.75) < 1e-9 &&
                    fabs(f.missed_at[1] - 18.75) < 1e-9,
                "the bar bare: missed %g, worst %g at (%g, %g)", f.missed, f.missed_worst, f.missed_at[0],
                f.missed_at[1]);
    else cr_assert(f.missed == 0.0 && f.missed_worst == 0.0, "hatched: missed %g, worst %g", f.missed, f.missed_worst);
    lw_splines_free(sp);
  }
  lw_grid2d_free(tone);
}

Test(fidelity, bad_input)
{
  lw_splines *sp = lw_splines_new(0, NULL, NULL);
  lw_grid2d *field = lw_grid2d_new(4, 4, 2, 0, 0, 1, 1, NULL);
  lw_fidelity f;
  lw_error err;
  cr_assert_eq(lw_fidelity_compute(sp, field, 0.3, 1, &f, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "tone raster"), "%s", err.msg);
  lw_grid2d *tone = lw_grid2d_new(4, 4, 1, 0, 0, 1, 1, NULL);
  cr_assert_eq(lw_fidelity_compute(sp, tone, 0.3, 0, &f, &err), LW_EINPUT);
  cr_assert_eq(lw_fidelity_compute(sp, tone, -1, 1, &f, &err), LW_EINPUT);
  cr_assert_eq(lw_fidelity_compute(sp, NULL, 0.3, 1, &f, &err), LW_EINPUT);
  lw_grid2d_free(field);
  lw_grid2d_free(tone);
  lw_splines_free(sp);
}

/* A target whose darkness varies across x only (isophotes run along y),
** 60 x 40 mm at 0.2 mm pixels, and two drawings with the same ink: lines
** along the isophotes spaced so that their density follows the darkness
** (pen / spacing = darkness), and evenly spaced lines across them.  Every
** score, at every blur, ranks the first above the second. */
static double ramp_dark(double x) { return 0.05 + 0.3 * (0.5 + 0.5 * sin(2 * M_PI * x / 30.0)); }

Test(fidelity, scores_rank_a_better_drawing_above_a_worse_one)
{
  const double px = 0.2, pen = 0.4;
  const int w = 300, h = 200;
  lw_grid2d *tone = lw_grid2d_new(w, h, 1, 0.5 * px, 0.5 * px, px, px, NULL);
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) tone->data[j * w + i] = 1.0 - ramp_dark((i + 0.5) * px);
  size_t segs[200];
  for (int k = 0; k < 200; k++) segs[k] = 1;
  /* along: x_{k+1} = x_k + pen / darkness at the midpoint */
  double xs[200];
  size_t na = 0;
  for (double x = 0.0; x < 60.0 && na < 200;) {
    double step = pen / ramp_dark(x + 0.5 * pen / ramp_dark(x));
    xs[na++] = x + 0.5 * step;
    x += step;
  }
  lw_splines *good = lw_splines_new(na, segs, NULL);
  for (size_t k = 0; k < na; k++) lw_test_straight(good, k, xs[k], -5, xs[k], 45);
  /* across: the mean darkness 0.2 is a spacing of pen / 0.2 = 2 mm */
  const size_t nb = 20;
  lw_splines *bad = lw_splines_new(nb, segs, NULL);
  for (size_t k = 0; k < nb; k++) lw_test_straight(bad, k, -5, 1 + 2.0 * k, 65, 1 + 2.0 * k);
  const double sigma[3] = {0.5, 1.0, 2.0};
  for (int s = 0; s < 3; s++) {
    lw_fidelity a, b;
    cr_assert_eq(lw_fidelity_compute(good, tone, pen, sigma[s], &a, NULL), LW_OK);
    cr_assert_eq(lw_fidelity_compute(bad, tone, pen, sigma[s], &b, NULL), LW_OK);
    cr_assert(a.mse < b.mse, "sigma %g: mse %g vs %g", sigma[s], a.mse, b.mse);
    cr_assert(a.ssim > b.ssim, "sigma %g: ssim %g vs %g", sigma[s], a.ssim, b.ssim);
    cr_assert(a.orientation > b.orientation + 0.5, "sigma %g: orientation %g vs %g", sigma[s], a.orientation,
              b.orientation);
    cr_assert(a.orientation > 0.8 && b.orientation < 0.1, "sigma %g: orientation %g vs %g", sigma[s], a.orientation,
              b.orientation);
  }
  lw_splines_free(good);
  lw_splines_free(bad);
  lw_grid2d_free(tone);
}

Test(fidelity, orientation_of_a_flat_target_is_undefined_and_of_no_ink_zero)
{
  const int w = 40, h = 30;
  double a[40 * 30], b[40 * 30];
  lw_fidelity f;
  for (int k = 0; k < w * h; k++) a[k] = b[k] = 0.3;
  cr_assert_eq(lw_fidelity_compare(a, b, w, h, 1, 1, LW_FIDELITY_WHITE, &f, NULL), LW_OK);
  cr_assert(isnan(f.orientation));
  disc(b, w, h, 20, 15);
  for (int k = 0; k < w * h; k++) a[k] = 0.0;
  cr_assert_eq(lw_fidelity_compare(a, b, w, h, 1, 1, LW_FIDELITY_WHITE, &f, NULL), LW_OK);
  cr_assert_eq(f.orientation, 0.0);
  /* the same disc, fainter: structure alike, tone not */
  disc(a, w, h, 20, 15);
  for (int k = 0; k < w * h; k++) a[k] *= 0.3;
  disc(b, w, h, 20, 15);
  cr_assert_eq(lw_fidelity_compare(a, b, w, h, 1, 1, LW_FIDELITY_WHITE, &f, NULL), LW_OK);
  cr_assert(fabs(f.orientation - 1) < 1e-12, "%g", f.orientation);
}

/* ---- the scores on whole planes ---------------------------------------- */

/* One plane under the SSIM window as fidelity.h defines it: a Gaussian of
** sigma 1.5 px cut at 5 px (or the image's size), renormalised by the
** weights inside, along x and then along y, each sum taken from the lowest
** index up. */
static void ref_window(double *v, int w, int h)
{
  const double s = LW_FIDELITY_SSIM_SIGMA;
  for (int axis = 0; axis < 2; axis++) {
    int n = axis ? h : w, lines = axis ? w : h, r = LW_FIDELITY_SSIM_RADIUS < n ? LW_FIDELITY_SSIM_RADIUS : n;
    double *line = malloc((size_t)n * sizeof *line);
    for (int c = 0; c < lines; c++) {
      for (int i = 0; i < n; i++) line[i] = axis ? v[i * w + c] : v[c * w + i];
      for (int i = 0; i < n; i++) {
        double sum = 0.0, norm = 0.0;
        for (int k = i - r; k <= i + r; k++)
          if (k >= 0 && k < n) norm += exp(-0.5 * (k - i) * (k - i) / (s * s));
        for (int k = i - r > 0 ? i - r : 0; k <= i + r && k < n; k++)
          sum += exp(-0.5 * (k - i) * (k - i) / (s * s)) * line[k];
        *(axis ? &v[i * w + c] : &v[c * w + i]) = sum / norm;
      }
    }
    free(line);
  }
}

/* SSIM and orientation of blurred a against blurred b on whole planes. */
static void ref_scores(const double *a, const double *b, int w, int h, double *ssim, double *orient)
{
  size_t n = (size_t)w * (size_t)h;
  double *m = malloc(11 * n * sizeof *m);
  for (size_t k = 0; k < n; k++) {
    m[k] = a[k], m[n + k] = b[k], m[2 * n + k] = a[k] * a[k], m[3 * n + k] = b[k] * b[k];
    m[4 * n + k] = a[k] * b[k];
  }
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++)
      for (int s = 0; s < 2; s++) {
        const double *v = s ? b : a;
        int il = i > 0 ? i - 1 : i, ir = i + 1 < w ? i + 1 : i, jd = j > 0 ? j - 1 : j, ju = j + 1 < h ? j + 1 : j;
        double gx = ir > il ? (v[j * w + ir] - v[j * w + il]) / (ir - il) : 0.0;
        double gy = ju > jd ? (v[ju * w + i] - v[jd * w + i]) / (ju - jd) : 0.0;
        size_t k = (size_t)j * (size_t)w + (size_t)i, at = (size_t)(5 + 3 * s) * n;
        m[at + k] = gx * gx, m[at + n + k] = gx * gy, m[at + 2 * n + k] = gy * gy;
      }
  for (int q = 0; q < 11; q++) ref_window(m + (size_t)q * n, w, h);
  /* each row summed along the row, then the rows' sums in row order */
  double sum = 0.0, num = 0.0, den = 0.0, flat = LW_FIDELITY_FLAT * LW_FIDELITY_FLAT;
  for (int j = 0; j < h; j++) {
    double rsum = 0.0, rnum = 0.0, rden = 0.0;
    for (size_t k = (size_t)j * (size_t)w; k < (size_t)(j + 1) * (size_t)w; k++) {
      double ma = m[k], mb = m[n + k], va = m[2 * n + k] - ma * ma, vb = m[3 * n + k] - mb * mb;
      double cov = m[4 * n + k] - ma * mb;
      rsum += (2 * ma * mb + C1) * (2 * cov + 0.03 * 0.03) / ((ma * ma + mb * mb + C1) * (va + vb + 0.03 * 0.03));
      double ua0 = m[5 * n + k] - m[7 * n + k], ua1 = 2 * m[6 * n + k];
      double ub0 = m[8 * n + k] - m[10 * n + k], ub1 = 2 * m[9 * n + k];
      double la = hypot(ua0, ua1), lb = hypot(ub0, ub1);
      if (lb <= flat) continue;
      rden += lb;
      if (la > flat) rnum += (ua0 * ub0 + ua1 * ub1) / la;
    }
    sum += rsum, num += rnum, den += rden;
  }
  *ssim = sum / (double)n;
  *orient = den > 0 ? num / den : NAN;
  free(m);
}

/* The SSIM window runs a row at a time (a ring of 11 rows instead of nine
** whole planes: 288 MB for a 4-megapixel picture before), each thread over
** a band of rows; its scores are those of the whole planes to the bit, on
** images narrower and shorter than the window too, and on 1, 2, 3 and 7
** threads.  A ring that reused a slot too early or started a band without
** the rows above it, a column sum in another order or an edge weight taken
** from the wrong axis fails. */
Test(fidelity, scores_row_by_row_are_those_of_whole_planes)
{
  static const int size[][2] = {{1, 1}, {1, 9}, {9, 1}, {4, 3}, {11, 11}, {12, 30}, {37, 23}, {64, 7}};
  rng_seed(11);
  for (size_t z = 0; z < sizeof size / sizeof size[0]; z++) {
    int w = size[z][0], h = size[z][1];
    size_t n = (size_t)w * (size_t)h;
    double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b), *a0 = malloc(n * sizeof *a0),
           *b0 = malloc(n * sizeof *b0);
    for (int j = 0; j < h; j++)
      for (int i = 0; i < w; i++) {
        a[j * w + i] = urand(0, 1) * (i % 3 == 0);
        b[j * w + i] = 0.5 + 0.4 * sin(0.7 * i + 0.3 * j) + urand(-0.05, 0.05);
      }
    memcpy(a0, a, n * sizeof *a);
    memcpy(b0, b, n * sizeof *b);
    static const int threads[] = {1, 2, 3, 7};
    const int had = omp_get_max_threads();
    for (size_t t = 0; t < sizeof threads / sizeof threads[0]; t++) {
      omp_set_num_threads(threads[t]);
      memcpy(a, a0, n * sizeof *a);
      memcpy(b, b0, n * sizeof *b);
      lw_fidelity f;
      cr_assert_eq(lw_fidelity_compare(a, b, w, h, 0.8, 1.3, LW_FIDELITY_WHITE, &f, NULL), LW_OK);
      /* lw_fidelity_compare blurred a and b in place: the reference starts there */
      double ssim, orient;
      ref_scores(a, b, w, h, &ssim, &orient);
      cr_assert(f.ssim == ssim, "%d x %d, %d threads: ssim %.17g, on whole planes %.17g", w, h, threads[t], f.ssim,
                ssim);
      cr_assert(f.orientation == orient || (isnan(f.orientation) && isnan(orient)),
                "%d x %d, %d threads: orientation %.17g, on whole planes %.17g", w, h, threads[t], f.orientation,
                orient);
    }
    omp_set_num_threads(had);
    free(a), free(b), free(a0), free(b0);
  }
}

/* The blurs share a picture's lines out among the threads: the same bits
** on 1 and 3 threads, summed directly (sigma 3) and sparsely (sigma 20,
** where every 2nd position is summed and the rest interpolated).  A
** scratch line shared between threads fails. */
Test(fidelity, blurs_are_the_same_on_any_number_of_threads)
{
  const int w = 197, h = 131;
  const size_t n = (size_t)w * (size_t)h;
  double *v = malloc(n * sizeof *v), *one = malloc(n * sizeof *one), *three = malloc(n * sizeof *three);
  rng_seed(5);
  for (size_t k = 0; k < n; k++) v[k] = urand(0, 1);
  const int had = omp_get_max_threads();
  const double sigma[] = {3, 20};
  for (int s = 0; s < 2; s++) {
    memcpy(one, v, n * sizeof *v);
    memcpy(three, v, n * sizeof *v);
    omp_set_num_threads(1);
    cr_assert_eq(lw_fidelity_blur(one, w, h, sigma[s], sigma[s], LW_FIDELITY_TRUNCATE, NULL), LW_OK);
    omp_set_num_threads(3);
    cr_assert_eq(lw_fidelity_blur(three, w, h, sigma[s], sigma[s], LW_FIDELITY_TRUNCATE, NULL), LW_OK);
    cr_assert(!memcmp(one, three, n * sizeof *v), "sigma %g: 1 and 3 threads differ", sigma[s]);
    cr_assert(memcmp(one, v, n * sizeof *v), "sigma %g: nothing was blurred", sigma[s]);
  }
  omp_set_num_threads(had);
  free(v), free(one), free(three);
}

/* The missed marks' note: of the whole drawing, else of the first layer's
** pen whose own score is over 0.1; not of a pen of output.pens, which draws
** a share of the tones by design (its light half missed 92 % of the marks
** of a drawing that missed 0.0012, and the note asked for a finer pen). */
Test(fidelity, missed_marks_are_noted_of_the_drawing_or_a_layer_not_of_a_tone_share)
{
  static lw_drawing_report d;
  char text[4096];
  d.paths = 10;
  d.has_fidelity = 1;
  d.n_pens = 2;
  d.fidelity.missed = 0.0012;
  d.pen_fidelity[1].missed = 0.92;
  d.pen_width[0] = d.pen_width[1] = 0.35;
  lw_drawing_report_text(&d, text, sizeof text);
  cr_assert(strstr(text, "fidelity of pen 2:") && !strstr(text, "note:"), "%s", text);
  d.pen_targets = 2; /* [layers]: each pen has its own target */
  lw_drawing_report_text(&d, text, sizeof text);
  cr_assert(strstr(text, "note: 92 % of pen 2's target's dark marks have no line within"), "%s", text);
  d.pen_targets = 0;
  d.fidelity.missed = 0.2; /* the whole drawing's */
  lw_drawing_report_text(&d, text, sizeof text);
  cr_assert(strstr(text, "note: 20 % of the picture's dark marks have no line within"), "%s", text);
}
