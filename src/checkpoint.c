/*
** checkpoint.c -- the run data of state.lw (checkpoint.h), by name:
**
**   [run]           scene, seed, sweep (state.h); the schedule's inputs
**                   (temperature, block, t_prev, prev_stats, block_energy, block_shift),
**                   energy_initial, max_drift, size_peak, trace_bytes and
**                   trace_mark.<move kind>
**   [chain], [chain K]   rung 0's and rung K's chain: rng, step.<move>,
**                   window.<move>, moves.<move>, and energy.<term> (the
**                   running totals of the replica at that rung)
**   [tempering]     the exchange machinery
**   [system <name>], [system <name> K]   the system's state at each rung,
**                   written and read by the system's row (system.h; for
**                   splines [system splines])
**
** The run-level parts see the system only through its row: move kinds and
** terms by the row's names, the chain's n_moves, the row's n_terms.  Keys
** per move kind and per term are optional on reading: a file written
** before a term or a move kind existed resumes with 0 (energy, counts) or
** the scene's initial step.  Anything unknown is refused (lw_ckpt_unread).
** Format 1 (the upgrade below) only ever held splines, so that part and
** lw_checkpoint_check_finite are the spline system's.
*/
#include "linewise/checkpoint.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "linewise/anneal_net.h"
#include "linewise/model.h"
#include "linewise/number.h"
#include "linewise/output.h"
#include "linewise/phase.h"
#include "linewise/state.h"
#include "linewise/sys_splines.h"

_Static_assert(2 * LW_TEMPERING_MAX <= LW_CKPT_LIST_MAX, "at_label holds two counts a replica");

#define COUNT_MAX 9007199254740992.0 /* 2^53 */

static void rung_section(char *buf, size_t n, const char *base, int k)
{
  if (k == 0) snprintf(buf, n, "%s", base);
  else snprintf(buf, n, "%s %d", base, k);
}

static void dir_file(char *buf, size_t n, const lw_anneal *a, const char *name) { lw_path_join(buf, n, a->dir, name); }

void lw_checkpoint_system_section(char *buf, size_t n, const lw_system_type *t, int k)
{
  if (k == 0) snprintf(buf, n, "system %s", t->name);
  else snprintf(buf, n, "system %s %d", t->name, k);
}

/* The rung of a section "BASE" (0) or "BASE K" (K from 1), else -1. */
static long rung_of(const char *name, const char *base)
{
  size_t n = strlen(base);
  if (strncmp(name, base, n)) return -1;
  if (!name[n]) return 0;
  char *end;
  long k = name[n] == ' ' && name[n + 1] >= '1' && name[n + 1] <= '9' ? strtol(name + n + 1, &end, 10) : -1;
  return k >= 1 && k < LW_TEMPERING_MAX && !*end ? k : -1;
}

static int chain_section(const char *name) { return rung_of(name, "chain") >= 0; }

typedef struct {
  char system[80]; /* "system NAME" of the scene's system */
  long rungs;      /* the [chain] sections the file has */
} known_ctx;

/* "run", "tempering", "dynamics", "chain" or "chain K", "system NAME" or
** "system NAME K", NAME the scene's system and K below the chains' count. */
static int section_known(const char *name, const void *ctx)
{
  const known_ctx *k = ctx;
  static const char *const plain[] = {"run", "tempering", "dynamics"};
  for (size_t i = 0; i < sizeof plain / sizeof plain[0]; i++)
    if (!strcmp(name, plain[i])) return 1;
  long r = rung_of(name, "chain");
  if (r < 0) r = rung_of(name, k->system);
  return r >= 0 && r < (k->rungs > 0 ? k->rungs : 1);
}

lw_status lw_checkpoint_sections_known(const lw_ckpt *doc, const char *system, lw_error *err)
{
  known_ctx k;
  snprintf(k.system, sizeof k.system, "system %s", system);
  k.rungs = (long)lw_ckpt_count_sections(doc, chain_section);
  return lw_ckpt_known_sections(doc, section_known, &k, err);
}

/* ---- writing ---------------------------------------------------------------- */

void lw_checkpoint_put_chain(lw_ckpt_writer *w, const lw_anneal *a, int k, int *bad)
{
  const lw_system_type *t = a->sys_type;
  const lw_chain *c = a->chains[k];
  char sec[32], key[96];
  double term[LW_SYSTEM_TERMS_MAX];
  rung_section(sec, sizeof sec, "chain", k);
  lw_ckpt_section(w, sec);
  char *hex = lw_rng_save(c->rng);
  if (!hex) *bad = 1;
  else lw_ckpt_put(w, "rng", "%s", hex);
  free(hex);
  for (int m = 0; m < c->n_moves; m++) {
    const char *name = t->move_names[m];
    const lw_move_stats *st = &c->stats[m];
    snprintf(key, sizeof key, "step.%s", name);
    lw_ckpt_put_numbers(w, key, &c->step[m], 1);
    snprintf(key, sizeof key, "window.%s", name);
    lw_ckpt_put_counts(w, key, (unsigned long[]){c->win_prop[m], c->win_acc[m]}, 2);
    snprintf(key, sizeof key, "moves.%s", name);
    lw_ckpt_put_counts(w, key,
                       (unsigned long[]){st->proposed, st->accepted, st->nan, st->irregular, st->crowded, st->outside},
                       6);
  }
  t->terms(c->sys->state, term);
  for (int q = 0; q < t->n_terms; q++) {
    snprintf(key, sizeof key, "energy.%s", t->term_names[q]);
    lw_ckpt_put_numbers(w, key, &term[q], 1);
  }
}

static void put_tempering(lw_ckpt_writer *w, const lw_anneal *a, int *bad)
{
  const lw_tempering *pt = a->pt;
  int n = pt->n;
  unsigned long v[2 * LW_TEMPERING_MAX];
  lw_ckpt_section(w, "tempering");
  char *hex = lw_rng_save(pt->rng);
  if (!hex) *bad = 1;
  else lw_ckpt_put(w, "rng", "%s", hex);
  free(hex);
  lw_ckpt_put_numbers(w, "ladder", pt->ladder, n);
  for (int k = 0; k < n; k++) {
    v[2 * k] = (unsigned long)pt->at[k];
    v[2 * k + 1] = (unsigned long)(pt->label[k] + 1);
  }
  lw_ckpt_put_counts(w, "at_label", v, 2 * n);
  for (int k = 0; k + 1 < n; k++) {
    v[2 * k] = pt->tried[k];
    v[2 * k + 1] = pt->accepted[k];
  }
  lw_ckpt_put_counts(w, "swaps", v, 2 * (n - 1));
  for (int k = 0; k + 1 < n; k++) {
    v[2 * k] = pt->win_tried[k];
    v[2 * k + 1] = pt->win_accepted[k];
  }
  lw_ckpt_put_counts(w, "window", v, 2 * (n - 1));
  lw_ckpt_put_counts(w, "trace_mark", a->swap_mark, 2 * (n - 1));
  lw_ckpt_put_counts(w, "round_trips", &pt->round_trips, 1);
  lw_ckpt_put_counts(w, "steps", &pt->steps, 1);
}

