/*
** domains.c -- checkerboard domain decomposition of a sweep (domains.h).
*/
#include "linewise/domains.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* the fuzz build compiles without OpenMP: the pragmas drop out, and so must the calls */
#ifdef _OPENMP
#include <omp.h>
#endif

#define DOMAINS_MAX 64 /* per side: 4225 cells, each with a stream and a scratch, are plenty */

void lw_domains_free(lw_domains *d)
{
  if (!d) return;
  for (int k = 0; d->cell && k < d->n; k++) lw_chain_free(d->cell[k]);
  free(d->cell);
  free(d->cell_of);
  free(d->site);
  free(d->start);
  free(d->active);
  free(d->seed);
  free(d->cell_cpu);
  free(d);
}

/* A chain like c for one cell: the same system, mix and targets, its own
** scratch and stream, committing into the scratch; never tuning itself
** (its statistics fill c's windows, lw_chain_absorb). */
static lw_chain *cell_chain(const lw_chain *c, lw_error *err)
{
  lw_chain *dc = calloc(1, sizeof *dc);
  if (!dc) return NULL;
  *dc = *c;
  dc->domains = NULL;
  dc->prop = NULL;
  dc->rng = NULL;
  dc->part = 1;
  dc->tuning = 0;
  memset(dc->stats, 0, sizeof dc->stats);
  memset(dc->win_prop, 0, sizeof dc->win_prop);
  memset(dc->win_acc, 0, sizeof dc->win_acc);
  /* only the kinds a domain can run, in their proportions (system.h;
  ** lw_domains_attach checks that their share is not 0) */
  const int nd = c->sys->type->n_domain_moves;
  if (nd > 0 && nd < c->n_moves)
    for (int k = 0; k < c->n_moves; k++)
      dc->cum_weight[k] = k < nd - 1 ? c->cum_weight[k] / c->cum_weight[nd - 1] : 1.0;
  dc->prop = c->sys->type->proposal_new(c->sys->state, err);
  dc->rng = lw_rng_new();
  if (!dc->prop || !dc->rng) {
    lw_chain_free(dc);
    return NULL;
  }
  return dc;
}

/* The share of the moves' groups (0 .. 1) whose boxes fall inside one
** domain of nx x ny over w x h: a group moves in a sweep only then. */
static double moved_share(const lw_chain *c, double w, double h, int nx, int ny)
{
  const lw_system_type *t = c->sys->type;
  double moved = 0.0;
  size_t groups = 0, n = t->sites ? t->sites(c->sys->state) : t->sweep_size(c->sys->state);
  for (size_t site = 0, k; site < n; site += k ? k : 1, groups++) {
    double box[4];
    k = t->group(c->sys->state, site, box);
    moved += fmax(0.0, 1.0 - (box[2] - box[0]) * nx / w) * fmax(0.0, 1.0 - (box[3] - box[1]) * ny / h);
  }
  return groups ? moved / (double)groups : 1.0;
}

static lw_status bad_key(const lw_params *p, lw_error *err, const char *fmt, const char *what)
{
  lw_error_set(err, LW_EINPUT, fmt, p->domains, what);
  return lw_params_blame(p, "anneal", "domains", err);
}

