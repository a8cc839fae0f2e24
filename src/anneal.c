#define _XOPEN_SOURCE 700 /* realpath */
/*
** anneal.c -- a whole annealing run (anneal.h): setup, temperature steps,
** tuning phases, drift checks, checkpoints, trace and summary.
*/
#include "linewise/anneal.h"

#include <errno.h>
#include <gsl/gsl_math.h>
#include <stdarg.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "linewise/init.h"
#include "linewise/json.h"
#include "linewise/output.h"
#include "linewise/state.h"

static double now_seconds(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double lw_anneal_seconds(const lw_anneal *a) { return a->wall_before + now_seconds() - a->wall_start; }

double lw_anneal_temperature(const lw_anneal *a) { return a->chain ? a->chain->temperature : 0.0; }

double lw_anneal_acceptance(const lw_anneal *a)
{
  unsigned long p = 0, acc = 0;
  for (int k = 0; k < a->chain->n_moves; k++) {
    p += a->chain->stats[k].proposed;
    acc += a->chain->stats[k].accepted;
  }
  return p ? (double)acc / (double)p : 0.0;
}

/* Temperature step of sweep s: the sweeps are shared out evenly; past the
** end the last step holds. */
static long block_of(const lw_anneal *a, long s)
{
  long S = a->params.sweeps, B = a->params.steps;
  if (S <= 0 || s >= S) return B - 1;
  return (long)((long long)s * B / S);
}

static long block_start(const lw_anneal *a, long b)
{
  long long S = a->params.sweeps, B = a->params.steps;
  return (long)((b * S + B - 1) / B);
}

static void dir_file(char *buf, size_t n, const lw_anneal *a, const char *name)
{
  lw_path_join(buf, n, a->dir, name);
}

/* mkdir -p */
static lw_status make_dir(const char *dir, lw_error *err)
{
  char buf[LW_PATH_MAX];
  snprintf(buf, sizeof buf, "%s", dir);
  for (char *c = buf + 1;; c++) {
    if (*c == '/' || *c == '\0') {
      char save = *c;
      *c = '\0';
      if (mkdir(buf, 0777) && errno != EEXIST)
        return lw_error_set(err, LW_EIO, "%s: cannot create directory: %s", buf, strerror(errno));
      *c = save;
      if (!save) break;
    }
  }
  return LW_OK;
}

/* Schedule and its table (relative to the scene file). */
static lw_status setup_schedule(lw_anneal *a, lw_error *err)
{
  const lw_params *p = &a->params;
  const lw_param_def *d = lw_params_find("anneal", "schedule");
  char where[LW_PATH_MAX + 32];
  lw_params_origin(p, d, where, sizeof where);
  a->sched_type = lw_schedule_find(p->schedule);
  if (!a->sched_type)
    return lw_error_set(err, LW_EINPUT, "%s: key 'anneal.schedule': expected one of %s, got '%s'", where,
                        lw_schedule_names(), p->schedule);
  a->sched.t_start = p->t_start;
  a->sched.t_end = p->t_end;
  a->sched.blocks = p->steps;
  a->sched.lambda = p->lambda;
  if (a->sched_type->needs & LW_SCHEDULE_USES_TABLE) {
    if (!p->table[0])
      return lw_error_set(err, LW_EINPUT, "%s: key 'anneal.schedule': 'table' needs anneal.table (a file)", where);
    lw_status s = lw_schedule_read_table(&a->sched, p->table, err);
    if (s) return s;
  }
  lw_error e2;
  if (lw_schedule_check(a->sched_type, &a->sched, &e2))
    return lw_error_set(err, LW_EINPUT, "%s: anneal.schedule = %s: %s", where, p->schedule, e2.msg);
  return LW_OK;
}

/* Paths in the scene are relative to the scene file; the resolved scene.ini
** lives in the run directory, so they are made absolute first. */
static void absolute_path(char *path, const char *scene_file)
{
  if (!path[0] || path[0] == '/') return;
  char dir[LW_PATH_MAX], joined[2 * LW_PATH_MAX + 2], real[4096];
  lw_path_dir(dir, sizeof dir, scene_file);
  lw_path_join(joined, sizeof joined, dir, path);
  if (realpath(joined, real) && strlen(real) < LW_PATH_MAX) strcpy(path, real);
  else if (strlen(joined) < LW_PATH_MAX) strcpy(path, joined);
}

/* The numbers of an explicit ladder (at most max are stored); returns how
** many there are, or -1 if something else is in the text. */
static int parse_ladder(const char *text, double *out, int max)
{
  int n = 0;
  for (const char *c = text;;) {
    while (*c == ' ' || *c == '\t' || *c == ',') c++;
    if (!*c) return n;
    char *end;
    double v = strtod(c, &end);
    if (end == c) return -1;
    if (n < max) out[n] = v;
    n++;
    c = end;
  }
}

/* Replicas of the run (the explicit ladder's length, or [tempering]
** replicas) and the base ladder; messages name the key's line. */
static lw_status setup_ladder(lw_anneal *a, double *ladder, lw_error *err)
{
  const lw_params *p = &a->params;
  char where[LW_PATH_MAX + 32];
  a->n_rep = p->replicas;
  if (p->ladder[0]) {
    lw_params_origin(p, lw_params_find("tempering", "ladder"), where, sizeof where);
    int n = parse_ladder(p->ladder, ladder, LW_TEMPERING_MAX);
    if (n < 2 || n > LW_TEMPERING_MAX)
      return lw_error_set(err, LW_EINPUT, "%s: key 'tempering.ladder': expected 2 to %d temperatures, got '%s'",
                          where, LW_TEMPERING_MAX, p->ladder);
    if (p->replicas != 1 && p->replicas != n)
      return lw_error_set(err, LW_EINPUT, "%s: key 'tempering.ladder': %d temperatures for %d replicas", where, n,
                          p->replicas);
    for (int k = 0; k < n; k++)
      if (!(ladder[k] > 0.0) || !isfinite(ladder[k]) || (k > 0 && !(ladder[k] > ladder[k - 1])))
        return lw_error_set(err, LW_EINPUT, "%s: key 'tempering.ladder': expected increasing positive "
                            "temperatures, got '%s'", where, p->ladder);
    a->n_rep = n;
  } else if (a->n_rep > 1) {
    lw_params_origin(p, lw_params_find("tempering", "t_max"), where, sizeof where);
    if (!(p->t_max > p->t_min))
      return lw_error_set(err, LW_EINPUT, "%s: key 'tempering.t_max': expected a value above t_min = %g, got %g",
                          where, p->t_min, p->t_max);
    lw_tempering_geometric(ladder, a->n_rep, p->t_min, p->t_max);
  }
  lw_params_origin(p, lw_params_find("anneal", "t_start"), where, sizeof where);
  if (a->n_rep > 1 && !(p->t_start > 0.0))
    return lw_error_set(err, LW_EINPUT, "%s: key 'anneal.t_start': parallel tempering scales the ladder by "
                        "T(step) / t_start, so t_start must be > 0", where);
  return LW_OK;
}

/* The system's row and its set-up of the scene. */
static lw_status setup_system(lw_anneal *a, lw_error *err)
{
  if (!(a->sys_type = lw_system_of(&a->params, err))) return err->code;
  a->setup = a->sys_type->setup_new(&a->params, err);
  return a->setup ? LW_OK : err->code;
}

/* Chain of rung k: rung 0 draws from stream 1 (as a run without tempering
** does), the master exchange stream is 2, rung k >= 1 is stream 2 + k. */
static unsigned long rung_stream(const lw_anneal *a, int k)
{
  return lw_stream_seed(a->seed, k == 0 ? 1 : 2 + (unsigned long)k);
}

/* Systems for the n_rep states[] (ownership passes, also on failure),
** chains for the rungs, the exchange machinery on the base ladder. */
static lw_status build(lw_anneal *a, void **states, const double *ladder, lw_error *err)
{
  const lw_params *p = &a->params;
  const lw_system_type *t = a->sys_type;
  int n = a->n_rep;
  a->systems = calloc((size_t)n, sizeof *a->systems);
  a->chains = calloc((size_t)n, sizeof *a->chains);
  if (!a->systems || !a->chains) {
    for (int r = 0; r < n; r++) t->state_free(states[r]);
    return lw_error_set(err, LW_ENOMEM, "out of memory for %d replicas", n);
  }
  lw_status s = LW_OK;
  for (int r = 0; r < n; r++) {
    if (!s) {
      a->systems[r] = lw_system_wrap(t, states[r], err);
      if (!a->systems[r]) s = err->code;
    } else {
      t->state_free(states[r]);
    }
  }
  if (s) return s;
  double weight[LW_MOVES_MAX], step[LW_MOVES_MAX], target[LW_MOVES_MAX];
  t->moves(p, weight, step, target);
  for (int k = 0; k < n; k++) {
    a->chains[k] = lw_chain_new(a->systems[k], weight, step, target, rung_stream(a, k), err);
    if (!a->chains[k]) return err->code;
  }
  a->chain = a->chains[0];
  a->sys = a->systems[0];
  if (n > 1) {
    a->pt = lw_tempering_new(n, ladder, lw_stream_seed(a->seed, 2), err);
    if (!a->pt) return err->code;
  }
  return LW_OK;
}

/* Rung temperatures from the schedule's: the ladder keeps its ratios and
** follows the schedule (a constant schedule samples at the ladder itself). */
static void set_temperatures(lw_anneal *a)
{
  if (!a->pt) {
    a->chain->temperature = a->t_sched;
    return;
  }
  double f = a->t_sched / a->params.t_start;
  for (int k = 0; k < a->n_rep; k++) a->chains[k]->temperature = a->pt->ladder[k] * f;
}

static lw_status open_trace(lw_anneal *a, int fresh, lw_error *err)
{
  char path[LW_PATH_MAX + 32];
  dir_file(path, sizeof path, a, "trace.csv");
  a->trace = fopen(path, fresh ? "w" : "a");
  if (!a->trace) return lw_error_set(err, LW_EIO, "%s: cannot write: %s", path, strerror(errno));
  if (fresh) {
    const lw_system_type *t = a->sys_type;
    fprintf(a->trace, "sweep,temperature");
    for (int k = 0; k < t->n_terms; k++)
      if (t->term_on(a->setup, k)) fprintf(a->trace, ",%s", t->term_names[k]);
    fprintf(a->trace, ",total");
    for (int k = 0; k < t->n_moves; k++) fprintf(a->trace, ",acc_%s", t->move_names[k]);
    for (int k = 0; a->pt && k < a->n_rep; k++) fprintf(a->trace, ",replica%d_temperature,replica%d_energy", k, k);
    for (int k = 0; a->pt && k + 1 < a->n_rep; k++) fprintf(a->trace, ",swap%d", k);
    fprintf(a->trace, "\n");
  }
  return LW_OK;
}

lw_status lw_anneal_start(lw_anneal *a, const lw_params *p, const char *dir, lw_error *err)
{
  memset(a, 0, sizeof *a);
  a->wall_start = now_seconds();
  a->params = *p;
  absolute_path(a->params.from, p->file);
  absolute_path(a->params.table, p->file);
  absolute_path(a->params.image, p->file);
  absolute_path(a->params.mask_image, p->file);
  snprintf(a->dir, sizeof a->dir, "%s", dir);
  a->seed = (unsigned long)p->seed;
  a->block = -1;
  lw_status s;
  double ladder[LW_TEMPERING_MAX];
  if ((s = lw_params_resolve(&a->params, err)) || (s = setup_ladder(a, ladder, err)) ||
      (s = setup_schedule(a, err)) ||
      (s = setup_system(a, err)))
    return s;
  const lw_system_type *t = a->sys_type;
  void *all[LW_TEMPERING_MAX] = {t->state_new(a->setup, &a->params, lw_stream_seed(a->seed, 0), err)};
  if (!all[0]) return err->code;
  /* every replica starts from the same state; their streams part them */
  for (int r = 1; r < a->n_rep; r++)
    if (!(all[r] = t->state_copy(all[0], err))) {
      for (int q = 0; q < r; q++) t->state_free(all[q]);
      return err->code;
    }
  if ((s = build(a, all, ladder, err))) return s;
  a->energy_initial = lw_system_total(a->sys);
  a->end_sweep = p->sweeps;
  /* Everything above only read input: the directory appears once the run
  ** is known to be valid. */
  if ((s = make_dir(dir, err))) return s;
  char path[LW_PATH_MAX + 32], tmp[LW_PATH_MAX + 64];
  dir_file(path, sizeof path, a, "scene.ini");
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) return err->code;
  fprintf(f, "; resolved parameters of this run (linewise)\n");
  lw_params_write(&a->params, f);
  if ((s = lw_output_commit(f, tmp, path, err))) return s;
  if ((s = open_trace(a, 1, err))) return s;
  if ((s = a->sys_type->draw(a->sys->state, &a->params, a->dir, LW_DRAW_START, err))) return s;
  return lw_anneal_checkpoint(a, err);
}

