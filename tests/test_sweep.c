/*
** test_sweep.c -- sweeps in storage order and splines numbered along the
** Hilbert curve (issue 14): the curve itself, the renumbering, and a sweep
** that visits every node once.
*/
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "linewise/hilbert.h"
#include "linewise/mc.h"
#include "linewise/model.h"
#include "linewise/phase.h"
#include "testutil.h"

/* Every cell of the 2^k grid once, and consecutive positions side by side:
** what makes a run of positions a compact patch of the page. */
Test(hilbert, the_curve_visits_every_cell_once_through_neighbours)
{
  for (int order = 1; order <= 6; order++) {
    uint32_t side = 1u << order;
    size_t cells = (size_t)side * side;
    int *x = malloc(cells * sizeof *x), *y = malloc(cells * sizeof *y);
    unsigned char *seen = calloc(cells, 1);
    for (uint32_t i = 0; i < side; i++)
      for (uint32_t j = 0; j < side; j++) {
        uint64_t d = lw_hilbert_index(i, j, order);
        cr_assert(d < cells, "order %d: (%u, %u) -> %llu out of range", order, i, j, (unsigned long long)d);
        cr_assert(!seen[d], "order %d: position %llu twice", order, (unsigned long long)d);
        seen[d] = 1;
        x[d] = (int)i;
        y[d] = (int)j;
      }
    for (size_t d = 1; d < cells; d++)
      cr_assert_eq(abs(x[d] - x[d - 1]) + abs(y[d] - y[d - 1]), 1, "order %d: positions %zu and %zu not adjacent",
                   order, d - 1, d);
    free(x);
    free(y);
    free(seen);
  }
}

/* n straight two-segment splines, 3 to 6 mm long, at random inside a
** 200 x 150 page's margin. */
static lw_splines *scattered(size_t n, uint64_t seed)
{
  size_t *segs = malloc(n * sizeof *segs);
  for (size_t i = 0; i < n; i++) segs[i] = 2;
  lw_splines *sp = lw_splines_new(n, segs, NULL);
  free(segs);
  cr_assert_not_null(sp);
  rng_seed(seed);
  for (size_t i = 0; i < n; i++) {
    double x = urand(30, 170), y = urand(30, 120), a = urand(0, 2 * M_PI), l = urand(3, 6);
    lw_test_straight(sp, i, x, y, x + l * cos(a), y + l * sin(a));
    sp->rest_length[i] = urand(5, 10);
  }
  return sp;
}

/* Sorted along the curve, each spline intact, and a second renumbering
** changes nothing. */
Test(hilbert, renumbering_sorts_along_the_curve_and_is_idempotent)
{
  const size_t n = 300;
  lw_splines *sp = scattered(n, 41), *was = lw_splines_clone(sp);
  size_t *order = malloc(n * sizeof *order);
  cr_assert_eq(lw_hilbert_order(sp, 0, 0, 200, 150, order, NULL), 1, "random placement is not sorted already");
  cr_assert_eq(lw_splines_permute(sp, order, NULL), LW_OK);
  double prev = -1.0;
  for (size_t k = 0; k < n; k++) {
    size_t i = order[k];
    cr_assert(!memcmp(&sp->node[sp->first[k]], &was->node[was->first[i]], 3 * sizeof(lw_node)),
              "spline %zu is not old spline %zu", k, i);
    cr_assert_eq(sp->rest_length[k], was->rest_length[i]);
    for (size_t g = lw_segment_index(sp, k, 0); g < lw_segment_index(sp, k, 2); g++) cr_assert_eq(sp->seg_spline[g], k);
    /* keys grow along the new numbering */
    double cx = (sp->node[sp->first[k]].px + sp->node[sp->first[k] + 1].px + sp->node[sp->first[k] + 2].px) / 3,
           cy = (sp->node[sp->first[k]].py + sp->node[sp->first[k] + 1].py + sp->node[sp->first[k] + 2].py) / 3;
    double key = (double)lw_hilbert_index((uint32_t)(cx / 200 * 65536), (uint32_t)(cy / 150 * 65536), 16);
    cr_assert_geq(key, prev, "spline %zu out of order", k);
    prev = key;
  }
  cr_assert_eq(lw_hilbert_order(sp, 0, 0, 200, 150, order, NULL), 0, "a sorted numbering must stay");
  for (size_t k = 0; k < n; k++) cr_assert_eq(order[k], k);
  free(order);
  lw_splines_free(sp);
  lw_splines_free(was);
}

