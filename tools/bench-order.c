/*
** bench-order.c -- the pen-up path ordering of large drawings (make bench,
** section "order"): greedy and 2-opt with Or-opt (order.h) on 10^4 and
** 10^5 paths at a drawing's density and on a dense A4 page.
*/
#include <gsl/gsl_math.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdlib.h>
#include <time.h>

#include "benchutil.h"
#include "linewise/order.h"

static double cpu_seconds(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* One kind of drawing: n paths of lmin to lmax mm in random directions,
** uniform on a w x h mm page (w = 0: a square of `area` mm^2 a path). */
typedef struct {
  const char *name;
  size_t n;
  double w, h, area, lmin, lmax;
} instance;

static lw_order_path *paths(const instance *in)
{
  gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
  gsl_rng_set(r, 7);
  lw_order_path *p = malloc(in->n * sizeof *p);
  if (!r || !p) bench_die("order", &(lw_error){.code = LW_ENOMEM, .msg = "out of memory"});
  double side = sqrt(in->area * (double)in->n), w = in->w > 0 ? in->w : side, h = in->w > 0 ? in->h : side;
  for (size_t i = 0; i < in->n; i++) {
    double x = w * gsl_rng_uniform(r), y = h * gsl_rng_uniform(r);
    double a = 2 * M_PI * gsl_rng_uniform(r), l = in->lmin + (in->lmax - in->lmin) * gsl_rng_uniform(r);
    p[i] = (lw_order_path){x, y, x + l * cos(a), y + l * sin(a)};
  }
  gsl_rng_free(r);
  return p;
}

/* Drawing density (the 10^5-spline scenes put one spline on 8 to 10 mm^2),
** and the dense page of docs/FORMATS.md: 10^5 paths of 5 mm on A4, lines
** 0.12 mm apart, where 2-opt makes many long reversals. */
static const instance kinds[] = {
  {"drawing, 9 mm^2 a path", 10000, 0, 0, 9.0, 0.5, 4.5},
  {"drawing, 9 mm^2 a path", 100000, 0, 0, 9.0, 0.5, 4.5},
  {"A4, 5 mm paths", 100000, 210, 297, 0, 5.0, 5.0},
};

void bench_order(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_PERFORMANCE];
  const int n_kinds = b->quick ? 1 : (int)(sizeof kinds / sizeof *kinds), reps = b->quick ? 1 : 5;
  fprintf(d, "## Path ordering\n\n"
             "Random paths in random directions, home at a corner: at a drawing's density (0.5 to 4.5 mm\n"
             "long on a square page, 9 mm^2 a path) and on the dense A4 page of docs/FORMATS.md (5 mm\n"
             "long, lines 0.12 mm apart). The greedy tour, then lw_order_2opt (2-opt and Or-opt moves,\n"
             "order.h) within its counted budget. Times are medians of %d runs, in thread CPU time\n"
             "(what a quiet machine's wall clock shows) and in wall time on the machine as it was\n"
             "(its load is in the note under Scaling, or at the top). 2-opt's time includes its\n"
             "candidate lists. Travel: the pen-up travel in index order, after greedy and after 2-opt.\n\n"
             "| paths | page | greedy s (CPU) | 2-opt s (CPU) | 2-opt s (wall) | travel in index order, m | "
             "greedy, m | 2-opt, m |\n|---|---|---|---|---|---|---|---|\n",
          reps);
  for (int i = 0; i < n_kinds; i++) {
    size_t n = kinds[i].n;
    lw_order_path *p = paths(&kinds[i]);
    size_t *order = malloc(n * sizeof *order);
    unsigned char *rev = malloc(n);
    if (!order || !rev) bench_die("order", &(lw_error){.code = LW_ENOMEM, .msg = "out of memory"});
    double tg[BENCH_MAX_REPS], to[BENCH_MAX_REPS], tw[BENCH_MAX_REPS], greedy = 0, after = 0;
    lw_error err;
    bench_note("order: %zu paths, %s", n, kinds[i].name);
    for (int k = 0; k < reps; k++) {
      /* (the travel between them is neither's time) */
      double c0 = cpu_seconds();
      if (lw_order_greedy(p, n, 0, 0, order, rev, &err)) bench_die("order", &err);
      tg[k] = cpu_seconds() - c0;
      greedy = lw_order_travel(p, n, order, rev, 0, 0);
      double c1 = cpu_seconds(), w1 = bench_now();
      if (lw_order_2opt(p, n, 0, 0, order, rev, &err)) bench_die("order", &err);
      to[k] = cpu_seconds() - c1;
      tw[k] = bench_now() - w1;
      after = lw_order_travel(p, n, order, rev, 0, 0);
    }
    fprintf(d, "| %zu | %s | %.3f | %.3f | %.3f | %.1f | %.1f | %.1f |\n", n, kinds[i].name, bench_median(tg, reps),
            bench_median(to, reps), bench_median(tw, reps), 1e-3 * lw_order_travel(p, n, NULL, NULL, 0, 0),
            1e-3 * greedy, 1e-3 * after);
    free(order);
    free(rev);
    free(p);
  }
  fprintf(d, "\n"
             "2-opt and Or-opt keep the tour in a two-level list (blocks of about sqrt(n) paths, each\n"
             "read forwards or backwards): a reversal splits at most two blocks and reverses the run of\n"
             "blocks between, O(sqrt n) entries; an Or-opt move is three reversals at most. On the\n"
             "dense page 43,000 2-opt and 840 Or-opt moves (45,000 reversals, 233 fresh lay-outs of the\n"
             "list) count 1.0 x 10^8 steps of work, a tenth of the budget of LW_ORDER_WORK per path.\n"
             "Before, the tour was an array, a reversal moved up to n / 2 entries, and 2-opt alone\n"
             "(no Or-opt) made 43,500 reversals there that moved 9.6 x 10^8 entries, just within the\n"
             "budget (10^9), in 2.9 to 3.5 s of CPU time at a load of 9 to 15 (0.67 s at a drawing's\n"
             "density; about 2.4 and 0.56 s on a quiet machine), for\n"
             "tours of 39.2 m on the dense page and 169.9 m at a drawing's density (10^5 paths, the\n"
             "instances of this table; 17.1 m at 10^4).\n\n");
}
