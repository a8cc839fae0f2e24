/*
** pairgrad.c -- the gradient of the pair term (gradient.h, pairgrad.h).
**
** The pair energy as model.c computes it: the far sum over sample pairs of
** different splines, dl_i dl_j k(r_ij), and for each near segment pair the
** blend E_AB = (1 - W) P_AB + W X_AB in place of its product-rule terms
** (pairnear.h).  Its derivative, from scratch in O(samples + near pairs):
**
**   far pairs      the kernel's derivative at each sample, and through
**                  dl = w_q |r'_q| at r'_q;
**   near pairs     dE_AB = (1 - W) dP_AB + (X_AB - P_AB) dW + W dX_AB, with
**                  dW that of the pair that sets the maximum;
**   X_AB           reverse mode through lw_pair_segments_exact: every
**                  quantity it computes is a value and a tape node (a
**                  "jet"), taken step by step through the same branches,
**                  blends, subdivision and closest points, and the exact
**                  segment-segment integrals of its leaves by
**                  lw_pair_segseg_grad; one sweep back gives the partials
**                  by the control points of A and B.
**
** The samples' weights are stored as float (pair.h); the derivative is that
** of the formula with the weights exact, whose float rounding is a step
** function of zero derivative.  Kinks the energy has (derivative
** discontinuous, docs/NUMERICS.md): the cutoff at r = rc, the largest of the
** near weights, the bounding circles and distances the subdivision decides
** with (maxima and minima), and the closest points where they jump.
*/
#include "linewise/pairgrad.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/gradient.h"
#include "linewise/grid.h"
#include "linewise/pairnear.h"
#include "linewise/terms.h"
#include "linewise/vec2.h"

/* ---- the segment-segment integral ----------------------------------------- */

static double dot2(const double a[2], const double b[2]) { return a[0] * b[0] + a[1] * b[1]; }
static double cross2(const double a[2], const double b[2]) { return a[0] * b[1] - a[1] * b[0]; }

/* The potential of segment [p0, p1] at x. */
static double potential(const double p0[2], const double p1[2], const double x[2])
{
  double u[2] = {p1[0] - p0[0], p1[1] - p0[1]}, L = sqrt(dot2(u, u));
  if (!(L > 0.0)) return 0.0;
  u[0] /= L;
  u[1] /= L;
  double d[2] = {x[0] - p0[0], x[1] - p0[1]};
  return lw_pair_seg_potential(L, dot2(d, u), cross2(u, d));
}

/* Below this sine of their angle two segments are taken as parallel. */
#define PARALLEL_SINE 1e-9

/*
** dI/dalpha for B parallel to A and rotated about b0: A = [0, La] on the x
** axis, B from (beta0, eta0) along +x.  -(1/eta0) times the integral over B
** of t [(La - X)/R(La - X) + X/R(X)], X = beta0 + t, R(x) = sqrt(x^2 +
** eta0^2), in closed form (docs/NUMERICS.md).  0 for collinear segments
** (the integral is even in alpha there).
*/
static double parallel_torque(double La, double Lb, double beta0, double eta0)
{
  if (eta0 == 0.0) return 0.0;
  const double e2 = eta0 * eta0, ae = fabs(eta0);
#define R_(x) sqrt((x) * (x) + e2)
#define K2_(x) (0.5 * ((x) * R_(x) - e2 * asinh((x) / ae)))
  double X0 = beta0, X1 = beta0 + Lb, c0 = La - beta0, Y0 = c0, Y1 = c0 - Lb;
  double part1 = (K2_(X1) - beta0 * R_(X1)) - (K2_(X0) - beta0 * R_(X0));
  double part2 = (c0 * R_(Y0) - K2_(Y0)) - (c0 * R_(Y1) - K2_(Y1));
#undef R_
#undef K2_
  return -(part1 + part2) / eta0;
}

/*
** The derivative of I = lw_pair_segseg(a0, a1, b0, b1) with respect to b0
** and b1 (docs/NUMERICS.md): along B the potentials of A at its ends; across
** B the sum S_b of the two from translation or scaling invariance (whichever
** divides by the larger number), and the rotation about the lines' crossing
** O, dI/dtheta = (R11 - R01 - R10 + R00) / sin(theta), for b1's share.
*/
static void segseg_grad_b(const double a0[2], const double a1[2], const double b0[2], const double b1[2],
                          double I, double gb0[2], double gb1[2])
{
  double u[2] = {a1[0] - a0[0], a1[1] - a0[1]}, w[2] = {b1[0] - b0[0], b1[1] - b0[1]};
  double La = sqrt(dot2(u, u)), Lb = sqrt(dot2(w, w));
  u[0] /= La;
  u[1] /= La;
  w[0] /= Lb;
  w[1] /= Lb;
  const double c = dot2(u, w), s = cross2(u, w), m[2] = {-w[1], w[0]};
  if (c < 0.0) { /* the parallel case wants B along A: reverse it */
    segseg_grad_b(a0, a1, b1, b0, I, gb1, gb0);
    return;
  }
  const double Ta0 = -potential(b0, b1, a0), Ta1 = potential(b0, b1, a1);
  const double Tb0 = -potential(a0, a1, b0), Tb1 = potential(a0, a1, b1);
  const double d0[2] = {b0[0] - a0[0], b0[1] - a0[1]}, d1[2] = {b0[0] - a1[0], b0[1] - a1[1]};
  const double k0 = cross2(d0, w), k1 = cross2(d1, w), t0 = dot2(d0, w), t1 = dot2(d1, w);
  const double Lr = La + Lb, qt = fabs(s), q0 = fabs(k0) / Lr, q1 = fabs(k1) / Lr;
  double Sb; /* translation along x; scaling about a0; scaling about a1 */
  if (qt >= q0 && qt >= q1) Sb = qt > 0.0 ? (Ta0 + Ta1 + c * (Tb0 + Tb1)) / s : 0.0;
  else if (q0 >= q1) Sb = (La * Ta1 + t0 * Tb0 + (t0 + Lb) * Tb1 - I) / k0;
  else Sb = (-La * Ta0 + t1 * Tb0 + (t1 + Lb) * Tb1 - I) / k1;
  const double eta0 = cross2(u, d0);
  double Nb1;
  if (qt >= PARALLEL_SINE) {
    double r11 = hypot(a1[0] - b1[0], a1[1] - b1[1]), r01 = hypot(a0[0] - b1[0], a0[1] - b1[1]);
    double r10 = hypot(a1[0] - b0[0], a1[1] - b0[1]), r00 = hypot(a0[0] - b0[0], a0[1] - b0[1]);
    Nb1 = ((r11 - r01) - (r10 - r00) - eta0 * Sb) / (s * Lb);
  } else {
    Nb1 = parallel_torque(La, Lb, t0, eta0) / Lb;
  }
  const double Nb0 = Sb - Nb1;
  gb0[0] = Tb0 * w[0] + Nb0 * m[0];
  gb0[1] = Tb0 * w[1] + Nb0 * m[1];
  gb1[0] = Tb1 * w[0] + Nb1 * m[0];
  gb1[1] = Tb1 * w[1] + Nb1 * m[1];
}

double lw_pair_segseg_grad(const double a0[2], const double a1[2], const double b0[2], const double b1[2],
                           double g[8])
{
  double I = lw_pair_segseg(a0, a1, b0, b1);
  for (int k = 0; k < 8; k++) g[k] = 0.0;
  if (!(I > 0.0)) return I; /* a segment without length */
  if (!isfinite(I)) {
    for (int k = 0; k < 8; k++) g[k] = NAN;
    return I;
  }
  segseg_grad_b(a0, a1, b0, b1, I, g + 4, g + 6);
  segseg_grad_b(b0, b1, a0, a1, I, g, g + 2);
  return I;
}

/* ---- jets: values on a tape, partials by one sweep back ---------------- */

