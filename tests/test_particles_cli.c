/*
** test_particles_cli.c -- the oriented-particle system through the seam, on
** the command line: the bundled sheet anneals and writes a valid final.ply,
** stop and resume give the bytes of an uninterrupted run, the outputs do
** not depend on the thread count with tempering, `linewise energy`
** recomputes a particle run, and the LJ13 cluster of params/lj13.ini melts
** with the heat capacity the physics asks for.
*/
#include <criterion/criterion.h>
#include <gsl/gsl_cdf.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_math.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static char dir[64];

static void make_dir(void) { cr_assert_eq(lw_test_dir_make(dir, "pcli"), 0); }
static void remove_dir(void) { cr_assert_eq(lw_test_dir_remove(dir), 0); }
#define sh lw_test_sh

TestSuite(particles_cli, .init = make_dir, .fini = remove_dir);

/* A small tempered sheet: 3 replicas, few sweeps, checkpoints inside. */
static const char scene[] =
  "[scene]\nsystem = particles\n"
  "[particles]\ncount = 37\npattern = plane\nnoise = 0.1\nnormal_noise = 10\nalpha_p = 10\nalpha_n = 10\n"
  "alpha_c = 0.5\ngravity = 0.01\nboundary = plane\nboundary_z = -3\nalpha_b = 0.1\npng_size = 64\n"
  "[moves]\ntranslate = 1\nrotate = 1\nstep_translate = 0.1\nstep_rotate = 5\n"
  "[anneal]\nschedule = geometric\nt_start = 0.05\nt_end = 0.001\nsweeps = 60\nsteps = 6\nseed = 5\n"
  "check_every = 7\n"
  "[tempering]\nreplicas = 3\nt_min = 0.05\nt_max = 0.5\n"
  "[output]\ncheckpoint_every = 9\ntrace_every = 3\n";

static void write_scene(void) { cr_assert_eq(lw_test_write_text(dir, "s.ini", scene), 0); }

static const char *const same[] = {"state.lw", "replica-1.lw", "replica-2.lw", "trace.csv", "final.ply", "final.png"};
#define N_SAME (sizeof same / sizeof *same)

/* One vertex line: six finite numbers, the last three a unit normal. */
static int vertex_ok(const char *line)
{
  double v[6];
  if (sscanf(line, "%lf %lf %lf %lf %lf %lf", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5]) != 6) return 0;
  for (int k = 0; k < 6; k++)
    if (!isfinite(v[k])) return 0;
  return fabs(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] - 1.0) < 1e-6;
}

Test(particles_cli, the_sheet_example_runs_and_writes_a_valid_ply)
{
  const char *root = getenv("LW_ROOT");
  cr_assert_not_null(root);
  cr_assert_eq(sh("%s run %s/params/particles-sheet.ini --out %s/sheet --quiet --set anneal.sweeps=300", lw_test_bin(), root,
                  dir), 0);
  char path[128];
  snprintf(path, sizeof path, "%s/sheet/final.ply", dir);
  FILE *f = fopen(path, "r");
  cr_assert_not_null(f, "%s", path);
  char line[256];
  long vertices = -1, header = 0, read = 0;
  const char *expect[] = {"ply", "format ascii 1.0"};
  while (fgets(line, sizeof line, f)) {
    if (header < 2) cr_assert_eq(strncmp(line, expect[header], strlen(expect[header])), 0, "header line %ld", header);
    header++;
    if (sscanf(line, "element vertex %ld", &vertices) == 1) continue;
    if (!strcmp(line, "end_header\n")) break;
  }
  cr_assert_eq(vertices, 127, "the sheet's 127 particles");
  while (fgets(line, sizeof line, f)) {
    cr_assert(vertex_ok(line), "vertex %ld: %s", read, line);
    read++;
  }
  fclose(f);
  cr_assert_eq(read, vertices);
  /* the other outputs, with the particle terms and move kinds by name */
  cr_assert_eq(sh("head -1 %s/sheet/trace.csv | grep -q '^sweep,temperature,lj,coplanarity,conormality,total,"
                  "acc_translate,acc_rotate$'", dir), 0);
  cr_assert_eq(sh("grep -q '\"system\": \"particles\"' %s/sheet/summary.json", dir), 0);
  cr_assert_eq(sh("grep -q '\"particles\": 127' %s/sheet/summary.json", dir), 0);
  cr_assert_eq(sh("grep -q '\"rotate\": ' %s/sheet/summary.json", dir), 0);
  cr_assert_eq(sh("grep -A1 '^\\[system particles\\]$' %s/sheet/state.lw | grep -q '^count = 127$'", dir), 0);
  cr_assert_eq(sh("test -s %s/sheet/final.png", dir), 0);
  /* the anneal lowered the energy well below the noisy start */
  double e0 = NAN, e1 = NAN;
  snprintf(path, sizeof path, "%s/sheet/summary.json", dir);
  f = fopen(path, "r");
  cr_assert_not_null(f);
  int in_energy = 0;
  while (fgets(line, sizeof line, f)) {
    if (strstr(line, "\"energy\": {")) in_energy = 1;
    if (in_energy && sscanf(line, " \"total\": %lf", &e1) == 1) in_energy = 0;
    sscanf(line, " \"energy_initial\": %lf", &e0);
  }
  fclose(f);
  cr_assert(isfinite(e0) && isfinite(e1), "energies %g %g", e0, e1);
  cr_assert_lt(e1, e0, "annealing lowers the energy: %g -> %g", e0, e1);
}

