/*
** order.c -- greedy, 2-opt and Or-opt ordering of plotter paths (order.h).
**
** End points are numbered 2p (start of path p) and 2p + 1 (end of path p).
** A uniform grid of them answers "nearest end point" for the greedy tour and
** "K nearest end points" for the 2-opt candidate lists.
*/
#include "linewise/order.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ---- a grid of points with removal ------------------------------------ */

/* Points sit in cells of side `side`; cell c holds item[start[c] ..
** start[c] + count[c]), removal swaps a point with the last one of its
** cell.  Search order inside a cell therefore changes as points go, which is
** why every search breaks ties by point id explicitly. */
typedef struct {
  double x0, y0, side;
  int nx, ny;
  size_t *start, *count, *item;
  double *ix, *iy;               /* coordinates of item[s], kept beside it so
                                    that a search reads memory in order */
  size_t *cell, *slot;           /* per point id */
  size_t *ring;                  /* scratch: the cells of one ring */
  size_t left;                   /* points still in */
} point_grid;

static void grid_free(point_grid *g)
{
  free(g->start);
  free(g->count);
  free(g->item);
  free(g->ix);
  free(g->iy);
  free(g->cell);
  free(g->slot);
  free(g->ring);
}

static void grid_locate(const point_grid *g, double x, double y, int *cx, int *cy)
{
  double fx = (x - g->x0) / g->side, fy = (y - g->y0) / g->side;
  *cx = fx >= 1.0 ? (fx < (double)g->nx ? (int)fx : g->nx - 1) : 0;
  *cy = fy >= 1.0 ? (fy < (double)g->ny ? (int)fy : g->ny - 1) : 0;
}

/* Grid of the points ids[0..np) at (px[id], py[id]); the per-point arrays
** are sized n_ids (the largest id + 1).  About two points per cell. */
static int grid_build(point_grid *g, const double *px, const double *py, const size_t *ids, size_t np,
                      size_t n_ids)
{
  memset(g, 0, sizeof *g);
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  for (size_t k = 0; k < np; k++) {
    size_t id = ids[k];
    x0 = fmin(x0, px[id]);
    x1 = fmax(x1, px[id]);
    y0 = fmin(y0, py[id]);
    y1 = fmax(y1, py[id]);
  }
  if (!np) x0 = y0 = x1 = y1 = 0;
  double w = x1 - x0, h = y1 - y0, target = fmax(1.0, 0.5 * (double)np);
  /* a square cell for `target` cells over the box; on a thin box the long
  ** side alone decides (a zero area would give zero-sized cells) */
  double side = fmax(sqrt(w * h / target), fmax(w, h) / target);
  if (!(side > 0)) side = 1.0;
  g->x0 = x0;
  g->y0 = y0;
  g->side = side;
  g->nx = (int)fmin(floor(w / side) + 1, target + 1);
  g->ny = (int)fmin(floor(h / side) + 1, target + 1);
  size_t nc = (size_t)g->nx * (size_t)g->ny;
  g->start = calloc(nc + 1, sizeof *g->start);
  g->count = calloc(nc, sizeof *g->count);
  g->item = malloc((np ? np : 1) * sizeof *g->item);
  g->ix = malloc((np ? np : 1) * sizeof *g->ix);
  g->iy = malloc((np ? np : 1) * sizeof *g->iy);
  g->cell = malloc((n_ids ? n_ids : 1) * sizeof *g->cell);
  g->slot = malloc((n_ids ? n_ids : 1) * sizeof *g->slot);
  g->ring = malloc((2 * ((size_t)g->nx + (size_t)g->ny) + 1) * sizeof *g->ring);
  if (!g->start || !g->count || !g->item || !g->ix || !g->iy || !g->cell || !g->slot || !g->ring) {
    grid_free(g);
    return 0;
  }
  for (size_t k = 0; k < np; k++) {
    int cx, cy;
    grid_locate(g, px[ids[k]], py[ids[k]], &cx, &cy);
    g->cell[ids[k]] = (size_t)cy * (size_t)g->nx + (size_t)cx;
    g->count[g->cell[ids[k]]]++;
  }
  for (size_t c = 0; c < nc; c++) g->start[c + 1] = g->start[c] + g->count[c];
  memset(g->count, 0, nc * sizeof *g->count);
  for (size_t k = 0; k < np; k++) {
    size_t c = g->cell[ids[k]], s = g->start[c] + g->count[c]++;
    g->item[s] = ids[k];
    g->ix[s] = px[ids[k]];
    g->iy[s] = py[ids[k]];
    g->slot[ids[k]] = s;
  }
  g->left = np;
  return 1;
}

