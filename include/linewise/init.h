/*
** init.h -- initial states: straight splines placed at random inside the
** boundary, and the seeds of independent random streams.
*/
#ifndef LINEWISE_INIT_H
#define LINEWISE_INIT_H

#include <gsl/gsl_rng.h>

#include "linewise/scene.h"
#include "linewise/spline.h"

/* n splines of `segments` straight segments of `segment_length` mm, each at
** a uniformly random centre and direction, kept only if its nodes and its
** quadrature samples lie inside the boundary; the rest length is the
** spline's length.  LW_EINPUT if a spline does not fit after many tries. */
lw_splines *lw_init_random(const lw_scene *sc, size_t n, size_t segments, double segment_length,
                           gsl_rng *rng, lw_error *err);

/* A seed for stream `stream` of a run seeded with `seed` (SplitMix64 of
** both), so replicas and the placement get independent, reproducible
** streams whatever the thread schedule. */
unsigned long lw_stream_seed(unsigned long seed, unsigned long stream);

#endif
