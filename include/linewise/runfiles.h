/*
** runfiles.h -- the files a run writes into its directory, and the run
** before set aside while a new one starts there.
**
** A run's files: scene.ini, state.lw, trace.csv, summary.json, timing.txt,
** ladder.ini, field.png, the final drawings (svg, png, pdf, hpgl, gcode,
** ply), animation.mp4, replica-K.lw, frames/frame-N.png,
** samples/sample-N.csv and the plots of tools/plot-run (plots/NAME.png).
** Other files in the directory or its subdirectories are the user's.
**
** A run made again in a directory that holds a run replaces it, but only
** once it has done its first sweep (its first checkpoint under MPI): until
** then the run before waits in DIR/.replaced, moved there by renames (which
** take no room on a full disk), and it comes back if the set-up or that
** sweep fails (lw_anneal_undo_start).  A process killed in between leaves
** the stash; the next run or resume there settles it under the directory's
** lock (lw_runfiles_recover): back before the new run's first checkpoint,
** gone after it.  A marker inside says what
** the stash holds: .moving while the run before is being moved (some of its
** files may still be in DIR), .moved once all are (every run file in DIR is
** the new run's), .restoring while it moves back (a run file in DIR with a
** counterpart in the stash is the new run's, one without the run before's).
** The marker goes last, so a kill leaves a stash that says what it is, or an
** empty DIR/.replaced, which is removed.  A DIR/.replaced that is not empty
** and has no marker is not linewise's, and is never written into or read
** from.
*/
#ifndef LINEWISE_RUNFILES_H
#define LINEWISE_RUNFILES_H

#include "linewise/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_RUNFILES_STASH ".replaced"

/* LW_EUSAGE naming the file where dir holds run files but no run (no run's
** scene.ini or state.lw, no stash): a person's, or what is left of a run
** whose scene.ini and state.lw were taken away; not to be written over (a
** write's x.tmp alone does not count: it is what a kill leaves).  LW_EINPUT
** where dir's frames, samples or plots is a symbolic link. */
lw_status lw_runfiles_check_free(const char *dir, lw_error *err);

/* LW_EINPUT where dir's frames/, samples/ or plots/ is a symbolic link: a
** run writes only into its own directory. */
lw_status lw_runfiles_check_links(const char *dir, lw_error *err);

/* LW_EUSAGE where dir/.replaced is there and is not linewise's stash (a
** link, a file, a folder of the user's), which a run there would refuse. */
lw_status lw_runfiles_check_stash(const char *dir, lw_error *err);

/* Whether dir/.replaced is there, whatever it is. */
int lw_runfiles_stashed(const char *dir);

/* Sets the run in dir aside into dir/.replaced.  On failure what was moved
** comes back (err says whether all did). */
lw_status lw_runfiles_stash(const char *dir, lw_error *err);

/* The run before back from dir/.replaced over the files of the run that was
** to replace it (whose files without a counterpart go).  On failure what
** is left stays in the stash, and err names it. */
lw_status lw_runfiles_unstash(const char *dir, lw_error *err);

/* Removes the stash: the new run stands (its first sweep is done).  LW_EIO where a
** file of it cannot be removed (the stash stays, saying what it holds). */
lw_status lw_runfiles_drop(const char *dir, lw_error *err);

/* Whether the name of an entry of a run directory is one of the run's own
** files there ("state.lw", "replica-3.lw"), or a write of one under way or
** cut off ("state.lw.tmp"). */
int lw_runfiles_is_top(const char *name);

/* Whether a path relative to a run directory names one of the run's files
** there (lw_runfiles_is_top, "frames/frame-00012.png", "plots/energy.png")
** or anything in the stash: what a run made there removes or writes over. */
int lw_runfiles_is_run_file(const char *rel);

/* Removes dir's run files: a set-up that failed where no run was before. */
void lw_runfiles_remove(const char *dir);

/* Settles a stash a killed process left, under dir's lock: dropped where
** the new run had written its state.lw, else put back (*back 1).  LW_EUSAGE
** where dir/.replaced is not linewise's stash (a link, a file, a folder of
** the user's): nothing is touched. */
lw_status lw_runfiles_recover(const char *dir, int *back, lw_error *err);

/* Removes dir's frames and samples of sweeps past `after` that lie off the
** grid of frames_every and samples_every (0: no grid) and are not of the
** run's end `end`: a killed run's, resumed under another interval, which
** the resumed run never writes over.  Best effort: a file that stays is
** an extra picture, not a wrong one. */
void lw_runfiles_drop_off_grid(const char *dir, long after, long end, long frames_every, long samples_every);

/* The size of dir/frames' newest frame of a sweep at most at_most: 1 with
** *sweep, *w and *h set, 0 where there is none or it cannot be read. */
int lw_runfiles_frame_size(const char *dir, long at_most, long *sweep, unsigned *w, unsigned *h);

#ifdef __cplusplus
}
#endif

#endif
