/*
** test_terms.c -- every energy term against closed forms, quadrature
** convergence, finite-difference checks and degenerate input.
*/
#include <criterion/criterion.h>
#include <gsl/gsl_rng.h>
#include <math.h>

#include "linewise/model.h"
#include "linewise/scene.h"
#include "linewise/terms.h"
#include "testutil.h"

static lw_splines *splines(size_t n, size_t segs)
{
  size_t s[64];
  for (size_t i = 0; i < n; i++) s[i] = segs;
  lw_splines *sp = lw_splines_new(n, s, NULL);
  cr_assert_not_null(sp);
  return sp;
}

/* A 100 x 100 mm page with a rect boundary at margin 0 and only what is set. */
static void scene_with(lw_scene *sc, lw_params *p)
{
  lw_error err;
  cr_assert_eq(lw_scene_init(sc, p, &err), LW_OK, "%s", err.msg);
}

static lw_params base_params(void)
{
  lw_params p;
  lw_params_defaults(&p);
  p.width = p.height = 100;
  p.margin = 0;
  /* These tests check the terms' arithmetic on random wiggly splines, some
  ** of whose segments fold; the regularity tests have their own (test_hard,
  ** test_regular). */
  p.min_speed = 0;
  p.regularity = 0;
  return p;
}

static double samples_of(const lw_quad *q, const lw_splines *sp, size_t g, lw_samples *s)
{
  const lw_node *a = &sp->node[lw_segment_node(sp, g)];
  lw_segment_sample(q, a, a + 1, s);
  return s->length;
}

static double spline_length(const lw_quad *q, const lw_splines *sp)
{
  lw_samples s;
  double L = 0;
  for (size_t g = 0; g < sp->n_segments; g++) L += samples_of(q, sp, g, &s);
  return L;
}

/* A random wiggly spline: points on a noisy line, random vectors. */
static void wiggly(lw_splines *sp, size_t i, gsl_rng *r, double x0, double y0)
{
  size_t n = lw_splines_segments(sp, i);
  lw_node *nd = &sp->node[sp->first[i]];
  for (size_t k = 0; k <= n; k++)
    nd[k] = (lw_node){x0 + 6.0 * k + gsl_rng_uniform(r), y0 + 2.0 * gsl_rng_uniform(r),
                      1.0 + gsl_rng_uniform(r), gsl_rng_uniform(r) - 0.5};
  sp->rest_length[i] = 6.0 * n;
}

/* A segment of 1e-65 mm: |r'|^5 underflows to 0 (and cross^2 with it on a
** straight one, which gave 0 / 0 = NaN and a refusal naming coordinates
** too large).  Bending goes as 1 / scale: a bent segment scaled down keeps
** bending x scale, a straight one bends 0; its gradient in r' and r'' goes
** as 1 / scale^2, to 1e-150 (it was inf - inf from 1e-62, then from 1e-103). */
Test(terms, a_tiny_segment_bends_as_its_scale_says)
{
  lw_quad q;
  lw_quad_init(&q, 8, NULL);
  lw_splines *sp = splines(1, 1);
  lw_test_straight(sp, 0, 0.3, 0.1, 10.3, 4.1);
  sp->node[1].vx += 1.5; /* bent */
  sp->node[0].vy -= 2.0;
  lw_samples s;
  samples_of(&q, sp, 0, &s);
  const double b1 = lw_term_bending(&s, &q);
  cr_assert(b1 > 0.0 && isfinite(b1));
  /* its gradient in r' and r'' goes as 1 / scale^2 (it was inf - inf) */
  const lw_term_ctx ctx = {.coef = 1.0, .quad = &q};
  lw_samples_grad g1 = {.n = s.n}, gk;
  lw_term_types[LW_TERM_BENDING].segment_grad(&s, &ctx, &g1);
  for (double k = 1e-60; k > 1e-151; k *= 1e-10) { /* s^5 underflows from 1e-62 on, s^3 from 1e-103 */
    lw_splines *t = splines(1, 1);
    for (int n = 0; n < 2; n++) {
      t->node[n] = sp->node[n];
      t->node[n].px *= k, t->node[n].py *= k, t->node[n].vx *= k, t->node[n].vy *= k;
    }
    samples_of(&q, t, 0, &s);
    cr_assert(fabs(lw_term_bending(&s, &q) * k / b1 - 1.0) < 1e-9, "scale %g: %g", k, lw_term_bending(&s, &q) * k);
    memset(&gk, 0, sizeof gk);
    gk.n = s.n;
    lw_term_types[LW_TERM_BENDING].segment_grad(&s, &ctx, &gk);
    for (int i = 0; i < s.n; i++) {
      const double want[4] = {g1.dx[i], g1.dy[i], g1.ddx[i], g1.ddy[i]},
                   got[4] = {gk.dx[i], gk.dy[i], gk.ddx[i], gk.ddy[i]};
      for (int c = 0; c < 4; c++)
        cr_assert(fabs(got[c] * k * k - want[c]) <= 1e-9 * fabs(want[c]) + 1e-12 * b1,
                  "scale %g node %d: %g against %g", k, i, got[c] * k * k, want[c]);
    }
    lw_test_straight(t, 0, 0.3 * k, 0.1 * k, 10.3 * k, 0.1 * k); /* level: its cross is 0 exactly */
    samples_of(&q, t, 0, &s);
    cr_assert(lw_term_bending(&s, &q) == 0.0, "scale %g: straight bends %g", k, lw_term_bending(&s, &q));
    lw_splines_free(t);
  }
  lw_splines_free(sp);
}

