/* walk.c -- the far sum and the near pairs of a set of samples over the cell grid (walk.h). */
#include "linewise/walk.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/vec2.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#if defined(__GNUC__)
#define l_unlikely(x) __builtin_expect(!!(x), 0)
#else
#define l_unlikely(x) (x)
#endif

/* Entries scanned per call of scan: the bits of a uint64_t. */
#define BLOCK 64

typedef lw_v2d v2d;


static inline v2d load2(const double *p)
{
  v2d v;
  memcpy(&v, p, sizeof v);
  return v;
}

typedef long long v2l __attribute__((vector_size(16)));
typedef float v4f __attribute__((vector_size(16)));
typedef int v4i __attribute__((vector_size(16)));

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

/* The larger of a and b in each lane (neither is NaN here). */
static inline v2d vmax(v2d a, v2d b)
{
#if defined(__SSE2__)
  return (v2d)_mm_max_pd((__m128d)a, (__m128d)b);
#else
  const v2l g = a > b;
  return (v2d)(((v2l)a & g) | ((v2l)b & ~g));
#endif
}

/* A 32-bit lane mask widened to 64-bit lanes: lanes 0, 1 (lo) or 2, 3 (hi). */
#if defined(__clang__) || __GNUC__ >= 12
static inline v2l lo2l(v4i m) { return (v2l)__builtin_shufflevector(m, m, 0, 0, 1, 1); }
static inline v2l hi2l(v4i m) { return (v2l)__builtin_shufflevector(m, m, 2, 2, 3, 3); }
#else /* GCC before 12 has only its own shuffle, the same lanes */
static inline v2l lo2l(v4i m) { return (v2l)__builtin_shuffle(m, (v4i){0, 0, 1, 1}); }
static inline v2l hi2l(v4i m) { return (v2l)__builtin_shuffle(m, (v4i){2, 2, 3, 3}); }
#endif

/* A probe's constants in every lane, set up once per walk, and its sums. */
typedef struct {
  v2d x, y;
  v2d rc2;        /* far pairs need r^2 < rc2; -1 for a weightless probe */
  v4f dl;
  v2d near2;      /* (near_scale dl)^2: a pair is near within the larger of its two */
  v2d scale;      /* scale dl: the factor on this probe's far pairs' dl_j (1/r - 1/rc) */
  double gx[3], gy[3]; /* squared gaps to the columns and rows of the block (lw_cellgrid_axis_gaps) */
  v2d s0, s1;     /* its far sum: entries 0, 1 and 2, 3 of each group of four (adjacent) */
} probe_ctx;

/* What every probe of a walk shares: the near scale and the cutoff. */
typedef struct {
  v2d ns;         /* near_scale */
  v2d cut2;       /* rc^2: near pairs lie within the cutoff too */
  v2d ic;         /* 1 / rc (0 without a cutoff) */
} shared_ctx;

/* The near pairs a scan of entries k0 on of cell c marked (bit t of
** near_bits[b]: entry k0 + t with probe b of `touched`), in the order of the
** probes and then of the entries. */
static inline __attribute__((always_inline)) void append_near(const lw_cell *c, uint32_t k0, unsigned touched,
                                                               uint32_t id0, const uint64_t *near_bits,
                                                               lw_pair_nearlist *near)
{
  const double *xs = c->x, *ys = lw_cell_y(c);
  const uint32_t *id = lw_cell_idx(c);
  const float *dls = lw_cell_dl(c);
  for (unsigned left = touched; left; left &= left - 1) {
    unsigned b = (unsigned)__builtin_ctz(left);
    for (uint64_t bits = near_bits[b]; bits; bits &= bits - 1) {
      uint32_t k = k0 + (uint32_t)__builtin_ctzll(bits);
      near->pair[near->n++] = (lw_pair_near){xs[k], ys[k], dls[k], id[k], id0 + b};
    }
  }
}

