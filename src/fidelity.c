/* fidelity.c -- rendered lines against a target tone: blur, MSE, SSIM
** (fidelity.h). */
#include "linewise/fidelity.h"

#include <cairo.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/output.h"

static int positive(double x) { return isfinite(x) && x > 0; }

static lw_status check_raster(const lw_grid2d *t, lw_error *err)
{
  if (!t || t->ncomp != 1 || t->nx < 1 || t->ny < 1 || !positive(t->hx) || !positive(t->hy) || !t->data)
    return lw_error_set(err, LW_EINPUT, "fidelity: the tone raster must have one value per pixel");
  return LW_OK;
}

/* The splines as paths of one pen (strokes.h); NULL and err set when one is
** not finite. */
static lw_strokes *as_strokes(const lw_splines *sp, lw_error *err)
{
  if (!lw_splines_finite(sp)) {
    lw_error_set(err, LW_EINPUT, "fidelity: a spline is not finite");
    return NULL;
  }
  return lw_strokes_from_plot(sp, NULL, err);
}

lw_status lw_fidelity_render(const lw_splines *sp, const lw_grid2d *tone, double pen_width_mm, double *ink,
                             lw_error *err)
{
  lw_strokes *st = as_strokes(sp, err);
  if (!st) return err ? err->code : LW_EINPUT;
  lw_status s = lw_fidelity_render_strokes(st, -1, tone, pen_width_mm, ink, err);
  lw_strokes_free(st);
  return s;
}

lw_status lw_fidelity_render_strokes(const lw_strokes *st, int pen, const lw_grid2d *tone, double pen_width_mm,
                                     double *ink, lw_error *err)
{
  lw_status s = check_raster(tone, err);
  if (s) return s;
  if (!positive(pen_width_mm))
    return lw_error_set(err, LW_EINPUT, "fidelity: pen width %g mm: expected a positive number", pen_width_mm);
  /* A8: the alpha channel alone is the ink coverage. */
  cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_A8, tone->nx, tone->ny);
  cairo_t *cr = cairo_create(surf);
  if (cairo_status(cr)) {
    s = lw_error_set(err, LW_ENOMEM, "fidelity: cannot render %d x %d pixels", tone->nx, tone->ny);
    goto done;
  }
  /* user unit mm, the raster's top-left corner at the surface origin */
  cairo_scale(cr, 1.0 / tone->hx, 1.0 / tone->hy);
  cairo_translate(cr, -(tone->x0 - 0.5 * tone->hx), -(tone->y0 - 0.5 * tone->hy));
  cairo_set_source_rgba(cr, 0, 0, 0, 1);
  cairo_set_line_width(cr, pen_width_mm);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  lw_output_cairo_strokes(cr, st, pen);
  cairo_surface_flush(surf);
  if (cairo_status(cr)) {
    s = lw_error_set(err, LW_ERUN, "fidelity: rendering failed: %s", cairo_status_to_string(cairo_status(cr)));
    goto done;
  }
  const unsigned char *data = cairo_image_surface_get_data(surf);
  int stride = cairo_image_surface_get_stride(surf);
  for (int j = 0; j < tone->ny; j++)
    for (int i = 0; i < tone->nx; i++)
      ink[(size_t)j * (size_t)tone->nx + (size_t)i] = data[(size_t)j * (size_t)stride + (size_t)i] / 255.0;
done:
  cairo_destroy(cr);
  cairo_surface_destroy(surf);
  return s;
}

/* One axis of the blur: n values spaced `step` apart starting at v[0],
** `count` such lines `line` apart.  g[0..r] the kernel's half, norm[i] the
** sum of the weights that land inside for position i. */
static void blur_axis(double *v, size_t n, size_t step, size_t count, size_t line, const double *g, int r,
                      const double *norm, double *row)
{
  for (size_t c = 0; c < count; c++) {
    double *base = v + c * line;
    for (size_t i = 0; i < n; i++) row[i] = base[i * step];
    for (size_t i = 0; i < n; i++) {
      size_t lo = i >= (size_t)r ? i - (size_t)r : 0, hi = i + (size_t)r < n ? i + (size_t)r : n - 1;
      double sum = 0.0;
      for (size_t k = lo; k <= hi; k++) sum += g[k > i ? k - i : i - k] * row[k];
      base[i * step] = sum / norm[i];
    }
  }
}

/* Kernel halves and edge norms for n positions, sigma s, radius r. */
static void kernel(double s, int r, size_t n, double *g, double *norm)
{
  for (int k = 0; k <= r; k++) g[k] = exp(-0.5 * (double)k * (double)k / (s * s));
  for (size_t i = 0; i < n; i++) {
    double sum = 0.0;
    for (int k = -r; k <= r; k++) {
      long at = (long)i + k;
      if (at >= 0 && at < (long)n) sum += g[k < 0 ? -k : k];
    }
    norm[i] = sum;
  }
}

