/*
** test_image.c -- pictures: decoding (gray conversion, alpha, orientation,
** formats, bad files), resampling, blur, levels, the tone curve, page fitting.
*/
#include <criterion/criterion.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <zlib.h>

#include "imageutil.h"
#include "linewise/image.h"
#include "testutil.h"

TestSuite(image, .init = lw_image_dir_make, .fini = lw_image_dir_remove);


static double mean_of(const float *p, size_t n)
{
  double s = 0;
  for (size_t k = 0; k < n; k++) s += p[k];
  return s / (double)n;
}

static lw_image *random_image(int w, int h)
{
  lw_image *img = lw_image_new(w, h, 0, NULL);
  cr_assert_not_null(img);
  for (size_t k = 0; k < (size_t)w * (size_t)h; k++) img->tone[k] = (float)urand(0, 1);
  return img;
}

/* A 24-bit BMP written by hand: rows bottom-up, BGR, padded to 4 bytes. */
static size_t bmp_bytes(unsigned char *b, int w, int h, const unsigned char *rgb)
{
  int pad = (4 - (3 * w) % 4) % 4;
  size_t data = (size_t)(3 * w + pad) * (size_t)h, size = 54 + data;
  memset(b, 0, 54);
  b[0] = 'B';
  b[1] = 'M';
  for (int k = 0; k < 4; k++) {
    b[2 + k] = (unsigned char)(size >> (8 * k));
    b[18 + k] = (unsigned char)((unsigned)w >> (8 * k));
    b[22 + k] = (unsigned char)((unsigned)h >> (8 * k));
  }
  b[10] = 54;
  b[14] = 40;
  b[26] = 1;
  b[28] = 24;
  unsigned char *p = b + 54;
  for (int j = h - 1; j >= 0; j--) {
    for (int i = 0; i < w; i++) {
      const unsigned char *c = rgb + 3 * (j * w + i);
      *p++ = c[2];
      *p++ = c[1];
      *p++ = c[0];
    }
    for (int k = 0; k < pad; k++) *p++ = 0;
  }
  return size;
}

Test(image, rgb_becomes_rec709_luma_with_row_0_at_the_top)
{
  /* pure red, green, blue on the top row, a mixed colour and gray below */
  const unsigned char rgb[] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 200, 100, 50, 64, 64, 64, 0, 0, 0};
  unsigned char b[256];
  size_t n = bmp_bytes(b, 3, 2, rgb);
  lw_error err;
  lw_image_info info;
  lw_image *img = lw_image_decode(b, n, "t.bmp", 1e6, &info, &err);
  cr_assert_not_null(img, "%s", err.msg);
  cr_assert(info.width == 3 && info.height == 2 && info.channels == 3 && info.bits == 8);
  cr_assert_null(img->alpha);
  const double want[6] = {0.2126, 0.7152, 0.0722, (0.2126 * 200 + 0.7152 * 100 + 0.0722 * 50) / 255.0,
                          64 / 255.0, 0};
  for (int k = 0; k < 6; k++)
    cr_assert(fabs(img->tone[k] - want[k]) < 1e-6, "pixel %d: %g, want %g", k, img->tone[k], want[k]);
  lw_image_free(img);
  /* the same picture stored top down, as a negative height (legal in
  ** every BMP header; each was refused as "damaged: 3 x -2 pixels"): the
  ** same pixels, the same way up */
  unsigned char t[256];
  memcpy(t, b, n);
  const int h = -2;
  for (int k = 0; k < 4; k++) t[22 + k] = (unsigned char)((unsigned)h >> (8 * k));
  memcpy(t + 54, b + 54 + 12, 12); /* rows of 9 bytes padded to 12, swapped */
  memcpy(t + 54 + 12, b + 54, 12);
  img = lw_image_decode(t, n, "t.bmp", 1e6, &info, &err);
  cr_assert_not_null(img, "%s", err.msg);
  cr_assert(info.width == 3 && info.height == 2, "%d x %d", info.width, info.height);
  for (int k = 0; k < 6; k++)
    cr_assert(fabs(img->tone[k] - want[k]) < 1e-6, "top down, pixel %d: %g, want %g", k, img->tone[k], want[k]);
  lw_image_free(img);
  /* and its size read without decoding it, as a scene's picture is first
  ** looked at (still "damaged: 3 x -2 pixels" there, a photographer's find) */
  char path[] = "/tmp/lw_topdown_XXXXXX";
  int fd = mkstemp(path);
  cr_assert(fd >= 0);
  FILE *f = fdopen(fd, "wb");
  cr_assert(f && fwrite(t, 1, n, f) == n && fclose(f) == 0);
  cr_assert_eq(lw_image_probe(path, &info, &err), LW_OK, "%s", err.msg);
  cr_assert(info.width == 3 && info.height == 2, "%d x %d", info.width, info.height);
  remove(path);
}

Test(image, pgm_and_ppm_any_maxval_and_truncation)
{
  const unsigned char p8[] = "P5\n3 1\n255\n\x00\x80\xff";
  lw_error err;
  lw_image *img = lw_image_decode(p8, sizeof p8 - 1, "t.pgm", 1e6, NULL, &err);
  cr_assert_not_null(img, "%s", err.msg);
  cr_assert(img->tone[0] == 0.0f && fabs(img->tone[1] - 128 / 255.0) < 1e-6 && img->tone[2] == 1.0f);
  lw_image_free(img);
  /* 16 bits keep their precision: 1 / 65535 is not a multiple of 1/255 */
  const unsigned char p16[] = "P5\n2 1\n65535\n\x00\x01\x80\x00";
  lw_image_info info;
  img = lw_image_decode(p16, sizeof p16 - 1, "t.pgm", 1e6, &info, &err);
  cr_assert_not_null(img, "%s", err.msg);
  cr_assert_eq(info.bits, 16);
  cr_assert(fabs(img->tone[0] - 1 / 65535.0) < 1e-9, "%.9g", img->tone[0]);
  cr_assert(fabs(img->tone[1] - 32768 / 65535.0) < 1e-7);
  lw_image_free(img);
  /* comments in the header, a maxval that is neither 255 nor 65535, RGB */
  const unsigned char p6[] = "P6 # a comment\n2 1\n# another\n15\n\x0f\x00\x00\x05\x05\x05";
  img = lw_image_decode(p6, sizeof p6 - 1, "t.ppm", 1e6, NULL, &err);
  cr_assert_not_null(img, "%s", err.msg);
  cr_assert(fabs(img->tone[0] - 0.2126) < 1e-6 && fabs(img->tone[1] - 1 / 3.0) < 1e-5);
  lw_image_free(img);
  /* a sample above maxval is damage (it was clamped: drawn white) */
  const unsigned char over[] = "P6 2 1 15\n\x0f\x00\x00\x05\x10\x05";
  cr_assert_null(lw_image_decode(over, sizeof over - 1, "o.ppm", 1e6, NULL, &err));
  cr_assert(strstr(err.msg, "o.ppm: the PPM is damaged: the sample at row 1, column 2 is 16, above its maxval 15"),
            "%s", err.msg);
  /* a raster shorter than the header promises */
  const unsigned char cut[] = "P5 4 4 255\nabcdefghij";
  cr_assert_null(lw_image_decode(cut, sizeof cut - 1, "cut.pgm", 1e6, NULL, &err));
  cr_assert(err.code == LW_EINPUT && strstr(err.msg, "cut.pgm") && strstr(err.msg, "truncated"), "%s", err.msg);
  const unsigned char bad[] = "P5 4 x 255\n";
  cr_assert_null(lw_image_decode(bad, sizeof bad - 1, "bad.pgm", 1e6, NULL, &err));
  cr_assert(err.code == LW_EINPUT && strstr(err.msg, "bad.pgm"), "%s", err.msg);
}

/* A GIF's first picture, with its transparency: 12 x 6, the left half
** black, the lower right gray (127), the upper right transparent (made by
** ImageMagick, with its application extension before the picture, which
** the walk to the picture's end must skip).  stb_image reads a GIF cut
** short as zeros, so every cut before the picture's last data block is
** refused, naming the file and the GIF. */
Test(image, a_gif_decodes_and_a_gif_cut_short_is_refused)
{
  static const unsigned char gif[] = {
    0x47, 0x49, 0x46, 0x38, 0x39, 0x61, 0x0c, 0x00, 0x06, 0x00, 0xf1, 0x00, 0x00, 0x00, 0x00, 0x00, 0x7f, 0x7f, 0x7f,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x21, 0xf9, 0x04, 0x01, 0x00, 0x00, 0x02, 0x00, 0x21, 0xff, 0x0b, 0x49, 0x6d,
    0x61, 0x67, 0x65, 0x4d, 0x61, 0x67, 0x69, 0x63, 0x6b, 0x0e, 0x67, 0x61, 0x6d, 0x6d, 0x61, 0x3d, 0x30, 0x2e, 0x34,
    0x35, 0x34, 0x35, 0x34, 0x35, 0x00, 0x2c, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x00, 0x06, 0x00, 0x00, 0x02, 0x0f, 0x84,
    0x2f, 0xa9, 0x87, 0x9a, 0x6c, 0xdc, 0x83, 0xa1, 0x5a, 0x08, 0xec, 0xa5, 0x3a, 0x14, 0x00, 0x3b};
  lw_error err;
  lw_image_info info;
  lw_image *img = lw_image_decode(gif, sizeof gif, "t.gif", 1e6, &info, &err);
  cr_assert_not_null(img, "%s", err.msg);
  cr_assert(img->width == 12 && img->height == 6 && img->alpha, "%d x %d", img->width, img->height);
  for (int y = 0; y < 6; y++)
    for (int x = 0; x < 12; x++) {
      size_t k = (size_t)y * 12 + (size_t)x;
      double tone = x < 6 ? 0.0 : y >= 3 ? 127 / 255.0 : 1.0, alpha = x >= 6 && y < 3 ? 0.0 : 1.0;
      cr_assert(fabs(img->tone[k] - tone) < 1e-6 && fabs(img->alpha[k] - alpha) < 1e-6,
                "pixel (%d, %d): tone %g alpha %g, expected %g and %g", x, y, img->tone[k], img->alpha[k], tone, alpha);
    }
  lw_image_free(img);
  /* the last data block ends at byte 90 (its empty terminator); the trailer after it is not needed */
  for (size_t cut = 1; cut < sizeof gif - 1; cut++) {
    cr_assert_null(lw_image_decode(gif, cut, "cut.gif", 1e6, NULL, &err), "a cut at %zu of %zu decoded", cut,
                   sizeof gif);
    cr_assert(err.code == LW_EINPUT && strstr(err.msg, "cut.gif: ") && (strstr(err.msg, "GIF") || cut < 6), "cut at %zu: %s",
              cut, err.msg);
  }
  img = lw_image_decode(gif, sizeof gif - 1, "t.gif", 1e6, NULL, &err);
  cr_assert_not_null(img, "without its trailer: %s", err.msg);
  lw_image_free(img);
}

