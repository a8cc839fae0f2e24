/* test_output.c -- plotter SVG with pens and order, PNG and PDF previews,
** frames, atomic writes, JSON writer. */
#include <cairo.h>
#include <criterion/criterion.h>
#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "linewise/json.h"
#include "linewise/output.h"
#include "linewise/strokes.h"
#include "testutil.h"

/* SVG numbers have 4 decimals: within 5e-5 mm, plus slack for the double
** arithmetic of b1 and b2. */
#define SVG_TOL (0.5e-4 + 1e-9)

static void make_dir(char *dir)
{
  lw_test_tmp_name(dir, "output");
  cr_assert_not_null(mkdtemp(dir));
}

/* Whole file as a NUL-terminated string (NULL if it cannot be read). */
static char *slurp(const char *path, size_t *len)
{
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  rewind(f);
  char *s = malloc((size_t)n + 1);
  cr_assert_not_null(s);
  cr_assert_eq(fread(s, 1, (size_t)n, f), (size_t)n);
  s[n] = '\0';
  fclose(f);
  if (len) *len = (size_t)n;
  return s;
}

static void write_text(const char *path, const char *text)
{
  FILE *f = fopen(path, "w");
  cr_assert_not_null(f);
  fputs(text, f);
  fclose(f);
}

/* Files in dir whose names end in ".tmp". */
static int count_tmp(const char *dir)
{
  DIR *d = opendir(dir);
  cr_assert_not_null(d);
  int n = 0;
  struct dirent *e;
  while ((e = readdir(d))) {
    size_t l = strlen(e->d_name);
    if (l >= 4 && !strcmp(e->d_name + l - 4, ".tmp")) n++;
  }
  closedir(d);
  return n;
}

/* Removes the files of dir, then dir (tests leave no files behind). */
static void remove_dir(const char *dir)
{
  DIR *d = opendir(dir);
  if (!d) return;
  struct dirent *e;
  char p[512];
  while ((e = readdir(d))) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
    if (remove(p)) rmdir(p);
  }
  closedir(d);
  rmdir(dir);
}

/* Value of attribute name="..." after position s, as a double. */
static double attr_num(const char *s, const char *name)
{
  char key[64];
  snprintf(key, sizeof key, " %s=\"", name);
  const char *a = strstr(s, key);
  cr_assert_not_null(a, "attribute %s present", name);
  return strtod(a + strlen(key), NULL);
}

/* Splines: 0 straight (3 segments), 1 a Bezier circle (8 segments), 2 all
** zero (a point: skipped). */
static lw_splines *two_splines(void)
{
  size_t segs[3] = {3, 8, 2};
  lw_splines *sp = lw_splines_new(3, segs, NULL);
  cr_assert_not_null(sp);
  lw_test_straight(sp, 0, 10.123456, 20.5, 190.987654, 250.25);
  lw_test_circle(sp, 1, 105.0, 148.5, 61.7);
  return sp;
}

Test(output, svg_paths_are_the_exact_bezier_segments)
{
  char dir[64], path[128];
  make_dir(dir);
  snprintf(path, sizeof path, "%s/drawing.svg", dir);
  lw_splines *sp = two_splines();
  lw_output_page page;
  lw_output_page_init(&page, 210, 297);
  page.pen[0].width_mm = 0.35;
  lw_error err;
  lw_error_clear(&err);
  cr_assert_eq(lw_output_svg(sp, &page, NULL, path, &err), LW_OK, "%s", err.msg);
  char *svg = slurp(path, NULL);
  cr_assert_not_null(svg);

  /* page in mm, user units mm; integers printed without decimals */
  cr_assert_not_null(strstr(svg, "version=\"1.1\""));
  cr_assert_not_null(strstr(svg, " width=\"210mm\""), "%s", svg);
  cr_assert_not_null(strstr(svg, " height=\"297mm\""));
  cr_assert_not_null(strstr(svg, " viewBox=\"0 0 210 297\""));
  /* Inkscape layer, namespace declared */
  cr_assert_not_null(strstr(svg, "xmlns:inkscape=\"http://www.inkscape.org/namespaces/inkscape\""));
  const char *layer = strstr(svg, "<g inkscape:groupmode=\"layer\" inkscape:label=\"1 pen\" id=\"pen1\">");
  cr_assert_not_null(layer);
  cr_assert_not_null(strstr(layer, "</g>"));

  size_t n_paths = 0;
  const char *at = svg;
  while ((at = strstr(at, "<path"))) {
    cr_assert(at > layer && at < strstr(layer, "</g>"), "path inside the layer");
    size_t i = n_paths == 0 ? 0 : 1;  /* spline 2 (zero length) must not appear */
    cr_assert(n_paths < 2, "the zero-length spline is skipped");
    const char *close = strstr(at, "/>");
    cr_assert_not_null(close);
    cr_assert(fabs(attr_num(at, "stroke-width") - 0.35) < 1e-12, "stroke-width is the pen width");
    cr_assert_not_null(strstr(at, "fill=\"none\""));
    cr_assert_not_null(strstr(at, "stroke-linecap=\"round\""));
    const char *d = strstr(at, " d=\"");
    cr_assert(d && d < close);
    d += 4;
    const char *dend = strchr(d, '"');
    cr_assert_not_null(dend);
    /* only M and C commands, no polyline or exponent */
    size_t nM = 0, nC = 0;
    for (const char *c = d; c < dend; c++) {
      cr_assert(*c != 'L' && *c != 'l' && *c != 'e' && *c != 'E', "unexpected '%c' in path data", *c);
      nM += *c == 'M';
      nC += *c == 'C';
    }
    size_t n = lw_splines_segments(sp, i);
    cr_assert_eq(nM, 1);
    cr_assert_eq(nC, n, "spline %zu: %zu C commands for %zu segments", i, nC, n);

    const char *c = d;
    int used;
    double x, y;
    cr_assert_eq(sscanf(c, " M %lf %lf%n", &x, &y, &used), 2);
    c += used;
    const lw_node *nd = &sp->node[sp->first[i]];
    cr_assert(fabs(x - nd[0].px) <= SVG_TOL && fabs(y - nd[0].py) <= SVG_TOL);
    for (size_t m = 0; m < n; m++) {
      double b[6];
      cr_assert_eq(sscanf(c, " C %lf %lf %lf %lf %lf %lf%n", &b[0], &b[1], &b[2], &b[3], &b[4], &b[5], &used), 6,
                   "spline %zu segment %zu", i, m);
      c += used;
      const double want[6] = {nd[m].px + nd[m].vx,         nd[m].py + nd[m].vy,
                              nd[m + 1].px - nd[m + 1].vx, nd[m + 1].py - nd[m + 1].vy,
                              nd[m + 1].px,                nd[m + 1].py};
      for (int k = 0; k < 6; k++)
        cr_assert(fabs(b[k] - want[k]) <= SVG_TOL, "spline %zu segment %zu value %d: %.6f vs %.6f", i, m, k,
                  b[k], want[k]);
    }
    cr_assert_eq(c, dend, "nothing after the last segment");
    n_paths++;
    at = close;
  }
  cr_assert_eq(n_paths, 2);
  cr_assert_eq(count_tmp(dir), 0);
  free(svg);
  lw_splines_free(sp);
  remove_dir(dir);
}

