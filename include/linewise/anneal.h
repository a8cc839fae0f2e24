/*
** anneal.h -- a whole annealing run: initial state, the temperature steps of
** a schedule with a tuning phase at the start of each, drift checks,
** checkpoints and the files of a run directory.  init / sweep / finish, no
** callbacks: the caller owns the loop (and the progress display).
**
** The run sees its system ([scene] system, system.h) only through the
** system's row.  Run directory: scene.ini (the resolved parameters),
** state.lw, trace.csv, summary.json, the system's drawings (for splines
** final.svg, final.png and as asked final.pdf and frames/, drawing.h); with
** parallel tempering also
** replica-K.lw, a copy of the replica at rung K >= 1 (state.lw holds every
** rung and the data of every rung's chain; checkpoint.h), and ladder.ini after ladder
** tuning.  The rungs sweep in parallel (OpenMP), each with its own stream;
** exchanges are drawn serially from a master stream, so the result does not
** depend on the number of threads.  The state file carries everything
** that steers the future of the run (RNG state, steps, tuning windows, the
** schedule's inputs, the running energies), so `resume` continues bit for
** bit: the same sweeps give the same state.lw whether or not the run was
** stopped in between.
*/
#ifndef LINEWISE_ANNEAL_H
#define LINEWISE_ANNEAL_H

#include <stdio.h>

