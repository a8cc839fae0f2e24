/*
** dyn_review.h -- the implicit scheme of the D-NURBS review as a choice of
** the dynamics driver (`dynamics.integrator = review`; docs/NUMERICS.md,
** "D-NURBS").  Central differences in time for the inertia and damping and
** the stiffness at the new time (the review's eqs. 98 and 103, with its
** slips corrected):
**
**     M (p+ - 2p + p-) / h^2 + D (p+ - p-) / 2h + grad E(p+) = 0.
**
** With D = (gamma/rho) M and E quadratic (frozen weights), p+ = p + delta
** solves the symmetric positive definite system
**
**     ((1 + h gamma / 2 rho) M + h^2 K) delta = h (1 - h gamma / 2 rho) pi - h^2 grad E(p)
**
** with pi = M (p - p-) / h the backward-difference momentum the driver
** keeps (so checkpoints and the kinetic energy need nothing new).  It is
** solved by conjugate gradients, whose products K v are differences of the
** row's gradient (exact for the quadratic energy), preconditioned by the
** row's factor of the matrix itself (mass_shift): one iteration, plus one or
** two for rounding.  A row without that factor (a mass matrix that depends
** on the coordinates, an energy that is not quadratic: splines, particles,
** free weights) is refused.  Unconditionally stable, first order: a mode of
** frequency omega loses amplitude at the rate omega^2 h / 2 that no
** physics asks for.
*/
#ifndef LINEWISE_DYN_REVIEW_H
#define LINEWISE_DYN_REVIEW_H

#include "linewise/dynamics.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Has the row factor the matrix (after the mass matrix is made) and
** allocates the scheme's scratch; LW_EINPUT naming the key if rho = 0 or the
** row has no such factor. */
lw_status lw_dyn_review_init(lw_dynamics *d, const lw_params *p, lw_error *err);

/* One step; LW_EINPUT if the solve does not converge or the state is forbidden. */
lw_status lw_dyn_review_step(lw_dynamics *d, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
