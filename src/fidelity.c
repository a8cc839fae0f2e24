/* fidelity.c -- rendered lines against a target tone: blur, MSE, SSIM
** (fidelity.h). */
#include "linewise/fidelity.h"

#include <cairo.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "linewise/image.h"
#include "linewise/output.h"

/* The threads the blurs and the window share a picture among (1 in a build
** without OpenMP, as the fuzzing harnesses are). */
static int threads_max(void)
{
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

static int thread_id(void)
{
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

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

/*
** Fine pixels a side for each raster pixel.  Coarse pixels miscount ink:
** cairo keeps coverage in eight bits and rounds it at every path, so a pen
** far narrower than a pixel inks it by a few 255ths a path, which round
** away (an 8 x 6 picture on A5, 21 mm pixels, scored as blank paper);
** and lines that share a pixel cannot be told apart from lines that
** overlap.  On pixels no wider than LW_FIDELITY_PEN_PIXELS pen widths a
** crossing covers much of a pixel and two strokes seldom share one; coarser
** pixels are rendered that fine and averaged.  The fine surface is capped
** at LW_FIDELITY_FINE_MAX pixels (and cairo's 32767 a side).
*/
static int supersampling(const lw_grid2d *t, double pen)
{
  double h = t->hx > t->hy ? t->hx : t->hy, want = ceil(h / (LW_FIDELITY_PEN_PIXELS * pen));
  double n = (double)t->nx * (double)t->ny, side = t->nx > t->ny ? t->nx : t->ny;
  double cap = floor(sqrt(LW_FIDELITY_FINE_MAX / n)), cap_side = floor(32767.0 / side);
  if (cap_side < cap) cap = cap_side;
  if (want > cap) want = cap;
  return want > 1 ? (int)want : 1;
}

lw_status lw_fidelity_render_strokes(const lw_strokes *st, int pen, const lw_grid2d *tone, double pen_width_mm,
                                     double *ink, lw_error *err)
{
  lw_status s = check_raster(tone, err);
  if (s) return s;
  if (!positive(pen_width_mm))
    return lw_error_set(err, LW_EINPUT, "fidelity: pen width %g mm: expected a positive number", pen_width_mm);
  const int k = supersampling(tone, pen_width_mm);
  /* A8: the alpha channel alone is the ink coverage. */
  cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_A8, tone->nx * k, tone->ny * k);
  cairo_t *cr = cairo_create(surf);
  if (cairo_status(cr)) {
    s = lw_error_set(err, LW_ENOMEM, "fidelity: cannot render %d x %d pixels", tone->nx * k, tone->ny * k);
    goto done;
  }
  /* user unit mm, the raster's top-left corner at the surface origin */
  cairo_scale(cr, k / tone->hx, k / tone->hy);
  cairo_translate(cr, -(tone->x0 - 0.5 * tone->hx), -(tone->y0 - 0.5 * tone->hy));
  cairo_set_source_rgba(cr, 0, 0, 0, 1);
  cairo_set_line_width(cr, pen_width_mm);
  /* Paths add their coverage (capped at full ink): lines that share a pixel
  ** without touching ink it together, where OVER would treat their coverage
  ** as independent and count 1 - (1 - a)(1 - b) of it. */
  cairo_set_operator(cr, CAIRO_OPERATOR_ADD);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  lw_output_cairo_strokes(cr, st, pen);
  cairo_surface_flush(surf);
  if (cairo_status(cr)) {
    s = lw_error_set(err, LW_ERUN, "fidelity: rendering failed: %s", cairo_status_to_string(cairo_status(cr)));
    goto done;
  }
  const unsigned char *data = cairo_image_surface_get_data(surf);
  const size_t stride = (size_t)cairo_image_surface_get_stride(surf), nx = (size_t)tone->nx, K = (size_t)k;
  const double scale = 1.0 / (255.0 * (double)k * (double)k);
  for (size_t j = 0; j < (size_t)tone->ny; j++)
    for (size_t i = 0; i < nx; i++) {
      unsigned sum = 0; /* at most 255 k^2 <= 255 LW_FIDELITY_FINE_MAX */
      for (size_t b = 0; b < K; b++)
        for (size_t a = 0; a < K; a++) sum += data[(j * K + b) * stride + i * K + a];
      ink[j * nx + i] = sum * scale;
    }
done:
  cairo_destroy(cr);
  cairo_surface_destroy(surf);
  return s;
}

/* Positions [from, to) of one line of the blur, from the copy in row. */
static void blur_positions(double *v, size_t n, size_t step, const double *g, int r, const double *norm,
                           const double *row, size_t from, size_t to)
{
  for (size_t i = from; i < to; i++) {
    size_t lo = i >= (size_t)r ? i - (size_t)r : 0, hi = i + (size_t)r < n ? i + (size_t)r : n - 1;
    double sum = 0.0;
    for (size_t k = lo; k < i; k++) sum += g[i - k] * row[k]; /* from the lowest index up, in two runs */
    for (size_t k = i; k <= hi; k++) sum += g[k - i] * row[k];
    v[i * step] = sum / norm[i];
  }
}

/* One line of the blur: n values spaced `step` apart starting at v[0].
** g[0..r] the kernel's half, norm[i] the sum of the weights that land
** inside for position i; row: scratch of n values. */
static void blur_line(double *v, size_t n, size_t step, const double *g, int r, const double *norm, double *row)
{
  for (size_t i = 0; i < n; i++) row[i] = v[i * step];
  const size_t R = (size_t)r;
  if (r <= LW_FIDELITY_SSIM_RADIUS && n >= 2 * R + 1) {
    /* the window's lines: where the kernel lies inside, eight positions a
    ** step, each its own sum from the lowest index up as below */
    double gf[2 * LW_FIDELITY_SSIM_RADIUS + 1];
    for (size_t t = 0; t <= 2 * R; t++) gf[t] = g[t > R ? t - R : R - t];
    size_t i = R;
    for (; i + R + 8 <= n; i += 8) {
      double acc[8] = {0};
      for (size_t t = 0; t <= 2 * R; t++) {
        const double w = gf[t], *e = row + i - R + t;
#pragma omp simd
        for (int j = 0; j < 8; j++) acc[j] += w * e[j];
      }
      for (int j = 0; j < 8; j++) v[(i + j) * step] = acc[j] / norm[i + j];
    }
    blur_positions(v, n, step, g, r, norm, row, 0, R);
    blur_positions(v, n, step, g, r, norm, row, i, n);
    return;
  }
  blur_positions(v, n, step, g, r, norm, row, 0, n);
}

/* The same sums for the wide blur of the scores, with the kernel folded
** where it lies wholly inside the line: g[0] v[i] + sum over d = 1 .. r of
** g[d] (v[i - d] + v[i + d]), d upward, eight positions a step (each its
** own sum, in that order, whatever the step holds), so the compiler can
** take the positions in vectors.  Half the products of blur_line, and the
** same value at every position on any machine. */
static void blur_line_folded(double *v, size_t n, size_t step, const double *g, int r, const double *norm,
                             double *row)
{
  const size_t R = (size_t)r;
  if (n < 2 * R + 1) {
    blur_line(v, n, step, g, r, norm, row);
    return;
  }
  for (size_t i = 0; i < n; i++) row[i] = v[i * step];
  blur_positions(v, n, step, g, r, norm, row, 0, R); /* the window cut by the start */
  size_t i = R;
  for (; i + R + 8 <= n; i += 8) {
    double acc[8];
    for (int j = 0; j < 8; j++) acc[j] = g[0] * row[i + j];
    for (size_t dd = 1; dd <= R; dd++)
      for (int j = 0; j < 8; j++) acc[j] += g[dd] * (row[i + j - dd] + row[i + j + dd]);
    for (int j = 0; j < 8; j++) v[(i + j) * step] = acc[j] / norm[i + j];
  }
  for (; i + R < n; i++) {
    double sum = g[0] * row[i];
    for (size_t dd = 1; dd <= R; dd++) sum += g[dd] * (row[i - dd] + row[i + dd]);
    v[i * step] = sum / norm[i];
  }
  blur_positions(v, n, step, g, r, norm, row, i, n); /* the window cut by the end */
}

/* `count` such lines `line` apart.  A picture's lines are independent and
** each is summed as one thread alone would, so the threads share them out
** and the result does not depend on how many there are (the scores of a
** camera's picture in four pens took 10 s serially). */
static lw_status blur_axis(double *v, size_t n, size_t step, size_t count, size_t line, const double *g, int r,
                           const double *norm)
{
  const int threads = threads_max();
  double *rows = malloc((size_t)threads * n * sizeof *rows);
  if (!rows) return LW_ENOMEM;
#pragma omp parallel for schedule(static) num_threads(threads)
  for (long c = 0; c < (long)count; c++)
    blur_line_folded(v + (size_t)c * line, n, step, g, r, norm, rows + (size_t)thread_id() * n);
  free(rows);
  return LW_OK;
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

/*
** Wide blurs, sparsely, as the picture's (image.c): a camera's picture on
** a small page is scored on a raster of its pixels, 1 mm a sigma of 28 of
** them, and the direct sums took 2 s of drawing the final files.  From
** SPARSE_SIGMA pixels on (both axes) each axis is summed at every f-th
** position, f = sigma / 8 rounded down, from one step before the first to
** two after the last (the sum and its norm are defined there too), and
** taken between by cubic (Catmull-Rom) interpolation: within 5e-6 of the
** direct sums on a sharp rim, far below the scores' digits
** (tests/test_fidelity.c).  Not where the radius was cut to the raster:
** there the window's ends, inside the interpolation's reach beyond the
** raster, make a kink of the sums (3e-4 off at sigma 90 on 131 pixels).
*/
#define SPARSE_SIGMA 16.0

/* The normalised sum of one line at position x (any integer). */
static double blur_at(const double *v, size_t n, size_t step, long x, const double *g, int r)
{
  long lo = x - r > 0 ? x - r : 0, hi = x + r < (long)n - 1 ? x + r : (long)n - 1;
  double sum = 0.0, norm = 0.0;
  for (long k = lo; k <= hi; k++) {
    const double wk = g[k > x ? k - x : x - k];
    sum += wk * v[(size_t)k * step];
    norm += wk;
  }
  return norm > 0.0 ? sum / norm : 0.0;
}

static lw_status blur_sparse(double *v, int w, int h, double sx, double sy, int rx, int ry, int f, lw_error *err)
{
  const size_t W = (size_t)w, H = (size_t)h, Kx = (W - 1) / (size_t)f + 4, Ky = (H - 1) / (size_t)f + 4;
  double *gx = malloc(((size_t)rx + 1) * sizeof *gx), *gy = malloc(((size_t)ry + 1) * sizeof *gy);
  double *rows = malloc(H * Kx * sizeof *rows), *grid = malloc(Ky * Kx * sizeof *grid);
  double *wx = malloc(4 * W * sizeof *wx);
  if (!gx || !gy || !rows || !grid || !wx) {
    free(gx), free(gy), free(rows), free(grid), free(wx);
    return lw_error_set(err, LW_ENOMEM, "fidelity: out of memory blurring %d x %d pixels", w, h);
  }
  for (int k = 0; k <= rx; k++) gx[k] = exp(-0.5 * (double)k * (double)k / (sx * sx));
  for (int k = 0; k <= ry; k++) gy[k] = exp(-0.5 * (double)k * (double)k / (sy * sy));
  /* every value below is one thread's sum: the threads only share them out */
#pragma omp parallel for schedule(static)
  for (size_t y = 0; y < H; y++)
    for (size_t k = 0; k < Kx; k++) rows[y * Kx + k] = blur_at(v + y * W, W, 1, ((long)k - 1) * f, gx, rx);
#pragma omp parallel for schedule(static)
  for (size_t k = 0; k < Kx; k++)
    for (size_t j = 0; j < Ky; j++) grid[j * Kx + k] = blur_at(rows + k, H, Kx, ((long)j - 1) * f, gy, ry);
  for (size_t x = 0; x < W; x++) lw_image_cubic_weights((double)(x % (size_t)f) / f, wx + 4 * x);
#pragma omp parallel for schedule(static)
  for (size_t y = 0; y < H; y++) {
    double wy[4];
    lw_image_cubic_weights((double)(y % (size_t)f) / f, wy);
    const double *g = grid + (y / (size_t)f) * Kx;
    for (size_t x = 0; x < W; x++) {
      const double *c = g + x / (size_t)f, *a = wx + 4 * x;
      double sum = 0.0;
      for (int j = 0; j < 4; j++, c += Kx) sum += wy[j] * (a[0] * c[0] + a[1] * c[1] + a[2] * c[2] + a[3] * c[3]);
      v[y * W + x] = sum;
    }
  }
  free(gx), free(gy), free(rows), free(grid), free(wx);
  return LW_OK;
}

/* Separable blur with explicit radii (0 or sigma 0: that axis untouched). */
static lw_status blur(double *v, int w, int h, double sx, double sy, int rx, int ry, lw_error *err)
{
  if (sx >= SPARSE_SIGMA && sy >= SPARSE_SIGMA && rx > 0 && ry > 0 && rx < w && ry < h)
    return blur_sparse(v, w, h, sx, sy, rx, ry, (int)(fmin(sx, sy) / 8.0), err);
  size_t W = (size_t)w, H = (size_t)h, n = W > H ? W : H;
  int rmax = rx > ry ? rx : ry;
  double *norm = malloc(n * sizeof *norm), *g = malloc(((size_t)rmax + 1) * sizeof *g);
  lw_status s = norm && g ? LW_OK : LW_ENOMEM;
  if (!s && sx > 0 && rx > 0) {
    kernel(sx, rx, W, g, norm);
    s = blur_axis(v, W, 1, H, W, g, rx, norm);
  }
  if (!s && sy > 0 && ry > 0) {
    kernel(sy, ry, H, g, norm);
    s = blur_axis(v, H, W, W, 1, g, ry, norm);
  }
  free(norm);
  free(g);
  return s ? lw_error_set(err, s, "fidelity: out of memory blurring %d x %d pixels", w, h) : LW_OK;
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

/*
** The SSIM window, a row at a time.  Scoring a 4-megapixel picture on whole
** planes held nine of them at once (288 MB); the window is separable and
** 11 rows tall, so the rows it needs are kept instead: each plane's rows
** are made (`fill`), blurred along x as they come, kept in a ring of
** 2 ry + 1, and each output row is their weighted sum down the column.
** The sums are those of the two-pass blur above, term for term and in the
** same order.  Each thread runs a ring over a band of rows (making the
** 2 ry rows above its band again), and a row's score is summed along the
** row alone, so every row's sum, and their total in row order, is the
** same for any number of threads.
*/
typedef void (*window_fill)(const void *ctx, int row, double **planes, double *scratch);
/* Adds what row's windowed planes t (plane q at t + q w) give to sums[]. */
typedef void (*window_score)(const double *t, size_t w, double *sums);

typedef struct {
  int w, h, planes, rx, ry, ring;
  double gx[LW_FIDELITY_SSIM_RADIUS + 1], gy[LW_FIDELITY_SSIM_RADIUS + 1];
  double *normx, *normy, *rows, *scratch, *out; /* scratch: 2 w, for fill and the blur */
  window_fill fill;
  const void *ctx;
  int made; /* rows made so far */
} window_rows;

static void window_rows_free(window_rows *r)
{
  free(r->normx);
  free(r->normy);
  free(r->rows);
  free(r->scratch);
  free(r->out);
}

/* A ring whose first row asked for is `first`; 0 when out of memory. */
static int window_rows_init(window_rows *r, int planes, int w, int h, window_fill fill, const void *ctx, int first)
{
  *r = (window_rows){.w = w, .h = h, .planes = planes, .fill = fill, .ctx = ctx};
  r->rx = LW_FIDELITY_SSIM_RADIUS < w ? LW_FIDELITY_SSIM_RADIUS : w;
  r->ry = LW_FIDELITY_SSIM_RADIUS < h ? LW_FIDELITY_SSIM_RADIUS : h;
  r->ring = 2 * r->ry + 1;
  r->made = first >= r->ry ? first - r->ry : 0;
  size_t W = (size_t)w, P = (size_t)planes;
  r->normx = malloc(W * sizeof *r->normx);
  r->normy = malloc((size_t)h * sizeof *r->normy);
  r->rows = malloc((size_t)r->ring * P * W * sizeof *r->rows);
  r->scratch = malloc(2 * W * sizeof *r->scratch);
  r->out = malloc(P * W * sizeof *r->out);
  if (!r->normx || !r->normy || !r->rows || !r->scratch || !r->out) {
    window_rows_free(r);
    return 0;
  }
  kernel(LW_FIDELITY_SSIM_SIGMA, r->rx, W, r->gx, r->normx);
  kernel(LW_FIDELITY_SSIM_SIGMA, r->ry, (size_t)h, r->gy, r->normy);
  return 1;
}

/* Row k's planes, made and blurred along x, in ring slot k mod ring. */
static void window_make(window_rows *r, int k)
{
  size_t W = (size_t)r->w, P = (size_t)r->planes;
  double *slot = r->rows + (size_t)(k % r->ring) * P * W, *planes[8];
  for (size_t q = 0; q < P; q++) planes[q] = slot + q * W;
  r->fill(r->ctx, k, planes, r->scratch);
  for (size_t q = 0; q < P; q++) blur_line(planes[q], W, 1, r->gx, r->rx, r->normx, r->scratch);
}

/* The windowed planes of row j into r->out (plane q at out + q w).  Rows
** are asked for in order from the ring's first. */
static const double *window_row(window_rows *r, int j)
{
  int lo = j >= r->ry ? j - r->ry : 0, hi = j + r->ry < r->h ? j + r->ry : r->h - 1;
  for (; r->made <= hi; r->made++) window_make(r, r->made);
  size_t W = (size_t)r->w, P = (size_t)r->planes;
  for (size_t q = 0; q < P; q++) {
    double *o = r->out + q * W;
    for (size_t c = 0; c < W; c++) o[c] = 0.0;
    for (int k = lo; k <= hi; k++) {
      const double *in = r->rows + ((size_t)(k % r->ring) * P + q) * W;
      double g = r->gy[k > j ? k - j : j - k];
      /* columns in vectors: each column's sum keeps its order */
#pragma omp simd
      for (size_t c = 0; c < W; c++) o[c] += g * in[c];
    }
    const double nj = r->normy[j];
#pragma omp simd
    for (size_t c = 0; c < W; c++) o[c] /= nj;
  }
  return r->out;
}

/* The sums[0 .. n) of score over every row of the window's planes. */
static lw_status window_sum(int planes, int w, int h, window_fill fill, const void *ctx, window_score score, int n,
                            double *sums, lw_error *err)
{
  double *part = calloc((size_t)h * (size_t)n, sizeof *part);
  if (!part) return lw_error_set(err, LW_ENOMEM, "fidelity: out of memory for %d x %d pixels", w, h);
  const int bands = threads_max() < h ? threads_max() : h;
  int failed = 0;
#pragma omp parallel for schedule(static, 1) num_threads(bands) reduction(| : failed)
  for (int b = 0; b < bands; b++) {
    const int j0 = (int)((long)h * b / bands), j1 = (int)((long)h * (b + 1) / bands);
    window_rows r;
    if (!window_rows_init(&r, planes, w, h, fill, ctx, j0)) {
      failed = 1;
      continue;
    }
    for (int j = j0; j < j1; j++) score(window_row(&r, j), (size_t)w, part + (size_t)j * (size_t)n);
    window_rows_free(&r);
  }
  for (int q = 0; q < n; q++) sums[q] = 0.0;
  for (size_t j = 0; j < (size_t)h; j++)
    for (int q = 0; q < n; q++) sums[q] += part[j * (size_t)n + (size_t)q];
  free(part);
  if (failed)
    return lw_error_set(err, LW_ENOMEM, "fidelity: out of memory for the SSIM window over %d x %d pixels", w, h);
  return LW_OK;
}

/* Central differences (one-sided at the edges) of row j of v into gx, gy. */
static void gradient_row(const double *v, int w, int h, int j, double *gx, double *gy)
{
  size_t W = (size_t)w;
  int jd = j > 0 ? j - 1 : j, ju = j + 1 < h ? j + 1 : j;
  for (int i = 0; i < w; i++) {
    int il = i > 0 ? i - 1 : i, ir = i + 1 < w ? i + 1 : i;
    gx[i] = ir > il ? (v[(size_t)j * W + ir] - v[(size_t)j * W + il]) / (ir - il) : 0.0;
    gy[i] = ju > jd ? (v[(size_t)ju * W + i] - v[(size_t)jd * W + i]) / (ju - jd) : 0.0;
  }
}

typedef struct {
  const double *a, *b;
  int w, h;
} pair_rows;

/* SSIM's planes: a, b, a^2, b^2, ab. */
static void fill_moments(const void *ctx, int row, double **pl, double *scratch)
{
  const pair_rows *c = ctx;
  const double *a = c->a + (size_t)row * (size_t)c->w, *b = c->b + (size_t)row * (size_t)c->w;
  for (int i = 0; i < c->w; i++) {
    pl[0][i] = a[i];
    pl[1][i] = b[i];
    pl[2][i] = a[i] * a[i];
    pl[3][i] = b[i] * b[i];
    pl[4][i] = a[i] * b[i];
  }
}

/* The structure tensors' planes: gx^2, gx gy, gy^2 of a, then of b. */
static void fill_tensors(const void *ctx, int row, double **pl, double *scratch)
{
  const pair_rows *c = ctx;
  double *gx = scratch, *gy = scratch + c->w;
  for (int s = 0; s < 2; s++) {
    gradient_row(s ? c->b : c->a, c->w, c->h, row, gx, gy);
    double *xx = pl[3 * s], *xy = pl[3 * s + 1], *yy = pl[3 * s + 2];
    for (int i = 0; i < c->w; i++) {
      xx[i] = gx[i] * gx[i];
      xy[i] = gx[i] * gy[i];
      yy[i] = gy[i] * gy[i];
    }
  }
}

/* A row's SSIM map, summed. */
static void score_ssim(const double *ma, size_t W, double *sums)
{
  const double *mb = ma + W, *aa = mb + W, *bb = aa + W, *ab = bb + W;
  const double C1 = 0.01 * 0.01, C2 = 0.03 * 0.03; /* L = 1 */
  double sum = 0.0;
  for (size_t k = 0; k < W; k++) {
    double va = aa[k] - ma[k] * ma[k], vb = bb[k] - mb[k] * mb[k], cov = ab[k] - ma[k] * mb[k];
    sum += (2 * ma[k] * mb[k] + C1) * (2 * cov + C2) / ((ma[k] * ma[k] + mb[k] * mb[k] + C1) * (va + vb + C2));
  }
  sums[0] = sum;
}

/* SSIM of a against b, its map averaged over every pixel. */
static lw_status ssim(const double *a, const double *b, int w, int h, double *out, lw_error *err)
{
  pair_rows c = {a, b, w, h};
  double sum;
  lw_status s = window_sum(5, w, h, fill_moments, &c, score_ssim, 1, &sum, err);
  *out = sum / ((double)w * (double)h);
  return s;
}

/* A row's agreement and weight (orientation, below).  Below
** LW_FIDELITY_FLAT a pixel has no direction: rounding in the blur leaves
** gradients of ~1e-17 on a flat image. */
static void score_orientation(const double *t, size_t W, double *sums)
{
  const double flat = LW_FIDELITY_FLAT * LW_FIDELITY_FLAT;
  double num = 0.0, den = 0.0;
  for (size_t k = 0; k < W; k++) {
    double ua0 = t[k] - t[2 * W + k], ua1 = 2 * t[W + k];
    double ub0 = t[3 * W + k] - t[5 * W + k], ub1 = 2 * t[4 * W + k];
    double la = hypot(ua0, ua1), lb = hypot(ub0, ub1);
    if (lb <= flat) continue;
    den += lb;
    if (la > flat) num += (ua0 * ub0 + ua1 * ub1) / la;
  }
  sums[0] = num;
  sums[1] = den;
}

/* Orientation agreement of a with b (the target): the mean of cos 2 dtheta
** between their dominant gradient axes, the doubled-angle vectors
** (Jxx - Jyy, 2 Jxy) of their structure tensors under the SSIM window,
** weighted by b's anisotropy; a pixel where a has no direction counts 0.
** NaN where b has no structure. */
static lw_status orientation(const double *a, const double *b, int w, int h, double *out, lw_error *err)
{
  pair_rows c = {a, b, w, h};
  double sums[2];
  lw_status s = window_sum(6, w, h, fill_tensors, &c, score_orientation, 2, sums, err);
  *out = sums[1] > 0 ? sums[0] / sums[1] : NAN;
  return s;
}

/* Step 6: the share of the marks (darkness of LW_FIDELITY_MARK black or
** more, unblurred) with no inked pixel (covered LW_FIDELITY_INKED or more)
** within rx, ry pixels along each axis: a square about each, by a running
** count along the rows, then the columns, of the inked pixels. */
static lw_status missed_marks(const double *ink, const double *dark, int w, int h, double rx, double ry, double black,
                              lw_fidelity *out, lw_error *err)
{
  const size_t n = (size_t)w * (size_t)h;
  const int ax = (int)ceil(rx), ay = (int)ceil(ry);
  /* a pixel is inked at a share of the ink black asks (a picture's coarse
  ** pixel under hatching at tone_ink 0.2 never held a quarter) */
  const double inked = LW_FIDELITY_INKED * black;
  unsigned char *row = malloc(n), *col = malloc(n); /* (2 bytes a pixel: scoring's peak) */
  if (!row || !col) {
    free(row);
    free(col);
    return lw_error_set(err, LW_ENOMEM, "fidelity: out of memory for %d x %d pixels", w, h);
  }
  /* row[k]: an inked pixel within ax along the row; col[k]: one of those
  ** within ay of k along the column (running counts of each window) */
  for (int j = 0; j < h; j++) {
    int c = 0;
    const double *in = ink + (size_t)j * (size_t)w;
    for (int i = 0; i < ax && i < w; i++) c += in[i] >= inked;
    for (int i = 0; i < w; i++) {
      if (i + ax < w) c += in[i + ax] >= inked;
      if (i - ax - 1 >= 0) c -= in[i - ax - 1] >= inked;
      row[(size_t)j * (size_t)w + (size_t)i] = c > 0;
    }
  }
  for (int i = 0; i < w; i++) {
    int c = 0;
    for (int j = 0; j < ay && j < h; j++) c += row[(size_t)j * (size_t)w + (size_t)i];
    for (int j = 0; j < h; j++) {
      if (j + ay < h) c += row[(size_t)(j + ay) * (size_t)w + (size_t)i];
      if (j - ay - 1 >= 0) c -= row[(size_t)(j - ay - 1) * (size_t)w + (size_t)i];
      col[(size_t)j * (size_t)w + (size_t)i] = c > 0;
    }
  }
  size_t marks = 0, bare = 0;
  for (size_t k = 0; k < n; k++)
    if (dark[k] >= LW_FIDELITY_MARK * black) {
      marks++;
      bare += col[k] == 0;
    }
  out->missed = marks ? (double)bare / (double)marks : 0.0;
  free(row);
  /* and the worst square of LW_FIDELITY_MISS_CELL pen widths a side, among
  ** those a fiftieth marks or more: a word left out beside a figure drawn
  ** whole was 0.01 of the picture's marks */
  const int cx = (int)ceil(rx * LW_FIDELITY_MISS_CELL / LW_FIDELITY_MISS_REACH),
            cy = (int)ceil(ry * LW_FIDELITY_MISS_CELL / LW_FIDELITY_MISS_REACH);
  const size_t nx = (size_t)((w + cx - 1) / cx), ny = (size_t)((h + cy - 1) / cy);
  size_t *cell = calloc(2 * nx * ny, sizeof *cell); /* marks, then bare ones */
  if (!cell) {
    free(col);
    return lw_error_set(err, LW_ENOMEM, "fidelity: out of memory for %zu cells", nx * ny);
  }
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      const size_t k = (size_t)j * (size_t)w + (size_t)i, c = (size_t)(j / cy) * nx + (size_t)(i / cx);
      if (dark[k] < LW_FIDELITY_MARK * black) continue;
      cell[2 * c]++;
      cell[2 * c + 1] += col[k] == 0;
    }
  out->missed_worst = 0.0;
  out->missed_at[0] = out->missed_at[1] = -1.0;
  for (size_t c = 0; c < nx * ny; c++) {
    const double share = cell[2 * c] ? (double)cell[2 * c + 1] / (double)cell[2 * c] : 0.0;
    /* (not the squares on the picture's edge, where the lines keep their
    ** clearance from a frame the picture fills: a dark rose read 0.6 there) */
    const size_t ci = c % nx, cj = c / nx;
    if (ci == 0 || cj == 0 || ci + 1 == nx || cj + 1 == ny) continue;
    if (50.0 * (double)cell[2 * c] >= (double)cx * cy && share > out->missed_worst) {
      out->missed_worst = share;
      out->missed_at[0] = ((double)(c % nx) + 0.5) * cx; /* pixels: the caller places them */
      out->missed_at[1] = ((double)(c / nx) + 0.5) * cy;
    }
  }
  free(cell);
  free(col);
  return LW_OK;
}

lw_status lw_fidelity_compare(double *a, double *b, int w, int h, double sx, double sy, double white,
                              lw_fidelity *out, lw_error *err)
{
  if (w < 1 || h < 1) return lw_error_set(err, LW_EINPUT, "fidelity: empty image %d x %d", w, h);
  lw_status s;
  if ((s = lw_fidelity_blur(b, w, h, sx, sy, LW_FIDELITY_TRUNCATE, err))) return s;
  size_t n = (size_t)w * (size_t)h;
  /* the ink before its blur, which would spread an edge's line into the white beside it */
  double ink = 0.0, stray = 0.0;
  for (size_t k = 0; k < n; k++) {
    ink += a[k];
    if (b[k] < white) stray += a[k];
  }
  out->stray = ink > 0 ? stray / ink : 0.0;
  if ((s = lw_fidelity_blur(a, w, h, sx, sy, LW_FIDELITY_TRUNCATE, err))) return s;
  double sum = 0.0;
  for (size_t k = 0; k < n; k++) sum += (a[k] - b[k]) * (a[k] - b[k]);
  out->mse = sum / (double)n;
  if ((s = ssim(a, b, w, h, &out->ssim, err))) return s;
  return orientation(a, b, w, h, &out->orientation, err);
}

lw_status lw_fidelity_compute(const lw_splines *sp, const lw_grid2d *tone, double pen_width_mm,
                              double sigma_mm, lw_fidelity *out, lw_error *err)
{
  lw_strokes *st = as_strokes(sp, err);
  if (!st) return err ? err->code : LW_EINPUT;
  lw_status s = lw_fidelity_compute_strokes(st, -1, tone, 1.0, pen_width_mm, sigma_mm, out, err);
  lw_strokes_free(st);
  return s;
}

lw_status lw_fidelity_compute_strokes(const lw_strokes *st, int pen, const lw_grid2d *tone, double black,
                                      double pen_width_mm, double sigma_mm, lw_fidelity *out, lw_error *err)
{
  lw_status s = check_raster(tone, err);
  if (s) return s;
  if (!positive(sigma_mm))
    return lw_error_set(err, LW_EINPUT, "fidelity: blur %g mm: expected a positive number", sigma_mm);
  if (!positive(black) || black > 1)
    return lw_error_set(err, LW_EINPUT, "fidelity: black ink %g: expected a number > 0 and <= 1", black);
  size_t n = (size_t)tone->nx * (size_t)tone->ny;
  double *ink = malloc(n * sizeof *ink), *dark = malloc(n * sizeof *dark);
  if (!ink || !dark) {
    free(ink);
    free(dark);
    return lw_error_set(err, LW_ENOMEM, "fidelity: out of memory for %d x %d pixels", tone->nx, tone->ny);
  }
  for (size_t k = 0; k < n; k++) {
    double t = tone->data[k];
    dark[k] = black * (1.0 - (t < 0 ? 0 : t > 1 ? 1 : t));
  }
  if (!(s = lw_fidelity_render_strokes(st, pen, tone, pen_width_mm, ink, err)) &&
      !(s = missed_marks(ink, dark, tone->nx, tone->ny, LW_FIDELITY_MISS_REACH * pen_width_mm / tone->hx,
                         LW_FIDELITY_MISS_REACH * pen_width_mm / tone->hy, black, out, err))) {
    /* the worst square's centre on the page (pixel (i, j)'s centre is x0 + i hx) */
    if (out->missed_at[0] >= 0.0) {
      out->missed_at[0] = tone->x0 + (out->missed_at[0] - 0.5) * tone->hx;
      out->missed_at[1] = tone->y0 + (out->missed_at[1] - 0.5) * tone->hy;
    }
    s = lw_fidelity_compare(ink, dark, tone->nx, tone->ny, sigma_mm / tone->hx, sigma_mm / tone->hy,
                            LW_FIDELITY_WHITE * black, out, err);
  }
  out->sigma_mm = sigma_mm;
  out->black = black;
  free(ink);
  free(dark);
  return s;
}