/* A disc of 1e-200 mm (in range) made a matrix cairo cannot invert: the run
** annealed, then lost its preview and summary.json.  It draws its dots. */
Test(particles_cli, a_vanishing_disc_still_draws_its_preview)
{
  cr_assert_eq(sh("%s run %s/params/particles-sheet.ini --out %s/tiny --quiet --set anneal.sweeps=4 --set "
                  "particles.disc=1e-200 2> %s/err.txt && test -s %s/tiny/final.png && test -s %s/tiny/summary.json",
                  lw_test_bin(), getenv("LW_ROOT"), dir, dir, dir, dir),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
}

Test(particles_cli, stop_and_resume_give_the_bytes_of_an_uninterrupted_run)
{
  write_scene();
  cr_assert_eq(sh("%s run %s/s.ini --out %s/a --quiet", lw_test_bin(), dir, dir), 0);
  /* stopped between checkpoints, then again later */
  cr_assert_eq(sh("%s run %s/s.ini --out %s/b --quiet --stop-at 22", lw_test_bin(), dir, dir), 0);
  cr_assert_eq(sh("%s resume %s/b --quiet --stop-at 41", lw_test_bin(), dir), 0);
  cr_assert_eq(sh("%s resume %s/b --quiet", lw_test_bin(), dir), 0);
  for (size_t k = 0; k < N_SAME; k++)
    cr_assert_eq(sh("cmp -s %s/a/%s %s/b/%s", dir, same[k], dir, same[k]), 0, "%s differs", same[k]);
}

Test(particles_cli, outputs_do_not_depend_on_the_thread_count_with_tempering)
{
  write_scene();
  const int threads[3] = {1, 2, 4};
  for (int i = 0; i < 3; i++)
    cr_assert_eq(sh("OMP_NUM_THREADS=%d %s run %s/s.ini --out %s/t%d --quiet", threads[i], lw_test_bin(), dir, dir, threads[i]),
                 0);
  for (int i = 1; i < 3; i++)
    for (size_t k = 0; k < N_SAME; k++)
      cr_assert_eq(sh("cmp -s %s/t1/%s %s/t%d/%s", dir, same[k], dir, threads[i], same[k]), 0,
                   "%s differs with %d threads", same[k], threads[i]);
  /* every term of the scene is on: a trace column each, and the ensemble */
  cr_assert_eq(sh("head -1 %s/t1/trace.csv | grep -q "
                  "'^sweep,temperature,lj,coplanarity,conormality,cocircularity,gravity,boundary,total,'", dir), 0);
  cr_assert_eq(sh("grep -q '\"swap_acceptance\"' %s/t1/summary.json", dir), 0);
}

Test(particles_cli, energy_recomputes_a_particle_run)
{
  write_scene();
  cr_assert_eq(sh("%s run %s/s.ini --out %s/e --quiet", lw_test_bin(), dir, dir), 0);
  cr_assert_eq(sh("%s energy %s/e > %s/energy.txt", lw_test_bin(), dir, dir), 0);
  char path[128], line[256];
  snprintf(path, sizeof path, "%s/energy.txt", dir);
  FILE *f = fopen(path, "r");
  cr_assert_not_null(f);
  const char *names[] = {"lj", "coplanarity", "conormality", "cocircularity", "gravity", "boundary", "total"};
  double v[7], sum = 0.0;
  for (int k = 0; k < 7; k++) {
    char name[32];
    cr_assert_not_null(fgets(line, sizeof line, f), "line %d", k);
    cr_assert_eq(sscanf(line, "%31s %lf", name, &v[k]), 2, "%s", line);
    cr_assert_str_eq(name, names[k]);
    if (k < 6) sum += v[k];
  }
  cr_assert_null(fgets(line, sizeof line, f), "nothing after the total");
  fclose(f);
  cr_assert(lw_close_rel(v[6], sum, 1e-12, 1.0), "total %.17g, sum %.17g", v[6], sum);
  /* the same total as the run's running energy in summary.json */
  snprintf(path, sizeof path, "%s/e/summary.json", dir);
  f = fopen(path, "r");
  cr_assert_not_null(f);
  double run_total = NAN;
  int in_energy = 0;
  while (fgets(line, sizeof line, f)) {
    if (strstr(line, "\"energy\": {")) in_energy = 1;
    if (in_energy && sscanf(line, " \"total\": %lf", &run_total) == 1) break;
  }
  fclose(f);
  cr_assert(lw_close_rel(v[6], run_total, 1e-9, 1.0), "recomputed %.17g, run %.17g", v[6], run_total);
  /* a second count among the particles is refused (it passed unread, as
  ** the NURBS one did) */
  cr_assert_eq(sh("cp -r %s/e %s/c2 && sed -i '0,/^particle = /s/^particle = .*/&\\ncount = 999/' %s/c2/state.lw && "
                  "{ %s energy %s/c2 2>%s/err.txt >/dev/null; test $? -eq 2; } && grep -q 'c2/state.lw:[0-9]*: "
                  "\\[system particles\\] count: given twice' %s/err.txt", dir, dir, dir, lw_test_bin(), dir, dir, dir),
               0, "%s", lw_test_slurp("%s/err.txt", dir));
  /* a damaged particle line is refused with the file and its line */
  cr_assert_eq(sh("sed -i '0,/^particle = /s/^particle = \\([^ ]*\\) /particle = nan /' %s/e/state.lw", dir), 0);
  cr_assert_eq(sh("%s energy %s/e 2>%s/err.txt >/dev/null", lw_test_bin(), dir, dir), 2);
  cr_assert_eq(sh("grep -q 'e/state.lw:[0-9]*: \\[system particles\\] particle: expected' %s/err.txt", dir), 0);
  /* a splines scene on a particle state: the missing section is named */
  cr_assert_eq(sh("sed -i 's/^system = particles/system = splines/' %s/e/scene.ini", dir), 0);
  cr_assert_eq(sh("%s energy %s/e 2>%s/err.txt >/dev/null", lw_test_bin(), dir, dir), 2);
  cr_assert_eq(sh("grep -q 'section \\[system splines\\]: missing' %s/err.txt", dir), 0);
}

/* The number after "key": in a JSON file (the first one). */
static double json_number(const char *path, const char *key)
{
  FILE *f = fopen(path, "r");
  cr_assert_not_null(f, "%s", path);
  char line[512], pat[80];
  snprintf(pat, sizeof pat, "\"%s\": ", key);
  double v = NAN;
  while (fgets(line, sizeof line, f)) {
    char *at = strstr(line, pat);
    if (at && sscanf(at + strlen(pat), "%lf", &v) == 1) break;
  }
  fclose(f);
  return v;
}

Test(particles_cli, a_run_starts_from_the_particles_of_another_runs_state)
{
  write_scene();
  cr_assert_eq(sh("%s run %s/s.ini --out %s/a --quiet", lw_test_bin(), dir, dir), 0);
  /* from the hottest rung's state, without tempering */
  cr_assert_eq(sh("sed -e 's/^replicas = 3/replicas = 1/' -e 's/^sweeps = 60/sweeps = 5/' %s/s.ini > %s/f.ini && "
                  "printf '[init]\\nfrom = %s/a/replica-2.lw\\n' >> %s/f.ini", dir, dir, dir, dir), 0);
  cr_assert_eq(sh("%s run %s/f.ini --out %s/f --quiet", lw_test_bin(), dir, dir), 0);
  cr_assert_eq(sh("%s energy %s/a > /dev/null && cp %s/a/replica-2.lw %s/a/state.lw && %s energy %s/a | "
                  "awk '$1 == \"total\" { print $2 }' > %s/e2.txt", lw_test_bin(), dir, dir, dir, lw_test_bin(), dir, dir), 0);
  char path[160];
  snprintf(path, sizeof path, "%s/e2.txt", dir);
  FILE *f = fopen(path, "r");
  cr_assert_not_null(f);
  double e2 = NAN;
  cr_assert_eq(fscanf(f, "%lf", &e2), 1);
  fclose(f);
  snprintf(path, sizeof path, "%s/f/summary.json", dir);
  double e0 = json_number(path, "energy_initial");
  cr_assert(lw_close_rel(e0, e2, 1e-12, 1.0), "started at %.17g, the state holds %.17g", e0, e2);
  /* a splines state is refused naming [init] from and the section */
  cr_assert_eq(sh("printf 'linewise-state 2\\n[run]\\nscene = s.ini\\nseed = 1\\nsweep = 0\\n[system splines]\\n"
                  "splines = 0\\n' > %s/spl.lw && sed -i 's|^from = .*|from = %s/spl.lw|' %s/f.ini", dir, dir, dir), 0);
  cr_assert_eq(sh("%s run %s/f.ini --out %s/g --quiet 2>%s/err.txt", lw_test_bin(), dir, dir, dir), 2);
  cr_assert_eq(sh("grep -q 'spl.lw: section \\[system particles\\]: missing' %s/err.txt", dir), 0);
}

/* The total of trace.csv's last row in run directory d and the one
** `linewise energy` recomputes from its state.lw. */
static void trace_and_state_totals(const char *d, double *traced, double *fresh)
{
  char path[256];
  cr_assert_eq(sh("awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == \"total\") c = i } END { print $c }' "
                  "%s/trace.csv > %s/t.txt && %s energy %s | awk '$1 == \"total\" { print $2 }' >> %s/t.txt",
                  d, dir, lw_test_bin(), d, dir), 0);
  snprintf(path, sizeof path, "%s/t.txt", dir);
  FILE *f = fopen(path, "r");
  cr_assert_not_null(f);
  cr_assert_eq(fscanf(f, "%lf %lf", traced, fresh), 2);
  fclose(f);
}

/* Particles of a points file on top of the pattern's start at about 1e19
** and fall to about -2,800 within twenty sweeps.  The running total kept
** that fall's rounding (a drift of 0.073 with check_every = 5), and resume
** refused the checkpoint of sweep 10 as damaged (its total -2768, the
** state's fresh energy 38).  Recomputed at sweeps 1, 2, 4 and 8 it was
** still off in between: trace rows 4e-7 off at sweep 1 (written before the
** recomputation) and 1e-8 at 5; and two points 1e-9 apart, at 8e17 and at
** 2,892 three sweeps on, left a finished run whose summary said lj = 0 and
** whose state resume --sweeps refused.  Now the energy is recomputed
** wherever it has fallen 8 times since the last time, before the row: every
** row (at check_every = 5) is within 1e-9 of its state, and a run stopped
** at any of the first sweeps resumes to the bytes of one that was not.  The
** points file is named relative to the scene.  (Seed 10 starts at 1.3e17
** and falls to about -2,800 within the first sweep; max_relative_drift
** counts that fall's rounding over the size before it, 1.8e-10; over the
** size after it, it read 3.5e-4.) */
Test(particles_cli, a_start_far_above_the_minimum_keeps_its_energy_and_resumes)
{
  char pts[25 * 16] = "", path[256], d[200];
  for (int i = 0; i < 5; i++)
    for (int j = 0; j < 5; j++) snprintf(pts + strlen(pts), sizeof pts - strlen(pts), "%g %g 0\n", 1.1 * i, 1.1 * j);
  cr_assert_eq(lw_test_write_text(dir, "pts.txt", pts), 0);
  cr_assert_eq(lw_test_write_text(dir, "pts.ini", "[scene]\nsystem = particles\n[particles]\npoints = pts.txt\n"
                                                  "[anneal]\nsweeps = 20\ncheck_every = 5\nseed = 10\n"), 0);
  cr_assert_eq(sh("%s run %s/pts.ini --out %s/p --quiet", lw_test_bin(), dir, dir), 0);
  snprintf(path, sizeof path, "%s/p/summary.json", dir);
  double start = json_number(path, "energy_initial"), drift = json_number(path, "max_relative_drift");
  cr_assert(start > 1e15 && drift < 1e-6, "start %g, drift %g", start, drift);
  static const int stops[] = {1, 3, 5, 6, 7, 10};
  for (size_t k = 0; k < sizeof stops / sizeof *stops; k++) {
    snprintf(d, sizeof d, "%s/q%d", dir, stops[k]);
    cr_assert_eq(sh("%s run %s/pts.ini --out %s --quiet --stop-at %d", lw_test_bin(), dir, d, stops[k]), 0);
    double traced, fresh;
    trace_and_state_totals(d, &traced, &fresh);
    cr_assert(lw_close_rel(traced, fresh, 1e-9, 1.0), "sweep %d: the row says %.17g, the state %.17g", stops[k],
              traced, fresh);
    cr_assert_eq(sh("%s resume %s --quiet", lw_test_bin(), d), 0);
    cr_assert_eq(sh("cmp -s %s/p/state.lw %s/state.lw && cmp -s %s/p/trace.csv %s/trace.csv", dir, d, dir, d), 0,
                 "stopped at sweep %d", stops[k]);
  }
  cr_assert_eq(lw_test_write_text(dir, "near.txt", "0 0 0\n1e-9 0 0\n3 0 0\n"), 0);
  cr_assert_eq(lw_test_write_text(dir, "near.ini", "[scene]\nsystem = particles\n[particles]\npoints = near.txt\n"
                                                   "count = 0\nnoise = 0\nnormal_noise = 0\nrange = 1.6\n"
                                                   "[anneal]\nschedule = geometric\nt_start = 0.001\n"
                                                   "t_end = 1e-5\nsweeps = 3\n"), 0);
  snprintf(d, sizeof d, "%s/n", dir);
  cr_assert_eq(sh("%s run %s/near.ini --out %s --quiet", lw_test_bin(), dir, d), 0);
  double traced, fresh;
  trace_and_state_totals(d, &traced, &fresh);
  cr_assert(lw_close_rel(traced, fresh, 1e-9, 1.0), "the row says %.17g, the state %.17g", traced, fresh);
  cr_assert_eq(sh("%s resume %s --sweeps 5 --quiet", lw_test_bin(), d), 0);
  /* a wall's energy that is not finite names the wall, not particles that
  ** coincide (these are 1 apart, 1e-300 above the floor) */
  cr_assert_eq(lw_test_write_text(dir, "wall.txt", "0 0 1e-300\n1 0 1e-300\n"), 0);
  cr_assert_eq(lw_test_write_text(dir, "wall.ini", "[scene]\nsystem = particles\n[particles]\npoints = wall.txt\n"
                                                   "count = 0\nboundary = plane\nboundary_z = 0\nalpha_b = 1\n"), 0);
  cr_assert_eq(sh("%s run %s/wall.ini --out %s/w --quiet 2>%s/err.txt", lw_test_bin(), dir, dir, dir), 2);
  cr_assert_eq(sh("grep -qx \"linewise: %s/wall.ini:4: key 'particles.points': the boundary energy of the particles "
                  "is not finite: a particle (nearly) on the boundary (particles.boundary, particles.alpha_b)\" "
                  "%s/err.txt", dir, dir), 0, "%s", lw_test_slurp("%s/err.txt", dir));
}

/* The rms distance of final.ply's particles to their least-squares plane
** and the largest angle (degrees) of a normal to that plane's. */
static void flatness(const char *path, double *rms, double *worst)
{
  FILE *f = fopen(path, "r");
  cr_assert_not_null(f, "%s", path);
  char line[256];
  while (fgets(line, sizeof line, f) && strcmp(line, "end_header\n")) {}
  double v[200][6], c[3] = {0, 0, 0};
  int n = 0;
  while (n < 200 && fgets(line, sizeof line, f) &&
         sscanf(line, "%lf %lf %lf %lf %lf %lf", &v[n][0], &v[n][1], &v[n][2], &v[n][3], &v[n][4], &v[n][5]) == 6)
    n++;
  fclose(f);
  cr_assert_gt(n, 3);
  for (int i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) c[k] += v[i][k] / n;
  /* the plane's normal: the scatter matrix's smallest eigenvector, the
  ** largest of trace - matrix (power iteration; for a disc the ratio of its
  ** two largest eigenvalues is about 1/2, so 60 rounds leave 1e-18) */
  double m[3][3] = {{0}}, u[3] = {0.3, 0.2, 1};
  for (int i = 0; i < n; i++)
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++) m[a][b] -= (v[i][a] - c[a]) * (v[i][b] - c[b]);
  double tr = -(m[0][0] + m[1][1] + m[2][2]);
  for (int a = 0; a < 3; a++) m[a][a] += tr;
  for (int it = 0; it < 60; it++) {
    double w[3], len = 0;
    for (int a = 0; a < 3; a++) {
      w[a] = m[a][0] * u[0] + m[a][1] * u[1] + m[a][2] * u[2];
      len += w[a] * w[a];
    }
    for (int a = 0; a < 3; a++) u[a] = w[a] / sqrt(len);
  }
  double s = 0;
  *worst = 0;
  for (int i = 0; i < n; i++) {
    double d = 0, dot = 0;
    for (int k = 0; k < 3; k++) {
      d += (v[i][k] - c[k]) * u[k];
      dot += v[i][3 + k] * u[k];
    }
    s += d * d;
    double ang = acos(fmin(1.0, fabs(dot))) * 180 / acos(-1.0);
    if (ang > *worst) *worst = ang;
  }
  *rms = sqrt(s / n);
}