/*
** A jet is a value and the tape node that made it (-1: a constant).  A node
** keeps its parents and its partials by them; one sweep back from the
** result gives its partials by the 16 control coordinates, which are the
** first 16 nodes.  Carrying the 16 partials forward through every operation
** cost 16 multiply-adds an operation, and the jets, 136 bytes each, filled
** the pieces the subdivision copies; the sweep costs one an edge (the same
** derivative, summed in another order).  The tape belongs to the thread's
** pairgrad_work and is reached through a thread-local pointer, so the
** operations keep their two-operand form.
*/
typedef struct {
  double v;
  int i;
} jet;

#define NCTRL 16 /* the control coordinates: a's 8, then b's */

typedef struct {
  int n, cap;     /* nodes, room */
  int m, mcap;    /* edges, room */
  int open;       /* the node jacc may still add edges to, or -1 */
  int failed;     /* out of memory: the partials are lost */
  int *start;     /* node k's edges are [start[k], start[k + 1]) */
  int *par;       /* an edge's parent node */
  double *d;      /* an edge's partial */
  double *adj;    /* the sweep's adjoints, one a node */
} jtape;

static _Thread_local jtape *T;

static int tape_grow(jtape *t, int nodes, int edges)
{
  if (nodes > t->cap) {
    int cap = t->cap ? 2 * t->cap : 4096;
    while (cap < nodes) cap *= 2;
    int *st = realloc(t->start, ((size_t)cap + 1) * sizeof *st);
    if (st) t->start = st;
    double *adj = st ? realloc(t->adj, (size_t)cap * sizeof *adj) : NULL;
    if (adj) t->adj = adj;
    if (!st || !adj) return -1;
    t->cap = cap;
  }
  if (edges > t->mcap) {
    int cap = t->mcap ? 2 * t->mcap : 8192;
    while (cap < edges) cap *= 2;
    int *par = realloc(t->par, (size_t)cap * sizeof *par);
    if (par) t->par = par;
    double *d = par ? realloc(t->d, (size_t)cap * sizeof *d) : NULL;
    if (d) t->d = d;
    if (!par || !d) return -1;
    t->mcap = cap;
  }
  return 0;
}

/* The rare path of tape_node and tape_edge: room, or the tape fails. */
static __attribute__((noinline)) int tape_room(jtape *t, int nodes, int edges)
{
  if (!t->failed && tape_grow(t, nodes, edges)) t->failed = 1;
  return t->failed;
}

/* A node with no edges yet, or -1 when the tape cannot grow.  Its edges
** end where the next node's start (tape_sweep closes the last one). */
static inline __attribute__((always_inline)) int tape_node(void)
{
  jtape *t = T;
  if (t->n + 1 >= t->cap && tape_room(t, t->n + 2, 0)) return -1;
  t->open = -1;
  t->start[t->n] = t->m;
  return t->n++;
}

/* An edge of the newest node (a constant parent has none). */
static inline __attribute__((always_inline)) void tape_edge(jtape *t, int par, double d)
{
  if (par < 0) return;
  if (t->m >= t->mcap && tape_room(t, 0, t->m + 1)) return;
  t->par[t->m] = par;
  t->d[t->m++] = d;
}

static inline __attribute__((always_inline)) jet jmake1(double v, int a, double da)
{
  jet r = {v, -1};
  if (a >= 0 && (r.i = tape_node()) >= 0) tape_edge(T, a, da);
  return r;
}

static inline __attribute__((always_inline)) jet jmake2(double v, int a, double da, int b, double db)
{
  jet r = {v, -1};
  if ((a >= 0 || b >= 0) && (r.i = tape_node()) >= 0) {
    jtape *t = T;
    tape_edge(t, a, da);
    tape_edge(t, b, db);
  }
  return r;
}

static inline jet jc(double v) { return (jet){v, -1}; }
static inline __attribute__((always_inline)) jet jadd(jet a, jet b) { return jmake2(a.v + b.v, a.i, 1.0, b.i, 1.0); }
static inline __attribute__((always_inline)) jet jsub(jet a, jet b) { return jmake2(a.v - b.v, a.i, 1.0, b.i, -1.0); }

static inline jet jaddc(jet a, double c)
{
  a.v += c;
  return a;
}

static inline __attribute__((always_inline)) jet jscale(jet a, double c) { return jmake1(a.v * c, a.i, c); }
static inline __attribute__((always_inline)) jet jmul(jet a, jet b) { return jmake2(a.v * b.v, a.i, b.v, b.i, a.v); }

static inline jet jdiv(jet a, jet b)
{
  double q = a.v / b.v;
  return jmake2(q, a.i, 1.0 / b.v, b.i, -q / b.v);
}

/* a / c for a constant c, rounded as the value is */
static inline jet jdivc(jet a, double c) { return jmake1(a.v / c, a.i, 1.0 / c); }

static inline jet jsqrt(jet a)
{
  double r = sqrt(a.v);
  return jmake1(r, a.i, r > 0.0 ? 0.5 / r : 0.0);
}

static inline jet jabs(jet a) { return a.v < 0.0 ? jscale(a, -1.0) : a; }

/* acc's partials += f times x's (partials only).  Repeated on the same acc
** with nothing else made between, the edges gather on one node. */
static inline __attribute__((always_inline)) void jacc(jet *acc, double f, const jet *x)
{
  if (x->i < 0) return;
  if (acc->i < 0 || acc->i != T->open) {
    int k = tape_node();
    if (k < 0) return;
    tape_edge(T, acc->i, 1.0);
    acc->i = k;
    T->open = k;
  }
  tape_edge(T, x->i, f);
}

/* The partials of the result r by the tape's first 16 nodes: one sweep
** back.  NAN when the tape ran out of memory. */
static double tape_sweep(jet r, double g[NCTRL])
{
  jtape *t = T;
  for (int k = 0; k < NCTRL; k++) g[k] = 0.0;
  if (t->failed) return NAN;
  if (r.i < 0) return r.v;
  t->start[t->n] = t->m;
  double *adj = t->adj;
  memset(adj, 0, ((size_t)r.i + 1) * sizeof *adj);
  adj[r.i] = 1.0;
  const int *start = t->start, *par = t->par;
  const double *d = t->d;
  for (int k = r.i; k >= NCTRL; k--) {
    const double a = adj[k];
    if (a == 0.0) continue; /* unused: its partials, infinite ones too, add nothing */
    for (int e = start[k]; e < start[k + 1]; e++) adj[par[e]] += d[e] * a;
  }
  for (int k = 0; k < NCTRL; k++) g[k] = adj[k];
  return r.v;
}

static inline jet jhypot(jet x, jet y) { return jsqrt(jadd(jmul(x, x), jmul(y, y))); }

/* pairnear.c's smooth_step: 0 at x <= 0, 1 at x >= 1, C2 between */
static jet jsmooth(jet x)
{
  if (x.v <= 0.0) return jc(0.0);
  if (x.v >= 1.0) return jc(1.0);
  double dr, r = lw_pair_ramp(x.v, &dr);
  return jmake1(r, x.i, dr);
}

/* ---- the near field's double integral, in jets ------------------------- */

#define K lw_pairnear_k

typedef struct {
  jet x[4], y[4];
} jcubic;

static void jcubic_from_bezier(const jet b[8], double ox, double oy, jcubic *c)
{
  jet x0 = jaddc(b[0], -ox), x1 = jaddc(b[2], -ox), x2 = jaddc(b[4], -ox), x3 = jaddc(b[6], -ox);
  jet y0 = jaddc(b[1], -oy), y1 = jaddc(b[3], -oy), y2 = jaddc(b[5], -oy), y3 = jaddc(b[7], -oy);
  c->x[0] = x0;
  c->x[1] = jscale(jsub(x1, x0), 3.0);
  c->x[2] = jscale(jadd(jsub(x0, jscale(x1, 2.0)), x2), 3.0);
  c->x[3] = jadd(jsub(x3, x0), jscale(jsub(x1, x2), 3.0));
  c->y[0] = y0;
  c->y[1] = jscale(jsub(y1, y0), 3.0);
  c->y[2] = jscale(jadd(jsub(y0, jscale(y1, 2.0)), y2), 3.0);
  c->y[3] = jadd(jsub(y3, y0), jscale(jsub(y1, y2), 3.0));
}

