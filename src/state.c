/*
** state.c -- reading and writing state.lw (state.h, docs/FORMATS.md).
**
** Format 2 (sections and keys, ckpt.h):
**     linewise-state 2
**     [run]
**     scene = scene.ini
**     seed = 42
**     sweep = 1000
**     ...                          (run data of a checkpoint, anneal.c)
**     [system splines]
**     splines = 2
**     spline = <segments> <rest length L0, mm> [<layer>]
**     node = <px> <py> <vx> <vy>   (segments + 1 lines per spline)
** (the layer on every spline or on none: splines born in layers, layers.h)
**
** Format 1 (the first release; still read, never written):
**     linewise-state 1
**     scene scene.ini
**     seed 42
**     sweep 1000
**     <key> <value...>             (run data, any number of lines)
**     splines 2
**     spline <segments> <rest length L0, mm>
**     <px> <py> <vx> <vy>          (segments + 1 node lines)
**     end
*/
#include "linewise/state.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/number.h"

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
  lw_ckpt_free(st->doc);
  st->doc = NULL;
}

/* ---- splines: shared checks ------------------------------------------------ */

/* A spline header "segments rest-length [layer]" (*layer = -1 without
** one; format 1 never has one); 1 if good. */
static int spline_header(const char *text, size_t *segs, double *rest, int *layer)
{
  double h[3];
  int n = lw_number_list(text, 0, h, 3);
  if ((n != 2 && !(n == 3 && layer)) || h[0] < 1 || h[0] > 1e6 || h[0] != floor(h[0]) || !(h[1] > 0)) return 0;
  if (n == 3 && !(h[2] >= 0 && h[2] <= 255 && h[2] == floor(h[2]))) return 0;
  *segs = (size_t)h[0];
  *rest = h[1];
  if (layer) *layer = n == 3 ? (int)h[2] : -1;
  return 1;
}

/* A node "px py vx vy", every coordinate within LW_STATE_COORD_MAX. */
static int node_values(const char *text, lw_node *nd)
{
  double q[4];
  if (lw_number_list(text, 0, q, 4) != 4) return 0;
  for (int i = 0; i < 4; i++)
    if (!(fabs(q[i]) <= LW_STATE_COORD_MAX)) return 0;
  *nd = (lw_node){q[0], q[1], q[2], q[3]};
  return 1;
}

/* Collects splines one by one (the segment counts are only known as they
** come) and builds the lw_splines at the end.  The arrays grow with the
** splines read, not with the count the file claims: a damaged count of 1e8
** took 2 GB first, and under a memory limit was said "out of memory"
** where the file was cut short. */
typedef struct {
  size_t ns, *segs;
  double *rest;
  int *layer;             /* -1: none (every spline alike) */
  size_t scap;            /* splines the three arrays above hold */
  lw_node *nodes;
  size_t nn, cap;
} collect;

static int collect_init(collect *c, size_t ns)
{
  *c = (collect){.ns = ns, .scap = ns < 1024 ? (ns ? ns : 1) : 1024, .cap = 1024};
  c->segs = malloc(c->scap * sizeof *c->segs);
  c->rest = malloc(c->scap * sizeof *c->rest);
  c->layer = malloc(c->scap * sizeof *c->layer);
  c->nodes = malloc(c->cap * sizeof *c->nodes);
  if (c->layer && !ns) c->layer[0] = -1;
  return c->segs && c->rest && c->layer && c->nodes;
}

/* Room for spline i (i < c->ns); 1 if there is. */
static int collect_room(collect *c, size_t i)
{
  if (i < c->scap) return 1;
  size_t grown = 2 * c->scap < c->ns ? 2 * c->scap : c->ns;
  size_t *s = realloc(c->segs, grown * sizeof *s);
  if (s) c->segs = s;
  double *r = s ? realloc(c->rest, grown * sizeof *r) : NULL;
  if (r) c->rest = r;
  int *l = r ? realloc(c->layer, grown * sizeof *l) : NULL;
  if (!l) return 0;
  c->layer = l;
  c->scap = grown;
  return 1;
}

static int collect_node(collect *c, lw_node nd)
{
  if (c->nn == c->cap) {
    lw_node *nb = realloc(c->nodes, 2 * c->cap * sizeof *nb);
    if (!nb) return 0;
    c->nodes = nb;
    c->cap *= 2;
  }
  c->nodes[c->nn++] = nd;
  return 1;
}

