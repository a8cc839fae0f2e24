/* runfiles.c -- a run's files in its directory, and the stash (runfiles.h). */
#include "linewise/runfiles.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "linewise/output.h"
#include "linewise/params.h"
#include "linewise/rundir.h"

static const char *const top_files[] = {"scene.ini", "state.lw",  "trace.csv",   "summary.json", "timing.txt",
                                        "ladder.ini", "field.png", "final.svg",   "final.png",    "final.pdf",
                                        "final.hpgl", "final.gcode", "final.ply", "animation.mp4"};

/* The subdirectories that hold run files, and which of their entries are. */
static const struct {
  const char *sub, *prefix, *suffix; /* prefix NULL: the plots' names */
} groups[] = {{".", "replica-", ".lw"}, {"frames", "frame-", ".png"}, {"samples", "sample-", ".csv"},
              {"plots", NULL, ".png"}};

static const char *const plots[] = {"energy", "temperature", "acceptance", "replicas", "swaps", "heat_capacity",
                                    "observables"};

/* Whether name is prefix + digits + suffix (or that + ".tmp": a write cut
** off), or with prefix NULL one of the plots + suffix. */
static int in_group(const char *name, const char *prefix, const char *suffix)
{
  if (!prefix) {
    for (size_t k = 0; k < sizeof plots / sizeof plots[0]; k++) {
      size_t n = strlen(plots[k]);
      if (!strncmp(name, plots[k], n) && !strcmp(name + n, suffix)) return 1;
    }
    return 0;
  }
  size_t np = strlen(prefix), nd = 0;
  if (strncmp(name, prefix, np)) return 0;
  while (name[np + nd] >= '0' && name[np + nd] <= '9') nd++;
  const char *rest = name + np + nd;
  size_t ns = strlen(suffix);
  return nd > 0 && !strncmp(rest, suffix, ns) && (!rest[ns] || !strcmp(rest + ns, ".tmp"));
}

int lw_runfiles_is_top(const char *name)
{
  size_t n = strlen(name);
  if (n > 4 && !strcmp(name + n - 4, ".tmp")) n -= 4;
  for (size_t i = 0; i < sizeof top_files / sizeof top_files[0]; i++)
    if (strlen(top_files[i]) == n && !strncmp(name, top_files[i], n)) return 1;
  return in_group(name, "replica-", ".lw");
}

int lw_runfiles_is_run_file(const char *rel)
{
  const size_t ns = strlen(LW_RUNFILES_STASH);
  if (!strncmp(rel, LW_RUNFILES_STASH, ns) && (!rel[ns] || rel[ns] == '/')) return 1;
  const char *slash = strchr(rel, '/');
  if (!slash) return lw_runfiles_is_top(rel);
  for (size_t g = 1; g < sizeof groups / sizeof groups[0]; g++)
    if (strlen(groups[g].sub) == (size_t)(slash - rel) && !strncmp(rel, groups[g].sub, (size_t)(slash - rel)) &&
        !strchr(slash + 1, '/') && in_group(slash + 1, groups[g].prefix, groups[g].suffix))
      return 1;
  return 0;
}

typedef int each_fn(const char *rel, void *ctx);

