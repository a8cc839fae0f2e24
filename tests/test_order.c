/* test_order.c -- pen-up travel, greedy and 2-opt tours, pens of a plot. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/order.h"
#include "linewise/plot.h"
#include "testutil.h"

/* n random paths of length up to 8 mm on an A4 page. */
static lw_order_path *random_paths(size_t n, uint64_t seed)
{
  rng_seed(seed);
  lw_order_path *p = malloc(n * sizeof *p);
  cr_assert_not_null(p);
  for (size_t i = 0; i < n; i++) {
    double x = urand(0, 210), y = urand(0, 297), a = urand(0, 2 * M_PI), l = urand(0.1, 8);
    p[i] = (lw_order_path){x, y, x + l * cos(a), y + l * sin(a)};
  }
  return p;
}

static void assert_permutation(const size_t *order, size_t n)
{
  unsigned char *seen = calloc(n ? n : 1, 1);
  for (size_t k = 0; k < n; k++) {
    cr_assert(order[k] < n, "entry %zu out of range", k);
    cr_assert(!seen[order[k]], "path %zu twice", order[k]);
    seen[order[k]] = 1;
  }
  free(seen);
}

Test(order, travel_of_a_hand_made_tour)
{
  const lw_order_path p[2] = {{3, 4, 10, 4}, {10, 10, 13, 14}};
  /* home (0,0) -> (3,4): 5; (10,4) -> (10,10): 6 */
  cr_assert_eq(lw_order_travel(p, 2, NULL, NULL, 0, 0), 11.0);
  /* path 1 reversed first: (0,0) -> (13,14), then (10,10) -> (3,4) */
  size_t order[2] = {1, 0};
  unsigned char rev[2] = {1, 0};
  double want = hypot(13, 14) + hypot(7, 6);
  cr_assert_eq(lw_order_travel(p, 2, order, rev, 0, 0), want);
  cr_assert_eq(lw_order_travel(p, 0, NULL, NULL, 5, 5), 0.0);
}

/* Travel is never worse after 2-opt than from the greedy tour it starts
** from, every tour is a permutation, and equal input gives equal output. */
Test(order, random_instances_improve_and_are_deterministic)
{
  const size_t sizes[] = {1, 2, 3, 7, 50, 400, 3000};
  for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++) {
    size_t n = sizes[s];
    for (uint64_t seed = 1; seed <= 3; seed++) {
      lw_order_path *p = random_paths(n, 1000 * seed + n);
      size_t *o1 = malloc(n * sizeof *o1), *o2 = malloc(n * sizeof *o2);
      unsigned char *r1 = malloc(n), *r2 = malloc(n);
      cr_assert_eq(lw_order_greedy(p, n, 0, 0, o1, r1, NULL), LW_OK);
      assert_permutation(o1, n);
      double greedy = lw_order_travel(p, n, o1, r1, 0, 0);
      cr_assert_eq(lw_order_2opt(p, n, 0, 0, o1, r1, NULL), LW_OK);
      assert_permutation(o1, n);
      double after = lw_order_travel(p, n, o1, r1, 0, 0);
      cr_assert(after <= greedy, "n %zu seed %llu: 2-opt %.9g > greedy %.9g", n, (unsigned long long)seed, after,
                greedy);
      /* the random order of index 0..n-1 is far longer on 50+ paths */
      if (n >= 50) cr_assert(after < 0.5 * lw_order_travel(p, n, NULL, NULL, 0, 0));
      cr_assert_eq(lw_order_greedy(p, n, 0, 0, o2, r2, NULL), LW_OK);
      cr_assert_eq(lw_order_2opt(p, n, 0, 0, o2, r2, NULL), LW_OK);
      cr_assert(!memcmp(o1, o2, n * sizeof *o1) && !memcmp(r1, r2, n), "n %zu: not deterministic", n);
      free(o1);
      free(o2);
      free(r1);
      free(r2);
      free(p);
    }
  }
}