/* A value v linear in a cubic's coefficients q[from..3], by c[from..3]. */
static jet jlin(double v, const jet q[4], int from, const double c[4])
{
  jet r = jc(v);
  for (int k = from; k < 4; k++) jacc(&r, c[k], &q[k]);
  return r;
}

/* r, r' and r'' at a fixed parameter t (dd may be NULL): values by Horner
** in pairnear.c's order of operations, each linear in the coefficients. */
static void jcubic_eval(const jcubic *c, double t, jet r[2], jet d[2], jet dd[2])
{
  const jet *p[2] = {c->x, c->y};
  const double t3 = 3.0 * t, t6 = 6.0 * t, tt = t * t;
  const double cr[4] = {1.0, t, tt, tt * t}, cd[4] = {0.0, 1.0, 2.0 * t, 3.0 * tt}, cdd[4] = {0.0, 0.0, 2.0, t6};
  for (int i = 0; i < 2; i++) {
    const jet *q = p[i];
    r[i] = jlin(q[0].v + t * (q[1].v + t * (q[2].v + t * q[3].v)), q, 0, cr);
    d[i] = jlin(q[1].v + t * (2.0 * q[2].v + t3 * q[3].v), q, 1, cd);
    if (dd) dd[i] = jlin(2.0 * q[2].v + t6 * q[3].v, q, 2, cdd);
  }
}

/* pairnear.c's piece: ends, bounding circle, flatness */
typedef struct {
  double t0, t1;
  jet r0[2], d0[2], r1[2], d1[2];
  jet cx, cy, rad, flat;
} jpiece;

static void jpiece_bound(jpiece *p)
{
  double h3 = (p->t1 - p->t0) / 3.0;
  jet cx = jscale(jadd(p->r0[0], p->r1[0]), 0.5), cy = jscale(jadd(p->r0[1], p->r1[1]), 0.5);
  jet ex = jsub(p->r0[0], cx), ey = jsub(p->r0[1], cy);
  jet rad2 = jadd(jmul(ex, ex), jmul(ey, ey));
  jet ax = jsub(jadd(p->r0[0], jscale(p->d0[0], h3)), cx), ay = jsub(jadd(p->r0[1], jscale(p->d0[1], h3)), cy);
  jet bx = jsub(jsub(p->r1[0], jscale(p->d1[0], h3)), cx), by = jsub(jsub(p->r1[1], jscale(p->d1[1], h3)), cy);
  jet a2 = jadd(jmul(ax, ax), jmul(ay, ay)), b2 = jadd(jmul(bx, bx), jmul(by, by));
  if (a2.v > rad2.v) rad2 = a2;
  if (b2.v > rad2.v) rad2 = b2;
  p->cx = cx;
  p->cy = cy;
  p->rad = jsqrt(rad2);
  jet chx = jsub(p->r1[0], p->r0[0]), chy = jsub(p->r1[1], p->r0[1]), ch = jhypot(chx, chy);
  jet fa = jabs(jsub(jmul(jsub(ax, ex), chy), jmul(jsub(ay, ey), chx)));
  jet fb = jabs(jsub(jmul(jsub(bx, ex), chy), jmul(jsub(by, ey), chx)));
  p->flat = ch.v > 0.0 ? jdiv(fa.v >= fb.v ? fa : fb, ch) : jscale(p->rad, 2.0);
}

static void jpiece_init(jpiece *p, const jcubic *c, double t0, double t1)
{
  p->t0 = t0;
  p->t1 = t1;
  jcubic_eval(c, t0, p->r0, p->d0, NULL);
  jcubic_eval(c, t1, p->r1, p->d1, NULL);
  jpiece_bound(p);
}

static void jpiece_split(const jpiece *p, const jcubic *c, jpiece *lo, jpiece *hi)
{
  double tm = 0.5 * (p->t0 + p->t1);
  jet rm[2], dm[2];
  jcubic_eval(c, tm, rm, dm, NULL);
  *lo = *p;
  *hi = *p;
  lo->t1 = hi->t0 = tm;
  for (int i = 0; i < 2; i++) {
    lo->r1[i] = hi->r0[i] = rm[i];
    lo->d1[i] = hi->d0[i] = dm[i];
  }
  jpiece_bound(lo);
  jpiece_bound(hi);
}

/* The nodes of a rule on a piece: positions and length weights. */
#define JNODES_MAX 64

typedef struct {
  int m;
  jet x[JNODES_MAX], y[JNODES_MAX], w[JNODES_MAX];
} jnodes;

static void jrule_nodes(const jcubic *c, double t0, double t1, const double *s, const double *w, int m,
                        jnodes *n)
{
  const double h = t1 - t0;
  const jet *qx = c->x, *qy = c->y;
  n->m = m;
  for (int k = 0; k < m; k++) {
    const double t = t0 + h * s[k], t3 = 3.0 * t, tt = t * t;
    const double cr[4] = {1.0, t, tt, tt * t}, cd[4] = {0.0, 1.0, 2.0 * t, 3.0 * tt};
    n->x[k] = jlin(qx[0].v + t * (qx[1].v + t * (qx[2].v + t * qx[3].v)), qx, 0, cr);
    n->y[k] = jlin(qy[0].v + t * (qy[1].v + t * (qy[2].v + t * qy[3].v)), qy, 0, cr);
    /* the length weight h w_k |r'(t)|, straight from the coefficients: its
    ** partial by r'_x is h w_k r'_x / |r'| */
    const double dx = qx[1].v + t * (2.0 * qx[2].v + t3 * qx[3].v), dy = qy[1].v + t * (2.0 * qy[2].v + t3 * qy[3].v);
    const double len = sqrt(dx * dx + dy * dy), hw = h * w[k], fx = len > 0.0 ? hw * dx / len : 0.0,
                 fy = len > 0.0 ? hw * dy / len : 0.0;
    jet wk = jc(len * hw);
    for (int j = 1; j < 4; j++) {
      jacc(&wk, fx * cd[j], &qx[j]);
      jacc(&wk, fy * cd[j], &qy[j]);
    }
    n->w[k] = wk;
  }
}

typedef enum { KERNEL_INV, KERNEL_CUT } kernel_kind;

/* The product rule over two node sets for the kernels of pairnear.c (1/r;
** (1/r - 1/rc)+), its partials gathered per node first (reverse mode
** inside, which costs O(m^2) and 6 m edges).  B's nodes go two at a time
** (m is even: the rules have 6 nodes or a multiple of 4). */
static jet jproduct(const jnodes *A, const jnodes *B, kernel_kind kind, double rc)
{
  typedef lw_v2d v2d;
  const int h = B->m / 2;
  const v2d inv = {rc > 0.0 ? 1.0 / rc : 0.0, rc > 0.0 ? 1.0 / rc : 0.0};
  const v2d rc2 = {rc > 0.0 ? rc * rc : INFINITY, rc > 0.0 ? rc * rc : INFINITY};
  v2d bx[JNODES_MAX / 2], by[JNODES_MAX / 2], bw[JNODES_MAX / 2];
  v2d gbw[JNODES_MAX / 2], gbx[JNODES_MAX / 2], gby[JNODES_MAX / 2];
  double aw[JNODES_MAX], ax[JNODES_MAX], ay[JNODES_MAX], sum = 0.0;
  for (int j = 0; j < h; j++) {
    bx[j] = (v2d){B->x[2 * j].v, B->x[2 * j + 1].v};
    by[j] = (v2d){B->y[2 * j].v, B->y[2 * j + 1].v};
    bw[j] = (v2d){B->w[2 * j].v, B->w[2 * j + 1].v};
    gbw[j] = gbx[j] = gby[j] = (v2d){0.0, 0.0};
  }
  for (int i = 0; i < A->m; i++) {
    const double wi = A->w[i].v;
    const v2d x = {A->x[i].v, A->x[i].v}, y = {A->y[i].v, A->y[i].v}, vwi = {wi, wi};
    v2d acc = {0.0, 0.0}, gx = {0.0, 0.0}, gy = {0.0, 0.0};
    for (int j = 0; j < h; j++) {
      const v2d dx = x - bx[j], dy = y - by[j], r2 = dx * dx + dy * dy, q = 1.0 / lw_vsqrt2(r2);
      v2d k = q, kr = -q / r2; /* k(r) and k'(r) / r */
      if (kind == KERNEL_CUT) {
        const lw_v2l in = r2 < rc2;
        if (!(in[0] | in[1])) continue;
        k = (v2d)((lw_v2l)(q - inv) & in);
        kr = (v2d)((lw_v2l)kr & in);
      }
      const v2d f = vwi * bw[j] * kr;
      acc += bw[j] * k;
      gbw[j] += vwi * k;
      gx += f * dx;
      gy += f * dy;
      gbx[j] -= f * dx;
      gby[j] -= f * dy;
    }
    aw[i] = acc[0] + acc[1];
    ax[i] = gx[0] + gx[1];
    ay[i] = gy[0] + gy[1];
    sum += wi * aw[i];
  }
  jet r = jc(sum);
  for (int i = 0; i < A->m; i++) {
    jacc(&r, aw[i], &A->w[i]);
    jacc(&r, ax[i], &A->x[i]);
    jacc(&r, ay[i], &A->y[i]);
  }
  for (int j = 0; j < B->m; j++) {
    jacc(&r, gbw[j / 2][j % 2], &B->w[j]);
    jacc(&r, gbx[j / 2][j % 2], &B->x[j]);
    jacc(&r, gby[j / 2][j % 2], &B->y[j]);
  }
  return r;
}