#include "linewise/anneal_net.h"
#include "linewise/dynamics.h"
#include "linewise/mc.h"
#include "linewise/params.h"
#include "linewise/quench.h"
#include "linewise/schedule.h"
#include "linewise/system.h"
#include "linewise/tempering.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lw_anneal {
  lw_params params;
  const lw_system_type *sys_type; /* [scene] system */
  void *setup;                 /* its set-up of the scene, shared by the replicas (owned) */
  lw_system *sys;              /* the replica at the coldest rung (= chains[0]->sys) */
  lw_chain *chain;             /* the coldest rung's chain (= chains[0]) */
  int n_rep;                   /* replicas: 1, or the rungs of parallel tempering */
  lw_system **systems;         /* by replica (owned) */
  lw_chain **chains;           /* by rung (owned): each has its stream, steps, statistics */
  lw_tempering *pt;            /* NULL without tempering */
  lw_dynamics *dyn;            /* [scene] driver = dynamics: moves the system instead of the chain; else NULL */
  double t_sched;              /* the schedule's temperature of this step */
  unsigned long swap_mark[2 * LW_TEMPERING_MAX]; /* tried, accepted per pair at the last trace row */
  const lw_schedule_type *sched_type;
  lw_schedule sched;
  char dir[LW_PATH_MAX];
  int dir_hold;                 /* lw_rundir_lock's hold on dir while it writes there, 0 none */
  unsigned long long dir_id[2]; /* dir's device and inode where the run began here (0 0: not taken) */
  int dir_moved;                /* dir was no longer that directory at a write: the run ended there */
  int unsummed;                 /* a run begun before 2026-12-07 (acc_unshifted): its state files end with
                                ** no checksum */
  char unread[1024];           /* keys the scene sets that only other drivers read, where set, or "" */
  char idle[4096];             /* keys the scene sets that its other settings leave idle, where and why */
  char schedule_note[2048];     /* a schedule whose steps never reach its end (lw_anneal_start), or "" */
  char memory_note[768];       /* a run expected to take more memory at its peak than it may, or "" */
  struct {                     /* what memory_note is made of (anneal.c) */
    double peak, replica, limit; /* the drawing's peak, a further replica's bytes, the limit */
    int here;                  /* replicas in this process */
    const char *by;            /* what sets the limit */
    char what[160];            /* the start's size */
  } mem;
  unsigned long seed;
  long sweep;                  /* sweeps done */
  long saved;                  /* sweep + 1 at the last checkpoint this process wrote; 0 none */
  long end_sweep;              /* stop after this sweep */
  long pause_at;               /* resume --sweeps N short of end_sweep: stop there as --stop-at does (-1: none) */
  int extending, new_end;      /* a resume to settle before its first sweep (anneal.c) */
  struct {                     /* the newest frame a resume found (lw_anneal_frames_note) */
    int have;
    long sweep;
    unsigned w, h;
  } frame_before;
  int fresh;                   /* the set-up has written files and no checkpoint yet */
  int stashed;                 /* the run it replaces is set aside until its first sweep (runfiles.h) */
  int ladder_from_file;        /* tempering.ladder was read from tempering.ladder_file (for messages) */
  int put_back;                /* a set-up that failed put the run it was to replace back */
  int undone;                  /* ... or, where no run was, removed its own first files (its checkpoint too) */
  int gave_way;                /* the set-up failed as a stop was asked (lw_phase_stopping) */
  char stash_left[LW_ERROR_MSG]; /* why the run replaced stayed in DIR/.replaced ("": it went) */
  unsigned long long scene_hash; /* lw_params_run_hash of scene.ini, kept in state.lw */
  lw_run_keys scene_keys;        /* and its keys' parts */
  long block;                  /* current temperature step */
  double t_prev;               /* temperature of the previous step */
  lw_block_stats prev;         /* energy statistics of the previous step */
  double acc_n, acc_sum, acc_sumsq; /* this step's energy samples (after tuning), less acc_shift */
  double acc_shift;            /* the step's first sample: summed whole, the energies' squares lost the
                               ** spread to rounding (the wire at T = 1e-7 read a negative variance) */
  int acc_unshifted;           /* a run begun before 2026-12-07 sums them whole, acc_shift 0 (state.lw
                               ** has no block_shift) */
  double max_drift;            /* largest relative drift seen at a check */
  char observables_rounded[256]; /* summary.json's observables of values printed to 10 digits that
                                 ** spread under 3 steps of the last (a resumed run of before 2026-12-07) */
  char observables_lost[512];  /* why summary.json's observables are null where rows were
                               ** there to sum (out of memory reading the trace), or "" */
  double row_drift;            /* the same over the largest size since the check before, by
                               ** this process (lw_anneal_drift_note; not kept in state.lw) */
  double size_peak[LW_TEMPERING_MAX]; /* by replica: the largest sum of the terms' magnitudes
                               ** at a sweep's end since its last recomputation (0: not yet
                               ** taken, the first sweep takes it; kept in state.lw) */
  double energy_initial;
  double wall_before;          /* seconds spent before a resume */
  double sweep_seconds;        /* seconds in sweeps, with the processes before (timing.txt) */
  double wall_start;           /* monotonic clock at start of this process */
  double ckpt_seconds;         /* of it, writing checkpoints (lw_anneal_checkpoint_note) */
  double ckpt_longest;         /* the longest of those writes, and how many there were: a */
  int ckpt_count;              /* process suspended during one is not a checkpoint's cost */
  double film_seconds[2];      /* of it, writing frames and samples (lw_anneal_film_note) */
  unsigned long untimed;       /* proposals of sweeps no timing.txt timed (a resume without
                               ** one), which proposals_per_second leaves out */
  int untimed_said;            /* this resume found no timing.txt to go on from (1), or one with the wall
                               ** time alone (2, before 2026-12-04): said by resume */
  lw_move_stats trace_mark[LW_MOVES_MAX]; /* stats at the last trace row */
  int quenched;                /* 1 once lw_anneal_finish has quenched (anneal.quench) */
  int finished;                /* 1 once lw_anneal_finish was called: sweeps, checkpoints and a
                               ** second finish are refused (the state may be quenched) */
  int totals_fresh;            /* the running energies are the set-up's, recomputed, and no
                               ** sweep since (a drift check may keep the running ones) */
  lw_quench_report quench;     /* what the quench did */
  const volatile sig_atomic_t *stop; /* not NULL: set (by a signal) stops a quench under way,
                               ** and lw_anneal_finish then draws nothing (not owned) */
  volatile sig_atomic_t *drawing; /* not NULL: set to 1 while the final files are written
                                      (lw_anneal_finish), for a signal handler to say so */
  FILE *trace;                 /* NULL on the processes other than the first (anneal_net.h) */
  lw_anneal_net *net;          /* NULL in one process; else the hooks of a spread run (not owned) */
} lw_anneal;

