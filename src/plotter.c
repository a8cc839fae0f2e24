/* plotter.c -- final.hpgl and final.gcode: the paths as chords for
** plotters that read no SVG (plotter.h). */
#include "linewise/plotter.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Coordinates past this (mm) are refused before anything is written: far
** beyond any page the scene accepts (1e7 mm), and still exact integers of
** HP-GL units and G-code's thousandths. */
#define LW_PLOTTER_MM_MAX 1e8


/* Points a PD instruction carries: long lists are legal, but short ones
** keep within the input buffers of older plotters. */
#define LW_HPGL_PD_POINTS 32

size_t lw_plotter_chords(const double *b, double tol)
{
  double m = 0.0;
  for (int k = 0; k < 2; k++) {
    const double *c = b + 2 * k;
    double dx = c[0] - 2.0 * c[2] + c[4], dy = c[1] - 2.0 * c[3] + c[5];
    m = fmax(m, hypot(dx, dy));
  }
  double n = ceil(sqrt(6.0 * m / (8.0 * tol)));
  if (!(n >= 1.0)) return 1; /* also NaN */
  return n > LW_PLOTTER_CHORDS_MAX ? LW_PLOTTER_CHORDS_MAX : (size_t)n;
}

#define SPELLED_(x) #x
#define SPELLED(x) SPELLED_(x)

const char *lw_plotter_gcode_line_fault(const char *line)
{
  static const char *const ascii = "expected one line of printable ASCII, at most " SPELLED(LW_PLOTTER_GCODE_LINE_MAX)
                                   " characters";
  if (!line || !line[0] || strlen(line) > LW_PLOTTER_GCODE_LINE_MAX) return ascii;
  for (const char *c = line; *c; c++)
    if (*c < 0x20 || *c >= 0x7f) return ascii;
  /* a pen line is written at every lift and every lowering: a move in the
  ** page's plane there (a shared scene's G0 X-900 Y-900) drove the head
  ** off the bed at each stroke, unseen by the bed check and the plot time,
  ** and a GRBL system command ($RST=* resets every setting) ran as often */
  /* A ( comment ) ends at its first ')', as controllers read it (counted
  ** as nesting, "(( ) X-900 )" hid a live move), and ';' ends the line. */
  int in_comment = 0;
  for (const char *c = line; *c && *c != ';'; c++) {
    if (in_comment) {
      in_comment = *c != ')';
      continue;
    }
    if (*c == '(') {
      in_comment = 1;
      continue;
    }
    const char *v = c + 1;
    while (*v == ' ') v++;
    if (*c == '$')
      return "a GRBL system command ($), which changes the machine's settings or state: expected a line that "
             "only lifts or lowers the pen";
    /* (a word's value only: Klipper's macros, SET_SERVO SERVO=pen, and
    ** LinuxCNC's parameters, Z#1, are pen lines too) */
    const int number = *v && strchr("+-.0123456789", *v);
    if (strchr("XxYy", *c) && number)
      return "a move across the page (an X or Y word), which the bed check and the plot time do not see: "
             "expected a line that only lifts or lowers the pen";
    if (strchr("Mm", *c) && number) {
      const long m = strtol(v, NULL, 10);
      if (m == 0 || m == 1 || m == 2 || m == 30 || m == 60)
        return "a program stop or end (M0, M1, M2, M30 or M60), which would halt the plot at its first lift: "
               "expected a line that only lifts or lowers the pen";
    }
    /* G28 and G30 go to stored positions across the page; G91 makes the
    ** drawing's moves after it relative, G92 shifts its coordinates */
    if (strchr("Gg", *c) && number) {
      const long g = strtol(v, NULL, 10);
      if (g == 28 || g == 30 || g == 91 || g == 92)
        return "G28, G30, G91 or G92, which move across the page or change how the drawing's moves are read: "
               "expected a line that only lifts or lowers the pen";
    }
  }
  return NULL;
}

/* A feed, mm/min: to the thousandth, so that a slow pen is not F0, which
** GRBL refuses (a whole number or a tenth took 0.00001 mm/s to F0). */
static void put_feed(FILE *f, double mm_per_s)
{
  fputs(" F", f);
  lw_output_put_fixed(f, 60.0 * mm_per_s, 3);
}

/* Page millimetres (y down) to the machine's (y up): the page's lower-left
** corner at the origin, or turned a quarter turn counterclockwise, its
** top-left corner there. */
static void machine(const lw_output_page *page, const lw_plotter_options *o, double x, double y, double *mx,
                    double *my)
{
  if (o->turn) {
    *mx = y;
    *my = x;
  } else {
    *mx = x;
    *my = page->height_mm - y;
  }
}

