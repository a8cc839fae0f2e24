/*
** sys_splines.c -- the spline system's row (sys_splines.h): the model,
** scene and placement behind the seam of system.h.
*/
#include "linewise/sys_splines.h"

#include <gsl/gsl_math.h>
#include <gsl/gsl_randist.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/checkpoint.h"
#include "linewise/drawing.h"
#include "linewise/driver.h"
#include "linewise/fieldview.h"
#include "linewise/gradient.h"
#include "linewise/hilbert.h"
#include "linewise/init.h"
#include "linewise/output.h"
#include "linewise/splmass.h"
#include "linewise/transdim.h"

const char *const lw_move_names[LW_MOVE_KINDS] = {"point", "vector", "translate", "rotate"};
static const char *const move_names_td[LW_MOVE_KINDS_TDJ] = {"point", "vector", "translate", "rotate", "birth",
                                                             "death", "grow",  "shrink", "split",  "join"};
/* steps are kept in mm and radians; [moves] step_rotate is in degrees; the
** trans-dimensional kinds have no step (their proposals are transdim.h's) */
static const double move_unit[LW_MOVE_KINDS_TDJ] = {1.0, 1.0, 1.0, M_PI / 180.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0};

typedef struct {
  lw_scene scene;
  lw_grid2d *tone;               /* the picture's tone on the page, or NULL */
  lw_td td;                      /* the trans-dimensional proposals (scene.transdim) */
  double log_w[6];               /* log of the birth, death, grow, shrink, split, join
                                    weights: the Hastings factors need their ratios */
  double join_r2;                /* the join radius squared, mm^2 */
  size_t td_sweep;               /* proposals a sweep with trans-dimensional moves */
} spl_setup;

typedef struct {
  const spl_setup *setup;        /* NULL for a view */
  lw_model *m;
  int owns_model;                /* 0 for a view */
  lw_drawing_report drawing;     /* of the last final drawing */
  lw_node *grad;                 /* the gradient's scratch, allocated by the first
                                    gradient() call: none on a Monte Carlo run */
  size_t grad_cap;               /* its nodes: births and grows add nodes between calls */
  double *margin;                /* blocked's reach and gap, one each a segment (none
                                    without a gradient driver and energy.min_spacing) */
  size_t margin_n;               /* their segments */
  /* split and join: the live splines' ends by cells of the join radius, and
  ** the splines that may split, as of the state m->serial (every commit
  ** changes it); built again when a split or join finds it stale */
  struct {
    int built;
    uint64_t serial;
    double side;                 /* the join radius, mm */
    int nx, ny;
    uint32_t *start;             /* nx ny + 1: where each cell's entries begin */
    uint32_t *entry;             /* spline << 1 | end (1: the tail), by cell, in slot order */
    uint32_t *split;             /* the splines that may split, in slot order */
    uint32_t *near;              /* scratch: the ends a scan finds */
    size_t n_split, cap_cells, cap_entry, cap_split, cap_near;
  } ends;
} spl_state;

static void setup_free(void *setup)
{
  spl_setup *su = setup;
  if (!su) return;
  lw_grid2d_free(su->tone);
  lw_td_clear(&su->td);
  lw_scene_clear(&su->scene);
  free(su);
}

/* A rigid move (translate, rotate) takes every segment of its spline along,
** where a point move takes two, so on long splines the rigid moves cost the
** rest of the sweep many times over, and a sweep grows as the square of the
** segments (one spline of 8000 segments: 25 s a sweep with the default
** weights, 0.2 s without).  Said before the run where the rigid moves' share
** of the proposals times the segments is 18 or more (20 times the point and
** vector moves at the default weights; every move, where they are all). */
static void long_splines_note(const lw_params *p, char *note, size_t n)
{
  const double rigid = p->mix_translate + p->mix_rotate, all = rigid + p->mix_point + p->mix_vector;
  if (lw_driver_is_motion(p) || p->from[0] || p->sweeps <= 0 || !(rigid > 0.0) ||
      rigid / all * p->segments < 18.0)
    return;
  size_t used = strlen(note);
  if (used < n)
    snprintf(note + used, n - used, "%sinit.segments = %d: the rigid moves (moves.translate and rotate), %.0f %% of "
             "the proposals, each take all %d segments of their spline along where a point move takes two, so a sweep "
             "grows as the square of the segments; give moves.translate and moves.rotate a small share for long "
             "splines (docs/PERFORMANCE.md, \"Scaling\")", used ? "\n" : "", p->segments, 100.0 * rigid / all,
             p->segments);
}

/* The run's peak, at its drawing, for `segments` segments: a fit to 64
** measured runs (docs/PERFORMANCE.md, "Memory"): 4 MB, 615 bytes a segment,
** 39 a point of the close share (which reads the lines every half pen
** width), 57 a picture pixel (and 8 more a layer; 2 more since the
** scores' missed marks, 2026-12-07, not measured but counted), 3.2 a pixel
** of final.png; with room for the worst miss held out (16 %, a four-pen
** picture), 1.3 times that and 10 MB more. */
static double drawing_peak(const spl_setup *su, const lw_params *p, double segments)
{
  const lw_scene *sc = &su->scene;
  const double points = segments * p->segment_length / (0.5 * p->pen_width);
  double pixels = 0.0, png = 0.0;
  if (sc->image) pixels = (double)sc->image->width * sc->image->height * (1.0 + 0.14 * sc->layers.n);
  const double longest = fmax(sc->width, sc->height), k = fmin(p->png_scale, LW_OUTPUT_PNG_MAX_PX / longest);
  if (longest > 0.0 && k > 0.0) png = sc->width * k * sc->height * k;
  return 1.3 * (4e6 + 615.0 * segments + 38.7 * points + 59.0 * pixels + 3.2 * png) + 10e6;
}

/* Under the least a segment's model was measured to take at its peak
** (docs/PERFORMANCE.md: 361 to 865 bytes), so that what would fit is never
** refused. */
#define SEGMENT_BYTES_LEAST 360.0

/* What a further tempering replica adds to the peak, a segment: 494 bytes
** measured on minimal.ini, 745 under the photo preset (docs/PERFORMANCE.md,
** "Memory"), with the drawing's room of 1.3 times the most.  The least
** above counted for it, and a run of 16 replicas annealed to its end past
** the memory, unwarned, then failed at its drawing. */
#define REPLICA_SEGMENT_BYTES 970.0

/* (system.h) The placed splines' model: 1e8 splines filled 3 GB in 15 s
** without a word, on their way to 160 GB, and a coverage's count was shown
** only once placed. */
static double start_bytes(const void *setup, const lw_params *p, char *what, size_t n, const char **key,
                          double *peak, double *replica)
{
  const spl_setup *su = setup;
  size_t count = (size_t)p->splines;
  lw_error e2; /* a count the placement refuses is refused there, with its own message */
  *peak = *replica = 0.0;
  if (p->from[0] || (!count && lw_init_count(&su->scene, p, &count, &e2))) return 0.0;
  *peak = drawing_peak(su, p, (double)count * p->segments);
  *replica = REPLICA_SEGMENT_BYTES * (double)count * p->segments;
  snprintf(what, n, "%zu splines of %d segments%s (%.0f bytes a segment at least)", count, p->segments,
           p->splines ? "" : " (from init.coverage)", SEGMENT_BYTES_LEAST);
  *key = p->splines ? "init.splines" : "init.coverage";
  return SEGMENT_BYTES_LEAST * (double)count * p->segments;
}

static void *setup_new(const lw_params *p, lw_error *err)
{
  spl_setup *su = calloc(1, sizeof *su);
  if (!su) {
    lw_error_set(err, LW_ENOMEM, "out of memory for a scene");
    return NULL;
  }
  if (lw_scene_init(&su->scene, p, err)) goto fail;
  lw_drawing_note(p, su->scene.note, sizeof su->scene.note);
  long_splines_note(p, su->scene.note, sizeof su->scene.note);
  /* the target of the fidelity score and the previews' underlay */
  if (su->scene.image && !(su->tone = lw_image_tone_grid(su->scene.image, &su->scene.image_place, err)))
    goto fail;
  if (lw_td_init(&su->td, &su->scene, (size_t)p->segments, p->segment_length, su->scene.max_segments,
                 p->birth_uniform, p->birth_spread, p->prior_sd)) {
    lw_error_set(err, LW_ENOMEM, "out of memory for the birth prior's darkness table");
    goto fail;
  }
  const double w[6] = {p->mix_birth, p->mix_death, p->mix_grow, p->mix_shrink, p->mix_split, p->mix_join};
  for (int k = 0; k < 6; k++) su->log_w[k] = log(w[k]);
  su->join_r2 = gsl_pow_2(p->join_radius * p->segment_length);
  if (su->scene.transdim) {
    size_t n = 0;
    if (lw_init_count(&su->scene, p, &n, err)) goto fail;
    su->td_sweep = n * (size_t)(p->segments + 1);
    if (su->td_sweep < (size_t)p->segments + 1) su->td_sweep = (size_t)p->segments + 1;
  }
  return su;
fail:
  setup_free(su);
  return NULL;
}

static const char *note(const void *setup) { return ((const spl_setup *)setup)->scene.note; }

/* A state owning model m (freed on failure). */
static spl_state *state_of(const spl_setup *su, lw_model *m, int owns, lw_error *err)
{
  if (!m) return NULL;
  spl_state *s = calloc(1, sizeof *s);
  if (!s) {
    if (owns) lw_model_free(m);
    lw_error_set(err, LW_ENOMEM, "out of memory for a state");
    return NULL;
  }
  s->setup = su;
  s->m = m;
  s->owns_model = owns;
  return s;
}

