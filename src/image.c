/*
** image.c -- pictures as planes of tone: loading, resampling, blur and the
** tone curve (image.h).
**
** Resampling is separable and streamed: every output pixel is a weighted sum
** of source pixels, the weights ("taps") factor into a column part and a row
** part, and source rows are fed one at a time.  A row is first resampled
** along x, then added with its row weights into every output row it feeds.
** The loader feeds rows straight from stb_image's buffer, so a picture far
** above the pixel budget never exists as a full-size float plane.
*/
#include "linewise/image.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <zlib.h>

#include "stb_image_impl.h"

static float *plane_alloc(int w, int h)
{
  size_t n = (size_t)w * (size_t)h;
  if (w < 1 || h < 1 || n > SIZE_MAX / sizeof(float)) return NULL;
  return malloc(n * sizeof(float));
}

static void plane_fill(float *p, size_t n, float v)
{
  for (size_t k = 0; k < n; k++) p[k] = v;
}

lw_image *lw_image_new(int w, int h, int with_alpha, lw_error *err)
{
  if (w < 1 || h < 1) {
    lw_error_set(err, LW_EINPUT, "an image of %d x %d pixels is empty", w, h);
    return NULL;
  }
  lw_image *img = calloc(1, sizeof *img);
  if (!img) goto nomem;
  img->width = w;
  img->height = h;
  img->tone = plane_alloc(w, h);
  if (with_alpha) img->alpha = plane_alloc(w, h);
  if (!img->tone || (with_alpha && !img->alpha)) {
    lw_image_free(img);
    goto nomem;
  }
  size_t n = (size_t)w * (size_t)h;
  plane_fill(img->tone, n, 1.0f);
  if (img->alpha) plane_fill(img->alpha, n, 1.0f);
  return img;
nomem:
  lw_error_set(err, LW_ENOMEM, "out of memory for an image of %d x %d pixels", w, h);
  return NULL;
}

void lw_image_free(lw_image *img)
{
  if (!img) return;
  free(img->tone);
  free(img->alpha);
  free(img);
}

/* ---- separable resampling ------------------------------------------- */

/* The taps of one axis: output k reads source idx[t] with weight w[t] for
** t in [start[k], start[k + 1]). */
typedef struct {
  int *start, *idx;
  float *w;
} axis_taps;

static void taps_free(axis_taps *t)
{
  free(t->start);
  free(t->idx);
  free(t->w);
}

/* Shrinking (n_out <= n_in): output k covers the source interval
** [k r, (k + 1) r), r = n_in / n_out, and averages it, partial pixels at
** its ends weighted by the overlap -- every source pixel then gives weight
** 1/r in all, so the mean is kept.  Enlarging: linear interpolation at
** the output pixel's centre, (k + 1/2) r - 1/2 in source pixel units,
** clamped to the first and last source centres. */
static int taps_build(axis_taps *t, int n_in, int n_out)
{
  const double r = (double)n_in / (double)n_out;
  size_t per = r >= 1.0 ? (size_t)ceil(r) + 2 : 2, cap = per * (size_t)n_out;
  t->start = malloc(((size_t)n_out + 1) * sizeof *t->start);
  t->idx = malloc(cap * sizeof *t->idx);
  t->w = malloc(cap * sizeof *t->w);
  if (!t->start || !t->idx || !t->w) return 0;
  int n = 0;
  for (int k = 0; k < n_out; k++) {
    t->start[k] = n;
    if (r >= 1.0) {
      double a = (double)k * n_in / n_out, b = (double)(k + 1) * n_in / n_out;
      int last = (int)ceil(b) - 1;
      if (last > n_in - 1) last = n_in - 1;
      for (int i = (int)floor(a); i <= last; i++) {
        double overlap = fmin(i + 1.0, b) - fmax((double)i, a);
        if (overlap > 0) {
          t->idx[n] = i;
          t->w[n++] = (float)(overlap / r);
        }
      }
    } else {
      double u = (k + 0.5) * r - 0.5;
      if (u < 0) u = 0;
      if (u > n_in - 1) u = n_in - 1;
      int i0 = (int)floor(u);
      double f = u - i0;
      t->idx[n] = i0;
      t->w[n++] = (float)(1.0 - f);
      if (i0 + 1 < n_in && f > 0) {
        t->idx[n] = i0 + 1;
        t->w[n++] = (float)f;
      }
    }
  }
  t->start[n_out] = n;
  return 1;
}

typedef struct {
  int w_in, h_in, w_out, h_out;
  axis_taps x;           /* per output column */
  int *rstart;       /* h_in + 1: source row j feeds the entries [rstart[j], rstart[j+1]) */
  int *rout;         /* ... of output row rout[e] */
  float *rw;         /* ... with weight rw[e] */
  float *hrow;       /* w_out scratch */
} resampler;

static void resampler_free(resampler *rs)
{
  taps_free(&rs->x);
  free(rs->rstart);
  free(rs->rout);
  free(rs->rw);
  free(rs->hrow);
}

/* The row taps are built per output row, then turned around (a counting
** sort by source row) so that each source row knows where it goes. */
static lw_status resampler_init(resampler *rs, int w_in, int h_in, int w_out, int h_out, lw_error *err)
{
  memset(rs, 0, sizeof *rs);
  rs->w_in = w_in;
  rs->h_in = h_in;
  rs->w_out = w_out;
  rs->h_out = h_out;
  axis_taps y = {0};
  int ok = taps_build(&rs->x, w_in, w_out) && taps_build(&y, h_in, h_out);
  if (ok) {
    int n = y.start[h_out];
    rs->rstart = calloc((size_t)h_in + 1, sizeof *rs->rstart);
    rs->rout = malloc(((size_t)n + 1) * sizeof *rs->rout);
    rs->rw = malloc(((size_t)n + 1) * sizeof *rs->rw);
    rs->hrow = malloc((size_t)w_out * sizeof *rs->hrow);
    ok = rs->rstart && rs->rout && rs->rw && rs->hrow;
    if (ok) {
      for (int e = 0; e < n; e++) rs->rstart[y.idx[e] + 1]++;
      for (int j = 0; j < h_in; j++) rs->rstart[j + 1] += rs->rstart[j];
      int *fill = malloc(((size_t)h_in + 1) * sizeof *fill);
      ok = fill != NULL;
      if (ok) {
        memcpy(fill, rs->rstart, ((size_t)h_in + 1) * sizeof *fill);
        for (int k = 0; k < h_out; k++)
          for (int e = y.start[k]; e < y.start[k + 1]; e++) {
            int slot = fill[y.idx[e]]++;
            rs->rout[slot] = k;
            rs->rw[slot] = y.w[e];
          }
        free(fill);
      }
    }
  }
  taps_free(&y);
  if (!ok) {
    resampler_free(rs);
    return lw_error_set(err, LW_ENOMEM, "out of memory resampling %d x %d to %d x %d pixels", w_in, h_in,
                        w_out, h_out);
  }
  return LW_OK;
}

/* Adds source row j (w_in values) into the output plane (w_out x h_out,
** zeroed before the first row). */
static void resampler_add_row(resampler *rs, int j, const float *row, float *out)
{
  const axis_taps *x = &rs->x;
  for (int k = 0; k < rs->w_out; k++) {
    float s = 0.0f;
    for (int t = x->start[k]; t < x->start[k + 1]; t++) s += x->w[t] * row[x->idx[t]];
    rs->hrow[k] = s;
  }
  for (int e = rs->rstart[j]; e < rs->rstart[j + 1]; e++) {
    float *o = out + (size_t)rs->rout[e] * (size_t)rs->w_out, w = rs->rw[e];
    for (int k = 0; k < rs->w_out; k++) o[k] += w * rs->hrow[k];
  }
}

static void plane_clamp01(float *p, size_t n)
{
  for (size_t k = 0; k < n; k++) p[k] = p[k] < 0.0f ? 0.0f : (p[k] > 1.0f ? 1.0f : p[k]);
}

lw_image *lw_image_resize(const lw_image *src, int w, int h, lw_error *err)
{
  lw_image *img = lw_image_new(w, h, src->alpha != NULL, err);
  if (!img) return NULL;
  resampler rs;
  if (resampler_init(&rs, src->width, src->height, w, h, err)) {
    lw_image_free(img);
    return NULL;
  }
  size_t n = (size_t)w * (size_t)h, sw = (size_t)src->width;
  plane_fill(img->tone, n, 0.0f);
  if (img->alpha) plane_fill(img->alpha, n, 0.0f);
  for (int j = 0; j < src->height; j++) {
    resampler_add_row(&rs, j, src->tone + (size_t)j * sw, img->tone);
    if (img->alpha) resampler_add_row(&rs, j, src->alpha + (size_t)j * sw, img->alpha);
  }
  resampler_free(&rs);
  /* float sums of weights that add to 1 can land a hair outside [0, 1] */
  plane_clamp01(img->tone, n);
  if (img->alpha) plane_clamp01(img->alpha, n);
  return img;
}

/* ---- loading -------------------------------------------------------- */

/* Source row j of a decoded buffer as tone (the luma, or one colour
** channel) and alpha in [0, 1]; alpha is written only for 2 and 4
** channels.  Tone is composited over white. */
static void decoded_row(const void *pix, int bits, int w, int ch, int j, lw_image_channel which, float *tone,
                        float *alpha)
{
  const float scale = bits == 16 ? 1.0f / 65535.0f : 1.0f / 255.0f;
  size_t base = (size_t)j * (size_t)w * (size_t)ch;
  for (int i = 0; i < w; i++) {
    float c[4] = {0, 0, 0, 0};
    for (int k = 0; k < ch; k++) {
      size_t at = base + (size_t)i * (size_t)ch + (size_t)k;
      c[k] = scale * (bits == 16 ? (float)((const uint16_t *)pix)[at] : (float)((const unsigned char *)pix)[at]);
    }
    float g = ch < 3                                             ? c[0]
              : which == LW_IMAGE_LUMA || which == LW_IMAGE_MASK ? 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]
                                                                 : c[which - LW_IMAGE_RED];
    float a = ch == 2 ? c[1] : ch == 4 ? c[3] : 1.0f;
    tone[i] = a * g + (1.0f - a);
    if (which == LW_IMAGE_MASK) tone[i] = tone[i] < 0.5f ? 0.0f : 1.0f;
    if (ch == 2 || ch == 4) alpha[i] = a;
  }
}

