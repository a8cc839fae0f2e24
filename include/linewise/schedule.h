/*
** schedule.h -- temperature schedules of the annealer, one pure function and
** one table entry each (in the style of GSL's gsl_rng_type).
**
** A run has B = blocks temperature steps, b = 0 .. B-1; the temperature is
** constant within a block.  f = b / (B-1) (0 when B = 1):
**
**   constant     T_b = t_start
**   linear       T_b = t_start + (t_end - t_start) f
**   geometric    T_b = t_start (t_end / t_start)^f
**   logarithmic  T_b = t_start / (1 + c ln(1 + b)),  c = (t_start/t_end - 1) / ln B
**   adaptive     T_b = T_{b-1} exp(-lambda T_{b-1} / sd_{b-1})   (Huang, Romeo and
**                Sangiovanni-Vincentelli 1986), never below t_end
**   table        piecewise linear in b through the rows of a text file
**
** The analytic schedules hit t_start and t_end exactly at the first and last
** block, stay between them and are monotone; b outside 0 .. B-1 is clamped
** (the temperature holds after the last block).
**
** A schedule function sees nothing but its arguments: the parameters, the
** block, the previous block's temperature and the previous block's energy
** statistics.  The annealer stores the last two in its checkpoint, so a
** resumed run gets exactly the temperatures an uninterrupted one would.
**
** Adding a schedule: write its function and add an lw_schedule_type to
** lw_schedule_types[] in schedule.c.  Lookup by name, the list of names,
** parameter checks (driven by the `needs` flags) and lw_schedule_run all work
** from the table and need no other edit.
*/
#ifndef LINEWISE_SCHEDULE_H
#define LINEWISE_SCHEDULE_H

#include <stddef.h>

#include "linewise/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The parameters of every schedule; each type reads the ones its `needs`
** flags name.  Copying the struct copies the table pointers, not the rows:
** exactly one copy may be passed to lw_schedule_clear. */
typedef struct {
  double t_start, t_end;  /* temperatures of the first and last block */
  long blocks;            /* B, number of temperature steps (>= 1) */
  double lambda;          /* adaptive: cooling rate (> 0; Huang et al. use ~0.7) */
  size_t n_table;         /* table: rows */
  double *table_block;    /* table: owned; block index of each row, strictly increasing */
  double *table_temp;     /* table: owned; temperature of each row (finite, >= 0) */
} lw_schedule;

/* The energy statistics of one finished block. */
typedef struct {
  double mean, sd;        /* energy mean and standard deviation over the block */
  long samples;           /* number of energy samples behind them */
} lw_block_stats;

/* Flags for lw_schedule_type.needs: the parameters a schedule reads and what
** it requires of them; lw_schedule_check validates exactly these. */
enum {
  LW_SCHEDULE_USES_START = 1 << 0,  /* t_start: finite, >= 0 */
  LW_SCHEDULE_USES_END = 1 << 1,    /* t_end: finite, >= 0 */
  LW_SCHEDULE_POSITIVE = 1 << 2,    /* t_start and t_end > 0 (ratios, logarithms) */
  LW_SCHEDULE_COOLING = 1 << 3,     /* t_end <= t_start */
  LW_SCHEDULE_USES_LAMBDA = 1 << 4, /* lambda: finite, > 0 */
  LW_SCHEDULE_USES_TABLE = 1 << 5,  /* a table read with lw_schedule_read_table */
  LW_SCHEDULE_RECURSIVE = 1 << 6    /* T_b from T_{b-1}: every step takes its turn, one without sweeps too */
};

typedef struct {
  const char *name;       /* as written in a scene file */
  const char *formula;    /* one line for the docs */
  unsigned needs;         /* LW_SCHEDULE_* flags */
  /* Temperature of block b (>= 0, finite for valid parameters).  t_prev is
  ** the temperature of block b-1 and prev the statistics of block b-1; for
  ** b = 0 t_prev is ignored and prev is NULL.  prev may be NULL for any b
  ** (no measurements): the schedule must still give a temperature.  Pure. */
  double (*temperature)(const lw_schedule *s, long b, double t_prev, const lw_block_stats *prev);
} lw_schedule_type;

extern const lw_schedule_type lw_schedule_constant, lw_schedule_linear, lw_schedule_geometric,
    lw_schedule_logarithmic, lw_schedule_adaptive, lw_schedule_table;

/* Every schedule, NULL-terminated, in the order the docs list them. */
extern const lw_schedule_type *const lw_schedule_types[];

/* The entry called name (exact match), or NULL. */
const lw_schedule_type *lw_schedule_find(const char *name);

/* "constant|linear|..." in table order, for messages and docs.  Built from
** the table on the first call (thread safe); never freed. */
const char *lw_schedule_names(void);

/* Validates the parameters type t reads (its `needs`) and blocks >= 1.
** LW_EINPUT with a message naming the schedule and the parameter. */
lw_status lw_schedule_check(const lw_schedule_type *t, const lw_schedule *s, lw_error *err);

/* Reads a table of "block temperature" lines into s (blank lines and '#'
** comments allowed; blocks whole numbers >= 0, strictly increasing;
** temperatures finite, >= 0; at least one row), replacing any table s has.
** On error s is unchanged and err says "path:line: expected ..." (LW_EINPUT;
** LW_ENOMEM if memory runs out). */
lw_status lw_schedule_read_table(lw_schedule *s, const char *path, lw_error *err);

/* Frees the table and zeroes its fields; other parameters stay. */
void lw_schedule_clear(lw_schedule *s);

/* Temperatures of all s->blocks blocks into out[0 .. blocks-1], each from the
** previous one, with no block statistics (prev = NULL): the schedule as
** planned, for previews, docs and tests. */
void lw_schedule_run(const lw_schedule_type *t, const lw_schedule *s, double *out);

#ifdef __cplusplus
}
#endif

#endif
