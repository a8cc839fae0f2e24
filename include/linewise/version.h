/*
** version.h -- the release, as `linewise --version` and summary.json give it
** (year.month of the release, then .N for a later one in the same month).
** docs/linewise.1 names it too; a test holds the two together.
*/
#ifndef LW_VERSION_H
#define LW_VERSION_H

#define LW_VERSION "2026.12"

/* The commit the build was made from (12 hex digits, "-dirty" after them
** where files differed from it), or "unknown" outside a git checkout: a
** release spans many changes that alter a run's files. */
const char *lw_version_build(void);

#endif
