/*
** test_tools.c -- the study tools in tools/ (seed-sweep, param-sweep,
** slurm-sweep.sbatch, plot-run, plot-sweep) run on params/minimal.ini made
** tiny with --set, and what they wrote is checked against the runs' own
** summary.json files.  Needs $LW_BIN and $LW_ROOT (make test sets them).
*/
#include <criterion/criterion.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "linewise/version.h"
#include "testutil.h"

static char dir[64];
static void make_dir(void) { cr_assert_eq(lw_test_dir_make(dir, "tools"), 0); }
static void remove_dir(void) { cr_assert_eq(lw_test_dir_remove(dir), 0); }

TestSuite(tools, .init = make_dir, .fini = remove_dir);

static const char *env(const char *name)
{
  const char *v = getenv(name);
  cr_assert_not_null(v, "$%s must be set (make test sets it)", name);
  return v;
}

/* 20 sweeps of 5 splines: a run takes milliseconds. */
#define TINY "--set anneal.sweeps=20 --set init.splines=5"

/* Runs a shell command with stdout in dir/out.txt and stderr in dir/err.txt;
** returns the exit status. */
static int sh(const char *fmt, ...)
{
  char cmd[4096];
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(cmd, sizeof cmd, fmt, ap);
  va_end(ap);
  cr_assert(n > 0 && (size_t)n + 64 < sizeof cmd);
  snprintf(cmd + n, sizeof cmd - (size_t)n, " >%s/out.txt 2>%s/err.txt", dir, dir);
  int st = system(cmd);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* The path of tools/<name> in the checkout. */
static const char *tool(const char *name)
{
  static char buf[4][1024];
  static int k;
  k = (k + 1) % 4;
  snprintf(buf[k], sizeof buf[k], "%s/tools/%s", env("LW_ROOT"), name);
  return buf[k];
}

static const char *scene(void)
{
  static char buf[1024];
  snprintf(buf, sizeof buf, "%s/params/minimal.ini", env("LW_ROOT"));
  return buf;
}

static char *out_txt(void) { return lw_test_slurp("%s/out.txt", dir); }
static char *err_txt(void) { return lw_test_slurp("%s/err.txt", dir); }

/* ---- sweep.csv and summary.json --------------------------------------- */

#define MAXC 96
#define MAXR 32
typedef struct {
  int ncol, nrow;
  char *head[MAXC];
  char *cell[MAXR][MAXC];
  char *text;
} csv;

static int split(char *line, char **out)
{
  int n = 0;
  for (char *c = line;; c++) {
    out[n++] = c;
    c = strchr(c, ',');
    cr_assert(n < MAXC);
    if (!c) break;
    *c = '\0';
  }
  return n;
}

static void csv_read(csv *t, const char *path)
{
  memset(t, 0, sizeof *t);
  t->text = lw_test_slurp("%s", path);
  cr_assert_not_null(t->text, "%s missing", path);
  char *save, *line = strtok_r(t->text, "\n", &save);
  cr_assert_not_null(line, "%s empty", path);
  t->ncol = split(line, t->head);
  while ((line = strtok_r(NULL, "\n", &save))) {
    cr_assert(t->nrow < MAXR);
    cr_assert_eq(split(line, t->cell[t->nrow]), t->ncol, "%s: row %d has another column count", path, t->nrow + 1);
    t->nrow++;
  }
}

static int col(const csv *t, const char *name)
{
  for (int c = 0; c < t->ncol; c++)
    if (!strcmp(t->head[c], name)) return c;
  return -1;
}

static const char *cell(const csv *t, int r, const char *name)
{
  int c = col(t, name);
  cr_assert(c >= 0, "no column '%s'", name);
  return t->cell[r][c];
}

/* The text of member key of summary.json, inside object obj (NULL: top
** level), as written; "" when absent. */
static void member(const char *json, const char *obj, const char *key, char *out, size_t n)
{
  char pat[96];
  const char *from = json, *to = json + strlen(json);
  out[0] = '\0';
  if (obj) {
    snprintf(pat, sizeof pat, "\n  \"%s\": {", obj);
    if (!(from = strstr(json, pat))) return;
    to = strstr(from, "\n  }");
    snprintf(pat, sizeof pat, "\n    \"%s\": ", key);
  } else {
    snprintf(pat, sizeof pat, "\n  \"%s\": ", key);
  }
  const char *at = strstr(from, pat);
  if (!at || at > to) return;
  at += strlen(pat);
  size_t len = strcspn(at, ",\n");
  snprintf(out, n, "%.*s", (int)(len < n ? len : n - 1), at);
}

/* Every energy, acceptance, close share, fidelity and observable cell of row r equals
** run/summary.json, text for text (the gatherer copies values, so the CSV is
** exact). */
static void row_matches_summary(const csv *t, int r, const char *run)
{
  char *js = lw_test_slurp("%s/%s/summary.json", dir, run);
  cr_assert_not_null(js, "%s/summary.json missing", run);
  char want[64];
  for (int c = 0; c < t->ncol; c++) {
    const char *h = t->head[c];
    if (!strncmp(h, "energy_", 7)) member(js, "energy", h + 7, want, sizeof want);
    else if (!strncmp(h, "acceptance_", 11)) member(js, "acceptance", h + 11, want, sizeof want);
    else if (!strncmp(h, "fidelity_", 9)) member(js, "fidelity", h + 9, want, sizeof want);
    else if (!strncmp(h, "obs_", 4)) member(js, "observables", h + 4, want, sizeof want);
    else if (!strcmp(h, "seed") || !strcmp(h, "proposals_per_second") || !strcmp(h, "wall_seconds") ||
             !strcmp(h, "temperature_final") ||
             !strcmp(h, "close_share") || !strcmp(h, "version") || !strcmp(h, "build"))
      member(js, NULL, h, want, sizeof want);
    else continue;
    if (!strcmp(want, "null")) want[0] = '\0';
    if (want[0] == '"') { /* a string's text, as the CSV holds it */
      memmove(want, want + 1, strlen(want));
      want[strcspn(want, "\"")] = '\0';
    }
    cr_assert_str_eq(t->cell[r][c], want, "%s: column %s", run, h);
  }
  free(js);
}

static double summary_total(const char *run)
{
  char *js = lw_test_slurp("%s/%s/summary.json", dir, run);
  cr_assert_not_null(js, "%s/summary.json missing", run);
  char v[64];
  member(js, "energy", "total", v, sizeof v);
  free(js);
  return strtod(v, NULL);
}

/* The number after "<label> " in text, or NAN. */
static double number_after(const char *text, const char *label)
{
  const char *at = strstr(text, label);
  return at ? strtod(at + strlen(label), NULL) : NAN;
}

static int exists(const char *name);

/* Writes an executable script dir/name from a format (a fake tool for the
** tests to put first on PATH or pass as --bin). */
static void write_script(const char *name, const char *fmt, ...)
{
  char path[256];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "w");
  cr_assert_not_null(f, "%s", path);
  va_list ap;
  va_start(ap, fmt);
  vfprintf(f, fmt, ap);
  va_end(ap);
  cr_assert_eq(fclose(f), 0);
  cr_assert_eq(chmod(path, 0755), 0);
}

/* Whether text holds a message of bash or a tool rather than the script's
** own (bash's "line 744: ...", "printf: write error", "tail: cannot open"). */
static int raw_error(const char *text)
{
  static const char *const raw[] = {": line ", "integer expression", "write error", "tail:", "mkdir:", "mv:",
                                    "printf:", "echo:", "No such file or directory"};
  for (size_t i = 0; i < sizeof raw / sizeof *raw; i++)
    if (strstr(text, raw[i])) return 1;
  return 0;
}

/* ---- seed-sweep ------------------------------------------------------- */

Test(tools, seed_sweep_gathers_every_summary_and_links_the_best)
{
  cr_assert_eq(sh("umask 027 && %s %s --seeds 1-4 -j 2 " TINY " --bin %s --out %s/s", tool("seed-sweep"), scene(),
                  env("LW_BIN"), dir), 0, "%s", err_txt());
  csv t;
  char path[128];
  snprintf(path, sizeof path, "%s/s/sweep.csv", dir);
  csv_read(&t, path);
  const char *want_cols[] = {"seed", "energy_total", "energy_strain", "energy_bending", "energy_pair",
                             "energy_boundary", "acceptance_point", "acceptance_rotate",
                             "temperature_final", "proposals_per_second", "wall_seconds", "close_share", "version",
                             "build", "run"};
  for (size_t i = 0; i < sizeof want_cols / sizeof *want_cols; i++)
    cr_assert(col(&t, want_cols[i]) >= 0, "no column %s", want_cols[i]);
  cr_assert(col(&t, "fidelity_ssim") < 0, "fidelity columns without a picture");
  cr_assert_eq(col(&t, "seed"), 0);
  cr_assert_eq(col(&t, "energy_total"), 1, "no key columns in a seed sweep");
  cr_assert_eq(t.nrow, 4);
  double e[4], sum = 0, best = INFINITY;
  int best_seed = 0;
  for (int r = 0; r < 4; r++) {
    char run[32];
    snprintf(run, sizeof run, "s/seed-%d", r + 1);
    cr_assert_eq(atoi(cell(&t, r, "seed")), r + 1, "rows in seed order");
    cr_assert_str_eq(cell(&t, r, "run"), run + 2);
    row_matches_summary(&t, r, run);
    e[r] = summary_total(run);
    cr_assert(isfinite(e[r]));
    sum += e[r];
    if (e[r] < best) best = e[r], best_seed = r + 1;
  }
  /* each run got its own seed */
  for (int a = 0; a < 4; a++)
    for (int b = a + 1; b < 4; b++) cr_assert_neq(e[a], e[b], "seeds %d and %d ran the same chain", a + 1, b + 1);

  char link[64] = {0}, want[32];
  snprintf(path, sizeof path, "%s/s/best", dir);
  cr_assert(readlink(path, link, sizeof link - 1) > 0, "no best link");
  snprintf(want, sizeof want, "seed-%d", best_seed);
  cr_assert_str_eq(link, want);

  /* the printed statistics: values carry 10 significant digits */
  double mean = sum / 4, ss = 0;
  for (int r = 0; r < 4; r++) ss += (e[r] - mean) * (e[r] - mean);
  double sd = sqrt(ss / 3);
  char *out = out_txt();
  cr_assert(fabs(number_after(out, "best ") - best) <= 1e-9 * fabs(best), "%s", out);
  cr_assert(fabs(number_after(out, "mean ") - mean) <= 1e-9 * fabs(mean), "%s", out);
  cr_assert(fabs(number_after(out, "std ") - sd) <= 1e-9 * sd, "sample std %.10g: %s", sd, out);
  cr_assert(fabs(number_after(out, "standard error of the mean ") - sd / 2) <= 1e-9 * sd, "%s", out);
  free(out);
  free(t.text);
  /* written aside under mktemp's names (0600), then given what the umask
  ** gives a new file, and nothing left beside them but the locks of the
  ** sweep's tasks */
  cr_assert_eq(sh("cd %s/s && test $(stat -c %%a sweep.csv) = 640 && test $(stat -c %%a sweep.conf) = 640 && "
                  "test $(stat -c %%a sweep.plan) = 640 && "
                  "test \"$(ls -A | grep '^\\.' | paste -sd' ')\" = '.sweep.lock .sweep.running'", dir), 0);
  /* a directory whose name ends in a line break, which linewise refuses
  ** for its runs (a CRLF script's CR made "out\r"): refused once, before
  ** anything is made */
  cr_assert_eq(sh("cd %s && { %s %s --seeds 1 " TINY " --bin %s --out 'n\n'; test $? -eq 2 && ! test -e 'n\n'; }",
                  dir, tool("seed-sweep"), scene(), env("LW_BIN")), 0, "%s", err_txt());
  char *said = err_txt();
  cr_assert(!strcmp(said, "seed-sweep: --out: a control character in 'n?': expected a path without one\n"), "%s", said);
  free(said);
  /* and one named with a leading '-' (mkdir and mv took it for options) */
  cr_assert_eq(sh("cd %s && %s %s --seeds 1 " TINY " --bin %s --out -d && test -s ./-d/sweep.csv && "
                  "test -L ./-d/best && test \"$(ls -A ./-d | grep '^\\.' | wc -l)\" = 2", dir, tool("seed-sweep"),
                  scene(), env("LW_BIN")), 0, "%s", err_txt());
}

