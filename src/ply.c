/* ply.c -- the vertices of a PLY file (ply.h). */
#include "linewise/ply.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "linewise/number.h"

/* Header limits: properties an element, elements a file, and the length of
** a list (a face's corners) worth believing. */
#define PROPS_MAX 64
#define ELEMS_MAX 16
#define LIST_MAX 1000000

typedef enum { T_NONE, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 } ptype;

static const struct {
  const char *name;
  ptype type;
} type_names[] = {{"char", T_I8},    {"int8", T_I8},     {"uchar", T_U8},   {"uint8", T_U8},   {"short", T_I16},
                  {"int16", T_I16},  {"ushort", T_U16},  {"uint16", T_U16}, {"int", T_I32},    {"int32", T_I32},
                  {"uint", T_U32},   {"uint32", T_U32},  {"float", T_F32},  {"float32", T_F32}, {"double", T_F64},
                  {"float64", T_F64}};

static const int type_size[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};

typedef struct {
  ptype type;  /* a scalar's type, or a list's items' */
  ptype count; /* a list's count type; T_NONE for a scalar */
  int want;    /* the index among the names asked for, or -1 */
} prop;

typedef struct {
  char name[32];
  size_t count;
  int n_props;
  prop props[PROPS_MAX];
} elem;

enum { ASCII, LITTLE, BIG };

typedef struct {
  FILE *f;
  const char *path;
  int format;
  long line;
  char *buf;
  size_t cap;
  lw_error *err;
  int oom; /* a line could not be held: not the end of the file, which the messages would say */
  int nul; /* a NUL byte in a header or ASCII line (read as its end: "got ''") */
} reader;

/* The next line into r->buf without its line end, or NULL at the end. */
static char *next_line(reader *r)
{
  ssize_t len = lw_text_getline(&r->buf, &r->cap, r->f);
  r->oom = len == -2;
  if (len < 0) return NULL;
  if (memchr(r->buf, '\0', (size_t)len)) {
    r->nul = 1;
    r->line++;
    return NULL;
  }
  if (++r->line == 1) {
    lw_text_drop_bom(r->buf);
    len = (ssize_t)strlen(r->buf);
  }
  while (len > 0 && (r->buf[len - 1] == '\n' || r->buf[len - 1] == '\r')) r->buf[--len] = '\0';
  return r->buf;
}

static ptype type_of(const char *s)
{
  for (size_t k = 0; k < sizeof type_names / sizeof *type_names; k++)
    if (s && !strcmp(s, type_names[k].name)) return type_names[k].type;
  return T_NONE;
}

int lw_ply_detect(FILE *f)
{
  /* "ply" in any case and blanks after it are a PLY file still, refused by
  ** its header's reader with a PLY message (a trailing blank was read as a
  ** text point file: "expected 'x y z' ..., got 'ply '") */
  char head[256] = {0};
  size_t got = fread(head, 1, sizeof head - 1, f);
  rewind(f);
  const size_t b = got >= 3 && !memcmp(head, "\xEF\xBB\xBF", 3) ? 3 : 0; /* a byte-order mark (number.h) */
  if (got < b + 4 || strncasecmp(head + b, "ply", 3)) return 0;
  const char *end = head + b + 3 + strspn(head + b + 3, " \t");
  return *end == '\n' || (end[0] == '\r' && end[1] == '\n');
}

/* Why the next line did not come where it was not the file's end: out of
** memory, or a read error (the messages of a malformed or short file would
** blame it); else LW_OK. */
static lw_status not_read(const reader *r)
{
  if (r->oom) return lw_error_set(r->err, LW_ENOMEM, "%s:%ld: out of memory reading the line", r->path, r->line + 1);
  if (r->nul) return lw_error_set(r->err, LW_EINPUT, "%s:%ld: " LW_TEXT_NUL_LINE, r->path, r->line);
  if (ferror(r->f)) return lw_error_set(r->err, LW_EIO, "%s:%ld: read error", r->path, r->line + 1);
  return LW_OK;
}

static lw_status bad_line(reader *r, const char *expected, const char *got)
{
  if (r->oom || r->nul || ferror(r->f)) return not_read(r);
  return lw_error_set(r->err, LW_EINPUT, "%s:%ld: expected %s, got '%.60s'", r->path, r->line, expected, got);
}

