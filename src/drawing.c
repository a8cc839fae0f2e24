/* drawing.c -- a run's drawing files from its parameters (drawing.h). */
#include "linewise/drawing.h"

#include <errno.h>
#include <gsl/gsl_math.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "linewise/plotter.h"
#include "linewise/spacing.h"
#include "linewise/state.h"

/* The page and pens of p: size from [scene], pens from [output].  Errors
** name the parameter's origin. */
static lw_status drawing_page(const lw_params *p, lw_output_page *page, lw_error *err)
{
  lw_output_page_init(page, p->width, p->height);
  page->n_pens = p->pens;
  unsigned char rgb[LW_PLOT_PENS_MAX][3] = {{0}};
  if (p->pen_colors[0] && lw_output_colors_parse(p->pen_colors, rgb, LW_PLOT_PENS_MAX) != p->pens) {
    char where[LW_PATH_MAX + 32];
    lw_params_origin(p, lw_params_find("output", "pen_colors"), where, sizeof where);
    return lw_error_set(err, LW_EINPUT, "%s: key 'output.pen_colors': expected %d colour%s, got '%s'", where,
                        p->pens, p->pens == 1 ? "" : "s", p->pen_colors);
  }
  for (int k = 0; k < p->pens; k++) {
    page->pen[k].width_mm = p->pen_width;
    memcpy(page->pen[k].rgb, rgb[k], 3);
  }
  lw_layers_spec ls;
  lw_status s = lw_layers_read(p, &ls, err);
  if (s || !ls.n) return s;
  /* a pen a layer, and inks that darken what they cross, as on paper */
  page->n_pens = ls.n;
  page->multiply = 1;
  for (int k = 0; k < ls.n; k++) {
    page->pen[k].width_mm = ls.spec[k].pen_width;
    memcpy(page->pen[k].rgb, ls.spec[k].rgb, 3);
    memcpy(page->pen_name[k], ls.spec[k].name, sizeof page->pen_name[k]);
  }
  return LW_OK;
}

static double potential_at(const void *ctx, double x, double y) { return lw_potential_eval(ctx, x, y); }

static double tone_at(const void *ctx, double x, double y)
{
  double v;
  lw_grid2d_eval(ctx, x, y, &v);
  return v;
}

/* Which pen draws each spline, in index order: the final drawing's
** post-pass (strokes.h) orders the paths it makes, and frames are not
** ordered. */
static lw_plot *make_plot(const lw_params *p, const lw_scene *sc, const lw_splines *sp, const lw_grid2d *tone,
                          lw_error *err)
{
  double *key = NULL;
  if (sc->layers.n) { /* layer k is pen k + 1 */
    int *pen = malloc((sp->n_splines ? sp->n_splines : 1) * sizeof *pen);
    if (!pen) {
      lw_error_set(err, LW_ENOMEM, "out of memory for the pens of %zu splines", sp->n_splines);
      return NULL;
    }
    for (size_t i = 0; i < sp->n_splines; i++) pen[i] = lw_splines_layer(&sc->layers, sp, i);
    lw_plot *pl = lw_plot_new_pens(sp, sc->layers.n, pen, LW_PLOT_ORDER_NONE, 0.0, 0.0, err);
    free(pen);
    return pl;
  }
  if (p->pens > 1 && (sc->on[LW_TERM_POTENTIAL] || tone)) {
    key = malloc((sp->n_splines ? sp->n_splines : 1) * sizeof *key);
    if (!key) {
      lw_error_set(err, LW_ENOMEM, "out of memory ranking %zu splines", sp->n_splines);
      return NULL;
    }
    /* the picture's tone where there is one: the photo preset's potential is
    ** tone^8, about 0 wherever the tone is under 0.5, so its ranking put half
    ** the strokes of a black area in the lightest pen */
    if (tone) lw_plot_mean_along(sp, &sc->quad, tone_at, tone, key);
    else lw_plot_mean_along(sp, &sc->quad, potential_at, &sc->potential, key);
  }
  lw_plot *pl = lw_plot_new(sp, p->pens, key, LW_PLOT_ORDER_NONE, 0.0, 0.0, err);
  free(key);
  return pl;
}

