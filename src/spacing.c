/* spacing.c -- the close share of a drawing (spacing.h). */
#include "linewise/spacing.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>


/* Point and speed of the cubic Bezier with control points b at t. */
static void bezier_at(const double b[8], double t, double *x, double *y, double *speed)
{
  double u = 1.0 - t, c0 = u * u * u, c1 = 3 * u * u * t, c2 = 3 * u * t * t, c3 = t * t * t;
  *x = c0 * b[0] + c1 * b[2] + c2 * b[4] + c3 * b[6];
  *y = c0 * b[1] + c1 * b[3] + c2 * b[5] + c3 * b[7];
  double d0 = 3 * u * u, d1 = 6 * u * t, d2 = 3 * t * t;
  double dx = d0 * (b[2] - b[0]) + d1 * (b[4] - b[2]) + d2 * (b[6] - b[4]);
  double dy = d0 * (b[3] - b[1]) + d1 * (b[5] - b[3]) + d2 * (b[7] - b[5]);
  *speed = hypot(dx, dy);
}

/* Pieces of a segment with control points b: by its control polygon's
** length, which is at least the curve's. */
static size_t pieces(const double b[8], double h)
{
  double l = hypot(b[2] - b[0], b[3] - b[1]) + hypot(b[4] - b[2], b[5] - b[3]) + hypot(b[6] - b[4], b[7] - b[5]);
  double k = ceil(l / h);
  if (!(k >= 1.0)) return 1; /* NaN too */
  return k > LW_SPACING_POINTS_MAX ? LW_SPACING_POINTS_MAX : (size_t)k;
}

/* The cell of (x, y) in a grid of nx columns of side c from (x0, y0). */
static size_t cell_of(double x, double y, double x0, double y0, double c, size_t nx, size_t ny)
{
  size_t cx = (size_t)fmax(0.0, floor((x - x0) / c)), cy = (size_t)fmax(0.0, floor((y - y0) / c));
  return (cy < ny ? cy : ny - 1) * nx + (cx < nx ? cx : nx - 1);
}

