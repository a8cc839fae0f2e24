/*
** test_gradient.c -- every term's gradient (gradient.h) against central
** differences of lw_energy_compute, one term at a time, on random regular
** splines and every kind of potential, field and boundary.
**
** Tolerance, in the style of HOOMD's force/energy test: coordinate x_i is
** stepped by h_i = 1e-6 max(|x_i|, l) (l the mean segment length, the scale
** of the shapes) and the central difference g_fd = (E(x+h) - E(x-h)) / 2h
** is compared with the analytic g as |g - g_fd| <= 1e-5 max(|g|, scale),
** scale the root mean square of the analytic gradient (the typical size of
** a component, |E_segment| / l).  The difference errs by
**   truncation  h^2 |E'''| / 6 ~ 1e-12 (l^2 / l^3) |E_seg| = 1e-12 scale, and
**   rounding    ~ eps |E| / h ~ 1e-16 N_seg |E_seg| / (1e-6 l) = 1e-10 N_seg scale
** (N_seg ~ 20 segments here), both far below 1e-5 scale; a wrong formula
** errs by the size of the gradient itself.  Points within h of a kink (a
** grid's cell line, a rect's medial axis, r'.v = 0 of the axial field) make
** the difference straddle two slopes; there the step is shortened until the
** differences at h and h/4 agree (check_term).
*/
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>

#include "linewise/gradient.h"
#include "linewise/model.h"
#include "linewise/scene.h"
#include "testutil.h"

static lw_params base_params(void)
{
  lw_params p;
  lw_params_defaults(&p);
  p.width = 120;
  p.height = 100;
  p.margin = 5;
  return p;
}

static void scene_with(lw_scene *sc, const lw_params *p)
{
  lw_error err;
  cr_assert_eq(lw_scene_init(sc, p, &err), LW_OK, "%s", err.msg);
}

/* n random smooth splines of segs segments inside [30, 90] x [25, 75]:
** a walk of slowly turning chords, handles near a third of the chord with
** random length and angle; regular for the scene (asserted). */
static lw_splines *random_splines(const lw_scene *sc, size_t n, size_t segs, uint64_t seed)
{
  size_t s[16];
  for (size_t i = 0; i < n; i++) s[i] = segs;
  rng_seed(seed);
  for (int attempt = 0; attempt < 100; attempt++) {
    lw_splines *sp = lw_splines_new(n, s, NULL);
    cr_assert_not_null(sp);
    for (size_t i = 0; i < n; i++) {
      lw_node *nd = &sp->node[sp->first[i]];
      double x = urand(40, 80), y = urand(35, 65), th = urand(0, 2 * M_PI), L = 0;
      for (size_t k = 0; k <= segs; k++) {
        double c = urand(4, 7);
        nd[k].px = x;
        nd[k].py = y;
        th += urand(-0.5, 0.5);
        x += c * cos(th);
        y += c * sin(th);
        L += c;
      }
      /* handles along the neighbours' chord, a third of a segment long, with
      ** random length and a small random turn */
      for (size_t k = 0; k <= segs; k++) {
        const lw_node *a = &nd[k > 0 ? k - 1 : k], *b = &nd[k < segs ? k + 1 : k];
        double dx = b->px - a->px, dy = b->py - a->py, f = (k > 0 && k < segs ? 6.0 : 3.0) / urand(0.8, 1.2);
        double t = urand(-0.2, 0.2);
        nd[k].vx = (cos(t) * dx - sin(t) * dy) / f;
        nd[k].vy = (sin(t) * dx + cos(t) * dy) / f;
      }
      sp->rest_length[i] = L * urand(0.6, 1.4);
    }
    lw_error err;
    if (lw_model_check_regular(sc, sp, "test", &err) == LW_OK) return sp;
    lw_splines_free(sp);
  }
  cr_assert_fail("no regular random splines");
  return NULL;
}

static double mean_segment_length(const lw_scene *sc, const lw_splines *sp)
{
  lw_samples s;
  double L = 0;
  for (size_t g = 0; g < sp->n_segments; g++) {
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    lw_segment_sample(&sc->quad, a, a + 1, &s);
    L += s.length;
  }
  return L / (double)sp->n_segments;
}

static double term_energy(const lw_scene *sc, const lw_splines *sp, int t)
{
  double term[LW_TERM_COUNT];
  lw_energy_compute(sc, sp, term, NULL);
  return term[t];
}

/* The central difference of term t in coordinate c of x (a node's px py vx vy) */
static double central(const lw_scene *sc, const lw_splines *sp, int t, double *x, int c, double h)
{
  double x0 = x[c];
  x[c] = x0 + h;
  double ep = term_energy(sc, sp, t);
  x[c] = x0 - h;
  double em = term_energy(sc, sp, t);
  x[c] = x0;
  return (ep - em) / (2 * h);
}

