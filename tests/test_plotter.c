/*
** test_plotter.c -- final.hpgl and final.gcode (plotter.h): the chord count
** keeps its bound and is not wasteful, both files read back to the curves
** they stand for (pens, order, directions, the flipped y or the quarter turn), their commands
** come in the order a machine needs, bad options write nothing, and the
** command line writes the same files for the same seed.
*/
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/plotter.h"
#include "testutil.h"

#define PAGE_W 100.0
#define PAGE_H 80.0
#define TOL 0.02
#define HPGL_ROUND (0.5 * M_SQRT2 / LW_HPGL_UNITS_PER_MM) /* a rounded point moves at most this */
#define GCODE_ROUND (0.5e-3 * M_SQRT2)

/* Distance from p to the segment a-b. */
static double to_segment(const double *p, const double *a, const double *b)
{
  double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2 : 0;
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  return hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy);
}

/* A random cubic in a 40 mm box, some nearly straight, some looped. */
static void random_cubic(double *b)
{
  double s = urand(0, 1) < 0.3 ? 0.05 : 1.0;
  b[0] = urand(0, 40);
  b[1] = urand(0, 40);
  b[6] = urand(0, 40);
  b[7] = urand(0, 40);
  for (int c = 2; c < 6; c++) b[c] = (c & 1 ? b[1] : b[0]) + s * urand(-20, 20) + (b[6 + (c & 1)] - b[c & 1]) * (c / 2) / 3.0;
}

Test(plotter, chords_keep_every_point_within_the_tolerance)
{
  rng_seed(2026);
  const double tols[] = {1e-3, 0.02, 0.5};
  for (int trial = 0; trial < 300; trial++) {
    double b[8];
    random_cubic(b);
    double tol = tols[trial % 3];
    size_t n = lw_plotter_chords(b, tol);
    cr_assert(n >= 1 && n <= LW_PLOTTER_CHORDS_MAX);
    double worst = 0;
    for (size_t i = 0; i < n; i++) {
      double a[2], z[2];
      lw_bezier_eval(b, (double)i / n, a);
      lw_bezier_eval(b, (double)(i + 1) / n, z);
      for (int q = 1; q < 32; q++) {
        double p[2];
        lw_bezier_eval(b, (i + q / 32.0) / n, p);
        worst = fmax(worst, to_segment(p, a, z));
      }
    }
    cr_assert(worst <= tol * (1 + 1e-9), "trial %d: %zu chords miss by %g > %g", trial, n, worst, tol);
  }
}

Test(plotter, chords_are_the_fewest_on_a_parabola)
{
  /* A cubic that is a parabola has constant B'' = 6 d, and its chords over
  ** [t0, t0 + h] miss it by exactly h^2/8 |B''| at their middles: the count
  ** is tight when n - 1 chords would miss by more than tol, i.e. the miss
  ** at n exceeds tol ((n - 1)/n)^2. */
  const double tols[] = {1e-3, 3e-3, 0.02, 0.1};
  for (int k = 0; k < 4; k++) {
    double q0[2] = {0, 0}, q1[2] = {15, 9}, q2[2] = {30, -2};
    double b[8] = {q0[0], q0[1], q0[0] + 2 * (q1[0] - q0[0]) / 3, q0[1] + 2 * (q1[1] - q0[1]) / 3,
                   q2[0] + 2 * (q1[0] - q2[0]) / 3, q2[1] + 2 * (q1[1] - q2[1]) / 3, q2[0], q2[1]};
    size_t n = lw_plotter_chords(b, tols[k]);
    cr_assert(n >= 2);
    double h = 1.0 / n, d = hypot(b[0] - 2 * b[2] + b[4], b[1] - 2 * b[3] + b[5]);
    double miss = h * h / 8 * 6 * d;
    double p[2], a[2], z[2];
    lw_bezier_eval(b, 0.5 * h, p);
    lw_bezier_eval(b, 0, a);
    lw_bezier_eval(b, h, z);
    cr_assert(fabs(hypot(p[0] - 0.5 * (a[0] + z[0]), p[1] - 0.5 * (a[1] + z[1])) - miss) < 1e-12);
    cr_assert(miss <= tols[k] && miss > tols[k] * pow((n - 1.0) / n, 2), "n = %zu, miss %g, tol %g", n, miss,
              tols[k]);
  }
}

/* The drawing the file tests read back: pen 1 a circle of four cubics
** (forward) and an S-curve drawn backwards, pen 2 a straight line. */
static lw_strokes *drawing(void)
{
  lw_strokes *s = lw_strokes_new(2, NULL);
  const double k = 0.5522847498 * 20, cx = 50, cy = 40;
  double circle[32] = {cx + 20, cy,     cx + 20, cy + k, cx + k,  cy + 20, cx,      cy + 20,
                       cx,      cy + 20, cx - k, cy + 20, cx - 20, cy + k, cx - 20, cy,
                       cx - 20, cy,     cx - 20, cy - k, cx - k,  cy - 20, cx,      cy - 20,
                       cx,      cy - 20, cx + k, cy - 20, cx + 20, cy - k, cx + 20, cy};
  double scurve[16] = {5, 5, 25, 5, 5, 30, 25, 30, 25, 30, 45, 30, 25, 55, 45, 75};
  double line[8] = {90, 2, 90, 30, 91, 50, 91, 78};
  cr_assert_eq(lw_strokes_add(s, 0, 0, 0, 0, circle, 4, NULL), LW_OK);
  cr_assert_eq(lw_strokes_add(s, 0, 1, 0, 1, scurve, 2, NULL), LW_OK);
  cr_assert_eq(lw_strokes_add(s, 1, 2, 0, 0, line, 1, NULL), LW_OK);
  return s;
}

