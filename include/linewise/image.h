/*
** image.h -- a picture as a plane of tone: loading (stb_image), resampling,
** Gaussian blur, the tone curve, and where the picture sits on the page.
**
** Tone is a float per pixel in [0, 1]: 0 black .. 1 white, row 0 at the top
** (the page's y points down, so nothing is flipped).  Colour becomes tone by
** the Rec. 709 luma weights applied to the stored (gamma-encoded) values,
**     tone = 0.2126 R + 0.7152 G + 0.0722 B,
** which is how bright the picture looks, not how much light it emits: ink
** density should follow the look.  A picture with an alpha channel keeps it
** in its own plane; its tone is composited over white paper first
** (tone = a t + 1 - a), so a transparent pixel asks for no ink.
**
** Memory: loading holds the whole file, then stb_image's decoded buffer of
** width * height * channels bytes (twice that for 16-bit PNG) -- the peak --
** and builds the float planes from it row by row, already downsampled to the
** pixel budget, so no full-size float plane of a huge picture ever exists.
** Pictures above LW_IMAGE_MAX_PIXELS are refused before decoding.
*/
#ifndef LINEWISE_IMAGE_H
#define LINEWISE_IMAGE_H

#include <stddef.h>

#include "linewise/error.h"
#include "linewise/field.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifndef LW_IMAGE_MAX_PIXELS /* the fuzz build lowers it to its memory limit */
#define LW_IMAGE_MAX_PIXELS 1e9 /* refused before decoding */
#endif
#define LW_IMAGE_MAX_FILE_BYTES (1L << 30) /* 1 GiB: refused before reading */

typedef struct {
  int width, height;  /* pixels, >= 1 */
  float *tone;        /* width * height, row-major: 0 black .. 1 white */
  float *alpha;       /* same layout, 0 transparent .. 1 opaque; NULL if none */
} lw_image;

/* What the file held before any downsampling. */
typedef struct {
  int width, height;  /* pixels */
  int channels;       /* 1 gray, 2 gray+alpha, 3 RGB, 4 RGBA */
  int bits;           /* 8 or 16 per channel */
} lw_image_info;

/* A w x h image with the tone plane white (1) and, if with_alpha, an alpha
** plane that is opaque (1).  NULL and err set on failure. */
lw_image *lw_image_new(int w, int h, int with_alpha, lw_error *err);
void lw_image_free(lw_image *img);

/* The picture format of a file beginning with the n bytes d, with its
** article ("a JPEG", "a HEIC"), or NULL; *readable (may be NULL) 1 where
** linewise decodes it.  A picture given where a scene file goes is said to
** be one. */
const char *lw_image_kind(const unsigned char *d, size_t n, int *readable);

/* Decodes a PNG, JPEG, GIF (its first picture), BMP or PGM/PPM file held
** in memory; `name` only labels messages.  If the picture has more than
** max_pixels pixels it is box-filtered down (same aspect ratio; a strip
** thinner than the reduction keeps one pixel across) to at most max_pixels
** while it is converted.  info (may be NULL) receives what the file held.  LW_EINPUT for
** anything that is not a decodable picture, naming `name` and the decoder's
** reason. */
lw_image *lw_image_decode(const unsigned char *data, size_t size, const char *name,
                          double max_pixels, lw_image_info *info, lw_error *err);

/* What becomes the tone plane: the luma above, or one colour channel as
** stored (a gray picture gives its gray for each), for colour separation
** (layers.h).  Everything else -- alpha, downsampling -- is the same.
** LW_IMAGE_MASK is a mask's inside: 0 where the luma composited over white is
** below 1/2, else 1, before downsampling, so that a pixel of a downsampled
** mask is 0 only where all it covers is inside (a thin gap outside, a river
** one source pixel wide, averaged away under 1/2 and lines crossed it). */
typedef enum { LW_IMAGE_LUMA, LW_IMAGE_RED, LW_IMAGE_GREEN, LW_IMAGE_BLUE, LW_IMAGE_MASK } lw_image_channel;
lw_image *lw_image_decode_channel(const unsigned char *data, size_t size, const char *name, double max_pixels,
                                  lw_image_channel which, lw_image_info *info, lw_error *err);

/* Reads path whole, then lw_image_decode.  An empty, unreadable or missing
** file is LW_EINPUT with a message naming path. */
lw_image *lw_image_load(const char *path, double max_pixels, lw_image_info *info,
                        lw_error *err);
lw_image *lw_image_load_channel(const char *path, double max_pixels, lw_image_channel which, lw_image_info *info,
                                lw_error *err);

/* What the file at path holds (its header only: nothing is decoded), for
** choices made before the scene is built (scene.orientation = auto). */
lw_status lw_image_probe(const char *path, lw_image_info *info, lw_error *err);

/* A new w x h image resampled from src, each axis on its own: shrinking
** averages the source area each new pixel covers (a box filter with
** fractional edges: the mean tone is kept exactly), enlarging interpolates
** linearly between pixel centres. */
lw_image *lw_image_resize(const lw_image *src, int w, int h, lw_error *err);

/* Gaussian blur of the tone plane with standard deviation sigma pixels
** (<= 0: nothing), separable, the kernel cut at 4 sigma and normalised.  The
** picture is mirrored at its edges (half-sample symmetric), which makes the
** blur conserve the mean tone exactly (to 1e-6 from sigma 16 on, where it is
** summed at every sigma/8-th pixel and interpolated: image.c). */
lw_status lw_image_blur(lw_image *img, double sigma, lw_error *err);

/* The same blur on any w x h float plane (the field code smooths its
** structure tensor with it). */
lw_status lw_image_blur_plane(float *plane, int w, int h, double sigma, lw_error *err);

