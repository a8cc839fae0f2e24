/*
** drawing.h -- the drawing files of a run, as its parameters ask, and what
** they report.
**
**   final.svg   pens as Inkscape layers, paths ordered per [output] order
**   final.png   preview at [output] png_scale
**   final.pdf   vector preview, when [output] pdf = 1
**   frames/frame-SSSSSS.png  every [output] frames_every sweeps
** The previews paint the target tone underneath when [output] preview_image
** = 1 and the run has one.
**
** Pens are ranked (plot.h) by the mean of the potential along each spline
** when the potential term is on, else by the mean target tone when there is
** a target, else round robin.  Frames use the same pens but no ordering (a
** frame is a picture, not a plot).
**
** The report holds the pen-up travel before and after ordering and, with a
** target tone, the fidelity score (fidelity.h) with [output] fidelity_sigma;
** The report also holds the close share (spacing.h): the share of the line
** length with another stroke within one output.pen_width.
** lw_drawing_report_json writes them into summary.json as
**     "pen_up_travel_mm": {"before": ..., "after": ...},
**     "close_share": ...,
**     "fidelity": {"mse": ..., "ssim": ..., "sigma_mm": ...}   (with a target)
*/
#ifndef LINEWISE_DRAWING_H
#define LINEWISE_DRAWING_H

#include "linewise/fidelity.h"
#include "linewise/json.h"
#include "linewise/output.h"
#include "linewise/params.h"
#include "linewise/scene.h"

typedef struct {
  size_t paths;                       /* paths drawn */
  double travel_before, travel_after; /* pen-up travel, mm (plot.h) */
  double close_share;                 /* share of the length within a pen width of another stroke */
  int has_fidelity;                   /* a target tone was given */
  lw_fidelity fidelity;
} lw_drawing_report;

/* The page and pens of p: size from [scene], pens from [output].  Errors
** name the parameter's origin. */
lw_status lw_drawing_page(const lw_params *p, lw_output_page *page, lw_error *err);

/* Writes final.svg, final.png and (if asked) final.pdf into dir and fills
** rep.  tone: the target tone raster (fidelity.h) or NULL. */
lw_status lw_drawing_write(const lw_params *p, const lw_scene *sc, const lw_splines *sp, const lw_grid2d *tone,
                           const char *dir, lw_drawing_report *rep, lw_error *err);

/* The animation frame of sweep into dir/frames/. */
lw_status lw_drawing_frame(const lw_params *p, const lw_scene *sc, const lw_splines *sp, const lw_grid2d *tone,
                           const char *dir, long sweep, lw_error *err);

/* The report's members of summary.json (into the open object of j). */
void lw_drawing_report_json(lw_json *j, const lw_drawing_report *rep);

#endif
