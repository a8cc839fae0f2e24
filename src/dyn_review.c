/* dyn_review.c -- the D-NURBS review's implicit scheme (dyn_review.h). */
#include "linewise/dyn_review.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Conjugate gradients stop at this relative residual.  With the row's
** factor as preconditioner one to seven iterations do (60,000 control
** points: 7); where they do not reach it in CG_ITER_MAX, the factor has
** lost what it stands for to rounding (a curve refined to 10^5 control
** points ran 10n + 100 iterations of the old cap, for minutes a step). */
#define CG_TOL 1e-11
#define CG_ITER_MAX 200

enum { W_DELTA, W_R, W_Z, W_S, W_AS, W_G, W_COUNT };

lw_status lw_dyn_review_init(lw_dynamics *d, const lw_params *p, lw_error *err)
{
  if (d->rho == 0.0) {
    char where[LW_PATH_MAX + 32];
    lw_params_origin(p, lw_params_find("dynamics", "integrator"), where, sizeof where);
    return lw_error_set(err, LW_EINPUT, "%s: key 'dynamics.integrator': the review's scheme needs inertia (rho > 0)",
                        where);
  }
  /* the scheme is derived for a constant M and a quadratic E: the row's
  ** factor of (1 + h c / 2) M + h^2 K says it has them */
  double h = d->dt, c = d->gamma / d->rho;
  int factored = 0;
  lw_status st = d->type->mass_shift ? d->type->mass_shift(d->mass, 1.0 + 0.5 * h * c, h * h, &factored, err) : LW_OK;
  if (st == LW_EINPUT) {
    /* K's entries grow like the cube of the control points, M's shrink:
    ** near 2e5 control points the sum is no longer positive definite in
    ** double precision, and the message named no key */
    char where[LW_PATH_MAX + 32], was[LW_ERROR_MSG];
    snprintf(was, sizeof was, "%s", err->msg);
    lw_params_origin(p, lw_params_find("dynamics", "integrator"), where, sizeof where);
    return lw_error_set(err, LW_EINPUT, "%s: key 'dynamics.integrator': the review's scheme cannot factor "
                        "(1 + h c/2) M + h^2 K: %s (the curve is refined past what double precision holds: its "
                        "stiffness grows like the cube of the control points); refine less (nurbs.refine), or use "
                        "integrator = leapfrog", where, was);
  }
  if (st) return st;
  if (!factored) {
    char where[LW_PATH_MAX + 32];
    lw_params_origin(p, lw_params_find("dynamics", "integrator"), where, sizeof where);
    return lw_error_set(err, LW_EINPUT, "%s: key 'dynamics.integrator': the review's scheme takes a constant mass "
                        "matrix and a quadratic energy (the nurbs system with frozen weights); the %s system's are "
                        "not: use integrator = leapfrog", where, d->type->name);
  }
  if (!(d->work = calloc(W_COUNT * d->n + 1, sizeof *d->work)))
    return lw_error_set(err, LW_ENOMEM, "out of memory for the dynamics of %zu coordinates", d->n);
  return LW_OK;
}

static double dot(const double *a, const double *b, size_t n)
{
  double s = 0.0;
  for (size_t i = 0; i < n; i++) s += a[i] * b[i];
  return s;
}

static void hold(const lw_dynamics *d, double *v)
{
  for (size_t i = 0; i < d->n; i++)
    if (d->type->mass_pinned(d->mass, i)) v[i] = 0.0;
}

/* out = (1 + h c / 2) M v + h^2 K v at x (grad E(x) in d->g), K v from the
** gradient at x + s v: s scales v to the size of x, where rounding is least. */
static lw_status apply_a(lw_dynamics *d, const double *v, double *out, lw_error *err)
{
  const lw_system_type *t = d->type;
  size_t n = d->n;
  double h = d->dt, c = d->gamma / d->rho, vmax = 0.0, xmax = 0.0;
  double *xs = d->tx, *gs = d->work + W_G * n;
  for (size_t i = 0; i < n; i++) vmax = fmax(vmax, fabs(v[i])), xmax = fmax(xmax, fabs(d->x[i]));
  t->mass_apply(d->mass, v, out);
  for (size_t i = 0; i < n; i++) out[i] *= 1.0 + 0.5 * h * c;
  if (vmax == 0.0) return LW_OK;
  double s = (1.0 + xmax) / vmax;
  for (size_t i = 0; i < n; i++) xs[i] = d->x[i] + s * v[i];
  lw_status st = t->set_coords(d->state, xs, err);
  if (st) return st;
  lw_error_clear(err); /* a row's gradient sets it only where it fails */
  t->gradient(d->state, gs, err);
  if (err->code) return err->code;
  for (size_t i = 0; i < n; i++) out[i] += h * h * (gs[i] - d->g[i]) / s;
  hold(d, out);
  return LW_OK;
}

lw_status lw_dyn_review_step(lw_dynamics *d, lw_error *err)
{
  const lw_system_type *t = d->type;
  size_t n = d->n;
  double h = d->dt, c = d->gamma / d->rho;
  double *delta = d->work + W_DELTA * n, *r = d->work + W_R * n, *z = d->work + W_Z * n, *s = d->work + W_S * n,
         *as = d->work + W_AS * n;
  lw_status st;
  /* r = h (1 - h c / 2) pi - h^2 grad E(p); delta from 0 */
  for (size_t i = 0; i < n; i++) {
    r[i] = h * (1.0 - 0.5 * h * c) * d->pi[i] - h * h * d->g[i];
    delta[i] = 0.0;
  }
  hold(d, r);
  t->mass_shift_solve(d->mass, r, z);
  memcpy(s, z, n * sizeof *s);
  double rz = dot(r, z, n), r0 = sqrt(dot(r, r, n));
  int it = 0;
  while (sqrt(dot(r, r, n)) > CG_TOL * r0) {
    if (++it > CG_ITER_MAX)
      return lw_error_set(err, LW_ERUN, "the review scheme's solve did not converge in %d iterations at t = %g s "
                          "(step %lu): at %zu coordinates its matrix is too ill-conditioned for the doubles; expected "
                          "fewer control points (nurbs.refine) or integrator = leapfrog", CG_ITER_MAX, d->time,
                          d->steps, n);
    if ((st = apply_a(d, s, as, err))) return st;
    double alpha = rz / dot(s, as, n);
    for (size_t i = 0; i < n; i++) delta[i] += alpha * s[i], r[i] -= alpha * as[i];
    t->mass_shift_solve(d->mass, r, z);
    double rz1 = dot(r, z, n);
    for (size_t i = 0; i < n; i++) s[i] = z[i] + rz1 / rz * s[i];
    rz = rz1;
  }
  if (it > d->iterations_max) d->iterations_max = it;
  /* p+ = p + delta, pi+ = M delta / h */
  for (size_t i = 0; i < n; i++) d->x[i] += delta[i];
  if ((st = t->set_coords(d->state, d->x, err))) return st;
  lw_error_clear(err);
  d->energy = t->gradient(d->state, d->g, err);
  if (err->code) return err->code;
  if (!isfinite(d->energy)) {
    char what[160];
    lw_dynamics_forbidden_what(t, d->state, what, sizeof what);
    return lw_error_set(err, LW_ERUN, "the motion reached a forbidden state at t = %g s%s: %s", d->time + h, what,
                        LW_DYNAMICS_FORBIDDEN_HINT);
  }
  t->mass_apply(d->mass, delta, d->pi);
  for (size_t i = 0; i < n; i++) d->pi[i] /= h;
  hold(d, d->pi);
  d->time += h;
  return LW_OK;
}
