/*
** fuzz_params.c -- fuzz harness for the INI scene reader: lw_params_read,
** then the scene built from what it accepted (lw_scene_init, which parses
** the polygon and checks the margins).
**
** Properties beyond "no crash, no leak, no undefined behaviour":
**   - a rejected file gets a message that names the file;
**   - an accepted file written back with lw_params_write reads back to the
**     same parameters (the written text is a fixed point).
**
** Built with clang -fsanitize=fuzzer by `make fuzz`; `make test` compiles it
** with cc and replays tests/fuzz/corpus/params through the same function.
*/
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_util.h"
#include "linewise/params.h"
#include "linewise/scene.h"

/* lw_params_write of p as a malloc'ed string. */
static char *params_text(const lw_params *p)
{
  char *buf = NULL;
  size_t n = 0;
  FILE *f = open_memstream(&buf, &n);
  if (!f) return NULL;
  lw_params_write(p, f);
  fclose(f);
  return buf;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  const char *path = lw_fuzz_file(data, size, 0, ".ini");
  if (!path) return 0;
  lw_params p;
  lw_error err = {LW_OK, ""};
  lw_status st = lw_params_read(&p, path, &err);
  if (st != LW_OK) {
    LW_FUZZ_CHECK(strstr(err.msg, path) != NULL, "message without the file: '%s'", err.msg);
    return 0;
  }
  lw_scene sc;
  st = lw_scene_init(&sc, &p, &err);
  if (st != LW_OK) LW_FUZZ_CHECK(err.msg[0] != '\0', "scene rejected without a message");
  lw_scene_clear(&sc);

  /* written back, the parameters read to the same text */
  char *text = params_text(&p);
  LW_FUZZ_CHECK(text != NULL, "cannot write the parameters");
  const char *path2 = lw_fuzz_file((const uint8_t *)text, strlen(text), 1, ".ini");
  if (path2) {
    lw_params q;
    st = lw_params_read(&q, path2, &err);
    LW_FUZZ_CHECK(st == LW_OK, "written parameters do not read back: %s\n%s", err.msg, text);
    char *text2 = params_text(&q);
    LW_FUZZ_CHECK(text2 && !strcmp(text, text2), "parameters changed on a write/read cycle");
    free(text2);
  }
  free(text);
  return 0;
}