/* Probe b's near pairs among entries t to t + 3 or t + 7 (bits of found):
** its bits start at 0 the first time it has any in a scan, so a scan
** zeroes no bits for the probes without near pairs (most of them), and
** touched lists the probes append_near has to read. */
static inline __attribute__((always_inline)) void note_near(uint64_t *near_bits, unsigned *touched, unsigned b,
                                                             unsigned found, uint32_t t)
{
  if (!found) return;
  if (!(*touched >> b & 1)) {
    near_bits[b] = 0;
    *touched |= 1u << b;
  }
  near_bits[b] |= (uint64_t)found << t;
}

/*
** Entries [k0, k1) of cell c, k1 - k0 <= BLOCK, against the probes of
** `mask` (bits into pc): far pairs go to each probe's sums, near ones to the near list
** (room for (k1 - k0) times the probes is there).  Four entries at a time
** (two SSE2 vectors of doubles, one of 32-bit lanes): what depends on the
** entries alone (loads, weights) once, the distances per probe.  The
** kernel runs on the four lanes of a probe and group only if one of them is
** a far pair; the others are masked to +0 (whatever inf or NaN they held).  Groups read past k1 (the cell's block is padded,
** grid.h); those lanes are masked off.  The index filter is done before
** (cell_ranges), so the scan sees only samples it may pair.  `with_near` is
** a constant at each call, so the common scan carries no near test.
*/
static inline __attribute__((always_inline)) void
scan(const lw_cell *c, uint32_t k0, uint32_t k1, const shared_ctx *sh, probe_ctx *pc, unsigned mask,
     uint32_t id0, lw_pair_nearlist *near, const int with_near)
{
  uint64_t near_bits[LW_PAIR_CHUNK]; /* those of the touched probes only (note_near) */
  unsigned touched = 0;
  const double *xs = c->x, *ys = lw_cell_y(c);
  const float *dls = lw_cell_dl(c);
  const v4f zero = {0.0f, 0.0f, 0.0f, 0.0f};
  const v4i lane = {0, 1, 2, 3};
  const v2d one = {1.0, 1.0};
  for (uint32_t k = k0, t = 0; k < k1; k += 4, t += 4) {
    v4f dlj;
    memcpy(&dlj, dls + k, sizeof dlj);
    const v4i left_in_block = {(int)(k1 - k), (int)(k1 - k), (int)(k1 - k), (int)(k1 - k)};
    const v4i skip = lane >= left_in_block; /* past k1 */
    v4i ok = ~skip & (v4i)(dlj > zero);
    const v2l ok0 = lo2l(ok), ok1 = hi2l(ok);
    const v2d x0 = load2(xs + k), x1 = load2(xs + k + 2), y0 = load2(ys + k), y1 = load2(ys + k + 2);
    const v2d w0 = lo2d(dlj), w1 = hi2d(dlj);
    /* the entries' own near radii: rounding is monotone, so the square of
    ** near_scale times the larger weight is the larger of the two squares,
    ** bit for bit the kernel's lw_pair_near_radius2 */
    const v2d e0 = sh->ns * w0, e1 = sh->ns * w1, m0 = e0 * e0, m1 = e1 * e1;
    /* the group's largest of them (lanes past k1, whose weights may be
    ** anything, as 0): a probe farther from all four than this and its own
    ** radius has no near pair among them, which is most groups */
    const v2d a0 = (v2d)((v2l)m0 & ~lo2l(skip)), a1 = (v2d)((v2l)m1 & ~hi2l(skip));
    const v2d a = vmax(a0, a1), mg = vmax(a, (v2d){a[1], a[0]});
    for (unsigned left = mask; left; left &= left - 1) {
      unsigned b = (unsigned)__builtin_ctz(left);
      probe_ctx *q = &pc[b];
      v2d dx0 = x0 - q->x, dx1 = x1 - q->x, dy0 = y0 - q->y, dy1 = y1 - q->y;
      v2d r0 = dx0 * dx0 + dy0 * dy0, r1 = dx1 * dx1 + dy1 * dy1;
      v2l f0 = (r0 < q->rc2) & ok0, f1 = (r1 < q->rc2) & ok1;
      const v2d G = vmax(mg, q->near2);
      if (with_near && bits2((r0 < G) | (r1 < G))) {
        v2l n0 = ((r0 < m0) | (r0 < q->near2)) & (r0 < sh->cut2) & ~lo2l(skip);
        v2l n1 = ((r1 < m1) | (r1 < q->near2)) & (r1 < sh->cut2) & ~hi2l(skip);
        f0 &= ~n0;
        f1 &= ~n1;
        note_near(near_bits, &touched, b, bits2(n0) | bits2(n1) << 2, t);
      }
      if (bits2(f0 | f1)) {
        v2d v0 = (w0 * q->scale) * (one / lw_vsqrt2(r0) - sh->ic);
        v2d v1 = (w1 * q->scale) * (one / lw_vsqrt2(r1) - sh->ic);
        q->s0 += (v2d)((v2l)v0 & f0);
        q->s1 += (v2d)((v2l)v1 & f1);
      }
    }
  }
  if (touched) append_near(c, k0, touched, id0, near_bits, near);
}

