/*
** bench-photo.c -- what a camera's picture costs before and after the anneal
** (section "photo", docs/PERFORMANCE.md): set-up (decoding, downsampling to
** the pixel budget, the blurs, the edge tangent flow, the tone target) and
** output (the files and the fidelity scores, one per pen and one for the
** drawing), end to end from the command line as a user runs it.
**
** The bundled picture (tools/make-picture.c) at 600 x 800 pixels and five
** times larger a side, 3000 x 4000 (a camera's 12 megapixels), and
** bin/linewise draws each with params/photo.ini for one sweep, in one pen
** and in four (CMYK).  One sweep on A4 is about a
** three-hundredth of the preset's anneal, so the wall time is set-up and
** output.  All four runs alternate, b->reps times; the medians.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <unistd.h>

#include "benchutil.h"

enum { PHOTO_SIZES = 2, PHOTO_PENS = 2 };

/* The program and the picture maker (LW_BIN, LW_MAKE_PICTURE, or the
** build's), in *bin and *maker; 0, with a line in d saying so, where they or
** params/photo.ini are missing. */
static int photo_tools(FILE *d, const char **bin, const char **maker)
{
  *bin = getenv("LW_BIN");
  *maker = getenv("LW_MAKE_PICTURE");
  if (!*bin || !**bin) *bin = "bin/linewise";
  if (!*maker || !**maker) *maker = "build/make-picture";
  if (!access(*bin, X_OK) && !access(*maker, X_OK) && !access("params/photo.ini", R_OK)) return 1;
  fprintf(d, "Not measured: no %s, %s or params/photo.ini (make bench runs it from the repository root).\n\n", *bin,
          *maker);
  return 0;
}

/* The bundled picture scale times larger a side, as datadir/photo-<scale>.png, in pic. */
static void photo_picture(const bench_ctx *b, const char *maker, int scale, char *pic, size_t n)
{
  char cmd[2048];
  snprintf(pic, n, "%s/photo-%d.png", b->datadir, scale);
  snprintf(cmd, sizeof cmd, "%s %s %d", maker, pic, scale);
  if (system(cmd) != 0) bench_die("photo: cannot draw the picture", NULL);
}

