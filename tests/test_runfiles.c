/*
** test_runfiles.c -- the run before set aside in DIR/.replaced while a new
** run starts there (runfiles.h).  Made with files of the run's names, whose
** contents say whose they are: "old" the run before's, "new" the new run's,
** "mine" the user's, which nothing may touch.
*/
#include <criterion/criterion.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "linewise/rundir.h"
#include "linewise/runfiles.h"
#include "testutil.h"

static char dir[64];

static void make_dir(void) { cr_assert_eq(lw_test_dir_make(dir, "rfiles"), 0); }
static void remove_dir(void) { cr_assert_eq(lw_test_dir_remove(dir), 0); }

TestSuite(runfiles, .init = make_dir, .fini = remove_dir);

#define sh lw_test_sh

/* A finished run with frames and plots, and the user's files beside. */
static void old_run(void)
{
  cr_assert_eq(sh("cd %s && mkdir -p r/frames r/plots && printf '%s\\nold\\n' > r/scene.ini && "
                  "for f in state.lw final.svg summary.json frames/frame-000100.png plots/energy.png "
                  "replica-1.lw; do echo old > r/$f; done && echo mine > r/notes.txt && echo mine > "
                  "r/frames/keep.txt && echo mine > r/plots/mine.png", dir, LW_RUN_SCENE_HEADER), 0);
}

/* Every file of the run before is back with its bytes, the user's too,
** and nothing else of the run's names is there. */
static void old_run_is_back(const char *when)
{
  cr_assert_eq(sh("cd %s/r && grep -qx old scene.ini && for f in state.lw final.svg summary.json "
                  "frames/frame-000100.png plots/energy.png replica-1.lw; do grep -qx old $f || exit 1; done && "
                  "grep -qx mine notes.txt && grep -qx mine frames/keep.txt && grep -qx mine plots/mine.png && "
                  "! test -e trace.csv && ! test -e frames/frame-000000.png && ! test -e .replaced", dir), 0,
               "%s", when);
}

