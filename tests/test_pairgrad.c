/* test_pairgrad.c -- the pair term's gradient (gradient.h, pairgrad.h) against central differences. */
#include <criterion/criterion.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/gradient.h"
#include "linewise/model.h"
#include "linewise/pair.h"
#include "linewise/pairgrad.h"
#include "linewise/pairnear.h"
#include "linewise/params.h"
#include "linewise/quad.h"
#include "linewise/spline.h"
#include "testutil.h"

static const double PI = 3.14159265358979323846;

/*
** Tolerances (HOOMD's force/energy test: relative 1e-5 at a step near 1e-6
** of the scale).  A central difference of step h errs by h^2 |f'''| / 6
** (truncation) plus eps_f |f| / h (rounding).  The configurations keep
** every singular point (a contact, a crossing of end points) at least
** delta = 1e-3 of the scale away, so |f'''| <= |f'| / delta^2 and the first
** part is below (h / delta)^2 = 1e-6 of the derivative; the functions are
** computed to eps_f <= 1e-13 relative (the segment integral to 3e-14, the
** near field's sums to a few ulps of their terms), so the second is below
** 1e-7 of f / scale.  Components that nearly vanish are compared against
** FLOOR times the largest component: relative 1e-5 of a component that
** is 1e-3 of the largest asks more than the rounding of the others allows.
** Kinks (docs/NUMERICS.md) are kept away the same way: the arcs are
** displaced off their symmetry, whose ties of maxima are kinks.
*/
#define REL 1e-5
#define FLOOR 1e-3
#define STEP 1e-6

/* |a - b| <= REL max(|b|, FLOOR big) */
static int grad_close(double a, double b, double big)
{
  return lw_close_rel(a, b, REL, FLOOR * big);
}

/* ---- lw_pair_segseg ------------------------------------------------------- */

static double segseg_at(const double p[8])
{
  return lw_pair_segseg(p, p + 2, p + 4, p + 6);
}

/* The eight derivatives of lw_pair_segseg at p against central differences
** of step STEP times the longer segment. */
static void check_segseg(const char *what, const double p[8])
{
  double g[8], q[8];
  double v = lw_pair_segseg_grad(p, p + 2, p + 4, p + 6, g);
  cr_assert(v == segseg_at(p), "%s: value %.17g vs %.17g", what, v, segseg_at(p));
  double h = STEP * fmax(hypot(p[2] - p[0], p[3] - p[1]), hypot(p[6] - p[4], p[7] - p[5])), big = 0.0;
  for (int k = 0; k < 8; k++) big = fmax(big, fabs(g[k]));
  for (int k = 0; k < 8; k++) {
    memcpy(q, p, sizeof q);
    q[k] = p[k] + h;
    double up = segseg_at(q);
    q[k] = p[k] - h;
    double fd = (up - segseg_at(q)) / (2.0 * h);
    cr_assert(grad_close(g[k], fd, big), "%s: dI/dp[%d] %.12g vs differences %.12g (rel %.1e)", what, k, g[k],
              fd, fabs(g[k] / fd - 1));
  }
}

