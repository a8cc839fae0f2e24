/*
** test_cli.c -- the command line as users and scripts see it: outputs,
** exit codes and messages.  Runs the binary named by $LW_BIN (make test
** sets it).
*/
#include <criterion/criterion.h>
#include <gsl/gsl_version.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include "linewise/model.h"
#include "linewise/state.h"
#include "linewise/version.h"
#include "testutil.h"

static char dir[64];

static void make_dir(void)
{
  lw_test_tmp_name(dir, "cli");
  cr_assert_not_null(mkdtemp(dir));
}

static void remove_dir(void)
{
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  cr_assert_eq(system(cmd), 0);
}

TestSuite(cli, .init = make_dir, .fini = remove_dir);

/* Runs "linewise <args>" capturing stdout and stderr; returns the exit status. */
static int run(const char *args, char *out, size_t nout, char *errs, size_t nerr)
{
  char cmd[1024];
  snprintf(cmd, sizeof cmd, "%s %s >%s/out.txt 2>%s/err.txt", lw_test_bin(), args, dir, dir);
  int st = system(cmd);
  char path[128];
  FILE *f;
  snprintf(path, sizeof path, "%s/out.txt", dir);
  f = fopen(path, "r");
  size_t n = fread(out, 1, nout - 1, f);
  out[n] = '\0';
  fclose(f);
  snprintf(path, sizeof path, "%s/err.txt", dir);
  f = fopen(path, "r");
  n = fread(errs, 1, nerr - 1, f);
  errs[n] = '\0';
  fclose(f);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static void write_file(const char *name, const char *text)
{
  char path[128];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "w");
  fputs(text, f);
  fclose(f);
}

static const char scene_text[] =
  "[scene]\nwidth = 100\nheight = 80\nmargin = 5\npotential = ramp\nfield = waves\n"
  "[energy]\nstrain = 2\nbending = 0.5\npotential = 0.3\nfield = -0.2\npair = 0.01\nboundary = 0.1\n";

Test(cli, energy_prints_each_enabled_term_and_the_total)
{
  write_file("scene.ini", scene_text);
  size_t segs[2] = {3, 4}; /* quarter circles: half circles in one segment are irregular */
  lw_state st = {.scene = "scene.ini", .seed = 7, .sp = lw_splines_new(2, segs, NULL)};
  lw_test_straight(st.sp, 0, 20, 20, 70, 30);
  lw_test_circle(st.sp, 1, 50, 45, 12);
  char path[128];
  snprintf(path, sizeof path, "%s/state.lw", dir);
  cr_assert_eq(lw_state_write(&st, path, NULL), LW_OK);

  char out[4096], errs[4096];
  char args[128];
  snprintf(args, sizeof args, "energy %s", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "stderr: %s", errs);

  /* the same numbers in-process */
  lw_params p;
  lw_scene sc;
  snprintf(path, sizeof path, "%s/scene.ini", dir);
  cr_assert_eq(lw_params_read(&p, path, NULL), LW_OK);
  cr_assert_eq(lw_scene_init(&sc, &p, NULL), LW_OK);
  double term[LW_TERM_COUNT];
  double total = lw_energy_compute(&sc, st.sp, term, NULL);
  const char *names[] = {"strain", "bending", "potential", "field", "pair", "boundary", "total"};
  char *line = strtok(out, "\n");
  for (int t = 0; t < 7; t++) {
    cr_assert_not_null(line, "missing line for %s", names[t]);
    char name[32];
    double v;
    cr_assert_eq(sscanf(line, "%31s %lf", name, &v), 2, "line '%s'", line);
    cr_assert_str_eq(name, names[t]);
    double want = t < 6 ? term[t] : total;
    cr_assert(isfinite(v) && v == want, "%s: printed %.17g, computed %.17g", name, v, want);
    line = strtok(NULL, "\n");
  }
  cr_assert_null(line, "extra output");
  lw_scene_clear(&sc);
  lw_state_clear(&st);
}

/* The total `linewise energy` prints for args, in *total; its exit status. */
static int energy_total(const char *args, double *total, char *errs, size_t n)
{
  char out[4096];
  const int rc = run(args, out, sizeof out, errs, n);
  const char *t = strstr(out, "total ");
  *total = t ? strtod(t + 6, NULL) : NAN;
  return rc;
}

Test(cli, energy_with_a_key_changed_is_that_scenes_energy)
{
  /* energy DIR --set energy.quadrature=24: the state's energy with the
  ** scene's nodes changed (what the run's nodes leave out), as computed in
  ** process with that scene, and not the run's own; a bad key is named. */
  write_file("scene.ini", scene_text);
  size_t segs[2] = {3, 4};
  lw_state st = {.scene = "scene.ini", .seed = 7, .sp = lw_splines_new(2, segs, NULL)};
  lw_test_straight(st.sp, 0, 20, 20, 70, 30);
  lw_test_circle(st.sp, 1, 50, 45, 12);
  char path[128], args[256], errs[4096];
  snprintf(path, sizeof path, "%s/state.lw", dir);
  cr_assert_eq(lw_state_write(&st, path, NULL), LW_OK);
  double own, fine;
  snprintf(args, sizeof args, "energy %s", dir);
  cr_assert_eq(energy_total(args, &own, errs, sizeof errs), 0, "%s", errs);
  snprintf(args, sizeof args, "energy --set energy.quadrature=24 %s", dir);
  cr_assert_eq(energy_total(args, &fine, errs, sizeof errs), 0, "%s", errs);
  lw_params p;
  lw_scene sc;
  snprintf(path, sizeof path, "%s/scene.ini", dir);
  cr_assert_eq(lw_params_read(&p, path, NULL), LW_OK);
  p.quadrature = 24;
  cr_assert_eq(lw_scene_init(&sc, &p, NULL), LW_OK);
  double term[LW_TERM_COUNT];
  const double want = lw_energy_compute(&sc, st.sp, term, NULL);
  cr_assert(fine == want && fine != own, "24 nodes: printed %.17g, computed %.17g; 8 nodes %.17g", fine, want, own);
  snprintf(args, sizeof args, "energy %s --set energy.quadrature=1", dir);
  cr_assert_eq(energy_total(args, &fine, errs, sizeof errs), 2);
  cr_assert(strstr(errs, "energy.quadrature"), "%s", errs);
  lw_scene_clear(&sc);
  lw_state_clear(&st);
}

/* A run's scene.ini edited since the run started (which resume refuses)
** gave `energy DIR` another energy without a word: it is noted, naming the
** key and line, and the energy printed is the edited scene's. */
Test(cli, energy_of_a_run_whose_scene_was_edited_says_so)
{
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out e --quiet --set anneal.sweeps=3 && %s energy e "
                          "2>err1.txt >e1.txt && sed -i 's/^strain = 10$/strain = 11/' e/scene.ini && %s energy e "
                          "2>err2.txt >e2.txt", dir, lw_test_bin(), lw_test_root(), lw_test_bin(), lw_test_bin()), 0);
  cr_assert_eq(lw_test_sh("cd %s && ! test -s err1.txt && ! cmp -s e1.txt e2.txt && grep -qF 'linewise: note: "
                          "e/scene.ini: ' err2.txt && grep -qF energy.strain err2.txt && "
                          "grep -qF \"(line $(grep -n '^strain = ' e/scene.ini | cut -d: -f1)) edited since the run "
                          "started; the energy below is of the scene "
                          "as it reads now\" err2.txt", dir),
               0, "%s", lw_test_slurp("%s/err2.txt", dir));
  /* a key's line taken out is noted too (a missing scene.field_core line
  ** makes a run one of before the core) */
  cr_assert_eq(lw_test_sh("cd %s && cp -r e k && sed -i -e 's/^strain = 11$/strain = 10/' -e '/^bending = /d' "
                          "k/scene.ini && %s energy k 2>err6.txt "
                          ">/dev/null && grep -qF \"linewise: note: k/scene.ini: 1 key fewer than when the run "
                          "started: the line of 'energy.bending' taken out\" err6.txt", dir, lw_test_bin()), 0, "%s",
               lw_test_slurp("%s/err6.txt", dir));
  /* values refused since 2026-12-05 stay a run's own (its scene.ini as
  ** resume and energy read it): a centre between -1 and 0 */
  cr_assert_eq(lw_test_sh("cd %s && sed -i 's/^center_y = .*/center_y = -0.5/' e/scene.ini && %s energy e "
                          ">/dev/null 2>err4.txt && grep -qF center_y err4.txt", dir, lw_test_bin()), 0, "%s",
               lw_test_slurp("%s/err4.txt", dir));
  /* but a value given now with --set is checked as a new scene's */
  cr_assert_eq(lw_test_sh("cd %s && %s energy e --set scene.center_x=-0.5 >/dev/null 2>err5.txt; test $? -eq 2 && "
                          "grep -qF 'expected -1 (the page centre)' err5.txt", dir, lw_test_bin()), 0, "%s",
               lw_test_slurp("%s/err5.txt", dir));
  /* a damaged hash is resume's to refuse, not an edit */
  cr_assert_eq(lw_test_sh("cd %s && cp -r e d && sed -i 's/^scene_hash = .*/scene_hash = zzzz/' d/state.lw && %s "
                          "energy d 2>err3.txt >/dev/null && ! test -s err3.txt", dir, lw_test_bin()), 0, "%s",
               lw_test_slurp("%s/err3.txt", dir));
}

/* A centre between -1 (the page centre) and 0 meant the page centre too,
** without a word; it is refused, naming the key. */
Test(cli, a_centre_below_0_other_than_minus_1_is_refused)
{
  char args[512], out[256], errs[1024];
  snprintf(args, sizeof args, "run %s/params/minimal.ini --out %s/c --set scene.center_y=-0.5", lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "%s", errs);
  cr_assert(strstr(errs, "key 'scene.center_y': expected -1 (the page centre) or a coordinate >= 0, got -0.5"), "%s",
            errs);
}

/* A polygon that reaches into the margin, where the crop cuts the drawing,
** was annealed and then drawn cut or empty, said only at the end: a note
** says so before the run; one inside the margin gets none.  And one that
** crosses itself is refused. */
Test(cli, a_polygon_in_the_margin_is_noted_before_the_run)
{
  char args[512], out[256], errs[8192];
  snprintf(args, sizeof args, "run %s/params/minimal.ini --out %s/p --stop-at 0 --set scene.boundary=polygon --set "
           "'scene.polygon=2 2 60 2 60 50 2 50'", lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert(strstr(errs, "linewise: note: scene.polygon (x 2 to 60, y 2 to 50 mm) reaches past the page inset by "
                         "scene.margin (5 mm), where plot.crop cuts the drawing"), "%s", errs);
  /* (closed by repeating its first vertex: no crossing) */
  snprintf(args, sizeof args, "run %s/params/minimal.ini --out %s/q --stop-at 0 --set scene.boundary=polygon --set "
           "'scene.polygon=10 10 60 10 60 50 10 50 10 10'", lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert_null(strstr(errs, "scene.polygon ("), "%s", errs);
  /* one that crosses itself is refused, naming its edges */
  snprintf(args, sizeof args, "run %s/params/minimal.ini --out %s/r --stop-at 0 --set scene.boundary=polygon --set "
           "'scene.polygon=20 20 80 90 80 20 20 90'", lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "%s", errs);
  cr_assert(strstr(errs, "key 'scene.polygon': the polygon crosses or touches itself: its edge from vertex 0 meets "
                         "the one from vertex 2: expected a simple polygon"), "%s", errs);
}

Test(cli, energy_lists_only_enabled_terms)
{
  write_file("scene.ini", "[energy]\nbending = 1\n");
  write_file("state.lw", "linewise-state 1\nscene scene.ini\nseed 1\nsweep 0\nsplines 1\nspline 1 3\n"
                         "10 10 3 0\n20 10 3 0\nend\n");
  char out[1024], errs[1024], args[128];
  snprintf(args, sizeof args, "energy %s", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert_str_eq(out, "bending 0\ntotal 0\n");
}

Test(cli, a_state_with_an_irregular_segment_is_refused)
{
  /* Segment 1 of spline 1 folds: its handles (length 1) are short against
  ** its chord (10 mm), so the speed dips to 3 / 10 = 0.3 of the mean at the
  ** ends, and with handles 0.2 to 0.06 (below the default). */
  write_file("scene.ini", "[energy]\nbending = 1\n");
  write_file("state.lw", "linewise-state 1\nscene scene.ini\nseed 1\nsweep 0\nsplines 2\nspline 1 3\n"
                         "10 10 3 0\n20 10 3 0\nspline 2 3\n10 20 3 0\n20 20 3 0\n30 20 0.2 0\nend\n");
  char out[1024], errs[1024], args[512];
  snprintf(args, sizeof args, "energy %s", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "%s", errs);
  cr_assert_str_eq(out, "", "nothing on stdout for a refused state");
  cr_assert(strstr(errs, "state.lw") && strstr(errs, "spline 1, segment 1") && strstr(errs, "0.06") &&
            strstr(errs, "energy.min_speed"), "the message must name the file, spline, segment, ratio "
            "and key: %s", errs);
  /* the keys relax it (the short handle also brings the integrand's
  ** singularity close: rho 1.28) */
  cr_assert(strstr(errs, "energy.regularity"), "%s", errs);
  write_file("scene.ini", "[energy]\nbending = 1\nmin_speed = 0.05\nregularity = 1.2\n");
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  /* and a run starting from it (init.from) is refused the same way, writing nothing */
  char scene[256];
  snprintf(scene, sizeof scene, "%s/from.ini", dir);
  write_file("from.ini", "[init]\nfrom = state.lw\n[energy]\nbending = 1\n[anneal]\nsweeps = 1\n");
  snprintf(args, sizeof args, "run %s --out %s/run --quiet", scene, dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "%s", errs);
  cr_assert(strstr(errs, "spline 1, segment 1") && strstr(errs, "energy.min_speed"), "%s", errs);
  char probe[256];
  snprintf(probe, sizeof probe, "%s/run", dir);
  cr_assert(access(probe, F_OK) != 0, "a refused run must not create its directory");
}

Test(cli, bad_input_exits_2_with_one_message)
{
  char out[1024], errs[1024], args[128];
  /* no state file */
  snprintf(args, sizeof args, "energy %s", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2);
  cr_assert(strstr(errs, "state.lw"), "%s", errs);
  cr_assert_str_eq(out, "");
  /* a bad key in the scene the state names */
  write_file("state.lw", "linewise-state 1\nscene scene.ini\nseed 1\nsweep 0\nsplines 0\nend\n");
  write_file("scene.ini", "[energy]\nbending = 1\nstrain = lots\n");
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2);
  cr_assert(strstr(errs, "scene.ini:3") && strstr(errs, "energy.strain"), "%s", errs);
  cr_assert_eq(strchr(errs, '\n'), errs + strlen(errs) - 1, "one line: %s", errs);
  cr_assert_str_eq(out, "");
  /* a malformed state */
  write_file("state.lw", "linewise-state 1\nscene scene.ini\nseed x\n");
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2);
  cr_assert(strstr(errs, "state.lw:3") && strstr(errs, "seed"), "%s", errs);
  /* usage */
  cr_assert_eq(run("energy", out, sizeof out, errs, sizeof errs), 2);
  cr_assert_eq(run("frobnicate", out, sizeof out, errs, sizeof errs), 2);
  cr_assert(strstr(errs, "frobnicate"));
  /* the listings and the version refuse an argument (help takes any: a command it is asked about) */
  static const char *const bare[] = {"params x", "schedules x", "--version x"};
  for (size_t k = 0; k < sizeof bare / sizeof bare[0]; k++) {
    cr_assert_eq(run(bare[k], out, sizeof out, errs, sizeof errs), 2, "%s", bare[k]);
    cr_assert(strstr(errs, "unexpected 'x' (it takes no arguments)"), "%s: %s", bare[k], errs);
  }
  /* splines that do not fit for the boundary's clearance name it too (it
  ** blamed init.segment_length alone), in its unit and in mm (it said the
  ** elements were mm) */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --out %s/bc --set energy.boundary_clearance=100 --set "
                          "init.segment_length=4 2>%s/err.txt; test $? -eq 2 && grep -q 'or lower "
                          "energy.boundary_clearance (100 length elements, 50 mm here, from every edge))$' "
                          "%s/err.txt", lw_test_bin(), lw_test_root(), dir, dir, dir), 0, "%s",
               lw_test_slurp("%s/err.txt", dir));
  /* a run directory named like an option: the message says how to name it,
  ** and "--" ends the options (an option's value "--" is no end); a
  ** directory's trailing slashes go (its files were "./-r////final.svg") */
  cr_assert_eq(lw_test_sh("cd %s && mkdir -p ./-r && { %s resume -r 2>err.txt; test $? -eq 2; } && "
                          "grep -q \"('-r' is a file or directory here: write './-r', or '--' before it)\" err.txt",
                          dir, lw_test_bin()), 0);
  cr_assert_eq(lw_test_sh("cd %s && cp %s/params/minimal.ini ./-s.ini && %s run --out -r --quiet --set "
                          "anneal.sweeps=30 --set moves.tune_sweeps=0 -- -s.ini && test -s ./-r/summary.json && "
                          "%s energy -- -r | grep -q '^total ' && %s stats -- -r >/dev/null && "
                          "{ %s resume --stop-at -- -r 2>err.txt; test $? -eq 2; } && grep -q 'stop-at' err.txt && "
                          "%s resume ./-r/// 2>err.txt && grep -q 'done: ./-r/final.svg' err.txt",
                          dir, lw_test_root(), lw_test_bin(), lw_test_bin(), lw_test_bin(), lw_test_bin(),
                          lw_test_bin()), 0,
               "%s", lw_test_slurp("%s/err.txt", dir));
}

/* A no-break space after a value that the reader takes as text (a schedule's
** or a system's name, a file's path) is named as the reader's refusals name
** it: it showed as "got 'geometric '" or "pic.png : cannot open". */
Test(cli, an_unseen_character_is_named_in_the_values_refused_after_reading)
{
  static const char *const line[][2] = {{"[anneal]\nschedule = geometric\xc2\xa0\n", "anneal.schedule"},
                                        {"[scene]\nsystem = splines\xc2\xa0\n", "scene.system"},
                                        {"[scene]\ndriver = barker\xc2\xa0\n", "scene.driver"},
                                        {"[scene]\nimage = none.png\xc2\xa0\n", "scene.image"}};
  char out[1024], errs[1024], args[256];
  for (size_t k = 0; k < sizeof line / sizeof line[0]; k++) {
    write_file("nbsp.ini", line[k][0]);
    snprintf(args, sizeof args, "run %s/nbsp.ini --out %s/nbsp --quiet", dir, dir);
    cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "%s", line[k][1]);
    cr_assert(strstr(errs, line[k][1]) && strstr(errs, "is a no-break space, U+00A0: delete it or type a plain space"),
              "%s", errs);
    cr_assert_eq(strchr(errs, '\n'), errs + strlen(errs) - 1, "one line: %s", errs);
  }
  /* but a file that is found holds its bytes rightly (a Latin-1 name):
  ** what is wrong with it is said without "delete it" */
  write_file("M\xfcller.png", "not an image");
  write_file("latin.ini", "[scene]\nimage = M\xfcller.png\n");
  snprintf(args, sizeof args, "run %s/latin.ini --out %s/latin --quiet", dir, dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2);
  cr_assert(strstr(errs, "key 'scene.image'") && strstr(errs, "not an image") && !strstr(errs, "delete it"), "%s",
            errs);
}

/* The release, as --version, version and -V give it, is the man page's and
** summary.json's. */
Test(cli, the_version_is_the_man_pages_and_the_summarys)
{
  char out[256], errs[256], want[64];
  snprintf(want, sizeof want, "linewise %s\n", LW_VERSION);
  static const char *const ask[] = {"--version", "version", "-V"};
  for (size_t k = 0; k < sizeof ask / sizeof ask[0]; k++) {
    cr_assert_eq(run(ask[k], out, sizeof out, errs, sizeof errs), 0, "%s", ask[k]);
    /* and the commit it was built from (version.h), "unknown" outside git */
    const char *build = out + strlen(want), *eol = strchr(build, '\n');
    cr_assert(!strncmp(out, want, strlen(want)) && !strncmp(build, "build ", 6) && eol &&
              (size_t)(eol - build) == 6 + strlen(lw_version_build()) && !strncmp(eol + 1, "pair kernels ", 13),
              "%s: %s", ask[k], out);
  }
  cr_assert_eq(lw_test_sh("grep -q '^.TH LINEWISE 1 \"[0-9]*\" \"linewise %s\"' %s/docs/linewise.1", LW_VERSION,
                          lw_test_root()),
               0, "docs/linewise.1 names another release than %s", LW_VERSION);
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set anneal.sweeps=2 --out %s/v --quiet && "
                          "grep -q '^  \"version\": \"%s\",$' %s/v/summary.json && "
                          "grep -q '^  \"build\": \"[0-9a-f]\\{12\\}\\(-dirty\\)\\?\",$\\|^  \"build\": \"unknown\",$' "
                          "%s/v/summary.json && grep -q '^; written by linewise %s, build ' %s/v/scene.ini",
                          lw_test_bin(), lw_test_root(), dir, LW_VERSION, dir, dir, LW_VERSION, dir),
               0);
}

/* The libraries the process runs with are --version's, summary.json's and
** scene.ini's; run of a scene.ini run on another version of one names it,
** and of one run on these says nothing of libraries. */
Test(cli, the_libraries_are_named_and_a_change_of_them_said)
{
  char libs[256], out[1024], errs[256];
  lw_version_libraries(libs, sizeof libs);
  cr_assert(strstr(libs, "GSL " GSL_VERSION ", cairo ") && strstr(libs, ", zlib "), "%s", libs);
  cr_assert_eq(run("--version", out, sizeof out, errs, sizeof errs), 0);
  char want[300];
  snprintf(want, sizeof want, "\nlibraries %s\ncompiler %s\n", libs, lw_version_compiler());
  cr_assert(strstr(out, want) && strncmp(lw_version_compiler(), "unknown", 7), "%s", out);
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set anneal.sweeps=2 --out %s/a --quiet && "
                          "grep -qxF '  \"libraries\": \"%s\",' %s/a/summary.json && "
                          "grep -qxF '; libraries %s' %s/a/scene.ini && "
                          "{ %s run %s/a/scene.ini --set anneal.sweeps=2 --out %s/b --quiet 2>%s/b.txt; } && "
                          "! grep -q 'libraries' %s/b.txt && "
                          /* blanks about the items, and a library the run's build did not record, are no change */
                          "sed 's/^; libraries \\(.*\\), \\(.*\\)$/; libraries  \\1 ,  \\2 , foo 1.0 /' %s/a/scene.ini "
                          "> %s/d.ini && grep -q '^; libraries  .* , foo 1.0 $' %s/d.ini && "
                          "{ %s run %s/d.ini --set anneal.sweeps=2 --out %s/d --quiet 2>%s/d.txt; } && "
                          "! grep -q 'libraries' %s/d.txt && sed -i 's/^; libraries \\(.*\\)cairo [^,]*/; "
                          "libraries \\1cairo 0.0.1/' %s/a/scene.ini && "
                          "{ %s run %s/a/scene.ini --set anneal.sweeps=2 --out %s/c --quiet 2>%s/c.txt; }",
                          lw_test_bin(), lw_test_root(), dir, libs, dir, libs, dir, lw_test_bin(), dir, dir, dir, dir,
                          dir, dir, dir, lw_test_bin(), dir, dir, dir, dir, dir, lw_test_bin(), dir, dir, dir),
               0, "%s", lw_test_slurp("%s/b.txt", dir));
  const char *said = lw_test_slurp("%s/c.txt", dir);
  const char *cairo = strstr(libs, "cairo ") + 6;
  snprintf(want, sizeof want, "was run on other libraries (cairo 0.0.1 then, %.*s now): the last bits",
           (int)strcspn(cairo, ","), cairo);
  cr_assert(strstr(said, want), "%s", said);
}

/* A resume without timing.txt (state.lw and scene.ini copied elsewhere)
** says so, and its rate counts its own proposals over its own sweeps, on
** later resumes too (timing.txt's untimed_proposals): every proposal over
** them gave a rate many times too high, unsaid. */
/* The film ends on the drawing: the end has a frame, on the frames_every
** grid or not (a film of 200 sweeps at every 30 ended at 180).  A killed
** run resumed after its interval was edited (the run's frames past the
** checkpoint stand in for the killed part's: 16 and 25 off the new grid,
** 20 on it): those off the grid go (the film had steps of 5 and then 20,
** with 105, 110 and 115 among the 20s), and a size edited too is said. */
Test(cli, the_film_ends_on_the_drawing_and_a_resume_keeps_one_grid)
{
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --set anneal.sweeps=23 --set output.frames_every=5 "
                          "--out f --quiet && test \"$(ls f/frames | tr '\\n' ' ')\" = 'frame-000000.png "
                          "frame-000005.png frame-000010.png frame-000015.png frame-000020.png frame-000023.png '",
                          dir, lw_test_bin(), lw_test_root()),
               0);
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --set anneal.sweeps=40 --set output.frames_every=5 "
                          "--out k --quiet --stop-at 15 && for s in 16 20 25; do cp k/frames/frame-000015.png "
                          "k/frames/frame-0000$s.png; done && sed -i 's/^frames_every = 5$/frames_every = 10/; 146s/^"
                          "png_scale = 4$/png_scale = 2/' k/scene.ini && grep -qx 'png_scale = 2' k/scene.ini && "
                          "{ %s resume k 2> k.err; }", dir, lw_test_bin(), lw_test_root(), lw_test_bin()),
               0);
  cr_assert_eq(lw_test_sh("cd %s && test \"$(ls k/frames | tr '\\n' ' ')\" = 'frame-000000.png frame-000005.png "
                          "frame-000010.png frame-000015.png frame-000020.png frame-000030.png frame-000040.png ' && "
                          "! cmp -s k/frames/frame-000015.png k/frames/frame-000020.png", dir),
               0);
  char *e = lw_test_slurp("%s/k.err", dir);
  cr_assert(strstr(e, "linewise: note: k/frames/ mixes sizes: its frames to sweep 15 are 400 x 400 pixels, this "
                      "resume's 200 x 200 (a drawing key of scene.ini"), "%s", e);
  free(e);
  /* a frames/ planted as a link is refused before the sweeps, as a run's
  ** is (it was found at the first frame, the sweeps since the checkpoint
  ** run for nothing) */
  cr_assert_eq(lw_test_sh("cd %s && cp k/state.lw k.lw && mv k/frames kf && mkdir vf && ln -s ../vf k/frames && "
                          "{ %s resume k --sweeps 10 --quiet 2> l.err; test $? = 2; } && cmp k.lw k/state.lw && "
                          "test -z \"$(ls vf)\" && grep -q 'k/frames: a symbolic link, not a folder' l.err", dir,
                          lw_test_bin()),
               0, "%s", lw_test_slurp("%s/l.err", dir));
}