Test(particles_cli, a_quench_takes_the_noisy_sheet_flat_at_once)
{
  /* The bundled sheet (127 particles, noise 0.1 r0 and 10 degrees) after one
  ** sweep, quenched by L-BFGS on the particles' gradient until its norm is
  ** 1e-6: measured 305 iterations, 0.02 s, rms distance to the plane 4e-8 r0
  ** and normals within 1.6e-3 degrees (seeds 2, 4, 5 and 6: 1e-7 r0 and 0.8e-3
  ** to 1.8e-3 degrees), where the 6000 sweeps of the example's anneal leave
  ** 9.7e-3 r0 and 0.40 degrees.  Bounds 1e-6 r0 and 1e-2 degrees:
  ** a gradient off by a term or a sign stalls far above them.  With the default
  ** stall rule: it waits while the gradient norm falls (before, it stopped
  ** at 59 iterations and 6e-3 r0). */
  const char *root = getenv("LW_ROOT");
  cr_assert_not_null(root);
  cr_assert_eq(sh("%s run %s/params/particles-sheet.ini --out %s/q --quiet --set anneal.sweeps=1 --set "
                  "anneal.quench=bfgs", lw_test_bin(), root, dir),
               0);
  char path[128];
  snprintf(path, sizeof path, "%s/q/summary.json", dir);
  cr_assert_eq(sh("grep -q '\"ended\": \"converged\"' %s", path), 0);
  double before = json_number(path, "energy_before"), after = json_number(path, "energy_after");
  cr_assert(before > 0 && after < -300, "energy %g -> %g", before, after);
  double rms, worst;
  snprintf(path, sizeof path, "%s/q/final.ply", dir);
  flatness(path, &rms, &worst);
  cr_assert(rms < 1e-6 && worst < 1e-2, "rms distance %g, worst normal %g degrees", rms, worst);
}

