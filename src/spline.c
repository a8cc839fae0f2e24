/* spline.c -- contiguous spline storage and segment evaluation (spline.h). */
#include "linewise/spline.h"

#include <complex.h>
#include <float.h>
#include <gsl/gsl_poly.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

lw_splines *lw_splines_new(size_t n_splines, const size_t *segments, lw_error *err)
{
  size_t n_nodes = 0;
  for (size_t i = 0; i < n_splines; i++) {
    if (segments[i] < 1) {
      lw_error_set(err, LW_EINPUT, "spline %zu has no segment (at least 1 expected)", i);
      return NULL;
    }
    n_nodes += segments[i] + 1;
  }
  lw_splines *sp = calloc(1, sizeof *sp);
  if (!sp) goto nomem;
  sp->n_splines = n_splines;
  sp->n_nodes = n_nodes;
  sp->n_segments = n_nodes - n_splines;
  sp->node = calloc(n_nodes ? n_nodes : 1, sizeof *sp->node);
  sp->first = malloc((n_splines + 1) * sizeof *sp->first);
  /* as many as the nodes, cap_nodes below: an append that fits in the nodes
  ** wrote past n_segments of them (splines that died, then a longer one born
  ** into their room after a renumbering or a resume: a heap overflow) */
  sp->seg_spline = malloc((n_nodes ? n_nodes : 1) * sizeof *sp->seg_spline);
  sp->rest_length = malloc((n_splines ? n_splines : 1) * sizeof *sp->rest_length);
  if (!sp->node || !sp->first || !sp->seg_spline || !sp->rest_length) goto nomem;
  size_t k = 0, g = 0;
  for (size_t i = 0; i < n_splines; i++) {
    sp->first[i] = k;
    k += segments[i] + 1;
    for (size_t m = 0; m < segments[i]; m++) sp->seg_spline[g++] = (uint32_t)i;
    sp->rest_length[i] = 1.0;
  }
  sp->first[n_splines] = k;
  sp->cap_nodes = n_nodes;
  sp->cap_splines = n_splines;
  return sp;
nomem:
  lw_splines_free(sp);
  lw_error_set(err, LW_ENOMEM, "out of memory for %zu splines", n_splines);
  return NULL;
}

void lw_splines_free(lw_splines *sp)
{
  if (!sp) return;
  free(sp->node);
  free(sp->first);
  free(sp->seg_spline);
  free(sp->rest_length);
  free(sp->layer);
  free(sp);
}

lw_splines *lw_splines_clone(const lw_splines *sp)
{
  size_t *segs = malloc((sp->n_splines ? sp->n_splines : 1) * sizeof *segs);
  if (!segs) return NULL;
  for (size_t i = 0; i < sp->n_splines; i++) segs[i] = lw_splines_segments(sp, i);
  lw_splines *c = lw_splines_new(sp->n_splines, segs, NULL);
  free(segs);
  if (!c) return NULL;
  memcpy(c->node, sp->node, sp->n_nodes * sizeof *sp->node);
  memcpy(c->rest_length, sp->rest_length, sp->n_splines * sizeof *sp->rest_length);
  if (sp->layer) {
    if (lw_splines_layers_alloc(c) != LW_OK) {
      lw_splines_free(c);
      return NULL;
    }
    memcpy(c->layer, sp->layer, sp->n_splines * sizeof *sp->layer);
  }
  return c;
}

lw_status lw_splines_permute(lw_splines *sp, const size_t *order, lw_error *err)
{
  size_t n = sp->n_splines;
  size_t *segs = calloc(n ? n : 1, sizeof *segs);
  if (!segs) return lw_error_set(err, LW_ENOMEM, "out of memory renumbering %zu splines", n);
  for (size_t k = 0; k < n; k++) segs[k] = lw_splines_segments(sp, order[k]);
  lw_splines *c = lw_splines_new(n, segs, err);
  free(segs);
  if (!c) return err ? err->code : LW_ENOMEM;
  if (sp->layer && lw_splines_layers_alloc(c) != LW_OK) {
    lw_splines_free(c);
    return lw_error_set(err, LW_ENOMEM, "out of memory renumbering %zu splines", n);
  }
  for (size_t k = 0; k < n; k++) {
    size_t i = order[k];
    memcpy(&c->node[c->first[k]], &sp->node[sp->first[i]], (sp->first[i + 1] - sp->first[i]) * sizeof *sp->node);
    c->rest_length[k] = sp->rest_length[i];
    if (sp->layer) c->layer[k] = sp->layer[i];
  }
  lw_splines old = *sp;
  *sp = *c;
  *c = old;
  lw_splines_free(c);
  return LW_OK;
}