/* Calls fn with the path relative to root of each run file there ("x.tmp"
** of a top file too), until one returns nonzero, which it returns. */
static int each_file(const char *root, each_fn *fn, void *ctx)
{
  char rel[LW_PATH_MAX], path[2 * LW_PATH_MAX];
  struct stat sb;
  for (size_t i = 0; i < sizeof top_files / sizeof top_files[0]; i++)
    for (int tmp = 0; tmp < 2; tmp++) {
      snprintf(rel, sizeof rel, "%s%s", top_files[i], tmp ? ".tmp" : "");
      snprintf(path, sizeof path, "%s/%s", root, rel);
      int r;
      if (!lstat(path, &sb) && (r = fn(rel, ctx))) return r;
    }
  for (size_t g = 0; g < sizeof groups / sizeof groups[0]; g++) {
    snprintf(path, sizeof path, "%s/%s", root, groups[g].sub);
    /* a link is not the run's folder: its files are another directory's
    ** (moved aside and deleted, they were lost) */
    if (groups[g].sub[0] != '.' && (lstat(path, &sb) || !S_ISDIR(sb.st_mode))) continue;
    DIR *d = opendir(path);
    /* (a folder that cannot be read, out of file handles say, would leave
    ** another run's frames in this one, or the run set aside half removed) */
    if (!d) return -1;
    int r = 0;
    for (struct dirent *e; !r && (e = readdir(d));) {
      if (!in_group(e->d_name, groups[g].prefix, groups[g].suffix)) continue;
      if (groups[g].sub[0] == '.') snprintf(rel, sizeof rel, "%s", e->d_name);
      else snprintf(rel, sizeof rel, "%s/%s", groups[g].sub, e->d_name);
      r = fn(rel, ctx);
    }
    closedir(d);
    if (r) return r;
  }
  return 0;
}

/* The subdirectories of root that hold run files, removed where empty (the
** user's own files in them keep them). */
static void prune(const char *root)
{
  char path[2 * LW_PATH_MAX];
  for (size_t g = 1; g < sizeof groups / sizeof groups[0]; g++) {
    snprintf(path, sizeof path, "%s/%s", root, groups[g].sub);
    rmdir(path);
  }
}

/* fsync of root and of its folders of run files.  A stash's marker changes
** only after this on both sides: on disk it never says more than the moves
** before it did (a .moved whose moves a power cut undid would have the
** recovery take the run before's state.lw, still in DIR, for the new run's
** and drop the rest of that run). */
static void sync_run_dirs(const char *root)
{
  char path[2 * LW_PATH_MAX];
  struct stat sb;
  for (size_t g = 0; g < sizeof groups / sizeof groups[0]; g++) {
    snprintf(path, sizeof path, "%s/%s", root, groups[g].sub);
    if (!lstat(path, &sb) && S_ISDIR(sb.st_mode)) lw_output_sync_dir(path);
  }
}

/* The run files of a directory that holds no run, for the refusal to name
** them all at once (it named one, and the user removed them one run at a
** time): the first few in full, then a count.  A write's temporary, x.tmp,
** is what a run killed as it wrote x leaves: debris of linewise's, not a
** file of anyone's. */
enum { NAMED_MAX = 6 };
typedef struct {
  int n;
  char names[NAMED_MAX][LW_PATH_MAX];
} found_files;

static int add_found(const char *rel, void *ctx)
{
  found_files *f = ctx;
  const size_t n = strlen(rel);
  if (n > 4 && !strcmp(rel + n - 4, ".tmp")) return 0;
  if (f->n < NAMED_MAX) snprintf(f->names[f->n], sizeof f->names[f->n], "%s", rel);
  f->n++;
  return 0;
}

/* What a stash is: stash_marker below. */
enum { NOT_OURS, MOVING, MOVED, RESTORING, EMPTY };
static int stash_marker(const char *dir);

lw_status lw_runfiles_check_links(const char *dir, lw_error *err)
{
  for (size_t k = 1; k < sizeof groups / sizeof groups[0]; k++) {
    char path[LW_PATH_MAX + 16];
    struct stat sb;
    snprintf(path, sizeof path, "%s/%s", dir, groups[k].sub);
    if (!lstat(path, &sb) && S_ISLNK(sb.st_mode))
      return lw_error_set(err, LW_EINPUT, "%s: a symbolic link, not a folder: a run writes its %s only into its own "
                          "directory; remove it (nothing was written)", path, groups[k].sub);
  }
  return LW_OK;
}

