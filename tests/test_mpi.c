/*
** test_mpi.c -- parallel tempering over MPI processes (bin/linewise-mpi,
** make mpi): the same bytes as the one-process run on 2 and 4 processes,
** resume with another process count, a stop asked of one process, a killed
** process, and a ladder too short for the processes.  Skipped, saying why,
** where the MPI build or mpirun is missing (make deps-mpi installs them).
*/
#include <criterion/criterion.h>
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>
#include <stdlib.h>

#include "testutil.h"

static char dir[64];
#define sh lw_test_sh

static void make_dir(void) { cr_assert_eq(lw_test_dir_make(dir, "mpi"), 0); }
static void remove_dir(void) { cr_assert_eq(lw_test_dir_remove(dir), 0); }

TestSuite(mpi, .init = make_dir, .fini = remove_dir);

/* mpirun with what a root container needs and room for 4 processes on 2
** cores; the processes default to cores / processes threads.  Under make
** asan, LeakSanitizer is told of Open MPI's own leaks (tests/lsan-mpi.supp),
** which it can only match with full stacks. */
#define MPIRUN                                                                                            \
  "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "                                             \
  "LSAN_OPTIONS=suppressions=${LW_ROOT:-.}/tests/lsan-mpi.supp:print_suppressions=0 "                      \
  "ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}fast_unwind_on_malloc=0 mpirun --oversubscribe"

/* The MPI binary, or skips the test saying what is missing. */
static const char *mpi_bin(void)
{
  const char *b = getenv("LW_MPI_BIN");
  if (!b || !*b) cr_skip_test("no MPI build: LW_MPI_BIN is not set (make test sets it where mpicc exists and mpirun "
                                      "starts a process; make deps-mpi)");
  if (sh("command -v mpirun >/dev/null 2>&1")) cr_skip_test("mpirun is not installed (make deps-mpi)");
  return b;
}

/* The ensemble of test_tempering.c: 4 replicas, ladder tuning, checkpoints,
** drift checks and trace rows at sweeps that do not line up. */
static const char scene[] =
  "[scene]\nwidth = 50\nheight = 40\nmargin = 2\n"
  "[init]\nsplines = 8\nsegments = 3\nsegment_length = 4\n"
  "[energy]\nstrain = 5\nbending = 0.5\npair = 0.05\npair_cutoff = 4\nboundary = 0.1\n"
  "[anneal]\nschedule = geometric\nt_start = 0.5\nt_end = 0.05\nsweeps = 90\nsteps = 5\nseed = 8\ncheck_every = 11\n"
  "[tempering]\nreplicas = 4\nt_min = 0.5\nt_max = 4\ntune_ladder = equal\nladder_sweeps = 40\n"
  "[output]\ncheckpoint_every = 13\ntrace_every = 4\n";

static void write_scene(void) { cr_assert_eq(lw_test_write_text(dir, "s.ini", scene), 0); }

static const char *const same[] = {"state.lw", "replica-1.lw", "replica-2.lw", "replica-3.lw",
                                   "trace.csv", "final.svg", "final.png", "ladder.ini"};

static void assert_same(const char *a, const char *b)
{
  for (int k = 0; k < 8; k++)
    cr_assert_eq(sh("cmp -s %s/%s/%s %s/%s/%s", dir, a, same[k], dir, b, same[k]), 0, "%s differs between %s and %s",
                 same[k], a, b);
}

Test(mpi, two_and_four_processes_write_the_bytes_of_the_one_process_run)
{
  const char *m = mpi_bin(), *b = lw_test_bin();
  write_scene();
  cr_assert_eq(sh("%s run %s/s.ini --out %s/ref --quiet", b, dir, dir), 0);
  cr_assert_eq(sh(MPIRUN " -n 2 %s run %s/s.ini --out %s/p2 --quiet", m, dir, dir), 0);
  cr_assert_eq(sh(MPIRUN " -n 4 %s run %s/s.ini --out %s/p4 --quiet", m, dir, dir), 0);
  assert_same("ref", "p2");
  assert_same("ref", "p4");
  /* the replicas did change process: with one each, every swap crosses */
  cr_assert_eq(sh("grep -q '^at_label = 0 ' %s/p4/state.lw", dir), 1, "replica 0 never left rung 0");
  cr_assert_eq(sh("grep -q '\"round_trips\"' %s/p4/summary.json", dir), 0);
  /* the study tools read it as any run */
  cr_assert_eq(sh("%s/tools/plot-run %s/p4 >/dev/null 2>&1", lw_test_root(), dir), 0);
  cr_assert_eq(sh("test -s %s/p4/plots/replicas.png && test -s %s/p4/plots/swaps.png", dir, dir), 0);
}

