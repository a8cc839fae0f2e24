/*
** terms.h -- the energy terms as pure functions of a segment's samples, and
** the term table: one row a term, each with a context of its own.
**
** Integrals run over the segment parameter s in [0,1] with the Gauss-Legendre
** weights of the scene's quadrature (w_q, sum 1).  Each function returns the
** integral without its coefficient; lw_term_types applies the coefficient.
**
**   strain    S (L - L0)^2 / L0^2 * L       per spline (L = sum of segment lengths)
**             or per segment with l0 = L0 / n                       (lw_term_strain)
**   bending   B * int (x'y'' - x''y')^2 / |r'|^5 ds  = B * int kappa^2 dl
**   potential Q * int Phi(r) |r'| ds
**   field     P * int r' . v(r) ds      (signed)   or   P * int |r' . v(r)| ds (axial)
**   pair      C * sum of sample-pair kernels between different splines (pair.h)
**   boundary  R * int f(d(r)) |r'| ds,  f(d) = 1/d^2 for d < 0, +infinity for d >= 0
**   user      coef * fn(samples), a per-segment energy registered by the caller
**             (lw_scene_set_user_term in scene.h); never set from a scene file
**   parametrisation
**             G * int (|r'| - l)^2 ds / l per segment, l = int |r'| ds (the
**             segment's length = its mean speed): 0 for uniform speed, so it
**             holds the handle lengths that do not change the shape
**             (docs/NUMERICS.md); 0 for a segment of no length
**   load      -int b . r |r'| ds, b = rho g + f: gravity on the line density
**             and a constant force per mm ([dynamics] gravity_x/_y, force_x/_y;
**             on when b != 0, coefficient 1); data is b (2 doubles)
**   tone      T * sum over pixels of A (G * ink - D)^2: the lines splatted
**             into a blurred ink raster against the picture's darkness
**             (tone.h)
**   chemical  mu_s + mu_l L per spline: the chemical potential, a cost per
**             spline and per mm of line ([energy] chem_spline, chem_length;
**             on when either is != 0, coefficient 1); data is {mu_s, mu_l}.
**             What trans-dimensional moves weigh a line's existence against
**
** The term table's order is the order of trace.csv's and state.lw's energy
** columns; a new term goes at the end so older state files still read.
**
** A term sees only its context (lw_term_ctx): its coefficient, the nodes
** its samples come from, and the one object it reads (a potential, a
** field, the boundary, the pair kernel's settings, the user's data).  The
** scene fills the contexts (lw_scene_term_ctx, scene.h); terms never see
** the scene.  A row has one of four shapes, which the model (model.h)
** treats alike for every term of that shape:
**   segment   a sum over segments of a function of one segment's samples
**             (cached per segment, differenced over the segments a move
**             touches): bending, potential, field, boundary, user,
**             parametrisation;
**   spline    a sum over splines of a function of one spline's segment
**             lengths and rest length (differenced over the moved spline):
**             strain, chemical;
**   pairwise  coef times the sum of the pair kernel (pair.h) over sample
**             pairs of different splines, found in a cell grid of the
**             kernel's cutoff; ctx.data is the lw_pair_ctx, ctx.quad the
**             pair samples' nodes.  One pairwise term at most is on (the
**             grid has one cutoff): pair.
**   raster    coef times a function of a raster into which every sample
**             (at ctx.quad's nodes) splats a footprint; not a sum over
**             segments (a pixel sees every line near it), but a move
**             changes only its samples' footprints, so the model keeps
**             one raster a term and differences a box around the move
**             (tone.h); ctx.data is the lw_tone.  Any number may be on:
**             tone.
**
** Gradients (gradient.h): a segment row's segment_grad ADDS the partials
** of its energy (coefficient applied) with respect to the samples r, r',
** r'' and the end points to an lw_samples_grad; a spline row's spline_grad
** ADDS coef * dE/d(segment length) of one spline to dlen[0..n_seg-1] (a
** segment's length is sum_q w_q |r'_q|, so it reaches r' only).  Where an
** energy is not differentiable the gradient is a one-sided value or a
** subgradient (docs/NUMERICS.md, "Gradients"): the axial field uses the
** sign of r'.v, |r'| = 0 contributes 0.  The user term has none (NULL).
**
** Degenerate samples never produce NaN: a sample with r' = 0 contributes 0 to
** bending (r' = 0 forces the numerator to 0 as well; the curvature of a point
** is taken as 0), and a sample on or outside the boundary gives +infinity
** whatever its speed.  The boundary term also checks the segment's two end
** nodes, which no Gauss node reaches: a spline end outside is +infinity.
*/
#ifndef LINEWISE_TERMS_H
#define LINEWISE_TERMS_H

