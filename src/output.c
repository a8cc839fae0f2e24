/* output.c -- plotter SVG, PNG and PDF previews, frames and atomic file
** writes (output.h). */
#include "linewise/output.h"

#include <cairo-pdf.h>
#include <cairo.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

void lw_output_page_init(lw_output_page *page, double width_mm, double height_mm)
{
  memset(page, 0, sizeof *page);
  page->width_mm = width_mm;
  page->height_mm = height_mm;
  page->n_pens = 1;
  page->pen[0].width_mm = LW_OUTPUT_PEN_DEFAULT;
}

static int hex_digit(char c)
{
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

int lw_output_color_parse(const char *text, size_t len, unsigned char rgb[3])
{
  if ((len != 4 && len != 7) || text[0] != '#') return 0;
  int d[6];
  for (size_t k = 1; k < len; k++)
    if ((d[k - 1] = hex_digit(text[k])) < 0) return 0;
  for (int c = 0; c < 3; c++)
    rgb[c] = (unsigned char)(len == 4 ? 17 * d[c] : 16 * d[2 * c] + d[2 * c + 1]);
  return 1;
}

int lw_output_colors_parse(const char *list, unsigned char (*rgb)[3], int max)
{
  int n = 0;
  for (const char *c = list;;) {
    c += strspn(c, " \t,");
    if (!*c) return n;
    size_t len = strcspn(c, " \t,");
    if (n == max || !lw_output_color_parse(c, len, rgb[n])) return -1;
    n++;
    c += len;
  }
}

/* ---- atomic writes ---------------------------------------------------- */

FILE *lw_output_open_tmp(const char *path, char *tmp, size_t n, lw_error *err)
{
  int len = snprintf(tmp, n, "%s.tmp", path);
  if (len < 0 || (size_t)len >= n) {
    lw_error_set(err, LW_EIO, "%s: path too long for its temporary file", path);
    return NULL;
  }
  /* a stale one (a kill as it was written) or a link goes, not what it
  ** names; O_EXCL then refuses one put back in between */
  struct stat sb;
  /* (a read-only file system refuses to unlink what is not there too: the
  ** write is what failed, and the open below says so) */
  if (unlink(tmp) && errno != ENOENT && !(errno == EROFS && lstat(tmp, &sb) && errno == ENOENT)) {
    lw_error_set(err, LW_EIO, "%s: cannot remove %s: %s", path, tmp, strerror(errno));
    return NULL;
  }
  int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
  FILE *f = fd < 0 ? NULL : fdopen(fd, "w");
  if (!f) {
    lw_error_set(err, LW_EIO, "%s: cannot write %s: %s", path, tmp, strerror(errno));
    if (fd >= 0) {
      close(fd);
      unlink(tmp);
    }
  }
  return f;
}

lw_status lw_output_subdir(const char *dir, const char *sub, char *path, size_t n, lw_error *err)
{
  int len = snprintf(path, n, "%s/%s", dir, sub);
  if (len < 0 || (size_t)len >= n - 32) return lw_error_set(err, LW_EIO, "%s: path too long for the %s", dir, sub);
  struct stat sb;
  if (mkdir(path, 0777) && errno != EEXIST)
    return lw_error_set(err, LW_EIO, "%s: cannot create directory: %s", path, strerror(errno));
  if (lstat(path, &sb)) return lw_error_set(err, LW_EIO, "%s: %s", path, strerror(errno));
  if (!S_ISDIR(sb.st_mode)) /* (bad input, as a run's start says it: exit 2) */
    return lw_error_set(err, LW_EINPUT, "%s: %s, not a folder: a run writes its %s only into its own directory; remove "
                        "it", path, S_ISLNK(sb.st_mode) ? "a symbolic link" : "a file", sub);
  return LW_OK;
}

/* A directory that cannot be synced (a file system without it) leaves the
** old file or the new one, each whole, so nothing is reported. */
void lw_output_sync_dir(const char *dir)
{
  int fd = open(dir, O_RDONLY | O_DIRECTORY);
  if (fd < 0) return;
  (void)fsync(fd);
  close(fd);
}

/* A rename outlasts a power cut only once its directory is on disk too. */
static void sync_directory_of(const char *path)
{
  char dir[4096];
  const char *slash = strrchr(path, '/');
  if (!slash) snprintf(dir, sizeof dir, ".");
  else if (slash == path) snprintf(dir, sizeof dir, "/");
  else if ((size_t)(slash - path) < sizeof dir) snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
  else return;
  lw_output_sync_dir(dir);
}

/* Why a write long before the commit failed, where the stream kept only
** that it did (a large fwrite fails in its own write; the flush after has
** nothing left to write, and under MPI a full disk read "I/O error"): the
** file system full, or the file at the size limit; 0 if neither. */
static int lost_write_error(FILE *f)
{
  struct statvfs v;
  struct stat st;
  struct rlimit r;
  if (!fstatvfs(fileno(f), &v) && (v.f_bavail == 0 || v.f_bfree == 0)) return ENOSPC;
  if (!getrlimit(RLIMIT_FSIZE, &r) && r.rlim_cur != RLIM_INFINITY && !fstat(fileno(f), &st) &&
      (rlim_t)st.st_size >= r.rlim_cur)
    return EFBIG;
  return 0;
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
  if (bad && !e) e = lost_write_error(f);
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
  sync_directory_of(path);
  return LW_OK;
}

void lw_output_abort(FILE *f, const char *tmp)
{
  if (f) fclose(f);
  remove(tmp);
}

/* ---- shared checks ---------------------------------------------------- */

static int positive(double x) { return isfinite(x) && x > 0; }

/* The page and tone of a drawing with n_pens pens.  Everything is checked
** before a temporary file exists, so bad input never costs a file
** operation. */
static lw_status check_page(const lw_output_page *page, int n_pens, const lw_grid2d *tone, const char *path,
                            lw_error *err)
{
  if (!positive(page->width_mm) || !positive(page->height_mm))
    return lw_error_set(err, LW_EINPUT, "%s: page size %g x %g mm: expected positive numbers", path,
                        page->width_mm, page->height_mm);
  if (page->n_pens < 1 || page->n_pens > LW_PLOT_PENS_MAX)
    return lw_error_set(err, LW_EINPUT, "%s: %d pens: expected 1 to %d", path, page->n_pens, LW_PLOT_PENS_MAX);
  for (int k = 0; k < page->n_pens; k++)
    if (!positive(page->pen[k].width_mm))
      return lw_error_set(err, LW_EINPUT, "%s: pen %d width %g mm: expected a positive number", path, k + 1,
                          page->pen[k].width_mm);
  if (n_pens != page->n_pens)
    return lw_error_set(err, LW_EINPUT, "%s: the plot has %d pens, the page %d", path, n_pens, page->n_pens);
  if (tone && (tone->ncomp != 1 || tone->nx < 1 || tone->ny < 1 || !positive(tone->hx) || !positive(tone->hy)))
    return lw_error_set(err, LW_EINPUT, "%s: the tone raster must have one value per pixel", path);
  return LW_OK;
}

/* The splines and plot of a drawing as paths (strokes.h), after checking
** them; NULL and err set when they are bad. */
static lw_strokes *checked_strokes(const lw_splines *sp, const lw_output_page *page, const lw_plot *plot,
                                   const lw_grid2d *tone, const char *path, lw_error *err)
{
  if (check_page(page, plot ? plot->n_pens : page->n_pens, tone, path, err)) return NULL;
  if (plot) {
    if (plot->pen_first[plot->n_pens] != plot->n) {
      lw_error_set(err, LW_EINPUT, "%s: the plot's pens hold %zu paths of %zu", path, plot->pen_first[plot->n_pens],
                   plot->n);
      return NULL;
    }
    for (size_t k = 0; k < plot->n; k++)
      if (plot->spline[k] >= sp->n_splines) {
        lw_error_set(err, LW_EINPUT, "%s: the plot names spline %zu of %zu", path, plot->spline[k], sp->n_splines);
        return NULL;
      }
  }
  for (size_t i = 0; i < sp->n_splines; i++)
    for (size_t k = sp->first[i]; k < sp->first[i + 1]; k++) {
      const lw_node *nd = &sp->node[k];
      if (!isfinite(nd->px) || !isfinite(nd->py) || !isfinite(nd->vx) || !isfinite(nd->vy)) {
        lw_error_set(err, LW_EINPUT, "%s: spline %zu node %zu is not finite", path, i, k - sp->first[i]);
        return NULL;
      }
    }
  lw_strokes *s = lw_strokes_from_plot(sp, plot, err);
  if (s && !plot) {
    /* without a plot every path is pen 1's, whatever the page holds */
    s->n_pens = page->n_pens;
    for (int k = 1; k <= page->n_pens; k++) s->pen_first[k] = s->n;
  }
  return s;
}

lw_status lw_output_check_strokes(const lw_strokes *s, const lw_output_page *page, const lw_grid2d *tone,
                                  const char *path, lw_error *err)
{
  lw_status st = check_page(page, s->n_pens, tone, path, err);
  if (st) return st;
  for (size_t k = 0; k < 8 * s->n_segs; k++)
    if (!isfinite(s->b[k]))
      return lw_error_set(err, LW_EINPUT, "%s: a control point of segment %zu is not finite", path, k / 8);
  return LW_OK;
}

/* ---- SVG -------------------------------------------------------------- */

void lw_output_put_fixed(FILE *f, double v, int decimals)
{
  char buf[352];
  snprintf(buf, sizeof buf, "%.*f", decimals, v);
  char *end = buf + strlen(buf);
  if (strchr(buf, '.')) {
    while (end[-1] == '0') *--end = '\0';
    if (end[-1] == '.') *--end = '\0';
  }
  fputs(strcmp(buf, "-0") ? buf : "0", f);
}

static void put_mm(FILE *f, double v) { lw_output_put_fixed(f, v, LW_OUTPUT_SVG_DECIMALS); }

static void put_coords(FILE *f, const double *xy, int n)
{
  for (int c = 0; c < n; c++) {
    fputc(' ', f);
    put_mm(f, xy[2 * c]);
    fputc(' ', f);
    put_mm(f, xy[2 * c + 1]);
  }
}

/* One path's d attribute, in the direction it is drawn. */
static void put_path_data(FILE *f, const lw_strokes *s, size_t k)
{
  double cp[8];
  fputs("M", f);
  for (size_t j = 0; j < s->first[k + 1] - s->first[k]; j++) {
    lw_strokes_drawn_segment(s, k, j, cp);
    if (!j) put_coords(f, cp, 1);
    fputs(" C", f);
    put_coords(f, cp + 2, 3);
  }
}

lw_status lw_output_svg_strokes(const lw_strokes *s, const lw_output_page *page, const char *path,
                                lw_error *err)
{
  lw_status st = lw_output_check_strokes(s, page, NULL, path, err);
  if (st) return st;
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
  fputs("\">\n", f);
  /* a pen's own strokes multiply too where they cross or overlap, as in
  ** final.png (the group's style alone painted them over each other flat) */
  if (page->multiply) fputs("  <style>path { mix-blend-mode: multiply }</style>\n", f);
  for (int k = 0; k < page->n_pens; k++) {
    const lw_output_pen *pen = &page->pen[k];
    char color[8];
    snprintf(color, sizeof color, "#%02x%02x%02x", pen->rgb[0], pen->rgb[1], pen->rgb[2]);
    /* the label begins with the pen's number: AxiDraw's software plots a
    ** layer by the number its name begins with ("Plot layer 2"); and it
    ** holds no other digit, since vpype takes every digit of a label for
    ** the layer's number ("1 cyan (0.35 mm)" was its layer 1035, and four
    ** pens of 0.35 mm shared one plotter pen): the width is each path's */
    fprintf(f, "  <g inkscape:groupmode=\"layer\" inkscape:label=\"%d %s\"", k + 1,
            page->pen_name[k][0] ? page->pen_name[k] : "pen");
    /* layers multiply as inks on paper, as the previews draw them (a browser
    ** or Inkscape showed the top pen opaque where two cross); plotter tools
    ** read no group style */
    fprintf(f, " id=\"pen%d\"%s>\n", k + 1, page->multiply ? " style=\"mix-blend-mode:multiply\"" : "");
    size_t a, z;
    lw_strokes_pen_range(s, k, &a, &z);
    for (size_t j = a; j < z; j++) {
      /* Style on every path rather than inherited from the group: simple
      ** plotter tools read a path's own attributes only, and a closed curve
      ** would otherwise be filled black. */
      fprintf(f, "    <path id=\"spline%zu", s->src[j]);
      if (s->part[j]) fprintf(f, "-%u", s->part[j]);
      fprintf(f, "\" fill=\"none\" stroke=\"%s\" stroke-width=\"", color);
      put_mm(f, pen->width_mm);
      fputs("\" stroke-linecap=\"round\" stroke-linejoin=\"round\"\n      d=\"", f);
      put_path_data(f, s, j);
      fputs("\"/>\n", f);
    }
    fputs("  </g>\n", f);
  }
  fputs("</svg>\n", f);
  return lw_output_commit(f, tmp, path, err);
}

lw_status lw_output_svg(const lw_splines *sp, const lw_output_page *page, const lw_plot *plot,
                        const char *path, lw_error *err)
{
  lw_strokes *s = checked_strokes(sp, page, plot, NULL, path, err);
  if (!s) return err ? err->code : LW_EINPUT;
  lw_status st = lw_output_svg_strokes(s, page, path, err);
  lw_strokes_free(s);
  return st;
}

/* ---- cairo drawings ----------------------------------------------------- */

/* Each segment as the plotter draws it (strokes.h), so final.pdf travels as final.svg does. */
void lw_output_cairo_path(cairo_t *cr, const lw_strokes *s, size_t k)
{
  double b[8];
  for (size_t j = 0; j < s->first[k + 1] - s->first[k]; j++) {
    lw_strokes_drawn_segment(s, k, j, b);
    if (!j) cairo_move_to(cr, b[0], b[1]);
    cairo_curve_to(cr, b[2], b[3], b[4], b[5], b[6], b[7]);
  }
}

void lw_output_cairo_strokes(cairo_t *cr, const lw_strokes *s, int pen)
{
  size_t a = 0, z = s->n;
  if (pen >= 0) lw_strokes_pen_range(s, pen, &a, &z);
  for (size_t k = a; k < z; k++) {
    lw_output_cairo_path(cr, s, k);
    /* One stroke per path keeps cairo's path memory to one path. */
    cairo_stroke(cr);
  }
}

/* The tone raster as grey pixels over its rectangle (mm), blended at
** LW_OUTPUT_UNDERLAY_ALPHA.  The surface is cairo's own copy of the tone,
** 8 bits per channel, which is all a preview shows. */
static void paint_tone(cairo_t *cr, const lw_grid2d *tone)
{
  cairo_surface_t *img = cairo_image_surface_create(CAIRO_FORMAT_RGB24, tone->nx, tone->ny);
  if (cairo_surface_status(img)) {
    cairo_surface_destroy(img);
    return;
  }
  cairo_surface_flush(img);
  unsigned char *data = cairo_image_surface_get_data(img);
  int stride = cairo_image_surface_get_stride(img);
  for (int j = 0; j < tone->ny; j++) {
    uint32_t *row = (uint32_t *)(data + (size_t)j * (size_t)stride);
    for (int i = 0; i < tone->nx; i++) {
      double v = tone->data[(size_t)j * (size_t)tone->nx + (size_t)i];
      uint32_t g = (uint32_t)lround(255.0 * (v < 0 ? 0 : v > 1 ? 1 : v));
      row[i] = g << 16 | g << 8 | g;
    }
  }
  cairo_surface_mark_dirty(img);
  cairo_save(cr);
  /* pixel (i, j) covers [x0 + (i - 1/2) hx, x0 + (i + 1/2) hx] x ... */
  cairo_translate(cr, tone->x0 - 0.5 * tone->hx, tone->y0 - 0.5 * tone->hy);
  cairo_scale(cr, tone->hx, tone->hy);
  cairo_set_source_surface(cr, img, 0, 0);
  /* PAD inside the rectangle: the edge pixels keep their grey instead of
  ** fading into the paper over half a pixel */
  cairo_pattern_set_extend(cairo_get_source(cr), CAIRO_EXTEND_PAD);
  cairo_rectangle(cr, 0, 0, tone->nx, tone->ny);
  cairo_clip(cr);
  cairo_paint_with_alpha(cr, LW_OUTPUT_UNDERLAY_ALPHA);
  cairo_restore(cr);
  cairo_surface_destroy(img);
}

/* A PDF's strokes go in batches of this many paths, one cairo_stroke each:
** cairo's PDF surface adds every drawing operation's box to one region
** when it finishes the page, at a cost that grows with the boxes already
** there, so a stroke a path took minutes at 10,000 paths (the image
** surface has no such cost, and keeps one path a stroke). */
#define PDF_BATCH 1024

/* The pen's strokes as paths of up to `batch` subpaths each.  With opaque
** pens drawn over each other this paints what a stroke a path does; under
** MULTIPLY a pen's own overlaps would darken once instead of twice. */
static void stroke_batches(cairo_t *cr, const lw_strokes *s, int pen, size_t batch)
{
  size_t a = 0, z = s->n;
  lw_strokes_pen_range(s, pen, &a, &z);
  for (size_t k = a; k < z; k++) {
    lw_output_cairo_path(cr, s, k);
    if ((k - a + 1) % batch == 0 || k + 1 == z) cairo_stroke(cr);
  }
}

/* The whole drawing on cr, whose user unit is 1 mm; strokes in batches of
** `batch` paths where the pens are opaque (1: a stroke a path). */
static void draw(cairo_t *cr, const lw_strokes *s, const lw_output_page *page, const lw_grid2d *tone, size_t batch)
{
  if (tone) paint_tone(cr, tone);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  if (page->multiply) cairo_set_operator(cr, CAIRO_OPERATOR_MULTIPLY);
  for (int k = 0; k < page->n_pens; k++) {
    const lw_output_pen *pen = &page->pen[k];
    cairo_set_source_rgb(cr, pen->rgb[0] / 255.0, pen->rgb[1] / 255.0, pen->rgb[2] / 255.0);
    cairo_set_line_width(cr, pen->width_mm);
    if (batch > 1 && !page->multiply) stroke_batches(cr, s, k, batch);
    else lw_output_cairo_strokes(cr, s, k);
  }
}

/* ---- PNG -------------------------------------------------------------- */

int lw_output_png_size(const lw_output_page *page, double px_per_mm, int *width_px,
                       int *height_px, double *scale)
{
  if (!positive(page->width_mm) || !positive(page->height_mm) || !positive(px_per_mm)) return 0;
  double longest = page->width_mm > page->height_mm ? page->width_mm : page->height_mm;
  double k = px_per_mm;
  if (longest * k > LW_OUTPUT_PNG_MAX_PX) k = LW_OUTPUT_PNG_MAX_PX / longest;
  /* and a pixel at least: a scale of 1e-200 made cairo's matrix singular,
  ** and the run failed after its anneal, without final.png or summary.json */
  if (longest * k < 1.0) k = 1.0 / longest;
  /* ceil so the whole page is shown; the 1e-6 keeps a product such as
  ** 1000 * 4.096 = 4096.0000000000005 from growing a pixel. */
  double w = ceil(page->width_mm * k - 1e-6), h = ceil(page->height_mm * k - 1e-6);
  *width_px = w < 1 ? 1 : w > LW_OUTPUT_PNG_MAX_PX ? LW_OUTPUT_PNG_MAX_PX : (int)w;
  *height_px = h < 1 ? 1 : h > LW_OUTPUT_PNG_MAX_PX ? LW_OUTPUT_PNG_MAX_PX : (int)h;
  if (scale) *scale = k;
  return 1;
}

/* cairo's stream to a file, keeping why a write failed: cairo reports
** only "error while writing to output stream", and a full disk must be
** named (FORMATS.md). */
typedef struct {
  FILE *f;
  int error;
} file_sink;

static cairo_status_t file_write(void *closure, const unsigned char *data, unsigned int length)
{
  file_sink *k = closure;
  if (fwrite(data, 1, length, k->f) == length) return CAIRO_STATUS_SUCCESS;
  if (!k->error) k->error = errno ? errno : EIO;
  return CAIRO_STATUS_WRITE_ERROR;
}

/* libpng's side of the writer below: a write that fails keeps errno, and
** libpng's errors end in the writer's setjmp with their text, never on
** stderr. */
typedef struct {
  file_sink sink;
  char why[128];
} png_sink;

static void png_sink_write(png_structp pp, png_bytep data, size_t n)
{
  png_sink *k = png_get_io_ptr(pp);
  if (fwrite(data, 1, n, k->sink.f) == n) return;
  if (!k->sink.error) k->sink.error = errno ? errno : EIO;
  png_error(pp, "write error");
}

static void png_sink_flush(png_structp pp) { (void)pp; }

static void png_sink_error(png_structp pp, png_const_charp msg)
{
  png_sink *k = png_get_error_ptr(pp);
  snprintf(k->why, sizeof k->why, "%s", msg);
  png_longjmp(pp, 1);
}

static void png_sink_warning(png_structp pp, png_const_charp msg) { (void)pp, (void)msg; }

/* An opaque surface as an 8-bit RGB PNG, rows unfiltered and deflated at
** level 5: cairo's writer (libpng's defaults: every filter tried on every
** row, level 6) took 90 % of a NURBS run that writes frames, and lines on
** white paper deflate best unfiltered (the A4 preview of params/photo.ini:
** 556 kB in about half cairo's time, against 739 kB; a wire's frame 6.2 kB
** against 5.7; levels 1 to 3 doubled a frame, a run-length deflate the
** preview). */
static lw_status png_write_rgb(cairo_surface_t *surf, png_sink *k)
{
  const int w = cairo_image_surface_get_width(surf), h = cairo_image_surface_get_height(surf),
            stride = cairo_image_surface_get_stride(surf);
  const unsigned char *data = cairo_image_surface_get_data(surf);
  png_structp pp = png_create_write_struct(PNG_LIBPNG_VER_STRING, k, png_sink_error, png_sink_warning);
  png_infop info = pp ? png_create_info_struct(pp) : NULL;
  unsigned char *row = malloc(3 * (size_t)w + 1);
  if (!pp || !info || !row || !data) {
    png_destroy_write_struct(&pp, &info);
    free(row);
    snprintf(k->why, sizeof k->why, "out of memory");
    return LW_ENOMEM;
  }
  if (setjmp(png_jmpbuf(pp))) {
    png_destroy_write_struct(&pp, &info);
    free(row);
    return LW_EIO;
  }
  png_set_write_fn(pp, k, png_sink_write, png_sink_flush);
  png_set_IHDR(pp, info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_filter(pp, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
  png_set_compression_level(pp, 5);
  png_write_info(pp, info);
  for (int y = 0; y < h; y++) {
    const uint32_t *px = (const uint32_t *)(const void *)(data + (size_t)y * (size_t)stride);
    for (int x = 0; x < w; x++) { /* RGB24: 0x00RRGGBB in a native word */
      row[3 * x] = (unsigned char)(px[x] >> 16);
      row[3 * x + 1] = (unsigned char)(px[x] >> 8);
      row[3 * x + 2] = (unsigned char)px[x];
    }
    png_write_row(pp, row);
  }
  png_write_end(pp, NULL);
  png_destroy_write_struct(&pp, &info);
  free(row);
  return LW_OK;
}

cairo_surface_t *lw_output_white_surface(int w, int h)
{
  cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
  if (cairo_surface_status(s) == CAIRO_STATUS_SUCCESS) {
    cairo_surface_flush(s);
    memset(cairo_image_surface_get_data(s), 0xff, (size_t)cairo_image_surface_get_stride(s) * (size_t)h);
    cairo_surface_mark_dirty(s);
  }
  return s;
}

lw_status lw_output_png_surface(cairo_surface_t *surf, const char *path, lw_error *err)
{
  /* To a stream on our temporary file rather than
  ** cairo_surface_write_to_png(tmp): the commit then fsyncs it like every
  ** other output. */
  char tmp[LW_OUTPUT_PATH_MAX];
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) return err ? err->code : LW_EIO;
  errno = 0;
  cairo_surface_flush(surf);
  if (cairo_image_surface_get_format(surf) == CAIRO_FORMAT_RGB24) {
    png_sink k = {{f, 0}, ""};
    lw_status s = png_write_rgb(surf, &k);
    if (s) {
      lw_output_abort(f, tmp);
      return lw_error_set(err, s, "%s: writing the PNG failed: %s", path,
                          k.sink.error ? strerror(k.sink.error) : k.why);
    }
    return lw_output_commit(f, tmp, path, err);
  }
  file_sink k = {f, 0};
  cairo_status_t cs = cairo_surface_write_to_png_stream(surf, file_write, &k);
  if (cs) {
    lw_output_abort(f, tmp);
    return lw_error_set(err, LW_EIO, "%s: writing the PNG failed: %s", path,
                        k.error ? strerror(k.error) : cairo_status_to_string(cs));
  }
  return lw_output_commit(f, tmp, path, err);
}

lw_status lw_output_png_strokes(const lw_strokes *st, const lw_output_page *page, const lw_grid2d *tone,
                                double px_per_mm, const char *path, lw_error *err)
{
  lw_status s = lw_output_check_strokes(st, page, tone, path, err);
  if (s) return s;
  int w, h;
  double k;
  if (!lw_output_png_size(page, px_per_mm, &w, &h, &k))
    return lw_error_set(err, LW_EINPUT, "%s: resolution %g px/mm: expected a positive number", path,
                        px_per_mm);

  /* RGB24: the preview is opaque, and the PNG needs no alpha channel. */
  cairo_surface_t *surf = lw_output_white_surface(w, h);
  cairo_t *cr = cairo_create(surf);
  if (cairo_status(cr)) {
    s = lw_error_set(err, LW_ENOMEM, "%s: cannot make a %d x %d preview: %s", path, w, h,
                     cairo_status_to_string(cairo_status(cr)));
    goto done;
  }
  /* Draw in mm: the line width is then the pen width in page units. */
  cairo_scale(cr, k, k);
  draw(cr, st, page, tone, 1);
  cairo_surface_flush(surf);
  if (cairo_status(cr)) {
    s = lw_error_set(err, LW_ERUN, "%s: drawing the preview failed: %s", path,
                     cairo_status_to_string(cairo_status(cr)));
    goto done;
  }

  s = lw_output_png_surface(surf, path, err);
done:
  cairo_destroy(cr);
  cairo_surface_destroy(surf);
  return s;
}

lw_status lw_output_png(const lw_splines *sp, const lw_output_page *page, const lw_plot *plot,
                        const lw_grid2d *tone, double px_per_mm, const char *path, lw_error *err)
{
  lw_strokes *s = checked_strokes(sp, page, plot, tone, path, err);
  if (!s) return err ? err->code : LW_EINPUT;
  lw_status st = lw_output_png_strokes(s, page, tone, px_per_mm, path, err);
  lw_strokes_free(s);
  return st;
}

lw_status lw_output_frame(const char *dir, long sweep, const lw_splines *sp, const lw_output_page *page,
                          const lw_plot *plot, const lw_grid2d *tone, double px_per_mm, lw_error *err)
{
  char path[LW_OUTPUT_PATH_MAX];
  if (lw_output_subdir(dir, "frames", path, sizeof path, err)) return err->code;
  size_t n = strlen(path);
  snprintf(path + n, sizeof path - n, "/frame-%06ld.png", sweep);
  return lw_output_png(sp, page, plot, tone, px_per_mm, path, err);
}

/* ---- PDF -------------------------------------------------------------- */

lw_status lw_output_pdf_strokes(const lw_strokes *st, const lw_output_page *page, const lw_grid2d *tone,
                                const char *path, lw_error *err)
{
  lw_status s = lw_output_check_strokes(st, page, tone, path, err);
  if (s) return s;
  char tmp[LW_OUTPUT_PATH_MAX];
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) return err ? err->code : LW_EIO;
  const double pt_per_mm = 72.0 / 25.4;
  file_sink k = {f, 0};
  errno = 0;
  cairo_surface_t *surf = cairo_pdf_surface_create_for_stream(file_write, &k, page->width_mm * pt_per_mm,
                                                              page->height_mm * pt_per_mm);
  /* An empty date leaves /CreationDate out: otherwise every run would
  ** differ from the last. */
  cairo_pdf_surface_set_metadata(surf, CAIRO_PDF_METADATA_CREATE_DATE, "");
  cairo_t *cr = cairo_create(surf);
  cairo_scale(cr, pt_per_mm, pt_per_mm);
  draw(cr, st, page, tone, PDF_BATCH);
  cairo_status_t cs = cairo_status(cr);
  cairo_destroy(cr);
  /* finishing writes the document; stream errors show up only now */
  cairo_surface_finish(surf);
  if (!cs) cs = cairo_surface_status(surf);
  cairo_surface_destroy(surf);
  if (cs) {
    lw_output_abort(f, tmp);
    return lw_error_set(err, cs == CAIRO_STATUS_WRITE_ERROR ? LW_EIO : LW_ERUN, "%s: writing the PDF failed: %s",
                        path, k.error ? strerror(k.error) : cairo_status_to_string(cs));
  }
  return lw_output_commit(f, tmp, path, err);
}

lw_status lw_output_pdf(const lw_splines *sp, const lw_output_page *page, const lw_plot *plot,
                        const lw_grid2d *tone, const char *path, lw_error *err)
{
  lw_strokes *s = checked_strokes(sp, page, plot, tone, path, err);
  if (!s) return err ? err->code : LW_EINPUT;
  lw_status st = lw_output_pdf_strokes(s, page, tone, path, err);
  lw_strokes_free(s);
  return st;
}