lw_status lw_runfiles_check_free(const char *dir, lw_error *err)
{
  /* a frames/, samples/ or plots/ that is a link (planted in a shared
  ** directory) is refused whether or not this run writes there: one that
  ** writes none ran, and left the link in its directory */
  lw_status s = lw_runfiles_check_links(dir, err);
  if (s) return s;
  /* (an empty stash, which recovery removes, holds no run) */
  const int stash = lw_runfiles_stashed(dir) && stash_marker(dir) != EMPTY;
  if (stash || lw_rundir_holds_run(dir)) return LW_OK;
  /* a run's file that cannot be read (out of file handles) says nothing of
  ** whose the directory is: "remove them" told a user to delete a run */
  static const char *const own[] = {"scene.ini", "state.lw"};
  for (int k = 0; k < 2; k++)
    if (lw_rundir_foreign(dir, own[k]) < 0)
      return lw_error_set(err, LW_EIO, "%s/%s: cannot read it to see whose the directory is: %s; nothing was written",
                          dir, own[k], strerror(errno));
  found_files f = {0};
  each_file(dir, add_found, &f);
  if (!f.n) return LW_OK;
  if (f.n == 1)
    return lw_error_set(err, LW_EUSAGE, "%s/%s is there, but no run's scene.ini or state.lw beside it, and the run "
                        "would write over it: expected a run directory or a new one (remove the file to reuse the "
                        "directory)", dir, f.names[0]);
  /* named within the directory, which is named once: six long paths did
  ** not fit the message, and cut off why */
  char list[1024];
  size_t used = 0;
  const int named = f.n < NAMED_MAX ? f.n : NAMED_MAX;
  for (int k = 0; k < named && used < sizeof list; k++)
    used += (size_t)snprintf(list + used, sizeof list - used, "%s%s", !k ? "" : k + 1 < named || f.n > named ?
                             ", " : " and ", f.names[k]);
  if (f.n > named && used < sizeof list) snprintf(list + used, sizeof list - used, " and %d more", f.n - named);
  return lw_error_set(err, LW_EUSAGE, "%s holds run files (%s), but no run's scene.ini or state.lw beside them, and "
                      "the run would write over them: expected a run directory or a new one (remove them to reuse "
                      "the directory)", dir, list);
}

/* ---- the stash ---------------------------------------------------------- */

static void stash_path(char *buf, size_t n, const char *dir, const char *rel)
{
  snprintf(buf, n, "%s/" LW_RUNFILES_STASH "%s%s", dir, rel ? "/" : "", rel ? rel : "");
}

int lw_runfiles_stashed(const char *dir)
{
  char st[LW_PATH_MAX + 16];
  struct stat sb;
  stash_path(st, sizeof st, dir, NULL);
  return lstat(st, &sb) == 0;
}

/* What the stash is (its marker): 1 .moving (the run before being moved in),
** 2 .moved (all of it in), 3 .restoring (being moved back), 4 an empty
** directory (a process killed before its marker, or after removing it),
** 0 not linewise's (not a directory, a link, no marker). */
static int stash_marker(const char *dir)
{
  static const char *const marker[] = {".moving", ".moved", ".restoring"};
  char path[LW_PATH_MAX + 32];
  struct stat sb;
  stash_path(path, sizeof path, dir, NULL);
  if (lstat(path, &sb) || !S_ISDIR(sb.st_mode)) return NOT_OURS;
  for (int k = 0; k < 3; k++) {
    stash_path(path, sizeof path, dir, marker[k]);
    if (!lstat(path, &sb) && S_ISREG(sb.st_mode)) return MOVING + k;
  }
  stash_path(path, sizeof path, dir, NULL);
  DIR *d = opendir(path);
  int entries = 0;
  for (struct dirent *e; d && (e = readdir(d));) entries += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
  if (d) closedir(d);
  return d && !entries ? EMPTY : NOT_OURS;
}

typedef struct {
  const char *from, *to; /* directories: a run file of from goes to the same place under to */
  int err;               /* errno of the rename that failed */
  char rel[LW_PATH_MAX];  /* and its file */
} mover;