static lw_output_page page_of(void)
{
  lw_output_page page;
  lw_output_page_init(&page, PAGE_W, PAGE_H);
  page.n_pens = 2;
  page.pen[1] = (lw_output_pen){0.5, {0, 255, 255}};
  snprintf(page.pen_name[1], sizeof page.pen_name[1], "cyan");
  return page;
}

/* A polyline read back from a file, page coordinates (y down). */
typedef struct {
  int pen;
  size_t n;
  double xy[2 * 8192];
} polyline;

/* Both ways: every vertex near the path's curve (rounding only), every
** point of the curve near the polyline (tolerance plus rounding), and the
** ends where the path is drawn from and to. */
static void assert_matches(const lw_strokes *s, size_t k, const polyline *pl, double round)
{
  double b[8], start[2], end[2];
  size_t nseg = s->first[k + 1] - s->first[k];
  lw_strokes_drawn_segment(s, k, 0, b);
  start[0] = b[0];
  start[1] = b[1];
  lw_strokes_drawn_segment(s, k, nseg - 1, b);
  end[0] = b[6];
  end[1] = b[7];
  cr_assert(pl->n >= 2, "path %zu: %zu points", k, pl->n);
  cr_assert(hypot(pl->xy[0] - start[0], pl->xy[1] - start[1]) <= round, "path %zu starts elsewhere", k);
  cr_assert(hypot(pl->xy[2 * pl->n - 2] - end[0], pl->xy[2 * pl->n - 1] - end[1]) <= round, "path %zu ends elsewhere",
            k);
  enum { DENSE = 2000 };
  static double curve[2 * 8 * (DENSE + 1)];
  size_t nc = 0;
  for (size_t j = 0; j < nseg; j++) {
    lw_strokes_drawn_segment(s, k, j, b);
    for (int q = 0; q <= DENSE; q++, nc++) lw_bezier_eval(b, (double)q / DENSE, curve + 2 * nc);
  }
  /* the dense samples' own chords miss the curve by under 1e-5 mm */
  for (size_t v = 0; v < pl->n; v++) {
    double best = INFINITY;
    for (size_t c = 0; c + 1 < nc; c++) best = fmin(best, to_segment(pl->xy + 2 * v, curve + 2 * c, curve + 2 * c + 2));
    cr_assert(best <= round + 1e-5, "path %zu vertex %zu lies %g from the curve", k, v, best);
  }
  size_t from = 0;
  for (size_t c = 0; c < nc; c++) {
    /* the polyline runs along the curve, so the nearest chord is at or
    ** after the last one found */
    double best = INFINITY;
    size_t at = from;
    for (size_t v = from; v + 1 < pl->n; v++) {
      double d = to_segment(curve + 2 * c, pl->xy + 2 * v, pl->xy + 2 * v + 2);
      if (d < best) {
        best = d;
        at = v;
      }
      if (d > 2.0 && v > at + 4) break;
    }
    from = at;
    cr_assert(best <= TOL + round, "path %zu: the curve lies %g from its chords", k, best);
  }
}

static lw_plotter_options options(void)
{
  return (lw_plotter_options){.tolerance = TOL, .speed_down = 50, .pen_up = "M3 S30", .pen_down = "M3 S90 G4 P0.2"};
}

/* The drawing() written by `write` to dir/name, the page turned or not; its
** text (caller frees), the drawing in *s. */
static char *written(lw_status (*write)(const lw_strokes *, const lw_output_page *, const lw_plotter_options *,
                                        const char *, lw_error *),
                     const char *name, int turn, char dir[64], lw_strokes **s)
{
  char path[128];
  cr_assert_eq(lw_test_dir_make(dir, "plotter"), 0);
  snprintf(path, sizeof path, "%s/%s", dir, name);
  *s = drawing();
  lw_output_page page = page_of();
  lw_plotter_options o = options();
  o.turn = turn;
  cr_assert_eq(write(*s, &page, &o, path, NULL), LW_OK);
  char *text = lw_test_slurp("%s", path);
  cr_assert_not_null(text);
  return text;
}

/* A machine point (plotter units, y up) back on the page: flipped, or
** turned back a quarter turn. */
static void page_point(long x, long y, int turn, double *xy)
{
  double mx = x / LW_HPGL_UNITS_PER_MM, my = y / LW_HPGL_UNITS_PER_MM;
  xy[0] = turn ? my : mx;
  xy[1] = turn ? mx : PAGE_H - my;
}

