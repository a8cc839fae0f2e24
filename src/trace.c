/*
** trace.c -- trace.csv read back, and its columns' statistics (trace.h).
*/
#include "linewise/trace.h"

#include <errno.h>
#include <gsl/gsl_cdf.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/driver.h"
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
    if (!*tok)
      return lw_error_set(err, LW_EINPUT, "%s:1: column %zu has no name (expected a header of names)", path, k + 1);
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
  if (lw_number_locale_ok(err) || lw_text_plain_file(path, err)) return NULL;
  FILE *f = fopen(path, "r");
  if (!f) {
    lw_error_set(err, errno == ENOENT ? LW_EINPUT : LW_EIO, "%s: cannot read: %s", path, strerror(errno));
    return NULL;
  }
  lw_trace *t = calloc(1, sizeof *t);
  char *line = NULL;
  size_t cap = 0, rows_cap = 0, line_no = 0;
  ssize_t len = 0;
  lw_status s = t ? LW_OK : lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
  while (!s && (len = lw_text_getline(&line, &cap, f)) > 0) {
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
    if (!whole && !feof(f)) { /* (cut by the reader, not the end: the rows after were dropped unsaid) */
      s = lw_error_set(err, LW_EINPUT, "%s:%zu: a line longer than %ld MiB (expected a row of numbers)", path,
                       line_no, LW_TEXT_LINE_MAX >> 20);
      break;
    }
    if (!whole) break; /* a row still being written */
    if (t->n_rows == rows_cap) {
      size_t nc = rows_cap ? 2 * rows_cap : 256;
      double *nv = realloc(t->v, nc * t->n_cols * sizeof *nv);
      if (!nv) {
        /* every row is held (the selection needs the sweeps of all): say how
        ** much that is, so that a trace of 20 million rows is understood */
        s = lw_error_set(err, LW_ENOMEM, "%s: out of memory holding %zu rows of %zu columns (%.0f MB; stats "
                         "holds the whole trace, whatever --from and --to take)", path, nc, t->n_cols,
                         (double)nc * (double)t->n_cols * sizeof *nv / 1e6);
        break;
      }
      t->v = nv;
      rows_cap = nc;
    }
    s = read_row(t, line, line_no, t->v + t->n_rows * t->n_cols, path, err);
    if (!s) t->n_rows++;
  }
  if (!s && len == -2) s = lw_error_set(err, LW_ENOMEM, "%s:%zu: out of memory reading the line", path, line_no + 1);
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

/* 1 if name is a column of rung K ("replicaK_...") and rung K's temperature
** at the end of the rows differs between the k runs. */
static int rung_moves(const lw_trace *const *t, size_t *const *row, const size_t *n, int k, const char *name)
{
  const char *end = strchr(name, '_');
  char col[64];
  if (strncmp(name, "replica", 7) || !end || (size_t)(end - name) + sizeof "_temperature" > sizeof col) return 0;
  snprintf(col, sizeof col, "%.*s_temperature", (int)(end - name), name);
  int c = lw_trace_column(t[0], col);
  if (c < 0 || !n[0]) return 0;
  const double first = at(t[0], row[0][n[0] - 1], c);
  for (int r = 1; r < k; r++) {
    int cr = lw_trace_column(t[r], col);
    if (cr >= 0 && n[r] && fabs(at(t[r], row[r][n[r] - 1], cr) - first) > 1e-9 * fabs(first)) return 1;
  }
  return 0;
}

/* Whether a column mixes ensembles between the runs: a rung's whose rung
** moves, or a swap rate of a pair of which either rung does. */
static int column_mixed(const lw_trace *const *t, size_t *const *row, const size_t *n, int k, const char *name)
{
  char rung[32];
  int pair;
  if (sscanf(name, "swap%d", &pair) == 1 && pair >= 0 && pair < 100000) {
    for (int q = pair; q <= pair + 1; q++) {
      snprintf(rung, sizeof rung, "replica%d_", q);
      if (rung_moves(t, row, n, k, rung)) return 1;
    }
    return 0;
  }
  return rung_moves(t, row, n, k, name);
}

void lw_trace_select_of(const lw_params *p, lw_trace_select *sel)
{
  if (sel->from < 0 && p->stats_from > 0) sel->from = p->stats_from;
  if (lw_driver_is_motion(p)) return; /* the dynamics tunes nothing */
  if (p->replicas > 1 && p->tune_ladder == LW_LADDER_EQUAL) sel->ladder = p->ladder_sweeps;
  sel->tune = p->tune_sweeps;
  sel->steps = p->steps;
  sel->sweeps = p->sweeps;
}