/* ---- checkpoints ---------------------------------------------------- */

static char *fmt(const char *f, ...) __attribute__((format(printf, 1, 2)));
static char *fmt(const char *f, ...)
{
  static char buf[1024];
  va_list ap;
  va_start(ap, f);
  vsnprintf(buf, sizeof buf, f, ap);
  va_end(ap);
  return buf;
}

/* Appends "%lu"/"%.17g" lists to a buffer. */
static int put_ulongs(char *buf, size_t cap, const unsigned long *v, int n)
{
  int k = 0;
  for (int i = 0; i < n; i++) k += snprintf(buf + k, cap - (size_t)k, "%s%lu", i ? " " : "", v[i]);
  return k;
}

static int put_doubles(char *buf, size_t cap, const double *v, int n)
{
  int k = 0;
  for (int i = 0; i < n; i++) k += snprintf(buf + k, cap - (size_t)k, "%s%.17g", i ? " " : "", v[i]);
  return k;
}

static void key_of(char *key, size_t n, const char *prefix, const char *name)
{
  snprintf(key, n, "%s%s", prefix, name);
}

/* What steers one rung's chain: its stream, steps, tuning window, counts. */
static lw_status add_chain(lw_state *st, const char *prefix, const lw_chain *c)
{
  char key[64], buf[1024];
  unsigned long v[3 * LW_MOVES_MAX];
  char *hex = lw_rng_save(c->rng);
  if (!hex) return LW_ENOMEM;
  key_of(key, sizeof key, prefix, "rng");
  int bad = lw_state_add(st, key, hex);
  free(hex);
  put_doubles(buf, sizeof buf, c->step, c->n_moves);
  key_of(key, sizeof key, prefix, "steps");
  bad = bad || lw_state_add(st, key, buf);
  for (int k = 0; k < c->n_moves; k++) {
    v[2 * k] = c->win_prop[k];
    v[2 * k + 1] = c->win_acc[k];
  }
  put_ulongs(buf, sizeof buf, v, 2 * c->n_moves);
  key_of(key, sizeof key, prefix, "tune_window");
  bad = bad || lw_state_add(st, key, buf);
  for (int k = 0; k < c->n_moves; k++) {
    v[3 * k] = c->stats[k].proposed;
    v[3 * k + 1] = c->stats[k].accepted;
    v[3 * k + 2] = c->stats[k].nan;
  }
  put_ulongs(buf, sizeof buf, v, 3 * c->n_moves);
  key_of(key, sizeof key, prefix, "moves");
  bad = bad || lw_state_add(st, key, buf);
  for (int k = 0; k < c->n_moves; k++) v[k] = c->stats[k].irregular;
  put_ulongs(buf, sizeof buf, v, c->n_moves);
  key_of(key, sizeof key, prefix, "moves_irregular");
  bad = bad || lw_state_add(st, key, buf);
  return bad ? LW_ENOMEM : LW_OK;
}

