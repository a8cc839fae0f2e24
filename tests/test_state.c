/* test_state.c -- state.lw round trips and malformed files. */
#include <criterion/criterion.h>
#include <gsl/gsl_math.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "linewise/state.h"

static char dir[64];

static void make_dir(void)
{
  strcpy(dir, "/tmp/lw_state_XXXXXX");
  cr_assert_not_null(mkdtemp(dir));
}

static void remove_dir(void)
{
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  cr_assert_eq(system(cmd), 0);
}

TestSuite(state, .init = make_dir, .fini = remove_dir);

Test(state, round_trip_is_bit_exact)
{
  size_t segs[3] = {1, 4, 2};
  lw_state st = {.scene = "scene.ini", .seed = 12345, .sweep = 678, .sp = lw_splines_new(3, segs, NULL)};
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  for (size_t k = 0; k < st.sp->n_nodes; k++) {
    /* high-entropy values across many magnitudes */
    double s = pow(10.0, 12 * gsl_rng_uniform(r) - 6);
    st.sp->node[k] = (lw_node){s * (gsl_rng_uniform(r) - 0.5), s * gsl_rng_uniform(r), -s / 3, M_PI * s};
  }
  for (int i = 0; i < 3; i++) st.sp->rest_length[i] = 1.0 / (i + 3.0);
  char path[128];
  snprintf(path, sizeof path, "%s/state.lw", dir);
  lw_error err;
  cr_assert_eq(lw_state_write(&st, path, &err), LW_OK, "%s", err.msg);
  lw_state back;
  cr_assert_eq(lw_state_read(&back, path, &err), LW_OK, "%s", err.msg);
  cr_assert_str_eq(back.scene, "scene.ini");
  cr_assert_eq(back.seed, 12345);
  cr_assert_eq(back.sweep, 678);
  cr_assert_eq(back.sp->n_splines, 3);
  cr_assert_eq(back.sp->n_nodes, st.sp->n_nodes);
  cr_assert(!memcmp(back.sp->node, st.sp->node, st.sp->n_nodes * sizeof(lw_node)), "nodes differ");
  cr_assert(!memcmp(back.sp->rest_length, st.sp->rest_length, 3 * sizeof(double)));
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
  expect_bad("", ":0:", "header");
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
