#define _XOPEN_SOURCE 700 /* realpath */
/*
** anneal.c -- a whole annealing run (anneal.h): setup, temperature steps,
** tuning phases, drift checks, checkpoints, trace and summary.
*/
#include "linewise/anneal.h"

#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <gsl/gsl_math.h>
#include <stdarg.h>
#include <limits.h>
#include <malloc.h>
#include <math.h>
#include <stddef.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include "linewise/checkpoint.h"
#include "linewise/domains.h"
#include "linewise/driver.h"
#include "linewise/image.h"
#include "linewise/init.h"
#include "linewise/json.h"
#include "linewise/number.h"
#include "linewise/output.h"
#include "linewise/phase.h"
#include "linewise/rundir.h"
#include "linewise/runfiles.h"
#include "linewise/state.h"
#include "linewise/trace.h"
#include "linewise/memlimit.h"
#include "linewise/version.h"

double lw_anneal_seconds(const lw_anneal *a) { return a->wall_before + lw_phase_clock() - a->wall_start; }

/* (NAN, not the chain's 0, before the first sweep of a new run sets it:
** t_start is not the chain's until then) */
double lw_anneal_temperature(const lw_anneal *a) { return a->chain && a->block >= 0 ? a->chain->temperature : NAN; }

/* LW_EUSAGE after lw_anneal_finish (anneal.h): a program that swept on
** after it continued a quenched state, or drew the final files twice. */
static lw_status refuse_finished(const lw_anneal *a, const char *what, lw_error *err)
{
  if (!a->finished) return LW_OK;
  return lw_error_set(err, LW_EUSAGE, "%s: the run in %s has finished (lw_anneal_finish); only lw_anneal_free may "
                      "follow", what, a->dir);
}

double lw_anneal_acceptance(const lw_anneal *a)
{
  unsigned long p = 0, acc = 0;
  for (int k = 0; k < a->chain->n_moves; k++) {
    p += a->chain->stats[k].proposed;
    acc += a->chain->stats[k].accepted;
  }
  return p ? (double)acc / (double)p : NAN; /* (every particle pinned: no proposal) */
}

/* A wire of 5 free points with the default 10 tuning sweeps (50 proposals)
** kept its first step and was accepted 2 % of the time against the target
** 44 %, so its samples' autocorrelation ran to 500 sweeps, and nothing said
** so.  Steps far too small are as bad (every move accepted, the chain
** crawling) unless the step is at its cap, where a flat energy takes
** everything.  Annealing schedules tune at every step, and their acceptance
** falls with the temperature by design: only a constant one is judged. */
void lw_anneal_tuning_note(const lw_anneal *a, char *buf, size_t n)
{
  buf[0] = '\0';
  const lw_chain *c = a->chain;
  if (a->dyn || !c || !a->sched_type || strcmp(a->sched_type->name, "constant")) return;
  /* A move never refused either has a step far too small or does not
  ** change the energy (translations of a lone spline with no term that sees
  ** where it lies, whose tuning grew the step to 135 mm and asked for more
  ** tuning): said apart, with both ways out.  A step at half its cap or more
  ** is neither (a temperature that takes everything), and is not said. */
  size_t m = 0, flat = 0;
  char same[256] = "";
  const double ceiling = lw_chain_ceiling(c); /* the smallest steps' acceptance (1 but for another rule) */
  for (int k = 0; k < c->n_moves && m + 1 < n; k++) {
    const lw_move_stats *st = &c->stats[k];
    if (!(c->step_max[k] > 0.0) || st->proposed < 100) continue;
    const double acc = (double)st->accepted / (double)st->proposed;
    if (st->accepted == st->proposed && c->step[k] < 0.5 * c->step_max[k]) {
      if (flat + 1 < sizeof same)
        flat += (size_t)snprintf(same + flat, sizeof same - flat, "%s%s", flat ? ", " : "", a->sys_type->move_names[k]);
    } else if (acc < 0.25 * c->target[k] ||
               (acc > ceiling - 0.25 * (ceiling - c->target[k]) && c->step[k] < 0.5 * c->step_max[k])) {
      m += (size_t)snprintf(buf + m, n - m, "%s%s moves were accepted %.1f %% of the time against the target %.0f %%",
                            m ? ", " : "", a->sys_type->move_names[k], 100.0 * acc, 100.0 * c->target[k]);
    }
  }
  if (m && m + 1 < n && ceiling < 1.0)
    m += (size_t)snprintf(buf + m, n - m, " (under driver = %s a target is its share of %.0f %%, the acceptance of "
                          "the smallest steps)", a->params.driver, 100.0 * ceiling);
  if (m && m + 1 < n)
    m += (size_t)snprintf(buf + m, n - m, ": moves.tune_sweeps = %d sweeps was too short to tune their step for this "
                          "system (raise it)", a->params.tune_sweeps);
  if (flat && m + 1 < n)
    snprintf(buf + m, n - m, "%s%s moves were accepted every time: their step is far too small for this system "
             "(moves.tune_sweeps = %d sweeps did not grow it enough), or the energy does not change under them (no "
             "term sees them: a weight of 0 for them in [moves] leaves them out)", m ? "; " : "", same,
             a->params.tune_sweeps);
}

void lw_anneal_ladder_note(const lw_anneal *a, char *buf, size_t n)
{
  buf[0] = '\0';
  const lw_tempering *pt = a->pt;
  if (!pt || a->params.tune_ladder != LW_LADDER_EQUAL || a->params.ladder_sweeps <= 0) return;
  double sum = 0.0, sq = 0.0, inv_tries = 0.0, lo = 2.0, hi = -1.0;
  int at_lo = 0, at_hi = 0;
  for (int k = 0; k + 1 < pt->n; k++) {
    if (pt->tried[k] < 1) return;
    const double r = lw_tempering_acceptance(pt, k);
    sum += r;
    sq += r * r;
    inv_tries += 1.0 / (double)pt->tried[k];
    if (r < lo) lo = r, at_lo = k;
    if (r > hi) hi = r, at_hi = k;
  }
  const double m = sum / (pt->n - 1), rms = sqrt(fmax(0.0, sq / (pt->n - 1) - m * m));
  /* Equal rates m measured over few tries spread by chance (binomially: sd
  ** sqrt(m (1 - m) / tries) a pair, with the rates pooled, since one pair's
  ** own over one or two tries is 0 or 1 and its r (1 - r) 0): only a spread
  ** past three of those says the ladder is uneven.  Past 1000 tries a pair
  ** the 0.06 decides. */
  if (rms > 0.06 && rms > 3.0 * sqrt(m * (1.0 - m) * inv_tries / (pt->n - 1)))
    snprintf(buf, n, "the swap rates since the ladder froze run from %.2f (rungs %d and %d) to %.2f (%d and %d), %.3f "
             "rms about their mean: tempering.ladder_sweeps = %d was too short to equalise them (raise it)", lo, at_lo,
             at_lo + 1, hi, at_hi, at_hi + 1, rms, a->params.ladder_sweeps);
}

void lw_anneal_checkpoint_note(const lw_anneal *a, char *buf, size_t n)
{
  double wall = lw_phase_clock() - a->wall_start, cost = a->ckpt_seconds;
  /* the longest write as long as the others on average: a process stopped
  ** (SIGSTOP, a batch system's suspend) during one write was told to
  ** checkpoint less (every write at the fastest one's time hid the note
  ** where the disk's times vary, on the file systems that need it most) */
  if (a->ckpt_count > 1) {
    const double others = (a->ckpt_seconds - a->ckpt_longest) / (a->ckpt_count - 1);
    cost -= a->ckpt_longest - others;
    wall -= a->ckpt_longest - others;
  }
  buf[0] = '\0';
  if (!(cost > 1.0 && cost > wall / 3.0)) return;
  /* (no figures of this run: a sweep shows each distinct note once) */
  const char *share = cost > wall / 2.0 ? "most" : "over a third";
  if (a->params.checkpoint_every < a->end_sweep)
    snprintf(buf, n, "writing state.lw every %d sweeps (output.checkpoint_every) took %s of this run's time: a "
             "larger value costs less, and a killed run then loses more sweeps", a->params.checkpoint_every, share);
  else /* (no checkpoint between the first and the last: the key would change nothing) */
    snprintf(buf, n, "writing state.lw at the start and the end took %s of this run's time%s", share,
             a->n_rep > 1 ? " (it and a replica-K.lw for each rung, each synced to disk)" : "");
}

void lw_anneal_frames_note(const lw_anneal *a, char *buf, size_t n)
{
  buf[0] = '\0';
  long now;
  unsigned w, h;
  if (!a->frame_before.have || !lw_runfiles_frame_size(a->dir, LONG_MAX, &now, &w, &h) ||
      now == a->frame_before.sweep || (w == a->frame_before.w && h == a->frame_before.h))
    return;
  snprintf(buf, n, "%s/frames/ mixes sizes: its frames to sweep %ld are %u x %u pixels, this resume's %u x %u (a "
           "drawing key of scene.ini, output.png_scale say, was edited): a film of them is scaled to one size",
           a->dir, a->frame_before.sweep, a->frame_before.w, a->frame_before.h, w, h);
}

void lw_anneal_film_note(const lw_anneal *a, char *buf, size_t n)
{
  static const char *const what[2] = {"a frame", "a sample"}, *const key[2] = {"frames_every", "samples_every"};
  const int every[2] = {a->params.frames_every, a->params.samples_every};
  const double wall = lw_phase_clock() - a->wall_start, cost = a->film_seconds[0] + a->film_seconds[1];
  buf[0] = '\0';
  if (!(cost > 1.0 && cost > wall / 3.0)) return;
  size_t used = 0;
  for (int k = 0; k < 2; k++) {
    char each[32] = "every sweep";
    if (every[k] > 1) snprintf(each, sizeof each, "every %d sweeps", every[k]);
    if (a->film_seconds[k] > cost / 4.0 && used < n)
      used += (size_t)snprintf(buf + used, n - used, "%swriting %s %s (output.%s) took %.0f %%", used ? ", " : "",
                               what[k], each, key[k], 100.0 * a->film_seconds[k] / wall);
  }
  if (used < n)
    snprintf(buf + used, n - used, " of this run's time: a larger value costs less (the run's results are the same)");
}

void lw_anneal_drift_note(const lw_anneal *a, char *buf, size_t n)
{
  buf[0] = '\0';
  if (a->row_drift > LW_ANNEAL_DRIFT_NOTE)
    snprintf(buf, n, "the running energy was %.2g off its recomputation from scratch (of the largest energy since "
             "the one before; rounding leaves about 1e-14): the moves' energy differences do not add up to the "
             "energy, and the run sampled another energy than the one it reports (a fault of the %s system's "
             "row; please report it)", a->row_drift, a->params.system);
}

void lw_anneal_observables_note(const lw_anneal *a, char *buf, size_t n)
{
  char word[LW_RUNDIR_WORD_MAX];
  buf[0] = '\0';
  if (a->observables_lost[0])
    snprintf(buf, n, "summary.json's observables are null: %s ('linewise stats %s' computes them from trace.csv, "
             "given the memory)", a->observables_lost, lw_rundir_shell_word(a->dir, word, sizeof word));
  else if (a->observables_rounded[0])
    snprintf(buf, n, "summary.json's statistics of %s are of values trace.csv prints to 10 digits "
             "(output.trace_exact = 0, as runs begun before 2026-12-07), which is coarse against their spread: their "
             "error bars and a heat capacity are off by over 1 %% (a new run writes every digit)",
             a->observables_rounded);
}

/* Temperature step of sweep s: the sweeps are shared out evenly; past the
** end the last step holds. */
static long block_of(const lw_anneal *a, long s)
{
  long S = a->params.sweeps, B = a->params.steps;
  if (S <= 0 || s >= S) return B - 1;
  return (long)((long long)s * B / S);
}

static long block_start(const lw_anneal *a, long b)
{
  long long S = a->params.sweeps, B = a->params.steps;
  return (long)((b * S + B - 1) / B);
}

/* The energies a resumed step has gathered (the adaptive schedule's next
** temperature is made of them): no more than the sweeps of the step so far,
** and a variance that is not negative (one fell back on the geometric ratio
** without a word). */
static lw_status check_block_energy(const lw_anneal *a, const char *path, lw_error *err)
{
  /* the step's sweeps since its tuning (sweep_once: a sweep tunes within
  ** the step's first tune_sweeps, before anneal.sweeps) */
  const long start = a->block >= 0 ? block_start(a, a->block) : a->sweep;
  long until = a->sweep;
  if (start + a->params.tune_sweeps < until) until = start + a->params.tune_sweeps;
  if (a->params.sweeps < until) until = a->params.sweeps;
  const double done = (double)(a->sweep - start - (until > start ? until - start : 0));
  const double n = a->acc_n, spread = n * a->acc_sumsq - a->acc_sum * a->acc_sum;
  if (n > done)
    return lw_error_set(err, LW_EINPUT, "%s: [run] block_energy: %.17g samples, but the step has had %.0f sweeps since "
                        "its step tuning: the state was edited", path, n, done);
  if (n == 0.0 && (a->acc_sum != 0.0 || a->acc_sumsq != 0.0))
    return lw_error_set(err, LW_EINPUT, "%s: [run] block_energy: no samples, but sums %.17g and %.17g: the state was "
                        "edited", path, a->acc_sum, a->acc_sumsq);
  /* the sums' rounding grows with n (a nearly constant energy summed 4e7
  ** times left n sum-of-squares - sum^2 at -2e-9 of it): 4 n eps of slack */
  if (spread < -fmax(1e-9, 4.0 * n * DBL_EPSILON) * n * a->acc_sumsq)
    return lw_error_set(err, LW_EINPUT, "%s: [run] block_energy: %.17g samples with sum %.17g and sum of squares %.17g "
                        "make a negative variance: the state was edited", path, n, a->acc_sum, a->acc_sumsq);
  return LW_OK;
}

/* The schedule's temperature of step b after step b - 1 at a->t_prev,
** measured in a->prev or (measured = 0: a step without sweeps, or b = 0) not
** at all.  The statistics are the coldest rung's, at ladder[0] t / t_start:
** Huang's T / sd for it is this on the schedule's own scale (the schedule's
** temperature with the cold rung's sd cooled 5 to 10 times too fast). */
static double step_temperature(const lw_anneal *a, long b, int measured)
{
  lw_block_stats prev = a->prev;
  if (a->pt && a->pt->ladder[0] > 0.0) prev.sd *= a->params.t_start / a->pt->ladder[0];
  return a->sched_type->temperature(&a->sched, b, a->t_prev, measured ? &prev : NULL);
}

static void dir_file(char *buf, size_t n, const lw_anneal *a, const char *name)
{
  lw_path_join(buf, n, a->dir, name);
}

/* A run spread over processes (anneal_net.h): process 0 writes the run's
** files, and each replica is swept by the process that owns it. */
static int writes_files(const lw_anneal *a) { return !a->net || a->net->rank == 0; }

/* The run's directory as this process found it, or 0 0.  Its files are
** written by path: a directory moved aside while the run went on, and
** another made under its name (a new run), took the old run's checkpoints,
** and its final files with exit 0, while the new run failed. */
static void dir_identity(lw_anneal *a)
{
  struct stat st;
  a->dir_id[0] = a->dir_id[1] = 0;
  if (!stat(a->dir, &st)) a->dir_id[0] = (unsigned long long)st.st_dev, a->dir_id[1] = (unsigned long long)st.st_ino;
}

lw_status lw_anneal_dir_ours(const lw_anneal *a, lw_error *err)
{
  struct stat st;
  if (!a->dir_id[0] && !a->dir_id[1]) return LW_OK;
  const int there = !stat(a->dir, &st);
  if (there && (unsigned long long)st.st_dev == a->dir_id[0] && (unsigned long long)st.st_ino == a->dir_id[1])
    return LW_OK;
  if (there)
    return lw_error_set(err, LW_EIO, "%s is another directory now: the run's directory was moved or removed, and "
                        "another made in its place, which this run leaves alone", a->dir);
  return lw_error_set(err, LW_EIO, "%s is no longer there: the run's directory was removed or moved", a->dir);
}

/* The same, dir_moved set. */
static lw_status dir_still_ours(lw_anneal *a, lw_error *err)
{
  lw_status s = lw_anneal_dir_ours(a, err);
  if (s) a->dir_moved = 1;
  return s;
}

static int replica_here(const lw_anneal *a, int r)
{
  return !a->net || lw_anneal_net_owner(r, a->n_rep, a->net->size) == a->net->rank;
}

static int rung_here(const lw_anneal *a, int k) { return replica_here(a, a->pt ? a->pt->at[k] : 0); }

/* The energy of the replica at rung k; a stand-in's is its owner's. */
static double rung_energy(const lw_anneal *a, int k)
{
  return rung_here(a, k) ? lw_system_total(a->chains[k]->sys) : a->net->energy[a->pt->at[k]];
}

double lw_anneal_energy(const lw_anneal *a) { return rung_energy(a, 0); }

/* n bytes as "2.2 TB", "3.36 GB", "62.7 MB" or "840 kB" into buf (16 bytes). */
static const char *bytes_text(double n, char *buf)
{
  const char *unit = n >= 1e12 ? "TB" : n >= 1e9 ? "GB" : n >= 1e6 ? "MB" : "kB";
  snprintf(buf, 16, "%.3g %s", n / (n >= 1e12 ? 1e12 : n >= 1e9 ? 1e9 : n >= 1e6 ? 1e6 : 1e3), unit);
  return buf;
}

