/*
** spline.h -- storage of all splines of a scene and their evaluation.
**
** Spline i has n_i cubic Bezier segments and n_i + 1 nodes; node k holds the
** point p_k and the vector v_k (mm).  All nodes of all splines live in one
** contiguous array (the seed's Q), spline after spline, so segment m of
** spline i reads the 8 doubles node[first[i] + m] and node[first[i] + m + 1].
**
** Segments are numbered globally too: segment g belongs to spline
** seg_spline[g] and starts at node g + seg_spline[g] (each spline has one more
** node than segments).
*/
#ifndef LINEWISE_SPLINE_H
#define LINEWISE_SPLINE_H

#include <stddef.h>
#include <stdint.h>

#include "linewise/error.h"
#include "linewise/quad.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  double px, py; /* point p_k, mm */
  double vx, vy; /* vector v_k, mm (r'(node) = 3 v_k) */
} lw_node;

typedef struct {
  size_t n_splines;
  size_t n_nodes;
  size_t n_segments;
  lw_node *node;          /* n_nodes, contiguous */
  size_t *first;          /* n_splines + 1 node offsets; first[n_splines] = n_nodes */
  uint32_t *seg_spline;   /* n_segments: the spline of each segment */
  double *rest_length;    /* n_splines: L0, mm (> 0) */
  uint8_t *layer;         /* n_splines: each spline's layer (layers.h) where splines are
                             born and die in layers, or NULL: the index rule gives it */
  size_t cap_nodes;       /* room in node and seg_spline (lw_splines_append grows it) */
  size_t cap_splines;     /* room in rest_length, layer, and first (plus one) */
} lw_splines;

/* Allocates n_splines splines with segments[i] >= 1 segments each; nodes are
** zeroed and rest lengths set to 1.  NULL and err set on failure. */
lw_splines *lw_splines_new(size_t n_splines, const size_t *segments, lw_error *err);
void lw_splines_free(lw_splines *sp);

/* A deep copy (NULL on allocation failure). */
lw_splines *lw_splines_clone(const lw_splines *sp);

/* Renumbers sp in place: its spline k becomes what spline order[k] was (a
** permutation of 0..n_splines-1), nodes and rest length with it.  The
** arrays are rebuilt, so pointers into them go stale; sp itself stays.
** LW_ENOMEM leaves sp as it was. */
lw_status lw_splines_permute(lw_splines *sp, const size_t *order, lw_error *err);

/* Appends a spline of the n_new >= 2 nodes `nodes`, rest length `rest`
** and layer `layer` (not read when sp->layer is NULL): amortised O(n_new)
** (trans-dimensional moves, model.h and slots.h).  LW_ENOMEM leaves sp as
** it was. */
lw_status lw_splines_append(lw_splines *sp, const lw_node *nodes, size_t n_new, double rest, int layer);

/* Gives sp a layer array (zeroed) if it has none.  LW_ENOMEM: none. */
lw_status lw_splines_layers_alloc(lw_splines *sp);

/* Room for more_nodes more nodes in more_splines more splines, so that
** the appends that follow cannot fail.  LW_ENOMEM leaves sp as it was
** (only larger). */
lw_status lw_splines_reserve(lw_splines *sp, size_t more_nodes, size_t more_splines);

/* Removes the splines i with dead[i] != 0, in place: the others keep their
** order and move down over the holes (the ghost slots of trans-dimensional
** storage, slots.h).  O(nodes), no allocation. */
void lw_splines_compact(lw_splines *sp, const unsigned char *dead);

static inline size_t lw_splines_segments(const lw_splines *sp, size_t i)
{
  return sp->first[i + 1] - sp->first[i] - 1;
}

/* First node of global segment g. */
static inline size_t lw_segment_node(const lw_splines *sp, size_t g)
{
  return g + sp->seg_spline[g];
}

/* Global index of segment m of spline i. */
static inline size_t lw_segment_index(const lw_splines *sp, size_t i, size_t m)
{
  return sp->first[i] - i + m;
}

/* The Bezier control points b0 b1 b2 b3 of the segment from node a to node
** b, as x0 y0 x1 y1 x2 y2 x3 y3 (mm): p_a, p_a + v_a, p_b - v_b, p_b. */
static inline void lw_segment_bezier(const lw_node *a, const lw_node *c, double b[8])
{
  b[0] = a->px;
  b[1] = a->py;
  b[2] = a->px + a->vx;
  b[3] = a->py + a->vy;
  b[4] = c->px - c->vx;
  b[5] = c->py - c->vy;
  b[6] = c->px;
  b[7] = c->py;
}

/* The Bezier control points of segment m of spline i (as above). */
static inline void lw_splines_bezier(const lw_splines *sp, size_t i, size_t m, double b[8])
{
  const lw_node *a = &sp->node[sp->first[i] + m];
  lw_segment_bezier(a, a + 1, b);
}

/* 1 if every control point of spline i equals its first point: the curve is
** then a single point, which drawings leave out (a plotter would only dab
** the paper).  The Bernstein polynomials are independent, so any other set
** of control points moves. */
int lw_splines_is_point(const lw_splines *sp, size_t i);

/* r, r', r'' at parameter s in [0,1] of the segment from node a to node b;
** any output may be NULL. */
void lw_segment_eval(const lw_node *a, const lw_node *b, double s,
                     double r[2], double d1[2], double d2[2]);