/* A GIF whose large screen its data could not paint a quarter of is
** refused before it is decoded: 35 bytes that said 23000 x 23000 took 2 GB
** (a 1 x 1 picture's data: clear, one pixel, end).  Up to 2e7 pixels such a
** screen is decoded as before, its background around the picture (a crop
** ImageMagick kept on its 2000 x 1500 canvas was refused). */
Test(image, a_gif_whose_data_cannot_cover_its_screen_is_refused_before_decoding)
{
  unsigned char gif[] = {'G', 'I', 'F', '8', '9', 'a', 0, 0, 0, 0, 0x80, 0, 0, 0, 0, 0, 255, 255, 255,
                         0x2c, 0, 0, 0, 0, 1, 0, 1, 0, 0, 2, 2, 0x04, 0x01, 0, 0x3b};
  const unsigned sides[][2] = {{23000, 23000}, {5001, 4000}, {2000, 1500}};
  for (int k = 0; k < 3; k++) {
    gif[6] = sides[k][0] & 255, gif[7] = sides[k][0] >> 8, gif[8] = sides[k][1] & 255, gif[9] = sides[k][1] >> 8;
    lw_error err;
    lw_image *img = lw_image_decode(gif, sizeof gif, "s.gif", 1e7, NULL, &err);
    if (k < 2)
      cr_assert(!img && err.code == LW_EINPUT && strstr(err.msg, "s.gif: a GIF whose ") &&
                    strstr(err.msg, " screen its first picture (1 x 1, 2 bytes of data) can paint at most 20 pixels "
                                    "of: damaged, or made to take memory"),
                "%u x %u: %s", sides[k][0], sides[k][1], img ? "decoded" : err.msg);
    else
      cr_assert(img && img->width == 2000 && img->height == 1500, "%s", img ? "" : err.msg);
    lw_image_free(img);
  }
}

/* stb_image 2.27 writes past a JPEG Huffman table whose code counts sum
** to more than 256 (UBSan in the image fuzzer: index 257 of size[257]),
** in stbi_info too, which reads the tables before the frame; and it reads
** its uninitialised memory for a table a scan names and no segment
** defined (valgrind; the fuzzer saw the same file decode, then not, in one
** process).  Such files, kept in the fuzz corpus (a table after the frame,
** one before it behind bytes the decoder skips one by one, one in a file
** that starts with fill bytes before its start marker; a scan with an
** undefined AC table, one with an undefined quantization table), are
** refused before they reach the decoder, by the probe too, and the
** corpus's sound JPEGs still decode. */
Test(image, pictures_the_decoder_mishandles_are_refused)
{
  static const char *const bad[] = {"dht-257-codes.jpg", "dht-in-info.jpg", "dht-after-fill.jpg",
                                    "undefined-huffman.jpg", "undefined-quant.jpg"};
  static const char *const codes[] = {"a Huffman table of 790 codes", "a Huffman table of 1234 codes",
                                      "a Huffman table of 301 codes", "a scan uses a Huffman table it never defined",
                                      "a scan uses a quantization table it never defined"};
  char path[1024];
  lw_error err;
  for (int k = 0; k < 5; k++) {
    snprintf(path, sizeof path, "%s/tests/fuzz/corpus/image/%s", lw_test_root(), bad[k]);
    cr_assert_null(lw_image_load(path, 1e6, NULL, &err));
    cr_assert(err.code == LW_EINPUT && strstr(err.msg, bad[k]) && strstr(err.msg, codes[k]), "%s", err.msg);
    lw_image_info info;
    cr_assert_eq(lw_image_probe(path, &info, &err), LW_EINPUT);
    cr_assert(strstr(err.msg, codes[k]), "probe: %s", err.msg);
  }
  /* found by the same harness: a BMP of width 0 passes stb_image's header check */
  snprintf(path, sizeof path, "%s/tests/fuzz/corpus/image/bmp-width-0.bmp", lw_test_root());
  cr_assert_null(lw_image_load(path, 1e6, NULL, &err));
  cr_assert(strstr(err.msg, "bmp-width-0.bmp: the BMP is damaged: 0 x 27 pixels"), "%s", err.msg);
  lw_image_info info;
  cr_assert_eq(lw_image_probe(path, &info, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "0 x 27 pixels"), "probe: %s", err.msg);
  const char *sound[] = {"exif6.jpg", "prog.jpg"};
  for (int k = 0; k < 2; k++) {
    snprintf(path, sizeof path, "%s/tests/fuzz/corpus/image/%s", lw_test_root(), sound[k]);
    lw_image *img = lw_image_load(path, 1e6, NULL, &err);
    cr_assert_not_null(img, "%s", err.msg);
    lw_image_free(img);
  }
}

/* JPEG frames the decoder does not read (12 bits, arithmetic-coded,
** lossless) are named as such: its own message said "not an image". */
Test(image, jpeg_kinds_the_decoder_does_not_read_are_named)
{
  char path[1024], dir[64];
  snprintf(path, sizeof path, "%s/tests/fuzz/corpus/image/exif6.jpg", lw_test_root());
  FILE *f = fopen(path, "rb");
  cr_assert_not_null(f);
  unsigned char d[65536];
  size_t n = fread(d, 1, sizeof d, f);
  fclose(f);
  size_t sof = 0;
  while (sof + 4 < n && !(d[sof] == 0xFF && d[sof + 1] == 0xC0)) sof++;
  cr_assert(sof + 4 < n, "a baseline frame");
  cr_assert_eq(lw_test_dir_make(dir, "jpeg"), 0);
  static const struct { size_t at; unsigned char byte; const char *msg; } kind[] = {
      {1, 0xC9, "an arithmetic-coded JPEG, which the decoder does not read"},
      {1, 0xC3, "a lossless JPEG, which the decoder does not read"},
      {4, 12, "a 12-bit JPEG, which the decoder does not read: expected 8 bits"}};
  for (int k = 0; k < 3; k++) {
    unsigned char was = d[sof + kind[k].at];
    d[sof + kind[k].at] = kind[k].byte;
    snprintf(path, sizeof path, "%s/k%d.jpg", dir, k);
    f = fopen(path, "wb");
    fwrite(d, 1, n, f);
    fclose(f);
    d[sof + kind[k].at] = was;
    lw_error err;
    cr_assert_null(lw_image_load(path, 1e6, NULL, &err));
    cr_assert(err.code == LW_EINPUT && strstr(err.msg, kind[k].msg), "%s", err.msg);
  }
  lw_test_dir_remove(dir);
}

/* Boxed down to at most max_pixels, whatever the shape: a strip thinner
** than the reduction keeps one pixel across and at most max_pixels along
** (the image fuzzer's JPEG of 23561 x 5 came to 549 x 1 for 64 pixels). */
Test(image, a_thin_strip_is_boxed_down_to_the_budget_too)
{
  unsigned char pgm[64 + 3000];
  for (int turn = 0; turn < 2; turn++) {
    int n = snprintf((char *)pgm, 64, "P5 %d %d 255\n", turn ? 1 : 3000, turn ? 3000 : 1);
    for (int k = 0; k < 3000; k++) pgm[n + k] = (unsigned char)(k < 1500 ? 0 : 255);
    lw_error err;
    lw_image *img = lw_image_decode(pgm, (size_t)n + 3000, "strip.pgm", 64, NULL, &err);
    cr_assert_not_null(img, "%s", err.msg);
    cr_assert(turn ? img->width == 1 && img->height == 64 : img->width == 64 && img->height == 1, "%d x %d",
              img->width, img->height);
    cr_assert(img->tone[0] < 0.01f && img->tone[63] > 0.99f, "the strip's ends: %g and %g", img->tone[0],
              img->tone[63]);
    lw_image_free(img);
  }
}

Test(image, alpha_is_kept_and_the_tone_composited_over_white)
{
  const float g[4] = {0, 0, 0.5f, 1}, a[4] = {1, 0.5f, 0.2f, 0};
  lw_test_png(lw_test_path("a.png"), 2, 2, g, a);
  lw_error err;
  lw_image_info info;
  lw_image *img = lw_image_load(lw_test_path("a.png"), 1e6, &info, &err);
  cr_assert_not_null(img, "%s", err.msg);
  cr_assert_eq(info.channels, 4);
  cr_assert_not_null(img->alpha);
  for (int k = 0; k < 4; k++) {
    double A = lround(255 * a[k]) / 255.0;
    cr_assert(fabs(img->alpha[k] - A) < 1e-6, "alpha %d: %g", k, img->alpha[k]);
    /* straight colour in the file is rounded to 8 bits: tolerance 1/255 */
    cr_assert(fabs(img->tone[k] - (A * g[k] + 1 - A)) < 1.01 / 255, "tone %d: %g", k, img->tone[k]);
  }
  lw_image_free(img);
}

