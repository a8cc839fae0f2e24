/* tempering.c -- ladder, exchanges, round trips, ladder tuning (tempering.h). */
#include "linewise/tempering.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/mc.h"

lw_tempering *lw_tempering_new(int n, const double *ladder, unsigned long seed, lw_error *err)
{
  if (n < 2 || n > LW_TEMPERING_MAX) {
    lw_error_set(err, LW_EINPUT, "tempering needs 2 to %d replicas, got %d", LW_TEMPERING_MAX, n);
    return NULL;
  }
  for (int k = 0; k < n; k++)
    if (!(ladder[k] > 0.0) || !isfinite(ladder[k]) || (k > 0 && !(ladder[k] > ladder[k - 1]))) {
      lw_error_set(err, LW_EINPUT, "tempering ladder: temperatures must be positive and increasing (rung %d: %g)",
                   k, ladder[k]);
      return NULL;
    }
  lw_tempering *pt = calloc(1, sizeof *pt);
  if (!pt) goto nomem;
  pt->n = n;
  pt->ladder = malloc((size_t)n * sizeof *pt->ladder);
  pt->at = malloc((size_t)n * sizeof *pt->at);
  pt->label = calloc((size_t)n, sizeof *pt->label);
  pt->tried = calloc((size_t)n, sizeof *pt->tried);
  pt->accepted = calloc((size_t)n, sizeof *pt->accepted);
  pt->win_tried = calloc((size_t)n, sizeof *pt->win_tried);
  pt->win_accepted = calloc((size_t)n, sizeof *pt->win_accepted);
  pt->rng = lw_rng_new();
  if (!pt->ladder || !pt->at || !pt->label || !pt->tried || !pt->accepted || !pt->win_tried ||
      !pt->win_accepted || !pt->rng)
    goto nomem;
  memcpy(pt->ladder, ladder, (size_t)n * sizeof *ladder);
  for (int k = 0; k < n; k++) pt->at[k] = k;
  pt->label[0] = 1; /* the coldest replica starts going up */
  gsl_rng_set(pt->rng, seed);
  return pt;
nomem:
  lw_tempering_free(pt);
  lw_error_set(err, LW_ENOMEM, "out of memory for %d replicas", n);
  return NULL;
}

void lw_tempering_free(lw_tempering *pt)
{
  if (!pt) return;
  free(pt->ladder);
  free(pt->at);
  free(pt->label);
  free(pt->tried);
  free(pt->accepted);
  free(pt->win_tried);
  free(pt->win_accepted);
  if (pt->rng) gsl_rng_free(pt->rng);
  free(pt);
}

void lw_tempering_geometric(double *ladder, int n, double t_min, double t_max)
{
  /* (a ratio past the doubles, 1e300 / 1e-10, in logarithms: its pow made
  ** every rung inf) */
  const double ratio = t_max / t_min, span = log(t_max) - log(t_min);
  for (int k = 0; k < n; k++) {
    const double f = n > 1 ? (double)k / (double)(n - 1) : 0.0;
    ladder[k] = isfinite(ratio) ? t_min * pow(ratio, f) : exp(log(t_min) + f * span);
  }
  ladder[0] = t_min; /* the ends exactly, whatever pow or exp rounds to */
  if (n > 1) ladder[n - 1] = t_max;
}

