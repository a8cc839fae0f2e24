/*
** layers.h -- hatching layers and colour pens: a scene split into layers,
** each a pen of its own with its own target, field, width and colour.
**
** A scene with [layers] names = "a b ..." has L layers, and each spline
** belongs to one, a function of its index alone (lw_layers_of): with the
** layers' shares s_k (the ink of each target over its pen's width, over the
** sum of those; equal shares without a picture) and the golden-ratio sequence
** x_i = frac((i + 1) phi), phi = (sqrt 5 - 1) / 2, spline i is of the
** layer k with s_0 + .. + s_(k-1) <= x_i < s_0 + .. + s_k.  The sequence
** is evenly spread for every count, so each layer gets its share of any
** number of splines (to O(log n) splines), and a layer without ink gets
** none.  The layer is part of each spline's state (spline.h, sp->layer),
** set by the index rule when the state is placed or loaded from a file
** without it, drawn by the shares for a born spline (layer k with
** probability s_k; moves.fixed_count = 0), kept by grow, shrink, split,
** join, compaction and the drift checks' renumbering, and saved in
** state.lw (docs/FORMATS.md).  Layer k is pen k + 1 of the drawing.
**
** What a layer changes: the terms that read the picture or the field read
** the layer's own (scene.h, lw_scene_layer_ctx):
**   field      the scene's field (scene.field) turned by the layer's `turn`:
**              R(turn) v, so `turn = 0 90` hatches along and across the
**              flow (the grid, if any, is the scene's, borrowed);
**   potential  with scene.potential = image, Phi = the layer's target tone;
**   tone       the layer's own raster and target, blurred alike, with the
**              layer's pen width as the ink per mm.
** The other terms (strain, bending, pair, boundary, ...) see all splines
** alike.  A scene without [layers] has no layers (n = 0) and is built and
** run exactly as before.
**
** Targets (tone 0 black .. 1 white, the picture's size and place):
**   tone      the processed picture's tone t through the layer's range:
**             darkness a = clamp((tone_max - t) / (tone_max - tone_min), 0, 1);
**   cmyk      the palette separation below into the process colours cyan,
**             magenta, yellow and black (4 layers, that order);
**   palette   the separation of the colour picture into the pens `colors`.
** The target tone is 1 - a.
**
** Separation (docs/NUMERICS.md, "Colour separation").  Ink of pen k with
** colour p_k (RGB in [0, 1]) laid side by side on white paper over an area
** fraction a_k reflects c = 1 - sum_k a_k u_k, u_k = 1 - p_k (exact while
** inks do not overlap, first order in the coverage when they do).  Per
** pixel of colour c the coverages minimise
**     1/2 |U a - (1 - c)|^2 + 1/2 lambda |a|^2 + mu sum_k a_k
**     subject to 0 <= a_k <= 1,
** U the 3 x K matrix of the u_k, lambda = LW_LAYERS_RIDGE, mu =
** LW_LAYERS_INK: a strictly convex quadratic, solved exactly by a bounded
** active-set method (each step a Cholesky solve of the free variables'
** normal equations).  When pens are dependent (K > 3, as CMYK) many
** coverages fit equally well; mu picks the one with the least ink (a grey
** in black alone rather than in cyan, magenta and yellow at once: 1 unit
** against 3), and lambda, far smaller, keeps the problem strictly convex.
** For independent pens both pull a fit that is exact by at most
** (lambda |a| + mu sqrt(K)) / s_min, s_min the smallest eigenvalue of
** U^T U: 2e-5 for cyan, magenta and yellow (s_min = 1), far below an 8-bit
** step (4e-3).
*/
#ifndef LINEWISE_LAYERS_H
#define LINEWISE_LAYERS_H

#include <math.h>
#include <stddef.h>

#include "linewise/error.h"
#include "linewise/field.h"
#include "linewise/image.h"
#include "linewise/params.h"
#include "linewise/plot.h"
#include "linewise/spline.h"
#include "linewise/tone.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_LAYERS_MAX LW_PLOT_PENS_MAX
#define LW_LAYERS_RIDGE 1e-6   /* lambda of the separation */
#define LW_LAYERS_INK 1e-5     /* mu of the separation */

/* One layer as the scene file describes it. */
typedef struct {
  char name[64];
  double turn;               /* field turn, radians */
  double tone_min, tone_max; /* source = tone: full ink at and below tone_min, none from tone_max */
  double pen_width;          /* mm */
  unsigned char rgb[3];      /* pen colour */
} lw_layer_spec;

typedef struct {
  int n;                     /* 0 = no layers */
  int source;                /* LW_LSRC_* */
  int apart;                 /* LW_APART_PEN: a line keeps apart from its own layer's only */
  lw_layer_spec spec[LW_LAYERS_MAX];
  double cum[LW_LAYERS_MAX + 1]; /* cumulated shares: cum[0] = 0, cum[n] = 1 */
} lw_layers_spec;

/* What a layer's terms read, built by the scene from its spec. */
typedef struct {
  lw_image *target;          /* the layer's target tone (owned), or NULL without a picture */
  lw_field field;            /* valid when the field term is on; its grid is the scene's */
  lw_potential potential;    /* valid when the potential term is on (grid owned) */
  lw_tone tone;              /* valid when the tone term is on */
} lw_layer;

/* Reads and checks [layers] of p.  LW_EINPUT with one message naming the
** file, line and key and what was expected. */
lw_status lw_layers_read(const lw_params *p, lw_layers_spec *ls, lw_error *err);

/* The shares of the layers from the ink (1 - tone) of their targets, each
** over its pen's width where by_width (a line of a pen half as wide lays
** half the ink, as the count of init.coverage has it; layers.share_width),
** or equal shares when there is no ink at all. */
void lw_layers_share(lw_layers_spec *ls, const lw_image *const *target, int by_width);

/* The layer whose share holds u in [0, 1): a birth's layer for u uniform
** (ls->n > 0). */
static inline int lw_layers_at(const lw_layers_spec *ls, double u)
{
  int k = 0;
  while (k < ls->n - 1 && u >= ls->cum[k + 1]) k++;
  return k;
}

/* The layer of spline i by the index rule (ls->n > 0; see above). */
static inline int lw_layers_of(const lw_layers_spec *ls, size_t i)
{
  double x = (double)(i + 1) * 0.6180339887498949;
  return lw_layers_at(ls, x - floor(x));
}

/* The layer of spline i of sp (ls->n > 0): stored with the spline where
** splines are born and die (sp->layer, trans-dimensional moves), else the
** index rule. */
static inline int lw_splines_layer(const lw_layers_spec *ls, const lw_splines *sp, size_t i)
{
  return sp->layer ? sp->layer[i] : lw_layers_of(ls, i);
}

/* Planes of the pair grid (grid.h): one a layer when a line keeps apart
** from its own layer's lines only (layers.apart = pen), else one. */
static inline int lw_layers_planes(const lw_layers_spec *ls)
{
  return ls->n > 1 && ls->apart == LW_APART_PEN ? ls->n : 1;
}

/* Separates n pixels of colour (r, g, b) into the k pens of colours rgb:
** a[j * n + p] = coverage of pen j at pixel p, in [0, 1] (see above).
** k in 1 .. LW_LAYERS_MAX.  No failure: the normal matrix is positive
** definite. */
void lw_layers_separate(const float *r, const float *g, const float *b, size_t n, int k,
                        const unsigned char (*rgb)[3], float *a);

#ifdef __cplusplus
}
#endif

#endif