/* The particles' quench runs to quench_tol unless the scene sets a stall
** share: the stall rule, measured against the first iterations' collapse,
** stopped the sphere's quench at -184.68 with a gradient of 12.2, where
** 1089 iterations reach -272.86 (a flat sheet). */
Test(particles_cli, a_particle_quench_runs_to_its_minimum)
{
  const char *run = "%s run %s/params/particles-sphere.ini --out %s/%s --quiet --set anneal.sweeps=1 --set "
                    "anneal.quench=bfgs %s";
  cr_assert_eq(sh(run, lw_test_bin(), getenv("LW_ROOT"), dir, "conv", ""), 0);
  char path[128];
  snprintf(path, sizeof path, "%s/conv/summary.json", dir);
  cr_assert_eq(sh("grep -q '\"ended\": \"converged\"' %s && grep -qx 'quench_stall = 0' %s/conv/scene.ini", path,
                  dir), 0);
  cr_assert(json_number(path, "energy_after") < -272.8, "quenched to %g", json_number(path, "energy_after"));
  cr_assert_eq(sh(run, lw_test_bin(), getenv("LW_ROOT"), dir, "stall", "--set anneal.quench_stall=0.05"), 0);
  snprintf(path, sizeof path, "%s/stall/summary.json", dir);
  cr_assert_eq(sh("grep -q '\"ended\": \"stalled\"' %s", path), 0, "a stall share given is kept");
  /* a hard wall holds what it presses, whose gradient never falls: 0.05 there */
  cr_assert_eq(sh(run, lw_test_bin(), getenv("LW_ROOT"), dir, "wall", "--set particles.boundary=plane --set "
                  "particles.boundary_z=-3 --set particles.alpha_b=0"), 0);
  cr_assert_eq(sh("grep -qx 'quench_stall = 0.050000000000000003' %s/wall/scene.ini", dir), 0);
}

