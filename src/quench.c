/*
** quench.c -- BFGS from the annealed state to the nearest local minimum
** (quench.h).
**
** Forbidden states.  The energy is +inf outside the allowed set (the
** boundary, regularity).  BFGS2's line search (Fletcher's, in GSL's
** linear_minimize.c) brackets along the search direction and then sections
** the bracket by interpolation, clamped into its inner part; a trial value
** above f(0) + rho alpha f'(0) ends the bracketing at once without asking
** for the slope there.  So a forbidden point evaluated as a large finite
** WALL is simply a much worse point: the bracket closes on it and the next
** trial lies strictly inside, at most ~0.9 of the way to it (GSL's tau
** bounds), so the step shortens geometrically until it is allowed again.
** A step is accepted only with a value below f(0), never at WALL, so every
** iterate is allowed.  GSL 2.x's sectioning happens to survive +inf too
** (its quadratic step falls back to the bracket's inner clamp; the tests
** give the same iterates), but a finite wall keeps every difference the
** line search may form finite, whichever interpolation it takes; halving by
** hand would duplicate the line search.  WALL is 1e150: far above any
** energy a scene reaches, yet its square (the cubic interpolation's
** discriminant) stays finite.  The slope at a forbidden point, should GSL
** ask for it, is given as 0.
**
** Every evaluation moves the system's state there (set_coords refreshes its
** caches and totals) and remembers the allowed point of lowest energy; at
** the end the state is set to that point (finite, hence allowed), or back
** to the start if nothing was lower.
*/
#include "linewise/quench.h"

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_multimin.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define WALL 1e150

typedef struct {
  lw_system *sys;
  size_t n;
  double *x, *g;   /* scratch: coordinates and gradient, n each */
  double *best;    /* the allowed point of lowest energy evaluated so far (n) */
  double best_f;
  lw_status st;    /* the first error, LW_OK if none */
  lw_error *err;
  long evaluations, forbidden;
} quench_ctx;

static double seconds_now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The energy at v (the gradient into grad if not NULL): WALL and a zero
** gradient where the state is forbidden or an error occurred (kept in
** ctx->st, so the minimiser stops making progress and the caller reports
** it). */
static double eval_at(const gsl_vector *v, quench_ctx *c, gsl_vector *grad)
{
  const lw_system_type *t = c->sys->type;
  for (size_t i = 0; i < c->n; i++) c->x[i] = gsl_vector_get(v, i);
  c->evaluations++;
  double e = WALL;
  lw_error e2 = {0};
  if (c->st == LW_OK) {
    if (t->set_coords(c->sys->state, c->x, &e2) != LW_OK) {
      /* non-finite coordinates (a runaway step) are forbidden, not an error */
      if (e2.code != LW_EINPUT) c->st = lw_error_set(c->err, e2.code, "quench: %s", e2.msg);
    } else if (grad) {
      e = t->gradient(c->sys->state, c->g, &e2);
      if (isnan(e)) c->st = lw_error_set(c->err, e2.code ? e2.code : LW_EINPUT, "quench: %s", e2.msg);
    } else {
      e = t->total(c->sys->state);
    }
  }
  int ok = c->st == LW_OK && isfinite(e) && e < WALL;
  c->forbidden += c->st == LW_OK && !ok;
  if (grad)
    for (size_t i = 0; i < c->n; i++) gsl_vector_set(grad, i, ok ? c->g[i] : 0.0);
  if (ok && e < c->best_f) {
    c->best_f = e;
    memcpy(c->best, c->x, c->n * sizeof *c->x);
  }
  return ok ? e : WALL;
}

static double f_cb(const gsl_vector *v, void *p) { return eval_at(v, p, NULL); }
static void df_cb(const gsl_vector *v, void *p, gsl_vector *g) { eval_at(v, p, g); }
static void fdf_cb(const gsl_vector *v, void *p, double *f, gsl_vector *g) { *f = eval_at(v, p, g); }

static double norm2(const double *g, size_t n)
{
  double s = 0.0;
  for (size_t i = 0; i < n; i++) s += g[i] * g[i];
  return sqrt(s);
}

/* The first trial step, in the coordinates' unit: a thousandth of their
** root mean square (for splines ~0.1 mm on a page); the line search
** scales it from there. */
static double first_step(const double *x, size_t n)
{
  double s = 0.0;
  for (size_t i = 0; i < n; i++) s += x[i] * x[i];
  s = sqrt(s / (double)(n ? n : 1));
  return s > 0.0 ? 1e-3 * s : 1e-3;
}

