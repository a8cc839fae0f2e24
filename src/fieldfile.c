/* fieldfile.c -- a grid of values from a .npy or a text file (fieldfile.h). */
#include "linewise/fieldfile.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "linewise/image.h"
#include "linewise/number.h"

#define NPY_MAGIC "\x93NUMPY"
/* np.save pads its header to 64 bytes or so; a megabyte is no header */
#define NPY_HEADER_MAX (1L << 20)
#define NPY_DIMS_MAX 8

typedef struct {
  char kind;        /* 'f', 'i' or 'u' */
  int size;         /* bytes a value */
  int swap;         /* the file's byte order is not this machine's */
  int fortran;      /* first index fastest */
  int ndim;
  long long shape[NPY_DIMS_MAX];
  long data_at;     /* the array's first byte in the file */
} npy_header;

/* What follows key in a header dict (after its ':' and blanks), or NULL. */
static const char *npy_value_of(const char *dict, const char *key)
{
  char quoted[2][32];
  snprintf(quoted[0], sizeof quoted[0], "'%s'", key);
  snprintf(quoted[1], sizeof quoted[1], "\"%s\"", key);
  for (int q = 0; q < 2; q++) {
    const char *at = strstr(dict, quoted[q]);
    if (!at) continue;
    at += strlen(quoted[q]);
    at += strspn(at, " \t");
    if (*at++ != ':') return NULL;
    return at + strspn(at, " \t");
  }
  return NULL;
}

static int host_little(void)
{
  const uint16_t one = 1;
  return *(const unsigned char *)&one == 1;
}

/* The dtype text (descr) into h: byte order, kind, size. */
static int npy_dtype(const char *descr, npy_header *h)
{
  char order = '=';
  if (strchr("<>|=", *descr) && *descr) order = *descr++;
  h->kind = *descr++;
  char *end;
  long size = strtol(descr, &end, 10);
  if (*end || end == descr) return 0;
  h->size = (int)size;
  const int ok = (h->kind == 'f' && (size == 4 || size == 8)) ||
                 ((h->kind == 'i' || h->kind == 'u') && (size == 1 || size == 2 || size == 4 || size == 8));
  h->swap = size > 1 && ((order == '<' && !host_little()) || (order == '>' && host_little()));
  return ok;
}

/* The shape tuple "(a, b, c)" (or "(a, b, c,)", "()") into h. */
static int npy_shape(const char *s, npy_header *h)
{
  if (*s++ != '(') return 0;
  h->ndim = 0;
  for (;;) {
    s += strspn(s, " \t");
    if (*s == ')') return 1;
    if (!isdigit((unsigned char)*s) || h->ndim == NPY_DIMS_MAX) return 0;
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (errno) return 0;
    h->shape[h->ndim++] = v;
    s = end + strspn(end, " \t");
    if (*s == ',') s++;
    else if (*s != ')') return 0;
  }
}

/* The shape as text, "(3, 4, 2)", into buf. */
static const char *shape_text(const npy_header *h, char *buf, size_t n)
{
  size_t used = (size_t)snprintf(buf, n, "(");
  for (int k = 0; k < h->ndim && used < n; k++)
    used += (size_t)snprintf(buf + used, n - used, "%s%lld", k ? ", " : "", h->shape[k]);
  if (used < n) snprintf(buf + used, n - used, "%s)", h->ndim == 1 ? "," : "");
  return buf;
}