Test(particles_cli, a_quench_lays_the_sheet_on_a_hard_floor)
{
  /* Gravity 1 pulls the bundled sheet onto a hard floor at z = -0.5 (no soft
  ** term: beyond it is forbidden, at it nothing).  The minimum is the flat
  ** sheet on the floor: its bonds' -302.44545 plus 127 x -0.5 of gravity.
  ** The row's `blocked` holds only the height of a particle a step would take
  ** through the floor, so the sheet still slides and turns: measured
  ** -365.94545 in 2000 iterations and 2251 evaluations, none forbidden.
  ** Without holds the line search halved every step at the floor (102,266
  ** evaluations, 100,252 forbidden) and stopped at -355.4; holding the whole
  ** position froze the lattice at -357.7. */
  const char *root = getenv("LW_ROOT");
  cr_assert_not_null(root);
  cr_assert_eq(sh("%s run %s/params/particles-sheet.ini --out %s/floor --quiet --set anneal.sweeps=1 --set "
                  "anneal.quench=bfgs --set anneal.quench_stall=0 --set particles.gravity=1 --set "
                  "particles.boundary=plane --set particles.boundary_z=-0.5 --set particles.alpha_b=0",
                  lw_test_bin(), root, dir),
               0);
  char path[128];
  snprintf(path, sizeof path, "%s/floor/summary.json", dir);
  double after = json_number(path, "energy_after"), evaluations = json_number(path, "evaluations");
  double iterations = json_number(path, "iterations"), forbidden = json_number(path, "forbidden");
  cr_assert(fabs(after - (-302.44545 - 63.5)) < 1e-3, "quenched to %.9g", after);
  cr_assert(evaluations < 1.5 * iterations + 50 && forbidden == 0, "%g evaluations, %g forbidden, %g iterations",
            evaluations, forbidden, iterations);
  /* the sheet lies an ulp above the floor: final.ply to nine digits put it
  ** on the floor, and the run continued from it (FORMATS.md) was refused,
  ** "point 1 ... is outside the plane boundary" */
  cr_assert_eq(sh("%s run %s/params/particles-sheet.ini --out %s/floor2 --quiet --stop-at 0 --set particles.count=0 "
                  "--set particles.points=%s/floor/final.ply --set particles.boundary=plane --set "
                  "particles.boundary_z=-0.5 --set particles.alpha_b=0 --set particles.gravity=1 && %s energy %s/floor2 "
                  "> %s/e2.txt", lw_test_bin(), root, dir, dir, lw_test_bin(), dir, dir),
               0);
  /* and it starts where the quench ended (the normals' last bits aside) */
  cr_assert_eq(sh("awk '/^total/ { d = $2 - (%.17g); f = d < 1e-9 && d > -1e-9 } END { exit !f }' %s/e2.txt", after,
                  dir), 0, "%s", lw_test_slurp("%s/e2.txt", dir));
}

/* A gas of 2000 particles with no pair term, under gravity 1 in a sphere of
** radius 5 with a soft wall (alpha_B 0.5) at T = 1: each particle samples
** p(x) ~ exp(-(g z + alpha_B / (R - |x|)^2) / T) on its own, so one snapshot
** after 600 sweeps is 2000 independent draws.  With domains (auto: a 3 x 3
** lattice shifted each sweep, moves leaving their domain refused) the x and z
** marginals must still follow p: chi-square against p integrated on a grid
** of 160^3 cells, over the 10 bins of each axis that expect 5 or more, at a
** false-alarm rate of 1e-3 for its degrees of freedom (measured 4.1 in z
** with 6 degrees).  A refusal that favoured a side would pile particles up
** in x (a rule refusing steps of more than 0.4 to the right gave 30665).
** The run is the same for 1 and 2 threads and after a stop and resume, and
** differs from the run without domains (the domains did split the sweeps). */
static void marginals(const char *ply, double hist[2][10])
{
  FILE *f = fopen(ply, "r");
  cr_assert_not_null(f, "%s", ply);
  char line[256];
  while (fgets(line, sizeof line, f) && strcmp(line, "end_header\n")) {}
  memset(hist, 0, 2 * 10 * sizeof(double));
  double v[3];
  while (fgets(line, sizeof line, f) && sscanf(line, "%lf %lf %lf", &v[0], &v[1], &v[2]) == 3)
    for (int a = 0; a < 2; a++) {
      int b = (int)floor((v[a ? 2 : 0] + 5.0));
      if (b >= 0 && b < 10) hist[a][b] += 1;
    }
  fclose(f);
}

