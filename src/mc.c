/*
** mc.c -- the Metropolis chain (mc.h).
*/
#include "linewise/mc.h"

#include "linewise/domains.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

lw_chain *lw_chain_new(lw_system *sys, const double *weight, const double *step, const double *target,
                       unsigned long seed, lw_error *err)
{
  const lw_system_type *t = sys->type;
  double sum = 0.0;
  for (int k = 0; k < t->n_moves; k++) sum += weight[k];
  if (!(sum > 0)) {
    lw_error_set(err, LW_EINPUT, "[moves]: every move weight is 0; at least one must be > 0");
    return NULL;
  }
  lw_chain *c = calloc(1, sizeof *c);
  if (!c) goto nomem;
  c->sys = sys;
  c->n_moves = t->n_moves;
  c->delayed = 1;
  c->prop = t->proposal_new(sys->state, err);
  c->rng = lw_rng_new();
  if (!c->prop || !c->rng) goto nomem;
  gsl_rng_set(c->rng, seed);
  double acc = 0.0;
  for (int k = 0; k < t->n_moves; k++) {
    acc += weight[k] / sum;
    c->cum_weight[k] = acc;
    c->step[k] = step[k];
    c->target[k] = target[k];
    c->step_max[k] = t->step_max(sys->state, k);
  }
  c->cum_weight[t->n_moves - 1] = 1.0;
  return c;
nomem:
  lw_chain_free(c);
  lw_error_set(err, LW_ENOMEM, "out of memory for a chain");
  return NULL;
}

void lw_chain_free(lw_chain *c)
{
  if (!c) return;
  lw_domains_free(c->domains);
  if (c->prop) c->sys->type->proposal_free(c->prop);
  if (c->rng) gsl_rng_free(c->rng);
  free(c);
}

void lw_chain_set_rule(lw_chain *c, double (*accept)(double x))
{
  const double from = lw_chain_ceiling(c);
  c->accept = accept;
  for (int k = 0; k < c->n_moves; k++) c->target[k] *= lw_chain_ceiling(c) / from;
}

double lw_chain_ceiling(const lw_chain *c) { return c->accept ? c->accept(0.0) : 1.0; }

/* A step update once the window of a kind is full. */
static void tune_window(lw_chain *c, int kind)
{
  if (c->win_prop[kind] < LW_TUNE_WINDOW) return;
  if (c->step_max[kind] <= 0.0) { /* a kind without a step: only the window restarts */
    c->win_prop[kind] = c->win_acc[kind] = 0;
    return;
  }
  double rate = (double)c->win_acc[kind] / (double)c->win_prop[kind];
  /* multiplicative update: a step that accepts too often grows, one that
  ** rarely accepts shrinks; the factor is bounded by e^{+-1} per window and
  ** vanishes at the target, so steps settle there */
  double s = c->step[kind] * exp(rate - c->target[kind]);
  c->step[kind] = fmin(s, c->step_max[kind]);
  if (c->step[kind] < 1e-300) c->step[kind] = 1e-300;
  c->win_prop[kind] = c->win_acc[kind] = 0;
}

static void tune(lw_chain *c, int kind, int accepted)
{
  c->win_prop[kind]++;
  c->win_acc[kind] += (unsigned long)accepted;
  tune_window(c, kind);
}

/* Whether a uniform u drawn from rng is below e^x (x < 0): Metropolis's
** draw.  Below -745, where e^x is at most the least subnormal, the move is
** lost without a draw (the stream stays where it was), in all three places
** alike. */
static int below_exp(gsl_rng *rng, double x) { return x > -745.0 && gsl_rng_uniform(rng) < exp(x); }

