/*
** test_placement.c -- where the splines start (darkness-weighted, along the
** field), how many (ink coverage), and the field preview.
*/
#include <cairo.h>
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "imageutil.h"
#include "linewise/fieldview.h"
#include "linewise/init.h"
#include "linewise/spacing.h"
#include "testutil.h"

TestSuite(placement, .init = lw_image_dir_make, .fini = lw_image_dir_remove);


/* A 100 x 100 mm page, rect boundary 5 mm in, and (if with_image) a 2 x 1
** picture: left pixel black (darkness 1), right pixel tone 0.75 (darkness
** 1/4).  Fitted into the 90 mm box it covers [5, 95] x [27.5, 72.5]. */
static void two_tone_scene(lw_params *p, lw_scene *sc, int with_image)
{
  lw_params_defaults(p);
  p->width = p->height = 100;
  p->margin = 5;
  /* 20 mm splines counted by a coverage of 1/2 with a 0.3 mm pen */
  p->splines = 0;
  p->coverage = 0.5;
  p->pen_width = 0.3;
  p->segments = 4;
  p->segment_length = 5;
  if (with_image) {
    const float g[2] = {0, 0.75f};
    snprintf(p->image, sizeof p->image, "%s", lw_test_path("two.png"));
    lw_test_png(p->image, 2, 1, g, NULL);
  }
  lw_error err;
  cr_assert_eq(lw_scene_init(sc, p, &err), LW_OK, "%s", err.msg);
}

static gsl_rng *rng(unsigned long seed)
{
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, seed);
  return r;
}

Test(placement, centres_follow_darkness)
{
  lw_params p;
  lw_scene sc;
  two_tone_scene(&p, &sc, 1);
  const size_t N = 4000;
  gsl_rng *r = rng(31);
  lw_splines *sp = lw_init_random(&sc, N, 1, 0.2, r, NULL);
  cr_assert_not_null(sp);
  size_t left = 0;
  for (size_t i = 0; i < N; i++) {
    const lw_node *nd = &sp->node[sp->first[i]];
    double x = 0.5 * (nd[0].px + nd[1].px), y = 0.5 * (nd[0].py + nd[1].py);
    cr_assert(y > 27.5 && y < 72.5, "spline %zu at y %g: outside the picture there is no darkness", i, y);
    left += x < 50;
  }
  /* darkness 1 against 1/4 on equal areas: P(left) = 0.8.  Binomial sd
  ** sqrt(0.8 * 0.2 / 4000) = 0.0063; the tolerance is 4 sd. */
  double frac = (double)left / N;
  cr_assert(fabs(frac - 0.8) < 4 * sqrt(0.16 / N), "left fraction %g", frac);
  lw_splines_free(sp);
  gsl_rng_free(r);
  lw_scene_clear(&sc);
}

Test(placement, a_white_picture_places_uniformly)
{
  lw_params p;
  lw_params_defaults(&p);
  p.width = p.height = 100;
  const float g[1] = {1};
  snprintf(p.image, sizeof p.image, "%s", lw_test_path("white.png"));
  lw_test_png(p.image, 1, 1, g, NULL);
  lw_scene sc;
  cr_assert_eq(lw_scene_init(&sc, &p, NULL), LW_OK);
  gsl_rng *r = rng(32);
  const size_t N = 2000;
  lw_splines *sp = lw_init_random(&sc, N, 1, 0.2, r, NULL);
  size_t top = 0;
  for (size_t i = 0; i < N; i++) top += sp->node[sp->first[i]].py < 50;
  /* P = 1/2, sd = 0.011; 4 sd */
  cr_assert(fabs((double)top / N - 0.5) < 4 * sqrt(0.25 / N), "%zu of %zu in the top half", top, N);
  lw_splines_free(sp);
  gsl_rng_free(r);
  lw_scene_clear(&sc);
}

