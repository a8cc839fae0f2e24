/*
** test_strokes.c -- the plotter post-pass (strokes.h): joins, drops, the
** exact crop, ordering, the plot time, and the [plot] keys on the command
** line.
*/
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "linewise/strokes.h"
#include "testutil.h"

/* A straight cubic from (x0, y0) to (x1, y1), uniform speed. */
static void line(double *b, double x0, double y0, double x1, double y1)
{
  for (int c = 0; c < 4; c++) {
    b[2 * c] = x0 + (x1 - x0) * c / 3.0;
    b[2 * c + 1] = y0 + (y1 - y0) * c / 3.0;
  }
}

static void add_line(lw_strokes *s, int pen, size_t src, double x0, double y0, double x1, double y1)
{
  double b[8];
  line(b, x0, y0, x1, y1);
  cr_assert_eq(lw_strokes_add(s, pen, src, 0, 0, b, 1, NULL), LW_OK);
}

static size_t segs(const lw_strokes *s, size_t k) { return s->first[k + 1] - s->first[k]; }

static const double *seg(const lw_strokes *s, size_t k, size_t m) { return s->b + 8 * (s->first[k] + m); }

Test(strokes, joins_close_aligned_ends_and_nothing_else)
{
  lw_strokes *s = lw_strokes_new(1, NULL);
  add_line(s, 0, 0, 0, 0, 10, 0);       /* A, ends at (10, 0) heading +x */
  add_line(s, 0, 1, 20, 0, 10.2, 0);    /* B backwards: its end meets A's end */
  add_line(s, 0, 2, 10.1, 0.05, 10.1, 8); /* C starts near A's end but turns 90 degrees */
  add_line(s, 0, 3, 20.5, 0, 30, 0);    /* D starts 0.5 after B's far end: too far */
  lw_strokes_report rep = {0};
  lw_strokes *j = lw_strokes_join(s, (const double[]){0.3}, 30 * M_PI / 180, 0, &rep, NULL);
  cr_assert_not_null(j);
  cr_assert_eq(rep.joins, 1);
  cr_assert_eq(j->n, 3, "A+B, C, D");
  /* A, then the bridge from (10, 0) to (10.2, 0), then B drawn backwards */
  cr_assert_eq(j->src[0], 0);
  cr_assert_eq(segs(j, 0), 3);
  cr_assert_eq(memcmp(seg(j, 0, 0), seg(s, 0, 0), 8 * sizeof(double)), 0);
  const double *br = seg(j, 0, 1), *b = seg(j, 0, 2), *orig = seg(s, 1, 0);
  cr_assert(br[0] == 10 && br[1] == 0 && br[6] == 10.2 && br[7] == 0);
  cr_assert(fabs(br[2] - (10 + 0.2 / 3)) < 1e-15 && fabs(br[4] - (10.2 - 0.2 / 3)) < 1e-15);
  for (int c = 0; c < 4; c++)
    cr_assert(b[2 * c] == orig[6 - 2 * c] && b[2 * c + 1] == orig[7 - 2 * c], "B reversed exactly");
  cr_assert_eq(j->src[1], 2);
  cr_assert_eq(j->src[2], 3);
  lw_strokes_free(j);

  /* any turn allowed and a wider distance: the nearest ends go first, so
  ** C (0.11 from A's end) takes A's end before B (0.2), and B joins D */
  memset(&rep, 0, sizeof rep);
  j = lw_strokes_join(s, (const double[]){0.6}, M_PI, 0, &rep, NULL);
  cr_assert_eq(rep.joins, 2);
  cr_assert_eq(j->n, 2);
  cr_assert_eq(segs(j, 0), 3, "A, a bridge, C");
  cr_assert_eq(j->src[0], 0);
  cr_assert_eq(j->src[1], 1);
  cr_assert_eq(segs(j, 1), 3, "B backwards, a bridge, D");
  lw_strokes_free(j);
  lw_strokes_free(s);

  /* strokes side by side, the second starting 0.2 behind where the first
  ** ends: they align, but the bridge would hook back over the ink */
  s = lw_strokes_new(1, NULL);
  add_line(s, 0, 0, 0, 0, 10, 0);
  add_line(s, 0, 1, 9.8, 0.1, 20, 0.1);
  memset(&rep, 0, sizeof rep);
  j = lw_strokes_join(s, (const double[]){0.3}, 30 * M_PI / 180, 0, &rep, NULL);
  cr_assert_eq(rep.joins, 0, "a bridge back over the ink");
  lw_strokes_free(j);
  /* 0.02 behind (a tenth of the distance): joined */
  s->b[8 * 1] = 9.98;
  s->b[8 * 1 + 2] = 9.98 + (20 - 9.98) / 3;
  s->b[8 * 1 + 4] = 9.98 + 2 * (20 - 9.98) / 3;
  memset(&rep, 0, sizeof rep);
  j = lw_strokes_join(s, (const double[]){0.3}, 30 * M_PI / 180, 0, &rep, NULL);
  cr_assert_eq(rep.joins, 1, "ends that overlap by a hair");
  lw_strokes_free(j);
  lw_strokes_free(s);
}

