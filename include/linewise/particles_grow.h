/*
** particles_grow.h -- births and deaths of oriented particles: the seed's
** growth of a surface ("split, join, or extend surfaces") as a reversible
** pair of Monte Carlo moves (particles.birth, particles.death, with the
** energy chem N; docs/NUMERICS.md, "Births and deaths").
**
** A birth picks an anchor j uniformly among all n particles and puts a new
** free particle in j's tangent plane:
**   position  x_j + rho (cos phi t1 + sin phi t2) + h n_j, uniform over the
**             annulus LW_GROW_INNER <= rho <= LW_GROW_OUTER (area measure)
**             times the slab |h| <= LW_GROW_SLAB (all in r0), so the density
**             is 1 / (pi (b^2 - a^2) 2 c) there and 0 elsewhere;
**   normal    von Mises-Fisher about n_j with concentration LW_GROW_KAPPA:
**             density kappa e^(kappa (n.n_j - 1)) 2 / (1 - e^(-2 kappa))
**             against the sphere's normalised area, and a uniform spin about
**             it, so the same density against the rotation group's
**             normalised measure.
** The density g of a new particle is the mean over the anchors that could
** have proposed it.  A death picks one of the n_f particles without pin
** flags uniformly.  With the reference measure of a particle dx / r0^3
** times the rotation group's, the Hastings factors are
**
**     birth  w_death / (n_f + 1)  /  (w_birth g(new | state) r0^3)
**     death  w_birth g(k | state without k) r0^3  /  (w_death / n_f)
**
** and the chain accepts with min(1, factor exp(-dE / T)), dE with chem's
** change.  A death no birth could have proposed (no anchor within reach)
** has factor 0.  Births stop at particles.max_count.
*/
#ifndef LINEWISE_PARTICLES_GROW_H
#define LINEWISE_PARTICLES_GROW_H

#include <gsl/gsl_rng.h>

#include "linewise/particles.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_GROW_INNER 0.75
#define LW_GROW_OUTER 1.25
#define LW_GROW_SLAB 0.25
/* 1 / sigma^2 for a spread of 15 degrees */
#define LW_GROW_KAPPA 14.59
/* the farthest an anchor can be, sqrt(outer^2 + slab^2), rounded up: the
** range must reach it for the grid's walk to find every anchor */
#define LW_GROW_REACH 1.275

/* Draws a birth (kind LW_PMOVE_BIRTH) or a death (LW_PMOVE_DEATH) into pr
** and returns its dE (chem included), with pr->log_ratio its Hastings
** factor.  A birth at max_count, or outside the boundary, is forbidden
** (+inf, *forbidden = 1); a death with no particle free of pins is the
** identity. */
double lw_particles_propose_grow(const lw_particles *p, lw_particles_prop *pr, int kind, gsl_rng *rng,
                                 int *forbidden);

#ifdef __cplusplus
}
#endif

#endif
