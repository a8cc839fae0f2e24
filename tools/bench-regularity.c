/*
** bench-regularity.c -- the regularity threshold energy.min_speed: how far
** the bending integral of an allowed segment can be off at each node count
** (section "regularity", docs/ACCURACY.md), and what the check costs a
** proposal (section "regularity_cost", docs/PERFORMANCE.md).
**
** The error study.  Bending and its relative error are invariant under
** translation, rotation and scale, so every segment is b0 = (0,0),
** b3 = (1,0) with b1, b2 free.  For each segment:
**   reference  B(t) = (x'y'' - x''y')^2 / |r'|^5 integrated over [0,1] by
**              GSL's adaptive QAGS (relative tolerance 1e-12);
**   n nodes    lw_segment_sample + lw_term_bending, the model's own code;
**   ratio      lw_segment_min_speed / the n-node length, the model's test
**              (lw_segment_allowed): a segment is allowed at threshold r and
**              n nodes if that ratio is >= r;
**   error      |I_n - I| / max(I, floor), floor = 1e-6 / length: the bending
**              of an arc turning one milliradian, so straight segments (whose
**              bending is 0 at any node count) do not divide by zero.
** The worst case is searched hard: random control points from five families
** (generic, loops, near-cusps built from a hodograph through zero, nearly
** straight with handles up to 100 chords, wide arcs), then, for every
** (threshold, node count), a hill climb from the worst few found, which
** moves b1 and b2 while the segment stays allowed and the error grows.
*/
#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_randist.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "benchutil.h"
#include "linewise/model.h"
#include "linewise/terms.h"

#define N_NODES 6
/* The two tests alone, then together: the minimum speed over the mean
** (energy.min_speed) and the Bernstein ellipse of the nearest singularity
** (energy.regularity). */
#define N_ALONE 12
#define N_R 5
#define N_RHO 5
#define N_CELLS (2 * N_ALONE + N_R * N_RHO)
static const double alone[2][N_ALONE] = {
    {0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95},
    {1.05, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6, 1.7, 1.8, 2.0, 2.2, 2.5}};
static const double both_r[N_R] = {0.0, 0.3, 0.4, 0.5, 0.6};
static const double both_rho[N_RHO] = {2.0, 2.2, 2.4, 2.6, 3.0};
typedef struct {
  double r, rho; /* a segment is allowed if its speed ratio >= r and its rho >= rho */
} cell;
static const int node_counts[N_NODES] = {4, 6, 8, 12, 16, 24};
#define KEEP 4 /* worst starts kept per cell for the hill climb */

typedef struct {
  double b[4]; /* b1x b1y b2x b2y: the inner control points (b0 = (0,0), b3 = (1,0)) */
} seg;

static void nodes_of(const seg *s, lw_node nd[2])
{
  nd[0] = (lw_node){0.0, 0.0, s->b[0], s->b[1]};
  nd[1] = (lw_node){1.0, 0.0, 1.0 - s->b[2], -s->b[3]};
}

static double integrand(double t, void *params)
{
  const lw_node *nd = params;
  double d1[2], d2[2];
  lw_segment_eval(&nd[0], &nd[1], t, NULL, d1, d2);
  double sp2 = d1[0] * d1[0] + d1[1] * d1[1];
  if (sp2 == 0.0) return 0.0;
  double c = d1[0] * d2[1] - d2[0] * d1[1];
  return c * c / (sp2 * sp2 * sqrt(sp2));
}

static double speed(double t, void *params)
{
  const lw_node *nd = params;
  double d1[2];
  lw_segment_eval(&nd[0], &nd[1], t, NULL, d1, NULL);
  return hypot(d1[0], d1[1]);
}

typedef struct {
  gsl_integration_workspace *ws;
  lw_quad q[N_NODES];
} study;

static double qags(study *st, double (*f)(double, void *), lw_node nd[2])
{
  gsl_function F = {f, nd};
  double v, e;
  gsl_integration_qags(&F, 0.0, 1.0, 0.0, 1e-12, 2000, st->ws, &v, &e);
  return v;
}

/* One segment measured: the reference bending and length, the exact
** minimum speed, and per node count the relative error and the speed ratio
** the model tests. */
typedef struct {
  double ref, length, min_speed, rho;
  double err[N_NODES], ratio[N_NODES];
} eval;

