/*
** mc.c -- the Metropolis chain (mc.h).
*/
#include "linewise/mc.h"

#include <gsl/gsl_math.h>
#include <gsl/gsl_randist.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

const char *const lw_move_names[LW_MOVE_KINDS] = {"point", "vector", "translate", "rotate"};

lw_chain *lw_chain_new(lw_model *m, const double weight[LW_MOVE_KINDS], const double step[LW_MOVE_KINDS],
                       const double target[LW_MOVE_KINDS], unsigned long seed, lw_error *err)
{
  double sum = 0.0;
  for (int k = 0; k < LW_MOVE_KINDS; k++) sum += weight[k];
  if (!(sum > 0)) {
    lw_error_set(err, LW_EINPUT, "[moves]: every move weight is 0; at least one must be > 0");
    return NULL;
  }
  lw_chain *c = calloc(1, sizeof *c);
  if (!c) goto nomem;
  c->model = m;
  c->prop = lw_proposal_new(m, err);
  c->rng = gsl_rng_alloc(gsl_rng_mt19937);
  if (!c->prop || !c->rng) goto nomem;
  gsl_rng_set(c->rng, seed);
  double acc = 0.0;
  /* Steps are capped at the page size: beyond that a Gaussian step only
  ** throws nodes off the page. */
  double page = fmax(m->scene->width, m->scene->height);
  for (int k = 0; k < LW_MOVE_KINDS; k++) {
    acc += weight[k] / sum;
    c->cum_weight[k] = acc;
    c->step[k] = step[k];
    c->target[k] = target[k];
    c->step_max[k] = k == LW_MOVE_ROTATE ? M_PI : page;
  }
  c->cum_weight[LW_MOVE_KINDS - 1] = 1.0;
  return c;
nomem:
  lw_chain_free(c);
  lw_error_set(err, LW_ENOMEM, "out of memory for a chain");
  return NULL;
}

void lw_chain_free(lw_chain *c)
{
  if (!c) return;
  lw_proposal_free(c->prop);
  if (c->rng) gsl_rng_free(c->rng);
  free(c);
}

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

static void tune(lw_chain *c, lw_move_kind kind, int accepted)
{
  c->win_prop[kind]++;
  c->win_acc[kind] += (unsigned long)accepted;
  if (c->win_prop[kind] < LW_TUNE_WINDOW) return;
  double rate = (double)c->win_acc[kind] / (double)c->win_prop[kind];
  /* multiplicative update: a step that accepts too often grows, one that
  ** rarely accepts shrinks; the factor is bounded by e^{+-1} per window and
  ** vanishes at the target, so steps settle there */
  double s = c->step[kind] * exp(rate - c->target[kind]);
  c->step[kind] = fmin(s, c->step_max[kind]);
  if (c->step[kind] < 1e-300) c->step[kind] = 1e-300;
  c->win_prop[kind] = c->win_acc[kind] = 0;
}

