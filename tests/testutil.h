/* testutil.h -- small helpers shared by the test files. */
#ifndef LINEWISE_TESTUTIL_H
#define LINEWISE_TESTUTIL_H

#include <criterion/criterion.h>
#include <ctype.h>
#include <gsl/gsl_math.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "linewise/init.h"
#include "linewise/mc.h"
#include "linewise/model.h"
#include "linewise/pairnear.h"
#include "linewise/scene.h"
#include "linewise/spline.h"
#include "linewise/sys_splines.h"

/* A chain on a view of model m (the test keeps the model) through the
** spline system's row; model_chain_free frees the chain and the view. */
static inline lw_chain *model_chain(lw_model *m, const double *w, const double *st, const double *tg,
                                    unsigned long seed, lw_error *err)
{
  lw_system *sys = lw_splines_view(m, err);
  if (!sys) return NULL;
  lw_chain *c = lw_chain_new(sys, w, st, tg, seed, err);
  if (!c) lw_system_free(sys);
  return c;
}

static inline void model_chain_free(lw_chain *c)
{
  if (!c) return;
  lw_system *sys = c->sys;
  lw_chain_free(c);
  lw_system_free(sys);
}

/* splitmix64: a fixed seed per test keeps failures reproducible while the
** values carry full 53-bit mantissas (no round test numbers). */
static inline uint64_t *lw_test_rng_state(void)
{
  static uint64_t state;
  return &state;
}
/* bin/linewise and the repository root, as `make test` sets them (LW_BIN,
** LW_ROOT) for the tests that run the binary or read bundled files. */
static inline const char *lw_test_bin(void)
{
  const char *b = getenv("LW_BIN");
  cr_assert_not_null(b, "LW_BIN must name bin/linewise (make test sets it)");
  return b;
}

static inline const char *lw_test_root(void)
{
  const char *r = getenv("LW_ROOT");
  return r ? r : ".";
}

/* Batch means of one observable (statistical tests): BATCHES batches of
** `per` samples each, added in order; the mean of the batch means and its
** standard error. */
#define BATCHES 50
typedef struct {
  double batch[BATCHES];
  long per, n;
} batch_mean;

static inline void bm_add(batch_mean *b, double v)
{
  b->batch[b->n / b->per] += v / (double)b->per;
  b->n++;
}

static inline double bm_mean(const batch_mean *b, double *se)
{
  double m = 0.0, ss = 0.0;
  for (int k = 0; k < BATCHES; k++) m += b->batch[k] / BATCHES;
  for (int k = 0; k < BATCHES; k++) ss += (b->batch[k] - m) * (b->batch[k] - m);
  *se = sqrt(ss / (BATCHES - 1) / BATCHES);
  return m;
}