static void evaluate(study *st, const seg *s, eval *e)
{
  lw_node nd[2];
  nodes_of(s, nd);
  e->ref = qags(st, integrand, nd);
  e->length = qags(st, speed, nd);
  e->min_speed = lw_segment_min_speed(&nd[0], &nd[1]);
  e->rho = lw_segment_rho(&nd[0], &nd[1]);
  double floor = 1e-6 / e->length;
  for (int k = 0; k < N_NODES; k++) {
    lw_samples sm;
    lw_segment_sample(&st->q[k], &nd[0], &nd[1], &sm);
    double in = lw_term_bending(&sm, &st->q[k]);
    e->err[k] = fabs(in - e->ref) / fmax(e->ref, floor);
    e->ratio[k] = sm.length > 0 ? e->min_speed / sm.length : 0.0;
  }
}

static int allowed(const eval *e, int k, cell c)
{
  return e->ratio[k] >= c.r && e->rho >= c.rho && isfinite(e->err[k]);
}

/* The five families of random segments. */
static void draw(gsl_rng *r, int family, seg *s)
{
  double u = gsl_rng_uniform(r);
  switch (family) {
  case 0: /* generic: handles anywhere near the chord */
    for (int i = 0; i < 4; i++) s->b[i] = gsl_ran_flat(r, -1.5, 2.5) * (i % 2 ? 0.75 : 1.0);
    break;
  case 1: /* loops: b1 and b2 crossed far over */
    s->b[0] = gsl_ran_flat(r, 0.5, 3.0);
    s->b[1] = gsl_ran_flat(r, 0.2, 2.0);
    s->b[2] = gsl_ran_flat(r, -2.0, 0.5);
    s->b[3] = s->b[1] + gsl_ran_gaussian(r, 0.5);
    break;
  case 2: { /* near-cusp: a hodograph h0 (1-t)^2 + 2 h1 t(1-t) + h2 t^2 through
            ** (nearly) zero at t0, then shifted so the chord is (1, 0) */
    double t0 = gsl_ran_flat(r, 0.05, 0.95), a = 2 * M_PI * u;
    double dx = cos(a), dy = sin(a), k = gsl_ran_flat(r, 0.2, 4.0), eps = pow(10.0, gsl_ran_flat(r, -4, 0));
    /* h(t) = (t - t0) D + k (t - t0)^2 E + eps N: a fold at t0 of depth eps */
    double ex = -dy, ey = dx, hx[3], hy[3];
    double nx = gsl_ran_gaussian(r, 1), ny = gsl_ran_gaussian(r, 1);
    const double ts[3] = {0.0, 0.5, 1.0};
    double val[3][2];
    for (int i = 0; i < 3; i++) {
      double t = ts[i] - t0;
      val[i][0] = t * dx + k * t * t * ex + eps * nx;
      val[i][1] = t * dy + k * t * t * ey + eps * ny;
    }
    /* Bezier control points from the values at 0, 1/2, 1 */
    hx[0] = val[0][0];
    hy[0] = val[0][1];
    hx[2] = val[2][0];
    hy[2] = val[2][1];
    hx[1] = 2 * val[1][0] - 0.5 * (val[0][0] + val[2][0]);
    hy[1] = 2 * val[1][1] - 0.5 * (val[0][1] + val[2][1]);
    /* control points b_{i+1} = b_i + h_i / 3, then rotate and scale the chord onto (1, 0) */
    double bx[4] = {0}, by[4] = {0};
    for (int i = 0; i < 3; i++) {
      bx[i + 1] = bx[i] + hx[i] / 3;
      by[i + 1] = by[i] + hy[i] / 3;
    }
    double cx = bx[3], cy = by[3], c2 = cx * cx + cy * cy;
    if (c2 < 1e-12) { /* a closed loop: no chord to map */
      draw(r, 0, s);
      return;
    }
    for (int i = 1; i <= 2; i++) {
      double x = (bx[i] * cx + by[i] * cy) / c2, y = (by[i] * cx - bx[i] * cy) / c2;
      s->b[2 * (i - 1)] = x;
      s->b[2 * (i - 1) + 1] = y;
    }
    break;
  }
  case 3: { /* nearly straight, handles up to 100 chords */
    double la = pow(10.0, gsl_ran_flat(r, -1, 2)), lb = pow(10.0, gsl_ran_flat(r, -1, 2));
    s->b[0] = la;
    s->b[1] = gsl_ran_gaussian(r, 0.05 * la);
    s->b[2] = 1.0 - lb;
    s->b[3] = gsl_ran_gaussian(r, 0.05 * lb);
    break;
  }
  default: { /* arcs of up to 330 degrees, handles off the standard length */
    double th = gsl_ran_flat(r, 0.1, 5.76), R = 0.5 / sin(th / 2), h = 4.0 / 3.0 * tan(th / 4) * R;
    double f0 = gsl_ran_flat(r, 0.3, 2.0), f1 = gsl_ran_flat(r, 0.3, 2.0);
    s->b[0] = f0 * h * cos(th / 2);
    s->b[1] = f0 * h * sin(th / 2);
    s->b[2] = 1.0 - f1 * h * cos(th / 2);
    s->b[3] = f1 * h * sin(th / 2);
  }
  }
}

