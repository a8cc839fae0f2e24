/* particles_place.c -- the placement patterns of the particle system (particles_place.h). */
#include "linewise/particles_place.h"

#include <gsl/gsl_math.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <string.h>
#include <stdlib.h>

#include "linewise/grid.h"
#include "linewise/mc.h"
#include "linewise/params.h"
#include "linewise/particles_geom.h"

double lw_particles_auto_size(int pattern, size_t count, double r0)
{
  double n = (double)(count ? count : 1);
  switch (pattern) {
  case LW_PPATTERN_CLOUD: return r0 * cbrt(n / M_SQRT2);
  case LW_PPATTERN_PLANE: return r0 * sqrt(2.0 * sqrt(3.0) * n / M_PI);
  default: return r0 * sqrt(sqrt(3.0) * n / (2.0 * M_PI));
  }
}

/* The lattice spacing of the plane pattern for `count` particles in a disc
** of diameter size. */
static double plane_spacing(size_t count, double size)
{
  return size * sqrt(M_PI / (2.0 * sqrt(3.0) * (double)(count ? count : 1)));
}

/* A site (i, j) of the hexagonal lattice, x = a (i + j/2), y = a j sqrt(3)/2,
** and its squared distance from the origin in units of a^2, an integer. */
typedef struct {
  long d2, i, j;
} site;

static int site_cmp(const void *pa, const void *pb)
{
  const site *a = pa, *b = pb;
  /* a total order, so the choice among equally distant sites is fixed */
  if (a->d2 != b->d2) return a->d2 < b->d2 ? -1 : 1;
  if (a->j != b->j) return a->j < b->j ? -1 : 1;
  return (a->i > b->i) - (a->i < b->i);
}

/* The count hexagonal sites nearest the origin, spacing a. */
static lw_status plane_sites(size_t count, double a, double *x, lw_error *err)
{
  long m = (long)ceil(sqrt((double)count)) + 2;
  size_t n = (size_t)(2 * m + 1) * (size_t)(2 * m + 1);
  site *s = malloc(n * sizeof *s);
  if (!s) return lw_error_set(err, LW_ENOMEM, "out of memory for the plane pattern (%zu particles)", count);
  size_t k = 0;
  for (long j = -m; j <= m; j++)
    for (long i = -m; i <= m; i++) s[k++] = (site){i * i + i * j + j * j, i, j};
  qsort(s, n, sizeof *s, site_cmp);
  for (k = 0; k < count; k++) {
    x[3 * k] = a * ((double)s[k].i + 0.5 * (double)s[k].j);
    x[3 * k + 1] = a * (double)s[k].j * (0.5 * sqrt(3.0));
    x[3 * k + 2] = 0.0;
  }
  free(s);
  return LW_OK;
}

/* 1 if a particle of g (positions x) lies closer than d to p. */
static int crowded(const lw_cellgrid *g, const double *x, const double p[3], double d)
{
  int cx, cy, cz;
  lw_cellgrid_locate3(g, p[0], p[1], p[2], &cx, &cy, &cz);
  for (int zz = cz > 0 ? cz - 1 : 0; zz <= cz + 1 && zz < g->nz; zz++)
    for (int yy = cy > 0 ? cy - 1 : 0; yy <= cy + 1 && yy < g->ny; yy++)
      for (int xx = cx > 0 ? cx - 1 : 0; xx <= cx + 1 && xx < g->nx; xx++) {
        const lw_cell *c = &g->cell[((size_t)zz * (size_t)g->ny + (size_t)yy) * (size_t)g->nx + (size_t)xx];
        const uint32_t *id = lw_cell_idx(c);
        for (uint32_t e = 0; e < c->n; e++) {
          const double *o = x + 3 * (size_t)id[e];
          double r[3] = {o[0] - p[0], o[1] - p[1], o[2] - p[2]};
          if (lw_v3_dot(r, r) < d * d) return 1;
        }
      }
  return 0;
}

