/*
** hilbert.h -- numbering along the Hilbert curve, for locality in memory.
**
** A Metropolis sweep visits nodes in storage order (mc.h); when splines that
** are near on the page are also near in the arrays, consecutive proposals
** touch the same grid cells and cache lines, and the cost of a proposal no
** longer grows with the scene (issue 14).  The Hilbert curve keeps every
** run of consecutive cells compact (no long jumps as a row-major or Morton
** order has), so it is the key.
*/
#ifndef LINEWISE_HILBERT_H
#define LINEWISE_HILBERT_H

#include <stddef.h>
#include <stdint.h>

#include "linewise/error.h"
#include "linewise/spline.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Cells per side of the grid the page is quantised to: 2^LW_HILBERT_ORDER. */
#define LW_HILBERT_ORDER 16

/* Position of cell (x, y), both < 2^order, along the Hilbert curve of the
** 2^order x 2^order grid (order 1..31): a bijection onto [0, 4^order) in
** which consecutive positions are cells sharing a side. */
uint64_t lw_hilbert_index(uint32_t x, uint32_t y, int order);

/* Fills order[0..n_splines) with the spline numbers of sp sorted along the
** curve by the mean of each spline's points, the box [x0, x0 + w] x
** [y0, y0 + h] quantised to LW_HILBERT_ORDER (points outside are clamped to
** its edge), ties by number.  Deterministic, and sorted input stays as it
** is: renumbering twice is renumbering once.  Returns 1 if the order is not
** the identity, 0 if it is, -1 (and err) when out of memory. */
int lw_hilbert_order(const lw_splines *sp, double x0, double y0, double w, double h, size_t *order,
                     lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
