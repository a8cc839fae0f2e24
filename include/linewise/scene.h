/*
** scene.h -- everything the energy reads besides the splines: coefficients,
** quadrature, fields, boundary, pair settings; built from lw_params.
**
** A scene with [scene] image holds the processed picture and where it lies
** on the page (docs/IMAGES.md has the pipeline: load, downsample, resize,
** blur, tone curve); the potential, the field and the mask boundary are
** built from it when the scene asks for them.
**
** Only what the scene names is built: the potential exists only when its
** coefficient Q is non-zero, the vector field only when P is, and so on; a
** term that is off is never evaluated (lw_scene.local lists the per-segment
** terms that are on, in a fixed order).
*/
#ifndef LINEWISE_SCENE_H
#define LINEWISE_SCENE_H

#include "linewise/boundary.h"
#include "linewise/field.h"
#include "linewise/image.h"
#include "linewise/pair.h"
#include "linewise/params.h"
#include "linewise/quad.h"
#include "linewise/terms.h"

typedef struct lw_scene {
  double width, height;         /* page, mm */
  double coef[LW_TERM_COUNT];   /* S B Q P C R; 0 = off */
  int on[LW_TERM_COUNT];        /* coef != 0 */
  int strain_per_segment;       /* strain mode */
  int field_axial;              /* field mode */
  lw_quad quad;
  lw_quad pair_quad;            /* nodes of the pair samples (valid when pair is on) */
  lw_pair_ctx pair;
  lw_potential potential;       /* valid when on[LW_TERM_POTENTIAL] */
  lw_field field;               /* valid when on[LW_TERM_FIELD] */
  lw_boundary boundary;         /* the frame (also used for placement) */
  int n_local;                  /* per-segment terms that are on ... */
  lw_term_id local[LW_TERM_COUNT]; /* ... and which */
  lw_image *image;              /* the processed picture (owned), or NULL */
  lw_image_place image_place;   /* where it lies on the page */
  char note[LW_ERROR_MSG];      /* something the user should know (a picture was
                                   downsampled), or empty; the CLI prints it */
} lw_scene;

/* Builds the scene; messages name the parameter's file and line. */
lw_status lw_scene_init(lw_scene *sc, const lw_params *p, lw_error *err);
void lw_scene_clear(lw_scene *sc);

#endif
