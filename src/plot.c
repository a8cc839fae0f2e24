/* plot.c -- pens and plotting order of the paths (plot.h). */
#include "linewise/plot.h"

#include <stdlib.h>
#include <string.h>

#include "linewise/order.h"

void lw_plot_free(lw_plot *pl)
{
  if (!pl) return;
  free(pl->spline);
  free(pl->reversed);
  free(pl);
}

void lw_plot_mean_along(const lw_splines *sp, const lw_quad *q, double (*f)(const void *ctx, double x, double y),
                        const void *ctx, double *key)
{
  for (size_t i = 0; i < sp->n_splines; i++) {
    double sum = 0.0, len = 0.0;
    size_t n = lw_splines_segments(sp, i);
    for (size_t m = 0; m < n; m++) {
      lw_samples s;
      const lw_node *a = &sp->node[sp->first[i] + m];
      lw_segment_sample(q, a, a + 1, &s);
      for (int k = 0; k < s.n; k++) {
        sum += f(ctx, s.x[k], s.y[k]) * s.dl[k];
        len += s.dl[k];
      }
    }
    key[i] = len > 0 ? sum / len : 0.0;
  }
}

/* qsort has no context argument: the keys travel in the array. */
typedef struct {
  double key;
  size_t spline;
} ranked;

static int by_key(const void *pa, const void *pb)
{
  const ranked *a = pa, *b = pb;
  if (a->key != b->key) return a->key < b->key ? -1 : 1;
  return a->spline < b->spline ? -1 : a->spline > b->spline;
}

/* End points of the paths of one pen, in index order. */
static void ends(const lw_splines *sp, const size_t *spline, size_t n, lw_order_path *out)
{
  for (size_t k = 0; k < n; k++) {
    const lw_node *first = &sp->node[sp->first[spline[k]]];
    const lw_node *last = &sp->node[sp->first[spline[k] + 1] - 1];
    out[k] = (lw_order_path){first->px, first->py, last->px, last->py};
  }
}

lw_status lw_plot_order_paths(const lw_order_path *path, size_t n, lw_plot_order order, double hx, double hy,
                              size_t *tour, unsigned char *rev, double *before, double *after, lw_error *err)
{
  for (size_t k = 0; k < n; k++) tour[k] = k;
  memset(rev, 0, n);
  *before = *after = lw_order_travel(path, n, NULL, NULL, hx, hy);
  if (order == LW_PLOT_ORDER_NONE) return LW_OK;
  lw_status s = lw_order_greedy(path, n, hx, hy, tour, rev, err);
  if (s) return s;
  *after = lw_order_travel(path, n, tour, rev, hx, hy);
  if (*after > *before) {
    for (size_t k = 0; k < n; k++) tour[k] = k;
    memset(rev, 0, n);
    *after = *before;
  }
  if (order == LW_PLOT_ORDER_2OPT) {
    if ((s = lw_order_2opt(path, n, hx, hy, tour, rev, err))) return s;
    *after = lw_order_travel(path, n, tour, rev, hx, hy);
  }
  return LW_OK;
}

/* Orders the n paths spline[] / rev[] of one pen in place; adds the travel
** before and after to the plot's sums. */
static lw_status order_pen(lw_plot *pl, const lw_splines *sp, size_t *spline, unsigned char *rev, size_t n,
                           lw_plot_order order, double hx, double hy, lw_error *err)
{
  lw_order_path *path = malloc((n ? n : 1) * sizeof *path);
  size_t *tour = malloc((n ? n : 1) * sizeof *tour);
  unsigned char *trev = calloc(n ? n : 1, 1);
  lw_status s = LW_OK;
  if (!path || !tour || !trev) {
    s = lw_error_set(err, LW_ENOMEM, "out of memory ordering %zu paths", n);
    goto done;
  }
  ends(sp, spline, n, path);
  double before, after;
  if ((s = lw_plot_order_paths(path, n, order, hx, hy, tour, trev, &before, &after, err))) goto done;
  /* tour[] indexes this pen's list: map it back to splines */
  for (size_t k = 0; k < n; k++) tour[k] = spline[tour[k]];
  memcpy(spline, tour, n * sizeof *spline);
  memcpy(rev, trev, n);
  pl->travel_before += before;
  pl->travel_after += after;
done:
  free(path);
  free(tour);
  free(trev);
  return s;
}