/* Decoded pixels: w x h samples of ch channels, 8 or 16 bits each. */
typedef struct {
  const void *pix;
  void *owned;       /* what to free: stb's buffer, ours, or NULL (pix points into the file) */
  int from_stb;
  int w, h, ch, bits;
} decoded;

static void decoded_free(decoded *d)
{
  if (d->from_stb) stbi_image_free(d->owned);
  else free(d->owned);
}

/* Binary netpbm (P5 gray, P6 RGB), read here rather than by stb_image,
** whose version in Debian reads 16-bit samples in the wrong byte order,
** ignores maxval and does not notice a truncated raster.  The header is
** "P5" or "P6", then width, height and maxval separated by white space and
** '#' comments, then one white space character and the raster, row 0 first,
** 16-bit samples big-endian when maxval > 255. */
static int pnm_number(const unsigned char *d, size_t n, size_t *at, long *v)
{
  for (;;) {
    while (*at < n && strchr(" \t\r\n\v\f", d[*at]) && d[*at]) (*at)++;
    if (*at < n && d[*at] == '#')
      while (*at < n && d[*at] != '\n') (*at)++;
    else break;
  }
  if (*at >= n || d[*at] < '0' || d[*at] > '9') return 0;
  *v = 0;
  while (*at < n && d[*at] >= '0' && d[*at] <= '9') {
    *v = 10 * *v + (d[*at] - '0');
    if (*v > 1L << 30) return 0;
    (*at)++;
  }
  return 1;
}

/* The P5/P6 header: sizes, maxval and where the raster starts (*at). */
static lw_status pnm_header(const unsigned char *d, size_t n, const char *name, long *w_out, long *h_out,
                            long *maxval_out, size_t *at_out, lw_error *err)
{
  size_t at = 2;
  long w, h, maxval;
  if (!pnm_number(d, n, &at, &w) || !pnm_number(d, n, &at, &h) || !pnm_number(d, n, &at, &maxval) || at >= n ||
      !strchr(" \t\r\n\v\f", d[at]) || !d[at])
    return lw_error_set(err, LW_EINPUT, "%s: not an image linewise reads: a malformed PGM/PPM header", name);
  at++;
  if (w < 1 || h < 1 || maxval < 1 || maxval > 65535)
    return lw_error_set(err, LW_EINPUT, "%s: PGM/PPM of %ld x %ld pixels, maxval %ld: expected sizes >= 1 and "
                        "maxval 1 to 65535", name, w, h, maxval);
  if ((double)w * (double)h > LW_IMAGE_MAX_PIXELS)
    return lw_error_set(err, LW_EINPUT, "%s: %ld x %ld pixels is more than the %.0e pixels linewise decodes", name,
                        w, h, (double)LW_IMAGE_MAX_PIXELS);
  *w_out = w;
  *h_out = h;
  *maxval_out = maxval;
  *at_out = at;
  return LW_OK;
}

static lw_status pnm_decode(const unsigned char *d, size_t n, const char *name, decoded *out, lw_error *err)
{
  size_t at;
  long w, h, maxval;
  lw_status st = pnm_header(d, n, name, &w, &h, &maxval, &at, err);
  if (st) return st;
  int ch = d[1] == '6' ? 3 : 1, wide = maxval > 255;
  size_t samples = (size_t)w * (size_t)h * (size_t)ch, bytes = samples * (wide ? 2 : 1);
  if (n - at < bytes)
    return lw_error_set(err, LW_EINPUT, "%s: truncated: %zu of the %zu bytes of pixels are there", name, n - at,
                        bytes);
  *out = (decoded){d + at, NULL, 0, (int)w, (int)h, ch, 8};
  if (maxval == 255) return LW_OK; /* the raster is already what decoded_row reads */
  uint16_t *v = malloc(samples * sizeof *v);
  if (!v) return lw_error_set(err, LW_ENOMEM, "%s: out of memory for %zu samples", name, samples);
  const unsigned char *r = d + at;
  for (size_t k = 0; k < samples; k++) {
    long x = wide ? (long)r[2 * k] << 8 | r[2 * k + 1] : (long)r[k];
    if (x > maxval) { /* Netpbm forbids it; clamped, a damaged file drew as white */
      free(v);
      return lw_error_set(err, LW_EINPUT, "%s: the %s is damaged: the sample at row %zu, column %zu is %ld, above "
                          "its maxval %ld", name, ch == 3 ? "PPM" : "PGM", k / ((size_t)w * (size_t)ch) + 1,
                          k / (size_t)ch % (size_t)w + 1, x, maxval);
    }
    v[k] = (uint16_t)((x * 65535 + maxval / 2) / maxval);
  }
  *out = (decoded){v, v, 0, (int)w, (int)h, ch, 16};
  return LW_OK;
}

