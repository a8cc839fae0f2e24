/*
** test_error.c -- GSL's errors in a program that uses the library
** (lw_gsl_handler, error.h).
*/
#include <criterion/criterion.h>
#include <criterion/redirect.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_vector.h>
#include <signal.h>

#include "linewise/error.h"

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