/* Paths of st that reach past the page [0, w] x [0, h], each segment taken
** at 9 points: with plot.crop = 0 they were kept without a word, and a
** plotter travelled off the paper. */
static size_t paths_off_page(const lw_strokes *st, double w, double h)
{
  size_t off = 0;
  for (size_t k = 0; k < st->n; k++) {
    int out = 0;
    for (size_t s = st->first[k]; s < st->first[k + 1] && !out; s++) {
      const double *b = st->b + 8 * s;
      for (int i = 0; i <= 8 && !out; i++) {
        double t = i / 8.0, u = 1.0 - t, c0 = u * u * u, c1 = 3 * u * u * t, c2 = 3 * u * t * t, c3 = t * t * t;
        double x = c0 * b[0] + c1 * b[2] + c2 * b[4] + c3 * b[6], y = c0 * b[1] + c1 * b[3] + c2 * b[5] + c3 * b[7];
        out = x < 0.0 || x > w || y < 0.0 || y > h;
      }
    }
    off += (size_t)out;
  }
  return off;
}

/* The post-pass options of p and sc (the crop rectangle from the picture);
** the gaps joined and the paths dropped in widths of each pen's own. */
static void options(const lw_params *p, const lw_scene *sc, const lw_output_page *page, lw_strokes_options *o)
{
  memset(o, 0, sizeof *o);
  for (int k = 0; k < page->n_pens; k++) {
    o->join_dist[k] = p->join_distance * page->pen[k].width_mm;
    o->min_length[k] = p->min_length * page->pen[k].width_mm;
  }
  o->join_angle = p->join_angle * M_PI / 180.0;
  /* the pen starts where the machine's origin is: a machine file's, the
  ** page's lower-left corner unless the page is turned; else the page's
  ** top-left corner, where an SVG plotter (AxiDraw) starts */
  if ((p->gcode || p->hpgl) && !p->plot_turn) o->home_y = page->height_mm;
  o->home_back = p->gcode || p->hpgl; /* both files end at home */
  o->order = (lw_plot_order)p->order;
  o->crop = p->crop;
  if (sc->image) {
    const lw_image_place *pl = &sc->image_place;
    o->x0 = pl->x0;
    o->y0 = pl->y0;
    o->x1 = pl->x0 + sc->image->width * pl->pixel;
    o->y1 = pl->y0 + sc->image->height * pl->pixel;
  } else {
    o->x0 = p->margin;
    o->y0 = p->margin;
    o->x1 = p->width - p->margin;
    o->y1 = p->height - p->margin;
  }
}

/* A copy of tone with paper (1) where the frame forbids lines: a mask's
** sea, a circle's corners (a cartographer's map, its sea empty as the mask
** asks, scored SSIM 0.25 for the ink it had no leave to draw, 0.94 against
** the same picture with the sea transparent).  NULL where the frame is the
** page's rectangle (nothing of the picture lies outside it), where it
** forbids nothing (energy.boundary = 0: lines may leave it) or memory fails. */
static lw_grid2d *paper_outside(const lw_params *p, const lw_scene *sc, const lw_grid2d *tone, lw_error *err)
{
  if (p->boundary == LW_BND_RECT || p->boundary_coef == 0.0) return NULL;
  lw_grid2d *g = lw_grid2d_new(tone->nx, tone->ny, 1, tone->x0, tone->y0, tone->hx, tone->hy, err);
  if (!g) return NULL;
  for (int j = 0; j < tone->ny; j++)
    for (int i = 0; i < tone->nx; i++) {
      const size_t at = (size_t)j * (size_t)tone->nx + (size_t)i;
      g->data[at] = lw_boundary_inside(&sc->boundary, tone->x0 + i * tone->hx, tone->y0 + j * tone->hy)
                    ? tone->data[at] : 1.0;
    }
  return g;
}