/* (a FIFO among them: opening one waits for a writer, and the test would
** hang there without the timeout) */
Test(image, bad_files_are_input_errors_naming_the_file, .timeout = 60)
{
  float g[64 * 64];
  for (int k = 0; k < 64 * 64; k++) g[k] = (float)urand(0, 1); /* incompressible: a long IDAT */
  lw_test_png(lw_test_path("good.png"), 64, 64, g, NULL);
  FILE *f = fopen(lw_test_path("good.png"), "rb");
  static unsigned char buf[65536];
  size_t n = fread(buf, 1, sizeof buf, f);
  fclose(f);
  lw_test_write(lw_test_path("cut.png"), buf, n / 2);
  lw_test_write(lw_test_path("empty.png"), "", 0);
  lw_test_write(lw_test_path("text.png"), "hello, I am not a picture\n", 26);
  static unsigned char rgb[3 * 20 * 10], bmp[1024];
  size_t nb = bmp_bytes(bmp, 20, 10, rgb);
  lw_test_write(lw_test_path("cut.bmp"), bmp, nb - 7);
  cr_assert_eq(mkfifo(lw_test_path("fifo.png"), 0600), 0);
  const char *names[] = {"cut.png", "empty.png", "text.png", "missing.png", ".", "cut.bmp", "fifo.png"};
  for (int k = 0; k < 7; k++) {
    lw_error err;
    lw_error_clear(&err);
    char path[128];
    snprintf(path, sizeof path, "%s", lw_test_path(names[k]));
    cr_assert_null(lw_image_load(path, 1e6, NULL, &err), "%s", names[k]);
    cr_assert_eq(err.code, LW_EINPUT, "%s: %s", names[k], err.msg);
    cr_assert(strstr(err.msg, path), "%s: message names the file: %s", names[k], err.msg);
    cr_assert_null(strchr(err.msg, '\n'));
  }
  lw_image *img = lw_image_load(lw_test_path("good.png"), 1e6, NULL, NULL);
  cr_assert_not_null(img);
  lw_image_free(img);
  img = lw_image_decode(bmp, nb, "whole.bmp", 1e6, NULL, NULL);
  cr_assert_not_null(img, "the whole BMP decodes");
  lw_image_free(img);
}

Test(image, pictures_above_the_budget_are_box_filtered_keeping_the_mean)
{
  int w = 203, h = 151;
  float *g = malloc(sizeof(float) * w * h);
  for (int k = 0; k < w * h; k++) g[k] = (float)urand(0, 1);
  lw_test_png(lw_test_path("big.png"), w, h, g, NULL);
  free(g);
  lw_image_info info;
  lw_image *full = lw_image_load(lw_test_path("big.png"), 1e9, &info, NULL);
  lw_image *small = lw_image_load(lw_test_path("big.png"), 3000, NULL, NULL);
  cr_assert(full && small);
  cr_assert(full->width == w && full->height == h);
  cr_assert(small->width * small->height <= 3000 && small->width * small->height > 2500,
            "%d x %d", small->width, small->height);
  cr_assert(fabs((double)small->width / small->height - (double)w / h) < 0.05, "aspect kept");
  /* box filtering with fractional edges keeps the mean up to float rounding */
  double m0 = mean_of(full->tone, (size_t)w * h), m1 = mean_of(small->tone, (size_t)small->width * small->height);
  cr_assert(fabs(m1 - m0) < 1e-5, "mean %.8f vs %.8f", m1, m0);
  lw_image_free(full);
  lw_image_free(small);
}

Test(image, resize_keeps_the_mean_and_interpolates_when_enlarging)
{
  rng_seed(11);
  lw_image *img = random_image(97, 61);
  double m0 = mean_of(img->tone, 97 * 61);
  lw_image *s = lw_image_resize(img, 40, 25, NULL);
  cr_assert_not_null(s);
  cr_assert(fabs(mean_of(s->tone, 40 * 25) - m0) < 1e-5);
  lw_image_free(s);
  /* enlarging a linear ramp by linear interpolation reproduces the ramp
  ** between the outermost pixel centres */
  lw_image *ramp = lw_image_new(10, 3, 0, NULL);
  for (int j = 0; j < 3; j++)
    for (int i = 0; i < 10; i++) ramp->tone[j * 10 + i] = (float)(0.05 + 0.1 * i);
  lw_image *big = lw_image_resize(ramp, 40, 7, NULL);
  cr_assert_not_null(big);
  for (int i = 2; i < 38; i++) {
    double u = (i + 0.5) * 10.0 / 40.0 - 0.5; /* source coordinate of the centre */
    cr_assert(fabs(big->tone[3 * 40 + i] - (0.05 + 0.1 * u)) < 1e-6, "column %d", i);
  }
  lw_image_free(big);
  lw_image_free(ramp);
  lw_image_free(img);
}

Test(image, blur_keeps_the_mean_exactly_even_when_wider_than_the_picture)
{
  rng_seed(12);
  double sigmas[] = {0.7, 2.3, 40};
  for (int k = 0; k < 3; k++) {
    lw_image *img = random_image(37, 23);
    double m0 = mean_of(img->tone, 37 * 23);
    cr_assert_eq(lw_image_blur(img, sigmas[k], NULL), LW_OK);
    cr_assert(fabs(mean_of(img->tone, 37 * 23) - m0) < 1e-6, "sigma %g", sigmas[k]);
    lw_image_free(img);
  }
}

/* A blur far under a pixel is the picture itself, to the last bit, down to
** widths whose square underflows (1e-170 pixels made every pixel NaN); at
** a tenth of a pixel, where it starts, its side taps are exp(-50). */
Test(image, a_blur_far_under_a_pixel_is_the_picture_itself)
{
  rng_seed(13);
  const double sigmas[] = {1e-170, 1e-10, 0.099, 0.1};
  for (int k = 0; k < 4; k++) {
    lw_image *img = random_image(9, 7), *orig = random_image(9, 7);
    memcpy(orig->tone, img->tone, 9 * 7 * sizeof *img->tone);
    cr_assert_eq(lw_image_blur(img, sigmas[k], NULL), LW_OK);
    cr_assert_eq(memcmp(orig->tone, img->tone, 9 * 7 * sizeof *img->tone), 0, "sigma %g", sigmas[k]);
    lw_image_free(img);
    lw_image_free(orig);
  }
}

Test(image, blur_is_the_same_for_any_thread_count)
{
  rng_seed(13);
  lw_image *a = random_image(83, 57), *b = lw_image_resize(a, 83, 57, NULL);
  cr_assert(b && !memcmp(a->tone, b->tone, sizeof(float) * 83 * 57));
  int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  cr_assert_eq(lw_image_blur(a, 3.3, NULL), LW_OK);
  omp_set_num_threads(3);
  cr_assert_eq(lw_image_blur(b, 3.3, NULL), LW_OK);
  omp_set_num_threads(threads);
  cr_assert(!memcmp(a->tone, b->tone, sizeof(float) * 83 * 57), "bit for bit");
  lw_image_free(a);
  lw_image_free(b);
}

/* Half-sample symmetric reflection, as the blur mirrors a picture. */
static long mirror(long i, long n)
{
  long m = ((i % (2 * n)) + 2 * n) % (2 * n);
  return m < n ? m : 2 * n - 1 - m;
}

/* The blur's definition summed directly in doubles: the Gaussian of sigma
** cut at 4 sigma and normalised, rows then columns, the picture mirrored. */
static void blur_reference(const float *in, int w, int h, double s, double *out)
{
  long R = (long)ceil(4 * s);
  double *g = malloc((size_t)(2 * R + 1) * sizeof *g), *t = malloc((size_t)w * h * sizeof *t), sum = 0;
  for (long d = -R; d <= R; d++) sum += g[d + R] = exp(-0.5 * (double)(d * d) / (s * s));
  for (long d = -R; d <= R; d++) g[d + R] /= sum;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      double v = 0;
      for (long d = -R; d <= R; d++) v += g[d + R] * in[(size_t)y * w + (size_t)mirror(x + d, w)];
      t[(size_t)y * w + x] = v;
    }
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      double v = 0;
      for (long d = -R; d <= R; d++) v += g[d + R] * t[(size_t)mirror(y + d, h) * w + x];
      out[(size_t)y * w + x] = v;
    }
  free(g);
  free(t);
}

/* Wide blurs are summed at every f-th pixel and interpolated (image.c):
** against the direct sum they stay within 5e-5 of the tone's range, on
** noise (worst 1.6e-6) and on a sharp edge (2e-5 at sigma 41: the kernel's
** cut at 4 sigma, a step of e^-8 of its peak, puts a kink in the blurred
** edge that the interpolation rounds), at the first sparse sigma and wider
** than the picture; an 8-bit picture's steps are 4e-3.  The same bits for
** any thread count. */
Test(image, wide_blurs_summed_sparsely_match_the_direct_sum)
{
  rng_seed(14);
  const int w = 151, h = 97;
  const double sigmas[] = {16, 23.5, 41, 180};
  double *ref = malloc((size_t)w * h * sizeof *ref);
  for (int edge = 0; edge < 2; edge++)
    for (int k = 0; k < 4; k++) {
      lw_image *img = random_image(w, h);
      if (edge)
        for (int i = 0; i < w * h; i++) img->tone[i] = (i % w) * 3 + (i / w) * 2 > 250 ? 1.0f : 0.0f;
      blur_reference(img->tone, w, h, sigmas[k], ref);
      lw_image *b = lw_image_resize(img, w, h, NULL);
      int threads = omp_get_max_threads();
      omp_set_num_threads(1);
      cr_assert_eq(lw_image_blur(img, sigmas[k], NULL), LW_OK);
      omp_set_num_threads(3);
      cr_assert_eq(lw_image_blur(b, sigmas[k], NULL), LW_OK);
      omp_set_num_threads(threads);
      cr_assert(!memcmp(img->tone, b->tone, sizeof(float) * w * h), "sigma %g: bit for bit", sigmas[k]);
      double worst = 0;
      for (int i = 0; i < w * h; i++) worst = fmax(worst, fabs(img->tone[i] - ref[i]));
      cr_log_info("sigma %g, %s: worst %.2e", sigmas[k], edge ? "edge" : "noise", worst);
      cr_assert(worst < 5e-5, "sigma %g, %s: %.3g off the direct sum", sigmas[k], edge ? "edge" : "noise", worst);
      lw_image_free(img);
      lw_image_free(b);
    }
  free(ref);
}