Test(plotter, hpgl_reads_back_to_the_curves_pen_by_pen)
{
  for (int turn = 0; turn < 2; turn++) {
    char dir[64];
    lw_strokes *s;
    char *text = written(lw_output_hpgl_strokes, "final.hpgl", turn, dir, &s);
    /* instructions are separated by ';', the newlines between them ignored */
    static polyline pl[3];
    int pen = 0, paths = 0, sp0 = 0;
    size_t n_ins = 0;
    for (char *ins = strtok(text, ";\n"); ins; ins = strtok(NULL, ";\n"), n_ins++) {
      cr_assert(!sp0, "'%s' after SP0", ins);
      if (n_ins == 0) cr_assert_str_eq(ins, "IN");
      else if (n_ins == 1) cr_assert_str_eq(ins, "VS5", "50 mm/s is 5 cm/s");
      else if (!strncmp(ins, "SP", 2)) {
        int k = atoi(ins + 2);
        if (k == 0) {
          sp0 = 1;
        } else {
          cr_assert_eq(k, pen + 1, "pens in order");
          pen = k;
        }
      } else if (!strcmp(ins, "PU") || !strcmp(ins, "PU0,0")) { /* the way home to change pens */
        continue;
      } else if (!strncmp(ins, "PU", 2)) {
        cr_assert(paths < 3 && pen >= 1);
        polyline *p = &pl[paths++];
        p->pen = pen;
        long x, y;
        cr_assert_eq(sscanf(ins + 2, "%ld,%ld", &x, &y), 2, "%s", ins);
        page_point(x, y, turn, p->xy);
        p->n = 1;
      } else {
        cr_assert(!strncmp(ins, "PD", 2) && paths > 0, "unexpected '%s'", ins);
        polyline *p = &pl[paths - 1];
        for (char *c = ins + 2; *c;) {
          long x = strtol(c, &c, 10);
          cr_assert_eq(*c, ',');
          long y = strtol(c + 1, &c, 10);
          if (*c == ',') c++;
          page_point(x, y, turn, p->xy + 2 * p->n);
          cr_assert(p->n == 0 || p->xy[2 * p->n] != p->xy[2 * p->n - 2] || p->xy[2 * p->n + 1] != p->xy[2 * p->n - 1],
                    "a repeated point");
          p->n++;
        }
      }
    }
    cr_assert(sp0, "the pen is put back at the end");
    cr_assert_eq(paths, 3);
    cr_assert(pl[0].pen == 1 && pl[1].pen == 1 && pl[2].pen == 2);
    for (size_t k = 0; k < 3; k++) assert_matches(s, k, &pl[k], HPGL_ROUND + 1e-12);
    /* the S-curve is drawn from its last point */
    cr_assert(fabs(pl[1].xy[0] - 45) < 0.02 && fabs(pl[1].xy[1] - 75) < 0.02);
    free(text);
    lw_strokes_free(s);
    lw_test_sh("rm -rf %s", dir);
  }
}

Test(plotter, gcode_reads_back_and_moves_the_pen_in_order)
{
  char dir[64];
  lw_strokes *s;
  char *text = written(lw_output_gcode_strokes, "final.gcode", 0, dir, &s);
  lw_plotter_options o = options();
  static polyline pl[3];
  int down = 0, pen = 1, paths = 0, pauses = 0, ended = 0, units = 0, absolute = 0, feed_next = 0, feed = 0;
  for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
    cr_assert(!ended, "'%s' after M2", line);
    if (line[0] == ';') {
      if (strstr(line, "load pen 2 (cyan, #00ffff, 0.5 mm)")) cr_assert_eq(pauses, 0, "the note comes before M0");
      continue;
    }
    /* GRBL's line buffer */
    cr_assert_leq(strlen(line), 79, "'%s'", line);
    if (!strcmp(line, "G21")) units = 1;
    else if (!strcmp(line, "G90")) absolute = 1;
    else if (!strncmp(line, "G94 F", 5)) {
      /* a feed before any pen line, whose G1 without one GRBL refused */
      cr_assert_eq(atof(line + 5), 3000.0, "'%s'", line);
      feed = 1;
    } else if (!strcmp(line, o.pen_up)) {
      cr_assert(feed, "a pen line before the feed");
      down = 0;
    } else if (!strcmp(line, o.pen_down)) {
      cr_assert(!down && paths > 0);
      down = feed_next = 1;
    } else if (!strcmp(line, "M0")) {
      cr_assert(!down, "the pen is up for a change");
      pauses++;
      pen++;
    } else if (!strcmp(line, "M2")) {
      ended = 1;
    } else {
      double x, y;
      cr_assert(units && absolute, "millimetres and absolute before any move");
      int g = -1;
      cr_assert_eq(sscanf(line, "G%d X%lf Y%lf", &g, &x, &y), 3, "'%s'", line);
      const char *f = strstr(line, " F");
      if (g == 0) {
        cr_assert(!down, "a travel with the pen down: '%s'", line);
        if (x == 0 && y == 0) continue; /* home */
        cr_assert(paths < 3);
        pl[paths] = (polyline){.pen = pen, .n = 0};
        paths++;
      } else {
        cr_assert(g == 1 && down, "'%s'", line);
        cr_assert_eq(f != NULL, feed_next, "the feed after each pen-down only: '%s'", line);
        if (f) cr_assert_eq(atof(f + 2), 3000.0, "50 mm/s is 3000 mm/min");
        feed_next = 0;
      }
      polyline *p = &pl[paths - 1];
      p->xy[2 * p->n] = x;
      p->xy[2 * p->n + 1] = PAGE_H - y;
      p->n++;
    }
  }
  cr_assert(ended && !down);
  cr_assert_eq(pauses, 1, "one pen change");
  cr_assert_eq(paths, 3);
  cr_assert(pl[0].pen == 1 && pl[1].pen == 1 && pl[2].pen == 2);
  for (size_t k = 0; k < 3; k++) assert_matches(s, k, &pl[k], GCODE_ROUND + 1e-12);
  free(text);
  lw_strokes_free(s);
  lw_test_sh("rm -rf %s", dir);
}

/* Every line of final.gcode fits GRBL's line buffer, the turned page's
** header too (131 characters, which a sender counting into GRBL's 128-byte
** buffer never sent); a slow pen's feed is to the thousandth (0.00001 mm/s
** was F0, which GRBL refuses), and travels at feed set theirs. */
Test(plotter, gcode_lines_fit_grbl_and_a_slow_feed_is_not_zero)
{
  char dir[64], path[128];
  lw_strokes *s;
  char *text = written(lw_output_gcode_strokes, "final.gcode", 1, dir, &s);
  cr_assert(strstr(text, "counterclockwise"), "%s", text);
  for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n"))
    cr_assert_leq(strlen(line), 79, "'%s'", line);
  free(text);
  lw_output_page page = page_of();
  lw_plotter_options o = options();
  o.speed_down = 0.01;
  o.speed_up = 0.0001;
  o.travel_feed = 1;
  snprintf(path, sizeof path, "%s/slow.gcode", dir);
  cr_assert_eq(lw_output_gcode_strokes(s, &page, &o, path, NULL), LW_OK);
  text = lw_test_slurp("%s", path);
  cr_assert(strstr(text, "\nG94 F0.6\n") && strstr(text, " F0.006\n") && !strstr(text, " F0\n"), "%s", text);
  free(text);
  lw_strokes_free(s);
  lw_test_sh("rm -rf %s", dir);
}