typedef struct {
  cell c[N_CELLS];
  double err[N_CELLS][N_NODES];
  seg worst[N_CELLS][N_NODES][KEEP];
  double werr[N_CELLS][N_NODES][KEEP];
  long allowed[N_CELLS]; /* at 8 nodes */
} table;

static void record(table *t, const seg *s, const eval *e)
{
  for (int i = 0; i < N_CELLS; i++)
    for (int k = 0; k < N_NODES; k++) {
      if (!allowed(e, k, t->c[i])) continue;
      if (node_counts[k] == 8) t->allowed[i]++;
      if (e->err[k] > t->err[i][k]) t->err[i][k] = e->err[k];
      /* keep the KEEP worst, replacing the smallest */
      int lo = 0;
      for (int j = 1; j < KEEP; j++)
        if (t->werr[i][k][j] < t->werr[i][k][lo]) lo = j;
      if (e->err[k] > t->werr[i][k][lo]) {
        t->werr[i][k][lo] = e->err[k];
        t->worst[i][k][lo] = *s;
      }
    }
}

/* Hill climb from s within the allowed set of (thr, node index k). */
static double climb(study *st, gsl_rng *r, seg s, cell lim, int k, int steps)
{
  eval e;
  evaluate(st, &s, &e);
  double best = e.err[k], step = 0.05;
  for (int it = 0; it < steps; it++) {
    seg c = s;
    double scale = step * (1.0 + fabs(s.b[0]) + fabs(s.b[2]));
    for (int i = 0; i < 4; i++) c.b[i] += gsl_ran_gaussian(r, scale);
    evaluate(st, &c, &e);
    if (allowed(&e, k, lim) && e.err[k] > best) {
      best = e.err[k];
      s = c;
      step *= 1.3;
    } else {
      step *= 0.93;
      if (step < 1e-5) step = 0.05;
    }
  }
  return best;
}

/* The climbs from the worst segments of the random phase, then the
** monotone fix: an allowed set that contains another has no smaller worst
** error (a climb may find more in the smaller set). */
static void finish(study *st, gsl_rng *r, table *t, int steps)
{
  for (int i = 0; i < N_CELLS; i++)
    for (int k = 0; k < N_NODES; k++)
      for (int j = 0; j < KEEP; j++) {
        if (t->werr[i][k][j] <= 0) continue;
        double e = climb(st, r, t->worst[i][k][j], t->c[i], k, steps);
        if (e > t->err[i][k]) t->err[i][k] = e;
      }
  for (int i = 0; i < N_CELLS; i++)
    for (int j = 0; j < N_CELLS; j++)
      if (t->c[j].r >= t->c[i].r && t->c[j].rho >= t->c[i].rho)
        for (int k = 0; k < N_NODES; k++)
          if (t->err[j][k] > t->err[i][k]) t->err[i][k] = t->err[j][k];
}

static double share(const table *t, int i, long drawn)
{
  return 100.0 * (double)t->allowed[i] / (double)drawn;
}

/* The cells first..first+N_ALONE-1 (one test alone) as a table. */
static void print_alone(FILE *d, const table *t, int first, const char *name, int which, long drawn)
{
  fprintf(d, "| %s | allowed (8 nodes) |", name);
  for (int k = 0; k < N_NODES; k++) fprintf(d, " %d nodes |", node_counts[k]);
  fprintf(d, "\n|---|---|");
  for (int k = 0; k < N_NODES; k++) fprintf(d, "---|");
  fprintf(d, "\n");
  for (int i = first; i < first + N_ALONE; i++) {
    fprintf(d, "| %g | %.1f %% |", which ? t->c[i].rho : t->c[i].r, share(t, i, drawn));
    for (int k = 0; k < N_NODES; k++) fprintf(d, " %.1e |", t->err[i][k]);
    fprintf(d, "\n");
  }
}