Test(image, blurred_impulse_has_the_variance_sigma_squared)
{
  /* A unit impulse blurred by a Gaussian of sigma s spreads with variance
  ** s^2 per axis.  The kernel is cut at 4 sigma (missing variance about
  ** 1e-3 relative) and sampled (error exponentially small for s >= 1). */
  const int n = 121, c = 60;
  const double s = 3.7;
  lw_image *img = lw_image_new(n, n, 0, NULL);
  memset(img->tone, 0, sizeof(float) * n * n);
  img->tone[c * n + c] = 1.0f;
  cr_assert_eq(lw_image_blur(img, s, NULL), LW_OK);
  double sum = 0, vx = 0, vy = 0, cxy = 0;
  for (int j = 0; j < n; j++)
    for (int i = 0; i < n; i++) {
      double v = img->tone[j * n + i];
      sum += v;
      vx += v * (i - c) * (i - c);
      vy += v * (j - c) * (j - c);
      cxy += v * (i - c) * (j - c);
    }
  cr_assert(fabs(sum - 1) < 1e-5);
  cr_assert(fabs(vx / sum - s * s) < 3e-3 * s * s, "var x %g, want %g", vx / sum, s * s);
  cr_assert(fabs(vy / sum - s * s) < 3e-3 * s * s, "var y %g", vy / sum);
  cr_assert(fabs(cxy / sum) < 1e-4, "no covariance");
  lw_image_free(img);
}

/* The curve takes the picture under a pixel's transparency, not the white
** paper it shows: a transparent background inverted had asked for full ink
** (a white logo on transparency, inverted, was hatched all over). */
Test(image, tone_curve_leaves_transparency_white)
{
  lw_image *img = lw_image_new(3, 1, 1, NULL);
  /* picture tones 0.2 under alpha 1, 0.5, 0 (composited over white) */
  const float a[3] = {1, 0.5f, 0}, t[3] = {0.2f, 0.2f, 0.2f};
  for (int k = 0; k < 3; k++) {
    img->alpha[k] = a[k];
    img->tone[k] = a[k] * t[k] + 1 - a[k];
  }
  lw_image_tone_curve(img, img->alpha, 2.0, 1.5, 1);
  for (int k = 0; k < 3; k++) {
    double c = 0.5 + 1.5 * (pow(1 - t[k], 2.0) - 0.5), want = a[k] * fmin(1, fmax(0, c)) + 1 - a[k];
    cr_assert(fabs(img->tone[k] - want) < 1e-6, "alpha %g: %g, want %g", a[k], img->tone[k], want);
  }
  cr_assert_eq(img->tone[2], 1.0f, "transparent stays paper");
  lw_image_free(img);
}

Test(image, tone_curve_invert_gamma_contrast)
{
  lw_image *img = lw_image_new(5, 1, 0, NULL);
  const float t[5] = {0, 0.25f, 0.5f, 0.8f, 1};
  memcpy(img->tone, t, sizeof t);
  lw_image_tone_curve(img, NULL, 2.0, 1.0, 0);
  for (int k = 0; k < 5; k++) cr_assert(fabs(img->tone[k] - t[k] * t[k]) < 1e-6);
  memcpy(img->tone, t, sizeof t);
  lw_image_tone_curve(img, NULL, 1.0, 1.0, 1);
  for (int k = 0; k < 5; k++) cr_assert(fabs(img->tone[k] - (1 - t[k])) < 1e-6);
  memcpy(img->tone, t, sizeof t);
  lw_image_tone_curve(img, NULL, 1.0, 3.0, 0);
  const float c3[5] = {0, 0, 0.5f, 1, 1}; /* 0.5 + 3 (t - 0.5), clipped */
  for (int k = 0; k < 5; k++) cr_assert(fabs(img->tone[k] - c3[k]) < 1e-6, "%d: %g", k, img->tone[k]);
  /* the order: invert, then gamma, then contrast */
  memcpy(img->tone, t, sizeof t);
  lw_image_tone_curve(img, NULL, 0.5, 0.5, 1);
  for (int k = 0; k < 5; k++) {
    double want = 0.5 + 0.5 * (sqrt(1 - t[k]) - 0.5);
    cr_assert(fabs(img->tone[k] - want) < 1e-6, "%d", k);
  }
  lw_image_free(img);
}

/* Auto levels on n tones spread evenly over [a, b]: the share `clip` at each
** end goes to 0 and 1 and the rest is the linear map of the tones between the
** levels found; those lie within a bin (1/4096) and a pixel's step of the
** clip's quantiles. */
Test(image, levels_stretch_the_tones_between_the_quantiles)
{
  const int n = 2000;
  const double a = 0.3, b = 0.6, step = (b - a) / (n - 1), bin = 1.0 / 4096;
  lw_image *img = lw_image_new(n, 1, 0, NULL);
  for (int k = 0; k < n; k++) img->tone[(k * 7) % n] = (float)(a + step * k); /* any order */
  float *orig = malloc(n * sizeof *orig);
  memcpy(orig, img->tone, n * sizeof *orig);
  double lo, hi;
  cr_assert_eq(lw_image_levels(img, NULL, 0.01, 1, &lo, &hi, NULL, NULL), LW_OK);
  cr_assert(fabs(lo - (a + 0.01 * (b - a))) < bin + step, "lo %g", lo);
  cr_assert(fabs(hi - (b - 0.01 * (b - a))) < bin + step, "hi %g", hi);
  int black = 0, white = 0;
  for (int k = 0; k < n; k++) {
    double want = (orig[k] - lo) / (hi - lo);
    want = want < 0 ? 0 : (want > 1 ? 1 : want);
    cr_assert(fabs(img->tone[k] - want) < 1e-6, "%d: %g, want %g", k, img->tone[k], want);
    black += img->tone[k] == 0.0f;
    white += img->tone[k] == 1.0f;
  }
  cr_assert(abs(black - n / 100) <= 2 + (int)(bin / step) && abs(white - n / 100) <= 2 + (int)(bin / step),
            "black %d, white %d", black, white);
  /* clip 0: the darkest and lightest pixels themselves */
  memcpy(img->tone, orig, n * sizeof *orig);
  cr_assert_eq(lw_image_levels(img, NULL, 0, 1, &lo, &hi, NULL, NULL), LW_OK);
  cr_assert(fabs(lo - a) < bin && fabs(hi - b) < bin, "%g %g", lo, hi);
  free(orig);
  lw_image_free(img);
}

/* A low-contrast elevation model: a flat sea at its darkest tone (57 % of
** the pixels at 0.4578) and land rising to 0.4639.  Its dark end, a flat
** colour left alone at 0, with the light end stretched down to the land's
** top made the sea 0.99, all white (an empty drawing); with flat = 2 that end
** is stretched as any, and the span, under 0.05, widened about its middle:
** the sea darker than the land, as in the picture.  flat = 1 (runs begun
** before) keeps the old levels; a flat colour that stays on its side (white
** paper under a darker picture) is still left alone. */
Test(image, a_flat_end_is_not_carried_across_the_middle)
{
  const int n = 1000;
  const double sea = 0.4578, top = 0.4639;
  lw_image *img = lw_image_new(n, 1, 0, NULL);
  double lo, hi;
  int kept;
  for (int flat = 1; flat <= 2; flat++) {
    for (int k = 0; k < n; k++) img->tone[k] = (float)(k < 570 ? sea : sea + (top - sea) * (k - 569) / 430.0);
    cr_assert_eq(lw_image_levels(img, NULL, 0.01, flat, &lo, &hi, &kept, NULL), LW_OK);
    /* (the dark end kept as a flat colour is said: the run's note tells why) */
    cr_assert_eq(kept, flat == 1 ? 1 : 0, "flat %d: kept %d", flat, kept);
    if (flat == 1) {
      cr_assert(lo == 0.0 && img->tone[0] > 0.98, "as before: levels %g to %g, sea %g", lo, hi, img->tone[0]);
      continue;
    }
    const double mid = 0.5 * (sea + top);
    cr_assert(fabs(hi - lo - LW_IMAGE_LEVELS_MIN_SPAN) < 1e-12 && fabs(0.5 * (lo + hi) - mid) < 2.0 / 4096,
              "levels %g to %g", lo, hi);
    cr_assert(img->tone[0] < 0.5 && img->tone[n - 1] > img->tone[0] + 0.1, "sea %g, land's top %g", img->tone[0],
              img->tone[n - 1]);
  }
  /* white paper (60 %) under a picture from 0.2 to 0.6: the paper stays white */
  for (int k = 0; k < n; k++) img->tone[k] = (float)(k < 600 ? 1.0 : 0.2 + 0.4 * (k - 600) / 399.0);
  cr_assert_eq(lw_image_levels(img, NULL, 0.01, 2, &lo, &hi, &kept, NULL), LW_OK);
  cr_assert(hi == 1.0 && img->tone[0] == 1.0f && lo > 0.2 && kept == 0, "levels %g to %g, kept %d", lo, hi, kept);
  /* a flat colour on its own side of the middle stays there, left alone: a
  ** flat 0.35 as the lightest of a dark logo (60 % from 0 to 0.2) went white,
  ** a flat 0.6 as the darkest of a pale one (60 % from 0.8 to 1) black */
  for (int k = 0; k < n; k++) img->tone[k] = (float)(k < 400 ? 0.35 : 0.2 * (k - 400) / 599.0);
  cr_assert_eq(lw_image_levels(img, NULL, 0.01, 2, &lo, &hi, NULL, NULL), LW_OK);
  cr_assert(hi == 1.0 && img->tone[0] < 0.5, "dark logo: levels %g to %g, its flat colour %g", lo, hi, img->tone[0]);
  for (int k = 0; k < n; k++) img->tone[k] = (float)(k < 400 ? 0.6 : 0.8 + 0.2 * (k - 400) / 599.0);
  cr_assert_eq(lw_image_levels(img, NULL, 0.01, 2, &lo, &hi, NULL, NULL), LW_OK);
  cr_assert(lo == 0.0 && img->tone[0] > 0.5, "pale logo: levels %g to %g, its flat colour %g", lo, hi, img->tone[0]);
  /* a disc's flat 0.33 (90 %) beside a bar from 0.10 to 0.26: kept, not white */
  for (int k = 0; k < n; k++) img->tone[k] = (float)(k < 900 ? 0.33 : 0.10 + 0.16 * (k - 900) / 99.0);
  cr_assert_eq(lw_image_levels(img, NULL, 0.01, 2, &lo, &hi, NULL, NULL), LW_OK);
  cr_assert(hi == 1.0 && img->tone[0] < 0.5, "disc and bar: levels %g to %g, the disc %g", lo, hi, img->tone[0]);
  /* crowded at the far end, a flat colour on either side of the middle: a
  ** signed elevation model's sea at 0.5 (land to 0.504), and a light flat
  ** sea at 0.40 (land down to 0.394), which went white and black whole */
  static const double sea2[2] = {0.5, 0.40}, rise[2] = {0.004, -0.006};
  for (int c = 0; c < 2; c++) {
    for (int k = 0; k < n; k++) img->tone[k] = (float)(k < 570 ? sea2[c] : sea2[c] + rise[c] * (k - 569) / 430.0);
    cr_assert_eq(lw_image_levels(img, NULL, 0.01, 2, &lo, &hi, NULL, NULL), LW_OK);
    cr_assert(fabs(hi - lo - LW_IMAGE_LEVELS_MIN_SPAN) < 1e-12 && img->tone[0] > 0.3 && img->tone[0] < 0.7,
              "sea %g: levels %g to %g, the sea %g", sea2[c], lo, hi, img->tone[0]);
  }
  lw_image_free(img);
}