/* The room for need elements after growth: half again as much, so that a
** run of single insertions costs amortised O(1) each. */
static size_t grown(size_t cap, size_t need)
{
  size_t c = cap + cap / 2 + 8;
  return c < need ? need : c;
}

lw_status lw_splines_layers_alloc(lw_splines *sp)
{
  if (sp->layer) return LW_OK;
  sp->layer = calloc(sp->cap_splines ? sp->cap_splines : 1, sizeof *sp->layer);
  return sp->layer ? LW_OK : LW_ENOMEM;
}

lw_status lw_splines_reserve(lw_splines *sp, size_t more_nodes, size_t more_splines)
{
  const size_t n_nodes = sp->n_nodes + more_nodes, n_splines = sp->n_splines + more_splines;
  /* an array that grew while its partner failed is only larger than its cap says */
  if (n_nodes > sp->cap_nodes) {
    size_t c = grown(sp->cap_nodes, n_nodes);
    lw_node *nd = realloc(sp->node, c * sizeof *nd);
    if (!nd) return LW_ENOMEM;
    sp->node = nd;
    uint32_t *ss = realloc(sp->seg_spline, c * sizeof *ss);
    if (!ss) return LW_ENOMEM;
    sp->seg_spline = ss;
    sp->cap_nodes = c;
  }
  if (n_splines > sp->cap_splines) {
    size_t c = grown(sp->cap_splines, n_splines);
    double *r = realloc(sp->rest_length, c * sizeof *r);
    if (!r) return LW_ENOMEM;
    sp->rest_length = r;
    size_t *fi = realloc(sp->first, (c + 1) * sizeof *fi);
    if (!fi) return LW_ENOMEM;
    sp->first = fi;
    if (sp->layer) {
      uint8_t *ly = realloc(sp->layer, c * sizeof *ly);
      if (!ly) return LW_ENOMEM;
      sp->layer = ly;
    }
    sp->cap_splines = c;
  }
  return LW_OK;
}

lw_status lw_splines_append(lw_splines *sp, const lw_node *nodes, size_t n_new, double rest, int layer)
{
  const size_t n_nodes = sp->n_nodes + n_new, n_splines = sp->n_splines + 1;
  /* all growth first, so that a failure leaves sp as it was */
  if (lw_splines_reserve(sp, n_new, 1) != LW_OK) return LW_ENOMEM;
  memcpy(sp->node + sp->n_nodes, nodes, n_new * sizeof *nodes);
  for (size_t g = sp->n_segments; g < sp->n_segments + n_new - 1; g++) sp->seg_spline[g] = (uint32_t)sp->n_splines;
  sp->rest_length[sp->n_splines] = rest;
  if (sp->layer) sp->layer[sp->n_splines] = (uint8_t)layer;
  sp->first[n_splines] = n_nodes;
  sp->n_nodes = n_nodes;
  sp->n_splines = n_splines;
  sp->n_segments = n_nodes - n_splines;
  return LW_OK;
}

void lw_splines_compact(lw_splines *sp, const unsigned char *dead)
{
  size_t k = 0, w = 0;
  for (size_t i = 0; i < sp->n_splines; i++) {
    /* first[i + 1] is read before first[w <= i] is written */
    const size_t f = sp->first[i], nn = sp->first[i + 1] - f;
    if (dead[i]) continue;
    memmove(sp->node + k, sp->node + f, nn * sizeof *sp->node);
    sp->first[w] = k;
    sp->rest_length[w] = sp->rest_length[i];
    if (sp->layer) sp->layer[w] = sp->layer[i];
    k += nn;
    w++;
  }
  sp->first[w] = k;
  sp->n_splines = w;
  sp->n_nodes = k;
  sp->n_segments = k - w;
  for (size_t i = 0, g = 0; i < w; i++)
    for (size_t m = lw_splines_segments(sp, i); m > 0; m--) sp->seg_spline[g++] = (uint32_t)i;
}

