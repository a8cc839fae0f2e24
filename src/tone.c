/*
** tone.c -- the tone term's raster (tone.h): footprints in fixed point, the
** energy of a raster and the difference of a box of changes.
*/
#include "linewise/tone.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/vec2.h"
#if LW_VEC_HAVE_WIDE
#include <immintrin.h>
#endif

/* Picture pixels a side of a raster pixel: the most whose side stays within
** sigma / LW_TONE_SIGMA_PIXELS (1 where the picture's pixels are coarser). */
static int tone_block(double sigma, double pixel)
{
  double k = floor(sigma / (LW_TONE_SIGMA_PIXELS * pixel));
  return k >= 1.0 ? (int)k : 1; /* below LW_TONE_BLUR_MAX / 4.5 */
}

lw_status lw_tone_init(lw_tone *t, const lw_image *img, const lw_image_place *pl, double sigma, double pen,
                       double ink, lw_error *err)
{
  memset(t, 0, sizeof *t);
  /* the target is blurred at the picture's pixels, with a ring of white
  ** paper 3 sigma wide, before it is read at the raster's */
  if (!(ceil(3.0 * sigma / pl->pixel) <= LW_TONE_BLUR_MAX)) {
    /* the largest blur allowed, cut (not rounded) to 4 digits so that it is */
    double most = LW_TONE_BLUR_MAX * pl->pixel / 3.0, scale = pow(10.0, 3.0 - floor(log10(most)));
    return lw_error_set(err, LW_EINPUT, "tone: a blur of %g mm reaches %.0f pixels of %g mm (3 sigma), more than "
                        "the %d the target allows; expected a blur of at most %g mm, or fewer pixels across the "
                        "picture (scene.image_width or scene.image_max_pixels)",
                        sigma, ceil(3.0 * sigma / pl->pixel), pl->pixel, LW_TONE_BLUR_MAX, floor(most * scale) / scale);
  }
  const int k = tone_block(sigma, pl->pixel);
  const double px = k * pl->pixel, r = ceil(3.0 * sigma / px);
  /* px > sigma / (2 LW_TONE_SIGMA_PIXELS), so r < 6 LW_TONE_SIGMA_PIXELS = 9:
  ** the footprint's weights fit weights()'s arrays */
  if (!(r <= LW_TONE_RADIUS_MAX))
    return lw_error_set(err, LW_ERUN, "tone: a footprint radius of %.0f raster pixels", r);
  t->radius = r < 1.0 ? 1 : (int)r;
  t->pad = t->radius;
  t->w = (img->width + k - 1) / k + 2 * t->pad;
  t->h = (img->height + k - 1) / k + 2 * t->pad;
  t->pixel = px;
  t->area = px * px;
  t->x0 = pl->x0 - t->pad * px;
  t->y0 = pl->y0 - t->pad * px;
  t->sigma = sigma;
  t->pen = pen;
  t->inv = 1.0 / (2.0 * sigma * sigma);
  t->floor = exp(-(t->radius * px) * (t->radius * px) * t->inv);
  t->fall = exp(-2.0 * px * px * t->inv);
  t->dark = calloc((size_t)t->w * (size_t)t->h, sizeof *t->dark);
  /* The target at the picture's own pixels, with a ring of white paper
  ** that reaches past every raster pixel centre, blurred there; then read
  ** at the raster's pixel centres (below). */
  const int fp = k == 1 ? t->pad : k * (t->pad + 1) + 1, fw = img->width + 2 * fp, fh = img->height + 2 * fp;
  float *fine = k == 1 ? t->dark : calloc((size_t)fw * (size_t)fh, sizeof *fine);
  if (!t->dark || !fine) {
    if (fine != t->dark) free(fine);
    lw_tone_clear(t);
    return lw_error_set(err, LW_ENOMEM, "out of memory for the tone raster (%d x %d)", fw, fh);
  }
  for (int j = 0; j < img->height; j++)
    for (int i = 0; i < img->width; i++)
      fine[(size_t)(j + fp) * (size_t)fw + (size_t)(i + fp)] =
          (float)(ink * (1.0 - img->tone[(size_t)j * (size_t)img->width + (size_t)i]));
  /* The same blur on both sides: G * ink cannot be sharper than G, so a
  ** sharp target would ask for ink piled along every edge (the picture's
  ** rim included) to make up for the blur. */
  lw_status st = lw_image_blur_plane(fine, fw, fh, sigma / pl->pixel, err);
  if (!st && k > 1) {
    /* Raster pixel I's centre is picture pixel k (I - pad) + (k - 1) / 2: a
    ** pixel centre for odd k, and for even k the middle of two, where the
    ** blurred target (smooth over sigma, 3 pixels and more) is read by the
    ** four-point midpoint rule (-1 9 9 -1) / 16 on each axis, exact for
    ** cubics: a mean of two would blur it by (pixel / 2)^2 more. */
    static const double mid[4] = {-1.0 / 16, 9.0 / 16, 9.0 / 16, -1.0 / 16};
    const int lo = fp - k * t->pad + (k - 1) / 2, even = k % 2 == 0;
    for (int J = 0; J < t->h; J++)
      for (int I = 0; I < t->w; I++) {
        const size_t u = (size_t)(lo + k * I), v = (size_t)(lo + k * J), W = (size_t)fw;
        double d = fine[v * W + u];
        if (even) {
          d = 0.0;
          for (int b = 0; b < 4; b++)
            for (int a = 0; a < 4; a++) d += mid[b] * mid[a] * fine[(v - 1 + (size_t)b) * W + u - 1 + (size_t)a];
          d = d > 0.0 ? d : 0.0; /* it may undershoot a little where the target falls to white */
        }
        t->dark[(size_t)J * (size_t)t->w + (size_t)I] = (float)d;
      }
  }
  if (fine != t->dark) free(fine);
  if (st) lw_tone_clear(t);
  return st;
}