/* The points in flat arrays sorted by cell (a counting sort), 40 bytes a
** point: a drawing of 10^5 splines has 1.4e7 of them, and the
** score comes after the run, which it must not fail for want of memory.
** Within a cell a run of one stroke's points is stepped over at once (skip):
** a stroke that winds over itself (a vortex, a spiral) filled its cells
** with its own points, which every point scanned and none counted, and one
** spline of 100,000 segments spent 60 % of its output there. */
lw_status lw_close_share(const double *b, const size_t *owner, const size_t *group, size_t n_seg, double d,
                         double *share, lw_error *err)
{
  *share = 0.0;
  const double h = 0.5 * d;
  size_t n = 0;
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  for (size_t g = 0; g < n_seg; g++) {
    const double *z = b + 8 * g;
    n += pieces(z, h);
    if (owner[g] >= UINT32_MAX || (group && group[g] >= UINT32_MAX))
      return lw_error_set(err, LW_EINPUT, "close share: stroke %zu exceeds the limit of 2^32", owner[g]);
    for (int k = 0; k < 8; k += 2) {
      x0 = fmin(x0, z[k]);
      x1 = fmax(x1, z[k]);
      y0 = fmin(y0, z[k + 1]);
      y1 = fmax(y1, z[k + 1]);
    }
  }
  if (n == 0) return LW_OK;
  if (n >= UINT32_MAX)
    return lw_error_set(err, LW_EINPUT, "close share: %zu points exceed the grid's limit of 2^32", n);
  /* cells at least d wide (a close point lies in the 3 x 3 around), and no
  ** more of them than points */
  double c = d, w = x1 - x0, ht = y1 - y0;
  if ((w / c + 1.0) * (ht / c + 1.0) > (double)n) c = fmax(c, sqrt(fmax(w * ht, d * d) / (double)n));
  const size_t nx = (size_t)floor(w / c) + 1, ny = (size_t)floor(ht / c) + 1, cells = nx * ny;
  double *px = malloc(n * sizeof *px), *py = malloc(n * sizeof *py);
  float *len = malloc(n * sizeof *len);
  uint32_t *who = malloc(n * sizeof *who), *grp = group ? malloc(n * sizeof *grp) : NULL;
  uint32_t *order = malloc(n * sizeof *order), *start = calloc(cells + 1, sizeof *start);
  uint32_t *skip = malloc(n * sizeof *skip);
  lw_status st = LW_OK;
  if (!px || !py || !len || !who || (group && !grp) || !order || !start || !skip) {
    st = lw_error_set(err, LW_ENOMEM, "out of memory for the close share of %zu points", n);
    goto done;
  }
  size_t i = 0;
  for (size_t g = 0; g < n_seg; g++) {
    const double *z = b + 8 * g;
    size_t k = pieces(z, h);
    for (size_t q = 0; q < k; q++, i++) {
      double x, y, speed;
      bezier_at(z, ((double)q + 0.5) / (double)k, &x, &y, &speed);
      px[i] = x;
      py[i] = y;
      len[i] = (float)(speed / (double)k);
      who[i] = (uint32_t)owner[g];
      if (grp) grp[i] = (uint32_t)group[g];
      start[cell_of(px[i], py[i], x0, y0, c, nx, ny) + 1]++;
    }
  }
  for (size_t q = 0; q < cells; q++) start[q + 1] += start[q];
  for (size_t p = 0; p < n; p++) order[start[cell_of(px[p], py[p], x0, y0, c, nx, ny)]++] = (uint32_t)p;
  for (size_t q = cells; q > 0; q--) start[q] = start[q - 1]; /* the fill advanced each start to the next */
  start[0] = 0;
  /* skip[e]: the first entry after e in its cell of another stroke's point */
  for (size_t q = 0; q < cells; q++)
    for (uint32_t e = start[q + 1]; e-- > start[q];)
      skip[e] = e + 1 < start[q + 1] && who[order[e + 1]] == who[order[e]] ? skip[e + 1] : e + 1;
  double close = 0.0, all = 0.0;
  const double d2 = d * d;
  /* the point's own cell first, where a close point most likely lies:
  ** strokes piled on one place (16,000 alike) filled the cell before it
  ** with points a little past d, which each point scanned first, O(n) */
  static const int off[9][2] = {{0, 0}, {-1, -1}, {0, -1}, {1, -1}, {-1, 0}, {1, 0}, {-1, 1}, {0, 1}, {1, 1}};
  for (size_t p = 0; p < n; p++) {
    const size_t cp = cell_of(px[p], py[p], x0, y0, c, nx, ny), cx = cp % nx, cy = cp / nx;
    int found = 0;
    for (int k = 0; !found && k < 9; k++) {
      if ((off[k][0] < 0 && cx == 0) || (off[k][1] < 0 && cy == 0) || (off[k][0] > 0 && cx + 1 == nx) ||
          (off[k][1] > 0 && cy + 1 == ny))
        continue;
      const size_t x = (size_t)((long)cx + off[k][0]), y = (size_t)((long)cy + off[k][1]);
      for (uint32_t e = start[y * nx + x]; e < start[y * nx + x + 1];) {
        const uint32_t o = order[e];
        if (who[o] == who[p]) {
          e = skip[e];
          continue;
        }
        const double dx = px[o] - px[p], dy = py[o] - py[p];
        if ((!grp || grp[o] == grp[p]) && dx * dx + dy * dy < d2) {
          found = 1;
          break;
        }
        e++;
      }
    }
    all += len[p];
    if (found) close += len[p];
  }
  *share = all > 0.0 ? close / all : 0.0;
done:
  free(px);
  free(py);
  free(len);
  free(who);
  free(grp);
  free(order);
  free(start);
  free(skip);
  return st;
}

lw_status lw_close_share_splines(const lw_splines *sp, double d, double *share, lw_error *err)
{
  size_t n = sp->n_segments ? sp->n_segments : 1;
  double *b = malloc(8 * n * sizeof *b);
  size_t *owner = malloc(n * sizeof *owner);
  lw_status s = LW_ENOMEM;
  if (b && owner) {
    for (size_t g = 0; g < sp->n_segments; g++) {
      const lw_node *a = &sp->node[lw_segment_node(sp, g)];
      lw_segment_bezier(a, a + 1, b + 8 * g);
      owner[g] = sp->seg_spline[g];
    }
    s = lw_close_share(b, owner, NULL, sp->n_segments, d, share, err);
  } else {
    lw_error_set(err, LW_ENOMEM, "out of memory for the close share of %zu segments", sp->n_segments);
  }
  free(b);
  free(owner);
  return s;
}