/* The field term's two modes on a straight segment across a constant field
** at angle a: r'.v is constant along it, so the signed integral is L cos a
** and the axial one L |cos a| exactly (the axial one once read the signed,
** and only the gradient's test, by differences of that same energy, saw it). */
Test(terms, the_field_term_is_the_signed_or_absolute_alignment)
{
  lw_quad q;
  lw_quad_init(&q, 8, NULL);
  lw_splines *sp = splines(1, 1);
  lw_test_straight(sp, 0, 1.0, 2.0, 9.0, 8.0); /* L = 10 along (0.8, 0.6) */
  lw_samples s;
  samples_of(&q, sp, 0, &s);
  const double angles[3] = {0.3, 2.2, M_PI / 2 + 0.9};
  for (int k = 0; k < 3; k++) {
    lw_field f = {.kind = LW_FIELD_CONSTANT, .ux = cos(angles[k]), .uy = sin(angles[k])};
    const double c = 0.8 * f.ux + 0.6 * f.uy;
    cr_assert(fabs(lw_term_field(&s, &q, &f, 0) - 10.0 * c) < 1e-12, "signed at %g: %.15g", angles[k],
              lw_term_field(&s, &q, &f, 0));
    cr_assert(fabs(lw_term_field(&s, &q, &f, 1) - 10.0 * fabs(c)) < 1e-12, "axial at %g: %.15g", angles[k],
              lw_term_field(&s, &q, &f, 1));
  }
  lw_splines_free(sp);
}

Test(terms, straight_length_exact_and_bending_zero)
{
  lw_quad q;
  lw_quad_init(&q, 3, NULL);
  lw_splines *sp = splines(1, 5);
  lw_test_straight(sp, 0, 1.5, -2.25, 31.7, 13.1);
  /* non-uniform speed along the line: still straight, |r'| a polynomial */
  sp->node[2].vx *= 2.5;
  sp->node[2].vy *= 2.5;
  double L = hypot(31.7 - 1.5, 13.1 + 2.25);
  cr_assert(lw_close_rel(spline_length(&q, sp), L, 1e-14, 1), "length %.17g vs %.17g", spline_length(&q, sp), L);
  lw_samples s;
  for (size_t g = 0; g < sp->n_segments; g++) {
    samples_of(&q, sp, g, &s);
    cr_assert(fabs(lw_term_bending(&s, &q)) < 1e-25, "bending %g", lw_term_bending(&s, &q));
  }
  cr_assert(fabs(lw_term_strain(L, L) - 0) < 1e-30);
  cr_assert(lw_close_rel(lw_term_strain(2 * L, L), 2 * L, 1e-15, 0));
  lw_splines_free(sp);
}

Test(terms, strain_derivative_is_the_corrected_seed_formula)
{
  /* d/dL [(L-L0)^2/L0^2 L] = (L-L0)(3L-L0)/L0^2 ; the seed's (2+L-L0) is a slip. */
  const double L0 = 7.3;
  for (double L = 1.0; L < 20; L += 1.7) {
    double h = 1e-5, fd = (lw_term_strain(L + h, L0) - lw_term_strain(L - h, L0)) / (2 * h);
    double exact = (L - L0) * (3 * L - L0) / (L0 * L0);
    cr_assert(fabs(fd - exact) < 1e-7 * fmax(1, fabs(exact)), "L=%g fd %g exact %g", L, fd, exact);
  }
}

Test(terms, constant_field_integral_is_exact_for_any_shape)
{
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 11);
  lw_params p = base_params();
  p.field_coef = -2.5;
  p.field_mode = LW_FIELDMODE_SIGNED;
  p.field_angle = 33;
  p.quadrature = 2;
  lw_scene sc;
  scene_with(&sc, &p);
  lw_splines *sp = splines(1, 7);
  wiggly(sp, 0, r, 10, 40);
  double vx = cos(33 * M_PI / 180), vy = sin(33 * M_PI / 180);
  const lw_node *a = &sp->node[0], *b = &sp->node[7];
  double exact = -2.5 * (vx * (b->px - a->px) + vy * (b->py - a->py));
  double term[LW_TERM_COUNT];
  double total = lw_energy_compute(&sc, sp, term, NULL);
  cr_assert(lw_close_rel(term[LW_TERM_FIELD], exact, 1e-13, 1), "%.17g vs %.17g", term[LW_TERM_FIELD], exact);
  cr_assert_eq(total, term[LW_TERM_FIELD]);
  lw_splines_free(sp);
  lw_scene_clear(&sc);
  gsl_rng_free(r);
}