/* The header, up to end_header: the format and the elements. */
static lw_status read_header(reader *r, const char *const *names, int n_names, elem *el, int *n_el)
{
  char *s = next_line(r);
  for (size_t n = s ? strlen(s) : 0; n && (s[n - 1] == ' ' || s[n - 1] == '\t');) s[--n] = '\0'; /* as after words */
  if (!s || strcmp(s, "ply")) return bad_line(r, "the PLY magic line 'ply'", s ? s : "");
  if (!(s = next_line(r))) return bad_line(r, "'format ascii 1.0' (or binary_little_endian, binary_big_endian)", "");
  char *save, *w = strtok_r(s, " \t", &save), *kind = strtok_r(NULL, " \t", &save),
              *ver = strtok_r(NULL, " \t", &save), *more = strtok_r(NULL, " \t", &save);
  if (!w || strcmp(w, "format") || !kind || !ver || strcmp(ver, "1.0") || more)
    return bad_line(r, "'format ascii 1.0' (or binary_little_endian, binary_big_endian)", w ? w : "");
  if (!strcmp(kind, "ascii")) r->format = ASCII;
  else if (!strcmp(kind, "binary_little_endian")) r->format = LITTLE;
  else if (!strcmp(kind, "binary_big_endian")) r->format = BIG;
  else return bad_line(r, "the format ascii, binary_little_endian or binary_big_endian", kind);
  *n_el = 0;
  while ((s = next_line(r))) {
    w = strtok_r(s, " \t", &save);
    if (!w || !strcmp(w, "comment") || !strcmp(w, "obj_info")) continue;
    if (!strcmp(w, "end_header")) {
      /* an instance without properties takes no bytes: a count of them
      ** would be read for nothing (and, in the billions, for ever) */
      for (int k = 0; k < *n_el; k++)
        if (el[k].count && !el[k].n_props)
          return lw_error_set(r->err, LW_EINPUT, "%s:%ld: expected properties for the element '%s', found none",
                              r->path, r->line, el[k].name);
      return LW_OK;
    }
    if (!strcmp(w, "element")) {
      char *name = strtok_r(NULL, " \t", &save), *count = strtok_r(NULL, " \t", &save);
      long long c;
      if (!name || strlen(name) >= sizeof el->name || !count || strtok_r(NULL, " \t", &save) ||
          !lw_number_parse_whole(count, 0, 1e15, &c))
        return bad_line(r, "'element NAME COUNT' (a name under 32 characters, a whole count)", name ? name : "");
      if (*n_el == ELEMS_MAX)
        return lw_error_set(r->err, LW_EINPUT, "%s:%ld: expected at most %d elements", r->path, r->line, ELEMS_MAX);
      if (!strcmp(name, "vertex") && c > LW_PLY_VERTICES_MAX)
        return lw_error_set(r->err, LW_EINPUT, "%s:%ld: expected at most %d vertices, got %lld", r->path, r->line,
                            LW_PLY_VERTICES_MAX, c);
      elem *e = el + (*n_el)++;
      strcpy(e->name, name);
      e->count = (size_t)c;
      e->n_props = 0;
      continue;
    }
    if (!strcmp(w, "property")) {
      if (!*n_el) return bad_line(r, "an element before its properties", w);
      elem *e = el + *n_el - 1;
      if (e->n_props == PROPS_MAX)
        return lw_error_set(r->err, LW_EINPUT, "%s:%ld: expected at most %d properties an element", r->path, r->line,
                            PROPS_MAX);
      prop *p = e->props + e->n_props++;
      char *t = strtok_r(NULL, " \t", &save), *name;
      p->count = T_NONE;
      if (t && !strcmp(t, "list")) {
        char *ct = strtok_r(NULL, " \t", &save);
        p->count = type_of(ct);
        if (p->count == T_NONE || p->count == T_F32 || p->count == T_F64)
          return bad_line(r, "a list's count type (an integer type such as uchar or int)", ct ? ct : "");
        t = strtok_r(NULL, " \t", &save);
      }
      p->type = type_of(t);
      if (p->type == T_NONE)
        return bad_line(r, "a property type (char, uchar, short, ushort, int, uint, float, double or int8 ... float64)",
                        t ? t : "");
      if (!(name = strtok_r(NULL, " \t", &save)) || strtok_r(NULL, " \t", &save))
        return bad_line(r, "'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'", name ? name : "");
      p->want = -1;
      if (!strcmp(e->name, "vertex") && p->count == T_NONE)
        for (int k = 0; k < n_names; k++)
          if (!strcmp(name, names[k])) p->want = k;
      continue;
    }
    return bad_line(r, "a header line (comment, element, property or end_header)", w);
  }
  if (r->oom || r->nul || ferror(r->f)) return not_read(r);
  return lw_error_set(r->err, LW_EINPUT, "%s:%ld: expected 'end_header', found the end of the file", r->path, r->line);
}

