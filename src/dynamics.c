/* dynamics.c -- the Lagrangian driver (dynamics.h). */
#include "linewise/dynamics.h"

#include "linewise/dyn_review.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A fixed point has converged when an iteration changes no coordinate by
** more than this relative to the largest: a few ulps above rounding. */
#define FIXED_TOL 1e-13
#define FIXED_MAX 200
/* Massless steps: the Armijo fraction and the most halvings of a step. */
#define ARMIJO 1e-4
#define HALVINGS_MAX 60

static double max_abs(const double *a, size_t n)
{
  double m = 0.0;
  for (size_t i = 0; i < n; i++)
    if (fabs(a[i]) > m) m = fabs(a[i]);
  return m;
}

/* max |a - b| <= FIXED_TOL max |a| (never for a value that is not finite) */
static int converged(const double *a, const double *b, size_t n)
{
  double d = 0.0;
  for (size_t i = 0; i < n; i++) {
    if (!isfinite(a[i])) return 0;
    if (fabs(a[i] - b[i]) > d) d = fabs(a[i] - b[i]);
  }
  return d <= FIXED_TOL * max_abs(a, n);
}

void lw_dynamics_free(lw_dynamics *d)
{
  if (!d) return;
  if (d->mass) d->type->mass_free(d->mass);
  free(d->x);
  free(d->pi);
  free(d->g);
  free(d->v);
  free(d->tx);
  free(d->x1);
  free(d->pi1);
  free(d->u);
  free(d->work);
  free(d->held);
  free(d);
}

/* Moves the system to x, and takes E and its gradient there.  Where two
** curves touch exactly the pair term's slope is infinite (pairgrad.h): a
** gradient that is not finite in an allowed state stops the motion with
** that reason rather than spreading NaN through the momenta. */
static lw_status evaluate(lw_dynamics *d, const double *x, lw_error *err)
{
  lw_status s = d->type->set_coords(d->state, x, err);
  if (s) return s;
  lw_error_clear(err); /* a row's gradient sets it only where it fails */
  d->energy = d->type->gradient(d->state, d->g, err);
  if (isnan(d->energy)) return err->code ? err->code : lw_error_set(err, LW_EINPUT, "the energy is not a number");
  if (isfinite(d->energy))
    for (size_t i = 0; i < d->n; i++)
      if (!isfinite(d->g[i]))
        return lw_error_set(err, LW_EINPUT, "the force on coordinate %zu is not finite at t = %g s (two lines "
                            "touch?): lower dynamics.dt or raise the pair term's near field", i, d->time);
  return LW_OK;
}

void lw_dynamics_forbidden_what(const lw_system_type *t, const void *state, char *buf, size_t n)
{
  char what[128] = "";
  t->describe(state, LW_DESCRIBE_FORBIDDEN, what, sizeof what);
  snprintf(buf, n, what[0] ? " (%s)" : "%s", what);
}

lw_status lw_dynamics_sync(lw_dynamics *d, lw_error *err)
{
  d->type->get_coords(d->state, d->x);
  lw_status s = evaluate(d, d->x, err);
  if (s) return s;
  if (!isfinite(d->energy)) {
    char what[160];
    lw_dynamics_forbidden_what(d->type, d->state, what, sizeof what);
    return lw_error_set(err, LW_EINPUT, "the dynamics starts in a forbidden state%s", what);
  }
  return d->type->mass_at(d->mass, d->x, err);
}

