/*
** bench-nurbs.c -- the D-NURBS wire's cost per time step against the number
** of control points (the review's Figure 10 measured 20 to 140), here up to
** 10^4: with banded matrices a leapfrog step is O(n), which the cost per
** control point shows.  The review's implicit scheme solves by conjugate
** gradients preconditioned by the row's factor of its matrix (mass_shift):
** O(n) too.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "benchutil.h"
#include "linewise/dynamics.h"
#include "linewise/sys_nurbs.h"

/* A wire of n control points at their Greville places on y = 5 from x = -5
** to 5: order 4, uniform knots (as `nurbs.knots` empty gives), ends held,
** the review's coefficients.  Built in memory: 10^4 points do not fit a
** scene file's line. */
static lw_nurbs_setup *wire(lw_params *p, size_t n, int integrator, lw_error *err)
{
  lw_params_defaults(p);
  strcpy(p->system, "nurbs");
  p->nb_alpha = 35;
  p->nb_beta = 10;
  p->nb_fixed = 1;
  p->dyn_rho = 30;
  p->dyn_gravity_y = -9.8;
  p->dyn_dt = 0.008;
  p->dyn_integrator = integrator;
  double *knot = malloc((n + 4) * sizeof *knot), *P = malloc(2 * n * sizeof *P);
  if (!knot || !P) bench_die("out of memory", NULL);
  for (size_t i = 0; i < n + 4; i++) knot[i] = i < 4 ? 0.0 : i >= n ? 1.0 : (double)(i - 3) / (double)(n - 3);
  for (size_t i = 0; i < n; i++) {
    P[2 * i] = -5 + 10 * (knot[i + 1] + knot[i + 2] + knot[i + 3]) / 3;
    P[2 * i + 1] = 5;
  }
  lw_nurbs_setup *su = lw_nurbs_setup_new(p, lw_nurbs_new(4, n, knot, P, NULL, err), err);
  free(knot);
  free(P);
  return su;
}

/* The highest frequency of the free wire, sqrt of the largest eigenvalue of
** M^-1 K, by power iteration on the bands (the leapfrog is stable for
** omega dt < 2). */
static double omega_max(const lw_nurbs_setup *su, double mu)
{
  size_t n = su->mat->n;
  int k = su->mat->k;
  double *L = malloc(n * (size_t)k * sizeof *L), *M = malloc(n * (size_t)k * sizeof *M), *v = malloc(2 * n * sizeof *v),
         *w = malloc(2 * n * sizeof *w), lam = 0.0;
  lw_error err;
  if (!L || !M || !v || !w) bench_die("out of memory", NULL);
  for (size_t i = 0; i < n * (size_t)k; i++) M[i] = mu * su->mat->M1[i];
  if (lw_band_factor(M, su->pin, n, k, L, &err)) bench_die("mass", &err);
  for (size_t i = 0; i < 2 * n; i++) v[i] = (i / 2) % 2 ? 1.0 : -1.0; /* the shortest wave */
  for (int it = 0; it < 300; it++) {
    for (size_t i = 0; i < n; i++)
      if (su->pin[i]) v[2 * i] = v[2 * i + 1] = 0.0;
    lw_band_apply(su->mat->K, n, k, v, w);
    lw_band_solve(L, su->pin, n, k, w, w);
    double a = 0.0, b = 0.0;
    for (size_t i = 0; i < 2 * n; i++) a = fmax(a, fabs(w[i])), b = fmax(b, fabs(v[i]));
    lam = a / b;
    for (size_t i = 0; i < 2 * n; i++) v[i] = w[i] / a;
  }
  free(L), free(M), free(v), free(w);
  return sqrt(lam);
}

#define N_SIZES 10
enum { LEAPFROG, REVIEW, N_WAYS };

