/*
** state.c -- reading and writing state.lw (state.h, docs/FORMATS.md).
**
** Layout: a header of "key value" lines, then one block per spline:
**     linewise-state 1
**     scene scene.ini
**     seed 42
**     sweep 1000
**     <key> <value...>             (run data, any number of lines)
**     splines 2
**     spline <segments> <rest length L0, mm>
**     <px> <py> <vx> <vy>          (segments + 1 node lines)
**     ...
**     end
** Blank lines and lines starting with '#' are ignored.
*/
#include "linewise/state.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

void lw_path_join(char *buf, size_t n, const char *dir, const char *name)
{
  if (name[0] == '/' || !dir[0] || !strcmp(dir, ".")) snprintf(buf, n, "%s", name);
  else snprintf(buf, n, "%s/%s", dir, name);
}

void lw_path_dir(char *buf, size_t n, const char *path)
{
  const char *slash = strrchr(path, '/');
  if (!slash) snprintf(buf, n, ".");
  else if (slash == path) snprintf(buf, n, "/");
  else snprintf(buf, n, "%.*s", (int)(slash - path), path);
}

void lw_state_clear(lw_state *st)
{
  lw_splines_free(st->sp);
  st->sp = NULL;
  for (size_t i = 0; i < st->n_extra; i++) {
    free(st->extra[i].key);
    free(st->extra[i].value);
  }
  free(st->extra);
  st->extra = NULL;
  st->n_extra = 0;
}

static lw_status add_line(lw_state *st, const char *key, size_t nkey, const char *value, int line)
{
  lw_state_extra *e = realloc(st->extra, (st->n_extra + 1) * sizeof *e);
  if (!e) return LW_ENOMEM;
  st->extra = e;
  e = &st->extra[st->n_extra];
  e->key = malloc(nkey + 1);
  e->value = strdup(value);
  if (!e->key || !e->value) {
    free(e->key);
    free(e->value);
    return LW_ENOMEM;
  }
  memcpy(e->key, key, nkey);
  e->key[nkey] = '\0';
  e->line = line;
  st->n_extra++;
  return LW_OK;
}

lw_status lw_state_add(lw_state *st, const char *key, const char *value)
{
  return add_line(st, key, strlen(key), value, 0);
}

const lw_state_extra *lw_state_get(const lw_state *st, const char *key)
{
  for (size_t i = 0; i < st->n_extra; i++)
    if (!strcmp(st->extra[i].key, key)) return &st->extra[i];
  return NULL;
}

typedef struct {
  FILE *f;
  const char *path;
  int line;
  char *buf;    /* getline's buffer: run data lines (the RNG state) are long */
  size_t cap;
} reader;

/* Next line that is not blank or a comment, without its newline; NULL at end. */
static char *next_line(reader *r)
{
  while (getline(&r->buf, &r->cap, r->f) >= 0) {
    r->line++;
    r->buf[strcspn(r->buf, "\r\n")] = '\0';
    char *c = r->buf;
    while (*c == ' ' || *c == '\t') c++;
    if (*c && *c != '#') return c;
  }
  return NULL;
}

static lw_status bad(reader *r, lw_error *err, const char *key, const char *expected, const char *got)
{
  return lw_error_set(err, LW_EINPUT, "%s:%d: %s: expected %s, got '%s'", r->path, r->line, key,
                      expected, got ? got : "end of file");
}

/* Reads a line "key <value>" with the given key; value points into r->buf. */
static lw_status expect_key(reader *r, const char *key, char **value, lw_error *err)
{
  char *c = next_line(r);
  size_t n = strlen(key);
  if (!c || strncmp(c, key, n) || (c[n] != ' ' && c[n] != '\t'))
    return bad(r, err, key, "a line starting with that key", c);
  c += n;
  while (*c == ' ' || *c == '\t') c++;
  *value = c;
  return LW_OK;
}

static int parse_long(const char *s, long *out)
{
  char *end;
  errno = 0;
  long v = strtol(s, &end, 10);
  while (*end == ' ' || *end == '\t') end++;
  if (end == s || *end || errno) return 0;
  *out = v;
  return 1;
}

/* Reads exactly n finite doubles from s. */
static int parse_doubles(const char *s, double *out, int n)
{
  char *end;
  for (int i = 0; i < n; i++) {
    errno = 0;
    out[i] = strtod(s, &end);
    if (end == s || errno == ERANGE || !isfinite(out[i])) return 0;
    s = end;
  }
  while (*s == ' ' || *s == '\t') s++;
  return *s == '\0';
}