/* The Metropolis decision on an evaluated proposal, its commit and the
** counts. */
static int decide(lw_chain *c, int kind, double dE, int forbidden)
{
  /* no part free to make the move: no proposal (once counted as proposed
  ** and accepted, a death among pinned particles read an acceptance of 1
  ** and fed the step tuning) */
  if (forbidden == LW_PROPOSE_NOTHING) return 0;
  if (forbidden == LW_PROPOSE_NOMEM) return -1; /* (as a commit that ran out of memory) */
  int accept;
  const double lr = c->sys->type->log_ratio ? c->sys->type->log_ratio(c->prop) : 0.0;
  lw_move_stats *s = &c->stats[kind];
  s->proposed++;
  if (isnan(dE)) {
    s->nan++;
    accept = 0;
  } else if (forbidden == LW_PROPOSE_OUTSIDE) {
    s->outside++;
    accept = 0;
  } else if (forbidden == LW_PROPOSE_CROWDED) {
    s->crowded++;
    accept = 0;
  } else if (forbidden) {
    s->irregular++;
    accept = 0;
  } else if (c->accept) {
    /* the driver's own rule (driver.h): one draw a decision at T > 0 */
    if (isnan(lr) || lr == -INFINITY || dE == INFINITY) accept = 0;
    else if (c->temperature > 0.0) accept = gsl_rng_uniform(c->rng) < c->accept(lr - dE / c->temperature);
    else accept = dE < 0.0 || (dE == 0.0 && lr >= 0.0);
  } else if (lr != 0.0) {
    /* Metropolis-Hastings in logs, so that no ratio of densities over- or
    ** underflows: accept if log u < lr - dE / T (docs/NUMERICS.md) */
    if (isnan(lr) || lr == -INFINITY || dE == INFINITY) accept = 0;
    else if (c->temperature > 0.0) {
      double x = lr - dE / c->temperature;
      accept = x >= 0.0 || below_exp(c->rng, x);
    } else {
      accept = dE < 0.0 || (dE == 0.0 && lr > 0.0);
    }
  } else if (dE <= 0.0) {
    accept = 1;
  } else if (c->temperature > 0.0 && dE < INFINITY) {
    accept = below_exp(c->rng, -dE / c->temperature);
  } else {
    accept = 0;
  }
  const lw_system_type *t = c->sys->type;
  if (accept && t->finish) {
    /* the second stage of delayed acceptance (system.h): the part of dE
    ** the first one saw only a stand-in for */
    int nomem = 0;
    const double d2 = t->finish(c->sys->state, c->prop, &nomem);
    if (nomem) return -1;
    if (isnan(d2)) {
      s->nan++;
      accept = 0;
    } else if (d2 == INFINITY) {
      s->crowded++; /* a constraint the row checks only here (system.h) */
      accept = 0;
    } else if (d2 > 0.0) {
      accept = below_exp(c->rng, -d2 / c->temperature); /* (defer is off at T = 0) */
    }
  }
  if (accept) {
    if ((c->part ? t->commit_part : t->commit)(c->sys->state, c->prop) != LW_OK) accept = -1;
    else s->accepted++;
  }
  if (c->tuning && accept >= 0) tune(c, kind, accept);
  return accept;
}

/* Delayed acceptance (system.h) where there is a temperature: at T = 0 the
** chain decides on the sign of the whole dE. */
static void stage(lw_chain *c)
{
  /* (the second stage is Metropolis's: not under another rule) */
  if (c->sys->type->defer) c->sys->type->defer(c->prop, c->delayed && !c->accept && c->temperature > 0.0);
}

int lw_chain_step(lw_chain *c, int kind)
{
  const lw_system_type *t = c->sys->type;
  void *state = c->sys->state;
  if (t->sweep_size(state) == 0) return 0;
  int forbidden = 0;
  stage(c);
  double dE = t->propose(state, c->prop, kind, c->step[kind], c->rng, &forbidden);
  return decide(c, kind, dE, forbidden);
}

int lw_chain_step_at(lw_chain *c, int kind, size_t site)
{
  const lw_system_type *t = c->sys->type;
  if (!t->propose_at) return lw_chain_step(c, kind);
  int forbidden = 0;
  stage(c);
  double dE = t->propose_at(c->sys->state, c->prop, kind, site, c->step[kind], c->rng, &forbidden);
  return decide(c, kind, dE, forbidden);
}

