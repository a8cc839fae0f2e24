/* imagefield.c -- potential and vector fields from a picture (imagefield.h). */
#include "linewise/imagefield.h"

#include <math.h>
#include <stdlib.h>

/* The white paper a blurred potential is padded with, in pixels: as far as
** the blur's Gaussian reaches (4 sigma), at most this; a blur of over 64
** pixels, which the plane's mirrored edge reflects, leaves the paper there
** and beyond short of white by up to twice the darkness its Gaussian carries
** past 256 pixels (docs/NUMERICS.md, "The potential between the nodes"). */
#define POTENTIAL_PAD_MAX 256
/* Pixels wider than this many mm on the page are read through a finer grid
** (refine()), of at most POTENTIAL_NODES_MAX nodes. */
#define POTENTIAL_NODE_MM 1.0
#define POTENTIAL_NODES_MAX (4L << 20)

/* The white paper around a picture blurred by sigma nodes, k nodes a pixel,
** in nodes (0 without the paper). */
static int pad(double sigma, int k, int paper)
{
  return sigma > 0.0 && paper ? (int)fmin(ceil(4.0 * sigma) + 1.0, (double)POTENTIAL_PAD_MAX * k) : 0;
}

/* The nodes a side of each pixel: 1, or where a pixel is wider than
** POTENTIAL_NODE_MM the odd count that brings the nodes that close (odd, so
** that the pixel centres are nodes and the bilinear reading of the picture
** between them is the same), fewer where the grid would pass its cap.  The
** grid's outer ring, white paper, lies one node beyond the picture's edge
** pixels' centres: with a node a pixel a picture of a few pixels 89 mm wide
** faded to white from its one pixel's centre, a pyramid, where its pixel is
** a square of its tone. */
static int refine(int w, int h, double pixel, double sigma, int paper)
{
  int k = (int)fmin(ceil(pixel / POTENTIAL_NODE_MM), 4097.0);
  k += !(k & 1);
  while (k > 1 && ((long)w * k + 2 * pad(sigma * k, k, paper) + 2) * ((long)h * k + 2 * pad(sigma * k, k, paper) + 2) >
                      POTENTIAL_NODES_MAX)
    k -= 2;
  return k;
}

/* The picture's tone^power at node (i, j) of the grid of k nodes a pixel
** (0 <= i < w k): bilinear between the pixel centres, the edge pixels' tone
** out to the picture's edge; t holds tone^power by pixel (k > 1 only: a
** node a pixel reads the picture, with no plane the size of the picture). */
static double tone_at(const lw_image *img, double power, const double *t, int k, int i, int j)
{
  const int w = img->width, h = img->height;
  if (k == 1) {
    const float v = img->tone[(size_t)j * (size_t)w + (size_t)i];
    return power == 1.0 ? v : pow(v, power);
  }
  const double u = fmin(fmax((i + 0.5) / k - 0.5, 0.0), w - 1.0), v = fmin(fmax((j + 0.5) / k - 0.5, 0.0), h - 1.0);
  const int i0 = (int)fmin(floor(u), w - 2.0 < 0 ? 0 : w - 2.0), j0 = (int)fmin(floor(v), h - 2.0 < 0 ? 0 : h - 2.0);
  const int i1 = i0 + (w > 1), j1 = j0 + (h > 1);
  const double a = u - i0, b = v - j0;
  const double *r0 = t + (size_t)j0 * (size_t)w, *r1 = t + (size_t)j1 * (size_t)w;
  return (1.0 - b) * ((1.0 - a) * r0[i0] + a * r0[i1]) + b * ((1.0 - a) * r1[i0] + a * r1[i1]);
}