/* 2-opt numbers the paths by their place in the starting tour: the paths'
** own numbering must not matter.  The same paths under another numbering,
** from the same starting tour, give the same tour (paths in random places:
** no equal distances, so no tie goes by number). */
Test(order, two_opt_does_not_depend_on_the_numbering_of_the_paths)
{
  const size_t n = 2000;
  lw_order_path *p = random_paths(n, 99), *q = malloc(n * sizeof *q);
  size_t *perm = malloc(n * sizeof *perm), *o1 = malloc(n * sizeof *o1), *o2 = malloc(n * sizeof *o2);
  unsigned char *r1 = malloc(n), *r2 = malloc(n);
  for (size_t k = 0; k < n; k++) perm[k] = k;
  for (size_t k = n - 1; k > 0; k--) {
    size_t j = (size_t)urand(0, (double)k + 1), t = perm[k];
    perm[k] = perm[j];
    perm[j] = t;
  }
  /* path perm[i] of q is path i of p */
  for (size_t i = 0; i < n; i++) q[perm[i]] = p[i];
  cr_assert_eq(lw_order_greedy(p, n, 0, 0, o1, r1, NULL), LW_OK);
  for (size_t k = 0; k < n; k++) {
    o2[k] = perm[o1[k]];
    r2[k] = r1[k];
  }
  cr_assert_eq(lw_order_2opt(p, n, 0, 0, o1, r1, NULL), LW_OK);
  cr_assert_eq(lw_order_2opt(q, n, 0, 0, o2, r2, NULL), LW_OK);
  for (size_t k = 0; k < n; k++)
    cr_assert(perm[o1[k]] == o2[k] && r1[k] == r2[k], "tours part at position %zu", k);
  cr_assert_eq(lw_order_travel(p, n, o1, r1, 0, 0), lw_order_travel(q, n, o2, r2, 0, 0));
  free(p);
  free(q);
  free(perm);
  free(o1);
  free(o2);
  free(r1);
  free(r2);
}

/* ---- the local optimum of 2-opt and Or-opt, checked by brute force --- */

/* End point id: 2 path + end, 2 n for home. */
static void end_xy(const lw_order_path *p, size_t n, double hx, double hy, size_t id, double *x, double *y)
{
  const lw_order_path *q = &p[id / 2];
  *x = id == 2 * n ? hx : (id & 1) ? q->x1 : q->x0;
  *y = id == 2 * n ? hy : (id & 1) ? q->y1 : q->y0;
}

/* Whether end point b is among the LW_ORDER_NEIGHBOURS nearest of end point
** a, its own path's other end left out (order.h: the candidates of a move). */
static int is_candidate(const lw_order_path *p, size_t n, double hx, double hy, size_t a, size_t b)
{
  double ax, ay, bx, by;
  end_xy(p, n, hx, hy, a, &ax, &ay);
  end_xy(p, n, hx, hy, b, &bx, &by);
  double d = hypot(bx - ax, by - ay);
  size_t nearer = 0;
  for (size_t c = 0; c <= 2 * n; c++) {
    if (c == a || c == b || (c < 2 * n && a < 2 * n && c / 2 == a / 2)) continue;
    double cx, cy;
    end_xy(p, n, hx, hy, c, &cx, &cy);
    if (hypot(cx - ax, cy - ay) < d && ++nearer >= LW_ORDER_NEIGHBOURS) return 0;
  }
  return 1;
}

/* The end point id at place e of the open tour: e = 2 k is the entry of the
** k-th path drawn, 2 k + 1 its exit; e = -1 is home. */
static size_t tour_id(size_t n, const size_t *o, const unsigned char *r, long e)
{
  return e < 0 ? 2 * n : 2 * o[e / 2] + (size_t)((e & 1) ^ r[e / 2]);
}

