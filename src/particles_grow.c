/* particles_grow.c -- births and deaths of oriented particles (particles_grow.h). */
#include "linewise/particles_grow.h"

#include <gsl/gsl_math.h>
#include <math.h>
#include <string.h>

#include "linewise/particles_geom.h"
#include "linewise/system.h"

/* The annulus times the slab: the volume over which an anchor spreads its
** births, in r0^3. */
static double spread_volume(void)
{
  return M_PI * (LW_GROW_OUTER * LW_GROW_OUTER - LW_GROW_INNER * LW_GROW_INNER) * 2.0 * LW_GROW_SLAB;
}

/* The von Mises-Fisher density at cosine c against the sphere's normalised
** area measure (c is uniform on [-1, 1] under it). */
static double vmf(double c)
{
  const double k = LW_GROW_KAPPA;
  return k * exp(k * (c - 1.0)) * 2.0 / -expm1(-2.0 * k);
}

/* A unit basis t1, t2 of the plane normal to n, a function of n alone. */
static void tangents(const double n[3], double t1[3], double t2[3])
{
  const double e[3] = {fabs(n[0]) < 0.9 ? 1.0 : 0.0, fabs(n[0]) < 0.9 ? 0.0 : 1.0, 0.0};
  lw_v3_cross(e, n, t1);
  double s = 1.0 / sqrt(lw_v3_dot(t1, t1));
  for (int k = 0; k < 3; k++) t1[k] *= s;
  lw_v3_cross(n, t1, t2);
}

typedef struct {
  const lw_particles *p;
  const double *n; /* the new particle's normal */
  double sum;
} density_ctx;

/* Anchor j's density at the new particle, r = x_j - x. */
static void anchor(void *ctx, size_t skip, size_t j, const double r[3], double d2)
{
  density_ctx *a = ctx;
  const double *nj = a->p->nrm + 3 * j, r0 = a->p->setup->pair.r0;
  double h = -lw_v3_dot(r, nj) / r0, rho2 = d2 / (r0 * r0) - h * h;
  if (fabs(h) > LW_GROW_SLAB || rho2 < LW_GROW_INNER * LW_GROW_INNER || rho2 > LW_GROW_OUTER * LW_GROW_OUTER) return;
  a->sum += vmf(lw_v3_dot(a->n, nj)) / spread_volume();
}

/* g: the density of a birth proposing a particle at x with normal n from
** the state's anchors other than `skip` (UINT32_MAX: none), per r0^-3 and
** per unit of the rotation group's normalised measure. */
static double birth_density(const lw_particles *p, uint32_t skip, const double x[3], const double n[3])
{
  size_t anchors = p->n - (skip < p->n ? 1 : 0);
  if (!anchors) return 0.0;
  density_ctx a = {p, n, 0.0};
  lw_particles_near(p, skip, x, anchor, &a);
  return a.sum / (double)anchors;
}

/* The refusal or the identity: nothing to commit. */
static double nothing(lw_particles_prop *pr, double dE, int *forbidden, int why)
{
  pr->identity = 1;
  pr->log_ratio = 0.0;
  for (int t = 0; t < LW_PTERM_COUNT; t++) pr->dterm[t] = 0.0;
  if (forbidden) *forbidden = why;
  return pr->dE = dE;
}

