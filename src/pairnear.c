/*
** pairnear.c -- the near field of the pair term (pairnear.h).
**
** lw_pair_segments_exact
** ----------------------
** T = double integral of |a'| |b'| / r by adaptive subdivision of the
** parameter square.  A piece of a cubic is again a cubic: its Bezier
** control points are r(t0), r(t0) + h r'(t0) / 3, r(t1) - h r'(t1) / 3,
** r(t1) (h = t1 - t0), and it lies in their convex hull, so in the circle
** about the chord's midpoint through the farthest of them.  A pair of pieces
** whose circles are more than SEP_RATIO times the larger radius apart takes
** the GAUSS_M x GAUSS_M product rule: 1/r is then analytic in a Bernstein
** ellipse of parameter rho >= 1 + SEP_RATIO + sqrt((1 + SEP_RATIO)^2 - 1)
** around each piece, and the rule's error is below rho^(-2 GAUSS_M) ~ 1e-10.
** Other pairs are split (the piece with the larger circle, at its middle)
** until both are shorter than LEAF_RATIO of the pair's size; such leaves are
** replaced by their chords and integrated exactly (lw_pair_segseg), an error
** of the order of the squared curvature times the leaf length squared.  The
** subdivision follows the curves into the points where they cross or touch
** (about log2(1 / LEAF_RATIO) levels) and along stretches where they run
** closer than their length (pieces about as long as the distance).  A
** decision of the test can flip with a small change of the curves; both
** sides are accurate to ~1e-10, so the integral moves by no more than that.
**
** The cutoff: (1/r - 1/rc)+ = 1/r - 1/rc + (1/rc - 1/r)+.  The first two
** parts are T - L_a L_b / rc; the last is bounded, vanishes where r < rc and
** has only a kink where r = rc, so a fixed 16 x 16 Gauss rule over the whole
** square takes it (accuracy ~ (element / rc)^2 of that part; fixed nodes keep
** it a continuous function of the curves).
*/
#include "linewise/pairnear.h"

#include <math.h>

/* A cubic in power form about a local origin: r(t) = c0 + c1 t + c2 t^2 + c3 t^3. */
typedef struct {
  double x[4], y[4];
} cubic;

static void cubic_from_bezier(const double b[8], double ox, double oy, cubic *c)
{
  double x0 = b[0] - ox, x1 = b[2] - ox, x2 = b[4] - ox, x3 = b[6] - ox;
  double y0 = b[1] - oy, y1 = b[3] - oy, y2 = b[5] - oy, y3 = b[7] - oy;
  c->x[0] = x0;
  c->x[1] = 3.0 * (x1 - x0);
  c->x[2] = 3.0 * (x0 - 2.0 * x1 + x2);
  c->x[3] = x3 - x0 + 3.0 * (x1 - x2);
  c->y[0] = y0;
  c->y[1] = 3.0 * (y1 - y0);
  c->y[2] = 3.0 * (y0 - 2.0 * y1 + y2);
  c->y[3] = y3 - y0 + 3.0 * (y1 - y2);
}

static inline void cubic_eval(const cubic *c, double t, double r[2], double d[2])
{
  r[0] = c->x[0] + t * (c->x[1] + t * (c->x[2] + t * c->x[3]));
  r[1] = c->y[0] + t * (c->y[1] + t * (c->y[2] + t * c->y[3]));
  d[0] = c->x[1] + t * (2.0 * c->x[2] + t * 3.0 * c->x[3]);
  d[1] = c->y[1] + t * (2.0 * c->y[2] + t * 3.0 * c->y[3]);
}

/* A piece [t0, t1] of a cubic: end points and derivatives, and its bounding
** circle (centre, radius). */
typedef struct {
  double t0, t1;
  double r0[2], d0[2], r1[2], d1[2];
  double cx, cy, rad;
} piece;

