/* benchutil.c -- shared pieces of the benchmark (benchutil.h). */
#define _XOPEN_SOURCE 700 /* nftw */
#include "benchutil.h"
#include <ctype.h>
#include <ftw.h>
#include <gsl/gsl_randist.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "linewise/anneal.h"
#include "linewise/init.h"
#include "linewise/vec2.h"

double bench_now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

double bench_median(double *v, int n)
{
  qsort(v, (size_t)n, sizeof *v, cmp_double);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

_Noreturn void bench_die(const char *what, const lw_error *err)
{
  fprintf(stderr, "bench: %s%s%s\n", what, err ? ": " : "", err ? err->msg : "");
  exit(1);
}

void bench_scratch_dir(char *dir, size_t n, const char *tag)
{
  /* the scratch paths go into shell commands unquoted (mpirun), so only a
  ** plain TMPDIR is taken */
  const char *t = getenv("TMPDIR");
  int plain = t && t[0] == '/' && strlen(t) <= 64;
  for (const char *c = t; plain && *c; c++) plain = isalnum((unsigned char)*c) || strchr("_./+-", *c);
  if ((size_t)snprintf(dir, n, "%s/lw_bench_%s_XXXXXX", plain ? t : "/tmp", tag) >= n || !mkdtemp(dir)) {
    fprintf(stderr, "bench: %s: cannot make a scratch directory for the %s runs\n", dir, tag);
    exit(1);
  }
}

static int remove_entry(const char *path, const struct stat *st, int type, struct FTW *ftw)
{
  (void)st, (void)type, (void)ftw;
  return remove(path);
}

void bench_scratch_remove(const char *dir)
{
  if (nftw(dir, remove_entry, 16, FTW_DEPTH | FTW_PHYS) != 0) bench_note("could not remove %s", dir);
}

FILE *bench_data(const bench_ctx *b, const char *name)
{
  char path[1024];
  snprintf(path, sizeof path, "%s/%s", b->datadir, name);
  FILE *f = fopen(path, "w");
  if (!f) {
    lw_error e;
    lw_error_set(&e, LW_EIO, "cannot write %s", path);
    bench_die("data file", &e);
  }
  return f;
}

void bench_note(const char *fmt, ...)
{
  va_list ap;
  va_start(ap, fmt);
  fflush(stdout);
  fputs("bench: ", stderr);
  vfprintf(stderr, fmt, ap);
  fputc('\n', stderr);
  va_end(ap);
}

void bench_random_params(lw_params *p, size_t n, int pair, double spacing)
{
  lw_params_defaults(p);
  p->splines = (int)n;
  p->segments = 4;
  p->segment_length = 5.0;
  /* a square page on which the lines' total length covers it at `spacing` */
  double side = sqrt((double)n * p->segments * p->segment_length * spacing);
  p->width = p->height = side + 2.0;
  p->margin = 1.0;
  p->strain = 10;
  p->bending = 1;
  p->potential_coef = 0.5;
  p->potential = LW_POT_RADIAL;
  p->field_coef = -0.5;
  p->field = LW_FLD_WAVES;
  p->boundary_coef = 0.1;
  if (pair) {
    p->pair = 0.01;
    p->pair_cutoff = 4;
  }
  p->seed = 1;
}

void bench_run_init(bench_run *r, const lw_params *p, lw_splines *sp, double T, const double *step)
{
  lw_error err;
  memset(r, 0, sizeof *r);
  if (lw_scene_init(&r->scene, p, &err)) bench_die("scene", &err);
  if (!sp) {
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, (unsigned long)p->seed);
    sp = lw_init_random(&r->scene, (size_t)p->splines, (size_t)p->segments, p->segment_length, rng, &err);
    gsl_rng_free(rng);
    if (!sp) bench_die("placement", &err);
  }
  r->model = lw_model_new(&r->scene, sp, &err);
  if (!r->model) bench_die("model", &err);
  const double w[LW_MOVE_KINDS] = {0.5, 0.5, 0, 0}, st0[LW_MOVE_KINDS] = {0.2, 0.2, 0.2, 0.05},
               tg[LW_MOVE_KINDS] = {0.44, 0.44, 0.3, 0.3};
  r->sys = lw_splines_view(r->model, &err);
  if (!r->sys) bench_die("system", &err);
  r->chain = lw_chain_new(r->sys, w, step ? step : st0, tg, 2, &err);
  if (!r->chain) bench_die("chain", &err);
  r->chain->temperature = T;
  r->chain->tuning = 0;
}

void bench_run_free(bench_run *r)
{
  lw_chain_free(r->chain);
  lw_system_free(r->sys);
  lw_model_free(r->model);
  lw_scene_clear(&r->scene);
  memset(r, 0, sizeof *r);
}

void bench_run_tune(bench_run *r, long proposals)
{
  r->chain->tuning = 1;
  for (long k = 0; k < proposals; k++) lw_chain_step(r->chain, k & 1);
  r->chain->tuning = 0;
}