lw_dynamics *lw_dynamics_new(const lw_system_type *t, void *state, const lw_params *p, lw_error *err)
{
  char where[LW_PATH_MAX + 32];
  if (!t->mass_new || !t->gradient) {
    lw_params_origin(p, lw_params_find("scene", "driver"), where, sizeof where);
    lw_error_set(err, LW_EINPUT, "%s: key 'scene.driver': the system '%s' has no equations of motion (no mass "
                 "matrix or gradient); use driver = metropolis", where, t->name);
    return NULL;
  }
  if (p->dyn_rho == 0.0 && p->dyn_gamma == 0.0) {
    lw_params_origin(p, lw_params_find("dynamics", "gamma"), where, sizeof where);
    lw_error_set(err, LW_EINPUT, "%s: key 'dynamics.gamma': a massless motion (rho = 0) is the gradient flow of "
                 "the damping, so gamma must be > 0", where);
    return NULL;
  }
  const char *dashpot = p->dyn_dashpot != 0.0 ? "dashpot" : p->dyn_dashpot_angular != 0.0 ? "dashpot_angular" : NULL;
  if (dashpot && (!t->damp_pairs || p->dyn_rho == 0.0)) {
    lw_params_origin(p, lw_params_find("dynamics", dashpot), where, sizeof where);
    if (!t->damp_pairs)
      lw_error_set(err, LW_EINPUT, "%s: key 'dynamics.%s': the system '%s' has no dampers between neighbours; "
                   "expected 0 (its damping is dynamics.gamma)", where, dashpot, t->name);
    else
      lw_error_set(err, LW_EINPUT, "%s: key 'dynamics.%s': a massless motion (rho = 0) is damped by gamma alone; "
                   "expected 0", where, dashpot);
    return NULL;
  }
  lw_dynamics *d = calloc(1, sizeof *d);
  if (!d) {
    lw_error_set(err, LW_ENOMEM, "out of memory");
    return NULL;
  }
  d->type = t;
  d->state = state;
  d->n = t->n_coords(state);
  d->rho = p->dyn_rho;
  d->gamma = p->dyn_gamma;
  d->dt = p->dyn_dt;
  d->integrator = p->dyn_integrator;
  d->h_ref = NAN;
  d->pair_dampers = dashpot != NULL;
  if (d->integrator == LW_INTEGRATOR_REVIEW && t->constrain) {
    lw_params_origin(p, lw_params_find("dynamics", "integrator"), where, sizeof where);
    lw_error_set(err, LW_EINPUT, "%s: key 'dynamics.integrator': the review's scheme takes free coordinates; the "
                 "%s system's are constrained: use integrator = leapfrog", where, t->name);
    lw_dynamics_free(d);
    return NULL;
  }
  double **arrays[] = {&d->x, &d->pi, &d->g, &d->v, &d->tx, &d->x1, &d->pi1, &d->u};
  for (size_t k = 0; k < sizeof arrays / sizeof *arrays; k++)
    if (!(*arrays[k] = calloc(d->n + 1, sizeof(double)))) {
      lw_error_set(err, LW_ENOMEM, "out of memory for the dynamics of %zu coordinates", d->n);
      lw_dynamics_free(d);
      return NULL;
    }
  if (d->rho == 0.0 && t->blocked && !(d->held = calloc(d->n + 1, 1))) {
    lw_error_set(err, LW_ENOMEM, "out of memory for the dynamics of %zu coordinates", d->n);
    lw_dynamics_free(d);
    return NULL;
  }
  /* massless: the matrix of the flow is the damping's, gamma per unit density */
  d->mass = t->mass_new(state, p, d->rho > 0.0 ? d->rho : d->gamma, err);
  if (!d->mass || lw_dynamics_sync(d, err) ||
      (d->integrator == LW_INTEGRATOR_REVIEW && lw_dyn_review_init(d, p, err))) {
    lw_dynamics_free(d);
    return NULL;
  }
  return d;
}

double lw_dynamics_kinetic(lw_dynamics *d)
{
  if (d->rho == 0.0) return 0.0;
  d->type->mass_solve(d->mass, d->pi, d->v);
  double t = 0.0;
  for (size_t i = 0; i < d->n; i++) t += d->pi[i] * d->v[i];
  return 0.5 * t;
}

void lw_dynamics_set_velocity(lw_dynamics *d, const double *xdot)
{
  d->type->mass_apply(d->mass, xdot, d->pi);
  for (size_t i = 0; i < d->n; i++)
    if (d->type->mass_pinned(d->mass, i)) d->pi[i] = 0.0;
}

