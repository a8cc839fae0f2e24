/* test_state.c -- state.lw round trips and malformed files. */
#include <criterion/criterion.h>
#include <gsl/gsl_math.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "linewise/number.h"
#include "linewise/state.h"
#include "testutil.h"

static char dir[64];

static void make_dir(void)
{
  lw_test_tmp_name(dir, "state");
  cr_assert_not_null(mkdtemp(dir));
}

static void remove_dir(void)
{
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  cr_assert_eq(system(cmd), 0);
}

TestSuite(state, .init = make_dir, .fini = remove_dir);

/* (2500 splines with layers: the reader's arrays grow past their first 1024) */
Test(state, round_trip_is_bit_exact)
{
  enum { N = 2500 };
  size_t segs[N];
  for (size_t i = 0; i < N; i++) segs[i] = 1 + i % 4;
  lw_state st = {.scene = "scene.ini", .seed = 12345, .sweep = 678, .sp = lw_splines_new(N, segs, NULL)};
  cr_assert_eq(lw_splines_layers_alloc(st.sp), LW_OK);
  for (size_t i = 0; i < N; i++) st.sp->layer[i] = (uint8_t)(i % 3);
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  for (size_t k = 0; k < st.sp->n_nodes; k++) {
    /* high-entropy values across many magnitudes */
    double s = pow(10.0, 12 * gsl_rng_uniform(r) - 6);
    st.sp->node[k] = (lw_node){s * (gsl_rng_uniform(r) - 0.5), s * gsl_rng_uniform(r), -s / 3, M_PI * s};
  }
  for (int i = 0; i < N; i++) st.sp->rest_length[i] = 1.0 / (i + 3.0);
  char path[128];
  snprintf(path, sizeof path, "%s/state.lw", dir);
  lw_error err;
  cr_assert_eq(lw_state_write(&st, path, &err), LW_OK, "%s", err.msg);
  lw_state back;
  cr_assert_eq(lw_state_read(&back, path, &err), LW_OK, "%s", err.msg);
  cr_assert_str_eq(back.scene, "scene.ini");
  cr_assert_eq(back.seed, 12345);
  cr_assert_eq(back.sweep, 678);
  cr_assert_eq(back.sp->n_splines, N);
  cr_assert_eq(back.sp->n_nodes, st.sp->n_nodes);
  cr_assert(!memcmp(back.sp->node, st.sp->node, st.sp->n_nodes * sizeof(lw_node)), "nodes differ");
  cr_assert(!memcmp(back.sp->rest_length, st.sp->rest_length, N * sizeof(double)));
  cr_assert(!memcmp(back.sp->first, st.sp->first, (N + 1) * sizeof *st.sp->first), "segment counts differ");
  cr_assert(back.sp->layer && !memcmp(back.sp->layer, st.sp->layer, N), "layers differ");
  char tmp[160];
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  cr_assert(access(tmp, F_OK) != 0, "temporary file left behind");
  lw_state_clear(&back);
  lw_state_clear(&st);
  gsl_rng_free(r);
}

static void expect_bad(const char *text, const char *line, const char *key)
{
  char path[128];
  snprintf(path, sizeof path, "%s/bad.lw", dir);
  FILE *f = fopen(path, "w");
  fputs(text, f);
  fclose(f);
  lw_state st;
  lw_error err;
  cr_assert_eq(lw_state_read(&st, path, &err), LW_EINPUT, "accepted: %s", text);
  cr_assert(strstr(err.msg, line) && strstr(err.msg, key) && strstr(err.msg, "bad.lw"),
            "message '%s' should name bad.lw, line '%s' and '%s'", err.msg, line, key);
  cr_assert_null(st.sp);
}

