/*
** fieldfile.h -- a grid of values from a scientist's file: the vector field
** of scene.field = file (two values a node, u and v), read into an lw_grid2d
** (field.h) for the scene to place on the page.
**
** Two formats, told apart by the file's first bytes:
**
**   NumPy .npy (np.save): versions 1 to 3, a plain array of floats (f4, f8)
**   or integers (i1..i8, u1..u8), either byte order, C or Fortran order, of
**   shape (rows, columns, ncomp); with ncomp 1 also (rows, columns).
**
**   Text: one grid row a line, ncomp values a node in a row ("u v u v ..."
**   for a field: np.savetxt(path, F.reshape(rows, -1)) of an array F of
**   shape (rows, columns, 2)), numbers separated by blanks or commas (not
**   both blanks and commas tight between digits: "0,5 0,7" has decimal
**   commas); '#' starts a comment; blank lines are skipped; every row holds
**   as many values as the first; a carriage return inside a line (old Mac
**   line ends) is refused.
**
** Values may be NaN or infinite ("nan", "inf", and "1e400" in text, as
** np.savetxt writes a masked cell and NumPy reads an overflow; "1e-400" is
** 0): they are kept as they are, for the caller to count and treat (the
** scene makes such a node's vector 0).  Row 0 is the file's first row; the grid's
** placement (x0, y0, hx, hy) is left at 0, 0, 1, 1.  Errors name the file
** and, in text, the line and the value, and say what was expected.
*/
#ifndef LINEWISE_FIELDFILE_H
#define LINEWISE_FIELDFILE_H

#include "linewise/field.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The most nodes a file may hold (a 4096 x 4096 grid: 256 MiB of doubles
** for a field); a larger grid is refused before it is allocated. */
#define LW_FIELDFILE_NODES_MAX (1L << 24)

/* The grid in the file at path with ncomp (1 or 2) values a node; NULL and
** err set on failure.  points (with ncomp 2): the file is a text list of
** points, "x y u v" a line, in any order, that sample a regular grid, each
** node once (lines of words before the first point are a header row whose
** names say the columns -- x or points:0, y, u or vx or NAME:0, v -- as
** ParaView's, a spreadsheet's or Tecplot's VARIABLES line, or a title): the grid's rows by ascending y,
** (x0, y0) the least x and y, hx and hy the spacings (their aspect the
** cells'; a grid file's are 1). */
lw_grid2d *lw_fieldfile_read(const char *path, int ncomp, int points, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