int lw_splines_is_point(const lw_splines *sp, size_t i)
{
  const lw_node *nd = &sp->node[sp->first[i]];
  size_t nn = sp->first[i + 1] - sp->first[i];
  for (size_t k = 0; k < nn; k++)
    if (nd[k].px != nd[0].px || nd[k].py != nd[0].py || nd[k].vx != 0 || nd[k].vy != 0) return 0;
  return 1;
}

void lw_segment_eval(const lw_node *a, const lw_node *b, double s,
                     double r[2], double d1[2], double d2[2])
{
  double cp[4], c1[4], c2[4];
  lw_quad_basis(s, cp, c1, c2);
  if (r) {
    r[0] = cp[0] * a->px + cp[1] * a->vx + cp[2] * b->px + cp[3] * b->vx;
    r[1] = cp[0] * a->py + cp[1] * a->vy + cp[2] * b->py + cp[3] * b->vy;
  }
  if (d1) {
    d1[0] = c1[0] * a->px + c1[1] * a->vx + c1[2] * b->px + c1[3] * b->vx;
    d1[1] = c1[0] * a->py + c1[1] * a->vy + c1[2] * b->py + c1[3] * b->vy;
  }
  if (d2) {
    d2[0] = c2[0] * a->px + c2[1] * a->vx + c2[2] * b->px + c2[3] * b->vx;
    d2[1] = c2[0] * a->py + c2[1] * a->vy + c2[2] * b->py + c2[3] * b->vy;
  }
}

void lw_segment_sample(const lw_quad *q, const lw_node *a, const lw_node *b, lw_samples *out)
{
  const int n = q->n;
  double len = 0.0;
  out->n = n;
  for (int i = 0; i < n; i++) {
    const double *cp = q->pos[i], *c1 = q->d1[i], *c2 = q->d2[i];
    out->x[i] = cp[0] * a->px + cp[1] * a->vx + cp[2] * b->px + cp[3] * b->vx;
    out->y[i] = cp[0] * a->py + cp[1] * a->vy + cp[2] * b->py + cp[3] * b->vy;
    double dx = c1[0] * a->px + c1[1] * a->vx + c1[2] * b->px + c1[3] * b->vx;
    double dy = c1[0] * a->py + c1[1] * a->vy + c1[2] * b->py + c1[3] * b->vy;
    out->dx[i] = dx;
    out->dy[i] = dy;
    out->ddx[i] = c2[0] * a->px + c2[1] * a->vx + c2[2] * b->px + c2[3] * b->vx;
    out->ddy[i] = c2[0] * a->py + c2[1] * a->vy + c2[2] * b->py + c2[3] * b->vy;
    double sp = sqrt(dx * dx + dy * dy);
    out->speed[i] = sp;
    out->dl[i] = q->w[i] * sp;
    len += out->dl[i];
  }
  out->length = len;
  out->end_x[0] = a->px;
  out->end_y[0] = a->py;
  out->end_x[1] = b->px;
  out->end_y[1] = b->py;
  out->hand_x[0] = a->px + a->vx;
  out->hand_y[0] = a->py + a->vy;
  out->hand_x[1] = b->px - b->vx;
  out->hand_y[1] = b->py - b->vy;
}

void lw_shape_finish(const lw_arc_moments *m, double ex, double ey, const double t0[2], const double t1[2],
                     lw_spline_shape *out)
{
  const double len = m->len, n0 = hypot(t0[0], t0[1]), n1 = hypot(t1[0], t1[1]);
  out->length = len;
  out->rg2 = len > 0.0 ? fmax(m->m2 / len - (m->mx * m->mx + m->my * m->my) / (len * len), 0.0) : 0.0;
  out->end2 = ex * ex + ey * ey;
  out->end_cos = n0 > 0.0 && n1 > 0.0 ? (t0[0] * t1[0] + t0[1] * t1[1]) / (n0 * n1) : 0.0;
}

void lw_spline_shape_of(const lw_splines *sp, size_t i, const lw_quad *q, lw_spline_shape *out)
{
  const lw_node *nd = sp->node + sp->first[i], *last = sp->node + sp->first[i + 1] - 1;
  lw_arc_moments m = {0.0, 0.0, 0.0, 0.0};
  lw_samples smp;
  for (const lw_node *a = nd; a < last; a++) {
    lw_segment_sample(q, a, a + 1, &smp);
    for (int k = 0; k < smp.n; k++) lw_arc_moments_add(&m, smp.x[k] - nd->px, smp.y[k] - nd->py, smp.dl[k]);
  }
  const double t0[2] = {nd->vx, nd->vy}, t1[2] = {last->vx, last->vy};
  lw_shape_finish(&m, last->px - nd->px, last->py - nd->py, t0, t1, out);
}