/* out = dH/dx(x, pi) = grad E - dT/dx(x, M(x)^-1 pi), with g = grad E(x) and
** the mass matrix factored at x. */
static void dh_dx(lw_dynamics *d, const double *x, const double *pi, double *out)
{
  d->type->mass_solve(d->mass, pi, d->v);
  d->type->mass_dx(d->mass, x, d->v, d->tx);
  for (size_t i = 0; i < d->n; i++) out[i] = d->g[i] - d->tx[i];
}

static lw_status not_converged(const lw_dynamics *d, const char *what, lw_error *err)
{
  return lw_error_set(err, LW_EINPUT, "the dynamics' %s did not converge at t = %g s (step %lu): lower dynamics.dt "
                      "(now %g s)", what, d->time, d->steps, d->dt);
}

/* Half a step of the pair dampers, forward (first half) or back (second). */
static void damp_pairs(lw_dynamics *d, double h, int second)
{
  if (d->pair_dampers) d->pairs_took += d->type->damp_pairs(d->state, d->mass, h, second, d->pi);
}

static lw_status leapfrog(lw_dynamics *d, lw_error *err)
{
  const lw_system_type *t = d->type;
  size_t n = d->n;
  double h = d->dt, *pih = d->pi1, *x1 = d->x1;
  lw_status s;
  /* gamma's decay inside each half kick, as the exact flow of
  ** pi' = -G - (gamma/rho) pi for a fixed force G: pi <- f pi - kick G with
  ** f = exp(-z), kick = h/2 (1 - f)/z, z = gamma h / 2 rho (f = 1 and kick =
  ** h/2 to the bit without damping).  Decaying pi in half steps on either
  ** side of the undamped kicks instead moved every overdamped step by
  ** -h^2/2 M^-1 grad E whatever gamma was: a 1000 times more viscous
  ** medium gave the same motion; now the step tends to -(h/gamma) grad E,
  ** the massless flow's (docs/NUMERICS.md, "Integrator") */
  const double z = d->gamma / d->rho * 0.5 * h, f = exp(-z), kick = 0.5 * h * (z > 0.0 ? -expm1(-z) / z : 1.0);
  damp_pairs(d, 0.5 * h, 0);
  /* pi+ = f pi - kick dH/dx(x, pi+), M factored at x */
  memcpy(pih, d->pi, n * sizeof *pih);
  int it = 0;
  for (;;) {
    dh_dx(d, d->x, pih, d->u);
    for (size_t i = 0; i < n; i++) d->u[i] = f * d->pi[i] - kick * d->u[i];
    int done = converged(d->u, pih, n);
    memcpy(pih, d->u, n * sizeof *pih);
    if (done) break;
    if (++it == FIXED_MAX) return not_converged(d, "momentum half step", err);
  }
  if (it > d->iterations_max) d->iterations_max = it;
  /* x' = x + h/2 (M(x)^-1 + M(x')^-1) pi+ */
  double *u0 = d->u;
  t->mass_solve(d->mass, pih, u0);
  for (size_t i = 0; i < n; i++) x1[i] = d->x[i] + h * u0[i];
  for (it = 0;;) {
    if ((s = t->mass_at(d->mass, x1, err))) return s;
    t->mass_solve(d->mass, pih, d->v);
    for (size_t i = 0; i < n; i++) d->tx[i] = d->x[i] + 0.5 * h * (u0[i] + d->v[i]);
    int done = converged(d->tx, x1, n);
    memcpy(x1, d->tx, n * sizeof *x1);
    if (done) break;
    if (++it == FIXED_MAX) return not_converged(d, "position step", err);
  }
  if (it > d->iterations_max) d->iterations_max = it;
  if (t->constrain) {
    /* RATTLE (Andersen 1983; Hairer, Lubich and Wanner VII.1): the new
    ** position goes back onto the constraint along its normal at the start,
    ** the half-step momentum takes the impulse that moved it there, M dx / h
    ** (a constant M: the rows with a constraint have one), and then its
    ** tangent part at the new position.  Projecting the position by the
    ** shortest way instead, with no impulse, lost energy at a rate O(h). */
    memcpy(d->tx, x1, n * sizeof *x1);
    t->constrain(d->state, d->x, x1, NULL);
    for (size_t i = 0; i < n; i++) d->tx[i] = (x1[i] - d->tx[i]) / h;
    t->mass_apply(d->mass, d->tx, d->v);
    for (size_t i = 0; i < n; i++) pih[i] += d->v[i];
    t->constrain(d->state, x1, NULL, pih);
  }
  if ((s = t->mass_at(d->mass, x1, err)) || (s = evaluate(d, x1, err))) return s;
  if (!isfinite(d->energy)) {
    char what[160];
    lw_dynamics_forbidden_what(t, d->state, what, sizeof what);
    return lw_error_set(err, LW_ERUN, "the motion reached a forbidden state at t = %g s%s: %s", d->time + h, what,
                        LW_DYNAMICS_FORBIDDEN_HINT);
  }
  memcpy(d->x, x1, n * sizeof *x1);
  /* pi' = f pi+ - kick dH/dx(x', pi+) */
  dh_dx(d, d->x, pih, d->u);
  for (size_t i = 0; i < n; i++) d->pi[i] = t->mass_pinned(d->mass, i) ? 0.0 : f * pih[i] - kick * d->u[i];
  damp_pairs(d, 0.5 * h, 1);
  d->time += h;
  return LW_OK;
}

