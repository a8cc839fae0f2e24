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

/* Names the phase starting now (a static string), or ends it (NULL). */
void lw_phase_set(const char *what);

/* The current phase (NULL: none) and, in *seconds, how long it has lasted. */
const char *lw_phase_get(double *seconds);

#endif
