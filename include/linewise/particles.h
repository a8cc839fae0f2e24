/*
** particles.h -- the oriented-particle system: particles in 3-D, each a
** position and a unit quaternion whose local z axis is the particle's normal
** (shared/seeds/oriented-particle-surfaces.txt; docs/NUMERICS.md,
** "Oriented particles").
**
** Energy: the pair terms of particles_pair.h over every pair closer than the
** range R, plus per particle
**
**   gravity    g z_i
**   boundary   alpha_B / d_i^2, d_i = z_i - boundary_z (plane) or
**              boundary_radius - |x_i| (sphere); d_i <= 0 is forbidden
**              (+infinity), whatever alpha_B (0: a hard wall)
**
** Each term is off (and costs nothing) when its coefficient is 0.
**
** Moves (lw_particles_move): translate adds a Gaussian step (standard
** deviation `step`, length) to each coordinate of one particle; rotate turns
** one particle's quaternion by an angle drawn from N(0, step) (radians) about
** a uniformly random axis, q <- dq q.  Both are symmetric: the reverse move
** (the opposite step, the same axis with the opposite angle) has the same
** density, so Metropolis needs no Hastings factor.  A move picks its particle
** uniformly among those free for its kind (pinned ones never move); when
** none is free there is no proposal, counted nowhere (it counted as an
** accepted identity).  A sweep is one draw per particle that has at least
** one free degree of freedom.
**
** dE of a move comes from the moved particle's neighbours only: a 3-D cell
** grid (grid.h) of cubes of side >= R over a box fixed by the set-up (the
** pattern, the points and the boundary, padded by R), so the grid and the
** order in which neighbours are summed depend on positions alone, never on
** the history: a state rebuilt from a checkpoint sums in the same order.
** Particles outside the box fall into its edge cells (still correct).
**
** Invariant (tested): after any sequence of commits the running totals equal
** lw_particles_energy of the state within 1e-9 relative.
**
** The API maps one-to-one onto the row of the system table
** (src/sys_particles.c, system.h): setup_new / setup_free, state_new (lw_particles_new),
** state_copy / state_free, sweep_size, step_max, proposal_new / free,
** propose, commit, total, terms, term_on, refresh; save / load as lines of
** the in-memory state.lw and energy (load, then lw_particles_energy) in
** particles_io.h; draw (final.ply, final.png) in particles_draw.h; the
** gradient-based members (n_coords, get_coords, set_coords, gradient,
** constrain) at the end of this file, the mass matrix in sys_particles.c.  The move
** kinds' [moves] keys are translate and rotate (step_translate, length;
** step_rotate, degrees).
*/
#ifndef LINEWISE_PARTICLES_H
#define LINEWISE_PARTICLES_H

#include <gsl/gsl_rng.h>
#include <stddef.h>
#include <stdint.h>

#include "linewise/error.h"
#include "linewise/grid.h"
#include "linewise/params.h"
#include "linewise/particles_pair.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { LW_PMOVE_TRANSLATE, LW_PMOVE_ROTATE, LW_PMOVE_KINDS } lw_particles_move;

/* With births and deaths (particles.birth, particles.death; particles_grow.h)
** two more kinds follow the moves of a fixed count. */
enum { LW_PMOVE_BIRTH = LW_PMOVE_KINDS, LW_PMOVE_DEATH, LW_PMOVE_ALL };

extern const char *const lw_particles_move_names[LW_PMOVE_ALL];

/* Pin flags of a particle. */
#define LW_PIN_POSITION 1
#define LW_PIN_ORIENTATION 2

/* The read-only set-up every replica shares: the energy's constants, the
** placement and the points of the point file, the grid's box, the preview. */
typedef struct {
  lw_ppair_ctx pair;
  double gravity;               /* energy / length */
  int boundary;                 /* LW_PBOUNDARY_* */
  double boundary_z, boundary_radius; /* length */
  double alpha_b;               /* energy length^2 */
  /* placement */
  int pattern;                  /* LW_PPATTERN_* */
  size_t count;                 /* particles of the pattern */
  double size;                  /* the pattern's extent, resolved (never 0), length */
  double noise;                 /* length */
  double normal_noise;          /* radians */
  size_t n_points;              /* particles of the point file */
  double *point;                /* 3 n_points: positions (owned) */
  double *point_normal;         /* 3 n_points: unit normals, (0, 0, 1) where none was given */
  unsigned char *point_pin;     /* n_points: pin flags */
  /* grid box */
  double lo[3], extent[3];      /* length */
  /* births and deaths (particles_grow.h) */
  double chem;                  /* energy per particle */
  double birth, death;          /* mix weights; both 0: the count is fixed */
  size_t max_count;             /* births stop there */
  char note[192];               /* for the command line before the run, or "" */
  /* preview */
  double view[3];               /* unit vector toward the viewer */
  int png_size;                 /* pixels */
  double disc;                  /* disc radius, length */
} lw_particles_setup;