void bench_regularity(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_ACCURACY];
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  study st;
  st.ws = gsl_integration_workspace_alloc(2000);
  for (int k = 0; k < N_NODES; k++)
    if (lw_quad_init(&st.q[k], node_counts[k], NULL)) bench_die("quadrature", NULL);
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 20261130);
  static table t;
  memset(&t, 0, sizeof t);
  for (int i = 0; i < N_ALONE; i++) {
    t.c[i] = (cell){alone[0][i], 0.0};
    t.c[N_ALONE + i] = (cell){0.0, alone[1][i]};
  }
  const int both = 2 * N_ALONE;
  for (int i = 0; i < N_R; i++)
    for (int j = 0; j < N_RHO; j++) t.c[both + i * N_RHO + j] = (cell){both_r[i], both_rho[j]};
  const long per_family = b->quick ? 2000 : 100000;
  const int steps = b->quick ? 100 : 1000;
  double t0 = bench_now();
  long drawn = 0;
  for (int f = 0; f < 5; f++)
    for (long i = 0; i < per_family; i++) {
      seg s;
      draw(r, f, &s);
      eval e;
      evaluate(&st, &s, &e);
      drawn++;
      record(&t, &s, &e);
    }
  double t_rand = bench_now() - t0;
  finish(&st, r, &t, steps);
  double t_all = bench_now() - t0;
  /* the default: within 1e-3 at 8 nodes, letting the most random segments through */
  int pick = -1;
  for (int i = both; i < N_CELLS; i++)
    if (t.err[i][2] <= 1e-3 && (pick < 0 || t.allowed[i] > t.allowed[pick])) pick = i;

  fprintf(d, "## Regular segments\n\n"
             "Where a segment's speed |r'| nearly stops, its curvature peaks between the quadrature\n"
             "nodes and a fixed rule misses the bending there; an annealer finds such folds and\n"
             "hides energy in them. Two exact tests forbid such segments (+infinity, like leaving\n"
             "the frame; spline.h, model.h, docs/NUMERICS.md):\n\n"
             "- `energy.min_speed` r: the minimum speed over [0, 1] (a cubic equation) below r times\n"
             "  the mean speed (the length at the model's nodes);\n"
             "- `energy.regularity` rho: the bending integrand's nearest singularity (a complex zero of\n"
             "  |r'|^2, a quadratic equation) inside the Bernstein ellipse of parameter rho around\n"
             "  the segment; Gauss-Legendre's error is O(rho^-2n) times the integrand's size there.\n\n"
             "The worst relative error of the bending integral int kappa^2 dl of one allowed segment,\n"
             "against adaptive quadrature (GSL QAGS, relative tolerance 1e-12), over %ld random\n"
             "segments (five families: generic, loops, near-cusps, nearly straight with handles up\n"
             "to 100 chords, arcs to 330 degrees), then a hill climb from the %d worst of each cell\n"
             "(%d steps each) that moves the handles while the segment stays allowed. Relative to\n"
             "max(bending, 1e-6 / length), the bending of an arc turning one milliradian, so that\n"
             "straight segments (bending 0 at every node count) count as exact. *allowed*: the share\n"
             "of the random segments let through at 8 nodes (the families are harsh on purpose:\n"
             "annealed line art is far more regular). %.0f s, of which %.0f s the random phase.\n\n"
             "Each test alone:\n\n",
          drawn, KEEP, steps, t_all, t_rand);
  print_alone(d, &t, 0, "min_speed", 0, drawn);
  fprintf(d, "\n");
  print_alone(d, &t, N_ALONE, "regularity", 1, drawn);
  fprintf(d, "\nNeither alone bounds the error at a threshold that leaves room to draw. The minimum\n"
             "speed misses tight U-turns: a segment can keep %.0f %% of its mean speed and still turn\n"
             "through 200 degrees or more within a width the nodes do not resolve. The ellipse misses\n"
             "the end of a segment whose speed falls toward a zero just past its end (a short\n"
             "handle): the singularity is far enough, the integrand there is still steep. Together\n"
             "(worst relative error at 8 nodes, and the share allowed):\n\n| min_speed |",
          100.0 * alone[0][N_ALONE - 2]);
  for (int j = 0; j < N_RHO; j++) fprintf(d, " rho %g |", both_rho[j]);
  fprintf(d, "\n|---|");
  for (int j = 0; j < N_RHO; j++) fprintf(d, "---|");
  fprintf(d, "\n");
  for (int i = 0; i < N_R; i++) {
    fprintf(d, "| %g |", both_r[i]);
    for (int j = 0; j < N_RHO; j++) {
      int c = both + i * N_RHO + j;
      fprintf(d, " %.1e (%.1f %%) |", t.err[c][2], share(&t, c, drawn));
    }
    fprintf(d, "\n");
  }
  if (pick >= 0) {
    /* (the hill climb's finding, a fixed fact of these defaults, written
    ** here so that a rerun keeps it: typed into the document, the next
    ** `make bench` would have dropped it) */
    fprintf(d, "\nThe defaults: the pair within 1e-3 at 8 nodes that allows the most segments,\n"
               "**min_speed = %g, regularity = %g** (worst %.1e).", t.c[pick].r, t.c[pick].rho, t.err[pick][2]);
    if (t.c[pick].r == 0.4 && t.c[pick].rho == 2.6)
      fprintf(d, " These worsts are the largest a\n"
                 "search found, not a bound: a later hill-climb over the four handle coordinates (a\n"
                 "helper's, 2026-12-06) reached 6.6e-04 at 8 nodes on the corner of both walls (min speed\n"
                 "0.400000 of the length, rho 2.600000), an overestimate (the chain sees more bending, not\n"
                 "less; the worst underestimate it found was 6.0e-04), still inside the 1e-3 the defaults\n"
                 "promise.");
    fprintf(d, " At every node count:\n\n| nodes |");
    for (int k = 0; k < N_NODES; k++) fprintf(d, " %d |", node_counts[k]);
    fprintf(d, "\n|---|");
    for (int k = 0; k < N_NODES; k++) fprintf(d, "---|");
    fprintf(d, "\n| worst relative error |");
    for (int k = 0; k < N_NODES; k++) fprintf(d, " %.1e |", t.err[pick][k]);
    fprintf(d, "\n\n");
  } else
    fprintf(d, "\nNo pair measured keeps 8 nodes within 1e-3.\n\n");
  fprintf(d, "The pair and boundary terms have scales of their own (the cutoff, the distance to the\n"
             "frame), and two more exact tests keep every allowed segment short enough against them:\n"
             "with a cutoff, no two consecutive pair samples more than %g cutoffs apart (the worst\n"
             "crossing of straight segments at that limit, in the middle of both widest gaps, errs by\n"
             "7.5e-4 at 8 nodes; near a node the near field's own error reaches 5e-3 at any gap); with the\n"
             "boundary term, the curve at least `energy.boundary_clearance` (1.5) of its own length\n"
             "elements from the frame (each segment's boundary integral within 2e-4 at 8 nodes, but\n"
             "for the kink of the distance along a corner's bisector: up to 1e-2 there).\n"
             "docs/NUMERICS.md (\"Regular segments\") has the tables behind both.\n\n",
          LW_PAIR_GAP_SHARE);
  gsl_rng_free(r);
  gsl_integration_workspace_free(st.ws);
  gsl_set_error_handler(old);
}

