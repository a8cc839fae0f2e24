/*
** pair.c -- the 1/r pair kernel and the exact segment-segment integral (pair.h).
**
** lw_pair_segseg
** --------------
** Put segment A on the x axis, a(s) = (s, 0), s in [0, La].  Segment B starts
** at (beta0, eta0) with unit direction (c, sn); B is oriented so that c >= 0
** (the integral ignores orientation), which puts the lines' intersection O
** "in front of" both when they are nearly parallel.  With z and t the signed
** coordinates from O along A and B, sigma = |sn|,
**
**     G(z, t) = z asinh((t - z c) / (|z| sigma)) + t asinh((z - t c) / (|t| sigma))
**
** has d2G/dz dt = 1/|x - y|, so the integral is the corner sum
** G(z1,t1) - G(z0,t1) - G(z1,t0) + G(z0,t0); a term with z = 0 or t = 0 is
** 0 in the limit.  Evaluated as written, each corner term is |z| or |t| times
** a log and the four cancel down to the answer; for nearly parallel lines O
** is far away (|z| ~ distance / sigma) and the cancellation costs eps / sigma
** of relative accuracy.  Per corner, with R the distance of its two endpoints,
** p = (b_j - a_i).w, q = (a_i - b_j).u, h = |z| sigma and k = |t| sigma the
** endpoints' distances from the other line (G = z asinh(p/h) + t asinh(q/k)):
**
**   same side (z, t of one sign; G is even, so take both > 0): with
**   delta = t - z, G = z S + delta asinh(q/k), S = asinh(p/h) + asinh(q/k),
**   and (R + p)(R + q) / (h k) = 1 + X where
**       X = [sigma^2 delta^2 + 2 h k (1 - c) + sigma R (h + k)] / ((1 + c) h k)
**   has no cancellation (every term >= 0), so
**       z S = h * [log1p(X) / X] * [X / sigma]
**   keeps full relative accuracy however far away O is; X / sigma contains no
**   1/sigma ((1 - c)/sigma = sigma/(1 + c)).  z S tends to R as the lines
**   become parallel, and sigma = 0 gives the parallel-line formula itself.
**   delta comes from endpoint differences, never from O:
**   t - z = beta_j - s_i + eta_j sn / (1 + c).
**
**   opposite sides (z, t of different signs, or one of them 0): with c >= 0
**   the endpoints are at least sqrt(z^2 + t^2) apart, so |z|, |t| <= R and the
**   plain G is well conditioned.
**
** All these inputs derive from one set of numbers (La, Lb, beta0, eta0, c, sn),
** one slightly rounded geometry, so the identities used (k - h = sigma delta,
** ...) hold for it and the result is backward stable.  The cancellation left
** is that of the four-corner sum itself, ~ (distance / length)^2 for segments
** far apart and ~ La / Lb for very unequal lengths; FAR_RATIO and SPLIT_RATIO
** route those cases to a Gauss-Legendre rule of the exact potential, which is
** accurate there.  Measured against 40-digit references (mpmath): 1e-15 to
** 3e-14 relative over crossing, skew, parallel, near-parallel (sigma from
** 1e-12 to 1), collinear and far-apart configurations; endpoint-touching
** configurations reach 3e-14 because the integral itself is sensitive there
** (moving an endpoint by e changes it by ~ e log e).
**
** Collinear segments: G -> |u| log|u| summed over the endpoint offsets u,
** finite when disjoint (or meeting end to end), +inf when overlapping.
*/
#include "linewise/pair.h"

#include <float.h>
#include <math.h>

/* ---- the exact element integral ---------------------------------------- */

/* log((|x| + R) / d) * sign(x) = asinh(x / d) for R = sqrt(x^2 + d^2), d > 0;
** the log form is free of overflow and costs one log. */
static double asinh_r(double x, double R, double d)
{
  if (x == 0.0) return 0.0; /* also where R = 0: coincident corner points */
  double v = log((fabs(x) + R) / d);
  return x < 0.0 ? -v : v;
}

/* Same-side corner distances below TINY * (La + Lb) are raised to it so that
** R / h and delta^2 / (h k) stay finite; only inputs closer than 1e-140 of
** the segment length to the other line are affected. */
#define TINY 1e-140

