/*
** series.h -- statistics of a correlated series, such as a column of a
** Markov chain's trace: the mean, the spread, the integrated
** autocorrelation time and the standard error of the mean that follows
** from it (docs/NUMERICS.md, "Error bars from a trace").
**
** A chain's successive states are correlated, so n values carry the
** information of only about n / (2 tau) independent ones, tau the
** integrated autocorrelation time 1/2 + sum over lags t >= 1 of rho(t).
** The sum is cut at Sokal's self-consistent window, the first lag W with
** W >= 5 tau(W): the noise of rho(t) at large t would otherwise swamp it.
*/
#ifndef LINEWISE_SERIES_H
#define LINEWISE_SERIES_H

#include <stddef.h>

/* The integrated autocorrelation time, in steps of the series, of n_ser
** series of length n stored one after another (x[j n + t]), from their
** pooled autocorrelation (each about its own mean).  *window (NULL: not
** asked) is the lag W at which the window closed, or 0 when it did not
** close before n / 2: then tau is a lower bound, the series too short.
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
                         units of its standard error (both halves with the whole
                         series' tau): beyond about 4 the series is not stationary */
} lw_series_stats;

/* The statistics of one series of n values (n >= 1). */
void lw_series_stats_of(const double *x, size_t n, lw_series_stats *out);

#endif