/* From the [particles] section (and the scene file's directory for the
** point file).  LW_EINPUT for a bad point file (file:line and what was
** expected) or keys that disagree (naming where they were set). */
lw_particles_setup *lw_particles_setup_new(const lw_params *p, lw_error *err);
void lw_particles_setup_free(lw_particles_setup *s);

/* 1 if a particle at x would be outside the boundary (forbidden). */
int lw_particles_outside(const lw_particles_setup *s, const double x[3]);

/* One state: the particles, their normals, the grid and the running totals. */
typedef struct {
  const lw_particles_setup *setup; /* not owned */
  size_t n;
  double *x;                    /* 3n positions, length */
  double *q;                    /* 4n unit quaternions {w, x, y, z} */
  double *nrm;                  /* 3n normals: lw_quat_normal of q, kept in step */
  unsigned char *pin;           /* n pin flags */
  size_t cap;                   /* room in the arrays, >= n (births grow it) */
  uint32_t *movable[LW_PMOVE_KINDS]; /* the particles free for each move kind */
  size_t n_movable[LW_PMOVE_KINDS];
  uint32_t *loose;              /* the particles with no pin flag: those a death may take */
  size_t n_loose;
  size_t n_sweep;               /* particles with a free degree of freedom */
  lw_cellgrid *grid;            /* positions by cell (x, y, z, index) */
  double term[LW_PTERM_COUNT];  /* running totals */
  double *qlen;                 /* n: |q| as last given to set_coords (NULL: never; 1 for a unit one) */
} lw_particles;

/* LW_EINPUT, with *key the [particles] key to blame ("points", "size" or
** "boundary_z"), when the start cannot lie inside the boundary: a point of
** the point file outside it, a plane or sphere pattern whose sites (before
** their noise) reach it, a cloud wholly below a floor (a cloud draws its
** places inside).  Called before lw_particles_new, whose own refusal of a
** particle outside names only the particle. */
lw_status lw_particles_check_start(const lw_particles_setup *s, const char **key, lw_error *err);

/* The initial state: the point file's particles, then `count` placed by the
** pattern from an mt19937 stream seeded with seed.  LW_EINPUT when a
** particle starts outside the boundary or two coincide (infinite energy);
** *key (may be NULL) names the [particles] key to blame when the pattern
** found no room inside the boundary, else NULL. */
lw_particles *lw_particles_new(const lw_particles_setup *s, unsigned long seed, const char **key, lw_error *err);

/* A state of n particles at x (3n) with quaternions q (4n, unit within
** 1e-9: they are renormalised) and pin flags (NULL: none pinned).
** LW_EINPUT for a non-finite value, a quaternion that is not unit, a
** particle outside the boundary or an infinite energy. */
lw_particles *lw_particles_new_from(const lw_particles_setup *s, size_t n, const double *x, const double *q,
                                    const unsigned char *pin, lw_error *err);

lw_particles *lw_particles_copy(const lw_particles *p, lw_error *err);
void lw_particles_free(lw_particles *p);

/* The energy of the state from scratch, per term (pure; the order of the
** sums is fixed by the positions). */
void lw_particles_energy(const lw_particles *p, double term[LW_PTERM_COUNT]);

/* 1 if term t (lw_pterm) is on: its coefficient is not 0 (the boundary
** term: alpha_b, on a plane or sphere wall). */
int lw_particles_term_on(const lw_particles_setup *s, int t);

/* The running totals and their sum. */
void lw_particles_terms(const lw_particles *p, double term[LW_PTERM_COUNT]);
double lw_particles_total(const lw_particles *p);

/* Recomputes the totals from scratch; drift (if not NULL) receives
** |new - old| / max(|new|, 1) of the sums. */
lw_status lw_particles_refresh(lw_particles *p, double *drift);

/* Proposals per sweep, and the largest step tuning may reach per kind (the
** box's diagonal for translate, pi for rotate). */
size_t lw_particles_sweep_size(const lw_particles *p);
double lw_particles_step_max(const lw_particles *p, int kind);

/* Scratch for one proposal (one per chain). */
typedef struct {
  int kind;
  int identity;                 /* 1: nothing was free to move */
  uint32_t k;                   /* the moved particle */
  double x[3], q[4], n[3];      /* its new position, quaternion and normal */
  double dterm[LW_PTERM_COUNT];
  double dE;
  double acc[LW_PTERM_COUNT];   /* domains: the changes lw_particles_commit_part kept */
  double log_ratio;             /* a birth's or death's Hastings factor (system.h); 0 for the others */
} lw_particles_prop;

lw_particles_prop *lw_particles_prop_new(const lw_particles *p, lw_error *err);
void lw_particles_prop_free(lw_particles_prop *pr);