/* The exchange machinery: master stream, ladder, who is where, counts. */
static lw_status add_tempering(lw_state *st, const lw_anneal *a)
{
  const lw_tempering *pt = a->pt;
  int n = pt->n, bad = 0;
  char buf[8192];
  unsigned long v[2 * LW_TEMPERING_MAX];
  char *hex = lw_rng_save(pt->rng);
  if (!hex) return LW_ENOMEM;
  bad = lw_state_add(st, "pt_rng", hex);
  free(hex);
  put_doubles(buf, sizeof buf, pt->ladder, n);
  bad = bad || lw_state_add(st, "pt_ladder", buf);
  for (int k = 0; k < n; k++) {
    v[2 * k] = (unsigned long)pt->at[k];
    v[2 * k + 1] = (unsigned long)(pt->label[k] + 1);
  }
  put_ulongs(buf, sizeof buf, v, 2 * n);
  bad = bad || lw_state_add(st, "pt_at_label", buf);
  for (int k = 0; k + 1 < n; k++) {
    v[2 * k] = pt->tried[k];
    v[2 * k + 1] = pt->accepted[k];
  }
  put_ulongs(buf, sizeof buf, v, 2 * (n - 1));
  bad = bad || lw_state_add(st, "pt_swaps", buf);
  for (int k = 0; k + 1 < n; k++) {
    v[2 * k] = pt->win_tried[k];
    v[2 * k + 1] = pt->win_accepted[k];
  }
  put_ulongs(buf, sizeof buf, v, 2 * (n - 1));
  bad = bad || lw_state_add(st, "pt_window", buf);
  put_ulongs(buf, sizeof buf, a->swap_mark, 2 * (n - 1));
  bad = bad || lw_state_add(st, "pt_trace_mark", buf);
  v[0] = pt->round_trips;
  v[1] = pt->steps;
  put_ulongs(buf, sizeof buf, v, 2);
  bad = bad || lw_state_add(st, "pt_trips_steps", buf);
  for (int k = 1; !bad && k < n; k++) {
    char prefix[32];
    snprintf(prefix, sizeof prefix, "rung%d_", k);
    bad = add_chain(st, prefix, a->chains[k]) != LW_OK;
  }
  return bad ? LW_ENOMEM : LW_OK;
}

