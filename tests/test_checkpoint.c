/*
** test_checkpoint.c -- run directories written by earlier releases still
** resume.  tests/fixtures/v1 holds two directories written by the release
** before the sectioned checkpoint format (state format 1), stopped at sweep
** 25 of 60: a plain run and a parallel-tempering run.  Resumed to the end,
** each must give the same files as an uninterrupted run of its scene.ini
** by the current binary: the old file carried everything the chain needs.
** The fixtures were rewritten by that release with today's sweep order
** backported (nodes in order, forward or backward, splines numbered along
** the Hilbert curve at the start: issue 14), since a fresh run of the
** current binary must follow the same trajectory; the file format is the
** old one.  Their scene.ini files have energy.boundary_clearance = 0
** added (a key absent from the old format's hash): the clearance, newer
** than these runs, forbids states they passed through.
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

/* Resumes a copy of fixture `name` and compares it with a fresh run. */
static void resume_fixture_matches_fresh_run(const char *name, const char *const *files)
{
  cr_assert_eq(lw_test_sh("cp -r %s/tests/fixtures/v1/%s %s/old", lw_test_root(), name, dir), 0);
  /* the old state reads through `linewise energy` as it is (its run data
  ** was said a section "written by a newer version") */
  cr_assert_eq(lw_test_sh("%s energy %s/old > %s/energy.txt 2>&1 && grep -q '^total ' %s/energy.txt", lw_test_bin(),
                          dir, dir, dir), 0, "%s", lw_test_slurp("%s/energy.txt", dir));
  /* a row torn by a kill after the checkpoint, whose numeric prefix reads
  ** as an earlier sweep (22 of "221,..."), must go, not stay */
  cr_assert_eq(lw_test_sh("printf '26,0.1\n22' >> %s/old/trace.csv", dir), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/old --quiet", lw_test_bin(), dir), 0, "the old run directory does not resume");
  /* (at the old trace's 10 digits, which a resume keeps and a new run of
  ** its scene.ini leaves for every digit) */
  cr_assert_eq(lw_test_sh("%s run %s/old/scene.ini --out %s/fresh --quiet --set output.trace_exact=0", lw_test_bin(),
                          dir, dir), 0);
  /* but for scene_hash and scene_keys: the old scene.ini lacks the keys
  ** added since, which a resume leaves out of the hash and a fresh run of it
  ** writes in; and size_peak, which a resume of a file without it begins at
  ** the state it read; and block_shift and the checksum, which a run begun
  ** before them goes on without */
  for (const char *const *f = files; *f; f++)
    cr_expect_eq(lw_test_sh("k='^(scene_hash|scene_keys|size_peak|block_shift|# checksum) '; "
                            "grep -avE \"$k\" %s/old/%s > %s/f1; "
                            "grep -avE \"$k\" %s/fresh/%s > %s/f2; cmp -s %s/f1 %s/f2", dir, *f, dir, dir, *f, dir,
                            dir, dir),
                 0, "%s: %s differs from an uninterrupted run", name, *f);
  /* and the resumed state reads back through `linewise energy` */
  cr_assert_eq(lw_test_sh("%s energy %s/old > %s/energy.txt", lw_test_bin(), dir, dir), 0);
}

Test(checkpoint, format_1_plain_run_resumes_to_the_uninterrupted_result)
{
  static const char *const files[] = {"state.lw", "trace.csv", "final.svg", "final.png", NULL};
  resume_fixture_matches_fresh_run("plain", files);
}

Test(checkpoint, format_1_tempering_run_resumes_to_the_uninterrupted_result)
{
  static const char *const files[] = {"state.lw", "replica-1.lw", "replica-2.lw", "trace.csv", "final.svg",
                                      "final.png", NULL};
  resume_fixture_matches_fresh_run("tempering", files);
  /* ladder.ini, written as the ladder froze, holds the old release's 17
  ** digits (a fresh run's the fewest that read back): the same numbers */
  cr_assert_eq(lw_test_sh("for r in old fresh; do sed -n '/^ladder = /,$p' %s/$r/ladder.ini | sed 's/^ladder = //' | "
                          "tr -s ' ' '\n' | awk 'NF { printf \"%%.17g\\n\", $1 }' > %s/$r.ladder; done; "
                          "test -s %s/old.ladder && cmp -s %s/old.ladder %s/fresh.ladder", dir, dir, dir, dir, dir),
               0, "ladder.ini holds other rungs than an uninterrupted run's");
}

/* A run of the plain fixture's scene stopped at sweep 20, in dir/r. */
static void stopped_run(void)
{
  cr_assert_eq(lw_test_sh("%s run %s/tests/fixtures/v1/plain.ini --out %s/r --stop-at 20 --quiet", lw_test_bin(), lw_test_root(), dir),
               0);
}

/* Resumes a copy of dir/r whose state.lw went through the sed script; the
** exit status, with stderr in dir/err.txt. */
static int resume_edited(const char *sed)
{
  lw_test_sh("rm -rf %s/x && cp -r %s/r %s/x", dir, dir, dir);
  cr_assert_eq(lw_test_sh("sed -i -e '%s' %s/x/state.lw", sed, dir), 0);
  return lw_test_sh("%s resume %s/x --quiet --sweeps 2 2>%s/err.txt", lw_test_bin(), dir, dir);
}

static int err_has(const char *text)
{
  char *e = lw_test_slurp("%s/err.txt", dir);
  const int has = e && strstr(e, text);
  free(e);
  return has;
}

Test(checkpoint, every_run_data_value_is_checked_on_resume)
{
  /* each edit was accepted (or crashed, or ran on NaN) before validation */
  static const struct { const char *sed, *msg; } bad[] = {
    {"s/^block = .*/block = 99999/", "[run] block: expected a whole number from -1 to 5"},
    {"s/^block = .*/block = -7/", "[run] block"},
    {"s/^moves.point = .*/moves.point = -1 0 0 0/", "[chain] moves.point"},
    {"s/^moves.point = \\([0-9]*\\) .*/moves.point = \\1 99999999 0 0/", "+ crowded + outside <= proposed"},
    {"s/^moves.point = \\([0-9]*\\) .*/moves.point = \\1 0 0 0 99999999/", "+ crowded + outside <= proposed"},
    {"s/^moves.point = \\([0-9]*\\) .*/moves.point = \\1 0 0 0 0 99999999/", "+ crowded + outside <= proposed"},
    {"s/^moves.point = .*/moves.point = 1 0 0 0 0 0 0/", "[chain] moves.point: expected 4 to 6 whole numbers"},
    {"s/^sweep = .*/sweep = 99999999999999999999/", "[run] sweep"},
    {"s/^energy.strain = .*/energy.strain = inf/", "[chain] energy.strain"},
    {"s/^energy.bending = .*/energy.bending = -1e308/", "-1e+308, but the state is at "},
    {"s/^temperature = .*/temperature = -1/", "[run] temperature"},
    {"s/^temperature = .*/temperature = inf/", "[run] temperature"},
    {"s/^step.point = .*/step.point = -0.34/", "[chain] step.point"},
    {"s/^step.point = .*/step.point = 0/", "[chain] step.point"},
    {"s/^step.point = .*/step.point = inf/", "[chain] step.point"},
    {"s/^step.point = .*/step.point = 0x1p-2/", "[chain] step.point"},
    {"s/^rng = ../rng = r;/", "[chain] rng: expected the state of a mt19937 generator"},
    {"s/^rng = \\(.*\\)$/rng = \\1ff/", "[chain] rng"},
    /* the position index of mt19937 (bytes 4992..4995): 0xffff0000 */
    {"s/^\\(rng = .\\{9984\\}\\)......../\\10000ffff/", "[chain] rng"},
    {"s/^node = \\([^ ]*\\) /node = 1e200 /", "spline 0 node 0"},
    /* either sign, the vectors too; a step past its greatest */
    {"s/^node = \\([^ ]*\\) /node = -1e200 /", "spline 0 node 0"},
    {"0,/^node = /{/^node = /s/ [^ ]*$/ -1e200/}", "spline 0 node 0"},
    {"s/^step.point = .*/step.point = 1e6/", "[chain] step.point: expected 1 number from"},
    /* a spline of no segment, a layer past 255, and a layer on one spline
    ** alone: the line named, not the splines' own check after */
    {"0,/^spline = /s/^spline = [0-9]*/spline = 0/", "<layer 0 to 255>]', got 'spline = 0 24'"},
    {"0,/^spline = /s/^spline = .*/& 256/", "spline = <segments >= 1> <rest length > 0> [<layer 0 to 255>]"},
    {"0,/^spline = /s/^spline = .*/& 0/", "as the first spline has"},
    {"s/^splines = .*/splines = 0x2/", "[system splines] splines"},
    {"s/^trace_mark.point = .*/trace_mark.point = 99999999 0 0/", "[run] trace_mark.point: beyond"},
    {"s/^max_drift = .*/max_drift = nan/", "[run] max_drift"},
    {"s/^window.point = .*/window.point = 1 5/", "[chain] window.point: more accepted"},
    {"/^trace_bytes = /d;s/^seed = .*/seed = 1 2/", "[run] seed"},
    {"s/^\\[chain\\]$/[chain 7]/", "section [chain] missing (the file has [chain 7] at line "},
    {"s/^\\[chain\\]$/[chainx]/", "section [chain] missing (the file has [chainx] at line "},
    {"/^step.point = /d", "[chain] step.point: missing (a damaged or edited file: window.point is there"},
    {"/^window.vector = /d", "[chain] window.vector: missing (a damaged or edited file: step.vector is there"},
    {"/^moves.point = /d", "[chain] moves.point: missing (a damaged or edited file: step.point is there"},
    {"$s/$/\\nextra = 1/", "[system splines] extra: expected nothing after"},
    {"s/^sweep = 20$/sweep = 20\\nsweep = 21/", "[run] sweep: unknown or repeated key"},
    {"s/^block = 1$/block = 1\\o000/", "a NUL byte inside the line"},
    /* the sweep against the schedule's step (6 of 10 sweeps) and the trace's rows */
    {"s/^sweep = 20$/sweep = 2/", "[run] sweep: 2 is in the schedule"},
    {"s/^sweep = 20$/sweep = 19/", "counts end at sweep 20, but it is at sweep 19 (a row every 1 sweeps)"},
    {"s/^end_sweep = .*/end_sweep = 19/", "[run] end_sweep: expected a whole number from 20"},
    {"s/^trace_bytes = .*/trace_bytes = 10/", "counts 10 bytes of it, which do not end a row"},
    /* a temperature or a seed of another run: each read, neither checked
    ** (the rest of the step ran at T = 5; summary.json named the new seed) */
    {"s/^temperature = .*/temperature = 5/", "[run] temperature: 5, but the geometric schedule"},
    {"s/^seed = .*/seed = 2/", "[run] seed: 2, but the run"},
    /* a count the lines do not hold, and a node line missing, said so */
    {"s/^splines = \\([0-9]*\\)$/splines = 1\\1/", "but the section ends after"},
    {"0,/^node = /{//d}", "segments have"},
    /* at each check's edge (a mutation tester's: each survived a looser
    ** check): the counts' sum one past proposed, one more accepted, nan past
    ** the chain's, a fraction; an energy off by some 5e-5 of itself; an sd
    ** of -1 */
    {"s/^moves.point = \\([0-9]*\\) .*/moves.point = \\1 \\1 1 0/", "+ crowded + outside <= proposed"},
    {"s/^window.point = .*/window.point = 6 7/", "[chain] window.point: more accepted (7) than proposed (6)"},
    {"s/^trace_mark.point = \\([0-9]*\\) \\([0-9]*\\) .*/trace_mark.point = \\1 \\2 5/",
     "[run] trace_mark.point: beyond"},
    {"s/^moves.point = \\([0-9]*\\) /moves.point = \\1.5 /", "[chain] moves.point: expected 4 to 6 whole numbers"},
    {"s/^\\(energy.bending = [0-9]*\\.[0-9]\\{4\\}\\)[0-4]/\\19/; t; "
     "s/^\\(energy.bending = [0-9]*\\.[0-9]\\{4\\}\\)[5-9]/\\10/", "but the state is at "},
    {"s/^prev_stats = .*/prev_stats = 0 -1 0/", "[run] prev_stats: expected 'mean sd samples' with sd >= 0"},
    /* lines a file of this release has taken out, each read as an older
    ** file's absence (a reviewer's: the first row after the resume read the
    ** acceptance since the run's start; any edit of scene.ini went through),
    ** and scene_keys' junk, read only where the hashes differed */
    {"/^trace_mark.point = /d", "[run] trace_mark.point: missing"},
    {"/^scene_hash = /d", "[run] scene_hash: missing"},
    {"s/^scene_keys = .*/scene_keys = 12x4/", "[run] scene_keys: expected 4 hexadecimal digits for each of the "},
    /* cut short where the hashes agree (a later edit was then "178 keys
    ** more"), and taken out beside a hash of this kind ("scene.ini was
    ** edited", nothing was) */
    {"s/^\\(scene_keys = ........\\).*/\\1/", "[run] scene_keys: expected 4 hexadecimal digits for each of the "},
    {"/^scene_keys = /d", "[run] scene_keys: missing (a line taken out"},
  };
  stopped_run();
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    /* (edited on purpose: the checksum taken out after, as its own message
    ** says, so that each value's check is what refuses) */
    char sed[512];
    snprintf(sed, sizeof sed, "%s' -e '/^# checksum [0-9a-f]*$/d", bad[i].sed);
    int rc = resume_edited(sed);
    cr_expect_eq(rc, 2, "edit '%s': exit %d", bad[i].sed, rc);
    cr_expect(err_has(bad[i].msg), "edit '%s': message lacks '%s'", bad[i].sed, bad[i].msg);
    cr_expect(err_has("x/state.lw"), "edit '%s': message lacks the file", bad[i].sed);
  }
  /* unedited, the copy resumes: the edits above are what was refused */
  cr_assert_eq(resume_edited("s/^sweep = 20$/sweep = 20/"), 0);
  /* the sweep edited forward within its temperature step (a step's edge,
  ** as at 20, is the schedule's check): past the trace's rows */
  cr_assert_eq(lw_test_sh("rm -rf %s/r && %s run %s/tests/fixtures/v1/plain.ini --out %s/r --stop-at 21 --quiet",
                          dir, lw_test_bin(), lw_test_root(), dir), 0);
  cr_assert_eq(resume_edited("s/^sweep = 21$/sweep = 22/;/^# checksum /d"), 2);
  cr_assert(err_has("x/state.lw counts end at sweep 21, but it is at sweep 22"), "%s",
            lw_test_slurp("%s/err.txt", dir));
}

