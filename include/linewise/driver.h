/*
** driver.h -- what moves a system between sweeps (docs/SYSTEMS.md),
** one table row each, in the style of the system rows (system.h) and the
** schedules (schedule.h).  `[scene] driver` names a row.
**
** A driver is of one of two kinds.  A chain (LW_DRIVE_CHAIN) is a Markov
** chain of the system's moves: it reads the row's [moves] keys
** (keys_metropolis), a temperature schedule, [tempering]'s rungs and
** [anneal] domains, tunes its steps over the first moves.tune_sweeps sweeps
** (which `linewise stats` leaves out) and decides each proposal by its
** acceptance rule (mc.c).  A motion (LW_DRIVE_MOTION) integrates the
** system's equations of motion (dynamics.h): the gradient and mass members,
** the row's keys_dynamics and [dynamics].
**
** Adding a chain driver with another acceptance rule: a file with its row
** (the name, LW_DRIVE_CHAIN, lw_driver_chain_keys, the keys it ignores, its
** `accept`; driver_barker.c), one entry in lw_driver_types[] (driver.c) and
** its extern below; mention it in the help of `[scene] driver` (src/params.c;
** `make docs`).  tests/test_system.c holds every such row to detailed balance.
** Everything else (the key checks and notes, docs/PARAMETERS.md's "read
** by", the chain and its step tuning, tempering, summary.json's `driver`,
** the statistics' tuning stretch) reads the row.
*/
#ifndef LINEWISE_DRIVER_H
#define LINEWISE_DRIVER_H

#include "linewise/error.h"
#include "linewise/params.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { LW_DRIVE_CHAIN, LW_DRIVE_MOTION };

typedef struct lw_driver_type {
  const char *name;        /* scene.driver's word */
  int kind;                /* LW_DRIVE_* */
  const char *const *keys; /* the scene keys it reads besides its system's (`section.key`, `section.*`),
                           ** the run's own among them, NULL-terminated */
  const char *const *ignores; /* keys a system offers drivers of its kind that this one does not
                              ** read (NULL: none) */
  /* a chain's acceptance rule: the probability of taking a move whose log
  ** ratio is x = log q - dE / T (q the system's Hastings factor, 1 for a
  ** symmetric move), x from -infinity to +infinity; the chain draws one
  ** uniform number for each decision at T > 0, runs without delayed
  ** acceptance, whose second stage is Metropolis's, and tunes its steps to
  ** each target as a share of accept(0) (mc.h), the acceptance of the
  ** smallest steps: so accept must be continuous at 0 (a greedy rule, 1 at
  ** x >= 0 and 0 below, takes half its smallest steps, and tuned its steps
  ** to 1e-12 mm chasing a target above that).  NULL: Metropolis, min(1,
  ** e^x), drawing nothing where x >= 0 (and delayed acceptance where the
  ** scene asks) */
  double (*accept)(double x);
} lw_driver_type;

/* What every chain reads, and every motion, besides the system's keys. */
extern const char *const lw_driver_chain_keys[];
extern const char *const lw_driver_motion_keys[];

extern const lw_driver_type lw_driver_metropolis, lw_driver_dynamics, lw_driver_barker;

/* The table, NULL-terminated; its first row is the default. */
extern const lw_driver_type *const lw_driver_types[];

const lw_driver_type *lw_driver_find(const char *name);

/* "metropolis, dynamics, ...": the rows' names. */
const char *lw_driver_names(void);

/* The scene's driver; NULL with a message naming the key and where it was
** set when no row has its name. */
const lw_driver_type *lw_driver_of(const lw_params *p, lw_error *err);

/* Whether the scene's driver moves by equations of motion (0 for a name no
** row has: lw_params_resolve refuses that first). */
int lw_driver_is_motion(const lw_params *p);

#ifdef __cplusplus
}
#endif

#endif
