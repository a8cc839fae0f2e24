/*
** fidelity.h -- how well the drawn lines reproduce a target tone.
**
** The target is a tone raster: an lw_grid2d (field.h) with one value per
** pixel, node (i, j) at the centre of pixel (i, j), pixels hx x hy mm, tone
** 0 = black .. 1 = white (values outside are clamped).  Its rectangle is
** [x0 - hx/2, x0 + (nx - 1/2) hx] x [y0 - hy/2, y0 + (ny - 1/2) hy].
**
** 1. The lines are rendered over that rectangle at the raster's resolution
**    (cairo, antialiased, the exact Bezier curves stroked with the pen
**    width, round caps): ink = the covered fraction of each pixel, summed
**    over the paths and capped at 1.  Pixels wider than
**    LW_FIDELITY_PEN_PIXELS pen widths are rendered as k x k finer ones and
**    averaged (cairo's coverage is eight bits a path).
**    The target is the ink the drawing is asked for: black * (1 - tone),
**    black the ink where the picture is black (the tone term's tone_ink: a
**    drawing whose black is lines two pen widths apart is scored against
**    half ink there, not against solid black it was never meant to reach).
**    "Darkness" below is this target.
** 2. Both are blurred with the same Gaussian of standard deviation sigma
**    (mm; sigma / hx and sigma / hy pixels per axis), truncated at 4 sigma
**    and renormalised by the weights that fall inside the raster, so a flat
**    tone stays flat up to the edges.  The blur stands for the eye at
**    viewing distance: hatching at spacing s averages to a flat grey once
**    sigma is about s / 2 (the fundamental of the pattern is damped by
**    exp(-2 pi^2 sigma^2 / s^2), below 1% at sigma = s / 2).  The default
**    1 mm suits a 0.3 mm pen, whose lines run 0.6 to 3 mm apart for
**    darkness 0.5 to 0.1.
** 3. MSE = mean over pixels of (ink - darkness)^2, both blurred.
**    SSIM (Wang, Bovik, Sheikh, Simoncelli 2004) with dynamic range L = 1,
**    C1 = (0.01 L)^2, C2 = (0.03 L)^2, local statistics under the 11 x 11
**    Gaussian window of sigma 1.5 pixels (renormalised at the edges like
**    the blur), the SSIM map averaged over every pixel.  1 = identical.
** 4. Orientation agreement: the structure tensor J = G * (grad grad^T) of
**    each blurred image (central differences, the SSIM window as G) gives
**    per pixel a dominant gradient axis as the doubled-angle vector
**    u = (Jxx - Jyy, 2 Jxy), whose length is the anisotropy.  The score is
**    sum |u_target| cos(2 dtheta) / sum |u_target|: the mean agreement of
**    the two axes where the target has structure, 1 = every edge of the
**    target matched by ink running the same way, 0 = no relation (or no
**    ink), -1 = everywhere crosswise.  A pixel where the ink has no
**    direction (gradient below LW_FIDELITY_FLAT) adds 0.  It ignores tone and contrast, and lines along the
**    target's isophotes agree with it whether the blur has merged them
**    into a tone (the tone's gradient) or not (each line's own gradient is
**    across it, along the target's), which is why it depends far less on
**    sigma than MSE and SSIM do (docs/IMAGES.md).  NaN for a flat target.
** 5. Stray ink: the share of the ink (unblurred, summed over pixels) that
**    lies where the blurred darkness is under LW_FIDELITY_WHITE of black: paper the
**    target leaves white for about two sigmas around, so a line along the
**    edge of a dark area does not count and one across a white background
**    does.  0 for a drawing without ink.
** 6. Missed marks, stray ink's mirror: the share of the target's dark pixels
**    (darkness LW_FIDELITY_MARK of black or more, unblurred) with no inked
**    pixel (covered LW_FIDELITY_INKED of black or more) within LW_FIDELITY_MISS_REACH
**    pen widths along x and y.  A dark area hatched at its density (lines
**    at most 2.9 pen widths apart at that darkness) has a line within 1.5
**    widths of every pixel; a mark no line came near -- a letter thinner
**    than the blurs see -- counts whole, which MSE and SSIM, blurred, barely
**    see (hairline letters half undrawn scored SSIM 0.94).  0 without marks.
**    The same share in the worst square of LW_FIDELITY_MISS_CELL pen widths
**    (off the raster's edge) finds a word left out beside a figure drawn.
**
** The drawing is scored as plotted (strokes.h: joined, cropped, dropped);
** a pen's score renders that pen's paths alone against the same target.
*/
#ifndef LINEWISE_FIDELITY_H
#define LINEWISE_FIDELITY_H