/* Pens that draw nothing (a grey picture's cyan, magenta and yellow) are
** not asked for: no load, no pause, no SP; each pen that draws is changed
** at the origin, where its tour starts. */
Test(plotter, pens_without_paths_are_not_asked_for)
{
  char dir[64], path[128];
  cr_assert_eq(lw_test_dir_make(dir, "plotter"), 0);
  lw_strokes *s = lw_strokes_new(4, NULL);
  double line[8] = {10, 10, 20, 10, 30, 10, 40, 10};
  cr_assert_eq(lw_strokes_add(s, 1, 0, 0, 0, line, 1, NULL), LW_OK);
  cr_assert_eq(lw_strokes_add(s, 3, 1, 0, 0, line, 1, NULL), LW_OK);
  lw_output_page page;
  lw_output_page_init(&page, PAGE_W, PAGE_H);
  page.n_pens = 4;
  for (int k = 1; k < 4; k++) page.pen[k] = page.pen[0];
  lw_plotter_options o = options();
  o.speed_up = 150;
  snprintf(path, sizeof path, "%s/final.gcode", dir);
  cr_assert_eq(lw_output_gcode_strokes(s, &page, &o, path, NULL), LW_OK);
  char *text = lw_test_slurp("%s", path);
  cr_assert(strstr(text, "; load pen 2 (") && strstr(text, "before starting\n") && strstr(text, "; load pen 4 (") &&
                !strstr(text, "pen 1 (") && !strstr(text, "pen 3 ("),
            "%s", text);
  size_t pauses = 0;
  for (const char *c = text; (c = strstr(c, "\nM0\n")); c++) pauses++;
  cr_assert_eq(pauses, 1, "%s", text);
  cr_assert(strstr(text, "G0 X0 Y0\n; load pen 4"), "home before the change: %s", text);
  free(text);
  snprintf(path, sizeof path, "%s/final.hpgl", dir);
  cr_assert_eq(lw_output_hpgl_strokes(s, &page, &o, path, NULL), LW_OK);
  text = lw_test_slurp("%s", path);
  cr_assert(strstr(text, "\nSP2;\n") && strstr(text, "PU0,0;SP4;\n") && !strstr(text, "SP1") && !strstr(text, "SP3"),
            "%s", text);
  free(text);
  lw_strokes_free(s);
  /* an empty drawing asks for no pen at all (it asked for pen 1) */
  s = lw_strokes_new(4, NULL);
  snprintf(path, sizeof path, "%s/final.gcode", dir);
  cr_assert_eq(lw_output_gcode_strokes(s, &page, &o, path, NULL), LW_OK);
  text = lw_test_slurp("%s", path);
  cr_assert(!strstr(text, "load") && !strstr(text, "\nM0\n") && strstr(text, "; an empty drawing: no pen is asked "
            "for\nG21\n"), "%s", text);
  free(text);
  lw_strokes_free(s);
  lw_test_sh("rm -rf %s", dir);
}

/* A path that rounds to one point of HP-GL's 0.025 mm is a dot, PD at the
** point the pen was lifted to (docs/FORMATS.md): without it such a path
** drew nothing, and a mutation that left it out passed. */
Test(plotter, a_path_that_rounds_to_one_point_is_a_dot)
{
  char dir[64], path[128];
  cr_assert_eq(lw_test_dir_make(dir, "plotter"), 0);
  lw_strokes *s = lw_strokes_new(1, NULL);
  double dot[8] = {10, 10, 10.003, 10, 10.006, 10, 10.009, 10}, line[8] = {20, 10, 25, 10, 30, 10, 35, 10};
  cr_assert_eq(lw_strokes_add(s, 0, 0, 0, 0, dot, 1, NULL), LW_OK);
  cr_assert_eq(lw_strokes_add(s, 0, 0, 0, 0, line, 1, NULL), LW_OK);
  lw_output_page page;
  lw_output_page_init(&page, PAGE_W, PAGE_H);
  lw_plotter_options o = options();
  snprintf(path, sizeof path, "%s/final.hpgl", dir);
  cr_assert_eq(lw_output_hpgl_strokes(s, &page, &o, path, NULL), LW_OK);
  char *text = lw_test_slurp("%s", path);
  const char *dotted = strstr(text, "PU400,");
  cr_assert(dotted && !strncmp(strchr(dotted, ';'), ";\nPD;\n", 6), "%s", text);
  free(text);
  lw_strokes_free(s);
  lw_test_sh("rm -rf %s", dir);
}

Test(plotter, bad_options_leave_the_old_file)
{
  char dir[64], path[128];
  cr_assert_eq(lw_test_dir_make(dir, "plotter"), 0);
  snprintf(path, sizeof path, "%s/final.gcode", dir);
  cr_assert_eq(lw_test_write_text(dir, "final.gcode", "old\n"), 0);
  lw_strokes *s = drawing();
  lw_output_page page = page_of();
  lw_plotter_options bad[4] = {options(), options(), options(), options()};
  bad[0].tolerance = 0;
  bad[1].speed_down = NAN;
  bad[2].pen_up = "G0 Z5\nM2";
  bad[3].pen_down = "";
  for (int k = 0; k < 4; k++) {
    lw_error err = {0};
    cr_assert_eq(lw_output_gcode_strokes(s, &page, &bad[k], path, &err), LW_EINPUT, "case %d", k);
    cr_assert(strstr(err.msg, path), "case %d: %s", k, err.msg);
    char *text = lw_test_slurp("%s", path);
    cr_assert_str_eq(text, "old\n");
    free(text);
    cr_assert_neq(lw_test_sh("test -e %s.tmp", path), 0, "no temporary file left");
  }
  page.height_mm = -1;
  cr_assert_eq(lw_output_hpgl_strokes(s, &page, &bad[3], path, NULL), LW_EINPUT);
  lw_strokes_free(s);
  lw_test_sh("rm -rf %s", dir);
}