/* A half-transparent picture (a faded overlay, a soft cut-out) keeps its
** transparency through the levels: its own tones, under the paper the alpha
** lets through, are stretched, and composited again.  The levels were taken
** of the composite and stretched it: with the tone curve's taking apart
** after, its darks went to one grey (gamma 1.2), or it came out opaque. */
Test(image, levels_stretch_the_picture_under_its_transparency)
{
  const int n = 1000;
  lw_image *img = lw_image_new(n, 1, 1, NULL);
  for (int k = 0; k < n; k++) {
    const double own = 0.2 + 0.4 * k / (n - 1), a = 0.5;
    img->alpha[k] = (float)a;
    img->tone[k] = (float)(a * own + 1.0 - a);
  }
  double lo, hi;
  cr_assert_eq(lw_image_levels(img, img->alpha, 0, 1, &lo, &hi, NULL, NULL), LW_OK);
  cr_assert(fabs(lo - 0.2) < 1e-3 && fabs(hi - 0.6) < 1e-3, "the picture's own levels: %g %g", lo, hi);
  for (int k = 0; k < n; k++) {
    const double own = 0.2 + 0.4 * k / (n - 1), want = 0.5 * fmin(fmax((own - lo) / (hi - lo), 0), 1) + 0.5;
    cr_assert(fabs(img->tone[k] - want) < 1e-5, "%d: %g, want %g (half ink at most)", k, img->tone[k], want);
  }
  /* then the tone curve takes the picture out from under it again: the
  ** stretched own tones, gamma applied, still at half ink */
  lw_image_tone_curve(img, img->alpha, 1.2, 1.0, 0);
  for (int k = 0; k < n; k += 111) {
    const double own = 0.2 + 0.4 * k / (n - 1), t = fmin(fmax((own - lo) / (hi - lo), 0), 1);
    cr_assert(fabs(img->tone[k] - (0.5 * pow(t, 1.2) + 0.5)) < 1e-5, "%d: %g", k, img->tone[k]);
  }
  lw_image_free(img);
}

/* Thin strokes on transparent paper, blurred (image_blur): the blurred
** alpha is under one half everywhere, and counting the pixels by it left
** only the border's (the levels came out 0 to 0.159 and the picture white);
** they are counted by the picture's own alpha, and read under the blurred
** one. */
Test(image, levels_of_blurred_strokes_on_transparent_paper)
{
  const int w = 60, h = 200;
  lw_image *img = lw_image_new(w, h, 1, NULL);
  float *cover = malloc((size_t)w * h * sizeof *cover);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      const double own = 0.15 + 0.5 * y / (h - 1), a = x == 30 ? 1.0 : 0.0;
      img->alpha[y * w + x] = (float)a;
      img->tone[y * w + x] = (float)(a * own + 1.0 - a);
    }
  memcpy(cover, img->alpha, (size_t)w * h * sizeof *cover);
  cr_assert_eq(lw_image_blur(img, 4.0, NULL), LW_OK);
  cr_assert_eq(lw_image_blur_plane(cover, w, h, 4.0, NULL), LW_OK);
  float most = 0;
  for (int k = 0; k < w * h; k++) most = fmaxf(most, cover[k]);
  cr_assert_lt(most, 0.5f, "the blurred stroke is under half opaque everywhere");
  double lo, hi;
  cr_assert_eq(lw_image_levels(img, cover, 0, 1, &lo, &hi, NULL, NULL), LW_OK);
  cr_assert(fabs(lo - 0.15) < 0.01 && fabs(hi - 0.65) < 0.01, "the strokes' own levels: %g %g", lo, hi);
  free(cover);
  lw_image_free(img);
}

/* Transparent pixels (white after compositing) are not counted and stay
** white; a flat picture is stretched at most 1 / LW_IMAGE_LEVELS_MIN_SPAN
** times, about its middle, and inside [0, 1] near white. */
Test(image, levels_skip_transparent_pixels_and_cap_the_stretch)
{
  const int n = 1000;
  lw_image *img = lw_image_new(2 * n, 1, 1, NULL);
  for (int k = 0; k < n; k++) {
    img->tone[2 * k] = (float)(0.3 + 0.3 * k / (n - 1));
    img->tone[2 * k + 1] = 1.0f;
    img->alpha[2 * k + 1] = k % 2 ? 0.0f : 0.49f;
  }
  double lo, hi;
  cr_assert_eq(lw_image_levels(img, NULL, 0.05, 1, &lo, &hi, NULL, NULL), LW_OK);
  cr_assert(fabs(lo - 0.315) < 1e-3 && fabs(hi - 0.585) < 1e-3, "%g %g", lo, hi);
  for (int k = 0; k < n; k++) cr_assert_eq(img->tone[2 * k + 1], 1.0f);
  lw_image_free(img);

  /* tones spread evenly over +-0.01 about 0.5, and about 0.99 (82 bins of
  ** the histogram, none a plateau) */
  static const double mid[2] = {0.5, 0.99};
  for (int m = 0; m < 2; m++) {
    img = lw_image_new(n, 1, 0, NULL);
    for (int k = 0; k < n; k++) img->tone[k] = (float)(mid[m] + 0.01 * (2.0 * k / (n - 1) - 1.0));
    cr_assert_eq(lw_image_levels(img, NULL, 0.01, 1, &lo, &hi, NULL, NULL), LW_OK);
    cr_assert(fabs(hi - lo - LW_IMAGE_LEVELS_MIN_SPAN) < 1e-12 && lo >= 0 && hi <= 1, "%g %g", lo, hi);
    if (m == 0) cr_assert(fabs(0.5 * (lo + hi) - 0.5) < 1e-3, "%g %g", lo, hi);
    else cr_assert(hi == 1.0, "%g", hi);
    double spread = 0;
    for (int k = 0; k < n; k++) spread = fmax(spread, fabs(img->tone[k] - img->tone[0]));
    cr_assert(spread <= 0.02 / LW_IMAGE_LEVELS_MIN_SPAN + 1e-5, "spread %g", spread);
    lw_image_free(img);
  }
}

/* A graphic's flat colours: an end whose level is one tone held by more than
** LW_IMAGE_LEVELS_PLATEAU of the pixels keeps its place.  A disc of tone 0.33
** (40 % of the pixels, the lightest) and a bar of 0.26 (10 %) stay as they
** are; the same disc over a ramp of darker tones keeps its light end while
** the dark end is stretched. */
Test(image, levels_leave_a_flat_colour_at_either_end_as_it_is)
{
  const int n = 1000;
  lw_image *img = lw_image_new(n, 1, 1, NULL);
  for (int k = 0; k < n; k++) {
    img->tone[k] = k < 400 ? 0.33f : (k < 500 ? 0.26f : 1.0f);
    img->alpha[k] = k < 500 ? 1.0f : 0.0f; /* transparent paper */
  }
  double lo, hi;
  cr_assert_eq(lw_image_levels(img, NULL, 0.01, 1, &lo, &hi, NULL, NULL), LW_OK);
  cr_assert(lo == 0.0 && hi == 1.0, "levels %g to %g", lo, hi);
  cr_assert(img->tone[0] == 0.33f && img->tone[450] == 0.26f && img->tone[600] == 1.0f);
  for (int k = 0; k < n; k++) {
    img->tone[k] = k < 400 ? 0.33f : (float)(0.1 + 0.2 * (k - 400) / (n - 401));
    img->alpha[k] = 1.0f;
  }
  cr_assert_eq(lw_image_levels(img, NULL, 0.01, 1, &lo, &hi, NULL, NULL), LW_OK);
  cr_assert(hi == 1.0 && fabs(lo - 0.102) < 2e-3, "levels %g to %g", lo, hi);
  /* the lightest flat colour with a thin tail past the 1 % clip (a JPEG's
  ** ringing around a flat background, 1.2 % of the pixels up to 0.6): the
  ** end stays (it was stretched to the tail, and the background went
  ** white); scene.image_levels_flat = 0, a run begun before, as it was */
  for (int k = 0; k < n; k++) {
    img->tone[k] = k < 400 ? 0.5f : (k < 412 ? (float)(0.51 + 0.09 * (k - 400) / 11.0) : 0.1f + 0.0003f * (k - 412));
    img->alpha[k] = 1.0f;
  }
  lw_image *copy = lw_image_new(n, 1, 1, NULL);
  memcpy(copy->tone, img->tone, n * sizeof *img->tone);
  memcpy(copy->alpha, img->alpha, n * sizeof *img->alpha);
  cr_assert_eq(lw_image_levels(img, NULL, 0.01, 1, &lo, &hi, NULL, NULL), LW_OK);
  cr_assert(hi == 1.0, "levels %g to %g", lo, hi);
  cr_assert_eq(lw_image_levels(copy, NULL, 0.01, 0, &lo, &hi, NULL, NULL), LW_OK);
  cr_assert(hi > 0.5 && hi < 0.6, "levels %g to %g", lo, hi);
  lw_image_free(copy);
  lw_image_free(img);
}