/* [dynamics]: the clock, the counters and the momenta (the positions are
** the system's state); four momenta a line. */
static void put_dynamics(lw_ckpt_writer *w, const lw_dynamics *d)
{
  lw_ckpt_section(w, "dynamics");
  lw_ckpt_put_numbers(w, "time", &d->time, 1);
  lw_ckpt_put_counts(w, "steps", (unsigned long[]){d->steps, d->halvings, (unsigned long)d->iterations_max}, 3);
  for (size_t i = 0; i < d->n; i += 4) lw_ckpt_put_numbers(w, "momentum", d->pi + i, d->n - i < 4 ? (int)(d->n - i) : 4);
}

/* replica-K.lw: a plain state of rung K for the user (init.from, energy):
** the header and the system's section as for the coldest rung. */
lw_status lw_checkpoint_write_replica(const lw_anneal *a, int k, lw_error *err)
{
  lw_state head = {.scene = "scene.ini", .seed = a->seed, .sweep = a->sweep};
  char name[64], path[LW_PATH_MAX + 64];
  snprintf(name, sizeof name, "replica-%d.lw", k);
  dir_file(path, sizeof path, a, name);
  lw_ckpt_writer w;
  /* (under MPI every process writes its rungs' files: the first one's check
  ** kept none of the others out of a directory made in its place) */
  lw_status s = lw_anneal_dir_ours(a, err);
  if (s || (s = lw_ckpt_begin(&w, path, LW_STATE_HEADER, err))) return s;
  w.no_sum = a->unsummed;
  lw_state_put_header(&w, &head);
  lw_checkpoint_system_section(name, sizeof name, a->sys_type, 0);
  if ((s = a->sys_type->save(a->chains[k]->sys->state, &w, name, err))) {
    lw_ckpt_abort(&w);
    return s;
  }
  return lw_ckpt_commit(&w, err);
}

lw_status lw_checkpoint_sync_trace(lw_anneal *a, long *bytes, lw_error *err)
{
  char path[LW_PATH_MAX + 32];
  *bytes = 0;
  if (!a->trace) return LW_OK;
  dir_file(path, sizeof path, a, "trace.csv");
  /* a row cut by a disk full for a moment leaves the flag and a later
  ** flush that succeeds: the state must not count the rows so damaged (a
  ** resume cuts the trace back to the checkpoint before) */
  if (ferror(a->trace))
    return lw_error_set(err, LW_EIO, "%s: write failed: a row since the last checkpoint was not written whole (a full "
                        "disk, a file-size limit?)", path);
  if (fflush(a->trace) || fsync(fileno(a->trace)) || (*bytes = ftell(a->trace)) < 0)
    return lw_error_set(err, LW_EIO, "%s: write failed: %s", path, strerror(errno));
  return LW_OK;
}

void lw_checkpoint_put_run(lw_ckpt_writer *w, const lw_anneal *a, long trace_bytes)
{
  lw_state head = {.scene = "scene.ini", .seed = a->seed, .sweep = a->sweep};
  lw_state_put_header(w, &head);
  /* where the run stops: a resume --sweeps N that is stopped or killed
  ** goes on to it, not to the scene's anneal.sweeps */
  lw_ckpt_put(w, "end_sweep", "%ld", a->end_sweep);
  /* what scene.ini held when the run started: a resume refuses another */
  lw_ckpt_put(w, "scene_hash", "%016llx", a->scene_hash);
  /* each key's part, so that a refusal can name the keys edited */
  char keys[4 * LW_PARAM_MAX + 1];
  for (size_t k = 0; k < a->scene_keys.n; k++) snprintf(keys + 4 * k, 5, "%04x", a->scene_keys.hash[k]);
  keys[4 * a->scene_keys.n] = '\0';
  lw_ckpt_put(w, "scene_keys", "%s", keys);
  lw_ckpt_put(w, "temperature", "%.17g", a->t_sched);
  lw_ckpt_put(w, "block", "%ld", a->block);
  lw_ckpt_put(w, "t_prev", "%.17g", a->t_prev);
  lw_ckpt_put(w, "prev_stats", "%.17g %.17g %ld", a->prev.mean, a->prev.sd, a->prev.samples);
  lw_ckpt_put(w, "block_energy", "%.17g %.17g %.17g", a->acc_n, a->acc_sum, a->acc_sumsq);
  if (!a->acc_unshifted) lw_ckpt_put(w, "block_shift", "%.17g", a->acc_shift);
  lw_ckpt_put(w, "energy_initial", "%.17g", a->energy_initial);
  lw_ckpt_put(w, "max_drift", "%.17g", a->max_drift);
  /* when the energy is next recomputed hangs on them (anneal.c,
  ** refresh_due): a resume that began them afresh took other decisions */
  lw_ckpt_put_numbers(w, "size_peak", a->size_peak, a->n_rep);
  lw_ckpt_put(w, "trace_bytes", "%ld", trace_bytes);
  const lw_system_type *t = a->sys_type;
  for (int m = 0; m < a->chain->n_moves; m++) {
    char key[96];
    const lw_move_stats *st = &a->trace_mark[m];
    snprintf(key, sizeof key, "trace_mark.%s", t->move_names[m]);
    lw_ckpt_put_counts(w, key, (unsigned long[]){st->proposed, st->accepted, st->nan}, 3);
  }
}

void lw_checkpoint_put_ensemble(lw_ckpt_writer *w, const lw_anneal *a, int *bad)
{
  if (a->pt) put_tempering(w, a, bad);
  if (a->dyn) put_dynamics(w, a->dyn);
}

lw_status lw_checkpoint_put_system(lw_ckpt_writer *w, const lw_anneal *a, int k, lw_error *err)
{
  char sec[96];
  lw_checkpoint_system_section(sec, sizeof sec, a->sys_type, k);
  return a->sys_type->save(a->chains[k]->sys->state, w, sec, err);
}