Test(plotter, command_line_writes_the_same_files_for_the_same_seed)
{
  const char *bin = lw_test_bin(), *root = lw_test_root();
  char dir[64];
  cr_assert_eq(lw_test_dir_make(dir, "plotter"), 0);
  const char *set = "--set output.hpgl=1 --set output.gcode=1 --set output.pens=2 --set anneal.sweeps=30";
  for (int r = 0; r < 2; r++)
    cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini %s --quiet --out %s/r%d", bin, root, set, dir, r), 0);
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set anneal.sweeps=30 --set output.pens=2 --quiet "
                          "--out %s/plain", bin, root, dir), 0);
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini %s --set plot.turn=90 --quiet --out %s/turned", bin, root, set,
                          dir), 0);
  cr_assert_eq(lw_test_sh("cmp -s %s/r0/final.hpgl %s/r1/final.hpgl && cmp -s %s/r0/final.gcode %s/r1/final.gcode",
                          dir, dir, dir, dir), 0);
  /* the paths are ordered from the machine's origin: the page's lower-left
  ** corner, or with the page turned its top-left one, an SVG plotter's */
  cr_assert_eq(lw_test_sh("cmp -s %s/turned/final.svg %s/plain/final.svg && test ! -e %s/plain/final.gcode", dir, dir,
                          dir), 0, "the machine files change nothing but where the order starts");
  cr_assert_eq(lw_test_sh("grep -c '<path' %s/r0/final.svg > %s/n0 && grep -c '<path' %s/plain/final.svg > %s/n1 && "
                          "cmp -s %s/n0 %s/n1", dir, dir, dir, dir, dir, dir), 0, "the same paths");
  /* one pen-down a path of final.svg, one SP a pen */
  char *svg = lw_test_slurp("%s/r0/final.svg", dir), *gcode = lw_test_slurp("%s/r0/final.gcode", dir),
       *hpgl = lw_test_slurp("%s/r0/final.hpgl", dir);
  size_t paths = 0, downs = 0, sp = 0, pu = 0;
  for (const char *c = svg; (c = strstr(c, "<path")); c++) paths++;
  for (const char *c = gcode; (c = strstr(c, "\nG1 Z0 F500\n")); c++) downs++;
  for (const char *c = hpgl; (c = strstr(c, "SP")); c++) sp++;
  for (const char *c = hpgl; (c = strstr(c, "PU")); c++) pu += c[2] != ';' && strncmp(c, "PU0,0;SP", 8);
  cr_assert(paths > 5);
  cr_assert_eq(downs, paths);
  cr_assert_eq(pu, paths);
  cr_assert_eq(sp, 3, "SP1, SP2, SP0");
  free(svg);
  free(gcode);
  free(hpgl);
  /* redrawn from its state without sweeps, the run draws the same */
  cr_assert_eq(lw_test_sh("%s run %s/r0/scene.ini --set init.from=%s/r0/state.lw --set anneal.sweeps=0 --quiet "
                          "--out %s/redraw && cmp -s %s/r0/final.svg %s/redraw/final.svg && "
                          "cmp -s %s/r0/final.hpgl %s/redraw/final.hpgl",
                          bin, dir, dir, dir, dir, dir, dir, dir), 0);
  /* an empty pen line is refused, naming the key */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set output.gcode=1 --set plot.gcode_pen_up= --quiet "
                          "--out %s/bad 2>%s/err.txt", bin, root, dir, dir), 2);
  char *errs = lw_test_slurp("%s/err.txt", dir);
  cr_assert(strstr(errs, "key 'plot.gcode_pen_up'") && strstr(errs, "expected one line of printable ASCII"), "%s",
            errs);
  free(errs);
  cr_assert_neq(lw_test_sh("test -e %s/bad", dir), 0, "nothing written");
  /* so is one past GRBL's 79 characters, a speed whose feed would be F0
  ** (drawing, or travelling at feed), and a pen line that moves across the
  ** page or is a GRBL system command (a shared scene's, run at every
  ** stroke: G0 X-900 Y-900 drove the head off the bed unseen, $RST=* reset
  ** the machine's settings); a Z move, a servo's S, a dwell's P and an X in
  ** a comment, ( ) or after a ';', are pen lines */
  static const char *const bad[][2] = {
    {"'plot.gcode_pen_down=M3 S90 G4 P0.2 %0*d'", "key 'plot.gcode_pen_down'"},
    {"plot.speed_down=0.0000083", "key 'plot.speed_down' = 8.3e-06 mm/s: final.gcode's feed"},
    {"plot.speed_up=0.000001 --set plot.gcode_travel=feed", "key 'plot.speed_up' = 1e-06 mm/s"},
    {"'plot.gcode_pen_down=G0 X-900 Y-900'", "key 'plot.gcode_pen_down' = 'G0 X-900 Y-900': a move across the page "
                                              "(an X or Y word), which the bed check and the plot time do not see"},
    {"'plot.gcode_pen_up=G1 Z5 y .5'", "key 'plot.gcode_pen_up' = 'G1 Z5 y .5': a move across the page"},
    {"'plot.gcode_pen_up=$RST=*'", "key 'plot.gcode_pen_up' = '$RST=*': a GRBL system command ($)"},
    /* a comment ends at its first ')' (counted as nesting, the move after
    ** it went through); homing, relative moves and offsets */
    {"'plot.gcode_pen_up=G0 Z5 (( ) X-900 Y-900 )'", "key 'plot.gcode_pen_up' = 'G0 Z5 (( ) X-900 Y-900 )': a move"},
    {"'plot.gcode_pen_up=G28'", "key 'plot.gcode_pen_up' = 'G28': G28, G30, G91 or G92, which move across the page"},
    {"'plot.gcode_pen_down=G91 G1 Z-5'", "key 'plot.gcode_pen_down' = 'G91 G1 Z-5': G28, G30, G91 or G92"},
    /* a program's end or stop (the plot ended at its first lift) */
    {"plot.gcode_pen_up=M30", "key 'plot.gcode_pen_up' = 'M30': a program stop or end (M0, M1, M2, M30 or M60)"},
    {"'plot.gcode_pen_up=G0 Z5 M2'", "key 'plot.gcode_pen_up' = 'G0 Z5 M2': a program stop or end"},
    {"'plot.gcode_pen_down=M00'", "key 'plot.gcode_pen_down' = 'M00': a program stop or end"},
    {"'plot.gcode_pen_up=M1 (optional stop)'", "= 'M1 (optional stop)': a program stop or end"},
    {"'plot.gcode_pen_up=M60 P1'", "= 'M60 P1': a program stop or end"},
    {"'plot.gcode_pen_up=G0 Z5 m30'", "= 'G0 Z5 m30': a program stop or end"},
  };
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set output.gcode=1 --set anneal.sweeps=0 --quiet --out "
                          "%s/servo --set 'plot.gcode_pen_down=M3 S90 G4 P0.2 (X axis: 0)' --set "
                          "'plot.gcode_pen_up=G0 Z5 (lift $5)'", bin, root, dir), 0);
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set output.gcode=1 --set anneal.sweeps=0 --quiet --out "
                          "%s/servo2 --set 'plot.gcode_pen_up=M5;lift X0 $'", bin, root, dir), 0, "a ; comment");
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set output.gcode=1 --set anneal.sweeps=0 --quiet --out "
                          "%s/servo3 --set 'plot.gcode_pen_up=M3S30 G4 P.25' --set 'plot.gcode_pen_down=G1 Z-1. F+300'",
                          bin, root, dir), 0, "words run together, a number's sign, a point at either end");
  /* Klipper's macros and LinuxCNC's parameters (refused for a day, as
  ** letters without numbers) */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set output.gcode=1 --set anneal.sweeps=0 --quiet --out "
                          "%s/servo4 --set 'plot.gcode_pen_up=SET_SERVO SERVO=pen ANGLE=90' --set "
                          "'plot.gcode_pen_down=G0 Z#1'", bin, root, dir), 0, "Klipper, LinuxCNC");
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    char keys[160];
    snprintf(keys, sizeof keys, bad[k][0], 70, 0);
    cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set output.gcode=1 --set %s --quiet --out %s/bad "
                            "2>%s/err.txt", bin, root, keys, dir, dir), 2, "%s", keys);
    errs = lw_test_slurp("%s/err.txt", dir);
    cr_assert(strstr(errs, bad[k][1]), "%s", errs);
    free(errs);
  }
  /* a feed rounded by more than 1 % is said, as HP-GL's VS */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set output.gcode=1 --set plot.speed_down=0.00001 "
                          "--set anneal.sweeps=0 --out %s/slow 2>%s/err.txt", bin, root, dir, dir), 0);
  errs = lw_test_slurp("%s/err.txt", dir);
  cr_assert(strstr(errs, "note: plot.speed_down = 1e-05 mm/s is F0.001 in final.gcode (mm/min to the thousandth), "
                    "67 % off"), "%s", errs);
  free(errs);
  /* travelling by rapids, no feed is written of speed_up */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set output.gcode=1 --set plot.speed_up=0.000001 --quiet "
                          "--set anneal.sweeps=0 --out %s/rapid", bin, root, dir), 0);
  lw_test_sh("rm -rf %s", dir);
}