static void grid_remove(point_grid *g, size_t id)
{
  size_t c = g->cell[id], last = g->start[c] + --g->count[c], s = g->slot[id];
  size_t other = g->item[last];
  double x = g->ix[s], y = g->iy[s];
  g->item[s] = other;
  g->ix[s] = g->ix[last];
  g->iy[s] = g->iy[last];
  g->slot[other] = s;
  g->item[last] = id;
  g->ix[last] = x;
  g->iy[last] = y;
  g->slot[id] = last;
  g->left--;
}

/* (d2, id) ordering: the nearer point, on a tie the lower id. */
static int before(double d2a, size_t ida, double d2b, size_t idb)
{
  return d2a < d2b || (d2a == d2b && ida < idb);
}

/* The cells of the grid at Chebyshev distance r from (cx, cy) into
** cells[] (room for 2 (nx + ny) + 1); returns their number. */
static size_t ring_cells(const point_grid *g, int cx, int cy, int r, size_t *cells)
{
  size_t n = 0;
  int lo_x = cx - r, hi_x = cx + r, lo_y = cy - r, hi_y = cy + r;
  for (int y = lo_y < 0 ? 0 : lo_y; y <= hi_y && y < g->ny; y++) {
    /* the top and bottom rows whole, the rows between only at both ends */
    int step = y == lo_y || y == hi_y ? 1 : hi_x - lo_x;
    for (int x = lo_x; x <= hi_x; x += step)
      if (x >= 0 && x < g->nx) cells[n++] = (size_t)y * (size_t)g->nx + (size_t)x;
  }
  return n;
}

/* Rings beyond r_max cover nothing. */
static int ring_max(const point_grid *g, int cx, int cy)
{
  int r = cx > g->nx - 1 - cx ? cx : g->nx - 1 - cx;
  int ry = cy > g->ny - 1 - cy ? cy : g->ny - 1 - cy;
  return r > ry ? r : ry;
}

/* Points in ring r lie at least (r - 1) cell sides from (x, y): clamping
** into the grid moves a point outside it by at most its true distance per
** axis, so the bound holds for queries outside the grid too. */
static double ring_bound2(const point_grid *g, int r)
{
  double b = r > 1 ? (double)(r - 1) * g->side : 0.0;
  return b * b;
}

/* The nearest point still in the grid; SIZE_MAX when it is empty. */
static size_t grid_nearest(const point_grid *g, double x, double y)
{
  size_t best = SIZE_MAX;
  double best_d2 = INFINITY;
  if (!g->left) return best;
  int cx, cy;
  grid_locate(g, x, y, &cx, &cy);
  int rmax = ring_max(g, cx, cy);
  for (int r = 0; r <= rmax; r++) {
    if (best != SIZE_MAX && best_d2 <= ring_bound2(g, r)) break;
    size_t nc = ring_cells(g, cx, cy, r, g->ring);
    for (size_t i = 0; i < nc; i++)
      for (size_t s = g->start[g->ring[i]], e = s + g->count[g->ring[i]]; s < e; s++) {
        size_t id = g->item[s];
        double dx = g->ix[s] - x, dy = g->iy[s] - y, d2 = dx * dx + dy * dy;
        if (before(d2, id, best_d2, best)) {
          best_d2 = d2;
          best = id;
        }
      }
  }
  return best;
}

/* The k nearest points to point id at (x, y), other than id and its
** partner id ^ 1, nearest first, into out[]; returns how many were found. */
static size_t grid_knearest(const point_grid *g, size_t id, double x, double y, size_t k, size_t *out,
                            double *d2s)
{
  size_t found = 0;
  int cx, cy;
  grid_locate(g, x, y, &cx, &cy);
  int rmax = ring_max(g, cx, cy);
  for (int r = 0; r <= rmax; r++) {
    if (found == k && d2s[k - 1] <= ring_bound2(g, r)) break;
    size_t nc = ring_cells(g, cx, cy, r, g->ring);
    for (size_t i = 0; i < nc; i++)
      for (size_t s = g->start[g->ring[i]], e = s + g->count[g->ring[i]]; s < e; s++) {
        size_t q = g->item[s];
        if ((q | 1) == (id | 1)) continue;
        double dx = g->ix[s] - x, dy = g->iy[s] - y, d2 = dx * dx + dy * dy;
        if (found == k && !before(d2, q, d2s[k - 1], out[k - 1])) continue;
        size_t at = found < k ? found++ : k - 1;
        while (at > 0 && before(d2, q, d2s[at - 1], out[at - 1])) {
          d2s[at] = d2s[at - 1];
          out[at] = out[at - 1];
          at--;
        }
        d2s[at] = d2;
        out[at] = q;
      }
  }
  return found;
}