/* lw_pair_segseg of four jet end points. */
static jet jsegseg(const jet a0[2], const jet a1[2], const jet b0[2], const jet b1[2])
{
  double p[4][2] = {{a0[0].v, a0[1].v}, {a1[0].v, a1[1].v}, {b0[0].v, b0[1].v}, {b1[0].v, b1[1].v}}, g[8];
  jet r = jc(lw_pair_segseg_grad(p[0], p[1], p[2], p[3], g));
  const jet *e[4] = {a0, a1, b0, b1};
  for (int k = 0; k < 4; k++) {
    jacc(&r, g[2 * k], &e[k][0]);
    jacc(&r, g[2 * k + 1], &e[k][1]);
  }
  return r;
}

/* The subdivision's stack (pairnear.c, inverse_distance), on the heap: a
** jet piece is large. */
typedef struct {
  jpiece *sa, *sb;
  jet *share;
  int *depth;
  jnodes na, nb; /* the whole-square rules' nodes (64 jets each way) */
  jtape tape;
} pairgrad_work;

static pairgrad_work *work_new(void)
{
  pairgrad_work *w = calloc(1, sizeof *w);
  if (!w) return NULL;
  size_t n = (size_t)K.stack_max;
  w->sa = malloc(n * sizeof *w->sa);
  w->sb = malloc(n * sizeof *w->sb);
  w->share = malloc(n * sizeof *w->share);
  w->depth = malloc(n * sizeof *w->depth);
  if (!w->sa || !w->sb || !w->share || !w->depth) {
    free(w->sa);
    free(w->sb);
    free(w->share);
    free(w->depth);
    free(w);
    return NULL;
  }
  return w;
}

static void work_free(pairgrad_work *w)
{
  if (!w) return;
  free(w->sa);
  free(w->sb);
  free(w->share);
  free(w->depth);
  free(w->tape.start);
  free(w->tape.par);
  free(w->tape.d);
  free(w->tape.adj);
  free(w);
}

/* The kernel of the subdivision (pairnear.c): 1/r, or (1/r - 1/rc)+ where on. */
typedef struct {
  int on;
  double rc, inv;
} cut;

static jet piece_rule(const jcubic *ca, const jpiece *pa, const jcubic *cb, const jpiece *pb, const cut *k)
{
  jnodes na, nb;
  jrule_nodes(ca, pa->t0, pa->t1, K.g6_s, K.g6_w, K.g6_n, &na);
  jrule_nodes(cb, pb->t0, pb->t1, K.g6_s, K.g6_w, K.g6_n, &nb);
  return jproduct(&na, &nb, k->on ? KERNEL_CUT : KERNEL_INV, k->rc);
}

/* pairnear.c's mean_chord: the chord moved across itself by the piece's
** mean distance from it. */
static void mean_chord(const jpiece *p, jet e0[2], jet e1[2])
{
  double h3 = (p->t1 - p->t0) / 3.0;
  jet ux = jsub(p->r1[0], p->r0[0]), uy = jsub(p->r1[1], p->r0[1]);
  jet ox = jscale(jscale(jsub(p->d0[0], p->d1[0]), h3), 0.25), oy = jscale(jscale(jsub(p->d0[1], p->d1[1]), h3), 0.25);
  jet uu = jadd(jmul(ux, ux), jmul(uy, uy));
  jet f = uu.v > 0.0 ? jdiv(jadd(jmul(ox, ux), jmul(oy, uy)), uu) : jc(0.0);
  ox = jsub(ox, jmul(f, ux));
  oy = jsub(oy, jmul(f, uy));
  e0[0] = jadd(p->r0[0], ox);
  e0[1] = jadd(p->r0[1], oy);
  e1[0] = jadd(p->r1[0], ox);
  e1[1] = jadd(p->r1[1], oy);
}

/* pairnear.c's leaf_value: the mean chords' exact integral, with the cutoff
** blended into the product rule where the pieces reach past it. */
static jet leaf_value(const jcubic *ca, const jpiece *pa, const jcubic *cb, const jpiece *pb, const cut *k)
{
  jet m = jc(1.0);
  if (k->on) {
    jet big = pa->rad.v > pb->rad.v ? pa->rad : pb->rad;
    jet far = jadd(jadd(jhypot(jsub(pa->cx, pb->cx), jsub(pa->cy, pb->cy)), pa->rad), pb->rad);
    m = big.v > 0.0 ? jsmooth(jdiv(jaddc(jscale(far, -1.0), k->rc), big)) : jc(0.0);
  }
  jet a0[2], a1[2], b0[2], b1[2];
  mean_chord(pa, a0, a1);
  mean_chord(pb, b0, b1);
  jet v = m.v > 0.0 ? jsegseg(a0, a1, b0, b1) : jc(0.0);
  if (!(v.v < INFINITY)) return piece_rule(ca, pa, cb, pb, k);
  if (k->on && m.v > 0.0) {
    jet la = jhypot(jsub(pa->r1[0], pa->r0[0]), jsub(pa->r1[1], pa->r0[1]));
    jet lb = jhypot(jsub(pb->r1[0], pb->r0[0]), jsub(pb->r1[1], pb->r0[1]));
    v = jsub(v, jscale(jmul(la, lb), k->inv));
    if (!(v.v > 0.0)) v = jc(0.0);
  }
  if (m.v < 1.0) v = jadd(jmul(m, v), jmul(jaddc(jscale(m, -1.0), 1.0), piece_rule(ca, pa, cb, pb, k)));
  return v;
}

static jet point_segment(const jet *p, const jet *a, const jet *b)
{
  jet ux = jsub(b[0], a[0]), uy = jsub(b[1], a[1]), px = jsub(p[0], a[0]), py = jsub(p[1], a[1]);
  jet uu = jadd(jmul(ux, ux), jmul(uy, uy));
  jet t = uu.v > 0.0 ? jdiv(jadd(jmul(px, ux), jmul(py, uy)), uu) : jc(0.0);
  if (t.v < 0.0) t = jc(0.0);
  else if (t.v > 1.0) t = jc(1.0);
  return jhypot(jsub(px, jmul(t, ux)), jsub(py, jmul(t, uy)));
}

/* point_segment's value alone, by the same operations. */
static double point_segment_value(const jet *p, const jet *a, const jet *b)
{
  double ux = b[0].v - a[0].v, uy = b[1].v - a[1].v, px = p[0].v - a[0].v, py = p[1].v - a[1].v;
  double uu = ux * ux + uy * uy, t = uu > 0.0 ? (px * ux + py * uy) / uu : 0.0;
  if (t < 0.0) t = 0.0;
  else if (t > 1.0) t = 1.0;
  double x = px - t * ux, y = py - t * uy;
  return sqrt(x * x + y * y);
}

