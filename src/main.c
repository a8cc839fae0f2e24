/*
** main.c -- the linewise command line: prolog (parse, load), the command,
** epilog (report).  Every failure below reaches the user as one line on
** stderr and an exit status: 2 for bad usage or input, 1 for failures while
** running.
*/
/* pthread_getattr_np: a thread's stack (thread_stack_too_small) */
#define _GNU_SOURCE
#include <errno.h>
#include <gsl/gsl_errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <omp.h>
#include <pthread.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "linewise/anneal.h"
#include "linewise/checkpoint.h"
#include "linewise/number.h"
#include "linewise/params.h"
#include "linewise/phase.h"
#include "linewise/reweight.h"
#include "linewise/rundir.h"
#include "linewise/runfiles.h"
#include "linewise/state.h"
#include "linewise/system.h"
#include "linewise/trace.h"
#include "linewise/vec2.h"
#include "linewise/version.h"
#ifdef LW_MPI
#include "linewise/mpi_tempering.h"
#endif

/* The processes of an MPI run (make mpi; NULL in the plain build). */
static lw_anneal_net *net;
#ifdef LW_MPI
/* Set once every process has started the run: a failure after that is one
** process's unless it was agreed; before it, every process read the same
** input and fails the same way. */
static int started;
#endif
/* a signal that ends the set-up says nothing: in a process of an MPI run but
** the first (mpirun ends the others when one fails: process 0 speaks), and
** once the failure is said (mpirun's signal came while it ended) */
static volatile sig_atomic_t signal_quiet = 0;

static const char usage[] =
  "usage: linewise <command> [options]\n"
  "\n"
  "commands:\n"
  "  run SCENE.ini       anneal a scene into a run directory\n"
  "      --out DIR           run directory, replaced if it holds a run (default\n"
  "                          out/<scene name>, or the first free out/<scene name>-N)\n"
  "      --set SEC.KEY=VAL   override a scene parameter (repeatable)\n"
  "      --seed N            override anneal.seed\n"
  "      --stop-at N         stop cleanly after sweep N, as if interrupted (0: after the\n"
  "                          set-up; resume refuses a sweep the run has passed)\n"
  "      --threads N         OpenMP threads: the replicas of parallel tempering, then\n"
  "                          anneal.domains (default OMP_NUM_THREADS or all cores;\n"
  "                          results never depend on it)\n"
  "      --quiet             no progress or parameter echo on stderr\n"
  "  resume DIR          continue the run in DIR bit-exactly from DIR/state.lw\n"
  "      --sweeps N          run N more sweeps (default: to the end of the schedule;\n"
  "                          short of it they stop as --stop-at does; past the end\n"
  "                          the last temperature holds)\n"
  "      --stop-at N, --threads N, --quiet  as for run\n"
  "  energy DIR          recompute DIR/state.lw's energy from scratch with its scene;\n"
  "                      prints '<term> <value>' per enabled term, then 'total <value>'\n"
  "      --set SEC.KEY=VAL   with a key of the scene changed (repeatable): with\n"
  "                          energy.quadrature=32 (and tone_quadrature, pair_quadrature\n"
  "                          where the scene sets them), what the run's nodes leave out\n"
  "  stats DIR...        means with error bars of DIR/trace.csv's columns (their\n"
  "                      integrated autocorrelation times), by default over the final\n"
  "                      temperature's sweeps (or from output.stats_from), tuning left\n"
  "                      out, and the heat capacity Var(E)/T^2 (each rung's when\n"
  "                      tempering); with several runs (seeds) also whether they agree\n"
  "                      and the error bar of their means' spread (se_runs)\n"
  "      --reweight N        instead, a tempering run's mean energy and heat capacity\n"
  "                          at N temperatures from the coldest rung's to the hottest's,\n"
  "                          every rung's energies reweighted (multiple histograms);\n"
  "                          empty between rungs that share almost no energies\n"
  "      --from S, --to S    only the rows of sweeps S to S (inclusive)\n"
  "      --csv               one CSV line a column: column,n,mean,stderr,sd,\n"
  "                          tau_sweeps,n_eff,window_closed,drift_z,batch_ratio (several runs:\n"
  "                          column,runs,n,mean,stderr,sd,tau_sweeps,n_eff,r_hat,p_runs,\n"
  "                          se_runs)\n"
  "  params              every scene parameter as Markdown (the table of docs/PARAMETERS.md)\n"
  "  schedules           the schedules' formulas as Markdown (the table of docs/SCHEDULES.md)\n"
  "  version             the release, build, SIMD widths, libraries, compiler (also --version, -V)\n"
  "  help                this text\n"
  "  --                  ends the options: a path after it may begin with '-'\n"
  "\n"
  "exit status: 0 done, 1 failed while running, 2 bad usage or bad input; a run stopped by Ctrl-C ends\n"
  "by SIGINT once its state is saved (130 in a shell)\n";

static int fail(const lw_error *err)
{
#ifdef LW_MPI
  if (net && net->size > 1 && started && !lw_mpi_agreed()) {
    /* the others would wait for this process at their next step */
    fprintf(stderr, "linewise: process %d: %s\n", net->rank, err->msg);
    lw_mpi_abort(lw_error_exit_status(err->code));
  }
#endif
  signal_quiet = 1;
  if (net && net->rank) return lw_error_exit_status(err->code); /* process 0 says it */
  fprintf(stderr, "linewise: %s\n", err->msg);
  return lw_error_exit_status(err->code);
}

/* Loads DIR/state.lw (its path into path) and the scene it names (relative
** to DIR). */
static lw_status load_run_dir(const char *dir, lw_params *p, lw_state *st, char *path, size_t n, lw_error *err)
{
  char scene_path[2 * LW_PATH_MAX + 2];
  lw_path_join(path, n, dir, "state.lw");
  lw_status s = lw_state_read(st, path, err);
  if (s) return s;
  if ((s = lw_state_scene_beside(st, path, err))) {
    lw_state_clear(st);
    return s;
  }
  lw_path_join(scene_path, sizeof scene_path, dir, st->scene);
  if ((s = lw_params_read_run(p, scene_path, 1, err))) lw_state_clear(st);
  return s;
}

static lw_status set_option(lw_params *p, const char *assignment, lw_error *err);

/* Whether the --set at argv[i] names a key that a later --set names again:
** the last one is the value (a script that appends its overrides was
** refused for a value it replaced). */
static int set_later(char **argv, int argc, int i)
{
  /* (--seed N is --set anneal.seed=N) */
  const char *name = !strcmp(argv[i], "--seed") ? "anneal.seed=" : argv[i + 1], *eq = strchr(name, '=');
  if (!eq) return 0;
  for (int j = i + 2; j + 1 < argc; j++)
    if ((!strcmp(argv[j], "--set") && !strncmp(argv[j + 1], name, (size_t)(eq - name) + 1)) ||
        (!strcmp(argv[j], "--seed") && !strncmp(name, "anneal.seed=", 12)))
      return 1;
  return 0;
}

/* For an argument refused as an option of a command whose options are
** `options` (NULL-ended; NULL: it has only --set): a file or directory of
** that name is what was meant, and "./" says so (options are read before
** names); or an option of it given as --out=DIR, the form of other
** programs, which is two words here (an option without a value says so). */
static const char *dash_hint(const char *arg, const char *const *options)
{
  static const char *const flags[] = {"--quiet", "--csv", NULL}, *const set_only[] = {"--set", NULL};
  static char buf[LW_PATH_MAX + 96];
  buf[0] = '\0';
  const char *eq = strchr(arg, '=');
  if (arg[0] == '-' && access(arg, F_OK) == 0) {
    snprintf(buf, sizeof buf, " ('%s' is a file or directory here: write './%s', or '--' before it)", arg, arg);
    return buf;
  }
  if (strncmp(arg, "--", 2) || !eq) return buf;
  const size_t len = (size_t)(eq - arg);
  int known = 0, flag = 0;
  for (const char *const *o = options ? options : set_only; *o; o++)
    known |= strlen(*o) == len && !strncmp(*o, arg, len);
  for (const char *const *o = flags; *o; o++) flag |= strlen(*o) == len && !strncmp(*o, arg, len);
  char word[LW_RUNDIR_WORD_MAX];
  if (known && flag)
    snprintf(buf, sizeof buf, " (%.*s takes no value)", (int)len, arg);
  else if (known)
    snprintf(buf, sizeof buf, " (an option and its value are two words: write '%.*s %s')", (int)len, arg,
             lw_rundir_shell_word(eq + 1, word, sizeof word));
  return buf;
}

/* " (did you mean 'X'?)" for the word of `list` (NULL-ended) nearest to a
** word that is none of them, or "": a typed --sed or rnu said only "unknown". */
static const char *nearest(const char *word, const char *const *list)
{
  static char buf[96];
  const char *hit = NULL;
  int best = 2 + (int)strlen(word) / 4; /* a suggestion is nearer than this */
  for (; *list; list++) {
    /* two letters swapped (rnu for run) are one slip, not two */
    int d = lw_params_edit_distance(word, *list);
    if (d == 2 && strlen(word) == strlen(*list)) {
      int count[256] = {0}, same = 1;
      for (const unsigned char *c = (const unsigned char *)word; *c; c++) count[*c]++;
      for (const unsigned char *c = (const unsigned char *)*list; *c; c++) same &= --count[*c] >= 0;
      if (same) d = 1;
    }
    if (d < best) best = d, hit = *list;
  }
  buf[0] = '\0';
  if (hit) snprintf(buf, sizeof buf, " (did you mean '%s'?)", hit);
  return buf;
}

static const char *const run_options[] = {"--out", "--seed", "--set", "--threads", "--stop-at", "--quiet", NULL},
                         *const resume_options[] = {"--sweeps", "--stop-at", "--threads", "--quiet", NULL},
                         *const stats_options[] = {"--from", "--to", "--csv", "--reweight", NULL},
                         *const commands[] = {"run", "resume", "energy", "stats", "params", "schedules", "help",
                                              "--help", "--version", NULL};

/* A run directory's path must leave room for the names of the files in it
** (DIR/frames/frame-000000.png and the like): paths are held in
** LW_PATH_MAX bytes, and a longer one would be cut to another directory. */
#define RUN_DIR_MAX (LW_PATH_MAX - 64)

/* A path with a control character in it: a script saved with CRLF line
** ends hands its last argument a CR, and the run went into a directory
** named "out\r" that no one can type (--set refused the same CR). */
static lw_status path_plain(const char *what, const char *path, lw_error *err)
{
  for (const char *c = path; *c; c++)
    if ((unsigned char)*c < 0x20 || *c == 0x7f)
      return lw_error_set(err, LW_EUSAGE, "%s: byte %zu of '%s' is 0x%02X, a control character%s: expected a path "
                          "without one", what, (size_t)(c - path) + 1, path, (unsigned char)*c,
                          *c == '\r' ? " (a CR: a script saved with CRLF line ends?)" : "");
  return LW_OK;
}

