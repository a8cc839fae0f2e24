/*
** test_fieldfile.c -- field files (fieldfile.h): the .npy reader against
** arrays written here byte by byte (both byte orders, C and Fortran order,
** versions 1 and 2, integers), the text reader (blanks, commas, comments,
** nan), the messages of the files refused; and scene.field = file: which
** way up the grid lies, its lengths, where on the page it lies.
*/
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "imageutil.h"
#include "linewise/fieldfile.h"
#include "linewise/params.h"
#include "linewise/scene.h"
#include "testutil.h"

TestSuite(fieldfile, .init = lw_image_dir_make, .fini = lw_image_dir_remove);

/* A 2-row, 3-column field: node (i, j) holds u = 10 j + i, v = -(10 j + i) - 0.5
** (exact in float too). */
static double value(int j, int i, int c) { return c ? -(10.0 * j + i) - 0.5 : 10.0 * j + i; }

/* Writes an .npy of that field (version major, dtype descr of `size`
** bytes, big-endian or not, Fortran order or not) to name; its path. */
static const char *write_npy(const char *name, int major, const char *descr, int size, int big, int fortran)
{
  char dict[160];
  int n = snprintf(dict, sizeof dict, "{'descr': '%s', 'fortran_order': %s, 'shape': (2, 3, 2), }", descr,
                   fortran ? "True" : "False");
  const int pre = major == 1 ? 10 : 12;
  while ((pre + n + 1) % 64) dict[n++] = ' ';
  dict[n++] = '\n';
  unsigned char buf[512];
  size_t at = 0;
  memcpy(buf, "\x93NUMPY", 6);
  buf[6] = (unsigned char)major;
  buf[7] = 0;
  buf[8] = (unsigned char)(n & 0xff);
  buf[9] = (unsigned char)(n >> 8);
  if (major > 1) buf[10] = buf[11] = 0;
  at = (size_t)pre;
  memcpy(buf + at, dict, (size_t)n);
  at += (size_t)n;
  for (int e = 0; e < 12; e++) {
    /* C order: (j, i, c), c fastest; Fortran: j fastest */
    const int j = fortran ? e % 2 : e / 6, i = fortran ? e / 2 % 3 : e / 2 % 3, c = fortran ? e / 6 : e % 2;
    const double v = value(j, i, c);
    unsigned char b[8];
    if (descr[1] == 'f' && size == 8) memcpy(b, &v, 8);
    else if (descr[1] == 'f') {
      float f = (float)v;
      memcpy(b, &f, 4);
    } else { /* (integers: v's whole part, in the dtype's size, its low byte first) */
      const int64_t k = (int64_t)floor(v);
      for (int q = 0; q < size; q++) b[q] = (unsigned char)((uint64_t)k >> (8 * q));
    }
    for (int k = 0; k < size; k++) buf[at + (size_t)k] = big ? b[size - 1 - k] : b[k];
    at += (size_t)size;
  }
  const char *path = lw_test_path(name);
  lw_test_write(path, buf, at);
  return path;
}

static void assert_field(const lw_grid2d *g, int integers)
{
  cr_assert_eq(g->nx, 3);
  cr_assert_eq(g->ny, 2);
  cr_assert_eq(g->ncomp, 2);
  for (int j = 0; j < 2; j++)
    for (int i = 0; i < 3; i++)
      for (int c = 0; c < 2; c++) {
        const double want = integers ? floor(value(j, i, c)) : value(j, i, c);
        cr_assert_eq(g->data[(j * 3 + i) * 2 + c], want, "node (%d, %d) component %d: %g, expected %g", i, j, c,
                     g->data[(j * 3 + i) * 2 + c], want);
      }
}

Test(fieldfile, npy_reads_both_byte_orders_both_index_orders_and_integers)
{
  static const struct {
    int major;
    const char *descr;
    int size, big, fortran, integers;
  } cases[] = {
    {1, "<f8", 8, 0, 0, 0}, {1, ">f8", 8, 1, 0, 0}, {1, "<f4", 4, 0, 1, 0},
    {2, ">f4", 4, 1, 1, 0}, {3, "<i4", 4, 0, 0, 1}, {1, ">i4", 4, 1, 1, 1},
    {1, "|i1", 1, 0, 0, 1}, {2, ">i2", 2, 1, 0, 1}, {1, "<i2", 2, 0, 1, 1}, {1, ">i8", 8, 1, 0, 1},
  };
  for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
    char name[32];
    snprintf(name, sizeof name, "f%zu.npy", k);
    const char *path = write_npy(name, cases[k].major, cases[k].descr, cases[k].size, cases[k].big, cases[k].fortran);
    lw_error err;
    lw_grid2d *g = lw_fieldfile_read(path, 2, 0, &err);
    cr_assert_not_null(g, "%s: %s", cases[k].descr, err.msg);
    assert_field(g, cases[k].integers);
    lw_grid2d_free(g);
  }
}