Test(particles_cli, domains_sample_the_gas_and_keep_their_bytes)
{
  cr_assert_eq(lw_test_write_text(dir, "gas.ini",
                                  "[scene]\nsystem = particles\n[particles]\ncount = 2000\npattern = cloud\nsize = 5\n"
                                  "r0 = 0.5\nalpha_lj = 0\nalpha_p = 0\nalpha_n = 0\nalpha_c = 0\ngravity = 1\n"
                                  "boundary = sphere\nboundary_radius = 5\nalpha_b = 0.5\npng_size = 64\n"
                                  "[moves]\ntranslate = 1\nrotate = 0\nstep_translate = 0.5\n"
                                  "[anneal]\nschedule = constant\nt_start = 1\nt_end = 1\nsweeps = 600\nseed = 11\n"
                                  "domains = auto\n"),
               0);
  cr_assert_eq(sh("%s run %s/gas.ini --out %s/g2 --threads 2 --quiet", lw_test_bin(), dir, dir), 0);
  cr_assert_eq(sh("%s run %s/gas.ini --out %s/g1 --threads 1 --quiet", lw_test_bin(), dir, dir), 0);
  cr_assert_eq(sh("cmp -s %s/g1/state.lw %s/g2/state.lw && cmp -s %s/g1/final.ply %s/g2/final.ply", dir, dir, dir,
                  dir), 0, "the thread count changed the run");
  cr_assert_eq(sh("%s run %s/gas.ini --out %s/gr --quiet --threads 2 --stop-at 250 && %s resume %s/gr --quiet",
                  lw_test_bin(), dir, dir, lw_test_bin(), dir), 0);
  cr_assert_eq(sh("cmp -s %s/g1/state.lw %s/gr/state.lw", dir, dir), 0, "a resumed run differs");
  cr_assert_eq(sh("%s run %s/gas.ini --out %s/g0 --quiet --set anneal.domains=off", lw_test_bin(), dir, dir), 0);
  cr_assert_neq(sh("cmp -s %s/g0/state.lw %s/g1/state.lw", dir, dir), 0, "domains = auto did not split the sweeps");
  /* p on a grid, binned along x and z */
  const double R = 5, ab = 0.5, g = 1, T = 1, h = 10.0 / 160;
  double expect[2][10] = {{0}}, total = 0;
  for (int i = 0; i < 160; i++)
    for (int j = 0; j < 160; j++)
      for (int k = 0; k < 160; k++) {
        double x = -5 + (i + 0.5) * h, y = -5 + (j + 0.5) * h, z = -5 + (k + 0.5) * h, r = sqrt(x * x + y * y + z * z);
        if (r >= R) continue;
        double w = exp(-(g * z + ab / ((R - r) * (R - r))) / T);
        expect[0][(int)floor(x + 5)] += w;
        expect[1][(int)floor(z + 5)] += w;
        total += w;
      }
  char path[128];
  snprintf(path, sizeof path, "%s/g1/final.ply", dir);
  double hist[2][10];
  marginals(path, hist);
  for (int a = 0; a < 2; a++) {
    double chi = 0, n = 0;
    int bins = 0;
    for (int b = 0; b < 10; b++) n += hist[a][b];
    cr_assert_eq(n, 2000, "axis %d: %g particles in the bins", a, n);
    /* bins expected to hold fewer than 5 are merged with their neighbours,
    ** in order (dropped, they left bins - 1 degrees of freedom to counts
    ** that no longer summed to n: a false alarm about 2e-3, not 1e-3) */
    double go = 0, ge = 0, last_o = 0, last_e = 0;
    for (int b = 0; b < 10; b++) {
      go += hist[a][b];
      ge += n * expect[a][b] / total;
      if (ge < 5) continue;
      if (bins) chi += (last_o - last_e) * (last_o - last_e) / last_e;
      last_o = go, last_e = ge, go = ge = 0, bins++;
    }
    last_o += go, last_e += ge; /* a short tail joins the last group */
    chi += (last_o - last_e) * (last_o - last_e) / last_e;
    double limit = gsl_cdf_chisq_Qinv(1e-3, bins - 1);
    cr_log_info("axis %s: chi-square %.2f over %d bins, limit %.1f", a ? "z" : "x", chi, bins, limit);
    cr_assert_lt(chi, limit, "axis %s: chi-square %.2f over %d bins (limit %.1f)", a ? "z" : "x", chi, bins, limit);
  }
}

/* Births and deaths (particles_grow.h) through the run loop: a sheet with a
** cost per particle (chem) that the bonds outweigh grows and shrinks while
** it anneals, with tempering and domains.  The count changes; the running
** totals match the energy from scratch (max_relative_drift, and `linewise
** energy` on the final state); stopped and resumed, and on 1 or 2 threads,
** the same bytes; the trace and summary name the two kinds. */
Test(particles_cli, births_and_deaths_keep_their_energy_bytes_and_resume)
{
  cr_assert_eq(lw_test_write_text(dir, "g.ini",
                                  "[scene]\nsystem = particles\n[particles]\ncount = 37\npattern = plane\nnoise = 0.05\n"
                                  "alpha_p = 5\nalpha_n = 5\nbirth = 0.2\ndeath = 0.2\nchem = 0.5\npng_size = 64\n"
                                  "[moves]\ntranslate = 1\nrotate = 1\nstep_translate = 0.1\nstep_rotate = 5\n"
                                  "[anneal]\nschedule = geometric\nt_start = 0.3\nt_end = 0.01\nsweeps = 200\n"
                                  "seed = 3\ncheck_every = 10\ndomains = auto\n"
                                  "[tempering]\nreplicas = 2\nt_min = 0.3\nt_max = 1\n"
                                  "[output]\ncheckpoint_every = 30\n"),
               0);
  cr_assert_eq(sh("%s run %s/g.ini --out %s/b1 --threads 1 --quiet", lw_test_bin(), dir, dir), 0);
  cr_assert_eq(sh("%s run %s/g.ini --out %s/b2 --threads 2 --quiet", lw_test_bin(), dir, dir), 0);
  cr_assert_eq(sh("%s run %s/g.ini --out %s/br --threads 2 --quiet --stop-at 77 && %s resume %s/br --quiet",
                  lw_test_bin(), dir, dir, lw_test_bin(), dir), 0);
  static const char *const files[] = {"state.lw", "replica-1.lw", "trace.csv", "final.ply"};
  for (int k = 0; k < 4; k++) {
    cr_assert_eq(sh("cmp -s %s/b1/%s %s/b2/%s", dir, files[k], dir, files[k]), 0, "%s: 1 and 2 threads differ",
                 files[k]);
    cr_assert_eq(sh("cmp -s %s/b1/%s %s/br/%s", dir, files[k], dir, files[k]), 0, "%s: the resumed run differs",
                 files[k]);
  }
  char path[160];
  snprintf(path, sizeof path, "%s/b1/summary.json", dir);
  const char *js = lw_test_read_text(path);
  long count = strtol(strstr(js, "\"particles\": ") + 13, NULL, 10);
  double drift = strtod(strstr(js, "\"max_relative_drift\": ") + 22, NULL);
  double total = strtod(strstr(strstr(js, "\"energy\": {"), "\"total\": ") + 9, NULL);
  cr_assert(count != 37 && count > 0, "the count stayed %ld", count);
  cr_assert_lt(drift, 1e-9, "running totals drifted by %g", drift);
  cr_assert(strstr(js, "\"birth\":") && strstr(js, "\"death\":"), "summary.json lacks the kinds");
  cr_assert_eq(sh("head -1 %s/b1/trace.csv | grep -q ',chem,.*acc_birth,acc_death'", dir), 0);
  cr_assert_eq(sh("%s energy %s/b1 > %s/e.txt", lw_test_bin(), dir, dir), 0);
  snprintf(path, sizeof path, "%s/e.txt", dir);
  const char *e = strstr(lw_test_read_text(path), "total ");
  cr_assert_not_null(e);
  double fresh = strtod(e + 6, NULL);
  cr_assert_lt(fabs(fresh - total), 1e-9 * fmax(1, fabs(total)), "from scratch %.17g, running %.17g", fresh, total);
}

