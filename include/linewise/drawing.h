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
** The final drawing goes through the plotter post-pass of strokes.h with
** the [plot] keys: join (join_distance pen widths, join_angle), crop to
** the picture's rectangle (without a picture the margin box), drop paths
** shorter than min_length pen widths, order.  SVG, PNG, PDF and the
** fidelity score all show that drawing; the state is not changed, and
** frames show the state's splines as they are.
**
** The report holds what the post-pass did, the pen-up travel before and
** after ordering, the plot time estimate and, with a target tone, the
** fidelity scores (fidelity.h) with [output] fidelity_sigma, overall and
** per pen when there are several; lw_drawing_report_json writes them into
** summary.json as
**     "paths": ..., "pen_up_travel_mm": {"before": ..., "after": ...},
**     "plot": {"lifts": {"before": ..., "after": ...}, "joins": ...,
**              "cut": ..., "outside": ..., "dropped": ...,
**              "crop_mm": [x0, y0, x1, y1] or null,
**              "pen_down_mm": ..., "pen_up_mm": ..., "time_s": ...},
**     "close_share": ...,   (the paths' length within a pen width of
**                            another path: spacing.h)
**     "fidelity": {"mse": ..., "ssim": ..., "orientation": ...,
**                  "sigma_mm": ..., "pens": [{"mse", "ssim",
**                  "orientation"}, ...]}   (with a target; pens if > 1;
**                                           null where memory ran out)
*/
#ifndef LINEWISE_DRAWING_H
#define LINEWISE_DRAWING_H

#include "linewise/fidelity.h"
#include "linewise/json.h"
#include "linewise/output.h"
#include "linewise/params.h"
#include "linewise/scene.h"
#include "linewise/strokes.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  size_t paths;                       /* paths drawn */
  double travel_before, travel_after; /* pen-up travel, mm (plot.h) */
  lw_strokes_report post;             /* what the post-pass did */
  double close_share;                 /* share of the length within a pen width of another path */
  int close_past_limit;               /* its points (two a pen width) past its grid's 2^32: NaN */
  int cropped;                        /* crop_mm holds the rectangle */
  size_t off_page;                    /* uncropped: paths that reach past the page's edge */
  double crop_mm[4];                  /* x0 y0 x1 y1 */
  double pen_down_mm;                 /* ink length */
  double time_s;                      /* plot time estimate */
  int has_fidelity;                   /* a target tone or a reference was given, and scored */
  int fidelity_lost;                  /* one was given, and memory ran out scoring it (null) */
  char reference[LW_PATH_MAX];        /* output.fidelity_reference scored against, or empty */
  lw_fidelity fidelity;               /* of all pens */
  int n_pens;
  size_t pen_paths[LW_PLOT_PENS_MAX];         /* paths of each pen */
  char pen_name[LW_PLOT_PENS_MAX][64];        /* its layer's name, or empty (the messages say "pen k") */
  char empty_why[400];                        /* with no path: what removed the lines, or empty */
  lw_fidelity pen_fidelity[LW_PLOT_PENS_MAX]; /* per pen, when n_pens > 1 */
  int pen_targets;                            /* the first pens with a target of their own (a layer's) */
  double pen_width[LW_PLOT_PENS_MAX];         /* each pen's, mm */
  int picture_thin;                           /* the picture lies narrower than two segments (noted before) */
  int frame_not_rect;                         /* scene.boundary is not the page's rectangle */
} lw_drawing_report;


/* Appends to note[n] ("; " between notes) what the drawing keys of p will
** not do as set: a pen speed past what HP-GL's VS takes, which final.hpgl
** limits, so that the plot time no longer holds for the machine. */
void lw_drawing_note(const lw_params *p, char *note, size_t n);

/* Writes final.svg, final.png and (if asked) final.pdf into dir and fills
** rep.  tone: the target tone raster (fidelity.h) or NULL. */
lw_status lw_drawing_write(const lw_params *p, const lw_scene *sc, const lw_splines *sp, const lw_grid2d *tone,
                           const char *dir, lw_drawing_report *rep, lw_error *err);

/* The animation frame of sweep into dir/frames/. */
lw_status lw_drawing_frame(const lw_params *p, const lw_scene *sc, const lw_splines *sp, const lw_grid2d *tone,
                           const char *dir, long sweep, lw_error *err);

/* The report's members of summary.json (into the open object of j). */
void lw_drawing_report_json(lw_json *j, const lw_drawing_report *rep);

/* Into buf, "" or what the report left out for want of memory (its close
** share, its fidelity: null in summary.json), without "linewise: " or a
** line end. */
void lw_drawing_lost_text(const lw_drawing_report *d, char *buf, size_t n);

/* The report's lines for the command line ("linewise: ...\n" each) into
** buf[n]. */
void lw_drawing_report_text(const lw_drawing_report *rep, char *buf, size_t n);

#ifdef __cplusplus
}
#endif

#endif