/* End point coordinates: px[2p], py[2p] the start of p, [2p + 1] its end;
** room for `extra` more points after them. */
static int end_points(const lw_order_path *path, size_t n, size_t extra, double **px, double **py)
{
  *px = malloc((2 * n + extra) * sizeof **px);
  *py = malloc((2 * n + extra) * sizeof **py);
  if (!*px || !*py) {
    free(*px);
    free(*py);
    return 0;
  }
  for (size_t p = 0; p < n; p++) {
    (*px)[2 * p] = path[p].x0;
    (*py)[2 * p] = path[p].y0;
    (*px)[2 * p + 1] = path[p].x1;
    (*py)[2 * p + 1] = path[p].y1;
  }
  return 1;
}

/* ---- travel ------------------------------------------------------------ */

double lw_order_travel(const lw_order_path *path, size_t n, const size_t *order,
                       const unsigned char *reversed, double hx, double hy)
{
  double sum = 0.0, x = hx, y = hy;
  for (size_t k = 0; k < n; k++) {
    const lw_order_path *p = &path[order ? order[k] : k];
    int r = reversed && reversed[k];
    sum += hypot((r ? p->x1 : p->x0) - x, (r ? p->y1 : p->y0) - y);
    x = r ? p->x0 : p->x1;
    y = r ? p->y0 : p->y1;
  }
  return sum;
}

/* ---- greedy ------------------------------------------------------------ */

lw_status lw_order_greedy(const lw_order_path *path, size_t n, double hx, double hy,
                          size_t *order, unsigned char *reversed, lw_error *err)
{
  double *px, *py;
  size_t *ids = malloc((2 * n + 1) * sizeof *ids);
  if (!ids || !end_points(path, n, 0, &px, &py)) {
    free(ids);
    return lw_error_set(err, LW_ENOMEM, "out of memory ordering %zu paths", n);
  }
  for (size_t id = 0; id < 2 * n; id++) ids[id] = id;
  point_grid g;
  if (!grid_build(&g, px, py, ids, 2 * n, 2 * n)) {
    free(ids);
    free(px);
    free(py);
    return lw_error_set(err, LW_ENOMEM, "out of memory ordering %zu paths", n);
  }
  double x = hx, y = hy;
  for (size_t k = 0; k < n; k++) {
    size_t id = grid_nearest(&g, x, y);
    size_t p = id / 2;
    order[k] = p;
    reversed[k] = (unsigned char)(id & 1);
    grid_remove(&g, 2 * p);
    grid_remove(&g, 2 * p + 1);
    x = px[id ^ 1];
    y = py[id ^ 1];
  }
  grid_free(&g);
  free(ids);
  free(px);
  free(py);
  return LW_OK;
}

/* ---- 2-opt ------------------------------------------------------------- */

/* The tour as a cycle of m = n + 1 items: the paths and a virtual home
** item n whose start is FREE (n * 2, at zero distance from everything) and
** whose end is the home point (n * 2 + 1).  Forward, home leads the tour
** and the leg back into it costs nothing, which is exactly the open tour
** from home.  A cycle can be reversed as a whole without changing its
** length (every leg is symmetric), so a cut may reverse either side.
**
** The cycle is a two-level list (Fredman, Johnson, McGeoch and Ostheimer
** 1995): the items lie in slots item[0..m), cut into blocks of neighbouring
** slots, each read forwards or backwards (brev); the tour is the blocks in
** the order of border[].  An array tour moved up to m / 2 entries per
** reversal, and at 10^5 dense paths the reversals were nearly all of the
** time (issue 14).  Here a stretch inside one block is reversed in its
** slots (at most `group` entries); any other is first cut at its two ends,
** which splits at most two blocks, and is then a run of whole blocks whose
** order and reading direction are reversed: O(sqrt m) entries a move.
** Splits only make blocks smaller and more numerous; when they would pass
** max_blk, the tour is laid out afresh in blocks of `group` slots. */
typedef struct {
  size_t n, m, free_pt;
  double *px, *py;              /* owned; by label after relabel() */
  size_t *orig;                 /* label -> path (n: home) */
  size_t *item, *slot;          /* slot -> item, item -> slot */
  unsigned char *rev;           /* per item: reversed within its block's reading */
  size_t *blk;                  /* item -> block */
  size_t *lo, *hi;              /* per block: its slots [lo, hi) */
  unsigned char *brev;          /* per block: read from hi - 1 down to lo */
  size_t *border, *bpos;        /* place in the tour -> block, block -> place */
  size_t nblk, max_blk, group;
  size_t *scratch;              /* m items: the tour while it is laid out afresh */
  size_t *nb;                   /* LW_ORDER_NEIGHBOURS candidates per point */
  unsigned char *nbn;           /* how many each point has */
  size_t *queue;                /* FIFO ring of items to look at */
  unsigned char *queued;
  size_t q_head, q_len;
  unsigned long long work, budget;
} two_opt;

