/*
** test_domains.c -- sweeps split into domains (domains.h): the same result
** for any thread count, with tempering too; bit-exact resume; running
** totals equal to the energy from scratch; bad values of the key refused.
** The statistical tests with domains on are in test_stats.c.
*/
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/anneal.h"
#include "linewise/domains.h"
#include "linewise/sys_splines.h"
#include "testutil.h"

#define sh lw_test_sh

/* Every kind of term a split must respect: segment terms, spline terms,
** the pair term with its spacing constraint (grid cells), the tone raster
** (footprints); 300 mm split 3 x 3 (100 mm domains, reach about 8 mm). */
static void write_scene(const char *dir, const char *extra)
{
  char path[128];
  snprintf(path, sizeof path, "%s/s.ini", dir);
  FILE *f = fopen(path, "w");
  cr_assert_not_null(f);
  fprintf(f,
          "[scene]\nwidth = 300\nheight = 300\nmargin = 5\nimage = %s/params/picture.png\nimage_width = 120\n"
          "potential = radial\nfield = waves\n"
          "[init]\nsplines = 400\nsegments = 3\nsegment_length = 4\n"
          "[energy]\nstrain = 10\nbending = 1\npotential = 0.3\nfield = -0.3\npair = 0.01\npair_cutoff = 2\n"
          "min_spacing = 0.2\ntone = 0.5\ntone_blur = 1\nboundary = 0.1\n"
          "[anneal]\nschedule = geometric\nt_start = 0.3\nt_end = 0.01\nsweeps = 30\nsteps = 3\n"
          "check_every = 7\ndomains = 3\n%s",
          lw_test_root(), extra);
  fclose(f);
}

static int same(const char *dir, const char *a, const char *b, const char *file)
{
  return sh("cmp -s %s/%s/%s %s/%s/%s", dir, a, file, dir, b, file) == 0;
}

/* Runs the scene (with `extra`) on 1, 2 and 4 threads into t1, t2, t4 and
** checks that they wrote the same files. */
static void same_on_1_2_4_threads(const char *dir, const char *extra)
{
  write_scene(dir, extra);
  const char *b = lw_test_bin();
  for (int t = 1; t <= 4; t *= 2)
    cr_assert_eq(sh("%s run %s/s.ini --out %s/t%d --threads %d --quiet", b, dir, dir, t, t), 0);
  const char *files[] = {"state.lw", "trace.csv", "final.svg"};
  for (int i = 0; i < 3; i++) {
    cr_assert(same(dir, "t1", "t2", files[i]), "%s differs between 1 and 2 threads", files[i]);
    cr_assert(same(dir, "t1", "t4", files[i]), "%s differs between 1 and 4 threads", files[i]);
  }
}

Test(domains, same_result_on_1_2_and_4_threads_and_not_the_unsplit_one)
{
  char dir[64];
  cr_assert_eq(lw_test_dir_make(dir, "domains"), 0);
  same_on_1_2_4_threads(dir, "");
  cr_assert_eq(sh("%s run %s/s.ini --out %s/off --set anneal.domains=off --quiet", lw_test_bin(), dir, dir), 0);
  /* the key is read: a split run is another chain */
  cr_assert(!same(dir, "t1", "off", "state.lw"), "domains = 3 changed nothing");
  lw_test_dir_remove(dir);
}

/* Threads go to the replicas first, then to each one's domains. */
Test(domains, tempering_replicas_then_domains_same_on_any_threads)
{
  char dir[64];
  cr_assert_eq(lw_test_dir_make(dir, "domains_pt"), 0);
  same_on_1_2_4_threads(dir, "[tempering]\nreplicas = 2\nt_min = 0.01\nt_max = 0.1\n");
  lw_test_dir_remove(dir);
}

Test(domains, resume_continues_bit_exactly)
{
  char dir[64];
  cr_assert_eq(lw_test_dir_make(dir, "domains_resume"), 0);
  write_scene(dir, "");
  const char *b = lw_test_bin();
  cr_assert_eq(sh("%s run %s/s.ini --out %s/a --threads 2 --quiet", b, dir, dir), 0);
  /* stopped mid-tuning and between drift checks, resumed on other thread counts */
  cr_assert_eq(sh("%s run %s/s.ini --out %s/b --threads 1 --quiet --stop-at 4", b, dir, dir), 0);
  cr_assert_eq(sh("%s resume %s/b --threads 2 --quiet --stop-at 17", b, dir), 0);
  cr_assert_eq(sh("%s resume %s/b --threads 4 --quiet", b, dir), 0);
  const char *files[] = {"state.lw", "trace.csv", "final.svg"};
  for (int i = 0; i < 3; i++) cr_assert(same(dir, "a", "b", files[i]), "%s differs after resume", files[i]);
  lw_test_dir_remove(dir);
}

