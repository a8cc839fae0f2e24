/* test_params.c -- the parameter table, INI reading, overrides and errors. */
#include <criterion/criterion.h>
#include <ini.h>
#include <locale.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "linewise/anneal.h"
#include "linewise/ckpt.h"
#include "linewise/driver.h"
#include "linewise/number.h"
#include "linewise/params.h"
#include "linewise/rundir.h"
#include "linewise/scene.h"
#include "linewise/schedule.h"
#include "linewise/system.h"
#include "linewise/trace.h"
#include "testutil.h"

/* Writes text to a fresh temporary file; returns its path (static buffer). */
static const char *ini(const char *text)
{
  static char path[64];
  lw_test_tmp_name(path, "params");
  int fd = mkstemp(path);
  cr_assert(fd >= 0);
  FILE *f = fdopen(fd, "w");
  fputs(text, f);
  fclose(f);
  return path;
}

static lw_status read_text(const char *text, lw_params *p, lw_error *err)
{
  const char *path = ini(text);
  lw_status s = lw_params_read(p, path, err);
  unlink(path);
  return s;
}

Test(params, defaults_cover_every_key_and_read_back)
{
  lw_params p, q;
  lw_params_defaults(&p);
  cr_assert_eq(p.quadrature, 8);
  cr_assert_eq(p.width, 210);
  /* write every value and read it back */
  char path[64];
  lw_test_tmp_name(path, "params_rt");
  int fd = mkstemp(path);
  FILE *f = fdopen(fd, "w");
  p.pair = 0.125;
  p.field = LW_FLD_WAVES;
  strcpy(p.polygon, "1 2 3 4 5 6");
  cr_assert_eq(lw_params_write(&p, f), 0);
  fclose(f);
  lw_error err;
  cr_assert_eq(lw_params_read(&q, path, &err), LW_OK, "%s", err.msg);
  unlink(path);
  for (size_t i = 0; i < lw_param_count; i++) {
    const lw_param_def *d = &lw_param_table[i];
    const char *a = (const char *)&p + d->offset, *b = (const char *)&q + d->offset;
    size_t n = d->type == LW_PT_DOUBLE || d->type == LW_PT_WHOLE ? sizeof(double)
               : d->type == LW_PT_STRING                            ? d->size
                                                                    : sizeof(int);
    cr_assert(!memcmp(a, b, n), "%s.%s differs after a round trip", d->section, d->key);
  }
}

