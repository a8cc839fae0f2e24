/*
** phase.c -- the current phase outside the sweeps (phase.h).
*/
#include "linewise/phase.h"

#include <stdatomic.h>
#include <stdio.h>
#include <time.h>

/* The name and its start time are two values: a reader may see a new name
** with the old time for an instant, which only shortens what it reports. */
static _Atomic(const char *) phase_what;
static _Atomic double phase_since;

double lw_phase_clock(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void lw_phase_set(const char *what)
{
  atomic_store(&phase_since, lw_phase_clock());
  atomic_store(&phase_what, what);
}

static volatile atomic_int unwritten;

void lw_phase_hold(void) { atomic_store(&unwritten, 1); }

void lw_phase_writing(void) { atomic_store(&unwritten, 0); }

int lw_phase_unwritten(void) { return atomic_load(&unwritten); }

static volatile atomic_int stash_waits;

void lw_phase_stash(int on) { atomic_store(&stash_waits, on); }

int lw_phase_stashed(void) { return atomic_load(&stash_waits); }

static volatile atomic_int stop_asked;

void lw_phase_stop(void) { atomic_store(&stop_asked, 1); }

void lw_phase_stop_clear(void) { atomic_store(&stop_asked, 0); }

int lw_phase_stopping(void) { return atomic_load(&stop_asked); }

static volatile atomic_long committed = -1, committing = -1;

void lw_phase_committing(long sweep) { atomic_store(&committing, sweep); }

void lw_phase_committed(long sweep)
{
  atomic_store(&committed, sweep);
  atomic_store(&committing, -1);
}

long lw_phase_last_commit(long *pending)
{
  if (pending) *pending = atomic_load(&committing);
  return atomic_load(&committed);
}

const char *lw_phase_get(double *seconds)
{
  const char *what = atomic_load(&phase_what);
  if (seconds) *seconds = what ? lw_phase_clock() - atomic_load(&phase_since) : 0.0;
  return what;
}

/* A terminal line is cleared before it is rewritten, so the seconds and the
** final line replace the progress bar's line instead of trailing it. */
const char *lw_phase_watch_tick(lw_phase_watch *w, const char *what, double seconds, char *buf, size_t n)
{
  const char *clear = w->tty ? "\r\033[K" : "";
  size_t used = 0;
  buf[0] = '\0';
  if (w->shown && what != w->shown) {
    used = (size_t)snprintf(buf, n, "%slinewise: %s: done in %.1f s\n", clear, w->shown, w->last);
    if (used >= n) used = n - 1;
    w->shown = NULL;
  }
  if (what && seconds > LW_PHASE_QUIET && (!w->shown || (w->tty && seconds - w->reported >= 1.0))) {
    if (w->tty) snprintf(buf + used, n - used, "%slinewise: %s... %.0f s", clear, what, seconds);
    else if (!w->shown) snprintf(buf + used, n - used, "linewise: %s...\n", what);
    w->shown = what;
    w->reported = seconds;
  }
  if (what && what == w->shown) w->last = seconds;
  return buf;
}

const char *lw_phase_watch_end(lw_phase_watch *w, int how, char *buf, size_t n)
{
  static const char *const ended[] = {"done in", "failed after", "stopped after"};
  buf[0] = '\0';
  if (w->shown)
    snprintf(buf, n, "%slinewise: %s: %s %.1f s\n", w->tty ? "\r\033[K" : "", w->shown,
             ended[how >= LW_PHASE_DONE && how <= LW_PHASE_STOPPED ? how : LW_PHASE_FAILED], w->last);
  w->shown = NULL;
  return buf;
}
