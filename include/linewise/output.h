/*
** output.h -- the drawing files of a run directory: the plotter SVG, a PNG
** preview, and the atomic-write helpers every text output shares.
**
** Coordinates are page millimetres with the origin at the top-left corner and
** y pointing down (field.h), which is SVG's own orientation, so nothing is
** flipped.  Each spline becomes one path: M to its first node, then one cubic
** Bezier C command per segment with the control points (spline.h)
**     b0 = p_m,  b1 = p_m + v_m,  b2 = p_{m+1} - v_{m+1},  b3 = p_{m+1}.
** A spline whose control points all coincide has zero length and is skipped
** (a plotter would only dab the paper).  A non-finite coordinate is an error:
** "nan" in a path would make the whole file unreadable.
**
** SVG numbers are millimetres with 4 fixed decimals (0.1 um, far below any
** pen's placement error) and trailing zeros removed: "12.5", "210", "0.3".
** Printed values are thus within 5e-5 mm of the doubles.
**
** Files are written to "<path>.tmp" in the same directory, flushed, synced and
** renamed over path, so a reader sees either the old file or the whole new
** one; on failure the old file is untouched and the temporary file removed.
*/
#ifndef LINEWISE_OUTPUT_H
#define LINEWISE_OUTPUT_H

#include <stddef.h>
#include <stdio.h>

#include "linewise/error.h"
#include "linewise/spline.h"

#define LW_OUTPUT_COLOR_MAX 64
#define LW_OUTPUT_PEN_DEFAULT 0.3     /* mm */
#define LW_OUTPUT_PNG_MAX_PX 4096     /* longest side of a preview, pixels */
#define LW_OUTPUT_PATH_MAX 4096       /* room for "<path>.tmp" in the writers here */

typedef struct {
  double width_mm, height_mm;         /* page, mm (> 0) */
  double stroke_mm;                   /* pen width, mm (> 0) */
  char color[LW_OUTPUT_COLOR_MAX];    /* SVG stroke colour: a name, #rgb, #rrggbb or
                                         rgb(...); characters that would need XML
                                         escaping are rejected */
} lw_output_page;

/* A page of the given size with the default pen (0.3 mm, "black"). */
void lw_output_page_init(lw_output_page *page, double width_mm, double height_mm);

/* The plotter SVG (SVG 1.1, user units = mm, paths in the Inkscape layer
** "pen 1"), written atomically.  LW_EINPUT for a bad page or a non-finite
** coordinate, LW_EIO when the file cannot be written. */
lw_status lw_output_svg(const lw_splines *sp, const lw_output_page *page, const char *path,
                        lw_error *err);

/* The preview PNG: white background, the exact Bezier curves stroked black
** with the pen width (round caps and joins), antialiased.  The image is
** ceil(page * px_per_mm) pixels, except that px_per_mm is lowered so that the
** longer side is at most LW_OUTPUT_PNG_MAX_PX (memory stays below 64 MiB).
** Written atomically; errors as for lw_output_svg. */
lw_status lw_output_png(const lw_splines *sp, const lw_output_page *page, double px_per_mm,
                        const char *path, lw_error *err);

/* The pixel size lw_output_png uses, and the scale after the cap (px per mm).
** 0 if the page or px_per_mm are not positive and finite. */
int lw_output_png_size(const lw_output_page *page, double px_per_mm, int *width_px,
                       int *height_px, double *scale);

/* Opens "<path>.tmp" for writing ("w"), its name stored in tmp[n].  NULL and
** err (LW_EIO, naming path) if the name does not fit or the file cannot be
** created, e.g. because path's directory does not exist. */
FILE *lw_output_open_tmp(const char *path, char *tmp, size_t n, lw_error *err);

/* Finishes a file from lw_output_open_tmp: flush, fsync, close, then rename
** tmp over path.  Any write error seen on f (ferror) also fails it.  On
** failure tmp is removed, path is untouched and err is LW_EIO.  f is closed
** in every case. */
lw_status lw_output_commit(FILE *f, const char *tmp, const char *path, lw_error *err);

/* Gives up a file from lw_output_open_tmp: closes f and removes tmp. */
void lw_output_abort(FILE *f, const char *tmp);

#endif