static jet chord_distance(const jpiece *pa, const jpiece *pb)
{
  double ux = pa->r1[0].v - pa->r0[0].v, uy = pa->r1[1].v - pa->r0[1].v;
  double vx = pb->r1[0].v - pb->r0[0].v, vy = pb->r1[1].v - pb->r0[1].v;
  double s0 = ux * (pb->r0[1].v - pa->r0[1].v) - uy * (pb->r0[0].v - pa->r0[0].v);
  double s1 = ux * (pb->r1[1].v - pa->r0[1].v) - uy * (pb->r1[0].v - pa->r0[0].v);
  double t0 = vx * (pa->r0[1].v - pb->r0[1].v) - vy * (pa->r0[0].v - pb->r0[0].v);
  double t1 = vx * (pa->r1[1].v - pb->r0[1].v) - vy * (pa->r1[0].v - pb->r0[0].v);
  if (((s0 < 0.0) != (s1 < 0.0)) && ((t0 < 0.0) != (t1 < 0.0))) return jc(0.0);
  /* the nearest of the four end points, chosen on the values as jmin
  ** chooses; only it goes on the tape */
  const jet *p[4] = {pa->r0, pa->r1, pb->r0, pb->r1}, *s[4][2] = {{pb->r0, pb->r1}, {pb->r0, pb->r1},
                                                                 {pa->r0, pa->r1}, {pa->r0, pa->r1}};
  double d[4];
  for (int k = 0; k < 4; k++) d[k] = point_segment_value(p[k], s[k][0], s[k][1]);
  int a = d[1] < d[0] ? 1 : 0, b = d[3] < d[2] ? 3 : 2, k = d[b] < d[a] ? b : a;
  return point_segment(p[k], s[k][0], s[k][1]);
}

/* pairnear.c's subdivided, in jets: the shares carry their partials too,
** since the blend weights that form them move with the curves. */
static jet subdivided(const jcubic *ca, const jpiece *root_a, const jcubic *cb, const jpiece *root_b,
                      jet root_rest, const cut *k, pairgrad_work *wk)
{
  jpiece *sa = wk->sa, *sb = wk->sb;
  jet *share = wk->share;
  int *depth = wk->depth;
  sa[0] = *root_a;
  sb[0] = *root_b;
  share[0] = root_rest;
  depth[0] = 0;
  const jet leaf = jscale(jadd(root_a->rad, root_b->rad), K.leaf_ratio);
  jet sum = jc(0.0);
  int top = 1;
  while (top > 0) {
    top--;
    jpiece *pa = &sa[top], *pb = &sb[top];
    jet f = share[top];
    int d = depth[top];
    jet dx = jsub(pa->cx, pb->cx), dy = jsub(pa->cy, pb->cy);
    jet big = pa->rad.v > pb->rad.v ? pa->rad : pb->rad;
    jet gap = jsub(jsub(jhypot(dx, dy), pa->rad), pb->rad);
    if (k->on && gap.v >= k->rc) continue;
    jet w = big.v > 0.0 ? jsmooth(jdivc(jaddc(jdiv(gap, big), -K.sep_lo), K.sep_hi - K.sep_lo)) : jc(1.0);
    if (w.v > 0.0) sum = jadd(sum, jmul(jmul(f, w), piece_rule(ca, pa, cb, pb, k)));
    f = jmul(f, jaddc(jscale(w, -1.0), 1.0));
    if (f.v == 0.0) continue;
    w = top + 2 > K.stack_max ? jc(1.0)
                              : jsmooth(jdiv(jsub(jscale(leaf, K.leaf_band), big), jscale(leaf, K.leaf_band - 1.0)));
    if (w.v < 1.0) {
      jet cd = jsub(jsub(chord_distance(pa, pb), pa->flat), pb->flat), inside = jc(1.0);
      if (k->on) {
        jet far = jadd(jadd(jhypot(dx, dy), pa->rad), pb->rad);
        inside = jsmooth(jaddc(jdiv(jaddc(jscale(far, -1.0), k->rc), big), -1.0));
      }
      if (cd.v > 0.0 && inside.v > 0.0) {
        jet v = jmul(inside, jsmooth(jdiv(jsub(jsub(jscale(cd, K.flat_band * K.flat_ratio), pa->flat), pb->flat),
                                          jscale(cd, (K.flat_band - 1.0) * K.flat_ratio))));
        if (v.v > w.v) w = v;
      }
    }
    if (w.v > 0.0) sum = jadd(sum, jmul(jmul(f, w), leaf_value(ca, pa, cb, pb, k)));
    f = jmul(f, jaddc(jscale(w, -1.0), 1.0));
    if (f.v == 0.0) continue;
    if (d % 2 == 0) {
      jpiece whole = *pa;
      jpiece_split(&whole, ca, &sa[top], &sa[top + 1]);
      sb[top + 1] = sb[top];
    } else {
      jpiece whole = *pb;
      jpiece_split(&whole, cb, &sb[top], &sb[top + 1]);
      sa[top + 1] = sa[top];
    }
    share[top] = share[top + 1] = f;
    depth[top] = depth[top + 1] = d + 1;
    top += 2;
  }
  return sum;
}

/* r, r' and r'' at a parameter t that is itself a jet (the same operations
** as pairnear.c's cubic_eval, so the same values to the bit). */
static void jcubic_eval_at(const jcubic *c, jet t, jet r[2], jet d[2], jet dd[2])
{
  const jet *p[2] = {c->x, c->y};
  for (int i = 0; i < 2; i++) {
    const jet *q = p[i];
    r[i] = jadd(q[0], jmul(t, jadd(q[1], jmul(t, jadd(q[2], jmul(t, q[3]))))));
    d[i] = jadd(q[1], jmul(t, jadd(jscale(q[2], 2.0), jmul(t, jscale(q[3], 3.0)))));
    dd[i] = jadd(jscale(q[2], 2.0), jscale(jmul(q[3], t), 6.0));
  }
}

/* The position of a cubic at t, values only, as pairnear.c computes it. */
static void value_at(const jcubic *c, double t, double r[2])
{
  r[0] = c->x[0].v + t * (c->x[1].v + t * (c->x[2].v + t * c->x[3].v));
  r[1] = c->y[0].v + t * (c->y[1].v + t * (c->y[2].v + t * c->y[3].v));
}

/* A parameter moved by a step and kept in [0, 1]: where it is clamped it
** no longer moves with the curves. */
static jet clamp01(jet x)
{
  double v = fmin(1.0, fmax(0.0, x.v));
  return v == x.v ? x : jc(v);
}

