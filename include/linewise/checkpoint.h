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
** for the user, written after state.lw (before it, by their
** processes, in a run over MPI: mpi_tempering.h); resume does not read them.
*/
#ifndef LINEWISE_CHECKPOINT_H
#define LINEWISE_CHECKPOINT_H

#include "linewise/anneal.h"
#include "linewise/ckpt.h"
#include "linewise/model.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The name of the system's section of rung k in state.lw: "system <name>"
** for the coldest rung, "system <name> K" for rung K. */
void lw_checkpoint_system_section(char *buf, size_t n, const lw_system_type *t, int k);

/* LW_EINPUT naming the first section of doc that a state of the scene's
** system is not written with: [run], [tempering], [dynamics], [chain K] and
** [system NAME K] (K below the file's count of chains), for a reader of the
** curves alone (linewise energy), which refuses what it does not read. */
lw_status lw_checkpoint_sections_known(const lw_ckpt *doc, const char *system, lw_error *err);

/* Writes the checkpoint of a (trace.csv synced, state.lw, replica-K.lw). */
lw_status lw_checkpoint_write(lw_anneal *a, lw_error *err);

/* The parts of the checkpoint, for a writer that assembles state.lw from
** several processes (mpi_tempering.c) in the same order as
** lw_checkpoint_write: [run] (with the header), [chain K] for every rung,
** the ensemble ([tempering], [dynamics]), [system <name> K] for every rung.
** sync_trace flushes and syncs trace.csv (if this process has it open) and
** gives its length; the writers set *bad when out of memory. */
lw_status lw_checkpoint_sync_trace(lw_anneal *a, long *bytes, lw_error *err);
void lw_checkpoint_put_run(lw_ckpt_writer *w, const lw_anneal *a, long trace_bytes);
void lw_checkpoint_put_chain(lw_ckpt_writer *w, const lw_anneal *a, int k, int *bad);
void lw_checkpoint_put_ensemble(lw_ckpt_writer *w, const lw_anneal *a, int *bad);
lw_status lw_checkpoint_put_system(lw_ckpt_writer *w, const lw_anneal *a, int k, lw_error *err);
/* Commits state.lw (lw_ckpt_commit), marked for a second signal's message
** as under way and then done (phase.h). */
lw_status lw_checkpoint_commit(lw_ckpt_writer *w, const lw_anneal *a, lw_error *err);
lw_status lw_checkpoint_write_replica(const lw_anneal *a, int k, lw_error *err);
/* timing.txt: the wall time so far (not part of the state: it differs run to run). */
lw_status lw_checkpoint_write_timing(const lw_anneal *a, lw_error *err);

/* Restores the run data of doc into a, whose systems and chains are built:
** every value checked (ranges, counts, the generator states, the running
** energies against a recomputation).  *trace_bytes is the length of
** trace.csv at the checkpoint, or -1 if the file does not say (format 1). */
/* *scene_hash and keys: lw_params_run_hash of p, the run's scene.ini (to
** be kept in state.lw from now on); LW_EINPUT if state.lw's [run]
** scene_hash (absent in older files) is another, naming the keys that
** differ where state.lw lists its keys' parts (scene_keys).  Checked before
** the state is rebuilt, whose energies an edited coefficient would change
** (a message blaming state.lw for what an edit of scene.ini did). */
lw_status lw_checkpoint_scene_hash(lw_ckpt *doc, const lw_params *p, lw_run_keys *keys,
                                   unsigned long long *scene_hash, lw_error *err);

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

#ifdef __cplusplus
}
#endif

#endif
