/*
** test_tone.c -- the tone term (tone.h): its local differences against the
** full recomputation, its raster after many moves, what it draws on a flat
** and a graded picture; the spacing constraint and the close share
** (spacing.h).
*/
#include <criterion/criterion.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>

#include "imageutil.h"
#include "linewise/init.h"
#include "linewise/model.h"
#include "linewise/quench.h"
#include "linewise/sys_splines.h"
#include "linewise/scene.h"
#include "linewise/spacing.h"
#include "linewise/vec2.h"
#include "testutil.h"

TestSuite(tone, .init = lw_image_dir_make, .fini = lw_image_dir_remove);

/* A page of side `page` mm (margin 2) with a w x w picture of tone f(u, v),
** u, v in [0, 1] across it, and the tone term at T with blur sigma. */
static lw_params tone_params(double page, int w, double (*f)(double, double), double T, double sigma)
{
  lw_params p;
  lw_params_defaults(&p);
  p.width = p.height = page;
  p.margin = 2;
  p.tone = T;
  p.tone_blur = sigma;
  p.pen_width = 0.3;
  p.min_speed = 0;
  p.regularity = 0;
  float *g = malloc((size_t)w * (size_t)w * sizeof *g);
  for (int j = 0; j < w; j++)
    for (int i = 0; i < w; i++) g[j * w + i] = (float)f((i + 0.5) / w, (j + 0.5) / w);
  static int k;
  char name[32];
  snprintf(name, sizeof name, "pic%d.png", k++);
  snprintf(p.image, sizeof p.image, "%s", lw_test_path(name));
  lw_test_png(p.image, w, w, g, NULL);
  free(g);
  return p;
}

static double blotches(double u, double v) { return 0.5 + 0.4 * sin(7 * u + 2 * v) * cos(5 * v - 3 * u * u); }
static double grey(double u, double v) { (void)u; (void)v; return 0.7; }
static double ramp(double u, double v) { (void)v; return 1.0 - u; } /* white at the left, black at the right */

/* The tone of a grey 30 mm page (blur 0.9 mm), for the footprint tests. */
static const lw_tone *grey_tone(lw_scene *sc)
{
  lw_params p = tone_params(30, 30, grey, 1.0, 0.9);
  lw_test_scene(sc, &p);
  return &sc->tone;
}


/* A chain over m at temperature T with the default mix. */
static lw_chain *chain_of(lw_model *m, double T, unsigned long seed)
{
  const double w[4] = {0.5, 0.4, 0.05, 0.05}, st[4] = {0.3, 0.3, 0.3, 0.05}, tg[4] = {0.44, 0.44, 0.3, 0.3};
  lw_error err;
  lw_chain *c = model_chain(m, w, st, tg, seed, &err);
  cr_assert_not_null(c, "%s", err.msg);
  c->temperature = T;
  return c;
}

static void anneal(lw_chain *c, double t0, double t1, int sweeps)
{
  for (int s = 0; s < sweeps; s++) {
    c->temperature = t0 * pow(t1 / t0, (double)s / (sweeps - 1));
    c->tuning = s < sweeps / 2;
    cr_assert_eq(lw_chain_sweep(c), LW_OK);
  }
}

Test(tone, a_move_changes_the_energy_by_the_full_recomputation)
{
  /* Random moves of every kind (one point, one vector, a whole spline),
  ** with the other terms on as well: each term's local difference against
  ** two recomputations from scratch, and the running totals after the
  ** accepted half of them. */
  lw_params p = tone_params(40, 50, blotches, 3.0, 0.8);
  p.potential_coef = 0.5;
  p.potential = LW_POT_IMAGE;
  p.bending = 0.3;
  p.pair = 0.02;
  p.pair_cutoff = 2;
  lw_scene sc;
  lw_test_scene(&sc, &p);
  lw_model *m = lw_test_model_random(&sc, 60, 3, 3, 11);
  double term0[LW_TERM_COUNT];
  lw_energy_compute(&sc, m->sp, term0, NULL);
  cr_assert(term0[LW_TERM_TONE] > 0.0);
  cr_assert(lw_test_moves_match_full(&sc, m, 300, 0.7, 12) > 100);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

/* The tone term's energy from the samples of every segment at nodes q,
** splatted by hand. */
static double tone_at_nodes(const lw_scene *sc, const lw_splines *sp, const lw_quad *q)
{
  const lw_tone *t = &sc->tone;
  int64_t *r = lw_tone_raster_new(t);
  cr_assert_not_null(r);
  lw_samples s;
  for (size_t g = 0; g < sp->n_segments; g++) {
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    lw_segment_sample(q, a, a + 1, &s);
    for (int k = 0; k < s.n; k++) lw_tone_splat(t, r, 0, 0, t->w, t->h, s.x[k], s.y[k], s.dl[k], 1);
  }
  const double e = sc->coef[LW_TERM_TONE] * lw_tone_energy(t, r);
  free(r);
  return e;
}

Test(tone, its_own_nodes_sample_the_ink)
{
  /* energy.tone_quadrature = 4 with every other term at 8 nodes: the
  ** running tone term is that of the 4-node samples (and not the 8-node
  ** ones, which differ by more than rounding on splines this coarse), and
  ** each move's local difference still matches the recomputation.  The
  ** key at 1 is refused by name. */
  lw_params p = tone_params(40, 50, blotches, 3.0, 0.8);
  p.tone_quadrature = 4;
  p.bending = 0.3;
  p.pair = 0.02;
  p.pair_cutoff = 2;
  lw_scene sc;
  lw_test_scene(&sc, &p);
  cr_assert_eq(sc.quad.n, 8);
  cr_assert_eq(sc.tone_quad.n, 4);
  lw_model *m = lw_test_model_random(&sc, 60, 3, 3, 11);
  const double own = tone_at_nodes(&sc, m->sp, &sc.tone_quad), eight = tone_at_nodes(&sc, m->sp, &sc.quad);
  cr_assert_eq(m->term[LW_TERM_TONE], own, "running %.17g, 4 nodes by hand %.17g", m->term[LW_TERM_TONE], own);
  cr_assert(fabs(own - eight) > 1e-6 * own, "4 nodes %.17g, 8 nodes %.17g", own, eight);
  cr_assert(lw_test_moves_match_full(&sc, m, 300, 0.7, 12) > 100);
  lw_model_free(m);
  lw_scene_clear(&sc);
  p.tone_quadrature = 1;
  lw_error err;
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "energy.tone_quadrature") && strstr(err.msg, "got 1"), "%s", err.msg);
}