/*
** pairnear.c's closest_points replayed in jets: the grid's choice,
** then the same Newton (or steepest descent) steps, halvings and
** acceptances, each step's partials carried along.  The iteration stops
** where a step no longer lowers the rounded distance, which can be short
** of the exact closest points (where the minimum lies on the square's edge,
** the projected steps converge slowly): the parameters the energy uses are
** these iterates, so their derivative is the iteration's, not the implicit
** one of the exact minimum.
*/
static void closest(const jcubic *ca, const jcubic *cb, jet *ps, jet *pt)
{
  enum { G = 64 }; /* room for pairnear.c's grid, which is 16 */
  const int g = K.cp_grid < G ? K.cp_grid : G;
  double best = INFINITY, s0 = 0.0, t0 = 0.0, ra[G + 1][2], rb[G + 1][2];
  for (int k = 0; k <= g; k++) {
    value_at(ca, k / (double)g, ra[k]);
    value_at(cb, k / (double)g, rb[k]);
  }
  for (int i = 0; i <= g; i++)
    for (int j = 0; j <= g; j++) {
      double dx = ra[i][0] - rb[j][0], dy = ra[i][1] - rb[j][1], q = dx * dx + dy * dy;
      if (q < best) best = q, s0 = i / (double)g, t0 = j / (double)g;
    }
  jet s = jc(s0), t = jc(t0);
  for (int it = 0; it < 30; it++) {
    jet a[2], a1[2], a2[2], b[2], b1[2], b2[2];
    jcubic_eval_at(ca, s, a, a1, a2);
    jcubic_eval_at(cb, t, b, b1, b2);
    jet D[2] = {jsub(a[0], b[0]), jsub(a[1], b[1])};
    jet gs = jadd(jmul(D[0], a1[0]), jmul(D[1], a1[1]));
    jet gt = jscale(jadd(jmul(D[0], b1[0]), jmul(D[1], b1[1])), -1.0);
    jet vs = jadd(jmul(a1[0], a1[0]), jmul(a1[1], a1[1])), vt = jadd(jmul(b1[0], b1[0]), jmul(b1[1], b1[1]));
    jet hss = jadd(jadd(vs, jmul(D[0], a2[0])), jmul(D[1], a2[1]));
    jet htt = jsub(jsub(vt, jmul(D[0], b2[0])), jmul(D[1], b2[1]));
    jet hst = jscale(jadd(jmul(a1[0], b1[0]), jmul(a1[1], b1[1])), -1.0);
    jet det = jsub(jmul(hss, htt), jmul(hst, hst)), ds, dt;
    if (det.v > 1e-12 * (vs.v * vt.v + 1e-300) && hss.v > 0.0) {
      ds = jscale(jdiv(jsub(jmul(htt, gs), jmul(hst, gt)), det), -1.0);
      dt = jscale(jdiv(jsub(jmul(hss, gt), jmul(hst, gs)), det), -1.0);
    } else {
      ds = vs.v > 0.0 ? jscale(jdiv(gs, vs), -1.0) : jc(0.0);
      dt = vt.v > 0.0 ? jscale(jdiv(gt, vt), -1.0) : jc(0.0);
    }
    int moved = 0;
    for (int half = 0; half < 20 && !moved; half++, ds = jscale(ds, 0.5), dt = jscale(dt, 0.5)) {
      jet ns = clamp01(jadd(s, ds)), nt = clamp01(jadd(t, dt));
      if (ns.v == s.v && nt.v == t.v) break;
      double r[2], q[2];
      value_at(ca, ns.v, r);
      value_at(cb, nt.v, q);
      double f = (r[0] - q[0]) * (r[0] - q[0]) + (r[1] - q[1]) * (r[1] - q[1]);
      if (f < best) {
        best = f;
        s = ns;
        t = nt;
        moved = 1;
      }
    }
    if (!moved) break;
  }
  *ps = s;
  *pt = t;
}

/* lw_pair_segments_exact in jets: the same steps, the same branches. */
static double segments_exact_grad(const double a[8], const double b[8], double cutoff, pairgrad_work *wk,
                                  double ga[8], double gb[8])
{
  jtape *outer = T;
  T = &wk->tape;
  T->n = T->m = 0;
  T->open = -1;
  T->failed = 0;
  jet ja[8], jb[8];
  for (int k = 0; k < 8; k++) ja[k] = (jet){a[k], tape_node()}; /* nodes 0..7 */
  for (int k = 0; k < 8; k++) jb[k] = (jet){b[k], tape_node()}; /* nodes 8..15 */
  /* the local origin is a constant: the integral does not depend on it */
  double ox = 0.25 * (a[0] + a[6] + b[0] + b[6]), oy = 0.25 * (a[1] + a[7] + b[1] + b[7]);
  jcubic ca, cb;
  jcubic_from_bezier(ja, ox, oy, &ca);
  jcubic_from_bezier(jb, ox, oy, &cb);
  jpiece pa, pb;
  jpiece_init(&pa, &ca, 0.0, 1.0);
  jpiece_init(&pb, &cb, 0.0, 1.0);
  jet ra[2], a1[2], a2[2], rb[2], b1[2], b2[2], ss, ts;
  closest(&ca, &cb, &ss, &ts);
  jcubic_eval_at(&ca, ss, ra, a1, a2);
  jcubic_eval_at(&cb, ts, rb, b1, b2);
  jet half = pa.rad.v >= pb.rad.v ? pa.rad : pb.rad, dist = jhypot(jsub(ra[0], rb[0]), jsub(ra[1], rb[1]));
  kernel_kind whole = cutoff > 0.0 ? KERNEL_CUT : KERNEL_INV;
  jet v = jc(0.0), rest = jc(1.0);
  for (int r = 0; r < K.n_whole && rest.v > 0.0; r++) {
    double lo = K.whole_lo[r], hi = K.whole_hi[r];
    jet w = half.v > 0.0 ? jsmooth(jdivc(jaddc(jdiv(dist, half), -lo), hi - lo)) : jc(1.0);
    if (w.v > 0.0) {
      jnodes *na = &wk->na, *nb = &wk->nb;
      jrule_nodes(&ca, 0.0, 1.0, K.whole_s[r], K.whole_w[r], K.whole_m[r], na);
      jrule_nodes(&cb, 0.0, 1.0, K.whole_s[r], K.whole_w[r], K.whole_m[r], nb);
      v = jadd(v, jmul(jmul(rest, w), jproduct(na, nb, whole, cutoff)));
    }
    rest = jmul(rest, jaddc(jscale(w, -1.0), 1.0));
  }
  if (rest.v > 0.0) {
    const cut k = {cutoff > 0.0, cutoff, cutoff > 0.0 ? 1.0 / cutoff : 0.0};
    v = jadd(v, subdivided(&ca, &pa, &cb, &pb, rest, &k, wk));
  }
  double g[NCTRL], e = tape_sweep(v, g);
  for (int k = 0; k < 8; k++) {
    ga[k] = g[k];
    gb[k] = g[8 + k];
  }
  T = outer;
  return e;
}

double lw_pair_segments_exact_grad(const double a[8], const double b[8], double cutoff, double ga[8],
                                   double gb[8])
{
  pairgrad_work *wk = work_new();
  if (!wk) return NAN;
  double v = segments_exact_grad(a, b, cutoff, wk, ga, gb);
  work_free(wk);
  return v;
}

/* ---- the near correction and the far field ------------------------------ */

/* dE/d(x, y, dl) of one pair sample. */
typedef struct {
  double x, y, dl;
} sample_grad;

/* Adds f times the derivative of dl_i dl_j (1/r - 1/rc) (r < rc) to gi, gj. */
static void kernel_grad(const lw_pair_sample *si, const lw_pair_sample *sj, double inv, double f, sample_grad *gi,
                        sample_grad *gj)
{
  double dx = si->x - sj->x, dy = si->y - sj->y, r2 = dx * dx + dy * dy, r = sqrt(r2);
  double dli = si->dl, dlj = sj->dl, k = 1.0 / r - inv, q = -f * dli * dlj / (r2 * r);
  gi->x += q * dx;
  gi->y += q * dy;
  gj->x -= q * dx;
  gj->y -= q * dy;
  gi->dl += f * dlj * k;
  gj->dl += f * dli * k;
}

/* 1 below half the radius, 0 from the radius on, C2 in between; and its
** derivative by u in *du. */
static double near_weight(double u, double *du)
{
  *du = 0.0;
  if (u >= 1.0) return 0.0;
  if (u <= 0.5) return 1.0;
  double dt, w = lw_pair_ramp(2.0 * (1.0 - u), &dt);
  *du = -2.0 * dt;
  return w;
}

