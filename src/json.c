/* json.c -- the streaming JSON writer (json.h). */
#include "linewise/json.h"

#include <math.h>
#include <string.h>

void lw_json_init(lw_json *j, FILE *f)
{
  memset(j, 0, sizeof *j);
  j->f = f;
}

static void misuse(lw_json *j, const char *what)
{
  if (!j->misuse) j->misuse = what;
}

static void newline_indent(lw_json *j, int depth)
{
  fputc('\n', j->f);
  for (int i = 0; i < depth; i++) fputs("  ", j->f);
}

/* Everything before a value or a key: the comma after the previous member,
** then a new indented line.  A value right after its key stays on the key's
** line.  Returns 0 (and writes nothing) if a value is not allowed here. */
static int before(lw_json *j, int is_key)
{
  if (j->misuse) return 0;
  if (j->done) {
    misuse(j, "a second top-level value");
    return 0;
  }
  int in_object = j->depth && j->kind[j->depth - 1] == '{';
  if (is_key) {
    if (!in_object || j->after_key) {
      misuse(j, in_object ? "two keys in a row" : "a key outside an object");
      return 0;
    }
  } else if (j->after_key) {
    j->after_key = 0;
    return 1;
  } else if (in_object) {
    misuse(j, "a value in an object without a key");
    return 0;
  }
  if (j->depth) {
    if (j->members[j->depth - 1]++) fputc(',', j->f);
    newline_indent(j, j->depth);
  }
  return 1;
}

/* After a complete value: at depth 0 the document is done. */
static void after(lw_json *j)
{
  if (!j->depth) j->done = 1;
}

static void begin(lw_json *j, char kind)
{
  /* Checked before before(), which already counts the member. */
  if (j->depth == LW_JSON_MAX_DEPTH) {
    misuse(j, "nesting deeper than LW_JSON_MAX_DEPTH");
    return;
  }
  if (!before(j, 0)) return;
  fputc(kind, j->f);
  j->kind[j->depth] = kind;
  j->members[j->depth] = 0;
  j->depth++;
}

static void end(lw_json *j, char kind)
{
  if (j->misuse) return;
  if (!j->depth || j->kind[j->depth - 1] != kind || j->after_key) {
    misuse(j, j->after_key ? "a key without a value" : "an end without its begin");
    return;
  }
  j->depth--;
  /* Empty containers stay on one line: "{}", "[]". */
  if (j->members[j->depth]) newline_indent(j, j->depth);
  fputc(kind == '{' ? '}' : ']', j->f);
  after(j);
}

void lw_json_begin_object(lw_json *j) { begin(j, '{'); }
void lw_json_end_object(lw_json *j) { end(j, '{'); }
void lw_json_begin_array(lw_json *j) { begin(j, '['); }
void lw_json_end_array(lw_json *j) { end(j, '['); }

/* The length of the well-formed UTF-8 sequence at c (1 to 4), 0 if there is
** none (a stray continuation byte, one cut short, an overlong form, a
** surrogate, past U+10FFFF). */
static int utf8_length(const unsigned char *c)
{
  if (*c < 0x80) return 1;
  int n = *c >= 0xC2 && *c <= 0xDF ? 2 : *c >= 0xE0 && *c <= 0xEF ? 3 : *c >= 0xF0 && *c <= 0xF4 ? 4 : 0;
  for (int k = 1; k < n; k++)
    if ((c[k] & 0xC0) != 0x80) return 0;
  if ((*c == 0xE0 && c[1] < 0xA0) || (*c == 0xED && c[1] > 0x9F) || (*c == 0xF0 && c[1] < 0x90) ||
      (*c == 0xF4 && c[1] > 0x8F))
    return 0;
  return n;
}

static void put_string(FILE *f, const char *s)
{
  fputc('"', f);
  for (const unsigned char *c = (const unsigned char *)s; *c; c++) {
    int n = utf8_length(c);
    if (n != 1) {
      /* JSON is UTF-8: a byte of a file name that is not (Latin-1, say) is
      ** U+FFFD, which every reader takes (Python's surrogate escape \udcXX
      ** would give the name back, but strict readers refuse a lone surrogate) */
      if (n) fwrite(c, 1, (size_t)n, f);
      else fputs("\\ufffd", f);
      c += n ? n - 1 : 0;
      continue;
    }
    switch (*c) {
    case '"': fputs("\\\"", f); break;
    case '\\': fputs("\\\\", f); break;
    case '\n': fputs("\\n", f); break;
    case '\r': fputs("\\r", f); break;
    case '\t': fputs("\\t", f); break;
    case '\b': fputs("\\b", f); break;
    case '\f': fputs("\\f", f); break;
    default:
      if (*c < 0x20) fprintf(f, "\\u%04x", *c);
      else fputc(*c, f);
    }
  }
  fputc('"', f);
}

void lw_json_key(lw_json *j, const char *name)
{
  if (!before(j, 1)) return;
  put_string(j->f, name);
  fputs(": ", j->f);
  j->after_key = 1;
}

void lw_json_number(lw_json *j, double v)
{
  if (!before(j, 0)) return;
  if (isfinite(v)) fprintf(j->f, "%.17g", v);
  else fputs("null", j->f);
  after(j);
}

void lw_json_int(lw_json *j, long long v)
{
  if (!before(j, 0)) return;
  fprintf(j->f, "%lld", v);
  after(j);
}

void lw_json_string(lw_json *j, const char *s)
{
  if (!before(j, 0)) return;
  put_string(j->f, s);
  after(j);
}

void lw_json_bool(lw_json *j, int v)
{
  if (!before(j, 0)) return;
  fputs(v ? "true" : "false", j->f);
  after(j);
}

void lw_json_null(lw_json *j)
{
  if (!before(j, 0)) return;
  fputs("null", j->f);
  after(j);
}

lw_status lw_json_finish(lw_json *j, lw_error *err)
{
  if (!j->misuse && !j->done) j->misuse = j->depth ? "a container left open" : "no value written";
  if (j->misuse) return lw_error_set(err, LW_ERUN, "JSON writer misused: %s", j->misuse);
  fputc('\n', j->f);
  if (ferror(j->f)) return lw_error_set(err, LW_EIO, "JSON output: write error");
  return LW_OK;
}