/* Term t's gradient against central differences at every coordinate, with
** steps of h_rel times the coordinate or the mean segment, quartered up to
** `shorter` times, and tolerance tol_rel times the larger of the gradient
** and its rms; returns how many coordinates disagree (and reports the
** first few). */
static int check_term_at(const lw_scene *sc, lw_splines *sp, int t, const char *what, double h_rel, int shorter,
                         double tol_rel)
{
  lw_error err = {0};
  lw_node *g = calloc(sp->n_nodes, sizeof *g);
  double term[LW_TERM_COUNT];
  double e = lw_energy_gradient(sc, sp, 1u << t, g, term, &err);
  cr_assert(isfinite(e), "%s: energy %g (%s)", what, e, err.msg);
  cr_assert_eq(e, term[t], "%s: the total is the selected term's", what);
  cr_assert_eq(term[t], term_energy(sc, sp, t), "%s: the same energy as lw_energy_compute", what);
  const double l = mean_segment_length(sc, sp);
  double rms = 0;
  for (size_t k = 0; k < sp->n_nodes; k++) {
    const double *gk = &g[k].px;
    for (int c = 0; c < 4; c++) rms += gk[c] * gk[c];
  }
  rms = sqrt(rms / (4.0 * (double)sp->n_nodes));
  cr_assert(rms > 0, "%s: a gradient of zero tests nothing", what);
  int bad = 0;
  for (size_t k = 0; k < sp->n_nodes; k++) {
    double *x = &sp->node[k].px;
    const double *gk = &g[k].px;
    for (int c = 0; c < 4; c++) {
      double x0 = x[c], h = h_rel * fmax(fabs(x0), l), tol = tol_rel * fmax(fabs(gk[c]), rms);
      double fd = central(sc, sp, t, x, c, h);
      /* A kink of an interpolation within h of a sample: the differences
      ** at h and h/4 disagree.  Shorter steps until two agree leave the
      ** kink outside (a wrong gradient disagrees at every step). */
      for (int r = 0; r < shorter; r++) {
        double fq = central(sc, sp, t, x, c, h / 4);
        if (fabs(fq - fd) <= 0.1 * tol) break;
        fd = fq;
        h /= 4;
      }
      if (!(fabs(gk[c] - fd) <= tol)) {
        if (bad < 4)
          cr_log_error("%s: node %zu coordinate %d: analytic %.12g, central difference %.12g (scale %.3g)", what, k,
                       c, gk[c], fd, rms);
        bad++;
      }
    }
  }
  free(g);
  return bad;
}

/* Term t alone on three sets of random splines, steps and tolerance as
** check_term_at. */
static void check_scene_at(const lw_scene *sc, int t, const char *what, double h_rel, int shorter, double tol_rel)
{
  for (uint64_t seed = 1; seed <= 3; seed++) {
    lw_splines *sp = random_splines(sc, 3, 5, 0x9e3779b9u * seed + (uint64_t)t);
    int bad = check_term_at(sc, sp, t, what, h_rel, shorter, tol_rel);
    cr_expect_eq(bad, 0, "%s (seed %llu): %d coordinates off", what, (unsigned long long)seed, bad);
    lw_splines_free(sp);
  }
}

static void check_scene(const lw_scene *sc, int t, const char *what) { check_scene_at(sc, t, what, 1e-6, 6, 1e-5); }

Test(gradient, strain_both_modes)
{
  for (int mode = 0; mode < 2; mode++) {
    lw_params p = base_params();
    p.strain = 2.5;
    p.strain_mode = mode;
    lw_scene sc;
    scene_with(&sc, &p);
    check_scene(&sc, LW_TERM_STRAIN, mode ? "strain per segment" : "strain per spline");
    lw_scene_clear(&sc);
  }
}

Test(gradient, bending)
{
  lw_params p = base_params();
  p.bending = 1.7;
  lw_scene sc;
  scene_with(&sc, &p);
  check_scene(&sc, LW_TERM_BENDING, "bending");
  lw_scene_clear(&sc);
}

Test(gradient, parametrisation)
{
  lw_params p = base_params();
  p.parametrisation = 0.9;
  lw_scene sc;
  scene_with(&sc, &p);
  check_scene(&sc, LW_TERM_PARAM, "parametrisation");
  lw_scene_clear(&sc);
}

/* Every term a scene's keys turn on, all on at once, each against its
** central differences: a term added later is covered here once it is on
** (a contributor's wrong sign in a new term's gradient passed every suite,
** and the quench stalled far above its minimum).  The tone needs a picture
** (tone_term below), the user term has no gradient (user_term_refused), and
** the pair term's near field is checked in tests/test_pairgrad.c, within
** its own rounding (its sum here differs from the energy's in the last
** bits). */
Test(gradient, every_term_at_once)
{
  lw_params p = base_params();
  p.strain = 2;
  p.bending = 0.8;
  p.potential_coef = 0.5;
  p.potential = LW_POT_RADIAL;
  p.field_coef = -0.4;
  p.field = LW_FLD_VORTEX;
  p.pair = 0.05;
  p.pair_cutoff = 8;
  p.boundary_coef = 0.3;
  p.parametrisation = 0.6;
  p.dyn_force_x = 0.02;
  p.dyn_force_y = -0.03;
  p.chem_spline = 0.4;
  p.chem_length = -0.02;
  lw_scene sc;
  scene_with(&sc, &p);
  for (int t = 0; t < LW_TERM_COUNT; t++) {
    cr_assert(sc.on[t] || t == LW_TERM_TONE || t == LW_TERM_USER,
              "term %s is off here: turn it on (tests/test_gradient.c) so that its gradient is checked",
              lw_term_names[t]);
    if (sc.on[t] && t != LW_TERM_PAIR) check_scene(&sc, t, lw_term_names[t]);
  }
  lw_scene_clear(&sc);
}

/* A grid of random values over the page (spacing ~ 7 mm: several cells per
** segment), ncomp values a node. */
static lw_grid2d *random_grid(int ncomp, uint64_t seed)
{
  lw_grid2d *g = lw_grid2d_new(17, 15, ncomp, 0.0, 0.0, 7.5, 7.1, NULL);
  cr_assert_not_null(g);
  rng_seed(seed);
  for (int k = 0; k < 17 * 15 * ncomp; k++) g->data[k] = urand(-1, 1);
  return g;
}

Test(gradient, potential_every_kind)
{
  const int kinds[] = {LW_POT_CONSTANT, LW_POT_RAMP, LW_POT_RADIAL};
  const char *names[] = {"potential constant", "potential ramp", "potential radial"};
  for (int k = 0; k < 4; k++) {
    lw_params p = base_params();
    p.potential_coef = 0.8;
    p.potential = kinds[k < 3 ? k : 0];
    p.potential_value = 1.3;
    p.potential_angle = 37;
    p.center_x = 11;
    p.center_y = 93;
    lw_scene sc;
    scene_with(&sc, &p);
    if (k == 3) { /* the image potential's kind: a bilinear grid */
      lw_potential_clear(&sc.potential);
      sc.potential.kind = LW_POTENTIAL_GRID;
      sc.potential.grid = random_grid(1, 77);
    }
    check_scene(&sc, LW_TERM_POTENTIAL, k < 3 ? names[k] : "potential grid");
    lw_scene_clear(&sc);
  }
}