/* Flat-field correction on a page lit unevenly: light L(x) rising from 0.4
** to 0.9 across 240 columns (slope s = 0.5 / 239 a pixel), white paper and
** bars 3 px wide of reflectance 0.3 every 60 px, radius r = 8 px.  Away from
** the bars the paper estimate is L(x + r) (the window's lightest mean; the
** blurs keep a linear ramp), so the paper comes out L(x) / L(x + r), at
** least 1 - r s / 0.4 = 0.958.  Near a bar the blurred tone dips, by at most
** 0.7 x 3 x phi(2) / 4 = 0.028 at the window's far end (r from the bar, the
** pre-blur's sigma r / 2): the estimate is low by that, and the paper stays
** within 1 - 0.042 - 0.028 = 0.93 of white and at most 1.  A bar keeps its
** ratio to the paper, 0.3, within 0.3 x 0.042 below and 0.3 x 0.028 / 0.972
** above: 0.015.  r = 8 px finds the paper on the picture boxed down by 2 (a
** linear ramp stays linear through the box means and the interpolation). */
Test(image, flatten_divides_out_uneven_light_and_keeps_a_marks_ratio)
{
  const int w = 240, h = 40, r = 8;
  lw_image *img = lw_image_new(w, h, 0, NULL);
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      const int bar = i % 60 >= 28 && i % 60 < 31;
      img->tone[j * w + i] = (float)((0.4 + 0.5 * i / (w - 1)) * (bar ? 0.3 : 1.0));
    }
  double lo, hi;
  cr_assert_eq(lw_image_flatten(img, r, &lo, &hi, NULL), LW_OK);
  cr_assert(lo >= 0.40 && lo <= 0.43 && hi >= 0.88 && hi <= 0.9001, "paper %g to %g", lo, hi);
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      const float t = img->tone[j * w + i];
      if (i % 60 == 29)
        cr_assert(fabsf(t - 0.3f) <= 0.015f, "bar at %d, %d: %g", i, j, t);
      else if (i % 60 < 28 || i % 60 >= 31)
        cr_assert(t >= 0.93f && t <= 1.0f, "paper at %d, %d: %g", i, j, t);
    }
  lw_image_free(img);
}

/* A dark area wider than twice the radius is paper to the correction from
** its inside: a square of 60 px, radius 5 px, turns white at its centre and
** keeps its tone one pixel in from its edge, where the window sees the
** white around it.  Black, its paper is under LW_IMAGE_FLATTEN_MIN_PAPER:
** white there too, not 0 / 0. */
Test(image, flatten_turns_a_wide_dark_area_light_from_inside)
{
  const float tones[2] = {0.2f, 0.0f};
  for (int k = 0; k < 2; k++) {
    lw_image *img = lw_image_new(100, 100, 0, NULL);
    for (int j = 20; j < 80; j++)
      for (int i = 20; i < 80; i++) img->tone[j * 100 + i] = tones[k];
    double lo, hi;
    cr_assert_eq(lw_image_flatten(img, 5, &lo, &hi, NULL), LW_OK);
    cr_assert(fabs(lo - tones[k]) < 1e-6 && fabs(hi - 1.0) < 1e-6, "paper %g to %g", lo, hi);
    cr_assert(img->tone[50 * 100 + 50] > 0.999f, "centre %g", img->tone[50 * 100 + 50]);
    cr_assert(img->tone[50 * 100 + 21] < tones[k] + 0.05f, "edge %g", img->tone[50 * 100 + 21]);
    cr_assert(img->tone[5 * 100 + 5] > 0.999f, "paper %g", img->tone[5 * 100 + 5]);
    lw_image_free(img);
  }
}

Test(image, fit_centres_and_keeps_the_aspect_ratio)
{
  lw_image_place pl = lw_image_fit(600, 800, 8, 8, 142, 192);
  cr_assert(fabs(pl.pixel - 134.0 / 600) < 1e-12);
  cr_assert(fabs(pl.x0 - 8) < 1e-12);
  cr_assert(fabs(pl.y0 - (8 + 0.5 * (184 - 800 * pl.pixel))) < 1e-12);
  /* tone lookups: white outside, pixel values at centres */
  lw_image *img = lw_image_new(2, 1, 0, NULL);
  img->tone[0] = 0.2f;
  img->tone[1] = 0.6f;
  lw_image_place q = {10, 20, 5};
  cr_assert(fabs(lw_image_tone_at(img, &q, 12.5, 22.5) - 0.2) < 1e-6);
  cr_assert(fabs(lw_image_tone_at(img, &q, 15, 22.5) - 0.4) < 1e-6);
  cr_assert(lw_image_tone_at(img, &q, 9.9, 22) == 1.0 && lw_image_tone_at(img, &q, 20.1, 22) == 1.0);
  cr_assert(lw_image_tone_at(img, &q, 15, 25.1) == 1.0);
  lw_image_free(img);
}

/* ---- EXIF orientation ------------------------------------------------------ */

#define STBI_WRITE_NO_STDIO
#include <stb/stb_image_write.h> /* compiled in tests/stb_write.c */

typedef struct {
  unsigned char b[8192];
  size_t n;
} jpeg_buf;

static void jpeg_put(void *ctx, void *data, int size)
{
  jpeg_buf *j = ctx;
  cr_assert(j->n + (size_t)size <= sizeof j->b);
  memcpy(j->b + j->n, data, (size_t)size);
  j->n += (size_t)size;
}

/* A 32 x 16 JPEG, light with a dark 8 x 8 block in its stored top-left
** corner, and an APP1 "Exif" segment with orientation o (0: none) in big-
** or little-endian TIFF order right after SOI; bad_ifd points IFD0 past
** the segment; fill > 0 puts that many fill bytes 0xFF before SOI and
** before the APP1 and the marker after it. */
static size_t exif_jpeg_filled(unsigned char *out, int o, int big_endian, int bad_ifd, int fill)
{
  unsigned char px[32 * 16];
  for (int y = 0; y < 16; y++)
    for (int x = 0; x < 32; x++) px[y * 32 + x] = x < 8 && y < 8 ? 20 : 230;
  jpeg_buf j = {.n = 0};
  cr_assert(stbi_write_jpg_to_func(jpeg_put, &j, 32, 16, 1, px, 100));
  unsigned char app[36] = {0xFF, 0xE1, 0, 34, 'E', 'x', 'i', 'f', 0, 0};
  unsigned char *t = app + 10;
  if (big_endian) {
    const unsigned char tiff[] = {'M', 'M', 0, 42, 0, 0, 0, 8, 0, 1, 0x01, 0x12, 0, 3, 0, 0, 0, 1, 0, (unsigned char)o, 0, 0};
    memcpy(t, tiff, sizeof tiff);
    if (bad_ifd) t[7] = 200;
  } else {
    const unsigned char tiff[] = {'I', 'I', 42, 0, 8, 0, 0, 0, 1, 0, 0x12, 0x01, 3, 0, 1, 0, 0, 0, (unsigned char)o, 0, 0, 0};
    memcpy(t, tiff, sizeof tiff);
    if (bad_ifd) t[4] = 200;
  }
  size_t n = (size_t)fill;
  memset(out, 0xFF, n);
  memcpy(out + n, j.b, 2);
  n += 2;
  if (o) {
    memset(out + n, 0xFF, (size_t)fill);
    memcpy(out + n + fill, app, sizeof app);
    n += (size_t)fill + sizeof app;
  }
  memset(out + n, 0xFF, (size_t)fill);
  n += (size_t)fill;
  memcpy(out + n, j.b + 2, j.n - 2);
  return n + j.n - 2;
}

static size_t exif_jpeg(unsigned char *out, int o, int big_endian, int bad_ifd)
{
  return exif_jpeg_filled(out, o, big_endian, bad_ifd, 0);
}

/* A JPEG cut short anywhere past its header is refused as a damaged JPEG,
** never with a reason about another format: the decoder keeps the reason
** of its last failure, and a PNG test before the JPEG decoder left "Not a
** PNG" (skimage's truncated.jpg) where the JPEG decoder set none.  A cut
** that decoded would be no error (a decoder may pad the scan), so the test
** asserts that cuts fail and that none is misreported. */
Test(image, a_jpeg_cut_short_is_reported_as_one)
{
  unsigned char jpg[8300];
  size_t n = exif_jpeg(jpg, 0, 0, 0);
  int failed = 0, unreasoned = 0;
  for (size_t cut = 200; cut < n; cut++) {
    lw_error err;
    lw_image *img = lw_image_decode(jpg, cut, "cut.jpg", 1e6, NULL, &err);
    if (img) {
      lw_image_free(img);
      continue;
    }
    failed++;
    cr_assert(strstr(err.msg, "cut.jpg: ") && strstr(err.msg, "JPEG") && !strstr(err.msg, "PNG") &&
                  !strstr(err.msg, "png"),
              "cut at %zu of %zu: %s", cut, n, err.msg);
    unreasoned += strchr(err.msg, '(') == NULL;
  }
  cr_assert_gt(failed, 0, "no cut of %zu bytes failed to decode", n);
  cr_log_info("%d of %zu cuts fail, %d without the decoder's reason", failed, n - 200, unreasoned);
}

/* Which corner of img holds the dark block: 0 top-left, 1 top-right,
** 2 bottom-right, 3 bottom-left; -1 unless exactly one 8 x 8 corner is dark. */
static int dark_corner(const lw_image *img)
{
  int found = -1, dark = 0;
  for (int c = 0; c < 4; c++) {
    int x0 = c == 1 || c == 2 ? img->width - 8 : 0, y0 = c >= 2 ? img->height - 8 : 0;
    double s = 0;
    for (int y = y0; y < y0 + 8; y++)
      for (int x = x0; x < x0 + 8; x++) s += img->tone[(size_t)y * (size_t)img->width + (size_t)x];
    if (s / 64 < 0.3) found = c, dark++;
  }
  return dark == 1 ? found : -1;
}

