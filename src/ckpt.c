/*
** ckpt.c -- sectioned key files (ckpt.h).
**
** A read file stays in memory as one text buffer cut into lines in place;
** sections and entries hold offsets into it, so a state of a million nodes
** costs one allocation for the text and one index entry per line.  A
** document built in memory appends to the same buffer.
*/
#include "linewise/ckpt.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "linewise/number.h"
#include "linewise/output.h"

typedef struct {
  size_t key, value;  /* offsets into text */
  int line;           /* 0 when built in memory */
  int read;
} entry;

typedef struct {
  size_t name;        /* offset into text */
  int line, read;
  size_t *idx, n, cap; /* its entries, in order */
} section;

struct lw_ckpt {
  char path[LW_PATH_MAX];
  char *text;
  size_t len, cap;
  size_t header;      /* offset, or (size_t)-1 */
  int header_line;
  int lines;          /* the file's lines */
  entry *e;
  size_t n, ecap;
  section *s;
  size_t ns, scap;
  size_t sum_at;      /* where its last line, "# checksum X", begins, or NONE */
  int sum_ok;         /* X is the checksum of the bytes before it */
  int sum_misplaced;  /* the line is not the last but blanks, or not of 16 hex digits */
  int sum_line;
};

/* FNV-1a, 64 bits: a flipped bit anywhere changes it (a damaged copy of a
** checkpoint resumed with a node moved in its fourth digit, unseen). */
static unsigned long long fnv1a(unsigned long long h, const unsigned char *b, size_t n)
{
  for (size_t k = 0; k < n; k++) h = (h ^ b[k]) * 0x100000001b3ULL;
  return h;
}
#define FNV_START 0xcbf29ce484222325ULL
#define SUM_LINE "# checksum "

#define NONE ((size_t)-1)

lw_ckpt *lw_ckpt_new(const char *path)
{
  lw_ckpt *c = calloc(1, sizeof *c);
  if (!c) return NULL;
  snprintf(c->path, sizeof c->path, "%s", path);
  c->header = NONE;
  c->sum_at = NONE;
  return c;
}

void lw_ckpt_free(lw_ckpt *c)
{
  if (!c) return;
  for (size_t i = 0; i < c->ns; i++) free(c->s[i].idx);
  free(c->s);
  free(c->e);
  free(c->text);
  free(c);
}

const char *lw_ckpt_path(const lw_ckpt *c) { return c->path; }
const char *lw_ckpt_header(const lw_ckpt *c) { return c->header == NONE ? NULL : c->text + c->header; }

/* Copies s to the end of the text; its offset, or NONE. */
static size_t store(lw_ckpt *c, const char *s)
{
  size_t n = strlen(s) + 1;
  if (c->len + n > c->cap) {
    size_t cap = c->cap ? 2 * c->cap : 4096;
    while (cap < c->len + n) cap *= 2;
    char *t = realloc(c->text, cap);
    if (!t) return NONE;
    c->text = t;
    c->cap = cap;
  }
  memcpy(c->text + c->len, s, n);
  c->len += n;
  return c->len - n;
}

static section *find_section(const lw_ckpt *c, const char *name)
{
  for (size_t i = 0; i < c->ns; i++)
    if (!strcmp(c->text + c->s[i].name, name)) return &c->s[i];
  return NULL;
}

static section *new_section(lw_ckpt *c, size_t name, int line)
{
  if (c->ns == c->scap) {
    size_t cap = c->scap ? 2 * c->scap : 8;
    section *s = realloc(c->s, cap * sizeof *s);
    if (!s) return NULL;
    c->s = s;
    c->scap = cap;
  }
  section *s = &c->s[c->ns++];
  *s = (section){.name = name, .line = line};
  return s;
}

static int new_entry(lw_ckpt *c, section *s, size_t key, size_t value, int line)
{
  if (c->n == c->ecap) {
    size_t cap = c->ecap ? 2 * c->ecap : 64;
    entry *e = realloc(c->e, cap * sizeof *e);
    if (!e) return 0;
    c->e = e;
    c->ecap = cap;
  }
  if (s->n == s->cap) {
    size_t cap = s->cap ? 2 * s->cap : 16;
    size_t *idx = realloc(s->idx, cap * sizeof *idx);
    if (!idx) return 0;
    s->idx = idx;
    s->cap = cap;
  }
  c->e[c->n] = (entry){key, value, line, 0};
  s->idx[s->n++] = c->n++;
  return 1;
}

