/*
** bench.c -- proposal throughput and memory of the annealer (make bench).
**
** Prints Markdown tables on stdout: proposals per second on one core with
** every term but pair, with the pair term at a density where each sample sees
** about 30 others within the cutoff (and 60), the cost per proposal from 10^3 to 10^5
** splines at constant density, and bytes of memory per segment.  Every figure
** is the median of several timed repetitions; ratios are taken within one run.
*/
#include <gsl/gsl_math.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "linewise/init.h"
#include "linewise/mc.h"

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

typedef struct {
  double ns_per_proposal;  /* median */
  double acceptance;
  double neighbours;       /* mean samples of other splines within the cutoff */
  double bytes_per_segment;
} result;

/* Samples of other splines within the cutoff, averaged over samples. */
static double mean_neighbours(const lw_model *m)
{
  if (!m->grid) return 0.0;
  const lw_cellgrid *g = m->grid;
  size_t n = g->n_samples, step = n > 20000 ? n / 20000 : 1, count = 0, seen = 0;
  double rc2 = m->scene->pair.cutoff * m->scene->pair.cutoff;
  for (size_t i = 0; i < n; i += step, seen++) {
    int cx, cy;
    lw_cellgrid_locate(g, m->ps[i].x, m->ps[i].y, &cx, &cy);
    for (int y = cy - 1; y <= cy + 1; y++)
      for (int x = cx - 1; x <= cx + 1; x++) {
        if (x < 0 || y < 0 || x >= g->nx || y >= g->ny) continue;
        const lw_cell *c = &g->cell[y * g->nx + x];
        for (uint32_t k = 0; k < c->n; k++) {
          const lw_pair_sample *o = &m->ps[c->idx[k]];
          double dx = o->x - m->ps[i].x, dy = o->y - m->ps[i].y;
          if (o->spline != m->ps[i].spline && dx * dx + dy * dy < rc2) count++;
        }
      }
  }
  return seen ? (double)count / (double)seen : 0.0;
}

static double model_bytes(const lw_model *m)
{
  const lw_splines *sp = m->sp;
  double b = sizeof *m + (double)sp->n_nodes * sizeof(lw_node) +
             (double)sp->n_splines * (2 * sizeof(size_t) + sizeof(double) + sizeof(double)) +
             (double)sp->n_segments * (sizeof(uint32_t) + sizeof(double) +
                                       (double)m->scene->n_local * sizeof(double));
  if (m->grid) {
    const lw_cellgrid *g = m->grid;
    b += (double)g->n_samples * sizeof(lw_pair_sample);
    for (int c = 0; c < g->nx * g->ny; c++) b += sizeof(lw_cell) + g->cell[c].cap * sizeof(uint32_t);
  }
  return b;
}