Test(terms, potential_constant_and_linear_against_exact_integrals)
{
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 5);
  /* constant Phi: Q Phi L for any shape (L from a 64-node reference) */
  lw_params p = base_params();
  p.potential_coef = 1.75;
  p.potential = LW_POT_CONSTANT;
  p.potential_value = 0.6;
  lw_scene sc;
  scene_with(&sc, &p);
  lw_splines *sp = splines(2, 6);
  wiggly(sp, 0, r, 5, 20);
  wiggly(sp, 1, r, 5, 60);
  lw_quad q64;
  lw_quad_init(&q64, 64, NULL);
  double term[LW_TERM_COUNT];
  lw_energy_compute(&sc, sp, term, NULL);
  double L8 = spline_length(&sc.quad, sp);
  cr_assert(lw_close_rel(term[LW_TERM_POTENTIAL], 1.75 * 0.6 * L8, 1e-14, 0));
  cr_assert(lw_close_rel(L8, spline_length(&q64, sp), 1e-6, 0), "8-node length within 1e-6");
  lw_scene_clear(&sc);

  /* ramp: Phi linear in r; along a straight line the integral is L Phi(midpoint) */
  p.potential = LW_POT_RAMP;
  p.potential_angle = 20;
  p.quadrature = 3;
  scene_with(&sc, &p);
  lw_test_straight(sp, 0, 12, 17, 71, 40);
  lw_test_straight(sp, 1, 80, 5, 20, 95);
  sp->node[3].vx *= 1.7; /* uneven speed along the line keeps the integrand polynomial */
  sp->node[3].vy *= 1.7;
  lw_energy_compute(&sc, sp, term, NULL);
  double exact = 0;
  double mids[2][2] = {{(12 + 71) / 2.0, (17 + 40) / 2.0}, {50, 50}};
  double lens[2] = {hypot(59, 23), hypot(60, 90)};
  for (int i = 0; i < 2; i++) exact += 1.75 * lens[i] * lw_potential_eval(&sc.potential, mids[i][0], mids[i][1]);
  cr_assert(lw_close_rel(term[LW_TERM_POTENTIAL], exact, 1e-13, 0), "%.17g vs %.17g", term[LW_TERM_POTENTIAL], exact);
  lw_splines_free(sp);
  lw_scene_clear(&sc);
  gsl_rng_free(r);
}

/* Bending of the n-segment Bezier circle of radius R with a given quadrature. */
static double circle_bending(int segs, int nodes, double R)
{
  lw_quad q;
  lw_quad_init(&q, nodes, NULL);
  lw_splines *sp = splines(1, (size_t)segs);
  lw_test_circle(sp, 0, 0, 0, R);
  lw_samples s;
  double b = 0;
  for (size_t g = 0; g < sp->n_segments; g++) {
    samples_of(&q, sp, g, &s);
    b += lw_term_bending(&s, &q);
  }
  lw_splines_free(sp);
  return b;
}

Test(terms, bending_of_bezier_circles_converges_to_two_pi_over_r)
{
  const double R = 3.7, exact = 2 * M_PI / R;
  double prev = INFINITY;
  for (int segs = 4; segs <= 64; segs *= 2) {
    double err = fabs(circle_bending(segs, 64, R) - exact) / exact;
    /* the standard handle length leaves a radial error ~ theta^6, so the
    ** curvature error falls by ~ 2^4 or more per doubling */
    cr_assert(err < prev / 8, "segments %d: error %g after %g", segs, err, prev);
    prev = err;
  }
  cr_assert(prev < 1e-7, "64 segments: %g", prev);
}

Test(terms, bending_quadrature_error_falls_with_nodes)
{
  /* 4-segment circle: the integrand is smooth, so Gauss-Legendre converges
  ** geometrically; against the 64-node value. */
  const double R = 2.0, ref = circle_bending(4, 64, R);
  double e[5];
  int nodes[5] = {2, 4, 8, 16, 24};
  for (int i = 0; i < 5; i++) e[i] = fabs(circle_bending(4, nodes[i], R) - ref) / ref;
  for (int i = 1; i < 5; i++) cr_assert(e[i] < e[i - 1] || e[i] < 1e-14, "n=%d err %g, n=%d err %g", nodes[i - 1], e[i - 1], nodes[i], e[i]);
  cr_assert(e[2] < 1e-4, "8 nodes: %g", e[2]);
  cr_assert(e[3] < 1e-9, "16 nodes: %g", e[3]);
}