int lw_splines_finite(const lw_splines *sp)
{
  for (size_t k = 0; k < sp->n_nodes; k++) {
    const lw_node *nd = &sp->node[k];
    if (!isfinite(nd->px) || !isfinite(nd->py) || !isfinite(nd->vx) || !isfinite(nd->vy))
      return 0;
  }
  return 1;
}

/* The hodograph's control points h0 h1 h2 (x, y each). */
static void hodograph(const lw_node *a, const lw_node *b, double h[6])
{
  h[0] = 3.0 * a->vx;
  h[1] = 3.0 * a->vy;
  h[2] = 3.0 * ((b->px - b->vx) - (a->px + a->vx));
  h[3] = 3.0 * ((b->py - b->vy) - (a->py + a->vy));
  h[4] = 3.0 * b->vx;
  h[5] = 3.0 * b->vy;
}

/* |h(t)|^2 of the quadratic Bezier h0 h1 h2. */
static double speed2_at(const double h[6], double t)
{
  double u = 1.0 - t, b0 = u * u, b1 = 2.0 * u * t, b2 = t * t;
  double x = b0 * h[0] + b1 * h[2] + b2 * h[4], y = b0 * h[1] + b1 * h[3] + b2 * h[5];
  return x * x + y * y;
}

double lw_segment_min_speed(const lw_node *a, const lw_node *b)
{
  double h[6];
  hodograph(a, b, h);
  /* h(t) = A + 2 B t + C t^2 */
  const double Ax = h[0], Ay = h[1], Bx = h[2] - h[0], By = h[3] - h[1];
  const double Cx = h[0] - 2.0 * h[2] + h[4], Cy = h[1] - 2.0 * h[3] + h[5];
  /* d|h|^2/dt / 4 = c3 t^3 + c2 t^2 + c1 t + c0 */
  const double c3 = Cx * Cx + Cy * Cy, c2 = 3.0 * (Bx * Cx + By * Cy);
  const double c1 = 2.0 * (Bx * Bx + By * By) + Ax * Cx + Ay * Cy, c0 = Ax * Bx + Ay * By;
  double best = fmin(speed2_at(h, 0.0), speed2_at(h, 1.0));
  double t[3];
  int n;
  /* A tiny leading coefficient makes the monic cubic's coefficients huge
  ** and its roots inaccurate; then the quadratic (or linear) part holds the
  ** roots that lie in [0, 1].  Newton steps below repair either choice. */
  const double scale = fabs(c2) + fabs(c1) + fabs(c0);
  if (c3 > 1e-9 * scale) n = gsl_poly_solve_cubic(c2 / c3, c1 / c3, c0 / c3, &t[0], &t[1], &t[2]);
  else n = gsl_poly_solve_quadratic(c2, c1, c0, &t[0], &t[1]);
  for (int i = 0; i < n; i++) {
    double x = t[i];
    for (int it = 0; it < 3; it++) {
      double f = ((c3 * x + c2) * x + c1) * x + c0, df = (3.0 * c3 * x + 2.0 * c2) * x + c1;
      if (!(df != 0.0)) break;
      double nx = x - f / df;
      if (!isfinite(nx)) break;
      x = nx;
    }
    if (x > 0.0 && x < 1.0) best = fmin(best, speed2_at(h, x));
  }
  return sqrt(best);
}

/* |h|^2 = sum_k c_k b^4_k(t), the quartic's Bernstein coefficients; the
** b^4_k are >= 0 and sum to 1, so min_k c_k <= |h|^2 <= max_k c_k.  1 if
** they are finite. */
static int speed2_bernstein(const double h[6], double c[5])
{
  c[0] = h[0] * h[0] + h[1] * h[1];
  c[1] = h[0] * h[2] + h[1] * h[3];
  c[2] = ((h[0] * h[4] + h[1] * h[5]) + 2.0 * (h[2] * h[2] + h[3] * h[3])) * (1.0 / 3.0);
  c[3] = h[2] * h[4] + h[3] * h[5];
  c[4] = h[4] * h[4] + h[5] * h[5];
  return isfinite(c[0] + c[1] + c[2] + c[3] + c[4]);
}

