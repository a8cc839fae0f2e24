/*
** dynamics.h -- the Lagrangian driver: equations of motion of a system with
** kinetic energy T = 1/2 xdot' M(x) xdot and potential energy E(x) (every
** term of the scene), integrated in time.  It sees the system only through
** its row (system.h: coordinates, gradient, mass matrix), so any system with
** inertia can use it.
**
** With momenta pi = M(x) xdot the Hamiltonian is H = 1/2 pi' M(x)^-1 pi + E(x)
** and the equations are
**
**     dx/dt = M^-1 pi,   dpi/dt = -grad E + dT/dx|_xdot - (gamma/rho) pi,
**
** where dT/dx at fixed velocity is the mass matrix's dependence on x (the
** seed's Terms 2 and 3, docs/NUMERICS.md) and the last term is Rayleigh
** damping with the dissipation function (gamma/2) int |dr/dt|^2 dl, which is
** (gamma/rho) T: its force is -(gamma/rho) M xdot = -(gamma/rho) pi.
**
** Integrator (rho > 0): the generalised leapfrog (Stormer-Verlet for a
** position-dependent mass; Hairer, Lubich and Wanner, Geometric Numerical
** Integration, VI.3), symmetric, symplectic and of order 2:
**
**     pi+ = pi  - h/2 dH/dx(x, pi+)                  (implicit: fixed point)
**     x'  = x   + h/2 (M(x)^-1 + M(x')^-1) pi+         (implicit: fixed point)
**     pi' = pi+ - h/2 dH/dx(x', pi+)                 (explicit)
**
** with dH/dx(x, pi) = grad E(x) - dT/dx(x, M(x)^-1 pi).  Without damping the
** energy error stays O(h^2) over long times where the energy is smooth (the
** pair term's near field has kinks: docs/NUMERICS.md, "Integrator") and the momentum of a
** translation-invariant scene is kept to rounding.  Damping is the exact
** flow pi <- pi exp(-gamma h / 2 rho) for half a step on either side
** (Strang splitting: order 2, and exact for the decay alone).  Dampers
** between neighbours (the row's damp_pairs; particles' dynamics.dashpot)
** take the momenta through half a step on either side too, their pairs in
** one order before and in the opposite order after, which keeps the step
** symmetric and so of order 2.
**
** Massless (rho = 0, gamma > 0): the gradient flow D(x) dx/dt = -grad E with
** the damping matrix D = gamma M/rho, as D-NURBS fits.  Each step is an
** explicit Euler step dx = -h D^-1 grad E, halved until the energy falls by
** at least 1e-4 of what the slope promises (Armijo), so the flow never
** leaves the allowed set and its energy never rises.  Where the system says
** which parts a trial would make forbidden (its row's `blocked`), the step
** holds their coordinates and moves the rest at the same length
** (lw_system_hold: measured from where the flow stands, in up to
** LW_HOLD_ROUNDS rounds) before it is halved: a page of thousands of
** segments always has one at a regularity wall, which would otherwise halve
** every step to nothing.
**
** `dynamics.integrator = review` replaces the leapfrog by the implicit
** scheme of the D-NURBS review (dyn_review.h): backward in the stiffness, so
** it damps high frequencies; meant for the quadratic D-NURBS energy.
*/
#ifndef LINEWISE_DYNAMICS_H
#define LINEWISE_DYNAMICS_H

#include "linewise/params.h"
#include "linewise/system.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  const lw_system_type *type;
  void *state;               /* the system's state (not owned) */
  void *mass;                /* the row's mass matrix (owned) */
  size_t n;                  /* coordinates */
  double *x, *pi, *g;        /* coordinates, momenta, grad E at x */
  double *v, *tx, *x1, *pi1, *u; /* scratch */
  double rho, gamma, dt;
  double energy;             /* E(x) */
  double time;               /* s */
  unsigned long steps;       /* time steps done */
  unsigned long halvings;    /* massless: step halvings so far */
  int iterations_max;        /* most fixed-point iterations a step needed */
  int integrator;            /* LW_INTEGRATOR_* */
  double *work;              /* the review scheme's scratch (dyn_review.h), or NULL */
  unsigned char *held;       /* massless: the coordinates a step holds (n) */
  double h_ref, h_scale;     /* E + K and |E| + K before the first step here (NAN: not yet) */
  double h_min, h_min_time;  /* the lowest E + K since, and when */
  double h_last, k_max;      /* E + K after the last step, the most K since */
  int pair_dampers;          /* 1 if the scene names dampers between neighbours */
  double pairs_took;         /* the kinetic energy they took since this driver began */
} lw_dynamics;

/* With inertia, E + K may not rise by more than this many times h_scale
** (damping only lowers it, the leapfrog's error is small): beyond it the
** motion is unstable, its step too long, and it stops. */
#define LW_DYN_BLOWUP 100.0

/* A damped motion whose E + K ends more than this share of (the energy the
** damping took + the most kinetic energy) above its lowest is said to have
** risen (lw_dynamics_rise_note): a mode the step cannot hold was growing,
** below the blow-up above (an engineer's run at a step too long ended
** "done", its lines strained 16 %, E + K up hundreds from its lowest).  Only
** where the damping took more than the most kinetic energy (a barely damped
** stable motion's energy error wobbles by a percent or two of it) and past
** rounding (a resume at rest rose by 1e-11, "0.5 of the energy in motion"). */
#define LW_DYN_RISE_NOTE 0.1

/* A warning into buf (n bytes) where a damped motion's E + K ended risen
** from its lowest by more than LW_DYN_RISE_NOTE, else "". */
void lw_dynamics_rise_note(const lw_dynamics *d, char *buf, size_t n);

/* What a motion that reached a forbidden state (+inf energy) can do: a
** step too long gets there where a shorter one does not; a motion that
** gets there at the same time whatever the step goes there itself. */
/* " (what makes the row's states forbidden)", from its describe(), or ""
** where it names nothing: for the messages of a motion that reached one. */
void lw_dynamics_forbidden_what(const lw_system_type *t, const void *state, char *buf, size_t n);

#define LW_DYNAMICS_FORBIDDEN_HINT                                                                     \
  "a shorter dynamics.dt passes it if the step took it there; if the motion stops at the same time " \
  "whatever the step, it goes there itself (more damping, dynamics.gamma, or stiffer terms hold it)"

/* A driver for `state` (a system of row t) with the [dynamics] parameters;
** momenta start at 0.  LW_EINPUT naming the key if the system has no
** inertia or gradient, or rho = gamma = 0. */
lw_dynamics *lw_dynamics_new(const lw_system_type *t, void *state, const lw_params *p, lw_error *err);
void lw_dynamics_free(lw_dynamics *d);

/* One time step; the system's state follows.  LW_EINPUT if the motion
** reaches a forbidden state or becomes unstable (lower dynamics.dt) or a
** fixed point does not converge. */
lw_status lw_dynamics_step(lw_dynamics *d, lw_error *err);

/* The kinetic energy 1/2 pi' M^-1 pi at the current x. */
double lw_dynamics_kinetic(lw_dynamics *d);

/* Sets the momenta from velocities xdot (pi = M xdot; held coordinates 0). */
void lw_dynamics_set_velocity(lw_dynamics *d, const double *xdot);

/* Recomputes x, E and its gradient, and the mass matrix from the system's
** state (after a resume or an outside change of the state). */
lw_status lw_dynamics_sync(lw_dynamics *d, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
