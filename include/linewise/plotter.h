/*
** plotter.h -- the drawing for plotters that read no SVG: HP-GL (final.hpgl,
** for HP, Roland and other pen plotters with a pen carousel) and G-code
** (final.gcode, for GRBL and other CNC-style plotters).
**
** Both languages draw straight moves only, so every cubic segment of the
** paths (strokes.h, as the post-pass left them: joined, cropped, ordered,
** reversed) is cut into n chords at t = 0, 1/n, ..., 1, with n the least
** that keeps every point of the curve within `tolerance` of its chord:
** on [t0, t0 + h] the chord misses the cubic by at most h^2/8 max |B''|
** (the linear interpolant's error, which holds for vectors since the Peano
** kernel is positive), and B'' = 6 [(1 - t) (b0 - 2 b1 + b2) + t (b1 - 2 b2
** + b3)] takes its largest length at an end, so
**     n = ceil( sqrt( 6 M / (8 tolerance) ) ),  M = max(|b0 - 2 b1 + b2|, |b1 - 2 b2 + b3|).
** The bound is tight for a parabola (constant B''), so n - 1 chords would
** miss it.  The machines' own grids add their rounding: HP-GL's plotter
** unit is 0.025 mm (a point moves by at most 0.0177 mm), G-code is written
** to 0.001 mm.  A point that rounds onto the one before it is left out.
**
** Both files put the origin at the page's lower-left corner with y up (the
** machines' convention; the page's own y points down, output.h), so the
** drawing is not mirrored; or, with `turn`, turn the page a quarter turn
** counterclockwise, (x, y) to (y, x): the page's top-left corner at the
** origin, its top edge along the machine's y axis, so a portrait page
** plots on paper loaded landscape (an HP 7475A's A4 and A3).  Pens are drawn in order, pen 1 first, each
** path from its first point.
**
** HP-GL: IN; then VS (pen-down speed in cm/s, from speed_down, limited to
** 0.01 .. 127.99 as HP-GL allows), then per pen SPk; and per path
** PUx,y; PDx,y,...; in plotter units (40 per mm); at the end PU;SP0;.
** G-code: G21 G90, the pen-up line, then per path G0 to its start, the
** pen-down line, G1 moves with F (speed_down in mm/min) on the first, and
** the pen-up line; M0 (a pause to change the pen) before every pen after
** the first; at the end G0 X0 Y0 and M2.  The pen lines are the scene's
** plot.gcode_pen_up and plot.gcode_pen_down, written as they are; with
** travel_feed the moves to a path's start and home are G1 at speed_up.
**
** With a bed, a drawing any of whose points falls outside [0, bed[0]] x
** [0, bed[1]] on the machine's axes is refused (LW_EINPUT, naming how far
** it reaches), and no file is written.
*/
#ifndef LINEWISE_PLOTTER_H
#define LINEWISE_PLOTTER_H

#include <stddef.h>

#include "linewise/error.h"
#include "linewise/output.h"
#include "linewise/strokes.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_HPGL_UNITS_PER_MM 40.0   /* HP-GL plotter units: 0.025 mm */
#define LW_HPGL_COORD_MAX 32767.0   /* HP-GL/1's largest coordinate, units */
#define LW_GCODE_DECIMALS 3         /* G-code coordinates: 0.001 mm */
#define LW_PLOTTER_CHORDS_MAX 65536 /* chords of one segment at most */
#define LW_HPGL_VS_MIN 0.01        /* HP-GL's VS, cm/s: 0 < v < 128 */
#define LW_HPGL_VS_MAX 127.99

typedef struct {
  double tolerance;          /* mm: every point of a curve within this of its chords (> 0) */
  double speed_down;         /* mm/s: HP-GL's VS, G-code's F of drawing moves (> 0) */
  const char *pen_up;        /* G-code: the line that lifts the pen */
  const char *pen_down;      /* G-code: the line that lowers it */
  int turn;                  /* 1: the page turned a quarter turn counterclockwise */
  double bed[2];             /* mm the machine reaches along x and y from its origin (0: unchecked) */
  int travel_feed;           /* G-code: 1 = pen-up moves by G1 at speed_up, 0 = rapids (G0) */
  double speed_up;           /* mm/s: travel_feed's F (> 0 where it is on) */
} lw_plotter_options;

/* The chords that keep the cubic b[8] within tol of them (above), 1 ..
** LW_PLOTTER_CHORDS_MAX. */
size_t lw_plotter_chords(const double *b, double tol);

/* NULL when line is a pen line a controller takes: not empty, printable
** ASCII only, at most LW_PLOTTER_GCODE_LINE_MAX characters (GRBL's line
** buffer holds 80 with its end), and no move across the page (an X or Y
** word, G28, G30), change of how the drawing's moves are read (G91, G92)
** nor GRBL system command ($) outside its comments (( ... ), or after ';');
** else what is wrong, as "expected ..." or "a ...: expected ...". */
#define LW_PLOTTER_GCODE_LINE_MAX 79
const char *lw_plotter_gcode_line_fault(const char *line);

/* What writing final.hpgl (gcode 0) or final.gcode (1) of the paths s
** would refuse, without writing: the drawing checks it before any of its
** files, so that a refused one leaves none of them behind. */
lw_status lw_plotter_check(const lw_strokes *s, const lw_output_page *page, const lw_plotter_options *o, int gcode,
                           const char *path, lw_error *err);

/* final.hpgl and final.gcode of the paths s on page: written atomically
** (output.h); LW_EINPUT for a bad page, path or option, LW_EIO when the
** file cannot be written. */
lw_status lw_output_hpgl_strokes(const lw_strokes *s, const lw_output_page *page, const lw_plotter_options *o,
                                 const char *path, lw_error *err);
lw_status lw_output_gcode_strokes(const lw_strokes *s, const lw_output_page *page, const lw_plotter_options *o,
                                  const char *path, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
