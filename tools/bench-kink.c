/*
** bench-kink.c -- what resolving the kink of (1/r - 1/rc)+ would buy the
** pair part of dE (section "kink", docs/ACCURACY.md, and docs/NUMERICS.md
** on the dE point of issue 13).
**
** The far field sums the Gauss product rule over the samples of two
** segments.  Where the circle of radius rc about a sample of A cuts B, the
** inner rule over B meets the kink of the kernel, and its error oscillates
** with the kink's place among B's nodes, so the error of dE (a derivative
** of the energy along a small move) falls only like the node spacing.  This
** study takes two curves A and B (cubic segments of 6 mm, rc = 2 mm, B a
** bent line 0.8 to 2.5 mm from A at up to 17 degrees: the study scene's
** far pairs) and a move of A's first handle by 0.055 mm (the annealer's
** final step there), and compares four outer Gauss rules of n nodes on A,
** each with its own inner integral over B at each node p of A:
**
**   product rule   the n nodes of B, sum w |b'| (1/r - 1/rc)+ (the engine's
**                  far field);
**   exact inner    the integral of |b'| (1/r - 1/rc) over the parts of B
**                  inside the circle, its ends found by bisection on
**                  |b - p|^2 - rc^2 and each part integrated to 1e-13: the
**                  kink resolved exactly in B's parameter, the best any
**                  scheme that keeps A's nodes can do;
**   interpolated   the integral of (P)+, P the polynomial through
**                  f = |b'| (1/r - 1/rc) at B's n nodes (their values outside
**                  the circle too): what a scheme that reads only B's
**                  samples can do;
**   split          the exact inner integral under n nodes on each piece of
**                  A between the places where p's circle touches B or passes
**                  one of B's ends (where the number of crossings changes):
**                  an outer rule that knows the singularities of order 3/2
**                  the others leave inside their pieces;
**   smoothed       the product rule with the kink rounded over one mean
**                  element w = 6 mm / n on either side of rc (smoothed_kernel
**                  below): a kernel the Gauss rule resolves, at the price of
**                  a bias against the defined one.
**
** Reference: the exact inner integral under 200 panels of 6 Gauss nodes on A
** (800 panels agree to 1e-4 of the error at 64 nodes).  Fixed seed; a
** configuration where B lies beyond the cutoff of all of A is drawn again;
** the figure is the median over the configurations of |dE - dE_ref| / |dE_ref|.
*/
#include <gsl/gsl_integration.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "benchutil.h"

#define KINK_RC 2.0
#define KINK_SCAN 600 /* the inner integrands' sign is read at this many points */
#define KINK_MAXN 64
#define KINK_PANELS 200 /* the reference's panels on A */
#define KINK_SPLIT_SCAN 400 /* A is scanned at this many points for changes in the crossings */
#define KINK_MAXBREAK 64

enum { RULE_PRODUCT, RULE_EXACT, RULE_INTERP, RULE_SPLIT, RULE_SMOOTH, RULES };

typedef struct {
  gsl_integration_glfixed_table *tab[KINK_MAXN + 1];
} kink_tables;

static const gsl_integration_glfixed_table *kink_table(kink_tables *k, int n)
{
  if (!k->tab[n] && !(k->tab[n] = gsl_integration_glfixed_table_alloc((size_t)n))) bench_die("out of memory", NULL);
  return k->tab[n];
}

static void cubic(const double c[8], double t, double r[2], double d[2])
{
  double u = 1 - t;
  for (int k = 0; k < 2; k++) {
    r[k] = u * u * u * c[k] + 3 * u * u * t * c[2 + k] + 3 * u * t * t * c[4 + k] + t * t * t * c[6 + k];
    d[k] = 3 * (u * u * (c[2 + k] - c[k]) + 2 * u * t * (c[4 + k] - c[2 + k]) + t * t * (c[6 + k] - c[4 + k]));
  }
}

/* The integrand of an inner integral over B at p, positive inside the circle. */
typedef struct {
  double (*f)(const void *ctx, double t);
  const void *ctx;
} kink_fn;