/* The four Catmull-Rom weights, for the samples at -1, 0, 1 and 2 steps,
** of the point u of a step (0 <= u < 1) past sample 0: how the wide blurs
** (here and in fidelity.c) fill in between the pixels they sum at. */
void lw_image_cubic_weights(double u, double w[4]);

/* Flat-field correction: divides the tone by the paper's brightness about
** each pixel, so that uneven light (a photographed page, a vignette, a
** shadow across a sketch) turns to white paper and only what is darker than
** its surroundings keeps its tone, as its ratio to them.  The paper is the
** lightest tone within `radius` pixels (a square window, the picture's
** edges repeated) of the tone blurred by radius / 2, itself blurred by
** radius / 2: the lightest local mean, not the lightest grain.  From 8
** pixels a radius on it is found on the picture boxed down to 4 pixels a
** radius and interpolated back: the same cost at any radius.
** Marks narrower than twice the radius are removed from that estimate and
** keep their contrast; a dark area wider than that turns light from its
** inside.  Where the paper is under LW_IMAGE_FLATTEN_MIN_PAPER (a black
** area wider than the window) there is no contrast to keep: white.  A
** radius under one pixel counts as one.  *lo and *hi receive the darkest
** and lightest paper tone found.  LW_ENOMEM with err set. */
#define LW_IMAGE_FLATTEN_MIN_PAPER (1.0 / 256.0)
lw_status lw_image_flatten(lw_image *img, double radius, double *lo, double *hi, lw_error *err);

/* Auto levels: stretches the tone linearly so that the darkest share `clip`
** of the picture's pixels turn black and the lightest share `clip` white,
** clipped to [0, 1].  Pixels less than half opaque (img->alpha) are not
** counted.  With a transparency `under` (the picture's alpha, blurred as its
** tone was; NULL: the tone as it is, composited over white) the levels and
** the stretch are of the picture under it, not of the white paper it lets
** through (the tone is a t + 1 - a, and stays so).  The
** stretch is at most 1 / LW_IMAGE_LEVELS_MIN_SPAN: a flatter picture is
** widened about its middle tone, so that sensor noise on a blank page is
** not blown up into structure.  An end whose level falls on a flat area,
** one tone (a bin of the histogram) held by more than
** LW_IMAGE_LEVELS_PLATEAU of the pixels, is not stretched: a graphic's
** flat colours would turn white or black whole (a logo's red disc, its
** lightest colour, vanished), where a photograph's ends are tails of a few
** pixels a tone; with `flat` >= 1, also where such a tone has no more than
** LW_IMAGE_LEVELS_PLATEAU of the pixels beyond it (anti-aliasing or a JPEG's
** ringing past a flat colour); with `flat` 2, a flat end left alone beside
** the other end's stretch that would crowd the picture's tones into less
** than LW_IMAGE_LEVELS_CROWDED of the range is stretched as any
** (a low-contrast elevation model's flat sea, its darkest, went white with
** all the rest).  scene.image_levels_flat: 0 for runs begun before it, 1
** before 2026-12-07.  *lo and *hi receive the tones that became 0 and 1,
** *kept (NULL: not asked) 1 and 2 for the dark and light end left alone as
** flat colours.
** LW_ENOMEM with err set. */
#define LW_IMAGE_LEVELS_MIN_SPAN 0.05
#define LW_IMAGE_LEVELS_PLATEAU 0.05
#define LW_IMAGE_LEVELS_CROWDED 0.1
/* A *lo from this tone up is a light picture's darkest (a pale sky's 0.45,
** a white board's 0.68; a dim photograph's, the moon's, 0.23), which the
** stretch turns black: the run's note says so, and how to keep it light. */
#define LW_IMAGE_LEVELS_LIGHT 0.35
/* ... and its lightest, from this tone up, near paper: a hazy photograph's
** tones lie mid-range (0.50 to 0.71), and the stretch that makes its
** darkest black is what draws it (kept light, it drew one even mat) */
#define LW_IMAGE_LEVELS_PAPER 0.85
lw_status lw_image_levels(lw_image *img, const float *under, double clip, int flat, double *lo, double *hi,
                          int *kept, lw_error *err);

/* The tone curve, in this order:
**     t <- 1 - t                         if invert
**     t <- t^gamma                       (gamma > 1 darkens the mid-tones)
**     t <- clamp(1/2 + contrast (t - 1/2), 0, 1)
** applied to the picture under a pixel's transparency alpha (NULL: opaque),
** not to the white paper it lets through: transparent stays white, inverted
** too.  alpha is the picture's, blurred as its tone was. */
void lw_image_tone_curve(lw_image *img, const float *alpha, double gamma, double contrast, int invert);

/* Where the picture lies on the page: pixel (i, j) covers the square of side
** `pixel` mm whose top-left corner is (x0 + i pixel, y0 + j pixel). */
typedef struct {
  double x0, y0;  /* top-left corner of the picture, mm */
  double pixel;   /* side of a pixel, mm */
} lw_image_place;

/* The largest placement of a w x h picture inside the box [bx0, bx1] x
** [by0, by1] that keeps its aspect ratio, centred in the box. */
lw_image_place lw_image_fit(int w, int h, double bx0, double by0, double bx1, double by1);

/* Tone at a page point by bilinear interpolation between pixel centres; 1
** (white paper) outside the picture. */
double lw_image_tone_at(const lw_image *img, const lw_image_place *pl, double x, double y);

/* The tone as a raster on the page (fidelity.h): one node per pixel centre,
** spacing pl->pixel.  NULL and err set when out of memory. */
lw_grid2d *lw_image_tone_grid(const lw_image *img, const lw_image_place *pl, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
