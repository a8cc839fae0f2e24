/*
** checkpoint.h -- a run's checkpoint: everything in state.lw that steers
** the rest of a run (docs/FORMATS.md, "Run data"), written and read by
** name in the sections of ckpt.h.
**
** One checkpoint is one atomic step.  trace.csv is flushed and synced
** first and its length recorded; then state.lw, which holds every rung
** (the run loop, each chain, the exchange machinery, each rung's system),
** replaces the old one by a single rename.  A kill at any moment leaves
** the previous or the new state.lw, each with the trace length it belongs
** to (resume cuts trace.csv back to it).  The system's state goes through
** its row (system.h): each rung's [system <name>] section is the row's.  replica-K.lw files are copies
** for the user, written after state.lw; resume does not read them.
*/
#ifndef LINEWISE_CHECKPOINT_H
#define LINEWISE_CHECKPOINT_H

#include "linewise/anneal.h"
#include "linewise/ckpt.h"
#include "linewise/model.h"

/* The name of the system's section of rung k in state.lw: "system <name>"
** for the coldest rung, "system <name> K" for rung K. */
void lw_checkpoint_system_section(char *buf, size_t n, const lw_system_type *t, int k);

/* Writes the checkpoint of a (trace.csv synced, state.lw, replica-K.lw). */
lw_status lw_checkpoint_write(lw_anneal *a, lw_error *err);

/* Restores the run data of doc into a, whose systems and chains are built:
** every value checked (ranges, counts, the generator states, the running
** energies against a recomputation).  *trace_bytes is the length of
** trace.csv at the checkpoint, or -1 if the file does not say (format 1). */
lw_status lw_checkpoint_restore(lw_anneal *a, lw_ckpt *doc, long *trace_bytes, lw_error *err);

/* The spline system's: LW_EINPUT if an energy of a state read from path is not finite (a node
** outside the boundary, coordinates too large): the message names the term,
** and the spline and segment where one alone is not finite.  term[] holds
** the state's energies by term. */
lw_status lw_checkpoint_check_finite(const lw_scene *sc, const lw_splines *sp, const double term[LW_TERM_COUNT],
                                     const char *path, lw_error *err);

/* Rewrites the [v1] section of a format-1 state (rung 0) and the [v1]
** sections of its replica files (rungs 1..n-1, NULL without tempering) as
** the keys of format 2, so one reader serves both. */
lw_status lw_checkpoint_upgrade_v1(lw_ckpt *doc, lw_ckpt *const *replicas, int n_rep, lw_error *err);

#endif