/* 1 if |h|^2 >= need on [0, 1] by the Bernstein bound, 0 if in doubt, -1
** for non-finite input. */
static int speed_bound(const double h[6], double need)
{
  double c[5];
  if (!speed2_bernstein(h, c)) return -1;
  /* plain comparisons: this runs for every new segment of every proposal */
  return c[0] >= need && c[1] >= need && c[2] >= need && c[3] >= need && c[4] >= need;
}

/* 1 if h_x + i h_y has no zero in the disc |t - 1/2| <= R (R2 = R^2), 0 if
** in doubt, -1 for non-finite input.  Around u = t - 1/2 it is
** P0 + P1 u + C u^2, |P0| the speed at the middle, |P1| that of r'' there,
** C = h0 - 2 h1 + h2; on |u| <= R it is at least |P0| - |P1| R - |C| R^2,
** > 0 when |P0|^2 > 2 (|P1|^2 R^2 + |C|^2 R^4) ((x + y)^2 <= 2 x^2 + 2 y^2). */
static int disc_bound(const double h[6], double R2)
{
  const double p0x = 0.25 * (h[0] + h[4]) + 0.5 * h[2], p0y = 0.25 * (h[1] + h[5]) + 0.5 * h[3];
  const double p1x = h[4] - h[0], p1y = h[5] - h[1];
  const double cx = h[0] - 2.0 * h[2] + h[4], cy = h[1] - 2.0 * h[3] + h[5];
  const double p0 = p0x * p0x + p0y * p0y, p1 = p1x * p1x + p1y * p1y, c2 = cx * cx + cy * cy;
  if (!isfinite(p0 + p1 + c2)) return -1;
  return p0 > 2.0 * R2 * (p1 + c2 * R2);
}

/* Bernstein ellipse parameter of the point t (foci 0 and 1): with
** z = 2t - 1, rho = |z + sqrt(z^2 - 1)| taken >= 1. */
static double ellipse_rho(double complex t)
{
  double complex z = 2.0 * t - 1.0, w = z + csqrt(z * z - 1.0);
  double r = cabs(w);
  return r >= 1.0 ? r : 1.0 / r;
}

double lw_segment_rho(const lw_node *a, const lw_node *b)
{
  double h[6];
  hodograph(a, b, h);
  /* h_x + i h_y = A + 2 B t + C t^2 with complex A, B, C */
  const double complex A = h[0] + I * h[1], B = (h[2] - h[0]) + I * (h[3] - h[1]);
  const double complex C = (h[0] - 2.0 * h[2] + h[4]) + I * (h[1] - 2.0 * h[3] + h[5]);
  if (!isfinite(creal(A) + cimag(A) + creal(B) + cimag(B) + creal(C) + cimag(C))) return NAN;
  /* roots of C t^2 + 2 B t + A: q = -(B + s sqrt(B^2 - A C)) with the sign
  ** that avoids cancellation, t1 = q / C, t2 = A / q (the stable pair;
  ** C = 0 leaves the linear root A / q = -A / 2B) */
  double complex d = csqrt(B * B - A * C), q = creal(conj(B) * d) >= 0.0 ? -(B + d) : -(B - d);
  if (q == 0.0) return A == 0.0 ? 1.0 : INFINITY; /* B = 0 and A C = 0 */
  double rho = ellipse_rho(A / q);
  if (C != 0.0) rho = fmin(rho, ellipse_rho(q / C));
  return rho;
}

