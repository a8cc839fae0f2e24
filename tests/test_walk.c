/* test_walk.c -- the neighbour walk over the cell grid (walk.h) against brute force. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "linewise/grid.h"
#include "linewise/pair.h"
#include "linewise/quad.h"
#include "linewise/vec2.h"
#include "linewise/walk.h"
#include "testutil.h"

#define N_SAMPLES 900
#define PER_SPLINE 8
#define PAGE 40.0
#define CUTOFF 4.0

typedef struct {
  double x[N_SAMPLES], y[N_SAMPLES];
  float dl[N_SAMPLES];
  lw_cellgrid *g;
  lw_pair_ctx ctx;
} scene;

/* Samples at random, some beyond the page (clamped into edge cells), some
** weightless; spline i / PER_SPLINE, so a spline's samples are consecutive. */
static void scene_init(scene *s, double near_scale)
{
  lw_pair_ctx_init(&s->ctx, CUTOFF, near_scale);
  s->g = lw_cellgrid_new(0.0, 0.0, PAGE, PAGE, CUTOFF, N_SAMPLES, NULL);
  cr_assert_not_null(s->g);
  for (uint32_t i = 0; i < N_SAMPLES; i++) {
    s->x[i] = urand(-3.0, PAGE + 3.0);
    s->y[i] = urand(-3.0, PAGE + 3.0);
    s->dl[i] = i % 37 == 5 ? 0.0f : (float)urand(0.1, 0.9);
    cr_assert_eq(lw_cellgrid_insert(s->g, i, s->x[i], s->y[i], s->dl[i]), LW_OK);
  }
}

/* The far sum and the near pairs of the walk's contract (walk.h), pair by pair. */
static double brute(const scene *s, const lw_pair_probe *P, size_t n, const lw_pair_filter *f, uint64_t *near,
                    size_t *n_near)
{
  double far = 0.0;
  *n_near = 0;
  for (size_t p = 0; p < n; p++)
    for (uint32_t j = f->from; j < N_SAMPLES; j++) {
      if ((j >= f->lo && j < f->hi) || (j >= f->lo2 && j < f->hi2)) continue;
      double dx = s->x[j] - P[p].x, dy = s->y[j] - P[p].y, r2 = dx * dx + dy * dy;
      double lim = s->ctx.near_scale * (double)(P[p].dl > s->dl[j] ? P[p].dl : s->dl[j]);
      if (r2 < lim * lim && r2 < s->ctx.cutoff2) near[(*n_near)++] = (uint64_t)p << 32 | j;
      else if (r2 < s->ctx.cutoff2 && P[p].dl != 0.0f && s->dl[j] != 0.0f)
        far += P[p].scale * (double)P[p].dl * (double)s->dl[j] * (1.0 / sqrt(r2) - s->ctx.inv_cutoff);
    }
  return far;
}

static int cmp_u64(const void *a, const void *b)
{
  uint64_t u = *(const uint64_t *)a, v = *(const uint64_t *)b;
  return u < v ? -1 : u > v;
}

/* Probes of spline `spline`: its own samples moved a little (as in a move),
** scale +1, and the samples where they were, scale -1. */
static size_t probes_of(const scene *s, uint32_t spline, lw_pair_probe *P)
{
  size_t n = 0;
  for (uint32_t i = spline * PER_SPLINE; i < (spline + 1) * PER_SPLINE; i++) {
    P[n++] = (lw_pair_probe){s->x[i] + urand(-0.3, 0.3), s->y[i] + urand(-0.3, 0.3), s->dl[i], 1.0};
    P[n++] = (lw_pair_probe){s->x[i], s->y[i], s->dl[i], -1.0};
  }
  return n;
}