Test(fieldfile, text_reads_blanks_commas_comments_and_nan)
{
  const char *path = lw_test_path("f.csv");
  static const char text[] = "# u v pairs, as np.savetxt writes them\r\n"
                             "0 -0.5, 1, -1.5\t2 -2.5   # a comment\r\n"
                             "\n"
                             "10,-10.5,11,-11.5,12,-12.5\n";
  lw_test_write(path, text, sizeof text - 1);
  lw_error err;
  lw_grid2d *g = lw_fieldfile_read(path, 2, 0, &err);
  cr_assert_not_null(g, "%s", err.msg);
  assert_field(g, 0);
  lw_grid2d_free(g);
  /* (1e400 and 1e-400 as NumPy reads them: infinite, 0) */
  /* (capital E too, as Fortran and %E write it) */
  static const char masked[] = "nan NaN 1 2\n-inf 0 3 1E400\n1e-400 0 0 0\n";
  lw_test_write(path, masked, sizeof masked - 1);
  g = lw_fieldfile_read(path, 2, 0, &err);
  cr_assert_not_null(g, "%s", err.msg);
  cr_assert(isnan(g->data[0]) && isnan(g->data[1]) && g->data[2] == 1 && g->data[3] == 2);
  cr_assert(isinf(g->data[4]) && g->data[4] < 0 && g->data[5] == 0 && isinf(g->data[7]) && g->data[8] == 0);
  cr_assert_eq(lw_grid2d_sanitize(g), 4);
  lw_grid2d_free(g);
}

/* The message for a file of these bytes holds every one of the words. */
static void refused(const char *name, const void *bytes, size_t n, const char *const *words)
{
  const char *path = lw_test_path(name);
  lw_test_write(path, bytes, n);
  lw_error err;
  lw_grid2d *g = lw_fieldfile_read(path, 2, 0, &err);
  cr_assert_null(g, "%s was read", name);
  cr_assert_eq(err.code, LW_EINPUT, "%s: code %d (%s)", name, err.code, err.msg);
  cr_assert(strstr(err.msg, path), "%s: the message does not name the file: %s", name, err.msg);
  for (; *words; words++) cr_assert(strstr(err.msg, *words), "%s: no '%s' in: %s", name, *words, err.msg);
}

#define REFUSED(name, text, ...) refused(name, text, sizeof text - 1, (const char *const[]){__VA_ARGS__, NULL})

/* An .npy (version 1) of header dict and then n bytes of data, refused with words. */
static void refused_npy(const char *name, const char *dict, const char *data, size_t n, const char *const *words)
{
  char buf[512];
  const size_t len = strlen(dict);
  memcpy(buf, "\x93NUMPY\x01\x00", 8);
  buf[8] = (char)(len & 0xff);
  buf[9] = (char)(len >> 8);
  memcpy(buf + 10, dict, len);
  memcpy(buf + 10 + len, data, n);
  refused(name, buf, 10 + len + n, words);
}

#define REFUSED_NPY(name, dict, data, ...) \
  refused_npy(name, dict, data, sizeof data - 1, (const char *const[]){__VA_ARGS__, NULL})

Test(fieldfile, text_refused_says_the_line_and_what_was_expected)
{
  REFUSED("odd.txt", "1 2 3\n", ":1:", "even count");
  REFUSED("short.txt", "1 2 3 4\n# c\n1 2\n", ":3:", "2 values", "line 1", "has 4");
  REFUSED("word.txt", "1 2\n3 u0\n", ":2:", "value 2", "'u0'", "not a number");
  /* hex, which strtod reads (the out-of-range reading let it through) */
  REFUSED("hex.txt", "1 2\n3 0x10\n", ":2:", "value 2", "'0x10'", "not a number");
  REFUSED("hexfloat.txt", "1 0X1p3\n", ":1:", "value 2", "not a number");
  REFUSED("empty.txt", "1,,2,3\n", ":1:", "empty value");
  REFUSED("first.txt", ",1,0,1,0\n", ":1:", "empty value after value 0");
  REFUSED("semicolon.txt", "0,5;0,7\n", ";", "decimal point");
  REFUSED("none.txt", "# nothing\n\n", "found none");
  REFUSED("nul.txt", "1 2\0 3 4\n", ":1:", "NUL");
  /* decimal commas between blanks, and old Mac line ends, read silently as
  ** twice the nodes and as one row */
  REFUSED("comma.txt", "0,5 0,7 1,0 0,2\n", ":1:", "decimal commas?");
  REFUSED("cr.txt", "1 0 1 0\r0 1 0 1\r", ":1:", "old Mac line ends");
  /* a header row, and a list of points (gnuplot's "x y u v") read as a grid of 2 columns */
  REFUSED("header.csv", "x,y,u,v\n0,0,1,0\n", ":1:", "'x', is not a number", "field_file_layout = points");
  REFUSED("xyuv.dat", "0 0 1 0\n1 0 1 0\n2 0 1 0\n3 0 1 0\n0 1 1 0\n1 1 1 0\n2 1 1 0\n3 1 1 0\n",
          "2 columns x 8 rows", "field_file_layout = points");
}