Test(strokes, a_ring_of_strokes_joins_into_one_open_path)
{
  /* four sides of a square with small gaps at the corners: with any turn
  ** allowed the fourth join would close a cycle, which is refused */
  lw_strokes *s = lw_strokes_new(1, NULL);
  add_line(s, 0, 0, 0.1, 0, 9.9, 0);
  add_line(s, 0, 1, 10, 0.1, 10, 9.9);
  add_line(s, 0, 2, 9.9, 10, 0.1, 10);
  add_line(s, 0, 3, 0, 9.9, 0, 0.1);
  lw_strokes_report rep = {0};
  lw_strokes *j = lw_strokes_join(s, (const double[]){0.2}, M_PI, 0, &rep, NULL);
  cr_assert_eq(rep.joins, 3);
  cr_assert_eq(j->n, 1);
  cr_assert_eq(segs(j, 0), 7, "four sides and three bridges");
  /* consecutive segments meet exactly */
  for (size_t m = 0; m + 1 < 7; m++)
    cr_assert(seg(j, 0, m)[6] == seg(j, 0, m + 1)[0] && seg(j, 0, m)[7] == seg(j, 0, m + 1)[1]);
  lw_strokes_free(j);
  /* a 90 degree corner is above the default 30 degrees */
  memset(&rep, 0, sizeof rep);
  j = lw_strokes_join(s, (const double[]){0.2}, 30 * M_PI / 180, 0, &rep, NULL);
  cr_assert_eq(rep.joins, 0);
  cr_assert_eq(j->n, 4);
  lw_strokes_free(j);
  lw_strokes_free(s);
}

Test(strokes, joins_stay_within_their_pen)
{
  lw_strokes *s = lw_strokes_new(2, NULL);
  add_line(s, 0, 0, 0, 0, 10, 0);
  add_line(s, 1, 1, 10.1, 0, 20, 0);
  lw_strokes_report rep = {0};
  lw_strokes *j = lw_strokes_join(s, (const double[]){0.3, 0.3}, M_PI, 0, &rep, NULL);
  cr_assert_eq(rep.joins, 0);
  cr_assert_eq(j->n, 2);
  cr_assert_eq(j->pen_first[1], 1);
  lw_strokes_free(j);
  lw_strokes_free(s);
}

/* Each pen joins the gaps and drops the paths its own width says: a gap of
** 0.8 mm is closed by a pen of 1 mm and kept by one of 0.3 mm, and a path
** of 2 mm is short for the wide pen (3 widths) only. */
Test(strokes, each_pen_joins_and_drops_by_its_own_width)
{
  lw_strokes *s = lw_strokes_new(2, NULL);
  for (int pen = 0; pen < 2; pen++) {
    const double y = 10.0 * pen;
    add_line(s, pen, 3 * (size_t)pen, 0, y, 10, y);
    add_line(s, pen, 3 * (size_t)pen + 1, 10.8, y, 20.8, y);
    add_line(s, pen, 3 * (size_t)pen + 2, 40, y, 42, y);
  }
  const double width[2] = {0.3, 1.0}, join[2] = {width[0], width[1]}, drop[2] = {3 * width[0], 3 * width[1]};
  lw_strokes_report rep = {0};
  lw_strokes *j = lw_strokes_join(s, join, M_PI, 0, &rep, NULL);
  cr_assert_eq(rep.joins, 1);
  cr_assert(j->n == 5 && j->pen_first[1] == 3, "%zu paths, pen 2 from %zu", j->n, j->pen_first[1]);
  lw_strokes *d = lw_strokes_drop(j, drop, &rep, NULL);
  cr_assert_eq(rep.dropped, 1);
  cr_assert(d->n == 4 && d->pen_first[1] == 3, "%zu paths, pen 2 from %zu", d->n, d->pen_first[1]);
  cr_assert(fabs(lw_strokes_length(d, 3) - 20.8) < 1e-9, "pen 2's joined path: %g mm", lw_strokes_length(d, 3));
  lw_strokes_free(d);
  lw_strokes_free(j);
  lw_strokes_free(s);
}

/* ---- the joins against every pair sorted at once --------------------------- */

typedef struct {
  double d;
  size_t a, b;
} ref_pair;

static int ref_by_gap(const void *pa, const void *pb)
{
  const ref_pair *x = pa, *y = pb;
  if (x->d != y->d) return x->d < y->d ? -1 : 1;
  if (x->a != y->a) return x->a < y->a ? -1 : 1;
  return (x->b > y->b) - (x->b < y->b);
}

static size_t ref_root(size_t *up, size_t k)
{
  while (up[k] != k) k = up[k];
  return k;
}