lw_status lw_ckpt_add(lw_ckpt *c, const char *sec, const char *key, const char *value, int line)
{
  /* copies first: the arguments may point into the text that grows here */
  char *k = strdup(key), *v = strdup(value), *sn = strdup(sec);
  lw_status st = LW_ENOMEM;
  if (k && v && sn) {
    section *s = find_section(c, sn);
    size_t name = s ? 0 : store(c, sn);
    if (!s && name != NONE) s = new_section(c, name, line);
    if (s) {
      size_t si = (size_t)(s - c->s), ko = store(c, k), vo = ko == NONE ? NONE : store(c, v);
      if (vo != NONE && new_entry(c, &c->s[si], ko, vo, line)) st = LW_OK;
    }
  }
  free(k);
  free(v);
  free(sn);
  return st;
}

static char *trim(char *a, char *b)
{
  while (a < b && (*a == ' ' || *a == '\t')) a++;
  while (b > a && (b[-1] == ' ' || b[-1] == '\t' || b[-1] == '\r')) b--;
  *b = '\0';
  return a;
}

/* Cuts the text into header, sections and entries. */
static lw_status parse(lw_ckpt *c, lw_error *err)
{
  section *cur = NULL;
  int line = 0;
  for (char *p = c->text, *end = c->text + c->len; p < end;) {
    char *nl = memchr(p, '\n', (size_t)(end - p));
    char *eol = nl ? nl : end;
    line++;
    if (memchr(p, '\0', (size_t)(eol - p)))
      return lw_error_set(err, LW_EINPUT, "%s:%d: " LW_TEXT_NUL_LINE, c->path, line);
    char *s = trim(p, eol);
    p = eol + 1;
    if (!*s || *s == '#') continue;
    if (c->header == NONE) {
      c->header = (size_t)(s - c->text);
      c->header_line = line;
      continue;
    }
    if (*s == '[') {
      size_t n = strlen(s);
      if (s[n - 1] != ']' || n < 3 || strchr(s + 1, '[') || memchr(s + 1, ']', n - 2))
        return lw_error_set(err, LW_EINPUT, "%s:%d: expected a section '[name]', got '%.60s'", c->path, line, s);
      s[n - 1] = '\0';
      char *name = trim(s + 1, s + n - 1);
      section *old = find_section(c, name);
      if (old)
        return lw_error_set(err, LW_EINPUT, "%s:%d: section [%s] repeated (first on line %d)", c->path, line, name,
                            old->line);
      if (!*name || !(cur = new_section(c, (size_t)(name - c->text), line)))
        return *name ? lw_error_set(err, LW_ENOMEM, "%s: out of memory", c->path)
                     : lw_error_set(err, LW_EINPUT, "%s:%d: a section without a name", c->path, line);
      continue;
    }
    char *eq = strchr(s, '=');
    if (!eq || !cur)
      return lw_error_set(err, LW_EINPUT, "%s:%d: expected %s, got '%.60s'", c->path, line,
                          cur ? "'key = value'" : "a section '[name]' first", s);
    char *key = trim(s, eq), *value = trim(eq + 1, eq + 1 + strlen(eq + 1));
    if (!*key || strpbrk(key, " \t"))
      return lw_error_set(err, LW_EINPUT, "%s:%d: expected a key without blanks before '=', got '%.60s'", c->path,
                          line, key);
    if (!new_entry(c, cur, (size_t)(key - c->text), (size_t)(value - c->text), line))
      return lw_error_set(err, LW_ENOMEM, "%s: out of memory", c->path);
  }
  if (c->header == NONE) return lw_error_set(err, LW_EINPUT, "%s:1: header: expected a header line, got an empty file", c->path);
  return LW_OK;
}

/* FNV-1a of n bytes less the CR of each CR LF: a copy with Windows line
** ends (git's autocrlf, an editor) keeps its sum. */
static unsigned long long sum_text(const char *t, size_t n)
{
  unsigned long long h = FNV_START;
  for (size_t k = 0; k < n; k++)
    if (!(t[k] == '\r' && k + 1 < n && t[k + 1] == '\n')) h = fnv1a(h, (const unsigned char *)t + k, 1);
  return h;
}

