/*
** embed.cpp -- linewise embedded in a C++ program through the headers and
** linewise.pc that `make install` puts in place (tests/test_tools.c builds
** it against an installed copy): a run of a scene file into a directory,
** the files `linewise run` makes.  Usage: embed SCENE.ini DIR
*/
#include <clocale>
#include <cstdio>

#include "linewise/anneal.h"

int main(int argc, char **argv)
{
  if (argc != 3) {
    std::fprintf(stderr, "usage: embed SCENE.ini DIR\n");
    return 2;
  }
  // a program that takes the user's locale keeps LC_NUMERIC at "C" (README)
  std::setlocale(LC_ALL, "");
  std::setlocale(LC_NUMERIC, "C");
  static lw_params p; // tens of kilobytes: not on the stack
  static lw_anneal a;
  lw_error err;
  if (lw_params_read(&p, argv[1], &err) || lw_anneal_start(&a, &p, argv[2], &err)) {
    std::fprintf(stderr, "embed: %s\n", err.msg);
    return 2;
  }
  lw_status s = LW_OK;
  while (!s && !lw_anneal_done(&a)) s = lw_anneal_sweep(&a, &err);
  if (!s) s = lw_anneal_finish(&a, &err);
  if (s) std::fprintf(stderr, "embed: %s\n", err.msg);
  else std::printf("%.17g\n", lw_anneal_energy(&a));
  lw_anneal_free(&a);
  return s ? 1 : 0;
}