/* A bundled scene named without its folder ("linewise run example.ini" as
** the README's bin/linewise run params/example.ini, from an install or
** another directory) that is not here: where the bundled one is, beside
** this binary's install (PREFIX/share/linewise/params) or checkout. */
static void bundled_hint(const char *scene, lw_error *err)
{
  char exe[LW_PATH_MAX], path[2 * LW_PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
  /* (a picture given as the scene: the hint's params/photo.ini, away from
  ** the checkout, is the bundled one) */
  if (strstr(err->msg, " picture, not a scene file: a scene draws it") && access("params/photo.ini", F_OK))
    scene = "photo.ini";
  else if (!strstr(err->msg, ": cannot open scene file: ") || !access(scene, F_OK))
    return;
  /* the README's own form, params/example.ini, away from the checkout, and
  ** a bare name without its .ini, are the same bundled scene */
  const char *bare = strncmp(scene, "params/", 7) ? scene : scene + 7;
  const size_t len = strlen(bare);
  if (n <= 0 || strchr(bare, '/') || !len || len > 200) return;
  char name[256];
  snprintf(name, sizeof name, "%s%s", bare, len > 4 && !strcmp(bare + len - 4, ".ini") ? "" : ".ini");
  exe[n] = '\0';
  char *slash = strrchr(exe, '/');
  if (slash) *slash = '\0';
  static const char *const under[] = {"/../share/linewise/params/", "/../params/"};
  for (int k = 0; k < 2; k++) {
    snprintf(path, sizeof path, "%s%s%s", exe, under[k], name);
    char real[PATH_MAX], word[LW_RUNDIR_WORD_MAX];
    if (!access(path, R_OK) && realpath(path, real)) {
      const size_t m = strlen(err->msg);
      snprintf(err->msg + m, sizeof err->msg - m, " (the bundled %s is %.1000s)", name,
               lw_rundir_shell_word(real, word, sizeof word));
      return;
    }
  }
}

static lw_status dir_fits(const char *what, const char *dir, lw_error *err)
{
  if (path_plain(what, dir, err)) return err->code;
  if (strlen(dir) <= RUN_DIR_MAX) return LW_OK;
  return lw_error_set(err, LW_EUSAGE, "%s: a path of %zu bytes, longer than the %d a run directory may have (a "
                      "relative path is shorter)", what, strlen(dir), RUN_DIR_MAX);
}

/* LW_EUSAGE where dir is no directory: a scene file given to resume or
** energy read as "x.ini/state.lw: ... Not a directory". */
static lw_status run_dir_there(const char *what, const char *dir, const char *how, lw_error *err)
{
  struct stat sb;
  const int gone = stat(dir, &sb) ? errno : 0;
  if (!gone && S_ISDIR(sb.st_mode)) return LW_OK;
  return lw_error_set(err, LW_EUSAGE, "%s: '%s': %s; expected the directory a run wrote (its --out, out/NAME by "
                      "default) %s", what, dir, gone ? strerror(gone) : "a file, not a directory", how);
}

/* A directory's path without trailing slashes ("run/" named its files
** "run//final.svg" in every message); "/" stays. */
static char *trim_slashes(char *path)
{
  size_t n = strlen(path);
  while (n > 1 && path[n - 1] == '/') path[--n] = '\0';
  return path;
}

/* A message about a run directory that could not be read says so where the
** run waits in DIR/.replaced, set aside by a run killed as it started (its
** files there are not the run's). */
/* Notes one a line (the scene's and the schedule's builders part them with
** '\n'): joined by "; " three of a photograph's ran 600 characters. */
static void print_notes(const char *notes)
{
  for (const char *s = notes; *s;) {
    const size_t len = strcspn(s, "\n");
    fprintf(stderr, "linewise: note: %.*s\n", (int)len, s);
    s += len + (s[len] == '\n');
  }
}

static void stash_note(lw_error *err, const char *dir)
{
  const size_t n = strlen(err->msg);
  char word[LW_RUNDIR_WORD_MAX];
  if (lw_runfiles_stashed(dir))
    snprintf(err->msg + n, sizeof err->msg - n, "; a run there waits in %s/" LW_RUNFILES_STASH ", set aside by a run "
             "stopped as it started: 'linewise resume %s' puts it back", dir,
             lw_rundir_shell_word(dir, word, sizeof word));
}

/* A state an earlier release wrote that a later check refuses (since
** 2026-12-04 a segment too long for the pair cutoff, a line within the
** boundary's clearance): the message said to raise a key, which a resume
** cannot, and not why a run that ran cannot go on (an upgrading study's find). */
static void older_state_note(const lw_params *p, const char *dir, lw_error *err)
{
  char this_build[64], word[LW_RUNDIR_WORD_MAX];
  snprintf(this_build, sizeof this_build, "%s, build %s", LW_VERSION, lw_version_build());
  /* (without a clearance a boundary refusal is a line outside the frame,
  ** which no release let through) */
  if (err->code != LW_EINPUT || !p->run_header || !strcmp(p->run_build, this_build) ||
      (!strstr(err->msg, "too long for the pair cutoff") &&
       !(strstr(err->msg, "boundary energy is not finite") && p->boundary_clearance > 0.0)))
    return;
  const size_t n = strlen(err->msg);
  /* (a path that long would cut the message short of its end: DIR then) */
  if (strlen(lw_rundir_shell_word(dir, word, sizeof word)) > 256) snprintf(word, sizeof word, "DIR");
  snprintf(err->msg + n, sizeof err->msg - n, " (the run was begun by %s%s, which let this state through: it does "
           "not resume here ('linewise energy' measures it with that key changed by --set); a redraw of it is a "
           "new run, 'linewise run %s/scene.ini --set init.from=%s/state.lw "
           "--set anneal.sweeps=0' with that key set there too: docs/FORMATS.md, \"Runs of older releases\")",
           p->run_build[0] ? "linewise " : "an earlier linewise", p->run_build, word, word);
}

/* energy DIR [--set SEC.KEY=VAL]...: the state's energy with its scene, or
** with keys of it changed (the quadrature's nodes, to see what the run's
** leave out: docs/NUMERICS.md, "The potential between the nodes"). */
static int cmd_energy(int argc, char **argv)
{
  lw_error err;
  lw_error_clear(&err);
  const char *dir = NULL;
  for (int i = 0; i < argc; i++) {
    if (!strcmp(argv[i], "--set")) {
      i++;
      continue;
    }
    if (argv[i][0] == '-' || dir) {
      lw_error_set(&err, LW_EUSAGE, "energy: expected one run directory and --set options, got '%s' "
                   "(usage: linewise energy DIR [--set SEC.KEY=VAL]...)%s", argv[i], dash_hint(argv[i], NULL));
      return fail(&err);
    }
    dir = trim_slashes(argv[i]);
  }
  if (!dir) {
    lw_error_set(&err, LW_EUSAGE, "energy: expected one run directory (usage: linewise energy DIR "
                 "[--set SEC.KEY=VAL]...)");
    return fail(&err);
  }
  if (dir_fits("energy", dir, &err) ||
      run_dir_there("energy", dir, "(usage: linewise energy DIR [--set SEC.KEY=VAL]...)", &err))
    return fail(&err);
  static lw_params p;
  lw_state st;
  char path[LW_PATH_MAX + 32];
  if (load_run_dir(dir, &p, &st, path, sizeof path, &err)) {
    stash_note(&err, dir);
    return fail(&err);
  }
  /* the energy is of the scene as DIR/scene.ini reads now: an edit since the
  ** run started (which resume refuses) gave another energy without a word */
  static lw_run_keys keys;
  unsigned long long hash;
  lw_error edited;
  lw_error_clear(&edited);
  if (st.doc && lw_checkpoint_scene_hash(st.doc, &p, &keys, &hash, &edited) &&
      (strstr(edited.msg, "edited since") || strstr(edited.msg, "than when the run started"))) {
    char *why = strstr(edited.msg, ": a run resumes with");
    if (why) *why = '\0';
    fprintf(stderr, "linewise: note: %s; the energy below is of the scene as it reads now\n", edited.msg);
  }
  int set = 0;
  for (int i = 0; i < argc && !err.code; i++) {
    if (strcmp(argv[i], "--set")) continue;
    if (i + 1 >= argc) lw_error_set(&err, LW_EUSAGE, "--set: expected section.key=value");
    else if (set_later(argv, argc, i)) i++;
    else set = !set_option(&p, argv[++i], &err);
  }
  if (err.code || (set && (lw_params_resolve(&p, &err) || lw_anneal_check_keys(&p, NULL, 0, &err)))) {
    lw_state_clear(&st);
    return fail(&err);
  }
  const lw_system_type *t = lw_system_of(&p, &err);
  void *setup = t ? t->setup_new(&p, &err) : NULL;
  int rc = 0;
  double term[LW_SYSTEM_TERMS_MAX];
  /* the row refuses a state it cannot place and names a term that is not
  ** finite (for splines: the spline and segment) */
  double total = setup ? t->energy(setup, &st, path, term, &err) : NAN;
  /* the run's sections are read by resume, not here; an unknown one is
  ** refused all the same, as every reader of a state does (after the row,
  ** whose message names a state of another system better); format 1's run
  ** data, the upgrade's under resume, is no section of a newer linewise */
  if (!err.code && st.doc && st.version != 1) lw_checkpoint_sections_known(st.doc, p.system, &err);
  older_state_note(&p, dir, &err);
  if (err.code) rc = fail(&err);
  else {
    for (int k = 0; k < t->n_terms; k++)
      if (t->term_on(setup, k)) printf("%s %.17g\n", t->term_names[k], term[k]);
    printf("total %.17g\n", total);
  }
  if (setup) t->setup_free(setup);
  lw_state_clear(&st);
  return rc;
}

/* --set section.key=value.  A file named on the command line is named from
** the current directory, as by every other command; in a scene file it is
** named from the file's directory (lw_params_read), so a relative path given
** here is made absolute before the scene's directory can be joined to it. */
static lw_status set_option(lw_params *p, const char *assignment, lw_error *err)
{
  const char *dot = strchr(assignment, '.'), *eq = strchr(assignment, '=');
  char section[64], key[64], cwd[4096], abs[2 * LW_PATH_MAX];
  if (dot && eq && dot < eq && (size_t)(dot - assignment) < sizeof section && (size_t)(eq - dot - 1) < sizeof key) {
    snprintf(section, sizeof section, "%.*s", (int)(dot - assignment), assignment);
    snprintf(key, sizeof key, "%.*s", (int)(eq - dot - 1), dot + 1);
    const lw_param_def *d = lw_params_find(section, key);
    if (d && d->unit && !strcmp(d->unit, "path") && eq[1] && eq[1] != '/' && getcwd(cwd, sizeof cwd) &&
        snprintf(abs, sizeof abs, "%.*s%s/%s", (int)(eq + 1 - assignment), assignment, cwd, eq + 1) < (int)sizeof abs)
      return lw_params_set(p, abs, err);
  }
  return lw_params_set(p, assignment, err);
}

static volatile sig_atomic_t stop_requested = 0;

static volatile sig_atomic_t on_terminal = 0; /* stderr is one: say what a signal does, after a new line that
                                                 ** ends the line a phase or the bar holds */

/* What a second signal says, written before it can come: the handler may
** only write.  The run's directory is named once, before a checkpoint is
** (checkpointed); the sweep of the last one committed (phase.h) the handler
** writes itself. */
static char second_msg[LW_RUNDIR_WORD_MAX + 160];
static size_t second_len;

static void name_run_dir(const char *dir)
{
  char word[LW_RUNDIR_WORD_MAX];
  int n = snprintf(second_msg, sizeof second_msg, "\nlinewise: a second signal: stopped at once; 'linewise resume "
                   "%s' continues from ", lw_rundir_shell_word(dir, word, sizeof word));
  second_len = n > 0 && (size_t)n < sizeof second_msg ? (size_t)n : 0; /* (0: it did not fit: nothing is said) */
}

/* Appends n bytes of text to buf at *at, room allowing (in a handler). */
static void put_text(char *buf, size_t room, size_t *at, const char *text, size_t n)
{
  for (size_t i = 0; i < n && *at < room; i++) buf[(*at)++] = text[i];
}

/* Appends the digits of v >= 0 (in a handler: no stdio). */
static void put_number(char *buf, size_t room, size_t *at, long v)
{
  char digits[24];
  size_t n = 0;
  do digits[n++] = (char)('0' + v % 10); while ((v /= 10) > 0);
  while (n) put_text(buf, room, at, &digits[--n], 1);
}

/* The second signal's line for a run with a checkpoint (in a handler:
** no stdio). */
static void say_second(void)
{
  static const char of[] = "the checkpoint of sweep ", last[] = "the last checkpoint",
                    either[] = " (or of sweep ", came[] = ", whose write the signal came during)";
  char line[sizeof second_msg + 160];
  size_t at = 0;
  if (!second_len) return;
  const size_t skip = !on_terminal;
  put_text(line, sizeof line, &at, second_msg + skip, second_len - skip);
  long pending, sweep = lw_phase_last_commit(&pending);
  if (sweep >= 0) {
    put_text(line, sizeof line, &at, of, sizeof of - 1);
    put_number(line, sizeof line, &at, sweep);
  } else {
    put_text(line, sizeof line, &at, last, sizeof last - 1);
  }
  if (pending >= 0) { /* the rename was under way: either is on disk */
    put_text(line, sizeof line, &at, either, sizeof either - 1);
    put_number(line, sizeof line, &at, pending);
    put_text(line, sizeof line, &at, came, sizeof came - 1);
  }
  put_text(line, sizeof line, &at, "\n", 1);
  ssize_t w = write(2, line, at);
  (void)w;
}

/* A run that has written nothing (lw_phase_unwritten: its set-up, which can
** take minutes) ends at the first signal: there is nothing to save.  The
** default directory made for it, empty but for its lock, goes too. */
static char made_lock[LW_PATH_MAX + 16], made_dir[LW_PATH_MAX];
static volatile sig_atomic_t made_what = 0; /* 1 made_dir was made for the run, 3 "out" too */

/* Ends the process from a handler: on SIGINT by the signal itself, as a run
** stopped cleanly does (a shell goes on with a loop after a child that
** exits, even with 130, and stops it only after one SIGINT killed), else
** with 128 + the signal, as a shell shows it, and no core file (SIGXCPU's
** default makes one).  Under MPI mpirun reports an exit, not a signal. */
static void exit_by(int sig)
{
#ifndef LW_MPI
  if (sig == SIGINT) {
    sigset_t only;
    sigemptyset(&only);
    sigaddset(&only, SIGINT);
    signal(SIGINT, SIG_DFL);
    pthread_sigmask(SIG_UNBLOCK, &only, NULL); /* (a handler runs with its signal blocked) */
    raise(SIGINT);
  }
#endif
  _exit(128 + sig);
}

static void stop_unwritten(int sig)
{
  static const char msg[] = "\nlinewise: stopped during the set-up, before anything was written\n";
  if (!signal_quiet) {
    ssize_t w = write(2, msg + !on_terminal, sizeof msg - 1 - !on_terminal);
    (void)w;
  }
  if (made_what) {
    unlink(made_lock);
    rmdir(made_dir);
    if (made_what & 2) rmdir("out");
  }
  exit_by(sig);
}

/* A second signal before the run's first checkpoint leaves nothing to resume. */
static volatile sig_atomic_t checkpointed = 0;

/* The first signal asks for a clean stop after the sweep in progress; a
** second ends the process at once (a sweep can take minutes), leaving
** the last checkpoint, which state.lw always holds whole. */
static volatile sig_atomic_t finishing = 0; /* 1 the final files are being written, 2 they are
                                                 (lw_anneal.drawing) */
static volatile sig_atomic_t say_finishing = 0; /* and a signal then says so (not --quiet) */

static void on_signal(int sig)
{
  static const char first[] = "\nlinewise: stopping after the sweep in progress (a second Ctrl-C stops at once)\n";
  /* nothing would answer a signal then until the files are written, which
  ** can take minutes on a large drawing: say so, terminal or log */
  static const char last[] = "\nlinewise: writing the final files first (a second signal stops at once, without "
                             "them)\n";
  static const char back[] = "\nlinewise: stopping; the run that was in the directory comes back (a second Ctrl-C "
                             "stops at once)\n";
  const int files = finishing == 1 && say_finishing;
  if (finishing == 2) return; /* the run is whole, summary.json too: it ends as it would have */
  /* past the soft CPU limit the kernel sends it again every CPU second: not
  ** a second signal, which would stop at once */
  if (sig == SIGXCPU && stop_requested) return;
  const int second = stop_requested != 0;
  if (!second && lw_phase_unwritten()) stop_unwritten(sig);
  /* the stop is set before the stash's mark is read: the first checkpoint
  ** marks itself before it reads the stop (checkpoint.c, gives_way), so
  ** one sees the other, and "comes back" is said only where it does */
  if (!second) {
    stop_requested = sig;
    lw_phase_stop();
  }
#ifdef LW_MPI
  const int gives_way = 0; /* (a spread run's processes stop together, at a sweep) */
#else
  const int gives_way = lw_phase_stashed() == 1 || lw_phase_stashed() == 3;
#endif
  if (!second && (files || on_terminal)) {
    ssize_t w = files       ? write(2, last + !on_terminal, sizeof last - 1 - !on_terminal)
                : gives_way ? write(2, back + !on_terminal, sizeof back - 1 - !on_terminal)
                            : write(2, first + !on_terminal, sizeof first - 1 - !on_terminal);
    (void)w;
  }
  if (second) {
    static const char none[] = "\nlinewise: a second signal: stopped at once, before the run's first checkpoint "
                               "(nothing to resume: run it again)\n";
    static const char kept[] = "\nlinewise: a second signal: stopped at once, before the run's first checkpoint; "
                               "the run that was in the directory waits in " LW_RUNFILES_STASH " and comes back "
                               "when linewise next runs or resumes there\n";
    static const char part[] = "\nlinewise: a second signal: stopped at once as the run's first checkpoint was "
                               "written; linewise's next run or resume there goes on from it, or, where it was not "
                               "written, puts the run that was in the directory back\n";
    static const char back_half[] = "\nlinewise: a second signal: stopped at once as the run that was in the "
                                    "directory was being put back; linewise's next run or resume there puts the "
                                    "rest of it back, or, where the put-back had not begun, goes on from this "
                                    "run's checkpoint\n";
    const int stash = lw_phase_stashed();
    /* (a first checkpoint committed within the set-up counts: "nothing to
    ** resume" was said beside a state.lw that resumed; while the run before
    ** comes back the checkpoint said is going) */
    if (stash == 4) {
      ssize_t w = write(2, back_half + !on_terminal, sizeof back_half - 1 - !on_terminal);
      (void)w;
    } else if (checkpointed || lw_phase_last_commit(NULL) >= 0) {
      say_second();
    } else {
      ssize_t w = stash == 1 ? write(2, kept + !on_terminal, sizeof kept - 1 - !on_terminal)
                  : stash == 2 ? write(2, part + !on_terminal, sizeof part - 1 - !on_terminal)
                               : write(2, none + !on_terminal, sizeof none - 1 - !on_terminal);
      (void)w;
    }
    exit_by(sig);
  }
}

/* Progress on stderr: a bar redrawn in place on a terminal, one plain line
** per tenth of the run otherwise (and every PLAIN_SECONDS at least: a job
** of ten hours said nothing for its first), nothing with --quiet. */
#define PLAIN_SECONDS 600.0
/* The time left is taken at the rate of the recent sweeps, between the
** marks: a job suspended for an hour early on (SIGSTOP, a batch system)
** read hours left to its end at the rate of all its sweeps. */
#define MARK_SECONDS 30.0
typedef struct {
  int quiet, tty;
  long start_sweep, next_plain, last_plain;
  double plain_t;    /* when the last plain line was shown */
  double mark_t[2];  /* the older and the newer mark: clock and sweep, from the
                     ** first sweep's start (a large picture's decoding, the
                     ** placement, is not a sweep's cost) */
  long mark_sweep[2];
} progress;

static void progress_init(progress *pg, int quiet, const lw_anneal *a)
{
  const double t = lw_anneal_seconds(a);
  *pg = (progress){quiet, isatty(2), a->sweep, a->sweep, -1, t, {t, t}, {a->sweep, a->sweep}};
}

/* The seconds left at the recent rate: since the older mark, which moves up
** to the newer one (and that to now) where `move` says (a bar: every
** MARK_SECONDS; plain lines: at each, so that the rate is the last line's
** stretch), at the whole run's before the marks have moved. */
static double progress_left(progress *pg, const lw_anneal *a, double t, int move)
{
  if (move) {
    pg->mark_t[0] = pg->mark_t[1], pg->mark_sweep[0] = pg->mark_sweep[1];
    pg->mark_t[1] = t, pg->mark_sweep[1] = a->sweep;
  }
  const long done = a->sweep - pg->mark_sweep[0];
  return done > 0 ? (t - pg->mark_t[0]) / (double)done * (double)(a->end_sweep - a->sweep) : 0.0;
}

/* What moves: the temperature and acceptance of the chain, or the clock
** and kinetic energy of the dynamics. */
static void progress_state(const lw_anneal *a, int digits, char *buf, size_t n)
{
  if (a->dyn)
    snprintf(buf, n, "t %.*g  E %.*g  K %.*g", digits, a->dyn->time, digits + 2, lw_anneal_energy(a), digits,
             lw_dynamics_kinetic(a->dyn));
  else if (isnan(lw_anneal_temperature(a))) /* before the first sweep sets it */
    snprintf(buf, n, "T -  E %.*g  acc -", digits + 2, lw_anneal_energy(a));
  else if (isnan(lw_anneal_acceptance(a)))
    snprintf(buf, n, "T %.*g  E %.*g  acc -", digits, lw_anneal_temperature(a), digits + 2, lw_anneal_energy(a));
  else
    snprintf(buf, n, "T %.*g  E %.*g  acc %.*f", digits, lw_anneal_temperature(a), digits + 2, lw_anneal_energy(a),
             digits - 1, lw_anneal_acceptance(a));
}

/* A time in seconds, or h:mm:ss from an hour on (a run of days read
** "left 259200s"). */
static const char *duration_text(double s, int decimals, char *buf, size_t n)
{
  if (!(s >= 3599.5)) snprintf(buf, n, "%.*fs", decimals, s); /* (3599.7 read "3600s") */
  else {
    const long t = lround(s);
    snprintf(buf, n, "%ld:%02ld:%02ld", t / 3600, t / 60 % 60, t % 60);
  }
  return buf;
}

static void progress_show(progress *pg, const lw_anneal *a, int final)
{
  if (pg->quiet) return;
  double t = lw_anneal_seconds(a);
  long done = a->sweep - pg->start_sweep, total = a->end_sweep - pg->start_sweep;
  if (pg->tty) {
    static double shown = -1;
    if (!final && t - shown < 0.2) return;
    shown = t;
    const double left = progress_left(pg, a, t, t - pg->mark_t[1] >= MARK_SECONDS);
    char state[160];
    progress_state(a, 4, state, sizeof state);
    char rest[32] = "-"; /* unknown before a sweep has taken its time */
    if (done > 0 || a->sweep >= a->end_sweep) duration_text(left, 0, rest, sizeof rest);
    char text[224];
    int len = snprintf(text, sizeof text, "sweep %ld/%ld  %s  left %s ", a->sweep, a->end_sweep, state, rest);
    /* a line longer than the terminal wraps, and each redraw then starts a
    ** new one: the bar narrows (to 8 marks) to fit, else goes, then the end
    ** of the line */
    struct winsize ws;
    const int cols = ioctl(2, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 ? ws.ws_col : 80;
    int width = cols - 1 - len - 3;
    width = width > 24 ? 24 : (width < 8 ? 0 : width);
    char line[256];
    int bar = 0;
    if (width) {
      const int fill = total > 0 ? (int)(width * done / total) : width;
      bar = snprintf(line, sizeof line, "[%.*s%*s] ", fill, "########################", width - fill, "");
    }
    snprintf(line + bar, sizeof line - (size_t)bar, "%s", text);
    len += bar;
    if (len > cols - 1) len = cols - 1 > 0 ? cols - 1 : 0;
    /* spaces over what a longer line before left */
    static int shown_len;
    fprintf(stderr, "\r%.*s%*s", len, line, shown_len > len ? shown_len - len : 0, "");
    shown_len = len;
    if (final) fputc('\n', stderr);
  } else if ((final && a->sweep != pg->last_plain) || a->sweep >= pg->next_plain ||
             (a->sweep != pg->last_plain && t - pg->plain_t >= PLAIN_SECONDS)) {
    pg->last_plain = a->sweep;
    pg->plain_t = t;
    const double left = progress_left(pg, a, t, 1);
    char state[160];
    progress_state(a, 6, state, sizeof state);
    char rest[32] = "-";
    if (done > 0 || a->sweep >= a->end_sweep) duration_text(left, 1, rest, sizeof rest);
    char elapsed[32];
    fprintf(stderr, "sweep %ld/%ld %s elapsed %s left %s\n", a->sweep, a->end_sweep, state,
            duration_text(t, 1, elapsed, sizeof elapsed), rest);
    while (pg->next_plain <= a->sweep) pg->next_plain += total / 10 > 0 ? total / 10 : 1;
  }
}

/* A watcher thread for the phases outside the sweeps (phase.h): one that
** lasts over a second is named while it runs, and again with its time when
** it ends, so a large scene's set-up and output never leave the terminal
** silent.  It only reads the phase and writes stderr. */
typedef struct {
  pthread_t thread;
  pthread_mutex_t lock; /* one tick at a time: the thread's or watcher_settle's */
  lw_phase_watch pw;
  int running, tty;
  atomic_int stop;
} watcher;

static void watcher_tick(watcher *w)
{
  char line[512];
  double t;
  pthread_mutex_lock(&w->lock);
  const char *what = lw_phase_get(&t);
  fputs(lw_phase_watch_tick(&w->pw, what, t, line, sizeof line), stderr);
  pthread_mutex_unlock(&w->lock);
}

static void *watch(void *arg)
{
  watcher *w = arg;
  char line[512];
  const struct timespec tick = {0, 100000000};
  while (!atomic_load(&w->stop)) {
    nanosleep(&tick, NULL);
    watcher_tick(w);
  }
  fputs(lw_phase_watch_end(&w->pw, atomic_load(&w->stop) - 1, line, sizeof line), stderr);
  return NULL;
}

static void watcher_start(watcher *w, int quiet)
{
  w->running = 0;
  w->tty = isatty(2);
  w->pw = (lw_phase_watch){.tty = w->tty};
  atomic_init(&w->stop, 0);
  if (!quiet && !pthread_mutex_init(&w->lock, NULL)) {
    w->running = pthread_create(&w->thread, NULL, watch, w) == 0;
    if (!w->running) pthread_mutex_destroy(&w->lock);
  }
}

/* The set-up's last phase has its line ("done in") before the run's header,
** which the thread's next tick would have printed after it. */
static void watcher_settle(watcher *w)
{
  if (w->running) watcher_tick(w);
}

/* how (LW_PHASE_*): how the phase shown last ended (an error is reported next). */
static void watcher_stop(watcher *w, int how)
{
  if (!w->running) return;
  atomic_store(&w->stop, how + 1);
  pthread_join(w->thread, NULL);
  pthread_mutex_destroy(&w->lock);
  w->running = 0;
}

/* The loop shared by run and resume: sweeps until done or a signal, then
** the final files (or a checkpoint for a clean stop). */
static int watched_fail(watcher *w, const lw_error *err)
{
  watcher_stop(w, LW_PHASE_FAILED);
  return fail(err);
}

/* The next item at *p of a libraries list ("name version, ..."), blanks
** about its parts aside: 0 past the last. */
typedef struct {
  const char *name, *version;
  int name_len, version_len;
} library_item;

static int next_library(const char **p, library_item *it)
{
  const char *s = *p + strspn(*p, " ,");
  if (!*s) return 0;
  int len = (int)strcspn(s, ",");
  *p = s + len;
  while (len && s[len - 1] == ' ') len--;
  it->name = s;
  it->name_len = (int)strcspn(s, " ");
  if (it->name_len > len) it->name_len = len;
  it->version = s + it->name_len + strspn(s + it->name_len, " ");
  it->version_len = (int)(s + len - it->version);
  if (it->version_len < 0) it->version_len = 0;
  return 1;
}

/* The libraries of both lists whose versions differ, as "cairo 1.14.0 then,
** 1.16.0 now"; 0 where none does.  One only a list names is not said: a
** release that records another library would say it of every older run. */
static int libraries_changed(const char *there, const char *here, char *buf, size_t n)
{
  int changed = 0;
  size_t used = 0;
  buf[0] = '\0';
  library_item h, t;
  for (const char *ph = here; next_library(&ph, &h);) {
    int found = 0;
    for (const char *pt = there; !found && next_library(&pt, &t);)
      found = t.name_len == h.name_len && !strncmp(t.name, h.name, (size_t)h.name_len);
    if (!found || (t.version_len == h.version_len && !strncmp(t.version, h.version, (size_t)h.version_len)))
      continue;
    if (used < n)
      used += (size_t)snprintf(buf + used, n - used, "%s%.*s %.*s then, %.*s now", changed ? "; " : "", h.name_len,
                               h.name, t.version_len ? t.version_len : 1, t.version_len ? t.version : "?",
                               h.version_len, h.version);
    changed++;
  }
  return changed;
}

/* The run set aside could not all be removed once this one replaced it:
** said under --quiet too (what is left takes disk space, and the next run or
** resume there tries again). */
static void say_stash_left(lw_anneal *a)
{
  if (a->stash_left[0]) fprintf(stderr, "linewise: warning: %s\n", a->stash_left);
  a->stash_left[0] = 0;
}

/* A --stop-at past the run's end stops nothing: the run finishes (a loop
** that asked for sweep 250 of 200 got a finished run, unsaid). */
static void say_stop_past_end(const lw_anneal *a, long stop_at, int quiet)
{
  if (!quiet && stop_at > a->end_sweep)
    fprintf(stderr, "linewise: note: --stop-at %ld is past the run's end at sweep %ld: it runs to its end and "
            "finishes ('resume --sweeps N' runs past an end)\n", stop_at, a->end_sweep);
}

/* Frames that will fill the disk: said under --quiet too, as the failure
** it foretells would be (the process that draws them says it). */
static void say_frames_disk(const lw_anneal *a, int quiet)
{
  char note[LW_PATH_MAX + 256];
  int warning;
  lw_anneal_frames_disk_note(a, note, sizeof note, &warning);
  if (note[0] && (warning || !quiet)) fprintf(stderr, "linewise: %s: %s\n", warning ? "warning" : "note", note);
}

/* libgomp ends the process (exit 1, "libgomp: Thread creation failed") where
** it cannot start a team's threads, which may first happen after the set-up
** (a team larger than the last: libgomp lets the threads a smaller team left
** idle go): the run set aside then comes back too, as after a failure
** linewise catches.  It took a finished drawing with it (an address-space
** limit and eight threads).  Later, the checkpoint a resume takes up is
** named, as after any failure.  A no-op after lw_anneal_free (a run that
** ended, or failed in linewise's own words). */
static lw_anneal *run_going;

static void run_ended_at_exit(void)
{
  lw_anneal *a = run_going;
  run_going = NULL;
  if (!a || !a->dir[0]) return;
  char word[LW_RUNDIR_WORD_MAX];
  lw_rundir_shell_word(a->dir, word, sizeof word);
  if (a->stashed) {
    if (lw_anneal_undo_start(a))
      fprintf(stderr, "linewise: the process ended before the run's first sweep was done; the run that was in %s is "
              "back as it was\n", word);
    return;
  }
  const long at = lw_phase_last_commit(NULL);
  if (at >= 0)
    fprintf(stderr, "linewise: the process ended at sweep %ld; %s/state.lw holds the checkpoint of sweep %ld "
            "('linewise resume %s' continues)\n", a->sweep, a->dir, at, word);
}

/* A run that failed to write (a full disk) says that state.lw still holds
** its last checkpoint, and how to go on: the last this process wrote, or
** the one the loop began from (the set-up's, or the one a resume read). */
static int loop_fail(lw_anneal *a, long began, watcher *w, lw_error *err)
{
  /* a run that failed before its first sweep was done gives the directory
  ** back to the run it was to replace (anneal.c, drop_stash) */
  if (a->stashed) {
    const size_t n = strlen(err->msg);
    char word[LW_RUNDIR_WORD_MAX];
    lw_rundir_shell_word(a->dir, word, sizeof word);
    if (lw_anneal_undo_start(a)) snprintf(err->msg + n, sizeof err->msg - n, "; the run that was in %s is back "
                                          "as it was", word);
    else snprintf(err->msg + n, sizeof err->msg - n, "; the run that was in %s did not all come back: what is "
                  "left of it is in %s/" LW_RUNFILES_STASH, word, word);
    return watched_fail(w, err);
  }
  /* memory too: the drawing's joins can run out after hours of sweeps; not
  ** where the directory itself went (removed during the run) */
  char state[LW_PATH_MAX + 16];
  snprintf(state, sizeof state, "%s/state.lw", a->dir);
  if (a->undone) { /* (its own checkpoint, not one removed by another) */
    size_t n = strlen(err->msg);
    snprintf(err->msg + n, sizeof err->msg - n, "; the run's first files are removed, as it had done no sweep: run "
             "it again once %s", err->code == LW_ENOMEM ? "there is more memory" : "the files can be written");
  } else if (err->code == LW_EIO && a->dir_moved) {
    size_t n = strlen(err->msg);
    snprintf(err->msg + n, sizeof err->msg - n, ", so the run ends (moved, it resumes from its last checkpoint where "
             "it is now)");
  } else if (err->code == LW_EIO && access(state, F_OK)) {
    size_t n = strlen(err->msg);
    snprintf(err->msg + n, sizeof err->msg - n, "; %s is no longer there: the run's directory was removed or moved, "
             "so the run ends (moved, it resumes from its last checkpoint where it is now)", state);
  } else if (err->code == LW_EIO || err->code == LW_ENOMEM) {
    size_t n = strlen(err->msg);
    char word[LW_RUNDIR_WORD_MAX];
    /* (state.lw is committed before the replicas' files: one of those that
    ** failed left the newer checkpoint, which the message named the older) */
    const long at = a->saved > 0 ? a->saved - 1 : began, committed = lw_phase_last_commit(NULL);
    snprintf(err->msg + n, sizeof err->msg - n, "; %s/state.lw holds the checkpoint of sweep %ld: 'linewise "
             "resume %s' continues from it once %s", a->dir, committed > at ? committed : at,
             lw_rundir_shell_word(a->dir, word, sizeof word),
             err->code == LW_EIO ? "the files can be written" : "there is more memory");
  }
  return watched_fail(w, err);
}

/* quiet: nothing on stderr but errors (--quiet, or a process of an MPI run
** other than the first); asked: --quiet itself.  The process that draws
** tells what it drew unless --quiet, whichever it is. */
static int anneal_loop(lw_anneal *a, long stop_at, int quiet, int asked, watcher *w, lw_error *err)
{
  a->stop = &stop_requested;
  progress pg;
  progress_init(&pg, quiet, a);
  /* a signal during start-up stops before the first sweep; the processes
  ** of an MPI run stop together, at the sweep where one of them was asked */
  int stopped = ((net ? net->stop_agreed : stop_requested) || (stop_at >= 0 && a->sweep >= stop_at)) &&
                !lw_anneal_done(a);
  while (!stopped && !lw_anneal_done(a)) {
    if (lw_anneal_sweep(a, err)) return loop_fail(a, pg.start_sweep, w, err);
    say_stash_left(a);
    progress_show(&pg, a, 0);
    stopped = (net ? net->stop_agreed : stop_requested) || (stop_at >= 0 && a->sweep >= stop_at);
  }
  progress_show(&pg, a, 1);
#ifdef LW_MPI
  lw_mpi_report(net, a, quiet);
#endif
  /* a signal before the new run's first sweep is done makes it give way, as
  ** one in its set-up does: the run it was to replace comes back (stopped
  ** "after sweep 0" or 1, the new run took that run's place, unsaid, where
  ** the README promised it back until the first sweep; a Ctrl-C just after
  ** starting a large scene into a directory by mistake cost the run there) */
  if (stopped && stop_requested && a->stashed && !net) {
    lw_phase_stash(4);
    if (!lw_anneal_undo_start(a)) {
      lw_error_set(err, LW_ERUN, "%s: stopped before the first sweep, and the run that was there waits in %s/"
                   LW_RUNFILES_STASH " (linewise puts it back when it next runs or resumes there)", a->dir, a->dir);
      return watched_fail(w, err);
    }
    lw_phase_stash(0);
    watcher_stop(w, LW_PHASE_STOPPED);
    fprintf(stderr, "linewise: stopped before the first sweep; the run that was in %s is back as it was\n", a->dir);
    return stop_requested != SIGINT ? 128 + stop_requested : 0; /* (SIGINT by itself, in main) */
  }
  /* the checkpoint of the end (lw_anneal_finish's first step) is written
  ** here, so that a second signal while the files are drawn names it */
  /* (a stop with the run before still aside, a --stop-at before the first
  ** sweep: its checkpoint drops that run, which an end keeps until its files
  ** are drawn) */
  if ((a->saved != a->sweep + 1 || (stopped && a->stashed)) && lw_anneal_checkpoint(a, err))
    return loop_fail(a, pg.start_sweep, w, err);
  say_stash_left(a);
  if (stopped) {
    watcher_stop(w, LW_PHASE_DONE);
    char mpi[LW_RUNDIR_WORD_MAX + 96] = "", word[LW_RUNDIR_WORD_MAX];
    lw_rundir_shell_word(a->dir, word, sizeof word);
    if (net && net->size > 1)
      snprintf(mpi, sizeof mpi, ", on one process, or over MPI as 'mpirun -n P linewise-mpi resume %s'", word);
    /* a log of --quiet runs must tell one a signal stopped too (under MPI
    ** the first process says it, whichever process the signal reached) */
    if (!quiet || (asked && (net ? net->stop_agreed && !net->rank : stop_requested)))
      fprintf(stderr, "linewise: stopped after sweep %ld%s; state saved in %s/state.lw ('linewise resume %s' "
              "continues%s)\n", a->sweep, stop_requested == SIGXCPU ? " (the soft CPU-time limit)" : "", a->dir,
              word, mpi);
    return 0;
  }
  say_finishing = !quiet;
  a->drawing = &finishing;
  lw_status s = lw_anneal_finish(a, err);
#ifdef LW_MPI
  /* only the process of the coldest replica drew and quenched it */
  int drew = !net || lw_anneal_net_owner(a->pt ? a->pt->at[0] : 0, a->n_rep, net->size) == net->rank;
  if (net) s = lw_mpi_agree(net, s, err);
#else
  int drew = 1;
#endif
  if (s) return loop_fail(a, pg.start_sweep, w, err);
  say_stash_left(a);
  watcher_stop(w, a->quench.ended == LW_QUENCH_STOPPED ? LW_PHASE_STOPPED : LW_PHASE_DONE);
  if (a->quench.ended == LW_QUENCH_STOPPED) {
    char word[LW_RUNDIR_WORD_MAX];
    if (!quiet || (asked && (net ? !net->rank : 1)))
      fprintf(stderr, "linewise: stopped during the quench (nothing drawn); state saved in %s/state.lw ('linewise resume "
              "%s' quenches again)\n", a->dir, lw_rundir_shell_word(a->dir, word, sizeof word));
    return 0;
  }
  if (drew && !asked) {
    char drawn[4096]; /* up to two lines a pen of a drawing of 16 (LW_PLOT_PENS_MAX) */
    a->sys_type->describe(a->sys->state, LW_DESCRIBE_DRAWING, drawn, sizeof drawn);
    fprintf(stderr, "%s", drawn);
    lw_anneal_tuning_note(a, drawn, sizeof drawn);
    if (drawn[0]) fprintf(stderr, "linewise: note: %s\n", drawn);
    lw_anneal_ladder_note(a, drawn, sizeof drawn);
    if (drawn[0]) fprintf(stderr, "linewise: note: %s\n", drawn);
    lw_anneal_checkpoint_note(a, drawn, sizeof drawn);
    if (drawn[0]) fprintf(stderr, "linewise: note: %s\n", drawn);
    lw_anneal_frames_note(a, drawn, sizeof drawn);
    if (drawn[0]) fprintf(stderr, "linewise: note: %s\n", drawn);
    lw_anneal_film_note(a, drawn, sizeof drawn);
    if (drawn[0]) fprintf(stderr, "linewise: note: %s\n", drawn);
  }
  /* the warnings, of numbers the run got wrong or left out, under --quiet
  ** too: a study's script reads its log (its statistics went null unsaid) */
  if (drew) {
    char warning[1024];
    lw_anneal_drift_note(a, warning, sizeof warning);
    if (warning[0]) fprintf(stderr, "linewise: warning: %s\n", warning);
    lw_anneal_observables_note(a, warning, sizeof warning);
    if (warning[0]) fprintf(stderr, "linewise: warning: %s\n", warning);
    if (a->dyn) {
      lw_dynamics_rise_note(a->dyn, warning, sizeof warning);
      if (warning[0]) fprintf(stderr, "linewise: warning: %s\n", warning);
    }
    a->sys_type->describe(a->sys->state, LW_DESCRIBE_LOST, warning, sizeof warning);
    if (warning[0]) fprintf(stderr, "linewise: warning: %s\n", warning);
  }
  if (!quiet) {
    if (a->quenched)
      fprintf(stderr, "linewise: quench: energy %.10g -> %.10g, gradient norm %.3g -> %.3g, %ld iterations (%s), %.2f s\n",
              a->quench.energy_before, a->quench.energy_after, a->quench.gradient_before, a->quench.gradient_after,
              a->quench.iterations, lw_quench_end_name(a->quench.ended), a->quench.seconds);
    /* the plotter's files beside the system's own, where the drawing wrote
    ** them (whichever process drew it; a run removes those of the run before) */
    static const char *const extra[] = {"final.pdf", "final.hpgl", "final.gcode"};
    char files[96] = "", path[LW_PATH_MAX + 16];
    for (int k = 0; k < 3; k++) {
      lw_path_join(path, sizeof path, a->dir, extra[k]);
      if (!access(path, F_OK)) snprintf(files + strlen(files), sizeof files - strlen(files), ", %s", extra[k]);
    }
    /* (the film and the samples, which a user looked for by the docs) */
    if (a->params.frames_every) snprintf(files + strlen(files), sizeof files - strlen(files), ", frames/");
    if (a->params.samples_every) snprintf(files + strlen(files), sizeof files - strlen(files), ", samples/");
    fprintf(stderr, "linewise: done: %s/%s%s, summary.json, trace.csv, state.lw\n", a->dir, a->sys_type->files, files);
  }
  return 0;
}

/* Whether arg is an option of some command that takes the next argument
** as its value: what "--" and the threads asked skip over. */
static int takes_value(const char *arg)
{
  static const char *const valued[] = {"--set",   "--out",  "--seed", "--stop-at", "--threads",
                                       "--sweeps", "--from", "--to",   "--reweight"};
  for (size_t k = 0; k < sizeof valued / sizeof *valued; k++)
    if (!strcmp(arg, valued[k])) return 1;
  return 0;
}

/* A count on the command line from lo to max, read by the parser of scene
** keys ("1.000" refused as --set refuses it: a thousand in a comma locale);
** sweep counts stop at 1e15, so sweep + count cannot overflow. */
static int parse_count(const char *opt, const char *v, double lo, double max, long *out, lw_error *err)
{
  long long n;
  char hint[96] = "";
  if (!v || lw_number_separator_hint(v, 1, hint, sizeof hint) || !lw_number_parse_whole(v, lo, max, &n)) {
    if (v && !hint[0]) lw_text_unseen_char(v, hint, sizeof hint); /* a minus sign U+2212, a full-width digit */
    lw_error_set(err, LW_EUSAGE, "%s: expected a whole number from %.0f to %.0f, got '%s'%s", opt, lo, max, v ? v : "",
                 hint);
    return 0;
  }
  *out = (long)n;
  return 1;
}

/* --threads N: OpenMP threads for the tempering replicas and the domains.
** Results never depend on it (each rung and cell has its own stream). */
static int set_threads(const char *v, lw_error *err)
{
  long t;
  if (!parse_count("--threads", v, 1, 4096, &t, err)) return 0;
  omp_set_num_threads((int)t);
  return 1;
}

/* The options run and resume share (--stop-at, --threads, --quiet): how
** many arguments the one at argv[i] takes (1 or 2), 0 if it is not one of
** them, -1 on bad input (err set). */
static int shared_option(char **argv, int argc, int i, long *stop_at, int *quiet, lw_error *err)
{
  const char *v = i + 1 < argc ? argv[i + 1] : NULL;
  if (!strcmp(argv[i], "--stop-at")) return parse_count("--stop-at", v, 0, LW_STATE_SWEEP_MAX, stop_at, err) ? 2 : -1;
  if (!strcmp(argv[i], "--threads")) return set_threads(v, err) ? 2 : -1;
  if (!strcmp(argv[i], "--quiet")) {
    *quiet = 1;
    return 1;
  }
  return 0;
}

/* An MPI run: the processes agree that all of them started (or take the
** first one's failure), then write the first checkpoint together. */
static lw_status spread_start(lw_status s, lw_anneal *a, int fresh, lw_error *err)
{
#ifdef LW_MPI
  if (!net) return s;
  if ((s = lw_mpi_agree(net, s, err))) return s;
  started = 1;
  /* every process holds every replica as placed or read, so the totals a
  ** run with no sweep left reads (its summary) are known before any share() */
  for (int r = 0; r < a->n_rep; r++) net->energy[r] = lw_system_total(a->systems[r]);
  if (fresh) s = lw_anneal_checkpoint(a, err);
#endif
  return s;
}

/* The default run directory: out/<scene name>, or out/<scene name>-2, -3,
** ... : the first that holds no run (nor a person's scene.ini or state.lw)
** and that no other process is writing, made and locked (rundir.h) before
** the run is set up, so that runs
** started together without --out each get their own, and none replaces
** the drawing of another (--out names a directory to replace).  *made: 1
** the directory is new, 2 out/ too (taken away again if the run is
** refused).  Where the directory cannot be made here (a read-only
** checkout), the first name without a run is taken unmade, and the run says
** why once its scene is known to be good.  Under MPI process 0 chooses and
** holds the lock, and tells the others. */
/* Whether dir holds a run with a checkpoint, or a scene.ini or state.lw of
** a person's, which a run would refuse to write over.  A run stopped before
** its first checkpoint has nothing to resume: its directory is taken again
** (unless the lock says it is still setting up). */
/* (a stash is a run that a killed set-up set aside: runfiles.h) */
static int taken(const char *dir)
{
  return (lw_rundir_holds_run(dir) && !lw_rundir_unstarted(dir)) || lw_rundir_foreign(dir, "scene.ini") ||
         lw_rundir_foreign(dir, "state.lw") || lw_runfiles_check_free(dir, NULL) || lw_runfiles_stashed(dir);
}

/* The run's name, out/<name>: the scene file's name without its leading
** dots and extension (*base, its length returned): "cat.v2.ini" is not
** "cat.v1.ini"'s out/cat-2, and ".ini" (nothing before its dot) wrote into
** out/ itself; "scene" where nothing is left ("...").  A file named
** scene.ini, as a run's, takes its folder's name: a redraw of
** out/mine/scene.ini went to out/scene, where its user did not look. */
static int scene_name(const char *scene, const char **base)
{
  const char *b = strrchr(scene, '/') ? strrchr(scene, '/') + 1 : scene;
  if (!strcmp(b, "scene.ini") && b - scene >= 2 && b[-2] != '/' && b[-2] != '.') {
    const char *folder = b - 1; /* the slash before scene.ini */
    while (folder > scene && folder[-1] != '/') folder--;
    folder += strspn(folder, "."); /* (.hidden/scene.ini: out/hidden) */
    if (folder < b - 1) {
      *base = folder;
      return (int)(b - 1 - folder);
    }
  }
  b += strspn(b, "."); /* a hidden file's dot is no extension: .hidden is out/hidden */
  const char *ext = strrchr(b, '.');
  int n = ext ? (int)(ext - b) : (int)strlen(b);
  if (!n) {
    b = "scene";
    n = 5;
  }
  *base = b;
  return n;
}

static lw_status default_dir(char *dir, size_t size, const char *scene, int *hold, int *made, lw_error *err)
{
  const char *base;
  const int n = scene_name(scene, &base);
  *hold = *made = 0;
  lw_status s = LW_OK;
#ifdef LW_MPI
  if (!net || !net->rank)
#endif
  {
    const int out_existed = access("out", F_OK) == 0;
    snprintf(dir, size, "out/%.*s", n, base);
    for (int k = 2;; k++) {
      const int existed = access(dir, F_OK) == 0;
      if (!existed || !taken(dir)) {
        lw_error e2;
        if (lw_rundir_make(dir, &e2)) break; /* taken unmade */
        s = lw_rundir_lock(dir, hold, err);
        if (s && s != LW_EUSAGE) break; /* LW_EUSAGE: another run's */
        if (!s && !taken(dir)) {
          *made = existed ? 0 : out_existed ? 1 : 3;
          break;
        }
        s = LW_OK;
        lw_rundir_unlock(*hold);
        *hold = 0;
      }
      if (k > 1000000) {
        s = lw_error_set(err, LW_EUSAGE, "out/%.*s: a million runs there already; give --out", n, base);
        break;
      }
      snprintf(dir, size, "out/%.*s-%d", n, base, k);
    }
  }
#ifdef LW_MPI
  if (net && !(s = lw_mpi_agree(net, s, err))) lw_mpi_share_text(net, dir, size);
#endif
  return s;
}

/* What default_dir made for a run that was then refused goes again, its
** lock too: "nothing is written" for bad input. */
static void unmake_dir(const char *dir, int hold, int made)
{
  if ((!hold && !made) || lw_rundir_holds_run(dir)) return;
  if (hold && !lw_rundir_held_here(dir, hold)) { /* (moved aside: what is there now is another's) */
    lw_rundir_unlock(hold);
    return;
  }
  char path[LW_PATH_MAX + 16];
  lw_path_join(path, sizeof path, dir, ".lock"); /* (made without locks, its file is there all the same) */
  unlink(path);
  if (made) rmdir(dir);
  if (made & 2) rmdir("out");
  lw_rundir_unlock(hold);
}

/* The --out directory locked for this run before its set-up, made first
** where its parent is there (*made 1): locked only as the run started, a
** second run into it during a set-up of seconds finished, and then the first
** took the directory and wrote over that result, both exiting 0.  A path of
** several new folders is made as the run starts, as before.  A directory
** that cannot be made is said now, not after the set-up; one that another
** run made and removed again as this one came (a signal in its set-up) is
** made again. */
static lw_status claim_out(const char *dir, int *hold, int *made, lw_error *err)
{
  for (int tries = 0;; tries++) {
    *made = 0;
    if (access(dir, F_OK)) {
      char parent[LW_PATH_MAX];
      lw_path_dir(parent, sizeof parent, dir);
      if (access(parent, F_OK)) return LW_OK;
      if (mkdir(dir, 0777)) {
        if (errno == EEXIST && !access(dir, F_OK)) continue; /* (made meanwhile by another) */
        return lw_rundir_make(dir, err); /* (its message: a link to nowhere, a read-only place) */
      }
      *made = 1;
    }
    lw_status s = lw_rundir_lock(dir, hold, err);
    /* (a directory this run made but another locked meanwhile is theirs) */
    if (s && *made && !access(dir, F_OK)) *made = 0;
    if (!s || !access(dir, F_OK) || tries == 4) return s;
  }
}

static int cmd_run(int argc, char **argv)
{
  lw_error err;
  lw_error_clear(&err);
  const char *scene = NULL, *out = NULL;
  long stop_at = -1, seed = -1;
  int quiet = 0, scene_split = 0;
  static lw_params p;
  /* the scene file first, so --set applies on top of it whatever the order */
  for (int i = 0; i < argc; i++) {
    /* run's own options with a value (takes_value has every command's: here
    ** another's, --sweeps say, is refused below as run's unknown option) */
    if (!strcmp(argv[i], "--set") || !strcmp(argv[i], "--out") || !strcmp(argv[i], "--seed") ||
        !strcmp(argv[i], "--stop-at") || !strcmp(argv[i], "--threads")) {
      /* an option where the value should be is the value left out (taken as
      ** the value, its own value was blamed as a second scene file) */
      if (i + 1 < argc && !strncmp(argv[i + 1], "--", 2)) {
        lw_error_set(&err, LW_EUSAGE, "%s: expected a value, got the option '%s' (was the value left out?%s%s)",
                     argv[i], argv[i + 1], strcmp(argv[i], "--out") ? "" : " a directory of that name is ./",
                     strcmp(argv[i], "--out") ? "" : argv[i + 1]);
        return fail(&err);
      }
      i++;
      continue;
    }
    if (argv[i][0] == '-' && strcmp(argv[i], "--quiet")) {
      lw_error_set(&err, LW_EUSAGE, "run: unknown option '%s'%s (try 'linewise --help')%s%s", argv[i],
                   strcmp(argv[i], "--sweeps") ? nearest(argv[i], run_options) : "", dash_hint(argv[i], run_options),
                   !strcmp(argv[i], "--sweeps") ? " (a run's length is --set anneal.sweeps=N; "
                   "--sweeps extends a finished run under resume)" : "");
      return fail(&err);
    }
    if (argv[i][0] != '-') {
      const int split_here = i >= 2 && !strcmp(argv[i - 2], "--set");
      if (scene) {
        /* (--set scene.image=my photo.jpg, or --set scene.page = a5: the
        ** shell split the value, before the scene file or after it) */
        const int split = split_here || scene_split;
        lw_error_set(&err, LW_EUSAGE, "run: one scene file expected, got '%s' and '%s'%s", scene, argv[i],
                     split ? " (after --set: no blanks around '=', and a value with blanks in quotes, "
                             "--set 'scene.image=my photo.jpg')" : "");
        return fail(&err);
      }
      scene = argv[i];
      scene_split = split_here;
    }
  }
  if (!scene) {
    lw_error_set(&err, LW_EUSAGE, "run: expected a scene file (usage: linewise run SCENE.ini [options])");
    return fail(&err);
  }
  /* resolved once --set has applied: lw_anneal_start */
  if (path_plain("run", scene, &err)) return fail(&err);
  if (lw_params_read_unresolved(&p, scene, &err)) {
    bundled_hint(scene, &err);
    return fail(&err);
  }
  for (int i = 0; i < argc; i++) {
    const char *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (!strcmp(argv[i], "--set")) {
      if (!v) { lw_error_set(&err, LW_EUSAGE, "--set: expected section.key=value"); return fail(&err); }
      if (!set_later(argv, argc, i) && set_option(&p, v, &err)) return fail(&err);
      i++;
    } else if (!strcmp(argv[i], "--out")) {
      struct stat sb; /* (an option as v was refused above: `--out $DIR --quiet`, DIR empty, wrote ./--quiet) */
      if (v) v = trim_slashes(argv[i + 1]); /* (before stat: "file/" is no file but ENOTDIR) */
      if (!v || !*v || (stat(v, &sb) == 0 && !S_ISDIR(sb.st_mode))) {
        lw_error_set(&err, LW_EUSAGE, "--out: expected a directory, got '%s'%s", v ? v : "",
                     !v || !*v ? "" : S_ISREG(sb.st_mode) ? " (a file)" : " (not a directory)");
        return fail(&err);
      }
      if (dir_fits("--out", v, &err)) return fail(&err);
      out = v;
      i++;
    } else if (!strcmp(argv[i], "--seed")) {
      if (set_later(argv, argc, i)) { /* the last value is the seed */
        i++;
        continue;
      }
      if (!parse_count("--seed", v, 0, LW_SEED_MAX, &seed, &err)) return fail(&err);
      char buf[64];
      snprintf(buf, sizeof buf, "anneal.seed=%ld", seed);
      if (lw_params_set(&p, buf, &err)) return fail(&err);
      p.line[lw_params_find("anneal", "seed") - lw_param_table] = LW_PARAMS_SEED_OPTION; /* named as given */
      i++;
    } else {
      int used = shared_option(argv, argc, i, &stop_at, &quiet, &err);
      if (used < 0) return fail(&err);
      if (used == 2) i++;
    }
  }
  char dir[LW_PATH_MAX];
  int hold = 0, made = 0; /* the default directory's lock, held to the end */
  if (out) snprintf(dir, sizeof dir, "%s", out);
  else if (default_dir(dir, sizeof dir, scene, &hold, &made, &err)) return fail(&err);
  name_run_dir(dir);
  /* the run writes its resolved parameters to DIR/scene.ini: over a run's
  ** (a run made again in place), never over a scene file a person wrote,
  ** the one this run reads included */
  static const char *const mine[] = {"scene.ini", "state.lw"}, *const what[] = {"a scene file?", "not a state"};
  for (int k = 0; k < 2; k++) /* (one that cannot be read: lw_runfiles_check_free says so) */
    if (lw_rundir_foreign(dir, mine[k]) > 0) {
      lw_error_set(&err, LW_EUSAGE, "--out %s: %s/%s is not a run's (%s) and the run would write over it: "
                   "expected a run directory or a new one", dir, dir, mine[k], what[k]);
      return fail(&err);
    }
  /* (one process of an MPI run could see process 0's first files there and
  ** leave the others waiting: there process 0 checks under its lock) */
  if (!net && (lw_runfiles_check_free(dir, &err) || lw_runfiles_check_stash(dir, &err))) return fail(&err);
  /* before a set-up of minutes, not after it */
  if (lw_rundir_writable(dir, &err) || (out && !net && claim_out(dir, &hold, &made, &err))) {
    unmake_dir(dir, hold, made);
    return fail(&err);
  }
  if (made) {
    snprintf(made_dir, sizeof made_dir, "%s", dir);
    lw_path_join(made_lock, sizeof made_lock, dir, ".lock");
    made_what = made;
  }
  static lw_anneal a;
  watcher w;
  const int asked = quiet;
  if (net && net->rank) quiet = 1;
  watcher_start(&w, quiet);
  /* (a directory the set-up could not make is not one removed since) */
  const int was_there = !access(dir, F_OK);
  if (spread_start(lw_anneal_start_net(&a, &p, dir, net, &err), &a, 1, &err)) {
    /* (a failed first write said only that, leaving a directory without a
    ** state.lw: what to do next, as loop_fail says later) */
    const int back = lw_anneal_undo_start(&a); /* (MPI: the network's checkpoint failed) */
    /* (the set-up's own files, its checkpoint among them, which the undo
    ** removes where no run was before: "no longer there" was said of them) */
    const int removed = a.undone;
    if (a.gave_way) { /* (one process: a log of --quiet runs is told too) */
      watcher_stop(&w, LW_PHASE_STOPPED);
      lw_anneal_free(&a);
      if (!back) {
        lw_error_set(&err, LW_ERUN, "%s: stopped during the set-up, and the run that was there waits in %s/"
                     LW_RUNFILES_STASH " (linewise puts it back when it next runs or resumes there)", dir, dir);
        return fail(&err);
      }
      fprintf(stderr, "linewise: stopped during the set-up; the run that was in %s is back as it was\n", dir);
      /* nothing of this run is kept, as when a signal ends a set-up that
      ** wrote nothing: 128 + the signal (SIGINT by itself, in main).  It
      ** exited 0 beside the earlier run's summary.json, which a script took
      ** for this run's result */
      return stop_requested && stop_requested != SIGINT ? 128 + stop_requested : 0;
    }
    const size_t n = strlen(err.msg);
    char state[LW_PATH_MAX + 16];
    snprintf(state, sizeof state, "%s/state.lw", dir);
    /* (the directory removed or moved during the set-up: "wrote no
    ** checkpoint" was said of one that went with it, and "the run that was
    ** in the directory is back as it was" of a run set aside in it, gone or
    ** moved along) */
    /* (a camera's picture under ulimit -v said "out of memory for a 1732 x
    ** 2309 grid" and no more; 1e6 pixels ran in 77 MB) */
    if (err.code == LW_ENOMEM) {
      /* (a file is decoded whole before image_max_pixels makes it smaller) */
      if (strstr(err.msg, "out of memory decoding"))
        snprintf(err.msg + n, sizeof err.msg - n, "; the picture's file is decoded whole before it is made smaller: "
                 "a file of fewer pixels, or more memory");
      else
        snprintf(err.msg + n, sizeof err.msg - n, "; in less memory %sfewer %s or fewer threads (--threads 1: "
                 "ulimit -v counts each thread's reserve) make a smaller run (docs/PERFORMANCE.md, \"Memory\")",
                 p.image[0] ? "a smaller scene.image_max_pixels, " : "",
                 /* (a particle cloud was told to take fewer splines) */
                 !strcmp(p.system, "particles") ? "particles" : !strcmp(p.system, "nurbs") ? "control points"
                                                                                          : "splines");
      stash_note(&err, dir);
    } else if (err.code == LW_EIO && access(dir, F_OK) &&
             (was_there || strstr(err.msg, ": cannot create directory: ") == NULL))
      snprintf(err.msg + n, sizeof err.msg - n, "; %s is no longer there: the run's directory was removed or moved "
               "during the set-up (moved, 'linewise resume' where it is now puts back the run that was there, or "
               "goes on from this run's checkpoint)", dir);
    else if (err.code == LW_EIO && lw_phase_last_commit(NULL) >= 0 && access(state, F_OK) && !removed)
      snprintf(err.msg + n, sizeof err.msg - n, "; %s is no longer there: the run's directory was removed or moved, "
               "so the run ends (moved, it resumes from its last checkpoint where it is now)", state);
    else if (err.code == LW_EIO && removed && lw_phase_last_commit(NULL) >= 0)
      snprintf(err.msg + n, sizeof err.msg - n, "; the run's first files are removed, as it had done no sweep: run "
               "it again once the files can be written");
    else if (err.code == LW_EIO && !lw_phase_unwritten())
      snprintf(err.msg + n, sizeof err.msg - n, "; the run wrote no checkpoint%s: run it again once the files can "
               "be written", back ? ", and the run that was in the directory is back as it was"
                         : lw_runfiles_stashed(dir) ? ", and the run that was in the directory waits in "
                         LW_RUNFILES_STASH " (linewise puts it back when it next runs or resumes there)" : "");
    else stash_note(&err, dir); /* (bad input into a directory where an earlier run waits aside) */
    lw_anneal_free(&a);
    unmake_dir(dir, hold, made);
    return watched_fail(&w, &err);
  }
  made_what = 0;
  checkpointed = 1;
  run_going = &a;
  atexit(run_ended_at_exit);
  watcher_settle(&w);
  say_stash_left(&a); /* (an MPI run's first checkpoint drops the run set aside) */
  /* under --quiet too: a seed sweep over an old run's scene.ini brought back
  ** the seeds that draw the same numbers without a word */
  if (a.params.run_header && !lw_params_line(&a.params, "anneal", "seed_version") &&
      (!net || !net->rank))
    fprintf(stderr, "linewise: note: anneal.seed_version = 1: %s is a run's scene.ini from before 2026-12-06, so this "
            "run seeds as that one did, where two seeds could draw the same numbers; --set anneal.seed_version=2 for "
            "a new study (docs/NUMERICS.md, \"Random numbers\")\n", scene);
  if (a.memory_note[0] && (!net || !net->rank)) fprintf(stderr, "linewise: note: %s\n", a.memory_note);
  say_frames_disk(&a, quiet);
  /* a release spans changes that draw a scene otherwise (each keeps a run
  ** begun before on resume, not a new run of its scene.ini) */
  char this_build[64];
  snprintf(this_build, sizeof this_build, "%s, build %s", LW_VERSION, lw_version_build());
  if (a.params.run_header && strcmp(a.params.run_build, this_build) && (!net || !net->rank))
    fprintf(stderr, "linewise: note: %s was written by %s%s; this is linewise %s, which may draw it otherwise where "
            "its behaviour changed since (docs/FORMATS.md, \"Runs of older releases\")\n", scene,
            a.params.run_build[0] ? "linewise " : "an earlier linewise, which recorded no build",
            a.params.run_build, this_build);
  /* the same build on other libraries may round otherwise: the scientist
  ** repeating a run to the bit is told before comparing files */
  char libs[sizeof a.params.run_libraries], libs_changed[2 * sizeof libs];
  lw_version_libraries(libs, sizeof libs);
  if (a.params.run_header && a.params.run_libraries[0] && (!net || !net->rank) &&
      libraries_changed(a.params.run_libraries, libs, libs_changed, sizeof libs_changed))
    fprintf(stderr, "linewise: note: %s was run on other libraries (%s): the last bits of state.lw and trace.csv and "
            "the bytes of final.png may differ from that run's (docs/NUMERICS.md, \"How far the same bits reach\")\n",
            scene, libs_changed);
  char changed[LW_PARAMS_FILES_MAX * (LW_PATH_MAX + 40)];
  const int n_changed = lw_params_files_changed(&a.params, changed, sizeof changed);
  if (n_changed && (!net || !net->rank))
    fprintf(stderr, "linewise: note: %s changed since the run that wrote %s read %s: this run does not repeat that "
            "one\n", changed, scene, n_changed > 1 ? "them" : "it");
  if (!quiet) {
    const char *note = a.sys_type->note(a.setup);
    char size[128];
    a.sys_type->describe(a.sys->state, LW_DESCRIBE_SIZE, size, sizeof size);
    print_notes(note);
    if (a.unread[0])
      fprintf(stderr, "linewise: note: under driver = %s these keys have no effect: %s\n",
              a.params.driver, a.unread);
    if (a.idle[0]) fprintf(stderr, "linewise: note: these keys have no effect here: %s\n", a.idle);
    print_notes(a.schedule_note);
    /* (a scene file emptied by mistake ran the defaults unsaid; --set
    ** values are no defaults) */
    size_t given = 0;
    for (size_t k = 0; k < lw_param_count; k++) given += a.params.line[k] != 0;
    if (!given && !a.params.of_run)
      fprintf(stderr, "linewise: note: %s sets no key: every value is the default (docs/PARAMETERS.md)\n", scene);
    /* (a student's final.pdf of Inkscape's in the run's folder went with
    ** the run it replaced, without a word) */
    fprintf(stderr, "linewise: scene %s, seed %lu, %s, into %s%s\n", scene, a.seed, size, dir,
            lw_runfiles_stashed(dir) ? ", replacing the run there: its files (any file of a run's name: final.pdf, "
                                       "animation.mp4, frames/frame-N.png) go once this run's first sweep is done"
                                     : "");
    fprintf(stderr, "linewise: resolved parameters:\n");
    lw_params_write(&a.params, stderr);
  } else if (!out && (!net || !net->rank)) {
    /* a directory chosen past out/<name>, which holds a run, said even
    ** quiet: a later `stats out/<name>` read the earlier run unsaid */
    const char *base;
    const int n = scene_name(scene, &base);
    char plain[LW_PATH_MAX];
    snprintf(plain, sizeof plain, "out/%.*s", n, base);
    if (strcmp(dir, plain))
      fprintf(stderr, "linewise: into %s (%s holds a run; --out names the directory)\n", dir, plain);
  }
  say_stop_past_end(&a, stop_at, quiet);
  int rc = anneal_loop(&a, stop_at, quiet, asked, &w, &err);
  lw_anneal_free(&a);
  return rc;
}

#define RESUME_USAGE "(usage: linewise resume DIR [--sweeps N] [--stop-at N] [--threads N] [--quiet])"

static int cmd_resume(int argc, char **argv)
{
  lw_error err;
  lw_error_clear(&err);
  const char *dir = NULL;
  long more = -1, stop_at = -1;
  int quiet = 0, used;
  for (int i = 0; i < argc; i++) {
    const char *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (!strcmp(argv[i], "--sweeps")) {
      if (!parse_count("--sweeps", v, 0, LW_STATE_SWEEP_MAX, &more, &err)) return fail(&err);
      i++;
    } else if ((used = shared_option(argv, argc, i, &stop_at, &quiet, &err)) != 0) {
      if (used < 0) return fail(&err);
      if (used == 2) i++;
    } else if (argv[i][0] == '-' || dir) {
      lw_error_set(&err, LW_EUSAGE, "resume: unexpected '%s'%s %s%s", argv[i],
                   argv[i][0] == '-' ? nearest(argv[i], resume_options) : "", RESUME_USAGE,
                   dash_hint(argv[i], resume_options));
      return fail(&err);
    } else {
      dir = trim_slashes(argv[i]);
    }
  }
  if (!dir) {
    lw_error_set(&err, LW_EUSAGE, "resume: expected a run directory %s", RESUME_USAGE);
    return fail(&err);
  }
  if (dir_fits("resume", dir, &err)) return fail(&err);
  if (run_dir_there("resume", dir, RESUME_USAGE, &err)) return fail(&err);
  name_run_dir(dir);
  static lw_anneal a;
  watcher w;
  const int asked = quiet;
  if (net && net->rank) quiet = 1;
  watcher_start(&w, quiet);
  checkpointed = 1; /* state.lw holds the last one */
  lw_status s = lw_anneal_resume_net(&a, dir, more, net, &err);
  if (!s) lw_phase_committed(a.sweep);
  /* judged before the processes of an MPI run agree, so that it is said
  ** once (each said it, and MPI_Abort's banner followed) */
  if (!s && stop_at >= 0 && stop_at < a.sweep)
    s = lw_error_set(&err, LW_EUSAGE, "--stop-at %ld: the run in %s stands at sweep %ld already; expected %ld or more",
                     stop_at, dir, a.sweep, a.sweep);
  if (spread_start(s, &a, 0, &err) || lw_anneal_settle(&a, &err)) {
    older_state_note(&a.params, dir, &err);
    lw_anneal_free(&a);
    /* a full disk as an extension starts said only "write failed" */
    if (err.code == LW_EIO) {
      char word[LW_RUNDIR_WORD_MAX], sweeps[64] = "";
      if (more >= 0) snprintf(sweeps, sizeof sweeps, " --sweeps %ld", more);
      if (stop_at >= 0) snprintf(sweeps + strlen(sweeps), sizeof sweeps - strlen(sweeps), " --stop-at %ld", stop_at);
      const size_t n = strlen(err.msg);
      snprintf(err.msg + n, sizeof err.msg - n, "; the run in %s is as its last checkpoint left it: 'linewise resume "
               "%s%s' goes on once its files can be read and written", dir,
               lw_rundir_shell_word(dir, word, sizeof word), sweeps);
    }
    return watched_fail(&w, &err);
  }
  if (a.pause_at >= 0 && (stop_at < 0 || a.pause_at < stop_at)) stop_at = a.pause_at;
  run_going = &a;
  atexit(run_ended_at_exit);
  watcher_settle(&w);
  /* a resume under the limit that failed its drawing failed again unsaid */
  if (a.memory_note[0] && (!net || !net->rank)) fprintf(stderr, "linewise: note: %s\n", a.memory_note);
  say_frames_disk(&a, quiet);
  /* (under --quiet too: a study's rates were many times too high unsaid) */
  if (a.untimed_said == 2 && (!net || !net->rank))
    fprintf(stderr, "linewise: note: %s/timing.txt, of a release before 2026-12-04, has the wall time alone: "
            "summary.json's sweep_seconds counts from this resume on, and proposals_per_second this resume's "
            "proposals\n", dir);
  else if (a.untimed_said && (!net || !net->rank))
    fprintf(stderr, "linewise: note: %s/timing.txt is missing or unreadable: summary.json's wall_seconds and "
            "sweep_seconds count from this resume on, and proposals_per_second this resume's proposals\n", dir);
  if (!quiet) fprintf(stderr, "linewise: resuming %s at sweep %ld of %ld\n", dir, a.sweep, a.end_sweep);
  say_stop_past_end(&a, stop_at, quiet);
  int rc = anneal_loop(&a, stop_at, quiet, asked, &w, &err);
  lw_anneal_free(&a);
  return rc;
}

/* Whether the directory named by path (trailing slashes aside) is a link. */
static int is_link(const char *path)
{
  char bare[LW_PATH_MAX];
  size_t n = strlen(path);
  while (n > 1 && path[n - 1] == '/') n--;
  if (n >= sizeof bare) return 0;
  memcpy(bare, path, n);
  bare[n] = '\0';
  struct stat sb;
  return !lstat(bare, &sb) && S_ISLNK(sb.st_mode);
}

/* stats DIR... [--from S] [--to S] [--csv] [--reweight N]: the means with
** error bars of the columns of DIR/trace.csv (trace.h), and with several
** runs whether they agree; or the rungs' energies reweighted to N
** temperatures (reweight.h).  Each run's scene.ini gives its tuning sweeps
** and stats_from. */
static int cmd_stats(int argc, char **argv)
{
  static const char use[] = "(usage: linewise stats DIR... [--from S] [--to S] [--csv] [--reweight N])";
  lw_error err;
  lw_error_clear(&err);
  const char **dir = calloc((size_t)argc + 1, sizeof *dir);
  int k = 0;
  lw_trace_select base = {.from = -1, .to = -1};
  long reweight = 0;
  for (int i = 0; dir && i < argc; i++) {
    const char *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (!strcmp(argv[i], "--from") || !strcmp(argv[i], "--to")) {
      if (!parse_count(argv[i], v, 0, LW_STATE_SWEEP_MAX, argv[i][2] == 'f' ? &base.from : &base.to, &err)) break;
      i++;
    } else if (!strcmp(argv[i], "--csv")) {
      base.csv = 1;
    } else if (!strcmp(argv[i], "--reweight")) {
      if (!parse_count(argv[i], v, 2, LW_REWEIGHT_TEMPS_MAX, &reweight, &err)) break;
      i++;
    } else if (argv[i][0] == '-') {
      lw_error_set(&err, LW_EUSAGE, "stats: unexpected '%s'%s %s%s", argv[i], nearest(argv[i], stats_options), use,
                   dash_hint(argv[i], stats_options));
      break;
    } else if (dir_fits("stats", argv[i], &err)) {
      break;
    } else {
      dir[k++] = trim_slashes(argv[i]);
    }
  }
  /* --to alone takes the rows from the trace's start, not from the default
  ** stretch's (it said "no row from sweep 1000 to 300") */
  if (base.to >= 0 && base.from < 0) base.from = 0;
  if (!err.code && base.to >= 0 && base.from > base.to)
    lw_error_set(&err, LW_EUSAGE, "stats: --from %ld is after --to %ld: expected --from no later than --to",
                 base.from, base.to);
  if (!dir) lw_error_set(&err, LW_ENOMEM, "out of memory");
  else if (!err.code && !k) lw_error_set(&err, LW_EUSAGE, "stats: expected a run directory %s", use);
  /* a glob of a sweep's directory names its files too (sweep.conf,
  ** sweep.csv, plot-sweep's sweep.png, a Slurm log: "sweep.conf/scene.ini:
  ** ... Not a directory"), which are left out with a note; a trace.csv named
  ** for its run is refused (pooled without it, a script got fewer runs
  ** than it named) */
  struct stat sd;
  for (int r = 0; !err.code && r < k; r++) {
    if (stat(dir[r], &sd) || S_ISDIR(sd.st_mode)) continue;
    const char *name = strrchr(dir[r], '/') ? strrchr(dir[r], '/') + 1 : dir[r];
    if (k > 1 && strcmp(name, "trace.csv")) {
      fprintf(stderr, "linewise: note: %s is no run directory: left out\n", dir[r]);
      memmove(dir + r, dir + r + 1, (size_t)(k - r - 1) * sizeof *dir);
      k--, r--;
    } else {
      lw_error_set(&err, LW_EUSAGE, "stats: %s is not a directory: expected run directories %s", dir[r], use);
    }
  }
  /* a run named twice (a sweep's `best` link beside its seed-N, as a glob
  ** of the sweep's directory gives) would count as two agreeing runs: it is
  ** counted once, by the name that is not a link */
  for (int r = 1; !err.code && r < k; r++) {
    char a[LW_PATH_MAX + 32], b[LW_PATH_MAX + 32];
    struct stat sa, sb;
    lw_path_join(a, sizeof a, dir[r], "trace.csv");
    for (int q = 0; q < r; q++) {
      lw_path_join(b, sizeof b, dir[q], "trace.csv");
      if (stat(a, &sa) || stat(b, &sb) || sa.st_dev != sb.st_dev || sa.st_ino != sb.st_ino) continue;
      if (is_link(dir[q]) && !is_link(dir[r])) {
        const char *keep = dir[r];
        dir[r] = dir[q];
        dir[q] = keep;
      }
      fprintf(stderr, "linewise: note: %s is the run in %s again: counted once\n", dir[r], dir[q]);
      memmove(dir + r, dir + r + 1, (size_t)(k - r - 1) * sizeof *dir);
      k--, r--;
      break;
    }
  }
  lw_trace **t = err.code ? NULL : calloc((size_t)k, sizeof *t);
  lw_trace_select *sel = t ? calloc((size_t)k, sizeof *sel) : NULL;
  char **path = sel ? calloc((size_t)k, sizeof *path) : NULL;
  if (!err.code && !path) lw_error_set(&err, LW_ENOMEM, "out of memory");
  static lw_params p;
  int failed = -1, other_driver = -1; /* the run an error is of; the first run of another driver than run 0's */
  /* each run's driver, compared once the runs left out are gone */
  char(*driver)[sizeof p.driver] = path ? calloc((size_t)k, sizeof *driver) : NULL;
  if (!err.code && !driver) lw_error_set(&err, LW_ENOMEM, "out of memory");
  for (int r = 0; !err.code && r < k; r++) {
    char where[LW_PATH_MAX + 32];
    lw_path_join(where, sizeof where, dir[r], "scene.ini");
    failed = r;
    if (lw_params_read_run(&p, where, 1, &err)) break;
    snprintf(driver[r], sizeof driver[r], "%s", p.driver);
    sel[r] = base;
    lw_trace_select_of(&p, &sel[r]);
    lw_path_join(where, sizeof where, dir[r], "trace.csv");
    if (!(path[r] = strdup(where))) lw_error_set(&err, LW_ENOMEM, "out of memory");
    else t[r] = lw_trace_read(where, &err);
    /* pooled with finished runs, a run stopped on the way counted as one of
    ** them, its shorter stretch shown only by its row count; one that has
    ** not reached the stretch yet is left out (a preempted task of a sweep
    ** refused the whole pool) */
    lw_path_join(where, sizeof where, dir[r], "summary.json");
    if (err.code || k < 2 || !access(where, F_OK)) continue;
    const int sweep = lw_trace_column(t[r], "sweep");
    const double last = sweep >= 0 && t[r]->n_rows ? t[r]->v[(t[r]->n_rows - 1) * t[r]->n_cols + (size_t)sweep] : 0;
    size_t *rows = NULL, n_rows = 0, tuned = 0;
    lw_error short_err = {0};
    if (!lw_trace_rows(t[r], path[r], &sel[r], &rows, &n_rows, &tuned, &short_err)) {
      fprintf(stderr, "linewise: note: %s has no summary.json: the run has not finished (its rows end at sweep %.0f "
              "of %ld), and it is pooled with its %zu rows\n", dir[r], last, sel[r].sweeps, n_rows);
    } else {
      fprintf(stderr, "linewise: note: %s has no summary.json and no row to pool yet (%s): left out\n", dir[r],
              short_err.msg);
      lw_trace_free(t[r]);
      free(path[r]);
      memmove(dir + r, dir + r + 1, (size_t)(k - r - 1) * sizeof *dir);
      memmove(t + r, t + r + 1, (size_t)(k - r - 1) * sizeof *t);
      memmove(sel + r, sel + r + 1, (size_t)(k - r - 1) * sizeof *sel);
      memmove(path + r, path + r + 1, (size_t)(k - r - 1) * sizeof *path);
      memmove(driver + r, driver + r + 1, (size_t)(k - r - 1) * sizeof *driver);
      t[k - 1] = NULL, path[k - 1] = NULL;
      k--, r--;
    }
    free(rows);
  }
  for (int r = 1; !err.code && other_driver < 0 && r < k; r++)
    if (strcmp(driver[r], driver[0])) other_driver = r;
  if (!err.code) {
    failed = -1;
    /* with --csv the warnings no column carries go to stderr, a line each */
    char *warned = NULL;
    size_t warned_len = 0;
    FILE *w = base.csv ? open_memstream(&warned, &warned_len) : NULL;
    for (int r = 0; r < k; r++) sel[r].csv_warnings = w;
    if (reweight) {
      lw_trace_reweight((const lw_trace *const *)t, (const char *const *)path, sel, k, (int)reweight, stdout, &err);
      if (!err.code && k > 1)
        lw_trace_warn_twins((const lw_trace *const *)t, (const char *const *)path, sel, k, w ? w : stdout);
    } else
      lw_trace_stats_runs((const lw_trace *const *)t, (const char *const *)path, sel, k, stdout, &err);
    if (w) fclose(w);
    for (char *line = warned; line && *line;) {
      size_t len = strcspn(line, "\n");
      fprintf(stderr, "linewise: %.*s\n", (int)len, line);
      line += len + (line[len] == '\n');
    }
    free(warned);
    /* pooled, their means sample one distribution; the rest is of each chain */
    if (!err.code && other_driver >= 0)
      fprintf(stderr, "linewise: note: the runs ran under different drivers (%s: %s, %s: %s): their means sample one "
              "distribution, their acceptances, steps and autocorrelation times are each of its own chain\n", dir[0],
              driver[0], dir[other_driver], driver[other_driver]);
  }
  /* (the run the error is of may wait aside: "no rows" of the run that
  ** was killed replacing it said nothing of it); a statistics' error begins
  ** with the trace's path */
  for (int r = 0; err.code && failed < 0 && path && r < k; r++)
    if (path[r] && !strncmp(err.msg, path[r], strlen(path[r])) && err.msg[strlen(path[r])] == ':') failed = r;
  if (err.code && failed >= 0) stash_note(&err, dir[failed]);
  for (int r = 0; path && r < k; r++) {
    lw_trace_free(t[r]);
    free(path[r]);
  }
  free(driver);
  free(path);
  free(sel);
  free(t);
  free(dir);
  return err.code ? fail(&err) : 0;
}

/* "--" ends the options (POSIX utility guideline 10): an argument after it
** that begins with '-' is a path (a scene file or run directory named "-x"),
** handed on as "./-x", which names the same file and matches no option.
** Returns 0, or 1 out of memory (the copies live as long as the process). */
static int end_of_options(int *argc, char **argv)
{
  for (int i = 2; i < *argc; i++) {
    if (strcmp(argv[i], "--")) {
      i += takes_value(argv[i]); /* its value, whatever it reads */
      continue;
    }
    memmove(argv + i, argv + i + 1, (size_t)(*argc - i) * sizeof *argv); /* argv[argc], NULL, too */
    --*argc;
    for (int k = i; k < *argc; k++) {
      if (argv[k][0] != '-') continue;
      char *dotted = malloc(strlen(argv[k]) + 3);
      if (!dotted) return 1;
      argv[k] = strcat(strcpy(dotted, "./"), argv[k]);
    }
    return 0;
  }
  return 0;
}

/* "linewise CMD --help" prints the usage and exits 0. */
static int wants_help(int argc, char **argv)
{
  for (int i = 2; i < argc; i++)
    if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) return 1;
  return 0;
}

/* From the first instruction: SIGINT, SIGTERM and SIGHUP ask for a clean stop
** (a run started meanwhile finishes its start-up, writes its first
** checkpoint and stops; a second signal ends it at once), and a file-size
** limit makes writes fail with EFBIG, reported with the file, instead of
** killing the process. */
static void install_signals(int pipe_proof)
{
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  on_terminal = isatty(2);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  /* a terminal or ssh session that goes away stops a run as cleanly, but
  ** for a run told to outlive it (nohup, trap '' HUP: ignored already) */
  struct sigaction was;
  if (!sigaction(SIGHUP, NULL, &was) && was.sa_handler != SIG_IGN) sigaction(SIGHUP, &sa, NULL);
  /* a CPU-time limit's soft end (ulimit -t; a batch system's warning before
  ** its hard end kills) ended the run unsaved */
  if (!sigaction(SIGXCPU, NULL, &was) && was.sa_handler != SIG_IGN) sigaction(SIGXCPU, &sa, NULL);
  signal(SIGXFSZ, SIG_IGN);
  /* run and resume write their results to files: a reader of their
  ** progress that goes away (`| head`, a closed log pipe) must not kill
  ** them (writes to stderr then fail, unheard); the other commands print
  ** their results, and stop when nobody reads them */
  if (pipe_proof) signal(SIGPIPE, SIG_IGN);
}

static int command(int argc, char **argv);

/* The threads a run or resume asks for: --threads, else OpenMP's. */
static int threads_asked(int argc, char **argv)
{
  int threads = omp_get_max_threads();
  long long n;
  for (int i = 2; i + 1 < argc && strcmp(argv[i], "--"); i += 1 + takes_value(argv[i]))
    if (!strcmp(argv[i], "--threads") && lw_number_parse_whole(argv[i + 1], 1, 4096, &n)) threads = (int)n;
  return threads;
}

#ifndef LW_MPI
/* OpenMP threads spin at their barriers (libgomp's default), which is fast
** while each has a core, but on a machine busy with other work a spinning
** thread waits for one that is not running: lj13.ini with --threads 2 on 2
** cores at a load of 6 took 6.1 s, with OMP_WAIT_POLICY=passive 0.96 s, on
** one thread 0.84 s.  Passive waits cost small rungs on an idle machine
** (lj13 at 16 threads of 16 idle cores: 1.19 s against 0.54 s;
** docs/SCALING.md), so they are chosen only where the threads and the load
** already there exceed the cores.  libgomp reads the policy when it loads,
** before main: the process starts again with it set.  A policy the
** environment sets is left alone (so is a single thread, which never
** waits). */
static void choose_wait_policy(int argc, char **argv)
{
  if (argc < 2 || (strcmp(argv[1], "run") && strcmp(argv[1], "resume")) || getenv("OMP_WAIT_POLICY")) return;
  const int threads = threads_asked(argc, argv);
  double load = 0.0;
  FILE *f = fopen("/proc/loadavg", "r");
  if (!f) return;
  int got = fscanf(f, "%lf", &load);
  fclose(f);
  if (got != 1 || threads < 2 || !(load + threads > omp_get_num_procs() + 0.5)) return;
  if (setenv("OMP_WAIT_POLICY", "passive", 1)) return;
  execv("/proc/self/exe", argv); /* on failure the process goes on spinning */
}
#endif

/* Descriptors 0 to 2 that the caller closed (2>&-) would be the first files
** a run opens: trace.csv took descriptor 2, and the progress lines went into
** it.  They are opened on /dev/null instead, stdout read-only, so that what
** a command prints to a closed stdout fails and says so (finish_stdout)
** rather than vanish. */
static void open_standard_descriptors(void)
{
  for (int fd = 0; fd < 3; fd++)
    if (fcntl(fd, F_GETFD) == -1 && errno == EBADF) (void)open("/dev/null", fd == 2 ? O_WRONLY : O_RDONLY);
}

/* Output that did not all reach stdout (a full disk, a closed stdout) is a
** failure: exit 1 with one line, not 0 and an empty file. */
static int finish_stdout(int rc)
{
  errno = 0;
  if (fflush(stdout) == 0 && !ferror(stdout)) return rc;
  fprintf(stderr, "linewise: writing to stdout failed%s%s\n", errno ? ": " : "", errno ? strerror(errno) : "");
  return rc ? rc : 1;
}

/* LW_LANES=2 or 4 narrows the SIMD kernels below what the processor has (a
** porter's check of the same-bits promise on one machine); 0 if unset. */
static int narrow_lanes(void)
{
  const char *v = getenv("LW_LANES");
  if (!v || !*v) return 0;
  if (strcmp(v, "2") && strcmp(v, "4") && strcmp(v, "8")) {
    lw_error err; /* (through lw_error_set, which shows no control character) */
    lw_error_set(&err, LW_EUSAGE, "environment LW_LANES: expected 2, 4 or 8 (the widest the processor has), got '%s'",
                 v);
    fprintf(stderr, "linewise: %s\n", err.msg);
    return -1;
  }
  if (v[0] == '2') lw_vec_set_wide(0);
  if (v[0] != '8') lw_vec_set_x8(0);
  return 0;
}

/* The stack a run needs, with room to spare: the photo preset crashed with
** worker threads of 16 KiB (OMP_STACKSIZE=16K; 24 KiB ran) and a main
** thread of 64 KiB (ulimit -s 64; 128 KiB ran, as did every bundled scene).
** A stack below it is refused with one line instead of a segmentation
** fault somewhere in the run. */
#define STACK_NEEDED_KIB 256

/* The main thread's stack: ulimit -s. */
static int main_stack_too_small(void)
{
  struct rlimit rl;
  if (getrlimit(RLIMIT_STACK, &rl) || rl.rlim_cur == RLIM_INFINITY || rl.rlim_cur >= STACK_NEEDED_KIB * 1024) return 0;
  fprintf(stderr, "linewise: the stack limit (ulimit -s) is %llu KiB: expected at least %d KiB (8192 is usual)\n",
          (unsigned long long)(rl.rlim_cur / 1024), STACK_NEEDED_KIB);
  return 1;
}

/* libgomp ends the process (exit 1, "libgomp: Thread creation failed") where
** it cannot start a team's threads (an address-space limit, ulimit -v, with
** eight threads of 8 MiB stacks, or a limit on processes): the first team
** is therefore started here, before anything is written, and this says what
** to do.  Started first in the run, after its set-up's state.lw, it took a
** finished run in the directory with it. */
static volatile sig_atomic_t team_starting;
static int team_wanted;

static void team_failed(void)
{
  if (team_starting)
    fprintf(stderr, "linewise: OpenMP could not start %d threads (the memory limit, ulimit -v, or the processes "
            "allowed); nothing was written: give --threads fewer, or more room\n", team_wanted);
}

/* OpenMP's threads' stack, measured on one of them: libgomp sizes it from
** OMP_STACKSIZE, or GOMP_STACKSIZE where that is unset, empty or not a size
** it reads, or else ulimit -s, each with its own rules for blanks, signs and
** sizes it ignores; reading the variables here let "+16K", "16K\r" and a
** GOMP_STACKSIZE behind a bad OMP_STACKSIZE through to the crash.  Only a
** run of more than one thread has such threads. */
static int thread_stack_too_small(int argc, char **argv)
{
  const int n = argc < 2 || (strcmp(argv[1], "run") && strcmp(argv[1], "resume")) ? 1 : threads_asked(argc, argv);
  if (n < 2) return 0;
  size_t size = 0;
  team_wanted = n;
  team_starting = 1;
  atexit(team_failed);
#pragma omp parallel num_threads(n)
  if (omp_get_thread_num() == 1) {
#if defined(__GLIBC__)
    pthread_attr_t at;
    if (!pthread_getattr_np(pthread_self(), &at)) {
      if (pthread_attr_getstacksize(&at, &size)) size = 0;
      pthread_attr_destroy(&at);
    }
#endif
  }
  team_starting = 0;
  if (!size || size >= STACK_NEEDED_KIB * 1024) return 0;
  char set[160] = "";
  static const char *const name[] = {"OMP_STACKSIZE", "GOMP_STACKSIZE"};
  for (int k = 0; k < 2; k++)
    if (getenv(name[k]))
      snprintf(set + strlen(set), sizeof set - strlen(set), "%s%s='%.60s'", set[0] ? ", " : "", name[k],
               getenv(name[k]));
  fprintf(stderr, "linewise: OpenMP's threads get %zu KiB of stack (%s%s): expected at least %d KiB (%s)\n",
          size / 1024, set[0] ? "environment " : "ulimit -s", set, STACK_NEEDED_KIB,
          set[0] ? "unset it, or set OMP_STACKSIZE=1M" : "raise it");
  return 1;
}

int main(int argc, char **argv)
{
  open_standard_descriptors();
  gsl_set_error_handler(lw_gsl_handler);
  if (narrow_lanes() || main_stack_too_small()) return 2;
  if (end_of_options(&argc, argv)) {
    fprintf(stderr, "linewise: out of memory\n");
    return 1;
  }
#ifndef LW_MPI
  choose_wait_policy(argc, argv);
#endif
  if (thread_stack_too_small(argc, argv)) return 2;
  const int runs = argc >= 2 && (!strcmp(argv[1], "run") || !strcmp(argv[1], "resume"));
  /* nothing written yet: from the handlers' first moment, a signal ends the
  ** set-up at once (one caught before this ran the whole set-up) */
  if (runs) lw_phase_hold();
  install_signals(runs);
#ifdef LW_MPI
  if (!(net = lw_mpi_init(&argc, &argv, &stop_requested))) return 1;
  signal_quiet = net->rank != 0;
  /* the commands other than run and resume are one process's */
  int spread = argc >= 2 && (!strcmp(argv[1], "run") || !strcmp(argv[1], "resume"));
  int rc = spread || net->rank == 0 ? command(argc, argv) : 0;
  rc = finish_stdout(rc);
  lw_mpi_finish();
  return rc;
#else
  int rc = finish_stdout(command(argc, argv));
  /* A Ctrl-C stop, its state saved, ends by the signal itself: a shell runs
  ** a loop on after a child that exits 0 (or 130) on SIGINT, so every run
  ** of an artist's series loop was stopped in turn.  SIGTERM and SIGHUP
  ** (a batch system's, a lost session's) still end with 0 where the state
  ** is saved (128 + the signal where the run gave its directory back to the
  ** one it replaces: cmd_run), and so does a run that a Ctrl-C during its
  ** final files let finish (summary.json). */
  if (rc == 0 && stop_requested == SIGINT && finishing != 2) {
    signal(SIGINT, SIG_DFL);
    raise(SIGINT);
  }
  return rc;
#endif
}

static int command(int argc, char **argv)
{
  if (argc >= 2 && wants_help(argc, argv)) {
    fputs(usage, stdout);
    return 0;
  }
  if (argc < 2 || !strcmp(argv[1], "help") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
    fputs(usage, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  if (!strcmp(argv[1], "energy")) return cmd_energy(argc - 2, argv + 2);
  if (!strcmp(argv[1], "run")) return cmd_run(argc - 2, argv + 2);
  if (!strcmp(argv[1], "resume")) return cmd_resume(argc - 2, argv + 2);
  if (!strcmp(argv[1], "stats")) return cmd_stats(argc - 2, argv + 2);
  const char *cmd = argv[1];
  const int listing = !strcmp(cmd, "schedules") || !strcmp(cmd, "params");
  if (listing || !strcmp(cmd, "version") || !strcmp(cmd, "--version") || !strcmp(cmd, "-V")) {
    if (argc > 2) {
      fprintf(stderr, "linewise %s: unexpected '%s' (it takes no arguments)\n", cmd, argv[2]);
      return 2;
    }
    if (!listing) {
      printf("linewise %s\nbuild %s\n", LW_VERSION, lw_version_build());
      /* what a porter checks the same-bits promise against (LW_LANES) */
      printf("pair kernels %d lanes, cell scan %d lanes (LW_LANES=2 or 4 narrows them; every width gives the same "
             "bits)\n", lw_vec_wide() ? 4 : 2, lw_vec_lanes());
      char libs[256];
      lw_version_libraries(libs, sizeof libs);
      printf("libraries %s\ncompiler %s\n", libs, lw_version_compiler());
      return 0;
    }
  }
  if (!strcmp(argv[1], "schedules")) {
    printf("\n| schedule | temperature of step b of B |\n|---|---|\n");
    for (const lw_schedule_type *const *t = lw_schedule_types; *t; t++)
      printf("| `%s` | %s |\n", (*t)->name, (*t)->formula);
    return 0;
  }
  if (!strcmp(argv[1], "params")) {
    lw_params_write_doc(stdout, lw_anneal_key_readers, lw_anneal_key_values);
    return 0;
  }
  lw_error err;
  lw_error_set(&err, LW_EUSAGE, "unknown command '%s'%s (try 'linewise --help')", argv[1], nearest(argv[1], commands));
  return fail(&err);
}
