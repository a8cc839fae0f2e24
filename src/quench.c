/*
** quench.c -- limited-memory BFGS from the annealed state to the nearest
** local minimum, holding the parts a step would take through a wall
** (quench.h).
**
** Why not GSL's minimisers.  The energy is +inf outside the allowed set
** (the boundary, regularity), and an annealed state of thousands of
** segments always has some of them at a regularity wall.  GSL's BFGS owns
** its line search: a trial point past a wall can only be given a large
** value, the search shrinks the step (some 150 evaluations a wall on the
** bundled example) and a restart from the lowest point meets the wall again
** at once, so it stopped after two iterations, having removed 1e-6 of the
** energy in 6.7 s.  Here the step itself knows the walls, as the massless
** flow's does (dynamics.c): the system's `blocked` names the parts a trial
** point would make forbidden, their coordinates are held for that step and
** the rest moves at full length while the direction still descends.  The
** direction is L-BFGS's two-loop recursion (Nocedal and Wright, Numerical
** Optimization, algorithm 7.4) over the last MEMORY steps; a step is taken
** at the first length, halving from 1, that meets Armijo's condition, and a
** step pair with s.y <= 0 (possible without the curvature condition) is
** not kept.  A direction that does not descend, or a search that fails,
** drops the memory and tries steepest descent; it stops when that fails too
** (the minimum to rounding, or every part that could still move is held).
**
** Every state evaluated is allowed or is never accepted (an Armijo test on
** +inf fails), so the state it ends in is finite, hence regular and inside.
** Deterministic: the same state gives the same iterates whatever the
** thread count (the gradient and the energy are serial sums in a fixed
** order).
*/
#include "linewise/quench.h"
#include "linewise/phase.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MEMORY 5         /* step pairs kept: 2 MEMORY + 6 vectors of n doubles in all */
#define HALVINGS_MAX 50  /* a step of 2^-50 of the first is nothing */
#define ARMIJO 1e-4
/* Near a minimum the decrease Armijo asks for, about |g|^2 / curvature, sinks
** under the energy's rounding and its test decides on noise: the hanging
** chain stalled at a gradient of 5e-6 (quench_tol 1e-6).  There a step is
** also taken where the energy rose by no more than ROUNDING of itself and
** the slope says the step went toward the minimum (level()). */
#define ROUNDING 1e-12
#define WOLFE_DELTA 0.1
#define WOLFE_SIGMA 0.9
/* No coordinate moves more than this many first steps in one (the rms of
** the coordinates: a page): where the energy has no floor (a weight with
** nothing to hold it) the quench walks off instead of leaping to
** coordinates no drawing can render. */
#define MAX_MOVE 1000.0
/* Rounds of the row's own minimum and L-BFGS (lw_quench_run): another
** only while the row's step lowers the energy by more than this share. */
#define ROUNDS_MAX 50
#define ROUND_GAIN 1e-13
/* What L-BFGS after an exact solve may seem to gain in rounding alone: a
** refined wire's energy sums band terms of 1e6 to about 3e3 (10^-12 of it) */
#define SOLVED_NOISE 1e-11

typedef struct {
  lw_system *sys;
  size_t n;
  double *x, *g, *x1, *g1, *d;     /* the point, its gradient, a trial, its gradient, the direction */
  double *d0;                      /* the direction before a trial's holds */
  double *solved;                  /* where the row's last solve (minimize) left the coordinates */
  double *s[MEMORY], *y[MEMORY];   /* step pairs, oldest at (head - used) mod MEMORY */
  double rho[MEMORY], a[MEMORY];
  int used, head;
  unsigned char *held;             /* n: this step's held coordinates */
  const unsigned char *pinned;     /* NULL, or n: coordinates never moved (lw_quench_opts) */
  long evaluations, forbidden, holds;
  int away;                        /* the state stands at a rejected trial, not at x */
} lbfgs;

static double dot(const double *u, const double *v, size_t n)
{
  double s = 0.0;
  for (size_t i = 0; i < n; i++) s += u[i] * v[i];
  return s;
}

/* The energy at x and its gradient into g: +inf where x is forbidden (a
** non-finite coordinate too); NAN with err set on a failure of the
** gradient. */
static double evaluate(lbfgs *q, const double *x, double *g, lw_error *err)
{
  const lw_system_type *t = q->sys->type;
  lw_error e2 = {0};
  q->evaluations++;
  if (t->set_coords(q->sys->state, x, &e2) != LW_OK) {
    if (e2.code != LW_EINPUT) {
      lw_error_set(err, e2.code, "quench: %s", e2.msg);
      return NAN;
    }
    q->forbidden++;
    return INFINITY;
  }
  double e = t->gradient(q->sys->state, g, &e2);
  /* a coordinate that feels no force is never moved: the steps are made of
  ** gradients (L-BFGS's pairs keep it 0 too) */
  for (size_t i = 0; q->pinned && i < q->n; i++)
    if (q->pinned[i]) g[i] = 0.0;
  if (isnan(e)) {
    lw_error_set(err, e2.code ? e2.code : LW_EINPUT, "quench: %s", e2.msg);
    return NAN;
  }
  if (!isfinite(e)) q->forbidden++;
  return e;
}