Test(state, malformed_files_name_line_and_key)
{
  const char *head = "linewise-state 1\nscene s.ini\nseed 1\nsweep 0\n";
  char buf[512];
  /* an empty file says so (it was "bad.lw:0: header ... got 'end of file'"),
  ** and a picture given as a state is named, not printed raw */
  expect_bad("", "bad.lw: empty file (0 bytes), not a state", "'linewise-state <version>'");
  expect_bad("\x89PNG\r\n\x1a\n\n", ":1:", "got binary bytes (a PNG picture, not a state)");
  expect_bad("\xff\xd8\xff\xe0\x01\x10JFIF\n", ":1:", "got binary bytes (not a state, which is text)");
  expect_bad("l\xe4uft 1\n", ":1:", "got bytes that are not UTF-8 text (a state is text)");
  expect_bad("l\xc0\xa4uft 1\n", ":1:", "not UTF-8 text"); /* an overlong lead byte */
  expect_bad("\x7f" "ELF\n", ":1:", "got binary bytes");
  { /* a real JPEG's first line holds a NUL (its APP0 length): binary too */
    char path[128];
    snprintf(path, sizeof path, "%s/bad.lw", dir);
    FILE *f = fopen(path, "wb");
    fwrite("\xff\xd8\xff\xe0\0\x10JFIF\n", 1, 11, f);
    fclose(f);
    lw_state st;
    lw_error err;
    cr_assert_eq(lw_state_read(&st, path, &err), LW_EINPUT);
    cr_assert(strstr(err.msg, "bad.lw:1: header: expected 'linewise-state <version>', got binary bytes"), "%s",
              err.msg);
  }
  expect_bad("l\xc3\xa4uft 1\n", ":1:", "got 'l\xc3\xa4uft 1'");
  expect_bad("linewise-state 9\n", ":1:", "version");
  expect_bad("linewise-state 1\nscene\n", ":2:", "scene");
  expect_bad("linewise-state 1\nscene s.ini\nseed -4\n", ":3:", "seed");
  snprintf(buf, sizeof buf, "%ssplines x\n", head);
  expect_bad(buf, ":5:", "splines");
  snprintf(buf, sizeof buf, "%ssplines 1\nspline 0 3\n", head);
  expect_bad(buf, ":6:", "spline");
  snprintf(buf, sizeof buf, "%ssplines 1\nspline 1 3\n0 0 1 0\n1 0 nan 0\nend\n", head);
  expect_bad(buf, ":8:", "node");
  snprintf(buf, sizeof buf, "%ssplines 1\nspline 1 3\n0 0 1 0\n1 0 1\nend\n", head);
  expect_bad(buf, ":8:", "node");
  snprintf(buf, sizeof buf, "%ssplines 2\nspline 1 3\n0 0 1 0\n1 0 1 0\nend\n", head);
  expect_bad(buf, ":9:", "spline");
  snprintf(buf, sizeof buf, "%ssplines 1\nspline 1 3\n0 0 1 0\n1 0 1 0\n", head);
  expect_bad(buf, "end", "end");
  snprintf(buf, sizeof buf, "%ssplines 1\nspline 1 3\n0 0 1 0\n1 0 1 0\nend\nmore\n", head);
  expect_bad(buf, ":10:", "end");
}

Test(state, failed_write_keeps_the_old_file)
{
  char path[128];
  snprintf(path, sizeof path, "%s/nodir/state.lw", dir);
  size_t segs[1] = {1};
  lw_state st = {.scene = "s.ini", .seed = 1, .sp = lw_splines_new(1, segs, NULL)};
  lw_error err;
  cr_assert_eq(lw_state_write(&st, path, &err), LW_EIO);
  cr_assert(strstr(err.msg, "nodir"));
  lw_state_clear(&st);
}

Test(state, format_2_malformed_files_name_line_section_and_key)
{
  const char *head = "linewise-state 2\n[run]\nscene = s.ini\nseed = 1\nsweep = 0\n[system splines]\n";
  char buf[512];
  expect_bad("linewise-state 2\nscene = s.ini\n", ":2:", "section");
  expect_bad("linewise-state 2\n[run]\nscene s.ini\n", ":3:", "key = value");
  expect_bad("linewise-state 2\n[run]\n[run]\n", ":3:", "[run] repeated");
  expect_bad("linewise-state 2\n[run\n", ":2:", "section");
  expect_bad("linewise-state 2\n[run]\nscene = s.ini\nseed = 0x1\nsweep = 0\n", ":4:", "[run] seed");
  expect_bad("linewise-state 2\n[run]\nscene = s.ini\nseed = 1\nsweep = 1e16\n", ":5:", "[run] sweep");
  snprintf(buf, sizeof buf, "%ssplines = 1\nspline = 1 3\nnode = 0 0 1 0\nnode = 1 0 1 0x1\n", head);
  expect_bad(buf, ":10:", "spline 0 node 1");
  snprintf(buf, sizeof buf, "%ssplines = 1\nspline = 1 3\nnode = 0 0 1 0\nnode = 1 0 1 2e9\n", head);
  expect_bad(buf, ":10:", "spline 0 node 1");
  snprintf(buf, sizeof buf, "%ssplines = 1\nspline = 1 3\nnode = 0 0 1 0\n", head);
  expect_bad(buf, ":9:", "spline 0 node 1");
  snprintf(buf, sizeof buf, "%ssplines = 1\nspline = 1 3\nnode = 0 0 1 0\nnode = 1 0 1 0\nnode = 1 0 1 0\n", head);
  expect_bad(buf, ":11:", "expected nothing after");
  snprintf(buf, sizeof buf, "%ssplines = 1\nspline = 1 3\nnode = 0 0 1 0\nno\001de = 1 0 1 0\n", head);
  expect_bad(buf, ":10:", "spline 0 node 1");
}

