/*
** version.h -- the release, as `linewise --version` and summary.json give it
** (year.month of the release, then .N for a later one in the same month).
** docs/linewise.1 names it too; a test holds the two together.
*/
#ifndef LW_VERSION_H
#define LW_VERSION_H

#define LW_VERSION "2026.12"

#endif