Test(cli, a_resume_without_its_timing_rates_its_own_proposals)
{
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --set anneal.sweeps=60 --stop-at 40 --out t --quiet "
                          "&& rm t/timing.txt && { %s resume t --quiet --sweeps 10 2> t1.txt; } && "
                          "{ %s resume t --quiet 2> t2.txt; }",
                          dir, lw_test_bin(), lw_test_root(), lw_test_bin(), lw_test_bin()),
               0);
  cr_assert(strstr(lw_test_slurp("%s/t1.txt", dir), "linewise: note: t/timing.txt is missing or unreadable: "
                                 "summary.json's wall_seconds and sweep_seconds count from this resume on"));
  cr_assert_eq(lw_test_slurp("%s/t2.txt", dir)[0], '\0', "said again: %s", lw_test_slurp("%s/t2.txt", dir));
  /* proposals_per_second x sweep_seconds = proposals less those of the 40
  ** sweeps before the timing was lost, which timing.txt counts */
  cr_assert_eq(lw_test_sh("cd %s/t && u=$(awk '/^untimed_proposals/ { print $2 }' timing.txt) && test \"$u\" -gt 0 && "
                          "awk -F'[:,]' -v u=$u '/\"proposals\"/ { p = $2 } /\"sweep_seconds\"/ { s = $2 } "
                          "/\"proposals_per_second\"/ { r = $2 } END { d = r * s - (p - u); "
                          "exit !(s > 0 && u == p * 40 / 60 && d * d < 1e-6 * p * p) }' summary.json",
                          dir),
               0, "%s", lw_test_slurp("%s/t/timing.txt", dir));
  /* a release before 2026-12-04 wrote the wall time alone: it counts on
  ** (it was said missing and dropped), the sweeps' time from the resume */
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --set anneal.sweeps=60 --stop-at 40 --out w --quiet "
                          "&& echo 'wall_seconds 1000' > w/timing.txt && { %s resume w --quiet 2> w1.txt; }",
                          dir, lw_test_bin(), lw_test_root(), lw_test_bin()),
               0);
  cr_assert(strstr(lw_test_slurp("%s/w1.txt", dir), "linewise: note: w/timing.txt, of a release before 2026-12-04, "
                                 "has the wall time alone: summary.json's sweep_seconds counts from this resume on"),
            "%s", lw_test_slurp("%s/w1.txt", dir));
  cr_assert_eq(lw_test_sh("cd %s/w && awk -F'[:,]' '/\"wall_seconds\"/ { w = $2 } /\"sweep_seconds\"/ { s = $2 } "
                          "END { exit !(w > 1000 && w < 1100 && s > 0 && s < 100) }' summary.json", dir),
               0, "%s", lw_test_slurp("%s/w/summary.json", dir));
  /* a sweep time there that is no number is damage, not an older release;
  ** so is a count of proposals below 0 ("-7" was read as 2^64 - 7) */
  static const char *const damaged[] = {"wall_seconds 1000\\nsweep_seconds garbage\\n",
                                        "wall_seconds 1000\\nsweep_seconds 5\\nuntimed_proposals -7\\n"};
  for (int k = 0; k < 2; k++) {
    cr_assert_eq(lw_test_sh("cd %s && rm -rf x && %s run %s/params/minimal.ini --set anneal.sweeps=60 --stop-at 40 "
                            "--out x --quiet && printf '%s' > x/timing.txt && { %s resume x --quiet 2> x1.txt; }", dir,
                            lw_test_bin(), lw_test_root(), damaged[k], lw_test_bin()),
                 0);
    cr_assert(strstr(lw_test_slurp("%s/x1.txt", dir), "linewise: note: x/timing.txt is missing or unreadable: "),
              "%s: %s", damaged[k], lw_test_slurp("%s/x1.txt", dir));
  }
}

/* A checkpoint whose state.lw was committed but whose replica file could
** not follow names the checkpoint state.lw holds (it named the one before). */
Test(cli, a_failed_replica_file_names_the_checkpoint_state_lw_holds)
{
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/lj13.ini --set anneal.sweeps=300 --set tempering.replicas=2 "
                          "--set output.checkpoint_every=100 --out r --quiet --stop-at 100 && rm r/replica-1.lw && "
                          "mkdir -p r/replica-1.lw/x && { %s resume r --quiet --stop-at 200 2> e.txt; "
                          "test $? -eq 1; } && grep -qx 'sweep = 200' r/state.lw",
                          dir, lw_test_bin(), lw_test_root(), lw_test_bin()),
               0, "%s", lw_test_slurp("%s/e.txt", dir));
  const char *e = lw_test_slurp("%s/e.txt", dir);
  cr_assert(strstr(e, "r/replica-1.lw: cannot replace: ") &&
                strstr(e, "r/state.lw holds the checkpoint of sweep 200: "), "%s", e);
}

/* LW_LANES narrows the SIMD kernels, so that one machine checks the promise
** that every width gives the same bits end to end: runs with every term
** and the near field on, at 2, 4 and the processor's lanes, write the same
** files; --version names the widths; another value is refused. */
Test(cli, every_simd_width_writes_the_same_files)
{
  cr_assert_eq(lw_test_sh("LW_LANES=2 %s --version | grep -q '^pair kernels 2 lanes, cell scan 2 lanes'",
                          lw_test_bin()), 0);
  cr_assert_eq(lw_test_sh("LW_LANES=3 %s --version 2>%s/e.txt; test $? -eq 2 && grep -q 'LW_LANES: expected 2, 4 or "
                          "8' %s/e.txt", lw_test_bin(), dir, dir), 0);
  static const char *const lanes[] = {"", "LW_LANES=4", "LW_LANES=2"};
  for (int k = 0; k < 3; k++)
    cr_assert_eq(lw_test_sh("%s %s run %s/params/example.ini --threads 1 --quiet --set anneal.sweeps=3 "
                            "--set output.png_scale=1 --out %s/w%d", lanes[k], lw_test_bin(), lw_test_root(), dir, k),
                 0);
  for (int k = 1; k < 3; k++)
    cr_assert_eq(lw_test_sh("cmp %s/w0/state.lw %s/w%d/state.lw && cmp %s/w0/final.svg %s/w%d/final.svg && cmp "
                            "%s/w0/trace.csv %s/w%d/trace.csv", dir, dir, k, dir, dir, k, dir, dir, k),
                 0, "%s", lanes[k]);
}

/* NUMERICS.md promises the same files from GCC and clang builds (the
** Makefile's -ffp-contract=off: clang fused a multiply and an add where
** -march allowed it): a clang build of the same sources writes the bytes of
** this build for a picture scene, a tempering NURBS wire and growing
** particles.  Needs clang (make deps installs it). */
Test(cli, a_clang_build_writes_the_same_files, .timeout = 300)
{
  if (lw_test_sh("command -v clang >/dev/null"))
    cr_skip_test("clang is not installed (make deps installs it)");
  cr_assert_eq(lw_test_sh("mkdir -p %s/cl && cp -r %s/Makefile %s/src %s/include %s/cl && cd %s/cl && "
                          "make -j2 CC=clang bin/linewise >make.log 2>&1", dir, lw_test_root(), lw_test_root(),
                          lw_test_root(), dir, dir),
               0, "%s", lw_test_slurp("%s/cl/make.log", dir));
  static const char *const run[][2] = {
      {"example", "--set anneal.sweeps=3 --set output.png_scale=1"},
      {"wire-ladder", "--set anneal.sweeps=20"},
      {"particles-grow", "--set anneal.sweeps=20"},
  };
  for (size_t k = 0; k < sizeof run / sizeof *run; k++) {
    cr_assert_eq(lw_test_sh("cd %s && for b in %s:gcc cl/bin/linewise:clang; do ${b%%:*} run %s/params/%s.ini "
                            "--threads 2 --quiet %s --out ${b##*:}-%zu || exit 1; done && for f in state.lw trace.csv "
                            "final.png; do cmp gcc-%zu/$f clang-%zu/$f || exit 1; done",
                            dir, lw_test_bin(), lw_test_root(), run[k][0], run[k][1], k, k, k),
                 0, "%s", run[k][0]);
  }
}

/* A key the scene's system reads under no driver is refused before
** anything is written, naming where it was set and who reads it; the
** default, named, is not; a key only the other driver reads is noted and the
** run goes on (one scene file may serve both drivers). */
Test(cli, keys_the_system_never_reads_are_refused)
{
  char out[4096], errs[8192], args[512];
  static const struct { const char *scene, *set, *want; } bad[] = {
    {"particles-sheet", "energy.bending=5",
     "--set: key 'energy.bending': the particles system reads it under no driver (read by: splines); "
     "expected no line, or the default '0'"},
    {"wire", "output.pdf=1", "key 'output.pdf': the nurbs system reads it under no driver (read by: splines)"},
    {"wire", "dynamics.pin=ends", "key 'dynamics.pin': the nurbs system reads it under no driver (read by: "
     "splines under dynamics)"},
    {"example", "particles.r0=2", "key 'particles.r0': the splines system reads it under no driver (read by: "
     "particles)"},
    {"lj13", "scene.preset=photo", "key 'scene.preset': the particles system"},
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    snprintf(args, sizeof args, "run %s/params/%s.ini --quiet --set %s --out %s/r%zu", lw_test_root(), bad[k].scene,
             bad[k].set, dir, k);
    cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "%s", bad[k].set);
    cr_assert(strstr(errs, bad[k].want), "%s: %s", bad[k].set, errs);
    snprintf(args, sizeof args, "test ! -e %s/r%zu", dir, k);
    cr_assert_eq(system(args), 0, "%s: a run directory was made", bad[k].set);
  }
  /* in the file, with its line; the default given is accepted */
  write_file("p.ini", "[scene]\nsystem = particles\n[particles]\ncount = 3\n[energy]\nbending = 0\n"
                      "[anneal]\nsweeps = 1\n");
  snprintf(args, sizeof args, "run %s/p.ini --out %s/p --quiet", dir, dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  write_file("q.ini", "[scene]\nsystem = particles\n[particles]\ncount = 3\n[energy]\nbending = 1\n");
  snprintf(args, sizeof args, "run %s/q.ini --out %s/q --quiet", dir, dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2);
  cr_assert(strstr(errs, "q.ini:6: key 'energy.bending'"), "%s", errs);
  /* energy --set of a key the run's system never reads measures nothing */
  snprintf(args, sizeof args, "energy %s/p --set energy.quadrature=32", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2);
  cr_assert(strstr(errs, "--set: key 'energy.quadrature': the particles system reads it under no driver"), "%s",
            errs);
  snprintf(args, sizeof args, "energy %s/p --set particles.r0=1.1", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  /* the other driver's keys: a note, and the run */
  snprintf(args, sizeof args, "run %s/params/hanging.ini --set anneal.sweeps=1 --set moves.point=3 --out %s/h",
           lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert(strstr(errs, "linewise: note: under driver = dynamics these keys have no effect: ") &&
            strstr(errs, "moves.point (--set)"), "%s", errs);
  /* keys the scene's other settings leave idle: a note with why (a table
  ** file that does not exist went unseen until its schedule was chosen) */
  write_file("i.ini", "[init]\nsplines = 3\n[anneal]\nsweeps = 1\ntable = missing.txt\n[scene]\n"
                      "polygon = 1 2 three\nimage_invert = 1\n[moves]\nbirth = 2\n");
  snprintf(args, sizeof args, "run %s/i.ini --out %s/i --set tempering.t_min=0.5 --set init.coverage=0.2", dir, dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert(strstr(errs, "linewise: note: these keys have no effect here: anneal.table (") &&
            strstr(errs, "i.ini:5: anneal.schedule reads no table)") &&
            strstr(errs, "scene.polygon (") && strstr(errs, "i.ini:7: scene.boundary is not polygon)") &&
            strstr(errs, "scene.image_invert (") && strstr(errs, "i.ini:8: no scene.image)") &&
            strstr(errs, "init.coverage (--set: init.splines is not 0)") &&
            strstr(errs, "tempering.t_min (--set: one replica)") &&
            strstr(errs, "moves.birth (") && strstr(errs, "i.ini:10: moves.fixed_count = 1)"), "%s", errs);
  /* the other systems' keys that their settings leave idle: the weights'
  ** with frozen weights, gravity without mass, the births' without births,
  ** a weighting's width under another weighting */
  static const struct { const char *scene, *set, *want; } idle[] = {
    {"wire", "--set nurbs.weight_inertia=5", "nurbs.weight_inertia (--set: nurbs.free_weights = 0)"},
    {"minimal", "--set energy.field=1 --set scene.field_core=3",
     "scene.field_core (--set: scene.field is not radial or vortex)"},
    {"study", "--set scene.potential_paper=0", "scene.potential_paper (--set: scene.potential_blur is 0)"},
    {"wire", "--set dynamics.rho=0 --set dynamics.gamma=5", "params/wire.ini:29: dynamics.rho = 0: no mass to weigh)"},
    {"particles-sheet", "--set particles.max_count=50 --set particles.sigma=0.3",
     "particles.max_count (--set: no particles.birth or death), particles.sigma (--set: particles.weight = poly)"},
    {"minimal", "--set 'tempering.ladder=0.01 0.1 1' --set tempering.t_max=5",
     "tempering.t_max (--set: tempering.ladder names the temperatures)"},
    {"whip", "--seed 2", "anneal.seed (--seed: the dynamics from init.from draws no random number)"},
    {"wire", "--seed 2", "anneal.seed (--seed: the D-NURBS dynamics draws no random number)"},
    /* a plotter's bed, which only machine files are checked against */
    {"minimal", "--set plot.bed_width=50 --set plot.gcode_pen_up=M5",
     "plot.bed_width (--set: neither output.hpgl nor output.gcode), plot.gcode_pen_up (--set: output.gcode = 0)"},
    {"minimal", "--set output.hpgl=1 --set plot.bed_width=500 --set plot.gcode_travel=feed",
     "no effect here: plot.gcode_travel (--set: output.gcode = 0)\n"},
    /* the quench's, the pair term's, the ladder tuning's and the walls' */
    {"minimal", "--set anneal.quench_tol=1e-3", "anneal.quench_tol (--set: anneal.quench = none)"},
    {"minimal", "--set energy.pair=0 --set energy.pair_near=3",
     "/params/minimal.ini:17: energy.pair = 0), energy.pair_near (--set: energy.pair = 0)"},
    {"minimal", "--set tempering.replicas=2 --set tempering.ladder_sweeps=5",
     "tempering.ladder_sweeps (--set: tempering.tune_ladder = fixed)"},
    /* a field or a potential without its term, and each kind's keys under another */
    {"minimal", "--set scene.field=vortex", "scene.field (--set: energy.field = 0)"},
    {"minimal", "--set energy.field=1 --set scene.field=vortex --set scene.field_wavelength=33",
     "scene.field_wavelength (--set: scene.field is not waves)"},
    {"minimal", "--set energy.potential=1 --set scene.potential=radial --set scene.potential_angle=45",
     "scene.potential_angle (--set: scene.potential is not ramp)"},
    {"minimal", "--set scene.center_y=30",
     "scene.center_y (--set: no radial or vortex field, no ramp or radial potential)"},
    /* a schedule's ends it does not read (t_start counts under tempering) */
    {"minimal", "--set anneal.schedule=constant --set anneal.t_end=0.5",
     "anneal.t_end (--set: anneal.schedule reads no t_end)"},
    {"particles-sheet", "--set particles.boundary_radius=3 --set particles.alpha_b=1 --set particles.pinned=1",
     "particles.boundary_radius (--set: particles.boundary is not sphere), particles.alpha_b (--set: "
     "particles.boundary = none), particles.pinned (--set: no particles.points)"},
  };
  for (size_t k = 0; k < sizeof idle / sizeof idle[0]; k++) {
    snprintf(args, sizeof args, "run %s/params/%s.ini --out %s/n%zu --set anneal.sweeps=1 %s", lw_test_root(),
             idle[k].scene, dir, k, idle[k].set);
    cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
    cr_assert(strstr(errs, "linewise: note: these keys have no effect here: ") && strstr(errs, idle[k].want),
              "%s: %s", idle[k].set, errs);
  }
  /* a table's t_start, with one replica (minimal.ini's t_end is the default: not noted) */
  write_file("t.txt", "1 1\n5 0.01\n");
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out tt --set anneal.sweeps=1 --set "
                          "anneal.schedule=table --set anneal.table=t.txt --set anneal.t_start=3 2>err.txt && grep -qF "
                          "'anneal.t_start (--set: anneal.schedule reads no t_start)' err.txt", dir,
                          lw_test_bin(), lw_test_root()), 0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* a schedule that never reaches its end says so (each was silent) */
  static const struct { const char *set, *want; } end[] = {
    {"--set anneal.sweeps=10 --set anneal.steps=15", "linewise: note: anneal.steps = 15 is more than the 10 sweeps: "
     "some steps are skipped, and the run ends at step 13 (steps count from 0 to 14), short of t_end\n"},
    {"--set anneal.sweeps=6 --set anneal.steps=1 --set anneal.t_end=0.5", "linewise: note: anneal.steps = 1: the run "
     "stays at t_start = 1 (t_end = 0.5 is the temperature of the last of two or more steps)\n"},
    {"--set anneal.sweeps=10 --set anneal.steps=5 --set anneal.schedule=table --set anneal.table=t.txt",
     "linewise: note: anneal.table has rows past step 4, the last of anneal.steps = 5 (steps count from 0): they "
     "are never reached\n"},
    {"--set anneal.sweeps=10 --set anneal.steps=20 --set anneal.schedule=table --set anneal.table=t19.txt",
     "linewise: note: anneal.steps = 20 is more than the 10 sweeps: some steps are skipped, and the run ends at step "
     "18 (steps count from 0 to 19), short of the table's last step\n"},
    /* a table that stops short of the run holds its last row, which was silent */
    {"--set anneal.sweeps=40 --set anneal.steps=10 --set anneal.schedule=table --set anneal.table=t.txt",
     "linewise: note: anneal.table ends at step 5, before the run's last step 9 (anneal.steps = 10, steps count from "
     "0): its last temperature, 0.01, holds for the 4 steps after it (a row at step 9 ends the table where the run "
     "does)\n"},
    /* steps tuned at T = 0 toward more than the half of the smallest steps
    ** taken there shrank to 1e-15 mm (a greedy descent's steps); barker
    ** aims at a share of its own half, which is in reach */
    {"--set anneal.sweeps=3 --set anneal.schedule=constant --set anneal.t_start=0 --set moves.target=0.7",
     "linewise: note: the run tunes its steps at T = 0, where a chain takes its smallest steps half the time: "
     "moves.target = 0.7 is out of reach there, and the steps shrink to nothing (expected a target below 0.5)\n"},
    /* (a table held at 0 too) */
    {"--set anneal.sweeps=3 --set anneal.steps=3 --set anneal.schedule=table --set anneal.table=t0.txt --set "
     "moves.target=0.6", "the run tunes its steps at T = 0, where a chain takes its smallest steps half the time: "
     "moves.target = 0.6 is out of reach there"},
  };
  write_file("t0.txt", "0 0\n2 0\n");
  write_file("t19.txt", "1 1\n19 0.01\n");
  /* two notes, two lines (joined by "; " they ran 600 characters) */
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out e8 --set anneal.sweeps=10 --set anneal.steps=10 "
                          "--set anneal.schedule=table --set anneal.table=t0.txt --set moves.target=0.6 2>err.txt "
                          ">/dev/null && grep -q '^linewise: note: anneal.table ends at step 2, .* does)$' err.txt && "
                          "grep -q '^linewise: note: the run tunes its steps at T = 0, ' err.txt", dir, lw_test_bin(),
                          lw_test_root()), 0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* (one that ends at the run's last step is not noted; one that ends
  ** before it is not said to fall short where the run skips steps) */
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out e6 --set anneal.sweeps=12 --set anneal.steps=6 "
                          "--set anneal.schedule=table --set anneal.table=t.txt 2>err.txt >/dev/null && ! grep -q "
                          "'anneal.table ends' err.txt && %s run %s/params/minimal.ini --out e7 --set anneal.sweeps=10 "
                          "--set anneal.steps=20 --set anneal.schedule=table --set anneal.table=t.txt 2>err.txt "
                          ">/dev/null && ! grep -q 'short of' err.txt && grep -q 'anneal.table ends at step 5, before "
                          "the run.s last step 18' err.txt", dir, lw_test_bin(), lw_test_root(), lw_test_bin(),
                          lw_test_root()), 0, "%s", lw_test_slurp("%s/err.txt", dir));
  for (size_t k = 0; k < sizeof end / sizeof end[0]; k++) {
    snprintf(args, sizeof args, "run %s/params/minimal.ini --out %s/e%zu %s", lw_test_root(), dir, k, end[k].set);
    /* (from dir: --set takes the table relative to the current directory) */
    cr_assert_eq(lw_test_sh("cd %s && %s %s 2>err.txt >/dev/null", dir, lw_test_bin(), args), 0, "%s", end[k].set);
    char *e = lw_test_slurp("%s/err.txt", dir);
    cr_assert(strstr(e, end[k].want), "%s: %s", end[k].set, e);
    free(e);
  }
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out bz --set anneal.sweeps=3 --set "
                          "anneal.schedule=constant --set anneal.t_start=0 --set moves.target=0.7 --set "
                          "scene.driver=barker 2>err.txt >/dev/null && ! grep -q 'at T = 0' err.txt", dir, lw_test_bin(),
                          lw_test_root()), 0);
  /* a target of exactly 0.5 and target_spline are noted; a run that tunes no steps is not */
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out b5 --set anneal.sweeps=3 --set "
                          "anneal.schedule=constant --set anneal.t_start=0 --set moves.target=0.5 2>err.txt "
                          ">/dev/null && grep -q 'moves.target = 0.5 is out of reach' err.txt && %s run "
                          "%s/params/minimal.ini --out b6 "
                          "--set anneal.sweeps=3 --set anneal.schedule=constant --set anneal.t_start=0 --set "
                          "moves.target_spline=0.7 2>err.txt >/dev/null && grep -q 'moves.target_spline = 0.7 is out of "
                          "reach' err.txt && %s run %s/params/minimal.ini --out b7 --set anneal.sweeps=3 --set "
                          "anneal.schedule=constant --set anneal.t_start=0 --set moves.target=0.7 --set "
                          "moves.tune_sweeps=0 "
                          "2>err.txt >/dev/null && ! grep -q 'at T = 0' err.txt", dir, lw_test_bin(), lw_test_root(),
                          lw_test_bin(), lw_test_root(), lw_test_bin(), lw_test_root()), 0);
  /* a target no move tunes toward is not noted */
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out bs --set anneal.sweeps=3 --set "
                          "anneal.schedule=constant --set anneal.t_start=0 --set moves.translate=0 --set moves.rotate=0 "
                          "--set moves.target_spline=0.6 2>err.txt >/dev/null && ! grep -q 'at T = 0' err.txt", dir,
                          lw_test_bin(), lw_test_root()), 0);
}