/* ---- binary -------------------------------------------------------------- */

/* One value of type t from f in the file's byte order; 0 at the end. */
static int read_binary(reader *r, ptype t, double *v)
{
  unsigned char b[8];
  int size = type_size[t];
  if (fread(b, 1, (size_t)size, r->f) != (size_t)size) return 0;
  uint64_t u = 0;
  for (int k = 0; k < size; k++) u |= (uint64_t)b[r->format == LITTLE ? k : size - 1 - k] << (8 * k);
  switch (t) {
  case T_I8: *v = (int8_t)u; break;
  case T_U8: *v = (uint8_t)u; break;
  case T_I16: *v = (int16_t)u; break;
  case T_U16: *v = (uint16_t)u; break;
  case T_I32: *v = (int32_t)u; break;
  case T_U32: *v = (uint32_t)u; break;
  case T_F32: {
    uint32_t u32 = (uint32_t)u;
    float fl;
    memcpy(&fl, &u32, sizeof fl);
    *v = fl;
    break;
  }
  default: {
    double d;
    memcpy(&d, &u, sizeof d);
    *v = d;
  }
  }
  return 1;
}

/* One instance of e; the wanted values into row.  0 where the file ends
** inside it, -1 for a list longer than LIST_MAX. */
static int binary_instance(reader *r, const elem *e, double *row)
{
  for (int k = 0; k < e->n_props; k++) {
    const prop *p = e->props + k;
    double v;
    if (p->count == T_NONE) {
      if (!read_binary(r, p->type, &v)) return 0;
      if (p->want >= 0) row[p->want] = v;
      continue;
    }
    if (!read_binary(r, p->count, &v)) return 0;
    if (v < 0 || v > LIST_MAX) return -1;
    /* read, not skipped by fseek, which passes the end of a file cut short
    ** without a word */
    for (long m = 0, items = (long)v; m < items; m++)
      if (!read_binary(r, p->type, &v)) return 0;
  }
  return 1;
}

/* ---- ASCII --------------------------------------------------------------- */

/* One instance of e from its line; the wanted values into row. */
static lw_status ascii_instance(reader *r, const elem *e, size_t index, double *row)
{
  char *s;
  do {
    if (!(s = next_line(r)) && (r->oom || r->nul || ferror(r->f))) return not_read(r);
    if (!s)
      return lw_error_set(r->err, LW_EINPUT, "%s:%ld: expected %zu %s lines, the file ends after %zu", r->path, r->line,
                          e->count, e->name, index);
  } while (strspn(s, " \t") == strlen(s));
  char *save, *tok = strtok_r(s, " \t", &save);
  for (int k = 0; k < e->n_props; k++) {
    const prop *p = e->props + k;
    double v;
    if (!tok || !lw_number_parse(tok, &v))
      return lw_error_set(r->err, LW_EINPUT, "%s:%ld: expected property %d of %s %zu as a finite number, got '%.40s'",
                          r->path, r->line, k + 1, e->name, index, tok ? tok : "");
    tok = strtok_r(NULL, " \t", &save);
    if (p->count == T_NONE) {
      if (p->want >= 0) row[p->want] = v;
      continue;
    }
    if (v < 0 || v > LIST_MAX || v != floor(v))
      return lw_error_set(r->err, LW_EINPUT, "%s:%ld: expected a list's length (a whole number up to %d), got %g",
                          r->path, r->line, LIST_MAX, v);
    double item;
    for (long m = 0, items = (long)v; m < items; m++, tok = strtok_r(NULL, " \t", &save))
      if (!tok || !lw_number_parse(tok, &item))
        return lw_error_set(r->err, LW_EINPUT, "%s:%ld: expected a list item as a finite number, got '%.40s'",
                            r->path, r->line, tok ? tok : "");
  }
  if (tok)
    return lw_error_set(r->err, LW_EINPUT, "%s:%ld: expected %d values for %s %zu (its properties), got more: '%.40s'",
                        r->path, r->line, e->n_props, e->name, index, tok);
  return LW_OK;
}

