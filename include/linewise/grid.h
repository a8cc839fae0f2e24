/*
** grid.h -- a uniform cell grid over the pair term's samples.
**
** Cells are squares of side >= the pair cutoff, so every sample within the
** cutoff of a point lies in the 3 x 3 block of cells around it.  Points beyond
** the covered area fall into the nearest edge cell; clamping is monotone and
** 1-Lipschitz per axis, so the 3 x 3 rule still holds for them.
**
** The grid is where the samples' positions and weights live: each cell holds
** what the far kernel reads of its samples as structure-of-arrays, x[], y[]
** (double, mm), dl[] (float, mm) and idx[] (the sample index), in one block
** per cell, so the walk over neighbours streams four flat arrays instead of
** gathering scattered samples.  24 bytes a sample, plus 4 for the cell of
** each sample (`home`, which finds a sample's data without its position).
** Cells grow by a quarter (at least 4 entries) and are fitted to their
** contents after a refill, so spare room stays small: memory is the
** constraint here (docs/PERFORMANCE.md, bytes per segment).
**
** The same grid works in 3-D (the particle system, particles.h): cubes of
** side >= the interaction range, so neighbours lie in the 3 x 3 x 3 block,
** and a z[] array of doubles after dl[] in each cell's block (dl is then
** unused).  z comes last so that a 2-D grid's block, the accessors below
** and the cell index y * nx + x that walk.c uses stay exactly as they
** were: a 2-D grid is a 3-D one with nz = 1 and no z array.
**
** Each cell keeps its samples in increasing index order.  Sums over
** neighbours therefore run in an order that depends on the current positions
** only, never on the history of moves: a run resumed from a checkpoint (which
** rebuilds the grid) adds the same numbers in the same order as one that never
** stopped, so results stay bit-identical.  Moving a sample costs a removal and
** a sorted insertion in cells of a few dozen entries.
*/
#ifndef LINEWISE_GRID_H
#define LINEWISE_GRID_H

#include <stddef.h>
#include <stdint.h>

#include "linewise/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* One block of cap entries: x[cap], y[cap], then idx[cap], dl[cap], in 3-D
** z[cap], and 3 floats of padding, so that reading any array in groups of
** four from entry 0 stays within the block (walk.c masks the entries past
** n). */
typedef struct {
  double *x;       /* the block; NULL while cap = 0 */
  uint32_t n, cap; /* entries used, allocated */
} lw_cell;

static inline double *lw_cell_y(const lw_cell *c) { return c->x + c->cap; }
static inline uint32_t *lw_cell_idx(const lw_cell *c) { return (uint32_t *)(c->x + 2 * (size_t)c->cap); }
static inline float *lw_cell_dl(const lw_cell *c) { return (float *)(lw_cell_idx(c) + c->cap); }
/* 3-D grids only: idx and dl take one double's room per entry together. */
static inline double *lw_cell_z(const lw_cell *c) { return c->x + 3 * (size_t)c->cap; }

typedef struct {
  double x0, y0;     /* lower corner of the covered area, mm */
  double inv_h;      /* 1 / cell side */
  int nx, ny;        /* cells per axis */
  lw_cell *cell;     /* nx * ny * nz */
  uint32_t *home;    /* n_samples: the cell of each inserted sample */
  size_t n_samples;  /* indices run from 0 to n_samples - 1 */
  double z0;         /* 3-D: lower corner in z; 0 in 2-D */
  int nz;            /* cells along z: 1 in 2-D; cell (x, y, z) is (z ny + y) nx + x */
  int dim;           /* 2 or 3 */
  size_t home_cap;   /* room in home (lw_cellgrid_reserve grows it) */
} lw_cellgrid;

/* A grid covering [x0, x0 + w] x [y0, y0 + h] with cells of side >= cell
** (cell <= 0: a single cell) for sample indices 0 .. n_samples-1.  The cell
** count per axis is capped so that memory stays proportional to samples. */
lw_cellgrid *lw_cellgrid_new(double x0, double y0, double w, double h, double cell,
                             size_t n_samples, lw_error *err);