/* replica-K.lw: the state at rung K >= 1 and its running energies. */
static lw_status write_replica(const lw_anneal *a, int k, lw_error *err)
{
  lw_state st = {.scene = "scene.ini", .seed = a->seed, .sweep = a->sweep};
  char name[64], path[LW_PATH_MAX + 64];
  snprintf(name, sizeof name, "replica-%d.lw", k);
  dir_file(path, sizeof path, a, name);
  const lw_system *sys = a->chains[k]->sys;
  lw_status s = sys->type->save(sys->state, &st, err);
  if (!s) s = lw_state_write(&st, path, err);
  lw_state_clear(&st);
  return s;
}

lw_status lw_anneal_checkpoint(lw_anneal *a, lw_error *err)
{
  lw_chain *c = a->chain;
  lw_state st = {.scene = "scene.ini", .seed = a->seed, .sweep = a->sweep};
  lw_status s = LW_OK;
  char buf[1024];
  unsigned long v[3 * LW_MOVES_MAX];
  /* The replicas first: state.lw, written last, is what resume starts from,
  ** and its sweep must match theirs. */
  for (int k = 1; k < a->n_rep && !s; k++) s = write_replica(a, k, err);
  if (s) return s;
#define ADD(key, value) do { if (!s && lw_state_add(&st, key, value)) s = LW_ENOMEM; } while (0)
  s = add_chain(&st, "", c);
  ADD("temperature", fmt("%.17g", a->t_sched));
  ADD("block", fmt("%ld", a->block));
  ADD("t_prev", fmt("%.17g", a->t_prev));
  ADD("prev_stats", fmt("%.17g %.17g %ld", a->prev.mean, a->prev.sd, a->prev.samples));
  ADD("block_energy", fmt("%.17g %.17g %.17g", a->acc_n, a->acc_sum, a->acc_sumsq));
  for (int k = 0; k < c->n_moves; k++) {
    v[3 * k] = a->trace_mark[k].proposed;
    v[3 * k + 1] = a->trace_mark[k].accepted;
    v[3 * k + 2] = a->trace_mark[k].nan;
  }
  put_ulongs(buf, sizeof buf, v, 3 * c->n_moves);
  ADD("trace_mark", buf);
  if (!s && (s = a->sys_type->save(a->sys->state, &st, err))) {
    lw_state_clear(&st);
    return s;
  }
  ADD("energy_initial", fmt("%.17g", a->energy_initial));
  ADD("max_drift", fmt("%.17g", a->max_drift));
  if (!s && a->pt) s = add_tempering(&st, a);
#undef ADD
  char path[LW_PATH_MAX + 32];
  dir_file(path, sizeof path, a, "state.lw");
  if (!s) s = lw_state_write(&st, path, err);
  else s = lw_error_set(err, LW_ENOMEM, "out of memory writing a checkpoint");
  if (!s && a->trace && fflush(a->trace)) s = lw_error_set(err, LW_EIO, "%s/trace.csv: write failed", a->dir);
  /* Wall time differs from run to run, so it lives beside the state, which
  ** must be byte-identical for the same sweeps. */
  if (!s) {
    char tmp[LW_PATH_MAX + 64];
    dir_file(path, sizeof path, a, "timing.txt");
    FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
    if (!f) s = err->code;
    else {
      fprintf(f, "wall_seconds %.6f\n", lw_anneal_seconds(a));
      s = lw_output_commit(f, tmp, path, err);
    }
  }
  lw_state_clear(&st);
  return s;
}

/* Parses exactly n numbers of a run-data line. */
static lw_status read_numbers(const lw_state *st, const char *path, const char *key, double *out, int n,
                              lw_error *err)
{
  const lw_state_extra *e = lw_state_get(st, key);
  if (!e) return lw_error_set(err, LW_EINPUT, "%s: %s: missing (not a checkpoint of a run?)", path, key);
  const char *c = e->value;
  for (int i = 0; i < n; i++) {
    char *end;
    out[i] = strtod(c, &end);
    if (end == c || isnan(out[i]))
      return lw_error_set(err, LW_EINPUT, "%s:%d: %s: expected %d numbers, got '%s'", path, e->line, key, n, e->value);
    c = end;
  }
  while (*c == ' ') c++;
  if (*c) return lw_error_set(err, LW_EINPUT, "%s:%d: %s: expected %d numbers, got '%s'", path, e->line, key, n, e->value);
  return LW_OK;
}

