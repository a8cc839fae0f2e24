/* spacing.c -- the close share of a drawing (spacing.h). */
#include "linewise/spacing.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "linewise/grid.h"

/* Point and speed of the cubic Bezier with control points b at t. */
static void bezier_at(const double b[8], double t, double *x, double *y, double *speed)
{
  double u = 1.0 - t, c0 = u * u * u, c1 = 3 * u * u * t, c2 = 3 * u * t * t, c3 = t * t * t;
  *x = c0 * b[0] + c1 * b[2] + c2 * b[4] + c3 * b[6];
  *y = c0 * b[1] + c1 * b[3] + c2 * b[5] + c3 * b[7];
  double d0 = 3 * u * u, d1 = 6 * u * t, d2 = 3 * t * t;
  double dx = d0 * (b[2] - b[0]) + d1 * (b[4] - b[2]) + d2 * (b[6] - b[4]);
  double dy = d0 * (b[3] - b[1]) + d1 * (b[5] - b[3]) + d2 * (b[7] - b[5]);
  *speed = hypot(dx, dy);
}

/* Pieces of a segment with control points b: by its control polygon's
** length, which is at least the curve's. */
static size_t pieces(const double b[8], double h)
{
  double l = hypot(b[2] - b[0], b[3] - b[1]) + hypot(b[4] - b[2], b[5] - b[3]) + hypot(b[6] - b[4], b[7] - b[5]);
  double k = ceil(l / h);
  if (!(k >= 1.0)) return 1; /* NaN too */
  return k > LW_SPACING_POINTS_MAX ? LW_SPACING_POINTS_MAX : (size_t)k;
}

lw_status lw_close_share(const double *b, const size_t *owner, const size_t *group, size_t n_seg, double d,
                         double *share, lw_error *err)
{
  *share = 0.0;
  const double h = 0.5 * d;
  size_t n = 0;
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  for (size_t g = 0; g < n_seg; g++) {
    const double *z = b + 8 * g;
    n += pieces(z, h);
    for (int k = 0; k < 8; k += 2) {
      x0 = fmin(x0, z[k]);
      x1 = fmax(x1, z[k]);
      y0 = fmin(y0, z[k + 1]);
      y1 = fmax(y1, z[k + 1]);
    }
  }
  if (n == 0) return LW_OK;
  if (n >= UINT32_MAX)
    return lw_error_set(err, LW_EINPUT, "close share: %zu points exceed the grid's limit of 2^32", n);
  size_t *who = malloc(n * sizeof *who), *grp = group ? malloc(n * sizeof *grp) : NULL;
  float *w = malloc(n * sizeof *w);
  lw_cellgrid *grid = who && w && (grp || !group) ? lw_cellgrid_new(x0, y0, x1 - x0, y1 - y0, d, n, err) : NULL;
  lw_status st = grid ? LW_OK : LW_ENOMEM;
  size_t i = 0;
  for (size_t g = 0; g < n_seg && st == LW_OK; g++) {
    const double *z = b + 8 * g;
    size_t k = pieces(z, h);
    for (size_t q = 0; q < k && st == LW_OK; q++, i++) {
      double x, y, speed;
      bezier_at(z, ((double)q + 0.5) / (double)k, &x, &y, &speed);
      who[i] = owner[g];
      if (grp) grp[i] = group[g];
      w[i] = (float)(speed / (double)k);
      st = lw_cellgrid_insert(grid, (uint32_t)i, x, y, w[i]);
    }
  }
  double close = 0.0, all = 0.0;
  const double d2 = d * d;
  for (size_t ci = 0; st == LW_OK && ci < lw_cellgrid_cells(grid); ci++) {
    const lw_cell *c = &grid->cell[ci];
    const int cx = (int)(ci % (size_t)grid->nx), cy = (int)(ci / (size_t)grid->nx);
    for (uint32_t e = 0; e < c->n; e++) {
      const uint32_t me = lw_cell_idx(c)[e];
      const double px = c->x[e], py = lw_cell_y(c)[e];
      int found = 0;
      for (int y = cy > 0 ? cy - 1 : 0; !found && y <= cy + 1 && y < grid->ny; y++)
        for (int x = cx > 0 ? cx - 1 : 0; !found && x <= cx + 1 && x < grid->nx; x++) {
          const lw_cell *o = &grid->cell[(size_t)y * (size_t)grid->nx + (size_t)x];
          if (!o->n) continue; /* an empty cell may have no block */
          const uint32_t *idx = lw_cell_idx(o);
          for (uint32_t f = 0; f < o->n; f++) {
            double dx = o->x[f] - px, dy = lw_cell_y(o)[f] - py;
            if (who[idx[f]] != who[me] && (!grp || grp[idx[f]] == grp[me]) && dx * dx + dy * dy < d2) {
              found = 1;
              break;
            }
          }
        }
      all += w[me];
      if (found) close += w[me];
    }
  }
  if (st == LW_OK) *share = all > 0.0 ? close / all : 0.0;
  else lw_error_set(err, LW_ENOMEM, "out of memory for the close share of %zu points", n);
  lw_cellgrid_free(grid);
  free(who);
  free(grp);
  free(w);
  return st;
}

lw_status lw_close_share_splines(const lw_splines *sp, double d, double *share, lw_error *err)
{
  size_t n = sp->n_segments ? sp->n_segments : 1;
  double *b = malloc(8 * n * sizeof *b);
  size_t *owner = malloc(n * sizeof *owner);
  lw_status s = LW_ENOMEM;
  if (b && owner) {
    for (size_t g = 0; g < sp->n_segments; g++) {
      const lw_node *a = &sp->node[lw_segment_node(sp, g)];
      lw_segment_bezier(a, a + 1, b + 8 * g);
      owner[g] = sp->seg_spline[g];
    }
    s = lw_close_share(b, owner, NULL, sp->n_segments, d, share, err);
  } else {
    lw_error_set(err, LW_ENOMEM, "out of memory for the close share of %zu segments", sp->n_segments);
  }
  free(b);
  free(owner);
  return s;
}
