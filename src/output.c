/* output.c -- plotter SVG, PNG preview and atomic file writes (output.h). */
#include "linewise/output.h"

#include <cairo.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

void lw_output_page_init(lw_output_page *page, double width_mm, double height_mm)
{
  memset(page, 0, sizeof *page);
  page->width_mm = width_mm;
  page->height_mm = height_mm;
  page->stroke_mm = LW_OUTPUT_PEN_DEFAULT;
  snprintf(page->color, sizeof page->color, "black");
}

/* ---- atomic writes ---------------------------------------------------- */

FILE *lw_output_open_tmp(const char *path, char *tmp, size_t n, lw_error *err)
{
  int len = snprintf(tmp, n, "%s.tmp", path);
  if (len < 0 || (size_t)len >= n) {
    lw_error_set(err, LW_EIO, "%s: path too long for its temporary file", path);
    return NULL;
  }
  FILE *f = fopen(tmp, "w");
  if (!f) lw_error_set(err, LW_EIO, "%s: cannot write %s: %s", path, tmp, strerror(errno));
  return f;
}

lw_status lw_output_commit(FILE *f, const char *tmp, const char *path, lw_error *err)
{
  /* ferror first: a failed fprintf long ago leaves the stream flagged even
  ** if the final flush succeeds, and the file would be short. */
  int bad = ferror(f), e = 0;
  if (fflush(f) || fsync(fileno(f))) {
    bad = 1;
    e = errno;
  }
  if (fclose(f)) {
    bad = 1;
    if (!e) e = errno;
  }
  if (bad) {
    remove(tmp);
    return lw_error_set(err, LW_EIO, "%s: write failed: %s", path, e ? strerror(e) : "I/O error");
  }
  if (rename(tmp, path)) {
    e = errno;
    remove(tmp);
    return lw_error_set(err, LW_EIO, "%s: cannot replace: %s", path, strerror(e));
  }
  return LW_OK;
}

void lw_output_abort(FILE *f, const char *tmp)
{
  if (f) fclose(f);
  remove(tmp);
}

/* ---- shared checks ---------------------------------------------------- */

static int positive(double x) { return isfinite(x) && x > 0; }

/* The colour goes verbatim into an XML attribute, so only characters that
** CSS colour syntax needs and XML does not escape are let through. */
static int color_ok(const char *c)
{
  if (!c[0] || !memchr(c, '\0', LW_OUTPUT_COLOR_MAX)) return 0;
  for (; *c; c++) {
    char ch = *c;
    int alnum = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9');
    if (!alnum && !strchr("#(),.% -", ch)) return 0;
  }
  return 1;
}

/* Everything is checked before a temporary file exists, so bad input never
** costs a file operation. */
static lw_status check_input(const lw_splines *sp, const lw_output_page *page, const char *path,
                             lw_error *err)
{
  if (!positive(page->width_mm) || !positive(page->height_mm))
    return lw_error_set(err, LW_EINPUT, "%s: page size %g x %g mm: expected positive numbers", path,
                        page->width_mm, page->height_mm);
  if (!positive(page->stroke_mm))
    return lw_error_set(err, LW_EINPUT, "%s: pen width %g mm: expected a positive number", path,
                        page->stroke_mm);
  if (!color_ok(page->color))
    return lw_error_set(err, LW_EINPUT, "%s: stroke colour '%.*s': expected a name, #rrggbb or rgb(...)",
                        path, LW_OUTPUT_COLOR_MAX - 1, page->color);
  for (size_t i = 0; i < sp->n_splines; i++)
    for (size_t k = sp->first[i]; k < sp->first[i + 1]; k++) {
      const lw_node *nd = &sp->node[k];
      if (!isfinite(nd->px) || !isfinite(nd->py) || !isfinite(nd->vx) || !isfinite(nd->vy))
        return lw_error_set(err, LW_EINPUT, "%s: spline %zu node %zu is not finite", path, i,
                            k - sp->first[i]);
    }
  return LW_OK;
}