void lw_cellgrid_free(lw_cellgrid *g);

/* The same with cells sized as if for `room` samples, however many it
** holds: a grid whose sample count changes (trans-dimensional moves, births
** and deaths) keeps the cells of a fixed room, so that its geometry, and
** with it the order of every sum over cells, depends on the scene alone and
** a resumed run adds in the same order as one that never stopped (sized for
** the larger of the two, a start above the room had other cells than its
** resume).  room 0: as lw_cellgrid_new. */
lw_cellgrid *lw_cellgrid_new_room(double x0, double y0, double w, double h, double cell,
                                  size_t n_samples, size_t room, lw_error *err);

/* Counts n more sample indices at the end, free for lw_cellgrid_insert
** (after lw_cellgrid_reserve for them). */
void lw_cellgrid_extend(lw_cellgrid *g, size_t n);

/* Renumbers the samples in groups of `per` (a segment's pair samples):
** group k becomes group to[k] for the groups in the grid, to increasing
** over them and to[k] <= k (a compaction: cells stay sorted, one pass over
** every cell); n_samples becomes n.  to[k] = UINT32_MAX for the groups
** with no samples in the grid. */
void lw_cellgrid_renumber(lw_cellgrid *g, const uint32_t *to, uint32_t per, size_t n);

/* Counts only the indices below n, which must all be out of the grid (a
** removal from the end). */
void lw_cellgrid_truncate(lw_cellgrid *g, size_t n);

/* Takes sample i (in the grid) out of it; its index stays counted. */
void lw_cellgrid_remove(lw_cellgrid *g, uint32_t i);

/* Room in home for n samples, so that an extension up to n cannot fail. */
lw_status lw_cellgrid_reserve(lw_cellgrid *g, size_t n);

/* The cell holding (x, y) after clamping. */
static inline void lw_cellgrid_locate(const lw_cellgrid *g, double x, double y, int *cx, int *cy)
{
  double fx = (x - g->x0) * g->inv_h, fy = (y - g->y0) * g->inv_h;
  /* comparisons written so that NaN lands in cell 0 instead of overflowing */
  int ix = fx >= 1.0 ? (fx < (double)g->nx ? (int)fx : g->nx - 1) : 0;
  int iy = fy >= 1.0 ? (fy < (double)g->ny ? (int)fy : g->ny - 1) : 0;
  *cx = ix;
  *cy = iy;
}

/* Inserts sample i (not in the grid) at (x, y) with weight dl.  LW_ENOMEM if
** its cell cannot grow (the grid is unchanged then).  Inserting in
** increasing index order appends. */
lw_status lw_cellgrid_insert(lw_cellgrid *g, uint32_t i, double x, double y, float dl);

/* ---- planes ---------------------------------------------------------------
** A 2-D grid may hold several planes of the same cells (nz of them): a
** sample is inserted into one and stays there when it moves, and a walk
** over one plane (lw_cellgrid_plane) never meets another's samples.  Each
** layer of lines (layers.h) is a plane when lines keep apart only from
** their own pen's.  Cell c of plane p is cell[p nx ny + c]. */

/* Gives a 2-D grid `planes` planes (emptying it).  LW_ENOMEM leaves it an
** empty grid of one plane. */
lw_status lw_cellgrid_planes(lw_cellgrid *g, int planes);

/* Inserts sample i into plane `plane`, as lw_cellgrid_insert does into 0. */
lw_status lw_cellgrid_insert_in(lw_cellgrid *g, int plane, uint32_t i, double x, double y, float dl);

