/*
** quench.h -- the quench after annealing ([anneal] quench = bfgs):
** limited-memory BFGS takes a system's state to the nearest local minimum
** of its energy, through the row's coordinates and gradient (system.h), so
** it works for any system that has a gradient and names none.
**
** The allowed set: a state the energy forbids (+inf: outside the boundary,
** an irregular segment) is never accepted.  Where the row says which parts
** a step would make forbidden (system.h, `blocked`), the step holds those
** parts and moves the rest, so one segment at a wall does not stop the
** others (quench.c has why GSL's minimisers could not); elsewhere the step
** is halved until it is allowed.
**
** Where the row can solve for part of its minimum itself (system.h,
** `minimize`), that solve comes first, and again after each stall while it
** lowers the energy (rounds): the stiff part is then solved, not iterated.
**
** Deterministic: the same state gives the same iterates whatever the thread
** count (the gradient and the energy are serial sums in a fixed order).
*/
#ifndef LINEWISE_QUENCH_H
#define LINEWISE_QUENCH_H

#include <signal.h>

#include "linewise/error.h"
#include "linewise/system.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Why a quench ended (lw_quench_end_name: its word in summary.json). */
typedef enum {
  LW_QUENCH_RUNNING,    /* not yet */
  LW_QUENCH_CONVERGED,  /* the gradient norm reached tol */
  LW_QUENCH_STALLED,    /* the stall rule */
  LW_QUENCH_ITERATIONS, /* max_iter */
  LW_QUENCH_STOPPED,    /* *stop was set (a signal) */
  LW_QUENCH_NO_DESCENT  /* no step descends: the minimum to rounding */
} lw_quench_end;

const char *lw_quench_end_name(lw_quench_end e);

typedef struct {
  double energy_before, energy_after;     /* total energy */
  double gradient_before, gradient_after; /* Euclidean norm of the gradient, energy/mm */
  long iterations;                        /* minimiser iterations */
  int rounds;                             /* rounds of the row's own minimum and L-BFGS (0: none ran) */
  long evaluations;                       /* energy evaluations (with or without gradient) */
  long forbidden;                         /* of which at forbidden points: steps shortened */
  long holds;                             /* parts held by a step at a wall (each time) */
  double seconds;                         /* wall-clock time of the quench */
  int converged;                          /* 1: the gradient norm reached tol */
  lw_quench_end ended;                    /* why it ended */
} lw_quench_report;

/* When to stop. */
#define LW_QUENCH_WINDOW 50 /* iterations the stall rule looks back over */
#define LW_QUENCH_STALL_GRADIENT 0.9 /* ... and waits while the gradient norm falls below this share */
typedef struct {
  double tol;      /* the gradient norm to stop at */
  long max_iter;   /* iterations at most */
  double stall;    /* stop when the last LW_QUENCH_WINDOW iterations removed less than this
                   ** share of the energy the quench removed so far, and the gradient norm
                   ** did not fall below LW_QUENCH_STALL_GRADIENT of its value over them
                   ** (0: never) */
  const volatile sig_atomic_t *stop; /* may be NULL; set (a signal): stop at the next iteration */
  const unsigned char *pinned; /* NULL, or 1 at the coordinates the scene holds besides those the row
                               ** holds itself (the dynamics' pins): never moved */
} lw_quench_opts;

/* Quenches the state of sys in place until one of o's rules, or no step
** descending any more, ends it (r->ended says which).  LW_EINPUT if the
** system has no gradient or its gradient fails (err says why), LW_ENOMEM;
** the state is then the last accepted one (or the start), never a
** forbidden one.  A start that is itself forbidden is left alone. */
lw_status lw_quench_run(lw_system *sys, const lw_quench_opts *o, lw_quench_report *r, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