/* Separable blur with explicit radii (0 or sigma 0: that axis untouched). */
static lw_status blur(double *v, int w, int h, double sx, double sy, int rx, int ry, lw_error *err)
{
  size_t W = (size_t)w, H = (size_t)h, n = W > H ? W : H;
  int rmax = rx > ry ? rx : ry;
  double *row = malloc(n * sizeof *row), *norm = malloc(n * sizeof *norm);
  double *g = malloc(((size_t)rmax + 1) * sizeof *g);
  if (!row || !norm || !g) {
    free(row);
    free(norm);
    free(g);
    return lw_error_set(err, LW_ENOMEM, "fidelity: out of memory blurring %d x %d pixels", w, h);
  }
  if (sx > 0 && rx > 0) {
    kernel(sx, rx, W, g, norm);
    blur_axis(v, W, 1, H, W, g, rx, norm, row);
  }
  if (sy > 0 && ry > 0) {
    kernel(sy, ry, H, g, norm);
    blur_axis(v, H, W, W, 1, g, ry, norm, row);
  }
  free(row);
  free(norm);
  free(g);
  return LW_OK;
}

/* Radius ceil(truncate * sigma), kept below the image size it acts on. */
static int radius(double sigma, double truncate, int n)
{
  double r = ceil(truncate * sigma);
  return sigma > 0 ? (int)(r < n ? r : n) : 0;
}

lw_status lw_fidelity_blur(double *v, int w, int h, double sx, double sy, double truncate, lw_error *err)
{
  return blur(v, w, h, sx, sy, radius(sx, truncate, w), radius(sy, truncate, h), err);
}

/* The local averages under the SSIM window of `planes` w x h images stored
** one after the other in m, in place. */
static lw_status window(double *m, int planes, int w, int h, lw_error *err)
{
  size_t n = (size_t)w * (size_t)h;
  int rx = LW_FIDELITY_SSIM_RADIUS < w ? LW_FIDELITY_SSIM_RADIUS : w;
  int ry = LW_FIDELITY_SSIM_RADIUS < h ? LW_FIDELITY_SSIM_RADIUS : h;
  for (int q = 0; q < planes; q++) {
    lw_status s = blur(m + (size_t)q * n, w, h, LW_FIDELITY_SSIM_SIGMA, LW_FIDELITY_SSIM_SIGMA, rx, ry, err);
    if (s) return s;
  }
  return LW_OK;
}

/* Central differences (one-sided at the edges) of v into gx, gy. */
static void gradient(const double *v, int w, int h, double *gx, double *gy)
{
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      size_t k = (size_t)j * (size_t)w + (size_t)i;
      int il = i > 0 ? i - 1 : i, ir = i + 1 < w ? i + 1 : i, jd = j > 0 ? j - 1 : j, ju = j + 1 < h ? j + 1 : j;
      gx[k] = ir > il ? (v[(size_t)j * w + ir] - v[(size_t)j * w + il]) / (ir - il) : 0.0;
      gy[k] = ju > jd ? (v[(size_t)ju * w + i] - v[(size_t)jd * w + i]) / (ju - jd) : 0.0;
    }
}

/* The doubled-angle vector (Jxx - Jyy, 2 Jxy) of the structure tensor of v
** under the SSIM window into u[0 .. 2n): its angle is twice the dominant
** gradient direction, its length the anisotropy. */
static lw_status tensor(const double *v, int w, int h, double *u, double *t, lw_error *err)
{
  size_t n = (size_t)w * (size_t)h;
  double *gx = u, *gy = u + n, *jxx = t, *jxy = t + n, *jyy = t + 2 * n;
  gradient(v, w, h, gx, gy);
  for (size_t k = 0; k < n; k++) {
    jxx[k] = gx[k] * gx[k];
    jxy[k] = gx[k] * gy[k];
    jyy[k] = gy[k] * gy[k];
  }
  lw_status s = window(t, 3, w, h, err);
  if (s) return s;
  for (size_t k = 0; k < n; k++) {
    u[k] = jxx[k] - jyy[k];
    u[n + k] = 2 * jxy[k];
  }
  return LW_OK;
}

