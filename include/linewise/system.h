/*
** system.h -- a system type as a table row (in the style of gsl_rng_type
** and the schedule table): what the degrees of freedom are, and everything
** the drivers need to know about them (docs/SYSTEMS.md).
**
** The drivers -- the Metropolis chain (mc.h), the tempering ladder, step
** tuning, the run loop and its checkpoints, trace and summary (anneal.c) --
** see a system only through its row.  The division of labour:
**   the chain owns the random stream, the step of each move kind, its
**     tuning, the acceptance decision and the statistics per move kind,
**     which it knows by the row's names;
**   the system owns its state and caches, its move kinds (it draws a
**     proposal of kind k with step `step` from the chain's stream and
**     evaluates dE), commit, the running energy per term, a from-scratch
**     refresh, its part of state.lw, and its drawings.
**
** Differences from the first sketch, and why:
**   - save/load work on a section of state.lw (ckpt.h) rather than a FILE:
**     the run loop writes state.lw atomically as a whole (checkpoint.h),
**     with its own sections beside the system's; a system writes its own
**     section and reads it back.  The running energies are the run loop's
**     (by term name, in each rung's chain section); set_terms restores them.
**   - moves() reads the [moves] weights, steps and targets of the system's
**     kinds from the parameters, and move_unit[] converts a step back to the
**     unit of its key for summary.json (the rotate step is kept in radians,
**     given and reported in degrees).
**   - draw() also writes animation frames, and the state keeps what its
**     final drawing reported (pen-up travel, fidelity) for summary(), which
**     writes the system's own members of summary.json.
**   - term_on(): a term that is off has no trace column or summary member
**     (as before); its running value is 0.  energy(): the energy per term
**     of a saved state from scratch, for `linewise energy`.
**   - propose() takes the state non-const: it may fill caches (the spline
**     model's near-field cache), never the state itself.
**   - note(), describe() and files give the command line its messages, so
**     main.c names no system either.
**
** An instance is an lw_system: the row plus the state.  The set-up (for
** splines the scene: fields, boundary, quadrature, the picture) is shared
** read-only by every replica and outlives them.
**
** Adding a system is local: new files with its functions and one entry in
** lw_system_types[] (system.c); docs/SYSTEMS.md has the recipe.
*/
#ifndef LINEWISE_SYSTEM_H
#define LINEWISE_SYSTEM_H

#include <gsl/gsl_rng.h>
#include <stddef.h>
#include <stdio.h>

#include "linewise/error.h"
#include "linewise/json.h"
#include "linewise/params.h"
#include "linewise/state.h"