Test(placement, splines_start_along_the_field)
{
  lw_params p;
  lw_params_defaults(&p);
  p.width = p.height = 100;
  p.margin = 5;
  p.field_coef = -1;
  p.field = LW_FLD_VORTEX;
  lw_scene sc;
  cr_assert_eq(lw_scene_init(&sc, &p, NULL), LW_OK);
  gsl_rng *r = rng(33);
  const size_t N = 200, segs = 6;
  const double h = 3;
  lw_splines *sp = lw_init_random(&sc, N, segs, h, r, NULL);
  cr_assert_not_null(sp);
  size_t checked = 0;
  for (size_t i = 0; i < N; i++) {
    const lw_node *nd = &sp->node[sp->first[i]];
    double r0 = hypot(nd[segs / 2].px - 50, nd[segs / 2].py - 50);
    if (r0 < 15) continue; /* near the vortex's centre the steps are too coarse */
    checked++;
    for (size_t k = 0; k <= segs; k++) {
      double dx = nd[k].px - 50, dy = nd[k].py - 50, rk = hypot(dx, dy);
      /* the midpoint rule drifts off a circle by O(h^3 / r^2) per step */
      cr_assert(fabs(rk - r0) < 0.01 * r0, "spline %zu node %zu: radius %g vs %g", i, k, rk, r0);
      double tv = fabs(nd[k].vx * dx + nd[k].vy * dy) / (hypot(nd[k].vx, nd[k].vy) * rk);
      cr_assert(tv < 0.02, "node vector not tangential: %g", tv);
      cr_assert(fabs(hypot(nd[k].vx, nd[k].vy) - h / 3) < 1e-12);
      if (k) cr_assert(fabs(hypot(nd[k].px - nd[k - 1].px, nd[k].py - nd[k - 1].py) - h) < 0.01 * h);
    }
  }
  cr_assert(checked > N / 2, "%zu splines checked", checked);
  lw_splines_free(sp);
  gsl_rng_free(r);
  lw_scene_clear(&sc);
}

Test(placement, coverage_gives_the_spline_count)
{
  lw_params p;
  lw_scene sc;
  two_tone_scene(&p, &sc, 0);
  size_t n;
  cr_assert_eq(lw_init_count(&sc, &p, &n, NULL), LW_OK);
  /* inside area 90 x 90 = 8100 mm^2, counted on cells of 100/1024 mm: off
  ** by at most the perimeter times half a cell (18 mm^2, 1.5 splines) */
  double want = 0.5 * 8100 / (0.3 * 20);
  cr_assert(fabs((double)n - want) <= 2, "%zu splines, want %g", n, want);
  lw_scene_clear(&sc);

  two_tone_scene(&p, &sc, 1);
  /* darkness 1 + (1 - 0.75) on two pixels of 45 x 45 mm, 0.75 as stored
  ** in 8 bits */
  double ink = (2 - lround(0.75 * 255) / 255.0) * 45 * 45;
  cr_assert(fabs(lw_init_ink_area(&sc) - ink) < 1e-3, "%g vs %g", lw_init_ink_area(&sc), ink);
  cr_assert_eq(lw_init_count(&sc, &p, &n, NULL), LW_OK);
  cr_assert_eq(n, (size_t)llround(0.5 * ink / 6));
  p.splines = 17; /* a count given in the file wins */
  p.line[lw_params_find("init", "splines") - lw_param_table] = 3;
  cr_assert_eq(lw_init_count(&sc, &p, &n, NULL), LW_OK);
  cr_assert_eq(n, 17);
  lw_error err;
  p.line[lw_params_find("init", "splines") - lw_param_table] = 0; /* left at its default */
  cr_assert_eq(lw_init_count(&sc, &p, &n, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "init.coverage") && strstr(err.msg, "init.splines = 0"), "%s", err.msg);
  p.splines = 0;
  p.coverage = 0; /* neither: none, as always */
  cr_assert_eq(lw_init_count(&sc, &p, &n, NULL), LW_OK);
  cr_assert_eq(n, 0);
  p.coverage = 100;
  p.pen_width = 1e-6;
  cr_assert_eq(lw_init_count(&sc, &p, &n, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "init.coverage"), "%s", err.msg);
  lw_scene_clear(&sc);
}