lw_status lw_state_read(lw_state *st, const char *path, lw_error *err)
{
  memset(st, 0, sizeof *st);
  reader r = {fopen(path, "r"), path, 0, NULL, 0};
  if (!r.f) return lw_error_set(err, LW_EINPUT, "%s: cannot open state file: %s", path, strerror(errno));
  lw_status status = LW_OK;
  size_t *segs = NULL;
  double *rest = NULL;
  long v;
  char *val;
  char *c = next_line(&r);
  if (!c || strncmp(c, "linewise-state ", 15) || !parse_long(c + 15, &v)) {
    status = bad(&r, err, "header", "'linewise-state <version>'", c);
    goto done;
  }
  if (v != LW_STATE_VERSION) {
    status = lw_error_set(err, LW_EINPUT, "%s:%d: header: version %ld is not supported (expected %d)",
                          path, r.line, v, LW_STATE_VERSION);
    goto done;
  }
  if ((status = expect_key(&r, "scene", &val, err))) goto done;
  if (!*val || strlen(val) >= sizeof st->scene) {
    status = bad(&r, err, "scene", "a file name", val);
    goto done;
  }
  strcpy(st->scene, val);
  if ((status = expect_key(&r, "seed", &val, err))) goto done;
  if (!parse_long(val, &v) || v < 0) {
    status = bad(&r, err, "seed", "a whole number >= 0", val);
    goto done;
  }
  st->seed = (unsigned long)v;
  if ((status = expect_key(&r, "sweep", &val, err))) goto done;
  if (!parse_long(val, &st->sweep) || st->sweep < 0) {
    status = bad(&r, err, "sweep", "a whole number >= 0", val);
    goto done;
  }
  /* run data lines until "splines" */
  for (;;) {
    c = next_line(&r);
    if (!c) {
      status = bad(&r, err, "splines", "a line 'splines <count>'", c);
      goto done;
    }
    size_t nk = strcspn(c, " \t");
    if (nk == 7 && !strncmp(c, "splines", 7)) break;
    val = c + nk;
    while (*val == ' ' || *val == '\t') val++;
    if (add_line(st, c, nk, val, r.line)) {
      status = lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
      goto done;
    }
  }
  val = c + 7;
  while (*val == ' ' || *val == '\t') val++;
  if (!parse_long(val, &v) || v < 0 || v > 100000000L) {
    status = bad(&r, err, "splines", "a whole number from 0 to 100000000", val);
    goto done;
  }
  size_t ns = (size_t)v;
  segs = malloc((ns ? ns : 1) * sizeof *segs);
  rest = malloc((ns ? ns : 1) * sizeof *rest);
  /* Nodes are read into a growing buffer first: the segment counts are only
  ** known spline by spline. */
  size_t cap = 1024, nn = 0;
  lw_node *nodes = malloc(cap * sizeof *nodes);
  if (!segs || !rest || !nodes) {
    free(nodes);
    status = lw_error_set(err, LW_ENOMEM, "%s: out of memory for %zu splines", path, ns);
    goto done;
  }
  for (size_t i = 0; i < ns && !status; i++) {
    if ((status = expect_key(&r, "spline", &val, err))) break;
    double h[2];
    if (!parse_doubles(val, h, 2) || h[0] < 1 || h[0] > 1e6 || h[0] != floor(h[0]) || !(h[1] > 0)) {
      status = bad(&r, err, "spline", "'<segments >= 1> <rest length > 0>'", val);
      break;
    }
    segs[i] = (size_t)h[0];
    rest[i] = h[1];
    for (size_t k = 0; k <= segs[i]; k++) {
      c = next_line(&r);
      double q[4];
      if (!c || !parse_doubles(c, q, 4)) {
        status = bad(&r, err, "node", "4 finite numbers 'px py vx vy'", c);
        break;
      }
      if (nn == cap) {
        lw_node *nb = realloc(nodes, 2 * cap * sizeof *nodes);
        if (!nb) {
          status = lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
          break;
        }
        nodes = nb;
        cap *= 2;
      }
      nodes[nn++] = (lw_node){q[0], q[1], q[2], q[3]};
    }
  }
  if (!status) {
    c = next_line(&r);
    if (!c || strcmp(c, "end")) status = bad(&r, err, "end", "'end' after the last spline", c);
    else if ((c = next_line(&r))) status = bad(&r, err, "end", "nothing after 'end'", c);
  }
  if (!status) {
    st->sp = lw_splines_new(ns, segs, err);
    if (!st->sp) status = err ? err->code : LW_ENOMEM;
    else {
      memcpy(st->sp->node, nodes, nn * sizeof *nodes);
      memcpy(st->sp->rest_length, rest, ns * sizeof *rest);
    }
  }
  free(nodes);
  if (!status && ferror(r.f)) status = lw_error_set(err, LW_EIO, "%s: read error", path);
done:
  free(segs);
  free(rest);
  free(r.buf);
  fclose(r.f);
  if (status) lw_state_clear(st);
  return status;
}

lw_status lw_state_write(const lw_state *st, const char *path, lw_error *err)
{
  char tmp[LW_PATH_MAX + 16];
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  FILE *f = fopen(tmp, "w");
  if (!f) return lw_error_set(err, LW_EIO, "%s: cannot write: %s", tmp, strerror(errno));
  const lw_splines *sp = st->sp;
  fprintf(f, "linewise-state %d\nscene %s\nseed %lu\nsweep %ld\n", LW_STATE_VERSION, st->scene,
          st->seed, st->sweep);
  for (size_t i = 0; i < st->n_extra; i++) fprintf(f, "%s %s\n", st->extra[i].key, st->extra[i].value);
  fprintf(f, "splines %zu\n", sp->n_splines);
  for (size_t i = 0; i < sp->n_splines; i++) {
    fprintf(f, "spline %zu %.17g\n", lw_splines_segments(sp, i), sp->rest_length[i]);
    for (size_t k = sp->first[i]; k < sp->first[i + 1]; k++) {
      const lw_node *nd = &sp->node[k];
      fprintf(f, "%.17g %.17g %.17g %.17g\n", nd->px, nd->py, nd->vx, nd->vy);
    }
  }
  fprintf(f, "end\n");
  int bad_write = ferror(f);
  if (fflush(f) || fsync(fileno(f))) bad_write = 1;
  if (fclose(f)) bad_write = 1;
  if (bad_write) {
    remove(tmp);
    return lw_error_set(err, LW_EIO, "%s: write failed", tmp);
  }
  if (rename(tmp, path)) {
    int e = errno;
    remove(tmp);
    return lw_error_set(err, LW_EIO, "%s: cannot replace: %s", path, strerror(e));
  }
  return LW_OK;
}
