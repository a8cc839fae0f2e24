/* particles_io.c -- point files and the checkpoint section of the particle system (particles_io.h). */
#include "linewise/particles_io.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/number.h"
#include "linewise/ply.h"
#include "linewise/state.h"

/* The points read so far, grown as they come. */
typedef struct {
  size_t n, cap;
  double *x, *normal;
  unsigned char *has_normal;
} points;

/* Appends a point at v[0..2] with the normal v[3..5] (NULL: none), which
** must have a direction (where names the line or vertex). */
static lw_status append(points *pt, const double *v, const double *nrm, const char *path, const char *where,
                        lw_error *err)
{
  for (int c = 0; c < 3; c++)
    if (!(fabs(v[c]) <= LW_POINTS_COORD_MAX))
      return lw_error_set(err, LW_EINPUT, "%s%s: expected coordinates within +-%g (in r0), got (%g, %g, %g)", path,
                          where, LW_POINTS_COORD_MAX, v[0], v[1], v[2]);
  double len = nrm ? sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]) : 1.0;
  if (!(len > 1e-300) || !isfinite(len))
    return lw_error_set(err, LW_EINPUT, "%s%s: expected a normal nx ny nz with a direction, got length %g", path,
                        where, len);
  if (pt->n == pt->cap) {
    size_t cap = pt->cap ? 2 * pt->cap : 64;
    double *nx = realloc(pt->x, 3 * cap * sizeof *nx), *nn = NULL;
    if (nx) pt->x = nx;
    if (nx && (nn = realloc(pt->normal, 3 * cap * sizeof *nn))) pt->normal = nn;
    unsigned char *nh = nn ? realloc(pt->has_normal, cap) : NULL;
    if (!nh) return lw_error_set(err, LW_ENOMEM, "%s: out of memory for %zu points", path, cap);
    pt->has_normal = nh;
    pt->cap = cap;
  }
  double *xi = pt->x + 3 * pt->n, *ni = pt->normal + 3 * pt->n;
  for (int c = 0; c < 3; c++) {
    xi[c] = v[c];
    ni[c] = nrm ? nrm[c] / len : (c == 2 ? 1.0 : 0.0);
  }
  pt->has_normal[pt->n++] = nrm != NULL;
  return LW_OK;
}

/* The text format: "x y z" or "x y z nx ny nz" a line, blanks or commas
** between the numbers. */
static lw_status read_text(FILE *f, const char *path, points *pt, lw_error *err)
{
  lw_status s = LW_OK;
  char *buf = NULL, where[32];
  size_t bcap = 0;
  long line = 0, len;
  while (!s && (len = lw_text_next_line(f, &buf, &bcap, &line)) >= 0) {
    char *hash = strchr(buf, '#');
    if (hash) *hash = '\0';
    /* CloudCompare's ASCII export heads its columns with "//X,Y,Z,..." */
    if (!strncmp(buf + strspn(buf, " \t"), "//", 2)) continue;
    double v[6];
    int k = lw_number_list(buf, 2, v, 6);
    if (k == 0) continue;
    if (lw_text_empty_field(buf)) {
      s = lw_error_set(err, LW_EINPUT, "%s:%ld: expected a number in every field, got an empty one in '%.80s'", path,
                       line, buf);
      break;
    }
    if (k != 3 && k != 6) {
      char unseen[96]; /* (a minus sign or a no-break space: the file is found, so the key's blame says none) */
      s = k < 0 ? lw_error_set(err, LW_EINPUT,
                               "%s:%ld: expected 'x y z' or 'x y z nx ny nz' (finite numbers), got '%.80s'%s", path,
                               line, buf, k == -2 ? lw_number_list_hint(k) : lw_text_unseen_char(buf, unseen,
                                                                                                   sizeof unseen))
                : lw_error_set(err, LW_EINPUT, "%s:%ld: expected 3 numbers (x y z) or 6 (x y z nx ny nz), got %d",
                               path, line, k);
      break;
    }
    snprintf(where, sizeof where, ":%ld", line);
    s = append(pt, v, k == 6 ? v + 3 : NULL, path, where, err);
  }
  if (!s && len == -2 && errno == ENOMEM)
    s = lw_error_set(err, LW_ENOMEM, "%s:%ld: out of memory reading the line", path, line + 1);
  else if (!s && ferror(f)) s = lw_error_set(err, LW_EIO, "%s: read error", path);
  else if (!s && len == -2) s = lw_error_set(err, LW_EINPUT, "%s:%ld: " LW_TEXT_NUL_LINE, path, line);
  else if (!s && pt->n == 0)
    s = line ? lw_error_set(err, LW_EINPUT, "%s:%ld: expected at least one point 'x y z [nx ny nz]', found none", path,
                            line)
             : lw_error_set(err, LW_EINPUT, "%s: an empty file: expected at least one point 'x y z [nx ny nz]'", path);
  free(buf);
  return s;
}

