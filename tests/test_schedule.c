/* test_schedule.c -- temperature schedules: formulas, the adaptive rule, the
** table file and the registry. */
#include <criterion/criterion.h>
#include <gsl/gsl_math.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "linewise/schedule.h"
#include "testutil.h"

/* The formulas written out independently of schedule.c, for comparison. */
static double expected(const lw_schedule_type *t, const lw_schedule *s, long b)
{
  double ts = s->t_start, te = s->t_end, B = (double)s->blocks, f = b / (B - 1);
  if (t == &lw_schedule_linear) return ts + (te - ts) * f;
  if (t == &lw_schedule_geometric) return ts * pow(te / ts, f);
  if (t == &lw_schedule_logarithmic) return ts / (1 + (ts / te - 1) / log(B) * log(1.0 + b));
  return ts; /* constant */
}

/* A temporary file holding text; the caller unlinks path. */
static void temp_file(char path[64], const char *text)
{
  lw_test_tmp_name(path, "schedule");
  int fd = mkstemp(path);
  cr_assert(fd >= 0, "mkstemp");
  size_t n = strlen(text);
  cr_assert_eq(write(fd, text, n), (ssize_t)n);
  close(fd);
}

/* Every row of the table, a schedule added later included (schedule.h
** promises: a temperature finite and >= 0; the analytic ones, reading
** t_start and t_end and neither a table nor their own past, hit both ends
** and are monotone between them).  A contributor's cosine schedule that
** heated half way (1 - cos for 1 + cos) passed every suite, as one that
** went below 0 did: the formula test above lists its schedules by hand. */
Test(schedule, every_row_keeps_the_promises_of_the_table)
{
  for (const lw_schedule_type *const *tp = lw_schedule_types; *tp; tp++) {
    const lw_schedule_type *t = *tp;
    if (t->needs & LW_SCHEDULE_USES_TABLE) continue; /* (its rows are the user's: table_* below) */
    const int analytic = (t->needs & LW_SCHEDULE_USES_END) && !(t->needs & LW_SCHEDULE_RECURSIVE);
    const long Bs[] = {1, 2, 5, 101};
    for (size_t i = 0; i < sizeof Bs / sizeof *Bs; i++) {
      lw_schedule s = {.t_start = 2.0, .t_end = 0.05, .blocks = Bs[i], .lambda = 0.7};
      cr_assert_eq(lw_schedule_check(t, &s, NULL), LW_OK, "%s", t->name);
      double T[101];
      lw_schedule_run(t, &s, T);
      for (long b = 0; b < s.blocks; b++) {
        cr_assert(isfinite(T[b]) && T[b] >= 0.0, "%s B=%ld: T_%ld = %g", t->name, s.blocks, b, T[b]);
        if (analytic && b > 0)
          cr_assert(T[b] <= T[b - 1] && T[b] >= s.t_end, "%s B=%ld: T_%ld = %.17g after %.17g, not monotone "
                    "between t_start and t_end", t->name, s.blocks, b, T[b], T[b - 1]);
      }
      cr_assert_eq(T[0], s.t_start, "%s: T_0 = %.17g", t->name, T[0]);
      if (analytic && s.blocks > 1) cr_assert_eq(T[s.blocks - 1], s.t_end, "%s: the last block", t->name);
    }
  }
}