/* A run whose trace.csv is gone is refused by resume (state.lw counts its
** bytes) and by stats, each in one line naming the file. */
Test(checkpoint, a_run_whose_trace_is_gone_is_refused_naming_it)
{
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out a --quiet --set anneal.sweeps=40 "
                          "--stop-at 20 && rm a/trace.csv", dir, lw_test_bin(), lw_test_root()), 0);
  cr_assert_eq(lw_test_sh("cd %s && %s resume a --quiet 2> err.txt", dir, lw_test_bin()), 2);
  cr_assert(err_has("a/trace.csv: No such file or directory, but state.lw counts "), "%s",
            lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(lw_test_sh("cd %s && %s stats a 2> err.txt", dir, lw_test_bin()), 2);
  cr_assert(err_has("a/trace.csv: cannot read: No such file or directory"), "%s", lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(lw_test_sh("test $(wc -l < %s/err.txt) -eq 1", dir), 0);
}

/* The [tempering] section's values are checked naming the line and the key
** (four of its refusals named no line, and one no key). */
Test(checkpoint, a_tempering_sections_values_are_refused_naming_line_and_key)
{
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --out %s/r --threads 1 --quiet --stop-at 10 --set "
                          "anneal.sweeps=20 --set tempering.replicas=3 --set tempering.t_min=0.01 --set "
                          "tempering.t_max=1 --set anneal.schedule=constant --set anneal.t_start=1",
                          lw_test_bin(), lw_test_root(), dir),
               0);
  static const struct { const char *sed, *key, *msg; } bad[] = {
    {"s/^ladder = .*/ladder = 0.01 0.001 1/", "ladder", "expected increasing temperatures"},
    {"s/^ladder = .*/ladder = 0.01 0.01 1/", "ladder", "expected increasing temperatures"},
    {"s/^at_label = .*/at_label = 0 2 0 1 2 1/", "at_label", "expected a permutation of the replicas"},
    {"s/^at_label = \\([0-9]\\) [0-9]/at_label = \\1 3/", "at_label",
     "expected a permutation of the replicas, each with a direction 0, 1 or 2"},
    {"s/^swaps = .*/swaps = 5 6 5 0/", "swaps", "more accepted than tried at pair 0"},
    {"s/^window = .*/window = 9 0 5 0/", "window", "9 tried at pair 0, beyond the 5 of swaps"},
    {"s/^trace_mark = .*/trace_mark = 9 0 5 0/", "trace_mark", "9 tried at pair 0, beyond the 5 of swaps"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    cr_assert_eq(lw_test_sh("grep -q '^%s = ' %s/r/state.lw", bad[i].key, dir), 0);
    cr_expect_eq(resume_edited(bad[i].sed), 2, "edit '%s'", bad[i].sed);
    cr_expect_eq(lw_test_sh("grep -q \"x/state.lw:$(grep -n '^%s = ' %s/r/state.lw | cut -d: -f1): \\[tempering\\] "
                            "%s: %s\" %s/err.txt", bad[i].key, dir, bad[i].key, bad[i].msg, dir),
                 0, "edit '%s': %s", bad[i].sed, lw_test_slurp("%s/err.txt", dir));
  }
}