/* The checksum's line, "# checksum" and 16 hex digits: where it begins and
** whether they are the sum of the bytes before it (a byte order mark an
** editor put first aside), where it is the last line but blanks; one with
** lines after it is a misplaced sum (an edit that added them). */
static void find_sum(lw_ckpt *c)
{
  const size_t k = strlen(SUM_LINE);
  size_t end = c->len;
  while (end > 0 && strchr(" \t\r\n", c->text[end - 1])) end--;
  size_t last = end; /* where the last line but blanks begins */
  while (last > 0 && c->text[last - 1] != '\n') last--;
  /* a checksum's line put out of form ("#checksum", indented, upper case)
  ** is one all the same: read as none, it let a damaged state through */
  int like = 0;
  const char *t = c->text + last + strspn(c->text + last, " \t");
  for (const char *w = t; *t == '#' && w + 8 <= c->text + end && !like; w++) like = !strncasecmp(w, "checksum", 8);
  size_t at = like ? last : NONE;
  for (size_t i = c->len; at == NONE && i-- > 0;)
    if ((i == 0 || c->text[i - 1] == '\n') && i + k <= c->len && !strncmp(c->text + i, SUM_LINE, k)) at = i;
  if (at == NONE) return;
  char *stop;
  const unsigned long long v = strtoull(c->text + at + k, &stop, 16);
  const int hex = !strncmp(c->text + at, SUM_LINE, k) && stop == c->text + at + k + 16 &&
                  isxdigit((unsigned char)c->text[at + k]);
  c->sum_at = at;
  c->sum_line = 1;
  for (size_t i = 0; i < at; i++) c->sum_line += c->text[i] == '\n';
  c->sum_misplaced = !hex || stop < c->text + end;
  const size_t from = at >= 3 && !memcmp(c->text, "\xef\xbb\xbf", 3) ? 3 : 0;
  c->sum_ok = !c->sum_misplaced && sum_text(c->text + from, at - from) == v;
}

lw_status lw_ckpt_verify(const lw_ckpt *c, lw_error *err)
{
  if (c->sum_at == NONE || c->sum_ok) return LW_OK;
  if (c->sum_misplaced)
    return lw_error_set(err, LW_EINPUT, "%s:%d: its checksum's line is not its last, or not '# checksum' and 16 hex "
                        "digits: the file was damaged or edited since linewise wrote it; a state edited on purpose "
                        "goes on once that line is taken out", c->path, c->sum_line);
  return lw_error_set(err, LW_EINPUT, "%s:%d: its checksum does not match its contents: the file was damaged (a disk's "
                      "or a copy's fault) or edited since linewise wrote it; a state edited on purpose goes on once "
                      "this line is taken out", c->path, c->sum_line);
}

lw_status lw_ckpt_read(lw_ckpt **out, const char *path, lw_error *err)
{
  *out = NULL;
  if (lw_number_locale_ok(err)) return err->code; /* (resume and energy read it first) */
  if (lw_text_plain_file(path, err)) return err->code;
  lw_ckpt *c = lw_ckpt_new(path);
  if (!c) return lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
  FILE *f = fopen(path, "rb");
  if (!f) {
    lw_ckpt_free(c);
    return lw_error_set(err, LW_EINPUT, "%s: cannot open: %s", path, strerror(errno));
  }
  lw_status s = LW_OK;
  char chunk[65536];
  size_t got, line_from = 0; /* where the line being read began */
  while ((got = fread(chunk, 1, sizeof chunk, f)) > 0) {
    if (c->len + got + 1 > c->cap) {
      size_t cap = c->cap ? 2 * c->cap : 65536;
      while (cap < c->len + got + 1) cap *= 2;
      char *t = realloc(c->text, cap);
      if (!t) {
        s = lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
        break;
      }
      c->text = t;
      c->cap = cap;
    }
    memcpy(c->text + c->len, chunk, got);
    for (size_t k = got; k > 0; k--)
      if (chunk[k - 1] == '\n') {
        line_from = c->len + k;
        break;
      }
    c->len += got;
    /* text: a NUL ends the reading at once (/dev/zero, a sparse file of
    ** gigabytes, were read whole first); the check below names its line */
    if (memchr(chunk, '\0', got)) break;
    if (c->len - line_from > (size_t)LW_TEXT_LINE_MAX) { /* (a text file of gigabytes named as a state) */
      size_t lines = 1;
      for (size_t k = 0; k < line_from; k++) lines += c->text[k] == '\n';
      s = lw_error_set(err, LW_EINPUT, "%s:%zu: a line longer than %ld MiB: not a state", path, lines,
                       LW_TEXT_LINE_MAX >> 20);
      break;
    }
  }
  /* a directory opens but does not read: the user named the wrong thing */
  if (!s && ferror(f)) s = lw_error_set(err, LW_EINPUT, "%s: cannot read: %s", path, strerror(errno ? errno : EIO));
  fclose(f);
  if (!s && !c->text && !(c->text = malloc(1))) s = lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
  if (!s) {
    c->text[c->len] = '\0';
    for (size_t k = 0; k < c->len; k++) c->lines += c->text[k] == '\n';
    /* every state this program writes ends its last line: one that does not
    ** was cut short inside it (a number cut there still read as a number);
    ** but a NUL, where the reading stopped, is named by parse (a state padded
    ** with gigabytes of NULs was called cut short) */
    if (c->len && c->text[c->len - 1] != '\n' && !memchr(c->text, '\0', c->len))
      s = lw_error_set(err, LW_EINPUT, "%s:%d: the file ends inside this line: cut short (a partial copy, a full "
                       "disk?); a state written by hand needs a newline after its last line", path, c->lines + 1);
    else {
      find_sum(c); /* (before parse, which cuts the lines' ends) */
      s = parse(c, err);
    }
    c->len++; /* what store() appends goes after the final NUL */
  }
  if (s) lw_ckpt_free(c);
  else *out = c;
  return s;
}