/* The fidelity scores of the drawing, overall and per pen, against the
** reference picture if there is one, else the target tone (paper where the
** frame forbids lines); a layer's pen against the layer's own target, drawn
** with its own width. */
static lw_status score(const lw_params *p, const lw_scene *sc, const lw_strokes *st, const lw_grid2d *tone,
                       lw_drawing_report *rep, lw_error *err)
{
  lw_grid2d *ref = NULL;
  lw_status s = LW_OK;
  if (sc->reference && !(ref = lw_image_tone_grid(sc->reference, &sc->reference_place, err)))
    s = err ? err->code : LW_ENOMEM;
  if (ref) {
    tone = ref;
    snprintf(rep->reference, sizeof rep->reference, "%s", p->fidelity_reference);
  } else if (tone && p->boundary != LW_BND_RECT && p->boundary_coef != 0.0) {
    if (!(ref = paper_outside(p, sc, tone, err))) s = err ? err->code : LW_ENOMEM;
    else tone = ref;
  }
  if (!s)
    s = lw_fidelity_compute_strokes(st, -1, tone, p->tone_ink, p->pen_width, p->fidelity_sigma, &rep->fidelity, err);
  for (int k = 0; !s && st->n_pens > 1 && k < st->n_pens; k++) {
    const lw_image *target = k < sc->layers.n ? sc->layer[k].target : NULL;
    if (!target) {
      s = lw_fidelity_compute_strokes(st, k, tone, p->tone_ink, p->pen_width, p->fidelity_sigma,
                                      &rep->pen_fidelity[k], err);
      continue;
    }
    lw_grid2d *g = lw_image_tone_grid(target, &sc->image_place, err), *in = g ? paper_outside(p, sc, g, err) : NULL;
    if (in) {
      lw_grid2d_free(g);
      g = in;
    }
    if (!g || (!in && p->boundary != LW_BND_RECT && p->boundary_coef != 0.0)) {
      lw_grid2d_free(g);
      s = err ? err->code : LW_ENOMEM;
      break;
    }
    s = lw_fidelity_compute_strokes(st, k, g, p->tone_ink, sc->layers.spec[k].pen_width, p->fidelity_sigma,
                                    &rep->pen_fidelity[k], err);
    lw_grid2d_free(g);
  }
  lw_grid2d_free(ref);
  rep->has_fidelity = !s;
  for (int k = 0; k < LW_PLOT_PENS_MAX; k++)
    rep->pen_width[k] = k < sc->layers.n ? sc->layers.spec[k].pen_width : p->pen_width;
  rep->pen_targets = sc->layers.n;
  /* (as scene.c's note of a strip narrower than two segments) */
  rep->picture_thin = sc->image && fmin(sc->image->width, sc->image->height) * sc->image_place.pixel <
                                       2.0 * p->segment_length;
  rep->frame_not_rect = p->boundary != LW_BND_RECT;
  /* as the close share below: a score of the finished drawing, which its
  ** want of memory must not fail (the run annealed, drew final.svg, then
  ** ended with exit 1 and no summary.json); summary.json's fidelity is null */
  if (s == LW_ENOMEM) {
    rep->fidelity_lost = 1;
    lw_error_clear(err);
    s = LW_OK;
  }
  return s;
}

/* The close share of the paths as plotted, each path a stroke (spacing.h);
** with layers.apart = pen, of each pen's paths among themselves. */
static lw_status close_share(const lw_params *p, const lw_scene *sc, const lw_strokes *st, lw_drawing_report *rep,
                             lw_error *err)
{
  const size_t n = st->n_segs ? st->n_segs : 1;
  const int by_pen = lw_layers_planes(&sc->layers) > 1;
  size_t *owner = malloc(n * sizeof *owner), *pen = by_pen ? malloc(n * sizeof *pen) : NULL;
  if (!owner || (by_pen && !pen)) {
    free(owner);
    free(pen);
    rep->close_share = NAN;
    return LW_OK;
  }
  for (int q = 0; q < st->n_pens; q++)
    for (size_t k = st->pen_first[q]; k < st->pen_first[q + 1]; k++)
      for (size_t g = st->first[k]; g < st->first[k + 1]; g++) {
        owner[g] = k;
        if (pen) pen[g] = (size_t)q;
      }
  lw_status s = lw_close_share(st->b, owner, pen, st->n_segs, p->pen_width, &rep->close_share, err);
  free(owner);
  free(pen);
  /* a score of the finished drawing, which its want of memory must not
  ** fail: summary.json's close_share is then null */
  if (s == LW_ENOMEM) {
    rep->close_share = NAN;
    lw_error_clear(err);
    s = LW_OK;
  }
  /* nor past its grid's 2^32 points (a very fine pen over a large drawing:
  ** exit 2 ended the run before its summary, and its resume again), which
  ** no memory lifts */
  if (s == LW_EINPUT) {
    rep->close_share = NAN;
    rep->close_past_limit = 1;
    lw_error_clear(err);
    s = LW_OK;
  }
  return s;
}

/* A G-code feed's rounding to the thousandth of a mm/min, where it is more
** than 1 % (below 0.05 mm/min; F0 is refused, params.c), as HP-GL's VS. */
static void gcode_feed_note(const lw_params *p, char *note, size_t n)
{
  const char *key[2] = {"speed_down", "speed_up"};
  const double v[2] = {p->speed_down, p->speed_up};
  for (int k = 0; p->gcode && k < 1 + (p->gcode_travel == 1); k++) {
    const double f = 60.0 * v[k], written = round(1000.0 * f) / 1000.0;
    const size_t used = strlen(note);
    if (fabs(written - f) > 0.01 * f && used < n)
      snprintf(note + used, n - used, "%splot.%s = %g mm/s is F%g in final.gcode (mm/min to the thousandth), "
               "%.0f %% off", used ? "\n" : "", key[k], v[k], written, 100.0 * fabs(written - f) / f);
  }
}

