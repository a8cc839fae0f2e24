/* testutil.h -- small helpers shared by the test files. */
#ifndef LINEWISE_TESTUTIL_H
#define LINEWISE_TESTUTIL_H

#include <math.h>

/* |a - b| <= tol * max(|b|, floor) */
static inline int lw_close_rel(double a, double b, double tol, double floor)
{
  double s = fabs(b) > floor ? fabs(b) : floor;
  return fabs(a - b) <= tol * s;
}

#endif