static double birth(const lw_particles *p, lw_particles_prop *pr, gsl_rng *rng, int *forbidden)
{
  const lw_particles_setup *s = p->setup;
  if (p->n >= s->max_count) return nothing(pr, INFINITY, forbidden, LW_PROPOSE_IRREGULAR);
  /* none to be born beside (the last one's death is refused by its
  ** reverse, so only a test's walk gets here): no proposal */
  if (p->n == 0) return nothing(pr, 0.0, forbidden, 0);
  size_t j = gsl_rng_uniform_int(rng, p->n);
  const double *xj = p->x + 3 * j, *nj = p->nrm + 3 * j, r0 = s->pair.r0;
  double t1[3], t2[3];
  tangents(nj, t1, t2);
  const double a2 = LW_GROW_INNER * LW_GROW_INNER, b2 = LW_GROW_OUTER * LW_GROW_OUTER;
  double rho = r0 * sqrt(a2 + gsl_rng_uniform(rng) * (b2 - a2)), phi = 2.0 * M_PI * gsl_rng_uniform(rng);
  double h = r0 * LW_GROW_SLAB * (2.0 * gsl_rng_uniform(rng) - 1.0);
  for (int k = 0; k < 3; k++) pr->x[k] = xj[k] + rho * (cos(phi) * t1[k] + sin(phi) * t2[k]) + h * nj[k];
  /* the normal: its cosine to n_j by inversion of the vMF's distribution,
  ** u in (0, 1] so that the logarithm is finite */
  const double kappa = LW_GROW_KAPPA;
  double u = 1.0 - gsl_rng_uniform(rng), psi = 2.0 * M_PI * gsl_rng_uniform(rng), spin = 2.0 * M_PI * gsl_rng_uniform(rng);
  double c = 1.0 + log(u + (1.0 - u) * exp(-2.0 * kappa)) / kappa;
  if (c < -1.0) c = -1.0;
  double sn = sqrt(fmax(0.0, 1.0 - c * c)), n[3], qn[4];
  for (int k = 0; k < 3; k++) n[k] = c * nj[k] + sn * (cos(psi) * t1[k] + sin(psi) * t2[k]);
  lw_quat_from_normal(n, qn);
  const double qs[4] = {cos(0.5 * spin), 0.0, 0.0, sin(0.5 * spin)};
  lw_quat_mul(qn, qs, pr->q);
  lw_quat_normalise(pr->q);
  lw_quat_normal(pr->q, pr->n);
  pr->k = (uint32_t)p->n;
  pr->identity = 0;
  double e[LW_PTERM_COUNT] = {0};
  if (lw_particles_site_energy(p, UINT32_MAX, pr->x, pr->n, e))
    return nothing(pr, INFINITY, forbidden, LW_PROPOSE_IRREGULAR);
  e[LW_PTERM_CHEM] = s->chem;
  double dE = 0.0;
  for (int t = 0; t < LW_PTERM_COUNT; t++) dE += pr->dterm[t] = e[t];
  /* (g is per r0^3 already, as the reference measure counts volume) */
  double g = birth_density(p, UINT32_MAX, pr->x, pr->n);
  pr->log_ratio = log(s->death) - log((double)(p->n_loose + 1)) - log(s->birth) - log(g);
  return pr->dE = dE;
}

static double death(const lw_particles *p, lw_particles_prop *pr, gsl_rng *rng, int *forbidden)
{
  const lw_particles_setup *s = p->setup;
  if (!p->n_loose) return nothing(pr, 0.0, forbidden, 0);
  uint32_t k = p->loose[gsl_rng_uniform_int(rng, p->n_loose)];
  const double *x = p->x + 3 * (size_t)k, *n = p->nrm + 3 * (size_t)k;
  pr->k = k;
  pr->identity = 0;
  double e[LW_PTERM_COUNT] = {0};
  lw_particles_site_energy(p, k, x, n, e); /* it is inside: the state is allowed */
  e[LW_PTERM_CHEM] = s->chem;
  double dE = 0.0;
  for (int t = 0; t < LW_PTERM_COUNT; t++) dE += pr->dterm[t] = -e[t];
  double g = birth_density(p, k, x, n);
  pr->log_ratio = log(s->birth) + log(g) - log(s->death) + log((double)p->n_loose);
  return pr->dE = dE;
}

double lw_particles_propose_grow(const lw_particles *p, lw_particles_prop *pr, int kind, gsl_rng *rng,
                                 int *forbidden)
{
  pr->kind = kind;
  if (forbidden) *forbidden = 0;
  return kind == LW_PMOVE_BIRTH ? birth(p, pr, rng, forbidden) : death(p, pr, rng, forbidden);
}
