/* driver.c -- the table of drivers (driver.h). */
#include "linewise/driver.h"

#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "linewise/number.h"

/* What a run reads under any driver: its length, seed, quench and outputs. */
#define RUN_KEYS "scene.system", "scene.driver", "anneal.sweeps", "anneal.seed", "anneal.seed_version", \
    "anneal.quench", "anneal.quench_tol", "anneal.quench_iterations", "anneal.quench_stall", \
    "output.checkpoint_every", "output.trace_every", "output.trace_exact", "output.observables", \
    "output.samples_every", "output.stats_from", "output.frames_every"

/* A chain: its schedule, its ladder, its tuning and its recomputations
** from scratch; a motion: its time step, damping and density (rho = 0: the
** massless flow, dynamics.c). */
const char *const lw_driver_chain_keys[] = {RUN_KEYS, "anneal.schedule", "anneal.t_start", "anneal.t_end",
                                            "anneal.steps", "anneal.lambda", "anneal.table", "anneal.check_every",
                                            "tempering.*", "moves.tune_sweeps", NULL};
const char *const lw_driver_motion_keys[] = {RUN_KEYS, "dynamics.rho", "dynamics.dt", "dynamics.gamma",
                                             "dynamics.steps_per_sweep", "dynamics.integrator", NULL};

const lw_driver_type lw_driver_metropolis = {"metropolis", LW_DRIVE_CHAIN, lw_driver_chain_keys, NULL, NULL};
const lw_driver_type lw_driver_dynamics = {"dynamics", LW_DRIVE_MOTION, lw_driver_motion_keys, NULL, NULL};

const lw_driver_type *const lw_driver_types[] = {&lw_driver_metropolis, &lw_driver_dynamics, &lw_driver_barker, NULL};

const lw_driver_type *lw_driver_find(const char *name)
{
  for (int k = 0; lw_driver_types[k]; k++)
    if (!strcmp(lw_driver_types[k]->name, name)) return lw_driver_types[k];
  return NULL;
}

static char names_buf[256];
static pthread_once_t names_once = PTHREAD_ONCE_INIT;

static void build_names(void)
{
  size_t n = 0;
  for (int k = 0; lw_driver_types[k] && n < sizeof names_buf; k++)
    n += (size_t)snprintf(names_buf + n, sizeof names_buf - n, "%s%s", k ? ", " : "", lw_driver_types[k]->name);
}

const char *lw_driver_names(void)
{
  pthread_once(&names_once, build_names);
  return names_buf;
}

const lw_driver_type *lw_driver_of(const lw_params *p, lw_error *err)
{
  const lw_driver_type *t = lw_driver_find(p->driver);
  if (!t) {
    char where[LW_PATH_MAX + 32], unseen[96];
    lw_params_origin(p, lw_params_find("scene", "driver"), where, sizeof where);
    lw_error_set(err, LW_EINPUT, "%s: key 'scene.driver': expected one of %s, got '%s'%s", where, lw_driver_names(),
                 p->driver, lw_text_unseen_char(p->driver, unseen, sizeof unseen));
  }
  return t;
}

int lw_driver_is_motion(const lw_params *p)
{
  const lw_driver_type *t = lw_driver_find(p->driver);
  return t && t->kind == LW_DRIVE_MOTION;
}