void lw_drawing_note(const lw_params *p, char *note, size_t n)
{
  gcode_feed_note(p, note, n);
  if (!p->hpgl) return;
  /* HP-GL/1 takes coordinates to 32,767 units: a page past that without a
  ** bed to check against wrote them unsaid (an A1 page reached 33,642) */
  const double reach = LW_HPGL_COORD_MAX / LW_HPGL_UNITS_PER_MM, side = fmax(p->width, p->height);
  size_t used = strlen(note);
  if (side > reach && !(p->plot_bed_w > 0.0 && p->plot_bed_h > 0.0) && used < n)
    snprintf(note + used, n - used, "%sthe page is %g mm on its long side, past the %g mm (%g units) HP-GL/1 "
             "coordinates reach: final.hpgl may hold points the plotter cannot take (plot.bed_width and "
             "plot.bed_height, set to its reach, refuse those)", used ? "\n" : "", side, reach, LW_HPGL_COORD_MAX);
  const double vs = p->speed_down / 10.0, asked = round(100.0 * fmin(fmax(vs, LW_HPGL_VS_MIN), LW_HPGL_VS_MAX)) / 100.0;
  /* VS has two decimals (0.1 mm/s): at a few mm/s its rounding is a few per
  ** cent (1.234 mm/s was written 1.2: 2.8 % slower than the plot time) */
  if (fabs(asked - vs) <= 0.01 * vs) return;
  used = strlen(note);
  const int past = vs < LW_HPGL_VS_MIN || vs > LW_HPGL_VS_MAX;
  if (used < n)
    snprintf(note + used, n - used, "%splot.speed_down = %g mm/s is %s (%g to %g mm/s, in steps of 0.1): final.hpgl "
             "asks %g (VS%g, in cm/s), and the plot time, reckoned at %g, does not hold for the machine",
             used ? "\n" : "", p->speed_down, past ? "past what HP-GL's VS takes" : "more than 1 % from what HP-GL's VS "
             "writes", 10.0 * LW_HPGL_VS_MIN, 10.0 * LW_HPGL_VS_MAX, 10.0 * asked, asked, p->speed_down);
}

