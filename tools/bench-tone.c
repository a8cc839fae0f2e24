/*
** bench-tone.c -- the tone term and the spacing constraint in make bench:
** what a proposal costs with them (PERFORMANCE.md) and how the tone
** term's value depends on the quadrature nodes it splats (ACCURACY.md).
** Both run on the annealed accuracy scene (bench_annealed: the example
** picture, 300 pixels of 0.45 mm across).
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "benchutil.h"
#include "linewise/model.h"
#include "linewise/spacing.h"

/* The accuracy scene's parameters with the tone term at coefficient T and
** blur sigma (T = 0: off), min_spacing as given. */
static lw_params tone_scene(bench_ctx *b, double T, double sigma, double spacing)
{
  bench_annealed(b);
  lw_params p = b->ann_params;
  p.tone = T;
  p.tone_blur = sigma;
  p.min_spacing = spacing;
  return p;
}

/* Times the rows' scenes interleaved (ratios to the first) and writes a table. */
typedef struct {
  const char *name;
  double T, sigma, spacing;
  int pair;
} tone_row;

/* Returns the picture's pixel, mm (0 without a tone row). */
static double tone_table(const bench_ctx *b, const tone_row *row, int n)
{
  FILE *d = b->doc[BENCH_PERFORMANCE];
  enum { MAXR = 8 };
  bench_run r[MAXR];
  for (int i = 0; i < n; i++) {
    lw_params p = tone_scene((bench_ctx *)b, row[i].T, row[i].sigma, row[i].spacing);
    if (!row[i].pair) p.pair = 0;
    lw_splines *sp = lw_splines_clone(b->ann_splines);
    if (!sp) bench_die("out of memory", NULL);
    bench_run_init(&r[i], &p, sp, 0.002, b->ann_step);
  }
  const double step[2] = {0.2, 0.2};
  const int nt = 4096;
  bench_trial *trials = bench_trials_new(r[0].model->sp, step, nt);
  double ev[MAXR], ratio[MAXR], spread[MAXR], ns[MAXR], unused[MAXR];
  bench_time_runs(b, r, n, 0, trials, nt, ev, ratio, spread);
  bench_time_runs(b, r, n, 0, NULL, 0, ns, unused, NULL);
  free(trials);
  fprintf(d, "| scene | footprint pixels | ns per evaluation | extra ns | ratio | ns per chain proposal | acceptance |\n"
             "|---|---|---|---|---|---|---|\n");
  for (int i = 0; i < n; i++) {
    char fp[64] = "-", extra[32] = "-";
    int side = 2 * r[i].scene.tone.radius + 1;
    if (row[i].T > 0) snprintf(fp, sizeof fp, "%d x %d of %.2f mm", side, side, r[i].scene.tone.pixel);
    if (i) snprintf(extra, sizeof extra, "%.0f", ev[i] - ev[0]);
    fprintf(d, "| %s | %s | %.0f | %s | %.3f +- %.3f | %.0f | %.2f |\n", row[i].name, fp, ev[i], extra, ratio[i],
            spread[i], ns[i], bench_run_acceptance(&r[i]));
  }
  fprintf(d, "\n");
  double pixel = 0.0;
  for (int i = 0; i < n; i++) {
    if (row[i].T > 0) pixel = r[i].scene.image_place.pixel;
    bench_run_free(&r[i]);
  }
  return pixel;
}