/* inih's settings are the host program's: a scene read leaves them as they
** were (it left continuation lines off and parses stopped at the first
** error, for a program that embeds the library and reads its own files
** with inih) */
Test(params, a_scene_read_leaves_inihs_settings_as_they_were)
{
  ini_allow_multiline = true;
  ini_stop_on_first_error = false;
  static lw_params p;
  lw_error err;
  cr_assert_eq(read_text("[anneal]\nsweeps = 7\n", &p, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(p.sweeps, 7);
  cr_assert(ini_allow_multiline && !ini_stop_on_first_error);
  /* and a bad one too */
  cr_assert_neq(read_text("[anneal]\nsweeps = 7\n  typo\n", &p, &err), LW_OK);
  cr_assert(ini_allow_multiline && !ini_stop_on_first_error);
  ini_allow_multiline = false, ini_stop_on_first_error = true;
  cr_assert_neq(read_text("[anneal]\nsweeps = 7\n  typo\n", &p, &err), LW_OK);
  cr_assert(!ini_allow_multiline && ini_stop_on_first_error);
}

Test(params, reads_values_and_records_lines)
{
  lw_params p;
  lw_error err;
  cr_assert_eq(read_text("; a comment\n[scene]\nwidth = 120\n\n[energy]\npair = 0.5 ; inline\nquadrature=12\n", &p, &err),
               LW_OK, "%s", err.msg);
  cr_assert_eq(p.width, 120);
  cr_assert_eq(p.pair, 0.5);
  cr_assert_eq(p.quadrature, 12);
  const lw_param_def *d = lw_params_find("energy", "quadrature");
  char where[1100];
  lw_params_origin(&p, d, where, sizeof where);
  cr_assert(strstr(where, ":7"), "origin %s names line 7", where);
}

static void expect_error(const char *text, const char *line, const char *key, const char *expected)
{
  lw_params p;
  lw_error err;
  lw_error_clear(&err);
  cr_assert_eq(read_text(text, &p, &err), LW_EINPUT, "accepted: %s", text);
  cr_assert(strstr(err.msg, line), "message '%s' lacks line '%s'", err.msg, line);
  if (key) cr_assert(strstr(err.msg, key), "message '%s' lacks key '%s'", err.msg, key);
  if (expected) cr_assert(strstr(err.msg, expected), "message '%s' lacks '%s'", err.msg, expected);
}

/* Every number key's open end is refused at the end itself, by the range
** check (a step of 0 freezes its moves; an image_gamma of 0 is no curve). */
Test(params, every_open_end_of_a_range_is_refused_at_the_end)
{
  int checked = 0;
  for (size_t i = 0; i < lw_param_count; i++) {
    const lw_param_def *d = &lw_param_table[i];
    if (d->type != LW_PT_DOUBLE && d->type != LW_PT_INT && d->type != LW_PT_WHOLE) continue;
    for (int end = 0; end < 2; end++) {
      if (!(d->open & (end ? LW_MAX_OPEN : LW_MIN_OPEN))) continue;
      char text[256], key[96], range[64];
      snprintf(text, sizeof text, "[%s]\n%s = %.17g\n", d->section, d->key, end ? d->max : d->min);
      snprintf(key, sizeof key, "%s.%s", d->section, d->key);
      snprintf(range, sizeof range, end ? "< %.10g, got" : "> %.10g and", end ? d->max : d->min);
      expect_error(text, ":2:", key, range);
      checked++;
    }
  }
  cr_assert_gt(checked, 10, "only %d open ends", checked);
}

Test(params, bad_input_names_file_line_and_key)
{
  expect_error("[scene]\nwidth = 100\nwidht = 3\n", ":3:", "scene.widht", "not a parameter");
  /* a section header is judged on its own line, keys or none */
  expect_error("[scenery]\nwidth = 100\n", ":1:", "[scenery]", "unknown section");
  expect_error("[scene]\nwidth = 100\n[bogus]\n", ":3:", "[bogus]", "unknown section");
  expect_error("[scene]]\nwidth = 100\n", ":1:", "'[scene]]'", "expected a section header '[name]'");
  expect_error("[scene] junk\nwidth = 100\n", ":1:", "'[scene] junk'", "expected a section header");
  /* a typo, or a key in the wrong section: the message names the parameter
  ** meant; a name near none names none */
  expect_error("[scene]\nwidht = 3\n", ":2:", "scene.widht", "did you mean 'scene.width'?");
  expect_error("[anneal]\nquadrature = 6\n", ":2:", "anneal.quadrature", "did you mean 'energy.quadrature'?");
  expect_error("[energy]\npair_cuttoff = 2\n", ":2:", NULL, "did you mean 'energy.pair_cutoff'?");
  expect_error("[scene]\nWIDTH = 3\n", ":2:", "scene.WIDTH", "did you mean 'scene.width'?"); /* case aside */
  expect_error("[scen]\nwidth = 100\n", ":1:", "[scen]", "unknown section [scen]; did you mean [scene]?");
  expect_error("; a scene\nwidth = 100\n[scene]\n", ":2:", "'width'", "before any [section]; did you mean 'scene.width'?");
  for (int k = 0; k < 2; k++) {
    lw_params p;
    lw_error err;
    cr_assert_eq(read_text(k ? "[scene]\nfoo = 1\n" : "[nothing]\nwidth = 1\n", &p, &err), LW_EINPUT);
    cr_assert_null(strstr(err.msg, "did you mean"), "%s", err.msg);
  }
  lw_params q;
  lw_error err;
  lw_params_defaults(&q);
  cr_assert_eq(lw_params_set(&q, "init.segmentlength=3", &err), LW_EUSAGE);
  cr_assert(strstr(err.msg, "--set init.segmentlength: not a parameter; did you mean 'init.segment_length'?"), "%s",
            err.msg);
  expect_error("[energy]\npair = -1\n", ":2:", "energy.pair", ">= 0");
  expect_error("[energy]\n\n\nquadrature = 65\n", ":4:", "energy.quadrature", "<= 64");
  expect_error("[energy]\nquadrature = 8.5\n", ":2:", "energy.quadrature", "whole number");
  expect_error("[energy]\nbending = abc\n", ":2:", "energy.bending", "number");
  expect_error("[energy]\nbending = nan\n", ":2:", "energy.bending", "number");
  /* a comma locale's number, and its thousands (1.000 read as one sweep) */
  expect_error("[anneal]\nt_end = 0,01\n", ":2:", "anneal.t_end", "(a decimal comma? numbers take a point");
  expect_error("[anneal]\nsweeps = 1.000\n", ":2:", "anneal.sweeps", "(a thousands separator? write 1000, not 1.000)");
  expect_error("[anneal]\nsweeps = 1,000\n", ":2:", "anneal.sweeps", "(a thousands separator? write 1000, not 1,000)");
  expect_error("[anneal]\nsweeps = 10.000.000\n", ":2:", "anneal.sweeps", "(a thousands separator? write 1000");
  /* a leading group of three digits too: one hundred thousand */
  expect_error("[anneal]\nsweeps = 100.000\n", ":2:", "anneal.sweeps", "(a thousands separator? write 1000");
  expect_error("[anneal]\nsweeps = 250,000\n", ":2:", "anneal.sweeps", "(a thousands separator? write 1000");
  expect_error("[anneal]\nt_end = 1,000,000\n", ":2:", "anneal.t_end",
               "(a thousands separator? write 1000, not 1,000)");
  expect_error("[anneal]\nt_end = 1,000\n", ":2:", "anneal.t_end", "(a decimal comma? numbers take a point");
  expect_error("[anneal]\nt_end = 1,000.5\n", ":2:", "anneal.t_end", "(a thousands separator? write 1000, not 1,000)");
  expect_error("[anneal]\nt_end = 1.000,5\n", ":2:", "anneal.t_end", "(a thousands separator? write 1000, not 1.000)");
  cr_assert_eq(read_text("[anneal]\nseed = 0.000\nsweeps = 1.0000\n", &q, &err), LW_OK, "%s", err.msg);
  cr_assert(q.seed == 0.0 && q.sweeps == 1, "seed %g, sweeps %d", q.seed, q.sweeps);
  cr_assert_eq(read_text("[anneal]\nsweeps = 1.0\nt_end = 0.002\n", &q, &err), LW_OK, "%s", err.msg);
  expect_error("[scene]\nboundary = hexagon\n", ":2:", "scene.boundary", "rect|circle|polygon");
  expect_error("[scene]\nwidth = 1\nwidth = 2\n", ":3:", "scene.width", "repeated");
  expect_error("[scene]\nthis line has no equals sign\n", ":2:", NULL, "syntax");
  expect_error("[scene\nwidth = 1\n", ":1:", NULL, "expected a section header");
  /* a character that prints like a blank, or like nothing, is named */
  expect_error("[scene]\nwidth = 50\xc2\xa0\n", ":2:", "scene.width",
               "got '50\xc2\xa0' (byte 3 is a no-break space, U+00A0: delete it or type a plain space)");
  /* in a key's name too, by its byte in the name the message quotes */
  expect_error("[init]\n\xc2\xa0splines = 3\n", ":2:", "init.\xc2\xa0splines' is not a parameter; did you mean "
               "'init.splines'?", "(byte 6 is a no-break space, U+00A0: delete it or type a plain space)");
  cr_assert_eq(lw_params_set(&q, "init.spl\xc2\xa0ines=3", &err), LW_EUSAGE);
  cr_assert(strstr(err.msg, "--set init.spl\xc2\xa0ines: not a parameter; did you mean 'init.splines'?") &&
            strstr(err.msg, "(byte 9 is a no-break space, U+00A0"), "%s", err.msg);
  cr_assert_eq(lw_params_set(&q, "energy.pair=\xef\xbb\xbf" "1", &err), LW_EUSAGE);
  cr_assert(strstr(err.msg, "(byte 1 is a byte-order mark, U+FEFF"), "%s", err.msg);
  /* and a byte that is no text (no UTF-8, or a control character) by its number; a letter of UTF-8 is text */
  /* and the look-alikes of a number's characters, by what to type instead */
  const char *stray[][2] = {{"bark\xff" "er", "(byte 5 is 0xFF, not UTF-8: a file saved as Latin-1 or 'ANSI'? save it "
                                               "as UTF-8)"},
                            {"2\r", "(byte 2 is 0x0D, a CR: a file saved with CRLF line ends? save it with LF)"},
                            {"me\x01tropolis", "(byte 3 is 0x01, not a character of text"},
                            {"m\xc3\xa9tropolis", NULL},
                            {"1\xc0\x85", "(byte 2 is 0xC0, not UTF-8"}, /* an overlong form */
                            {"\xe2\x88\x92" "1", "(byte 1 is a minus sign, U+2212: type '-')"},
                            {"1\xef\xbc\x90", "(byte 2 is a full-width '0', U+FF10: type '0')"},
                            {"0\xef\xbc\x8e" "5", "(byte 2 is a full-width '.', U+FF0E: type '.')"},
                            {"\xef\xbd\x9e", "(byte 1 is a full-width '~', U+FF5E: type '~')"}};
  for (size_t k = 0; k < sizeof stray / sizeof stray[0]; k++) {
    char buf[96];
    lw_text_unseen_char(stray[k][0], buf, sizeof buf);
    cr_assert(stray[k][1] ? strstr(buf, stray[k][1]) != NULL : !buf[0], "%s: '%s'", stray[k][0], buf);
  }
}

Test(params, missing_file_is_input_error)
{
  lw_params p;
  lw_error err;
  cr_assert_eq(lw_params_read(&p, "/nonexistent/scene.ini", &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "/nonexistent/scene.ini"));
}

Test(params, set_overrides)
{
  lw_params p;
  lw_error err;
  lw_params_defaults(&p);
  cr_assert_eq(lw_params_set(&p, "energy.bending=2.5", &err), LW_OK);
  cr_assert_eq(p.bending, 2.5);
  cr_assert_eq(lw_params_set(&p, "scene.field=vortex", &err), LW_OK);
  cr_assert_eq(p.field, LW_FLD_VORTEX);
  cr_assert_eq(lw_params_set(&p, "energy.bendin=2", &err), LW_EUSAGE);
  cr_assert(strstr(err.msg, "energy.bendin"));
  cr_assert_eq(lw_params_set(&p, "energy.bending", &err), LW_EUSAGE);
  cr_assert_eq(lw_params_set(&p, "energy.bending=-3", &err), LW_EUSAGE);
  cr_assert(strstr(err.msg, ">= 0"));
  const lw_param_def *d = lw_params_find("energy", "bending");
  char where[64];
  lw_params_origin(&p, d, where, sizeof where);
  cr_assert_str_eq(where, "--set");
}

Test(params, scene_builds_only_what_is_named)
{
  lw_params p;
  lw_params_defaults(&p);
  lw_scene sc;
  cr_assert_eq(lw_scene_init(&sc, &p, NULL), LW_OK);
  for (int t = 0; t < LW_TERM_COUNT; t++) cr_assert(!sc.on[t], "term %d on by default", t);
  cr_assert_eq(sc.n_local, 0);
  lw_scene_clear(&sc);
  p.bending = 1;
  p.boundary_coef = 2;
  cr_assert_eq(lw_scene_init(&sc, &p, NULL), LW_OK);
  cr_assert_eq(sc.n_local, 2);
  cr_assert_eq(sc.local[0], LW_TERM_BENDING);
  cr_assert_eq(sc.local[1], LW_TERM_BOUNDARY);
  cr_assert(!sc.on[LW_TERM_PAIR] && !sc.on[LW_TERM_POTENTIAL] && !sc.on[LW_TERM_FIELD]);
  lw_scene_clear(&sc);
}

Test(params, bad_polygon_and_margin_name_the_key)
{
  lw_params p;
  lw_error err;
  lw_scene sc;
  cr_assert_eq(read_text("[scene]\nboundary = polygon\npolygon = 0 0 10 0 10\n", &p, &err), LW_OK);
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "scene.polygon") && strstr(err.msg, ":3"), "%s", err.msg);
  cr_assert_eq(read_text("[scene]\nboundary = polygon\npolygon = 0 0 10 0 20 0\n", &p, &err), LW_OK);
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_EINPUT, "collinear polygon accepted");
  cr_assert(strstr(err.msg, "zero area"), "%s", err.msg);
  cr_assert_eq(read_text("[scene]\nwidth = 100\nheight = 100\nboundary = polygon\npolygon = 200 200 300 200 300 300\n",
                         &p, &err), LW_OK);
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, ":5: key 'scene.polygon': the polygon (x 200 to 300, y 200 to 300 mm) lies off the page"),
            "%s", err.msg);
  cr_assert_eq(read_text("[scene]\nwidth = 50\nmargin = 30\n", &p, &err), LW_OK);
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "scene.margin") && strstr(err.msg, ":3"), "%s", err.msg);
}