void lw_anneal_frames_disk_note(const lw_anneal *a, char *buf, size_t n, int *warning)
{
  buf[0] = '\0';
  *warning = 0;
  const long every = a->params.frames_every, from = a->sweep, to = a->end_sweep;
  long at;
  unsigned w, h;
  char path[LW_PATH_MAX + 64], t[3][16];
  struct stat st;
  struct statvfs fs;
  if (!every || to <= from || !rung_here(a, 0) || !lw_runfiles_frame_size(a->dir, LONG_MAX, &at, &w, &h)) return;
  snprintf(path, sizeof path, "%s/frames/frame-%06ld.png", a->dir, at);
  if (stat(path, &st) || statvfs(path, &fs)) return;
  /* those on the grid past the sweep done, and the end's where it is off it */
  const double frames = (double)(to / every - from / every) + (to % every != 0);
  const double need = frames * (double)st.st_size, free = (double)fs.f_bavail * (double)fs.f_frsize;
  if (!(need > free) && !(need > 1e9)) return;
  *warning = need > free;
  snprintf(buf, n, "%s/frames/: the %.0f frames still to come (output.frames_every = %ld) take about %s at the %s "
           "of %s, %s %s free there%s", a->dir, frames, every, bytes_text(need, t[0]), bytes_text(st.st_size, t[1]),
           strrchr(path, '/') + 1, *warning ? "more than the" : "with", bytes_text(free, t[2]),
           *warning ? ": the run fails when the disk fills (a larger frames_every takes less)" : "");
}

/* Schedule and its table (relative to the scene file).  The dynamics has no
** temperature: its scene's schedule keys are only noted as unread
** (lw_anneal_check_keys), not checked. */
static lw_status setup_schedule(lw_anneal *a, lw_error *err)
{
  const lw_params *p = &a->params;
  if (lw_driver_is_motion(p)) return LW_OK;
  const lw_param_def *d = lw_params_find("anneal", "schedule");
  char where[LW_PATH_MAX + 32];
  lw_params_origin(p, d, where, sizeof where);
  a->sched_type = lw_schedule_find(p->schedule);
  char unseen[96];
  if (!a->sched_type)
    return lw_error_set(err, LW_EINPUT, "%s: key 'anneal.schedule': expected one of %s, got '%s'%s", where,
                        lw_schedule_names(), p->schedule, lw_text_unseen_char(p->schedule, unseen, sizeof unseen));
  a->sched.t_start = p->t_start;
  a->sched.t_end = p->t_end;
  a->sched.blocks = p->steps;
  a->sched.lambda = p->lambda;
  if (a->sched_type->needs & LW_SCHEDULE_USES_TABLE) {
    if (!p->table[0])
      return lw_error_set(err, LW_EINPUT, "%s: key 'anneal.schedule': 'table' needs anneal.table (a file)", where);
    if (lw_schedule_read_table(&a->sched, p->table, err)) return lw_params_blame(p, "anneal", "table", err);
  }
  lw_error e2;
  if (!lw_schedule_check(a->sched_type, &a->sched, &e2)) return LW_OK;
  /* the message names the parameter it found wrong: blame its key (the
  ** order takes t_end where a cooling schedule's t_end exceeds t_start) */
  static const char *const named[][2] = {{"t_end", "t_end"}, {"t_start", "t_start"}, {"lambda", "lambda"},
                                         {"blocks", "steps"}};
  for (size_t k = 0; k < sizeof named / sizeof named[0]; k++)
    if (strstr(e2.msg, named[k][0])) {
      lw_error_set(err, LW_EINPUT, "%s", e2.msg);
      return lw_params_blame(p, "anneal", named[k][1], err);
    }
  return lw_error_set(err, LW_EINPUT, "%s: anneal.schedule = %s: %s", where, p->schedule, e2.msg);
}

/* Paths in the scene are relative to the scene file; the resolved scene.ini
** lives in the run directory, so they are made absolute first (path is a
** key's field of LW_PATH_MAX bytes). */
static void make_absolute(char *path, const char *scene_file)
{
  if (!path[0] || path[0] == '/') return;
  char dir[LW_PATH_MAX], joined[2 * LW_PATH_MAX + 2], real[4096];
  lw_path_dir(dir, sizeof dir, scene_file);
  lw_path_join(joined, sizeof joined, dir, path);
  if (realpath(joined, real) && strlen(real) < LW_PATH_MAX) {
    strcpy(path, real);
    return;
  }
  /* A missing file stays missing, but its name must still be absolute:
  ** relative, the scene's directory would be joined to it a second time
  ** when the picture is opened. */
  if (joined[0] != '/' && getcwd(real, sizeof real)) {
    size_t nc = strlen(real);
    snprintf(real + nc, sizeof real - nc, "/%s", joined);
    if (strlen(real) < LW_PATH_MAX) strcpy(path, real);
  } else if (strlen(joined) < LW_PATH_MAX) {
    strcpy(path, joined);
  }
}

/* A start (init.from) from a state the run would write over: its own
** directory's state.lw (by any name: a link to it too) or a replica file
** there (a redraw into its own directory kept one row of the run's
** trace.csv).  A start file of the user's beside a run is read before the run
** replaces the run's files, as a run without one would. */
static lw_status from_elsewhere(const lw_anneal *a, const char *dir, lw_error *err)
{
  const char *from = a->params.from;
  char real[4096], fdir[4096], rd[4096], state[LW_PATH_MAX + 16];
  struct stat sf, ss;
  if (!from[0] || !realpath(from, real) || !realpath(dir, rd) || stat(real, &sf)) return LW_OK;
  lw_path_dir(fdir, sizeof fdir, real);
  lw_path_join(state, sizeof state, dir, "state.lw");
  const int run_there = !stat(state, &ss);
  const int same_file = run_there && ss.st_dev == sf.st_dev && ss.st_ino == sf.st_ino;
  const char *base = real + strlen(fdir) + (real[strlen(fdir)] == '/');
  /* (the run before, set aside in DIR/.replaced while a run replaces it,
  ** comes back over whatever a start from it would write) */
  char stash[4096 + 16];
  snprintf(stash, sizeof stash, "%s/%s", rd, LW_RUNFILES_STASH);
  if (!strncmp(fdir, stash, strlen(stash)) && (!fdir[strlen(stash)] || fdir[strlen(stash)] == '/')) {
    lw_error_set(err, LW_EINPUT, "'%s' is in %s, where the run in %s waits while a run replaces it: expected a "
                 "state elsewhere (a run or resume there puts that run back first; copy the state out to redraw "
                 "from it)", from, stash, dir);
    return lw_params_blame(&a->params, "init", "from", err);
  }
  if (!same_file && !(!strcmp(fdir, rd) && (!strncmp(base, "replica-", 8) || !strcmp(base, "state.lw"))))
    return LW_OK;
  char scene[LW_PATH_MAX + 16], resume[LW_RUNDIR_WORD_MAX + 64] = "", word[LW_RUNDIR_WORD_MAX];
  lw_path_join(scene, sizeof scene, dir, "scene.ini");
  if (run_there && !access(scene, F_OK))
    snprintf(resume, sizeof resume, ", or 'linewise resume %s' to go on with it",
             lw_rundir_shell_word(dir, word, sizeof word));
  lw_error_set(err, LW_EINPUT, "'%s' is %s in %s, the directory this run writes, which would replace it%s; expected "
               "another --out (a redraw: docs/FORMATS.md, \"Redrawing a finished run\")%s", from,
               same_file ? "the state" : "a state", dir,
               run_there ? " and the files of the run there (its trace.csv, summary.json and drawings)" : "", resume);
  return lw_params_blame(&a->params, "init", "from", err);
}

/* A file a key names (init.from aside: from_elsewhere) that is one of the
** run files in dir, which this run removes or writes over: a picture drawn
** from the run's own final.png was gone when the run was resumed. */
static lw_status inputs_elsewhere(const lw_anneal *a, const char *dir, lw_error *err)
{
  char rd[4096];
  if (!realpath(dir, rd)) return LW_OK; /* (a new directory holds no run) */
  const size_t nd = strlen(rd);
  for (size_t i = 0; i < lw_param_count; i++) {
    const lw_param_def *d = &lw_param_table[i];
    const char *path = (const char *)&a->params + d->offset;
    if (d->type != LW_PT_STRING || strcmp(d->unit, "path") || !path[0] || lw_params_file_idle(&a->params, d))
      continue;
    /* the file itself, and the name in its folder (a link there is removed
    ** as well, whatever it leads to) */
    char real[2][4096 + LW_PATH_MAX], folder[LW_PATH_MAX];
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    lw_path_dir(folder, sizeof folder, path);
    if (!realpath(path, real[0])) real[0][0] = '\0';
    if (!realpath(folder, real[1]) ||
        snprintf(real[1] + strlen(real[1]), sizeof real[1] - strlen(real[1]), "/%s", base) < 0)
      real[1][0] = '\0';
    for (int k = 0; k < 2; k++) {
      if (strncmp(real[k], rd, nd) || real[k][nd] != '/' || !lw_runfiles_is_run_file(real[k] + nd + 1)) continue;
      lw_error_set(err, LW_EINPUT, "'%s' is %s of the run in %s, which this run removes or writes over (and then "
                   "resume could not read it); expected it elsewhere: a copy outside %s", path, real[k] + nd + 1, dir,
                   dir);
      return lw_params_blame(&a->params, d->section, d->key, err);
    }
  }
  return LW_OK;
}

/* Every key of a's parameters that names a file, made absolute; refused
** where that no longer fits on a line of the run's scene.ini, which resume
** reads (a picture named "pic.png" from a deep directory wrote a scene.ini
** that neither resume nor energy could read). */
static lw_status absolute_paths(lw_anneal *a, lw_error *err)
{
  for (size_t i = 0; i < lw_param_count; i++) {
    const lw_param_def *d = &lw_param_table[i];
    if (d->type != LW_PT_STRING || !d->unit || strcmp(d->unit, "path") || d->size != LW_PATH_MAX) continue;
    char *path = (char *)&a->params + d->offset, was[LW_PATH_MAX];
    snprintf(was, sizeof was, "%s", path);
    make_absolute(path, a->params.file);
    size_t len = strlen(path), cap = lw_params_text_cap(d);
    char where[LW_PATH_MAX + 32];
    if (len > cap || (was[0] && path[0] != '/')) {
      lw_params_origin(&a->params, d, where, sizeof where);
      /* (the path itself: links are followed, so a short link to a deep
      ** folder measures the deep path) */
      char size[LW_PATH_MAX + 48] = "too long";
      if (path[0] == '/') snprintf(size, sizeof size, "%zu bytes ('%s')", len, path);
      return lw_error_set(err, LW_EINPUT, "%s: key '%s.%s': '%s' made absolute is %s, and the run's scene.ini "
                          "(which resume reads) holds %zu on its line; copy the file to a shorter path (a link to it is "
                          "followed, which does not shorten it)",
                          where, d->section, d->key, was, size, cap);
    }
    /* a folder named "Fotos ;alt" is a comment from its ';' on, once the
    ** name is written into scene.ini: resume would look for "Fotos" */
    if (!lw_params_text_reads_back(path)) {
      lw_params_origin(&a->params, d, where, sizeof where);
      /* (a newline in a folder's name, shown as '?', was blamed on ';') */
      const char *c = path;
      while ((unsigned char)*c >= 0x20 || *c == '\t') c++;
      char why[96] = "';' after a blank begins a comment there, and blanks at either end are dropped";
      if (*c) snprintf(why, sizeof why, "byte %zu is a control character (0x%02X), which ends or breaks a line there",
                       (size_t)(c - path) + 1, (unsigned char)*c);
      return lw_error_set(err, LW_EINPUT, "%s: key '%s.%s': '%s' made absolute is '%s', which the run's "
                          "scene.ini (which resume reads) cannot hold: %s; rename the file or its folder",
                          where, d->section, d->key, was, path, why);
    }
  }
  return LW_OK;
}

/* The explicit ladder text into ladder[]: its count, or 0 with a message
** naming where the text was written. */
static int parse_ladder(const lw_params *p, const char *text, const char *where, double *ladder, lw_error *err)
{
  int n = lw_number_list(text, p->of_run ? 1 : 2, ladder, LW_TEMPERING_MAX);
  const int long_text = strlen(text) > 120; /* (257 rungs echoed 4.7 KB on one line) */
  if (n == -1) { /* the word that is no number ("1 2x 4" was said not to be 2 to 256 temperatures) */
    const char *w = text;
    size_t len = 0;
    double v;
    while (*(w += len + strspn(w + len, " \t,")) && lw_number_parse_n(w, len = strcspn(w, " \t,"), &v)) {}
    /* the word whole for what it hides (a no-break space between two
    ** numbers shows as "'1 2' is not a temperature"), shown cut between
    ** two characters */
    char whole[256], unseen[96];
    len = strcspn(w, " \t,");
    snprintf(whole, sizeof whole, "%.*s", (int)(len < sizeof whole ? len : sizeof whole - 1), w);
    size_t cut = len > 60 ? 57 : len;
    while (cut < len && cut > 0 && ((unsigned char)w[cut] & 0xC0) == 0x80) cut--;
    return lw_error_set(err, LW_EINPUT, "%s: key 'tempering.ladder': '%.*s%s' is not a temperature; expected finite "
                        "numbers such as 0.5 or 2e-3%s", where, (int)cut, w, cut < len ? "..." : "",
                        lw_text_unseen_char(whole, unseen, sizeof unseen)), 0;
  }
  if (n < 2 || n > LW_TEMPERING_MAX)
    return lw_error_set(err, LW_EINPUT, "%s: key 'tempering.ladder': expected 2 to %d temperatures, got '%.120s%s'%s",
                        where, LW_TEMPERING_MAX, text, long_text ? "..." : "", lw_number_list_hint(n)), 0;
  /* (up to 1e300, as t_min and t_max); before the count against replicas,
  ** which sent "1 2 2 4" to replicas = 4 first and then refused it anyway */
  for (int k = 0; k < n; k++)
    if (!(ladder[k] > 0.0) || !(ladder[k] <= 1e300) || (k > 0 && !(ladder[k] > ladder[k - 1])))
      return lw_error_set(err, LW_EINPUT, "%s: key 'tempering.ladder': expected increasing positive "
                          "temperatures up to 1e300, got '%.120s%s'", where, text, long_text ? "..." : ""), 0;
  if (p->replicas != 1 && p->replicas != n)
    return lw_error_set(err, LW_EINPUT, "%s: key 'tempering.ladder': %d temperatures for %d replicas: the ladder "
                        "sets the count, so expected tempering.replicas = %d or 1 (its default)", where, n,
                        p->replicas, n), 0;
  return n;
}

/* tempering.ladder_file into tempering.ladder, checked where the file says
** it.  The run's scene.ini holds the ladder in its place, with no file: a
** resume reads none (it may have been tuned again since), and a redraw
** from that scene.ini is not given the ladder twice. */
static lw_status read_ladder_file(lw_anneal *a, lw_error *err)
{
  lw_params *p = &a->params;
  if (!p->ladder_file[0] || lw_driver_is_motion(p)) return LW_OK;
  const lw_param_def *dl = lw_params_find("tempering", "ladder");
  char where[LW_PATH_MAX + 32], other[LW_PATH_MAX + 32];
  if (lw_params_given(p, dl)) {
    lw_params_origin(p, lw_params_find("tempering", "ladder_file"), where, sizeof where);
    lw_params_origin(p, dl, other, sizeof other);
    return lw_error_set(err, LW_EINPUT, "%s: key 'tempering.ladder_file': tempering.ladder is given too (%s); "
                        "expected one of them", where, other);
  }
  struct stat st;
  const int unread = stat(p->ladder_file, &st) ? errno : 0;
  if (unread || !S_ISREG(st.st_mode)) { /* (the reader's own message would call it a scene file) */
    lw_error_set(err, LW_EINPUT, "cannot read '%s': %s", p->ladder_file,
                 unread ? strerror(unread) : "not a regular file");
    return lw_params_blame(p, "tempering", "ladder_file", err);
  }
  /* (the reader's advice for a picture is to draw it) */
  unsigned char head[16];
  FILE *hf = fopen(p->ladder_file, "rb");
  const size_t got = hf ? fread(head, 1, sizeof head, hf) : 0;
  if (hf) fclose(hf);
  const char *picture = lw_image_kind(head, got, NULL);
  if (picture) {
    lw_error_set(err, LW_EINPUT, "%s: %s picture, not a ladder file: expected a [tempering] section with ladder = "
                 "t0 t1 ..., as a run's ladder.ini", p->ladder_file, picture);
    return lw_params_blame(p, "tempering", "ladder_file", err);
  }
  lw_params *f = malloc(sizeof *f);
  if (!f) return lw_error_set(err, LW_ENOMEM, "out of memory reading %s", p->ladder_file);
  lw_status s = lw_params_read_unresolved(f, p->ladder_file, err);
  if (s == LW_EINPUT) {
    free(f);
    return lw_params_blame(p, "tempering", "ladder_file", err);
  }
  const int at = f->line[dl - lw_param_table];
  for (size_t i = 0; !s && i < lw_param_count; i++)
    if (f->line[i] > 0 && &lw_param_table[i] != dl)
      s = lw_error_set(err, LW_EINPUT, "%s:%d: key '%s.%s': a ladder file holds only tempering.ladder (it is "
                       "tempering.ladder_file of %s)", f->file, f->line[i], lw_param_table[i].section,
                       lw_param_table[i].key, p->file);
  if (!s && at <= 0)
    s = lw_error_set(err, LW_EINPUT, "%s: no tempering.ladder in it: expected a [tempering] section with "
                     "ladder = t0 t1 ..., as a run's ladder.ini (it is tempering.ladder_file of %s)", f->file,
                     p->file);
  double ladder[LW_TEMPERING_MAX];
  snprintf(where, sizeof where, "%s:%d", f->file, at);
  /* (its values' faults name the scene's key too, as its lines' do) */
  if (!s && !parse_ladder(p, f->ladder, where, ladder, err)) s = lw_params_blame(p, "tempering", "ladder_file", err);
  if (!s) {
    snprintf(p->ladder, sizeof p->ladder, "%s", f->ladder);
    p->ladder_file[0] = '\0';
    a->ladder_from_file = 1;
  }
  free(f);
  return s;
}