Test(gradient, field_every_kind_signed_and_axial)
{
  const int kinds[] = {LW_FLD_CONSTANT, LW_FLD_RADIAL, LW_FLD_VORTEX, LW_FLD_WAVES};
  char what[96];
  for (int k = 0; k < 6; k++)
    for (int mode = 0; mode < 2; mode++) {
      lw_params p = base_params();
      p.field_coef = -0.6;
      p.field = kinds[k < 4 ? k : 0];
      p.field_mode = mode ? LW_FIELDMODE_AXIAL : LW_FIELDMODE_SIGNED;
      p.field_angle = 23;
      p.field_wavelength = 31;
      p.field_amplitude = 4;
      p.center_x = 13;
      p.center_y = 9;
      lw_scene sc;
      scene_with(&sc, &p);
      if (k >= 4) { /* the picture's fields: gradient (grid) and etf (grid_axial) */
        lw_field_clear(&sc.field);
        sc.field.kind = k == 4 ? LW_FIELD_GRID : LW_FIELD_GRID_AXIAL;
        sc.field.grid = random_grid(2, 91 + (uint64_t)k);
      }
      snprintf(what, sizeof what, "field kind %d %s", k, mode ? "axial" : "signed");
      check_scene(&sc, LW_TERM_FIELD, what);
      lw_scene_clear(&sc);
    }
}

Test(gradient, boundary_every_kind)
{
  for (int k = 0; k < 4; k++) {
    lw_params p = base_params();
    p.boundary_coef = 3.0;
    p.boundary = k == 1 ? LW_BND_CIRCLE : LW_BND_RECT;
    lw_scene sc;
    scene_with(&sc, &p);
    if (k == 2) { /* a pentagon around the splines' region */
      double x[5], y[5];
      for (int v = 0; v < 5; v++) {
        x[v] = 60 + 58 * cos(0.3 + 2 * M_PI * v / 5);
        y[v] = 50 + 58 * sin(0.3 + 2 * M_PI * v / 5);
      }
      lw_boundary_clear(&sc.boundary);
      cr_assert_eq(lw_boundary_polygon(&sc.boundary, 5, x, y, NULL), LW_OK);
    } else if (k == 3) { /* a mask: signed distances of an ellipse-like blob, on a grid */
      lw_boundary_clear(&sc.boundary);
      lw_grid2d *g = lw_grid2d_new(25, 21, 1, 0.0, 0.0, 5.0, 5.0, NULL);
      cr_assert_not_null(g);
      for (int j = 0; j < 21; j++)
        for (int i = 0; i < 25; i++) {
          double dx = 5.0 * i - 60, dy = 5.0 * j - 50;
          g->data[j * 25 + i] = sqrt(dx * dx + 1.4 * dy * dy) - 57 + 2 * sin(0.1 * dx * dy / 10);
        }
      sc.boundary.kind = LW_BOUNDARY_MASK;
      sc.boundary.sdt = g;
    }
    const char *names[] = {"boundary rect", "boundary circle", "boundary polygon", "boundary mask"};
    check_scene(&sc, LW_TERM_BOUNDARY, names[k]);
    lw_scene_clear(&sc);
  }
}

/* The picture's potential, edge tangent flow and mask through the image
** pipeline: the same interpolations the energy reads. */
Test(gradient, image_scene)
{
  const char *root = getenv("LW_ROOT");
  char path[512];
  snprintf(path, sizeof path, "%s/params/picture.png", root ? root : ".");
  lw_params p = base_params();
  snprintf(p.image, sizeof p.image, "%s", path);
  p.potential = LW_POT_IMAGE;
  p.potential_coef = 2.0;
  p.field = LW_FLD_ETF;
  p.field_coef = -1.0;
  lw_scene sc;
  scene_with(&sc, &p);
  check_scene(&sc, LW_TERM_POTENTIAL, "image potential");
  check_scene(&sc, LW_TERM_FIELD, "image etf field");
  lw_scene_clear(&sc);
}

/* The tone term (tone.h): each sample's footprint moves and stretches with
** the sample, and the gradient is that of the raster the energy reads.  At
** blurs of 1 and 0.5 mm (1.8 and 2.2 raster pixels of 0.56 and 0.23 mm),
** and with two pens of a palette, each with its own target and plane of
** the raster.
** The differences take steps of 2e-4 of a coordinate, shortened at most
** three times, and agree within 5e-3 of the gradient's scale: the raster's
** fixed point (2^-33 of ink a pixel and footprint) makes shorter steps
** noise, and the footprint's cut (a kink where a pixel centre crosses rho)
** lies within a step at some coordinates.  A footprint's slope without its
** normalisation term, or a sample's length element left out, is off by
** tenths at most coordinates.  The fourth case samples the tone at 4
** nodes (energy.tone_quadrature) and every other term at 8: its gradient
** taken through the 8 nodes' basis, or with their weights, is off. */
Test(gradient, tone_term)
{
  const char *root = getenv("LW_ROOT");
  const double blur[] = {1.0, 0.5};
  static const char *const what[] = {"tone, blur 1 mm", "tone, blur 0.5 mm", "tone, two pens", "tone at 4 nodes"};
  for (int k = 0; k < 4; k++) {
    lw_params p = base_params();
    snprintf(p.image, sizeof p.image, "%s/params/picture.png", root ? root : ".");
    p.tone = 4.0;
    p.tone_blur = blur[k < 2 ? k : 0];
    p.pen_width = 0.5;
    if (k == 3) p.tone_quadrature = 4;
    if (k == 2) {
      snprintf(p.ly_names, sizeof p.ly_names, "a b");
      p.ly_source = LW_LSRC_PALETTE;
      snprintf(p.ly_colors, sizeof p.ly_colors, "#303030 #a0a0a0");
      snprintf(p.ly_pen_width, sizeof p.ly_pen_width, "0.3 0.6");
    }
    lw_scene sc;
    scene_with(&sc, &p);
    cr_assert(sc.on[LW_TERM_TONE] && sc.layers.n == (k == 2 ? 2 : 0));
    cr_assert_eq(sc.tone_quad.n, k == 3 ? 4 : sc.quad.n);
    check_scene_at(&sc, LW_TERM_TONE, what[k], 2e-4, 3, 5e-3);
    lw_scene_clear(&sc);
  }
}