/* A dense scene (twice the ink the picture asks for, lines crossing
** everywhere) on a picture of w pixels a side and 40 sweeps: the running
** total equals the recomputation to 1e-9, and the raster is bit for bit the
** one a fresh model of the final state builds (the fixed-point sums are
** exact), which is what makes a resumed run identical to an unbroken one. */
static void raster_after_sweeps_is_fresh(int w, int k)
{
  lw_params p = tone_params(30, w, blotches, 2.0, 0.7);
  p.strain = 5;
  p.bending = 0.2;
  lw_scene sc;
  lw_test_scene(&sc, &p);
  cr_assert(fabs(sc.tone.pixel - k * sc.image_place.pixel) < 1e-12, "raster pixel %g", sc.tone.pixel);
  lw_model *m = lw_test_model_random(&sc, 300, 3, 2, 21);
  lw_chain *c = chain_of(m, 0.05, 22);
  for (int s = 0; s < 40; s++) cr_assert_eq(lw_chain_sweep(c), LW_OK);
  unsigned long acc = 0;
  for (int q = 0; q < 4; q++) acc += c->stats[q].accepted;
  cr_assert(acc > 10000, "only %lu accepted moves", acc);
  double term[LW_TERM_COUNT];
  lw_energy_compute(&sc, m->sp, term, NULL);
  cr_assert(fabs(m->term[LW_TERM_TONE] - term[LW_TERM_TONE]) <= 1e-9 * fabs(term[LW_TERM_TONE]),
            "running %.17g, recomputed %.17g", m->term[LW_TERM_TONE], term[LW_TERM_TONE]);
  lw_model *fresh = lw_model_new(&sc, lw_splines_clone(m->sp), NULL);
  cr_assert_not_null(fresh);
  cr_assert_eq(memcmp(m->raster[LW_TERM_TONE], fresh->raster[LW_TERM_TONE],
                      (size_t)sc.tone.w * (size_t)sc.tone.h * sizeof(int64_t)), 0);
  cr_assert_eq(fresh->term[LW_TERM_TONE], term[LW_TERM_TONE], "a fresh model sums as the recomputation does");
  lw_model_free(fresh);
  model_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

Test(tone, the_raster_after_many_moves_is_the_one_built_from_scratch)
{
  raster_after_sweeps_is_fresh(40, 1);
  raster_after_sweeps_is_fresh(160, 2);
}

Test(tone, off_it_holds_no_raster)
{
  lw_params p = tone_params(30, 20, grey, 0.0, 1.0);
  p.bending = 1;
  lw_scene sc;
  lw_test_scene(&sc, &p);
  cr_assert_null(sc.tone.dark, "no target is built for a term that is off");
  lw_model *m = lw_test_model_random(&sc, 20, 2, 3, 5);
  lw_proposal *pr = lw_proposal_new(m, NULL);
  lw_node nd = m->sp->node[1];
  nd.px += 0.3;
  lw_model_propose(m, pr, 0, 1, 1, &nd);
  cr_assert_eq(lw_model_commit(m, pr), LW_OK);
  for (int t = 0; t < LW_TERM_COUNT; t++) {
    cr_assert_null(m->raster[t]);
    cr_assert_eq(pr->box[t].cap, 0, "a proposal grows no box");
  }
  cr_assert_eq(m->term[LW_TERM_TONE], 0.0);
  lw_proposal_free(pr);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

Test(tone, a_sample_deposits_its_ink_area)
{
  /* The footprint is normalised per axis: inside the raster a sample adds
  ** pen * dl to sum_p A B_p, up to the rounding of each pixel (2^-32). */
  lw_scene sc;
  const lw_tone *t = grey_tone(&sc);
  int64_t *r = lw_tone_raster_new(t);
  cr_assert_not_null(r);
  rng_seed(3);
  double want = 0.0;
  for (int k = 0; k < 50; k++) {
    double dl = urand(0.1, 0.6);
    lw_tone_splat(t, r, 0, 0, t->w, t->h, urand(4, 26), urand(4, 26), dl, 1);
    want += t->pen * dl;
  }
  double sum = 0.0;
  for (size_t k = 0; k < (size_t)t->w * (size_t)t->h; k++) sum += (double)r[k] / LW_TONE_ONE * t->area;
  size_t px = (size_t)(2 * t->radius + 1) * (size_t)(2 * t->radius + 1);
  cr_assert(fabs(sum - want) <= 50 * px * 0.5 / LW_TONE_ONE * t->area + 1e-12 * want, "deposited %.17g, want %.17g",
            sum, want);
  free(r);
  lw_scene_clear(&sc);
}

/* The footprints' integers are the same at every width the processor
** offers (the eight-lane rows of AVX-512 and the scalar rows): samples all
** over the raster and past its edges, into the whole raster and into a box
** whose rows are not a multiple of eight, added and taken away. */
Test(tone, footprints_are_the_same_integers_at_every_width)
{
  lw_scene sc;
  const lw_tone *t = grey_tone(&sc);
  const int bx = 3, by = 5, bw = t->w - 7, bh = t->h - 9;
  int64_t *r[2], *b[2];
  for (int x8 = 0; x8 < 2; x8++) {
    lw_vec_set_x8(x8);
    r[x8] = lw_tone_raster_new(t);
    b[x8] = calloc((size_t)bw * (size_t)bh, sizeof(int64_t));
    cr_assert(r[x8] && b[x8]);
    rng_seed(11);
    for (int k = 0; k < 400; k++) {
      double x = urand(-3, 33), y = urand(-3, 33), dl = urand(0.05, 0.8);
      int sign = k % 3 ? 1 : -1;
      lw_tone_splat(t, r[x8], 0, 0, t->w, t->h, x, y, dl, sign);
      lw_tone_splat(t, b[x8], bx, by, bw, bh, x, y, dl, sign);
    }
  }
  lw_vec_set_x8(1);
  cr_assert(!memcmp(r[0], r[1], (size_t)t->w * (size_t)t->h * sizeof(int64_t)), "the rasters differ");
  cr_assert(!memcmp(b[0], b[1], (size_t)bw * (size_t)bh * sizeof(int64_t)), "the boxes differ");
  int64_t nonzero = 0;
  for (size_t k = 0; k < (size_t)bw * (size_t)bh; k++) nonzero += b[0][k] != 0;
  cr_assert(nonzero > bw * bh / 2, "the samples cover the box (%lld of %d pixels)", (long long)nonzero, bw * bh);
  for (int x8 = 0; x8 < 2; x8++) free(r[x8]), free(b[x8]);
  lw_scene_clear(&sc);
}

/* A box's energy difference is summed in eight lanes a row (tone.c), so the
** AVX-512 rows and the scalar ones give the same bits, on boxes whose width
** is not a multiple of eight and whose pixels are mostly unchanged; and it
** is the difference of the two rasters' energies.  A lane fold in another
** order, a masked tail that adds garbage, or pixels read from the wrong row
** fails. */
Test(tone, a_box_difference_is_the_same_at_every_width)
{
  lw_scene sc;
  const lw_tone *t = grey_tone(&sc);
  int64_t *r = lw_tone_raster_new(t);
  cr_assert(r);
  rng_seed(17);
  for (int k = 0; k < 300; k++) lw_tone_splat(t, r, 0, 0, t->w, t->h, urand(0, 30), urand(0, 30), urand(0.05, 0.8), 1);
  const double before = lw_tone_energy(t, r);
  int ragged = 0; /* boxes whose width is not a multiple of eight */
  for (int trial = 0; trial < 20; trial++) {
    /* a moved sample: taken away at (x, y), put back nearby */
    double x = urand(2, 28), y = urand(2, 28), dl = urand(0.1, 0.8), x2 = x + urand(-1.5, 1.5), y2 = y + urand(-1, 1);
    lw_tone_splat(t, r, 0, 0, t->w, t->h, x, y, dl, 1);
    const double base = lw_tone_energy(t, r);
    double dE[2];
    lw_tone_box b[2] = {{0}, {0}};
    for (int x8 = 0; x8 < 2; x8++) {
      lw_vec_set_x8(x8);
      lw_tone_box_reset(&b[x8]);
      lw_tone_box_cover(t, &b[x8], fmin(x, x2), fmin(y, y2), fmax(x, x2), fmax(y, y2));
      cr_assert_eq(lw_tone_box_ready(&b[x8]), LW_OK);
      lw_tone_box_splat(t, &b[x8], x, y, dl, -1);
      lw_tone_box_splat(t, &b[x8], x2, y2, dl, 1);
      dE[x8] = lw_tone_delta(t, r, &b[x8]);
    }
    lw_vec_set_x8(1);
    ragged += (b[0].x1 - b[0].x0) % 8 != 0;
    cr_assert(dE[0] == dE[1], "trial %d: scalar %.17g, eight lanes %.17g", trial, dE[0], dE[1]);
    lw_tone_apply(t, r, &b[0]);
    const double after = lw_tone_energy(t, r);
    cr_assert(fabs(dE[0] - (after - base)) <= 1e-9 * fabs(before), "trial %d: dE %.17g, energies differ by %.17g",
              trial, dE[0], after - base);
    lw_tone_box_free(&b[0]);
    lw_tone_box_free(&b[1]);
  }
  cr_assert(ragged > 5, "%d ragged boxes", ragged);
  free(r);
  lw_scene_clear(&sc);
}

/* A white picture with a dark square: pixels [48, 96) x [120, 144) of 240. */
static double dark_square(double u, double v) { return u >= 0.2 && u < 0.4 && v >= 0.5 && v < 0.6 ? 0.25 : 1.0; }

Test(tone, the_raster_is_coarser_than_a_fine_picture_and_keeps_its_target)
{
  /* A 240-pixel picture over 26 mm (0.108 mm a pixel): a blur of sigma
  ** takes raster pixels of k picture pixels, the most within sigma / 1.5
  ** (LW_TONE_SIGMA_PIXELS), here 1, 2, 5 and 7.  The target D, read at
  ** their centres, keeps the square's ink (tone_ink 0.75 times its
  ** darkness, 1 - 64 / 255 in 8 bits, over 5.2 x 2.6 mm) and its centre of
  ** mass: a raster shifted by a pixel, or half of one, would move that by
  ** 0.05 mm or more.  What is left is the blur's truncation at 4 sigma and
  ** the rounding of float. */
  const double sigma[] = {0.2, 0.4, 0.9, 1.2};
  const int want_k[] = {1, 2, 5, 7};
  for (int c = 0; c < 4; c++) {
    lw_params p = tone_params(30, 240, dark_square, 1.0, sigma[c]);
    p.tone_ink = 0.75;
    lw_scene sc;
    lw_test_scene(&sc, &p);
    const lw_tone *t = &sc.tone;
    const double px = sc.image_place.pixel;
    cr_assert(fabs(t->pixel - want_k[c] * px) < 1e-12, "sigma %g: raster pixel %g, picture pixel %g", sigma[c],
              t->pixel, px);
    const double most = sigma[c] / LW_TONE_SIGMA_PIXELS;
    cr_assert(want_k[c] == 1 || (t->pixel <= most && t->pixel > 0.5 * most), "sigma %g: raster pixel %g", sigma[c],
              t->pixel);
    double mass = 0, mx = 0, my = 0;
    for (int j = 0; j < t->h; j++)
      for (int i = 0; i < t->w; i++) {
        double d = t->dark[(size_t)j * (size_t)t->w + (size_t)i] * t->area;
        mass += d;
        mx += d * (t->x0 + (i + 0.5) * t->pixel);
        my += d * (t->y0 + (j + 0.5) * t->pixel);
      }
    const double side = 240 * px, want = 0.75 * (191.0 / 255.0) * (0.2 * side) * (0.1 * side);
    const double cx = sc.image_place.x0 + 0.3 * side, cy = sc.image_place.y0 + 0.55 * side;
    cr_assert(fabs(mass / want - 1) < 1e-5, "sigma %g: ink %.8g, want %.8g", sigma[c], mass, want);
    cr_assert(fabs(mx / mass - cx) < 1e-4 && fabs(my / mass - cy) < 1e-4,
              "sigma %g (k %d): centre (%.6f, %.6f), want (%.6f, %.6f)", sigma[c], want_k[c], mx / mass, my / mass,
              cx, cy);
    lw_scene_clear(&sc);
  }
}

/* Mean and variance of the blurred ink B over the raster pixels at least
** `rim` pixels inside the picture, in a bx x bx grid of blocks: block
** means into bm. */
static void ink_stats(const lw_model *m, int rim, int bx, double *mean, double *var, double *bm, int *block_px)
{
  const lw_tone *t = &m->scene->tone;
  const int64_t *r = m->raster[LW_TERM_TONE];
  int i0 = t->pad + rim, n = t->w - 2 * (t->pad + rim), side = n / bx;
  double s = 0, s2 = 0;
  for (int b = 0; b < bx * bx; b++) bm[b] = 0;
  for (int j = 0; j < side * bx; j++)
    for (int i = 0; i < side * bx; i++) {
      double v = (double)r[(size_t)(i0 + j) * (size_t)t->w + (size_t)(i0 + i)] / LW_TONE_ONE;
      s += v;
      s2 += v * v;
      bm[(j / side) * bx + i / side] += v;
    }
  double N = (double)(side * bx) * (side * bx);
  *mean = s / N;
  *var = s2 / N - *mean * *mean;
  for (int b = 0; b < bx * bx; b++) bm[b] /= (double)side * side;
  *block_px = side * side;
}

Test(tone, a_flat_grey_picture_gets_uniform_ink_at_its_darkness)
{
  /* Tone 0.7 everywhere: darkness D = 0.3.  The lines are free to stretch
  ** (no strain) and start with half the ink D asks for; the tone term
  ** alone decides how much line there is.
  **
  ** Expected ink fraction: B = G * ink cannot be flat (the lines are
  ** lines), and at the minimum the energy cannot fall by scaling all ink
  ** by (1 + e): d/de sum (B(1 + e) - D)^2 = 0 gives mean(B^2) = D mean(B),
  ** so mean(B) = D - var(B) / mean(B), a little below D by the texture's
  ** variance.  Tolerance: the thermal and texture noise of the mean over
  ** the interior, whose B is correlated over the area 4 pi sigma^2 of a
  ** Gaussian-blurred field: n_eff = area / (4 pi sigma^2) independent
  ** values, standard error sqrt(var / n_eff); 4 of them, plus 0.01 for
  ** the scaling argument holding only approximately (stretching lines
  ** moves ink as well as adding it).
  **
  ** Uniform: each of 3 x 3 blocks has the overall mean within 4 standard
  ** errors sqrt(var / n_eff(block)). */
  const double D = 0.3, sigma = 0.8;
  lw_params p = tone_params(30, 40, grey, 20.0, sigma);
  p.bending = 0.3;
  p.boundary_coef = 0.05;
  lw_scene sc;
  lw_test_scene(&sc, &p);
  double area = 26.0 * 26.0, half = 0.5 * D * area / p.pen_width;
  lw_model *m = lw_test_model_random(&sc, (size_t)(half / 6.0), 3, 2, 31);
  lw_chain *c = chain_of(m, 0.01, 32);
  anneal(c, 0.05, 0.0005, 120);
  int rim = (int)ceil(3 * sigma / sc.tone.pixel), bpx;
  double mean, var, bm[9];
  ink_stats(m, rim, 3, &mean, &var, bm, &bpx);
  double cell = 4 * M_PI * sigma * sigma / sc.tone.area; /* pixels per independent value */
  double n_eff = 9.0 * bpx / cell, want = D - var / mean;
  cr_log_info("flat grey: mean ink %.4f (D %.2f, expected %.4f), sd %.4f, blocks of %d px", mean, D, want,
              sqrt(var), bpx);
  cr_assert(fabs(mean - want) <= 4 * sqrt(var / n_eff) + 0.01, "mean ink %g, expected %g (sd %g, n_eff %g)", mean,
            want, sqrt(var), n_eff);
  for (int b = 0; b < 9; b++)
    cr_assert(fabs(bm[b] - mean) <= 4 * sqrt(var * cell / bpx), "block %d: ink %g against the mean %g", b, bm[b],
              mean);
  model_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

/* Share of the line length (at the quadrature samples) over the darkest
** tenth of a ramp picture (its right tenth, x beyond 90 % of it). */
static double darkest_tenth_share(const lw_model *m)
{
  const lw_image_place *pl = &m->scene->image_place;
  double x9 = pl->x0 + 0.9 * m->scene->image->width * pl->pixel, in = 0, all = 0;
  lw_samples s;
  for (size_t g = 0; g < m->sp->n_segments; g++) {
    const lw_node *a = &m->sp->node[lw_segment_node(m->sp, g)];
    lw_segment_sample(&m->scene->quad, a, a + 1, &s);
    for (int q = 0; q < s.n; q++) {
      all += s.dl[q];
      if (s.x[q] > x9) in += s.dl[q];
    }
  }
  return in / all;
}

Test(tone, density_follows_tone_instead_of_piling_into_the_darks)
{
  /* A ramp from white (left) to black (right) and as much line as the
  ** picture's darkness asks for (strain holds the lengths).  Darkness
  ** D(u) = u over u in [0, 1]: ink in proportion to it puts
  ** int_0.9^1 u du / int_0^1 u du = 19 % of the length in the darkest
  ** tenth.  The potential alone (Phi = tone) has its minimum with every
  ** line in the darkest place, and piles them there; the tone term stops
  ** adding ink where the blurred ink reaches the darkness. */
  double share[2];
  for (int with_tone = 0; with_tone < 2; with_tone++) {
    lw_params p = tone_params(30, 40, ramp, with_tone ? 20.0 : 0.0, 0.8);
    if (!with_tone) {
      p.potential = LW_POT_IMAGE;
      p.potential_coef = 1.0;
    }
    p.strain = 20;
    p.bending = 0.3;
    p.boundary_coef = 0.05;
    lw_scene sc;
    lw_test_scene(&sc, &p);
    double ink = 0.5 * 26.0 * 26.0 / p.pen_width; /* mm of line the darkness asks for */
    lw_model *m = lw_test_model_random(&sc, (size_t)(ink / 6.0), 3, 2, 41);
    lw_chain *c = chain_of(m, 0.01, 42);
    anneal(c, 0.05, 0.0005, 100);
    share[with_tone] = darkest_tenth_share(m);
    model_chain_free(c);
    lw_model_free(m);
    lw_scene_clear(&sc);
  }
  cr_log_info("darkest tenth: %.3f of the length with the potential, %.3f with the tone term", share[0], share[1]);
  cr_assert(share[0] > 0.4, "the potential piles lines into the darks: %g", share[0]);
  cr_assert(fabs(share[1] - 0.19) < 0.06, "the tone term follows the ramp: %g of the length in the darkest tenth",
            share[1]);
}

Test(tone, bad_keys_are_named)
{
  lw_params p;
  lw_params_defaults(&p);
  p.tone = 1;
  lw_scene sc;
  lw_error err;
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "energy.tone") && strstr(err.msg, "scene.image"), "%s", err.msg);
  lw_params_defaults(&p);
  p.min_spacing = 0.3;
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "energy.min_spacing") && strstr(err.msg, "energy.pair"), "%s", err.msg);
  p.pair = 1;
  p.pair_cutoff = 0.2;
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "energy.min_spacing") && strstr(err.msg, "pair_cutoff"), "%s", err.msg);
  p = tone_params(30, 20, grey, 1.0, 2000.0);
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "energy.tone_blur"), "%s", err.msg);
}

