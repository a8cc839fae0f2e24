/*
** scene.h -- everything the energy reads besides the splines: coefficients,
** quadrature, fields, boundary, pair settings; built from lw_params.
**
** A scene with [scene] image holds the processed picture and where it lies
** on the page (docs/IMAGES.md has the pipeline: load, downsample, resize,
** blur, tone curve); the potential, the field and the mask boundary are
** built from it when the scene asks for them.
**
** With [layers] (layers.h) each layer has its own target, field,
** potential and tone raster besides the scene's; lw_scene_layer_ctx gives
** the term contexts a layer's splines read.
**
** Only what the scene names is built: the potential exists only when its
** coefficient Q is non-zero, the vector field only when P is, and so on; a
** term that is off is never evaluated (lw_scene.local lists the per-segment
** terms that are on, in a fixed order).
**
** Besides the terms a scene file names, a program (a test, a study) may
** register one energy of its own, the user term: a function of a segment's
** samples that the model caches, differences and sums exactly like the
** built-in per-segment terms.  It is off unless set, so it costs nothing
** otherwise.  Examples: a quadratic of the Gauss samples, which makes every
** point coordinate an exactly Gaussian degree of freedom (the statistical
** tests), or an energy of the segment's end nodes (s->end_x, s->end_y).
*/
#ifndef LINEWISE_SCENE_H
#define LINEWISE_SCENE_H

#include "linewise/boundary.h"
#include "linewise/field.h"
#include "linewise/image.h"
#include "linewise/layers.h"
#include "linewise/pair.h"
#include "linewise/params.h"
#include "linewise/quad.h"
#include "linewise/terms.h"
#include "linewise/tone.h"

#ifdef __cplusplus
extern "C" {
#endif

/* With a cutoff rc, a segment whose consecutive pair samples lie more than
** this share of rc apart is forbidden: a line crossing it between two of
** them might then pass no sample pair within rc / 2, where the near field
** takes a crossing whole, and the product rule would hide most of it.
** 0.75: the worst crossing of segments at the limit (a right angle, in the
** middle of both segments' widest gaps) errs by 7.5e-4 at 8 nodes, 7e-3 at
** 0.8 and 5.5e-2 at 0.9 (docs/NUMERICS.md, "Regular segments").  Placement
** asks it of the placed segments (lw_init_count). */
#define LW_PAIR_GAP_SHARE 0.75

/* The least energy.pair_near (other than 0, off) for the pair rule q: the
** near field takes a crossing whole where a sample pair lies within half
** its radius, near times the larger element length.  A right angle in the
** middle of both lines' widest gaps (spacing s of the rule, of elements
** up to w long) has its nearest pair s / sqrt 2 from it, so near must be
** at least sqrt(2) s / w: 1.431 at 8 nodes, 1.633 at 2 (rounded up, as the
** scene refuses less).  Below, crossings between samples are taken in
** part: 3e-3 hidden at 1.3, 14 % at 1, 38 % at 0.5 (8 nodes;
** docs/ACCURACY.md, "Near field"). */
double lw_pair_near_least(const lw_quad *q);

typedef struct lw_scene {
  double width, height;         /* page, mm */
  double coef[LW_TERM_COUNT];   /* S B Q P C R, the user term's, G, T; 0 = off */
  int on[LW_TERM_COUNT];        /* coef != 0 */
  int strain_per_segment;       /* strain mode */
  int field_axial;              /* field mode */
  double min_speed;             /* regularity: fraction of a segment's mean speed its
                                   speed must keep; 0 = no check (spline.h) */
  double regularity;            /* regularity: the Bernstein ellipse its bending
                                   integrand must be analytic in; 0 = no check */
  double pair_gap_max;          /* the widest space between a segment's consecutive
                                   pair samples, mm (LW_PAIR_GAP_SHARE of the
                                   cutoff); 0 = no check (no pair term or no cutoff) */
  lw_quad quad;
  lw_quad pair_quad;            /* nodes of the pair samples (valid when pair is on) */
  lw_quad tone_quad;            /* nodes of the tone samples (valid when tone is on) */
  lw_pair_ctx pair;
  lw_potential potential;       /* valid when on[LW_TERM_POTENTIAL] */
  lw_field field;               /* valid when on[LW_TERM_FIELD] */
  lw_boundary boundary;         /* the frame (also used for placement) */
  lw_tone tone;                 /* valid when on[LW_TERM_TONE]: target and footprint */
  double min_spacing;           /* least distance between the curves of different
                                   splines, mm (a hard constraint, model.h); 0 = none */
  lw_user_term_fn user_fn;      /* valid when on[LW_TERM_USER] */
  const void *user_data;        /* passed to user_fn; not owned */
  double load[2];               /* b of the load term: rho g + f, force per mm */
  double chem[2];               /* the chemical term's mu_s (energy) and mu_l (energy/mm) */
  int transdim;                 /* 1: trans-dimensional moves on (moves.fixed_count = 0) */
  size_t max_segments;          /* then: the longest a spline may grow, segments */
  int n_local;                  /* per-segment terms that are on ... */
  lw_term_id local[LW_TERM_COUNT]; /* ... and which */
  lw_image *image;              /* the processed picture (owned), or NULL */
  lw_image_place image_place;   /* where it lies on the page */
  lw_image *reference;          /* output.fidelity_reference as loaded (owned), or NULL */
  lw_image_place reference_place;
  lw_layers_spec layers;        /* [layers]; layers.n = 0: none (layers.h) */
  lw_layer layer[LW_LAYERS_MAX]; /* what each layer's terms read */
  char note[LW_ERROR_MSG];      /* something the user should know (a picture was
                                   downsampled), or empty; the CLI prints it */
} lw_scene;

/* Builds the scene; messages name the parameter's file and line. */
lw_status lw_scene_init(lw_scene *sc, const lw_params *p, lw_error *err);
void lw_scene_clear(lw_scene *sc);

/* The context of every term (terms.h): its coefficient and what it reads
** of this scene.  The pointers are into sc: valid while sc is. */
void lw_scene_term_ctx(const lw_scene *sc, lw_term_ctx ctx[LW_TERM_COUNT]);

/* The contexts of the terms of a spline of layer k (layers.h): as
** lw_scene_term_ctx, with the layer's field, potential and tone.  Without
** layers, lw_scene_term_ctx's. */
void lw_scene_layer_ctx(const lw_scene *sc, int k, lw_term_ctx ctx[LW_TERM_COUNT]);

/* Registers fn as the user term with coefficient coef: its energy is
** coef * fn(samples, quad, data) summed over all segments (term name
** "user").  coef = 0 turns it off again.  Call it before building a model on
** the scene (models cache the term list); data must outlive those models.
** LW_EINPUT if coef is not finite or fn is NULL while coef != 0. */
lw_status lw_scene_set_user_term(lw_scene *sc, double coef, lw_user_term_fn fn, const void *data,
                                 lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