#ifdef __cplusplus
extern "C" {
#endif

/* At most this many move kinds, terms and observables a system (fixed arrays in the
** chain and the run loop's trace marks). */
#define LW_MOVES_MAX 10
#define LW_SYSTEM_TERMS_MAX 16
#define LW_OBSERVABLES_MAX 8

typedef struct lw_system_type lw_system_type;

/* Keys (NULL-terminated, "section.key" or "section.*") that a scene's other
** settings leave idle where `idle` is set, and why ("moves.fixed_count =
** 1"): a scene that gives one a value is noted before its run, so that a
** mistake there shows before the setting that reads it is chosen. */
typedef struct {
  const char *const *keys;
  int idle;
  const char *why;
} lw_idle_rule;
#define LW_IDLE_RULES_MAX 24

/* *forbidden of a proposal (lw_system_type.propose; 0: a move to decide).
** The chain counts each refusal apart (lw_move_stats, summary.json's
** rejected_*): a number of a row's own would be counted as what it happens
** to equal here. */
enum {
  LW_PROPOSE_IRREGULAR = 1, /* a forbidden state: a segment the quadrature cannot trust, beyond the range */
  LW_PROPOSE_OUTSIDE = 2,   /* a part outside its domain's box (propose_in) or the frame */
  LW_PROPOSE_CROWDED = 3,   /* closer to another stroke than a hard spacing rule allows */
  LW_PROPOSE_NOTHING = 4,   /* no proposal: no part free to make the move; counted nowhere */
  LW_PROPOSE_NOMEM = 5      /* not evaluated for want of memory: the chain stops (lw_chain_step < 0) */
};

struct lw_system_type {
  const char *name;                   /* [scene] system = name */
  int n_moves;                        /* move kinds, <= LW_MOVES_MAX ... */
  const char *const *move_names;      /* ... by name: trace, summary, state.lw */
  const double *move_unit;            /* step in the chain's unit per unit of its key */
  int n_terms;                        /* energy terms, <= LW_SYSTEM_TERMS_MAX ... */
  const char *const *term_names;      /* ... by name: trace columns, summary, state.lw */

  /* The scene keys the row reads, "section.key" or "section.*" (each list
  ** NULL-terminated, or NULL): under every driver, and under the dynamics
  ** or the Monte Carlo chains only (a key named there is read under drivers
  ** of that kind only, driver.h, though `keys` names its section).  The drivers' own keys (the schedule,
  ** [tempering], a run's outputs, the time step) need no listing.  A scene
  ** that gives a key the row reads under no driver a value of its own
  ** is refused before the run (anneal.c): it would change nothing, and a
  ** study that varied it would measure noise. */
  const char *const *keys;
  const char *const *keys_dynamics;
  const char *const *keys_metropolis;

  /* Optional (NULL: the row itself): the row the scene's settings choose
  ** among the system's variants (for splines and particles, those with
  ** trans-dimensional move kinds), all of one name. */
  const lw_system_type *(*variant)(const lw_params *p);
  /* Optional (NULL: none): the row's own rules for keys its other settings
  ** leave idle (a boundary's size under another boundary), noted before a
  ** run beside the drivers' rules (anneal.c); returns how many it wrote. */
  int (*idle)(const lw_params *p, lw_idle_rule rule[LW_IDLE_RULES_MAX]);

  /* The shared set-up of a scene (NULL and err set on bad input, naming the
  ** parameter's file and line), and a note for the user or "" (e.g. a
  ** picture was downsampled). */
  void *(*setup_new)(const lw_params *p, lw_error *err);
  void (*setup_free)(void *setup);
  const char *(*note)(const void *setup);
  /* Optional (NULL: no estimate): the least memory, in bytes, one replica's
  ** start will take, with in *what its size ("100 splines of 4 segments")
  ** and in *key the key that sets it ("section.key"), so that a start past the machine's
  ** memory is refused before its placement (anneal.c); 0 where unknown (a
  ** state read from a file).  In *peak the run's expected peak, its
  ** drawing's (a measured fit, with room), that a run past it is told
  ** before it anneals for hours, and in *replica what each further
  ** replica adds to it (the same); 0 where unknown. */
  double (*start_bytes)(const void *setup, const lw_params *p, char *what, size_t n, const char **key,
                        double *peak, double *replica);

  /* The initial state of a run: placed from `seed` (a stream of its own) or
  ** read from the file the parameters name; copies for the replicas. */
  void *(*state_new)(const void *setup, const lw_params *p, unsigned long seed, lw_error *err);
  void *(*state_copy)(const void *state, lw_error *err);
  void (*state_free)(void *state);

  /* Monte Carlo.  moves(): the mix weights, initial steps and acceptance
  ** targets of the n_moves kinds from the parameters.  sweep_size: proposals
  ** a sweep (0: nothing to move).  step_max: tuning never grows a step of
  ** kind k past it; 0 for a kind that has no step (a birth, say): its step
  ** is 0, never tuned, and summary.json writes null for it.  propose:
  ** draws one proposal of kind k with step `step` from rng into prop (the
  ** chain's scratch) and returns dE (NaN: undefined,
  ** rejected and counted; +inf forbidden), with *forbidden one of
  ** LW_PROPOSE_* where it is refused (LW_PROPOSE_NOTHING with dE 0 when no
  ** part is free to make a move of kind k, every particle pinned for it:
  ** no proposal, counted nowhere).  The state is not
  ** changed, but caches may be filled: one thread per state.  commit applies
  ** the last proposal (LW_ENOMEM leaves the state as it was). */
  void (*moves)(const lw_params *p, double *weight, double *step, double *target);
  size_t (*sweep_size)(const void *state);
  double (*step_max)(const void *state, int kind);
  void *(*proposal_new)(const void *state, lw_error *err);
  void (*proposal_free)(void *prop);
  double (*propose)(void *state, void *prop, int kind, double step, gsl_rng *rng, int *forbidden);
  /* Optional (NULL: sweeps draw their sites through propose): the same at a
  ** given site, 0 <= site < sweep_size, whose sites the row numbers so that
  ** neighbours in the numbering are near in memory (for splines: the node,
  ** a rigid move taking the node's spline).  A sweep then visits every site
  ** once, in order, forward or backward at random (mc.h, NUMERICS.md). */
  double (*propose_at)(void *state, void *prop, int kind, size_t site, double step, gsl_rng *rng,
                       int *forbidden);
  lw_status (*commit)(void *state, void *prop);
  /* Optional (NULL: dE comes whole): delayed acceptance.  defer(prop, on)
  ** lets the following proposals leave a costly part of dE out, returning a
  ** cheap stand-in for it; finish() replaces the stand-in of the last one by
  ** the part itself and returns the difference (0 where nothing was left
  ** out).  The chain (mc.c) turns it on at temperatures above 0, decides on
  ** propose's dE and calls finish only for a proposal that passed, deciding
  ** on what it returns a second time: the chain keeps exp(-E/T) exactly
  ** whatever the stand-in, as long as it is a function of the two states
  ** (docs/NUMERICS.md, "Delayed acceptance").  finish() may also check a
  ** constraint that only a move about to be taken needs: +inf refuses the
  ** move, counted as crowded (lw_move_stats).  *nomem = 1 where it ran out
  ** of memory: the chain stops (-inf is a move out of a forbidden state). */
  void (*defer)(void *prop, int on);
  double (*finish)(void *state, void *prop, int *nomem);
  /* Optional (NULL: a sweep is never split; domains.h, [anneal] domains):
  ** domain decomposition within a replica.  split() gives the page
  ** (x0, y0, x1, y1) and the reach of a move, the distance beyond the
  ** bounding box of what it moves (old and new) within which it reads or
  ** writes anything (pair cutoff cells, a raster's footprint), or returns why
  ** the scene cannot be split (a term that is not local).  group() gives
  ** the box of the sites that move together from `site` on (for splines
  ** the node's spline) and their count.  propose_in() is propose_at()
  ** rejecting (dE = +inf, LW_PROPOSE_OUTSIDE) a move whose box leaves `box`;
  ** commit_part() commits keeping the running totals' changes in prop,
  ** merge() adds them to the state's.  Moves in disjoint domains, more than
  ** twice the reach apart, may then run in parallel, each with its own prop. */
  const char *(*split)(const void *state, double page[4], double *reach);
  size_t (*group)(const void *state, size_t site, double box[4]);
  double (*propose_in)(void *state, void *prop, int kind, size_t site, double step, gsl_rng *rng,
                       int *forbidden, const double box[4]);
  lw_status (*commit_part)(void *state, void *prop);
  lw_status (*merge)(void *state, void *prop);
  /* With split: kinds 0 .. n_domain_moves-1 run inside the domains; the
  ** others (for splines birth, death, grow, shrink, which draw their own
  ** spline anywhere and change the storage) run serially from the chain's
  ** stream after a sweep's phases, their share of the mix of sweep_size
  ** proposals (mc.h).  0: every kind runs inside.  sites(): the sites a
  ** domain sweep visits (NULL: sweep_size), for a row whose sweep_size is
  ** a fixed count of proposals rather than its sites. */
  int n_domain_moves;
  size_t (*sites)(const void *state);
  /* Optional (NULL: a spline's, 16 init.segments init.segment_length):
  ** the least side `anneal.domains = auto` gives a domain besides 2.5
  ** reach, about a group's extent, so that few groups sit on a boundary
  ** (a group on one is not moved that sweep); 0 for groups that are points. */
  double (*domain_side)(const void *state);
  /* Optional (NULL: every proposal is symmetric): the log of the last
  ** proposal's Hastings factor, log [q(x' -> x) / q(x -> x')] with the
  ** reference measures' change folded in; the chain then accepts with
  ** probability min(1, exp(log_ratio - dE / T)).  Exactly 0 for the
  ** symmetric kinds, whose decision then stays what it always was. */
  double (*log_ratio)(const void *prop);
  /* Optional (NULL: the numbering never changes): renumbers the state's
  ** sites for locality in memory, as a function of the state alone, so that
  ** a resumed run does the same.  The run loop calls it between sweeps,
  ** every anneal.check_every sweeps, right before refresh, which rebuilds
  ** the caches; the running energies are unchanged by it. */
  lw_status (*renumber)(void *state, lw_error *err);
  /* Optional (NULL: nothing to do): called at the end of every sweep
  ** (lw_chain_sweep), before anything else reads the state; for splines
  ** with trans-dimensional moves it compacts the ghost slots away
  ** (slots.h).  LW_ENOMEM stops the run. */
  lw_status (*sweep_end)(void *state);

  /* Energies: the running total (+inf in a forbidden state), the running
  ** value of each term (n_terms values, 0 when off), whether term t is on
  ** in the set-up, and a recomputation of every cache and total from the
  ** state (lw_system_drift measures what it changed). */
  double (*total)(const void *state);
  void (*terms)(const void *state, double *term);
  int (*term_on)(const void *setup, int t);
  lw_status (*refresh)(void *state);
  /* The energy per term of a saved state (st, read from path) computed from
  ** scratch, and the total; err set (naming path) when the state is refused
  ** or memory runs out (`linewise energy`). */
  double (*energy)(const void *setup, const lw_state *st, const char *path, double *term, lw_error *err);

  /* Checkpoints (checkpoint.h): save writes the state into its own section
  ** of state.lw with the writer of ckpt.h ([system <name>] for the coldest
  ** rung, [system <name> K] for rung K); load builds a state from that
  ** section of st->doc (for splines the coldest rung's splines, already
  ** read into st->sp, are taken from there), with running energies summed
  ** afresh, messages naming path; NULL and err set when the state is
  ** refused (for splines also when an energy is not finite, naming the
  ** spline and segment).  The run loop keeps the running energies by term
  ** name in its own sections and hands them back with set_terms after
  ** checking them against the fresh ones. */
  lw_status (*save)(const void *state, lw_ckpt_writer *w, const char *section, lw_error *err);
  void *(*load)(const void *setup, lw_state *st, const char *section, const char *path, lw_error *err);
  void (*set_terms)(void *state, const double *term);

  /* Outputs: into dir the files of a run's start (LW_DRAW_START: for
  ** splines field.png, as asked), the final drawing files (LW_DRAW_FINAL),
  ** or the animation frame of a sweep >= 0; summary() writes the system's members of
  ** summary.json (sizes, what the final drawing reported); describe()
  ** text for the command line: the size (LW_DESCRIBE_SIZE, "20 splines, 80
  ** segments"), what the final drawing reported (LW_DESCRIBE_DRAWING,
  ** whole lines "linewise: ...\n", or "") or what makes a state forbidden
  ** (LW_DESCRIBE_FORBIDDEN, "a segment irregular or outside the boundary",
  ** or "" where nothing does), or what the final drawing's report left out
  ** (LW_DESCRIBE_LOST: a score memory ran short for, said as a warning under
  ** --quiet too; "" where nothing); files names the drawing files. */
  /* Gradient-based drivers (dynamics, quench; gradient.h): the state as a
  ** vector of n_coords() generalised coordinates (for splines the nodes'
  ** px py vx vy in node order), set_coords() moves the state there and
  ** recomputes every cache and running total, gradient() returns the total
  ** energy and dE/dx (+inf, g undefined, in a forbidden state), 0 for the
  ** coordinates the scene holds (pinned particles, a curve's fixed points:
  ** Monte Carlo never moves them, and neither may the quench).  NULL when a
  ** system has no gradient; a driver that needs one refuses such a scene. */
  size_t (*n_coords)(const void *state);
  void (*get_coords)(const void *state, double *x);
  lw_status (*set_coords)(void *state, const double *x, lw_error *err);
  double (*gradient)(void *state, double *g, lw_error *err);
  /* Optional (NULL: none): sets blocked[i] = 1 for the coordinates of every
  ** part of the state that coordinates x would make forbidden (for splines
  ** the nodes of a segment that would be irregular, leave the boundary or
  ** come closer than energy.min_spacing to another stroke, model.h),
  ** leaves the other entries as they were and the state unchanged; returns
  ** how many parts.  A gradient driver holds those coordinates and lets
  ** the rest move, where shortening the whole step would let one segment
  ** at a wall stop every other (dynamics.h, quench.h).  changed: NULL
  ** (ask every part), or 1 for the coordinates x changed since the previous
  ** call on the same state, each only by moving less (held back to where
  ** the state stands); then only the parts with a changed coordinate are
  ** asked, since a part that was allowed stays so when the others move
  ** less (lw_system_hold). */
  size_t (*blocked)(void *state, const double *x, unsigned char *blocked, const unsigned char *changed);
  /* Optional (NULL: none): moves the state to the minimum of its energy
  ** over the coordinates the system can solve for in one step (where the
  ** energy is quadratic in them: one linear solve), the others and the held
  ** parts where they are, and does nothing where it cannot; the quench
  ** (quench.h) calls it first, goes on from there, and calls it again after
  ** a stall for as long as it lowers the energy.
  ** Iterations alone converge slowly where the energy is stiff: L-BFGS
  ** stalled at a gradient of 379 on a refined wire whose minimum this finds
  ** to rounding. */
  lw_status (*minimize)(void *state, lw_error *err);
  /* Inertia (the dynamics driver, dynamics.h): the mass matrix M(x) of the
  ** kinetic energy T = 1/2 xdot' M(x) xdot for a density (mass per unit
  ** of the system's measure), with the coordinates the scene pins held:
  ** mass_at assembles and factors it at x, mass_solve gives v = M^-1 b (0 at
  ** held coordinates), mass_apply b = M v, mass_dx d/dx (1/2 v' M(x) v) at
  ** fixed v, mass_pinned 1 at a held coordinate.  NULL when the system has
  ** no inertia. */
  void *(*mass_new)(const void *state, const lw_params *p, double density, lw_error *err);
  void (*mass_free)(void *mass);
  lw_status (*mass_at)(void *mass, const double *x, lw_error *err);
  void (*mass_solve)(const void *mass, const double *b, double *v);
  void (*mass_apply)(const void *mass, const double *v, double *b);
  void (*mass_dx)(const void *mass, const double *x, const double *v, double *out);
  int (*mass_pinned)(const void *mass, size_t i);
  /* Optional (NULL: none): where the energy is quadratic, its Hessian K
  ** constant, factors a M + b K with the held coordinates held and sets
  ** *done = 1 (0, nothing factored, where the row cannot at this state);
  ** mass_shift_solve then gives v = (a M + b K)^-1 b, 0 at held
  ** coordinates.  The review's implicit scheme (dyn_review.h) takes only a
  ** row that has it, and solves with it in one iteration a step at any dt
  ** (conjugate gradients preconditioned by M alone needed a number growing
  ** as h omega_max). */
  lw_status (*mass_shift)(void *mass, double a, double b, int *done, lw_error *err);
  void (*mass_shift_solve)(const void *mass, const double *b, double *v);
  /* Optional (NULL: the coordinates are free): brings coordinates x that a
  ** step left off the system's constraint back onto it (for particles,
  ** unit quaternions): along the constraint's normal at `from`, the step's
  ** start, where from is given (RATTLE's projection), else by the shortest
  ** way; and momenta pi (NULL: none) onto its tangent at x (at from where x
  ** is NULL).  The dynamics calls it on every new position before the
  ** state moves there, so the state and the driver's coordinates agree bit
  ** for bit. */
  void (*constrain)(const void *state, const double *from, double *x, double *pi);
  /* Optional (NULL: none): what a motion that failed (dynamics.h) needs
  ** besides the shorter dynamics.dt its message asks for, or NULL; for
  ** D-NURBS, free weights without a mass of their own, which no dt helps. */
  const char *(*motion_advice)(const lw_params *p);
  /* Optional (NULL: none, and a scene that sets dynamics.dashpot or
** dashpot_angular is refused): the dampers between neighbours the scene
** names, read by mass_new; for particles the seed's beta_1 and beta_3.
** Takes the momenta pi (of that mass matrix, at the state's positions)
** through time h of the dampers alone, one pair at a time and each pair
** exactly, in the row's order of its pairs or (reverse = 1) in exactly the
** opposite order, so that a half step each way makes a symmetric step.
** Returns the kinetic energy taken (>= 0). */
  double (*damp_pairs)(const void *state, const void *mass, double h, int reverse, double *pi);

  /* Optional (NULL: none, and a scene that sets output.observables = 1 is
  ** refused): what a study reads off a state besides its energy, as
  ** trace.csv columns obs_<name> (docs/FORMATS.md): n_observables values,
  ** at most LW_OBSERVABLES_MAX, each a function of the state alone, NaN
  ** where it is undefined (a mean over no splines). */
  int n_observables;
  const char *const *observable_names;
  void (*observe)(const void *state, double *out);
  /* Optional (NULL: output.samples_every is refused): the state's degrees
  ** of freedom as CSV, a header line and a row per point (for splines
  ** spline,node,px,py,vx,vy), every number with 17 digits, for studies that
  ** read configurations (samples/sample-SSSSSS.csv, docs/FORMATS.md). */
  void (*write_sample)(const void *state, FILE *f);
  /* Optional (NULL: never): whether the scene's energy under this row is
  ** smooth enough that its quench runs to anneal.quench_tol where the scene
  ** sets no anneal.quench_stall (a run starts with 0 there, which its
  ** scene.ini keeps).  The stall rule, a share of the energy the quench has
  ** removed, is measured mostly against its first iterations' collapse: on
  ** the particles' sphere it stopped 88 above the minimum, which 1,089
  ** iterations (0.24 s) reached; a kinked energy (the particles' Gaussian
  ** weights at R) never reaches quench_tol, and needs the rule. */
  int (*quench_converges)(const lw_params *p);

  const char *files;
  lw_status (*draw)(void *state, const lw_params *p, const char *dir, long sweep, lw_error *err);
  void (*summary)(const void *state, lw_json *j);
  void (*describe)(const void *state, int what, char *buf, size_t n);
};

#define LW_DRAW_START (-2)
#define LW_DRAW_FINAL (-1)
enum { LW_DESCRIBE_SIZE, LW_DESCRIBE_DRAWING, LW_DESCRIBE_FORBIDDEN, LW_DESCRIBE_LOST };

/* One instance: the row and a state (owned). */
typedef struct {
  const lw_system_type *type;
  void *state;
} lw_system;

/* The table, NULL-terminated: splines first. */
extern const lw_system_type *const lw_system_types[];

/* The row of that name, or NULL; lw_system_names lists them for messages. */
const lw_system_type *lw_system_find(const char *name);
const char *lw_system_names(void);

/* The row the parameters name ([scene] system); NULL and LW_EINPUT naming
** the key's file and line if there is none of that name, or if the row does
** not fit (lw_system_row_fits). */
const lw_system_type *lw_system_of(const lw_params *p, lw_error *err);

/* Whether row t's move kinds, terms and observables fit the fixed arrays of
** the chain and the run loop (LW_MOVES_MAX ...); 0 and err set if not: a
** row past them would write over its neighbours and still exit 0. */
int lw_system_row_fits(const lw_system_type *t, lw_error *err);

/* An instance owning `state` (freed on failure too). */
lw_system *lw_system_wrap(const lw_system_type *type, void *state, lw_error *err);
void lw_system_free(lw_system *s);

/* The trial x1 = x + h dir of a gradient driver (dynamics.h, quench.h),
** with the coordinates of every part it would make forbidden held: marked
** in held and zeroed in dir, a round at a time, since a part held moves
** those beside it (a held segment's nodes are its neighbours' too).  The
** state must stand at x: `blocked` measures a step from where the state
** is.  Returns g . dir left, < 0 when the trial may be evaluated; 0 when
** holding took the descent, or when LW_HOLD_ROUNDS rounds still left a part
** at a wall (a shorter step holds less).  *holds counts the parts held.
** Rounds after the first ask only the parts beside the new holds. */
#define LW_HOLD_ROUNDS 8
double lw_system_hold(const lw_system_type *t, void *state, const double *x, const double *g, double *dir, double h,
                      double *x1, unsigned char *held, size_t n, long *holds);

/* The row's calls on an instance. */
static inline double lw_system_total(const lw_system *s) { return s->type->total(s->state); }

/* How far a recomputation moved the total: |sum(after) - sum(before)| over
** max(sum |after[t]|, 1), for n terms.  Against the terms' sizes, not the
** total's, since the rounding of a running sum is the terms' (terms of
** +-6e10 around a total of 3 drift 1e-5 absolute, which is 1e-16 of them);
** infinite where a sum is not finite and the two differ. */
double lw_system_drift(const double *before, const double *after, int n);

#ifdef __cplusplus
}
#endif

#endif