/* Points of the strokes, each with its spline. */
typedef struct {
  double *x, *y;
  uint32_t *owner;
  size_t n;
} stroke_points;

static stroke_points stroke_points_new(size_t n)
{
  stroke_points p = {malloc(n * sizeof *p.x), malloc(n * sizeof *p.y), malloc(n * sizeof *p.owner), n};
  cr_assert(p.x && p.y && p.owner);
  return p;
}

/* The pairs of points of different splines closer than d (brute force);
** frees the points. */
static size_t stroke_points_closer(stroke_points *p, double d)
{
  size_t count = 0;
  for (size_t i = 0; i < p->n; i++)
    for (size_t j = i + 1; j < p->n; j++) {
      double dx = p->x[i] - p->x[j], dy = p->y[i] - p->y[j];
      count += p->owner[i] != p->owner[j] && dx * dx + dy * dy < d * d;
    }
  free(p->x);
  free(p->y);
  free(p->owner);
  return count;
}

static size_t close_pairs(const lw_scene *sc, const lw_splines *sp, double d)
{
  stroke_points p = stroke_points_new(sp->n_segments * (size_t)sc->pair_quad.n);
  lw_samples s;
  for (size_t g = 0, k = 0; g < sp->n_segments; g++) {
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    lw_segment_sample(&sc->pair_quad, a, a + 1, &s);
    for (int q = 0; q < s.n; q++, k++) {
      p.x[k] = s.x[q];
      p.y[k] = s.y[q];
      p.owner[k] = sp->seg_spline[g];
    }
  }
  return stroke_points_closer(&p, d);
}