/* with_two: a second spline left out as well, later in the index order (a
** join's two old splines); a walk that ignored it would pair with its
** samples and disagree with the brute force on every spline near it. */
static void check(double near_scale, int with_from, int with_two)
{
  static scene s;
  rng_seed(0x5eed0000u + (uint64_t)(near_scale * 10) + (uint64_t)with_from + 100u * (uint64_t)with_two);
  scene_init(&s, near_scale);
  lw_pair_nearlist near = {0};
  lw_pair_probe P[2 * PER_SPLINE];
  static uint64_t want[2 * PER_SPLINE * N_SAMPLES], got[2 * PER_SPLINE * N_SAMPLES];
  for (uint32_t spline = 0; spline < N_SAMPLES / PER_SPLINE; spline++) {
    size_t n = probes_of(&s, spline, P);
    lw_pair_filter f = {.lo = spline * PER_SPLINE, .hi = (spline + 1) * PER_SPLINE,
                        .from = with_from ? (uint32_t)urand(0, N_SAMPLES) : 0};
    if (with_two) {
      const uint32_t other = spline + 1 + (uint32_t)urand(0, N_SAMPLES / PER_SPLINE - 1 - spline);
      if (other < N_SAMPLES / PER_SPLINE) {
        f.lo2 = other * PER_SPLINE;
        f.hi2 = (other + 1) * PER_SPLINE;
      }
    }
    size_t n_want;
    double far_want = brute(&s, P, n, &f, want, &n_want), far;
    near.n = 0;
    /* the narrow kernels on odd splines, the processor's choice on even ones */
    lw_vec_set_wide(spline % 2 == 0);
    cr_assert_eq(lw_pair_walk(s.g, &s.ctx, P, n, &f, &far, NULL, &near, NULL), LW_OK);
    lw_vec_set_wide(1);
    cr_assert(lw_close_rel(far, far_want, 1e-12, 1e-12), "spline %u: far %.17g, brute force %.17g", spline, far,
              far_want);
    cr_assert_eq(near.n, n_want, "spline %u: %zu near pairs, brute force %zu", spline, near.n, n_want);
    for (size_t k = 0; k < near.n; k++) {
      const lw_pair_near *q = &near.pair[k];
      cr_assert(q->x == s.x[q->idx] && q->y == s.y[q->idx] && q->dl == s.dl[q->idx]);
      got[k] = (uint64_t)q->probe << 32 | q->idx;
    }
    qsort(got, near.n, sizeof *got, cmp_u64);
    qsort(want, n_want, sizeof *want, cmp_u64);
    for (size_t k = 0; k < n_want; k++) cr_assert_eq(got[k], want[k], "spline %u: near pair %zu", spline, k);
  }
  lw_pair_nearlist_free(&near);
  lw_cellgrid_free(s.g);
}

Test(walk, far_sum_matches_brute_force)
{
  check(0.0, 0, 0);
}

Test(walk, far_sum_respects_from)
{
  check(0.0, 1, 0);
}

Test(walk, near_pairs_respect_from)
{
  check(1.5, 1, 0);
}

Test(walk, near_pairs_without_from)
{
  check(1.5, 0, 0);
}

Test(walk, two_splines_left_out)
{
  check(1.5, 0, 1);
  check(0.0, 1, 1);
}

/*
** The four-wide (AVX2) and eight-wide (AVX-512) scans give the bits of the
** two-wide one: the far sum, each probe's sum and the near pairs in the same
** order, with and without near pairs and a lower bound, on every spline of
** the scene.  Adding the lanes to the accumulators in another order fails
** this, and so does an eight-wide step that finds other near pairs.
*/
static void set_lanes(int lanes)
{
  lw_vec_set_wide(lanes > LW_VEC_2);
  lw_vec_set_x8(lanes > LW_VEC_4);
}

Test(walk, scans_of_every_width_give_the_same_bits)
{
  if (!lw_vec_wide()) cr_skip_test("this processor has no AVX2: only the narrow scan runs here");
  static const int widths[3] = {LW_VEC_2, LW_VEC_4, LW_VEC_8};
  static scene s;
  lw_pair_nearlist near[3] = {{0}, {0}, {0}};
  lw_pair_probe P[2 * PER_SPLINE];
  double each[3][2 * PER_SPLINE];
  int differ[3] = {0}, walks = 0;
  for (int with_near = 0; with_near < 2; with_near++) {
    rng_seed(5150 + (uint64_t)with_near);
    scene_init(&s, with_near ? 1.5 : 0.0);
    for (uint32_t spline = 0; spline < N_SAMPLES / PER_SPLINE; spline++) {
      size_t n = probes_of(&s, spline, P);
      lw_pair_filter f = {.lo = spline * PER_SPLINE, .hi = (spline + 1) * PER_SPLINE,
                          .from = spline % 3 ? 0 : (uint32_t)urand(0, N_SAMPLES)};
      double far[3];
      for (int w = 0; w < 3; w++) {
        set_lanes(widths[w]);
        near[w].n = 0;
        cr_assert_eq(lw_pair_walk(s.g, &s.ctx, P, n, &f, &far[w], each[w], &near[w], NULL), LW_OK);
      }
      walks++;
      for (int w = 1; w < 3; w++) {
        int same = memcmp(&far[0], &far[w], sizeof far[0]) == 0 && memcmp(each[0], each[w], n * sizeof each[0][0]) == 0 &&
                   near[0].n == near[w].n;
        for (size_t k = 0; same && k < near[0].n; k++)
          same = near[0].pair[k].idx == near[w].pair[k].idx && near[0].pair[k].probe == near[w].pair[k].probe;
        differ[w] += !same;
      }
    }
    lw_cellgrid_free(s.g);
  }
  set_lanes(LW_VEC_8);
  for (int w = 0; w < 3; w++) lw_pair_nearlist_free(&near[w]);
  cr_assert(differ[1] == 0, "%d of %d walks differ between the four-wide and the narrow scans", differ[1], walks);
  cr_assert(differ[2] == 0, "%d of %d walks differ between the eight-wide (%s here) and the narrow scans", differ[2],
            walks, lw_vec_lanes() == LW_VEC_8 ? "AVX-512" : "four-wide: no AVX-512");
}