Test(output, svg_rejects_non_finite_nodes_and_keeps_the_old_file)
{
  char dir[64], path[128];
  make_dir(dir);
  snprintf(path, sizeof path, "%s/drawing.svg", dir);
  write_text(path, "old\n");
  lw_splines *sp = two_splines();
  sp->node[5].vy = NAN;
  lw_output_page page;
  lw_output_page_init(&page, 210, 297);
  lw_error err;
  cr_assert_eq(lw_output_svg(sp, &page, NULL, path, &err), LW_EINPUT);
  cr_assert_not_null(strstr(err.msg, "spline 1"), "%s", err.msg);
  char *s = slurp(path, NULL);
  cr_assert_str_eq(s, "old\n");
  cr_assert_eq(count_tmp(dir), 0);
  /* a pen that draws nothing */
  sp->node[5].vy = 0;
  page.pen[0].width_mm = 0;
  cr_assert_eq(lw_output_svg(sp, &page, NULL, path, &err), LW_EINPUT);
  cr_assert_not_null(strstr(err.msg, "pen 1 width"), "%s", err.msg);
  free(s);
  lw_splines_free(sp);
  remove_dir(dir);
}

/* Pixel (x, y) of an RGB24/ARGB32 image as grey 0..255 (mean of RGB). */
static int grey(cairo_surface_t *s, int x, int y)
{
  const unsigned char *data = cairo_image_surface_get_data(s);
  uint32_t px = *(const uint32_t *)(data + (size_t)y * cairo_image_surface_get_stride(s) + 4 * (size_t)x);
  return (int)(((px >> 16) & 255) + ((px >> 8) & 255) + (px & 255)) / 3;
}