void lw_tone_clear(lw_tone *t)
{
  free(t->dark);
  t->dark = NULL;
}

int64_t *lw_tone_raster_new(const lw_tone *t) { return calloc((size_t)t->w * (size_t)t->h, sizeof(int64_t)); }

/* The pixel column (or row) nearest to page coordinate c, in *k; 0 when the
** footprint around it misses [0, n) or c is not finite.  Decided in doubles
** so that no huge coordinate is converted to int. */
static int nearest(double c, double c0, double pixel, int radius, int n, int *k)
{
  double u = floor((c - c0) / pixel);
  if (!(u >= -radius && u < (double)n + radius)) return 0;
  *k = (int)u;
  return 1;
}

#if LW_VEC_HAVE_WIDE
/* g[0, n) /= d, eight at a time (AVX-512). */
__attribute__((target(LW_VEC_X8_TARGET))) static void divide8(double *g, int n, double d)
{
  const __m512d v = _mm512_set1_pd(d);
  for (int i = 0; i < n; i += 8) {
    const __mmask8 m = n - i >= 8 ? (__mmask8)0xff : (__mmask8)((1u << (n - i)) - 1u);
    _mm512_mask_storeu_pd(g + i, m, _mm512_div_pd(_mm512_maskz_loadu_pd(m, g + i), v));
  }
}
#endif

/* The distance d0 from c to the first of the 2 radius + 1 pixel centres
** around pixel k, and a0 = (2 d0 p + p^2) inv, the exponent of the ratio of
** its Gaussian to the next's; 1 where the Gaussians can go by products
** (weights_from), 0 where they would overflow (a blur well below a pixel). */
static int first_centre(const lw_tone *t, double c, double c0, int k, double *d0, double *a0)
{
  const double p = t->pixel;
  *d0 = c0 + (k - t->radius + 0.5) * p - c;
  *a0 = (2.0 * *d0 * p + p * p) * t->inv;
  return fabs(*a0) < 600.0 && *d0 * *d0 * t->inv < 600.0;
}

/* g[m] /= sum for m in [0, 2 R], where sum > 0; else all of the ink in the
** sample's own pixel, g[R] = 1 (a blur far below a pixel).  Divisions in
** vectors are the same correctly rounded quotients, several a step: one at a
** time they were half of the weights' time. */
static void normalise(double *g, int R, double sum, int x8)
{
  if (!(sum > 0.0)) g[R] = sum = 1.0;
#if LW_VEC_HAVE_WIDE
  if (x8) {
    divide8(g, 2 * R + 1, sum);
    return;
  }
#endif
#pragma omp simd
  for (int m = 0; m <= 2 * R; m++) g[m] /= sum;
}