Test(params, named_pages_set_the_size)
{
  const struct {
    const char *text;
    double w, h;
  } cases[] = {
    {"[scene]\npage = a4\n", 210, 297},
    {"[scene]\npage = a3\n", 297, 420},
    {"[scene]\npage = letter\n", 215.9, 279.4},
    {"[scene]\npage = a5\n", 148, 210},
    {"[scene]\npage = a6\norientation = landscape\n", 148, 105},
    {"[scene]\npage = a2\n", 420, 594},
    {"[scene]\npage = a1\norientation = landscape\n", 841, 594},
    {"[scene]\npage = a0\n", 841, 1189},
    {"[scene]\npage = legal\n", 215.9, 355.6},
    {"[scene]\npage = tabloid\norientation = landscape\n", 431.8, 279.4},
    {"[scene]\npage = a4\norientation = landscape\n", 297, 210},
    {"[scene]\npage = letter\norientation = landscape\n", 279.4, 215.9},
    /* an explicit size that agrees is fine (a resolved scene.ini has both) */
    {"[scene]\npage = a3\nwidth = 297\nheight = 420\n", 297, 420},
    /* custom keeps width and height; orientation does not touch them */
    {"[scene]\npage = custom\norientation = landscape\nwidth = 100\nheight = 300\n", 100, 300},
  };
  for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
    lw_params p;
    lw_error err;
    cr_assert_eq(read_text(cases[k].text, &p, &err), LW_OK, "%s", err.msg);
    cr_assert(p.width == cases[k].w && p.height == cases[k].h, "case %zu: %g x %g", k, p.width, p.height);
  }
  /* a size that disagrees names its line and the page's */
  expect_error("[scene]\npage = a4\nheight = 300\n", ":3:", "scene.height", "conflicts with scene.page = a4");
  expect_error("[scene]\nwidth = 200\n\npage = letter\n", ":2:", "scene.width", ":4)");
  /* --set after the file: the page follows, a disagreeing size fails */
  lw_params p;
  lw_error err;
  cr_assert_eq(read_text("[scene]\npage = a4\n", &p, &err), LW_OK);
  cr_assert_eq(lw_params_set(&p, "scene.page=a3", &err), LW_OK);
  cr_assert_eq(lw_params_set(&p, "scene.orientation=landscape", &err), LW_OK);
  cr_assert_eq(lw_params_resolve(&p, &err), LW_OK);
  cr_assert(p.width == 420 && p.height == 297);
  cr_assert_eq(lw_params_set(&p, "scene.width=100", &err), LW_OK);
  cr_assert_eq(lw_params_resolve(&p, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "--set: key 'scene.width'"), "%s", err.msg);
  /* a size given over the file's page is told the page custom (it was told
  ** to give the page's own width) */
  cr_assert_eq(read_text("[scene]\npage = a4\n", &p, &err), LW_OK);
  cr_assert_eq(lw_params_set(&p, "scene.width=100", &err), LW_OK);
  cr_assert_eq(lw_params_resolve(&p, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "expected 210 or no width (for a size of your own, give --set scene.page=custom too)"),
            "%s", err.msg);
  cr_assert_eq(lw_params_set(&p, "scene.page=custom", &err), LW_OK);
  cr_assert_eq(lw_params_set(&p, "scene.height=50", &err), LW_OK);
  cr_assert_eq(lw_params_resolve(&p, &err), LW_OK, "%s", err.msg);
}

Test(params, pen_colours_match_the_pens)
{
  lw_params p;
  lw_error err;
  cr_assert_eq(read_text("[output]\npens = 3\npen_colors = #000 #c00 #0000ff\n", &p, &err), LW_OK, "%s", err.msg);
  expect_error("[output]\npens = 3\npen_colors = #000 #c00\n", ":3:", "output.pen_colors", "expected 3 colours");
  expect_error("[output]\npen_colors = red\n", ":2:", "output.pen_colors", "#rrggbb");
}