/* Runs that agree to the last bit have no spread: the sums of e and e^2
** left about |mean| 1e-8 of one (4.3e-5 on energies of 3197).  The wire's
** dynamics draws no random number, so every seed runs the same chain. */
Test(tools, identical_runs_have_a_standard_deviation_of_zero)
{
  cr_assert_eq(sh("%s %s/params/wire.ini --seeds 1-3 -j 2 --set anneal.sweeps=40 --set output.frames_every=0 "
                  "--bin %s --out %s/w", tool("seed-sweep"), env("LW_ROOT"), env("LW_BIN"), dir), 0, "%s", err_txt());
  char *out = out_txt();
  cr_assert(strstr(out, "energy_total over 3 runs: best ") && strstr(out, ", std 0, standard error of the mean 0\n"),
            "%s", out);
  free(out);
  /* and stats says they are one run (it read R_hat 0.99 and p_runs 1, agreeing seeds) */
  cr_assert_eq(sh("%s stats %s/w/seed-1 %s/w/seed-2 %s/w/seed-3", env("LW_BIN"), dir, dir, dir), 0, "%s", err_txt());
  out = out_txt();
  cr_assert(strstr(out, "warning: the 3 runs are the same, row for row: one seed run twice, or seeds that change "
                        "nothing"), "%s", out);
  free(out);
  cr_assert_eq(sh("%s stats %s/w/seed-1 %s/w/seed-2 --csv", env("LW_BIN"), dir, dir), 0, "%s", err_txt());
  out = out_txt();
  cr_assert_null(strstr(out, "warning"), "the CSV stays a table: %s", out);
  free(out);
  /* with no column saying so, the warning goes to stderr (the CSV said R_hat 0.97 alone) */
  out = err_txt();
  cr_assert(strstr(out, "linewise: warning: the 2 runs are the same, row for row"), "%s", out);
  free(out);
  /* two of three the same (one seed twice in a sweep of several): it was
  ** said only when all were, and the twin's weight made the error bars
  ** 15 to 27 % small; "other" is seed-3 with one value changed, and has
  ** no summary.json (a run stopped on the way, pooled unsaid) */
  cr_assert_eq(sh("cd %s/w && cp -r seed-3 other && rm other/summary.json && awk -F, -v OFS=, 'NR > 1 && !d { $2 = "
                  "$2 + 1; d = 1 } 1' seed-3/trace.csv > other/trace.csv && %s stats seed-1 seed-2 other", dir,
                  env("LW_BIN")), 0, "%s", err_txt());
  out = out_txt();
  char *errs = err_txt();
  cr_assert(strstr(out, "warning: seed-1/trace.csv and seed-2/trace.csv are one run, row for row over the rows they "
                        "share") && !strstr(out, "runs are the same"), "%s", out);
  cr_assert(strstr(errs, "linewise: note: other has no summary.json: the run has not finished"), "%s", errs);
  free(errs);
  /* the pooled CSV carries no window, batch or sample-count column: the
  ** table's warnings of those go to stderr (they went nowhere, and a script
  ** took lower bounds for error bars) */
  cr_assert_eq(sh("cd %s/w && %s stats seed-1 seed-2 other --csv", dir, env("LW_BIN")), 0, "%s", err_txt());
  errs = err_txt();
  int lines = 0;
  for (char *l = strstr(out, "\nwarning: "); l; l = strstr(l + 1, "\nwarning: "), lines++) {
    char want[1024];
    snprintf(want, sizeof want, "linewise: %.*s\n", (int)strcspn(l + 1, "\n"), l + 1);
    cr_assert(strstr(errs, want) || strstr(want, "disagree beyond their error bars"), "%s not in:\n%s", want, errs);
  }
  cr_assert_geq(lines, 2, "%s", out);
  free(errs);
  free(out);
  /* a copy of a run stopped earlier (its rows the first of the other's),
  ** under --reweight too, which pooled every rung unsaid */
  cr_assert_eq(sh("cd %s/w && cp -r other part && head -n -5 other/trace.csv > part/trace.csv && %s stats other part "
                  "seed-1", dir, env("LW_BIN")), 0, "%s", err_txt());
  out = out_txt();
  cr_assert(strstr(out, "warning: other/trace.csv and part/trace.csv are one run, row for row over the rows they "
                        "share (one seed run twice, or a copy of a run stopped earlier or traced otherwise)"), "%s",
            out);
  free(out);
  /* a run stopped before the stretch (a preempted task of a sweep) is left
  ** out with a note: it refused the whole pool ("no row from sweep 30") */
  cr_assert_eq(sh("cd %s/w && cp -r other early && awk -F, 'NR == 1 || $1 <= 20' other/trace.csv > early/trace.csv && "
                  "sed -i 's/^driver = .*/driver = barker/' early/scene.ini && %s stats seed-1 early seed-2 --from 30",
                  dir, env("LW_BIN")), 0, "%s", err_txt());
  out = out_txt();
  errs = err_txt();
  cr_assert(strstr(errs, "linewise: note: early has no summary.json and no row to pool yet (early/trace.csv: no row "
                         "from sweep 30 to ") && strstr(errs, "): left out\n"), "%s", errs);
  /* (of another driver, it left a note that the pooled runs were too,
  ** naming another run) */
  cr_assert(!strstr(errs, "different drivers"), "%s", errs);
  cr_assert(strstr(out, "2 runs:\n") && !strstr(out, "early"), "%s", out);
  free(errs);
  free(out);
  /* a glob of the sweep's directory: its files are left out (plot-sweep's
  ** picture too), best counted once; a run's trace.csv is refused */
  cr_assert_eq(sh("cd %s/w && touch sweep.png && %s stats *", dir, env("LW_BIN")), 0, "%s", err_txt());
  errs = err_txt();
  cr_assert(strstr(errs, "linewise: note: sweep.conf is no run directory: left out\n") &&
            strstr(errs, "linewise: note: sweep.png is no run directory: left out\n") &&
            strstr(errs, "linewise: note: best is the run in "), "%s", errs);
  free(errs);
  cr_assert_eq(sh("cd %s/w && %s stats seed-1/trace.csv seed-2", dir, env("LW_BIN")), 2, "%s", err_txt());
  errs = err_txt();
  cr_assert(strstr(errs, "linewise: stats: seed-1/trace.csv is not a directory: expected run directories"), "%s", errs);
  free(errs);
}

/* Ctrl-C to the whole sweep (its process group; INT at its default, as in a
** terminal): the runs in progress stop at the end of their sweep with their
** state saved, no further run starts, and the script returns only then.  It
** returned at once, xargs dead, while its runs still wrote (a rerun met their
** locks); run in the background of a script, INT is ignored on entry, which
** env --default-signal undoes here.  The signal comes 0.3 s after the first
** checkpoints: at them, a loaded machine stopped a run at sweep 0.
** The sweep is the first of a shell loop's: it ends by SIGINT, so the loop
** stops with it (it exited 1, and bash started the loop's next sweep). */
Test(tools, ctrl_c_stops_the_sweep_after_its_runs_have_saved)
{
  cr_assert_eq(sh("(setsid env --default-signal=INT bash -c 'for o in i i2; do %s %s %s --seeds 1-3 -j 2 --threads 1 "
                  "--set anneal.sweeps=1000000 --bin %s --out %s/$o; done; echo the loop went on' >%s/i.out 2>%s/i.err "
                  "& echo $! >%s/i.pid); i=0; while [ $i -lt 1000 ] && ! { "
                  "test -s %s/i/seed-1/state.lw && test -s %s/i/seed-2/state.lw; }; do sleep 0.02; i=$((i+1)); done; "
                  "sleep 0.3; p=$(cat %s/i.pid); kill -INT -$p; i=0; while kill -0 $p 2>/dev/null && "
                  "[ $i -lt 1500 ]; do sleep 0.02; i=$((i+1)); done; kill -KILL -$p 2>/dev/null; test $i -lt 1500 && "
                  "flock -n %s/i/seed-1/.lock true && flock -n %s/i/seed-2/.lock true && ! test -e %s/i/seed-3",
                  "bash", tool("seed-sweep"), scene(), env("LW_BIN"), dir, dir, dir, dir, dir, dir, dir, dir, dir, dir),
               0, "%s", err_txt());
  char *e = lw_test_slurp("%s/i.err", dir), *o = lw_test_slurp("%s/i.out", dir);
  cr_assert(strstr(e, "seed-sweep: interrupted: no further run started, and each run in progress said how it ended (")
            && strstr(e, "; rerun the sweep to go on") && strstr(e, "[1/3] seed-1: interrupted, state saved"), "%s", e);
  cr_assert(!strstr(o, "the loop went on") && !exists("i2"), "%s%s", o, e);
  cr_assert_eq(sh("test -z \"$(ls -A %s/i | grep notes)\"", dir), 0, "the notes left behind");
  free(o);
  free(e);
  cr_assert_eq(lw_test_sh("grep -q '^sweep = [1-9]' %s/i/seed-1/state.lw", dir), 0);
}

/* Runs that stop at different times (a sweep of 2 splines and one of 600):
** the sweep returns after the last has saved.  xargs returned as soon as
** the first task said "stopped" (255) and printed "aborting"; the sweep then
** removed its stop file, so the slower run was reported as "stopped by a
** signal to it alone", after the sweep's last line.  A hang-up (SIGHUP to
** the group) stops the runs as Ctrl-C does: they kept it ignored from the
** sweep and ran to their end, the sweep waiting. */
Test(tools, ctrl_c_or_a_hang_up_waits_for_the_slowest_run)
{
  static const char *const sig[] = {"INT", "HUP"};
  for (int k = 0; k < 2; k++) {
    cr_assert_eq(sh("rm -rf %s/w && (setsid env --default-signal=INT,HUP %s %s %s --vary init.splines=2,600 --seeds 1 "
                    "-j 2 --threads 1 --set anneal.sweeps=1000000 --set scene.width=300 --bin %s --out %s/w >%s/w.out "
                    "2>%s/w.err & echo $! >%s/w.pid); a=%s/w/init.splines=2__seed-1; b=%s/w/init.splines=600__seed-1; "
                    "i=0; while [ $i -lt 1500 ] && ! { test -s $a/state.lw && test -s $b/state.lw; }; do sleep 0.02; "
                    "i=$((i+1)); done; p=$(cat %s/w.pid); kill -%s -$p; i=0; while kill -0 $p 2>/dev/null && "
                    "[ $i -lt 1500 ]; do sleep 0.02; i=$((i+1)); done; kill -KILL -$p 2>/dev/null; test $i -lt 1500 && "
                    "flock -n $a/.lock true && flock -n $b/.lock true",
                    dir, "bash", tool("param-sweep"), scene(), env("LW_BIN"), dir, dir, dir, dir, dir, dir, dir, sig[k]),
                 0, "SIG%s: %s", sig[k], lw_test_slurp("%s/w.err", dir));
    char *e = lw_test_slurp("%s/w.err", dir);
    const char *last = strstr(e, "param-sweep: interrupted: no further run started, and each run in progress said how");
    cr_assert(last && !strstr(last, "\n["), "SIG%s: %s", sig[k], e);
    cr_assert(strstr(e, "[1/2] init.splines=2__seed-1: interrupted, state saved") &&
                  strstr(e, "[2/2] init.splines=600__seed-1: interrupted, state saved"), "SIG%s: %s", sig[k], e);
    cr_assert(!strstr(e, "aborting") && !strstr(e, "alone") && !strstr(e, "Hangup"), "SIG%s: %s", sig[k], e);
    free(e);
  }
}

/* A sweep of a picture gathers the drawing's scores too: close share and
** fidelity_mse, _ssim, _orientation and _stray, each the run's own. */
Test(tools, a_sweep_of_a_picture_gathers_the_drawings_scores)
{
  cr_assert_eq(sh("%s %s/params/example.ini --seeds 1-2 -j 2 --set anneal.sweeps=2 --bin %s --out %s/p",
                  tool("seed-sweep"), env("LW_ROOT"), env("LW_BIN"), dir),
               0, "%s", err_txt());
  csv t;
  char path[128];
  snprintf(path, sizeof path, "%s/p/sweep.csv", dir);
  csv_read(&t, path);
  const char *want_cols[] = {"close_share", "fidelity_mse", "fidelity_ssim", "fidelity_orientation",
                             "fidelity_stray", "fidelity_missed", "fidelity_black"};
  for (size_t i = 0; i < sizeof want_cols / sizeof *want_cols; i++)
    cr_assert(col(&t, want_cols[i]) >= 0, "no column %s", want_cols[i]);
  cr_assert_eq(t.nrow, 2);
  for (int r = 0; r < 2; r++) {
    char run[32];
    snprintf(run, sizeof run, "p/seed-%d", r + 1);
    row_matches_summary(&t, r, run);
    cr_assert(atof(cell(&t, r, "fidelity_ssim")) > 0, "seed %d: ssim %s", r + 1, cell(&t, r, "fidelity_ssim"));
    /* the scores' target, the photo preset's tone_ink */
    cr_assert_str_eq(cell(&t, r, "fidelity_black"), "0.5", "seed %d", r + 1);
  }
  free(t.text);
}

/* A sweep of a study gathers summary.json's observables: each one's mean,
** standard error and autocorrelation time, as the run reported them. */
Test(tools, a_sweep_of_a_study_gathers_its_observables_with_error_bars)
{
  cr_assert_eq(sh("%s %s/params/wlc.ini --seeds 1-2 -j 2 --set anneal.sweeps=1500 --set output.stats_from=500 "
                  "--bin %s --out %s/o", tool("seed-sweep"), env("LW_ROOT"), env("LW_BIN"), dir),
               0, "%s", err_txt());
  csv t;
  char path[128];
  snprintf(path, sizeof path, "%s/o/sweep.csv", dir);
  csv_read(&t, path);
  const char *want_cols[] = {"obs_count", "obs_length", "obs_end2", "obs_end2_stderr", "obs_end2_tau_sweeps",
                             "obs_end2_n_eff", "obs_end2_window_closed", "obs_end2_drift_z", "obs_rg2",
                             "obs_end_cos_stderr"};
  for (size_t i = 0; i < sizeof want_cols / sizeof *want_cols; i++)
    cr_assert(col(&t, want_cols[i]) >= 0, "no column %s", want_cols[i]);
  cr_assert(col(&t, "obs_from") < 0 && col(&t, "obs_rows") < 0, "the stretch is not an observable");
  cr_assert_eq(t.nrow, 2);
  for (int r = 0; r < 2; r++) {
    char run[32];
    snprintf(run, sizeof run, "o/seed-%d", r + 1);
    row_matches_summary(&t, r, run);
    cr_assert_str_eq(cell(&t, r, "obs_count"), "50");
    cr_assert(atof(cell(&t, r, "obs_end2_stderr")) > 0, "seed %d: no error bar", r + 1);
  }
  free(t.text);
}

static void set_old_mtime(const char *path)
{
  struct timespec ts[2] = {{946684800, 0}, {946684800, 0}}; /* 2000-01-01 */
  cr_assert_eq(utimensat(AT_FDCWD, path, ts, 0), 0, "%s", path);
}

static time_t mtime(const char *path)
{
  struct stat st;
  cr_assert_eq(stat(path, &st), 0, "%s", path);
  return st.st_mtime;
}

Test(tools, rerun_skips_finished_runs_and_redoes_missing_ones)
{
  const char *cmd = "%s %s --seeds 1-3 -j 2 " TINY " --bin %s --out %s/s";
  cr_assert_eq(sh(cmd, tool("seed-sweep"), scene(), env("LW_BIN"), dir), 0, "%s", err_txt());
  double e2 = summary_total("s/seed-2");
  const char *files[] = {"summary.json", "state.lw", "trace.csv", "final.svg"};
  char path[128];
  for (int i = 0; i < 4; i++) {
    snprintf(path, sizeof path, "%s/s/seed-1/%s", dir, files[i]);
    set_old_mtime(path);
  }
  char *before = lw_test_slurp("%s/s/seed-1/summary.json", dir);
  cr_assert_eq(sh("rm -r %s/s/seed-2", dir), 0);

  cr_assert_eq(sh(cmd, tool("seed-sweep"), scene(), env("LW_BIN"), dir), 0, "%s", err_txt());
  for (int i = 0; i < 4; i++) {
    snprintf(path, sizeof path, "%s/s/seed-1/%s", dir, files[i]);
    cr_assert_eq(mtime(path), 946684800, "finished run rewritten: %s", files[i]);
  }
  char *after = lw_test_slurp("%s/s/seed-1/summary.json", dir);
  cr_assert_str_eq(after, before);
  /* the deleted run is done again, to the same result (same seed) */
  cr_assert_eq(summary_total("s/seed-2"), e2);
  char *out = out_txt();
  cr_assert(strstr(out, "seed-1: finished already") && strstr(out, "seed-3: finished already"), "%s", out);
  cr_assert(strstr(out, "seed-2: ran"), "%s", out);
  csv t;
  snprintf(path, sizeof path, "%s/s/sweep.csv", dir);
  csv_read(&t, path);
  cr_assert_eq(t.nrow, 3);
  free(out);
  free(before);
  free(after);
  free(t.text);
}

