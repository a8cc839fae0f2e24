/*
** version.h -- the release, as `linewise --version` and summary.json give it
** (year.month of the release, then .N for a later one in the same month).
** docs/linewise.1 names it too; a test holds the two together.
*/
#ifndef LW_VERSION_H
#define LW_VERSION_H

#include <stddef.h>

#define LW_VERSION "2026.12"

#ifdef __cplusplus
extern "C" {
#endif

/* The commit the build was made from (12 hex digits, "-dirty" after them
** where files differed from it), or "unknown" outside a git checkout: a
** release spans many changes that alter a run's files. */
const char *lw_version_build(void);

/* The compiler that built it ("gcc 12.2.0"), and the libraries the process
** runs with, whose versions may change a run's last bits and final.png's
** bytes (docs/NUMERICS.md): "glibc 2.36, GSL 2.7.1, cairo 1.16.0, libpng
** 1.6.39, zlib 1.2.13", cut to n bytes. */
const char *lw_version_compiler(void);
void lw_version_libraries(char *buf, size_t n);

#ifdef __cplusplus
}
#endif

#endif
