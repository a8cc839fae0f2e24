/* walk.c -- the far sum and the near list of one sample over the cell grid (walk.h). */
#include "linewise/walk.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#if defined(__GNUC__)
#define l_unlikely(x) __builtin_expect(!!(x), 0)
#else
#define l_unlikely(x) (x)
#endif

/* Candidates scanned between looks at the far buffer: a flush at BLOCK or
** more entries leaves none, and a block adds at most BLOCK, so the buffer
** never holds more than 2 BLOCK - 1 (plus 3 entries of padding). */
#define BLOCK 64 /* the bits of a uint64_t */
#define BUF (2 * BLOCK + 4)

typedef double v2d __attribute__((vector_size(16)));

/* sqrt is correctly rounded in SSE2 and in C alike, so both branches give
** the same bits. */
static inline v2d vsqrt(v2d a)
{
#if defined(__SSE2__)
  return (v2d)_mm_sqrt_pd((__m128d)a);
#else
  return (v2d){sqrt(a[0]), sqrt(a[1])};
#endif
}

static inline v2d load2(const double *p)
{
  v2d v;
  memcpy(&v, p, sizeof v);
  return v;
}

/*
** Sum of w[k] (1/sqrt(r2[k]) - ic) over k < m: the only part of the walk
** that needs square roots and divisions, on far pairs only.  Two
** accumulators of two lanes hide the latency of the divider; the entries
** are padded to a multiple of four with w = 0, which adds exact zeros.
*/
static double flush(double *r2, double *w, uint32_t m, double ic)
{
  for (; m & 3; m++) {
    r2[m] = 1.0;
    w[m] = 0.0;
  }
  const v2d one = {1.0, 1.0}, icv = {ic, ic};
  v2d s0 = {0.0, 0.0}, s1 = {0.0, 0.0};
  for (uint32_t k = 0; k < m; k += 4) {
    s0 += load2(w + k) * (one / vsqrt(load2(r2 + k)) - icv);
    s1 += load2(w + k + 2) * (one / vsqrt(load2(r2 + k + 2)) - icv);
  }
  v2d s = s0 + s1;
  return s[0] + s[1];
}

typedef long long v2l __attribute__((vector_size(16)));
typedef float v4f __attribute__((vector_size(16)));
typedef int v4i __attribute__((vector_size(16)));
typedef unsigned v4u __attribute__((vector_size(16)));

/* One bit per lane of a comparison's result. */
static inline unsigned bits2(v2l m)
{
#if defined(__SSE2__)
  return (unsigned)_mm_movemask_pd((__m128d)m);
#else
  return (unsigned)(m[0] & 1) | (unsigned)(m[1] & 2);
#endif
}

/* Lanes 0, 1 (lo) or 2, 3 (hi) of v as doubles (cvtps2pd; GCC's generic
** conversion goes through the stack). */
static inline v2d lo2d(v4f v)
{
#if defined(__SSE2__)
  return (v2d)_mm_cvtps_pd((__m128)v);
#else
  return (v2d){v[0], v[1]};
#endif
}

static inline v2d hi2d(v4f v)
{
#if defined(__SSE2__)
  return (v2d)_mm_cvtps_pd(_mm_movehl_ps((__m128)v, (__m128)v));
#else
  return (v2d){v[2], v[3]};
#endif
}

/* A 32-bit lane mask widened to 64-bit lanes: lanes 0, 1 (lo) or 2, 3 (hi). */
static inline v2l lo2l(v4i m) { return (v2l)__builtin_shufflevector(m, m, 0, 0, 1, 1); }
static inline v2l hi2l(v4i m) { return (v2l)__builtin_shufflevector(m, m, 2, 2, 3, 3); }

/* What the scan of a cell reads besides the cell: the probe and the
** kernel's constants in every lane, set up once per walk. */
typedef struct {
  v2d x, y;
  v2d rc2;        /* far pairs need r^2 < rc2; -1 for a weightless probe */
  v2d ns;         /* near_scale */
  v4f dl;
  /* own spline: idx - lo < span, unsigned; SSE2 compares signed 32-bit
  ** lanes, so both sides carry the sign bit flipped: idx - (lo + 2^31) and
  ** span - 2^31, as int */
  v4u lo_flip;
  v4i span_flip;
  v4i from_flip;  /* idx >= from, flipped alike: idx - 2^31 >= from - 2^31 */
} scan_ctx;