#include "linewise/error.h"
#include "linewise/field.h"
#include "linewise/spline.h"
#include "linewise/strokes.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_FIDELITY_TRUNCATE 4.0      /* blur kernel radius, in sigmas */
#define LW_FIDELITY_SSIM_SIGMA 1.5    /* SSIM window, pixels */
#define LW_FIDELITY_SSIM_RADIUS 5     /* SSIM window half width: 11 x 11 */
#define LW_FIDELITY_FLAT 1e-9         /* gradient (per pixel) below which a pixel has no direction */
#define LW_FIDELITY_PEN_PIXELS 1.0    /* coarser pixels (in pen widths) are rendered finer and averaged */
#define LW_FIDELITY_FINE_MAX 16777216.0 /* the fine render's most pixels */
#define LW_FIDELITY_SIDE_MAX 32767    /* the most pixels a side cairo renders: a longer picture cannot be scored */
#define LW_FIDELITY_WHITE 0.02        /* blurred darkness under which the target is white paper */
#define LW_FIDELITY_MARK 0.7          /* darkness (of black) from which a target pixel is a mark */
#define LW_FIDELITY_INKED 0.25        /* a pixel's ink, of black, from which it counts as inked */
#define LW_FIDELITY_MISS_REACH 2.0    /* pen widths within which a mark's line must lie */
#define LW_FIDELITY_MISS_CELL 25.0    /* pen widths a side of the squares missed_worst is of */

typedef struct {
  double mse;       /* mean squared difference of blurred ink and darkness */
  double ssim;      /* mean structural similarity, -1..1 */
  double orientation; /* orientation agreement, -1..1 (NaN: flat target) */
  double stray;     /* share of the ink on white paper, 0..1 */
  double missed;    /* share of the dark marks with no line near, 0..1 */
  double missed_worst; /* the same in the worst square of LW_FIDELITY_MISS_CELL pen widths (a fiftieth marks or
                          more; not on the raster's edge) */
  double missed_at[2]; /* that square's centre, mm on the page (-1 -1: none) */
  double sigma_mm;  /* the blur used, mm */
  double black;     /* the ink the target asks where the picture is black, 0..1 */
} lw_fidelity;

/* Steps 1-6 above for the splines against the tone raster, black 1 (solid
** ink where the picture is black), pen width and blur sigma in mm.
** LW_EINPUT for a raster that is not one value per pixel or a width or
** sigma that is not positive, LW_ENOMEM. */
lw_status lw_fidelity_compute(const lw_splines *sp, const lw_grid2d *tone, double pen_width_mm,
                              double sigma_mm, lw_fidelity *out, lw_error *err);

/* The same for the paths of pen `pen` of a drawing (0-based; -1: all),
** against black * (1 - tone), black in (0, 1]. */
lw_status lw_fidelity_compute_strokes(const lw_strokes *s, int pen, const lw_grid2d *tone, double black,
                                      double pen_width_mm, double sigma_mm, lw_fidelity *out, lw_error *err);

/* Step 1 alone: ink[j * nx + i] for the pixels of the tone raster. */
lw_status lw_fidelity_render(const lw_splines *sp, const lw_grid2d *tone, double pen_width_mm, double *ink,
                             lw_error *err);
lw_status lw_fidelity_render_strokes(const lw_strokes *s, int pen, const lw_grid2d *tone, double pen_width_mm,
                                     double *ink, lw_error *err);

/* Steps 2-5 (not 6: lw_fidelity_compute_strokes counts the missed marks) for
** the ink a and the darkness b, w x h (changed in place: blurred),
** blur sigma sx, sy in pixels (0 = none), paper white where the blurred b is
** under `white`; out->sigma_mm and out->black are left alone. */
lw_status lw_fidelity_compare(double *a, double *b, int w, int h, double sx, double sy, double white,
                              lw_fidelity *out, lw_error *err);

/* Gaussian blur of the w x h image v in place, sigma sx, sy pixels (0 =
** none along that axis), kernel radius ceil(truncate * sigma) pixels,
** renormalised at the edges.  LW_ENOMEM if the scratch row cannot be had. */
lw_status lw_fidelity_blur(double *v, int w, int h, double sx, double sy, double truncate, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