lw_status lw_checkpoint_write_timing(const lw_anneal *a, lw_error *err)
{
  char path[LW_PATH_MAX + 32], aside[LW_PATH_MAX + 40], tmp[LW_PATH_MAX + 64];
  dir_file(path, sizeof path, a, "timing.txt");
  /* a spread run's process that draws, not the first, writes it after the
  ** drawing under a name of its own: the first's checkpoint may still be
  ** writing timing.txt.tmp, and each would remove the other's */
  snprintf(aside, sizeof aside, "%s%s", path, a->net && a->net->rank ? ".drawn" : "");
  FILE *f = lw_output_open_tmp(aside, tmp, sizeof tmp, err);
  if (!f) return err->code;
  fprintf(f, "wall_seconds %.17g\nsweep_seconds %.17g\n", lw_anneal_seconds(a), a->sweep_seconds);
  if (a->untimed) fprintf(f, "untimed_proposals %lu\n", a->untimed);
  return lw_output_commit(f, tmp, path, err);
}

/* The first checkpoint of a run that replaces another, set aside in
** DIR/.replaced until state.lw is committed: a stop asked by then makes the
** new run, no sweep done, give way (a Ctrl-C just after starting a run into
** a directory by mistake would else cost the run that was there), and the
** caller puts that run back (lw_anneal_undo_start).  Asked just before the
** commit, once the rest is written, and after marking it (lw_phase_stash
** 2), while the signal handler sets the stop before it reads the mark: one
** of them sees the other, so the handler never says the run before comes
** back when it goes (asked after the commit, a second signal there left the
** new state.lw beside the stash, and the next resume dropped the run the
** message said would come back).  One process only: a spread run's processes
** stop together, at a sweep. */
static int gives_way(lw_anneal *a, lw_error *err)
{
  if (!a->fresh || !a->stashed || a->net) return 0;
  lw_phase_stash(2);
  if (!lw_phase_stopping()) return 0;
  lw_phase_stash(1);
  a->gave_way = 1;
  lw_error_set(err, LW_ERUN, "%s: stopped during the set-up", a->dir);
  return 1;
}

lw_status lw_checkpoint_commit(lw_ckpt_writer *w, const lw_anneal *a, lw_error *err)
{
  lw_phase_committing(a->sweep);
  lw_status s = lw_ckpt_commit(w, err);
  if (s) lw_phase_committing(-1);
  else lw_phase_committed(a->sweep);
  return s;
}

lw_status lw_checkpoint_write(lw_anneal *a, lw_error *err)
{
  char path[LW_PATH_MAX + 32];
  long trace_bytes = 0;
  /* The trace first, on disk: the state that records its length must
  ** never be newer than the rows it counts. */
  lw_status s = lw_checkpoint_sync_trace(a, &trace_bytes, err);
  if (s) return s;
  dir_file(path, sizeof path, a, "state.lw");
  lw_ckpt_writer w;
  if ((s = lw_ckpt_begin(&w, path, LW_STATE_HEADER, err))) return s;
  w.no_sum = a->unsummed;
  lw_checkpoint_put_run(&w, a, trace_bytes);
  int bad = 0;
  for (int k = 0; k < a->n_rep; k++) lw_checkpoint_put_chain(&w, a, k, &bad);
  lw_checkpoint_put_ensemble(&w, a, &bad);
  for (int k = 0; k < a->n_rep; k++)
    if ((s = lw_checkpoint_put_system(&w, a, k, err))) {
      lw_ckpt_abort(&w);
      return s;
    }
  if (bad) {
    lw_ckpt_abort(&w);
    return lw_error_set(err, LW_ENOMEM, "out of memory writing a checkpoint");
  }
  if (gives_way(a, err)) {
    lw_ckpt_abort(&w);
    return err->code;
  }
  if ((s = lw_checkpoint_commit(&w, a, err))) return s;
  for (int k = 1; k < a->n_rep && !s; k++) s = lw_checkpoint_write_replica(a, k, err);
  /* Wall time differs from run to run, so it lives beside the state, which
  ** must be byte-identical for the same sweeps. */
  return s ? s : lw_checkpoint_write_timing(a, err);
}

/* ---- reading ---------------------------------------------------------------- */

static lw_status get_rng(lw_ckpt *doc, const char *sec, gsl_rng *r, lw_error *err)
{
  int line = 0;
  const char *hex = lw_ckpt_text(doc, sec, "rng", &line);
  if (!hex && !lw_ckpt_has(doc, sec)) return lw_ckpt_no_section(doc, sec, err);
  if (!hex) return lw_error_set(err, LW_EINPUT, "%s: [%s] rng: missing", lw_ckpt_path(doc), sec);
  if (!lw_rng_load(r, hex))
    return lw_error_set(err, LW_EINPUT, "%s:%d: [%s] rng: expected the state of a %s generator in hex (%zu digits)",
                        lw_ckpt_path(doc), line, sec, gsl_rng_name(r), 2 * gsl_rng_size(r));
  return LW_OK;
}

static lw_status get_chain(lw_ckpt *doc, int k, const lw_system_type *t, lw_chain *c, lw_error *err)
{
  char sec[32], key[96];
  const char *path = lw_ckpt_path(doc);
  rung_section(sec, sizeof sec, "chain", k);
  lw_status s = get_rng(doc, sec, c->rng, err);
  for (int m = 0; m < c->n_moves && !s; m++) {
    const char *name = t->move_names[m];
    unsigned long v[6] = {0, 0, 0, 0, 0, 0};
    /* a kind a newer release added has none of its three lines (counts at
    ** 0, the scene's step); one line without the others was taken out, and
    ** reading on would restart that step silently */
    static const char *const part[3] = {"step", "window", "moves"};
    int has[3], there = 0;
    for (int q = 0; q < 3; q++) {
      snprintf(key, sizeof key, "%s.%s", part[q], name);
      there += has[q] = lw_ckpt_text(doc, sec, key, NULL) != NULL;
    }
    if (there == 1 || there == 2) {
      int gone = !has[0] ? 0 : !has[1] ? 1 : 2, kept = has[0] ? 0 : has[1] ? 1 : 2;
      char what[160];
      snprintf(what, sizeof what, "[%s] %s.%s", sec, part[gone], name);
      snprintf(key, sizeof key, "a damaged or edited file: %s.%s is there", part[kept], name);
      s = lw_ckpt_missing(doc, what, key, err);
      break;
    }
    snprintf(key, sizeof key, "step.%s", name);
    /* tuning keeps steps in [1e-300, step_max] (mc.c), but a step never
    ** tuned (moves.tune_sweeps = 0, the dynamics, a stop before the first
    ** tuning) is still the scene's, which may be larger, or smaller (a
    ** scene's step of 1e-310 wrote a state its resume called damaged): c's
    ** own, as the scene set it; a kind without a step has 0, or before
    ** 2026-12 whatever tuning had left in [0, 1] */
    if (c->step_max[m] > 0.0)
      s = lw_ckpt_numbers(doc, sec, key, &c->step[m], 1, fmin(1e-300, c->step[m]), fmax(c->step_max[m], c->step[m]),
                          0, err);
    else if (!(s = lw_ckpt_numbers(doc, sec, key, &c->step[m], 1, 0.0, 1.0, 0, err))) c->step[m] = 0.0;
    if (s) break;
    snprintf(key, sizeof key, "window.%s", name);
    if ((s = lw_ckpt_counts(doc, sec, key, v, 2, 0, err))) break;
    if (v[1] > v[0]) {
      s = lw_error_set(err, LW_EINPUT, "%s: [%s] %s: more accepted (%lu) than proposed (%lu)", path, sec, key, v[1], v[0]);
      break;
    }
    c->win_prop[m] = v[0];
    c->win_acc[m] = v[1];
    snprintf(key, sizeof key, "moves.%s", name);
    memset(v, 0, sizeof v);
    /* the crowded and outside counts are new: older files have four or five */
    if ((s = lw_ckpt_counts_upto(doc, sec, key, v, 4, 6, 0, err))) break;
    unsigned long left = v[0];
    int fits = 1;
    for (int q = 1; q < 6 && fits; q++) {
      fits = v[q] <= left;
      left -= fits ? v[q] : 0;
    }
    if (!fits) {
      s = lw_error_set(err, LW_EINPUT, "%s: [%s] %s: expected 'proposed accepted nan irregular crowded outside' "
                       "with accepted + nan + irregular + crowded + outside <= proposed, got %lu %lu %lu %lu %lu %lu",
                       path, sec, key, v[0], v[1], v[2], v[3], v[4], v[5]);
      break;
    }
    c->stats[m] = (lw_move_stats){v[0], v[1], v[2], v[3], v[4], v[5]};
  }
  return s;
}