/* Rows of straight strokes 0.45 mm apart (3 strokes of 6 mm a row, 1.5 mm
** gaps): crowded, but no pair of samples of different strokes closer than
** 0.3 mm (at 8 pair nodes on 2 mm segments the samples along a row are at
** most 0.4 mm apart; across rows 0.45 mm). */
/* The pairs of points of different splines closer than d, the curves drawn
** at 32 points a segment (0.06 mm apart on these 2 mm segments): the
** distance of the curves themselves, between the pair samples too. */
static size_t close_curve_points(const lw_splines *sp, double d)
{
  enum { PER = 32 };
  stroke_points p = stroke_points_new(sp->n_segments * PER);
  for (size_t g = 0, k = 0; g < sp->n_segments; g++) {
    double c[8];
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    lw_segment_bezier(a, a + 1, c);
    for (int q = 0; q < PER; q++, k++) {
      double t = (q + 0.5) / PER, u = 1 - t;
      double w[4] = {u * u * u, 3 * u * u * t, 3 * u * t * t, t * t * t};
      p.x[k] = w[0] * c[0] + w[1] * c[2] + w[2] * c[4] + w[3] * c[6];
      p.y[k] = w[0] * c[1] + w[1] * c[3] + w[2] * c[5] + w[3] * c[7];
      p.owner[k] = sp->seg_spline[g];
    }
  }
  return stroke_points_closer(&p, d);
}

