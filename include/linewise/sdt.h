/*
** sdt.h -- exact Euclidean (signed) distance transforms of pixel masks.
**
** lw_sdt_squared is the squared distance from every pixel centre to the
** nearest pixel centre marked as a feature, computed exactly by the
** lower-envelope-of-parabolas method of Felzenszwalb and Huttenlocher
** ("Distance transforms of sampled functions", 2012): a 1-D pass along
** every column, then one along every row, O(pixels) in all.
**
** lw_sdt_grid turns an inside/outside mask into the signed distance the
** boundary term reads (boundary.h): negative inside, positive outside, in
** millimetres, sampled at pixel centres.  A pixel's value is the distance
** to the nearest pixel centre on the other side, less half a pixel, so the
** zero level runs along the pixel edges between inside and outside (read
** bilinearly, it cuts an outside pixel's corner among inside pixels by up to
** 0.27 px along each side; docs/IMAGES.md):
**     inside:  d = -(D_out - 1/2) px      outside:  d = D_in - 1/2 px
** The grid carries one extra ring of outside pixels around the picture, so
** bilinear interpolation never reads an inside value beyond the picture's
** edge, and lookups further out (clamped to the ring) are outside too.
*/
#ifndef LINEWISE_SDT_H
#define LINEWISE_SDT_H

#include "linewise/error.h"
#include "linewise/field.h"
#include "linewise/image.h"

#ifdef __cplusplus
extern "C" {
#endif

/* out[j * w + i] = squared distance (pixels^2) from pixel (i, j) to the
** nearest pixel with feature != 0; HUGE_VAL everywhere if there is none. */
lw_status lw_sdt_squared(const unsigned char *feature, int w, int h, double *out, lw_error *err);

/* The signed distance grid (ncomp 1, mm) of the mask `inside` (w x h,
** row-major, non-zero = inside) placed on the page by pl.  LW_EINPUT if no
** pixel is inside. */
lw_grid2d *lw_sdt_grid(const unsigned char *inside, int w, int h, const lw_image_place *pl, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
