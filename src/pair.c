/*
** pair.c -- the 1/r pair kernel and the exact segment-segment integral (pair.h).
**
** lw_pair_segseg
** --------------
** Put segment A on the x axis: a(s) = (s, 0), s in [0, La].  Segment B starts
** at (beta0, eta0) with unit direction (c, sn); orienting B so that c >= 0
** changes nothing (the integral ignores orientation) and keeps the lines'
** intersection O "in front of" both when they are nearly parallel.  With z and
** t the signed coordinates from O along A and B (sigma = |sn|),
**
**     G(z, t) = z asinh((t - z c) / (|z| sigma)) + t asinh((z - t c) / (|t| sigma))
**
** has d2G/dz dt = 1/|x - y|, so the integral is the corner sum
** G(z1,t1) - G(z0,t1) - G(z1,t0) + G(z0,t0).  (A term with z = 0 or t = 0
** is 0 in the limit.)  Written like this, each corner term is of size |z|,
** |t| times a log, and the terms cancel to the answer: for nearly parallel
** lines O is far away (|z| ~ distance / sigma) and the cancellation costs
** eps / sigma relative accuracy.  Two rewrites remove it:
**
**   same-side corners (z, t of one sign; G(-z,-t) = G(z,t), so take both > 0):
**   with h = z sigma and k = t sigma the distances of the two endpoints from
**   the other line, delta = t - z and tau = sigma / (1 + c) = tan(theta/2),
**
**       G = z (asinh a - asinh b) - delta asinh b,
**       a = delta/h + tau,  b = delta/k - tau,
**       (a - b)/sigma = delta^2/(h k) + 2/(1 + c)   (k - h = sigma delta),
**
**   so z (asinh a - asinh b) = h * [(asinh a - asinh b)/(a - b)] * (a - b)/sigma
**   is a product of well-conditioned factors, bounded by the corner's own
**   geometry (it tends to the endpoint distance sqrt(delta^2 + h^2) as the
**   lines become parallel).  With sigma = 0 exactly this is the parallel-line
**   formula, so parallel lines need no separate branch.  delta itself is
**   computed from endpoint differences (never from the far-away O):
**   t - z = beta_j - s_i + eta_j sn / (1 + c).
**
**   opposite-side corners (z, t of different signs, or one of them 0): with
**   c >= 0 the endpoints are at least sqrt(z^2 + t^2) apart, so |z|, |t| are
**   bounded by their own distance and the plain G is well conditioned.
**
** Every input to these formulas is derived from one set of numbers (La, Lb,
** beta0, eta0, c, sn), i.e. from one slightly rounded geometry, so the
** identities used above (k - h = sigma delta, ...) hold for it and the result
** is backward stable.  The remaining cancellation is the ordinary one of the
** four-corner sum, ~ (distance/length)^2 when the segments are far apart
** compared with their lengths; there a Gauss-Legendre rule over the shorter
** segment of the other one's exact potential is both accurate and stable
** (see FAR_RATIO).
**
** Collinear segments (sn = 0 and eta0 = 0) have G -> |u| log|u| summed over
** the endpoint offsets u, finite when disjoint, +inf when overlapping.
*/
#include "linewise/pair.h"

#include <float.h>
#include <math.h>

/* ---- the exact element integral ---------------------------------------- */

/* asinh(p / h) for h > 0 without overflow for |p| >> h. */
static double asinh_ratio(double p, double h)
{
  double ap = fabs(p);
  if (ap > 1e8 * h) {
    /* asinh x = log 2x + 1/(4x^2) - ...: the tail is below rounding here */
    double v = log(2.0 * ap) - log(h);
    return p < 0 ? -v : v;
  }
  return asinh(p / h);
}