/* The cases of test_pair.c's fixed values and their neighbours: skew,
** crossing (at right angles, shallow), touching within 1e-3 (T and L, where
** the derivative itself grows like log of the gap), parallel and
** antiparallel, near-parallel from 1e-4 to 1e-12, collinear apart, far
** apart, very unequal lengths. */
Test(pairgrad, segseg_derivative_matches_differences)
{
  static const struct {
    const char *what;
    double p[8];
  } C[] = {
      {"skew", {0.1, 0.2, 1.3, 0.4, 0.5, 1.1, 1.7, 2.9}},
      {"crossing at right angles", {0.0, 0.0, 2.0, 0.0, 0.5, -1.0, 0.5, 0.75}},
      {"crossing at 30 degrees", {0.0, 0.0, 1.0, 0.0, 0.2, -0.2, 0.2 + 1.2 * 0.8660254, -0.2 + 1.2 * 0.5}},
      {"crossing shallow 1e-2", {0.0, 0.0, 1.0, 0.0, -0.1, -0.004, 1.1, 0.008}},
      {"T, 1e-3 apart", {0.0, 0.0, 1.0, 0.0, 0.4, 1e-3, 0.45, 0.8}},
      {"T, crossing by 1e-3", {0.0, 0.0, 1.0, 0.0, 0.4, -1e-3, 0.45, 0.8}},
      {"L, 1e-3 apart", {0.0, 0.0, 1.0, 0.0, 1.001, 0.0, 1.3, 0.7}},
      {"parallel 0.02 apart", {0.0, 0.0, 1.0, 0.0, 0.3, 0.02, 1.1, 0.02}},
      {"parallel 1 apart", {0.0, 0.0, 1.0, 0.0, 0.3, 1.0, 1.1, 1.0}},
      {"antiparallel 0.1 apart", {0.0, 0.0, 1.0, 0.0, 1.2, 0.1, 0.5, 0.1}},
      {"near-parallel 1e-4", {0.0, 0.0, 1.0, 0.0, 0.3, 0.05, 1.3, 0.05 + 1e-4}},
      {"near-parallel 1e-8", {0.0, 0.0, 1.0, 0.0, 0.3, 0.05, 1.3, 0.05 + 1e-8}},
      {"near-parallel 1e-12", {0.0, 0.0, 1.0, 0.0, 0.3, 0.05, 1.3, 0.05 + 1e-12}},
      {"collinear apart", {0.0, 0.0, 1.0, 0.0, 1.5, 0.0, 2.0, 0.0}},
      {"far apart", {0.0, 0.0, 0.3, 0.1, 3.0, 2.0, 3.2, 2.5}},
      {"unequal lengths", {0.0, 0.0, 10.0, 0.5, 3.0, 0.4, 3.2, 0.9}},
  };
  for (size_t k = 0; k < sizeof C / sizeof C[0]; k++) check_segseg(C[k].what, C[k].p);
  /* and random pairs, many of them crossing */
  rng_seed(16);
  for (int k = 0; k < 200; k++) {
    double p[8];
    for (int i = 0; i < 8; i++) p[i] = urand(-1.0, 1.0);
    double g[8];
    lw_pair_segseg_grad(p, p + 2, p + 4, p + 6, g);
    /* an end point within 1e-3 of the other segment is near a singular
    ** point (covered by the cases above) */
    int near = 0;
    for (int e = 0; e < 4; e++) {
      const double *x = p + 2 * e, *s0 = e < 2 ? p + 4 : p, *s1 = s0 + 2;
      double ux = s1[0] - s0[0], uy = s1[1] - s0[1], t = ((x[0] - s0[0]) * ux + (x[1] - s0[1]) * uy) / (ux * ux + uy * uy);
      t = fmin(1.0, fmax(0.0, t));
      near |= hypot(x[0] - s0[0] - t * ux, x[1] - s0[1] - t * uy) < 1e-3;
    }
    if (!near) check_segseg("random", p);
  }
}

/* Where an end point lies on the other segment the integral's slope is
** infinite (it changes like e log e as the end point moves off): the
** derivative says so rather than giving a finite number. */
Test(pairgrad, segseg_derivative_is_not_finite_at_a_contact)
{
  const double T[8] = {0.0, 0.0, 1.0, 0.0, 0.4, 0.0, 0.45, 0.8}, L[8] = {0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.3, 0.7};
  const double *C[2] = {T, L};
  for (int c = 0; c < 2; c++) {
    double g[8], v = lw_pair_segseg_grad(C[c], C[c] + 2, C[c] + 4, C[c] + 6, g);
    int finite = 1;
    for (int k = 0; k < 8; k++) finite &= isfinite(g[k]);
    cr_assert(isfinite(v) && v > 0.0 && !finite, "%s contact: %g, gradient finite", c ? "L" : "T", v);
  }
}