/* A start above max_count (13 particles, births stopping at 1) resumes
** to the bytes of a run that never stopped, from a stop while the deaths
** bring the count down and after: the cells were sized for the larger of
** the count and max_count, so the resumed process, at 10 particles, had
** other cells than the start, walked the neighbours in another order, and
** its running totals parted in the last digits (coplanarity ...158 for
** ...169). */
Test(particles_cli, a_start_above_max_count_resumes_to_the_same_bytes)
{
  cr_assert_eq(lw_test_write_text(dir, "m.ini",
                                  "[scene]\nsystem = particles\n[particles]\ncount = 13\npattern = cloud\n"
                                  "birth = 0.2\ndeath = 1\nmax_count = 1\n[anneal]\nsweeps = 20\n"),
               0);
  /* and is said (it was kept without a word) */
  cr_assert_eq(sh("%s run %s/m.ini --out %s/m --threads 1 2> %s/m.err && grep -q 'note: the start.s 13 particles are "
                  "more than particles.max_count = 1: no birth until deaths bring the count under it' %s/m.err",
                  lw_test_bin(), dir, dir, dir, dir), 0);
  for (int stop = 1; stop <= 12; stop += 4) {
    cr_assert_eq(sh("rm -rf %s/ms && %s run %s/m.ini --out %s/ms --threads 1 --quiet --stop-at %d && "
                    "%s resume %s/ms --quiet --threads 1",
                    dir, lw_test_bin(), dir, dir, stop, lw_test_bin(), dir),
                 0);
    cr_assert_eq(sh("cmp -s %s/m/state.lw %s/ms/state.lw && cmp -s %s/m/trace.csv %s/ms/trace.csv", dir, dir, dir,
                    dir),
                 0, "stopped at sweep %d, the resumed run differs", stop);
  }
}

/* The bundled growth (params/particles-grow.ini): seven particles grow by
** births into a sheet that fills the disc the sphere wall (radius 6 r0)
** leaves them.  Measured: 121 particles, all within 5.65 r0 of the centre,
** 0.022 r0 rms off their fitted plane, normals 0.68 degrees off its normal
** on average.  A birth off the tangent plane, a death that left its
** neighbours' bonds behind or a sheet that stopped growing fails it. */
Test(particles_cli, the_bundled_seed_patch_grows_into_a_flat_sheet)
{
  cr_assert_eq(sh("%s run %s/params/particles-grow.ini --out %s/grow --quiet", lw_test_bin(), lw_test_root(), dir), 0);
  char path[160], line[256];
  snprintf(path, sizeof path, "%s/grow/final.ply", dir);
  FILE *f = fopen(path, "r");
  cr_assert_not_null(f, "%s", path);
  while (fgets(line, sizeof line, f) && strcmp(line, "end_header\n")) {}
  static double v[1000][6];
  int n = 0;
  while (n < 1000 && fgets(line, sizeof line, f) &&
         sscanf(line, "%lf %lf %lf %lf %lf %lf", &v[n][0], &v[n][1], &v[n][2], &v[n][3], &v[n][4], &v[n][5]) == 6)
    n++;
  fclose(f);
  cr_assert_gt(n, 100, "the sheet grew to %d particles only", n);
  double c[3] = {0, 0, 0};
  for (int i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) c[k] += v[i][k] / n;
  gsl_matrix *cov = gsl_matrix_calloc(3, 3), *vec = gsl_matrix_alloc(3, 3);
  gsl_vector *val = gsl_vector_alloc(3);
  for (int i = 0; i < n; i++) {
    cr_assert_lt(sqrt(v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2]), 6.0, "particle %d outside", i);
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++) *gsl_matrix_ptr(cov, a, b) += (v[i][a] - c[a]) * (v[i][b] - c[b]) / n;
  }
  gsl_eigen_symmv_workspace *ws = gsl_eigen_symmv_alloc(3);
  gsl_eigen_symmv(cov, val, vec, ws);
  gsl_eigen_symmv_sort(val, vec, GSL_EIGEN_SORT_VAL_ASC);
  double nrm[3] = {gsl_matrix_get(vec, 0, 0), gsl_matrix_get(vec, 1, 0), gsl_matrix_get(vec, 2, 0)}, angle = 0;
  for (int i = 0; i < n; i++)
    angle += acos(fmin(1, fabs(nrm[0] * v[i][3] + nrm[1] * v[i][4] + nrm[2] * v[i][5]))) * 180 / M_PI / n;
  cr_assert_lt(sqrt(gsl_vector_get(val, 0)), 0.1, "rms %g off the plane", sqrt(gsl_vector_get(val, 0)));
  cr_assert_lt(angle, 5.0, "normals %g degrees off", angle);
  gsl_eigen_symmv_free(ws);
  gsl_vector_free(val);
  gsl_matrix_free(vec);
  gsl_matrix_free(cov);
}