static void piece_bound(piece *p)
{
  double h3 = (p->t1 - p->t0) / 3.0;
  double cx = 0.5 * (p->r0[0] + p->r1[0]), cy = 0.5 * (p->r0[1] + p->r1[1]);
  double ex = p->r0[0] - cx, ey = p->r0[1] - cy;
  double rad2 = ex * ex + ey * ey;
  double ax = p->r0[0] + h3 * p->d0[0] - cx, ay = p->r0[1] + h3 * p->d0[1] - cy;
  double bx = p->r1[0] - h3 * p->d1[0] - cx, by = p->r1[1] - h3 * p->d1[1] - cy;
  double a2 = ax * ax + ay * ay, b2 = bx * bx + by * by;
  if (a2 > rad2) rad2 = a2;
  if (b2 > rad2) rad2 = b2;
  p->cx = cx;
  p->cy = cy;
  p->rad = sqrt(rad2);
}

static void piece_init(piece *p, const cubic *c, double t0, double t1)
{
  p->t0 = t0;
  p->t1 = t1;
  cubic_eval(c, t0, p->r0, p->d0);
  cubic_eval(c, t1, p->r1, p->d1);
  piece_bound(p);
}

static void piece_split(const piece *p, const cubic *c, piece *lo, piece *hi)
{
  double tm = 0.5 * (p->t0 + p->t1), rm[2], dm[2];
  cubic_eval(c, tm, rm, dm);
  *lo = *p;
  *hi = *p;
  lo->t1 = hi->t0 = tm;
  lo->r1[0] = hi->r0[0] = rm[0];
  lo->r1[1] = hi->r0[1] = rm[1];
  lo->d1[0] = hi->d0[0] = dm[0];
  lo->d1[1] = hi->d0[1] = dm[1];
  piece_bound(lo);
  piece_bound(hi);
}

#ifndef SEP_LO
#define SEP_LO 0.5
#endif
#ifndef SEP_HI
#define SEP_HI 1.0
#endif
#ifndef LEAF_RATIO
#define LEAF_RATIO 1e-2
#endif
#define STACK_MAX 128

/* Gauss-Legendre on [0, 1], 6 nodes (tabulated: the tree calls this per pair). */
#define GAUSS_M 6
static const double GM_S[GAUSS_M] = {0.033765242898423986, 0.16939530676686774, 0.38069040695840154,
                                     0.61930959304159846, 0.83060469323313226, 0.96623475710157601};
static const double GM_W[GAUSS_M] = {0.085662246189585173, 0.18038078652406930, 0.23395696728634552,
                                     0.23395696728634552, 0.18038078652406930, 0.085662246189585173};

/* Product rule of |a'| |b'| / r over two separated pieces. */
static double product_pieces(const cubic *ca, const piece *pa, const cubic *cb, const piece *pb)
{
  double ax[GAUSS_M], ay[GAUSS_M], aw[GAUSS_M], bx[GAUSS_M], by[GAUSS_M], bw[GAUSS_M];
  double ha = pa->t1 - pa->t0, hb = pb->t1 - pb->t0, r[2], d[2];
  for (int k = 0; k < GAUSS_M; k++) {
    cubic_eval(ca, pa->t0 + ha * GM_S[k], r, d);
    ax[k] = r[0];
    ay[k] = r[1];
    aw[k] = ha * GM_W[k] * sqrt(d[0] * d[0] + d[1] * d[1]);
    cubic_eval(cb, pb->t0 + hb * GM_S[k], r, d);
    bx[k] = r[0];
    by[k] = r[1];
    bw[k] = hb * GM_W[k] * sqrt(d[0] * d[0] + d[1] * d[1]);
  }
  double sum = 0.0;
  for (int i = 0; i < GAUSS_M; i++) {
    double s = 0.0;
    for (int j = 0; j < GAUSS_M; j++) {
      double dx = ax[i] - bx[j], dy = ay[i] - by[j];
      s += bw[j] / sqrt(dx * dx + dy * dy);
    }
    sum += aw[i] * s;
  }
  return sum;
}

/* 0 at x <= 0, 1 at x >= 1, C2 between. */
static inline double smooth_step(double x)
{
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  return x * x * x * (10.0 + x * (6.0 * x - 15.0));
}