/* A recomputation from scratch at the last sweep (check_every 10 of 90)
** changes the totals in their last bits after the sweep's exchange of
** energies: summary.json still reads every rung's as one process does. */
Test(mpi, summary_json_reads_every_rung_as_the_one_process_run)
{
  const char *m = mpi_bin(), *b = lw_test_bin();
  write_scene();
  cr_assert_eq(sh("%s run %s/s.ini --set anneal.check_every=10 --out %s/ref --quiet", b, dir, dir), 0);
  cr_assert_eq(sh(MPIRUN " -n 2 %s run %s/s.ini --set anneal.check_every=10 --out %s/p2 --quiet", m, dir, dir), 0);
  cr_assert_eq(sh("sed -n '/\"replicas\"/,/]/p' %s/ref/summary.json > %s/r1 && "
                  "sed -n '/\"replicas\"/,/]/p' %s/p2/summary.json > %s/r2 && grep -c energy %s/r1 | grep -qx 4 && "
                  "cmp -s %s/r1 %s/r2",
                  dir, dir, dir, dir, dir, dir, dir),
               0, "summary.json's replicas differ between one and two processes");
}

/* A run killed in its final drawings (state.lw at the last sweep, no
** summary.json) is resumed with no sweep left: the rungs held by the other
** process read as before any exchange of energies. */
Test(mpi, a_resume_with_no_sweep_left_reads_every_rung)
{
  const char *m = mpi_bin(), *b = lw_test_bin();
  write_scene();
  cr_assert_eq(sh("%s run %s/s.ini --out %s/ref --quiet && rm %s/ref/summary.json && cp -r %s/ref %s/p2", b, dir, dir,
                  dir, dir, dir), 0);
  cr_assert_eq(sh("%s resume %s/ref --quiet", b, dir), 0);
  cr_assert_eq(sh(MPIRUN " -n 2 %s resume %s/p2 --quiet", m, dir), 0);
  cr_assert_eq(sh("sed -n '/\"replicas\"/,/]/p' %s/ref/summary.json > %s/r1 && "
                  "sed -n '/\"replicas\"/,/]/p' %s/p2/summary.json > %s/r2 && grep -c energy %s/r1 | grep -qx 4 && "
                  "cmp -s %s/r1 %s/r2",
                  dir, dir, dir, dir, dir, dir, dir),
               0, "summary.json's replicas differ between one and two processes");
}

/* The process that drew tells what it drew, whichever it is, and the done
** line names the plotter's files. */
Test(mpi, the_drawing_is_described_and_every_file_named)
{
  const char *m = mpi_bin();
  write_scene();
  cr_assert_eq(sh(MPIRUN " -n 2 %s run %s/s.ini --set anneal.sweeps=50 --set output.gcode=1 --out %s/g 2>%s/err.txt",
                  m, dir, dir, dir), 0);
  cr_assert_eq(sh("grep -q '^linewise: [0-9]* paths (' %s/err.txt && grep -q '^linewise: plot time about' %s/err.txt && "
                  "grep -q '^linewise: done: .*final.gcode' %s/err.txt && test -s %s/g/final.gcode",
                  dir, dir, dir, dir), 0, "the MPI run did not describe its drawing or name final.gcode");
}

Test(mpi, resume_with_other_process_counts_continues_bit_exactly)
{
  const char *m = mpi_bin(), *b = lw_test_bin();
  write_scene();
  cr_assert_eq(sh("%s run %s/s.ini --out %s/ref --quiet", b, dir, dir), 0);
  /* stopped inside the ladder warm-up, then 4, 1 and 3 processes */
  cr_assert_eq(sh(MPIRUN " -n 2 %s run %s/s.ini --out %s/r --quiet --stop-at 23", m, dir, dir), 0);
  cr_assert_eq(sh(MPIRUN " -n 4 %s resume %s/r --quiet --stop-at 61", m, dir), 0);
  cr_assert_eq(sh("%s resume %s/r --quiet --stop-at 70", b, dir), 0);
  cr_assert_eq(sh(MPIRUN " -n 3 %s resume %s/r --quiet", m, dir), 0);
  assert_same("ref", "r");
}