/* One Armijo-limited Euler step of the gradient flow; M (the damping
** matrix) is factored at x on entry and on exit. */
static lw_status flow(lw_dynamics *d, lw_error *err)
{
  const lw_system_type *t = d->type;
  size_t n = d->n;
  double *dir = d->u, e0 = d->energy, slope = 0.0;
  t->mass_solve(d->mass, d->g, dir);
  for (size_t i = 0; i < n; i++) {
    dir[i] = -dir[i];
    slope += d->g[i] * dir[i];
  }
  memcpy(d->pi1, d->g, n * sizeof *d->g); /* grad E at x, should every trial fail */
  if (d->held) memcpy(d->tx, dir, n * sizeof *dir); /* the direction before a trial's holds */
  double h = d->dt;
  lw_status s;
  long holds = 0;
  int away = 0; /* the state stands at a rejected trial */
  for (int k = 0; k <= HALVINGS_MAX; k++, h *= 0.5) {
    /* hold the parts this trial would take through a wall (measured from
    ** x, where the state must stand: back from a rejected trial first); a
    ** shorter trial may hold less */
    if (d->held) {
      memcpy(dir, d->tx, n * sizeof *dir);
      memset(d->held, 0, n);
      if (away && (s = t->set_coords(d->state, d->x, err))) return s;
      away = 0;
      slope = lw_system_hold(t, d->state, d->x, d->pi1, dir, h, d->x1, d->held, n, &holds);
      if (!(slope < 0.0)) {
        d->halvings++;
        continue;
      }
    } else {
      for (size_t i = 0; i < n; i++) d->x1[i] = d->x[i] + h * dir[i];
    }
    if (t->constrain) t->constrain(d->state, NULL, d->x1, NULL);
    if ((s = evaluate(d, d->x1, err))) return s;
    away = 1;
    if (d->energy <= e0 + ARMIJO * h * slope) {
      memcpy(d->x, d->x1, n * sizeof *d->x);
      d->time += h;
      return t->mass_at(d->mass, d->x, err);
    }
    d->halvings++;
  }
  /* at a minimum to rounding: stay */
  memcpy(d->g, d->pi1, n * sizeof *d->g);
  d->energy = e0;
  return t->set_coords(d->state, d->x, err);
}

