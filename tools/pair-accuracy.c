/*
** pair-accuracy.c -- error and cost of the pair term's near-field scheme.
**
** Build (after `make build/liblinewise.a`):
**   cc -O2 -Iinclude tools/pair-accuracy.c build/liblinewise.a $(pkg-config --libs gsl) -lm
**
** Prints the relative error of the pair energy of two straight splines
** (parallel at distance d, and crossing at an angle) summed over all sample
** pairs with lw_pair_kernel, against the exact value, for several near-field
** radii and quadrature orders; then the cost of one kernel call in the far
** and near branches.  Lengths are in units of the mean element length
** h = (segment length) / n, which is what the near radius is measured in.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "linewise/pair.h"
#include "linewise/quad.h"
#include "linewise/spline.h"

#define MAXS 4096

/* A straight spline from p to q with m segments, uniform parametrisation. */
static void straight(lw_splines *sp, size_t i, const double p[2], const double q[2])
{
  size_t m = lw_splines_segments(sp, i);
  for (size_t k = 0; k <= m; k++) {
    lw_node *nd = &sp->node[sp->first[i] + k];
    double t = (double)k / (double)m;
    nd->px = p[0] + t * (q[0] - p[0]);
    nd->py = p[1] + t * (q[1] - p[1]);
    nd->vx = (q[0] - p[0]) / (3.0 * (double)m);
    nd->vy = (q[1] - p[1]) / (3.0 * (double)m);
  }
}

/* All samples of spline i. */
static size_t samples(const lw_splines *sp, const lw_quad *q, size_t i, lw_pair_sample *out)
{
  size_t n = 0;
  for (size_t m = 0; m < lw_splines_segments(sp, i); m++) {
    size_t g = lw_segment_index(sp, i, m), k = lw_segment_node(sp, g);
    lw_samples s;
    lw_segment_sample(q, &sp->node[k], &sp->node[k + 1], &s);
    for (int j = 0; j < s.n; j++) {
      out[n] = (lw_pair_sample){s.x[j], s.y[j], s.dx[j], s.dy[j], s.dl[j], (uint32_t)i, (uint32_t)j};
      n++;
    }
  }
  return n;
}

static double pair_energy(const lw_splines *sp, int nq, double near)
{
  static lw_pair_sample A[MAXS], B[MAXS];
  lw_quad q;
  lw_pair_ctx ctx;
  lw_quad_init(&q, nq, NULL);
  lw_pair_ctx_init(&ctx, &q, 0.0, near);
  size_t na = samples(sp, &q, 0, A), nb = samples(sp, &q, 1, B);
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

static double now(void)
{
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* ns per kernel call over many sample pairs that all take one branch. */
static double time_kernel(double near, double dist)
{
  enum { N = 1024 };
  static lw_pair_sample a[N], b[N];
  lw_quad q;
  lw_pair_ctx ctx;
  lw_quad_init(&q, 8, NULL);
  lw_pair_ctx_init(&ctx, &q, 0.0, near);
  srand(1);
  for (int i = 0; i < N; i++) {
    double ang = 6.283185307179586 * rand() / RAND_MAX, ang2 = 6.283185307179586 * rand() / RAND_MAX;
    double dl = 0.1;
    int qi = rand() % 8;
    a[i] = (lw_pair_sample){0, 0, cos(ang) * dl / q.w[qi], sin(ang) * dl / q.w[qi], dl, 0, (uint32_t)qi};
    qi = rand() % 8;
    b[i] = (lw_pair_sample){dist * dl * cos(ang2), dist * dl * sin(ang2), cos(ang2 + 1) * dl / q.w[qi],
                            sin(ang2 + 1) * dl / q.w[qi], dl, 1, (uint32_t)qi};
  }
  volatile double sink = 0;
  int reps = near > 0 && dist < near ? 200 : 20000;
  double t0 = now(), s = 0;
  for (int r = 0; r < reps; r++)
    for (int i = 0; i < N; i++) s += lw_pair_kernel(&a[i], &b[(i + r) % N], &ctx);
  double t1 = now();
  sink = s;
  (void)sink;
  return (t1 - t0) / ((double)reps * N) * 1e9;
}

int main(int argc, char **argv)
{
  int m = argc > 1 ? atoi(argv[1]) : 6; /* segments per line */
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
  printf("\nns per kernel call (n = 8): far %.1f, near %.1f\n", time_kernel(2.0, 3.0),
         time_kernel(2.0, 1.0));
  return 0;
}