/* The tour as order.h's cycle: item 0 is home, entered at FREE (SIZE_MAX,
** at no distance from anything) and left at the home point; item k + 1 is
** the k-th path.  in[] and out[] are end point ids. */
static double cycle_leg(const lw_order_path *p, size_t n, double hx, double hy, size_t a, size_t b)
{
  if (a == SIZE_MAX || b == SIZE_MAX) return 0.0;
  double ax, ay, bx, by;
  end_xy(p, n, hx, hy, a, &ax, &ay);
  end_xy(p, n, hx, hy, b, &bx, &by);
  return hypot(bx - ax, by - ay);
}

/* No Or-opt move in reach is left either: a stretch of 1 to
** LW_ORDER_OR_MAX paths taken out (its neighbours joined, saving `removed`)
** and put between c and d either way round, seen from the stretch's end z
** when a new leg from z is shorter than `removed` and goes to one of z's
** candidates.  Moves next to the stretch's own place are not Or-opt moves
** (order.c leaves them to 2-opt or to a neighbour's stretch), nor, here,
** stretches through home. */
static void assert_no_or_opt_in_reach(const lw_order_path *p, size_t n, double hx, double hy, const size_t *o,
                                      const unsigned char *r)
{
  size_t m = n + 1, *in = malloc(m * sizeof *in), *out = malloc(m * sizeof *out);
  in[0] = SIZE_MAX;
  out[0] = 2 * n;
  for (size_t k = 0; k < n; k++) {
    in[k + 1] = 2 * o[k] + r[k];
    out[k + 1] = 2 * o[k] + 1 - r[k];
  }
  for (size_t s1 = 1; s1 < m; s1++)
    for (size_t len = 1; len <= LW_ORDER_OR_MAX && s1 + len <= m; len++) {
      size_t s2 = s1 + len - 1, pv = s1 - 1, nx = (s2 + 1) % m, e1 = in[s1], x2 = out[s2];
      double removed = cycle_leg(p, n, hx, hy, out[pv], e1) + cycle_leg(p, n, hx, hy, x2, in[nx]) -
                       cycle_leg(p, n, hx, hy, out[pv], in[nx]);
      for (size_t c = 0; c < m; c++) {
        size_t d = (c + 1) % m;
        if ((c >= s1 && c <= s2) || c == pv || c == nx || d == pv) continue;
        double fwd = cycle_leg(p, n, hx, hy, out[c], e1) + cycle_leg(p, n, hx, hy, x2, in[d]);
        double flp = cycle_leg(p, n, hx, hy, out[c], x2) + cycle_leg(p, n, hx, hy, e1, in[d]);
        double gain = removed + cycle_leg(p, n, hx, hy, out[c], in[d]) - fmin(fwd, flp);
        if (gain <= 1e-6) continue;
        const size_t z[2] = {e1, x2}, q[2] = {out[c], in[d]};
        for (int i = 0; i < 2; i++)
          for (int j = 0; j < 2; j++)
            cr_assert(q[j] == SIZE_MAX || cycle_leg(p, n, hx, hy, z[i], q[j]) >= removed - 1e-9 ||
                          !is_candidate(p, n, hx, hy, z[i], q[j]),
                      "moving places %zu..%zu of the tour after %zu gains %.3g mm and was in reach", s1 - 1, s2 - 1,
                      c, gain);
      }
    }
  free(in);
  free(out);
}