/* End e of straight path e / 2 (strokes.h's order: 2k its start, 2k + 1 its
** end): the point, and the direction out of the path there. */
static void ref_end(const lw_strokes *s, size_t e, double *pt, double *out)
{
  const double *b = seg(s, e / 2, 0), *p = b + (e & 1 ? 6 : 0), *q = b + (e & 1 ? 0 : 6);
  const double len = hypot(p[0] - q[0], p[1] - q[1]);
  pt[0] = p[0];
  pt[1] = p[1];
  out[0] = (p[0] - q[0]) / len;
  out[1] = (p[1] - q[1]) / len;
}

/* The joins strokes.h describes, taken from one list of every pair of ends
** of one pen of straight one-segment paths (directed: a path's end with
** another's start alone): for each chain its two free ends' points, as 4
** numbers in the order the chains' first paths come (directed: the chain's
** start first). */
static size_t ref_join(const lw_strokes *s, double dist, double angle, int directed, double *chains)
{
  const size_t n = s->n, ne = 2 * n;
  const double cos_max = cos(angle) - 1e-12;
  double *pt = malloc(ne * 2 * sizeof *pt), *dir = malloc(ne * 2 * sizeof *dir);
  size_t *link = malloc(ne * sizeof *link), *up = malloc(n * sizeof *up), np = 0;
  ref_pair *pairs = malloc(ne * ne / 2 * sizeof *pairs);
  for (size_t e = 0; e < ne; e++) {
    ref_end(s, e, pt + 2 * e, dir + 2 * e);
    link[e] = SIZE_MAX;
  }
  for (size_t a = 0; a < ne; a++)
    for (size_t b = a + 1; b < ne; b++) {
      const double gx = pt[2 * b] - pt[2 * a], gy = pt[2 * b + 1] - pt[2 * a + 1], d = hypot(gx, gy);
      const double c = -(dir[2 * a] * dir[2 * b] + dir[2 * a + 1] * dir[2 * b + 1]);
      const int hook = gx * dir[2 * a] + gy * dir[2 * a + 1] < -0.1 * dist ||
                       -(gx * dir[2 * b] + gy * dir[2 * b + 1]) < -0.1 * dist;
      if (a / 2 != b / 2 && d <= dist && c >= cos_max && !(cos_max > -1.0 && hook) && !(directed && (a & 1) == (b & 1)))
        pairs[np++] = (ref_pair){d, a, b};
    }
  qsort(pairs, np, sizeof *pairs, ref_by_gap);
  for (size_t k = 0; k < n; k++) up[k] = k;
  size_t joins = 0;
  for (size_t p = 0; p < np; p++) {
    const size_t a = pairs[p].a, b = pairs[p].b, ra = ref_root(up, a / 2), rb = ref_root(up, b / 2);
    if (link[a] != SIZE_MAX || link[b] != SIZE_MAX || ra == rb) continue;
    link[a] = b;
    link[b] = a;
    up[ra] = rb;
    joins++;
  }
  /* each chain from its free end of lower index to the other */
  size_t m = 0;
  for (size_t e = 0; e < ne; e++) {
    if (link[e] != SIZE_MAX) continue;
    size_t f = e ^ 1;
    while (link[f] != SIZE_MAX) f = link[f] ^ 1;
    if (directed ? (e & 1) : f < e) continue;
    memcpy(chains + 4 * m, pt + 2 * e, 2 * sizeof *chains);
    memcpy(chains + 4 * m + 2, pt + 2 * f, 2 * sizeof *chains);
    m++;
  }
  free(pt);
  free(dir);
  free(link);
  free(up);
  free(pairs);
  return joins;
}

static int by_four(const void *pa, const void *pb)
{
  const double *x = pa, *y = pb;
  for (int c = 0; c < 4; c++)
    if (x[c] != y[c]) return x[c] < y[c] ? -1 : 1;
  return 0;
}

/* A path's two ends, the smaller (x, then y) first, so that the direction
** a chain is walked in does not count. */
static void ends_in_order(double *four)
{
  if (four[0] > four[2] || (four[0] == four[2] && four[1] > four[3])) {
    double t[2] = {four[0], four[1]};
    four[0] = four[2];
    four[1] = four[3];
    four[2] = t[0];
    four[3] = t[1];
  }
}