/* The splines row's `blocked` (system.h): the nodes of exactly the segments
** a point would make irregular or take outside the boundary, and nothing
** else; what it was given stays marked. */
Test(gradient, blocked_marks_the_segments_at_a_wall)
{
  lw_params p = base_params();
  p.bending = 1;
  p.boundary_coef = 0.5;
  lw_scene sc;
  scene_with(&sc, &p);
  lw_error err = {0};
  lw_model *m = lw_model_new(&sc, random_splines(&sc, 3, 4, 77), &err);
  cr_assert_not_null(m, "%s", err.msg);
  lw_system *sys = lw_splines_view(m, &err);
  cr_assert_not_null(sys);
  const lw_system_type *t = sys->type;
  size_t n = t->n_coords(sys->state);
  double *x = malloc(n * sizeof *x);
  unsigned char *held = calloc(n, 1);
  t->get_coords(sys->state, x);
  cr_assert_eq(t->blocked(sys->state, x, held, NULL), 0);
  for (size_t i = 0; i < n; i++) cr_assert_eq(held[i], 0);
  /* spline 1's third node outside the page: its two segments; spline 2's
  ** first handle folded back over its segment: that segment */
  size_t k1 = m->sp->first[1] + 2, k2 = m->sp->first[2];
  held[1] = 1; /* a mark from before stays */
  x[4 * k1] = -50;
  x[4 * k2 + 2] = -40 * (x[4 * k2 + 4] - x[4 * k2]);
  x[4 * k2 + 3] = -40 * (x[4 * k2 + 5] - x[4 * k2 + 1]);
  cr_assert_eq(t->blocked(sys->state, x, held, NULL), 3);
  for (size_t k = 0; k < m->sp->n_nodes; k++) {
    int want = (k + 1 >= k1 && k <= k1 + 1) || k == k2 || k == k2 + 1;
    for (int c = 0; c < 4; c++)
      cr_assert_eq(held[4 * k + c], want || (k == 0 && c == 1), "node %zu coordinate %d", k, c);
  }
  cr_assert_neq(m->sp->node[k1].px, -50.0, "the state is left as it was");
  free(x);
  free(held);
  lw_system_free(sys);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

/* The sum over every term equals lw_energy_compute's total and each term's
** value, and the gradient of the sum is the sum of the gradients. */
Test(gradient, total_matches_energy_compute)
{
  lw_params p = base_params();
  p.strain = 2;
  p.bending = 0.5;
  p.potential_coef = 0.3;
  p.potential = LW_POT_RADIAL;
  p.field_coef = 0.4;
  p.field = LW_FLD_VORTEX;
  p.boundary_coef = 1.5;
  p.parametrisation = 0.2;
  lw_scene sc;
  scene_with(&sc, &p);
  lw_splines *sp = random_splines(&sc, 4, 6, 12345);
  double t1[LW_TERM_COUNT], t2[LW_TERM_COUNT];
  lw_node *g = calloc(sp->n_nodes, sizeof *g), *gt = calloc(sp->n_nodes, sizeof *gt);
  lw_error err = {0};
  double e = lw_energy_gradient(&sc, sp, LW_GRAD_ALL, g, t1, &err);
  double ref = lw_energy_compute(&sc, sp, t2, NULL);
  cr_assert_eq(e, ref, "total %.17g, lw_energy_compute %.17g", e, ref);
  for (int t = 0; t < LW_TERM_COUNT; t++) cr_assert_eq(t1[t], t2[t], "term %s", lw_term_names[t]);
  lw_node *sum = calloc(sp->n_nodes, sizeof *sum);
  for (int t = 0; t < LW_TERM_COUNT; t++) {
    if (!sc.on[t]) continue;
    lw_energy_gradient(&sc, sp, 1u << t, gt, NULL, &err);
    for (size_t k = 0; k < sp->n_nodes; k++) {
      sum[k].px += gt[k].px;
      sum[k].py += gt[k].py;
      sum[k].vx += gt[k].vx;
      sum[k].vy += gt[k].vy;
    }
  }
  for (size_t k = 0; k < sp->n_nodes; k++) {
    cr_assert(lw_close_rel(g[k].px, sum[k].px, 1e-12, 1e-9));
    cr_assert(lw_close_rel(g[k].vy, sum[k].vy, 1e-12, 1e-9));
  }
  free(sum);
  free(g);
  free(gt);
  lw_splines_free(sp);
  lw_scene_clear(&sc);
}

/* Forbidden states: outside the boundary or irregular, the energy is +inf. */
Test(gradient, forbidden_states_are_infinite)
{
  lw_params p = base_params();
  p.boundary_coef = 1;
  p.bending = 1;
  lw_scene sc;
  scene_with(&sc, &p);
  lw_splines *sp = random_splines(&sc, 2, 3, 5);
  lw_node *g = calloc(sp->n_nodes, sizeof *g);
  sp->node[0].px = -3; /* an end point off the page */
  cr_assert(isinf(lw_energy_gradient(&sc, sp, LW_GRAD_ALL, g, NULL, NULL)));
  lw_splines_free(sp);
  sp = random_splines(&sc, 2, 3, 5);
  sp->node[1].vx = sp->node[1].vy = 0; /* speed 0 at a node: irregular */
  cr_assert(isinf(lw_energy_gradient(&sc, sp, 1u << LW_TERM_BENDING, g, NULL, NULL)));
  free(g);
  lw_splines_free(sp);
  lw_scene_clear(&sc);
}

static double user_fn(const lw_samples *s, const lw_quad *q, const void *data)
{
  (void)q;
  (void)data;
  return s->x[0];
}

/* The user term has no gradient: a mask selecting it is refused; the pair
** term is delegated to lw_pair_gradient. */
Test(gradient, user_term_refused)
{
  lw_params p = base_params();
  p.bending = 1;
  lw_scene sc;
  scene_with(&sc, &p);
  lw_error err = {0};
  cr_assert_eq(lw_scene_set_user_term(&sc, 1.0, user_fn, NULL, &err), LW_OK);
  lw_splines *sp = random_splines(&sc, 1, 3, 9);
  lw_node *g = calloc(sp->n_nodes, sizeof *g);
  cr_assert(isnan(lw_energy_gradient(&sc, sp, LW_GRAD_ALL, g, NULL, &err)));
  cr_assert_eq(err.code, LW_EINPUT);
  cr_assert(strstr(err.msg, "user term"), "%s", err.msg);
  err.code = LW_OK;
  cr_assert(isfinite(lw_energy_gradient(&sc, sp, 1u << LW_TERM_BENDING, g, NULL, &err)));
  free(g);
  lw_splines_free(sp);
  lw_scene_clear(&sc);
}

/* The splines row: coordinates are the nodes in order, set_coords moves the
** state and refreshes every running total, gradient() is the gradient of
** every term; non-finite coordinates are refused. */
Test(gradient, splines_row_coordinates_and_gradient)
{
  lw_params p = base_params();
  p.strain = 1;
  p.bending = 0.5;
  p.boundary_coef = 1;
  lw_scene sc;
  scene_with(&sc, &p);
  lw_splines *sp = random_splines(&sc, 2, 4, 44);
  lw_splines *ref = lw_splines_clone(sp);
  lw_error err = {0};
  lw_model *m = lw_model_new(&sc, sp, &err);
  cr_assert_not_null(m, "%s", err.msg);
  lw_system *sys = lw_splines_view(m, &err);
  const lw_system_type *t = sys->type;
  size_t n = t->n_coords(sys->state);
  cr_assert_eq(n, 4 * ref->n_nodes);
  double *x = malloc(n * sizeof *x), *g = malloc(n * sizeof *g);
  t->get_coords(sys->state, x);
  cr_assert_eq(x[4 * 3 + 2], ref->node[3].vx);
  lw_node *gr = calloc(ref->n_nodes, sizeof *gr);
  double e = t->gradient(sys->state, g, &err);
  cr_assert_eq(e, lw_energy_gradient(&sc, ref, LW_GRAD_ALL, gr, NULL, &err));
  cr_assert_eq(g[4 * 5 + 1], gr[5].py);
  cr_assert_eq(e, lw_system_total(sys));
  x[4 * 2] += 0.3; /* move one point */
  cr_assert_eq(t->set_coords(sys->state, x, &err), LW_OK);
  ref->node[2].px += 0.3;
  double term[LW_TERM_COUNT];
  double e2 = lw_energy_compute(&sc, ref, term, NULL);
  cr_assert(e2 != e);
  cr_assert(lw_close_rel(lw_system_total(sys), e2, 1e-12, 1e-12), "%.17g %.17g", lw_system_total(sys), e2);
  x[7] = NAN;
  cr_assert_eq(t->set_coords(sys->state, x, &err), LW_EINPUT);
  cr_assert_eq(m->sp->node[1].vy, ref->node[1].vy, "a refused set leaves the state");
  free(x);
  free(g);
  free(gr);
  lw_system_free(sys);
  lw_model_free(m);
  lw_splines_free(ref);
  lw_scene_clear(&sc);
}

/* ---- the quench (quench.h) ------------------------------------------ */

#include "linewise/dynamics.h"
#include "linewise/quench.h"
#include "linewise/sys_splines.h"

/* Quenches random splines on sc through the splines row; returns the
** report, the model left in *out (the caller frees it). */
static lw_quench_report quench_splines(const lw_scene *sc, size_t n, size_t segs, uint64_t seed, lw_model **out)
{
  lw_error err = {0};
  lw_model *m = lw_model_new(sc, random_splines(sc, n, segs, seed), &err);
  cr_assert_not_null(m, "%s", err.msg);
  lw_system *sys = lw_splines_view(m, &err);
  cr_assert_not_null(sys);
  lw_quench_report r;
  const lw_quench_opts o = {1e-6, 5000, 0.0, NULL, NULL};
  cr_assert_eq(lw_quench_run(sys, &o, &r, &err), LW_OK, "%s", err.msg);
  lw_system_free(sys);
  *out = m;
  return r;
}

/* The state a quench leaves is allowed: finite from scratch (inside the
** boundary, end points too), regular, and its running totals are fresh. */
static void assert_allowed(const lw_scene *sc, const lw_model *m, double e)
{
  double term[LW_TERM_COUNT];
  double ref = lw_energy_compute(sc, m->sp, term, NULL);
  cr_assert(isfinite(ref), "the quenched state is forbidden");
  cr_assert_eq(lw_model_check_regular(sc, m->sp, "quenched", NULL), LW_OK);
  cr_assert(lw_close_rel(e, ref, 1e-9, 1e-9), "reported %.17g, from scratch %.17g", e, ref);
  cr_assert(lw_close_rel(lw_model_total(m), ref, 1e-9, 1e-9));
}

Test(quench, lowers_the_energy_to_a_small_gradient)
{
  lw_params p = base_params();
  p.strain = 2;
  p.bending = 0.5;
  p.potential_coef = 0.05; /* a smooth pull against the boundary's barrier */
  p.potential = LW_POT_RAMP;
  p.potential_angle = 30;
  p.boundary = LW_BND_CIRCLE; /* smooth: the rect's distance has a kink on its medial axis */
  p.boundary_coef = 0.5;
  p.parametrisation = 0.2;
  lw_scene sc;
  scene_with(&sc, &p);
  lw_model *m;
  lw_quench_report r = quench_splines(&sc, 3, 4, 2024, &m);
  cr_log_info("quench: %.10g -> %.10g, |g| %.3g -> %.3g, %ld iterations, %ld evaluations", r.energy_before,
              r.energy_after, r.gradient_before, r.gradient_after, r.iterations, r.evaluations);
  cr_assert(r.energy_after < r.energy_before - 1e-3 * fabs(r.energy_before), "%g -> %g", r.energy_before,
            r.energy_after);
  cr_assert(r.converged && r.gradient_after <= 1e-6, "|g| = %g after %ld iterations", r.gradient_after, r.iterations);
  cr_assert(r.gradient_before > 1e3 * r.gradient_after);
  assert_allowed(&sc, m, r.energy_after);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

/* A potential that pulls the splines toward the circle's edge against a
** weak boundary term, and a tight min_speed with strain pulling the splines
** short: the minimiser's trial steps run into the walls (counted) and are
** shortened; the state it ends in is allowed. */
Test(quench, never_leaves_the_allowed_set)
{
  lw_params p = base_params();
  p.strain = 5;
  p.bending = 0.5;
  p.potential_coef = 3;
  p.potential = LW_POT_RAMP;
  p.potential_angle = 180; /* Phi falls toward +x */
  p.boundary = LW_BND_CIRCLE;
  p.boundary_coef = 1e-4;
  lw_scene sc;
  scene_with(&sc, &p);
  lw_model *m;
  lw_quench_report r = quench_splines(&sc, 3, 4, 77, &m);
  cr_log_info("boundary: %.10g -> %.10g, %ld iterations, %ld of %ld trials forbidden, %ld parts held", r.energy_before,
              r.energy_after, r.iterations, r.forbidden, r.evaluations, r.holds);
  cr_assert(r.energy_after < r.energy_before);
  cr_assert(r.holds > 0, "the steps never met a wall: the test tests nothing");
  assert_allowed(&sc, m, r.energy_after);
  lw_model_free(m);
  lw_scene_clear(&sc);

  p = base_params();
  p.strain = 5;
  p.min_speed = 0.7;
  p.regularity = 0;
  scene_with(&sc, &p);
  r = quench_splines(&sc, 3, 4, 78, &m);
  cr_log_info("min_speed: %.10g -> %.10g, %ld iterations, %ld of %ld trials forbidden, %ld parts held",
              r.energy_before, r.energy_after, r.iterations, r.forbidden, r.evaluations, r.holds);
  cr_assert(r.energy_after < r.energy_before);
  cr_assert(r.holds > 0, "the steps never met a wall: the test tests nothing");
  assert_allowed(&sc, m, r.energy_after);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

/* A system with walls: thin bands of each coordinate where the energy is
** +inf, which a longer step may jump and a shorter one land in.  Its energy
** has ripples, so that line searches reject trials.  It counts what a
** driver should never do: evaluate a state in a band, or ask blocked about
** a trial whose held parts are not where the state stands (blocked
** measures a step from there, as the spacing rule does). */
enum { WALLED_N = 8 };
static const double walled_ripple = 0.3, walled_k = 10.0, walled_band = 20.0;
typedef struct {
  double cur[WALLED_N];
  long stale, checks;
} walled;

static int walled_in_band(double x) { return sin(walled_band * x) > 0.9; }
static double walled_energy(const double *x, double *g)
{
  double e = 0.0;
  for (int i = 0; i < WALLED_N; i++) {
    const double c = 3.0 + 0.5 * i;
    if (walled_in_band(x[i])) return INFINITY;
    e += 0.5 * (x[i] - c) * (x[i] - c) + walled_ripple * sin(walled_k * x[i]);
    if (g) g[i] = (x[i] - c) + walled_ripple * walled_k * cos(walled_k * x[i]);
  }
  return e;
}
static size_t walled_n(const void *st) { return (void)st, WALLED_N; }
static void walled_get(const void *st, double *x) { memcpy(x, ((const walled *)st)->cur, WALLED_N * sizeof *x); }
static lw_status walled_set(void *st, const double *x, lw_error *err)
{
  memcpy(((walled *)st)->cur, x, WALLED_N * sizeof *x);
  return LW_OK;
}
static double walled_gradient(void *st, double *g, lw_error *err) { return walled_energy(((walled *)st)->cur, g); }
static double walled_total(const void *st) { return walled_energy(((const walled *)st)->cur, NULL); }
static size_t walled_blocked(void *st, const double *x, unsigned char *held, const unsigned char *changed)
{
  walled *w = st;
  size_t parts = 0;
  for (int i = 0; i < WALLED_N; i++) {
    w->stale += held[i] && x[i] != w->cur[i];
    if (walled_in_band(x[i])) held[i] = 1, parts++;
  }
  w->checks++;
  return parts;
}
static void walled_free(void *st) { (void)st; }
/* the massless flow's damping matrix: the identity */
static void *walled_mass_new(const void *st, const lw_params *p, double density, lw_error *err)
{
  return (void *)st;
}
static void walled_mass_free(void *mass) { (void)mass; }
static lw_status walled_mass_at(void *mass, const double *x, lw_error *err) { return LW_OK; }
static void walled_mass_solve(const void *mass, const double *b, double *v) { memcpy(v, b, WALLED_N * sizeof *v); }
static int walled_mass_pinned(const void *mass, size_t i) { return 0; }

static const lw_system_type walled_type = {
  .name = "walled", .state_free = walled_free, .total = walled_total, .n_coords = walled_n,
  .get_coords = walled_get, .set_coords = walled_set, .gradient = walled_gradient, .blocked = walled_blocked,
  .mass_new = walled_mass_new, .mass_free = walled_mass_free, .mass_at = walled_mass_at,
  .mass_solve = walled_mass_solve, .mass_pinned = walled_mass_pinned};

/* A gradient driver measures each trial's walls from the point it stands
** at (lw_system_hold), and evaluates no trial that passes one.  The quench
** and the massless flow did not: after a rejected trial the state stood
** there, and the next length's holds were measured from it (7 and 16 times
** here).  The energy is lowered on the way. */
Test(quench, measures_each_trial_from_where_it_stands)
{
  walled w = {.cur = {0}};
  lw_error err = {0};
  lw_system sys = {&walled_type, &w};
  lw_quench_report r;
  const lw_quench_opts o = {1e-8, 500, 0.0, NULL, NULL};
  cr_assert_eq(lw_quench_run(&sys, &o, &r, &err), LW_OK, "%s", err.msg);
  cr_log_info("walled: %.10g -> %.10g, %ld iterations, %ld evaluations, %ld holds, %ld checks, %ld stale, %ld forbidden", r.energy_before,
              r.energy_after, r.iterations, r.evaluations, r.holds, w.checks, w.stale, r.forbidden);
  cr_assert(r.holds > 0 && r.evaluations > r.iterations + 1, "no wall met or no trial rejected: nothing tested");
  cr_assert_eq(w.stale, 0, "%ld trials measured from elsewhere", w.stale);
  cr_assert_eq(r.forbidden, 0, "%ld trials evaluated past a wall", r.forbidden);
  cr_assert(r.energy_after < r.energy_before);
}

Test(dynamics, the_massless_flow_measures_each_trial_from_where_it_stands)
{
  walled w = {.cur = {0}};
  lw_error err = {0};
  lw_params p = base_params();
  p.dyn_rho = 0;
  p.dyn_gamma = 1;
  p.dyn_dt = 4;
  lw_dynamics *d = lw_dynamics_new(&walled_type, &w, &p, &err);
  cr_assert_not_null(d, "%s", err.msg);
  const double e0 = d->energy;
  for (int k = 0; k < 100; k++) {
    const double before = d->energy;
    cr_assert_eq(lw_dynamics_step(d, &err), LW_OK, "%s", err.msg);
    cr_assert_leq(d->energy, before);
  }
  cr_log_info("walled flow: %.10g -> %.10g, %lu halvings, %ld checks, %ld stale", e0, d->energy, d->halvings,
              w.checks, w.stale);
  cr_assert(d->halvings > 0 && w.checks > 0, "no trial rejected or no wall: nothing tested");
  cr_assert_eq(w.stale, 0, "%ld trials measured from elsewhere", w.stale);
  cr_assert(d->energy < e0);
  lw_dynamics_free(d);
}

/* A stop asked for (a signal, main.c) ends the quench at the next
** iteration: asked before it starts, it takes no step and leaves the state
** where it was; not asked, the same quench takes its steps. */
Test(quench, a_stop_ends_it_and_says_so)
{
  lw_params p = base_params();
  p.strain = 2;
  p.bending = 0.5;
  lw_scene sc;
  scene_with(&sc, &p);
  for (int asked = 0; asked < 2; asked++) {
    lw_error err = {0};
    lw_model *m = lw_model_new(&sc, random_splines(&sc, 3, 4, 2024), &err);
    cr_assert_not_null(m, "%s", err.msg);
    lw_system *sys = lw_splines_view(m, &err);
    const double e0 = lw_model_total(m);
    volatile sig_atomic_t stop = asked;
    lw_quench_report r;
    const lw_quench_opts o = {1e-6, 5000, 0.0, &stop, NULL};
    cr_assert_eq(lw_quench_run(sys, &o, &r, &err), LW_OK, "%s", err.msg);
    cr_assert_eq(r.ended == LW_QUENCH_STOPPED, asked);
    if (asked) {
      cr_assert_eq(r.iterations, 0);
      cr_assert_eq(lw_model_total(m), e0, "a stopped quench moved the state");
      cr_assert_eq(r.energy_after, r.energy_before);
    } else {
      cr_assert(r.iterations > 10 && r.energy_after < e0, "%ld iterations, %g -> %g", r.iterations, e0, r.energy_after);
    }
    lw_system_free(sys);
    lw_model_free(m);
  }
  lw_scene_clear(&sc);
}

static char qdir[64];
static void qsetup(void) { cr_assert_eq(lw_test_dir_make(qdir, "quench"), 0); }
static void qteardown(void) { lw_test_dir_remove(qdir); }

/* A signal during the quench stops it (the quench of a picture's page takes
** minutes): the run ends at once, with the annealed state saved and
** nothing drawn, as a run stopped between sweeps (by SIGINT itself, as
** Ctrl-C's clean stops end: the shell's 130); the phase line on stderr
** says when the quench is under way. */
Test(quench, a_signal_stops_a_quench_under_way, .init = qsetup, .fini = qteardown)
{
  /* the quench's second before the signal counts in timing.txt (a stopped
  ** quench's time was lost: the file held the last checkpoint's) */
  int rc = lw_test_sh("t0=$(date +%%s.%%N); %s run %s/params/example.ini --set anneal.sweeps=1 --set "
                      "anneal.quench=bfgs --out %s/r 2> %s/err.txt & p=$!; i=0; while [ $i -lt 600 ] && "
                      "! grep -q 'quenching' %s/err.txt 2>/dev/null; do sleep 0.1; i=$((i+1)); done; sleep 1; "
                      "t1=$(date +%%s.%%N); kill -INT $p; wait $p; test $? -eq 130 && awk -v t=\"$t0\" -v u=\"$t1\" "
                      "'/^wall_seconds/ { ok = $2 >= u - t - 0.3 } END { exit !ok }' %s/r/timing.txt",
                      lw_test_bin(), lw_test_root(), qdir, qdir, qdir, qdir);
  cr_assert_eq(rc, 0, "%s", lw_test_slurp("%s/r/timing.txt", qdir));
  cr_assert_eq(lw_test_sh("grep -q 'stopped during the quench' %s/err.txt", qdir), 0, "no stop message");
  cr_assert_eq(lw_test_sh("test -f %s/r/state.lw && ! test -e %s/r/final.svg && ! test -e %s/r/summary.json", qdir,
                          qdir, qdir), 0, "a stopped quench saves the state and draws nothing");
}

/* A weight with nothing to hold it (params/wire.ini's wire under gravity,
** its ends let go: nurbs.fixed = 0) has an energy without a floor.
** The quench then walks off a bounded length a step and the stall rule ends
** it, so the run draws: an unbounded step leapt to coordinates whose
** drawing did not finish within the minute. */
Test(quench, an_energy_without_a_floor_walks_off_and_still_draws, .init = qsetup, .fini = qteardown)
{
  int rc = lw_test_sh("timeout -s KILL 60 %s run %s/params/wire.ini --set scene.driver=metropolis "
                      "--set nurbs.fixed=0 --set anneal.quench=bfgs --set anneal.sweeps=20 --out %s/w --quiet",
                      lw_test_bin(), lw_test_root(), qdir);
  cr_assert_eq(rc, 0, "exit %d", rc);
  cr_assert_eq(lw_test_sh("test -s %s/w/final.svg && python3 -c \"import json,sys; "
                          "q=json.load(open('%s/w/summary.json'))['quench']; "
                          "sys.exit(0 if q['energy_after'] < q['energy_before'] - 1e5 else 1)\"", qdir, qdir), 0);
}

/* The quench's line on stderr says what summary.json records: the energies
** to 10 digits, the gradient norms to 3, the iterations and how it ended. */
Test(quench, the_report_line_says_what_the_summary_records, .init = qsetup, .fini = qteardown)
{
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set anneal.quench=bfgs --set anneal.sweeps=20 --out %s/r "
                          "2> %s/r.err", lw_test_bin(), lw_test_root(), qdir, qdir), 0);
  cr_assert_eq(lw_test_sh("python3 -c \"import json,re,sys; q=json.load(open('%s/r/summary.json'))['quench']; "
                          "m=re.search(r'quench: energy (\\S+) -> (\\S+), gradient norm (\\S+) -> (\\S+), "
                          "(\\d+) iterations \\((\\w+)\\), ', open('%s/r.err').read()); "
                          "ok=lambda s, v, d: float(s) == float('%%.*g' %% (d, v)); "
                          "sys.exit(0 if m and ok(m[1], q['energy_before'], 10) and ok(m[2], q['energy_after'], 10) "
                          "and ok(m[3], q['gradient_before'], 3) and ok(m[4], q['gradient_after'], 3) "
                          "and int(m[5]) == q['iterations'] and m[6] == q['ended'] else 1)\"", qdir, qdir),
               0, "%s", lw_test_slurp("%s/r.err", qdir));
}

/* On a smooth energy the quench goes on to quench_tol: the hanging chain's
** from its placement (E about -8800) stalled at a gradient of 5.2e-6, where
** the decrease Armijo's test asks for sank under the energy's rounding.
** The approximate Wolfe conditions take the steps from there on their
** slope; the energy ends no higher than the stalled run's to 1e-12. */
Test(quench, a_smooth_energy_converges_past_the_energys_rounding, .init = qsetup, .fini = qteardown)
{
  cr_assert_eq(lw_test_sh("%s run %s/params/hanging.ini --set anneal.sweeps=0 --set anneal.quench=bfgs --out %s/h "
                          "--quiet", lw_test_bin(), lw_test_root(), qdir), 0);
  cr_assert_eq(lw_test_sh("python3 -c \"import json,sys; q=json.load(open('%s/h/summary.json'))['quench']; "
                          "sys.exit(0 if q['converged'] and q['ended'] == 'converged' and q['gradient_after'] <= 1e-6 "
                          "and q['energy_after'] <= -8834.1234356430268 * (1 - 1e-12) else 1)\"", qdir), 0, "%s",
               lw_test_slurp("%s/h/summary.json", qdir));
}

/* Same scene and seed: the same bytes for any thread count (tempering,
** two replicas: the coldest is quenched), and a run stopped and resumed
** quenches to the bytes of an uninterrupted one. */
Test(quench, deterministic_and_resumable, .init = qsetup, .fini = qteardown)
{
  const char *set = "--set anneal.quench=bfgs --set tempering.replicas=2 --set tempering.t_min=0.001 "
                    "--set tempering.t_max=0.01 --set anneal.sweeps=40";
  const char *sc = "tests/fixtures/v1/plain.ini";
  cr_assert_eq(lw_test_sh("OMP_NUM_THREADS=1 %s run %s/%s %s --out %s/a --quiet", lw_test_bin(), lw_test_root(), sc, set, qdir), 0);
  cr_assert_eq(lw_test_sh("OMP_NUM_THREADS=2 %s run %s/%s %s --out %s/b --quiet", lw_test_bin(), lw_test_root(), sc, set, qdir), 0);
  cr_assert_eq(lw_test_sh("%s run %s/%s %s --out %s/c --stop-at 17 --quiet && %s resume %s/c --quiet", lw_test_bin(), lw_test_root(),
                          sc, set, qdir, lw_test_bin(), qdir), 0);
  const char *files[] = {"final.svg", "state.lw", "trace.csv"};
  for (int f = 0; f < 3; f++) {
    cr_expect_eq(lw_test_sh("cmp -s %s/a/%s %s/b/%s", qdir, files[f], qdir, files[f]), 0, "%s: threads", files[f]);
    cr_expect_eq(lw_test_sh("cmp -s %s/a/%s %s/c/%s", qdir, files[f], qdir, files[f]), 0, "%s: resume", files[f]);
  }
  /* the summary's quench, less the seconds */
  for (const char *o = "abc"; *o; o++)
    cr_assert_eq(lw_test_sh("python3 -c \"import json; q=json.load(open('%s/%c/summary.json'))['quench']; "
                            "q.pop('seconds'); print(sorted(q.items()))\" > %s/q%c.txt", qdir, *o, qdir, *o), 0);
  cr_expect_eq(lw_test_sh("cmp -s %s/qa.txt %s/qb.txt", qdir, qdir), 0, "summary quench: threads");
  cr_expect_eq(lw_test_sh("cmp -s %s/qa.txt %s/qc.txt", qdir, qdir), 0, "summary quench: resume");
  /* and it lowered the energy, and says why it ended and what it held */
  cr_assert_eq(lw_test_sh("python3 -c \"import json,sys; q=json.load(open('%s/a/summary.json'))['quench']; "
                          "sys.exit(0 if q['energy_after'] < q['energy_before'] and q['ended'] in "
                          "('converged', 'stalled', 'iterations', 'no descent') and q['holds'] >= 0 else 1)\"",
                          qdir), 0);
}