/* Skips or reads one instance of e (row NULL: skipped). */
static lw_status instance(reader *r, const elem *e, size_t index, double *row)
{
  if (r->format == ASCII) return ascii_instance(r, e, index, row);
  double scratch[PROPS_MAX];
  int got = binary_instance(r, e, row ? row : scratch);
  if (got > 0) return LW_OK;
  if (ferror(r->f)) return lw_error_set(r->err, LW_EIO, "%s: read error in %s %zu", r->path, e->name, index);
  if (got < 0)
    return lw_error_set(r->err, LW_EINPUT, "%s: %s %zu: expected a list of at most %d items", r->path, e->name,
                        index, LIST_MAX);
  return lw_error_set(r->err, LW_EINPUT, "%s: %s %zu: the file ends inside it (the header says %zu)", r->path,
                      e->name, index, e->count);
}

lw_status lw_ply_read_vertices(FILE *f, const char *path, const char *const *names, int n_names, size_t *n,
                               double **values, unsigned *found, lw_error *err)
{
  *n = 0;
  *values = NULL;
  *found = 0;
  reader r = {f, path, ASCII, 0, NULL, 0, err, 0, 0};
  elem el[ELEMS_MAX];
  int n_el = 0;
  lw_status s = read_header(&r, names, n_names, el, &n_el);
  const elem *v = NULL;
  for (int k = 0; !s && k < n_el; k++) {
    if (strcmp(el[k].name, "vertex")) {
      if (!v)
        for (size_t i = 0; !s && i < el[k].count; i++) s = instance(&r, el + k, i, NULL);
      continue;
    }
    if (v) {
      s = lw_error_set(err, LW_EINPUT, "%s: expected one element 'vertex', found two", path);
      break;
    }
    v = el + k;
    for (int p = 0; p < v->n_props; p++)
      if (v->props[p].want >= 0) *found |= 1u << v->props[p].want;
    /* grown as the vertices come, so that a count the file cannot hold
    ** costs no memory before it is found out */
    size_t cap = 0;
    for (size_t i = 0; !s && i < v->count; i++) {
      if (i == cap) {
        cap = cap ? 2 * cap : 1024;
        if (cap > v->count) cap = v->count;
        double *nv = realloc(*values, cap * (size_t)n_names * sizeof *nv);
        if (!nv) {
          s = lw_error_set(err, LW_ENOMEM, "%s: out of memory for %zu vertices", path, cap);
          break;
        }
        *values = nv;
      }
      double *row = *values + i * (size_t)n_names;
      memset(row, 0, (size_t)n_names * sizeof *row);
      if ((s = instance(&r, v, i, row))) break;
      for (int c = 0; c < n_names && !s; c++)
        if (!isfinite(row[c]))
          s = lw_error_set(err, LW_EINPUT, "%s: vertex %zu: expected a finite %s, got %g", path, i, names[c], row[c]);
    }
    if (!s) *n = v->count;
  }
  if (!s && !v) s = lw_error_set(err, LW_EINPUT, "%s: expected an element 'vertex' in the header, found none", path);
  if (!s && !*n) s = lw_error_set(err, LW_EINPUT, "%s: expected at least one vertex, the element has none", path);
  if (!s && ferror(f)) s = lw_error_set(err, LW_EIO, "%s: read error", path);
  free(r.buf);
  if (s) {
    free(*values);
    *values = NULL;
    *n = 0;
    *found = 0;
  }
  return s;
}