static int move_one(const char *rel, void *ctx)
{
  mover *m = ctx;
  char a[2 * LW_PATH_MAX + 32], b[2 * LW_PATH_MAX + 32];
  snprintf(a, sizeof a, "%s/%s", m->from, rel);
  snprintf(b, sizeof b, "%s/%s", m->to, rel);
  const char *slash = strchr(rel, '/');
  if (slash) { /* frames/, samples/, plots/ under to */
    char sub[2 * LW_PATH_MAX + 32];
    snprintf(sub, sizeof sub, "%s/%.*s", m->to, (int)(slash - rel), rel);
    if (mkdir(sub, 0777) && errno != EEXIST) {
      m->err = errno;
      snprintf(m->rel, sizeof m->rel, "%.*s", (int)(slash - rel), rel);
      return 1;
    }
  }
  if (rename(a, b)) {
    m->err = errno;
    snprintf(m->rel, sizeof m->rel, "%s", rel);
    return 1;
  }
  return 0;
}

/* A file of the new run in dir without a counterpart in the stash. */
static int remove_new(const char *rel, void *ctx)
{
  const char *dir = ctx;
  char in_stash[2 * LW_PATH_MAX + 32], path[2 * LW_PATH_MAX + 32];
  struct stat sb;
  stash_path(in_stash, sizeof in_stash, dir, rel);
  if (!lstat(in_stash, &sb)) return 0; /* the rename back replaces it */
  snprintf(path, sizeof path, "%s/%s", dir, rel);
  unlink(path);
  return 0;
}

static int remove_one(const char *rel, void *ctx)
{
  char path[2 * LW_PATH_MAX + 32];
  snprintf(path, sizeof path, "%s/%s", (const char *)ctx, rel);
  unlink(path);
  return 0;
}

/* The stash's subdirectories and marker, then the stash itself, where that
** leaves them empty: the marker last, so that a kill before leaves a stash
** that says what it is, and one after an empty directory (EMPTY). */
static void remove_stash_dir(const char *dir)
{
  static const char *const marker[] = {".moving", ".moved", ".restoring"};
  char st[LW_PATH_MAX + 32], path[LW_PATH_MAX + 32];
  stash_path(st, sizeof st, dir, NULL);
  prune(st);
  for (int k = 0; k < 3; k++) {
    stash_path(path, sizeof path, dir, marker[k]);
    unlink(path);
  }
  rmdir(st);
}

lw_status lw_runfiles_unstash(const char *dir, lw_error *err)
{
  int marker = stash_marker(dir);
  char st[LW_PATH_MAX + 16], moved[LW_PATH_MAX + 32], restoring[LW_PATH_MAX + 32];
  stash_path(st, sizeof st, dir, NULL);
  if (marker == EMPTY) rmdir(st);
  if (marker == NOT_OURS || marker == EMPTY) return LW_OK;
  if (marker == MOVED) {
    /* all of the run before is in the stash: the run files in dir are the
    ** new run's, and those without a counterpart go; then the marker says
    ** that what comes back into dir is the run before's (a kill while
    ** moving back left it .moved, and the next recover took the run before's
    ** state.lw, back already, for the new run's and dropped the rest) */
    each_file(dir, remove_new, (void *)dir);
    sync_run_dirs(dir);
    stash_path(moved, sizeof moved, dir, ".moved");
    stash_path(restoring, sizeof restoring, dir, ".restoring");
    if (rename(moved, restoring))
      return lw_error_set(err, LW_EIO, "%s: cannot rename: %s; the run that was there before is in %s", moved,
                          strerror(errno), st);
    lw_output_sync_dir(st);
  }
  /* .moving or .restoring: every run file in the stash goes back, over a
  ** counterpart in dir (the new run's) */
  mover m = {st, dir, 0, ""};
  if (each_file(st, move_one, &m)) {
    if (!m.err) /* (a folder of the stash that would not open) */
      return lw_error_set(err, LW_EIO, "%s: cannot read its folders: %s; the run that was there before is in it",
                          st, strerror(errno));
    return lw_error_set(err, LW_EIO, "%s/%s: cannot put it back: %s; the rest of the run that was there before "
                        "is in %s", dir, m.rel, strerror(m.err), st);
  }
  sync_run_dirs(dir);
  sync_run_dirs(st);
  remove_stash_dir(dir);
  prune(dir);
  return LW_OK;
}