void bench_photo(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_PERFORMANCE];
  const char *bin, *maker;
  fprintf(d, "## Set-up and output on a camera's picture\n\n");
  if (!photo_tools(d, &bin, &maker)) return;
  static const int scale[PHOTO_SIZES] = {1, 5};
  static const char *const pens[PHOTO_PENS] = {"one pen", "four pens (cmyk)"};
  char pic[PHOTO_SIZES][512], cmd[2048];
  for (int i = 0; i < PHOTO_SIZES; i++) photo_picture(b, maker, scale[i], pic[i], sizeof pic[i]);
  const int reps = b->quick ? 1 : b->reps;
  double t[PHOTO_SIZES][PHOTO_PENS][BENCH_MAX_REPS];
  for (int k = 0; k < reps; k++)
    for (int i = 0; i < PHOTO_SIZES; i++)
      for (int j = 0; j < PHOTO_PENS; j++) {
        bench_note("photo: %d x %d pixels, %s, run %d of %d", 600 * scale[i], 800 * scale[i], pens[j], k + 1,
                   reps);
        snprintf(cmd, sizeof cmd,
                 "%s run params/photo.ini --set scene.image=%s --set anneal.sweeps=1%s --out %s/photo-run "
                 "--quiet >/dev/null 2>&1",
                 bin, pic[i], j ? " --set layers.source=cmyk" : "", b->datadir);
        double t0 = bench_now();
        if (system(cmd) != 0) bench_die("photo: a run failed", NULL);
        t[i][j][k] = bench_now() - t0;
      }
  snprintf(cmd, sizeof cmd, "rm -rf %s/photo-run", b->datadir);
  if (system(cmd) != 0) bench_note("photo: could not remove %s/photo-run", b->datadir);
  fprintf(d,
          "What a picture's size costs before and after the anneal, from the command line as a user\n"
          "runs it: `%s run params/photo.ini` (A4) for one sweep, about a three-hundredth of the\n"
          "preset's anneal, so the wall time is set-up (decoding, the downsampling to\n"
          "`scene.image_max_pixels`, 4 megapixels, the blurs, the edge tangent flow and the tone\n"
          "target, a layer each) and output (the files and the fidelity scores: the drawing's and,\n"
          "with several pens, each pen's). The picture is the bundled one (tools/make-picture.c) as\n"
          "a PNG of 600 x 800 pixels and five times larger a side, a camera's 12 megapixels (1732 x\n"
          "2309 after the budget). Medians of %d alternated runs, wall seconds on all cores:\n\n"
          "| picture | %s | %s |\n|---|---|---|\n",
          bin, reps, pens[0], pens[1]);
  for (int i = 0; i < PHOTO_SIZES; i++) {
    fprintf(d, "| %d x %d |", 600 * scale[i], 800 * scale[i]);
    for (int j = 0; j < PHOTO_PENS; j++) fprintf(d, " %.2f |", bench_median(t[i][j], reps));
    fprintf(d, "\n");
  }
  fprintf(d, "\nThe blurs and the scores' windows run on every core, and the scores are the same bits\n"
             "on any number of threads (docs/IMAGES.md, \"How a drawing is scored\"). Before (2026-12-03,\n"
             "the build of that morning, 3 runs alternated with the new one): 16.7 s for the 12-megapixel\n"
             "picture in four pens and 4.5 s in one, against 8.3 and 2.8 s, when the scores ran on one\n"
             "core, their direct blur unfolded and the picture's blurs a pixel at a time.\n\n");
}

/* The tone energy of run directory dir at n nodes (its scene.ini edited),
** from `linewise energy`. */
static double tone_at(const char *bin, const char *dir, int n)
{
  char cmd[2048];
  snprintf(cmd, sizeof cmd,
           "sed -i 's/^tone_quadrature = .*/tone_quadrature = %d/' %s/scene.ini && %s energy %s | "
           "sed -n 's/^tone //p'",
           n, dir, bin, dir);
  FILE *f = popen(cmd, "r");
  double e = NAN;
  if (!f || fscanf(f, "%lf", &e) != 1) e = NAN;
  if (f) pclose(f);
  if (!isfinite(e)) bench_die("photo: no tone energy", NULL);
  return e;
}

/* The CPU seconds of the finished children so far. */
static double children_cpu(void)
{
  struct rusage u;
  getrusage(RUSAGE_CHILDREN, &u);
  return (double)u.ru_utime.tv_sec + 1e-6 * (double)u.ru_utime.tv_usec + (double)u.ru_stime.tv_sec +
         1e-6 * (double)u.ru_stime.tv_usec;
}