/* No 2-opt move that lw_order_2opt could have seen is left: reversing tour
** places i..j swaps legs X -> U and Y -> V (X the exit before i, U the entry
** of i, Y the exit of j, V the entry after j) for X -> Y and U -> V, and a
** move that gains is seen from any of X, Y, U, V whose new leg is shorter
** than its old one and goes to one of its candidates.  Every pair (i, j) is
** checked by brute force, then every Or-opt move. */
static void assert_local_optimum(const lw_order_path *p, size_t n, double hx, double hy, const size_t *o,
                                 const unsigned char *r)
{
  for (long i = 0; i < (long)n; i++) {
    double Xx, Xy, Ux, Uy;
    end_xy(p, n, hx, hy, tour_id(n, o, r, 2 * i - 1), &Xx, &Xy);
    end_xy(p, n, hx, hy, tour_id(n, o, r, 2 * i), &Ux, &Uy);
    double xu = hypot(Ux - Xx, Uy - Xy);
    for (long j = i; j < (long)n; j++) {
      double Yx, Yy, Vx = 0, Vy = 0;
      end_xy(p, n, hx, hy, tour_id(n, o, r, 2 * j + 1), &Yx, &Yy);
      int last = j == (long)n - 1; /* V is the free end of the open tour */
      if (!last) end_xy(p, n, hx, hy, tour_id(n, o, r, 2 * j + 2), &Vx, &Vy);
      double yv = last ? 0 : hypot(Vx - Yx, Vy - Yy), xy = hypot(Yx - Xx, Yy - Xy);
      double uv = last ? 0 : hypot(Vx - Ux, Vy - Uy);
      double gain = xu + yv - xy - uv;
      if (gain <= 1e-6) continue;
      size_t X = tour_id(n, o, r, 2 * i - 1), U = tour_id(n, o, r, 2 * i), Y = tour_id(n, o, r, 2 * j + 1);
      int seen = (xy < xu - 1e-9 && is_candidate(p, n, hx, hy, X, Y)) ||
                 (xy < yv - 1e-9 && is_candidate(p, n, hx, hy, Y, X));
      if (!last) {
        size_t V = tour_id(n, o, r, 2 * j + 2);
        seen = seen || (uv < xu - 1e-9 && is_candidate(p, n, hx, hy, U, V)) ||
               (uv < yv - 1e-9 && is_candidate(p, n, hx, hy, V, U));
      }
      cr_assert(!seen, "a move reversing places %ld..%ld gains %.3g mm and was in reach", i, j, gain);
    }
  }
  assert_no_or_opt_in_reach(p, n, hx, hy, o, r);
}

/* Dense paths (lines about 0.5 mm apart), from a scrambled tour and from the
** greedy one: thousands of long reversals, which split and lay out the
** two-level list afresh many times.  Where lw_order_2opt stops, no move in
** reach is left (a succ/pred/orientation slip in the list shows up as such
** a move, or as a tour that is not a permutation); the tour is never longer
** than the one it started from, and the same twice. */
Test(order, two_opt_and_or_opt_stop_at_a_local_optimum_of_their_candidate_moves)
{
  const size_t n = 1500;
  const double hx = 0, hy = 0;
  rng_seed(4242);
  lw_order_path *p = malloc(n * sizeof *p);
  size_t *o = malloc(n * sizeof *o), *o2 = malloc(n * sizeof *o2);
  unsigned char *r = malloc(n), *r2 = malloc(n);
  for (size_t i = 0; i < n; i++) {
    double x = urand(0, 30), y = urand(0, 30), a = urand(0, 2 * M_PI), l = urand(0.2, 6);
    p[i] = (lw_order_path){x, y, x + l * cos(a), y + l * sin(a)};
    o[i] = i;
    r[i] = urand(0, 1) < 0.5;
  }
  for (size_t k = n - 1; k > 0; k--) {
    size_t j = (size_t)urand(0, (double)k + 1), t = o[k];
    o[k] = o[j];
    o[j] = t;
  }
  for (int from_greedy = 0; from_greedy < 2; from_greedy++) {
    if (from_greedy) cr_assert_eq(lw_order_greedy(p, n, hx, hy, o, r, NULL), LW_OK);
    memcpy(o2, o, n * sizeof *o);
    memcpy(r2, r, n);
    double start = lw_order_travel(p, n, o, r, hx, hy);
    cr_assert_eq(lw_order_2opt(p, n, hx, hy, o, r, NULL), LW_OK);
    assert_permutation(o, n);
    double after = lw_order_travel(p, n, o, r, hx, hy);
    /* from the scramble a tenth; greedy is about a third longer than 2-opt */
    cr_assert(after < (from_greedy ? 0.9 : 0.1) * start, "2-opt %.6g from %.6g", after, start);
    cr_assert_eq(lw_order_2opt(p, n, hx, hy, o2, r2, NULL), LW_OK);
    cr_assert(!memcmp(o, o2, n * sizeof *o) && !memcmp(r, r2, n), "not deterministic");
    assert_local_optimum(p, n, hx, hy, o, r);
  }
  free(p);
  free(o);
  free(o2);
  free(r);
  free(r2);
}

