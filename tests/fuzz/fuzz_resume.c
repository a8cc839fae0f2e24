/*
** fuzz_resume.c -- fuzz harness for the whole resume path: a run directory
** made of the input (scene.ini, the scene echo a run writes; state.lw, any
** format; trace.csv; replica-1.lw for format-1 tempering runs), resumed by
** lw_anneal_resume and swept once.
**
** Properties beyond "no crash, no leak, no undefined behaviour":
**   - a refused directory gets a message that starts with a file's path;
**   - an accepted one resumes at the state's sweep with finite running
**     energies, and its sweep keeps them finite.
**
** Built with clang -fsanitize=fuzzer by `make fuzz`; `make test` compiles it
** with cc and replays tests/fuzz/corpus/resume through the same function.
*/
#define _GNU_SOURCE /* memmem */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_split.h"
#include "fuzz_util.h"
#include "linewise/anneal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  static const char *const names[] = {"scene.ini", "state.lw", "trace.csv", "replica-1.lw"};
  const char *dir = lw_fuzz_dir();
  if (!dir || !lw_fuzz_split(data, size, dir, names, 4)) return 0;
  static lw_anneal a;
  lw_error err = {LW_OK, ""};
  if (lw_anneal_resume(&a, dir, 1, &err) != LW_OK) {
    /* the file may be outside dir: the scene a state names may be absolute */
    size_t colon = strcspn(err.msg, ":");
    LW_FUZZ_CHECK(memchr(err.msg, '/', colon) != NULL || strstr(err.msg, "out of memory"),
                  "message without a file: '%s'", err.msg);
    lw_anneal_free(&a);
    return 0;
  }
  LW_FUZZ_CHECK(isfinite(lw_anneal_energy(&a)), "resumed with a non-finite energy");
  /* one sweep of a tiny state only: the harness must stay fast */
  if (a.sys_type->sweep_size(a.sys->state) * (size_t)a.n_rep <= 2000 && a.params.checkpoint_every > 1 &&
      lw_anneal_sweep(&a, &err) == LW_OK)
    LW_FUZZ_CHECK(isfinite(lw_anneal_energy(&a)), "a sweep left a non-finite energy");
  lw_anneal_free(&a);
  return 0;
}