static lw_status truncate_trace(lw_anneal *a, lw_error *err)
{
  char path[LW_PATH_MAX + 32], tmp[LW_PATH_MAX + 64];
  dir_file(path, sizeof path, a, "trace.csv");
  FILE *in = fopen(path, "r");
  if (!in) return open_trace(a, 1, err);
  FILE *out = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!out) {
    fclose(in);
    return err->code;
  }
  char *line = NULL;
  size_t cap = 0;
  int first = 1;
  /* rows written after the checkpoint belong to sweeps that will run again */
  while (getline(&line, &cap, in) >= 0) {
    if (first || strtol(line, NULL, 10) <= a->sweep) fputs(line, out);
    first = 0;
  }
  free(line);
  fclose(in);
  lw_status s = lw_output_commit(out, tmp, path, err);
  return s ? s : open_trace(a, 0, err);
}

static lw_status read_chain(const lw_state *st, const char *path, const char *prefix, lw_chain *c,
                            lw_error *err)
{
  char key[64];
  double v[3 * LW_MOVES_MAX];
  lw_status s;
  key_of(key, sizeof key, prefix, "rng");
  const lw_state_extra *rng = lw_state_get(st, key);
  if (!rng || !lw_rng_load(c->rng, rng->value))
    return lw_error_set(err, LW_EINPUT, "%s:%d: %s: expected the generator state in hex", path, rng ? rng->line : 0,
                        key);
  key_of(key, sizeof key, prefix, "steps");
  if ((s = read_numbers(st, path, key, v, c->n_moves, err))) return s;
  for (int k = 0; k < c->n_moves; k++) c->step[k] = v[k];
  key_of(key, sizeof key, prefix, "tune_window");
  if ((s = read_numbers(st, path, key, v, 2 * c->n_moves, err))) return s;
  for (int k = 0; k < c->n_moves; k++) {
    c->win_prop[k] = (unsigned long)v[2 * k];
    c->win_acc[k] = (unsigned long)v[2 * k + 1];
  }
  key_of(key, sizeof key, prefix, "moves");
  if ((s = read_numbers(st, path, key, v, 3 * c->n_moves, err))) return s;
  for (int k = 0; k < c->n_moves; k++)
    c->stats[k] = (lw_move_stats){.proposed = (unsigned long)v[3 * k], .accepted = (unsigned long)v[3 * k + 1],
                                  .nan = (unsigned long)v[3 * k + 2]};
  /* A separate line, so states written before it was counted still resume
  ** (with 0 rejections for irregularity so far). */
  key_of(key, sizeof key, prefix, "moves_irregular");
  if (lw_state_get(st, key)) {
    if ((s = read_numbers(st, path, key, v, c->n_moves, err))) return s;
    for (int k = 0; k < c->n_moves; k++) c->stats[k].irregular = (unsigned long)v[k];
  }
  return LW_OK;
}

static lw_status read_tempering(lw_anneal *a, const lw_state *st, const char *path, lw_error *err)
{
  lw_tempering *pt = a->pt;
  int n = pt->n;
  double v[2 * LW_TEMPERING_MAX];
  lw_status s;
  const lw_state_extra *rng = lw_state_get(st, "pt_rng");
  if (!rng || !lw_rng_load(pt->rng, rng->value))
    return lw_error_set(err, LW_EINPUT, "%s:%d: pt_rng: expected the generator state in hex", path,
                        rng ? rng->line : 0);
  if ((s = read_numbers(st, path, "pt_ladder", pt->ladder, n, err))) return s;
  if ((s = read_numbers(st, path, "pt_at_label", v, 2 * n, err))) return s;
  int seen[LW_TEMPERING_MAX] = {0};
  for (int k = 0; k < n; k++) {
    int r = (int)v[2 * k];
    if (r < 0 || r >= n || seen[r] || v[2 * k + 1] < 0 || v[2 * k + 1] > 2)
      return lw_error_set(err, LW_EINPUT, "%s: pt_at_label: expected a permutation of the replicas", path);
    seen[r] = 1;
    pt->at[k] = r;
    pt->label[k] = (int)v[2 * k + 1] - 1;
  }
  if ((s = read_numbers(st, path, "pt_swaps", v, 2 * (n - 1), err))) return s;
  for (int k = 0; k + 1 < n; k++) {
    pt->tried[k] = (unsigned long)v[2 * k];
    pt->accepted[k] = (unsigned long)v[2 * k + 1];
  }
  if ((s = read_numbers(st, path, "pt_window", v, 2 * (n - 1), err))) return s;
  for (int k = 0; k + 1 < n; k++) {
    pt->win_tried[k] = (unsigned long)v[2 * k];
    pt->win_accepted[k] = (unsigned long)v[2 * k + 1];
  }
  if ((s = read_numbers(st, path, "pt_trace_mark", v, 2 * (n - 1), err))) return s;
  for (int k = 0; k < 2 * (n - 1); k++) a->swap_mark[k] = (unsigned long)v[k];
  if ((s = read_numbers(st, path, "pt_trips_steps", v, 2, err))) return s;
  pt->round_trips = (unsigned long)v[0];
  pt->steps = (unsigned long)v[1];
  for (int k = 1; k < n; k++) {
    char prefix[32];
    snprintf(prefix, sizeof prefix, "rung%d_", k);
    if ((s = read_chain(st, path, prefix, a->chains[k], err))) return s;
  }
  /* systems[] is by replica: rung k holds replica at[k] */
  lw_system *by_rung[LW_TEMPERING_MAX];
  for (int k = 0; k < n; k++) by_rung[k] = a->systems[k];
  for (int k = 0; k < n; k++) a->systems[pt->at[k]] = by_rung[k];
  return LW_OK;
}