/* The sectioned file API as a system uses it: its own section written and
** read back without knowing the rest; unknown keys and sections refused
** only when the reader asks, missing optional keys keep their defaults. */
Test(state, sections_and_keys_round_trip_and_refuse_what_is_unknown)
{
  char path[128];
  snprintf(path, sizeof path, "%s/k.lw", dir);
  lw_ckpt_writer w;
  lw_error err;
  cr_assert_eq(lw_ckpt_begin(&w, path, "linewise-test 1", &err), LW_OK);
  lw_ckpt_section(&w, "system demo");
  double v[3] = {M_PI, -1e-310, 6.02214076e23};
  unsigned long u[2] = {0, 9007199254740992UL};
  lw_ckpt_put_numbers(&w, "x", v, 3);
  lw_ckpt_put_counts(&w, "n", u, 2);
  lw_ckpt_put(&w, "item", "%d", 1);
  lw_ckpt_put(&w, "item", "%d", 2);
  lw_ckpt_section(&w, "later");
  lw_ckpt_put(&w, "novel", "%s", "1");
  cr_assert_eq(lw_ckpt_commit(&w, &err), LW_OK, "%s", err.msg);
  lw_ckpt *c;
  cr_assert_eq(lw_ckpt_read(&c, path, &err), LW_OK, "%s", err.msg);
  cr_assert_str_eq(lw_ckpt_header(c), "linewise-test 1");
  double back[3], opt = 42;
  unsigned long ub[2];
  cr_assert_eq(lw_ckpt_numbers(c, "system demo", "x", back, 3, -1e300, 1e300, 1, &err), LW_OK, "%s", err.msg);
  cr_assert(!memcmp(back, v, sizeof v), "numbers changed on a write/read cycle");
  cr_assert_eq(lw_ckpt_counts(c, "system demo", "n", ub, 2, 1, &err), LW_OK, "%s", err.msg);
  cr_assert(ub[0] == u[0] && ub[1] == u[1]);
  cr_assert_eq(lw_ckpt_numbers(c, "system demo", "absent", &opt, 1, 0, 100, 0, &err), LW_OK);
  cr_assert_eq(opt, 42, "a missing optional key must keep its default");
  cr_assert_eq(lw_ckpt_numbers(c, "system demo", "absent", &opt, 1, 0, 100, 1, &err), LW_EINPUT);
  cr_assert_eq(lw_ckpt_numbers(c, "system demo", "x", back, 3, 0, 1, 1, &err), LW_EINPUT, "range not checked");
  cr_assert(strstr(err.msg, "k.lw:4: [system demo] x: expected 3 numbers"), "%s", err.msg);
  size_t pos = 0;
  const char *key, *val;
  int items = 0;
  while (lw_ckpt_next(c, "system demo", &pos, &key, &val, NULL))
    if (!strcmp(key, "item")) cr_assert_eq(atoi(val), ++items, "bulk entries out of order");
  cr_assert_eq(items, 2);
  cr_assert_eq(lw_ckpt_unread(c, &err), LW_EINPUT, "an unknown section passed");
  cr_assert(strstr(err.msg, "section [later] is unknown"), "%s", err.msg);
  cr_assert(lw_ckpt_has(c, "later"));
  cr_assert_eq(lw_ckpt_unread(c, &err), LW_EINPUT, "an unknown key passed");
  cr_assert(strstr(err.msg, "k.lw:10: [later] novel: unknown"), "%s", err.msg);
  cr_assert_not_null(lw_ckpt_text(c, "later", "novel", NULL));
  cr_assert_eq(lw_ckpt_unread(c, &err), LW_OK, "%s", err.msg);
  lw_ckpt_free(c);
}

