/*
** fuzz_state.c -- fuzz harness for the state.lw reader (lw_state_read).
**
** Properties beyond "no crash, no leak, no undefined behaviour":
**   - a rejected file gets a message that names the file, and no splines;
**   - an accepted state (format 1 or 2) has finite nodes and positive rest
**     lengths, and lw_state_write then lw_state_read gives its header and
**     splines back bit for bit (in format 2).
**
** Built with clang -fsanitize=fuzzer by `make fuzz`; `make test` compiles it
** with cc and replays tests/fuzz/corpus/state through the same function.
*/
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_util.h"
#include "linewise/state.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  const char *path = lw_fuzz_file(data, size, 0, ".lw");
  if (!path) return 0;
  lw_state st;
  lw_error err = {LW_OK, ""};
  if (lw_state_read(&st, path, &err) != LW_OK) {
    LW_FUZZ_CHECK(strstr(err.msg, path) != NULL, "message without the file: '%s'", err.msg);
    LW_FUZZ_CHECK(st.sp == NULL && st.doc == NULL, "a rejected state kept data");
    return 0;
  }
  if (!st.sp) { /* a state of another system: its row reads its section (linewise refuses it for splines) */
    lw_state_clear(&st);
    return 0;
  }
  const lw_splines *sp = st.sp;
  LW_FUZZ_CHECK(lw_splines_finite(sp), "accepted a non-finite node");
  for (size_t i = 0; i < sp->n_splines; i++)
    LW_FUZZ_CHECK(sp->rest_length[i] > 0 && isfinite(sp->rest_length[i]), "rest length %g", sp->rest_length[i]);

  const char *path2 = lw_fuzz_path(1, ".lw");
  if (lw_state_write(&st, path2, &err) == LW_OK) {
    lw_state back;
    LW_FUZZ_CHECK(lw_state_read(&back, path2, &err) == LW_OK, "written state does not read back: %s", err.msg);
    LW_FUZZ_CHECK(!strcmp(back.scene, st.scene) && back.seed == st.seed && back.sweep == st.sweep,
                  "header changed on a write/read cycle");
    LW_FUZZ_CHECK(back.sp->n_splines == sp->n_splines && back.sp->n_nodes == sp->n_nodes, "shape changed");
    LW_FUZZ_CHECK(!memcmp(back.sp->node, sp->node, sp->n_nodes * sizeof *sp->node), "nodes changed");
    LW_FUZZ_CHECK(!memcmp(back.sp->rest_length, sp->rest_length, sp->n_splines * sizeof(double)),
                  "rest lengths changed");
    for (size_t i = 0; i <= sp->n_splines; i++) LW_FUZZ_CHECK(back.sp->first[i] == sp->first[i], "offsets changed");
    lw_state_clear(&back);
  }
  lw_state_clear(&st);
  return 0;
}