/* The greedy step takes the nearest end point; on a tie the lower path,
** start before end. */
Test(order, greedy_picks_nearest_end_and_reverses)
{
  const lw_order_path p[3] = {
    {50, 0, 40, 0},  /* end (40,0) nearer home than its start */
    {5, 0, 9, 0},    /* start at 5: the first */
    {39, 0, 20, 0},  /* from (9,0): start 39 is 30 away, end 20 is 11 */
  };
  size_t o[3];
  unsigned char r[3];
  cr_assert_eq(lw_order_greedy(p, 3, 0, 0, o, r, NULL), LW_OK);
  cr_assert(o[0] == 1 && !r[0]);
  cr_assert(o[1] == 2 && r[1], "path 2 reversed: %zu %d", o[1], r[1]);
  /* at (39,0): path 0's end (40,0) is 1 away */
  cr_assert(o[2] == 0 && r[2]);
  cr_assert_eq(lw_order_travel(p, 3, o, r, 0, 0), 5 + 11 + 1);
}

/* Collinear unit paths 1 mm apart on y = 0, shuffled and randomly turned:
** the best tour sweeps from the nearest end, travel = 1 (to x = 1) plus
** n - 1 gaps of 1 mm.  2-opt must find it from a scrambled tour, not only
** from the greedy one. */
Test(order, collinear_paths_reach_the_optimum)
{
  const size_t n = 60;
  lw_order_path p[60];
  size_t o[60];
  unsigned char r[60];
  rng_seed(77);
  for (size_t k = 0; k < n; k++) {
    double x = 1 + 2 * (double)k;
    p[k] = urand(0, 1) < 0.5 ? (lw_order_path){x, 0, x + 1, 0} : (lw_order_path){x + 1, 0, x, 0};
    o[k] = k;
    r[k] = urand(0, 1) < 0.5;
  }
  for (size_t k = n - 1; k > 0; k--) {
    size_t j = (size_t)urand(0, (double)k + 1);
    size_t t = o[k];
    o[k] = o[j];
    o[j] = t;
  }
  const double best = (double)n;
  cr_assert(lw_order_travel(p, n, o, r, 0, 0) > 10 * best);
  cr_assert_eq(lw_order_2opt(p, n, 0, 0, o, r, NULL), LW_OK);
  assert_permutation(o, n);
  cr_assert(fabs(lw_order_travel(p, n, o, r, 0, 0) - best) < 1e-9, "2-opt: %.12g, best %.12g",
            lw_order_travel(p, n, o, r, 0, 0), best);
  /* and so must greedy followed by 2-opt, starting from home (0, 5) */
  cr_assert_eq(lw_order_greedy(p, n, 0, 5, o, r, NULL), LW_OK);
  cr_assert_eq(lw_order_2opt(p, n, 0, 5, o, r, NULL), LW_OK);
  cr_assert(fabs(lw_order_travel(p, n, o, r, 0, 5) - (hypot(1, 5) + (double)(n - 1))) < 1e-9);
}

/* ---- plots ---------------------------------------------------------- */