/* With inertia: E + K against its value before this driver's first step
** (after a resume too, once the momenta are read). */
static lw_status check_stable(lw_dynamics *d, lw_error *err)
{
  const double h = d->energy + lw_dynamics_kinetic(d);
  if (isnan(d->h_ref)) {
    d->h_ref = d->h_min = d->h_last = h;
    d->h_min_time = d->time;
    d->k_max = h - d->energy;
    d->h_scale = fabs(d->energy) + (h - d->energy);
    if (!(d->h_scale > 0.0)) d->h_scale = 1.0;
    return LW_OK;
  }
  d->h_last = h;
  d->k_max = fmax(d->k_max, h - d->energy);
  if (h < d->h_min) {
    d->h_min = h;
    d->h_min_time = d->time;
  }
  /* Heavily damped (gamma dt / 2 rho >= 1) a step is the massless flow's
  ** Euler step, -(dt/gamma) grad E, stable only below 2 gamma over the
  ** stiffest curvature, and nothing halves it: past that E rose 40 % and
  ** the run ended "done" (the check below waits for a hundredfold).  Damped,
  ** E + K cannot pass its start by more than the most kinetic energy (a
  ** step's error is a part of it; 1e-9 of the scale for rounding at rest). */
  if (d->gamma / d->rho * 0.5 * d->dt >= 1.0 && h - d->h_ref > d->k_max + 1e-9 * d->h_scale)
    return lw_error_set(err, LW_EINPUT, "the heavily damped motion is unstable at t = %g s: its energy E + K rose from "
                        "%g to %g, past its start by more than its kinetic energy ever was (a step this long is an "
                        "Euler step of the massless flow, stable only below 2 gamma over the stiffest curvature): "
                        "lower dynamics.dt (now %g s), or take rho = 0, whose steps halve where they must", d->time,
                        d->h_ref, h, d->dt);
  if (h - d->h_ref <= LW_DYN_BLOWUP * d->h_scale) return LW_OK;
  return lw_error_set(err, LW_EINPUT, "the motion is unstable at t = %g s: the energy E + K rose from %g to %g: "
                      "lower dynamics.dt (now %g s)", d->time, d->h_ref, h, d->dt);
}

void lw_dynamics_rise_note(const lw_dynamics *d, char *buf, size_t n)
{
  buf[0] = '\0';
  if (!(d->rho > 0.0) || (d->gamma == 0.0 && !d->pair_dampers) || isnan(d->h_ref)) return;
  const double rise = d->h_last - d->h_min, took = d->h_ref - d->h_min, scale = took + d->k_max;
  if (rise > LW_DYN_RISE_NOTE * scale && took > d->k_max && rise > 1e-9 * d->h_scale)
    snprintf(buf, n, "the damped motion's E + K ended %.3g above its lowest (%.10g at t = %g s), %.2g of the energy "
             "in motion (damped plus the most kinetic), where damping only lowers it: a mode the step cannot hold "
             "was growing; lower dynamics.dt (now %g s) and run it again", rise, d->h_min, d->h_min_time,
             rise / scale, d->dt);
}

lw_status lw_dynamics_step(lw_dynamics *d, lw_error *err)
{
  lw_status s;
  if (d->rho > 0.0 && isnan(d->h_ref) && (s = check_stable(d, err))) return s;
  s = d->rho == 0.0                             ? flow(d, err)
      : d->integrator == LW_INTEGRATOR_REVIEW ? lw_dyn_review_step(d, err)
                                              : leapfrog(d, err);
  if (!s && d->rho > 0.0) s = check_stable(d, err);
  if (!s) d->steps++;
  /* a state the row cannot hold (a D-NURBS weight past the doubles' range)
  ** says what it is, not what to do: the step that took it there */
  if (s == LW_EINPUT && !strstr(err->msg, "dynamics.dt")) {
    char msg[LW_ERROR_MSG];
    snprintf(msg, sizeof msg, "%s", err->msg);
    lw_error_set(err, LW_EINPUT, "the motion at t = %g s: %s: lower dynamics.dt (now %g s)", d->time, msg, d->dt);
  }
  return s;
}
