/* version.c -- the build's commit (version.h). */
#include "linewise/version.h"

/* set by the Makefile from git; a build without it knows no commit */
#ifndef LW_BUILD_ID
#define LW_BUILD_ID "unknown"
#endif

const char *lw_version_build(void)
{
  return LW_BUILD_ID;
}
