/*
** output.h -- the drawing files: the plotter SVG, PNG and PDF previews,
** animation frames, and the atomic-write helpers every output shares.
**
** Coordinates are page millimetres with the origin at the top-left corner and
** y pointing down (field.h), which is SVG's own orientation, so nothing is
** flipped.  Each spline becomes one path: M to its first node, then one cubic
** Bezier C command per segment with the control points (spline.h)
**     b0 = p_m,  b1 = p_m + v_m,  b2 = p_{m+1} - v_{m+1},  b3 = p_{m+1}.
** A spline whose control points all coincide has zero length and is skipped
** (lw_splines_is_point).  A non-finite coordinate is an error:
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

#include <cairo.h>

#include "linewise/error.h"
#include "linewise/field.h"
#include "linewise/plot.h"
#include "linewise/spline.h"
#include "linewise/strokes.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_OUTPUT_PEN_DEFAULT 0.3     /* mm */
#define LW_OUTPUT_PNG_MAX_PX 4096     /* longest side of a preview, pixels */
#define LW_OUTPUT_PATH_MAX 4096       /* room for "<path>.tmp" in the writers here */
#define LW_OUTPUT_UNDERLAY_ALPHA 0.5  /* strength of the source image under a preview */
#define LW_OUTPUT_SVG_DECIMALS 4      /* decimals of final.svg's millimetres */

typedef struct {
  double width_mm;                    /* stroke width, mm (> 0) */
  unsigned char rgb[3];               /* colour, 0..255 per channel */
} lw_output_pen;

typedef struct {
  double width_mm, height_mm;         /* page, mm (> 0) */
  int n_pens;                         /* 1 .. LW_PLOT_PENS_MAX */
  lw_output_pen pen[LW_PLOT_PENS_MAX];
  char pen_name[LW_PLOT_PENS_MAX][64]; /* each pen's SVG layer label, or empty: "pen <k>" */
  int multiply;                       /* 1: the previews lay each pen's ink over the
                                         others by multiplying colours (cyan over yellow
                                         is green); 0: each paints over */
} lw_output_page;

/* v with `decimals` fixed decimals, trailing zeros and a bare point removed,
** "-0" folded to "0".  Fixed decimals rather than %g: the precision of a plot
** is absolute (mm), not relative, and %g would switch to exponents that some
** plotter tools do not parse.  Any finite double fits (309 digits). */
void lw_output_put_fixed(FILE *f, double v, int decimals);

/* The page (as lw_output_svg checks it), tone (may be NULL) and paths of a
** drawing that is about to be written to path: LW_EINPUT and err naming
** path when a size, pen or control point is not what a file can hold. */
lw_status lw_output_check_strokes(const lw_strokes *s, const lw_output_page *page, const lw_grid2d *tone,
                                  const char *path, lw_error *err);

/* A page of the given size with one pen: 0.3 mm, black. */
void lw_output_page_init(lw_output_page *page, double width_mm, double height_mm);

/* Reads a colour "#rgb" or "#rrggbb" (hex digits, either case) of len
** characters; 1 on success. */
int lw_output_color_parse(const char *text, size_t len, unsigned char rgb[3]);

/* Reads up to max colours separated by spaces, tabs or commas into rgb[];
** returns how many there are, or -1 if one is malformed or there are more
** than max. */
int lw_output_colors_parse(const char *list, unsigned char (*rgb)[3], int max);

/* The drawings below take an optional plot (plot.h): with it, pen k's paths
** are drawn with page->pen[k] in plotting order and direction; without it
** (NULL) every path is pen 1's, in index order.  A path's id in the SVG is
** "spline<i>", i the spline of its first piece, with "-<k>" added for the
** k-th further piece of a cropped spline (strokes.h).  The plot must have as many
** pens as the page.  An optional tone raster (field.h: ncomp 1, node (i, j)
** the centre of pixel (i, j), tone 0 = black .. 1 = white) is painted under
** the lines of the previews in grey at LW_OUTPUT_UNDERLAY_ALPHA, covering
** its pixels' rectangle; NULL paints none. */

/* The plotter SVG, written atomically: width and height in mm, viewBox in
** mm (user unit = 1 mm), one Inkscape layer group per pen in pen order
** (id "pen<k>", label "<k> pen", or "<k> <name>" for a named pen, no
** other digit: AxiDraw's software plots a layer by its leading number, and
** vpype takes a label's every digit for it;
** with page->multiply each group's style is mix-blend-mode:multiply), one
** path per spline with
** M and C commands only.  A reversed path lists the control points of its
** segments backwards, last segment first, so it is the same curve.
** LW_EINPUT for a bad page or plot or a non-finite coordinate, LW_EIO when
** the file cannot be written. */
lw_status lw_output_svg(const lw_splines *sp, const lw_output_page *page, const lw_plot *plot,
                        const char *path, lw_error *err);

