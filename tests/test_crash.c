/*
** test_crash.c -- crash consistency: runs killed with SIGKILL at random
** moments (during start-up, sweeps, checkpoints, the final drawings, and
** during the resumes that follow) always resume, and the finished run is
** byte-identical to an uninterrupted one: state.lw, the replica files,
** trace.csv, final.svg and final.png.
**
** Three scenes: a plain run, parallel tempering (4 rungs) and an image
** scene.  make test kills each a few times; make test-long (LW_LONG=1)
** kills at least 200 times in all and prints the counts (docs/FORMATS.md).
*/
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "testutil.h"

static char dir[64];

static void setup(void) { cr_assert_eq(lw_test_dir_make(dir, "crash"), 0); }
static void teardown(void) { lw_test_dir_remove(dir); }

TestSuite(crash, .init = setup, .fini = teardown, .timeout = 1200);

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* "linewise <cmd>" killed with SIGKILL after `delay` seconds unless it ends
** first; returns its exit status (137 when the kill got it). */
static int run_killed(const char *cmd, double delay)
{
  return lw_test_sh("exec 2>/dev/null; %s %s --quiet 2>>%s/err.txt & p=$!; sleep %.4f; kill -9 $p; wait $p", lw_test_bin(),
                    cmd, dir, delay);
}

typedef struct {
  int kills, kills_start, kills_resume, reruns;
} counts;

static void compare(const char *ref, const char *got, int replicas)
{
  const char *files[] = {"state.lw", "trace.csv", "final.svg", "final.png"};
  for (int k = 0; k < 4; k++)
    cr_assert_eq(lw_test_sh("cmp -s %s/%s %s/%s", ref, files[k], got, files[k]), 0, "%s differs after kills",
                 files[k]);
  for (int k = 1; k < replicas; k++)
    cr_assert_eq(lw_test_sh("cmp -s %s/replica-%d.lw %s/replica-%d.lw", ref, k, got, k), 0,
                 "replica-%d.lw differs after kills", k);
  cr_assert_neq(lw_test_sh("ls %s/*.tmp 2>/dev/null | grep -q .", got), 0, "a temporary file survived");
}

/* Kills `trials` runs of scene at random moments; each is then resumed,
** itself killed again with probability 1/2, until one resume finishes. */
static void kill_and_resume(const char *scene, const char *set, int replicas, int trials, uint64_t seed, counts *c)
{
  char ref[128], got[128], cmd[1024];
  snprintf(ref, sizeof ref, "%s/ref", dir);
  snprintf(got, sizeof got, "%s/got", dir);
  lw_test_sh("rm -rf %s %s", ref, got);
  double t0 = now();
  snprintf(cmd, sizeof cmd, "%s run %s %s --out %s --quiet", lw_test_bin(), scene, set, ref);
  cr_assert_eq(lw_test_sh("%s", cmd), 0, "the reference run failed");
  double span = 1.2 * (now() - t0);
  rng_seed(seed);
  for (int t = 0; t < trials; t++) {
    lw_test_sh("rm -rf %s", got);
    snprintf(cmd, sizeof cmd, "run %s %s --out %s", scene, set, got);
    int rc = run_killed(cmd, urand(0, span));
    if (rc == 137) c->kills++;
    for (int round = 0; rc != 0; round++) {
      cr_assert(rc == 137 || rc == 0, "exit %d (see %s/err.txt)", rc, dir);
      cr_assert_lt(round, 100, "no end in sight");
      if (lw_test_sh("test -f %s/state.lw", got)) {
        /* killed before the first checkpoint: nothing to resume, run again */
        c->kills_start++;
        c->reruns++;
        rc = run_killed(cmd, urand(0, span));
        if (rc == 137) c->kills++;
        continue;
      }
      char res[256];
      snprintf(res, sizeof res, "resume %s", got);
      if (urand(0, 1) < 0.5) {
        rc = run_killed(res, urand(0, span));
        if (rc == 137) {
          c->kills++;
          c->kills_resume++;
        }
      } else {
        rc = lw_test_sh("%s %s --quiet 2>>%s/err.txt", lw_test_bin(), res, dir);
        cr_assert_eq(rc, 0, "resume failed after a kill (see %s/err.txt)", dir);
      }
    }
    compare(ref, got, replicas);
  }
}

Test(crash, sigkill_at_random_moments_then_resume_gives_the_same_files)
{
  const char *root = getenv("LW_ROOT");
  cr_assert_not_null(root);
  int trials = lw_test_long() ? 70 : 1;
  counts c[3] = {{0}};
  char scene[1024];
  snprintf(scene, sizeof scene, "%s/tests/fixtures/v1/plain.ini", root);
  kill_and_resume(scene, "--set output.checkpoint_every=3 --set anneal.sweeps=40", 1, trials, 21, &c[0]);
  snprintf(scene, sizeof scene, "%s/tests/fixtures/v1/tempering.ini", root);
  kill_and_resume(scene, "--set output.checkpoint_every=3 --set anneal.sweeps=40 --set tempering.replicas=4", 4,
                  trials, 22, &c[1]);
  snprintf(scene, sizeof scene, "%s/image.ini", dir);
  FILE *f = fopen(scene, "w");
  cr_assert_not_null(f);
  fprintf(f, "[scene]\nwidth = 60\nheight = 50\nimage = %s/params/picture.png\npotential = image\nfield = etf\n"
             "margin = 4\n[init]\nsplines = 0\ncoverage = 0.15\nsegments = 3\nsegment_length = 4\n"
             "[energy]\nstrain = 5\nbending = 1\npotential = 1\nfield = -0.5\npair = 0.01\nboundary = 0.1\n"
             "[anneal]\nsweeps = 30\nsteps = 3\nseed = 5\n[output]\ncheckpoint_every = 4\npreview_image = 1\n", root);
  fclose(f);
  kill_and_resume(scene, "", 1, trials, 23, &c[2]);
  const char *names[3] = {"plain", "tempering", "image"};
  int all = 0;
  for (int k = 0; k < 3; k++) {
    all += c[k].kills;
    cr_log_info("crash: %s: %d trials, %d kills (%d before the first checkpoint, %d of resumes), %d reruns", names[k],
                trials, c[k].kills, c[k].kills_start, c[k].kills_resume, c[k].reruns);
    if (lw_test_long())
      fprintf(stderr, "crash: %s: %d trials, %d kills (%d before the first checkpoint, %d of resumes), all resumed "
            "byte-identically\n", names[k], trials, c[k].kills, c[k].kills_start, c[k].kills_resume);
  }
  if (lw_test_long()) cr_assert_geq(all, 200, "only %d kills landed", all);
}