/* (asinh a - asinh b) / (a - b) for a >= b; 1/sqrt(1+a^2) when a == b. */
static double asinh_slope(double a, double b)
{
  if (b < 0.0 && a <= 0.0) { /* mirror to the side where the formula is stable */
    double t = -b;
    b = -a;
    a = t;
  }
  double d = a - b;
  if (b >= 0.0) {
    /* asinh a - asinh b = asinh(X), X = (a - b)(a + b) / (a Sb + b Sa) */
    if (b > 1e8) {
      /* asinh a - asinh b = log(a/b) + O(1/b^2) */
      double y = d / b;
      return y > 1e-8 ? log1p(y) / d : (1.0 - 0.5 * y) / b;
    }
    double sa = sqrt(1.0 + a * a), sb = sqrt(1.0 + b * b);
    double den = a * sb + b * sa;
    if (!(den > 0.0)) return 1.0; /* a = b = 0 */
    double f = (a + b) / den;
    double X = d * f;
    double r = fabs(X) < 1e-5 ? 1.0 - X * X / 6.0 : asinh(X) / X;
    return r * f;
  }
  /* a > 0 > b: no cancellation */
  return (asinh(a) - asinh(b)) / d;
}

/* Upper bound of the ratio h/|delta| below which a same-side corner's
** distances are floored, so delta/h and delta^2/(h k) stay finite.  Only
** inputs closer than 1e-280 of the segment length are affected. */
#define TINY 1e-280

/* G at one corner.  si: the corner's position along A (0 or La); the B end
** is (bj, ej) in A's frame.  zeta: signed distance of the A end from line B
** (cross(w, a - b0)). */
static double corner(double si, double bj, double ej, double zeta,
                     double c, double sn, double sigma, double tau, double scale)
{
  int same = sn == 0.0 ? 1 : (zeta * ej < 0.0);
  if (same) {
    /* sign(t) = sign(ej * sn); for sn == 0 every corner counts as same-side
    ** and the sign is immaterial (G is even). */
    double delta = bj - si + ej * (sn / (1.0 + c));
    if (ej * sn < 0.0) delta = -delta;
    double h = fabs(zeta), k = fabs(ej);
    double floor_ = TINY * scale;
    if (h < floor_) h = floor_;
    if (k < floor_) k = floor_;
    double a = delta / h + tau, b = delta / k - tau;
    double m = delta * (delta / k) + 2.0 * h / (1.0 + c); /* h (a - b)/sigma */
    return asinh_slope(a, b) * m - delta * asinh(b);
  }
  /* opposite sides: plain G; z = -zeta/sn, t = ej/sn */
  double g = 0.0;
  if (zeta != 0.0) {
    double z = -zeta / sn;
    double p = (bj - si) * c + ej * sn; /* (b_j - a_i) . w */
    g += z * asinh_ratio(p, fabs(zeta));
  }
  if (ej != 0.0) {
    double t = ej / sn;
    double q = si - bj; /* (a_i - b_j) . u */
    g += t * asinh_ratio(q, fabs(ej));
  }
  return g;
}

static double xlogx(double x)
{
  x = fabs(x);
  return x > 0.0 ? x * log(x) : 0.0;
}

/* Potential of the segment (0,0)-(L,0) at (x, y): integral of 1/|p - q|. */
static double seg_potential(double L, double x, double y)
{
  double r0 = sqrt(x * x + y * y), r1 = sqrt((x - L) * (x - L) + y * y);
  double y2 = y * y;
  /* log((r0 + r1 + L) / (r0 + r1 - L)); the denominator is
  ** (r0 - x) + (r1 - (L - x)) with each bracket written without cancellation */
  double d0 = x <= 0.0 ? r0 - x : y2 / (r0 + x);
  double d1 = x >= L ? r1 - (L - x) : y2 / (r1 + (L - x));
  double den = d0 + d1;
  if (!(den > 0.0)) return INFINITY;
  /* (r0 + r1 + L) / den = 1 + 2L / den: log1p keeps far points accurate */
  return log1p(2.0 * L / den);
}

/* Gauss-Legendre nodes and weights on [-1, 1] (10 points, half listed). */
static const double GL10_X[5] = {0.1488743389816312108848260, 0.4333953941292471907992659,
                                 0.6794095682990244062343274, 0.8650633666889845107320967,
                                 0.9739065285171717200779640};
static const double GL10_W[5] = {0.2955242247147528701738930, 0.2692667193099963550912269,
                                 0.2190863625159820439955349, 0.1494513491505805931457763,
                                 0.0666713443086881375935688};