static lw_splines *rows(int n_rows)
{
  size_t n = 3 * (size_t)n_rows, segs[256];
  for (size_t i = 0; i < n; i++) segs[i] = 3;
  lw_splines *sp = lw_splines_new(n, segs, NULL);
  for (size_t i = 0; i < n; i++) {
    double x = 4.5 + 7.5 * (double)(i % 3), y = 4.5 + 0.45 * (double)(i / 3);
    lw_test_straight(sp, i, x, y, x + 6, y);
  }
  return sp;
}

/* Darker blotches whose tone term pulls strokes together, with the spacing
** rule at 0.3 mm on or off. */
static void spacing_scene(lw_scene *sc, int on)
{
  lw_params p = tone_params(30, 30, blotches, 20.0, 0.8);
  p.pair = 0.001;
  p.pair_cutoff = 1.0;
  p.min_spacing = on ? 0.3 : 0.0;
  p.strain = 10;
  p.bending = 0.3;
  lw_test_scene(sc, &p);
}

Test(tone, the_spacing_constraint_holds_once_kept)
{
  /* From a crowded layout that keeps 0.3 mm, the tone term of a picture
  ** with darker blotches pulls strokes together: without the constraint
  ** pairs come closer than 0.3 mm within a few sweeps, with it none ever
  ** does (checked from scratch after every sweep). */
  size_t worst[2] = {0, 0}, curves[2] = {0, 0};
  unsigned long accepted = 0, crowded[2] = {0, 0};
  for (int on = 0; on < 2; on++) {
    lw_scene sc;
    spacing_scene(&sc, on);
    lw_splines *sp = rows(40);
    cr_assert_eq(close_pairs(&sc, sp, 0.3), 0, "the start keeps the spacing");
    lw_model *m = lw_model_new(&sc, sp, NULL);
    cr_assert_not_null(m);
    lw_chain *c = chain_of(m, 0.02, 52);
    for (int s = 0; s < 20; s++) {
      cr_assert_eq(lw_chain_sweep(c), LW_OK);
      size_t k = close_pairs(&sc, m->sp, 0.3);
      if (k > worst[on]) worst[on] = k;
      /* and the curves between the samples (points at most 0.03 mm from
      ** the nearest: 0.04 mm below the spacing is closer for certain),
      ** every fourth sweep (the count is quadratic) */
      const size_t kc = on && s % 4 == 3 ? close_curve_points(m->sp, 0.3 - 0.04) : 0;
      if (kc > curves[on]) curves[on] = kc;
    }
    for (int k = 0; k < 4; k++) {
      if (on) accepted += c->stats[k].accepted;
      crowded[on] += c->stats[k].crowded;
    }
    model_chain_free(c);
    lw_model_free(m);
    lw_scene_clear(&sc);
  }
  cr_log_info("spacing: up to %zu pairs closer than 0.3 mm without the constraint, %zu (%zu points of the "
              "curves) with it",
              worst[0], worst[1], curves[1]);
  cr_assert(worst[0] > 0, "the tone term pulls strokes together when nothing stops it");
  cr_assert_eq(worst[1], 0, "%zu pairs closer than min_spacing", worst[1]);
  cr_assert_eq(curves[1], 0, "%zu points of the curves closer than min_spacing", curves[1]);
  cr_assert(accepted > 1000, "the chain kept moving: %lu accepted", accepted);
  /* the refusals are counted as such (summary.json, rejected_crowded), and
  ** only where the rule is on */
  cr_assert_eq(crowded[0], 0, "%lu counted crowded without the rule", crowded[0]);
  cr_assert(crowded[1] > 0, "no refusal of the rule was counted");
}

