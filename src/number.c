/*
** number.c -- the strict number parser (number.h).
**
** The syntax is checked by hand before strtod sees the text: strtod alone
** takes hex, "inf", "nan", leading blanks and stops silently at trailing
** garbage.  Within the checked syntax strtod does the rounding; it follows
** LC_NUMERIC, which lw_number_locale_ok holds to a '.' point.
*/
#include "linewise/number.h"

#include <errno.h>
#include <langinfo.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static int is_digit(char c) { return c >= '0' && c <= '9'; }

lw_status lw_number_locale_ok(lw_error *err)
{
  /* nl_langinfo is thread-safe where localeconv and setlocale's name are not */
  const char *point = nl_langinfo(RADIXCHAR);
  if (point && !strcmp(point, ".")) return LW_OK;
  return lw_error_set(err, LW_EUSAGE, "the locale's numbers (LC_NUMERIC) take '%s' as the decimal point, and linewise "
                      "reads and writes numbers with '.': a program calling into it sets LC_NUMERIC to \"C\" first "
                      "(setlocale(LC_NUMERIC, \"C\"))", point ? point : "");
}

int lw_number_parse_n(const char *s, size_t len, double *out)
{
  char buf[128];
  size_t i = 0, digits = 0;
  if (len == 0 || len >= sizeof buf) return 0; /* no real number needs more than 17 digits and an exponent */
  if (s[i] == '+' || s[i] == '-') i++;
  for (; i < len && is_digit(s[i]); i++) digits++;
  if (i < len && s[i] == '.')
    for (i++; i < len && is_digit(s[i]); i++) digits++;
  if (!digits) return 0;
  if (i < len && (s[i] == 'e' || s[i] == 'E')) {
    size_t exp_digits = 0;
    i++;
    if (i < len && (s[i] == '+' || s[i] == '-')) i++;
    for (; i < len && is_digit(s[i]); i++) exp_digits++;
    if (!exp_digits) return 0;
  }
  if (i != len) return 0;
  memcpy(buf, s, len);
  buf[len] = '\0';
  errno = 0;
  char *end;
  double v = strtod(buf, &end);
  /* ERANGE also flags underflow, which is fine down to the subnormals (a
  ** file's %.17g of one reads back); a number that is not 0 and reads as 0
  ** is refused, as overflow is: "1e-400" made moves.fixed_count 0 */
  if (*end || !isfinite(v) || (errno == ERANGE && (fabs(v) > 1.0 || v == 0.0))) return 0;
  *out = v;
  return 1;
}

int lw_number_parse(const char *s, double *out) { return lw_number_parse_n(s, strlen(s), out); }

char *lw_number_format_exact(char *buf, size_t n, double v)
{
  snprintf(buf, n, "%.15g", v);
  if (strtod(buf, NULL) != v) snprintf(buf, n, "%.17g", v);
  return buf;
}

void lw_number_print_exact(FILE *f, double v)
{
  char buf[32];
  fputs(lw_number_format_exact(buf, sizeof buf, v), f);
}

int lw_number_parse_whole(const char *s, double lo, double hi, long long *out)
{
  double v;
  if (!lw_number_parse(s, &v) || v != floor(v) || v < lo || v > hi) return 0;
  *out = (long long)v;
  return 1;
}

int lw_number_separator_hint(const char *s, int whole, char *hint, size_t n)
{
  static const char digits[] = "0123456789";
  const char *p = s + (*s == '+' || *s == '-');
  const size_t lead = strspn(p, digits);
  const char sep = p[lead] == '.' || p[lead] == ',' ? p[lead] : 0;
  int groups = 0, fraction = 0;
  /* (a leading group of zeros is 0 in every writing: "0.000" reads) */
  if (sep && lead >= 1 && lead <= 3 && strspn(p, "0") < lead) {
    const char *q = p + lead;
    for (; *q == sep && strspn(q + 1, digits) == 3; q += 4) groups++;
    /* and the other mark after them, a fraction: "1,000.5", "1.000,5" */
    const size_t tail = strlen(q + 1);
    if (groups && *q == (sep == '.' ? ',' : '.') && tail && strspn(q + 1, digits) == tail) {
      q += 1 + tail;
      fraction = 1;
    }
    if (*q) groups = 0;
  }
  const char *comma = strchr(s, ',');
  if (groups && (whole || groups > 1 || fraction))
    snprintf(hint, n, " (a thousands separator? write 1000, not 1%c000)", sep);
  else if (comma && comma > s && is_digit(comma[-1]) && is_digit(comma[1]))
    snprintf(hint, n, " (a decimal comma? numbers take a point: 0.5, not 0,5)");
  else if (n) *hint = '\0';
  return groups && whole && !fraction;
}