/* 1 if no zero of h_x + i h_y lies inside the Bernstein ellipse of
** parameter rho (foci 0 and 1), 0 if one does or for non-finite input:
** lw_segment_rho(a, b) >= rho without its complex square roots and
** divisions (58 % of the checks' time in a profile of an anneal).  A point t
** is on or outside the ellipse where |t| + |t - 1| >= (rho + 1/rho) / 2, the
** sum of its distances to the foci; for the roots t1 = A / q and t2 = q / C
** of lw_segment_rho that is |A| + |A - q| >= s |q| and |q| + |q - C| >= s |C|
** (C = 0 passes: no second root).  The coefficients are first scaled by a
** power of two (exactly), so that no square overflows. */
static int roots_outside(const double h[6], double rho)
{
  double ax = h[0], ay = h[1], bx = h[2] - h[0], by = h[3] - h[1];
  double cx = h[0] - 2.0 * h[2] + h[4], cy = h[1] - 2.0 * h[3] + h[5];
  const double m = fmax(fmax(fmax(fabs(ax), fabs(ay)), fmax(fabs(bx), fabs(by))), fmax(fabs(cx), fabs(cy)));
  if (!(m > 0.0 && m <= DBL_MAX)) return 0; /* NaN or infinite; all 0: a point, zero everywhere */
  const int e = -ilogb(m);
  /* by one factor where 2^e is a double: the same single rounding as
  ** scalbn's, six library calls fewer on half of all segment checks */
  if (e >= DBL_MIN_EXP - 1 && e < DBL_MAX_EXP) {
    const double k = scalbn(1.0, e);
    ax *= k, ay *= k, bx *= k, by *= k, cx *= k, cy *= k;
  } else {
    ax = scalbn(ax, e), ay = scalbn(ay, e), bx = scalbn(bx, e), by = scalbn(by, e), cx = scalbn(cx, e);
    cy = scalbn(cy, e);
  }
  /* d = a square root of B^2 - A C (either: q's sign choice below makes up
  ** for it), from the half-angle formulas without cancellation */
  const double wr = (bx * bx - by * by) - (ax * cx - ay * cy), wi = 2.0 * bx * by - (ax * cy + ay * cx);
  const double r = sqrt(wr * wr + wi * wi);
  double dr, di;
  if (wr >= 0.0) {
    dr = sqrt(0.5 * (r + wr));
    di = dr > 0.0 ? wi / (2.0 * dr) : 0.0;
  } else {
    di = sqrt(0.5 * (r - wr));
    dr = wi / (2.0 * di);
  }
  const int plus = bx * dr + by * di >= 0.0;
  const double qx = plus ? -(bx + dr) : -(bx - dr), qy = plus ? -(by + di) : -(by - di);
  if (qx == 0.0 && qy == 0.0) return ax != 0.0 || ay != 0.0; /* B = 0, A C = 0: as lw_segment_rho */
  const double s = 0.5 * (rho + 1.0 / rho), q = sqrt(qx * qx + qy * qy);
  return sqrt(ax * ax + ay * ay) + sqrt((ax - qx) * (ax - qx) + (ay - qy) * (ay - qy)) >= s * q &&
         q + sqrt((qx - cx) * (qx - cx) + (qy - cy) * (qy - cy)) >= s * sqrt(cx * cx + cy * cy);
}

/* The Bernstein ellipse of parameter rho (foci 0 and 1) lies in the disc
** |t - 1/2| <= (rho + 1/rho) / 4: its semi-major axis. */
static double disc_radius2(double rho)
{
  double R = 0.25 * (rho + 1.0 / rho);
  return R * R;
}

double lw_segment_widest_gap(const lw_quad *q, const lw_node *a, const lw_node *b)
{
  double widest = 0.0, px = 0.0, py = 0.0;
  for (int i = 0; i < q->n; i++) {
    const double *c = q->pos[i];
    const double x = c[0] * a->px + c[1] * a->vx + c[2] * b->px + c[3] * b->vx;
    const double y = c[0] * a->py + c[1] * a->vy + c[2] * b->py + c[3] * b->vy;
    if (i > 0) {
      const double g = hypot(x - px, y - py);
      if (!(g <= widest)) widest = g; /* NaN wins */
    }
    px = x;
    py = y;
  }
  return widest;
}

int lw_segment_gaps_within(const lw_quad *q, const lw_node *a, const lw_node *b, double gap_max)
{
  double h[6], c[5];
  hodograph(a, b, h);
  if (!speed2_bernstein(h, c)) return 0;
  const double top = fmax(fmax(fmax(c[0], c[1]), fmax(c[2], c[3])), c[4]); /* >= |h|^2 */
  if (q->spacing * q->spacing * top <= gap_max * gap_max) return 1;
  return lw_segment_widest_gap(q, a, b) <= gap_max;
}

int lw_segment_check(const lw_node *a, const lw_node *b, double min_speed, double rho)
{
  double h[6];
  hodograph(a, b, h);
  if (min_speed > 0.0) {
    int clear = speed_bound(h, min_speed * min_speed);
    if (clear < 0 || (!clear && !(lw_segment_min_speed(a, b) >= min_speed))) return 0;
  }
  if (rho > 1.0) {
    int clear = disc_bound(h, disc_radius2(rho));
    if (clear < 0 || (!clear && !roots_outside(h, rho))) return 0;
  }
  return 1;
}