/* d = -H g by the two-loop recursion; H0 = gamma I, gamma from the newest
** pair, or scale0 (the first step's length over |g|) without one. */
static void direction(lbfgs *q, double scale0)
{
  const size_t n = q->n;
  double *d = q->d;
  memcpy(d, q->g, n * sizeof *d);
  for (int k = 0; k < q->used; k++) {
    const int i = (q->head - 1 - k + MEMORY) % MEMORY;
    q->a[i] = q->rho[i] * dot(q->s[i], d, n);
    for (size_t j = 0; j < n; j++) d[j] -= q->a[i] * q->y[i][j];
  }
  double gamma = scale0;
  if (q->used) {
    const int i = (q->head - 1 + MEMORY) % MEMORY;
    gamma = 1.0 / (q->rho[i] * dot(q->y[i], q->y[i], n));
  }
  for (size_t j = 0; j < n; j++) d[j] *= gamma;
  for (int k = q->used - 1; k >= 0; k--) {
    const int i = (q->head - 1 - k + MEMORY) % MEMORY;
    const double b = q->rho[i] * dot(q->y[i], d, n);
    for (size_t j = 0; j < n; j++) d[j] += (q->a[i] - b) * q->s[i][j];
  }
  for (size_t j = 0; j < n; j++) d[j] = -d[j];
}

/* Moves the state back to x from a rejected trial, for the next trial's
** holds (lw_system_hold measures from where the state stands: from the
** rejected trial a part held at x moved, and was held again every round).
** Only a system with walls needs it; the next evaluation moves it anyway. */
static lw_status restore(lbfgs *q, lw_error *err)
{
  const lw_system_type *t = q->sys->type;
  if (!t->blocked) return LW_OK;
  lw_error e2 = {0};
  if (t->set_coords(q->sys->state, q->x, &e2) != LW_OK) return lw_error_set(err, e2.code, "quench: %s", e2.msg);
  q->away = 0;
  return LW_OK;
}

/* Whether the trial's slope along the step (g1 . d, d the step as held)
** lies in [SIGMA, 2 DELTA - 1] times the start's, slope: the slope part of
** Hager and Zhang's approximate Wolfe conditions (SIAM J. Optim. 16, 2005),
** which decide on derivatives where the energy's decrease has sunk under
** its rounding. */
static int level(const lbfgs *q, double slope)
{
  const double s1 = dot(q->g1, q->d, q->n);
  return s1 >= WOLFE_SIGMA * slope && s1 <= (2.0 * WOLFE_DELTA - 1.0) * slope;
}

/* One step from x along d, no coordinate moving more than max_move: 1 if
** taken (x, g and *e moved on), 0 if no length descended, -1 on an error. */
static int line_search(lbfgs *q, double *e, double max_move, lw_error *err)
{
  const lw_system_type *t = q->sys->type;
  const size_t n = q->n;
  const double slope0 = dot(q->g, q->d, n);
  if (!(slope0 < 0.0)) return 0;
  memcpy(q->d0, q->d, n * sizeof *q->d);
  double longest = 0.0;
  for (size_t i = 0; i < n; i++) longest = fmax(longest, fabs(q->d[i]));
  double h = longest > max_move ? max_move / longest : 1.0;
  for (int k = 0; k <= HALVINGS_MAX; k++, h *= 0.5) {
    /* each length holds what it would take through a wall; a shorter one
    ** may hold less (held all, it is only shorter) */
    memcpy(q->d, q->d0, n * sizeof *q->d);
    memset(q->held, 0, n);
    if (q->away && restore(q, err) != LW_OK) return -1;
    const double slope = lw_system_hold(t, q->sys->state, q->x, q->g, q->d, h, q->x1, q->held, n, &q->holds);
    if (!(slope < 0.0)) continue;
    const double e1 = evaluate(q, q->x1, q->g1, err);
    if (isnan(e1)) return -1;
    q->away = 1;
    if (e1 <= *e + ARMIJO * h * slope || (e1 <= *e + ROUNDING * fabs(*e) && level(q, slope))) {
      q->away = 0;
      /* the pair (s, y) before x and g move on, kept if s.y > 0 */
      double *s = q->s[q->head], *y = q->y[q->head];
      for (size_t i = 0; i < n; i++) {
        s[i] = q->x1[i] - q->x[i];
        y[i] = q->g1[i] - q->g[i];
      }
      const double sy = dot(s, y, n);
      if (sy > 0.0 && isfinite(sy)) {
        q->rho[q->head] = 1.0 / sy;
        q->head = (q->head + 1) % MEMORY;
        if (q->used < MEMORY) q->used++;
      }
      memcpy(q->x, q->x1, n * sizeof *q->x);
      memcpy(q->g, q->g1, n * sizeof *q->g);
      *e = e1;
      return 1;
    }
  }
  return 0;
}

