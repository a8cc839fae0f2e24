/*
** test_layers.c -- hatching layers and colour pens (layers.h): the local
** differences of layered terms against the full recomputation, a single
** whole-range layer that is the scene without layers, layers that follow
** their own fields, the colour separation against pictures mixed from
** known pen coverages, the drawing's pens and the previews' colour, and
** bad [layers] keys on the command line.
*/
#include <cairo.h>
#include <criterion/criterion.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include "imageutil.h"
#include "linewise/gradient.h"
#include "linewise/init.h"
#include "linewise/layers.h"
#include "linewise/model.h"
#include "linewise/output.h"
#include "linewise/scene.h"
#include "linewise/spacing.h"
#include "linewise/state.h"
#include "testutil.h"

TestSuite(layers, .init = lw_image_dir_make, .fini = lw_image_dir_remove);

/* A w x h RGB picture, colour f(u, v, rgb) with u, v in [0, 1] across it. */
static void write_colour_png(const char *path, int w, int h, void (*f)(double, double, double *))
{
  cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
  unsigned char *d = cairo_image_surface_get_data(s);
  int stride = cairo_image_surface_get_stride(s);
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      double c[3];
      f((i + 0.5) / w, (j + 0.5) / h, c);
      uint32_t px = 0;
      for (int k = 0; k < 3; k++) px = px << 8 | (uint32_t)lround(255.0 * c[k]);
      *(uint32_t *)(d + (size_t)j * (size_t)stride + 4 * (size_t)i) = px;
    }
  cairo_surface_mark_dirty(s);
  cr_assert_eq(cairo_surface_write_to_png(s, path), CAIRO_STATUS_SUCCESS);
  cairo_surface_destroy(s);
}

static void blotch_colours(double u, double v, double *c)
{
  c[0] = 0.5 + 0.4 * sin(7 * u + 2 * v);
  c[1] = 0.5 + 0.4 * cos(5 * v - 3 * u * u);
  c[2] = 0.6 + 0.3 * sin(4 * u * v + 1);
}

static void cyan_yellow(double u, double v, double *c)
{
  (void)v;
  c[0] = 0.0;
  c[1] = 1.0;
  c[2] = u < 0.5 ? 1.0 : 0.0;
  if (u >= 0.5) c[0] = 1.0;
}

/* A page of side `page` mm (margin 2) with a colour picture. */
static lw_params colour_params(double page, int w, void (*f)(double, double, double *))
{
  lw_params p;
  lw_params_defaults(&p);
  p.width = p.height = page;
  p.margin = 2;
  p.pen_width = 0.3;
  p.min_speed = 0;
  p.regularity = 0;
  static int k;
  char name[32];
  snprintf(name, sizeof name, "col%d.png", k++);
  snprintf(p.image, sizeof p.image, "%s", lw_test_path(name));
  write_colour_png(p.image, w, w, f);
  return p;
}


/* Three pens of a palette over blotches of colour, each with its own tone
** raster, image potential and field turned by 0, 60 and 120 degrees. */
static lw_params three_pens(void)
{
  lw_params p = colour_params(40, 40, blotch_colours);
  snprintf(p.ly_names, sizeof p.ly_names, "a b c");
  p.ly_source = LW_LSRC_PALETTE;
  snprintf(p.ly_colors, sizeof p.ly_colors, "#20a0c0 #c02060 #e0c020");
  snprintf(p.ly_turn, sizeof p.ly_turn, "0 60 120");
  snprintf(p.ly_pen_width, sizeof p.ly_pen_width, "0.3 0.5 0.4");
  p.tone = 3;
  p.tone_blur = 0.8;
  p.potential = LW_POT_IMAGE;
  p.potential_coef = 0.5;
  p.field = LW_FLD_ETF;
  p.field_coef = -0.7;
  p.bending = 0.3;
  return p;
}