/* B farther than FAR_RATIO * Lb from A (Lb <= La) is integrated by 10-point
** Gauss-Legendre over B of A's exact potential: the potential is analytic
** within that distance of B, so the rule's error is below ~ (4 FAR_RATIO)^-20,
** while the corner sum would lose ~ (distance / length)^2 to cancellation. */
#define FAR_RATIO 3.0

/* A longer than SPLIT_RATIO * Lb is cut into the part near B and the two
** far parts: the corner sum on a long A loses ~ La / Lb to cancellation. */
#define SPLIT_RATIO 8.0

/*
** The integral in A's frame: A = [0, La] x {0}, B from (beta0, eta0) along
** the unit vector (c, sn), c >= 0, length Lb <= La.
*/
static double far_gl(double La, double Lb, double beta0, double eta0, double c, double sn)
{
  double mx = beta0 + 0.5 * Lb * c, my = eta0 + 0.5 * Lb * sn;
  double hx = 0.5 * Lb * c, hy = 0.5 * Lb * sn;
  double sum = 0.0;
  for (int k = 0; k < 5; k++) {
    double x = GL10_X[k];
    sum += GL10_W[k] * (seg_potential(La, mx + x * hx, my + x * hy) +
                        seg_potential(La, mx - x * hx, my - x * hy));
  }
  return 0.5 * Lb * sum;
}

/* Lower bound of the distance between the segments. */
static double gap_bound(double La, double beta0, double eta0, double beta1, double eta1)
{
  double d = 0.0;
  if ((eta0 > 0.0) == (eta1 > 0.0) && eta0 != 0.0 && eta1 != 0.0)
    d = fabs(eta0) < fabs(eta1) ? fabs(eta0) : fabs(eta1);
  double gap = beta0 > La ? beta0 - La : (beta1 < 0.0 ? -beta1 : 0.0);
  return gap > d ? gap : d;
}

static double corner_sum(double La, double Lb, double beta0, double eta0, double c, double sn)
{
  double beta1 = beta0 + Lb * c, eta1 = eta0 + Lb * sn;
  if (sn == 0.0 && eta0 == 0.0) {
    /* collinear: B = [beta0, beta1] on A's line, beta1 > beta0 */
    double lo = beta0 > 0.0 ? beta0 : 0.0, hi = beta1 < La ? beta1 : La;
    if (hi > lo) return INFINITY;
    return xlogx(La - beta0) + xlogx(beta1) - xlogx(La - beta1) - xlogx(beta0);
  }
  double sigma = fabs(sn), tau = sigma / (1.0 + c);
  double scale = La + Lb;
  /* zeta_i = cross(w, a_i - b0), the signed distance of A's ends from line B */
  double zeta0 = sn * beta0 - c * eta0, zeta1 = zeta0 - sn * La;
  double g11 = corner(La, beta1, eta1, zeta1, c, sn, sigma, tau, scale);
  double g01 = corner(0.0, beta1, eta1, zeta0, c, sn, sigma, tau, scale);
  double g10 = corner(La, beta0, eta0, zeta1, c, sn, sigma, tau, scale);
  double g00 = corner(0.0, beta0, eta0, zeta0, c, sn, sigma, tau, scale);
  double v = (g11 - g01) - (g10 - g00);
  /* the integral is positive; a negative v can only be rounding of a value
  ** negligible against the corner terms */
  return v > 0.0 ? v : 0.0;
}

static double segseg_frame(double La, double Lb, double beta0, double eta0, double c, double sn)
{
  double beta1 = beta0 + Lb * c, eta1 = eta0 + Lb * sn;
  if (gap_bound(La, beta0, eta0, beta1, eta1) > FAR_RATIO * Lb)
    return far_gl(La, Lb, beta0, eta0, c, sn);
  if (La > SPLIT_RATIO * Lb) {
    /* [lo, hi]: B's shadow on A widened by 4 Lb; the rest of A is far */
    double lo = beta0 - 4.0 * Lb, hi = beta1 + 4.0 * Lb; /* beta1 >= beta0 as c >= 0 */
    if (lo < 0.0) lo = 0.0;
    if (hi > La) hi = La;
    double v = 0.0;
    if (lo > 0.0) v += far_gl(lo, Lb, beta0, eta0, c, sn);
    if (hi < La) v += far_gl(La - hi, Lb, beta0 - hi, eta0, c, sn);
    if (hi > lo) v += corner_sum(hi - lo, Lb, beta0 - lo, eta0, c, sn);
    return v;
  }
  return corner_sum(La, Lb, beta0, eta0, c, sn);
}

