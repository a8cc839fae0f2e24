/*
** order.h -- the order in which a pen plotter draws a set of paths, chosen
** to shorten the pen-up travel between them.
**
** A path is known here by its two end points only: it is drawn from its start
** to its end, or reversed, from its end to its start.  A tour is a sequence
** of (path, reversed) starting at a fixed home point (the plotter's origin).
**
** Pen-up travel of a tour = |home - entry_1| + sum_k |exit_k - entry_{k+1}|
** (Euclidean, mm), where entry/exit are the start/end of a forward path and
** the end/start of a reversed one.  The pen does not return home after the
** last path: a plotter parks wherever the user likes, and a closing leg
** would only reward tours that end near the origin.
**
** Two optimisers, both deterministic (no clock, no random numbers; ties
** between equal distances go to the lower path index, start before end):
**   greedy  nearest neighbour from home: the next path is the one with the
**           end point nearest to the pen, drawn from that end.  Candidate
**           points come from a uniform cell grid (about two end points per
**           cell) searched ring by ring, so a tour costs O(n) expected on
**           spread-out paths.
**   2-opt   (with Or-opt) improves a tour by reversing a contiguous stretch of it (order
**           reversed, and every path in it reversed too), which swaps two
**           pen-up legs for two others: legs exit_a -> entry_b and
**           exit_c -> entry_d become exit_a -> exit_c and entry_b -> entry_d.
**           Candidates come from the K nearest end points of each end point
**           (LW_ORDER_NEIGHBOURS); a queue of paths whose neighbourhood
**           changed decides what is looked at next.  The tour is kept as a
**           cycle through a virtual "home" item whose incoming leg is free,
**           so either side of a cut may be reversed (the one that spans
**           fewer blocks, below, is).  Or-opt moves join in: a stretch of
**           1 to LW_ORDER_OR_MAX paths is taken out and put between two
**           others, either way round, when a candidate of one of its ends
**           makes that shorter (three reversals at most).
**           The cycle is a two-level list: blocks of about sqrt(n) paths,
**           each read forwards or backwards, so a reversal rewrites
**           O(sqrt n) entries where an array rewrote up to n / 2.
**           The work is capped at LW_ORDER_WORK per path (candidate checks
**           plus entries a reversal or a re-layout of the list rewrites),
**           which bounds the time on any input while giving the same answer
**           on every machine.
** A move is made only when it shortens the tour by more than
** LW_ORDER_EPS mm, so the travel never grows.
*/
#ifndef LINEWISE_ORDER_H
#define LINEWISE_ORDER_H

#include <stddef.h>

#include "linewise/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_ORDER_NEIGHBOURS 10 /* candidate end points per end point in 2-opt */
#define LW_ORDER_WORK 10000    /* 2-opt work cap per path (checks + rewritten entries) */
#define LW_ORDER_OR_MAX 3      /* longest stretch an Or-opt move carries, paths */
#define LW_ORDER_EPS 1e-9      /* mm: smallest gain that counts as an improvement */

typedef struct {
  double x0, y0;  /* start point, mm */
  double x1, y1;  /* end point, mm */
} lw_order_path;

/* The pen-up travel of a tour (mm): order[k] is the k-th path drawn (NULL:
** 0, 1, ..., n-1) and reversed[k] says whether it is drawn backwards (NULL:
** none is); home = (hx, hy). */
double lw_order_travel(const lw_order_path *path, size_t n, const size_t *order,
                       const unsigned char *reversed, double hx, double hy);

/* Greedy nearest-neighbour tour from home into order[n] and reversed[n].
** LW_ENOMEM (err set) if its grid cannot be allocated. */
lw_status lw_order_greedy(const lw_order_path *path, size_t n, double hx, double hy,
                          size_t *order, unsigned char *reversed, lw_error *err);

/* Improves the tour in order[] / reversed[] by 2-opt and Or-opt moves (see
** above), never lengthening it; the result is again a permutation with its
** reversal flags.  LW_ENOMEM (err set, tour unchanged) if the work space
** cannot be allocated. */
lw_status lw_order_2opt(const lw_order_path *path, size_t n, double hx, double hy,
                        size_t *order, unsigned char *reversed, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