/* Integral over [0, 1] of the positive part of fn: its sign read at
** KINK_SCAN + 1 points, each sign change bisected to the last bit, each part
** where fn > 0 by `panels` panels of `nodes` Gauss nodes (8 of 20: exact);
** *parts (if not NULL) counts the parts. */
static double positive_part_by(kink_tables *k, kink_fn fn, int nodes, int panels, long *parts)
{
  const gsl_integration_glfixed_table *g = kink_table(k, nodes);
  double cut[KINK_SCAN + 2], prev = fn.f(fn.ctx, 0.0), s = 0.0;
  int nc = 0;
  cut[nc++] = 0.0;
  for (int i = 1; i <= KINK_SCAN; i++) {
    double t = (double)i / KINK_SCAN, v = fn.f(fn.ctx, t);
    if ((v > 0) != (prev > 0)) {
      double lo = (double)(i - 1) / KINK_SCAN, hi = t;
      while (hi - lo > 1e-15) {
        double m = 0.5 * (lo + hi);
        if ((fn.f(fn.ctx, m) > 0) == (prev > 0)) lo = m;
        else hi = m;
      }
      cut[nc++] = 0.5 * (lo + hi);
    }
    prev = v;
  }
  cut[nc++] = 1.0;
  for (int i = 0; i + 1 < nc; i++) {
    double a = cut[i], b = cut[i + 1];
    if (!(fn.f(fn.ctx, 0.5 * (a + b)) > 0)) continue;
    if (parts) ++*parts;
    for (int q = 0; q < panels; q++)
      for (size_t j = 0; j < (size_t)nodes; j++) {
        double x, w;
        gsl_integration_glfixed_point(a + (b - a) * q / panels, a + (b - a) * (q + 1) / panels, j, &x, &w, g);
        s += w * fn.f(fn.ctx, x);
      }
  }
  return s;
}

static double positive_part(kink_tables *k, kink_fn fn) { return positive_part_by(k, fn, 20, 8, NULL); }

typedef struct {
  const double *b;
  double p[2];
} exact_ctx;

static double exact_f(const void *v, double t)
{
  const exact_ctx *c = v;
  double r[2], d[2];
  cubic(c->b, t, r, d);
  return hypot(d[0], d[1]) * (1 / hypot(r[0] - c->p[0], r[1] - c->p[1]) - 1 / KINK_RC);
}

/* How many times B crosses the circle about p (sign changes of the
** integrand on the scan of positive_part). */
static int crossings(const double b[8], const double p[2])
{
  exact_ctx e = {b, {p[0], p[1]}};
  int n = 0, prev = exact_f(&e, 0.0) > 0;
  for (int i = 1; i <= KINK_SCAN; i++) {
    int in = exact_f(&e, (double)i / KINK_SCAN) > 0;
    n += in != prev;
    prev = in;
  }
  return n;
}

static int crossings_at(const double a[8], const double b[8], double s)
{
  double r[2], d[2];
  cubic(a, s, r, d);
  return crossings(b, r);
}

/* The places on A (0 and 1 included, ascending) where the crossings change:
** scanned at KINK_SPLIT_SCAN + 1 points, each change bisected to 1e-14. */
static int split_points(const double a[8], const double b[8], double at[KINK_MAXBREAK])
{
  int n = 0, prev = crossings_at(a, b, 0.0);
  at[n++] = 0.0;
  for (int i = 1; i <= KINK_SPLIT_SCAN; i++) {
    double s = (double)i / KINK_SPLIT_SCAN;
    int c = crossings_at(a, b, s);
    if (c != prev && n < KINK_MAXBREAK - 1) {
      double lo = (double)(i - 1) / KINK_SPLIT_SCAN, hi = s;
      while (hi - lo > 1e-14) {
        double m = 0.5 * (lo + hi);
        if (crossings_at(a, b, m) == prev) lo = m;
        else hi = m;
      }
      at[n++] = 0.5 * (lo + hi);
    }
    prev = c;
  }
  at[n++] = 1.0;
  return n;
}