/* Same positions, grids filled in different orders: the same bits. */
Test(walk, independent_of_insertion_history)
{
  static scene a, b;
  rng_seed(77);
  scene_init(&a, 1.5);
  lw_cellgrid_free(a.g);
  b = a;
  a.g = lw_cellgrid_new(0.0, 0.0, PAGE, PAGE, CUTOFF, N_SAMPLES, NULL);
  b.g = lw_cellgrid_new(0.0, 0.0, PAGE, PAGE, CUTOFF, N_SAMPLES, NULL);
  for (uint32_t i = 0; i < N_SAMPLES; i++) {
    cr_assert_eq(lw_cellgrid_insert(a.g, i, a.x[i], a.y[i], a.dl[i]), LW_OK);
    uint32_t k = N_SAMPLES - 1 - i;
    /* b: inserted backwards, each first at a wrong place and then moved */
    cr_assert_eq(lw_cellgrid_insert(b.g, k, b.y[k], b.x[k], 1.0f), LW_OK);
    cr_assert_eq(lw_cellgrid_move(b.g, k, b.x[k], b.y[k], b.dl[k]), LW_OK);
  }
  lw_pair_probe P[2 * PER_SPLINE];
  lw_pair_nearlist na = {0}, nb = {0};
  for (uint32_t spline = 0; spline < N_SAMPLES / PER_SPLINE; spline += 7) {
    size_t n = probes_of(&a, spline, P);
    lw_pair_filter f = {.lo = spline * PER_SPLINE, .hi = (spline + 1) * PER_SPLINE};
    double fa, fb;
    na.n = nb.n = 0;
    cr_assert_eq(lw_pair_walk(a.g, &a.ctx, P, n, &f, &fa, NULL, &na, NULL), LW_OK);
    cr_assert_eq(lw_pair_walk(b.g, &b.ctx, P, n, &f, &fb, NULL, &nb, NULL), LW_OK);
    cr_assert_eq(fa, fb, "spline %u: %.17g against %.17g", spline, fa, fb);
    cr_assert_eq(na.n, nb.n);
    for (size_t k = 0; k < na.n; k++)
      cr_assert(na.pair[k].idx == nb.pair[k].idx && na.pair[k].probe == nb.pair[k].probe);
  }
  lw_pair_nearlist_free(&na);
  lw_pair_nearlist_free(&nb);
  lw_cellgrid_free(a.g);
  lw_cellgrid_free(b.g);
}