lw_grid2d *lw_imagefield_potential(const lw_image *img, const lw_image_place *pl, double power, double sigma,
                                   int paper, int fine, lw_error *err)
{
  const int k = fine ? refine(img->width, img->height, pl->pixel, sigma, paper) : 1;
  const int w = img->width * k, h = img->height * k;
  const double node = pl->pixel / k;
  sigma *= k;
  /* tone^power by pixel, for the finer grid's interpolation */
  const size_t n_px = (size_t)img->width * (size_t)img->height;
  double *t = NULL;
  if (k > 1) {
    if (!(t = malloc(n_px * sizeof *t))) {
      lw_error_set(err, LW_ENOMEM, "out of memory for a potential of %d x %d pixels", img->width, img->height);
      return NULL;
    }
    for (size_t q = 0; q < n_px; q++) t[q] = power == 1.0 ? img->tone[q] : pow(img->tone[q], power);
  }
  /* blurred, the picture is blurred on its paper: white as far as the blur
  ** reaches, so Phi rises to 1 beyond the picture without a step; without
  ** the paper the blur repeats the edge pixels and the ring continues them */
  const int m = pad(sigma, k, paper);
  const int pw = w + 2 * m, ph = h + 2 * m, W = pw + 2, H = ph + 2;
  /* node (i, j) is the centre of fine pixel (i - 1 - m, j - 1 - m); the outer
  ** ring is white, or blurred continues the padded plane */
  lw_grid2d *g = lw_grid2d_new(W, H, 1, pl->x0 - (m + 0.5) * node, pl->y0 - (m + 0.5) * node, node, node, err);
  /* blurred, Phi goes through the blur's float plane; else straight in */
  float *phi = NULL;
  if (g && sigma > 0.0) {
    if (!(phi = malloc((size_t)pw * (size_t)ph * sizeof *phi))) {
      lw_error_set(err, LW_ENOMEM, "out of memory for a potential of %d x %d pixels", pw, ph);
    } else {
      for (int j = 0; j < ph; j++)
        for (int i = 0; i < pw; i++) {
          const int x = i - m, y = j - m;
          phi[(size_t)j * (size_t)pw + (size_t)i] =
              x >= 0 && x < w && y >= 0 && y < h ? (float)tone_at(img, power, t, k, x, y) : 1.0f;
        }
      if (lw_image_blur_plane(phi, pw, ph, sigma, err)) {
        free(phi);
        phi = NULL;
      }
    }
    if (!phi) {
      lw_grid2d_free(g);
      g = NULL;
    }
  }
  for (int j = 0; g && j < H; j++)
    for (int i = 0; i < W; i++) {
      const int inner = i >= 1 && i <= w && j >= 1 && j <= h;
      double v = 1.0;
      if (phi) {
        const int ii = i < 1 ? 0 : (i > pw ? pw - 1 : i - 1), jj = j < 1 ? 0 : (j > ph ? ph - 1 : j - 1);
        v = phi[(size_t)jj * (size_t)pw + (size_t)ii];
      } else if (inner) {
        v = tone_at(img, power, t, k, i - 1, j - 1);
      }
      g->data[(size_t)j * W + (size_t)i] = v;
    }
  free(phi);
  free(t);
  return g;
}

/* Sobel gradient of the tone at pixel (i, j), tone per mm; the picture's
** edge pixels repeat beyond it, so its border is no edge. */
static void sobel(const lw_image *img, double pixel, int i, int j, double *gx, double *gy)
{
  const int w = img->width, h = img->height;
  const float *t = img->tone;
  int i0 = i > 0 ? i - 1 : 0, i1 = i < w - 1 ? i + 1 : w - 1;
  int j0 = j > 0 ? j - 1 : 0, j1 = j < h - 1 ? j + 1 : h - 1;
#define T(a, b) ((double)t[(size_t)(b) * (size_t)w + (size_t)(a)])
  *gx = (T(i1, j0) + 2 * T(i1, j) + T(i1, j1) - T(i0, j0) - 2 * T(i0, j) - T(i0, j1)) / (8.0 * pixel);
  *gy = (T(i0, j1) + 2 * T(i, j1) + T(i1, j1) - T(i0, j0) - 2 * T(i, j0) - T(i1, j0)) / (8.0 * pixel);
#undef T
}

/* A grid node at every pixel centre, two components. */
static lw_grid2d *pixel_grid(const lw_image *img, const lw_image_place *pl, lw_error *err)
{
  return lw_grid2d_new(img->width, img->height, 2, pl->x0 + 0.5 * pl->pixel, pl->y0 + 0.5 * pl->pixel,
                       pl->pixel, pl->pixel, err);
}