/* Whether the row of sweep s (counted from 1) reports a sweep whose steps
** or ladder still adapted: within the first `tune` sweeps of one of the
** schedule's temperature steps, as the run loop decides (anneal.c), or
** within the ladder's warm-up. */
static int tuning(const lw_trace_select *sel, long s)
{
  if (s <= sel->ladder) return 1;
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

enum { WARN_OPEN, WARN_FEW, WARN_ONE, WARN_DRIFT, WARN_BATCH, WARN_RUNS, WARN_COARSE, WARN_ROUNDED };

/* A column's statistics: per run (k of them), and with several runs what
** they say together. */
typedef struct {
  lw_series_stats *run; /* k */
  double mean, stderr_mean, sd, tau_sweeps, n_eff;
  int mixed;            /* a rung's column whose rung stands at other temperatures in other runs */
  int coarse;           /* a run's values about uncorrelated at their spacing of more than a sweep: tau at
                        ** its floor of half a value, tau_sweeps a bound (wire-ladder at trace_every 1000
                        ** read 500 sweeps against the 17 of every row) */
  int rounded;          /* a run's values all printed to 10 digits (traces before 2026-12-07), their spread
                        ** under 3 steps of the last one: the rounding's variance, step^2 / 12, is over 1 %
                        ** of theirs (and a heat capacity of that energy is off by as much) */
  double r_hat;         /* Gelman and Rubin's potential scale reduction */
  double p_runs;        /* chi-square probability of the runs' means under their error bars */
  double se_runs;       /* the runs' means' sd over sqrt(runs): an error bar no run's own estimate makes
                        ** (a slow tail the autocorrelation's sum ends before left wlc's 1.45 times small) */
} column_stats;

/* Whether a run's column with spread has problem `what` (one run's kinds). */
static int run_problem(const lw_series_stats *s, int what)
{
  if (what == WARN_ONE || s->n == 1) return what == WARN_ONE && s->n == 1; /* no error bar at all */
  if (!s->n || !(s->sd > 0.0)) return 0;
  switch (what) {
  case WARN_OPEN:
    return !s->window;
  case WARN_FEW:
    return s->window && s->n_eff < 25.0;
  case WARN_BATCH:
    return s->batch_ratio > LW_SERIES_BATCH_WARN;
  default:
    return fabs(s->drift_z) > 4.0;
  }
}

/* A statistic's cell: for --csv every digit that reads back (scripts read
** it, and it gave 4 where summary.json gave 17), for the table fmt. */
static void stat_cell(char *buf, size_t n, int csv, const char *fmt, double v)
{
  if (csv) lw_number_format_exact(buf, n, v);
  else snprintf(buf, n, fmt, v);
}

/* Whether column c has problem `what` in any of its k runs, or (WARN_RUNS)
** across them: means further apart than their error bars allow (p < 1e-3)
** or a potential scale reduction above 1.1. */
static int has_problem(const column_stats *c, int k, int what)
{
  if (what == WARN_RUNS) return k > 1 && !isnan(c->p_runs) && (c->p_runs < 1e-3 || c->r_hat > 1.1);
  /* (a window that did not close says the bar is too small: not that it holds) */
  if (what == WARN_COARSE) return c->coarse && !has_problem(c, k, WARN_OPEN);
  if (what == WARN_ROUNDED) return c->rounded;
  for (int r = 0; r < k; r++)
    if (run_problem(&c->run[r], what)) return 1;
  return 0;
}

static int flagged(const column_stats *c, int k)
{
  return has_problem(c, k, WARN_OPEN) || has_problem(c, k, WARN_FEW) || has_problem(c, k, WARN_ONE) ||
         has_problem(c, k, WARN_BATCH) || has_problem(c, k, WARN_RUNS) || has_problem(c, k, WARN_ROUNDED);
}

/* One line naming every column with problem `what`, or nothing. */
static void warn(FILE *out, const lw_trace *t, const column_stats *cs, int k, int what, const char *text)
{
  int any = 0;
  if (!out) return;
  for (size_t c = 0; c < t->n_cols; c++) {
    if (is_coordinate(t->name[c]) || !cs[c].run[0].n || !has_problem(&cs[c], k, what)) continue;
    fprintf(out, "%s%s", any ? ", " : "warning: ", t->name[c]);
    any = 1;
  }
  if (any) fprintf(out, ": %s\n", text);
}

/* The runs together (k > 1): the mean of their means with the error bar of
** that mean, the within-run spread, the mean tau, the summed n_eff; the
** chi-square of the means against their error bars (about their weighted
** average, k - 1 degrees of freedom); and R-hat = sqrt(var+ / W), W the mean within-run variance, B / n
** the variance of the means, var+ = (n - 1) / n W + B / n (Gelman and Rubin
** 1992, Stat. Sci. 7, 457), n the mean rows a run. */
static void combine(column_stats *c, int k, const double *gap)
{
  double m = 0.0, se2 = 0.0, w = 0.0, n = 0.0, tau = 0.0, neff = 0.0;
  for (int r = 0; r < k; r++) {
    const lw_series_stats *s = &c->run[r];
    m += s->mean / k;
    se2 += s->stderr_mean * s->stderr_mean / ((double)k * k);
    w += s->n > 1 ? s->sd * s->sd * (double)s->n / (double)(s->n - 1) / k : 0.0;
    n += (double)s->n / k;
    tau += s->tau * gap[r] / k;
    neff += s->n_eff;
  }
  /* The chi-square is taken about the means' weighted average, each weighed
  ** by 1 / se^2: about the plain average it follows no chi-square law once
  ** the error bars differ (one run of a tenth the error bar made 4 agreeing
  ** runs fail p < 0.001 in 37 % of trials).  A run without spread fixes the
  ** mean (all such runs must agree on it), and the others count a degree of
  ** freedom each. */
  double b = 0.0, chi2 = 0.0, sw = 0.0, swm = 0.0, m_exact = 0.0, ref = NAN;
  int n_exact = 0, apart = 0;
  for (int r = 0; r < k; r++) {
    const lw_series_stats *s = &c->run[r];
    b += (s->mean - m) * (s->mean - m) / (k - 1);
    if (s->stderr_mean > 0.0) {
      /* the average as a step from the first such mean: equal means give it
      ** exactly, and a chi-square of 0 (their sum's rounding read p_runs
      ** 0.99999999999993 for a run named twice) */
      if (isnan(ref)) ref = s->mean;
      sw += 1.0 / (s->stderr_mean * s->stderr_mean);
      swm += (s->mean - ref) / (s->stderr_mean * s->stderr_mean);
    } else {
      apart |= n_exact && s->mean != m_exact;
      m_exact = s->mean;
      n_exact++;
    }
  }
  double m_w = n_exact ? m_exact : ref + swm / sw;
  for (int r = 0; r < k; r++) {
    const lw_series_stats *s = &c->run[r];
    if (s->stderr_mean > 0.0) chi2 += (s->mean - m_w) * (s->mean - m_w) / (s->stderr_mean * s->stderr_mean);
  }
  int exact = n_exact == k; /* every run without spread: the means must agree exactly */
  c->mean = m;
  c->se_runs = sqrt(b / k);
  c->stderr_mean = sqrt(se2);
  c->sd = sqrt(w);
  c->tau_sweeps = tau;
  c->n_eff = neff;
  int single = 0; /* a run of one row has no error bar: the runs' means are the samples */
  for (int r = 0; r < k; r++) single |= c->run[r].n < 2;
  if (single) {
    c->stderr_mean = sqrt(b / k);
    c->sd = c->p_runs = c->r_hat = NAN;
    return;
  }
  if (exact) { /* compared with each other: their mean's rounding (50 / 6 six times) is no spread */
    c->p_runs = apart ? 0.0 : 1.0;
    c->r_hat = apart ? INFINITY : 1.0;
    if (!apart) c->mean = m_exact;
  } else {
    c->p_runs = apart ? 0.0 : gsl_cdf_chisq_Q(chi2, (double)(n_exact ? k - n_exact : k - 1));
    c->r_hat = w > 0.0 ? sqrt(((n - 1.0) / n * w + b) / w) : INFINITY;
  }
}

lw_status lw_trace_rows(const lw_trace *t, const char *path, const lw_trace_select *sel, size_t **rows, size_t *n,
                        size_t *tuned, lw_error *err)
{
  *rows = NULL;
  *n = *tuned = 0;
  int sweep = lw_trace_column(t, "sweep");
  if (sweep < 0) return lw_error_set(err, LW_EINPUT, "%s: no 'sweep' column (expected a trace.csv)", path);
  if (!t->n_rows)
    return lw_error_set(err, LW_EINPUT, "%s: no rows (none before a run's first sweep; a run of no sweeps, as a "
                        "redraw, has none)", path);
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
    if (*tuned) /* a run shortened for a try: every row there tunes, and nothing said what to change */
      return lw_error_set(err, LW_EINPUT, "%s: no row from sweep %ld to %ld with frozen steps: its %zu rows there "
                          "all tune (the first %ld sweeps of each temperature step, moves.tune_sweeps%s)%s", path,
                          from, to, *tuned, sel->tune, sel->ladder ? ", and tempering.ladder_sweeps" : "",
                          sel->to >= 0 ? "" : "; more anneal.sweeps or fewer moves.tune_sweeps leave rows to average");
    return lw_error_set(err, LW_EINPUT, "%s: no row from sweep %ld to %ld (its rows run from sweep %.0f to %.0f)",
                        path, from, to, at(t, 0, sweep), at(t, t->n_rows - 1, sweep));
  }
  return LW_OK;
}