Test(schedule, analytic_endpoints_monotone_and_formula)
{
  const lw_schedule_type *types[] = {&lw_schedule_linear, &lw_schedule_geometric, &lw_schedule_logarithmic};
  const long Bs[] = {2, 3, 7, 100, 100000};
  /* 1 -> 0.3: 1 + (0.3 - 1) rounds above 0.3, so the last block must be t_end itself */
  const double ends[][2] = {{10, 0.01}, {1, 0.999}, {3.7, 0.5}, {1, 0.3}};
  gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(rng, 12345);
  for (size_t k = 0; k < sizeof types / sizeof *types; k++)
    for (size_t i = 0; i < sizeof Bs / sizeof *Bs; i++)
      for (size_t e = 0; e < sizeof ends / sizeof *ends; e++) {
        const lw_schedule_type *t = types[k];
        lw_schedule s = {.t_start = ends[e][0], .t_end = ends[e][1], .blocks = Bs[i]};
        cr_assert_eq(lw_schedule_check(t, &s, NULL), LW_OK);
        long B = s.blocks;
        double *T = malloc((size_t)B * sizeof *T);
        lw_schedule_run(t, &s, T);
        cr_assert_eq(T[0], s.t_start, "%s B=%ld: T_0 = %.17g", t->name, B, T[0]);
        cr_assert_eq(T[B - 1], s.t_end, "%s B=%ld: T_B-1 = %.17g", t->name, B, T[B - 1]);
        for (long b = 1; b < B; b++)
          cr_assert(T[b] <= T[b - 1], "%s B=%ld: T_%ld = %.17g > T_%ld = %.17g", t->name, B, b, T[b], b - 1,
                    T[b - 1]);
        for (int r = 0; r < 50; r++) {
          long b = (long)gsl_rng_uniform_int(rng, (unsigned long)B);
          double want = expected(t, &s, b);
          cr_assert(lw_close_rel(T[b], want, 1e-12, 0), "%s B=%ld b=%ld: %.17g vs %.17g", t->name, B, b, T[b],
                    want);
          /* pure: the same block gives the same temperature from any caller */
          cr_assert_eq(t->temperature(&s, b, 123.0, NULL), T[b]);
        }
        /* outside the run the temperature holds */
        cr_assert_eq(t->temperature(&s, -5, 0, NULL), s.t_start);
        cr_assert_eq(t->temperature(&s, B + 10, 0, NULL), s.t_end);
        free(T);
      }
  gsl_rng_free(rng);
}

/* Ends whose ratio leaves a double's range (1e-200 / 1e200 is 0): geometric
** and the adaptive schedule's fallback step by the ratio's logarithm, and
** logarithmic by its limit t_end ln B / ln(1 + b); they quenched to t_end
** from the second step on. */
Test(schedule, ends_whose_ratio_leaves_a_double_still_cool_step_by_step)
{
  lw_schedule s = {.t_start = 1e200, .t_end = 1e-200, .blocks = 10, .lambda = 0.7};
  double T[10];
  lw_schedule_run(&lw_schedule_geometric, &s, T);
  for (int b = 0; b < 10; b++) {
    double want = pow(10.0, 200.0 - 400.0 * b / 9.0);
    cr_assert(fabs(T[b] / want - 1) < 1e-12, "geometric T_%d = %g, expected %g", b, T[b], want);
  }
  lw_schedule_run(&lw_schedule_logarithmic, &s, T);
  cr_assert(fabs(T[1] / (1e-200 * log(10.0) / log(2.0)) - 1) < 1e-12, "logarithmic T_1 = %g", T[1]);
  cr_assert(T[1] > T[2] && T[8] > T[9] && T[9] == 1e-200);
  double t1 = lw_schedule_adaptive.temperature(&s, 1, s.t_start, NULL);
  cr_assert(fabs(t1 / pow(10.0, 200.0 - 400.0 / 9.0) - 1) < 1e-12, "adaptive's fallback step: %g", t1);
  /* a subnormal ratio has a few bits: pow of it stepped 16 % off */
  lw_schedule q = {.t_start = 1e300, .t_end = 7e-24, .blocks = 3};
  lw_schedule_run(&lw_schedule_geometric, &q, T);
  cr_assert(fabs(T[1] / sqrt(1e300 * 7e-24) - 1) < 1e-12, "geometric mean %g, got %g", sqrt(1e300 * 7e-24), T[1]);
}

