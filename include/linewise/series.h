/*
** series.h -- statistics of a correlated series, such as a column of a
** Markov chain's trace: the mean, the spread, the integrated
** autocorrelation time and the standard error of the mean that follows
** from it (docs/NUMERICS.md, "Error bars from a trace").
**
** A chain's successive states are correlated, so n values carry the
** information of only about n / (2 tau) independent ones, tau the
** integrated autocorrelation time 1/2 + sum over lags t >= 1 of rho(t).
** The sum is taken by Geyer's initial monotone sequence: pairs of lags
** while their sum stays positive, each capped by the pair before, since the
** noise of rho(t) at large t would otherwise swamp it.  Its window (the
** lags summed) reaches into a slow mode's plateau, which Sokal's window
** (cut at W >= 5 tau(W), until 2026-12-07) closed before.
*/
#ifndef LINEWISE_SERIES_H
#define LINEWISE_SERIES_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The integrated autocorrelation time, in steps of the series, of n_ser
** series of length n stored one after another (x[j n + t]), from their
** pooled autocorrelation (each about its own mean).  *window (NULL: not
** asked) is the count of lags summed, W (the window closed there), or 0
** when the sum ran to n / 2: then tau is a lower bound, the series too
** short.
** A series without spread (or n < 2) gives 0.5. */
double lw_series_tau(const double *x, size_t n_ser, size_t n, size_t *window);

typedef struct {
  size_t n;           /* values */
  double mean;
  double sd;          /* standard deviation (the 1/n moment) */
  double tau;         /* integrated autocorrelation time, steps; at least 0.5 (an
                         anticorrelated series is not credited with more than n
                         independent values) */
  size_t window;      /* as lw_series_tau's: 0 when the window did not close */
  double n_eff;       /* n / (2 tau) */
  double stderr_mean; /* sd sqrt(2 tau / n) */
  double drift_z;     /* the difference of the first and second halves' means in
                         units of its standard error (each half with its own tau):
                         beyond about 4 the series is not stationary,
                         or (with batch_ratio past its warning) has a slow mode;
                         NAN under 20 values */
  double batch_ratio; /* the standard error from the means of LW_SERIES_BATCHES
                         batches over stderr_mean: about 1 where tau is right;
                         above LW_SERIES_BATCH_WARN a slower mode the sum missed
                         (NAN under 2 values a batch, or without spread) */
} lw_series_stats;

/* The batch-means check: the standard error from 20 batch means is itself
** uncertain by 1 / sqrt(2 x 19) = 16 %, so where tau is right it exceeds
** 1.5 times tau's by chance with chi-square probability 0.0014 (19
** degrees of freedom at 19 x 1.5^2).  A refined wire's energy read 1.5
** times the error bar of Sokal's window (until 2026-12-07) this way, and
** one seed +2.7 sigma off equipartition by that window's. */
#define LW_SERIES_BATCHES 20
#define LW_SERIES_BATCH_WARN 1.5

/* The statistics of one series of n values (n >= 1). */
void lw_series_stats_of(const double *x, size_t n, lw_series_stats *out);

#ifdef __cplusplus
}
#endif

#endif