double lw_trace_every(const lw_trace *t)
{
  int sweep = lw_trace_column(t, "sweep");
  return sweep >= 0 && t->n_rows > 1 ? at(t, 1, sweep) - at(t, 0, sweep) : 1.0;
}

/* A swapK column is filled on every other row (even and odd pairs take
** turns), so its tau in values is in twice the rows' sweeps (it read 1.1
** sweeps for 2.2). */
double lw_trace_column_gap(double every, size_t n, const lw_series_stats *st)
{
  return st->n ? every * (double)n / (double)st->n : every;
}

void lw_trace_column_stats(const lw_trace *t, const size_t *rows, size_t n, int col, double *x, lw_series_stats *out)
{
  size_t m = 0;
  for (size_t i = 0; i < n; i++)
    if (!isnan(at(t, rows[i], col))) x[m++] = at(t, rows[i], col);
  if (m) lw_series_stats_of(x, m, out);
  else memset(out, 0, sizeof *out);
}

/* The temperatures of the rows chosen, widened into [*lo, *hi]. */
static void temperature_range(const lw_trace *t, const size_t *row, size_t n, double *lo, double *hi)
{
  int temp = lw_trace_column(t, "temperature");
  for (size_t i = 0; temp >= 0 && i < n; i++) {
    *lo = fmin(*lo, at(t, row[i], temp));
    *hi = fmax(*hi, at(t, row[i], temp));
  }
}

