/* particles_io.c -- point files and the checkpoint section of the particle system (particles_io.h). */
#include "linewise/particles_io.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Reads up to max numbers separated by blanks from text into v; returns how
** many, or -1 (with the offending word in bad[n]) if a word is not a finite
** number or there are more than max. */
static int numbers(const char *text, double *v, int max, char *bad, size_t n)
{
  int k = 0;
  const char *c = text;
  for (;;) {
    while (*c == ' ' || *c == '\t' || *c == '\r' || *c == '\n') c++;
    if (!*c) return k;
    const char *w = c;
    while (*c && *c != ' ' && *c != '\t' && *c != '\r' && *c != '\n') c++;
    char word[64];
    size_t len = (size_t)(c - w);
    snprintf(bad, n, "%.*s", (int)(len < 40 ? len : 40), w);
    if (k == max || len >= sizeof word) return -1;
    memcpy(word, w, len);
    word[len] = '\0';
    char *end;
    errno = 0;
    double x = strtod(word, &end);
    if (*end || end == word || errno == ERANGE || !isfinite(x)) return -1;
    v[k++] = x;
  }
}

/* The next line of f into *buf (newline removed), or NULL at the end. */
static char *next_line(FILE *f, char **buf, size_t *cap, int *line)
{
  ssize_t len = getline(buf, cap, f);
  if (len < 0) return NULL;
  (*line)++;
  if (len > 0 && (*buf)[len - 1] == '\n') (*buf)[--len] = '\0';
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
  char *buf = NULL, bad[48];
  size_t bcap = 0, cap = 0;
  int line = 0;
  while (next_line(f, &buf, &bcap, &line)) {
    char *hash = strchr(buf, '#');
    if (hash) *hash = '\0';
    double v[6];
    int k = numbers(buf, v, 6, bad, sizeof bad);
    if (k == 0) continue;
    if (k != 3 && k != 6) {
      s = k < 0 ? lw_error_set(err, LW_EINPUT, "%s:%d: expected 'x y z' or 'x y z nx ny nz' (finite numbers), got '%s'",
                               path, line, bad)
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

/* ---- the checkpoint section ---------------------------------------------
** One body, two carriers: lines of a FILE, or the "particles" lines of an
** lw_state (the run loop's in-memory state.lw).  The body is made and read
** line by line through a sink and a source, so both carriers share one
** format and one reader. */

typedef lw_status (*line_sink)(void *ctx, const char *line);

static lw_status emit(const lw_particles *p, line_sink put, void *ctx, lw_error *err)
{
  char line[512];
  lw_status s;
  snprintf(line, sizeof line, "count = %zu", p->n);
  if ((s = put(ctx, line))) goto fail;
  for (int t = 0; t < LW_PTERM_COUNT; t++) {
    snprintf(line, sizeof line, "energy.%s = %.17g", lw_pterm_names[t], p->term[t]);
    if ((s = put(ctx, line))) goto fail;
  }
  for (size_t i = 0; i < p->n; i++) {
    const double *x = p->x + 3 * i, *q = p->q + 4 * i;
    snprintf(line, sizeof line, "%.17g %.17g %.17g %.17g %.17g %.17g %.17g %d", x[0], x[1], x[2], q[0], q[1], q[2],
             q[3], p->pin[i]);
    if ((s = put(ctx, line))) goto fail;
  }
  return LW_OK;
fail:
  return lw_error_set(err, s, s == LW_ENOMEM ? "out of memory for the particles' section" : "writing the particles failed");
}

static lw_status put_file(void *ctx, const char *line)
{
  return fprintf(ctx, "%s\n", line) < 0 ? LW_EIO : LW_OK;
}

static lw_status put_state(void *ctx, const char *line)
{
  return lw_state_add(ctx, LW_PARTICLES_KEY, line) ? LW_ENOMEM : LW_OK;
}

lw_status lw_particles_save(const lw_particles *p, FILE *f, lw_error *err)
{
  lw_status s = emit(p, put_file, f, err);
  if (!s && ferror(f)) s = lw_error_set(err, LW_EIO, "writing the particles failed");
  return s;
}

lw_status lw_particles_save_state(const lw_particles *p, lw_state *st, lw_error *err)
{
  return emit(p, put_state, st, err);
}

/* The next line of the body and its number (*line), or NULL at its end. */
typedef struct {
  char *(*next)(void *ctx, int *line);
  void *ctx;
} line_source;

typedef struct {
  FILE *f;
  char *buf;
  size_t cap;
} file_source;

static char *next_file(void *ctx, int *line)
{
  file_source *fs = ctx;
  char *text = next_line(fs->f, &fs->buf, &fs->cap, line);
  if (!text) (*line)++; /* the line that is missing */
  return text;
}

typedef struct {
  const lw_state *st;
  size_t i;
} state_source;

static char *next_state(void *ctx, int *line)
{
  state_source *ss = ctx;
  while (ss->i < ss->st->n_extra) {
    const lw_state_extra *e = &ss->st->extra[ss->i++];
    if (strcmp(e->key, LW_PARTICLES_KEY)) continue;
    *line = e->line;
    return e->value;
  }
  (*line)++;
  return NULL;
}

/* Reads "key = value" (one finite number) from the next line into *v. */
static lw_status read_key(line_source *src, const char *path, int *line, const char *key, double *v, lw_error *err)
{
  char *c = src->next(src->ctx, line), bad[48];
  if (!c)
    return lw_error_set(err, LW_EINPUT, "%s:%d: expected '%s = <number>', got the end of the particles", path, *line,
                        key);
  const char *text = c;
  size_t n = strlen(key);
  if (strncmp(c, key, n) || (c[n] != ' ' && c[n] != '='))
    return lw_error_set(err, LW_EINPUT, "%s:%d: expected '%s = <number>', got '%.60s'", path, *line, key, text);
  c += n;
  while (*c == ' ') c++;
  if (*c++ != '=' || numbers(c, v, 1, bad, sizeof bad) != 1)
    return lw_error_set(err, LW_EINPUT, "%s:%d: key '%s': expected one finite number, got '%.60s'", path, *line, key,
                        text);
  return LW_OK;
}

static lw_particles *load(const lw_particles_setup *s, line_source *src, const char *path, int *line, lw_error *err)
{
  char bad[48], key[64];
  double count, energy[LW_PTERM_COUNT];
  int energy_line[LW_PTERM_COUNT];
  double *x = NULL, *q = NULL;
  unsigned char *pin = NULL;
  lw_particles *p = NULL;
  if (read_key(src, path, line, "count", &count, err)) goto out;
  if (count != floor(count) || count < 1 || count > UINT32_MAX / 2) {
    lw_error_set(err, LW_EINPUT, "%s:%d: key 'count': expected a whole number from 1 to %u, got %.17g", path, *line,
                 UINT32_MAX / 2, count);
    goto out;
  }
  for (int t = 0; t < LW_PTERM_COUNT; t++) {
    snprintf(key, sizeof key, "energy.%s", lw_pterm_names[t]);
    if (read_key(src, path, line, key, &energy[t], err)) goto out;
    energy_line[t] = *line;
  }
  size_t n = (size_t)count;
  x = malloc(3 * n * sizeof *x);
  q = malloc(4 * n * sizeof *q);
  pin = malloc(n);
  if (!x || !q || !pin) {
    lw_error_set(err, LW_ENOMEM, "%s: out of memory for %zu particles", path, n);
    goto out;
  }
  for (size_t i = 0; i < n; i++) {
    char *text = src->next(src->ctx, line);
    if (!text) {
      lw_error_set(err, LW_EINPUT, "%s:%d: expected particle %zu of %zu 'x y z qw qx qy qz pin', got the end of the "
                   "particles", path, *line, i + 1, n);
      goto out;
    }
    double v[8];
    int k = numbers(text, v, 8, bad, sizeof bad);
    if (k != 8 || (v[7] != 0 && v[7] != 1 && v[7] != 2 && v[7] != 3)) {
      lw_error_set(err, LW_EINPUT, "%s:%d: expected 'x y z qw qx qy qz pin' (8 finite numbers, pin 0 to 3), got '%.80s'",
                   path, *line, text);
      goto out;
    }
    memcpy(x + 3 * i, v, 3 * sizeof *v);
    memcpy(q + 4 * i, v + 3, 4 * sizeof *v);
    pin[i] = (unsigned char)v[7];
    double nq = sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
    if (!(fabs(nq - 1.0) <= 1e-9)) {
      lw_error_set(err, LW_EINPUT, "%s:%d: expected a unit quaternion qw qx qy qz, got length %.17g", path, *line, nq);
      goto out;
    }
    if (lw_particles_outside(s, v)) {
      lw_error_set(err, LW_EINPUT, "%s:%d: expected a particle inside the boundary, got (%g, %g, %g)", path, *line,
                   v[0], v[1], v[2]);
      goto out;
    }
  }
  lw_error e;
  p = lw_particles_new_from(s, n, x, q, pin, &e);
  if (!p) {
    lw_error_set(err, e.code, "%s:%d: %s", path, *line, e.msg);
    goto out;
  }
  /* The running totals carry on from the saved ones (bit for bit), once
  ** they are shown to belong to these particles. */
  for (int t = 0; t < LW_PTERM_COUNT; t++) {
    if (fabs(energy[t] - p->term[t]) > 1e-6 * fmax(fabs(p->term[t]), 1.0)) {
      lw_error_set(err, LW_EINPUT, "%s:%d: key 'energy.%s' = %.17g does not match the particles (recomputed %.17g)",
                   path, energy_line[t], lw_pterm_names[t], energy[t], p->term[t]);
      lw_particles_free(p);
      p = NULL;
      goto out;
    }
    p->term[t] = energy[t];
  }
out:
  free(x);
  free(q);
  free(pin);
  return p;
}

lw_particles *lw_particles_load(const lw_particles_setup *s, FILE *f, const char *path, int *line, lw_error *err)
{
  file_source fs = {f, NULL, 0};
  line_source src = {next_file, &fs};
  lw_particles *p = load(s, &src, path, line, err);
  free(fs.buf);
  return p;
}

lw_particles *lw_particles_load_state(const lw_particles_setup *s, const lw_state *st, const char *path,
                                      lw_error *err)
{
  state_source ss = {st, 0};
  line_source src = {next_state, &ss};
  int line = 0;
  return load(s, &src, path, &line, err);
}