/* Draws a move of kind `kind` with step `step` from rng and returns its dE
** (also in pr->dE); +inf with *forbidden = 1 when it would leave the
** boundary (forbidden may be NULL).  The state is not changed. */
double lw_particles_propose(const lw_particles *p, lw_particles_prop *pr, int kind, double step, gsl_rng *rng,
                            int *forbidden);

/* Evaluates moving particle k to position x (3) with quaternion q (4, unit)
** into pr: the propose step without the random draw (tests, tools). */
double lw_particles_evaluate(const lw_particles *p, lw_particles_prop *pr, uint32_t k, const double x[3],
                             const double q[4], int *forbidden);

/* Applies an evaluated proposal (births and deaths too).  LW_ENOMEM if the
** grid or the arrays could not grow (the state is unchanged then). */
lw_status lw_particles_commit(lw_particles *p, const lw_particles_prop *pr);

/* The energies per term of a particle at x with normal n against every
** particle but `skip` (UINT32_MAX: none), and its own terms (gravity, wall;
** not chem), added to e; 1 (e's boundary term not set) if x is outside the
** boundary. */
int lw_particles_site_energy(const lw_particles *p, uint32_t skip, const double x[3], const double n[3],
                             double e[LW_PTERM_COUNT]);

/* Calls visit(ctx, skip, j, r, d2) for every particle j != skip closer to x
** than the range, r = x_j - x, d2 = |r|^2, in the walk's fixed order (the
** visitor of lw_particles_each_pair; skip UINT32_MAX: none). */
void lw_particles_near(const lw_particles *p, uint32_t skip, const double x[3],
                       void (*visit)(void *ctx, size_t i, size_t j, const double r[3], double d2), void *ctx);

/* ---- domains (domains.h, [anneal] domains) ----
** Sites are the particles 0 .. n-1, each its own group (a point).
** propose_in draws a move of particle `site` (the identity where it is
** pinned for that kind) and refuses one whose new position leaves
** box = {x0, y0, x1, y1} (dE = +inf, *forbidden = 2); commit_part commits
** keeping the running totals' changes in pr->acc, which merge adds to the
** state's.  A move reads the cells within the range of its old and new
** places and writes those it leaves and enters: within two cell sides of
** the box, the reach split() gives. */
double lw_particles_propose_in(const lw_particles *p, lw_particles_prop *pr, int kind, size_t site, double step,
                               gsl_rng *rng, int *forbidden, const double box[4]);
lw_status lw_particles_commit_part(lw_particles *p, lw_particles_prop *pr);
void lw_particles_merge(lw_particles *p, lw_particles_prop *pr);

/* ---- the gradient-based drivers (quench.h, dynamics.h) ----
** The state as LW_PARTICLE_COORDS coordinates a particle: x y z, then the
** quaternion w x y z.  The energy is read at q / |q| (a quaternion within
** LW_PARTICLE_UNIT_TOL of unit length as it is), so its gradient along q is
** 0 and a quench may leave the sphere; set_coords stores q / |q|.  A pinned
** part's gradient is 0 and set_coords leaves it as it is, to the bit.  With the isotropic
** inertia of the seed, |omega| = 2 |dq/dt| on the sphere: the kinetic energy
** is 1/2 (4 I) |dq/dt|^2, a constant mass for the quaternion's coordinates,
** and constrain() brings a driver's coordinates back to the sphere (and its
** momenta to its tangent) after each step (docs/NUMERICS.md). */
#define LW_PARTICLE_COORDS 7
#define LW_PARTICLE_UNIT_TOL 1e-12

size_t lw_particles_n_coords(const lw_particles *p);
void lw_particles_get_coords(const lw_particles *p, double *c);
/* Moves the state to c and sums its energy afresh (+inf in the totals where
** a particle is outside the boundary).  LW_EINPUT for a coordinate that is
** not finite or a quaternion of length 0, LW_ENOMEM. */
lw_status lw_particles_set_coords(lw_particles *p, const double *c, lw_error *err);
/* The total energy and its gradient by the coordinates into g (+inf, g
** untouched, in a forbidden state; NAN with err set when memory runs out). */
double lw_particles_gradient(const lw_particles *p, double *g, lw_error *err);
/* The row's constrain (system.h): unit quaternions in c (when not NULL),
** brought back along from's (when not NULL) or by normalising; momenta pi
** (when not NULL) onto the tangent at c, or at from where c is NULL.
** Pinned orientations are untouched. */
void lw_particles_constrain(const lw_particles *p, const double *from, double *c, double *pi);
/* Calls visit(ctx, i, j, r, d2) for every pair i < j closer than the
** range, r = x_j - x_i and d2 = |r|^2: in the order of the energy's sum,
** or with reverse = 1 in exactly the reverse order (the dynamics' pair
** dampers go one way for the first half of a step and back for the
** second, which keeps the step symmetric). */
void lw_particles_each_pair(const lw_particles *p, int reverse,
                            void (*visit)(void *ctx, size_t i, size_t j, const double r[3], double d2), void *ctx);

#ifdef __cplusplus
}
#endif

#endif