Test(mpi, more_processes_than_replicas_is_refused_before_anything_is_written)
{
  const char *m = mpi_bin();
  write_scene();
  cr_assert_eq(sh(MPIRUN " -n 3 %s run %s/s.ini --set tempering.replicas=2 --out %s/x --quiet 2>%s/err.txt", m, dir,
                  dir, dir), 2);
  cr_assert_eq(sh("grep -q '^linewise: --set: key .tempering.replicas.: 2 replicas for 3 processes' %s/err.txt", dir), 0);
  /* said once, by process 0 */
  cr_assert_eq(sh("test $(grep -c 'replicas for 3 processes' %s/err.txt) -eq 1", dir), 0);
  cr_assert_neq(sh("test -e %s/x", dir), 0, "an output directory was created for bad input");
  /* a ladder sets the count: its key is named, not replicas "not set: the
  ** default, 1" */
  cr_assert_eq(sh(MPIRUN " -n 3 %s run %s/s.ini --set tempering.replicas=1 --set 'tempering.ladder=1 2' --out %s/x "
                  "--quiet 2>%s/err.txt", m, dir, dir, dir), 2);
  cr_assert_eq(sh("grep -q \"^linewise: --set: key 'tempering.ladder': 2 replicas for 3 processes; expected at least "
                  "one replica per process (the ladder's temperatures set the count)$\" %s/err.txt", dir), 0, "%s",
               lw_test_slurp("%s/err.txt", dir));
  /* from a ladder file, the key that names it; on resume, the ladder's
  ** line of the run's scene.ini (its "replicas = 1" was blamed) */
  cr_assert_eq(sh("cd %s && printf '[tempering]\\nladder = 1 2\\n' > lad.ini && " MPIRUN " -n 3 %s run s.ini --set "
                  "tempering.replicas=1 --set tempering.ladder_file=lad.ini --out x --quiet 2> err.txt; test $? -ne 0 "
                  "&& grep -q \"^linewise: --set: key 'tempering.ladder_file': 2 replicas for 3 processes\" err.txt",
                  dir, m), 0, "%s", lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(sh("cd %s && %s run s.ini --set tempering.replicas=1 --set 'tempering.ladder=1 2' --set "
                  "anneal.sweeps=2 --set tempering.tune_ladder=fixed --out two --quiet && " MPIRUN " -n 3 %s resume "
                  "two --quiet 2> err.txt; test $? -ne 0 "
                  "&& grep -q \"^linewise: two/scene.ini:$(grep -n '^ladder = ' two/scene.ini | cut -d: -f1): key "
                  "'tempering.ladder': 2 replicas for 3 processes\" err.txt", dir, lw_test_bin(), m), 0, "%s",
               lw_test_slurp("%s/err.txt", dir));
  /* a new run from that scene.ini, whose empty ladder_file line was blamed */
  cr_assert_eq(sh("cd %s && cp two/scene.ini again.ini && " MPIRUN " -n 3 %s run again.ini --out x --quiet 2> err.txt; "
                  "test $? -ne 0 && grep -q \"^linewise: again.ini:$(grep -n '^ladder = ' again.ini | cut -d: -f1): "
                  "key 'tempering.ladder': 2 replicas\" err.txt", dir, m), 0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* the dynamics moves one system: the driver is what to change, not the
  ** replicas it leaves idle (the message asked for more of them) */
  cr_assert_eq(sh(MPIRUN " -n 2 %s run %s/params/wire.ini --set tempering.replicas=2 --out %s/x --quiet 2>%s/err.txt",
                  m, lw_test_root(), dir, dir),
               2);
  cr_assert_eq(sh("grep -q \"key 'scene.driver': dynamics moves one system, which one process holds; expected one "
                  "process (mpirun -n 1, or linewise) for 2\" %s/err.txt", dir),
               0);
}

/* A run made again over a finished one keeps the run before until the
** network's first checkpoint: the MPI build dropped it when its set-up had
** written the start, before that checkpoint, and a full disk then lost both
** (the plain build put it back). */
Test(mpi, a_failed_first_checkpoint_puts_the_run_before_back)
{
  const char *m = mpi_bin();
  write_scene();
  cr_assert_eq(sh(MPIRUN " -n 2 %s run %s/s.ini --set anneal.sweeps=50 --out %s/r --quiet && cp -rp %s/r %s/keep", m,
                  dir, dir, dir, dir), 0);
  cr_assert_eq(sh(MPIRUN " -n 2 sh -c 'ulimit -f 8; exec %s run %s/s.ini --set anneal.sweeps=50 --seed 5 --out %s/r "
                  "--quiet' 2>%s/err.txt; grep -q 'the run that was in the directory is back as it was' %s/err.txt",
                  m, dir, dir, dir, dir), 0, "%s", lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(sh("rm -f %s/r/.lock %s/keep/.lock && diff -r %s/r %s/keep", dir, dir, dir, dir), 0);
}

/* The observables in the trace are the coldest rung's, whichever process
** sweeps its replica: the same bytes as one process, and summary.json's
** statistics of them the same text. */
Test(mpi, observables_and_timing_come_from_the_process_of_the_coldest_rung)
{
  const char *m = mpi_bin(), *b = lw_test_bin();
  write_scene();
  const char *obs = "--set output.observables=1 --set output.stats_from=30";
  cr_assert_eq(sh("%s run %s/s.ini --out %s/ref --quiet %s", b, dir, dir, obs), 0);
  cr_assert_eq(sh(MPIRUN " -n 2 %s run %s/s.ini --out %s/p2 --quiet %s", m, dir, dir, obs), 0);
  cr_assert_eq(sh(MPIRUN " -n 4 %s run %s/s.ini --out %s/p4 --quiet %s", m, dir, dir, obs), 0);
  cr_assert_eq(sh("head -1 %s/ref/trace.csv | grep -q ',obs_count,obs_length,obs_end2,obs_rg2,obs_end_cos$'", dir), 0);
  assert_same("ref", "p2");
  assert_same("ref", "p4");
  for (int k = 0; k < 2; k++)
    cr_assert_eq(sh("sed -n '/\"observables\"/,/}/p' %s/ref/summary.json > %s/o1 && "
                    "sed -n '/\"observables\"/,/}/p' %s/%s/summary.json > %s/o2 && test -s %s/o1 && cmp -s %s/o1 %s/o2",
                    dir, dir, dir, k ? "p4" : "p2", dir, dir, dir, dir),
                 0, "summary.json's observables differ");
  /* timing.txt counts the drawing, whichever process drew (one other than
  ** the first left it out, and an extension's wall time went down) */
  for (int k = 0; k < 2; k++)
    cr_assert_eq(sh("awk -F': ' '/\"wall_seconds\"/ { s = $2 + 0 } END { print s }' %s/%s/summary.json > %s/sw && "
                    "awk -v s=\"$(cat %s/sw)\" '/^wall_seconds/ { ok = $2 >= s - 1e-6 } END { exit !ok }' "
                    "%s/%s/timing.txt", dir, k ? "p4" : "p2", dir, dir, dir, k ? "p4" : "p2"),
                 0, "%s: timing.txt's wall time is short of summary.json's", k ? "p4" : "p2");
}

/* Starts a long run on 2 processes in the background (mpirun's status into
** DIR/NAME.rc, its output into DIR/NAME.err), waits for a checkpoint past
** sweep 0 and sends sig to the process of the given rank alone. */
static int signal_rank_mid_run(const char *m, const char *name, const char *sig, int rank)
{
  return sh("cd %s && { timeout 120 sh -c '" MPIRUN " -n 2 %s run s.ini --out %s --quiet --set anneal.sweeps=1000000 "
            "--set output.checkpoint_every=20 2>%s.err; echo $? > %s.rc' & } && "
            "for i in $(seq 600); do grep -q '^sweep = [1-9]' %s/state.lw 2>/dev/null && break; sleep 0.1; done && "
            "for p in /proc/[0-9]*; do { tr '\\0' ' ' < $p/cmdline; } 2>/dev/null | grep -q 'linewise-mpi run s.ini --out %s ' && "
            "  { tr '\\0' '\\n' < $p/environ; } 2>/dev/null | grep -qx OMPI_COMM_WORLD_RANK=%d && kill -%s ${p#/proc/}; done; "
            "for i in $(seq 1200); do test -s %s.rc && exit 0; sleep 0.1; done; exit 1",
            dir, m, name, name, name, name, name, rank, sig, name);
}

/* DIR/NAME/state.lw against a one-process run stopped at its sweep (into
** DIR/NAME-ref): the bytes are the same. */
static void assert_state_is_the_run_at_its_sweep(const char *b, const char *name)
{
  cr_assert_eq(sh("cd %s && s=$(sed -n 's/^sweep = //p' %s/state.lw) && "
                  "%s run s.ini --out %s-ref --quiet --set anneal.sweeps=1000000 --set output.checkpoint_every=20 "
                  "--stop-at $s && cmp -s %s/state.lw %s-ref/state.lw", dir, name, b, name, name, name),
               0, "%s/state.lw is not the one-process run's at its sweep", name);
}

Test(mpi, a_stop_asked_of_one_process_stops_all_at_the_same_sweep, .timeout = 300)
{
  const char *m = mpi_bin(), *b = lw_test_bin();
  write_scene();
  cr_assert_eq(signal_rank_mid_run(m, "stop", "TERM", 1), 0, "the run did not end after SIGTERM to process 1");
  cr_assert_eq(sh("test $(cat %s/stop.rc) -eq 0", dir), 0, "a clean stop exits 0");
  assert_state_is_the_run_at_its_sweep(b, "stop");
  cr_assert_eq(sh("cmp -s %s/stop/trace.csv %s/stop-ref/trace.csv", dir, dir), 0);
}

Test(mpi, a_killed_process_ends_the_run_with_a_message_and_leaves_it_resumable, .timeout = 300)
{
  const char *m = mpi_bin(), *b = lw_test_bin();
  write_scene();
  cr_assert_eq(signal_rank_mid_run(m, "kill", "KILL", 1), 0, "the run hung after process 1 was killed");
  cr_assert_eq(sh("test $(cat %s/kill.rc) -ne 0 && test $(cat %s/kill.rc) -ne 124", dir, dir), 0,
               "a killed process must fail the run, not time out");
  cr_assert_eq(sh("grep -q 'rank 1 .*signal 9' %s/kill.err", dir), 0, "no message names the killed process");
  /* the last checkpoint is whole, and resumes on any process count */
  assert_state_is_the_run_at_its_sweep(b, "kill");
  cr_assert_eq(sh(MPIRUN " -n 2 %s resume %s/kill --quiet --sweeps 7", m, dir), 0);
  cr_assert_eq(sh("cd %s && %s resume kill-ref --quiet --sweeps 7 && "
                  "cmp -s kill/state.lw kill-ref/state.lw && cmp -s kill/trace.csv kill-ref/trace.csv", dir, b), 0);
}

/* An MPI run without --out takes a directory no other process is writing,
** as a one-process run does: process 0 chooses and locks it, and tells the
** others.  Before, every process looked only for a directory without a
** run, chose out/s while another process was setting up there, and then
** found it locked (exit 2).  Here the test holds out/s's lock. */
Test(mpi, a_run_without_out_skips_a_directory_another_process_writes)
{
  const char *m = mpi_bin();
  write_scene();
  char path[128];
  cr_assert_eq(sh("mkdir -p %s/out/s", dir), 0);
  snprintf(path, sizeof path, "%s/out/s/.lock", dir);
  int fd = open(path, O_RDONLY | O_CREAT, 0666);
  cr_assert(fd >= 0 && flock(fd, LOCK_EX | LOCK_NB) == 0);
  cr_assert_eq(sh("cd %s && " MPIRUN " -n 2 %s run s.ini --quiet --set anneal.sweeps=50", dir, m), 0);
  close(fd);
  cr_assert_eq(sh("test -s %s/out/s-2/summary.json && test ! -e %s/out/s/summary.json", dir, dir), 0);
}