static void state_free(void *state)
{
  spl_state *s = state;
  if (!s) return;
  if (s->owns_model) lw_model_free(s->m);
  free(s->grad);
  free(s->margin);
  free(s->ends.start);
  free(s->ends.entry);
  free(s->ends.split);
  free(s->ends.near);
  free(s);
}

/* Renumbers sp along the Hilbert curve of the page (hilbert.h): sweeps go
** node after node (mc.h), so splines near on the page are then near in
** memory too.  1 if the numbering changed, 0 if not, -1 out of memory. */
static int along_curve(const lw_scene *sc, lw_splines *sp, lw_error *err)
{
  size_t *order = malloc((sp->n_splines ? sp->n_splines : 1) * sizeof *order);
  if (!order) {
    lw_error_set(err, LW_ENOMEM, "out of memory renumbering %zu splines", sp->n_splines);
    return -1;
  }
  int moved = lw_hilbert_order(sp, 0.0, 0.0, sc->width, sc->height, order, err);
  if (moved > 0 && lw_splines_permute(sp, order, err)) moved = -1;
  free(order);
  return moved;
}

/* A model on sp (owned) after checking that the splines read from path are
** allowed for the scene and that their energy is finite (where: path and
** the section, for that message); renumbered along the page's curve if
** renumber, after the checks, whose messages count splines as the file
** does. */
static spl_state *state_from_file(const spl_setup *su, lw_splines *sp, const char *path, const char *where,
                                  int renumber, lw_error *err)
{
  if (lw_model_check_regular(&su->scene, sp, path, err) || lw_model_check_layers(&su->scene, sp, path, err)) {
    lw_splines_free(sp);
    return NULL;
  }
  /* the file's numbering kept for the finite check's message (the totals
  ** do not depend on it) */
  lw_splines *as_read = renumber ? lw_splines_clone(sp) : NULL;
  if (renumber && !as_read) lw_error_set(err, LW_ENOMEM, "out of memory reading %s", path);
  if (renumber && (!as_read || along_curve(&su->scene, sp, err) < 0)) {
    lw_splines_free(as_read);
    lw_splines_free(sp);
    return NULL;
  }
  spl_state *s = state_of(su, lw_model_new(&su->scene, sp, err), 1, err);
  if (s && lw_checkpoint_check_finite(&su->scene, as_read ? as_read : s->m->sp, s->m->term, where, err)) {
    state_free(s);
    s = NULL;
  }
  lw_splines_free(as_read);
  return s;
}

/* The coldest rung's splines, read with the header (st->sp, taken over);
** a state without them (of another system) is refused naming the section. */
static void no_splines(const lw_state *st, const char *path, lw_error *err)
{
  if (st->doc) lw_state_missing_section(st->doc, "system splines", err);
  else lw_error_set(err, LW_EINPUT, "%s: section [system splines]: missing (a state of another system)", path);
}

static lw_splines *take_splines(lw_state *st, const char *path, lw_error *err)
{
  lw_splines *sp = st->sp;
  st->sp = NULL;
  if (!sp) no_splines(st, path, err);
  return sp;
}

static void *state_new(const void *setup, const lw_params *p, unsigned long seed, lw_error *err)
{
  const spl_setup *su = setup;
  lw_splines *sp;
  if (p->from[0]) {
    lw_state st;
    if (lw_state_read(&st, p->from, err)) {
      lw_params_blame(p, "init", "from", err);
      return NULL;
    }
    sp = take_splines(&st, p->from, err);
    lw_state_clear(&st);
    if (!sp) {
      lw_params_blame(p, "init", "from", err);
      return NULL;
    }
    /* Renumbered for the sweeps' sake only: a run of no sweeps (a redraw)
    ** keeps the state's numbering, and so its drawing's path ids, pens
    ** and order. */
    spl_state *s = state_from_file(su, sp, p->from, p->from, p->sweeps > 0, err);
    if (!s && err->code == LW_EINPUT) lw_params_blame(p, "init", "from", err);
    return s;
  }
  size_t n;
  if (lw_init_count(&su->scene, p, &n, err)) return NULL;
  gsl_rng *r = lw_rng_new();
  if (!r) {
    lw_error_set(err, LW_ENOMEM, "out of memory");
    return NULL;
  }
  gsl_rng_set(r, seed);
  sp = lw_init_random(&su->scene, n, (size_t)p->segments, p->segment_length, r, err);
  gsl_rng_free(r);
  if (!sp) {
    if (err->code == LW_EINPUT) lw_params_blame(p, "init", "segment_length", err);
    return NULL;
  }
  if (along_curve(&su->scene, sp, err) < 0) {
    lw_splines_free(sp);
    return NULL;
  }
  return state_of(su, lw_model_new(&su->scene, sp, err), 1, err);
}

static void *state_copy(const void *state, lw_error *err)
{
  const spl_state *s = state;
  lw_splines *sp = lw_splines_clone(s->m->sp);
  if (!sp) {
    lw_error_set(err, LW_ENOMEM, "out of memory for a replica");
    return NULL;
  }
  return state_of(s->setup, lw_model_new(s->m->scene, sp, err), 1, err);
}

static void moves(const lw_params *p, double *weight, double *step, double *target)
{
  const double w[LW_MOVE_KINDS_TDJ] = {p->mix_point, p->mix_vector, p->mix_translate, p->mix_rotate,
                                       p->mix_birth, p->mix_death, p->mix_grow,      p->mix_shrink,
                                       p->mix_split, p->mix_join};
  const double st[LW_MOVE_KINDS] = {p->step_point, p->step_vector, p->step_translate, p->step_rotate};
  const double tg[LW_MOVE_KINDS] = {p->target, p->target, p->target_spline, p->target_spline};
  const int n = lw_splines_row(p)->n_moves;
  for (int k = 0; k < n; k++) {
    weight[k] = w[k];
    /* a trans-dimensional kind has no step (step_max 0) */
    step[k] = k < LW_MOVE_KINDS ? st[k] * move_unit[k] : 0.0;
    target[k] = k < LW_MOVE_KINDS ? tg[k] : p->target_spline;
  }
}

/* With trans-dimensional moves a sweep is a fixed number of proposals, the
** nodes the placement would make: a sweep as long as the state's nodes
** would observe the chain at times that depend on its state, which biases
** what a sweep's end sees toward the states that make long sweeps (the
** ideal-gas tests catch that); and an empty page still gets its births. */
static size_t sweep_size(const void *state)
{
  const spl_state *s = state;
  if (s->m->scene->transdim && s->setup) return s->setup->td_sweep;
  return s->m->sp->n_nodes;
}

static size_t sites(const void *state) { return ((const spl_state *)state)->m->sp->n_nodes; }

/* Steps are capped at the page size: beyond that a Gaussian step only
** throws nodes off the page; an angle at half a turn.  The
** trans-dimensional kinds have none. */
static double step_max(const void *state, int kind)
{
  const lw_scene *sc = ((const spl_state *)state)->m->scene;
  return kind == LW_MOVE_ROTATE ? M_PI : kind >= LW_MOVE_KINDS ? 0.0 : fmax(sc->width, sc->height);
}

static void *proposal_new(const void *state, lw_error *err)
{
  return lw_proposal_new(((const spl_state *)state)->m, err);
}

static void proposal_free(void *prop) { lw_proposal_free(prop); }

/* Spline that owns global node k (binary search over first[]). */
static uint32_t spline_of_node(const lw_splines *sp, size_t k)
{
  size_t lo = 0, hi = sp->n_splines;
  while (hi - lo > 1) {
    size_t mid = (lo + hi) / 2;
    if (sp->first[mid] <= k) lo = mid;
    else hi = mid;
  }
  return (uint32_t)lo;
}

/* The same, trying first the spline of the last proposal and its
** neighbours: a sweep goes node after node. */
static uint32_t spline_near(const lw_splines *sp, uint32_t hint, size_t k)
{
  if (hint < sp->n_splines) {
    if (k >= sp->first[hint] && k < sp->first[hint + 1]) return hint;
    if (hint + 1 < sp->n_splines && k >= sp->first[hint + 1] && k < sp->first[hint + 2]) return hint + 1;
    if (hint > 0 && k >= sp->first[hint - 1] && k < sp->first[hint]) return hint - 1;
  }
  return spline_of_node(sp, k);
}

static void spline_box(const lw_splines *sp, uint32_t i, size_t k0, size_t k1, size_t node0, size_t n,
                       const lw_node *nd, double b[4]);

/* A refused proposal (no spline to remove, a spline at its longest or
** shortest, a ghost's site): rejected, dE = +inf. */
static double refuse(lw_proposal *p)
{
  p->splice = 0;
  p->crowded = 0;
  p->near_pending = 0;
  p->log_ratio = 0.0;
  return INFINITY;
}

/* A split or join whose scan could not grow its buffers: no move, and the
** run stops for want of memory (propose's wrapper) rather than go on
** another way. */
static double out_of_memory(lw_proposal *p)
{
  refuse(p);
  p->nomem = 1;
  return NAN;
}

/* The refusal an evaluated proposal carries (system.h), for the chain to
** count apart; one that is both is counted as crowded. */
static int refusal(const lw_proposal *p)
{
  return p->crowded ? LW_PROPOSE_CROWDED : p->irregular ? LW_PROPOSE_IRREGULAR : 0;
}

