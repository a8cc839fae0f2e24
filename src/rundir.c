/* rundir.c -- the lock of a run directory (rundir.h). */
#include "linewise/rundir.h"

#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "linewise/params.h"
#include "linewise/runfiles.h"
#include "linewise/state.h"

/* The locks this process holds, by the lock file's identity: flock locks
** of two open files conflict even within one process, so a second lock of
** a held directory (a default directory chosen, then started) must find
** the first.  A hold is a slot's index + 1.  Runs of a program that embeds
** the library may start in threads of their own (anneal.h): the table is
** theirs together, under held_lock (two could take one free slot). */
#define HELD_MAX 64
static struct {
  dev_t dev;
  ino_t ino;
  int fd, count;
} held[HELD_MAX];
static pthread_mutex_t held_lock = PTHREAD_MUTEX_INITIALIZER;

lw_status lw_rundir_make(const char *dir, lw_error *err)
{
  char buf[LW_PATH_MAX];
  snprintf(buf, sizeof buf, "%s", dir);
  /* the ends of the folders this call made, taken away again where a later
  ** one fails (a full disk left an empty "x" of --out x/y) */
  size_t made[64], n_made = 0;
  for (char *c = buf + 1;; c++) {
    if (*c == '/' || *c == '\0') {
      char save = *c;
      *c = '\0';
      /* a place no directory can be made (a file in the way, /proc, no
      ** permission, a read-only mount) is the user's choice (exit 2, as
      ** --out naming a file); a disk that is full or fails is the machine's */
      const int failed = mkdir(buf, 0777);
      if (failed && errno != EEXIST) {
        const int e = errno, machine = e == ENOSPC || e == EIO || e == EDQUOT || e == ENOMEM;
        /* a relative one under a working directory a log does not show (cron's
        ** /, a read-only folder): "out: cannot create directory" said no where */
        char cwd[LW_PATH_MAX] = "";
        if (!machine && buf[0] != '/' && !getcwd(cwd, sizeof cwd)) cwd[0] = '\0';
        const lw_status s = lw_error_set(err, machine ? LW_EIO : LW_EUSAGE, "%s: cannot create directory: %s%s%s%s",
                                         buf, strerror(e), cwd[0] ? " (in the working directory " : "", cwd,
                                         cwd[0] ? "; --out names another place)" : "");
        while (n_made) {
          buf[made[--n_made]] = '\0';
          rmdir(buf);
        }
        return s;
      }
      if (!failed && n_made < sizeof made / sizeof *made) made[n_made++] = (size_t)(c - buf);
      *c = save;
      if (!save) break;
    }
  }
  /* mkdir says EEXIST for a symbolic link whose target is missing or loops */
  struct stat st;
  if (stat(dir, &st)) {
    const int e = errno, link = !lstat(dir, &st) && S_ISLNK(st.st_mode);
    return lw_error_set(err, LW_EUSAGE, "%s: cannot create directory: %s%s", dir, strerror(e),
                        link && e == ENOENT ? " (a symbolic link to a place that does not exist)" : "");
  }
  return LW_OK;
}

/* Whether the first line of dir/name begins with head (and, whole, is it):
** 1 or 0, or -1 (errno set) where it is there but cannot be read. */
static int first_line_is(const char *dir, const char *name, const char *head, int whole)
{
  char path[LW_PATH_MAX + 16], line[256];
  lw_path_join(path, sizeof path, dir, name);
  struct stat sb; /* (a FIFO is not a run's file, and opening it would wait for ever) */
  if (!stat(path, &sb) && (S_ISFIFO(sb.st_mode) || S_ISSOCK(sb.st_mode))) return 0;
  FILE *f = fopen(path, "r");
  if (!f) return errno == ENOENT || errno == ENOTDIR || errno == ELOOP ? 0 : -1;
  int is = 0;
  if (fgets(line, sizeof line, f)) {
    size_t n = strcspn(line, "\r\n"), h = strlen(head);
    is = n >= h && !strncmp(line, head, h) && (!whole || (n == h && line[n] != '\0'));
  } else if (ferror(f)) {
    is = errno == EISDIR ? 0 : -1;
  }
  fclose(f);
  return is;
}

