/* imageutil.h -- pictures for the image tests: PNG files and a scratch
** directory per test (lw_test_dir, made by lw_image_dir_make in a suite's
** .init and removed by lw_image_dir_remove in its .fini). */
#ifndef LINEWISE_IMAGEUTIL_H
#define LINEWISE_IMAGEUTIL_H

#include <cairo.h>
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "testutil.h"

static char lw_test_dir[64];

static inline void lw_image_dir_make(void) { cr_assert_eq(lw_test_dir_make(lw_test_dir, "image"), 0); }
static inline void lw_image_dir_remove(void) { cr_assert_eq(lw_test_dir_remove(lw_test_dir), 0); }

/* lw_test_dir/name; the last four results stay valid. */
static inline const char *lw_test_path(const char *name)
{
  static char path[4][256];
  static int k;
  k = (k + 1) % 4;
  snprintf(path[k], sizeof path[k], "%s/%s", lw_test_dir, name);
  return path[k];
}

/* A w x h PNG of gray levels g[j * w + i] in [0, 1]; with a non-NULL alpha
** plane an RGBA file (cairo stores straight alpha in PNG), else RGB. */
static inline void lw_test_png(const char *path, int w, int h, const float *g, const float *alpha)
{
  cairo_surface_t *s = cairo_image_surface_create(alpha ? CAIRO_FORMAT_ARGB32 : CAIRO_FORMAT_RGB24, w, h);
  cr_assert_eq(cairo_surface_status(s), CAIRO_STATUS_SUCCESS);
  cairo_surface_flush(s);
  unsigned char *data = cairo_image_surface_get_data(s);
  int stride = cairo_image_surface_get_stride(s);
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      double a = alpha ? alpha[j * w + i] : 1.0;
      /* cairo keeps colour premultiplied by alpha */
      uint32_t A = (uint32_t)lround(255 * a), G = (uint32_t)lround(255 * a * g[j * w + i]);
      ((uint32_t *)(data + (size_t)j * stride))[i] = A << 24 | G << 16 | G << 8 | G;
    }
  cairo_surface_mark_dirty(s);
  cr_assert_eq(cairo_surface_write_to_png(s, path), CAIRO_STATUS_SUCCESS, "%s", path);
  cairo_surface_destroy(s);
}

static inline void lw_test_write(const char *path, const void *bytes, size_t n)
{
  FILE *f = fopen(path, "wb");
  cr_assert_not_null(f, "%s", path);
  cr_assert_eq(fwrite(bytes, 1, n, f), n);
  fclose(f);
}

#endif
