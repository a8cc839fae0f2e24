/*
** bench-tempering.c -- the tempering section of the benchmark: wall-time
** speed-up of parallel tempering on the available cores, and the cost of the
** exchange steps.
**
** For R = 2, 4, 8 replicas of a scene with the pair term on,
** times the same sweeps with 1 thread and with all cores; prints the median
** of several repetitions and the ratio of the medians, measured in the same
** run.  The exchange overhead is the time of one exchange step (energies,
** the Metropolis draws, the pointer swaps) against the time of one sweep of
** the ensemble, at the default interval (every sweep).
*/
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "benchutil.h"
#include "linewise/anneal.h"

/* Seconds per sweep of the ensemble (median of reps), after warm-up sweeps. */
static double time_sweeps(int replicas, int threads, int sweeps, int reps, const char *dir)
{
  lw_params p;
  lw_error err;
  lw_params_defaults(&p);
  p.width = p.height = 120;
  p.margin = 5;
  p.splines = 150;
  p.segments = 4;
  p.segment_length = 5;
  p.strain = 10;
  p.bending = 1;
  p.pair = 0.01;
  p.pair_cutoff = 4;
  p.boundary_coef = 0.1;
  p.replicas = replicas;
  p.t_min = 0.05;
  p.t_max = 1;
  strcpy(p.schedule, "constant");
  p.t_start = 0.05;
  p.sweeps = 1000000;
  p.checkpoint_every = 1000000;
  p.trace_every = 1000000;
  omp_set_num_threads(threads);
  lw_anneal a;
  if (lw_anneal_start(&a, &p, dir, &err)) bench_die("tempering", &err);
  double t[BENCH_MAX_REPS];
  for (int k = 0; k < 2; k++)
    if (lw_anneal_sweep(&a, &err)) bench_die("tempering", &err);
  for (int r = 0; r < reps; r++) {
    double t0 = bench_now();
    for (int k = 0; k < sweeps; k++)
      if (lw_anneal_sweep(&a, &err)) bench_die("tempering", &err);
    t[r] = (bench_now() - t0) / sweeps;
  }
  lw_anneal_free(&a);
  return bench_median(t, reps);
}

/* Seconds per exchange step of n rungs with energies that swap about half
** the time. */
static double time_exchange(int n)
{
  double ladder[LW_TEMPERING_MAX], e[LW_TEMPERING_MAX];
  int swapped[LW_TEMPERING_MAX];
  lw_tempering_geometric(ladder, n, 0.05, 1);
  lw_error err;
  lw_tempering *pt = lw_tempering_new(n, ladder, 1, &err);
  if (!pt) bench_die("tempering", &err);
  const long steps = 2000000;
  double t0 = bench_now(), sink = 0;
  for (long s = 0; s < steps; s++) {
    for (int k = 0; k < n; k++) e[k] = 10.0 + 0.01 * (double)((s + k) % 7);
    sink += lw_tempering_exchange(pt, e, ladder, swapped);
  }
  double t = (bench_now() - t0) / (double)steps;
  lw_tempering_free(pt);
  return sink >= 0 ? t : 0.0;
}

void bench_tempering(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_PERFORMANCE];
  int reps = b->reps, cores = omp_get_num_procs();
  char dir[] = "/tmp/lw_bench_pt_XXXXXX";
  if (!mkdtemp(dir)) {
    lw_error err = {.code = LW_EIO};
    snprintf(err.msg, sizeof err.msg, "cannot make a scratch directory");
    bench_die("tempering", &err);
  }
  fprintf(d, "## Parallel tempering\n\n"
             "150 splines of 4 segments, every term but potential and field, pair cutoff 4 mm,\n"
             "constant temperature, geometric ladder 0.05 to 1, an exchange step every sweep (the\n"
             "default). Milliseconds per sweep of the whole ensemble: median of %d blocks; the\n"
             "speed-up is the ratio of the two medians, measured in the same run on %d cores. The\n"
             "exchange overhead is the time of one exchange step (energies, draws, pointer swaps)\n"
             "over the time of one sweep of the ensemble on %d threads.\n\n"
             "| replicas | 1 thread, ms per sweep | %d threads, ms per sweep | speed-up | exchange overhead |\n"
             "|---|---|---|---|---|\n", reps, cores, cores, cores);
  const int rs[3] = {2, 4, 8};
  for (int i = 0; i < 3; i++) {
    int R = rs[i], sweeps = (b->quick ? 8 : 16) / R > 2 ? (b->quick ? 8 : 16) / R : 2;
    bench_note("tempering: %d replicas", R);
    double t1 = time_sweeps(R, 1, sweeps, reps, dir);
    double tn = time_sweeps(R, cores, sweeps, reps, dir);
    double tx = time_exchange(R);
    fprintf(d, "| %d | %.1f | %.1f | %.2f | %.1e |\n", R, 1e3 * t1, 1e3 * tn, t1 / tn, tx / tn);
  }
  fprintf(d, "\n");
  omp_set_num_threads(cores);
  char cmd[64];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  if (system(cmd) != 0) bench_note("tempering: could not remove %s", dir);
}