/* The derivative is the integral's, not an approximation to it: the
** derivative along a rigid motion is 0 and along a scaling the value
** (I(lambda x) = lambda I(x)), to rounding. */
Test(pairgrad, segseg_derivative_keeps_the_invariances)
{
  rng_seed(1616);
  for (int k = 0; k < 100; k++) {
    double p[8], g[8];
    for (int i = 0; i < 8; i++) p[i] = urand(-1.0, 1.0);
    double I = lw_pair_segseg_grad(p, p + 2, p + 4, p + 6, g), tx = 0, ty = 0, rot = 0, scale = 0, big = 0;
    for (int e = 0; e < 4; e++) {
      tx += g[2 * e];
      ty += g[2 * e + 1];
      rot += p[2 * e] * g[2 * e + 1] - p[2 * e + 1] * g[2 * e];
      scale += p[2 * e] * g[2 * e] + p[2 * e + 1] * g[2 * e + 1];
      big = fmax(big, fmax(fabs(g[2 * e]), fabs(g[2 * e + 1])));
    }
    cr_assert(fabs(tx) < 1e-11 * big && fabs(ty) < 1e-11 * big, "translation: %g %g of %g", tx, ty, big);
    cr_assert(fabs(rot) < 1e-11 * big, "rotation: %g of %g", rot, big);
    cr_assert(lw_close_rel(scale, I, 1e-11, big), "scaling: %.15g vs %.15g", scale, I);
  }
}

/* ---- the near field's integral of two cubic segments -------------------- */

static double exact_at(const double p[16], double rc) { return lw_pair_segments_exact(p, p + 8, rc); }

static void check_exact(const char *what, const double p[16], double rc)
{
  double g[16], q[16];
  double v = lw_pair_segments_exact_grad(p, p + 8, rc, g, g + 8), big = 0.0;
  cr_assert(lw_close_rel(v, exact_at(p, rc), 1e-13, 0.0), "%s: value %.17g vs %.17g", what, v, exact_at(p, rc));
  for (int k = 0; k < 16; k++) big = fmax(big, fabs(g[k]));
  double h = STEP * hypot(p[6] - p[0], p[7] - p[1]);
  for (int k = 0; k < 16; k++) {
    memcpy(q, p, sizeof q);
    q[k] = p[k] + h;
    double up = exact_at(q, rc);
    q[k] = p[k] - h;
    double fd = (up - exact_at(q, rc)) / (2.0 * h);
    cr_assert(grad_close(g[k], fd, big), "%s (rc %g): dX/dp[%d] %.12g vs differences %.12g (rel %.1e)", what, rc,
              k, g[k], fd, fabs(g[k] / fd - 1));
  }
}

/* Two quarter circles of 4 segments (test_pair.c's two_arcs): 0 touching
** at a node, 1 touching mid-segment, 2 and 3 crossing at 40 and 14 degrees,
** 4 parallel 0.02 apart, 5 parallel 0.3 apart.  The touching ones are
** lifted by `lift` (a contact is a singular point of the integral). */
static lw_splines *two_arcs(int which, double lift)
{
  static const double CX[] = {0, 0.37, 0.4, 0.4, 0, 0}, LIFT[] = {0, 0, 0.3, 0.05, -0.02, -0.3};
  size_t segs[2] = {4, 4};
  lw_splines *sp = lw_splines_new(2, segs, NULL);
  cr_assert_not_null(sp);
  lw_test_arc(sp, 0, 10, 13, 3, -0.75 * PI, -0.25 * PI);
  if (which >= 4) lw_test_arc(sp, 1, 10, 13 + LIFT[which], 3, -0.75 * PI, -0.25 * PI);
  else lw_test_arc(sp, 1, 10 + CX[which], 8 + LIFT[which] - lift, 2, 0.25 * PI, 0.75 * PI);
  return sp;
}