/* The samples of one segment at the quadrature nodes: everything an energy
** term needs, so terms are pure functions of this struct. */
typedef struct {
  int n;                     /* nodes */
  double x[LW_QUAD_MAX], y[LW_QUAD_MAX];     /* r, mm */
  double dx[LW_QUAD_MAX], dy[LW_QUAD_MAX];   /* r', mm per unit s */
  double ddx[LW_QUAD_MAX], ddy[LW_QUAD_MAX]; /* r'', mm per unit s^2 */
  double speed[LW_QUAD_MAX];                 /* |r'| */
  double dl[LW_QUAD_MAX];                    /* w_q |r'|: length element, mm */
  double length;                             /* sum of dl, mm */
  double end_x[2], end_y[2];                 /* r(0) and r(1): the nodes, which no
                                                Gauss node reaches (boundary term) */
  double hand_x[2], hand_y[2];               /* the inner control points p_a + v_a and
                                                p_b - v_b: with the ends they bound the
                                                curve (the boundary's clearance) */
} lw_samples;

void lw_segment_sample(const lw_quad *q, const lw_node *a, const lw_node *b, lw_samples *out);

/* What a study reads off spline i (the observables of a trace, system.h):
** its length by the rule q, the squared distance between its ends, its
** squared radius of gyration along the contour, 1/L integral |r - r_cm|^2 dl
** by the same rule, and the cosine of the angle between its end tangents
** v_0 and v_n (0 where either is zero: no direction to compare). */
typedef struct {
  double length, end2, rg2, end_cos;
} lw_spline_shape;

void lw_spline_shape_of(const lw_splines *sp, size_t i, const lw_quad *q, lw_spline_shape *out);

/* The moments behind a shape, summed sample by sample (x, y about a fixed
** point of the curve, where the page's offset cannot cancel; dl the
** sample's length element), then lw_shape_finish with the far end (ex, ey)
** relative to that point and the end tangents t0, t1 (any lengths).  For
** curves of other systems too (the D-NURBS curve). */
typedef struct {
  double len, mx, my, m2;
} lw_arc_moments;

static inline void lw_arc_moments_add(lw_arc_moments *m, double x, double y, double dl)
{
  m->len += dl;
  m->mx += x * dl;
  m->my += y * dl;
  m->m2 += (x * x + y * y) * dl;
}

void lw_shape_finish(const lw_arc_moments *m, double ex, double ey, const double t0[2], const double t1[2],
                     lw_spline_shape *out);

/*
** Regularity: the hodograph r'(t) of a cubic segment is the quadratic Bezier
** with control points h0 = 3 v_a, h1 = 3 (b2 - b1), h2 = 3 v_b.  Where
** |r'| nearly stops the curvature is huge between quadrature nodes and a
** fixed rule misses the bending there, so the model forbids segments whose
** minimum speed falls below energy.min_speed times their mean speed (the
** segment length: the parameter runs over [0, 1]).  docs/NUMERICS.md has the
** derivation, docs/ACCURACY.md the table the default comes from.
*/

/* The exact minimum of |r'(t)| over t in [0, 1], mm per unit t: with
** h(t) = A + 2 B t + C t^2 the stationary points of |h|^2 solve the cubic
** (C.C) t^3 + 3 (B.C) t^2 + (2 B.B + A.C) t + A.B = 0 (GSL's polynomial
** solvers, roots polished by Newton); the minimum over its roots in [0, 1]
** and the two ends.  Not finite if a coordinate is not. */
double lw_segment_min_speed(const lw_node *a, const lw_node *b);

/* How far the bending integrand (x'y'' - x''y')^2 / |r'|^5 stays analytic
** around [0, 1]: its singularities are the complex zeros of |r'(t)|^2, the
** roots of the complex quadratic h_x(t) + i h_y(t) (and their conjugates).
** Returns the parameter rho >= 1 of the Bernstein ellipse (foci 0 and 1,
** semi-axes summing to rho / 2) through the nearest one: Gauss-Legendre with
** n nodes then errs by O(rho^-2n) (docs/NUMERICS.md).  1 where |r'| = 0 on
** [0, 1] (a cusp), +inf where |r'| is constant and never 0.  NaN for
** non-finite input. */
double lw_segment_rho(const lw_node *a, const lw_node *b);

/* Both tests with one hodograph: 1 if min |r'| >= min_speed (mm per unit t;
** 0 = no test) and lw_segment_rho >= rho (<= 1 = no test).  Each first tries
** a cheap exact bound and solves only when that is in doubt: |r'|^2 is a
** quartic whose Bernstein coefficients bound it from below; the ellipse rho
** lies in the disc |t - 1/2| <= (rho + 1/rho) / 4, where Taylor's bound at
** t = 1/2 keeps |h_x + i h_y| away from 0.  0 for non-finite input. */
int lw_segment_check(const lw_node *a, const lw_node *b, double min_speed, double rho);

/* 1 if no two consecutive nodes of the rule q lie more than gap_max (mm)
** apart on the segment from a to b (chords): the pair term's guarantee
** that a line crossing the segment passes within gap_max of one of its
** samples (docs/NUMERICS.md, "Regular segments").  First the bound
** (largest node spacing) x (largest speed), the speed bounded by the
** Bernstein coefficients of |r'|^2; the chords only where that is in
** doubt.  0 for non-finite input. */
int lw_segment_gaps_within(const lw_quad *q, const lw_node *a, const lw_node *b, double gap_max);

/* The widest space between consecutive nodes of q on the segment (chords,
** mm): what lw_segment_gaps_within compares. */
double lw_segment_widest_gap(const lw_quad *q, const lw_node *a, const lw_node *b);

/* 1 if every coordinate is finite. */
int lw_splines_finite(const lw_splines *sp);

#ifdef __cplusplus
}
#endif

#endif
