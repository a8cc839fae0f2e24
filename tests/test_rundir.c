/*
** test_rundir.c -- one process at a time in a run directory (rundir.h):
** runs started together without --out each get their own directory, and a
** run, a resume or a redraw into a directory another process is writing is
** refused before it writes anything.
*/
#include <criterion/criterion.h>
#include <dirent.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <sys/file.h>
#include <unistd.h>

#include "linewise/rundir.h"
#include "testutil.h"

static char dir[64];

static void make_dir(void) { cr_assert_eq(lw_test_dir_make(dir, "rdir"), 0); }
static void remove_dir(void) { cr_assert_eq(lw_test_dir_remove(dir), 0); }

TestSuite(rundir, .init = make_dir, .fini = remove_dir);

#define sh lw_test_sh

/* Three runs of one scene started at once without --out: before, two of
** them shared out/minimal (4 times in 4), and a summary.json of seed 1 sat
** beside a scene.ini of seed 2.  Each now has its own directory, whose
** files all are its own. */
/* A path that names a file is no run directory, said so (a library host's
** run into one was told "Permission denied"). */
Test(rundir, a_file_is_no_run_directory)
{
  char path[128];
  snprintf(path, sizeof path, "%s/afile", dir);
  cr_assert_eq(lw_test_sh("touch %s", path), 0);
  lw_error err;
  cr_assert_eq(lw_rundir_writable(path, &err), LW_EINPUT);
  cr_assert(strstr(err.msg, "afile: not a directory (a file of that name is there)"), "%s", err.msg);
  cr_assert_eq(lw_rundir_writable(dir, &err), LW_OK, "%s", err.msg);
}

Test(rundir, runs_started_together_without_out_each_get_their_own_directory)
{
  cr_assert_eq(sh("cd %s && for s in 1 2 3; do %s run %s/params/minimal.ini --set anneal.sweeps=400 --threads 1 "
                  "--quiet --seed $s & done; wait", dir, lw_test_bin(), lw_test_root()), 0);
  for (int s = 1; s <= 3; s++)
    cr_assert_eq(sh("cd %s && n=$(grep -l '\"seed\": %d,' out/*/summary.json | wc -l) && test $n = 1 && "
                    "d=$(dirname $(grep -l '\"seed\": %d,' out/*/summary.json)) && grep -q '^seed = %d$' $d/scene.ini",
                    dir, s, s, s), 0, "seed %d", s);
  cr_assert_eq(sh("test $(ls -d %s/out/minimal* | wc -l) = 3", dir), 0);
}

/* A directory chosen past out/<name> is named even under --quiet (a later
** `stats out/<name>` read the earlier run unsaid); out/<name> itself is not. */
Test(rundir, a_run_into_another_default_directory_says_so_even_quiet)
{
  for (int k = 0; k < 2; k++)
    cr_assert_eq(sh("cd %s && %s run %s/params/minimal.ini --set anneal.sweeps=5 --quiet 2> err%d.txt", dir,
                    lw_test_bin(), lw_test_root(), k), 0);
  cr_assert_eq(sh("cd %s && test ! -s err0.txt && grep -qx 'linewise: into out/minimal-2 (out/minimal holds a run; "
                  "--out names the directory)' err1.txt", dir), 0);
}

/* While another process holds DIR/.lock, run, resume and a redraw into
** DIR exit 2 with one line and leave the run there as it was; once it
** lets go, they go on. */
Test(rundir, a_directory_another_process_writes_is_refused)
{
  cr_assert_eq(sh("%s run %s/params/minimal.ini --out %s/r --quiet --set anneal.sweeps=20 --stop-at 10", lw_test_bin(),
                  lw_test_root(), dir), 0);
  cr_assert_eq(sh("cp %s/r/state.lw %s/state.before", dir, dir), 0);
  char path[128];
  snprintf(path, sizeof path, "%s/r/.lock", dir);
  int fd = open(path, O_RDWR | O_CREAT, 0666);
  cr_assert(fd >= 0 && flock(fd, LOCK_EX | LOCK_NB) == 0, "the test takes the lock");
  cr_assert_eq(sh("%s resume %s/r 2> %s/err.txt", lw_test_bin(), dir, dir), 2);
  cr_assert_eq(sh("grep -q \"r: another linewise process is writing this run directory (it holds .*r/.lock); wait "
                  "for it to end, or write another directory\" %s/err.txt && test $(wc -l < %s/err.txt) = 1",
                  dir, dir), 0);
  cr_assert_eq(sh("%s run %s/params/minimal.ini --out %s/r --set anneal.sweeps=0 2> %s/err.txt", lw_test_bin(),
                  lw_test_root(), dir, dir), 2);
  cr_assert_eq(sh("grep -q 'another linewise process is writing this run directory' %s/err.txt", dir), 0);
  cr_assert_eq(sh("cmp -s %s/r/state.lw %s/state.before && test ! -e %s/r/summary.json", dir, dir, dir), 0);
  close(fd);
  cr_assert_eq(sh("%s resume %s/r --quiet && test -s %s/r/summary.json", lw_test_bin(), dir, dir), 0);
}

