/*
** particles_place.h -- initial placement of the oriented particles: a random
** cloud, a noisy plane or a noisy sphere (particles.pattern).
**
**   cloud   positions uniform in the cube of side `size` around the origin
**           and inside the boundary, no two closer than min_dist (r0/2:
**           random sequential addition, LW_PLACE_TRIES draws for a clear
**           place, then the last draw stands), orientations uniform over all rotations (a normalised
**           4-D Gaussian quaternion).  Pure uniform placement puts some
**           pairs so close that the Lennard-Jones energy reaches 1e20 and
**           more, which no running total can later cancel to 1e-9 of
**           what is left;
**   plane   the `count` sites of a hexagonal lattice in z = 0 nearest the
**           origin, spaced so that they fill a disc of diameter `size`,
**           normals +z;
**   sphere  a Fibonacci sphere of diameter `size` (point k at height
**           z = 1 - (2k + 1)/count, turned by the golden angle k pi (3 - sqrt 5)
**           about z), normals outward.
**
** Then every coordinate gets Gaussian noise of standard deviation `noise`
** (but for a site it would push outside the boundary, which keeps its place),
** and every orientation a tilt about a uniformly random axis by an angle of
** standard deviation `normal_noise`.  The automatic size (size = 0) fills
** the pattern at the spacing r0: a hexagonal sheet holds one particle per
** sqrt(3)/2 r0^2 of area (the seed's A_p), a face-centred cubic packing one
** per r0^3 / sqrt(2) of volume.
**
** Draws come from one mt19937 stream in particle order (position, then
** orientation, then the noises), so a seed fixes the placement.
*/
#ifndef LINEWISE_PARTICLES_PLACE_H
#define LINEWISE_PARTICLES_PLACE_H

#include <stddef.h>

#include "linewise/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The automatic extent of `count` particles of the pattern at spacing r0. */
double lw_particles_auto_size(int pattern, size_t count, double r0);


#define LW_PLACE_TRIES 100

/* Places count particles: x (3 count) and q (4 count, unit).  A cloud's
** tries also count a place where outside(ctx, x) is not 0 as taken (a
** boundary; outside NULL: none).  LW_ENOMEM if the lattice or the cloud's
** grid cannot be built. */
lw_status lw_particles_place(int pattern, size_t count, double size, double noise, double normal_noise,
                             double min_dist, unsigned long seed, int (*outside)(const void *, const double[3]),
                             const void *ctx, double *x, double *q, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