/* The line about one run's stretch of rows. */
static void stretch_line(FILE *out, const char *lead, const lw_trace *t, const char *path, const size_t *row, size_t n,
                         size_t tuned)
{
  int sweep = lw_trace_column(t, "sweep"), temp = lw_trace_column(t, "temperature");
  double every = lw_trace_every(t), tlo = INFINITY, thi = -INFINITY;
  temperature_range(t, row, n, &tlo, &thi);
  fprintf(out, "%s%s: sweeps %.0f to %.0f", lead, path, at(t, row[0], sweep), at(t, row[n - 1], sweep));
  if (temp >= 0 && tlo == thi) fprintf(out, " at temperature %.6g", tlo);
  else if (temp >= 0) fprintf(out, " at temperatures %.6g to %.6g", tlo, thi);
  fprintf(out, ": %zu row%s", n, n == 1 ? "" : "s");
  if (every != 1.0) fprintf(out, ", one every %.6g sweeps", every);
  if (tuned) fprintf(out, " (%zu row%s of tuning sweeps left out)", tuned, tuned == 1 ? "" : "s");
  fputc('\n', out);
}

int lw_trace_rungs(const lw_trace *t, int *energy, int *temp, int max)
{
  int n = 0;
  for (; n < max; n++) {
    char e[48], tt[48];
    snprintf(e, sizeof e, "replica%d_energy", n);
    snprintf(tt, sizeof tt, "replica%d_temperature", n);
    if ((energy[n] = lw_trace_column(t, e)) < 0 || (temp[n] = lw_trace_column(t, tt)) < 0) break;
  }
  return n;
}

/* Whether values x[n] of spread sd are all at 10 significant digits, the
** trace's print before 2026-12-07, and spread under 3 steps of the last
** digit (WARN_ROUNDED).  A value written in full is at 10 digits by chance
** about once in 10^7. */
static int rounded_values(const double *x, size_t n, double sd)
{
  double most = 0.0;
  if (!(sd > 0.0)) return 0;
  for (size_t i = 0; i < n; i++)
    if (fabs(x[i]) > most) most = fabs(x[i]);
  if (!(most > 0.0 && sd < 3.0 * pow(10.0, floor(log10(most)) - 9.0))) return 0;
  /* (the digits last: a print each, and only of a column so narrow) */
  for (size_t i = 0; i < n; i++) {
    char buf[32];
    snprintf(buf, sizeof buf, "%.10g", x[i]);
    if (strtod(buf, NULL) != x[i]) return 0;
  }
  return 1;
}

int lw_trace_rounded(const double *x, size_t n)
{
  double m = 0.0, s = 0.0;
  for (size_t i = 0; i < n; i++) m += (x[i] - m) / (double)(i + 1);
  for (size_t i = 0; i < n; i++) s += (x[i] - m) * (x[i] - m);
  return n > 1 && rounded_values(x, n, sqrt(s / (double)(n - 1)));
}

/* The energy columns whose fluctuations make a heat capacity, each with its
** temperature column: with tempering every rung's, else the total at the
** row's temperature (the dynamics has neither).  Their count, at most max. */
static int heat_sources(const lw_trace *t, int *energy, int *temp, int max)
{
  int n = lw_trace_rungs(t, energy, temp, max);
  if (n || max < 1) return n;
  energy[0] = lw_trace_column(t, "total");
  temp[0] = lw_trace_column(t, "temperature");
  return energy[0] >= 0 && temp[0] >= 0;
}

lw_trace *lw_trace_with_heat_capacity(const lw_trace *t, const size_t *rows, size_t n, const char *path,
                                      lw_error *err)
{
  int energy[LW_TRACE_HEAT_MAX], temp[LW_TRACE_HEAT_MAX];
  const int k = heat_sources(t, energy, temp, LW_TRACE_HEAT_MAX);
  const size_t cols = t->n_cols + (size_t)k;
  lw_trace *h = calloc(1, sizeof *h);
  if (!h || !(h->name = calloc(cols, sizeof *h->name)) ||
      !(h->v = malloc((t->n_rows ? t->n_rows : 1) * cols * sizeof *h->v))) {
    lw_trace_free(h);
    lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
    return NULL;
  }
  h->n_rows = t->n_rows;
  for (size_t c = 0; c < cols; c++) {
    char derived[64] = "";
    if (c >= t->n_cols) { /* replicaK_energy -> replicaK_heat_capacity, total -> heat_capacity */
      const char *src = t->name[energy[c - t->n_cols]];
      int keep = strcmp(src, "total") ? (int)(strlen(src) - strlen("energy")) : 0;
      snprintf(derived, sizeof derived, "%.*sheat_capacity", keep, src);
    }
    if (!(h->name[c] = strdup(c < t->n_cols ? t->name[c] : derived))) {
      lw_trace_free(h);
      lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
      return NULL;
    }
    h->n_cols = c + 1;
  }
  for (size_t r = 0; r < t->n_rows; r++) {
    memcpy(h->v + r * cols, t->v + r * t->n_cols, t->n_cols * sizeof *h->v);
    for (int j = 0; j < k; j++) h->v[r * cols + t->n_cols + (size_t)j] = NAN;
  }
  for (int j = 0; j < k; j++) {
    double mean = 0.0, T = at(t, rows[0], temp[j]);
    size_t m = 0;
    int same = 1;
    for (size_t i = 0; i < n; i++) {
      double e = at(t, rows[i], energy[j]);
      same &= at(t, rows[i], temp[j]) == T;
      if (!isnan(e)) mean += (e - mean) / (double)++m;
    }
    /* one energy has no variance, and two give two equal squares (an error
    ** bar of 0): left empty */
    /* (a temperature whose square underflows or overflows, 1e-170: Var(E) /
    ** T^2 printed inf and -nan where summary.json has null) */
    if (!same || !(T * T > 0.0 && T * T < INFINITY) || m < 3) continue;
    for (size_t i = 0; i < n; i++) {
      double d = at(t, rows[i], energy[j]) - mean;
      h->v[rows[i] * cols + t->n_cols + (size_t)j] = d * d / (T * T);
    }
  }
  return h;
}