/* The joins of s at one distance and angle against ref_join's: the same
** count, and chains between the same pairs of free ends (directed: from
** the same start to the same end). */
static void joins_as_reference(const lw_strokes *s, double dist, double angle, int directed)
{
  const size_t n = s->n;
  double *want = malloc(4 * n * sizeof *want), *got = malloc(4 * n * sizeof *got);
  const size_t joins = ref_join(s, dist, angle, directed, want);
  lw_strokes_report rep = {0};
  lw_strokes *j = lw_strokes_join(s, (const double[]){dist}, angle, directed, &rep, NULL);
  cr_assert_not_null(j);
  cr_assert_eq(rep.joins, joins, "distance %g, angle %g: %zu joins, every pair sorted %zu", dist, angle, rep.joins,
               joins);
  cr_assert_eq(j->n, n - joins);
  for (size_t p = 0; p < j->n; p++) {
    const double *first = seg(j, p, 0), *last = seg(j, p, segs(j, p) - 1);
    double *g = got + 4 * p;
    g[0] = first[0];
    g[1] = first[1];
    g[2] = last[6];
    g[3] = last[7];
    if (!directed) {
      ends_in_order(g);
      ends_in_order(want + 4 * p);
    }
  }
  qsort(got, j->n, 4 * sizeof *got, by_four);
  qsort(want, j->n, 4 * sizeof *want, by_four);
  cr_assert_eq(memcmp(got, want, 4 * j->n * sizeof *got), 0, "distance %g, angle %g: other chains", dist, angle);
  lw_strokes_free(j);
  free(want);
  free(got);
}

/* Under output.order = none (directed) a path keeps the direction it is
** drawn in: two strokes drawn toward each other are not joined (a signed
** field's lines came out joined against it), one drawn on from the other's
** end is, and so is a stroke drawn backward (its reversed flag) whose drawn
** start meets the other's end. */
Test(strokes, directed_joins_keep_each_path_drawn_forward)
{
  lw_strokes_report rep = {0};
  for (int k = 0; k < 3; k++) {
    lw_strokes *s = lw_strokes_new(1, NULL);
    add_line(s, 0, 0, 0, 0, 10, 0);
    double b[8];
    if (k == 0) line(b, 20, 0, 10.1, 0); /* toward the first's end */
    else if (k == 1) line(b, 10.1, 0, 20, 0); /* on from it */
    else line(b, 20, 0, 10.1, 0);             /* stored toward it, drawn from it */
    cr_assert_eq(lw_strokes_add(s, 0, 1, 0, k == 2, b, 1, NULL), LW_OK);
    for (int directed = 0; directed < 2; directed++) {
      rep.joins = 0;
      lw_strokes *j = lw_strokes_join(s, (const double[]){0.5}, M_PI, directed, &rep, NULL);
      cr_assert_not_null(j);
      cr_assert_eq(rep.joins, directed && k == 0 ? 0u : 1u, "case %d, directed %d", k, directed);
      if (directed && k) /* from (0, 0) to (20, 0) */
        cr_assert(seg(j, 0, 0)[0] == 0.0 && seg(j, 0, segs(j, 0) - 1)[6] == 20.0, "case %d", k);
      lw_strokes_free(j);
    }
    lw_strokes_free(s);
  }
}

/* n straight strokes of 1 to 5 mm at random turns, starting at random in a
** square of side box from the origin, the first at (far, far) where far is
** not 0; a fixed stream from seed. */
static lw_strokes *random_strokes(size_t n, double box, double far, unsigned long long seed)
{
  lw_strokes *s = lw_strokes_new(1, NULL);
  for (size_t k = 0; k < n; k++) {
    double u[4];
    for (int c = 0; c < 4; c++) {
      seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
      u[c] = (double)(seed >> 11) / 9007199254740992.0;
    }
    const double x = k || !far ? box * u[0] : far, y = k || !far ? box * u[1] : far, len = 1 + 4 * u[2],
                 th = 2 * M_PI * u[3];
    add_line(s, 0, k, x, y, x + len * cos(th), y + len * sin(th));
  }
  return s;
}

/* The joins are gathered band by band of distance among the ends still
** free (strokes.c), so that a distance past the ends' spacing costs no n^2
** candidates; they must be the joins of one list of every pair, sorted.
** 300 random straight paths on 50 x 50 mm, distances from a tenth of the
** ends' spacing to the whole page, a tight angle and any. */
Test(strokes, joins_by_bands_are_those_of_every_pair_sorted)
{
  lw_strokes *s = random_strokes(300, 50, 0, 12345);
  const double dists[] = {0.1, 0.5, 2, 8, 30, 1e6}, angles[] = {30 * M_PI / 180, M_PI};
  for (size_t i = 0; i < sizeof dists / sizeof dists[0]; i++)
    for (size_t k = 0; k < 4; k++) joins_as_reference(s, dists[i], angles[k % 2], k / 2);
  lw_strokes_free(s);
}

/* A cluster of 800 strokes in 10 x 10 mm and one far off: the first band,
** sized by the page the outlier widens, took the whole cluster's pairs
** (8 GB at 20,000 strokes) until a band past its budget was taken again
** narrower; the joins are still those of every pair sorted. */
Test(strokes, a_cluster_beside_an_outlier_joins_as_every_pair_sorted)
{
  lw_strokes *s = random_strokes(800, 10, 1000, 777);
  joins_as_reference(s, 1e6, 30 * M_PI / 180, 0);
  joins_as_reference(s, 1e6, M_PI, 0);
  joins_as_reference(s, 1e6, M_PI, 1);
  lw_strokes_free(s);
}