/* A new run of the scene file (with overrides already applied to p; a
** seed of its own by lw_params_set(p, "anneal.seed=N")) into dir.  Creates
** dir (bad input is reported before anything is written).  The directory's
** lock keeps other processes out, not this one: a program must not run two
** anneals into one directory at once (the second would replace the first's
** files); runs into other directories may go on in threads of their own,
** up to 64 open at once in one process (LW_ERUN past that).
** The threads a run uses are OpenMP's (omp_set_num_threads, OMP_NUM_THREADS),
** and its results do not depend on their count (a run of several rungs split
** into domains, on more threads than rungs, nests its parallel regions: it
** raises omp_get_max_active_levels to 2 and leaves it so).  LC_NUMERIC must
** read '.' (lw_number_locale_ok), here and at every sweep, checkpoint and
** the finish.  On failure dir and its .lock may stay: a caller that made dir
** removes it (the command line does).  A stop asked (lw_phase_stop) while
** the run before waits aside ends the set-up with LW_ERUN and gave_way set:
** the caller's lw_anneal_undo_start puts that run back. */
lw_status lw_anneal_start(lw_anneal *a, const lw_params *p, const char *dir, lw_error *err);

/* The same for one process of a run spread by net (anneal_net.h; NULL:
** lw_anneal_start): process 0 writes the run's files, and the first
** checkpoint is left to the caller, who agrees on the start first. */
lw_status lw_anneal_start_net(lw_anneal *a, const lw_params *p, const char *dir, lw_anneal_net *net, lw_error *err);

/* Continues the run in dir for `more` sweeps (< 0: to the end of the
** schedule; past the end the last temperature holds). */
lw_status lw_anneal_resume(lw_anneal *a, const char *dir, long more, lw_error *err);
lw_status lw_anneal_resume_net(lw_anneal *a, const char *dir, long more, lw_anneal_net *net, lw_error *err);

/* What a resume writes once it is to go on: a new end (--sweeps) into
** state.lw, and a finished run's summary.json removed.  Nothing before, so
** that a caller may still refuse to go on; the first sweep or checkpoint
** does it where the caller did not. */
lw_status lw_anneal_settle(lw_anneal *a, lw_error *err);

/* One sweep with everything that falls due after it (trace row, drift check,
** checkpoint).  A run's first sweep drops the run it replaced (set aside in
** DIR/.replaced), but for a stop asked meanwhile (lw_phase_stop): then the
** caller may still give way with lw_anneal_undo_start. */
lw_status lw_anneal_sweep(lw_anneal *a, lw_error *err);

static inline int lw_anneal_done(const lw_anneal *a) { return a->sweep >= a->end_sweep; }

/* Whether a resume for `more` sweeps short of the end has made them: the
** caller stops there as at --stop-at, with lw_anneal_checkpoint and no
** lw_anneal_finish (a later resume goes on to the end).  The loop of a run
** or resume is therefore
**     while (!lw_anneal_done(a) && !lw_anneal_paused(a)) lw_anneal_sweep(a, err);
**     then lw_anneal_finish(a, err) if lw_anneal_done(a), else lw_anneal_checkpoint(a, err)
** (tests/embed.cpp). */
static inline int lw_anneal_paused(const lw_anneal *a) { return a->pause_at >= 0 && a->sweep >= a->pause_at; }

/* After a start that failed, here or later (the network's first checkpoint),
** or a run that failed before its first sweep was done (lw_anneal_sweep)
** or its end (lw_anneal_finish): the set-up's files go and the run it was
** to replace comes back; 1 if that run all came back.  Nothing once the first
** checkpoint is written where no run was set aside, nor once the run set
** aside has gone (the first sweep, a later checkpoint, the end; under MPI
** the first checkpoint). */
int lw_anneal_undo_start(lw_anneal *a);

/* LW_EIO with a message once a->dir names another directory than the one
** the run began in (moved aside, another made in its place) or none: its
** files are written by path, and went into the other. */
lw_status lw_anneal_dir_ours(const lw_anneal *a, lw_error *err);

/* Writes state.lw now (a clean stop). */
lw_status lw_anneal_checkpoint(lw_anneal *a, lw_error *err);

