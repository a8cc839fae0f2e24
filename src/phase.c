/*
** phase.c -- the current phase outside the sweeps (phase.h).
*/
#include "linewise/phase.h"

#include <stdatomic.h>
#include <time.h>

/* The name and its start time are two values: a reader may see a new name
** with the old time for an instant, which only shortens what it reports. */
static _Atomic(const char *) phase_what;
static _Atomic double phase_since;

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void lw_phase_set(const char *what)
{
  atomic_store(&phase_since, now());
  atomic_store(&phase_what, what);
}

const char *lw_phase_get(double *seconds)
{
  const char *what = atomic_load(&phase_what);
  if (seconds) *seconds = what ? now() - atomic_load(&phase_since) : 0.0;
  return what;
}