/* The normalised weights of the 2 radius + 1 pixel centres around pixel k
** for a sample at c (d0, a0 and ok from first_centre): the Gaussian less its
** value at rho = radius pixels, 0 beyond.  Every centre outside the window
** is farther than rho from c, so the footprint is continuous in c as the
** window moves with the sample (a Gaussian cut at the window would jump by
** e^-4.5 of its peak there). */
static void weights_from(const lw_tone *t, double d0, double a0, int ok, double *g, int x8)
{
  const int R = t->radius;
  const double p = t->pixel, inv = t->inv, floor_ = t->floor;
  double sum = 0.0;
  if (ok) {
    /* exp(-d_m^2 inv) for d_m = d0 + m p by products: the ratio of
    ** neighbours is exp(-(2 d_m p + p^2) inv), itself falling by
    ** exp(-2 p^2 inv) (t->fall) a step.  Two exps an axis instead of 2 R + 1. */
    double e = exp(-d0 * d0 * inv), r = exp(-a0);
    const double c2 = t->fall;
    for (int m = 0; m <= 2 * R; m++) {
      g[m] = e > floor_ ? e - floor_ : 0.0;
      sum += g[m];
      e *= r;
      r *= c2;
    }
  } else {
    for (int m = 0; m <= 2 * R; m++) {
      double d = d0 + m * p;
      double e = exp(-d * d * inv);
      g[m] = e > floor_ ? e - floor_ : 0.0;
      sum += g[m];
    }
  }
  normalise(g, R, sum, x8);
}

/* weights_from on both axes where both go by products: the two chains of
** products interleaved (each is a chain of dependent multiplications, so
** one alone leaves the multiplier idle), each axis with the operations
** weights_from takes in its order, so the same bits. */
static void weights_xy(const lw_tone *t, double dx, double ax, double dy, double ay, double *gx, double *gy, int x8)
{
  const int R = t->radius;
  const double inv = t->inv, floor_ = t->floor, c2 = t->fall;
  double ex = exp(-dx * dx * inv), rx = exp(-ax), ey = exp(-dy * dy * inv), ry = exp(-ay), sx = 0.0, sy = 0.0;
  for (int m = 0; m <= 2 * R; m++) {
    gx[m] = ex > floor_ ? ex - floor_ : 0.0;
    gy[m] = ey > floor_ ? ey - floor_ : 0.0;
    sx += gx[m];
    sy += gy[m];
    ex *= rx;
    ey *= ry;
    rx *= c2;
    ry *= c2;
  }
  normalise(gx, R, sx, x8);
  normalise(gy, R, sy, x8);
}

/* The weights of a sample at (x, y) on both axes, around pixels ci and cj. */
static void weights(const lw_tone *t, double x, double y, int ci, int cj, double *gx, double *gy, int x8)
{
  double dx, ax, dy, ay;
  const int okx = first_centre(t, x, t->x0, ci, &dx, &ax), oky = first_centre(t, y, t->y0, cj, &dy, &ay);
  if (okx && oky) {
    weights_xy(t, dx, ax, dy, ay, gx, gy, x8);
    return;
  }
  weights_from(t, dx, ax, okx, gx, x8);
  weights_from(t, dy, ay, oky, gy, x8);
}

/* One raster pixel's share of a footprint: rounded (half up: v >= 0) from
** the sample alone, so its +1 and -1 cancel exactly; a cast, not llrint,
** which is a call into libm. */
static inline int64_t splat_units(double v)
{
  return (int64_t)((v < LW_TONE_CAP ? v : LW_TONE_CAP) * LW_TONE_ONE + 0.5);
}

/* A footprint's row, pixel by pixel; unsigned sums, whose wrap-around is
** defined and whose exact sums come out right. */
static void splat_row(int64_t *row, const double *g, int n, double ay, int sign)
{
  for (int i = 0; i < n; i++) {
    int64_t q = splat_units(ay * g[i]);
    row[i] = (int64_t)((uint64_t)row[i] + (uint64_t)(sign > 0 ? q : -q));
  }
}