#if LW_VEC_HAVE_WIDE
#include <immintrin.h>

/*
** scan four entries a vector (AVX2): each lane computed as scan computes it,
** and the far terms of entries 0, 1 and 2, 3 added to the probe's accumulators s0
** and s1 as there, so the same bits (vec2.h).  A maximum over lanes is
** exact in any order.  wide_group is one group of four, entries k to k + 3
** (bit t on of near_bits[b]), against every probe of the mask.
*/
static inline __attribute__((always_inline, target("avx2"))) void
wide_group(const lw_cell *c, uint32_t k, uint32_t k1, uint32_t t, const shared_ctx *sh, probe_ctx *pc,
           unsigned mask, uint64_t *near_bits, unsigned *touched, const int with_near)
{
  const double *xs = c->x, *ys = lw_cell_y(c);
  const float *dls = lw_cell_dl(c);
  const __m128i lane = _mm_setr_epi32(0, 1, 2, 3);
  const __m256d one = _mm256_set1_pd(1.0), ns = _mm256_set1_pd(sh->ns[0]), cut2 = _mm256_set1_pd(sh->cut2[0]);
  const __m256d ic = _mm256_set1_pd(sh->ic[0]);
  const __m128 dlj = _mm_loadu_ps(dls + k);
  const __m128i in_block = _mm_cmpgt_epi32(_mm_set1_epi32((int)(k1 - k)), lane); /* not past k1 */
  const __m128i pos = _mm_castps_si128(_mm_cmpgt_ps(dlj, _mm_setzero_ps()));
  const __m256d ok = _mm256_castsi256_pd(_mm256_cvtepi32_epi64(_mm_and_si128(in_block, pos)));
  const __m256d kept = _mm256_castsi256_pd(_mm256_cvtepi32_epi64(in_block));
  const __m256d x = _mm256_loadu_pd(xs + k), y = _mm256_loadu_pd(ys + k), w = _mm256_cvtps_pd(dlj);
  const __m256d e = _mm256_mul_pd(ns, w), m = _mm256_mul_pd(e, e);
  const __m256d a = _mm256_and_pd(m, kept), a2 = _mm256_max_pd(a, _mm256_permute4x64_pd(a, 0x4e));
  const __m256d mg = _mm256_max_pd(a2, _mm256_permute_pd(a2, 0x5));
  for (unsigned left = mask; left; left &= left - 1) {
    unsigned b = (unsigned)__builtin_ctz(left);
    probe_ctx *q = &pc[b];
    const __m256d dx = _mm256_sub_pd(x, _mm256_set1_pd(q->x[0])), dy = _mm256_sub_pd(y, _mm256_set1_pd(q->y[0]));
    const __m256d r = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy));
    const __m256d near2 = _mm256_set1_pd(q->near2[0]);
    __m256d f = _mm256_and_pd(_mm256_cmp_pd(r, _mm256_set1_pd(q->rc2[0]), _CMP_LT_OQ), ok);
    const __m256d G = _mm256_max_pd(mg, near2);
    if (with_near && _mm256_movemask_pd(_mm256_cmp_pd(r, G, _CMP_LT_OQ))) {
      __m256d n = _mm256_or_pd(_mm256_cmp_pd(r, m, _CMP_LT_OQ), _mm256_cmp_pd(r, near2, _CMP_LT_OQ));
      n = _mm256_and_pd(_mm256_and_pd(n, _mm256_cmp_pd(r, cut2, _CMP_LT_OQ)), kept);
      f = _mm256_andnot_pd(n, f);
      note_near(near_bits, touched, b, (unsigned)_mm256_movemask_pd(n), t);
    }
    /* no test for a far pair among the lanes: whether there is one is a
    ** coin toss in most groups, and the mispredicted branch cost more than
    ** the kernel (5 % of a proposal); lanes masked off add +0, which leaves
    ** the sums' bits as they are (they are never -0) */
    const __m256d inv = _mm256_sub_pd(_mm256_div_pd(one, _mm256_sqrt_pd(r)), ic);
    const __m256d v = _mm256_and_pd(_mm256_mul_pd(_mm256_mul_pd(w, _mm256_set1_pd(q->scale[0])), inv), f);
    /* s0 and s1 lie side by side: lanes 0, 1 and 2, 3 of one vector */
    _mm256_storeu_pd((double *)&q->s0, _mm256_add_pd(_mm256_loadu_pd((const double *)&q->s0), v));
  }
}

