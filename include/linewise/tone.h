/*
** tone.h -- the tone term's raster: the lines splatted into a blurred ink
** raster, compared with the picture's darkness (in the spirit of Turk and
** Banks 1996).  The raster's pixels are blocks of k x k picture pixels, k
** the most that keeps them within sigma / LW_TONE_SIGMA_PIXELS (1 where the
** picture is coarser): sampled that finely a footprint keeps its centre
** within 2e-4 sigma (docs/NUMERICS.md), and it is at most 19 x 19 pixels
** whatever the picture's resolution.
**
**   E_tone = T * sum over pixels p of A (B_p - D_p)^2,
**   B = G * ink,   ink = pen width times the lines' length per area,
**
** A = pixel^2 (mm^2, the raster's pixel), D = G * (1 - tone) the picture's
** darkness in [0, 1] blurred by the same G at the picture's pixels and read
** at the raster's pixel centres (with a ring of white paper, 0, around the picture
** as wide as a footprint), G a Gaussian of standard deviation sigma (mm).
** Blurring the target too keeps the minimum within reach: without it the
** lines would pile up along every edge of the picture to make the blurred
** ink as sharp as the target.  B is kept directly: blurring is linear, so each
** quadrature sample (position r_q, length element dl_q) adds the blurred
** footprint of its ink area a_q = pen dl_q,
**
**   B_p += a_q gx_i(r_q) gy_j(r_q) / A,
**
** gx, gy the Gaussian less its value at rho = `radius` raster pixels
** (ceil(3 sigma / pixel)), 0 beyond, sampled at the pixel centres and normalised to sum 1
** per axis: the footprint is continuous in the sample's position, and a
** sample inside the raster deposits exactly its ink area, sum_p A B_p =
** pen * (length of line in the raster).  Derivation
** and the choice of footprint in docs/NUMERICS.md.
**
** Exact sums: B is stored in fixed point (LW_TONE_ONE units per unit of ink
** fraction, int64) and each footprint value is rounded once, from the
** sample alone.  Adding and taking away footprints is then exact and
** order-free: the raster is a function of the state, whether built from
** scratch (a resume) or updated by a million moves, so dE and the run stay
** bit-identical.  The rounding (2^-32 of full ink per pixel) is part of the
** energy's definition.  A footprint value is capped at LW_TONE_CAP (a
** sample that alone inks a pixel 65536 times over is a degenerate state,
** not a drawing), so a pixel overflows only past 2^15 such samples.
**
** Memory: the target, 4 bytes a raster pixel, shared by the replicas; the
** raster, 8 bytes a pixel, in each replica's model (with layers, layers.h,
** a target and a raster plane a layer); a proposal's box, 8
** bytes a pixel of the largest box it has needed.
**
** A move: lw_tone_box_cover() grows a box over the footprints of the
** affected segments (old and new), lw_tone_box_ready() zeroes it, the old
** samples splat -1 and the new ones +1 into it, lw_tone_delta() gives
** dE / T from the box alone (O(box)), and lw_tone_apply() adds it to the
** raster on commit.
*/
#ifndef LINEWISE_TONE_H
#define LINEWISE_TONE_H

#include <stddef.h>
#include <stdint.h>

#include "linewise/error.h"
#include "linewise/image.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_TONE_ONE 4294967296.0 /* 2^32 raster units per unit of ink fraction */
#define LW_TONE_CAP 65536.0      /* largest footprint value, ink fractions */
#define LW_TONE_RADIUS_MAX 16    /* footprint half-width limit, raster pixels (9 reached) */
#define LW_TONE_BLUR_MAX 512     /* 3 sigma in picture pixels, at most */
#define LW_TONE_SIGMA_PIXELS 1.5 /* raster pixels per sigma, at least (above) */