/* A PDF page past what PDF allows (14,400 points) is refused before the run:
** cairo's PDF of a page of kilometres ran out of memory or crashed. */
Test(cli, a_pdf_page_past_what_pdf_allows_is_refused)
{
  char out[1024], errs[2048], args[512];
  snprintf(args, sizeof args, "run %s/params/minimal.ini --quiet --set scene.width=6000 --set output.pdf=1 "
           "--out %s/pdf", lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2);
  cr_assert(strstr(errs, "key 'output.pdf': a page of 6000 x 100 mm; PDF pages are at most 5080 mm"), "%s", errs);
  snprintf(args, sizeof args, "run %s/params/minimal.ini --quiet --set scene.width=5000 --set output.pdf=1 "
           "--set anneal.sweeps=1 --out %s/pdf", lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
}

Test(cli, empty_scene_has_zero_energy)
{
  write_file("scene.ini", "[energy]\npair = 1\nboundary = 1\n");
  write_file("state.lw", "linewise-state 1\nscene scene.ini\nseed 1\nsweep 0\nsplines 0\nend\n");
  char out[1024], errs[1024], args[128];
  snprintf(args, sizeof args, "energy %s", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert_str_eq(out, "pair 0\nboundary 0\ntotal 0\n");
}

/* A generated reference must end with exactly what the command prints. */
static void check_generated_doc(const char *command, const char *doc_name)
{
  const char *root = getenv("LW_ROOT");
  cr_assert_not_null(root);
  static char out[262144], errs[1024], doc[262144];
  cr_assert_eq(run(command, out, sizeof out, errs, sizeof errs), 0);
  /* (the parameters' text passed 64 KiB, cut off here: "stale") */
  cr_assert(strlen(out) < sizeof out - 1, "'linewise %s' printed %zu bytes or more", command, sizeof out - 1);
  char path[1024];
  snprintf(path, sizeof path, "%s/docs/%s", root, doc_name);
  FILE *f = fopen(path, "r");
  cr_assert_not_null(f, "%s missing", path);
  size_t n = fread(doc, 1, sizeof doc - 1, f);
  doc[n] = '\0';
  fclose(f);
  const char *gen = out + 1; /* the generated text starts with a blank line */
  size_t lg = strlen(gen);
  cr_assert(n >= lg && !strcmp(doc + n - lg, gen), "docs/%s is stale: run 'make docs'", doc_name);
}

Test(cli, generated_references_are_current)
{
  check_generated_doc("params", "PARAMETERS.md");
  check_generated_doc("schedules", "SCHEDULES.md");
}

Test(cli, a_state_without_a_later_term_resumes_and_unknown_keys_are_refused)
{
  /* A checkpoint written before a term existed has no energy.<term> key: it
  ** resumes with that term at 0.  A key this release does not know (a newer
  ** writer's term) is refused with its line, not dropped. */
  const char *root = getenv("LW_ROOT");
  cr_assert_not_null(root);
  char out[1024], errs[1024], args[512];
  snprintf(args, sizeof args, "run %s/params/minimal.ini --out %s/old --set anneal.sweeps=40 --stop-at 20 --quiet",
           root, dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert_eq(lw_test_sh("grep -q '^energy.parametrisation = 0$' %s/old/state.lw", dir), 0, "state.lw must name the term");
  cr_assert_eq(lw_test_sh("cp -r %s/old %s/new && sed -i 's/^energy.parametrisation = 0$/energy.torsion = 0/' "
                          "%s/new/state.lw", dir, dir, dir), 0);
  cr_assert_eq(lw_test_sh("sed -i '/^energy.parametrisation = /d; /^# checksum /d' %s/old/state.lw", dir), 0);
  snprintf(args, sizeof args, "resume %s/old --quiet", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  snprintf(args, sizeof args, "resume %s/new --quiet", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2);
  cr_assert(strstr(errs, "new/state.lw:") && strstr(errs, "[chain] energy.torsion: unknown"), "%s", errs);
  /* energy reads no [chain]; a section nothing writes is refused there too
  ** (it printed the energy and exited 0), a rung's sections are not (the
  ** file's chains count the rungs: [chain 1] beside [chain]) */
  cr_assert_eq(lw_test_sh("printf '[chain 1]\\nx = 1\\n' >> %s/old/state.lw", dir), 0);
  snprintf(args, sizeof args, "energy %s/old", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  static const char *const extra[] = {"extra", "system bogus", "chain 7", "system splines 3"};
  for (size_t k = 0; k < sizeof extra / sizeof extra[0]; k++) {
    cr_assert_eq(lw_test_sh("cp %s/old/state.lw %s/x.lw && printf '[%s]\\nx = 1\\n' >> %s/old/state.lw", dir, dir,
                            extra[k], dir), 0);
    cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "[%s]", extra[k]);
    cr_assert(strstr(errs, "old/state.lw:") && strstr(errs, ": section [") && strstr(errs, extra[k]) &&
              strstr(errs, "] is unknown"), "%s", errs);
    cr_assert_eq(lw_test_sh("mv %s/x.lw %s/old/state.lw", dir, dir), 0);
  }
}

/* A state an earlier release let through and a later check refuses (a run
** begun before 2026-12-04, its scene.ini without a scene hash): resume and
** energy say so and how to go on, not only which key to raise (which a
** resume cannot); the same state of this build is refused without it. */
Test(cli, an_older_releases_state_a_later_check_refuses_says_what_is_left)
{
  const char *root = getenv("LW_ROOT");
  cr_assert_not_null(root);
  char out[1024], errs[2048], args[512];
  snprintf(args, sizeof args, "run %s/params/minimal.ini --out %s/o --set anneal.sweeps=3 --quiet", root, dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  /* as that release wrote it: no scene hash; a cutoff the state's segments outgrow */
  cr_assert_eq(lw_test_sh("cd %s && sed -i '/^scene_hash\\|^scene_keys/d' o/state.lw && sed -i "
                          "'s/^pair_cutoff = .*/pair_cutoff = 0.3/' o/scene.ini && cp -r o same && sed -i "
                          "'s/^; written by linewise .*/; written by linewise 2026.12, build 0123/' o/scene.ini", dir),
               0);
  /* and a line within the boundary's clearance */
  cr_assert_eq(lw_test_sh("cd %s && cp -r same b && sed -i 's/^pair_cutoff = .*/pair_cutoff = 6/; "
                          "s/^boundary_clearance = .*/boundary_clearance = 100/; "
                          "s/^; written by linewise .*/; written by linewise 2026.12, build 0123/' b/scene.ini", dir),
               0);
  static const char *const cmd[] = {"resume %s/o --quiet", "energy %s/o", "resume %s/same --quiet",
                                    "resume %s/b --quiet"};
  for (int k = 0; k < 4; k++) {
    snprintf(args, sizeof args, cmd[k], dir);
    cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "%s", args);
    cr_assert(strstr(errs, k == 3 ? "boundary energy is not finite" : "too long for the pair cutoff"), "%s: %s",
              args, errs);
    if (k == 2) {
      cr_assert(!strstr(errs, "begun by"), "this build's own run: %s", errs);
      continue;
    }
    cr_assert(strstr(errs, "(the run was begun by linewise 2026.12, build 0123, which let this state through: ") &&
              strstr(errs, k == 3 ? "/b/state.lw --set anneal.sweeps=0' with that key set there" :
                                    "/o/state.lw --set anneal.sweeps=0' with that key set there") &&
              strstr(errs, "\"Runs of older releases\")\n"), "%s: %s", args, errs);
    cr_assert_eq(strstr(errs, "linewise:"), errs, "one message: %s", errs);
    cr_assert_null(strstr(errs + 1, "linewise:"), "one message: %s", errs);
  }
}

/* Bad input of every kind exits 2 with one message naming the file, line
** and key (issue 21: each of these exited 1, 0 or 139, or read garbage). */
Test(cli, hostile_input_exits_2_naming_file_line_and_key)
{
  char out[1024], errs[2048], args[1024];
  write_file("s.ini", scene_text);
  write_file("hex.ini", "[scene]\nwidth = 0x10\n");
  write_file("trail.ini", "[scene]\nwidth = 100mm\n");
  write_file("tb.ini", "[anneal]\nschedule = table\ntable = t.txt\n");
  write_file("t.txt", "0 1\n1 0x1\n");
  write_file("fr.ini", "[init]\nfrom = fr.lw\n");
  write_file("fr.lw", "linewise-state 2\n[run]\nscene = s.ini\nseed = 1\nsweep = 0\n[system splines]\nsplines = 1x\n");
  write_file("pl.ini", "[scene]\nwidth = 100\nheight = 80\n[init]\nsegment_length = 500\n");
  write_file("te.ini", "[anneal]\nschedule = geometric\nt_end = 0\n");
  write_file("odd.ini", "[scene]\nboundary = polygon\npolygon = 10 10 90 10 90 90 10\n");
  {
    char path[128];
    snprintf(path, sizeof path, "%s/nul.ini", dir);
    FILE *f = fopen(path, "wb");
    fwrite("[scene]\nwidth = 100\0garbage\n", 1, 28, f);
    fclose(f);
  }
  static const struct { const char *args, *msg; } bad[] = {
    {"run %s", "a folder, not a scene file: expected a scene file (.ini, as params/example.ini)"},
    {"run %s/s.ini --out ''", "--out: expected a directory"},
    {"run %s/s.ini --out /dev/null", "--out: expected a directory, got '/dev/null' (not a directory)"},
    {"run %s/s.ini --out /etc/passwd", "--out: expected a directory, got '/etc/passwd' (a file)"},
    {"run %s/s.ini --out --quiet", "--out: expected a value, got the option '--quiet' (was the value left out? a "
     "directory of that name is ./--quiet)"},
    /* the option's own value was blamed as a second scene file */
    {"run %s/s.ini --out --threads 1", "--out: expected a value, got the option '--threads' (was the value left"},
    {"run %s/s.ini --seed --out x", "--seed: expected a value, got the option '--out'"},
    /* mkdir's EEXIST on a link to nowhere read as success: exit 1 at the lock */
    {"run %1$s/s.ini --out %1$s/dangling", "/dangling: cannot create directory: No such file or directory (a "
     "symbolic link to a place that does not exist)"},
    {"run %s/odd.ini", "odd.ini:3: key 'scene.polygon': expected at least 3 vertices as 'x y' pairs, got 7 numbers "
     "(an odd count: one x or y is missing)"},
    {"run %s/s.ini --stop-at 99999999999999999999", "--stop-at: expected a whole number"},
    {"run %s/s.ini --stop-at 0x10", "--stop-at: expected a whole number"},
    {"run %s/s.ini --seed 1e300", "--seed: expected a whole number"},
    {"run %s/s.ini --threads 2x", "--threads: expected a whole number"},
    {"resume %s --sweeps 99999999999999999999", "--sweeps: expected a whole number"},
    {"run %s/hex.ini", "hex.ini:2: key 'scene.width': expected a number"},
    {"run %s/trail.ini", "trail.ini:2: key 'scene.width'"},
    {"run %s/nul.ini", "nul.ini:2: a NUL byte inside the line"},
    {"run %s/s.ini --set scene.width=0x10", "--set: key 'scene.width': expected a number"},
    {"run %s/s.ini --set anneal.seed=1.5", "--set: key 'anneal.seed': expected a whole number >= 0"},
    /* a tab showed as '?', and nothing said the blank was the fault */
    {"run %s/s.ini --set 'scene.width=\t100'",
     "got '?100' (a blank or tab before or after the value, which --set keeps"},
    {"run %s/s.ini --set 'scene.width=100 '", "got '100 ' (a blank or tab before or after the value, which --set keeps"},
    {"run %s/s.ini --set tempering.replicas=2 --set tempering.t_max=2 --set tempering.tune_ladder=equal "
     "--set tempering.ladder_sweeps=999 --set anneal.sweeps=10",
     "key 'tempering.ladder_sweeps': the ladder is tuned for the first"},
    {"run %s/tb.ini", "tb.ini:3: key 'anneal.table': "},
    {"run %s/fr.ini", "fr.ini:2: key 'init.from': "},
    {"run %s/pl.ini", "pl.ini:5: key 'init.segment_length': "},
    {"run %s/s.ini --set 'anneal.sweeps =5'", "--set 'anneal.sweeps =5': blanks around the name"},
    {"run %s/te.ini", "te.ini:3: key 'anneal.t_end': schedule geometric: t_end must be a finite number > 0"},
    {"run %s/s.ini --set anneal.t_start=-0", "--set: key 'anneal.t_start': schedule geometric: t_start must be"},
    {"energy %s", "state.lw: a folder, not a file: expected a file, which linewise reads whole"},
    /* the margin sets a polygon's crop (no picture): it annealed, then failed */
    {"run %s/s.ini --set scene.boundary=polygon --set 'scene.polygon=10 10 90 10 50 70' --set scene.margin=40",
     "--set: key 'scene.margin': expected less than half the page (100 x 80 mm), got 40"},
  };
  char sub[128];
  snprintf(sub, sizeof sub, "%s/sd/state.lw", dir);
  cr_assert_eq(lw_test_sh("mkdir -p %s && ln -s %s/nowhere/x %s/dangling", sub, dir, dir), 0);
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    /* energy and resume get the directory whose state.lw is a directory */
    char where[128];
    snprintf(where, sizeof where, "%s%s", dir, bad[i].args[0] == 'r' && bad[i].args[1] == 'u' ? "" : "/sd");
    snprintf(args, sizeof args, bad[i].args, where);
    if (bad[i].args[0] == 'r') strcat(args, " --quiet");
    if (bad[i].args[1] == 'u' && !strstr(bad[i].args, "--out"))
      snprintf(args + strlen(args), sizeof args - strlen(args), " --out %s/o%zu", dir, i);
    int rc = run(args, out, sizeof out, errs, sizeof errs);
    cr_expect_eq(rc, 2, "'%s': exit %d: %s", args, rc, errs);
    cr_expect(strstr(errs, bad[i].msg) != NULL, "'%s': message '%s' lacks '%s'", args, errs, bad[i].msg);
  }
}

/* SIGTERM during start-up (a scene that takes a while to place) leaves a
** directory that resumes, and a file-size limit is a clean error that
** names the file and leaves no temporary file. */
Test(cli, a_signal_in_start_up_leaves_a_resumable_run_and_a_size_limit_is_an_error)
{
  write_file("s.ini", scene_text);
  /* the signal once the run's first file is there: its set-up has written
  ** (a fixed sleep raced a slow start, as under the sanitizers; the
  ** directory itself is made and locked before the set-up) */
  cr_assert_eq(lw_test_sh("%s run %s/s.ini --out %s/sig --quiet --set init.splines=200 --set anneal.sweeps=1 & "
                          "p=$!; i=0; while [ $i -lt 500 ] && ! test -e %s/sig/scene.ini; do sleep 0.01; "
                          "i=$((i+1)); done; "
                          "kill -TERM $p; wait $p", lw_test_bin(), dir, dir, dir), 0);
  cr_assert_eq(lw_test_sh("test -f %s/sig/state.lw && ! test -e %s/sig/state.lw.tmp", dir, dir), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/sig --quiet", lw_test_bin(), dir), 0);
  char out[256], errs[1024], args[512];
  snprintf(args, sizeof args, "run %s/s.ini --out %s/fz --quiet --set output.checkpoint_every=1", dir, dir);
  char cmd[700];
  snprintf(cmd, sizeof cmd, "sh -c 'ulimit -f 8; %s %s' >%s/out.txt 2>%s/err.txt", lw_test_bin(), args, dir, dir);
  int st = system(cmd);
  cr_assert(WIFEXITED(st) && WEXITSTATUS(st) == 1, "a size limit must be an error (exit 1), got status %d", st);
  (void)out;
  snprintf(cmd, sizeof cmd, "%s/err.txt", dir);
  FILE *f = fopen(cmd, "r");
  size_t n = fread(errs, 1, sizeof errs - 1, f);
  errs[n] = '\0';
  fclose(f);
  cr_assert(strstr(errs, "fz/state.lw: write failed: File too large"), "%s", errs);
  cr_assert_neq(lw_test_sh("ls %s/fz/*.tmp 2>/dev/null | grep -q .", dir), 0, "a temporary file was left behind");
  /* a first checkpoint that fails leaves nothing to resume: said so (it was
  ** the bare write failure) */
  cr_assert_eq(lw_test_sh("sh -c 'ulimit -f 8; %s run %s/params/minimal.ini --out %s/f0 --quiet' 2>%s/err.txt; test "
                          "$? -eq 1 && grep -q 'f0/state.lw: write failed: File too large; the run wrote no "
                          "checkpoint: run it again once the files can be written' %s/err.txt", lw_test_bin(),
                          lw_test_root(), dir, dir, dir), 0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* made again over a finished run (with frames), the run before stays until
  ** the new one's first checkpoint: a failed one puts it back, byte for
  ** byte (it was removed first, and both were lost); a run that goes on
  ** replaces it and leaves no .replaced */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --out %s/old --quiet --set output.frames_every=100 && cp -rp "
                          "%s/old %s/keep && sh -c 'ulimit -f 8; %s run %s/params/minimal.ini --out %s/old --quiet "
                          "--seed 5' 2>%s/err.txt; test $? -eq 1 && grep -q 'old/state.lw: write failed: File too "
                          "large; the run wrote no checkpoint, and the run that was in the directory is back as it "
                          "was' %s/err.txt && rm %s/old/.lock %s/keep/.lock && diff -r %s/old %s/keep",
                          lw_test_bin(), lw_test_root(), dir, dir, dir, lw_test_bin(), lw_test_root(), dir, dir, dir,
                          dir, dir, dir, dir), 0, "%s", lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --out %s/old --quiet --seed 5 --stop-at 0 && ! test -e "
                          "%s/old/.replaced && ! test -e %s/old/frames && ! test -e %s/old/final.svg", lw_test_bin(),
                          lw_test_root(), dir, dir, dir, dir), 0);
  /* a PNG cut short says why too (cairo's own message named no reason) */
  cr_assert_eq(lw_test_sh("sh -c 'ulimit -f 60; %s run %s/params/minimal.ini --out %s/fp --quiet --set "
                          "output.png_scale=20 --set anneal.sweeps=5' 2>%s/err.txt; test $? -eq 1 && grep -q "
                          "'fp/final.png: writing the PNG failed: File too large' %s/err.txt", lw_test_bin(),
                          lw_test_root(), dir, dir, dir), 0);
  /* and that the last checkpoint is whole, and how to go on */
  cr_assert_eq(lw_test_sh("grep -q 'File too large; %s/fp/state.lw holds the checkpoint of sweep 5: ' %s/err.txt", dir,
                          dir), 0);
  /* an extension whose PNG fails leaves no final.png of the state before
  ** beside its new final.svg (a full disk left the old one unsaid) */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --out %s/fx --quiet --set output.png_scale=20 --set "
                          "anneal.sweeps=5 && test -f %s/fx/final.png && sh -c 'ulimit -f 60; %s resume %s/fx --sweeps 2 "
                          "--quiet' 2>%s/err.txt; test $? -eq 1 && grep -q 'File too large; final.png of the state "
                          "before removed (final.svg is this one.s)' %s/err.txt && ! test -e %s/fx/final.png && test -f "
                          "%s/fx/final.svg", lw_test_bin(), lw_test_root(), dir, dir, lw_test_bin(), dir, dir, dir, dir,
                          dir), 0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* a resume's too: the checkpoint it read, where it has written none yet */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --out %s/rf --quiet --stop-at 50 && sh -c 'ulimit -f 30; %s "
                          "resume %s/rf --quiet' 2>%s/err.txt; test $? -eq 1 && grep -q 'File too large; "
                          "%s/rf/state.lw holds the checkpoint of sweep 50: ' %s/err.txt", lw_test_bin(),
                          lw_test_root(), dir, lw_test_bin(), dir, dir, dir, dir), 0);
}

/* A set-up of seconds (100,000 splines placed, or read back: each 4 s here,
** and a phase under 1 s prints nothing) has its "done in" line before the
** run's header: the watcher thread printed it at its next tick, after the
** header and the parameters.  The progress line at sweep 0 has no
** temperature or time left yet. */
Test(cli, the_set_up_ends_its_line_before_the_run_header)
{
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --threads 1 --set init.splines=100000 "
                          "--set scene.width=6500 --set scene.height=6500 --stop-at 0 --out big 2>err.txt && "
                          "%s resume big --threads 1 --stop-at 0 2>>err.txt", dir, lw_test_bin(),
                          lw_test_root(), lw_test_bin()),
               0);
  char *e = lw_test_slurp("%s/err.txt", dir);
  const char *placed = strstr(e, "linewise: placing the initial state and building its energy: done in ");
  const char *header = strstr(e, "linewise: scene ");
  const char *read = strstr(e, "linewise: reading state.lw and rebuilding the energy: done in ");
  const char *resuming = strstr(e, "linewise: resuming big at sweep 0");
  cr_assert(placed && header && read && resuming, "%s", e);
  cr_assert(placed < header && header < read && read < resuming, "%s", e);
  /* no temperature before the first sweep (it read T 0), nor a time left (0.0s) */
  cr_assert(strstr(e, "\nsweep 0/300 T -  E ") && strstr(e, " acc - elapsed ") && strstr(e, "s left -\n"), "%s", e);
  free(e);
}

/* A set-up that has written nothing yet (50,000 splines placed: seconds, a
** million: minutes) ends at the first signal, leaving nothing: the signal
** once waited for the whole set-up, and a second one then spoke of a
** checkpoint that was never written.  The default directory made for the
** run goes too. */
Test(cli, a_signal_before_anything_is_written_ends_the_set_up_at_once)
{
  cr_assert_eq(lw_test_sh("cd %s && { %s run %s/params/minimal.ini --threads 1 --set init.splines=50000 "
                          "--set scene.width=1060 --set scene.height=1060 2>err.txt & p=$!; i=0; "
                          "while [ $i -lt 3000 ] && ! grep -q 'placing the initial state' err.txt; do sleep 0.01; "
                          "i=$((i+1)); done; kill -INT $p; wait $p; test $? -eq 130; }",
                          dir, lw_test_bin(), lw_test_root()),
               0);
  char *e = lw_test_slurp("%s/err.txt", dir);
  /* its one line, without the new line that ends a terminal's phase line (a log had an empty one) */
  cr_assert(!strcmp(e, "linewise: stopped during the set-up, before anything was written\n") ||
                strstr(e, "...\nlinewise: stopped during the set-up, before anything was written\n"), "%s", e);
  free(e);
  cr_assert_neq(lw_test_sh("test -e %s/out", dir), 0, "the default directory was left");
  /* and it ends by SIGINT, as a stop after a sweep does, so that Ctrl-C in
  ** a set-up stops a shell loop of runs (it exited 130, and the loop went on) */
  cr_assert_eq(lw_test_sh("cd %s && printf 'for i in 1 2; do %s run %s/params/minimal.ini --threads 1 --set "
                          "init.splines=50000 --set scene.width=1060 --set scene.height=1060 --out l$i; "
                          "echo \"run $i: $?\"; done; echo finished\n' > loop.sh && "
                          "(setsid env --default-signal=INT bash loop.sh >loop.log 2>&1 & echo $! >loop.pid); i=0; "
                          "while [ $i -lt 3000 ] && ! grep -q 'placing the initial state' loop.log; do sleep 0.01; "
                          "i=$((i+1)); done; kill -INT -$(cat loop.pid); i=0; while kill -0 $(cat loop.pid) "
                          "2>/dev/null && [ $i -lt 1500 ]; do sleep 0.02; i=$((i+1)); done; test $i -lt 1500; r=$?; "
                          "kill -KILL -$(cat loop.pid) 2>/dev/null; exit $r", dir, lw_test_bin(), lw_test_root()),
               0);
  e = lw_test_slurp("%s/loop.log", dir);
  cr_assert(strstr(e, "stopped during the set-up, before anything was written") && !strstr(e, "run 1") &&
            !strstr(e, "finished"), "%s", e);
  free(e);
  /* what a second signal leaves before the first checkpoint (a run's
  ** scene.ini, a cut state.lw.tmp, no state.lw): resume says why it cannot,
  ** and the next run into the default directory takes it again, not
  ** out/minimal-2 beside it for good */
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --quiet --stop-at 0 && rm out/minimal/state.lw && "
                          "echo cut > out/minimal/state.lw.tmp && "
                          "{ %s resume out/minimal 2>err.txt; test $? -eq 2; } && "
                          "grep -q 'out/minimal: no state.lw: the run there stopped before its first checkpoint' "
                          "err.txt && %s run %s/params/minimal.ini --quiet --set anneal.sweeps=2 && "
                          "test -s out/minimal/summary.json && ! test -e out/minimal/state.lw.tmp && ! test -e "
                          "out/minimal-2", dir, lw_test_bin(), lw_test_root(), lw_test_bin(), lw_test_bin(),
                          lw_test_root()),
               0);
  /* but a finished run whose state.lw was deleted keeps its drawing */
  cr_assert_eq(lw_test_sh("cd %s && rm out/minimal/state.lw && %s run %s/params/minimal.ini --quiet "
                          "--set anneal.sweeps=2 && test -s out/minimal-2/summary.json && test -s out/minimal/final.svg",
                          dir, lw_test_bin(), lw_test_root()),
               0);
}

