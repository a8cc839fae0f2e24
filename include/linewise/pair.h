/*
** pair.h -- the 1/r repulsion between quadrature samples of different splines.
**
**   E_pair = C * sum over pairs of different splines of
**            double integral |r0'| |r1'| / |r0 - r1| ds1 ds0
**
** Far field: each sample pair (i, j) contributes dl_i dl_j / r_ij, the Gauss
** product rule, with dl = w_q |r'_q|.
**
** Near field: the double integral is finite where curves touch or cross, but
** the product rule is not accurate there (and not finite if two samples
** coincide).  Each sample owns a straight piece of its curve (its element):
** the tangent line at the node, from parameter e_q to e_{q+1} (quad.h), i.e.
** from r - (s_q - e_q) r' to r + (e_{q+1} - s_q) r'.  Elements of a straight
** spline tile it exactly.  With dm = max(dl_i, dl_j) and r the node distance:
**   r < near dm          the exact double integral of 1/r over the two
**                        elements (lw_pair_segseg), and always where the
**                        elements can touch (r < 1.25 dm);
**   r < 6 near dm        a 2x2 Gauss-Legendre rule over the two elements,
**                        blended smoothly into the product rule over the
**                        outer quarter of that range;
**   beyond               the product rule dl_i dl_j / r.
** The middle zone is there because a node is not the centre of its element:
** the product rule's error on one element pair has a first-order part that
** the Gauss rule cancels only over whole segments, so switching to element
** integrals at some radius leaves an error ~ 1/radius^2 of the near-field
** share of the energy.  The cheap element rule moves that radius out; the
** exact integral is needed only where elements can touch.
** At near = 1.5 (recommended) the energy of straight lines, parallel or
** crossing, is within ~6e-4 relative for 4 to 16 nodes (tools/pair-accuracy.c);
** curves that touch tangentially carry an extra O(dl) error from the straight
** elements (~3e-3 for quarter circles of 4 segments at 8 nodes).  near = 0
** turns the near field off (product rule everywhere).
**
** Cutoff: with rc > 0 the kernel is shifted, 1/r - 1/rc for r < rc and 0
** beyond, so the energy is continuous at the cutoff (the near-field zones
** subtract dl_i dl_j / rc, and the element zone ends by rc); rc = 0 means no
** cutoff.  A cutoff inside the exact zone (rc < near dm) leaves a jump there.
*/
#ifndef LINEWISE_PAIR_H
#define LINEWISE_PAIR_H

#include <stdint.h>

#include <math.h>

#include "linewise/quad.h"

/* One sample as the pair term (and the cell grid) sees it: 32 bytes, since
** the walk over neighbours is bound by memory traffic.  Positions stay double
** (a page of 1e6 mm must still resolve 1e-6 mm); the derivative and weight
** are float, relative 6e-8, far below the quadrature's own error.  The
** energy is defined by these stored values, so every sum (incremental or
** from scratch) sees the same rounding. */
#define LW_PAIR_MAX_SPLINES (1u << 26)
typedef struct {
  double x, y;         /* r at the node, mm */
  float dx, dy;        /* r' at the node, mm per unit s */
  float dl;            /* w_q |r'_q|, mm */
  uint32_t spline : 26; /* owning spline (pairs within a spline do not count) */
  uint32_t q : 6;      /* node index within its segment (LW_QUAD_MAX = 64) */
} lw_pair_sample;

typedef struct {
  double cutoff;        /* rc, mm; 0 = none */
  double inv_cutoff;    /* 1/rc, or 0 */
  double near;          /* near-field radius in element lengths; 0 = off */
  double cutoff2;       /* rc^2, or +inf without a cutoff */
  double zone_cap;      /* rc, or +inf: the element zone ends by the cutoff */
  double zone_outer;    /* outer radius of the element zone / dm; 0 = no near field */
  double zone_exact;    /* outer radius of the exact zone / dm */
  double near_scale;    /* pairs with r < near_scale * dm are near (walk.h); 0 = none.
                        ** Glue until the near-field rewrite: the radius inside which
                        ** lw_pair_kernel is not the product rule (zone_outer). */
  double elem_lo[LW_QUAD_MAX]; /* s_q - e_q: element start before the node, in s */
  double elem_hi[LW_QUAD_MAX]; /* e_{q+1} - s_q: element end after the node, in s */
} lw_pair_ctx;

void lw_pair_ctx_init(lw_pair_ctx *ctx, const lw_quad *q, double cutoff, double near);

/* Exact double integral of 1/|x - y| over x on segment [a0, a1] and y on
** [b0, b1] (arc length measure, mm).  Finite for crossing or touching
** segments; +infinity only where they overlap collinearly over a positive
** length; 0 if either has zero length. */
double lw_pair_segseg(const double a0[2], const double a1[2],
                      const double b0[2], const double b1[2]);

/* The element and exact zones of the kernel (r2: squared node distance, ro:
** outer radius of the element zone); lw_pair_kernel calls it. */
double lw_pair_kernel_near(const lw_pair_sample *a, const lw_pair_sample *b, const lw_pair_ctx *ctx,
                           double r2, double ro);

/* The kernel of one sample pair (no coefficient C), cutoff and near field
** applied.  The caller skips pairs of the same spline.  The neighbour walk
** (walk.h) evaluates the far field itself, vectorised, and calls this for
** the pairs it reports as near. */
static inline double lw_pair_kernel(const lw_pair_sample *a, const lw_pair_sample *b, const lw_pair_ctx *ctx)
{
  double dx = a->x - b->x, dy = a->y - b->y;
  double r2 = dx * dx + dy * dy;
  if (r2 >= ctx->cutoff2) return 0.0;
  /* a sample without length weighs nothing, even at r = 0 (0 * inf) */
  if (a->dl == 0.0f || b->dl == 0.0f) return 0.0;
  double dm = a->dl > b->dl ? a->dl : b->dl;
  double ro = ctx->zone_outer * dm;
  if (ro > ctx->zone_cap) ro = ctx->zone_cap;
  if (r2 >= ro * ro) return (double)a->dl * (double)b->dl * (1.0 / sqrt(r2) - ctx->inv_cutoff);
  return lw_pair_kernel_near(a, b, ctx, r2, ro);
}

#endif