static lw_status npy_read_header(FILE *f, const char *path, npy_header *h, lw_error *err)
{
  unsigned char head[12];
  if (fread(head, 1, 10, f) != 10) return lw_error_set(err, LW_EINPUT, "%s: the NumPy file ends in its header", path);
  const int major = head[6], minor = head[7];
  if (major < 1 || major > 3)
    return lw_error_set(err, LW_EINPUT, "%s: NumPy format version %d.%d: expected 1.0, 2.0 or 3.0 (np.save writes "
                        "them)", path, major, minor);
  unsigned long len = (unsigned long)head[8] | (unsigned long)head[9] << 8;
  long at = 10;
  if (major > 1) {
    if (fread(head + 10, 1, 2, f) != 2)
      return lw_error_set(err, LW_EINPUT, "%s: the NumPy file ends in its header", path);
    len |= (unsigned long)head[10] << 16 | (unsigned long)head[11] << 24;
    at = 12;
  }
  if (len > NPY_HEADER_MAX)
    return lw_error_set(err, LW_EINPUT, "%s: a NumPy header of %lu bytes: expected at most %ld (np.save writes "
                        "about 128)", path, len, NPY_HEADER_MAX);
  char *dict = malloc(len + 1);
  if (!dict) return lw_error_set(err, LW_ENOMEM, "%s: out of memory for the NumPy header", path);
  lw_status s = LW_OK;
  if (fread(dict, 1, len, f) != len) s = lw_error_set(err, LW_EINPUT, "%s: the NumPy file ends in its header", path);
  dict[len] = '\0';
  h->data_at = at + (long)len;
  const char *descr = s ? NULL : npy_value_of(dict, "descr"), *order = npy_value_of(dict, "fortran_order"),
             *shape = npy_value_of(dict, "shape");
  char dtype[24] = "";
  if (!s && (!descr || !order || !shape || strlen(dict) != len))
    s = lw_error_set(err, LW_EINPUT, "%s: a NumPy header without 'descr', 'fortran_order' and 'shape': expected a "
                     "file np.save wrote", path);
  else if (!s && (*descr == '[' || (*descr != '\'' && *descr != '"')))
    s = lw_error_set(err, LW_EINPUT, "%s: a NumPy array of records (a structured dtype): expected a plain array of "
                     "numbers", path);
  if (!s) {
    size_t n = strcspn(descr + 1, "'\"");
    snprintf(dtype, sizeof dtype, "%.*s", (int)(n < sizeof dtype ? n : sizeof dtype - 1), descr + 1);
    if (n >= sizeof dtype || !npy_dtype(dtype, h))
      s = lw_error_set(err, LW_EINPUT, "%s: a NumPy array of dtype '%s': expected floats (f4, f8) or integers "
                       "(i1..i8, u1..u8); %s", path, dtype,
                       strchr(dtype, 'c') ? "a complex u + iv is np.stack([z.real, z.imag], axis=-1)"
                                          : "arr.astype(float) makes one");
  }
  if (!s) {
    h->fortran = !strncmp(order, "True", 4);
    if (!h->fortran && strncmp(order, "False", 5))
      s = lw_error_set(err, LW_EINPUT, "%s: the NumPy header's fortran_order: expected True or False", path);
    else if (!npy_shape(shape, h))
      s = lw_error_set(err, LW_EINPUT, "%s: the NumPy header's shape: expected a tuple of whole numbers", path);
  }
  free(dict);
  return s;
}

/* The value of the size bytes at b (in the file's byte order). */
static double npy_number(const unsigned char *b, const npy_header *h)
{
  unsigned char v[8];
  for (int k = 0; k < h->size; k++) v[k] = h->swap ? b[h->size - 1 - k] : b[k];
  if (h->kind == 'f') {
    if (h->size == 4) {
      float x;
      memcpy(&x, v, 4);
      return x;
    }
    double x;
    memcpy(&x, v, 8);
    return x;
  }
  switch (h->size * (h->kind == 'i' ? -1 : 1)) {
  case -1: return (int8_t)v[0];
  case 1: return v[0];
  case -2: { int16_t x; memcpy(&x, v, 2); return x; }
  case 2: { uint16_t x; memcpy(&x, v, 2); return x; }
  case -4: { int32_t x; memcpy(&x, v, 4); return x; }
  case 4: { uint32_t x; memcpy(&x, v, 4); return x; }
  case -8: { int64_t x; memcpy(&x, v, 8); return (double)x; }
  default: { uint64_t x; memcpy(&x, v, 8); return (double)x; }
  }
}

static lw_grid2d *read_npy(FILE *f, const char *path, int ncomp, lw_error *err)
{
  npy_header h;
  char shape[160];
  if (npy_read_header(f, path, &h, err)) return NULL;
  const int fits = (h.ndim == 3 && h.shape[2] == ncomp) || (ncomp == 1 && h.ndim == 2);
  if (!fits) {
    lw_error_set(err, LW_EINPUT, "%s: a NumPy array of shape %s: expected %s", path,
                 shape_text(&h, shape, sizeof shape),
                 ncomp == 2 ? "(rows, columns, 2), u and v last (np.stack([u, v], axis=-1) makes one)"
                            : "(rows, columns)");
    return NULL;
  }
  const long long ny = h.shape[0], nx = h.shape[1];
  if (nx < 1 || ny < 1 || nx > LW_FIELDFILE_NODES_MAX || ny > LW_FIELDFILE_NODES_MAX ||
      nx * ny > LW_FIELDFILE_NODES_MAX) {
    lw_error_set(err, LW_EINPUT, "%s: a NumPy array of shape %s: expected at least 1 and at most %ld nodes "
                 "(rows x columns)", path, shape_text(&h, shape, sizeof shape), LW_FIELDFILE_NODES_MAX);
    return NULL;
  }
  const long long count = nx * ny * ncomp, bytes = count * h.size;
  struct stat st;
  if (!fstat(fileno(f), &st) && S_ISREG(st.st_mode) && st.st_size - h.data_at != bytes) {
    lw_error_set(err, LW_EINPUT, "%s: %lld bytes after the NumPy header, where its shape %s of %c%d holds %lld: %s",
                 path, (long long)(st.st_size - h.data_at), shape_text(&h, shape, sizeof shape), h.kind, h.size, bytes,
                 st.st_size - h.data_at < bytes ? "the file is cut short" : "expected the file to end there");
    return NULL;
  }
  lw_grid2d *g = lw_grid2d_new((int)nx, (int)ny, ncomp, 0.0, 0.0, 1.0, 1.0, err);
  if (!g) return NULL;
  unsigned char block[8192];
  long long done = 0;
  long long j = 0, i = 0, c = 0; /* (Fortran order: j fastest, then i, then c) */
  while (done < count) {
    const long long want = count - done < (long long)(sizeof block) / h.size ? count - done
                                                                             : (long long)(sizeof block) / h.size;
    if (fread(block, (size_t)h.size, (size_t)want, f) != (size_t)want) {
      lw_error_set(err, ferror(f) ? LW_EIO : LW_EINPUT, "%s: %s after %lld of its %lld values", path,
                   ferror(f) ? "read error" : "the NumPy file ends", done, count);
      lw_grid2d_free(g);
      return NULL;
    }
    for (long long k = 0; k < want; k++, done++) {
      const double v = npy_number(block + k * h.size, &h);
      if (!h.fortran) {
        g->data[done] = v;
        continue;
      }
      g->data[(j * nx + i) * ncomp + c] = v;
      if (++j == ny) {
        j = 0;
        if (++i == nx) {
          i = 0;
          c++;
        }
      }
    }
  }
  return g;
}