Test(terms, boundary_parallel_to_a_wall_and_outside)
{
  lw_params p = base_params();
  p.boundary_coef = 0.5;
  lw_scene sc;
  scene_with(&sc, &p);
  lw_splines *sp = splines(1, 3);
  lw_test_straight(sp, 0, 40, 2.5, 62, 2.5); /* 2.5 mm from y = 0, far from the others */
  double term[LW_TERM_COUNT];
  lw_energy_compute(&sc, sp, term, NULL);
  cr_assert(lw_close_rel(term[LW_TERM_BOUNDARY], 0.5 * 22 / (2.5 * 2.5), 1e-14, 0), "%.17g", term[LW_TERM_BOUNDARY]);
  lw_test_straight(sp, 0, 40, 2.5, 62, -0.001);
  lw_energy_compute(&sc, sp, term, NULL);
  cr_assert(isinf(term[LW_TERM_BOUNDARY]) && term[LW_TERM_BOUNDARY] > 0);
  /* a zero-speed sample outside is still +inf, not 0 * inf = NaN */
  for (int k = 0; k < 4; k++) sp->node[k] = (lw_node){-5, -5, 0, 0};
  lw_energy_compute(&sc, sp, term, NULL);
  cr_assert(isinf(term[LW_TERM_BOUNDARY]) && term[LW_TERM_BOUNDARY] > 0);
  lw_splines_free(sp);
  lw_scene_clear(&sc);
}

Test(terms, boundary_every_allowed_segment_is_resolved_at_8_nodes)
{
  /* Regular segments (the default speed and rho checks) thrown at the
  ** bottom wall y = 0 at every angle, ends and bulges reaching toward it:
  ** wherever the term allows one (1.5 of its own length elements from the
  ** frame, between the nodes too), its 8-node value is within 2e-4 of 64
  ** nodes', the bound energy.boundary_clearance's help quotes.  The worst
  ** cases are an end pointing at the wall (3e-5 at 1.5 elements) and a
  ** curved segment's bulge (1.7e-4 at a turn of 2.6 rad; docs/NUMERICS.md). */
  lw_boundary b = {.kind = LW_BOUNDARY_RECT, .x0 = -1e3, .y0 = 0, .x1 = 1e3, .y1 = 1e3, .clearance = 1.5};
  lw_quad q8, q64;
  cr_assert_eq(lw_quad_init(&q8, 8, NULL), LW_OK);
  cr_assert_eq(lw_quad_init(&q64, 64, NULL), LW_OK);
  rng_seed(0x7e5a0001);
  int allowed = 0, refused = 0;
  double worst = 0.0;
  for (int k = 0; k < 20000; k++) {
    const double L = 6.0, turn = urand(-M_PI, M_PI), bend = urand(-1.3, 1.3);
    const lw_node a = {0.0, urand(0.5, 4.0), L / 3 * cos(turn - bend), L / 3 * sin(turn - bend)};
    const lw_node e = {L * cos(turn), a.py + L * sin(turn), L / 3 * cos(turn + bend) * urand(0.8, 1.2),
                       L / 3 * sin(turn + bend) * urand(0.8, 1.2)};
    lw_samples s8, s64;
    lw_segment_sample(&q8, &a, &e, &s8);
    if (!lw_segment_check(&a, &e, 0.4 * s8.length, 2.6)) continue;
    const double v8 = lw_term_boundary(&s8, &q8, &b);
    if (!isfinite(v8)) {
      refused++;
      continue;
    }
    allowed++;
    lw_segment_sample(&q64, &a, &e, &s64);
    const double v64 = lw_term_boundary(&s64, &q64, &b);
    cr_assert(isfinite(v64), "allowed at 8 nodes, not at 64");
    worst = fmax(worst, fabs(v8 - v64) / v64);
  }
  cr_assert(allowed > 2000 && refused > 2000, "%d allowed, %d refused", allowed, refused);
  cr_assert(worst <= 2e-4, "an allowed segment's boundary integral is off by %.3g at 8 nodes", worst);
}