static lw_splines *collect_done(collect *c, lw_error *err)
{
  lw_splines *sp = lw_splines_new(c->ns, c->segs, err);
  if (sp) {
    memcpy(sp->node, c->nodes, c->nn * sizeof *c->nodes);
    memcpy(sp->rest_length, c->rest, c->ns * sizeof *c->rest);
    if (c->ns && c->layer[0] >= 0) {
      if (lw_splines_layers_alloc(sp) != LW_OK) {
        lw_splines_free(sp);
        lw_error_set(err, LW_ENOMEM, "out of memory for %zu splines", c->ns);
        return NULL;
      }
      for (size_t i = 0; i < c->ns; i++) sp->layer[i] = (uint8_t)c->layer[i];
    }
  }
  return sp;
}

static void collect_free(collect *c)
{
  free(c->segs);
  free(c->rest);
  free(c->layer);
  free(c->nodes);
}

static const char node_expected[] = "4 numbers 'px py vx vy', each within +-1e9 mm";

/* ---- format 2 ------------------------------------------------------------- */

void lw_state_put_header(lw_ckpt_writer *w, const lw_state *st)
{
  lw_ckpt_section(w, "run");
  lw_ckpt_put(w, "scene", "%s", st->scene);
  lw_ckpt_put(w, "seed", "%lu", st->seed);
  lw_ckpt_put(w, "sweep", "%ld", st->sweep);
}

void lw_state_put_splines(lw_ckpt_writer *w, const char *section, const lw_splines *sp)
{
  lw_ckpt_section(w, section);
  lw_ckpt_put(w, "splines", "%zu", sp->n_splines);
  for (size_t i = 0; i < sp->n_splines; i++) {
    if (sp->layer)
      lw_ckpt_put(w, "spline", "%zu %.17g %d", lw_splines_segments(sp, i), sp->rest_length[i], sp->layer[i]);
    else
      lw_ckpt_put(w, "spline", "%zu %.17g", lw_splines_segments(sp, i), sp->rest_length[i]);
    for (size_t k = sp->first[i]; k < sp->first[i + 1]; k++) {
      const lw_node *nd = &sp->node[k];
      lw_ckpt_put(w, "node", "%.17g %.17g %.17g %.17g", nd->px, nd->py, nd->vx, nd->vy);
    }
  }
}