static inline void rng_seed(uint64_t s) { *lw_test_rng_state() = s; }
static inline double urand(double lo, double hi)
{
  uint64_t z = (*lw_test_rng_state() += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return lo + (hi - lo) * ((double)(z >> 11) * 0x1.0p-53);
}

/* 1 when the long versions of the statistical and stress tests run
** (`make test-long` sets LW_LONG=1); quick versions otherwise. */
static inline int lw_test_long(void)
{
  const char *e = getenv("LW_LONG");
  return e && *e && strcmp(e, "0") != 0;
}

/* The mean and standard error of row `name` of `linewise stats --csv`. */
static inline void lw_test_stats_row(const char *csv, const char *name, double *mean, double *se)
{
  char key[128];
  snprintf(key, sizeof key, "\n%s,", name);
  const char *p = strstr(csv, key);
  cr_assert_not_null(p, "no row %s in:\n%s", name, csv);
  long n;
  cr_assert_eq(sscanf(p + strlen(key), "%ld,%lf,%lf", &n, mean, se), 3, "%s", p);
}

/* |a - b| <= tol * max(|b|, floor) */
static inline int lw_close_rel(double a, double b, double tol, double floor)
{
  double s = fabs(b) > floor ? fabs(b) : floor;
  return fabs(a - b) <= tol * s;
}

/* Spline i of sp becomes the straight line from (x0,y0) to (x1,y1) with
** uniform parametrisation (v_k = chord / (3 n)). */
static inline void lw_test_straight(lw_splines *sp, size_t i, double x0, double y0, double x1, double y1)
{
  size_t n = lw_splines_segments(sp, i);
  lw_node *nd = &sp->node[sp->first[i]];
  for (size_t k = 0; k <= n; k++) {
    double t = (double)k / (double)n;
    nd[k] = (lw_node){x0 + t * (x1 - x0), y0 + t * (y1 - y0), (x1 - x0) / (3.0 * n), (y1 - y0) / (3.0 * n)};
  }
  sp->rest_length[i] = hypot(x1 - x0, y1 - y0);
}

/* Spline i of sp becomes the standard cubic Bezier approximation of the
** circle of radius R around (cx, cy), one arc of 2 pi / n per segment
** (handle length 4/3 tan(theta/4) R). */
static inline void lw_test_circle(lw_splines *sp, size_t i, double cx, double cy, double R)
{
  size_t n = lw_splines_segments(sp, i);
  double th = 2.0 * M_PI / (double)n, h = 4.0 / 3.0 * tan(th / 4.0) * R;
  lw_node *nd = &sp->node[sp->first[i]];
  for (size_t k = 0; k <= n; k++) {
    double a = th * (double)k;
    nd[k] = (lw_node){cx + R * cos(a), cy + R * sin(a), -h * sin(a), h * cos(a)};
  }
  sp->rest_length[i] = 2.0 * M_PI * R;
}

/* Where the suites keep their files: $TMPDIR when it is a plain absolute path
** of at most 32 characters, else /tmp.  The suites paste these paths into
** shell commands unquoted and keep them in 64-byte buffers, so a TMPDIR with
** spaces, quotes or a long name is passed over rather than half-honoured. */
static inline const char *lw_test_tmp(void)
{
  const char *t = getenv("TMPDIR");
  if (!t || t[0] != '/' || strlen(t) > 32) return "/tmp";
  for (const char *c = t; *c; c++)
    if (!isalnum((unsigned char)*c) && !strchr("_./+-", *c)) return "/tmp";
  return t;
}

/* The mkstemp/mkdtemp template <tmp>/lw_<tag>_XXXXXX, into path (64 chars). */
static inline char *lw_test_tmp_name(char path[64], const char *tag)
{
  snprintf(path, 64, "%s/lw_%s_XXXXXX", lw_test_tmp(), tag);
  return path;
}

/* A fresh directory <tmp>/lw_<tag>_XXXXXX for a suite's files, into dir
** (64 chars); 0 on success.  lw_test_dir_remove deletes it and its files. */
static inline int lw_test_dir_make(char dir[64], const char *tag)
{
  return mkdtemp(lw_test_tmp_name(dir, tag)) ? 0 : -1;
}
/* The whole file named by the format (NUL-terminated, caller frees), or NULL. */
static inline char *lw_test_slurp(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static inline char *lw_test_slurp(const char *fmt, ...)
{
  char path[512];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(path, sizeof path, fmt, ap);
  va_end(ap);
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  size_t cap = 4096, n = 0;
  char *s = malloc(cap);
  size_t got;
  while ((got = fread(s + n, 1, cap - n - 1, f)) > 0) {
    n += got;
    if (n + 1 == cap) s = realloc(s, cap *= 2);
  }
  fclose(f);
  s[n] = '\0';
  return s;
}

/* Runs a shell command built like printf; its exit status, or -1. */
static inline int lw_test_sh(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static inline int lw_test_sh(const char *fmt, ...)
{
  char cmd[2048];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(cmd, sizeof cmd, fmt, ap);
  va_end(ap);
  int st = system(cmd);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* Skips a test that watches a run through strace(1) where strace cannot
** trace (a container or a build chroot without ptrace), as a test needing
** clang or MPI skips: it failed there, a packager's build with it. */
static inline void lw_test_need_strace(void)
{
  if (lw_test_sh("strace -o /dev/null true >/dev/null 2>&1"))
    cr_skip_test("strace cannot trace here (not installed, or no ptrace: make deps installs it)");
}

/* The text of the file at path, in a static buffer of 1 MiB (cut there): one
** file at a time, valid until the next call. */
static inline char *lw_test_read_text(const char *path)
{
  static char buf[1 << 20];
  FILE *f = fopen(path, "rb");
  cr_assert_not_null(f, "%s", path);
  size_t n = fread(buf, 1, sizeof buf - 1, f);
  buf[n] = '\0';
  fclose(f);
  return buf;
}

/* dir/name holds text afterwards (a scene file); 0 on success. */
static inline int lw_test_write_text(const char *dir, const char *name, const char *text)
{
  char path[256];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "w");
  if (!f) return -1;
  int bad = fputs(text, f) < 0;
  return fclose(f) || bad ? -1 : 0;
}

static inline int lw_test_dir_remove(const char *dir)
{
  char cmd[96];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  return system(cmd);
}

/* Spline i of sp becomes an arc of the circle (cx, cy, R) from angle t0 to t1
** in the standard cubic approximation (handles 4/3 tan(dt/4) R), one segment
** per equal angle step; the rest length is the arc's length. */
static inline void lw_test_arc(lw_splines *sp, size_t i, double cx, double cy, double R, double t0, double t1)
{
  size_t m = lw_splines_segments(sp, i);
  double dt = (t1 - t0) / (double)m, k = 4.0 / 3.0 * tan(dt / 4.0) * R;
  lw_node *nd = &sp->node[sp->first[i]];
  for (size_t j = 0; j <= m; j++) {
    double t = t0 + (double)j * dt;
    nd[j] = (lw_node){cx + R * cos(t), cy + R * sin(t), -k * sin(t), k * cos(t)};
  }
  sp->rest_length[i] = fabs(t1 - t0) * R;
}

/* A random move of sp for checks of dE against recomputation: kind 0 moves
** one point p, 1 one vector v, 2 the whole spline, by a Gaussian step of
** standard deviation sd (x then y drawn from r).  The new nodes go to nd
** (room for the longest spline), the spline, first node and count to *i,
** *node0, *n_node, as lw_model_propose takes them. */
static inline void lw_test_random_move(const lw_splines *sp, gsl_rng *r, int kind, double sd, lw_node *nd,
                                       uint32_t *i, size_t *node0, size_t *n_node)
{
  *i = (uint32_t)gsl_rng_uniform_int(r, sp->n_splines);
  size_t nn = sp->first[*i + 1] - sp->first[*i];
  const lw_node *src = &sp->node[sp->first[*i]];
  *node0 = 0;
  *n_node = nn;
  if (kind < 2) {
    *node0 = gsl_rng_uniform_int(r, nn);
    *n_node = 1;
  }
  double dx = gsl_ran_gaussian(r, sd), dy = gsl_ran_gaussian(r, sd);
  for (size_t k = 0; k < *n_node; k++) {
    nd[k] = src[*node0 + k];
    if (kind == 1) {
      nd[k].vx += dx;
      nd[k].vy += dy;
    } else {
      nd[k].px += dx;
      nd[k].py += dy;
    }
  }
}

/* A scene from p, asserting that it builds. */
static inline void lw_test_scene(lw_scene *sc, const lw_params *p)
{
  lw_error err;
  cr_assert_eq(lw_scene_init(sc, p, &err), LW_OK, "%s", err.msg);
}

/* A model of n random splines of segs segments of length len (lw_init_random,
** stream seeded with seed) on sc, asserting that it builds. */
static inline lw_model *lw_test_model_random(const lw_scene *sc, size_t n, size_t segs, double len,
                                            unsigned long seed)
{
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, seed);
  lw_error err;
  lw_splines *sp = lw_init_random(sc, n, segs, len, r, &err);
  cr_assert_not_null(sp, "%s", err.msg);
  gsl_rng_free(r);
  lw_model *m = lw_model_new(sc, sp, &err);
  cr_assert_not_null(m, "%s", err.msg);
  return m;
}

/* Every pair slot of m (model.h) holds what lw_pair_near_correction gives its
** pair now, bit for bit, and no segment holds a partner twice; returns how
** many slots were full, so a caller can see that the check saw something. */
static inline size_t lw_test_pair_slots_hold_current(const lw_model *m)
{
  if (!m->near_pid) return 0;
  const int np = m->scene->pair_quad.n;
  size_t full = 0;
  for (size_t g = 0; g < m->sp->n_segments; g++) {
    const uint32_t *id = m->near_pid + g * LW_NEAR_SLOTS;
    for (int k = 0; k < LW_NEAR_SLOTS; k++) {
      if (id[k] == LW_NEAR_FREE) continue;
      for (int j = 0; j < k; j++) cr_assert_neq(id[j], id[k], "segment %zu holds partner %u twice", g, id[k]);
      const uint32_t h = id[k];
      double a[8], b[8];
      lw_pair_sample sa[LW_QUAD_MAX], sb[LW_QUAD_MAX];
      lw_segment_bezier(&m->sp->node[lw_segment_node(m->sp, g)], &m->sp->node[lw_segment_node(m->sp, g) + 1], a);
      lw_segment_bezier(&m->sp->node[lw_segment_node(m->sp, h)], &m->sp->node[lw_segment_node(m->sp, h) + 1], b);
      for (int q = 0; q < np; q++) {
        lw_cellgrid_get(m->grid, (uint32_t)(g * (size_t)np + (size_t)q), &sa[q].x, &sa[q].y, &sa[q].dl);
        lw_cellgrid_get(m->grid, (uint32_t)(h * (size_t)np + (size_t)q), &sb[q].x, &sb[q].y, &sb[q].dl);
      }
      double now = lw_pair_near_correction(a, sa, b, sb, np, &m->scene->pair);
      cr_assert(now == m->near_pval[g * LW_NEAR_SLOTS + (size_t)k], "segment %zu, partner %u: slot %.17g, now %.17g",
                g, h, m->near_pval[g * LW_NEAR_SLOTS + (size_t)k], now);
      full++;
    }
  }
  return full;
}

/* Random moves of every kind (one point, one vector, a whole spline; steps
** of sd, stream seeded with seed) on model m of scene sc: each term's local
** difference against a recomputation from scratch within 1e-9, and after
** the accepted half of them (every odd trial is committed) the model's
** running terms and total.  Returns how many moves had a finite energy
** (a move off the frame is +inf either way and is skipped). */
static inline int lw_test_moves_match_full(const lw_scene *sc, lw_model *m, int trials, double sd,
                                           unsigned long seed)
{
  lw_proposal *pr = lw_proposal_new(m, NULL);
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, seed);
  double term0[LW_TERM_COUNT], term1[LW_TERM_COUNT];
  double e0 = lw_energy_compute(sc, m->sp, term0, NULL);
  lw_node *nd = malloc(m->sp->n_nodes * sizeof *nd);
  cr_assert_not_null(nd);
  int checked = 0;
  for (int trial = 0; trial < trials; trial++) {
    uint32_t i;
    size_t node0, n_node;
    lw_test_random_move(m->sp, r, trial % 3, sd, nd, &i, &node0, &n_node);
    lw_model_propose(m, pr, i, node0, n_node, nd);
    lw_splines *moved = lw_splines_clone(m->sp);
    memcpy(&moved->node[moved->first[i] + node0], nd, n_node * sizeof *nd);
    double e1 = lw_energy_compute(sc, moved, term1, NULL);
    lw_splines_free(moved);
    if (!isfinite(e1) || !isfinite(pr->dE)) continue;
    checked++;
    for (int t = 0; t < LW_TERM_COUNT; t++)
      cr_assert(fabs(pr->dterm[t] - (term1[t] - term0[t])) <= 1e-9 * fmax(fabs(term0[t]), 1e-3),
                "trial %d term %s: local %.17g, full %.17g", trial, lw_term_names[t], pr->dterm[t],
                term1[t] - term0[t]);
    cr_assert(fabs(pr->dE - (e1 - e0)) <= 1e-9 * fmax(fabs(e0), 1.0), "trial %d: dE %.17g, full %.17g", trial,
              pr->dE, e1 - e0);
    if (trial % 2) {
      cr_assert_eq(lw_model_commit(m, pr), LW_OK);
      e0 = e1;
      memcpy(term0, term1, sizeof term0);
    }
  }
  for (int t = 0; t < LW_TERM_COUNT; t++)
    cr_assert(fabs(m->term[t] - term0[t]) <= 1e-9 * fmax(fabs(term0[t]), 1e-3), "%s", lw_term_names[t]);
  cr_assert(fabs(lw_model_total(m) - e0) <= 1e-9 * fmax(fabs(e0), 1.0));
  lw_test_pair_slots_hold_current(m);
  free(nd);
  gsl_rng_free(r);
  lw_proposal_free(pr);
  return checked;
}

#endif