/* A run into --out DIR holds DIR's lock from before its set-up: a second
** run into DIR started during a first's set-up of seconds finished, then the
** first took DIR and wrote over its result, both exiting 0.  Now the second
** is refused (exit 2), and DIR holds the first run's files. */
Test(rundir, a_run_into_a_directory_whose_run_is_setting_up_is_refused, .timeout = 60)
{
  cr_assert_eq(sh("cd %s && { %s run %s/params/minimal.ini --out d --quiet --threads 1 --set init.splines=20000 "
                  "--set scene.width=2000 --set scene.height=2000 --set anneal.sweeps=0 --seed 1 & } && sleep 0.3 && "
                  "{ %s run %s/params/minimal.ini --out d --quiet --threads 1 --set anneal.sweeps=2 --seed 2 "
                  "2> err.txt; echo $? > second.txt; wait; }", dir, lw_test_bin(), lw_test_root(), lw_test_bin(),
                  lw_test_root()), 0);
  cr_assert_eq(sh("cd %s && test \"$(cat second.txt)\" = 2 && grep -q 'd: another linewise process is writing this run "
                  "directory' err.txt && grep -q '\"seed\": 1,' d/summary.json", dir), 0, "%s",
               lw_test_slurp("%s/err.txt", dir));
}

/* A resume into a directory whose run is setting up (only its lock there)
** is said busy: it was told the directory holds no run ("run it again"),
** and, where the run's files came as it looked, resumed beside the run. */
Test(rundir, a_resume_into_a_run_setting_up_is_said_busy, .timeout = 60)
{
  cr_assert_eq(sh("cd %s && { %s run %s/params/minimal.ini --out d --quiet --threads 1 --set init.splines=30000 "
                  "--set scene.width=2000 --set scene.height=2000 --set anneal.sweeps=2 & } && "
                  "until test -e d/.lock; do sleep 0.01; done && "
                  "{ %s resume d --quiet 2> err.txt; echo $? > rc.txt; wait; }", dir, lw_test_bin(), lw_test_root(),
                  lw_test_bin()), 0);
  cr_assert_eq(sh("cd %s && test \"$(cat rc.txt)\" = 2 && grep -q 'd: another linewise process is writing this run "
                  "directory' err.txt", dir), 0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* A run another user is writing, in a directory this one may not write,
** is said busy: before, the files' modes were said ("cannot write over the
** run's trace"), and the run going on not; once it ends, the modes are. */
Test(rundir, another_users_run_going_on_is_said_busy_before_its_modes)
{
  if (geteuid() || sh("setpriv --reuid=65534 --regid=65534 --clear-groups %s --version >/dev/null", lw_test_bin()))
    cr_skip_test("needs root, setpriv, and a binary user nobody may run");
  cr_assert_eq(sh("%s run %s/params/minimal.ini --out %s/r --quiet --set anneal.sweeps=20 --stop-at 10 && "
                  "chmod 755 %s", lw_test_bin(), lw_test_root(), dir, dir), 0);
  char path[128];
  snprintf(path, sizeof path, "%s/r/.lock", dir);
  int fd = open(path, O_RDWR);
  cr_assert(fd >= 0 && flock(fd, LOCK_EX | LOCK_NB) == 0, "the test takes the lock");
  static const char *const said[] = {"another linewise process is writing this run directory",
                                     "expected a run directory this user can write"};
  for (int k = 0; k < 2; k++) {
    if (k) close(fd);
    cr_assert_eq(sh("setpriv --reuid=65534 --regid=65534 --clear-groups %s resume %s/r 2> %s/err.txt",
                    lw_test_bin(), dir, dir), 2);
    cr_assert_eq(sh("grep -q '%s' %s/err.txt && test $(wc -l < %s/err.txt) = 1", said[k], dir, dir), 0, "%s",
                 lw_test_slurp("%s/err.txt", dir));
    /* and run --out into it, which looked at the modes alone */
    cr_assert_eq(sh("setpriv --reuid=65534 --regid=65534 --clear-groups %s run %s/params/minimal.ini --out %s/r "
                    "2> %s/err.txt", lw_test_bin(), lw_test_root(), dir, dir), 2);
    cr_assert_eq(sh("grep -q '%s' %s/err.txt && test $(wc -l < %s/err.txt) = 1", said[k], dir, dir), 0, "%s",
                 lw_test_slurp("%s/err.txt", dir));
  }
}

/* A lock that is a FIFO is refused, by root and by another user, at once:
** the busy probe of another user's run opened it for reading and waited
** for a writer for ever. */
Test(rundir, a_lock_that_is_a_fifo_is_refused_at_once)
{
  cr_assert_eq(sh("%s run %s/params/minimal.ini --out %s/r --quiet --set anneal.sweeps=20 --stop-at 10 && "
                  "rm %s/r/.lock && mkfifo -m 644 %s/r/.lock && chmod 755 %s", lw_test_bin(), lw_test_root(), dir, dir,
                  dir, dir), 0);
  cr_assert_eq(sh("timeout 20 %s resume %s/r 2> %s/err.txt", lw_test_bin(), dir, dir), 2);
  cr_assert_eq(sh("grep -q 'r/.lock: not a regular file (a FIFO, a device or a folder)' %s/err.txt", dir), 0, "%s",
               lw_test_slurp("%s/err.txt", dir));
  if (geteuid() || sh("setpriv --reuid=65534 --regid=65534 --clear-groups %s --version >/dev/null", lw_test_bin()))
    return; /* (the other user's case needs root and setpriv) */
  cr_assert_eq(sh("timeout 20 setpriv --reuid=65534 --regid=65534 --clear-groups %s resume %s/r 2> %s/err.txt",
                  lw_test_bin(), dir, dir), 2, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* Another user's write of a run file (state.lw.tmp) left in a sticky run
** directory is refused before a resume starts (the checkpoint that would
** remove it failed at its sweep, the sweeps since the last one lost);
** without it the resume goes on, beside files of theirs of other names. */
Test(rundir, another_users_leftover_in_a_sticky_directory_is_refused_at_once)
{
  if (geteuid() || sh("setpriv --reuid=65534 --regid=65534 --clear-groups %s --version >/dev/null", lw_test_bin()))
    cr_skip_test("needs root, setpriv, and a binary user nobody may run");
  cr_assert_eq(sh("chmod 755 %s && %s run %s/params/minimal.ini --out %s/r --quiet --set anneal.sweeps=20 --stop-at 5 "
                  "&& chmod 1777 %s/r && chown 65534 %s/r/* && touch %s/r/state.lw.tmp", dir, lw_test_bin(),
                  lw_test_root(), dir, dir, dir, dir),
               0);
  static const char *const nobody = "setpriv --reuid=65534 --regid=65534 --clear-groups";
  cr_assert_eq(sh("%s %s resume %s/r --quiet 2> %s/err.txt", nobody, lw_test_bin(), dir, dir), 2);
  cr_assert_eq(sh("grep -q 'r/state.lw.tmp: cannot replace another user.s file in a sticky directory' %s/err.txt", dir),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* a file or folder of theirs of another name is theirs */
  cr_assert_eq(sh("rm %s/r/state.lw.tmp && touch %s/r/notes.tmp && mkdir %s/r/old.tmp && %s %s resume %s/r --quiet",
                  dir, dir, dir, nobody, lw_test_bin(), dir),
               0);
  /* any run file of theirs (a replica's, a drawing) the run would replace:
  ** an extension failed after its sweeps, exit 1 */
  cr_assert_eq(sh("chown 0 %s/r/final.svg && %s %s resume %s/r --quiet --sweeps 5 2> %s/err.txt", dir, nobody,
                  lw_test_bin(), dir, dir),
               2);
  cr_assert_eq(sh("grep -q 'r/final.svg: cannot replace another user.s file in a sticky directory' %s/err.txt", dir),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* A directory that cannot be made under the working directory names it (a
** cron job's "out: cannot create directory" said no where), and --out. */
Test(rundir, a_relative_directory_that_cannot_be_made_names_the_working_directory)
{
  cr_assert_eq(sh("cd %s && touch f && %s run %s/params/minimal.ini --out f/x --quiet 2> err.txt", dir, lw_test_bin(),
                  lw_test_root()),
               2);
  char want[256];
  snprintf(want, sizeof want, "linewise: f/x: cannot create directory: Not a directory (in the working directory %s; "
           "--out names another place)\n", dir);
  cr_assert_str_eq(lw_test_slurp("%s/err.txt", dir), want);
}

/* The lock is per process: taken twice here it is held once, and let go
** when the last hold goes. */
Test(rundir, a_process_may_hold_its_own_lock_twice)
{
  lw_error err;
  int a = 0, b = 0;
  cr_assert_eq(lw_rundir_lock(dir, &a, &err), LW_OK);
  cr_assert_eq(lw_rundir_lock(dir, &b, &err), LW_OK, "%s", err.msg);
  cr_assert(a > 0 && a == b);
  char path[128];
  snprintf(path, sizeof path, "%s/.lock", dir);
  lw_rundir_unlock(a);
  int fd = open(path, O_RDWR);
  cr_assert(fd >= 0);
  cr_assert_neq(flock(fd, LOCK_EX | LOCK_NB), 0, "one hold is left");
  lw_rundir_unlock(b);
  cr_assert_eq(flock(fd, LOCK_EX | LOCK_NB), 0, "both let go");
  close(fd);
}

/* Open descriptors of this process. */
static int open_fds(void)
{
  DIR *d = opendir("/proc/self/fd");
  int n = 0;
  for (struct dirent *e; d && (e = readdir(d));) n += e->d_name[0] != '.';
  if (d) closedir(d);
  return n;
}

typedef struct {
  char dir[96];
  pthread_barrier_t *go;
  int failed;
} locker;

static void *lock_and_let_go(void *arg)
{
  locker *l = arg;
  for (int k = 0; k < 2000; k++) {
    lw_error err;
    int hold = 0;
    if (k % 50 == 0) pthread_barrier_wait(l->go);
    if (lw_rundir_lock(l->dir, &hold, &err) || hold < 1) l->failed++;
    lw_rundir_unlock(hold);
  }
  return NULL;
}

/* A program that embeds the library may start runs in threads of their own
** (anneal.h): the table of the locks this process holds is theirs together.
** Unguarded, two threads could take one free slot, and one lock's
** descriptor leaked while the other's was closed under its run.  Four
** threads take and let go of their own directories' locks 2000 times: each
** is taken every time, every one is let go at the end, and no descriptor
** is left open.  (A race shows only now and then: the test cannot fail
** without one, and can with one.) */
Test(rundir, threads_of_one_process_take_their_locks_apart)
{
  enum { THREADS = 4 };
  locker l[THREADS];
  pthread_t th[THREADS];
  pthread_barrier_t go;
  pthread_barrier_init(&go, NULL, THREADS);
  const int fds = open_fds();
  for (int i = 0; i < THREADS; i++) {
    l[i] = (locker){.go = &go};
    snprintf(l[i].dir, sizeof l[i].dir, "%s/t%d", dir, i);
    cr_assert_eq(sh("mkdir %s", l[i].dir), 0);
    cr_assert_eq(pthread_create(&th[i], NULL, lock_and_let_go, &l[i]), 0);
  }
  for (int i = 0; i < THREADS; i++) pthread_join(th[i], NULL);
  pthread_barrier_destroy(&go);
  cr_assert_eq(open_fds(), fds, "descriptors left open");
  for (int i = 0; i < THREADS; i++) {
    cr_assert_eq(l[i].failed, 0, "thread %d", i);
    char path[512];
    snprintf(path, sizeof path, "%s/.lock", l[i].dir);
    int fd = open(path, O_RDWR);
    cr_assert(fd >= 0);
    cr_assert_eq(flock(fd, LOCK_EX | LOCK_NB), 0, "%s still held", l[i].dir);
    close(fd);
  }
}

/* A run refused for bad input leaves no directory behind, out/ included,
** when it chose out/<name> itself. */
Test(rundir, a_refused_run_without_out_leaves_no_directory)
{
  cr_assert_eq(sh("cd %s && printf '[scene]\\nimage = nothere.png\\n' > bad.ini && %s run bad.ini 2> err.txt", dir,
                  lw_test_bin()), 2);
  cr_assert_eq(sh("cd %s && grep -q 'nothere.png' err.txt && test ! -e out", dir), 0);
}

/* Resume of a directory that holds no run, or of a file, is bad input
** (exit 2, saying so) and writes nothing there, no lock file either. */
Test(rundir, resume_of_what_holds_no_run_writes_nothing)
{
  cr_assert_eq(sh("mkdir %s/empty && touch %s/afile", dir, dir), 0);
  cr_assert_eq(sh("%s resume %s/empty 2> %s/err.txt", lw_test_bin(), dir, dir), 2);
  cr_assert_eq(sh("grep -q 'empty: holds no run' %s/err.txt && test -z \"$(ls -A %s/empty)\"", dir, dir), 0);
  cr_assert_eq(sh("%s resume %s/afile 2> %s/err.txt", lw_test_bin(), dir, dir), 2);
}