#include "linewise/boundary.h"
#include "linewise/field.h"
#include "linewise/quad.h"
#include "linewise/spline.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
  LW_TERM_STRAIN,
  LW_TERM_BENDING,
  LW_TERM_POTENTIAL,
  LW_TERM_FIELD,
  LW_TERM_PAIR,
  LW_TERM_BOUNDARY,
  LW_TERM_USER,
  LW_TERM_PARAM,
  LW_TERM_LOAD,
  LW_TERM_TONE,
  LW_TERM_CHEMICAL,
  LW_TERM_COUNT
} lw_term_id;

/* dE/d(sample values) of one segment: per quadrature node the partials with
** respect to r = (x, y), r' = (dx, dy) and r'' = (ddx, ddy), and the
** partials with respect to the two end points r(0), r(1) (gradient.h). */
typedef struct lw_samples_grad {
  int n;
  double x[LW_QUAD_MAX], y[LW_QUAD_MAX];
  double dx[LW_QUAD_MAX], dy[LW_QUAD_MAX];
  double ddx[LW_QUAD_MAX], ddy[LW_QUAD_MAX];
  double end_x[2], end_y[2];
} lw_samples_grad;

/* A user term: the energy of one segment from its samples (coefficient not
** applied).  It must be a pure function of its arguments, like the built-in
** terms: replicas call it from several threads at once.  +infinity forbids a
** state; it should never return NaN (a NaN dE is rejected and counted). */
typedef double (*lw_user_term_fn)(const lw_samples *s, const lw_quad *q, const void *data);

/* What one term reads.  Pointers are into the scene, which outlives every
** model built on it. */
typedef struct {
  double coef;               /* 0 = off */
  const lw_quad *quad;       /* the nodes of the samples it is given */
  const void *data;          /* lw_potential, lw_field, lw_boundary, lw_pair_ctx, user data, lw_tone, or NULL */
  lw_user_term_fn fn;        /* the user term's function */
  int mode;                  /* field: 1 axial; strain: 1 per segment */
} lw_term_ctx;

/* One row: exactly one of segment, spline, pairwise, raster.  segment returns the
** energy of one segment with its coefficient; spline the energy of one
** spline without it (the model multiplies, so differences round as
** coef * (new - old)), and spline_change its change, without the
** coefficient, when the n_changed segment lengths old_seg become new_seg
** (of n_seg) and the length old_len becomes new_len: a move of one node
** costs what it changes, not the whole spline (a spline of 100,000
** segments took 0.8 MB of copying a proposal). */
typedef struct {
  lw_term_id id;
  double (*segment)(const lw_samples *s, const lw_term_ctx *c);
  double (*spline)(const double *seg_len, size_t n_seg, double length, double rest_length, const lw_term_ctx *c);
  double (*spline_change)(const double *old_seg, const double *new_seg, size_t n_changed, size_t n_seg,
                          double old_len, double new_len, double rest_length, const lw_term_ctx *c);
  int pairwise;
  void (*segment_grad)(const lw_samples *s, const lw_term_ctx *c, lw_samples_grad *g);
  void (*spline_grad)(const double *seg_len, size_t n_seg, double length, double rest_length, const lw_term_ctx *c,
                      double *dlen);
  int raster;
} lw_term_type;

extern const lw_term_type lw_term_types[LW_TERM_COUNT];
/* as in scene files, traces, summaries and the state's energy keys */
extern const char *const lw_term_names[LW_TERM_COUNT];

double lw_term_strain(double length, double rest_length);

/* A spline's length is summed by blocks of LW_TERM_LEN_BLOCK segments from
** its first, each in order, then the blocks' sums in order: a function of
** the lengths alone (a resumed run sees the bits of one that never
** stopped), the plain sum under a block, and with the blocks' sums kept
** (the model's seg_block) a commit on a long spline costs a block and the
** blocks, not the whole spline: one of 100,000 segments swept 21 times
** slower than the same segments cut into 100 (2026-12-06). */
#define LW_TERM_LEN_BLOCK 128

/* The sum of the block of seg[0..n) from segment b0. */
double lw_term_block_sum(const double *seg, size_t n, size_t b0);

/* The length of a spline of n segments of lengths seg; blk, where not NULL,
** its blocks' sums (blk[b0] for the block from segment b0). */
double lw_term_spline_length(const double *seg, size_t n, const double *blk);
double lw_term_bending(const lw_samples *s, const lw_quad *q);
double lw_term_potential(const lw_samples *s, const lw_quad *q, const lw_potential *f);
double lw_term_field(const lw_samples *s, const lw_quad *q, const lw_field *f, int axial);
double lw_term_boundary(const lw_samples *s, const lw_quad *q, const lw_boundary *b);
double lw_term_parametrisation(const lw_samples *s, const lw_quad *q);
double lw_term_load(const lw_samples *s, const double b[2]);

#ifdef __cplusplus
}
#endif

#endif