/* 1 if every control point of spline i equals its first point: the curve is
** then a single point (the Bernstein polynomials are independent, so any
** other set of control points moves). */
static int zero_length(const lw_splines *sp, size_t i)
{
  const lw_node *nd = &sp->node[sp->first[i]];
  size_t nn = sp->first[i + 1] - sp->first[i];
  for (size_t k = 0; k < nn; k++)
    if (nd[k].px != nd[0].px || nd[k].py != nd[0].py || nd[k].vx != 0 || nd[k].vy != 0) return 0;
  return 1;
}

/* The four control points of segment m of spline i: x0 y0 x1 y1 x2 y2 x3 y3. */
static void control_points(const lw_splines *sp, size_t i, size_t m, double b[8])
{
  const lw_node *a = &sp->node[sp->first[i] + m], *c = a + 1;
  b[0] = a->px;
  b[1] = a->py;
  b[2] = a->px + a->vx;
  b[3] = a->py + a->vy;
  b[4] = c->px - c->vx;
  b[5] = c->py - c->vy;
  b[6] = c->px;
  b[7] = c->py;
}

/* ---- SVG -------------------------------------------------------------- */

/* A length in mm with 4 fixed decimals, trailing zeros and a bare point
** removed, "-0" folded to "0".  Fixed decimals rather than %g: the precision
** of a plot is absolute (mm), not relative, and %g would switch to exponents
** that some plotter tools do not parse.  The buffer holds the widest finite
** double (309 digits). */
static void put_mm(FILE *f, double v)
{
  char buf[352];
  snprintf(buf, sizeof buf, "%.4f", v);
  char *end = buf + strlen(buf);
  while (end[-1] == '0') *--end = '\0';
  if (end[-1] == '.') *--end = '\0';
  fputs(strcmp(buf, "-0") ? buf : "0", f);
}

lw_status lw_output_svg(const lw_splines *sp, const lw_output_page *page, const char *path,
                        lw_error *err)
{
  lw_status s = check_input(sp, page, path, err);
  if (s) return s;
  char tmp[LW_OUTPUT_PATH_MAX];
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) return err ? err->code : LW_EIO;

  fputs("<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n"
        "<svg xmlns=\"http://www.w3.org/2000/svg\"\n"
        "     xmlns:inkscape=\"http://www.inkscape.org/namespaces/inkscape\"\n"
        "     version=\"1.1\" width=\"", f);
  put_mm(f, page->width_mm);
  fputs("mm\" height=\"", f);
  put_mm(f, page->height_mm);
  fputs("mm\" viewBox=\"0 0 ", f);
  put_mm(f, page->width_mm);
  fputc(' ', f);
  put_mm(f, page->height_mm);
  fputs("\">\n  <g inkscape:groupmode=\"layer\" inkscape:label=\"pen 1\" id=\"pen1\">\n", f);
  for (size_t i = 0; i < sp->n_splines; i++) {
    if (zero_length(sp, i)) continue;
    /* Style on every path rather than inherited from the group: simple
    ** plotter tools read a path's own attributes only, and a closed curve
    ** would otherwise be filled black. */
    fprintf(f, "    <path id=\"spline%zu\" fill=\"none\" stroke=\"%s\" stroke-width=\"", i, page->color);
    put_mm(f, page->stroke_mm);
    fputs("\" stroke-linecap=\"round\" stroke-linejoin=\"round\"\n      d=\"M ", f);
    size_t n = lw_splines_segments(sp, i);
    double b[8];
    for (size_t m = 0; m < n; m++) {
      control_points(sp, i, m, b);
      if (!m) {
        put_mm(f, b[0]);
        fputc(' ', f);
        put_mm(f, b[1]);
      }
      fputs(" C", f);
      for (int c = 2; c < 8; c++) {
        fputc(' ', f);
        put_mm(f, b[c]);
      }
    }
    fputs("\"/>\n", f);
  }
  fputs("  </g>\n</svg>\n", f);
  return lw_output_commit(f, tmp, path, err);
}