#if LW_VEC_HAVE_WIDE
/* The same eight pixels a step where the processor has AVX-512 (F, DQ and
** VL, whose vcvttpd2qq truncates to 64-bit integers as the cast does): the
** scalar row's operations in its order, a product, the cap (min_pd(v, cap)
** is v < cap ? v : cap), a product and a sum without fused multiply-add,
** so the same integers. */
__attribute__((target(LW_VEC_X8_TARGET))) static void splat_row8(int64_t *row, const double *g, int n, double ay,
                                                                  int sign)
{
  const __m512d a = _mm512_set1_pd(ay), cap = _mm512_set1_pd(LW_TONE_CAP), one = _mm512_set1_pd(LW_TONE_ONE),
                half = _mm512_set1_pd(0.5);
  for (int i = 0; i < n; i += 8) {
    const __mmask8 m = n - i >= 8 ? (__mmask8)0xff : (__mmask8)((1u << (n - i)) - 1u);
    __m512d v = _mm512_min_pd(_mm512_mul_pd(a, _mm512_maskz_loadu_pd(m, g + i)), cap);
    __m512i q = _mm512_cvttpd_epi64(_mm512_add_pd(_mm512_mul_pd(v, one), half));
    if (sign < 0) q = _mm512_sub_epi64(_mm512_setzero_si512(), q);
    _mm512_mask_storeu_epi64(row + i, m, _mm512_add_epi64(_mm512_maskz_loadu_epi64(m, row + i), q));
  }
}
#endif

void lw_tone_splat(const lw_tone *t, int64_t *r, int wx, int wy, int ww, int wh, double x, double y, double dl,
                   int sign)
{
  const int R = t->radius;
  int ci, cj;
  if (!(dl > 0.0) || !nearest(x, t->x0, t->pixel, R, t->w, &ci) || !nearest(y, t->y0, t->pixel, R, t->h, &cj))
    return;
#if LW_VEC_HAVE_WIDE
  const int x8 = lw_vec_lanes() == LW_VEC_8;
#else
  const int x8 = 0;
#endif
  double gx[2 * LW_TONE_RADIUS_MAX + 1], gy[2 * LW_TONE_RADIUS_MAX + 1];
  weights(t, x, y, ci, cj, gx, gy, x8);
  /* the window within the raster, in raster pixels */
  int i0 = ci - R, i1 = ci + R + 1, j0 = cj - R, j1 = cj + R + 1;
  if (i0 < wx) i0 = wx;
  if (j0 < wy) j0 = wy;
  if (i1 > wx + ww) i1 = wx + ww;
  if (j1 > wy + wh) j1 = wy + wh;
  if (i0 < 0) i0 = 0;
  if (j0 < 0) j0 = 0;
  if (i1 > t->w) i1 = t->w;
  if (j1 > t->h) j1 = t->h;
  if (i0 >= i1) return;
  const double a = t->pen * dl / t->area;
  const double *g = gx + (i0 - ci + R);
  for (int j = j0; j < j1; j++) {
    const double ay = a * gy[j - cj + R];
    int64_t *row = r + (size_t)(j - wy) * (size_t)ww + (i0 - wx);
#if LW_VEC_HAVE_WIDE
    if (x8) {
      splat_row8(row, g, i1 - i0, ay, sign);
      continue;
    }
#endif
    splat_row(row, g, i1 - i0, ay, sign);
  }
}

/* The weights of weights() (at one exp a pixel: the gradient is not the
** chain's loop) and their derivatives with respect to the sample's
** coordinate c: for f = exp(-d^2 inv) - floor, d the pixel centre less c,
** df/dc = 2 d inv exp(-d^2 inv) where f > 0, and g = f / sum f. */
static void weight_slopes(const lw_tone *t, double c, double c0, int k, double *g, double *dg)
{
  const int R = t->radius;
  const double p = t->pixel, inv = t->inv, d0 = c0 + (k - R + 0.5) * p - c;
  double sum = 0.0, dsum = 0.0;
  for (int m = 0; m <= 2 * R; m++) {
    double d = d0 + m * p, e = exp(-d * d * inv);
    g[m] = e > t->floor ? e - t->floor : 0.0;
    dg[m] = e > t->floor ? 2.0 * d * inv * e : 0.0;
    sum += g[m];
    dsum += dg[m];
  }
  if (!(sum > 0.0)) { /* all of it in the sample's own pixel, wherever it lies in it */
    for (int m = 0; m <= 2 * R; m++) g[m] = dg[m] = 0.0;
    g[R] = 1.0;
    return;
  }
  for (int m = 0; m <= 2 * R; m++) {
    dg[m] = (dg[m] - g[m] * dsum / sum) / sum;
    g[m] /= sum;
  }
}