/* A standard output that goes away or fills ends neither the runs nor the
** sweep before them: a reader that closed took the tasks' SIGPIPE, and
** xargs, its task killed, returned at once with runs still writing and
** seed-3 never started.  A full stdout is said, with exit 1; a TMPDIR that
** is not there stops nothing (the sweep's files are its own). */
Test(tools, a_sweep_whose_output_goes_away_runs_to_its_end)
{
  cr_assert_eq(sh("{ (%s %s --seeds 1-3 -j 1 " TINY " --bin %s --out %s/p; echo $? >%s/p.rc) | head -c 1; }",
                  tool("seed-sweep"), scene(), env("LW_BIN"), dir, dir), 0, "%s", err_txt());
  cr_assert_eq(sh("{ TMPDIR=%s/none %s %s --seeds 1-3 -j 1 " TINY " --bin %s --out %s/f >/dev/full; }", dir,
                  tool("seed-sweep"), scene(), env("LW_BIN"), dir), 1, "%s", err_txt());
  char *err = err_txt();
  cr_assert(strstr(err, "seed-sweep: the standard output could not be written (closed, full, or its reader gone); "
                        "the runs went on to their end, and ") && !strstr(err, "xargs") && !strstr(err, "error"),
            "%s", err);
  free(err);
  for (int k = 0; k < 2; k++) {
    const char *sweep = k ? "f" : "p";
    cr_assert_eq(sh("for s in 1 2 3; do test -s %s/%s/seed-$s/summary.json || exit 1; done && test \"$(wc -l <%s/%s/"
                    "sweep.csv)\" -eq 4 && ! ls -a %s/%s | grep -q notes", dir, sweep, dir, sweep, dir, sweep), 0,
                 "sweep %s", sweep);
  }
  char *rc = lw_test_slurp("%s/p.rc", dir);
  cr_assert(rc && (!strcmp(rc, "0\n") || !strcmp(rc, "1\n")), "%s", rc ? rc : "(no status)");
  free(rc);
}

Test(tools, interrupted_run_is_resumed_not_restarted)
{
  /* run seed-2 stopped at sweep 7 as a signal would, then the sweep */
  cr_assert_eq(sh("%s run %s " TINY " --seed 2 --stop-at 7 --quiet --out %s/a/seed-2", env("LW_BIN"), scene(), dir), 0);
  char path[128];
  snprintf(path, sizeof path, "%s/a/seed-2/summary.json", dir);
  cr_assert_neq(access(path, F_OK), 0);
  cr_assert_eq(sh("%s %s --seeds 2 " TINY " --bin %s --out %s/a", tool("seed-sweep"), scene(), env("LW_BIN"), dir), 0,
               "%s", err_txt());
  char *out = out_txt(), *log = lw_test_slurp("%s/a/seed-2/linewise.log", dir);
  cr_assert(strstr(out, "seed-2: resumed"), "%s", out);
  cr_assert(log && strstr(log, "at sweep 7 of 20"), "%s", log);
  /* and ends where an uninterrupted run ends, bit for bit */
  cr_assert_eq(sh("%s %s --seeds 2 " TINY " --bin %s --out %s/b", tool("seed-sweep"), scene(), env("LW_BIN"), dir), 0);
  cr_assert_eq(sh("cmp %s/a/seed-2/state.lw %s/b/seed-2/state.lw", dir, dir), 0);
  cr_assert_eq(sh("cmp %s/a/seed-2/trace.csv %s/b/seed-2/trace.csv", dir, dir), 0);
  free(out);
  free(log);
}

/* ---- param-sweep ------------------------------------------------------ */

Test(tools, param_sweep_crosses_every_value_with_every_seed)
{
  const char *args = "%s %s --vary anneal.t_start=1,0.5 --vary energy.pair=0,0.02 --seeds 3-4 -j 2 " TINY
                     " --bin %s --out %s/p";
  cr_assert_eq(sh(args, tool("param-sweep"), scene(), env("LW_BIN"), dir), 0, "%s", err_txt());
  char *said = out_txt();
  csv t;
  char path[128];
  snprintf(path, sizeof path, "%s/p/sweep.csv", dir);
  csv_read(&t, path);
  cr_assert_eq(col(&t, "seed"), 0);
  cr_assert_eq(col(&t, "anneal.t_start"), 1);
  cr_assert_eq(col(&t, "energy.pair"), 2);
  cr_assert_eq(col(&t, "energy_total"), 3);
  cr_assert_eq(t.nrow, 2 * 2 * 2);
  int seen[2][2][2] = {{{0}}};
  for (int r = 0; r < t.nrow; r++) {
    const char *ts = cell(&t, r, "anneal.t_start"), *pair = cell(&t, r, "energy.pair");
    int seed = atoi(cell(&t, r, "seed"));
    int i = !strcmp(ts, "0.5"), j = !strcmp(pair, "0.02");
    cr_assert(i || !strcmp(ts, "1"), "t_start %s", ts);
    cr_assert(j || !strcmp(pair, "0"), "pair %s", pair);
    cr_assert(seed == 3 || seed == 4);
    seen[i][j][seed - 3]++;
    char run[128];
    snprintf(run, sizeof run, "anneal.t_start=%s__energy.pair=%s__seed-%d", ts, pair, seed);
    cr_assert_str_eq(cell(&t, r, "run"), run);
    char sub[160];
    snprintf(sub, sizeof sub, "p/%s", run);
    row_matches_summary(&t, r, sub);
    /* the run really used the value: its resolved scene says so */
    char *ini = lw_test_slurp("%s/p/%s/scene.ini", dir, run);
    char want[64];
    snprintf(want, sizeof want, "\nt_start = %s\n", ts);
    cr_assert(ini && strstr(ini, want), "%s: scene.ini lacks '%s'", run, want + 1);
    free(ini);
    /* pair = 0 switches the term off: an empty cell, not a zero */
    cr_assert_eq(cell(&t, r, "energy_pair")[0] == '\0', !j, "%s: energy_pair '%s'", run, cell(&t, r, "energy_pair"));
  }
  for (int i = 0; i < 8; i++) cr_assert_eq(seen[i / 4][i / 2 % 2][i % 2], 1, "combination %d seen %d times", i, seen[i / 4][i / 2 % 2][i % 2]);
  /* each point's printed line: its two seeds' best and mean, as the awk
  ** computes them (a + (b - a) / 2; a mutant that merged the points into
  ** one line passed) */
  for (int r = 0; r < t.nrow; r++) {
    const char *ts = cell(&t, r, "anneal.t_start"), *pair = cell(&t, r, "energy.pair");
    int other = -1;
    for (int q = 0; q < t.nrow; q++)
      if (q != r && !strcmp(cell(&t, q, "anneal.t_start"), ts) && !strcmp(cell(&t, q, "energy.pair"), pair)) other = q;
    cr_assert(other >= 0);
    const int first = r < other ? r : other, second = r < other ? other : r;
    const double a = atof(cell(&t, first, "energy_total")), b = atof(cell(&t, second, "energy_total"));
    const int best = b < a ? second : first;
    char want[256];
    snprintf(want, sizeof want, "  anneal.t_start=%s energy.pair=%s: 2 runs: best %.10g (seed %s), mean %.10g, std ",
             ts, pair, b < a ? b : a, cell(&t, best, "seed"), a + (b - a) / 2);
    cr_assert(strstr(said, want), "'%s' is not in:\n%s", want, said);
  }
  free(said);
  /* --list is the same plan */
  cr_assert_eq(sh("%s %s --vary anneal.t_start=1,0.5 --vary energy.pair=0,0.02 --seeds 3-4 --list | wc -l",
                  tool("param-sweep"), scene()), 0);
  char *out = out_txt();
  cr_assert_eq(atoi(out), 8);
  free(out);
  free(t.text);
}

Test(tools, failed_runs_are_reported_and_the_others_finish)
{
  int rc = sh("%s %s --vary init.splines=4,-1 --seeds 1-2 --set anneal.sweeps=20 --bin %s --out %s/f", tool("param-sweep"),
              scene(), env("LW_BIN"), dir);
  char *errs = err_txt();
  /* refused input, each reason in full once (a typo's was printed a run),
  ** their folders gone, the sweep's exit bad input's */
  cr_assert_eq(rc, 2, "%s", errs);
  const char *first = strstr(errs, "FAILED (exit 2): linewise: --set: key 'init.splines'");
  cr_assert(first && !strstr(first + 1, "FAILED (exit 2): linewise:") &&
              strstr(errs, "FAILED (exit 2): refused as init.splines=-1__seed-"), "one reason, in full once: %s", errs);
  cr_assert(strstr(errs, "param-sweep: runs were refused their input"), "%s", errs);
  cr_assert_eq(sh("test \"$(sort %s/f/sweep.refused | paste -sd' ')\" = "
                  "'init.splines=-1__seed-1 init.splines=-1__seed-2'", dir),
               0, "%s", lw_test_slurp("%s/f/sweep.refused", dir));
  csv t;
  char path[128];
  snprintf(path, sizeof path, "%s/f/sweep.csv", dir);
  csv_read(&t, path);
  cr_assert_eq(t.nrow, 2);
  for (int r = 0; r < 2; r++) cr_assert_str_eq(cell(&t, r, "init.splines"), "4");
  free(errs);
  free(t.text);
  /* the same sweep again: its refused runs stay planned (they are its own) */
  cr_assert_eq(sh("%s %s --vary init.splines=4,-1 --seeds 1-2 --set anneal.sweeps=20 --bin %s --out %s/f",
                  tool("param-sweep"), scene(), env("LW_BIN"), dir), 2);
  cr_assert_eq(sh("test $(grep -c 'init.splines=-1' %s/f/sweep.plan) = 2", dir), 0);
  /* the value corrected into the same --out: the refused runs leave the
  ** plan, which kept a gather failing for good */
  cr_assert_eq(sh("%s %s --vary init.splines=4,5 --seeds 1-2 --set anneal.sweeps=20 --bin %s --out %s/f",
                  tool("param-sweep"), scene(), env("LW_BIN"), dir), 0, "%s", err_txt());
  cr_assert_eq(sh("%s --gather-only %s/f && ! grep -qF init.splines=-1 %s/f/sweep.plan", tool("param-sweep"), dir, dir),
               0, "%s", err_txt());
  /* a refusal beside a failure of another kind (a file where a run's folder
  ** goes) is a failed sweep, exit 1, not bad input */
  cr_assert_eq(sh("mkdir %s/g && touch %s/g/init.splines=4__seed-1 && %s %s --vary init.splines=-1,4 --seeds 1 "
                  "--set anneal.sweeps=20 --bin %s --out %s/g", dir, dir, tool("param-sweep"), scene(), env("LW_BIN"),
                  dir), 1, "%s", err_txt());
}

/* A run stopped by a signal to it alone (here: --stop-at, which ends a run as
** a signal does, exit 0 without summary.json) is reported and the others go
** on (it returned xargs' 255, which started no further run); an idle key's
** note, in every run's log, is shown once; words sort the rows with the
** seeds of a point together; the same --set options in another order are
** the same sweep. */
Test(tools, a_run_stopped_alone_leaves_the_others_and_notes_reach_the_sweep)
{
  char fake[128];
  snprintf(fake, sizeof fake, "%s/fake-linewise", dir);
  FILE *f = fopen(fake, "w");
  cr_assert_not_null(f);
  fprintf(f,
          "#!/bin/sh\ncase \"$*\" in *schedule=linear*'exchange_every=5 --seed 1 '*) exec %s \"$@\" --stop-at 3 ;; "
          "esac\nexec %s \"$@\"\n",
          env("LW_BIN"), env("LW_BIN"));
  fclose(f);
  cr_assert_eq(chmod(fake, 0755), 0);
  const char *args = "%s %s --vary anneal.schedule=linear,geometric --vary tempering.exchange_every=5,10 --seeds 1-2 "
                     "-j 1 --set anneal.sweeps=20 --set init.splines=5 --bin %s --out %s/n";
  cr_assert_eq(sh(args, tool("param-sweep"), scene(), fake, dir), 1, "%s", err_txt());
  char *errs = err_txt(), *out = out_txt();
  cr_assert(strstr(errs, "anneal.schedule=linear__tempering.exchange_every=5__seed-1: stopped by a signal to it alone"),
            "%s", errs);
  const char *note = strstr(errs, "note: these keys have no effect here: tempering.exchange_every");
  cr_assert(note && !strstr(note + 1, "note: these keys"), "one note: %s", errs);
  cr_assert(strstr(out, "7 finished runs gathered"), "%s", out);
  csv t;
  char path[128];
  snprintf(path, sizeof path, "%s/n/sweep.csv", dir);
  csv_read(&t, path);
  cr_assert_eq(t.nrow, 7);
  static const char *const order[7][2] = {{"1", "geometric"}, {"2", "geometric"}, {"1", "geometric"},
                                          {"2", "geometric"}, {"2", "linear"},    {"1", "linear"},
                                          {"2", "linear"}};
  for (int r = 0; r < 7; r++)
    cr_assert(!strcmp(cell(&t, r, "seed"), order[r][0]) && !strcmp(cell(&t, r, "anneal.schedule"), order[r][1]),
              "row %d: seed %s, %s", r, cell(&t, r, "seed"), cell(&t, r, "anneal.schedule"));
  free(t.text);
  free(errs);
  free(out);
  /* the --set options swapped: the same sweep, whose stopped run resumes */
  cr_assert_eq(sh("%s %s --vary anneal.schedule=linear,geometric --vary tempering.exchange_every=5,10 --seeds 1-2 "
                  "-j 1 --set init.splines=5 --set anneal.sweeps=20 --bin %s --out %s/n",
                  tool("param-sweep"), scene(), env("LW_BIN"), dir), 0, "%s", err_txt());
  out = out_txt();
  cr_assert(strstr(out, "seed-1: resumed") && strstr(out, "8 finished runs gathered"), "%s", out);
  free(out);
}

