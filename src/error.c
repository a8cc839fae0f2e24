/* error.c -- status codes and messages (see error.h). */
#include "linewise/error.h"

#include <gsl/gsl_errno.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

int lw_utf8_at(const unsigned char *c, unsigned *cp)
{
  const int len = c[0] >= 0xc2 && c[0] <= 0xdf ? 2 : c[0] >= 0xe0 && c[0] <= 0xef ? 3 : c[0] >= 0xf0 && c[0] <= 0xf4 ? 4
                                                                                                                   : 0;
  unsigned v = c[0] & (len == 2 ? 0x1fu : len == 3 ? 0x0fu : 0x07u);
  for (int k = 1; k < len; k++) {
    if ((c[k] & 0xc0) != 0x80) return 0;
    v = v << 6 | (c[k] & 0x3fu);
  }
  if (!len || (len == 3 && v < 0x800) || (len == 4 && (v < 0x10000 || v > 0x10ffff)) || (v >= 0xd800 && v <= 0xdfff))
    return 0;
  *cp = v;
  return len;
}

/* What a terminal takes for a command or a line's end, or shows text
** around reversed: C1 controls, the bidi marks and overrides, the line and
** paragraph separators. */
static int unseen_control(unsigned cp)
{
  return (cp >= 0x80 && cp <= 0x9f) || (cp >= 0x202a && cp <= 0x202e) || (cp >= 0x2066 && cp <= 0x2069) ||
         cp == 0x200e || cp == 0x200f || cp == 0x061c || cp == 0x2028 || cp == 0x2029;
}

lw_status lw_error_set(lw_error *err, lw_status code, const char *fmt, ...)
{
  if (err) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
    /* a message quotes input, which may be binary: no control character
    ** reaches the terminal, and the message stays one line; nor does a C1
    ** control, of UTF-8 or a lone byte of an 8-bit terminal's (U+0085 ends
    ** a line too, 0x9B begins a command), or a bidi override (U+202E shows
    ** the rest of a file's name reversed), each one '?'; a byte that begins
    ** no character otherwise (a Latin-1 name's) stays */
    unsigned char *to = (unsigned char *)err->msg;
    for (const unsigned char *c = to; *c;) {
      unsigned cp = *c;
      const int len = *c < 0x80 ? 1 : lw_utf8_at(c, &cp);
      const int bad = len ? cp < 0x20 || cp == 0x7f || unseen_control(cp) : *c <= 0x9f;
      if (bad) *to++ = '?';
      else
        for (int k = 0; k < (len ? len : 1); k++) *to++ = c[k];
      c += len ? len : 1;
    }
    *to = '\0';
    err->code = code;
  }
  return code;
}

void lw_error_clear(lw_error *err)
{
  if (err) {
    err->code = LW_OK;
    err->msg[0] = '\0';
  }
}

int lw_error_exit_status(lw_status code)
{
  switch (code) {
  case LW_OK: return 0;
  case LW_EINPUT:
  case LW_EUSAGE: return 2;
  default: return 1;
  }
}

void lw_gsl_handler(const char *reason, const char *file, int line, int gsl_errno)
{
  if (gsl_errno == GSL_ENOMEM) return;
  fprintf(stderr, "linewise: internal error: GSL: %s (%s:%d, %s); please report it\n", reason, file, line,
          gsl_strerror(gsl_errno));
  abort();
}

static pthread_mutex_t gsl_lock = PTHREAD_MUTEX_INITIALIZER;
static int gsl_off_depth;
static gsl_error_handler_t *gsl_saved;

void lw_gsl_off(void)
{
  pthread_mutex_lock(&gsl_lock);
  if (gsl_off_depth++ == 0) gsl_saved = gsl_set_error_handler_off();
  pthread_mutex_unlock(&gsl_lock);
}

void lw_gsl_on(void)
{
  pthread_mutex_lock(&gsl_lock);
  if (--gsl_off_depth == 0) gsl_set_error_handler(gsl_saved);
  pthread_mutex_unlock(&gsl_lock);
}