/* A word that names a value not finite, as np.savetxt and printf write it
** ("nan", "-inf", "Infinity"), into *v; 1 if it is one. */
static int nonfinite_word(const char *s, size_t len, double *v)
{
  int neg = 0;
  if (len && (*s == '-' || *s == '+')) {
    neg = *s == '-';
    s++;
    len--;
  }
  if ((len == 3 && !strncasecmp(s, "nan", 3))) {
    *v = NAN;
    return 1;
  }
  if ((len == 3 && !strncasecmp(s, "inf", 3)) || (len == 8 && !strncasecmp(s, "infinity", 8))) {
    *v = neg ? -INFINITY : INFINITY;
    return 1;
  }
  return 0;
}

/* The values grown as the text's rows come. */
typedef struct {
  double *v;
  size_t n, cap;
} values;

static int values_push(values *a, double v)
{
  if (a->n == a->cap) {
    size_t cap = a->cap ? 2 * a->cap : 1024;
    double *nv = realloc(a->v, cap * sizeof *nv);
    if (!nv) return -1;
    a->v = nv;
    a->cap = cap;
  }
  a->v[a->n++] = v;
  return 0;
}

/* A decimal token strtod reads whole but that is out of a double's range
** ("1e400", "1e-400", as NumPy reads them: infinite, 0) into *v; 1 if it
** is one.  (Hex, "0x10", strtod reads too: refused as everywhere.) */
static int out_of_range(const char *s, size_t len, double *v)
{
  char tok[64], *end;
  if (len >= sizeof tok || !len || !strchr("+-.0123456789", *s) || strspn(s, "+-.0123456789eE") < len) return 0;
  memcpy(tok, s, len);
  tok[len] = '\0';
  *v = strtod(tok, &end);
  return *end == '\0';
}

/* One row of text into a; its count of values into *got, or an error.
** Values are separated by blanks or by commas: a row with both a comma
** tight between two values and blanks alone between two others is refused,
** as "0,5 0,7" (decimal commas) read as four values silently doubled the
** nodes. */
static lw_status text_row(char *s, const char *path, long line, values *a, long *got, lw_error *err)
{
  *got = 0;
  int comma = 1;                /* (the line's start counts as one: a leading comma is an empty value) */
  int blanks = 0, tight = 0, blank_sep = 0, tight_sep = 0;
  for (;;) {
    const size_t skip = strspn(s, " \t");
    blanks |= skip > 0;
    s += skip;
    if (!*s) break;
    if (*s == ',') {
      if (comma) return lw_error_set(err, LW_EINPUT, "%s:%ld: an empty value after value %ld of the row: expected "
                                     "a number in every field (nan for a cell without one)", path, line, *got);
      tight = !blanks && s[1] != ' ' && s[1] != '\t';
      comma = 1;
      s++;
      continue;
    }
    if (*got) {
      blank_sep |= !comma;
      tight_sep |= comma && tight;
    }
    const size_t len = strcspn(s, " \t,");
    /* a value quoted as R's write.csv and pandas' QUOTE_NONNUMERIC write a
    ** row's name ("1") */
    const int quoted = len >= 2 && (*s == '"' || *s == '\'') && s[len - 1] == *s;
    const char *num = s + quoted;
    const size_t nl = len - 2 * (size_t)quoted;
    double v;
    if (!lw_number_parse_n(num, nl, &v) && !nonfinite_word(num, nl, &v) && !out_of_range(num, nl, &v)) {
      char unseen[96];
      const char *hint = memchr(s, ';', len) ? " (values separated by ';': expected blanks or commas, and '.' as "
                                               "the decimal point)"
                         : memchr(s, '\r', len) ? " (a carriage return inside the line: old Mac line ends? expected "
                                                  "LF or CRLF)"
                                                : lw_text_unseen_char(s, unseen, sizeof unseen);
      return lw_error_set(err, LW_EINPUT, "%s:%ld: value %ld of the row, '%.*s', is not a number%s", path, line,
                          *got + 1, (int)(len < 40 ? len : 40), s, hint);
    }
    if (a->n >= (size_t)LW_FIELDFILE_NODES_MAX * 2 || values_push(a, v))
      return a->n >= (size_t)LW_FIELDFILE_NODES_MAX * 2
             ? lw_error_set(err, LW_EINPUT, "%s:%ld: more than %ld nodes: expected at most that many", path, line,
                            LW_FIELDFILE_NODES_MAX)
             : lw_error_set(err, LW_ENOMEM, "%s:%ld: out of memory for the grid's values", path, line);
    ++*got;
    comma = blanks = 0;
    s += len;
  }
  if (blank_sep && tight_sep)
    return lw_error_set(err, LW_EINPUT, "%s:%ld: values separated by blanks, and by commas tight between digits "
                        "(decimal commas?): expected '.' as the decimal point, and blanks or commas between values",
                        path, line);
  return LW_OK;
}