/* The quench (quench.h) keeps the spacing rule too: on the same crowded rows
** and blotches, quenched without the rule it brings strokes closer than
** 0.3 mm; with it, the segments a step would bring closer are held, and
** neither a pair of samples nor the curves between them (model.h,
** lw_model_segment_crowds) come closer at the end while the energy still
** falls. */
Test(tone, the_quench_keeps_the_spacing)
{
  size_t close[2], curves[2];
  double removed[2];
  for (int on = 0; on < 2; on++) {
    lw_scene sc;
    spacing_scene(&sc, on);
    lw_error err = {0};
    lw_splines *start = rows(16);
    cr_assert_eq(close_curve_points(start, 0.3 - 0.04), 0, "the start keeps the spacing between samples too");
    lw_model *m = lw_model_new(&sc, start, &err);
    cr_assert_not_null(m, "%s", err.msg);
    lw_system *sys = lw_splines_view(m, &err);
    cr_assert_not_null(sys, "%s", err.msg);
    const lw_quench_opts o = {1e-9, 100, 0.0, NULL, NULL};
    lw_quench_report r;
    cr_assert_eq(lw_quench_run(sys, &o, &r, &err), LW_OK, "%s", err.msg);
    close[on] = close_pairs(&sc, m->sp, 0.3);
    curves[on] = close_curve_points(m->sp, 0.3 - 0.04);
    removed[on] = r.energy_before - r.energy_after;
    cr_log_info("quench, spacing %s: %g removed in %ld iterations, %ld held, %zu close pairs, %zu close curve points",
                on ? "on" : "off", removed[on], r.iterations, r.holds, close[on], curves[on]);
    lw_system_free(sys);
    lw_model_free(m);
    lw_scene_clear(&sc);
  }
  cr_assert(close[0] > 0, "the quench brings strokes together when nothing stops it: the test tests nothing");
  cr_assert_eq(close[1], 0, "%zu pairs closer than min_spacing after the quench", close[1]);
  /* and the curves between the samples: 0.04 mm below min_spacing is
  ** closer for certain (the points are at most 0.03 mm from the nearest) */
  cr_assert_eq(curves[1], 0, "%zu points of the curves closer than min_spacing after the quench", curves[1]);
  cr_assert(removed[1] > 0.2 * removed[0], "held too much: %g removed, against %g without the rule", removed[1],
            removed[0]);
}