/* The power form q0 + q1 t + q2 t^2 + q3 t^3 of one coordinate (offset 0
** for x, 1 for y) of the cubic Bezier b. */
static void power_form(const double b[8], int o, double q[4])
{
  q[0] = b[o];
  q[1] = 3.0 * (b[2 + o] - b[o]);
  q[2] = 3.0 * (b[o] - 2.0 * b[2 + o] + b[4 + o]);
  q[3] = b[6 + o] - b[o] + 3.0 * (b[2 + o] - b[4 + o]);
}

#define LW_BEZIER_STEPS 16    /* steps of the local search */
#define LW_BEZIER_TRUST 0.125 /* the longest step in either parameter */
#define LW_BEZIER_TRIES 12    /* dampings of one step, tenfold each */

/* a(s) - b(t) for the power forms, and the two columns of its Jacobian */
static void gap_at(const double q[4][4], double s, double t, double e[2], double ja[2], double jb[2])
{
  for (int o = 0; o < 2; o++) {
    const double *a = q[o], *b = q[2 + o];
    e[o] = a[0] + s * (a[1] + s * (a[2] + s * a[3])) - (b[0] + t * (b[1] + t * (b[2] + t * b[3])));
    ja[o] = a[1] + s * (2.0 * a[2] + 3.0 * s * a[3]);
    jb[o] = -(b[1] + t * (2.0 * b[2] + 3.0 * t * b[3]));
  }
}

/* The least squared distance between the curves a and b that a local
** search finds from the parameters (s, t): Levenberg-Marquardt on
** a(s) - b(t), steps of at most LW_BEZIER_TRUST in either parameter, a side
** whose step would leave [0, 1] held at its end; the least value met. */
static double bezier_distance2(const double a[8], const double b[8], double s, double t)
{
  /* Levenberg-Marquardt on the gap e(s, t) = a(s) - b(t): undamped where
  ** the curves cross it is Newton's method for e = 0 (quadratic), elsewhere
  ** it converges as fast as the curves are straight on the scale of their
  ** distance.  Along nearly parallel curves J'J is nearly singular and the
  ** undamped step runs far along the valley: a step that does not lower
  ** |e| is damped tenfold and tried again. */
  double q[4][4];
  power_form(a, 0, q[0]), power_form(a, 1, q[1]), power_form(b, 0, q[2]), power_form(b, 1, q[3]);
  double e[2], ja[2], jb[2];
  gap_at(q, s, t, e, ja, jb);
  double best = e[0] * e[0] + e[1] * e[1], damp = 1e-12;
  for (int it = 0; it < LW_BEZIER_STEPS && best > 0.0; it++) {
    const double gs = ja[0] * e[0] + ja[1] * e[1], gt = jb[0] * e[0] + jb[1] * e[1];
    const double hss = ja[0] * ja[0] + ja[1] * ja[1], htt = jb[0] * jb[0] + jb[1] * jb[1];
    const double hst = ja[0] * jb[0] + ja[1] * jb[1];
    /* a side at its end with the descent pointing out stays there */
    const int free_s = !((s <= 0.0 && gs > 0.0) || (s >= 1.0 && gs < 0.0)) && hss > 0.0;
    const int free_t = !((t <= 0.0 && gt > 0.0) || (t >= 1.0 && gt < 0.0)) && htt > 0.0;
    if (!free_s && !free_t) break; /* held at a corner */
    int taken = 0;
    for (int tries = 0; tries < LW_BEZIER_TRIES && !taken; tries++, damp = damp < 1e-6 ? 1e-6 : 10.0 * damp) {
      const double mu = damp * (hss + htt);
      double ds = free_s ? -gs / (hss + mu) : 0.0, dt = free_t ? -gt / (htt + mu) : 0.0;
      if (free_s && free_t) {
        const double det = (hss + mu) * (htt + mu) - hst * hst;
        const double js = -((htt + mu) * gs - hst * gt) / det, jt = -((hss + mu) * gt - hst * gs) / det;
        /* a side at its end that the joint step would push out is held */
        const int out_s = (s <= 0.0 && js < 0.0) || (s >= 1.0 && js > 0.0);
        const int out_t = (t <= 0.0 && jt < 0.0) || (t >= 1.0 && jt > 0.0);
        if (out_s && out_t) ds = dt = 0.0;
        else if (out_t) dt = 0.0;
        else if (out_s) ds = 0.0;
        else ds = js, dt = jt;
      }
      /* a trust region: a long step on a bent curve can fall into another
      ** valley, lower than the start but not the nearest one's floor; more
      ** damping turns the step towards the descent as it shortens it */
      const double longest = fmax(fabs(ds), fabs(dt));
      if (longest > LW_BEZIER_TRUST && tries < LW_BEZIER_TRIES - 1) continue;
      double step = longest > LW_BEZIER_TRUST ? LW_BEZIER_TRUST / longest : 1.0;
      /* to the box's side at most: along the step the model falls all the
      ** way, and the next step holds that side if the descent points out */
      if (s + ds > 1.0) step = fmin(step, (1.0 - s) / ds);
      if (s + ds < 0.0) step = fmin(step, -s / ds);
      if (t + dt > 1.0) step = fmin(step, (1.0 - t) / dt);
      if (t + dt < 0.0) step = fmin(step, -t / dt);
      const double s1 = fmin(1.0, fmax(0.0, s + step * ds)), t1 = fmin(1.0, fmax(0.0, t + step * dt));
      double e1[2], ja1[2], jb1[2];
      gap_at(q, s1, t1, e1, ja1, jb1);
      const double f1 = e1[0] * e1[0] + e1[1] * e1[1];
      if (f1 < best) {
        best = f1, s = s1, t = t1, taken = 1;
        e[0] = e1[0], e[1] = e1[1], ja[0] = ja1[0], ja[1] = ja1[1], jb[0] = jb1[0], jb[1] = jb1[1];
      }
    }
    if (!taken) break;
    damp = fmax(1e-12, 0.01 * damp); /* the loop's last step raised it once more */
  }
  return best;
}