void bench_tone(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_PERFORMANCE];
  bench_annealed(b);
  static const tone_row alone[] = {
      {"the scene's terms but pair, tone off", 0, 1, 0, 0},
      {"tone, blur 0.5 mm", 1, 0.5, 0, 0},
      {"tone, blur 1 mm", 1, 1, 0, 0},
      {"tone, blur 2 mm", 1, 2, 0, 0},
  };
  /* The off rows differ by noise alone: many short blocks, as in "What
  ** each term costs", follow the machine's load more finely. */
  static const tone_row off[] = {
      {"the scene's terms but pair, tone off", 0, 1, 0, 0},
      {"tone named with coefficient 0 (off)", 0, 2, 0, 0},
      {"tone off (again: the noise)", 0, 1, 0, 0},
  };
  static const tone_row spaced[] = {
      {"the scene's terms (pair cutoff 2 mm, near field)", 0, 1, 0, 1},
      {"and min_spacing 0.35 mm", 0, 1, 0.35, 1},
      {"and tone, blur 1 mm", 1, 1, 0, 1},
  };
  fprintf(d, "## The tone term and the spacing constraint\n\n"
             "The accuracy scene (params/study.ini annealed, %zu splines) with the tone term added\n"
             "(coefficient 1; docs/NUMERICS.md) at three blurs.\n"
             "Evaluation: the same point and vector moves of 0.2 mm, evaluated and never committed;\n"
             "ratio to the first row block by block (+- the median absolute deviation). Chain: the\n"
             "Metropolis walk at T = 0.002 with the anneal's final steps. First without the pair term,\n"
             "whose near field would hide the rest:\n\n",
          b->ann_splines->n_splines);
  bench_ctx fine = *b;
  fine.reps = BENCH_MAX_REPS;
  fine.block = b->block * b->reps / BENCH_MAX_REPS;
  double pixel = tone_table(b, alone, (int)(sizeof alone / sizeof alone[0]));
  fprintf(d, "The picture's pixel is %.2f mm; the raster's is k of them, the most within sigma / 1.5\n"
             "(docs/NUMERICS.md). A move splats the old and new samples of its segments (2 x 2 x %d\n"
             "for a point move) into a box of changes and sums the box: the cost grows with the\n"
             "footprint's area, (2 ceil(3 sigma / h) + 1)^2 pixels a sample for the raster's pixel h,\n"
             "as sigma^2 while h is the picture's pixel and no further (19 x 19 at most).\n"
             "Named with coefficient 0 the term builds nothing (no target, no\n"
             "raster, no box) and costs nothing: the scene without it, with it at coefficient 0, and\n"
             "without it again (the noise), in %d blocks of %.3f s:\n\n",
          pixel, b->ann_params.quadrature, fine.reps, fine.block);
  tone_table(&fine, off, (int)(sizeof off / sizeof off[0]));
  fprintf(d, "With the scene's pair term, and the spacing constraint (energy.min_spacing), which\n"
             "counts the neighbours closer than 0.35 mm in the pair grid's cells and asks the moves\n"
             "the Metropolis test takes what their curves touch (docs/NUMERICS.md, \"Spacing\"; the\n"
             "chain's second stage, so in the chain's column only):\n\n");
  tone_table(b, spaced, (int)(sizeof spaced / sizeof spaced[0]));
}

void bench_tone_accuracy(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_ACCURACY];
  static const int nodes[] = {4, 6, 8, 12, 16, 32};
  enum { N = sizeof nodes / sizeof nodes[0] };
  static const double sigmas[] = {0.5, 1.0, 2.0};
  enum { S = sizeof sigmas / sizeof sigmas[0] };
  double e[S][N];
  lw_error err;
  for (int k = 0; k < S; k++)
    for (int i = 0; i < N; i++) {
      lw_params p = tone_scene(b, 1.0, sigmas[k], 0.0);
      p.tone_quadrature = nodes[i];
      lw_scene sc;
      if (lw_scene_init(&sc, &p, &err)) bench_die("tone accuracy", &err);
      double term[LW_TERM_COUNT];
      lw_energy_compute(&sc, b->ann_splines, term, &err);
      e[k][i] = term[LW_TERM_TONE];
      lw_scene_clear(&sc);
    }
  double share;
  if (lw_close_share_splines(b->ann_splines, b->ann_params.pen_width, &share, &err)) bench_die("close share", &err);
  fprintf(d, "## Tone term: quadrature nodes\n\n"
             "The tone term splats each quadrature sample as a Gaussian footprint (tone.h), so its\n"
             "value depends on how finely the samples cover the line: a sample stands for dl of ink\n"
             "at one point. The annealed accuracy scene's tone energy at each node count\n"
             "(`energy.tone_quadrature`), against 32 nodes (segments of %.0f mm, blur sigma as given;\n"
             "the picture's pixel is 0.45 mm, the\n"
             "raster's the same but at sigma 2 mm, where it is two of them):\n\n"
             "| nodes | sample spacing mm |",
          b->ann_params.segment_length);
  for (int k = 0; k < S; k++) fprintf(d, " error, sigma %g mm |", sigmas[k]);
  fprintf(d, "\n|---|---|");
  for (int k = 0; k < S; k++) fprintf(d, "---|");
  fprintf(d, "\n");
  for (int i = 0; i < N; i++) {
    fprintf(d, "| %d | %.2f |", nodes[i], b->ann_params.segment_length / nodes[i]);
    for (int k = 0; k < S; k++) fprintf(d, " %.2e |", fabs(e[k][i] - e[k][N - 1]) / e[k][N - 1]);
    fprintf(d, "\n");
  }
  fprintf(d, "\nThe error is small once the samples are closer than about the blur: a footprint wider\n"
             "than the gaps between samples sees a line, not a row of dots. Keep\n"
             "segment_length / tone_quadrature below tone_blur; the tone's cost a proposal grows with\n"
             "its nodes, and the other terms keep theirs (`quadrature`). Below about 1e-7 the errors\n"
             "stop falling:\n"
             "the fixed-point raster rounds each footprint value to 2^-32 of full ink, some 1e-9 of\n"
             "a pixel's value summed over its footprints, 1e-8 to 1e-7 of (B - D). The annealed scene's\n"
             "close share (the share of its line length within one pen width, %.2f mm, of another\n"
             "stroke; summary.json's close_share) is %.3f.\n\n",
          b->ann_params.pen_width, share);
}