/* A leaf: the chords, integrated exactly; their lengths stand in for the
** arcs (equal to O(leaf^2)).  Chords of curves that touch tangentially end
** to end can overlap by a rounding error, which the exact integral reads as
** +inf; the product rule's interior nodes keep such a leaf finite. */
static double leaf_value(const cubic *ca, const piece *pa, const cubic *cb, const piece *pb)
{
  double v = lw_pair_segseg(pa->r0, pa->r1, pb->r0, pb->r1);
  return v < INFINITY ? v : product_pieces(ca, pa, cb, pb);
}

/* T: the 1/r double integral by subdivision (see the file comment). */
static double inverse_distance(const cubic *ca, const cubic *cb)
{
  piece sa[STACK_MAX], sb[STACK_MAX];
  double share[STACK_MAX];
  int depth[STACK_MAX];
  piece_init(&sa[0], ca, 0.0, 1.0);
  piece_init(&sb[0], cb, 0.0, 1.0);
  share[0] = 1.0;
  depth[0] = 0;
  const double leaf = LEAF_RATIO * (sa[0].rad + sb[0].rad);
  double sum = 0.0;
  int top = 1;
  while (top > 0) {
    top--;
    piece pa = sa[top], pb = sb[top];
    double f = share[top];
    int d = depth[top];
    double dx = pa.cx - pb.cx, dy = pa.cy - pb.cy;
    double big = pa.rad > pb.rad ? pa.rad : pb.rad;
    double gap = sqrt(dx * dx + dy * dy) - pa.rad - pb.rad;
    /* accepted for the product rule: fully from SEP_HI, partly from SEP_LO */
    double w = smooth_step((gap - SEP_LO * big) / ((SEP_HI - SEP_LO) * big));
    if (!(big > 0.0)) w = 1.0;
    if (w > 0.0) sum += f * w * product_pieces(ca, &pa, cb, &pb);
    f *= 1.0 - w;
    if (f == 0.0) continue;
    /* a leaf: fully below the leaf size, partly below twice that */
    w = top + 2 > STACK_MAX ? 1.0 : smooth_step((2.0 * leaf - big) / leaf);
    if (w > 0.0) sum += f * w * leaf_value(ca, &pa, cb, &pb);
    f *= 1.0 - w;
    if (f == 0.0) continue;
    /* split A and B in turn: a choice by size would flip between two
    ** subtrees, whose values differ by their errors */
    if (d % 2 == 0) {
      piece_split(&pa, ca, &sa[top], &sa[top + 1]);
      sb[top] = sb[top + 1] = pb;
    } else {
      piece_split(&pb, cb, &sb[top], &sb[top + 1]);
      sa[top] = sa[top + 1] = pa;
    }
    share[top] = share[top + 1] = f;
    depth[top] = depth[top + 1] = d + 1;
    top += 2;
  }
  return sum;
}

/* Gauss-Legendre on [0, 1], 16 nodes, for the fixed rules. */
#define GAUSS_F 16
static const double GF_X[8] = {0.0950125098376374, 0.2816035507792589, 0.4580167776572274,
                               0.6178762444026438, 0.7554044083550030, 0.8656312023878318,
                               0.9445750230732326, 0.9894009349916499};
static const double GF_W[8] = {0.1894506104550685, 0.1826034150449236, 0.1691565193950025,
                               0.1495959888165767, 0.1246289712555339, 0.0951585116824928,
                               0.0622535239386479, 0.0271524594117541};

static void fixed_nodes(const cubic *c, double x[GAUSS_F], double y[GAUSS_F], double w[GAUSS_F])
{
  for (int k = 0; k < GAUSS_F; k++) {
    int h = k < 8 ? 7 - k : k - 8;
    double t = k < 8 ? 0.5 * (1.0 - GF_X[h]) : 0.5 * (1.0 + GF_X[h]), r[2], d[2];
    cubic_eval(c, t, r, d);
    x[k] = r[0];
    y[k] = r[1];
    w[k] = 0.5 * GF_W[h] * sqrt(d[0] * d[0] + d[1] * d[1]);
  }
}

