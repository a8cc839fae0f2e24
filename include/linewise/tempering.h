/*
** tempering.h -- parallel tempering: a temperature ladder, replica exchanges
** decided from one master stream, swap statistics, round trips and the
** tuning of the ladder toward equal swap acceptance.
**
** The module knows nothing of splines: it sees the energy of the replica at
** each rung of the ladder and answers which neighbours swap.  Whoever owns
** the replicas (lw_anneal, or a test with a system of its own) runs them
** between exchanges and then swaps what sits at the two rungs: state
** pointers, never copies of states.
**
** Exchange of the replicas at rungs k and k+1 (temperatures T_k < T_k+1,
** beta = 1/T): accept with probability min(1, exp((beta_k - beta_k+1)
** (E_k - E_k+1))), the Metropolis rule for the product of the two Boltzmann
** distributions, so the ensemble stays in equilibrium.  Exchange steps
** alternate between the even pairs (0-1, 2-3, ...) and the odd pairs
** (1-2, 3-4, ...); every attempt draws one uniform number from the master
** stream, so the stream's position depends on the number of steps only.
**
** Round trips: a replica that has visited the coldest rung is marked "going
** up"; when it reaches the hottest it is marked "going down", and when it
** then comes back to the coldest one round trip is counted.
*/
#ifndef LINEWISE_TEMPERING_H
#define LINEWISE_TEMPERING_H

#include <gsl/gsl_rng.h>

#include "linewise/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_TEMPERING_MAX 256

typedef struct {
  int n;                      /* rungs = replicas, >= 2 */
  double *ladder;             /* base temperatures, increasing (the schedule scales them) */
  int *at;                    /* at[k]: the replica at rung k */
  int *label;                 /* per replica: +1 going up, -1 going down, 0 not yet at an end */
  unsigned long *tried, *accepted; /* per neighbour pair (k, k+1), n - 1 of each */
  unsigned long *win_tried, *win_accepted; /* since the last ladder update */
  unsigned long round_trips;
  unsigned long steps;        /* exchange steps done; the parity picks the pairs */
  gsl_rng *rng;               /* the master stream (owned) */
} lw_tempering;

/* A ladder of n temperatures for n replicas, each replica at its own rung.
** ladder must be positive and strictly increasing. */
lw_tempering *lw_tempering_new(int n, const double *ladder, unsigned long seed, lw_error *err);
void lw_tempering_free(lw_tempering *pt);

/* n temperatures from t_min to t_max in geometric progression. */
void lw_tempering_geometric(double *ladder, int n, double t_min, double t_max);

/* One exchange step.  energy[k] is the energy of the replica at rung k and
** temp[k] the rung's current temperature (the ladder times the schedule's
** factor).  Updates at[], the statistics and the round trips; swapped[k]
** (n - 1 entries, may be NULL) is set to 1 where rungs k and k+1 swapped,
** and the caller must swap its replicas there too.  Returns the number of
** swaps. */
int lw_tempering_exchange(lw_tempering *pt, const double *energy, const double *temp, int *swapped);

/* Moves the inner rungs toward equal swap acceptance from the window's
** counts, keeping the two ends: the log-temperature gap of a pair is
** scaled by exp(gain (acceptance - mean)), growing where acceptance is above
** the mean and shrinking where it is below.  Clears the window.  Only for a
** warm-up phase: a ladder that moves breaks detailed balance. */
void lw_tempering_tune(lw_tempering *pt, double gain);

/* The gain of update number `updates` (counted from the start of the
** tuning): 1 for the first four, then 4 / updates.  A window's
** acceptance (about 20 attempts a pair) is noisy by +-0.1: at a fixed gain
** the ladder wandered with it and froze wherever it was (a harmonic wire
** whose geometric ladder is the equal one ended at swap rates 0.19 to
** 0.43); a falling gain (Robbins and Monro) settles on the mean of the
** windows, its spread shrinking like 1 / sqrt(updates).  4 did better than
** 2 or 10 from an equal ladder and from an uneven one (measured 2026-12-05,
** wire-ladder, 4 rungs: rms 0.013 off equal at 10000 tuning sweeps). */
double lw_tempering_tune_gain(long updates);

/* Exchange steps between two calls of lw_tempering_tune (about 20 attempts
** a pair, even and odd pairs alternating). */
#define LW_TEMPERING_TUNE_EVERY 40

/* Clears the swap statistics and round trips (after the warm-up). */
void lw_tempering_reset_stats(lw_tempering *pt);

/* Measured swap acceptance of the pair of rungs (k, k+1). */
static inline double lw_tempering_acceptance(const lw_tempering *pt, int k)
{
  return pt->tried[k] ? (double)pt->accepted[k] / (double)pt->tried[k] : 0.0;
}

#ifdef __cplusplus
}
#endif

#endif
