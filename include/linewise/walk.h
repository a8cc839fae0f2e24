/*
** walk.h -- the pair term's walk over the cell grid: the far sum of one
** sample against its neighbours, and the list of its near neighbours.
**
** For a sample P (position, weight dl_P, its spline's index range) the walk
** visits the 3 x 3 cells around P in a fixed order and, within each cell,
** the samples in increasing index order (grid.h), so its results depend on
** the positions alone.  For each neighbour j of another spline, with
** r = |P - j| and dm = max(dl_P, dl_j):
**
**   near   r^2 < (ctx->near_scale * dm)^2: j is appended to the near list
**          (whatever `from` says, so the caller sees every near pair), and
**          j adds nothing to the far sum;
**   far    otherwise, if r < rc, j >= from and both weights are non-zero:
**          the product rule dl_P dl_j (1/r - 1/rc) joins the far sum
**          (1/rc = ctx->inv_cutoff, 0 without a cutoff).
**
** How it runs: a scalar, branch-free pass over a cell's four arrays keeps
** the far candidates (r^2 and dl_j) in a small buffer; a vector pass over
** the buffer evaluates dl_j (1/r - 1/rc), two lanes (SSE2) at a time with two
** accumulators.  Only about a third of the candidates lie within the
** cutoff, so the square roots and divisions run on those alone.  The buffer
** is flushed at fixed points of the visiting order, so the summation order
** is a function of the positions only: the same on every thread, and the
** same after a resume that rebuilds the grid.
*/
#ifndef LINEWISE_WALK_H
#define LINEWISE_WALK_H

#include <stddef.h>
#include <stdint.h>

#include "linewise/error.h"
#include "linewise/grid.h"
#include "linewise/pair.h"

/* Indices of near neighbours, appended in walk order.  The caller owns it
** (a workspace or a proposal), empties it (n = 0) when it likes, and frees
** it; the walk grows it (amortised, doubling). */
typedef struct {
  uint32_t *idx;
  size_t n, cap;
} lw_pair_nearlist;

void lw_pair_nearlist_free(lw_pair_nearlist *l);

/* The sample a walk is for. */
typedef struct {
  double x, y;      /* mm */
  float dl;         /* w_q |r'_q|, mm */
  uint32_t lo, hi;  /* its spline's sample indices [lo, hi): never paired */
  uint32_t from;    /* far pairs only with samples of index >= from (0: all) */
} lw_pair_probe;

/* Sets *far to the far sum of P (no coefficient C) and appends P's near
** neighbours to `near` (may be NULL when ctx->near_scale is 0).  LW_ENOMEM
** if the near list could not grow (*far is then 0 and the list holds what
** was found so far). */
lw_status lw_pair_walk(const lw_cellgrid *g, const lw_pair_ctx *ctx, const lw_pair_probe *P, double *far,
                       lw_pair_nearlist *near);

#endif