/* A PLY file's vertices: x, y, z, and nx, ny, nz where it has all three. */
static lw_status read_ply(FILE *f, const char *path, points *pt, lw_error *err)
{
  static const char *const names[6] = {"x", "y", "z", "nx", "ny", "nz"};
  size_t n;
  double *v;
  unsigned found;
  lw_status s = lw_ply_read_vertices(f, path, names, 6, &n, &v, &found, err);
  if (s) return s;
  for (int c = 0; c < 6 && !s; c++)
    if (c < 3 ? !(found >> c & 1) : (found >> 3 & 7) && !(found >> c & 1))
      s = lw_error_set(err, LW_EINPUT, "%s: expected the vertex property '%s' (x, y, z%s), found none", path, names[c],
                       c < 3 ? "; nx, ny, nz if any" : ", and nx, ny, nz all or none");
  char where[48];
  for (size_t i = 0; i < n && !s; i++) {
    snprintf(where, sizeof where, ": vertex %zu", i);
    s = append(pt, v + 6 * i, found >> 3 & 7 ? v + 6 * i + 3 : NULL, path, where, err);
  }
  free(v);
  return s;
}

lw_status lw_particles_read_points(const char *path, size_t *n, double **x, double **normal,
                                   unsigned char **has_normal, lw_error *err)
{
  *n = 0;
  *x = *normal = NULL;
  *has_normal = NULL;
  if (lw_text_plain_file(path, err)) return err->code;
  FILE *f = fopen(path, "rb");
  if (!f) return lw_error_set(err, LW_EINPUT, "%s: cannot open point file: %s", path, strerror(errno));
  points pt = {0};
  lw_status s = lw_ply_detect(f) ? read_ply(f, path, &pt, err) : read_text(f, path, &pt, err);
  fclose(f);
  if (s) {
    free(pt.x);
    free(pt.normal);
    free(pt.has_normal);
    return s;
  }
  *n = pt.n;
  *x = pt.x;
  *normal = pt.normal;
  *has_normal = pt.has_normal;
  return LW_OK;
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
    lw_state_missing_section(c, section, err);
    return NULL;
  }
  long count;
  if (lw_ckpt_whole(c, section, "count", &count, 1, UINT32_MAX / 2, 1, err) ||
      lw_ckpt_single(c, section, "count", err))
    return NULL;
  size_t n = (size_t)count, pos = 0, i = 0, lines = 0;
  const char *key, *val;
  int line = 0;
  /* memory for the particles there are, not for the count the file claims:
  ** a damaged count of 1e8 was said "out of memory" under a batch job's
  ** limit, where the file was cut short */
  while (lw_ckpt_next(c, section, &pos, &key, &val, &line)) lines += !strcmp(key, "particle");
  pos = 0;
  const size_t room = lines < n ? (lines ? lines : 1) : n;
  double *x = malloc(3 * room * sizeof *x), *q = malloc(4 * room * sizeof *q);
  unsigned char *pin = malloc(room);
  lw_particles *p = NULL;
  if (!x || !q || !pin) {
    lw_error_set(err, LW_ENOMEM, "%s: out of memory for %zu particles", path, n);
    goto out;
  }
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
    lw_error_set(err, LW_EINPUT, "%s: [%s]: count = %zu, but %zu particle lines%s", path, section, n, i,
                 lw_ckpt_cut_hint(c, section));
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