/* CPU time of this thread, s: a shared machine preempts the bench, and
** preemption does not count here. */
static double thread_seconds(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ns per evaluation of all the trials once on r. */
static double pass_ns(bench_run *r, const bench_trial *t, int nt)
{
  double t0 = thread_seconds();
  for (int k = 0; k < nt; k++) bench_run_propose(r, &t[k]);
  return (thread_seconds() - t0) / nt * 1e9;
}

/* What the check costs: every term but pair, both checks off and at their
** defaults, the same lines and proposals.  Rounds of four passes over the
** trials in the order off, on, on, off (ABBA: a drift in the machine's speed
** within a round cancels, and so does any advantage of going first), timed in
** thread CPU time; the ratio is the median over the rounds of on / off. */
void bench_regularity_cost(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_PERFORMANCE];
  lw_params p;
  bench_random_params(&p, 1000, 0, 2.8);
  lw_params off = p;
  off.min_speed = 0;
  off.regularity = 0;
  bench_run r[2];
  bench_run_init(&r[0], &off, NULL, 0.05, NULL);
  lw_splines *sp = lw_splines_clone(r[0].model->sp);
  if (!sp) bench_die("out of memory", NULL);
  bench_run_init(&r[1], &p, sp, 0.05, NULL);
  const double step[2] = {0.2, 0.2};
  const int nt = 4096, rounds = b->quick ? 21 : 301;
  bench_trial *trials = bench_trials_new(r[0].model->sp, step, nt);
  double *ratio = malloc((size_t)rounds * sizeof *ratio), *ns_off = malloc((size_t)rounds * sizeof *ns_off);
  double *ns_on = malloc((size_t)rounds * sizeof *ns_on);
  if (!ratio || !ns_off || !ns_on) bench_die("out of memory", NULL);
  for (int k = 0; k < 2; k++) pass_ns(&r[k], trials, nt); /* warm the caches */
  for (int q = 0; q < rounds; q++) {
    double a = pass_ns(&r[0], trials, nt), bb = pass_ns(&r[1], trials, nt);
    bb += pass_ns(&r[1], trials, nt);
    a += pass_ns(&r[0], trials, nt);
    ns_off[q] = a / 2;
    ns_on[q] = bb / 2;
    ratio[q] = bb / a;
  }
  double med = bench_median(ratio, rounds);
  /* the spread: the median absolute deviation of the round ratios */
  for (int q = 0; q < rounds; q++) ratio[q] = fabs(ratio[q] - med);
  double mad = bench_median(ratio, rounds);
  double off_ns = bench_median(ns_off, rounds), on_ns = bench_median(ns_on, rounds);
  /* how many new segments the bounds could not clear (the solvers ran) */
  long segs = 0, doubt = 0;
  for (int k = 0; k < nt; k++) {
    const lw_node *base = &r[1].model->sp->node[r[1].model->sp->first[trials[k].spline]];
    size_t nn = r[1].model->sp->first[trials[k].spline + 1] - r[1].model->sp->first[trials[k].spline];
    for (int side = -1; side <= 0; side++) {
      long m = (long)trials[k].node + side;
      if (m < 0 || m + 1 >= (long)nn) continue;
      lw_node a = base[m], c = base[m + 1];
      if ((size_t)m == trials[k].node) a = trials[k].nd;
      else c = trials[k].nd;
      lw_samples s;
      lw_segment_sample(&r[1].scene.quad, &a, &c, &s);
      segs++;
      /* the bounds alone: a test with thresholds the exact fallback cannot change */
      doubt += lw_segment_check(&a, &c, p.min_speed * s.length, p.regularity) !=
               lw_segment_check(&a, &c, 0.0, 0.0);
    }
  }
  free(trials);
  fprintf(d, "## What the regularity check costs\n\n"
             "The 1000-spline scene without the pair term (every other term on, lines 2.8 mm apart,\n"
             "quadrature 8): the same %d proposals (point and vector moves of 0.2 mm) evaluated and\n"
             "never committed, with the regularity checks off (`energy.min_speed` = 0, `energy.regularity`\n"
             "= 0: the code path of the release before them) and at their defaults (%g, %g). %d rounds of\n"
             "four passes over the proposals, off, on, on, off, so that a change in the machine's speed\n"
             "within a round cancels; thread CPU time (a shared machine preempts, which does not count);\n"
             "the ratio is the median over the rounds (+- the median absolute deviation).\n\n"
             "| checks | ns per evaluation |\n|---|---|\n"
             "| off (as before) | %.0f |\n| on (defaults) | %.0f |\n\n"
             "Ratio on / off: **%.3f +- %.3f**. Of the %ld new segments, %ld %s refused (the rest pass\n"
             "the cheap bounds or the exact tests).\n\n"
             "These small moves of a placed scene understate a run: in an anneal the steps grow and the\n"
             "segments bend, the cheap bounds decide fewer segments and 17 %% of the proposals are refused\n"
             "as irregular. A profiler's measurement (2026-12-07, params/flow.ini without the pair term,\n"
             "100 sweeps): the checks took 15.5 %% more of the sweeps' instructions (58 %% of the checks\n"
             "reaching the exact test, then lw_segment_rho, and its complex square roots and divisions)\n"
             "and about 1.32 times the time, natively (5 runs interleaved, all on slower than all off).\n"
             "The exact test now compares the roots' distances to the ellipse's foci with its major\n"
             "axis, in real arithmetic (one complex square root written out, no complex division;\n"
             "spline.c, roots_outside): 2.7 times as fast on random segments with the same decisions in 2\n"
             "million (but within rounding of the threshold), and on that run, 3000 sweeps, 2.87 s\n"
             "against 3.30 s of CPU (medians of 5 interleaved runs, 1.15 times as fast; 2026-12-07),\n"
             "state.lw the same to the bit.\n"
             "\n",
          nt, p.min_speed, p.regularity, rounds, off_ns, on_ns, med, mad, segs, doubt, doubt == 1 ? "is" : "are");
  free(ratio);
  free(ns_off);
  free(ns_on);
  for (int k = 0; k < 2; k++) bench_run_free(&r[k]);
}