/* ---- PNG -------------------------------------------------------------- */

int lw_output_png_size(const lw_output_page *page, double px_per_mm, int *width_px,
                       int *height_px, double *scale)
{
  if (!positive(page->width_mm) || !positive(page->height_mm) || !positive(px_per_mm)) return 0;
  double longest = page->width_mm > page->height_mm ? page->width_mm : page->height_mm;
  double k = px_per_mm;
  if (longest * k > LW_OUTPUT_PNG_MAX_PX) k = LW_OUTPUT_PNG_MAX_PX / longest;
  /* ceil so the whole page is shown; the 1e-6 keeps a product such as
  ** 1000 * 4.096 = 4096.0000000000005 from growing a pixel. */
  double w = ceil(page->width_mm * k - 1e-6), h = ceil(page->height_mm * k - 1e-6);
  *width_px = w < 1 ? 1 : w > LW_OUTPUT_PNG_MAX_PX ? LW_OUTPUT_PNG_MAX_PX : (int)w;
  *height_px = h < 1 ? 1 : h > LW_OUTPUT_PNG_MAX_PX ? LW_OUTPUT_PNG_MAX_PX : (int)h;
  if (scale) *scale = k;
  return 1;
}

static cairo_status_t png_write(void *closure, const unsigned char *data, unsigned int length)
{
  return fwrite(data, 1, length, closure) == length ? CAIRO_STATUS_SUCCESS : CAIRO_STATUS_WRITE_ERROR;
}

lw_status lw_output_png(const lw_splines *sp, const lw_output_page *page, double px_per_mm,
                        const char *path, lw_error *err)
{
  lw_status s = check_input(sp, page, path, err);
  if (s) return s;
  int w, h;
  double k;
  if (!lw_output_png_size(page, px_per_mm, &w, &h, &k))
    return lw_error_set(err, LW_EINPUT, "%s: resolution %g px/mm: expected a positive number", path,
                        px_per_mm);

  /* RGB24: the preview is opaque, and the PNG needs no alpha channel. */
  cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
  cairo_t *cr = cairo_create(surf);
  if (cairo_status(cr)) {
    s = lw_error_set(err, LW_ENOMEM, "%s: cannot make a %d x %d preview: %s", path, w, h,
                     cairo_status_to_string(cairo_status(cr)));
    goto done;
  }
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  /* Draw in mm: the line width is then the pen width in page units. */
  cairo_scale(cr, k, k);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, page->stroke_mm);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  for (size_t i = 0; i < sp->n_splines; i++) {
    if (zero_length(sp, i)) continue;
    size_t n = lw_splines_segments(sp, i);
    double b[8];
    for (size_t m = 0; m < n; m++) {
      control_points(sp, i, m, b);
      if (!m) cairo_move_to(cr, b[0], b[1]);
      cairo_curve_to(cr, b[2], b[3], b[4], b[5], b[6], b[7]);
    }
    /* One stroke per spline keeps cairo's path memory to one spline. */
    cairo_stroke(cr);
  }
  cairo_surface_flush(surf);
  if (cairo_status(cr)) {
    s = lw_error_set(err, LW_ERUN, "%s: drawing the preview failed: %s", path,
                     cairo_status_to_string(cairo_status(cr)));
    goto done;
  }

  /* To a stream on our temporary file rather than
  ** cairo_surface_write_to_png(tmp): the commit then fsyncs it like every
  ** other output. */
  char tmp[LW_OUTPUT_PATH_MAX];
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) {
    s = err ? err->code : LW_EIO;
    goto done;
  }
  cairo_status_t cs = cairo_surface_write_to_png_stream(surf, png_write, f);
  if (cs) {
    lw_output_abort(f, tmp);
    s = lw_error_set(err, LW_EIO, "%s: writing the PNG failed: %s", path, cairo_status_to_string(cs));
    goto done;
  }
  s = lw_output_commit(f, tmp, path, err);
done:
  cairo_destroy(cr);
  cairo_surface_destroy(surf);
  return s;
}