/* - L_a L_b / rc + double integral of |a'| |b'| (1/rc - 1/r)+ (fixed rule). */
static double cutoff_part(const cubic *ca, const cubic *cb, double rc)
{
  double ax[GAUSS_F], ay[GAUSS_F], aw[GAUSS_F], bx[GAUSS_F], by[GAUSS_F], bw[GAUSS_F];
  fixed_nodes(ca, ax, ay, aw);
  fixed_nodes(cb, bx, by, bw);
  double inv = 1.0 / rc, rc2 = rc * rc, la = 0.0, lb = 0.0, sum = 0.0;
  for (int k = 0; k < GAUSS_F; k++) {
    la += aw[k];
    lb += bw[k];
  }
  for (int i = 0; i < GAUSS_F; i++) {
    double s = 0.0;
    for (int j = 0; j < GAUSS_F; j++) {
      double dx = ax[i] - bx[j], dy = ay[i] - by[j], r2 = dx * dx + dy * dy;
      if (r2 > rc2) s += bw[j] * (inv - 1.0 / sqrt(r2));
    }
    sum += aw[i] * s;
  }
  return sum - la * lb * inv;
}

double lw_pair_segments_exact(const double a[8], const double b[8], double cutoff)
{
  cubic ca, cb;
  /* a local origin keeps the power form's coefficients small */
  double ox = 0.25 * (a[0] + a[6] + b[0] + b[6]), oy = 0.25 * (a[1] + a[7] + b[1] + b[7]);
  cubic_from_bezier(a, ox, oy, &ca);
  cubic_from_bezier(b, ox, oy, &cb);
  double v = inverse_distance(&ca, &cb);
  if (cutoff > 0.0) v += cutoff_part(&ca, &cb, cutoff);
  return v;
}

/* 1 below half the radius, 0 from the radius on, C2 in between. */
static inline double near_weight(double u)
{
  if (u >= 1.0) return 0.0;
  if (u <= 0.5) return 1.0;
  double t = 2.0 * (1.0 - u);
  return t * t * t * (10.0 + t * (6.0 * t - 15.0));
}

/* 1 if a comes before b in the lexicographic order of the control points. */
static int bezier_before(const double a[8], const double b[8])
{
  for (int k = 0; k < 8; k++)
    if (a[k] != b[k]) return a[k] < b[k];
  return 1;
}

double lw_pair_near_correction(const double a[8], const lw_pair_sample *sa, const double b[8],
                               const lw_pair_sample *sb, int n, const lw_pair_ctx *ctx)
{
  /* one order for the two segments, so that the value is bitwise symmetric */
  if (!bezier_before(a, b)) {
    const double *t = a;
    const lw_pair_sample *u = sa;
    a = b;
    b = t;
    sa = sb;
    sb = u;
  }
  double W = 0.0, far = 0.0, near = 0.0;
  const double cut2 = ctx->cutoff2, inv = ctx->inv_cutoff;
  for (int i = 0; i < n; i++) {
    for (int j = 0; j < n; j++) {
      double dx = sa[i].x - sb[j].x, dy = sa[i].y - sb[j].y, r2 = dx * dx + dy * dy;
      double rho2 = lw_pair_near_radius2(ctx, sa[i].dl, sb[j].dl);
      if (r2 < rho2) {
        double w = near_weight(sqrt(r2 / rho2));
        if (w > W) W = w;
        if (r2 < cut2 && sa[i].dl != 0.0f && sb[j].dl != 0.0f)
          near += (double)sa[i].dl * (double)sb[j].dl * (1.0 / sqrt(r2) - inv);
      } else if (r2 < cut2) {
        far += (double)sa[i].dl * (double)sb[j].dl * (1.0 / sqrt(r2) - inv);
      }
    }
  }
  if (W == 0.0) return 0.0;
  double e = W * lw_pair_segments_exact(a, b, ctx->cutoff);
  if (W < 1.0) e += (1.0 - W) * (near + far);
  return e - far;
}
