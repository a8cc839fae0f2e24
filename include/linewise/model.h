/*
** model.h -- the state being annealed with its caches: per-segment lengths
** and energies, per-spline lengths, running term totals, and the pair
** samples in a cell grid.  Proposals are evaluated from the affected
** segments only and committed in O(segments touched).
**
** The terms come from the term table (terms.h), each with its context,
** and are treated by their shape, never by name: segment terms are cached
** per segment, spline terms are evaluated from the cached segment and
** spline lengths, and the pairwise term (one at most) keeps its samples in
** a cell grid of its cutoff.
**
** A proposal replaces a run of consecutive nodes of one spline (one node for
** a single point or vector move, all nodes for a rigid move).  The segments
** touching a changed node are re-sampled; their old energies come from the
** cache.  A spline term sees the moved spline's cached lengths, so it costs
** O(segments of a spline); the pairwise term visits the 3 x 3 cells around
** each new and old sample; a raster term splats the old samples out of and
** the new ones into a box of changes, O(samples x footprint + box).
**
** Spacing (scene->min_spacing > 0, with the pair term): a hard constraint
** between pair samples of different splines.  A proposal whose new samples
** have more neighbours of other splines closer than min_spacing than its
** old samples had is forbidden (dE = +inf, p->crowded set).  A state that
** keeps the constraint thus never loses it, and one that starts without it
** (a random placement) can only come closer to it: the pairs too close are
** never more after a move than before.  The 3 x 3 cells of the pair grid
** hold every neighbour within the cutoff >= min_spacing.
**
** Invariant (tested): after any sequence of commits, the running totals equal
** lw_energy_compute of the state within 1e-9 relative.
**
** Regularity (lw_segment_allowed): a segment whose speed falls below
** scene->min_speed times its length, or whose bending integrand has a
** singularity inside the Bernstein ellipse scene->regularity (spline.h), or
** whose pair samples lie wider apart than scene->pair_gap_max, is
** forbidden.  The terms of a state
** with one stay what the quadrature gives, but its total is +infinity
** (lw_model_total, lw_energy_compute); a proposal that makes a segment
** irregular has dE = +inf and p->irregular set, one that leaves the last
** irregular segment among those it touches for regular ones has dE = -inf.
*/
#ifndef LINEWISE_MODEL_H
#define LINEWISE_MODEL_H

#include "linewise/grid.h"
#include "linewise/pair.h"
#include "linewise/scene.h"
#include "linewise/slots.h"
#include "linewise/spline.h"
#include "linewise/tone.h"
#include "linewise/walk.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The pair samples live in the grid only (grid.h: x, y and dl in the
** structure-of-arrays form the walk reads); the spline and node of sample i
** follow from i (quad.n samples per segment, the segments of a spline
** consecutive).  Per segment at 8 nodes: 8 x (24 in a cell + 4 home) = 224
** bytes of pair data plus the cells' spare room, against 8 x (32 + 4). */

/* The terms of a scene as the model uses them: every term's context
** (lw_scene_term_ctx), the spline terms that are on, and the pairwise term
** that is on (-1 if none). */
typedef struct {
  lw_term_ctx ctx[LW_TERM_COUNT];
  int n_spline;
  lw_term_id spline[LW_TERM_COUNT];
  int pair;
  int n_raster;             /* the raster terms that are on */
  lw_term_id raster[LW_TERM_COUNT];
  int n_layers;             /* the scene's layers (layers.h), 0 = none: then ctx serves every spline */
  const lw_layers_spec *layers; /* the scene's, with n_layers */
  lw_term_ctx layer_ctx[LW_LAYERS_MAX][LW_TERM_COUNT]; /* each layer's contexts */
} lw_term_set;