/* A directory no run wrote (a run that failed at once on a full disk left
** only its lock) is said to hold no run, with the way on: it was the bare
** "state.lw: cannot open state file".  A run whose state.lw is a link to
** nowhere had one: not "stopped before its first checkpoint". */
Test(cli, resume_of_a_directory_without_a_run_says_so)
{
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --out %s/dl --quiet --set anneal.sweeps=2 && cd %s/dl && "
                          "rm state.lw summary.json final.svg final.png && ln -s /nonexistent/state.lw state.lw && "
                          "{ %s resume . 2>../dl.err; test $? -eq 2; } && grep -q 'state.lw: cannot open state file' "
                          "../dl.err && ! grep -q 'first checkpoint' ../dl.err", lw_test_bin(), lw_test_root(), dir,
                          dir, lw_test_bin()), 0, "%s", lw_test_slurp("%s/dl.err", dir));
  cr_assert_eq(lw_test_sh("mkdir -p %s/none && : > %s/none/.lock && { %s resume %s/none 2>%s/err.txt; test $? -eq 2; "
                          "} && grep -q 'none: holds no run (no state.lw, no scene.ini of a run): resume takes a "
                          "directory that .linewise run --out. wrote' %s/err.txt", dir, dir, lw_test_bin(), dir, dir,
                          dir), 0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* A sweep can take minutes (here a billion time steps of the whip): the
** first SIGINT asks for a stop after it, a second stops the process at
** once (exit 128 + 2), and the checkpoint state.lw holds still reads.  The
** signals come a second after the first checkpoint, in the first sweep (in
** the start-up one alone would stop the run cleanly before it). */
Test(cli, a_second_signal_stops_at_once_and_leaves_the_checkpoint)
{
  cr_assert_eq(lw_test_sh("%s run %s/params/whip.ini --out %s/w --quiet --set dynamics.steps_per_sweep=1000000000 & "
                          "p=$!; i=0; while [ $i -lt 500 ] && ! test -f %s/w/state.lw; do sleep 0.01; i=$((i+1)); "
                          "done; sleep 1; kill -INT $p; sleep 0.2; kill -INT $p; wait $p; test $? -eq 130",
                          lw_test_bin(), lw_test_root(), dir, dir),
               0);
  cr_assert_eq(lw_test_sh("%s energy %s/w >/dev/null && ! test -e %s/w/summary.json", lw_test_bin(), dir, dir), 0);
  /* past the first checkpoint it names the one state.lw holds (how much
  ** the stop loses): sweeps of seconds, a checkpoint after each (at 600000
  ** steps a sweep a loaded machine ended one between the two signals; the
  ** wait for sweep 2 allows the sanitizers' 10 times slower sweeps; the
  ** signals come 0.3 s into the next sweep: at its checkpoint the first
  ** signal ended the run before the second came) */
  cr_assert_eq(lw_test_sh("%s run %s/params/whip.ini --out %s/c --quiet --set dynamics.steps_per_sweep=1200000 --set "
                          "output.checkpoint_every=1 --set anneal.sweeps=1000 2>%s/c.err & p=$!; i=0; while [ $i -lt "
                          "9000 ] && ! grep -q '^sweep = [2-9]' %s/c/state.lw 2>/dev/null; do sleep 0.02; "
                          "i=$((i+1)); done; sleep 0.3; kill -INT $p; sleep 0.02; kill -INT $p; wait $p; test $? -eq "
                          "130 && grep -q \"continues from the checkpoint of sweep "
                          "$(sed -n 's/^sweep = //p' %s/c/state.lw)$\" %s/c.err",
                          lw_test_bin(), lw_test_root(), dir, dir, dir, dir, dir),
               0, "%s", lw_test_slurp("%s/c.err", dir));
  /* a resume stopped before its first checkpoint names the one it resumed
  ** from (nothing tested it: without the mark it said "the last checkpoint") */
  cr_assert_eq(lw_test_sh("%s run %s/params/whip.ini --out %s/r --quiet --set dynamics.steps_per_sweep=1200000 --set "
                          "output.checkpoint_every=1000 --set anneal.sweeps=1000 --stop-at 1", lw_test_bin(),
                          lw_test_root(), dir), 0);
  cr_assert_eq(lw_test_sh("%s resume %s/r --threads 1 2>%s/r.err & p=$!; i=0; while [ $i -lt 9000 ] && ! grep -q "
                          "resuming %s/r.err 2>/dev/null; do sleep 0.02; i=$((i+1)); done; sleep 0.3; kill -INT $p; "
                          "sleep 0.02; kill -INT $p; wait $p; test $? -eq 130 && grep -q 'continues from the "
                          "checkpoint of sweep 1$' %s/r.err", lw_test_bin(), dir, dir, dir, dir),
               0, "%s", lw_test_slurp("%s/r.err", dir));
}

/* A hang-up (a terminal or ssh session gone) stops a run as cleanly as
** SIGTERM, and a reader of its progress that goes away (a log pipe closed,
** `| head`) does not end it: both killed the run, losing the sweeps since
** the last checkpoint. */
Test(cli, a_hang_up_or_a_cpu_limit_stops_cleanly_and_a_closed_progress_pipe_is_harmless)
{
  const char *b = lw_test_bin();
  /* (a hang-up that the shell running the tests ignores, under nohup, stays
  ** ignored in the run, as it should: the default is given back for it) */
  cr_assert_eq(lw_test_sh("env --default-signal=HUP %s run %s/params/minimal.ini --out %s/h --quiet --set "
                          "anneal.sweeps=1000000 & "
                          "p=$!; i=0; while [ $i -lt 500 ] && ! test -f %s/h/state.lw; do sleep 0.01; i=$((i+1)); "
                          "done; sleep 0.3; kill -HUP $p; wait $p", b, lw_test_root(), dir, dir),
               0, "a hang-up did not stop the run cleanly");
  cr_assert_eq(lw_test_sh("grep -q '^sweep = [1-9]' %s/h/state.lw && ! test -e %s/h/summary.json", dir, dir), 0);
  cr_assert_eq(lw_test_sh("{ %s run %s/params/minimal.ini --out %s/p --set anneal.sweeps=300 2>&1; echo $? > %s/rc; } "
                          "| head -c 1 >/dev/null; test \"$(cat %s/rc)\" = 0 && test -f %s/p/summary.json", b,
                          lw_test_root(), dir, dir, dir, dir),
               0, "the run ended with its progress pipe");
  /* a CPU-time limit's soft end stops as cleanly (it ended the run unsaved,
  ** exit 152), though the kernel sends it again every CPU second after */
  cr_assert_eq(lw_test_sh("(ulimit -H -t 60; ulimit -S -t 1; exec %s run %s/params/minimal.ini --out %s/x --quiet "
                          "--set anneal.sweeps=1000000 --set output.checkpoint_every=1000000) 2>%s/err.txt", b,
                          lw_test_root(), dir, dir), 0, "%s", lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(lw_test_sh("grep -q '^sweep = [1-9]' %s/x/state.lw && ! test -e %s/x/summary.json && grep -q "
                          "'stopped after sweep [1-9][0-9]* (the soft CPU-time limit); state saved' %s/err.txt", dir,
                          dir, dir), 0);
}

/* Ctrl-C to a shell loop of runs (its process group, INT at its default as
** in a terminal) stops the loop: the run saves its state, says so under
** --quiet too (a log showed nothing), then ends by SIGINT, so that bash
** goes no further.  It exited 0, and the loop drew every other picture,
** one Ctrl-C each.  SIGTERM (a batch system's) still exits 0. */
Test(cli, ctrl_c_stops_a_shell_loop_of_runs_with_the_state_saved)
{
  cr_assert_eq(lw_test_sh("printf 'for i in 1 2; do %s run %s/params/minimal.ini --out %s/l$i --quiet --threads 1 "
                          "--set anneal.sweeps=1000000; echo \"run $i: $?\"; done; echo finished\n' > %s/loop.sh && "
                          "(setsid env --default-signal=INT bash %s/loop.sh >%s/loop.log 2>&1 & echo $! >%s/loop.pid); "
                          "i=0; while [ $i -lt 500 ] && ! test -f %s/l1/state.lw; do sleep 0.01; i=$((i+1)); done; "
                          "sleep 0.3; kill -INT -$(cat %s/loop.pid); i=0; while kill -0 $(cat %s/loop.pid) 2>/dev/null "
                          "&& [ $i -lt 1500 ]; do sleep 0.02; i=$((i+1)); done; test $i -lt 1500; r=$?; "
                          "kill -KILL -$(cat %s/loop.pid) 2>/dev/null; exit $r",
                          lw_test_bin(), lw_test_root(), dir, dir, dir, dir, dir, dir, dir, dir, dir),
               0);
  char *log = lw_test_slurp("%s/loop.log", dir);
  cr_assert(strstr(log, "linewise: stopped after sweep ") && !strstr(log, "run 1") && !strstr(log, "finished"),
            "%s", log);
  free(log);
  cr_assert_eq(lw_test_sh("grep -q '^sweep = [1-9]' %s/l1/state.lw && ! test -e %s/l2", dir, dir), 0);
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --out %s/t --quiet --set anneal.sweeps=1000000 2>%s/t.err & "
                          "p=$!; i=0; while [ $i -lt 500 ] && ! test -f %s/t/state.lw; do sleep 0.01; i=$((i+1)); "
                          "done; sleep 0.3; kill -TERM $p; wait $p && grep -q 'stopped after sweep' %s/t.err",
                          lw_test_bin(), lw_test_root(), dir, dir, dir, dir),
               0);
}