/* One scene of n splines at a fixed density; times `reps` blocks of
** proposals after tuning. */
static result measure(size_t n, int pair, double spacing, int reps)
{
  lw_params p;
  lw_params_defaults(&p);
  const int segs = 4;
  const double seg_len = 5.0, L = segs * seg_len;
  /* page area so that lines of length L sit about `spacing` apart */
  double side = sqrt((double)n * L * spacing);
  p.width = p.height = side + 2.0;
  p.margin = 1.0;
  p.strain = 10;
  p.bending = 1;
  p.potential_coef = 0.5;
  p.potential = LW_POT_RADIAL;
  p.field_coef = -0.5;
  p.field = LW_FLD_WAVES;
  p.boundary_coef = 0.1;
  if (pair) {
    p.pair = 0.01;
    p.pair_cutoff = 4;
  }
  lw_scene sc;
  lw_error err;
  if (lw_scene_init(&sc, &p, &err)) {
    fprintf(stderr, "bench: %s\n", err.msg);
    exit(1);
  }
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 1);
  lw_splines *sp = lw_init_random(&sc, n, segs, seg_len, r, &err);
  if (!sp) {
    fprintf(stderr, "bench: %s\n", err.msg);
    exit(1);
  }
  lw_model *m = lw_model_new(&sc, sp, &err);
  double w[LW_MOVE_KINDS] = {0.5, 0.5, 0, 0}, st[LW_MOVE_KINDS] = {0.2, 0.2, 0.2, 0.05},
         tg[LW_MOVE_KINDS] = {0.44, 0.44, 0.3, 0.3};
  lw_chain *c = lw_chain_new(m, w, st, tg, 2, &err);
  c->temperature = 0.05;
  c->tuning = 1;
  long per_rep = pair ? 20000 : 200000;
  for (long k = 0; k < per_rep; k++) lw_chain_step(c, (lw_move_kind)(k & 1));
  c->tuning = 0;
  double t[16];
  unsigned long a0 = c->stats[0].accepted + c->stats[1].accepted, p0 = c->stats[0].proposed + c->stats[1].proposed;
  for (int rep = 0; rep < reps; rep++) {
    double t0 = now();
    for (long k = 0; k < per_rep; k++) lw_chain_step(c, (lw_move_kind)(k & 1));
    t[rep] = (now() - t0) / (double)per_rep * 1e9;
  }
  qsort(t, (size_t)reps, sizeof t[0], cmp);
  result res;
  res.ns_per_proposal = t[reps / 2];
  res.acceptance = (double)(c->stats[0].accepted + c->stats[1].accepted - a0) /
                   (double)(c->stats[0].proposed + c->stats[1].proposed - p0);
  res.neighbours = mean_neighbours(m);
  res.bytes_per_segment = model_bytes(m) / (double)m->sp->n_segments;
  lw_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
  gsl_rng_free(r);
  return res;
}

int main(int argc, char **argv)
{
  int reps = argc > 1 ? atoi(argv[1]) : 5;
  if (reps < 1 || reps > 16) reps = 5;
  printf("Median of %d timed blocks of 200,000 proposals (20,000 with the pair term) of point\n"
         "and vector moves after as many tuning proposals, at T = 0.05, quadrature 8, one core.\n"
         "Splines of 4 segments of 5 mm placed at random at the stated mean spacing.\n\n", reps);

  printf("## Throughput\n\n| scene | splines | neighbours per sample | ns per proposal | proposals per second | acceptance |\n"
         "|---|---|---|---|---|---|\n");
  result a = measure(1000, 0, 2.0, reps);
  printf("| every term but pair | 1000 | - | %.0f | %.0f | %.2f |\n", a.ns_per_proposal, 1e9 / a.ns_per_proposal,
         a.acceptance);
  /* spacing 2.8 mm gives the ~30 neighbours the aim is stated for; 1.4 mm twice that */
  const double spacings[2] = {2.8, 1.4};
  for (int i = 0; i < 2; i++) {
    result b = measure(1000, 1, spacings[i], reps);
    printf("| every term, pair cutoff 4 mm, lines %.1f mm apart | 1000 | %.1f | %.0f | %.0f | %.2f |\n", spacings[i],
           b.neighbours, b.ns_per_proposal, 1e9 / b.ns_per_proposal, b.acceptance);
  }

  printf("\n## Scaling at constant density (every term, pair cutoff 4 mm, lines 2.8 mm apart)\n\n"
         "| splines | segments | ns per proposal | ratio to 1000 | bytes per segment |\n|---|---|---|---|---|\n");
  double base = 0;
  size_t sizes[3] = {1000, 10000, 100000};
  for (int i = 0; i < 3; i++) {
    result s = measure(sizes[i], 1, 2.8, reps);
    if (i == 0) base = s.ns_per_proposal;
    printf("| %zu | %zu | %.0f | %.2f | %.0f |\n", sizes[i], sizes[i] * 4, s.ns_per_proposal, s.ns_per_proposal / base,
           s.bytes_per_segment);
  }
  return 0;
}