/* One iteration: L-BFGS's direction, or steepest descent where that leads
** nowhere (scale0 sizes a step without curvature pairs); 1 if a step was
** taken, 0 if none descends (or an error, in *st). */
static int step(lbfgs *q, double *e, double scale0, double max_move, lw_status *st, lw_error *err)
{
  direction(q, scale0);
  int took = line_search(q, e, max_move, err);
  if (took == 0 && q->used) {
    q->used = 0;
    direction(q, scale0);
    took = line_search(q, e, max_move, err);
  }
  if (took < 0) *st = err->code;
  return took > 0;
}

/* The first step's length, in the coordinates' unit: a thousandth of their
** root mean square (for splines ~0.1 mm on a page); later steps take the
** length L-BFGS's curvature estimate gives. */
static double first_step(const double *x, size_t n)
{
  double s = dot(x, x, n);
  s = sqrt(s / (double)(n ? n : 1));
  return s > 0.0 ? 1e-3 * s : 1e-3;
}

/* Whether o's rules end the quench before iteration `it` (at energy e,
** gradient norm gnorm; back[] and back_g[] the energies and gradient norms
** before the last iterations, by iteration mod the window).  The stall rule
** waits while the gradient norm still falls by a tenth over the window: on a smooth
** energy the last digits of the minimum remove little energy but the norm
** keeps falling, where on a picture's kinked one it stops falling. */
static lw_quench_end end_now(const lw_quench_opts *o, long it, double gnorm, const double *back,
                             const double *back_g, double e, double e_start)
{
  if (gnorm <= o->tol) return LW_QUENCH_CONVERGED;
  if (it >= o->max_iter) return LW_QUENCH_ITERATIONS;
  if (o->stop && *o->stop) return LW_QUENCH_STOPPED;
  /* (stall 0 is never: the test read "energy rose over the window", which
  ** the approximate Wolfe steps allow by rounding, and a quench told never to
  ** stall said "stalled") */
  if (o->stall > 0.0 && it >= LW_QUENCH_WINDOW && back[it % LW_QUENCH_WINDOW] - e < o->stall * (e_start - e) &&
      !(gnorm < LW_QUENCH_STALL_GRADIENT * back_g[it % LW_QUENCH_WINDOW]))
    return LW_QUENCH_STALLED;
  return LW_QUENCH_RUNNING;
}

const char *lw_quench_end_name(lw_quench_end e)
{
  static const char *const name[] = {"running", "converged", "stalled", "iterations", "stopped", "no descent"};
  return (unsigned)e < sizeof name / sizeof name[0] ? name[e] : "?";
}

static void lbfgs_free(lbfgs *q)
{
  free(q->x);
  free(q->g);
  free(q->x1);
  free(q->g1);
  free(q->d);
  free(q->d0);
  free(q->solved);
  for (int k = 0; k < MEMORY; k++) {
    free(q->s[k]);
    free(q->y[k]);
  }
  free(q->held);
}