/* energy.tone_quadrature on the photo preset: the preset's tone nodes
** against the other terms' six, from the command line on the bundled
** picture at A6 (one thread, the whole anneal), alternated. */
void bench_photo_tone(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_ACCURACY];
  const char *bin, *maker;
  fprintf(d, "### On the photo preset\n\n");
  if (!photo_tools(d, &bin, &maker)) return;
  char pic[512], cmd[2048], dir[2][600];
  photo_picture(b, maker, 1, pic, sizeof pic);
  static const int nodes[2] = {0, 6}; /* the preset's; the other terms' */
  const int reps = b->quick ? 1 : b->reps;
  double t[2][BENCH_MAX_REPS], own[2] = {0}, fine[2] = {0};
  for (int k = 0; k < reps; k++)
    for (int j = 0; j < 2; j++) {
      const int i = (j + k) % 2; /* each first in turn */
      bench_note("photo tone nodes: %s, run %d of %d", nodes[i] ? "6" : "the preset's", k + 1, reps);
      snprintf(dir[i], sizeof dir[i], "%s/photo-tone-%d", b->datadir, i);
      char set[64] = "";
      if (nodes[i]) snprintf(set, sizeof set, " --set energy.tone_quadrature=%d", nodes[i]);
      snprintf(cmd, sizeof cmd,
               "%s run params/photo.ini --set scene.image=%s --set scene.page=a6%s --threads 1 --out %s --quiet "
               ">/dev/null 2>&1",
               bin, pic, set, dir[i]);
      const double t0 = children_cpu();
      if (system(cmd) != 0) bench_die("photo: a run failed", NULL);
      t[i][k] = children_cpu() - t0;
    }
  char line[256];
  int preset = 0;
  snprintf(cmd, sizeof cmd, "sed -n 's/^tone_quadrature = //p' %s/scene.ini", dir[0]);
  FILE *f = popen(cmd, "r");
  if (!f || !fgets(line, sizeof line, f) || sscanf(line, "%d", &preset) != 1) bench_die("photo: no tone nodes", NULL);
  pclose(f);
  for (int i = 0; i < 2; i++) {
    own[i] = tone_at(bin, dir[i], nodes[i] ? nodes[i] : preset);
    fine[i] = tone_at(bin, dir[i], 32);
  }
  snprintf(cmd, sizeof cmd, "rm -rf %s/photo-tone-0 %s/photo-tone-1", b->datadir, b->datadir);
  if (system(cmd) != 0) bench_note("photo: could not remove the runs");
  const double m0 = bench_median(t[0], reps), m1 = bench_median(t[1], reps);
  fprintf(d,
          "`params/photo.ini` sets `energy.tone_quadrature` to the fewest nodes that keep the tone's\n"
          "samples 0.7 tone_blur apart along a segment or closer (here %d, for segments of 8 pen widths\n"
          "and a blur of 3); the other terms keep `quadrature` (6). The bundled picture on A6, the\n"
          "whole anneal on one thread (CPU seconds, which a shared machine's preemption does not\n"
          "inflate), each run's final tone energy at its own nodes against 32, medians of %d runs\n"
          "alternated, each setting first in turn (`linewise run params/photo.ini --set\n"
          "scene.page=a6 --threads 1 [--set energy.tone_quadrature=6]`, then `linewise energy DIR\n"
          "[--set energy.tone_quadrature=32]`):\n\n"
          "| tone nodes | CPU s | x time | tone energy | at 32 nodes | relative error |\n"
          "|---|---|---|---|---|---|\n"
          "| %d (the preset's) | %.2f | %.2f | %.6g | %.6g | %.1e |\n"
          "| 6 | %.2f | 1.00 | %.6g | %.6g | %.1e |\n\n",
          preset, reps, preset, m0, m0 / m1, own[0], fine[0], fabs(own[0] - fine[0]) / fine[0], m1, own[1], fine[1],
          fabs(own[1] - fine[1]) / fine[1]);
  fprintf(d, "On photographs (2026-12-03, python3-skimage's chelsea, astronaut, coffee and camera on A5,\n"
             "seeds 7 and 8, one thread, each pair run back to back): 4 tone nodes took 0.77 to 0.95 of\n"
             "the CPU time of 6 (median 0.88), at the same scores (SSIM 0.0006 lower on average, between\n"
             "-0.0044 and +0.0022; from seed 7 to 8 at 6 nodes it moved by up to 0.003). Their final\n"
             "states' tone energy at 4 nodes was within 3e-6 to 5.5e-4 of 32 nodes' (the annealer finds\n"
             "some of the 4-node rule's error: 3e-5 on a state annealed at 6), 2e-5 of the total energy\n"
             "at most. Counted in instructions, which a shared machine does not disturb (callgrind,\n"
             "the bundled picture on A6, 30 sweeps, set-up and output included): 0.87 of 6 nodes'.\n\n");
}