void lw_tone_sample_grad(const lw_tone *t, const int64_t *r, double coef, double x, double y, double dl,
                         double *ex, double *ey, double *edl)
{
  *ex = *ey = *edl = 0.0;
  const int R = t->radius;
  int ci, cj;
  if (!(dl > 0.0) || !nearest(x, t->x0, t->pixel, R, t->w, &ci) || !nearest(y, t->y0, t->pixel, R, t->h, &cj))
    return;
  double gx[2 * LW_TONE_RADIUS_MAX + 1], gy[2 * LW_TONE_RADIUS_MAX + 1];
  double dgx[2 * LW_TONE_RADIUS_MAX + 1], dgy[2 * LW_TONE_RADIUS_MAX + 1];
  weight_slopes(t, x, t->x0, ci, gx, dgx);
  weight_slopes(t, y, t->y0, cj, gy, dgy);
  int i0 = ci - R > 0 ? ci - R : 0, i1 = ci + R + 1 < t->w ? ci + R + 1 : t->w;
  int j0 = cj - R > 0 ? cj - R : 0, j1 = cj + R + 1 < t->h ? cj + R + 1 : t->h;
  double s = 0.0, sx = 0.0, sy = 0.0;
  for (int j = j0; j < j1; j++) {
    const int64_t *row = r + (size_t)j * (size_t)t->w;
    const float *dark = t->dark + (size_t)j * (size_t)t->w;
    const double wy = gy[j - cj + R], dwy = dgy[j - cj + R];
    double rs = 0.0, rsx = 0.0;
    for (int i = i0; i < i1; i++) {
      double res = (double)row[i] / LW_TONE_ONE - dark[i];
      rs += res * gx[i - ci + R];
      rsx += res * dgx[i - ci + R];
    }
    s += rs * wy;
    sx += rsx * wy;
    sy += rs * dwy;
  }
  /* dE/dB_p = 2 coef A (B_p - D_p), and the sample adds (pen dl / A) gx gy */
  const double k = 2.0 * coef * t->pen;
  *edl = k * s;
  *ex = k * dl * sx;
  *ey = k * dl * sy;
}

double lw_tone_energy(const lw_tone *t, const int64_t *r)
{
  const size_t n = (size_t)t->w * (size_t)t->h;
  double sum = 0.0;
  for (size_t k = 0; k < n; k++) {
    double e = (double)r[k] / LW_TONE_ONE - t->dark[k];
    sum += e * e;
  }
  return t->area * sum;
}

void lw_tone_box_reset(lw_tone_box *b) { b->x0 = b->y0 = b->x1 = b->y1 = 0; }

/* Pixels [*k0, *k1) of an axis of n pixels that the footprints of samples
** in [c0, c1] can reach, one to spare on each side; decided in doubles so
** that no huge coordinate is converted to int. */
static void reach(double c0, double c1, double origin, double pixel, int radius, int n, int *k0, int *k1)
{
  double u0 = floor((c0 - origin) / pixel) - radius - 1, u1 = floor((c1 - origin) / pixel) + radius + 2;
  if (!(u0 > 0.0)) u0 = 0.0; /* NaN too */
  if (!(u1 < (double)n)) u1 = (double)n;
  if (!(u0 < u1)) u0 = u1 = 0.0;
  *k0 = (int)u0;
  *k1 = (int)u1;
}

void lw_tone_box_cover(const lw_tone *t, lw_tone_box *b, double x0, double y0, double x1, double y1)
{
  int i0, i1, j0, j1;
  reach(x0, x1, t->x0, t->pixel, t->radius, t->w, &i0, &i1);
  reach(y0, y1, t->y0, t->pixel, t->radius, t->h, &j0, &j1);
  if (i0 >= i1 || j0 >= j1) return;
  if (b->x0 >= b->x1 || b->y0 >= b->y1) {
    *b = (lw_tone_box){i0, j0, i1, j1, b->d, b->cap};
    return;
  }
  if (i0 < b->x0) b->x0 = i0;
  if (j0 < b->y0) b->y0 = j0;
  if (i1 > b->x1) b->x1 = i1;
  if (j1 > b->y1) b->y1 = j1;
}

lw_status lw_tone_box_ready(lw_tone_box *b)
{
  size_t n = b->x0 < b->x1 && b->y0 < b->y1 ? (size_t)(b->x1 - b->x0) * (size_t)(b->y1 - b->y0) : 0;
  if (n > b->cap) {
    size_t cap = b->cap ? b->cap : 256;
    while (cap < n) cap *= 2;
    int64_t *d = realloc(b->d, cap * sizeof *d);
    if (!d) return LW_ENOMEM;
    b->d = d;
    b->cap = cap;
  }
  if (n) memset(b->d, 0, n * sizeof *b->d);
  return LW_OK;
}

void lw_tone_box_free(lw_tone_box *b)
{
  free(b->d);
  b->d = NULL;
  b->cap = 0;
}