/* Spline i of sp alone, or from node m to m + 1 alone when m >= 0. */
static lw_splines *part(const lw_splines *sp, size_t i, long m)
{
  size_t segs = m >= 0 ? 1 : lw_splines_segments(sp, i), off = sp->first[i] + (m >= 0 ? (size_t)m : 0);
  lw_splines *one = lw_splines_new(1, &segs, NULL);
  if (one) {
    memcpy(one->node, sp->node + off, (segs + 1) * sizeof *one->node);
    one->rest_length[0] = m >= 0 ? sp->rest_length[i] / (double)lw_splines_segments(sp, i) : sp->rest_length[i];
  }
  return one;
}

static int part_finite(const lw_scene *sc, const lw_splines *sp, size_t i, long m)
{
  double t[LW_TERM_COUNT];
  lw_splines *one = part(sp, i, m);
  int ok = !one || isfinite(lw_energy_compute(sc, one, t, NULL));
  lw_splines_free(one);
  return ok;
}

lw_status lw_checkpoint_check_finite(const lw_scene *sc, const lw_splines *sp, const double term[LW_TERM_COUNT],
                                     const char *path, lw_error *err)
{
  int bad = -1;
  for (int t = 0; t < LW_TERM_COUNT && bad < 0; t++)
    if (!isfinite(term[t])) bad = t;
  if (bad < 0) return LW_OK;
  /* the culprit, searched only now that there is one */
  for (size_t i = 0; i < sp->n_splines; i++) {
    if (part_finite(sc, sp, i, -1)) continue;
    for (size_t m = 0; m < lw_splines_segments(sp, i); m++)
      if (!part_finite(sc, sp, i, (long)m))
        return lw_error_set(err, LW_EINPUT, "%s: spline %zu segment %zu (nodes %zu and %zu): the %s energy is not "
                            "finite (%s)", path, i, m, m, m + 1, lw_term_names[bad],
                            bad == LW_TERM_BOUNDARY ? "outside the frame, or closer to it than "
                            "energy.boundary_clearance allows" : "coordinates too large");
    return lw_error_set(err, LW_EINPUT, "%s: spline %zu: the %s energy is not finite", path, i,
                        lw_term_names[bad]);
  }
  return lw_error_set(err, LW_EINPUT, "%s: the %s energy of this state is not finite (curves that coincide, or cross "
                      "with energy.pair_near = 0?)", path, lw_term_names[bad]);
}

/* The running totals carry the rounding of the moves so far; restoring them
** (rather than the fresh sums) keeps the trace identical to an uninterrupted
** run.  They must still agree with the fresh sums (the row's load computed
** them, and refused a state whose energies are not finite) to rounding,
** which also makes an edited total an error. */
static lw_status get_energy(lw_ckpt *doc, int k, const lw_system_type *t, lw_system *sys, lw_error *err)
{
  char sec[32], key[96];
  rung_section(sec, sizeof sec, "chain", k);
  double fresh[LW_SYSTEM_TERMS_MAX], run[LW_SYSTEM_TERMS_MAX], scale = 1.0;
  t->terms(sys->state, fresh);
  for (int q = 0; q < t->n_terms; q++) {
    if (!isfinite(fresh[q]))
      return lw_error_set(err, LW_EINPUT, "%s: [system %s%s%.0d]: the %s energy of this state is not finite",
                          lw_ckpt_path(doc), t->name, k ? " " : "", k, t->term_names[q]);
    scale += fabs(fresh[q]);
  }
  lw_status s;
  for (int q = 0; q < t->n_terms; q++) {
    const char *name = t->term_names[q];
    double v = 0.0; /* a term the writer did not know was off */
    snprintf(key, sizeof key, "energy.%s", name);
    if ((s = lw_ckpt_numbers(doc, sec, key, &v, 1, -DBL_MAX, DBL_MAX, 0, err))) return s;
    if (!(fabs(v - fresh[q]) <= 1e-6 * scale))
      return lw_error_set(err, LW_EINPUT, "%s: [%s] %s: %.17g, but the state is at %.17g (the file was changed "
                          "or damaged, a file the scene reads was changed: its picture, field or table, or the run "
                          "was begun by a release whose energy differs: docs/FORMATS.md, \"Runs of older "
                          "releases\")",
                          lw_ckpt_path(doc), sec, key, v, fresh[q]);
    run[q] = v;
  }
  t->set_terms(sys->state, run);
  return LW_OK;
}

/* The line of a [tempering] key read already, for a message about its
** value ("file:line: [tempering] key: ..."). */
static int tempering_line(lw_ckpt *doc, const char *key)
{
  int line = 0;
  lw_ckpt_text(doc, "tempering", key, &line);
  return line;
}