lw_status lw_anneal_resume(lw_anneal *a, const char *dir, long more, lw_error *err)
{
  memset(a, 0, sizeof *a);
  a->wall_start = now_seconds();
  snprintf(a->dir, sizeof a->dir, "%s", dir);
  char path[LW_PATH_MAX + 32], scene_path[2 * LW_PATH_MAX + 2];
  dir_file(path, sizeof path, a, "state.lw");
  lw_state st, rep[LW_TEMPERING_MAX];
  int n_read = 0;
  lw_status s = lw_state_read(&st, path, err);
  if (s) return s;
  lw_path_join(scene_path, sizeof scene_path, dir, st.scene);
  double ladder[LW_TEMPERING_MAX];
  if ((s = lw_params_read(&a->params, scene_path, err)) || (s = setup_ladder(a, ladder, err)) ||
      (s = setup_schedule(a, err)) || (s = setup_system(a, err))) {
    lw_state_clear(&st);
    return s;
  }
  const lw_system_type *t = a->sys_type;
  void *all[LW_TEMPERING_MAX] = {t->load(a->setup, &st, path, err)};
  if (!all[0]) {
    lw_state_clear(&st);
    return err->code;
  }
  a->seed = st.seed;
  a->sweep = st.sweep;
  for (int k = 1; k < a->n_rep; k++, n_read++) {
    char name[64], rpath[LW_PATH_MAX + 64];
    snprintf(name, sizeof name, "replica-%d.lw", k);
    dir_file(rpath, sizeof rpath, a, name);
    s = lw_state_read(&rep[k], rpath, err);
    if (!s && rep[k].sweep != a->sweep)
      s = lw_error_set(err, LW_EINPUT, "%s: sweep %ld, but state.lw is at sweep %ld (an interrupted checkpoint?)",
                       rpath, rep[k].sweep, a->sweep);
    if (!s && !(all[k] = t->load(a->setup, &rep[k], rpath, err))) s = err->code;
    if (s) {
      lw_state_clear(&rep[k]);
      for (int q = 0; q < k; q++) t->state_free(all[q]);
      goto out;
    }
  }
  if ((s = build(a, all, ladder, err))) goto out;
  dir_file(path, sizeof path, a, "state.lw");
  double v[3 * LW_MOVES_MAX];
  const int n_moves = a->chain->n_moves;
  if ((s = read_chain(&st, path, "", a->chain, err))) goto out;
#define NUMS(key, n) if ((s = read_numbers(&st, path, key, v, n, err))) goto out
  NUMS("temperature", 1); a->t_sched = v[0];
  NUMS("block", 1); a->block = (long)v[0];
  NUMS("t_prev", 1); a->t_prev = v[0];
  NUMS("prev_stats", 3); a->prev = (lw_block_stats){v[0], v[1], (long)v[2]};
  NUMS("block_energy", 3); a->acc_n = v[0]; a->acc_sum = v[1]; a->acc_sumsq = v[2];
  NUMS("trace_mark", 3 * n_moves);
  for (int k = 0; k < n_moves; k++)
    a->trace_mark[k] = (lw_move_stats){.proposed = (unsigned long)v[3 * k], .accepted = (unsigned long)v[3 * k + 1],
                                       .nan = (unsigned long)v[3 * k + 2]};
  NUMS("energy_initial", 1); a->energy_initial = v[0];
  NUMS("max_drift", 1); a->max_drift = v[0];
#undef NUMS
  if (a->pt && (s = read_tempering(a, &st, path, err))) goto out;
  set_temperatures(a);
  dir_file(path, sizeof path, a, "timing.txt");
  FILE *tf = fopen(path, "r");
  if (tf) {
    if (fscanf(tf, "wall_seconds %lf", &a->wall_before) != 1 || !(a->wall_before >= 0)) a->wall_before = 0;
    fclose(tf);
  }
  a->end_sweep = more >= 0 ? a->sweep + more : (a->params.sweeps > a->sweep ? a->params.sweeps : a->sweep);
  for (int k = 0; k < n_moves; k++) a->proposals_before += a->chain->stats[k].proposed;
  s = truncate_trace(a, err);
out:
  for (int k = 1; k <= n_read && k < a->n_rep; k++) lw_state_clear(&rep[k]);
  lw_state_clear(&st);
  return s;
}

/* ---- the loop ------------------------------------------------------- */

static void trace_row(lw_anneal *a)
{
  lw_chain *c = a->chain;
  const lw_system_type *t = a->sys_type;
  double term[LW_SYSTEM_TERMS_MAX];
  t->terms(a->sys->state, term);
  fprintf(a->trace, "%ld,%.10g", a->sweep, c->temperature);
  for (int k = 0; k < t->n_terms; k++)
    if (t->term_on(a->setup, k)) fprintf(a->trace, ",%.10g", term[k]);
  fprintf(a->trace, ",%.10g", lw_system_total(a->sys));
  for (int k = 0; k < c->n_moves; k++) {
    unsigned long p = c->stats[k].proposed - a->trace_mark[k].proposed;
    unsigned long acc = c->stats[k].accepted - a->trace_mark[k].accepted;
    if (p) fprintf(a->trace, ",%.6f", (double)acc / (double)p);
    else fprintf(a->trace, ",");
    a->trace_mark[k] = c->stats[k];
  }
  if (a->pt) {
    for (int k = 0; k < a->n_rep; k++)
      fprintf(a->trace, ",%.10g,%.10g", a->chains[k]->temperature, lw_system_total(a->chains[k]->sys));
    /* swap acceptance since the previous row */
    for (int k = 0; k + 1 < a->n_rep; k++) {
      unsigned long tried = a->pt->tried[k] - a->swap_mark[2 * k];
      unsigned long acc = a->pt->accepted[k] - a->swap_mark[2 * k + 1];
      if (tried) fprintf(a->trace, ",%.6f", (double)acc / (double)tried);
      else fprintf(a->trace, ",");
      a->swap_mark[2 * k] = a->pt->tried[k];
      a->swap_mark[2 * k + 1] = a->pt->accepted[k];
    }
  }
  fprintf(a->trace, "\n");
}