/* The first entry with this key: a repeated key stays unread, so
** lw_ckpt_unread refuses it. */
static entry *find(lw_ckpt *c, const char *sec, const char *key)
{
  section *s = find_section(c, sec);
  if (!s) return NULL;
  s->read = 1;
  for (size_t i = 0; i < s->n; i++) {
    entry *e = &c->e[s->idx[i]];
    if (!strcmp(c->text + e->key, key)) return e;
  }
  return NULL;
}

int lw_ckpt_has(lw_ckpt *c, const char *sec)
{
  section *s = find_section(c, sec);
  if (s) s->read = 1;
  return s != NULL;
}

const char *lw_ckpt_text(lw_ckpt *c, const char *sec, const char *key, int *line)
{
  entry *e = find(c, sec, key);
  if (!e) return NULL;
  e->read = 1;
  if (line) *line = e->line;
  return c->text + e->value;
}

lw_status lw_ckpt_missing(const lw_ckpt *c, const char *what, const char *guess, lw_error *err)
{
  return lw_error_set(err, LW_EINPUT, "%s: %s: missing (%s, or a file cut short: it ends at its line %d)", c->path,
                      what, guess, c->lines);
}

lw_status lw_ckpt_no_section(const lw_ckpt *c, const char *sec, lw_error *err)
{
  /* the sections not read yet first (a renamed one is among them), as many
  ** as fit, and "..." for the rest */
  char list[1024] = "";
  size_t at = 0, shown = 0;
  for (int pass = 0; pass < 2; pass++)
    for (size_t i = 0; i < c->ns; i++) {
      if (c->s[i].read != pass) continue;
      char one[192];
      int m = snprintf(one, sizeof one, "%s[%.150s] at line %d", shown ? ", " : "", c->text + c->s[i].name,
                       c->s[i].line); /* (a name of any length: at most 150 bytes of it, so one holds m) */
      if (m < 0 || at + (size_t)m + 8 >= sizeof list) {
        snprintf(list + at, sizeof list - at, ", ...");
        goto done;
      }
      memcpy(list + at, one, (size_t)m + 1);
      at += (size_t)m;
      shown++;
    }
done:
  return lw_error_set(err, LW_EINPUT, "%s: section [%s] missing (the file has %s; a damaged or edited file, or one "
                      "cut short: it ends at its line %d)", c->path, sec, c->ns ? list : "none", c->lines);
}

const char *lw_ckpt_cut_hint(const lw_ckpt *c, const char *sec)
{
  const section *s = find_section(c, sec);
  return s && s->line && s == &c->s[c->ns - 1]
             ? ", where the file ends (cut short by a partial copy or a full disk, or edited?)"
             : "";
}

static lw_status missing(const lw_ckpt *c, const char *sec, const char *key, lw_error *err)
{
  char what[160];
  snprintf(what, sizeof what, "[%s] %s", sec, key);
  return lw_ckpt_missing(c, what, "not a checkpoint of a run, or a damaged one", err);
}

static lw_status bad_value(const lw_ckpt *c, int line, const char *sec, const char *key, const char *expected,
                           const char *got, lw_error *err)
{
  return lw_error_set(err, LW_EINPUT, "%s:%d: [%s] %s: expected %s, got '%.80s%s'", c->path, line, sec, key,
                      expected, got, strlen(got) > 80 ? "..." : "");
}