#define FLIP 0x80000000u

/*
** Entries [k0, k1) of cell c, k1 - k0 <= BLOCK: far candidates are appended
** to (r2b, wb) from m on, near ones to nidx from *nn on (room for k1 - k0 is
** there).  The tests run on four entries at a time (two SSE2 vectors of
** doubles, one of 32-bit lanes) and leave one bit per entry; the kept
** entries are then copied by walking the set bits, so the geometry costs
** no mispredicted branches.  Groups read past k1 (the cell's block is
** padded, grid.h); those lanes are masked off.  `with_near` and
** `with_from` are constants at each call, so the common scan carries
** neither test.
*/
static inline __attribute__((always_inline)) uint32_t
scan(const lw_cell *c, uint32_t k0, uint32_t k1, const scan_ctx *s, double *r2b, double *wb, uint32_t m,
     uint32_t *nidx, size_t *nn, const int with_near, const int with_from)
{
  _Alignas(16) double r2t[BLOCK];
  const double *xs = c->x, *ys = lw_cell_y(c);
  const uint32_t *id = lw_cell_idx(c);
  const float *dls = lw_cell_dl(c);
  const v2d px = s->x, py = s->y, rc2 = s->rc2, ns = s->ns;
  const v4f dl = s->dl, zero = {0.0f, 0.0f, 0.0f, 0.0f};
  const v4u lo = s->lo_flip, flip = {FLIP, FLIP, FLIP, FLIP};
  const v4i span = s->span_flip, from = s->from_flip;
  uint64_t far_bits = 0, near_bits = 0;
  for (uint32_t k = k0, t = 0; k < k1; k += 4, t += 4) {
    v4u j;
    v4f dlj;
    memcpy(&j, id + k, sizeof j);
    memcpy(&dlj, dls + k, sizeof dlj);
    v4i own = (v4i)(j - lo) < span;
    v4i ok = ~own & (v4i)(dlj > zero);
    if (with_from) ok &= (v4i)(j ^ flip) >= from;
    v2d dx0 = load2(xs + k) - px, dx1 = load2(xs + k + 2) - px;
    v2d dy0 = load2(ys + k) - py, dy1 = load2(ys + k + 2) - py;
    v2d r0 = dx0 * dx0 + dy0 * dy0, r1 = dx1 * dx1 + dy1 * dy1;
    memcpy(r2t + t, &r0, sizeof r0);
    memcpy(r2t + t + 2, &r1, sizeof r1);
    v2l f0 = (r0 < rc2) & lo2l(ok), f1 = (r1 < rc2) & hi2l(ok);
    if (with_near) {
      /* the kernel's own test: max of the float weights, then in double */
      v4i big = dlj > dl;
      v4f dm = (v4f)(((v4i)dlj & big) | ((v4i)dl & ~big));
      v2d l0 = ns * lo2d(dm), l1 = ns * hi2d(dm);
      v2l n0 = (r0 < l0 * l0) & ~lo2l(own), n1 = (r1 < l1 * l1) & ~hi2l(own);
      f0 &= ~n0;
      f1 &= ~n1;
      near_bits |= (uint64_t)(bits2(n0) | bits2(n1) << 2) << t;
    }
    far_bits |= (uint64_t)(bits2(f0) | bits2(f1) << 2) << t;
  }
  /* the lanes past k1 of the last group */
  uint64_t valid = k1 - k0 == BLOCK ? ~(uint64_t)0 : ((uint64_t)1 << (k1 - k0)) - 1;
  far_bits &= valid;
  near_bits &= valid;
  for (; far_bits; far_bits &= far_bits - 1) {
    unsigned t = (unsigned)__builtin_ctzll(far_bits);
    r2b[m] = r2t[t];
    wb[m] = (double)dls[k0 + t];
    m++;
  }
  if (with_near) {
    size_t n_near = *nn;
    for (; near_bits; near_bits &= near_bits - 1) nidx[n_near++] = id[k0 + (unsigned)__builtin_ctzll(near_bits)];
    *nn = n_near;
  }
  return m;
}

void lw_pair_nearlist_free(lw_pair_nearlist *l)
{
  free(l->idx);
  l->idx = NULL;
  l->n = l->cap = 0;
}