/* A radial or vortex field turns through pi within any distance d of its
** centre, so a segment passing at d has an integrand that changes on the
** scale d: without a core 8 nodes were off by up to 0.18 L here (48 % and
** 81 % of the term in the cases an adversary found), whatever the nodes.  With the core of scene.field_core's default
** (a segment length) the integrand changes on the core's scale: over
** segments of that length passing within a quarter of it, straight and
** bent, 8 nodes stay within 2e-4 L of 64 nodes in the signed mode (worst
** measured 7.2e-5 L) and 4e-3 L in the axial (2.9e-3 L: |r'.v| has a
** kink where the curve crosses the field square, which a constant field's
** bent segments show as well, up to 7.2e-3 L). */
Test(terms, a_segment_passing_a_field_centre_is_resolved_by_its_nodes)
{
  lw_quad q8, q64;
  cr_assert_eq(lw_quad_init(&q8, 8, NULL), LW_OK);
  cr_assert_eq(lw_quad_init(&q64, 64, NULL), LW_OK);
  rng_seed(0x7e5a0002);
  const double L = 10.0;
  double worst[2][2] = {{0.0, 0.0}, {0.0, 0.0}}; /* [none][axial] */
  for (int k = 0; k < 4000; k++) {
    const double turn = urand(-M_PI, M_PI), bend = urand(-0.8, 0.8), d = urand(0.0, 0.25 * L);
    const double along = urand(-0.7 * L, -0.3 * L), nx = -sin(turn), ny = cos(turn);
    const double x0 = along * cos(turn) + d * nx, y0 = along * sin(turn) + d * ny;
    const lw_node a = {x0, y0, L / 3 * cos(turn - bend), L / 3 * sin(turn - bend)};
    const lw_node e = {x0 + L * cos(turn), y0 + L * sin(turn), L / 3 * cos(turn + bend), L / 3 * sin(turn + bend)};
    lw_samples s8, s64;
    lw_segment_sample(&q8, &a, &e, &s8);
    lw_segment_sample(&q64, &a, &e, &s64);
    const int axial = k % 4 >= 2;
    for (int none = 0; none < 2; none++) {
      lw_field f = {.kind = k % 2 ? LW_FIELD_VORTEX : LW_FIELD_RADIAL, .core = none ? 0.0 : L};
      const double v8 = lw_term_field(&s8, &q8, &f, axial), v64 = lw_term_field(&s64, &q64, &f, axial);
      worst[none][axial] = fmax(worst[none][axial], fabs(v8 - v64) / L);
    }
  }
  cr_assert(worst[0][0] <= 2e-4 && worst[0][1] <= 4e-3, "with the core, 8 nodes are off by %.3g L (signed), %.3g L "
            "(axial)", worst[0][0], worst[0][1]);
  cr_assert(worst[1][0] >= 0.1 && worst[1][1] >= 0.1, "without it, the worst cases were %.3g L and %.3g L: the test "
            "no longer shows why", worst[1][0], worst[1][1]);
}

static lw_params all_terms(void)
{
  lw_params p = base_params();
  p.strain = 3;
  p.bending = 0.7;
  p.potential_coef = 0.4;
  p.potential = LW_POT_RADIAL;
  p.field_coef = -0.3;
  p.field = LW_FLD_VORTEX;
  p.pair = 0.05;
  p.pair_cutoff = 8;
  p.boundary_coef = 0.2;
  p.parametrisation = 0.3;
  p.dyn_force_x = 0.02;
  p.dyn_force_y = -0.05;
  p.chem_spline = 0.4;
  p.chem_length = -0.01;
  return p;
}

/* The terms no scene without a picture or a program turns on: the tone
** (a picture's, tests/test_tone.c) and the user term (a program's
** function, lw_scene_set_user_term). */
static int needs_more_than_keys(int t) { return t == LW_TERM_TONE || t == LW_TERM_USER; }

/* all_terms() turns on every term a scene's keys can, so that the tests on
** it cover a term added later: one left off there fails here. */
Test(terms, the_all_terms_scene_turns_every_term_on)
{
  lw_params p = all_terms();
  lw_scene sc;
  scene_with(&sc, &p);
  for (int t = 0; t < LW_TERM_COUNT; t++)
    if (!needs_more_than_keys(t))
      cr_assert(sc.on[t], "term %s is off in all_terms() (tests/test_terms.c): turn it on there, and in "
                "every_term_at_once (tests/test_gradient.c), so that their tests cover it", lw_term_names[t]);
  lw_scene_clear(&sc);
}

/* Every term has its name (an entry left out of lw_term_names is NULL, and
** every run crashed on it) and its own row of one kind. */
Test(terms, every_term_has_a_name_and_a_row_of_one_kind)
{
  for (int t = 0; t < LW_TERM_COUNT; t++) {
    cr_assert_not_null(lw_term_names[t], "term %d has no name in lw_term_names (src/terms.c)", t);
    for (int u = 0; u < t; u++) cr_assert_str_neq(lw_term_names[t], lw_term_names[u]);
    const lw_term_type *r = &lw_term_types[t];
    cr_assert_eq((int)r->id, t, "lw_term_types[%d] holds term %d", t, (int)r->id);
    const int kinds = (r->segment != NULL) + (r->spline != NULL) + (r->pairwise != 0) + (r->raster != 0);
    cr_assert_eq(kinds, 1, "term %s: %d kinds (segment, spline, pairwise, raster): expected one", lw_term_names[t],
                 kinds);
    cr_assert(!r->spline == !r->spline_change, "term %s: a spline term needs spline_change", lw_term_names[t]);
  }
}

