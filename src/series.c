/*
** series.c -- statistics of a correlated series (series.h).
*/
#include "linewise/series.h"

#include <gsl/gsl_fft_halfcomplex.h>
#include <gsl/gsl_fft_real.h>
#include <math.h>
#include <stdlib.h>

/* Lags summed directly, O(n) each; a longer sum takes every lag by FFT.
** Short sums (tau up to about 15) stay exact sums. */
#define DIRECT_LAGS 64

static double mean_of(const double *x, size_t n)
{
  double m = 0.0;
  for (size_t t = 0; t < n; t++) m += x[t];
  return m / (double)n;
}

/* The lagged sums c(k) = sum_t (x_t - m)(x_{t+k} - m), k < n, of n_ser
** series pooled, into c (n values), by FFT: the series zero-padded to a
** power of two at least 2n, so that the circular correlation is the linear
** one.  0 on success, -1 when memory runs out. */
static int lagged_sums_fft(const double *x, size_t n_ser, size_t n, const double *mean, double *c)
{
  size_t m = 1;
  while (m < 2 * n) m <<= 1;
  double *d = malloc(m * sizeof *d);
  if (!d) return -1;
  for (size_t k = 0; k < n; k++) c[k] = 0.0;
  for (size_t j = 0; j < n_ser; j++) {
    for (size_t t = 0; t < m; t++) d[t] = t < n ? x[j * n + t] - mean[j] : 0.0;
    gsl_fft_real_radix2_transform(d, 1, m);
    /* the halfcomplex spectrum becomes its power, whose inverse is the
    ** autocorrelation (GSL's inverse divides by m) */
    d[0] *= d[0];
    d[m / 2] *= d[m / 2];
    for (size_t i = 1; i < m / 2; i++) {
      d[i] = d[i] * d[i] + d[m - i] * d[m - i];
      d[m - i] = 0.0;
    }
    gsl_fft_halfcomplex_radix2_inverse(d, 1, m);
    for (size_t k = 0; k < n; k++) c[k] += d[k];
  }
  free(d);
  return 0;
}

/* The autocorrelation at lag k of the n_ser series pooled: c(k) / c0,
** scaled by n / (n - k) since its sum has n - k terms and c0 n.  Past
** DIRECT_LAGS every lag is taken at once by FFT into *c (made on first
** use); NAN where memory runs out. */
static double autocorrelation(const double *x, size_t n_ser, size_t n, const double *mean, double c0, size_t k,
                              double **c)
{
  if (!k) return 1.0;
  double ck = 0.0;
  if (k <= DIRECT_LAGS) {
    for (size_t j = 0; j < n_ser; j++) {
      const double *s = x + j * n;
      for (size_t t = 0; t + k < n; t++) ck += (s[t] - mean[j]) * (s[t + k] - mean[j]);
    }
  } else {
    if (!*c && (!(*c = malloc(n * sizeof **c)) || lagged_sums_fft(x, n_ser, n, mean, *c))) return NAN;
    ck = (*c)[k];
  }
  return ck / c0 * (double)n / (double)(n - k);
}

double lw_series_tau(const double *x, size_t n_ser, size_t n, size_t *window)
{
  if (window) *window = 0;
  if (n < 2 || n_ser == 0) return 0.5;
  double *mean = malloc(n_ser * sizeof *mean), *c = NULL;
  if (!mean) return NAN;
  double c0 = 0.0;
  for (size_t j = 0; j < n_ser; j++) {
    const double *s = x + j * n;
    mean[j] = mean_of(s, n);
    for (size_t t = 0; t < n; t++) c0 += (s[t] - mean[j]) * (s[t] - mean[j]);
  }
  double tau = 0.5;
  /* (values so large that their squares overflow: no tau to take, and NAN
  ** is kept for out of memory) */
  if (c0 > 0.0 && isfinite(c0)) {
    /* Geyer's initial monotone sequence (Geyer 1992, Statist. Sci. 7, 473):
    ** for a reversible chain the sums of neighbouring lags G_k = rho(2k) +
    ** rho(2k + 1) are positive and decreasing, so the sum runs while their
    ** estimates stay positive, each capped by the one before, and tau =
    ** sum G_k - 1/2.  Sokal's window (cut at W >= 5 tau(W)) closed at the
    ** plateau of a slow mode of small weight before summing it: a
    ** worm-like chain's energy read tau 15 sweeps of some 35, its error
    ** bars 1.5 times too small. */
    double sum = 0.0, before = INFINITY;
    for (size_t k = 0;; k++) {
      if (2 * k + 1 >= n / 2) { /* positive to half the rows: a bound */
        tau = sum - 0.5;
        break;
      }
      const double g = autocorrelation(x, n_ser, n, mean, c0, 2 * k, &c) +
                       autocorrelation(x, n_ser, n, mean, c0, 2 * k + 1, &c);
      if (isnan(g)) {
        tau = NAN;
        break;
      }
      if (g <= 0.0) {
        tau = sum - 0.5;
        if (window) *window = 2 * k > 0 ? 2 * k : 1;
        break;
      }
      before = fmin(g, before);
      sum += before;
    }
  } else if (window) {
    *window = 1; /* nothing to correlate: the answer is exact */
  }
  free(c);
  free(mean);
  return tau;
}

