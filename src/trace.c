/*
** trace.c -- trace.csv read back, and its columns' statistics (trace.h).
*/
#include "linewise/trace.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/number.h"
#include "linewise/series.h"

void lw_trace_free(lw_trace *t)
{
  if (!t) return;
  for (size_t k = 0; k < t->n_cols; k++) free(t->name[k]);
  free(t->name);
  free(t->v);
  free(t);
}

int lw_trace_column(const lw_trace *t, const char *name)
{
  for (size_t k = 0; k < t->n_cols; k++)
    if (!strcmp(t->name[k], name)) return (int)k;
  return -1;
}

/* The header's names, split at commas (line without its newline). */
static lw_status read_header(lw_trace *t, char *line, const char *path, lw_error *err)
{
  size_t n = 1;
  for (const char *c = line; *c; c++) n += *c == ',';
  if (!(t->name = calloc(n, sizeof *t->name))) return lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
  char *tok = line;
  for (size_t k = 0; k < n; k++) {
    char *end = strchr(tok, ',');
    if (end) *end = '\0';
    if (!*tok) return lw_error_set(err, LW_EINPUT, "%s:1: column %zu has no name (expected a header of names)", path, k + 1);
    for (const char *c = tok; *c; c++)
      if ((unsigned char)*c < 0x20 || *c == 0x7f)
        return lw_error_set(err, LW_EINPUT, "%s:1: column %zu: a control character in its name", path, k + 1);
    if (!(t->name[k] = strdup(tok))) return lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
    t->n_cols = k + 1;
    tok = end ? end + 1 : tok;
  }
  return LW_OK;
}

/* One row into v (n_cols values); line without its newline. */
static lw_status read_row(const lw_trace *t, const char *line, size_t line_no, double *v, const char *path,
                          lw_error *err)
{
  const char *tok = line;
  for (size_t k = 0; k < t->n_cols; k++) {
    const char *end = strchr(tok, ',');
    if ((k + 1 < t->n_cols) != (end != NULL))
      return lw_error_set(err, LW_EINPUT, "%s:%zu: %s fields, expected %zu as in the header", path, line_no,
                          end ? "more" : "fewer", t->n_cols);
    size_t len = end ? (size_t)(end - tok) : strlen(tok);
    if (!len) v[k] = NAN;
    else if (!lw_number_parse_n(tok, len, &v[k]))
      return lw_error_set(err, LW_EINPUT, "%s:%zu: column '%s': '%.*s' is not a number", path, line_no, t->name[k],
                          (int)(len > 40 ? 40 : len), tok);
    tok = end ? end + 1 : tok;
  }
  return LW_OK;
}

lw_trace *lw_trace_read(const char *path, lw_error *err)
{
  FILE *f = fopen(path, "r");
  if (!f) {
    lw_error_set(err, errno == ENOENT ? LW_EINPUT : LW_EIO, "%s: cannot read: %s", path, strerror(errno));
    return NULL;
  }
  lw_trace *t = calloc(1, sizeof *t);
  char *line = NULL;
  size_t cap = 0, rows_cap = 0, line_no = 0;
  ssize_t len;
  lw_status s = t ? LW_OK : lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
  while (!s && (len = getline(&line, &cap, f)) > 0) {
    line_no++;
    int whole = line[len - 1] == '\n';
    if (whole) line[--len] = '\0';
    if (len && line[len - 1] == '\r') line[--len] = '\0';
    if (strlen(line) != (size_t)len) {
      s = lw_error_set(err, LW_EINPUT, "%s:%zu: a NUL byte (expected text)", path, line_no);
      break;
    }
    if (line_no == 1) {
      s = read_header(t, line, path, err);
      continue;
    }
    if (!whole) break; /* a row still being written */
    if (t->n_rows == rows_cap) {
      size_t nc = rows_cap ? 2 * rows_cap : 256;
      double *nv = realloc(t->v, nc * t->n_cols * sizeof *nv);
      if (!nv) {
        s = lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
        break;
      }
      t->v = nv;
      rows_cap = nc;
    }
    s = read_row(t, line, line_no, t->v + t->n_rows * t->n_cols, path, err);
    if (!s) t->n_rows++;
  }
  if (!s && ferror(f)) s = lw_error_set(err, LW_EIO, "%s: read error", path);
  if (!s && line_no == 0) s = lw_error_set(err, LW_EINPUT, "%s: empty (expected a header line and rows)", path);
  free(line);
  fclose(f);
  if (s) {
    lw_trace_free(t);
    return NULL;
  }
  return t;
}

