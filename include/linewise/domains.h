/*
** domains.h -- one replica's sweep on every core: the checkerboard domain
** decomposition of Anderson et al. 2013 (HOOMD-blue's HPMC) for the
** Metropolis chain (mc.h) of a system whose row can split (system.h).
**
** The page is cut by an nx x ny lattice of domains of side lx x ly, each
** wider than twice the reach of a move; every sweep shifts the lattice by
** (ox, oy) uniform in [0, lx) x [0, ly), so it covers the page with
** (nx + 1) x (ny + 1) cells, those on the edge reaching to infinity.  A
** group of sites (a spline) belongs to the cell holding its whole box; a
** group on a cell boundary is not moved this sweep.  The cells fall into
** four sub-lattices by the parity of their indices; the sweep takes them in
** turn (0 1 2 3, or 3 2 1 0 when the sweep goes backward) and in each phase
** runs the active cells in parallel, each over its sites in storage order
** (backward: in reverse), rejecting a move whose box would leave its cell.
** Two cells of a phase are a cell apart, so what one move reads or writes
** (its box grown by the reach) never meets what another one changes.
**
** Streams belong to cells, not threads: each sweep draws the shift, the
** direction and one seed per cell from the chain's own stream, so the
** result is the same for any thread count, and a checkpoint between sweeps
** needs nothing more than the chain's stream.  Each cell commits into its
** own scratch (commit_part); after a phase the scratches are merged into
** the running totals, and their statistics into the chain's, in cell
** order; while the chain tunes, its steps move once a phase (each cell
** takes them at the start of a phase).  Why this samples exp(-E/T):
** docs/NUMERICS.md, "Domains".
**
** The cells run only the kinds of the row's n_domain_moves (system.h), in
** the proportions of their weights; kinds that draw their own object
** anywhere (births and deaths) run after the phases, serially (mc.h;
** docs/NUMERICS.md, "Trans-dimensional moves with domains").
*/
#ifndef LINEWISE_DOMAINS_H
#define LINEWISE_DOMAINS_H

#include <stddef.h>
#include <stdint.h>

#include "linewise/mc.h"
#include "linewise/params.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Below this many sites a phase is not worth waking threads for. */
#define LW_DOMAINS_MIN_PARALLEL 256

typedef struct lw_domains {
  int nx, ny;           /* domains per side; the shifted lattice has (nx + 1) x (ny + 1) cells */
  int n;                /* cells */
  double page[4];       /* x0, y0, x1, y1 */
  double lx, ly;        /* domain sides, > 2 reach */
  double reach;         /* of a move, from the row */
  int threads;          /* for one replica's cells */
  lw_chain **cell;      /* n chains: own stream and scratch, reseeded every sweep */
  uint32_t *cell_of;    /* per site: its cell this sweep, or UINT32_MAX */
  size_t *site;         /* sites by cell, storage order within each */
  size_t *start;        /* n + 1 offsets into site */
  size_t cap;           /* sites cell_of and site hold */
  int *active;          /* scratch: the cells of a phase */
  unsigned long *seed;  /* scratch: each cell's seed this sweep */
  size_t min_parallel;  /* a phase of fewer sites runs on one thread (no effect on results) */
  /* Profile for the benchmark (tools/bench-domains.c), off while cell_cpu
  ** is NULL: each cell's thread CPU seconds in the last sweep (0 if it had
  ** no sites), and the last sweep's own seconds outside the cells. */
  double *cell_cpu;
  double serial_cpu;
  unsigned long frozen; /* site visits skipped for a group on a cell boundary, since the start */
  unsigned long visits; /* sites swept, since the start */
} lw_domains;

/* Reads [anneal] domains and, unless it is off (or auto finds fewer than 2
** domains a side), attaches domains to chain c (c->domains), for a run of
** `replicas` replicas sharing the threads.  LW_EINPUT naming the key's file
** and line when the value is not off, auto or a count from 1 to 64, when
** the domains would not be wider than twice the reach, or when the system
** cannot split (no row functions, or a term that is not local). */
lw_status lw_domains_attach(lw_chain *c, const lw_params *p, int replicas, lw_error *err);

void lw_domains_free(lw_domains *d);

/* One sweep of chain c (mc.h's lw_chain_sweep calls it). */
lw_status lw_domains_sweep(lw_domains *d, lw_chain *c);

#ifdef __cplusplus
}
#endif

#endif