Test(terms, degenerate_input_never_gives_nan)
{
  lw_params p = all_terms();
  lw_scene sc;
  scene_with(&sc, &p);
  lw_splines *sp = splines(3, 3);
  /* coincident control points everywhere (a zero-length spline) */
  for (int k = 0; k < 4; k++) sp->node[k] = (lw_node){50, 50, 0, 0};
  /* a cusp: r' = 0 inside a segment (v0 = -v1 with p0 = p1) */
  lw_test_straight(sp, 1, 20, 20, 40, 20);
  sp->node[5] = sp->node[4];
  sp->node[5].vx = -sp->node[4].vx;
  sp->node[5].vy = -sp->node[4].vy;
  /* coincident nodes with non-zero vectors: a loop */
  lw_test_straight(sp, 2, 20, 70, 60, 70);
  sp->node[9] = (lw_node){sp->node[8].px, sp->node[8].py, 5, 5};
  sp->node[10].vx = 5;
  sp->node[10].vy = -5;
  double term[LW_TERM_COUNT];
  double total = lw_energy_compute(&sc, sp, term, NULL);
  for (int t = 0; t < LW_TERM_COUNT; t++) cr_assert(!isnan(term[t]), "term %s is NaN", lw_term_names[t]);
  cr_assert(!isnan(total));
  cr_assert(term[LW_TERM_BENDING] >= 0);
  lw_splines_free(sp);
  lw_scene_clear(&sc);
}

Test(terms, local_energy_change_equals_full_recomputation_for_every_dof)
{
  /* What the annealer relies on: moving any one point or vector changes the
  ** running total by exactly the full-recomputation difference. */
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 99);
  lw_params p = all_terms();
  p.strain_mode = LW_STRAIN_SEGMENT;
  lw_scene sc;
  scene_with(&sc, &p);
  for (int mode = 0; mode < 2; mode++) {
    sc.strain_per_segment = mode;
    lw_splines *sp = splines(3, 4);
    wiggly(sp, 0, r, 20, 30);
    wiggly(sp, 1, r, 22, 33);
    wiggly(sp, 2, r, 25, 36);
    lw_model *m = lw_model_new(&sc, sp, NULL);
    cr_assert_not_null(m);
    lw_proposal *pr = lw_proposal_new(m, NULL);
    double term0[LW_TERM_COUNT], term1[LW_TERM_COUNT];
    double e0 = lw_energy_compute(&sc, m->sp, term0, NULL);
    cr_assert(lw_close_rel(lw_model_total(m), e0, 1e-13, 1));
    for (uint32_t i = 0; i < 3; i++)
      for (size_t k = 0; k <= 4; k++)
        for (int which = 0; which < 4; which++) {
          lw_node nd = m->sp->node[m->sp->first[i] + k];
          double h = 1e-3 * (1 + gsl_rng_uniform(r));
          double *c = which == 0 ? &nd.px : which == 1 ? &nd.py : which == 2 ? &nd.vx : &nd.vy;
          *c += h;
          lw_model_propose(m, pr, i, k, 1, &nd);
          /* full recomputation of the moved state */
          lw_splines *moved = lw_splines_clone(m->sp);
          moved->node[moved->first[i] + k] = nd;
          double e1 = lw_energy_compute(&sc, moved, term1, NULL);
          for (int t = 0; t < LW_TERM_COUNT; t++) {
            double d = term1[t] - term0[t];
            cr_assert(fabs(pr->dterm[t] - d) <= 1e-9 * fmax(fabs(term0[t]), 1e-3),
                      "spline %u node %zu dof %d term %s: local %.17g full %.17g", i, k, which,
                      lw_term_names[t], pr->dterm[t], d);
          }
          cr_assert(fabs(pr->dE - (e1 - e0)) <= 1e-9 * fmax(fabs(e0), 1));
          /* and a smooth energy: dE/h agrees between h and h/2 to first order */
          lw_splines_free(moved);
        }
    lw_proposal_free(pr);
    lw_model_free(m);
  }
  lw_scene_clear(&sc);
  gsl_rng_free(r);
}

Test(terms, energy_is_differentiable_in_every_dof)
{
  /* Central differences of the local dE at h and h/2 agree to O(h^2): the
  ** energy is smooth in each point and vector away from the near-field and
  ** cutoff switches (the pair term is off here so no switch is crossed). */
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 7);
  lw_params p = all_terms();
  p.pair = 0;
  lw_scene sc;
  scene_with(&sc, &p);
  lw_splines *sp = splines(2, 3);
  wiggly(sp, 0, r, 20, 30);
  wiggly(sp, 1, r, 20, 60);
  lw_model *m = lw_model_new(&sc, sp, NULL);
  lw_proposal *pr = lw_proposal_new(m, NULL);
  for (uint32_t i = 0; i < 2; i++)
    for (size_t k = 0; k <= 3; k++)
      for (int which = 0; which < 4; which++) {
        double slope[2];
        for (int level = 0; level < 2; level++) {
          double h = level ? 5e-5 : 1e-4, de[2];
          for (int sgn = 0; sgn < 2; sgn++) {
            lw_node nd = m->sp->node[m->sp->first[i] + k];
            double *c = which == 0 ? &nd.px : which == 1 ? &nd.py : which == 2 ? &nd.vx : &nd.vy;
            *c += sgn ? -h : h;
            lw_model_propose(m, pr, i, k, 1, &nd);
            de[sgn] = pr->dE;
          }
          slope[level] = (de[0] - de[1]) / (2 * h);
        }
        cr_assert(fabs(slope[0] - slope[1]) <= 1e-5 * fmax(fabs(slope[1]), 1),
                  "spline %u node %zu dof %d: %.12g vs %.12g", i, k, which, slope[0], slope[1]);
      }
  lw_proposal_free(pr);
  lw_model_free(m);
  lw_scene_clear(&sc);
  gsl_rng_free(r);
}