Test(layers, a_move_changes_the_energy_by_the_full_recomputation)
{
  /* Three pens of a palette, each with its own tone raster, potential and
  ** turned field, and the pair term across them: every term's local
  ** difference against the recomputation, and the running totals after
  ** the accepted half of the moves. */
  lw_params p = three_pens();
  p.pair = 0.02;
  p.pair_cutoff = 2;
  lw_scene sc;
  lw_test_scene(&sc, &p);
  cr_assert_eq(sc.layers.n, 3);
  lw_model *m = lw_test_model_random(&sc, 45, 3, 3, 11);
  double term0[LW_TERM_COUNT];
  lw_energy_compute(&sc, m->sp, term0, NULL);
  cr_assert(term0[LW_TERM_TONE] > 0.0 && term0[LW_TERM_FIELD] != 0.0);
  int checked = lw_test_moves_match_full(&sc, m, 240, 0.7, 12);
  cr_assert(checked > 100, "only %d finite moves", checked);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

/* sp without its splines i where dead[i], and with the n nodes nd of
** rest length `rest` in layer `layer` appended when n > 0. */
static lw_splines *spliced(const lw_splines *sp, const unsigned char *dead, const lw_node *nd, size_t n,
                           double rest, int layer)
{
  lw_splines *c = lw_splines_clone(sp);
  cr_assert_not_null(c);
  lw_splines_compact(c, dead);
  if (n) cr_assert_eq(lw_splines_append(c, nd, n, rest, layer), LW_OK);
  return c;
}

/* The drift checks renumber the splines along a curve of the page (every
** anneal.check_every sweeps).  With a fixed count a spline's layer came
** from its index, so a renumbering moved splines into other layers: their
** field, potential and tone target changed and the energy jumped (here
** from 1152 to 1360).  A layer is state now, so renumbering keeps every spline's
** layer and the energy. */
Test(layers, renumbering_keeps_every_splines_layer_and_the_energy)
{
  lw_params p = three_pens();
  lw_scene sc;
  lw_test_scene(&sc, &p);
  lw_model *m = lw_test_model_random(&sc, 45, 3, 3, 11);
  const size_t n = m->sp->n_splines;
  double *x0 = malloc(n * sizeof *x0);
  int *layer = malloc(n * sizeof *layer);
  cr_assert(x0 && layer);
  for (size_t i = 0; i < n; i++) {
    x0[i] = m->sp->node[m->sp->first[i]].px;
    layer[i] = lw_splines_layer(&sc.layers, m->sp, i);
  }
  double term[LW_TERM_COUNT], e0 = lw_energy_compute(&sc, m->sp, term, NULL);
  lw_error err;
  lw_system *sys = lw_splines_view(m, &err);
  cr_assert_not_null(sys, "%s", err.msg);
  cr_assert_eq(sys->type->renumber(sys->state, &err), LW_OK, "%s", err.msg);
  size_t moved = 0;
  for (size_t i = 0; i < n; i++) {
    size_t k = 0;
    while (k < n && x0[k] != m->sp->node[m->sp->first[i]].px) k++;
    cr_assert(k < n, "spline %zu is not one of the splines before", i);
    moved += k != i;
    cr_assert_eq(lw_splines_layer(&sc.layers, m->sp, i), layer[k], "spline %zu (was %zu) changed its layer", i, k);
  }
  cr_assert(moved > n / 2, "the renumbering moved only %zu of %zu splines", moved, n);
  double e1 = lw_energy_compute(&sc, m->sp, term, NULL);
  cr_assert(fabs(e1 - e0) <= 1e-9 * fabs(e0), "energy %.17g before the renumbering, %.17g after", e0, e1);
  lw_system_free(sys);
  free(x0);
  free(layer);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

/* With trans-dimensional moves a spline's layer is state (layers.h).  The
** three pens of the test above, each with its own tone raster, potential
** and turned field: a birth into each layer, a death and a grow of splines
** of every layer, each term's difference against the recomputation (1e-9);
** the committed half keeps the running totals and each layer's raster
** plane what a fresh model of the state builds.  Catches a splice evaluated
** with the scene's contexts or raster plane rather than its layer's (the
** tone term off by a whole layer's share).  With apart = pen each layer is
** a plane of the pair grid, and min_spacing holds within layers. */
static void births_and_deaths(int apart)
{
  lw_params p = three_pens();
  p.strain = 1;
  p.pair = 0.02;
  p.pair_cutoff = 2;
  p.fixed_count = 0;
  p.ly_apart = apart;
  if (apart == LW_APART_PEN) p.min_spacing = 0.15;
  lw_scene sc;
  lw_test_scene(&sc, &p);
  lw_model *m = lw_test_model_random(&sc, 45, 3, 3, 11);
  cr_assert_not_null(m->sp->layer, "a scene whose splines are born in layers stores them");
  for (size_t i = 0; i < m->sp->n_splines; i++) cr_assert_eq(m->sp->layer[i], lw_layers_of(&sc.layers, i));
  lw_proposal *pr = lw_proposal_new(m, NULL);
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 13);
  double term0[LW_TERM_COUNT], term1[LW_TERM_COUNT];
  lw_model_compact(m);
  double e0 = lw_energy_compute(&sc, m->sp, term0, NULL);
  unsigned char dead[128];
  lw_node nd[8];
  int checked[3] = {0};
  for (int trial = 0; trial < 150; trial++) {
    /* the state as it is: the ghosts of the last commit compacted away */
    cr_assert_eq(lw_model_compact(m), LW_OK);
    const lw_splines *sp = m->sp;
    cr_assert(sp->n_splines < sizeof dead);
    memset(dead, 0, sizeof dead);
    const uint32_t i = (uint32_t)gsl_rng_uniform_int(r, sp->n_splines);
    const size_t n = lw_splines_segments(sp, i) + 1;
    const lw_node *src = &sp->node[sp->first[i]];
    const int kind = trial % 3, layer = (trial / 3) % 3;
    lw_splines *after;
    if (kind == 0) { /* a birth into `layer`: spline i's shape moved by up to 10 mm */
      const double dx = gsl_ran_flat(r, -10, 10), dy = gsl_ran_flat(r, -10, 10);
      for (size_t k = 0; k < n; k++) nd[k] = (lw_node){src[k].px + dx, src[k].py + dy, src[k].vx, src[k].vy};
      lw_model_propose_splice(m, pr, 0, 0, nd, n, 7.0, layer);
      after = spliced(sp, dead, nd, n, 7.0, layer);
    } else if (kind == 1) { /* a death */
      lw_model_propose_splice(m, pr, i, 1, NULL, 0, 0.0, 0);
      dead[i] = 1;
      after = spliced(sp, dead, NULL, 0, 0.0, 0);
    } else { /* a grow at the tail: spline i replaced, in its own layer */
      memcpy(nd, src, n * sizeof *nd);
      nd[n] = (lw_node){src[n - 1].px + 2.0 * src[n - 1].vx, src[n - 1].py + 2.0 * src[n - 1].vy, src[n - 1].vx,
                        src[n - 1].vy};
      lw_model_propose_splice(m, pr, i, 1, nd, n + 1, sp->rest_length[i] + 3.0, 0);
      cr_assert_eq(pr->layer, sp->layer[i], "a grown spline keeps its layer");
      dead[i] = 1;
      after = spliced(sp, dead, nd, n + 1, sp->rest_length[i] + 3.0, sp->layer[i]);
    }
    double e1 = lw_energy_compute(&sc, after, term1, NULL);
    lw_splines_free(after);
    if (!isfinite(e1) || !isfinite(pr->dE)) continue;
    checked[kind]++;
    for (int t = 0; t < LW_TERM_COUNT; t++)
      cr_assert(fabs(pr->dterm[t] - (term1[t] - term0[t])) <= 1e-9 * fmax(fabs(term0[t]), 1e-3),
                "trial %d (kind %d, layer %d) term %s: local %.17g, full %.17g", trial, kind, layer, lw_term_names[t],
                pr->dterm[t], term1[t] - term0[t]);
    if (trial % 2) {
      cr_assert_eq(lw_model_commit(m, pr), LW_OK);
      e0 = e1;
      memcpy(term0, term1, sizeof term0);
    }
  }
  for (int k = 0; k < 3; k++) cr_assert(checked[k] > 30, "kind %d: only %d finite splices", k, checked[k]);
  cr_assert_eq(lw_model_compact(m), LW_OK);
  cr_assert(fabs(lw_model_total(m) - e0) <= 1e-9 * fabs(e0));
  /* each layer's plane of the tone raster is what the state gives afresh */
  lw_error err;
  lw_model *f = lw_model_new(&sc, lw_splines_clone(m->sp), &err);
  cr_assert_not_null(f, "%s", err.msg);
  const lw_tone *tn = sc.layer[0].tone.w ? &sc.layer[0].tone : NULL;
  cr_assert_not_null(tn);
  const size_t bytes = 3 * (size_t)tn->w * (size_t)tn->h * sizeof(int64_t);
  cr_assert_eq(memcmp(f->raster[LW_TERM_TONE], m->raster[LW_TERM_TONE], bytes), 0,
               "a layer's raster plane differs from a fresh one");
  lw_model_free(f);
  gsl_rng_free(r);
  lw_proposal_free(pr);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

Test(layers, births_and_deaths_in_layers_change_the_energy_by_the_full_recomputation)
{
  births_and_deaths(LW_APART_ALL);
}

Test(layers, births_and_deaths_in_layers_kept_apart_by_pen_match_the_full_recomputation)
{
  births_and_deaths(LW_APART_PEN);
}

/* ---- layers.apart = pen ------------------------------------------------- */

/* With apart = pen a line is repelled by its own layer's lines only: the
** pair energy of a state is the sum over the layers of the pair energy of
** that layer's splines alone, and pairs across layers count nothing. */
Test(layers, kept_apart_by_pen_the_pair_energy_is_each_layers_own)
{
  lw_params p = three_pens();
  p.pair = 0.02;
  p.pair_cutoff = 2;
  p.ly_apart = LW_APART_PEN;
  lw_scene sc;
  lw_test_scene(&sc, &p);
  lw_model *m = lw_test_model_random(&sc, 60, 3, 3, 17);
  double term[LW_TERM_COUNT], all[LW_TERM_COUNT], each[LW_TERM_COUNT];
  lw_energy_compute(&sc, m->sp, term, NULL);
  p.ly_apart = LW_APART_ALL;
  lw_scene sa;
  lw_test_scene(&sa, &p);
  lw_energy_compute(&sa, m->sp, all, NULL);
  double sum = 0.0;
  unsigned char dead[64];
  cr_assert(m->sp->n_splines <= sizeof dead);
  for (int k = 0; k < 3; k++) {
    for (size_t i = 0; i < m->sp->n_splines; i++) dead[i] = lw_splines_layer(&sc.layers, m->sp, i) != k;
    lw_splines *one = spliced(m->sp, dead, NULL, 0, 0.0, 0);
    lw_energy_compute(&sa, one, each, NULL);
    cr_assert(each[LW_TERM_PAIR] > 0.0, "layer %d has no pairs of its own", k);
    sum += each[LW_TERM_PAIR];
    lw_splines_free(one);
  }
  cr_assert(fabs(term[LW_TERM_PAIR] - sum) <= 1e-12 * sum, "by pen %.17g, layers alone %.17g", term[LW_TERM_PAIR],
            sum);
  cr_assert(all[LW_TERM_PAIR] > 1.2 * sum, "pairs across layers add %g to %g", all[LW_TERM_PAIR] - sum, sum);
  /* moves, their pair sums from the layer's plane, against the recomputation */
  cr_assert(lw_test_moves_match_full(&sc, m, 200, 0.7, 5) > 80);
  lw_model_free(m);
  lw_scene_clear(&sa);
  lw_scene_clear(&sc);
}

/* Straight splines: 0 of layer 0 along y = 20, 1 of layer 1 above it
** along x = 18.5, 2 of layer 0 beside 1.  Moving spline 1's first node down
** onto spline 0 adds close pairs: min_spacing refuses it when lines of
** every layer keep apart, and allows it with apart = pen.  Moving spline
** 2's onto spline 0 (its own pen) is refused either way. */
Test(layers, kept_apart_by_pen_lines_of_other_pens_may_cross)
{
  for (int apart = LW_APART_ALL; apart <= LW_APART_PEN; apart++) {
    lw_params p = three_pens();
    snprintf(p.ly_names, sizeof p.ly_names, "a b");
    snprintf(p.ly_colors, sizeof p.ly_colors, "#20a0c0 #c02060");
    snprintf(p.ly_turn, sizeof p.ly_turn, "0 90");
    snprintf(p.ly_pen_width, sizeof p.ly_pen_width, "0.3 0.3");
    p.pair = 0.02;
    p.pair_cutoff = 2;
    p.min_spacing = 0.3;
    p.ly_apart = apart;
    lw_scene sc;
    lw_test_scene(&sc, &p);
    size_t segs[3] = {2, 2, 2};
    lw_error err;
    lw_splines *sp = lw_splines_new(3, segs, &err);
    cr_assert_not_null(sp);
    cr_assert_eq(lw_splines_layers_alloc(sp), LW_OK);
    /* segments of 1.5 mm: pair samples closer than min_spacing along each line */
    const double x0[3] = {17, 18.5, 21.5}, y0[3] = {20, 21, 21}, dx[3] = {1.5, 0, 0}, dy[3] = {0, 1.5, 1.5};
    const int layer[3] = {0, 1, 0};
    for (int i = 0; i < 3; i++) {
      sp->layer[i] = (uint8_t)layer[i];
      sp->rest_length[i] = 10;
      for (int k = 0; k < 3; k++)
        sp->node[sp->first[i] + (size_t)k] = (lw_node){x0[i] + k * dx[i], y0[i] + k * dy[i], dx[i] / 3, dy[i] / 3};
    }
    lw_model *m = lw_model_new(&sc, sp, &err);
    cr_assert_not_null(m, "%s", err.msg);
    lw_proposal *pr = lw_proposal_new(m, NULL);
    lw_node to = m->sp->node[m->sp->first[1]];
    to.py = 20.05;
    lw_model_propose(m, pr, 1, 0, 1, &to);
    if (apart == LW_APART_PEN)
      cr_assert(!pr->crowded && isfinite(pr->dE), "a crossing of two pens refused (dE %g)", pr->dE);
    else
      cr_assert(pr->crowded && pr->dE == INFINITY, "a crossing allowed with every line apart (dE %g)", pr->dE);
    lw_node on = m->sp->node[m->sp->first[2]];
    on.px = 17.5;
    on.py = 20.05;
    lw_model_propose(m, pr, 2, 0, 1, &on);
    cr_assert(pr->crowded && pr->dE == INFINITY, "apart %d: a line moved onto its own pen's was allowed", apart);
    lw_proposal_free(pr);
    lw_model_free(m);
    lw_scene_clear(&sc);
  }
}

/* Two layers of the picture's whole tone range on a page of side `page`,
** kept apart by pen, with the pair term (coefficient pair, cutoff rc). */
static lw_params two_layers_by_pen(double page, double pair, double rc)
{
  lw_params p = colour_params(page, (int)page, blotch_colours);
  snprintf(p.ly_names, sizeof p.ly_names, "a b");
  p.ly_source = LW_LSRC_TONE;
  p.ly_apart = LW_APART_PEN;
  p.pair = pair;
  p.pair_cutoff = rc;
  return p;
}

/* The placement starts lines apart from their own pen's only: with two
** layers of one target, close sample pairs (min_spacing) within a layer are
** none, across the layers as many as chance gives (some 36 crossings of two
** random sets of 30 lines of 9 mm on this page; a placement that kept every
** line apart leaves none). */
Test(layers, kept_apart_by_pen_the_placement_spaces_each_layer_alone)
{
  lw_params p = two_layers_by_pen(40, 0.02, 2);
  p.min_spacing = 0.3;
  lw_scene sc;
  lw_test_scene(&sc, &p);
  lw_model *m = lw_test_model_random(&sc, 60, 3, 3, 21);
  const lw_splines *sp = m->sp;
  size_t same = 0, across = 0;
  for (size_t g = 0; g < sp->n_segments; g++)
    for (size_t h = g + 1; h < sp->n_segments; h++) {
      const size_t i = sp->seg_spline[g], j = sp->seg_spline[h];
      if (i == j) continue;
      lw_samples a, b;
      const lw_node *na = &sp->node[lw_segment_node(sp, g)], *nb = &sp->node[lw_segment_node(sp, h)];
      lw_segment_sample(&sc.pair_quad, na, na + 1, &a);
      lw_segment_sample(&sc.pair_quad, nb, nb + 1, &b);
      for (int q = 0; q < a.n; q++)
        for (int r = 0; r < b.n; r++) {
          const double dx = a.x[q] - b.x[r], dy = a.y[q] - b.y[r];
          if (dx * dx + dy * dy >= p.min_spacing * p.min_spacing) continue;
          if (sp->layer[i] == sp->layer[j]) same++;
          else across++;
        }
    }
  cr_assert_eq(same, 0, "%zu close pairs within layers", same);
  cr_assert(across >= 10, "only %zu close pairs across layers", across);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

/* The close share of pens kept apart counts a stroke's own pen only. */
Test(layers, the_close_share_of_pens_kept_apart_counts_each_pen_alone)
{
  /* two strokes crossing at right angles */
  const double b[16] = {0, 5, 3, 5, 7, 5, 10, 5, 5, 0, 5, 3, 5, 7, 5, 10};
  const size_t owner[2] = {0, 1}, one[2] = {0, 0}, two[2] = {0, 1};
  double all, same, apart;
  cr_assert_eq(lw_close_share(b, owner, NULL, 2, 0.3, &all, NULL), LW_OK);
  cr_assert_eq(lw_close_share(b, owner, one, 2, 0.3, &same, NULL), LW_OK);
  cr_assert_eq(lw_close_share(b, owner, two, 2, 0.3, &apart, NULL), LW_OK);
  cr_assert(all > 0.0 && all < 0.1, "%g", all);
  cr_assert_eq(same, all);
  cr_assert_eq(apart, 0.0);
}

static double blotches(double u, double v) { return 0.5 + 0.4 * sin(7 * u + 2 * v) * cos(5 * v - 3 * u * u); }

Test(layers, one_whole_range_layer_is_the_scene_without_layers)
{
  /* tone_min 0, tone_max 1, no turn, the output pen: the layer's target is
  ** the picture's tone bit for bit, so every term is the same double. */
  lw_params p;
  lw_params_defaults(&p);
  p.width = p.height = 40;
  p.margin = 2;
  p.min_speed = p.regularity = 0;
  float g[30 * 30];
  for (int j = 0; j < 30; j++)
    for (int i = 0; i < 30; i++) g[j * 30 + i] = (float)blotches((i + 0.5) / 30, (j + 0.5) / 30);
  snprintf(p.image, sizeof p.image, "%s", lw_test_path("grey.png"));
  lw_test_png(p.image, 30, 30, g, NULL);
  p.tone = 2;
  p.potential = LW_POT_IMAGE;
  p.potential_coef = 0.4;
  p.field = LW_FLD_ETF;
  p.field_coef = -0.5;
  p.bending = 0.2;
  lw_scene plain, one;
  lw_test_scene(&plain, &p);
  snprintf(p.ly_names, sizeof p.ly_names, "all");
  lw_test_scene(&one, &p);
  lw_model *m = lw_test_model_random(&plain, 40, 3, 3, 4);
  double a[LW_TERM_COUNT], b[LW_TERM_COUNT];
  double ea = lw_energy_compute(&plain, m->sp, a, NULL), eb = lw_energy_compute(&one, m->sp, b, NULL);
  for (int t = 0; t < LW_TERM_COUNT; t++) cr_assert_eq(a[t], b[t], "%s: %.17g and %.17g", lw_term_names[t], a[t], b[t]);
  cr_assert_eq(ea, eb);
  /* the same number of splines from a coverage, and twice as many for two
  ** such layers (each layer's ink in its own pen) */
  p.splines = 0;
  p.coverage = 0.4;
  size_t n_plain, n_one, n_two;
  lw_error err;
  cr_assert_eq(lw_init_count(&plain, &p, &n_plain, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(lw_init_count(&one, &p, &n_one, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(n_plain, n_one);
  lw_scene two;
  snprintf(p.ly_names, sizeof p.ly_names, "all again");
  lw_test_scene(&two, &p);
  cr_assert_eq(lw_init_count(&two, &p, &n_two, &err), LW_OK, "%s", err.msg);
  cr_assert(n_two >= 2 * n_one - 1 && n_two <= 2 * n_one + 1, "%zu and %zu", n_one, n_two);
  lw_scene_clear(&two);
  snprintf(p.ly_names, sizeof p.ly_names, "all");
  /* and a narrower range asks for less ink: the tone term sees it */
  lw_scene half;
  snprintf(p.ly_tone_max, sizeof p.ly_tone_max, "0.5");
  lw_test_scene(&half, &p);
  lw_energy_compute(&half, m->sp, b, NULL);
  cr_assert_neq(a[LW_TERM_TONE], b[LW_TERM_TONE]);
  lw_model_free(m);
  lw_scene_clear(&plain);
  lw_scene_clear(&one);
  lw_scene_clear(&half);
}

/* Mean |cos| between the tangents of layer k's splines and (ux, uy),
** weighted by length. */
static double alignment(const lw_model *m, int k, double ux, double uy)
{
  double s = 0.0, w = 0.0;
  lw_samples smp;
  for (size_t g = 0; g < m->sp->n_segments; g++) {
    if (lw_splines_layer(&m->scene->layers, m->sp, m->sp->seg_spline[g]) != k) continue;
    const lw_node *a = &m->sp->node[lw_segment_node(m->sp, g)];
    lw_segment_sample(&m->scene->quad, a, a + 1, &smp);
    for (int q = 0; q < smp.n; q++) {
      if (!(smp.speed[q] > 0)) continue;
      s += smp.dl[q] * fabs(smp.dx[q] * ux + smp.dy[q] * uy) / smp.speed[q];
      w += smp.dl[q];
    }
  }
  return s / w;
}

Test(layers, hatching_layers_follow_their_own_fields)
{
  /* A constant field along x; layer `across` turns it by 90 degrees.  The
  ** splines start at random angles (placed by a scene without the field),
  ** so the layers must turn them: after annealing each layer lies along
  ** its own direction (mean |cos| > 0.95, where a random direction gives
  ** 2 / pi = 0.64) and across the other's. */
  lw_params p;
  lw_params_defaults(&p);
  p.width = p.height = 60;
  p.margin = 3;
  p.strain = 5;
  p.bending = 0.5;
  p.boundary_coef = 0.05;
  p.min_speed = p.regularity = 0;
  lw_scene plain, sc;
  lw_test_scene(&plain, &p);
  p.field = LW_FLD_CONSTANT;
  p.field_angle = 0;
  p.field_coef = -2;
  snprintf(p.ly_names, sizeof p.ly_names, "along across");
  snprintf(p.ly_turn, sizeof p.ly_turn, "0 90");
  lw_test_scene(&sc, &p);
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 9);
  lw_error err;
  lw_splines *sp = lw_init_random(&plain, 30, 3, 4, r, &err);
  cr_assert_not_null(sp, "%s", err.msg);
  gsl_rng_free(r);
  lw_model *m = lw_model_new(&sc, sp, &err);
  cr_assert_not_null(m, "%s", err.msg);
  cr_assert(alignment(m, 1, 0, 1) < 0.85 && alignment(m, 0, 1, 0) < 0.85, "the start is at random angles");
  const double w[4] = {0.4, 0.3, 0.1, 0.2}, st[4] = {0.5, 0.5, 0.5, 0.3}, tg[4] = {0.44, 0.44, 0.3, 0.3};
  lw_chain *c = model_chain(m, w, st, tg, 5, &err);
  cr_assert_not_null(c, "%s", err.msg);
  for (int s = 0; s < 300; s++) {
    c->temperature = 0.5 * pow(0.002 / 0.5, s / 299.0);
    c->tuning = s < 150;
    cr_assert_eq(lw_chain_sweep(c), LW_OK);
  }
  double a0 = alignment(m, 0, 1, 0), a1 = alignment(m, 1, 0, 1);
  cr_assert(a0 > 0.95, "layer along: %g", a0);
  cr_assert(a1 > 0.95, "layer across: %g", a1);
  cr_assert(alignment(m, 1, 1, 0) < 0.3, "layer across is not along x");
  model_chain_free(c);
  lw_model_free(m);
  /* and the placement starts each layer along its own field already */
  m = lw_test_model_random(&sc, 30, 3, 4, 9);
  cr_assert(alignment(m, 0, 1, 0) > 0.99 && alignment(m, 1, 0, 1) > 0.99, "%g %g", alignment(m, 0, 1, 0),
            alignment(m, 1, 0, 1));
  lw_model_free(m);
  lw_scene_clear(&sc);
  lw_scene_clear(&plain);
}

Test(layers, each_layer_gets_splines_by_its_share_of_the_ink)
{
  /* Shares 0.7, 0, 0.3: the golden-ratio sequence gives layer k its share
  ** of any number of splines to within a few splines, none to a layer
  ** without ink. */
  lw_layers_spec ls = {.n = 3, .cum = {0, 0.7, 0.7, 1.0}};
  for (size_t n = 10; n <= 10000; n *= 10) {
    size_t count[3] = {0};
    for (size_t i = 0; i < n; i++) count[lw_layers_of(&ls, i)]++;
    cr_assert_eq(count[1], 0);
    cr_assert(fabs((double)count[0] - 0.7 * n) <= 2 + log((double)n), "n %zu: %zu in layer 0", n, count[0]);
  }
}

/* A layer's share is its ink over its pen's width: two layers of the same
** ink in pens of 0.2 and 0.8 mm take 4/5 and 1/5 of the splines (by ink
** alone, half each, the fine pen drew 0.34 of a full tone the wide one
** drew at 0.52). */
Test(layers, a_layers_share_is_its_ink_over_its_pens_width)
{
  lw_error err;
  lw_image *a = lw_image_new(4, 3, 0, &err), *b = lw_image_new(4, 3, 0, &err);
  cr_assert(a && b);
  for (int q = 0; q < 12; q++) a->tone[q] = b->tone[q] = q % 2 ? 0.25f : 1.0f;
  lw_layers_spec ls = {.n = 2};
  ls.spec[0].pen_width = 0.2;
  ls.spec[1].pen_width = 0.8;
  const lw_image *t[2] = {a, b};
  lw_layers_share(&ls, t, 1);
  cr_expect_float_eq(ls.cum[1], 0.8, 1e-12);
  cr_expect_eq(ls.cum[2], 1.0);
  lw_layers_share(&ls, t, 0); /* layers.share_width = 0, runs before it: the ink alone */
  cr_expect_float_eq(ls.cum[1], 0.5, 1e-12);
  ls.spec[1].pen_width = 0.2; /* equal pens: the ink alone */
  lw_layers_share(&ls, t, 1);
  cr_expect_float_eq(ls.cum[1], 0.5, 1e-12);
  lw_image_free(a);
  lw_image_free(b);
}

Test(layers, the_gradient_reads_each_layers_field_and_potential)
{
  /* Layers with turned fields and their own potentials: the gradient of
  ** field + potential + bending matches central differences of
  ** lw_energy_compute (which reads each spline's layer) for every
  ** coordinate of a few splines of each layer. */
  lw_params p = colour_params(40, 40, blotch_colours);
  snprintf(p.ly_names, sizeof p.ly_names, "a b");
  p.ly_source = LW_LSRC_PALETTE;
  snprintf(p.ly_colors, sizeof p.ly_colors, "#20a0c0 #c02060");
  snprintf(p.ly_turn, sizeof p.ly_turn, "30 100");
  p.potential = LW_POT_IMAGE;
  p.potential_coef = 0.5;
  p.field = LW_FLD_CONSTANT;
  p.field_angle = 10;
  p.field_mode = LW_FIELDMODE_SIGNED;
  p.field_coef = -0.7;
  p.bending = 0.3;
  lw_scene sc;
  lw_test_scene(&sc, &p);
  lw_model *m = lw_test_model_random(&sc, 8, 2, 3, 3);
  lw_splines *sp = lw_splines_clone(m->sp);
  lw_node *g = calloc(sp->n_nodes, sizeof *g);
  lw_error err;
  double term[LW_TERM_COUNT];
  cr_assert(isfinite(lw_energy_gradient(&sc, sp, LW_GRAD_ALL, g, term, &err)), "%s", err.msg);
  const double h = 1e-6;
  for (size_t k = 0; k < sp->n_nodes; k++)
    for (int c = 0; c < 4; c++) {
      double *x = &sp->node[k].px + c, x0 = *x, tp[LW_TERM_COUNT], tm[LW_TERM_COUNT];
      *x = x0 + h;
      double ep = lw_energy_compute(&sc, sp, tp, NULL);
      *x = x0 - h;
      double em = lw_energy_compute(&sc, sp, tm, NULL);
      *x = x0;
      double fd = (ep - em) / (2 * h), an = (&g[k].px)[c];
      cr_assert(fabs(fd - an) <= 1e-4 * fmax(1.0, fabs(fd)), "node %zu coordinate %d: analytic %g, differences %g", k,
                c, an, fd);
    }
  free(g);
  lw_splines_free(sp);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

/* The pair gradient with lines kept apart by pen pairs each sample with its
** own layer's only, as the energy does: it is, node for node, the pair
** gradient of each layer's splines alone (drawing the pairs across layers
** in would add their forces). */
Test(layers, kept_apart_by_pen_the_pair_gradient_is_each_layers_own)
{
  lw_params p = two_layers_by_pen(30, 0.05, 3);
  lw_scene sc, sa;
  lw_test_scene(&sc, &p);
  p.ly_apart = LW_APART_ALL;
  lw_test_scene(&sa, &p);
  lw_model *m = lw_test_model_random(&sc, 16, 2, 4, 9);
  const lw_splines *sp = m->sp;
  const unsigned mask = 1u << LW_TERM_PAIR;
  lw_node *g = calloc(sp->n_nodes, sizeof *g), *ga = calloc(sp->n_nodes, sizeof *ga);
  cr_assert(g && ga);
  lw_error err;
  double term[LW_TERM_COUNT], big = 0.0, across = 0.0;
  cr_assert(isfinite(lw_energy_gradient(&sc, sp, mask, g, term, &err)), "%s", err.msg);
  cr_assert(isfinite(lw_energy_gradient(&sa, sp, mask, ga, term, &err)), "%s", err.msg);
  unsigned char dead[16];
  for (int k = 0; k < 2; k++) {
    for (size_t i = 0; i < sp->n_splines; i++) dead[i] = sp->layer[i] != k;
    lw_splines *one = spliced(sp, dead, NULL, 0, 0.0, 0);
    lw_node *g1 = calloc(one->n_nodes, sizeof *g1);
    cr_assert(isfinite(lw_energy_gradient(&sa, one, mask, g1, term, &err)), "%s", err.msg);
    for (size_t i = 0, j = 0; i < sp->n_splines; i++) {
      if (dead[i]) continue;
      for (size_t q = 0; q <= lw_splines_segments(sp, i); q++)
        for (int c = 0; c < 4; c++) {
          const double mine = (&g[sp->first[i] + q].px)[c], alone = (&g1[one->first[j] + q].px)[c];
          const double all = (&ga[sp->first[i] + q].px)[c];
          cr_assert(fabs(mine - alone) <= 1e-9 * fmax(1e-3, fabs(alone)), "spline %zu node %zu: %.17g, alone %.17g", i,
                    q, mine, alone);
          big = fmax(big, fabs(alone));
          across = fmax(across, fabs(all - alone));
        }
      j++;
    }
    free(g1);
    lw_splines_free(one);
  }
  cr_assert(across > 1e-2 * big, "the pairs across layers add only %g to a gradient of %g", across, big);
  free(g);
  free(ga);
  lw_model_free(m);
  lw_scene_clear(&sa);
  lw_scene_clear(&sc);
}

/* ---- separation --------------------------------------------------------- */

/* Smallest eigenvalue of U^T U for the pens rgb (k <= 3, independent). */
static double smallest_eigen(const unsigned char (*rgb)[3], int k)
{
  gsl_matrix *M = gsl_matrix_alloc((size_t)k, (size_t)k);
  for (int i = 0; i < k; i++)
    for (int j = 0; j < k; j++) {
      double s = 0;
      for (int c = 0; c < 3; c++) s += (1 - rgb[i][c] / 255.0) * (1 - rgb[j][c] / 255.0);
      gsl_matrix_set(M, (size_t)i, (size_t)j, s);
    }
  gsl_vector *ev = gsl_vector_alloc((size_t)k);
  gsl_eigen_symm_workspace *ws = gsl_eigen_symm_alloc((size_t)k);
  gsl_eigen_symm(M, ev, ws);
  double mn = gsl_vector_min(ev);
  gsl_eigen_symm_free(ws);
  gsl_vector_free(ev);
  gsl_matrix_free(M);
  return mn;
}

Test(layers, a_palette_separation_recovers_the_pen_coverages_a_picture_was_mixed_from)
{
  /* Pixels mixed from three pens at known coverages a (c = 1 - U a): the
  ** separation gives a back, up to the pull of the ridge and the ink
  ** penalty, (lambda |a| + mu sqrt(3)) / s_min (s_min the smallest
  ** eigenvalue of U^T U), and the float rounding of c (6e-8 a channel,
  ** amplified by at most 1 / sqrt(s_min)). */
  const unsigned char pens[3][3] = {{0x20, 0x90, 0xc0}, {0xc0, 0x30, 0x70}, {0xe0, 0xc0, 0x20}};
  const double smin = smallest_eigen(pens, 3);
  cr_assert(smin > 0.01, "an independent palette");
  enum { N = 2000 };
  static float r[N], g[N], b[N], got[3 * N], want[3 * N];
  rng_seed(17);
  for (int p = 0; p < N; p++) {
    double a[3], c[3] = {1, 1, 1};
    for (int k = 0; k < 3; k++) a[k] = want[k * N + p] = (float)urand(0, 0.45);
    for (int k = 0; k < 3; k++)
      for (int ch = 0; ch < 3; ch++) c[ch] -= a[k] * (1 - pens[k][ch] / 255.0);
    r[p] = (float)c[0];
    g[p] = (float)c[1];
    b[p] = (float)c[2];
    cr_assert(c[0] >= 0 && c[1] >= 0 && c[2] >= 0);
  }
  lw_layers_separate(r, g, b, N, 3, pens, got);
  const double tol = (LW_LAYERS_RIDGE * sqrt(3) * 0.45 + LW_LAYERS_INK * sqrt(3)) / smin + 4 * 6e-8 / sqrt(smin) + 1e-7;
  double worst = 0;
  for (int k = 0; k < 3 * N; k++) worst = fmax(worst, fabs(got[k] - want[k]));
  cr_assert(worst <= tol, "largest error %g, bound %g", worst, tol);
}

Test(layers, the_separation_is_the_bounded_least_squares_minimum)
{
  /* Five pens (dependent: more pens than channels) and colours no mix
  ** reaches: the coverages satisfy the optimality conditions of
  ** min |U a - d|^2 + lambda |a|^2 over [0, 1]^5 -- gradient 0 where
  ** 0 < a < 1, pointing outward where a sits on a bound (layers.h). */
  const unsigned char pens[5][3] = {{0, 255, 255}, {255, 0, 255}, {255, 255, 0}, {0, 0, 0}, {200, 40, 40}};
  enum { N = 500 };
  static float r[N], g[N], b[N], a[5 * N];
  rng_seed(23);
  for (int p = 0; p < N; p++) {
    r[p] = (float)urand(0, 1);
    g[p] = (float)urand(0, 1);
    b[p] = (float)urand(0, 1);
  }
  lw_layers_separate(r, g, b, N, 5, pens, a);
  for (int p = 0; p < N; p++) {
    double d[3] = {1 - r[p], 1 - g[p], 1 - b[p]}, res[3];
    for (int ch = 0; ch < 3; ch++) {
      res[ch] = -d[ch];
      for (int k = 0; k < 5; k++) res[ch] += (1 - pens[k][ch] / 255.0) * a[k * N + p];
    }
    for (int k = 0; k < 5; k++) {
      double grad = LW_LAYERS_RIDGE * a[k * N + p] + LW_LAYERS_INK;
      for (int ch = 0; ch < 3; ch++) grad += (1 - pens[k][ch] / 255.0) * res[ch];
      double ak = a[k * N + p];
      /* float storage of a moves the gradient by at most |U^T U| 6e-8 */
      const double tol = 1e-6;
      if (ak > 1e-6 && ak < 1 - 1e-6) cr_assert(fabs(grad) <= tol, "pixel %d pen %d: a %g, gradient %g", p, k, ak, grad);
      else if (ak <= 1e-6) cr_assert(grad >= -tol, "pixel %d pen %d at 0: gradient %g", p, k, grad);
      else cr_assert(grad <= tol, "pixel %d pen %d at 1: gradient %g", p, k, grad);
    }
  }
}

Test(layers, cmyk_draws_a_grey_in_black_and_a_colour_in_its_process_inks)
{
  const unsigned char cmyk[4][3] = {{0, 255, 255}, {255, 0, 255}, {255, 255, 0}, {0, 0, 0}};
  float r[2] = {0.4f, 0.0f}, g[2] = {0.4f, 1.0f}, b[2] = {0.4f, 1.0f}, a[8];
  lw_layers_separate(r, g, b, 2, 4, cmyk, a);
  /* grey 0.4: black 0.6, no colour (the ink penalty prefers one unit of
  ** black to three of colour) */
  cr_assert(fabs(a[3 * 2 + 0] - 0.6) < 1e-4 && a[0] < 1e-4 && a[2] < 1e-4 && a[4] < 1e-4, "%g %g %g %g", a[0],
            a[2], a[4], a[6]);
  /* cyan: all cyan */
  cr_assert(fabs(a[1] - 1.0) < 1e-4 && a[3] < 1e-4 && a[5] < 1e-4 && a[7] < 1e-4);
}

Test(layers, a_cmyk_scene_gives_each_pen_its_separation_as_target)
{
  /* Cyan on the left half, yellow on the right: the cyan layer's target
  ** is full ink (tone 0) on the left and none on the right, the yellow
  ** one's the other way round, magenta and black none anywhere. */
  lw_params p = colour_params(40, 32, cyan_yellow);
  snprintf(p.ly_names, sizeof p.ly_names, "c m y k");
  p.ly_source = LW_LSRC_CMYK;
  p.tone = 1;
  lw_scene sc;
  lw_test_scene(&sc, &p);
  cr_assert_eq(sc.layers.n, 4);
  cr_assert_eq(sc.layers.spec[0].rgb[0], 0);
  cr_assert_eq(sc.layers.spec[2].rgb[2], 0);
  const lw_image *t[4];
  for (int k = 0; k < 4; k++) t[k] = sc.layer[k].target;
  size_t left = 16 * 32 + 4, right = 16 * 32 + 27;
  cr_assert(t[0]->tone[left] < 1e-3 && t[0]->tone[right] > 1 - 1e-3);
  cr_assert(t[2]->tone[left] > 1 - 1e-3 && t[2]->tone[right] < 1e-3);
  cr_assert(t[1]->tone[left] > 1 - 1e-3 && t[3]->tone[right] > 1 - 1e-3);
  /* each layer's tone target is its own */
  cr_assert_neq(sc.layer[0].tone.dark[(size_t)(sc.layer[0].tone.pad + 16) * (size_t)sc.layer[0].tone.w +
                                      (size_t)sc.layer[0].tone.pad + 4],
                sc.layer[2].tone.dark[(size_t)(sc.layer[2].tone.pad + 16) * (size_t)sc.layer[2].tone.w +
                                      (size_t)sc.layer[2].tone.pad + 4]);
  lw_scene_clear(&sc);
}

/* ---- drawing ------------------------------------------------------------ */

Test(layers, the_preview_lays_inks_over_each_other)
{
  /* A cyan line across a yellow one: with multiply the crossing is green,
  ** as inks on paper, where painting over would leave it yellow. */
  size_t segs[2] = {1, 1};
  lw_splines *sp = lw_splines_new(2, segs, NULL);
  lw_test_straight(sp, 0, 2, 10, 18, 10);
  lw_test_straight(sp, 1, 10, 2, 10, 18);
  lw_output_page page;
  lw_output_page_init(&page, 20, 20);
  page.n_pens = 2;
  page.multiply = 1;
  unsigned char cy[3] = {0, 255, 255}, ye[3] = {255, 255, 0};
  page.pen[0] = (lw_output_pen){1.0, {cy[0], cy[1], cy[2]}};
  page.pen[1] = (lw_output_pen){1.0, {ye[0], ye[1], ye[2]}};
  lw_plot *pl = lw_plot_new(sp, 2, NULL, LW_PLOT_ORDER_NONE, 0, 0, NULL);
  cr_assert_not_null(pl);
  const char *path = lw_test_path("cross.png");
  lw_error err;
  cr_assert_eq(lw_output_png(sp, &page, pl, NULL, 10, path, &err), LW_OK, "%s", err.msg);
  cairo_surface_t *s = cairo_image_surface_create_from_png(path);
  cr_assert_eq(cairo_surface_status(s), CAIRO_STATUS_SUCCESS);
  const unsigned char *d = cairo_image_surface_get_data(s);
  int stride = cairo_image_surface_get_stride(s);
#define PX(x, y, c) d[(size_t)(y) * (size_t)stride + 4 * (size_t)(x) + (2 - (c))]
  cr_assert(PX(100, 100, 0) < 30 && PX(100, 100, 1) > 225 && PX(100, 100, 2) < 30, "crossing %d %d %d",
            PX(100, 100, 0), PX(100, 100, 1), PX(100, 100, 2));
  cr_assert(PX(50, 100, 0) < 30 && PX(50, 100, 2) > 225, "cyan alone");
  cr_assert(PX(100, 50, 0) > 225 && PX(100, 50, 2) < 30, "yellow alone");
#undef PX
  cairo_surface_destroy(s);
  lw_plot_free(pl);
  lw_splines_free(sp);
}

/* Runs "cd DIR && linewise <args>", stderr into errs; the exit status. */
static int run(const char *args, char *errs, size_t nerr)
{
  char cmd[2048];
  snprintf(cmd, sizeof cmd, "cd %s && %s %s >/dev/null 2>%s", lw_test_dir, lw_test_bin(), args,
           lw_test_path("err.txt"));
  int st = system(cmd);
  FILE *f = fopen(lw_test_path("err.txt"), "r");
  size_t n = fread(errs, 1, nerr - 1, f);
  errs[n] = '\0';
  fclose(f);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static const char colour_scene[] =
  "[scene]\nwidth = 40\nheight = 40\nmargin = 2\nimage = colour.png\nfield = etf\n"
  "[init]\nsplines = 40\nsegments = 2\nsegment_length = 3\n"
  "[energy]\nstrain = 5\nbending = 1\nfield = -0.5\ntone = 2\nboundary = 0.1\n"
  "[anneal]\nsweeps = 3\nsteps = 1\n[plot]\nmin_length = 0\n"
  "[layers]\nnames = c m y k\nsource = cmyk\npen_width = 0.3 0.3 0.3 0.5\n";

Test(layers, the_svg_has_one_group_a_pen_with_its_colour_and_width)
{
  write_colour_png(lw_test_path("colour.png"), 32, 32, blotch_colours);
  lw_test_write(lw_test_path("scene.ini"), colour_scene, strlen(colour_scene));
  char errs[4096];
  cr_assert_eq(run("run scene.ini --out out --quiet", errs, sizeof errs), 0, "%s", errs);
  char path[512];
  snprintf(path, sizeof path, "%s", lw_test_path("out/final.svg"));
  const char *svg = lw_test_read_text(path);
  static const char *const colour[4] = {"#00ffff", "#ff00ff", "#ffff00", "#000000"};
  static const char *const width[4] = {"0.3", "0.3", "0.3", "0.5"};
  int groups = 0;
  for (const char *c = svg; (c = strstr(c, "<g ")); c++) groups++;
  cr_assert_eq(groups, 4, "one group a pen");
  /* a pen's own strokes multiply where they overlap, as in final.png (a
  ** viewer showed them flat: RMSE 0.013 against final.png, now 0.0008) */
  const char *style = strstr(svg, "\n  <style>path { mix-blend-mode: multiply }</style>\n");
  cr_assert(style && style < strstr(svg, "<g "), "%s", svg);
  for (int k = 0; k < 4; k++) {
    char id[32], head[128], stroke[64];
    snprintf(id, sizeof id, "id=\"pen%d\"", k + 1);
    const char *g = strstr(svg, id), *next = k < 3 ? strstr(svg, (snprintf(head, sizeof head, "id=\"pen%d\"", k + 2), head)) : svg + strlen(svg);
    cr_assert_not_null(g, "%s", id);
    /* (no width in the label: vpype takes its every digit for the layer's number) */
    snprintf(head, sizeof head, "inkscape:label=\"%d %c\" id=\"pen%d\" style=\"mix-blend-mode:multiply\">", k + 1,
             "cmyk"[k], k + 1);
    cr_assert_not_null(strstr(svg, head), "%s", head);
    /* every path of the group in the pen's colour and width */
    snprintf(stroke, sizeof stroke, "stroke=\"%s\" stroke-width=\"%s\"", colour[k], width[k]);
    int paths = 0;
    for (const char *c = g; (c = strstr(c, "<path")) && c < next; c++) {
      const char *end = strstr(c, "/>");
      cr_assert(strstr(c, stroke) && strstr(c, stroke) < end, "pen %d: a path without %s", k + 1, stroke);
      paths++;
    }
    if (k < 3) cr_assert(paths > 0, "pen %d draws", k + 1);
  }
  snprintf(path, sizeof path, "%s", lw_test_path("out/summary.json"));
  const char *js = lw_test_read_text(path);
  const char *pens = strstr(js, "\"pens\"");
  cr_assert_not_null(pens, "fidelity per layer");
  int n = 0;
  for (const char *c = pens; (c = strstr(c, "\"ssim\"")); c++) n++;
  cr_assert_eq(n, 4, "one score a layer");
}

/* A picture of cyan and yellow asks nothing of the magenta and black pens:
** their layers stay in final.svg (pen numbers are plotting order), and the
** run says they draw nothing, by number and name, so that no pen is changed
** for an empty layer; summary.json counts each pen's paths. */
Test(layers, a_pen_that_draws_nothing_is_named)
{
  write_colour_png(lw_test_path("colour.png"), 32, 32, cyan_yellow);
  lw_test_write(lw_test_path("scene.ini"), colour_scene, strlen(colour_scene));
  char errs[8192];
  cr_assert_eq(run("run scene.ini --out out", errs, sizeof errs), 0, "%s", errs);
  static const char *const name[] = {"c", "m", "y", "k"};
  for (int k = 1; k <= 4; k++) {
    char line[64];
    snprintf(line, sizeof line, "linewise: pen %d %s draws nothing", k, name[k - 1]);
    if (k == 2 || k == 4) cr_assert_not_null(strstr(errs, line), "no note for pen %d:\n%s", k, errs);
    else cr_assert_null(strstr(errs, line), "pen %d draws:\n%s", k, errs);
  }
  char path[512];
  snprintf(path, sizeof path, "%s", lw_test_path("out/summary.json"));
  const char *js = lw_test_read_text(path), *pp = strstr(js, "\"pen_paths\"");
  cr_assert_not_null(pp, "summary.json counts the paths of each pen");
  long n[4];
  cr_assert_eq(sscanf(pp, "\"pen_paths\": [ %ld , %ld , %ld , %ld ]", &n[0], &n[1], &n[2], &n[3]), 4, "%.80s", pp);
  cr_assert(n[0] > 0 && n[1] == 0 && n[2] > 0 && n[3] == 0, "pen paths %ld %ld %ld %ld", n[0], n[1], n[2], n[3]);
}

Test(layers, bad_layer_keys_give_one_line_with_file_line_and_key_and_exit_2)
{
  write_colour_png(lw_test_path("colour.png"), 16, 16, blotch_colours);
  static const struct {
    const char *text, *want;
  } cases[] = {
    {"[layers]\nnames = a b\nturn = 0 90 45\n", "scene.ini:10: key 'layers.turn': expected 2 numbers"},
    {"[layers]\nnames = a b\ncolors = #000 #12\n", "scene.ini:10: key 'layers.colors': expected 2 colours"},
    {"[layers]\nnames = a b c\nsource = cmyk\n", "scene.ini:10: key 'layers.source': 'cmyk' needs 4 layers"},
    /* a layer named for one ink that draws another: cmyk's layers renamed to
    ** plot yellow first, and cmyk's own names over colours in another order
    ** (a real cyan pen's colour, #00a0e0, is cyan's) */
    {"[layers]\nnames = yellow cyan magenta black\nsource = cmyk\n",
     "scene.ini:9: key 'layers.names': layer 1 is named 'yellow', but its colour #00ffff is a cyan"},
    {"[layers]\nsource = cmyk\ncolors = #00a0e0 #ffff00 #ff00ff #000\n",
     "scene.ini:10: key 'layers.colors': layer 2 is named 'magenta', but its colour #ffff00 is a yellow"},
    /* under a palette: no word of cmyk's order */
    {"[layers]\nnames = cyan magenta\nsource = palette\ncolors = #ff00ff #00ffff\n",
     "scene.ini:9: key 'layers.names': layer 1 is named 'cyan', but its colour #ff00ff is a magenta, which it draws (a "
     "separation draws each layer's colour):"},
    /* (names are matched whatever their case) */
    {"[layers]\nnames = Yellow Cyan Magenta Black\nsource = cmyk\n",
     "scene.ini:9: key 'layers.names': layer 1 is named 'Yellow', but its colour #00ffff is a cyan"},
    {"[layers]\nnames = a\nsource = palette\n", "scene.ini:10: key 'layers.source': 'palette' needs layers.colors"},
    {"[layers]\nnames = a b\ntone_min = 0 0.6\ntone_max = 1 0.5\n",
     "scene.ini:11: key 'layers.tone_max': expected layers.tone_min < layers.tone_max"},
    /* (the bound on the later line is blamed) */
    {"[layers]\nnames = a b\ntone_max = 1 0.5\ntone_min = 0 0.6\n",
     "scene.ini:11: key 'layers.tone_min': expected layers.tone_min < layers.tone_max"},
    {"[layers]\nturn = 0 90\n", "scene.ini:9: key 'layers.turn': needs layers.names"},
    {"[layers]\nnames = a b\npen_width = 0.3 -1\n", "scene.ini:10: key 'layers.pen_width': expected values"},
    {"[layers]\nnames = a b\n[output]\npens = 3\n", "scene.ini:11: key 'output.pens': layers set the pens"},
    /* (a count of colours for the one pen was asked first, and then refused) */
    {"[layers]\nnames = a b\n[output]\npen_colors = #f00 #0f0\n",
     "scene.ini:11: key 'output.pen_colors': layers set the pens' colours: use layers.colors"},
    {"[layers]\nnames = a <b>\n", "scene.ini:9: key 'layers.names': expected names of ASCII letters"},
    {"[layers]\nnames = a b a\n", "scene.ini:9: key 'layers.names': expected names that differ, got 'a' twice"},
    {"[layers]\nnames = ,\n", "scene.ini:9: key 'layers.names': expected at least one name"},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    char text[1024], errs[4096];
    snprintf(text, sizeof text,
             "[scene]\nwidth = 30\nheight = 30\nimage = colour.png\n[init]\nsplines = 5\n\n%s", cases[k].text);
    lw_test_write(lw_test_path("bad.ini"), text, strlen(text));
    char args[256];
    snprintf(args, sizeof args, "run bad.ini --out bad%zu", k);
    cr_assert_eq(run(args, errs, sizeof errs), 2, "case %zu: %s", k, errs);
    cr_assert_not_null(strstr(errs, cases[k].want + strlen("scene.ini")), "case %zu: %s", k, errs);
    cr_assert_not_null(strstr(errs, "bad.ini:"), "case %zu names the file: %s", k, errs);
    cr_assert_eq(strchr(errs, '\n'), errs + strlen(errs) - 1, "case %zu: one line: %s", k, errs);
    char dir[256];
    struct stat sb;
    snprintf(dir, sizeof dir, "%s/bad%zu/final.svg", lw_test_dir, k);
    cr_assert_neq(stat(dir, &sb), 0, "case %zu wrote nothing", k);
  }
  /* the bound given last is blamed: a tone_min raised by --set over the
  ** file's tone_max (the file's line was named) */
  static const char tones[] = "[scene]\nwidth = 30\nheight = 30\nimage = colour.png\n[init]\nsplines = 5\n"
                              "[layers]\nnames = a b\ntone_max = 1 0.5\n";
  lw_test_write(lw_test_path("bad.ini"), tones, strlen(tones));
  char errs[4096];
  cr_assert_eq(run("run bad.ini --out badset --set 'layers.tone_min=0 0.6'", errs, sizeof errs), 2, "%s", errs);
  cr_assert_not_null(strstr(errs, "--set: key 'layers.tone_min': expected layers.tone_min < layers.tone_max"), "%s",
                     errs);
  /* hatching layers of the tone named for inks draw no separation: left alone */
  static const char hatch[] = "[scene]\nwidth = 30\nheight = 30\nimage = colour.png\n[init]\nsplines = 5\n"
                              "segment_length = 2\n[layers]\nnames = cyan magenta\n";
  lw_test_write(lw_test_path("hatch.ini"), hatch, strlen(hatch));
  cr_assert_eq(run("run hatch.ini --out hatchnames --set anneal.sweeps=0", errs, sizeof errs), 0, "%s", errs);
}

/* A CMYK scene whose splines are born and die in their layers: the layer
** goes into state.lw with each spline, so a run stopped and resumed ends
** where the uninterrupted one does, on 1 and 3 threads alike; a state of
** the older kind, without layers, still loads (the index rule gives
** them), and a layer the scene does not have is refused naming the spline. */
Test(layers, born_splines_keep_their_layers_through_checkpoints)
{
  write_colour_png(lw_test_path("colour.png"), 32, 32, blotch_colours);
  char text[2048];
  snprintf(text, sizeof text, "%s%s", colour_scene,
           "[moves]\nfixed_count = 0\nbirth = 0.3\ndeath = 0.3\ngrow = 0.2\nshrink = 0.2\nmax_segments = 5\n");
  lw_test_write(lw_test_path("scene.ini"), text, strlen(text));
  char errs[4096];
  const char *set = "--set anneal.sweeps=30 --set anneal.t_start=1 --set anneal.seed=3 --quiet";
  char cmd[512];
  snprintf(cmd, sizeof cmd, "run scene.ini --out a --threads 1 %s", set);
  cr_assert_eq(run(cmd, errs, sizeof errs), 0, "%s", errs);
  snprintf(cmd, sizeof cmd, "run scene.ini --out b --threads 3 %s --stop-at 11", set);
  cr_assert_eq(run(cmd, errs, sizeof errs), 0, "%s", errs);
  cr_assert_eq(run("resume b --threads 2 --quiet", errs, sizeof errs), 0, "%s", errs);
  char dir[512];
  snprintf(dir, sizeof dir, "%s", lw_test_path(""));
  const char *files[] = {"state.lw", "trace.csv", "final.svg"};
  for (int i = 0; i < 3; i++)
    cr_assert_eq(lw_test_sh("cmp -s %s/a/%s %s/b/%s", dir, files[i], dir, files[i]), 0, "%s differs", files[i]);
  /* births and deaths happened, and every spline line holds a layer */
  cr_assert_neq(lw_test_sh("grep -q '\"splines\": 40,' %s/a/summary.json", dir), 0, "the count never changed");
  cr_assert_eq(lw_test_sh("grep '^spline = ' %s/a/state.lw | grep -qv '^spline = [0-9]* [-0-9.e+]* [0-3]$'", dir), 1,
               "a spline line without its layer");
  /* the older kind of state: no layers */
  cr_assert_eq(lw_test_sh("mkdir -p %s/old && sed 's/^\\(spline = [0-9]* [^ ]*\\) [0-9]*$/\\1/' %s/a/state.lw > "
                          "%s/old/state.lw && cp %s/a/scene.ini %s/old && "
                          "grep -q '^spline = [0-9]* [^ ]*$' %s/old/state.lw", dir, dir, dir, dir, dir, dir), 0);
  cr_assert_eq(run("energy a", errs, sizeof errs), 0, "%s", errs);
  cr_assert_eq(run("energy old", errs, sizeof errs), 0, "%s", errs);
  /* a layer past the scene's four */
  cr_assert_eq(lw_test_sh("mkdir -p %s/bad && sed '0,/^spline = /s/^\\(spline = [0-9]* [^ ]*\\) [0-9]*$/\\1 7/' "
                          "%s/a/state.lw > %s/bad/state.lw && cp %s/a/scene.ini %s/bad", dir, dir, dir, dir, dir), 0);
  cr_assert_eq(run("energy bad", errs, sizeof errs), 2);
  cr_assert(strstr(errs, "spline 0 is of layer 7, but the scene has 4 layers"), "%s", errs);
}

/* The photo preset keeps lines apart by pen (layers.apart = pen, written to
** the run's scene.ini), and a colour run of it, with its domains, is the
** same on 1 and 2 threads and through a stop and resume.  source = cmyk
** needs no names.  A user's apart outranks the preset's, and a run's
** scene.ini written before the key existed resumes as it ran. */
/* photo.ini: the photo preset on A6 over a blotchy colour picture, in
** CMYK, with the given [anneal] lines. */
static void write_colour_photo_scene(const char *anneal)
{
  write_colour_png(lw_test_path("colour.png"), 48, 64, blotch_colours);
  char scene[512];
  snprintf(scene, sizeof scene,
           "[scene]\npreset = photo\npage = a6\nimage = colour.png\n[layers]\nsource = cmyk\n[anneal]\n%s", anneal);
  lw_test_write(lw_test_path("photo.ini"), scene, strlen(scene));
}

Test(layers, the_photo_preset_draws_colour_pens_kept_apart_by_pen_on_any_thread_count)
{
  write_colour_photo_scene("sweeps = 16\nseed = 5\n");
  char errs[4096];
  cr_assert_eq(run("run photo.ini --out p1 --threads 1 --quiet", errs, sizeof errs), 0, "%s", errs);
  cr_assert_eq(run("run photo.ini --out p2 --threads 2 --quiet --stop-at 7", errs, sizeof errs), 0, "%s", errs);
  cr_assert_eq(run("resume p2 --threads 2 --quiet", errs, sizeof errs), 0, "%s", errs);
  char dir[512];
  snprintf(dir, sizeof dir, "%s", lw_test_path(""));
  cr_assert_eq(lw_test_sh("grep -qx 'apart = pen' %s/p1/scene.ini && grep -qx 'domains = [2-9]' %s/p1/scene.ini", dir,
                          dir),
               0, "the preset's apart or domains");
  const char *files[] = {"state.lw", "trace.csv", "final.svg"};
  for (int i = 0; i < 3; i++)
    cr_assert_eq(lw_test_sh("cmp -s %s/p1/%s %s/p2/%s", dir, files[i], dir, files[i]), 0, "%s differs", files[i]);
  /* cmyk without layers.names names its own four pens */
  cr_assert_eq(lw_test_sh("grep -c 'inkscape:label=\"[1-4] \\(cyan\\|magenta\\|yellow\\|black\\)\"' %s/p1/final.svg | "
                          "grep -qx 4",
                          dir),
               0, "the pens of cmyk are not cyan, magenta, yellow and black");
  cr_assert_eq(run("run photo.ini --out pa --quiet --set layers.apart=all --set anneal.sweeps=4", errs, sizeof errs),
               0, "%s", errs);
  cr_assert_eq(lw_test_sh("grep -qx 'apart = all' %s/pa/scene.ini", dir), 0);
  /* a run begun before layers.apart existed ran with every line apart: its
  ** scene.ini has no apart, and it resumes as it ran, not as the preset
  ** would set it now (the state's energy would not match) */
  cr_assert_eq(run("run photo.ini --out old --quiet --set layers.apart=all --set anneal.sweeps=4 --stop-at 2", errs,
                   sizeof errs),
               0, "%s", errs);
  cr_assert_eq(lw_test_sh("sed -i '/^apart = /d' %s/old/scene.ini && "
                          "sed -i '/^scene_hash = /d; /^scene_keys = /d; /^# checksum /d' %s/old/state.lw",
                          dir, dir), 0);
  cr_assert_eq(run("resume old --quiet", errs, sizeof errs), 0, "%s", errs);
  cr_assert_eq(run("energy old", errs, sizeof errs), 0, "%s", errs);
  /* (its scene_hash is of the keys its scene.ini holds) */
  cr_assert_eq(lw_test_sh("k='^scene_[hk]\\|^# checksum '; grep -v \"$k\" %s/pa/state.lw > %s/a1; grep -v \"$k\" "
                          "%s/old/state.lw > %s/a2; cmp -s %s/a1 %s/a2", dir, dir, dir, dir, dir, dir),
               0, "the old run resumed differently");
}

/* The point of a spline's segment g at parameter s (cubic Bezier of the
** nodes' points and vectors, r'(node) = 3 v). */
static void segment_point(const lw_node *a, double s, double *x, double *y)
{
  const lw_node *b = a + 1;
  const double u = 1.0 - s, w0 = u * u * u, w1 = 3 * u * u * s, w2 = 3 * u * s * s, w3 = s * s * s;
  *x = w0 * a->px + w1 * (a->px + a->vx) + w2 * (b->px - b->vx) + w3 * b->px;
  *y = w0 * a->py + w1 * (a->py + a->vy) + w2 * (b->py - b->vy) + w3 * b->py;
}

/* A colour run kept apart by pen starts with every pen's lines apart from
** that pen's others, as the placement spaced them.  The placement gave
** each spline its layer by its index, and the renumbering of the splines
** along the page (sys_splines.c) came after it: where no spline was cut
** (which stored the layers) the model took the layer from the new index,
** so the pens were shuffled, lines lay across their own pen's (412 pairs
** closer than the spacing on a coffee cup at A6), and every pen sat on
** the picture's mean colour. */
Test(layers, a_colour_run_kept_apart_by_pen_starts_with_each_pens_lines_apart)
{
  write_colour_photo_scene("seed = 3\n");
  char errs[4096];
  cr_assert_eq(run("run photo.ini --out s --threads 1 --quiet --stop-at 0", errs, sizeof errs), 0, "%s", errs);
  cr_assert_eq(lw_test_sh("grep -qx 'apart = pen' %s/scene.ini", lw_test_path("s")), 0);
  lw_state st = {0};
  lw_error err = {0};
  cr_assert_eq(lw_state_read(&st, lw_test_path("s/state.lw"), &err), LW_OK, "%s", err.msg);
  const lw_splines *sp = st.sp;
  cr_assert(sp && sp->layer && sp->n_splines > 50, "splines %zu", sp ? sp->n_splines : 0);
  /* 16 points a segment (segments of a few mm: under 0.5 mm apart), the
  ** spacing less a margin for the points between them */
  enum { K = 16 };
  const double d = 0.25;
  double *x = malloc(sp->n_segments * K * sizeof *x), *y = malloc(sp->n_segments * K * sizeof *y);
  cr_assert(x && y);
  for (size_t g = 0; g < sp->n_segments; g++)
    for (int k = 0; k < K; k++)
      segment_point(&sp->node[lw_segment_node(sp, g)], (k + 0.5) / K, &x[g * K + k], &y[g * K + k]);
  size_t same = 0, across = 0;
  for (size_t g = 0; g < sp->n_segments; g++)
    for (size_t h = g + 1; h < sp->n_segments; h++) {
      const size_t i = sp->seg_spline[g], j = sp->seg_spline[h];
      if (i == j) continue;
      for (int q = 0; q < K * K; q++) {
        const double dx = x[g * K + q / K] - x[h * K + q % K], dy = y[g * K + q / K] - y[h * K + q % K];
        if (dx * dx + dy * dy >= d * d) continue;
        if (sp->layer[i] == sp->layer[j]) same++;
        else across++;
      }
    }
  free(x);
  free(y);
  cr_assert_eq(same, 0, "%zu close point pairs within pens (%zu across)", same, across);
  cr_assert_gt(across, 0, "no pens overlap: the test does not tell");
  lw_state_clear(&st);
}
