/*
** transdim.h -- the proposal densities of the trans-dimensional moves
** (birth, death, grow, shrink) of the spline system, and the reference
** measure their acceptance is taken against (docs/NUMERICS.md,
** "Trans-dimensional moves", has the derivation).
**
** Target: a state is a set of N splines; spline i with n_i segments has
** n_i + 1 nodes.  Its density, against the Poisson reference measure of
** sets (docs/NUMERICS.md), is
**     f(x) = prod_i q_{n_i}(x_i) exp(-E(x) / T),
** where q_n, the prior of a spline's shape, is the density of the
** placement kernel below: node 0 as a birth draws it, each later node from
** the one before as a grow at the tail draws it.  Each q_n is a probability
** density (a product of normalised conditionals), so with only the
** chemical potential mu_s on, N is Poisson with mean K exp(-mu_s / T), K
** the number of segment counts the chain can reach (1 without grow and
** shrink, max_segments with them), and each n_i is uniform over them.
** The prior is part of the target: the moves that keep the count (point,
** vector, translate, rotate) carry its ratio q(x') / q(x) as their
** Hastings factor, births and tail grows propose from it exactly (it
** cancels), head grows and shrinks carry what is left.  It is what the
** drawing would be without its energy: lines along the field.
**
** Proposals (each node from the last, "along the field"):
**   birth  p_0 from pi: with a picture (scene.image, not white) the mixture
**          pi(p) = b / (W H) + (1 - b) d(p) / (D a^2), b =
**          moves.birth_uniform, d(p) = 1 - tone of p's pixel, D the sum of
**          d over the pixels, a the pixel side: a uniform point on the page
**          with probability b, else a point drawn as placement draws a
**          centre (lw_init_dark_point); without one pi = 1 / (W H);
**          v_0 = (l/3) u + N(0, s_v^2) with u the
**          field's direction at p_0 either way (probability 1/2 each), or,
**          where there is no field, a uniform direction (v_0 then has the
**          density of a Gaussian ring, with a Bessel I0); then node k+1
**          from node k as for grow at the tail, for the segment count
**          lw_td_birth_size draws.
**   grow   at the tail (dir = +1) after node a: p ~ N(p_a + 3 v_a, s_p^2),
**          v ~ N((l/3) u(p), s_v^2), u the field's direction at p turned
**          to agree with v_a (the direction of v_a where the field is off
**          or vanishes, 0 where v_a is 0 too); at the head (dir = -1)
**          before node a: p ~ N(p_a - 3 v_a, s_p^2), v likewise (vectors
**          keep pointing from node 0 to node n).
**   l = init.segment_length, s_p = l / 4, s_v = l / 12.  Every density is
**   returned as a logarithm, so nothing under- or overflows.
*/
#ifndef LINEWISE_TRANSDIM_H
#define LINEWISE_TRANSDIM_H

#include <gsl/gsl_rng.h>

#include "linewise/scene.h"
#include "linewise/spline.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  const lw_scene *scene;
  double *cum;            /* the picture's cumulated row darkness (lw_init_darkness; owned),
                             NULL without a picture or for a white one: pi uniform */
  double uniform;         /* b: the share of uniform first points with a picture */
  double dark_scale;      /* (1 - b) / (D a^2), 1 / mm^2 */
  double length;          /* l: mm */
  double sigma_p, sigma_v; /* mm */
  size_t birth_segments;  /* segments of most born splines */
  size_t max_segments;    /* grow stops here */
  double spread;          /* share of births of another segment count (moves.birth_spread) */
} lw_td;

/* LW_ENOMEM if the picture's darkness table cannot be had.  spread in
** [0, 1): the share of births whose segment count is drawn uniformly from
** 1 .. max_segments other than birth_segments; sd > 0: sigma_p in units of
** length (moves.prior_sd), sigma_v a third of it. */
lw_status lw_td_init(lw_td *td, const lw_scene *sc, size_t birth_segments, double length, size_t max_segments,
                     double uniform, double spread, double sd);
void lw_td_clear(lw_td *td);

/* log q_{n-1} of the n >= 1 nodes nd (-inf when node 0 is off the page). */
double lw_td_prior(const lw_td *td, const lw_node *nd, size_t n);

/* log of node 0's factor of the prior: log pi(p) + log of v's density as
** a birth draws it. */
double lw_td_first_log(const lw_td *td, const lw_node *n0);

/* The change of log q when node k of the n nodes nd becomes *to. */
double lw_td_prior_change(const lw_td *td, const lw_node *nd, size_t n, size_t k, const lw_node *to);

/* The segment count of a birth: birth_segments with probability
** 1 - spread, else one of the other counts 1 .. max_segments uniformly.
** With spread 0 it draws nothing from rng, so a chain without the spread
** keeps its stream.  lw_td_size_log: the log of that law at n (-inf where
** it is 0), the factor a birth's and a death's Hastings ratios carry. */
size_t lw_td_birth_size(const lw_td *td, gsl_rng *rng);
double lw_td_size_log(const lw_td *td, size_t n);

/* Draws a born spline of n segments (n + 1 nodes) into nd from the prior. */
void lw_td_birth_draw(const lw_td *td, gsl_rng *rng, size_t n, lw_node *nd);

/* The rest length of a spline of n_old segments and rest length `rest`
** after a grow or shrink to n_new: n_new l plus the spline's own excess
** rest - n_old l, so that a grow undone by a shrink gives the rest length
** back whatever it was (loaded splines may have any), exactly when the
** excess is 0 (births: n l).  NAN if it would not be positive: the move is
** refused, and its reverse, from a rest length that is not positive,
** cannot happen either. */
double lw_td_rest(const lw_td *td, double rest, size_t n_old, size_t n_new);

/* 1 if a spline of n segments has rest length n l exactly, as births, and
** the grows and shrinks of what they make, leave it: only those split and
** join (docs/NUMERICS.md), so that a split's pieces (n l each) joined
** again give the rest length back, and a join of two undone likewise. */
int lw_td_plain(const lw_td *td, size_t n, double rest);

/* 1 if a death may remove a spline of n segments and rest length `rest`:
** a birth could have made it (a segment count births draw, rest length
** n l exactly); the reverse density is 0 for the others. */
int lw_td_mortal(const lw_td *td, size_t n, double rest);

/* Draws the node beyond `end` (dir +1: after it, -1: before it) into out;
** returns log g.  lw_td_next_log: log g of a given node. */
double lw_td_next_draw(const lw_td *td, const lw_node *end, int dir, gsl_rng *rng, lw_node *out);
double lw_td_next_log(const lw_td *td, const lw_node *end, int dir, const lw_node *nd);

#ifdef __cplusplus
}
#endif

#endif
