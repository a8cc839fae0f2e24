/*
** state.h -- the state file state.lw: the splines of a run and everything
** needed to continue it (format in docs/FORMATS.md).
**
** Format 2 is a file of named sections and keys (ckpt.h): [run] holds the
** header data (scene, seed, sweep) and the run loop's data, [system
** splines] the splines (of the coldest rung; [system splines K] those of
** rung K with parallel tempering).  Format 1, the positional format of the
** first release, still reads: its run-data lines come back as the keys of
** a section [v1] for the run loop to upgrade (checkpoint.c).
**
** Numbers are written with 17 significant digits, which read back to the
** same doubles, so a state survives a write/read cycle bit for bit.  Files
** are written to a temporary name in the same directory and renamed.
*/
#ifndef LINEWISE_STATE_H
#define LINEWISE_STATE_H

#include "linewise/ckpt.h"
#include "linewise/error.h"
#include "linewise/params.h"
#include "linewise/spline.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_STATE_VERSION 2
#define LW_STATE_MAGIC "linewise-state " /* and the version */
#define LW_STATE_HEADER "linewise-state 2"

/* Node coordinates (mm) beyond this are refused: the largest page is 1e7
** mm, and squares of coordinates much larger overflow the energies. */
#define LW_STATE_COORD_MAX 1e9
/* The largest sweep count a state may hold (exact in a double). */
#define LW_STATE_SWEEP_MAX 1e15

typedef struct {
  char scene[LW_PATH_MAX];  /* scene file, relative to the state file's directory */
  unsigned long seed;
  long sweep;               /* sweeps done */
  int version;              /* the format read: 1 or 2 */
  lw_splines *sp;           /* owned: the splines ([system splines]); NULL if none */
  lw_ckpt *doc;             /* owned: the whole file, for the run data; NULL if made in memory */
} lw_state;

/* Reads path into st; messages name the file, line, section and key. */
lw_status lw_state_read(lw_state *st, const char *path, lw_error *err);

/* Whether the scene st (read from path) names is a file beside it, as a
** reader of the run directory (energy) needs: a path elsewhere ("/etc/x",
** "../o/scene.ini") had any file read and parsed.  A start state
** (init.from) never reads its scene. */
lw_status lw_state_scene_beside(const lw_state *st, const char *path, lw_error *err);

/* Writes a plain state (scene, seed, sweep, splines) atomically. */
lw_status lw_state_write(const lw_state *st, const char *path, lw_error *err);

void lw_state_clear(lw_state *st);

/* The [run] header keys of a state (scene, seed, sweep). */
void lw_state_put_header(lw_ckpt_writer *w, const lw_state *st);

/* A system's own section: the splines, written to and read from `section`
** of a file (the splines system's save and load). */
void lw_state_put_splines(lw_ckpt_writer *w, const char *section, const lw_splines *sp);
lw_status lw_state_get_splines(lw_ckpt *c, const char *section, lw_splines **out, lw_error *err);

/* "path: section [section]: missing" for a state without a system's section:
** a state of another system, or one cut short (lw_ckpt_missing). */
lw_status lw_state_missing_section(const lw_ckpt *c, const char *section, lw_error *err);

/* dir + "/" + name into buf (name unchanged if absolute). */
void lw_path_join(char *buf, size_t n, const char *dir, const char *name);

/* The directory part of path ("." if none) into buf. */
void lw_path_dir(char *buf, size_t n, const char *path);

#ifdef __cplusplus
}
#endif

#endif