lw_status lw_quench_run(lw_system *sys, double tol, long max_iter, lw_quench_report *r, lw_error *err)
{
  const lw_system_type *t = sys->type;
  const double t0 = seconds_now();
  memset(r, 0, sizeof *r);
  r->energy_before = r->energy_after = t->total(sys->state);
  if (!t->gradient || !t->n_coords || !t->get_coords || !t->set_coords)
    return lw_error_set(err, LW_EINPUT, "quench: the %s system has no gradient", t->name);
  const size_t n = t->n_coords(sys->state), nb = (n ? n : 1) * sizeof(double);
  quench_ctx c = {.sys = sys, .n = n, .x = malloc(nb), .g = malloc(nb), .best = malloc(nb), .best_f = INFINITY,
                  .st = LW_OK, .err = err};
  double *start = malloc(nb);
  gsl_vector *x0 = n ? gsl_vector_alloc(n) : NULL;
  gsl_multimin_fdfminimizer *m = n ? gsl_multimin_fdfminimizer_alloc(gsl_multimin_fdfminimizer_vector_bfgs2, n) : NULL;
  lw_status st = LW_OK;
  if (!c.x || !c.g || !c.best || !start || (n && (!x0 || !m))) {
    st = lw_error_set(err, LW_ENOMEM, "out of memory for the quench of %zu coordinates", n);
    goto out;
  }
  if (n == 0 || !isfinite(r->energy_before)) goto out; /* nothing to move, or a forbidden start */
  t->get_coords(sys->state, start);
  for (size_t i = 0; i < n; i++) gsl_vector_set(x0, i, start[i]);
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  gsl_multimin_function_fdf F = {.f = f_cb, .df = df_cb, .fdf = fdf_cb, .n = n, .params = &c};
  const double step = first_step(start, n);
  int gs = gsl_multimin_fdfminimizer_set(m, &F, x0, step, 0.1);
  r->gradient_before = gsl_blas_dnrm2(gsl_multimin_fdfminimizer_gradient(m));
  double gnorm = r->gradient_before;
  /*
  ** A line search fails when the minimum along its direction lies on the
  ** wall of the allowed set (a segment at the regularity limit, a sample
  ** at the boundary): the slope there is still negative, so no step meets
  ** the curvature condition.  It has still evaluated lower allowed points;
  ** the minimiser restarts from the lowest (its Hessian estimate starts
  ** afresh) and counts the restart as an iteration.  It stops when a failed
  ** search found nothing lower (the minimum to rounding) or when the search
  ** right after a restart fails too: steepest descent runs into the wall
  ** at once, so the state sits on the wall, where only a method that knows
  ** the wall's normal could slide along it (docs/ACCURACY.md).
  */
  int failed = 0;
  while (gs == GSL_SUCCESS && c.st == LW_OK && !(gnorm <= tol) && r->iterations < max_iter) {
    double f_before = gsl_multimin_fdfminimizer_minimum(m);
    gs = gsl_multimin_fdfminimizer_iterate(m);
    if (c.st != LW_OK) break;
    r->iterations++;
    /* an iteration that did not lower the energy failed too (its search
    ** shrank to nothing against the wall) */
    int fail = gs != GSL_SUCCESS || !(gsl_multimin_fdfminimizer_minimum(m) < f_before);
    failed = fail ? failed + 1 : 0;
    if (fail) {
      if (!(c.best_f < f_before) || failed > 1) break;
      for (size_t i = 0; i < n; i++) gsl_vector_set(x0, i, c.best[i]);
      gs = gsl_multimin_fdfminimizer_set(m, &F, x0, step, 0.1);
    }
    gnorm = gsl_blas_dnrm2(gsl_multimin_fdfminimizer_gradient(m));
  }
  gsl_set_error_handler(old);
  st = c.st;
  /* the lowest allowed point seen (finite, so regular and inside), or the start */
  lw_error e2 = {0};
  const double *end = c.best_f < r->energy_before ? c.best : start;
  if (t->set_coords(sys->state, end, &e2) != LW_OK && !st) st = lw_error_set(err, e2.code, "quench: %s", e2.msg);
  double g_end = t->gradient(sys->state, c.g, &e2);
  r->gradient_after = isfinite(g_end) ? norm2(c.g, n) : NAN;
  r->converged = r->gradient_after <= tol;
  r->energy_after = t->total(sys->state);
out:
  r->evaluations = c.evaluations;
  r->forbidden = c.forbidden;
  r->seconds = seconds_now() - t0;
  gsl_multimin_fdfminimizer_free(m);
  gsl_vector_free(x0);
  free(start);
  free(c.x);
  free(c.g);
  free(c.best);
  return st;
}