lw_status lw_ckpt_numbers(lw_ckpt *c, const char *sec, const char *key, double *out, int n, double lo, double hi,
                          int required, lw_error *err)
{
  int line;
  const char *v = lw_ckpt_text(c, sec, key, &line);
  if (!v) return required ? missing(c, sec, key, err) : LW_OK;
  double tmp[LW_CKPT_LIST_MAX];
  char expected[160];
  snprintf(expected, sizeof expected, "%d number%s from %.17g to %.17g", n, n == 1 ? "" : "s", lo, hi);
  if (n > LW_CKPT_LIST_MAX || lw_number_list(v, 0, tmp, n) != n)
    return bad_value(c, line, sec, key, expected, v, err);
  for (int i = 0; i < n; i++)
    if (!(tmp[i] >= lo && tmp[i] <= hi)) return bad_value(c, line, sec, key, expected, v, err);
  memcpy(out, tmp, (size_t)n * sizeof *out);
  return LW_OK;
}

lw_status lw_ckpt_counts(lw_ckpt *c, const char *sec, const char *key, unsigned long *out, int n, int required,
                         lw_error *err)
{
  return lw_ckpt_counts_upto(c, sec, key, out, n, n, required, err);
}

lw_status lw_ckpt_counts_upto(lw_ckpt *c, const char *sec, const char *key, unsigned long *out, int n_min,
                              int n_max, int required, lw_error *err)
{
  int line;
  const char *v = lw_ckpt_text(c, sec, key, &line);
  if (!v) return required ? missing(c, sec, key, err) : LW_OK;
  double tmp[LW_CKPT_LIST_MAX];
  char expected[96];
  if (n_min == n_max)
    snprintf(expected, sizeof expected, "%d whole number%s from 0 to 2^53", n_max, n_max == 1 ? "" : "s");
  else snprintf(expected, sizeof expected, "%d to %d whole numbers from 0 to 2^53", n_min, n_max);
  const int n = n_max > LW_CKPT_LIST_MAX ? -1 : lw_number_list(v, 0, tmp, n_max);
  if (n < n_min || n > n_max) return bad_value(c, line, sec, key, expected, v, err);
  for (int i = 0; i < n; i++)
    if (!(tmp[i] >= 0 && tmp[i] <= 9007199254740992.0) || tmp[i] != floor(tmp[i]))
      return bad_value(c, line, sec, key, expected, v, err);
  for (int i = 0; i < n; i++) out[i] = (unsigned long)tmp[i];
  return LW_OK;
}

lw_status lw_ckpt_whole(lw_ckpt *c, const char *sec, const char *key, long *out, long lo, long hi, int required,
                        lw_error *err)
{
  int line;
  const char *v = lw_ckpt_text(c, sec, key, &line);
  if (!v) return required ? missing(c, sec, key, err) : LW_OK;
  long long x;
  char expected[96];
  snprintf(expected, sizeof expected, "a whole number from %ld to %ld", lo, hi);
  if (!lw_number_parse_whole(v, (double)lo, (double)hi, &x)) return bad_value(c, line, sec, key, expected, v, err);
  *out = (long)x;
  return LW_OK;
}

int lw_ckpt_next(lw_ckpt *c, const char *sec, size_t *pos, const char **key, const char **value, int *line)
{
  section *s = find_section(c, sec);
  if (!s || *pos >= s->n) return 0;
  s->read = 1;
  entry *e = &c->e[s->idx[(*pos)++]];
  e->read = 1;
  *key = c->text + e->key;
  *value = c->text + e->value;
  if (line) *line = e->line;
  return 1;
}

lw_status lw_ckpt_single(lw_ckpt *c, const char *sec, const char *key, lw_error *err)
{
  const section *s = find_section(c, sec);
  int seen = 0;
  for (size_t i = 0; s && i < s->n; i++) {
    const entry *e = &c->e[s->idx[i]];
    if (strcmp(c->text + e->key, key) || !seen++) continue;
    return lw_error_set(err, LW_EINPUT, "%s:%d: [%s] %s: given twice (expected one line of it)", c->path, e->line,
                        sec, key);
  }
  return LW_OK;
}