Test(plotter, a_drawing_past_the_bed_is_refused_and_travel_can_feed)
{
  char dir[64], path[128];
  cr_assert_eq(lw_test_dir_make(dir, "plotter"), 0);
  snprintf(path, sizeof path, "%s/final.gcode", dir);
  lw_strokes *s = drawing();
  lw_output_page page = page_of();
  lw_plotter_options o = options();
  /* the page itself is a bed the drawing fits; a bed 1 mm narrower than
  ** the drawing's reach refuses both files and keeps the old one */
  o.bed[0] = PAGE_W, o.bed[1] = PAGE_H;
  cr_assert_eq(lw_output_gcode_strokes(s, &page, &o, path, NULL), LW_OK);
  double reach = 0; /* the segments' ends lie on the drawing */
  for (size_t k = 0; k < s->n_segs; k++) reach = fmax(reach, fmax(s->b[8 * k], s->b[8 * k + 6]));
  cr_assert_eq(lw_test_write_text(dir, "final.gcode", "old\n"), 0);
  for (int hpgl = 0; hpgl < 2; hpgl++) {
    lw_error err = {0};
    o.bed[0] = reach - 1;
    lw_status st = hpgl ? lw_output_hpgl_strokes(s, &page, &o, path, &err)
                        : lw_output_gcode_strokes(s, &page, &o, path, &err);
    cr_assert_eq(st, LW_EINPUT);
    cr_assert(strstr(err.msg, "the drawing reaches x = ") && strstr(err.msg, "(plot.bed_width)"), "%s", err.msg);
    char *text = lw_test_slurp("%s", path);
    cr_assert_str_eq(text, "old\n");
    free(text);
  }
  /* the other turn is offered only where the drawing fits the bed with it:
  ** turned, it reaches 78 mm along x and 91 mm along y */
  for (int k = 0; k < 2; k++) {
    lw_error err = {0};
    o.bed[0] = 90, o.bed[1] = k ? 90 : 100;
    cr_assert_eq(lw_plotter_check(s, &page, &o, 1, path, &err), LW_EINPUT);
    cr_assert(strstr(err.msg, "the drawing reaches x = 5.000 to 91.000 mm"), "%s", err.msg);
    cr_assert_eq(!strstr(err.msg, "or the other turn (plot.turn = 90)"), k, "%s", err.msg);
  }
  o.turn = 1, o.bed[0] = 90, o.bed[1] = 100;
  cr_assert_eq(lw_plotter_check(s, &page, &o, 1, path, NULL), LW_OK);
  o.turn = 0;
  /* a point 0.01 mm past the bed: on it within HP-GL's half unit (0.0125
  ** mm, where it rounds onto the edge), past it in G-code, whose three
  ** decimals keep it past (GRBL's soft limit) */
  o.bed[0] = 91.0 - 0.01, o.bed[1] = 200;
  cr_assert_eq(lw_plotter_check(s, &page, &o, 0, path, NULL), LW_OK);
  cr_assert_eq(lw_plotter_check(s, &page, &o, 1, path, NULL), LW_EINPUT);
  o.bed[0] = 91.0 - 0.0004;
  cr_assert_eq(lw_plotter_check(s, &page, &o, 1, path, NULL), LW_OK);
  /* a drawing left of the machine's origin is past the origin, not the
  ** bed's width, which it fits (it was blamed on plot.bed_width) */
  for (size_t k = 0; k < s->n_segs; k++)
    for (int c = 0; c < 8; c += 2) s->b[8 * k + (size_t)c] -= 8.0;
  {
    lw_error err = {0};
    o.bed[0] = 200, o.bed[1] = 200;
    cr_assert_eq(lw_plotter_check(s, &page, &o, 1, path, &err), LW_EINPUT);
    cr_assert(strstr(err.msg, "the drawing reaches x = -3.000 to 83.000 mm on the machine, past its origin (x below "
                              "0): expected plot.crop = 1"), "%s", err.msg);
    /* past on both axes: both said (the second was refused once the first
    ** was mended) */
    o.bed[1] = 50;
    cr_assert_eq(lw_plotter_check(s, &page, &o, 1, path, &err), LW_EINPUT);
    cr_assert(strstr(err.msg, "past its origin (x below 0), and y = ") &&
                  strstr(err.msg, "mm on the machine, past its bed of 50 mm (plot.bed_height): expected plot.crop = 1"),
              "%s", err.msg);
  }
  for (size_t k = 0; k < s->n_segs; k++)
    for (int c = 0; c < 8; c += 2) s->b[8 * k + (size_t)c] += 8.0;
  /* a point past the files' reach: its coordinate and the limit in full
  ** (%g wrote "lies 1e+08 mm ...: expected at most 1e+08") */
  {
    lw_error err = {0};
    o.bed[0] = o.bed[1] = 0;
    const double kept = s->b[5];
    s->b[5] = -100000020.0;
    cr_assert_eq(lw_plotter_check(s, &page, &o, 0, path, &err), LW_EINPUT);
    cr_assert(strstr(err.msg, ": a stroke reaches y = -100000020 mm: expected coordinates within 100000000 mm of the "
                              "page's corner; plot.crop = 1 cuts"), "%s", err.msg);
    s->b[5] = kept;
  }
  /* travel by feed: each path's start and the way home are G1 at speed_up
  ** (150 mm/s: F9000), each path's first drawing move sets speed_down again */
  o.bed[0] = o.bed[1] = 0;
  o.travel_feed = 1;
  o.speed_up = 150;
  cr_assert_eq(lw_output_gcode_strokes(s, &page, &o, path, NULL), LW_OK);
  char *text = lw_test_slurp("%s", path);
  size_t travels = 0, resets = 0, rapids = 0;
  for (const char *l = text; *l; l = strchr(l, '\n') + 1) {
    travels += !strncmp(l, "G1 X", 4) && strstr(l, " F9000\n") == strchr(l, '\n') - 6;
    resets += !strncmp(l, "G1 X", 4) && strstr(l, " F3000\n") == strchr(l, '\n') - 6;
    rapids += !strncmp(l, "G0 X", 4);
  }
  cr_assert_eq(travels, s->n + 1 + (size_t)(s->n_pens - 1), "a travel a path, home, and home at each change: %s",
               text);
  cr_assert_eq(resets, s->n, "%s", text);
  cr_assert_eq(rapids, 0);
  free(text);
  o.speed_up = 0;
  cr_assert_eq(lw_output_gcode_strokes(s, &page, &o, path, NULL), LW_EINPUT);
  lw_strokes_free(s);
  lw_test_sh("rm -rf %s", dir);
}