static double leg(const two_opt *t, size_t a, size_t b)
{
  if (a == t->free_pt || b == t->free_pt) return 0.0;
  /* not hypot(): no overflow is possible at page scale, and the square
  ** root is several times cheaper */
  double dx = t->px[a] - t->px[b], dy = t->py[a] - t->py[b];
  return sqrt(dx * dx + dy * dy);
}

/* Whether the item is drawn backwards in the tour. */
static int orient(const two_opt *t, size_t item) { return t->rev[item] ^ t->brev[t->blk[item]]; }
static size_t entry_of(const two_opt *t, size_t item) { return 2 * item + (size_t)orient(t, item); }
static size_t exit_of(const two_opt *t, size_t item) { return 2 * item + 1 - (size_t)orient(t, item); }

/* The first and the last item of block b in tour order. */
static size_t block_first(const two_opt *t, size_t b) { return t->item[t->brev[b] ? t->hi[b] - 1 : t->lo[b]]; }
static size_t block_last(const two_opt *t, size_t b) { return t->item[t->brev[b] ? t->lo[b] : t->hi[b] - 1]; }

static size_t succ(const two_opt *t, size_t item)
{
  size_t b = t->blk[item], s = t->slot[item];
  if (t->brev[b] ? s > t->lo[b] : s + 1 < t->hi[b]) return t->item[t->brev[b] ? s - 1 : s + 1];
  size_t p = t->bpos[b] + 1;
  return block_first(t, t->border[p == t->nblk ? 0 : p]);
}

static size_t pred(const two_opt *t, size_t item)
{
  size_t b = t->blk[item], s = t->slot[item];
  if (t->brev[b] ? s + 1 < t->hi[b] : s > t->lo[b]) return t->item[t->brev[b] ? s + 1 : s - 1];
  size_t p = t->bpos[b];
  return block_last(t, t->border[(p ? p : t->nblk) - 1]);
}

/* Blocks of `group` slots over item[], each read forwards, in slot order. */
static void cut_blocks(two_opt *t)
{
  size_t g = t->group;
  t->nblk = (t->m + g - 1) / g;
  for (size_t b = 0; b < t->nblk; b++) {
    t->lo[b] = b * g;
    t->hi[b] = t->m < (b + 1) * g ? t->m : (b + 1) * g;
    t->brev[b] = 0;
    t->border[b] = t->bpos[b] = b;
    for (size_t s = t->lo[b]; s < t->hi[b]; s++) t->blk[t->item[s]] = b;
  }
}

/* The tour laid out afresh: slot k holds its k-th item (from the first
** block), each drawn as before with its block's reading folded into rev. */
static void lay_out(two_opt *t)
{
  size_t k = 0;
  for (size_t p = 0; p < t->nblk; p++) {
    size_t b = t->border[p];
    if (t->brev[b])
      for (size_t s = t->hi[b]; s-- > t->lo[b];) {
        t->scratch[k++] = t->item[s];
        t->rev[t->item[s]] ^= 1;
      }
    else
      for (size_t s = t->lo[b]; s < t->hi[b]; s++) t->scratch[k++] = t->item[s];
  }
  for (k = 0; k < t->m; k++) {
    t->item[k] = t->scratch[k];
    t->slot[t->scratch[k]] = k;
  }
  cut_blocks(t);
  t->work += 3 * t->m;
}