/* No line to move, kill, grow, shrink or split (none to join with, for a
** join): no proposal (system.h), counted nowhere.  A page whose lines had
** all died counted every such move as a rejection, and a death's acceptance
** read 0.32 where 428 of 440 were taken. */
static double nothing(lw_proposal *p, int *forbidden)
{
  refuse(p);
  *forbidden = LW_PROPOSE_NOTHING;
  return 0.0;
}

/* A proposal of the kind at global node k (a point or vector move) or on
** its spline (a rigid move); with a box (domains.h), rejected (+inf,
** LW_PROPOSE_OUTSIDE) if the spline would leave it. */
static double propose_on(const lw_model *m, const lw_td *td, lw_proposal *p, int kind, size_t at, uint32_t i,
                         double st, gsl_rng *rng, int *forbidden, const double *box)
{
  const lw_splines *sp = m->sp;
  size_t node0, n_node;
  lw_node *nd = p->node; /* proposals are built in place in the scratch */
  if (lw_model_ghost(m, i)) {
    /* a site in a ghost slot (slots.h) until the sweep's end: no move, which
    ** keeps balance (the site is the state's own, like a wrapped one) */
    p->spline = i;
    *forbidden = 0;
    return refuse(p);
  }
  if (kind == LW_MOVE_POINT || kind == LW_MOVE_VECTOR) {
    node0 = at - sp->first[i];
    n_node = 1;
    nd[0] = sp->node[at];
    double dx = gsl_ran_gaussian_ziggurat(rng, st), dy = gsl_ran_gaussian_ziggurat(rng, st);
    if (kind == LW_MOVE_POINT) {
      nd[0].px += dx;
      nd[0].py += dy;
    } else {
      nd[0].vx += dx;
      nd[0].vy += dy;
    }
  } else {
    node0 = 0;
    n_node = sp->first[i + 1] - sp->first[i];
    const lw_node *src = &sp->node[sp->first[i]];
    if (kind == LW_MOVE_TRANSLATE) {
      double dx = gsl_ran_gaussian_ziggurat(rng, st), dy = gsl_ran_gaussian_ziggurat(rng, st);
      for (size_t k = 0; k < n_node; k++) {
        nd[k] = src[k];
        nd[k].px += dx;
        nd[k].py += dy;
      }
    } else {
      double a = gsl_ran_gaussian_ziggurat(rng, st), ca = cos(a), sa = sin(a);
      double cx = 0.0, cy = 0.0;
      for (size_t k = 0; k < n_node; k++) {
        cx += src[k].px;
        cy += src[k].py;
      }
      cx /= (double)n_node;
      cy /= (double)n_node;
      for (size_t k = 0; k < n_node; k++) {
        double x = src[k].px - cx, y = src[k].py - cy;
        nd[k] = (lw_node){cx + ca * x - sa * y, cy + sa * x + ca * y,
                          ca * src[k].vx - sa * src[k].vy, sa * src[k].vx + ca * src[k].vy};
      }
    }
  }
  if (box) {
    /* the segments the move changes: the rest lay inside the box when the
    ** group began (domains.c, cell_holding) and every move taken since kept
    ** them there, so the answer is the whole spline's (a scan of it made a
    ** point move on a spline of 150 segments cost 1.6 to 5 times one without
    ** domains: docs/PERFORMANCE.md).  A NaN node passes here (fmin and fmax
    ** step over it); the state's range check refuses it. */
    double b[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
    spline_box(sp, i, node0 ? node0 - 1 : 0, node0 + n_node, node0, n_node, nd, b);
    if (!(b[0] >= box[0] && b[1] >= box[1] && b[2] <= box[2] && b[3] <= box[3])) {
      p->spline = i;
      *forbidden = LW_PROPOSE_OUTSIDE;
      return INFINITY;
    }
  }
  lw_model_propose(m, p, i, node0, n_node, NULL);
  /* the prior of the shapes is part of the target with trans-dimensional
  ** moves (transdim.h): its ratio is these moves' Hastings factor */
  if (td) {
    const lw_node *src = &sp->node[sp->first[i]];
    const size_t nn = sp->first[i + 1] - sp->first[i];
    p->log_ratio = n_node == 1 ? lw_td_prior_change(td, src, nn, node0, &nd[0])
                               : lw_td_prior(td, nd, nn) - lw_td_prior(td, src, nn);
  }
  *forbidden = refusal(p);
  return p->dE;
}

/* The trans-dimensional proposals of spl_setup (NULL for a view). */
static const lw_td *td_of(const spl_state *s)
{
  return s->setup && s->m->scene->transdim ? &s->setup->td : NULL;
}

/* A live spline drawn uniformly (some must be): slots drawn until one is
** not a ghost, an exact uniform draw over the live ones whose expected
** cost is the slots over the live splines, about 1 (ghosts last a sweep). */
static uint32_t live_spline(const lw_model *m, gsl_rng *rng)
{
  uint32_t i;
  do i = (uint32_t)gsl_rng_uniform_int(rng, m->sp->n_splines);
  while (lw_model_ghost(m, i));
  return i;
}

/* ---- split and join (docs/NUMERICS.md, "Split and join") ---- */

/* Node a run the other way: the same point, the vector turned round. */
static lw_node reversed_node(const lw_node *a) { return (lw_node){a->px, a->py, -a->vx, -a->vy}; }

/* The n nodes src into dst, run the other way if rev (the same curve; a
** spline's vectors point from node 0 to node n). */
static void copy_nodes(lw_node *dst, const lw_node *src, size_t n, int rev)
{
  for (size_t k = 0; k < n; k++) dst[k] = rev ? reversed_node(&src[n - 1 - k]) : src[k];
}

/* 1 if ends at nodes a and b are close enough to join. */
static int joinable(const spl_setup *su, const lw_node *a, const lw_node *b)
{
  return gsl_pow_2(a->px - b->px) + gsl_pow_2(a->py - b->py) <= su->join_r2;
}

/* log of the weight of joining end e (node e, te = 1 at its spline's tail)
** to end f of another spline: the prior's factor g(after | before) of the
** segment the join adds (transdim.h), e's spline keeping its direction and
** f's turned round where the two ends are of the same kind (tail to tail,
** head to head). */
static double join_log(const lw_td *td, const lw_node *e, int te, const lw_node *f, int tf)
{
  const lw_node fo = tf == te ? reversed_node(f) : *f;
  return te ? lw_td_next_log(td, e, 1, &fo) : lw_td_next_log(td, &fo, 1, e);
}

/* Adds log weight lw to the running log-sum (*mx, *sum), sum relative to
** exp(mx), so that nothing over- or underflows. */
static void log_add(double lw, double *mx, double *sum)
{
  if (!(lw > -INFINITY)) return;
  if (lw > *mx) {
    *sum = *sum * exp(*mx - lw) + 1.0;
    *mx = lw;
  } else {
    *sum += exp(lw - *mx);
  }
}

/* The layer of spline i (layers.h): a join links splines of one layer
** only, and a split's pieces keep the cut spline's, so that each undoes
** the other with the layers as state. */
static int spline_layer(const lw_splines *sp, uint32_t i) { return sp->layer ? sp->layer[i] : 0; }

/* 1 if spline i may split: 3 .. max_segments segments (each piece keeps
** one, and a join could make it) and rest length n l (lw_td_plain). */
static int splittable(const lw_td *td, const lw_splines *sp, uint32_t i)
{
  const size_t n = lw_splines_segments(sp, i);
  return n >= 3 && n <= td->max_segments && lw_td_plain(td, n, sp->rest_length[i]);
}

/* End `tail` (1: the last node) of spline i. */
static const lw_node *spline_end(const lw_splines *sp, uint32_t i, int tail)
{
  return &sp->node[tail ? sp->first[i + 1] - 1 : sp->first[i]];
}

/* The cell of coordinate c along an axis of n cells from 0: clamped, so
** that an end off the page (or not finite) still has one; clamping keeps
** two coordinates within a side of each other within a cell of each other. */
static int end_cell(double c, double side, int n)
{
  const double u = floor(c / side);
  return u >= 0.0 ? (u < (double)(n - 1) ? (int)u : n - 1) : 0;
}

static size_t ends_cell(const spl_state *s, const lw_node *a)
{
  return (size_t)end_cell(a->py, s->ends.side, s->ends.ny) * (size_t)s->ends.nx +
         (size_t)end_cell(a->px, s->ends.side, s->ends.nx);
}

static int room_u32(uint32_t **a, size_t *cap, size_t n)
{
  if (n <= *cap) return 1;
  uint32_t *q = realloc(*a, n * sizeof *q);
  if (!q) return 0;
  *a = q;
  *cap = n;
  return 1;
}

/* The ends table of s for the state as it is: O(N + cells), once after each
** commit that a split or join proposal follows.  0 if out of memory. */
static int ends_ready(spl_state *s)
{
  const lw_model *m = s->m;
  const lw_splines *sp = m->sp;
  if (s->ends.built && s->ends.serial == m->serial) return 1;
  const lw_scene *sc = m->scene;
  const double side = sqrt(s->setup->join_r2);
  const int nx = (int)fmin(fmax(ceil(sc->width / side), 1.0), 1024.0);
  const int ny = (int)fmin(fmax(ceil(sc->height / side), 1.0), 1024.0);
  const size_t cells = (size_t)nx * (size_t)ny, n = sp->n_splines;
  if (!room_u32(&s->ends.start, &s->ends.cap_cells, cells + 1) ||
      !room_u32(&s->ends.entry, &s->ends.cap_entry, 2 * n + 1) || !room_u32(&s->ends.split, &s->ends.cap_split, n + 1))
    return 0;
  uint32_t *start = s->ends.start;
  memset(start, 0, (cells + 1) * sizeof *start);
  s->ends.side = side;
  s->ends.nx = nx;
  s->ends.ny = ny;
  s->ends.n_split = 0;
  /* a counting sort by cell: entries in slot order within each */
  for (uint32_t i = 0; i < n; i++) {
    if (lw_model_ghost(m, i)) continue;
    if (splittable(&s->setup->td, sp, i)) s->ends.split[s->ends.n_split++] = i;
    for (int t = 0; t < 2; t++) start[ends_cell(s, spline_end(sp, i, t)) + 1]++;
  }
  for (size_t c = 0; c < cells; c++) start[c + 1] += start[c];
  for (uint32_t i = 0; i < n; i++) {
    if (lw_model_ghost(m, i)) continue;
    for (int t = 0; t < 2; t++) s->ends.entry[start[ends_cell(s, spline_end(sp, i, t))]++] = i << 1 | (uint32_t)t;
  }
  for (size_t c = cells; c > 0; c--) start[c] = start[c - 1];
  start[0] = 0;
  s->ends.serial = m->serial;
  s->ends.built = 1;
  return 1;
}

static int entry_order(const void *a, const void *b)
{
  const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
  return (x > y) - (x < y);
}

/* The partners of end e (node en, tail te) of a spline of layer `layer` for
** a join: the ends within the join radius of every live spline of that
** layer but `skip`, in slot order, then the ends
** `extra[0]` (head) and `extra[1]` (tail) of a spline not in the state yet
** (NULL: none; a split's other piece).  With u < 0 returns log Z, the log
** of the sum of their join weights (-inf if there are none); with u in
** [0, 1) and log_z that sum, picks the partner whose cumulative share
** first exceeds u into *pick (its spline) and *pick_tail.  The ends come
** from the cells of the ends table around en (ends_ready), sorted back into
** slot order, so that the sums and the pick are those of a scan of every
** spline in turn.  NAN if out of memory. */
static double join_scan(spl_state *s, const lw_node *en, int te, int layer, uint32_t skip, const lw_node *extra,
                        double u, double log_z, uint32_t *pick, int *pick_tail)
{
  const lw_model *m = s->m;
  const lw_splines *sp = m->sp;
  const spl_setup *su = s->setup;
  if (!ends_ready(s)) return NAN;
  size_t n_near = 0;
  const int cx = end_cell(en->px, s->ends.side, s->ends.nx), cy = end_cell(en->py, s->ends.side, s->ends.ny);
  for (int y = cy > 0 ? cy - 1 : 0; y <= cy + 1 && y < s->ends.ny; y++)
    for (int x = cx > 0 ? cx - 1 : 0; x <= cx + 1 && x < s->ends.nx; x++) {
      const size_t c = (size_t)y * (size_t)s->ends.nx + (size_t)x;
      for (uint32_t k = s->ends.start[c]; k < s->ends.start[c + 1]; k++) {
        const uint32_t e = s->ends.entry[k], i = e >> 1;
        if (i == skip || spline_layer(sp, i) != layer) continue;
        if (!joinable(su, en, spline_end(sp, i, (int)(e & 1)))) continue;
        if (!room_u32(&s->ends.near, &s->ends.cap_near, n_near + 1 + n_near / 2)) return NAN;
        s->ends.near[n_near++] = e;
      }
    }
  const uint32_t *near = s->ends.near;
  if (n_near > 1) qsort(s->ends.near, n_near, sizeof *near, entry_order);
  double mx = -INFINITY, sum = 0.0, cum = 0.0;
  for (size_t k = 0; k < n_near; k++) {
    const uint32_t i = near[k] >> 1;
    const int t = (int)(near[k] & 1);
    const double lw = join_log(&su->td, en, te, spline_end(sp, i, t), t);
    if (u < 0.0) {
      log_add(lw, &mx, &sum);
    } else if (lw > -INFINITY) {
      /* the last partner with a weight, should rounding leave cum below u */
      *pick = i;
      *pick_tail = t;
      if (u < (cum += exp(lw - log_z))) return log_z;
    }
  }
  for (int t = 0; extra && u < 0.0 && t < 2; t++)
    if (joinable(su, en, &extra[t])) log_add(join_log(&su->td, en, te, &extra[t], t), &mx, &sum);
  return u < 0.0 ? mx + log(sum) : log_z;
}

/*
** The log Hastings factor of splitting spline J (n segments, nodes jn) after
** segment c into F (nodes fp, c segments) and B (nodes bp, n - 1 - c), as
** they are in the state x after the split: r = 0 both as in J, 1 F run the
** other way, 2 B.  n_x is the count of live splines in x, n_split the
** count of those that may split in x' (with J).  The reverse, a join in x,
** reaches J from end e = F's tail (if F runs as in J) or e = B's head (if
** B does), each with probability 1/(2 N_x) times its weight over the sum
** Z_e of its partners' weights; both weights are the factor g(B_0 | F_c)
** that J's prior has and F's and B's lack.  For a split the pieces are not
** in the state (pieces_live = 0): the ends of the other piece join each
** scan, and J's are left out (skip_f = skip_b = J); for a join they are F's
** and B's own slots.  `layer` is J's (and so F's and B's).  The join's
** factor is minus this one.
*/
static double split_log_ratio(spl_state *s, const lw_node *jn, size_t n, size_t c, int r, const lw_node *fp,
                              const lw_node *bp, size_t n_x, size_t n_split, uint32_t skip_f, uint32_t skip_b,
                              int pieces_live, int layer, int *nomem)
{
  *nomem = 0;
  const spl_setup *su = s->setup;
  const lw_td *td = &su->td;
  const size_t nb = n - 1 - c;
  const double lg = lw_td_next_log(td, &jn[c], 1, &jn[c + 1]);
  double mx = -INFINITY, sum = 0.0;
  if (r != 1) {
    const lw_node ends[2] = {bp[0], bp[nb]};
    const double z = join_scan(s, &fp[c], 1, layer, skip_f, pieces_live ? NULL : ends, -1.0, 0.0, NULL, NULL);
    if (isnan(z)) return *nomem = 1, NAN;
    log_add(lg - z, &mx, &sum);
  }
  if (r != 2) {
    const lw_node ends[2] = {fp[0], fp[c]};
    const double z = join_scan(s, &bp[0], 0, layer, skip_b, pieces_live ? NULL : ends, -1.0, 0.0, NULL, NULL);
    if (isnan(z)) return *nomem = 1, NAN;
    log_add(lg - z, &mx, &sum);
  }
  double lq = lw_td_prior(td, fp, c + 1) + lw_td_prior(td, bp, nb + 1) - lw_td_prior(td, jn, n + 1);
  /* with layers the target has the layer's share s_k per spline: one more */
  const lw_layers_spec *ls = &s->m->scene->layers;
  if (ls->n) lq += log(ls->cum[layer + 1] - ls->cum[layer]);
  const double join = su->log_w[5] - log(2.0 * (double)n_x) + mx + log(sum);
  const double split = su->log_w[4] - log((double)n_split) - log((double)(n - 2)) - log(3.0);
  return lq + join - split;
}

/* How many live splines may split (the ends table's list); with pick below
** that count, the pick-th of them in slot order into *which.  SIZE_MAX if
** out of memory. */
static size_t count_splittable(spl_state *s, size_t pick, uint32_t *which)
{
  if (!ends_ready(s)) return SIZE_MAX;
  if (pick < s->ends.n_split) *which = s->ends.split[pick];
  return s->ends.n_split;
}

/*
** A split removes inner segment c of a spline drawn uniformly among those
** that may split (c = 1 .. n - 2 uniformly, so that each piece keeps one),
** and runs one piece or none the other way (1/3 each): the nodes stay as
** they were, so the dimension match is the identity and the Jacobian 1.
** Refused where no join could undo it: segment ends farther apart than the
** join radius.
*/
static double propose_split(spl_state *s, lw_proposal *p, gsl_rng *rng)
{
  const lw_td *td = &s->setup->td;
  const lw_model *m = s->m;
  const lw_splines *sp = m->sp;
  uint32_t j = 0;
  const size_t n_split = count_splittable(s, SIZE_MAX, NULL);
  if (n_split == SIZE_MAX) return out_of_memory(p);
  if (n_split == 0) return refuse(p);
  count_splittable(s, gsl_rng_uniform_int(rng, n_split), &j);
  const size_t n = lw_splines_segments(sp, j);
  const size_t c = 1 + gsl_rng_uniform_int(rng, n - 2);
  const int r = (int)gsl_rng_uniform_int(rng, 3);
  const lw_node *src = &sp->node[sp->first[j]];
  if (!joinable(s->setup, &src[c], &src[c + 1])) return refuse(p);
  lw_node *fp = p->node, *bp = p->node + c + 1;
  copy_nodes(fp, src, c + 1, r == 1);
  copy_nodes(bp, src + c + 1, n - c, r == 2);
  int nomem;
  const double lr = split_log_ratio(s, src, n, c, r, fp, bp, lw_model_count(m) + 1, n_split, j, j, 0,
                                    spline_layer(sp, j), &nomem);
  /* (a NaN of its own arithmetic, an absurd prior, is a move refused: mc.c) */
  if (nomem) return out_of_memory(p);
  const size_t nodes[2] = {c + 1, n - c};
  const double rest[2] = {(double)c * td->length, (double)(n - 1 - c) * td->length};
  lw_model_propose_regroup(m, p, &j, 1, NULL, nodes, 2, rest, 0);
  p->log_ratio = lr;
  return p->dE;
}

/*
** A join picks an end e of a live spline X (1/(2N)) and a partner end f of
** another, Y, within the join radius with probability w(e, f) / Z_e
** (join_scan), and links them by a segment: X keeps its direction, Y runs
** the other way where f is of e's kind.  Refused where no split could undo
** it: a rest length other than n l, more than max_segments together.
*/
static double propose_join(spl_state *s, lw_proposal *p, gsl_rng *rng)
{
  const lw_td *td = &s->setup->td;
  const lw_model *m = s->m;
  const lw_splines *sp = m->sp;
  const size_t N = lw_model_count(m);
  if (N < 2) return refuse(p);
  const uint32_t x = live_spline(m, rng);
  const int te = gsl_rng_uniform(rng) < 0.5;
  const size_t nx = lw_splines_segments(sp, x);
  const lw_node *xn = &sp->node[sp->first[x]], *en = &xn[te ? nx : 0];
  const int layer = spline_layer(sp, x);
  const double log_z = join_scan(s, en, te, layer, x, NULL, -1.0, 0.0, NULL, NULL);
  if (isnan(log_z)) return out_of_memory(p); /* (join_scan's NaN: its buffers could not grow) */
  if (!(log_z > -INFINITY)) return refuse(p);
  uint32_t y = x;
  int tf = 0;
  join_scan(s, en, te, layer, x, NULL, gsl_rng_uniform(rng), log_z, &y, &tf);
  const size_t ny = lw_splines_segments(sp, y), n = nx + ny + 1;
  if (n > td->max_segments || !lw_td_plain(td, nx, sp->rest_length[x]) || !lw_td_plain(td, ny, sp->rest_length[y]))
    return refuse(p);
  /* F, the first piece of the joined spline, and B as they are now */
  const int y_turned = tf == te;
  const uint32_t f = te ? x : y, b = te ? y : x;
  const size_t c = lw_splines_segments(sp, f);
  const lw_node *fp = &sp->node[sp->first[f]], *bp = &sp->node[sp->first[b]];
  copy_nodes(p->node, fp, c + 1, !te && y_turned);
  copy_nodes(p->node + c + 1, bp, n - c, te && y_turned);
  const int r = y_turned ? (te ? 2 : 1) : 0;
  /* the splines that may split after the join: F and B leave, J comes */
  if (count_splittable(s, SIZE_MAX, NULL) == SIZE_MAX) return out_of_memory(p);
  const size_t n_split = count_splittable(s, SIZE_MAX, NULL) - (size_t)splittable(td, sp, f) -
                         (size_t)splittable(td, sp, b) + 1;
  int nomem;
  const double lr = -split_log_ratio(s, p->node, n, c, r, fp, bp, N, n_split, f, b, 1, layer, &nomem);
  if (nomem) return out_of_memory(p);
  const uint32_t old[2] = {x, y};
  const size_t nodes = n + 1;
  const double rest = (double)n * td->length;
  lw_model_propose_regroup(m, p, old, 2, NULL, &nodes, 1, &rest, 0);
  p->log_ratio = lr;
  return p->dE;
}

/*
** Birth, death, grow and shrink (transdim.h; docs/NUMERICS.md has the
** derivation of each Hastings factor).  A birth adds a spline drawn from
** the prior, its segment count from lw_td_birth_size, a death removes one
** chosen uniformly: the state is a set, and its numbering (where the model
** puts a new spline, slots.h) plays no part in any density.  A death
** removes only splines a birth could have made (lw_td_mortal): for the
** others the reverse proposal has density 0.  A
** grow or shrink moves the rest length by l and keeps its excess over n l
** (lw_td_rest), so that each undoes the other for any rest length.
*/
static double propose_td(spl_state *s, lw_proposal *p, int kind, gsl_rng *rng, int *forbidden)
{
  const spl_setup *su = s->setup;
  const lw_td *td = &su->td;
  const lw_model *m = s->m;
  const lw_splines *sp = m->sp;
  const size_t N = lw_model_count(m);
  const double *lw = su->log_w;
  *forbidden = 0;
  if (kind == LW_MOVE_SPLIT || kind == LW_MOVE_JOIN) {
    if (N < (kind == LW_MOVE_JOIN ? 2u : 1u)) return nothing(p, forbidden);
    const double dE = kind == LW_MOVE_SPLIT ? propose_split(s, p, rng) : propose_join(s, p, rng);
    *forbidden = p->splice ? refusal(p) : 0;
    return dE;
  }
  if (kind == LW_MOVE_BIRTH) {
    const size_t nb = lw_td_birth_size(td, rng);
    lw_td_birth_draw(td, rng, nb, p->node);
    /* its layer by the layers' shares, the prior's own law of a layer:
    ** the factors cancel (docs/NUMERICS.md) */
    const lw_layers_spec *ls = &m->scene->layers;
    const int layer = ls->n ? lw_layers_at(ls, gsl_rng_uniform(rng)) : 0;
    lw_model_propose_splice(m, p, 0, 0, NULL, nb + 1, (double)nb * td->length, layer);
    p->log_ratio = lw[1] - lw[0] - log((double)(N + 1)) - lw_td_size_log(td, nb);
  } else if (kind == LW_MOVE_DEATH) {
    if (N == 0) return nothing(p, forbidden);
    uint32_t j = live_spline(m, rng);
    const size_t n = lw_splines_segments(sp, j);
    if (!lw_td_mortal(td, n, sp->rest_length[j])) return refuse(p);
    lw_model_propose_splice(m, p, j, 1, NULL, 0, 0.0, 0);
    p->log_ratio = lw[0] - lw[1] + log((double)N) + lw_td_size_log(td, n);
  } else {
    if (N == 0) return nothing(p, forbidden);
    uint32_t i = live_spline(m, rng);
    int tail = gsl_rng_uniform(rng) < 0.5;
    const size_t n = lw_splines_segments(sp, i);
    const lw_node *src = &sp->node[sp->first[i]];
    double lr;
    const double rest = lw_td_rest(td, sp->rest_length[i], n, kind == LW_MOVE_GROW ? n + 1 : n - 1);
    if (isnan(rest)) return refuse(p);
    if (kind == LW_MOVE_GROW) {
      if (n >= td->max_segments) return refuse(p);
      /* the old nodes before a new last one, or after a new first one */
      lw_node *keep = tail ? p->node : p->node + 1, *add = tail ? p->node + n + 1 : p->node;
      memcpy(keep, src, (n + 1) * sizeof *src);
      double lg = lw_td_next_draw(td, tail ? &keep[n] : &keep[0], tail ? 1 : -1, rng, add);
      /* at the tail the prior's new factor is the proposal itself */
      lr = tail ? 0.0
                : lw_td_first_log(td, add) + lw_td_next_log(td, add, 1, &keep[0]) - lw_td_first_log(td, &keep[0]) - lg;
      lw_model_propose_splice(m, p, i, 1, NULL, n + 2, rest, 0);
      p->log_ratio = lw[3] - lw[2] + lr;
    } else {
      if (n <= 1) return refuse(p);
      memcpy(p->node, tail ? src : src + 1, n * sizeof *src);
      lr = tail ? 0.0
                : lw_td_first_log(td, &src[1]) - lw_td_first_log(td, &src[0]) - lw_td_next_log(td, &src[0], 1, &src[1]) +
                      lw_td_next_log(td, &src[1], -1, &src[0]);
      lw_model_propose_splice(m, p, i, 1, NULL, n, rest, 0);
      p->log_ratio = lw[2] - lw[3] + lr;
    }
  }
  *forbidden = refusal(p);
  return p->dE;
}

/* A node drawn uniformly for a point or vector move, a spline for a rigid
** one, among the live ones: drawn again while in a ghost (slots.h), an
** exact uniform draw.  The row with split and join sweeps this way rather
** than site by site (propose_at): there a site's node depends on where the
** sweep's earlier splices left the splines, so which node a step updates
** would depend on what the chain did before it in the sweep, and the
** stationary law is lost (docs/NUMERICS.md, "Split and join": measured). */
static double propose_once(void *state, void *prop, int kind, double st, gsl_rng *rng, int *forbidden)
{
  spl_state *s = state;
  const lw_model *m = s->m;
  const lw_splines *sp = m->sp;
  if (kind >= LW_MOVE_KINDS) return propose_td(s, prop, kind, rng, forbidden);
  if (lw_model_count(m) == 0) return nothing(prop, forbidden);
  if (kind == LW_MOVE_POINT || kind == LW_MOVE_VECTOR) {
    size_t k;
    uint32_t i;
    do {
      k = gsl_rng_uniform_int(rng, sp->n_nodes);
      i = spline_of_node(sp, k);
    } while (lw_model_ghost(m, i));
    return propose_on(m, td_of(s), prop, kind, k, i, st, rng, forbidden, NULL);
  }
  const uint32_t i = live_spline(m, rng);
  return propose_on(m, td_of(s), prop, kind, sp->first[i], i, st, rng, forbidden, NULL);
}

/* Site k is global node k; a rigid move there moves the node's spline, so a
** spline of n nodes gets n chances a sweep, as many as its nodes get point
** and vector moves.  Trans-dimensional kinds draw their own spline, and
** the count of sites may change within a sweep: a site past the end wraps
** around (each proposal is still a Metropolis update of one node). */
static double propose_at_once(void *state, void *prop, int kind, size_t k, double st, gsl_rng *rng, int *forbidden)
{
  spl_state *s = state;
  const lw_model *m = s->m;
  lw_proposal *p = prop;
  if (kind >= LW_MOVE_KINDS) return propose_td(s, p, kind, rng, forbidden);
  if (m->sp->n_nodes == 0) {
    *forbidden = 0;
    return refuse(p);
  }
  if (k >= m->sp->n_nodes) k %= m->sp->n_nodes;
  return propose_on(m, td_of(s), p, kind, k, spline_near(m->sp, p->spline, k), st, rng, forbidden, NULL);
}

/* ---- domain decomposition (system.h, domains.h) ---- */

/* Grows box b (x0, y0, x1, y1) over segments [k0, k1) of spline i (k1 up
** to its node count: the last node's point) with nodes [node0, node0 + n)
** replaced by nd (n = 0: as it is): the Bezier control points of its
** segments, whose convex hull holds every sample of every term. */
static void spline_box(const lw_splines *sp, uint32_t i, size_t k0, size_t k1, size_t node0, size_t n,
                       const lw_node *nd, double b[4])
{
  const lw_node *base = &sp->node[sp->first[i]];
  const size_t nn = sp->first[i + 1] - sp->first[i];
  for (size_t k = k0; k < k1 && k < nn; k++) {
    const lw_node *a = k >= node0 && k < node0 + n ? &nd[k - node0] : &base[k];
    double z[8];
    lw_node next = *a;
    if (k + 1 < nn) next = k + 1 >= node0 && k + 1 < node0 + n ? nd[k + 1 - node0] : base[k + 1];
    lw_segment_bezier(a, &next, z);
    for (int c = 0; c < (k + 1 < nn ? 8 : 2); c += 2) {
      b[0] = fmin(b[0], z[c]);
      b[1] = fmin(b[1], z[c + 1]);
      b[2] = fmax(b[2], z[c]);
      b[3] = fmax(b[3], z[c + 1]);
    }
  }
}

/* Every term of the spline model is local: segment and spline terms read
** the moved spline only, the pair term the 3 x 3 grid cells around each
** sample (cells at least the cutoff wide, min_spacing too), a raster term
** the pixels its box covers (the footprint plus the rounding of
** lw_tone_box_cover). */
static const char *split(const void *state, double page[4], double *reach)
{
  const lw_model *m = ((const spl_state *)state)->m;
  const lw_scene *sc = m->scene;
  page[0] = 0.0;
  page[1] = 0.0;
  page[2] = sc->width;
  page[3] = sc->height;
  double r = 0.0;
  if (m->grid) r = fmax(r, 2.0 / m->grid->inv_h);
  for (int k = 0; k < m->terms.n_raster; k++) {
    const lw_tone *t = m->terms.ctx[m->terms.raster[k]].data;
    r = fmax(r, (t->radius + 3) * t->pixel);
  }
  *reach = r;
  return NULL;
}

/* Site k starts its spline's group: rigid moves at any of its nodes move
** the whole spline, and the spline terms read all of it. */
static size_t group(const void *state, size_t site, double box[4])
{
  const lw_splines *sp = ((const spl_state *)state)->m->sp;
  uint32_t i = spline_of_node(sp, site);
  box[0] = box[1] = INFINITY;
  box[2] = box[3] = -INFINITY;
  spline_box(sp, i, 0, sp->first[i + 1] - sp->first[i], 0, 0, NULL, box);
  return sp->first[i + 1] - site;
}

static double propose_in_once(void *state, void *prop, int kind, size_t k, double st, gsl_rng *rng, int *forbidden,
                         const double box[4])
{
  const spl_state *s = state;
  lw_proposal *p = prop;
  return propose_on(s->m, td_of(s), p, kind, k, spline_near(s->m->sp, p->spline, k), st, rng, forbidden, box);
}

/* The entry points: a proposal the model could not evaluate for want of
** memory says so (LW_PROPOSE_NOMEM), and the run stops with out of memory
** (its NaN was counted as an undefined energy and rejected: a run under
** memory pressure went another way without a word). */
static double checked(void *prop, double dE, int *forbidden)
{
  if (((lw_proposal *)prop)->nomem) *forbidden = LW_PROPOSE_NOMEM;
  return dE;
}

static double propose(void *state, void *prop, int kind, double st, gsl_rng *rng, int *forbidden)
{
  ((lw_proposal *)prop)->nomem = 0;
  return checked(prop, propose_once(state, prop, kind, st, rng, forbidden), forbidden);
}

static double propose_at(void *state, void *prop, int kind, size_t k, double st, gsl_rng *rng, int *forbidden)
{
  ((lw_proposal *)prop)->nomem = 0;
  return checked(prop, propose_at_once(state, prop, kind, k, st, rng, forbidden), forbidden);
}

static double propose_in(void *state, void *prop, int kind, size_t k, double st, gsl_rng *rng, int *forbidden,
                         const double box[4])
{
  ((lw_proposal *)prop)->nomem = 0;
  return checked(prop, propose_in_once(state, prop, kind, k, st, rng, forbidden, box), forbidden);
}

static lw_status commit_part(void *state, void *prop)
{
  return lw_model_commit_part(((spl_state *)state)->m, prop);
}

static lw_status merge(void *state, void *prop) { return lw_model_merge(((spl_state *)state)->m, prop); }

/* Between sweeps, before the run loop's refresh (which rebuilds every
** cache from the renumbered state). */
static lw_status renumber(void *state, lw_error *err)
{
  spl_state *s = state;
  return along_curve(s->m->scene, s->m->sp, err) < 0 ? err->code : LW_OK;
}

static lw_status commit(void *state, void *prop) { return lw_model_commit(((spl_state *)state)->m, prop); }

static void defer(void *prop, int on) { ((lw_proposal *)prop)->defer_near = on; }

static double finish(void *state, void *prop, int *nomem)
{
  const double d = lw_model_propose_finish(((spl_state *)state)->m, prop);
  *nomem = ((lw_proposal *)prop)->nomem;
  return d;
}

static lw_status sweep_end(void *state) { return lw_model_compact(((spl_state *)state)->m); }

static double log_ratio(const void *prop) { return ((const lw_proposal *)prop)->log_ratio; }

static double total(const void *state) { return lw_model_total(((const spl_state *)state)->m); }

_Static_assert(LW_TERM_COUNT <= LW_SYSTEM_TERMS_MAX, "the spline terms fit the run loop's arrays (system.h)");

static void terms(const void *state, double *term)
{
  memcpy(term, ((const spl_state *)state)->m->term, LW_TERM_COUNT * sizeof *term);
}

static int term_on(const void *setup, int t) { return ((const spl_setup *)setup)->scene.on[t]; }

static lw_status refresh(void *state) { return lw_model_refresh(((spl_state *)state)->m, NULL); }

static double energy(const void *setup, const lw_state *st, const char *path, double *term, lw_error *err)
{
  const lw_scene *sc = &((const spl_setup *)setup)->scene;
  if (!st->sp) {
    no_splines(st, path, err);
    return NAN;
  }
  if (lw_model_check_regular(sc, st->sp, path, err) || lw_model_check_layers(sc, st->sp, path, err)) return NAN;
  lw_error_clear(err); /* lw_energy_compute sets it only where it fails */
  double total = lw_energy_compute(sc, st->sp, term, err);
  if (err->code || lw_checkpoint_check_finite(sc, st->sp, term, path, err)) return NAN;
  return total;
}

static lw_status save(const void *state, lw_ckpt_writer *w, const char *section, lw_error *err)
{
  lw_state_put_splines(w, section, ((const spl_state *)state)->m->sp);
  return LW_OK;
}

/* The coldest rung's splines were read with the header (st->sp); the
** others come from their section.  A state whose energies are not finite is
** refused here, naming the spline and segment. */
static void *load(const void *setup, lw_state *st, const char *section, const char *path, lw_error *err)
{
  const spl_setup *su = setup;
  lw_splines *sp = NULL;
  if (!strcmp(section, "system splines")) {
    if (!(sp = take_splines(st, path, err))) return NULL;
  } else if (lw_state_get_splines(st->doc, section, &sp, err)) {
    return NULL;
  }
  char where[LW_PATH_MAX + 64];
  snprintf(where, sizeof where, "%s: [%s]", path, section);
  return state_from_file(su, sp, path, where, 0, err);
}

static void set_terms(void *state, const double *term)
{
  memcpy(((spl_state *)state)->m->term, term, LW_TERM_COUNT * sizeof *term);
}

/* The coordinates are the nodes' px py vx vy in node order (lw_node holds
** exactly those four doubles). */
static size_t n_coords(const void *state) { return 4 * ((const spl_state *)state)->m->sp->n_nodes; }

static void get_coords(const void *state, double *x)
{
  const lw_splines *sp = ((const spl_state *)state)->m->sp;
  for (size_t k = 0; k < sp->n_nodes; k++) {
    const lw_node *nd = &sp->node[k];
    x[4 * k] = nd->px;
    x[4 * k + 1] = nd->py;
    x[4 * k + 2] = nd->vx;
    x[4 * k + 3] = nd->vy;
  }
}

/* No NaN enters a state: coordinates that are not finite are refused and
** the state is left as it was. */
static lw_status set_coords(void *state, const double *x, lw_error *err)
{
  lw_model *m = ((spl_state *)state)->m;
  lw_splines *sp = m->sp;
  for (size_t i = 0; i < 4 * sp->n_nodes; i++)
    if (!isfinite(x[i]))
      return lw_error_set(err, LW_EINPUT, "coordinate %zu (node %zu) is not finite", i, i / 4);
  for (size_t k = 0; k < sp->n_nodes; k++) sp->node[k] = (lw_node){x[4 * k], x[4 * k + 1], x[4 * k + 2], x[4 * k + 3]};
  if (lw_model_refresh(m, NULL) != LW_OK)
    return lw_error_set(err, LW_ENOMEM, "out of memory refreshing the model of %zu segments", sp->n_segments);
  return LW_OK;
}

static double gradient(void *state, double *g, lw_error *err)
{
  spl_state *s = state;
  const lw_splines *sp = s->m->sp;
  if (!s->grad || s->grad_cap < sp->n_nodes) {
    size_t cap = sp->n_nodes ? sp->n_nodes : 1;
    lw_node *g2 = realloc(s->grad, cap * sizeof *g2);
    if (!g2) {
      lw_error_set(err, LW_ENOMEM, "out of memory for the gradient of %zu nodes", sp->n_nodes);
      return NAN;
    }
    s->grad = g2;
    s->grad_cap = cap;
  }
  double e = lw_energy_gradient(s->m->scene, sp, LW_GRAD_ALL, s->grad, NULL, err);
  for (size_t k = 0; k < sp->n_nodes; k++) {
    g[4 * k] = s->grad[k].px;
    g[4 * k + 1] = s->grad[k].py;
    g[4 * k + 2] = s->grad[k].vx;
    g[4 * k + 3] = s->grad[k].vy;
  }
  return e;
}

/* 1 if coordinates c are those of nodes o and o + 1: a segment that does not
** move cannot close in on anything (whatever comes to it is the mover's). */
static int same_nodes(const lw_node *o, const double *c)
{
  return o[0].px == c[0] && o[0].py == c[1] && o[0].vx == c[2] && o[0].vy == c[3] && o[1].px == c[4] &&
         o[1].py == c[5] && o[1].vx == c[6] && o[1].vy == c[7];
}

/* The segments coordinates x would make forbidden: not finite, irregular
** (lw_segment_allowed) or, with the boundary term on, with a sample or an
** end outside (lw_term_boundary infinite); and those that would close in on
** another stroke against energy.min_spacing (lw_model_segment_crowds,
** against the others' curves where they stand, each with a margin of the
** farthest its own control points move, which bounds how far it may come):
** their two nodes' coordinates.  With `changed` (a later round of holds,
** system.h) only the segments with a changed coordinate are asked: the
** others were allowed, and every curve near them now moves less, so each
** test they passed, against margins at least as wide, still holds. */
static size_t blocked(void *state, const double *x, unsigned char *held, const unsigned char *changed)
{
  spl_state *s = state;
  const lw_scene *sc = s->m->scene;
  const lw_splines *sp = s->m->sp;
  size_t parts = 0;
  lw_step_margins mg = {0};
  if (sc->min_spacing > 0.0) {
    if (s->margin_n < sp->n_segments) {
      double *r = realloc(s->margin, 2 * sp->n_segments * sizeof *r);
      if (!r) { /* no room for the margins: every moving segment is held */
        for (size_t g = 0; g < sp->n_segments; g++) {
          const size_t k = lw_segment_node(sp, g);
          if (same_nodes(sp->node + k, x + 4 * k)) continue;
          memset(held + 4 * k, 1, 8);
          parts++;
        }
        return parts;
      }
      s->margin = r;
      s->margin_n = sp->n_segments;
    }
    double *reach = s->margin, *gap = s->margin + sp->n_segments;
    lw_model_sample_gaps(s->m, gap);
    for (size_t g = 0; g < sp->n_segments; g++) {
      const size_t k = lw_segment_node(sp, g);
      double r = 0.0;
      for (int e = 0; e < 2; e++) {
        const double *c = x + 4 * (k + (size_t)e);
        const lw_node *o = &sp->node[k + (size_t)e];
        const double d = hypot(c[0] - o->px, c[1] - o->py) + hypot(c[2] - o->vx, c[3] - o->vy);
        if (d > r || isnan(d)) r = isnan(d) ? INFINITY : d;
      }
      reach[g] = r;
      mg.reach_max = fmax(mg.reach_max, r);
      mg.gap_max = fmax(mg.gap_max, gap[g]);
    }
    mg.reach = reach;
    mg.gap = gap;
  }
  lw_samples smp;
  for (size_t g = 0; g < sp->n_segments; g++) {
    const size_t k = lw_segment_node(sp, g);
    if (changed && !memchr(changed + 4 * k, 1, 8)) continue; /* allowed before, and the others moved less */
    const double *c = x + 4 * k;
    const lw_node a = {c[0], c[1], c[2], c[3]}, b = {c[4], c[5], c[6], c[7]};
    int bad = 0;
    for (int i = 0; i < 8; i++) bad |= !isfinite(c[i]);
    if (!bad) {
      lw_segment_sample(&sc->quad, &a, &b, &smp);
      bad = !lw_segment_allowed(sc, &a, &b, smp.length) ||
            (sc->on[LW_TERM_BOUNDARY] && !isfinite(lw_term_boundary(&smp, &sc->quad, &sc->boundary))) ||
            (!same_nodes(sp->node + k, c) && lw_model_segment_crowds(s->m, g, &a, &b, &mg));
    }
    if (!bad) continue;
    memset(held + 4 * k, 1, 8);
    parts++;
  }
  return parts;
}

static lw_status draw(void *state, const lw_params *p, const char *dir, long sweep, lw_error *err)
{
  spl_state *s = state;
  const lw_scene *sc = &s->setup->scene;
  if (sweep == LW_DRAW_START) {
    if (!p->field_preview) return LW_OK;
    char path[LW_PATH_MAX + 32];
    lw_path_join(path, sizeof path, dir, "field.png");
    return lw_fieldview_png(sc, p->png_scale, path, err);
  }
  if (sweep >= 0) return lw_drawing_frame(p, sc, s->m->sp, s->setup->tone, dir, sweep, err);
  return lw_drawing_write(p, sc, s->m->sp, s->setup->tone, dir, &s->drawing, err);
}

static void summary(const void *state, lw_json *j)
{
  const spl_state *s = state;
  lw_json_key(j, "splines");
  lw_json_int(j, (long long)s->m->sp->n_splines);
  lw_json_key(j, "segments");
  lw_json_int(j, (long long)s->m->sp->n_segments);
  lw_drawing_report_json(j, &s->drawing);
}

/* The observables: the count, and means over the splines of
** lw_spline_shape's members (docs/FORMATS.md, "trace.csv"). */
static const char *const observable_names[] = {"count", "length", "end2", "rg2", "end_cos"};

static void observe(const void *state, double *out)
{
  const spl_state *s = state;
  const lw_splines *sp = s->m->sp;
  double sum[4] = {0.0, 0.0, 0.0, 0.0};
  for (size_t i = 0; i < sp->n_splines; i++) {
    lw_spline_shape sh;
    lw_spline_shape_of(sp, i, &s->m->scene->quad, &sh);
    sum[0] += sh.length;
    sum[1] += sh.end2;
    sum[2] += sh.rg2;
    sum[3] += sh.end_cos;
  }
  out[0] = (double)sp->n_splines;
  for (int k = 0; k < 4; k++) out[k + 1] = sp->n_splines ? sum[k] / (double)sp->n_splines : NAN;
}

/* A sample of the configuration (system.h): every node of every spline. */
static void write_sample(const void *state, FILE *f)
{
  const lw_splines *sp = ((const spl_state *)state)->m->sp;
  fputs("spline,node,px,py,vx,vy\n", f);
  for (size_t i = 0; i < sp->n_splines; i++)
    for (size_t k = sp->first[i]; k < sp->first[i + 1]; k++) {
      const lw_node *nd = &sp->node[k];
      fprintf(f, "%zu,%zu,%.17g,%.17g,%.17g,%.17g\n", i, k - sp->first[i], nd->px, nd->py, nd->vx, nd->vy);
    }
}

static void describe(const void *state, int what, char *buf, size_t n)
{
  const spl_state *s = state;
  const lw_splines *sp = s->m->sp;
  const lw_drawing_report *d = &s->drawing;
  if (what == LW_DESCRIBE_SIZE) snprintf(buf, n, "%zu splines, %zu segments", sp->n_splines, sp->n_segments);
  else if (what == LW_DESCRIBE_FORBIDDEN) snprintf(buf, n, "a segment irregular or outside the boundary");
  else if (what == LW_DESCRIBE_LOST) lw_drawing_lost_text(d, buf, n);
  else lw_drawing_report_text(d, buf, n);
}

/* ---- inertia (the dynamics driver) ------------------------------------------ */

/* [dynamics] pin and pin_vectors: which coordinates are held. */
static void *mass_new(const void *state, const lw_params *p, double density, lw_error *err)
{
  const spl_state *s = state;
  const lw_splines *sp = s->m->sp;
  unsigned char *pin = calloc(4 * sp->n_nodes + 1, 1);
  if (!pin) {
    lw_error_set(err, LW_ENOMEM, "out of memory");
    return NULL;
  }
  for (size_t i = 0; i < sp->n_splines; i++) {
    size_t ends[2] = {sp->first[i], sp->first[i + 1] - 1};
    for (int e = 0; e < 2; e++) {
      int held = p->dyn_pin == LW_PIN_ENDS || (p->dyn_pin == LW_PIN_FIRST && e == 0) ||
                 (p->dyn_pin == LW_PIN_LAST && e == 1);
      if (!held) continue;
      memset(pin + 4 * ends[e], 1, 2);
      if (p->dyn_pin_vectors) memset(pin + 4 * ends[e] + 2, 1, 2);
    }
  }
  lw_spline_mass *m = lw_spline_mass_new(sp, &s->m->scene->quad, density, pin, err);
  free(pin);
  /* (too few nodes: the one input of the message, named as every key is) */
  if (!m && err->code == LW_EINPUT) lw_params_blame(p, "energy", "quadrature", err);
  return m;
}

static void mass_free(void *mass) { lw_spline_mass_free(mass); }

static lw_status mass_at(void *mass, const double *x, lw_error *err) { return lw_spline_mass_at(mass, x, err); }

static void mass_solve(const void *mass, const double *b, double *v) { lw_spline_mass_solve(mass, b, v); }

static void mass_apply(const void *mass, const double *v, double *b) { lw_spline_mass_apply(mass, v, b); }

static void mass_dx(const void *mass, const double *x, const double *v, double *out)
{
  lw_spline_mass_dx(mass, x, v, out);
}

static int mass_pinned(const void *mass, size_t i) { return lw_spline_mass_pinned(mass, i); }

/* Every key of the page, the curves and their drawing; the load acts on
** Monte Carlo too, the pins only in the dynamics. */
static const char *const keys[] = {"scene.*", "init.*", "energy.*", "output.*", "plot.*", "layers.*",
                                   "dynamics.rho", "dynamics.gravity_x", "dynamics.gravity_y", "dynamics.force_x",
                                   "dynamics.force_y", NULL};
static const char *const keys_dynamics[] = {"dynamics.pin", "dynamics.pin_vectors", NULL};
static const char *const keys_metropolis[] = {"moves.*", "anneal.delayed_acceptance", "anneal.domains", NULL};

/* Keys the scene's other settings leave idle (system.h). */
static int idle(const lw_params *p, lw_idle_rule rule[LW_IDLE_RULES_MAX])
{
  static const char *const coverage[] = {"init.coverage", NULL},
                           *const jumps[] = {"moves.birth", "moves.birth_uniform", "moves.birth_spread",
                                             "moves.prior_sd", "moves.death", "moves.grow", "moves.shrink",
                                             "moves.max_segments", "moves.split", "moves.join",
                                             "moves.join_radius", NULL};
  /* the field and the potential are built only for their terms, and each
  ** kind reads its own keys (an artist's vortex without energy.field drew
  ** random strokes without a word) */
  static const char *const field[] = {"scene.field", "scene.field_angle", "scene.field_sigma", "scene.field_flat",
                                      "scene.field_wavelength", "scene.field_amplitude", "scene.field_core",
                                      "energy.field_mode", "scene.field_file", "scene.field_file_y",
                                      "scene.field_file_scale", "scene.field_file_layout",
                                      "layers.turn", NULL},
                           *const potential[] = {"scene.potential", "scene.potential_value", "scene.potential_angle",
                                                 "scene.potential_scale", "scene.potential_power",
                                                 "scene.potential_blur", "scene.potential_paper",
                                                 "scene.potential_fine", NULL},
                           *const angle[] = {"scene.field_angle", NULL}, *const sigma[] = {"scene.field_sigma", NULL},
                           *const flat[] = {"scene.field_flat", NULL},
                           *const waves[] = {"scene.field_wavelength", "scene.field_amplitude", NULL},
                           *const value[] = {"scene.potential_value", NULL},
                           *const ramp[] = {"scene.potential_angle", NULL},
                           *const scale[] = {"scene.potential_scale", NULL},
                           *const picture[] = {"scene.potential_power", "scene.potential_blur",
                                               "scene.potential_paper", "scene.potential_fine", NULL},
                           *const paper[] = {"scene.potential_paper", NULL},
                           *const centre[] = {"scene.center_x", "scene.center_y", NULL},
                           *const core[] = {"scene.field_core", NULL};
  const int fo = p->field_coef != 0.0, po = p->potential_coef != 0.0, f = p->field, q = p->potential;
  const int grid = f == LW_FLD_ETF || f == LW_FLD_GRADIENT;
  int n = 0;
  rule[n++] = (lw_idle_rule){coverage, p->splines != 0, "init.splines is not 0"};
  rule[n++] = (lw_idle_rule){jumps, p->fixed_count, "moves.fixed_count = 1"};
  rule[n++] = (lw_idle_rule){field, !fo, "energy.field = 0"};
  rule[n++] = (lw_idle_rule){potential, !po, "energy.potential = 0"};
  rule[n++] = (lw_idle_rule){angle, fo && f != LW_FLD_CONSTANT && f != LW_FLD_ETF,
                             "scene.field is not constant or etf"};
  rule[n++] = (lw_idle_rule){sigma, fo && f != LW_FLD_ETF, "scene.field is not etf"};
  rule[n++] = (lw_idle_rule){flat, fo && !grid, "scene.field is not etf or gradient"};
  rule[n++] = (lw_idle_rule){waves, fo && f != LW_FLD_WAVES, "scene.field is not waves"};
  rule[n++] = (lw_idle_rule){value, po && q != LW_POT_CONSTANT, "scene.potential is not constant"};
  rule[n++] = (lw_idle_rule){ramp, po && q != LW_POT_RAMP, "scene.potential is not ramp"};
  rule[n++] = (lw_idle_rule){scale, po && q != LW_POT_RAMP && q != LW_POT_RADIAL,
                             "scene.potential is not ramp or radial"};
  rule[n++] = (lw_idle_rule){picture, po && q != LW_POT_IMAGE, "scene.potential is not image"};
  rule[n++] = (lw_idle_rule){paper, po && q == LW_POT_IMAGE && !(p->potential_blur > 0.0),
                             "scene.potential_blur is 0"};
  rule[n++] = (lw_idle_rule){centre, !(fo && (f == LW_FLD_RADIAL || f == LW_FLD_VORTEX)) &&
                                         !(po && (q == LW_POT_RAMP || q == LW_POT_RADIAL)),
                             "no radial or vortex field, no ramp or radial potential"};
  rule[n++] = (lw_idle_rule){core, fo && f != LW_FLD_RADIAL && f != LW_FLD_VORTEX, "scene.field is not radial or "
                             "vortex"};
  return n;
}

/* The rows differ only in their move kinds (sys_splines.h). */
#define SPLINES_ROW \
  .keys = keys, \
  .keys_dynamics = keys_dynamics, \
  .keys_metropolis = keys_metropolis, \
  .n_terms = LW_TERM_COUNT, \
  .term_names = lw_term_names, \
  .setup_new = setup_new, \
  .setup_free = setup_free, \
  .note = note, \
  .start_bytes = start_bytes, \
  .state_new = state_new, \
  .state_copy = state_copy, \
  .state_free = state_free, \
  .moves = moves, \
  .sweep_size = sweep_size, \
  .step_max = step_max, \
  .proposal_new = proposal_new, \
  .proposal_free = proposal_free, \
  .propose = propose, \
  .renumber = renumber, \
  .sweep_end = sweep_end, \
  .commit = commit, \
  .defer = defer, \
  .finish = finish, \
  .log_ratio = log_ratio, \
  .total = total, \
  .terms = terms, \
  .term_on = term_on, \
  .refresh = refresh, \
  .energy = energy, \
  .save = save, \
  .load = load, \
  .set_terms = set_terms, \
  .n_coords = n_coords, \
  .get_coords = get_coords, \
  .set_coords = set_coords, \
  .gradient = gradient, \
  .blocked = blocked, \
  .mass_new = mass_new, \
  .mass_free = mass_free, \
  .mass_at = mass_at, \
  .mass_solve = mass_solve, \
  .mass_apply = mass_apply, \
  .mass_dx = mass_dx, \
  .mass_pinned = mass_pinned, \
  .variant = lw_splines_row, \
  .idle = idle, \
  .files = "final.svg, final.png", \
  .draw = draw, \
  .summary = summary, \
  .describe = describe, \
  .n_observables = (int)(sizeof observable_names / sizeof observable_names[0]), \
  .observable_names = observable_names, \
  .observe = observe, \
  .write_sample = write_sample, \
  .split = split, \
  .group = group, \
  .propose_in = propose_in, \
  .commit_part = commit_part, \
  .merge = merge,

const lw_system_type lw_system_splines = {
    .name = "splines",
    .n_moves = LW_MOVE_KINDS,
    .move_names = lw_move_names,
    .move_unit = move_unit,
    SPLINES_ROW
    .propose_at = propose_at,
};

/* Births, deaths, grows and shrinks draw their own spline anywhere on the
** page and change the storage: with domains they run after the phases
** (mc.h), and the domains visit the nodes, not sweep_size's fixed count.
** Neither row has propose_at: with splices inside a sweep, which node a
** site holds would depend on the sweep's own past (docs/NUMERICS.md,
** "Split and join", "Sweeps"), so a sweep without domains draws each
** node or spline at random among the live ones. */
const lw_system_type lw_system_splines_td = {
    .name = "splines",
    .n_moves = LW_MOVE_KINDS_TD,
    .move_names = move_names_td,
    .move_unit = move_unit,
    SPLINES_ROW
    .n_domain_moves = LW_MOVE_KINDS,
    .sites = sites,
};

const lw_system_type lw_system_splines_tdj = {
    .name = "splines",
    .n_moves = LW_MOVE_KINDS_TDJ,
    .move_names = move_names_td,
    .move_unit = move_unit,
    SPLINES_ROW
    .n_domain_moves = LW_MOVE_KINDS,
    .sites = sites,
};

const lw_system_type *lw_splines_row(const lw_params *p)
{
  if (p->fixed_count) return &lw_system_splines;
  return p->mix_split > 0.0 || p->mix_join > 0.0 ? &lw_system_splines_tdj : &lw_system_splines_td;
}

lw_system *lw_splines_view(lw_model *m, lw_error *err)
{
  return lw_system_wrap(&lw_system_splines, state_of(NULL, m, 0, err), err);
}

lw_model *lw_splines_model(const lw_system *s) { return ((const spl_state *)s->state)->m; }