/*
** Issue 21, defect 12: a long spline coiled into one cell.  Its own samples
** must not be visited one by one (quadratic in its length): each walk looks
** at no more than the other splines' samples, whatever the spline's length,
** both as a move (from = 0) and as the full sum does it (from = i + 1).  The
** count of visited pairs is the walk's work, so this catches the quadratic
** behaviour without timing anything.
*/
Test(walk, own_spline_not_visited)
{
  enum { OWN = 6000, OTHER = 40 };
  lw_pair_ctx ctx;
  lw_pair_ctx_init(&ctx, CUTOFF, 1.5);
  lw_cellgrid *g = lw_cellgrid_new(0.0, 0.0, PAGE, PAGE, CUTOFF, OWN + 2 * OTHER, NULL);
  cr_assert_not_null(g);
  rng_seed(2112);
  /* other splines below and above the long one's indices, all close by */
  uint32_t i = 0;
  for (; i < OTHER; i++) cr_assert_eq(lw_cellgrid_insert(g, i, urand(19, 22), urand(19, 22), 0.3f), LW_OK);
  for (; i < OTHER + OWN; i++) {
    double a = 0.01 * i; /* a circle of radius 1 wound round ~10 times */
    cr_assert_eq(lw_cellgrid_insert(g, i, 20.5 + cos(a), 20.5 + sin(a), 0.3f), LW_OK);
  }
  for (; i < 2 * OTHER + OWN; i++) cr_assert_eq(lw_cellgrid_insert(g, i, urand(19, 22), urand(19, 22), 0.3f), LW_OK);
  lw_pair_filter f = {.lo = OTHER, .hi = OTHER + OWN};
  lw_pair_nearlist near = {0};
  uint64_t move = 0, full = 0;
  double far;
  for (uint32_t k = OTHER; k < OTHER + OWN; k++) {
    double x, y;
    float dl;
    lw_cellgrid_get(g, k, &x, &y, &dl);
    lw_pair_probe P = {x, y, dl, 1.0};
    near.n = 0;
    f.from = 0;
    cr_assert_eq(lw_pair_walk(g, &ctx, &P, 1, &f, &far, NULL, &near, &move), LW_OK);
    f.from = k + 1;
    cr_assert_eq(lw_pair_walk(g, &ctx, &P, 1, &f, &far, NULL, &near, &full), LW_OK);
  }
  /* a move sees both groups of others, the full sum only those above */
  cr_assert_leq(move, (uint64_t)OWN * 2 * OTHER, "%llu pairs visited", (unsigned long long)move);
  cr_assert_geq(move, (uint64_t)OWN * OTHER, "%llu pairs visited", (unsigned long long)move);
  cr_assert_leq(full, (uint64_t)OWN * OTHER, "%llu pairs visited", (unsigned long long)full);
  lw_pair_nearlist_free(&near);
  lw_cellgrid_free(g);
}

/*
** The contract a model's memo of the far field rests on (walk.h): a probe's
** own far sum, and its near pairs in their order, are functions of the probe
** and of the samples it may pair alone.  Each spline's probes walked together
** and each probe walked alone give the same bits; so do they after the
** spline's own samples (which the filter leaves out) moved to other cells,
** which shifts the other samples' positions in the cells' arrays.  Run for
** both kernel widths.
*/
Test(walk, each_probes_sum_is_its_own)
{
  static scene s;
  rng_seed(0x5eed0777u);
  scene_init(&s, 1.5);
  lw_pair_nearlist all = {0}, one = {0};
  lw_pair_probe P[2 * PER_SPLINE];
  double each[2 * PER_SPLINE], far;
  long compared = 0;
  for (int wide = 0; wide < 2; wide++) {
    lw_vec_set_wide(wide);
    for (uint32_t spline = 0; spline < N_SAMPLES / PER_SPLINE; spline += 3) {
      size_t n = probes_of(&s, spline, P);
      const lw_pair_filter f = {.lo = spline * PER_SPLINE, .hi = (spline + 1) * PER_SPLINE};
      all.n = 0;
      cr_assert_eq(lw_pair_walk(s.g, &s.ctx, P, n, &f, &far, each, &all, NULL), LW_OK);
      /* the spline's own samples elsewhere: other cells, other array positions */
      for (uint32_t i = f.lo; i < f.hi; i++)
        cr_assert_eq(lw_cellgrid_move(s.g, i, urand(0.0, PAGE), urand(0.0, PAGE), s.dl[i]), LW_OK);
      size_t at = 0;
      for (size_t k = 0; k < n; k++) {
        one.n = 0;
        cr_assert_eq(lw_pair_walk(s.g, &s.ctx, &P[k], 1, &f, &far, NULL, &one, NULL), LW_OK);
        cr_assert(far == each[k], "spline %u probe %zu (%s): %.17g alone, %.17g with the others", spline, k,
                  wide ? "wide" : "narrow", far, each[k]);
        /* its near pairs, in the order they came among the others' */
        for (size_t q = 0; q < one.n; q++) {
          while (at < all.n && all.pair[at].probe != k) at++;
          cr_assert(at < all.n && all.pair[at].idx == one.pair[q].idx, "spline %u probe %zu: near pair %zu", spline,
                    k, q);
          at++;
        }
        size_t mine = 0;
        for (size_t q = 0; q < all.n; q++) mine += all.pair[q].probe == k;
        cr_assert_eq(mine, one.n, "spline %u probe %zu: %zu near pairs among the others, %zu alone", spline, k, mine,
                     one.n);
        at = 0;
        compared++;
      }
      for (uint32_t i = f.lo; i < f.hi; i++)
        cr_assert_eq(lw_cellgrid_move(s.g, i, s.x[i], s.y[i], s.dl[i]), LW_OK);
    }
  }
  lw_vec_set_wide(1);
  cr_assert_gt(compared, 1000);
  lw_pair_nearlist_free(&all);
  lw_pair_nearlist_free(&one);
  lw_cellgrid_free(s.g);
}
