/*
** rundir.h -- one process at a time in a run directory.
**
** Two runs writing one directory at once (two runs started without --out
** that chose the same out/<name>, a sweep submitted twice, a resume while
** the run still goes) left a summary.json over another run's scene.ini, and
** trace files with holes.  A run, a resume and a redraw hold an exclusive
** flock(2) on DIR/.lock while they write; the kernel drops it when the
** process ends, however it ends, so a killed run leaves no stale lock.  On a
** file system without locks the run goes on unguarded, as before.
*/
#ifndef LINEWISE_RUNDIR_H
#define LINEWISE_RUNDIR_H

#include <stddef.h>

#include "linewise/error.h"
#include "linewise/params.h" /* LW_PATH_MAX */

#ifdef __cplusplus
extern "C" {
#endif

/* mkdir -p dir. */
lw_status lw_rundir_make(const char *dir, lw_error *err);

/* The first line of a run directory's scene.ini (its resolved parameters). */
#define LW_RUN_SCENE_HEADER "; resolved parameters of this run (linewise)"

/* Whether dir holds a run: a scene.ini a run wrote (its first line
** LW_RUN_SCENE_HEADER) or a state.lw (its first line a state's header).
** Only then may a run clear the directory's run files: a file of either
** name that a person put there keeps the directory theirs. */
int lw_rundir_holds_run(const char *dir);

/* Whether dir/name exists and is not a run's (a scene file a person wrote,
** any state.lw without a state's header): a run refuses to write there.
** -1 (errno set) where it is there but cannot be read (out of file
** handles, say): not a verdict on the file. */
int lw_rundir_foreign(const char *dir, const char *name);

/* Whether dir holds a run that stopped before its first checkpoint: a run's
** scene.ini, but no state.lw and nothing a finished run leaves (summary.json,
** the final drawings).  It has nothing to resume, and a new run may take
** the directory; a finished run whose state.lw was deleted is not one. */
int lw_rundir_unstarted(const char *dir);

/* LW_EINPUT with a message where this process may not write into dir or
** over a run's files there (read-only, another user's); LW_EUSAGE, said
** busy, where another process holds dir's lock besides; LW_OK otherwise,
** also where dir is not there yet. */
lw_status lw_rundir_writable(const char *dir, lw_error *err);

/* Takes the lock of the existing directory dir for this process: LW_OK and
** *hold set (0 where the file system has no locks), or LW_EUSAGE naming the
** directory when another process holds it.  The lock is on the file at
** dir/.lock when it is taken (one removed meanwhile by the run that held
** it is let go and the new one taken), so that a holder may remove it.  A second call for a directory
** this process holds succeeds; each needs its lw_rundir_unlock. */
lw_status lw_rundir_lock(const char *dir, int *hold, lw_error *err);

/* Whether dir/.lock is still the file lw_rundir_lock's hold locked (the
** directory was not moved aside, another made in its place). */
int lw_rundir_held_here(const char *dir, int hold);

/* Gives back one lw_rundir_lock (hold 0: nothing); the last of a directory
** releases its lock. */
void lw_rundir_unlock(int hold);

/* dir as one word of a shell command that a message tells the user to
** paste ('linewise resume DIR'): as it is where it has only letters,
** digits and _ . / : @ % + , = -, else in double quotes with \ " $ `
** escaped, or where it has a ! (which an interactive bash expands there)
** in single quotes with each ' as '\''; ./ before a relative path that
** begins with '-' (an option to the command otherwise).  In buf of n bytes
** (LW_RUNDIR_WORD_MAX holds any); returns buf. */
#define LW_RUNDIR_WORD_MAX (4 * LW_PATH_MAX + 8)
const char *lw_rundir_shell_word(const char *dir, char *buf, size_t n);

#ifdef __cplusplus
}
#endif

#endif
