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

#include "linewise/fieldview.h"
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
  for (int k = 0; k < LW_MOVE_KINDS; k++) {
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

static lw_status build(lw_anneal *a, lw_splines *sp, lw_error *err)
{
  const lw_params *p = &a->params;
  a->model = lw_model_new(&a->scene, sp, err);
  if (!a->model) return err ? err->code : LW_ENOMEM;
  double weight[LW_MOVE_KINDS] = {p->mix_point, p->mix_vector, p->mix_translate, p->mix_rotate};
  double step[LW_MOVE_KINDS] = {p->step_point, p->step_vector, p->step_translate, p->step_rotate * M_PI / 180.0};
  double target[LW_MOVE_KINDS] = {p->target, p->target, p->target_spline, p->target_spline};
  a->chain = lw_chain_new(a->model, weight, step, target, lw_stream_seed(a->seed, 1), err);
  if (!a->chain) return err ? err->code : LW_ENOMEM;
  return LW_OK;
}

static lw_status open_trace(lw_anneal *a, int fresh, lw_error *err)
{
  char path[LW_PATH_MAX + 32];
  dir_file(path, sizeof path, a, "trace.csv");
  a->trace = fopen(path, fresh ? "w" : "a");
  if (!a->trace) return lw_error_set(err, LW_EIO, "%s: cannot write: %s", path, strerror(errno));
  if (fresh) {
    fprintf(a->trace, "sweep,temperature");
    for (int t = 0; t < LW_TERM_COUNT; t++)
      if (a->scene.on[t]) fprintf(a->trace, ",%s", lw_term_types[t].name);
    fprintf(a->trace, ",total");
    for (int k = 0; k < LW_MOVE_KINDS; k++) fprintf(a->trace, ",acc_%s", lw_move_names[k]);
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
  if ((s = setup_schedule(a, err)) || (s = lw_scene_init(&a->scene, &a->params, err))) return s;
  lw_splines *sp;
  if (a->params.from[0]) {
    lw_state st;
    if ((s = lw_state_read(&st, a->params.from, err))) return s;
    sp = st.sp;
    st.sp = NULL;
    lw_state_clear(&st);
  } else {
    size_t n;
    if ((s = lw_init_count(&a->scene, p, &n, err))) return s;
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    if (!r) return lw_error_set(err, LW_ENOMEM, "out of memory");
    gsl_rng_set(r, lw_stream_seed(a->seed, 0));
    sp = lw_init_random(&a->scene, n, (size_t)p->segments, p->segment_length, r, err);
    gsl_rng_free(r);
    if (!sp) return err->code;
  }
  if ((s = build(a, sp, err))) return s;
  a->energy_initial = lw_model_total(a->model);
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
  dir_file(path, sizeof path, a, "field.png");
  if (p->field_preview && (s = lw_fieldview_png(&a->scene, p->png_scale, path, err))) return s;
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

lw_status lw_anneal_checkpoint(lw_anneal *a, lw_error *err)
{
  lw_chain *c = a->chain;
  lw_state st = {.scene = "scene.ini", .seed = a->seed, .sweep = a->sweep, .sp = a->model->sp};
  lw_status s = LW_OK;
  char *hex = lw_chain_rng_save(c);
  char buf[1024];
  int n;
#define ADD(key, value) do { if (!s && lw_state_add(&st, key, value)) s = LW_ENOMEM; } while (0)
  ADD("rng", hex ? hex : "");
  ADD("temperature", fmt("%.17g", c->temperature));
  ADD("block", fmt("%ld", a->block));
  ADD("t_prev", fmt("%.17g", a->t_prev));
  ADD("prev_stats", fmt("%.17g %.17g %ld", a->prev.mean, a->prev.sd, a->prev.samples));
  ADD("block_energy", fmt("%.17g %.17g %.17g", a->acc_n, a->acc_sum, a->acc_sumsq));
  n = 0;
  for (int k = 0; k < LW_MOVE_KINDS; k++) n += snprintf(buf + n, sizeof buf - (size_t)n, "%s%.17g", k ? " " : "", c->step[k]);
  ADD("steps", buf);
  n = 0;
  for (int k = 0; k < LW_MOVE_KINDS; k++)
    n += snprintf(buf + n, sizeof buf - (size_t)n, "%s%lu %lu", k ? " " : "", c->win_prop[k], c->win_acc[k]);
  ADD("tune_window", buf);
  n = 0;
  for (int k = 0; k < LW_MOVE_KINDS; k++)
    n += snprintf(buf + n, sizeof buf - (size_t)n, "%s%lu %lu %lu", k ? " " : "", c->stats[k].proposed,
                  c->stats[k].accepted, c->stats[k].nan);
  ADD("moves", buf);
  n = 0;
  for (int k = 0; k < LW_MOVE_KINDS; k++)
    n += snprintf(buf + n, sizeof buf - (size_t)n, "%s%lu %lu %lu", k ? " " : "", a->trace_mark[k].proposed,
                  a->trace_mark[k].accepted, a->trace_mark[k].nan);
  ADD("trace_mark", buf);
  n = 0;
  for (int t = 0; t < LW_TERM_COUNT; t++) n += snprintf(buf + n, sizeof buf - (size_t)n, "%s%.17g", t ? " " : "", a->model->term[t]);
  ADD("energy", buf);
  ADD("energy_initial", fmt("%.17g", a->energy_initial));
  ADD("max_drift", fmt("%.17g", a->max_drift));
#undef ADD
  free(hex);
  char path[LW_PATH_MAX + 32];
  dir_file(path, sizeof path, a, "state.lw");
  if (!s && hex) s = lw_state_write(&st, path, err);
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
  st.sp = NULL; /* the model's */
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

lw_status lw_anneal_resume(lw_anneal *a, const char *dir, long more, lw_error *err)
{
  memset(a, 0, sizeof *a);
  a->wall_start = now_seconds();
  snprintf(a->dir, sizeof a->dir, "%s", dir);
  char path[LW_PATH_MAX + 32], scene_path[2 * LW_PATH_MAX + 2];
  dir_file(path, sizeof path, a, "state.lw");
  lw_state st;
  lw_status s = lw_state_read(&st, path, err);
  if (s) return s;
  lw_path_join(scene_path, sizeof scene_path, dir, st.scene);
  if ((s = lw_params_read(&a->params, scene_path, err)) || (s = setup_schedule(a, err)) ||
      (s = lw_scene_init(&a->scene, &a->params, err))) {
    lw_state_clear(&st);
    return s;
  }
  a->seed = st.seed;
  a->sweep = st.sweep;
  lw_splines *sp = st.sp;
  st.sp = NULL;
  if ((s = build(a, sp, err))) {
    lw_state_clear(&st);
    return s;
  }
  lw_chain *c = a->chain;
  const lw_state_extra *rng = lw_state_get(&st, "rng");
  double v[3 * LW_MOVE_KINDS];
  if (!rng || !lw_chain_rng_load(c, rng->value)) {
    s = lw_error_set(err, LW_EINPUT, "%s:%d: rng: expected the generator state in hex", path, rng ? rng->line : 0);
    goto out;
  }
#define NUMS(key, n) if ((s = read_numbers(&st, path, key, v, n, err))) goto out
  NUMS("temperature", 1); c->temperature = v[0];
  NUMS("block", 1); a->block = (long)v[0];
  NUMS("t_prev", 1); a->t_prev = v[0];
  NUMS("prev_stats", 3); a->prev = (lw_block_stats){v[0], v[1], (long)v[2]};
  NUMS("block_energy", 3); a->acc_n = v[0]; a->acc_sum = v[1]; a->acc_sumsq = v[2];
  NUMS("steps", LW_MOVE_KINDS);
  for (int k = 0; k < LW_MOVE_KINDS; k++) c->step[k] = v[k];
  NUMS("tune_window", 2 * LW_MOVE_KINDS);
  for (int k = 0; k < LW_MOVE_KINDS; k++) {
    c->win_prop[k] = (unsigned long)v[2 * k];
    c->win_acc[k] = (unsigned long)v[2 * k + 1];
  }
  NUMS("moves", 3 * LW_MOVE_KINDS);
  for (int k = 0; k < LW_MOVE_KINDS; k++)
    c->stats[k] = (lw_move_stats){(unsigned long)v[3 * k], (unsigned long)v[3 * k + 1], (unsigned long)v[3 * k + 2]};
  NUMS("trace_mark", 3 * LW_MOVE_KINDS);
  for (int k = 0; k < LW_MOVE_KINDS; k++)
    a->trace_mark[k] = (lw_move_stats){(unsigned long)v[3 * k], (unsigned long)v[3 * k + 1], (unsigned long)v[3 * k + 2]};
  /* The running totals carry the rounding of the moves so far; restoring
  ** them (rather than the fresh sums) keeps the trace identical to an
  ** uninterrupted run. */
  NUMS("energy", LW_TERM_COUNT);
  for (int t = 0; t < LW_TERM_COUNT; t++) a->model->term[t] = v[t];
  NUMS("energy_initial", 1); a->energy_initial = v[0];
  NUMS("max_drift", 1); a->max_drift = v[0];
#undef NUMS
  dir_file(path, sizeof path, a, "timing.txt");
  FILE *tf = fopen(path, "r");
  if (tf) {
    if (fscanf(tf, "wall_seconds %lf", &a->wall_before) != 1 || !(a->wall_before >= 0)) a->wall_before = 0;
    fclose(tf);
  }
  a->end_sweep = more >= 0 ? a->sweep + more : (a->params.sweeps > a->sweep ? a->params.sweeps : a->sweep);
  for (int k = 0; k < LW_MOVE_KINDS; k++) a->proposals_before += c->stats[k].proposed;
  s = truncate_trace(a, err);
out:
  lw_state_clear(&st);
  return s;
}

/* ---- the loop ------------------------------------------------------- */

static void trace_row(lw_anneal *a)
{
  lw_chain *c = a->chain;
  fprintf(a->trace, "%ld,%.10g", a->sweep, c->temperature);
  for (int t = 0; t < LW_TERM_COUNT; t++)
    if (a->scene.on[t]) fprintf(a->trace, ",%.10g", a->model->term[t]);
  fprintf(a->trace, ",%.10g", lw_model_total(a->model));
  for (int k = 0; k < LW_MOVE_KINDS; k++) {
    unsigned long p = c->stats[k].proposed - a->trace_mark[k].proposed;
    unsigned long acc = c->stats[k].accepted - a->trace_mark[k].accepted;
    if (p) fprintf(a->trace, ",%.6f", (double)acc / (double)p);
    else fprintf(a->trace, ",");
    a->trace_mark[k] = c->stats[k];
  }
  fprintf(a->trace, "\n");
}

lw_status lw_anneal_sweep(lw_anneal *a, lw_error *err)
{
  lw_chain *c = a->chain;
  const lw_params *p = &a->params;
  long b = block_of(a, a->sweep);
  if (b != a->block) {
    if (a->block >= 0) {
      double n = a->acc_n, mean = n > 0 ? a->acc_sum / n : 0.0;
      double var = n > 1 ? (a->acc_sumsq - n * mean * mean) / (n - 1) : 0.0;
      a->prev = (lw_block_stats){mean, var > 0 ? sqrt(var) : 0.0, (long)n};
      a->t_prev = c->temperature;
    }
    c->temperature = a->sched_type->temperature(&a->sched, b, a->t_prev, a->block >= 0 ? &a->prev : NULL);
    a->block = b;
    a->acc_n = a->acc_sum = a->acc_sumsq = 0.0;
    memset(c->win_prop, 0, sizeof c->win_prop);
    memset(c->win_acc, 0, sizeof c->win_acc);
  }
  c->tuning = a->sweep - block_start(a, b) < p->tune_sweeps && a->sweep < p->sweeps;
  if (lw_chain_sweep(c) != LW_OK) return lw_error_set(err, LW_ENOMEM, "out of memory growing the pair grid");
  a->sweep++;
  double e = lw_model_total(a->model);
  if (!c->tuning && isfinite(e)) {
    a->acc_n += 1.0;
    a->acc_sum += e;
    a->acc_sumsq += e * e;
  }
  if (a->sweep % p->trace_every == 0 || lw_anneal_done(a)) trace_row(a);
  if (a->sweep % p->check_every == 0) {
    double drift;
    if (lw_model_refresh(a->model, &drift) != LW_OK) return lw_error_set(err, LW_ENOMEM, "out of memory");
    if (drift > a->max_drift) a->max_drift = drift;
  }
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
  unsigned long prop = 0, acc = 0, nan = 0;
  for (int k = 0; k < LW_MOVE_KINDS; k++) {
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
  lw_json_key(&j, "splines"); lw_json_int(&j, (long long)a->model->sp->n_splines);
  lw_json_key(&j, "segments"); lw_json_int(&j, (long long)a->model->sp->n_segments);
  lw_json_key(&j, "proposals"); lw_json_int(&j, (long long)prop);
  lw_json_key(&j, "accepted"); lw_json_int(&j, (long long)acc);
  lw_json_key(&j, "rejected_nan"); lw_json_int(&j, (long long)nan);
  lw_json_key(&j, "wall_seconds"); lw_json_number(&j, wall);
  double here = now_seconds() - a->wall_start;
  lw_json_key(&j, "proposals_per_second");
  lw_json_number(&j, here > 0 ? (double)(prop - a->proposals_before) / here : 0.0);
  lw_json_key(&j, "max_relative_drift"); lw_json_number(&j, a->max_drift);
  lw_json_key(&j, "temperature_final"); lw_json_number(&j, c->temperature);
  lw_json_key(&j, "schedule"); lw_json_string(&j, a->sched_type->name);
  lw_json_key(&j, "energy");
  lw_json_begin_object(&j);
  lw_json_key(&j, "total"); lw_json_number(&j, lw_model_total(a->model));
  for (int t = 0; t < LW_TERM_COUNT; t++)
    if (a->scene.on[t]) {
      lw_json_key(&j, lw_term_types[t].name);
      lw_json_number(&j, a->model->term[t]);
    }
  lw_json_end_object(&j);
  lw_json_key(&j, "energy_initial"); lw_json_number(&j, a->energy_initial);
  lw_json_key(&j, "acceptance");
  lw_json_begin_object(&j);
  for (int k = 0; k < LW_MOVE_KINDS; k++) {
    lw_json_key(&j, lw_move_names[k]);
    if (c->stats[k].proposed) lw_json_number(&j, (double)c->stats[k].accepted / (double)c->stats[k].proposed);
    else lw_json_null(&j);
  }
  lw_json_end_object(&j);
  lw_json_key(&j, "proposed");
  lw_json_begin_object(&j);
  for (int k = 0; k < LW_MOVE_KINDS; k++) {
    lw_json_key(&j, lw_move_names[k]);
    lw_json_int(&j, (long long)c->stats[k].proposed);
  }
  lw_json_end_object(&j);
  lw_json_key(&j, "steps");
  lw_json_begin_object(&j);
  for (int k = 0; k < LW_MOVE_KINDS; k++) {
    lw_json_key(&j, lw_move_names[k]);
    lw_json_number(&j, k == LW_MOVE_ROTATE ? c->step[k] * 180.0 / M_PI : c->step[k]);
  }
  lw_json_end_object(&j);
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
  lw_output_page page;
  lw_output_page_init(&page, a->params.width, a->params.height);
  page.stroke_mm = a->params.pen_width;
  char path[LW_PATH_MAX + 32];
  dir_file(path, sizeof path, a, "final.svg");
  if ((s = lw_output_svg(a->model->sp, &page, path, err))) return s;
  dir_file(path, sizeof path, a, "final.png");
  if ((s = lw_output_png(a->model->sp, &page, a->params.png_scale, path, err))) return s;
  return write_summary(a, err);
}

void lw_anneal_free(lw_anneal *a)
{
  if (a->trace) fclose(a->trace);
  lw_chain_free(a->chain);
  lw_model_free(a->model);
  lw_scene_clear(&a->scene);
  lw_schedule_clear(&a->sched);
  memset(a, 0, sizeof *a);
}