/* Splits block b into its slots [lo, c) and [c, hi), lo < c < hi; the
** smaller part becomes a new block, placed before or after b in the tour
** as b's reading direction says. */
static void split(two_opt *t, size_t b, size_t c)
{
  size_t nw = t->nblk++;
  int low_new = c - t->lo[b] < t->hi[b] - c;
  if (low_new) {
    t->lo[nw] = t->lo[b];
    t->hi[nw] = t->lo[b] = c;
  } else {
    t->lo[nw] = c;
    t->hi[nw] = t->hi[b];
    t->hi[b] = c;
  }
  t->brev[nw] = t->brev[b];
  for (size_t s = t->lo[nw]; s < t->hi[nw]; s++) t->blk[t->item[s]] = nw;
  /* the low slots come first in the tour when b reads forwards */
  size_t at = t->bpos[b] + (low_new ^ t->brev[b] ? 0 : 1);
  memmove(&t->border[at + 1], &t->border[at], (t->nblk - 1 - at) * sizeof *t->border);
  t->border[at] = nw;
  for (size_t p = at; p < t->nblk; p++) t->bpos[t->border[p]] = p;
  t->work += (t->hi[nw] - t->lo[nw]) + (t->nblk - at);
}

/* Makes the item the first (cut_before) or the last (cut_after) of its
** block in tour order. */
static void cut_before(two_opt *t, size_t item)
{
  size_t b = t->blk[item], c = t->slot[item] + (t->brev[b] ? 1 : 0);
  if (c > t->lo[b] && c < t->hi[b]) split(t, b, c);
}

static void cut_after(two_opt *t, size_t item)
{
  size_t b = t->blk[item], c = t->slot[item] + (t->brev[b] ? 0 : 1);
  if (c > t->lo[b] && c < t->hi[b]) split(t, b, c);
}

/* Reverses the stretch of the cycle from item `from` forward to item `to`,
** or the rest of the cycle when that has fewer blocks (the same tour read
** the other way round). */
static void reverse(two_opt *t, size_t from, size_t to)
{
  size_t b = t->blk[from];
  if (b == t->blk[to] && (t->brev[b] ? t->slot[from] >= t->slot[to] : t->slot[from] <= t->slot[to])) {
    /* inside one block: its slots, whichever way it reads */
    size_t i = t->slot[from] < t->slot[to] ? t->slot[from] : t->slot[to];
    size_t j = t->slot[from] ^ t->slot[to] ^ i;
    t->work += j - i + 1;
    for (; i < j; i++, j--) {
      size_t ia = t->item[i], ib = t->item[j];
      t->item[i] = ib;
      t->item[j] = ia;
      t->slot[ib] = i;
      t->slot[ia] = j;
      t->rev[ia] ^= 1;
      t->rev[ib] ^= 1;
    }
    if (i == j) t->rev[t->item[i]] ^= 1;
    return;
  }
  if (t->nblk + 2 > t->max_blk) lay_out(t);
  cut_before(t, from);
  cut_after(t, to);
  size_t nb = t->nblk, i = t->bpos[t->blk[from]], j = t->bpos[t->blk[to]];
  size_t len = (j + nb - i) % nb + 1;
  if (2 * len > nb) {
    size_t ni = j + 1 == nb ? 0 : j + 1;
    j = (i ? i : nb) - 1;
    i = ni;
    len = nb - len;
  }
  for (size_t k = 0; k < (len + 1) / 2; k++) {
    size_t ba = t->border[i], bb = t->border[j];
    t->border[i] = bb;
    t->border[j] = ba;
    t->bpos[bb] = i;
    t->bpos[ba] = j;
    t->brev[ba] ^= 1;
    if (bb != ba) t->brev[bb] ^= 1;
    i = i + 1 == nb ? 0 : i + 1;
    j = j == 0 ? nb - 1 : j - 1;
  }
  t->work += len;
}

static void push(two_opt *t, size_t item)
{
  if (t->queued[item]) return;
  t->queued[item] = 1;
  t->queue[(t->q_head + t->q_len++) % t->m] = item;
}