int lw_text_empty_field(const char *s)
{
  int comma = 1, empty = 0; /* the line's start counts as a comma */
  for (; *s; s++) {
    if (*s == ' ' || *s == '\t' || *s == '\r' || *s == '\n') continue;
    if (*s != ',' && empty) return 1; /* trailing empty fields ("x,y,z,,,": blank normals) are none */
    empty |= *s == ',' && comma;
    comma = *s == ',';
  }
  return 0;
}

int lw_number_list(const char *s, int commas, double *out, int max)
{
  /* ("0,,5" read as 0 5) */
  if (commas == 2 && lw_text_empty_field(s)) return -3;
  const char *sep = commas ? " \t," : " \t";
  /* a comma with no blank beside it between two numbers ("0,5"), and a
  ** separator of blanks alone, both in one list */
  int tight = 0, blank = 0, n = 0;
  for (;;) {
    size_t gap = strspn(s, sep);
    if (n > 0 && gap && s[gap]) {
      if (!memchr(s, ',', gap)) blank = 1;
      else if (gap == 1) tight = 1;
    }
    s += gap;
    if (!*s) break;
    size_t len = strcspn(s, sep);
    double v;
    if (!lw_number_parse_n(s, len, &v)) return -1;
    if (n < max) out[n] = v;
    n++;
    s += len;
  }
  return commas == 2 && tight && blank ? -2 : n;
}

const char *lw_number_list_hint(int count)
{
  return count == -2   ? " (a comma between digits, and blanks between numbers: decimal commas? numbers take a point, "
                         "0.5 not 0,5; a list takes blanks, commas or ', ' between its numbers)"
         : count == -3 ? " (an empty value between two commas: expected a number in every field)"
                       : "";
}

void lw_text_drop_bom(char *s)
{
  if ((unsigned char)s[0] == 0xEF && (unsigned char)s[1] == 0xBB && (unsigned char)s[2] == 0xBF)
    memmove(s, s + 3, strlen(s + 3) + 1);
}

ssize_t lw_text_getline(char **buf, size_t *cap, FILE *f)
{
  size_t len = 0;
  int c;
  flockfile(f);
  while (len < LW_TEXT_LINE_MAX && (c = getc_unlocked(f)) != EOF) {
    if (len + 2 > *cap) {
      size_t grown = *cap < 128 ? 128 : 2 * *cap;
      char *b = realloc(*buf, grown);
      if (!b) {
        funlockfile(f);
        errno = ENOMEM;
        return -2;
      }
      *buf = b;
      *cap = grown;
    }
    (*buf)[len++] = (char)c;
    if (c == '\n' || c == '\0') break;
  }
  funlockfile(f);
  /* (a read error wins over the part of a line before it, which a reader
  ** would parse as a whole one and blame the file for) */
  if (!len || ferror(f)) return -1;
  (*buf)[len] = '\0';
  return (ssize_t)len;
}