lw_status lw_particles_place(int pattern, size_t count, double size, double noise, double normal_noise,
                             double min_dist, unsigned long seed, int (*outside)(const void *, const double[3]),
                             const void *ctx, double *x, double *q, lw_error *err)
{
  lw_cellgrid *g = NULL;
  if (pattern == LW_PPATTERN_PLANE) {
    lw_status s = plane_sites(count, plane_spacing(count, size), x, err);
    if (s) return s;
  } else if (pattern == LW_PPATTERN_CLOUD && min_dist > 0) {
    const double lo[3] = {-0.5 * size, -0.5 * size, -0.5 * size}, ext[3] = {size, size, size};
    if (!(g = lw_cellgrid_new3(lo, ext, min_dist, count, err))) return LW_ENOMEM;
  }
  gsl_rng *r = lw_rng_new();
  if (!r) {
    lw_cellgrid_free(g);
    return lw_error_set(err, LW_ENOMEM, "out of memory for the placement's generator");
  }
  gsl_rng_set(r, seed);
  const double golden = M_PI * (3.0 - sqrt(5.0));
  for (size_t k = 0; k < count; k++) {
    double *xk = x + 3 * k, *qk = q + 4 * k;
    if (pattern == LW_PPATTERN_CLOUD) {
      /* random sequential addition: a few tries for a place inside the
      ** boundary and min_dist clear of the others, then the last try stands */
      for (int tries = 0; tries < LW_PLACE_TRIES; tries++) {
        for (int c = 0; c < 3; c++) xk[c] = size * (gsl_rng_uniform(r) - 0.5);
        if ((!outside || !outside(ctx, xk)) && (!g || !crowded(g, x, xk, min_dist))) break;
      }
      if (outside && outside(ctx, xk)) { /* a crowded place stands; one outside cannot */
        gsl_rng_free(r);
        lw_cellgrid_free(g);
        return lw_error_set(err, LW_EINPUT, "the cloud pattern (a cube of side %g) found no place inside the boundary "
                            "for particle %zu in %d tries: expected a boundary that holds more of the cube", size,
                            k + 1, LW_PLACE_TRIES);
      }
      if (g && lw_cellgrid_insert3(g, (uint32_t)k, xk[0], xk[1], xk[2])) {
        gsl_rng_free(r);
        lw_cellgrid_free(g);
        return lw_error_set(err, LW_ENOMEM, "out of memory for the cloud pattern");
      }
      /* a Gaussian 4-vector has a uniform direction: a uniform rotation */
      for (int c = 0; c < 4; c++) qk[c] = gsl_ran_gaussian_ziggurat(r, 1.0);
      lw_quat_normalise(qk);
    } else if (pattern == LW_PPATTERN_PLANE) {
      qk[0] = 1.0;
      qk[1] = qk[2] = qk[3] = 0.0;
    } else {
      double z = 1.0 - (2.0 * (double)k + 1.0) / (double)count, rho = sqrt(fmax(0.0, 1.0 - z * z));
      double phi = golden * (double)k, n[3] = {rho * cos(phi), rho * sin(phi), z};
      for (int c = 0; c < 3; c++) xk[c] = 0.5 * size * n[c];
      lw_quat_from_normal(n, qk);
    }
    if (noise > 0) {
      /* a site the noise would push past the boundary keeps its place (a
      ** cloud that fills its sphere could not start: "particle 70 is
      ** outside"); the noise is drawn either way, so the stream, and every
      ** placement it did not refuse, stay as they were */
      double moved[3];
      for (int c = 0; c < 3; c++) moved[c] = xk[c] + gsl_ran_gaussian_ziggurat(r, noise);
      if (!outside || !outside(ctx, moved)) memcpy(xk, moved, sizeof moved);
    }
    if (normal_noise > 0) {
      double axis[3], dq[4], t[4];
      gsl_ran_dir_3d(r, &axis[0], &axis[1], &axis[2]);
      lw_quat_axis_angle(axis, gsl_ran_gaussian_ziggurat(r, normal_noise), dq);
      lw_quat_mul(dq, qk, t);
      lw_quat_normalise(t);
      for (int c = 0; c < 4; c++) qk[c] = t[c];
    }
  }
  gsl_rng_free(r);
  lw_cellgrid_free(g);
  return LW_OK;
}