typedef struct {
  const lw_scene *scene;
  lw_splines *sp;           /* owned */
  double *seg_len;          /* n_segments, mm */
  double *seg_local;        /* n_segments * scene->n_local: cached local energies */
  double *spline_len;       /* n_splines, mm: sum of seg_len by blocks (model.c, spline_length) */
  double *seg_block;        /* at a block's first segment, its sum (a long spline's length in
                              ** O(block + blocks) a commit); NULL: summed afresh */
  unsigned char *seg_irregular; /* n_segments: 1 where a segment is irregular */
  size_t n_irregular;       /* how many; the total is +inf while > 0 */
  double term[LW_TERM_COUNT]; /* running totals (0 for terms that are off) */
  lw_term_set terms;        /* the terms' contexts and shapes */
  lw_cellgrid *grid;        /* the pair samples' positions and weights (pairwise term on), else NULL */
  double *near_cache;       /* n_segments: each segment's pair near field (pair on) */
  uint8_t *near_valid;      /* n_segments: 1 where near_cache holds the current value */
  /* Segment g's corrections with up to LW_NEAR_SLOTS of its near partners
  ** (pair and near field on, else NULL): near_pid[g LW_NEAR_SLOTS + k] the partner (LW_NEAR_FREE: an
  ** empty slot) and near_pval the value lw_pair_near_correction gives the
  ** pair in the current state.  A commit writes a move's new pair values
  ** into both segments' slots, so a segment whose near_cache a partner's
  ** move invalidated sums it again without recomputing its other pairs. */
  uint32_t *near_pid;
  double *near_pval;
  int64_t *raster[LW_TERM_COUNT]; /* each raster term's raster (tone.h) while on, else NULL;
                                     with layers one plane a layer, layer k at k w h */
  size_t max_segments;      /* longest spline, for sizing proposals (with trans-dimensional
                              moves at least scene->max_segments) */
  size_t cap_seg, cap_spl;  /* room in the per-segment and per-spline caches (splices) */
  lw_slots *slots;          /* the ghosts that splices leave (slots.h); none between sweeps */
  uint64_t serial;          /* changes with every change of the state (commits, splices,
                            ** refreshes, compactions), unique among models: what a
                            ** proposal's memo of the far field was taken at */
} lw_model;

/* Splines alive: those of m->sp less the ghosts. */
static inline size_t lw_model_count(const lw_model *m)
{
  return m->sp->n_splines - (m->slots ? m->slots->n_ghost : 0);
}

/* 1 if spline slot i is a ghost (slots.h): no proposal touches it. */
static inline int lw_model_ghost(const lw_model *m, size_t i)
{
  return lw_slots_ghost(m->slots, i);
}

/* Removes the ghosts: the live splines keep their order and are numbered
** 0 .. N-1, with their caches and pair samples (one pass over the arrays
** and the grid's cells; every cached value stays what a fresh computation
** gives, the renumbering being monotone).  Nothing to do without ghosts.
** LW_ENOMEM (the segment map) leaves the model as it was. */
lw_status lw_model_compact(lw_model *m);

/* Builds the caches for sp (ownership passes to the model, also on failure). */
lw_model *lw_model_new(const lw_scene *sc, lw_splines *sp, lw_error *err);
void lw_model_free(lw_model *m);

/* The sum of the running terms; +inf while a segment is irregular. */
double lw_model_total(const lw_model *m);

/* Recomputes every cache and total from the state (after compacting its
** ghosts away).  If drift is not NULL it
** receives the relative difference between the old running total and the
** new one, |new - old| / max(|new|, 1). */
lw_status lw_model_refresh(lw_model *m, double *drift);

/* Pair slots a segment keeps (lw_model.near_pid): as many as a segment of a
** drawing usually has near partners; more are recomputed when needed. */
#define LW_NEAR_SLOTS 6
#define LW_NEAR_FREE UINT32_MAX

/* One segment pair's near correction, as a proposal computed it. */
typedef struct {
  uint32_t seg, partner; /* the changed segment (global index) and its partner */
  double value;
} lw_near_value;

typedef struct {
  lw_near_value *v;
  size_t n, cap;
} lw_near_values;

/* A growable list of segment numbers (near partners). */
typedef struct {
  uint32_t *idx;
  size_t n, cap;
} lw_near_list;