static inline __attribute__((always_inline, target("avx2"))) void
scan_wide_body(const lw_cell *c, uint32_t k0, uint32_t k1, const shared_ctx *sh, probe_ctx *pc, unsigned mask,
               uint32_t id0, lw_pair_nearlist *near, const int with_near)
{
  uint64_t near_bits[LW_PAIR_CHUNK]; /* those of the touched probes only (note_near) */
  unsigned touched = 0;
  for (uint32_t k = k0, t = 0; k < k1; k += 4, t += 4)
    wide_group(c, k, k1, t, sh, pc, mask, near_bits, &touched, with_near);
  if (touched) append_near(c, k0, touched, id0, near_bits, near);
}

__attribute__((target("avx2"))) static void scan_wide_near(const lw_cell *c, uint32_t k0, uint32_t k1,
                                                           const shared_ctx *sh, probe_ctx *pc, unsigned mask,
                                                           uint32_t id0, lw_pair_nearlist *near)
{
  scan_wide_body(c, k0, k1, sh, pc, mask, id0, near, 1);
}

__attribute__((target("avx2"))) static void scan_wide_far(const lw_cell *c, uint32_t k0, uint32_t k1,
                                                          const shared_ctx *sh, probe_ctx *pc, unsigned mask,
                                                          uint32_t id0)
{
  scan_wide_body(c, k0, k1, sh, pc, mask, id0, NULL, 0);
}

/*
** scan eight entries a vector (AVX-512), two groups of four: each lane as
** wide_group computes it, and a probe's terms of the first group added to
** its accumulators, then those of the second, so the same bits.  The
** eight-wide steps read no further than the four-wide ones (the second
** group is in the block); the last group, if alone, goes four-wide.  It
** halves the instructions a group costs outside the divider.
*/