/* 600 strokes out of one point, every other one drawn inward: 180,000
** pairs of ends at distance 0, past the band's budget however narrow
** (strokes.c takes them as one distance, end by end, without a list: 32,000
** such strokes took 3 GB); the joins are still those of every pair sorted,
** whose equal distances go in the order of their ends.  (Ends that only
** all but coincide, within 4^-20 of the band, are taken as coinciding.) */
Test(strokes, ends_that_coincide_join_as_every_pair_sorted)
{
  lw_strokes *s = lw_strokes_new(1, NULL);
  unsigned long long seed = 99;
  for (size_t k = 0; k < 600; k++) {
    double u[2];
    for (int c = 0; c < 2; c++) {
      seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
      u[c] = (double)(seed >> 11) / 9007199254740992.0;
    }
    const double len = 1 + 4 * u[0], th = 2 * M_PI * u[1], x = len * cos(th), y = len * sin(th);
    double b[8];
    line(b, 0, 0, x, y);
    if (k % 2) { /* reversed, its end at (0, 0) exactly (x + (0 - x) * 3 / 3 need not be) */
      for (int c = 0; c < 8; c++) b[c] = (c % 2 ? y : x) - b[c];
      b[6] = b[7] = 0.0;
    }
    cr_assert_eq(lw_strokes_add(s, 0, k, 0, 0, b, 1, NULL), LW_OK);
  }
  const double dists[] = {0.5, 1e6}, angles[] = {30 * M_PI / 180, M_PI};
  for (size_t i = 0; i < 2; i++)
    for (size_t k = 0; k < 4; k++) joins_as_reference(s, dists[i], angles[k % 2], k / 2);
  lw_strokes_free(s);
}

/* A pen joined whole: 20,000 paths and a distance of a kilometre, any
** turn, make one path (every pair a candidate took 4.7 GB). */
Test(strokes, a_pen_joined_whole_takes_no_candidate_per_pair)
{
  const size_t n = 20000;
  lw_strokes *s = lw_strokes_new(1, NULL);
  for (size_t k = 0; k < n; k++) {
    const double x = (double)(k % 200), y = (double)(k / 200);
    add_line(s, 0, k, x, y, x + 0.5, y + 0.25);
  }
  lw_strokes_report rep = {0};
  lw_strokes *j = lw_strokes_join(s, (const double[]){1e6}, M_PI, 0, &rep, NULL);
  cr_assert_not_null(j);
  cr_assert_eq(rep.joins, n - 1);
  cr_assert_eq(j->n, 1);
  cr_assert_eq(segs(j, 0), 2 * n - 1, "every path and a bridge between each two");
  lw_strokes_free(j);
  lw_strokes_free(s);
}


Test(strokes, drops_paths_shorter_than_the_minimum)
{
  lw_strokes *s = lw_strokes_new(1, NULL);
  add_line(s, 0, 0, 0, 0, 0.5, 0);
  add_line(s, 0, 1, 5, 5, 5, 6); /* exactly the minimum: kept */
  add_line(s, 0, 2, 5, 5, 8, 9);
  cr_assert(fabs(lw_strokes_length(s, 2) - 5) < 1e-12);
  lw_strokes_report rep = {0};
  lw_strokes *d = lw_strokes_drop(s, (const double[]){1.0}, &rep, NULL);
  cr_assert_eq(rep.dropped, 1);
  cr_assert_eq(d->n, 2);
  cr_assert_eq(d->src[0], 1);
  cr_assert_eq(d->src[1], 2);
  lw_strokes_free(d);
  /* min_length 0 keeps all but a point at the files' precision (written
  ** "M 50 50 C 50 50 50 50 50 50", a laser firing on one spot) */
  add_line(s, 0, 3, 50, 50, 50.00002, 50);
  add_line(s, 0, 4, 50, 50, 50 + 1.5 * LW_STROKES_DOT_MM, 50);
  memset(&rep, 0, sizeof rep);
  d = lw_strokes_drop(s, (const double[]){0.0}, &rep, NULL);
  cr_assert_eq(rep.dropped, 1);
  cr_assert_eq(d->n, 4);
  cr_assert_eq(d->src[3], 4);
  lw_strokes_free(d);
  lw_strokes_free(s);
}