Test(output, png_preview_pixels)
{
  char dir[64], path[128];
  make_dir(dir);
  snprintf(path, sizeof path, "%s/preview.png", dir);
  /* page 100 x 50 mm at 4 px/mm: 400 x 200 px.  A horizontal line at
  ** y = 25.125 mm runs along pixel row 100's centre (100.5 px); the pen of
  ** 0.5 mm covers rows 99.5..101.5 px, so the pixel is fully inked. */
  size_t segs[2] = {2, 8};
  lw_splines *sp = lw_splines_new(2, segs, NULL);
  lw_test_straight(sp, 0, 10, 25.125, 60, 25.125);
  lw_test_circle(sp, 1, 80, 25, 10);
  lw_output_page page;
  lw_output_page_init(&page, 100, 50);
  page.pen[0].width_mm = 0.5;
  lw_error err;
  lw_error_clear(&err);
  cr_assert_eq(lw_output_png(sp, &page, NULL, NULL, 4.0, path, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(count_tmp(dir), 0);

  size_t len;
  char *bytes = slurp(path, &len);
  cr_assert(bytes && len > 8);
  cr_assert(!memcmp(bytes, "\x89PNG\r\n\x1a\n", 8), "PNG signature");
  free(bytes);

  cairo_surface_t *img = cairo_image_surface_create_from_png(path);
  cr_assert_eq(cairo_surface_status(img), CAIRO_STATUS_SUCCESS);
  cr_assert_eq(cairo_image_surface_get_width(img), 400);
  cr_assert_eq(cairo_image_surface_get_height(img), 200);
  cairo_surface_flush(img);
  cr_assert(grey(img, 120, 100) < 40, "on the straight line: %d", grey(img, 120, 100));
  /* circle's rightmost point (90, 25) mm = (360, 100) px, and its top (80, 15) mm */
  cr_assert(grey(img, 359, 100) < 100 || grey(img, 360, 100) < 100, "on the circle");
  cr_assert(grey(img, 320, 60) < 100 || grey(img, 320, 59) < 100, "circle top");
  /* far from every line: white */
  cr_assert_eq(grey(img, 120, 20), 255);
  cr_assert_eq(grey(img, 320, 100), 255, "circle centre");
  cr_assert_eq(grey(img, 5, 190), 255);
  /* the end cap does not reach x = 65 mm */
  cr_assert_eq(grey(img, 260, 100), 255);
  cairo_surface_destroy(img);
  lw_splines_free(sp);
  remove_dir(dir);
}

/* The PNG writer (libpng, rows unfiltered: cairo's took 90 % of a run
** writing frames) gives back every pixel of the surface, colours and
** antialiasing included, as 8-bit RGB; a surface with alpha goes through
** cairo's writer as before. */
Test(output, png_surface_round_trips_every_pixel)
{
  char dir[64], path[128];
  make_dir(dir);
  snprintf(path, sizeof path, "%s/s.png", dir);
  const int w = 173, h = 61; /* a stride past the width */
  cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
  cairo_t *cr = cairo_create(s);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_set_line_width(cr, 1.3);
  for (int k = 0; k < 12; k++) {
    cairo_set_source_rgb(cr, (k % 3) / 2.0, (k % 4) / 3.0, (k % 5) / 4.0);
    cairo_move_to(cr, 3 + 13 * k, 2);
    cairo_curve_to(cr, 40 + 7 * k, 30, 9 * k, 50, 170 - 5 * k, 58);
    cairo_stroke(cr);
  }
  cairo_destroy(cr);
  lw_error err;
  lw_error_clear(&err);
  cr_assert_eq(lw_output_png_surface(s, path, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(count_tmp(dir), 0);
  size_t len;
  unsigned char *bytes = (unsigned char *)slurp(path, &len);
  cr_assert(bytes && len > 26 && bytes[24] == 8 && bytes[25] == 2, "8-bit RGB");
  free(bytes);
  cairo_surface_t *back = cairo_image_surface_create_from_png(path);
  cr_assert_eq(cairo_surface_status(back), CAIRO_STATUS_SUCCESS);
  cr_assert(cairo_image_surface_get_width(back) == w && cairo_image_surface_get_height(back) == h);
  cairo_surface_flush(s);
  int differ = 0, inked = 0;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      const uint32_t a = ((const uint32_t *)(const void *)(cairo_image_surface_get_data(s) +
                                                           y * cairo_image_surface_get_stride(s)))[x] & 0xffffff;
      const uint32_t b = ((const uint32_t *)(const void *)(cairo_image_surface_get_data(back) +
                                                           y * cairo_image_surface_get_stride(back)))[x] & 0xffffff;
      differ += a != b;
      inked += a != 0xffffff;
    }
  cr_assert_eq(differ, 0, "%d pixels differ", differ);
  cr_assert_gt(inked, 500, "the strokes drew");
  cairo_surface_destroy(back);
  cairo_surface_destroy(s);
  remove_dir(dir);
}

Test(output, png_size_is_capped)
{
  lw_output_page page;
  lw_output_page_init(&page, 1000, 500);
  int w, h;
  double k;
  cr_assert(lw_output_png_size(&page, 10.0, &w, &h, &k));
  cr_assert_eq(w, LW_OUTPUT_PNG_MAX_PX);
  cr_assert_eq(h, LW_OUTPUT_PNG_MAX_PX / 2);
  cr_assert(fabs(k - 4.096) < 1e-12);
  lw_output_page_init(&page, 210, 297);
  cr_assert(lw_output_png_size(&page, 2.0, &w, &h, &k));
  cr_assert(w == 420 && h == 594 && k == 2.0);
  cr_assert(!lw_output_png_size(&page, 0.0, &w, &h, &k));
  cr_assert(!lw_output_png_size(&page, NAN, &w, &h, &k));
  /* and a pixel at least on the longest side (1e-200 px/mm made cairo's
  ** matrix singular after the anneal) */
  cr_assert(lw_output_png_size(&page, 1e-200, &w, &h, &k));
  cr_assert(w == 1 && h == 1 && k == 1.0 / 297, "%d x %d at %g", w, h, k);

  /* and the file really has the capped size */
  char dir[64], path[128];
  make_dir(dir);
  snprintf(path, sizeof path, "%s/big.png", dir);
  size_t segs[1] = {1};
  lw_splines *sp = lw_splines_new(1, segs, NULL);
  lw_test_straight(sp, 0, 0, 0, 1000, 500);
  lw_output_page_init(&page, 1000, 500);
  lw_error err;
  cr_assert_eq(lw_output_png(sp, &page, NULL, NULL, 10.0, path, &err), LW_OK, "%s", err.msg);
  cairo_surface_t *img = cairo_image_surface_create_from_png(path);
  cr_assert_eq(cairo_image_surface_get_width(img), 4096);
  cr_assert_eq(cairo_image_surface_get_height(img), 2048);
  cairo_surface_destroy(img);
  lw_splines_free(sp);
  remove_dir(dir);
}

Test(output, atomic_write_missing_directory_fails_with_path)
{
  char dir[64], path[160];
  make_dir(dir);
  snprintf(path, sizeof path, "%s/no/such/dir/drawing.svg", dir);
  lw_splines *sp = two_splines();
  lw_output_page page;
  lw_output_page_init(&page, 210, 297);
  lw_error err;
  lw_error_clear(&err);
  cr_assert_eq(lw_output_svg(sp, &page, NULL, path, &err), LW_EIO);
  cr_assert_not_null(strstr(err.msg, path), "message names the path: %s", err.msg);
  lw_error_clear(&err);
  snprintf(path, sizeof path, "%s/no/preview.png", dir);
  cr_assert_eq(lw_output_png(sp, &page, NULL, NULL, 1.0, path, &err), LW_EIO);
  cr_assert_not_null(strstr(err.msg, path), "%s", err.msg);
  cr_assert_eq(count_tmp(dir), 0);
  lw_splines_free(sp);
  remove_dir(dir);
}

Test(output, atomic_write_replaces_an_existing_file)
{
  char dir[64], path[128];
  make_dir(dir);
  snprintf(path, sizeof path, "%s/drawing.svg", dir);
  write_text(path, "old content that is not an svg\n");
  lw_splines *sp = two_splines();
  lw_output_page page;
  lw_output_page_init(&page, 210, 297);
  lw_error err;
  cr_assert_eq(lw_output_svg(sp, &page, NULL, path, &err), LW_OK, "%s", err.msg);
  char *s = slurp(path, NULL);
  cr_assert(!strncmp(s, "<?xml", 5));
  cr_assert_null(strstr(s, "old content"));
  cr_assert_not_null(strstr(s, "</svg>\n"));
  cr_assert_eq(count_tmp(dir), 0);
  free(s);
  lw_splines_free(sp);
  remove_dir(dir);
}

Test(output, atomic_write_failed_rename_removes_tmp)
{
  /* The target is a directory: the temporary file is written but cannot be
  ** renamed over it.  The directory stays, the temporary file goes. */
  char dir[64], path[128];
  make_dir(dir);
  snprintf(path, sizeof path, "%s/drawing.svg", dir);
  cr_assert_eq(mkdir(path, 0700), 0);
  lw_splines *sp = two_splines();
  lw_output_page page;
  lw_output_page_init(&page, 210, 297);
  lw_error err;
  lw_error_clear(&err);
  cr_assert_eq(lw_output_svg(sp, &page, NULL, path, &err), LW_EIO);
  cr_assert_not_null(strstr(err.msg, path), "%s", err.msg);
  struct stat st;
  cr_assert_eq(stat(path, &st), 0);
  cr_assert(S_ISDIR(st.st_mode));
  cr_assert_eq(count_tmp(dir), 0);
  lw_splines_free(sp);
  remove_dir(dir);
}

/* A write that failed inside a large fwrite leaves the stream flagged with
** nothing for the flush to fail on: the commit named no cause ("I/O
** error"; linewise-mpi's state.lw on a full disk).  The cause is found from
** the file: here the size limit (the test's own process: Criterion forks
** one a test), as a full file system would be. */
Test(output, a_write_that_failed_long_before_the_commit_is_named)
{
  char dir[64], path[128], tmp[LW_OUTPUT_PATH_MAX];
  make_dir(dir);
  snprintf(path, sizeof path, "%s/state.lw", dir);
  signal(SIGXFSZ, SIG_IGN);
  struct rlimit r = {4096, RLIM_INFINITY};
  getrlimit(RLIMIT_FSIZE, &r);
  r.rlim_cur = 4096;
  cr_assert_eq(setrlimit(RLIMIT_FSIZE, &r), 0);
  lw_error err;
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, &err);
  cr_assert_not_null(f, "%s", err.msg);
  static char block[65536];
  memset(block, 'x', sizeof block);
  cr_assert_lt(fwrite(block, 1, sizeof block, f), sizeof block);
  cr_assert_eq(lw_output_commit(f, tmp, path, &err), LW_EIO);
  cr_assert(strstr(err.msg, "state.lw: write failed: File too large"), "%s", err.msg);
  cr_assert_eq(count_tmp(dir), 0);
  remove_dir(dir);
}

Test(output, open_tmp_and_commit_for_text_files)
{
  char dir[64], path[128], tmp[LW_OUTPUT_PATH_MAX];
  make_dir(dir);
  snprintf(path, sizeof path, "%s/trace.csv", dir);
  write_text(path, "old\n");
  lw_error err;
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, &err);
  cr_assert_not_null(f, "%s", err.msg);
  fputs("sweep,energy\n1,2.5\n", f);
  /* until the commit, readers see the old file */
  char *s = slurp(path, NULL);
  cr_assert_str_eq(s, "old\n");
  free(s);
  cr_assert_eq(count_tmp(dir), 1);
  cr_assert_eq(lw_output_commit(f, tmp, path, &err), LW_OK, "%s", err.msg);
  s = slurp(path, NULL);
  cr_assert_str_eq(s, "sweep,energy\n1,2.5\n");
  free(s);
  cr_assert_eq(count_tmp(dir), 0);
  /* abort leaves the old file */
  f = lw_output_open_tmp(path, tmp, sizeof tmp, &err);
  fputs("half", f);
  lw_output_abort(f, tmp);
  s = slurp(path, NULL);
  cr_assert_str_eq(s, "sweep,energy\n1,2.5\n");
  free(s);
  cr_assert_eq(count_tmp(dir), 0);
  /* a temporary name that does not fit */
  char small[8];
  cr_assert_null(lw_output_open_tmp(path, small, sizeof small, &err));
  cr_assert_eq(err.code, LW_EIO);
  remove_dir(dir);
}

/* ---- JSON ----------------------------------------------------------- */

/* Runs the writer into a memory buffer; returns the text (caller frees). */
typedef struct {
  FILE *f;
  char *buf;
  size_t len;
  lw_json j;
} json_buf;

static void json_open(json_buf *b)
{
  b->f = open_memstream(&b->buf, &b->len);
  cr_assert_not_null(b->f);
  lw_json_init(&b->j, b->f);
}

static char *json_close(json_buf *b, lw_status want)
{
  lw_error err;
  lw_error_clear(&err);
  cr_assert_eq(lw_json_finish(&b->j, &err), want, "%s", err.msg);
  fclose(b->f);
  return b->buf;
}

Test(output, json_nested_exact_text)
{
  json_buf b;
  json_open(&b);
  lw_json *j = &b.j;
  lw_json_begin_object(j);
  lw_json_key(j, "name");
  lw_json_string(j, "run");
  lw_json_key(j, "sweeps");
  lw_json_int(j, 1000);
  lw_json_key(j, "energy");
  lw_json_begin_object(j);
  lw_json_key(j, "total");
  lw_json_number(j, 1.5);
  lw_json_key(j, "terms");
  lw_json_begin_array(j);
  lw_json_number(j, 0.1);
  lw_json_number(j, -2e-300);
  lw_json_begin_array(j);
  lw_json_end_array(j);
  lw_json_begin_object(j);
  lw_json_end_object(j);
  lw_json_end_array(j);
  lw_json_end_object(j);
  lw_json_key(j, "ok");
  lw_json_bool(j, 1);
  lw_json_key(j, "failed");
  lw_json_bool(j, 0);
  lw_json_key(j, "none");
  lw_json_null(j);
  lw_json_end_object(j);
  char *s = json_close(&b, LW_OK);
  cr_assert_str_eq(s,
                   "{\n"
                   "  \"name\": \"run\",\n"
                   "  \"sweeps\": 1000,\n"
                   "  \"energy\": {\n"
                   "    \"total\": 1.5,\n"
                   "    \"terms\": [\n"
                   "      0.10000000000000001,\n"
                   "      -2.0000000000000001e-300,\n"
                   "      [],\n"
                   "      {}\n"
                   "    ]\n"
                   "  },\n"
                   "  \"ok\": true,\n"
                   "  \"failed\": false,\n"
                   "  \"none\": null\n"
                   "}\n");
  /* %.17g reads back exactly */
  cr_assert_eq(strtod("0.10000000000000001", NULL), 0.1);
  free(s);
}

Test(output, json_escapes_and_non_finite)
{
  json_buf b;
  json_open(&b);
  lw_json *j = &b.j;
  lw_json_begin_array(j);
  lw_json_string(j, "a\"b\\c\nd\te\x01/\xc3\xa9");
  lw_json_number(j, NAN);
  lw_json_number(j, INFINITY);
  lw_json_number(j, -INFINITY);
  lw_json_int(j, -9223372036854775807LL);
  lw_json_end_array(j);
  char *s = json_close(&b, LW_OK);
  cr_assert_str_eq(s,
                   "[\n"
                   "  \"a\\\"b\\\\c\\nd\\te\\u0001/\xc3\xa9\",\n"
                   "  null,\n"
                   "  null,\n"
                   "  null,\n"
                   "  -9223372036854775807\n"
                   "]\n");
  free(s);

  /* bytes that are not UTF-8 (a Latin-1 file name, a stray continuation
  ** byte, an overlong '/', a surrogate, a sequence cut short) as U+FFFD, one
  ** a byte; well-formed sequences of 2 to 4 bytes kept */
  json_open(&b);
  lw_json_string(&b.j, "latin\xfc \x80 \xc0\xaf \xed\xa0\x80 \xe2\x82 \xe2\x82\xac \xf0\x9f\x96\x8a");
  s = json_close(&b, LW_OK);
  cr_assert_str_eq(s, "\"latin\\ufffd \\ufffd \\ufffd\\ufffd \\ufffd\\ufffd\\ufffd \\ufffd\\ufffd "
                      "\xe2\x82\xac \xf0\x9f\x96\x8a\"\n");
  free(s);

  /* keys are escaped too */
  json_open(&b);
  lw_json_begin_object(&b.j);
  lw_json_key(&b.j, "k\"");
  lw_json_int(&b.j, 1);
  lw_json_end_object(&b.j);
  s = json_close(&b, LW_OK);
  cr_assert_str_eq(s, "{\n  \"k\\\"\": 1\n}\n");
  free(s);
}

Test(output, json_misuse_is_reported)
{
  json_buf b;
  /* key inside an array */
  json_open(&b);
  lw_json_begin_array(&b.j);
  lw_json_key(&b.j, "x");
  lw_json_end_array(&b.j);
  free(json_close(&b, LW_ERUN));
  /* value in an object without a key */
  json_open(&b);
  lw_json_begin_object(&b.j);
  lw_json_int(&b.j, 1);
  lw_json_end_object(&b.j);
  free(json_close(&b, LW_ERUN));
  /* mismatched end */
  json_open(&b);
  lw_json_begin_object(&b.j);
  lw_json_end_array(&b.j);
  free(json_close(&b, LW_ERUN));
  /* left open */
  json_open(&b);
  lw_json_begin_object(&b.j);
  lw_json_key(&b.j, "a");
  lw_json_begin_array(&b.j);
  free(json_close(&b, LW_ERUN));
  /* key without value */
  json_open(&b);
  lw_json_begin_object(&b.j);
  lw_json_key(&b.j, "a");
  lw_json_end_object(&b.j);
  free(json_close(&b, LW_ERUN));
  /* too deep */
  json_open(&b);
  for (int i = 0; i <= LW_JSON_MAX_DEPTH; i++) lw_json_begin_array(&b.j);
  free(json_close(&b, LW_ERUN));
  /* a second top-level value */
  json_open(&b);
  lw_json_int(&b.j, 1);
  lw_json_int(&b.j, 2);
  free(json_close(&b, LW_ERUN));
}

/* ---- pens, order, PDF, frames ----------------------------------------- */

/* The d attribute of the path with id="<id>" (caller frees). */
static char *path_data(const char *svg, const char *id)
{
  char key[64];
  snprintf(key, sizeof key, "<path id=\"%s\"", id);
  const char *at = strstr(svg, key);
  cr_assert_not_null(at, "path %s present", id);
  const char *d = strstr(at, " d=\"");
  cr_assert_not_null(d);
  d += 4;
  size_t n = strcspn(d, "\"");
  char *s = malloc(n + 1);
  memcpy(s, d, n);
  s[n] = '\0';
  return s;
}

/* The numbers of a path's data, commands dropped; returns the count. */
static size_t path_numbers(char *d, char **tok, size_t max)
{
  size_t n = 0;
  for (char *t = strtok(d, " "); t; t = strtok(NULL, " "))
    if (strcmp(t, "M") && strcmp(t, "C")) {
      cr_assert(n < max);
      tok[n++] = t;
    }
  return n;
}

Test(output, svg_pens_are_layers_and_reversed_paths_are_exact)
{
  char dir[64], fwd_path[128], plot_path[128];
  make_dir(dir);
  snprintf(fwd_path, sizeof fwd_path, "%s/forward.svg", dir);
  snprintf(plot_path, sizeof plot_path, "%s/plot.svg", dir);
  lw_splines *sp = two_splines();
  lw_output_page page;
  lw_output_page_init(&page, 210, 297);
  lw_error err;
  cr_assert_eq(lw_output_svg(sp, &page, NULL, fwd_path, &err), LW_OK, "%s", err.msg);
  /* pen 1: the circle reversed; pen 2: the straight line forward; pen 3
  ** draws nothing and still has its layer */
  page.n_pens = 3;
  page.pen[0] = (lw_output_pen){0.35, {0, 0, 0}};
  page.pen[1] = (lw_output_pen){0.7, {0xcc, 0x00, 0x11}};
  page.pen[2] = (lw_output_pen){1.25, {0x12, 0xab, 0xef}};
  size_t order[2] = {1, 0};
  unsigned char rev[2] = {1, 0};
  lw_plot pl = {.n = 2, .spline = order, .reversed = rev, .n_pens = 3, .pen_first = {0, 1, 2, 2}};
  cr_assert_eq(lw_output_svg(sp, &page, &pl, plot_path, &err), LW_OK, "%s", err.msg);
  char *fwd = slurp(fwd_path, NULL), *svg = slurp(plot_path, NULL);

  const char *l1 = strstr(svg, "<g inkscape:groupmode=\"layer\" inkscape:label=\"1 pen\" id=\"pen1\">");
  const char *l2 = strstr(svg, "<g inkscape:groupmode=\"layer\" inkscape:label=\"2 pen\" id=\"pen2\">");
  const char *l3 = strstr(svg, "<g inkscape:groupmode=\"layer\" inkscape:label=\"3 pen\" id=\"pen3\">");
  cr_assert(l1 && l2 && l3 && l1 < l2 && l2 < l3, "three layers in pen order:\n%s", svg);
  const char *p1 = strstr(svg, "<path id=\"spline1\""), *p0 = strstr(svg, "<path id=\"spline0\"");
  cr_assert(p1 > l1 && p1 < l2 && p0 > l2 && p0 < l3, "each path in its pen's layer");
  cr_assert(!strncmp(strstr(l3, ">") + 1, "\n  </g>\n</svg>\n", 14), "pen 3's layer is empty");
  cr_assert_not_null(strstr(p1, "stroke=\"#000000\" stroke-width=\"0.35\""));
  cr_assert_not_null(strstr(p0, "stroke=\"#cc0011\" stroke-width=\"0.7\""));
  cr_assert_null(strstr(svg, "spline2"), "the point is left out");

  /* the straight line is unchanged, the circle's numbers come reversed
  ** point by point, as the very same strings */
  char *a = path_data(fwd, "spline0"), *b = path_data(svg, "spline0");
  cr_assert_str_eq(a, b);
  free(a);
  free(b);
  a = path_data(fwd, "spline1");
  b = path_data(svg, "spline1");
  cr_assert_eq(strncmp(b, "M ", 2), 0);
  char *ta[64], *tb[64];
  size_t na = path_numbers(a, ta, 64), nb = path_numbers(b, tb, 64);
  cr_assert_eq(na, 2 * (3 * 8 + 1), "M point and 3 points per segment");
  cr_assert_eq(na, nb);
  for (size_t k = 0; k < na / 2; k++) {
    size_t j = na / 2 - 1 - k;
    cr_assert(!strcmp(ta[2 * j], tb[2 * k]) && !strcmp(ta[2 * j + 1], tb[2 * k + 1]),
              "point %zu: %s %s vs %s %s", k, ta[2 * j], ta[2 * j + 1], tb[2 * k], tb[2 * k + 1]);
  }
  free(a);
  free(b);

  /* a plot with other pens than the page is refused */
  page.n_pens = 2;
  cr_assert_eq(lw_output_svg(sp, &page, &pl, plot_path, &err), LW_EINPUT);
  free(fwd);
  free(svg);
  lw_splines_free(sp);
  remove_dir(dir);
}

Test(output, colors_parse)
{
  unsigned char rgb[4][3];
  cr_assert(lw_output_color_parse("#c01", 4, rgb[0]));
  cr_assert(rgb[0][0] == 0xcc && rgb[0][1] == 0x00 && rgb[0][2] == 0x11);
  cr_assert(lw_output_color_parse("#C0fFeE", 7, rgb[0]));
  cr_assert(rgb[0][0] == 0xc0 && rgb[0][1] == 0xff && rgb[0][2] == 0xee);
  cr_assert(!lw_output_color_parse("red", 3, rgb[0]));
  cr_assert(!lw_output_color_parse("#12", 3, rgb[0]));
  cr_assert(!lw_output_color_parse("#12345g", 7, rgb[0]));
  cr_assert_eq(lw_output_colors_parse(" #000 #fff,#123456\t", rgb, 4), 3);
  cr_assert(rgb[2][0] == 0x12 && rgb[2][1] == 0x34 && rgb[2][2] == 0x56 && rgb[1][1] == 0xff);
  cr_assert_eq(lw_output_colors_parse("", rgb, 4), 0);
  cr_assert_eq(lw_output_colors_parse("#000 #000 #000 #000 #000", rgb, 4), -1);
  cr_assert_eq(lw_output_colors_parse("#000 black", rgb, 4), -1);
}

/* RGB of pixel (x, y). */
static void pixel(cairo_surface_t *s, int x, int y, int rgb[3])
{
  const unsigned char *data = cairo_image_surface_get_data(s);
  uint32_t px = *(const uint32_t *)(data + (size_t)y * cairo_image_surface_get_stride(s) + 4 * (size_t)x);
  rgb[0] = (px >> 16) & 255;
  rgb[1] = (px >> 8) & 255;
  rgb[2] = px & 255;
}

Test(output, png_pen_colours_and_tone_underneath)
{
  char dir[64], path[128];
  make_dir(dir);
  snprintf(path, sizeof path, "%s/preview.png", dir);
  /* page 100 x 50 mm at 4 px/mm; two horizontal lines through pixel row
  ** centres (see png_preview_pixels): pen 1 black at y = 10.125 mm, pen 2
  ** red at y = 40.125 mm */
  size_t segs[2] = {1, 1};
  lw_splines *sp = lw_splines_new(2, segs, NULL);
  lw_test_straight(sp, 0, 5, 10.125, 95, 10.125);
  lw_test_straight(sp, 1, 5, 40.125, 95, 40.125);
  lw_output_page page;
  lw_output_page_init(&page, 100, 50);
  page.n_pens = 2;
  page.pen[0] = (lw_output_pen){0.5, {0, 0, 0}};
  page.pen[1] = (lw_output_pen){0.5, {255, 0, 0}};
  size_t order[2] = {0, 1};
  unsigned char rev[2] = {0, 1};
  lw_plot pl = {.n = 2, .spline = order, .reversed = rev, .n_pens = 2, .pen_first = {0, 1, 2}};
  /* tone: two pixels of 25 x 50 mm covering x in [0, 50] mm, black then
  ** white; the right half of the page has no tone */
  lw_grid2d *tone = lw_grid2d_new(2, 1, 1, 12.5, 25, 25, 50, NULL);
  tone->data[0] = 0.0;
  tone->data[1] = 1.0;
  lw_error err;
  cr_assert_eq(lw_output_png(sp, &page, &pl, tone, 4.0, path, &err), LW_OK, "%s", err.msg);
  cairo_surface_t *img = cairo_image_surface_create_from_png(path);
  cr_assert_eq(cairo_surface_status(img), CAIRO_STATUS_SUCCESS);
  cairo_surface_flush(img);
  int c[3];
  pixel(img, 320, 40, c); /* on the black line, no tone there */
  cr_assert(c[0] < 40 && c[1] < 40 && c[2] < 40, "black line %d %d %d", c[0], c[1], c[2]);
  pixel(img, 320, 160, c); /* on the red line */
  cr_assert(c[0] > 215 && c[1] < 40 && c[2] < 40, "red line %d %d %d", c[0], c[1], c[2]);
  /* black tone at half strength: 255 (1 - 0.5) = 127.5 */
  pixel(img, 40, 100, c);
  cr_assert(abs(c[0] - 128) <= 1 && c[0] == c[1] && c[1] == c[2], "black tone under: %d", c[0]);
  pixel(img, 0, 100, c); /* the raster's edge does not fade into the paper */
  cr_assert(abs(c[0] - 128) <= 1, "edge of the tone: %d", c[0]);
  pixel(img, 190, 100, c); /* white tone, past its pixel centre */
  cr_assert_eq(c[0], 255);
  pixel(img, 300, 100, c); /* no tone */
  cr_assert_eq(c[0], 255);
  cairo_surface_destroy(img);
  lw_grid2d_free(tone);
  lw_splines_free(sp);
  remove_dir(dir);
}

/* cairo (final.pdf, the PNG, the fidelity raster) draws a path the way the
** plotter does: a reversed one from its end, its segments' control points
** backwards.  final.pdf once kept the order but not the directions, and a
** plot from it travelled up to 4 times as far as final.svg's. */
Test(output, cairo_paths_follow_the_plotters_direction)
{
  lw_error err;
  lw_strokes *st = lw_strokes_new(1, &err);
  cr_assert_not_null(st);
  const double b[16] = {0, 0, 1, 2, 3, 2, 4, 0, 4, 0, 5, -2, 7, -2, 8, 0};
  cr_assert_eq(lw_strokes_add(st, 0, 0, 0, 1, b, 2, &err), LW_OK);
  cr_assert_eq(lw_strokes_add(st, 0, 1, 0, 0, b, 2, &err), LW_OK);
  cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_A8, 4, 4);
  cairo_t *cr = cairo_create(surf);
  for (size_t k = 0; k < 2; k++) {
    lw_output_cairo_path(cr, st, k);
    cairo_path_t *path = cairo_copy_path(cr);
    cr_assert_eq(path->status, CAIRO_STATUS_SUCCESS);
    /* move_to (2 slots) and two curve_to (4 slots each) */
    cr_assert_eq(path->num_data, 10);
    const cairo_path_data_t *d = path->data;
    cr_assert_eq(d[0].header.type, CAIRO_PATH_MOVE_TO);
    cr_assert_eq(d[2].header.type, CAIRO_PATH_CURVE_TO);
    /* the points in drawing order: b's 8 points forwards, or backwards */
    const int at[7] = {1, 3, 4, 5, 7, 8, 9};
    for (int i = 0; i < 7; i++) {
      int src = k ? i + (i > 3) : 7 - i - (i > 3);
      cr_assert_float_eq(d[at[i]].point.x, b[2 * src], 1e-12, "path %zu point %d", k, i);
      cr_assert_float_eq(d[at[i]].point.y, b[2 * src + 1], 1e-12, "path %zu point %d", k, i);
    }
    cairo_path_destroy(path);
    cairo_new_path(cr);
  }
  cairo_destroy(cr);
  cairo_surface_destroy(surf);
  lw_strokes_free(st);
}

