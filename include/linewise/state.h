/*
** state.h -- the state file state.lw: a text file that holds the splines
** and everything needed to rebuild a run (format in docs/FORMATS.md).
**
** Numbers are written with 17 significant digits, which read back to the
** same doubles, so a state survives a write/read cycle bit for bit.  Files
** are written to a temporary name in the same directory and renamed, so a
** reader never sees half a file and an old state is only replaced by a
** complete new one.
*/
#ifndef LINEWISE_STATE_H
#define LINEWISE_STATE_H

#include "linewise/error.h"
#include "linewise/params.h"
#include "linewise/spline.h"

#define LW_STATE_VERSION 1

/* A "key value..." line of run data between the header and the splines
** (RNG state, step sizes, counters): state.c keeps them as text, the
** annealer gives them meaning. */
typedef struct {
  char *key, *value;        /* owned */
  int line;                 /* where it was read (0 if made in memory) */
} lw_state_extra;

typedef struct {
  char scene[LW_PATH_MAX];  /* scene file, relative to the state file's directory */
  unsigned long seed;
  long sweep;               /* sweeps done */
  lw_splines *sp;           /* owned */
  lw_state_extra *extra;    /* owned */
  size_t n_extra;
} lw_state;

/* Appends a key/value line (both copied); LW_ENOMEM on failure. */
lw_status lw_state_add(lw_state *st, const char *key, const char *value);
/* The extra line with this key, or NULL. */
const lw_state_extra *lw_state_get(const lw_state *st, const char *key);

/* Reads path into st (st->sp allocated); messages name the file and line. */
lw_status lw_state_read(lw_state *st, const char *path, lw_error *err);

/* Writes st atomically (temporary file, then rename). */
lw_status lw_state_write(const lw_state *st, const char *path, lw_error *err);

void lw_state_clear(lw_state *st);

/* dir + "/" + name into buf (name unchanged if absolute). */
void lw_path_join(char *buf, size_t n, const char *dir, const char *name);

/* The directory part of path ("." if none) into buf. */
void lw_path_dir(char *buf, size_t n, const char *path);

#endif