Test(fieldfile, npy_refused_says_what_was_expected)
{
  REFUSED_NPY("shape.npy", "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }\n", "", "(2, 3)",
              "(rows, columns, 2)");
  REFUSED_NPY("complex.npy", "{'descr': '<c16', 'fortran_order': False, 'shape': (1, 1, 2), }\n", "", "'<c16'",
              "z.real, z.imag");
  REFUSED_NPY("bool.npy", "{'descr': '|b1', 'fortran_order': False, 'shape': (1, 1, 2), }\n", "", "'|b1'",
              "astype");
  REFUSED_NPY("records.npy", "{'descr': [('u', '<f8')], 'fortran_order': False, 'shape': (1,), }\n", "",
              "structured");
  /* a header whose shape asks for 25 GB, in a file of a few bytes: refused before any allocation */
  REFUSED_NPY("huge.npy", "{'descr': '<f8', 'fortran_order': False, 'shape': (40000, 40000, 2), }\n", "",
              "at most");
  REFUSED_NPY("cut.npy", "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 1, 2), }\n",
              "\0\0\0\0\0\0\xf0\x3f", "cut short");
  REFUSED_NPY("long.npy", "{'descr': '|u1', 'fortran_order': False, 'shape': (1, 1, 2), }\n", "\1\2\3",
              "expected the file to end there");
  REFUSED_NPY("order.npy", "{'descr': '<f8', 'fortran_order': maybe, 'shape': (1, 1, 2), }\n", "",
              "True or False");
  static const char version[] = "\x93NUMPY\x09\x00\x10\x00{}";
  REFUSED("version.npy", version, "version 9.0");
  REFUSED("zip.npz", "PK\x03\x04....", "np.savez");
}

Test(fieldfile, a_picture_is_named_with_where_its_field_comes_from)
{
  const char *path = lw_test_path("pic.png");
  const float g[4] = {0, 1, 1, 0};
  lw_test_png(path, 2, 2, g, NULL);
  lw_error err;
  cr_assert_null(lw_fieldfile_read(path, 2, 0, &err));
  cr_assert(strstr(err.msg, "a PNG picture") && strstr(err.msg, "etf or gradient"), "%s", err.msg);
}

/* The parameters of a 100 x 50 mm page (margin 5) with a signed field from
** the text in a file (y and scale as given). */
static lw_params field_params(const char *text, int y, int scale, const char *image)
{
  lw_params p;
  lw_params_defaults(&p);
  p.width = 100;
  p.height = 50;
  p.margin = 5;
  p.field_coef = -1;
  p.field_mode = LW_FIELDMODE_SIGNED;
  p.field = LW_FLD_FILE;
  p.field_file_y = y;
  p.field_file_scale = scale;
  snprintf(p.field_file, sizeof p.field_file, "%s", lw_test_path("scene.txt"));
  lw_test_write(p.field_file, text, strlen(text));
  if (image) snprintf(p.image, sizeof p.image, "%s", image);
  return p;
}

/* A scene of field_params, or the status and the message in err. */
static lw_status field_scene(lw_scene *sc, const char *text, int y, int scale, const char *image, lw_error *err)
{
  const lw_params p = field_params(text, y, scale, image);
  return lw_scene_init(sc, &p, err);
}

Test(fieldfile, up_puts_the_first_row_at_the_bottom_and_turns_v_up_the_page)
{
  /* two rows of two nodes: the first row (u 1, v 1), the second (u -1, v 0);
  ** fitted into 90 x 40 mm, the 2 x 2 grid is 40 mm square, nodes 20 mm
  ** apart at x 40 and 60, y 15 and 35 */
  static const char text[] = "1 1 1 1\n-1 0 -1 0\n";
  for (int y = LW_FFY_UP; y <= LW_FFY_DOWN; y++) {
    lw_scene sc;
    lw_error err;
    cr_assert_eq(field_scene(&sc, text, y, LW_FFS_NONE, NULL, &err), LW_OK, "%s", err.msg);
    double top[2], bottom[2];
    lw_field_eval(&sc.field, 50, 15, &top[0], &top[1]);
    lw_field_eval(&sc.field, 50, 35, &bottom[0], &bottom[1]);
    const double *first = y == LW_FFY_UP ? bottom : top, *second = y == LW_FFY_UP ? top : bottom;
    cr_assert_eq(first[0], 1.0, "y %d: the first row's u at its end of the grid: %g", y, first[0]);
    cr_assert_eq(first[1], y == LW_FFY_UP ? -1.0 : 1.0, "y %d: v %g", y, first[1]);
    cr_assert_eq(second[0], -1.0);
    cr_assert_eq(second[1], 0.0);
    /* half way between the rows, the mean */
    double mid[2];
    lw_field_eval(&sc.field, 50, 25, &mid[0], &mid[1]);
    cr_assert(fabs(mid[0]) < 1e-12, "u half way: %g", mid[0]);
    lw_scene_clear(&sc);
  }
}

