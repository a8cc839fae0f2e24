/*
** walk.h -- the pair term's walk over the cell grid: the far sum of a set of
** samples (probes) against their neighbours, and the list of their near
** neighbours.
**
** For a probe P (position, weight dl_P) of the spline whose samples are
** [lo, hi), the walk visits the cells of the 3 x 3 block around P's cell
** that come closer to P than the cutoff, in a fixed order, and within each
** cell its samples in increasing index order (grid.h).  For each neighbour
** j >= from of another spline, with r = |P - j| and dm = max(dl_P, dl_j):
**
**   near   r^2 < (ctx->near_scale * dm)^2 and r < rc: (P, j) is appended
**          to the near list with j's position and weight, and adds nothing
**          to the far sum;
**   far    otherwise, if r < rc and both weights are non-zero:
**          scale_P dl_P dl_j (1/r - 1/rc) joins the far sum (1/rc =
**          ctx->inv_cutoff, 0 without a cutoff).
**
** The samples the filter excludes (the probes' own spline or two, indices
** below `from`) are never visited: a cell keeps its indices sorted, so they are
** one or two runs of its entries, found by binary search.  Excluding a
** spline's own samples costs O(log n) per cell, so a long spline coiled
** into a few cells costs no more than a short one (it used to be visited
** sample by sample, quadratic in its length).
**
** The near scale is meant to be capped so that near pairs lie within the
** cutoff; the walk skips the cells beyond it and reports none beyond it.
**
** How it runs: the probes of one call are taken LW_PAIR_CHUNK at a time (a
** move's are one chunk), and the cells of the union of their 3 x 3 blocks
** in the grid's order, each cell once for every probe whose block holds it
** (a mask of probes): its runs of entries the filter keeps, four entries at
** a time, the weights once, the distances and tests per probe, in SSE2 (or
** AVX2) lanes.  Where a probe has a far pair among the four, the kernel
** runs on all four lanes and the others are masked to +0.  A little under
** half of the (probe, group) pairs need it (44 % in the benchmark scenes)
** against about a quarter of the lanes being far pairs, but the lanes stay
** in registers: no copying out, no second pass.  Each probe keeps its own
** two accumulators of two lanes, which take its terms in the visiting
** order: the cells in the grid's order, each run of a cell's entries in
** groups of four from the run's start.  So a probe's sum is a function of
** its position and the samples it may pair only: the same on every thread,
** after a resume that rebuilds the grid, whatever other probes share the
** walk and wherever the samples the filter leaves out lie.
*/
#ifndef LINEWISE_WALK_H
#define LINEWISE_WALK_H

#include <stddef.h>
#include <stdint.h>

#include "linewise/error.h"
#include "linewise/grid.h"
#include "linewise/pair.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_PAIR_CHUNK 32 /* probes walked together (at most the bits of a mask) */

/* One near pair: the neighbour as the grid holds it, and the probe. */
typedef struct {
  double x, y;     /* the neighbour's position, mm */
  float dl;        /* its weight, mm */
  uint32_t idx;    /* its sample index */
  uint32_t probe;  /* the probe's index in the walk's probes */
} lw_pair_near;

/* Near pairs, appended in walk order.  The caller owns the list (a
** workspace or a proposal), empties it (n = 0) when it likes, and frees it;
** the walk grows it (amortised, doubling). */
typedef struct {
  lw_pair_near *pair;
  size_t n, cap;
} lw_pair_nearlist;

void lw_pair_nearlist_free(lw_pair_nearlist *l);

/* A sample a walk is for. */
typedef struct {
  double x, y;      /* mm */
  float dl;         /* w_q |r'_q|, mm */
  double scale;     /* its far pairs count scale times: +1, or -1 for the old
                    ** samples of a move, whose pairs the move takes away */
} lw_pair_probe;

/* What every probe of a walk shares. */
typedef struct {
  uint32_t lo, hi;  /* the probes' spline's sample indices [lo, hi): never paired */
  uint32_t from;    /* pairs only with samples of index >= from (0: all) */
  uint32_t lo2, hi2; /* a second spline's, hi2 >= lo2 >= hi (a join's two; lo2 = hi2: none) */
  int plane;        /* the grid's plane the probes pair in (grid.h; 0 with one plane) */
} lw_pair_filter;

/* Sets *far to the far sum of the n probes P (no coefficient C), the sum of
** the probes' own far sums in their order, and appends their near pairs to
** `near` (may be NULL when ctx->near_scale is 0).  each (may be NULL):
** receives the probes' own far sums, each[k] that of P[k].  A probe's own
** sum, and the order of its near pairs in `near`, are functions of the
** probe and of the samples it may pair alone, whatever other probes share
** the walk and wherever the filtered samples lie: the cells are taken in a
** fixed order and each cell's runs of samples the filter keeps in groups
** of four from the run's start (a model can keep a segment's sums and
** reuse them, bit for bit).  visited (may be NULL): adds the number of
** (probe, sample) pairs the walk looked at, the measure of its work.
** LW_ENOMEM if the near list could not grow (*far is then 0 and the list
** holds what was found so far). */
lw_status lw_pair_walk(const lw_cellgrid *g, const lw_pair_ctx *ctx, const lw_pair_probe *P, size_t n,
                       const lw_pair_filter *f, double *far, double *each, lw_pair_nearlist *near,
                       uint64_t *visited);

#ifdef __cplusplus
}
#endif

#endif