static lw_status nearlist_reserve(lw_pair_nearlist *l, size_t more)
{
  if (l->cap - l->n >= more) return LW_OK;
  size_t cap = l->cap ? 2 * l->cap : 64;
  while (cap - l->n < more) cap *= 2;
  uint32_t *idx = realloc(l->idx, cap * sizeof *idx);
  if (!idx) return LW_ENOMEM;
  l->idx = idx;
  l->cap = cap;
  return LW_OK;
}

/* Squared gaps along one axis between p, in cell c of the axis starting at
** a with cells of side h, and the cells c - 1, c, c + 1: gap[0], 0, gap[2].
** Only the sides facing p count, and those are true bounds even for edge
** cells, which hold the points clamped from beyond the grid on their outer
** sides. */
static void axis_gaps(double a, double h, int c, double p, double gap[3])
{
  double below = p - (a + c * h), above = a + (c + 1) * h - p;
  gap[0] = below * below;
  gap[1] = 0.0;
  gap[2] = above * above;
}

/* Cells are skipped when their gap exceeds the cutoff by this factor: a
** point sits in its cell up to the rounding of (x - x0) / h. */
#define GAP_MARGIN (1.0 + 1e-9)

lw_status lw_pair_walk(const lw_cellgrid *g, const lw_pair_ctx *ctx, const lw_pair_probe *P, double *far,
                       lw_pair_nearlist *near)
{
  _Alignas(16) double r2b[BUF], wb[BUF];
  /* a weightless probe has no far pairs (its kernel is 0, even at r = 0) */
  const double rc2 = P->dl != 0.0f ? ctx->cutoff2 : -1.0, ns = ctx->near_scale;
  const uint32_t lo = P->lo + FLIP;
  const int span = (int)((P->hi - P->lo) ^ FLIP), from = (int)(P->from ^ FLIP);
  const scan_ctx s = {{P->x, P->x}, {P->y, P->y}, {rc2, rc2}, {ns, ns}, {P->dl, P->dl, P->dl, P->dl},
                      {lo, lo, lo, lo}, {span, span, span, span}, {from, from, from, from}};
  const double ic = ctx->inv_cutoff, h = 1.0 / g->inv_h, skip2 = ctx->cutoff2 * GAP_MARGIN;
  double gx[3], gy[3];
  const int with_near = ns > 0.0, with_from = P->from > 0;
  double sum = 0.0;
  uint32_t m = 0;
  *far = 0.0;
  int cx, cy;
  lw_cellgrid_locate(g, P->x, P->y, &cx, &cy);
  const int x0 = cx > 0 ? cx - 1 : 0, x1 = cx + 1 < g->nx ? cx + 1 : g->nx - 1;
  const int y0 = cy > 0 ? cy - 1 : 0, y1 = cy + 1 < g->ny ? cy + 1 : g->ny - 1;
  axis_gaps(g->x0, h, cx, P->x, gx);
  axis_gaps(g->y0, h, cy, P->y, gy);
  for (int y = y0; y <= y1; y++) {
    const lw_cell *row = g->cell + (size_t)y * (size_t)g->nx;
    for (int x = x0; x <= x1; x++) {
      const lw_cell *c = row + x;
      if (!c->n || gx[x - cx + 1] + gy[y - cy + 1] > skip2) continue;
      for (uint32_t k0 = 0; k0 < c->n; k0 += BLOCK) {
        uint32_t k1 = c->n - k0 > BLOCK ? k0 + BLOCK : c->n;
        if (with_near) {
          if (l_unlikely(nearlist_reserve(near, k1 - k0) != LW_OK)) return LW_ENOMEM;
          m = with_from ? scan(c, k0, k1, &s, r2b, wb, m, near->idx, &near->n, 1, 1)
                        : scan(c, k0, k1, &s, r2b, wb, m, near->idx, &near->n, 1, 0);
        } else {
          m = with_from ? scan(c, k0, k1, &s, r2b, wb, m, NULL, NULL, 0, 1)
                        : scan(c, k0, k1, &s, r2b, wb, m, NULL, NULL, 0, 0);
        }
        if (m >= BLOCK) {
          sum += flush(r2b, wb, m, ic);
          m = 0;
        }
      }
    }
  }
  sum += flush(r2b, wb, m, ic);
  *far = (double)P->dl * sum;
  return LW_OK;
}
