/*
** pair-accuracy.c -- error and cost of the pair term's near-field scheme.
**
** Build and run:
**   make build/pair-accuracy && build/pair-accuracy [segments per line, default 6]
**
** Prints the relative error of the pair energy of two straight splines of
** unit segments (parallel at distance d; crossing at an angle, at a generic
** place and at special places), summed over all sample pairs with
** lw_pair_kernel, against the exact value (closed form, lw_pair_segseg of the
** whole lines), for near-field radii near = 0 (off), 1, 1.5, 2, 3, 4 and
** 4, 8, 16 nodes; then the cost of whole energies and of one kernel call in
** each zone.  Distances are in units of h = 1/n, the mean element length
** (the near radius itself is in units of the larger element, which is up
** to 1.5 h for n = 8).
**
** What it showed (and why near = 1.5 is the recommended default): the product
** rule alone is off by 6.5 at d = 0.01 h and by 2e-3 at d = h; with exact
** element integrals only within near element lengths (the first design) the
** error stayed ~1e-3 up to near = 4, because the product rule's per-pair
** first-order error, which the Gauss rule cancels over whole segments, is no
** longer cancelled at the edge of the near zone.  With the cheap 2x2 element
** rule out to 6 near (pair.h) the error is below 6e-4 for near = 1.5 and any
** d, angle and n in 4..16, and falls like 1/near^2 (1e-4 at near = 3); the
** cost grows with near about linearly for parallel lines (exact integrals
** dominate), so 1.5 buys a 2x margin under 1e-3 for ~3.3x the product rule's
** cost where lines run close together (nothing extra where they do not).
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "benchutil.h"
#include "linewise/pair.h"
#include "linewise/quad.h"
#include "linewise/spline.h"
#include "pairref.h"
#include "testutil.h"

#define MAXS 4096

/* A straight spline from p to q, uniform parametrisation. */
static void straight(lw_splines *sp, size_t i, const double p[2], const double q[2])
{
  lw_test_straight(sp, i, p[0], p[1], q[0], q[1]);
}

static double pair_energy(const lw_splines *sp, int nq, double near)
{
  static lw_pair_sample A[MAXS], B[MAXS];
  lw_quad q;
  lw_pair_ctx ctx;
  lw_quad_init(&q, nq, NULL);
  lw_pair_ctx_init(&ctx, &q, 0.0, near);
  size_t na = lw_pairref_samples(sp, &q, 0, A), nb = lw_pairref_samples(sp, &q, 1, B);
  double e = 0.0;
  for (size_t i = 0; i < na; i++)
    for (size_t j = 0; j < nb; j++) e += lw_pair_kernel(&A[i], &B[j], &ctx);
  return e;
}

static const double NEARS[] = {0.0, 1.0, 1.5, 2.0, 3.0, 4.0};
static const int NQ[] = {4, 8, 16};
#define NNEAR (int)(sizeof NEARS / sizeof NEARS[0])
#define NNQ (int)(sizeof NQ / sizeof NQ[0])

static void header(const char *what)
{
  printf("%-22s", what);
  for (int k = 0; k < NNEAR; k++) printf(" near=%-4g", NEARS[k]);
  printf("\n");
}

/* Two parallel lines of m unit segments at distance d = ratio * h. */
static void parallel_row(int nq, int m, double ratio)
{
  size_t segs[2] = {(size_t)m, (size_t)m};
  lw_splines *sp = lw_splines_new(2, segs, NULL);
  double h = 1.0 / nq, d = ratio * h, L = m;
  double p0[2] = {0, 0}, p1[2] = {L, 0}, q0[2] = {0, d}, q1[2] = {L, d};
  straight(sp, 0, p0, p1);
  straight(sp, 1, q0, q1);
  double exact = 2.0 * (L * asinh(L / d) - sqrt(L * L + d * d) + d);
  printf("n=%-2d par d/h=%-6g   ", nq, ratio);
  for (int k = 0; k < NNEAR; k++) printf(" %9.1e", fabs(pair_energy(sp, nq, NEARS[k]) / exact - 1));
  printf("\n");
  lw_splines_free(sp);
}

