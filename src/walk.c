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
#define BLOCK 64
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

/* What the scan of a cell reads besides the cell: the probe and the
** kernel's constants, copied to locals once per walk. */
typedef struct {
  double x, y;
  double rc2;        /* far pairs need r^2 < rc2; -1 for a weightless probe */
  double ns;         /* near_scale */
  float dl;
  uint32_t lo, span; /* own spline: (idx - lo) < span, unsigned */
  uint32_t from;
} scan_ctx;

/*
** Entries [k0, k1) of cell c: far candidates go to (r2b, wb) from m on,
** near ones to nidx from *nn on (room for k1 - k0 is there).  Branch-free:
** every entry is written and the count advances by its test, so the
** unpredictable geometry costs no mispredictions.  `with_near` is a
** constant at each call, so the near-free scan carries none of it.
*/
static inline __attribute__((always_inline)) uint32_t
scan(const lw_cell *c, uint32_t k0, uint32_t k1, const scan_ctx *s, double *r2b, double *wb, uint32_t m,
     uint32_t *nidx, size_t *nn, const int with_near)
{
  const double *xs = c->x, *ys = lw_cell_y(c);
  const uint32_t *id = lw_cell_idx(c);
  const float *dls = lw_cell_dl(c);
  const double px = s->x, py = s->y, rc2 = s->rc2, ns = s->ns;
  const float dl = s->dl;
  const uint32_t lo = s->lo, span = s->span, from = s->from;
  size_t n_near = with_near ? *nn : 0;
  for (uint32_t k = k0; k < k1; k++) {
    double dx = xs[k] - px, dy = ys[k] - py;
    double r2 = dx * dx + dy * dy;
    float dlj = dls[k];
    uint32_t j = id[k];
    int other = j - lo >= span;
    int keep = other & (r2 < rc2) & (j >= from) & (dlj != 0.0f);
    if (with_near) {
      double lim = ns * (double)(dlj > dl ? dlj : dl);
      int near = other & (r2 < lim * lim);
      nidx[n_near] = j;
      n_near += (size_t)near;
      keep &= !near;
    }
    r2b[m] = r2;
    wb[m] = (double)dlj;
    m += (uint32_t)keep;
  }
  if (with_near) *nn = n_near;
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

lw_status lw_pair_walk(const lw_cellgrid *g, const lw_pair_ctx *ctx, const lw_pair_probe *P, double *far,
                       lw_pair_nearlist *near)
{
  _Alignas(16) double r2b[BUF], wb[BUF];
  /* a weightless probe has no far pairs (its kernel is 0, even at r = 0) */
  const scan_ctx s = {P->x, P->y, P->dl != 0.0f ? ctx->cutoff2 : -1.0, ctx->near_scale, P->dl,
                      P->lo, P->hi - P->lo, P->from};
  const double ic = ctx->inv_cutoff;
  const int with_near = ctx->near_scale > 0.0;
  double sum = 0.0;
  uint32_t m = 0;
  *far = 0.0;
  int cx, cy;
  lw_cellgrid_locate(g, P->x, P->y, &cx, &cy);
  for (int y = cy - 1; y <= cy + 1; y++) {
    if (y < 0 || y >= g->ny) continue;
    for (int x = cx - 1; x <= cx + 1; x++) {
      if (x < 0 || x >= g->nx) continue;
      const lw_cell *c = &g->cell[(size_t)y * (size_t)g->nx + (size_t)x];
      for (uint32_t k0 = 0; k0 < c->n; k0 += BLOCK) {
        uint32_t k1 = c->n - k0 > BLOCK ? k0 + BLOCK : c->n;
        if (with_near) {
          if (l_unlikely(nearlist_reserve(near, k1 - k0) != LW_OK)) return LW_ENOMEM;
          m = scan(c, k0, k1, &s, r2b, wb, m, near->idx, &near->n, 1);
        } else {
          m = scan(c, k0, k1, &s, r2b, wb, m, NULL, NULL, 0);
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