/* put(ctx, x, y) for the first point of path k and the end of each chord
** after it, machine millimetres. */
static void walk_path(const lw_strokes *s, size_t k, const lw_output_page *page, const lw_plotter_options *o,
                      void (*put)(void *, double, double), void *ctx)
{
  double b[8], xy[2], m[2];
  for (size_t j = 0; j < s->first[k + 1] - s->first[k]; j++) {
    lw_strokes_drawn_segment(s, k, j, b);
    if (!j) {
      machine(page, o, b[0], b[1], &m[0], &m[1]);
      put(ctx, m[0], m[1]);
    }
    size_t n = lw_plotter_chords(b, o->tolerance);
    for (size_t i = 1; i <= n; i++) {
      if (i < n) lw_bezier_eval(b, (double)i / (double)n, xy);
      else memcpy(xy, b + 6, sizeof xy);
      machine(page, o, xy[0], xy[1], &m[0], &m[1]);
      put(ctx, m[0], m[1]);
    }
  }
}

/* The box of every point the files would visit, on the machine's axes; a
** point on the bed's edge within half the file's grid step is on it (HP-GL's
** 0.0125 mm; G-code's 0.0005 mm: a point 0.012 mm past a GRBL bed, whose
** three decimals kept it past, passed). */
#define HPGL_SLACK (0.5 / LW_HPGL_UNITS_PER_MM)
#define GCODE_SLACK 0.0005
typedef struct {
  double lo[2], hi[2];
  double slack;
} extent;

static void extend(void *ctx, double x, double y)
{
  extent *e = ctx;
  e->lo[0] = fmin(e->lo[0], x), e->hi[0] = fmax(e->hi[0], x);
  e->lo[1] = fmin(e->lo[1], y), e->hi[1] = fmax(e->hi[1], y);
}

/* The box of the drawing on the machine's axes under turn `turn`, for the
** G-code file or the HP-GL one. */
static extent reach(const lw_strokes *s, const lw_output_page *page, const lw_plotter_options *o, int turn, int gcode)
{
  lw_plotter_options t = *o;
  t.turn = turn;
  extent e = {{INFINITY, INFINITY}, {-INFINITY, -INFINITY}, gcode ? GCODE_SLACK : HPGL_SLACK};
  for (size_t j = 0; j < s->n; j++) walk_path(s, j, page, &t, extend, &e);
  return e;
}

/* The first axis (0, 1) from `from` on along which e leaves the bed, or -1. */
static int off_bed(const extent *e, const double bed[2], int from)
{
  for (int k = from; k < 2; k++)
    if (bed[k] > 0.0 && !(e->lo[k] >= -e->slack && e->hi[k] <= bed[k] + e->slack)) return k;
  return -1;
}

/* Where e leaves the bed along axis k, into buf. */
static void past_bed(const extent *e, const double bed[2], int k, char *buf, size_t n)
{
  /* below 0 is past the machine's origin, not its bed's far side (a
  ** stroke at x = -3 was blamed on the bed's width) */
  const int below = e->lo[k] < -e->slack, beyond = bed[k] > 0.0 && e->hi[k] > bed[k] + e->slack;
  char origin[32] = "", far[64] = "";
  if (below) snprintf(origin, sizeof origin, "its origin (%c below 0)", "xy"[k]);
  if (beyond) snprintf(far, sizeof far, "its bed of %g mm (plot.bed_%s)", bed[k], k ? "height" : "width");
  snprintf(buf, n, "%c = %.3f to %.3f mm on the machine, past %s%s%s", "xy"[k], e->lo[k], e->hi[k], origin,
           below && beyond ? " and " : "", far);
}