static inline __attribute__((always_inline, target(LW_VEC_X8_TARGET))) void
scan_x8_body(const lw_cell *c, uint32_t k0, uint32_t k1, const shared_ctx *sh, probe_ctx *pc, unsigned mask,
             uint32_t id0, lw_pair_nearlist *near, const int with_near)
{
  uint64_t near_bits[LW_PAIR_CHUNK]; /* those of the touched probes only (note_near) */
  unsigned touched = 0;
  const double *xs = c->x, *ys = lw_cell_y(c);
  const float *dls = lw_cell_dl(c);
  const __m512i lane = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7);
  const __m512d one = _mm512_set1_pd(1.0), ns = _mm512_set1_pd(sh->ns[0]), cut2 = _mm512_set1_pd(sh->cut2[0]);
  const __m512d ic = _mm512_set1_pd(sh->ic[0]);
  uint32_t k = k0, t = 0;
  for (; k + 4 < k1; k += 8, t += 8) {
    const __m256 dlj = _mm256_loadu_ps(dls + k);
    const __mmask8 kept = _mm512_cmpgt_epi64_mask(_mm512_set1_epi64((long long)(k1 - k)), lane); /* not past k1 */
    const __mmask8 ok = kept & _mm256_cmp_ps_mask(dlj, _mm256_setzero_ps(), _CMP_GT_OQ);
    const __m512d x = _mm512_loadu_pd(xs + k), y = _mm512_loadu_pd(ys + k), w = _mm512_cvtps_pd(dlj);
    const __m512d e = _mm512_mul_pd(ns, w), m = _mm512_mul_pd(e, e);
    /* each group's largest radius in its four lanes (swap halves, then pairs) */
    const __m512d a = _mm512_maskz_mov_pd(kept, m), a2 = _mm512_max_pd(a, _mm512_permutex_pd(a, 0x4e));
    const __m512d mg = _mm512_max_pd(a2, _mm512_permute_pd(a2, 0x55));
    for (unsigned left = mask; left; left &= left - 1) {
      unsigned b = (unsigned)__builtin_ctz(left);
      probe_ctx *q = &pc[b];
      const __m512d dx = _mm512_sub_pd(x, _mm512_set1_pd(q->x[0])), dy = _mm512_sub_pd(y, _mm512_set1_pd(q->y[0]));
      const __m512d r = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
      const __m512d near2 = _mm512_set1_pd(q->near2[0]);
      __mmask8 f = _mm512_mask_cmp_pd_mask(ok, r, _mm512_set1_pd(q->rc2[0]), _CMP_LT_OQ);
      /* a lane with r under G is in either group: testing both at once finds the same pairs */
      if (with_near && _mm512_cmp_pd_mask(r, _mm512_max_pd(mg, near2), _CMP_LT_OQ)) {
        __mmask8 n = _mm512_cmp_pd_mask(r, m, _CMP_LT_OQ) | _mm512_cmp_pd_mask(r, near2, _CMP_LT_OQ);
        n &= _mm512_cmp_pd_mask(r, cut2, _CMP_LT_OQ) & kept;
        f &= (__mmask8)~n;
        note_near(near_bits, &touched, b, n, t);
      }
      const __m512d inv = _mm512_sub_pd(_mm512_div_pd(one, _mm512_sqrt_pd(r)), ic);
      const __m512d v = _mm512_maskz_mul_pd(f, _mm512_mul_pd(w, _mm512_set1_pd(q->scale[0])), inv);
      __m256d acc = _mm256_loadu_pd((const double *)&q->s0);
      acc = _mm256_add_pd(acc, _mm512_castpd512_pd256(v));
      acc = _mm256_add_pd(acc, _mm512_extractf64x4_pd(v, 1));
      _mm256_storeu_pd((double *)&q->s0, acc);
    }
  }
  if (k < k1) wide_group(c, k, k1, t, sh, pc, mask, near_bits, &touched, with_near);
  if (touched) append_near(c, k0, touched, id0, near_bits, near);
}

__attribute__((target(LW_VEC_X8_TARGET))) static void scan_x8_near(const lw_cell *c, uint32_t k0, uint32_t k1,
                                                                    const shared_ctx *sh, probe_ctx *pc, unsigned mask,
                                                                    uint32_t id0, lw_pair_nearlist *near)
{
  scan_x8_body(c, k0, k1, sh, pc, mask, id0, near, 1);
}

__attribute__((target(LW_VEC_X8_TARGET))) static void scan_x8_far(const lw_cell *c, uint32_t k0, uint32_t k1,
                                                                   const shared_ctx *sh, probe_ctx *pc, unsigned mask,
                                                                   uint32_t id0)
{
  scan_x8_body(c, k0, k1, sh, pc, mask, id0, NULL, 0);
}
#endif

void lw_pair_nearlist_free(lw_pair_nearlist *l)
{
  free(l->pair);
  l->pair = NULL;
  l->n = l->cap = 0;
}

