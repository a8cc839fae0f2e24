/* version.c -- the build's commit, compiler and libraries (version.h). */
#include "linewise/version.h"

#include <cairo.h>
#include <gsl/gsl_version.h>
#include <png.h>
#include <stdio.h>
#include <zlib.h>
#ifdef __GLIBC__
#include <gnu/libc-version.h>
#endif

/* set by the Makefile from git; a build without it knows no commit */
#ifndef LW_BUILD_ID
#define LW_BUILD_ID "unknown"
#endif

const char *lw_version_build(void)
{
  return LW_BUILD_ID;
}

const char *lw_version_compiler(void)
{
#if defined(__clang__)
  return "clang " __clang_version__;
#elif defined(__GNUC__)
  return "gcc " __VERSION__;
#else
  return "unknown";
#endif
}

/* The versions the process runs with, not those it was compiled against:
** a library upgraded under an installed binary is the case to tell. */
void lw_version_libraries(char *buf, size_t n)
{
  const char *libc =
#ifdef __GLIBC__
      gnu_get_libc_version();
#else
      NULL;
#endif
  snprintf(buf, n, "%s%s%sGSL %s, cairo %s, libpng %s, zlib %s", libc ? "glibc " : "", libc ? libc : "",
           libc ? ", " : "", gsl_version, cairo_version_string(), png_get_libpng_ver(NULL), zlibVersion());
}