/* Replicas of the run (the explicit ladder's length, or [tempering]
** replicas) and the base ladder; messages name the key's line. */
static lw_status setup_ladder(lw_anneal *a, double *ladder, lw_error *err)
{
  const lw_params *p = &a->params;
  char where[LW_PATH_MAX + 32];
  a->n_rep = p->replicas;
  /* the dynamics moves one system: a scene's ladder is for Monte Carlo
  ** (lw_anneal_check_keys notes it) */
  if (lw_driver_is_motion(p)) a->n_rep = 1;
  else if (p->ladder[0]) {
    lw_params_origin(p, lw_params_find("tempering", "ladder"), where, sizeof where);
    int n = parse_ladder(p, p->ladder, where, ladder, err);
    if (!n) return err->code;
    a->n_rep = n;
  } else if (a->n_rep > 1) {
    lw_params_origin(p, lw_params_find("tempering", "t_max"), where, sizeof where);
    if (!(p->t_max > p->t_min))
      return lw_error_set(err, LW_EINPUT, "%s: key 'tempering.t_max': expected a value above t_min = %g, got %g",
                          where, p->t_min, p->t_max);
    lw_tempering_geometric(ladder, a->n_rep, p->t_min, p->t_max);
  }
  if (a->net && a->n_rep < a->net->size && lw_driver_is_motion(p)) {
    /* its replicas key is idle (one system): not the key to change */
    lw_params_origin(p, lw_params_find("scene", "driver"), where, sizeof where);
    return lw_error_set(err, LW_EINPUT, "%s: key 'scene.driver': dynamics moves one system, which one process "
                        "holds; expected one process (mpirun -n 1, or linewise) for %d", where, a->net->size);
  }
  if (a->net && a->n_rep < a->net->size) {
    /* the key that set the count: the ladder's length, where there is one
    ** (replicas "not set: the default, 1" was blamed for a ladder of 3; a
    ** resume, the line "replicas = 1" of the run's scene.ini), read from
    ** its file where the scene names one (read_ladder_file has put the
    ** file's ladder in its place) */
    const char *key = !p->ladder[0] ? "replicas" : a->ladder_from_file ? "ladder_file" : "ladder";
    lw_params_origin(p, lw_params_find("tempering", key), where, sizeof where);
    return lw_error_set(err, LW_EINPUT, "%s: key 'tempering.%s': %d replicas for %d processes; expected at least one "
                        "replica per process%s", where, key, a->n_rep, a->net->size,
                        key[0] == 'l' ? " (the ladder's temperatures set the count)" : "");
  }
  lw_params_origin(p, lw_params_find("anneal", "t_start"), where, sizeof where);
  if (a->n_rep > 1 && !(p->t_start > 0.0))
    return lw_error_set(err, LW_EINPUT, "%s: key 'anneal.t_start': parallel tempering scales the ladder by "
                        "T(step) / t_start, so t_start must be > 0", where);
  return LW_OK;
}

/* Whether a scene of system t under driver v reads key d: a key the row
** names for one kind of driver is read under that kind only, though its
** `keys` name it too (a section's wildcard). */
static int key_read(const lw_system_type *t, const lw_driver_type *v, const lw_param_def *d)
{
  if (lw_params_named(v->keys, d)) return 1;
  if (lw_params_named(v->ignores, d)) return 0;
  /* a chain of its own rule runs without delayed acceptance, whose second
  ** stage is Metropolis's (driver.h): said by the rule, not by each row */
  if (v->accept && !strcmp(d->section, "anneal") && !strcmp(d->key, "delayed_acceptance")) return 0;
  if (lw_params_named(t->keys_dynamics, d)) return v->kind == LW_DRIVE_MOTION;
  if (lw_params_named(t->keys_metropolis, d)) return v->kind == LW_DRIVE_CHAIN;
  /* (a row's [moves] keys count under the chains only, wherever it lists them) */
  if (!strcmp(d->section, "moves") && v->kind != LW_DRIVE_CHAIN) return 0;
  return lw_params_named(t->keys, d);
}

/* The systems that read key d under driver v: "all", "splines, nurbs", or "". */
static void systems_reading(const lw_param_def *d, const lw_driver_type *v, char *sys, size_t n)
{
  int all = 1;
  size_t m = 0;
  sys[0] = '\0';
  for (int k = 0; lw_system_types[k]; k++) {
    if (!key_read(lw_system_types[k], v, d)) all = 0;
    else if (m < n) m += (size_t)snprintf(sys + m, n - m, "%s%s", m ? ", " : "", lw_system_types[k]->name);
  }
  if (all) snprintf(sys, n, "all");
}

void lw_anneal_key_readers(const lw_param_def *d, char *buf, size_t n)
{
  char first[128], sys[128], other[128];
  systems_reading(d, lw_driver_types[0], first, sizeof first);
  int same = 1;
  for (int v = 1; lw_driver_types[v]; v++) {
    systems_reading(d, lw_driver_types[v], sys, sizeof sys);
    same &= !strcmp(sys, first);
  }
  if (same) {
    snprintf(buf, n, "%s", first);
    return;
  }
  /* the drivers that read it from the same systems together: "S under a, b; T under c" */
  size_t m = 0;
  if (n) buf[0] = '\0';
  for (int v = 0; lw_driver_types[v] && m < n; v++) {
    systems_reading(d, lw_driver_types[v], sys, sizeof sys);
    int seen = !sys[0];
    for (int u = 0; u < v && !seen; u++) {
      systems_reading(d, lw_driver_types[u], other, sizeof other);
      seen = !strcmp(other, sys);
    }
    if (seen) continue;
    m += (size_t)snprintf(buf + m, n - m, "%s%s under %s", m ? "; " : "", sys, lw_driver_types[v]->name);
    for (int u = v + 1; lw_driver_types[u] && m < n; u++) {
      systems_reading(d, lw_driver_types[u], other, sizeof other);
      if (!strcmp(other, sys)) m += (size_t)snprintf(buf + m, n - m, ", %s", lw_driver_types[u]->name);
    }
  }
}

const char *lw_anneal_key_values(const lw_param_def *d)
{
  if (!strcmp(d->section, "scene") && !strcmp(d->key, "system")) return lw_system_names();
  if (!strcmp(d->section, "scene") && !strcmp(d->key, "driver")) return lw_driver_names();
  if (!strcmp(d->section, "anneal") && !strcmp(d->key, "schedule")) return lw_schedule_names();
  if (!strcmp(d->section, "anneal") && !strcmp(d->key, "domains")) return "off|1 to 64|auto";
  return NULL;
}

lw_status lw_anneal_check_keys(const lw_params *p, char *unread, size_t size, lw_error *err)
{
  const lw_system_type *t = lw_system_of(p, err);
  const lw_driver_type *v = t ? lw_driver_of(p, err) : NULL;
  if (!v) return err->code;
  size_t m = 0;
  if (size) unread[0] = '\0';
  for (size_t i = 0; i < lw_param_count; i++) {
    const lw_param_def *d = &lw_param_table[i];
    if (!lw_params_given(p, d) || key_read(t, v, d)) continue;
    /* a run's scene.ini, redrawn, writes every key at its run's values: a
    ** default changed since (image_levels_flat's 1) refused a D-NURBS redraw
    ** for a picture key no one set */
    if (p->run_header && p->line[i] > 0) continue;
    char where[LW_PATH_MAX + 32], readers[300];
    lw_params_origin(p, d, where, sizeof where);
    int elsewhere = 0; /* read under another driver */
    for (int k = 0; lw_driver_types[k]; k++) elsewhere |= key_read(t, lw_driver_types[k], d);
    if (elsewhere) {
      if (m < size)
        m += (size_t)snprintf(unread + m, size - m, "%s%s.%s (%s)", m ? ", " : "", d->section, d->key, where);
      continue;
    }
    lw_anneal_key_readers(d, readers, sizeof readers);
    return lw_error_set(err, LW_EINPUT, "%s: key '%s.%s': the %s system reads it under no driver (read by: "
                        "%s); expected no line, or the default '%s'", where, d->section, d->key, t->name, readers,
                        d->def);
  }
  return LW_OK;
}

/* Settings under which the schedule never reaches its end, in buf (empty if
** none), for a note: more steps than sweeps skip some and end short of
** t_end; one step stays at t_start; table rows past the last step (steps
** count from 0) are never read.  Each was silent, and a methods paper
** would have described another schedule. */
static void schedule_note(const lw_anneal *a, char *buf, size_t n)
{
  const lw_params *p = &a->params;
  const lw_schedule *s = &a->sched;
  buf[0] = '\0';
  if (!a->sched_type || lw_driver_is_motion(p) || p->sweeps <= 0) return;
  const unsigned needs = a->sched_type->needs;
  const int table = s->n_table > 0, ends = (needs & LW_SCHEDULE_USES_END) || table;
  const long last = block_of(a, p->sweeps - 1);
  size_t m = 0;
  /* steps counted from 0, as state.lw's block and the table's rows */
  /* (a table that ends before the last step the run reaches misses
  ** nothing: the note below says it holds) */
  if (last < s->blocks - 1 && ends && !(table && s->table_block[s->n_table - 1] <= (double)last))
    m += (size_t)snprintf(buf, n, "anneal.steps = %ld is more than the %ld sweeps: some steps are skipped, and "
                          "the run ends at step %ld (steps count from 0 to %ld), short of %s", s->blocks,
                          (long)p->sweeps, last, s->blocks - 1, table ? "the table's last step" : "t_end");
  if (table && s->table_block[s->n_table - 1] > (double)(s->blocks - 1) && m < n)
    m += (size_t)snprintf(buf + m, n - m, "%sanneal.table has rows past step %ld, the last of anneal.steps = %ld "
                          "(steps count from 0): they are never reached", m ? "\n" : "", s->blocks - 1, s->blocks);
  /* a table that ends before the run's last step holds its last row for
  ** the rest, which a table's writer took for the run's end (a helper's
  ** 0.01 at step 9 of 20 held for 55 % of the sweeps, unsaid) */
  const long reached = last < s->blocks - 1 ? last : s->blocks - 1;
  if (table && s->table_block[s->n_table - 1] < (double)reached && m < n)
    m += (size_t)snprintf(buf + m, n - m, "%sanneal.table ends at step %.0f, before the run's last step %ld "
                          "(anneal.steps = %ld, steps count from 0): its last temperature, %g, holds for the %ld "
                          "steps after it (a row at step %ld ends the table where the run does)", m ? "\n" : "",
                          s->table_block[s->n_table - 1], reached, s->blocks, s->table_temp[s->n_table - 1],
                          reached - (long)s->table_block[s->n_table - 1], reached);
  if (s->blocks == 1 && (needs & LW_SCHEDULE_USES_END) && s->t_end != s->t_start && m < n)
    m += (size_t)snprintf(buf + m, n - m, "%sanneal.steps = 1: the run stays at t_start = %g (t_end = %g is the "
                          "temperature of the last of two or more steps)", m ? "\n" : "", s->t_start, s->t_end);
  /* At T = 0 a chain takes a move that lowers the energy and no other,
  ** whatever its rule: its smallest steps are taken half the time, so a
  ** target above that shrank the steps to 1e-15 mm, unsaid.  (A share of
  ** the rule's a(0) is the target: under barker, half of it.) */
  const lw_driver_type *v = lw_driver_find(p->driver);
  const double ceiling = v && v->accept ? v->accept(0.0) : 1.0, t0 = table ? s->table_temp[0] : s->t_start;
  /* (each target only where a move tunes toward it) */
  const double single = p->mix_point > 0.0 || p->mix_vector > 0.0 ? p->target : 0.0,
               rigid = p->mix_translate > 0.0 || p->mix_rotate > 0.0 ? p->target_spline : 0.0;
  if (t0 == 0.0 && p->tune_sweeps > 0 && fmax(single, rigid) * ceiling >= 0.5 && m < n)
    m += (size_t)snprintf(buf + m, n - m, "%sthe run tunes its steps at T = 0, where a chain takes its smallest steps "
                          "half the time: moves.target%s = %g is out of reach there, and the steps shrink to nothing "
                          "(expected a target below 0.5)", m ? "\n" : "", single >= rigid ? "" : "_spline",
                          fmax(single, rigid));
  /* replicas = 1 given to turn tempering off, under a scene's ladder that
  ** sets the count: its rungs all ran, unsaid */
  if (a->n_rep > 1 && p->replicas == 1 && !p->of_run && lw_params_line(p, "tempering", "replicas") && m < n)
    m += (size_t)snprintf(buf + m, n - m, "%stempering.replicas = 1 is given, but tempering.ladder%s has %d rungs and "
                          "sets the count: %d replicas run (for one chain, give tempering.ladder%s empty too)",
                          m ? "\n" : "", a->ladder_from_file ? "_file's ladder" : "", a->n_rep, a->n_rep,
                          a->ladder_from_file ? "_file" : "");
  /* a ladder tuned over no sweeps, or while the steps still tune (LJ13's
  ** default 200 of its 2000: swap rates less even than the geometric
  ** start's, two round trips in 40000 sweeps), was silent */
  if (a->n_rep > 1 && p->tune_ladder == LW_LADDER_EQUAL && m < n) {
    if (p->ladder_sweeps == 0)
      snprintf(buf + m, n - m, "%stempering.tune_ladder = equal with ladder_sweeps = 0 tunes nothing: the ladder "
               "stays as given", m ? "\n" : "");
    /* (the ladder moves once every LW_TEMPERING_TUNE_EVERY exchanges) */
    else if (p->ladder_sweeps / p->exchange_every < LW_TEMPERING_TUNE_EVERY)
      snprintf(buf + m, n - m, "%stempering.ladder_sweeps = %d holds %d exchange%s (exchange_every = %d), and the "
               "ladder moves once every %d: it stays as given%s", m ? "\n" : "", p->ladder_sweeps,
               p->ladder_sweeps / p->exchange_every, p->ladder_sweeps / p->exchange_every == 1 ? "" : "s",
               p->exchange_every, LW_TEMPERING_TUNE_EVERY,
               p->exchange_every > p->ladder_sweeps ? ", the swap statistics count from the start and no ladder.ini "
                                                      "is written" : "");
    else if (p->ladder_sweeps <= p->tune_sweeps)
      snprintf(buf + m, n - m, "%stempering.ladder_sweeps = %d ends within moves.tune_sweeps = %d: the ladder is "
               "tuned on rungs whose steps still tune, far from settled, and may come out less even than where it "
               "started (a few times tune_sweeps tunes it on settled rungs)", m ? "\n" : "", p->ladder_sweeps,
               p->tune_sweeps);
  }
}

/* Keys the scene sets that its other settings leave idle (a table under a
** schedule that reads none, a polygon under another frame), in idle with
** why: noted, so that a mistake there shows before the setting that reads
** them is chosen (a missing table file went unseen). */
static void idle_keys(const lw_anneal *a, char *idle, size_t size)
{
  const lw_params *p = &a->params;
  const unsigned needs = a->sched_type ? a->sched_type->needs : ~0u; /* (dynamics: noted as unread) */
  static const char *const table[] = {"anneal.table", NULL}, *const lambda[] = {"anneal.lambda", NULL},
                           *const polygon[] = {"scene.polygon", NULL}, *const mask[] = {"scene.mask_image", NULL},
                           *const field_file[] = {"scene.field_file", "scene.field_file_y", "scene.field_file_scale",
                                                  "scene.field_file_layout", NULL},
                           *const orientation[] = {"scene.orientation", NULL},
                           *const picture[] = {"scene.image_width", "scene.image_blur", "scene.image_flatten",
                                               "scene.image_levels", "scene.image_levels_alpha",
                                               "scene.image_levels_flat", "scene.image_gamma", "scene.image_contrast",
                                               "scene.image_invert",
                                               NULL},
                           *const levels_alpha[] = {"scene.image_levels_alpha", "scene.image_levels_flat", NULL},
                           *const ladder[] = {"tempering.t_min", "tempering.t_max", "tempering.exchange_every",
                                              "tempering.tune_ladder", "tempering.ladder_sweeps", NULL},
                           *const ends[] = {"tempering.t_min", "tempering.t_max", NULL},
                           *const seed[] = {"anneal.seed", "anneal.seed_version", NULL},
                           *const gravity[] = {"dynamics.gravity_x", "dynamics.gravity_y", NULL},
                           *const pin_vectors[] = {"dynamics.pin_vectors", NULL},
                           *const machine[] = {"plot.tolerance", "plot.turn", "plot.bed_width", "plot.bed_height",
                                               NULL},
                           *const gcode[] = {"plot.gcode_travel", "plot.gcode_pen_up", "plot.gcode_pen_down", NULL},
                           *const quench[] = {"anneal.quench_tol", "anneal.quench_iterations", "anneal.quench_stall",
                                              NULL},
                           *const pair[] = {"energy.pair_cutoff", "energy.pair_near", "energy.pair_quadrature", NULL},
                           *const tuning[] = {"tempering.ladder_sweeps", NULL},
                           *const t_start[] = {"anneal.t_start", NULL}, *const t_end[] = {"anneal.t_end", NULL};
  const lw_idle_rule drivers[] = {
      {table, a->sched_type && lw_params_file_idle(p, lw_params_find("anneal", "table")),
       "anneal.schedule reads no table"},
      {lambda, !(needs & LW_SCHEDULE_USES_LAMBDA), "anneal.schedule is not adaptive"},
      /* (a constant schedule's t_end, a table's: a study that varied it measured noise) */
      {t_end, !(needs & LW_SCHEDULE_USES_END), "anneal.schedule reads no t_end"},
      /* (tempering scales its ladder by T / t_start, which a constant
      ** schedule keeps at 1) */
      {t_start, !(needs & LW_SCHEDULE_USES_START) && a->n_rep == 1, "anneal.schedule reads no t_start"},
      {t_start, a->n_rep > 1 && a->sched_type == &lw_schedule_constant,
       "a constant schedule keeps the rungs at the ladder"},
      {polygon, p->boundary != LW_BND_POLYGON, "scene.boundary is not polygon"},
      {mask, lw_params_file_idle(p, lw_params_find("scene", "mask_image")), "scene.mask is not image"},
      /* (under energy.field = 0 the system's rule names them) */
      {field_file, p->field != LW_FLD_FILE && p->field_coef != 0.0, "scene.field is not file"},
      /* (the photo preset's own auto, which a run's scene.ini holds: a redraw
      ** from it noted a key its user never set) */
      {orientation, p->page == LW_PAGE_CUSTOM && !(p->preset == LW_PRESET_PHOTO && p->orientation == LW_ORIENT_AUTO),
       "no scene.page names a size"},
      {picture, !p->image[0], "no scene.image"},
      {levels_alpha, p->image[0] && p->image_levels == 0.0, "scene.image_levels = 0"},
      {ladder, a->n_rep == 1, "one replica"},
      {ends, a->n_rep > 1 && p->ladder[0], "tempering.ladder names the temperatures"},
      /* (a seed sweep of the whip gave identical "independent" runs) */
      {seed, lw_driver_is_motion(p) && p->from[0], "the dynamics from init.from draws no random number"},
      {gravity, p->dyn_rho == 0.0, "dynamics.rho = 0: no mass to weigh"},
      {pin_vectors, lw_driver_is_motion(p) && p->dyn_pin == LW_PIN_NONE, "dynamics.pin = none"},
      /* (a bed too small for the page passed unchecked, without a word) */
      {machine, !p->hpgl && !p->gcode, "neither output.hpgl nor output.gcode"},
      {gcode, !p->gcode, "output.gcode = 0"},
      {quench, p->quench == LW_QUENCH_NONE, "anneal.quench = none"},
      {pair, p->pair == 0.0, "energy.pair = 0"},
      {tuning, a->n_rep > 1 && p->tune_ladder == LW_LADDER_FIXED, "tempering.tune_ladder = fixed"},
  };
  /* and the system's own (its particles' boundary, its nurbs' weights) */
  lw_idle_rule rule[sizeof drivers / sizeof *drivers + LW_IDLE_RULES_MAX];
  size_t n = sizeof drivers / sizeof *drivers, m = 0;
  memcpy(rule, drivers, sizeof drivers);
  if (a->sys_type && a->sys_type->idle) n += (size_t)a->sys_type->idle(p, rule + n);
  if (size) idle[0] = '\0';
  for (size_t r = 0; r < n; r++) {
    if (!rule[r].idle) continue;
    for (size_t i = 0; i < lw_param_count; i++) {
      const lw_param_def *d = &lw_param_table[i];
      if (!lw_params_named(rule[r].keys, d) || !lw_params_given(p, d)) continue;
      char where[LW_PATH_MAX + 32];
      lw_params_origin(p, d, where, sizeof where);
      if (m < size)
        m += (size_t)snprintf(idle + m, size - m, "%s%s.%s (%s: %s)", m ? ", " : "", d->section, d->key, where,
                              rule[r].why);
    }
  }
  if (m >= size && size > 4) strcpy(idle + size - 4, "..."); /* cut: said so */
}

