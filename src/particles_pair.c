/* particles_pair.c -- the pair energy's constants (particles_pair.h). */
#include "linewise/particles_pair.h"

const char *const lw_pterm_names[LW_PTERM_COUNT] = {"lj", "coplanarity", "conormality", "cocircularity",
                                                    "gravity", "boundary"};

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