lw_status lw_plotter_check(const lw_strokes *s, const lw_output_page *page, const lw_plotter_options *o, int gcode,
                           const char *path, lw_error *err)
{
  lw_status st = lw_output_check_strokes(s, page, NULL, path, err);
  if (st) return st;
  if (!(o->tolerance > 0 && isfinite(o->tolerance)))
    return lw_error_set(err, LW_EINPUT, "%s: chord tolerance %g mm: expected a positive number", path, o->tolerance);
  if (!(o->speed_down > 0 && isfinite(o->speed_down)))
    return lw_error_set(err, LW_EINPUT, "%s: pen-down speed %g mm/s: expected a positive number", path,
                        o->speed_down);
  for (size_t k = 0; k < 8 * s->n_segs; k++)
    if (fabs(s->b[k]) > LW_PLOTTER_MM_MAX)
      /* (%g wrote both as 1e+08, and "segment N" counted the strokes' pieces,
      ** which no file of the user's numbers) */
      return lw_error_set(err, LW_EINPUT, "%s: a stroke reaches %c = %.10g mm: expected coordinates within %.10g mm "
                          "of the page's corner; plot.crop = 1 cuts the strokes to the page", path, "xy"[k % 2],
                          s->b[k], LW_PLOTTER_MM_MAX);
  if (o->bed[0] > 0.0 || o->bed[1] > 0.0) {
    extent e = reach(s, page, o, o->turn, gcode);
    int k = off_bed(&e, o->bed, 0);
    if (k >= 0) {
      /* the other turn only where the drawing would fit the bed with it */
      extent t = reach(s, page, o, !o->turn, gcode);
      char turn[64] = "";
      if (off_bed(&t, o->bed, 0) < 0)
        snprintf(turn, sizeof turn, " or the other turn (plot.turn = %d)", o->turn ? 0 : 90);
      /* both axes, where both are off (one named, then the other refused
      ** once that was mended) */
      char past[2][160] = {"", ""};
      past_bed(&e, o->bed, k, past[0], sizeof past[0]);
      const int k2 = off_bed(&e, o->bed, k + 1);
      if (k2 >= 0) past_bed(&e, o->bed, k2, past[1], sizeof past[1]);
      return lw_error_set(err, LW_EINPUT, "%s: the drawing reaches %s%s%s: expected plot.crop = 1 (which cuts the "
                          "strokes to the page inside its margin)%s%s", path, past[0], k2 >= 0 ? ", and " : "",
                          past[1], turn[0] ? ", a wider margin in a new run" : " or a wider margin in a new run", turn);
    }
  }
  if (!gcode) return LW_OK;
  if (o->travel_feed && !(o->speed_up > 0 && isfinite(o->speed_up)))
    return lw_error_set(err, LW_EINPUT, "%s: pen-up speed %g mm/s: expected a positive number", path, o->speed_up);
  const char *line[2] = {o->pen_up, o->pen_down}, *what[2] = {"pen-up", "pen-down"};
  for (int k = 0; k < 2; k++) {
    const char *fault = lw_plotter_gcode_line_fault(line[k]);
    if (fault)
      return lw_error_set(err, LW_EINPUT, "%s: the %s line '%s': %s", path, what[k], line[k] ? line[k] : "", fault);
  }
  return LW_OK;
}

/* ---- HP-GL -------------------------------------------------------------- */

typedef struct {
  FILE *f;
  long x, y;         /* the last point, plotter units */
  size_t points;     /* points of the path so far */
  size_t drawn;      /* of them in PD instructions */
} hpgl_path;

static void hpgl_point(void *ctx, double x, double y)
{
  hpgl_path *h = ctx;
  long px = lround(x * LW_HPGL_UNITS_PER_MM), py = lround(y * LW_HPGL_UNITS_PER_MM);
  if (h->points++ == 0) {
    fprintf(h->f, "PU%ld,%ld;\n", px, py);
  } else {
    if (px == h->x && py == h->y) return;
    if (h->drawn % LW_HPGL_PD_POINTS == 0) fputs(h->drawn ? ";\nPD" : "PD", h->f);
    else fputc(',', h->f);
    fprintf(h->f, "%ld,%ld", px, py);
    h->drawn++;
  }
  h->x = px;
  h->y = py;
}

lw_status lw_output_hpgl_strokes(const lw_strokes *s, const lw_output_page *page, const lw_plotter_options *o,
                                 const char *path, lw_error *err)
{
  lw_status st = lw_plotter_check(s, page, o, 0, path, err);
  if (st) return st;
  char tmp[LW_OUTPUT_PATH_MAX];
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) return err ? err->code : LW_EIO;
  fputs("IN;\nVS", f);
  lw_output_put_fixed(f, fmin(fmax(o->speed_down / 10.0, LW_HPGL_VS_MIN), LW_HPGL_VS_MAX), 2);
  fputs(";\n", f);
  for (int k = 0, drew = 0; k < s->n_pens; k++) {
    size_t a, z;
    lw_strokes_pen_range(s, k, &a, &z);
    if (a == z) continue; /* a pen that draws nothing is not asked for */
    /* pens change at the origin, where the next pen's tour starts */
    fprintf(f, "%sSP%d;\n", drew++ ? "PU0,0;" : "", k + 1);
    for (size_t j = a; j < z; j++) {
      hpgl_path h = {.f = f};
      walk_path(s, j, page, o, hpgl_point, &h);
      /* a path that rounds to one point is a dot */
      fputs(h.drawn ? ";\n" : "PD;\n", f);
    }
  }
  fputs("PU0,0;SP0;\n", f); /* home, as the G-code ends, and the pen put away */
  return lw_output_commit(f, tmp, path, err);
}

/* ---- G-code ------------------------------------------------------------- */