lw_status lw_domains_attach(lw_chain *c, const lw_params *p, int replicas, lw_error *err)
{
  const lw_system_type *t = c->sys->type;
  if (!strcmp(p->domains, "off")) return LW_OK;
  long side = 0;
  int is_auto = !strcmp(p->domains, "auto");
  if (!is_auto) {
    char *end;
    errno = 0;
    side = strtol(p->domains, &end, 10);
    if (errno || end == p->domains || *end || side < 1 || side > DOMAINS_MAX)
      return bad_key(p, err, "'%s': expected off, auto or a count of domains per side from 1 to 64%s", "");
  }
  if (!t->split || !t->group || !t->propose_in || !t->commit_part || !t->merge)
    return bad_key(p, err, "'%s': the system '%s' cannot split its sweeps into domains; expected off", t->name);
  /* every kind with weight runs serially (mc.h): nothing for the domains */
  if (t->n_domain_moves > 0 && t->n_domain_moves < c->n_moves && !(c->cum_weight[t->n_domain_moves - 1] > 0.0))
    return LW_OK;
  double page[4], reach;
  const char *why = t->split(c->sys->state, page, &reach);
  if (why) return bad_key(p, err, "'%s': this scene cannot be split into domains (%s); expected off", why);
  double w = page[2] - page[0], h = page[3] - page[1];
  int nx, ny;
  if (is_auto) {
    /* Wider than twice the reach with room to spare, and wide against a
    ** spline, so few sit on a boundary (those are not moved that sweep);
    ** from the parameters alone, so a resumed run splits the same way. */
    double l = fmax(2.5 * reach, t->domain_side ? t->domain_side(c->sys->state)
                                                : 16.0 * p->segments * p->segment_length);
    nx = (int)fmin(floor(w / l), DOMAINS_MAX);
    ny = (int)fmin(floor(h / l), DOMAINS_MAX);
    if (nx < 2 || ny < 2) return LW_OK; /* nothing to gain: sweeps stay serial */
  } else {
    nx = ny = (int)side;
    /* a count the photo preset chose from the page alone (the key unset:
    ** line 0) gives way to the reach as auto does: a picture of a few
    ** pixels has tone footprints centimetres wide.  A run of the preset
    ** resumed does too: runs before 2026-12-05 wrote the page's count into
    ** scene.ini, not the one they took (later ones write the one taken,
    ** which fits) */
    const int chosen = !lw_params_line(p, "anneal", "domains") ||
                       (p->of_run && p->preset == LW_PRESET_PHOTO);
    if (chosen) {
      while (nx > 1 && !(w / nx > 2.0 * reach && h / ny > 2.0 * reach)) nx = ny = nx - 1;
      if (nx < 2) return LW_OK;
    }
    if (!(w / nx > 2.0 * reach) || !(h / ny > 2.0 * reach)) {
      /* in the system's lengths: mm for curves, the scene's unit for particles */
      char what[160];
      snprintf(what, sizeof what, " (domains %.4g x %.4g against a reach of %.4g, in the scene's lengths)", w / nx,
               h / ny, reach);
      return bad_key(p, err,
                     "'%s': domains must be wider than twice the reach of a move%s; expected fewer, or auto, "
                     "which picks a count that fits",
                     what);
    }
    /* A group moves in a sweep only where its box falls inside one domain
    ** (the grid lies anew each sweep): with boxes near a domain's size most
    ** would never move, and the run would end near where it began.  Below a
    ** quarter a sweep, refused (the photo preset's A4 page at 8 domains moves
    ** 48 %, and draws as well as unsplit: docs/SCALING.md). */
    /* judged on the state a run begins with: a resumed one was accepted then,
    ** and its splines may have grown since (a run refused at its resume);
    ** the preset's count gives way here too (its A4 page of 40 mm strokes
    ** was refused, blaming a key the user never set) */
    double share = p->of_run ? 1.0 : moved_share(c, w, h, nx, ny);
    while (chosen && nx > 1 && share < 0.25) {
      nx = ny = nx - 1;
      share = moved_share(c, w, h, nx, ny);
    }
    if (chosen && nx < 2) return LW_OK;
    if (share < 0.25) {
      char what[200];
      snprintf(what, sizeof what, " (domains %.4g x %.4g in the scene's lengths: %.0f %% of the moves' groups a "
               "sweep, a spline as wide as a domain never)", w / nx, h / ny, 100.0 * share);
      return bad_key(p, err, "'%s': domains this small leave most of the state unmoved%s; expected fewer, or auto",
                     what);
    }
  }
  lw_domains *d = calloc(1, sizeof *d);
  if (!d) goto nomem;
  d->nx = nx;
  d->ny = ny;
  d->n = (nx + 1) * (ny + 1);
  memcpy(d->page, page, sizeof page);
  d->lx = w / nx;
  d->ly = h / ny;
  d->reach = reach;
  /* threads go to the replicas first (anneal.c), the rest to each one's cells */
#ifdef _OPENMP
  d->threads = omp_get_max_threads() / (replicas > 0 ? replicas : 1);
  if (d->threads < 1) d->threads = 1;
  if (replicas > 1 && d->threads > 1 && omp_get_max_active_levels() < 2) omp_set_max_active_levels(2);
#else
  d->threads = 1;
#endif
  d->cell = calloc((size_t)d->n, sizeof *d->cell);
  d->start = calloc((size_t)d->n + 1, sizeof *d->start);
  d->active = calloc((size_t)d->n, sizeof *d->active);
  d->seed = calloc((size_t)d->n, sizeof *d->seed);
  if (!d->cell || !d->start || !d->active || !d->seed) goto nomem;
  d->min_parallel = LW_DOMAINS_MIN_PARALLEL;
  for (int k = 0; k < d->n; k++)
    if (!(d->cell[k] = cell_chain(c, err))) goto nomem;
  c->domains = d;
  return LW_OK;
nomem:
  lw_domains_free(d);
  return lw_error_set(err, LW_ENOMEM, "out of memory for %d domains", (nx + 1) * (ny + 1));
}

