/* grid.c -- the uniform cell grid with sorted structure-of-arrays cells (grid.h). */
#include "linewise/grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Bytes of one entry across the four arrays of a 2-D cell's block; a 3-D
** block adds z. */
#define ENTRY_BYTES (2 * sizeof(double) + sizeof(uint32_t) + sizeof(float))
#define ENTRY_BYTES_OF(g) (ENTRY_BYTES + ((g)->dim == 3 ? sizeof(double) : 0))
/* The walk reads entries in groups of four, past the last one (grid.h). */
#define BLOCK_PAD (3 * sizeof(float))

/* A grid of dim 2 or 3 over lo + [0, size] (size[2], lo[2] unused in 2-D). */
static lw_cellgrid *grid_new(int dim, const double lo[3], const double size[3], double cell,
                             size_t n_samples, size_t room, lw_error *err)
{
  lw_cellgrid *g = calloc(1, sizeof *g);
  if (!g) goto nomem;
  g->dim = dim;
  g->x0 = lo[0];
  g->y0 = lo[1];
  g->z0 = dim == 3 ? lo[2] : 0.0;
  double w = size[0], h = size[1], d = dim == 3 ? size[2] : 0.0;
  double side = cell > 0 ? cell : fmax(fmax(w, h), d) + 1.0;
  /* No more cells than samples (times a small factor): a tiny cutoff on a huge
  ** page would otherwise allocate mostly empty cells. */
  double max_cells = 4.0 * (double)(room ? room : n_samples) + 16.0;
  while ((ceil(w / side) + 1) * (ceil(h / side) + 1) * (dim == 3 ? ceil(d / side) + 1 : 1) > max_cells)
    side *= 1.5;
  g->inv_h = 1.0 / side;
  g->nx = (int)ceil(w / side);
  g->ny = (int)ceil(h / side);
  g->nz = (int)ceil(d / side);
  if (g->nx < 1) g->nx = 1;
  if (g->ny < 1) g->ny = 1;
  if (g->nz < 1) g->nz = 1;
  g->cell = calloc(lw_cellgrid_cells(g), sizeof *g->cell);
  g->home = malloc((n_samples ? n_samples : 1) * sizeof *g->home);
  if (!g->cell || !g->home) goto nomem;
  g->n_samples = n_samples;
  g->home_cap = n_samples;
  return g;
nomem:
  lw_cellgrid_free(g);
  lw_error_set(err, LW_ENOMEM, "out of memory for the %s grid (%zu entries)", dim == 3 ? "particle" : "pair",
               n_samples);
  return NULL;
}

lw_cellgrid *lw_cellgrid_new(double x0, double y0, double w, double h, double cell,
                             size_t n_samples, lw_error *err)
{
  return grid_new(2, (const double[3]){x0, y0, 0.0}, (const double[3]){w, h, 0.0}, cell, n_samples, 0, err);
}

lw_cellgrid *lw_cellgrid_new_room(double x0, double y0, double w, double h, double cell,
                                  size_t n_samples, size_t room, lw_error *err)
{
  return grid_new(2, (const double[3]){x0, y0, 0.0}, (const double[3]){w, h, 0.0}, cell, n_samples, room, err);
}

lw_cellgrid *lw_cellgrid_new3(const double lo[3], const double size[3], double cell, size_t n_samples,
                              lw_error *err)
{
  return grid_new(3, lo, size, cell, n_samples, 0, err);
}

lw_cellgrid *lw_cellgrid_new3_room(const double lo[3], const double size[3], double cell, size_t n_samples,
                                   size_t room, lw_error *err)
{
  return grid_new(3, lo, size, cell, n_samples, room, err);
}

void lw_cellgrid_free(lw_cellgrid *g)
{
  if (!g) return;
  if (g->cell)
    for (size_t c = 0; c < lw_cellgrid_cells(g); c++) free(g->cell[c].x);
  free(g->cell);
  free(g->home);
  free(g);
}