/* A user term of the segment's end nodes: k |p_{m+1} - p_m|^2. */
static double chord_spring(const lw_samples *s, const lw_quad *q, const void *data)
{
  double dx = s->end_x[1] - s->end_x[0], dy = s->end_y[1] - s->end_y[0];
  return *(const double *)data * (dx * dx + dy * dy);
}

Test(terms, user_term_is_summed_cached_and_differenced_like_the_others)
{
  lw_params p = base_params();
  p.bending = 1;
  lw_scene sc;
  scene_with(&sc, &p);
  static const double k = 0.75;
  lw_error err;
  cr_assert_eq(lw_scene_set_user_term(&sc, 2.0, NULL, &k, &err), LW_EINPUT);
  cr_assert_eq(lw_scene_set_user_term(&sc, NAN, chord_spring, &k, &err), LW_EINPUT);
  cr_assert(!sc.on[LW_TERM_USER] && sc.n_local == 1, "a refused term must stay off");
  cr_assert_eq(lw_scene_set_user_term(&sc, 2.0, chord_spring, &k, &err), LW_OK, "%s", err.msg);
  cr_assert(sc.on[LW_TERM_USER] && sc.n_local == 2 && sc.local[1] == LW_TERM_USER);
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 21);
  lw_splines *sp = splines(2, 3);
  wiggly(sp, 0, r, 20, 30);
  wiggly(sp, 1, r, 22, 40);
  double want = 0.0, term[LW_TERM_COUNT], term1[LW_TERM_COUNT];
  for (size_t i = 0; i < 2; i++)
    for (size_t m = 0; m < 3; m++) {
      const lw_node *a = &sp->node[sp->first[i] + m];
      want += 2.0 * k * ((a[1].px - a[0].px) * (a[1].px - a[0].px) + (a[1].py - a[0].py) * (a[1].py - a[0].py));
    }
  lw_energy_compute(&sc, sp, term, NULL);
  cr_assert(lw_close_rel(term[LW_TERM_USER], want, 1e-14, 0), "user %.17g, expected %.17g", term[LW_TERM_USER], want);
  lw_model *m = lw_model_new(&sc, sp, NULL);
  cr_assert(lw_close_rel(m->term[LW_TERM_USER], want, 1e-14, 0));
  /* a move of an interior point changes two chords: the local difference
  ** equals the recomputed one */
  lw_proposal *pr = lw_proposal_new(m, NULL);
  lw_node nd = m->sp->node[m->sp->first[1] + 2];
  nd.px += 0.37;
  nd.py -= 0.21;
  lw_model_propose(m, pr, 1, 2, 1, &nd);
  lw_splines *moved = lw_splines_clone(m->sp);
  moved->node[moved->first[1] + 2] = nd;
  lw_energy_compute(&sc, moved, term1, NULL);
  cr_assert(lw_close_rel(pr->dterm[LW_TERM_USER], term1[LW_TERM_USER] - term[LW_TERM_USER], 1e-12, 1e-12));
  cr_assert(pr->dterm[LW_TERM_USER] != 0.0);
  lw_splines_free(moved);
  lw_proposal_free(pr);
  lw_model_free(m);
  /* coefficient 0: off again, not evaluated */
  cr_assert_eq(lw_scene_set_user_term(&sc, 0.0, chord_spring, &k, &err), LW_OK);
  cr_assert(!sc.on[LW_TERM_USER] && sc.n_local == 1 && sc.user_fn == NULL);
  lw_scene_clear(&sc);
  gsl_rng_free(r);
}

