/*
** series.c -- statistics of a correlated series (series.h).
*/
#include "linewise/series.h"

#include <math.h>
#include <stdlib.h>

/* The window constant: Sokal's c (Madras and Sokal 1988, J. Stat. Phys. 50,
** 109): the bias of the cut sum falls like exp(-c) for an exponential
** decay, its variance grows like c. */
#define WINDOW_C 5.0

static double mean_of(const double *x, size_t n)
{
  double m = 0.0;
  for (size_t t = 0; t < n; t++) m += x[t];
  return m / (double)n;
}

double lw_series_tau(const double *x, size_t n_ser, size_t n, size_t *window)
{
  if (window) *window = 0;
  if (n < 2 || n_ser == 0) return 0.5;
  double *mean = malloc(n_ser * sizeof *mean);
  if (!mean) return NAN;
  double c0 = 0.0;
  for (size_t j = 0; j < n_ser; j++) {
    const double *s = x + j * n;
    mean[j] = mean_of(s, n);
    for (size_t t = 0; t < n; t++) c0 += (s[t] - mean[j]) * (s[t] - mean[j]);
  }
  double tau = 0.5;
  if (c0 > 0.0) {
    for (size_t k = 1; k < n / 2; k++) {
      double ck = 0.0;
      for (size_t j = 0; j < n_ser; j++) {
        const double *s = x + j * n;
        for (size_t t = 0; t + k < n; t++) ck += (s[t] - mean[j]) * (s[t + k] - mean[j]);
      }
      /* n / (n - k): each lag's sum has n - k terms, c0 has n */
      tau += ck / c0 * (double)n / (double)(n - k);
      if ((double)k >= WINDOW_C * tau) {
        if (window) *window = k;
        break;
      }
    }
  } else if (window) {
    *window = 1; /* nothing to correlate: the answer is exact */
  }
  free(mean);
  return tau;
}

void lw_series_stats_of(const double *x, size_t n, lw_series_stats *out)
{
  out->n = n;
  out->mean = n ? mean_of(x, n) : NAN;
  double v = 0.0;
  for (size_t t = 0; t < n; t++) v += (x[t] - out->mean) * (x[t] - out->mean);
  out->sd = n ? sqrt(v / (double)n) : NAN;
  out->tau = fmax(lw_series_tau(x, 1, n, &out->window), 0.5);
  out->n_eff = (double)n / (2.0 * out->tau);
  out->stderr_mean = n ? out->sd * sqrt(2.0 * out->tau / (double)n) : NAN;
  out->drift_z = 0.0;
  size_t h = n / 2;
  if (h >= 2) {
    double se2 = 0.0, m[2];
    for (int k = 0; k < 2; k++) {
      const double *s = x + (size_t)k * h;
      size_t len = k ? n - h : h;
      m[k] = mean_of(s, len);
      double vk = 0.0;
      for (size_t t = 0; t < len; t++) vk += (s[t] - m[k]) * (s[t] - m[k]);
      se2 += vk / (double)len * 2.0 * out->tau / (double)len;
    }
    if (se2 > 0.0) out->drift_z = (m[1] - m[0]) / sqrt(se2);
    else if (m[1] != m[0]) out->drift_z = m[1] > m[0] ? INFINITY : -INFINITY;
  }
}