/* Orientation agreement of a with b (the target): the mean of cos 2 dtheta
** between their dominant gradient axes, weighted by b's anisotropy; a pixel
** where a has no direction counts 0.  NaN where b has no structure. */
static lw_status orientation(const double *a, const double *b, int w, int h, double *out, lw_error *err)
{
  size_t n = (size_t)w * (size_t)h;
  double *m = malloc(7 * n * sizeof *m);
  if (!m) return lw_error_set(err, LW_ENOMEM, "fidelity: out of memory for %d x %d pixels", w, h);
  double *ua = m, *ub = m + 2 * n, *t = m + 4 * n;
  lw_status s;
  if ((s = tensor(a, w, h, ua, t, err)) || (s = tensor(b, w, h, ub, t, err))) {
    free(m);
    return s;
  }
  /* below LW_FIDELITY_FLAT a pixel has no direction: rounding in the blur
  ** leaves gradients of ~1e-17 on a flat image */
  double num = 0.0, den = 0.0, flat = LW_FIDELITY_FLAT * LW_FIDELITY_FLAT;
  for (size_t k = 0; k < n; k++) {
    double la = hypot(ua[k], ua[n + k]), lb = hypot(ub[k], ub[n + k]);
    if (lb <= flat) continue;
    den += lb;
    if (la > flat) num += (ua[k] * ub[k] + ua[n + k] * ub[n + k]) / la;
  }
  *out = den > 0 ? num / den : NAN;
  free(m);
  return LW_OK;
}

lw_status lw_fidelity_compare(double *a, double *b, int w, int h, double sx, double sy, lw_fidelity *out,
                              lw_error *err)
{
  if (w < 1 || h < 1) return lw_error_set(err, LW_EINPUT, "fidelity: empty image %d x %d", w, h);
  lw_status s;
  if ((s = lw_fidelity_blur(a, w, h, sx, sy, LW_FIDELITY_TRUNCATE, err)) ||
      (s = lw_fidelity_blur(b, w, h, sx, sy, LW_FIDELITY_TRUNCATE, err)))
    return s;
  size_t n = (size_t)w * (size_t)h;
  double sum = 0.0;
  for (size_t k = 0; k < n; k++) sum += (a[k] - b[k]) * (a[k] - b[k]);
  out->mse = sum / (double)n;

  /* SSIM: local means, variances and covariance under the window */
  double *m = malloc(5 * n * sizeof *m);
  if (!m) return lw_error_set(err, LW_ENOMEM, "fidelity: out of memory for SSIM of %d x %d pixels", w, h);
  double *ma = m, *mb = m + n, *aa = m + 2 * n, *bb = m + 3 * n, *ab = m + 4 * n;
  for (size_t k = 0; k < n; k++) {
    ma[k] = a[k];
    mb[k] = b[k];
    aa[k] = a[k] * a[k];
    bb[k] = b[k] * b[k];
    ab[k] = a[k] * b[k];
  }
  if ((s = window(m, 5, w, h, err))) {
    free(m);
    return s;
  }
  const double C1 = 0.01 * 0.01, C2 = 0.03 * 0.03; /* L = 1 */
  sum = 0.0;
  for (size_t k = 0; k < n; k++) {
    double va = aa[k] - ma[k] * ma[k], vb = bb[k] - mb[k] * mb[k], cov = ab[k] - ma[k] * mb[k];
    sum += (2 * ma[k] * mb[k] + C1) * (2 * cov + C2) /
           ((ma[k] * ma[k] + mb[k] * mb[k] + C1) * (va + vb + C2));
  }
  out->ssim = sum / (double)n;
  free(m);
  return orientation(a, b, w, h, &out->orientation, err);
}

lw_status lw_fidelity_compute(const lw_splines *sp, const lw_grid2d *tone, double pen_width_mm,
                              double sigma_mm, lw_fidelity *out, lw_error *err)
{
  lw_strokes *st = as_strokes(sp, err);
  if (!st) return err ? err->code : LW_EINPUT;
  lw_status s = lw_fidelity_compute_strokes(st, -1, tone, pen_width_mm, sigma_mm, out, err);
  lw_strokes_free(st);
  return s;
}

lw_status lw_fidelity_compute_strokes(const lw_strokes *st, int pen, const lw_grid2d *tone, double pen_width_mm,
                                      double sigma_mm, lw_fidelity *out, lw_error *err)
{
  lw_status s = check_raster(tone, err);
  if (s) return s;
  if (!positive(sigma_mm))
    return lw_error_set(err, LW_EINPUT, "fidelity: blur %g mm: expected a positive number", sigma_mm);
  size_t n = (size_t)tone->nx * (size_t)tone->ny;
  double *ink = malloc(n * sizeof *ink), *dark = malloc(n * sizeof *dark);
  if (!ink || !dark) {
    free(ink);
    free(dark);
    return lw_error_set(err, LW_ENOMEM, "fidelity: out of memory for %d x %d pixels", tone->nx, tone->ny);
  }
  for (size_t k = 0; k < n; k++) {
    double t = tone->data[k];
    dark[k] = 1.0 - (t < 0 ? 0 : t > 1 ? 1 : t);
  }
  if (!(s = lw_fidelity_render_strokes(st, pen, tone, pen_width_mm, ink, err)))
    s = lw_fidelity_compare(ink, dark, tone->nx, tone->ny, sigma_mm / tone->hx, sigma_mm / tone->hy, out, err);
  out->sigma_mm = sigma_mm;
  free(ink);
  free(dark);
  return s;
}