Test(fieldfile, scale_makes_vectors_unit_divides_by_the_longest_or_keeps_them)
{
  static const char text[] = "2 0 0 4\n2 0 0 4\n";
  const double want[3][2] = {{1, 1}, {0.5, 1}, {2, 4}}; /* |v| at the left and right nodes */
  for (int s = LW_FFS_UNIT; s <= LW_FFS_NONE; s++) {
    lw_scene sc;
    lw_error err;
    cr_assert_eq(field_scene(&sc, text, LW_FFY_DOWN, s, NULL, &err), LW_OK, "%s", err.msg);
    double l[2], r[2];
    lw_field_eval(&sc.field, 40, 25, &l[0], &l[1]);
    lw_field_eval(&sc.field, 60, 25, &r[0], &r[1]);
    cr_assert(fabs(hypot(l[0], l[1]) - want[s][0]) < 1e-12 && fabs(hypot(r[0], r[1]) - want[s][1]) < 1e-12,
              "scale %d: %g and %g", s, hypot(l[0], l[1]), hypot(r[0], r[1]));
    lw_scene_clear(&sc);
  }
}

Test(fieldfile, the_grid_covers_the_picture_and_a_grid_of_another_shape_is_refused)
{
  /* a 40 x 20 picture fitted into 90 x 40 mm lies 80 x 40 mm, from x 10 */
  char pic[256]; /* (lw_test_path's results last four calls) */
  snprintf(pic, sizeof pic, "%s", lw_test_path("wide.png"));
  float g[40 * 20];
  for (int k = 0; k < 40 * 20; k++) g[k] = 0.5f;
  lw_test_png(pic, 40, 20, g, NULL);
  lw_scene sc;
  lw_error err;
  /* 4 columns x 2 rows: node centres 20 mm apart from (20, 15) */
  cr_assert_eq(field_scene(&sc, "1 0 2 0 3 0 4 0\n5 0 6 0 7 0 8 0\n", LW_FFY_DOWN, LW_FFS_NONE, pic, &err), LW_OK,
               "%s", err.msg);
  double v[2];
  lw_field_eval(&sc.field, 20, 15, &v[0], &v[1]);
  cr_assert_eq(v[0], 1.0);
  lw_field_eval(&sc.field, 80, 35, &v[0], &v[1]);
  cr_assert_eq(v[0], 8.0);
  lw_field_eval(&sc.field, 30, 25, &v[0], &v[1]);
  cr_assert(fabs(v[0] - 3.5) < 1e-12, "between four nodes: %g", v[0]);
  lw_scene_clear(&sc);
  cr_assert_neq(field_scene(&sc, "1 0 2 0\n3 0 4 0\n5 0 6 0\n7 0 8 0\n", LW_FFY_DOWN, LW_FFS_NONE, pic, &err), LW_OK);
  cr_assert(strstr(err.msg, "2 columns x 4 rows") && strstr(err.msg, "40 x 20 picture") &&
            strstr(err.msg, "scene.field_file"), "%s", err.msg);
  /* a row off is a stretch of 2 on a grid this coarse: refused; 3 columns
  ** take 1.5 rows, so 2 rows are the shape rounded */
  cr_assert_neq(field_scene(&sc, "1 0 2 0\n3 0 4 0\n", LW_FFY_DOWN, LW_FFS_NONE, pic, &err), LW_OK);
  cr_assert(strstr(err.msg, "2 columns x 2 rows"), "%s", err.msg);
  cr_assert_eq(field_scene(&sc, "1 0 2 0 3 0\n4 0 5 0 6 0\n", LW_FFY_DOWN, LW_FFS_NONE, pic, &err), LW_OK, "%s",
               err.msg);
  lw_scene_clear(&sc);
}

Test(fieldfile, a_grid_of_its_own_shape_lies_as_a_picture_of_that_shape)
{
  /* 4 columns x 2 rows fitted into 90 x 40 mm: 80 x 40 mm from x 10, nodes
  ** 20 mm apart from (20, 15) */
  lw_scene sc;
  lw_error err;
  cr_assert_eq(field_scene(&sc, "1 0 2 0 3 0 4 0\n5 0 6 0 7 0 8 0\n", LW_FFY_DOWN, LW_FFS_NONE, NULL, &err), LW_OK,
               "%s", err.msg);
  const double at[4][3] = {{20, 15, 1}, {80, 15, 4}, {20, 35, 5}, {60, 35, 7}};
  for (int k = 0; k < 4; k++) {
    double v[2];
    lw_field_eval(&sc.field, at[k][0], at[k][1], &v[0], &v[1]);
    cr_assert_eq(v[0], at[k][2], "at (%g, %g): %g, expected %g", at[k][0], at[k][1], v[0], at[k][2]);
  }
  lw_scene_clear(&sc);
}