Test(schedule, analytic_single_block_heating_and_zero)
{
  const lw_schedule_type *types[] = {&lw_schedule_constant, &lw_schedule_linear, &lw_schedule_geometric,
                                     &lw_schedule_logarithmic, &lw_schedule_adaptive};
  for (size_t k = 0; k < sizeof types / sizeof *types; k++) {
    lw_schedule s = {.t_start = 2, .t_end = 1, .blocks = 1, .lambda = 0.7};
    double T;
    lw_schedule_run(types[k], &s, &T);
    cr_assert_eq(T, 2.0, "%s: B = 1 gives t_start, got %g", types[k]->name, T);
  }
  /* heating runs (t_end > t_start) are monotone the other way */
  const lw_schedule_type *heat[] = {&lw_schedule_linear, &lw_schedule_geometric, &lw_schedule_logarithmic};
  for (size_t k = 0; k < 3; k++) {
    lw_schedule s = {.t_start = 0.5, .t_end = 4, .blocks = 33};
    double T[33];
    lw_schedule_run(heat[k], &s, T);
    cr_assert_eq(T[0], 0.5);
    cr_assert_eq(T[32], 4.0);
    for (int b = 1; b < 33; b++) cr_assert(T[b] >= T[b - 1], "%s heating at %d", heat[k]->name, b);
    for (int b = 0; b < 33; b++)
      cr_assert(lw_close_rel(T[b], expected(heat[k], &s, b), 1e-12, 0), "%s heating at %d", heat[k]->name, b);
  }
  /* constant: every block t_start, 0 included (greedy descent) */
  lw_schedule c = {.t_start = 0, .t_end = 99, .blocks = 5};
  cr_assert_eq(lw_schedule_check(&lw_schedule_constant, &c, NULL), LW_OK);
  double T[5];
  lw_schedule_run(&lw_schedule_constant, &c, T);
  for (int b = 0; b < 5; b++) cr_assert_eq(T[b], 0.0);
  c.t_start = 3.25;
  lw_schedule_run(&lw_schedule_constant, &c, T);
  for (int b = 0; b < 5; b++) cr_assert_eq(T[b], 3.25);
  /* linear down to 0: the last block is greedy */
  lw_schedule l = {.t_start = 1, .t_end = 0, .blocks = 5};
  cr_assert_eq(lw_schedule_check(&lw_schedule_linear, &l, NULL), LW_OK);
  lw_schedule_run(&lw_schedule_linear, &l, T);
  const double lin[5] = {1, 0.75, 0.5, 0.25, 0};
  for (int b = 0; b < 5; b++) cr_assert_eq(T[b], lin[b]);
}

Test(schedule, adaptive_follows_huang_formula)
{
  const lw_schedule_type *a = &lw_schedule_adaptive;
  lw_schedule s = {.t_start = 10, .t_end = 0.1, .blocks = 100, .lambda = 0.7};
  cr_assert_eq(lw_schedule_check(a, &s, NULL), LW_OK);
  lw_block_stats st = {.mean = 5, .sd = 2, .samples = 100};
  /* 4 exp(-0.7 * 4 / 2) */
  double T = a->temperature(&s, 7, 4.0, &st);
  cr_assert(lw_close_rel(T, 0.986387855766426, 1e-14, 0), "got %.17g", T);
  cr_assert(lw_close_rel(T, 4.0 * exp(-0.7 * 4.0 / 2.0), 1e-15, 0));
  /* the mean plays no part; the first block is t_start whatever the stats */
  st.mean = -1e9;
  cr_assert_eq(a->temperature(&s, 7, 4.0, &st), T);
  cr_assert_eq(a->temperature(&s, 0, 4.0, &st), 10.0);
  cr_assert_eq(a->temperature(&s, 0, NAN, NULL), 10.0);
  /* a larger sd (larger fluctuations) cools more slowly */
  st.sd = 20;
  double T2 = a->temperature(&s, 7, 4.0, &st);
  cr_assert(T2 > T && T2 < 4.0);
  cr_assert(lw_close_rel(T2, 4.0 * exp(-0.14), 1e-15, 0));
}

Test(schedule, adaptive_falls_back_without_usable_stats)
{
  const lw_schedule_type *a = &lw_schedule_adaptive;
  lw_schedule s = {.t_start = 10, .t_end = 0.1, .blocks = 100, .lambda = 0.7};
  /* 4 (0.1 / 10)^(1/99) */
  const double want = 3.8181938266473363;
  lw_block_stats bad[] = {
    {.mean = 1, .sd = 0, .samples = 100},         {.mean = 1, .sd = NAN, .samples = 100},
    {.mean = 1, .sd = INFINITY, .samples = 100},  {.mean = 1, .sd = -1, .samples = 100},
    {.mean = 1, .sd = 2, .samples = 1},           {.mean = 1, .sd = 2, .samples = 0},
    {.mean = NAN, .sd = NAN, .samples = 100},
  };
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    double T = a->temperature(&s, 3, 4.0, &bad[i]);
    cr_assert(lw_close_rel(T, want, 1e-14, 0), "stats %zu: %.17g", i, T);
  }
  cr_assert(lw_close_rel(a->temperature(&s, 3, 4.0, NULL), want, 1e-14, 0));
  /* without any stats the run is the geometric schedule (up to rounding) */
  double T[100];
  lw_schedule_run(a, &s, T);
  cr_assert_eq(T[0], 10.0);
  for (int b = 1; b < 100; b++) {
    cr_assert(T[b] <= T[b - 1] && T[b] >= 0.1);
    cr_assert(lw_close_rel(T[b], 10.0 * pow(0.01, b / 99.0), 1e-12, 0), "b=%d %.17g", b, T[b]);
  }
}