Test(placement, field_preview_shows_tone_and_strokes)
{
  lw_params p;
  lw_params_defaults(&p);
  p.width = 60;
  p.height = 40;
  p.margin = 0.001;
  p.field_coef = -1;
  p.field = LW_FLD_ETF;
  p.field_angle = 0; /* a flat picture: the flow is the fallback, horizontal */
  p.field_preview = 1;
  float g[6 * 4];
  for (int k = 0; k < 24; k++) g[k] = 0.5f;
  snprintf(p.image, sizeof p.image, "%s", lw_test_path("flat.png"));
  lw_test_png(p.image, 6, 4, g, NULL);
  lw_scene sc;
  lw_error err;
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_OK, "%s", err.msg);
  const char *path = lw_test_path("field.png");
  cr_assert_eq(lw_fieldview_png(&sc, 4, path, &err), LW_OK, "%s", err.msg);
  cairo_surface_t *s = cairo_image_surface_create_from_png(path);
  cr_assert_eq(cairo_surface_status(s), CAIRO_STATUS_SUCCESS);
  cr_assert(cairo_image_surface_get_width(s) == 240 && cairo_image_surface_get_height(s) == 160);
  const unsigned char *d = cairo_image_surface_get_data(s);
  int stride = cairo_image_surface_get_stride(s);
#define PX(i, j) (((const uint32_t *)(d + (j) * stride))[i])
  /* strokes every mm (60 across), centred on x.5 mm, 0.8 mm long: the
  ** pixel at (30.5, 20.5) mm is on one, (30.5, 21) mm lies between rows */
  uint32_t on = PX(122, 82), off = PX(122, 84);
  cr_assert((on & 0xFF) > ((on >> 16) & 0xFF) + 60, "a blue stroke: %08x", on);
  unsigned want = (unsigned)lround(255 * (0.35 + 0.65 * (128 / 255.0)));
  cr_assert(abs((int)(off & 0xFF) - (int)want) <= 1 && (off & 0xFF) == ((off >> 16) & 0xFF),
            "gray of tone 1/2 between strokes: %08x, want %u", off, want);
#undef PX
  cairo_surface_destroy(s);
  lw_scene_clear(&sc);
}

/* Pairs of pair samples of different splines closer than d, by brute force. */
static size_t close_sample_pairs(const lw_scene *sc, const lw_splines *sp, double d)
{
  size_t ns = 0;
  for (size_t i = 0; i < sp->n_splines; i++) ns += (sp->first[i + 1] - sp->first[i] - 1) * (size_t)sc->pair_quad.n;
  double *x = malloc(ns * sizeof *x), *y = malloc(ns * sizeof *y);
  size_t *own = malloc(ns * sizeof *own), k = 0, close = 0;
  for (size_t i = 0; i < sp->n_splines; i++)
    for (size_t m = 0; m < (sp->first[i + 1] - sp->first[i] - 1); m++) {
      const lw_node *nd = &sp->node[sp->first[i] + m];
      lw_samples s;
      lw_segment_sample(&sc->pair_quad, &nd[0], &nd[1], &s);
      for (int q = 0; q < s.n; q++, k++) {
        x[k] = s.x[q];
        y[k] = s.y[q];
        own[k] = i;
      }
    }
  for (size_t a = 0; a < ns; a++)
    for (size_t b = a + 1; b < ns; b++)
      close += own[a] != own[b] && hypot(x[a] - x[b], y[a] - y[b]) < d;
  free(x);
  free(y);
  free(own);
  return close;
}

/* Pairs of segments of different splines whose curves come within d, by
** brute force. */
static size_t close_curve_pairs(const lw_splines *sp, double d)
{
  size_t close = 0;
  for (size_t i = 0; i < sp->n_splines; i++)
    for (size_t j = i + 1; j < sp->n_splines; j++)
      for (size_t a = 0; a < lw_splines_segments(sp, i); a++)
        for (size_t b = 0; b < lw_splines_segments(sp, j); b++) {
          double ba[8], bb[8];
          lw_splines_bezier(sp, i, a, ba);
          lw_splines_bezier(sp, j, b, bb);
          close += lw_bezier_near2(ba, bb, d) < d * d;
        }
  return close;
}