Test(fieldfile, cells_not_finite_are_noted_and_a_file_without_a_vector_refused)
{
  lw_scene sc;
  lw_error err;
  cr_assert_eq(field_scene(&sc, "nan nan 1 0\n0 1 inf 0\n", LW_FFY_DOWN, LW_FFS_UNIT, NULL, &err), LW_OK, "%s",
               err.msg);
  cr_assert(strstr(sc.note, "2 of the 4 nodes not finite"), "%s", sc.note);
  double v[2];
  lw_field_eval(&sc.field, 40, 15, &v[0], &v[1]);
  cr_assert(v[0] == 0.0 && v[1] == 0.0, "a NaN node: (%g, %g)", v[0], v[1]);
  lw_scene_clear(&sc);
  cr_assert_neq(field_scene(&sc, "0 0 nan 0\n", LW_FFY_DOWN, LW_FFS_UNIT, NULL, &err), LW_OK);
  cr_assert(strstr(err.msg, "every vector is zero or not finite"), "%s", err.msg);
}

/* Runs "cd DIR && linewise <args>", stdout to out.txt and stderr to err.txt;
** the exit status. */
static int run_cli(const char *args)
{
  const char *bin = getenv("LW_BIN");
  cr_assert_not_null(bin, "LW_BIN must name bin/linewise (make test sets it)");
  return lw_test_sh("cd %s && %s %s >out.txt 2>err.txt", lw_test_dir, bin, args);
}

/* The field term's value in `linewise energy`'s output. */
static double energy_field(void)
{
  char *text = lw_test_slurp("%s", lw_test_path("out.txt"));
  const char *at = strstr(text, "\nfield ");
  cr_assert_not_null(at, "%s", text);
  const double v = strtod(at + 7, NULL);
  free(text);
  return v;
}

Test(fieldfile, a_run_follows_the_file_and_a_bad_file_is_refused_before_it)
{
  /* a field up the page in a physicist's axes, a 4 x 3 grid beside the scene */
  const char *flow = "0 1 0 1 0 1 0 1\n0 1 0 1 0 1 0 1\n0 1 0 1 0 1 0 1\n";
  lw_test_write(lw_test_path("flow.txt"), flow, strlen(flow));
  static const char scene[] = "[scene]\nwidth = 60\nheight = 50\nmargin = 4\nfield = file\nfield_file = flow.txt\n"
                              "[init]\nsplines = 12\nsegments = 3\nsegment_length = 5\n"
                              "[energy]\nstrain = 5\nbending = 1\nfield = -1\nfield_mode = signed\nboundary = 0.1\n"
                              "[anneal]\nsweeps = 30\nsteps = 3\nseed = 3\n";
  lw_test_write(lw_test_path("scene.ini"), scene, sizeof scene - 1);
  cr_assert_eq(run_cli("run scene.ini --out out --quiet"), 0, "%s", lw_test_slurp("%s", lw_test_path("err.txt")));
  /* the run's scene.ini names the file by its full path: energy reads it from elsewhere */
  cr_assert_eq(run_cli("energy out"), 0);
  const double up = energy_field();
  cr_assert(up < -0.5 * 12 * 3 * 5, "the lines run up the page: field %g of at most 180 mm of line", up);
  cr_assert_eq(run_cli("energy out --set scene.field_file_y=down"), 0);
  cr_assert(fabs(energy_field() + up) < 1e-9 * fabs(up), "down turns v over: %g against %g", energy_field(), up);
  /* one line, the file and its line, exit 2, and no run directory */
  lw_test_write(lw_test_path("flow.txt"), "0 1 0 1\n0 1\n", 12);
  cr_assert_eq(run_cli("run scene.ini --out out2 --quiet"), 2);
  char *errs = lw_test_slurp("%s", lw_test_path("err.txt"));
  cr_assert(strstr(errs, "scene.ini:6") && strstr(errs, "flow.txt:2: 2 values") && !strchr(errs, '\n')[1], "%s",
            errs);
  free(errs);
  struct stat sb;
  cr_assert_neq(stat(lw_test_path("out2"), &sb), 0, "nothing written");
}