lw_grid2d *lw_imagefield_gradient(const lw_image *img, const lw_image_place *pl, double flat,
                                  double gentle[LW_IMAGEFIELD_GENTLE], lw_error *err)
{
  lw_grid2d *g = pixel_grid(img, pl, err);
  if (!g) return NULL;
  size_t faded[LW_IMAGEFIELD_GENTLE] = {0};
  for (int j = 0; j < img->height; j++)
    for (int i = 0; i < img->width; i++) {
      double gx, gy;
      sobel(img, pl->pixel, i, j, &gx, &gy);
      const double slope = sqrt(gx * gx + gy * gy);
      for (int k = 0, f = 1; k < LW_IMAGEFIELD_GENTLE; k++, f *= 10) faded[k] += slope > 0.0 && slope * f < flat;
      double n = fmax(slope, flat);
      double *d = g->data + 2 * ((size_t)j * (size_t)img->width + (size_t)i);
      d[0] = n > 0 ? gx / n : 0.0;
      d[1] = n > 0 ? gy / n : 0.0;
    }
  for (int k = 0; gentle && k < LW_IMAGEFIELD_GENTLE; k++)
    gentle[k] = (double)faded[k] / ((double)img->width * (double)img->height);
  return g;
}

lw_grid2d *lw_imagefield_etf(const lw_image *img, const lw_image_place *pl, double sigma_mm, double flat,
                             double angle, double gentle[LW_IMAGEFIELD_GENTLE], lw_error *err)
{
  const int w = img->width, h = img->height;
  const size_t n = (size_t)w * (size_t)h;
  lw_grid2d *g = pixel_grid(img, pl, err);
  if (!g) return NULL;
  /* the three tensor planes in float: a third of the memory of doubles,
  ** and the smoothing they get needs no more precision */
  float *J = malloc(3 * n * sizeof *J);
  if (!J) {
    lw_grid2d_free(g);
    lw_error_set(err, LW_ENOMEM, "out of memory for the structure tensor of %d x %d pixels", w, h);
    return NULL;
  }
  float *J11 = J, *J12 = J + n, *J22 = J + 2 * n;
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      double gx, gy;
      sobel(img, pl->pixel, i, j, &gx, &gy);
      size_t k = (size_t)j * (size_t)w + (size_t)i;
      J11[k] = (float)(gx * gx);
      J12[k] = (float)(gx * gy);
      J22[k] = (float)(gy * gy);
    }
  double sigma_px = sigma_mm / pl->pixel;
  for (int c = 0; c < 3; c++)
    if (lw_image_blur_plane(J + (size_t)c * n, w, h, sigma_px, err)) {
      free(J);
      lw_grid2d_free(g);
      return NULL;
    }
  const double fc = flat * flat * cos(2 * angle), fs = flat * flat * sin(2 * angle);
  const double uc = cos(2 * angle), us = sin(2 * angle);
  size_t fallback[LW_IMAGEFIELD_GENTLE] = {0};
  double below[LW_IMAGEFIELD_GENTLE]; /* (flat / 10^e)^4 */
  for (int e = 0; e < LW_IMAGEFIELD_GENTLE; e++) below[e] = pow(flat * pow(10.0, -e), 4);
  for (size_t k = 0; k < n; k++) {
    /* (weak but coherent: a direction the picture has, under the fallback;
    ** noise has none, and a noisy grey card counted in full) */
    const double ax = (double)J22[k] - J11[k], ay = -2.0 * J12[k], own = ax * ax + ay * ay;
    if (own > 0.0 && sqrt(own) > 0.5 * ((double)J11[k] + J22[k]))
      for (int e = 0; e < LW_IMAGEFIELD_GENTLE; e++) fallback[e] += own < below[e];
    double tx = ax + fc, ty = ay + fs;
    double m = sqrt(tx * tx + ty * ty);
    g->data[2 * k] = m > 0 ? tx / m : uc;
    g->data[2 * k + 1] = m > 0 ? ty / m : us;
  }
  free(J);
  for (int e = 0; gentle && e < LW_IMAGEFIELD_GENTLE; e++) gentle[e] = (double)fallback[e] / (double)n;
  return g;
}