lw_status lw_runfiles_stash(const char *dir, lw_error *err)
{
  char st[LW_PATH_MAX + 16], marker[LW_PATH_MAX + 32], moved[LW_PATH_MAX + 32];
  stash_path(st, sizeof st, dir, NULL);
  stash_path(marker, sizeof marker, dir, ".moving");
  stash_path(moved, sizeof moved, dir, ".moved");
  if (mkdir(st, 0777))
    return lw_error_set(err, LW_EIO, "%s: cannot make it to set the run there aside: %s; that run is as it was", st,
                        strerror(errno));
  int fd = open(marker, O_WRONLY | O_CREAT | O_EXCL, 0666);
  if (fd < 0 || close(fd)) {
    const int e = errno;
    unlink(marker);
    rmdir(st);
    return lw_error_set(err, LW_EIO, "%s: cannot write: %s; the run there is as it was", marker, strerror(e));
  }
  /* (the stash and its marker on disk before any move into it: a stash
  ** without a marker is not linewise's, and what it held would be lost) */
  lw_output_sync_dir(st);
  lw_output_sync_dir(dir);
  mover m = {dir, st, 0, ""};
  const int unread = each_file(dir, move_one, &m) && !m.err; /* (a folder of it would not open) */
  if (!m.err && !unread) {
    sync_run_dirs(dir);
    sync_run_dirs(st);
  }
  if (m.err || unread || rename(marker, moved)) {
    const int e = m.err ? m.err : errno;
    char what[LW_PATH_MAX + 32];
    snprintf(what, sizeof what, "%s%s%s", dir, m.err ? "/" : unread ? "" : "/" LW_RUNFILES_STASH "/.moving",
             m.err ? m.rel : "");
    lw_error back;
    if (lw_runfiles_unstash(dir, &back))
      return lw_error_set(err, LW_EIO, "%s: cannot set it aside: %s; %s", what, strerror(e), back.msg);
    return lw_error_set(err, LW_EIO, "%s: cannot set it aside: %s; the run there is as it was", what, strerror(e));
  }
  lw_output_sync_dir(st);
  prune(dir);
  return LW_OK;
}

static int remove_stashed(const char *rel, void *ctx)
{
  char path[2 * LW_PATH_MAX + 32];
  stash_path(path, sizeof path, ctx, rel);
  return unlink(path) && errno != ENOENT;
}

lw_status lw_runfiles_drop(const char *dir, lw_error *err)
{
  char st[LW_PATH_MAX + 16];
  const int marker = stash_marker(dir);
  stash_path(st, sizeof st, dir, NULL);
  if (marker == NOT_OURS) return LW_OK;
  if (marker != EMPTY && each_file(st, remove_stashed, (void *)dir))
    return lw_error_set(err, LW_EIO, "%s: cannot remove the run set aside there (the run that replaced it has its "
                        "checkpoint): %s; linewise's next run or resume there removes it", st, strerror(errno));
  remove_stash_dir(dir);
  return LW_OK;
}

void lw_runfiles_remove(const char *dir)
{
  each_file(dir, remove_one, (void *)dir);
  prune(dir);
}

