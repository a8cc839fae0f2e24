/*
** phase.h -- what the program is doing outside the sweeps, for a progress
** display on another thread.
**
** Set-up (a picture, a million splines placed and sampled) and output
** (state.lw, path ordering, the drawings) can take many seconds on a large
** scene, with no sweep to show progress.  The run loop names each such phase
** as it starts; the command line's watcher thread (main.c) reads the name
** and how long it has lasted, and reports a phase that lasts over a second.
** One phase at a time per process: the value is process-wide, written by
** the thread that runs the set-up or output (never by the replicas'
** threads), read by any.
*/
#ifndef LINEWISE_PHASE_H
#define LINEWISE_PHASE_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Names the phase starting now (a static string), or ends it (NULL). */
void lw_phase_set(const char *what);

/* The current phase (NULL: none) and, in *seconds, how long it has lasted. */
const char *lw_phase_get(double *seconds);

/* Seconds on the monotonic clock (the phases' clock, and the runs' wall
** time): differences only. */
double lw_phase_clock(void);

/* Whether the run has written nothing yet, so that a signal may end it at
** once, even in a set-up of minutes, and lose nothing (main.c): the command
** line sets it (lw_phase_hold) before it starts or resumes a run, and the
** run clears it (lw_phase_writing) before its first write, the run
** directory or a resumed trace cut back.  Lock-free: a signal handler reads
** lw_phase_unwritten. */
void lw_phase_hold(void);
void lw_phase_writing(void);
int lw_phase_unwritten(void);

/* Whether the run before waits in DIR/.replaced (runfiles.h), for a signal
** handler's message: 0 no, 1 it does until the new run's first checkpoint
** (a stop puts it back), 2 that checkpoint is being committed, 3 it is
** committed and the run before waits for the first sweep (a stop still
** puts it back; a kill keeps the checkpoint), 4 the run before is being put
** back.  Lock-free too. */
void lw_phase_stash(int on);
int lw_phase_stashed(void);

/* Whether a signal has asked the run to stop (the command line's handler
** calls lw_phase_stop; a program's Cancel may too).  A new run asked during
** its set-up, while the run before waits aside, puts that run back rather
** than take its place with a run of no sweeps (lw_anneal_start, anneal.h).
** Asked once, it stays so until lw_phase_stop_clear: a program that runs
** again after a stop clears it first (its every later start into a run's
** directory gave way).  Lock-free. */
void lw_phase_stop(void);
void lw_phase_stop_clear(void);
int lw_phase_stopping(void);

/* The sweep of the last state.lw this process committed (-1: none yet),
** set as its rename ends, so that a second signal, which ends the process
** at once, names the checkpoint a resume takes up (it named the one before
** while the replicas' files of the new one were written).  Around the
** rename itself (lw_phase_committing) either may be on disk: *pending (not
** NULL) is then that sweep, else -1.  Lock-free. */
void lw_phase_committing(long sweep);
void lw_phase_committed(long sweep);
long lw_phase_last_commit(long *pending);

/* What a watcher prints, decided from what it reads at each tick, so that
** the rule can be tested with a made-up clock.  A phase is named once it has
** lasted over LW_PHASE_QUIET seconds: on a terminal (tty) in place, its
** seconds counting up every second; in a log, one line.  When it ends (or
** another starts) a line gives its time.  Shorter phases print nothing. */
#define LW_PHASE_QUIET 1.0 /* s: the longest a phase may run unannounced */

typedef struct {
  int tty;            /* 1: rewrite one terminal line; 0: whole lines for a log */
  const char *shown;  /* the phase being shown, NULL: none */
  double last;        /* s: how long it had lasted at the last tick */
  double reported;    /* s: its time when last printed */
} lw_phase_watch;

/* One look at the phase: `what` (NULL: none) has lasted `seconds`.  Writes
** the text to print into buf[n] ("" for nothing) and returns buf. */
const char *lw_phase_watch_tick(lw_phase_watch *w, const char *what, double seconds, char *buf, size_t n);

/* How the phase still shown when the watcher stops ended. */
enum { LW_PHASE_DONE, LW_PHASE_FAILED, LW_PHASE_STOPPED };

/* The watcher stops: the end of a phase still shown ("done in", "failed
** after" if the run ended in an error, "stopped after" by a signal: how =
** LW_PHASE_*), into buf[n] ("" for nothing); returns buf. */
const char *lw_phase_watch_end(lw_phase_watch *w, int how, char *buf, size_t n);

#ifdef __cplusplus
}
#endif

#endif