Test(terms, every_row_reads_its_own_context_only)
{
  /* The table has exactly one shape a row; a segment row's value is its
  ** context's coefficient times the pure function of the context's object,
  ** and a context changed after the scene filled it changes the value
  ** (the row never looks at the scene). */
  lw_params p = all_terms();
  p.strain_mode = LW_STRAIN_SEGMENT;
  lw_scene sc;
  scene_with(&sc, &p);
  lw_term_ctx ctx[LW_TERM_COUNT];
  lw_scene_term_ctx(&sc, ctx);
  for (int t = 0; t < LW_TERM_COUNT; t++) {
    const lw_term_type *row = &lw_term_types[t];
    cr_assert_eq(row->id, t);
    cr_assert_eq(!!row->segment + !!row->spline + !!row->pairwise + !!row->raster, 1, "%s: one shape",
                 lw_term_names[t]);
    cr_assert_eq(ctx[t].coef, sc.coef[t], "%s", lw_term_names[t]);
  }
  cr_assert(ctx[LW_TERM_PAIR].data == &sc.pair && ctx[LW_TERM_PAIR].quad == &sc.pair_quad);
  cr_assert(ctx[LW_TERM_TONE].data == &sc.tone && ctx[LW_TERM_TONE].quad == &sc.tone_quad);
  lw_splines *sp = splines(1, 2);
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 5);
  wiggly(sp, 0, r, 40, 45);
  lw_samples s;
  samples_of(&sc.quad, sp, 0, &s);
  const double pure[LW_TERM_COUNT] = {
      [LW_TERM_BENDING] = lw_term_bending(&s, &sc.quad),
      [LW_TERM_POTENTIAL] = lw_term_potential(&s, &sc.quad, &sc.potential),
      [LW_TERM_FIELD] = lw_term_field(&s, &sc.quad, &sc.field, sc.field_axial),
      [LW_TERM_BOUNDARY] = lw_term_boundary(&s, &sc.quad, &sc.boundary),
      [LW_TERM_PARAM] = lw_term_parametrisation(&s, &sc.quad),
      [LW_TERM_LOAD] = lw_term_load(&s, sc.load),
  };
  for (int t = 0; t < LW_TERM_COUNT; t++) {
    if (!lw_term_types[t].segment || t == LW_TERM_USER) continue;
    lw_term_ctx c = ctx[t];
    cr_assert_eq(lw_term_types[t].segment(&s, &c), c.coef * pure[t], "%s", lw_term_names[t]);
    c.coef *= 3.0;
    cr_assert_eq(lw_term_types[t].segment(&s, &c), c.coef * pure[t], "%s with its own coefficient", lw_term_names[t]);
  }
  /* strain, a spline row: the whole length, or (mode 1) each segment against its share */
  const double len[2] = {7.0, 5.0};
  lw_term_ctx c = ctx[LW_TERM_STRAIN];
  cr_assert_eq(c.mode, 1);
  cr_assert_eq(lw_term_types[LW_TERM_STRAIN].spline(len, 2, 12.0, 10.0, &c),
               lw_term_strain(7.0, 5.0) + lw_term_strain(5.0, 5.0));
  c.mode = 0;
  cr_assert_eq(lw_term_types[LW_TERM_STRAIN].spline(len, 2, 12.0, 10.0, &c), lw_term_strain(12.0, 10.0));
  gsl_rng_free(r);
  lw_splines_free(sp);
  lw_scene_clear(&sc);
}

/* A spline past a block of LW_TERM_LEN_BLOCK segments keeps its blocks'
** sums, so that a commit costs a block and the blocks, not the whole
** spline: its length stays a function of the lengths alone, bit for bit
** what a model built afresh on the moved splines holds (a resumed run's),
** and the strain (both modes) and chemical terms' local changes match a
** recomputation from scratch.  Three turns of a spiral of 300 segments
** (three blocks) beside a short spline. */
Test(terms, a_long_splines_length_is_a_function_of_its_segments)
{
  lw_params p = all_terms();
  p.pair = 0.0;
  p.chem_length = 0.3;
  p.chem_spline = 1.0;
  lw_scene sc;
  for (int mode = 0; mode < 2; mode++) {
    p.strain_mode = mode ? LW_STRAIN_SEGMENT : LW_STRAIN_SPLINE;
    scene_with(&sc, &p);
    size_t segs[2] = {300, 4};
    lw_splines *sp = lw_splines_new(2, segs, NULL);
    cr_assert_not_null(sp);
    for (size_t k = 0; k <= 300; k++) {
      const double t = 0.0628 * (double)k, r = 10.0 + 2.0 * t, dt = 0.0628 / 3.0;
      sp->node[k] = (lw_node){50 + r * cos(t), 50 + r * sin(t), (2.0 * cos(t) - r * sin(t)) * dt,
                              (2.0 * sin(t) + r * cos(t)) * dt};
    }
    for (size_t k = 0; k <= 4; k++) sp->node[sp->first[1] + k] = (lw_node){5.0 + 4.0 * (double)k, 5.0, 1.3, 0.0};
    sp->rest_length[0] = 800.0;
    sp->rest_length[1] = 14.0;
    lw_model *m = lw_model_new(&sc, sp, NULL);
    cr_assert_not_null(m);
    cr_assert_not_null(m->seg_block, "a spline of 300 segments keeps its blocks' sums");
    cr_assert_gt(lw_test_moves_match_full(&sc, m, 600, 0.05, 17 + (unsigned long)mode), 300);
    lw_model *fresh = lw_model_new(&sc, lw_splines_clone(m->sp), NULL);
    cr_assert_not_null(fresh);
    for (size_t i = 0; i < 2; i++)
      cr_expect(m->spline_len[i] == fresh->spline_len[i], "mode %d spline %zu: kept %.17g, afresh %.17g", mode, i,
                m->spline_len[i], fresh->spline_len[i]);
    lw_model_free(fresh);
    lw_model_free(m);
    lw_scene_clear(&sc);
  }
}