/* The run's expected peak against its limit (a->mem), said in memory_note
** where past it: told, not refused (a fit with room, not a bound).  The
** drawing's, the close share's points above all: the run annealed for hours,
** then lost its close share or its preview. */
static void memory_note(lw_anneal *a)
{
  const double peak = a->mem.peak + a->mem.replica * (a->mem.here - 1);
  char reps[48] = "";
  if (a->mem.here > 1) snprintf(reps, sizeof reps, " in %d replicas", a->mem.here);
  a->memory_note[0] = '\0';
  if (a->mem.peak > 0.0 && peak > a->mem.limit)
    snprintf(a->memory_note, sizeof a->memory_note, "%s%s may take up to about %.3g GB at the drawing, more than "
             "the %.3g GB of %s: short of it the drawing leaves out its scores (summary.json's close_share and "
             "fidelity null) or fails (its state kept, to resume with more memory); %sfewer splines%s or a wider "
             "output.pen_width take less (docs/PERFORMANCE.md, \"Memory\")", a->mem.what, reps, peak / 1e9,
             a->mem.limit / 1e9, a->mem.by,
             /* (a camera's picture was 228 of 251 MB, the splines 16: the note
             ** named only them) */
             a->params.image[0] ? "a smaller scene.image_max_pixels (59 bytes a pixel while scored), " : "",
             a->mem.here > 1 ? " or replicas" : "");
}

/* The threads a parallel region may start (1 built without OpenMP, as the
** fuzz harnesses are: a call of OpenMP's own left them unlinked). */
static int threads_most(void)
{
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

/* The heap's bytes in use, or -1 where the C library does not say. */
static double heap_bytes(void)
{
#if defined(__GLIBC__) && (__GLIBC__ > 2 || __GLIBC_MINOR__ >= 33)
  const struct mallinfo2 mi = mallinfo2();
  return (double)mi.uordblks + (double)mi.hblkhd;
#else
  return -1.0;
#endif
}

/* The further replicas measured as they were made, from `before` (the
** first state made) to now (every replica built, its chain and domains
** too): each one's share of the heap's growth, with the fit's room, counts
** in the note where it is more than the row's estimate (1.8 MB each of a
** picture scene's 50 splines, their pair grids, rasters and 25 domains,
** where 970 bytes a segment counted 0.24). */
static void replicas_measured(lw_anneal *a, double before)
{
  const double after = heap_bytes();
  if (a->n_rep < 2 || before < 0.0 || after < before) return;
  const double each = 1.3 * (after - before) / (a->n_rep - 1);
  if (!(each > a->mem.replica)) return;
  a->mem.replica = each;
  memory_note(a);
}

/* A start whose replicas here would not fit the memory this process may use
** is refused before its placement, naming the key that sets its size. */
static lw_status fits_memory(lw_anneal *a, lw_error *err)
{
  const lw_system_type *t = a->sys_type;
  const char *key = NULL;
  a->mem.peak = a->mem.replica = 0.0;
  a->mem.what[0] = '\0';
  const double one = t->start_bytes ? t->start_bytes(a->setup, &a->params, a->mem.what, sizeof a->mem.what, &key,
                                                     &a->mem.peak, &a->mem.replica) : 0.0;
  int here = 0;
  for (int r = 0; r < a->n_rep; r++) here += rung_here(a, r);
  a->mem.here = here;
  a->mem.limit = lw_memory_limit(&a->mem.by);
  const double limit = a->mem.limit, bytes = one * here;
  char reps[48] = "";
  if (here > 1) snprintf(reps, sizeof reps, " in %d replicas", here);
  if (!(bytes > limit)) memory_note(a);
  if (!(bytes > limit) || !key) return LW_OK;
  lw_error_set(err, LW_EINPUT, "%s take at least %.3g GB%s, more than the %.3g GB of %s: expected a smaller %s",
               a->mem.what, bytes / 1e9, reps, limit / 1e9, a->mem.by, key);
  const char *dot = strchr(key, '.');
  char section[32];
  snprintf(section, sizeof section, "%.*s", dot ? (int)(dot - key) : 0, key);
  return lw_params_blame(&a->params, section, dot ? dot + 1 : key, err);
}

/* The system's row and its set-up of the scene; a quench needs a row with
** a gradient. */
static lw_status setup_system(lw_anneal *a, lw_error *err)
{
  if (!(a->sys_type = lw_system_of(&a->params, err))) return err->code;
  if (a->sys_type->quench_converges && a->sys_type->quench_converges(&a->params) &&
      !lw_params_line(&a->params, "anneal", "quench_stall"))
    a->params.quench_stall = 0.0;
  if (a->params.quench != LW_QUENCH_NONE && !a->sys_type->gradient) {
    char where[LW_PATH_MAX + 32];
    lw_params_origin(&a->params, lw_params_find("anneal", "quench"), where, sizeof where);
    return lw_error_set(err, LW_EINPUT, "%s: key 'anneal.quench': the %s system has no gradient to quench with; "
                        "expected none", where, a->sys_type->name);
  }
  const char *missing = a->params.samples_every && !a->sys_type->write_sample ? "samples_every"
                        : a->params.observables && !a->sys_type->observe       ? "observables"
                                                                                : NULL;
  if (missing) {
    char where[LW_PATH_MAX + 32];
    lw_params_origin(&a->params, lw_params_find("output", missing), where, sizeof where);
    return lw_error_set(err, LW_EINPUT, "%s: key 'output.%s': the %s system has no %s; expected 0", where, missing,
                        a->sys_type->name, *missing == 's' ? "samples" : "observables");
  }
  a->setup = a->sys_type->setup_new(&a->params, err);
  return a->setup ? fits_memory(a, err) : err->code;
}

/* A scene that asks for a quench must have a gradient of every term it
** names (a term without one refuses with LW_EINPUT, gradient.h): one
** evaluation on the start state finds out now rather than after the run.
** Only when the quench is asked for, so a plain run allocates nothing. */
static lw_status check_quench(const lw_anneal *a, lw_error *err)
{
  if (a->params.quench == LW_QUENCH_NONE) return LW_OK;
  const lw_system_type *t = a->sys_type;
  size_t n = t->n_coords(a->sys->state);
  double *g = malloc((n ? n : 1) * sizeof *g);
  if (!g) return lw_error_set(err, LW_ENOMEM, "out of memory for the gradient of %zu coordinates", n);
  lw_error e2 = {0};
  double e = t->gradient(a->sys->state, g, &e2);
  free(g);
  if (!isnan(e)) return LW_OK;
  if (e2.code != LW_EINPUT) return lw_error_set(err, e2.code ? e2.code : LW_ENOMEM, "%s", e2.msg);
  char where[LW_PATH_MAX + 32];
  lw_params_origin(&a->params, lw_params_find("anneal", "quench"), where, sizeof where);
  return lw_error_set(err, LW_EINPUT, "%s: key 'anneal.quench': this scene has no gradient to quench with (%s); "
                      "expected none", where, e2.msg);
}

/* The generator seed of the run's stream k (docs/NUMERICS.md, "Random
** numbers"). */
static unsigned long stream_seed(const lw_anneal *a, unsigned long k)
{
  return lw_stream_seed(a->seed, k, a->params.seed_version);
}

/* Chain of rung k: rung 0 draws from stream 1 (as a run without tempering
** does), the master exchange stream is 2, rung k >= 1 is stream 2 + k. */
static unsigned long rung_stream(const lw_anneal *a, int k)
{
  return stream_seed(a, k == 0 ? 1 : 2 + (unsigned long)k);
}

/* Every move weight of the system 0: refused naming its move keys, the one
** the user set to 0 blamed (the chain's own check named no file or key). */
static lw_status no_move(const lw_anneal *a, lw_error *err)
{
  const lw_params *p = &a->params;
  const lw_system_type *t = a->sys_type;
  const lw_param_def *blame = NULL;
  char names[256] = "";
  size_t m = 0;
  for (int k = 0; k < t->n_moves; k++) {
    const lw_param_def *d = lw_params_find("moves", t->move_names[k]);
    if (!d) continue;
    if (m < sizeof names) m += (size_t)snprintf(names + m, sizeof names - m, "%smoves.%s", m ? ", " : "", d->key);
    if (!blame || (lw_params_given(p, d) && !lw_params_given(p, blame))) blame = d;
  }
  lw_error_set(err, LW_EINPUT, "every move weight is 0 (%s): expected at least one above 0", names);
  return blame ? lw_params_blame(p, "moves", blame->key, err) : err->code;
}

/* Systems for the n_rep states[] (ownership passes, also on failure),
** chains for the rungs, the exchange machinery on the base ladder. */
static lw_status build(lw_anneal *a, void **states, const double *ladder, lw_error *err)
{
  const lw_params *p = &a->params;
  const lw_system_type *t = a->sys_type;
  int n = a->n_rep;
  a->systems = calloc((size_t)n, sizeof *a->systems);
  a->chains = calloc((size_t)n, sizeof *a->chains);
  if (!a->systems || !a->chains) {
    for (int r = 0; r < n; r++) t->state_free(states[r]);
    return lw_error_set(err, LW_ENOMEM, "out of memory for %d replicas", n);
  }
  lw_status s = LW_OK;
  for (int r = 0; r < n; r++) {
    if (!s) {
      a->systems[r] = lw_system_wrap(t, states[r], err);
      if (!a->systems[r]) s = err->code;
    } else {
      t->state_free(states[r]);
    }
  }
  if (s) return s;
  double weight[LW_MOVES_MAX], step[LW_MOVES_MAX], target[LW_MOVES_MAX], sum = 0.0;
  t->moves(p, weight, step, target);
  for (int k = 0; k < t->n_moves; k++) sum += weight[k];
  if (!(sum > 0.0)) return no_move(a, err);
  for (int k = 0; k < n; k++) {
    a->chains[k] = lw_chain_new(a->systems[k], weight, step, target, rung_stream(a, k), err);
    if (!a->chains[k]) return err->code;
    a->chains[k]->delayed = p->delayed_acceptance; /* before the domains copy the chain */
    lw_chain_set_rule(a->chains[k], lw_driver_find(p->driver)->accept);
    if (!lw_driver_is_motion(p) && lw_domains_attach(a->chains[k], p, n, err)) return err->code;
  }
  a->chain = a->chains[0];
  a->sys = a->systems[0];
  if (n > 1) {
    a->pt = lw_tempering_new(n, ladder, stream_seed(a, 2), err);
    if (!a->pt) return err->code;
  }
  if (lw_driver_is_motion(p) && !(a->dyn = lw_dynamics_new(t, a->sys->state, p, err))) return err->code;
  return LW_OK;
}

/* Rung temperatures from the schedule's: the ladder keeps its ratios and
** follows the schedule (a constant schedule samples at the ladder itself). */
static void set_temperatures(lw_anneal *a)
{
  if (!a->pt) {
    a->chain->temperature = a->t_sched;
    return;
  }
  double f = a->t_sched / a->params.t_start;
  for (int k = 0; k < a->n_rep; k++) a->chains[k]->temperature = a->pt->ladder[k] * f;
}

/* The end of trace.csv's header and of a row: the observables of the
** coldest rung's state where the scene asks for them (output.observables),
** and the newline.  An undefined one (NaN) is an empty field. */
static void trace_header_end(lw_anneal *a)
{
  const lw_system_type *t = a->sys_type;
  for (int k = 0; a->params.observables && k < t->n_observables; k++)
    fprintf(a->trace, ",obs_%s", t->observable_names[k]);
  fprintf(a->trace, "\n");
}

/* A trace's number, after its comma: every digit that reads back (trace
** rows are few, the %.17g at most twice a number), or as a run from before
** output.trace_exact wrote it; the dynamics' energies were %.17g there. */
static void trace_number(lw_anneal *a, double v, int energy)
{
  fputc(',', a->trace);
  if (a->params.trace_exact) lw_number_print_exact(a->trace, v);
  else fprintf(a->trace, a->dyn && energy ? "%.17g" : "%.10g", v);
}

static void trace_row_end(lw_anneal *a, const double *v)
{
  const lw_system_type *t = a->sys_type;
  if (a->params.observables) {
    for (int k = 0; k < t->n_observables; k++)
      if (isnan(v[k])) fprintf(a->trace, ",");
      else trace_number(a, v[k], 0);
  }
  fprintf(a->trace, "\n");
}

static lw_status open_trace(lw_anneal *a, int fresh, lw_error *err)
{
  char path[LW_PATH_MAX + 32];
  dir_file(path, sizeof path, a, "trace.csv");
  /* written in place (a resume appends), so never through a link */
  int fd = open(path, O_WRONLY | O_CREAT | O_NOFOLLOW | O_CLOEXEC | (fresh ? O_TRUNC : O_APPEND), 0666);
  /* (at the end, so that ftell counts the bytes before it, as fopen's "a" does) */
  if (fd < 0 || lseek(fd, 0, SEEK_END) < 0 || !(a->trace = fdopen(fd, fresh ? "w" : "a"))) {
    const int e = errno;
    if (fd >= 0) close(fd);
    return lw_error_set(err, LW_EIO, "%s: cannot write: %s%s", path, strerror(e),
                        e == ELOOP ? " (a symbolic link: a run writes into its own directory only)" : "");
  }
  if (fresh && a->dyn) {
    const lw_system_type *t = a->sys_type;
    fprintf(a->trace, "sweep,time");
    for (int k = 0; k < t->n_terms; k++)
      if (t->term_on(a->setup, k)) fprintf(a->trace, ",%s", t->term_names[k]);
    /* U as potential_energy: "potential" is a term of the splines' */
    fprintf(a->trace, ",potential_energy,kinetic,total");
    trace_header_end(a);
  } else if (fresh) {
    const lw_system_type *t = a->sys_type;
    fprintf(a->trace, "sweep,temperature");
    for (int k = 0; k < t->n_terms; k++)
      if (t->term_on(a->setup, k)) fprintf(a->trace, ",%s", t->term_names[k]);
    fprintf(a->trace, ",total");
    for (int k = 0; k < t->n_moves; k++) fprintf(a->trace, ",acc_%s", t->move_names[k]);
    for (int k = 0; a->pt && k < a->n_rep; k++) fprintf(a->trace, ",replica%d_temperature,replica%d_energy", k, k);
    for (int k = 0; a->pt && k + 1 < a->n_rep; k++) fprintf(a->trace, ",swap%d", k);
    trace_header_end(a);
  }
  return LW_OK;
}

lw_status lw_anneal_start(lw_anneal *a, const lw_params *p, const char *dir, lw_error *err)
{
  return lw_anneal_start_net(a, p, dir, NULL, err);
}

static lw_status write_start(lw_anneal *a, lw_anneal_net *net, lw_error *err);

/* a->dir cut short would name another directory than dir: the stash checked
** in one and the files removed in the other.  The limit is the command
** line's (main.c's RUN_DIR_MAX), with 64 bytes left for the names inside. */
static lw_status dir_fits(const lw_anneal *a, const char *dir, lw_error *err)
{
  if (strlen(dir) <= sizeof a->dir - 64) return LW_OK;
  return lw_error_set(err, LW_EUSAGE, "%.80s...: a run directory's path of %zu bytes, expected at most %zu", dir,
                      strlen(dir), sizeof a->dir - 64);
}

lw_status lw_anneal_start_net(lw_anneal *a, const lw_params *p, const char *dir, lw_anneal_net *net, lw_error *err)
{
  memset(a, 0, sizeof *a);
  a->net = net;
  a->pause_at = -1;
  a->wall_start = lw_phase_clock();
  a->params = *p;
  lw_status s;
  /* every file is written with '.': a program that set a decimal-comma
  ** locale after reading the scene wrote 'pair = 0,02' and JSON that is not */
  if ((s = lw_number_locale_ok(err))) return s;
  if ((s = dir_fits(a, dir, err))) return s;
  if ((s = absolute_paths(a, err)) || (s = from_elsewhere(a, dir, err)) || (s = inputs_elsewhere(a, dir, err)) ||
      (s = read_ladder_file(a, err)))
    return s;
  snprintf(a->dir, sizeof a->dir, "%s", dir);
  a->seed = (unsigned long)a->params.seed;
  a->block = -1;
  double ladder[LW_TEMPERING_MAX];
  lw_phase_set("setting up the scene");
  if ((s = lw_params_resolve(&a->params, err)) || (s = setup_ladder(a, ladder, err)) ||
      (s = lw_anneal_check_keys(&a->params, a->unread, sizeof a->unread, err)) || (s = setup_schedule(a, err)) ||
      (s = setup_system(a, err)))
    return s;
  idle_keys(a, a->idle, sizeof a->idle);
  schedule_note(a, a->schedule_note, sizeof a->schedule_note);
  const lw_params *rp = &a->params;
  /* (a redraw, no sweeps, tunes nothing: FORMATS' recipe was refused) */
  if (a->n_rep > 1 && rp->tune_ladder == LW_LADDER_EQUAL && rp->sweeps > 0 && rp->ladder_sweeps >= rp->sweeps) {
    /* (a run of an older release that did so still resumes) */
    char where[LW_PATH_MAX + 32];
    lw_params_origin(rp, lw_params_find("tempering", "ladder_sweeps"), where, sizeof where);
    return lw_error_set(err, LW_EINPUT, "%s: key 'tempering.ladder_sweeps': the ladder is tuned for the first "
                        "ladder_sweeps sweeps, then frozen, and the swap statistics and ladder.ini come after: "
                        "expected fewer than anneal.sweeps (%d), got %d", where, rp->sweeps, rp->ladder_sweeps);
  }
  const lw_system_type *t = a->sys_type;
  lw_phase_set("placing the initial state and building its energy");
  void *all[LW_TEMPERING_MAX] = {t->state_new(a->setup, &a->params, stream_seed(a, 0), err)};
  if (!all[0]) return err->code;
  /* every replica starts from the same state; their streams part them */
  const double heap = heap_bytes();
  for (int r = 1; r < a->n_rep; r++) {
    if (!(all[r] = t->state_copy(all[0], err))) {
      for (int q = 0; q < r; q++) t->state_free(all[q]);
      /* the replicas are what is too many, more than the scene */
      if (err->code == LW_ENOMEM) {
        char msg[LW_ERROR_MSG];
        snprintf(msg, sizeof msg, "%s", err->msg);
        /* (under ulimit -v the threads' malloc arenas, 64 MiB of address
        ** space each, ran out with 8 threads where 4 fitted: the replicas were
        ** blamed alone; not where MALLOC_ARENA_MAX=1 already keeps one) */
        const char *by, *arena_max = getenv("MALLOC_ARENA_MAX");
        const int arenas = threads_most() > 1 && lw_memory_limit(&by) < INFINITY && strstr(by, "ulimit") &&
                           !(arena_max && !strcmp(arena_max, "1"));
        lw_error_set(err, LW_ENOMEM, "%s, at replica %d of %d (tempering.replicas: each holds the whole scene%s)",
                     msg, r + 1, a->n_rep, arenas ? "; under ulimit -v each thread's malloc arena counts too: fewer "
                     "--threads or MALLOC_ARENA_MAX=1 (docs/PERFORMANCE.md, \"Memory limits\")" : "");
      }
      return err->code;
    }
  }
  if ((s = build(a, all, ladder, err)) || (s = check_quench(a, err))) return s;
  replicas_measured(a, heap);
  a->totals_fresh = 1;
  /* where the photo preset's count of domains gave way to a move's reach (a
  ** picture of a few pixels: domains.c), scene.ini, which a resume reads as
  ** given, holds the count the run took (it held the page's, refused there) */
  if (strcmp(a->params.domains, "auto") && strcmp(a->params.domains, "off")) {
    if (a->chain->domains) snprintf(a->params.domains, sizeof a->params.domains, "%d", a->chain->domains->nx);
    else snprintf(a->params.domains, sizeof a->params.domains, "off");
  }
  a->energy_initial = lw_system_total(a->sys);
  /* the systems refuse the states they know to be bad; an energy that is
  ** still not finite (a knot span of 1e-300, a blur of 1e-200 mm) would have
  ** the chain reject every proposal as NaN and the run end "done" */
  if (!isfinite(a->energy_initial)) {
    double v[LW_SYSTEM_TERMS_MAX];
    t->terms(a->sys->state, v);
    int q = 0;
    while (q < t->n_terms - 1 && isfinite(v[q])) q++;
    return lw_error_set(err, LW_EINPUT, "the %s energy of the initial state is %g: expected a finite energy (a "
                        "length, weight or width of the scene at the edge of what a double holds?)",
                        t->term_names[q], v[q]);
  }
  a->end_sweep = a->params.sweeps; /* resolved: the caller's p may not be (a preset's sweeps) */
  a->scene_hash = lw_params_run_hash(&a->params, &a->scene_keys);
  /* a file the run read but could not fingerprint (out of file handles, a
  ** read error) would be hashed as unread, and every resume refuse the run
  ** as edited */
  for (size_t k = 0; k < a->scene_keys.n; k++)
    if (a->scene_keys.unread[k]) {
      const lw_param_def *d = &lw_param_table[a->scene_keys.index[k]];
      return lw_error_set(err, LW_EIO, "%s.%s: cannot read the file it names again to fingerprint it: %s",
                          d->section, d->key, strerror(a->scene_keys.unread[k]));
    }
  /* Everything above only read input: the directory appears once the run
  ** is known to be valid. */
  lw_phase_writing();
  if ((s = lw_rundir_make(dir, err)) || (writes_files(a) && (s = lw_rundir_lock(dir, &a->dir_hold, err))))
    return s;
  dir_identity(a);
  if (!writes_files(a)) {
    lw_phase_set(NULL);
    return LW_OK;
  }
  /* the run before (a final.gcode, a replica state or a film of it beside
  ** the new drawing would be taken for the new run's) waits until the new
  ** run's first sweep (drop_stash), or comes back if the set-up or that
  ** sweep fails (runfiles.h) */
  int back;
  if ((s = lw_runfiles_recover(dir, &back, err)) || (s = lw_runfiles_check_free(dir, err))) return s;
  if (lw_rundir_holds_run(dir)) {
    /* said before the first file moves: a second signal while they do
    ** leaves the run half in .replaced, which the next run or resume puts
    ** back (it said "nothing to resume: run it again") */
    lw_phase_stash(1);
    if ((s = lw_runfiles_stash(dir, err))) {
      lw_phase_stash(0); /* (all of it put back) */
      return s;
    }
    a->stashed = 1;
  }
  a->fresh = 1;
  if ((s = write_start(a, net, err))) lw_anneal_undo_start(a);
  return s;
}

int lw_anneal_undo_start(lw_anneal *a)
{
  lw_error e0;
  /* (by path: a directory moved aside meanwhile keeps what is there, and
  ** one made in its place is another's) */
  if ((!a->fresh && !a->stashed) || dir_still_ours(a, &e0)) return a->put_back;
  const int fresh = a->fresh;
  a->fresh = 0;
  if (a->stashed) {
    lw_error e;
    a->put_back = !lw_runfiles_unstash(a->dir, &e);
    a->stashed = 0;
    if (fresh) lw_phase_stash(a->put_back ? 0 : 1);
  } else {
    lw_runfiles_remove(a->dir); /* no run was there: every run file is the set-up's */
    a->undone = 1;
  }
  return a->put_back;
}

/* The run set aside goes once this one has done a sweep or ended: a run
** that failed before (a dynamics whose first step cannot converge, at
** sweep 0 after its first checkpoint) took the finished drawing with it and
** left a state that fails again on resume.  A kill in between leaves the
** new run's checkpoint, which the next run or resume there keeps
** (lw_runfiles_recover), as a stop does here. */
static void drop_stash(lw_anneal *a)
{
  lw_error e;
  if (!a->stashed || a->fresh) return;
  lw_phase_stash(0); /* (first: a signal while it goes said it would come back) */
  if (lw_runfiles_drop(a->dir, &e)) snprintf(a->stash_left, sizeof a->stash_left, "%s", e.msg);
  a->stashed = 0;
}

/* The new run's first files, up to its first checkpoint (net: the first is
** the network's, after this). */
static lw_status write_start(lw_anneal *a, lw_anneal_net *net, lw_error *err)
{
  lw_status s;
  char path[LW_PATH_MAX + 32], tmp[LW_PATH_MAX + 64];
  dir_file(path, sizeof path, a, "scene.ini");
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) return err->code;
  fprintf(f, "%s\n", LW_RUN_SCENE_HEADER);
  lw_params_write_files(&a->params, f);
  lw_params_write(&a->params, f);
  if ((s = lw_output_commit(f, tmp, path, err))) return s;
  if ((s = open_trace(a, 1, err))) return s;
  lw_phase_set("drawing the start files");
  if ((s = a->sys_type->draw(a->sys->state, &a->params, a->dir, LW_DRAW_START, err))) return s;
  /* the film's first frame is the start (whip's began at sweep 5, already
  ** swinging) */
  if (a->params.frames_every && rung_here(a, 0) && (s = a->sys_type->draw(a->sys->state, &a->params, a->dir, 0, err)))
    return s;
  s = net ? LW_OK : lw_anneal_checkpoint(a, err);
  lw_phase_set(NULL);
  return s;
}