lw_status lw_state_get_splines(lw_ckpt *c, const char *section, lw_splines **out, lw_error *err)
{
  *out = NULL;
  const char *path = lw_ckpt_path(c), *key, *val;
  int line = 0;
  size_t pos = 0;
  if (!lw_ckpt_has(c, section)) return lw_state_missing_section(c, section, err);
#define BAD(what, got)                                                                                     \
  lw_error_set(err, LW_EINPUT, "%s:%d: [%s] %s: expected %s, got '%.60s'", path, line, section, key ? key : "", \
               what, got)
  key = NULL;
  if (!lw_ckpt_next(c, section, &pos, &key, &val, &line))
    return lw_error_set(err, LW_EINPUT, "%s: [%s]: expected 'splines = <count>' first, got the end of the section%s",
                        path, section, lw_ckpt_cut_hint(c, section));
  if (strcmp(key, "splines")) return BAD("'splines = <count>' first", key);
  long long ns;
  if (!lw_number_parse_whole(val, 0, 1e8, &ns)) return BAD("a whole number from 0 to 100000000", val);
  const int count_line = line;
  char got[96]; /* the line read, key and value: a count that disagrees with the lines showed only a value */
  collect col;
  if (!collect_init(&col, (size_t)ns)) {
    collect_free(&col);
    return lw_error_set(err, LW_ENOMEM, "%s: out of memory for %lld splines", path, ns);
  }
  lw_status s = LW_OK;
  for (size_t i = 0; i < (size_t)ns && !s; i++) {
    key = NULL;
    int more = lw_ckpt_next(c, section, &pos, &key, &val, &line);
    if (!more) {
      s = lw_error_set(err, LW_EINPUT, "%s:%d: [%s] splines: %lld, but the section ends after %zu of them%s",
                       path, count_line, section, ns, i, lw_ckpt_cut_hint(c, section));
      break;
    }
    if (!collect_room(&col, i)) {
      s = lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
      break;
    }
    if (strcmp(key, "spline") || !spline_header(val, &col.segs[i], &col.rest[i], &col.layer[i])) {
      snprintf(got, sizeof got, "%s = %s", key, val);
      s = BAD("'spline = <segments >= 1> <rest length > 0> [<layer 0 to 255>]'", got);
      break;
    }
    if (i > 0 && (col.layer[i] < 0) != (col.layer[0] < 0)) {
      s = BAD(col.layer[0] < 0 ? "no layer, as the first spline" : "a layer, as the first spline has", val);
      break;
    }
    for (size_t k = 0; k <= col.segs[i] && !s; k++) {
      lw_node nd;
      more = lw_ckpt_next(c, section, &pos, &key, &val, &line);
      if (more) snprintf(got, sizeof got, "'%.24s = %.60s'", key, val);
      else snprintf(got, sizeof got, "the end of the section");
      if (!more || strcmp(key, "node") || !node_values(val, &nd))
        s = lw_error_set(err, LW_EINPUT,
                         "%s:%d: [%s] spline %zu node %zu: expected 'node = ' and %s, got %s%s (its %zu segments have "
                         "%zu nodes)", path, line, section, i, k, node_expected, got,
                         more ? "" : lw_ckpt_cut_hint(c, section), col.segs[i], col.segs[i] + 1);
      else if (!collect_node(&col, nd))
        s = lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
    }
  }
  if (!s && lw_ckpt_next(c, section, &pos, &key, &val, &line)) s = BAD("nothing after the last spline's nodes", key);
#undef BAD
  if (!s && !(*out = collect_done(&col, err))) s = err ? err->code : LW_ENOMEM;
  collect_free(&col);
  return s;
}

lw_status lw_state_missing_section(const lw_ckpt *c, const char *section, lw_error *err)
{
  char what[128];
  snprintf(what, sizeof what, "section [%s]", section);
  return lw_ckpt_missing(c, what, "a state of another system", err);
}

static lw_status read_v2(lw_state *st, lw_ckpt *c, lw_error *err)
{
  const char *path = lw_ckpt_path(c);
  int line = 0;
  const char *scene = lw_ckpt_text(c, "run", "scene", &line);
  if (!scene) return lw_ckpt_missing(c, "[run] scene", "not a state of a run", err);
  if (!*scene || strlen(scene) >= sizeof st->scene)
    return lw_error_set(err, LW_EINPUT, "%s:%d: [run] scene: expected a file name, got '%.60s'", path, line, scene);
  strcpy(st->scene, scene);
  long seed;
  lw_status s;
  if ((s = lw_ckpt_whole(c, "run", "seed", &seed, 0, (long)LW_SEED_MAX, 1, err)) ||
      (s = lw_ckpt_whole(c, "run", "sweep", &st->sweep, 0, (long)LW_STATE_SWEEP_MAX, 1, err)))
    return s;
  st->seed = (unsigned long)seed;
  /* a state of another system has its own section instead (read by its row) */
  if (!lw_ckpt_has(c, "system splines")) return LW_OK;
  return lw_state_get_splines(c, "system splines", &st->sp, err);
}

/* ---- format 1 ------------------------------------------------------------- */

typedef struct {
  FILE *f;
  const char *path;
  int line;
  char *buf;    /* getline's buffer: run data lines (the RNG state) are long */
  size_t cap;
  int nul;      /* the last line held a NUL byte */
  int oom;      /* a line could not be held: out of memory, not the end */
} reader;

/* Next line that is not blank or a comment, without its newline; NULL at
** the end or at a line with a NUL byte (r->nul). */
static char *next_line(reader *r)
{
  ssize_t len;
  while ((len = lw_text_getline(&r->buf, &r->cap, r->f)) >= 0) {
    r->line++;
    if (memchr(r->buf, '\0', (size_t)len)) {
      r->nul = 1;
      return NULL;
    }
    if (r->line == 1) lw_text_drop_bom(r->buf);
    /* trailing blanks go, as format 2 trims them: a value reads the same in both */
    size_t n = strcspn(r->buf, "\r\n");
    while (n > 0 && (r->buf[n - 1] == ' ' || r->buf[n - 1] == '\t')) n--;
    r->buf[n] = '\0';
    char *c = r->buf;
    while (*c == ' ' || *c == '\t') c++;
    if (*c && *c != '#') return c;
  }
  r->oom = len == -2;
  return NULL;
}