double lw_pair_segseg(const double a0[2], const double a1[2],
                      const double b0[2], const double b1[2])
{
  double ux = a1[0] - a0[0], uy = a1[1] - a0[1];
  double wx = b1[0] - b0[0], wy = b1[1] - b0[1];
  double La = sqrt(ux * ux + uy * uy), Lb = sqrt(wx * wx + wy * wy);
  if (!(La > 0.0) || !(Lb > 0.0) || !isfinite(La) || !isfinite(Lb)) return 0.0;
  ux /= La; uy /= La;
  wx /= Lb; wy /= Lb;
  /* B in A's frame */
  double dx = b0[0] - a0[0], dy = b0[1] - a0[1];
  double beta0 = dx * ux + dy * uy, eta0 = ux * dy - uy * dx;
  double c = ux * wx + uy * wy, sn = ux * wy - uy * wx;
  if (!isfinite(beta0) || !isfinite(eta0)) return 0.0;
  if (c < 0.0) { /* reverse B */
    beta0 += Lb * c;
    eta0 += Lb * sn;
    c = -c;
    sn = -sn;
  }
  if (Lb > La) {
    /* the same geometry in B's frame: A starts at a0 - b0, direction (c, -sn) */
    double b = -beta0 * c - eta0 * sn, e = sn * beta0 - c * eta0;
    return segseg_frame(Lb, La, b, e, c, -sn);
  }
  return segseg_frame(La, Lb, beta0, eta0, c, sn);
}

/* ---- the kernel --------------------------------------------------------- */

void lw_pair_ctx_init(lw_pair_ctx *ctx, const lw_quad *q, double cutoff, double near)
{
  ctx->cutoff = cutoff > 0.0 ? cutoff : 0.0;
  ctx->inv_cutoff = cutoff > 0.0 ? 1.0 / cutoff : 0.0;
  ctx->near = near > 0.0 ? near : 0.0;
  for (int i = 0; i < LW_QUAD_MAX; i++) {
    ctx->elem_lo[i] = 0.0;
    ctx->elem_hi[i] = 0.0;
  }
  for (int i = 0; i < q->n; i++) {
    ctx->elem_lo[i] = q->s[i] - q->e[i];
    ctx->elem_hi[i] = q->e[i + 1] - q->s[i];
  }
}

double lw_pair_kernel(const lw_pair_sample *a, const lw_pair_sample *b, const lw_pair_ctx *ctx)
{
  double dx = a->x - b->x, dy = a->y - b->y;
  double r2 = dx * dx + dy * dy;
  if (ctx->cutoff > 0.0 && r2 >= ctx->cutoff * ctx->cutoff) return 0.0;
  double rn = ctx->near * (a->dl > b->dl ? a->dl : b->dl);
  if (r2 >= rn * rn) return a->dl * b->dl * (1.0 / sqrt(r2) - ctx->inv_cutoff);
  /* near field: the exact integral over the two tangent elements */
  double lo = ctx->elem_lo[a->q], hi = ctx->elem_hi[a->q];
  double a0[2] = {a->x - lo * a->dx, a->y - lo * a->dy};
  double a1[2] = {a->x + hi * a->dx, a->y + hi * a->dy};
  lo = ctx->elem_lo[b->q];
  hi = ctx->elem_hi[b->q];
  double b0[2] = {b->x - lo * b->dx, b->y - lo * b->dy};
  double b1[2] = {b->x + hi * b->dx, b->y + hi * b->dy};
  return lw_pair_segseg(a0, a1, b0, b1) - a->dl * b->dl * ctx->inv_cutoff;
}