lw_status lw_ckpt_known_sections(const lw_ckpt *c, int (*known)(const char *name, const void *ctx), const void *ctx,
                                 lw_error *err)
{
  for (size_t i = 0; i < c->ns; i++)
    if (!known(c->text + c->s[i].name, ctx))
      return lw_error_set(err, LW_EINPUT, "%s:%d: section [%s] is unknown to this linewise (written by a newer "
                          "version?)", c->path, c->s[i].line, c->text + c->s[i].name);
  return LW_OK;
}

size_t lw_ckpt_count_sections(const lw_ckpt *c, int (*match)(const char *name))
{
  size_t n = 0;
  for (size_t i = 0; i < c->ns; i++) n += match(c->text + c->s[i].name) != 0;
  return n;
}

lw_status lw_ckpt_unread(const lw_ckpt *c, lw_error *err)
{
  for (size_t i = 0; i < c->ns; i++) {
    const section *s = &c->s[i];
    if (!s->read)
      return lw_error_set(err, LW_EINPUT, "%s:%d: section [%s] is unknown to this linewise (written by a newer "
                          "version?)", c->path, s->line, c->text + s->name);
    for (size_t k = 0; k < s->n; k++) {
      const entry *e = &c->e[s->idx[k]];
      if (!e->read)
        return lw_error_set(err, LW_EINPUT, "%s:%d: [%s] %s: unknown or repeated key (written by a newer "
                            "version?)", c->path, e->line, c->text + s->name, c->text + e->key);
    }
  }
  return LW_OK;
}

/* ---- writing -------------------------------------------------------------- */

lw_status lw_ckpt_begin(lw_ckpt_writer *w, const char *path, const char *header, lw_error *err)
{
  /* (a host that set a comma locale wrote "30,94 12,68" and LW_OK: a state
  ** that neither it nor linewise could read back) */
  lw_error mine;
  if (lw_number_locale_ok(err ? err : &mine)) return err ? err->code : LW_EINPUT;
  snprintf(w->path, sizeof w->path, "%s", path);
  w->no_sum = 0;
  w->f = lw_output_open_tmp(w->path, w->tmp, sizeof w->tmp, err);
  if (!w->f) return err ? err->code : LW_EIO;
  fprintf(w->f, "%s\n", header);
  return LW_OK;
}

void lw_ckpt_section(lw_ckpt_writer *w, const char *name) { fprintf(w->f, "\n[%s]\n", name); }

void lw_ckpt_put(lw_ckpt_writer *w, const char *key, const char *fmt, ...)
{
  va_list ap;
  va_start(ap, fmt);
  fprintf(w->f, "%s = ", key);
  vfprintf(w->f, fmt, ap);
  fputc('\n', w->f);
  va_end(ap);
}

void lw_ckpt_put_numbers(lw_ckpt_writer *w, const char *key, const double *v, int n)
{
  fprintf(w->f, "%s =", key);
  for (int i = 0; i < n; i++) fprintf(w->f, " %.17g", v[i]);
  fputc('\n', w->f);
}

void lw_ckpt_put_counts(lw_ckpt_writer *w, const char *key, const unsigned long *v, int n)
{
  fprintf(w->f, "%s =", key);
  for (int i = 0; i < n; i++) fprintf(w->f, " %lu", v[i]);
  fputc('\n', w->f);
}

lw_status lw_ckpt_commit(lw_ckpt_writer *w, lw_error *err)
{
  /* the checksum of what was written, read back (the MPI writer puts its
  ** processes' parts in whole); a file that cannot be goes without one,
  ** which a resume reads as a file written so */
  unsigned long long h = FNV_START;
  unsigned char buf[65536];
  size_t got;
  if (!w->no_sum && fflush(w->f)) { /* (the write's own error: a later flush had none to give) */
    const int e = errno;
    lw_output_abort(w->f, w->tmp);
    w->f = NULL;
    return lw_error_set(err, LW_EIO, "%s: write failed: %s", w->path, strerror(e));
  }
  FILE *back = w->no_sum ? NULL : fopen(w->tmp, "rb");
  while (back && (got = fread(buf, 1, sizeof buf, back)) > 0) h = fnv1a(h, buf, got);
  if (back && !ferror(back)) fprintf(w->f, SUM_LINE "%016llx\n", h);
  if (back) fclose(back);
  lw_status s = lw_output_commit(w->f, w->tmp, w->path, err);
  w->f = NULL;
  return s;
}

void lw_ckpt_abort(lw_ckpt_writer *w)
{
  lw_output_abort(w->f, w->tmp);
  w->f = NULL;
}