/* n straight splines at random, two segments each; spline 3 a point. */
static lw_splines *random_splines(size_t n, uint64_t seed)
{
  size_t *segs = calloc(n, sizeof *segs);
  cr_assert_not_null(segs);
  for (size_t i = 0; i < n; i++) segs[i] = 2;
  lw_splines *sp = lw_splines_new(n, segs, NULL);
  free(segs);
  rng_seed(seed);
  for (size_t i = 0; i < n; i++) {
    double x = urand(10, 200), y = urand(10, 280);
    lw_test_straight(sp, i, x, y, x + urand(-9, 9), y + urand(-9, 9));
  }
  for (size_t k = sp->first[3]; k < sp->first[4]; k++) sp->node[k] = (lw_node){50, 60, 0, 0};
  return sp;
}

/* Each pen's paths are a permutation of its splines, points left out, and
** the plot's travel sums match the tours it reports. */
Test(plot, pens_by_rank_and_travel_never_grows)
{
  const size_t n = 300;
  lw_splines *sp = random_splines(n, 5);
  double key[300];
  for (size_t i = 0; i < n; i++) key[i] = urand(0, 1);
  key[7] = key[8]; /* a tie: index order decides */
  for (int order = LW_PLOT_ORDER_NONE; order <= LW_PLOT_ORDER_2OPT; order++) {
    lw_error err;
    lw_plot *pl = lw_plot_new(sp, 3, key, (lw_plot_order)order, 0, 0, &err);
    cr_assert_not_null(pl, "%s", err.msg);
    cr_assert_eq(pl->n, n - 1);
    /* 299 paths in 3 equal runs by rank: 100, 100, 99 (floor(r 3 / 299)) */
    cr_assert(pl->pen_first[0] == 0 && pl->pen_first[1] == 100 && pl->pen_first[2] == 200 && pl->pen_first[3] == 299,
              "%zu %zu %zu", pl->pen_first[1], pl->pen_first[2], pl->pen_first[3]);
    double top[3] = {-INFINITY, -INFINITY, -INFINITY}, low[3] = {INFINITY, INFINITY, INFINITY};
    unsigned char seen[300] = {0};
    double sum_after = 0, sum_before = 0;
    for (int k = 0; k < 3; k++) {
      size_t a = pl->pen_first[k], b = pl->pen_first[k + 1];
      lw_order_path *path = malloc((b - a) * sizeof *path);
      size_t *sorted = malloc((b - a) * sizeof *sorted);
      for (size_t j = a; j < b; j++) {
        size_t i = pl->spline[j];
        cr_assert(i != 3 && !seen[i]);
        seen[i] = 1;
        top[k] = fmax(top[k], key[i]);
        low[k] = fmin(low[k], key[i]);
        const lw_node *f = &sp->node[sp->first[i]], *l = &sp->node[sp->first[i + 1] - 1];
        path[j - a] = (lw_order_path){f->px, f->py, l->px, l->py};
        if (order == LW_PLOT_ORDER_NONE) cr_assert(!pl->reversed[j] && (j == a || pl->spline[j - 1] < i));
      }
      sum_after += lw_order_travel(path, b - a, NULL, pl->reversed + a, 0, 0);
      /* before: the same splines in index order */
      for (size_t j = a; j < b; j++) sorted[j - a] = pl->spline[j];
      for (size_t x = 1; x < b - a; x++)
        for (size_t y = x; y > 0 && sorted[y - 1] > sorted[y]; y--) {
          size_t t = sorted[y];
          sorted[y] = sorted[y - 1];
          sorted[y - 1] = t;
        }
      for (size_t j = 0; j < b - a; j++) {
        const lw_node *f = &sp->node[sp->first[sorted[j]]], *l = &sp->node[sp->first[sorted[j] + 1] - 1];
        path[j] = (lw_order_path){f->px, f->py, l->px, l->py};
      }
      sum_before += lw_order_travel(path, b - a, NULL, NULL, 0, 0);
      free(path);
      free(sorted);
    }
    /* darker (lower key) pens first: the runs do not overlap */
    cr_assert(top[0] <= low[1] && top[1] <= low[2]);
    cr_assert(fabs(sum_after - pl->travel_after) <= 1e-9 * sum_after, "%.12g vs %.12g", sum_after, pl->travel_after);
    cr_assert(fabs(sum_before - pl->travel_before) <= 1e-9 * sum_before);
    cr_assert(pl->travel_after <= pl->travel_before);
    if (order == LW_PLOT_ORDER_NONE) cr_assert_eq(pl->travel_after, pl->travel_before);
    else cr_assert(pl->travel_after < 0.25 * pl->travel_before);
    lw_plot_free(pl);
  }
  lw_splines_free(sp);
}