static lw_grid2d *read_text(FILE *f, const char *path, int ncomp, lw_error *err)
{
  values a = {NULL, 0, 0};
  char *buf = NULL;
  size_t bcap = 0;
  long line = 0, first_line = 0, width = 0, rows = 0, len, got;
  lw_status s = LW_OK;
  while (!s && (len = lw_text_next_line(f, &buf, &bcap, &line)) >= 0) {
    char *hash = strchr(buf, '#');
    if (hash) *hash = '\0';
    if ((s = text_row(buf, path, line, &a, &got, err))) {
      /* (a header row of names, as a spreadsheet or ParaView writes one) */
      if (!rows && s == LW_EINPUT && strpbrk(buf, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ")) {
        const size_t used = strlen(err->msg);
        snprintf(err->msg + used, sizeof err->msg - used, "; a grid holds numbers only (a header row goes after "
                 "'#'), and a list of points 'x y u v' a line is read with scene.field_file_layout = points");
      }
      continue;
    }
    if (!got) continue;
    if (!width) {
      width = got;
      first_line = line;
      if (width % ncomp)
        s = lw_error_set(err, LW_EINPUT, "%s:%ld: %ld values in the first row: expected u v for each node, an even "
                         "count", path, line, width);
    } else if (got != width) {
      s = lw_error_set(err, LW_EINPUT, "%s:%ld: %ld values, where the first row (line %ld) has %ld: expected every "
                       "row as long", path, line, got, first_line, width);
    }
    if (!s && ++rows * (width / ncomp) > LW_FIELDFILE_NODES_MAX)
      s = lw_error_set(err, LW_EINPUT, "%s:%ld: more than %ld nodes: expected at most that many", path, line,
                       LW_FIELDFILE_NODES_MAX);
  }
  if (!s && len == -2 && errno == ENOMEM)
    s = lw_error_set(err, LW_ENOMEM, "%s:%ld: out of memory reading the line", path, line + 1);
  else if (!s && ferror(f)) s = lw_error_set(err, LW_EIO, "%s: read error", path);
  else if (!s && len == -2) s = lw_error_set(err, LW_EINPUT, "%s:%ld: " LW_TEXT_NUL_LINE, path, line);
  else if (!s && !rows)
    s = lw_error_set(err, LW_EINPUT, "%s: expected rows of numbers (%s), found none", path,
                     ncomp == 2 ? "u v for each node of a row" : "a value for each node of a row");
  /* four values a line over many lines is a list of points (gnuplot's
  ** "x y u v"), which read as a grid of two columns drew nonsense */
  else if (!s && ncomp == 2 && width == 4 && rows >= 8)
    s = lw_error_set(err, LW_EINPUT, "%s: a grid of 2 columns x %ld rows: a list of points 'x y u v' a line? "
                     "scene.field_file_layout = points reads one; a grid so narrow is refused as one", path, rows);
  free(buf);
  lw_grid2d *g = s ? NULL : lw_grid2d_new((int)(width / ncomp), (int)rows, ncomp, 0.0, 0.0, 1.0, 1.0, err);
  if (g) {
    /* the grid takes the values read (the same count: rows x width) */
    free(g->data);
    g->data = a.v;
    return g;
  }
  free(a.v);
  return NULL;
}

static int cmp_double(const void *pa, const void *pb)
{
  const double a = *(const double *)pa, b = *(const double *)pb;
  return (a > b) - (a < b);
}

/* The distinct values of v[0..n) (sorted in place) within tol of each other
** into u (n values); their count. */
static size_t distinct(double *v, size_t n, double tol, double *u)
{
  qsort(v, n, sizeof *v, cmp_double);
  size_t m = 0;
  for (size_t k = 0; k < n; k++)
    if (!m || v[k] - u[m - 1] > tol) u[m++] = v[k];
  return m;
}

/* The even spacing of the m sorted values u, or 0 where they are not evenly
** spaced to a thousandth of it, with *at the gap u[*at - 1] to u[*at]
** farthest from it and *even what it would be. */
static double even_spacing(const double *u, size_t m, size_t *at, double *even)
{
  if (m < 2) return 0.0;
  const double h = *even = (u[m - 1] - u[0]) / (double)(m - 1);
  double worst = 0.0;
  for (size_t k = 1; k < m; k++)
    if (fabs(u[k] - u[k - 1] - h) > worst) {
      worst = fabs(u[k] - u[k - 1] - h);
      *at = k;
    }
  return worst <= 1e-3 * h ? h : 0.0;
}

/* The index of the value of the m sorted u nearest v. */
static size_t nearest_of(const double *u, size_t m, double v)
{
  size_t lo = 0, hi = m; /* the first u >= v in [lo, hi] */
  while (lo < hi) {
    const size_t mid = lo + (hi - lo) / 2;
    if (u[mid] < v) lo = mid + 1;
    else hi = mid;
  }
  if (lo == m) return m - 1;
  return lo > 0 && v - u[lo - 1] < u[lo] - v ? lo - 1 : lo;
}

/* A name as a header holds it: a unit in brackets after it dropped ("x [m]",
** "u (m/s)"), in lower case. */
static void name_tidy(char *t)
{
  size_t len = strlen(t);
  while (len && (t[len - 1] == ' ' || t[len - 1] == '\t')) t[--len] = '\0';
  while (len && (t[len - 1] == ']' || t[len - 1] == ')')) {
    const char want = t[len - 1] == ']' ? '[' : '(';
    char *open = t + len - 1;
    while (open > t && *open != want) open--;
    if (open == t) break;
    for (len = (size_t)(open - t); len && (t[len - 1] == ' ' || t[len - 1] == '\t'); len--) {}
    t[len] = '\0';
  }
  for (char *k = t; *k; k++) *k = (char)tolower((unsigned char)*k);
}

/* The names of a header row into names (at most 64), after a Tecplot
** "VARIABLES =".  A row with commas (else semicolons) is a CSV's: a name
** is what lies between them, blanks and all ("X Position", pandas'
** "Unnamed: 0"), quoted or not, an empty one a column too (pandas' and R's
** unnamed index: ",x,y,u,v", "\"\",\"x\""), but for a last one after a
** trailing comma.  Else names lie between blanks, a quoted one whole ("X
** [m]"), a unit in brackets after an unquoted one part of it.  Their count. */
static long header_names(char *line, char *names[64])
{
  long n = 0;
  char *body = line + strspn(line, " \t");
  if (!strncasecmp(body, "variables", 9) && strchr(" \t=", body[9])) {
    body += 9 + strspn(body + 9, " \t");
    if (*body == '=') body++;
  }
  const char sep = strchr(body, ',') ? ',' : strchr(body, ';') ? ';' : 0;
  if (sep) {
    for (char *c = body; n < 64;) {
      char *end = strchr(c, sep);
      if (end) *end = '\0';
      char *t = c + strspn(c, " \t");
      if (*t == '"' || *t == '\'') {
        const char q = *t++;
        char *close = strchr(t, q);
        if (close) *close = '\0';
      }
      name_tidy(t);
      if (end || *t) names[n++] = t;
      if (!end) break;
      c = end + 1;
    }
    return n;
  }
  for (char *c = body; *c && n < 64;) {
    c += strspn(c, " \t=");
    if (!*c) break;
    char *t = c;
    if (*c == '"' || *c == '\'') {
      const char q = *c++;
      t = c;
      c += strcspn(c, q == '"' ? "\"" : "'");
    } else {
      c += strcspn(c, " \t=");
      /* a unit after the name, unquoted ("x [m] y [m]"): part of it */
      char *unit = c + strspn(c, " \t"), *close = NULL;
      if (*unit == '[' || *unit == '(') close = strchr(unit, *unit == '[' ? ']' : ')');
      if (close) {
        *c = '\0';
        c = close;
      }
    }
    const int more = *c != '\0';
    *c = '\0';
    c += more;
    name_tidy(t);
    if (*t) names[n++] = t;
  }
  return n;
}

/* Which column of a header row of names (header_names) holds x, y, u and v
** into col: x or points:0, y or points:1, u or vx, v or vy (and the words
** of Fluent's "X Velocity"), else the first vector NAME:0 and NAME:1 (or
** OpenFOAM's NAME_0 and NAME_1) besides the points (ParaView's "U:0",
** "U:1").  The count of names into *count; that count, or 0 where x, y, u
** and v are not all named. */
static long header_columns(const char *line, int col[4], long *count)
{
  char copy[4096], *names[64];
  snprintf(copy, sizeof copy, "%s", line);
  const long n = *count = header_names(copy, names);
  static const char *const own[4][10] = {
      {"x", "points:0", "coordinates:0", "points_0", "x-coordinate", "x coordinate", "x position", "lon",
       "longitude", NULL},
      {"y", "points:1", "coordinates:1", "points_1", "y-coordinate", "y coordinate", "y position", "lat",
       "latitude", NULL},
      {"u", "vx", "ux", "x velocity", "x-velocity", "velocity_x", "vel_x", "u velocity", NULL},
      {"v", "vy", "uy", "y velocity", "y-velocity", "velocity_y", "vel_y", "v velocity", NULL}};
  for (int c = 0; c < 4; c++) {
    col[c] = -1;
    for (long k = 0; k < n && col[c] < 0; k++)
      for (int w = 0; own[c][w] && col[c] < 0; w++)
        if (!strcmp(names[k], own[c][w])) col[c] = (int)k;
  }
  for (long k = 0; k < n && (col[2] < 0 || col[3] < 0); k++) {
    const size_t len = strlen(names[k]), stem = len - 2;
    const char mark = len >= 3 ? names[k][stem] : 0, first = len >= 3 ? names[k][stem + 1] : 0; /* ':0', '_0', '_x' */
    if ((mark != ':' && mark != '_') || (first != '0' && first != 'x') ||
        (stem == 6 && !strncmp(names[k], "points", 6)) || (stem == 11 && !strncmp(names[k], "coordinates", 11)))
      continue;
    for (long m = 0; m < n; m++)
      if (strlen(names[m]) == stem + 2 && !strncmp(names[m], names[k], stem) && names[m][stem] == mark &&
          names[m][stem + 1] == (first == '0' ? '1' : 'y')) {
        col[2] = (int)k;
        col[3] = (int)m;
      }
  }
  return col[0] >= 0 && col[1] >= 0 && col[2] >= 0 && col[3] >= 0 ? n : 0;
}

/* A list of points, "x y u v" a line, onto the regular grid they sample:
** rows by ascending y, hx and hy the spacings, (x0, y0) the least x and y.
** Lines of words before the first point are a header row, whose names say
** the columns (header_columns), or a title (Tecplot's TITLE and ZONE). */
static lw_grid2d *read_points(FILE *f, const char *path, int ncomp, lw_error *err)
{
  values a = {NULL, 0, 0};
  char *buf = NULL;
  size_t bcap = 0;
  long line = 0, len, got, rows = 0, width = 4, *at = NULL; /* at: each point's line */
  int col[4] = {0, 1, 2, 3}, understood = 0;
  /* the last line of words that named not every column, as a header
  ** row might: its line, its count of names and which it named */
  long odd_line = 0, odd_count = 0;
  int odd_named[4] = {-1, -1, -1, -1}, odd_header = 0;
  lw_status s = LW_OK;
  while (!s && (len = lw_text_next_line(f, &buf, &bcap, &line)) >= 0) {
    char *hash = strchr(buf, '#');
    if (hash) *hash = '\0';
    const size_t before = a.n;
    lw_error e2;
    if ((s = text_row(buf, path, line, &a, &got, &e2))) {
      int named[4];
      long count;
      const long names = header_columns(buf, named, &count);
      if (!rows && s == LW_EINPUT && strpbrk(buf, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ")) {
        if (names) {
          width = names;
          memcpy(col, named, sizeof col);
          understood = 1;
        } else {
          odd_line = line;
          odd_count = count;
          memcpy(odd_named, named, sizeof odd_named);
          /* a header more than a title: it names two of the columns (a
          ** title's words, "Wake flow, Re 100", "flow in x direction",
          ** name one at most) */
          odd_header = (named[0] >= 0) + (named[1] >= 0) + (named[2] >= 0) + (named[3] >= 0) >= 2;
        }
        a.n = before;
        s = LW_OK;
        continue;
      }
      *err = e2;
      break;
    }
    if (!got) continue;
    /* ("x,y,speed,angle": speed taken for u, angle for v, without a word) */
    if (!rows && !understood && odd_header && odd_count == got) {
      static const char *const what[4] = {"x", "y", "u", "v"};
      char missing[32] = "";
      int left = 0;
      for (int c = 0; c < 4; c++) left += odd_named[c] < 0;
      for (int c = 0; c < 4; c++)
        if (odd_named[c] < 0)
          snprintf(missing + strlen(missing), sizeof missing - strlen(missing), "%s%s", what[c],
                   --left > 1 ? ", " : left == 1 ? " or " : "");
      s = lw_error_set(err, LW_EINPUT, "%s:%ld: a header row of %ld names, none of them %s: expected names x, y, u "
                       "and v (or Points:0 and :1, vx and vy, a vector's NAME:0 and NAME:1: docs/FORMATS.md, \"Field "
                       "files\"), or the line made a comment with '#' to take the columns as x y u v",
                       path, odd_line, odd_count, missing);
      break;
    }
    if (got != width)
      s = lw_error_set(err, LW_EINPUT, "%s:%ld: %ld values: expected %ld a line (%s)", path, line, got, width,
                       width == 4 ? "x y u v" : "as the header row names");
    long *grown = s || (rows & (rows - 1)) ? at : realloc(at, (rows ? 2 * (size_t)rows : 1) * sizeof *at);
    if (!s && !grown) s = lw_error_set(err, LW_ENOMEM, "%s: out of memory for the points", path);
    if (!s) {
      at = grown;
      at[rows] = line;
    }
    rows++;
  }
  if (!s && len == -2) s = lw_error_set(err, errno == ENOMEM ? LW_ENOMEM : LW_EINPUT, "%s:%ld: %s", path, line,
                                        errno == ENOMEM ? "out of memory reading the line" : LW_TEXT_NUL_LINE);
  else if (!s && ferror(f)) s = lw_error_set(err, LW_EIO, "%s: read error", path);
  else if (!s && rows <= 0) s = lw_error_set(err, LW_EINPUT, "%s: expected points 'x y %s' a line, found none", path,
                                             ncomp == 2 ? "u v" : "value");
  free(buf);
  const size_t n = s ? 0 : a.n / (size_t)width;
  double *xs = n ? malloc(4 * n * sizeof *xs) : NULL;
  if (!s && !xs) s = lw_error_set(err, LW_ENOMEM, "%s: out of memory for %zu points", path, n);
  lw_grid2d *g = NULL;
  if (!s) {
    double *ys = xs + n, *ux = xs + 2 * n, *uy = xs + 3 * n;
    for (size_t k = 0; k < n; k++) {
      xs[k] = a.v[k * (size_t)width + (size_t)col[0]];
      ys[k] = a.v[k * (size_t)width + (size_t)col[1]];
      if (!isfinite(xs[k]) || !isfinite(ys[k]))
        s = lw_error_set(err, LW_EINPUT, "%s:%ld: the point at (%g, %g): expected finite coordinates", path, at[k],
                         xs[k], ys[k]);
    }
    size_t nx = 0, ny = 0;
    if (!s) {
      double lo = xs[0], hi = xs[0], ylo = ys[0], yhi = ys[0];
      for (size_t k = 0; k < n; k++) lo = fmin(lo, xs[k]), hi = fmax(hi, xs[k]), ylo = fmin(ylo, ys[k]),
                                    yhi = fmax(yhi, ys[k]);
      nx = distinct(xs, n, 1e-9 * fmax(hi - lo, 1e-300), ux);
      ny = distinct(ys, n, 1e-9 * fmax(yhi - ylo, 1e-300), uy);
    }
    /* each point's node, by its nearest distinct x and y, so that a point
    ** there twice or a node with none is named by its line and place */
    unsigned char *seen = NULL;
    size_t *node = NULL;
    if (!s && nx * ny <= (size_t)LW_FIELDFILE_NODES_MAX) {
      seen = calloc(nx * ny, 1);
      node = malloc(n * sizeof *node);
      if (!seen || !node) s = lw_error_set(err, LW_ENOMEM, "%s: out of memory for %zu points", path, n);
      for (size_t k = 0; !s && k < n; k++) {
        const double *pt = a.v + k * (size_t)width;
        node[k] = nearest_of(uy, ny, pt[col[1]]) * nx + nearest_of(ux, nx, pt[col[0]]);
        if (!seen[node[k]]++) continue;
        size_t first = 0;
        while (node[first] != node[k]) first++;
        s = lw_error_set(err, LW_EINPUT, "%s:%ld: the point at (%g, %g) is there twice (first on line %ld): expected "
                         "every node of a regular grid once", path, at[k], pt[col[0]], pt[col[1]], at[first]);
      }
      /* a column or row of few points is a mistyped coordinate more likely
      ** than many nodes missing ("2.0001" for 2 was said to leave a node at
      ** (2.0001, 0) without a point) */
      if (!s && n < nx * ny) {
        size_t *per = calloc(nx + ny, sizeof *per), few = SIZE_MAX, which = 0;
        if (!per) s = lw_error_set(err, LW_ENOMEM, "%s: out of memory for %zu points", path, n);
        for (size_t k = 0; per && k < n; k++) per[node[k] % nx]++, per[nx + node[k] / nx]++;
        /* (a column of few points beside another far closer than the grid's
        ** spacing: a hole in the grid, an obstacle's, has its columns
        ** evenly spaced and was said mistyped) */
        for (size_t c = 0; per && c < nx + ny; c++) {
          const double *u = c < nx ? ux : uy;
          const size_t m = c < nx ? nx : ny, idx = c < nx ? c : c - nx;
          const double even = m > 1 ? (u[m - 1] - u[0]) / (double)(m - 1) : 0.0,
                       near = fmin(idx > 0 ? u[idx] - u[idx - 1] : HUGE_VAL,
                                   idx + 1 < m ? u[idx + 1] - u[idx] : HUGE_VAL);
          if (per[c] < few && 2 * per[c] < (c < nx ? ny : nx) && near < 0.1 * even) few = per[c], which = c;
        }
        const int row = which >= nx;
        for (size_t k = 0; per && few != SIZE_MAX && k < n; k++)
          if (row ? node[k] / nx == which - nx : node[k] % nx == which) {
            const double *pt = a.v + k * (size_t)width;
            s = lw_error_set(err, LW_EINPUT, "%s:%ld: the point at (%g, %g) lies off the grid the others make: its %s "
                             "is that of %zu point%s, where a %s of the grid holds %zu (a mistyped coordinate?)", path,
                             at[k], pt[col[0]], pt[col[1]], row ? "y" : "x", few, few == 1 ? "" : "s",
                             row ? "row" : "column", row ? nx : ny);
            break;
          }
        free(per);
      }
      for (size_t m = 0; !s && n < nx * ny && m < nx * ny; m++)
        if (!seen[m])
          s = lw_error_set(err, LW_EINPUT, "%s: no point at (%g, %g), a node of the %zu x %zu grid the other points "
                           "make: expected every node of a regular grid once", path, ux[m % nx], uy[m / nx], nx, ny);
    }
    double hx = 0, hy = 0, even = 0;
    size_t gap = 0;
    if (!s && nx * ny != n)
      s = lw_error_set(err, LW_EINPUT, "%s: %zu points over %zu distinct x and %zu distinct y: expected every node of "
                       "a regular grid once (%zu points)", path, n, nx, ny, nx * ny);
    else if (!s && ((nx > 1 && !(hx = even_spacing(ux, nx, &gap, &even))) ||
                    (ny > 1 && !(hy = even_spacing(uy, ny, &gap, &even))))) {
      const int in_x = nx > 1 && !hx;
      const double *u = in_x ? ux : uy;
      s = lw_error_set(err, LW_EINPUT, "%s: the %s spacing is uneven: %s = %g to %g is %g apart, where even spacing "
                       "is %g: expected a regular grid (a stretched one resampled to even spacing)", path,
                       in_x ? "x" : "y", in_x ? "x" : "y", u[gap - 1], u[gap], u[gap] - u[gap - 1], even);
    }
    if (!s && nx * ny > (size_t)LW_FIELDFILE_NODES_MAX)
      s = lw_error_set(err, LW_EINPUT, "%s: %zu points: expected at most %ld", path, n, LW_FIELDFILE_NODES_MAX);
    if (!s) {
      if (!hx) hx = hy ? hy : 1.0;
      if (!hy) hy = hx;
      g = lw_grid2d_new((int)nx, (int)ny, ncomp, ux[0], uy[0], hx, hy, err);
    }
    for (size_t k = 0; g && k < n; k++) {
      double *d = g->data + node[k] * (size_t)ncomp;
      for (int c = 0; c < ncomp; c++) d[c] = a.v[k * (size_t)width + (size_t)col[2 + c]];
    }
    free(seen);
    free(node);
    if (s) {
      lw_grid2d_free(g);
      g = NULL;
    }
  }
  free(xs);
  free(a.v);
  free(at);
  return g;
}

lw_grid2d *lw_fieldfile_read(const char *path, int ncomp, int points, lw_error *err)
{
  if (lw_text_plain_file(path, err)) return NULL;
  FILE *f = fopen(path, "rb");
  if (!f) {
    lw_error_set(err, LW_EINPUT, "%s: cannot open the field file: %s", path, strerror(errno));
    return NULL;
  }
  unsigned char head[16];
  const size_t n = fread(head, 1, sizeof head, f);
  rewind(f);
  int readable;
  const char *picture = lw_image_kind(head, n, &readable);
  lw_grid2d *g = NULL;
  if (n >= 6 && !memcmp(head, NPY_MAGIC, 6)) {
    if (points) lw_error_set(err, LW_EINPUT, "%s: a NumPy array, where scene.field_file_layout = points reads a text "
                             "list of points 'x y u v': expected grid for an array", path);
    else g = read_npy(f, path, ncomp, err);
  } else if (n >= 4 && !memcmp(head, "PK\x03\x04", 4)) {
    lw_error_set(err, LW_EINPUT, "%s: a zip archive (np.savez writes one): expected one array, as np.save or "
                 "np.savetxt writes it", path);
  } else if (picture) {
    lw_error_set(err, LW_EINPUT, "%s: %s picture: expected a grid of numbers (.npy or text); a picture's own field "
                 "is scene.field = etf or gradient", path, picture);
  } else {
    g = points && ncomp == 2 ? read_points(f, path, ncomp, err) : read_text(f, path, ncomp, err);
  }
  fclose(f);
  return g;
}