/* ---- checkpoints (checkpoint.c) ------------------------------------- */

/* A new end goes into state.lw before the first sweep, or a kill before the
** first checkpoint would leave the old one (this process holds every replica
** as read, so it writes them alone); a finished run extended by --sweeps is
** no longer finished, and its summary would describe a state that is gone
** (studies take a summary.json as the sign of a finished run). */
lw_status lw_anneal_settle(lw_anneal *a, lw_error *err)
{
  if (!a->extending) return LW_OK;
  a->extending = 0;
  /* a killed run's frames and samples past the checkpoint are written again,
  ** unless scene.ini's interval was edited: those off the new grid stayed,
  ** a film of steps 5 then 20 with 105, 110 and 115 among the 20s */
  lw_runfiles_drop_off_grid(a->dir, a->sweep, a->end_sweep, a->params.frames_every, a->params.samples_every);
  if (a->new_end) {
    lw_status s = lw_checkpoint_write(a, err);
    if (s) return s;
  }
  char path[LW_PATH_MAX + 32];
  dir_file(path, sizeof path, a, "summary.json");
  if (unlink(path) && errno != ENOENT) return lw_error_set(err, LW_EIO, "%s: cannot remove: %s", path, strerror(errno));
  return LW_OK;
}

lw_status lw_anneal_checkpoint(lw_anneal *a, lw_error *err)
{
  lw_status se = refuse_finished(a, "lw_anneal_checkpoint", err);
  /* (the locale changed since the start) */
  if (se || (se = lw_number_locale_ok(err)) || (se = lw_anneal_settle(a, err))) return se;
  if (writes_files(a) && (se = dir_still_ours(a, err))) return se;
  const char *was = lw_phase_get(NULL);
  lw_phase_set("writing state.lw");
  const double t0 = lw_phase_clock();
  lw_status s = a->net ? a->net->checkpoint(a->net, a, err) : lw_checkpoint_write(a, err);
  const double took = lw_phase_clock() - t0;
  a->ckpt_seconds += took;
  if (!a->ckpt_count++ || took > a->ckpt_longest) a->ckpt_longest = took;
  lw_phase_set(was);
  if (!s) a->saved = a->sweep + 1;
  if (s) return s;
  const int first = a->fresh;
  a->fresh = 0;
  /* (a stop still makes the new run give way, until its first sweep) */
  if (first) lw_phase_stash(a->stashed && !a->net ? 3 : 0);
  /* the run set aside goes with the first sweep (drop_stash), a stop asked
  ** in it aside (its checkpoint, checkpoint_every = 1, dropped the run a stop
  ** was to put back); a spread run's with the first checkpoint, its
  ** processes failing together only at a sweep */
  if (a->net || (!first && !lw_phase_stopping())) drop_stash(a);
  return LW_OK;
}

/* The sweep of the last row within the first `bytes` bytes of the trace
** (a run writes one every trace_every sweeps, and one where it ends), or
** -1 if there is only the header; -2 if those bytes do not end a line; -3
** (errno set) if they cannot be read (out of memory or file handles: not
** the files' fault, which the message for -2 blames). */
static long last_row_sweep(const char *path, long bytes)
{
  enum { TAIL = 1 << 16 };
  FILE *f = fopen(path, "rb");
  if (!f) return -3;
  long from = bytes > TAIL ? bytes - TAIL : 0, n = bytes - from, sweep = -2;
  char *buf = malloc((size_t)n + 1);
  int whole = buf && n > 0 && !fseek(f, from, SEEK_SET) && fread(buf, 1, (size_t)n, f) == (size_t)n;
  if (n > 0 && !whole) {
    const int e = buf ? (errno ? errno : EIO) : ENOMEM;
    free(buf);
    fclose(f);
    errno = e;
    return -3;
  }
  if (whole && buf[n - 1] == '\n') {
    buf[--n] = '\0';
    char *line = strrchr(buf, '\n');
    if (!line && from == 0) {
      sweep = -1; /* the header alone */
    } else if (line) {
      long long v;
      line++;
      line[strcspn(line, ",")] = '\0';
      if (lw_number_parse_whole(line, 0, LW_STATE_SWEEP_MAX, &v)) sweep = (long)v;
    }
  }
  free(buf);
  fclose(f);
  return sweep;
}

/* The first `bytes` bytes of the trace at path, as a file of its own there. */
static lw_status copy_trace(const char *path, long bytes, lw_error *err)
{
  char tmp[LW_PATH_MAX + 64], buf[65536];
  FILE *in = fopen(path, "rb");
  if (!in) return lw_error_set(err, LW_EIO, "%s: cannot read: %s", path, strerror(errno));
  FILE *out = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!out) {
    fclose(in);
    return err->code;
  }
  long done = 0;
  errno = 0;
  for (size_t got = 1; done < bytes && got;) {
    got = fread(buf, 1, bytes - done < (long)sizeof buf ? (size_t)(bytes - done) : sizeof buf, in);
    if (got && fwrite(buf, 1, got, out) != got) break;
    done += (long)got;
  }
  fclose(in);
  if (done != bytes) {
    const int e = errno;
    lw_output_abort(out, tmp);
    return lw_error_set(err, LW_EIO, "%s: cannot copy it to a file of this run's own: %s", path,
                        e ? strerror(e) : "it was cut meanwhile");
  }
  return lw_output_commit(out, tmp, path, err);
}

/* trace.csv back to the checkpoint: rows written after it belong to sweeps
** that will run again.  A format-2 checkpoint knows the length it synced;
** a format-1 one only its sweep, so complete rows up to it are kept. */
static lw_status truncate_trace(lw_anneal *a, long bytes, lw_error *err)
{
  char path[LW_PATH_MAX + 32], tmp[LW_PATH_MAX + 64];
  dir_file(path, sizeof path, a, "trace.csv");
  struct stat sb;
  /* a link is refused before the trace is cut (truncate cut the file it
  ** named) or read, in either format (a format-1 state's resume wrote
  ** through it, exit 1 where this says 2); and so is what is not a file (a
  ** FIFO there held a format-1 resume in fopen for ever, deaf to SIGTERM) */
  if (!lstat(path, &sb) && S_ISLNK(sb.st_mode))
    return lw_error_set(err, LW_EINPUT, "%s: a symbolic link: a run writes into its own directory only (put the "
                        "trace itself there)", path);
  if (!lstat(path, &sb) && !S_ISREG(sb.st_mode))
    return lw_error_set(err, LW_EINPUT, "%s: not a regular file (a FIFO, a device or a folder): the run's trace is "
                        "a file of its own", path);
  if (bytes >= 0) {
    if (stat(path, &sb))
      return lw_error_set(err, LW_EINPUT, "%s: %s, but state.lw counts %ld bytes of it", path, strerror(errno), bytes);
    if (!S_ISREG(sb.st_mode) || sb.st_size < bytes)
      return lw_error_set(err, LW_EINPUT, "%s: %lld bytes, but state.lw counts %ld (the trace was cut or replaced)",
                          path, (long long)sb.st_size, bytes);
    /* the rows the state counts end at its sweep: a state whose sweep was
    ** edited would run sweeps again and write their rows twice */
    long last = last_row_sweep(path, bytes), every = a->params.trace_every;
    char state[LW_PATH_MAX + 32];
    dir_file(state, sizeof state, a, "state.lw");
    if (last == -3)
      return lw_error_set(err, LW_EIO, "%s: cannot read it to check the rows %s counts: %s", path, state,
                          strerror(errno));
    if (last == -2)
      return lw_error_set(err, LW_EINPUT, "%s: %s counts %ld bytes of it, which do not end a row with its sweep (the "
                          "state or the trace was edited)", path, state, bytes);
    if (last >= 0 && (last > a->sweep || a->sweep - last >= every))
      return lw_error_set(err, LW_EINPUT, "%s: the rows %s counts end at sweep %ld, but it is at sweep %ld (a row "
                          "every %ld sweeps): the state or the trace was edited, or is of another run",
                          path, state, last, a->sweep, every);
    /* a trace with other names (a copy of the run made by cp -al or rsync
    ** --link-dest) is cut and appended to in both: the copy's resume took
    ** 80 rows off the finished original; so it gets a file of its own */
    lw_status s = sb.st_nlink > 1 ? copy_trace(path, bytes, err) : LW_OK;
    if (s) return s;
    /* (a FUSE FAT refuses a truncate to the size a file has: every clean
    ** stop's resume failed there) */
    if (sb.st_nlink < 2 && sb.st_size != bytes && truncate(path, bytes))
      return lw_error_set(err, LW_EIO, "%s: cannot truncate: %s", path, strerror(errno));
    return open_trace(a, 0, err);
  }
  FILE *in = fopen(path, "r");
  if (!in) return open_trace(a, 1, err);
  FILE *out = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!out) {
    fclose(in);
    return err->code;
  }
  char *line = NULL;
  size_t cap = 0;
  ssize_t len;
  for (int first = 1; (len = lw_text_getline(&line, &cap, in)) > 0; first = 0) {
    /* a torn last row has no newline; its sweep may read as a smaller one */
    long long sweep;
    size_t nf = strcspn(line, ",");
    if (line[len - 1] != '\n') break;
    if (!first) {
      line[nf] = '\0';
      int ok = lw_number_parse_whole(line, 0, LW_STATE_SWEEP_MAX, &sweep) && sweep <= a->sweep;
      line[nf] = ',';
      if (!ok) break;
    }
    fputs(line, out);
  }
  free(line);
  fclose(in);
  if (len == -2) { /* (not the end of the trace, which the rows after would lose) */
    lw_output_abort(out, tmp);
    return lw_error_set(err, LW_ENOMEM, "%s: out of memory reading it", path);
  }
  lw_status s = lw_output_commit(out, tmp, path, err);
  return s ? s : open_trace(a, 0, err);
}