/* The field's detail finer than the samples along a segment: annealed
** segments bent between the samples and hid up to 19 % of the field term
** (docs/NUMERICS.md).  A scene says so where it is, naming what sets the
** detail, and says nothing where the detail is wider than the samples. */
Test(fieldfile, a_field_finer_than_the_samples_gets_a_note)
{
  char pic[256];
  snprintf(pic, sizeof pic, "%s", lw_test_path("grey.png"));
  float g[64 * 64];
  for (int k = 0; k < 64 * 64; k++) g[k] = (float)(0.5 + 0.4 * sin(k % 64 * 0.3));
  lw_test_png(pic, 64, 64, g, NULL);
  static const struct {
    int field;
    double blur, wavelength;
    int grid; /* a file of grid x grid nodes, its u (i % 3 or, smooth, i / grid) */
    int smooth;
    const char *note;
  } cases[] = {
    {LW_FLD_GRADIENT, 0.5, 0, 0, 0, "(0.5 mm: scene.image_blur)"}, {LW_FLD_GRADIENT, 4, 0, 0, 0, NULL},
    {LW_FLD_WAVES, 0, 4, 0, 0, "the waves turn a radian"}, {LW_FLD_WAVES, 0, 70, 0, 0, NULL},
    /* the field's turning, not its nodes' spacing: a fine grid of a smooth field has no note */
    {LW_FLD_FILE, 0, 0, 200, 0, "field_file's field turns a radian within it between"},
    {LW_FLD_FILE, 0, 0, 8, 0, NULL}, {LW_FLD_FILE, 0, 0, 200, 1, NULL},
  };
  for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
    lw_params p;
    lw_params_defaults(&p);
    p.width = p.height = 100;
    p.margin = 5;
    p.segment_length = 8;
    p.field_coef = -1;
    p.field_mode = LW_FIELDMODE_SIGNED;
    p.field = cases[c].field;
    p.image_blur = cases[c].blur;
    if (cases[c].field == LW_FLD_GRADIENT) snprintf(p.image, sizeof p.image, "%s", pic);
    if (cases[c].wavelength > 0) p.field_wavelength = cases[c].wavelength;
    if (cases[c].grid) {
      snprintf(p.field_file, sizeof p.field_file, "%s", lw_test_path("grid.txt"));
      FILE *f = fopen(p.field_file, "w");
      for (int j = 0; j < cases[c].grid; j++)
        for (int i = 0; i < cases[c].grid; i++)
          fprintf(f, "%g 1%c", cases[c].smooth ? (double)i / cases[c].grid : i % 3, i == cases[c].grid - 1 ? '\n' : ' ');
      fclose(f);
    }
    lw_scene sc;
    lw_error err;
    cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_OK, "case %zu: %s", c, err.msg);
    if (cases[c].note)
      cr_assert(strstr(sc.note, "scene.field: the placed segments' samples lie up to") &&
                strstr(sc.note, cases[c].note), "case %zu: %s", c, sc.note);
    else
      cr_assert_null(strstr(sc.note, "scene.field:"), "case %zu: %s", c, sc.note);
    lw_scene_clear(&sc);
  }
}

/* A smooth picture (a scientist's field drawn as tones, 0..1 over a page)
** changes slower than the default field_flat nearly everywhere: the field
** was field_angle's (etf) or 0 (gradient) there, unsaid.  Said now; not
** where field_flat is below its slope. */
Test(fieldfile, a_picture_smoother_than_field_flat_gets_a_note)
{
  /* a ramp over the whole picture, and one over 60 % of it beside white
  ** paper (flat: not counted), which is under the note's three quarters */
  float g[64 * 64];
  for (int k = 0; k < 64 * 64; k++) g[k] = (float)(0.3 + 0.4 * (k % 64) / 63.0); /* 0.0044 tone/mm */
  lw_test_png(lw_test_path("ramp.png"), 64, 64, g, NULL);
  for (int k = 0; k < 64 * 64; k++) g[k] = k % 64 < 26 ? 1.0f : (float)(0.3 + 0.4 * (k % 64) / 63.0);
  lw_test_png(lw_test_path("part.png"), 64, 64, g, NULL);
  for (int field = LW_FLD_ETF; field <= LW_FLD_GRADIENT; field++)
    for (int smaller = 0; smaller < 3; smaller++) {
      const char *pic = lw_test_path(smaller == 2 ? "part.png" : "ramp.png");
      lw_params p;
      lw_params_defaults(&p);
      p.width = p.height = 100;
      p.margin = 5;
      p.field_coef = -1;
      p.field = field;
      p.field_mode = field == LW_FLD_ETF ? LW_FIELDMODE_AXIAL : LW_FIELDMODE_SIGNED;
      p.field_flat = smaller == 1 ? 1e-3 : 0.01;
      snprintf(p.image, sizeof p.image, "%s", pic);
      lw_scene sc;
      lw_error err;
      cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_OK, "%s", err.msg);
      if (smaller) cr_assert_null(strstr(sc.note, "field_flat"), "%s", sc.note);
      else
        /* with the value that follows it (the ramp's 0.0044 tone/mm); all of
        ** it, not "over 100 %" */
        cr_assert(strstr(sc.note, "scene.field_flat: on all of the picture the tone changes slower than "
                                  "field_flat") &&
                  strstr(sc.note, field == LW_FLD_ETF ? "turns to field_angle" : "fades to 0") &&
                  strstr(sc.note, "follows it (0.001 leaves 0 %, 0.0001 leaves 0 %; docs/IMAGES.md)"),
                  "%s", sc.note);
      lw_scene_clear(&sc);
    }
}