/* (1/r - 1/rc)+ with its kink rounded over |r - rc| < w, keeping the
** defined kernel's integral against any cubic in r: near rc the kernel is
** sum_k (rc - r)+^k / rc^(k+1); each term up to k = 3 is convolved with
** K(x) = 945/512 (1 - x^2)^3 (1 - 11/3 x^2) on [-w, w], whose second moment
** is 0, so a convolved cubic is the cubic itself beyond w (what is left,
** of order 4, keeps its kink: a jump in the fourth derivative).  The
** convolution is a polynomial of degree 11 in the offset: 12 Gauss nodes
** take it exactly. */
static double smoothed_kernel(kink_tables *k, double r, double w)
{
  const double x = KINK_RC - r, kink = r < KINK_RC ? 1 / r - 1 / KINK_RC : 0;
  if (!(fabs(x) < w)) return kink;
  const gsl_integration_glfixed_table *g = kink_table(k, 12);
  const double c1 = 1 / (KINK_RC * KINK_RC), c2 = c1 / KINK_RC, c3 = c2 / KINK_RC, xp = x > 0 ? x : 0;
  double s = 0;
  for (size_t j = 0; j < 12; j++) {
    double z, wt;
    gsl_integration_glfixed_point(-w, x, j, &z, &wt, g);
    const double u = 1 - (z / w) * (z / w), y = x - z;
    s += wt * 945.0 / 512 * u * u * u * (1 - 11.0 / 3 * (z / w) * (z / w)) / w * y * (c1 + y * (c2 + y * c3));
  }
  return kink + s - xp * (c1 + xp * (c2 + xp * c3));
}

/* P through n values at the Gauss nodes, in barycentric form (weights of the
** Legendre points: (-1)^j sqrt((1 - z_j^2) w_j), z = 2t - 1). */
typedef struct {
  int n;
  double t[KINK_MAXN], f[KINK_MAXN], lam[KINK_MAXN];
} interp_ctx;

static double interp_f(const void *v, double t)
{
  const interp_ctx *c = v;
  double num = 0, den = 0;
  for (int j = 0; j < c->n; j++) {
    double d = t - c->t[j];
    if (d == 0) return c->f[j];
    num += c->lam[j] / d * c->f[j];
    den += c->lam[j] / d;
  }
  return num / den;
}

/* The inner integral over B at p by rule `rule` with n nodes. */
static double inner(kink_tables *k, int rule, const double b[8], const double p[2], int n)
{
  exact_ctx e = {b, {p[0], p[1]}};
  if (rule == RULE_EXACT || rule == RULE_SPLIT) return positive_part(k, (kink_fn){exact_f, &e});
  const gsl_integration_glfixed_table *g = kink_table(k, n);
  interp_ctx ip = {.n = n};
  double s = 0;
  for (int j = 0; j < n; j++) {
    double t, w;
    gsl_integration_glfixed_point(0, 1, (size_t)j, &t, &w, g);
    double f = exact_f(&e, t), z = 2 * t - 1;
    if (rule == RULE_SMOOTH) {
      double q[2], dq[2];
      cubic(b, t, q, dq);
      s += w * hypot(dq[0], dq[1]) * smoothed_kernel(k, hypot(q[0] - p[0], q[1] - p[1]), 6.0 / n);
      continue;
    }
    s += f > 0 ? w * f : 0;
    ip.t[j] = t;
    ip.f[j] = f;
    ip.lam[j] = ((j & 1) ? -1 : 1) * sqrt((1 - z * z) * w);
  }
  return rule == RULE_PRODUCT || rule == RULE_SMOOTH ? s : positive_part(k, (kink_fn){interp_f, &ip});
}

/* The pair energy (C = 1): n Gauss nodes on each piece of A between
** consecutive points of `at` (np of them). */
static double pair_energy_pieces(kink_tables *k, int rule, const double a[8], const double b[8], int n,
                                 const double *at, int np)
{
  const gsl_integration_glfixed_table *g = kink_table(k, n);
  double s = 0;
  for (int q = 0; q + 1 < np; q++)
    for (int i = 0; i < n; i++) {
      double x, w, r[2], d[2];
      gsl_integration_glfixed_point(at[q], at[q + 1], (size_t)i, &x, &w, g);
      cubic(a, x, r, d);
      s += w * hypot(d[0], d[1]) * inner(k, rule, b, r, n);
    }
  return s;
}

/* What the split rule costs: m Gauss nodes on each piece of A, and at each
** of them m Gauss nodes on each part of B inside its circle (found exactly
** here; a chain would find them as roots of a degree-6 polynomial).
** *values counts the kernel values. */
static double pair_energy_split_m(kink_tables *k, const double a[8], const double b[8], int m, const double *at,
                                  int np, long *values)
{
  const gsl_integration_glfixed_table *g = kink_table(k, m);
  double s = 0;
  for (int q = 0; q + 1 < np; q++)
    for (int i = 0; i < m; i++) {
      double x, w, r[2], d[2];
      long parts = 0;
      gsl_integration_glfixed_point(at[q], at[q + 1], (size_t)i, &x, &w, g);
      cubic(a, x, r, d);
      exact_ctx e = {b, {r[0], r[1]}};
      s += w * hypot(d[0], d[1]) * positive_part_by(k, (kink_fn){exact_f, &e}, m, 1, &parts);
      *values += parts * m;
    }
  return s;
}