/* The state of rung k, loaded by the row from its section of state.lw
** ([system <name>] or [system <name> K]), or (format 1, rungs K >= 1) from
** replica-K.lw, whose document *rep keeps the replica's run data for the
** upgrade. */
static lw_status rung_state(lw_anneal *a, lw_state *st, int k, void **state, lw_ckpt **rep, lw_error *err)
{
  const lw_system_type *t = a->sys_type;
  char sec[64], path[LW_PATH_MAX + 64];
  lw_status s = LW_OK;
  *state = NULL;
  if (st->version != 1 || k == 0) {
    lw_checkpoint_system_section(sec, sizeof sec, t, k);
    dir_file(path, sizeof path, a, "state.lw");
    *state = t->load(a->setup, st, sec, path, err);
  } else {
    lw_state r;
    snprintf(sec, sizeof sec, "replica-%d.lw", k);
    dir_file(path, sizeof path, a, sec);
    if ((s = lw_state_read(&r, path, err))) return s;
    if (r.sweep != st->sweep || r.version != 1)
      s = lw_error_set(err, LW_EINPUT, "%s: sweep %ld of format %d, but state.lw is at sweep %ld of format 1 (an "
                       "interrupted checkpoint of an older release?)", path, r.sweep, r.version, st->sweep);
    lw_checkpoint_system_section(sec, sizeof sec, t, 0);
    if (!s) *state = t->load(a->setup, &r, sec, path, err);
    *rep = r.doc;
    r.doc = NULL;
    lw_state_clear(&r);
  }
  if (!s && !*state) s = err->code;
  return s;
}

lw_status lw_anneal_resume(lw_anneal *a, const char *dir, long more, lw_error *err)
{
  return lw_anneal_resume_net(a, dir, more, NULL, err);
}

lw_status lw_anneal_resume_net(lw_anneal *a, const char *dir, long more, lw_anneal_net *net, lw_error *err)
{
  memset(a, 0, sizeof *a);
  a->net = net;
  a->wall_start = lw_phase_clock();
  lw_status sd = dir_fits(a, dir, err);
  if (sd) return sd;
  snprintf(a->dir, sizeof a->dir, "%s", dir);
  char path[LW_PATH_MAX + 32], scene_path[2 * LW_PATH_MAX + 2];
  dir_file(path, sizeof path, a, "state.lw");
  lw_state st;
  void *all[LW_TEMPERING_MAX] = {NULL};
  lw_ckpt *rep[LW_TEMPERING_MAX] = {NULL};
  lw_phase_set("reading state.lw and rebuilding the energy");
  /* (a directory that holds no run has no state.lw to read, which says so,
  ** and gets no lock file; but one with a lock file is locked first: a run
  ** setting up there holds it, and its files, come meanwhile, were resumed
  ** beside it, or it was said to hold no run) */
  char lock_path[LW_PATH_MAX + 16];
  snprintf(lock_path, sizeof lock_path, "%s/.lock", dir);
  lw_status sl = LW_OK;
  if (writes_files(a) && (lw_rundir_holds_run(dir) || lw_runfiles_stashed(dir) || !access(lock_path, F_OK))) {
    int back;
    sl = lw_rundir_lock(dir, &a->dir_hold, err);
    /* a run made again there was stopped in its set-up: the run before
    ** comes back, to be resumed (or its new run's first checkpoint stands) */
    if (!sl) sl = lw_runfiles_recover(dir, &back, err);
  }
  if (net) { /* the other processes read the directory once process 0 has settled it */
    double failed = sl != LW_OK;
    net->broadcast(net, 0, &failed, 1);
    if (failed && !sl)
      sl = lw_error_set(err, LW_EIO, "%s: process 0 could not take the run directory (it says why)", dir);
  }
  if (sl) return sl;
  dir_identity(a);
  /* a run stopped before its first checkpoint left its scene.ini alone */
  if (lw_rundir_unstarted(dir))
    return lw_error_set(err, LW_EINPUT, "%s: no state.lw: the run there stopped before its first checkpoint, so "
                        "there is nothing to resume; run it again (linewise run SCENE --out %s)", dir, dir);
  /* (a run that failed before writing anything, on a full disk, left only
  ** its lock: "cannot open state file" named no way on) */
  struct stat sb;
  if (!lw_rundir_holds_run(dir) && stat(path, &sb) && errno == ENOENT && !stat(dir, &sb) && S_ISDIR(sb.st_mode))
    return lw_error_set(err, LW_EINPUT, "%s: holds no run (no state.lw, no scene.ini of a run): resume takes a "
                        "directory that 'linewise run --out' wrote; a run that failed before writing them has "
                        "nothing to resume: run it again", dir);
  lw_status s = lw_state_read(&st, path, err);
  if (s) return s;
  /* the run goes on writing scene = scene.ini: another name left it naming
  ** a file it never had */
  if (strcmp(st.scene, "scene.ini")) {
    s = lw_error_set(err, LW_EINPUT, "%s: [run] scene: expected scene.ini, the scene of the run directory, got '%s' "
                     "(a state not of a run: 'linewise run SCENE --set init.from=%s' starts a run from it)", path,
                     st.scene, path);
    goto out;
  }
  lw_path_join(scene_path, sizeof scene_path, dir, st.scene);
  double ladder[LW_TEMPERING_MAX];
  long trace_bytes = -1;
  /* a path edited into scene.ini is relative to it, as in any scene file:
  ** made absolute before the files' bytes are checked and read */
  if ((s = lw_params_read_run(&a->params, scene_path, 0, err)) || (s = absolute_paths(a, err)) ||
      (s = lw_checkpoint_scene_hash(st.doc, &a->params, &a->scene_keys, &a->scene_hash, err)) ||
      (s = lw_params_resolve(&a->params, err)) || (s = setup_ladder(a, ladder, err)) ||
      (s = setup_schedule(a, err)) || (s = setup_system(a, err)))
    goto out;
  a->seed = st.seed;
  a->sweep = st.sweep;
  double heap = -1.0;
  for (int k = 0; k < a->n_rep && !s; k++) {
    s = rung_state(a, &st, k, &all[k], &rep[k], err);
    if (k == 0) heap = heap_bytes();
  }
  if (s) {
    for (int k = 0; k < a->n_rep; k++)
      if (all[k]) a->sys_type->state_free(all[k]);
    goto out;
  }
  if ((s = build(a, all, ladder, err)) || (s = check_quench(a, err))) goto out;
  replicas_measured(a, heap);
  if (st.version == 1 && (s = lw_checkpoint_upgrade_v1(st.doc, rep, a->n_rep, err))) goto out;
  if ((s = lw_checkpoint_restore(a, st.doc, &trace_bytes, err))) goto out;
  if (!a->dyn && a->block != (a->sweep ? block_of(a, a->sweep - 1) : -1)) {
    s = lw_error_set(err, LW_EINPUT, "%s: [run] sweep: %ld is in the schedule's temperature step %ld, but the "
                     "file's block is %ld: the state was edited", path, a->sweep,
                     a->sweep ? block_of(a, a->sweep - 1) : -1, a->block);
    goto out;
  }
  if (!a->dyn && (s = check_block_energy(a, path, err))) goto out;
  /* the schedule's temperature follows from the step and the parameters,
  ** the adaptive one's from the measurements the file holds as well (but its
  ** rule under tempering changed on 2026-12-04: there only its range is
  ** checked); an edited one ran the rest of its step at that temperature,
  ** and an adaptive one at any, 0 or 1e300 */
  const int adaptive = a->sched_type == &lw_schedule_adaptive;
  if (!a->dyn && a->block >= 0 && adaptive && a->n_rep > 1 &&
      !(a->t_sched >= a->params.t_end && a->t_sched <= a->params.t_start)) {
    s = lw_error_set(err, LW_EINPUT, "%s: [run] temperature: %.17g, outside the adaptive schedule's range [%g, %g]: "
                     "the state was edited", path, a->t_sched, a->params.t_end, a->params.t_start);
    goto out;
  }
  if (!a->dyn && a->block >= 0 && !(adaptive && a->n_rep > 1)) {
    /* (measured where the step before had sweeps) */
    const long b = a->block;
    const double t = step_temperature(a, b, b > 0 && block_start(a, b - 1) < block_start(a, b));
    if (t != a->t_sched) {
      s = lw_error_set(err, LW_EINPUT, "%s: [run] temperature: %.17g, but the %s schedule's step %ld is at %.17g: "
                       "the state was edited, or written by a release whose schedule differs (t_end / t_start "
                       "under 2.2e-308 or over 1.8e308 before 2026-12-05): run it again", path, a->t_sched,
                       a->sched_type->name, a->block, t);
      goto out;
    }
  }
  if (a->seed != (unsigned long)a->params.seed) {
    s = lw_error_set(err, LW_EINPUT, "%s: [run] seed: %lu, but the run's scene.ini has anneal.seed = %.0f: the state "
                     "was edited", path, a->seed, a->params.seed);
    goto out;
  }
  set_temperatures(a);
  dir_file(path, sizeof path, a, "timing.txt");
  lw_error fifo; /* (a FIFO there is no timing: opening it would wait for ever) */
  FILE *tf = lw_text_plain_file(path, &fifo) ? NULL : fopen(path, "r");
  /* Without the sweeps' time before (timing.txt lost, as where state.lw and
  ** scene.ini alone were copied to another machine, or from before
  ** 2026-12-04), the rate counts this process's proposals over its own
  ** sweeps: every proposal over them gave a rate many times too high. */
  int timed = 0, wall = 0, got = 0;
  if (tf) {
    wall = fscanf(tf, "wall_seconds %lf", &a->wall_before) == 1 && a->wall_before >= 0 && a->wall_before < 1e12;
    if (!wall) a->wall_before = 0;
    timed = wall && (got = fscanf(tf, " sweep_seconds %lf", &a->sweep_seconds)) == 1 && a->sweep_seconds >= 0 &&
            a->sweep_seconds < 1e12;
    /* (the wall time alone is an older release's; a line after it that is
    ** no sweep time is damage: unreadable, timed from here on) */
    if (wall && !timed && got != EOF) a->wall_before = 0, wall = 0;
    /* (a count that is no whole number from 0 to 2^53 is damage: "-7" read
    ** as 2^64 - 7 gave a rate of 0) */
    double untimed = 0.0;
    got = timed ? fscanf(tf, " untimed_proposals %lf", &untimed) : EOF;
    if (got == 1 && untimed >= 0.0 && untimed <= 9007199254740992.0 && untimed == floor(untimed))
      a->untimed = (unsigned long)untimed;
    else if (got != EOF) timed = 0, a->wall_before = 0, wall = 0;
    fclose(tf);
  }
  if (!timed) {
    /* (a release before 2026-12-04 wrote the wall time alone: kept, where
    ** it was said missing and thrown away) */
    a->sweep_seconds = 0;
    a->untimed = 0;
    for (int k = 0; a->chain && k < a->chain->n_moves; k++) a->untimed += a->chain->stats[k].proposed;
    a->untimed_said = wall ? 2 : 1;
  }
  if (a->end_sweep < 0) a->end_sweep = a->params.sweeps > a->sweep ? a->params.sweeps : a->sweep;
  const long saved_end = a->end_sweep;
  /* N more sweeps that stay short of the end stop there, unfinished, so that
  ** a plain resume goes on to the end (they once made sweep + N the end, and
  ** the run "finished" half cooled); N that reach it or past extend the run */
  a->pause_at = -1;
  if (more >= 0 && a->sweep + more < saved_end) a->pause_at = a->sweep + more;
  else if (more >= 0) a->end_sweep = a->sweep + more;
  /* the checksum after every value's own check, which names what it finds,
  ** and before anything is written; a run begun before it (a state without
  ** block_shift, of the same day) is written on without, to its old
  ** release's bytes, and one whose line was taken out on purpose with */
  if (st.doc && (s = lw_ckpt_verify(st.doc, err))) goto out;
  a->unsummed = a->acc_unshifted;
  /* (every process of an MPI run: one that writes nothing must still stop
  ** with the others, not at once) */
  lw_phase_writing();
  /* (a link planted as frames/ was found at the first frame, the sweeps
  ** since the checkpoint run for nothing) */
  if (writes_files(a)) s = lw_runfiles_check_links(a->dir, err) ? err->code : truncate_trace(a, trace_bytes, err);
  a->frame_before.have = a->params.frames_every &&
                         lw_runfiles_frame_size(a->dir, a->sweep, &a->frame_before.sweep, &a->frame_before.w,
                                                &a->frame_before.h);
  /* nothing else is written yet: the caller may still refuse to go on */
  a->extending = !s && writes_files(a) && !lw_anneal_done(a);
  a->new_end = a->end_sweep != saved_end;
out:
  lw_phase_set(NULL);
  for (int k = 1; k < LW_TEMPERING_MAX; k++) lw_ckpt_free(rep[k]);
  lw_state_clear(&st);
  return s;
}

/* ---- the loop ------------------------------------------------------- */

static void trace_row(lw_anneal *a)
{
  /* the observables come from the process that sweeps the replica at rung
  ** 0 (every process holds every replica, but the others' are stand-ins:
  ** anneal_net.h), so every process takes part before all but the one
  ** writing the trace return */
  const lw_system_type *t = a->sys_type;
  double v[LW_OBSERVABLES_MAX];
  if (a->params.observables) {
    if (rung_here(a, 0)) t->observe(a->sys->state, v);
    if (a->net)
      a->net->broadcast(a->net, lw_anneal_net_owner(a->pt ? a->pt->at[0] : 0, a->n_rep, a->net->size), v,
                        t->n_observables);
  }
  if (!a->trace) return; /* another process writes it */
  lw_chain *c = a->chain;
  double term[LW_SYSTEM_TERMS_MAX];
  t->terms(a->sys->state, term);
  if (a->dyn) {
    double kin = lw_dynamics_kinetic(a->dyn), pot = lw_system_total(a->sys);
    fprintf(a->trace, "%ld", a->sweep);
    trace_number(a, a->dyn->time, 0);
    for (int k = 0; k < t->n_terms; k++)
      if (t->term_on(a->setup, k)) trace_number(a, term[k], 0);
    trace_number(a, pot, 1);
    trace_number(a, kin, 1);
    trace_number(a, pot + kin, 1);
    trace_row_end(a, v);
    return;
  }
  fprintf(a->trace, "%ld", a->sweep);
  trace_number(a, c->temperature, 0);
  for (int k = 0; k < t->n_terms; k++)
    if (t->term_on(a->setup, k)) trace_number(a, term[k], 0);
  trace_number(a, rung_energy(a, 0), 0);
  for (int k = 0; k < c->n_moves; k++) {
    unsigned long p = c->stats[k].proposed - a->trace_mark[k].proposed;
    unsigned long acc = c->stats[k].accepted - a->trace_mark[k].accepted;
    if (p) fprintf(a->trace, ",%.6f", (double)acc / (double)p);
    else fprintf(a->trace, ",");
    a->trace_mark[k] = c->stats[k];
  }
  if (a->pt) {
    for (int k = 0; k < a->n_rep; k++) {
      trace_number(a, a->chains[k]->temperature, 0);
      trace_number(a, rung_energy(a, k), 0);
    }
    /* swap acceptance since the previous row */
    for (int k = 0; k + 1 < a->n_rep; k++) {
      unsigned long tried = a->pt->tried[k] - a->swap_mark[2 * k];
      unsigned long acc = a->pt->accepted[k] - a->swap_mark[2 * k + 1];
      if (tried) fprintf(a->trace, ",%.6f", (double)acc / (double)tried);
      else fprintf(a->trace, ",");
      a->swap_mark[2 * k] = a->pt->tried[k];
      a->swap_mark[2 * k + 1] = a->pt->accepted[k];
    }
  }
  trace_row_end(a, v);
}

