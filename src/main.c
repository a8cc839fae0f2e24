/*
** main.c -- the linewise command line: prolog (parse, load), the command,
** epilog (report).  Every failure below reaches the user as one line on
** stderr and an exit status: 2 for bad usage or input, 1 for failures while
** running.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/model.h"
#include "linewise/params.h"
#include "linewise/scene.h"
#include "linewise/state.h"

static const char usage[] =
  "usage: linewise <command> [options]\n"
  "\n"
  "commands:\n"
  "  energy DIR          recompute DIR/state.lw's energy from scratch with its scene;\n"
  "                      prints '<term> <value>' per enabled term, then 'total <value>'\n"
  "  params              print every scene parameter as Markdown (docs/PARAMETERS.md)\n"
  "  help                this text\n"
  "\n"
  "exit status: 0 done, 1 failed while running, 2 bad usage or bad input\n";

static int fail(const lw_error *err)
{
  fprintf(stderr, "linewise: %s\n", err->msg);
  return lw_error_exit_status(err->code);
}

/* Loads DIR/state.lw and the scene it names (relative to DIR). */
static lw_status load_run_dir(const char *dir, lw_params *p, lw_scene *sc, lw_state *st, lw_error *err)
{
  char path[LW_PATH_MAX + 32], scene_path[2 * LW_PATH_MAX + 2];
  lw_path_join(path, sizeof path, dir, "state.lw");
  lw_status s = lw_state_read(st, path, err);
  if (s) return s;
  lw_path_join(scene_path, sizeof scene_path, dir, st->scene);
  if ((s = lw_params_read(p, scene_path, err)) || (s = lw_scene_init(sc, p, err))) {
    lw_state_clear(st);
    return s;
  }
  return LW_OK;
}

static int cmd_energy(int argc, char **argv)
{
  lw_error err;
  lw_error_clear(&err);
  if (argc != 1) {
    lw_error_set(&err, LW_EUSAGE, "energy: expected one run directory (usage: linewise energy DIR)");
    return fail(&err);
  }
  static lw_params p;
  lw_scene sc;
  lw_state st;
  if (load_run_dir(argv[0], &p, &sc, &st, &err)) return fail(&err);
  double term[LW_TERM_COUNT];
  double total = lw_energy_compute(&sc, st.sp, term, &err);
  int rc = 0;
  if (err.code) rc = fail(&err);
  else {
    for (int t = 0; t < LW_TERM_COUNT; t++)
      if (sc.on[t]) printf("%s %.17g\n", lw_term_types[t].name, term[t]);
    printf("total %.17g\n", total);
  }
  lw_state_clear(&st);
  lw_scene_clear(&sc);
  return rc;
}

int main(int argc, char **argv)
{
  if (argc < 2 || !strcmp(argv[1], "help") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
    fputs(usage, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  if (!strcmp(argv[1], "energy")) return cmd_energy(argc - 2, argv + 2);
  if (!strcmp(argv[1], "params")) {
    lw_params_write_doc(stdout);
    return 0;
  }
  fprintf(stderr, "linewise: unknown command '%s' (try 'linewise --help')\n", argv[1]);
  return 2;
}