static lw_status get_tempering(lw_ckpt *doc, lw_anneal *a, lw_error *err)
{
  lw_tempering *pt = a->pt;
  int n = pt->n;
  const char *path = lw_ckpt_path(doc);
  unsigned long v[2 * LW_TEMPERING_MAX];
  lw_status s;
  if ((s = get_rng(doc, "tempering", pt->rng, err)) ||
      /* (any positive rung the scene may set: one of 1e-310 ran, and its
      ** resume was refused) */
      (s = lw_ckpt_numbers(doc, "tempering", "ladder", pt->ladder, n, DBL_TRUE_MIN, 1e300, 1, err)))
    return s;
  for (int k = 1; k < n; k++)
    if (!(pt->ladder[k] > pt->ladder[k - 1]))
      return lw_error_set(err, LW_EINPUT, "%s:%d: [tempering] ladder: expected increasing temperatures", path,
                          tempering_line(doc, "ladder"));
  if ((s = lw_ckpt_counts(doc, "tempering", "at_label", v, 2 * n, 1, err))) return s;
  int seen[LW_TEMPERING_MAX] = {0};
  for (int k = 0; k < n; k++) {
    unsigned long r = v[2 * k];
    if (r >= (unsigned long)n || seen[r] || v[2 * k + 1] > 2)
      return lw_error_set(err, LW_EINPUT, "%s:%d: [tempering] at_label: expected a permutation of the replicas, "
                          "each with a direction 0, 1 or 2", path, tempering_line(doc, "at_label"));
    seen[r] = 1;
    pt->at[k] = (int)r;
    pt->label[k] = (int)v[2 * k + 1] - 1;
  }
  static const char *const pairs[] = {"swaps", "window", "trace_mark"};
  for (int q = 0; q < 3; q++) {
    if ((s = lw_ckpt_counts(doc, "tempering", pairs[q], v, 2 * (n - 1), 1, err))) return s;
    for (int k = 0; k + 1 < n; k++)
      if (v[2 * k + 1] > v[2 * k])
        return lw_error_set(err, LW_EINPUT, "%s:%d: [tempering] %s: more accepted than tried at pair %d", path,
                            tempering_line(doc, pairs[q]), pairs[q], k);
    for (int k = 0; k + 1 < n; k++) {
      unsigned long *tried = q == 0 ? pt->tried : q == 1 ? pt->win_tried : NULL;
      unsigned long *acc = q == 0 ? pt->accepted : q == 1 ? pt->win_accepted : NULL;
      if (tried) {
        tried[k] = v[2 * k];
        acc[k] = v[2 * k + 1];
      } else {
        a->swap_mark[2 * k] = v[2 * k];
        a->swap_mark[2 * k + 1] = v[2 * k + 1];
      }
    }
  }
  for (int k = 0; k + 1 < n; k++)
    if (a->swap_mark[2 * k] > pt->tried[k] || pt->win_tried[k] > pt->tried[k]) {
      const char *key = pt->win_tried[k] > pt->tried[k] ? "window" : "trace_mark";
      return lw_error_set(err, LW_EINPUT, "%s:%d: [tempering] %s: %lu tried at pair %d, beyond the %lu of swaps", path,
                          tempering_line(doc, key), key, pt->win_tried[k] > pt->tried[k] ? pt->win_tried[k]
                          : a->swap_mark[2 * k], k, pt->tried[k]);
    }
  if ((s = lw_ckpt_counts(doc, "tempering", "round_trips", &pt->round_trips, 1, 1, err)) ||
      (s = lw_ckpt_counts(doc, "tempering", "steps", &pt->steps, 1, 1, err)))
    return s;
  /* systems[] is by replica: rung k holds replica at[k] */
  lw_system *by_rung[LW_TEMPERING_MAX];
  for (int k = 0; k < n; k++) by_rung[k] = a->systems[k];
  for (int k = 0; k < n; k++) a->systems[pt->at[k]] = by_rung[k];
  return LW_OK;
}

static lw_status get_dynamics(lw_ckpt *doc, lw_dynamics *d, lw_error *err)
{
  const char *path = lw_ckpt_path(doc), *key, *val;
  lw_status s;
  unsigned long u[3];
  if ((s = lw_ckpt_numbers(doc, "dynamics", "time", &d->time, 1, 0, DBL_MAX, 1, err)) ||
      (s = lw_ckpt_counts(doc, "dynamics", "steps", u, 3, 1, err)))
    return s;
  d->steps = u[0];
  d->halvings = u[1];
  d->iterations_max = (int)(u[2] < 1000 ? u[2] : 1000);
  size_t pos = 0, i = 0;
  int line = 0;
  while (lw_ckpt_next(doc, "dynamics", &pos, &key, &val, &line)) {
    if (strcmp(key, "momentum")) continue;
    double v[5];
    int want = d->n - i < 4 ? (int)(d->n - i) : 4, got = i < d->n ? lw_number_list(val, 0, v, 5) : -2;
    if (got != want)
      return lw_error_set(err, LW_EINPUT, "%s:%d: [dynamics] momentum: expected %d numbers (coordinates %zu of %zu), "
                          "got '%.60s'", path, line, want, i, d->n, val);
    memcpy(d->pi + i, v, (size_t)want * sizeof *v);
    i += (size_t)want;
  }
  if (i != d->n)
    return lw_error_set(err, LW_EINPUT, "%s: [dynamics] momentum: %zu of the system's %zu coordinates%s", path, i,
                        d->n, lw_ckpt_cut_hint(doc, "dynamics"));
  return LW_OK;
}

/* The keys whose parts differ from state.lw's scene_keys (text, 4 hex
** digits a key): the first eight as "'a.b' (line N), ..." in buf, *path
** set where one of them names a file; their count, or -1 where the two do
** not list as many keys. */
static int edited_keys(const lw_params *p, const lw_run_keys *now, const char *text, char *buf, size_t n,
                       int *path, int *unread_key)
{
  if (strlen(text) != 4 * now->n || strspn(text, "0123456789abcdef") != strlen(text)) return -1;
  int count = 0;
  size_t used = 0;
  buf[0] = '\0';
  *path = 0;
  *unread_key = -1;
  for (size_t k = 0; k < now->n; k++) {
    char part[5] = {text[4 * k], text[4 * k + 1], text[4 * k + 2], text[4 * k + 3], '\0'};
    if (strtoul(part, NULL, 16) == now->hash[k]) continue;
    const lw_param_def *d = &lw_param_table[now->index[k]];
    if (now->unread[k] && *unread_key < 0) *unread_key = (int)k;
    if (d->type == LW_PT_STRING && !strcmp(d->unit, "path")) *path = 1;
    if (count < 8 && used < n)
      used += (size_t)snprintf(buf + used, n - used, "%s'%s.%s' (line %d)", count ? ", " : "", d->section, d->key,
                               p->line[now->index[k]]);
    else if (count == 8 && used < n)
      used += (size_t)snprintf(buf + used, n - used, ", ...");
    count++;
  }
  return count;
}