static lw_status nearlist_reserve(lw_pair_nearlist *l, size_t more)
{
  if (l->cap - l->n >= more) return LW_OK;
  size_t cap = l->cap ? 2 * l->cap : 64;
  while (cap - l->n < more) cap *= 2;
  lw_pair_near *pair = realloc(l->pair, cap * sizeof *pair);
  if (!pair) return LW_ENOMEM;
  l->pair = pair;
  l->cap = cap;
  return LW_OK;
}

/* Position of the first entry of index >= i in the cell's sorted indices. */
static uint32_t first_from(const uint32_t *idx, uint32_t n, uint32_t i)
{
  uint32_t lo = 0, hi = n;
  while (lo < hi) {
    uint32_t mid = lo + (hi - lo) / 2;
    if (idx[mid] < i) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

/*
** The entries of cell c a walk may pair, as at most three runs of positions
** [r[0], r[1]), [r[2], r[3]) and [r[4], r[5]): indices >= from and outside
** [lo, hi) and [lo2, hi2).  A
** cell keeps its indices sorted and a spline's samples have consecutive
** indices, so the excluded ones are one run found by binary search: a
** spline's own samples cost O(log n) per cell however many there are (a
** long spline coiled into a few cells would otherwise be visited sample by
** sample from each of its samples: quadratic).
*/
static void cell_ranges(const lw_cell *c, const lw_pair_filter *f, uint32_t r[6])
{
  const uint32_t *idx = lw_cell_idx(c);
  uint32_t n = c->n, a = f->from ? first_from(idx, n, f->from) : 0;
  r[0] = a;
  r[1] = r[2] = r[3] = r[4] = r[5] = n;
  if (f->hi2 > f->lo2) {
    /* two splines left out (a join): three runs, each bound by binary search */
    const uint32_t bound[4] = {f->lo, f->hi, f->lo2, f->hi2};
    for (int k = 0; k < 4; k++) {
      uint32_t at = first_from(idx, n, bound[k]);
      r[k + 1] = at > a ? at : a;
    }
    return;
  }
  if (a == n || idx[a] >= f->hi || idx[n - 1] < f->lo) return; /* nothing of the spline after from */
  uint32_t l = idx[a] >= f->lo ? a : first_from(idx + a, n - a, f->lo) + a;
  r[1] = l;
  r[2] = idx[n - 1] < f->hi ? n : first_from(idx + l, n - l, f->hi) + l;
}

/* Cells a group of probes may span (the union of their 3 x 3 blocks): a
** proposal's probes lie within a few cells of each other. */
#define BOX_MAX 256

/* The box of cells around probe cells [x0, x1] x [y0, y1]: the grid's cells
** within one of them. */
typedef struct {
  int x0, y0, w, h;
} box;

static box box_around(const lw_cellgrid *g, int x0, int x1, int y0, int y1)
{
  box b;
  b.x0 = x0 > 0 ? x0 - 1 : 0;
  b.y0 = y0 > 0 ? y0 - 1 : 0;
  b.w = (x1 + 1 < g->nx ? x1 + 1 : g->nx - 1) - b.x0 + 1;
  b.h = (y1 + 1 < g->ny ? y1 + 1 : g->ny - 1) - b.y0 + 1;
  return b;
}

/* Asks for the blocks of the box's cells before the probes are set up, so
** that they arrive meanwhile: each is a heap block of its own, and the
** first read of one (the filter's binary search) stalled for it (a quarter
** of walk_group's samples in a profile; 3 % of a proposal, measured). */
static void prefetch_box(const lw_cellgrid *g, box bx)
{
  for (int y = 0; y < bx.h; y++) {
    const lw_cell *row = g->cell + (size_t)(bx.y0 + y) * (size_t)g->nx + (size_t)bx.x0;
    for (int x = 0; x < bx.w; x++) {
      const lw_cell *c = &row[x];
      if (!c->n) continue;
      const char *xs = (const char *)c->x, *ys = (const char *)lw_cell_y(c);
      const char *is = (const char *)lw_cell_idx(c), *ds = (const char *)lw_cell_dl(c);
      for (size_t o = 0; o < 8 * (size_t)c->n; o += 64) __builtin_prefetch(xs + o), __builtin_prefetch(ys + o);
      for (size_t o = 0; o < 4 * (size_t)c->n; o += 64) __builtin_prefetch(is + o), __builtin_prefetch(ds + o);
    }
  }
}

/* Probes id0 to id0 + nb - 1 of P (nb <= LW_PAIR_CHUNK, cells cx[], cy[]),
** whose cells' 3 x 3 blocks lie in box bx: one pass over the box's cells in
** the grid's order, each cell read once for every probe whose block holds
** it and whose gap to it is within the cutoff.  So each probe meets its
** cells in the grid's order and their entries in theirs, whatever the
** others.  Each probe's far sum goes to sum[b].  *visited (NULL:
** not counted) counts entries scanned times the probes that scan them. */
static lw_status walk_group(const lw_cellgrid *g, const lw_pair_ctx *ctx, const shared_ctx *sh,
                            const lw_pair_probe *P, uint32_t id0, int nb, const int *cx, const int *cy,
                            box bx, const lw_pair_filter *f, int wide, double *sum,
                            lw_pair_nearlist *near, uint64_t *visited)
{
  probe_ctx pc[LW_PAIR_CHUNK];
  uint32_t mask[BOX_MAX];
  const double h = 1.0 / g->inv_h, skip2 = ctx->cutoff2 * LW_CELLGRID_GAP_MARGIN;
  const int with_near = ctx->near_scale > 0.0;
  if (nb > 1) prefetch_box(g, bx); /* a lone probe (the full sum's walks) sets up too fast to gain */
  memset(mask, 0, (size_t)(bx.w * bx.h) * sizeof *mask);
  for (int b = 0; b < nb; b++) {
    const lw_pair_probe *p = &P[id0 + (uint32_t)b];
    /* a weightless probe has no far pairs (its kernel is 0, even at r = 0) */
    const double rc2 = p->dl != 0.0f ? ctx->cutoff2 : -1.0, l = ctx->near_scale * (double)p->dl;
    /* field by field: a compound literal is zeroed whole first (a string
    ** store a probe, 1 % of a proposal); lw_cellgrid_axis_gaps sets gx and gy */
    probe_ctx *q = &pc[b];
    q->x = (v2d){p->x, p->x};
    q->y = (v2d){p->y, p->y};
    q->rc2 = (v2d){rc2, rc2};
    q->dl = (v4f){p->dl, p->dl, p->dl, p->dl};
    q->near2 = (v2d){l * l, l * l};
    q->scale = (v2d){p->scale * (double)p->dl, p->scale * (double)p->dl};
    q->s0 = q->s1 = (v2d){0.0, 0.0};
    lw_cellgrid_axis_gaps(g->x0, h, cx[b], p->x, pc[b].gx);
    lw_cellgrid_axis_gaps(g->y0, h, cy[b], p->y, pc[b].gy);
    for (int dy = -1; dy <= 1; dy++) {
      const int y = cy[b] + dy;
      if (y < 0 || y >= g->ny) continue;
      for (int dx = -1; dx <= 1; dx++) {
        const int x = cx[b] + dx;
        if (x < 0 || x >= g->nx || pc[b].gx[dx + 1] + pc[b].gy[dy + 1] > skip2) continue;
        mask[(y - bx.y0) * bx.w + (x - bx.x0)] |= 1u << b;
      }
    }
  }
  for (int y = 0; y < bx.h; y++) {
    const lw_cell *row = g->cell + (size_t)(bx.y0 + y) * (size_t)g->nx + (size_t)bx.x0;
    for (int x = 0; x < bx.w; x++) {
      const unsigned m = mask[y * bx.w + x];
      const lw_cell *c = row + x;
      if (!m || !c->n) continue;
      uint32_t r[6];
      cell_ranges(c, f, r);
      for (int run = 0; run < 6; run += 2) {
        if (visited) *visited += (uint64_t)(r[run + 1] - r[run]) * (uint64_t)__builtin_popcount(m);
        for (uint32_t k0 = r[run]; k0 < r[run + 1]; k0 += BLOCK) {
          uint32_t k1 = r[run + 1] - k0 > BLOCK ? k0 + BLOCK : r[run + 1];
          if (with_near && l_unlikely(nearlist_reserve(near, (size_t)(k1 - k0) * (size_t)nb) != LW_OK))
            return LW_ENOMEM;
#if LW_VEC_HAVE_WIDE
          if (wide == LW_VEC_8) {
            if (with_near) scan_x8_near(c, k0, k1, sh, pc, m, id0, near);
            else scan_x8_far(c, k0, k1, sh, pc, m, id0);
            continue;
          }
          if (wide == LW_VEC_4) {
            if (with_near) scan_wide_near(c, k0, k1, sh, pc, m, id0, near);
            else scan_wide_far(c, k0, k1, sh, pc, m, id0);
            continue;
          }
#endif
          if (with_near) scan(c, k0, k1, sh, pc, m, id0, near, 1);
          else scan(c, k0, k1, sh, pc, m, id0, NULL, 0);
        }
      }
    }
  }
  for (int b = 0; b < nb; b++) {
    const v2d t = pc[b].s0 + pc[b].s1;
    sum[b] = t[0] + t[1];
  }
  return LW_OK;
}

lw_status lw_pair_walk(const lw_cellgrid *g, const lw_pair_ctx *ctx, const lw_pair_probe *P, size_t n,
                       const lw_pair_filter *f, double *far, double *each, lw_pair_nearlist *near,
                       uint64_t *visited)
{
  const shared_ctx sh = {{ctx->near_scale, ctx->near_scale},
                         {ctx->cutoff2, ctx->cutoff2},
                         {ctx->inv_cutoff, ctx->inv_cutoff}};
  uint64_t seen = 0;
  const int wide = lw_vec_lanes();
  lw_cellgrid view;
  g = lw_cellgrid_plane(g, f->plane, &view);
  double total = 0.0;
  *far = 0.0;
  for (size_t c0 = 0; c0 < n; c0 += LW_PAIR_CHUNK) {
    int cx[LW_PAIR_CHUNK], cy[LW_PAIR_CHUNK];
    double sum[LW_PAIR_CHUNK];
    const int nc = n - c0 < LW_PAIR_CHUNK ? (int)(n - c0) : LW_PAIR_CHUNK;
    for (int i = 0; i < nc; i++) lw_cellgrid_locate(g, P[c0 + i].x, P[c0 + i].y, &cx[i], &cy[i]);
    /* groups of consecutive probes whose box fits (one, for a move's) */
    for (int b = 0; b < nc;) {
      int x0 = cx[b], x1 = cx[b], y0 = cy[b], y1 = cy[b], e = b + 1;
      box bx = box_around(g, x0, x1, y0, y1);
      for (; e < nc; e++) {
        const int ax0 = cx[e] < x0 ? cx[e] : x0, ax1 = cx[e] > x1 ? cx[e] : x1;
        const int ay0 = cy[e] < y0 ? cy[e] : y0, ay1 = cy[e] > y1 ? cy[e] : y1;
        const box wider = box_around(g, ax0, ax1, ay0, ay1);
        if (wider.w * wider.h > BOX_MAX) break;
        x0 = ax0, x1 = ax1, y0 = ay0, y1 = ay1, bx = wider;
      }
      if (walk_group(g, ctx, &sh, P, (uint32_t)(c0 + (size_t)b), e - b, cx + b, cy + b, bx, f, wide, sum + b, near,
                     visited ? &seen : NULL) != LW_OK)
        return LW_ENOMEM;
      b = e;
    }
    for (int i = 0; i < nc; i++) total += sum[i];
    if (each) memcpy(each + c0, sum, (size_t)nc * sizeof *sum);
  }
  *far = total;
  if (visited) *visited += seen;
  return LW_OK;
}