/*
** lw_pair_near_correction with its derivative: adds it to the sample
** gradients gsa, gsb and to the control point gradients ga, gb, and
** returns it.  The same order of A and B as the energy, so the same X_AB.
*/
static double near_correction_grad(const double a[8], const lw_pair_sample *sa, const double b[8],
                                   const lw_pair_sample *sb, int n, const lw_pair_ctx *ctx, pairgrad_work *wk,
                                   sample_grad *gsa, sample_grad *gsb, double ga[8], double gb[8])
{
  if (!lw_pair_bezier_before(a, b)) {
    const double *t = a;
    const lw_pair_sample *u = sa;
    sample_grad *v = gsa;
    double *g = ga;
    a = b, b = t;
    sa = sb, sb = u;
    gsa = gsb, gsb = v;
    ga = gb, gb = g;
  }
  double W = 0.0, far = 0.0, near = 0.0;
  int wi = -1, wj = -1;
  const double cut2 = ctx->cutoff2, inv = ctx->inv_cutoff;
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      double dx = sa[i].x - sb[j].x, dy = sa[i].y - sb[j].y, r2 = dx * dx + dy * dy, du;
      double rho2 = lw_pair_near_radius2(ctx, sa[i].dl, sb[j].dl);
      int weighs = sa[i].dl != 0.0f && sb[j].dl != 0.0f;
      double k = weighs && r2 < cut2 ? (double)sa[i].dl * (double)sb[j].dl * (1.0 / sqrt(r2) - inv) : 0.0;
      if (r2 < rho2) {
        double w = near_weight(sqrt(r2 / rho2), &du);
        if (w > W) W = w, wi = i, wj = j;
        near += k;
      } else {
        far += k;
      }
    }
  /* W = 0 with near pairs: each at the near radius itself (u rounded to
  ** 1), whose terms are the product rule's, as lw_pair_near_correction */
  double gxa[8] = {0}, gxb[8] = {0}, dwa[8], dwb[8], X = 0.0;
  if (W > 0.0) X = segments_exact_grad(a, b, ctx->cutoff, wk, gxa, gxb);
  const double ow = W > 0.0 ? lw_pair_order_weight(a, b, dwa, dwb) : 1.0;
  if (ow != 1.0) { /* both orders in the band (pairnear.h) */
    double hb[8], ha[8];
    const double Y = segments_exact_grad(b, a, ctx->cutoff, wk, hb, ha);
    for (int k = 0; k < 8; k++) {
      gxa[k] = ow * gxa[k] + (1.0 - ow) * ha[k] + dwa[k] * (X - Y);
      gxb[k] = ow * gxb[k] + (1.0 - ow) * hb[k] + dwb[k] * (X - Y);
    }
    X = ow * X + (1.0 - ow) * Y;
  }
  double e = W * X;
  if (W < 1.0) e += (1.0 - W) * (near + far);
  e = W > 0.0 ? e - far : near;
  /* e = W X + (1 - W)(near + far) - far: the near terms weigh 1 - W, the
  ** far ones -W, and W moves with its pair where it is below 1 */
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      double dx = sa[i].x - sb[j].x, dy = sa[i].y - sb[j].y, r2 = dx * dx + dy * dy;
      if (!(sa[i].dl != 0.0f && sb[j].dl != 0.0f && r2 < cut2)) continue;
      double rho2 = lw_pair_near_radius2(ctx, sa[i].dl, sb[j].dl);
      kernel_grad(&sa[i], &sb[j], inv, r2 < rho2 ? 1.0 - W : -W, &gsa[i], &gsb[j]);
    }
  if (W < 1.0 && W > 0.0) {
    const lw_pair_sample *p = &sa[wi], *q = &sb[wj];
    double dx = p->x - q->x, dy = p->y - q->y, r = sqrt(dx * dx + dy * dy), du;
    double rho = sqrt(lw_pair_near_radius2(ctx, p->dl, q->dl)), u = r / rho;
    near_weight(u, &du);
    double c = du * (X - (near + far)); /* dE/du */
    if (r > 0.0) {
      gsa[wi].x += c * dx / (r * rho);
      gsa[wi].y += c * dy / (r * rho);
      gsb[wj].x -= c * dx / (r * rho);
      gsb[wj].y -= c * dy / (r * rho);
    }
    /* rho = near max(dl_i, dl_j), unless the cutoff caps it */
    double free_rho = ctx->near_scale * (double)(p->dl > q->dl ? p->dl : q->dl);
    if (!(free_rho > ctx->cutoff && ctx->cutoff > 0.0)) {
      double dr = -c * u / rho * ctx->near_scale;
      if (p->dl > q->dl) gsa[wi].dl += dr;
      else gsb[wj].dl += dr;
    }
  }
  for (int k = 0; k < 8; k++) {
    ga[k] += W * gxa[k];
    gb[k] += W * gxb[k];
  }
  return e;
}

/* ---- the whole term ------------------------------------------------------- */

/* One near segment pair's share, kept apart so that the pairs can be
** evaluated in any order (threads) and summed in the list's. */
typedef struct {
  double e;
  double ga[8], gb[8];
} near_out;

static int cmp_pair(const void *a, const void *b)
{
  const uint32_t *x = a, *y = b;
  return x[0] != y[0] ? (x[0] > y[0]) - (x[0] < y[0]) : (x[1] > y[1]) - (x[1] < y[1]);
}

/* Appends (ga, gb) to a list of pairs.  LW_ENOMEM if it cannot grow. */
static lw_status pairs_push(uint32_t **v, size_t *n, size_t *cap, uint32_t ga, uint32_t gb)
{
  if (*n + 2 > *cap) {
    size_t c = *cap ? 2 * *cap : 256;
    uint32_t *nv = realloc(*v, c * sizeof *nv);
    if (!nv) return LW_ENOMEM;
    *v = nv;
    *cap = c;
  }
  (*v)[(*n)++] = ga;
  (*v)[(*n)++] = gb;
  return LW_OK;
}

/*
** Every pair of samples of different splines once (j > i), by the cells of
** the grid: far pairs into *far and the sample gradients, near ones into
** the list of segment pairs (lower, higher), as the walk decides them
** (walk.h).
*/
static lw_status far_plane(const lw_cellgrid *g, const lw_splines *sp, uint32_t np, const lw_pair_ctx *ctx,
                           sample_grad *gs, double *far, uint32_t **pairs, size_t *n_pairs, size_t *cap)
{
  double sum = 0.0;
  const double inv = ctx->inv_cutoff, cut2 = ctx->cutoff2, ns = ctx->near_scale;
  for (int cy = 0; cy < g->ny; cy++)
    for (int cx = 0; cx < g->nx; cx++) {
      const lw_cell *c = &g->cell[(size_t)cy * (size_t)g->nx + (size_t)cx];
      for (uint32_t k = 0; k < c->n; k++) {
        const lw_pair_sample P = {c->x[k], lw_cell_y(c)[k], lw_cell_dl(c)[k]};
        const uint32_t i = lw_cell_idx(c)[k], si = sp->seg_spline[i / np];
        for (int ny = cy - 1; ny <= cy + 1; ny++)
          for (int nx = cx - 1; nx <= cx + 1; nx++) {
            if (ny < 0 || ny >= g->ny || nx < 0 || nx >= g->nx) continue;
            const lw_cell *d = &g->cell[(size_t)ny * (size_t)g->nx + (size_t)nx];
            for (uint32_t e = 0; e < d->n; e++) {
              const uint32_t j = lw_cell_idx(d)[e];
              if (j <= i || sp->seg_spline[j / np] == si) continue;
              const lw_pair_sample Q = {d->x[e], lw_cell_y(d)[e], lw_cell_dl(d)[e]};
              double dx = P.x - Q.x, dy = P.y - Q.y, r2 = dx * dx + dy * dy;
              double l = ns * (double)(P.dl > Q.dl ? P.dl : Q.dl);
              if (r2 < l * l && r2 < cut2) {
                if (pairs_push(pairs, n_pairs, cap, i / np, j / np) != LW_OK) return LW_ENOMEM;
              } else if (r2 < cut2 && P.dl > 0.0f && Q.dl > 0.0f) {
                sum += (double)P.dl * (double)Q.dl * (1.0 / sqrt(r2) - inv);
                kernel_grad(&P, &Q, inv, 1.0, &gs[i], &gs[j]);
              }
            }
          }
      }
    }
  *far += sum;
  return LW_OK;
}

/* The same over every plane of the grid (a layer each with apart = pen):
** pairs across planes count nothing. */
static lw_status far_field(const lw_cellgrid *grid, const lw_splines *sp, uint32_t np, const lw_pair_ctx *ctx,
                           sample_grad *gs, double *far, uint32_t **pairs, size_t *n_pairs)
{
  size_t cap = 0;
  lw_cellgrid view;
  *far = 0.0;
  for (int plane = 0; plane < grid->nz; plane++)
    if (far_plane(lw_cellgrid_plane(grid, plane, &view), sp, np, ctx, gs, far, pairs, n_pairs, &cap) != LW_OK)
      return LW_ENOMEM;
  return LW_OK;
}

/* Near pairs evaluated together: their results wait in a buffer of this
** many to be added in the list's order. */
#define NEAR_CHUNK 1024