/* The key whose line was taken out, where the stored hashes (text, one
** more than now's) match now's but for one left out: it lies between the
** two keys now holds around the gap, among those without a line.  Their
** names into buf ("" if the hashes do not line up so). */
static void removed_key(const lw_params *p, const lw_run_keys *now, const char *text, char *buf, size_t n)
{
  buf[0] = '\0';
  size_t j = 0, was = strlen(text) / 4;
  if (was != now->n + 1 || was > LW_PARAM_MAX + 1 || strspn(text, "0123456789abcdef") != strlen(text)) return;
  unsigned long stored[LW_PARAM_MAX + 1];
  for (size_t k = 0; k < was; k++) {
    char part[5] = {text[4 * k], text[4 * k + 1], text[4 * k + 2], text[4 * k + 3], '\0'};
    stored[k] = strtoul(part, NULL, 16);
  }
  while (j < now->n && stored[j] == now->hash[j]) j++;
  for (size_t k = j; k < now->n; k++)
    if (stored[k + 1] != now->hash[k]) return;
  size_t used = 0;
  const size_t lo = j ? now->index[j - 1] + 1u : 0, hi = j < now->n ? now->index[j] : lw_param_count;
  for (size_t i = lo; i < hi && used < n; i++)
    if (p->line[i] <= 0)
      used += (size_t)snprintf(buf + used, n - used, "%s'%s.%s'", used ? " or " : "", lw_param_table[i].section,
                               lw_param_table[i].key);
}

lw_status lw_checkpoint_scene_hash(lw_ckpt *doc, const lw_params *p, lw_run_keys *keys,
                                   unsigned long long *scene_hash, lw_error *err)
{
  int line = 0, kline = 0;
  *scene_hash = lw_params_run_hash(p, keys);
  /* both absent in older files; scene_keys read either way, or it stays unread */
  const char *hash = lw_ckpt_text(doc, "run", "scene_hash", &line);
  const char *text = lw_ckpt_text(doc, "run", "scene_keys", &kline);
  const char *path = lw_ckpt_path(doc), *scene = p->file;
  /* scene_keys came a day after scene_hash: a file with it and without the
  ** hash is damaged, not old, and took no edit of scene.ini for one */
  if (!hash && text) return lw_ckpt_missing(doc, "[run] scene_hash", "a line taken out", err);
  if (!hash) return LW_OK;
  if (strlen(hash) != 16 || strspn(hash, "0123456789abcdef") != 16)
    return lw_error_set(err, LW_EINPUT, "%s:%d: [run] scene_hash: expected 16 hexadecimal digits, got '%s'", path,
                        line, hash);
  const unsigned long long h = strtoull(hash, NULL, 16);
  /* and the hash of this release's kind without scene_keys: that line taken
  ** out (it was "scene.ini edited", nothing edited) */
  if (!text && h == *scene_hash)
    return lw_ckpt_missing(doc, "[run] scene_keys", "a line taken out", err);
  /* (read whether or not the hashes agree, and as many keys as the scene
  ** hashes where they do: junk there passed, and a cut line misnamed a
  ** later edit) */
  if (text && (strlen(text) % 4 || strspn(text, "0123456789abcdef") != strlen(text) ||
               (h == *scene_hash && strlen(text) / 4 != keys->n)))
    return lw_error_set(err, LW_EINPUT, "%s:%d: [run] scene_keys: expected 4 hexadecimal digits for each of the %zu "
                        "keys the scene hashes, got '%.40s%s'", path, kline, keys->n, text,
                        strlen(text) > 40 ? "..." : "");
  /* files before 2026-12-05 hashed the files' names */
  const unsigned long long mine = text ? *scene_hash : lw_params_run_hash(p, NULL);
  if (h == mine) return LW_OK;
  static const char resumes[] = "a run resumes with the parameters and files it ran with (only [plot] and the "
                                "keys of the final files may change, docs/FORMATS.md, scene_hash; a file may move, "
                                "its key naming the new place): undo the edit; 'resume --sweeps N' runs more "
                                "sweeps, and a redraw draws the state with other keys (docs/FORMATS.md, \"Redrawing "
                                "a finished run\")";
  char which[1024];
  int in_path = 0, unread = -1, count = text ? edited_keys(p, keys, text, which, sizeof which, &in_path, &unread) : -1;
  if (unread >= 0) {
    const lw_param_def *d = &lw_param_table[keys->index[unread]];
    /* (nothing was edited: the file moved, or went, as a checkout does) */
    return lw_error_set(err, LW_EINPUT, "%s:%d: key '%s.%s': cannot read %s: %s (a run resumes with the files it "
                        "ran with: put the file back, or set this key in %s to the place it moved to)", scene,
                        p->line[keys->index[unread]], d->section, d->key, (const char *)p + d->offset,
                        strerror(keys->unread[unread]), scene);
  }
  if (count > 8)
    return lw_error_set(err, LW_EINPUT, "%s:%d: [run] scene_hash: %s and %s seem to be of different runs: %d keys "
                        "differ (%s)", path, line, path, scene, count, which);
  if (count > 0)
    return lw_error_set(err, LW_EINPUT, "%s: %s edited since the run started%s: %s", scene, which,
                        !in_path ? "" : count > 1 ? ", or a file they name changed" : ", or the file it names changed",
                        resumes);
  if (text && strlen(text) % 4 == 0 && strlen(text) / 4 != keys->n) {
    const size_t was = strlen(text) / 4;
    const size_t off = was > keys->n ? was - keys->n : keys->n - was;
    char gone[256];
    removed_key(p, keys, text, gone, sizeof gone);
    if (gone[0])
      return lw_error_set(err, LW_EINPUT, "%s: 1 key fewer than when the run started: the line of %s taken out: %s",
                          scene, gone, resumes);
    return lw_error_set(err, LW_EINPUT, "%s: %zu key%s %s than when the run started (a key's line %s?): %s", scene,
                        off, off > 1 ? "s" : "", was > keys->n ? "fewer" : "more",
                        was > keys->n ? "taken out" : "added", resumes);
  }
  return lw_error_set(err, LW_EINPUT, "%s:%d: [run] scene_hash %016llx, of scene.ini now %016llx: scene.ini was "
                      "edited in a key that steers the run, or state.lw is another run's; %s", path, line, h, mine,
                      resumes);
}

