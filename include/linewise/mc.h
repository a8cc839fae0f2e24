/*
** mc.h -- one Metropolis chain on a system (system.h): move kinds by the
** row's names, acceptance, step tuning.
**
** The system draws a proposal of the chosen kind from the chain's stream
** with the kind's step and evaluates dE; every proposal of every system is
** symmetric (for splines: Gaussian steps of one point or vector, rigid
** translations and rotations about the mean of a spline's points).  Accept
** if dE <= 0, else with probability exp(-dE / T); a NaN dE is rejected and
** counted, +inf is rejected (and counted apart when the system says a
** forbidden state made it so).
**
** Steps adapt toward a target acceptance only while `tuning` is set (the
** annealer sets it at the start of each temperature); otherwise they are
** frozen so the chain obeys detailed balance.
**
** A sweep is as many proposals as the row's sweep_size (for splines: the
** scene's nodes), site after site where the row numbers its sites.
*/
#ifndef LINEWISE_MC_H
#define LINEWISE_MC_H

#include <gsl/gsl_rng.h>

#include "linewise/system.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  unsigned long proposed, accepted, nan; /* nan: proposals rejected for a NaN dE */
  unsigned long irregular;  /* proposals rejected for a forbidden state (model.h) */
  unsigned long crowded;    /* ... for closing in on another stroke (energy.min_spacing) */
  unsigned long outside;    /* ... for leaving its domain (anneal.domains): no Metropolis
                            ** test saw them, so tuning leaves them out */
} lw_move_stats;

/* How often tuning looks at the acceptance of a move kind (proposals):
** small enough that rare rigid moves get tuned within a few sweeps. */
#define LW_TUNE_WINDOW 25

struct lw_domains;

typedef struct {
  lw_system *sys;                /* not owned; tempering swaps them between chains */
  void *prop;                    /* owned scratch of sys's type */
  gsl_rng *rng;                  /* owned: this chain's stream */
  double temperature;            /* energy units; 0 = greedy descent */
  int n_moves;                   /* the row's move kinds */
  double cum_weight[LW_MOVES_MAX]; /* cumulative mix, normalised to 1 */
  double step[LW_MOVES_MAX];     /* in the row's units (splines: mm, mm, mm, radians) */
  double target[LW_MOVES_MAX];   /* acceptance targets */
  double step_max[LW_MOVES_MAX]; /* tuning never grows a step past this */
  int tuning;
  unsigned long win_prop[LW_MOVES_MAX], win_acc[LW_MOVES_MAX]; /* tuning window */
  lw_move_stats stats[LW_MOVES_MAX]; /* since the start of the run */
  struct lw_domains *domains;    /* owned; not NULL: sweeps are split into domains (domains.h) */
  int part;                      /* 1 for a domain's chain: commits through commit_part */
  int delayed;                   /* 1 (the default): delayed acceptance where the row offers it
                                 ** (system.h, defer and finish) and T > 0 */
  double (*accept)(double x);    /* the driver's acceptance rule (driver.h); NULL: Metropolis */
} lw_chain;

/* A chain on sys with the mix, steps and targets of its n_moves kinds (mix
** weights need not sum to 1; at least one must be > 0). */
lw_chain *lw_chain_new(lw_system *sys, const double *weight, const double *step, const double *target,
                       unsigned long seed, lw_error *err);
void lw_chain_free(lw_chain *c);

/* The driver's acceptance rule (driver.h; NULL: Metropolis).  A rule that
** takes a vanishing step with probability a(0) < 1 (Barker's: 1/2) tunes
** its steps to that share of each target: the targets are relative to the
** smallest steps' acceptance (a target above a(0) shrank the steps to
** 1e-45 and froze the chain).  Before the chain is copied. */
void lw_chain_set_rule(lw_chain *c, double (*accept)(double x));

/* The acceptance of the smallest steps under the chain's rule: 1, or a(0). */
double lw_chain_ceiling(const lw_chain *c);

/* One proposal of the given kind; returns 1 if accepted, 0 if rejected, -1
** if the commit ran out of memory. */
int lw_chain_step(lw_chain *c, int kind);

/* The same at site `site` of a row with propose_at (system.h); a row
** without it draws its own site. */
int lw_chain_step_at(lw_chain *c, int kind, size_t site);

/* A domain's chain (domains.h): one proposal at `site` of a kind drawn
** from the mix, rejected if what it moves leaves box (x0, y0, x1, y1);
** returns as lw_chain_step. */
int lw_chain_visit_in(lw_chain *c, size_t site, const double box[4]);

/* Adds the statistics of a domain's chain `from` to c's and clears them;
** while c tunes, they fill c's tuning windows as c's own proposals would. */
void lw_chain_absorb(lw_chain *c, lw_chain *from);

/* While c tunes, one step update for each kind whose window is full: after
** absorbing every domain of a phase, whose proposals all used the same
** steps, so that one body of evidence moves a step once. */
void lw_chain_tune(lw_chain *c);

/* One sweep: sweep_size proposals with kinds drawn from the mix.  A row with
** propose_at has every site visited once, in order, forward or backward
** (one draw per sweep); each visit is a Metropolis update that leaves the
** Boltzmann distribution stationary, and the two directions, equally
** likely, make the sweep reversible (docs/NUMERICS.md, "Sweep order").  A
** row without it draws each proposal's site at random.  A chain with
** domains sweeps them instead (domains.h), with the kinds they can run,
** then the others (system.h, n_domain_moves) serially: their share of the
** mix of sweep_size proposals.  Then the row's sweep_end, if any.
** LW_ENOMEM if a commit could not grow the system's caches. */
lw_status lw_chain_sweep(lw_chain *c);

/* An MT19937 generator, or NULL when memory runs out: gsl_rng_alloc's
** default error handler aborts the process there (a set-up under a memory
** limit ended in "Default GSL error handler invoked" and a core dump). */
gsl_rng *lw_rng_new(void);

/* A generator's state as hex text (malloc'ed) and back, for checkpoints;
** load returns 0 if the text does not fit the generator. */
char *lw_rng_save(const gsl_rng *r);
int lw_rng_load(gsl_rng *r, const char *hex);

#ifdef __cplusplus
}
#endif

#endif