Test(tools, job_array_tasks_then_gather_only)
{
  /* what Slurm does: one task per array index, then a gathering job */
  for (int i = 1; i <= 3; i++)
    cr_assert_eq(sh("SLURM_ARRAY_TASK_ID=%d SLURM_SUBMIT_DIR=%s %s %s --seeds 5-7 " TINY " --bin %s --out %s/j", i,
                    env("LW_ROOT"), tool("slurm-sweep.sbatch"), scene(), env("LW_BIN"), dir),
                 0, "task %d: %s", i, err_txt());
  char path[128];
  snprintf(path, sizeof path, "%s/j/sweep.csv", dir);
  cr_assert_neq(access(path, F_OK), 0, "a task does not gather");
  /* a task number with a leading zero is that number (08 read as octal was refused) */
  cr_assert_eq(sh("%s %s --seeds 5-14 " TINY " --bin %s --out %s/z --task 08", tool("seed-sweep"), scene(),
                  env("LW_BIN"), dir),
               0, "%s", err_txt());
  char *zo = out_txt();
  cr_assert(strstr(zo, "[8/10] seed-12: ran"), "%s", zo);
  free(zo);
  cr_assert_eq(sh("%s --gather-only %s/j", tool("seed-sweep"), dir), 0, "%s", err_txt());
  /* a gather after an array where a task did not finish fails, naming it
  ** (it said "3 finished runs gathered" with exit 0, so the dependent job of
  ** the recipe passed); the table holds the finished ones */
  cr_assert_eq(sh("rm %s/j/seed-6/summary.json && mkdir %s/j/seed-9 && %s --gather-only %s/j", dir, dir,
                  tool("seed-sweep"), dir), 1);
  char *errs = err_txt();
  cr_assert(strstr(errs, "/j/seed-6: not finished: stopped on the way (rerun the sweep to resume it)\n") &&
                strstr(errs, "1 of 3 planned runs have not finished; sweep.csv holds the 2 that have\n") &&
                !strstr(errs, "seed-9"), "%s", errs);
  free(errs);
  cr_assert_eq(sh("SLURM_ARRAY_TASK_ID=2 SLURM_SUBMIT_DIR=%s %s %s --seeds 5-7 " TINY " --bin %s --out %s/j && "
                  "%s --gather-only %s/j", env("LW_ROOT"), tool("slurm-sweep.sbatch"), scene(), env("LW_BIN"), dir,
                  tool("seed-sweep"), dir), 0, "%s", err_txt());
  /* a sweep directory of an older release (no sweep.plan): its runs by
  ** their names, a folder of one's own beside them none */
  cr_assert_eq(sh("mv %s/j/sweep.plan %s/plan && rmdir %s/j/seed-9 && mkdir %s/j/notes && %s --gather-only %s/j", dir,
                  dir, dir, dir, tool("seed-sweep"), dir), 0, "%s", err_txt());
  cr_assert_eq(sh("rm %s/j/seed-5/summary.json && %s --gather-only %s/j", dir, tool("seed-sweep"), dir), 1);
  errs = err_txt();
  cr_assert(strstr(errs, "1 of 3 planned runs have not finished") && !strstr(errs, "notes"), "%s", errs);
  free(errs);
  /* a plan's name with a terminal's control bytes (a shared sweep's): shown
  ** as ?, as linewise shows them (it set the title and cleared the screen) */
  cr_assert_eq(sh("cp %s/plan %s/plan.kept && printf '\\033[2Jx\\n' >> %s/plan && mv %s/plan %s/j/sweep.plan && "
                  "%s --gather-only %s/j", dir, dir, dir, dir, dir, tool("seed-sweep"), dir), 1);
  errs = err_txt();
  cr_assert(strstr(errs, "/j/?[2Jx: not finished: never started\n") && !strchr(errs, '\033'), "%s", errs);
  free(errs);
  cr_assert_eq(sh("mv %s/plan.kept %s/plan", dir, dir), 0);
  cr_assert_eq(sh("mv %s/plan %s/j/sweep.plan && SLURM_ARRAY_TASK_ID=1 SLURM_SUBMIT_DIR=%s %s %s --seeds 5-7 " TINY
                  " --bin %s --out %s/j && %s --gather-only %s/j", dir, dir, env("LW_ROOT"), tool("slurm-sweep.sbatch"),
                  scene(), env("LW_BIN"), dir, tool("seed-sweep"), dir), 0, "%s", err_txt());
  csv t;
  csv_read(&t, path);
  cr_assert_eq(t.nrow, 3);
  for (int r = 0; r < 3; r++) {
    char run[32];
    snprintf(run, sizeof run, "j/seed-%d", r + 5);
    cr_assert_eq(atoi(cell(&t, r, "seed")), r + 5);
    row_matches_summary(&t, r, run);
  }
  /* a task outside the plan is a usage error */
  cr_assert_eq(sh("SLURM_ARRAY_TASK_ID=4 SLURM_SUBMIT_DIR=%s %s %s --seeds 5-7 " TINY " --bin %s --out %s/j",
                  env("LW_ROOT"), tool("slurm-sweep.sbatch"), scene(), env("LW_BIN"), dir),
               2);
  /* an array past the site's largest index is split, each part told the
  ** runs before it: task 1 after 2 runs is run 3 (seed 7); a missing task
  ** or a bad offset is a usage error, exit 2 (bash's ${VAR:?} exited 1) */
  cr_assert_eq(sh("rm -r %s/j/seed-7 && SLURM_ARRAY_TASK_ID=1 LINEWISE_TASK_OFFSET=2 SLURM_SUBMIT_DIR=%s %s %s --seeds "
                  "5-7 " TINY " --bin %s --out %s/j > %s/o.txt && grep -q 'seed-7: ran' %s/o.txt", dir,
                  env("LW_ROOT"), tool("slurm-sweep.sbatch"), scene(), env("LW_BIN"), dir, dir, dir),
               0, "%s", err_txt());
  cr_assert_eq(sh("SLURM_SUBMIT_DIR=%s %s %s --seeds 5-7 --out %s/j", env("LW_ROOT"), tool("slurm-sweep.sbatch"),
                  scene(), dir), 2);
  cr_assert_eq(sh("SLURM_ARRAY_TASK_ID=1 LINEWISE_TASK_OFFSET=x SLURM_SUBMIT_DIR=%s %s %s --seeds 5-7 --out %s/j",
                  env("LW_ROOT"), tool("slurm-sweep.sbatch"), scene(), dir), 2);
  free(t.text);
  /* LINEWISE_TOOLS naming an install's bin/ (linewise-param-sweep there) */
  cr_assert_eq(sh("mkdir -p %s/inst && ln -sf %s %s/inst/linewise-param-sweep && SLURM_ARRAY_TASK_ID=1 "
                  "SLURM_SUBMIT_DIR=/nonexistent LINEWISE_TOOLS=%s/inst %s %s --seeds 8 " TINY " --bin %s --out %s/i",
                  dir, tool("param-sweep"), dir, dir, tool("slurm-sweep.sbatch"), scene(), env("LW_BIN"), dir),
               0, "%s", err_txt());
}

/* slurm-tempering.sbatch hands srun the run with --threads: after the
** user's arguments it followed a "--" that ended the options, and the run
** took it for a second scene.  srun stood in for by a script that drops its
** own options and runs the rest, the plain binary for linewise-mpi. */
Test(tools, the_tempering_job_keeps_a_scene_after_the_end_of_options)
{
  cr_assert_eq(sh("mkdir -p %s/fake && printf '#!/bin/sh\\nwhile [ \"${1#--}\" != \"$1\" ]; do shift; done\\n"
                  "exec \"$@\"\\n' "
                  "> %s/fake/srun && chmod +x %s/fake/srun && cp %s %s/-x.ini && cd %s && PATH=%s/fake:$PATH "
                  "LINEWISE_MPI=%s SLURM_CPUS_PER_TASK=1 bash %s run --set tempering.replicas=2 " TINY " --quiet --out "
                  "pt -- -x.ini && test -s pt/summary.json", dir, dir, dir, scene(), dir, dir, dir, env("LW_BIN"),
                  tool("slurm-tempering.sbatch")),
               0, "%s", err_txt());
}