/* ladder.ini: the tuned ladder, ready to paste into a scene or --set. */
static lw_status write_ladder(const lw_anneal *a, lw_error *err)
{
  char path[LW_PATH_MAX + 32], tmp[LW_PATH_MAX + 64];
  dir_file(path, sizeof path, a, "ladder.ini");
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) return err->code;
  fprintf(f, "; ladder tuned toward equal swap acceptance over %d sweeps\n[tempering]\nladder =",
          a->params.ladder_sweeps);
  for (int k = 0; k < a->n_rep; k++) fprintf(f, " %.17g", a->pt->ladder[k]);
  fprintf(f, "\n");
  return lw_output_commit(f, tmp, path, err);
}

/* Exchange step and, during the warm-up, ladder tuning; after the warm-up
** the ladder is frozen and the swap statistics start afresh. */
static lw_status exchange(lw_anneal *a, lw_error *err)
{
  const lw_params *p = &a->params;
  lw_tempering *pt = a->pt;
  int n = a->n_rep, swapped[LW_TEMPERING_MAX];
  double e[LW_TEMPERING_MAX] = {0}, t[LW_TEMPERING_MAX] = {0};
  for (int k = 0; k < n; k++) {
    e[k] = lw_system_total(a->chains[k]->sys);
    t[k] = a->chains[k]->temperature;
  }
  lw_tempering_exchange(pt, e, t, swapped);
  for (int k = 0; k + 1 < n; k++)
    if (swapped[k]) {
      lw_system *sys = a->chains[k]->sys;
      a->chains[k]->sys = a->chains[k + 1]->sys;
      a->chains[k + 1]->sys = sys;
    }
  a->sys = a->chains[0]->sys;
  if (p->tune_ladder == LW_LADDER_EQUAL && a->sweep <= p->ladder_sweeps) {
    /* every pair has had ~20 attempts by then */
    if (pt->steps % 40 == 0) {
      lw_tempering_tune(pt);
      set_temperatures(a);
    }
    if (a->sweep + p->exchange_every > p->ladder_sweeps) {
      lw_tempering_reset_stats(pt);
      memset(a->swap_mark, 0, sizeof a->swap_mark);
      return write_ladder(a, err);
    }
  }
  return LW_OK;
}

lw_status lw_anneal_sweep(lw_anneal *a, lw_error *err)
{
  const lw_params *p = &a->params;
  int n = a->n_rep;
  long b = block_of(a, a->sweep);
  if (b != a->block) {
    if (a->block >= 0) {
      double cnt = a->acc_n, mean = cnt > 0 ? a->acc_sum / cnt : 0.0;
      double var = cnt > 1 ? (a->acc_sumsq - cnt * mean * mean) / (cnt - 1) : 0.0;
      a->prev = (lw_block_stats){mean, var > 0 ? sqrt(var) : 0.0, (long)cnt};
      a->t_prev = a->t_sched;
    }
    a->t_sched = a->sched_type->temperature(&a->sched, b, a->t_prev, a->block >= 0 ? &a->prev : NULL);
    set_temperatures(a);
    a->block = b;
    a->acc_n = a->acc_sum = a->acc_sumsq = 0.0;
    for (int k = 0; k < n; k++) {
      memset(a->chains[k]->win_prop, 0, sizeof a->chains[k]->win_prop);
      memset(a->chains[k]->win_acc, 0, sizeof a->chains[k]->win_acc);
    }
  }
  int tuning = a->sweep - block_start(a, b) < p->tune_sweeps && a->sweep < p->sweeps;
  int failed = 0;
  /* The rungs are independent between exchanges: each touches only its own
  ** chain, stream and system, so the thread count cannot change the result. */
#pragma omp parallel for schedule(static, 1) reduction(| : failed) if (n > 1)
  for (int k = 0; k < n; k++) {
    a->chains[k]->tuning = tuning;
    if (lw_chain_sweep(a->chains[k]) != LW_OK) failed = 1;
  }
  if (failed) return lw_error_set(err, LW_ENOMEM, "out of memory growing a system's caches");
  a->sweep++;
  lw_status s;
  if (a->pt && a->sweep % p->exchange_every == 0 && (s = exchange(a, err))) return s;
  double e = lw_system_total(a->sys);
  if (!tuning && isfinite(e)) {
    a->acc_n += 1.0;
    a->acc_sum += e;
    a->acc_sumsq += e * e;
  }
  if (a->sweep % p->trace_every == 0 || lw_anneal_done(a)) trace_row(a);
  if (a->sweep % p->check_every == 0)
    for (int r = 0; r < n; r++) {
      double drift;
      if (a->sys_type->refresh(a->systems[r]->state, &drift) != LW_OK)
        return lw_error_set(err, LW_ENOMEM, "out of memory");
      if (drift > a->max_drift) a->max_drift = drift;
    }
  /* Frames are extra files: they read the state and change nothing. */
  if (p->frames_every && a->sweep % p->frames_every == 0 &&
      a->sys_type->draw(a->sys->state, p, a->dir, a->sweep, err))
    return err->code;
  if (a->sweep % p->checkpoint_every == 0) return lw_anneal_checkpoint(a, err);
  return LW_OK;
}