void lw_tone_box_splat(const lw_tone *t, lw_tone_box *b, double x, double y, double dl, int sign)
{
  if (b->x0 < b->x1 && b->y0 < b->y1) lw_tone_splat(t, b->d, b->x0, b->y0, b->x1 - b->x0, b->y1 - b->y0, x, y, dl, sign);
}

/*
** dE / T of a box: the sum over its pixels of A db (2 e + db), e the
** raster's ink less the darkness and db the box's change, both in ink
** fractions (the fixed point times 2^-32, exact), which is (e + db)^2 - e^2
** without the cancellation of two large squares.  Each row's pixels go into
** eight lanes, pixel i (from the box's left edge) into lane i mod 8, folded
** as ((0 + 4) + (1 + 5)) + ((2 + 6) + (3 + 7)); the rows' sums are added in
** order.  So eight pixels a step in one AVX-512 vector give the scalar
** loop's bits.  Pixels the box leaves unchanged (most of a box around a
** moved segment) add exact zeros, which change no sum.
*/
#define TONE_UNIT (1.0 / LW_TONE_ONE)

static double fold8(const double *l) { return ((l[0] + l[4]) + (l[1] + l[5])) + ((l[2] + l[6]) + (l[3] + l[7])); }

static double delta_row(const int64_t *row, const int64_t *d, const float *dark, int n)
{
  double lane[8] = {0};
  for (int i = 0; i < n; i++) {
    const double e = (double)row[i] * TONE_UNIT - (double)dark[i], db = (double)d[i] * TONE_UNIT;
    lane[i & 7] += db * (2.0 * e + db);
  }
  return fold8(lane);
}

#if LW_VEC_HAVE_WIDE
/* The same, eight lanes in one vector (vcvtqq2pd converts as the cast does:
** correctly rounded), without fused multiply-add. */
__attribute__((target(LW_VEC_X8_TARGET))) static double delta_row8(const int64_t *row, const int64_t *d,
                                                                    const float *dark, int n)
{
  const __m512d unit = _mm512_set1_pd(TONE_UNIT), two = _mm512_set1_pd(2.0);
  __m512d acc = _mm512_setzero_pd();
  for (int i = 0; i < n; i += 8) {
    const __mmask8 m = n - i >= 8 ? (__mmask8)0xff : (__mmask8)((1u << (n - i)) - 1u);
    const __m512d e = _mm512_sub_pd(_mm512_mul_pd(_mm512_cvtepi64_pd(_mm512_maskz_loadu_epi64(m, row + i)), unit),
                                    _mm512_cvtps_pd(_mm256_maskz_loadu_ps(m, dark + i)));
    const __m512d db = _mm512_mul_pd(_mm512_cvtepi64_pd(_mm512_maskz_loadu_epi64(m, d + i)), unit);
    acc = _mm512_mask_add_pd(acc, m, acc, _mm512_mul_pd(db, _mm512_add_pd(_mm512_mul_pd(two, e), db)));
  }
  double lane[8];
  _mm512_storeu_pd(lane, acc);
  return fold8(lane);
}
#endif

double lw_tone_delta(const lw_tone *t, const int64_t *r, const lw_tone_box *b)
{
  const int bw = b->x1 - b->x0;
#if LW_VEC_HAVE_WIDE
  const int x8 = lw_vec_lanes() == LW_VEC_8;
#endif
  double sum = 0.0;
  for (int j = b->y0; j < b->y1; j++) {
    const int64_t *d = b->d + (size_t)(j - b->y0) * (size_t)bw;
    const int64_t *row = r + (size_t)j * (size_t)t->w + b->x0;
    const float *dark = t->dark + (size_t)j * (size_t)t->w + b->x0;
#if LW_VEC_HAVE_WIDE
    if (x8) {
      sum += delta_row8(row, d, dark, bw);
      continue;
    }
#endif
    sum += delta_row(row, d, dark, bw);
  }
  return t->area * sum;
}

void lw_tone_apply(const lw_tone *t, int64_t *r, const lw_tone_box *b)
{
  const int bw = b->x1 - b->x0;
  for (int j = b->y0; j < b->y1; j++) {
    const int64_t *d = b->d + (size_t)(j - b->y0) * (size_t)bw;
    int64_t *row = r + (size_t)j * (size_t)t->w + b->x0;
    for (int i = 0; i < bw; i++) row[i] = (int64_t)((uint64_t)row[i] + (uint64_t)d[i]);
  }
}