int lw_chain_step(lw_chain *c, lw_move_kind kind)
{
  lw_model *m = c->model;
  const lw_splines *sp = m->sp;
  if (sp->n_nodes == 0) return 0;
  uint32_t i;
  size_t node0, n_node;
  lw_node *nd = c->prop->node; /* proposals are built in place in the scratch */
  const double st = c->step[kind];
  if (kind == LW_MOVE_POINT || kind == LW_MOVE_VECTOR) {
    size_t k = gsl_rng_uniform_int(c->rng, sp->n_nodes);
    i = spline_of_node(sp, k);
    node0 = k - sp->first[i];
    n_node = 1;
    nd[0] = sp->node[k];
    double dx = gsl_ran_gaussian_ziggurat(c->rng, st), dy = gsl_ran_gaussian_ziggurat(c->rng, st);
    if (kind == LW_MOVE_POINT) {
      nd[0].px += dx;
      nd[0].py += dy;
    } else {
      nd[0].vx += dx;
      nd[0].vy += dy;
    }
  } else {
    i = (uint32_t)gsl_rng_uniform_int(c->rng, sp->n_splines);
    node0 = 0;
    n_node = sp->first[i + 1] - sp->first[i];
    const lw_node *src = &sp->node[sp->first[i]];
    if (kind == LW_MOVE_TRANSLATE) {
      double dx = gsl_ran_gaussian_ziggurat(c->rng, st), dy = gsl_ran_gaussian_ziggurat(c->rng, st);
      for (size_t k = 0; k < n_node; k++) {
        nd[k] = src[k];
        nd[k].px += dx;
        nd[k].py += dy;
      }
    } else {
      double a = gsl_ran_gaussian_ziggurat(c->rng, st), ca = cos(a), sa = sin(a);
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
  lw_model_propose(m, c->prop, i, node0, n_node, NULL);
  double dE = c->prop->dE;
  int accept;
  lw_move_stats *s = &c->stats[kind];
  s->proposed++;
  if (isnan(dE)) {
    s->nan++;
    accept = 0;
  } else if (c->prop->irregular) {
    s->irregular++;
    accept = 0;
  } else if (dE <= 0.0) {
    accept = 1;
  } else if (c->temperature > 0.0 && dE < INFINITY) {
    double x = -dE / c->temperature;
    /* exp underflows to 0 below about -745: no need to draw then */
    accept = x > -745.0 && gsl_rng_uniform(c->rng) < exp(x);
  } else {
    accept = 0;
  }
  if (accept) {
    if (lw_model_commit(m, c->prop) != LW_OK) accept = -1;
    else s->accepted++;
  }
  if (c->tuning && accept >= 0) tune(c, kind, accept);
  return accept;
}

lw_status lw_chain_sweep(lw_chain *c)
{
  size_t n = c->model->sp->n_nodes;
  for (size_t k = 0; k < n; k++) {
    double u = gsl_rng_uniform(c->rng);
    int kind = 0;
    while (kind < LW_MOVE_KINDS - 1 && u >= c->cum_weight[kind]) kind++;
    if (lw_chain_step(c, (lw_move_kind)kind) < 0) return LW_ENOMEM;
  }
  return LW_OK;
}

char *lw_rng_save(const gsl_rng *r)
{
  size_t n = gsl_rng_size(r);
  const unsigned char *b = gsl_rng_state(r);
  char *hex = malloc(2 * n + 1);
  if (!hex) return NULL;
  for (size_t i = 0; i < n; i++) sprintf(hex + 2 * i, "%02x", b[i]);
  hex[2 * n] = '\0';
  return hex;
}

/* Strict: exactly the state's size in lower-case hex, and for mt19937 (the
** generator of every stream) a position index and words GSL itself could
** have left there, since it indexes its table with the one and returns the
** others unmasked. */
int lw_rng_load(gsl_rng *r, const char *hex)
{
  size_t n = gsl_rng_size(r);
  if (strspn(hex, "0123456789abcdef") != 2 * n || hex[2 * n]) return 0;
  unsigned char *b = gsl_rng_state(r), *copy = malloc(n);
  if (!copy) return 0;
  for (size_t i = 0; i < n; i++) {
    unsigned hi = (unsigned)(hex[2 * i] <= '9' ? hex[2 * i] - '0' : hex[2 * i] - 'a' + 10);
    unsigned lo = (unsigned)(hex[2 * i + 1] <= '9' ? hex[2 * i + 1] - '0' : hex[2 * i + 1] - 'a' + 10);
    copy[i] = (unsigned char)(hi << 4 | lo);
  }
  int ok = 1;
  if (r->type == gsl_rng_mt19937) {
    enum { MT_N = 624 };
    unsigned long mt[MT_N];
    int mti;
    ok = n >= sizeof mt + sizeof mti;
    if (ok) {
      memcpy(mt, copy, sizeof mt);
      memcpy(&mti, copy + sizeof mt, sizeof mti);
      ok = mti >= 0 && mti <= MT_N;
      for (int i = 0; ok && i < MT_N; i++) ok = mt[i] <= 0xffffffffUL;
    }
  }
  if (ok) memcpy(b, copy, n);
  free(copy);
  return ok;
}