static uint32_t le32(const unsigned char *p)
{
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* stb_image reads missing bytes at the end of a BMP as zeros; an
** uncompressed one (BI_RGB or BI_BITFIELDS) must hold its whole raster:
** |height| rows of width * bpp bits, padded to 4 bytes, after the offset. */
static lw_status bmp_complete(const unsigned char *d, size_t n, const char *name, lw_error *err)
{
  if (n < 30 || d[0] != 'B' || d[1] != 'M' || le32(d + 14) < 40) return LW_OK;
  uint32_t offset = le32(d + 10), compression = n >= 34 ? le32(d + 30) : 0;
  int32_t w = (int32_t)le32(d + 18), h = (int32_t)le32(d + 22);
  unsigned bpp = (unsigned)d[28] | (unsigned)d[29] << 8;
  /* the decoder reads no run-length BMP (ImageMagick writes grey ones so),
  ** and its "not of any known type" hid why */
  if (compression == 1 || compression == 2)
    return lw_error_set(err, LW_EINPUT, "%s: a run-length (RLE%d) BMP, which the decoder does not read: save it "
                        "uncompressed or as PNG", name, compression == 1 ? 8 : 4);
  if (compression != 0 && compression != 3) return LW_OK;
  double row = 4.0 * floor(((double)bpp * fabs((double)w) + 31) / 32), need = offset + row * fabs((double)h);
  if ((double)n < need)
    return lw_error_set(err, LW_EINPUT, "%s: truncated: the BMP needs %.0f bytes, the file has %zu", name, need, n);
  return LW_OK;
}

static uint32_t be32(const unsigned char *p)
{
  return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

/* stb_image checks no PNG's CRCs, and a bit flipped inside the compressed
** pixels mostly still decodes, to other pixels (9 of 12 random flips drew,
** one with tones off by 89/255).  Every chunk carries a CRC-32 of its type
** and data (zlib's, the PNG one), and every one is checked, but for the
** chunks known to change nothing drawn (text, colour profile and gamma,
** which nothing here reads; APNG's later frames), which pass damaged as
** libpng lets them: a run begun on such a picture resumes.  Judged by a
** list of harmless names, not by the type's ancillary bit, which a flipped
** bit can set (a tRNS read as "tRnS" dropped the transparency unseen).  A
** file that ends before IEND is cut short.  A fuzzing build skips the
** CRCs: a fuzzer's mutations would stop here and never reach the decoder. */
#ifndef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
static int png_chunk_harmless(const unsigned char *type)
{
  static const char names[][5] = {"tEXt", "zTXt", "iTXt", "iCCP", "gAMA", "cHRM", "sRGB", "sBIT", "bKGD", "hIST",
                                  "pHYs", "sPLT", "tIME", "acTL", "fcTL", "fdAT", "oFFs", "pCAL", "sCAL", "sTER"};
  for (size_t k = 0; k < sizeof names / sizeof names[0]; k++)
    if (!memcmp(type, names[k], 4)) return 1;
  return 0;
}
#endif

static lw_status png_chunks_sound(const unsigned char *d, size_t n, const char *name, lw_error *err)
{
  if (n < 8 || memcmp(d, "\x89PNG\r\n\x1a\n", 8)) return LW_OK;
  for (size_t at = 8; at < n;) {
    if (n - at < 12)
      return lw_error_set(err, LW_EINPUT, "%s: the PNG is damaged or cut short: it ends at byte %zu inside a chunk's "
                          "header, before its IEND chunk", name, n);
    const uint32_t len = be32(d + at);
    char type[5];
    for (int k = 0; k < 4; k++) type[k] = d[at + 4 + k] >= 0x20 && d[at + 4 + k] < 0x7F ? (char)d[at + 4 + k] : '?';
    type[4] = '\0';
    if (len > 0x7FFFFFFFu || n - at - 12 < len)
      return lw_error_set(err, LW_EINPUT, "%s: the PNG is damaged or cut short: its chunk '%s' at byte %zu holds %u "
                          "bytes, the file has %zu after its header", name, type, at, (unsigned)len, n - at - 12);
#ifndef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
    const uLong crc = crc32(crc32(0L, Z_NULL, 0), d + at + 4, (uInt)len + 4);
    if (!png_chunk_harmless(d + at + 4) && crc != be32(d + at + 8 + len))
      return lw_error_set(err, LW_EINPUT, "%s: the PNG is damaged: its chunk '%s' at byte %zu fails its CRC check",
                          name, type, at);
#endif
    if (!memcmp(d + at + 4, "IEND", 4)) return LW_OK;
    if (at == 8 && !memcmp(d + at + 4, "IHDR", 4) && len >= 8 && (!be32(d + 16) || !be32(d + 20)))
      return lw_error_set(err, LW_EINPUT, "%s: the PNG is damaged: %u x %u pixels", name, (unsigned)be32(d + 16),
                          (unsigned)be32(d + 20));
    at += 12 + (size_t)len;
  }
  return lw_error_set(err, LW_EINPUT, "%s: the PNG is damaged or cut short: it ends at byte %zu without its IEND "
                      "chunk", name, n);
}

/* A GIF whose screen (the picture's size, which the decoder fills) is
** large and its first picture's LZW data could not paint a quarter of it:
** a 35-byte file that said 23000 x 23000 was decoded, 2 GB, all of it
** background.  Each code is code + 1 bits or more, and the k-th paints at
** most k + 1 pixels, 4096 past the table's end: a bound no real picture
** comes near.  Up to 2e7 pixels (80 MB decoded) a small picture on a large
** screen is decoded as before (a crop ImageMagick kept on its canvas). */
static lw_status gif_data_enough(const unsigned char *d, const unsigned char *image, double data, unsigned code,
                                 const char *name, lw_error *err)
{
  const double w = d[6] | d[7] << 8, h = d[8] | d[9] << 8, codes = floor(8.0 * data / (code + 1.0));
  const double full = fmin(codes, 4095.0), most = full * (full + 3.0) / 2.0 + (codes - full) * 4096.0;
  if (w * h <= 2e7 || 4.0 * most >= w * h) return LW_OK;
  return lw_error_set(err, LW_EINPUT, "%s: a GIF whose %.0f x %.0f screen its first picture (%d x %d, %.0f bytes of "
                      "data) can paint at most %.0f pixels of: damaged, or made to take memory; expected a picture "
                      "that covers its screen", name, w, h, image[5] | image[6] << 8, image[7] | image[8] << 8, data,
                      most);
}

/* stb_image reads missing bytes at the end of a GIF as zeros too, so a
** cut file decodes to a picture with a black or garbled foot.  The blocks
** are walked to the end of the first picture's data (the one decoded): the
** screen descriptor and global colour table, then extensions (a label and
** sub-blocks) up to the image descriptor, its local colour table, the LZW
** code size and its data sub-blocks, each a length byte and that many
** bytes, up to the empty one. */
static lw_status gif_complete(const unsigned char *d, size_t n, const char *name, lw_error *err)
{
  if (n < 13 || memcmp(d, "GIF8", 4)) return LW_OK;
  size_t at = 13;
  if (d[10] & 0x80) at += 3u << ((d[10] & 7) + 1);
  while (at < n && d[at] != 0x2C) {
    if (d[at] != 0x21) return LW_OK; /* the trailer or a stray byte: the decoder's to refuse */
    at += 2;
    while (at < n && d[at]) at += (size_t)d[at] + 1;
    at++;
  }
  if (at + 10 <= n) {
    const unsigned char *image = d + at;
    unsigned flags = d[at + 9];
    at += 10 + ((flags & 0x80) ? 3u << ((flags & 7) + 1) : 0u);
    const unsigned code = at < n ? d[at] : 0; /* the LZW minimum code size */
    double data = 0;
    for (at++; at < n && d[at]; at += (size_t)d[at] + 1) data += d[at];
    if (at < n) return gif_data_enough(d, image, data, code, name, err);
  }
  return lw_error_set(err, LW_EINPUT, "%s: truncated: the GIF's first picture runs past the end of the file (%zu bytes)",
                      name, n);
}

/* A byte of d as stb_image reads it: 0 past the end. */
static unsigned byte_at(const unsigned char *d, size_t n, size_t at) { return at < n ? d[at] : 0u; }

/* stb_image 2.27 (Debian's libstb) builds a JPEG Huffman table without
** checking that its 16 code counts sum to at most 256, and writes past the
** table when they do; and a scan that names a Huffman or quantization
** table no segment defined reads the decoder's uninitialised memory, so
** that the picture, or whether it decodes at all, changes from run to run
** (both found by tests/fuzz/fuzz_image.c).  Every table of every DHT
** segment the decoder could reach is checked first, and every scan's
** tables: the DC table where a scan starts the DC coefficients, the AC
** table where it codes any AC one, the quantization table of each of its
** components.  The markers are walked as the decoder walks them: bytes
** that are not 0xFF skipped one by one, fill bytes 0xFF before a marker
** (the start marker too), segments by their lengths, and after a scan's
** header its entropy-coded data up to the next 0xFF that is neither a
** stuffed zero, a fill byte nor a restart marker.  A frame the decoder does
** not read (12 bits, lossless, arithmetic-coded) is named here, where its
** own message would say "not an image". */
static lw_status jpeg_tables_sound(const unsigned char *d, size_t n, const char *name, lw_error *err)
{
  size_t at = 0;
  while (at < n && d[at] == 0xFF) at++; /* the decoder takes fill bytes before the start marker too */
  if (at == 0 || at >= n || d[at] != 0xD8) return LW_OK;
  at++;
  /* the tables defined so far: Huffman DC 0-3 and AC 4-7, quantization 0-3;
  ** the frame's components (id and quantization table) */
  unsigned huffman = 0, quant = 0, frame_quant[4] = {0, 0, 0, 0};
  int frame_id[4] = {-1, -1, -1, -1};
  while (at < n) {
    if (d[at] != 0xFF) {
      at++;
      continue;
    }
    while (at < n && d[at] == 0xFF) at++;
    if (at >= n) break;
    const unsigned marker = d[at++];
    if (marker == 0xD9) break;
    if (marker == 0x00 || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD8)) continue;
    const size_t len = byte_at(d, n, at) << 8 | byte_at(d, n, at + 1);
    if (marker == 0xC4)
      for (size_t t = at + 2; t < at + len && t < n;) {
        const unsigned q = d[t];
        if (q >> 4 > 1 || (q & 15) > 3) break; /* refused by the decoder itself */
        size_t count = 0;
        for (size_t i = 1; i <= 16; i++) count += byte_at(d, n, t + i);
        if (count > 256)
          return lw_error_set(err, LW_EINPUT, "%s: the JPEG is damaged: a Huffman table of %zu codes (256 at most)",
                              name, count);
        huffman |= 1u << ((q >> 4) * 4 + (q & 15));
        t += 17 + count;
      }
    else if (marker == 0xDB)
      for (size_t t = at + 2; t < at + len && t < n && (d[t] & 15) <= 3; t += 1 + (d[t] >> 4 ? 128 : 64))
        quant |= 1u << (d[t] & 15);
    else if (marker >= 0xC3 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC)
      /* the decoder's message would call it no image at all */
      return lw_error_set(err, LW_EINPUT, "%s: %s JPEG, which the decoder does not read: expected a baseline or "
                          "progressive one (save it again as such)", name,
                          marker >= 0xC9 ? "an arithmetic-coded" : marker == 0xC3 ? "a lossless" : "a hierarchical");
    else if (marker >= 0xC0 && marker <= 0xC2 && byte_at(d, n, at + 2) != 8)
      return lw_error_set(err, LW_EINPUT, "%s: a %u-bit JPEG, which the decoder does not read: expected 8 bits (save "
                          "it again as such)", name, byte_at(d, n, at + 2));
    else if (marker >= 0xC0 && marker <= 0xC2)
      for (unsigned c = 0; c < byte_at(d, n, at + 7) && c < 4; c++) {
        frame_id[c] = (int)byte_at(d, n, at + 8 + 3 * c);
        frame_quant[c] = byte_at(d, n, at + 10 + 3 * c) & 15;
      }
    else if (marker == 0xDA) {
      const unsigned ns = byte_at(d, n, at + 2), ss = byte_at(d, n, at + 3 + 2 * ns),
                     se = byte_at(d, n, at + 4 + 2 * ns), ah = byte_at(d, n, at + 5 + 2 * ns) >> 4;
      for (unsigned c = 0; c < ns && c < 4; c++) {
        const unsigned id = byte_at(d, n, at + 3 + 2 * c), q = byte_at(d, n, at + 4 + 2 * c);
        unsigned need = (ss == 0 && ah == 0 ? 1u << (q >> 4) : 0u) | (se > 0 ? 1u << (4 + (q & 15)) : 0u);
        for (int f = 0; f < 4; f++)
          if (frame_id[f] == (int)id) need |= 1u << (8 + frame_quant[f]);
        if (need & ~(huffman | quant << 8))
          return lw_error_set(err, LW_EINPUT, "%s: the JPEG is damaged: a scan uses a %s table it never defined",
                              name, need & ~(huffman | quant << 8) & 0xFF ? "Huffman" : "quantization");
      }
    }
    at += len;
    if (marker == 0xDA)
      while (at + 1 < n && !(d[at] == 0xFF && d[at + 1] != 0x00 && d[at + 1] != 0xFF &&
                             !(d[at + 1] >= 0xD0 && d[at + 1] <= 0xD7)))
        at++;
  }
  return LW_OK;
}

static uint32_t tiff32(const unsigned char *p, int be)
{
  return be ? be32(p) : le32(p);
}

/* The segments of a JPEG before its first scan, one a call: *at starts at
** 0; returns 1 with the marker and its payload (seg, len), 0 at the scan,
** the end or anything malformed.  Fill bytes 0xFF may stand before any
** marker, as the decoder allows; every length is checked against the file. */
static int jpeg_segment(const unsigned char *d, size_t n, size_t *at, unsigned *marker, const unsigned char **seg,
                        size_t *len)
{
  size_t i = *at;
  if (i == 0) {
    while (i < n && d[i] == 0xFF) i++;
    if (i == 0 || i >= n || d[i] != 0xD8) return 0;
    i++;
  }
  if (i >= n || d[i] != 0xFF) return 0;
  while (i < n && d[i] == 0xFF) i++;
  if (i + 3 > n) return 0;
  const unsigned m = d[i];
  const size_t l = (size_t)d[i + 1] << 8 | d[i + 2];
  if (m == 0xDA || m == 0xD9 || l < 2 || i + 1 + l > n) return 0;
  *marker = m, *seg = d + i + 3, *len = l - 2, *at = i + 1 + l;
  return 1;
}

/* The orientation (1 to 8) in an EXIF block t of tn bytes (a TIFF header,
** then IFD0 with tag 0x0112); 1 when there is none or it cannot be read.
** Every offset is checked against the block: a bad one means "none". */
static int tiff_orientation(const unsigned char *t, size_t tn)
{
  if (tn < 8) return 1;
  int be = t[0] == 'M' && t[1] == 'M';
  if (!be && !(t[0] == 'I' && t[1] == 'I')) return 1;
  uint32_t ifd = tiff32(t + 4, be);
  if (ifd > tn || tn - ifd < 2) return 1;
  unsigned count = be ? (unsigned)t[ifd] << 8 | t[ifd + 1] : (unsigned)t[ifd] | (unsigned)t[ifd + 1] << 8;
  for (unsigned e = 0; e < count && (size_t)ifd + 2 + 12 * ((size_t)e + 1) <= tn; e++) {
    const unsigned char *q = t + ifd + 2 + 12 * e;
    unsigned tag = be ? (unsigned)q[0] << 8 | q[1] : (unsigned)q[0] | (unsigned)q[1] << 8;
    if (tag != 0x0112) continue;
    unsigned v = be ? (unsigned)q[8] << 8 | q[9] : (unsigned)q[8] | (unsigned)q[9] << 8;
    return v >= 1 && v <= 8 ? (int)v : 1;
  }
  return 1;
}

/*
** The EXIF orientation of a JPEG or PNG (1 to 8; 1 when there is none or it
** cannot be read): a camera stores the sensor's rows and says how to turn
** them for display, so a phone's portrait photograph is stored on its side.
** A JPEG's markers before the first scan are walked to an APP1 segment
** "Exif\0\0" (fill bytes 0xFF may stand before any marker, as the decoder
** allows); a PNG's chunks to its eXIf chunk (a phone's screenshot, a
** converted photograph), before the image data or after it.
*/
static int exif_orientation(const unsigned char *d, size_t n)
{
  if (n >= 8 && !memcmp(d, "\x89PNG\r\n\x1a\n", 8)) {
    for (size_t at = 8; at + 12 <= n;) {
      size_t len = (size_t)d[at] << 24 | (size_t)d[at + 1] << 16 | (size_t)d[at + 2] << 8 | d[at + 3];
      if (len > n - at - 12) break;
      if (!memcmp(d + at + 4, "eXIf", 4)) /* (some writers keep JPEG's "Exif\0\0" before it) */
        return len >= 6 && !memcmp(d + at + 8, "Exif\0\0", 6) ? tiff_orientation(d + at + 14, len - 6)
                                                                : tiff_orientation(d + at + 8, len);
      if (!memcmp(d + at + 4, "IEND", 4)) break;
      at += 12 + len;
    }
    return 1;
  }
  size_t at = 0, sn;
  unsigned marker;
  const unsigned char *seg;
  while (jpeg_segment(d, n, &at, &marker, &seg, &sn))
    if (marker == 0xE1 && sn >= 14 && !memcmp(seg, "Exif\0\0", 6)) return tiff_orientation(seg + 6, sn - 6);
  return 1;
}

/* The raster of dec turned for display by EXIF orientation o (2 to 8): a
** copy the decoder owns, w and h swapped for the quarter turns (5 to 8).
** Displayed pixel (X, Y) comes from stored pixel (x, y) as the EXIF table
** says: 2 mirrors, 3 turns half round, 4 flips, 5 transposes, 6 turns a
** quarter clockwise, 7 transposes across the other diagonal, 8 turns a
** quarter anticlockwise. */
static lw_status decoded_orient(decoded *dec, int o, const char *name, lw_error *err)
{
  const int w = dec->w, h = dec->h, turn = o >= 5, W = turn ? h : w, H = turn ? w : h;
  const size_t px = (size_t)dec->ch * (size_t)(dec->bits / 8);
  unsigned char *out = malloc((size_t)w * (size_t)h * px);
  if (!out) return lw_error_set(err, LW_ENOMEM, "%s: out of memory turning the image upright", name);
  const unsigned char *in = dec->pix;
  for (int Y = 0; Y < H; Y++)
    for (int X = 0; X < W; X++) {
      int x, y;
      switch (o) {
      case 2: x = w - 1 - X, y = Y; break;
      case 3: x = w - 1 - X, y = h - 1 - Y; break;
      case 4: x = X, y = h - 1 - Y; break;
      case 5: x = Y, y = X; break;
      case 6: x = Y, y = h - 1 - X; break;
      case 7: x = w - 1 - Y, y = h - 1 - X; break;
      default: x = w - 1 - Y, y = X; break; /* 8 */
      }
      memcpy(out + ((size_t)Y * (size_t)W + (size_t)X) * px, in + ((size_t)y * (size_t)w + (size_t)x) * px, px);
    }
  decoded_free(dec);
  *dec = (decoded){out, out, 0, W, H, dec->ch, dec->bits};
  return LW_OK;
}

/* The format a file's first bytes name, for messages. */
static const char *format_name(const unsigned char *d, size_t n)
{
  if (n >= 4 && d[0] == 0x89 && d[1] == 'P' && d[2] == 'N' && d[3] == 'G') return "PNG";
  if (n >= 2 && d[0] == 0xFF && d[1] == 0xD8) return "JPEG";
  if (n >= 2 && d[0] == 'B' && d[1] == 'M') return "BMP";
  if (n >= 4 && !memcmp(d, "GIF8", 4)) return "GIF";
  return "image";
}

/* A picture format linewise does not read, from its first bytes, with its
** article ("a WebP"), or NULL: an iPhone's HEIC, a WebP from the web, a scanner's TIFF
** were "not of any known type, or corrupt", which sent people looking for
** a broken file. */
static const char *foreign_format(const unsigned char *d, size_t n)
{
  if (n >= 12 && !memcmp(d, "RIFF", 4) && !memcmp(d + 8, "WEBP", 4)) return "a WebP";
  /* the Netpbm kinds but the binary PGM/PPM (P5, P6) that are read */
  if (n >= 3 && d[0] == 'P' && strchr(" \t\r\n#", d[2]) && d[2]) {
    static const char *const pnm[] = {['1'] = "a plain-text PBM (P1)", ['2'] = "a plain-text PGM (P2)",
                                      ['3'] = "a plain-text PPM (P3)", ['4'] = "a PBM (P4)", ['7'] = "a PAM (P7)"};
    if (d[1] < sizeof pnm / sizeof pnm[0] && pnm[d[1]]) return pnm[d[1]];
  }
  if (n >= 4 && (!memcmp(d, "II*\0", 4) || !memcmp(d, "MM\0*", 4) || !memcmp(d, "II+\0", 4) || !memcmp(d, "MM\0+", 4)))
    return "a TIFF";
  if (n >= 12 && !memcmp(d + 4, "ftyp", 4)) {
    /* the major brand, then the compatible ones (an AVIF may say mif1 first) */
    size_t box = (size_t)d[0] << 24 | (size_t)d[1] << 16 | (size_t)d[2] << 8 | d[3];
    if (box < 16) box = 12;
    if (box > n) box = n;
    int heic = 0;
    for (size_t at = 8; at + 4 <= box; at += at == 8 ? 8 : 4) {
      if (!memcmp(d + at, "avif", 4) || !memcmp(d + at, "avis", 4)) return "an AVIF";
      if (!memcmp(d + at, "jp2 ", 4)) return "a JPEG 2000";
      if (!memcmp(d + at, "jxl ", 4)) return "a JPEG XL";
      heic |= !memcmp(d + at, "hei", 3) || !memcmp(d + at, "hev", 3) || !memcmp(d + at, "mif1", 4) ||
              !memcmp(d + at, "msf1", 4);
    }
    if (heic) return "a HEIC";
  }
  if (n >= 12 && !memcmp(d, "\0\0\0\x0cjP  ", 8)) return "a JPEG 2000";
  if (n >= 4 && !memcmp(d, "\xff\x4f\xff\x51", 4)) return "a JPEG 2000";
  if (n >= 12 && !memcmp(d, "\0\0\0\x0cJXL \r\n\x87\n", 12)) return "a JPEG XL";
  if (n >= 2 && d[0] == 0xFF && d[1] == 0x0A) return "a JPEG XL";
  if (n >= 4 && !memcmp(d, "8BPS", 4)) return "a Photoshop";
  if (n >= 5 && !memcmp(d, "%PDF-", 5)) return "a PDF";
  size_t at = n >= 3 && !memcmp(d, "\xef\xbb\xbf", 3) ? 3 : 0; /* a BOM, then blanks */
  while (at < n && at < 256 && (d[at] == ' ' || d[at] == '\t' || d[at] == '\r' || d[at] == '\n')) at++;
  if (n - at >= 5 && (!memcmp(d + at, "<svg", 4) || !memcmp(d + at, "<?xml", 5) || !memcmp(d + at, "<!DOC", 5) ||
                      !memcmp(d + at, "<!--", 4)))
    return "an SVG";
  return NULL;
}

const char *lw_image_kind(const unsigned char *d, size_t n, int *readable)
{
  static const char *const read[] = {"PNG", "a PNG", "JPEG", "a JPEG", "BMP", "a BMP", "GIF", "a GIF"};
  const char *name = format_name(d, n);
  if (readable) *readable = 1;
  for (size_t k = 0; k < sizeof read / sizeof *read; k += 2)
    if (!strcmp(name, read[k])) return read[k + 1];
  if (n >= 3 && d[0] == 'P' && (d[1] == '5' || d[1] == '6') && strchr(" \t\r\n#", d[2]) && d[2])
    return d[1] == '5' ? "a PGM" : "a PPM";
  if (readable) *readable = 0;
  return foreign_format(d, n);
}

/* Why the decoder refuses a picture as too large, or NULL: a side past
** 2^24 pixels, or more bytes of pixels (width x height x channels, a
** palette's counted as 4) than it allocates: 2^30 for a PNG, INT_MAX for
** the others (a 24000 x 15000 RGB JPEG decodes); both before linewise's
** own 1e9 pixels.  A PNG's header is read here, as the formats the decoder
** tries after PNG leave "unknown type" as the reason (a 20000 x 20000 RGB
** PNG was called corrupt); the others give w, h and ch from stbi_info (a
** 30000 x 30000 JPEG was "damaged or cut short"). */
static const char *too_large(const unsigned char *d, size_t n, double w, double h, int ch)
{
  const int png = n >= 26 && !strcmp(format_name(d, n), "PNG") && !memcmp(d + 12, "IHDR", 4);
  if (png) {
    w = (double)((uint32_t)d[16] << 24 | (uint32_t)d[17] << 16 | (uint32_t)d[18] << 8 | d[19]);
    h = (double)((uint32_t)d[20] << 24 | (uint32_t)d[21] << 16 | (uint32_t)d[22] << 8 | d[23]);
    static const int channels[7] = {1, 0, 3, 4, 2, 0, 4}; /* by colour type: grey, -, RGB, palette, grey+alpha, -, RGBA */
    ch = d[25] < 7 ? channels[d[25]] : 0;
  }
  if (w > 16777216.0 || h > 16777216.0) return "a side is more than 2^24 pixels";
  if (png && ch && w * h * ch > 1073741824.0)
    return "its width x height x channels is more than 2^30 (1.07e9 grey, 358 million RGB or 268 million RGBA pixels)";
  if (!png && ch && w * h * ch > (double)INT_MAX)
    return "its width x height x channels is more than 2^31 (2.1e9 grey, 716 million RGB or 537 million RGBA pixels)";
  return NULL;
}

/* A JPEG's frame: its first SOF segment (seg, its payload of sn bytes:
** precision, rows, columns, components, then 3 bytes a component), or 0 if
** none; *scan (if asked) where the segments before the first scan end. */
static int jpeg_frame(const unsigned char *d, size_t n, const unsigned char **seg, size_t *sn, size_t *scan)
{
  size_t at = 0, len;
  unsigned m;
  const unsigned char *s;
  int found = 0;
  while (jpeg_segment(d, n, &at, &m, &s, &len))
    if (!found && m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC) {
      *seg = s, *sn = len, found = 1;
      if (!scan) return 1;
    }
  if (scan) *scan = at;
  return found;
}

/* The components of a JPEG's frame, 0 if none is found: stbi_info says 3
** for a CMYK JPEG, which the decoder holds to its limit with 4 (one between
** 537 and 716 million pixels was "damaged"). */
static int jpeg_components(const unsigned char *d, size_t n)
{
  const unsigned char *seg;
  size_t sn;
  return jpeg_frame(d, n, &seg, &sn, NULL) && sn >= 6 ? seg[5] : 0;
}

/* The decoder reads a JPEG's missing data as zeros, so a header claiming
** 30000 x 30000 pixels on 3.7 KB of data took 35 s and 1.8 GB and drew a
** black page.  Every 8 x 8 block of every component is Huffman-coded at
** least once (its DC coefficient, in a baseline and in a progressive
** JPEG's first DC scan) in a code of at least one bit, so the data holds at
** least a bit a block (a uniform grey baseline JPEG takes 2: the DC and the
** AC's end of block); a file with fewer bytes than blocks / 8 is cut short.
** A component sampled Hi x Vi of the largest Hmax x Vmax covers
** ceil(w Hi / Hmax) x ceil(h Vi / Vmax) pixels. */
static lw_status jpeg_data_enough(const unsigned char *d, size_t n, const char *name, lw_error *err)
{
  size_t sn, scan;
  const unsigned char *seg;
  if (!jpeg_frame(d, n, &seg, &sn, &scan) || sn < 6) return LW_OK; /* the decoder's to refuse */
  const double h = seg[1] << 8 | seg[2], w = seg[3] << 8 | seg[4];
  const unsigned nc = seg[5];
  if (sn < 6 + 3 * (size_t)nc || h == 0) return LW_OK; /* the decoder's to refuse; h = 0: rows told later (DNL) */
  unsigned hmax = 1, vmax = 1;
  for (unsigned c = 0; c < nc; c++) {
    unsigned hv = seg[7 + 3 * c];
    if ((hv >> 4) > hmax) hmax = hv >> 4;
    if ((hv & 15) > vmax) vmax = hv & 15;
  }
  double blocks = 0;
  for (unsigned c = 0; c < nc; c++) {
    unsigned hv = seg[7 + 3 * c];
    blocks += ceil(ceil(w * (hv >> 4) / hmax) / 8) * ceil(ceil(h * (hv & 15) / vmax) / 8);
  }
  /* the bytes from the first scan on: an ICC profile or an EXIF thumbnail
  ** before it (64 KB and more on a phone's photo) hid a cut scan */
  const size_t data = n - scan;
  if ((double)data < blocks / 8)
    return lw_error_set(err, LW_EINPUT, "%s: the JPEG is damaged or cut short: its %.0f x %.0f pixels take at least "
                        "%.0f bytes of coded data, the file has %zu from its first scan on", name, w, h,
                        ceil(blocks / 8), data);
  return LW_OK;
}

static lw_status too_large_error(const unsigned char *d, size_t n, const char *name, const char *why, lw_error *err)
{
  return lw_error_set(err, LW_EINPUT, "%s: the %s is too large to decode: %s; scale it down first", name,
                      format_name(d, n), why);
}

/* Why stb_image refused what it was given: too large, a format it does not
** read, or not an image. */
static lw_status not_decoded(const unsigned char *data, size_t size, const char *name, lw_error *err)
{
  const char *why = too_large(data, size, 0, 0, 0), *foreign = foreign_format(data, size);
  if (why) return too_large_error(data, size, name, why, err);
  const unsigned char *seg;
  size_t sn;
  if (!strcmp(format_name(data, size), "JPEG") && jpeg_frame(data, size, &seg, &sn, NULL) && sn >= 5) {
    const unsigned h = (unsigned)seg[1] << 8 | seg[2], w = (unsigned)seg[3] << 8 | seg[4];
    if (!w || !h)
      return lw_error_set(err, LW_EINPUT, "%s: the JPEG's frame says %u x %u pixels: damaged%s", name, w, h,
                          w ? ", or rows told after the data (a DNL marker), which the decoder does not read" : "");
  }
  if (foreign)
    return lw_error_set(err, LW_EINPUT, "%s: %s file, which linewise does not read (PNG, JPEG, GIF, BMP, binary "
                        "PGM/PPM): convert it to PNG or JPEG first", name, foreign);
  return lw_error_set(err, LW_EINPUT, "%s: not an image linewise reads (PNG, JPEG, GIF, BMP, binary PGM/PPM): %s",
                      name, size == 0 ? "empty file" : stbi_failure_reason());
}

/* What stb_image must not be given: a BMP or GIF cut short, a JPEG whose
** tables would make it write out of bounds or read uninitialised memory.
** Checked before any call into it, stbi_info too (which reads a JPEG's
** tables). */
static lw_status stb_input_sound(const unsigned char *data, size_t size, const char *name, lw_error *err)
{
  lw_status st = bmp_complete(data, size, name, err);
  if (!st) st = gif_complete(data, size, name, err);
  /* (a PNG too large to decode is said to be, from its header, damaged or not) */
  if (!st && !too_large(data, size, 0, 0, 0)) st = png_chunks_sound(data, size, name, err);
  if (!st) st = jpeg_tables_sound(data, size, name, err);
  return st;
}

/* stbi_info, with a BMP's rows stored top down, as a negative height
** (legal in every header), given the height's magnitude: the decoder gives
** them upright (they were all refused as damaged, and then again where a
** scene's picture is first looked at). */
static int stb_info(const unsigned char *data, size_t size, int *w, int *h, int *ch)
{
  if (!stbi_info_from_memory(data, (int)size, w, h, ch)) return 0;
  if (!strcmp(format_name(data, size), "BMP") && *h < 0 && *h > INT_MIN) *h = -*h;
  return 1;
}

static lw_status stb_decode(const unsigned char *data, size_t size, const char *name, decoded *out, lw_error *err)
{
  if (size > INT_MAX)
    return lw_error_set(err, LW_EINPUT, "%s: a file of %zu bytes is too large for the image decoder", name, size);
  lw_status st = stb_input_sound(data, size, name, err);
  if (st) return st;
  int w, h, ch;
  if (!stb_info(data, size, &w, &h, &ch)) return not_decoded(data, size, name, err);
  if (w < 1 || h < 1) /* stb_image passes a BMP of width 0 */
    return lw_error_set(err, LW_EINPUT, "%s: the %s is damaged: %d x %d pixels", name, format_name(data, size), w, h);
  const int comps = !strcmp(format_name(data, size), "JPEG") ? jpeg_components(data, size) : 0;
  const char *big = too_large(data, size, w, h, comps > ch ? comps : ch);
  if (big) return too_large_error(data, size, name, big, err);
  if ((st = jpeg_data_enough(data, size, name, err))) return st;
  if ((double)w * (double)h > LW_IMAGE_MAX_PIXELS)
    return lw_error_set(err, LW_EINPUT, "%s: %d x %d pixels is more than the %.0e pixels linewise decodes", name,
                        w, h, (double)LW_IMAGE_MAX_PIXELS);
  int bits = stbi_is_16_bit_from_memory(data, (int)size) ? 16 : 8;
  /* The decoder keeps its last reason until a new one is set, and some
  ** failures set none: a JPEG cut short was reported as "Not a PNG", from
  ** the format tests before it.  A reason the load did not change is not
  ** given. */
  const char *before = stbi_failure_reason();
  errno = 0;
  void *pix = bits == 16 ? (void *)stbi_load_16_from_memory(data, (int)size, &w, &h, &ch, 0)
                         : (void *)stbi_load_from_memory(data, (int)size, &w, &h, &ch, 0);
  if (!pix) {
    const char *why = stbi_failure_reason();
    /* (a PNG's inflate sets no reason where its buffer cannot be had: the
    ** failed malloc's errno tells memory from damage, which was said) */
    const int nomem = why && why != before ? !strcmp(why, "outofmem") || !strcmp(why, "Out of memory")
                                           : errno == ENOMEM;
    if (nomem)
      return lw_error_set(err, LW_ENOMEM, "%s: out of memory decoding the %s (%d x %d pixels)", name,
                          format_name(data, size), w, h);
    return lw_error_set(err, LW_EINPUT, "%s: the %s is damaged or cut short: it does not decode%s%s%s", name,
                        format_name(data, size), why && why != before ? " (" : "", why && why != before ? why : "",
                        why && why != before ? ")" : "");
  }
  *out = (decoded){pix, pix, 1, w, h, ch, bits};
  int o = exif_orientation(data, size);
  if (o != 1 && (st = decoded_orient(out, o, name, err)) != LW_OK) decoded_free(out);
  return st;
}

lw_image *lw_image_decode(const unsigned char *data, size_t size, const char *name,
                          double max_pixels, lw_image_info *info, lw_error *err)
{
  return lw_image_decode_channel(data, size, name, max_pixels, LW_IMAGE_LUMA, info, err);
}

lw_image *lw_image_decode_channel(const unsigned char *data, size_t size, const char *name, double max_pixels,
                                  lw_image_channel which, lw_image_info *info, lw_error *err)
{
  if (size == 0) {
    lw_error_set(err, LW_EINPUT, "%s: empty file (0 bytes), not an image", name);
    return NULL;
  }
  decoded dec;
  int pnm = size >= 2 && data[0] == 'P' && (data[1] == '5' || data[1] == '6');
  if ((pnm ? pnm_decode : stb_decode)(data, size, name, &dec, err)) return NULL;
  const int w = dec.w, h = dec.h, ch = dec.ch, bits = dec.bits;
  if (info) *info = (lw_image_info){w, h, ch, bits};

  int w2 = w, h2 = h;
  if (max_pixels >= 1 && (double)w * (double)h > max_pixels) {
    double f = sqrt(max_pixels / ((double)w * (double)h));
    w2 = (int)floor(w * f);
    h2 = (int)floor(h * f);
    /* a strip thinner than the factor keeps one pixel across and gives up
    ** its aspect along: still at most max_pixels */
    if (w2 < 1) w2 = 1, h2 = (int)fmin(h, floor(max_pixels));
    if (h2 < 1) h2 = 1, w2 = (int)fmin(w, floor(max_pixels));
  }
  int has_alpha = ch == 2 || ch == 4;
  lw_image *img = lw_image_new(w2, h2, has_alpha, err);
  float *row = malloc(2 * (size_t)w * sizeof *row);
  resampler rs;
  int rs_ok = img && row && resampler_init(&rs, w, h, w2, h2, err) == LW_OK;
  if (!rs_ok) {
    if (img && !row) lw_error_set(err, LW_ENOMEM, "%s: out of memory converting the image", name);
    free(row);
    lw_image_free(img);
    decoded_free(&dec);
    return NULL;
  }
  size_t n = (size_t)w2 * (size_t)h2;
  plane_fill(img->tone, n, 0.0f);
  if (has_alpha) plane_fill(img->alpha, n, 0.0f);
  for (int j = 0; j < h; j++) {
    decoded_row(dec.pix, bits, w, ch, j, which, row, row + w);
    resampler_add_row(&rs, j, row, img->tone);
    if (has_alpha) resampler_add_row(&rs, j, row + w, img->alpha);
  }
  resampler_free(&rs);
  free(row);
  decoded_free(&dec);
  plane_clamp01(img->tone, n);
  if (has_alpha) plane_clamp01(img->alpha, n);
  return img;
}

lw_image *lw_image_load(const char *path, double max_pixels, lw_image_info *info, lw_error *err)
{
  return lw_image_load_channel(path, max_pixels, LW_IMAGE_LUMA, info, err);
}

/* The whole file at path, malloc'd, into *size; NULL and err set if it
** cannot be an image linewise reads. */
static unsigned char *read_picture_file(const char *path, size_t *size_out, lw_error *err)
{
  /* looked at before it is opened too: opening a FIFO waits for a writer,
  ** and the set-up hung there */
  struct stat sb;
  if (!stat(path, &sb) && !S_ISREG(sb.st_mode)) {
    lw_error_set(err, LW_EINPUT, "%s: not a regular file, so not an image", path);
    return NULL;
  }
  FILE *f = fopen(path, "rb");
  if (!f) {
    /* what a missing picture's name most often holds by mistake: a ~ the
    ** shell leaves after '=' (photos live in ~/Pictures), quotes a scene
    ** file keeps as part of the value */
    const int e = errno, tilde = path[0] == '~' || strstr(path, "/~");
    const int quoted = strchr("\"'", path[0]) || strstr(path, "/\"") || strstr(path, "/'");
    lw_error_set(err, LW_EINPUT, "%s: cannot open the image: %s%s", path, strerror(e),
                 e != ENOENT ? ""
                 : tilde ? " (a ~ is not expanded here, nor after '=' by the shell: write the whole path)"
                 : quoted ? " (quotes in a scene file or inside --set's value are part of the name: write it "
                            "without them)" : "");
    return NULL;
  }
  if (fstat(fileno(f), &sb) || !S_ISREG(sb.st_mode)) {
    lw_error_set(err, LW_EINPUT, "%s: not a regular file, so not an image", path);
    fclose(f);
    return NULL;
  }
  if (sb.st_size > LW_IMAGE_MAX_FILE_BYTES) {
    lw_error_set(err, LW_EINPUT, "%s: a file of %lld bytes is larger than the %ld bytes linewise reads", path,
                 (long long)sb.st_size, LW_IMAGE_MAX_FILE_BYTES);
    fclose(f);
    return NULL;
  }
  size_t size = (size_t)sb.st_size;
  unsigned char *data = malloc(size ? size : 1);
  if (!data) {
    lw_error_set(err, LW_ENOMEM, "%s: out of memory reading %zu bytes", path, size);
    fclose(f);
    return NULL;
  }
  size_t got = fread(data, 1, size, f);
  int bad = ferror(f), e = errno;
  fclose(f);
  if (bad || got != size) {
    lw_error_set(err, LW_EINPUT, "%s: cannot read the image: %s", path, bad ? strerror(e) : "file changed while read");
    free(data);
    return NULL;
  }
  *size_out = size;
  return data;
}

lw_image *lw_image_load_channel(const char *path, double max_pixels, lw_image_channel which, lw_image_info *info,
                                lw_error *err)
{
  size_t size;
  unsigned char *data = read_picture_file(path, &size, err);
  if (!data) return NULL;
  lw_image *img = lw_image_decode_channel(data, size, path, max_pixels, which, info, err);
  free(data);
  return img;
}

lw_status lw_image_probe(const char *path, lw_image_info *info, lw_error *err)
{
  size_t size;
  unsigned char *data = read_picture_file(path, &size, err);
  if (!data) return err->code;
  lw_status st = LW_OK;
  long w, h, maxval;
  size_t at;
  if (size >= 2 && data[0] == 'P' && (data[1] == '5' || data[1] == '6')) {
    if ((st = pnm_header(data, size, path, &w, &h, &maxval, &at, err)) == LW_OK)
      *info = (lw_image_info){(int)w, (int)h, data[1] == '6' ? 3 : 1, maxval > 255 ? 16 : 8};
  } else {
    int iw, ih, ch;
    if (size > 0 && size <= INT_MAX) st = stb_input_sound(data, size, path, err);
    if (st)
      ; /* refused before stb_image reads it */
    else if (size == 0 || size > INT_MAX || !stb_info(data, size, &iw, &ih, &ch))
      st = not_decoded(data, size, path, err);
    else if (iw < 1 || ih < 1)
      st = lw_error_set(err, LW_EINPUT, "%s: the %s is damaged: %d x %d pixels", path, format_name(data, size), iw, ih);
    else if (exif_orientation(data, size) >= 5) /* stored on its side */
      *info = (lw_image_info){ih, iw, ch, stbi_is_16_bit_from_memory(data, (int)size) ? 16 : 8};
    else
      *info = (lw_image_info){iw, ih, ch, stbi_is_16_bit_from_memory(data, (int)size) ? 16 : 8};
  }
  free(data);
  return st;
}

/* ---- blur ------------------------------------------------------------- */

/* Half-sample symmetric reflection of index i onto [0, n): ... 1 0 | 0 1 ...
** n-1 | n-1 n-2 ...; periodic with period 2n, so any offset is fine. */
static int reflect(long i, int n)
{
  long m = i % (2L * n);
  if (m < 0) m += 2L * n;
  return (int)(m < n ? m : 2L * n - 1 - m);
}

/* Inside a parallel region: whether some thread of the team lacks what it
** needed (has 0), the same answer on every thread, so that they all go into
** the region's work-sharing loops or none does (a thread whose scratch
** failed skipped the loops the others waited in: undefined in OpenMP, a
** hang where it ends); *failed, shared, is set. */
static int team_lacks(int has, int *failed)
{
  if (!has) {
#pragma omp atomic write
    *failed = 1;
  }
#pragma omp barrier
  int any;
#pragma omp atomic read
  any = *failed;
  return any;
}

/* One axis of the blur over `count` lines of length n: element i of line l
** sits at p[l * lstride + i * estride], and
**     out[x] = sum_t kern[t] ext[x + t],   ext[i] = line[reflect(i - off)].
** The mirrored line is built in scratch first, so the inner loop is a plain
** dot product and the line can be overwritten in place.  Lines are
** independent, so threads share them out without changing a single value. */
static lw_status blur_axis(float *p, int n, int count, size_t estride, size_t lstride, const double *kern,
                           int taps, int off)
{
  int failed = 0;
#pragma omp parallel
  {
    float *ext = malloc(((size_t)n + (size_t)taps) * sizeof *ext);
    if (!team_lacks(ext != NULL, &failed)) {
#pragma omp for schedule(static)
      for (int l = 0; l < count; l++) {
        float *q = p + (size_t)l * lstride;
        for (int i = 0; i < n + taps - 1; i++) ext[i] = q[(size_t)reflect((long)i - off, n) * estride];
        int x = 0;
        for (; x + 8 <= n; x += 8) { /* eight pixels a step, each its own sum in the order below */
          double s[8] = {0};
          for (int t = 0; t < taps; t++) {
            const double k = kern[t];
            const float *e = ext + x + t;
#pragma omp simd
            for (int j = 0; j < 8; j++) s[j] += k * e[j];
          }
          for (int j = 0; j < 8; j++) q[(size_t)(x + j) * estride] = (float)s[j];
        }
        for (; x < n; x++) {
          double s = 0.0;
          for (int t = 0; t < taps; t++) s += kern[t] * ext[x + t];
          q[(size_t)x * estride] = (float)s;
        }
      }
    }
    free(ext);
  }
  return failed ? LW_ENOMEM : LW_OK;
}

/* The kernel of one axis of length n.  Since the mirrored signal has
** period 2n, a kernel wider than that folds onto 2n taps (weights whose
** offsets agree mod 2n add up): the cost per pixel stays below 2n. */
static double *blur_kernel(double sigma, int n, int *taps, int *off)
{
  long R = (long)ceil(4.0 * sigma);
  double *g = malloc((2 * (size_t)R + 1) * sizeof *g);
  if (!g) return NULL;
  double sum = 0.0;
  for (long d = -R; d <= R; d++) sum += g[d + R] = exp(-0.5 * (double)(d * d) / (sigma * sigma));
  for (long d = 0; d <= 2 * R; d++) g[d] /= sum;
  if (2 * R + 1 <= 2L * n) {
    *taps = (int)(2 * R + 1);
    *off = (int)R;
    return g;
  }
  double *f = calloc(2 * (size_t)n, sizeof *f);
  if (f)
    for (long d = -R; d <= R; d++) {
      long m = d % (2L * n);
      f[m < 0 ? m + 2L * n : m] += g[d + R];
    }
  free(g);
  *taps = 2 * n;
  *off = 0;
  return f;
}

/*
** Wide blurs, sparsely.  The direct sums cost 8 sigma + 1 taps a pixel and
** axis: a camera's picture on a small page (4 megapixels, the field's
** 2 mm at 0.035 mm a pixel, sigma 57) took 10 s to set up.  The result of
** a wide blur is smooth at the scale of sigma, so from BLUR_SPARSE_SIGMA
** pixels on it is summed only at every f-th pixel of each axis (f = sigma /
** BLUR_SAMPLES_A_SIGMA, rounded down) and taken between those by cubic
** (Catmull-Rom) interpolation: within 2e-6 of the tone's range of the
** direct sum on noise, 2e-5 at a sharp edge, where the kernel's cut at 4
** sigma leaves a kink the interpolation rounds (tests/test_image.c); an
** 8-bit picture's steps are 4e-3.
** The samples run from one step before the first pixel to two after the
** last (the blurred line is mirrored as the picture is).
*/
#define BLUR_SPARSE_SIGMA 16.0
#define BLUR_SAMPLES_A_SIGMA 8.0

/* out[k * ostride] = the blur of one line (n values estride apart from q)
** at position (k - 1) f, k < K, the sum of blur_axis; ext: scratch of
** (K - 1) f + taps values. */
static void blur_line_sparse(const float *q, size_t estride, int n, const double *kern, int taps, int off, int f,
                             int K, float *ext, float *out, size_t ostride)
{
  const int len = (K - 1) * f + taps;
  for (int i = 0; i < len; i++) ext[i] = q[(size_t)reflect((long)i - f - off, n) * estride];
  for (int k = 0; k < K; k++) {
    const float *e = ext + (size_t)k * (size_t)f;
    double s = 0.0;
    for (int t = 0; t < taps; t++) s += kern[t] * e[t];
    out[(size_t)k * ostride] = (float)s;
  }
}

void lw_image_cubic_weights(double u, double wt[4])
{
  const double u2 = u * u, u3 = u2 * u;
  wt[0] = 0.5 * (-u3 + 2.0 * u2 - u);
  wt[1] = 0.5 * (3.0 * u3 - 5.0 * u2 + 2.0);
  wt[2] = 0.5 * (-3.0 * u3 + 4.0 * u2 + u);
  wt[3] = 0.5 * (u3 - u2);
}

static lw_status blur_sparse(float *plane, int w, int h, const double *kx, int tx, int ox, const double *ky, int ty,
                             int oy, int f)
{
  const int Kx = (w - 1) / f + 4, Ky = (h - 1) / f + 4;
  float *rows = malloc((size_t)h * (size_t)Kx * sizeof *rows), *grid = malloc((size_t)Ky * (size_t)Kx * sizeof *grid);
  double *wx = malloc(4 * (size_t)w * sizeof *wx);
  int failed = !rows || !grid || !wx;
  if (!failed) {
    for (int x = 0; x < w; x++) lw_image_cubic_weights((double)(x % f) / f, wx + 4 * (size_t)x);
#pragma omp parallel
    {
      const int longest = (w > h ? w : h) + 3 * f + (tx > ty ? tx : ty);
      float *ext = malloc((size_t)longest * sizeof *ext);
      if (!team_lacks(ext != NULL, &failed)) {
        /* rows at every f-th column, then those columns at every f-th row */
#pragma omp for schedule(static)
        for (int y = 0; y < h; y++)
          blur_line_sparse(plane + (size_t)y * (size_t)w, 1, w, kx, tx, ox, f, Kx, ext, rows + (size_t)y * Kx, 1);
#pragma omp for schedule(static)
        for (int k = 0; k < Kx; k++) blur_line_sparse(rows + k, (size_t)Kx, h, ky, ty, oy, f, Ky, ext, grid + k, (size_t)Kx);
#pragma omp for schedule(static)
        for (int y = 0; y < h; y++) {
          double wy[4];
          lw_image_cubic_weights((double)(y % f) / f, wy);
          const float *g = grid + (size_t)(y / f) * Kx;
          float *out = plane + (size_t)y * (size_t)w;
          for (int x = 0; x < w; x++) {
            const float *c = g + x / f;
            const double *a = wx + 4 * (size_t)x;
            double s = 0.0;
            for (int j = 0; j < 4; j++, c += Kx)
              s += wy[j] * (a[0] * c[0] + a[1] * c[1] + a[2] * c[2] + a[3] * c[3]);
            out[x] = (float)s;
          }
        }
      }
      free(ext);
    }
  }
  free(rows);
  free(grid);
  free(wx);
  return failed ? LW_ENOMEM : LW_OK;
}

lw_status lw_image_blur_plane(float *plane, int w, int h, double sigma, lw_error *err)
{
  /* below a tenth of a pixel the side taps are exp(-50) of the centre's or
  ** less, so the blur is the picture itself to a float's rounding (and under
  ** 1e-154 sigma^2 underflows: the kernel was 0 / 0) */
  if (!(sigma >= 0.1)) return LW_OK;
  if (!isfinite(sigma)) return lw_error_set(err, LW_EINPUT, "blur of sigma %g pixels", sigma);
  int tx, ox, ty, oy;
  double *kx = blur_kernel(sigma, w, &tx, &ox), *ky = blur_kernel(sigma, h, &ty, &oy);
  lw_status s = kx && ky ? LW_OK : LW_ENOMEM;
  const int f = sigma >= BLUR_SPARSE_SIGMA ? (int)(sigma / BLUR_SAMPLES_A_SIGMA) : 1;
  if (!s && f > 1) {
    s = blur_sparse(plane, w, h, kx, tx, ox, ky, ty, oy, f);
  } else if (!s) {
    s = blur_axis(plane, w, h, 1, (size_t)w, kx, tx, ox); /* rows */
    if (!s) s = blur_axis(plane, h, w, (size_t)w, 1, ky, ty, oy); /* columns */
  }
  free(kx);
  free(ky);
  if (s) lw_error_set(err, LW_ENOMEM, "out of memory blurring %d x %d pixels", w, h);
  return s;
}

lw_status lw_image_blur(lw_image *img, double sigma, lw_error *err)
{
  return lw_image_blur_plane(img->tone, img->width, img->height, sigma, err);
}

#define FLATTEN_COARSE 4 /* pixels a radius kept when the paper is found coarsely */

/* The largest of in[i - r .. i + r] for each i of a line of n values (the
** line's ends repeated beyond it), by van Herk and Gil-Werman: x is the line
** padded by r on each side and cut into blocks of k = 2r + 1; the running
** maximum from each block's start (g) and to its end (h) give any window of
** k values, which spans at most two blocks, in one comparison.  Three
** comparisons a value, whatever r. */
static void running_max(const float *in, size_t stride, int n, int r, float *out, size_t ostride, float *x,
                        float *g, float *h)
{
  const int m = n + 2 * r, k = 2 * r + 1;
  for (int j = 0; j < m; j++) {
    int i = j - r;
    x[j] = in[(size_t)(i < 0 ? 0 : (i >= n ? n - 1 : i)) * stride];
  }
  for (int j = 0; j < m; j++) g[j] = j % k == 0 ? x[j] : fmaxf(g[j - 1], x[j]);
  for (int j = m - 1; j >= 0; j--) h[j] = (j % k == k - 1 || j == m - 1) ? x[j] : fmaxf(h[j + 1], x[j]);
  for (int i = 0; i < n; i++) out[(size_t)i * ostride] = fmaxf(h[i], g[i + 2 * r]);
}

/* The paper of lw_image_flatten on a w x h plane, in place.  Blurred first,
** the maximum is that of the paper's mean, not of its grain (on skimage's
** text.png the paper came out 0.88 from the raw maximum, 0.98 from the
** blurred one); blurred after, the maximum's steps, where a light area
** enters or leaves the window, are smoothed. */
static lw_status paper_of(float *p, int w, int h, double radius, lw_error *err)
{
  const int big = w > h ? w : h;
  const int r = radius < 1.0 ? 1 : (radius > big ? big : (int)lround(radius));
  const size_t m = (size_t)big + 2 * (size_t)r;
  float *line = malloc(3 * m * sizeof *line);
  if (!line) return lw_error_set(err, LW_ENOMEM, "out of memory flattening %d x %d pixels", w, h);
  lw_status st = lw_image_blur_plane(p, w, h, 0.5 * r, err);
  if (!st) {
    for (int y = 0; y < h; y++) /* in place: running_max copies its line first */
      running_max(p + (size_t)y * w, 1, w, r, p + (size_t)y * w, 1, line, line + m, line + 2 * m);
    for (int x = 0; x < w; x++) running_max(p + x, (size_t)w, h, r, p + x, (size_t)w, line, line + m, line + 2 * m);
    st = lw_image_blur_plane(p, w, h, 0.5 * r, err);
  }
  free(line);
  return st;
}

lw_status lw_image_flatten(lw_image *img, double radius, double *lo, double *hi, lw_error *err)
{
  const int w = img->width, h = img->height;
  const size_t n = (size_t)w * (size_t)h;
  /* The paper is smooth over the radius: beyond FLATTEN_COARSE pixels a
  ** radius it is found on the picture boxed down to that many and
  ** interpolated back, which keeps its cost (a blur of sigma radius / 2 is
  ** most of it) that of a small radius. */
  const lw_image tone = {w, h, img->tone, NULL};
  const int f = radius >= 2 * FLATTEN_COARSE ? (int)(radius / FLATTEN_COARSE) : 1;
  const int cw = (w + f - 1) / f, ch = (h + f - 1) / f;
  lw_image *paper = lw_image_resize(&tone, cw, ch, err); /* f = 1: a copy */
  if (!paper) return err ? err->code : LW_ENOMEM;
  lw_status st = paper_of(paper->tone, cw, ch, radius * cw / w, err);
  if (!st && f > 1) {
    lw_image *full = lw_image_resize(paper, w, h, err);
    lw_image_free(paper);
    if (!(paper = full)) return err ? err->code : LW_ENOMEM;
  }
  if (st) {
    lw_image_free(paper);
    return st;
  }
  double l = 1.0, u = 0.0;
  for (size_t k = 0; k < n; k++) {
    const double b = paper->tone[k], t = img->tone[k];
    if (b < l) l = b;
    if (b > u) u = b;
    img->tone[k] = b > LW_IMAGE_FLATTEN_MIN_PAPER ? (float)(t < b ? t / b : 1.0) : 1.0f;
  }
  lw_image_free(paper);
  *lo = l;
  *hi = u;
  return LW_OK;
}

/* ---- tone and page -------------------------------------------------- */

/* Bins of the levels' histogram: 1/4096 of the tone range, finer than an
** 8-bit picture's steps and than anything a line density can show. */
#define LEVELS_BINS 4096

/* A pixel's tone without the paper its transparency shows (composited over
** white as it loaded, tone = a t + 1 - a): the levels are the picture's.
** They were taken of the composite, and stretched it, which the tone curve
** then took apart as if it were still a t + 1 - a: a half-transparent
** picture's darks went to one grey, or it came out opaque. */
static double own_tone(const lw_image *img, const float *under, size_t k)
{
  const double a = under ? under[k] : 1.0;
  if (!(a < 1.0)) return img->tone[k];
  if (!(a > 0.0)) return 1.0;
  const double t = (img->tone[k] - (1.0 - a)) / a;
  return t < 0 ? 0 : (t > 1 ? 1 : t);
}

/* Whether an end of hist is a flat colour: b, the bin its clip falls in,
** held by more than `plateau` pixels, or with `tail` a bin so held with no
** more than `plateau` pixels beyond it, walking in by `step` from `end` (a
** graphic's lightest colour with a thin tail past it: the anti-aliased edge
** of a disc on transparent paper, a JPEG's ringing around a flat background,
** 1.05 and 1.2 % of the pixels, were past the 1 % clip, and it turned white). */
static int flat_end(const size_t *hist, int b, int end, int step, double plateau, int tail)
{
  if ((double)hist[b] > plateau) return 1;
  double beyond = 0.0;
  for (int k = end; tail && k >= 0 && k < LEVELS_BINS && beyond <= plateau; k += step) {
    if ((double)hist[k] > plateau) return 1;
    beyond += (double)hist[k];
  }
  return 0;
}

lw_status lw_image_levels(lw_image *img, const float *under, double clip, int flat, double *lo, double *hi,
                          int *kept, lw_error *err)
{
  size_t n = (size_t)img->width * (size_t)img->height;
  size_t *hist = calloc(LEVELS_BINS, sizeof *hist);
  if (!hist) return lw_error_set(err, LW_ENOMEM, "out of memory for the picture's levels");
  size_t count = 0;
  for (size_t k = 0; k < n; k++) {
    if (img->alpha && img->alpha[k] < 0.5f) continue;
    int b = (int)(own_tone(img, under, k) * LEVELS_BINS);
    hist[b < 0 ? 0 : (b >= LEVELS_BINS ? LEVELS_BINS - 1 : b)]++;
    count++;
  }
  double l = 0.0, h = 1.0;
  if (kept) *kept = 0;
  if (count) {
    /* the first bin from each end past `cut` pixels */
    size_t cut = (size_t)floor(clip * (double)count), c = 0;
    int b = 0;
    const double plateau = LW_IMAGE_LEVELS_PLATEAU * (double)count;
    while (b < LEVELS_BINS - 1 && (c += hist[b]) <= cut) b++;
    const double bl = (double)b / LEVELS_BINS;
    const int l_flat = flat_end(hist, b, 0, 1, plateau, flat >= 1);
    c = 0;
    b = LEVELS_BINS - 1;
    while (b > 0 && (c += hist[b]) <= cut) b--;
    const double bh = (double)(b + 1) / LEVELS_BINS;
    const int h_flat = flat_end(hist, b, LEVELS_BINS - 1, -1, plateau, flat >= 1);
    if (!l_flat) l = bl;
    if (!h_flat) h = bh;
    /* an end left alone keeps its flat colour from turning white or black
    ** whole, but with the other end stretched up to it the picture's tones
    ** were crowded at the far end: a DEM's flat sea at 0.458, its land up to
    ** 0.464, went to 0.99 and up (white, an empty drawing) with l at 0, and
    ** one stored signed, its sea at 0.5, alike.  Where its tones would fill
    ** under LW_IMAGE_LEVELS_CROWDED of the range, that end is stretched as
    ** any; a graphic's flat colour beside its other tones (a dark logo's
    ** 0.35 over 0 to 0.2: 0.35 of the range; a disc's 0.33 beside a bar of
    ** 0.12 to 0.26: 0.24) is left alone */
    if (flat >= 2 && l_flat && !h_flat && 1.0 - (bl - l) / (h - l) < LW_IMAGE_LEVELS_CROWDED) l = bl;
    if (flat >= 2 && h_flat && !l_flat && (bh - l) / (h - l) < LW_IMAGE_LEVELS_CROWDED) h = bh;
    if (kept) *kept = (l == 0.0 && l_flat && bl > 0.0) | (h == 1.0 && h_flat && bh < 1.0) << 1;
  }
  free(hist);
  if (h - l < LW_IMAGE_LEVELS_MIN_SPAN) {
    double m = 0.5 * (l + h);
    l = m - 0.5 * LW_IMAGE_LEVELS_MIN_SPAN;
    h = m + 0.5 * LW_IMAGE_LEVELS_MIN_SPAN;
    if (l < 0) h -= l, l = 0;
    if (h > 1) l -= h - 1, h = 1;
  }
  const double scale = 1.0 / (h - l);
  for (size_t k = 0; k < n; k++) {
    const double a = under ? under[k] : 1.0;
    if (!(a > 0.0)) continue; /* paper alone: white, as loaded */
    double t = (own_tone(img, under, k) - l) * scale;
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    img->tone[k] = (float)(a < 1.0 ? a * t + (1.0 - a) : t);
  }
  *lo = l;
  *hi = h;
  return LW_OK;
}

void lw_image_tone_curve(lw_image *img, const float *alpha, double gamma, double contrast, int invert)
{
  size_t n = (size_t)img->width * (size_t)img->height;
  const int identity = !invert && gamma == 1.0 && contrast == 1.0;
  for (size_t k = 0; k < n; k++) {
    /* The curve is the picture's, not the paper's that a transparent pixel
    ** shows (composited over white as it loaded): inverted, that paper had
    ** asked for full ink.  So a pixel short of opaque is taken apart into
    ** its picture and its paper, and only the picture goes through. */
    const double a = alpha && !identity ? alpha[k] : 1.0;
    if (!(a > 0.0)) continue; /* paper alone: white, as loaded */
    double t = a < 1.0 ? (img->tone[k] - (1.0 - a)) / a : img->tone[k];
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    if (invert) t = 1.0 - t;
    if (gamma != 1.0) t = pow(t > 0 ? t : 0, gamma);
    t = 0.5 + contrast * (t - 0.5);
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    img->tone[k] = (float)(a < 1.0 ? a * t + (1.0 - a) : t);
  }
}

lw_image_place lw_image_fit(int w, int h, double bx0, double by0, double bx1, double by1)
{
  double bw = bx1 - bx0, bh = by1 - by0;
  double px = fmin(bw / w, bh / h);
  return (lw_image_place){bx0 + 0.5 * (bw - w * px), by0 + 0.5 * (bh - h * px), px};
}

double lw_image_tone_at(const lw_image *img, const lw_image_place *pl, double x, double y)
{
  double u = (x - pl->x0) / pl->pixel, v = (y - pl->y0) / pl->pixel;
  if (!(u >= 0 && v >= 0 && u < img->width && v < img->height)) return 1.0;
  /* between pixel centres, clamped to the outermost centres */
  u -= 0.5;
  v -= 0.5;
  if (u < 0) u = 0;
  if (v < 0) v = 0;
  if (u > img->width - 1) u = img->width - 1;
  if (v > img->height - 1) v = img->height - 1;
  int i = (int)u, j = (int)v;
  int i1 = i + 1 < img->width ? i + 1 : i, j1 = j + 1 < img->height ? j + 1 : j;
  double fx = u - i, fy = v - j;
  const float *t = img->tone;
  size_t W = (size_t)img->width;
  return (1 - fy) * ((1 - fx) * t[j * W + i] + fx * t[j * W + i1]) + fy * ((1 - fx) * t[j1 * W + i] + fx * t[j1 * W + i1]);
}

lw_grid2d *lw_image_tone_grid(const lw_image *img, const lw_image_place *pl, lw_error *err)
{
  lw_grid2d *g = lw_grid2d_new(img->width, img->height, 1, pl->x0 + 0.5 * pl->pixel, pl->y0 + 0.5 * pl->pixel,
                               pl->pixel, pl->pixel, err);
  if (!g) return NULL;
  for (size_t i = 0; i < (size_t)img->width * (size_t)img->height; i++) g->data[i] = img->tone[i];
  return g;
}

/* stb_image 2.27 declares stbi_set_unpremultiply_on_load_thread and defines
** it nowhere (2.28 does, so no stub can stand in for it); static, GCC warns
** of it as the file ends, which is where it reads this.  So GCC says nothing
** of a static function of this file declared and never defined; one defined
** and left unused above is still warned of (GCC judges those where they
** stand), and clang, which takes this pragma too, still warns of both. */
#if defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wunused-function"
#endif