/* The adaptive schedule's temperature follows from the previous step's and
** the energies the file holds: an edited one (5, 0, 1e300) ran the rest of
** the run there, and energies with a negative variance, or more samples
** than the step has had sweeps, made the next temperature without a word.
** Under tempering (whose rule changed on 2026-12-04) its range is checked. */
Test(checkpoint, an_adaptive_schedules_state_is_checked_on_resume)
{
  /* (2 tuning sweeps a step of 10: the temperature is made of step 1's 8
  ** energies, and step 2 has 3 of its own) */
  cr_assert_eq(lw_test_sh("%s run %s/tests/fixtures/v1/plain.ini --out %s/r --stop-at 25 --quiet --set "
                          "anneal.schedule=adaptive --set moves.tune_sweeps=2", lw_test_bin(),
                          lw_test_root(), dir), 0);
  cr_assert_eq(lw_test_sh("grep -q '^prev_stats = .* 8$' %s/r/state.lw && grep -q '^block_energy = 3 ' %s/r/state.lw",
                          dir, dir), 0);
  static const struct { const char *sed, *msg; } bad[] = {
    {"s/^temperature = .*/temperature = 5/", "[run] temperature: 5, but the adaptive schedule"},
    {"s/^temperature = .*/temperature = 0/", "[run] temperature: 0, but the adaptive schedule"},
    {"s/^temperature = .*/temperature = 1e300/", "[run] temperature: 1.0000000000000001e+300, but the adaptive"},
    {"s/^block_energy = .*/block_energy = 3 1000 2372/", "[run] block_energy: 3 samples with sum 1000 and sum of "
     "squares 2372 make a negative variance: the state was edited"},
    {"s/^block_energy = .*/block_energy = 4 1 1/", "[run] block_energy: 4 samples, but the step has had 3 sweeps since "
     "its step tuning"},
    {"s/^block_energy = .*/block_energy = 0 5 30/", "[run] block_energy: no samples, but sums 5 and 30"},
    /* the measured rule, from the previous step's energies (the state's own
    ** temperature, then the one they make) */
    {"s/^prev_stats = \\([^ ]*\\) [^ ]* 8$/prev_stats = \\1 0.5 8/", "step 2 is at "},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    int rc = resume_edited(bad[i].sed);
    cr_expect_eq(rc, 2, "edit '%s': exit %d", bad[i].sed, rc);
    cr_expect(err_has(bad[i].msg), "edit '%s': message lacks '%s'", bad[i].sed, bad[i].msg);
  }
  cr_assert_eq(resume_edited("s/^sweep = 25$/sweep = 25/"), 0);
  /* a file of before 2026-12-07 sums the energies whole, shift 0, to its
  ** end: its checkpoints write no shift (the step's first sample here) */
  cr_assert_eq(lw_test_sh("grep -q '^block_shift = ' %s/x/state.lw", dir), 0);
  cr_assert_eq(resume_edited("/^block_shift = /d;$d"), 0);
  cr_assert_neq(lw_test_sh("grep -q '^block_shift' %s/x/state.lw", dir), 0);
  cr_assert_eq(lw_test_sh("rm -rf %s/r && %s run %s/tests/fixtures/v1/plain.ini --out %s/r --stop-at 25 --quiet --set "
                          "anneal.schedule=adaptive --set tempering.replicas=2", dir, lw_test_bin(), lw_test_root(),
                          dir), 0);
  cr_expect_eq(resume_edited("s/^temperature = .*/temperature = 5/"), 2);
  cr_expect(err_has("[run] temperature: 5, outside the adaptive schedule") &&
            err_has("range [0.01, 1]: the state was edited"));
  cr_assert_eq(resume_edited("s/^sweep = 25$/sweep = 25/"), 0);
}

