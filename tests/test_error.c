/*
** test_error.c -- GSL's errors in a program that uses the library
** (lw_gsl_handler, error.h), and what a message may show.
*/
#include <criterion/criterion.h>
#include <criterion/redirect.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_vector.h>
#include <signal.h>

#include "linewise/error.h"
#include "linewise/mc.h"

/* An allocation GSL cannot make returns to its caller (GSL's own handler
** aborted the run, which then left no message and no exit status 1). */
Test(error, an_allocation_gsl_cannot_make_returns_to_its_caller)
{
  gsl_error_handler_t *old = gsl_set_error_handler(lw_gsl_handler);
  gsl_error("failed to allocate space for block data", __FILE__, __LINE__, GSL_ENOMEM); /* gsl_block_alloc's */
  gsl_set_error_handler(old);
}

/* Any other error of GSL is a fault of the library: the process ends.  (Its
** "internal error ... please report it" line is kept from the test log,
** where a packager took it for a fault.) */
Test(error, any_other_gsl_error_ends_the_process, .signal = SIGABRT, .init = cr_redirect_stderr)
{
  gsl_set_error_handler(lw_gsl_handler);
  gsl_vector *v = gsl_vector_alloc(2);
  gsl_vector_get(v, 5); /* index out of range: GSL_EINVAL */
  gsl_vector_free(v);
}

static int program_handler_calls;
static void program_handler(const char *reason, const char *file, int line, int gsl_errno)
{
  (void)reason, (void)file, (void)line, (void)gsl_errno;
  program_handler_calls++;
}

/* The library turns GSL's handler off around the calls whose failure it
** handles (lw_gsl_off), on many threads at once: the program's handler is
** back after them however they interleave.  Each call saving and restoring
** it alone, two threads left it off for good (3 times in 3 tries). */
Test(error, the_programs_gsl_handler_survives_the_librarys_threads)
{
  gsl_error_handler_t *old = gsl_set_error_handler(program_handler);
#pragma omp parallel for num_threads(8) schedule(static, 1)
  for (int i = 0; i < 20000; i++) {
    gsl_rng *r = lw_rng_new(); /* off and on again, as every chain's set-up */
    gsl_rng_free(r);
  }
  cr_assert_eq(gsl_set_error_handler(old), program_handler, "the program's handler is gone");
  /* nested, it stays off until the last, then the program's is back */
  gsl_set_error_handler(program_handler);
  program_handler_calls = 0;
  lw_gsl_off();
  lw_gsl_off();
  lw_gsl_on();
  gsl_error("within", __FILE__, __LINE__, GSL_EDOM);
  lw_gsl_on();
  cr_assert_eq(program_handler_calls, 0, "the handler ran while off");
  gsl_error("after", __FILE__, __LINE__, GSL_EDOM);
  cr_assert_eq(program_handler_calls, 1);
  gsl_set_error_handler(old);
}

/* A message quotes input, which may hold anything: what would move the
** terminal's cursor or break the line (a control character, DEL, a C1
** control such as U+0085, NEXT LINE) or show the rest of a file's name
** reversed (a bidi override, U+202E: "a\u202egnp.exe" reads "aexe.png") is
** one '?' each; UTF-8 letters stay. */
Test(error, a_message_shows_no_control_or_bidi_character)
{
  lw_error err;
  cr_assert_eq(lw_error_set(&err, LW_EINPUT, "%s: x", "a\nb\tc\x7f" "d\xc2\x85" "e\xe2\x80\xae" "f\xe2\x81\xa6" "g"),
               LW_EINPUT);
  cr_assert_str_eq(err.msg, "a?b?c?d?e?f?g: x");
  cr_assert_eq(lw_error_set(&err, LW_EIO, "%s", "M\xc3\xbcller \xe6\x97\xa5 \xe2\x80\x94 \xc2\xa0."), LW_EIO);
  cr_assert_str_eq(err.msg, "M\xc3\xbcller \xe6\x97\xa5 \xe2\x80\x94 \xc2\xa0.",
                   "letters, a dash, a no-break space stay");
  cr_assert_eq(lw_error_set(&err, LW_EIO, "%s", "end\xc2"), LW_EIO); /* a sequence cut at the end */
  cr_assert_str_eq(err.msg, "end\xc2");
  /* a lone C1 byte (an 8-bit terminal's CSI), an overlong NEXT LINE, the
  ** line separator and a right-to-left mark are '?' too; a Latin-1 name's
  ** bytes stay */
  cr_assert_eq(lw_error_set(&err, LW_EIO, "%s", "a\x9b" "2J \xc0\x85 b\xe2\x80\xa8" "c\xe2\x80\x8f" "d M\xfcller"),
               LW_EIO);
  cr_assert_str_eq(err.msg, "a?2J \xc0? b?c?d M\xfcller");
}