/* Trans-dimensional moves with domains (docs/NUMERICS.md, "Trans-dimensional
** moves with domains"): births, deaths, grows and shrinks by the dozen
** (warm, chemical potential against the tone and pair terms); their
** ghosts are filled and compacted between the domains' phases. */
static const char *td_extra = "[moves]\nfixed_count = 0\nmax_segments = 6\nbirth = 0.05\ndeath = 0.05\n"
                              "grow = 0.05\nshrink = 0.05\n";
/* ... and splits and joins, which run in the same serial block; a split
** pays the first-node density of its new piece on a large page, so a
** chemical potential per spline gets some accepted */
static const char *sj_extra = "[moves]\nfixed_count = 0\nmax_segments = 6\nbirth = 0.05\ndeath = 0.05\n"
                              "grow = 0.05\nshrink = 0.05\nsplit = 0.1\njoin = 0.1\n"
                              "[energy]\nchem_spline = -1\n";

/* The same bytes on 1 and 3 threads (two tempering replicas), and after a
** run stopped twice and resumed on other thread counts.  Catches a domain
** sweep that skips the compaction of the sweep's ghosts (sweep_end): the
** run then fails, its domains grouping ghosts as splines. */
static void td_same_on_threads_and_resume(const char *moves)
{
  char dir[64], extra[512];
  cr_assert_eq(lw_test_dir_make(dir, "domains_td"), 0);
  /* two replicas: threads go to the rungs first, then to each one's domains */
  snprintf(extra, sizeof extra, "%s[tempering]\nreplicas = 2\nt_min = 0.01\nt_max = 0.1\n", moves);
  write_scene(dir, extra);
  const char *b = lw_test_bin();
  cr_assert_eq(sh("%s run %s/s.ini --out %s/t1 --threads 1 --quiet", b, dir, dir), 0);
  cr_assert_eq(sh("%s run %s/s.ini --out %s/t3 --threads 3 --quiet", b, dir, dir), 0);
  cr_assert_eq(sh("%s run %s/s.ini --out %s/r --threads 2 --quiet --stop-at 9", b, dir, dir), 0);
  cr_assert_eq(sh("%s resume %s/r --threads 1 --quiet --stop-at 20", b, dir), 0);
  cr_assert_eq(sh("%s resume %s/r --threads 3 --quiet", b, dir), 0);
  const char *files[] = {"state.lw", "trace.csv", "final.svg"};
  for (int i = 0; i < 3; i++) {
    cr_assert(same(dir, "t1", "t3", files[i]), "%s differs between 1 and 3 threads", files[i]);
    cr_assert(same(dir, "t1", "r", files[i]), "%s differs after resume", files[i]);
  }
  /* the moves happened: the count changed */
  cr_assert_neq(sh("grep -q '\"splines\": 400,' %s/t1/summary.json", dir), 0, "the count never changed");
  lw_test_dir_remove(dir);
}

Test(domains, trans_dimensional_same_on_1_and_3_threads_and_resume, .timeout = 300)
{
  td_same_on_threads_and_resume(td_extra);
}

Test(domains, split_and_join_same_on_1_and_3_threads_and_resume, .timeout = 300)
{
  td_same_on_threads_and_resume(sj_extra);
}