/* A hold round after the first asks only the segments beside the new
** holds (system.h, `changed`): the others were allowed and every curve now
** moves less.  On the crowded rows (lines 0.45 apart, spacing 0.3), a step
** down the gradient whose longest move is 6 mm holds more in later rounds
** (the neighbours of held segments, half moved), and each round asking
** only beside the new holds holds what asking every segment holds. */
Test(tone, later_hold_rounds_ask_only_beside_the_new_holds)
{
  lw_scene sc;
  spacing_scene(&sc, 1);
  /* the spacing rule's rounds alone: a 6 mm step stretches segments past the
  ** pair term's sample gaps (its cutoff is 1 mm), which held them all in the
  ** first round */
  sc.pair_gap_max = 0.0;
  lw_error err = {0};
  lw_model *m = lw_model_new(&sc, rows(16), &err);
  cr_assert_not_null(m, "%s", err.msg);
  lw_system *sys = lw_splines_view(m, &err);
  cr_assert_not_null(sys, "%s", err.msg);
  const lw_system_type *t = sys->type;
  const size_t n = t->n_coords(sys->state);
  double *x = malloc(n * sizeof *x), *x1 = malloc(n * sizeof *x1);
  unsigned char *held = calloc(n, 1), *all = calloc(n, 1), *changed = calloc(n, 1);
  t->get_coords(sys->state, x);
  double *g = malloc(n * sizeof *g), gmax = 0;
  cr_assert(isfinite(t->gradient(sys->state, g, &err)), "%s", err.msg);
  for (size_t i = 0; i < n; i++) gmax = fmax(gmax, fabs(g[i]));
  for (size_t i = 0; i < n; i++) x1[i] = x[i] - 6.0 * g[i] / gmax;
  size_t parts = t->blocked(sys->state, x1, held, NULL), later = 0;
  cr_assert(parts > 0, "nothing met a wall: the test tests nothing");
  for (int r = 1; parts && r < 20; r++) {
    for (size_t i = 0; i < n; i++) {
      changed[i] = held[i] && x1[i] != x[i];
      if (held[i]) x1[i] = x[i];
    }
    memcpy(all, held, n);
    parts = t->blocked(sys->state, x1, held, changed);
    size_t every = t->blocked(sys->state, x1, all, NULL);
    cr_assert_eq(parts, every, "round %d: %zu parts asking beside the holds, %zu asking all", r, parts, every);
    cr_assert(!memcmp(held, all, n), "round %d: other parts held", r);
    later += parts;
  }
  cr_log_info("hold rounds: %zu parts after the first round", later);
  cr_assert(later > 0, "no later round held anything: the test tests nothing");
  cr_assert_eq(parts, 0);
  free(x), free(x1), free(g), free(held), free(all), free(changed);
  lw_system_free(sys);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

Test(tone, a_crowded_start_only_gets_less_crowded)
{
  /* A random placement breaks the spacing everywhere; no move may add a
  ** pair too close, so the count never grows from sweep to sweep, and the
  ** pair repulsion lowers it. */
  lw_params p = tone_params(30, 30, blotches, 5.0, 0.8);
  p.pair = 0.05;
  p.pair_cutoff = 1.5;
  p.min_spacing = 0.3;
  p.strain = 10;
  p.bending = 0.3;
  lw_scene sc;
  lw_test_scene(&sc, &p);
  lw_model *m = lw_test_model_random(&sc, 120, 3, 2, 51);
  size_t before = close_pairs(&sc, m->sp, 0.3), now = before;
  cr_assert(before > 20, "the start is crowded: %zu pairs", before);
  lw_chain *c = chain_of(m, 0.02, 52);
  for (int s = 0; s < 20; s++) {
    cr_assert_eq(lw_chain_sweep(c), LW_OK);
    size_t k = close_pairs(&sc, m->sp, 0.3);
    cr_assert(k <= now, "sweep %d: %zu pairs too close after %zu", s, k, now);
    now = k;
  }
  cr_log_info("spacing: %zu pairs too close at the start, %zu after 20 sweeps", before, now);
  cr_assert(now < before / 2, "%zu of %zu pairs still too close", now, before);
  model_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

/* Point of the cubic Bezier c at t. */
static void bezier_point(const double c[8], double t, double *x, double *y)
{
  const double u = 1.0 - t, w0 = u * u * u, w1 = 3 * u * u * t, w2 = 3 * u * t * t, w3 = t * t * t;
  *x = w0 * c[0] + w1 * c[2] + w2 * c[4] + w3 * c[6];
  *y = w0 * c[1] + w1 * c[3] + w2 * c[5] + w3 * c[7];
}

/* lw_bezier_near2 (the spacing rule between curves) against brute force:
** 1500 pairs of segments 2.8 mm long crossing a disc of 1.6 mm at random
** angles, their handles off the chord by up to 0.05 to 0.3 of its length
** (gentle to strong bends), each against its least distance on a grid of
** N + 1 parameters a side.  The grid's points lie at most half a step
** from any point of a curve, a step at most 3 (longest leg) / N along it,
** which bounds the grid's error e.  Where the reference is more than e
** from d = 0.35 the answer must agree on "within d", and every distance
** returned is a distance between two points of the curves, so no less
** than the grid's least less e and, the search being local from the
** nearest points of the polygons, at most 0.02 mm above it. */
static double longest_leg(const double c[8])
{
  return fmax(hypot(c[2] - c[0], c[3] - c[1]), fmax(hypot(c[4] - c[2], c[5] - c[3]), hypot(c[6] - c[4], c[7] - c[5])));
}

Test(tone, the_curves_distance_agrees_with_brute_force)
{
  enum { N = 300 };
  const double d = 0.35;
  rng_seed(17);
  int checked = 0, off = 0;
  static double xa[N + 1], ya[N + 1], xb[N + 1], yb[N + 1];
  for (int n = 0; n < 1500; n++) {
    const double bend = 0.05 + 0.25 * (n % 6) / 5.0;
    double c[2][8];
    for (int k = 0; k < 2; k++) {
      const double x0 = urand(-0.8, 0.8), y0 = urand(-0.8, 0.8), th = urand(-M_PI, M_PI), L = 2.8;
      const double dx = cos(th) * L, dy = sin(th) * L;
      double *z = c[k];
      z[0] = x0 - dx / 2, z[1] = y0 - dy / 2, z[6] = x0 + dx / 2, z[7] = y0 + dy / 2;
      z[2] = z[0] + dx / 3 + urand(-bend, bend) * L, z[3] = z[1] + dy / 3 + urand(-bend, bend) * L;
      z[4] = z[6] - dx / 3 + urand(-bend, bend) * L, z[5] = z[7] - dy / 3 + urand(-bend, bend) * L;
    }
    double ref = INFINITY;
    for (int i = 0; i <= N; i++) {
      bezier_point(c[0], (double)i / N, &xa[i], &ya[i]);
      bezier_point(c[1], (double)i / N, &xb[i], &yb[i]);
    }
    for (int i = 0; i <= N; i++)
      for (int j = 0; j <= N; j++) {
        const double dx = xa[i] - xb[j], dy = ya[i] - yb[j];
        ref = fmin(ref, dx * dx + dy * dy);
      }
    ref = sqrt(ref);
    const double e = 1.5 * (longest_leg(c[0]) + longest_leg(c[1])) / N;
    const double got2 = lw_bezier_near2(c[0], c[1], d), got = sqrt(got2);
    if (fabs(ref - d) > e) {
      cr_assert_eq(got2 < d * d, ref < d, "pair %d: %g against %g", n, got, ref);
      checked++;
    }
    if (got2 < INFINITY) {
      cr_assert(got >= ref - e && got <= ref + 0.02, "pair %d: %g against %g (grid error %g)", n, got, ref, e);
      off += got > ref + 1e-3;
    }
  }
  cr_log_info("curves' distance: %d decisions checked, %d distances more than 1e-3 mm above the grid's", checked, off);
  cr_assert(checked > 1400 && off < 15, "%d checked, %d off", checked, off);
  /* known layouts: parallel lines 0.2 apart, crossing lines, lines 0.5 apart */
  const double par[2][8] = {{0, 0, 1, 0, 2, 0, 3, 0}, {0.5, 0.2, 1.5, 0.2, 2.5, 0.2, 3.5, 0.2}};
  const double parallel = lw_bezier_near2(par[0], par[1], d);
  cr_assert(fabs(parallel - 0.04) < 1e-12, "parallel: %g", parallel);
  const double cross[8] = {1.5, -1, 1.5, 0, 1.5, 1, 1.5, 2};
  cr_assert(lw_bezier_near2(par[0], cross, d) < 1e-20, "crossing: %g", lw_bezier_near2(par[0], cross, d));
  const double apart[8] = {0, 0.5, 1, 0.5, 2, 0.5, 3, 0.5};
  cr_assert_eq(lw_bezier_near2(par[0], apart, d), INFINITY);
}

Test(tone, close_share_of_known_layouts)
{
  /* Straight strokes 20 mm long: parallel at 0.2 mm are close over their
  ** whole length, at 0.4 mm not at all, with pen 0.3; two crossing at right
  ** angles are close where |s| < 0.3 from the crossing, 0.6 mm of each
  ** 20 mm (the points are d / 2 apart: the band is resolved to d / 2). */
  const double d = 0.3;
  const double gap[2] = {0.2, 0.4}, want[2] = {1.0, 0.0};
  for (int k = 0; k < 2; k++) {
    size_t segs[2] = {4, 4};
    lw_splines *sp = lw_splines_new(2, segs, NULL);
    lw_test_straight(sp, 0, 10, 10, 30, 10);
    lw_test_straight(sp, 1, 10, 10 + gap[k], 30, 10 + gap[k]);
    double share;
    cr_assert_eq(lw_close_share_splines(sp, d, &share, NULL), LW_OK);
    cr_assert(fabs(share - want[k]) < 1e-12, "gap %g: share %g", gap[k], share);
    lw_splines_free(sp);
  }
  size_t segs[2] = {4, 4};
  lw_splines *sp = lw_splines_new(2, segs, NULL);
  lw_test_straight(sp, 0, 10, 20, 30, 20);
  lw_test_straight(sp, 1, 20.013, 10, 20.013, 30);
  double share;
  cr_assert_eq(lw_close_share_splines(sp, d, &share, NULL), LW_OK);
  cr_assert(fabs(share - 0.6 / 20) <= 0.5 * d / 20, "crossing: share %g, want %g", share, 0.6 / 20);
  lw_splines_free(sp);
}

/* The close share against every pair of its points: random curved
** segments, strokes of three, packed tight enough that much of the line is
** close, and one stroke far off, so that the cells grow past the pen width
** (no more cells than points).  The points are the documented
** ones (FORMATS.md): k = ceil(control polygon / (d / 2)) pieces of equal
** parameter, each its midpoint with the length |r'| / k. */
Test(tone, close_share_equals_a_search_of_every_pair)
{
  enum { SEGS = 300 };
  const double d = 0.35;
  static double b[8 * SEGS];
  static size_t owner[SEGS], group[SEGS];
  unsigned long r = 12345;
  for (int g = 0; g < SEGS; g++) {
    double x = 0, y = 0;
    for (int k = 0; k < 8; k += 2) {
      /* a stroke of 3 segments every 3, in one of two pens */
      r = r * 6364136223846793005UL + 1442695040888963407UL;
      double u = (double)(r >> 11) / 9007199254740992.0;
      r = r * 6364136223846793005UL + 1442695040888963407UL;
      double v = (double)(r >> 11) / 9007199254740992.0;
      if (k == 0) x = (g % 3 && g) ? b[8 * (g - 1) + 6] : 60.0 * u, y = (g % 3 && g) ? b[8 * (g - 1) + 7] : 8.0 * v;
      if (k == 0 && g == SEGS - 3) x = 3000.0; /* a stroke far off: the grid's box grows */
      else x += 3.0 * (u - 0.3), y += 1.0 * (v - 0.5);
      b[8 * g + k] = x;
      b[8 * g + k + 1] = y;
    }
    owner[g] = (size_t)g / 3;
    group[g] = ((size_t)g / 3) % 2;
  }
  for (int grouped = 0; grouped < 2; grouped++) {
    double share;
    cr_assert_eq(lw_close_share(b, owner, grouped ? group : NULL, SEGS, d, &share, NULL), LW_OK);
    /* every point against every point */
    static double px[SEGS * 64], py[SEGS * 64], len[SEGS * 64];
    static size_t who[SEGS * 64], grp[SEGS * 64];
    size_t n = 0;
    for (int g = 0; g < SEGS; g++) {
      const double *z = b + 8 * g;
      double poly = hypot(z[2] - z[0], z[3] - z[1]) + hypot(z[4] - z[2], z[5] - z[3]) + hypot(z[6] - z[4], z[7] - z[5]);
      size_t k = (size_t)ceil(poly / (0.5 * d));
      cr_assert(k >= 1 && k <= 64);
      for (size_t q = 0; q < k; q++, n++) {
        double t = ((double)q + 0.5) / (double)k, u = 1.0 - t;
        px[n] = u * u * u * z[0] + 3 * u * u * t * z[2] + 3 * u * t * t * z[4] + t * t * t * z[6];
        py[n] = u * u * u * z[1] + 3 * u * u * t * z[3] + 3 * u * t * t * z[5] + t * t * t * z[7];
        double dx = 3 * u * u * (z[2] - z[0]) + 6 * u * t * (z[4] - z[2]) + 3 * t * t * (z[6] - z[4]);
        double dy = 3 * u * u * (z[3] - z[1]) + 6 * u * t * (z[5] - z[3]) + 3 * t * t * (z[7] - z[5]);
        len[n] = (float)(hypot(dx, dy) / (double)k);
        who[n] = owner[g];
        grp[n] = grouped ? group[g] : 0;
      }
    }
    double close = 0.0, all = 0.0;
    for (size_t p = 0; p < n; p++) {
      int found = 0;
      for (size_t o = 0; o < n && !found; o++)
        found = who[o] != who[p] && grp[o] == grp[p] && (px[o] - px[p]) * (px[o] - px[p]) +
                (py[o] - py[p]) * (py[o] - py[p]) < d * d;
      all += len[p];
      if (found) close += len[p];
    }
    cr_assert(close > 0.1 * all && close < 0.9 * all, "a layout that tests little: %g of %g", close, all);
    cr_assert(fabs(share - close / all) < 1e-12, "grouped %d: %.17g against every pair's %.17g", grouped, share,
              close / all);
  }
}

Test(tone, runs_resume_and_thread_counts_give_the_same_bytes)
{
  /* Through the binary: a scene with the tone term and the spacing
  ** constraint, two replicas.  On 1 and 2 threads, and stopped halfway and
  ** resumed, the run ends with the same state.lw (the raster is rebuilt on
  ** resume: its exact sums make that invisible), and summary.json has the
  ** close share. */
  const char *b = getenv("LW_BIN");
  cr_assert_not_null(b, "LW_BIN must name bin/linewise (make test sets it)");
  lw_params p = tone_params(30, 30, blotches, 5.0, 0.8); /* writes the picture */
  FILE *f = fopen(lw_test_path("s.ini"), "w");
  cr_assert_not_null(f);
  fprintf(f, "[scene]\nwidth = 30\nheight = 30\nmargin = 2\nimage = %s\n"
             "[init]\nsplines = 40\nsegments = 3\nsegment_length = 2\n"
             "[energy]\ntone = 5\ntone_blur = 0.8\nstrain = 10\nbending = 0.3\npair = 0.05\npair_cutoff = 1.5\n"
             "min_spacing = 0.3\nboundary = 0.1\n"
             "[anneal]\nsweeps = 12\nsteps = 3\nt_start = 0.05\nt_end = 0.005\nseed = 9\n"
             "[tempering]\nreplicas = 2\nt_max = 0.1\n"
             "[output]\npen_width = 0.3\ncheckpoint_every = 3\n",
          strrchr(p.image, '/') + 1);
  fclose(f);
  const char *dir = lw_test_dir;
  cr_assert_eq(lw_test_sh("%s run %s/s.ini --out %s/a --threads 1 --quiet", b, dir, dir), 0);
  cr_assert_eq(lw_test_sh("%s run %s/s.ini --out %s/b --threads 2 --quiet", b, dir, dir), 0);
  cr_assert_eq(lw_test_sh("%s run %s/s.ini --out %s/c --stop-at 6 --quiet && %s resume %s/c --quiet", b, dir, dir,
                          b, dir),
               0);
  cr_assert_eq(lw_test_sh("cmp -s %s/a/state.lw %s/b/state.lw", dir, dir), 0, "1 and 2 threads differ");
  cr_assert_eq(lw_test_sh("cmp -s %s/a/state.lw %s/c/state.lw", dir, dir), 0, "the resumed run differs");
  cr_assert_eq(lw_test_sh("cmp -s %s/a/trace.csv %s/c/trace.csv", dir, dir), 0, "the resumed trace differs");
  cr_assert_eq(lw_test_sh("grep -q '\"close_share\": 0' %s/a/summary.json && grep -q '\"tone\":' %s/a/summary.json",
                          dir, dir),
               0, "summary.json names the tone term and the close share");
}

/* energy.tone_ink scales the target: black asks for that share of ink, so
** every pixel of the target is exactly tone_ink times the full one (halving
** is exact in floating point). */
Test(tone, tone_ink_scales_the_target)
{
  lw_params p = tone_params(30, 20, grey, 1.0, 1.0), q = p;
  q.tone_ink = 0.5;
  lw_scene a, b;
  lw_test_scene(&a, &p);
  lw_test_scene(&b, &q);
  cr_assert(a.tone.w == b.tone.w && a.tone.h == b.tone.h);
  double most = 0.0;
  for (size_t k = 0; k < (size_t)a.tone.w * (size_t)a.tone.h; k++) {
    cr_assert_eq(b.tone.dark[k], 0.5f * a.tone.dark[k], "pixel %zu: %g against %g", k, b.tone.dark[k],
                 a.tone.dark[k]);
    if (a.tone.dark[k] > most) most = a.tone.dark[k];
  }
  cr_assert(most > 0.25, "the target has no ink to scale (%g)", most);
  lw_scene_clear(&a);
  lw_scene_clear(&b);
}