/* Position of i in the sorted cell (or where it would go). */
static uint32_t lower_bound(const lw_cell *c, uint32_t i)
{
  const uint32_t *idx = lw_cell_idx(c);
  uint32_t lo = 0, hi = c->n;
  while (lo < hi) {
    uint32_t mid = (lo + hi) / 2;
    if (idx[mid] < i) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

static uint32_t cell_of(const lw_cellgrid *g, double x, double y, double z)
{
  int cx, cy, cz;
  lw_cellgrid_locate3(g, x, y, z, &cx, &cy, &cz);
  return ((uint32_t)cz * (uint32_t)g->ny + (uint32_t)cy) * (uint32_t)g->nx + (uint32_t)cx;
}

/* Gives c a block of cap >= c->n entries.  The arrays' offsets depend on the
** capacity, so the entries are copied into a new block rather than
** realloc'ed. */
static lw_status cell_resize(const lw_cellgrid *g, lw_cell *c, uint32_t cap)
{
  /* zeroed, so that what the walk reads past the entries is defined */
  double *blk = calloc(1, (size_t)cap * ENTRY_BYTES_OF(g) + BLOCK_PAD);
  if (!blk) return LW_ENOMEM;
  lw_cell to = {blk, c->n, cap};
  if (c->n) {
    memcpy(to.x, c->x, c->n * sizeof(double));
    memcpy(lw_cell_y(&to), lw_cell_y(c), c->n * sizeof(double));
    memcpy(lw_cell_idx(&to), lw_cell_idx(c), c->n * sizeof(uint32_t));
    memcpy(lw_cell_dl(&to), lw_cell_dl(c), c->n * sizeof(float));
    if (g->dim == 3) memcpy(lw_cell_z(&to), lw_cell_z(c), c->n * sizeof(double));
  }
  free(c->x);
  *c = to;
  return LW_OK;
}

/* Spare room after a fit: a few moves into a cell before it must grow. */
static uint32_t fitted(uint32_t n)
{
  return n + n / 8 + 2;
}

/* Room for one more entry.  A quarter more (at least 4) keeps the amortised
** cost O(1) with little spare room. */
static lw_status cell_reserve(const lw_cellgrid *g, lw_cell *c)
{
  if (c->n < c->cap) return LW_OK;
  return cell_resize(g, c, c->cap + c->cap / 8 + 2);
}

/* Shifts entries [k, n) of every array of c by `by` (+1 or -1) entries. */
static void cell_shift(const lw_cellgrid *g, lw_cell *c, uint32_t k, int by)
{
  size_t m = c->n - k;
  double *y = lw_cell_y(c);
  uint32_t *idx = lw_cell_idx(c);
  float *dl = lw_cell_dl(c);
  memmove(c->x + k + by, c->x + k, m * sizeof *c->x);
  memmove(y + k + by, y + k, m * sizeof *y);
  memmove(idx + k + by, idx + k, m * sizeof *idx);
  memmove(dl + k + by, dl + k, m * sizeof *dl);
  if (g->dim == 3) {
    double *z = lw_cell_z(c);
    memmove(z + k + by, z + k, m * sizeof *z);
  }
}

static void cell_set(const lw_cellgrid *g, lw_cell *c, uint32_t k, uint32_t i, double x, double y, double z,
                     float dl)
{
  c->x[k] = x;
  lw_cell_y(c)[k] = y;
  lw_cell_idx(c)[k] = i;
  lw_cell_dl(c)[k] = dl;
  if (g->dim == 3) lw_cell_z(c)[k] = z;
}

/* Cells of one plane of a 2-D grid. */
static uint32_t plane_cells(const lw_cellgrid *g) { return (uint32_t)g->nx * (uint32_t)g->ny; }

/* The cell of (x, y, z), in 2-D in the given plane (z is ignored there). */
static uint32_t cell_in(const lw_cellgrid *g, int plane, double x, double y, double z)
{
  return g->dim == 2 ? (uint32_t)plane * plane_cells(g) + cell_of(g, x, y, 0.0) : cell_of(g, x, y, z);
}

/* Insert and move for both dimensions. */
static lw_status insert(lw_cellgrid *g, int plane, uint32_t i, double x, double y, double z, float dl)
{
  uint32_t to = cell_in(g, plane, x, y, z);
  lw_cell *c = &g->cell[to];
  if (cell_reserve(g, c) != LW_OK) return LW_ENOMEM;
  uint32_t k = lower_bound(c, i);
  cell_shift(g, c, k, 1);
  c->n++;
  cell_set(g, c, k, i, x, y, z, dl);
  g->home[i] = to;
  return LW_OK;
}

static lw_status move(lw_cellgrid *g, uint32_t i, double x, double y, double z, float dl)
{
  /* in 2-D a sample stays in its plane */
  const int plane = g->dim == 2 && g->nz > 1 ? (int)(g->home[i] / plane_cells(g)) : 0;
  uint32_t from = g->home[i], to = cell_in(g, plane, x, y, z);
  lw_cell *c = &g->cell[from];
  uint32_t k = lower_bound(c, i);
  if (from == to) {
    cell_set(g, c, k, i, x, y, z, dl);
    return LW_OK;
  }
  if (cell_reserve(g, &g->cell[to]) != LW_OK) return LW_ENOMEM;
  cell_shift(g, c, k + 1, -1);
  c->n--;
  /* A cell that emptied gives its spare room back, so capacity follows the
  ** occupancy instead of the largest it ever had; the gap between this and
  ** the growth threshold keeps a cell from resizing back and forth.  A
  ** failed shrink keeps the larger block, which is as good. */
  if (c->cap - c->n > c->n / 4 + 4) (void)cell_resize(g, c, fitted(c->n));
  return insert(g, plane, i, x, y, z, dl); /* cannot fail: room reserved */
}

lw_status lw_cellgrid_insert(lw_cellgrid *g, uint32_t i, double x, double y, float dl)
{
  return insert(g, 0, i, x, y, 0.0, dl);
}

lw_status lw_cellgrid_insert_in(lw_cellgrid *g, int plane, uint32_t i, double x, double y, float dl)
{
  return insert(g, plane, i, x, y, 0.0, dl);
}

lw_status lw_cellgrid_planes(lw_cellgrid *g, int planes)
{
  if (planes <= 1 || g->dim != 2 || g->nz == planes) return LW_OK;
  size_t n = (size_t)plane_cells(g) * (size_t)planes;
  for (size_t c = 0; c < lw_cellgrid_cells(g); c++) free(g->cell[c].x);
  lw_cell *cell = realloc(g->cell, n * sizeof *cell);
  if (!cell) {
    /* the old cells, emptied, are still a grid of one plane */
    memset(g->cell, 0, lw_cellgrid_cells(g) * sizeof *g->cell);
    return LW_ENOMEM;
  }
  memset(cell, 0, n * sizeof *cell);
  g->cell = cell;
  g->nz = planes;
  return LW_OK;
}

lw_status lw_cellgrid_move(lw_cellgrid *g, uint32_t i, double x, double y, float dl)
{
  return move(g, i, x, y, 0.0, dl);
}

lw_status lw_cellgrid_insert3(lw_cellgrid *g, uint32_t i, double x, double y, double z)
{
  return insert(g, 0, i, x, y, z, 0.0f);
}

lw_status lw_cellgrid_move3(lw_cellgrid *g, uint32_t i, double x, double y, double z)
{
  return move(g, i, x, y, z, 0.0f);
}

void lw_cellgrid_get(const lw_cellgrid *g, uint32_t i, double *x, double *y, float *dl)
{
  const lw_cell *c = &g->cell[g->home[i]];
  uint32_t k = lower_bound(c, i);
  *x = c->x[k];
  *y = lw_cell_y(c)[k];
  *dl = lw_cell_dl(c)[k];
}

void lw_cellgrid_get_run(const lw_cellgrid *g, uint32_t i0, uint32_t n, double *x, double *y, float *dl)
{
  const lw_cell *c = NULL;
  uint32_t k = 0;
  for (uint32_t q = 0; q < n; q++) {
    const uint32_t i = i0 + q;
    const lw_cell *ci = &g->cell[g->home[i]];
    /* a segment's samples are consecutive indices, mostly in one cell: the
    ** entry after the last one found, where it is i, saves the search */
    if (!(ci == c && k + 1 < c->n && lw_cell_idx(c)[k + 1] == i)) k = lower_bound(ci, i);
    else k++;
    c = ci;
    x[q] = c->x[k];
    y[q] = lw_cell_y(c)[k];
    dl[q] = lw_cell_dl(c)[k];
  }
}

void lw_cellgrid_fit(lw_cellgrid *g)
{
  for (size_t c = 0; c < lw_cellgrid_cells(g); c++) {
    lw_cell *cell = &g->cell[c];
    /* a failed shrink keeps the larger block, which is as good */
    if (cell->cap > fitted(cell->n)) (void)cell_resize(g, cell, fitted(cell->n));
  }
}

size_t lw_cellgrid_bytes(const lw_cellgrid *g)
{
  size_t b = sizeof *g + g->n_samples * sizeof *g->home;
  for (size_t c = 0; c < lw_cellgrid_cells(g); c++)
    b += sizeof *g->cell + (g->cell[c].cap ? g->cell[c].cap * ENTRY_BYTES_OF(g) + BLOCK_PAD : 0);
  return b;
}

void lw_cellgrid_clear(lw_cellgrid *g)
{
  for (size_t c = 0; c < lw_cellgrid_cells(g); c++) g->cell[c].n = 0;
}

lw_status lw_cellgrid_reserve(lw_cellgrid *g, size_t n)
{
  if (n <= g->home_cap) return LW_OK;
  size_t c = g->home_cap + g->home_cap / 2 + 64;
  if (c < n) c = n;
  uint32_t *h = realloc(g->home, c * sizeof *h);
  if (!h) return LW_ENOMEM;
  g->home = h;
  g->home_cap = c;
  return LW_OK;
}

void lw_cellgrid_extend(lw_cellgrid *g, size_t n)
{
  g->n_samples += n;
}

void lw_cellgrid_truncate(lw_cellgrid *g, size_t n)
{
  g->n_samples = n;
}

void lw_cellgrid_renumber(lw_cellgrid *g, const uint32_t *to, uint32_t per, size_t n)
{
  for (size_t ci = 0; ci < lw_cellgrid_cells(g); ci++) {
    lw_cell *c = &g->cell[ci];
    uint32_t *idx = c->n ? lw_cell_idx(c) : NULL;
    for (uint32_t k = 0; k < c->n; k++) idx[k] = to[idx[k] / per] * per + idx[k] % per;
  }
  /* home moves down with its samples: to[k] <= k, so forward is safe */
  const size_t groups = g->n_samples / per;
  for (size_t k = 0; k < groups; k++)
    if (to[k] != UINT32_MAX && to[k] != k) memmove(g->home + (size_t)to[k] * per, g->home + k * per, per * sizeof *g->home);
  g->n_samples = n;
}

void lw_cellgrid_remove(lw_cellgrid *g, uint32_t i)
{
  lw_cell *c = &g->cell[g->home[i]];
  uint32_t k = lower_bound(c, i);
  cell_shift(g, c, k + 1, -1);
  c->n--;
  /* as in move: an emptied cell gives its room back (a failed shrink keeps it) */
  if (c->cap - c->n > c->n / 4 + 4) (void)cell_resize(g, c, fitted(c->n));
}