/* The preview PNG: white background, the tone underneath if given, the
** exact Bezier curves stroked with their pen's colour and width (round caps
** and joins), antialiased.  The image is ceil(page * px_per_mm) pixels,
** except that px_per_mm is lowered so that the longer side is at most
** LW_OUTPUT_PNG_MAX_PX (memory stays below 64 MiB).  Written atomically;
** errors as for lw_output_svg. */
lw_status lw_output_png(const lw_splines *sp, const lw_output_page *page, const lw_plot *plot,
                        const lw_grid2d *tone, double px_per_mm, const char *path, lw_error *err);

/* The same drawing as a one-page vector PDF of the page's size (1 mm =
** 72 / 25.4 pt); no creation date is stored, so equal drawings give equal
** files.  Written atomically; errors as for lw_output_svg. */
lw_status lw_output_pdf(const lw_splines *sp, const lw_output_page *page, const lw_plot *plot,
                        const lw_grid2d *tone, const char *path, lw_error *err);

/* An animation frame: the preview PNG as DIR/frames/frame-SSSSSS.png (the
** sweep, at least 6 digits), creating DIR/frames if needed. */
lw_status lw_output_frame(const char *dir, long sweep, const lw_splines *sp, const lw_output_page *page,
                          const lw_plot *plot, const lw_grid2d *tone, double px_per_mm, lw_error *err);

/* An RGB24 surface of w x h pixels, white: its bytes set, where a
** cairo_paint of white, out of memory inside cairo, was dropped without a
** status, and the preview came out black with exit 0 (a fault injector's
** find).  The caller checks cairo_surface_status and destroys it. */
cairo_surface_t *lw_output_white_surface(int w, int h);

/* Writes surf as a PNG to path through a temporary file and
** lw_output_commit; a failed write names the file and the reason (errno,
** which cairo's own message leaves out). */
lw_status lw_output_png_surface(cairo_surface_t *surf, const char *path, lw_error *err);

/* The same three drawings of paths (strokes.h) as they are: their pens,
** order and directions; the calls above turn the splines and plot into
** paths and call these. */
lw_status lw_output_svg_strokes(const lw_strokes *s, const lw_output_page *page, const char *path,
                                lw_error *err);
lw_status lw_output_png_strokes(const lw_strokes *s, const lw_output_page *page, const lw_grid2d *tone,
                                double px_per_mm, const char *path, lw_error *err);
lw_status lw_output_pdf_strokes(const lw_strokes *s, const lw_output_page *page, const lw_grid2d *tone,
                                const char *path, lw_error *err);

/* Appends path k to cr's path as the plotter draws it (a reversed path from
** its end: the PDF's subpaths in final.svg's order and directions). */
void lw_output_cairo_path(cairo_t *cr, const lw_strokes *s, size_t k);

/* Strokes every path of pen `pen` (0-based; -1: every pen) with the current
** source, line width and transformation of cr (for renderers elsewhere). */
void lw_output_cairo_strokes(cairo_t *cr, const lw_strokes *s, int pen);

/* The pixel size lw_output_png uses, and the scale after the cap (px per mm).
** 0 if the page or px_per_mm are not positive and finite. */
int lw_output_png_size(const lw_output_page *page, double px_per_mm, int *width_px,
                       int *height_px, double *scale);

/* Opens "<path>.tmp" for writing, its name stored in tmp[n]: a new file, in
** place of whatever was there, never through a link (one planted in a run
** directory had a run write, as root, into any file).  NULL and err (LW_EIO,
** naming path) if the name does not fit or the file cannot be created, e.g.
** because path's directory does not exist. */
FILE *lw_output_open_tmp(const char *path, char *tmp, size_t n, lw_error *err);

/* DIR/sub (frames, samples), made where it is not, into path[n]: a link or a
** file there is refused (a run's files go into its own directory only). */
lw_status lw_output_subdir(const char *dir, const char *sub, char *path, size_t n, lw_error *err);

/* Finishes a file from lw_output_open_tmp: flush, fsync, close, then rename
** tmp over path.  Any write error seen on f (ferror) also fails it.  On
** failure tmp is removed, path is untouched and err is LW_EIO.  f is closed
** in every case. */
lw_status lw_output_commit(FILE *f, const char *tmp, const char *path, lw_error *err);

/* fsync of the directory dir, so that the renames and removals in it so far
** outlast a power cut; quiet where the file system cannot. */
void lw_output_sync_dir(const char *dir);

/* Gives up a file from lw_output_open_tmp: closes f and removes tmp. */
void lw_output_abort(FILE *f, const char *tmp);

#ifdef __cplusplus
}
#endif

#endif