static const char *const ARC_CASE[] = {"touching at a node", "touching mid-segment", "crossing at 40 degrees",
                                       "crossing at 14 degrees", "parallel 0.02 apart", "parallel 0.3 apart"};

/* Every segment pair of the two arcs that lies within reach of the near
** field, with and without a cutoff: each of the near field's ways (16 x 16
** rule, subtraction, subdivision with its leaves) and the blends between
** them come up. */
Test(pairgrad, near_integral_derivative_matches_differences)
{
  rng_seed(1603);
  for (int c = 0; c < 6; c++) {
    lw_splines *sp = two_arcs(c, 1e-3);
    for (size_t m = 0; m < 4; m++)
      for (size_t j = 0; j < 4; j++) {
        double p[16];
        lw_splines_bezier(sp, 0, m, p);
        lw_splines_bezier(sp, 1, j, p + 8);
        /* off the arcs' symmetry: a symmetric piece has its two inner
        ** control points equally far from its chord, a tie of the maxima
        ** that bound it, where the computed integral has a kink */
        for (int k = 0; k < 16; k++) p[k] += urand(-2e-3, 2e-3);
        double d = hypot(p[0] + p[6] - p[8] - p[14], p[1] + p[7] - p[9] - p[15]) / 2;
        if (d > 1.5) continue; /* far apart: the 16 x 16 rule only */
        char what[96];
        snprintf(what, sizeof what, "%s, segments %zu and %zu", ARC_CASE[c], m, j);
        check_exact(what, p, 0.0);
        check_exact(what, p, 0.8);
      }
    lw_splines_free(sp);
  }
}

/* ---- the whole term ------------------------------------------------------- */

/* A scene with the pair term alone, coefficient C. */
static void pair_scene(lw_scene *sc, double C, double cutoff, double near, int nq)
{
  lw_params p;
  lw_params_defaults(&p);
  p.width = p.height = 20;
  p.margin = 0;
  p.strain = p.bending = p.potential_coef = p.field_coef = p.boundary_coef = 0;
  p.pair = C;
  p.pair_cutoff = cutoff;
  p.pair_near = near;
  p.quadrature = nq;
  lw_error err;
  cr_assert_eq(lw_scene_init(sc, &p, &err), LW_OK, "%s", err.msg);
}

/* 1 below half the radius, 0 from the radius on (pairnear.c). */
static double near_weight(double u)
{
  if (u >= 1.0) return 0.0;
  if (u <= 0.5) return 1.0;
  double t = 2.0 * (1.0 - u);
  return t * t * t * (10.0 + t * (6.0 * t - 15.0));
}

