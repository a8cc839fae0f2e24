/*
** fuzz_trace.c -- fuzz harness for trace.csv read back and its statistics
** (lw_trace_read, lw_trace_stats: `linewise stats`).
**
** Properties beyond "no crash, no leak, no undefined behaviour":
**   - a rejected file gets a message that names the file;
**   - an accepted trace's values are finite or NaN (an empty field), and
**     written back with 17 digits it reads back the same, bit for bit;
**   - its statistics, and its rungs reweighted, either print or refuse with
**     a message naming it,
**     with the tuning settings taken from the input's first bytes, and the
**     same trace taken as two runs does the same.
**
** Built with clang -fsanitize=fuzzer by `make fuzz`; `make test` compiles it
** with cc and replays tests/fuzz/corpus/trace through the same function.
*/
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "fuzz_util.h"
#include "linewise/reweight.h"
#include "linewise/trace.h"

static int same(double a, double b) { return (isnan(a) && isnan(b)) || !memcmp(&a, &b, sizeof a); }

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  const char *path = lw_fuzz_file(data, size, 0, ".csv");
  if (!path) return 0;
  lw_error err = {LW_OK, ""};
  lw_trace *t = lw_trace_read(path, &err);
  if (!t) {
    LW_FUZZ_CHECK(strstr(err.msg, path) != NULL || err.code == LW_ENOMEM, "message without the file: '%s'", err.msg);
    return 0;
  }
  for (size_t i = 0; i < t->n_rows * t->n_cols; i++)
    LW_FUZZ_CHECK(isfinite(t->v[i]) || isnan(t->v[i]), "value %zu is infinite", i);
  const char *path2 = lw_fuzz_path(1, ".csv");
  FILE *f = fopen(path2, "w");
  if (f) {
    for (size_t k = 0; k < t->n_cols; k++) fprintf(f, "%s%s", k ? "," : "", t->name[k]);
    fputc('\n', f);
    for (size_t r = 0; r < t->n_rows; r++) {
      for (size_t k = 0; k < t->n_cols; k++) {
        double v = t->v[r * t->n_cols + k];
        if (k) fputc(',', f);
        if (!isnan(v)) fprintf(f, "%.17g", v);
      }
      fputc('\n', f);
    }
    if (!fclose(f)) {
      lw_trace *u = lw_trace_read(path2, &err);
      LW_FUZZ_CHECK(u != NULL, "a written trace does not read back: %s", err.msg);
      LW_FUZZ_CHECK(u->n_rows == t->n_rows && u->n_cols == t->n_cols, "the shape changed on a write/read cycle");
      for (size_t i = 0; i < t->n_rows * t->n_cols; i++)
        LW_FUZZ_CHECK(same(u->v[i], t->v[i]), "value %zu changed on a write/read cycle", i);
      lw_trace_free(u);
    }
  }
  lw_trace_select sel = {.from = -1, .to = -1};
  if (size >= 3) {
    sel.tune = data[0] % 8;
    sel.steps = data[1] % 8;
    sel.sweeps = data[2] * 3;
    sel.csv = data[0] & 8;
    if (data[1] & 8) sel.from = data[2] / 4;
  }
  FILE *out = fopen("/dev/null", "w");
  if (out) {
    lw_status s = lw_trace_stats(t, path, &sel, out, &err);
    LW_FUZZ_CHECK(!s || strstr(err.msg, path) || s == LW_ENOMEM, "stats refused without the file: '%s'", err.msg);
    /* the same trace twice, as two runs: the same refusal, or a table */
    const lw_trace *two[2] = {t, t};
    const char *paths[2] = {path, path};
    const lw_trace_select sels[2] = {sel, sel};
    lw_status s2 = lw_trace_stats_runs(two, paths, sels, 2, out, &err);
    LW_FUZZ_CHECK(s2 == s || s2 == LW_ENOMEM || s == LW_ENOMEM, "one run gave %d, the same twice %d", (int)s, (int)s2);
    /* reweighting the rungs: a table, or a refusal naming the file */
    lw_status s3 = lw_trace_reweight((const lw_trace *const *)&t, &path, &sel, 1, 2 + (size ? data[0] % 5 : 0), out,
                                     &err);
    LW_FUZZ_CHECK(!s3 || strstr(err.msg, path) || s3 == LW_ENOMEM, "reweighting refused without the file: '%s'",
                  err.msg);
    fclose(out);
  }
  lw_trace_free(t);
  return 0;
}