/* Median microseconds a step of one way of stepping the wire of n points;
** its set-up's milliseconds, omega_max and dt (the leapfrog's: it sets them
** first) and the most CG iterations a step took (the review's). */
static double time_steps(bench_ctx *b, size_t n, int way, double *assembly, double *om, double *dt0, int *iters)
{
  const lw_system_type *row = &lw_system_nurbs;
  lw_params *p = malloc(sizeof *p);
  lw_error err = {0};
  double t0 = bench_now();
  lw_nurbs_setup *su = p ? wire(p, n, way == LEAPFROG ? LW_INTEGRATOR_LEAPFROG : LW_INTEGRATOR_REVIEW, &err) : NULL;
  if (!su) bench_die("nurbs set-up", &err);
  if (way == LEAPFROG) {
    *assembly = 1e3 * (bench_now() - t0);
    /* the leapfrog at omega_max dt = 1 (a stable step; the cost of a step
    ** does not depend on it), the review's scheme at its 0.008 s */
    *om = omega_max(su, p->dyn_rho);
    p->dyn_dt = *dt0 = fmin(0.008, 1.0 / *om);
  }
  void *st = row->state_new(su, p, 0, &err);
  lw_dynamics *dy = st ? lw_dynamics_new(row, st, p, &err) : NULL;
  if (!dy) bench_die("nurbs dynamics", &err);
  double per[BENCH_MAX_REPS];
  for (int rep = 0; rep < b->reps; rep++) {
    double t1 = bench_now(), t;
    unsigned long steps = 0;
    do {
      if (lw_dynamics_step(dy, &err)) bench_die("nurbs step", &err);
      steps++;
      t = bench_now() - t1;
    } while (t < b->block);
    per[rep] = 1e6 * t / (double)steps;
  }
  *iters = dy->iterations_max;
  lw_dynamics_free(dy);
  row->state_free(st);
  row->setup_free(su);
  free(p);
  return bench_median(per, b->reps);
}

void bench_nurbs(bench_ctx *b)
{
  static const size_t sizes[N_SIZES] = {20, 40, 60, 80, 100, 120, 140, 400, 1000, 10000};
  FILE *d = b->doc[BENCH_PERFORMANCE];
  FILE *dat = bench_data(b, "nurbs-cost.dat");
  fprintf(d, "## D-NURBS: cost per time step\n\n"
             "The elastic wire of `params/wire.ini` (order 4, alpha 35, beta 10, mu 30, g 9.8, dt 0.008,\n"
             "10 Gauss points a span, ends held) with n control points on uniform knots, started\n"
             "straight. The leapfrog is explicit: it runs at omega_max dt = 1 (its stable limit is 2; the\n"
             "highest frequency grows as n^2 through the beta term), the review's implicit scheme at\n"
             "the review's dt = 0.008 s. Each figure is the median of %d blocks of at least %g s (wall time) of time steps through\n"
             "the system's row (`lw_dynamics_step`). Assembly is the set-up's banded K, M and b. The\n"
             "review's scheme solves ((1 + h c/2) M + h^2 K) delta = r by conjugate gradients (the most\n"
             "iterations a step took is shown), preconditioned by the banded Cholesky factor of that\n"
             "matrix (`mass_shift`, factored once): O(n) a step, like the leapfrog. (Preconditioned by M\n"
             "alone, as before that factor, its iterations grew with the condition number, about\n"
             "h^2 omega_max^2: 28 a step at n = 20, 954 at 140, where a step took 7.6 ms.)\n"
             "\n"
             "| control points | assembly ms | omega_max 1/s | leapfrog dt s | leapfrog us/step | ns/step per point | review us/step | CG iterations (most a step) |\n"
             "|---|---|---|---|---|---|---|---|\n",
          b->reps, b->block);
  if (dat) fprintf(dat, "# n  leapfrog_us  review_us\n");
  for (int k = 0; k < N_SIZES; k++) {
    size_t n = sizes[k];
    if (b->quick && n > 1000) continue;
    double us[N_WAYS], assembly = 0.0, om = 0.0, dt0 = 0.0;
    int iters[N_WAYS];
    for (int way = 0; way < N_WAYS; way++) us[way] = time_steps(b, n, way, &assembly, &om, &dt0, &iters[way]);
    fprintf(d, "| %zu | %.2f | %.3g | %.3g | %.1f | %.0f | %.1f | %d |\n", n, assembly, om, dt0, us[LEAPFROG],
            1e3 * us[LEAPFROG] / (double)n, us[REVIEW], iters[REVIEW]);
    if (dat) fprintf(dat, "%zu %.6g %.6g\n", n, us[LEAPFROG], us[REVIEW]);
  }
  if (dat) fclose(dat);
  fprintf(d, "\n");
}