/* A change no value's own check sees (a node moved in its 14th digit, under
** the energy's 1e-6 check; of 120 single flipped bits 40 resumed) is the
** checksum's: the last line, of every byte before it.  Taken out, the
** state is resumed as one edited on purpose; a state without one (older, or
** written by hand) is read as before. */
Test(checkpoint, a_change_no_value_check_sees_is_the_checksums)
{
  stopped_run();
  cr_assert_eq(lw_test_sh("tail -n 1 %s/r/state.lw | grep -qx '# checksum [0-9a-f]\\{16\\}'", dir), 0);
  const char *nudge = "0,/^node = \\([^ ]*\\)[0-9] /s//node = \\11 /";
  cr_assert_eq(resume_edited(nudge), 2);
  cr_assert_eq(lw_test_sh("cmp -s %s/r/state.lw %s/x/state.lw", dir, dir), 1, "the edit changed nothing");
  cr_assert(err_has("x/state.lw:") && err_has(": its checksum does not match its contents: the file was damaged (a "
                                               "disk's or a copy's fault) or edited since linewise wrote it"));
  /* a blank line after it, or Windows line ends, with the nudge: refused
  ** (each skipped the sum, unsaid); with Windows line ends alone, a copy
  ** that changed nothing, it resumes */
  char more[256];
  snprintf(more, sizeof more, "%s;$s/$/\\n/", nudge);
  cr_assert_eq(resume_edited(more), 2);
  snprintf(more, sizeof more, "%s;s/$/\\r/", nudge);
  cr_assert_eq(resume_edited(more), 2);
  cr_assert(err_has(": its checksum does not match its contents"));
  cr_assert_eq(resume_edited("s/$/\\r/"), 0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* a line after it is an edit too, and so is its line put out of form
  ** (read as none, it let the damage through) */
  cr_assert_eq(resume_edited("s/^# checksum/#checksum/"), 2);
  cr_assert(err_has(": its checksum's line is not its last, or not '# checksum' and 16 hex digits"));
  cr_assert_eq(resume_edited("$s/$/\\n# a note/"), 2);
  cr_assert(err_has("x/state.lw:") && err_has(": its checksum's line is not its last") && !err_has("state.lw: its"));
  /* taken out on purpose, the run goes on, and its next state has one again */
  snprintf(more, sizeof more, "%s;$d", nudge);
  cr_assert_eq(resume_edited(more), 0, "%s", lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(lw_test_sh("tail -n 1 %s/x/state.lw | grep -q '^# checksum '", dir), 0);
  cr_assert_eq(resume_edited("$d"), 0);
}

/* A state.lw cut short (a partial copy) is said to be.  Cut inside [run] or
** [chain] it was blamed on "a state of another system?", naming no line;
** cut inside its last number it resumed with that number shortened.  Every
** state ends its last line, so one that does not is refused at once; one cut
** at a line's end names what is missing and where the file ends. */
Test(checkpoint, a_state_cut_short_is_said_to_be)
{
  stopped_run();
  /* in [run], in [chain]'s rng, after it (of 13899 bytes), and 4 bytes into the last number */
  static const long at[] = {300, 5000, 11220, -5};
  for (size_t i = 0; i < sizeof at / sizeof at[0]; i++) {
    /* (a byte less where the cut falls at a line's end: the state's bytes
    ** move with its keys) */
    lw_test_sh("rm -rf %s/x && cp -r %s/r %s/x && truncate -s %s%ld %s/x/state.lw && "
               "if test \"$(tail -c 1 %s/x/state.lw)\" = ''; then truncate -s -1 %s/x/state.lw; fi", dir, dir, dir,
               at[i] < 0 ? "-" : "", at[i] < 0 ? -at[i] : at[i], dir, dir, dir);
    cr_assert_eq(lw_test_sh("test \"$(tail -c 1 %s/x/state.lw)\" != ''", dir), 0, "cut inside a line");
    cr_expect_eq(lw_test_sh("%s resume %s/x --quiet 2>%s/err.txt", lw_test_bin(), dir, dir), 2, "cut at %ld", at[i]);
    cr_expect(err_has(": the file ends inside this line: cut short (a partial copy, a full disk?)"), "cut at %ld",
              at[i]);
  }
  lw_test_sh("rm -rf %s/x && cp -r %s/r %s/x && sed -i '/^\\[system splines\\]$/,$d' %s/x/state.lw", dir, dir, dir,
             dir);
  cr_expect_eq(lw_test_sh("%s resume %s/x --quiet 2>%s/err.txt", lw_test_bin(), dir, dir), 2);
  cr_expect(err_has("x/state.lw: section [system splines]: missing (a state of another system, or a file cut short: "
                    "it ends at its line 50)"));
  /* cut after a whole node line: the spline short of its last node (and
  ** the checksum after it) */
  lw_test_sh("rm -rf %s/x && cp -r %s/r %s/x && sed -i '$d' %s/x/state.lw && sed -i '$d' %s/x/state.lw", dir, dir,
             dir, dir, dir);
  cr_expect_eq(lw_test_sh("%s resume %s/x --quiet 2>%s/err.txt", lw_test_bin(), dir, dir), 2);
  cr_expect(err_has("got the end of the section, where the file ends (cut short by a partial copy or a full disk, or "
                    "edited?) (its"));
  /* cut right after the section's name (it said line 0 and an empty key) */
  lw_test_sh("rm -rf %s/x && cp -r %s/r %s/x && sed -i '/^\\[system splines\\]$/q' %s/x/state.lw", dir, dir, dir, dir);
  cr_expect_eq(lw_test_sh("%s resume %s/x --quiet 2>%s/err.txt", lw_test_bin(), dir, dir), 2);
  cr_expect(err_has("x/state.lw: [system splines]: expected ") &&
            err_has(" first, got the end of the section, where the file ends"));
}

Test(checkpoint, a_state_with_an_infinite_energy_is_refused_with_the_spline_and_segment)
{
  stopped_run();
  /* spline 1 moved off the page as a whole: regular, but outside the boundary */
  cr_assert_eq(lw_test_sh("rm -rf %s/x && cp -r %s/r %s/x && awk '/^spline = /{n++} /^node = /&&n==2{$3+=500} {print}' "
                          "%s/r/state.lw > %s/x/state.lw", dir, dir, dir, dir, dir), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/x --quiet 2>%s/err.txt", lw_test_bin(), dir, dir), 2);
  cr_assert(err_has("spline 1 segment 0 (nodes 0 and 1): the boundary energy is not finite"));
  cr_assert_eq(lw_test_sh("%s energy %s/x 2>%s/err.txt", lw_test_bin(), dir, dir), 2);
  cr_assert(err_has("spline 1 segment 0 (nodes 0 and 1): the boundary energy is not finite"));
}

Test(checkpoint, rows_written_after_the_checkpoint_are_cut_back_on_resume)
{
  stopped_run();
  /* what a kill between the checkpoint and the next leaves: later rows, the
  ** last one torn */
  cr_assert_eq(lw_test_sh("cp -r %s/r %s/x && printf '21,0.3,1\n22,0.3,1\n2' >> %s/x/trace.csv", dir, dir, dir), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/r --quiet && %s resume %s/x --quiet", lw_test_bin(), dir, lw_test_bin(), dir), 0);
  cr_assert_eq(lw_test_sh("cmp -s %s/r/trace.csv %s/x/trace.csv", dir, dir), 0);
  /* a trace shorter than the checkpoint says was cut or replaced: refused */
  cr_assert_eq(lw_test_sh("rm -rf %s/r && %s run %s/tests/fixtures/v1/plain.ini --out %s/r --stop-at 20 --quiet && "
                          "truncate -s 100 %s/r/trace.csv", dir, lw_test_bin(), lw_test_root(), dir, dir), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/r --quiet 2>%s/err.txt", lw_test_bin(), dir, dir), 2);
  cr_assert(err_has("trace.csv: 100 bytes, but state.lw counts"));
}

/* resume --sweeps N saves its end with the state: stopped on the way, a
** plain resume goes on to it and ends as the extension run at once; while
** it runs the run is not finished, so summary.json is gone. */
Test(checkpoint, an_extension_stopped_on_the_way_resumes_to_its_own_end)
{
  const char *b = lw_test_bin();
  cr_assert_eq(lw_test_sh("%s run %s/tests/fixtures/v1/plain.ini --out %s/a --quiet && cp -r %s/a %s/b", b,
                          lw_test_root(), dir, dir, dir),
               0);
  cr_assert_eq(lw_test_sh("%s resume %s/a --sweeps 30 --quiet", b, dir), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/b --sweeps 30 --stop-at 75 --quiet", b, dir), 0);
  cr_assert_eq(lw_test_sh("! test -e %s/b/summary.json && grep -qx 'end_sweep = 90' %s/b/state.lw", dir, dir), 0,
               "the stopped extension kept a summary.json or lost its end");
  cr_assert_eq(lw_test_sh("%s resume %s/b --quiet", b, dir), 0);
  static const char *const files[] = {"state.lw", "trace.csv", "final.svg", "final.png"};
  for (int k = 0; k < 4; k++)
    cr_expect_eq(lw_test_sh("cmp -s %s/a/%s %s/b/%s", dir, files[k], dir, files[k]), 0, "%s differs", files[k]);
  cr_assert_eq(lw_test_sh("grep -qx 'sweep = 90' %s/b/state.lw && grep -q '\"sweeps\": 90' %s/b/summary.json", dir,
                          dir),
               0);
}

/* resume --sweeps N on a run short of its end, N within it: the sweeps run
** and stop there, unfinished, as --stop-at; a plain resume then goes on to
** the schedule's end, as the run that never stopped (sweep 50 + 20 once
** became the end: a summary of a run half cooled, t_end never reached). */
Test(checkpoint, more_sweeps_short_of_the_end_stop_there_and_leave_the_end)
{
  const char *b = lw_test_bin();
  const char *set = "--set anneal.sweeps=103 --set anneal.steps=7 --quiet --threads 1";
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini %s --out %s/a --stop-at 50 && "
                          "%s run %s/params/minimal.ini %s --out %s/b", b, lw_test_root(), set, dir, b,
                          lw_test_root(), set, dir),
               0);
  cr_assert_eq(lw_test_sh("%s resume %s/a --sweeps 20 --quiet", b, dir), 0);
  cr_assert_eq(lw_test_sh("! test -e %s/a/summary.json && grep -qx 'sweep = 70' %s/a/state.lw && "
                          "grep -qx 'end_sweep = 103' %s/a/state.lw", dir, dir, dir),
               0, "the sweeps short of the end ended the run there");
  cr_assert_eq(lw_test_sh("%s resume %s/a --quiet", b, dir), 0);
  static const char *const files[] = {"state.lw", "trace.csv", "final.svg"};
  for (int k = 0; k < 3; k++)
    cr_expect_eq(lw_test_sh("cmp -s %s/a/%s %s/b/%s", dir, files[k], dir, files[k]), 0, "%s differs", files[k]);
}

/* The new end of an extension is in state.lw before its first sweep: a
** kill before the extension's first checkpoint still resumes to it. */
Test(checkpoint, an_extension_killed_before_its_first_checkpoint_keeps_its_end)
{
  const char *b = lw_test_bin();
  cr_assert_eq(lw_test_sh("%s run %s/params/example.ini --set anneal.sweeps=2 --set init.splines=200 --out %s/a "
                          "--quiet", b, lw_test_root(), dir), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/a --sweeps 1000 2>%s/err.txt & p=$!; i=0; "
                          "until grep -q 'resuming' %s/err.txt || [ $i -gt 600 ]; do sleep 0.05; i=$((i+1)); done; "
                          "kill -KILL $p; wait $p; test $? -eq 137",
                          b, dir, dir, dir),
               0);
  cr_assert_eq(lw_test_sh("grep -qx 'end_sweep = 1002' %s/a/state.lw && grep -qx 'sweep = 2' %s/a/state.lw && "
                          "! test -e %s/a/summary.json", dir, dir, dir),
               0, "the extension's end was not saved before its first sweep");
}

/* scene.ini is what the run ran with: an edit of a key that steers the
** run is refused on resume; [plot] and the final files' keys may change. */
Test(checkpoint, a_scene_ini_edited_in_a_key_that_steers_the_run_is_refused)
{
  const char *b = lw_test_bin();
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set anneal.sweeps=40 --out %s/a --quiet --stop-at 20 && "
                          "cp %s/a/scene.ini %s/scene.keep", b, lw_test_root(), dir, dir, dir), 0);
  /* an energy coefficient too: the state's energies then differ from the
  ** file's, which was reported first, blaming state.lw */
  static const char *const steer[] = {"s/^t_end = .*/t_end = 0.5/", "s/^domains = off/domains = 2/",
                                      "s/^trace_every = .*/trace_every = 3/", "s/^point = .*/point = 0.9/",
                                      "s/^bending = .*/bending = 1.5/"};
  static const char *const key[] = {"anneal.t_end", "anneal.domains", "output.trace_every", "moves.point",
                                    "energy.bending"};
  for (int k = 0; k < 5; k++) {
    cr_assert_eq(lw_test_sh("sed -i '%s' %s/a/scene.ini && ! cmp -s %s/a/scene.ini %s/scene.keep", steer[k], dir, dir,
                            dir), 0, "%s", steer[k]);
    cr_assert_eq(lw_test_sh("%s resume %s/a --quiet 2>%s/err.txt", b, dir, dir), 2, "%s", steer[k]);
    /* the message names the key and its line */
    cr_assert_eq(lw_test_sh("grep -q \"a/scene.ini: '%s' (line [0-9]*) edited since the run started\" "
                            "%s/err.txt && grep -qx 'sweep = 20' %s/a/state.lw", key[k], dir, dir), 0, "%s", steer[k]);
    cr_assert_eq(lw_test_sh("cp %s/scene.keep %s/a/scene.ini", dir, dir), 0);
  }
  /* another run's state.lw: not blamed on an edit */
  cr_assert_eq(lw_test_sh("%s run %s/params/study.ini --set anneal.sweeps=40 --out %s/other --quiet --stop-at 0 && "
                          "cp %s/a/state.lw %s/state.keep && cp %s/other/state.lw %s/a/", b, lw_test_root(), dir, dir,
                          dir, dir, dir), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/a --quiet 2>%s/err.txt", b, dir, dir), 2);
  cr_assert_eq(lw_test_sh("grep -q 'state.lw and .*scene.ini seem to be of different runs: [0-9]* keys differ' "
                          "%s/err.txt", dir), 0);
  cr_assert_eq(lw_test_sh("cp %s/state.keep %s/a/state.lw", dir, dir), 0);
  /* a key's line taken out of scene.ini: said so, naming the key where
  ** the other keys' hashes line up around the gap, and in general where
  ** another key was edited beside it */
  cr_assert_eq(lw_test_sh("sed -i '/^strain = /d' %s/a/scene.ini && %s resume %s/a --quiet 2>%s/err.txt; test $? = 2 "
                          "&& grep -q \"a/scene.ini: 1 key fewer than when the run started: the line of "
                          "'energy.strain' taken out\" %s/err.txt", dir, b, dir, dir, dir), 0,
               "%s", lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(lw_test_sh("sed -i 's/^bending = .*/bending = 7/' %s/a/scene.ini && %s resume %s/a --quiet "
                          "2>%s/err.txt; test $? = 2 && grep -q 'a/scene.ini: 1 key fewer than when the run started "
                          "(a key.s line taken out?)' %s/err.txt", dir, b, dir, dir, dir), 0,
               "%s", lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(lw_test_sh("cp %s/scene.keep %s/a/scene.ini", dir, dir), 0);
  cr_assert_eq(lw_test_sh("sed -i -e 's/^min_length = .*/min_length = 0/' -e 's/^png_scale = .*/png_scale = 2/' "
                          "%s/a/scene.ini && %s resume %s/a --quiet", dir, b, dir), 0,
               "a key of the drawing only was refused");
}

/* The files a run reads count by their bytes, not their names: a run whose
** table moved resumes once scene.ini names the new place (to the result of
** a run left alone); one whose table was edited is refused, naming the key,
** and so is one whose table is gone. */
Test(checkpoint, a_run_resumes_with_its_files_wherever_they_are_and_not_with_others)
{
  const char *b = lw_test_bin();
  cr_assert_eq(lw_test_sh("mkdir %s/t1 && printf '0 1\\n10 0.2\\n39 0.01\\n' > %s/t1/table.txt", dir, dir), 0);
  const char *set = "--set anneal.sweeps=40 --set anneal.schedule=table --set output.trace_every=1";
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini %s --set anneal.table=%s/t1/table.txt --out %s/whole "
                          "--quiet && %s run %s/params/minimal.ini %s --set anneal.table=%s/t1/table.txt --out %s/a "
                          "--quiet --stop-at 20", b, lw_test_root(), set, dir, dir, b, lw_test_root(), set, dir, dir),
               0);
  cr_assert_eq(lw_test_sh("cp -r %s/a %s/keep && cp -r %s/a %s/rel && mv %s/t1 %s/t2", dir, dir, dir, dir, dir, dir),
               0);
  /* a path edited into scene.ini is relative to it, from any directory */
  cr_assert_eq(lw_test_sh("cp %s/t2/table.txt %s/rel/ && sed -i 's#^table = .*#table = table.txt#' %s/rel/scene.ini && "
                          "cd / && %s resume %s/rel --quiet && cmp %s/rel/final.svg %s/whole/final.svg", dir, dir, dir,
                          b, dir, dir, dir), 0, "a table named relative to the run's scene.ini");
  cr_assert_eq(lw_test_sh("%s resume %s/a --quiet 2>%s/err.txt", b, dir, dir), 2);
  /* (nothing was edited: it said "undo the edit") */
  cr_assert_eq(lw_test_sh("grep -q \"a/scene.ini:[0-9]*: key 'anneal.table': cannot read .*t1/table.txt: No such "
                          "file or directory (a run resumes with the files it ran with: put the file back, or set "
                          "this key in .*a/scene.ini to the place it moved to)$\" %s/err.txt", dir), 0, "%s",
               lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(lw_test_sh("sed -i 's#/t1/table.txt#/t2/table.txt#' %s/a/scene.ini && %s resume %s/a --quiet && "
                          "cmp %s/a/final.svg %s/whole/final.svg && cmp %s/a/trace.csv %s/whole/trace.csv", dir, b, dir,
                          dir, dir, dir, dir), 0, "the moved table's run did not resume as if left alone");
  cr_assert_eq(lw_test_sh("sed -i 's#/t1/table.txt#/t2/table.txt#' %s/keep/scene.ini && "
                          "printf '0 5\\n39 3\\n' > %s/t2/table.txt", dir, dir), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/keep --quiet 2>%s/err.txt", b, dir, dir), 2);
  cr_assert_eq(lw_test_sh("grep -q \"keep/scene.ini: 'anneal.table' (line [0-9]*) edited since the run started, or "
                          "the file it names changed\" %s/err.txt && grep -qx 'sweep = 20' %s/keep/state.lw", dir, dir),
               0);
}

/* --stop-at at the sweep the run stands at stops before any sweep; one it
** has passed is refused; 0 on a new run stops after the set-up. */
Test(checkpoint, stop_at_a_sweep_reached_runs_no_sweep)
{
  const char *b = lw_test_bin();
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set anneal.sweeps=40 --out %s/a --quiet --stop-at 0 && "
                          "grep -qx 'sweep = 0' %s/a/state.lw", b, lw_test_root(), dir, dir), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/a --quiet --stop-at 12 && %s resume %s/a --quiet --stop-at 12 && "
                          "grep -qx 'sweep = 12' %s/a/state.lw", b, dir, b, dir, dir), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/a --stop-at 5 2>%s/err.txt", b, dir, dir), 2);
  cr_assert_eq(lw_test_sh("grep -q 'stands at sweep 12 already; expected 12 or more' %s/err.txt && "
                          "grep -qx 'sweep = 12' %s/a/state.lw", dir, dir), 0);
  /* a refused extension of a finished run leaves it finished, with its end */
  cr_assert_eq(lw_test_sh("%s resume %s/a --quiet && test -e %s/a/summary.json && cp %s/a/state.lw %s/was.lw",
                          b, dir, dir, dir, dir), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/a --sweeps 5 --stop-at 2 --quiet 2>/dev/null", b, dir), 2);
  cr_assert_eq(lw_test_sh("test -e %s/a/summary.json && cmp -s %s/a/state.lw %s/was.lw", dir, dir, dir), 0,
               "the refused extension changed the run");
}

/* A finished run resumed keeps a whole-run proposal rate. */
Test(checkpoint, a_resumed_run_keeps_its_whole_proposal_rate)
{
  const char *b = lw_test_bin();
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set anneal.sweeps=10 --set 'tempering.ladder=0.01 0.1 1' "
                          "--out %s/a --quiet && %s resume %s/a --quiet", b, lw_test_root(), dir, b, dir), 0);
  cr_assert_eq(lw_test_sh("awk -F: '/\"proposals\"/ { p = $2 + 0 } /\"sweep_seconds\"/ { w = $2 + 0 } "
                          "/\"proposals_per_second\"/ { r = $2 + 0 } END { exit !(r > 0 && w > 0 && "
                          "(r * w / p - 1) ^ 2 < 1e-6) }' %s/a/summary.json", dir), 0,
               "proposals_per_second is not proposals / sweep_seconds");
}

/* A step the scene sets above the row's cap (tuning never grows one past
** it) stays as set where nothing tunes it: moves.tune_sweeps = 0, or a
** step the dynamics never uses.  The checkpoint kept it and resume
** refused it ("expected 1 number from 1e-300 to 100"), so such a run could
** never go on; now it resumes to the bytes of one that did not stop.  So
** does a step below the 1e-300 that tuning keeps to, which the scene
** allows (any step above 0; 1e-300 degrees is 1.7e-302 radians). */
Test(checkpoint, a_step_outside_the_tuned_range_that_nothing_tuned_resumes)
{
  const char *b = lw_test_bin(), *r = lw_test_root();
  static const char *const runs[][2] = {
      {"minimal.ini", "--set anneal.sweeps=20 --set moves.tune_sweeps=0 --set moves.step_point=1000"},
      {"wire.ini", "--set anneal.sweeps=20 --set nurbs.step_weight=5 --set output.frames_every=0"},
      {"minimal.ini", "--set anneal.sweeps=20 --set moves.tune_sweeps=0 --set moves.step_vector=1e-320"},
      {"particles-sheet.ini", "--set anneal.sweeps=20 --set moves.tune_sweeps=0 --set moves.step_rotate=1e-300"}};
  for (int k = 0; k < 4; k++) {
    cr_assert_eq(lw_test_sh("%s run %s/params/%s %s --out %s/u%d --quiet", b, r, runs[k][0], runs[k][1], dir, k), 0);
    cr_assert_eq(lw_test_sh("%s run %s/params/%s %s --out %s/s%d --quiet --stop-at 7", b, r, runs[k][0], runs[k][1],
                            dir, k), 0);
    cr_assert_eq(lw_test_sh("%s resume %s/s%d --quiet 2>%s/err.txt", b, dir, k, dir), 0, "%s", runs[k][0]);
    cr_assert_eq(lw_test_sh("cmp -s %s/u%d/state.lw %s/s%d/state.lw && cmp -s %s/u%d/trace.csv %s/s%d/trace.csv", dir,
                            k, dir, k, dir, k, dir, k), 0, "%s resumed differently", runs[k][0]);
  }
}

/* tests/fixtures/<v>/<name>: a run of <name>.ini (its picture <name>.png)
** written by a release before an energy change that a key keeps for it,
** stopped at sweep 12 of 30, and <name>-whole that release's uninterrupted
** run.  Its scene.ini has no line for the key: resumed, it keeps the energy
** it ran with and ends on that release's files to the bit (it was refused,
** the running potential term not the state's); a new run of the same scene
** takes the new energy, another potential. */
static void resume_from_before(const char *v, const char *name, const char *key)
{
  cr_assert_eq(lw_test_sh("cp -r %s/tests/fixtures/%s %s/%s && cd %s/%s && sed -i \"s|^image = .*|image = "
                          "$PWD/%s.png|\" %s/scene.ini && ! grep -q '^%s' %s/scene.ini", lw_test_root(), v, dir, v, dir,
                          v, name, name, key, name), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/%s/%s --quiet 2> %s/err.txt", lw_test_bin(), dir, v, name, dir), 0, "%s",
               lw_test_slurp("%s/err.txt", dir));
  static const char *const file[] = {"state.lw", "trace.csv"};
  for (int f = 0; f < 2; f++)
    cr_expect_eq(lw_test_sh("cmp -s %s/%s/%s/%s %s/%s/%s-whole/%s", dir, v, name, file[f], dir, v, name, file[f]), 0,
                 "%s differs from the old release's run", file[f]);
  cr_assert_eq(lw_test_sh("cd %s/%s && %s run %s.ini --set init.from=%s/state.lw --set anneal.sweeps=0 --out fresh "
                          "--quiet && %s energy %s | grep '^potential ' > a.txt && grep -q '\"potential\": ' "
                          "fresh/summary.json && ! grep -q \"\\\"potential\\\": $(cut -d' ' -f2 a.txt)\" "
                          "fresh/summary.json", dir, v, lw_test_bin(), name, name, lw_test_bin(), name), 0);
}

/* v2/paper: from before the blurred potential read white paper beyond the
** picture (2026-12-06; scene.potential_paper): its potential continued the
** picture's dark bottom edge below it. */
Test(checkpoint, a_run_from_before_the_white_paper_resumes_to_its_own_end)
{
  resume_from_before("v2", "paper", "potential_paper");
}

/* v4/light: a D-NURBS wire from before the quadrature's pieces beside a
** clamped end followed the knot's multiplicity (2026-12-07; nurbs.pieces),
** its end point of weight 0.01: resumed, it ends on that release's files to
** the bit; the same state in a new run reads the curve's energy, 1.7 times
** the old one (0.58 of it was read). */
Test(checkpoint, a_nurbs_run_from_before_the_clamped_pieces_resumes_to_its_own_end)
{
  const char *b = lw_test_bin();
  cr_assert_eq(lw_test_sh("cp -r %s/tests/fixtures/v4 %s/v4 && ! grep -q '^pieces' %s/v4/light/scene.ini && "
                          "%s resume %s/v4/light --quiet 2> %s/err.txt", lw_test_root(), dir, dir, b, dir, dir), 0,
               "%s", lw_test_slurp("%s/err.txt", dir));
  static const char *const file[] = {"state.lw", "trace.csv"};
  for (int f = 0; f < 2; f++)
    cr_expect_eq(lw_test_sh("cmp -s %s/v4/light/%s %s/v4/light-whole/%s", dir, file[f], dir, file[f]), 0,
                 "%s differs from the old release's run", file[f]);
  cr_assert_eq(lw_test_sh("cd %s/v4 && %s energy light | grep '^elastic ' | cut -d' ' -f2 > old.txt && %s run light.ini "
                          "--set init.from=light/state.lw --set anneal.sweeps=0 --out fresh --quiet && %s energy fresh | "
                          "grep '^elastic ' | cut -d' ' -f2 > new.txt", dir, b, b, b), 0);
  /* and its redraw from its own scene.ini (FORMATS' recipe), which holds a
  ** picture key at that day's default, since changed, that the D-NURBS
  ** system reads not (it was refused, naming the key) */
  cr_assert_eq(lw_test_sh("cd %s/v4 && %s run light/scene.ini --set init.from=light/state.lw --set anneal.sweeps=0 "
                          "--out redraw --quiet 2> err.txt", dir, b), 0, "%s", lw_test_slurp("%s/v4/err.txt", dir));
  char *o = lw_test_slurp("%s/v4/old.txt", dir), *n = lw_test_slurp("%s/v4/new.txt", dir);
  cr_assert(o && n && atof(n) > 1.5 * atof(o), "the curve's energy %s, the old pieces' %s", n ? n : "-", o ? o : "-");
  free(o);
  free(n);
}

/* v3/levels: from before the levels of a half-transparent picture were of
** the picture under its transparency (2026-12-06; scene.image_levels_alpha). */
Test(checkpoint, a_run_from_before_the_levels_under_alpha_resumes_to_its_own_end)
{
  resume_from_before("v3", "levels", "image_levels_alpha");
}