/* The same on `panels` (at most KINK_PANELS) equal panels of A. */
static double pair_energy(kink_tables *k, int rule, const double a[8], const double b[8], int n, int panels)
{
  double at[KINK_PANELS + 1];
  for (int q = 0; q <= panels; q++) at[q] = (double)q / panels;
  return pair_energy_pieces(k, rule, a, b, n, at, panels + 1);
}

void bench_kink(bench_ctx *b)
{
  static const int nodes[] = {4, 6, 8, 12, 16, 24, 32, 64};
  enum { NN = (int)(sizeof nodes / sizeof nodes[0]) };
  static const char *const rule_name[RULES] = {"product rule", "exact inner", "interpolated inner",
                                               "exact inner, A split", "kink smoothed over an element"};
  const int configs = b->quick ? 30 : 200, panels = KINK_PANELS;
  FILE *d = b->doc[BENCH_ACCURACY];
  kink_tables k = {{0}};
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  if (!r) bench_die("out of memory", NULL);
  double *err[RULES][NN];
  for (int m = 0; m < RULES; m++)
    for (int i = 0; i < NN; i++)
      if (!(err[m][i] = malloc((size_t)configs * sizeof(double)))) bench_die("out of memory", NULL);
  gsl_rng_set(r, 3);
  static const int split_m[] = {2, 3, 4, 5, 6, 8};
  enum { NM = (int)(sizeof split_m / sizeof split_m[0]) };
  double *err_m[NM];
  long values_m[NM] = {0};
  for (int i = 0; i < NM; i++)
    if (!(err_m[i] = malloc((size_t)configs * sizeof(double)))) bench_die("out of memory", NULL);
  double t0 = bench_now(), pieces_sum = 0;
  for (int c = 0; c < configs; c++) {
    /* one draw a statement: the order of evaluation within an initialiser is unspecified */
    double a[8] = {0, 0, 2, 0, 4, 0, 6, 0}, bb[8];
    a[3] = gsl_ran_flat(r, -1, 1);
    a[5] = gsl_ran_flat(r, -1, 1);
    double dist = gsl_ran_flat(r, 0.8, 2.5);
    double th = gsl_ran_flat(r, -0.3, 0.3);
    double x0 = gsl_ran_flat(r, 0, 6);
    for (int j = 0; j < 4; j++) {
      double s = -3 + 2 * j, off = (j == 1 || j == 2) ? gsl_ran_flat(r, -0.7, 0.7) : 0;
      bb[2 * j] = x0 + s * cos(th) - off * sin(th);
      bb[2 * j + 1] = dist + s * sin(th) + off * cos(th);
    }
    double a2[8];
    for (int j = 0; j < 8; j++) a2[j] = a[j];
    double ang = gsl_ran_flat(r, 0, 2 * M_PI);
    a2[2] += 0.055 * cos(ang);
    a2[3] += 0.055 * sin(ang);
    double e0 = pair_energy(&k, RULE_EXACT, a, bb, 6, panels);
    if (e0 == 0.0) { /* B beyond the cutoff of every point of A: no pair, draw again */
      c--;
      continue;
    }
    double ref = pair_energy(&k, RULE_EXACT, a2, bb, 6, panels) - e0;
    double at[KINK_MAXBREAK], at2[KINK_MAXBREAK];
    int np = split_points(a, bb, at), np2 = split_points(a2, bb, at2);
    pieces_sum += np - 1 + np2 - 1;
    for (int m = 0; m < RULES; m++)
      for (int i = 0; i < NN; i++) {
        double de = m == RULE_SPLIT ? pair_energy_pieces(&k, m, a2, bb, nodes[i], at2, np2) -
                                          pair_energy_pieces(&k, m, a, bb, nodes[i], at, np)
                                    : pair_energy(&k, m, a2, bb, nodes[i], 1) - pair_energy(&k, m, a, bb, nodes[i], 1);
        err[m][i][c] = fabs(de - ref) / fabs(ref);
      }
    for (int i = 0; i < NM; i++) {
      double de = pair_energy_split_m(&k, a2, bb, split_m[i], at2, np2, &values_m[i]) -
                  pair_energy_split_m(&k, a, bb, split_m[i], at, np, &values_m[i]);
      err_m[i][c] = fabs(de - ref) / fabs(ref);
    }
  }
  bench_note("kink: %d configurations in %.1f s", configs, bench_now() - t0);

  fprintf(d, "What resolving the kink would buy (tools/bench-kink.c): two curves, A and a bent line B\n"
             "0.8 to 2.5 mm from it (cubic segments of 6 mm, rc = 2 mm, %d random configurations, fixed\n"
             "seed), and a 0.055 mm move of A's handle. The median relative error of the pair's dE\n"
             "against the reference, for an outer Gauss rule of n nodes on A with three inner integrals\n"
             "over B: the product rule (the engine's far field); the exact integral over the parts of B\n"
             "inside each node's circle (the kink resolved in B's parameter, the best any rule on A's\n"
             "nodes can do); and the integral of (P)+, P the polynomial through B's n node values of\n"
             "|b'| (1/r - 1/rc), outside the circle too (what B's samples alone can give). The fourth\n"
             "column keeps the exact inner integral but splits A where a node's circle touches B or\n"
             "passes one of B's ends (%.1f pieces a segment on average), n nodes on each piece.\n"
             "The fifth is the product rule again, with the kink rounded over one mean element on either\n"
             "side of rc by a kernel of second moment 0 (no bias against a cubic in r).\n\n"
             "| nodes | %s | %s | %s | %s | %s |\n|---|---|---|---|---|---|\n",
          configs, pieces_sum / (2.0 * configs), rule_name[0], rule_name[1], rule_name[2], rule_name[3],
          rule_name[4]);
  int first[RULES] = {0};
  double med[RULES][NN];
  for (int i = 0; i < NN; i++) {
    for (int m = 0; m < RULES; m++) {
      gsl_sort(err[m][i], 1, (size_t)configs);
      med[m][i] = gsl_stats_median_from_sorted_data(err[m][i], 1, (size_t)configs);
      if (!first[m] && med[m][i] < 1e-3) first[m] = nodes[i];
    }
    fprintf(d, "| %d | %.1e | %.1e | %.1e | %.1e | %.1e |\n", nodes[i], med[0][i], med[1][i], med[2][i], med[3][i],
            med[4][i]);
  }
  char from[RULES][16];
  for (int m = 0; m < RULES; m++)
    snprintf(from[m], sizeof from[m], first[m] ? "%d" : "none up to 64", first[m]);
  fprintf(d, "\nThe first node count with an error below 1e-3: %s for the product rule, %s for the exact\n"
             "inner integral, %s for the interpolated one, %s a piece with A split, %s with the kink\n"
             "smoothed (whose rounding, shrinking with the element, errs in dE by about as much as the\n"
             "rule gains: NUMERICS.md, \"The dE point\"). With the kink\n"
             "resolved along B the error left is the outer rule's: the inner integral, as a function of\n"
             "the node p on A, has a singularity of order 3/2 wherever p's circle touches B, and a jump\n"
             "in its second derivative where the circle passes B's end; an outer rule with its pieces\n"
             "ending there is spectrally accurate again, down to the reference's own error (NUMERICS.md,\n"
             "\"The dE point\").\n\n",
          from[0], from[1], from[2], from[3], from[4]);
  fprintf(d, "What the split rule would cost: with m Gauss nodes on each piece of A and m on each part of\n"
             "B inside a node's circle (instead of the exact inner integral), the median error of dE and\n"
             "the kernel values a segment pair takes (the mean over the configurations and both sides of\n"
             "the move; the product rule at 8 nodes takes 64 distances, and the kernel at the 20 to 30 of\n"
             "them inside rc). Finding the pieces (where circles about A touch B) and each node's parts\n"
             "(the roots of a degree-6 polynomial) comes on top.\n\n"
             "| m | dE | kernel values a pair |\n|---|---|---|\n");
  for (int i = 0; i < NM; i++) {
    gsl_sort(err_m[i], 1, (size_t)configs);
    fprintf(d, "| %d | %.1e | %.0f |\n", split_m[i], gsl_stats_median_from_sorted_data(err_m[i], 1, (size_t)configs),
            (double)values_m[i] / (2.0 * configs));
    free(err_m[i]);
  }
  fprintf(d, "\n");
  for (int m = 0; m < RULES; m++)
    for (int i = 0; i < NN; i++) free(err[m][i]);
  for (int n = 0; n <= KINK_MAXN; n++)
    if (k.tab[n]) gsl_integration_glfixed_table_free(k.tab[n]);
  gsl_rng_free(r);
}
