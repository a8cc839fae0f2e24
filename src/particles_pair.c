/* particles_pair.c -- the pair energy's constants (particles_pair.h). */
#include "linewise/particles_pair.h"

const char *const lw_pterm_names[LW_PTERM_COUNT] = {"lj", "coplanarity", "conormality", "cocircularity",
                                                    "gravity", "boundary", "chem"};

lw_status lw_ppair_init(lw_ppair_ctx *c, double r0, double range, int weight, double sigma, double sigma_normal,
                        const double alpha[LW_PTERM_PAIRS], lw_error *err)
{
  if (weight == LW_PWEIGHT_ANISO && sigma_normal > sigma)
    return lw_error_set(err, LW_EINPUT, "expected sigma_normal <= sigma for weight = aniso (the seed's b <= a), "
                                        "got %g > %g", sigma_normal, sigma);
  *c = (lw_ppair_ctx){.r0 = r0, .range = range * r0, .weight = weight};
  c->range2 = c->range * c->range;
  c->inv_range2 = 1.0 / c->range2;
  double a = sigma * r0, b = (weight == LW_PWEIGHT_ANISO ? sigma_normal : sigma) * r0;
  c->ia = 0.5 / (a * a);
  c->ib = 0.5 / (b * b);
  c->g_R = exp(-c->range2 * c->ia);
  c->g_scale = 1.0 / (1.0 - c->g_R);
  double s = 1.0 / (range * range), s6 = s * s * s;
  c->lj_shift = s6 * s6 - 2.0 * s6;
  for (int k = 0; k < LW_PTERM_PAIRS; k++) {
    c->alpha[k] = alpha[k];
    if (alpha[k] != 0.0) c->on = 1;
  }
  c->weighted = alpha[LW_PTERM_PLANAR] != 0.0 || alpha[LW_PTERM_NORMAL] != 0.0 || alpha[LW_PTERM_CIRCULAR] != 0.0;
  return LW_OK;
}

/* The weight's gradient: dw/dr into wr, dw/dn_i into wi, dw/dn_j into wj
** (docs/NUMERICS.md, "Forces and torques"); returns w. */
static double weight_grad(const lw_ppair_ctx *c, const double r[3], double d2, const double ni[3],
                          const double nj[3], double zi, double zj, double wr[3], double wi[3], double wj[3])
{
  for (int k = 0; k < 3; k++) wr[k] = wi[k] = wj[k] = 0.0;
  switch (c->weight) {
  case LW_PWEIGHT_POLY: {
    double t = 1.0 - d2 * c->inv_range2, dw = -6.0 * t * t * c->inv_range2; /* dw/dd2 times 2 */
    for (int k = 0; k < 3; k++) wr[k] = dw * r[k];
    return t * t * t;
  }
  case LW_PWEIGHT_GAUSS: {
    double e = exp(-d2 * c->ia), dw = -2.0 * c->ia * e * c->g_scale;
    for (int k = 0; k < 3; k++) wr[k] = dw * r[k];
    return (e - c->g_R) * c->g_scale;
  }
  default: { /* aniso: each end's g clipped at 0 has no slope where it is clipped */
    double w = 0.0, h = 0.5 * c->g_scale;
    const double *n[2] = {ni, nj};
    double z[2] = {zi, zj}, *wn[2] = {wi, wj};
    for (int e = 0; e < 2; e++) {
      double z2 = z[e] * z[e], ge = exp(-(d2 - z2) * c->ia - z2 * c->ib);
      if (!(ge - c->g_R > 0.0)) continue;
      w += h * (ge - c->g_R);
      double dz = h * ge * 2.0 * z[e] * (c->ia - c->ib), dd = -h * ge * 2.0 * c->ia;
      for (int k = 0; k < 3; k++) {
        wr[k] += dd * r[k] + dz * n[e][k];
        wn[e][k] = dz * r[k];
      }
    }
    return w;
  }
  }
}

void lw_ppair_grad(const lw_ppair_ctx *c, const double r[3], double d2, const double ni[3], const double nj[3],
                   double gr[3], double gi[3], double gj[3])
{
  if (c->alpha[LW_PTERM_LJ] != 0.0) {
    double s = c->r0 * c->r0 / d2, s6 = s * s * s;
    double f = c->alpha[LW_PTERM_LJ] * -12.0 * s6 * (s6 - 1.0) / d2; /* 2 dphi/dd2 */
    for (int k = 0; k < 3; k++) gr[k] += f * r[k];
  }
  if (!c->weighted) return;
  double zi = lw_v3_dot(ni, r), zj = lw_v3_dot(nj, r), s = zi + zj;
  double wr[3], wi[3], wj[3];
  double w = weight_grad(c, r, d2, ni, nj, zi, zj, wr, wi, wj);
  const double ap = c->alpha[LW_PTERM_PLANAR], an = c->alpha[LW_PTERM_NORMAL], ac = c->alpha[LW_PTERM_CIRCULAR];
  double dn[3] = {ni[0] - nj[0], ni[1] - nj[1], ni[2] - nj[2]};
  /* U = aP (zi^2 + zj^2) + aN |ni - nj|^2 + aC (zi + zj)^2, E = w U */
  double u = ap * (zi * zi + zj * zj) + an * lw_v3_dot(dn, dn) + ac * s * s;
  for (int k = 0; k < 3; k++) {
    double ur = 2.0 * (ap * (zi * ni[k] + zj * nj[k]) + ac * s * (ni[k] + nj[k]));
    double ui = 2.0 * (ap * zi * r[k] + an * dn[k] + ac * s * r[k]);
    double uj = 2.0 * (ap * zj * r[k] - an * dn[k] + ac * s * r[k]);
    gr[k] += u * wr[k] + w * ur;
    gi[k] += u * wi[k] + w * ui;
    gj[k] += u * wj[k] + w * uj;
  }
}