int lw_rundir_holds_run(const char *dir)
{
  return first_line_is(dir, "scene.ini", LW_RUN_SCENE_HEADER, 1) == 1 ||
         first_line_is(dir, "state.lw", LW_STATE_MAGIC, 0) == 1;
}

int lw_rundir_foreign(const char *dir, const char *name)
{
  char path[LW_PATH_MAX + 16];
  lw_path_join(path, sizeof path, dir, name);
  if (access(path, F_OK)) return 0;
  const int is = !strcmp(name, "state.lw") ? first_line_is(dir, name, LW_STATE_MAGIC, 0)
                                           : first_line_is(dir, name, LW_RUN_SCENE_HEADER, 1);
  return is < 0 ? -1 : !is;
}

int lw_rundir_unstarted(const char *dir)
{
  static const char *const later[] = {"state.lw", "summary.json", "final.svg", "final.png", "final.ply"};
  if (!lw_rundir_holds_run(dir)) return 0;
  for (size_t k = 0; k < sizeof later / sizeof later[0]; k++) {
    char path[LW_PATH_MAX + 16];
    lw_path_join(path, sizeof path, dir, later[k]);
    struct stat sb; /* a link to nowhere is there too (a state.lw gone: not a run that never wrote one) */
    if (lstat(path, &sb) == 0) return 0;
  }
  return 1;
}

/* Whether this process may write path (a file written in place, or a
** directory it writes files into): 0, or the errno that says why not. */
static int denied(const char *path, int dir)
{
  if (access(path, F_OK) || !access(path, W_OK | (dir ? X_OK : 0))) return 0;
  return errno == EACCES || errno == EROFS || errno == EPERM ? errno : 0;
}

/* A directory this process may never write, or a run there whose files it
** may not (another user's, in a shared directory), is the wrong one (exit 2,
** as for one that cannot be made), not a failure while running: a queue's
** script that retries on 1 retried it for ever.  The run writes trace.csv
** in place and the lock, and the rest by rename, which needs only the
** directory, unless it is sticky (/tmp-like) and the file another user's. */
#define LW_RUNDIR_BUSY "%s: another linewise process is writing this run directory (it holds %s); wait for it to " \
                       "end, or write another directory%s"

/* LW_EUSAGE, LW_RUNDIR_BUSY of dir and its lock file path: a lock file with
** other names is another directory's too (a copy made with hard links),
** whose run may be the one that holds it. */
static lw_status busy(const char *dir, const char *path, lw_error *err)
{
  struct stat st;
  const int shared = !lstat(path, &st) && S_ISREG(st.st_mode) && st.st_nlink > 1;
  return lw_error_set(err, LW_EUSAGE, LW_RUNDIR_BUSY, dir, path, shared ? " (the lock file is a hard link, shared "
                      "with a copy of the run made with cp -al or rsync --link-dest: the process may be writing the "
                      "copy; a copy made with cp -r has its own)" : "");
}