lw_status lw_drawing_write(const lw_params *p, const lw_scene *sc, const lw_splines *sp, const lw_grid2d *tone,
                           const char *dir, lw_drawing_report *rep, lw_error *err)
{
  memset(rep, 0, sizeof *rep);
  lw_output_page page;
  lw_status s = drawing_page(p, &page, err);
  if (s) return s;
  lw_plot *pl = make_plot(p, sc, sp, tone, err);
  if (!pl) return err ? err->code : LW_ENOMEM;
  lw_strokes_options o;
  options(p, sc, &page, &o);
  lw_strokes *st = lw_strokes_prepare(sp, pl, &o, &rep->post, err);
  lw_plot_free(pl);
  if (!st) return err ? err->code : LW_ENOMEM;
  rep->paths = st->n;
  rep->n_pens = st->n_pens;
  for (int k = 0; k < st->n_pens; k++) {
    rep->pen_paths[k] = st->pen_first[k + 1] - st->pen_first[k];
    snprintf(rep->pen_name[k], sizeof rep->pen_name[k], "%s", page.pen_name[k]);
  }
  /* an empty drawing said only that: what removed its lines, and the keys */
  if (!st->n && rep->post.lifts_before)
    snprintf(rep->empty_why, sizeof rep->empty_why, "every stroke was cut by the crop or too short for "
             "plot.min_length (%g pen widths)", p->min_length);
  /* the prices of line that could have emptied it, each named (a high
  ** chem_spline was blamed on the potential, and the potential on a tiny
  ** chem_spline) */
  else if (!st->n && !p->fixed_count && (p->potential_coef > 0.0 || p->chem_spline > 0.0 || p->chem_length > 0.0)) {
    char price[160] = "";
    size_t k = 0;
    if (p->potential_coef > 0.0)
      k += (size_t)snprintf(price + k, sizeof price - k, "energy.potential %g", p->potential_coef);
    if (p->chem_spline > 0.0 && k < sizeof price)
      k += (size_t)snprintf(price + k, sizeof price - k, "%senergy.chem_spline %g", k ? ", " : "", p->chem_spline);
    if (p->chem_length > 0.0 && k < sizeof price)
      snprintf(price + k, sizeof price - k, "%senergy.chem_length %g", k ? ", " : "", p->chem_length);
    snprintf(rep->empty_why, sizeof rep->empty_why, "no spline is left: none was placed (init.splines, "
             "init.coverage), or the anneal removed every one, the price of line (%s) being more than what the "
             "lines lower%s: lower it", price, sc->image ? " (a pale picture, or a price too high)" : "");
  }
  else if (!st->n && p->fixed_count)
    snprintf(rep->empty_why, sizeof rep->empty_why, "no spline was placed (init.splines, or init.coverage on a "
             "picture without dark to cover)");
  else if (!st->n)
    snprintf(rep->empty_why, sizeof rep->empty_why, "no spline is left: none was placed (init.splines, "
             "init.coverage), or the anneal's deaths removed every one");
  rep->travel_before = rep->post.travel_before;
  rep->travel_after = rep->post.travel_after;
  rep->cropped = o.crop;
  if (!o.crop) rep->off_page = paths_off_page(st, page.width_mm, page.height_mm);
  memcpy(rep->crop_mm, (double[4]){o.x0, o.y0, o.x1, o.y1}, sizeof rep->crop_mm);
  rep->pen_down_mm = lw_strokes_total_length(st);
  rep->time_s = lw_strokes_time(st, rep->travel_after, p->speed_down, p->speed_up, p->lift_time);
  const lw_plotter_options po = {.tolerance = p->plot_tolerance,
                                 .speed_down = p->speed_down,
                                 .pen_up = p->gcode_pen_up,
                                 .pen_down = p->gcode_pen_down,
                                 .turn = p->plot_turn,
                                 .bed = {p->plot_bed_w, p->plot_bed_h},
                                 .travel_feed = p->gcode_travel == LW_GCODE_TRAVEL_FEED,
                                 .speed_up = p->speed_up};
  char path[LW_OUTPUT_PATH_MAX];
  /* a machine file the drawing cannot make (off the bed, without the crop)
  ** is known before any file is written: none is, and the annealed state
  ** stays for a redraw with other plot keys */
  for (int g = 0; g < 2 && !s; g++) {
    if (!(g ? p->gcode : p->hpgl)) continue;
    lw_path_join(path, sizeof path, dir, g ? "final.gcode" : "final.hpgl");
    if ((s = lw_plotter_check(st, &page, &po, g, path, err)) && err) {
      size_t n = strlen(err->msg);
      /* (a resumed run's end: the files of its earlier end stay, and a
      ** plotter was sent a final.gcode its state.lw had moved on from) */
      char svg[LW_OUTPUT_PATH_MAX];
      lw_path_join(svg, sizeof svg, dir, "final.svg");
      snprintf(err->msg + n, sizeof err->msg - n, "; no drawing was written%s, and the annealed state is in "
               "%s/state.lw: redraw it with other plot keys (docs/FORMATS.md, \"Redrawing a finished run\")",
               access(svg, F_OK) ? "" : " (the final files there are of the run's earlier end, not of this state)",
               dir);
    }
  }
  if (s) {
    lw_strokes_free(st);
    if (err) err->code = LW_ERUN; /* the run itself went well: not a bad input's exit status */
    return LW_ERUN;
  }
  const lw_grid2d *under = p->preview_image ? tone : NULL;
  lw_path_join(path, sizeof path, dir, "final.svg");
  if (!(s = lw_output_svg_strokes(st, &page, path, err))) {
    lw_path_join(path, sizeof path, dir, "final.png");
    s = lw_output_png_strokes(st, &page, under, p->png_scale, path, err);
  }
  if (!s && p->pdf) {
    lw_path_join(path, sizeof path, dir, "final.pdf");
    s = lw_output_pdf_strokes(st, &page, under, path, err);
  }
  if (!s && p->hpgl) {
    lw_path_join(path, sizeof path, dir, "final.hpgl");
    s = lw_output_hpgl_strokes(st, &page, &po, path, err);
  }
  if (!s && p->gcode) {
    lw_path_join(path, sizeof path, dir, "final.gcode");
    s = lw_output_gcode_strokes(st, &page, &po, path, err);
  }
  /* a file that failed after this state's final.svg was written, and those
  ** after it, are the drawing of an earlier state: removed, so that none
  ** stands beside the new final.svg (a full disk left the old final.png) */
  static const char *const after_svg[] = {"final.png", "final.pdf", "final.hpgl", "final.gcode"};
  const char *failed = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
  for (int k = 0, from = -1; s && err && k < 4; k++) {
    if (from < 0 && strcmp(failed, after_svg[k])) continue;
    from = k;
    char old[LW_PATH_MAX + 16];
    lw_path_join(old, sizeof old, dir, after_svg[k]);
    const size_t m = strlen(err->msg);
    if (!remove(old))
      snprintf(err->msg + m, sizeof err->msg - m, "; %s of the state before removed (final.svg is this one's)",
               after_svg[k]);
  }
  /* a format turned off since the run's last end (scene.ini edited, then
  ** resumed) leaves no file of the old drawing beside the new: a plotter
  ** was sent a final.gcode that final.svg no longer showed */
  static const char *const optional[] = {"final.pdf", "final.hpgl", "final.gcode"};
  const int wrote[] = {p->pdf, p->hpgl, p->gcode};
  for (int k = 0; k < 3 && !s; k++) {
    lw_path_join(path, sizeof path, dir, optional[k]);
    if (!wrote[k] && remove(path) && errno != ENOENT)
      s = lw_error_set(err, LW_EIO, "%s: cannot remove the file of an earlier end (output.%s is now 0): %s", path,
                       optional[k] + 6, strerror(errno));
  }
  if (!s) s = close_share(p, sc, st, rep, err);
  if (!s && (tone || sc->reference)) s = score(p, sc, st, tone, rep, err);
  lw_strokes_free(st);
  return s;
}