Test(plotter, a_page_past_the_bed_is_refused_before_the_run)
{
  /* params/minimal.ini: a 100 mm square page, margin 5, so the drawing
  ** area reaches 95 mm on both axes */
  const char *bin = lw_test_bin(), *root = lw_test_root();
  char dir[64];
  cr_assert_eq(lw_test_dir_make(dir, "plotter"), 0);
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set output.gcode=1 --set plot.bed_width=94.9 --quiet "
                          "--out %s/r 2> %s/err.txt", bin, root, dir, dir), 2);
  char *err = lw_test_slurp("%s/err.txt", dir);
  cr_assert(strstr(err, "--set: key 'plot.bed_width' = 94.9 mm: the drawing area (the 100 x 100 mm page inset by "
                        "scene.margin = 5) reaches x = 95 mm on the machine; expected a wider margin or a smaller page\n"),
            "%s", err);
  free(err);
  cr_assert_neq(lw_test_sh("test -e %s/r", dir), 0, "nothing written");
  /* with a picture the crop is its rectangle: params/picture.png (600 x 800)
  ** in the 90 mm square spans x 16.25 to 83.75 (the page's inset refused a
  ** landscape photo on A4 that fitted the bed by 45 mm) */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set scene.image=%s/params/picture.png --set output.gcode=1 "
                          "--set plot.bed_width=85 --stop-at 0 --quiet --out %s/p", bin, root, root, dir), 0);
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set scene.image=%s/params/picture.png --set output.gcode=1 "
                          "--set plot.bed_width=80 --stop-at 0 --quiet --out %s/q 2> %s/err.txt", bin, root, root, dir,
                          dir), 2);
  err = lw_test_slurp("%s/err.txt", dir);
  cr_assert(strstr(err, "key 'plot.bed_width' = 80 mm: the drawing area (the picture's 67.5 x 90 mm rectangle from "
                        "(16.25, 5) mm, to which plot.crop cuts the strokes) reaches x = 83.75 mm on the machine"), "%s",
            err);
  free(err);
  /* uncropped, the strokes may reach the margins */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set scene.image=%s/params/picture.png --set output.gcode=1 "
                          "--set plot.bed_width=85 --set plot.crop=0 --stop-at 0 --quiet --out %s/q 2> %s/err.txt",
                          bin, root, root, dir, dir), 2);
  /* the bed's own size fits; without a machine file the bed is not asked */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set output.hpgl=1 --set plot.bed_height=95 --set "
                          "anneal.sweeps=5 --quiet --out %s/r", bin, root, dir), 0);
  cr_assert_eq(lw_test_sh("test -s %s/r/final.hpgl", dir), 0);
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set plot.bed_width=10 --set anneal.sweeps=5 --quiet "
                          "--out %s/s", bin, root, dir), 0);
  /* a pen speed HP-GL cannot ask is said before the run (VS was limited without a word) */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set output.hpgl=1 --set plot.speed_down=2000 --stop-at 0 "
                          "--out %s/v 2>&1 | grep -q 'note: plot.speed_down = 2000 mm/s is past what HP-GL.s VS takes "
                          "(0.1 to 1279.9 mm/s, in steps of 0.1): final.hpgl asks 1279.9 (VS127.99, in cm/s), and the "
                          "plot time, reckoned at 2000, does not hold'", bin, root, dir), 0);
  /* and one its two decimals round by more than 1 % (1.234 mm/s was 1.2) */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set output.hpgl=1 --set plot.speed_down=1.234 --stop-at 0 "
                          "--out %s/v 2>&1 | grep -q 'note: plot.speed_down = 1.234 mm/s is more than 1 %% from what "
                          "HP-GL.s VS writes (0.1 to 1279.9 mm/s, in steps of 0.1): final.hpgl asks 1.2 (VS0.12, in "
                          "cm/s),'", bin, root, dir), 0);
  cr_assert_neq(lw_test_sh("%s run %s/params/minimal.ini --set output.hpgl=1 --set plot.speed_down=12.3456 --stop-at 0 "
                           "--out %s/v 2>&1 | grep -q 'HP-GL.s VS'", bin, root, dir), 0, "0.4 %% off: no note");
  /* a drawing that leaves the bed only after the anneal (no crop, no
  ** boundary term, hot) is refused before any drawing file is written, with
  ** exit 1 (the run went well), the state kept for a redraw */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set output.gcode=1 --set plot.bed_width=100 --set "
                          "plot.crop=0 --set energy.boundary=0 --set scene.margin=0 --set anneal.t_start=5 --set "
                          "anneal.t_end=1 --set anneal.sweeps=100 --quiet --out %s/t 2> %s/err.txt", bin, root, dir,
                          dir), 1);
  err = lw_test_slurp("%s/err.txt", dir);
  cr_assert(strstr(err, "t/final.gcode: the drawing reaches x = ") &&
            strstr(err, "no drawing was written, and the annealed state is in "), "%s", err);
  free(err);
  cr_assert_eq(lw_test_sh("cd %s/t && test -s state.lw && ! ls final.* 2>/dev/null", dir), 0);
  /* a resumed run whose end is refused so keeps the files of its earlier
  ** end, and says they are not of this state (a plotter was sent them) */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set output.gcode=1 --set energy.boundary=0 --set "
                          "scene.margin=0 --set anneal.t_start=5 --set anneal.t_end=1 --set anneal.sweeps=100 --quiet "
                          "--out %s/u && sed -i 's/^bed_width = .*/bed_width = 100/; s/^crop = .*/crop = 0/' "
                          "%s/u/scene.ini && %s resume %s/u --sweeps 5 --quiet 2> %s/err.txt", bin, root, dir, dir,
                          bin, dir, dir), 1);
  err = lw_test_slurp("%s/err.txt", dir);
  cr_assert(strstr(err, "no drawing was written (the final files there are of the run's earlier end, not of this "
                        "state), and the annealed state is in "), "%s", err);
  free(err);
  cr_assert_eq(lw_test_sh("test -s %s/u/final.gcode", dir), 0, "nothing already written is lost");
  /* a page past HP-GL/1's 32,767 units without a bed is said before the run */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set scene.width=900 --set scene.height=300 --set "
                          "output.hpgl=1 --stop-at 0 --out %s/w 2>&1 | grep -q 'note: the page is 900 mm on its long "
                          "side, past the 819.175 mm (32767 units) HP-GL/1 coordinates reach'", bin, root, dir), 0);
  lw_test_sh("rm -rf %s", dir);
}