/* A no-break space that a word processor put after "50" showed as "got
** '50 '", and ordinary trailing blanks are accepted, so the message names it. */
const char *lw_text_unseen_char(const char *value, char *buf, size_t n)
{
  static const struct { const char *utf8, *name; unsigned code; } unseen[] = {
    {"\xc2\xa0", "a no-break space", 0xa0},         {"\xe2\x80\xaf", "a narrow no-break space", 0x202f},
    {"\xe2\x80\x89", "a thin space", 0x2009},       {"\xe3\x80\x80", "an ideographic space", 0x3000},
    {"\xe2\x80\x8b", "a zero-width space", 0x200b}, {"\xef\xbb\xbf", "a byte-order mark", 0xfeff},
    {"\xe2\x81\xa0", "a word joiner", 0x2060},    {"\xe2\x80\x82", "an en space", 0x2002},
    {"\xe2\x80\x83", "an em space", 0x2003},       {"\xe2\x80\x87", "a figure space", 0x2007},
  };
  buf[0] = '\0';
  for (const char *c = value; *c; c++)
    for (size_t k = 0; k < sizeof unseen / sizeof unseen[0]; k++)
      if (!strncmp(c, unseen[k].utf8, strlen(unseen[k].utf8))) {
        snprintf(buf, n, " (byte %zu is %s, U+%04X: delete it or type a plain space)", (size_t)(c - value) + 1,
                 unseen[k].name, unseen[k].code);
        return buf;
      }
  /* look-alikes of what a number is written with: a word processor's minus
  ** sign, and the full-width forms of an East Asian input method ("２０") */
  for (const unsigned char *c = (const unsigned char *)value; *c; c++) {
    const size_t at = (size_t)(c - (const unsigned char *)value) + 1;
    if (c[0] == 0xe2 && c[1] == 0x88 && c[2] == 0x92) {
      snprintf(buf, n, " (byte %zu is a minus sign, U+2212: type '-')", at);
      return buf;
    }
    if (c[0] == 0xef && ((c[1] == 0xbc && c[2] >= 0x81 && c[2] <= 0xbf) || (c[1] == 0xbd && c[2] >= 0x80 &&
                                                                            c[2] <= 0x9e))) {
      const unsigned code = 0xf000u | (c[1] & 0x3fu) << 6 | (c[2] & 0x3fu);
      snprintf(buf, n, " (byte %zu is a full-width '%c', U+%04X: type '%c')", at, (char)(code - 0xfee0),
               code, (char)(code - 0xfee0));
      return buf;
    }
  }
  /* a control character or a byte that is no UTF-8 (0xFF, a Latin-1 letter)
  ** shows as nothing or as garbage in the message: its number, then */
  for (size_t i = 0; value[i];) {
    const unsigned char b = (unsigned char)value[i];
    unsigned cp;
    const int len = b < 0x80 ? 1 : lw_utf8_at((const unsigned char *)value + i, &cp);
    /* (a Latin-1 scene's "Über" was told to delete its Ü; a CRLF script's
    ** value to delete its CR) */
    if (!len && b >= 0x80) {
      snprintf(buf, n, " (byte %zu is 0x%02X, not UTF-8: a file saved as Latin-1 or 'ANSI'? save it as UTF-8)", i + 1,
               b);
      return buf;
    }
    if (b == '\r') {
      snprintf(buf, n, " (byte %zu is 0x0D, a CR: a file saved with CRLF line ends? save it with LF)", i + 1);
      return buf;
    }
    if (!len || (b < 0x20 && b != '\t') || b == 0x7f) {
      snprintf(buf, n, " (byte %zu is 0x%02X, not a character of text: delete it)", i + 1, b);
      return buf;
    }
    i += (size_t)len;
  }
  return buf;
}

lw_status lw_text_plain_file(const char *path, lw_error *err)
{
  struct stat sb;
  /* (a terminal, /dev/ptmx, held a read for ever as a FIFO did) */
  if (stat(path, &sb) || S_ISREG(sb.st_mode)) return LW_OK;
  return lw_error_set(err, LW_EINPUT, "%s: a %s, not a file: expected a file, which linewise reads whole", path,
                      S_ISFIFO(sb.st_mode)   ? "FIFO (named pipe)"
                      : S_ISSOCK(sb.st_mode) ? "socket"
                      : S_ISDIR(sb.st_mode)  ? "folder"
                      : S_ISCHR(sb.st_mode)  ? "character device (a terminal, /dev/null, /dev/zero)"
                                             : "block device");
}

long lw_text_next_line(FILE *f, char **buf, size_t *cap, long *line)
{
  errno = 0;
  ssize_t len = lw_text_getline(buf, cap, f);
  if (len < 0) return len == -2 || ferror(f) ? -2 : -1;
  ++*line;
  if (memchr(*buf, '\0', (size_t)len)) return -2;
  if (*line == 1) {
    lw_text_drop_bom(*buf);
    len = (ssize_t)strlen(*buf);
  }
  while (len > 0 && ((*buf)[len - 1] == '\n' || (*buf)[len - 1] == '\r')) (*buf)[--len] = '\0';
  return (long)len;
}