/* The cell along one axis holding coordinate v for the lattice shifted by o:
** 0 below lo + o, n from lo + o + (n - 1) l on. */
static int axis_cell(double v, double lo, double o, double l, int n)
{
  double u = floor((v - lo - o) / l) + 1.0;
  if (!(u > 0.0)) return 0;
  return u >= (double)n ? n : (int)u;
}

static void axis_bounds(int i, double lo, double o, double l, int n, double *a, double *b)
{
  *a = i == 0 ? -INFINITY : lo + o + (i - 1) * l;
  *b = i == n ? INFINITY : lo + o + i * l;
}

static void cell_box(const lw_domains *d, int k, double ox, double oy, double box[4])
{
  int i = k % (d->nx + 1), j = k / (d->nx + 1);
  axis_bounds(i, d->page[0], ox, d->lx, d->nx, &box[0], &box[2]);
  axis_bounds(j, d->page[1], oy, d->ly, d->ny, &box[1], &box[3]);
}

/* The cell whose box holds b, or UINT32_MAX (on a boundary, or NaN). */
static uint32_t cell_holding(const lw_domains *d, const double b[4], double ox, double oy)
{
  int i = axis_cell(b[0], d->page[0], ox, d->lx, d->nx), j = axis_cell(b[1], d->page[1], oy, d->ly, d->ny);
  int k = j * (d->nx + 1) + i;
  double box[4];
  cell_box(d, k, ox, oy, box);
  /* the test propose_in makes: a group held here stays held by its moves */
  if (!(b[0] >= box[0] && b[1] >= box[1] && b[2] <= box[2] && b[3] <= box[3])) return UINT32_MAX;
  return (uint32_t)k;
}

/* Sorts the sites into their cells, storage order kept within each. */
static lw_status assign(lw_domains *d, const lw_chain *c, size_t n, double ox, double oy)
{
  const lw_system_type *t = c->sys->type;
  const void *state = c->sys->state;
  if (n > d->cap) {
    uint32_t *co = realloc(d->cell_of, n * sizeof *co);
    if (co) d->cell_of = co;
    size_t *st = realloc(d->site, n * sizeof *st);
    if (st) d->site = st;
    if (!co || !st) return LW_ENOMEM;
    d->cap = n;
  }
  memset(d->start, 0, ((size_t)d->n + 1) * sizeof *d->start);
  for (size_t s = 0; s < n;) {
    double b[4];
    size_t g = t->group(state, s, b);
    if (g == 0 || g > n - s) g = n - s; /* a row's bug must not hang the sweep */
    uint32_t k = cell_holding(d, b, ox, oy);
    for (size_t q = 0; q < g; q++) d->cell_of[s + q] = k;
    if (k != UINT32_MAX) d->start[k + 1] += g;
    else d->frozen += g;
    s += g;
  }
  for (int k = 0; k < d->n; k++) d->start[k + 1] += d->start[k];
  /* start[k] is cell k's next free slot while filling, then restored */
  for (size_t s = 0; s < n; s++)
    if (d->cell_of[s] != UINT32_MAX) d->site[d->start[d->cell_of[s]]++] = s;
  for (int k = d->n; k > 0; k--) d->start[k] = d->start[k - 1];
  d->start[0] = 0;
  d->visits += n;
  return LW_OK;
}