/* Set aside, the run leaves only the user's files; the new run's files,
** some of the old names and some not, go when the run before comes back. */
Test(runfiles, a_run_set_aside_comes_back_over_the_new_runs_files)
{
  old_run();
  lw_error err;
  char r[96];
  snprintf(r, sizeof r, "%s/r", dir);
  cr_assert_eq(lw_runfiles_stash(r, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(sh("cd %s/r && ! test -e scene.ini && ! test -e frames/frame-000100.png && ! test -e plots/energy.png "
                  "&& grep -qx mine notes.txt && grep -qx mine plots/mine.png && test -f .replaced/.moved", dir), 0);
  /* the new run's set-up: a scene.ini and state.lw over the old names, a
  ** trace and a first frame the old run did not have */
  cr_assert_eq(sh("cd %s/r && for f in scene.ini state.lw trace.csv frames/frame-000000.png; do echo new > $f; "
                  "done", dir), 0);
  cr_assert_eq(lw_runfiles_unstash(r, &err), LW_OK, "%s", err.msg);
  old_run_is_back("put back");
  /* set aside again, and the new run had its checkpoint: the stash goes */
  cr_assert_eq(lw_runfiles_stash(r, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(lw_runfiles_drop(r, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(sh("cd %s/r && ! test -e .replaced && grep -qx mine notes.txt && ! test -e state.lw", dir), 0);
}

/* A process killed with the stash there: the next run or resume settles
** it.  Killed while moving (.moving): some files still in DIR, all are the
** run before's.  Killed after (.moved) without a state.lw: the new run's
** files go.  Killed after its first checkpoint: the stash goes. */
Test(runfiles, a_stash_a_killed_process_left_is_settled)
{
  lw_error err;
  char r[96];
  int back = -1;
  snprintf(r, sizeof r, "%s/r", dir);
  /* killed while moving: state.lw and the frame moved, the rest not yet */
  old_run();
  cr_assert_eq(sh("cd %s/r && mkdir -p .replaced/frames && touch .replaced/.moving && mv state.lw .replaced/ && "
                  "mv frames/frame-000100.png .replaced/frames/", dir), 0);
  cr_assert_eq(lw_runfiles_recover(r, &back, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(back, 1);
  old_run_is_back("killed while moving");
  /* killed in the set-up after the move */
  cr_assert_eq(lw_runfiles_stash(r, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(sh("cd %s/r && echo new > scene.ini && echo new > trace.csv && echo new > state.lw.tmp", dir), 0);
  cr_assert_eq(lw_runfiles_recover(r, &back, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(back, 1);
  old_run_is_back("killed in the set-up");
  cr_assert_neq(sh("test -e %s/r/state.lw.tmp", dir), 0);
  /* killed while putting it back: state.lw back already, scene.ini still the
  ** new run's in dir and the old in the stash (marked .moved, the next
  ** recover took the old state.lw for the new run's and dropped the rest) */
  cr_assert_eq(lw_runfiles_stash(r, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(sh("cd %s/r && echo new > scene.ini && mv .replaced/.moved .replaced/.restoring && "
                  "mv .replaced/state.lw state.lw", dir), 0);
  cr_assert_eq(lw_runfiles_recover(r, &back, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(back, 1);
  old_run_is_back("killed while putting it back");
  /* killed with the stash made and no marker yet, or its marker gone and
  ** the folder not: an empty .replaced is removed (it was refused as not
  ** linewise's, and the directory blocked) */
  cr_assert_eq(sh("mkdir %s/r/.replaced", dir), 0);
  cr_assert_eq(lw_runfiles_recover(r, &back, &err), LW_OK, "%s", err.msg);
  old_run_is_back("an empty stash");
  /* killed between the first checkpoint and dropping the stash */
  cr_assert_eq(lw_runfiles_stash(r, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(sh("cd %s/r && echo new > scene.ini && echo new > state.lw", dir), 0);
  cr_assert_eq(lw_runfiles_recover(r, &back, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(back, 0);
  cr_assert_eq(sh("cd %s/r && grep -qx new state.lw && ! test -e .replaced && ! test -e final.svg && "
                  "grep -qx mine notes.txt", dir), 0);
}

/* A .replaced that linewise did not make (a folder of the user's, a link
** to another run, a file) is refused and nothing is touched: a link was
** followed, and the run it led to was deleted. */
Test(runfiles, a_replaced_that_is_not_linewises_is_refused_and_left_alone)
{
  static const char *const make[] = {
    "mkdir .replaced && echo mine > .replaced/mine.txt && echo old > .replaced/state.lw", "ln -s ../other .replaced",
    "echo mine > .replaced"};
  char r[96];
  snprintf(r, sizeof r, "%s/r", dir);
  for (size_t k = 0; k < sizeof make / sizeof make[0]; k++) {
    old_run();
    cr_assert_eq(sh("cd %s && rm -rf other && mkdir other && echo other > other/state.lw && cd r && %s", dir, make[k]),
                 0);
    lw_error err;
    int back = -1;
    cr_assert_eq(lw_runfiles_check_stash(r, &err), LW_EUSAGE, "case %zu", k);
    cr_assert_eq(lw_runfiles_recover(r, &back, &err), LW_EUSAGE, "case %zu", k);
    cr_assert(strstr(err.msg, "r/.replaced: not linewise's"), "%s", err.msg);
    cr_assert_eq(sh("cd %s && grep -qx old r/state.lw && grep -qx other other/state.lw", dir), 0, "case %zu", k);
    cr_assert_eq(sh("cd %s && rm -rf r/.replaced", dir), 0);
  }
}

/* Files of a run's names in a directory that holds no run are someone's:
** a run there is refused naming one (a failed set-up removed them all). */
Test(runfiles, run_files_where_no_run_is_are_not_written_over)
{
  static const char *const names[] = {"final.pdf", "animation.mp4", "plots/energy.png", "frames/frame-000003.png",
                                      "replica-2.lw"};
  for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
    cr_assert_eq(sh("cd %s && rm -rf u && mkdir -p u/plots u/frames && echo mine > u/%s && echo mine > "
                    "u/plots/other.png", dir, names[k]), 0);
    char u[96];
    snprintf(u, sizeof u, "%s/u", dir);
    lw_error err;
    cr_assert_eq(lw_runfiles_check_free(u, &err), LW_EUSAGE, "%s", names[k]);
    cr_assert(strstr(err.msg, names[k]) && strstr(err.msg, "is there, but no run's scene.ini or state.lw"), "%s",
              err.msg);
  }
  /* several are named at once (one at a time, a user removed them a run
  ** each), the first six, then a count */
  cr_assert_eq(sh("cd %s && rm -rf u && mkdir -p u/frames && for f in final.gcode animation.mp4 replica-1.lw; do "
                  "echo mine > u/$f; done", dir), 0);
  char u[96];
  snprintf(u, sizeof u, "%s/u", dir);
  lw_error err;
  cr_assert_eq(lw_runfiles_check_free(u, &err), LW_EUSAGE);
  cr_assert(strstr(err.msg, "u holds run files (") && strstr(err.msg, "final.gcode") &&
            strstr(err.msg, "animation.mp4") && strstr(err.msg, " and ") && strstr(err.msg, "replica-1.lw") &&
            strstr(err.msg, "), but no run's scene.ini or state.lw beside them"), "%s", err.msg);
  cr_assert_eq(sh("cd %s && for k in 1 2 3 4 5; do echo mine > u/frames/frame-00000$k.png; done", dir), 0);
  cr_assert_eq(lw_runfiles_check_free(u, &err), LW_EUSAGE);
  cr_assert(strstr(err.msg, " and 2 more), but no run's"), "%s", err.msg);
  /* an empty .replaced holds no run (recovery removes it): it let a run
  ** write over the files beside it */
  cr_assert_eq(sh("cd %s && rm -rf u && mkdir -p u/.replaced && echo mine > u/final.svg", dir), 0);
  cr_assert_eq(lw_runfiles_check_free(u, NULL), LW_EUSAGE);
  /* a write's temporary alone is what a run killed as it wrote its first
  ** file leaves (the kill test's rerun was refused) */
  cr_assert_eq(sh("cd %s && rm -rf u && mkdir -p u && echo x > u/scene.ini.tmp", dir), 0);
  cr_assert_eq(lw_runfiles_check_free(u, NULL), LW_OK);
  /* the user's own names are not a run's */
  cr_assert_eq(sh("cd %s && rm -rf u && mkdir -p u/plots && echo mine > u/plots/other.png && echo mine > u/a.svg",
                  dir), 0);
  cr_assert_eq(lw_runfiles_check_free(u, NULL), LW_OK);
}

/* A run that waits in DIR/.replaced, set aside by a run killed as it
** started (its scene.ini and a trace of no row in DIR): `stats`, `energy`
** and a run refused for bad input there say where it waits and how it
** comes back (stats said only "no rows yet"), a start from its state is
** refused, and the resume they name puts it back, whose rows stats reads. */
Test(runfiles, stats_and_energy_name_the_run_waiting_aside)
{
  const char *b = lw_test_bin();
  cr_assert_eq(sh("%s run %s/params/minimal.ini --out %s/r --threads 1 --quiet", b, lw_test_root(), dir), 0);
  lw_error err;
  char r[96];
  snprintf(r, sizeof r, "%s/r", dir);
  cr_assert_eq(lw_runfiles_stash(r, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(sh("cd %s/r && cp .replaced/scene.ini . && head -1 .replaced/trace.csv > trace.csv", dir), 0);
  const char *cmd[] = {"stats", "energy"};
  const char *says[] = {"r/trace.csv: no rows (none before a run's first sweep; a run of no sweeps, as a redraw, has "
                        "none); a run there waits in ",
                        "r/state.lw: cannot open state file"};
  for (int k = 0; k < 2; k++) {
    cr_assert_eq(sh("%s %s %s/r > %s/out.txt 2> %s/err.txt", b, cmd[k], dir, dir, dir), 2, "%s", cmd[k]);
    char *msg = lw_test_slurp("%s/err.txt", dir);
    cr_assert(strstr(msg, says[k]) && strstr(msg, "r/.replaced, set aside by a run stopped as it started: "
                                                  "'linewise resume "), "%s: %s", cmd[k], msg);
    free(msg);
  }
  /* the note is of the run the error is of: not of r beside a run b whose
  ** trace is gone (any directory whose name the message held took it) */
  cr_assert_eq(sh("cd %s && %s run %s/params/minimal.ini --out b --quiet && rm b/trace.csv && "
                  "{ %s stats b r 2> err.txt; test $? -eq 2; } && "
                  "grep -q '^linewise: b/trace.csv: cannot read' err.txt && ! grep -q 'waits in' err.txt",
                  dir, b, lw_test_root(), b),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* a run refused for bad input there says so too, and leaves it waiting */
  cr_assert_eq(sh("cd %s && { %s run %s/params/minimal.ini --out r --quiet --set tempering.ladder_file=nope.ini "
                  "2> err.txt; test $? -eq 2; } && "
                  "grep -q \"tempering.ladder_file.*; a run there waits in r/.replaced\" err.txt && "
                  "test -s r/.replaced/state.lw", dir, b, lw_test_root()),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* a start from the state waiting there is refused, and the stash kept */
  cr_assert_eq(sh("cd %s && %s run %s/params/minimal.ini --out r --quiet --set init.from=r/.replaced/state.lw "
                  "2> err.txt", dir, b, lw_test_root()), 2);
  cr_assert_eq(sh("cd %s && grep -q \"r/.replaced/state.lw' is in .*/r/.replaced, where the run in r waits while a run "
                  "replaces it\" err.txt && test -s r/.replaced/state.lw", dir),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(sh("%s resume %s/r --quiet && %s stats %s/r > %s/out.txt", b, dir, b, dir, dir), 0);
  cr_assert_eq(sh("grep -q '^total  ' %s/out.txt && ! test -e %s/r/.replaced", dir, dir), 0);
}