/*
** The pair energy of model.c written out in double precision, segment pair
** by segment pair, with the weights dl kept in double: the model stores
** them as float (pair.h), whose rounding steps (6e-8 relative) would swamp a
** central difference of step 1e-6.  Far pairs dl_i dl_j k(r); a segment
** pair with a sample pair within the near radius takes
** W X + (1 - W)(near + far) instead, X of both orders blended in the band
** (pairnear.h).
*/
static double pair_energy_double(const lw_splines *sp, double C, double rc, double near, int nq)
{
  lw_quad q;
  cr_assert_eq(lw_quad_init(&q, nq, NULL), LW_OK);
  const double inv = rc > 0.0 ? 1.0 / rc : 0.0, cut2 = rc > 0.0 ? rc * rc : INFINITY;
  lw_samples *S = malloc(sp->n_segments * sizeof *S);
  cr_assert_not_null(S);
  for (size_t g = 0; g < sp->n_segments; g++) {
    const lw_node *a = &sp->node[lw_segment_node(sp, g)];
    lw_segment_sample(&q, a, a + 1, &S[g]);
  }
  double e = 0.0;
  for (size_t ga = 0; ga < sp->n_segments; ga++)
    for (size_t gb = ga + 1; gb < sp->n_segments; gb++) {
      if (sp->seg_spline[ga] == sp->seg_spline[gb]) continue;
      const lw_samples *A = &S[ga], *B = &S[gb];
      double W = 0.0, nsum = 0.0, fsum = 0.0;
      for (int i = 0; i < nq; i++)
        for (int j = 0; j < nq; j++) {
          double dx = A->x[i] - B->x[j], dy = A->y[i] - B->y[j], r2 = dx * dx + dy * dy;
          double rho = near * fmax(A->dl[i], B->dl[j]);
          if (rc > 0.0 && rho > rc) rho = rc;
          double k = r2 < cut2 ? A->dl[i] * B->dl[j] * (1.0 / sqrt(r2) - inv) : 0.0;
          if (r2 < rho * rho) {
            W = fmax(W, near_weight(sqrt(r2) / rho));
            nsum += k;
          } else {
            fsum += k;
          }
        }
      if (W == 0.0) { /* near pairs only at the radius itself: the product rule */
        e += nsum + fsum;
        continue;
      }
      double a[8], b[8];
      const lw_node *na = &sp->node[lw_segment_node(sp, ga)], *nb = &sp->node[lw_segment_node(sp, gb)];
      lw_segment_bezier(na, na + 1, a);
      lw_segment_bezier(nb, nb + 1, b);
      if (!lw_pair_bezier_before(a, b))
        for (int k = 0; k < 8; k++) {
          const double t = a[k];
          a[k] = b[k], b[k] = t;
        }
      const double ow = lw_pair_order_weight(a, b, NULL, NULL);
      const double X = ow * lw_pair_segments_exact(a, b, rc) + (1.0 - ow) * lw_pair_segments_exact(b, a, rc);
      e += W * X + (1.0 - W) * (nsum + fsum);
    }
  free(S);
  return C * e;
}

static double *node_coord(lw_node *n, int c)
{
  return c == 0 ? &n->px : c == 1 ? &n->py : c == 2 ? &n->vx : &n->vy;
}

/* lw_pair_gradient at sp: its energy against lw_energy_compute's pair term
** (the same sums in another order) and the double-precision energy (float
** weights), its gradient against central differences of the latter.
** Returns the gradient's largest component; grad_out (if not NULL) gets
** the gradient. */
static double check_gradient(const char *what, lw_splines *sp, double C, double rc, double near, int nq,
                             lw_node *grad_out)
{
  lw_scene sc;
  pair_scene(&sc, C, rc, near, nq);
  lw_error err;
  lw_node *g = calloc(sp->n_nodes, sizeof *g);
  cr_assert_not_null(g);
  double e = lw_pair_gradient(&sc, sp, g, &err), term[LW_TERM_COUNT];
  lw_energy_compute(&sc, sp, term, &err);
  cr_assert(lw_close_rel(e, term[LW_TERM_PAIR], 1e-12, 0.0), "%s: energy %.17g vs the model's %.17g", what, e,
            term[LW_TERM_PAIR]);
  double ed = pair_energy_double(sp, C, rc, near, nq);
  cr_assert(lw_close_rel(e, ed, 1e-6, 0.0), "%s: energy %.17g vs in double %.17g", what, e, ed);
  double big = 0.0;
  for (size_t k = 0; k < sp->n_nodes; k++)
    for (int c = 0; c < 4; c++) big = fmax(big, fabs(*node_coord(&g[k], c)));
  for (size_t k = 0; k < sp->n_nodes; k++)
    for (int c = 0; c < 4; c++) {
      double *x = node_coord(&sp->node[k], c), x0 = *x, h = STEP; /* the curves are mm across */
      *x = x0 + h;
      double up = pair_energy_double(sp, C, rc, near, nq);
      *x = x0 - h;
      double fd = (up - pair_energy_double(sp, C, rc, near, nq)) / (2.0 * h);
      *x = x0;
      double an = *node_coord(&g[k], c);
      cr_assert(grad_close(an, fd, big), "%s (rc %g, near %g): node %zu coordinate %d: %.12g vs differences %.12g",
                what, rc, near, k, c, an, fd);
    }
  if (grad_out) memcpy(grad_out, g, sp->n_nodes * sizeof *g);
  free(g);
  lw_scene_clear(&sc);
  return big;
}

