/*
** plot.h -- what a pen plotter draws: which pen draws each spline, and in
** which order and direction each pen's paths are drawn.
**
** Paths are the splines that are not a single point (lw_splines_is_point).
**
** Pens.  With one pen every path is pen 1's.  With N > 1 pens and a key per
** spline (e.g. the mean of the potential along it: dark tone = low
** potential), the paths are ranked by key, lowest first (ties by spline
** index), and cut into N runs of equal size: the path of rank r gets pen
** floor(r N / M) + 1 of M paths, so pen 1 draws the darkest.  Without keys
** spline i gets pen (i mod N) + 1 (round robin).
**
** Order.  Each pen is plotted as its own tour starting at the home point
** (the page origin, top-left), since a pen change normally happens there
** (order.h defines tours and pen-up travel):
**   none    index order, every path forward;
**   greedy  the greedy nearest-neighbour tour, or index order if that is
**           already shorter;
**   2opt    the better of those two, improved by 2-opt.
** So the travel after is never longer than before.  travel_before is the
** sum over pens of the index-order tours, travel_after that of the chosen
** tours.
*/
#ifndef LINEWISE_PLOT_H
#define LINEWISE_PLOT_H

#include <stddef.h>

#include "linewise/error.h"
#include "linewise/order.h"
#include "linewise/spline.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_PLOT_PENS_MAX 16

/* Values of [output] order, in the order of its choices. */
typedef enum { LW_PLOT_ORDER_NONE, LW_PLOT_ORDER_GREEDY, LW_PLOT_ORDER_2OPT } lw_plot_order;

typedef struct {
  size_t n;                  /* paths drawn */
  size_t *spline;            /* n: spline index of each path, in plotting order */
  unsigned char *reversed;   /* n: 1 = drawn from its last node to its first */
  int n_pens;
  size_t pen_first[LW_PLOT_PENS_MAX + 1]; /* pen k (0-based) draws paths
                                             pen_first[k] .. pen_first[k+1]-1 */
  double travel_before;      /* pen-up travel in index order, mm */
  double travel_after;       /* pen-up travel in plotting order, mm */
} lw_plot;

/* The plot of sp with n_pens pens (1 .. LW_PLOT_PENS_MAX), keys per spline
** (finite; NULL: round robin), ordered as `order` from home (hx, hy).  NULL
** and err set on bad arguments or non-finite splines (LW_EINPUT) or lack of
** memory. */
lw_plot *lw_plot_new(const lw_splines *sp, int n_pens, const double *key, lw_plot_order order,
                     double hx, double hy, lw_error *err);
/* The same with the pen of each spline given: pen[i] in 0 .. n_pens - 1
** (LW_EINPUT otherwise), as a scene's layers assign them (layers.h). */
lw_plot *lw_plot_new_pens(const lw_splines *sp, int n_pens, const int *pen, lw_plot_order order, double hx,
                          double hy, lw_error *err);
void lw_plot_free(lw_plot *pl);

/* The ordering above for n paths known by their end points: tour[k] the
** k-th path drawn, rev[k] its direction; *before the travel in index order,
** *after as ordered (never longer).  LW_ENOMEM (err set). */
lw_status lw_plot_order_paths(const lw_order_path *path, size_t n, lw_plot_order order, double hx, double hy,
                              size_t *tour, unsigned char *rev, double *before, double *after, lw_error *err);

/* key[i] = the length-weighted mean of f along spline i (quadrature q); 0
** for a spline of zero length.  f is called as f(ctx, x, y) with mm. */
void lw_plot_mean_along(const lw_splines *sp, const lw_quad *q, double (*f)(const void *ctx, double x, double y),
                        const void *ctx, double *key);

#ifdef __cplusplus
}
#endif

#endif