/* ladder.ini: the tuned ladder, ready to paste into a scene or --set. */
static lw_status write_ladder(const lw_anneal *a, lw_error *err)
{
  char path[LW_PATH_MAX + 32], tmp[LW_PATH_MAX + 64];
  dir_file(path, sizeof path, a, "ladder.ini");
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) return err->code;
  /* "ready to reuse": the fewest digits that read back the same double, so
  ** a run on it starts where this one froze (the field holds 256 rungs at
  ** 17 digits), over indented lines as scene.ini writes it */
  const lw_param_def *d = lw_params_find("tempering", "ladder");
  char value[LW_TEMPERING_MAX * 26];
  size_t used = 0;
  for (int k = 0; k < a->n_rep; k++) {
    int n = 0;
    for (int digits = 15; digits <= 17; digits++) {
      n = snprintf(value + used, sizeof value - used, "%s%.*g", k ? " " : "", digits, a->pt->ladder[k]);
      if (strtod(value + used, NULL) == a->pt->ladder[k]) break;
    }
    used += (size_t)n;
  }
  fprintf(f, "; ladder tuned toward equal swap acceptance over %d sweeps\n[tempering]\n", a->params.ladder_sweeps);
  lw_params_write_list(f, d, value);
  return lw_output_commit(f, tmp, path, err);
}

/* Exchange step and, during the warm-up, ladder tuning; after the warm-up
** the ladder is frozen and the swap statistics start afresh. */
static lw_status exchange(lw_anneal *a, lw_error *err)
{
  const lw_params *p = &a->params;
  lw_tempering *pt = a->pt;
  int n = a->n_rep, swapped[LW_TEMPERING_MAX];
  double e[LW_TEMPERING_MAX] = {0}, t[LW_TEMPERING_MAX] = {0};
  for (int k = 0; k < n; k++) {
    e[k] = rung_energy(a, k);
    t[k] = a->chains[k]->temperature;
  }
  lw_tempering_exchange(pt, e, t, swapped);
  for (int k = 0; k + 1 < n; k++)
    if (swapped[k]) {
      lw_system *sys = a->chains[k]->sys;
      a->chains[k]->sys = a->chains[k + 1]->sys;
      a->chains[k + 1]->sys = sys;
    }
  a->sys = a->chains[0]->sys;
  lw_status s;
  if (a->net && (s = a->net->moved(a->net, a, swapped, err))) return s;
  if (p->tune_ladder == LW_LADDER_EQUAL && a->sweep <= p->ladder_sweeps) {
    if (pt->steps % LW_TEMPERING_TUNE_EVERY == 0) {
      /* (counted from the start: from the end of the moves' step tuning
      ** instead, LJ13's ladders came out no more even and the wire's less) */
      lw_tempering_tune(pt, lw_tempering_tune_gain((long)(pt->steps / LW_TEMPERING_TUNE_EVERY)));
      set_temperatures(a);
    }
    if (a->sweep + p->exchange_every > p->ladder_sweeps) {
      lw_tempering_reset_stats(pt);
      memset(a->swap_mark, 0, sizeof a->swap_mark);
      return writes_files(a) ? write_ladder(a, err) : LW_OK;
    }
  }
  return LW_OK;
}

/* samples/sample-SSSSSS.csv: the coldest replica's configuration, written
** whole under a temporary name and renamed.  A run resumed from an earlier
** checkpoint writes the same bytes again, so no sample needs undoing. */
static lw_status write_sample(lw_anneal *a, lw_error *err)
{
  char path[LW_PATH_MAX + 64], tmp[LW_PATH_MAX + 96];
  if (lw_output_subdir(a->dir, "samples", path, sizeof path, err)) return err->code;
  size_t n = strlen(path);
  snprintf(path + n, sizeof path - n, "/sample-%06ld.csv", a->sweep);
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) return err->code;
  a->sys_type->write_sample(a->sys->state, f);
  return lw_output_commit(f, tmp, path, err);
}

/* Frames, samples and checkpoints that fall due after a sweep.  Frames and
** samples are extra files: they read the state and change nothing. */
static lw_status sweep_files(lw_anneal *a, lw_error *err)
{
  const lw_params *p = &a->params;
  /* the end has a frame as it has a trace row, on the grid or not: the film
  ** ended short of the drawing (at 180 of 200, at 0 with frames_every past
  ** the sweeps) */
  double t0 = lw_phase_clock();
  const int frame = p->frames_every && (a->sweep % p->frames_every == 0 || lw_anneal_done(a)) && rung_here(a, 0),
            sample = p->samples_every && a->sweep % p->samples_every == 0 && rung_here(a, 0);
  if ((frame || sample) && dir_still_ours(a, err)) return err->code;
  if (frame) {
    if (a->sys_type->draw(a->sys->state, p, a->dir, a->sweep, err)) return err->code;
    a->film_seconds[0] += lw_phase_clock() - t0;
  }
  if (sample) {
    t0 = lw_phase_clock();
    if (write_sample(a, err)) return err->code;
    a->film_seconds[1] += lw_phase_clock() - t0;
  }
  if (a->sweep % p->checkpoint_every == 0) return lw_anneal_checkpoint(a, err);
  return LW_OK;
}

/* A sweep of the dynamics: steps_per_sweep time steps.  The system's state
** is recomputed from scratch at every step (set_coords), so there is no
** drift to check. */
static lw_status dynamics_sweep(lw_anneal *a, lw_error *err)
{
  const lw_params *p = &a->params;
  for (int k = 0; k < p->dyn_steps_per_sweep; k++) {
    lw_status s = lw_dynamics_step(a->dyn, err);
    /* the scene was read and checked: what stops the motion now is the
    ** run's failure (exit 1), its files kept */
    if (s == LW_EINPUT) s = err->code = LW_ERUN;
    /* where no dt helps, the row says what does (system.h) */
    const char *advice = s && a->sys_type->motion_advice ? a->sys_type->motion_advice(p) : NULL;
    if (advice) {
      char msg[LW_ERROR_MSG];
      snprintf(msg, sizeof msg, "%s", err->msg);
      lw_error_set(err, s, "%s; %s", msg, advice);
    }
    if (s) return s;
  }
  a->sweep++;
  if (a->sweep % p->trace_every == 0 || lw_anneal_done(a)) trace_row(a);
  return sweep_files(a, err);
}

/* The sum of the magnitudes of replica r's running terms (at least 1, the
** scale of lw_system_drift); on every process, whose stand-ins hold the
** terms of the replicas swept elsewhere (anneal_net.h). */
static double replica_size(const lw_anneal *a, int r)
{
  double v[LW_SYSTEM_TERMS_MAX], size = 0.0;
  a->sys_type->terms(a->systems[r]->state, v);
  for (int t = 0; t < a->sys_type->n_terms; t++) size += fabs(v[t]);
  return fmax(size, 1.0);
}

/* Whether the energy is recomputed from scratch after this sweep: every
** check_every sweeps (the drift check, with the renumbering before it), and
** wherever a replica's terms have fallen to under 1 / LW_ANNEAL_FALL of
** their largest size since its last recomputation.  A running total keeps
** the rounding of where it has been: particles of a points file on top of
** a pattern's start near 1e19 and are at -2,800 twenty sweeps on, with an
** error of all of it, which the trace and summary showed and which made
** resume refuse a checkpoint as damaged.  Where the totals agree with the
** recomputation to LW_ANNEAL_EARLY_DRIFT they stay (the bits of every
** ordinary run).  The peaks are kept in state.lw: a resumed process that
** began them at the state it read skipped recomputations the run which
** never stopped made, and where those replaced the totals (a strain of
** 1e12, its drift 5e-9) the two went apart.  Sizes are of terms every
** process holds (stand-ins included), so every process decides alike. */
#define LW_ANNEAL_EARLY_DRIFT 1e-9 /* relative drift an early recomputation corrects */
#define LW_ANNEAL_FALL 8.0
static int refresh_due(lw_anneal *a, int *renumber)
{
  int fell = 0;
  for (int r = 0; r < a->n_rep; r++) {
    const double size = replica_size(a, r);
    if (size > a->size_peak[r]) a->size_peak[r] = size;
    if (size * LW_ANNEAL_FALL < a->size_peak[r]) fell = 1;
  }
  *renumber = a->sweep % a->params.check_every == 0;
  return *renumber || fell;
}

/* The recomputation of replica r from scratch (with the renumbering of
** its parts where due), its drift, and the running totals kept where an
** early one agrees with them: the bits of a run without it (and of runs
** begun by older releases); such a one does not count in max_drift. */
static lw_status refresh_replica(lw_anneal *a, int r, int renumber, double *drift, lw_error *err)
{
  double run[LW_SYSTEM_TERMS_MAX], fresh[LW_SYSTEM_TERMS_MAX];
  void *state = a->systems[r]->state;
  lw_status s;
  *drift = 0.0;
  if (renumber && a->sys_type->renumber && (s = a->sys_type->renumber(state, err))) return s;
  a->sys_type->terms(state, run);
  if (a->sys_type->refresh(state) != LW_OK) return lw_error_set(err, LW_ENOMEM, "out of memory");
  a->sys_type->terms(state, fresh);
  *drift = lw_system_drift(run, fresh, a->sys_type->n_terms);
  if (!renumber && !(*drift > LW_ANNEAL_EARLY_DRIFT)) a->sys_type->set_terms(state, run);
  return LW_OK;
}

static lw_status sweep_once(lw_anneal *a, lw_error *err)
{
  if (a->dyn) return dynamics_sweep(a, err);
  const lw_params *p = &a->params;
  int n = a->n_rep;
  long b = block_of(a, a->sweep);
  if (b != a->block) {
    if (a->block >= 0) {
      double cnt = a->acc_n, mean = cnt > 0 ? a->acc_sum / cnt : 0.0;
      double var = cnt > 1 ? (a->acc_sumsq - cnt * mean * mean) / (cnt - 1) : 0.0;
      a->prev = (lw_block_stats){a->acc_shift + mean, var > 0 ? sqrt(var) : 0.0, (long)cnt};
      a->t_prev = a->t_sched;
    }
    /* steps without a sweep (more steps than sweeps) each take their turn
    ** in a recursive schedule, unmeasured: the adaptive rule cooled one
    ** ratio per sweep, not per step, and ended 12 times above where the step
    ** it reached stands; the others go straight to step b (a loop over 1e9
    ** steps took 16 s) */
    const int recursive = (a->sched_type->needs & LW_SCHEDULE_RECURSIVE) != 0;
    for (long k = recursive || a->block < 0 ? a->block + 1 : b; k <= b; k++) {
      if (k > a->block + 1) a->t_prev = a->t_sched;
      a->t_sched = step_temperature(a, k, a->block >= 0 && k == a->block + 1);
    }
    /* (schedule.h's promise, which a new schedule's function may break: a
    ** run at T < 0 climbed the energy and reported its t_end) */
    if (!(a->t_sched >= 0.0) || !isfinite(a->t_sched))
      return lw_error_set(err, LW_ERUN, "anneal.schedule = %s gave the temperature %g at step %ld: expected a finite "
                          "temperature >= 0 (a fault of the schedule's function, include/linewise/schedule.h)",
                          a->sched_type->name, a->t_sched, b);
    set_temperatures(a);
    a->block = b;
    a->acc_n = a->acc_sum = a->acc_sumsq = 0.0;
    for (int k = 0; k < n; k++) {
      memset(a->chains[k]->win_prop, 0, sizeof a->chains[k]->win_prop);
      memset(a->chains[k]->win_acc, 0, sizeof a->chains[k]->win_acc);
    }
  }
  int tuning = a->sweep - block_start(a, b) < p->tune_sweeps && a->sweep < p->sweeps;
  if (a->size_peak[0] == 0.0)
    for (int r = 0; r < n; r++) a->size_peak[r] = replica_size(a, r);
  int failed = 0, here[LW_TEMPERING_MAX], m = 0;
  for (int k = 0; k < n; k++)
    if (rung_here(a, k)) here[m++] = k; /* all of them in one process */
  /* The rungs are independent between exchanges: each touches only its own
  ** chain, stream and system, so the thread count cannot change the result. */
  /* Threads go to the rungs first; a rung split into domains runs its
  ** share of the rest there (domains.h). */
  /* (one rung outside any parallel region: under an inactive one, `if
  ** (m > 1)`, its domains' team was a nested one, which libgomp starts anew
  ** at every sweep, 4 threads a sweep, where a team of the top level keeps
  ** its threads; under a memory limit a sweep then ended the process) */
  if (m == 1) {
    a->chains[here[0]]->tuning = tuning;
    failed = lw_chain_sweep(a->chains[here[0]]) != LW_OK;
  } else {
#pragma omp parallel for schedule(static, 1) reduction(| : failed) \
    num_threads(m < omp_get_max_threads() ? m : omp_get_max_threads())
    for (int i = 0; i < m; i++) {
      a->chains[here[i]]->tuning = tuning;
      if (lw_chain_sweep(a->chains[here[i]]) != LW_OK) failed = 1;
    }
  }
  lw_status s;
  if (a->net && (s = a->net->share(a->net, a, failed, err))) return s;
  if (failed) return lw_error_set(err, LW_ENOMEM, "out of memory growing a system's caches");
  a->sweep++;
  if (a->pt && a->sweep % p->exchange_every == 0 && (s = exchange(a, err))) return s;
  double e = rung_energy(a, 0);
  if (!tuning && isfinite(e)) {
    if (a->acc_n == 0.0 && !a->acc_unshifted) a->acc_shift = e;
    const double d = e - a->acc_shift;
    a->acc_n += 1.0;
    a->acc_sum += d;
    a->acc_sumsq += d * d;
  }
  int renumber;
  if (refresh_due(a, &renumber)) {
    /* each replica's recomputation is its own, like its sweep: on the
    ** sweep's threads, then the first failure in replica order and the
    ** largest drift, so the thread count changes nothing */
    int rep[LW_TEMPERING_MAX], nr = 0, first_r = n;
    double drift[LW_TEMPERING_MAX];
    lw_status rs[LW_TEMPERING_MAX];
    lw_error first = {0};
    for (int r = 0; r < n; r++)
      if (replica_here(a, r)) rep[nr++] = r;
#pragma omp parallel for schedule(static, 1) num_threads(nr < omp_get_max_threads() ? nr : omp_get_max_threads()) if (nr > 1)
    for (int i = 0; i < nr; i++) {
      lw_error re = {0};
      if ((rs[i] = refresh_replica(a, rep[i], renumber, &drift[i], &re)) != LW_OK) {
#pragma omp critical(lw_anneal_refresh)
        if (rep[i] < first_r) first_r = rep[i], first = re;
      }
    }
    s = LW_OK;
    for (int i = 0; i < nr && !s; i++) {
      if (rs[i] != LW_OK) {
        *err = first;
        s = first.code;
      } else {
        /* over the largest size since the last recomputation, the scale of
        ** the totals' rounding: a fall's own stays near eps (a start at 1e17
        ** that fell to -2800 within a sweep read 3.5e-4 in max_drift over the
        ** size after it), and a row whose commits do not add up its moves' dE
        ** stands out */
        const double d = drift[i] * replica_size(a, rep[i]) / fmax(a->size_peak[rep[i]], 1.0);
        if ((renumber || drift[i] > LW_ANNEAL_EARLY_DRIFT) && d > a->max_drift) a->max_drift = d;
        if (d > a->row_drift) a->row_drift = d;
      }
    }
    if (a->net) s = a->net->drift(a->net, a, s, err);
    if (s) return s;
    for (int r = 0; r < n; r++) a->size_peak[r] = replica_size(a, r);
  }
  /* after the recomputation: a row shows the totals a checkpoint here keeps */
  if (a->sweep % p->trace_every == 0 || lw_anneal_done(a)) trace_row(a);
  return sweep_files(a, err);
}

/* The sweep timed: proposals_per_second is the sweeps' rate, not the set-up's
** or the drawings' (which at 10^5 splines took four fifths of a short run). */
lw_status lw_anneal_sweep(lw_anneal *a, lw_error *err)
{
  /* (the locale changed since the start: checked at a checkpoint only, a
  ** program's trace.csv took decimal commas for a hundred rows first) */
  lw_status s = refuse_finished(a, "lw_anneal_sweep", err);
  if (s || (s = lw_number_locale_ok(err)) || (s = lw_anneal_settle(a, err))) return s;
  const double t0 = lw_phase_clock();
  a->totals_fresh = 0;
  s = sweep_once(a, err);
  a->sweep_seconds += lw_phase_clock() - t0;
  /* (a stop asked during the first sweep keeps the run set aside: the
  ** caller may give way, lw_anneal_undo_start) */
  if (!s && !lw_phase_stopping()) drop_stash(a);
  return s;
}

/* One count of lw_move_stats (at byte offset `at`) per move kind, by name. */
static void put_per_move(lw_json *j, const char *key, const lw_chain *c, const lw_system_type *t, size_t at)
{
  lw_json_key(j, key);
  lw_json_begin_object(j);
  for (int k = 0; k < c->n_moves; k++) {
    unsigned long v;
    memcpy(&v, (const char *)&c->stats[k] + at, sizeof v);
    lw_json_key(j, t->move_names[k]);
    lw_json_int(j, (long long)v);
  }
  lw_json_end_object(j);
}

/* Where the run prints its trace to 10 digits (output.trace_exact = 0),
** names an observable whose values x[m] (a heat capacity: its energy's, in
** t) are coarse against their spread (lw_trace_rounded) in
** a->observables_rounded.  x is overwritten. */
static void observable_rounded(lw_anneal *a, const lw_trace *t, const size_t *rows, size_t n, const char *name,
                               int obs, double *x, size_t m)
{
  if (!obs) { /* replicaK_heat_capacity of replicaK_energy, heat_capacity of total */
    char src[64];
    const size_t keep = strlen(name) - strlen("heat_capacity");
    snprintf(src, sizeof src, "%.*s%s", (int)keep, name, keep ? "energy" : "total");
    const int e = lw_trace_column(t, src);
    m = 0;
    for (size_t i = 0; e >= 0 && i < n; i++)
      if (!isnan(t->v[rows[i] * t->n_cols + (size_t)e])) x[m++] = t->v[rows[i] * t->n_cols + (size_t)e];
  }
  const size_t used = strlen(a->observables_rounded);
  if (lw_trace_rounded(x, m) && used < sizeof a->observables_rounded)
    snprintf(a->observables_rounded + used, sizeof a->observables_rounded - used, "%s%s", used ? ", " : "", name);
}