/* A finished run resumed after output.gcode and output.pdf were turned off
** in its scene.ini (a redraw) leaves no final.gcode or final.pdf of the old
** drawing: they stayed, and a plotter could be sent a G-code file that
** final.svg no longer showed; the done line named them as written. */
Test(cli, a_format_turned_off_leaves_no_file_of_the_old_drawing)
{
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --out %s/g --quiet --set anneal.sweeps=5 --set output.gcode=1 "
                          "--set output.pdf=1 --set output.hpgl=1 && test -s %s/g/final.gcode && test -s "
                          "%s/g/final.pdf && test -s %s/g/final.hpgl && sed -i 's/^gcode = 1/gcode = 0/; "
                          "s/^pdf = 1/pdf = 0/; s/^hpgl = 1/hpgl = 0/' %s/g/scene.ini && %s resume %s/g 2>%s/err.txt",
                          lw_test_bin(), lw_test_root(), dir, dir, dir, dir, dir, lw_test_bin(), dir, dir),
               0);
  cr_assert_eq(lw_test_sh("test -s %s/g/final.svg && ! test -e %s/g/final.gcode && ! test -e %s/g/final.pdf && "
                          "! test -e %s/g/final.hpgl && grep -q 'done: .*final.png, summary' %s/err.txt", dir, dir, dir,
                          dir, dir),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* A run directory's path as given takes at most 960 bytes: one of exactly
** 960 runs and resumes (it was refused by the set-up's own check, which
** wanted fewer), 961 is refused with the limit. */
Test(cli, a_directory_path_too_long_to_hold_is_refused)
{
  /* five components of 250 bytes: the run was written into the path cut at
  ** 1023 bytes, another directory, and said nothing */
  write_file("s.ini", scene_text);
  char a[251];
  memset(a, 'a', 250);
  a[250] = '\0';
  const char *b = lw_test_bin();
  cr_assert_eq(lw_test_sh("cd %s && %s run s.ini --quiet --set anneal.sweeps=2 --out d/%s/%s/%s/%s 2> err.txt",
                          dir, b, a, a, a, a),
               2);
  cr_assert_eq(lw_test_sh("cd %s && grep -q -- '--out: a path of 1005 bytes, longer than the 960' err.txt && "
                          "! test -e d",
                          dir),
               0);
  cr_assert_eq(lw_test_sh("cd %s && %s resume d/%s/%s/%s/%s 2> err.txt; test $? = 2 && "
                          "grep -q 'resume: a path of 1005 bytes' err.txt",
                          dir, b, a, a, a, a),
               0);
  /* d/ and three components of 250 and their slashes: 755 bytes; a last
  ** one of 205 makes 960 */
  char last[207];
  memset(last, 'e', 206);
  last[206] = '\0';
  cr_assert_eq(lw_test_sh("cd %s && %s run s.ini --quiet --set anneal.sweeps=2 --out d/%s/%s/%s/%s 2> err.txt; "
                          "test $? = 2 && grep -q -- '--out: a path of 961 bytes, longer than the 960' err.txt",
                          dir, b, a, a, a, last), 0);
  last[205] = '\0';
  cr_assert_eq(lw_test_sh("cd %s && P=d/%s/%s/%s/%s && %s run s.ini --quiet --set anneal.sweeps=2 --out $P 2> err.txt "
                          "&& %s resume $P --sweeps 2 --quiet 2>> err.txt && grep -q '^sweep = 4$' $P/state.lw",
                          dir, a, a, a, last, b, b), 0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* A run started without --out goes to out/<scene name>, and when that
** holds a run, to the first out/<scene name>-N that does not: the first
** drawing is not replaced.  --out names a directory to replace. */
Test(cli, a_run_without_out_never_replaces_another)
{
  write_file("s.ini", scene_text);
  const char *b = lw_test_bin();
  for (int k = 0; k < 3; k++)
    cr_assert_eq(lw_test_sh("cd %s && %s run s.ini --quiet --seed %d --set anneal.sweeps=2", dir, b, k + 1), 0);
  cr_assert_eq(lw_test_sh("cd %s/out && test -f s/final.svg && test -f s-2/final.svg && test -f s-3/final.svg && "
                          "! test -e s-4 && grep -q 'seed = 1' s/scene.ini && grep -q 'seed = 2' s-2/scene.ini && "
                          "grep -q 'seed = 3' s-3/scene.ini",
                          dir),
               0, "three runs without --out: out/s, out/s-2 and out/s-3, seeds 1, 2 and 3");
  /* a directory without a run in it is used as it is */
  cr_assert_eq(lw_test_sh("mkdir -p %s/out/t && cp %s/s.ini %s/t.ini && cd %s && %s run t.ini --quiet "
                          "--set anneal.sweeps=2 && test -f out/t/final.svg && ! test -e out/t-2",
                          dir, dir, dir, dir, b),
               0);
  cr_assert_eq(lw_test_sh("cd %s && %s run s.ini --quiet --seed 9 --set anneal.sweeps=2 --out out/s && "
                          "grep -q 'seed = 9' out/s/scene.ini && ! test -e out/s-4",
                          dir, b),
               0, "--out replaces the run it names");
  /* the name is the file's without its leading dots and extension: ".ini"
  ** (nothing before its dot) wrote its run into out/ itself, and cat.v2.ini
  ** went to out/cat */
  cr_assert_eq(lw_test_sh("cd %s && cp s.ini .ini && cp s.ini c.v2.ini && cp s.ini .h && %s run .ini --quiet "
                          "--set anneal.sweeps=2 && %s run c.v2.ini --quiet --set anneal.sweeps=2 && %s run .h --quiet "
                          "--set anneal.sweeps=2 && test -f out/ini/final.svg && test -f out/c.v2/final.svg && "
                          "test -f out/h/final.svg && ! test -e out/final.svg", dir, b, b, b),
               0);
  /* a file named scene.ini, as a run's, takes its folder's name: a redraw
  ** of out/t/scene.ini went to out/scene */
  cr_assert_eq(lw_test_sh("cd %s && %s run out/t/scene.ini --set init.from=out/t/state.lw --set anneal.sweeps=0 "
                          "--quiet 2>err.txt && test -f out/t-2/final.svg && ! test -e out/scene && grep -qx "
                          "'linewise: into out/t-2 (out/t holds a run; --out names the directory)' err.txt", dir, b),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* a CR a script saved with CRLF line ends puts at the end of --out or of
  ** the scene's path: refused, not a directory named "r\r" */
  cr_assert_eq(lw_test_sh("cd %s && %s run s.ini --quiet --out \"$(printf 'r\\r')\" 2>err.txt; test $? -eq 2 && "
                          "grep -qx \"linewise: --out: byte 2 of 'r?' is 0x0D, a control character (a CR: a script "
                          "saved with CRLF line ends?): expected a path without one\" err.txt && ! ls | grep -q '^r'",
                          dir, b),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* resume goes on writing "scene = scene.ini" into state.lw: a state naming
** another scene is refused (the run it rewrote named a scene.ini it never
** had, and could be neither extended nor measured), energy reads it. */
Test(cli, resume_refuses_a_state_of_another_scene_file)
{
  write_file("s.ini", scene_text);
  cr_assert_eq(lw_test_sh("cd %s && %s run s.ini --quiet --out o --set anneal.sweeps=2 && cp o/scene.ini o/my.ini && "
                          "sed -i 's/^scene = scene.ini$/scene = my.ini/' o/state.lw && %s energy o >/dev/null && "
                          "cp o/state.lw before.lw && { %s resume o --sweeps 2 2>err.txt; test $? -eq 2; } && "
                          "cmp -s before.lw o/state.lw && grep -q \"o/state.lw: \\[run\\] scene: expected scene.ini, "
                          "the scene of the run directory, got 'my.ini'\" err.txt", dir, lw_test_bin(), lw_test_bin(),
                          lw_test_bin()),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* energy reads the scene beside the state alone (it read and parsed any
  ** file a state named: /etc/passwd's first key echoed); a start state
  ** (init.from) never reads its scene, and may name any */
  cr_assert_eq(lw_test_sh("cd %s && sed -i 's|^scene = my.ini$|scene = ../s.ini|' o/state.lw && "
                          "{ %s energy o 2>err.txt; test $? -eq 2; } && grep -qx \"linewise: o/state.lw: \\[run\\] "
                          "scene: expected the name of a file beside the state (no '/'), got '../s.ini'\" err.txt && "
                          "%s run s.ini --quiet --out p --set anneal.sweeps=2 --set init.from=o/state.lw 2>err.txt",
                          dir, lw_test_bin(), lw_test_bin()),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* A workshop's slips, each said in one line with its way out: a photo where
** the scene goes (it was "a NUL byte inside the line (UTF-16 text ...)"), a
** drawing's SVG there, a ~ the shell left after '=', quotes a scene file
** keeps in a value (before a folder too), and --out=DIR as other programs
** take it (of a command's options only, and not of one without a value). */
Test(cli, a_students_slips_are_said_with_the_way_out)
{
  static const char *const cases[][2] = {
    {"run %s/params/picture.png", "picture.png: a PNG picture, not a scene file: a scene draws it, e.g. 'linewise "
     "run params/photo.ini --set scene.image="},
    {"run d.svg", "d.svg: an SVG file, not a scene file (a scene file is text"},
    {"run %s/params/minimal.ini --quiet --out t --set scene.image=~/Pictures/cat.jpg",
     "/~/Pictures/cat.jpg: cannot open the image: No such file or directory (a ~ is not expanded here, nor after '=' "
     "by the shell: write the whole path)"},
    {"run q.ini --quiet --out t", "/\"photos/my photo.jpg\": cannot open the image: No such file or directory (quotes "
     "in a scene file or inside --set's value are part of the name: write it without them)"},
    {"run %s/params/minimal.ini --out=t", "(an option and its value are two words: write '--out t')"},
    {"run %s/params/minimal.ini '--out=my t'", "write '--out \"my t\"')"},
    {"run %s/params/minimal.ini --quiet=1", "(--quiet takes no value)"},
    /* not said of what is not an option of the command, nor of HTML or of
    ** text that begins as a BMP does */
    {"resume t --out=t", "resume: unexpected '--out=t' (usage: "},
    {"run h.ini", "h.ini: an XML or HTML file, not a scene file"},
    {"run bm.ini", "bm.ini:1: key 'BMx' comes before any [section]"},
    /* a unit, a comment, quotes, words for a switch; a value the shell
    ** split; a scene file where resume and energy take a run; a file of 0
    ** bytes (a failed save drew 100 random lines) */
    {"run u.ini", "u.ini:2: key 'scene.margin': expected a number >= 0 and <= 10000000 (the number alone: it is in "
     "mm), got '10mm'"},
    {"run c.ini", "c.ini:2: key 'scene.margin': expected a number >= 0 and <= 10000000 (the value alone: in a scene "
     "file a comment after it starts with ';' after a blank, '10 ; ...'; --set takes none), got '10 # mm'"},
    {"run %s/params/minimal.ini --set \"scene.boundary='circle'\"", "(without the quotes), got ''circle''"},
    {"run %s/params/minimal.ini --set output.pdf=yes", "expected a whole number >= 0 and <= 1 (0 = off, 1 = on), got "
     "'yes'"},
    {"run %s/params/minimal.ini --set scene.image=my photo.jpg", "run: one scene file expected, got '"},
    {"run --set scene.image=my photo.jpg %s/params/minimal.ini", "(after --set: no blanks around '=', and a value with "
     "blanks in quotes"},
    {"resume q.ini", "resume: 'q.ini': a file, not a directory; expected the directory a run wrote"},
    {"energy nothere", "energy: 'nothere': No such file or directory; expected the directory a run wrote"},
    {"run z.ini", "z.ini: empty (0 bytes): expected a scene file (a line '[scene]' alone takes every default)"},
  };
  write_file("u.ini", "[scene]\nmargin = 10mm\n");
  write_file("c.ini", "[scene]\nmargin = 10 # mm\n");
  write_file("z.ini", "");
  write_file("h.ini", "\n<!DOCTYPE html>\n<html>\n");
  write_file("bm.ini", "BMx = 1\n");
  write_file("d.svg", "<svg xmlns=\"http://www.w3.org/2000/svg\"></svg>\n");
  write_file("q.ini", "[scene]\nimage = \"photos/my photo.jpg\"\n");
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    char args[512];
    snprintf(args, sizeof args, cases[k][0], lw_test_root());
    cr_assert_eq(lw_test_sh("cd %s && %s %s > out.txt 2> err.txt", dir, lw_test_bin(), args), 2, "%s", args);
    char *e = lw_test_slurp("%s/err.txt", dir);
    cr_assert(e && strstr(e, cases[k][1]) && strchr(e, '\n') == e + strlen(e) - 1 &&
              (k != 7 || !strstr(e, "two words")) && (k != 0 || strstr(e, "(the bundled photo.ini is /")) &&
              (k != 14 || strstr(e, "(after --set: no blanks around '=', and a value with blanks in quotes")),
              "%s: %s", args, e);
    free(e);
  }
}

/* A key given twice by --set takes the last value, and the first is not
** judged (a script appending its overrides was refused for a width it
** replaced); energy's --set alike. */
Test(cli, a_key_set_twice_takes_the_last_value)
{
  const char *b = lw_test_bin(), *r = lw_test_root();
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out o --set scene.width=0.5 --set anneal.sweeps=1 "
                          "--set scene.width=120 --quiet && grep -qx 'width = 120' o/scene.ini && "
                          "%s energy o --set energy.quadrature=1 --set energy.quadrature=12 > e.txt && grep -q '^total ' e.txt "
                          "&& { %s run %s/params/minimal.ini --out o2 --set scene.width=120 --set scene.width=0.5 "
                          "2> err.txt; test $? -eq 2; } && grep -q \"scene.width': expected a value >= 1\" err.txt "
                          "&& %s run %s/params/minimal.ini --out o3 --set anneal.seed=-3 --seed 5 --set anneal.sweeps=1 "
                          "--quiet && grep -qx 'seed = 5' o3/scene.ini && %s run %s/params/minimal.ini --out o4 --seed -3 "
                          "--set anneal.seed=6 --set anneal.sweeps=1 --quiet && grep -qx 'seed = 6' o4/scene.ini",
                          dir, b, r, b, b, r, b, r, b, r), 0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* A resume of a finished run redraws it and writes summary.json again: its
** sweep_seconds came back cut to timing.txt's 6 decimals (a script that
** resumed every run as a safe retry changed the numbers of finished ones). */
Test(cli, a_resume_of_a_finished_run_keeps_its_sweep_seconds)
{
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out f --set anneal.sweeps=20 --quiet && grep -o "
                          "'\"sweep_seconds\": [0-9.e-]*' f/summary.json > a.txt && %s resume f --quiet && grep -o "
                          "'\"sweep_seconds\": [0-9.e-]*' f/summary.json > b.txt && cmp a.txt b.txt && "
                          "test $(wc -c < a.txt) -gt 26", dir, lw_test_bin(), lw_test_root(), lw_test_bin()), 0, "%s %s",
               lw_test_slurp("%s/a.txt", dir), lw_test_slurp("%s/b.txt", dir));
}

/* A field file without the field term is named in the note of keys without
** effect, as the field's other keys are (it was left out), and once only
** where the field is not file either. */
Test(cli, a_field_file_without_the_field_term_is_noted)
{
  const char *b = lw_test_bin(), *r = lw_test_root();
  write_file("f.txt", "1 0 1 0\n1 0 1 0\n");
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out o --set anneal.sweeps=0 --set scene.field=%s "
                          "--set scene.field_file=f.txt 2> err.txt && grep -c 'scene.field_file (--set: energy.field "
                          "= 0)' err.txt > n.txt && grep -qx 1 n.txt && %s run %s/params/minimal.ini --out o2 "
                          "--set anneal.sweeps=0 --set scene.field=vortex --set energy.field=-1 --set "
                          "scene.field_file=f.txt 2> err.txt && grep -q 'scene.field_file (--set: scene.field is not "
                          "file)' err.txt", dir, b, r, "file", b, r), 0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* A picture taken from the run a run replaces (its final.png, a frame) was
** gone when the run was resumed: refused, the run there kept; a file of the
** user's in the directory is no run file and draws, with the note that no
** term of a scene without preset reads its picture. */
Test(cli, a_file_of_the_run_replaced_is_no_input)
{
  const char *b = lw_test_bin(), *r = lw_test_root();
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out o --set anneal.sweeps=2 --quiet && mkdir o/frames "
                          "&& cp o/final.png o/frames/frame-00002.png && cp o/final.png o/mine.png && cp o/state.lw s.lw",
                          dir, b, r), 0);
  static const char *const inputs[] = {"o/final.png", "o/frames/frame-00002.png", "o/./final.png"};
  for (size_t k = 0; k < sizeof inputs / sizeof *inputs; k++) {
    cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out o --set scene.image=%s --quiet 2> err.txt",
                            dir, b, r, inputs[k]), 2, "%s", inputs[k]);
    char *e = lw_test_slurp("%s/err.txt", dir);
    char want[128];
    snprintf(want, sizeof want, "is %s of the run in o, which this run removes or writes over", inputs[k] + 2 + (k == 2) * 2);
    cr_assert(e && strstr(e, "--set: key 'scene.image': '") && strstr(e, want) && !strchr(e, '\n')[1], "%s", e);
    free(e);
    cr_assert_eq(lw_test_sh("cd %s && cmp -s o/state.lw s.lw && test -f o/%s", dir, inputs[k] + 2), 0, "%s", inputs[k]);
  }
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out o --set scene.image=o/mine.png "
                          "--set anneal.sweeps=2 2> err.txt && test -f o/mine.png && ! test -e o/frames && "
                          "grep -q 'note: scene.image: no term of the energy reads the picture, so the drawing does "
                          "not follow it' err.txt && grep -q 'into o, replacing the run there: its files' err.txt",
                          dir, b, r), 0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* A bundled scene named without its folder, from another directory (or
** from an install, whose scenes are in PREFIX/share/linewise/params): the
** message says where the bundled one is, found beside the binary (a build
** elsewhere, make asan's, has none to point to); another name gets no hint;
** the README's params/NAME.ini and a bare NAME get it too. */
Test(cli, a_bundled_scene_named_alone_elsewhere_is_pointed_to)
{
  if (lw_test_sh("test -f \"$(dirname \"$(readlink -f %s)\")/../params/example.ini\"", lw_test_bin()))
    cr_skip_test("no bundled scenes beside %s", lw_test_bin());
  cr_assert_eq(lw_test_sh("R=$(cd %s && pwd -P) && cd %s && { %s run example.ini 2>err.txt; test $? -eq 2; } && "
                          "grep -qx \"linewise: example.ini: cannot open scene file: No such file or directory (the "
                          "bundled example.ini is $R/params/example.ini)\" err.txt && { %s run nothere.ini 2>err.txt; "
                          "test $? -eq 2; } && grep -qx 'linewise: nothere.ini: cannot open scene file: No such "
                          "file or directory' err.txt", lw_test_root(), dir, lw_test_bin(), lw_test_bin()),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* the README's form, params/example.ini, and a bare name too */
  cr_assert_eq(lw_test_sh("R=$(cd %s && pwd -P) && cd %s && { %s run params/minimal.ini 2>err.txt; %s run minimal "
                          "2>>err.txt; } ; test \"$(grep -c \"(the bundled minimal.ini is $R/params/minimal.ini)$\" "
                          "err.txt)\" = 2", lw_test_root(), dir, lw_test_bin(), lw_test_bin()),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* A run whose directory is removed while it runs ends at its next
** checkpoint (exit 1) saying so, not offering a resume of what is gone.
** (rm -rf loses the race with a checkpoint written between its reading
** the folder and removing it: "Directory not empty", the run went on, and
** the test waited for its million sweeps; so rm again while the folder
** stands, and a time limit.) */
Test(cli, a_run_whose_directory_is_removed_says_it_is_gone)
{
  write_file("s.ini", scene_text);
  cr_assert_eq(lw_test_sh("cd %s && { timeout 120 %s run s.ini --quiet --out g/r --set anneal.sweeps=1000000 "
                          "--set output.checkpoint_every=1 2>err.txt & p=$!; i=0; while [ $i -lt 3000 ] && "
                          "! test -f g/r/state.lw; do sleep 0.01; i=$((i+1)); done; while [ -e g ]; do "
                          "rm -rf g 2>/dev/null; done; wait $p; test $? -eq 1; }",
                          dir, lw_test_bin()),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  char *e = lw_test_slurp("%s/err.txt", dir);
  /* (after the sweeps began, or, where rm came during the set-up's last
  ** files, of the set-up) */
  cr_assert(strstr(e, "g/r/state.lw is no longer there: the run's directory was removed or moved, so the run ends") ||
            strstr(e, "g/r is no longer there: the run's directory was removed or moved, so the run ends") ||
            strstr(e, "the run's first files are removed, as it had done no sweep") ||
            strstr(e, "g/r is no longer there: the run's directory was removed or moved during the set-up"), "%s", e);
  free(e);
}

/* A run whose directory is moved aside, another made in its place (a new
** run there), writes nothing into that one: it took the old run's
** checkpoints and final files, and ended with exit 0.  The moved run
** resumes where it is. */
Test(cli, a_run_whose_directory_is_replaced_leaves_the_new_one_alone)
{
  write_file("s.ini", scene_text);
  cr_assert_eq(lw_test_sh("cd %s && { timeout 120 %s run s.ini --quiet --out m --set anneal.sweeps=1000000 "
                          "--set output.checkpoint_every=1 2>err.txt & p=$!; i=0; while [ $i -lt 3000 ] && "
                          "! grep -qs '^sweep = [1-9]' m/state.lw; do sleep 0.01; i=$((i+1)); done; "
                          "mv m moved && mkdir m && "
                          "touch m/mine; wait $p; test $? -eq 1; }", dir, lw_test_bin()),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  char *e = lw_test_slurp("%s/err.txt", dir);
  /* (another in its place, or, checked between the mv and the mkdir, none;
  ** or its state.lw written there and timing.txt not) */
  cr_assert((strstr(e, " is no longer there: the run's directory was removed or moved") ||
             strstr(e, "m is another directory now: the run's directory was moved or removed, and another made in its "
                       "place, which this run leaves alone")) && strstr(e, "so the run ends"), "%s", e);
  free(e);
  /* (a write under way as the directory went may leave its timing.txt) */
  cr_assert_eq(lw_test_sh("cd %s && test -e m/mine && ! ls m/state.lw m/trace.csv m/final.* m/summary.json "
                          "2>/dev/null && test -s moved/state.lw", dir), 0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* A line inih cannot read names its look-alike character: a Japanese
** input method's full-width '=' or '[' and a byte order mark inside the
** file (two files saved with one, joined) were a bare syntax error.  A
** byte order mark is not counted in the first line's 198 bytes. */
Test(cli, a_syntax_error_names_its_look_alike_character)
{
  static const char *const scene[][2] = {
    {"[scene]\nwidth \xef\xbc\x9d 100\n", "s.ini:2: syntax error: expected '[section]', 'key = value' or a comment "
                                            "(byte 7 is a full-width '=', U+FF1D: type '=')"},
    {"\xef\xbc\xbbscene\xef\xbc\xbd\n", "s.ini:1: syntax error: expected '[section]', 'key = value' or a comment "
                                           "(byte 1 is a full-width '[', U+FF3B: type '[')"},
    {"[scene]\n\xef\xbb\xbf[anneal]\n", "s.ini:2: syntax error: expected '[section]', 'key = value' or a comment "
                                       "(byte 1 is a byte-order mark, U+FEFF"},
    /* the first line's byte order mark is read as none (it was blamed) */
    {"\xef\xbb\xbf\xef\xbc\xbbscene\xef\xbc\xbd\n", "s.ini:1: syntax error: expected '[section]', 'key = value' or a "
                                                     "comment (byte 1 is a full-width '[', U+FF3B: type '[')"}};
  for (size_t k = 0; k < sizeof scene / sizeof scene[0]; k++) {
    write_file("s.ini", scene[k][0]);
    cr_assert_eq(lw_test_sh("cd %s && %s run s.ini --out o --quiet 2> err.txt; test $? -eq 2", dir, lw_test_bin()), 0);
    char *e = lw_test_slurp("%s/err.txt", dir);
    cr_assert(e && strstr(e, scene[k][1]), "%s", e);
    free(e);
  }
  char line[256] = "\xef\xbb\xbf; ";
  memset(line + strlen(line), 'a', 196 - 2);
  strcat(line, "\r\n[scene]\nwidth = 100\n");
  write_file("s.ini", line);
  cr_assert_eq(lw_test_sh("cd %s && %s run s.ini --out b --quiet --stop-at 0", dir, lw_test_bin()), 0);
  /* a Windows path names no file: its '\\' is said to be a letter */
  write_file("s.ini", "[scene]\nimage = photos\\a.png\n");
  cr_assert_eq(lw_test_sh("cd %s && %s run s.ini --out c --quiet 2>&1 | grep -qF \"a.png: cannot open the image: "
                          "No such "
                          "file or directory ('\\\\' is a letter of a name here, not a folder's end: paths take '/')\"",
                          dir, lw_test_bin()), 0);
  /* a plain syntax error says no more (its line's end was told to be deleted) */
  write_file("s.ini", "[scene]\nwidth 100\n");
  cr_assert_eq(lw_test_sh("cd %s && %s run s.ini --out c --quiet 2>&1 | grep -qx 'linewise: s.ini:2: syntax error: "
                          "expected .\\[section\\]., .key = value. or a comment'", dir, lw_test_bin()), 0);
}

/* A --stop-at past the run's end is said: the run finishes (a loop that
** asked for sweep 250 of 200 got a finished run, unsaid); short of it, no
** note. */
Test(cli, a_stop_past_the_end_is_said)
{
  write_file("s.ini", scene_text);
  cr_assert_eq(lw_test_sh("cd %s && %s run s.ini --out a --set anneal.sweeps=6 --stop-at 9 2> err.txt && "
                          "grep -q 'note: --stop-at 9 is past the run.s end at sweep 6: it runs to its end' err.txt && "
                          "test -s a/summary.json && "
                          "%s run s.ini --out b --set anneal.sweeps=6 --stop-at 3 2> err.txt && "
                          "! grep -q 'note: --stop-at' err.txt && %s resume b --stop-at 7 2> err.txt && "
                          "grep -q 'note: --stop-at 7 is past' err.txt", dir, lw_test_bin(), lw_test_bin(),
                          lw_test_bin()), 0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* A service running others' scenes confines the files their keys name to
** LINEWISE_INPUT_ROOT: outside it (a path, a '..', a link inside leading
** out) each is refused before it is read, and the refusal quotes none of
** it (a .env file's first line was quoted by the table's reader). */
Test(cli, a_service_confines_the_files_a_scene_names)
{
  cr_assert_eq(lw_test_sh("mkdir %s/job", dir), 0);
  write_file("job/s.ini", scene_text);
  write_file("secret.txt", "API_KEY=sk_live_SECRET\n");
  cr_assert_eq(lw_test_sh("cd %s && ln -s ../secret.txt job/link.txt && cp %s/params/picture.png job/", dir,
                          lw_test_root()), 0);
  static const char *const set[] = {"anneal.table=secret.txt", "anneal.table=job/../secret.txt",
                                    "anneal.table=job/link.txt", "init.from=/etc/passwd"};
  for (size_t k = 0; k < sizeof set / sizeof set[0]; k++) {
    cr_assert_eq(lw_test_sh("cd %s && LINEWISE_INPUT_ROOT=job %s run job/s.ini --out job/o --quiet --set "
                            "anneal.schedule=table --set %s 2> err.txt; test $? -eq 2", dir, lw_test_bin(), set[k]),
                 0, "%s", set[k]);
    char *e = lw_test_slurp("%s/err.txt", dir);
    cr_assert(e && strstr(e, "' is not inside LINEWISE_INPUT_ROOT (") && !strstr(e, "sk_live") && !strstr(e, "root:"),
              "%s: %s", set[k], e);
    free(e);
  }
  cr_assert_eq(lw_test_sh("cd %s && test ! -e job/o && LINEWISE_INPUT_ROOT=job %s run job/s.ini --out job/o --quiet "
                          "--set scene.image=job/picture.png --set anneal.sweeps=2 && LINEWISE_INPUT_ROOT=job %s resume "
                          "job/o --quiet", dir, lw_test_bin(), lw_test_bin()), 0);
  /* a missing folder inside is a missing file, not one outside; a '..'
  ** below it could lead out once it is made; a root that is a file */
  cr_assert_eq(lw_test_sh("cd %s && LINEWISE_INPUT_ROOT=job %s run job/s.ini --out job/p --set "
                          "scene.image=job/sub/no.png 2>&1 | grep -q 'job/sub/no.png: cannot open the image: No such "
                          "file'", dir, lw_test_bin()), 0);
  cr_assert_eq(lw_test_sh("cd %s && LINEWISE_INPUT_ROOT=job %s run job/s.ini --out job/p --set "
                          "scene.image=job/sub/../../secret.txt 2>&1 | grep -q 'is not inside LINEWISE_INPUT_ROOT'", dir,
                          lw_test_bin()), 0);
  /* a link inside that leads nowhere yet: outside (it passed as a missing
  ** folder); a name that merely begins with '..' is a name */
  cr_assert_eq(lw_test_sh("cd %s && ln -s ../nowhere job/dangling && LINEWISE_INPUT_ROOT=job %s run job/s.ini --out "
                          "job/p --set scene.image=job/dangling/x.png 2>&1 | "
                          "grep -q 'is not inside LINEWISE_INPUT_ROOT'",
                          dir, lw_test_bin()), 0);
  cr_assert_eq(lw_test_sh("cd %s && LINEWISE_INPUT_ROOT=job %s run job/s.ini --out job/p --set scene.image=job/..x.png "
                          "2>&1 | grep -q 'job/..x.png: cannot open the image: No such file'", dir, lw_test_bin()), 0);
  cr_assert_eq(lw_test_sh("cd %s && LINEWISE_INPUT_ROOT=job/picture.png %s run job/s.ini --out job/p 2>&1 | grep -q "
                          "'LINEWISE_INPUT_ROOT=job/picture.png: not a folder: expected the folder'", dir,
                          lw_test_bin()),
               0);
}

/* A copy made with hard links (cp -al, rsync --link-dest) shares the files
** a run writes in place: the copy's resume cut the finished original's
** trace to its own stop, and a run of either was said busy while the other
** ran.  Each resume takes a trace and a lock file of its own; both end as
** the run that never stopped. */
Test(cli, a_copy_made_with_hard_links_is_a_run_of_its_own)
{
  write_file("s.ini", scene_text);
  cr_assert_eq(lw_test_sh("cd %s && B=%s && $B run s.ini --quiet --out whole --set anneal.sweeps=40 && "
                          "$B run s.ini --quiet --out a --set anneal.sweeps=40 --stop-at 20 && cp -al a b && "
                          "$B resume a --quiet && cmp a/trace.csv whole/trace.csv && "
                          "$B resume b --quiet --stop-at 30 && cmp a/trace.csv whole/trace.csv && "
                          "test \"$(stat -c %%i a/.lock)\" != \"$(stat -c %%i b/.lock)\" && $B resume b --quiet && "
                          "cmp b/trace.csv whole/trace.csv && cmp b/state.lw whole/state.lw", dir, lw_test_bin()), 0);
}

/* A run into a directory that held another leaves none of the old run's
** files: its machine files, replica states, frames, samples, the film
** tools/animate.sh made and the plots of tools/plot-run would be taken for
** the new run's.  What the user
** put there stays. */
Test(cli, a_run_replacing_another_removes_the_files_it_does_not_write_again)
{
  write_file("s.ini", scene_text);
  const char *b = lw_test_bin();
  cr_assert_eq(lw_test_sh("cd %s && %s run s.ini --quiet --out r --set anneal.sweeps=4 --set tempering.replicas=2 "
                          "--set tempering.t_max=2 --set output.gcode=1 --set output.hpgl=1 --set output.pdf=1 "
                          "--set output.frames_every=2 --set output.samples_every=2 && echo mine > r/notes.txt && "
                          "echo mine > r/frames/keep.txt && touch r/state.lw.tmp r/animation.mp4 && "
                          "mkdir r/plots && touch r/plots/swaps.png r/plots/mine.png && "
                          "test -f r/replica-1.lw && "
                          "test -f r/final.gcode && test -f r/frames/frame-000002.png && "
                          "test -f r/samples/sample-000002.csv",
                          dir, b),
               0);
  cr_assert_eq(lw_test_sh("cd %s && %s run s.ini --quiet --out r --set anneal.sweeps=2", dir, b), 0);
  cr_assert_eq(lw_test_sh("cd %s/r && test -f final.svg && test -f summary.json && ! test -e replica-1.lw && "
                          "! test -e final.gcode && ! test -e final.hpgl && ! test -e final.pdf && "
                          "! test -e ladder.ini && ! test -e samples && ! test -e state.lw.tmp && "
                          "! test -e frames/frame-000002.png && ! test -e animation.mp4 && "
                          "! test -e plots/swaps.png && test -e plots/mine.png && "
                          "test \"$(cat notes.txt frames/keep.txt)\" = "
                          "\"$(printf 'mine\\nmine')\"",
                          dir),
               0, "the old run's files stay, or the user's went");
  /* a drawing of a run's name where no run is (a person's, or a run's whose
  ** scene.ini and state.lw were taken away) is not written over */
  cr_assert_eq(lw_test_sh("cd %s && mkdir stray && echo mine > stray/final.svg && %s run s.ini --quiet --out stray "
                          "2>err.txt; test $? -eq 2 && grep -q 'stray/final.svg is there, but no run' err.txt && "
                          "test \"$(cat stray/final.svg)\" = mine", dir, b), 0);
  /* a refused run leaves the old one whole */
  cr_assert_eq(lw_test_sh("cd %s && %s run s.ini --quiet --out r --set anneal.sweeps=-1 2>/dev/null", dir, b), 2);
  cr_assert_eq(lw_test_sh("test -f %s/r/final.svg && test -f %s/r/summary.json", dir, dir), 0);
  /* a run made again in place from its own scene.ini is fine; a scene file
  ** a person wrote is never overwritten by the run's resolved one */
  cr_assert_eq(lw_test_sh("cd %s && %s run r/scene.ini --quiet --out r --seed 5 && grep -q '^seed = 5' "
                          "r/scene.ini", dir, b),
               0);
  cr_assert_eq(lw_test_sh("cd %s && mkdir own && cp s.ini own/scene.ini && %s run own/scene.ini --quiet --out own "
                          "2>err.txt; test $? -eq 2 && grep -q 'is not a run.s (a scene file?)' err.txt && "
                          "cmp -s s.ini own/scene.ini",
                          dir, b),
               0);
  /* nor does a stray state.lw make a person's directory a run's, whose
  ** run files (their final.gcode, frames) the run would clear */
  cr_assert_eq(lw_test_sh("cd %s && mkdir -p mine/frames && echo st > mine/state.lw && echo g > mine/final.gcode && "
                          "echo f > mine/frames/frame-000001.png && %s run s.ini --quiet --out mine 2>err.txt; "
                          "test $? -eq 2 && grep -q 'mine/state.lw is not a run.s (not a state)' err.txt && "
                          "test \"$(cat mine/state.lw mine/final.gcode mine/frames/frame-000001.png)\" = "
                          "\"$(printf 'st\\ng\\nf')\"",
                          dir, b),
               0, "a stray state.lw let the run clear the directory");
}


/* scene.driver = barker: the Monte Carlo chain deciding by Barker's rule
** (driver.h).  It reads the chain's keys without a note, names itself in
** summary.json, takes fewer of its proposals than Metropolis at the same
** steps and seed (its probability is at most Metropolis's), leaves the same
** tuning sweeps out of `stats`, and a run stopped and resumed writes the
** same files as one that never stopped. */
Test(cli, the_barker_driver_runs_the_chain_by_its_own_rule)
{
  const char *b = lw_test_bin(), *root = lw_test_root();
  const char *common = "--set anneal.sweeps=60 --set anneal.steps=2 --quiet";
  for (int fixed = 0; fixed < 2; fixed++)
    for (int k = 0; k < 2; k++)
      cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini %s %s%s --out %s%d", dir, b, root, common,
                              k ? "--set scene.driver=barker" : "", fixed ? " --set moves.tune_sweeps=0" : "",
                              k ? "b" : "m", fixed),
                   0);
  cr_assert_eq(lw_test_sh("cd %s && grep -q '\"driver\": \"barker\"' b0/summary.json && "
                          "grep -q '\"driver\": \"metropolis\"' m0/summary.json", dir), 0);
  /* a chain's key, read without a note */
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --set scene.driver=barker --set moves.point=0.4 "
                          "--set anneal.sweeps=2 --out p > err.txt 2>&1 && ! grep -q 'no effect' err.txt", dir, b,
                          root), 0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* at fixed steps the share of moves taken */
  double rate[2];
  for (int k = 0; k < 2; k++) {
    char *js = lw_test_slurp("%s/%s1/summary.json", dir, k ? "b" : "m");
    cr_assert_not_null(js);
    const char *acc = strstr(js, "\n  \"accepted\": "), *prop = strstr(js, "\n  \"proposals\": ");
    cr_assert(acc && prop, "%s", js);
    rate[k] = strtod(acc + 15, NULL) / strtod(prop + 16, NULL);
    free(js);
  }
  cr_assert(rate[1] < rate[0] && rate[1] > 0.0, "Barker took %g of its proposals, Metropolis %g", rate[1], rate[0]);
  /* pooled with Metropolis's run, a note says what the pooling means */
  cr_assert_eq(lw_test_sh("cd %s && %s stats m0 b0 2> pooled.txt > /dev/null && grep -q 'note: the runs ran under "
                          "different drivers (m0: metropolis, b0: barker): their means sample one distribution' "
                          "pooled.txt", dir, b), 0, "%s", lw_test_slurp("%s/pooled.txt", dir));
  /* the statistics leave out the same tuning rows */
  cr_assert_eq(lw_test_sh("cd %s && %s stats m0 --csv | sed -n 2p | cut -d, -f2 > nm && %s stats b0 --csv | sed -n 2p "
                          "| cut -d, -f2 > nb && cmp -s nm nb && test $(cat nb) -lt 60", dir, b, b), 0);
  /* the targets are of the smallest steps' acceptance, which is 1/2 under
  ** Barker: a target of 0.8 tunes to 0.4 (its steps shrank to 4e-6 in 60
  ** sweeps, on their way to 1e-45, and the chain froze) */
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini %s --set scene.driver=barker --set moves.target=0.8 "
                          "--out t && awk '/\"steps\"/ { s = 1; next } s && /\"point\"/ { exit !($2 > 0.05) }' "
                          "t/summary.json", dir, b, root, common), 0, "%s", lw_test_slurp("%s/t/summary.json", dir));
  /* steps far too small show as the smallest steps' acceptance, 1/2, not 1:
  ** the tuning note judges against that (it waited for 80 %) */
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/wlc.ini --set scene.driver=barker --set moves.tune_sweeps=0 "
                          "--set moves.step_point=1e-9 --set moves.step_vector=1e-9 --set anneal.sweeps=300 --out f "
                          "2> note.txt && grep -q 'point moves were accepted 5[0-9.]* %% of the time against the "
                          "target 22 %%.* (under driver = barker a target is its share of 50 %%, the acceptance of "
                          "the smallest steps)' note.txt", dir, b, root), 0, "%s", lw_test_slurp("%s/note.txt", dir));
  /* its second stage would be Metropolis's: delayed acceptance is a key it does not read */
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --set scene.driver=barker --set anneal.sweeps=2 "
                          "--set anneal.delayed_acceptance=0 --out d 2>&1 | grep -q 'under driver = barker these keys "
                          "have no effect: anneal.delayed_acceptance (--set)'", dir, b, root), 0);
  /* stopped and resumed: the same chain */
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini %s --set scene.driver=barker --stop-at 25 --out r "
                          "2>/dev/null && %s resume r --quiet && cmp -s r/state.lw b0/state.lw && "
                          "cmp -s r/trace.csv b0/trace.csv", dir, b, root, common, b), 0);
}

/* A study as a user runs it: params/wlc.ini samples 50 free worm-like
** chains with output.observables, and `linewise stats` gives the means
** with error bars (from output.stats_from, the scene's burn-in; summary.json
** has the same), which must match the 2-D Kratky-Porod chain within the
** discretisation's bias measured in docs/NUMERICS.md ("Worm-like chain":
** l_p up to 6 % long, R^2 up to 0.33 l0 / l_p high) plus 4 of the stats'
** own standard errors.  Then a run stopped half way and resumed writes
** the same trace, observables included. */
Test(cli, a_worm_like_chain_study_matches_kratky_porod_with_the_stats_error_bars)
{
  char out[8192], errs[1024], args[512];
  const double lp = 10.0, l0 = 1.0;
  snprintf(args, sizeof args, "run %s/params/wlc.ini --out %s/wlc --quiet --set output.samples_every=6000",
           lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  snprintf(args, sizeof args, "stats %s/wlc --csv", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  double L, Lse, r2, r2se, c, cse;
  lw_test_stats_row(out, "obs_length", &L, &Lse);
  lw_test_stats_row(out, "obs_end2", &r2, &r2se);
  lw_test_stats_row(out, "obs_end_cos", &c, &cse);
  /* a column without spread has no tau and n_eff (it had 0.5 and n) */
  cr_assert(strstr(out, "\nobs_count,4001,50,0,0,,,"), "%s", out);
  double kp = 2.0 * lp * L * (1.0 - lp / L * (1.0 - exp(-L / lp)));
  double kp6 = 2.0 * 1.06 * lp * L * (1.0 - 1.06 * lp / L * (1.0 - exp(-L / (1.06 * lp))));
  double bias = 0.33 * l0 / lp + fabs(kp6 / kp - 1.0);
  cr_log_info("wlc study: L %.4f, R^2 %.4f +- %.4f (Kratky-Porod %.4f, bound %.4f), end cos %.4f +- %.4f", L, r2,
              r2se, kp, bias, c, cse);
  cr_assert(fabs(r2 / kp - 1.0) <= bias + 4.0 * r2se / kp, "<R^2> %.4f +- %.4f against %.4f", r2, r2se, kp);
  /* the end tangents' l_p, and its standard error by the delta method */
  double lp_c = -L / log(c), lp_se = L * cse / (c * log(c) * log(c));
  cr_assert(fabs(lp_c / lp - 1.0) <= 0.06 + 4.0 * lp_se / lp, "end tangents give l_p %.3f +- %.3f", lp_c, lp_se);
  cr_assert(lp_se / lp < 0.05 && r2se / kp < 0.01, "error bars too wide to test anything");
  /* summary.json reports the same stretch's means and error bars */
  cr_assert_eq(lw_test_sh("grep -q '^    \"from\": 4000,$' %s/wlc/summary.json", dir), 0);
  char *js = lw_test_slurp("%s/wlc/summary.json", dir);
  cr_assert_not_null(js);
  const char *at = strstr(js, "\n    \"end2\": "), *se = strstr(js, "\n    \"end2_stderr\": "),
             *br = strstr(js, "\n    \"end2_batch_ratio\": ");
  cr_assert(at && se && br, "%s", js);
  /* the batch-means check, which warns beyond 1.5, passes the well-mixed study */
  double ratio = strtod(br + 25, NULL);
  cr_assert(ratio > 0.5 && ratio < 1.5, "end2's batch ratio %g", ratio);
  cr_assert(fabs(strtod(at + 13, NULL) / r2 - 1.0) < 1e-9 && fabs(strtod(se + 20, NULL) / r2se - 1.0) < 1e-3,
            "summary.json's end2 differs from the stats' %.10g +- %.4g", r2, r2se);
  /* and the window and halves' checks of the stats' --csv row: closed, and
  ** the drift in standard errors to the --csv's three digits; a column
  ** without spread has neither */
  const char *wc = strstr(js, "\n    \"end2_window_closed\": "), *dz = strstr(js, "\n    \"end2_drift_z\": "),
             *row = strstr(out, "\nobs_end2,");
  cr_assert(wc && dz && row, "%s", js);
  cr_assert(!strncmp(wc + 27, "true,", 5), "%.40s", wc);
  const char *fld = row;
  for (int k = 0; k < 8; k++) fld = strchr(fld + 1, ',');
  double z = strtod(dz + 21, NULL);
  cr_assert(!strncmp(fld - 2, ",1,", 3) && fabs(strtod(fld + 1, NULL) - z) <= 5e-3 * fabs(z) + 1e-12, "%s: %g", row,
            z);
  cr_assert(strstr(js, "\n    \"count_window_closed\": null,\n    \"count_drift_z\": null,"), "%s", js);
  free(js);
  /* the table for people says the same, with the stretch it took */
  snprintf(args, sizeof args, "stats %s/wlc", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert(strstr(out, "sweeps 4000 to 24000 at temperature 1: 4001 rows, one every 5 sweeps\n"), "%s", out);
  cr_assert(strstr(out, "\nobs_count                     50           0           0           -         -\n"), "%s",
            out);
  /* --to alone takes the rows from the trace's start (the first 200 sweeps tune) */
  snprintf(args, sizeof args, "stats %s/wlc --to 1000", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert(strstr(out, "sweeps 205 to 1000 at temperature 1: 160 rows, one every 5 sweeps"), "%s", out);
  /* stopped and resumed: the same trace, byte for byte */
  snprintf(args, sizeof args, "run %s/params/wlc.ini --out %s/half --quiet --stop-at 10000 "
           "--set output.samples_every=6000", lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  snprintf(args, sizeof args, "resume %s/half --quiet", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert_eq(lw_test_sh("cmp -s %s/wlc/trace.csv %s/half/trace.csv", dir, dir), 0, "the resumed trace differs");
  cr_assert_eq(lw_test_sh("diff -r %s/wlc/samples %s/half/samples", dir, dir), 0, "the resumed samples differ");
  /* the two runs together: the same chain, so their means agree exactly */
  snprintf(args, sizeof args, "stats %s/wlc %s/half --csv", dir, dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert(strstr(out, "column,runs,n,mean,stderr,sd,tau_sweeps,n_eff,r_hat,p_runs,se_runs\n") &&
            strstr(out, "\nobs_end2,2,8002,") && strstr(out, ",1,0\nobs_rg2,"), "%s", out);
  /* a run named twice, once through a link (a sweep's `best`): counted once */
  cr_assert_eq(lw_test_sh("ln -s wlc %s/best", dir), 0);
  snprintf(args, sizeof args, "stats %s/best %s/wlc --csv", dir, dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert(strstr(errs, "/best is the run in ") && strstr(out, "column,n,mean,stderr,"), "%s%s", errs, out);
  /* the samples: at sweeps 6000 .. 24000, each every node of the 50 chains;
  ** the last one's mean squared end-to-end distance is the last trace
  ** row's obs_end2 (both of the state after sweep 24000) */
  cr_assert_eq(lw_test_sh("test \"$(ls %s/wlc/samples | tr '\\n' ' ')\" = "
                          "'sample-006000.csv sample-012000.csv sample-018000.csv sample-024000.csv '", dir), 0);
  char *smp = lw_test_slurp("%s/wlc/samples/sample-024000.csv", dir), *tr = lw_test_slurp("%s/wlc/trace.csv", dir);
  cr_assert(smp && tr && !strncmp(smp, "spline,node,px,py,vx,vy\n", 24));
  double p0[2] = {0, 0}, sum = 0;
  int rows = 0, spl, node;
  for (const char *l = strchr(smp, '\n') + 1; *l; l = strchr(l, '\n') + 1, rows++) {
    double px, py;
    cr_assert_eq(sscanf(l, "%d,%d,%lf,%lf", &spl, &node, &px, &py), 4, "%.60s", l);
    if (node == 0) p0[0] = px, p0[1] = py;
    if (node == 4) sum += (px - p0[0]) * (px - p0[0]) + (py - p0[1]) * (py - p0[1]);
  }
  cr_assert_eq(rows, 250, "50 chains of 5 nodes");
  /* the column of obs_end2 in the header, and that field of the last row */
  int col = 0;
  for (const char *h = tr; h < strstr(tr, "obs_end2,"); h++) col += *h == ',';
  const char *last = tr + strlen(tr) - 1;
  while (last > tr && last[-1] != '\n') last--;
  for (int k = 0; k < col; k++) last = strchr(last, ',') + 1;
  double want = strtod(last, NULL);
  cr_assert(fabs(sum / 50.0 / want - 1.0) < 1e-9, "sample end2 %.10g, trace %.10g", sum / 50.0, want);
  free(smp);
  free(tr);
}

/* summary.json's tau of an observable is `linewise stats`'s: a spline's
** observables are empty on the rows where births and deaths left none (297
** rows of 2900 here), and summary.json counted their tau in rows, not in the
** sweeps between their values (8.3 sweeps for stats' 81). */
Test(cli, summary_and_stats_agree_on_tau_where_a_column_has_gaps)
{
  char out[8192], errs[4096], args[1024];
  cr_assert_eq(lw_test_sh("printf '[scene]\\nwidth = 100\\nheight = 100\\n[init]\\nsplines = 2\\nsegments = 2\\n"
                          "segment_length = 8\\n[energy]\\nboundary = 0.5\\nchem_spline = 1\\n[moves]\\n"
                          "fixed_count = 0\\nbirth = 1\\ndeath = 1\\n[anneal]\\nschedule = constant\\nsweeps = 3000\\n"
                          "seed = 3\\n[output]\\nobservables = 1\\ntrace_every = 1\\n' > %s/gaps.ini", dir), 0);
  snprintf(args, sizeof args, "run %s/gaps.ini --out %s/gaps --quiet --threads 1", dir, dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  snprintf(args, sizeof args, "stats %s/gaps --csv", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  char *sum = lw_test_slurp("%s/gaps/summary.json", dir);
  cr_assert_not_null(sum);
  const char *names[] = {"length", "count"};
  for (int k = 0; k < 2; k++) {
    char key[64];
    snprintf(key, sizeof key, "\nobs_%s,", names[k]);
    const char *row = strstr(out, key);
    cr_assert_not_null(row, "%s", out);
    int filled = atoi(row + strlen(key));
    for (int comma = 0; comma < 5; comma++) row = strchr(row + 1, ',');
    double stats_tau = atof(row + 1);
    snprintf(key, sizeof key, "\"%s_tau_sweeps\": ", names[k]);
    const char *at = strstr(sum, key);
    cr_assert_not_null(at, "%s", sum);
    double summary_tau = atof(at + strlen(key));
    /* stats --csv prints 4 digits */
    cr_assert(fabs(summary_tau / stats_tau - 1.0) < 1e-3, "%s: tau %g in summary.json, %g in stats", names[k],
              summary_tau, stats_tau);
    if (k == 0) cr_assert(filled > 50 && filled < 2000, "the length column has gaps: %d of 2900 rows", filled);
  }
  free(sum);
}

/* Links planted in a run directory (by another user of a shared one) are
** not followed: a run wrote its temporaries through them (as root: into
** any file), created the file a .lock link named, and moved aside and then
** deleted the frames of another folder that frames/ linked to. */
Test(cli, links_planted_in_a_run_directory_are_not_followed)
{
  cr_assert_eq(lw_test_sh("cd %s && mkdir -p out/m vd && echo secret > victim && touch vd/frame-000000.png && "
                          "ln -s %s/victim out/m/state.lw.tmp && ln -s %s/victim out/m/timing.txt.tmp", dir, dir, dir),
               0);
  char args[1024], out[4096], errs[4096];
  snprintf(args, sizeof args, "run %s/params/minimal.ini --out %s/out/m --quiet --set anneal.sweeps=5", lw_test_root(),
           dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert_eq(lw_test_sh("cd %s && grep -qx secret victim && test -f out/m/state.lw && ! test -L out/m/state.lw && "
                          "! test -e out/m/state.lw.tmp", dir), 0, "a temporary was written through a link");
  /* a lock that is a link: refused, the file it names not made */
  cr_assert_eq(lw_test_sh("cd %s && mkdir out/k && ln -s %s/made out/k/.lock", dir, dir), 0);
  snprintf(args, sizeof args, "run %s/params/minimal.ini --out %s/out/k --quiet", lw_test_root(), dir);
  cr_assert_neq(run(args, out, sizeof out, errs, sizeof errs), 0);
  cr_assert(strstr(errs, ".lock: cannot open the run directory's lock") && strstr(errs, "symbolic link"), "%s", errs);
  cr_assert_neq(lw_test_sh("test -e %s/made", dir), 0, "the lock's link made its file");
  /* frames/ a link to another folder: its files stay, and the run is refused */
  cr_assert_eq(lw_test_sh("cd %s && ln -s %s/vd out/m/frames", dir, dir), 0);
  snprintf(args, sizeof args, "run %s/params/minimal.ini --out %s/out/m --quiet --set anneal.sweeps=5 "
           "--set output.frames_every=5", lw_test_root(), dir);
  cr_assert_neq(run(args, out, sizeof out, errs, sizeof errs), 0);
  cr_assert(strstr(errs, "frames: a symbolic link, not a folder"), "%s", errs);
  cr_assert_eq(lw_test_sh("test -f %s/vd/frame-000000.png && test \"$(ls %s/vd)\" = frame-000000.png", dir, dir), 0,
               "the linked folder's frames were moved or written");
  cr_assert_eq(lw_test_sh("test -s %s/out/m/state.lw", dir), 0, "the run that was there is gone");
  /* refused too by a run that writes no frames (it ran, and its first
  ** checkpoint would have dropped the run before with the link beside it) */
  snprintf(args, sizeof args, "run %s/params/minimal.ini --out %s/out/m --quiet --set anneal.sweeps=5", lw_test_root(),
           dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "%s", errs);
  cr_assert(strstr(errs, "frames: a symbolic link, not a folder"), "%s", errs);
  cr_assert_eq(lw_test_sh("test \"$(ls %s/vd)\" = frame-000000.png", dir), 0, "the linked folder's frames went");
  /* a resume whose trace.csv is a link: refused before the trace is cut
  ** back (truncate cut the file the link named) */
  cr_assert_eq(lw_test_sh("cd %s && rm out/m/frames && %s run %s/params/minimal.ini --out out/m --quiet --set "
                          "anneal.sweeps=30 --set output.checkpoint_every=10 --stop-at 15 && "
                          "cp out/m/trace.csv precious && echo 'a line past the checkpoint' >> precious && "
                          "cp precious kept && rm out/m/trace.csv && "
                          "ln -s %s/precious out/m/trace.csv", dir, lw_test_bin(), lw_test_root(), dir), 0);
  snprintf(args, sizeof args, "resume %s/out/m --quiet", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2);
  cr_assert(strstr(errs, "trace.csv: a symbolic link"), "%s", errs);
  cr_assert_eq(lw_test_sh("cmp -s %s/precious %s/kept", dir, dir), 0, "the file the trace's link named was cut");
  /* a format-1 state (which counts no trace bytes) with a dangling link:
  ** refused alike, the file it names not made (it was written, exit 1) */
  cr_assert_eq(lw_test_sh("cd %s && cp -r %s/tests/fixtures/v1/plain v1 && rm v1/trace.csv && "
                          "ln -s %s/planted v1/trace.csv", dir, lw_test_root(), dir), 0);
  snprintf(args, sizeof args, "resume %s/v1 --quiet --threads 1", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "%s", errs);
  cr_assert(strstr(errs, "trace.csv: a symbolic link"), "%s", errs);
  cr_assert_neq(lw_test_sh("test -e %s/planted", dir), 0, "the trace's link made its file");
  /* a FIFO there held that resume in fopen for ever, deaf to SIGTERM */
  cr_assert_eq(lw_test_sh("cd %s && rm v1/trace.csv && mkfifo v1/trace.csv", dir), 0);
  cr_assert_eq(lw_test_sh("timeout -s KILL 30 %s resume %s/v1 --quiet --threads 1 2>%s/fifo.err; test $? -eq 2 && "
                          "grep -q 'trace.csv: not a regular file' %s/fifo.err", lw_test_bin(), dir, dir, dir), 0,
               "%s", lw_test_slurp("%s/fifo.err", dir));
}

/* A file a key names that never ends: a FIFO waited for a writer for ever
** (the picture alone was refused), and /dev/zero or a sparse file of
** gigabytes was read as one line until the memory was gone.  Each is
** refused at once, naming the key. */
Test(cli, a_fifo_or_an_endless_file_named_by_a_key_is_refused_at_once)
{
  cr_assert_eq(lw_test_sh("mkfifo %s/fifo", dir), 0);
  const char *sets[][2] = {
    {"init.from=%s/fifo", "key 'init.from': %s/fifo: a FIFO (named pipe), not a file"},
    {"anneal.schedule=table --set anneal.table=%s/fifo", "key 'anneal.table': %s/fifo: a FIFO (named pipe)"},
    {"init.from=/dev/zero%.0s", "key 'init.from': /dev/zero: a character device (a terminal, /dev/null, /dev/zero), "
                               "not a "
                               "file%.0s"},
    {"anneal.schedule=table --set anneal.table=/dev/zero%.0s", "key 'anneal.table': /dev/zero: a character device%.0s"},
    /* a terminal's master held the read for ever */
    {"init.from=/dev/ptmx%.0s", "key 'init.from': /dev/ptmx: a character device%.0s"},
    /* a folder: "read error" and exit 1 for some, a line 1 for the table */
    {"anneal.schedule=table --set anneal.table=%s", "key 'anneal.table': %s: a folder, not a file"},
  };
  for (size_t k = 0; k < sizeof sets / sizeof sets[0]; k++) {
    char set[256], want[256], args[1024];
    snprintf(set, sizeof set, sets[k][0], dir);
    snprintf(want, sizeof want, sets[k][1], dir);
    snprintf(args, sizeof args, "run %s/params/minimal.ini --out %s/o --quiet --set %s", lw_test_root(), dir, set);
    cr_assert_eq(lw_test_sh("timeout 60 %s %s > /dev/null 2> %s/err.txt; test $? -eq 2", lw_test_bin(),
                            args, dir), 0, "%s", set);
    char *e = lw_test_slurp("%s/err.txt", dir);
    cr_assert(e && strstr(e, want), "%s: %s", set, e);
    free(e);
  }
  cr_assert_eq(lw_test_sh("timeout 60 %s run %s/fifo 2>&1 | grep -q 'fifo: a FIFO (named pipe), not a file'",
                          lw_test_bin(), dir), 0);
  const char *keys[][2] = {{"particles-sheet", "particles.points"}, {"dipole", "scene.field_file"}};
  for (int k = 0; k < 2; k++)
    cr_assert_eq(lw_test_sh("{ %s run %s/params/%s.ini --out %s/o --quiet --set %s=%s; test $? -eq 2; } 2>&1 | "
                            "grep -q \"key '%s': %s: a folder, not a file\"", lw_test_bin(), lw_test_root(), keys[k][0],
                            dir, keys[k][1], dir, keys[k][1], dir), 0, "%s", keys[k][1]);
  /* a socket too (the check went untested) */
  struct sockaddr_un sa = {.sun_family = AF_UNIX};
  snprintf(sa.sun_path, sizeof sa.sun_path, "%s/sock", dir);
  int fd = socket(AF_UNIX, SOCK_STREAM, 0);
  cr_assert(fd >= 0 && !bind(fd, (struct sockaddr *)&sa, sizeof sa));
  cr_assert_eq(lw_test_sh("timeout 60 %s run %s/params/minimal.ini --out %s/o --quiet --set init.from=%s/sock 2>&1 | "
                          "grep -q 'sock: a socket, not a file'", lw_test_bin(), lw_test_root(), dir, dir), 0);
  close(fd);
  /* a FIFO in a run directory, where a run's own file stands: refused, not waited on */
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out r --quiet --stop-at 0 && rm r/scene.ini && "
                          "mkfifo r/scene.ini && rm -f r/timing.txt && mkfifo r/timing.txt", dir, lw_test_bin(),
                          lw_test_root()), 0);
  cr_assert_eq(lw_test_sh("cd %s && timeout 60 %s run %s/params/minimal.ini --out r --quiet 2>err.txt; "
                          "test $? -eq 2 && grep -q 'r/scene.ini is not a run' err.txt", dir, lw_test_bin(),
                          lw_test_root()), 0);
}

Test(cli, stats_refuses_a_missing_run_and_a_bad_option_in_one_line)
{
  char out[2048], errs[1024], args[512];
  snprintf(args, sizeof args, "stats %s/nothing", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "%s", errs);
  cr_assert(strstr(errs, "nothing/scene.ini") && !strchr(strchr(errs, '\n') + 1, '\n'), "%s", errs);
  snprintf(args, sizeof args, "stats %s --from x", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "%s", errs);
  cr_assert(strstr(errs, "--from: expected a whole number"), "%s", errs);
}

/* Settings the docs say are refused, refused before anything is written,
** in one line naming the key at fault and where it was set. */
Test(cli, settings_the_docs_refuse_name_their_key_and_write_nothing)
{
  static const struct {
    const char *scene, *set, *says;
  } bad[] = {
      {"wire.ini", "--set nurbs.fixed=4", "--set: key 'nurbs.fixed': expected at most half of the 7 control points"},
      {"particles-sheet.ini", "--set particles.birth=1",
       "particles-sheet.ini (not set: the default, 0): key 'particles.death': births and deaths are each other's "
       "reverse, so both or neither"},
      {"minimal.ini", "--set tempering.ladder=1", "--set: key 'tempering.ladder': expected 2 to 256 temperatures"},
      {"minimal.ini", "--set tempering.replicas=2 --set anneal.t_start=0",
       "--set: key 'anneal.t_start': parallel tempering scales the ladder by T(step) / t_start"},
      {"minimal.ini", "--set anneal.schedule=table", "--set: key 'anneal.schedule': 'table' needs anneal.table"},
      {"minimal.ini", "--set energy.pair_cutoff=1", "--set: key 'energy.pair_cutoff': expected at least 1.957 mm"},
      {"example.ini", "--set scene.image_width=5000 --set scene.image_max_pixels=1e6",
       "--set: key 'scene.image_width': 5000 x 6667 pixels is more than scene.image_max_pixels (1000000)"},
      {"hatch.ini", "--set layers.names=aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa",
       "--set: key 'layers.names': expected names of at most 63 characters"},
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    cr_expect_eq(lw_test_sh("cd %s && %s run %s/params/%s %s --out o%zu --quiet > out.txt 2> err.txt", dir,
                            lw_test_bin(), lw_test_root(), bad[k].scene, bad[k].set, k),
                 2, "%s %s", bad[k].scene, bad[k].set);
    char *msg = lw_test_slurp("%s/err.txt", dir);
    cr_expect(msg && strstr(msg, bad[k].says) && strchr(msg, '\n') && !strchr(strchr(msg, '\n') + 1, '\n'), "%s %s: %s",
              bad[k].scene, bad[k].set, msg);
    free(msg);
    cr_expect_eq(lw_test_sh("test ! -e %s/o%zu", dir, k), 0, "%s %s wrote its directory", bad[k].scene, bad[k].set);
  }
}

/* Every way of calling a command wrongly exits 2 with one line naming what
** was expected, and writes nothing: no out/ where a run without --out would
** write, and the run the calls name unchanged. */
Test(cli, usage_errors_exit_2_in_one_line_and_write_nothing)
{
  cr_assert_eq(lw_test_sh("cd %s && mkdir u && cd u && %s run %s/params/minimal.ini --out r --quiet "
                          "--set anneal.sweeps=30 && cp r/state.lw ../before.lw", dir, lw_test_bin(), lw_test_root()),
               0);
  static const struct {
    const char *args, *says;
  } bad[] = {
      {"run", "run: expected a scene file (usage: linewise run SCENE.ini"},
      {"run M M", "run: one scene file expected, got "},
      {"run M --bogus", "run: unknown option '--bogus' (try 'linewise --help')"},
      {"run M --sweeps 5", "(a run's length is --set anneal.sweeps=N; --sweeps extends a finished run under resume"},
      {"run M --threads 0", "--threads: expected a whole number from 1 to 4096, got '0'"},
      {"run M --seed -1", "--seed: expected a whole number from 0 to 4294967295, got '-1'"},
      {"run M --stop-at x", "--stop-at: expected a whole number from 0 to"},
      /* "1.000", a thousand in a comma locale, is refused as --set refuses
      ** it (the options read it as 1: seed 1, 10 more sweeps for 10.000) */
      {"run M --seed 1.000", "got '1.000' (a thousands separator? write 1000, not 1.000)"},
      {"run M --threads 1.000", "--threads: expected a whole number from 1 to 4096, got '1.000' (a thousands"},
      {"run M --seed 1,5", "got '1,5' (a decimal comma? numbers take a point"},
      {"run M --seed \xe2\x88\x92" "1", "got '\xe2\x88\x92" "1' (byte 1 is a minus sign, U+2212: type '-')"},
      {"run M --set anneal.sweeps=10.000.000", "(a thousands separator? write 1000, not 1.000), got '10.000.000'"},
      {"resume r --sweeps 10.000", "--sweeps: expected a whole number from 0 to 1000000000000000, got '10.000' (a"},
      {"stats r --reweight 2.000", "--reweight: expected a whole number from 2 to 10000, got '2.000' (a thousands"},
      {"resume", "resume: expected a run directory (usage: linewise resume DIR"},
      {"resume r r", "resume: unexpected 'r' (usage: linewise resume DIR"},
      {"resume r --sweeps -3", "--sweeps: expected a whole number from 0 to"},
      {"energy", "energy: expected one run directory (usage: linewise energy DIR"},
      {"energy r r", "energy: expected one run directory and --set options, got 'r'"},
      {"stats", "stats: expected a run directory (usage: linewise stats DIR..."},
      {"stats r --from 10 --to 5", "stats: --from 10 is after --to 5: expected --from no later than --to"},
      {"stats r --reweight 1", "--reweight: expected a whole number from 2 to 10000, got '1'"},
      {"stats r --reweight", "--reweight: expected a whole number from 2 to 10000, got ''"}, /* (was '(null)') */
      {"stats r --zap", "stats: unexpected '--zap' (usage: linewise stats DIR..."},
      {"frobnicate", "unknown command 'frobnicate' (try 'linewise --help')"},
      /* a slip is met with what was meant (it said only "unknown") */
      {"rnu M", "unknown command 'rnu' (did you mean 'run'?) (try 'linewise --help')"},
      {"run M --sed 3", "run: unknown option '--sed' (did you mean '--seed'?)"},
      {"resume r --sweep 3", "resume: unexpected '--sweep' (did you mean '--sweeps'?) (usage"},
      {"stats r --form 3", "stats: unexpected '--form' (did you mean '--from'?) (usage"},
      {"run M --set seed=3", "--set 'seed=3': expected section.key=value (did you mean 'anneal.seed'?)"},
  };
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
    char args[256] = "";
    for (const char *c = bad[k].args; *c; c++) { /* M: the bundled minimal scene */
      size_t n = strlen(args);
      if (*c == 'M' && (c[1] == ' ' || !c[1]) && (c == bad[k].args || c[-1] == ' '))
        snprintf(args + n, sizeof args - n, "%s/params/minimal.ini", lw_test_root());
      else snprintf(args + n, sizeof args - n, "%c", *c);
    }
    cr_expect_eq(lw_test_sh("cd %s/u && %s %s > out.txt 2> err.txt", dir, lw_test_bin(), args), 2, "%s", args);
    char *msg = lw_test_slurp("%s/u/err.txt", dir);
    cr_expect(msg && !strncmp(msg, "linewise: ", 10) && strstr(msg, bad[k].says) && strchr(msg, '\n') &&
                  !strchr(strchr(msg, '\n') + 1, '\n'), "%s: %s", args, msg);
    free(msg);
    cr_expect_eq(lw_test_sh("cd %s/u && ! test -e out && test ! -s out.txt && cmp -s r/state.lw ../before.lw", dir), 0,
                 "%s wrote something", args);
  }
}

/* The end of a run reads its trace for summary.json's observables: where
** memory runs out there they are null, and the run says so under --quiet
** too (a study's statistics went null with exit 0 and nothing said).  The
** limit lets the run through (it needs under 30 MB) but not twice its
** 11 MB trace beside it. */
Test(cli, observables_lost_for_want_of_memory_are_said)
{
  if (strstr(lw_test_bin(), "asan")) cr_skip_test("an AddressSanitizer build cannot run under ulimit -v");
  cr_assert_eq(lw_test_sh("cd %s && (ulimit -v 36000; %s run %s/params/lj13.ini --out o --threads 1 --quiet --set "
                          "output.trace_every=1 --set output.observables=1 --set anneal.sweeps=20000 2> err.txt)", dir,
                          lw_test_bin(), lw_test_root()), 0);
  char *msg = lw_test_slurp("%s/err.txt", dir);
  cr_assert(strstr(msg, "linewise: warning: summary.json's observables are null: ") && strstr(msg, "out of memory") &&
            strstr(msg, "('linewise stats o' computes them from trace.csv, given the memory)\n"), "%s", msg);
  free(msg);
  cr_assert_eq(lw_test_sh("cd %s && grep -q '\"observables\": null' o/summary.json && %s stats o | grep -q obs_",
                          dir, lw_test_bin()), 0);
}

/* The trace writes every digit that reads back: at T = 1e-7 the harmonic
** wire's energy (3193.4) fluctuates by 2e-7, under the last of the 10
** digits it was written to before, and its heat capacity, exactly 5 by
** equipartition (params/wire-ladder.ini), read 21.9 +- 0.6.  Within 4 of
** its own error bars now (fixed seed). */
Test(cli, a_heat_capacity_at_a_low_temperature_reads_the_trace_in_full)
{
  char out[8192], errs[2048], args[1024];
  snprintf(args, sizeof args, "run %s/params/wire-ladder.ini --out %s/low --quiet --set tempering.ladder= --set "
           "tempering.replicas=1 --set anneal.t_start=1e-7 --set output.stats_from=20000", lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  snprintf(args, sizeof args, "stats %s/low --csv", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  const char *h = strstr(out, "\nheat_capacity,");
  double c, se;
  cr_assert(h && sscanf(h, "\nheat_capacity,%*d,%lf,%lf", &c, &se) == 2, "%s", out);
  cr_assert(fabs(c - 5.0) < 4.0 * se && se < 1.0, "C = %g +- %g against 5", c, se);
  cr_assert(!strstr(errs, "printed to 10 digits"), "%s", errs);
  /* its scene.ini as a run of before wrote it (no trace_exact line): run
  ** again, every digit (it kept 10, and stats blamed an old version); a
  ** resume keeps 10 (tests/test_checkpoint.c, the fixtures) */
  cr_assert_eq(lw_test_sh("cd %s && sed '/^trace_exact/d' low/scene.ini > old.ini && %s run old.ini --out again "
                          "--quiet && cmp -s low/trace.csv again/trace.csv", dir, lw_test_bin()), 0);
  /* at 10 digits, the run's own summary.json says so at its end */
  snprintf(args, sizeof args, "run %s/params/wire-ladder.ini --out %s/low10 --quiet --set tempering.ladder= --set "
           "tempering.replicas=1 --set anneal.t_start=1e-7 --set output.stats_from=20000 --set output.observables=1 "
           "--set output.trace_exact=0", lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert(strstr(errs, "linewise: warning: summary.json's statistics of heat_capacity are of values trace.csv "
                          "prints to 10 digits"), "%s", errs);
  /* three rungs at 10 digits: stats --reweight says so too */
  snprintf(args, sizeof args, "run %s/params/wire-ladder.ini --out %s/rungs --quiet --set 'tempering.ladder=1e-7 "
           "2e-7 4e-7' --set anneal.t_start=1e-7 --set output.stats_from=20000 --set output.trace_exact=0",
           lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  snprintf(args, sizeof args, "stats %s/rungs --reweight 3", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert(strstr(out, "warning: 3 rungs' energies are printed to 10 digits"), "%s", out);
}

/* Monte Carlo runs of one chain are said one run: a copy stopped earlier,
** the same seed with a later stats_from or another trace_every (their rows
** compared at the sweeps both record).  Each went unwarned: the stretches'
** i-th rows were compared, heat capacities of each stretch's own mean among
** them, and pooled the error bars were up to sqrt(2) small.  Another seed
** is not. */
Test(cli, runs_of_one_chain_are_said_one_run_however_traced)
{
  static const char *const runs[][2] = {{"a", ""}, {"b", "--stop-at 800"},
                                         {"c", "--set output.stats_from=600"}, {"d", "--set output.trace_every=1"},
                                         {"e", "--seed 2"}, {"f", "--set output.trace_exact=0"}};
  for (size_t k = 0; k < 6; k++)
    cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/wlc.ini --out %s --quiet --set anneal.sweeps=1200 --set "
                            "output.stats_from=300 --set output.trace_every=5 --seed 1 %s", dir, lw_test_bin(),
                            lw_test_root(), runs[k][0], runs[k][1]), 0, "%s", runs[k][0]);
  /* (f: printed to 10 digits, as a run of before 2026-12-07) */
  static const char *const twin[] = {"b", "c", "d", "f"};
  for (size_t k = 0; k < 4; k++) {
    cr_assert_eq(lw_test_sh("cd %s && %s stats a %s e > out.txt 2> err.txt", dir, lw_test_bin(), twin[k]), 0);
    char *out = lw_test_slurp("%s/out.txt", dir), want[128];
    snprintf(want, sizeof want, "warning: a/trace.csv and %s/trace.csv are one run, row for row", twin[k]);
    cr_assert(strstr(out, want) && !strstr(out, "e/trace.csv are one run"), "%s", out);
    free(out);
  }
  /* a study of end states, one row a run: a seed twice is said too */
  for (int k = 0; k < 3; k++)
    cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/wlc.ini --out one%d --quiet --set anneal.sweeps=600 --set "
                            "output.stats_from=300 --set output.trace_every=600 --seed %d", dir, lw_test_bin(),
                            lw_test_root(), k, k < 2 ? 1 : 2), 0);
  cr_assert_eq(lw_test_sh("cd %s && %s stats one0 one1 one2 > out.txt 2> err.txt", dir, lw_test_bin()), 0);
  char *out = lw_test_slurp("%s/out.txt", dir);
  cr_assert(strstr(out, "warning: one0/trace.csv and one1/trace.csv are one run") &&
            !strstr(out, "one2/trace.csv are one run"), "%s", out);
  free(out);
}

/* A state whose spline count was damaged up to 1e8 is said cut short under
** a memory limit too: the reader took memory for the count first, and said
** "out of memory for 100000000 splines" (exit 1) where 2 GB did not fit.
** So is a particle count. */
Test(cli, a_damaged_count_is_said_under_a_memory_limit_too)
{
  if (strstr(lw_test_bin(), "asan")) cr_skip_test("an AddressSanitizer build cannot run under ulimit -v");
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --set anneal.sweeps=5 --out g --quiet && "
                          "sed -i 's/^splines = 20$/splines = 100000000/' g/state.lw && grep -q '^splines = 1000' "
                          "g/state.lw", dir, lw_test_bin(), lw_test_root()), 0);
  cr_assert_eq(lw_test_sh("cd %s && (ulimit -v 400000; %s energy g 2> err.txt)", dir, lw_test_bin()), 2);
  char *msg = lw_test_slurp("%s/err.txt", dir);
  cr_assert(strstr(msg, "g/state.lw:") && strstr(msg, "splines: 100000000, but the section ends after 20 of them"),
            "%s", msg);
  free(msg);
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/particles-sheet.ini --set anneal.sweeps=2 --out p --quiet && "
                          "sed -i 's/^count = 127$/count = 100000000/' p/state.lw && grep -q '^count = 1000' "
                          "p/state.lw", dir, lw_test_bin(), lw_test_root()), 0);
  cr_assert_eq(lw_test_sh("cd %s && (ulimit -v 400000; %s energy p 2> err.txt)", dir, lw_test_bin()), 2);
  msg = lw_test_slurp("%s/err.txt", dir);
  cr_assert(strstr(msg, "p/state.lw: [system particles]: count = 100000000, but 127 particle lines"), "%s", msg);
  free(msg);
}

/* A signal after the new run's first checkpoint but before its first sweep
** is done puts the run before back, as one in the set-up does (the README
** promises it aside until that sweep): it was dropped unsaid, the new run
** "stopped after sweep 0" (or 1, the sweep going on finished) in its place. */
Test(cli, a_signal_before_the_first_sweep_is_done_puts_the_run_before_back, .timeout = 90)
{
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --set anneal.sweeps=5 --out b --quiet && "
                          "cp -a b b0 && rm b0/.lock", dir, lw_test_bin(), lw_test_root()), 0);
  /* the signal once the new run's checkpoint is whole: a sweep of 30000
  ** splines takes seconds; and with a checkpoint at the first sweep, which
  ** dropped the run before as that sweep ended */
  for (int every = 0; every < 2; every++) {
    const int rc = lw_test_sh("cd %s && { %s run %s/params/minimal.ini --out b --threads 1 --set init.splines=30000 "
                              "--set scene.width=2000 --set scene.height=2000 --set anneal.sweeps=3 %s 2> err.txt & } "
                              "&& until grep -qx 'splines = 30000' b/scene.ini 2>/dev/null && test -e b/state.lw && "
                              "! test -e b/state.lw.tmp; do sleep 0.01; done && kill -TERM $! && wait $!",
                              dir, lw_test_bin(), lw_test_root(), every ? "--set output.checkpoint_every=1" : "");
    char *msg = lw_test_slurp("%s/err.txt", dir);
    cr_assert_eq(rc, 128 + 15, "%s", msg);
    cr_assert(strstr(msg, "stopped before the first sweep; the run that was in b is back as it was"), "%s", msg);
    cr_assert_eq(lw_test_sh("cd %s && rm -f b/.lock && diff -r b0 b", dir), 0, "%s", msg);
    free(msg);
  }
}

/* libgomp ends the process (exit 1) where it cannot start a team's threads,
** which may first happen after the set-up: under an address-space limit
** eight threads' stacks did not fit, and the finished run in the directory
** was gone, a set-up's state.lw in its place.  The run set aside now comes
** back then too.  Whether the threads start depends on the machine's
** allocator: either the run fails and the run before is back to the byte,
** or it ran whole.  (Not under AddressSanitizer, which needs terabytes of
** address space.) */
Test(cli, a_process_ended_by_openmp_puts_the_run_before_back)
{
  if (strstr(lw_test_bin(), "asan")) cr_skip_test("an AddressSanitizer build cannot run under ulimit -v");
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --set anneal.sweeps=5 --out g --quiet && "
                          "cp -a g g0 && rm g0/.lock", dir, lw_test_bin(), lw_test_root()), 0);
  const int rc = lw_test_sh("cd %s && (ulimit -v 120000; OMP_WAIT_POLICY=passive %s run %s/params/example.ini --out g "
                            "--threads 8 --seed 9 --set anneal.sweeps=3 --quiet 2> err.txt)", dir, lw_test_bin(),
                            lw_test_root());
  char *msg = lw_test_slurp("%s/err.txt", dir);
  if (rc) {
    cr_assert_eq(rc, 1, "%s", msg);
    cr_assert(strstr(msg, "the run that was in g is back as it was"), "%s", msg);
    cr_assert_eq(lw_test_sh("cd %s && rm -f g/.lock && diff -r g0 g", dir), 0, "%s", msg);
  } else {
    cr_assert_eq(lw_test_sh("cd %s && grep -q '\"seed\": 9,' g/summary.json", dir), 0, "%s", msg);
  }
  free(msg);
  /* threads that cannot start at all are found before anything is written,
  ** and said in linewise's words too */
  cr_assert_eq(lw_test_sh("cd %s && (ulimit -v 30000; %s run %s/params/minimal.ini --threads 8 --out t --quiet "
                          "2> err.txt)", dir, lw_test_bin(), lw_test_root()), 1);
  msg = lw_test_slurp("%s/err.txt", dir);
  cr_assert(strstr(msg, "linewise: OpenMP could not start 8 threads (the memory limit, ulimit -v, or the processes "
                        "allowed); nothing was written: give --threads fewer, or more room"), "%s", msg);
  free(msg);
  cr_assert_eq(lw_test_sh("test ! -e %s/t", dir), 0);
}

/* A stack too small for a run (OpenMP's threads, the main thread of ulimit
** -s) is refused in one line before anything is written; before, the photo
** preset died of a segmentation fault mid-run at OMP_STACKSIZE=16K.  The
** threads' stack is measured on one, so every spelling libgomp reads is
** caught, a GOMP_STACKSIZE behind a bad OMP_STACKSIZE too (reading the
** variables here let "+16K" and "16K" with a carriage return through).  A
** stack of the needed 256 KiB runs. */
Test(cli, a_stack_too_small_is_refused_before_the_run)
{
  static const struct {
    const char *env, *says;
  } small[] = {
      {"OMP_STACKSIZE=16K", "OpenMP's threads get 16 KiB of stack (environment OMP_STACKSIZE='16K'): expected at "
                            "least 256 KiB (unset it, or set OMP_STACKSIZE=1M)"},
      {"OMP_STACKSIZE=' 200 k '", "OpenMP's threads get 200 KiB of stack (environment OMP_STACKSIZE=' 200 k ')"},
      {"OMP_STACKSIZE=+16K", "OpenMP's threads get 16 KiB"},
      {"OMP_STACKSIZE=\"$(printf '16K\\r')\"", "OpenMP's threads get 16 KiB"},
      {"GOMP_STACKSIZE=100", "OpenMP's threads get 100 KiB of stack (environment GOMP_STACKSIZE='100')"},
      {"OMP_STACKSIZE= GOMP_STACKSIZE=100", "OpenMP's threads get 100 KiB"},
      {"ulimit -s 100;", "the stack limit (ulimit -s) is 100 KiB: expected at least 256 KiB"},
  };
  for (size_t k = 0; k < sizeof small / sizeof small[0]; k++) {
    cr_expect_eq(lw_test_sh("cd %s && %s %s run %s/params/minimal.ini --out s%zu --threads 2 --quiet 2> err.txt", dir,
                            small[k].env, lw_test_bin(), lw_test_root(), k), 2, "%s", small[k].env);
    char *msg = lw_test_slurp("%s/err.txt", dir);
    cr_expect(msg && strstr(msg, "linewise: ") && strstr(msg, small[k].says) && strchr(msg, '\n'), "%s: %s",
              small[k].env, msg);
    free(msg);
    cr_expect_eq(lw_test_sh("test ! -e %s/s%zu", dir, k), 0, "%s wrote its directory", small[k].env);
  }
  /* (8K: below what libgomp takes, which keeps its default and says so) */
  const char *enough[] = {"OMP_STACKSIZE=256", "OMP_STACKSIZE=1m", "OMP_STACKSIZE=262144B", "ulimit -s 256;",
                          "OMP_STACKSIZE=8K"};
  for (size_t k = 0; k < sizeof enough / sizeof enough[0]; k++)
    cr_expect_eq(lw_test_sh("cd %s && %s %s run %s/params/minimal.ini --out e%zu --threads 2 --quiet "
                            "--set anneal.sweeps=2 2>/dev/null && "
                            "test -s e%zu/summary.json", dir, enough[k], lw_test_bin(), lw_test_root(), k, k),
                 0, "%s", enough[k]);
}

/* A signal while a run replaces an earlier one, before its first checkpoint
** is committed, puts the earlier run back and ends as a set-up stopped
** before anything was written does: 128 + the signal (by SIGINT itself).
** It exited 0 on SIGTERM and SIGHUP, and a script took the earlier run's
** summary.json for the new run's.  strace(1) sends the signal as the first
** checkpoint opens its file, inside that window. */
Test(cli, a_signal_that_gives_the_directory_back_does_not_exit_0)
{
  lw_test_need_strace();
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out r --quiet --set anneal.sweeps=10 && "
                          "cp -a r before && rm -f before/.lock", dir, lw_test_bin(), lw_test_root()), 0);
  static const struct {
    const char *sig;
    int rc;
  } stop[] = {{"TERM", 143}, {"HUP", 129}, {"INT", 130}};
  for (size_t k = 0; k < sizeof stop / sizeof stop[0]; k++) {
    cr_expect_eq(lw_test_sh("cd %s && env --default-signal=%s strace -o /dev/null -P r/state.lw.tmp -e "
                            "trace=openat -e inject=openat:signal=%s %s run %s/params/minimal.ini --seed 2 --out r "
                            "--quiet --set anneal.sweeps=10 2> err.txt", dir, stop[k].sig, stop[k].sig, lw_test_bin(),
                            lw_test_root()),
                 stop[k].rc, "SIG%s", stop[k].sig);
    cr_expect_eq(lw_test_sh("cd %s && grep -qx 'linewise: stopped during the set-up; the run that was in r is back as "
                            "it was' err.txt && rm -f r/.lock && diff -r r before", dir), 0, "SIG%s: %s", stop[k].sig,
                 lw_test_slurp("%s/err.txt", dir));
  }
}

/* The command a stopped run names to go on with it pastes into a shell as
** it is, whatever the directory's name: 'linewise resume with space' ran
** `resume with space`, and 'linewise resume -dash' took it for an option. */
Test(cli, the_resume_command_a_stop_names_pastes_into_a_shell)
{
  static const char *const name[] = {"plain", "with space", "-dash", "q\"u$o`te\\s", "it's!"};
  for (size_t k = 0; k < sizeof name / sizeof *name; k++) {
    char q[64] = "'"; /* the name in single quotes for the test's own shell */
    for (const char *c = name[k]; *c; c++)
      snprintf(q + strlen(q), sizeof q - strlen(q), "%s", *c == '\'' ? "'\\''" : (char[2]){*c, '\0'});
    strcat(q, "'");
    cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out %s --stop-at 3 --set anneal.sweeps=6 "
                            "2> err.txt", dir, lw_test_bin(), lw_test_root(), q), 0, "%s", name[k]);
    /* the command between "('" and "' continues", with the binary's path for linewise */
    cr_assert_eq(lw_test_sh("cd %s && sed -n \"s/^linewise: stopped after sweep 3; "
                            ".*('linewise \\(.*\\)' continues)$/\\1/p\" err.txt > cmd.txt && test -s cmd.txt && "
                            "sh -c \"%s $(cat cmd.txt) --quiet\" && test -s ./%s/summary.json", dir, lw_test_bin(), q),
                 0, "%s: %s", name[k],
                 lw_test_slurp("%s/err.txt", dir));
  }
}

