/*
** terms.h -- the energy terms as pure functions of a segment's samples.
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
**
** The term table's order is the order of trace.csv's and state.lw's energy
** columns; a new term goes at the end so older state files still read.
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

typedef enum {
  LW_TERM_STRAIN,
  LW_TERM_BENDING,
  LW_TERM_POTENTIAL,
  LW_TERM_FIELD,
  LW_TERM_PAIR,
  LW_TERM_BOUNDARY,
  LW_TERM_USER,
  LW_TERM_PARAM,
  LW_TERM_COUNT
} lw_term_id;

struct lw_scene;

/* A term that is a sum over segments of a function of that segment's
** samples has a `segment` function (coefficient applied); strain and pair
** are not of that shape and have NULL there: the model treats them itself. */
typedef struct {
  lw_term_id id;
  const char *name;   /* as in scene files, traces and summaries */
  double (*segment)(const lw_samples *s, const struct lw_scene *sc);
} lw_term_type;

extern const lw_term_type lw_term_types[LW_TERM_COUNT];

double lw_term_strain(double length, double rest_length);
double lw_term_bending(const lw_samples *s, const lw_quad *q);
double lw_term_potential(const lw_samples *s, const lw_quad *q, const lw_potential *f);
double lw_term_field(const lw_samples *s, const lw_quad *q, const lw_field *f, int axial);
double lw_term_boundary(const lw_samples *s, const lw_quad *q, const lw_boundary *b);
double lw_term_parametrisation(const lw_samples *s, const lw_quad *q);

#endif