/* Columns that are the row's coordinates or settings, not measurements. */
static int is_coordinate(const char *name)
{
  size_t n = strlen(name);
  return !strcmp(name, "sweep") || !strcmp(name, "temperature") || !strcmp(name, "time") ||
         (n > 12 && !strcmp(name + n - 12, "_temperature"));
}

static double at(const lw_trace *t, size_t row, int col) { return t->v[row * t->n_cols + (size_t)col]; }

void lw_trace_select_of(const lw_params *p, lw_trace_select *sel)
{
  if (sel->from < 0 && p->stats_from > 0) sel->from = p->stats_from;
  if (p->driver != LW_DRIVER_METROPOLIS) return; /* the dynamics tunes nothing */
  sel->tune = p->tune_sweeps;
  sel->steps = p->steps;
  sel->sweeps = p->sweeps;
}

/* Whether the row of sweep s (counted from 1) reports a sweep whose steps
** still adapted: within the first `tune` sweeps of one of the schedule's
** temperature steps, as the run loop decides (anneal.c). */
static int tuning(const lw_trace_select *sel, long s)
{
  long long i = s - 1, S = sel->sweeps, B = sel->steps;
  if (sel->tune <= 0 || S <= 0 || B <= 0 || i < 0 || i >= S) return 0;
  long long b = i * B / S; /* its step, and the step's first sweep */
  return i - (b * S + B - 1) / B < sel->tune;
}

/* The default first sweep (trace.h). */
static long default_from(const lw_trace *t, int sweep)
{
  int temp = lw_trace_column(t, "temperature");
  if (temp < 0) return (long)at(t, 0, sweep);
  size_t r = t->n_rows - 1;
  double last = at(t, r, temp);
  while (r > 0 && at(t, r - 1, temp) == last) r--;
  return (long)at(t, r, sweep);
}

enum { WARN_OPEN, WARN_FEW, WARN_DRIFT };

/* Whether a column with spread has problem `what`. */
static int has_problem(const lw_series_stats *s, int what)
{
  if (!s->n || !(s->sd > 0.0)) return 0;
  switch (what) {
  case WARN_OPEN:
    return !s->window;
  case WARN_FEW:
    return s->window && s->n_eff < 25.0;
  default:
    return fabs(s->drift_z) > 4.0;
  }
}

static int flagged(const lw_series_stats *s) { return has_problem(s, WARN_OPEN) || has_problem(s, WARN_FEW); }

/* One line naming every column with problem `what`, or nothing. */
static void warn(FILE *out, const lw_trace *t, const lw_series_stats *st, int what, const char *text)
{
  int any = 0;
  for (size_t k = 0; k < t->n_cols; k++) {
    if (is_coordinate(t->name[k]) || !has_problem(&st[k], what)) continue;
    fprintf(out, "%s%s", any ? ", " : "warning: ", t->name[k]);
    any = 1;
  }
  if (any) fprintf(out, ": %s\n", text);
}

lw_status lw_trace_rows(const lw_trace *t, const char *path, const lw_trace_select *sel, size_t **rows, size_t *n,
                        size_t *tuned, lw_error *err)
{
  *rows = NULL;
  *n = *tuned = 0;
  int sweep = lw_trace_column(t, "sweep");
  if (sweep < 0) return lw_error_set(err, LW_EINPUT, "%s: no 'sweep' column (expected a trace.csv)", path);
  if (!t->n_rows) return lw_error_set(err, LW_EINPUT, "%s: no rows yet", path);
  for (size_t r = 0; r < t->n_rows; r++) {
    double v = at(t, r, sweep);
    if (!(v >= 0.0 && v <= 9007199254740992.0) || v != floor(v))
      return lw_error_set(err, LW_EINPUT, "%s:%zu: column 'sweep': expected a sweep count", path, r + 2);
  }
  long from = sel->from >= 0 ? sel->from : default_from(t, sweep);
  long to = sel->to >= 0 ? sel->to : (long)at(t, t->n_rows - 1, sweep);
  size_t r0 = 0, r1 = 0; /* the rows [r0, r1) */
  while (r0 < t->n_rows && at(t, r0, sweep) < (double)from) r0++;
  for (r1 = r0; r1 < t->n_rows && at(t, r1, sweep) <= (double)to; r1++) continue;
  if (!(*rows = malloc((r1 > r0 ? r1 - r0 : 1) * sizeof **rows))) return lw_error_set(err, LW_ENOMEM, "out of memory");
  for (size_t r = r0; r < r1; r++) {
    if (tuning(sel, (long)at(t, r, sweep))) ++*tuned;
    else (*rows)[(*n)++] = r;
  }
  if (!*n) {
    free(*rows);
    *rows = NULL;
    return lw_error_set(err, LW_EINPUT, "%s: no row from sweep %ld to %ld%s (its rows run from sweep %.0f to %.0f)",
                        path, from, to, *tuned ? " with frozen steps" : "", at(t, 0, sweep),
                        at(t, t->n_rows - 1, sweep));
  }
  return LW_OK;
}