/* This thread's CPU seconds (the profile: preemption does not count). */
static double cpu_now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* One cell's sites through its chain; 0, or -1 when a commit ran out of memory. */
static int sweep_cell(const lw_domains *d, int k, int backward, double ox, double oy)
{
  const double t0 = d->cell_cpu ? cpu_now() : 0.0;
  lw_chain *dc = d->cell[k];
  /* seeded here, by whichever thread runs the cell: only cells with sites
  ** pay for it */
  gsl_rng_set(dc->rng, d->seed[k]);
  double box[4];
  cell_box(d, k, ox, oy, box);
  const size_t s0 = d->start[k], s1 = d->start[k + 1];
  for (size_t q = 0; q < s1 - s0; q++)
    if (lw_chain_visit_in(dc, d->site[backward ? s1 - 1 - q : s0 + q], box) < 0) return -1;
  if (d->cell_cpu) d->cell_cpu[k] = cpu_now() - t0;
  return 0;
}

lw_status lw_domains_sweep(lw_domains *d, lw_chain *c)
{
  const lw_system_type *t = c->sys->type;
  void *state = c->sys->state;
  size_t n = t->sites ? t->sites(state) : t->sweep_size(state);
  if (n == 0) return LW_OK;
  double t0 = d->cell_cpu ? cpu_now() : 0.0;
  if (d->cell_cpu) memset(d->cell_cpu, 0, (size_t)d->n * sizeof *d->cell_cpu);
  d->serial_cpu = 0.0;
  /* Everything random about the sweep's plan comes from the chain's
  ** stream, in this order; each cell's moves from its own stream. */
  double ox = gsl_rng_uniform(c->rng) * d->lx, oy = gsl_rng_uniform(c->rng) * d->ly;
  int backward = gsl_rng_uniform(c->rng) < 0.5;
  for (int k = 0; k < d->n; k++) {
    lw_chain *dc = d->cell[k];
    d->seed[k] = gsl_rng_get(c->rng);
    /* tempering swaps systems between chains and the run loop sets the
    ** temperature: the cells follow their chain */
    dc->sys = c->sys;
    dc->temperature = c->temperature;
  }
  if (assign(d, c, n, ox, oy) != LW_OK) return LW_ENOMEM;
  lw_status st = LW_OK;
  for (int ph = 0; ph < 4 && st == LW_OK; ph++) {
    const int colour = backward ? 3 - ph : ph;
    int n_act = 0;
    for (int k = 0; k < d->n; k++) {
      int i = k % (d->nx + 1), j = k / (d->nx + 1);
      if ((i & 1) + 2 * (j & 1) == colour && d->start[k + 1] > d->start[k]) d->active[n_act++] = k;
    }
    /* the steps as tuned after the last phase: a window must see the step
    ** it tunes, or four updates a sweep on the same evidence overshoot */
    for (int a = 0; a < n_act; a++) memcpy(d->cell[d->active[a]]->step, c->step, sizeof c->step);
    if (d->cell_cpu) d->serial_cpu += cpu_now() - t0;
    int failed = 0;
    size_t work = 0;
    for (int a = 0; a < n_act; a++) work += d->start[d->active[a] + 1] - d->start[d->active[a]];
    (void)work; /* read only by the pragma, which a build without OpenMP drops */
    /* Cells of one phase touch disjoint data (domains.h): any thread may
    ** run any cell, in any order. */
#pragma omp parallel for schedule(dynamic, 1) reduction(| : failed) num_threads(d->threads) \
    if (n_act > 1 && d->threads > 1 && work >= d->min_parallel)
    for (int a = 0; a < n_act; a++)
      if (sweep_cell(d, d->active[a], backward, ox, oy) < 0) failed = 1;
    if (d->cell_cpu) t0 = cpu_now();
    /* in cell order, whatever ran where */
    for (int a = 0; a < n_act; a++) {
      lw_chain *dc = d->cell[d->active[a]];
      if (t->merge(state, dc->prop) != LW_OK) st = LW_ENOMEM;
      lw_chain_absorb(c, dc);
    }
    lw_chain_tune(c);
    if (failed) st = LW_ENOMEM;
  }
  if (d->cell_cpu) d->serial_cpu += cpu_now() - t0;
  return st;
}