Test(params, text_that_ini_cannot_hold_is_refused)
{
  /* Regression (found by tests/fuzz/fuzz_params.c): "polygon =;0 0 12" was
  ** read as ';0 0 12', written to scene.ini as "polygon = ;0 0 12", which
  ** reads back as a comment, so a resumed run saw other parameters. */
  expect_error("[scene]\nboundary = polygon\npolygon =;0 0 12\n", ":3:", "scene.polygon", "';'");
  lw_params p;
  lw_error err;
  lw_params_defaults(&p);
  const char *bad[] = {"anneal.table=a ;b", "anneal.table=a\t;b", "anneal.table= a", "anneal.table=a ",
                       "anneal.table=a\nb", "anneal.table=;a"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    cr_assert_eq(lw_params_set(&p, bad[i], &err), LW_EUSAGE, "accepted %s", bad[i]);
    cr_assert(strstr(err.msg, "anneal.table"), "%s", err.msg);
  }
  /* what INI does hold is still fine, and survives a write/read cycle */
  cr_assert_eq(lw_params_set(&p, "anneal.table=dir with spaces/a;b #c.txt", &err), LW_OK, "%s", err.msg);
  char path[64];
  lw_test_tmp_name(path, "params_txt");
  FILE *f = fdopen(mkstemp(path), "w");
  cr_assert_eq(lw_params_write(&p, f), 0);
  fclose(f);
  lw_params q;
  cr_assert_eq(lw_params_read(&q, path, &err), LW_OK, "%s", err.msg);
  unlink(path);
  cr_assert_str_eq(q.table, "dir with spaces/a;b #c.txt");
}