/* A file the scene names (here its schedule's table, beside it) changed
** under a finished sweep: the rerun is refused naming it, where it skipped
** the finished runs and gathered them beside new ones of the other file, one
** table of two scenes; the same file again, or a sweep.conf from before the
** files were named, reruns as before. */
Test(tools, a_file_the_scene_names_changed_under_a_sweep_is_refused)
{
  cr_assert_eq(sh("mkdir %s/sc && cd %s/sc && printf '0 0.5\\n1 0.1\\n' > t.txt && printf '[scene]\\nwidth = 60\\n"
                  "height = 60\\n[anneal]\\nschedule = table\\ntable = t.txt ; the schedule\\n' > s.ini && true",
                  dir, dir),
               0);
  const char *sweep = "%s %s/sc/s.ini --seeds %s " TINY " --bin %s --out %s/w";
  cr_assert_eq(sh(sweep, tool("seed-sweep"), dir, "1", env("LW_BIN"), dir), 0, "%s", err_txt());
  cr_assert_eq(sh("grep -qx 'file anneal.table [0-9]* 12' %s/w/sweep.conf", dir), 0, "%s",
               lw_test_slurp("%s/w/sweep.conf", dir));
  cr_assert_eq(sh(sweep, tool("seed-sweep"), dir, "1-2", env("LW_BIN"), dir), 0, "%s", err_txt());
  cr_assert_eq(sh("printf '0 0.4\\n1 0.1\\n' > %s/sc/t.txt && true", dir), 0);
  cr_assert_eq(sh(sweep, tool("seed-sweep"), dir, "1-3", env("LW_BIN"), dir), 2);
  char *e = err_txt();
  cr_assert(strstr(e, "/w/sweep.conf: this directory holds a sweep of another scene, --set or --vary keys, or of "
                      "files they name (it has: file anneal.table ") && !strstr(e, "seed-3"), "%s", e);
  free(e);
  /* a sweep.conf of before: no file lines, the same sweep */
  cr_assert_eq(sh("sed -i '/^file /d' %s/w/sweep.conf", dir), 0);
  cr_assert_eq(sh(sweep, tool("seed-sweep"), dir, "1-2", env("LW_BIN"), dir), 0, "%s", err_txt());
  /* inih's other spellings, a BOM and 'key: value', and a --vary over files
  ** (each value's file; the scene's own, which no run reads, is not) */
  cr_assert_eq(sh("cd %s/sc && cp t.txt u.txt && printf '\\357\\273\\277[anneal]\\nschedule = table\\n"
                  "table: t.txt\\n[scene]\\nwidth = 60\\nheight = 60\\n' > b.ini && true", dir),
               0);
  const char *vary = "cd %s/sc && %s b.ini --seeds 1 %s " TINY " --bin %s --out %s/%s";
  cr_assert_eq(sh(vary, dir, tool("param-sweep"), "", env("LW_BIN"), dir, "b"), 0, "%s", err_txt());
  cr_assert_eq(sh(vary, dir, tool("param-sweep"), "--vary anneal.table=t.txt,u.txt", env("LW_BIN"), dir, "v"), 0,
               "%s", err_txt());
  cr_assert_eq(sh("grep -q '^file anneal.table ' %s/b/sweep.conf && grep -q '^file anneal.table=u.txt ' "
                  "%s/v/sweep.conf && ! grep -q '^file anneal.table ' %s/v/sweep.conf", dir, dir, dir),
               0);
  cr_assert_eq(sh("printf '0 0.3\\n1 0.1\\n' > %s/sc/u.txt && true", dir), 0);
  cr_assert_eq(sh(vary, dir, tool("param-sweep"), "--vary anneal.table=t.txt,u.txt", env("LW_BIN"), dir, "v"), 2);
  cr_assert(strstr(lw_test_slurp("%s/err.txt", dir), "(it has: file anneal.table=u.txt "), "%s",
            lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(sh("printf '0 0.2\\n1 0.1\\n' > %s/sc/t.txt && true", dir), 0);
  cr_assert_eq(sh(vary, dir, tool("param-sweep"), "", env("LW_BIN"), dir, "b"), 2);
}

/* Two job arrays of other settings started together into one --out: the
** second's tasks are refused while the first's run (each ran with its own
** settings, and sweep.conf named one of them); with none running and no run
** kept, the directory is the new sweep's, as after a --set typo.  A task of
** the first array holds .sweep.running: here flock stands in for it. */
Test(tools, a_sweep_of_other_settings_is_refused_while_one_runs)
{
  cr_assert_eq(sh("%s %s --seeds 1 --set energy.bending=abc --bin %s --out %s/r", tool("seed-sweep"), scene(),
                  env("LW_BIN"), dir), 2);
  cr_assert_eq(sh("flock -s %s/r/.sweep.running env SLURM_ARRAY_TASK_ID=1 SLURM_SUBMIT_DIR=%s %s %s --seeds 1 " TINY
                  " --bin %s --out %s/r", dir, env("LW_ROOT"), tool("slurm-sweep.sbatch"), scene(), env("LW_BIN"), dir),
               2);
  char *errs = err_txt();
  cr_assert(strstr(errs, "/r/sweep.conf: a sweep is running in this directory of another scene, --set or --vary keys, "
                         "or of files they name (it has: set energy.bending=abc; this sweep: set anneal.sweeps=20;"),
            "%s", errs);
  free(errs);
  cr_assert_eq(sh("SLURM_ARRAY_TASK_ID=1 SLURM_SUBMIT_DIR=%s %s %s --seeds 1 " TINY " --bin %s --out %s/r",
                  env("LW_ROOT"), tool("slurm-sweep.sbatch"), scene(), env("LW_BIN"), dir), 0, "%s", err_txt());
  cr_assert_eq(sh("grep -qx 'set anneal.sweeps=20' %s/r/sweep.conf && test -s %s/r/seed-1/summary.json", dir, dir), 0);
  /* where the lock files cannot be locked (a file system without flock),
  ** the check is made without them, as before */
  cr_assert_eq(sh("mkdir %s/fl", dir), 0);
  write_script("fl/flock", "#!/bin/sh\nexit 1\n");
  cr_assert_eq(sh("PATH=%s/fl:$PATH SLURM_ARRAY_TASK_ID=1 SLURM_SUBMIT_DIR=%s %s %s --seeds 1 " TINY " --bin %s --out "
                  "%s/n && test -s %s/n/seed-1/summary.json", dir, env("LW_ROOT"), tool("slurm-sweep.sbatch"), scene(),
                  env("LW_BIN"), dir, dir), 0, "%s", err_txt());
}

/* A lock planted as a link had the sweep's open make the file it named
** (another user's, in a shared sweep folder), and a FIFO there held the sweep
** forever: both are refused with one line.  The sweep's own notes lay at
** names made of one mktemp name (.sweep-notes.X.rc, .xargs), known while it
** ran: they are in a directory of their own, which only the sweep may write. */
Test(tools, a_sweep_takes_no_lock_that_is_a_link_or_no_file)
{
  static const char *const lock[] = {".sweep.lock", ".sweep.running"};
  for (int k = 0; k < 2; k++) {
    cr_assert_eq(sh("rm -rf %s/l && mkdir %s/l && ln -s %s/victim %s/l/%s", dir, dir, dir, dir, lock[k]), 0);
    cr_assert_eq(sh("%s %s --seeds 1 " TINY " --bin %s --out %s/l", tool("seed-sweep"), scene(), env("LW_BIN"), dir),
                 2, "%s", lock[k]);
    char *e = err_txt();
    cr_assert(strstr(e, lock[k]) && strstr(e, "a symbolic link") && strchr(e, '\n') == e + strlen(e) - 1, "%s", e);
    free(e);
    cr_assert(!exists("victim"), "%s: the file a planted link names was made", lock[k]);
    cr_assert(!exists("l/seed-1"), "%s: a run started", lock[k]);
  }
  cr_assert_eq(sh("rm -rf %s/l && mkdir %s/l && mkfifo %s/l/.sweep.lock && timeout 20 %s %s --seeds 1 " TINY
                  " --bin %s --out %s/l", dir, dir, dir, tool("seed-sweep"), scene(), env("LW_BIN"), dir), 2,
               "a FIFO as the lock");
  char *e = err_txt();
  cr_assert(strstr(e, ".sweep.lock: a symbolic link or not a plain file"), "%s", e);
  free(e);
  /* what a run sees of the notes: a file in a directory of the sweep's own
  ** (0700), not beside the runs */
  write_script("notes-linewise", "#!/bin/sh\nd=${LW_SWEEP_NOTES%%/*}\nstat -c '%%a %%n' \"$d\" >>%s/notes.txt\n"
               "exec %s \"$@\"\n", dir, env("LW_BIN"));
  cr_assert_eq(sh("%s %s --seeds 1 " TINY " --bin %s/notes-linewise --out %s/m", tool("seed-sweep"), scene(), dir,
                  dir), 0, "%s", err_txt());
  char *notes = lw_test_slurp("%s/notes.txt", dir), want[128];
  snprintf(want, sizeof want, "700 %s/m/.sweep-notes.", dir);
  cr_assert(notes && !strncmp(notes, want, strlen(want)), "%s", notes ? notes : "(none)");
  free(notes);
  cr_assert_eq(sh("test -z \"$(ls -A %s/m | grep notes)\"", dir), 0, "the notes left behind");
  /* a sweep killed outright (SIGKILL) never ran its EXIT trap: its notes go
  ** with the next sweep into the directory */
  cr_assert_eq(sh("mkdir %s/m/.sweep-notes.kiLLed && : >%s/m/.sweep-notes.kiLLed/notes && %s %s --seeds 1 " TINY
                  " --bin %s --out %s/m", dir, dir, tool("seed-sweep"), scene(), env("LW_BIN"), dir),
               0, "%s", err_txt());
  cr_assert(!exists("m/.sweep-notes.kiLLed"), "a killed sweep's notes were left for good");
  /* a run's folder planted as a link: the run was written where it pointed
  ** and left out of the table unsaid, exit 0 */
  cr_assert_eq(sh("rm -r %s/m/seed-1 && mkdir %s/vict && ln -s ../vict %s/m/seed-1 && %s %s --seeds 1 " TINY
                  " --bin %s --out %s/m", dir, dir, dir, tool("seed-sweep"), scene(), env("LW_BIN"), dir), 1);
  e = err_txt();
  cr_assert(strstr(e, "[1/1] seed-1: FAILED: ") && strstr(e, "/m/seed-1: a symbolic link; a sweep writes its runs only "
                                                         "into its own directory: remove it\n"), "%s", e);
  free(e);
  cr_assert_eq(sh("test -z \"$(ls -A %s/vict)\"", dir), 0, "a run was written through the link");
}

/* xargs's status reached the sweep through a file, which a full disk left
** empty: "integer expression expected", and a sweep whose run failed exited
** 0.  Here the file reads back empty as on a full disk (a link to
** /dev/null, planted at its name once xargs returns); a failed run is a
** failed sweep whatever became of such a file. */
Test(tools, a_failed_run_fails_the_sweep_on_a_full_disk)
{
  cr_assert_eq(sh("mkdir %s/px", dir), 0);
  write_script("px/xargs", "#!/bin/sh\n%s \"$@\"\nrc=$?\nln -sf /dev/null \"$LW_SWEEP_NOTES.rc\"\nexit $rc\n",
               "$(PATH=/usr/local/bin:/usr/bin:/bin command -v xargs)");
  int rc = sh("PATH=%s/px:$PATH %s %s --vary init.splines=4,-1 --seeds 1 --set anneal.sweeps=20 --bin %s --out %s/f",
              dir, tool("param-sweep"), scene(), env("LW_BIN"), dir);
  char *e = err_txt();
  cr_assert_eq(rc, 2, "%s", e);
  cr_assert(strstr(e, "runs were refused their input") && !raw_error(e), "%s", e);
  free(e);
}

/* On a file system without symbolic links (FAT, some network shares) a
** whole sweep exits 0 and names its best run (it said "could not link" and
** exited 1 every time); ln is faked to fail as FAT's does. */
Test(tools, a_sweep_where_no_link_can_be_made_names_its_best_run)
{
  cr_assert_eq(sh("cd %s && mkdir fake && printf '#!/bin/sh\necho \"ln: failed to create symbolic link: Operation not "
                  "permitted\" >&2; exit 1\n' > fake/ln && chmod +x fake/ln && PATH=$PWD/fake:$PATH bash %s %s "
                  "--seeds 1-2 -j 1 --bin %s " TINY " --out s", dir, tool("seed-sweep"), scene(), env("LW_BIN")),
               0, "%s", err_txt());
  char *out = out_txt();
  cr_assert(strstr(out, "seed-sweep: best run: seed-") &&
                strstr(out, " (this file system takes no symbolic links, so s/best is not made)\n"), "%s", out);
  free(out);
  cr_assert_eq(sh("test ! -e %s/s/best && test -s %s/s/sweep.csv", dir, dir), 0);
  /* a gather alone still fails where a planned run has not finished */
  cr_assert_eq(sh("cd %s && rm -r s/seed-2 && PATH=$PWD/fake:$PATH bash %s --gather-only s", dir, tool("seed-sweep")),
               1);
  char *e = err_txt();
  cr_assert(strstr(e, "seed-sweep: 1 of 2 planned runs have not finished"), "%s", e);
  free(e);
}

/* A run another process writes (a second sweep into the same directory) is
** said so, by this attempt's own line of the shared log (the last line, a
** progress line of the other run, was given as the reason), and the gather
** says it is still running, not stopped. */
Test(tools, a_run_another_process_writes_is_said_running)
{
  cr_assert_eq(sh("%s run %s --seed 1 --stop-at 2 --out %s/s/seed-1 --quiet " TINY " && echo 'sweep 10/20 T 0.1' >> "
                  "%s/s/seed-1/linewise.log", env("LW_BIN"), scene(), dir, dir),
               0, "%s", err_txt());
  char path[128];
  snprintf(path, sizeof path, "%s/s/seed-1/.lock", dir);
  int fd = open(path, O_RDWR);
  cr_assert(fd >= 0 && flock(fd, LOCK_EX | LOCK_NB) == 0, "the test takes the lock");
  cr_assert_eq(sh("bash %s %s --seeds 1-2 -j 1 --bin %s " TINY " --out %s/s", tool("seed-sweep"), scene(),
                  env("LW_BIN"), dir),
               1);
  close(fd);
  char *e = err_txt();
  cr_assert(strstr(e, "[1/2] seed-1: FAILED (exit 2): linewise: ") &&
                strstr(e, "seed-1: another linewise process is writing this run directory") &&
                strstr(e, "/s/seed-1: not finished: still running in another process (a task of this sweep, or a "
                          "second sweep)"), "%s", e);
  free(e);
  /* a run that failed for its own reason while a second sweep's refusal
  ** went into the log after its line is given its own (exit 1, not the
  ** busy directory's 2); a line before this attempt is none of its */
  write_script("raced-linewise", "#!/bin/sh\necho 'linewise: t.csv: write failed: No space left on device'\n"
               "echo 'linewise: s2/seed-1: another linewise process is writing this run directory (it holds "
               "s2/seed-1/.lock)'\nexit 1\n");
  cr_assert_eq(sh("mkdir -p %s/s2/seed-1 && echo 'linewise: an earlier line' > %s/s2/seed-1/linewise.log && "
                  "bash %s %s --seeds 1 -j 1 --bin %s/raced-linewise " TINY " --out %s/s2", dir, dir,
                  tool("seed-sweep"), scene(), dir, dir),
               1);
  e = err_txt();
  cr_assert(strstr(e, "[1/1] seed-1: FAILED (exit 1): linewise: t.csv: write failed: No space left on device\n"), "%s",
            e);
  free(e);
}

/* A finished sweep another user made, in a directory this one may only
** read, is gathered again by the same command, every run skipped (its
** notes went into the directory: refused at once), and the table it may
** not write is said, exit 2 (a place the user chose, not a failed run). */
Test(tools, a_finished_sweep_another_user_made_is_read_not_refused)
{
  if (geteuid() || sh("setpriv --reuid=65534 --regid=65534 --clear-groups bash %s --help", tool("seed-sweep")))
    cr_skip_test("needs root, setpriv, and tools user nobody may run");
  char cmd[3500];
  snprintf(cmd, sizeof cmd, "bash %s %s --seeds 1-2 -j 1 --bin %s " TINY " --out %s/s", tool("seed-sweep"), scene(),
           env("LW_BIN"), dir);
  cr_assert_eq(sh("{ %s && chmod 755 %s; }", cmd, dir), 0, "%s", err_txt());
  /* (TMPDIR /tmp: the suite's may be root's alone, as a package build's) */
  cr_assert_eq(sh("cd / && TMPDIR=/tmp setpriv --reuid=65534 --regid=65534 --clear-groups %s", cmd), 2, "%s",
               err_txt());
  char *out = out_txt(), *e = err_txt();
  cr_assert(strstr(out, "[1/2] seed-1: finished already") && strstr(out, "[2/2] seed-2: finished already"), "%s",
            out);
  cr_assert(strstr(e, "/s/sweep.csv: could not write: Permission denied\n") && !strstr(e, "cannot create a file"),
            "%s", e);
  free(out);
  free(e);
}

/* A run's log that cannot be made (a full disk, no inodes left; here a
** directory in its place) left a reason of nothing after "FAILED (exit 1): "
** among bash's and tail's words, and pointed at a log that is not there; a
** log a full disk left empty (here: a linewise that says nothing) said
** nothing either; a run directory that cannot be made, and a sweep.conf that
** cannot be written (a file-size limit, as a full disk), said it twice, the
** tool's line and the sweep's.  Each is one line of the sweep's. */
Test(tools, a_run_whose_log_cannot_be_written_is_said_so)
{
  write_script("quiet-linewise", "#!/bin/sh\ncase \"$*\" in *'--seed 2 '*) exit 1 ;; esac\nexec %s \"$@\"\n",
               env("LW_BIN"));
  cr_assert_eq(sh("mkdir -p %s/g/seed-3/linewise.log && touch %s/g/seed-4", dir, dir), 0);
  cr_assert_eq(sh("%s %s --seeds 1-4 -j 1 " TINY " --bin %s/quiet-linewise --out %s/g", tool("seed-sweep"), scene(),
                  dir, dir), 1);
  char *e = err_txt();
  cr_assert(!raw_error(e), "%s", e);
  cr_assert(strstr(e, "seed-2: FAILED (exit 1): it wrote nothing into its linewise.log"), "%s", e);
  cr_assert(strstr(e, "seed-3: FAILED: its linewise.log could not be written (Is a directory); the run was not "
                      "started\n"), "%s", e);
  cr_assert(strstr(e, "seed-3: not finished: failed or not started (it has no linewise.log to say which)"), "%s", e);
  cr_assert(strstr(e, "seed-4: FAILED: ") && strstr(e, "/g/seed-4: cannot create directory: File exists\n"), "%s",
            e);
  free(e);
  cr_assert_eq(sh("test -s %s/g/seed-1/summary.json", dir), 0, "the other runs go on");
  /* (its words through a pipe: the limit holds for every file it writes) */
  cr_assert_eq(sh("(trap '' XFSZ; ulimit -f 0; %s %s --seeds 1 " TINY " --bin %s --out %s/c 2>&1; echo \"exit $?\") | "
                  "cat", tool("seed-sweep"), scene(), env("LW_BIN"), dir), 0);
  e = out_txt();
  cr_assert(strstr(e, "/c/sweep.conf: cannot write: File too large\nexit 1\n") && strchr(e, '\n') < strstr(e, "exit"),
            "%s", e);
  free(e);
}

Test(tools, bad_usage_exits_2_with_one_message_and_writes_nothing)
{
  const char *bad[][2] = {
    {"--seeds 3-1", "backwards"},
    {"--seeds 1,x", "'x'"},
    {"", "--seeds"},
    {"--seeds 1,1", "twice"},
    {"--seeds 1 --seeds 1-2", "seed 1 is listed twice: in '1' and in '1-2'"}, /* two runs shared a directory */
    {"--seeds 1 --vary anneal.seed=1,2", "--seeds"},
    /* (the runs took --seeds' and --vary's values, sweep.conf the --set's) */
    {"--seeds 1 --set anneal.seed=5", "--set anneal.seed: every run's seed comes from --seeds"},
    {"--seeds 1 --set anneal.sweeps=20 --vary anneal.sweeps=10,30", "varied by --vary too"},
    {"--seeds 1 --vary scene.width=a/b", "scene.width"},
    {"--seeds 1 --vary width=3", "section.key"},
    {"--seeds 1 -j 0", "-j"},
    {"--seeds 1 --frobnicate", "frobnicate"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    cr_assert_eq(sh("%s %s %s --bin %s --out %s/u", tool("param-sweep"), scene(), bad[i][0], env("LW_BIN"), dir), 2,
                 "'%s'", bad[i][0]);
    char *errs = err_txt();
    cr_assert(strstr(errs, bad[i][1]), "'%s': %s", bad[i][0], errs);
    cr_assert_eq(strchr(errs, '\n'), errs + strlen(errs) - 1, "one line: %s", errs);
    free(errs);
  }
  char path[128];
  snprintf(path, sizeof path, "%s/u", dir);
  cr_assert_neq(access(path, F_OK), 0, "nothing written");
  /* a directory made by another sweep is refused: its runs would be stale */
  cr_assert_eq(sh("%s %s --seeds 1 " TINY " --bin %s --out %s/u", tool("seed-sweep"), scene(), env("LW_BIN"), dir), 0);
  cr_assert_eq(sh("%s %s --seeds 1 --set anneal.sweeps=30 --bin %s --out %s/u", tool("seed-sweep"), scene(),
                  env("LW_BIN"), dir), 2);
  char *errs = err_txt();
  cr_assert(strstr(errs, "sweep.conf"), "%s", errs);
  free(errs);
  /* but a sweep whose every run was refused (a --set typo) left nothing to
  ** guard, and the corrected one takes its directory */
  cr_assert_eq(sh("%s %s --seeds 1,2 --set energy.bending=abc --bin %s --out %s/t", tool("seed-sweep"), scene(),
                  env("LW_BIN"), dir), 2);
  cr_assert_eq(sh("%s %s --seeds 1,2 " TINY " --bin %s --out %s/t", tool("seed-sweep"), scene(), env("LW_BIN"), dir),
               0, "%s", err_txt());
  cr_assert_eq(sh("test -s %s/t/seed-1/summary.json && test -s %s/t/seed-2/summary.json", dir, dir), 0);
  cr_assert_eq(sh("%s --gather-only %s", tool("seed-sweep"), dir), 2, "not a sweep directory");
  /* every tool: --help prints its usage (exit 0), nothing at all is bad usage (exit 2) */
  static const char *const all[] = {"seed-sweep", "param-sweep", "plot-run", "plot-sweep", "animate.sh"};
  for (size_t i = 0; i < sizeof all / sizeof *all; i++) {
    cr_assert_eq(sh("%s --help > %s/help.txt && grep -q usage %s/help.txt", tool(all[i]), dir, dir), 0, "%s --help",
                 all[i]);
    cr_assert_eq(sh("%s", tool(all[i])), 2, "%s without arguments", all[i]);
  }
  /* a frame rate that is no number above 0 is the script's usage error,
  ** before ffmpeg (which said "Unable to parse option value") */
  cr_assert_eq(sh("mkdir -p %s/an/frames && : > %s/an/frames/frame-000000.png", dir, dir), 0);
  static const char *const fps[] = {"0", "abc", "-1", "1.2.3", "0.0"};
  for (size_t i = 0; i < sizeof fps / sizeof *fps; i++)
    cr_assert_eq(sh("%s %s/an '%s' 2> %s/an.err; test $? -eq 2 && grep -q \"FPS: expected a number above 0, got "
                    "'%s'\" %s/an.err", tool("animate.sh"), dir, fps[i], dir, fps[i], dir), 0, "FPS %s", fps[i]);
  /* ffmpeg is given no input: it reads one for keys, and ate the rest of a
  ** `while read` loop's list of runs (a stand-in ffmpeg that would read it) */
  cr_assert_eq(sh("mkdir -p %s/ff && printf 'n=0; while read -r l; do n=$((n+1)); done; echo $n > %s/ff/read; "
                  "for a; do out=$a; done; : > \"$out\"\\n' > %s/ff/ffmpeg && chmod +x %s/ff/ffmpeg", dir, dir, dir,
                  dir), 0);
  cr_assert_eq(sh("cd %s && printf 'an\\nan\\n' | while read -r d; do PATH=%s/ff:$PATH %s \"$d\" || exit 1; done && "
                  "test \"$(cat ff/read)\" = 0 && test -e an/animation.mp4", dir, dir, tool("animate.sh")), 0, "%s",
               err_txt());
  /* a FIFO among the frames (an archive can carry one), or as plot-run's
  ** trace: it held ffmpeg, or the script, for ever, deaf to SIGTERM */
  cr_assert_eq(sh("mkfifo %s/an/frames/frame-000001.png && PATH=%s/ff:$PATH timeout -s KILL 20 %s %s/an", dir, dir,
                  tool("animate.sh"), dir), 2);
  cr_assert(strstr(err_txt(), "an/frames/frame-000001.png: not a regular file\n"), "%s", err_txt());
  cr_assert_eq(sh("rm %s/an/frames/frame-000001.png && mkdir %s/fr && mkfifo %s/fr/trace.csv && timeout -s KILL 20 %s "
                  "%s/fr", dir, dir, dir, tool("plot-run"), dir), 2);
  cr_assert(strstr(err_txt(), "fr/trace.csv: not a regular file\n"), "%s", err_txt());
  /* a run another user may only read: said so, exit 2 (mktemp's words and
  ** exit 1 before) */
  if (geteuid() || sh("setpriv --reuid=65534 --regid=65534 --clear-groups sh %s --help", tool("animate.sh"))) return;
  cr_assert_eq(sh("chmod 755 %s && cd %s && PATH=%s/ff:$PATH setpriv --reuid=65534 --regid=65534 --clear-groups sh %s "
                  "an", dir, dir, dir, tool("animate.sh")),
               2);
  char *e = err_txt();
  cr_assert(!strcmp(e, "animate.sh: an: cannot write animation.mp4 there: Permission denied (copy the run's frames to "
                       "a folder of your own)\n"), "%s", e);
  free(e);
}

/* ---- plots ------------------------------------------------------------ */

/* A PNG: signature, then the IHDR chunk with a non-zero size, and more than
** a blank canvas's worth of bytes. */
static void check_png(const char *name)
{
  char path[256];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "rb");
  cr_assert_not_null(f, "%s missing", name);
  unsigned char h[24];
  cr_assert_eq(fread(h, 1, 24, f), 24);
  fseek(f, 0, SEEK_END);
  long size = ftell(f);
  fclose(f);
  cr_assert(!memcmp(h, "\x89PNG\r\n\x1a\n", 8), "%s: no PNG signature", name);
  cr_assert(!memcmp(h + 12, "IHDR", 4));
  unsigned w = (unsigned)h[16] << 24 | h[17] << 16 | h[18] << 8 | h[19];
  unsigned ht = (unsigned)h[20] << 24 | h[21] << 16 | h[22] << 8 | h[23];
  cr_assert(w >= 320 && ht >= 240, "%s: %ux%u", name, w, ht);
  cr_assert(size > 8000, "%s: only %ld bytes", name, size);
}

static int exists(const char *name)
{
  char path[256];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  return access(path, F_OK) == 0;
}

/* Names a shell script mishandles: xargs -I{} once put each task number into
** a "{}" of the arguments too (the runs went to "runs 1/", "runs 2/"); awk
** read a relative operand "v=2/..." as an assignment (an empty sweep.csv,
** plot-run waiting on stdin); gnuplot took a file "<cmd" as a pipe. */
Test(tools, sweeps_and_plots_take_any_directory_name)
{
  cr_assert_eq(sh("cd %s && %s %s --seeds 1-2 -j 2 " TINY " --bin %s --out 'v=2 {}' </dev/null", dir,
                  tool("seed-sweep"), scene(), env("LW_BIN")),
               0, "%s", err_txt());
  char *out = out_txt();
  cr_assert(strstr(out, "2 finished runs gathered into v=2 {}/sweep.csv"), "%s", out);
  free(out);
  cr_assert_eq(sh("test $(wc -l < '%s/v=2 {}/sweep.csv') -eq 3 && test ! -e '%s/v=2 1'", dir, dir), 0,
               "the runs went elsewhere, or sweep.csv lacks them");
  cr_assert_eq(sh("cd %s && mv 'v=2 {}/seed-1' '<touch made;x' && %s '<touch made;x' </dev/null", dir,
                  tool("plot-run")),
               0, "%s", err_txt());
  check_png("<touch made;x/plots/energy.png");
  cr_assert(!exists("made"), "plot-run ran a directory's name as a command");
  cr_assert_eq(sh("cd '%s/v=2 {}' && %s sweep.csv --out 'v=3.png' </dev/null", dir, tool("plot-sweep")), 0, "%s",
               err_txt());
  check_png("v=2 {}/v=3.png");
}

/* The word after "--" is the scene whatever it is named, and a scene named
** like an option is said a file where it is taken for one; options may
** follow it, as the sweep's own tasks and the Slurm recipe append --task
** (once every task failed), and after a scene named before it "--" is
** nothing more (a wrapper's trailing one: every task failed).  A newline
** in the scene's path is refused before anything is made (it split
** sweep.conf's line, and every run failed).  The cores a sweep counts are
** the machine's, whatever OMP_NUM_THREADS says (nproc answers it: a
** login's =1 ran one run at a time). */
Test(tools, a_scene_named_like_an_option_follows_double_dash)
{
  cr_assert_eq(sh("cd %s && cp %s ./-m.ini", dir, scene()), 0);
  cr_assert_eq(sh("cd %s && %s -m.ini --seeds 1", dir, tool("seed-sweep")), 2);
  char *errs = err_txt();
  cr_assert(strstr(errs, "unknown option '-m.ini' (try 'seed-sweep --help'; a file of that name: ./-m.ini)"), "%s",
            errs);
  free(errs);
  cr_assert_eq(sh("cd %s && %s --seeds 1-2 -j 2 " TINY " --bin %s --out sw -- -m.ini </dev/null", dir,
                  tool("seed-sweep"), env("LW_BIN")), 0, "%s", err_txt());
  cr_assert_eq(sh("cd %s && test -s sw/seed-1/summary.json && test -s sw/seed-2/summary.json && "
                  "test $(wc -l < sw/sweep.csv) -eq 3", dir), 0);
  cr_assert_eq(sh("cd %s && %s --seeds 1-3 " TINY " --bin %s --out sw -- -m.ini --threads 1 --task 3 </dev/null", dir,
                  tool("seed-sweep"), env("LW_BIN")), 0, "%s", err_txt());
  cr_assert_eq(sh("cd %s && %s %s --seeds 1 " TINY " --bin %s --out tr -- </dev/null", dir, tool("seed-sweep"),
                  scene(), env("LW_BIN")), 0, "%s", err_txt());
  cr_assert_eq(sh("cd %s && test -s sw/seed-3/summary.json && test -s tr/seed-1/summary.json", dir), 0);
  cr_assert_eq(sh("cd %s && %s --threads 1 --reps 1 " TINY " --bin %s -- -m.ini </dev/null", dir,
                  tool("thread-scaling"), env("LW_BIN")), 0, "%s", err_txt());
  cr_assert_eq(sh("cd %s && %s --out sw.png -- sw/sweep.csv </dev/null", dir, tool("plot-sweep")), 0, "%s", err_txt());
  check_png("sw.png");
  cr_assert_eq(sh("cd %s && cp %s 'm\nx.ini' && %s 'm\nx.ini' --seeds 1 --out nl", dir, scene(),
                  tool("seed-sweep")), 2);
  errs = err_txt();
  cr_assert(strstr(errs, "'m?x.ini': a control character in the scene file's path"), "%s", errs);
  free(errs);
  cr_assert(!exists("nl"), "a sweep directory was made");
  cr_assert_eq(sh("cd %s && OMP_NUM_THREADS=1 %s %s --seeds 1 " TINY " --bin %s --out om </dev/null", dir,
                  tool("seed-sweep"), scene(), env("LW_BIN")), 0, "%s", err_txt());
  char *said = out_txt();
  cr_assert_eq(sh("env -u OMP_NUM_THREADS nproc"), 0);
  char *cores = out_txt(), want[128];
  snprintf(want, sizeof want, "seed-sweep: 1 runs into om, %ld at a time", strtol(cores, NULL, 10));
  cr_assert(!strncmp(said, want, strlen(want)), "'%s' is not '%s...'", said, want);
  free(said);
  free(cores);
}

Test(tools, plot_run_draws_energy_temperature_and_acceptance)
{
  cr_assert_eq(sh("%s run %s " TINY " --quiet --out %s/r", env("LW_BIN"), scene(), dir), 0);
  cr_assert_eq(sh("%s %s/r", tool("plot-run"), dir), 0, "%s", err_txt());
  check_png("r/plots/energy.png");
  check_png("r/plots/temperature.png");
  check_png("r/plots/acceptance.png");
  cr_assert(!exists("r/plots/replicas.png") && !exists("r/plots/swaps.png"), "no tempering, no tempering plots");
  cr_assert(!exists("r/plots/observables.png"), "no observables traced, no plot of them");
  cr_assert_eq(sh("%s %s/nothing", tool("plot-run"), dir), 2);
  /* observables get their own panels, drawn after the swaps' bars (whose
  ** settings once left the observables' data unread) */
  cr_assert_eq(sh("%s run %s " TINY " --quiet --out %s/o --set output.observables=1 --set tempering.replicas=2",
                  env("LW_BIN"), scene(), dir), 0);
  cr_assert_eq(sh("%s %s/o", tool("plot-run"), dir), 0, "%s", err_txt());
  check_png("o/plots/swaps.png");
  check_png("o/plots/observables.png");
}

/* A run this user may only read is plotted into a folder of their own
** (--out; a run's own plots/ needed write access to the run); a standard
** output that is closed fails the script, exit 1, once every plot is in
** place (a reader gone, `| head -1`, killed it half way by SIGPIPE); the
** plots of a run another user may not read are said unreadable, not "not a
** run directory". */
Test(tools, plot_run_writes_elsewhere_and_says_a_lost_output)
{
  cr_assert_eq(sh("%s run %s " TINY " --quiet --out %s/r", env("LW_BIN"), scene(), dir), 0);
  /* a hidden .tmp of the user's there stays (every one went) */
  cr_assert_eq(sh("mkdir -p %s/mine/p && echo draft > %s/mine/p/.draft.tmp && %s %s/r --out %s/mine/p/", dir, dir,
                  tool("plot-run"), dir, dir),
               0, "%s", err_txt());
  cr_assert_eq(sh("grep -qx draft %s/mine/p/.draft.tmp", dir), 0);
  cr_assert_eq(sh("%s %s/r --out %s/a --out %s/b", tool("plot-run"), dir, dir, dir), 2);
  check_png("mine/p/energy.png");
  check_png("mine/p/acceptance.png");
  cr_assert(!exists("r/plots"), "the run's own folder untouched");
  cr_assert_eq(sh("{ %s %s/r >&-; }", tool("plot-run"), dir), 1);
  char *e = err_txt();
  cr_assert(strstr(e, "plot-run: the standard output could not be written (closed, full, or its reader gone); the "
                      "plots are written\n"), "%s", e);
  free(e);
  check_png("r/plots/temperature.png");
  cr_assert_eq(sh("test -z \"$(ls -A %s/r/plots | grep tmp)\"", dir), 0, "temporaries left");
  if (geteuid() || sh("setpriv --reuid=65534 --regid=65534 --clear-groups bash %s --help", tool("plot-run"))) return;
  cr_assert_eq(sh("chmod 755 %s && chmod 700 %s/r && cd / && setpriv --reuid=65534 --regid=65534 --clear-groups "
                  "bash %s %s/r --out /tmp/nobody-plots", dir, dir, tool("plot-run"), dir),
               2);
  e = err_txt();
  cr_assert(strstr(e, "/r/trace.csv: cannot read: Permission denied\n"), "%s", e);
  free(e);
}

static void write_text(const char *name, const char *text)
{
  char path[256];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "w");
  cr_assert_not_null(f);
  fputs(text, f);
  fclose(f);
}