/* A list of points (ParaView's CSV, gnuplot's blocks): "x y u v" a line in
** any order, a header row of names, onto the regular grid it samples, rows
** by ascending y, its spacings kept (here 2 in x, 1 in y). */
Test(fieldfile, a_list_of_points_reads_onto_its_grid)
{
  const char *path = lw_test_path("points.csv");
  static const char text[] = "\"Points:0\",\"Points:1\",\"U:0\",\"U:1\"\n"
                             "4,1,12,-12.5\n0,0,0,-0.5\n2,0,1,-1.5\n\n# a block\n"
                             "0,1,10,-10.5\n4,0,2,-2.5\n2,1,11,-11.5\n";
  lw_test_write(path, text, sizeof text - 1);
  lw_error err;
  lw_grid2d *g = lw_fieldfile_read(path, 2, 1, &err);
  cr_assert_not_null(g, "%s", err.msg);
  assert_field(g, 0);
  cr_assert(g->hx == 2 && g->hy == 1 && g->x0 == 0 && g->y0 == 0, "spacing %g, %g from (%g, %g)", g->hx, g->hy,
            g->x0, g->y0);
  lw_grid2d_free(g);
  /* the columns by the header's names: ParaView's vector first with a third
  ** component, and Tecplot's title, VARIABLES and ZONE lines */
  static const char *const named[] = {
    "\"U:0\",\"U:1\",\"U:2\",\"Points:0\",\"Points:1\",\"Points:2\"\n12,-12.5,0,4,1,0\n0,-0.5,0,0,0,0\n"
    "1,-1.5,0,2,0,0\n10,-10.5,0,0,1,0\n2,-2.5,0,4,0,0\n11,-11.5,0,2,1,0\n",
    "TITLE = \"flow\"\nVARIABLES = \"X\", \"Y\", \"U\", \"V\"\nZONE I=3, J=2, F=POINT\n0 0 0 -0.5\n2 0 1 -1.5\n"
    "4 0 2 -2.5\n0 1 10 -10.5\n2 1 11 -11.5\n4 1 12 -12.5\n",
    /* names with blanks and units, quoted (they were split at the blanks);
    ** OpenFOAM's NAME_0 and NAME_1 after a z; Fluent's words */
    "VARIABLES = \"V [m/s]\", \"Y [m]\", \"X [m]\", \"U (m/s)\"\n-0.5 0 0 0\n-1.5 0 2 1\n-2.5 0 4 2\n-10.5 1 0 10\n"
    "-11.5 1 2 11\n-12.5 1 4 12\n",
    "x,y,z,U_0,U_1,U_2\n0,0,7,0,-0.5,9\n2,0,7,1,-1.5,9\n4,0,7,2,-2.5,9\n0,1,7,10,-10.5,9\n2,1,7,11,-11.5,9\n"
    "4,1,7,12,-12.5,9\n",
    "nodenumber, x-coordinate, y-coordinate, x-velocity, y-velocity\n1,0,0,0,-0.5\n2,2,0,1,-1.5\n3,4,0,2,-2.5\n"
    "4,0,1,10,-10.5\n5,2,1,11,-11.5\n6,4,1,12,-12.5\n",
    /* units unquoted (a spreadsheet's), and pandas' unnamed index column */
    "x [m],y [m],u (m/s),v (m/s)\n0,0,0,-0.5\n2,0,1,-1.5\n4,0,2,-2.5\n0,1,10,-10.5\n2,1,11,-11.5\n4,1,12,-12.5\n",
    ",x,y,u,v\n0,0,0,0,-0.5\n1,2,0,1,-1.5\n2,4,0,2,-2.5\n3,0,1,10,-10.5\n4,2,1,11,-11.5\n5,4,1,12,-12.5\n",
    /* pandas read and written again, R's write.csv (its row names quoted),
    ** a spreadsheet's names with blanks and units, OpenFOAM's U_x U_y */
    ",Unnamed: 0,x,y,u,v\n0,0,0,0,0,-0.5\n1,1,2,0,1,-1.5\n2,2,4,0,2,-2.5\n3,3,0,1,10,-10.5\n4,4,2,1,11,-11.5\n"
    "5,5,4,1,12,-12.5\n",
    "\"\",\"x\",\"y\",\"u\",\"v\"\n\"1\",0,0,0,-0.5\n\"2\",2,0,1,-1.5\n\"3\",4,0,2,-2.5\n\"4\",0,1,10,-10.5\n"
    "\"5\",2,1,11,-11.5\n\"6\",4,1,12,-12.5\n",
    "X Position (m),Y Position (m),U (m/s),V (m/s)\n0,0,0,-0.5\n2,0,1,-1.5\n4,0,2,-2.5\n0,1,10,-10.5\n2,1,11,-11.5\n"
    "4,1,12,-12.5\n",
    "x,y,z,U_x,U_y,U_z\n0,0,7,0,-0.5,9\n2,0,7,1,-1.5,9\n4,0,7,2,-2.5,9\n0,1,7,10,-10.5,9\n2,1,7,11,-11.5,9\n"
    "4,1,7,12,-12.5,9\n",
  };
  for (size_t k = 0; k < sizeof named / sizeof *named; k++) {
    lw_test_write(path, named[k], strlen(named[k]));
    g = lw_fieldfile_read(path, 2, 1, &err);
    cr_assert_not_null(g, "case %zu: %s", k, err.msg);
    assert_field(g, 0);
    lw_grid2d_free(g);
  }
  static const struct {
    const char *text, *word;
  } bad[] = {
    /* each named by its place and line */
    {"0 0 1 0\n1 0 1 0\n0 1 1 0\n", ": no point at (1, 1), a node of the 2 x 2 grid the other points make"},
    {"0 0 1 0\n1 0 1 0\n3 0 1 0\n", ": the x spacing is uneven: x = 0 to 1 is 1 apart, where even spacing is 1.5"},
    {"# a grid\n0 0 1 0\n1 0 1 0\n0 0 1 0\n2 0 1 0\n0 1 1 0\n1 1 1 0\n", ":4: the point at (0, 0) is there twice "
     "(first on line 2)"},
    {"x y u v\n0 0 1 0\nnan 0 1 0\n", ":3: the point at (nan, 0): expected finite coordinates"},
    /* a header naming two columns but not all was read as x y u v unsaid
    ** (speed taken for u, angle for v); a title of words naming one at
    ** most is no header (titles of real exports were refused) */
    {"x,y,speed,angle\n0,0,1,0\n1,0,1,0\n", ":1: a header row of 4 names, none of them u or v: expected names x, y, "
     "u and v"},
    {"\"X [m]\" \"Y [m]\" speed angle\n0 0 1 0\n", ":1: a header row of 4 names, none of them u or v"},
    {"flow past a cylinder\n0 0 1 0\n1 0 1 0\n0 1 1 0\n", "no point at (1, 1)"},
    /* a hole in the grid (an obstacle's): its first node, not a mistyped
    ** coordinate (its columns evenly spaced) */
    {"0 0 1 0\n1 0 1 0\n2 0 1 0\n3 0 1 0\n0 1 1 0\n3 1 1 0\n0 2 1 0\n3 2 1 0\n0 3 1 0\n1 3 1 0\n2 3 1 0\n3 3 1 0\n",
     ": no point at (1, 1), a node of the 4 x 4 grid"},
    /* a mistyped coordinate: its line, not a node of its own column */
    {"0 0 1 0\n1 0 1 0\n2 0 1 0\n0 1 1 0\n1 1 1 0\n2 1 1 0\n0 2 1 0\n1.0001 2 1 0\n2 2 1 0\n0 3 1 0\n1 3 1 0\n2 3 1 0\n",
     ":8: the point at (1.0001, 2) lies off the grid the others make: its x is that of 1 point, where a column of the "
     "grid holds 4"},
    {"Wake flow, Re 100\n0 0 1 0\n1 0 1 0\n0 1 1 0\n", "no point at (1, 1)"},
    {"flow in x direction\n0 0 1 0\n1 0 1 0\n0 1 1 0\n", "no point at (1, 1)"},
    {"0 0 1 0 5\n", "5 values: expected 4 a line"},
    {"x y u v\nx y u v\n", "found none"},
    {"x y u v\n0 0 1 0\nx y u v\n", ":3: value 1 of the row, 'x', is not a number"},
  };
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    lw_test_write(path, bad[k].text, strlen(bad[k].text));
    cr_assert_null(lw_fieldfile_read(path, 2, 1, &err), "case %zu read", k);
    cr_assert(strstr(err.msg, bad[k].word), "case %zu: %s", k, err.msg);
  }
}

