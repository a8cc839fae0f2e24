/*
** hilbert.c -- numbering along the Hilbert curve (hilbert.h).
*/
#include "linewise/hilbert.h"

#include <math.h>
#include <stdlib.h>

uint64_t lw_hilbert_index(uint32_t x, uint32_t y, int order)
{
  uint64_t d = 0;
  for (uint32_t s = 1u << (order - 1); s > 0; s >>= 1) {
    uint32_t rx = (x & s) != 0, ry = (y & s) != 0;
    /* the quadrant's rank along the curve: (0,0) (0,1) (1,1) (1,0) */
    d += (uint64_t)s * s * ((3u * rx) ^ ry);
    /* turn the sub-square into the curve's base orientation: the lower
    ** quadrants are transposed, the lower right one mirrored too; only the
    ** bits below s matter from here on */
    if (!ry) {
      if (rx) {
        x ^= s - 1;
        y ^= s - 1;
      }
      uint32_t t = x;
      x = y;
      y = t;
    }
  }
  return d;
}

typedef struct {
  uint64_t key;
  size_t i;
} keyed;

static int by_key(const void *a, const void *b)
{
  const keyed *p = a, *q = b;
  if (p->key != q->key) return p->key < q->key ? -1 : 1;
  return p->i < q->i ? -1 : p->i > q->i;
}

static uint32_t cell(double v, double v0, double extent)
{
  const double side = (double)(1u << LW_HILBERT_ORDER);
  double c = extent > 0 ? (v - v0) / extent * side : 0.0;
  /* NaN lands on 0 too: a key need not be meaningful, only deterministic */
  if (!(c > 0.0)) return 0;
  return c >= side - 1.0 ? (1u << LW_HILBERT_ORDER) - 1 : (uint32_t)c;
}

int lw_hilbert_order(const lw_splines *sp, double x0, double y0, double w, double h, size_t *order,
                     lw_error *err)
{
  size_t n = sp->n_splines;
  keyed *k = malloc((n ? n : 1) * sizeof *k);
  if (!k) {
    lw_error_set(err, LW_ENOMEM, "out of memory renumbering %zu splines", n);
    return -1;
  }
  for (size_t i = 0; i < n; i++) {
    double cx = 0.0, cy = 0.0;
    size_t a = sp->first[i], b = sp->first[i + 1];
    for (size_t j = a; j < b; j++) {
      cx += sp->node[j].px;
      cy += sp->node[j].py;
    }
    cx /= (double)(b - a);
    cy /= (double)(b - a);
    k[i] = (keyed){lw_hilbert_index(cell(cx, x0, w), cell(cy, y0, h), LW_HILBERT_ORDER), i};
  }
  qsort(k, n, sizeof *k, by_key);
  int moved = 0;
  for (size_t i = 0; i < n; i++) {
    order[i] = k[i].i;
    moved |= k[i].i != i;
  }
  free(k);
  return moved;
}