double lw_trace_every(const lw_trace *t)
{
  int sweep = lw_trace_column(t, "sweep");
  return sweep >= 0 && t->n_rows > 1 ? at(t, 1, sweep) - at(t, 0, sweep) : 1.0;
}

void lw_trace_column_stats(const lw_trace *t, const size_t *rows, size_t n, int col, double *x, lw_series_stats *out)
{
  size_t m = 0;
  for (size_t i = 0; i < n; i++)
    if (!isnan(at(t, rows[i], col))) x[m++] = at(t, rows[i], col);
  if (m) lw_series_stats_of(x, m, out);
  else memset(out, 0, sizeof *out);
}

lw_status lw_trace_stats(const lw_trace *t, const char *path, const lw_trace_select *sel, FILE *out,
                         lw_error *err)
{
  size_t *row, n, tuned;
  lw_status status = lw_trace_rows(t, path, sel, &row, &n, &tuned, err);
  if (status) return status;
  double *x = malloc(n * sizeof *x);
  lw_series_stats *st = calloc(t->n_cols, sizeof *st);
  if (!x || !st) {
    free(row);
    free(x);
    free(st);
    return lw_error_set(err, LW_ENOMEM, "out of memory");
  }
  int sweep = lw_trace_column(t, "sweep"), temp = lw_trace_column(t, "temperature");
  double first = at(t, row[0], sweep), last = at(t, row[n - 1], sweep), every = lw_trace_every(t);
  double tlo = INFINITY, thi = -INFINITY;
  for (size_t i = 0; temp >= 0 && i < n; i++) {
    tlo = fmin(tlo, at(t, row[i], temp));
    thi = fmax(thi, at(t, row[i], temp));
  }
  if (!sel->csv) {
    fprintf(out, "%s: sweeps %.0f to %.0f", path, first, last);
    if (temp >= 0 && tlo == thi) fprintf(out, " at temperature %.6g", tlo);
    else if (temp >= 0) fprintf(out, " at temperatures %.6g to %.6g", tlo, thi);
    fprintf(out, ": %zu rows", n);
    if (every != 1.0) fprintf(out, ", one every %.6g sweeps", every);
    if (tuned) fprintf(out, " (%zu rows of tuning sweeps left out)", tuned);
    fprintf(out, "\n%-16s %15s %11s %11s %11s %9s\n", "column", "mean", "stderr", "sd", "tau_sweeps", "n_eff");
  } else {
    fprintf(out, "column,n,mean,stderr,sd,tau_sweeps,n_eff,window_closed,drift_z\n");
  }
  for (size_t k = 0; k < t->n_cols; k++) {
    if (is_coordinate(t->name[k])) continue;
    lw_series_stats *s = &st[k];
    lw_trace_column_stats(t, row, n, (int)k, x, s);
    if (!s->n) {
      if (!sel->csv) fprintf(out, "%-16s %15s\n", t->name[k], "(empty)");
    } else if (sel->csv) {
      fprintf(out, "%s,%zu,%.10g,%.4g,%.4g,%.4g,%.4g,%d,%.3g\n", t->name[k], s->n, s->mean, s->stderr_mean, s->sd,
              s->tau * every, s->n_eff, s->window > 0, s->drift_z);
    } else if (!(s->sd > 0.0)) {
      fprintf(out, "%-16s %15.9g %11.4g %11.4g %11s %9s\n", t->name[k], s->mean, 0.0, 0.0, "-", "-");
    } else {
      fprintf(out, "%-16s %15.9g %11.4g %11.4g %11.4g %9.0f%s\n", t->name[k], s->mean, s->stderr_mean, s->sd,
              s->tau * every, s->n_eff, flagged(s) ? " *" : "");
    }
  }
  if (!sel->csv) {
    if (temp >= 0 && tlo != thi)
      fprintf(out, "warning: the temperature changes within these rows: the means mix ensembles\n");
    warn(out, t, st, WARN_OPEN, "the autocorrelation did not die out within half the rows: tau is a lower bound "
         "and the error bar too small (a longer stretch is needed)");
    warn(out, t, st, WARN_FEW, "fewer than 25 independent samples: the error bar is rough");
    warn(out, t, st, WARN_DRIFT, "the first and second halves differ by more than 4 standard errors: not yet "
         "stationary (start later with --from)");
  }
  free(row);
  free(x);
  free(st);
  return LW_OK;
}