Test(params, text_longer_than_its_field_is_refused)
{
  /* Regression (found by tests/fuzz/fuzz_params.c): every text key was
  ** checked against LW_PATH_MAX, but anneal.schedule holds 64 bytes, so a
  ** long schedule name overwrote the numbers stored after it. */
  lw_params p;
  lw_error err;
  char text[300];
  snprintf(text, sizeof text, "[anneal]\nschedule = %0100d\nt_start = 2\n", 0);
  expect_error(text, ":2:", "anneal.schedule", "at most 63 bytes");
  lw_params_defaults(&p);
  memset(text, 'g', 64);
  strcpy(text + 64, "");
  char set[400];
  snprintf(set, sizeof set, "anneal.schedule=%s", text);
  double t_start = p.t_start;
  cr_assert_eq(lw_params_set(&p, set, &err), LW_EUSAGE);
  cr_assert_eq(p.t_start, t_start, "the neighbouring field was overwritten");
  text[63] = '\0';
  snprintf(set, sizeof set, "anneal.schedule=%s", text);
  cr_assert_eq(lw_params_set(&p, set, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(strlen(p.schedule), 63);
  for (size_t i = 0; i < lw_param_count; i++)
    if (lw_param_table[i].type == LW_PT_STRING)
      cr_assert(lw_param_table[i].size >= 64, "%s.%s: capacity %zu", lw_param_table[i].section, lw_param_table[i].key,
                lw_param_table[i].size);
}

Test(params, long_lines_are_refused_with_their_own_line_number)
{
  /* Regression (found by tests/fuzz/fuzz_params.c): inih holds 199
  ** characters of a line and read the rest of a longer one as a line of its
  ** own, so a polygon of 40 vertices gave "syntax error" on the next line. */
  char text[1200] = "[scene]\nboundary = polygon\npolygon =";
  for (int i = 0; i < 60; i++) snprintf(text + strlen(text), 20, " %d %d", 10 + i % 50, 10 + (i * 7) % 40);
  strcat(text, "\nwidth = 100\n");
  expect_error(text, ":3:", NULL, "line longer than 198 bytes");
  /* the longest value accepted without a blank is written on a line that
  ** reads back (a list breaks only at its blanks) */
  lw_params p, q;
  lw_error err;
  lw_params_defaults(&p);
  char set[400] = "scene.polygon=";
  size_t cap = 200 - 5 - strlen("polygon");
  memset(set + strlen(set), '7', cap + 1);
  cr_assert_eq(lw_params_set(&p, set, &err), LW_EUSAGE, "accepted %zu characters", cap + 1);
  set[strlen(set) - 1] = '\0';
  cr_assert_eq(lw_params_set(&p, set, &err), LW_OK, "%s", err.msg);
  char path[64];
  lw_test_tmp_name(path, "params_long");
  FILE *f = fdopen(mkstemp(path), "w");
  cr_assert_eq(lw_params_write(&p, f), 0);
  fclose(f);
  cr_assert_eq(lw_params_read(&q, path, &err), LW_OK, "%s", err.msg);
  unlink(path);
  cr_assert_str_eq(q.polygon, p.polygon);
  /* 198 characters and a CRLF line end are a line (refused as 199 before);
  ** a file of CR line ends is named as such (it read as one long line, or,
  ** shorter, as one comment and an empty scene) */
  char crlf[400] = ";";
  memset(crlf + 1, 'x', 197);
  strcpy(crlf + 198, "\r\n[scene]\r\nwidth = 50\r\n");
  cr_assert_eq(read_text(crlf, &p, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(p.width, 50.0);
  expect_error("; a scene\r[scene]\rwidth = 50\r", ":1:", NULL, "a CR inside the line (a file of CR line ends");
}

/* A list (a polygon, a ladder, a NURBS curve's numbers) goes on over
** indented lines: a tempering ladder of more than about 26 rungs could not
** be given at all (one line holds 198 bytes), though 256 replicas are
** allowed, and ladder.ini of a tuned 64-rung ladder could not be used. */
Test(params, a_list_goes_on_over_indented_lines_and_reads_back)
{
  lw_params p, q;
  lw_error err;
  lw_error_clear(&err);
  cr_assert_eq(read_text("[scene]\nboundary = polygon\npolygon = 10 10 90 10   ; the base\n"
                         "    90 60\n\t  50 80  ; the top: y=80\n  10 60\nwidth = 100\n  height = 100\n", &p, &err),
               LW_OK, "%s", err.msg);
  cr_assert_str_eq(p.polygon, "10 10 90 10 90 60 50 80 10 60");
  cr_assert_eq(p.height, 100.0, "an indented key = value is a key");
  cr_assert_eq(p.line[lw_params_find("scene", "polygon") - lw_param_table], 3, "the list's line is its key's");
  /* only a list goes on, and only on the lines right after it */
  expect_error("[scene]\nwidth = 100\n  120\n", ":3:", NULL, "syntax error");
  expect_error("[scene]\npolygon = 10 10 90 10\n\n  90 60\n", ":4:", NULL, "syntax error");
  expect_error("[scene]\npolygon = 10 10 90 10\n; a comment\n  90 60\n", ":4:", NULL, "syntax error");
  expect_error("[scene]\npolygon = 10 10 90 10\n90 60\n", ":3:", NULL, "syntax error"); /* not indented */
  /* an indented key after a list is a key, not more of the list */
  cr_assert_eq(read_text("[scene]\nboundary = polygon\npolygon = 10 10 90 10 50 80\n  height = 120\n", &p, &err),
               LW_OK, "%s", err.msg);
  cr_assert(!strcmp(p.polygon, "10 10 90 10 50 80") && p.height == 120.0, "'%s', %g", p.polygon, p.height);
  /* the field's last byte: a list of 4095 bytes over lines reads back
  ** whole, one of 4096 is refused (not cut by a byte) */
  for (int extra = 0; extra <= 1; extra++) {
    char big[6000] = "[nurbs]\nknots = 0";
    for (int i = 0; i < 2047; i++) strcat(big, i % 40 ? " 1" : "\n  1");
    if (extra) strcat(big, "1");
    strcat(big, "\n");
    if (extra) {
      expect_error(big, ":", "nurbs.knots", "goes on past 4095 bytes");
      continue;
    }
    cr_assert_eq(read_text(big, &p, &err), LW_OK, "%s", err.msg);
    cr_assert_eq(strlen(p.nb_knots), 4095);
    cr_assert(!strcmp(p.nb_knots + 4090, "1 1 1"), "%s", p.nb_knots + 4090);
  }
  /* past the field, or a part too long to write back on a line */
  char text[9000] = "[nurbs]\nknots = 0";
  for (int i = 0; i < 560; i++) strcat(text, "\n  0.25 0.25 0.5");
  expect_error(text, ":", "nurbs.knots", "goes on past 4095 bytes");
  char word[200];
  memset(word, '1', 190);
  word[190] = '\0';
  snprintf(text, sizeof text, "[scene]\npolygon = 1 2\n %s\n", word);
  expect_error(text, ":3:", "scene.polygon", "without a single blank");
  /* 256 rungs at 17 digits: --set takes them, scene.ini writes them over
  ** lines, and they read back byte for byte */
  lw_params_defaults(&p);
  char set[7000] = "tempering.ladder=";
  for (int k = 0; k < 256; k++)
    snprintf(set + strlen(set), sizeof set - strlen(set), "%s%.17g", k ? " " : "", 0.01 * (1 + k / 3.0));
  cr_assert_eq(lw_params_set(&p, set, &err), LW_OK, "%s", err.msg);
  /* on the command line, where a list has no lines, its tabs and runs of
  ** blanks become one blank where it is written over lines */
  lw_params q2;
  lw_params_defaults(&q2);
  char tabs[7000] = "tempering.ladder=", *v = tabs + strlen(tabs);
  for (char *c = strchr(set, '=') + 1; *c; c++) *v++ = *c == ' ' ? '\t' : *c;
  *v = '\0';
  cr_assert_eq(lw_params_set(&q2, tabs, &err), LW_OK, "%s", err.msg);
  cr_assert_str_eq(q2.ladder, p.ladder);
  char path[64];
  lw_test_tmp_name(path, "params_list");
  FILE *f = fdopen(mkstemp(path), "w");
  cr_assert_eq(lw_params_write(&p, f), 0);
  fclose(f);
  cr_assert_eq(lw_params_read(&q, path, &err), LW_OK, "%s", err.msg);
  cr_assert_str_eq(q.ladder, p.ladder);
  char cmd[200];
  snprintf(cmd, sizeof cmd, "awk 'length > 110 || /^ladder =/ { n++ } END { exit n != 1 }' %s", path);
  cr_assert_eq(system(cmd), 0, "a long list is written on lines of about 100 bytes");
  unlink(path);
}

/*
** scene.preset = photo fills the keys a scene leaves unset, lengths in pen
** widths and the domain lattice from the page; keys the file or --set give
** win, and a later resolve follows a changed pen width.
*/
Test(params, photo_preset_scales_with_the_pen_and_the_page)
{
  lw_params p;
  lw_error err;
  cr_assert_eq(read_text("[scene]\npreset = photo\npage = a4\n[output]\npen_width = 0.35\n", &p, &err), LW_OK,
               "%s", err.msg);
  cr_assert(fabs(p.segment_length - 8 * 0.35) < 1e-12 && fabs(p.pair_cutoff - 3 * 0.35) < 1e-12 &&
                fabs(p.min_spacing - 0.35) < 1e-12 && fabs(p.tone_blur - 3 * 0.35) < 1e-12,
            "segment %g, cutoff %g, spacing %g, blur %g", p.segment_length, p.pair_cutoff, p.min_spacing,
            p.tone_blur);
  cr_assert(fabs(p.field_sigma - 10 * 0.35) < 1e-12);
  cr_assert(p.tone == 80 && p.tone_ink == 0.5 && p.coverage == 0.6 && p.splines == 0 && p.sweeps == 300);
  /* Phi blurred over about the nodes' spacing (8 / 6 pen widths) */
  cr_assert(fabs(p.potential_blur - 1.5 * 0.35) < 1e-12, "potential_blur %g", p.potential_blur);
  /* the tone's own nodes, the fewest 0.7 tone_blur apart: 8 / (0.7 x 3) */
  cr_assert(p.quadrature == 6 && p.tone_quadrature == 4, "nodes %d, tone's %d", p.quadrature, p.tone_quadrature);
  cr_assert(p.image_levels == 0.01, "image_levels %g", p.image_levels);
  /* the annealer chooses the count where the tone term pays for line: no
  ** chemical potential darkens every light tone */
  cr_assert(p.fixed_count == 0 && p.chem_length == 0 && p.mix_grow == 0.05 && p.mix_shrink == 0.05,
            "fixed_count %d, chem_length %.17g", p.fixed_count, p.chem_length);
  /* A4 less 10 mm margins: 190 mm / (90 x 0.35 mm) = 6 domains a side */
  cr_assert_str_eq(p.domains, "6");
  /* a message about a key the preset filled names the preset, and the pen
  ** widths it sized a length from; the file's own keys name their line */
  char where[256];
  lw_params_origin(&p, lw_params_find("energy", "tone_blur"), where, sizeof where);
  char want[sizeof p.file + 64];
  snprintf(want, sizeof want, "%s:2 (scene.preset = photo, 3 pen widths of 0.35 mm)", p.file);
  cr_assert_str_eq(where, want);
  lw_params_origin(&p, lw_params_find("energy", "tone"), where, sizeof where);
  snprintf(want, sizeof want, "%s:2 (scene.preset = photo)", p.file);
  cr_assert_str_eq(where, want);
  /* a preset a program set has no line to name (it named itself, forever) */
  static lw_params q;
  lw_params_defaults(&q);
  q.preset = LW_PRESET_PHOTO;
  lw_params_origin(&q, lw_params_find("energy", "tone"), where, sizeof where);
  cr_assert_str_eq(where, "scene.preset = photo");
  lw_params_origin(&q, lw_params_find("energy", "tone_blur"), where, sizeof where);
  cr_assert_str_eq(where, "scene.preset = photo (3 pen widths of 0.3 mm)");
  lw_params_origin(&p, lw_params_find("output", "pen_width"), where, sizeof where);
  cr_assert(strstr(where, ":5"), "%s", where);
  lw_params_origin(&p, lw_params_find("energy", "strain_mode"), where, sizeof where);
  char expect[sizeof p.file + 48];
  snprintf(expect, sizeof expect, "%s (not set: the default, spline)", p.file);
  cr_assert_str_eq(where, expect, "a default names the scene file");
  /* --set of the pen width: the preset's keys follow, a set key stays */
  cr_assert_eq(lw_params_set(&p, "output.pen_width=0.5", &err), LW_OK);
  cr_assert_eq(lw_params_set(&p, "energy.pair_cutoff=4", &err), LW_OK);
  cr_assert_eq(lw_params_resolve(&p, &err), LW_OK);
  cr_assert(fabs(p.segment_length - 4.0) < 1e-12 && p.pair_cutoff == 4.0, "%g %g", p.segment_length,
            p.pair_cutoff);
  cr_assert(fabs(p.potential_coef - 2.5 / 0.35 * 0.5) < 1e-12, "potential %.17g", p.potential_coef);
  cr_assert_str_eq(p.domains, "4");
  /* a finer blur asks for more tone nodes, past the other terms' (it stopped
  ** at their 6, and a blur of 0.2 mm read 6 % high) */
  cr_assert_eq(p.tone_quadrature, 4);
  cr_assert_eq(lw_params_set(&p, "energy.tone_blur=0.6", &err), LW_OK);
  cr_assert_eq(lw_params_resolve(&p, &err), LW_OK);
  cr_assert_eq(p.tone_quadrature, 10, "4 mm segments at 0.42 mm: 10 nodes, more than 6");
  cr_assert_eq(lw_params_set(&p, "energy.tone_blur=1.2", &err), LW_OK);
  cr_assert_eq(lw_params_resolve(&p, &err), LW_OK);
  cr_assert_eq(p.tone_quadrature, 5, "4 mm segments at 0.84 mm: 5 nodes");
  /* the file's keys win; A6 at the default pen of 0.3 mm: 85 mm / 27 mm = 3
  ** domains a side, and with a 1 mm pen fewer than 2, so not split */
  cr_assert_eq(read_text("[scene]\npreset = photo\npage = a6\n[init]\ncoverage = 0.3\n", &p, &err), LW_OK);
  cr_assert(p.coverage == 0.3 && fabs(p.segment_length - 8 * 0.3) < 1e-12);
  cr_assert_str_eq(p.domains, "3");
  cr_assert_eq(lw_params_set(&p, "output.pen_width=1", &err), LW_OK);
  cr_assert_eq(lw_params_resolve(&p, &err), LW_OK);
  cr_assert_str_eq(p.domains, "off");
  /* a millimetre of line costs 7.14 pen widths where the picture is white,
  ** for one pen (1 mm here) and for a colour separation's */
  cr_assert(p.potential == LW_POT_IMAGE && fabs(p.potential_coef - 2.5 / 0.35) < 1e-12 && p.potential_power == 8,
            "potential %d, %.17g, power %g", p.potential, p.potential_coef, p.potential_power);
  cr_assert_eq(read_text("[scene]\npreset = photo\n[layers]\nsource = cmyk\n[output]\npen_width = 0.35\n", &p, &err),
               LW_OK, "%s", err.msg);
  cr_assert(p.potential == LW_POT_IMAGE && fabs(p.potential_coef - 2.5) < 1e-12 && p.potential_power == 8,
            "potential %d, %.17g, power %g", p.potential, p.potential_coef, p.potential_power);
  cr_assert(p.birth_spread == 0.1, "a short piece may die: birth_spread %g", p.birth_spread);
  /* no near field while the spacing keeps strokes apart; without it (a
  ** photograph then annealed to a pair energy 11.6 % low) the default's,
  ** and a near field given stays */
  cr_assert(p.pair_near == 0 && p.min_spacing > 0, "near %g, spacing %g", p.pair_near, p.min_spacing);
  cr_assert_eq(lw_params_set(&p, "energy.min_spacing=0", &err), LW_OK);
  cr_assert_eq(lw_params_resolve(&p, &err), LW_OK, "%s", err.msg);
  cr_assert(p.pair_near == 1.5, "near %g", p.pair_near);
  cr_assert_eq(lw_params_set(&p, "energy.pair_near=2", &err), LW_OK);
  cr_assert_eq(lw_params_resolve(&p, &err), LW_OK, "%s", err.msg);
  cr_assert(p.pair_near == 2, "near %g", p.pair_near);
  /* without the preset nothing changes */
  lw_params d;
  lw_params_defaults(&d);
  cr_assert_eq(read_text("[scene]\npage = a4\n", &p, &err), LW_OK);
  cr_assert(p.segment_length == d.segment_length && p.tone == d.tone && !strcmp(p.domains, d.domains));
  cr_assert(p.image_levels == 0 && d.image_levels == 0 && p.birth_spread == 0 && d.birth_spread == 0);
}

/* orientation = auto turns a named page to the picture, which the photo
** preset asks for: a landscape photograph on a portrait page would leave
** half of it blank.  The header alone decides (the raster here is short). */
Test(params, auto_orientation_follows_the_picture)
{
  char dir[64], wide[128], tall[128], text[512];
  cr_assert_eq(lw_test_dir_make(dir, "orient"), 0);
  snprintf(wide, sizeof wide, "%s/wide.pgm", dir);
  snprintf(tall, sizeof tall, "%s/tall.pgm", dir);
  FILE *f = fopen(wide, "w");
  fprintf(f, "P5\n# a comment\n30 20\n255\n");
  fclose(f);
  f = fopen(tall, "w");
  fprintf(f, "P5 20 30 255\n");
  fclose(f);
  lw_params p;
  lw_error err;
  static const struct {
    const char *image, *extra;
    double width;
  } cases[] = {
      {"wide.pgm", "orientation = auto\n", 297}, {"tall.pgm", "orientation = auto\n", 210},
      {"wide.pgm", "preset = photo\n", 297},     {"wide.pgm", "preset = photo\norientation = portrait\n", 210},
      {"wide.pgm", "", 210},                     {"", "orientation = auto\n", 210},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    char image[192] = "";
    if (cases[k].image[0]) snprintf(image, sizeof image, "image = %s/%s\n", dir, cases[k].image);
    snprintf(text, sizeof text, "[scene]\npage = a4\n%s%s", cases[k].extra, image);
    cr_assert_eq(read_text(text, &p, &err), LW_OK, "case %zu: %s", k, err.msg);
    cr_assert(p.width == cases[k].width && p.height == (cases[k].width == 297 ? 210 : 297), "case %zu: %g x %g", k,
              p.width, p.height);
  }
  /* a picture that is not there, or that linewise cannot read: one message
  ** naming the picture's key and line, whether orientation = auto is the
  ** scene's or the photo preset's */
  static const char *const extras[] = {"orientation = auto\n", "preset = photo\n"};
  for (size_t k = 0; k < 2; k++) {
    snprintf(text, sizeof text, "[scene]\npage = a4\n%simage = %s/none.png\n", extras[k], dir);
    cr_assert_eq(read_text(text, &p, &err), LW_EINPUT);
    cr_assert(strstr(err.msg, ":4: key 'scene.image': ") && strstr(err.msg, "none.png") &&
                  !strstr(err.msg, "orientation"),
              "%s", err.msg);
  }
  cr_assert_eq(lw_test_dir_remove(dir), 0);
}

/* The constant schedule has one temperature, so one step by default (its
** moves tune once); a scene's own anneal.steps wins, an override of the
** schedule brings the usual default back, and the photo preset's 5 holds
** for its own schedule only. */
Test(params, a_constant_schedule_has_one_step_unless_the_scene_says)
{
  lw_params p;
  lw_error err;
  cr_assert_eq(read_text("[anneal]\nschedule = constant\n", &p, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(p.steps, 1);
  cr_assert_eq(lw_params_set(&p, "anneal.schedule=geometric", &err), LW_OK);
  cr_assert_eq(lw_params_resolve(&p, &err), LW_OK);
  cr_assert_eq(p.steps, 20, "the default after the schedule changed: %d", p.steps);
  cr_assert_eq(read_text("[anneal]\nschedule = constant\nsteps = 7\n", &p, &err), LW_OK);
  cr_assert_eq(p.steps, 7);
  cr_assert_eq(read_text("[anneal]\nschedule = linear\n", &p, &err), LW_OK);
  cr_assert_eq(p.steps, 20);
  cr_assert_eq(read_text("[scene]\npreset = photo\n", &p, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(p.steps, 5);
  cr_assert_eq(read_text("[scene]\npreset = photo\n[anneal]\nschedule = constant\n", &p, &err), LW_OK);
  cr_assert_eq(p.steps, 1);
}

/* A key counts as given when the file or --set names it with another value
** than its default, and never in a run's own scene.ini (which names all). */
Test(params, a_key_is_given_only_with_a_value_of_its_own)
{
  char path[64];
  lw_test_tmp_name(path, "params_given");
  int fd = mkstemp(path);
  FILE *f = fdopen(fd, "w");
  fputs("[energy]\nbending = 0\nstrain = 2\n[output]\norder = 2opt\npen_colors =\n[scene]\nfield = vortex\n", f);
  fclose(f);
  lw_params p;
  lw_error err;
  cr_assert_eq(lw_params_read(&p, path, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(lw_params_set(&p, "energy.tone=0.5", &err), LW_OK, "%s", err.msg);
  cr_assert(!lw_params_given(&p, lw_params_find("energy", "bending")), "the default, named");
  cr_assert(lw_params_given(&p, lw_params_find("energy", "strain")));
  cr_assert(!lw_params_given(&p, lw_params_find("output", "order")), "a choice at its default");
  cr_assert(!lw_params_given(&p, lw_params_find("output", "pen_colors")), "a text at its default");
  cr_assert(lw_params_given(&p, lw_params_find("scene", "field")));
  cr_assert(lw_params_given(&p, lw_params_find("energy", "tone")), "--set");
  cr_assert(!lw_params_given(&p, lw_params_find("energy", "pair")), "not named");
  cr_assert_eq(lw_params_read_run(&p, path, 1, &err), LW_OK, "%s", err.msg);
  cr_assert(!lw_params_given(&p, lw_params_find("energy", "strain")), "a run's own scene.ini");
  cr_assert_eq(lw_params_set(&p, "energy.pair=0.5", &err), LW_OK, "%s", err.msg);
  cr_assert(lw_params_given(&p, lw_params_find("energy", "pair")), "--set on a run's scene.ini");
  unlink(path);
  static const char *const pat[] = {"energy.strain", "plot.*", NULL};
  cr_assert(lw_params_named(pat, lw_params_find("energy", "strain")));
  cr_assert(!lw_params_named(pat, lw_params_find("energy", "strain_mode")), "a whole key, not a prefix");
  cr_assert(lw_params_named(pat, lw_params_find("plot", "crop")));
  cr_assert(!lw_params_named(NULL, lw_params_find("plot", "crop")));
}

/* scene.field_core: -1 is init.segment_length, and a run's scene.ini
** written before the key existed (its header, no line for the key) keeps
** the unit field it ran with, so that its energies, and its resume, are
** what they were; a scene.ini written by hand beside a state (no header)
** takes the default; a value below 0 but -1 is refused. */
Test(params, a_field_core_of_a_run_begun_before_it_is_none)
{
  char path[64];
  lw_test_tmp_name(path, "params_core");
  int fd = mkstemp(path);
  cr_assert_geq(fd, 0);
  close(fd);
  static const char body[] = "[scene]\nfield = vortex\n[energy]\nfield = -1\n[init]\nsegment_length = 6\n";
  static const struct { int header, run; const char *more; double core; } cases[] = {
    {0, 0, "", 6.0},                            /* a new scene */
    {1, 1, "", 0.0},                            /* a run's of before the key */
    {0, 1, "", 6.0},                            /* a hand-made one beside a state */
    {1, 1, "[scene]\nfield_core = 2.5\n", 2.5}, /* a run's with the line */
    {0, 0, "[scene]\nfield_core = 0\n", 0.0},   /* none asked */
  };
  lw_params p;
  lw_scene sc;
  lw_error err;
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    FILE *f = fopen(path, "w");
    cr_assert_not_null(f);
    fprintf(f, "%s%s%s", cases[k].header ? LW_RUN_SCENE_HEADER "\n" : "", body, cases[k].more);
    fclose(f);
    cr_assert_eq(cases[k].run ? lw_params_read_run(&p, path, 1, &err) : lw_params_read(&p, path, &err), LW_OK,
                 "%s", err.msg);
    cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_OK, "%s", err.msg);
    cr_assert_eq(sc.field.core, cases[k].core, "case %zu: core %g", k, sc.field.core);
    lw_scene_clear(&sc);
  }
  cr_assert_eq(lw_params_read(&p, path, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(lw_params_set(&p, "scene.field_core=-0.5", &err), LW_OK, "%s", err.msg);
  cr_assert_neq(lw_scene_init(&sc, &p, &err), LW_OK);
  cr_assert(strstr(err.msg, "scene.field_core") &&
                strstr(err.msg, "expected -1 (init.segment_length) or a radius >= 0"), "%s", err.msg);
  unlink(path);
}

/* Every key is read by some system under some driver (a key no row lists
** would be refused in every scene), and the readers are what the rows say. */
Test(params, every_key_has_a_reader)
{
  char buf[256];
  for (size_t i = 0; i < lw_param_count; i++) {
    lw_anneal_key_readers(&lw_param_table[i], buf, sizeof buf);
    cr_assert(buf[0], "%s.%s: no system reads it", lw_param_table[i].section, lw_param_table[i].key);
  }
  /* the chain drivers by the table (a chain driver added is one more
  ** there: "metropolis, barker" written out failed every new one) */
  char chains[128] = "", want[256];
  for (const lw_driver_type *const *d = lw_driver_types; *d; d++)
    if ((*d)->kind == LW_DRIVE_CHAIN)
      snprintf(chains + strlen(chains), sizeof chains - strlen(chains), "%s%s", chains[0] ? ", " : "", (*d)->name);
  static const struct { const char *section, *key, *want; } known[] = {
    {"anneal", "sweeps", "all"},
    {"energy", "bending", "splines"},
    {"particles", "r0", "particles"},
    {"nurbs", "alpha", "nurbs"},
    {"dynamics", "dt", "all under dynamics"},
    {"tempering", "replicas", "all under %s"},
    {"moves", "point", "splines under %s"},
    {"particles", "birth", "particles under %s"},
    {"nurbs", "weight_inertia", "nurbs under dynamics"},
    {"anneal", "delayed_acceptance", "splines under metropolis"},
    {"dynamics", "pin", "splines under dynamics"},
    {"dynamics", "rho", "splines, nurbs under %s; all under dynamics"},
  };
  for (size_t k = 0; k < sizeof known / sizeof known[0]; k++) {
    lw_anneal_key_readers(lw_params_find(known[k].section, known[k].key), buf, sizeof buf);
    snprintf(want, sizeof want, known[k].want, chains);
    cr_assert_str_eq(buf, want, "%s.%s: '%s', expected '%s'", known[k].section, known[k].key, buf, want);
  }
}

/* The help of scene.system, scene.driver and anneal.schedule (linewise
** params, docs/PARAMETERS.md) names every row of the tables, so a new one
** is not left out of what users read. */
Test(params, the_help_names_every_system_driver_and_schedule)
{
  const char *sys_help = lw_params_find("scene", "system")->help;
  for (int k = 0; lw_system_types[k]; k++) {
    char quoted[64];
    snprintf(quoted, sizeof quoted, "`%s`", lw_system_types[k]->name);
    cr_assert(strstr(sys_help, quoted), "scene.system's help does not name %s", quoted);
  }
  const char *driver_help = lw_params_find("scene", "driver")->help;
  for (int k = 0; lw_driver_types[k]; k++) {
    char quoted[64];
    snprintf(quoted, sizeof quoted, "`%s`", lw_driver_types[k]->name);
    cr_assert(strstr(driver_help, quoted), "scene.driver's help does not name %s", quoted);
  }
  const char *sched_help = lw_params_find("anneal", "schedule")->help;
  for (int k = 0; lw_schedule_types[k]; k++)
    cr_assert(strstr(sched_help, lw_schedule_types[k]->name), "anneal.schedule's help does not name %s",
              lw_schedule_types[k]->name);
}

/* The table of docs/PARAMETERS.md lists scene.system, anneal.schedule and
** anneal.domains as choices with their words (they were "text" with range
** "-", though anything but the tables' names is refused). */
Test(params, the_doc_lists_the_words_of_table_keys_as_choices)
{
  char *text = NULL;
  size_t n = 0;
  FILE *f = open_memstream(&text, &n);
  cr_assert_not_null(f);
  lw_params_write_doc(f, lw_anneal_key_readers, lw_anneal_key_values);
  cr_assert_eq(fclose(f), 0);
  char words[128], want[256];
  /* the words from the tables themselves: a new row is listed, not a test to edit */
  const char *tables[3][2] = {{"schedule", "geometric"}, {"system", "splines"}, {"driver", "metropolis"}};
  for (int k = 0; k < 3; k++) {
    const char *from = k == 2 ? lw_driver_names() : k ? lw_system_names() : lw_schedule_names();
    char *to = words; /* '|' and ", " become '/', as in the doc */
    for (; *from && to < words + sizeof words - 1; from++)
      if (*from == '|' || (*from == ',' && from[1] == ' ' && from++)) *to++ = '/';
      else *to++ = *from;
    *to = '\0';
    snprintf(want, sizeof want, "| `%s` | choice | `%s` | - | %s |", tables[k][0], tables[k][1], words);
    cr_assert(strstr(text, want), "no row %s", want);
  }
  cr_assert(strstr(words, "metropolis/dynamics"), "%s", words);
  cr_assert(strstr(text, "| `domains` | choice | `off` | - | off/1 to 64/auto |"));
  free(text);
}

/* A program calling into the library after setlocale(LC_ALL, "") (a GUI
** toolkit does) under a decimal-comma locale refused "0.02" in a correct
** scene, collapsed the built-in defaults and would have written "0,5":
** reading a scene or a trace is refused there, naming LC_NUMERIC and the
** way round.  The locale is built for the test (localedef, the locales
** package of make deps), as a CI machine has none but C. */
Test(params, a_decimal_comma_locale_is_refused_with_the_way_round)
{
  char dir[64];
  cr_assert_eq(lw_test_dir_make(dir, "locale"), 0);
  cr_assert_eq(lw_test_sh("localedef -i de_DE -f UTF-8 %s/de_DE.UTF-8 2>/dev/null; test -d %s/de_DE.UTF-8", dir,
                          dir), 0, "localedef (make deps installs locales)");
  setenv("LOCPATH", dir, 1);
  cr_assert_not_null(setlocale(LC_NUMERIC, "de_DE.UTF-8"));
  lw_params p;
  lw_error err;
  cr_assert_eq(read_text("[energy]\npair = 0.02\n", &p, &err), LW_EUSAGE);
  cr_assert(strstr(err.msg, "the locale's numbers (LC_NUMERIC) take ',' as the decimal point") &&
                strstr(err.msg, "setlocale(LC_NUMERIC, \"C\")"), "%s", err.msg);
  cr_assert_null(lw_trace_read("/nonexistent/trace.csv", &err));
  cr_assert(strstr(err.msg, "LC_NUMERIC"), "%s", err.msg);
  /* and in the C locale the same scene reads */
  setlocale(LC_NUMERIC, "C");
  cr_assert_eq(read_text("[energy]\npair = 0.02\n", &p, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(p.pair, 0.02);
  /* a scene read, then the locale set: a run there would write "0,02" into
  ** scene.ini and JSON that is not; it is refused before it writes */
  cr_assert_not_null(setlocale(LC_NUMERIC, "de_DE.UTF-8"));
  static lw_anneal a;
  char out[96];
  snprintf(out, sizeof out, "%s/run", dir);
  cr_assert_eq(lw_anneal_start(&a, &p, out, &err), LW_EUSAGE);
  cr_assert(strstr(err.msg, "LC_NUMERIC"), "%s", err.msg);
  cr_assert_neq(access(out, F_OK), 0, "the run wrote a directory");
  lw_anneal_free(&a);
  /* the locale set between sweeps: the next sweep is refused before its
  ** trace row (checked at checkpoints only, rows of decimal commas went
  ** into trace.csv until the next one) */
  setlocale(LC_NUMERIC, "C");
  cr_assert_eq(read_text("[init]\nsplines = 2\n[anneal]\nsweeps = 10\n[output]\ntrace_every = 1\n", &p, &err), LW_OK,
               "%s", err.msg);
  cr_assert_eq(lw_anneal_start(&a, &p, out, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(lw_anneal_sweep(&a, &err), LW_OK, "%s", err.msg);
  cr_assert_not_null(setlocale(LC_NUMERIC, "de_DE.UTF-8"));
  cr_assert_eq(lw_anneal_sweep(&a, &err), LW_EUSAGE);
  cr_assert(strstr(err.msg, "LC_NUMERIC"), "%s", err.msg);
  /* the library's own writers, called by a host, refuse too (a state of
  ** "30,94 12,68" and a scene of "t_end = 0,01" were written with success) */
  lw_ckpt_writer w;
  char path[128];
  snprintf(path, sizeof path, "%s/state.lw", dir);
  cr_assert_eq(lw_ckpt_begin(&w, path, "linewise-state 2", &err), LW_EUSAGE);
  cr_assert(strstr(err.msg, "LC_NUMERIC"), "%s", err.msg);
  cr_assert_neq(access(path, F_OK), 0);
  FILE *f = fopen("/dev/null", "w");
  cr_assert_eq(lw_params_write(&p, f), -1, "a scene of decimal commas written");
  setlocale(LC_NUMERIC, "C");
  cr_assert_eq(lw_params_write(&p, f), 0);
  fclose(f);
  lw_anneal_free(&a);
  cr_assert_eq(lw_test_sh("test $(awk -F, 'NR == 1 { n = NF } NF != n' %s/trace.csv | wc -l) -eq 0 && "
                          "test $(wc -l < %s/trace.csv) -eq 2", out, out),
               0, "trace.csv took a row in the comma locale");
  lw_test_dir_remove(dir);
}

/* A choice given in other case ("A4", as a page is printed) is refused with
** the word to type; one that matches none in any case has no such hint. */
Test(params, a_choice_in_other_case_is_named_in_lower_case)
{
  lw_params p;
  lw_params_defaults(&p);
  lw_error err;
  cr_assert_neq(lw_params_set(&p, "scene.page=A4", &err), LW_OK);
  cr_assert(strstr(err.msg, "(in lower case: 'a4'), got 'A4'"), "%s", err.msg);
  cr_assert_neq(lw_params_set(&p, "scene.field=Vortex", &err), LW_OK);
  cr_assert(strstr(err.msg, "(in lower case: 'vortex')"), "%s", err.msg);
  cr_assert_neq(lw_params_set(&p, "scene.page=b5", &err), LW_OK);
  cr_assert_null(strstr(err.msg, "lower case"), "%s", err.msg);
}