/* The near segment pairs, sorted without repeats, each with its
** correction; their sum in the list's order.  Threads take the pairs of a
** chunk in any order; one thread then adds the chunk's results in order, so
** the sums are the same for any thread count. */
static lw_status near_field(const lw_splines *sp, const lw_pair_sample *smp, uint32_t np, const lw_pair_ctx *ctx,
                            uint32_t *pairs, size_t n, sample_grad *gs, double *gctrl, double *near)
{
  size_t m = 0;
  if (n) qsort(pairs, n / 2, 2 * sizeof *pairs, cmp_pair);
  for (size_t k = 0; k < n; k += 2)
    if (m == 0 || pairs[k] != pairs[m - 2] || pairs[k + 1] != pairs[m - 1]) {
      pairs[m++] = pairs[k];
      pairs[m++] = pairs[k + 1];
    }
  const size_t np2 = (size_t)np * 2, n_near = m / 2;
  near_out *out = malloc(NEAR_CHUNK * sizeof *out);
  sample_grad *sg = malloc(NEAR_CHUNK * np2 * sizeof *sg);
  int failed = !out || !sg;
  double sum = 0.0;
#pragma omp parallel if (!failed && n_near > 1)
  {
    pairgrad_work *wk = failed ? NULL : work_new();
    if (!wk) {
#pragma omp atomic write
      failed = 1;
    }
    for (size_t c0 = 0; c0 < n_near; c0 += NEAR_CHUNK) {
      const size_t c1 = c0 + NEAR_CHUNK < n_near ? c0 + NEAR_CHUNK : n_near;
#pragma omp for schedule(dynamic, 4)
      for (size_t p = c0; p < c1; p++) {
        if (!wk) continue;
        uint32_t ga = pairs[2 * p], gb = pairs[2 * p + 1];
        double a[8], b[8];
        const lw_node *na = &sp->node[lw_segment_node(sp, ga)], *nb = &sp->node[lw_segment_node(sp, gb)];
        lw_segment_bezier(na, na + 1, a);
        lw_segment_bezier(nb, nb + 1, b);
        near_out *o = &out[p - c0];
        sample_grad *d = sg + (p - c0) * np2;
        memset(o, 0, sizeof *o);
        memset(d, 0, np2 * sizeof *d);
        o->e = near_correction_grad(a, smp + (size_t)ga * np, b, smp + (size_t)gb * np, (int)np, ctx, wk, d,
                                    d + np, o->ga, o->gb);
      }
#pragma omp single
      for (size_t p = c0; p < c1 && !failed; p++) {
        const near_out *o = &out[p - c0];
        sum += o->e;
        for (int e = 0; e < 2; e++) {
          size_t g = pairs[2 * p + (size_t)e];
          const double *gc = e ? o->gb : o->ga;
          for (int k = 0; k < 8; k++) gctrl[g * 8 + (size_t)k] += gc[k];
          for (uint32_t q = 0; q < np; q++) {
            const sample_grad *d = &sg[(p - c0) * np2 + (size_t)e * np + q];
            sample_grad *t = &gs[g * np + q];
            t->x += d->x;
            t->y += d->y;
            t->dl += d->dl;
          }
        }
      }
    }
    work_free(wk);
  }
  free(out);
  free(sg);
  *near = sum;
  return failed ? LW_ENOMEM : LW_OK;
}

double lw_pair_gradient(const lw_scene *sc, const lw_splines *sp, lw_node *grad, lw_error *err)
{
  lw_term_ctx tc[LW_TERM_COUNT];
  lw_scene_term_ctx(sc, tc);
  const lw_term_ctx *pc = NULL;
  for (int t = 0; t < LW_TERM_COUNT && !pc; t++)
    if (lw_term_types[t].pairwise && tc[t].coef != 0.0) pc = &tc[t];
  if (!pc) return 0.0;
  const lw_quad *q = pc->quad;
  const lw_pair_ctx *ctx = pc->data;
  const uint32_t np = (uint32_t)q->n;
  const size_t n = sp->n_segments * (size_t)np;
  lw_pair_sample *smp = malloc((n ? n : 1) * sizeof *smp);
  double *tan = malloc((n ? n : 1) * 2 * sizeof *tan); /* d dl / d r' = w_q r' / |r'| */
  sample_grad *gs = calloc(n ? n : 1, sizeof *gs);
  double *gctrl = calloc((sp->n_segments ? sp->n_segments : 1) * 8, sizeof *gctrl);
  uint32_t *pairs = NULL;
  size_t n_pairs = 0;
  double far = 0.0, near = 0.0, e = NAN;
  lw_cellgrid *g = NULL;
  if (!smp || !tan || !gs || !gctrl) goto nomem;
  if (!(g = lw_cellgrid_new(0.0, 0.0, sc->width, sc->height, ctx->cutoff, n, err))) goto done;
  /* a layer a plane when lines keep apart from their own pen's only (model.c) */
  const int planes = lw_layers_planes(&sc->layers);
  if (lw_cellgrid_planes(g, planes) != LW_OK) goto nomem;
  for (size_t s = 0; s < sp->n_segments; s++) {
    const int plane = planes > 1 ? lw_splines_layer(&sc->layers, sp, sp->seg_spline[s]) : 0;
    const lw_node *a = &sp->node[lw_segment_node(sp, s)];
    lw_samples ss;
    lw_segment_sample(q, a, a + 1, &ss);
    for (uint32_t k = 0; k < np; k++) {
      size_t i = s * np + k;
      smp[i] = (lw_pair_sample){ss.x[k], ss.y[k], (float)ss.dl[k]};
      double f = ss.speed[k] > 0.0 ? q->w[k] / ss.speed[k] : 0.0;
      tan[2 * i] = f * ss.dx[k];
      tan[2 * i + 1] = f * ss.dy[k];
      if (lw_cellgrid_insert_in(g, plane, (uint32_t)i, smp[i].x, smp[i].y, smp[i].dl) != LW_OK) goto nomem;
    }
  }
  if (far_field(g, sp, np, ctx, gs, &far, &pairs, &n_pairs) != LW_OK) goto nomem;
  if (near_field(sp, smp, np, ctx, pairs, n_pairs, gs, gctrl, &near) != LW_OK) goto nomem;
  /* to the nodes: samples through the basis of q, control points through
  ** b0 = p_a, b1 = p_a + v_a, b2 = p_b - v_b, b3 = p_b */
  const double C = pc->coef;
  for (size_t s = 0; s < sp->n_segments; s++) {
    lw_node *ga = &grad[lw_segment_node(sp, s)], *gb = ga + 1;
    for (uint32_t k = 0; k < np; k++) {
      size_t i = s * np + k;
      double gx = C * gs[i].x, gy = C * gs[i].y, tx = C * gs[i].dl * tan[2 * i], ty = C * gs[i].dl * tan[2 * i + 1];
      const double *p = q->pos[k], *d = q->d1[k];
      ga->px += p[0] * gx + d[0] * tx;
      ga->py += p[0] * gy + d[0] * ty;
      ga->vx += p[1] * gx + d[1] * tx;
      ga->vy += p[1] * gy + d[1] * ty;
      gb->px += p[2] * gx + d[2] * tx;
      gb->py += p[2] * gy + d[2] * ty;
      gb->vx += p[3] * gx + d[3] * tx;
      gb->vy += p[3] * gy + d[3] * ty;
    }
    const double *c = gctrl + 8 * s;
    ga->px += C * (c[0] + c[2]);
    ga->py += C * (c[1] + c[3]);
    ga->vx += C * c[2];
    ga->vy += C * c[3];
    gb->px += C * (c[4] + c[6]);
    gb->py += C * (c[5] + c[7]);
    gb->vx -= C * c[4];
    gb->vy -= C * c[5];
  }
  e = C * (far + near);
  goto done;
nomem:
  lw_error_set(err, LW_ENOMEM, "out of memory for the pair gradient of %zu segments (%zu pair samples)",
               sp->n_segments, n);
  e = NAN;
done:
  lw_cellgrid_free(g);
  free(smp);
  free(tan);
  free(gs);
  free(gctrl);
  free(pairs);
  return e;
}
