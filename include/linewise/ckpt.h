/*
** ckpt.h -- files of named sections and keys: the format of state.lw and of
** every checkpoint (docs/FORMATS.md).
**
**     linewise-state 2            header line (the caller checks it)
**     [run]                       a section: a name, words separated by blanks
**     sweep = 1000                key = value; keys are unique in a section
**     [system splines]
**     spline = 3 30               bulk data may repeat a key, read in order
**
** Blank lines and lines starting with '#' are ignored.  A reader takes what
** it knows by section and key; a key it does not ask for is an error only
** when it calls lw_ckpt_unread at the end (so a newer writer's data is
** refused instead of dropped), and a missing optional key keeps the
** caller's default (so an older writer's file still reads).  A system writes
** and reads its own section without knowing the rest of the file.
**
** Every getter checks its value (strict numbers, number.h; ranges; counts)
** and names the file, line, section and key when it refuses one.
*/
#ifndef LINEWISE_CKPT_H
#define LINEWISE_CKPT_H

#include <stddef.h>
#include <stdio.h>

#include "linewise/error.h"
#include "linewise/params.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- reading ------------------------------------------------------------ */

typedef struct lw_ckpt lw_ckpt;

/* Reads path: the first line that is not blank or a comment is the header
** (lw_ckpt_header), then sections.  Refuses NUL bytes, keys outside a
** section, lines that are neither, repeated sections and repeated keys
** (other than bulk keys, see lw_ckpt_next). */
lw_status lw_ckpt_read(lw_ckpt **out, const char *path, lw_error *err);

/* An empty document (to build one in memory, as a reader of an older
** format does); path names it in messages. */
lw_ckpt *lw_ckpt_new(const char *path);
void lw_ckpt_free(lw_ckpt *c);

const char *lw_ckpt_path(const lw_ckpt *c);
const char *lw_ckpt_header(const lw_ckpt *c);

/* Appends key = value to section (created at the end if new), as read from
** line (0: made in memory); LW_ENOMEM. */
lw_status lw_ckpt_add(lw_ckpt *c, const char *section, const char *key, const char *value, int line);

/* 1 if the section exists (and marks it read). */
int lw_ckpt_has(lw_ckpt *c, const char *section);

/* "path: what: missing" and why: `guess`, or a file cut short at the end of
** a line (lw_ckpt_read refuses one cut inside a line), naming its last. */
lw_status lw_ckpt_missing(const lw_ckpt *c, const char *what, const char *guess, lw_error *err);
/* "section [sec] missing", naming the sections the file has and their lines,
** those not read yet first (a renamed one stands out). */
lw_status lw_ckpt_no_section(const lw_ckpt *c, const char *sec, lw_error *err);

/* For a message on bulk data that stops short: the words that say the file
** ends there too (section is its last, read from a file), else "". */
const char *lw_ckpt_cut_hint(const lw_ckpt *c, const char *section);

/* The text of a key (marked read), or NULL if missing; *line (if not NULL)
** is its line, 0 when built in memory. */
const char *lw_ckpt_text(lw_ckpt *c, const char *section, const char *key, int *line);

/* The longest list of numbers a key may hold: a tempering run's at_label,
** two a replica (its lists were read into 64 places, and a run of 33
** replicas or more could not resume). */
#define LW_CKPT_LIST_MAX 512

/* Exactly n (<= LW_CKPT_LIST_MAX) finite numbers in [lo, hi].  A missing key
** is an error when required, otherwise out keeps its values. */
lw_status lw_ckpt_numbers(lw_ckpt *c, const char *section, const char *key, double *out, int n, double lo,
                          double hi, int required, lw_error *err);

/* Exactly n counts: whole numbers from 0 to 2^53. */
lw_status lw_ckpt_counts(lw_ckpt *c, const char *section, const char *key, unsigned long *out, int n,
                         int required, lw_error *err);

/* n_min to n_max of them (a list that older files wrote shorter); the
** entries past those given keep their values. */
lw_status lw_ckpt_counts_upto(lw_ckpt *c, const char *section, const char *key, unsigned long *out, int n_min,
                              int n_max, int required, lw_error *err);

/* One whole number in [lo, hi] (|lo|, |hi| <= 2^53). */
lw_status lw_ckpt_whole(lw_ckpt *c, const char *section, const char *key, long *out, long lo, long hi,
                        int required, lw_error *err);

/* LW_EINPUT, naming the second line, where the section holds key more than
** once: a keyed read takes the first, and bulk reading (lw_ckpt_next) marks
** the rest read, so a repeated key among bulk data passed unseen. */
lw_status lw_ckpt_single(lw_ckpt *c, const char *section, const char *key, lw_error *err);

/* Bulk data: the entries of a section in file order.  *pos starts at 0;
** returns 1 and the next entry (marked read), 0 at the end of the section. */
int lw_ckpt_next(lw_ckpt *c, const char *section, size_t *pos, const char **key, const char **value, int *line);

/* Refuses the first section whose name known(name, ctx) does not take (a
** reader that leaves parts of the file unread still drops nothing unknown). */
lw_status lw_ckpt_known_sections(const lw_ckpt *c, int (*known)(const char *name, const void *ctx), const void *ctx,
                                 lw_error *err);

/* How many sections' names match() takes. */
size_t lw_ckpt_count_sections(const lw_ckpt *c, int (*match)(const char *name));

/* LW_EINPUT naming the first section or key nothing asked for (written by
** a newer linewise), else LW_OK. */
lw_status lw_ckpt_unread(const lw_ckpt *c, lw_error *err);

/* LW_EINPUT naming the file where its last line, "# checksum X" (written
** by lw_ckpt_commit since 2026-12-07), does not match the bytes before it;
** LW_OK where it does or there is none (an older or a hand-written file). */
lw_status lw_ckpt_verify(const lw_ckpt *c, lw_error *err);

/* ---- writing ------------------------------------------------------------ */

/* Streams a file to path.tmp; commit renames it over path (a reader never
** sees half a file, a failed write leaves the old file and no temporary). */
typedef struct {
  FILE *f;
  char path[LW_PATH_MAX + 64];
  char tmp[LW_PATH_MAX + 80];
  int no_sum;  /* commit adds no checksum line (a run's files from before them: lw_anneal.unsummed) */
} lw_ckpt_writer;

lw_status lw_ckpt_begin(lw_ckpt_writer *w, const char *path, const char *header, lw_error *err);
void lw_ckpt_section(lw_ckpt_writer *w, const char *name);
void lw_ckpt_put(lw_ckpt_writer *w, const char *key, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* Numbers with 17 significant digits (they read back to the same doubles). */
void lw_ckpt_put_numbers(lw_ckpt_writer *w, const char *key, const double *v, int n);
void lw_ckpt_put_counts(lw_ckpt_writer *w, const char *key, const unsigned long *v, int n);
/* fsync and rename; messages name the file and the reason. */
lw_status lw_ckpt_commit(lw_ckpt_writer *w, lw_error *err);
/* Drops the temporary file (after a failure elsewhere). */
void lw_ckpt_abort(lw_ckpt_writer *w);

#ifdef __cplusplus
}
#endif

#endif
