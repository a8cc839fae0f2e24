/* particles_io.c -- point files and the checkpoint section of the particle system (particles_io.h). */
#include "linewise/particles_io.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/number.h"

/* The next line of f into *buf (newline removed), or NULL at the end. */
static char *next_line(FILE *f, char **buf, size_t *cap, int *line)
{
  ssize_t len = getline(buf, cap, f);
  if (len < 0) return NULL;
  (*line)++;
  while (len > 0 && ((*buf)[len - 1] == '\n' || (*buf)[len - 1] == '\r')) (*buf)[--len] = '\0';
  return *buf;
}

lw_status lw_particles_read_points(const char *path, size_t *n, double **x, double **normal,
                                   unsigned char **has_normal, lw_error *err)
{
  *n = 0;
  *x = *normal = NULL;
  *has_normal = NULL;
  FILE *f = fopen(path, "r");
  if (!f) return lw_error_set(err, LW_EINPUT, "%s: cannot open point file: %s", path, strerror(errno));
  lw_status s = LW_OK;
  char *buf = NULL;
  size_t bcap = 0, cap = 0;
  int line = 0;
  while (next_line(f, &buf, &bcap, &line)) {
    char *hash = strchr(buf, '#');
    if (hash) *hash = '\0';
    double v[6];
    int k = lw_number_list(buf, 0, v, 6);
    if (k == 0) continue;
    if (k != 3 && k != 6) {
      s = k < 0 ? lw_error_set(err, LW_EINPUT, "%s:%d: expected 'x y z' or 'x y z nx ny nz' (finite numbers), got '%.80s'",
                               path, line, buf)
                : lw_error_set(err, LW_EINPUT, "%s:%d: expected 3 numbers (x y z) or 6 (x y z nx ny nz), got %d",
                               path, line, k);
      goto out;
    }
    double len = k == 6 ? sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5]) : 1.0;
    if (!(len > 1e-300) || !isfinite(len)) {
      s = lw_error_set(err, LW_EINPUT, "%s:%d: expected a normal nx ny nz with a direction, got length %g", path,
                       line, len);
      goto out;
    }
    if (*n == cap) {
      cap = cap ? 2 * cap : 64;
      double *nx = realloc(*x, 3 * cap * sizeof **x), *nn = realloc(*normal, 3 * cap * sizeof **normal);
      if (nx) *x = nx;
      if (nn) *normal = nn;
      unsigned char *nh = realloc(*has_normal, cap);
      if (nh) *has_normal = nh;
      if (!nx || !nn || !nh) {
        s = lw_error_set(err, LW_ENOMEM, "%s: out of memory for %zu points", path, cap);
        goto out;
      }
    }
    double *xi = *x + 3 * *n, *ni = *normal + 3 * *n;
    for (int c = 0; c < 3; c++) {
      xi[c] = v[c];
      ni[c] = k == 6 ? v[3 + c] / len : (c == 2 ? 1.0 : 0.0);
    }
    (*has_normal)[*n] = k == 6;
    (*n)++;
  }
  if (ferror(f)) s = lw_error_set(err, LW_EIO, "%s: read error", path);
  else if (*n == 0) s = lw_error_set(err, LW_EINPUT, "%s:%d: expected at least one point 'x y z [nx ny nz]', found none", path, line);
out:
  free(buf);
  fclose(f);
  if (s) {
    free(*x);
    free(*normal);
    free(*has_normal);
    *x = *normal = NULL;
    *has_normal = NULL;
    *n = 0;
  }
  return s;
}

/* ---- the checkpoint section ------------------------------------------------ */

void lw_particles_put(lw_ckpt_writer *w, const char *section, const lw_particles *p)
{
  lw_ckpt_section(w, section);
  lw_ckpt_put(w, "count", "%zu", p->n);
  for (size_t i = 0; i < p->n; i++) {
    const double *x = p->x + 3 * i, *q = p->q + 4 * i;
    lw_ckpt_put(w, "particle", "%.17g %.17g %.17g %.17g %.17g %.17g %.17g %d", x[0], x[1], x[2], q[0], q[1], q[2],
                q[3], p->pin[i]);
  }
}

lw_particles *lw_particles_get(const lw_particles_setup *s, lw_ckpt *c, const char *section, lw_error *err)
{
  const char *path = lw_ckpt_path(c);
  if (!lw_ckpt_has(c, section)) {
    lw_error_set(err, LW_EINPUT, "%s: section [%s]: missing (a state of another system?)", path, section);
    return NULL;
  }
  long count;
  if (lw_ckpt_whole(c, section, "count", &count, 1, UINT32_MAX / 2, 1, err)) return NULL;
  size_t n = (size_t)count, pos = 0, i = 0;
  double *x = malloc(3 * n * sizeof *x), *q = malloc(4 * n * sizeof *q);
  unsigned char *pin = malloc(n);
  lw_particles *p = NULL;
  if (!x || !q || !pin) {
    lw_error_set(err, LW_ENOMEM, "%s: out of memory for %zu particles", path, n);
    goto out;
  }
  const char *key, *val;
  int line = 0;
  while (lw_ckpt_next(c, section, &pos, &key, &val, &line)) {
    if (!strcmp(key, "count")) continue;
    double v[9];
    int k = strcmp(key, "particle") ? -1 : lw_number_list(val, 0, v, 9);
    if (i == n || k != 8 || (v[7] != 0 && v[7] != 1 && v[7] != 2 && v[7] != 3)) {
      lw_error_set(err, LW_EINPUT, "%s:%d: [%s] %s: expected %s, got '%s = %.80s'", path, line, section,
                   i == n ? "after the last particle" : "particle",
                   i == n ? "nothing (count is the number of particles)"
                          : "'particle = x y z qw qx qy qz pin' (8 numbers, pin 0 to 3)",
                   key, val);
      goto out;
    }
    double nq = sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
    if (!(fabs(nq - 1.0) <= 1e-9)) {
      lw_error_set(err, LW_EINPUT, "%s:%d: [%s] particle: expected a unit quaternion qw qx qy qz, got length %.17g",
                   path, line, section, nq);
      goto out;
    }
    if (lw_particles_outside(s, v)) {
      lw_error_set(err, LW_EINPUT, "%s:%d: [%s] particle: expected a position inside the boundary, got (%g, %g, %g)",
                   path, line, section, v[0], v[1], v[2]);
      goto out;
    }
    memcpy(x + 3 * i, v, 3 * sizeof *v);
    memcpy(q + 4 * i, v + 3, 4 * sizeof *v);
    pin[i++] = (unsigned char)v[7];
  }
  if (i < n) {
    lw_error_set(err, LW_EINPUT, "%s: [%s]: count = %zu, but %zu particle lines", path, section, n, i);
    goto out;
  }
  lw_error e;
  p = lw_particles_new_from(s, n, x, q, pin, &e);
  if (!p) lw_error_set(err, e.code, "%s: [%s]: %s", path, section, e.msg);
out:
  free(x);
  free(q);
  free(pin);
  return p;
}