/* Refuses a run whose columns are not the first run's. */
static lw_status same_columns(const lw_trace *a, const char *pa, const lw_trace *b, const char *pb, lw_error *err)
{
  for (size_t c = 0; c < a->n_cols || c < b->n_cols; c++)
    if (c >= a->n_cols || c >= b->n_cols || strcmp(a->name[c], b->name[c]))
      return lw_error_set(err, LW_EINPUT, "%s: column %zu is '%s', but '%s' in %s (expected runs of one scene)", pb,
                          c + 1, c < b->n_cols ? b->name[c] : "(none)", c < a->n_cols ? a->name[c] : "(none)", pa);
  return LW_OK;
}

/* How many of the k runs stood still over the rows: every acc_ column
** they filled is 0 throughout, and the total has no spread (a chain that
** accepted nothing gave each column a mean and an error bar of 0, and no
** word; under tempering the exchanges still move the coldest rung's state,
** whose own moves the acc_ columns count). */
static int frozen_runs(const lw_trace *t, const column_stats *cs, int k)
{
  int frozen = 0;
  for (int r = 0; r < k; r++) {
    int acc = 0, moved = 0;
    for (size_t c = 0; c < t->n_cols; c++) {
      const lw_series_stats *s = &cs[c].run[r];
      if (!s->n) continue;
      if (!strncmp(t->name[c], "acc_", 4)) {
        acc = 1;
        moved |= s->mean != 0.0 || s->sd > 0.0;
      } else if (!strcmp(t->name[c], "total")) {
        moved |= s->sd > 0.0;
      }
    }
    frozen += acc && !moved;
  }
  return frozen;
}

/* Whether the first m rows of runs q and r hold the same values (NaN for
** NaN). */
static int one_chain(const lw_trace *a, const lw_trace *b)
{
  const int sa = lw_trace_column(a, "sweep"), sb = lw_trace_column(b, "sweep");
  int *in_b = malloc((a->n_cols ? a->n_cols : 1) * sizeof *in_b), shared = 0;
  if (sa < 0 || sb < 0 || !in_b) {
    free(in_b);
    return 0;
  }
  /* the columns both have, by name (one run's observables off left it
  ** unwarned), but the rates over each row's own window, which trace_every
  ** sets */
  for (size_t c = 0; c < a->n_cols; c++) {
    const int rate = !strncmp(a->name[c], "acc_", 4) || !strncmp(a->name[c], "swap", 4);
    in_b[c] = rate || (int)c == sa ? -1 : lw_trace_column(b, a->name[c]);
    shared += in_b[c] >= 0;
  }
  size_t i = 0, j = 0, common = 0;
  int same = shared > 0;
  while (same && i < a->n_rows && j < b->n_rows) {
    const double x = at(a, i, sa), y = at(b, j, sb);
    if (x != y) {
      i += x < y;
      j += y < x;
      continue;
    }
    for (size_t c = 0; same && c < a->n_cols; c++) {
      if (in_b[c] < 0) continue;
      /* (to 10 digits: a trace of before 2026-12-07 beside the same seed's
      ** run again, in full) */
      const double u = at(a, i, (int)c), v = at(b, j, in_b[c]);
      same = u == v || (isnan(u) && isnan(v)) || fabs(u - v) <= 6e-10 * fmax(fabs(u), fabs(v));
    }
    common++, i++, j++;
  }
  free(in_b);
  return same && common >= 1; /* (one row a run: a study of end states) */
}

/* Runs that are one chain, another's rows value for value at the sweeps both
** traces record (the whole traces, their columns but the rates over a row's
** window): one seed run twice, a copy of a run stopped earlier, the same
** seed with a later stats_from or another trace_every (rows of one sweep
** compared, not the stretches' i-th: those went unwarned, as did any pair
** the heat capacities of their own stretches told apart), or seeds that
** changed nothing (a scene that draws no random number), which the
** comparison took for agreeing runs (R_hat 0.99, p_runs 1); pooled, such a
** run counts twice and the error bar is too small (one seed twice among
** four: 16 % small).  All alike is one warning, else one a set of twins.
** (Other runs part at their first common row: k^2 / 2 rows.) */
static void warn_twins(FILE *out, const lw_trace *const *t, const size_t *n, const char *const *path, int k)
{
  int *twin = malloc((size_t)k * sizeof *twin); /* the first run that run r repeats, or r */
  int distinct = 0, same_length = 1;
  for (int r = 0; twin && r < k; r++) {
    twin[r] = r;
    for (int q = 0; q < r && twin[r] == r; q++)
      if (twin[q] == q && n[q] && n[r] && one_chain(t[q], t[r])) twin[r] = q;
    distinct += twin[r] == r;
    same_length &= n[r] == n[0];
  }
  if (twin && distinct == 1 && same_length)
    fprintf(out, "warning: the %d runs are the same, row for row: one seed run twice, or seeds that change "
            "nothing (a scene that draws no random number, as the dynamics from init.from or the D-NURBS dynamics), "
            "so they are one run, and R_hat and p_runs say nothing\n", k);
  for (int q = 0; twin && !(distinct == 1 && same_length) && q < k; q++) {
    int copies = 0;
    for (int r = q + 1; r < k; r++) copies += twin[r] == q;
    if (!copies) continue;
    fprintf(out, "warning: %s", path[q]);
    for (int r = q + 1; r < k; r++)
      if (twin[r] == q) fprintf(out, "%s%s", --copies ? ", " : " and ", path[r]);
    fprintf(out, " are one run, row for row over the rows they share (one seed run twice, or a copy of a run "
            "stopped earlier or traced otherwise): pooled, it counts as more than one, so the error bars are too small "
            "and the runs' agreement too kind; leave all but one out\n");
  }
  free(twin);
}

