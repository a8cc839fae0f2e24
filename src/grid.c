/* grid.c -- the uniform cell grid with sorted cells (grid.h). */
#include "linewise/grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

lw_cellgrid *lw_cellgrid_new(double x0, double y0, double w, double h, double cell,
                             size_t n_samples, lw_error *err)
{
  lw_cellgrid *g = calloc(1, sizeof *g);
  if (!g) goto nomem;
  g->x0 = x0;
  g->y0 = y0;
  double side = cell > 0 ? cell : fmax(w, h) + 1.0;
  /* No more cells than samples (times a small factor): a tiny cutoff on a huge
  ** page would otherwise allocate mostly empty cells. */
  double max_cells = 4.0 * (double)n_samples + 16.0;
  while ((ceil(w / side) + 1) * (ceil(h / side) + 1) > max_cells) side *= 1.5;
  g->inv_h = 1.0 / side;
  g->nx = (int)ceil(w / side);
  g->ny = (int)ceil(h / side);
  if (g->nx < 1) g->nx = 1;
  if (g->ny < 1) g->ny = 1;
  g->cell = calloc((size_t)g->nx * (size_t)g->ny, sizeof *g->cell);
  if (!g->cell) goto nomem;
  g->n_samples = n_samples;
  return g;
nomem:
  lw_cellgrid_free(g);
  lw_error_set(err, LW_ENOMEM, "out of memory for the pair grid (%zu samples)", n_samples);
  return NULL;
}

void lw_cellgrid_free(lw_cellgrid *g)
{
  if (!g) return;
  if (g->cell)
    for (size_t c = 0; c < (size_t)g->nx * (size_t)g->ny; c++) free(g->cell[c].idx);
  free(g->cell);
  free(g);
}

/* Position of i in the sorted cell (or where it would go). */
static uint32_t lower_bound(const lw_cell *c, uint32_t i)
{
  uint32_t lo = 0, hi = c->n;
  while (lo < hi) {
    uint32_t mid = (lo + hi) / 2;
    if (c->idx[mid] < i) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

static uint32_t cell_of(const lw_cellgrid *g, double x, double y)
{
  int cx, cy;
  lw_cellgrid_locate(g, x, y, &cx, &cy);
  return (uint32_t)cy * (uint32_t)g->nx + (uint32_t)cx;
}

static lw_status cell_reserve(lw_cell *c)
{
  if (c->n < c->cap) return LW_OK;
  uint32_t cap = c->cap ? 2 * c->cap : 8;
  uint32_t *nidx = realloc(c->idx, cap * sizeof *nidx);
  if (!nidx) return LW_ENOMEM;
  c->idx = nidx;
  c->cap = cap;
  return LW_OK;
}

static void cell_add(lw_cell *c, uint32_t i)
{
  uint32_t k = lower_bound(c, i);
  memmove(c->idx + k + 1, c->idx + k, (c->n - k) * sizeof *c->idx);
  c->idx[k] = i;
  c->n++;
}

static void cell_remove(lw_cell *c, uint32_t i)
{
  uint32_t k = lower_bound(c, i);
  if (k == c->n || c->idx[k] != i) return; /* not there: nothing to remove */
  memmove(c->idx + k, c->idx + k + 1, (c->n - k - 1) * sizeof *c->idx);
  c->n--;
}

lw_status lw_cellgrid_insert(lw_cellgrid *g, uint32_t i, double x, double y)
{
  lw_cell *c = &g->cell[cell_of(g, x, y)];
  if (cell_reserve(c) != LW_OK) return LW_ENOMEM;
  cell_add(c, i);
  return LW_OK;
}

lw_status lw_cellgrid_move(lw_cellgrid *g, uint32_t i, double ox, double oy, double x, double y)
{
  uint32_t from = cell_of(g, ox, oy), to = cell_of(g, x, y);
  if (from == to) return LW_OK;
  if (cell_reserve(&g->cell[to]) != LW_OK) return LW_ENOMEM;
  cell_remove(&g->cell[from], i);
  cell_add(&g->cell[to], i);
  return LW_OK;
}

void lw_cellgrid_clear(lw_cellgrid *g)
{
  for (size_t c = 0; c < (size_t)g->nx * (size_t)g->ny; c++) g->cell[c].n = 0;
}