/* The least squared distance between the segments [p0, p1] and [q0, q1],
** and the parameters (*u, *v) in [0, 1] of the nearest points (Ericson,
** Real-Time Collision Detection, 5.1.9: the nearest points of the lines,
** clamped to one segment and projected on the other). */
static double chords_distance2(const double p0[2], const double p1[2], const double q0[2], const double q1[2],
                               double *u, double *v)
{
  const double d1[2] = {p1[0] - p0[0], p1[1] - p0[1]}, d2[2] = {q1[0] - q0[0], q1[1] - q0[1]};
  const double r[2] = {p0[0] - q0[0], p0[1] - q0[1]};
  const double a = d1[0] * d1[0] + d1[1] * d1[1], e = d2[0] * d2[0] + d2[1] * d2[1], f = d2[0] * r[0] + d2[1] * r[1];
  double s = 0.0, t = 0.0;
  if (a == 0.0) {
    t = e > 0.0 ? fmin(1.0, fmax(0.0, f / e)) : 0.0;
  } else {
    const double c = d1[0] * r[0] + d1[1] * r[1];
    if (e == 0.0) {
      s = fmin(1.0, fmax(0.0, -c / a));
    } else {
      const double b = d1[0] * d2[0] + d1[1] * d2[1], denom = a * e - b * b;
      s = denom > 0.0 ? fmin(1.0, fmax(0.0, (b * f - c * e) / denom)) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) t = 0.0, s = fmin(1.0, fmax(0.0, -c / a));
      else if (t > 1.0) t = 1.0, s = fmin(1.0, fmax(0.0, (b - c) / a));
    }
  }
  const double x = r[0] + s * d1[0] - t * d2[0], y = r[1] + s * d1[1] - t * d2[1];
  *u = s, *v = t;
  return x * x + y * y;
}