bench_trial *bench_trials_new(const lw_splines *sp, const double step[2], int n)
{
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  bench_trial *t = malloc((size_t)n * sizeof *t);
  if (!r || !t) bench_die("out of memory", NULL);
  gsl_rng_set(r, 11);
  for (int k = 0; k < n; k++) {
    size_t g = gsl_rng_uniform_int(r, sp->n_nodes);
    size_t lo = 0, hi = sp->n_splines; /* the spline holding node g */
    while (hi - lo > 1) {
      size_t mid = (lo + hi) / 2;
      if (sp->first[mid] <= g) lo = mid;
      else hi = mid;
    }
    t[k].spline = (uint32_t)lo;
    t[k].node = g - sp->first[lo];
    t[k].nd = sp->node[g];
    double s = step[k & 1], dx = gsl_ran_gaussian_ziggurat(r, s), dy = gsl_ran_gaussian_ziggurat(r, s);
    if (k & 1) {
      t[k].nd.vx += dx;
      t[k].nd.vy += dy;
    } else {
      t[k].nd.px += dx;
      t[k].nd.py += dy;
    }
  }
  gsl_rng_free(r);
  return t;
}

double bench_run_propose(bench_run *r, const bench_trial *t)
{
  lw_proposal *prop = r->chain->prop;
  lw_model_propose(r->model, prop, t->spline, t->node, 1, &t->nd);
  return prop->dE;
}

double bench_run_block(bench_run *r, double seconds, const bench_trial *trials, int n_trials)
{
  /* the clock is read every 64 proposals: ~1 ns a proposal, under the noise */
  long n = 0;
  lw_vec_set_wide(!r->narrow);
  double t0 = bench_now(), t;
  do {
    if (trials) {
      for (int k = 0; k < 64; k++) bench_run_propose(r, &trials[(n + k) % n_trials]);
      n += 64;
    } else if (r->sweeps) {
      if (lw_chain_sweep(r->chain) != LW_OK) bench_die("sweep", &(lw_error){.code = LW_ENOMEM, .msg = "sweep"});
      n += (long)r->sys->type->sweep_size(r->sys->state);
    } else {
      for (int k = 0; k < 64; k++) lw_chain_step(r->chain, k & 1);
      n += 64;
    }
    t = bench_now() - t0;
  } while (t < seconds);
  lw_vec_set_wide(1);
  return t / (double)n * 1e9;
}

void bench_time_runs(const bench_ctx *b, bench_run *runs, int n, int ref, const bench_trial *trials,
                     int n_trials, double *ns, double *ratio, double *spread)
{
  double (*t)[BENCH_MAX_REPS] = malloc((size_t)n * sizeof *t);
  if (!t) bench_die("out of memory", NULL);
  for (int rep = 0; rep < b->reps; rep++)
    for (int i = 0; i < n; i++) t[i][rep] = bench_run_block(&runs[i], b->block, trials, n_trials);
  for (int i = 0; i < n; i++) {
    double q[BENCH_MAX_REPS];
    for (int rep = 0; rep < b->reps; rep++) q[rep] = t[i][rep] / t[ref][rep];
    ratio[i] = bench_median(q, b->reps);
    if (spread) {
      for (int rep = 0; rep < b->reps; rep++) q[rep] = fabs(q[rep] - ratio[i]);
      spread[i] = bench_median(q, b->reps);
    }
    ns[i] = bench_median(t[i], b->reps);
  }
  free(t);
}

double bench_run_acceptance(const bench_run *r)
{
  const lw_move_stats *s = r->chain->stats;
  double prop = (double)(s[LW_MOVE_POINT].proposed + s[LW_MOVE_VECTOR].proposed);
  return prop > 0 ? (double)(s[LW_MOVE_POINT].accepted + s[LW_MOVE_VECTOR].accepted) / prop : 0.0;
}

const lw_splines *bench_annealed(bench_ctx *b)
{
  if (b->ann_splines) return b->ann_splines;
  lw_params *p = &b->ann_params;
  lw_error err;
  if (lw_params_read(p, "params/study.ini", &err)) bench_die("the accuracy scene", &err);
  static const char *const extra[] = {"scene.potential=radial", "energy.potential=0.3"};
  for (size_t k = 0; k < sizeof extra / sizeof extra[0]; k++)
    if (lw_params_set(p, extra[k], &err)) bench_die("the accuracy scene", &err);
  if (b->quick) p->sweeps = 40;
  char dir[1024];
  snprintf(dir, sizeof dir, "%s/anneal", b->datadir);
  bench_note("annealing the accuracy scene (%d sweeps) into %s", p->sweeps, dir);
  lw_anneal a;
  double t0 = bench_now();
  if (lw_anneal_start(&a, p, dir, &err)) bench_die("anneal", &err);
  while (!lw_anneal_done(&a))
    if (lw_anneal_sweep(&a, &err)) bench_die("anneal", &err);
  if (lw_anneal_finish(&a, &err)) bench_die("anneal", &err);
  b->ann_seconds = bench_now() - t0;
  for (int k = 0; k < LW_MOVE_KINDS; k++) b->ann_step[k] = a.chain->step[k];
  const lw_model *m = lw_splines_model(a.sys);
  b->ann_splines = lw_splines_clone(m->sp);
  if (!b->ann_splines) bench_die("out of memory", NULL);
  double length = 0.0;
  for (size_t i = 0; i < m->sp->n_splines; i++) length += m->spline_len[i];
  b->ann_spacing = (p->width - 2 * p->margin) * (p->height - 2 * p->margin) / length;
  lw_anneal_free(&a);
  return b->ann_splines;
}
