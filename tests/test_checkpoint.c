/*
** test_checkpoint.c -- run directories written by earlier releases still
** resume.  tests/fixtures/v1 holds two directories written by the release
** before the sectioned checkpoint format (state format 1), stopped at sweep
** 25 of 60: a plain run and a parallel-tempering run.  Resumed to the end,
** each must give the same files as an uninterrupted run of its scene.ini
** by the current binary: the old file carried everything the chain needs.
*/
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static char dir[64];

static void setup(void) { cr_assert_eq(lw_test_dir_make(dir, "ckpt"), 0); }
static void teardown(void) { lw_test_dir_remove(dir); }

TestSuite(checkpoint, .init = setup, .fini = teardown);

static const char *bin(void)
{
  const char *b = getenv("LW_BIN");
  cr_assert_not_null(b, "LW_BIN must name bin/linewise (make test sets it)");
  return b;
}

static const char *root(void)
{
  const char *r = getenv("LW_ROOT");
  return r ? r : ".";
}

/* Resumes a copy of fixture `name` and compares it with a fresh run. */
static void resume_fixture_matches_fresh_run(const char *name, const char *const *files)
{
  cr_assert_eq(lw_test_sh("cp -r %s/tests/fixtures/v1/%s %s/old", root(), name, dir), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/old --quiet", bin(), dir), 0, "the old run directory does not resume");
  cr_assert_eq(lw_test_sh("%s run %s/old/scene.ini --out %s/fresh --quiet", bin(), dir, dir), 0);
  for (const char *const *f = files; *f; f++)
    cr_expect_eq(lw_test_sh("cmp -s %s/old/%s %s/fresh/%s", dir, *f, dir, *f), 0,
                 "%s: %s differs from an uninterrupted run", name, *f);
  /* and the resumed state reads back through `linewise energy` */
  cr_assert_eq(lw_test_sh("%s energy %s/old > %s/energy.txt", bin(), dir, dir), 0);
}

Test(checkpoint, format_1_plain_run_resumes_to_the_uninterrupted_result)
{
  static const char *const files[] = {"state.lw", "trace.csv", "final.svg", "final.png", NULL};
  resume_fixture_matches_fresh_run("plain", files);
}

Test(checkpoint, format_1_tempering_run_resumes_to_the_uninterrupted_result)
{
  static const char *const files[] = {"state.lw", "replica-1.lw", "replica-2.lw", "trace.csv", "final.svg",
                                      "final.png", "ladder.ini", NULL};
  resume_fixture_matches_fresh_run("tempering", files);
}
