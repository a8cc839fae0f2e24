/*
** quench.h -- the quench after annealing ([anneal] quench = bfgs): GSL's
** BFGS minimiser (gsl_multimin_fdfminimizer_vector_bfgs2) takes a system's
** state to the nearest local minimum of its energy, through the row's
** coordinates and gradient (system.h), so it works for any system that has
** a gradient and names none.
**
** The allowed set: a state the energy forbids (+inf: outside the boundary,
** an irregular segment) is never accepted.  Its energy is handed to the
** minimiser as a large finite wall, so the line search sees a point far
** worse than where it came from and shortens the step (quench.c has the
** argument); the state it ends in is the best one it accepted, which is
** finite, hence regular and inside.
**
** Deterministic: the same state gives the same iterates whatever the thread
** count (the gradient and the energy are serial sums in a fixed order).
*/
#ifndef LINEWISE_QUENCH_H
#define LINEWISE_QUENCH_H

#include "linewise/error.h"
#include "linewise/system.h"

typedef struct {
  double energy_before, energy_after;     /* total energy */
  double gradient_before, gradient_after; /* Euclidean norm of the gradient, energy/mm */
  long iterations;                        /* minimiser iterations */
  long evaluations;                       /* energy evaluations (with or without gradient) */
  long forbidden;                         /* of which at forbidden points: steps shortened */
  double seconds;                         /* wall-clock time of the quench */
  int converged;                          /* 1: the gradient norm reached tol */
} lw_quench_report;

/* Quenches the state of sys in place: at most max_iter iterations, until
** the gradient norm is <= tol or a line search makes no progress.
** LW_EINPUT if the system has no gradient or its gradient fails (err says
** why), LW_ENOMEM; the state is then the last accepted one (or the start),
** never a forbidden one.  A start that is itself forbidden is left alone. */
lw_status lw_quench_run(lw_system *sys, double tol, long max_iter, lw_quench_report *r, lw_error *err);

#endif
