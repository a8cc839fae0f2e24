/*
** benchutil.h -- what the sections of the benchmark (tools/bench*.c) share:
** the clock and medians, the two Markdown documents and the data files for
** the plots, scenes of random lines at a given density, the annealed scene of
** the accuracy study, and timed Metropolis chains.
**
** Timing rules (make bench): every figure is the median of `reps` timed
** blocks; runs compared with each other are timed interleaved (block 1 of
** each, then block 2, ...) so that a change in machine load hits all of them
** alike, and their ratios are taken block by block, then the median.
** A timed proposal is a point or a vector move, alternating; one core.
*/
#ifndef LINEWISE_BENCHUTIL_H
#define LINEWISE_BENCHUTIL_H

#include <stdio.h>

#include "linewise/mc.h"
#include "linewise/sys_splines.h"
#include "linewise/params.h"
#include "linewise/scene.h"

typedef enum { BENCH_PERFORMANCE, BENCH_ACCURACY, BENCH_DOCS } bench_doc;

#define BENCH_MAX_REPS 35

/* What the accuracy sections measured, for the guide (bench_guide). */
#define BENCH_MAX_ROWS 16
typedef struct {
  int n;                          /* rows measured (0: section not run) */
  double value[BENCH_MAX_ROWS];   /* nodes, cutoff mm (0 = none) or near radius */
  double err[BENCH_MAX_ROWS];     /* relative error of the pair energy */
  double de[BENCH_MAX_ROWS];      /* median relative error of dE */
  double decisions[BENCH_MAX_ROWS]; /* share of Metropolis decisions that differ */
  double ns[BENCH_MAX_ROWS];      /* ns per proposal */
  double ratio[BENCH_MAX_ROWS];   /* time over the default's */
} bench_study;

/* Settings of one benchmark run and the state sections share. */
typedef struct {
  int quick;                 /* a smoke run (BENCH_QUICK=1): fewer, shorter blocks */
  int reps;                  /* timed blocks behind every median (odd) */
  double block;              /* seconds per timed block */
  const char *datadir;       /* where the plots' data files go */
  FILE *doc[BENCH_DOCS];     /* the Markdown documents being written */
  /* The annealed accuracy scene (bench_annealed), built on first use. */
  lw_params ann_params;
  lw_splines *ann_splines;
  double ann_step[LW_MOVE_KINDS];
  double ann_spacing;        /* boundary area / total line length, mm */
  double ann_seconds;        /* wall time of the anneal */
  bench_study quadrature, cutoff, near; /* what the accuracy sections found */
  double near_curves_worst[2];  /* two-curve cases at 8 nodes: worst error, near off / 1.5 */
  double cutoff_exponent;       /* time per proposal grows as cutoff^this */
} bench_ctx;

double bench_now(void);

/* Median of v[0..n-1] (v is sorted in place). */
double bench_median(double *v, int n);

/* Prints what failed and exits 1 (the benchmark is a tool, not the library). */
_Noreturn void bench_die(const char *what, const lw_error *err);

/* Opens datadir/name for writing (exits on failure). */
FILE *bench_data(const bench_ctx *b, const char *name);

/* A fresh scratch directory $TMPDIR/lw_bench_<tag>_XXXXXX into dir[n] (/tmp
** when TMPDIR is unset, long, or holds characters a shell would read);
** exits on failure.  bench_scratch_remove deletes it and all in it. */
void bench_scratch_dir(char *dir, size_t n, const char *tag);
void bench_scratch_remove(const char *dir);

/* A progress line on stderr. */
void bench_note(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* The scene of random lines: n splines of 4 segments of 5 mm, spread at a
** mean spacing (area / total length) of `spacing` mm on a square page, every
** term on (radial potential, waves field), the pair term only if `pair`
** (C = 0.01, cutoff 4 mm).  Quadrature 8, near field 1.5. */
void bench_random_params(lw_params *p, size_t n, int pair, double spacing);

/* A scene, its model and one chain on it: what a timed block runs. */
typedef struct {
  lw_scene scene;
  lw_model *model;
  lw_system *sys;   /* a view of the model: the chain goes through the row */
  lw_chain *chain;
  int narrow;       /* its blocks run the two-wide kernels even where AVX2 is there (vec2.h) */
  int sweeps;       /* its blocks run whole sweeps, as a run makes them (lw_chain_sweep), instead
                    ** of point and vector moves of nodes drawn at random */
} bench_run;

/* Builds the scene of p, a model on sp (owned; NULL: p->splines random lines
** of p->segments segments of p->segment_length, placed with seed p->seed)
** and a chain of point and vector moves at temperature T with the given
** steps (NULL: 0.2 mm) and tuning off. */
void bench_run_init(bench_run *r, const lw_params *p, lw_splines *sp, double T, const double *step);
void bench_run_free(bench_run *r);

/* Runs `proposals` proposals with step tuning on, then freezes the steps. */
void bench_run_tune(bench_run *r, long proposals);

/* A fixed list of proposals: one node of one spline and its new value. */
typedef struct {
  uint32_t spline;
  size_t node;   /* within the spline */
  lw_node nd;    /* the proposed node */
} bench_trial;

/* n point and vector moves (alternating) of random nodes of sp with Gaussian
** steps step[0] (points) and step[1] (vectors), mm; from a fixed seed. */
bench_trial *bench_trials_new(const lw_splines *sp, const double step[2], int n);

/* dE of trial t on r's model (the model is not changed). */
double bench_run_propose(bench_run *r, const bench_trial *t);

/* ns per proposal over one block of at least `seconds`: chain steps (or
** sweeps, with r->sweeps), or with trials, evaluations of the trials in turn
** (lw_model_propose, never committed: the cost of the energy terms without
** the Metropolis walk). */
double bench_run_block(bench_run *r, double seconds, const bench_trial *trials, int n_trials);

/* Times runs[0..n-1] in b->reps interleaved blocks of b->block seconds
** (chain steps, or the trials as in bench_run_block): ns[i] the median ns per
** proposal of run i, ratio[i] the median of run i's time over run ref's in the
** same block, spread[i] (may be NULL) the median absolute deviation of that
** ratio (a measure of the noise). */
void bench_time_runs(const bench_ctx *b, bench_run *runs, int n, int ref, const bench_trial *trials,
                     int n_trials, double *ns, double *ratio, double *spread);

/* Acceptance of the point and vector moves since the chain began. */
double bench_run_acceptance(const bench_run *r);

/* The scene of the accuracy study, built once: params/study.ini with a
** radial potential added (every term on), annealed by the annealer itself
** (lw_anneal, its files in datadir/anneal) so the curves are bent and close
** together.  Returns the splines; the parameters, the final steps and the
** spacing are in b->ann_*. */
const lw_splines *bench_annealed(bench_ctx *b);

#endif
