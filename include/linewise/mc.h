/*
** mc.h -- one Metropolis chain: move kinds, acceptance, step tuning.
**
** A proposal perturbs one point p_k or one vector v_k by a Gaussian step in
** x and y, or moves a whole spline rigidly (translation, or rotation about
** the mean of its points, which the rotation leaves in place, so every
** proposal is symmetric).  Accept if dE <= 0, else with probability
** exp(-dE / T); a NaN dE is rejected and counted, +inf is rejected (and
** counted apart when an irregular segment made it so).
**
** Steps adapt toward a target acceptance only while `tuning` is set (the
** annealer sets it at the start of each temperature); otherwise they are
** frozen so the chain obeys detailed balance.
**
** A sweep is as many proposals as the scene has nodes.
*/
#ifndef LINEWISE_MC_H
#define LINEWISE_MC_H

#include <gsl/gsl_rng.h>

#include "linewise/model.h"

typedef enum { LW_MOVE_POINT, LW_MOVE_VECTOR, LW_MOVE_TRANSLATE, LW_MOVE_ROTATE, LW_MOVE_KINDS } lw_move_kind;

extern const char *const lw_move_names[LW_MOVE_KINDS];

typedef struct {
  unsigned long proposed, accepted, nan; /* nan: proposals rejected for a NaN dE */
  unsigned long irregular;  /* proposals rejected for an irregular segment (model.h) */
} lw_move_stats;

/* How often tuning looks at the acceptance of a move kind (proposals):
** small enough that rare rigid moves get tuned within a few sweeps. */
#define LW_TUNE_WINDOW 25

typedef struct {
  lw_model *model;               /* not owned */
  lw_proposal *prop;             /* owned scratch */
  gsl_rng *rng;                  /* owned: this chain's stream */
  double temperature;            /* energy units; 0 = greedy descent */
  double cum_weight[LW_MOVE_KINDS]; /* cumulative mix, normalised to 1 */
  double step[LW_MOVE_KINDS];    /* mm, mm, mm, radians */
  double target[LW_MOVE_KINDS];  /* acceptance targets */
  double step_max[LW_MOVE_KINDS];/* tuning never grows a step past this */
  int tuning;
  unsigned long win_prop[LW_MOVE_KINDS], win_acc[LW_MOVE_KINDS]; /* tuning window */
  lw_move_stats stats[LW_MOVE_KINDS]; /* since the start of the run */
} lw_chain;

/* A chain on model m with the mix, steps and targets of the parameters
** (mix weights need not sum to 1; at least one must be > 0). */
lw_chain *lw_chain_new(lw_model *m, const double weight[LW_MOVE_KINDS], const double step[LW_MOVE_KINDS],
                       const double target[LW_MOVE_KINDS], unsigned long seed, lw_error *err);
void lw_chain_free(lw_chain *c);

/* One proposal of the given kind; returns 1 if accepted. */
int lw_chain_step(lw_chain *c, lw_move_kind kind);

/* One sweep: n_nodes proposals with kinds drawn from the mix.  LW_ENOMEM if a
** commit could not grow the grid. */
lw_status lw_chain_sweep(lw_chain *c);

/* A generator's state as hex text (malloc'ed) and back, for checkpoints;
** load returns 0 if the text does not fit the generator. */
char *lw_rng_save(const gsl_rng *r);
int lw_rng_load(gsl_rng *r, const char *hex);

#endif