/* Two lines of m unit segments crossing at angle deg; the crossing sits at
** parameter fa of A's middle segment and fb of B's. */
static void crossing_row(int nq, int m, double deg, double fa, double fb, const char *label)
{
  size_t segs[2] = {(size_t)m, (size_t)m};
  lw_splines *sp = lw_splines_new(2, segs, NULL);
  double th = deg * 3.14159265358979323846 / 180.0, L = m;
  double sa = 0.5 * m - 0.5 + fa, sb = 0.5 * m - 0.5 + fb; /* crossing's arc length along A, B */
  double p0[2] = {-sa, 0}, p1[2] = {L - sa, 0};
  double q0[2] = {-sb * cos(th), -sb * sin(th)}, q1[2] = {(L - sb) * cos(th), (L - sb) * sin(th)};
  straight(sp, 0, p0, p1);
  straight(sp, 1, q0, q1);
  double exact = lw_pair_segseg(p0, p1, q0, q1);
  printf("n=%-2d %-17s", nq, label);
  for (int k = 0; k < NNEAR; k++) printf(" %9.1e", fabs(pair_energy(sp, nq, NEARS[k]) / exact - 1));
  printf("\n");
  lw_splines_free(sp);
}

/* ns per kernel call over many sample pairs at node distance dist * dl (random
** directions), so that all of them take one branch of the kernel. */
static double time_kernel(double near, double dist)
{
  enum { N = 1024 };
  static lw_pair_sample a[N], b[N];
  lw_quad q;
  lw_pair_ctx ctx;
  lw_quad_init(&q, 8, NULL);
  lw_pair_ctx_init(&ctx, &q, 0.0, near);
  srand(1);
  const double dl = 0.1, tau = 6.283185307179586;
  for (int i = 0; i < N; i++) {
    double t1 = tau * rand() / RAND_MAX, t2 = tau * rand() / RAND_MAX, t3 = tau * rand() / RAND_MAX;
    int qa = rand() % 8, qb = rand() % 8;
    /* r' = tangent * dl / w_q so that w_q |r'| = dl */
    a[i] = (lw_pair_sample){0, 0, cos(t1) * dl / q.w[qa], sin(t1) * dl / q.w[qa], dl, 0, (uint32_t)qa};
    b[i] = (lw_pair_sample){dist * dl * cos(t2), dist * dl * sin(t2), cos(t3) * dl / q.w[qb],
                            sin(t3) * dl / q.w[qb], dl, 1, (uint32_t)qb};
  }
  int reps = dist < near ? 300 : 30000;
  double t0 = bench_now(), s = 0;
  for (int r = 0; r < reps; r++)
    for (int i = 0; i < N; i++) s += lw_pair_kernel(&a[i], &b[i], &ctx);
  double t1 = bench_now();
  if (!(s > 0)) printf("(unexpected sum %g)\n", s);
  return (t1 - t0) / ((double)reps * N) * 1e9;
}

/* ns per lw_pair_segseg call for unit segments at random angles and offsets
** within a unit square (crossing, touching-close and apart mixed). */
static double time_segseg(void)
{
  enum { N = 4096 };
  static double P[N][8];
  srand(3);
  for (int i = 0; i < N; i++) {
    double t1 = 6.283185307179586 * rand() / RAND_MAX, t2 = 6.283185307179586 * rand() / RAND_MAX;
    double cx = 2.0 * rand() / RAND_MAX - 1, cy = 2.0 * rand() / RAND_MAX - 1;
    double p[8] = {0, 0, cos(t1), sin(t1), cx, cy, cx + cos(t2), cy + sin(t2)};
    for (int k = 0; k < 8; k++) P[i][k] = p[k];
  }
  int reps = 100;
  double t0 = bench_now(), s = 0;
  for (int r = 0; r < reps; r++)
    for (int i = 0; i < N; i++) s += lw_pair_segseg(P[i], P[i] + 2, P[i] + 4, P[i] + 6);
  double t1 = bench_now();
  if (!(s > 0)) printf("(unexpected sum %g)\n", s);
  return (t1 - t0) / ((double)reps * N) * 1e9;
}