lw_status lw_checkpoint_restore(lw_anneal *a, lw_ckpt *doc, long *trace_bytes, lw_error *err)
{
  const char *path = lw_ckpt_path(doc);
  lw_status s = LW_OK;
  const lw_system_type *t = a->sys_type;
  for (int k = 0; k < a->n_rep && !s; k++)
    if (!(s = get_chain(doc, k, t, a->chains[k], err))) s = get_energy(doc, k, t, a->chains[k]->sys, err);
  if (s) return s;
  double v[3];
  unsigned long u[3];
  long block = 0, tb = -1;
  /* absent in files of older releases: the caller falls back on anneal.sweeps */
  a->end_sweep = -1;
  if ((s = lw_ckpt_whole(doc, "run", "end_sweep", &a->end_sweep, a->sweep, (long)LW_STATE_SWEEP_MAX, 0, err)))
    return s;
#define NUMS(key, n, lo, hi) if ((s = lw_ckpt_numbers(doc, "run", key, v, n, lo, hi, 1, err))) return s
  NUMS("temperature", 1, 0, DBL_MAX); a->t_sched = v[0];
  if ((s = lw_ckpt_whole(doc, "run", "block", &block, -1, a->params.steps - 1, 1, err))) return s;
  a->block = block;
  NUMS("t_prev", 1, 0, DBL_MAX); a->t_prev = v[0];
  NUMS("prev_stats", 3, -DBL_MAX, DBL_MAX);
  if (!(v[1] >= 0) || !(v[2] >= 0 && v[2] <= COUNT_MAX && v[2] == floor(v[2])))
    return lw_error_set(err, LW_EINPUT, "%s: [run] prev_stats: expected 'mean sd samples' with sd >= 0 and a whole "
                        "number of samples", path);
  a->prev = (lw_block_stats){v[0], v[1], (long)v[2]};
  NUMS("block_energy", 3, -DBL_MAX, DBL_MAX);
  if (!(v[0] >= 0 && v[0] <= COUNT_MAX && v[0] == floor(v[0]) && v[2] >= 0))
    return lw_error_set(err, LW_EINPUT, "%s: [run] block_energy: expected 'samples sum sum-of-squares' with a whole "
                        "number of samples and a sum of squares >= 0", path);
  a->acc_n = v[0]; a->acc_sum = v[1]; a->acc_sumsq = v[2];
  /* (files before 2026-12-07 lack it: their runs go on summing whole) */
  a->acc_unshifted = !lw_ckpt_text(doc, "run", "block_shift", &(int){0});
  a->acc_shift = 0.0;
  if (!a->acc_unshifted) {
    NUMS("block_shift", 1, -DBL_MAX, DBL_MAX);
    a->acc_shift = v[0];
  }
  NUMS("energy_initial", 1, -DBL_MAX, DBL_MAX); a->energy_initial = v[0];
  NUMS("max_drift", 1, 0, DBL_MAX); a->max_drift = v[0];
#undef NUMS
  /* (files before 2026-12-05 lack it: the first sweep takes the sizes read) */
  if ((s = lw_ckpt_numbers(doc, "run", "size_peak", a->size_peak, a->n_rep, 0, DBL_MAX, 0, err))) return s;
  if ((s = lw_ckpt_whole(doc, "run", "trace_bytes", &tb, 0, (long)COUNT_MAX, 0, err))) return s;
  *trace_bytes = tb;
  /* the marks of the last trace row, which every file since the first
  ** release has for the moves it counts: optional only for a kind newer
  ** than the file, which then has no [chain] moves.<kind> either.  One
  ** taken out began the counts at 0, and the first row after the resume
  ** read the run's acceptance since its start. */
  for (int m = 0; m < a->chain->n_moves; m++) {
    char key[96];
    snprintf(key, sizeof key, "moves.%s", t->move_names[m]);
    const int counted = lw_ckpt_text(doc, "chain", key, NULL) != NULL;
    snprintf(key, sizeof key, "trace_mark.%s", t->move_names[m]);
    u[0] = u[1] = u[2] = 0;
    if ((s = lw_ckpt_counts(doc, "run", key, u, 3, counted, err))) return s;
    const lw_move_stats *st = &a->chain->stats[m];
    if (u[0] > st->proposed || u[1] > st->accepted || u[2] > st->nan)
      return lw_error_set(err, LW_EINPUT, "%s: [run] %s: beyond the chain's counts (moves.%s)", path, key,
                          t->move_names[m]);
    a->trace_mark[m] = (lw_move_stats){.proposed = u[0], .accepted = u[1], .nan = u[2]};
  }
  if (a->pt && (s = get_tempering(doc, a, err))) return s;
  if (a->dyn && (s = get_dynamics(doc, a->dyn, err))) return s;
  return lw_ckpt_unread(doc, err);
}

/* ---- format 1 ----------------------------------------------------------------- */

typedef struct {
  lw_ckpt *doc;
  const char *path;
  lw_error *err;
  lw_status s;
} upgrade;

/* Splits value into exactly n blank-separated words (malloc'ed); 0 and the
** error set otherwise. */
static int words(upgrade *u, const char *key, int line, const char *value, int n, char **w)
{
  int k = 0;
  for (const char *c = value + strspn(value, " \t"); *c; c += strspn(c, " \t")) {
    size_t len = strcspn(c, " \t");
    if (k == n || !(w[k] = strndup(c, len))) {
      for (int i = 0; i < k; i++) free(w[i]);
      if (k < n) u->s = lw_error_set(u->err, LW_ENOMEM, "%s: out of memory", u->path);
      k = -1;
      break;
    }
    k++;
    c += len;
  }
  if (k == n) return 1;
  if (k > 0)
    for (int i = 0; i < k; i++) free(w[i]);
  if (!u->s)
    u->s = lw_error_set(u->err, LW_EINPUT, "%s:%d: %s: expected %d values, got '%.60s'", u->path, line, key, n, value);
  return 0;
}

static void add(upgrade *u, const char *sec, const char *key, const char *value, int line)
{
  if (!u->s && lw_ckpt_add(u->doc, sec, key, value, line)) u->s = lw_error_set(u->err, LW_ENOMEM, "%s: out of memory", u->path);
}

/* key = the words at stride positions: word i * stride + j for j < per. */
static void add_grouped(upgrade *u, const char *sec, const char *prefix, char **w, int groups, int per,
                        const char *const *names, int line)
{
  for (int g = 0; g < groups; g++) {
    char key[64], val[256] = "";
    snprintf(key, sizeof key, "%s.%s", prefix, names[g]);
    for (int j = 0; j < per; j++) {
      size_t len = strlen(val);
      snprintf(val + len, sizeof val - len, "%s%.60s", j ? " " : "", w[g * per + j]);
    }
    add(u, sec, key, val, line);
  }
}