/* Whether another process holds dir's lock, looked at without taking it
** for long (a shared lock at once let go); non-blocking: a FIFO planted
** there held the open for ever. */
static int lock_busy(const char *dir)
{
  char path[LW_PATH_MAX + 16];
  if (snprintf(path, sizeof path, "%s/.lock", dir) >= (int)sizeof path) return 0;
  int fd = open(path, O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  struct stat st;
  if (fd < 0) return 0;
  const int busy = !fstat(fd, &st) && S_ISREG(st.st_mode) && flock(fd, LOCK_SH | LOCK_NB) && errno == EWOULDBLOCK;
  close(fd);
  return busy;
}

lw_status lw_rundir_writable(const char *dir, lw_error *err)
{
  /* (plots: a new run moves tools/plot-run's plots aside with the rest) */
  static const char *const inside[] = {"", "frames", "samples", "plots"};
  const mode_t sticky = 01000; /* S_ISVTX, which POSIX leaves to XSI */
  char path[LW_PATH_MAX + 16];
  const char *what = NULL;
  int e = 0;
  /* (a library host's run into a file's path was told "Permission denied") */
  struct stat sd, sf;
  if (!stat(dir, &sd) && !S_ISDIR(sd.st_mode))
    return lw_error_set(err, LW_EINPUT, "%s: not a directory (a file of that name is there); expected a run "
                        "directory", dir);
  for (size_t k = 0; k < sizeof inside / sizeof inside[0] && !e; k++)
    if (snprintf(path, sizeof path, "%s%s%s", dir, k ? "/" : "", inside[k]) < (int)sizeof path && (e = denied(path, 1)))
      what = k ? "cannot write into it" : "cannot write into the run directory";
  if (!e && snprintf(path, sizeof path, "%s/trace.csv", dir) < (int)sizeof path && (e = denied(path, 0)))
    what = "cannot write over the run's trace";
  if (!e && snprintf(path, sizeof path, "%s/.lock", dir) < (int)sizeof path && !access(path, F_OK) &&
      access(path, R_OK) && errno == EACCES)
    e = EACCES, what = "cannot read the run directory's lock";
  const uid_t me = geteuid();
  /* another user's run file there (state.lw, a replica-K.lw, a write left,
  ** state.lw.tmp): the checkpoint that would replace it failed at its
  ** sweep, the sweeps since the last one lost (a file of theirs of another
  ** name is theirs) */
  const int foreign_sticky = me && !stat(dir, &sd) && (sd.st_mode & sticky) && sd.st_uid != me;
  DIR *d = !e && foreign_sticky ? opendir(dir) : NULL;
  for (struct dirent *de; d && !e && (de = readdir(d));) {
    if (lw_runfiles_is_top(de->d_name) && snprintf(path, sizeof path, "%s/%s", dir, de->d_name) < (int)sizeof path &&
        !lstat(path, &sf) && S_ISREG(sf.st_mode) && sf.st_uid != me)
      e = EPERM, what = "cannot replace another user's file in a sticky directory";
  }
  if (d) closedir(d);
  if (!e) return LW_OK;
  /* a run another user is writing is busy before it is theirs: its files'
  ** modes were said, and the run going on not */
  if (lock_busy(dir)) {
    snprintf(path, sizeof path, "%s/.lock", dir);
    return busy(dir, path, err);
  }
  return lw_error_set(err, LW_EINPUT, "%s: %s: %s; expected a run directory this user can write", path, what,
                      strerror(e));
}

/* The lock of dir's lock file fd (st its identity) into the table: the
** hold this process has on it already, or a new one.  Called under
** held_lock. */
static lw_status hold_lock(const char *dir, const char *path, int fd, const struct stat *st, int *hold,
                           lw_error *err)
{
  int k, free_slot = -1;
  for (k = 0; k < HELD_MAX; k++) {
    if (held[k].count && held[k].dev == st->st_dev && held[k].ino == st->st_ino) {
      close(fd);
      held[k].count++;
      *hold = k + 1;
      return LW_OK;
    }
    if (!held[k].count && free_slot < 0) free_slot = k;
  }
  if (free_slot < 0) {
    close(fd);
    return lw_error_set(err, LW_ERUN, "%s: more than %d run directories open in one process", dir, HELD_MAX);
  }
  /* a few tries: another process's look at the lock (a busy probe, a
  ** sweep's gather) holds it shared for a moment, and the run failed as busy */
  int e = 0;
  for (int tries = 0; flock(fd, LOCK_EX | LOCK_NB); tries++) {
    e = errno;
    if (e != EWOULDBLOCK || tries == 4) break;
    struct timespec pause = {0, 20000000};
    nanosleep(&pause, NULL);
    e = 0;
  }
  if (e) {
    close(fd);
    if (e == EWOULDBLOCK)
      return busy(dir, path, err);
    /* no locks here (EBADF: an NFS lock on a file we could only read) */
    if (e == ENOLCK || e == EOPNOTSUPP || e == ENOSYS || e == EINVAL || e == EBADF) return LW_OK;
    return lw_error_set(err, LW_EIO, "%s: cannot lock the run directory: %s", path, strerror(e));
  }
  held[free_slot].dev = st->st_dev;
  held[free_slot].ino = st->st_ino;
  held[free_slot].fd = fd;
  held[free_slot].count = 1;
  *hold = free_slot + 1;
  return LW_OK;
}

/* A lock file with other names (a copy of the run made by cp -al or rsync
** --link-dest) is the copy's lock as well: a run there was said busy while
** the other ran.  One no process holds is removed, for a file of this
** directory's own; one held stays (its holder may be writing here). */
static void unshare_lock(const char *path)
{
  struct stat st;
  if (lstat(path, &st) || !S_ISREG(st.st_mode) || st.st_nlink < 2) return;
  int fd = open(path, O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (fd < 0) return;
  if (!flock(fd, LOCK_EX | LOCK_NB)) unlink(path);
  close(fd);
}

lw_status lw_rundir_lock(const char *dir, int *hold, lw_error *err)
{
  char path[LW_PATH_MAX + 16];
  *hold = 0;
  if (snprintf(path, sizeof path, "%s/.lock", dir) >= (int)sizeof path)
    return lw_error_set(err, LW_EINPUT, "%s: the run directory's name is too long", dir);
  /* for writing where it may (NFS's flock takes an exclusive lock only on a
  ** file open for writing), else read-only (another user of a shared
  ** directory may read the lock file the first one made, and a local flock
  ** needs no more) */
  lw_status s = lw_rundir_writable(dir, err);
  if (s) return s;
  /* A run that ends before its first files removes the lock file it holds
  ** (and the directory it made): a process that opened that file before
  ** then and locks it after holds a lock no one else sees, and it once set
  ** up beside another run and removed that run's lock on its way out.  So
  ** a lock counts only while its file is still the one at the path: else
  ** the one there now is taken, afresh. */
  for (int tries = 0;; tries++) {
    unshare_lock(path);
    /* never through a link: one planted there made a root's run create any file */
    int fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0666);
    if (fd < 0 && errno == EACCES) fd = open(path, O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
    struct stat st, now;
    if (fd < 0 || fstat(fd, &st)) {
      int e = errno;
      if (fd >= 0) close(fd);
      return lw_error_set(err, LW_EIO, "%s: cannot open the run directory's lock: %s%s", path, strerror(e),
                          e == ELOOP ? " (a symbolic link, which linewise does not follow: remove it)" : "");
    }
    if (!S_ISREG(st.st_mode)) {
      close(fd);
      return lw_error_set(err, LW_EINPUT, "%s: not a regular file (a FIFO, a device or a folder): the run "
                          "directory's lock is a file of its own; remove it", path);
    }
    pthread_mutex_lock(&held_lock);
    s = hold_lock(dir, path, fd, &st, hold, err);
    pthread_mutex_unlock(&held_lock);
    if (s || !*hold || (!lstat(path, &now) && now.st_dev == st.st_dev && now.st_ino == st.st_ino)) return s;
    lw_rundir_unlock(*hold);
    *hold = 0;
    if (tries == 8) return busy(dir, path, err);
  }
}

int lw_rundir_held_here(const char *dir, int hold)
{
  char path[LW_PATH_MAX + 16];
  struct stat st;
  snprintf(path, sizeof path, "%s/.lock", dir);
  pthread_mutex_lock(&held_lock);
  const int here = hold >= 1 && hold <= HELD_MAX && held[hold - 1].count && !lstat(path, &st) &&
                   held[hold - 1].dev == st.st_dev && held[hold - 1].ino == st.st_ino;
  pthread_mutex_unlock(&held_lock);
  return here;
}

void lw_rundir_unlock(int hold)
{
  pthread_mutex_lock(&held_lock);
  if (hold >= 1 && hold <= HELD_MAX && held[hold - 1].count && !--held[hold - 1].count) close(held[hold - 1].fd);
  pthread_mutex_unlock(&held_lock);
}

const char *lw_rundir_shell_word(const char *dir, char *buf, size_t n)
{
  int plain = dir[0] != '\0';
  for (const char *c = dir; *c && plain; c++) plain = isalnum((unsigned char)*c) || strchr("_./:@%+,=-", *c);
  /* an interactive bash expands ! inside double quotes: single ones then,
  ** each ' of the name as '\'' */
  const char quote = plain ? '\0' : strchr(dir, '!') ? '\'' : '"';
  size_t at = (size_t)snprintf(buf, n, "%.1s%s", &quote, dir[0] == '-' ? "./" : "");
  for (const char *c = dir; *c && at + 5 < n; c++) {
    if (quote == '\'' && *c == '\'') {
      memcpy(buf + at, "'\\''", 4);
      at += 4;
      continue;
    }
    if (quote == '"' && strchr("\\\"$`", *c)) buf[at++] = '\\';
    buf[at++] = *c;
  }
  if (quote && at + 1 < n) buf[at++] = quote;
  buf[at < n ? at : n - 1] = '\0';
  return buf;
}
