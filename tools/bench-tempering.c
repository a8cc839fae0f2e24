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
**
** Across processes (bin/linewise-mpi, where make mpi built it and mpirun is
** installed): the same scene as a scene file, run by mpirun on P processes
** of cores / P threads, and the binary's own report of the time its
** processes spent in the exchange steps' messages (mpi_tempering.h).
*/
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

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

/* The scene of time_sweeps as a file for the MPI binary, on a ladder narrow
** enough (0.05 to 0.0525) that replicas swap and chain data moves. */
static void write_scene(const char *path, int replicas, int sweeps)
{
  FILE *f = fopen(path, "w");
  if (!f) {
    lw_error err = {.code = LW_EIO};
    snprintf(err.msg, sizeof err.msg, "%s: cannot write", path);
    bench_die("tempering", &err);
  }
  fprintf(f, "[scene]\nwidth = 120\nheight = 120\nmargin = 5\n"
             "[init]\nsplines = 150\nsegments = 4\nsegment_length = 5\n"
             "[energy]\nstrain = 10\nbending = 1\npair = 0.01\npair_cutoff = 4\nboundary = 0.1\n"
             "[anneal]\nschedule = constant\nt_start = 0.05\nsweeps = %d\n"
             "[tempering]\nreplicas = %d\nt_min = 0.05\nt_max = 0.0525\n"
             "[output]\ncheckpoint_every = 1000000\ntrace_every = 1000000\n", sweeps, replicas);
  fclose(f);
}

/* One MPI run of R replicas on P processes: its report line's numbers
** (ms a sweep, ms in the exchange steps on the quickest and the slowest
** process, chain moves a sweep, us for one reduction and one chain move
** alone); 0 if it did not run. */
enum { MPI_VALUES = 6 };
static int mpi_run(const char *bin, const char *dir, int R, int P, int threads, int sweeps, double v[MPI_VALUES])
{
  char cmd[1024], path[128], line[1024];
  snprintf(path, sizeof path, "%s/mpi.ini", dir);
  write_scene(path, R, sweeps);
  snprintf(cmd, sizeof cmd, "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=%d "
           "mpirun --oversubscribe -n %d %s run %s --out %s/mpi-run 2>%s/mpi.log >/dev/null",
           threads, P, bin, path, dir, dir);
  const int ran = system(cmd) == 0;
  snprintf(path, sizeof path, "%s/mpi.log", dir);
  FILE *f = fopen(path, "r");
  int got = 0;
  /* (from "each:" on: "1 process" and "1 thread" are said in the singular,
  ** which every row on 2 cores has) */
  const char *each;
  while (f && fgets(line, sizeof line, f))
    if (ran && !strncmp(line, "linewise: MPI: ", 15) && (each = strstr(line, " each: ")) &&
        sscanf(each, " each: %lf ms a sweep; exchange steps %lf ms a sweep (%*f %%) on the quickest process, %lf "
               "ms (%*f %%) on the one that waited longest; %lf chain moves a sweep of %*d bytes; alone, one "
               "reduction of %*d words %lf us, one chain move %lf", &v[0], &v[1], &v[2], &v[3], &v[4],
               &v[5]) == MPI_VALUES)
      got = 1;
  /* the log goes with the scratch directory: its lines here */
  if (!got && f) {
    rewind(f);
    fprintf(stderr, "bench: tempering: MPI, %d replicas on %d processes: %s; its log:\n", R, P,
            ran ? "no report line" : "the run failed");
    while (fgets(line, sizeof line, f)) fprintf(stderr, "  %s", line);
  }
  if (f) fclose(f);
  return got;
}

/* The MPI table, where the MPI build and mpirun are there. */
static void bench_mpi(bench_ctx *b, FILE *d, const char *dir, int cores)
{
  const char *bin = getenv("LW_MPI_BIN");
  if (!bin || !*bin) bin = "bin/linewise-mpi";
  if (access(bin, X_OK) || system("command -v mpirun >/dev/null 2>&1")) {
    fprintf(d, "### Across processes (MPI)\n\nNot measured: no %s or no mpirun (make deps-mpi && make mpi).\n\n", bin);
    return;
  }
  int sweeps = b->quick ? 10 : 30, reps = b->quick ? 1 : 3;
  fprintf(d, "### Across processes (MPI)\n\n"
             "The same scene on a ladder from 0.05 to 0.0525 (so that replicas swap), run by\n"
             "`mpirun -n P bin/linewise-mpi` for %d sweeps, each process with %d / P threads, as\n"
             "the binary reports it (the run of median sweep time of %d): wall milliseconds per\n"
             "sweep (start-up excluded); the milliseconds per sweep that processes spent in the\n"
             "exchange steps (the reduction of every replica's energy terms after each sweep, the\n"
             "chain data of swaps that cross processes, the drift checks), on the process that\n"
             "spent least and on the one that spent most, both including the wait for the other\n"
             "processes to finish their sweep; and, timed alone after the run (median of 201), one\n"
             "reduction and one chain move (about 5 kB between two processes): the messages' own\n"
             "cost. P = 1 runs the same code with no peer.\n\n"
             "| replicas | processes | threads each | ms per sweep | exchange, least | exchange, most | "
             "chain moves per sweep | one reduction | one chain move |\n|---|---|---|---|---|---|---|---|---|\n",
             sweeps, cores, reps);
  const int rs[2] = {4, 8};
  for (int i = 0; i < 2; i++)
    for (int P = 1; P <= cores && P <= rs[i]; P *= 2) {
      double run[3][MPI_VALUES], t[3];
      int threads = cores / P > 0 ? cores / P : 1, ok = 1;
      bench_note("tempering: MPI, %d replicas on %d processes", rs[i], P);
      for (int r = 0; r < reps && ok; r++) {
        if ((ok = mpi_run(bin, dir, rs[i], P, threads, sweeps, run[r]))) t[r] = run[r][0];
      }
      if (!ok) {
        fprintf(d, "| %d | %d | %d | failed (its log on the bench's standard error) | | | | | |\n", rs[i], P,
                threads);
        continue;
      }
      double mid = bench_median(t, reps), *v = run[0];
      for (int r = 0; r < reps; r++)
        if (run[r][0] == mid) v = run[r];
      fprintf(d, "| %d | %d | %d | %.1f | %.3f ms (%.1f %%) | %.3f ms (%.1f %%) | %.2f | %.1f us | %.1f us |\n", rs[i],
              P, threads, v[0], v[1], 100 * v[1] / v[0], v[2], 100 * v[2] / v[0], v[3], v[4], v[5]);
    }
  fprintf(d, "\n");
}

void bench_tempering(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_PERFORMANCE];
  int reps = b->reps, cores = omp_get_num_procs();
  char dir[128];
  bench_scratch_dir(dir, sizeof dir, "pt");
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
  bench_mpi(b, d, dir, cores);
  omp_set_num_threads(cores);
  bench_scratch_remove(dir);
}