/* lw_plot_new with keys, or lw_plot_new_pens with given pens (pens not NULL). */
static lw_plot *plot_new(const lw_splines *sp, int n_pens, const double *key, const int *pens, lw_plot_order order,
                         double hx, double hy, lw_error *err)
{
  if (n_pens < 1 || n_pens > LW_PLOT_PENS_MAX) {
    lw_error_set(err, LW_EINPUT, "%d pens: expected 1 to %d", n_pens, LW_PLOT_PENS_MAX);
    return NULL;
  }
  if (!lw_splines_finite(sp)) {
    lw_error_set(err, LW_EINPUT, "a spline to plot is not finite");
    return NULL;
  }
  lw_plot *pl = calloc(1, sizeof *pl);
  ranked *rk = NULL;
  if (!pl) goto nomem;
  pl->n_pens = n_pens;
  for (size_t i = 0; i < sp->n_splines; i++) pl->n += !lw_splines_is_point(sp, i);
  size_t n = pl->n;
  pl->spline = malloc((n ? n : 1) * sizeof *pl->spline);
  pl->reversed = calloc(n ? n : 1, 1);
  rk = malloc((n ? n : 1) * sizeof *rk);
  if (!pl->spline || !pl->reversed || !rk) goto nomem;
  size_t m = 0;
  for (size_t i = 0; i < sp->n_splines; i++)
    if (!lw_splines_is_point(sp, i)) rk[m++] = (ranked){key ? key[i] : 0.0, i};

  /* pen of each path, then a stable bucket pass keeps index order per pen */
  int *pen = malloc((n ? n : 1) * sizeof *pen);
  if (!pen) goto nomem;
  if (pens) {
    for (size_t r = 0; r < n; r++) {
      pen[r] = pens[rk[r].spline];
      if (pen[r] < 0 || pen[r] >= n_pens) {
        lw_error_set(err, LW_EINPUT, "spline %zu has pen %d: expected 0 to %d", rk[r].spline, pen[r], n_pens - 1);
        free(pen);
        free(rk);
        lw_plot_free(pl);
        return NULL;
      }
    }
  } else if (key && n_pens > 1) {
    qsort(rk, n, sizeof *rk, by_key);
    for (size_t r = 0; r < n; r++) pen[r] = (int)(r * (size_t)n_pens / n);
    /* back to index order with the pens attached */
    for (size_t r = 0; r < n; r++) rk[r].key = pen[r];
    qsort(rk, n, sizeof *rk, by_key);  /* ties (same pen) by index */
    for (size_t r = 0; r < n; r++) pen[r] = (int)rk[r].key;
  } else {
    for (size_t r = 0; r < n; r++) pen[r] = (int)(rk[r].spline % (size_t)n_pens);
  }
  memset(pl->pen_first, 0, sizeof pl->pen_first);
  for (size_t r = 0; r < n; r++) pl->pen_first[pen[r] + 1]++;
  for (int k = 0; k < n_pens; k++) pl->pen_first[k + 1] += pl->pen_first[k];
  size_t fill[LW_PLOT_PENS_MAX];
  memcpy(fill, pl->pen_first, sizeof fill);
  for (size_t r = 0; r < n; r++) pl->spline[fill[pen[r]]++] = rk[r].spline;
  free(pen);
  free(rk);
  rk = NULL;

  for (int k = 0; k < n_pens; k++) {
    size_t a = pl->pen_first[k], b = pl->pen_first[k + 1];
    if (order_pen(pl, sp, pl->spline + a, pl->reversed + a, b - a, order, hx, hy, err)) {
      lw_plot_free(pl);
      return NULL;
    }
  }
  return pl;
nomem:
  free(rk);
  lw_plot_free(pl);
  lw_error_set(err, LW_ENOMEM, "out of memory planning %zu splines", sp->n_splines);
  return NULL;
}

lw_plot *lw_plot_new(const lw_splines *sp, int n_pens, const double *key, lw_plot_order order, double hx, double hy,
                     lw_error *err)
{
  return plot_new(sp, n_pens, key, NULL, order, hx, hy, err);
}

lw_plot *lw_plot_new_pens(const lw_splines *sp, int n_pens, const int *pen, lw_plot_order order, double hx,
                          double hy, lw_error *err)
{
  return plot_new(sp, n_pens, NULL, pen, order, hx, hy, err);
}