/* Regression for the split commits: the running totals are merged from the
** domains' own sums, and must still equal the energy from scratch; with
** trans-dimensional moves (td = 1) also after the splices between the
** phases and the compactions (a sweep without its compaction leaves a
** total that is not finite). */
static void running_totals_are_full(const char *name, int td)
{
  char dir[64];
  cr_assert_eq(lw_test_dir_make(dir, name), 0);
  write_scene(dir, td == 2 ? sj_extra : td ? td_extra : "");
  lw_params p;
  lw_error err;
  char path[128];
  snprintf(path, sizeof path, "%s/s.ini", dir);
  cr_assert_eq(lw_params_read(&p, path, &err), LW_OK, "%s", err.msg);
  p.check_every = 1000000; /* no refresh between: the totals run on their own */
  /* long: about 10^6 proposals; joins are rare here (about 1 in 1700
  ** proposed are accepted), so the split/join scene runs longer to see
  ** enough of them */
  p.sweeps = lw_test_long() ? 600 : td == 2 ? 120 : 40;
  lw_anneal a;
  snprintf(path, sizeof path, "%s/run", dir);
  cr_assert_eq(lw_anneal_start(&a, &p, path, &err), LW_OK, "%s", err.msg);
  cr_assert_not_null(a.chain->domains, "domains = 3 did not split");
  unsigned long accepted = 0;
  while (!lw_anneal_done(&a)) cr_assert_eq(lw_anneal_sweep(&a, &err), LW_OK, "%s", err.msg);
  for (int k = 0; k < LW_MOVE_KINDS; k++) accepted += a.chain->stats[k].accepted;
  const lw_model *m = lw_splines_model(a.sys);
  cr_assert_gt(accepted, 10 * m->sp->n_nodes, "too few moves to test: %lu", accepted);
  /* births and deaths (td = 1), or splits and joins (td = 2), happened */
  const int k0 = td == 2 ? LW_MOVE_SPLIT : LW_MOVE_KINDS, k1 = td == 2 ? LW_MOVE_KINDS_TDJ : LW_MOVE_KINDS_TD;
  for (int k = k0; td && k < k1; k++)
    cr_assert_gt(a.chain->stats[k].accepted, td == 2 ? 5 : 20, "%s accepted %lu of %lu times",
                 a.chain->sys->type->move_names[k], a.chain->stats[k].accepted, a.chain->stats[k].proposed);
  double term[LW_TERM_COUNT];
  double full = lw_energy_compute(m->scene, m->sp, term, &err);
  double run = lw_model_total(m);
  cr_assert(isfinite(full), "%s", err.msg);
  for (int t = 0; t < LW_TERM_COUNT; t++)
    cr_assert(fabs(m->term[t] - term[t]) <= 1e-9 * fmax(fabs(full), 1.0), "term %s: running %.17g, scratch %.17g",
              lw_term_names[t], m->term[t], term[t]);
  cr_assert(fabs(run - full) <= 1e-9 * fmax(fabs(full), 1.0), "running %.17g, scratch %.17g", run, full);
  /* commits in cells that ran at once kept the pair slots current */
  lw_test_pair_slots_hold_current(m);
  /* and the split left some splines unmoved each sweep, but not most */
  const lw_domains *d = a.chain->domains;
  /* (grown splines, up to 6 segments, lie across a boundary more often: 28 %
  ** of the visits over the long run's 600 sweeps) */
  cr_assert(d->frozen < d->visits / (td ? 3 : 4), "%lu of %lu site visits frozen", d->frozen, d->visits);
  lw_anneal_free(&a);
  lw_test_dir_remove(dir);
}

Test(domains, running_totals_equal_the_energy_from_scratch) { running_totals_are_full("domains_inc", 0); }

Test(domains, running_totals_equal_the_energy_from_scratch_with_births_and_deaths)
{
  running_totals_are_full("domains_inc_td", 1);
}

Test(domains, running_totals_equal_the_energy_from_scratch_with_splits_and_joins)
{
  running_totals_are_full("domains_inc_sj", 2);
}

/* One clear message naming the key, exit status 2, nothing written: the
** scene s.ini in dir, or `scene` when not NULL. */
static void refused(const char *dir, const char *scene, const char *value, const char *expect)
{
  char path[160];
  if (!scene) {
    write_scene(dir, "");
    snprintf(path, sizeof path, "%s/s.ini", dir);
  } else {
    snprintf(path, sizeof path, "%s/%s", lw_test_root(), scene);
  }
  int st = sh("%s run %s --out %s/bad --set anneal.domains=%s --quiet 2> %s/err.txt", lw_test_bin(), path, dir,
              value, dir);
  cr_assert_eq(st, 2, "domains = %s: exit status %d", value, st);
  cr_assert_eq(sh("grep -q \"key 'anneal.domains'\" %s/err.txt", dir), 0, "domains = %s: key not named", value);
  cr_assert_eq(sh("grep -q -- '%s' %s/err.txt", expect, dir), 0, "domains = %s: expected '%s'", value, expect);
  cr_assert_neq(sh("test -e %s/bad/state.lw", dir), 0, "domains = %s: a state was written", value);
}

Test(domains, bad_values_are_refused_naming_the_key)
{
  char dir[64];
  cr_assert_eq(lw_test_dir_make(dir, "domains_bad"), 0);
  refused(dir, NULL, "banana", "expected off, auto or a count");
  refused(dir, NULL, "0", "expected off, auto or a count");
  refused(dir, NULL, "3x", "expected off, auto or a count");
  /* 300 mm in 40 domains is 7.5 mm, under twice the reach of the pair grid and tone */
  refused(dir, NULL, "40", "wider than twice the reach");
  /* domains narrower than the splines (32 mm in 33 mm): 7 % would move a sweep */
  refused(dir, "params/minimal.ini --set init.splines=60", "3", "leave most of the state unmoved");
  /* a system whose row cannot split (the NURBS curve under Monte Carlo):
  ** refused, not run serially behind the user's back */
  refused(dir, "params/wire.ini --set scene.driver=metropolis", "2", "the nurbs system reads it under no driver");
  lw_test_dir_remove(dir);
}