Test(strokes, length_of_a_curved_segment)
{
  /* a quarter of a circle of radius 10 as the usual cubic (k = 0.5523):
  ** its length is within 0.03 % of 5 pi, and the adaptive rule converges
  ** to the cubic's own length (checked against a 1e5-chord polyline) */
  const double k = 0.5522847498;
  double b[8] = {10, 0, 10, 10 * k, 10 * k, 10, 0, 10};
  lw_strokes *s = lw_strokes_new(1, NULL);
  cr_assert_eq(lw_strokes_add(s, 0, 0, 0, 0, b, 1, NULL), LW_OK);
  double poly = 0, prev[2], xy[2];
  lw_bezier_eval(b, 0, prev);
  for (int i = 1; i <= 100000; i++) {
    lw_bezier_eval(b, i / 1e5, xy);
    poly += hypot(xy[0] - prev[0], xy[1] - prev[1]);
    memcpy(prev, xy, sizeof xy);
  }
  double len = lw_strokes_length(s, 0);
  cr_assert(fabs(len - poly) < 1e-8, "%.12f vs %.12f", len, poly);
  cr_assert(fabs(len - 5 * M_PI) < 3e-4 * 5 * M_PI);
  lw_strokes_free(s);
}

/* ---- crop ---------------------------------------------------------------- */

static const double R[4] = {10, 20, 50, 60}; /* x0 y0 x1 y1 */

static int in_rect(const double *xy, double tol)
{
  return xy[0] >= R[0] - tol && xy[0] <= R[2] + tol && xy[1] >= R[1] - tol && xy[1] <= R[3] + tol;
}

static double edge_distance(const double *xy)
{
  return fmin(fmin(fabs(xy[0] - R[0]), fabs(xy[0] - R[2])), fmin(fabs(xy[1] - R[1]), fabs(xy[1] - R[3])));
}

/* The inside stretches of cubic b, found without the library's root
** finder: the inside indicator sampled densely, each change bisected. */
static size_t expected_runs(const double *b, double *t0, double *t1)
{
  const int N = 20000;
  size_t n = 0;
  double xy[2];
  lw_bezier_eval(b, 0, xy);
  int was = in_rect(xy, 0);
  double start = 0;
  for (int i = 1; i <= N; i++) {
    double t = (double)i / N;
    lw_bezier_eval(b, t, xy);
    int is = in_rect(xy, 0);
    if (is == was) continue;
    double lo = (double)(i - 1) / N, hi = t;
    for (int it = 0; it < 80; it++) {
      double mid = 0.5 * (lo + hi);
      lw_bezier_eval(b, mid, xy);
      if (in_rect(xy, 0) == was) lo = mid;
      else hi = mid;
    }
    double cross = 0.5 * (lo + hi);
    if (was) {
      t0[n] = start;
      t1[n++] = cross;
    } else {
      start = cross;
    }
    was = is;
  }
  if (was) {
    t0[n] = start;
    t1[n++] = 1.0;
  }
  return n;
}

Test(strokes, crop_cuts_exactly_at_the_rectangle)
{
  rng_seed(2026);
  lw_strokes *s = lw_strokes_new(1, NULL);
  const size_t N = 400;
  for (size_t i = 0; i < N; i++) {
    double b[8];
    for (int c = 0; c < 4; c++) {
      b[2 * c] = urand(-5, 65);
      b[2 * c + 1] = urand(5, 75);
    }
    cr_assert_eq(lw_strokes_add(s, 0, i, 0, 0, b, 1, NULL), LW_OK);
  }
  lw_strokes_report rep = {0};
  lw_strokes *c = lw_strokes_crop(s, R[0], R[1], R[2], R[3], &rep, NULL);
  cr_assert_not_null(c);
  size_t at = 0, cut = 0, outside = 0, pieces = 0;
  for (size_t i = 0; i < N; i++) {
    const double *b = seg(s, i, 0);
    double t0[16], t1[16];
    size_t n = expected_runs(b, t0, t1);
    pieces += n;
    cut += n && !(n == 1 && t0[0] == 0 && t1[0] == 1);
    outside += !n;
    for (size_t r = 0; r < n; r++, at++) {
      cr_assert(at < c->n, "curve %zu: too few pieces", i);
      cr_assert_eq(c->src[at], i);
      cr_assert_eq(c->part[at], r, "curve %zu piece %zu", i, r);
      cr_assert_eq(segs(c, at), 1);
      const double *p = seg(c, at, 0);
      /* the piece is the original between the crossings */
      for (int q = 0; q <= 8; q++) {
        double sq = q / 8.0, a[2], e[2];
        lw_bezier_eval(p, sq, a);
        lw_bezier_eval(b, t0[r] + sq * (t1[r] - t0[r]), e);
        cr_assert(hypot(a[0] - e[0], a[1] - e[1]) < 1e-9, "curve %zu piece %zu at %g: off by %g", i, r, sq,
                  hypot(a[0] - e[0], a[1] - e[1]));
        cr_assert(in_rect(a, 0), "curve %zu piece %zu leaves the rectangle", i, r);
      }
      /* cut ends lie on the rectangle */
      if (t0[r] > 0) cr_assert(edge_distance(p) < 1e-9, "curve %zu: start %g off the edge", i, edge_distance(p));
      if (t1[r] < 1)
        cr_assert(edge_distance(p + 6) < 1e-9, "curve %zu: end %g off the edge", i, edge_distance(p + 6));
    }
  }
  cr_assert_eq(c->n, pieces);
  cr_assert_eq(rep.cut, cut);
  cr_assert_eq(rep.outside, outside);
  cr_assert(cut > 50 && outside > 10 && pieces > N / 2, "the sample crosses the edge often: %zu %zu", cut, outside);
  lw_strokes_free(c);
  lw_strokes_free(s);
}