/* The greatest |c''(t)| on [0, 1]: c'' is linear between
** 6 (c0 - 2 c1 + c2) and 6 (c1 - 2 c2 + c3). */
static double bend_bound(const double c[8])
{
  return 6.0 * fmax(hypot(c[0] - 2.0 * c[2] + c[4], c[1] - 2.0 * c[3] + c[5]),
                    hypot(c[2] - 2.0 * c[4] + c[6], c[3] - 2.0 * c[5] + c[7]));
}

#define LW_POLY_MAX 16 /* pieces of a curve's polygon */

/* n + 1 points of the curve c at t = k / n, as x y pairs. */
static void polygon_of(const double c[8], int n, double *xy)
{
  for (int k = 0; k <= n; k++) {
    const double t = (double)k / n, u = 1.0 - t;
    const double w0 = u * u * u, w1 = 3.0 * u * u * t, w2 = 3.0 * u * t * t, w3 = t * t * t;
    xy[2 * k] = w0 * c[0] + w1 * c[2] + w2 * c[4] + w3 * c[6];
    xy[2 * k + 1] = w0 * c[1] + w1 * c[3] + w2 * c[5] + w3 * c[7];
  }
}

/* 1 if the control points of a and b, projected on the chord of c and on
** its normal, lie d or more apart on either: the curves lie in the convex
** hulls of their control points, so they are d or more apart too. */
static int parted_along(const double c[8], const double a[8], const double b[8], double d)
{
  const double tx = c[6] - c[0], ty = c[7] - c[1];
  const double len = sqrt(tx * tx + ty * ty);
  if (!(len > 0.0)) return 0;
  const double ux = tx / len, uy = ty / len;
  double lo[2][2] = {{INFINITY, INFINITY}, {INFINITY, INFINITY}};
  double hi[2][2] = {{-INFINITY, -INFINITY}, {-INFINITY, -INFINITY}};
  for (int k = 0; k < 8; k += 2)
    for (int w = 0; w < 2; w++) {
      const double *p = w ? b : a;
      const double along = ux * p[k] + uy * p[k + 1], across = ux * p[k + 1] - uy * p[k];
      lo[w][0] = along < lo[w][0] ? along : lo[w][0], hi[w][0] = along > hi[w][0] ? along : hi[w][0];
      lo[w][1] = across < lo[w][1] ? across : lo[w][1], hi[w][1] = across > hi[w][1] ? across : hi[w][1];
    }
  for (int axis = 0; axis < 2; axis++)
    if (lo[1][axis] - hi[0][axis] >= d || lo[0][axis] - hi[1][axis] >= d) return 1;
  return 0;
}

double lw_bezier_near2(const double a[8], const double b[8], double d)
{
  /* First the hulls of the control points on the chords' axes, which part
  ** most neighbours of a line.  Then polygons of the curves: a piece of
  ** parameter length h lies within h^2 / 8 max|c''| of its chord (the
  ** interpolation error of a straight line, by components of its integral
  ** form), so the polygons' distance less both bounds is a lower bound of
  ** the curves'; fine enough for a twentieth of d, their nearest points
  ** start the local search. */
  if (parted_along(a, a, b, d) || parted_along(b, a, b, d)) return INFINITY;
  const double ma = bend_bound(a), mb = bend_bound(b);
  double u, v;
  const double tol = 0.05 * d;
  const int na = (int)fmin(LW_POLY_MAX, fmax(1.0, ceil(sqrt(ma / (8.0 * tol)))));
  const int nb = (int)fmin(LW_POLY_MAX, fmax(1.0, ceil(sqrt(mb / (8.0 * tol)))));
  double pa[2 * (LW_POLY_MAX + 1)], pb[2 * (LW_POLY_MAX + 1)];
  polygon_of(a, na, pa);
  polygon_of(b, nb, pb);
  double least = INFINITY, s0 = 0.0, t0 = 0.0;
  for (int i = 0; i < na; i++)
    for (int j = 0; j < nb; j++) {
      const double dd = chords_distance2(pa + 2 * i, pa + 2 * i + 2, pb + 2 * j, pb + 2 * j + 2, &u, &v);
      if (dd < least) least = dd, s0 = (i + u) / na, t0 = (j + v) / nb;
    }
  if (sqrt(least) - 0.125 * (ma / ((double)na * na) + mb / ((double)nb * nb)) >= d) return INFINITY;
  return bezier_distance2(a, b, s0, t0);
}