/* An extension (resume --sweeps) that a full disk stops as it starts says
** what is left and how to go on, as a failure mid-run does: it said only
** "write failed".  strace(1) fails the new state's writes with ENOSPC; the
** run is as it was, and the command it names then extends it. */
Test(cli, an_extension_a_full_disk_stops_says_how_to_go_on)
{
  lw_test_need_strace();
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --out m --quiet --set anneal.sweeps=50 && "
                          "cp m/state.lw before.lw", dir, lw_test_bin(), lw_test_root()), 0);
  cr_assert_eq(lw_test_sh("cd %s && strace -o /dev/null -P \"$PWD/m/state.lw.tmp\" -e trace=write "
                          "-e inject=write:error=ENOSPC %s resume m --sweeps 30 --quiet 2> err.txt", dir,
                          lw_test_bin()), 1);
  cr_assert_eq(lw_test_sh("cd %s && grep -qx \"linewise: m/state.lw: write failed: No space left on device; the run in "
                          "m is as its last checkpoint left it: 'linewise resume m --sweeps 30' goes on once its "
                          "files can be read and written\" err.txt && cmp -s m/state.lw before.lw", dir), 0, "%s",
               lw_test_slurp("%s/err.txt", dir));
  cr_assert_eq(lw_test_sh("cd %s && %s resume m --sweeps 30 --quiet && grep -qx 'sweep = 80' m/state.lw", dir,
                          lw_test_bin()), 0);
}

