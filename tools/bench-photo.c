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
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "benchutil.h"

enum { PHOTO_SIZES = 2, PHOTO_PENS = 2 };

void bench_photo(bench_ctx *b)
{
  FILE *d = b->doc[BENCH_PERFORMANCE];
  const char *bin = getenv("LW_BIN"), *maker = getenv("LW_MAKE_PICTURE");
  if (!bin || !*bin) bin = "bin/linewise";
  if (!maker || !*maker) maker = "build/make-picture";
  fprintf(d, "## Set-up and output on a camera's picture\n\n");
  if (access(bin, X_OK) || access(maker, X_OK) || access("params/photo.ini", R_OK)) {
    fprintf(d, "Not measured: no %s, %s or params/photo.ini (make bench runs it from the repository root).\n\n",
            bin, maker);
    return;
  }
  static const int scale[PHOTO_SIZES] = {1, 5};
  static const char *const pens[PHOTO_PENS] = {"one pen", "four pens (cmyk)"};
  char pic[PHOTO_SIZES][512], cmd[2048];
  for (int i = 0; i < PHOTO_SIZES; i++) {
    snprintf(pic[i], sizeof pic[i], "%s/photo-%d.png", b->datadir, scale[i]);
    snprintf(cmd, sizeof cmd, "%s %s %d", maker, pic[i], scale[i]);
    if (system(cmd) != 0) bench_die("photo: cannot draw the picture", NULL);
  }
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
