/*
** fuzz_energy.c -- fuzz harness for `linewise energy DIR`: scene.ini and
** state.lw from the input, read, checked and evaluated from scratch as the
** command does (lw_state_read, lw_params_read, lw_scene_init, the
** regularity check, lw_energy_compute, lw_checkpoint_check_finite).
**
** Properties beyond "no crash, no leak, no undefined behaviour":
**   - a refused input gets a message naming its file;
**   - an accepted state has a finite energy per term and in total (the
**     command never prints nan or inf).
**
** Built with clang -fsanitize=fuzzer by `make fuzz`; `make test` compiles it
** with cc and replays tests/fuzz/corpus/energy through the same function.
*/
#define _GNU_SOURCE /* memmem */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_split.h"
#include "fuzz_util.h"
#include "linewise/checkpoint.h"
#include "linewise/model.h"
#include "linewise/state.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  static const char *const names[] = {"scene.ini", "state.lw"};
  const char *dir = lw_fuzz_dir();
  if (!dir || !lw_fuzz_split(data, size, dir, names, 2)) return 0;
  char path[512], scene[512];
  snprintf(path, sizeof path, "%s/state.lw", dir);
  snprintf(scene, sizeof scene, "%s/scene.ini", dir);
  static lw_params p;
  lw_scene sc;
  lw_state st;
  lw_error err = {LW_OK, ""};
  if (lw_state_read(&st, path, &err)) {
    LW_FUZZ_CHECK(strstr(err.msg, path) != NULL, "message without the file: '%s'", err.msg);
    return 0;
  }
  if (!st.sp) { /* a state of another system (no [system splines]): `linewise energy` refuses it by its row */
    lw_state_clear(&st);
    return 0;
  }
  /* the state names its scene; the harness always reads scene.ini */
  if (lw_params_read(&p, scene, &err) || lw_scene_init(&sc, &p, &err)) {
    LW_FUZZ_CHECK(err.msg[0] != '\0', "scene refused without a message");
    lw_state_clear(&st);
    return 0;
  }
  double term[LW_TERM_COUNT];
  if (st.sp->n_nodes <= 20000 && !lw_model_check_regular(&sc, st.sp, path, &err)) {
    double total = lw_energy_compute(&sc, st.sp, term, &err);
    if (!err.code && !lw_checkpoint_check_finite(&sc, st.sp, term, path, &err)) {
      LW_FUZZ_CHECK(isfinite(total), "accepted with total %g", total);
      for (int t = 0; t < LW_TERM_COUNT; t++) LW_FUZZ_CHECK(isfinite(term[t]), "term %d is %g", t, term[t]);
    } else {
      LW_FUZZ_CHECK(strstr(err.msg, path) != NULL || err.code != LW_EINPUT, "message without the file: '%s'",
                    err.msg);
    }
  }
  lw_state_clear(&st);
  lw_scene_clear(&sc);
  return 0;
}
