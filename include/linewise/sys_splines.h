/*
** sys_splines.h -- the spline system, the first row of lw_system_types
** (system.h): cubic Bezier splines (spline.h) with their model (model.h) on
** a scene (scene.h).
**
** Set-up: the scene built from the parameters and the picture's tone on the
** page (fidelity, previews).  State: one model, which owns its splines.
** Move kinds, in this order: point and vector (one node's p_k or v_k by a
** Gaussian step in x and y), translate and rotate (a whole spline rigidly,
** by a Gaussian offset, or by a Gaussian angle about the mean of its points,
** which the rotation leaves in place, so every proposal is symmetric).  The
** [moves] keys name them; the rotate step is given in degrees.  With
** moves.fixed_count = 0 four more: birth, death, grow and shrink
** (transdim.h), whose acceptance carries a Hastings factor (log_ratio);
** with moves.split or moves.join > 0 also split and join.
**
** In state.lw the system keeps the splines in its section [system splines]
** ([system splines K] for rung K); the run loop keeps the running value of
** every term by name (checkpoint.h).
*/
#ifndef LINEWISE_SYS_SPLINES_H
#define LINEWISE_SYS_SPLINES_H

#include "linewise/model.h"
#include "linewise/system.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { LW_MOVE_POINT, LW_MOVE_VECTOR, LW_MOVE_TRANSLATE, LW_MOVE_ROTATE, LW_MOVE_KINDS } lw_move_kind;

/* The trans-dimensional kinds (transdim.h), after the four: a scene with
** moves.fixed_count = 0 gets the row lw_system_splines_td, which has all
** eight; the default row keeps four, so that traces, summaries and
** state.lw stay as they were. */
enum { LW_MOVE_BIRTH = LW_MOVE_KINDS, LW_MOVE_DEATH, LW_MOVE_GROW, LW_MOVE_SHRINK, LW_MOVE_KINDS_TD };

/* Split and join, after the eight: only the row lw_system_splines_tdj,
** which a scene gets with moves.split or moves.join > 0, has them, so that
** scenes without them keep the traces, summaries and random draws of the
** eight-kind row. */
enum { LW_MOVE_SPLIT = LW_MOVE_KINDS_TD, LW_MOVE_JOIN, LW_MOVE_KINDS_TDJ };

extern const char *const lw_move_names[LW_MOVE_KINDS];

extern const lw_system_type lw_system_splines;
extern const lw_system_type lw_system_splines_td;
extern const lw_system_type lw_system_splines_tdj;

/* The spline row the parameters ask for: four kinds with a fixed count,
** eight with trans-dimensional moves, ten with split or join too. */
const lw_system_type *lw_splines_row(const lw_params *p);

/* An instance on a model the caller keeps (tests, benchmarks): freeing it
** leaves the model; it has no set-up, so it does not draw. */
lw_system *lw_splines_view(lw_model *m, lw_error *err);

/* The model of a spline instance. */
lw_model *lw_splines_model(const lw_system *s);

#ifdef __cplusplus
}
#endif

#endif
