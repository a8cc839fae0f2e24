/*
** grid.h -- a uniform cell grid over the pair term's samples.
**
** Cells are squares of side >= the pair cutoff, so every sample within the
** cutoff of a point lies in the 3 x 3 block of cells around it.  Points beyond
** the covered area fall into the nearest edge cell; clamping is monotone and
** 1-Lipschitz per axis, so the 3 x 3 rule still holds for them.
**
** Each cell keeps the indices of its samples in increasing order.  Sums over
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

typedef struct {
  uint32_t *idx;   /* sample indices, increasing */
  uint32_t n, cap;
} lw_cell;

typedef struct {
  double x0, y0;     /* lower corner of the covered area, mm */
  double inv_h;      /* 1 / cell side */
  int nx, ny;        /* cells per axis */
  lw_cell *cell;     /* nx * ny */
  size_t n_samples;  /* indices run from 0 to n_samples - 1 */
} lw_cellgrid;

/* A grid covering [x0, x0 + w] x [y0, y0 + h] with cells of side >= cell
** (cell <= 0: a single cell) for sample indices 0 .. n_samples-1.  The cell
** count per axis is capped so that memory stays proportional to samples. */
lw_cellgrid *lw_cellgrid_new(double x0, double y0, double w, double h, double cell,
                             size_t n_samples, lw_error *err);
void lw_cellgrid_free(lw_cellgrid *g);

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

/* Inserts sample i at (x, y).  LW_ENOMEM if its cell cannot grow (the grid
** is unchanged then).  Inserting in increasing index order appends. */
lw_status lw_cellgrid_insert(lw_cellgrid *g, uint32_t i, double x, double y);

/* Moves sample i from (ox, oy), where it was inserted, to (x, y).  The grid
** keeps no per-sample cell (4 bytes a sample): the caller knows the old
** position.  LW_ENOMEM as for insert. */
lw_status lw_cellgrid_move(lw_cellgrid *g, uint32_t i, double ox, double oy, double x, double y);

/* Empties every cell, keeping their capacity. */
void lw_cellgrid_clear(lw_cellgrid *g);

#endif