/* A file a run replaces (state.lw, the drawings, summary.json) is on disk
** before the rename that replaces the last one, and the rename is on disk
** after it: strace sees fsync of the temporary file, the rename, then fsync
** of the directory.  Without the first, a power cut could leave an empty
** state.lw, the run's only checkpoint (a helper's mutant dropped the fsync
** and every test passed); without the second, the old one.  The trace,
** whose bytes state.lw counts, is synced before each state.lw's rename (a
** mutant that left that out passed too). */
Test(cli, every_file_a_run_replaces_is_synced_before_and_its_rename_after)
{
  lw_test_need_strace();
  /* (LeakSanitizer cannot run under ptrace: make asan's build leaves it out here) */
  cr_assert_eq(lw_test_sh("cd %s && ASAN_OPTIONS=detect_leaks=0 strace -f -y -e trace=fsync,rename,renameat,renameat2 "
                          "-o st.txt %s run "
                          "%s/params/minimal.ini --set anneal.sweeps=5 --out s --quiet && "
                          "awk -f %s/tests/fsync-order.awk st.txt > order.txt", dir, lw_test_bin(), lw_test_root(),
                          lw_test_root()),
               0, "%s", lw_test_slurp("%s/order.txt", dir));
}

/* A run that replaces one sets the run before aside by renames into
** DIR/.replaced, whose marker then says .moved: from then on a recovery takes
** DIR's state.lw for the new run's.  The marker's rename on disk before the
** moves it speaks of would, after a power cut, have the run before's
** state.lw taken for the new run's and the rest of that run dropped: strace
** sees the directory and the stash synced between the last move and the
** marker's rename, and the stash after it. */
Test(cli, a_run_set_aside_is_synced_before_its_marker_says_so)
{
  lw_test_need_strace();
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --set anneal.sweeps=5 --out r --quiet && "
                          "ASAN_OPTIONS=detect_leaks=0 strace -f -y -e trace=fsync,rename,renameat,renameat2 -o st.txt "
                          "%s run %s/params/minimal.ini --set anneal.sweeps=7 --out r --quiet && "
                          "grep -qx 'sweep = 7' r/state.lw && test ! -e r/.replaced && "
                          "awk -f %s/tests/stash-order.awk st.txt > order.txt",
                          dir, lw_test_bin(), lw_test_root(), lw_test_bin(), lw_test_root(), lw_test_root()),
               0, "%s", lw_test_slurp("%s/order.txt", dir));
}

/* On a terminal the progress is one bar redrawn in place (carriage returns,
** no plain "elapsed" lines), full at the last sweep and ended by a new
** line; --quiet draws none.  script(1) gives the run its terminal. */
Test(cli, a_terminal_gets_one_bar_redrawn_in_place)
{
  for (int quiet = 0; quiet < 2; quiet++) {
    cr_assert_eq(lw_test_sh("cd %s && script -qec '%s run %s/params/minimal.ini --out t%d --set anneal.sweeps=30%s' "
                            "/dev/null > tty%d.txt", dir, lw_test_bin(), lw_test_root(), quiet,
                            quiet ? " --quiet" : "", quiet), 0);
    char *out = lw_test_slurp("%s/tty%d.txt", dir, quiet);
    cr_assert_not_null(out);
    const char *full = strstr(out, "\r[########################] sweep 30/30  T 0.01  E "), *end;
    cr_expect(quiet ? !strstr(out, "sweep 30/30") : full && (end = strstr(full, "left 0s ")) != NULL &&
                                                      end[8 + strspn(end + 8, " ")] == '\r',
              "%s", out);
    cr_expect(!strstr(out, "elapsed"), "%s", out);
    free(out);
  }
}

/* A terminal narrower than the bar's line: it wrapped, and every redraw
** then began a new line.  The bar narrows to fit (an 80-column terminal
** lost it whole), else goes, then the line's end: no piece between carriage
** returns is wider than the terminal's columns less one, and the last
** still names the sweep. */
Test(cli, a_narrow_terminal_gets_its_bar_cut_to_its_width)
{
  const int cols[2] = {40, 72};
  for (int c = 0; c < 2; c++) {
    cr_assert_eq(lw_test_sh("cd %s && script -qec 'stty cols %d; %s run %s/params/minimal.ini --out n%d "
                            "--set anneal.sweeps=30' /dev/null > tty.txt", dir, cols[c], lw_test_bin(), lw_test_root(),
                            c),
                 0);
    char *out = lw_test_slurp("%s/tty.txt", dir);
    cr_assert_not_null(out);
    const char *last = NULL;
    for (const char *p = strchr(out, '\r'); p; p = strchr(p + 1, '\r')) {
      size_t n = strcspn(p + 1, "\r\n"); /* the terminal's line ends are "\r\n" */
      cr_expect(n <= (size_t)cols[c] - 1, "a piece of %zu characters: %.*s", n, (int)n, p + 1);
      if (n) last = p + 1;
    }
    cr_assert_not_null(last, "%s", out);
    if (c) /* 72 columns: a bar of fewer marks, full at the end */
      cr_assert(last[0] == '[' && strstr(last, "#] sweep 30/30  T 0.01  E ") && strchr(last, ']') - last < 25, "%s",
                out);
    else
      cr_assert(!strncmp(last, "sweep 30/30  T 0.01  E ", 23) && !strchr(out, '#'), "%s", out);
    free(out);
  }
}

/* A caller that closes stderr (2>&-) gets a clean trace: before, trace.csv
** took descriptor 2, and the parameter echo and progress lines went into
** it (exit 0, and `stats` then failed on it).  Output that does not reach
** stdout (a full disk, a closed stdout) exits 1 with one line: before,
** `energy > full/file` left an empty file and exit 0. */
Test(cli, closed_and_full_standard_streams_are_not_written_over_or_ignored)
{
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --out %s/c --set anneal.sweeps=20 2>&-", lw_test_bin(),
                          lw_test_root(), dir), 0);
  cr_assert_eq(lw_test_sh("head -1 %s/c/trace.csv | grep -q '^sweep,' && "
                          "awk -F, 'NR > 1 && $1 !~ /^[0-9]+$/ { bad = 1 } END { exit bad || NR != 21 }' "
                          "%s/c/trace.csv", dir, dir), 0);
  const char *cmd[] = {"energy %s/c > /dev/full", "params > /dev/full", "energy %s/c >&-", "schedules >&-"};
  for (size_t k = 0; k < sizeof cmd / sizeof cmd[0]; k++) {
    char args[256], line[512];
    snprintf(args, sizeof args, cmd[k], dir);
    snprintf(line, sizeof line, "%s %s 2> %s/err.txt", lw_test_bin(), args, dir);
    cr_assert_eq(lw_test_sh("%s", line), 1, "%s", args);
    cr_assert_eq(lw_test_sh("grep -q '^linewise: writing to stdout failed: ' %s/err.txt && test $(wc -l < %s/err.txt) "
                            "= 1", dir, dir), 0, "%s", args);
  }
}

