/*
** trace.h -- a run's trace.csv read back, and the means with error bars of
** its columns over a stretch of sweeps (`linewise stats`, docs/FORMATS.md).
*/
#ifndef LINEWISE_TRACE_H
#define LINEWISE_TRACE_H

#include <stdio.h>

#include "linewise/error.h"
#include "linewise/params.h"
#include "linewise/series.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_TRACE_HEAT_MAX 256 /* heat capacity columns at most: a rung each (tempering.replicas) */

typedef struct {
  size_t n_cols, n_rows;
  char **name;   /* n_cols column names, from the header */
  double *v;     /* n_rows x n_cols, row-major; NaN for an empty field */
} lw_trace;

/* Reads a trace.csv.  A last line without its newline (a run still writing,
** or killed mid-row) is left out.  NULL and err set (LW_EINPUT naming the
** file, line and column) on anything else that is not a header of names and
** rows of numbers or empty fields under it. */
lw_trace *lw_trace_read(const char *path, lw_error *err);
void lw_trace_free(lw_trace *t);

/* The column of that name, or -1. */
int lw_trace_column(const lw_trace *t, const char *name);

/* The rungs of a tempering run's trace: the columns of replicaK_energy and
** replicaK_temperature for K = 0, 1, ... into energy[] and temp[]; their
** count (0 without tempering), at most max. */
int lw_trace_rungs(const lw_trace *t, int *energy, int *temp, int max);

/* Which rows `linewise stats` takes, by sweep: from <= sweep <= to (from < 0:
** the first sweep at the last row's temperature, or without a temperature
** column, the dynamics' trace, the first row; to < 0: to the end), less
** the rows of sweeps whose steps still adapted: the first `tune`
** (moves.tune_sweeps) of each of the schedule's `steps` temperature steps
** over `sweeps` (anneal.steps, anneal.sweeps; tune = 0: none), and the
** first `ladder` sweeps, a tempering ladder's warm-up (tempering.ladder_sweeps
** under tune_ladder = equal; 0: none). */
typedef struct {
  long from, to;
  long tune, steps, sweeps;
  long ladder;
  int csv;       /* 1: one CSV line per column; 0: a table for people */
  FILE *csv_warnings; /* with csv: where the warnings no column carries go (NULL: nowhere) */
} lw_trace_select;

/* From a run's parameters: the tuning (steps and ladder) that the rows leave out, and from =
** output.stats_from where it is set and sel->from is not. */
void lw_trace_select_of(const lw_params *p, lw_trace_select *sel);

/* The rows sel chooses: their indices into *rows (malloc'd: free it), their
** count *n, and *tuned the rows left out for tuning.  LW_EINPUT naming path
** for a trace without a sweep count column or with no row chosen. */
lw_status lw_trace_rows(const lw_trace *t, const char *path, const lw_trace_select *sel, size_t **rows, size_t *n,
                        size_t *tuned, lw_error *err);

/* A copy of t with a heat capacity column after its own for each energy
** with a temperature: `heat_capacity` of the total at the row's
** temperature, or with tempering `replicaK_heat_capacity` of every rung
** (lw_trace_rungs).  On the n rows chosen its values are (E - <E>)^2 / T^2,
** <E> their mean, so that the column's mean is C = Var(E) / T^2 (k_B = 1)
** and its error bar comes from its own autocorrelation like any column's;
** elsewhere, and where T changes within the rows (no ensemble to speak
** of), they are empty.  NULL and err (LW_ENOMEM, naming path). */
lw_trace *lw_trace_with_heat_capacity(const lw_trace *t, const size_t *rows, size_t n, const char *path,
                                      lw_error *err);

/* The rows' spacing in sweeps (output.trace_every), from the first two. */
double lw_trace_every(const lw_trace *t);

/* Whether the n values (a column's, or a rung's energies) are all at 10
** significant digits, as traces were printed before 2026-12-07, and spread
** under 3 steps of the last digit: the rounding's variance is then over 1 %
** of theirs, and a heat capacity of them off by as much or more. */
int lw_trace_rounded(const double *x, size_t n);

/* The statistics of column col over the n rows, empty fields skipped (out->n
** = 0 when every one is empty); x is scratch for n values. */
void lw_trace_column_stats(const lw_trace *t, const size_t *rows, size_t n, int col, double *x, lw_series_stats *out);

/* Sweeps between a column's values, its statistics st taken over n rows
** every sweeps apart: a column filled on only some rows (swapK on every
** other one, a spline's observable while none lives) has its tau counted in
** its own values.  summary.json and `linewise stats` both take tau so. */
double lw_trace_column_gap(double every, size_t n, const lw_series_stats *st);

/* Prints the statistics (series.h) of every column but the sweep and
** temperature or time (and the rungs' temperatures) over the rows chosen,
** then of the heat capacities Var(E) / T^2 derived from them (of the
** total, or with tempering of each rung's energy; docs/FORMATS.md),
** as a table or CSV (sel->csv); the table is followed by one warning line
** per kind of trouble, naming its columns: a window that did not close,
** fewer than 25 independent samples, halves that disagree (series.h's
** drift_z beyond 4), a temperature that changes.  path names the file in
** messages.  LW_EINPUT when no row is chosen. */
lw_status lw_trace_stats(const lw_trace *t, const char *path, const lw_trace_select *sel, FILE *out,
                         lw_error *err);

/* The same for k >= 1 runs of one scene (independent seeds, say), each with
** its own stretch (sel[r]; the format from sel[0].csv): per column the
** mean of the runs' means and its error bar, and whether they agree: the
** chi-square probability of their spread under their own error bars
** (p_runs) and Gelman and Rubin's R-hat; a warning names the columns where
** p_runs < 0.001 or R-hat > 1.1.  LW_EINPUT when a run's columns are not
** the first's. */
lw_status lw_trace_stats_runs(const lw_trace *const *t, const char *const *path, const lw_trace_select *sel, int k,
                              FILE *out, lw_error *err);

/* Warns on out of runs among the k that are one run over the rows they
** share, each over its own stretch (sel[r]): the same seed twice, or a copy
** stopped earlier (lw_trace_stats_runs says it too; the reweighting pools
** rungs, and says it with this). */
void lw_trace_warn_twins(const lw_trace *const *t, const char *const *path, const lw_trace_select *sel, int k,
                         FILE *out);

#ifdef __cplusplus
}
#endif

#endif