/* The run's numbering points: a placed state starts sorted, and the row's
** renumber() re-sorts a state whose splines have moved; the running energies
** stay, and the refresh that follows it finds no drift. */
Test(hilbert, the_spline_row_starts_sorted_and_renumbers_between_sweeps)
{
  lw_params p;
  lw_params_defaults(&p);
  p.width = 200;
  p.height = 150;
  p.splines = 200;
  p.pair = 0.01;
  p.pair_cutoff = 4;
  lw_error err;
  const lw_system_type *t = &lw_system_splines;
  void *su = t->setup_new(&p, &err);
  cr_assert_not_null(su, "%s", err.msg);
  void *st = t->state_new(su, &p, 5, &err);
  cr_assert_not_null(st, "%s", err.msg);
  lw_system *sys = lw_system_wrap(t, st, &err);
  cr_assert_not_null(sys);
  lw_model *m = lw_splines_model(sys);
  lw_splines *sp = m->sp;
  size_t n = sp->n_splines, *order = malloc(n * sizeof *order);
  cr_assert_eq(lw_hilbert_order(sp, 0, 0, p.width, p.height, order, NULL), 0, "placed, but not sorted");
  lw_splines *sorted = lw_splines_clone(sp);
  /* exchange two splines of equal size: the numbering is no longer sorted */
  size_t a = 3, b = n - 4, len = sp->first[a + 1] - sp->first[a];
  cr_assert_eq(sp->first[b + 1] - sp->first[b], len);
  lw_node tmp[64];
  memcpy(tmp, &sp->node[sp->first[a]], len * sizeof *tmp);
  memcpy(&sp->node[sp->first[a]], &sp->node[sp->first[b]], len * sizeof *tmp);
  memcpy(&sp->node[sp->first[b]], tmp, len * sizeof *tmp);
  double ta = sp->rest_length[a];
  sp->rest_length[a] = sp->rest_length[b];
  sp->rest_length[b] = ta;
  cr_assert_eq(lw_hilbert_order(sp, 0, 0, p.width, p.height, order, NULL), 1);
  double before = t->total(st), run[LW_TERM_COUNT], term[LW_TERM_COUNT];
  cr_assert_eq(t->renumber(st, &err), LW_OK);
  cr_assert_eq(t->total(st), before, "renumbering changed the running energy");
  cr_assert(!memcmp(sp->node, sorted->node, sp->n_nodes * sizeof *sp->node), "not back in curve order");
  t->terms(st, run);
  cr_assert_eq(t->refresh(st), LW_OK);
  t->terms(st, term);
  double drift = lw_system_drift(run, term, t->n_terms);
  cr_assert(drift < 1e-12, "drift %g after renumbering", drift);
  cr_assert(lw_close_rel(lw_energy_compute(m->scene, sp, term, NULL), t->total(st), 1e-12, 1e-12));
  lw_splines_free(sorted);
  free(order);
  lw_system_free(sys);
  t->setup_free(su);
}

/* A sweep proposes at every node exactly once: at a temperature where every
** proposal is accepted each node moves.  Drawn at random, a node would be
** missed with probability (1 - 1/n)^n ~ 0.37. */
Test(sweep, a_sweep_moves_every_node_once)
{
  lw_params p;
  lw_params_defaults(&p);
  p.width = 200;
  p.height = 150;
  lw_scene sc;
  lw_error err;
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_OK, "%s", err.msg);
  lw_model *m = lw_model_new(&sc, scattered(100, 9), &err);
  cr_assert_not_null(m, "%s", err.msg);
  const double w[LW_MOVE_KINDS] = {1, 0, 0, 0}, st[LW_MOVE_KINDS] = {0.01, 0.01, 0.01, 0.01},
               tg[LW_MOVE_KINDS] = {0.44, 0.44, 0.3, 0.3};
  lw_chain *c = model_chain(m, w, st, tg, 3, &err);
  cr_assert_not_null(c, "%s", err.msg);
  c->temperature = 1e300;
  for (int s = 0; s < 4; s++) {
    lw_splines *was = lw_splines_clone(m->sp);
    unsigned long acc0 = c->stats[LW_MOVE_POINT].accepted, prop0 = c->stats[LW_MOVE_POINT].proposed;
    cr_assert_eq(lw_chain_sweep(c), LW_OK);
    cr_assert_eq(c->stats[LW_MOVE_POINT].proposed - prop0, m->sp->n_nodes);
    cr_assert_eq(c->stats[LW_MOVE_POINT].accepted - acc0, m->sp->n_nodes, "refused: %lu irregular, %lu NaN",
                 c->stats[LW_MOVE_POINT].irregular, c->stats[LW_MOVE_POINT].nan);
    for (size_t k = 0; k < m->sp->n_nodes; k++)
      cr_assert(m->sp->node[k].px != was->node[k].px, "sweep %d: node %zu was not visited", s, k);
    lw_splines_free(was);
  }
  model_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