/* Plane p of a 2-D grid as a grid of one plane, sharing its cells: what a
** walk over that plane reads (the view is valid while g is unchanged). */
static inline const lw_cellgrid *lw_cellgrid_plane(const lw_cellgrid *g, int p, lw_cellgrid *view)
{
  if (p == 0) return g;
  *view = *g;
  view->cell = g->cell + (size_t)p * (size_t)g->nx * (size_t)g->ny;
  view->nz = 1;
  return view;
}

/* Moves sample i (in the grid) to (x, y) with weight dl, within its plane.
** LW_ENOMEM as for insert. */
lw_status lw_cellgrid_move(lw_cellgrid *g, uint32_t i, double x, double y, float dl);

/* Position and weight of sample i (in the grid): a binary search in its cell. */
void lw_cellgrid_get(const lw_cellgrid *g, uint32_t i, double *x, double *y, float *dl);

/* Samples i0 to i0 + n - 1, as lw_cellgrid_get gives each: one search for a
** run that shares a cell. */
void lw_cellgrid_get_run(const lw_cellgrid *g, uint32_t i0, uint32_t n, double *x, double *y, float *dl);

/* Shrinks every cell to its entries plus a little spare room: after a
** refill, which grows cells one entry at a time. */
void lw_cellgrid_fit(lw_cellgrid *g);

/* Bytes the grid holds: its cells, their blocks (padding included) and the
** home of every sample. */
size_t lw_cellgrid_bytes(const lw_cellgrid *g);

/* Empties every cell, keeping their capacity. */
void lw_cellgrid_clear(lw_cellgrid *g);

/* Cells of the grid: nx ny nz. */
static inline size_t lw_cellgrid_cells(const lw_cellgrid *g)
{
  return (size_t)g->nx * (size_t)g->ny * (size_t)g->nz;
}

/* ---- 3-D grids ------------------------------------------------------------
** The same cells over the box lo + [0, size] with cubes of side >= cell
** (the same cap on the cell count); entries hold x, y, z and idx. */
lw_cellgrid *lw_cellgrid_new3(const double lo[3], const double size[3], double cell, size_t n_samples,
                              lw_error *err);

/* The same with cells sized for room samples, as lw_cellgrid_new_room. */
lw_cellgrid *lw_cellgrid_new3_room(const double lo[3], const double size[3], double cell, size_t n_samples,
                                   size_t room, lw_error *err);

/* The cell holding (x, y, z) after clamping, per axis as in 2-D. */
static inline void lw_cellgrid_locate3(const lw_cellgrid *g, double x, double y, double z, int *cx, int *cy,
                                       int *cz)
{
  lw_cellgrid_locate(g, x, y, cx, cy);
  double fz = (z - g->z0) * g->inv_h;
  *cz = fz >= 1.0 ? (fz < (double)g->nz ? (int)fz : g->nz - 1) : 0;
}

/* Squared gaps along one axis between p, in cell c of the axis starting at
** a with cells of side h, and the cells c - 1, c, c + 1: gap[0], 0, gap[2].
** Only the sides facing p count, and those are true bounds even for edge
** cells, which hold the points clamped from beyond the grid on their outer
** sides.  (The walks of the splines and of the particles share it, and the
** margin below, so that neither skips a cell the other would visit.) */
static inline void lw_cellgrid_axis_gaps(double a, double h, int c, double p, double gap[3])
{
  double below = p - (a + c * h), above = a + (c + 1) * h - p;
  gap[0] = below * below;
  gap[1] = 0.0;
  gap[2] = above * above;
}

/* Cells are skipped when their gap exceeds the cutoff by this factor: a
** point sits in its cell up to the rounding of (x - x0) / h. */
#define LW_CELLGRID_GAP_MARGIN (1.0 + 1e-9)

/* Insert and move as in 2-D, for a 3-D grid. */
lw_status lw_cellgrid_insert3(lw_cellgrid *g, uint32_t i, double x, double y, double z);
lw_status lw_cellgrid_move3(lw_cellgrid *g, uint32_t i, double x, double y, double z);

#ifdef __cplusplus
}
#endif

#endif
