/*
** model.h -- the state being annealed with its caches: per-segment lengths
** and energies, per-spline lengths, running term totals, and the pair
** samples in a cell grid.  Proposals are evaluated from the affected
** segments only and committed in O(segments touched).
**
** A proposal replaces a run of consecutive nodes of one spline (one node for
** a single point or vector move, all nodes for a rigid move).  The segments
** touching a changed node are re-sampled; their old energies come from the
** cache.  The per-spline strain uses the cached spline length, so it costs
** O(1); the pair term visits the 3 x 3 cells around each new and old sample.
**
** Invariant (tested): after any sequence of commits, the running totals equal
** lw_energy_compute of the state within 1e-9 relative.
*/
#ifndef LINEWISE_MODEL_H
#define LINEWISE_MODEL_H

#include "linewise/grid.h"
#include "linewise/pair.h"
#include "linewise/scene.h"
#include "linewise/spline.h"

typedef struct {
  const lw_scene *scene;
  lw_splines *sp;           /* owned */
  double *seg_len;          /* n_segments, mm */
  double *seg_local;        /* n_segments * scene->n_local: cached local energies */
  double *spline_len;       /* n_splines, mm: sum of seg_len in segment order */
  double term[LW_TERM_COUNT]; /* running totals (0 for terms that are off) */
  lw_pair_sample *ps;       /* n_segments * quad.n pair samples (pair on), else NULL */
  lw_cellgrid *grid;        /* over ps (pair on), else NULL */
  double *near_cache;       /* n_segments: each segment's pair near field (pair on) */
  uint8_t *near_valid;      /* n_segments: 1 where near_cache holds the current value */
  size_t max_segments;      /* longest spline, for sizing proposals */
} lw_model;

/* Builds the caches for sp (ownership passes to the model, also on failure). */
lw_model *lw_model_new(const lw_scene *sc, lw_splines *sp, lw_error *err);
void lw_model_free(lw_model *m);

double lw_model_total(const lw_model *m);

/* Recomputes every cache and total from the state.  If drift is not NULL it
** receives the relative difference between the old running total and the
** new one, |new - old| / max(|new|, 1). */
lw_status lw_model_refresh(lw_model *m, double *drift);

/* Sample indices of near pairs found by a neighbour walk (growable). */
typedef struct {
  uint32_t *idx;
  size_t n, cap;
} lw_near_list;

/* Scratch for one proposal: owned by one thread, sized for the model. */
typedef struct {
  uint32_t spline;
  size_t node0, n_node;       /* changed nodes: local index and count */
  size_t seg0, n_seg;         /* affected segments: local index and count */
  lw_node *node;              /* n_node new nodes */
  double *len;                /* n_seg new segment lengths */
  double *local;              /* n_seg * n_local new local energies */
  lw_pair_sample *ps;         /* n_seg * quad.n new pair samples */
  double new_spline_len;
  double dterm[LW_TERM_COUNT];
  double dE;                  /* sum of dterm; +inf for a forbidden state, NaN never kept */
  size_t cap_seg;
  lw_near_list near;          /* the pair walk's near pairs */
  lw_near_list partners;      /* near partners of the changed segments, old and new */
  double *near_new;           /* n_seg new near fields (no coefficient) */
  int pair_done;              /* 1 if the pair part was evaluated */
} lw_proposal;

lw_proposal *lw_proposal_new(const lw_model *m, lw_error *err);
void lw_proposal_free(lw_proposal *p);

/* Evaluates replacing n_node nodes of spline `spline` starting at local node
** node0 with `nodes` (copied into p; NULL: they are already in p->node).  Fills p->dterm and p->dE.  The
** state is not changed, but the pair term's near-field cache may be filled
** (model.c): one thread per model. */
void lw_model_propose(const lw_model *m, lw_proposal *p, uint32_t spline, size_t node0,
                      size_t n_node, const lw_node *nodes);

/* Applies an evaluated proposal.  LW_ENOMEM if the grid could not grow. */
lw_status lw_model_commit(lw_model *m, const lw_proposal *p);

/* Energy of a state computed from scratch, one value per term (0 for terms
** that are off); returns the total. */
double lw_energy_compute(const lw_scene *sc, const lw_splines *sp, double term[LW_TERM_COUNT],
                         lw_error *err);

#endif