typedef struct {
  FILE *f;
  const lw_plotter_options *o;
  long long x, y;    /* the last point, thousandths of a mm */
  size_t points;     /* points of the path so far */
  size_t drawn;      /* of them drawn (G1) */
} gcode_path;

static void put_xy(FILE *f, long long x, long long y)
{
  fputs(" X", f);
  lw_output_put_fixed(f, (double)x / 1000.0, LW_GCODE_DECIMALS);
  fputs(" Y", f);
  lw_output_put_fixed(f, (double)y / 1000.0, LW_GCODE_DECIMALS);
}

/* A pen-up move: a rapid, or a feed at speed_up (set again each time: a
** drawing move between has set its own) */
static void travel(FILE *f, const lw_plotter_options *o, long long x, long long y)
{
  fputs(o->travel_feed ? "G1" : "G0", f);
  put_xy(f, x, y);
  if (o->travel_feed) put_feed(f, o->speed_up);
  fputc('\n', f);
}

static void gcode_point(void *ctx, double x, double y)
{
  gcode_path *g = ctx;
  long long px = llround(x * 1000.0), py = llround(y * 1000.0);
  if (g->points++ == 0) {
    travel(g->f, g->o, px, py);
    fprintf(g->f, "%s\n", g->o->pen_down);
  } else {
    if (px == g->x && py == g->y) return;
    fputs("G1", g->f);
    put_xy(g->f, px, py);
    /* the pen-down line may set a feed of its own (G1 Z0 F...) */
    if (g->drawn++ == 0) put_feed(g->f, g->o->speed_down);
    fputc('\n', g->f);
  }
  g->x = px;
  g->y = py;
}

/* "pen 2 (cyan, #00ffff, 0.3 mm)" */
static void put_pen(FILE *f, const lw_output_page *page, int k)
{
  const lw_output_pen *pen = &page->pen[k];
  fprintf(f, "pen %d (", k + 1);
  if (page->pen_name[k][0]) fprintf(f, "%s, ", page->pen_name[k]);
  fprintf(f, "#%02x%02x%02x, ", pen->rgb[0], pen->rgb[1], pen->rgb[2]);
  lw_output_put_fixed(f, pen->width_mm, LW_OUTPUT_SVG_DECIMALS);
  fputs(" mm)", f);
}

lw_status lw_output_gcode_strokes(const lw_strokes *s, const lw_output_page *page, const lw_plotter_options *o,
                                  const char *path, lw_error *err)
{
  lw_status st = lw_plotter_check(s, page, o, 1, path, err);
  if (st) return st;
  char tmp[LW_OUTPUT_PATH_MAX];
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) return err ? err->code : LW_EIO;
  fputs("; linewise: a page of ", f);
  lw_output_put_fixed(f, page->width_mm, LW_OUTPUT_SVG_DECIMALS);
  fputs(" x ", f);
  lw_output_put_fixed(f, page->height_mm, LW_OUTPUT_SVG_DECIMALS);
  /* (lines of at most 79 characters: a sender that counts them into
  ** GRBL's 128-byte buffer stalled on a page's 131) */
  fputs(o->turn ? " mm\n; turned a quarter turn counterclockwise, origin at its top-left corner,\n; its top edge "
                  "along y\n" : " mm\n; origin at its lower-left corner, y up\n", f);
  int first = 0; /* the first pen that draws: a pen that draws nothing is not asked for */
  while (first + 1 < s->n_pens && s->pen_first[first] == s->pen_first[first + 1]) first++;
  size_t a0, z0;
  lw_strokes_pen_range(s, first, &a0, &z0);
  if (a0 < z0) {
    fputs("; load ", f);
    put_pen(f, page, first);
    fputs(" before starting\n", f);
  } else {
    fputs("; an empty drawing: no pen is asked for\n", f);
  }
  /* the feed set before the pen lines, whose G1 without an F of its own
  ** would be refused before any (GRBL's error 22) */
  fputs("G21\nG90\nG94", f);
  put_feed(f, o->speed_down);
  fprintf(f, "\n%s\n", o->pen_up);
  for (int k = first; k < s->n_pens; k++) {
    size_t a, z;
    lw_strokes_pen_range(s, k, &a, &z);
    if (a == z) continue;
    if (k > first) {
      /* pens change at the origin, where the next pen's tour starts */
      travel(f, o, 0, 0);
      fputs("; load ", f);
      put_pen(f, page, k);
      fputs(", then resume\nM0\n", f);
    }
    for (size_t j = a; j < z; j++) {
      gcode_path g = {.f = f, .o = o};
      walk_path(s, j, page, o, gcode_point, &g);
      fprintf(f, "%s\n", o->pen_up);
    }
  }
  travel(f, o, 0, 0);
  fputs("M2\n", f);
  return lw_output_commit(f, tmp, path, err);
}
