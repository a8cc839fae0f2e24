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
  g->where = malloc((n_samples ? n_samples : 1) * sizeof *g->where);
  if (!g->cell || !g->where) goto nomem;
  for (size_t i = 0; i < n_samples; i++) g->where[i] = UINT32_MAX;
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
  free(g->where);
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

lw_status lw_cellgrid_place(lw_cellgrid *g, uint32_t i, double x, double y)
{
  int cx, cy;
  lw_cellgrid_locate(g, x, y, &cx, &cy);
  uint32_t target = (uint32_t)cy * (uint32_t)g->nx + (uint32_t)cx;
  uint32_t old = g->where[i];
  if (old == target) return LW_OK;
  lw_cell *c = &g->cell[target];
  if (c->n == c->cap) {
    uint32_t cap = c->cap ? 2 * c->cap : 8;
    uint32_t *nidx = realloc(c->idx, cap * sizeof *nidx);
    if (!nidx) return LW_ENOMEM;
    c->idx = nidx;
    c->cap = cap;
  }
  if (old != UINT32_MAX) {
    lw_cell *o = &g->cell[old];
    uint32_t k = lower_bound(o, i);
    memmove(o->idx + k, o->idx + k + 1, (o->n - k - 1) * sizeof *o->idx);
    o->n--;
  }
  uint32_t k = lower_bound(c, i);
  memmove(c->idx + k + 1, c->idx + k, (c->n - k) * sizeof *c->idx);
  c->idx[k] = i;
  c->n++;
  g->where[i] = target;
  return LW_OK;
}