Test(schedule, adaptive_clamped_and_never_nan)
{
  const lw_schedule_type *a = &lw_schedule_adaptive;
  lw_schedule s = {.t_start = 10, .t_end = 0.1, .blocks = 50, .lambda = 0.5};
  /* 2.5 exp(-0.5 * 2.5 / 0.25) = 0.0168 < t_end */
  lw_block_stats st = {.mean = 0, .sd = 0.25, .samples = 10};
  cr_assert_eq(a->temperature(&s, 5, 2.5, &st), 0.1);
  /* tiny sd: exp(-huge) = 0 */
  st.sd = 1e-310;
  cr_assert_eq(a->temperature(&s, 5, 2.5, &st), 0.1);
  /* never above t_start, never below t_end, never NaN */
  const double tprev[] = {NAN, INFINITY, -INFINITY, -1, 0, 1e-300, 0.05, 0.1, 3, 10, 1e300};
  const double sds[] = {NAN, INFINITY, -1, 0, 1e-300, 1e-3, 1, 1e300};
  const double lambdas[] = {1e-300, 0.7, 1e300};
  for (size_t i = 0; i < sizeof tprev / sizeof *tprev; i++)
    for (size_t j = 0; j < sizeof sds / sizeof *sds; j++)
      for (size_t k = 0; k < 3; k++) {
        lw_schedule sk = s;
        sk.lambda = lambdas[k];
        lw_block_stats bs = {.mean = 1, .sd = sds[j], .samples = 5};
        double T = a->temperature(&sk, 4, tprev[i], &bs);
        cr_assert(!isnan(T) && T >= 0.1 && T <= 10.0, "t_prev %g sd %g lambda %g: %g", tprev[i], sds[j],
                  lambdas[k], T);
      }
}

Test(schedule, table_interpolates_and_holds)
{
  char path[64];
  temp_file(path, "# step temperature\n"
                  "\n"
                  "  5 10\n"
                  "15\t5   # halfway\r\n"
                  "25 5\n"
                  "35 0\n");
  lw_schedule s = {.blocks = 40};
  lw_error err;
  cr_assert_eq(lw_schedule_read_table(&s, path, &err), LW_OK, "%s", err.msg);
  unlink(path);
  cr_assert_eq(s.n_table, 4);
  cr_assert_eq(lw_schedule_check(&lw_schedule_table, &s, NULL), LW_OK);
  const lw_schedule_type *t = &lw_schedule_table;
  const long b[] = {-3, 0, 4, 5, 6, 10, 14, 15, 20, 25, 30, 34, 35, 39, 1000};
  const double want[] = {10, 10, 10, 10, 9.5, 7.5, 5.5, 5, 5, 5, 2.5, 0.5, 0, 0, 0};
  for (size_t i = 0; i < sizeof b / sizeof *b; i++) {
    double T = t->temperature(&s, b[i], 0, NULL);
    cr_assert(fabs(T - want[i]) < 1e-14, "b=%ld: %.17g, want %g", b[i], T, want[i]);
  }
  double T[40];
  lw_schedule_run(t, &s, T);
  for (int k = 0; k < 40; k++) cr_assert_eq(T[k], t->temperature(&s, k, 0, NULL));

  /* a second table replaces the first; a single row is constant */
  temp_file(path, "7 0.25\n");
  cr_assert_eq(lw_schedule_read_table(&s, path, &err), LW_OK, "%s", err.msg);
  unlink(path);
  cr_assert_eq(s.n_table, 1);
  cr_assert_eq(t->temperature(&s, 0, 0, NULL), 0.25);
  cr_assert_eq(t->temperature(&s, 99, 0, NULL), 0.25);
  lw_schedule_clear(&s);
  cr_assert(s.n_table == 0 && !s.table_block && !s.table_temp);
  cr_assert_eq(s.blocks, 40, "clear keeps the other parameters");
  cr_assert_eq(lw_schedule_check(t, &s, &err), LW_EINPUT, "no table");
  lw_schedule_clear(&s); /* twice is harmless */
}