Test(strokes, crop_keeps_a_path_whole_across_nodes_inside)
{
  /* a straight spline of five 10 mm segments from x = 5 to 55 at y = 40:
  ** one piece from x = 10 to x = 50, the inner segments untouched */
  lw_strokes *s = lw_strokes_new(1, NULL);
  double b[40];
  for (int m = 0; m < 5; m++) line(b + 8 * m, 5 + 10 * m, 40, 15 + 10 * m, 40);
  cr_assert_eq(lw_strokes_add(s, 0, 7, 0, 0, b, 5, NULL), LW_OK);
  add_line(s, 0, 8, 20, 30, 40, 50); /* wholly inside: kept as it is */
  lw_strokes_report rep = {0};
  lw_strokes *c = lw_strokes_crop(s, R[0], R[1], R[2], R[3], &rep, NULL);
  cr_assert_eq(c->n, 2);
  cr_assert_eq(rep.cut, 1);
  cr_assert_eq(rep.outside, 0);
  cr_assert_eq(segs(c, 0), 5);
  cr_assert(fabs(seg(c, 0, 0)[0] - 10) < 1e-12 && fabs(seg(c, 0, 4)[6] - 50) < 1e-12);
  for (int m = 1; m < 4; m++) cr_assert_eq(memcmp(seg(c, 0, m), b + 8 * m, 8 * sizeof(double)), 0);
  cr_assert_eq(memcmp(seg(c, 1, 0), seg(s, 1, 0), 8 * sizeof(double)), 0);
  lw_strokes_free(c);
  lw_strokes_free(s);
}

/* ---- the whole post-pass on splines ------------------------------------ */

Test(strokes, prepared_splines_stay_inside_and_keep_their_counts)
{
  rng_seed(77);
  const size_t n = 300, nseg = 4;
  size_t counts[300];
  for (size_t i = 0; i < n; i++) counts[i] = nseg;
  lw_splines *sp = lw_splines_new(n, counts, NULL);
  for (size_t i = 0; i < n; i++) {
    double x = urand(0, 60), y = urand(10, 70), a = urand(0, 2 * M_PI), len = urand(0.5, 12);
    for (size_t k = 0; k <= nseg; k++) {
      double t = (double)k / nseg;
      sp->node[sp->first[i] + k] = (lw_node){x + t * len * cos(a) + 0.5 * sin(3 * t), y + t * len * sin(a),
                                             len * cos(a) / (3.0 * nseg), len * sin(a) / (3.0 * nseg)};
    }
  }
  lw_strokes_options o = {.join_dist = {0.3}, .join_angle = 30 * M_PI / 180, .crop = 1, .x0 = R[0], .y0 = R[1],
                          .x1 = R[2], .y1 = R[3], .min_length = {1.0}, .order = LW_PLOT_ORDER_2OPT};
  lw_strokes_report rep;
  lw_strokes *s = lw_strokes_prepare(sp, NULL, &o, &rep, NULL);
  cr_assert_not_null(s);
  cr_assert_eq(rep.lifts_before, n);
  cr_assert_eq(rep.lifts_after, s->n);
  cr_assert(rep.cut > 0 && rep.outside > 0 && rep.dropped > 0, "%zu %zu %zu", rep.cut, rep.outside, rep.dropped);
  cr_assert(rep.travel_after <= rep.travel_before);
  for (size_t k = 0; k < s->n; k++) {
    cr_assert(lw_strokes_length(s, k) >= 1.0);
    for (size_t m = s->first[k]; m < s->first[k + 1]; m++)
      for (int q = 0; q <= 16; q++) {
        double xy[2];
        lw_bezier_eval(s->b + 8 * m, q / 16.0, xy);
        cr_assert(in_rect(xy, 0), "path %zu leaves the rectangle at (%g, %g)", k, xy[0], xy[1]);
      }
  }
  /* the state is not touched: the splines still leave the rectangle */
  int outside = 0;
  for (size_t k = 0; k < sp->n_nodes; k++) outside |= !in_rect(&sp->node[k].px, 0);
  cr_assert(outside);
  lw_strokes_free(s);
  lw_splines_free(sp);
}