Test(state, strict_numbers)
{
  /* a number not 0 that reads as 0 (underflow past the subnormals) is
  ** refused, as overflow is: "1e-400" made moves.fixed_count 0 */
  static const char *good[] = {"0",  "-0",       "+12",      "1.5",    ".5",
                               "5.", "1e3",      "1E-3",     "-2.5e+10", "4.9406564584124654e-324",
                               "0e-400", "1e-320"};
  static const char *bad[] = {"", " 1", "1 ", "0x10", "inf", "nan", "1e", "e3", ".", "-", "1.2.3", "100mm", "1e999",
                              "1,5", "--1", "1e-400", "-2e-999"};
  double v;
  for (size_t i = 0; i < sizeof good / sizeof *good; i++) cr_expect(lw_number_parse(good[i], &v), "refused '%s'", good[i]);
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) cr_expect(!lw_number_parse(bad[i], &v), "accepted '%s'", bad[i]);
  cr_assert(lw_number_parse_n("12\0garbage", 11, &v) == 0, "a NUL inside must not end the number");
  long long n;
  cr_assert(lw_number_parse_whole("1e3", 0, 1e15, &n) && n == 1000);
  cr_assert(!lw_number_parse_whole("1.5", 0, 1e15, &n) && !lw_number_parse_whole("1e16", 0, 1e15, &n));
  double list[4];
  cr_assert_eq(lw_number_list("1, 2, 3 ,4", 1, list, 4), 4);
  cr_assert_eq(lw_number_list(" 1\t2 3 4 ", 1, list, 4), 4);
  cr_assert_eq(lw_number_list("1 2 3 4 5", 0, list, 2), 5, "tokens past max are counted");
  cr_assert_eq(lw_number_list("1 2x", 0, list, 4), -1);
  /* a comma alone between digits beside blanks alone: decimal commas
  ** ("0,5 0,7": 2 numbers, not 4), the SVG style too; ", " and "," read, as
  ** every mix does for a run's own scene.ini (1) */
  cr_assert_eq(lw_number_list("0,5 0,7", 2, list, 4), -2);
  cr_assert_eq(lw_number_list("10,2 10,4 90,6 10,8", 2, list, 4), -2);
  cr_assert_eq(lw_number_list("10,5 20,5 90 10 50 90", 2, list, 4), -2);
  cr_assert_eq(lw_number_list("0,5 0,7", 1, list, 4), 4);
  cr_assert_eq(lw_number_list("1,2,3,4", 2, list, 4), 4);
  cr_assert_eq(lw_number_list("0 0 0 0, 0.25, 0.5, 0.75, 1 1 1 1", 2, list, 4), 11);
  cr_assert_eq(lw_number_list("1, 2 4", 2, list, 4), 3);
  cr_assert_eq(lw_number_list("1 ,2\t3", 2, list, 4), 3);
  cr_assert(strstr(lw_number_list_hint(-2), "0.5 not 0,5") && !*lw_number_list_hint(-1));
  /* an empty field, which read as none ("0,,5" as 0 5, nurbs.file's point
  ** (0, 5)), but not at the end (a point cloud's blank normals) */
  cr_assert_eq(lw_number_list("0,,5", 2, list, 4), -3);
  cr_assert_eq(lw_number_list("0, ,5", 2, list, 4), -3);
  cr_assert_eq(lw_number_list("0,\t,5", 2, list, 4), -3, "a tab-separated blank cell");
  cr_assert_eq(lw_number_list(",1 2", 2, list, 4), -3);
  cr_assert_eq(lw_number_list("1,2,", 2, list, 4), 2);
  cr_assert_eq(lw_number_list("0,,5", 1, list, 4), 2, "a run's own scene.ini as it was");
  cr_assert(strstr(lw_number_list_hint(-3), "an empty value between two commas"));
}

/* Text stops at its first NUL: a line reader returns what came before it,
** and a state padded with NULs (a sparse file: 96 MiB of them, more than a
** line may hold) is refused at once naming the NUL, not read to 64 MiB and
** called a long line, nor called cut short (it ends in NULs, not a line). */
Test(state, text_stops_at_its_first_nul)
{
  char path[128];
  snprintf(path, sizeof path, "%s/nul.txt", dir);
  FILE *f = fopen(path, "wb");
  fwrite("ab\0cd\nef\n", 1, 9, f);
  fclose(f);
  f = fopen(path, "rb");
  char *buf = NULL;
  size_t cap = 0;
  cr_assert_eq(lw_text_getline(&buf, &cap, f), 3, "the line up to its NUL, and the NUL");
  cr_assert_str_eq(buf, "ab");
  free(buf);
  fclose(f);
  snprintf(path, sizeof path, "%s/state.lw", dir);
  f = fopen(path, "wb");
  fputs("linewise-state 2\n", f);
  fclose(f);
  cr_assert_eq(truncate(path, 96L << 20), 0);
  lw_state st;
  lw_error err;
  cr_assert_eq(lw_state_read(&st, path, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "state.lw:2: a NUL byte inside the line"), "%s", err.msg);
  unlink(path);
  snprintf(path, sizeof path, "%s/nul.txt", dir);
  unlink(path);
  rmdir(dir);
}
