/*
** test_fuzz.c -- replays the fuzz corpus (tests/fuzz/corpus) through the
** fuzz harnesses, compiled here with cc: every seed input and every input
** that once crashed a reader stays a regression test.  A broken property
** aborts inside the harness, which Criterion reports as a crash.
*/
#include <criterion/criterion.h>
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

int lw_fuzz_params_one(const uint8_t *data, size_t size);
int lw_fuzz_state_one(const uint8_t *data, size_t size);
int lw_fuzz_resume_one(const uint8_t *data, size_t size);
int lw_fuzz_energy_one(const uint8_t *data, size_t size);
int lw_fuzz_image_one(const uint8_t *data, size_t size);
int lw_fuzz_points_one(const uint8_t *data, size_t size);
int lw_fuzz_trace_one(const uint8_t *data, size_t size);
int lw_fuzz_fieldfile_one(const uint8_t *data, size_t size);

/* The harnesses' scratch files go to TMPDIR (fuzz_util.h): a directory of
** the suite's, removed after, so that a replay leaves none in /tmp (each
** process left five files and a run directory). */
static char scratch[64];

static void make_dir(void)
{
  cr_assert_eq(lw_test_dir_make(scratch, "fuzz"), 0);
  cr_assert_eq(setenv("TMPDIR", scratch, 1), 0);
}

static void remove_dir(void) { cr_assert_eq(lw_test_dir_remove(scratch), 0); }

TestSuite(fuzz, .init = make_dir, .fini = remove_dir);

/* Feeds every file of tests/fuzz/corpus/<name> to fn; returns the count. */
static int replay(const char *name, int (*fn)(const uint8_t *, size_t))
{
  const char *root = getenv("LW_ROOT");
  char dir[1024];
  snprintf(dir, sizeof dir, "%s/tests/fuzz/corpus/%s", root ? root : ".", name);
  DIR *d = opendir(dir);
  cr_assert_not_null(d, "cannot open %s (is LW_ROOT set?)", dir);
  int n = 0;
  struct dirent *e;
  while ((e = readdir(d))) {
    if (e->d_name[0] == '.') continue;
    char path[2048];
    snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
    FILE *f = fopen(path, "rb");
    cr_assert_not_null(f, "cannot read %s", path);
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *buf = malloc(size > 0 ? (size_t)size : 1);
    cr_assert_eq(fread(buf, 1, (size_t)size, f), (size_t)size);
    fclose(f);
    fn(buf, (size_t)size);
    free(buf);
    n++;
  }
  closedir(d);
  return n;
}

Test(fuzz, params_corpus_replays_clean)
{
  cr_assert_geq(replay("params", lw_fuzz_params_one), 10, "the params corpus lost its seeds");
}

Test(fuzz, state_corpus_replays_clean)
{
  cr_assert_geq(replay("state", lw_fuzz_state_one), 10, "the state corpus lost its seeds");
}

Test(fuzz, resume_corpus_replays_clean)
{
  cr_assert_geq(replay("resume", lw_fuzz_resume_one), 8, "the resume corpus lost its seeds");
}

Test(fuzz, energy_corpus_replays_clean)
{
  cr_assert_geq(replay("energy", lw_fuzz_energy_one), 4, "the energy corpus lost its seeds");
}

Test(fuzz, image_corpus_replays_clean)
{
  cr_assert_geq(replay("image", lw_fuzz_image_one), 12, "the image corpus lost its seeds");
}

Test(fuzz, points_corpus_replays_clean)
{
  cr_assert_geq(replay("points", lw_fuzz_points_one), 5, "the points corpus lost its seeds");
}

Test(fuzz, trace_corpus_replays_clean)
{
  cr_assert_geq(replay("trace", lw_fuzz_trace_one), 4, "the trace corpus lost its seeds");
}

Test(fuzz, fieldfile_corpus_replays_clean)
{
  cr_assert_geq(replay("fieldfile", lw_fuzz_fieldfile_one), 6, "the fieldfile corpus lost its seeds");
}
