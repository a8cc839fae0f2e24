/*
** init.h -- initial states: splines placed at random inside the boundary
** (weighted by the picture's darkness, shaped along the field), the number
** of splines from a target ink coverage, and the seeds of independent
** random streams.
*/
#ifndef LINEWISE_INIT_H
#define LINEWISE_INIT_H

#include <gsl/gsl_rng.h>

#include "linewise/params.h"
#include "linewise/scene.h"
#include "linewise/spline.h"

#ifdef __cplusplus
extern "C" {
#endif

/* n splines of `segments` segments of `segment_length` mm, kept only if
** their nodes and quadrature samples lie inside the boundary; the rest
** length is segments * segment_length.  The centre of each is uniform over
** the page, or drawn with density proportional to darkness (1 - tone) when
** the scene has a picture (uniform again if the picture is white).  Each is
** straight at a uniformly random angle, or, when the scene's field term is
** on, follows the streamline of the field through its centre (the random
** angle then only picks the way along an axial field and stands in where
** the field vanishes).  LW_EINPUT if a spline does not fit after many
** tries. */
lw_splines *lw_init_random(const lw_scene *sc, size_t n, size_t segments, double segment_length,
                           gsl_rng *rng, lw_error *err);

/* The picture's darkness (1 - tone) summed per row and cumulated, for
** lw_init_dark_point: cum[j] sums the rows before j, cum[height] is the
** total.  Malloc'ed; NULL without a picture or memory. */
double *lw_init_darkness(const lw_image *img);

/* A point drawn as placement draws a centre (sc's image_place, cum from
** lw_init_darkness, total > 0): a pixel with probability proportional to
** its darkness, then uniformly inside it.  Its density is therefore
** (1 - tone of its pixel) / (cum[height] pixel^2) per mm^2. */
void lw_init_dark_point(const lw_scene *sc, const lw_image *img, const double *cum, gsl_rng *rng, double *x,
                        double *y);

/* Integral of darkness over the inside of the boundary, mm^2: sum over the
** picture's pixels whose centre is inside of (1 - tone) * pixel area, or,
** without a picture, the inside's area. */
double lw_init_ink_area(const lw_scene *sc);

/* How many splines a run starts with: init.splines, or when that is 0 and
** init.coverage > 0, the count whose ink (output.pen_width wide, segments *
** segment_length long each) covers that fraction of the darkness:
**     n = round(coverage * ink area / (pen_width * segments * segment_length)).
** LW_EINPUT (naming init.coverage) above 1e8, or when a coverage is given
** but init.splines was left at its default (the coverage would be ignored),
** and (naming energy.pair_cutoff) for a cutoff shorter than two length
** elements of the placed segments (segment_length / pair nodes). */
lw_status lw_init_count(const lw_scene *sc, const lw_params *p, size_t *n, lw_error *err);

/* The 32-bit generator seed of stream `stream` of a run seeded with `seed`,
** so replicas and the placement get independent, reproducible streams
** whatever the thread schedule: distinct for distinct seeds of one stream,
** and for any two pairs whose seeds are closer than 8,243,553 (streams up
** to 257), but for one pair per stream that GSL seeds alike (0 is its
** 4357).  version: anneal.seed_version (1, runs begun before 2026-12-06). */
unsigned long lw_stream_seed(unsigned long seed, unsigned long stream, int version);

#ifdef __cplusplus
}
#endif

#endif