/* A tempering run as its files will look: replica and swap columns in the
** trace, the ladder and swap acceptance in the summary. */
static void write_tempering_run(const char *sub, int with_replica_columns)
{
  char name[128], row[256];
  cr_assert_eq(sh("mkdir -p %s/%s", dir, sub), 0);
  size_t cap = 1 << 14, n = 0;
  char *trace = malloc(cap);
  n += (size_t)snprintf(trace, cap, "sweep,temperature,bending,total,acc_point%s\n",
                        with_replica_columns ? ",replica0_temperature,replica0_energy,replica1_temperature,"
                                               "replica1_energy,swap0" : "");
  for (int s = 1; s <= 40; s++) {
    if (with_replica_columns)
      snprintf(row, sizeof row, "%d,%g,%g,%g,%g,0.1,%g,0.5,%g,%g\n", s, 1.0 / s, 3.0 / s, 3.0 / s + 0.2, 0.45, 2.0 / s,
               4.0 / s, 0.3 + 0.01 * s);
    else
      snprintf(row, sizeof row, "%d,%g,%g,%g,%g\n", s, 1.0 / s, 3.0 / s, 3.0 / s + 0.2, 0.45);
    n += (size_t)snprintf(trace + n, cap - n, "%s", row);
  }
  snprintf(name, sizeof name, "%s/trace.csv", sub);
  write_text(name, trace);
  free(trace);
  snprintf(name, sizeof name, "%s/summary.json", sub);
  write_text(name, "{\n  \"seed\": 1,\n  \"energy\": {\n    \"total\": 0.275,\n    \"bending\": 0.075\n  },\n"
                   "  \"replicas\": [\n    {\n      \"temperature\": 0.1,\n      \"energy\": 0.275\n    },\n"
                   "    {\n      \"temperature\": 0.5,\n      \"energy\": 0.4\n    }\n  ],\n"
                   "  \"swap_acceptance\": [\n    0.42\n  ],\n  \"round_trips\": 2\n}\n");
}