/* A list of points lies on the page with its cells' own shape: 3 x 2
** nodes 2 and 1 apart span 6 x 2, fitted into 90 x 40 mm as 90 x 30 from
** (5, 10); the first row (the least y) at the bottom, v up the page. */
Test(fieldfile, a_list_of_points_keeps_its_aspect)
{
  lw_params p = field_params("x y u v\n0 0 1 1\n2 0 2 1\n4 0 3 1\n0 1 4 1\n2 1 5 1\n4 1 6 1\n", LW_FFY_UP,
                              LW_FFS_NONE, NULL);
  p.field_file_layout = LW_FFL_POINTS;
  lw_scene sc;
  lw_error err;
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_OK, "%s", err.msg);
  cr_assert(fabs(sc.field.grid->hx - 30) < 1e-12 && fabs(sc.field.grid->hy - 15) < 1e-12, "cells %g x %g mm",
            sc.field.grid->hx, sc.field.grid->hy);
  double v[2];
  lw_field_eval(&sc.field, 20, 32.5, &v[0], &v[1]); /* the least x and y: bottom left */
  cr_assert(v[0] == 1 && v[1] == -1, "(%g, %g)", v[0], v[1]);
  lw_field_eval(&sc.field, 80, 17.5, &v[0], &v[1]); /* the greatest: top right */
  cr_assert(v[0] == 6 && v[1] == -1, "(%g, %g)", v[0], v[1]);
  lw_scene_clear(&sc);
}