lw_status lw_runfiles_check_stash(const char *dir, lw_error *err)
{
  char st[LW_PATH_MAX + 16];
  stash_path(st, sizeof st, dir, NULL);
  if (!lw_runfiles_stashed(dir) || stash_marker(dir) != NOT_OURS) return LW_OK;
  return lw_error_set(err, LW_EUSAGE, "%s: not linewise's (a run sets the run before aside there while it starts, "
                      "with a marker file in it): expected no such file or folder; remove or rename it", st);
}

lw_status lw_runfiles_recover(const char *dir, int *back, lw_error *err)
{
  *back = 0;
  lw_status s = lw_runfiles_check_stash(dir, err);
  if (s || !lw_runfiles_stashed(dir)) return s;
  const int marker = stash_marker(dir);
  char state[LW_PATH_MAX + 16];
  struct stat sb;
  snprintf(state, sizeof state, "%s/state.lw", dir);
  if (marker == EMPTY) return lw_runfiles_drop(dir, err);
  if (marker == MOVED && !lstat(state, &sb)) return lw_runfiles_drop(dir, err); /* the new run had its checkpoint */
  s = lw_runfiles_unstash(dir, err);
  *back = !s;
  return s;
}

/* The sweep in a frame's or a sample's name (in_group's), or -1. */
static long group_sweep(const char *name, const char *prefix)
{
  const char *digits = name + strlen(prefix);
  char *end;
  errno = 0;
  const long s = strtol(digits, &end, 10);
  return errno || end == digits ? -1 : s;
}

void lw_runfiles_drop_off_grid(const char *dir, long after, long end, long frames_every, long samples_every)
{
  const long every[] = {0, frames_every, samples_every};
  char path[2 * LW_PATH_MAX + 8];
  for (size_t g = 1; g <= 2; g++) {
    snprintf(path, sizeof path, "%s/%s", dir, groups[g].sub);
    DIR *d = opendir(path);
    if (!d) continue;
    for (struct dirent *e; (e = readdir(d));) {
      if (!in_group(e->d_name, groups[g].prefix, groups[g].suffix)) continue;
      const long s = group_sweep(e->d_name, groups[g].prefix);
      if (s <= after || s == end || (every[g] && s % every[g] == 0)) continue;
      snprintf(path, sizeof path, "%s/%s/%s", dir, groups[g].sub, e->d_name);
      unlink(path);
    }
    closedir(d);
  }
}

int lw_runfiles_frame_size(const char *dir, long at_most, long *sweep, unsigned *w, unsigned *h)
{
  char path[2 * LW_PATH_MAX + 8], name[64] = "";
  snprintf(path, sizeof path, "%s/frames", dir);
  DIR *d = opendir(path);
  if (!d) return 0;
  long best = -1;
  for (struct dirent *e; (e = readdir(d));) {
    const size_t n = strlen(e->d_name);
    if (!in_group(e->d_name, "frame-", ".png") || !strcmp(e->d_name + n - 4, ".tmp") || n >= sizeof name) continue;
    const long s = group_sweep(e->d_name, "frame-");
    if (s > best && s <= at_most) {
      best = s;
      memcpy(name, e->d_name, n + 1);
    }
  }
  closedir(d);
  if (best < 0) return 0;
  snprintf(path, sizeof path, "%s/frames/%s", dir, name);
  /* PNG's signature, then IHDR's length and type, then its width and
  ** height, big-endian */
  unsigned char b[24];
  FILE *f = fopen(path, "rb");
  if (!f) return 0;
  const size_t got = fread(b, 1, sizeof b, f);
  fclose(f);
  if (got != sizeof b || memcmp(b, "\x89PNG\r\n\x1a\n", 8) || memcmp(b + 12, "IHDR", 4)) return 0;
  *sweep = best;
  *w = (unsigned)b[16] << 24 | (unsigned)b[17] << 16 | (unsigned)b[18] << 8 | b[19];
  *h = (unsigned)b[20] << 24 | (unsigned)b[21] << 16 | (unsigned)b[22] << 8 | b[23];
  return 1;
}