/* summary.json's observables: each obs_ column's, and each heat capacity's
** (trace.h), mean, standard error, autocorrelation time and effective
** samples over the stretch that `linewise stats` takes by default (trace.h),
** read back from trace.csv, which the checkpoint before has flushed; null
** where the trace has no such stretch.  The effective samples let a sweep's table show the error bars
** too rough to trust (under 25, as `linewise stats` warns). */
static void put_observables(lw_anneal *a, lw_json *j)
{
  char path[LW_PATH_MAX + 32], key[96];
  dir_file(path, sizeof path, a, "trace.csv");
  lw_error e;
  lw_trace *t = lw_trace_read(path, &e);
  lw_trace_select sel = {.from = -1, .to = -1};
  lw_trace_select_of(&a->params, &sel);
  size_t *rows = NULL, n = 0, tuned;
  double *x = NULL;
  lw_trace *h = NULL; /* t with its heat capacities */
  lw_json_key(j, "observables");
  lw_status rs = LW_OK;
  a->observables_lost[0] = a->observables_rounded[0] = '\0';
  if (!t || (rs = lw_trace_rows(t, path, &sel, &rows, &n, &tuned, &e)) || !(x = malloc(n * sizeof *x)) ||
      !(h = lw_trace_with_heat_capacity(t, rows, n, path, &e))) {
    /* null too where no row qualifies (documented, and nothing to say) */
    if (rs != LW_EINPUT)
      snprintf(a->observables_lost, sizeof a->observables_lost, "%.500s", t && !rs && !x ? "out of memory" : e.msg);
    lw_json_null(j);
  } else {
    const int sweep = lw_trace_column(t, "sweep");
    const double every = lw_trace_every(t);
    lw_json_begin_object(j);
    lw_json_key(j, "from"); lw_json_int(j, (long long)t->v[rows[0] * t->n_cols + (size_t)sweep]);
    lw_json_key(j, "to"); lw_json_int(j, (long long)t->v[rows[n - 1] * t->n_cols + (size_t)sweep]);
    lw_json_key(j, "rows"); lw_json_int(j, (long long)n);
    for (size_t k = 0; k < h->n_cols; k++) {
      const char *name = h->name[k];
      size_t len = strlen(name);
      int obs = !strncmp(name, "obs_", 4), heat = len >= 13 && !strcmp(name + len - 13, "heat_capacity");
      if (!obs && !heat) continue;
      lw_series_stats st;
      lw_trace_column_stats(h, rows, n, (int)k, x, &st);
      if (!a->params.trace_exact) observable_rounded(a, t, rows, n, name, obs, x, st.n);
      const char *suffix[7] = {"", "_stderr", "_tau_sweeps", "_n_eff", "_window_closed", "_drift_z", "_batch_ratio"};
      const double value[7] = {st.mean, st.stderr_mean, st.tau * lw_trace_column_gap(every, n, &st), st.n_eff,
                               st.window > 0, st.drift_z, st.batch_ratio};
      for (int q = 0; q < 7; q++) {
        snprintf(key, sizeof key, "%s%s", obs ? name + 4 : name, suffix[q]);
        lw_json_key(j, key);
        /* tau, n_eff, the window, the halves and the batches mean nothing
        ** for a column without spread */
        if (!st.n || (q >= 2 && !(st.sd > 0.0)) || isnan(value[q])) lw_json_null(j);
        else if (q == 4) lw_json_bool(j, st.window > 0);
        else lw_json_number(j, value[q]);
      }
    }
    lw_json_end_object(j);
  }
  free(x);
  free(rows);
  lw_trace_free(h);
  lw_trace_free(t);
}

static lw_status write_summary(lw_anneal *a, lw_error *err)
{
  char path[LW_PATH_MAX + 32], tmp[LW_PATH_MAX + 64];
  dir_file(path, sizeof path, a, "summary.json");
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) return err->code;
  lw_chain *c = a->chain;
  const lw_system_type *t = a->sys_type;
  unsigned long prop = 0, acc = 0, nan = 0;
  for (int k = 0; k < c->n_moves; k++) {
    prop += c->stats[k].proposed;
    acc += c->stats[k].accepted;
    nan += c->stats[k].nan;
  }
  double wall = lw_anneal_seconds(a);
  lw_json j;
  lw_json_init(&j, f);
  lw_json_begin_object(&j);
  lw_json_key(&j, "version"); lw_json_string(&j, LW_VERSION); /* the release that wrote it */
  lw_json_key(&j, "build"); lw_json_string(&j, lw_version_build());
  char libs[256];
  lw_version_libraries(libs, sizeof libs);
  lw_json_key(&j, "libraries"); lw_json_string(&j, libs);
  lw_json_key(&j, "seed"); lw_json_int(&j, (long long)a->seed);
  lw_json_key(&j, "sweeps"); lw_json_int(&j, a->sweep);
  lw_json_key(&j, "system"); lw_json_string(&j, t->name);
  t->summary(a->sys->state, &j);
  /* the dynamics proposes nothing and has no temperature: what Monte Carlo
  ** counts would read as zeros and the unread schedule's name */
  const int mc = !a->dyn;
  if (mc) {
    lw_json_key(&j, "proposals"); lw_json_int(&j, (long long)prop);
    lw_json_key(&j, "accepted"); lw_json_int(&j, (long long)acc);
    lw_json_key(&j, "rejected_nan"); lw_json_int(&j, (long long)nan);
    put_per_move(&j, "rejected_irregular", c, t, offsetof(lw_move_stats, irregular));
    put_per_move(&j, "rejected_crowded", c, t, offsetof(lw_move_stats, crowded));
    put_per_move(&j, "rejected_outside", c, t, offsetof(lw_move_stats, outside));
  }
  lw_json_key(&j, "wall_seconds"); lw_json_number(&j, wall);
  lw_json_key(&j, "sweep_seconds"); lw_json_number(&j, a->sweep_seconds);
  if (mc) {
    /* of the sweeps of the whole run; none where no sweep was timed (a
    ** redraw), not a 0 that a script averaging rates would count */
    lw_json_key(&j, "proposals_per_second");
    if (a->sweep_seconds > 0 && prop >= a->untimed) lw_json_number(&j, (double)(prop - a->untimed) / a->sweep_seconds);
    else lw_json_null(&j);
    lw_json_key(&j, "max_relative_drift"); lw_json_number(&j, a->max_drift);
    lw_json_key(&j, "temperature_final"); /* none where no sweep ran (a redraw) */
    if (a->sweep > 0) lw_json_number(&j, c->temperature);
    else lw_json_null(&j);
    lw_json_key(&j, "schedule"); lw_json_string(&j, a->sched_type->name);
  }
  lw_json_key(&j, "driver"); lw_json_string(&j, a->params.driver);
  if (a->dyn) {
    lw_dynamics *d = a->dyn;
    lw_json_key(&j, "dynamics");
    lw_json_begin_object(&j);
    lw_json_key(&j, "time"); lw_json_number(&j, d->time);
    lw_json_key(&j, "time_steps"); lw_json_int(&j, (long long)d->steps);
    lw_json_key(&j, "kinetic"); lw_json_number(&j, lw_dynamics_kinetic(d));
    lw_json_key(&j, "halvings"); lw_json_int(&j, (long long)d->halvings);
    lw_json_key(&j, "fixed_point_iterations_max"); lw_json_int(&j, d->iterations_max);
    lw_json_end_object(&j);
  }
  lw_json_key(&j, "energy");
  lw_json_begin_object(&j);
  lw_json_key(&j, "total"); lw_json_number(&j, lw_system_total(a->sys));
  double term[LW_SYSTEM_TERMS_MAX];
  t->terms(a->sys->state, term);
  for (int k = 0; k < t->n_terms; k++)
    if (t->term_on(a->setup, k)) {
      lw_json_key(&j, t->term_names[k]);
      lw_json_number(&j, term[k]);
    }
  lw_json_end_object(&j);
  lw_json_key(&j, "energy_initial"); lw_json_number(&j, a->energy_initial);
  if (a->quenched) {
    const lw_quench_report *q = &a->quench;
    lw_json_key(&j, "quench");
    lw_json_begin_object(&j);
    lw_json_key(&j, "method"); lw_json_string(&j, "bfgs");
    lw_json_key(&j, "energy_before"); lw_json_number(&j, q->energy_before);
    lw_json_key(&j, "energy_after"); lw_json_number(&j, q->energy_after);
    lw_json_key(&j, "gradient_before"); lw_json_number(&j, q->gradient_before);
    lw_json_key(&j, "gradient_after"); lw_json_number(&j, q->gradient_after);
    lw_json_key(&j, "converged"); lw_json_bool(&j, q->converged);
    lw_json_key(&j, "ended"); lw_json_string(&j, lw_quench_end_name(q->ended));
    lw_json_key(&j, "iterations"); lw_json_int(&j, q->iterations);
    lw_json_key(&j, "rounds"); lw_json_int(&j, q->rounds);
    lw_json_key(&j, "evaluations"); lw_json_int(&j, q->evaluations);
    lw_json_key(&j, "forbidden"); lw_json_int(&j, q->forbidden);
    lw_json_key(&j, "holds"); lw_json_int(&j, q->holds);
    lw_json_key(&j, "seconds"); lw_json_number(&j, q->seconds);
    lw_json_end_object(&j);
  }
  if (mc) {
    lw_json_key(&j, "acceptance");
    lw_json_begin_object(&j);
    for (int k = 0; k < c->n_moves; k++) {
      lw_json_key(&j, t->move_names[k]);
      if (c->stats[k].proposed) lw_json_number(&j, (double)c->stats[k].accepted / (double)c->stats[k].proposed);
      else lw_json_null(&j);
    }
    lw_json_end_object(&j);
  }
  if (a->params.observables) put_observables(a, &j);
  if (mc) {
    lw_json_key(&j, "proposed");
    lw_json_begin_object(&j);
    for (int k = 0; k < c->n_moves; k++) {
      lw_json_key(&j, t->move_names[k]);
      lw_json_int(&j, (long long)c->stats[k].proposed);
    }
    lw_json_end_object(&j);
    lw_json_key(&j, "steps");
    lw_json_begin_object(&j);
    for (int k = 0; k < c->n_moves; k++) {
      lw_json_key(&j, t->move_names[k]);
      if (c->step_max[k] > 0.0) lw_json_number(&j, c->step[k] / t->move_unit[k]);
      else lw_json_null(&j);
    }
    lw_json_end_object(&j);
  }
  if (a->pt) {
    const lw_tempering *pt = a->pt;
    lw_json_key(&j, "replicas");
    lw_json_begin_array(&j);
    for (int k = 0; k < a->n_rep; k++) {
      lw_json_begin_object(&j);
      lw_json_key(&j, "temperature"); /* none where no sweep ran, as temperature_final */
      if (a->sweep > 0) lw_json_number(&j, a->chains[k]->temperature);
      else lw_json_null(&j);
      lw_json_key(&j, "energy"); lw_json_number(&j, rung_energy(a, k));
      lw_json_end_object(&j);
    }
    lw_json_end_array(&j);
    lw_json_key(&j, "ladder");
    lw_json_begin_array(&j);
    for (int k = 0; k < a->n_rep; k++) lw_json_number(&j, pt->ladder[k]);
    lw_json_end_array(&j);
    lw_json_key(&j, "swap_acceptance");
    lw_json_begin_array(&j);
    for (int k = 0; k + 1 < a->n_rep; k++) {
      if (pt->tried[k]) lw_json_number(&j, lw_tempering_acceptance(pt, k));
      else lw_json_null(&j);
    }
    lw_json_end_array(&j);
    lw_json_key(&j, "swap_attempts");
    lw_json_begin_array(&j);
    for (int k = 0; k + 1 < a->n_rep; k++) lw_json_int(&j, (long long)pt->tried[k]);
    lw_json_end_array(&j);
    lw_json_key(&j, "round_trips"); lw_json_int(&j, (long long)pt->round_trips);
  }
  lw_json_end_object(&j);
  lw_status s = lw_json_finish(&j, err);
  if (s) {
    lw_output_abort(f, tmp);
    /* (the writer does not know the file's name, which the message needs) */
    char msg[LW_ERROR_MSG];
    snprintf(msg, sizeof msg, "%s", err->msg);
    return lw_error_set(err, s, "%s: %s", path, msg);
  }
  return lw_output_commit(f, tmp, path, err);
}

lw_status lw_anneal_finish(lw_anneal *a, lw_error *err)
{
  lw_status s = refuse_finished(a, "lw_anneal_finish", err);
  if (s || (s = lw_number_locale_ok(err))) return s;
  /* the last sweep's checkpoint, where one fell due, holds this state
  ** already: written again, the same bytes (1.3 s at 1e5 splines); its
  ** timings were taken before that sweep's time was added */
  if (a->saved != a->sweep + 1) s = lw_anneal_checkpoint(a, err);
  else s = writes_files(a) ? lw_checkpoint_write_timing(a, err) : LW_OK;
  if (s) return s;
  a->finished = 1;
  if (!rung_here(a, 0)) return LW_OK; /* the process of the coldest replica draws it */
  if ((s = dir_still_ours(a, err))) return s;
  /* summary.json's energies are the state's, recomputed: the running totals
  ** keep the rounding of every commit since the last check, which the drift
  ** check's floor of 1 lets pass below an energy of 1 (a particle cloud fallen
  ** from 72487 to 2e-4 in 20 sweeps read 3.4e-7 off in its 7th digit) */
  /* (not where they are already: a redraw, anneal.sweeps = 0, built the
  ** model twice, 12 % of its time at 4000 splines; the same bits) */
  /* the recomputation's drift counts too: a run shorter than check_every
  ** said 0 in max_relative_drift, as if its totals had been exact */
  /* (against the size now, not the peak since the last check as a sweep's
  ** check: a resumed process starts its peaks at the state it read, and its
  ** summary.json would differ from the run's that never stopped) */
  if (!a->totals_fresh) {
    double run[LW_SYSTEM_TERMS_MAX], fresh[LW_SYSTEM_TERMS_MAX];
    a->sys_type->terms(a->sys->state, run);
    /* (2 to 5 s unnamed at the end of a poster's run) */
    lw_phase_set("recomputing the energy from scratch");
    const lw_status r = a->sys_type->refresh(a->sys->state);
    lw_phase_set(NULL);
    if (r != LW_OK) return lw_error_set(err, LW_ENOMEM, "out of memory");
    a->sys_type->terms(a->sys->state, fresh);
    const double d = lw_system_drift(run, fresh, a->sys_type->n_terms);
    if (d > a->max_drift) a->max_drift = d;
  }
  if (a->params.quench == LW_QUENCH_BFGS && !a->quenched) {
    lw_phase_set("quenching to the nearest minimum");
    /* the dynamics' pins hold in its quench too */
    unsigned char *pinned = NULL;
    if (a->dyn) {
      const size_t n = a->sys_type->n_coords(a->sys->state);
      if (!(pinned = malloc(n ? n : 1))) return lw_error_set(err, LW_ENOMEM, "out of memory for the quench's pins");
      for (size_t i = 0; i < n; i++) pinned[i] = (unsigned char)a->sys_type->mass_pinned(a->dyn->mass, i);
    }
    const lw_quench_opts o = {a->params.quench_tol, a->params.quench_iterations, a->params.quench_stall, a->stop,
                              pinned};
    s = lw_quench_run(a->sys, &o, &a->quench, err);
    free(pinned);
    /* (a stopped quench stays the phase, which the watcher ends as stopped) */
    if (s || a->quench.ended != LW_QUENCH_STOPPED) lw_phase_set(NULL);
    if (s) return s;
    /* state.lw holds the annealed state: resume quenches again; the time
    ** spent is kept (a stopped 2-minute quench vanished from the totals) */
    if (a->quench.ended == LW_QUENCH_STOPPED) return lw_checkpoint_write_timing(a, err);
    a->quenched = 1;
  }
  /* (again: a quench of a minute, and the drawing, are long enough to move
  ** the directory in, and another made in its place took the results) */
  if ((s = dir_still_ours(a, err))) return s;
  lw_phase_set("drawing the final files and scoring them");
  if (a->drawing) *a->drawing = 1;
  if (!(s = a->sys_type->draw(a->sys->state, &a->params, a->dir, LW_DRAW_FINAL, err)) && !(s = dir_still_ours(a, err)))
    s = write_summary(a, err);
  /* the quench and the drawing counted too: an extension's total took up
  ** the last checkpoint's, before them (4 s of 12 lost on study.ini).  The
  ** run is whole once summary.json is written, which a script takes as its
  ** sign: a failure here (only a later extension's wall time would miss
  ** the drawing's) no longer makes it exit 1 beside a finished summary.
  ** Written by the process that drew, which wrote summary.json (under MPI
  ** one other than the first left the drawing out) */
  if (!s) {
    lw_error ignored;
    lw_checkpoint_write_timing(a, &ignored);
  }
  if (a->drawing) *a->drawing = s ? 0 : 2;
  lw_phase_set(NULL);
  if (!s) drop_stash(a);
  return s;
}

void lw_anneal_free(lw_anneal *a)
{
  /* a run given up after its first checkpoint without a sweep (a program's
  ** start then free) stands, as the next run or resume there would keep it */
  drop_stash(a);
  if (a->trace) fclose(a->trace);
  lw_dynamics_free(a->dyn);
  /* the chains first: tempering swaps systems between them */
  for (int k = 0; a->chains && k < a->n_rep; k++) lw_chain_free(a->chains[k]);
  for (int k = 0; a->systems && k < a->n_rep; k++) lw_system_free(a->systems[k]);
  free(a->chains);
  free(a->systems);
  if (a->setup) a->sys_type->setup_free(a->setup);
  lw_tempering_free(a->pt);
  lw_schedule_clear(&a->sched);
  lw_rundir_unlock(a->dir_hold);
  memset(a, 0, sizeof *a);
}