/* What the pair walk found for the segments of one spline in one state
** (model.c, pair_walk): for segment k of the spline, where ok[k], its
** samples' far sum and first-stage stand-in (lw_pair_walk's sums of its
** samples, +1 each) and its near partners.  A sweep proposes the nodes of a
** spline one after the other, and each move shares a segment with the
** previous one: that segment's old side is taken from here.  Valid while
** the model's serial is the one recorded (only the spline's own commits,
** which never change its far field, move it on). */
typedef struct {
  const lw_model *model;
  uint64_t serial;
  uint32_t spline;            /* UINT32_MAX: none */
  unsigned char *ok;          /* cap_seg each */
  double *far, *stand;
  lw_near_list *partners;
} lw_far_memo;

/* Scratch for one proposal: owned by one thread, sized for the model. */
typedef struct {
  uint32_t spline;
  size_t node0, n_node;       /* changed nodes: local index and count */
  size_t seg0, n_seg;         /* affected segments: local index and count */
  lw_node *node;              /* n_node new nodes */
  double *len;                /* n_seg new segment lengths */
  double *local;              /* n_seg * n_local new local energies */
  lw_pair_sample *ps;         /* n_seg * quad.n new pair samples */
  lw_pair_sample *ps_old;     /* n_seg * quad.n pair samples before the move (pair on; the
                              ** walk's old side, and the undo of a failed commit) */
  lw_pair_probe *probe;       /* 2 n_seg quad.n: each new sample, then its old self, as probes */
  lw_pair_nearlist near;      /* the walk's near pairs (walk.h), by their probes' numbers */
  lw_pair_probe *walked;      /* the probes walked: those not taken from the memo */
  uint32_t *walked_id;        /* their numbers */
  size_t n_walked;            /* how many (the others' sums came from the memo) */
  double *each;               /* 2 n_seg quad.n: each probe's far sum (+1 each; walk.h) */
  double *stand;              /* and its pairs' stand-in of the near field (near_stand_in) */
  lw_near_list *side;         /* 2 cap_seg: the near partners of changed segment j, new (2j)
                              ** and old (2j + 1; the memo's list holds them after the walk) */
  double *seg_sum;            /* 4 n_seg: segment j's far sum and stand-in, new (4j, 4j + 1)
                              ** and old (4j + 2, 4j + 3) */
  int walk_done;              /* the walk of this move ran and its memo entries hold */
  int nomem;                  /* an allocation failed: its dE is NAN for want of memory */
  int any_near;               /* a changed segment has near pairs, new or old */
  double stand_in;            /* the first stage's stand-in of the near field's change */
  lw_far_memo memo;
  double new_spline_len;
  double dterm[LW_TERM_COUNT];
  unsigned char *seg_irregular; /* n_seg: 1 where a new segment is irregular */
  int irregular;              /* 1 if any is: the proposal is forbidden for that */
  double dE;                  /* sum of dterm; +inf for a forbidden state, NaN never kept */
  size_t cap_seg;
  lw_near_list segs;          /* scratch: the near partners of one segment */
  lw_near_list partners;      /* near partners of the changed segments, old and new */
  /* delayed acceptance (lw_model_propose_finish) */
  int defer_near;             /* set by the caller: a move may leave its near field for later */
  int near_pending;           /* the last move did: dterm and dE hold a stand-in for it */
  double pe_walk, dE_pre_pair; /* what the finish starts from */
  double *near_new;           /* n_seg new near fields (no coefficient) */
  lw_near_values near_vals;   /* the pairs that make up near_new, for the pair slots */
  int pair_done;              /* 1 if the pair part was evaluated */
  lw_tone_box box[LW_TERM_COUNT]; /* each raster term's changes */
  int raster_done;            /* 1 if the raster terms were evaluated */
  int crowded;                /* 1 if refused by the spacing constraint */
  int curves_pending;         /* its rule between the curves waits for lw_model_propose_finish */
  /* Changes of the running totals committed through this scratch and not
  ** yet merged into the model (lw_model_commit_part); -0.0 when none, the
  ** identity of +, so a merged single commit adds exactly dterm. */
  double sum_term[LW_TERM_COUNT];
  long sum_irregular;
  int sum_stale;              /* a raster term's change is unknown: refresh on merge */
  /* a splice (lw_model_propose_regroup): the n_old splines old[] (old_seg[]
  ** segments each, n_old_seg in all) replaced by n_new new ones, whose
  ** new_node[] nodes lie one after the other in node (n_node in all, n_seg
  ** new segments); node0 = seg0 = 0; spline = old[0] */
  int splice;
  int n_old, n_new;
  uint32_t old[2];
  size_t old_seg[2], n_old_seg;
  size_t new_node[2];
  double new_rest[2];         /* the new splines' rest lengths, mm */
  double new_len[2];          /* and lengths, mm */
  int layer;                  /* the layer of every spline involved (layers.h; 0 without layers) */
  uint64_t kept_old, kept_new; /* the segments it keeps bit for bit (the first 64 of each side;
                              ** old ones numbered through the old splines in order) */
  uint8_t kept_from[64];      /* kept new segment j: that number of its old self */
  int kept_pending;           /* the kept segments' pair samples are still to be read */
  double log_ratio;           /* the Hastings factor of a trans-dimensional kind (system.h);
                              ** 0 for the symmetric ones */
} lw_proposal;

