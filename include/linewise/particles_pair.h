/*
** particles_pair.h -- the pair energy of two oriented particles (the seed's
** section 4.2 and 4.5, derived again in docs/NUMERICS.md, "Oriented
** particles").
**
** For particles i and j at x_i, x_j with unit normals n_i, n_j, r = x_j - x_i,
** d = |r| < R (R = range r0; nothing beyond it):
**
**   E_ij = alpha_LJ phi_LJ(d)
**        + w_ij [alpha_P phi_P + alpha_N phi_N + alpha_C phi_C]
**
**   phi_LJ = (r0/d)^12 - 2 (r0/d)^6 - (the same at R)   minimum at d = r0
**   phi_P  = (n_i . r)^2 + (n_j . r)^2                   co-planarity, symmetrised
**   phi_N  = |n_i - n_j|^2                                co-normality
**   phi_C  = ((n_i + n_j) . r)^2                          co-circularity
**
** and the weight w_ij (particles.weight):
**
**   poly   (1 - d^2/R^2)^3
**   gauss  (g(d, 0) - g_R) / (1 - g_R)
**   aniso  [max(0, g(d, n_i.r) - g_R) + max(0, g(d, n_j.r) - g_R)] / (2 (1 - g_R))
**   with   g(d, z) = exp(-(d^2 - z^2) / 2a^2 - z^2 / 2b^2),  g_R = exp(-R^2 / 2a^2)
**
** (gauss is aniso with b = a.)  Every form is 1 at d = 0 for a particle in
** the other's tangent plane and falls continuously to 0 at R.  As in the
** seed's E_ij, the Lennard-Jones term is not weighted: its minimum stays at
** r0 whatever the weight.  E_ij is symmetric in i and j, and bit for bit so:
** swapping i and j negates r, which leaves every square, sum and product
** here unchanged.
*/
#ifndef LINEWISE_PARTICLES_PAIR_H
#define LINEWISE_PARTICLES_PAIR_H

#include <math.h>

#include "linewise/error.h"
#include "linewise/params.h"
#include "linewise/particles_geom.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The energy terms of the particle system, in the order of their totals
** (the pair terms first). */
typedef enum {
  LW_PTERM_LJ,
  LW_PTERM_PLANAR,
  LW_PTERM_NORMAL,
  LW_PTERM_CIRCULAR,
  LW_PTERM_GRAVITY,
  LW_PTERM_BOUNDARY,
  LW_PTERM_CHEM, /* chem N: the particles' own energy (births and deaths) */
  LW_PTERM_COUNT
} lw_pterm;

#define LW_PTERM_PAIRS 4 /* LJ, planar, normal, circular */

extern const char *const lw_pterm_names[LW_PTERM_COUNT];

typedef struct {
  double r0, range;            /* length; range = R (absolute) */
  double range2, inv_range2;   /* R^2, 1 / R^2 */
  double alpha[LW_PTERM_PAIRS];/* coefficients of LJ, P, N, C (0 = off) */
  int weight;                  /* LW_PWEIGHT_* (params.h) */
  double ia, ib;               /* 1 / 2a^2, 1 / 2b^2 */
  double g_R, g_scale;         /* exp(-R^2 ia), 1 / (1 - g_R) */
  double lj_shift;             /* the unshifted LJ at R */
  int weighted;                /* 1 if P, N or C is on */
  int on;                      /* 1 if any pair term is on */
} lw_ppair_ctx;

/* Fills c; range, sigma and sigma_normal in units of r0.  LW_EINPUT when
** sigma_normal > sigma for weight = aniso (the message names no file: the
** caller adds where the keys were set). */
lw_status lw_ppair_init(lw_ppair_ctx *c, double r0, double range, int weight, double sigma, double sigma_normal,
                        const double alpha[LW_PTERM_PAIRS], lw_error *err);

/* The Lennard-Jones potential at d^2 (shifted, no coefficient). */
static inline double lw_ppair_lj(const lw_ppair_ctx *c, double d2)
{
  double s = c->r0 * c->r0 / d2, s6 = s * s * s;
  return s6 * s6 - 2.0 * s6 - c->lj_shift;
}

/* The weight of a pair at d^2 < R^2 with zi = n_i.r, zj = n_j.r. */
static inline double lw_ppair_weight(const lw_ppair_ctx *c, double d2, double zi, double zj)
{
  switch (c->weight) {
  case LW_PWEIGHT_POLY: {
    double t = 1.0 - d2 * c->inv_range2;
    return t * t * t;
  }
  case LW_PWEIGHT_GAUSS:
    return (exp(-d2 * c->ia) - c->g_R) * c->g_scale;
  default: { /* LW_PWEIGHT_ANISO */
    double zi2 = zi * zi, zj2 = zj * zj;
    double gi = exp(-(d2 - zi2) * c->ia - zi2 * c->ib) - c->g_R;
    double gj = exp(-(d2 - zj2) * c->ia - zj2 * c->ib) - c->g_R;
    return 0.5 * ((gi > 0.0 ? gi : 0.0) + (gj > 0.0 ? gj : 0.0)) * c->g_scale;
  }
  }
}

/* Adds the pair's energy per term (coefficients applied) to e[0..3] for
** r = x_j - x_i with d2 = |r|^2 < R^2.  Terms that are off add nothing and
** cost nothing but a test. */
static inline void lw_ppair_add(const lw_ppair_ctx *c, const double r[3], double d2, const double ni[3],
                                const double nj[3], double e[LW_PTERM_PAIRS])
{
  if (c->alpha[LW_PTERM_LJ] != 0.0) e[LW_PTERM_LJ] += c->alpha[LW_PTERM_LJ] * lw_ppair_lj(c, d2);
  if (!c->weighted) return;
  double zi = lw_v3_dot(ni, r), zj = lw_v3_dot(nj, r);
  double w = lw_ppair_weight(c, d2, zi, zj);
  if (c->alpha[LW_PTERM_PLANAR] != 0.0) e[LW_PTERM_PLANAR] += c->alpha[LW_PTERM_PLANAR] * w * (zi * zi + zj * zj);
  if (c->alpha[LW_PTERM_NORMAL] != 0.0) {
    /* from the difference, not 2 - 2 n_i.n_j, which cancels for close normals */
    double a = ni[0] - nj[0], b = ni[1] - nj[1], g = ni[2] - nj[2];
    e[LW_PTERM_NORMAL] += c->alpha[LW_PTERM_NORMAL] * w * (a * a + b * b + g * g);
  }
  if (c->alpha[LW_PTERM_CIRCULAR] != 0.0) {
    double s = zi + zj;
    e[LW_PTERM_CIRCULAR] += c->alpha[LW_PTERM_CIRCULAR] * w * s * s;
  }
}

/* Adds the pair energy's gradient (coefficients applied, every term that is
** on) for r = x_j - x_i with d2 = |r|^2 < R^2: dE/dr to gr (so dE/dx_j;
** dE/dx_i is its negative), dE/dn_i to gi and dE/dn_j to gj, the normals
** taken as free vectors (the caller projects onto what moves them). */
void lw_ppair_grad(const lw_ppair_ctx *c, const double r[3], double d2, const double ni[3], const double nj[3],
                   double gr[3], double gi[3], double gj[3]);

#ifdef __cplusplus
}
#endif

#endif