/* With energy.min_spacing the placement leaves room between splines, which
** the spacing constraint then keeps (it refuses only moves that add close
** samples, so crossings placed at the start would stay).  Random straight
** lines at a density where they cross often, with and without. */
Test(placement, min_spacing_places_lines_apart)
{
  lw_params p;
  lw_scene plain, spaced;
  two_tone_scene(&p, &plain, 0);
  p.pair = 0.01;
  p.pair_cutoff = 1;
  p.min_spacing = 0.5;
  lw_error err;
  cr_assert_eq(lw_scene_init(&spaced, &p, &err), LW_OK, "%s", err.msg);
  /* 1 m of line on 8100 mm^2.  Two 20 mm lines at random cross with
  ** probability 2 L^2 / (pi A) = 0.031: the last line drawn meets 1.6 of the
  ** others on average, so one in five draws is free and 64 draws find one
  ** (at 150 lines only one in a hundred would be, and the fallback rules) */
  const size_t N = 50;
  size_t close[2];
  const lw_scene *scs[2] = {&plain, &spaced};
  for (int k = 0; k < 2; k++) {
    gsl_rng *r = rng(5);
    lw_splines *sp = lw_init_random(scs[k], N, 4, 5, r, &err);
    cr_assert_not_null(sp, "%s", err.msg);
    close[k] = close_sample_pairs(&spaced, sp, p.min_spacing);
    lw_splines_free(sp);
    gsl_rng_free(r);
  }
  /* N^2 / 2 pairs crossing with that probability: about 39 crossings, each
  ** with a few close samples */
  cr_assert_gt(close[0], 39, "without the spacing %zu close pairs", close[0]);
  cr_assert_eq(close[1], 0, "with it %zu close pairs, without %zu", close[1], close[0]);
  lw_scene_clear(&plain);
  lw_scene_clear(&spaced);
}

/* Where the annealer chooses the count (moves.fixed_count = 0) a spline that
** finds no clear room in its draws is cut to the longest run of its best
** draw's segments that is clear, or left out: births and grows can add line
** later, while the spacing rule would keep every contact placed.  At 150
** lines of the test above only one draw in a hundred is clear, so with a
** fixed count the fallback places crowded lines; here none is crowded, the
** cut splines keep the rest length of what is left (n l, as a birth's grows
** give it), and most of the line is still placed. */
Test(placement, a_chosen_count_cuts_crowded_splines_to_their_clear_runs)
{
  lw_params p;
  lw_scene fixed, chosen;
  two_tone_scene(&p, &fixed, 0);
  lw_scene_clear(&fixed);
  p.pair = 0.01;
  p.pair_cutoff = 1;
  p.min_spacing = 0.5;
  lw_error err;
  cr_assert_eq(lw_scene_init(&fixed, &p, &err), LW_OK, "%s", err.msg);
  p.fixed_count = 0;
  cr_assert_eq(lw_scene_init(&chosen, &p, &err), LW_OK, "%s", err.msg);
  const size_t N = 150, S = 4;
  const double l = 5;
  gsl_rng *r = rng(5);
  lw_splines *sp = lw_init_random(&fixed, N, S, l, r, &err);
  gsl_rng_free(r);
  cr_assert_not_null(sp, "%s", err.msg);
  const size_t crowded = close_sample_pairs(&fixed, sp, p.min_spacing);
  cr_assert(sp->n_splines == N && sp->n_segments == N * S && crowded > 0, "fixed: %zu splines, %zu close pairs",
            sp->n_splines, crowded);
  lw_splines_free(sp);
  r = rng(5);
  sp = lw_init_random(&chosen, N, S, l, r, &err);
  gsl_rng_free(r);
  cr_assert_not_null(sp, "%s", err.msg);
  /* the curves too: samples up to 0.92 mm apart (8 Gauss nodes on 5 mm)
  ** against 0.5 let lines cross between them */
  cr_assert_eq(close_curve_pairs(sp, p.min_spacing), 0);
  size_t cut = 0;
  for (size_t i = 0; i < sp->n_splines; i++) {
    const size_t m = lw_splines_segments(sp, i);
    cr_assert(m >= 1 && m <= S && sp->rest_length[i] == (double)m * l, "spline %zu: %zu segments, rest %.17g", i,
              m, sp->rest_length[i]);
    cut += m < S;
  }
  cr_log_info("%zu splines, %zu segments of %zu, %zu cut; %zu close pairs with a fixed count", sp->n_splines,
              sp->n_segments, N * S, cut, crowded);
  cr_assert(cut > 0 && sp->n_splines <= N, "%zu cut of %zu", cut, sp->n_splines);
  cr_assert(sp->n_segments > N * S / 2, "%zu segments of %zu placed", sp->n_segments, N * S);
  lw_splines_free(sp);
  lw_scene_clear(&fixed);
  lw_scene_clear(&chosen);
}