lw_proposal *lw_proposal_new(const lw_model *m, lw_error *err);
void lw_proposal_free(lw_proposal *p);

/* Evaluates replacing n_node nodes of spline `spline` starting at local node
** node0 with `nodes` (copied into p; NULL: they are already in p->node).  Fills p->dterm and p->dE.  The
** state is not changed, but the pair term's near-field cache may be filled
** (model.c): one thread per model.  Should a near list fail to grow, the
** pair term's difference and dE are NaN: the move is rejected. */
void lw_model_propose(const lw_model *m, lw_proposal *p, uint32_t spline, size_t node0,
                      size_t n_node, const lw_node *nodes);

/* Delayed acceptance (docs/NUMERICS.md).  With p->defer_near set, a move
** whose walk found near pairs leaves their near field out: dterm and dE hold
** a cheap stand-in (near_pending = 1).  lw_model_propose_finish computes it
** and returns what it adds to dE (0 when nothing was left out), leaving
** dterm and dE bitwise what a proposal without deferral gives.  A commit
** finishes a pending proposal first.  With energy.min_spacing the spacing
** rule between the curves waits here too, for every move that passed the
** count of samples (curves_pending): +inf, crowded = 1 and dE = +inf if the
** move's curves touch more of the other strokes' segments than they did
** (docs/NUMERICS.md, "Spacing"); a commit takes the move without it. */
double lw_model_propose_finish(const lw_model *m, lw_proposal *p);

/*
** Trans-dimensional proposals: replaces the n_old <= 2 splines old[] (none
** for a birth) by n_new <= 2 new ones (none for a death), new one k of
** new_node[k] >= 2 nodes and rest length rest[k], their nodes one after the
** other in `nodes` (NULL: already in p->node), at most m->max_segments + 1
** nodes in all and as many old segments.  Every spline involved is of one
** layer (layers.h): the old ones', or `layer` for a birth.  dE is the new
** splines' energy less the old ones': their segment and spline terms, their pair sums with every other spline
** (one walk over the new samples, +1, and the old ones, -1, the old
** splines' samples left out) and with each other, their raster changes;
** forbidden and crowded as for lw_model_propose.  Birth, death, grow,
** shrink, split and join are all this one operation (sys_splines.c draws
** them, transdim.h has the proposal densities).  The commit leaves the
** replaced splines as ghosts and puts each new one into a ghost slot of its
** segment count, or at the end if there is none (slots.h): O(their
** segments), nothing else moves.
*/
void lw_model_propose_regroup(const lw_model *m, lw_proposal *p, const uint32_t *old, int n_old,
                              const lw_node *nodes, const size_t *new_node, int n_new, const double *rest,
                              int layer);

/* The one-for-one case: replaces spline `at` (remove = 1) or inserts a
** spline (remove = 0; `at` is not read) by the n_new nodes `nodes` with
** rest length `rest`, or by nothing (n_new = 0, remove = 1: a death).  An
** inserted spline is of layer `layer`, a replacing one of the replaced
** spline's (`layer` not read). */
void lw_model_propose_splice(const lw_model *m, lw_proposal *p, uint32_t at, int remove, const lw_node *nodes,
                             size_t n_new, double rest, int layer);