/* The phase a watcher reads: the name set last, and the time since. */
Test(phase, the_current_phase_and_its_duration)
{
  static const char *const what = "writing state.lw";
  lw_phase_set(what);
  const struct timespec pause = {0, 20000000};
  nanosleep(&pause, NULL);
  double t;
  cr_assert_eq(lw_phase_get(&t), what);
  cr_assert(t >= 0.019 && t < 5.0, "phase lasted %g s", t);
  lw_phase_set(NULL);
  cr_assert_null(lw_phase_get(&t));
  cr_assert_eq(t, 0.0);
}

/* The watcher's rule on a made-up clock: a phase is named once it has
** lasted over a second (a log: one line; a terminal: its seconds counted in
** place), its time is given when it ends or another starts, and shorter
** phases print nothing. */
Test(phase, the_watcher_names_phases_over_a_second_and_their_time)
{
  static const char *const a = "placing", *const b = "drawing the final files", *const c = "writing state.lw";
  char buf[256];
  lw_phase_watch log = {.tty = 0};
  const struct {
    const char *what;
    double t;
    const char *want;
  } steps[] = {
    {NULL, 0.0, ""},
    {a, 0.5, ""},
    {a, 0.95, ""},
    {b, 0.1, ""}, /* a ended unannounced */
    {b, 1.05, "linewise: drawing the final files...\n"},
    {b, 2.0, ""}, /* a log gets one line */
    {b, 3.44, ""},
    {c, 0.2, "linewise: drawing the final files: done in 3.4 s\n"},
    {NULL, 0.0, ""},
    {c, 1.5, "linewise: writing state.lw...\n"},
  };
  for (size_t k = 0; k < sizeof steps / sizeof *steps; k++)
    cr_assert_str_eq(lw_phase_watch_tick(&log, steps[k].what, steps[k].t, buf, sizeof buf), steps[k].want,
                     "log, step %zu", k);
  cr_assert_str_eq(lw_phase_watch_end(&log, LW_PHASE_FAILED, buf, sizeof buf),
                   "linewise: writing state.lw: failed after 1.5 s\n");
  cr_assert_str_eq(lw_phase_watch_end(&log, LW_PHASE_DONE, buf, sizeof buf), "");
  /* a quench a signal stopped said "done in" */
  cr_assert_str_eq(lw_phase_watch_tick(&log, a, 2.5, buf, sizeof buf), "linewise: placing...\n");
  cr_assert_str_eq(lw_phase_watch_end(&log, LW_PHASE_STOPPED, buf, sizeof buf),
                   "linewise: placing: stopped after 2.5 s\n");

  lw_phase_watch tty = {.tty = 1};
  cr_assert_str_eq(lw_phase_watch_tick(&tty, b, 0.9, buf, sizeof buf), "");
  cr_assert_str_eq(lw_phase_watch_tick(&tty, b, 1.05, buf, sizeof buf), "\r\033[Klinewise: drawing the final files... 1 s");
  cr_assert_str_eq(lw_phase_watch_tick(&tty, b, 1.6, buf, sizeof buf), "");
  cr_assert_str_eq(lw_phase_watch_tick(&tty, b, 2.06, buf, sizeof buf), "\r\033[Klinewise: drawing the final files... 2 s");
  /* another long phase seen first at 1.3 s: the old one's time, then it */
  cr_assert_str_eq(lw_phase_watch_tick(&tty, c, 1.3, buf, sizeof buf),
                   "\r\033[Klinewise: drawing the final files: done in 2.1 s\n\r\033[Klinewise: writing state.lw... 1 s");
  cr_assert_str_eq(lw_phase_watch_tick(&tty, NULL, 0.0, buf, sizeof buf),
                   "\r\033[Klinewise: writing state.lw: done in 1.3 s\n");
  cr_assert_str_eq(lw_phase_watch_end(&tty, LW_PHASE_DONE, buf, sizeof buf), "");
}