/* A camera stores its rows as the sensor reads them and says in EXIF how
** to turn them; each of the eight orientations is a distinct pair of
** (upright size, corner the stored top-left lands in), from the EXIF
** table: 2 mirror, 3 half turn, 4 flip, 5 mirror then a quarter turn
** anticlockwise (a transpose), 6 a quarter turn clockwise, 7 mirror then a
** quarter turn clockwise, 8 a quarter turn anticlockwise.  Ignoring the tag
** (the old decoder) fails every orientation but 1; a broken IFD offset
** means "as stored", not an error.  Fill bytes before the markers, which
** the decoder skips, hide no tag (a walk that wanted SOI at byte 0 and a
** marker right after each segment missed it).  lw_image_probe, which
** sizes the page of scene.orientation = auto, reports the upright size
** too. */
Test(image, jpeg_exif_orientation_is_turned_upright)
{
  static const int corner[9] = {0, 0, 1, 2, 3, 0, 1, 2, 3};
  unsigned char jpg[8400];
  lw_error err;
  for (int o = 0; o <= 8; o++)
    for (int be = 0; be < 4; be++) {
      size_t n = exif_jpeg_filled(jpg, o, be & 1, 0, be >> 1 ? 3 : 0);
      lw_image_info info;
      lw_image *img = lw_image_decode(jpg, n, "t.jpg", 1e6, &info, &err);
      cr_assert_not_null(img, "orientation %d: %s", o, err.msg);
      int turned = o >= 5;
      cr_assert(img->width == (turned ? 16 : 32) && img->height == (turned ? 32 : 16) &&
                    info.width == img->width && info.height == img->height,
                "orientation %d: %d x %d", o, img->width, img->height);
      cr_assert_eq(dark_corner(img), corner[o], "orientation %d (%s-endian%s): dark corner %d, expected %d", o,
                   be & 1 ? "big" : "little", be >> 1 ? ", fill bytes" : "", dark_corner(img), corner[o]);
      lw_image_free(img);
    }
  for (int be = 0; be < 2; be++) {
    size_t n = exif_jpeg(jpg, 6, be, 1);
    lw_image *img = lw_image_decode(jpg, n, "t.jpg", 1e6, NULL, &err);
    cr_assert_not_null(img, "%s", err.msg);
    cr_assert(img->width == 32 && dark_corner(img) == 0);
    lw_image_free(img);
  }
  const char *path = lw_test_path("side.jpg");
  FILE *f = fopen(path, "wb");
  cr_assert_not_null(f);
  size_t n = exif_jpeg(jpg, 6, 1, 0);
  cr_assert_eq(fwrite(jpg, 1, n, f), n);
  fclose(f);
  lw_image_info info;
  cr_assert_eq(lw_image_probe(path, &info, &err), LW_OK, "%s", err.msg);
  cr_assert(info.width == 16 && info.height == 32, "probe: %d x %d", info.width, info.height);
}

/* Writes the CRC of the PNG chunk at c (its length, type and data). */
static void png_crc_set(unsigned char *c)
{
  const size_t len = (size_t)c[0] << 24 | (size_t)c[1] << 16 | (size_t)c[2] << 8 | c[3];
  const unsigned long crc = crc32(crc32(0L, Z_NULL, 0), c + 4, (uInt)len + 4);
  for (int k = 0; k < 4; k++) c[8 + len + (size_t)k] = (unsigned char)(crc >> (24 - 8 * k));
}

/* The 32 x 16 picture of exif_jpeg as a PNG, with an eXIf chunk of
** orientation o (0: none) after its header, or with `late` 1 after its
** image data; `late` 2: after its header, the TIFF block behind JPEG's
** "Exif\0\0" as some writers keep it. */
static size_t exif_png(unsigned char *out, int o, int late)
{
  unsigned char px[32 * 16];
  for (int y = 0; y < 16; y++)
    for (int x = 0; x < 32; x++) px[y * 32 + x] = x < 8 && y < 8 ? 20 : 230;
  jpeg_buf j = {.n = 0};
  cr_assert(stbi_write_png_to_func(jpeg_put, &j, 32, 16, 1, px, 32));
  static const unsigned char chunk[34] = {0, 0, 0, 22, 'e', 'X', 'I', 'f', 'M', 'M', 0, 42, 0, 0, 0, 8, 0, 1,
                                          0x01, 0x12, 0, 3, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0};
  size_t head = late == 1 ? j.n - 12 : 8 + 25, n = 0; /* before IEND, or after the signature and IHDR */
  memcpy(out, j.b, head);
  n = head;
  if (o && late == 2) {
    memcpy(out + n, chunk, 8);
    out[n + 3] = 28;
    memcpy(out + n + 8, "Exif\0\0", 6);
    memcpy(out + n + 14, chunk + 8, sizeof chunk - 8);
    out[n + 33] = (unsigned char)o;
    png_crc_set(out + n);
    n += sizeof chunk + 6;
  } else if (o) {
    memcpy(out + n, chunk, sizeof chunk);
    out[n + 27] = (unsigned char)o;
    png_crc_set(out + n);
    n += sizeof chunk;
  }
  memcpy(out + n, j.b + head, j.n - head);
  return n + j.n - head;
}

/* A PNG's eXIf chunk turns it as a JPEG's EXIF does (a phone's portrait
** PNG was drawn on its side), found after the image data too (before IEND,
** where older writers put it); the probe of orientation = auto agrees. */
Test(image, png_exif_orientation_is_turned_upright)
{
  static const int corner[9] = {0, 0, 1, 2, 3, 0, 1, 2, 3};
  unsigned char png[8400];
  lw_error err;
  for (int o = 0; o <= 26; o++) {
    size_t n = exif_png(png, o % 9, o / 9);
    lw_image_info info;
    lw_image *img = lw_image_decode(png, n, "t.png", 1e6, &info, &err);
    cr_assert_not_null(img, "orientation %d: %s", o, err.msg);
    cr_assert(img->width == (o % 9 >= 5 ? 16 : 32) && dark_corner(img) == corner[o % 9],
              "orientation %d%s: %d x %d, corner %d", o % 9,
              o > 17 ? " (Exif prefix)" : o > 8 ? " (after the data)" : "", img->width, img->height, dark_corner(img));
    lw_image_free(img);
  }
  const char *path = lw_test_path("side.png");
  FILE *f = fopen(path, "wb");
  cr_assert_not_null(f);
  size_t n = exif_png(png, 8, 0);
  cr_assert_eq(fwrite(png, 1, n, f), n);
  fclose(f);
  lw_image_info info;
  cr_assert_eq(lw_image_probe(path, &info, &err), LW_OK, "%s", err.msg);
  cr_assert(info.width == 16 && info.height == 32, "probe: %d x %d", info.width, info.height);
}

/* Writes into a growing buffer (a picture past jpeg_buf's 8 KB). */
typedef struct {
  unsigned char *b;
  size_t n;
} grow_buf;

static void grow_put(void *ctx, void *data, int size)
{
  grow_buf *g = ctx;
  unsigned char *b = realloc(g->b, g->n + (size_t)size);
  cr_assert_not_null(b);
  memcpy(b + g->n, data, (size_t)size);
  g->b = b, g->n += (size_t)size;
}

/* The decoder checks no PNG CRC, and a bit flipped in the compressed
** pixels mostly decoded to other pixels: each drawn chunk's CRC is checked, a bit
** flipped in every seventh byte of the header and data is caught (each byte
** in a different bit), and a file without its IEND
** is cut short; a PNG of width 0 is damaged. */
Test(image, a_png_with_a_flipped_bit_or_no_end_is_refused)
{
  unsigned char px[64 * 64];
  for (int k = 0; k < 64 * 64; k++) px[k] = (unsigned char)(k * 37 % 251);
  grow_buf g = {NULL, 0};
  cr_assert(stbi_write_png_to_func(grow_put, &g, 64, 64, 1, px, 64));
  lw_error err;
  lw_image *img = lw_image_decode(g.b, g.n, "ok.png", 1e6, NULL, &err);
  cr_assert_not_null(img, "%s", err.msg);
  lw_image_free(img);
  const size_t idat = 8 + 25; /* signature, IHDR; stb writes one IDAT */
  cr_assert(!memcmp(g.b + idat + 4, "IDAT", 4));
  for (size_t at = 8; at < g.n - 12; at += 7) {
    const unsigned char bit = (unsigned char)(1u << (at % 8));
    g.b[at] ^= bit;
    img = lw_image_decode(g.b, g.n, "f.png", 1e6, NULL, &err);
    g.b[at] ^= bit;
    cr_assert_null(img, "a bit flipped at byte %zu of %zu decoded", at, g.n);
    cr_assert(strstr(err.msg, "f.png: the PNG is damaged"), "byte %zu: %s", at, err.msg);
  }
  g.b[idat + 20] ^= 4;
  cr_assert_null(lw_image_decode(g.b, g.n, "f.png", 1e6, NULL, &err));
  cr_assert(strstr(err.msg, "f.png: the PNG is damaged: its chunk 'IDAT' at byte 33 fails its CRC check"), "%s",
            err.msg);
  g.b[idat + 20] ^= 4;
  cr_assert_null(lw_image_decode(g.b, g.n - 12, "cut.png", 1e6, NULL, &err));
  cr_assert(strstr(err.msg, "cut.png: the PNG is damaged or cut short: it ends at byte"), "%s", err.msg);
  cr_assert(strstr(err.msg, "without its IEND chunk"), "%s", err.msg);
  /* a damaged text chunk, which nothing reads, passes (a run begun on such
  ** a picture resumes); a damaged tRNS, which changes what is drawn, not */
  unsigned char *t = malloc(g.n + 32);
  cr_assert_not_null(t);
  static const unsigned char text[] = {0, 0, 0, 5, 't', 'E', 'X', 't', 'a', 0, 'b', 'c', 'd', 0, 0, 0, 0};
  memcpy(t, g.b, idat);
  memcpy(t + idat, text, sizeof text);
  memcpy(t + idat + sizeof text, g.b + idat, g.n - idat);
  img = lw_image_decode(t, g.n + sizeof text, "text.png", 1e6, NULL, &err);
  cr_assert_not_null(img, "%s", err.msg);
  lw_image_free(img);
  memcpy(t + idat + 4, "tRNS", 4);
  cr_assert_null(lw_image_decode(t, g.n + sizeof text, "trns.png", 1e6, NULL, &err));
  cr_assert(strstr(err.msg, "trns.png: the PNG is damaged: its chunk 'tRNS' at byte 33 fails its CRC check"), "%s",
            err.msg);
  /* a flipped bit in the type that made it look ancillary ("tRnS", "pLTE")
  ** hid it: the harmless are known by name */
  memcpy(t + idat + 4, "tRnS", 4);
  cr_assert_null(lw_image_decode(t, g.n + sizeof text, "trns.png", 1e6, NULL, &err));
  cr_assert(strstr(err.msg, "its chunk 'tRnS' at byte 33 fails its CRC check"), "%s", err.msg);
  free(t);
  unsigned char ihdr[8];
  memcpy(ihdr, g.b + 16, 8);
  memset(g.b + 16, 0, 4);
  png_crc_set(g.b + 8);
  cr_assert_null(lw_image_decode(g.b, g.n, "w0.png", 1e6, NULL, &err));
  cr_assert(strstr(err.msg, "w0.png: the PNG is damaged: 0 x 64 pixels"), "%s", err.msg);
  memcpy(g.b + 16, ihdr, 8);
  memset(g.b + 20, 0, 4);
  png_crc_set(g.b + 8);
  cr_assert_null(lw_image_decode(g.b, g.n, "h0.png", 1e6, NULL, &err));
  cr_assert(strstr(err.msg, "h0.png: the PNG is damaged: 64 x 0 pixels"), "%s", err.msg);
  free(g.b);
}