/* Moves the stretch s1 .. s2 (at most a few items, p before it, nx after)
** to between c and d = succ(c), drawn the other way round if `flip`, by
** three reversals at most: s1 .. c, then c .. nx (which puts the stretch
** reversed between c and d and the items between back as they were), then
** the stretch itself unless it is to be flipped.  Each reversal may read the
** cycle the other way round (reverse()), so each step finds its ends by
** looking at the cycle again.  c is none of p, pred(p), the stretch and nx. */
static void move_stretch(two_opt *t, size_t p, size_t s1, size_t s2, size_t nx, size_t c, int flip)
{
  reverse(t, s1, c);
  if (succ(t, p) == c) reverse(t, c, nx);
  else reverse(t, nx, c);
  if (!flip) {
    if (succ(t, c) == s2) reverse(t, s2, s1);
    else reverse(t, s1, s2);
  }
}

/* An Or-opt move for the stretch of 1 to LW_ORDER_OR_MAX items from a
** forward: taken out (its neighbours p and nx joined) and put between two
** items c and d elsewhere, either way round.  Candidates are the end points
** near the stretch's two ends (entry e1 of its first item, exit x2 of its
** last): an exit near one of them is a c, an entry a d.  As in 2-opt, a new
** leg that is not shorter than what taking the stretch out saves ends the
** search in that list. */
static int or_opt(two_opt *t, size_t a)
{
  const size_t K = LW_ORDER_NEIGHBOURS;
  if (t->m < 2 * LW_ORDER_OR_MAX + 4) return 0;
  size_t p = pred(t, a), s[LW_ORDER_OR_MAX];
  size_t xp = exit_of(t, p), e1 = entry_of(t, a);
  s[0] = a;
  for (size_t len = 1; len <= LW_ORDER_OR_MAX; len++) {
    if (len > 1) s[len - 1] = succ(t, s[len - 2]);
    size_t s2 = s[len - 1], nx = succ(t, s2), x2 = exit_of(t, s2), en = entry_of(t, nx);
    if (nx == p) return 0;
    double removed = leg(t, xp, e1) + leg(t, x2, en) - leg(t, xp, en);
    if (removed <= LW_ORDER_EPS) continue;
    for (int end = 0; end < 2; end++) {
      size_t z = end ? x2 : e1;
      if (z == t->free_pt) continue;
      for (size_t k = 0; k < t->nbn[z]; k++) {
        size_t q = t->nb[z * K + k], item = q / 2;
        double new1 = leg(t, z, q);
        t->work++;
        if (new1 >= removed - LW_ORDER_EPS) break;
        /* q an exit: c = its item, d after it; q an entry: d = its item */
        size_t c = q == exit_of(t, item) ? item : pred(t, item), d = succ(t, c);
        int skip = c == p || c == nx || d == p;
        for (size_t i = 0; i < len; i++) skip |= c == s[i];
        if (skip) continue;
        size_t xc = exit_of(t, c), ed = entry_of(t, d);
        /* forward: c -> s1 ... s2 -> d; flipped: c -> s2 ... s1 -> d */
        double fwd = leg(t, xc, e1) + leg(t, x2, ed), flp = leg(t, xc, x2) + leg(t, e1, ed);
        int flip = flp < fwd;
        double gain = removed + leg(t, xc, ed) - (flip ? flp : fwd);
        if (gain > LW_ORDER_EPS) {
          move_stretch(t, p, a, s2, nx, c, flip);
          push(t, p);
          push(t, nx);
          push(t, c);
          push(t, d);
          push(t, a);
          push(t, s2);
          return 1;
        }
      }
    }
  }
  return 0;
}

/* One improving move around item a, if its candidate lists offer one. */
static int improve(two_opt *t, size_t a)
{
  const size_t K = LW_ORDER_NEIGHBOURS;
  /* Leg a -> b out of a's exit: a new leg exit(a) -> exit(c) for c whose
  ** exit is near, reversing b .. c. */
  size_t x = exit_of(t, a);
  if (x != t->free_pt) {
    size_t b = succ(t, a);
    double old1 = leg(t, x, entry_of(t, b));
    for (size_t k = 0; k < t->nbn[x]; k++) {
      size_t q = t->nb[x * K + k], c = q / 2;
      double new1 = leg(t, x, q);
      t->work++;
      if (new1 >= old1 - LW_ORDER_EPS) break;
      if (q != exit_of(t, c)) continue;
      size_t d = succ(t, c);
      double gain = old1 + leg(t, q, entry_of(t, d)) - new1 - leg(t, entry_of(t, b), entry_of(t, d));
      if (gain > LW_ORDER_EPS) {
        reverse(t, b, c);
        push(t, a);
        push(t, b);
        push(t, c);
        push(t, d);
        return 1;
      }
    }
  }
  /* Leg p -> a into a's entry: a new leg entry(a) -> entry(c) for c whose
  ** entry is near, reversing a .. pred(c). */
  size_t e = entry_of(t, a);
  if (e != t->free_pt) {
    size_t p = pred(t, a);
    double old1 = leg(t, exit_of(t, p), e);
    for (size_t k = 0; k < t->nbn[e]; k++) {
      size_t q = t->nb[e * K + k], c = q / 2;
      double new1 = leg(t, e, q);
      t->work++;
      if (new1 >= old1 - LW_ORDER_EPS) break;
      if (q != entry_of(t, c)) continue;
      size_t qc = pred(t, c);
      double gain = old1 + leg(t, exit_of(t, qc), q) - new1 - leg(t, exit_of(t, p), exit_of(t, qc));
      if (gain > LW_ORDER_EPS) {
        reverse(t, a, qc);
        push(t, a);
        push(t, p);
        push(t, c);
        push(t, qc);
        return 1;
      }
    }
  }
  return or_opt(t, a);
}