lw_status lw_drawing_frame(const lw_params *p, const lw_scene *sc, const lw_splines *sp, const lw_grid2d *tone,
                           const char *dir, long sweep, lw_error *err)
{
  lw_output_page page;
  lw_status s = drawing_page(p, &page, err);
  if (s) return s;
  lw_plot *pl = make_plot(p, sc, sp, tone, err);
  if (!pl) return err ? err->code : LW_ENOMEM;
  s = lw_output_frame(dir, sweep, sp, &page, pl, p->preview_image ? tone : NULL, p->png_scale, err);
  lw_plot_free(pl);
  return s;
}

/* The share of missed marks (fidelity.h) from which the run says so: the
** bundled example misses 0, a few large words 0.001, photographs up to 0.03,
** bold capitals with crossbars gone 0.15, hairline letters half undrawn 0.38
** (0.03 with a pen fine enough); or, in the worst square, the share from
** which it does: a word left out there, its marks half bare or more. */
#define MISSED_NOTE 0.1
#define MISSED_WORST_NOTE 0.5

static int missed_note(const lw_fidelity *f) { return f->missed > MISSED_NOTE || f->missed_worst > MISSED_WORST_NOTE; }

static void fidelity_members(lw_json *j, const lw_fidelity *f)
{
  lw_json_key(j, "mse");
  lw_json_number(j, f->mse);
  lw_json_key(j, "ssim");
  lw_json_number(j, f->ssim);
  lw_json_key(j, "orientation");
  lw_json_number(j, f->orientation);
  lw_json_key(j, "stray");
  lw_json_number(j, f->stray);
  lw_json_key(j, "missed");
  lw_json_number(j, f->missed);
}

static void count(lw_json *j, const char *key, size_t v)
{
  lw_json_key(j, key);
  lw_json_int(j, (long long)v);
}