/* log of the acceptance ratio of swapping rungs k and k+1 (k the colder on
** the ladder).  A rung at T = 0 has beta = inf: the swap is then accepted
** only if it does not raise the cold side's energy.  So also where a schedule
** has brought every rung to 0, the limit of the ladder's rule as T falls:
** a free swap there handed the coldest rung, whose state the run reports,
** whichever rung's came, the worst of three in a helper's run.  Equal
** temperatures above 0 (a rounding) or energies make the swap free. */
static double log_ratio(double tk, double tk1, double ek, double ek1)
{
  double de = ek - ek1;
  if (de == 0.0) return 0.0;
  if (tk == tk1) return tk > 0.0 ? 0.0 : de > 0.0 ? INFINITY : -INFINITY;
  double bk = tk > 0.0 ? 1.0 / tk : INFINITY, bk1 = tk1 > 0.0 ? 1.0 / tk1 : INFINITY;
  double x = (bk - bk1) * de;
  /* rungs below 1 / DBL_MAX (a schedule may end at 1e-310) have 1/T
  ** overflow on both: inf - inf refused every swap there */
  if (isnan(x) && tk > 0.0 && tk1 > 0.0) x = de * ((tk1 - tk) / tk) / tk1;
  return isnan(x) ? -INFINITY : x;
}

static void mark_ends(lw_tempering *pt)
{
  int cold = pt->at[0], hot = pt->at[pt->n - 1];
  if (pt->label[cold] == -1) pt->round_trips++;
  pt->label[cold] = 1;
  if (pt->label[hot] == 1) pt->label[hot] = -1;
}

int lw_tempering_exchange(lw_tempering *pt, const double *energy, const double *temp, int *swapped)
{
  int n = pt->n, swaps = 0;
  if (swapped) memset(swapped, 0, (size_t)(n - 1) * sizeof *swapped);
  for (int k = (int)(pt->steps & 1); k + 1 < n; k += 2) {
    double u = gsl_rng_uniform(pt->rng);
    double x = log_ratio(temp[k], temp[k + 1], energy[k], energy[k + 1]);
    pt->tried[k]++;
    pt->win_tried[k]++;
    if (x >= 0.0 || u < exp(x)) {
      pt->accepted[k]++;
      pt->win_accepted[k]++;
      int t = pt->at[k];
      pt->at[k] = pt->at[k + 1];
      pt->at[k + 1] = t;
      if (swapped) swapped[k] = 1;
      swaps++;
    }
  }
  pt->steps++;
  mark_ends(pt);
  return swaps;
}

double lw_tempering_tune_gain(long updates) { return updates > 4 ? 4.0 / (double)updates : 1.0; }

void lw_tempering_tune(lw_tempering *pt, double gain)
{
  int n = pt->n;
  double mean = 0.0;
  for (int k = 0; k + 1 < n; k++) {
    if (!pt->win_tried[k]) return; /* not every pair seen yet: wait */
    mean += (double)pt->win_accepted[k] / (double)pt->win_tried[k];
  }
  mean /= (double)(n - 1);
  /* The factor is bounded (e^-1 .. e), so a pair that never swaps cannot
  ** collapse the ladder in one update; renormalising keeps both ends. */
  double gap[LW_TEMPERING_MAX], total = 0.0, span = log(pt->ladder[n - 1] / pt->ladder[0]);
  for (int k = 0; k + 1 < n; k++) {
    double a = (double)pt->win_accepted[k] / (double)pt->win_tried[k];
    gap[k] = log(pt->ladder[k + 1] / pt->ladder[k]) * exp(gain * (a - mean));
    total += gap[k];
  }
  double u = log(pt->ladder[0]);
  for (int k = 1; k + 1 < n; k++) {
    u += gap[k - 1] * span / total;
    pt->ladder[k] = exp(u);
  }
  memset(pt->win_tried, 0, (size_t)n * sizeof *pt->win_tried);
  memset(pt->win_accepted, 0, (size_t)n * sizeof *pt->win_accepted);
}

void lw_tempering_reset_stats(lw_tempering *pt)
{
  size_t sz = (size_t)pt->n * sizeof(unsigned long);
  memset(pt->tried, 0, sz);
  memset(pt->accepted, 0, sz);
  memset(pt->win_tried, 0, sz);
  memset(pt->win_accepted, 0, sz);
  memset(pt->label, 0, (size_t)pt->n * sizeof *pt->label);
  pt->round_trips = 0;
  mark_ends(pt);
}
