/* sdt.c -- exact Euclidean distance transforms of pixel masks (sdt.h). */
#include "linewise/sdt.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* d[q] = min over p of (q - p)^2 + f[p], f[p] = HUGE_VAL meaning "no
** sample here".  The parabolas of the finite samples are kept as a lower
** envelope: v[k] is the apex of the k-th parabola of the envelope and z[k]
** where it starts to be the lowest one.  A new parabola removes from the
** top those it beats at their own start.  v and z need n and n + 1 slots. */
static void edt_1d(const double *f, int n, double *d, int *v, double *z)
{
  int k = -1;
  for (int q = 0; q < n; q++) {
    if (f[q] == HUGE_VAL) continue;
    double fq = f[q] + (double)q * q, s = -HUGE_VAL;
    while (k >= 0) {
      int p = v[k];
      s = (fq - (f[p] + (double)p * p)) / (2.0 * (q - p));
      if (s > z[k]) break;
      k--;
    }
    if (k < 0) s = -HUGE_VAL;
    v[++k] = q;
    z[k] = s;
  }
  if (k < 0) {
    for (int q = 0; q < n; q++) d[q] = HUGE_VAL;
    return;
  }
  z[k + 1] = HUGE_VAL;
  for (int q = 0, j = 0; q < n; q++) {
    while (z[j + 1] < q) j++;
    double dq = q - v[j];
    d[q] = dq * dq + f[v[j]];
  }
}

lw_status lw_sdt_squared(const unsigned char *feature, int w, int h, double *out, lw_error *err)
{
  int n = w > h ? w : h;
  double *f = calloc((size_t)n, sizeof *f), *d = calloc((size_t)n, sizeof *d);
  double *z = malloc(((size_t)n + 1) * sizeof *z);
  int *v = malloc((size_t)n * sizeof *v);
  if (!f || !d || !z || !v) {
    free(f);
    free(d);
    free(z);
    free(v);
    return lw_error_set(err, LW_ENOMEM, "out of memory for a distance transform of %d x %d pixels", w, h);
  }
  const size_t W = (size_t)w;
  for (int i = 0; i < w; i++) {
    for (int j = 0; j < h; j++) f[j] = feature[(size_t)j * W + (size_t)i] ? 0.0 : HUGE_VAL;
    edt_1d(f, h, d, v, z);
    for (int j = 0; j < h; j++) out[(size_t)j * W + (size_t)i] = d[j];
  }
  for (int j = 0; j < h; j++) {
    double *row = out + (size_t)j * W;
    memcpy(f, row, W * sizeof *f);
    edt_1d(f, w, row, v, z);
  }
  free(f);
  free(d);
  free(z);
  free(v);
  return LW_OK;
}

lw_grid2d *lw_sdt_grid(const unsigned char *inside, int w, int h, const lw_image_place *pl, lw_error *err)
{
  const int W = w + 2, H = h + 2;
  const size_t n = (size_t)W * (size_t)H;
  size_t count = 0;
  for (size_t k = 0; k < (size_t)w * (size_t)h; k++) count += inside[k] != 0;
  if (!count) {
    lw_error_set(err, LW_EINPUT, "the mask has no inside pixel");
    return NULL;
  }
  /* node (i, j) of the padded grid is the centre of pixel (i - 1, j - 1) */
  lw_grid2d *g = lw_grid2d_new(W, H, 1, pl->x0 - 0.5 * pl->pixel, pl->y0 - 0.5 * pl->pixel, pl->pixel,
                               pl->pixel, err);
  if (!g) return NULL;
  unsigned char *in = calloc(n, 1), *out = malloc(n);
  double *din = malloc(n * sizeof *din);
  if (!in || !out || !din) {
    lw_error_set(err, LW_ENOMEM, "out of memory for the mask's distance transform (%d x %d pixels)", w, h);
    goto fail;
  }
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) in[(size_t)(j + 1) * W + (size_t)(i + 1)] = inside[(size_t)j * (size_t)w + (size_t)i] != 0;
  for (size_t k = 0; k < n; k++) out[k] = !in[k];
  if (lw_sdt_squared(out, W, H, g->data, err) || lw_sdt_squared(in, W, H, din, err)) goto fail;
  for (size_t k = 0; k < n; k++)
    g->data[k] = pl->pixel * (in[k] ? 0.5 - sqrt(g->data[k]) : sqrt(din[k]) - 0.5);
  free(in);
  free(out);
  free(din);
  return g;
fail:
  free(in);
  free(out);
  free(din);
  lw_grid2d_free(g);
  return NULL;
}