void lw_series_stats_of(const double *x, size_t n, lw_series_stats *out)
{
  out->n = n;
  /* rows of one value have no spread, exactly: their mean is that value (a
  ** sum of 600 copies of 0.2074103559 is not, by 1e-16, whose spread gave
  ** a tau of 1248 and a warning) */
  size_t same = 1;
  while (same < n && x[same] == x[0]) same++;
  out->mean = !n ? NAN : same == n ? x[0] : mean_of(x, n);
  double v = 0.0;
  for (size_t t = 0; t < n; t++) v += (x[t] - out->mean) * (x[t] - out->mean);
  /* one row has a mean and no spread to speak of: its error bar is unknown,
  ** not 0 */
  out->sd = n > 1 ? sqrt(v / (double)n) : NAN;
  if (n && same == n) { /* nothing to correlate: exact (its own mean of the rows would not be) */
    out->tau = 0.5;
    out->window = 1;
  } else {
    /* NAN (out of memory) stays: fmax would take it for 0.5, and the error
    ** bars would shrink without a word */
    const double tau = lw_series_tau(x, 1, n, &out->window);
    out->tau = isnan(tau) ? NAN : fmax(tau, 0.5);
  }
  out->n_eff = (double)n / (2.0 * out->tau);
  out->stderr_mean = n > 1 ? out->sd * sqrt(2.0 * out->tau / (double)n) : NAN;
  /* halves of a few rows compare nothing (two rows a half warned of a
  ** drift of 14.7 standard errors): 10 rows a half at least.  Each half's
  ** error bar is of its own tau: the whole series' sums a drift between
  ** them as a slow correlation (a step of half an sd read 2.8 standard
  ** errors where it is 11) */
  out->drift_z = NAN;
  size_t h = n / 2;
  if (h >= 10) {
    double se2 = 0.0, m[2];
    for (int k = 0; k < 2; k++) {
      const double *s = x + (size_t)k * h;
      size_t len = k ? n - h : h;
      m[k] = mean_of(s, len);
      double vk = 0.0;
      for (size_t t = 0; t < len; t++) vk += (s[t] - m[k]) * (s[t] - m[k]);
      const double tau_h = lw_series_tau(s, 1, len, NULL);
      se2 += vk / (double)len * 2.0 * (isnan(tau_h) ? out->tau : fmax(tau_h, 0.5)) / (double)len;
    }
    out->drift_z = 0.0;
    if (se2 > 0.0) out->drift_z = (m[1] - m[0]) / sqrt(se2);
    else if (m[1] != m[0]) out->drift_z = m[1] > m[0] ? INFINITY : -INFINITY;
  }
  out->batch_ratio = NAN;
  const size_t len = n / LW_SERIES_BATCHES; /* the first B len values */
  if (len >= 2 && out->stderr_mean > 0.0) {
    double b[LW_SERIES_BATCHES], mb = 0.0, vb = 0.0;
    for (int k = 0; k < LW_SERIES_BATCHES; k++) mb += (b[k] = mean_of(x + (size_t)k * len, len)) / LW_SERIES_BATCHES;
    for (int k = 0; k < LW_SERIES_BATCHES; k++) vb += (b[k] - mb) * (b[k] - mb) / (LW_SERIES_BATCHES - 1);
    out->batch_ratio = sqrt(vb / LW_SERIES_BATCHES) / out->stderr_mean;
  }
}