/* Whether a line holds a control byte but tab and CR. */
static int has_control(const char *c)
{
  for (const unsigned char *u = (const unsigned char *)c; *u; u++)
    if ((*u < 0x20 && *u != '\t' && *u != '\r') || *u == 0x7F) return 1;
  return 0;
}

/* Whether a line reads as text: no control byte, and valid UTF-8 where a
** byte is not ASCII (a picture's bytes were printed raw). */
static int text_like(const char *c)
{
  if (has_control(c)) return 0;
  for (const unsigned char *u = (const unsigned char *)c; *u; u++) {
    if (*u < 0x80) continue;
    int more = *u >= 0xF0 && *u < 0xF5 ? 3 : *u >= 0xE0 && *u < 0xF0 ? 2 : *u >= 0xC2 && *u < 0xE0 ? 1 : -1;
    if (more < 0) return 0;
    for (; more > 0; more--)
      if ((*++u & 0xC0) != 0x80) return 0;
  }
  return 1;
}

static lw_status bad(reader *r, lw_error *err, const char *key, const char *expected, const char *got)
{
  if (r->oom) return lw_error_set(err, LW_ENOMEM, "%s:%d: out of memory reading the next line", r->path, r->line);
  return lw_error_set(err, LW_EINPUT, "%s:%d: %s: expected %s, got '%.60s'", r->path, r->line, key, expected,
                      r->nul ? "a NUL byte" : got ? got : "end of file");
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

static lw_status read_v1(lw_state *st, reader *r, lw_error *err)
{
  const char *path = r->path;
  long long v;
  char *val, *c;
  lw_status s;
  if ((s = expect_key(r, "scene", &val, err))) return s;
  if (!*val || strlen(val) >= sizeof st->scene) return bad(r, err, "scene", "a file name", val);
  strcpy(st->scene, val);
  if ((s = expect_key(r, "seed", &val, err))) return s;
  if (!lw_number_parse_whole(val, 0, LW_SEED_MAX, &v))
    return bad(r, err, "seed", "a whole number from 0 to 2^32 - 1", val);
  st->seed = (unsigned long)v;
  if ((s = expect_key(r, "sweep", &val, err))) return s;
  if (!lw_number_parse_whole(val, 0, LW_STATE_SWEEP_MAX, &v)) return bad(r, err, "sweep", "a whole number from 0 to 1e15", val);
  st->sweep = (long)v;
  /* run data lines until "splines", kept as section [v1] */
  if (!(st->doc = lw_ckpt_new(path))) return lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
  for (;;) {
    if (!(c = next_line(r))) return bad(r, err, "splines", "a line 'splines <count>'", c);
    size_t nk = strcspn(c, " \t");
    if (nk == 7 && !strncmp(c, "splines", 7)) break;
    val = c + nk + strspn(c + nk, " \t");
    c[nk] = '\0';
    if (lw_ckpt_add(st->doc, "v1", c, val, r->line)) return lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
  }
  val = c + 7 + strspn(c + 7, " \t");
  if (!lw_number_parse_whole(val, 0, 1e8, &v)) return bad(r, err, "splines", "a whole number from 0 to 100000000", val);
  collect col;
  if (!collect_init(&col, (size_t)v)) {
    collect_free(&col);
    return lw_error_set(err, LW_ENOMEM, "%s: out of memory for %lld splines", path, v);
  }
  for (size_t i = 0; i < col.ns && !s; i++) {
    if ((s = expect_key(r, "spline", &val, err))) break;
    if (!collect_room(&col, i)) {
      s = lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
      break;
    }
    col.layer[i] = -1;
    if (!spline_header(val, &col.segs[i], &col.rest[i], NULL)) {
      s = bad(r, err, "spline", "'<segments >= 1> <rest length > 0>'", val);
      break;
    }
    for (size_t k = 0; k <= col.segs[i] && !s; k++) {
      c = next_line(r);
      lw_node nd;
      if (!c || !node_values(c, &nd)) {
        char key[64];
        snprintf(key, sizeof key, "spline %zu node %zu", i, k);
        s = bad(r, err, key, node_expected, c);
      } else if (!collect_node(&col, nd))
        s = lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
    }
  }
  if (!s) {
    c = next_line(r);
    if (!c || strcmp(c, "end")) s = bad(r, err, "end", "'end' after the last spline", c);
    else if ((c = next_line(r)) || r->nul) s = bad(r, err, "end", "nothing after 'end'", c);
  }
  if (!s && !(st->sp = collect_done(&col, err))) s = err ? err->code : LW_ENOMEM;
  collect_free(&col);
  return s;
}

/* ---- reading and writing ---------------------------------------------------- */

lw_status lw_state_read(lw_state *st, const char *path, lw_error *err)
{
  memset(st, 0, sizeof *st);
  if (lw_text_plain_file(path, err)) return err->code;
  reader r = {fopen(path, "r"), path, 0, NULL, 0, 0, 0};
  if (!r.f) return lw_error_set(err, LW_EINPUT, "%s: cannot open state file: %s", path, strerror(errno));
  lw_status s = LW_OK;
  errno = 0;
  char *c = next_line(&r);
  long long version = 0;
  if (!c && r.oom)
    s = lw_error_set(err, LW_ENOMEM, "%s: out of memory reading its first line", path);
  else if (!c && ferror(r.f)) /* a directory opens but does not read */
    s = lw_error_set(err, LW_EINPUT, "%s: cannot read state file: %s", path, strerror(errno ? errno : EIO));
  else if (!c && !r.nul && r.line == 0) /* (line 0 of an empty file meant nothing to its reader) */
    s = lw_error_set(err, LW_EINPUT, "%s: empty file (0 bytes), not a state: expected 'linewise-state <version>'",
                     path);
  else if ((c && strncmp(c, LW_STATE_MAGIC, strlen(LW_STATE_MAGIC)) && !text_like(c)) || (!c && r.nul))
    s = lw_error_set(err, LW_EINPUT, "%s:1: header: expected 'linewise-state <version>', got %s", path,
                     c && !strncmp(c, "\x89PNG", 4) ? "binary bytes (a PNG picture, not a state)"
                     : r.nul || has_control(c)     ? "binary bytes (not a state, which is text)"
                                                   : "bytes that are not UTF-8 text (a state is text)");
  else if (!c || strncmp(c, LW_STATE_MAGIC, strlen(LW_STATE_MAGIC)) ||
           !lw_number_parse_whole(c + strlen(LW_STATE_MAGIC), 0, 1e9, &version))
    s = bad(&r, err, "header", "'linewise-state <version>'", c);
  else if (version != 1 && version != LW_STATE_VERSION)
    s = lw_error_set(err, LW_EINPUT, "%s:%d: header: version %lld is not supported (expected 1 or %d)", path, r.line,
                     version, LW_STATE_VERSION);
  else if (version == 1) {
    st->version = 1;
    s = read_v1(st, &r, err);
    if (!s && ferror(r.f)) s = lw_error_set(err, LW_EIO, "%s: read error", path);
  }
  free(r.buf);
  fclose(r.f);
  if (!s && version == LW_STATE_VERSION) {
    st->version = LW_STATE_VERSION;
    if (!(s = lw_ckpt_read(&st->doc, path, err))) s = read_v2(st, st->doc, err);
  }
  if (s) lw_state_clear(st);
  return s;
}

lw_status lw_state_write(const lw_state *st, const char *path, lw_error *err)
{
  lw_ckpt_writer w;
  lw_status s = lw_ckpt_begin(&w, path, LW_STATE_HEADER, err);
  if (s) return s;
  lw_state_put_header(&w, st);
  lw_state_put_splines(&w, "system splines", st->sp);
  return lw_ckpt_commit(&w, err);
}

lw_status lw_state_scene_beside(const lw_state *st, const char *path, lw_error *err)
{
  if (!strchr(st->scene, '/') && strcmp(st->scene, ".") && strcmp(st->scene, "..")) return LW_OK;
  return lw_error_set(err, LW_EINPUT, "%s: [run] scene: expected the name of a file beside the state (no '/'), got "
                      "'%.60s'", path, st->scene);
}