/* What the tone term reads (its context's data); built by the scene. */
typedef struct {
  int w, h;         /* raster pixels: the picture's blocks and `pad` on every side */
  int pad;          /* ring of white paper, pixels (= radius) */
  double x0, y0;    /* top-left corner of raster pixel (0, 0), mm */
  double pixel;     /* side of a pixel, mm */
  double area;      /* pixel^2, mm^2 */
  double sigma;     /* blur G, mm */
  double pen;       /* ink area per mm of line, mm */
  int radius;       /* footprint half-width, pixels */
  double inv;       /* 1 / (2 sigma^2), mm^-2 */
  double floor;     /* the Gaussian at radius pixels: exp(-(radius pixel)^2 inv) */
  double fall;      /* exp(-2 pixel^2 inv), by which the ratio of neighbours falls */
  float *dark;      /* w * h target D = G * darkness in [0, 1], row-major */
} lw_tone;

/* Builds the target, ink times the darkness, from the processed picture img
** placed at pl.  sigma > 0 and pen > 0, mm; 0 < ink <= 1.  LW_ENOMEM, or
** LW_EINPUT when 3 sigma is more than LW_TONE_BLUR_MAX picture pixels (the
** target is blurred at the picture's resolution). */
lw_status lw_tone_init(lw_tone *t, const lw_image *img, const lw_image_place *pl, double sigma, double pen,
                       double ink, lw_error *err);
void lw_tone_clear(lw_tone *t);

/* A zeroed w * h raster, or NULL. */
int64_t *lw_tone_raster_new(const lw_tone *t);

/* Adds sign (+1 or -1) times the footprint of the sample (x, y, dl) to the
** window of r that starts at pixel (wx, wy) and is ww pixels wide (r holds
** rows of ww); pixels outside the window and the raster are skipped. */
void lw_tone_splat(const lw_tone *t, int64_t *r, int wx, int wy, int ww, int wh, double x, double y, double dl,
                   int sign);

/* sum_p A (B_p - D_p)^2 (no coefficient) in pixel order. */
double lw_tone_energy(const lw_tone *t, const int64_t *r);

/* The partials of coef sum_p A (B_p - D_p)^2, r the raster of every
** sample, with respect to one sample's position (x, y) and length element
** dl, into *ex, *ey, *edl: the derivative of the footprint as the raster
** holds it, its rounding to fixed point left out (2^-33 of full ink a
** pixel).  0 for a sample whose footprint misses the raster. */
void lw_tone_sample_grad(const lw_tone *t, const int64_t *r, double coef, double x, double y, double dl,
                         double *ex, double *ey, double *edl);

/* A rectangle of changes to the raster, [x0, x1) x [y0, y1). */
typedef struct {
  int x0, y0, x1, y1;
  int64_t *d;       /* (x1 - x0) (y1 - y0) changes, rows of x1 - x0 */
  size_t cap;       /* allocated entries */
} lw_tone_box;

/* Empties the box (keeps its memory). */
void lw_tone_box_reset(lw_tone_box *b);
/* Grows the box to cover the footprints of every sample inside the
** rectangle [x0, x1] x [y0, y1] (mm; a segment's control points bound it),
** with a pixel to spare for rounding, clipped to the raster. */
void lw_tone_box_cover(const lw_tone *t, lw_tone_box *b, double x0, double y0, double x1, double y1);
/* Zeroes the box's changes, growing its memory if needed (LW_ENOMEM). */
lw_status lw_tone_box_ready(lw_tone_box *b);
void lw_tone_box_free(lw_tone_box *b);
/* Splats a sample into the box (as lw_tone_splat). */
void lw_tone_box_splat(const lw_tone *t, lw_tone_box *b, double x, double y, double dl, int sign);

/* sum over the box of A [(B + dB - D)^2 - (B - D)^2] (no coefficient). */
double lw_tone_delta(const lw_tone *t, const int64_t *r, const lw_tone_box *b);
/* r += the box's changes. */
void lw_tone_apply(const lw_tone *t, int64_t *r, const lw_tone_box *b);

#ifdef __cplusplus
}
#endif

#endif