Test(tools, plot_run_draws_replicas_and_swaps_when_tempering)
{
  write_tempering_run("pt", 1);
  cr_assert_eq(sh("%s %s/pt", tool("plot-run"), dir), 0, "%s", err_txt());
  check_png("pt/plots/energy.png");
  check_png("pt/plots/replicas.png");
  check_png("pt/plots/swaps.png");
  /* a hand-made trace without its scene cannot be reweighted: a note, no
  ** heat capacity plot, and still success */
  char *e = err_txt();
  cr_assert(strstr(e, "plot-run: no heat capacity plot: "), "%s", e);
  free(e);
  cr_assert_eq(sh("test ! -e %s/pt/plots/heat_capacity.png", dir), 0);
  /* the summary alone (no replica columns in the trace) still gives both */
  write_tempering_run("ps", 0);
  cr_assert_eq(sh("%s %s/ps", tool("plot-run"), dir), 0, "%s", err_txt());
  check_png("ps/plots/replicas.png");
  check_png("ps/plots/swaps.png");
}

Test(tools, plot_run_draws_the_heat_capacity_between_the_rungs)
{
  cr_assert_eq(sh("%s run %s/params/wire-ladder.ini --out %s/wl --quiet", env("LW_BIN"), env("LW_ROOT"), dir), 0,
               "%s", err_txt());
  cr_assert_eq(sh("%s %s/wl", tool("plot-run"), dir), 0, "%s", err_txt());
  char *out = out_txt();
  cr_assert(strstr(out, "wl/plots/heat_capacity.png\n"), "%s", out);
  free(out);
  check_png("wl/plots/heat_capacity.png");
  cr_assert_eq(sh("test ! -e %s/wl/plots/.reweight.csv.tmp", dir), 0, "no temporary file left");
  /* rungs 100 apart share no energies: the curve has gaps between them,
  ** drawn as gaps (not lines joining the rungs), and a note says so */
  size_t cap = 1 << 19, n = 0; /* past the scene's stats_from */
  char *trace = malloc(cap);
  n += (size_t)snprintf(trace, cap, "sweep,temperature,total,replica0_temperature,replica0_energy,"
                                    "replica1_temperature,replica1_energy\n");
  for (int t = 1; t <= 6000; t++)
    n += (size_t)snprintf(trace + n, cap - n, "%d,1,%.6f,1,%.6f,2,%.6f\n", t, 100 + sin(1.7 * t), 100 + sin(1.7 * t),
                          200 + cos(2.3 * t));
  cr_assert_eq(sh("mkdir %s/wg && cp %s/wl/scene.ini %s/wg/", dir, dir, dir), 0);
  write_text("wg/trace.csv", trace);
  free(trace);
  cr_assert_eq(sh("%s %s/wg", tool("plot-run"), dir), 0, "%s", err_txt());
  char *e = err_txt();
  cr_assert(strstr(e, "plot-run: the heat capacity plot has gaps where rungs share almost no energies"), "%s", e);
  free(e);
  check_png("wg/plots/heat_capacity.png");
}

/* What the plots read goes into gnuplot's commands, and another user may
** hand one a run or a sweep: summary.json's "from" went into a command as
** text (system(...) ran), a line break in a name began a command of its own,
** a seed of "EOD" ended sweep.csv's datablock and the next row ran, and
** a planted link at a plot's temporary name was written through. */
Test(tools, plots_run_nothing_a_run_or_sweep_file_says)
{
  cr_assert_eq(sh("%s run %s " TINY " --quiet --out %s/r --set output.observables=1", env("LW_BIN"), scene(), dir), 0);
  cr_assert_eq(sh("cd %s && sed -i 's/^  \"observables\": null,/  \"observables\": {\\n    \"from\": "
                  "0,0;x=system(\"id>made1\");#,\\n    \"to\": 10\\n  },/' r/summary.json && "
                  "grep -q made1 r/summary.json && mkdir r/plots && echo keep > victim && "
                  "ln -s %s/victim r/plots/.energy.png.tmp && %s r </dev/null", dir, dir, tool("plot-run")),
               0, "%s", err_txt());
  check_png("r/plots/energy.png");
  cr_assert(!exists("made1"), "summary.json's text ran as a gnuplot command");
  cr_assert_eq(sh("grep -qx keep %s/victim", dir), 0, "a plot was written through a planted link");
  cr_assert_eq(sh("cd %s && cp -r r \"$(printf 'r\\n!touch made2\\nx')\" && %s \"$(printf 'r\\n!touch made2\\nx')\" "
                  "</dev/null", dir, tool("plot-run")), 2);
  cr_assert(!exists("made2"), "a line break in the name began a gnuplot command");
  write_text("eod.csv", "seed,energy_total,run\nEOD,2.5,a\nsystem('touch made3'),1.5,b\n");
  cr_assert_eq(sh("cd %s && %s eod.csv </dev/null", dir, tool("plot-sweep")), 0, "%s", err_txt());
  cr_assert(!exists("made3"), "a sweep.csv field ended the datablock and ran");
  /* the replicas' temperatures go into a datablock too: an EOD there ends
  ** it, and the line after runs as a command, but for the numbers-only
  ** filter, which nothing tested */
  write_tempering_run("pi", 0);
  cr_assert_eq(sh("cd %s && sed -i '0,/\"temperature\": 0.1,/s//\"temperature\": EOD,/; "
                  "s/\"temperature\": 0.5,/\"temperature\": !touch made4,/' pi/summary.json && "
                  "grep -q EOD pi/summary.json && grep -q made4 pi/summary.json && %s pi </dev/null", dir,
                  tool("plot-run")), 0, "%s", err_txt());
  cr_assert(!exists("made4"), "summary.json's replica values ended the datablock and ran");
}

/* A run's log planted as a link (another user's, in a shared sweep folder)
** had the sweep append the run's output to the file it named. */
Test(tools, a_sweep_writes_no_log_through_a_link)
{
  cr_assert_eq(sh("mkdir -p %s/s/seed-1 && echo keep > %s/victim && ln -s %s/victim %s/s/seed-1/linewise.log", dir, dir,
                  dir, dir), 0);
  cr_assert_neq(sh("%s %s --seeds 1-2 " TINY " --bin %s --out %s/s", tool("seed-sweep"), scene(), env("LW_BIN"), dir),
                0);
  char *e = err_txt();
  cr_assert(strstr(e, "seed-1/linewise.log: a symbolic link"), "%s", e);
  free(e);
  cr_assert_eq(sh("grep -qx keep %s/victim && test $(wc -l < %s/victim) -eq 1", dir, dir), 0,
               "the log was written through the link");
  cr_assert_eq(sh("test -s %s/s/seed-2/summary.json", dir), 0, "the other run did not finish");
  /* a FIFO there held the run's task, and the sweep, forever */
  cr_assert_eq(sh("mkdir -p %s/f/seed-1 && mkfifo %s/f/seed-1/linewise.log && timeout 20 %s %s --seeds 1-2 " TINY
                  " --bin %s --out %s/f", dir, dir, tool("seed-sweep"), scene(), env("LW_BIN"), dir), 1);
  e = err_txt();
  cr_assert(strstr(e, "seed-1/linewise.log: a symbolic link or a FIFO"), "%s", e);
  free(e);
}

/* gnuplot says nothing of a picture it could not write: on a nearly full
** disk an empty or cut-off PNG replaced a good one, with exit 0; on a full
** one, every line of the script said "echo: write error", then mv, then exit
** 2.  Here a file-size limit stands in for the disk: gnuplot's pictures are
** cut off at 4 KiB (SIGXFSZ ignored, as a full disk gives ENOSPC and no
** signal), or the script at 512 bytes.  The good plots stay, with one line a
** plot and exit 1, and no temporary is left. */
Test(tools, a_plot_that_cannot_be_written_whole_leaves_the_earlier_one)
{
  cr_assert_eq(sh("%s run %s " TINY " --quiet --out %s/r", env("LW_BIN"), scene(), dir), 0);
  cr_assert_eq(sh("%s %s/r && cp -r %s/r/plots %s/good", tool("plot-run"), dir, dir, dir), 0, "%s", err_txt());
  cr_assert_eq(sh("mkdir %s/pg", dir), 0);
  write_script("pg/gnuplot", "#!/bin/sh\ntrap '' XFSZ\nulimit -f 8\nexec %s \"$@\"\n",
               "$(PATH=/usr/local/bin:/usr/bin:/bin command -v gnuplot)");
  cr_assert_eq(sh("PATH=%s/pg:$PATH %s %s/r", dir, tool("plot-run"), dir), 1, "%s", err_txt());
  char *e = err_txt();
  cr_assert(strstr(e, "plot-run: ") && strstr(e, "/r/plots/energy.png: gnuplot's picture was not written whole (a "
                                                 "full disk?); the earlier one is kept\n") && !raw_error(e), "%s", e);
  free(e);
  cr_assert_eq(sh("for f in energy temperature acceptance; do cmp %s/good/$f.png %s/r/plots/$f.png || exit 1; done && "
                  "test -z \"$(ls -A %s/r/plots | grep tmp)\"", dir, dir, dir), 0,
               "a plot was replaced, or a temporary left");
  cr_assert_eq(sh("(trap '' XFSZ; ulimit -f 1; %s %s/r)", tool("plot-run"), dir), 1);
  e = err_txt();
  cr_assert(strstr(e, ".plot.gp.tmp: gnuplot's script could not be written whole") &&
            strchr(e, '\n') == e + strlen(e) - 1, "%s", e);
  free(e);
  cr_assert_eq(sh("for f in energy temperature acceptance; do cmp %s/good/$f.png %s/r/plots/$f.png || exit 1; done && "
                  "test -z \"$(ls -A %s/r/plots | grep tmp)\"", dir, dir, dir), 0);
  /* plot-sweep: an empty picture (no room at all) */
  write_text("seeds.csv", "seed,energy_total,run\n1,2.5,seed-1\n2,1.75,seed-2\n");
  cr_assert_eq(sh("%s %s/seeds.csv && cp %s/seeds.png %s/seeds.good", tool("plot-sweep"), dir, dir, dir), 0, "%s",
               err_txt());
  write_script("pg/gnuplot", "#!/bin/sh\ntrap '' XFSZ\nulimit -f 0\nexec %s \"$@\"\n",
               "$(PATH=/usr/local/bin:/usr/bin:/bin command -v gnuplot)");
  cr_assert_eq(sh("PATH=%s/pg:$PATH %s %s/seeds.csv", dir, tool("plot-sweep"), dir), 1, "%s", err_txt());
  e = err_txt();
  cr_assert(strstr(e, "seeds.png: gnuplot's picture was not written whole (a full disk?); the earlier one is "
                      "kept\n") && strchr(e, '\n') == e + strlen(e) - 1, "%s", e);
  free(e);
  cr_assert_eq(sh("cmp %s/seeds.good %s/seeds.png && test ! -e %s/seeds.png.tmp", dir, dir, dir), 0);
  /* a file-size limit that kills gnuplot (SIGXFSZ, as a batch system sets
  ** it): said so, exit 1, the earlier pictures kept ("gnuplot failed: ",
  ** nothing after it, exit 2) */
  write_script("pg/gnuplot", "#!/bin/sh\nulimit -f 8\nexec %s \"$@\"\n",
               "$(PATH=/usr/local/bin:/usr/bin:/bin command -v gnuplot)");
  cr_assert_eq(sh("PATH=%s/pg:$PATH %s %s/r", dir, tool("plot-run"), dir), 1, "%s", err_txt());
  e = err_txt();
  static const char why[] = ".png: gnuplot's picture was not written whole (gnuplot was killed by SIGXFSZ (a file-size "
                            "limit: ulimit -f))";
  cr_assert(strstr(e, "/r/plots/energy.png: ") && !raw_error(e), "%s", e);
  for (const char *l = e; *l; l = strchr(l, '\n') + 1)
    cr_assert(!strncmp(l, "plot-run: ", 10) && strstr(l, why) && strstr(l, why) < strchr(l, '\n') &&
                  !strncmp(strstr(l, why) + strlen(why), "; the earlier one is kept\n", 26), "%s", e);
  free(e);
  cr_assert_eq(sh("for f in energy temperature acceptance; do cmp %s/good/$f.png %s/r/plots/$f.png || exit 1; done && "
                  "test -z \"$(ls -A %s/r/plots | grep tmp)\"", dir, dir, dir), 0);
  /* the limit reached at the last plot: those drawn before it are whole and
  ** kept (they went with it) */
  write_script("pg/gnuplot", "#!/bin/sh\n%s \"$@\"\nf=%s/r/plots/.acceptance.png.tmp\ntest -s $f && truncate -s 100 $f"
               " && kill -XFSZ $$\n", "$(PATH=/usr/local/bin:/usr/bin:/bin command -v gnuplot)", dir);
  cr_assert_eq(sh("rm -r %s/r/plots && PATH=%s/pg:$PATH %s %s/r", dir, dir, tool("plot-run"), dir), 1, "%s",
               err_txt());
  e = err_txt();
  cr_assert(!strncmp(e, "plot-run: ", 10) && strstr(e, "/r/plots/acceptance") && strstr(e, why) &&
                strchr(e, '\n') == e + strlen(e) - 1, "%s", e);
  free(e);
  cr_assert_eq(sh("for f in energy temperature; do cmp %s/good/$f.png %s/r/plots/$f.png || exit 1; done && "
                  "test -z \"$(ls -A %s/r/plots | grep 'tmp\\|acceptance')\"", dir, dir, dir), 0);
}