/* Applies an evaluated proposal (either kind).  LW_ENOMEM if the grid could
** not grow: for a move the model is as before; for a splice the caches are
** rebuilt when they can be, and the run should stop. */
lw_status lw_model_commit(lw_model *m, lw_proposal *p);

/* The same in two halves, for moves made in parallel in disjoint domains
** (domains.h): commit_part changes the state and its caches but keeps the
** changes of the running totals in p; merge adds them to the model's (a
** full refresh when a total is no longer finite, as lw_model_commit does)
** and clears them.  commit = commit_part then merge.  Merging the domains'
** scratches in a fixed order keeps the totals independent of the threads. */
lw_status lw_model_commit_part(lw_model *m, lw_proposal *p);
lw_status lw_model_merge(lw_model *m, lw_proposal *p);

/* How far the segments may come in a step that moves many (system.h
** `blocked`): per segment, the farthest any of its control points moves
** (reach) and the widest space between its pair samples where it stands
** (gap, lw_model_sample_gaps), with the largest of each. */
typedef struct {
  const double *reach, *gap;
  double reach_max, gap_max;
} lw_step_margins;

/* 1 if global segment g moved to nodes a and b in such a step could come
** closer to another stroke than energy.min_spacing and than it is: the
** spacing rule of a proposal (p->crowded), asked of one segment for the
** quench and the massless flow.  Its check points (four a pair sample,
** evenly along the curve) are measured to the other strokes' curves where
** they stand (Newton from their nearest sample; the curves within reach
** found by their samples, within min_spacing + gap / 2 + reach): a point
** within min_spacing + reach of a curve must move away from it by more than
** reach.  0 without the rule. */
int lw_model_segment_crowds(const lw_model *m, size_t g, const lw_node *a, const lw_node *b,
                            const lw_step_margins *mg);

/* gap[g] for every segment: the widest space between consecutive pair
** samples of segment g where it stands (0 without the pair term). */
void lw_model_sample_gaps(const lw_model *m, double *gap);

/* 1 if the segment from a to b, of quadrature length `length`, is regular
** for the scene: its speed never falls below scene->min_speed times its
** length, the mean speed, and its bending integrand is analytic inside the
** Bernstein ellipse of parameter scene->regularity (spline.h; each test off
** at 0), and, with the pair term's cutoff, no two consecutive pair samples
** lie more than scene->pair_gap_max apart (lw_segment_gaps_within).  A
** segment without length has no direction at all, so it is irregular
** whenever a speed or rho test is on. */
int lw_segment_allowed(const lw_scene *sc, const lw_node *a, const lw_node *b, double length);

/* LW_EINPUT naming path, the spline, the segment, its speed ratio and rho,
** and the keys energy.min_speed and energy.regularity if a segment of sp is
** irregular for the scene: states
** read from files (init.from, resume, energy) are refused rather than
** started in a forbidden state. */
lw_status lw_model_check_regular(const lw_scene *sc, const lw_splines *sp, const char *path, lw_error *err);

/* Fits the layers stored with splines read from path (spline.h) to the
** scene: dropped when it has no layers, else each checked against its
** count (LW_EINPUT naming path, the spline and [layers] names). */
lw_status lw_model_check_layers(const lw_scene *sc, lw_splines *sp, const char *path, lw_error *err);

/* Energy of a state computed from scratch, one value per term (0 for terms
** that are off); returns the total, +inf if a segment is irregular. */
double lw_energy_compute(const lw_scene *sc, const lw_splines *sp, double term[LW_TERM_COUNT],
                         lw_error *err);

/* The raster of raster term t (the tone term) for sp, built as
** lw_energy_compute builds it (a plane a layer, each layer's w * h after
** the one before), in *out (the caller frees it), and the term's energy
** with its coefficient, bit for bit lw_energy_compute's.  NAN and
** LW_ENOMEM through err. */
double lw_energy_raster(const lw_scene *sc, const lw_splines *sp, int t, int64_t **out, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
