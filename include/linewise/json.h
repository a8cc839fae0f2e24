/*
** json.h -- a small streaming JSON writer (summary.json); no parser.
**
** Calls write straight to the FILE; the struct only remembers the nesting so
** that commas, newlines and the 2-space indentation come out right:
**
**     lw_json j;
**     lw_json_init(&j, f);
**     lw_json_begin_object(&j);
**     lw_json_key(&j, "sweeps"); lw_json_int(&j, 1000);
**     lw_json_key(&j, "energy"); lw_json_begin_array(&j);
**     lw_json_number(&j, 1.5); lw_json_end_array(&j);
**     lw_json_end_object(&j);
**     lw_json_finish(&j, &err);
** gives
**     {
**       "sweeps": 1000,
**       "energy": [
**         1.5
**       ]
**     }
** Empty containers are written "{}" and "[]".
**
** Numbers: finite doubles with %.17g, which reads back to the same double.
** JSON has no infinity or NaN, so non-finite values are written as null
** (readers see a missing value rather than a broken file).  Numbers assume
** the C locale's decimal point (linewise never calls setlocale).
**
** Strings are written as given (UTF-8 expected); '"', '\' and control
** characters are escaped.
**
** Misuse (a key outside an object, a value in an object without its key, an
** end that does not match its begin, nesting deeper than LW_JSON_MAX_DEPTH)
** is remembered and reported by lw_json_finish; the calls then write nothing
** more.
*/
#ifndef LINEWISE_JSON_H
#define LINEWISE_JSON_H

#include <stdio.h>

#include "linewise/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_JSON_MAX_DEPTH 32

typedef struct {
  FILE *f;
  int depth;                         /* open containers */
  char kind[LW_JSON_MAX_DEPTH];      /* '{' or '[' per open container */
  int members[LW_JSON_MAX_DEPTH];    /* values written so far in it */
  int after_key;                     /* a key was written, its value is next */
  int done;                          /* the top-level value is complete */
  const char *misuse;                /* first misuse, or NULL */
} lw_json;

void lw_json_init(lw_json *j, FILE *f);

void lw_json_begin_object(lw_json *j);
void lw_json_end_object(lw_json *j);
void lw_json_begin_array(lw_json *j);
void lw_json_end_array(lw_json *j);

/* The name of the next member of the current object. */
void lw_json_key(lw_json *j, const char *name);

void lw_json_number(lw_json *j, double v);  /* non-finite -> null */
void lw_json_int(lw_json *j, long long v);
void lw_json_string(lw_json *j, const char *s);
void lw_json_bool(lw_json *j, int v);
void lw_json_null(lw_json *j);

/* Ends the document with a newline.  LW_ERUN if it was misused or is not
** complete (a container still open), LW_EIO if the stream has an error;
** the file itself is not closed. */
lw_status lw_json_finish(lw_json *j, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