static lw_status write_summary(lw_anneal *a, lw_error *err)
{
  char path[LW_PATH_MAX + 32], tmp[LW_PATH_MAX + 64];
  dir_file(path, sizeof path, a, "summary.json");
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) return err->code;
  lw_chain *c = a->chain;
  const lw_system_type *t = a->sys_type;
  unsigned long prop = 0, acc = 0, nan = 0;
  for (int k = 0; k < c->n_moves; k++) {
    prop += c->stats[k].proposed;
    acc += c->stats[k].accepted;
    nan += c->stats[k].nan;
  }
  double wall = lw_anneal_seconds(a);
  lw_json j;
  lw_json_init(&j, f);
  lw_json_begin_object(&j);
  lw_json_key(&j, "seed"); lw_json_int(&j, (long long)a->seed);
  lw_json_key(&j, "sweeps"); lw_json_int(&j, a->sweep);
  lw_json_key(&j, "system"); lw_json_string(&j, t->name);
  t->summary(a->sys->state, &j);
  lw_json_key(&j, "proposals"); lw_json_int(&j, (long long)prop);
  lw_json_key(&j, "accepted"); lw_json_int(&j, (long long)acc);
  lw_json_key(&j, "rejected_nan"); lw_json_int(&j, (long long)nan);
  lw_json_key(&j, "rejected_irregular");
  lw_json_begin_object(&j);
  for (int k = 0; k < c->n_moves; k++) {
    lw_json_key(&j, t->move_names[k]);
    lw_json_int(&j, (long long)c->stats[k].irregular);
  }
  lw_json_end_object(&j);
  lw_json_key(&j, "wall_seconds"); lw_json_number(&j, wall);
  double here = now_seconds() - a->wall_start;
  lw_json_key(&j, "proposals_per_second");
  lw_json_number(&j, here > 0 ? (double)(prop - a->proposals_before) / here : 0.0);
  lw_json_key(&j, "max_relative_drift"); lw_json_number(&j, a->max_drift);
  lw_json_key(&j, "temperature_final"); lw_json_number(&j, c->temperature);
  lw_json_key(&j, "schedule"); lw_json_string(&j, a->sched_type->name);
  lw_json_key(&j, "energy");
  lw_json_begin_object(&j);
  lw_json_key(&j, "total"); lw_json_number(&j, lw_system_total(a->sys));
  double term[LW_SYSTEM_TERMS_MAX];
  t->terms(a->sys->state, term);
  for (int k = 0; k < t->n_terms; k++)
    if (t->term_on(a->setup, k)) {
      lw_json_key(&j, t->term_names[k]);
      lw_json_number(&j, term[k]);
    }
  lw_json_end_object(&j);
  lw_json_key(&j, "energy_initial"); lw_json_number(&j, a->energy_initial);
  lw_json_key(&j, "acceptance");
  lw_json_begin_object(&j);
  for (int k = 0; k < c->n_moves; k++) {
    lw_json_key(&j, t->move_names[k]);
    if (c->stats[k].proposed) lw_json_number(&j, (double)c->stats[k].accepted / (double)c->stats[k].proposed);
    else lw_json_null(&j);
  }
  lw_json_end_object(&j);
  lw_json_key(&j, "proposed");
  lw_json_begin_object(&j);
  for (int k = 0; k < c->n_moves; k++) {
    lw_json_key(&j, t->move_names[k]);
    lw_json_int(&j, (long long)c->stats[k].proposed);
  }
  lw_json_end_object(&j);
  lw_json_key(&j, "steps");
  lw_json_begin_object(&j);
  for (int k = 0; k < c->n_moves; k++) {
    lw_json_key(&j, t->move_names[k]);
    lw_json_number(&j, c->step[k] / t->move_unit[k]);
  }
  lw_json_end_object(&j);
  if (a->pt) {
    const lw_tempering *pt = a->pt;
    lw_json_key(&j, "replicas");
    lw_json_begin_array(&j);
    for (int k = 0; k < a->n_rep; k++) {
      lw_json_begin_object(&j);
      lw_json_key(&j, "temperature"); lw_json_number(&j, a->chains[k]->temperature);
      lw_json_key(&j, "energy"); lw_json_number(&j, lw_system_total(a->chains[k]->sys));
      lw_json_end_object(&j);
    }
    lw_json_end_array(&j);
    lw_json_key(&j, "ladder");
    lw_json_begin_array(&j);
    for (int k = 0; k < a->n_rep; k++) lw_json_number(&j, pt->ladder[k]);
    lw_json_end_array(&j);
    lw_json_key(&j, "swap_acceptance");
    lw_json_begin_array(&j);
    for (int k = 0; k + 1 < a->n_rep; k++) {
      if (pt->tried[k]) lw_json_number(&j, lw_tempering_acceptance(pt, k));
      else lw_json_null(&j);
    }
    lw_json_end_array(&j);
    lw_json_key(&j, "swap_attempts");
    lw_json_begin_array(&j);
    for (int k = 0; k + 1 < a->n_rep; k++) lw_json_int(&j, (long long)pt->tried[k]);
    lw_json_end_array(&j);
    lw_json_key(&j, "round_trips"); lw_json_int(&j, (long long)pt->round_trips);
  }
  lw_json_end_object(&j);
  lw_status s = lw_json_finish(&j, err);
  if (s) {
    lw_output_abort(f, tmp);
    return s;
  }
  return lw_output_commit(f, tmp, path, err);
}

lw_status lw_anneal_finish(lw_anneal *a, lw_error *err)
{
  lw_status s;
  if ((s = lw_anneal_checkpoint(a, err))) return s;
  if ((s = a->sys_type->draw(a->sys->state, &a->params, a->dir, LW_DRAW_FINAL, err))) return s;
  return write_summary(a, err);
}

void lw_anneal_free(lw_anneal *a)
{
  if (a->trace) fclose(a->trace);
  /* the chains first: tempering swaps systems between them */
  for (int k = 0; a->chains && k < a->n_rep; k++) lw_chain_free(a->chains[k]);
  for (int k = 0; a->systems && k < a->n_rep; k++) lw_system_free(a->systems[k]);
  free(a->chains);
  free(a->systems);
  if (a->setup) a->sys_type->setup_free(a->setup);
  lw_tempering_free(a->pt);
  lw_schedule_clear(&a->sched);
  memset(a, 0, sizeof *a);
}