static void two_opt_free(two_opt *t)
{
  free(t->px);
  free(t->py);
  free(t->orig);
  free(t->item);
  free(t->slot);
  free(t->rev);
  free(t->blk);
  free(t->lo);
  free(t->hi);
  free(t->brev);
  free(t->border);
  free(t->bpos);
  free(t->scratch);
  free(t->nb);
  free(t->nbn);
  free(t->queue);
  free(t->queued);
}

/* Items are renumbered by their place in the starting tour, home first, and
** laid out in that order: a reversal then rewrites neighbouring entries
** instead of entries scattered over the arrays, each of which was a cache
** miss (issue 14).  Point 2 l + e is end e of the item labelled l, so FREE
** is 0 and home 1.  The candidate lists, found by path index, are carried
** over, so the moves and the result do not depend on the paths' numbering.
** t->px, t->py, t->nb and t->nbn go from path index to label. */
static lw_status relabel(two_opt *t, const size_t *order, const unsigned char *reversed)
{
  const size_t K = LW_ORDER_NEIGHBOURS, n = t->n, m = t->m, npt = 2 * m;
  size_t *lab = malloc(m * sizeof *lab), *nb = malloc(npt * K * sizeof *nb);
  unsigned char *nbn = malloc(npt);
  double *lx = malloc(npt * sizeof *lx), *ly = malloc(npt * sizeof *ly);
  t->orig = malloc(m * sizeof *t->orig);
  if (!lab || !nb || !nbn || !lx || !ly || !t->orig) {
    free(lab);
    free(nb);
    free(nbn);
    free(lx);
    free(ly);
    return LW_ENOMEM;
  }
  t->orig[0] = n;
  for (size_t k = 0; k < n; k++) t->orig[k + 1] = order[k];
  for (size_t l = 0; l < m; l++) lab[t->orig[l]] = l;
  for (size_t l = 0; l < m; l++)
    for (size_t e = 0; e < 2; e++) {
      size_t q = 2 * t->orig[l] + e, to = 2 * l + e;
      lx[to] = t->px[q];
      ly[to] = t->py[q];
      nbn[to] = t->nbn[q];
      for (size_t k = 0; k < t->nbn[q]; k++) {
        size_t r = t->nb[q * K + k];
        nb[to * K + k] = 2 * lab[r / 2] + (r & 1);
      }
    }
  free(lab);
  free(t->nb);
  free(t->nbn);
  free(t->px);
  free(t->py);
  t->nb = nb;
  t->nbn = nbn;
  t->px = lx;
  t->py = ly;
  t->free_pt = 0;
  for (size_t l = 0; l < m; l++) {
    t->item[l] = t->slot[l] = l;
    t->rev[l] = l ? reversed[l - 1] : 0;
  }
  cut_blocks(t);
  return LW_OK;
}

