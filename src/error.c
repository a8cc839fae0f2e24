/* error.c -- status codes and messages (see error.h). */
#include "linewise/error.h"

#include <gsl/gsl_errno.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

lw_status lw_error_set(lw_error *err, lw_status code, const char *fmt, ...)
{
  if (err) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
    /* a message quotes input, which may be binary: no control character
    ** reaches the terminal, and the message stays one line; nor does a C1
    ** control of UTF-8 (U+0085 ends a line too) or a bidi override (U+202E
    ** shows the rest of a file's name reversed), each one '?' */
    unsigned char *to = (unsigned char *)err->msg;
    for (const unsigned char *c = to; *c; c++) {
      const int c1 = c[0] == 0xc2 && c[1] >= 0x80 && c[1] <= 0x9f;
      const int bidi = c[0] == 0xe2 && ((c[1] == 0x80 && c[2] >= 0xaa && c[2] <= 0xae) ||
                                        (c[1] == 0x81 && c[2] >= 0xa6 && c[2] <= 0xa9));
      if (*c < 0x20 || *c == 0x7f || c1 || bidi) *to++ = '?';
      else *to++ = *c;
      c += c1 ? 1 : bidi ? 2 : 0;
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