lw_status lw_quench_run(lw_system *sys, const lw_quench_opts *o, lw_quench_report *r, lw_error *err)
{
  const lw_system_type *t = sys->type;
  const double t0 = lw_phase_clock();
  memset(r, 0, sizeof *r);
  r->ended = LW_QUENCH_NO_DESCENT;
  r->energy_before = r->energy_after = t->total(sys->state);
  if (!t->gradient || !t->n_coords || !t->get_coords || !t->set_coords)
    return lw_error_set(err, LW_EINPUT, "quench: the %s system has no gradient", t->name);
  const size_t n = t->n_coords(sys->state), nb = (n ? n : 1) * sizeof(double);
  lbfgs q = {.sys = sys, .n = n, .pinned = o->pinned};
  int ok = (q.x = malloc(nb)) && (q.g = malloc(nb)) && (q.x1 = malloc(nb)) && (q.g1 = malloc(nb)) &&
           (q.d = malloc(nb)) && (q.d0 = malloc(nb)) && (q.held = calloc(n ? n : 1, 1)) &&
           (!t->minimize || (q.solved = malloc(nb)));
  for (int k = 0; ok && k < MEMORY; k++) ok = (q.s[k] = malloc(nb)) && (q.y[k] = malloc(nb));
  lw_status st = LW_OK;
  if (!ok) {
    st = lw_error_set(err, LW_ENOMEM, "out of memory for the quench of %zu coordinates", n);
    goto out;
  }
  if (n == 0 || !isfinite(r->energy_before)) goto out; /* nothing to move, or a forbidden start */
  /* the energy and gradient norm of the last iterations, by iteration mod the window */
  double back[LW_QUENCH_WINDOW], back_g[LW_QUENCH_WINDOW], e = NAN, e_start = NAN, gnorm = NAN, step0 = 0.0;
  lw_quench_end end = LW_QUENCH_RUNNING;
  if (t->minimize) { /* the row's solve moves first: the gradient before the quench is the start's */
    t->get_coords(sys->state, q.x);
    if (isnan(e = evaluate(&q, q.x, q.g, err))) {
      st = err->code;
      goto out;
    }
    r->gradient_before = sqrt(dot(q.g, q.g, n));
  }
  /* Rounds: the row's own step to the minimum over what it can solve for
  ** (the control points of a D-NURBS curve at its present weights), then
  ** L-BFGS over everything; where that stalls and the row's step still
  ** lowers the energy, another round.  Without `minimize`, one round. */
  for (int round = 0; round < ROUNDS_MAX; round++) {
    const double e_was = e, gnorm_was = gnorm;
    if (round > 0) memcpy(q.x1, q.x, n * sizeof *q.x); /* where L-BFGS left it */
    if (t->minimize && (st = t->minimize(sys->state, err))) goto out;
    t->get_coords(sys->state, q.x);
    e = evaluate(&q, q.x, q.g, err);
    if (isnan(e)) {
      st = err->code;
      goto out;
    }
    gnorm = sqrt(dot(q.g, q.g, n));
    const double e_solved = e, g_solved = gnorm;
    if (t->minimize) memcpy(q.solved, q.x, n * sizeof *q.x);
    if (round == 0) {
      step0 = first_step(q.x, n);
      e_start = e;
      if (!t->minimize) r->gradient_before = gnorm;
    } else if (!(e < e_was - ROUND_GAIN * fabs(e_was))) {
      /* the solve gained nothing: the quench ends where L-BFGS did */
      memcpy(q.x, q.x1, n * sizeof *q.x);
      e = e_was, gnorm = gnorm_was;
      break;
    }
    r->rounds = round + 1;
    q.used = 0;
    while ((end = end_now(o, r->iterations, gnorm, back, back_g, e, e_start)) == LW_QUENCH_RUNNING) {
      back[r->iterations % LW_QUENCH_WINDOW] = e;
      back_g[r->iterations % LW_QUENCH_WINDOW] = gnorm;
      if (!step(&q, &e, gnorm > 0.0 ? step0 / gnorm : 0.0, MAX_MOVE * step0, &st, err)) break;
      r->iterations++;
      gnorm = sqrt(dot(q.g, q.g, n));
    }
    /* Where the solve found the minimum to rounding (a frozen-weight wire
    ** refined far: K ~ 5e9), L-BFGS after it moves only within the
    ** energy's rounding, to a larger gradient (2.4 against the solve's 2e-4,
    ** at 700 evaluations): the quench ends at the solve's point. */
    if (t->minimize && end != LW_QUENCH_CONVERGED && end != LW_QUENCH_STOPPED && gnorm > g_solved &&
        !(e < e_solved - SOLVED_NOISE * fabs(e_solved))) {
      memcpy(q.x, q.solved, n * sizeof *q.x);
      e = e_solved, gnorm = g_solved;
      if (end != LW_QUENCH_ITERATIONS) end = LW_QUENCH_NO_DESCENT; /* a cap that was hit is still said */
      break;
    }
    if (st || !t->minimize || end == LW_QUENCH_CONVERGED || end == LW_QUENCH_ITERATIONS || end == LW_QUENCH_STOPPED)
      break;
    if ((st = t->set_coords(sys->state, q.x, err))) goto out;
  }
  if (end != LW_QUENCH_RUNNING) r->ended = end;
  /* the state where the last accepted step left it (the start if none) */
  lw_error e2 = {0};
  if (t->set_coords(sys->state, q.x, &e2) != LW_OK && !st) st = lw_error_set(err, e2.code, "quench: %s", e2.msg);
  r->gradient_after = gnorm;
  r->converged = gnorm <= o->tol;
  r->energy_after = t->total(sys->state);
out:
  r->evaluations = q.evaluations;
  r->forbidden = q.forbidden;
  r->holds = q.holds;
  r->seconds = lw_phase_clock() - t0;
  lbfgs_free(&q);
  return st;
}