/* Three random regular splines of 3 segments, each in its own band 4 mm
** apart: no sample pair comes within the near radius. */
static lw_splines *random_bands(void)
{
  size_t segs[3] = {3, 3, 3};
  lw_splines *sp = lw_splines_new(3, segs, NULL);
  cr_assert_not_null(sp);
  for (size_t i = 0; i < 3; i++) {
    lw_node *nd = &sp->node[sp->first[i]];
    for (size_t k = 0; k <= 3; k++)
      nd[k] = (lw_node){3.0 + 4.0 * (double)k + urand(-0.4, 0.4), 4.0 + 4.0 * (double)i + urand(-0.4, 0.4),
                        urand(0.8, 1.4), urand(-0.4, 0.4)};
  }
  return sp;
}

Test(pairgrad, far_field_gradient_matches_differences)
{
  rng_seed(1601);
  for (int k = 0; k < 3; k++) {
    lw_splines *sp = random_bands();
    check_gradient("random bands, no cutoff", sp, 0.7, 0.0, 1.5, 8, NULL);
    check_gradient("random bands, cutoff 5", sp, 0.7, 5.0, 1.5, 8, NULL);
    check_gradient("random bands, product rule only", sp, 0.7, 5.0, 0.0, 6, NULL);
    lw_splines_free(sp);
  }
}

/* Curves that touch (1e-3 apart), cross and run 0.02 apart: the near field
** decides, through every part of it.  Its part of the gradient is large
** here -- the product rule's alone differs from it by more than 1 % of the
** largest component -- so the agreement with the energy's differences
** fails if that part is dropped or wrong. */
Test(pairgrad, near_field_gradient_matches_differences)
{
  rng_seed(1602);
  for (int c = 0; c < 5; c++) {
    lw_splines *sp = two_arcs(c, 1e-3);
    /* a small random displacement: off the arcs' symmetry, where ties of
    ** the near field's maxima are kinks, and no symmetry helps */
    for (size_t k = 0; k < sp->n_nodes; k++)
      for (int q = 0; q < 4; q++) *node_coord(&sp->node[k], q) += urand(-2e-3, 2e-3);
    for (int r = 0; r < 2; r++) {
      double rc = r ? 1.0 : 0.0;
      lw_node *g = calloc(sp->n_nodes, sizeof *g), *gp = calloc(sp->n_nodes, sizeof *gp);
      cr_assert(g && gp);
      double big = check_gradient(ARC_CASE[c], sp, 1.3, rc, 1.5, 8, g);
      lw_scene sc;
      lw_error err;
      pair_scene(&sc, 1.3, rc, 0.0, 8);
      lw_pair_gradient(&sc, sp, gp, &err);
      lw_scene_clear(&sc);
      double diff = 0.0;
      for (size_t k = 0; k < sp->n_nodes; k++)
        for (int q = 0; q < 4; q++) diff = fmax(diff, fabs(*node_coord(&g[k], q) - *node_coord(&gp[k], q)));
      cr_assert(diff > 1e-2 * big, "%s: the near field's part is %.1e of the gradient", ARC_CASE[c], diff / big);
      free(g);
      free(gp);
    }
    lw_splines_free(sp);
  }
}

