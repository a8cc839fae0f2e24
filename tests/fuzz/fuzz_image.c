/*
** fuzz_image.c -- fuzz harness for the picture decoder (lw_image_decode):
** linewise's own readers (PGM/PPM, the checks that a BMP or GIF holds its
** whole raster, the EXIF orientation walk) and stb_image behind them.
**
** Properties beyond "no crash, no leak, no undefined behaviour":
**   - a refused input gets LW_EINPUT and a message that names it;
**   - an accepted picture has a size of at least 1 x 1 and at most the
**     pixels asked for, what the file held (info) at least as many pixels,
**     tones in [0, 1] and alpha, if any, in [0, 1];
**   - decoding to at most 64 pixels accepts what the full decode accepts
**     (the box filter runs on every accepted picture).
**
** stb_image allocates the whole raster before it reads the data, so the
** fuzz build refuses pictures above 2^22 pixels (LW_IMAGE_MAX_PIXELS, set
** in the Makefile): the fuzzer's memory limit would report a large
** declared size as a crash.
**
** Built with clang -fsanitize=fuzzer by `make fuzz`; `make test` compiles it
** with cc and replays tests/fuzz/corpus/image through the same function.
*/
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_util.h"
#include "linewise/image.h"

#define NAME "fuzz.img"

/* A decoded picture's properties; 1 if it was accepted. */
static int check(const lw_image *img, const lw_image_info *info, const lw_error *err, double max_pixels)
{
  if (!img) {
    LW_FUZZ_CHECK(err->code == LW_EINPUT, "refused with code %d: %s", (int)err->code, err->msg);
    LW_FUZZ_CHECK(strstr(err->msg, NAME) != NULL, "message without the name: '%s'", err->msg);
    return 0;
  }
  const double px = (double)img->width * (double)img->height;
  LW_FUZZ_CHECK(img->width >= 1 && img->height >= 1 && px <= max_pixels, "%d x %d for at most %g pixels",
                img->width, img->height, max_pixels);
  LW_FUZZ_CHECK((double)info->width * (double)info->height >= px, "held %d x %d, decoded %d x %d", info->width,
                info->height, img->width, img->height);
  LW_FUZZ_CHECK(info->channels >= 1 && info->channels <= 4 && (info->bits == 8 || info->bits == 16),
                "%d channels of %d bits", info->channels, info->bits);
  for (size_t k = 0; k < (size_t)px; k++) {
    LW_FUZZ_CHECK(img->tone[k] >= 0.0f && img->tone[k] <= 1.0f, "tone %g at %zu", (double)img->tone[k], k);
    LW_FUZZ_CHECK(!img->alpha || (img->alpha[k] >= 0.0f && img->alpha[k] <= 1.0f), "alpha %g at %zu",
                  (double)img->alpha[k], k);
  }
  return 1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  lw_error err = {LW_OK, ""};
  lw_image_info info;
  lw_image *img = lw_image_decode(data, size, NAME, 1e6, &info, &err);
  const int full = check(img, &info, &err, 1e6);
  lw_image_free(img);
  img = lw_image_decode(data, size, NAME, 64, &info, &err);
  const int small = check(img, &info, &err, 64);
  lw_image_free(img);
  LW_FUZZ_CHECK(full == small, "decoded at 1e6 pixels: %s, at 64: %s", full ? "yes" : "no", small ? "yes" : "no");
  return 0;
}