/*
** G at one corner.  si: the corner's position along A (0 or La); the B end is
** (bj, ej) in A's frame; zeta: signed distance of the A end from line B,
** cross(w, a_i - b0).  With R the corner's endpoint distance,
** p = (b_j - a_i).w, q = (a_i - b_j).u, h = |zeta|, k = |ej|:
**     G = z asinh(p/h) + t asinh(q/k).
** Same side (z, t > 0 after the even flip): with delta = t - z,
**     G = z S + delta asinh(q/k),   S = asinh(p/h) + asinh(q/k),
** and (R + p)(R + q) / (h k) = 1 + X with
**     X = [sigma^2 delta^2 + 2 h k (1 - c) + sigma R (h + k)] / ((1 + c) h k),
** every term >= 0, so z S = h log1p(X)/X * X/sigma keeps full relative
** accuracy however far O is; X/sigma has no 1/sigma in it
** ((1 - c)/sigma = tau = sigma/(1 + c)).
*/
static double corner(double si, double bj, double ej, double zeta, double c, double sn,
                     double sigma, double tau, double inv1c, double floor_)
{
  double dx = bj - si;
  double R = sqrt(dx * dx + ej * ej);
  if (sn == 0.0 || zeta * ej < 0.0) {
    /* sign(t) = sign(ej sn); for sn == 0 every corner counts as same-side and
    ** the sign is immaterial (G is even) */
    double delta = dx + ej * (sn * inv1c), q = -dx;
    if (ej * sn < 0.0) {
      delta = -delta;
      q = -q;
    }
    double h = fabs(zeta), k = fabs(ej);
    if (h < floor_) h = floor_;
    if (k < floor_) k = floor_;
    double ih = 1.0 / h, ik = 1.0 / k;
    double xs = (sigma * delta * delta * ih * ik + 2.0 * tau + R * (ih + ik)) * inv1c; /* X / sigma */
    double X = sigma * xs;
    /* log1p(X)/X; log(1 + X) is as accurate for X >= 0.5 and much cheaper */
    double l = X >= 0.5 ? log(1.0 + X) / X : (X > 1e-8 ? log1p(X) / X : 1.0 - 0.5 * X);
    double g = h * l * xs;
    if (q != 0.0) {
      double v = log((fabs(q) + R) * ik); /* asinh(|q| / k) */
      g += q < 0.0 ? -delta * v : delta * v;
    }
    return g;
  }
  /* opposite sides: plain G with z = -zeta/sn, t = ej/sn (|z|, |t| <= R) */
  double g = 0.0, isn = 1.0 / sn;
  if (zeta != 0.0) g -= zeta * isn * asinh_r(dx * c + ej * sn, R, fabs(zeta));
  if (ej != 0.0) g += ej * isn * asinh_r(-dx, R, fabs(ej));
  return g;
}

static double xlogx(double x)
{
  x = fabs(x);
  return x > 0.0 ? x * log(x) : 0.0;
}

double lw_pair_seg_potential(double L, double x, double y)
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
    sum += GL10_W[k] * (lw_pair_seg_potential(La, mx + x * hx, my + x * hy) +
                        lw_pair_seg_potential(La, mx - x * hx, my - x * hy));
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
  /* Collinear within the rounding of the frame (eta0 is a cross product of
  ** rounded differences): B = [beta0, beta1] on A's line, beta1 > beta0.  An
  ** overlap within that rounding counts as touching, so segments that meet
  ** end to end stay finite and identical ones are +inf whatever the
  ** rounding. */
  double tol = 32.0 * DBL_EPSILON * (fabs(beta0) + fabs(eta0) + La + Lb);
  if (fabs(eta0) <= tol && fabs(eta1) <= tol) {
    double lo = beta0 > 0.0 ? beta0 : 0.0, hi = beta1 < La ? beta1 : La;
    if (hi - lo > tol) return INFINITY;
    return xlogx(La - beta0) + xlogx(beta1) - xlogx(La - beta1) - xlogx(beta0);
  }
  double inv1c = 1.0 / (1.0 + c), sigma = fabs(sn), tau = sigma * inv1c;
  double fl = TINY * (La + Lb);
  /* zeta_i = cross(w, a_i - b0), the signed distance of A's ends from line B */
  double zeta0 = sn * beta0 - c * eta0, zeta1 = zeta0 - sn * La;
  double g11 = corner(La, beta1, eta1, zeta1, c, sn, sigma, tau, inv1c, fl);
  double g01 = corner(0.0, beta1, eta1, zeta0, c, sn, sigma, tau, inv1c, fl);
  double g10 = corner(La, beta0, eta0, zeta1, c, sn, sigma, tau, inv1c, fl);
  double g00 = corner(0.0, beta0, eta0, zeta0, c, sn, sigma, tau, inv1c, fl);
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

/* ---- the context ------------------------------------------------------- */

void lw_pair_ctx_init(lw_pair_ctx *ctx, double cutoff, double near)
{
  ctx->cutoff = cutoff > 0.0 ? cutoff : 0.0;
  ctx->inv_cutoff = cutoff > 0.0 ? 1.0 / cutoff : 0.0;
  ctx->cutoff2 = cutoff > 0.0 ? cutoff * cutoff : INFINITY;
  ctx->near_scale = near > 0.0 ? near : 0.0;
}