Test(schedule, table_rejects_malformed_files_with_line_numbers)
{
  static const struct {
    const char *text;
    int line;
    const char *what;
  } cases[] = {
    {"0 1\nfoo\n", 2, "'step temperature'"},
    {"0 1\n1\n", 2, "'step temperature'"},
    {"0 1\n\n1 2 3\n", 3, "'step temperature'"},
    {"0 1\r1 0.5\r", 1, "got a CR inside the line"},
    {"0 10 # hot\r150 1\r", 1, "got a CR inside the line"},
    {"# step temperature\r0 10\r", 1, "got a CR inside the line"},
    {"0 1x\n", 1, "temperature"},
    {"x1 1\n", 1, "step number"},
    {"0 1\n# again\n0 2\n", 3, "greater than"},
    {"0 1\n5 1\n3 1\n", 3, "greater than"},
    {"-1 1\n", 1, "step number"},
    {"1.5 1\n", 1, "step number"},
    {"1e300 1\n", 1, "step number"},
    /* a comma locale's writing: "1.000" is a thousand there (it read as step 1) */
    {"0 1\n1.000 0.5\n", 2, "got '1.000' (a thousands separator? write 1000, not 1.000)"},
    {"0 0,5\n", 1, "got '0,5' (a decimal comma? numbers take a point"},
    /* and a look-alike character, by what to type instead */
    {"0 1\n1000 0\xef\xbc\x8e" "5\n", 2, "(byte 2 is a full-width '.', U+FF0E: type '.')"},
    {"0 1\n1000\xc2\xa0" "0.5\n", 2, "(byte 5 is a no-break space, U+00A0"},
    {"\xef\xbc\x90 1\n", 1, "step number (a whole number >= 0), got '\xef\xbc\x90' (byte 1 is a full-width '0'"},
    {"0 -1\n", 1, "temperature"},
    {"0 -1e-300\n", 1, "temperature"},
    {"0 nan\n", 1, "temperature"},
    {"0 inf\n", 1, "temperature"},
    {"0 1e999\n", 1, "temperature"},
    {"0 1e301\n", 1, "a temperature from 0 to 1e300"}, /* t_start's bound too */
    {"", 1, "at least one"},
    {"# nothing\n\n   \n", 3, "at least one"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    char path[64], want[128];
    temp_file(path, cases[i].text);
    lw_schedule s = {.blocks = 10};
    lw_error err;
    lw_error_clear(&err);
    cr_assert_eq(lw_schedule_read_table(&s, path, &err), LW_EINPUT, "case %zu", i);
    cr_assert_eq(err.code, LW_EINPUT);
    snprintf(want, sizeof want, "%s:%d: expected ", path, cases[i].line);
    cr_assert(strstr(err.msg, want) == err.msg, "case %zu: '%s' does not start with '%s'", i, err.msg, want);
    cr_assert(strstr(err.msg, cases[i].what), "case %zu: '%s' lacks '%s'", i, err.msg, cases[i].what);
    cr_assert(s.n_table == 0 && !s.table_block && !s.table_temp, "case %zu: s unchanged", i);
    unlink(path);
  }
  /* a long row is shown cut at a character's start and said cut; a letter
  ** the cut fell in is no byte to delete (the hint was of the cut copy) */
  {
    char path[64], row[128] = "0 1\n1000 0.5 ";
    for (int i = 0; i < 53; i++) strcat(row, "x");
    strcat(row, "\xc3\xa9x\n");
    temp_file(path, row);
    lw_schedule s = {.blocks = 10};
    lw_error err;
    cr_assert_eq(lw_schedule_read_table(&s, path, &err), LW_EINPUT);
    cr_assert(strstr(err.msg, "xxx...'") && !strstr(err.msg, "\xc3'") && !strstr(err.msg, "delete it"), "%s",
              err.msg);
    unlink(path);
  }
  /* a NUL byte would end the line early as a string: refused, not cut */
  {
    char path[64];
    temp_file(path, "0 1\n");
    FILE *f = fopen(path, "a");
    cr_assert(f);
    fwrite("100 0.5\0 zzz\n", 1, 14, f);
    fclose(f);
    lw_schedule s = {.blocks = 10};
    lw_error err;
    cr_assert_eq(lw_schedule_read_table(&s, path, &err), LW_EINPUT);
    char want[128];
    snprintf(want, sizeof want, "%s:2: a NUL byte", path);
    cr_assert(strstr(err.msg, want), "%s", err.msg);
    unlink(path);
  }
  /* a failed read leaves an existing table alone */
  char path[64];
  temp_file(path, "0 3\n10 1\n");
  lw_schedule s = {.blocks = 10};
  lw_error err;
  cr_assert_eq(lw_schedule_read_table(&s, path, &err), LW_OK);
  unlink(path);
  temp_file(path, "0 3\nbad\n");
  cr_assert_eq(lw_schedule_read_table(&s, path, &err), LW_EINPUT);
  unlink(path);
  cr_assert(s.n_table == 2 && s.table_temp[0] == 3 && s.table_temp[1] == 1);
  lw_schedule_clear(&s);
  /* unreadable: missing file, a directory */
  cr_assert_eq(lw_schedule_read_table(&s, "/tmp/lw_schedule_does_not_exist.txt", &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "/tmp/lw_schedule_does_not_exist.txt"), "%s", err.msg);
  cr_assert_eq(lw_schedule_read_table(&s, "/tmp", &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "/tmp:"), "%s", err.msg);
  cr_assert(s.n_table == 0 && !s.table_block);
}

Test(schedule, check_validates_what_each_type_reads)
{
  lw_error err;
  lw_schedule ok = {.t_start = 2, .t_end = 0.5, .blocks = 10, .lambda = 0.7};
  for (const lw_schedule_type *const *t = lw_schedule_types; *t; t++)
    if (*t != &lw_schedule_table) cr_assert_eq(lw_schedule_check(*t, &ok, &err), LW_OK, "%s: %s", (*t)->name, err.msg);
  static const struct {
    const lw_schedule_type *t;
    lw_schedule s;
    const char *key;
  } bad[] = {
    {&lw_schedule_geometric, {.t_start = 2, .t_end = 0, .blocks = 10}, "t_end"},
    {&lw_schedule_logarithmic, {.t_start = 0, .t_end = 1, .blocks = 10}, "t_start"},
    {&lw_schedule_adaptive, {.t_start = 2, .t_end = 0, .blocks = 10, .lambda = 0.7}, "t_end"},
    {&lw_schedule_adaptive, {.t_start = 2, .t_end = 1, .blocks = 10, .lambda = 0}, "lambda"},
    {&lw_schedule_adaptive, {.t_start = 2, .t_end = 1, .blocks = 10, .lambda = NAN}, "lambda"},
    {&lw_schedule_adaptive, {.t_start = 1, .t_end = 2, .blocks = 10, .lambda = 0.7}, "t_end"},
    {&lw_schedule_linear, {.t_start = -1, .t_end = 0, .blocks = 10}, "t_start"},
    {&lw_schedule_linear, {.t_start = 1, .t_end = INFINITY, .blocks = 10}, "t_end"},
    {&lw_schedule_constant, {.t_start = NAN, .blocks = 10}, "t_start"},
    {&lw_schedule_constant, {.t_start = 1, .blocks = 0}, "blocks"},
    {&lw_schedule_table, {.blocks = 10}, "table"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    lw_error_clear(&err);
    cr_assert_eq(lw_schedule_check(bad[i].t, &bad[i].s, &err), LW_EINPUT, "case %zu", i);
    cr_assert(strstr(err.msg, bad[i].t->name) && strstr(err.msg, bad[i].key), "case %zu: '%s'", i, err.msg);
  }
  /* what a type does not read is not checked: constant ignores t_end */
  lw_schedule c = {.t_start = 1, .t_end = NAN, .blocks = 3, .lambda = -1};
  cr_assert_eq(lw_schedule_check(&lw_schedule_constant, &c, NULL), LW_OK);
  /* an unknown name from lw_schedule_find lists the choices */
  cr_assert_eq(lw_schedule_check(lw_schedule_find("quadratic"), &ok, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, lw_schedule_names()), "%s", err.msg);
}

Test(schedule, registry_names_find_and_formulas)
{
  size_t n = 0;
  char joined[512] = "";
  for (const lw_schedule_type *const *t = lw_schedule_types; *t; t++, n++) {
    cr_assert((*t)->name && (*t)->name[0], "entry %zu has a name", n);
    cr_assert((*t)->formula && (*t)->formula[0], "%s has a formula", (*t)->name);
    cr_assert((*t)->temperature, "%s has a function", (*t)->name);
    cr_assert(!strchr((*t)->name, '|') && !strchr((*t)->name, ' '), "%s: plain name", (*t)->name);
    cr_assert(!strchr((*t)->formula, '\n'), "%s: one-line formula", (*t)->name);
    for (const lw_schedule_type *const *u = lw_schedule_types; u != t; u++)
      cr_assert(strcmp((*u)->name, (*t)->name), "duplicate name %s", (*t)->name);
    cr_assert_eq(lw_schedule_find((*t)->name), *t);
    if (n) strcat(joined, "|");
    strcat(joined, (*t)->name);
  }
  cr_assert(n >= 6, "the six built-in schedules");
  cr_assert_str_eq(lw_schedule_names(), joined);
  cr_assert_eq(lw_schedule_names(), lw_schedule_names(), "one buffer");
  cr_assert_null(lw_schedule_find("nope"));
  cr_assert_null(lw_schedule_find(""));
  cr_assert_null(lw_schedule_find(NULL));
  cr_assert_null(lw_schedule_find("Geometric"));
  cr_assert_null(lw_schedule_find("geometric "));
}

/* A schedule defined outside schedule.c: its function and its entry are all
** it takes to go through the generic code (check, run). */
static double cosine_temperature(const lw_schedule *s, long b, double t_prev, const lw_block_stats *prev)
{
  double f = s->blocks > 1 ? (double)b / (double)(s->blocks - 1) : 0.0;
  f = f < 0 ? 0 : f > 1 ? 1 : f;
  return s->t_end + (s->t_start - s->t_end) * 0.5 * (1.0 + cos(M_PI * f));
}

/* a name no real schedule takes, so that adding a real cosine keeps this test */
static const lw_schedule_type cosine = {
  "test-cosine", "T_b = t_end + (t_start - t_end) (1 + cos(pi b/(B-1))) / 2",
  LW_SCHEDULE_USES_START | LW_SCHEDULE_USES_END, cosine_temperature};

Test(schedule, new_schedule_needs_only_function_and_entry)
{
  lw_schedule s = {.t_start = 8, .t_end = 2, .blocks = 9};
  lw_error err;
  cr_assert_eq(lw_schedule_check(&cosine, &s, &err), LW_OK);
  double T[9];
  lw_schedule_run(&cosine, &s, T);
  cr_assert_eq(T[0], 8.0);
  cr_assert(fabs(T[8] - 2.0) < 1e-15);
  cr_assert(fabs(T[4] - 5.0) < 1e-15, "midpoint %.17g", T[4]);
  cr_assert(fabs(T[2] - (2.0 + 6.0 * 0.5 * (1.0 + M_SQRT1_2))) < 1e-14);
  for (int b = 1; b < 9; b++) cr_assert(T[b] <= T[b - 1]);
  /* the generic check applies its flags: it reads t_end, so t_end is checked */
  s.t_end = -1;
  cr_assert_eq(lw_schedule_check(&cosine, &s, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "test-cosine") && strstr(err.msg, "t_end"), "%s", err.msg);
  /* lookup and the names list come from lw_schedule_types alone: an entry
  ** not in the table is not known by name, and one in it needs no other edit */
  cr_assert_null(lw_schedule_find("test-cosine"));
  cr_assert_null(strstr(lw_schedule_names(), "test-cosine"));
}
