/*
** imagefield.h -- what the energy reads, made from a picture placed on the
** page (image.h): the potential grid, the edge tangent flow and the
** gradient field.  Units: page millimetres; tone gradients in tone per mm.
**
** Potential: Phi = tone at the pixel centres (0 black .. 1 white, so dark
** is low and attracts lines when Q > 0), with one ring of white (1) around
** the picture: outside it the paper is white and lookups, which clamp to
** the grid's edge, read 1 (blurred, the paper around the picture is white
** as the blur reaches it).
**
** Gradient g = grad tone by the Sobel operator (3 x 3, the picture's edge
** pixels repeated beyond it), pointing toward lighter tone.
**
** Edge tangent flow (ETF): the direction along edges and isophotes.  The
** structure tensor J = g g^T is smoothed by a Gaussian of sigma_mm; its
** eigenvector of the smaller eigenvalue is the direction in which the tone
** changes least.  J's doubled-angle vector (J11 - J22, 2 J12) has the angle
** 2 theta of the gradient direction and the length lambda1 - lambda2 (how
** much one direction dominates), so the tangent's doubled angle is that
** vector turned by 180 degrees.  Where the picture is flat the tensor
** vanishes and the direction is undefined; there the tensor of a weak
** fallback structure, flat^2 n n^T with n normal to the direction `angle`, takes
** over:
**     T = (J22 - J11 + flat^2 cos 2a,  -2 J12 + flat^2 sin 2a),
** normalised, stored as an LW_FIELD_GRID_AXIAL grid of unit length.  Where
** the image's anisotropy (in (tone/mm)^2) is well above flat^2 the image
** decides, where it is well below the fallback does, and in between the two
** blend smoothly.  The field thus has unit length everywhere: the field
** energy weighs alignment equally on the whole page.  Beyond the picture
** the grid's edge values continue (lookups clamp).
**
** Gradient field: v = g / max(|g|, flat), a signed LW_FIELD_GRID: unit
** length where the tone changes faster than `flat` per mm, fading to 0
** where the picture is flat (a gradient has no direction there).
*/
#ifndef LINEWISE_IMAGEFIELD_H
#define LINEWISE_IMAGEFIELD_H

#include "linewise/field.h"
#include "linewise/image.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The potential of scene.potential = image: Phi = tone^power at the pixel
** centres, white beyond the picture; or (sigma > 0) the picture on white
** paper blurred by a Gaussian of sigma pixels, the grid reaching as far as
** the blur does (4 sigma, at most 256 pixels), so that Phi rises to white
** beyond the picture without a step between two quadrature nodes.  With
** paper 0 the blur repeats the picture's edge pixels and Phi continues the
** edge beyond it (as before 2026-12-06: a line beyond a dark edge costs
** nothing there).  With fine, where a pixel is wider than 1 mm the grid has
** an odd number of nodes a pixel, no more than 1 mm apart (at most 4
** million nodes): the same bilinear reading between the pixel centres, and
** the edge pixels' tone out to the picture's edge; without, a node a pixel
** (as before 2026-12-06: Phi turned white from the edge pixels' centres). */
lw_grid2d *lw_imagefield_potential(const lw_image *img, const lw_image_place *pl, double power, double sigma,
                                   int paper, int fine, lw_error *err);

/* gentle[k] (gentle may be NULL): under flat / 10^k, k < LW_IMAGEFIELD_GENTLE,
** the share of the pixels the field_flat rule below decides: so that a
** note can say which smaller field_flat would follow the picture (a height
** map's contours were lost at the default, and the note named no value). */
#define LW_IMAGEFIELD_GENTLE 3

/* angle: the fallback direction, radians (0 = +x, pi/2 = +y, down).
** gentle: the shares of the pixels where the picture's (smoothed) structure
** is there, coherent (its anisotropy above half its trace: a direction, not
** noise) but under the flat, so that the fallback decides: a smooth picture
** of a scientist's field, 0..1 over a page, changes by about 0.01 tone/mm
** everywhere, and the default field_flat made most of its field the
** fallback's, unsaid. */
lw_grid2d *lw_imagefield_etf(const lw_image *img, const lw_image_place *pl, double sigma_mm, double flat,
                             double angle, double gentle[LW_IMAGEFIELD_GENTLE], lw_error *err);

/* gentle: the shares of the pixels whose tone changes, but slower than the
** flat, where the field fades. */
lw_grid2d *lw_imagefield_gradient(const lw_image *img, const lw_image_place *pl, double flat,
                                  double gentle[LW_IMAGEFIELD_GENTLE], lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
