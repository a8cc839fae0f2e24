/* init.c -- random initial placement and stream seeds (init.h). */
#include "linewise/init.h"

#include <gsl/gsl_math.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

unsigned long lw_stream_seed(unsigned long seed, unsigned long stream)
{
  uint64_t z = (uint64_t)seed * 0x9E3779B97F4A7C15ULL + (uint64_t)stream + 1;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  z ^= z >> 31;
  /* gsl_rng_set treats 0 as its default seed: keep streams apart from it */
  return (unsigned long)(z & 0xFFFFFFFFu) | 1u;
}

static int fits(const lw_scene *sc, const lw_node *nd, size_t segments)
{
  lw_samples s;
  for (size_t m = 0; m < segments; m++) {
    lw_segment_sample(&sc->quad, &nd[m], &nd[m + 1], &s);
    for (int q = 0; q < s.n; q++)
      if (!(lw_boundary_distance(&sc->boundary, s.x[q], s.y[q]) < 0)) return 0;
  }
  for (size_t k = 0; k <= segments; k++)
    if (!(lw_boundary_distance(&sc->boundary, nd[k].px, nd[k].py) < 0)) return 0;
  return 1;
}

lw_splines *lw_init_random(const lw_scene *sc, size_t n, size_t segments, double segment_length,
                           gsl_rng *rng, lw_error *err)
{
  size_t *segs = calloc(n ? n : 1, sizeof *segs);
  if (!segs) {
    lw_error_set(err, LW_ENOMEM, "out of memory for %zu splines", n);
    return NULL;
  }
  for (size_t i = 0; i < n; i++) segs[i] = segments;
  lw_splines *sp = lw_splines_new(n, segs, err);
  free(segs);
  if (!sp) return NULL;
  const double L = segment_length * (double)segments;
  const int tries = 10000;
  for (size_t i = 0; i < n; i++) {
    lw_node *nd = &sp->node[sp->first[i]];
    int t;
    for (t = 0; t < tries; t++) {
      double cx = gsl_rng_uniform(rng) * sc->width, cy = gsl_rng_uniform(rng) * sc->height;
      double a = 2.0 * M_PI * gsl_rng_uniform(rng), ux = cos(a), uy = sin(a);
      for (size_t k = 0; k <= segments; k++) {
        double u = ((double)k / (double)segments - 0.5) * L;
        nd[k] = (lw_node){cx + u * ux, cy + u * uy, segment_length * ux / 3.0, segment_length * uy / 3.0};
      }
      if (fits(sc, nd, segments)) break;
    }
    if (t == tries) {
      lw_error_set(err, LW_EINPUT,
                   "[init]: spline %zu of length %g mm did not fit inside the boundary in %d tries "
                   "(shorten init.segment_length or init.segments)", i, L, tries);
      lw_splines_free(sp);
      return NULL;
    }
    sp->rest_length[i] = L;
  }
  return sp;
}
