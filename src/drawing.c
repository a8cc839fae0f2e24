/* drawing.c -- a run's drawing files from its parameters (drawing.h). */
#include "linewise/drawing.h"

#include <stdlib.h>
#include <string.h>

#include "linewise/spacing.h"

lw_status lw_drawing_page(const lw_params *p, lw_output_page *page, lw_error *err)
{
  lw_output_page_init(page, p->width, p->height);
  page->n_pens = p->pens;
  unsigned char rgb[LW_PLOT_PENS_MAX][3] = {{0}};
  if (p->pen_colors[0] && lw_output_colors_parse(p->pen_colors, rgb, LW_PLOT_PENS_MAX) != p->pens) {
    char where[LW_PATH_MAX + 32];
    lw_params_origin(p, lw_params_find("output", "pen_colors"), where, sizeof where);
    return lw_error_set(err, LW_EINPUT, "%s: key 'output.pen_colors': expected %d colours, got '%s'", where,
                        p->pens, p->pen_colors);
  }
  for (int k = 0; k < p->pens; k++) {
    page->pen[k].width_mm = p->pen_width;
    memcpy(page->pen[k].rgb, rgb[k], 3);
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

/* The plot of p's pens, ordered as `order`, home at the page origin. */
static lw_plot *make_plot(const lw_params *p, const lw_scene *sc, const lw_splines *sp, const lw_grid2d *tone,
                          lw_plot_order order, lw_error *err)
{
  double *key = NULL;
  if (p->pens > 1 && (sc->on[LW_TERM_POTENTIAL] || tone)) {
    key = malloc((sp->n_splines ? sp->n_splines : 1) * sizeof *key);
    if (!key) {
      lw_error_set(err, LW_ENOMEM, "out of memory ranking %zu splines", sp->n_splines);
      return NULL;
    }
    if (sc->on[LW_TERM_POTENTIAL]) lw_plot_mean_along(sp, &sc->quad, potential_at, &sc->potential, key);
    else lw_plot_mean_along(sp, &sc->quad, tone_at, tone, key);
  }
  lw_plot *pl = lw_plot_new(sp, p->pens, key, order, 0.0, 0.0, err);
  free(key);
  return pl;
}

static void dir_file(char *buf, size_t n, const char *dir, const char *name)
{
  snprintf(buf, n, "%s/%s", dir, name);
}

lw_status lw_drawing_write(const lw_params *p, const lw_scene *sc, const lw_splines *sp, const lw_grid2d *tone,
                           const char *dir, lw_drawing_report *rep, lw_error *err)
{
  memset(rep, 0, sizeof *rep);
  lw_output_page page;
  lw_status s = lw_drawing_page(p, &page, err);
  if (s) return s;
  lw_plot *pl = make_plot(p, sc, sp, tone, (lw_plot_order)p->order, err);
  if (!pl) return err ? err->code : LW_ENOMEM;
  rep->paths = pl->n;
  rep->travel_before = pl->travel_before;
  rep->travel_after = pl->travel_after;
  const lw_grid2d *under = p->preview_image ? tone : NULL;
  char path[LW_OUTPUT_PATH_MAX];
  dir_file(path, sizeof path, dir, "final.svg");
  if (!(s = lw_output_svg(sp, &page, pl, path, err))) {
    dir_file(path, sizeof path, dir, "final.png");
    s = lw_output_png(sp, &page, pl, under, p->png_scale, path, err);
  }
  if (!s && p->pdf) {
    dir_file(path, sizeof path, dir, "final.pdf");
    s = lw_output_pdf(sp, &page, pl, under, path, err);
  }
  lw_plot_free(pl);
  if (!s) s = lw_close_share(sp, p->pen_width, &rep->close_share, err);
  if (!s && tone) {
    s = lw_fidelity_compute(sp, tone, p->pen_width, p->fidelity_sigma, &rep->fidelity, err);
    rep->has_fidelity = !s;
  }
  return s;
}

lw_status lw_drawing_frame(const lw_params *p, const lw_scene *sc, const lw_splines *sp, const lw_grid2d *tone,
                           const char *dir, long sweep, lw_error *err)
{
  lw_output_page page;
  lw_status s = lw_drawing_page(p, &page, err);
  if (s) return s;
  lw_plot *pl = make_plot(p, sc, sp, tone, LW_PLOT_ORDER_NONE, err);
  if (!pl) return err ? err->code : LW_ENOMEM;
  s = lw_output_frame(dir, sweep, sp, &page, pl, p->preview_image ? tone : NULL, p->png_scale, err);
  lw_plot_free(pl);
  return s;
}

void lw_drawing_report_json(lw_json *j, const lw_drawing_report *rep)
{
  lw_json_key(j, "paths");
  lw_json_int(j, (long long)rep->paths);
  lw_json_key(j, "pen_up_travel_mm");
  lw_json_begin_object(j);
  lw_json_key(j, "before");
  lw_json_number(j, rep->travel_before);
  lw_json_key(j, "after");
  lw_json_number(j, rep->travel_after);
  lw_json_end_object(j);
  lw_json_key(j, "close_share");
  lw_json_number(j, rep->close_share);
  if (rep->has_fidelity) {
    lw_json_key(j, "fidelity");
    lw_json_begin_object(j);
    lw_json_key(j, "mse");
    lw_json_number(j, rep->fidelity.mse);
    lw_json_key(j, "ssim");
    lw_json_number(j, rep->fidelity.ssim);
    lw_json_key(j, "sigma_mm");
    lw_json_number(j, rep->fidelity.sigma_mm);
    lw_json_end_object(j);
  }
}
