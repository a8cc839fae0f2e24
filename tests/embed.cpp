/*
** embed.cpp -- linewise embedded in a C++ program through the headers and
** linewise.pc that `make install` puts in place (tests/test_tools.c builds
** it against an installed copy): a run of a scene file into a directory,
** or a resume of one for N more sweeps (N < 0: to its end), making the
** files `linewise run` and `linewise resume --sweeps N` make.
** Usage: embed SCENE.ini DIR | embed --resume DIR N
*/
#include <clocale>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <gsl/gsl_errno.h>

#include "linewise/anneal.h"
#include "linewise/memlimit.h"
#include "linewise/version.h"

int main(int argc, char **argv)
{
  const bool resume = argc == 4 && !std::strcmp(argv[1], "--resume");
  if (argc != 3 && !resume) {
    // (which library, and the memory it sees: two headers that lacked
    // extern "C", so a C++ host could not link these calls)
    const char *by = "";
    std::fprintf(stderr, "usage: embed SCENE.ini DIR | embed --resume DIR N (linewise %s, build %s; %g bytes, %s)\n",
                 LW_VERSION, lw_version_build(), lw_memory_limit(&by), by);
    return 2;
  }
  // a program that takes the user's locale keeps LC_NUMERIC at "C" (README)
  std::setlocale(LC_ALL, "");
  std::setlocale(LC_NUMERIC, "C");
  gsl_set_error_handler(lw_gsl_handler); // "out of memory", not GSL's abort (README)
  static lw_params p; // tens of kilobytes: not on the stack
  static lw_anneal a;
  lw_error err;
  lw_status s = resume ? lw_anneal_resume(&a, argv[2], std::atol(argv[3]), &err)
                       : lw_params_read(&p, argv[1], &err) ? err.code : lw_anneal_start(&a, &p, argv[2], &err);
  if (s) {
    std::fprintf(stderr, "embed: %s\n", err.msg);
    return 2;
  }
  // to the end, or to a resume's N sweeps short of it, where it stops as
  // at --stop-at: a checkpoint, no final files
  while (!s && !lw_anneal_done(&a) && !lw_anneal_paused(&a)) s = lw_anneal_sweep(&a, &err);
  if (!s) s = lw_anneal_done(&a) ? lw_anneal_finish(&a, &err) : lw_anneal_checkpoint(&a, &err);
  if (s) std::fprintf(stderr, "embed: %s\n", err.msg);
  else std::printf("sweep %ld: %.17g\n", a.sweep, lw_anneal_energy(&a));
  lw_anneal_free(&a);
  return s ? 1 : 0;
}