void lw_drawing_report_json(lw_json *j, const lw_drawing_report *rep)
{
  count(j, "paths", rep->paths);
  if (rep->n_pens > 1) {
    lw_json_key(j, "pen_paths");
    lw_json_begin_array(j);
    for (int k = 0; k < rep->n_pens; k++) lw_json_int(j, (long long)rep->pen_paths[k]);
    lw_json_end_array(j);
  }
  lw_json_key(j, "pen_up_travel_mm");
  lw_json_begin_object(j);
  lw_json_key(j, "before");
  lw_json_number(j, rep->travel_before);
  lw_json_key(j, "after");
  lw_json_number(j, rep->travel_after);
  lw_json_end_object(j);
  const lw_strokes_report *r = &rep->post;
  lw_json_key(j, "plot");
  lw_json_begin_object(j);
  lw_json_key(j, "lifts");
  lw_json_begin_object(j);
  count(j, "before", r->lifts_before);
  count(j, "after", r->lifts_after);
  lw_json_end_object(j);
  count(j, "joins", r->joins);
  count(j, "cut", r->cut);
  count(j, "outside", r->outside);
  count(j, "dropped", r->dropped);
  count(j, "off_page", rep->off_page);
  lw_json_key(j, "crop_mm");
  if (rep->cropped) {
    lw_json_begin_array(j);
    for (int k = 0; k < 4; k++) lw_json_number(j, rep->crop_mm[k]);
    lw_json_end_array(j);
  } else {
    lw_json_null(j);
  }
  lw_json_key(j, "pen_down_mm");
  lw_json_number(j, rep->pen_down_mm);
  lw_json_key(j, "pen_up_mm");
  lw_json_number(j, rep->travel_after);
  lw_json_key(j, "time_s");
  lw_json_number(j, rep->time_s);
  lw_json_end_object(j);
  lw_json_key(j, "close_share");
  lw_json_number(j, rep->close_share);
  if (rep->has_fidelity) {
    lw_json_key(j, "fidelity");
    lw_json_begin_object(j);
    fidelity_members(j, &rep->fidelity);
    lw_json_key(j, "sigma_mm");
    lw_json_number(j, rep->fidelity.sigma_mm);
    lw_json_key(j, "black");
    lw_json_number(j, rep->fidelity.black);
    if (rep->reference[0]) {
      lw_json_key(j, "reference");
      lw_json_string(j, rep->reference);
    }
    if (rep->n_pens > 1) {
      lw_json_key(j, "pens");
      lw_json_begin_array(j);
      for (int k = 0; k < rep->n_pens; k++) {
        lw_json_begin_object(j);
        fidelity_members(j, &rep->pen_fidelity[k]);
        lw_json_end_object(j);
      }
      lw_json_end_array(j);
    }
    lw_json_end_object(j);
  } else if (rep->fidelity_lost) {
    lw_json_key(j, "fidelity");
    lw_json_null(j);
  }
}

/* The orientation score for the terminal: none where the picture has no
** direction to follow (a flat tone; summary.json has null). */
static const char *orientation_text(double o, char buf[40])
{
  if (isnan(o)) return "none (a flat picture)";
  snprintf(buf, 40, "%.4f", o);
  return buf;
}

/* h:mm:ss, or m:ss under an hour */
static void clock_text(double s, char *buf, size_t n)
{
  long t = lround(s), h = t / 3600, m = t / 60 % 60, sec = t % 60;
  if (h) snprintf(buf, n, "%ld:%02ld:%02ld", h, m, sec);
  else snprintf(buf, n, "%ld:%02ld", m, sec);
}

void lw_drawing_lost_text(const lw_drawing_report *d, char *buf, size_t n)
{
  const int close = isnan(d->close_share) && !d->close_past_limit, fid = d->fidelity_lost;
  if (!n) return;
  buf[0] = '\0';
  int w = 0;
  if (d->close_past_limit)
    w = snprintf(buf, n, "the drawing holds 2^32 points or more at half a pen width apart, past the close share's "
                 "grid: summary.json's close_share is null (a wider output.pen_width, or fewer or shorter lines, "
                 "scores it)%s", close || fid ? "; " : "");
  if ((close || fid) && w >= 0 && (size_t)w < n)
    w += snprintf(buf + w, n - (size_t)w, "memory ran out scoring the drawing: summary.json's %s null (a redraw "
                  "where there is more memory scores it: docs/FORMATS.md, \"Redrawing a finished run\")",
                  close && fid ? "close_share and fidelity are" : close ? "close_share is" : "fidelity is");
  /* (said under --quiet too, as a warning: the plotter's files drive the pen
  ** off the paper, and a quiet script heard nothing) */
  if (d->off_page && w >= 0 && (size_t)w < n)
    snprintf(buf + w, n - (size_t)w, "%s%zu path%s reach%s past the page's edge (plot.crop = 0 keeps %s whole): a "
             "plotter would draw off the paper", w ? "; " : "", d->off_page, d->off_page == 1 ? "" : "s",
             d->off_page == 1 ? "es" : "", d->off_page == 1 ? "it" : "them");
}