/* Text inputs saved with a UTF-8 byte-order mark (Windows editors) read as
** without one: a schedule table, a points file, a curve's file and a state
** file.  Before, only scene files did; the others said "expected 'block
** temperature', got ''" with the mark invisible in the quote. */
Test(cli, text_files_with_a_byte_order_mark_read_as_without)
{
  cr_assert_eq(lw_test_sh("cd %s && printf '\\357\\273\\2770 1\\n3 0.01\\n' > t.txt && "
                          "printf '0 1\\n3 0.01\\n' > u.txt", dir), 0);
  const char *run_t = "%s run %s/params/minimal.ini --out %s/%s --quiet --set anneal.schedule=table "
                      "--set anneal.table=%s/%s --set anneal.sweeps=20";
  cr_assert_eq(lw_test_sh(run_t, lw_test_bin(), lw_test_root(), dir, "t", dir, "t.txt"), 0);
  cr_assert_eq(lw_test_sh(run_t, lw_test_bin(), lw_test_root(), dir, "u", dir, "u.txt"), 0);
  cr_assert_eq(lw_test_sh("cmp -s %s/t/trace.csv %s/u/trace.csv", dir, dir), 0);
  /* points and a curve's file */
  cr_assert_eq(lw_test_sh("cd %s && printf '\\357\\273\\2770 0 0\\n1.1 0 0\\n0 1.1 0\\n' > p.xyz && "
                          "printf '[scene]\\nsystem = particles\\n[particles]\\npoints = p.xyz\\n"
                          "[anneal]\\nsweeps = 2\\n' > p.ini && %s run p.ini --out p --quiet", dir, lw_test_bin()), 0);
  cr_assert_eq(lw_test_sh("cd %s && printf '\\357\\273\\277ply\\nformat ascii 1.0\\nelement vertex 3\\n"
                          "property float x\\nproperty float y\\nproperty float z\\nend_header\\n"
                          "0 0 0\\n1.1 0 0\\n0 1.1 0\\n' > q.ply && "
                          "%s run p.ini --out q --quiet --set particles.points=q.ply", dir, lw_test_bin()), 0);
  cr_assert_eq(lw_test_sh("cd %s && printf '\\357\\273\\2770 0\\n1 1\\n2 0\\n3 1\\n' > c.txt && printf '[scene]\\n"
                          "system = nurbs\\n[nurbs]\\norder = 3\\nfile = c.txt\\nfixed = 1\\n"
                          "[anneal]\\nsweeps = 2\\n' > c.ini"
                          " && %s run c.ini --out c --quiet", dir, lw_test_bin()), 0);
  /* a state file: the run resumes from it as from the one written */
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --out %s/s --quiet --set anneal.sweeps=20 --stop-at 10 && "
                          "cp -r %s/s %s/b && { printf '\\357\\273\\277'; cat %s/s/state.lw; } > %s/b/state.lw && "
                          "%s resume %s/s --quiet && %s resume %s/b --quiet && cmp -s %s/s/final.svg %s/b/final.svg",
                          lw_test_bin(), lw_test_root(), dir, dir, dir, dir, dir, lw_test_bin(), dir, lw_test_bin(),
                          dir, dir, dir), 0);
}

/* A redraw into the run's own directory is refused before it writes: it
** replaced the run's trace.csv (one row left) and summary.json. */
Test(cli, a_start_from_a_state_in_the_directory_it_writes_is_refused)
{
  const char *b = lw_test_bin();
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set anneal.sweeps=5 --out %s/m --quiet --threads 1", b,
                          lw_test_root(), dir), 0);
  cr_assert_eq(lw_test_sh("cd %s && sha256sum m/* > sums && %s run m/scene.ini --set init.from=m/state.lw --set "
                          "anneal.sweeps=0 --out m/ --quiet 2>err.txt; test $? -eq 2 && grep -q \"^linewise: --set: "
                          "key 'init.from': '%s/m/state.lw' is the state in m, the directory this run writes, which "
                          "would replace it and the files of the run there (its trace.csv\" err.txt && "
                          "sha256sum -c --quiet sums", dir, b, dir), 0);
  /* by a link to it too; but a start file of the user's, beside a run or not, is read before the run writes */
  cr_assert_eq(lw_test_sh("cd %s && ln -s m/state.lw link.lw && %s run m/scene.ini --set init.from=link.lw --set "
                          "anneal.sweeps=0 --out m --quiet 2>err.txt; test $? -eq 2 && sha256sum -c --quiet sums && "
                          "mkdir f && cp m/state.lw f/start.lw && %s run m/scene.ini --set init.from=f/start.lw --set "
                          "anneal.sweeps=0 --out f --quiet && %s run m/scene.ini --set init.from=f/start.lw --set "
                          "anneal.sweeps=0 --out f --quiet && cmp m/state.lw f/start.lw", dir, b, b, b), 0);
  /* into another directory it is the documented redraw */
  cr_assert_eq(lw_test_sh("cd %s && %s run m/scene.ini --set init.from=m/state.lw --set anneal.sweeps=0 --out r "
                          "--quiet && cmp m/final.svg r/final.svg", dir, b), 0);
}

/* Long splines under the default rigid moves get a note before the run: a
** sweep of one spline of 16,000 segments passed 2 minutes without a word.
** Without the rigid moves, or on short splines, none. */
Test(cli, long_splines_under_rigid_moves_get_a_note)
{
  static const struct { const char *set; int noted; } cases[] = {
    {"--set init.segments=400", 1},
    {"--set init.segments=400 --set moves.point=0 --set moves.vector=0", 1}, /* every move rigid */
    {"--set init.segments=400 --set moves.translate=0 --set moves.rotate=0", 0},
    {"--set init.segments=100", 0},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    char out[256], errs[16384], args[512];
    snprintf(args, sizeof args, "run %s/params/minimal.ini --set init.splines=2 --set init.segment_length=2 --set "
             "scene.width=1000 --set scene.height=1000 --stop-at 0 --out %s/l%zu %s", lw_test_root(), dir, k,
             cases[k].set);
    cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
    cr_assert_eq(strstr(errs, "linewise: note: init.segments = 400: the rigid moves (moves.translate and rotate), ") &&
                     strstr(errs, " of the proposals, each take all 400 segments of their spline along where a point "
                                  "move takes two, so a sweep grows as the square of the segments"),
                 cases[k].noted, "%s: %s", cases[k].set, errs);
  }
}

/* A start whose model cannot fit the memory the process may use is refused
** before its placement: 1e8 splines filled 3 GB in 15 s without a word (on
** their way to 160 GB).  16 segments of each: at least 640 GB, more than any
** machine this runs on. */
Test(cli, a_start_past_the_machines_memory_is_refused_before_placing)
{
  char out[256], errs[4096], args[512];
  snprintf(args, sizeof args, "run %s/params/minimal.ini --set init.splines=100000000 --set init.segments=16 "
           "--stop-at 0 --out %s/h", lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "%s", errs);
  cr_assert(strstr(errs, "linewise: --set: key 'init.splines': 100000000 splines of 16 segments (360 bytes a segment "
                         "at least) take at least 576 GB, more than the "), "%s", errs);
  cr_assert_null(strstr(errs, "placing"), "%s", errs);
  /* a replica a copy: splines that take half the memory fit once, not four times */
  const double memory = (double)sysconf(_SC_PHYS_PAGES) * (double)sysconf(_SC_PAGE_SIZE);
  snprintf(args, sizeof args, "run %s/params/minimal.ini --set init.splines=%.0f --set init.segments=16 --set "
           "tempering.replicas=4 --stop-at 0 --threads 1 --out %s/h", lw_test_root(), floor(memory / 2 / (360.0 * 16)),
           dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "%s", errs);
  cr_assert(strstr(errs, " in 4 replicas, more than the ") &&
                (strstr(errs, " of this machine's memory") || strstr(errs, " of this process's cgroup")), "%s", errs);
  /* and the address space a batch job allows (not under make asan, whose shadow takes terabytes of it) */
  if (strstr(lw_test_bin(), "asan")) return;
  cr_assert_eq(lw_test_sh("sh -c 'ulimit -v 1000000; %s run %s/params/minimal.ini --set init.splines=1000000 "
                          "--stop-at 0 --threads 1 --out %s/h' 2>%s/err.txt; test $? -eq 2 && grep -q 'take at least "
                          "1.44 GB, more than the 1.02 GB of this process.s address space (ulimit -v)' %s/err.txt",
                          lw_test_bin(), lw_test_root(), dir, dir, dir), 0);
  /* one that fits its splines but not the drawing's peak (the close share's
  ** points: 20,000 splines of 4 on a page of 2 m^2 peaked at 227 MB) is
  ** told, even quiet, and runs; with room, nothing is said */
  cr_assert_eq(lw_test_sh("sh -c 'ulimit -v 280000; %s run %s/params/minimal.ini --set init.splines=20000 --set "
                          "scene.width=1414 --set scene.height=1414 --stop-at 0 --threads 1 --quiet --out %s/m' "
                          "2>%s/err.txt && grep -q '^linewise: note: 20000 splines of 4 segments (360 bytes a segment "
                          "at least) may take up to about 0.364 GB at the drawing, more than the 0.287 GB of this "
                          "process.s address space (ulimit -v): short of it the drawing leaves out its scores' "
                          "%s/err.txt && "
                          "sh -c 'ulimit -v 2000000; %s run %s/params/minimal.ini --set init.splines=20000 --set "
                          "scene.width=1414 --set scene.height=1414 --stop-at 0 --threads 1 --quiet --out %s/m' "
                          "2>%s/err.txt && ! grep -q 'at the drawing' %s/err.txt", lw_test_bin(), lw_test_root(), dir,
                          dir, dir, lw_test_bin(), lw_test_root(), dir, dir, dir),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* each further replica counted as measured (the least a segment, 360
  ** bytes, was: 16 replicas of example.ini annealed to their end past
  ** 125 MB unwarned, then failed at the drawing) */
  cr_assert_eq(lw_test_sh("sh -c 'ulimit -v 125000; %s run %s/params/example.ini --set tempering.replicas=16 "
                          "--stop-at 0 --threads 1 --quiet --out %s/r16' 2>%s/err.txt && grep -q '^linewise: note: "
                          "1284 splines of 5 segments .* in 16 replicas may take up to about 0.1[0-9]* GB at the "
                          "drawing, more than the 0.128 GB' %s/err.txt", lw_test_bin(), lw_test_root(), dir, dir, dir),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* and as they were made where that is more: few splines on a picture,
  ** each replica's grid, raster and domains (64 of 50 splines annealed past
  ** 158 MB unwarned, then failed at the drawing) */
  cr_assert_eq(lw_test_sh("sh -c 'ulimit -v 158000; %s run %s/params/example.ini --set init.splines=50 --set "
                          "tempering.replicas=64 --stop-at 0 --threads 1 --quiet --out %s/r64' 2>%s/err.txt && grep -q "
                          "'^linewise: note: 50 splines of 5 segments .* in 64 replicas may take up to about [0-9.]* "
                          "GB at the drawing, more than the 0.162 GB' %s/err.txt", lw_test_bin(), lw_test_root(), dir,
                          dir, dir), 0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* and a resume under the limit its drawing failed under (it failed again unsaid) */
  cr_assert_eq(lw_test_sh("sh -c 'ulimit -v 280000; %s resume %s/m --stop-at 0 --threads 1 --quiet' 2>%s/err.txt && "
                          "grep -q '^linewise: note: 20000 splines of 4 segments .* may take up to about 0.364 GB at "
                          "the drawing' %s/err.txt", lw_test_bin(), dir, dir, dir),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* FORMATS' redraw (no sweeps) of a tempering run that tuned its ladder: it
** was refused, as if it had to tune within its 0 sweeps. */
Test(cli, a_tempering_run_with_a_tuned_ladder_redraws)
{
  const char *b = lw_test_bin();
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --set tempering.replicas=3 --set tempering.t_max=5 "
                          "--set tempering.tune_ladder=equal --set tempering.ladder_sweeps=10 --set anneal.sweeps=20 "
                          "--out t --quiet && %s run t/scene.ini --set init.from=t/state.lw --set anneal.sweeps=0 "
                          "--out r --quiet && cmp t/final.svg r/final.svg", dir, b, lw_test_root(), b), 0);
}

/* A run directory on a read-only file system is the wrong directory (exit
** 2), like one that cannot be made, not a failure while running (exit 1,
** which a queue's script retries); nothing in it changes. */
Test(cli, a_run_directory_that_cannot_be_written_is_refused_with_exit_2)
{
  const char *b = lw_test_bin();
  cr_assert_eq(lw_test_sh("cd %s && %s run %s/params/minimal.ini --set anneal.sweeps=5 --out src/m --quiet", dir, b,
                          lw_test_root()), 0);
  if (lw_test_sh("cd %s && mkdir ro && mount --bind src ro 2>/dev/null && { mount -o remount,bind,ro ro 2>/dev/null "
                 "|| { umount ro; false; }; }", dir)) {
    lw_test_dir_remove(dir); /* (a skipped test's suite runs no .fini) */
    cr_skip_test("cannot mount a read-only directory here (needs root and mount)");
  }
  int rc_run = lw_test_sh("cd %s && sha256sum src/m/* > sums && %s run %s/params/minimal.ini --out ro/m --quiet "
                          "2>err.txt", dir, b, lw_test_root());
  int rc_resume = lw_test_sh("cd %s && %s resume ro/m 2>>err.txt", dir, b);
  lw_test_sh("cd %s && umount ro", dir);
  cr_expect_eq(rc_run, 2);
  cr_expect_eq(rc_resume, 2);
  char *e = lw_test_slurp("%s/err.txt", dir);
  cr_expect(strstr(e, "linewise: ro/m: cannot write into the run directory: Read-only file system; expected a run "
                      "directory this user can write\n"), "%s", e);
  free(e);
  cr_assert_eq(lw_test_sh("cd %s && sha256sum -c --quiet sums", dir), 0);
}

/* An irregular segment's message names the test that failed and the key to
** lower: both were named, and both values called reasons, when one test was
** off or passed. */
Test(cli, an_irregular_segment_is_refused_naming_the_test_that_failed)
{
  const char *b = lw_test_bin();
  cr_assert_eq(lw_test_sh("%s run %s/params/minimal.ini --set anneal.sweeps=30 --out %s/m --quiet --threads 1", b,
                          lw_test_root(), dir), 0);
  cr_assert_eq(lw_test_sh("%s run %s/m/scene.ini --set init.from=%s/m/state.lw --set anneal.sweeps=0 --set "
                          "energy.min_speed=0.95 --out %s/s --quiet 2>%s/err.txt; test $? -eq 2 && grep -q "
                          "'its speed falls to 0.[0-9]* of its mean (energy.min_speed = 0.95; the mean as 8 nodes "
                          "measure the length), a fold the quadrature cannot see; lower energy.min_speed to accept it' "
                          "%s/err.txt", b, dir, dir, dir, dir, dir), 0);
  cr_assert_eq(lw_test_sh("%s run %s/m/scene.ini --set init.from=%s/m/state.lw --set anneal.sweeps=0 --set "
                          "energy.min_speed=0 --set energy.regularity=3 --out %s/r --quiet 2>%s/err.txt; test $? -eq 2 "
                          "&& grep -q 'is irregular: its bending integrand is analytic only within rho = [0-9.]* "
                          "(energy.regularity = 3), a fold the quadrature cannot see; lower energy.regularity' %s/err.txt",
                          b, dir, dir, dir, dir, dir), 0);
}

/* A state given as init.from is renumbered along the page for the sweeps;
** its irregular segment was named by the spline's new number (3 for the
** file's third spline, 2 from 0) */
Test(cli, an_irregular_segment_of_init_from_is_named_as_the_file_counts)
{
  cr_assert_eq(lw_test_sh("awk '/^spline =/ {s++; n = 0} /^node/ && s == 3 && ++n == 5 {$5 = 0; $6 = 0} {print}' "
                          "%s/params/hanging.lw > %s/bent.lw", lw_test_root(), dir), 0);
  cr_assert_eq(lw_test_sh("%s run %s/params/hanging.ini --set init.from=%s/bent.lw --stop-at 0 --out %s/h --quiet "
                          "2>%s/err.txt; test $? -eq 2", lw_test_bin(), lw_test_root(), dir, dir, dir), 0);
  char *e = lw_test_slurp("%s/err.txt", dir);
  cr_assert(strstr(e, "bent.lw: spline 2, segment 3 is irregular: "), "%s", e);
  free(e);
  /* and so is one whose energy is not finite (the sixth spline moved off the page was called 2) */
  cr_assert_eq(lw_test_sh("awk '/^spline =/ {s++} /^node/ && s == 6 {$4 = $4 + 500} {print}' %s/params/hanging.lw > "
                          "%s/off.lw && %s run %s/params/hanging.ini --set init.from=%s/off.lw --set "
                          "energy.boundary=0.5 "
                          "--stop-at 0 --out %s/h2 --quiet 2>%s/err.txt; test $? -eq 2", lw_test_root(), dir,
                          lw_test_bin(), lw_test_root(), dir, dir, dir), 0);
  e = lw_test_slurp("%s/err.txt", dir);
  cr_assert(strstr(e, "off.lw: spline 5 segment 0 (nodes 0 and 1): the boundary energy is not finite"), "%s", e);
  free(e);
}

/* A scene file that sets no key (emptied by mistake, or comments alone)
** ran the defaults unsaid */
Test(cli, a_scene_that_sets_no_key_is_noted)
{
  cr_assert_eq(lw_test_sh("printf '; nothing yet\\n' > %s/empty.ini && %s run %s/empty.ini --stop-at 0 --out %s/e "
                          "2>%s/err.txt && grep -q 'note: .*empty.ini sets no key: every value is the default' "
                          "%s/err.txt && %s run %s/params/minimal.ini --stop-at 0 --out %s/m 2>%s/err.txt && ! grep -q "
                          "'sets no key' %s/err.txt", dir, lw_test_bin(), dir, dir, dir, dir, lw_test_bin(),
                          lw_test_root(), dir, dir, dir), 0);
  /* a run's folder given as the scene says what to do with it */
  cr_assert_eq(lw_test_sh("%s run %s/m 2>%s/err.txt; test $? -eq 2 && grep -q \"m: a folder, not a scene file: it holds "
                          "a run, which 'linewise resume' continues\" %s/err.txt", lw_test_bin(), dir, dir, dir), 0);
  /* (with --set the values are no defaults: the note said so anyway) */
  cr_assert_eq(lw_test_sh("%s run %s/empty.ini --stop-at 0 --out %s/s --set anneal.sweeps=5 2>%s/err.txt && ! grep -q "
                          "'sets no key' %s/err.txt", lw_test_bin(), dir, dir, dir, dir), 0);
}

/* An empty drawing says what removed its lines (it said only "final.svg has
** no path"): here every stroke is under plot.min_length's 3 pen widths. */
Test(cli, an_empty_drawing_says_what_removed_its_lines)
{
  char out[1024], errs[16384], args[512];
  snprintf(args, sizeof args, "run %s/params/minimal.ini --set output.pen_width=100 --set anneal.sweeps=5 --out %s/e",
           lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert(strstr(errs, "the drawing is empty: final.svg has no path: every stroke was cut by the crop or too short "
                         "for plot.min_length (3 pen widths)"), "%s", errs);
  /* a white picture's coverage places nothing, and without deaths the
  ** anneal removed nothing: it blamed the price of line */
  write_file("white.pgm", "P5\n4 4\n255\n\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff");
  write_file("white.ini", "[scene]\nwidth = 60\nheight = 60\nimage = white.pgm\npotential = image\n"
                          "[init]\nsplines = 0\ncoverage = 0.45\n[energy]\npotential = 0.001\n[anneal]\nsweeps = 2\n");
  snprintf(args, sizeof args, "run %s/white.ini --out %s/w", dir, dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert(strstr(errs, "the drawing is empty: final.svg has no path: no spline was placed (init.splines, or "
                         "init.coverage on a picture without dark to cover)"), "%s", errs);
  /* deaths under a price of line above what the lines lower: the price is
  ** named, the only one set (300 sweeps empty the page at seeds 1 to 5) */
  snprintf(args, sizeof args, "run %s/params/minimal.ini --set moves.fixed_count=0 --set moves.birth=0.3 --set "
           "moves.death=0.3 --set energy.chem_spline=100 --set anneal.sweeps=300 --out %s/d", lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert(strstr(errs, "the drawing is empty: final.svg has no path: no spline is left: none was placed "
                         "(init.splines, init.coverage), or the anneal removed every one, the price of line "
                         "(energy.chem_spline 100) being more than what the lines lower: lower it"), "%s", errs);
}

/* With plot.crop = 0 a path past the page's edge is kept whole, and said
** (a plotter travelled off the paper without a word): as many as the crop
** cuts or leaves out of the same state on a page half as wide, without a
** margin (the crop's rectangle is the page less its margin, the edge the
** page's). */
Test(cli, paths_past_the_page_kept_by_crop_0_are_said)
{
  char out[1024], errs[16384], args[1024];
  snprintf(args, sizeof args, "run %s/params/minimal.ini --set anneal.sweeps=20 --out %s/f --quiet", lw_test_root(),
           dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  size_t past = 0, cut = 0, outside = 0;
  for (int crop = 0; crop < 2; crop++) {
    snprintf(args, sizeof args, "run %s/params/minimal.ini --set init.from=%s/f/state.lw --set anneal.sweeps=0 "
             "--set scene.width=50 --set scene.margin=0 --set energy.boundary=0 --set plot.crop=%d --out %s/h%d",
             lw_test_root(), dir,
             crop, dir, crop);
    cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
    const char *c = crop ? strstr(errs, " cut by the crop, ") : strstr(errs, " paths reach past the page's edge");
    if (!crop) {
      cr_assert(c, "%s", errs);
      while (c > errs && c[-1] >= '0' && c[-1] <= '9') c--;
      past = strtoul(c, NULL, 10);
      /* a warning, said under --quiet too, and counted in summary.json */
      cr_assert_eq(c - strlen("linewise: warning: "), strstr(errs, "linewise: warning: "), "%s", errs);
      char quiet[sizeof args + 16];
      snprintf(quiet, sizeof quiet, "%s --quiet", args);
      memcpy(strstr(quiet, "/h0 --quiet"), "/q0", 3);
      cr_assert_eq(run(quiet, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
      cr_assert_null(strstr(errs, "paths ("), "quiet: %s", errs);
      cr_assert(strstr(errs, "linewise: warning: ") && strstr(errs, " past the page's edge"), "%s", errs);
      cr_assert_eq(lw_test_sh("grep -q '\"off_page\": %zu,' %s/q0/summary.json", past, dir), 0);
    } else {
      cr_assert(c && !strstr(errs, "reach past the page"), "%s", errs);
      while (c > errs && c[-1] >= '0' && c[-1] <= '9') c--;
      cr_assert_eq(sscanf(c, "%zu cut by the crop, %zu outside it", &cut, &outside), 2, "%s", errs);
    }
  }
  cr_assert(past > 0 && past == cut + outside, "%zu past the edge uncropped; %zu cut and %zu outside cropped", past,
            cut, outside);
}

/* The photo preset's domain count, worked out from the page alone, gives way
** to the share of strokes a sweep can move as it does to the reach: strokes
** of 40 mm on the example's page were refused, blaming anneal.domains, which
** the user never set ("not set: the default, off" beside the preset's 4). */
Test(cli, the_presets_domains_give_way_to_long_strokes)
{
  char out[1024], errs[16384], args[1024];
  snprintf(args, sizeof args, "run %s/params/example.ini --out %s/d --threads 1 --stop-at 0 --set init.splines=5 "
           "--set init.segment_length=40 --set energy.pair=0 --set energy.min_spacing=0", lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  /* the count taken is the one scene.ini holds, so the run resumes as it
  ** ran (with the page's count it took other domains from there on) */
  snprintf(args, sizeof args, "resume %s/d --threads 1 --stop-at 2 --quiet", dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  snprintf(args, sizeof args, "run %s/params/example.ini --out %s/d2 --threads 1 --stop-at 2 --set init.splines=5 "
           "--set init.segment_length=40 --set energy.pair=0 --set energy.min_spacing=0", lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
  cr_assert_eq(lw_test_sh("cmp %s/d/state.lw %s/d2/state.lw", dir, dir), 0);
  /* set by the user, the same count is refused, naming where it was set */
  snprintf(args, sizeof args, "run %s/params/example.ini --out %s/e --threads 1 --stop-at 0 --set init.splines=5 "
           "--set init.segment_length=40 --set energy.pair=0 --set energy.min_spacing=0 --set anneal.domains=4",
           lw_test_root(), dir);
  cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 2, "%s", errs);
  cr_assert(strstr(errs, "--set: key 'anneal.domains': '4': domains this small leave most of the state unmoved"),
            "%s", errs);
}

/* The product rule alone where nothing keeps strokes apart: the photo preset
** with energy.min_spacing = 0 annealed a photograph to a pair energy 11.6 %
** low, silently.  Either guard (a near field or a spacing) ends the note, and
** a scene without the pair term has nothing to note. */
Test(cli, a_pair_term_without_near_field_or_spacing_gets_a_note)
{
  static const struct { const char *set; int noted; } cases[] = {
    {"--set energy.pair_near=0", 1},
    {"--set energy.pair_near=0 --set energy.min_spacing=0.1", 0},
    {"--set energy.pair_near=1.5", 0},
    {"--set energy.pair_near=0 --set energy.pair=0", 0},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    char out[256], errs[16384], args[512];
    snprintf(args, sizeof args, "run %s/params/minimal.ini --stop-at 0 --out %s/g%zu %s", lw_test_root(), dir, k,
             cases[k].set);
    cr_assert_eq(run(args, out, sizeof out, errs, sizeof errs), 0, "%s", errs);
    cr_assert_eq(strstr(errs, "energy.pair_near = 0 and energy.min_spacing = 0: strokes may touch and cross") != NULL,
                 cases[k].noted, "%s: %s", cases[k].set, errs);
  }
}