void lw_trace_warn_twins(const lw_trace *const *t, const char *const *path, const lw_trace_select *sel, int k,
                         FILE *out)
{
  size_t **row = calloc((size_t)k, sizeof *row), *n = calloc((size_t)k, sizeof *n), tuned;
  lw_error e;
  int ok = row && n;
  for (int r = 0; ok && r < k; r++) ok = !lw_trace_rows(t[r], path[r], &sel[r], &row[r], &n[r], &tuned, &e);
  if (ok) warn_twins(out, t, n, path, k);
  for (int r = 0; row && r < k; r++) free(row[r]);
  free(row);
  free(n);
}

lw_status lw_trace_stats_runs(const lw_trace *const *t, const char *const *path, const lw_trace_select *sel, int k,
                              FILE *out, lw_error *err)
{
  const int csv = sel[0].csv;
  size_t **row = calloc((size_t)k, sizeof *row), *n = calloc((size_t)k, sizeof *n);
  size_t *tuned = calloc((size_t)k, sizeof *tuned);
  double *every = calloc((size_t)k, sizeof *every), *gap = calloc((size_t)k, sizeof *gap), *x = NULL;
  lw_trace **heat = calloc((size_t)k, sizeof *heat); /* t with its heat capacities */
  const size_t cols = t[0]->n_cols + LW_TRACE_HEAT_MAX;
  column_stats *cs = calloc(cols, sizeof *cs);
  lw_series_stats *runs = calloc(cols * (size_t)k, sizeof *runs);
  lw_status status =
      row && n && tuned && every && gap && heat && cs && runs ? LW_OK : lw_error_set(err, LW_ENOMEM, "out of memory");
  size_t most = 0;
  for (int r = 0; !status && r < k; r++) {
    if (r && (status = same_columns(t[0], path[0], t[r], path[r], err))) break;
    if ((status = lw_trace_rows(t[r], path[r], &sel[r], &row[r], &n[r], &tuned[r], err))) break;
    every[r] = lw_trace_every(t[r]);
    if (n[r] > most) most = n[r];
  }
  if (!status && !(x = malloc(most * sizeof *x))) status = lw_error_set(err, LW_ENOMEM, "out of memory");
  for (int r = 0; !status && r < k; r++)
    if (!(heat[r] = lw_trace_with_heat_capacity(t[r], row[r], n[r], path[r], err)))
      status = err ? err->code : LW_ENOMEM;
  if (status) goto done;
  const lw_trace *const *raw = t; /* (the twins are of the runs' own columns) */
  t = (const lw_trace *const *)heat;
  double tlo = INFINITY, thi = -INFINITY;
  for (int r = 0; r < k; r++) temperature_range(t[r], row[r], n[r], &tlo, &thi);
  /* rungs at other temperatures in other runs (each tuned its own ladder,
  ** tune_ladder = equal): their replicaK columns are other ensembles, and
  ** every inner rung was called "not converged"; the ladder's two ends stay
  ** where they were and are compared */
  int ladders_differ = 0;
  for (size_t c = 0; c < t[0]->n_cols; c++) ladders_differ |= rung_moves(t, row, n, k, t[0]->name[c]);
  for (size_t c = 0; c < t[0]->n_cols; c++) {
    cs[c].run = runs + c * (size_t)k;
    if (is_coordinate(t[0]->name[c])) continue;
    int empty = 0;
    for (int r = 0; r < k; r++) {
      lw_trace_column_stats(t[r], row[r], n[r], (int)c, x, &cs[c].run[r]);
      if (c < raw[r]->n_cols) cs[c].rounded |= rounded_values(x, cs[c].run[r].n, cs[c].run[r].sd);
      if (cs[c].run[r].n > 1 && isnan(cs[c].run[r].tau)) {
        status = lw_error_set(err, LW_ENOMEM, "%s: out of memory for the autocorrelation of %s", path[r],
                              t[0]->name[c]);
        goto done;
      }
      empty |= !cs[c].run[r].n;
      gap[r] = lw_trace_column_gap(every[r], n[r], &cs[c].run[r]);
      const lw_series_stats *s = &cs[c].run[r];
      /* (not a relaxation's: the drift test speaks for it) */
      cs[c].coarse |= s->n > 1 && s->sd > 0.0 && s->tau < 0.75 && gap[r] > 1.0 && !(fabs(s->drift_z) > 4.0);
    }
    /* a heat capacity is of its energy's fluctuations: rounded with them */
    const char *hc = strstr(t[0]->name[c], "heat_capacity");
    if (c >= raw[0]->n_cols && hc) {
      char src[64];
      snprintf(src, sizeof src, "%.*s%s", (int)(hc - t[0]->name[c]), t[0]->name[c], hc == t[0]->name[c] ? "total"
               : "energy");
      const int e = lw_trace_column(raw[0], src);
      if (e >= 0) cs[c].rounded = cs[e].rounded;
    }
    cs[c].tau_sweeps = cs[c].run[0].tau * gap[0];
    if (empty) {
      cs[c].run[0].n = 0; /* a column some run never filled: left out */
    } else if (k > 1) {
      combine(&cs[c], k, gap);
      /* an acceptance depends on each run's own tuned step: runs need not
      ** agree; nor need a rung's columns where the rungs' temperatures differ */
      cs[c].mixed = column_mixed(t, row, n, k, t[0]->name[c]);
      if (!strncmp(t[0]->name[c], "acc_", 4) || !strncmp(t[0]->name[c], "swap", 4) || cs[c].mixed)
        cs[c].p_runs = cs[c].r_hat = cs[c].se_runs = NAN; /* (the runs' spread of these is by design) */
    }
  }
  int width = 16; /* the names' column */
  for (size_t c = 0; c < t[0]->n_cols; c++)
    if (!is_coordinate(t[0]->name[c]) && strlen(t[0]->name[c]) > (size_t)width) width = (int)strlen(t[0]->name[c]);
  if (csv) {
    fprintf(out, k > 1 ? "column,runs,n,mean,stderr,sd,tau_sweeps,n_eff,r_hat,p_runs,se_runs\n"
                       : "column,n,mean,stderr,sd,tau_sweeps,n_eff,window_closed,drift_z,batch_ratio\n");
  } else {
    if (k > 1) fprintf(out, "%d runs:\n", k);
    for (int r = 0; r < k; r++) stretch_line(out, k > 1 ? "  " : "", t[r], path[r], row[r], n[r], tuned[r]);
    fprintf(out, "%-*s %15s %11s %11s %11s %9s", width, "column", "mean", "stderr", "sd", "tau_sweeps", "n_eff");
    fprintf(out, k > 1 ? " %8s %9s %9s\n" : "\n", "R_hat", "p_runs", "se_runs");
  }
  for (size_t c = 0; c < t[0]->n_cols; c++) {
    const char *name = t[0]->name[c];
    const column_stats *q = &cs[c];
    const lw_series_stats *s = &q->run[0];
    if (is_coordinate(name)) continue;
    if (!s->n) {
      /* (in the CSV too, so that scripts see the table's columns) */
      if (!csv) fprintf(out, "%-*s %15s\n", width, name, "(empty)");
      else if (k > 1) fprintf(out, "%s,%d,0,,,,,,,,\n", name, k);
      else fprintf(out, "%s,0,,,,,,,,\n", name);
    } else if (k > 1) {
      size_t rows = 0;
      for (int r = 0; r < k; r++) rows += q->run[r].n;
      char tau[32] = "-", neff[32] = "-", rh[32] = "-", pr[32] = "-";
      if (csv) tau[0] = neff[0] = rh[0] = pr[0] = '\0'; /* a value that is not there: empty, as for one run */
      if (q->sd > 0.0) {
        stat_cell(tau, sizeof tau, csv, "%.4g", q->tau_sweeps);
        stat_cell(neff, sizeof neff, csv, "%.0f", q->n_eff);
      }
      if (!isnan(q->p_runs)) {
        stat_cell(rh, sizeof rh, csv, "%.4g", q->r_hat);
        stat_cell(pr, sizeof pr, csv, "%.3g", q->p_runs);
      }
      char sd[32] = "-";
      if (csv) sd[0] = '\0';
      if (!isnan(q->sd)) stat_cell(sd, sizeof sd, csv, "%.4g", q->sd);
      /* a mean over other temperatures in other runs is no one ensemble's */
      char mean[32] = "-", se[32] = "-", spread[32] = "-";
      if (csv) mean[0] = se[0] = spread[0] = '\0';
      if (!q->mixed) {
        stat_cell(mean, sizeof mean, csv, "%.9g", q->mean);
        stat_cell(se, sizeof se, csv, "%.4g", q->stderr_mean);
        if (!isnan(q->se_runs)) stat_cell(spread, sizeof spread, csv, "%.4g", q->se_runs);
      }
      if (csv)
        fprintf(out, "%s,%d,%zu,%s,%s,%s,%s,%s,%s,%s,%s\n", name, k, rows, mean, se, sd, tau, neff, rh, pr, spread);
      else
        fprintf(out, "%-*s %15s %11s %11s %11s %9s %8s %9s %9s%s\n", width, name, mean, se, sd, tau, neff, rh, pr,
                spread, flagged(q, k) ? " *" : "");
    } else if (csv) {
      /* tau and n_eff mean nothing for a column without spread: empty, as
      ** the table's '-' and summary.json's null */
      char tau[32] = "", neff[32] = "";
      if (s->sd > 0.0) {
        lw_number_format_exact(tau, sizeof tau, q->tau_sweeps);
        lw_number_format_exact(neff, sizeof neff, s->n_eff);
      }
      char batch[32] = "", closed[8] = "", drift[32] = "", mean[32];
      if (s->sd > 0.0) snprintf(closed, sizeof closed, "%d", s->window > 0);
      /* (as summary.json's observables: halves of a column without spread
      ** have no difference to weigh, and read 0 here, null there) */
      if (s->sd > 0.0 && !isnan(s->drift_z)) lw_number_format_exact(drift, sizeof drift, s->drift_z);
      if (!isnan(s->batch_ratio)) lw_number_format_exact(batch, sizeof batch, s->batch_ratio);
      char se[32] = "", sd[32] = ""; /* one row: none */
      if (s->n > 1) {
        lw_number_format_exact(se, sizeof se, s->stderr_mean);
        lw_number_format_exact(sd, sizeof sd, s->sd);
      }
      fprintf(out, "%s,%zu,%s,%s,%s,%s,%s,%s,%s,%s\n", name, s->n, lw_number_format_exact(mean, sizeof mean, s->mean),
              se, sd, tau, neff, closed, drift, batch);
    } else if (s->n == 1) {
      fprintf(out, "%-*s %15.9g %11s %11s %11s %9s *\n", width, name, s->mean, "-", "-", "-", "-");
    } else if (!(s->sd > 0.0)) {
      fprintf(out, "%-*s %15.9g %11.4g %11.4g %11s %9s\n", width, name, s->mean, 0.0, 0.0, "-", "-");
    } else {
      fprintf(out, "%-*s %15.9g %11.4g %11.4g %11.4g %9.0f%s\n", width, name, s->mean, s->stderr_mean, s->sd,
              q->tau_sweeps, s->n_eff, flagged(q, 1) ? " *" : "");
    }
  }
  /* these two have no column in --csv: there they go apart (stderr) */
  FILE *apart = csv ? sel[0].csv_warnings : out;
  if (apart && tlo < thi) /* equal: one temperature; inf > -inf: no temperature column (dynamics) */
    fprintf(apart, "warning: the temperature changes within %s: the means mix ensembles\n",
            k > 1 ? "or between the runs" : "these rows");
  if (apart && ladders_differ)
    fprintf(apart, "warning: the runs' rungs stand at other temperatures (other ladders, or each tuned its own): "
            "the columns of those rungs and their swaps mix ensembles, and their mean, stderr, R_hat and p_runs are "
            "left empty; compare them run by run, or with --reweight\n");
  const int frozen = frozen_runs(t[0], cs, k);
  if (apart && frozen)
    fprintf(apart, "warning: %s accepted no move in these rows (every acc_ column 0): %s chain stood still, so "
            "its columns' means are one state's and their error bars 0 say nothing of the distribution (a step "
            "too large, or a temperature too low, for the moves)\n",
            k > 1 ? (frozen > 1 ? "runs" : "a run") : "the run", frozen > 1 ? "their" : "its");
  if (apart && k > 1) warn_twins(apart, raw, n, path, k);
  warn(apart, t[0], cs, k, WARN_ROUNDED, "printed to 10 digits (output.trace_exact = 0, as runs begun before "
       "2026-12-07), which is coarse "
       "against their spread: the rounding's variance is over 1 % of theirs, so their error bars and a heat "
       "capacity from them are off by as much or more (a new run writes every digit)");
  /* the table's warnings; with --csv, those of one run are its columns
  ** (window_closed, n and n_eff, drift_z, batch_ratio), and of several runs
  ** only r_hat and p_runs: the rest go apart, where a script sees that the
  ** error bars are lower bounds or absent (they went nowhere) */
  FILE *per_column = csv ? (k > 1 ? apart : NULL) : out, *in_table = csv ? NULL : out;
  warn(per_column, t[0], cs, k, WARN_OPEN, "the autocorrelation did not die out within half the rows: tau is a lower "
       "bound and the error bar too small (a longer stretch is needed)");
  warn(per_column, t[0], cs, k, WARN_ONE, k > 1 ? "a run of one row, which has no error bar of its own: the error bar "
       "above is the spread of the runs' means over sqrt(runs), and the runs are not compared (R_hat and p_runs "
       "empty)" : "one row: a mean and no error bar (a longer stretch is needed)");
  warn(per_column, t[0], cs, k, WARN_FEW, k > 1 ? "fewer than 25 independent samples in a run (n_eff sums the "
       "runs): that run's error bar, and the test of the runs against each other, are rough"
       : "fewer than 25 independent samples: the error bar is rough");
  warn(per_column, t[0], cs, k, WARN_BATCH, "the means of 20 batches spread more than 1.5 times the error bar allows "
       "(by chance 1 time in 700): a slower mode the autocorrelation time missed, so the error bar is too small "
       "(batch_ratio in --csv is the factor; run longer, or trust the larger bar)");
  warn(per_column, t[0], cs, k, WARN_DRIFT, "the first and second halves differ by more than 4 standard errors: not "
       "yet stationary (start later with --from), or, where the batch means warn too, the same slow mode (run "
       "longer)");
  warn(in_table, t[0], cs, k, WARN_RUNS, "the runs disagree beyond their error bars (p_runs < 0.001 or R_hat > 1.1): "
       "not converged, or the stretches too short for their error bars");
  warn(per_column, t[0], cs, k, WARN_COARSE, "the values are about uncorrelated at their spacing, so tau_sweeps is "
       "at most half of it, not a measurement (the error bar holds; rows more often, output.trace_every, measure "
       "it)");
done:
  for (int r = 0; row && r < k; r++) free(row[r]);
  for (int r = 0; heat && r < k; r++) lw_trace_free(heat[r]);
  free(heat);
  free(row);
  free(n);
  free(tuned);
  free(every);
  free(gap);
  free(x);
  free(cs);
  free(runs);
  return status;
}

lw_status lw_trace_stats(const lw_trace *t, const char *path, const lw_trace_select *sel, FILE *out,
                         lw_error *err)
{
  return lw_trace_stats_runs(&t, &path, sel, 1, out, err);
}