/* One [v1] line of a chain (prefix "" or "rungK_" stripped) into section sec. */
static int upgrade_chain_key(upgrade *u, const char *sec, const char *key, const char *value, int line,
                             const char *irregular)
{
  char *w[3 * LW_MOVE_KINDS + 4];
  if (!strcmp(key, "rng")) add(u, sec, "rng", value, line);
  else if (!strcmp(key, "steps")) {
    if (!words(u, key, line, value, LW_MOVE_KINDS, w)) return 1;
    add_grouped(u, sec, "step", w, LW_MOVE_KINDS, 1, lw_move_names, line);
    for (int i = 0; i < LW_MOVE_KINDS; i++) free(w[i]);
  } else if (!strcmp(key, "tune_window")) {
    if (!words(u, key, line, value, 2 * LW_MOVE_KINDS, w)) return 1;
    add_grouped(u, sec, "window", w, LW_MOVE_KINDS, 2, lw_move_names, line);
    for (int i = 0; i < 2 * LW_MOVE_KINDS; i++) free(w[i]);
  } else if (!strcmp(key, "moves")) {
    char *irr[LW_MOVE_KINDS];
    if (!words(u, key, line, value, 3 * LW_MOVE_KINDS, w)) return 1;
    int have_irr = irregular && words(u, "moves_irregular", line, irregular, LW_MOVE_KINDS, irr);
    for (int m = 0; m < LW_MOVE_KINDS && !u->s; m++) {
      char k2[64], val[256];
      snprintf(k2, sizeof k2, "moves.%s", lw_move_names[m]);
      snprintf(val, sizeof val, "%.60s %.60s %.60s %.60s", w[3 * m], w[3 * m + 1], w[3 * m + 2],
               have_irr ? irr[m] : "0");
      add(u, sec, k2, val, line);
    }
    for (int i = 0; i < 3 * LW_MOVE_KINDS; i++) free(w[i]);
    for (int i = 0; have_irr && i < LW_MOVE_KINDS; i++) free(irr[i]);
  } else if (!strcmp(key, "moves_irregular")) {
    /* folded into moves */
  } else return 0;
  return 1;
}

static void upgrade_energy(upgrade *u, const char *sec, const char *value, int line)
{
  /* Format 1 knew the terms up to parametrisation; states written before
  ** that term hold one number fewer: it was off in them.  Later terms are
  ** missing, which reads as off. */
  enum { V1_TERMS = LW_TERM_PARAM + 1 };
  char *w[V1_TERMS];
  int n = V1_TERMS;
  double tmp[V1_TERMS + 1];
  if (lw_number_list(value, 0, tmp, V1_TERMS + 1) == V1_TERMS - 1) n = V1_TERMS - 1;
  if (!words(u, "energy", line, value, n, w)) return;
  const char *names[V1_TERMS];
  for (int t = 0; t < V1_TERMS; t++) names[t] = lw_term_names[t];
  add_grouped(u, sec, "energy", w, n, 1, names, line);
  for (int i = 0; i < n; i++) free(w[i]);
}

lw_status lw_checkpoint_upgrade_v1(lw_ckpt *doc, lw_ckpt *const *replicas, int n_rep, lw_error *err)
{
  upgrade u = {doc, lw_ckpt_path(doc), err, LW_OK};
  static const char *const trace_names[] = {"point", "vector", "translate", "rotate"};
  _Static_assert(LW_MOVE_KINDS == 4, "format 1 knew four move kinds");
  size_t pos = 0;
  const char *key, *value;
  int line;
  /* moves_irregular folds into moves: find it (and each rung's) first */
  while (!u.s && lw_ckpt_next(doc, "v1", &pos, &key, &value, &line)) {
    char sec[32], *w[3 * LW_MOVE_KINDS];
    int rung = 0;
    const char *k = key;
    if (!strncmp(key, "rung", 4) && strchr(key, '_')) {
      char *end;
      long r = strtol(key + 4, &end, 10);
      if (end == key + 4 || *end != '_' || r < 1 || r >= n_rep) {
        u.s = lw_error_set(err, LW_EINPUT, "%s:%d: %s: a rung this run does not have", u.path, line, key);
        break;
      }
      rung = (int)r;
      k = end + 1;
    }
    rung_section(sec, sizeof sec, "chain", rung);
    char irr_key[64];
    snprintf(irr_key, sizeof irr_key, "%.*smoves_irregular", (int)(k - key), key);
    size_t p2 = 0;
    const char *k2, *v2, *irregular = NULL;
    while (lw_ckpt_next(doc, "v1", &p2, &k2, &v2, NULL))
      if (!strcmp(k2, irr_key)) irregular = v2;
    if (upgrade_chain_key(&u, sec, k, value, line, irregular)) continue;
    if (rung) {
      u.s = lw_error_set(err, LW_EINPUT, "%s:%d: %s: not a run-data line of format 1", u.path, line, key);
    } else if (!strcmp(key, "energy")) {
      upgrade_energy(&u, "chain", value, line);
    } else if (!strcmp(key, "trace_mark")) {
      if (words(&u, key, line, value, 3 * LW_MOVE_KINDS, w)) {
        add_grouped(&u, "run", "trace_mark", w, LW_MOVE_KINDS, 3, trace_names, line);
        for (int i = 0; i < 3 * LW_MOVE_KINDS; i++) free(w[i]);
      }
    } else if (!strcmp(key, "temperature") || !strcmp(key, "block") || !strcmp(key, "t_prev") ||
               !strcmp(key, "prev_stats") || !strcmp(key, "block_energy") || !strcmp(key, "energy_initial") ||
               !strcmp(key, "max_drift")) {
      add(&u, "run", key, value, line);
    } else if (!strcmp(key, "pt_trips_steps")) {
      if (words(&u, key, line, value, 2, w)) {
        add(&u, "tempering", "round_trips", w[0], line);
        add(&u, "tempering", "steps", w[1], line);
        free(w[0]);
        free(w[1]);
      }
    } else if (!strncmp(key, "pt_", 3) && (!strcmp(key + 3, "rng") || !strcmp(key + 3, "ladder") ||
                                          !strcmp(key + 3, "at_label") || !strcmp(key + 3, "swaps") ||
                                          !strcmp(key + 3, "window") || !strcmp(key + 3, "trace_mark"))) {
      add(&u, "tempering", key + 3, value, line);
    } else {
      u.s = lw_error_set(err, LW_EINPUT, "%s:%d: %s: not a run-data line of format 1", u.path, line, key);
    }
  }
  for (int k = 1; k < n_rep && !u.s; k++) {
    char sec[32];
    rung_section(sec, sizeof sec, "chain", k);
    upgrade ur = {replicas[k], lw_ckpt_path(replicas[k]), err, LW_OK};
    pos = 0;
    while (!ur.s && lw_ckpt_next(replicas[k], "v1", &pos, &key, &value, &line)) {
      if (strcmp(key, "energy")) {
        ur.s = lw_error_set(err, LW_EINPUT, "%s:%d: %s: not a line of a format-1 replica file", ur.path, line, key);
        break;
      }
      /* the replica's running totals belong to its rung's chain in doc */
      upgrade ud = {doc, ur.path, err, LW_OK};
      upgrade_energy(&ud, sec, value, line);
      ur.s = ud.s;
    }
    u.s = ur.s;
  }
  return u.s;
}