/* auto splits only where domains can be wide against a spline: not the
** small scene, but a page 16 x 16 splines' arc wide at least twice over. */
Test(domains, auto_splits_large_pages_only)
{
  lw_params p;
  lw_params_defaults(&p);
  strcpy(p.domains, "auto");
  p.splines = 50;
  lw_anneal a;
  lw_error err;
  char dir[64];
  cr_assert_eq(lw_test_dir_make(dir, "domains_auto"), 0);
  char path[128];
  snprintf(path, sizeof path, "%s/small", dir);
  cr_assert_eq(lw_anneal_start(&a, &p, path, &err), LW_OK, "%s", err.msg);
  cr_assert_null(a.chain->domains, "a 210 x 297 page of 40 mm splines was split");
  lw_anneal_free(&a);
  p.width = p.height = 2000; /* 16 x 4 x 10 mm = 640 mm: 3 domains a side */
  snprintf(path, sizeof path, "%s/large", dir);
  cr_assert_eq(lw_anneal_start(&a, &p, path, &err), LW_OK, "%s", err.msg);
  cr_assert_not_null(a.chain->domains, "a 2 m page was not split");
  cr_assert_eq(a.chain->domains->nx, 3);
  lw_anneal_free(&a);
  lw_test_dir_remove(dir);
}

/* A proposal refused for leaving its domain saw no Metropolis test: it is
** counted as such (summary.json's rejected_outside), and tuning leaves it
** out.  With no energy every test accepts, so the steps grow to their caps
** as they do unsplit (counted as rejections, a 160 mm page at 4 domains
** held the point step at 15 mm). */
Test(domains, refusals_at_a_domain_border_are_counted_apart_and_not_tuned_on)
{
  char dir[64], path[128];
  cr_assert_eq(lw_test_dir_make(dir, "domains_outside"), 0);
  cr_assert_eq(lw_test_write_text(dir, "s.ini",
                                  "[scene]\nwidth = 160\nheight = 160\nmargin = 5\n"
                                  "[init]\nsplines = 200\nsegments = 3\nsegment_length = 4\n"
                                  "[energy]\nstrain = 0\nbending = 0\nboundary = 0\nmin_speed = 0\nregularity = 0\n"
                                  "[anneal]\nschedule = constant\nt_start = 1\nsweeps = 40\nseed = 7\ndomains = 4\n"
                                  "[moves]\ntune_sweeps = 20\n"),
               0);
  lw_params p;
  lw_error err;
  snprintf(path, sizeof path, "%s/s.ini", dir);
  cr_assert_eq(lw_params_read(&p, path, &err), LW_OK, "%s", err.msg);
  lw_anneal a;
  snprintf(path, sizeof path, "%s/run", dir);
  cr_assert_eq(lw_anneal_start(&a, &p, path, &err), LW_OK, "%s", err.msg);
  cr_assert_not_null(a.chain->domains);
  while (!lw_anneal_done(&a)) cr_assert_eq(lw_anneal_sweep(&a, &err), LW_OK, "%s", err.msg);
  const lw_chain *c = a.chain;
  unsigned long outside = 0;
  for (int k = 0; k < c->n_moves; k++) {
    const lw_move_stats *s = &c->stats[k];
    cr_assert_eq(s->accepted + s->outside, s->proposed, "%s: %lu accepted, %lu outside, %lu proposed",
                 c->sys->type->move_names[k], s->accepted, s->outside, s->proposed);
    outside += s->outside;
  }
  cr_assert_gt(outside, 1000, "only %lu proposals left their domain", outside);
  cr_assert_eq(c->step[LW_MOVE_POINT], c->step_max[LW_MOVE_POINT], "point step %g, cap %g", c->step[LW_MOVE_POINT],
               c->step_max[LW_MOVE_POINT]);
  /* and summary.json says so */
  const unsigned long point = c->stats[LW_MOVE_POINT].outside;
  cr_assert_eq(lw_anneal_finish(&a, &err), LW_OK, "%s", err.msg);
  lw_anneal_free(&a);
  cr_assert_eq(sh("grep -A1 '\"rejected_outside\"' %s/run/summary.json | grep -q '\"point\": %lu,'", dir, point), 0);
  /* free of every energy the splines stretch to domains' width: the share
  ** of them a sweep can move is judged at the start, not again at a resume
  ** (which refused the run it had accepted) */
  const char *b = lw_test_bin();
  cr_assert_eq(sh("%s run %s/s.ini --out %s/a --quiet --stop-at 20 && %s resume %s/a --quiet && "
                  "%s run %s/s.ini --out %s/b --quiet && cmp -s %s/a/state.lw %s/b/state.lw",
                  b, dir, dir, b, dir, b, dir, dir, dir, dir),
               0);
  lw_test_dir_remove(dir);
}
