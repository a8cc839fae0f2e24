/*
** fuzz_fieldfile.c -- fuzz harness for field files (lw_fieldfile_read: NumPy
** .npy and text).
**
** Properties beyond "no crash, no leak, no undefined behaviour":
**   - a rejected file gets a message that names the file;
**   - an accepted grid has at least one node, at most LW_FIELDFILE_NODES_MAX,
**     two values a node, and written back as text with 17 digits ("nan",
**     "inf" where a value is one) it reads back the same, bit for bit (NaN
**     as NaN);
**   - read as a list of points, an accepted grid has at least one node, at
**     most LW_FIELDFILE_NODES_MAX, positive spacings and a finite origin.
**
** Built with clang -fsanitize=fuzzer by `make fuzz`; `make test` compiles it
** with cc and replays tests/fuzz/corpus/fieldfile through the same function.
*/
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_util.h"
#include "linewise/fieldfile.h"

/* The file as a grid: written back as text, read back the same. */
static void check_grid(const char *path)
{
  lw_error err = {LW_OK, ""};
  lw_grid2d *g = lw_fieldfile_read(path, 2, 0, &err);
  if (!g) {
    LW_FUZZ_CHECK(strstr(err.msg, path) != NULL, "message without the file: '%s'", err.msg);
    return;
  }
  const size_t nodes = (size_t)g->nx * (size_t)g->ny;
  LW_FUZZ_CHECK(g->nx >= 1 && g->ny >= 1 && nodes <= (size_t)LW_FIELDFILE_NODES_MAX && g->ncomp == 2,
                "a grid of %d x %d x %d", g->nx, g->ny, g->ncomp);
  const char *back = lw_fuzz_path(1, ".txt");
  FILE *f = fopen(back, "w");
  if (!f) {
    lw_grid2d_free(g);
    return;
  }
  for (int j = 0; j < g->ny; j++)
    for (int i = 0; i < 2 * g->nx; i++) {
      const double v = g->data[(size_t)j * 2 * (size_t)g->nx + (size_t)i];
      if (isnan(v)) fputs("nan", f);
      else if (isinf(v)) fputs(v < 0 ? "-inf" : "inf", f);
      else fprintf(f, "%.17g", v);
      fputc(i == 2 * g->nx - 1 ? '\n' : ' ', f);
    }
  const int written = !fclose(f);
  lw_grid2d *h = written ? lw_fieldfile_read(back, 2, 0, &err) : NULL;
  if (written) {
    LW_FUZZ_CHECK(h != NULL, "the grid written back is refused: %s", err.msg);
    LW_FUZZ_CHECK(h->nx == g->nx && h->ny == g->ny, "%d x %d read back as %d x %d", g->nx, g->ny, h->nx, h->ny);
    for (size_t k = 0; k < 2 * nodes; k++)
      LW_FUZZ_CHECK((isnan(g->data[k]) && isnan(h->data[k])) || !memcmp(&g->data[k], &h->data[k], sizeof(double)),
                    "value %zu: %.17g read back as %.17g", k, g->data[k], h->data[k]);
  }
  lw_grid2d_free(h);
  lw_grid2d_free(g);
}

/* The file as a list of points. */
static void check_points(const char *path)
{
  lw_error err = {LW_OK, ""};
  lw_grid2d *q = lw_fieldfile_read(path, 2, 1, &err);
  if (!q) {
    LW_FUZZ_CHECK(strstr(err.msg, path) != NULL, "message without the file: '%s'", err.msg);
    return;
  }
  LW_FUZZ_CHECK(q->nx >= 1 && q->ny >= 1 && (size_t)q->nx * (size_t)q->ny <= (size_t)LW_FIELDFILE_NODES_MAX &&
                    q->hx > 0 && q->hy > 0 && isfinite(q->x0) && isfinite(q->y0),
                "points: a grid of %d x %d, spacing %g, %g", q->nx, q->ny, q->hx, q->hy);
  lw_grid2d_free(q);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  const char *path = lw_fuzz_file(data, size, 0, ".npy");
  if (!path) return 0;
  check_grid(path);
  check_points(path);
  return 0;
}
