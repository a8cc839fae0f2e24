/*
** fuzz_points.c -- fuzz harness for the particles' point files
** (lw_particles_read_points: the text format and PLY, ascii and binary).
**
** Properties beyond "no crash, no leak, no undefined behaviour":
**   - a rejected file gets a message that names the file, and no points;
**   - accepted points are finite, their normals unit (+z where a point has
**     none), and written back as an ASCII PLY with 17 digits they read back
**     the same: the positions bit for bit, the normals (where every point
**     has one) to rounding.
**
** Built with clang -fsanitize=fuzzer by `make fuzz`; `make test` compiles it
** with cc and replays tests/fuzz/corpus/points through the same function.
*/
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_util.h"
#include "linewise/particles_io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  const char *path = lw_fuzz_file(data, size, 0, ".pts");
  if (!path) return 0;
  size_t n;
  double *x, *nrm;
  unsigned char *has;
  lw_error err = {LW_OK, ""};
  if (lw_particles_read_points(path, &n, &x, &nrm, &has, &err) != LW_OK) {
    LW_FUZZ_CHECK(strstr(err.msg, path) != NULL, "message without the file: '%s'", err.msg);
    LW_FUZZ_CHECK(!x && !nrm && !has && !n, "a rejected file kept points");
    return 0;
  }
  LW_FUZZ_CHECK(n > 0, "accepted no points");
  int all = 1;
  for (size_t i = 0; i < n; i++) {
    const double *p = x + 3 * i, *v = nrm + 3 * i;
    LW_FUZZ_CHECK(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]), "point %zu not finite", i);
    LW_FUZZ_CHECK(fabs(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] - 1) < 1e-12, "normal %zu not unit", i);
    LW_FUZZ_CHECK(has[i] || (v[0] == 0 && v[1] == 0 && v[2] == 1), "point %zu without a normal is not +z", i);
    all &= has[i];
  }
  const char *path2 = lw_fuzz_path(1, ".ply");
  FILE *f = fopen(path2, "w");
  if (f) {
    fprintf(f, "ply\nformat ascii 1.0\nelement vertex %zu\nproperty double x\nproperty double y\nproperty double z\n%s"
               "end_header\n", n, all ? "property double nx\nproperty double ny\nproperty double nz\n" : "");
    for (size_t i = 0; i < n; i++) {
      fprintf(f, "%.17g %.17g %.17g", x[3 * i], x[3 * i + 1], x[3 * i + 2]);
      if (all) fprintf(f, " %.17g %.17g %.17g", nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]);
      fputc('\n', f);
    }
    if (!fclose(f)) {
      size_t n2;
      double *x2, *nrm2;
      unsigned char *has2;
      LW_FUZZ_CHECK(lw_particles_read_points(path2, &n2, &x2, &nrm2, &has2, &err) == LW_OK,
                    "written points do not read back: %s", err.msg);
      LW_FUZZ_CHECK(n2 == n && !memcmp(x2, x, 3 * n * sizeof *x), "positions changed on a write/read cycle");
      /* normals are written only where every point has one (PLY has no
      ** per-vertex absence) */
      for (size_t i = 0; all && i < 3 * n; i++)
        LW_FUZZ_CHECK(fabs(nrm2[i] - nrm[i]) < 1e-15, "normal %zu changed", i / 3);
      for (size_t i = 0; i < n; i++) LW_FUZZ_CHECK(has2[i] == all, "has_normal %zu changed", i);
      free(x2);
      free(nrm2);
      free(has2);
    }
  }
  free(x);
  free(nrm);
  free(has);
  return 0;
}