Test(particles_cli, the_lj13_cluster_melts_with_a_heat_capacity_peak, .timeout = 240)
{
  /* params/lj13.ini over 60,000 sweeps (fixed seed, a trace row every
  ** sweep for the error bars below), then quenched:
  ** - the quench finds the icosahedron, the global minimum of LJ13
  **   (-44.326801, Wales and Doye 1997), shifted by the cut: all 78 pairs
  **   lie within 3 r0, each raised by -phi(3) = 2/3^6 - 1/3^12;
  ** - at low T the energy is harmonic in the 33 vibrations (translation
  **   and rotation cost nothing in the hard sphere), so C -> 33/2: the
  **   weighted straight line through the rungs' C at T <= 0.08 meets T = 0
  **   within 4 of its standard errors of 16.5 (they must be under 0.3, so
  **   that 3N/2 - 1.5 = 18, counting the translations, fails);
  ** - reweighted between the rungs, C(T) rises to an inner maximum, the
  **   melting, between T = 0.23 and 0.34 (the literature's is near 0.3),
  **   over three times its value at T = 0.1. */
  cr_assert_eq(sh("%s run %s/params/lj13.ini --out %s/lj --quiet --set anneal.sweeps=60000 --set anneal.quench=bfgs "
                  "--set output.trace_every=1",
                  lw_test_bin(), lw_test_root(), dir),
               0);
  const double phi3 = pow(3, -12) - 2 * pow(3, -6), global = -44.326801 - 78 * phi3;
  cr_assert_eq(sh("awk -F': ' '/\"energy_after\"/ { d = $2 - (%.9f); f = d < 1e-6 && d > -1e-6 } END { exit !f }' "
                  "%s/lj/summary.json",
                  global, dir),
               0, "the quench missed %.6f", global);
  cr_assert_eq(sh("%s stats %s/lj --csv > %s/lj.csv", lw_test_bin(), dir, dir), 0);
  char *csv = lw_test_slurp("%s/lj.csv", dir);
  cr_assert_not_null(csv);
  double sw = 0, st = 0, stt = 0, sc = 0, stc = 0;
  for (int k = 0; k < 7; k++) {
    double T = 0.02 * pow(30, k / 15.0), c, se;
    char row[64];
    snprintf(row, sizeof row, "replica%d_heat_capacity", k);
    lw_test_stats_row(csv, row, &c, &se);
    double w = 1 / (se * se);
    sw += w, st += w * T, stt += w * T * T, sc += w * c, stc += w * T * c;
  }
  free(csv);
  double det = sw * stt - st * st, c0 = (stt * sc - st * stc) / det, se0 = sqrt(stt / det);
  cr_log_info("C(T -> 0) = %.3f +- %.3f (16.5)", c0, se0);
  cr_assert(se0 < 0.3 && fabs(c0 - 16.5) < 4 * se0, "C(T -> 0) = %g +- %g, expected 16.5", c0, se0);
  cr_assert_eq(sh("%s stats %s/lj --reweight 30 --csv > %s/rw.csv", lw_test_bin(), dir, dir), 0);
  csv = lw_test_slurp("%s/rw.csv", dir);
  const char *line = strchr(csv, '\n') + 1;
  double tmax = 0, cmax = 0, c01 = 0, best = INFINITY;
  for (int j = 0; j < 30; j++, line = strchr(line, '\n') + 1) {
    double T, e, se, c, sc2;
    cr_assert_eq(sscanf(line, "%lf,%lf,%lf,%lf,%lf", &T, &e, &se, &c, &sc2), 5, "%s", csv);
    if (c > cmax) cmax = c, tmax = T;
    if (fabs(T - 0.1) < best) best = fabs(T - 0.1), c01 = c;
  }
  free(csv);
  cr_log_info("C(T) peaks at %.3f: %.1f (C(0.1) = %.1f)", tmax, cmax, c01);
  cr_assert(tmax > 0.23 && tmax < 0.34 && cmax > 3 * c01, "C(T) peaks at T = %g: %g, against %g at 0.1", tmax, cmax,
            c01);
}

/* A move no particle is free to make is no proposal: one pinned particle and
** births and deaths of a second (the two-state chain of "Births and deaths",
** chem making P(2) = 1/2): a death with only the pinned one was counted as
** proposed and accepted, reading 0.66 against 0.333 (the real deaths over
** 400,000 sweeps), and so were its rotations.  About 6,600 real deaths in
** 20,000 sweeps: the rate's standard error is about 0.006, so 0.05 is eight
** of them. */
Test(particles_cli, a_move_no_particle_is_free_to_make_is_not_counted)
{
  cr_assert_eq(lw_test_write_text(dir, "one.txt", "0 0 0 0 0 1\n"), 0);
  cr_assert_eq(lw_test_write_text(dir, "db.ini",
                                  "[scene]\nsystem = particles\n[particles]\ncount = 0\npoints = one.txt\npinned = 1\n"
                                  "range = 1.6\nalpha_lj = 0\nalpha_p = 0\nalpha_n = 1\nbirth = 1\ndeath = 1\n"
                                  "chem = -0.15655378626807898\nmax_count = 2\n[moves]\ntranslate = 0\nrotate = 1\n"
                                  "step_rotate = 30\n[anneal]\nschedule = constant\nt_start = 0.2\nsweeps = 20000\n"
                                  "seed = 5\n"),
               0);
  cr_assert_eq(sh("%s run %s/db.ini --out %s/db --quiet --threads 1", lw_test_bin(), dir, dir), 0);
  char *js = lw_test_slurp("%s/db/summary.json", dir);
  const char *acc = js ? strstr(js, "\"acceptance\": {") : NULL;
  double death = NAN;
  cr_assert(acc && sscanf(strstr(acc, "\"death\": ") + 9, "%lf", &death) == 1, "%s", js);
  cr_assert(fabs(death - 1.0 / 3.0) < 0.05, "death acceptance %.4f, expected 1/3", death);
  free(js);
}