/* Wall time of one pair energy of the two lines, ns per sample of a line. */
static void cost_row(const char *label, int nq, int m, double deg, double ratio)
{
  size_t segs[2] = {(size_t)m, (size_t)m};
  lw_splines *sp = lw_splines_new(2, segs, NULL);
  double L = m, h = 1.0 / nq, th = deg * 3.14159265358979323846 / 180.0;
  double p0[2] = {0, 0}, p1[2] = {L, 0};
  double q0[2] = {deg == 0 ? 0 : 0.5 * L - 0.5 * L * cos(th), deg == 0 ? ratio * h : -0.5 * L * sin(th)};
  double q1[2] = {deg == 0 ? L : 0.5 * L + 0.5 * L * cos(th), deg == 0 ? ratio * h : 0.5 * L * sin(th)};
  straight(sp, 0, p0, p1);
  straight(sp, 1, q0, q1);
  printf("n=%-2d %-17s", nq, label);
  for (int k = 0; k < NNEAR; k++) {
    int reps = 0;
    double t0 = bench_now(), t1;
    do {
      volatile double e = pair_energy(sp, nq, NEARS[k]);
      (void)e;
      reps++;
      t1 = bench_now();
    } while (t1 - t0 < 0.05);
    printf(" %9.0f", (t1 - t0) / reps / (m * nq) * 1e9);
  }
  printf("\n");
  lw_splines_free(sp);
}

int main(int argc, char **argv)
{
  int m = argc > 1 ? atoi(argv[1]) : 6; /* segments per line */
  if (m < 1 || m > 200) m = 6;
  printf("relative error of the pair energy, %d unit segments per line, h = 1/n\n\n", m);
  static const double RATIOS[] = {0.01, 0.1, 0.5, 1, 3, 10};
  header("parallel");
  for (int iq = 0; iq < NNQ; iq++)
    for (size_t k = 0; k < sizeof RATIOS / sizeof RATIOS[0]; k++) parallel_row(NQ[iq], m, RATIOS[k]);
  printf("\n");
  header("crossing");
  static const double DEG[] = {90, 30, 5};
  for (int iq = 0; iq < NNQ; iq++)
    for (size_t k = 0; k < sizeof DEG / sizeof DEG[0]; k++) {
      char lab[32];
      snprintf(lab, sizeof lab, "cross %g deg", DEG[k]);
      crossing_row(NQ[iq], m, DEG[k], 0.37, 0.61, lab);
    }
  printf("\n");
  header("crossing place, n=8");
  crossing_row(8, m, 60, 0.5, 0.5, "60 mid-segment");
  crossing_row(8, m, 60, 0.0, 0.0, "60 at nodes");
  crossing_row(8, m, 60, 0.01, 0.97, "60 near ends");
  crossing_row(8, m, 10, 0.01, 0.97, "10 near ends");
  printf("\ncost: ns per sample of one line (all pairs with the other line)\n");
  header("cost");
  cost_row("par d/h=0.5", 8, m, 0, 0.5);
  cost_row("cross 30 deg", 8, m, 30, 0);
  /* near = 2: exact below 2 dl, element rule to 12 dl (blended from 9 dl) */
  printf("\nns per kernel call (n = 8, near = 2): far %.1f, element rule %.1f, blend %.1f, exact %.1f\n",
         time_kernel(2.0, 14.0), time_kernel(2.0, 4.0), time_kernel(2.0, 10.5), time_kernel(2.0, 1.0));
  printf("ns per lw_pair_segseg call (unit segments, random placement): %.1f\n", time_segseg());
  return 0;
}