/* Two crossing segments whose first points' x lie within the band where the
** near field blends both orders of the pair (pairnear.h): the weight's own
** derivative, times X(a, b) - X(b, a), is part of the gradient there. */
Test(pairgrad, gradient_matches_differences_where_both_orders_are_blended)
{
  const double A0[8] = {0, 0, 1.7, 0.4, 3.3, 0.6, 5, 1}, B0[8] = {0, 2, 1.7, 1, 3.3, 0, 5, -1};
  const double at[] = {0.05, -0.12, 0.2};
  for (size_t k = 0; k < sizeof at / sizeof at[0]; k++) {
    size_t segs[2] = {1, 1};
    lw_splines *sp = lw_splines_new(2, segs, NULL);
    cr_assert_not_null(sp);
    sp->node[0] = (lw_node){A0[0], A0[1], A0[2] - A0[0], A0[3] - A0[1]};
    sp->node[1] = (lw_node){A0[6], A0[7], A0[6] - A0[4], A0[7] - A0[5]};
    sp->node[2] = (lw_node){B0[0] + at[k], B0[1], B0[2] - B0[0], B0[3] - B0[1]};
    sp->node[3] = (lw_node){B0[6], B0[7], B0[6] - B0[4], B0[7] - B0[5]};
    double a[8], b[8];
    lw_segment_bezier(&sp->node[0], &sp->node[1], a);
    lw_segment_bezier(&sp->node[2], &sp->node[3], b);
    const int ab = lw_pair_bezier_before(a, b);
    const double w = ab ? lw_pair_order_weight(a, b, NULL, NULL) : lw_pair_order_weight(b, a, NULL, NULL);
    cr_assert(w > 0.5 && w < 1.0, "B at %g: weight %g, not inside the band", at[k], w);
    check_gradient("crossing, both orders blended", sp, 0.7, 0.0, 1.5, 8, NULL);
    check_gradient("crossing, both orders blended, cutoff 3", sp, 0.7, 3.0, 1.5, 8, NULL);
    lw_splines_free(sp);
  }
}

/* The term off: nothing added, energy 0. */
Test(pairgrad, term_off_adds_nothing)
{
  lw_splines *sp = two_arcs(2, 0.0);
  lw_scene sc;
  pair_scene(&sc, 0.0, 0.0, 1.5, 8);
  lw_node *g = calloc(sp->n_nodes, sizeof *g);
  lw_error err;
  cr_assert_eq(lw_pair_gradient(&sc, sp, g, &err), 0.0);
  for (size_t k = 0; k < sp->n_nodes; k++)
    cr_assert(g[k].px == 0.0 && g[k].py == 0.0 && g[k].vx == 0.0 && g[k].vy == 0.0);
  free(g);
  lw_scene_clear(&sc);
  lw_splines_free(sp);
}

/* The near pairs are evaluated in parallel and summed in their list's
** order: the same bits for any number of threads. */
Test(pairgrad, same_bits_for_any_thread_count)
{
  rng_seed(1604);
  lw_splines *sp = two_arcs(3, 0.0);
  for (size_t k = 0; k < sp->n_nodes; k++)
    for (int q = 0; q < 4; q++) *node_coord(&sp->node[k], q) += urand(-2e-3, 2e-3);
  lw_scene sc;
  pair_scene(&sc, 1.0, 1.0, 1.5, 8);
  lw_node *g[2] = {calloc(sp->n_nodes, sizeof *g[0]), calloc(sp->n_nodes, sizeof *g[1])};
  double e[2];
  lw_error err;
  int threads = omp_get_max_threads();
  for (int t = 0; t < 2; t++) {
    omp_set_num_threads(t ? 3 : 1);
    e[t] = lw_pair_gradient(&sc, sp, g[t], &err);
  }
  omp_set_num_threads(threads);
  cr_assert(memcmp(&e[0], &e[1], sizeof e[0]) == 0, "energy %.17g vs %.17g", e[0], e[1]);
  cr_assert(memcmp(g[0], g[1], sp->n_nodes * sizeof *g[0]) == 0, "the gradients differ");
  free(g[0]);
  free(g[1]);
  lw_scene_clear(&sc);
  lw_splines_free(sp);
}