/* needle in the n bytes at hay, which may hold NULs (memmem is not C11). */
static const char *find_bytes(const char *hay, size_t n, const char *needle)
{
  size_t m = strlen(needle);
  for (size_t k = 0; k + m <= n; k++)
    if (!memcmp(hay + k, needle, m)) return hay + k;
  return NULL;
}

Test(output, pdf_has_the_page_size_and_is_reproducible)
{
  char dir[64], a[128], b[128];
  make_dir(dir);
  snprintf(a, sizeof a, "%s/a.pdf", dir);
  snprintf(b, sizeof b, "%s/b.pdf", dir);
  lw_splines *sp = two_splines();
  lw_output_page page;
  lw_output_page_init(&page, 210, 297);
  lw_error err;
  cr_assert_eq(lw_output_pdf(sp, &page, NULL, NULL, a, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(lw_output_pdf(sp, &page, NULL, NULL, b, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(count_tmp(dir), 0);
  size_t la, lb;
  char *pa = slurp(a, &la), *pb = slurp(b, &lb);
  cr_assert(la > 200 && !strncmp(pa, "%PDF-", 5), "a PDF file");
  cr_assert(la == lb && !memcmp(pa, pb, la), "the same drawing gives the same bytes");
  cr_assert_null(find_bytes(pa, la, "/CreationDate"));
  /* A4 in points: 210 and 297 mm times 72 / 25.4 */
  const char *mb = find_bytes(pa, la, "/MediaBox ["); /* the file holds binary streams */
  cr_assert_not_null(mb);
  double x0, y0, x1, y1;
  cr_assert_eq(sscanf(mb + 11, "%lf %lf %lf %lf", &x0, &y0, &x1, &y1), 4);
  cr_assert(x0 == 0 && y0 == 0);
  cr_assert(fabs(x1 - 210 * 72 / 25.4) < 1e-3 && fabs(y1 - 297 * 72 / 25.4) < 1e-3, "MediaBox %g %g", x1, y1);
  free(pa);
  free(pb);
  /* more paths than a batch of strokes (PDF_BATCH): the same bytes again,
  ** and a whole file (the batches took the page from minutes at 10,000
  ** paths to seconds: docs/PERFORMANCE.md) */
  {
    size_t segs[2500];
    for (size_t k = 0; k < 2500; k++) segs[k] = 1;
    lw_splines *many = lw_splines_new(2500, segs, NULL);
    cr_assert_not_null(many);
    for (size_t k = 0; k < 2500; k++)
      lw_test_straight(many, k, 10 + (double)(k % 50) * 3.8, 10 + (double)(k / 50) * 5, 12 + (double)(k % 50) * 3.8,
                       13 + (double)(k / 50) * 5);
    cr_assert_eq(lw_output_pdf(many, &page, NULL, NULL, a, &err), LW_OK, "%s", err.msg);
    cr_assert_eq(lw_output_pdf(many, &page, NULL, NULL, b, &err), LW_OK, "%s", err.msg);
    pa = slurp(a, &la);
    pb = slurp(b, &lb);
    cr_assert(la == lb && !memcmp(pa, pb, la), "the same drawing gives the same bytes");
    cr_assert(la > 1000 && !strncmp(pa, "%PDF-", 5) && find_bytes(pa + la - 8, 8, "%%EOF"), "a whole PDF file");
    free(pa);
    free(pb);
    lw_splines_free(many);
  }
  /* bad input is refused before a file exists */
  sp->node[2].px = INFINITY;
  cr_assert_eq(lw_output_pdf(sp, &page, NULL, NULL, a, &err), LW_EINPUT);
  snprintf(a, sizeof a, "%s/missing/a.pdf", dir);
  sp->node[2].px = 1;
  cr_assert_eq(lw_output_pdf(sp, &page, NULL, NULL, a, &err), LW_EIO);
  lw_splines_free(sp);
  remove_dir(dir);
}

Test(output, frames_are_numbered_by_sweep)
{
  char dir[64], path[192];
  make_dir(dir);
  lw_splines *sp = two_splines();
  lw_output_page page;
  lw_output_page_init(&page, 210, 297);
  lw_error err;
  cr_assert_eq(lw_output_frame(dir, 12, sp, &page, NULL, NULL, 0.5, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(lw_output_frame(dir, 1234567, sp, &page, NULL, NULL, 0.5, &err), LW_OK, "%s", err.msg);
  const char *names[2] = {"frame-000012.png", "frame-1234567.png"};
  for (int k = 0; k < 2; k++) {
    snprintf(path, sizeof path, "%s/frames/%s", dir, names[k]);
    size_t len;
    char *bytes = slurp(path, &len);
    cr_assert(bytes && len > 8 && !memcmp(bytes, "\x89PNG", 4), "%s written", names[k]);
    free(bytes);
    remove(path);
  }
  snprintf(path, sizeof path, "%s/frames", dir);
  rmdir(path);
  lw_splines_free(sp);
  remove_dir(dir);
}
