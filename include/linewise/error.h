/*
** error.h -- one status enum and a message buffer that travels with it.
**
** Library code never prints and never exits: it fills an lw_error and returns
** its code.  The command line turns the message into one line on stderr and the
** code into an exit status (2 for bad input or usage, 1 for failures while
** running).  Messages name the file, line and key where the input was bad.
*/
#ifndef LINEWISE_ERROR_H
#define LINEWISE_ERROR_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
  LW_OK = 0,
  LW_EINPUT,    /* bad input: a file, a key, a value (exit 2) */
  LW_EUSAGE,    /* bad command line (exit 2) */
  LW_ENOMEM,    /* allocation failed (exit 1) */
  LW_EIO,       /* reading or writing a file failed (exit 1) */
  LW_ERUN       /* a failure while running (exit 1) */
} lw_status;

/* room for two paths of LW_PATH_MAX and the words about them: at 1024 a
** message about a long path was cut before it said what was wrong */
#define LW_ERROR_MSG 4096

typedef struct {
  lw_status code;
  char msg[LW_ERROR_MSG];
} lw_error;

/* Sets err (if not NULL) to code and a printf-style message; returns code. */
lw_status lw_error_set(lw_error *err, lw_status code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* The length of the UTF-8 sequence at c (2 to 4), its code point in *cp;
** 0 where c begins none (a stray continuation byte, an overlong form, a
** surrogate, a sequence cut short).  What the messages and the readers'
** hints take for a character. */
int lw_utf8_at(const unsigned char *c, unsigned *cp);

/* Clears err to LW_OK with an empty message. */
void lw_error_clear(lw_error *err);

/* The process exit status for a code: 0, 1 or 2. */
int lw_error_exit_status(lw_status code);

/* A GSL error handler for a program that uses the library (gsl_set_error_handler):
** an allocation GSL cannot make (GSL_ENOMEM) returns, so that its caller sees
** NULL and says "out of memory" (GSL's own handler aborted the process, which
** a run out of memory should not); any other GSL error is a fault of this
** library, and ends the process with one line saying so. */
void lw_gsl_handler(const char *reason, const char *file, int line, int gsl_errno);

/* GSL's error handler off around a call whose failure the caller handles
** (a Cholesky factor of a matrix that may not be positive definite), then
** back.  The handler is one for the process, so the calls are counted under
** a lock: the first to turn it off keeps the program's, and the last to
** finish puts it back, however the threads of one run, or a program's runs
** in threads of its own, interleave (each saving and restoring it alone,
** two threads left it off for good).  Meanwhile it is off for every thread. */
void lw_gsl_off(void);
void lw_gsl_on(void);

#ifdef __cplusplus
}
#endif

#endif