/* A run-length BMP (ImageMagick writes grey BMPs so) and a JPEG whose
** frame has a side of 0 were "not of any known type, or corrupt": each is
** named, with the way round. */
Test(image, an_rle_bmp_and_a_jpeg_of_side_0_are_named)
{
  unsigned char bmp[128] = {'B', 'M'};
  bmp[10] = 54, bmp[14] = 40, bmp[18] = 4, bmp[22] = 4, bmp[26] = 1, bmp[28] = 8, bmp[30] = 1; /* BI_RLE8 */
  lw_error err;
  cr_assert_null(lw_image_decode(bmp, sizeof bmp, "r.bmp", 1e6, NULL, &err));
  cr_assert(strstr(err.msg, "r.bmp: a run-length (RLE8) BMP, which the decoder does not read: save it uncompressed "
                            "or as PNG"), "%s", err.msg);
  bmp[28] = 4, bmp[30] = 2; /* BI_RLE4 */
  cr_assert_null(lw_image_decode(bmp, sizeof bmp, "r.bmp", 1e6, NULL, &err));
  cr_assert(strstr(err.msg, "r.bmp: a run-length (RLE4) BMP"), "%s", err.msg);
  unsigned char jpg[8400];
  size_t n = exif_jpeg(jpg, 0, 0, 0), at = 2;
  while (at + 9 < n && !(jpg[at] == 0xFF && jpg[at + 1] == 0xC0)) at += 2 + ((size_t)jpg[at + 2] << 8 | jpg[at + 3]);
  cr_assert(at + 9 < n, "no SOF0");
  jpg[at + 5] = jpg[at + 6] = 0; /* no rows */
  cr_assert_null(lw_image_decode(jpg, n, "h0.jpg", 1e6, NULL, &err));
  cr_assert(strstr(err.msg, "h0.jpg: the JPEG's frame says 32 x 0 pixels: damaged, or rows told after the data"),
            "%s", err.msg);
}

/* A JPEG's header claiming 30000 x 30000 grey pixels on 3.7 KB of data
** took 35 s and 1.8 GB, the missing data read as zeros (a black page):
** every block is coded in at least a bit, so fewer bytes than blocks / 8
** is cut short.  A uniform grey JPEG at the lowest quality decodes (a DC
** and an end-of-block code a block: 6 bits with the standard tables stb
** writes; PIL's optimised tables took 2, twice the bound). */
Test(image, a_jpeg_header_larger_than_its_data_is_refused)
{
  const int side = 1024;
  unsigned char *px = malloc((size_t)side * side);
  cr_assert_not_null(px);
  memset(px, 128, (size_t)side * side);
  grow_buf g = {NULL, 0};
  cr_assert(stbi_write_jpg_to_func(grow_put, &g, side, side, 1, px, 1));
  free(px);
  lw_error err;
  lw_image *img = lw_image_decode(g.b, g.n, "grey.jpg", 1e7, NULL, &err);
  cr_assert_not_null(img, "%s", err.msg);
  lw_image_free(img);
  size_t at = 2;
  while (at + 9 < g.n && !(g.b[at] == 0xFF && g.b[at + 1] == 0xC0)) at += 2 + ((size_t)g.b[at + 2] << 8 | g.b[at + 3]);
  cr_assert(at + 9 < g.n, "no SOF0");
  /* 12000 rows: stb writes Y sampled 2 x 2 and Cb, Cr at half, so 1 + 1/4 + 1/4 of 128 x 1500 blocks */
  g.b[at + 5] = 12000 >> 8, g.b[at + 6] = 12000 & 255;
  cr_assert_null(lw_image_decode(g.b, g.n, "tall.jpg", 1e7, NULL, &err));
  cr_assert(strstr(err.msg, "tall.jpg: the JPEG is damaged or cut short: its 1024 x 12000 pixels take at least "
                   "36000 bytes of coded data, the file has "), "%s", err.msg);
  /* the bound is on the bytes from the first scan: a 60 KB colour profile
  ** (APP2) before it does not count (it hid a cut scan) */
  const size_t app = 60000;
  unsigned char *big = malloc(g.n + app);
  cr_assert_not_null(big);
  memcpy(big, g.b, 2);
  big[2] = 0xFF, big[3] = 0xE2, big[4] = (unsigned char)((app - 2) >> 8), big[5] = (unsigned char)((app - 2) & 255);
  memset(big + 6, 'p', app - 4);
  memcpy(big + 2 + app, g.b + 2, g.n - 2);
  cr_assert_null(lw_image_decode(big, g.n + app, "icc.jpg", 1e7, NULL, &err));
  cr_assert(strstr(err.msg, "icc.jpg: the JPEG is damaged or cut short: its 1024 x 12000 pixels take at least "
                   "36000 bytes of coded data, the file has "), "%s", err.msg);
  free(big);
  free(g.b);
}

/* Formats linewise does not read are named, with the way round: an
** iPhone's HEIC, a WebP, a TIFF were "not of any known type, or corrupt".
** A JPEG past the decoder's INT_MAX bytes of pixels (its header says 30000
** x 30000 RGB) is refused as too large before decoding, as a PNG past 2^30
** is: it was "damaged or cut short". */
Test(image, foreign_formats_are_named_and_a_huge_jpeg_is_too_large)
{
  static const struct { const char *head; size_t n; const char *name; } f[] = {
    {"\0\0\0\x18" "ftypheic\0\0\0\0mif1heic", 24, "a HEIC file"},
    {"RIFF\x10\0\0\0WEBPVP8 ", 16, "a WebP file"},
    {"II*\0\x08\0\0\0\0\0\0\0", 12, "a TIFF file"},
    {"\0\0\0\x1c" "ftypavif\0\0\0\0avifmif1", 24, "an AVIF file"},
    /* an AVIF whose major brand is mif1 names avif among the compatible ones */
    {"\0\0\0\x18" "ftypmif1\0\0\0\0mif1avif", 24, "an AVIF file"},
    {"\0\0\0\x0cJXL \r\n\x87\n", 12, "a JPEG XL file"},
    {"II+\0\x08\0\0\0", 8, "a TIFF file"},
    {"\xef\xbb\xbf\n  <svg xmlns=", 16, "an SVG file"},
    /* the Netpbm kinds but the binary PGM and PPM read (a generic "not of
    ** any known type, or corrupt" before) */
    {"P2\n2 1\n255\n0 9\n", 15, "a plain-text PGM (P2) file"},
    {"P3 1 1 255 0 0 0\n", 17, "a plain-text PPM (P3) file"},
    {"P1\n1 1\n0\n", 10, "a plain-text PBM (P1) file"},
    {"P4\n8 1\n\xff", 8, "a PBM (P4) file"},
    {"P7\nWIDTH 1\n", 11, "a PAM (P7) file"},
  };
  lw_error err;
  for (size_t i = 0; i < sizeof f / sizeof f[0]; i++) {
    unsigned char buf[64] = {0};
    memcpy(buf, f[i].head, f[i].n);
    cr_assert_null(lw_image_decode(buf, sizeof buf, "x", 1e6, NULL, &err));
    cr_assert(strstr(err.msg, f[i].name) && strstr(err.msg, "convert it to PNG or JPEG first"), "%s", err.msg);
  }
  unsigned char jpg[8400];
  size_t n = exif_jpeg(jpg, 0, 0, 0);
  size_t at = 2;
  while (at + 4 < n && !(jpg[at] == 0xFF && jpg[at + 1] == 0xC0)) at += 2 + ((size_t)jpg[at + 2] << 8 | jpg[at + 3]);
  cr_assert(at + 9 < n, "no SOF0");
  jpg[at + 5] = 30000 >> 8, jpg[at + 6] = 30000 & 255, jpg[at + 7] = 30000 >> 8, jpg[at + 8] = 30000 & 255;
  jpg[at + 9] = 3; /* 3 components: RGB */
  cr_assert_null(lw_image_decode(jpg, n, "big.jpg", 1e6, NULL, &err));
  cr_assert(strstr(err.msg, "big.jpg: the JPEG is too large to decode: its width x height x channels is more than "
                   "2^31"), "%s", err.msg);
  /* a CMYK JPEG of 24000 x 24000: 4 components, which stbi_info counts as 3
  ** (1.7e9 bytes, under the limit) and the decoder as 4 (2.3e9: "damaged") */
  unsigned char cmyk[128] = {0xFF, 0xD8, 0xFF, 0xEE, 0, 14, 'A', 'd', 'o', 'b', 'e', 0, 100, 0, 0, 0, 0, 0,
                             0xFF, 0xDB, 0, 67, 0};
  size_t m = 18 + 69;
  memset(cmyk + 23, 1, 64);
  const unsigned char sof[] = {0xFF, 0xC0, 0, 20, 8, 24000 >> 8, 24000 & 255, 24000 >> 8, 24000 & 255, 4,
                               1, 0x11, 0, 2, 0x11, 0, 3, 0x11, 0, 4, 0x11, 0};
  memcpy(cmyk + m, sof, sizeof sof);
  m += sizeof sof;
  cmyk[m++] = 0xFF, cmyk[m++] = 0xD9;
  cr_assert_null(lw_image_decode(cmyk, m, "cmyk.jpg", 1e6, NULL, &err));
  cr_assert(strstr(err.msg, "cmyk.jpg: the JPEG is too large to decode: its width x height x channels is more than "
                   "2^31"), "%s", err.msg);
}