Test(strokes, plot_time_and_travel_of_hand_made_drawings)
{
  /* two strokes of 30 and 40 mm; unordered from home (0, 0):
  ** travel = |(0,0) - (10,0)| + |(40,0) - (40,10)| = 10 + 10 */
  lw_strokes *s = lw_strokes_new(1, NULL);
  add_line(s, 0, 0, 10, 0, 40, 0);
  add_line(s, 0, 1, 40, 10, 40, 50);
  lw_strokes_report rep = {0};
  cr_assert_eq(lw_strokes_order(s, LW_PLOT_ORDER_NONE, 0, 0, 0, &rep, NULL), LW_OK);
  cr_assert(fabs(rep.travel_after - 20) < 1e-12);
  cr_assert(fabs(lw_strokes_total_length(s) - 70) < 1e-12);
  double t = lw_strokes_time(s, rep.travel_after, 50, 150, 0.2);
  cr_assert(fabs(t - (70 / 50.0 + 20 / 150.0 + 2 * 0.2)) < 1e-12, "%.15g", t);
  lw_strokes_free(s);
  /* each pen starts at home, and goes home from the last path of a pen
  ** that drew to be changed: 1 out, 2 back, 3 out; an empty pen adds nothing */
  s = lw_strokes_new(3, NULL);
  add_line(s, 0, 0, 1, 0, 2, 0);
  add_line(s, 2, 1, 3, 0, 4, 0);
  cr_assert_eq(lw_strokes_order(s, LW_PLOT_ORDER_NONE, 0, 0, 0, &rep, NULL), LW_OK);
  cr_assert(fabs(rep.travel_after - 6) < 1e-12 && fabs(rep.travel_before - 6) < 1e-12, "%g %g", rep.travel_before,
            rep.travel_after);
  /* the machine files end at home: 4 back from the last path's end */
  cr_assert_eq(lw_strokes_order(s, LW_PLOT_ORDER_NONE, 0, 0, 1, &rep, NULL), LW_OK);
  cr_assert(fabs(rep.travel_after - 10) < 1e-12 && fabs(rep.travel_before - 10) < 1e-12, "%g %g", rep.travel_before,
            rep.travel_after);
  lw_strokes_free(s);
}

Test(strokes, ordering_reverses_and_reorders_within_pens)
{
  lw_strokes *s = lw_strokes_new(1, NULL);
  add_line(s, 0, 0, 100, 0, 90, 0);
  add_line(s, 0, 1, 50, 0, 1, 0);
  lw_strokes_report rep = {0};
  cr_assert_eq(lw_strokes_order(s, LW_PLOT_ORDER_2OPT, 0, 0, 0, &rep, NULL), LW_OK);
  /* from home: the second stroke backwards from (1, 0), then the first backwards */
  cr_assert_eq(s->src[0], 1);
  cr_assert_eq(s->reversed[0], 1);
  cr_assert_eq(s->src[1], 0);
  cr_assert_eq(s->reversed[1], 1);
  cr_assert(fabs(rep.travel_after - (1 + 40)) < 1e-12, "%g", rep.travel_after);
  cr_assert(fabs(rep.travel_before - (100 + 40)) < 1e-12, "%g", rep.travel_before);
  lw_strokes_free(s);
}

/* ---- keys ------------------------------------------------------------- */

Test(strokes, bad_plot_keys_exit_2_naming_file_line_and_key)
{
  const char *b = getenv("LW_BIN");
  cr_assert_not_null(b, "LW_BIN must name bin/linewise (make test sets it)");
  char dir[64];
  lw_test_tmp_name(dir, "strokes");
  cr_assert_not_null(mkdtemp(dir));
  struct {
    const char *line, *key;
  } cases[] = {
    {"join_distance = -1", "plot.join_distance"}, {"join_angle = 200", "plot.join_angle"},
    {"crop = 2", "plot.crop"},                    {"min_length = -0.5", "plot.min_length"},
    {"speed_down = 0", "plot.speed_down"},        {"speed_up = fast", "plot.speed_up"},
    {"lift_time = -1", "plot.lift_time"},
  };
  for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
    char cmd[1024], errs[4096] = "";
    snprintf(cmd, sizeof cmd,
             "cd %s && printf '[scene]\\nwidth = 50\\nheight = 50\\n\\n[plot]\\n%s\\n' > s.ini && "
             "%s run s.ini --out o >/dev/null 2>err.txt",
             dir, cases[k].line, b);
    int st = system(cmd);
    cr_assert(WIFEXITED(st) && WEXITSTATUS(st) == 2, "%s: status %d", cases[k].line, st);
    snprintf(cmd, sizeof cmd, "%s/err.txt", dir);
    FILE *f = fopen(cmd, "r");
    errs[fread(errs, 1, sizeof errs - 1, f)] = '\0';
    fclose(f);
    char want[128];
    snprintf(want, sizeof want, "s.ini:6: key '%s': expected", cases[k].key);
    cr_assert(strstr(errs, want), "%s: %s", cases[k].line, errs);
    snprintf(cmd, sizeof cmd, "test ! -e %s/o", dir);
    cr_assert_eq(system(cmd), 0, "%s: nothing written", cases[k].line);
  }
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  cr_assert_eq(system(cmd), 0);
}