Test(tools, plot_sweep_draws_a_png_beside_the_csv)
{
  write_text("seeds.csv", "seed,energy_total,energy_bending,proposals_per_second,wall_seconds,run\n"
                          "1,2.5,1.5,1000,0.1,seed-1\n2,1.75,1.25,1100,0.1,seed-2\n3,2.125,1,900,0.1,seed-3\n");
  cr_assert_eq(sh("%s %s/seeds.csv", tool("plot-sweep"), dir), 0, "%s", err_txt());
  check_png("seeds.png");
  /* a standard output that is full, or whose reader is gone: one line, the
  ** plot written (bash's raw "write error", or death by SIGPIPE) */
  cr_assert_eq(sh("rm %s/seeds.png && { %s %s/seeds.csv >/dev/full; }", dir, tool("plot-sweep"), dir), 1);
  char *e = err_txt();
  cr_assert(!strcmp(e, "plot-sweep: the standard output could not be written (closed, full, or its reader gone); the "
                       "plot is written\n"), "%s", e);
  free(e);
  check_png("seeds.png");
  cr_assert_eq(sh("{ %s %s/seeds.csv; echo $? >%s/ps.rc; } | head -c 0", tool("plot-sweep"), dir, dir), 0);
  e = lw_test_slurp("%s/ps.rc", dir);
  cr_assert(!strcmp(e, "1\n"), "%s", e);
  free(e);
  write_text("params.csv", "seed,energy.bending,energy_total,wall_seconds,run\n"
                           "1,0.5,2.5,0.1,a\n2,0.5,1.5,0.1,b\n1,2,3.5,0.1,c\n2,2,3.25,0.1,d\n");
  cr_assert_eq(sh("%s %s/params.csv --y wall_seconds", tool("plot-sweep"), dir), 0, "%s", err_txt());
  check_png("params-wall_seconds.png");
  /* a column with its own error bar draws each run's */
  write_text("obs.csv", "seed,anneal.t_start,energy_total,obs_end2,obs_end2_stderr,run\n"
                        "1,0.5,2.5,15.1,0.04,a\n2,0.5,1.5,15.3,0.03,b\n1,1,3.5,14.5,0.06,c\n2,1,3.25,14.55,,d\n");
  cr_assert_eq(sh("%s %s/obs.csv --y obs_end2", tool("plot-sweep"), dir), 0, "%s", err_txt());
  check_png("obs-obs_end2.png");
  write_text("words.csv", "seed,anneal.schedule,energy_total,run\n1,linear,2.5,a\n1,geometric,1.5,b\n");
  cr_assert_eq(sh("%s %s/words.csv --out %s/w.png", tool("plot-sweep"), dir, dir), 0, "%s", err_txt());
  check_png("w.png");
  cr_assert_eq(sh("%s %s/seeds.csv --y nothing", tool("plot-sweep"), dir), 2);
}

Test(tools, thread_scaling_times_each_count_and_checks_the_bytes)
{
  cr_assert_eq(sh("%s %s/params/minimal.ini --threads 1,2 --reps 2 --bin %s --set anneal.sweeps=30 "
                  "--set tempering.replicas=2",
                  tool("thread-scaling"), env("LW_ROOT"), env("LW_BIN")),
               0, "%s", err_txt());
  char *out = out_txt();
  double s1, s2, u1, u2;
  const char *r1 = strstr(out, "\n       1 "), *r2 = strstr(out, "\n       2 ");
  cr_assert(r1 && r2, "%s", out);
  cr_assert_eq(sscanf(r1, "%*d %lf %lf", &s1, &u1), 2, "%s", out);
  cr_assert_eq(sscanf(r2, "%*d %lf %lf", &s2, &u2), 2, "%s", out);
  /* the table prints seconds to 3 decimals and the speed-up, from the unrounded
  ** medians, to 2: the ratio of the printed seconds is off by up to half a
  ** millisecond in each, relative to its size */
  double slack = 0.005 + s1 / s2 * (0.0005 / s1 + 0.0005 / s2) + 1e-9;
  cr_assert(s1 > 0 && s2 > 0 && u1 == 1.0 && fabs(u2 - s1 / s2) <= slack, "%s", out);
  cr_assert(strstr(r2, "the same bytes"), "%s", out);
  free(out);
  /* a binary whose state depends on its threads is caught: exit 1 */
  write_text("fake", "#!/bin/sh\n# run SCENE --out DIR --quiet --threads T ...\n"
                     "mkdir -p \"$4\" && echo \"threads $7\" > \"$4/state.lw\" && "
                     "echo '{\"wall_seconds\": 0.5}' > \"$4/summary.json\"\n");
  cr_assert_eq(sh("chmod +x %s/fake && %s %s/params/minimal.ini --threads 1,3 --reps 1 --bin %s/fake", dir,
                  tool("thread-scaling"), env("LW_ROOT"), dir),
               1, "%s", err_txt());
  out = out_txt();
  cr_assert(strstr(out, "       3        0.500      1.00  DIFFERS"), "%s", out);
  free(out);
  cr_assert_eq(sh("%s %s/params/minimal.ini --threads 0", tool("thread-scaling"), env("LW_ROOT")), 2);
  char *err = err_txt();
  cr_assert(strstr(err, "thread-scaling: --threads: expected whole numbers >= 1, got '0'"), "%s", err);
  free(err);
  /* an unknown option named (the usage alone said nothing of it), an empty
  ** list refused (it ran the default); the default counts are the cores it
  ** may use (taskset to one: one count, where getconf counted the machine's) */
  cr_assert_eq(sh("%s %s/params/minimal.ini --bogus", tool("thread-scaling"), env("LW_ROOT")), 2);
  err = err_txt();
  cr_assert(!strcmp(err, "thread-scaling: unknown option '--bogus' (try 'thread-scaling --help')\n"), "%s", err);
  free(err);
  cr_assert_eq(sh("%s %s/params/minimal.ini --threads ''", tool("thread-scaling"), env("LW_ROOT")), 2);
  if (!sh("command -v taskset")) {
    cr_assert_eq(sh("taskset -c 0 %s %s/params/minimal.ini --reps 1 --bin %s/fake", tool("thread-scaling"),
                    env("LW_ROOT"), dir), 0, "%s", err_txt());
    out = out_txt();
    cr_assert(strstr(out, " on 1 cores (nproc),") && !strstr(out, "\n       2 "), "%s", out);
    free(out);
  }
}

/* ---- make install ------------------------------------------------------ */

/* A library folder of a multiarch system's (LIBDIR), linewise.pc found there. */
#define MULTIARCH "lib/x86_64-linux-gnu"

/* A program embeds the installed library, in C++ too, installed under any
** umask and into a multiarch LIBDIR: tests/embed.cpp, built with nothing
** but what linewise.pc names, makes the run `linewise run` makes, to the
** byte but for summary.json's clock.  Every header compiles in C++ with
** those flags (cairo's too: moved with the prefix, they were lost), and the
** library defines no global name but lw_ ones (its
** stb_image was global, and a program with its own either failed to link
** or had linewise read pictures through it, upside down). */
Test(tools, an_installed_library_embeds_in_cxx_through_its_pkg_config, .timeout = 120)
{
  if (sh("{ command -v c++ && command -v pkg-config; }")) cr_skip_test("no c++ or pkg-config here");
  /* under a root's umask of 077, every file for every user to read */
  cr_assert_eq(sh("umask 077 && make -s -C %s install DESTDIR=%s/lib PREFIX=/usr LIBDIR=" MULTIARCH, env("LW_ROOT"),
                  dir),
               0, "%s", err_txt());
  cr_assert_eq(sh("find %s/lib ! -perm -o=r", dir), 0);
  char *unreadable = out_txt();
  cr_assert_eq(unreadable[0], '\0', "not every user's to read: %s", unreadable);
  free(unreadable);
  cr_assert_eq(sh("cd %s && flags=$(PKG_CONFIG_PATH=lib/usr/" MULTIARCH "/pkgconfig pkg-config --cflags --libs "
                  "linewise) && "
                  "c++ -Wall -Werror -o embed lib/usr/share/doc/linewise/embed.cpp $flags && "
                  "for h in lib/usr/include/linewise/*.h; do echo \"#include \\\"linewise/${h##*/}\\\"\"; "
                  "done > all.cpp && "
                  "c++ -Wall -Wextra -Werror -fsyntax-only all.cpp $flags",
                  dir),
               0, "%s", err_txt());
  cr_assert_eq(sh("nm -g --defined-only %s/lib/usr/" MULTIARCH "/liblinewise.a | "
                  "awk 'NF == 3 && $3 !~ /^(lw_|.gomp_critical_user_lw_)/'", dir),
               0);
  char *names = out_txt();
  cr_assert_eq(names[0], '\0', "global names outside lw_: %s", names);
  free(names);
  /* (its usage line names the release and build, and the memory it sees:
  ** version.h and memlimit.h lacked extern "C", and a C++ host could not
  ** link them) */
  cr_assert_eq(sh("cd %s && ./embed", dir), 2);
  char *usage = err_txt();
  cr_assert(strstr(usage, "(linewise " LW_VERSION ", build "), "%s", usage);
  free(usage);
  cr_assert_eq(sh("cd %s && { ./embed %s e && %s run %s --quiet --out c; }", dir, scene(), env("LW_BIN"), scene()),
               0, "%s", err_txt());
  cr_assert_eq(sh("cd %s && for f in state.lw trace.csv final.svg scene.ini; do cmp e/$f c/$f || exit 1; done && "
                  "grep -v _second e/summary.json > e.json && grep -v _second c/summary.json > c.json && "
                  "cmp e.json c.json && test $(grep -c _second c/summary.json) -eq 3", dir),
               0, "%s", out_txt());
  /* resumed for 50 sweeps short of the end it stops there, with no final
  ** files (the loop of lw_anneal_done alone finished the run), then goes on */
  cr_assert_eq(sh("cd %s && { %s run %s --quiet --stop-at 100 --out r && cp -r r s && ./embed --resume r 50 && "
                  "%s resume s --quiet --sweeps 50 && cmp r/state.lw s/state.lw && cmp r/trace.csv s/trace.csv && "
                  "! test -e r/summary.json && grep -qx 'sweep = 150' r/state.lw && ./embed --resume r -1 && "
                  "%s resume s --quiet && cmp r/state.lw s/state.lw && cmp r/final.svg s/final.svg; }",
                  dir, env("LW_BIN"), scene(), env("LW_BIN"), env("LW_BIN")),
               0, "%s", err_txt());
  cr_assert_eq(sh("make -s -C %s uninstall DESTDIR=%s/lib PREFIX=/usr LIBDIR=" MULTIARCH " && "
                  "test -z \"$(find %s/lib -type f)\"",
                  env("LW_ROOT"), dir, dir),
               0, "%s", err_txt());
}

/* An installed copy runs on its own: every scene with what it reads (the
** states of init.from once stayed behind), from another directory; the
** tools say the names they are installed under; uninstall takes it all. */
Test(tools, install_runs_every_scene_away_from_the_checkout_and_uninstall_removes_it, .timeout = 120)
{
  /* into a DESTDIR with a blank, beside a directory named as its part
  ** before the blank (uninstall removed that one) */
  cr_assert_eq(sh("cd %s && mkdir ro && echo mine > ro/keep && make -s -C %s install DESTDIR=\"$PWD/ro ot\" "
                  "PREFIX=/usr", dir, env("LW_ROOT")),
               0, "%s", err_txt());
  cr_assert_eq(sh("cd %s && for s in 'ro ot'/usr/share/linewise/params/*.ini; do "
                  "  'ro ot'/usr/bin/linewise run \"$s\" --stop-at 0 --quiet --threads 1 --out \"o-${s##*/}\" || "
                  "  { echo \"$s\" >&2; exit 1; }; done",
                  dir),
               0, "%s", err_txt());
  cr_assert_eq(sh("cd %s && { 'ro ot'/usr/bin/linewise-seed-sweep --help && "
                  "'ro ot'/usr/bin/linewise-plot-run --help; }", dir),
               0);
  char *out = out_txt();
  cr_assert(strstr(out, "usage: linewise-seed-sweep SCENE.ini") && strstr(out, "usage: linewise-plot-run RUN_DIR"),
            "%s", out);
  free(out);
  cr_assert_eq(sh("test -s '%s/ro ot/usr/share/doc/linewise/docs/PARAMETERS.md'", dir), 0);
  /* README's links to docs/ hold where it is installed */
  cr_assert_eq(sh("cd '%s/ro ot/usr/share/doc/linewise' && for t in $(grep -o '](docs/[^)#]*' README.md | cut -c3-); do "
                  "test -e \"$t\" || exit 1; done", dir), 0);
  /* a man page for each tool: its NAME, and its --help under the name it is installed by */
  cr_assert_eq(sh("cd '%s/ro ot/usr' && for t in seed-sweep param-sweep plot-run plot-sweep thread-scaling animate; do "
                  "  m=share/man/man1/linewise-$t.1; grep -q \"^linewise-$t .- [a-z]\" $m && "
                  "  grep -q \"^usage: linewise-$t \" $m && grep -qx 'README.md in /usr/share/doc/linewise.' $m && "
                  "  { ! command -v groff || test -z \"$(groff -man -ww -z $m 2>&1)\"; } "
                  "  || { echo $t >&2; exit 1; }; done", dir),
               0, "%s", err_txt());
  /* a LIBDIR not under PREFIX (GNU's absolute libdir went under it twice) is refused */
  cr_assert_eq(sh("cd %s && make -s -C %s install DESTDIR=\"$PWD/ro ot\" PREFIX=/usr LIBDIR=/usr/lib", dir,
                  env("LW_ROOT")),
               2);
  char *e = err_txt();
  cr_assert(strstr(e, "LIBDIR=/usr/lib: expected a folder under PREFIX"), "%s", e);
  free(e);
  /* linewise-mpi's is linewise's, where it is installed */
  cr_assert_eq(sh("cd '%s/ro ot/usr' && { test ! -e bin/linewise-mpi || grep -qx '.so man1/linewise.1' "
                  "share/man/man1/linewise-mpi.1; }", dir),
               0);
  /* a scene the user saved beside the bundled ones stays (uninstall removed
  ** share/linewise whole), and its folder with it, said once (share/linewise
  ** was said too, as if files were in it) */
  cr_assert_eq(sh("cd %s && echo mine > 'ro ot/usr/share/linewise/params/my.ini' && { make -s -C %s uninstall "
                  "DESTDIR=\"$PWD/ro ot\" PREFIX=/usr && test \"$(find 'ro ot' -type f)\" = "
                  "'ro ot/usr/share/linewise/params/my.ini' && grep -qx mine ro/keep && "
                  "test ! -e 'ro ot/usr/bin/linewise'; }", dir, env("LW_ROOT")),
               0, "%s", err_txt());
  char *kept = err_txt();
  cr_assert(!strcmp(kept, "uninstall: share/linewise/params kept: files not installed are in it\n"), "%s", kept);
  free(kept);
  /* where nothing of it is (another PREFIX than install's), said */
  cr_assert_eq(sh("cd %s && make -s -C %s uninstall DESTDIR=\"$PWD/ro ot\" PREFIX=/opt", dir, env("LW_ROOT")), 0);
  kept = err_txt();
  cr_assert(strstr(kept, "uninstall: no file of linewise's in ") && strstr(kept, "ro ot/opt' (installed with another "
                                                                              "PREFIX?)\n"), "%s", kept);
  free(kept);
}