lw_status lw_order_2opt(const lw_order_path *path, size_t n, double hx, double hy,
                        size_t *order, unsigned char *reversed, lw_error *err)
{
  if (n == 1) {
    /* one path: only its direction can change */
    const lw_order_path *p = &path[order[0]];
    double to_start = hypot(p->x0 - hx, p->y0 - hy), to_end = hypot(p->x1 - hx, p->y1 - hy);
    double cur = reversed[0] ? to_end : to_start, other = reversed[0] ? to_start : to_end;
    if (other < cur - LW_ORDER_EPS) reversed[0] ^= 1;
  }
  if (n < 2) return LW_OK;
  const size_t K = LW_ORDER_NEIGHBOURS;
  two_opt t = {.n = n, .m = n + 1, .free_pt = 2 * n};
  /* blocks of about sqrt(m) slots, and a fresh lay-out once splits have
  ** doubled their number: a move then costs O(sqrt m) entries, and so,
  ** spread over the moves between two, does a lay-out */
  t.group = (size_t)ceil(sqrt((double)t.m));
  t.max_blk = 2 * ((t.m + t.group - 1) / t.group) + 2;
  double *px, *py;
  if (!end_points(path, n, 2, &px, &py)) return lw_error_set(err, LW_ENOMEM, "out of memory ordering %zu paths", n);
  px[2 * n] = py[2 * n] = 0.0;  /* FREE: never measured */
  px[2 * n + 1] = hx;
  py[2 * n + 1] = hy;
  t.px = px;
  t.py = py;
  size_t npt = 2 * n + 2;
  t.item = malloc(t.m * sizeof *t.item);
  t.slot = malloc(t.m * sizeof *t.slot);
  t.rev = calloc(t.m, 1);
  t.blk = malloc(t.m * sizeof *t.blk);
  t.scratch = malloc(t.m * sizeof *t.scratch);
  t.lo = malloc(t.max_blk * sizeof *t.lo);
  t.hi = malloc(t.max_blk * sizeof *t.hi);
  t.brev = calloc(t.max_blk, 1);
  t.border = malloc(t.max_blk * sizeof *t.border);
  t.bpos = malloc(t.max_blk * sizeof *t.bpos);
  t.nb = malloc(npt * K * sizeof *t.nb);
  t.nbn = calloc(npt, 1);
  t.queue = malloc(t.m * sizeof *t.queue);
  t.queued = calloc(t.m, 1);
  size_t *ids = malloc(npt * sizeof *ids);
  double *d2s = malloc(K * sizeof *d2s);
  point_grid g;
  int ok = t.item && t.slot && t.rev && t.blk && t.scratch && t.lo && t.hi && t.brev && t.border && t.bpos && t.nb &&
           t.nbn && t.queue && t.queued && ids && d2s;
  if (ok) {
    /* every point but FREE */
    for (size_t id = 0; id < 2 * n; id++) ids[id] = id;
    ids[2 * n] = 2 * n + 1;
    ok = grid_build(&g, px, py, ids, 2 * n + 1, npt);
  }
  if (!ok) {
    two_opt_free(&t);
    free(ids);
    free(d2s);
    return lw_error_set(err, LW_ENOMEM, "out of memory ordering %zu paths", n);
  }
  for (size_t k = 0; k < 2 * n + 1; k++)
    t.nbn[ids[k]] = (unsigned char)grid_knearest(&g, ids[k], px[ids[k]], py[ids[k]], K, &t.nb[ids[k] * K], d2s);
  grid_free(&g);
  free(ids);
  free(d2s);
  if (relabel(&t, order, reversed) != LW_OK) {
    two_opt_free(&t);
    return lw_error_set(err, LW_ENOMEM, "out of memory ordering %zu paths", n);
  }
  t.budget = (unsigned long long)LW_ORDER_WORK * t.m;
  /* A reversal flips every path inside it, which can open a move for a
  ** path whose own legs did not change and which is not queued; so when
  ** the queue runs dry every item is looked at once more, in tour order,
  ** until a whole round finds nothing. */
  for (int moved = 1; moved && t.work < t.budget;) {
    moved = 0;
    for (size_t k = 0, a = 0; k < t.m; k++, a = succ(&t, a)) push(&t, a);
    while (t.q_len && t.work < t.budget) {
      size_t a = t.queue[t.q_head];
      t.q_head = (t.q_head + 1) % t.m;
      t.q_len--;
      t.queued[a] = 0;
      while (t.work < t.budget && improve(&t, a)) moved = 1;
    }
  }

  /* read the cycle from home in the direction in which home is forward */
  int back = orient(&t, 0);
  for (size_t k = 0, item = 0; k < n; k++) {
    item = back ? pred(&t, item) : succ(&t, item);
    order[k] = t.orig[item];
    reversed[k] = (unsigned char)(orient(&t, item) ^ back);
  }
  two_opt_free(&t);
  return LW_OK;
}