void lw_drawing_report_text(const lw_drawing_report *d, char *buf, size_t n)
{
  const lw_strokes_report *r = &d->post;
  char clock[32], close[96];
  clock_text(d->time_s, clock, sizeof clock);
  if (isnan(d->close_share))
    snprintf(close, sizeof close, "not measured (%s)", d->close_past_limit ? "past 2^32 points" : "out of memory");
  else snprintf(close, sizeof close, "%.4f (of the line within a pen width of another stroke)", d->close_share);
  size_t k = 0;
  int w = snprintf(buf, n,
                   "linewise: %zu path%s (%zu stroke%s: %zu join%s, %zu cut by the crop, %zu outside it, %zu too "
                   "short); pen-up travel %.1f mm in index order, %.1f mm as plotted\n"
                   "linewise: plot time about %s (%.0f s: %.0f mm pen down, %zu lift%s); close share %s\n",
                   d->paths, d->paths == 1 ? "" : "s", r->lifts_before, r->lifts_before == 1 ? "" : "s", r->joins,
                   r->joins == 1 ? "" : "s", r->cut, r->outside, r->dropped, d->travel_before, d->travel_after, clock,
                   d->time_s, d->pen_down_mm, r->lifts_after, r->lifts_after == 1 ? "" : "s", close);
  if (w < 0 || (size_t)w >= n) return;
  k = (size_t)w;
  if (!d->paths) {
    w = snprintf(buf + k, n - k, "linewise: the drawing is empty: final.svg has no path%s%s\n",
                 d->empty_why[0] ? ": " : "", d->empty_why);
    if (w < 0 || (k += (size_t)w) >= n) return;
  }
  /* a colour pen whose separation is empty (a warm picture's cyan) still has
  ** its layer in final.svg: say so, so that no pen is changed for nothing */
  for (int p = 0; d->n_pens > 1 && d->paths && p < d->n_pens; p++) {
    if (d->pen_paths[p]) continue;
    w = snprintf(buf + k, n - k, "linewise: pen %d%s%s draws nothing (its layer in final.svg is empty)\n", p + 1,
                 d->pen_name[p][0] ? " " : "", d->pen_name[p]);
    if (w < 0 || (k += (size_t)w) >= n) return;
  }
  if (!d->has_fidelity) return;
  char o[40];
  w = snprintf(buf + k, n - k,
               "linewise: fidelity%s%s (blur %g mm, black %g): MSE %.6g, SSIM %.4f, orientation %s, stray ink %.4f, "
               "missed marks %.4f\n",
               d->reference[0] ? " against " : "", d->reference, d->fidelity.sigma_mm, d->fidelity.black,
               d->fidelity.mse, d->fidelity.ssim,
               orientation_text(d->fidelity.orientation, o), d->fidelity.stray, d->fidelity.missed);
  for (int p = 0; d->n_pens > 1 && p < d->n_pens && w >= 0 && (k += (size_t)w) < n; p++)
    w = snprintf(buf + k, n - k, "linewise: fidelity of pen %d%s%s: MSE %.6g, SSIM %.4f, orientation %s, stray ink "
                 "%.4f, missed marks %.4f\n", p + 1, d->pen_name[p][0] ? " " : "", d->pen_name[p],
                 d->pen_fidelity[p].mse, d->pen_fidelity[p].ssim,
                 orientation_text(d->pen_fidelity[p].orientation, o), d->pen_fidelity[p].stray,
                 d->pen_fidelity[p].missed);
  /* (hairline letters half undrawn scored SSIM 0.94, unsaid; a word left
  ** out beside a figure drawn whole was 0.01 of the marks, a pen's 0.31 of
  ** its own; not of a picture too thin for the page, said before the run.
  ** A pen of output.pens draws a share of the tones by design: its marks
  ** are the whole picture's, and its misses no pen's fault) */
  const lw_fidelity *f = &d->fidelity;
  int pen = -1;
  for (int p = 0; !missed_note(f) && d->n_pens > 1 && p < d->n_pens && p < d->pen_targets; p++)
    if (missed_note(&d->pen_fidelity[p])) f = &d->pen_fidelity[pen = p];
  if (w < 0 || (k += (size_t)w) >= n || !missed_note(f) || d->picture_thin) return;
  char who[96] = "the picture's", where[160] = "";
  if (pen >= 0) snprintf(who, sizeof who, "pen %d%s%s's target's", pen + 1, d->pen_name[pen][0] ? " " : "",
                         d->pen_name[pen]);
  if (f->missed_worst > MISSED_WORST_NOTE)
    snprintf(where, sizeof where, " (%.0f %% in the square of %.3g mm about (%.0f, %.0f) mm)", 100.0 * f->missed_worst,
             LW_FIDELITY_MISS_CELL * d->pen_width[pen >= 0 ? pen : 0], f->missed_at[0], f->missed_at[1]);
  snprintf(buf + k, n - k, "linewise: note: %.0f %% of %s dark marks have no line within %g pen widths%s: marks too "
           "thin for the pen, which the blurred scores barely see; a finer output.pen_width or a larger page draws "
           "them (docs/IMAGES.md, \"Thin lines on white\")%s\n", 100.0 * f->missed, who, LW_FIDELITY_MISS_REACH,
           where, d->frame_not_rect ? ", unless they lie outside the frame (scene.boundary), where no line goes" : "");
}