/* The kind whose slice of the cumulative mix holds u in [0, 1). */
static int kind_at(const lw_chain *c, double u)
{
  int kind = 0;
  while (kind < c->n_moves - 1 && u >= c->cum_weight[kind]) kind++;
  return kind;
}

static int draw_kind(lw_chain *c) { return kind_at(c, gsl_rng_uniform(c->rng)); }

int lw_chain_visit_in(lw_chain *c, size_t site, const double box[4])
{
  int kind = draw_kind(c), forbidden = 0;
  stage(c);
  double dE = c->sys->type->propose_in(c->sys->state, c->prop, kind, site, c->step[kind], c->rng, &forbidden, box);
  return decide(c, kind, dE, forbidden);
}

void lw_chain_absorb(lw_chain *c, lw_chain *from)
{
  for (int k = 0; k < c->n_moves; k++) {
    lw_move_stats *a = &c->stats[k], *b = &from->stats[k];
    a->proposed += b->proposed;
    a->accepted += b->accepted;
    a->nan += b->nan;
    a->irregular += b->irregular;
    a->crowded += b->crowded;
    a->outside += b->outside;
    if (c->tuning) {
      c->win_prop[k] += b->proposed - b->outside;
      c->win_acc[k] += b->accepted;
    }
    *b = (lw_move_stats){0};
  }
}

void lw_chain_tune(lw_chain *c)
{
  for (int k = 0; c->tuning && k < c->n_moves; k++) tune_window(c, k);
}

/*
** The kinds a domain cannot run (system.h, n_domain_moves), after a domain
** sweep's phases: serially, from the chain's stream, their share of the mix
** of sweep_size proposals, a count that the state does not change (the
** sweep stays a fixed product of kernels that each fix the target; a count
** that followed the state would observe the chain at times that depend on
** it, docs/NUMERICS.md, "Trans-dimensional moves with domains").
*/
static lw_status global_moves(lw_chain *c)
{
  const lw_system_type *t = c->sys->type;
  const int first = t->n_domain_moves;
  if (first <= 0 || first >= c->n_moves) return LW_OK;
  const double lo = c->cum_weight[first - 1];
  const size_t n = (size_t)llround((1.0 - lo) * (double)t->sweep_size(c->sys->state));
  for (size_t k = 0; k < n; k++)
    if (lw_chain_step(c, kind_at(c, lo + (1.0 - lo) * gsl_rng_uniform(c->rng))) < 0) return LW_ENOMEM;
  return LW_OK;
}

lw_status lw_chain_sweep(lw_chain *c)
{
  const lw_system_type *t = c->sys->type;
  size_t n = t->sweep_size(c->sys->state);
  if (c->domains) {
    lw_status st = lw_domains_sweep(c->domains, c);
    if (st == LW_OK) st = global_moves(c);
    if (st != LW_OK) return st;
  } else if (!t->propose_at) {
    for (size_t k = 0; k < n; k++)
      if (lw_chain_step(c, draw_kind(c)) < 0) return LW_ENOMEM;
  } else if (n > 0) {
    /* Sites in order, so that consecutive proposals share cache lines and
    ** grid cells; the direction is drawn per sweep so that the sweep as a
    ** whole is reversible (docs/NUMERICS.md, "Sweep order"). */
    int backward = gsl_rng_uniform(c->rng) < 0.5;
    for (size_t k = 0; k < n; k++) {
      size_t site = backward ? n - 1 - k : k;
      if (lw_chain_step_at(c, draw_kind(c), site) < 0) return LW_ENOMEM;
    }
  }
  return t->sweep_end ? t->sweep_end(c->sys->state) : LW_OK;
}

gsl_rng *lw_rng_new(void)
{
  lw_gsl_off();
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  lw_gsl_on();
  return r;
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
  /* (on the stack: a failed malloc read as a damaged state; mt19937 holds 5000 bytes) */
  unsigned char copy[8192], *b = gsl_rng_state(r);
  size_t n = gsl_rng_size(r);
  if (n > sizeof copy || strspn(hex, "0123456789abcdef") != 2 * n || hex[2 * n]) return 0;
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
  return ok;
}