/* An input order that beats greedy: home at x = 0, short paths at x = -2,
** 1, 5, 9.  Greedy goes to 1, back to -2, then out to 5 and 9; index order
** sweeps -2, 1, 5, 9.  The plot keeps the input (travel after == before),
** and 2-opt starts from it. */
Test(plot, an_input_order_better_than_greedy_is_kept)
{
  size_t segs[4] = {1, 1, 1, 1};
  lw_splines *sp = lw_splines_new(4, segs, NULL);
  const double x[4] = {-2, 1, 5, 9};
  lw_order_path p[4];
  for (int i = 0; i < 4; i++) {
    lw_test_straight(sp, (size_t)i, x[i], 0, x[i], 0.5);
    p[i] = (lw_order_path){x[i], 0, x[i], 0.5};
  }
  size_t o[4];
  unsigned char r[4];
  cr_assert_eq(lw_order_greedy(p, 4, 0, 0, o, r, NULL), LW_OK);
  double greedy = lw_order_travel(p, 4, o, r, 0, 0), index = lw_order_travel(p, 4, NULL, NULL, 0, 0);
  cr_assert(greedy > index + 1, "the instance is a greedy trap: %g vs %g", greedy, index);
  for (int order = LW_PLOT_ORDER_GREEDY; order <= LW_PLOT_ORDER_2OPT; order++) {
    lw_plot *pl = lw_plot_new(sp, 1, NULL, (lw_plot_order)order, 0, 0, NULL);
    cr_assert_not_null(pl);
    cr_assert_eq(pl->travel_before, index);
    if (order == LW_PLOT_ORDER_GREEDY) {
      cr_assert_eq(pl->travel_after, index);
      for (size_t j = 0; j < 4; j++) cr_assert(pl->spline[j] == j && !pl->reversed[j]);
    } else {
      cr_assert(pl->travel_after <= index);
    }
    lw_plot_free(pl);
  }
  lw_splines_free(sp);
}

Test(plot, round_robin_without_keys_and_bad_input)
{
  lw_splines *sp = random_splines(10, 9);
  lw_plot *pl = lw_plot_new(sp, 4, NULL, LW_PLOT_ORDER_NONE, 0, 0, NULL);
  cr_assert_not_null(pl);
  /* spline i -> pen i mod 4; spline 3 (a point) is left out */
  const size_t want[9] = {0, 4, 8, 1, 5, 9, 2, 6, 7};
  const size_t first[5] = {0, 3, 6, 8, 9};
  cr_assert_eq(pl->n, 9);
  for (int k = 0; k <= 4; k++) cr_assert_eq(pl->pen_first[k], first[k]);
  for (size_t j = 0; j < 9; j++) cr_assert_eq(pl->spline[j], want[j], "path %zu", j);
  lw_plot_free(pl);
  lw_error err;
  cr_assert_null(lw_plot_new(sp, 0, NULL, LW_PLOT_ORDER_NONE, 0, 0, &err));
  cr_assert_eq(err.code, LW_EINPUT);
  cr_assert_null(lw_plot_new(sp, LW_PLOT_PENS_MAX + 1, NULL, LW_PLOT_ORDER_NONE, 0, 0, &err));
  sp->node[5].vx = NAN;
  cr_assert_null(lw_plot_new(sp, 1, NULL, LW_PLOT_ORDER_2OPT, 0, 0, &err));
  cr_assert_eq(err.code, LW_EINPUT);
  lw_splines_free(sp);
}