/* The final files: state.lw, then (anneal.quench = bfgs) the quench of the
** coldest replica (quench.h), the system's drawings and summary.json of
** the quenched state.  state.lw keeps the annealed state: the quench is a
** function of it, so a resumed run quenches to the same bytes, and a run
** resumed for more sweeps continues the chain as an uninterrupted longer
** run would.  Once it has written that state.lw, whatever it returns, only
** lw_anneal_free: the quench left the coldest replica quenched, and a
** checkpoint then would save that state; lw_anneal_sweep,
** lw_anneal_checkpoint and lw_anneal_finish refuse (LW_EUSAGE).  A finish
** that failed before (the checkpoint's write) may be called again.  A start needs a zeroed or freed lw_anneal (a second
** start over a running one leaks it and keeps its directory locked). */
lw_status lw_anneal_finish(lw_anneal *a, lw_error *err);

void lw_anneal_free(lw_anneal *a);

/* Which scenes read key d, for messages and docs/PARAMETERS.md: "all",
** "splines", "all under dynamics", "splines, nurbs under metropolis; all
** under dynamics". */
void lw_anneal_key_readers(const lw_param_def *d, char *buf, size_t n);

/* The words text key d takes where they are a fixed list, '|'- or ", "-separated (the
** systems', drivers' and schedules' names from their tables; domains' forms), or NULL. */
const char *lw_anneal_key_values(const lw_param_def *d);

/* LW_EINPUT, naming where it was set and who reads it, when p gives a key
** (lw_params_given) that its system reads under no driver (driver.h): it
** would change nothing, and a study that varied it would measure noise.
** Keys only other drivers read are listed in unread (size bytes, may be 0):
** one scene file may serve every driver of its system.  lw_anneal_start
** calls it. */
lw_status lw_anneal_check_keys(const lw_params *p, char *unread, size_t size, lw_error *err);


/* Current temperature, energy and overall acceptance (for progress displays):
** the temperature NAN before a new run's first sweep sets it (and under
** dynamics), the acceptance NAN before any proposal. */
double lw_anneal_temperature(const lw_anneal *a);
double lw_anneal_energy(const lw_anneal *a);
double lw_anneal_acceptance(const lw_anneal *a);

/* A note, or "", where a constant-temperature run's tuning was too short
** for its system: a move kind accepted under a quarter of its target over
** the run, from the process that holds the coldest rung. */
void lw_anneal_tuning_note(const lw_anneal *a, char *buf, size_t n);

/* A note (else "") when, after tune_ladder = equal, the swap rates since
** the ladder froze (each pair tried 1000 times or more) spread more than
** 0.06 rms about their mean: a ladder_sweeps too short to equalise them. */
void lw_anneal_ladder_note(const lw_anneal *a, char *buf, size_t n);

/* A note (else "") when this process spent over a third of its time, and
** over a second, writing checkpoints: fsync'd state of a small system
** every output.checkpoint_every sweeps made a 1-second study take 8. */
void lw_anneal_checkpoint_note(const lw_anneal *a, char *buf, size_t n);
/* A note (else "") when the frames a resumed run drew differ in size from
** those before it (a drawing key edited in scene.ini): the film mixes them. */
void lw_anneal_frames_note(const lw_anneal *a, char *buf, size_t n);
/* The same for frames and samples (output.frames_every, samples_every):
** a frame a sweep of a small scene made a 0.3-second run take 2 minutes. */
void lw_anneal_film_note(const lw_anneal *a, char *buf, size_t n);
/* A note (else "") where the frames still to come at the size of the
** newest take more than the disk has free (warning = 1), or over 1 GB:
** 10,000 frames of a page at png_scale 40 (3.5 GB) began unsaid. */
void lw_anneal_frames_disk_note(const lw_anneal *a, char *buf, size_t n, int *warning);
/* A note (else "") when a recomputation from scratch moved the running
** energy by more than LW_ANNEAL_DRIFT_NOTE of its size (row_drift): a
** system row whose commits do not add up its moves' dE (system.h); the
** shipped rows drift by about 1e-14. */
#define LW_ANNEAL_DRIFT_NOTE 1e-6
void lw_anneal_drift_note(const lw_anneal *a, char *buf, size_t n);
/* Into buf, "" or what a user is told where summary.json's observables are
** null for want of memory (or a trace that could not be read): a study's
** statistics were gone from a run that ended with exit 0 and nothing said. */
void lw_anneal_observables_note(const lw_anneal *a, char *buf, size_t n);
double lw_anneal_seconds(const lw_anneal *a);

#ifdef __cplusplus
}
#endif

#endif
