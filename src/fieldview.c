/* fieldview.c -- the field preview image (fieldview.h). */
#include "linewise/fieldview.h"

#include <cairo.h>
#include <gsl/gsl_math.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "linewise/output.h"

/* The tone under the strokes, one value per preview pixel. */
static void paint_tone(cairo_surface_t *s, const lw_scene *sc, double scale)
{
  cairo_surface_flush(s);
  unsigned char *data = cairo_image_surface_get_data(s);
  int w = cairo_image_surface_get_width(s), h = cairo_image_surface_get_height(s);
  int stride = cairo_image_surface_get_stride(s);
  for (int j = 0; j < h; j++) {
    uint32_t *row = (uint32_t *)(data + (size_t)j * (size_t)stride);
    for (int i = 0; i < w; i++) {
      double t = sc->image ? lw_image_tone_at(sc->image, &sc->image_place, (i + 0.5) / scale, (j + 0.5) / scale)
                           : 1.0;
      /* lighter than the picture, so the strokes stand out on dark parts */
      uint32_t g = (uint32_t)lround(255.0 * (0.35 + 0.65 * t));
      row[i] = 0xFF000000u | g << 16 | g << 8 | g;
    }
  }
  cairo_surface_mark_dirty(s);
}

lw_status lw_fieldview_png(const lw_scene *sc, double px_per_mm, const char *path, lw_error *err)
{
  double longest = fmax(sc->width, sc->height);
  double scale = fmin(px_per_mm, LW_FIELDVIEW_MAX_PX / longest);
  int w = (int)ceil(sc->width * scale), h = (int)ceil(sc->height * scale);
  if (!(scale > 0) || w < 1 || h < 1)
    return lw_error_set(err, LW_EINPUT, "%s: preview scale %g px/mm gives no pixels", path, px_per_mm);
  cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
  if (cairo_surface_status(s) != CAIRO_STATUS_SUCCESS) {
    cairo_surface_destroy(s);
    return lw_error_set(err, LW_ENOMEM, "%s: cannot create a %d x %d preview", path, w, h);
  }
  paint_tone(s, sc, scale);
  cairo_t *cr = cairo_create(s);
  cairo_scale(cr, scale, scale); /* from here on, page millimetres */
  /* about 60 strokes along the longer side */
  double gap = longest / 60.0, half = 0.4 * gap;
  cairo_set_line_width(cr, fmax(0.12 * gap, 1.0 / scale));
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_set_source_rgb(cr, 0.05, 0.25, 0.75);
  const int signed_field = sc->field.kind != LW_FIELD_GRID_AXIAL && !sc->field_axial;
  for (double y = 0.5 * gap; y < sc->height; y += gap)
    for (double x = 0.5 * gap; x < sc->width; x += gap) {
      double vx, vy;
      lw_field_eval(&sc->field, x, y, &vx, &vy);
      double m = sqrt(vx * vx + vy * vy);
      if (!(m > 1e-9)) continue;
      double k = half * fmin(m, 1.0) / m;
      cairo_move_to(cr, x - k * vx, y - k * vy);
      cairo_line_to(cr, x + k * vx, y + k * vy);
      cairo_stroke(cr);
      if (signed_field) {
        cairo_arc(cr, x + k * vx, y + k * vy, 0.12 * gap, 0, 2 * M_PI);
        cairo_fill(cr);
      }
    }
  cairo_destroy(cr);

  lw_status st = lw_output_png_surface(s, path, err);
  cairo_surface_destroy(s);
  return st;
}
