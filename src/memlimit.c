/* memlimit.c -- the memory this process may use (memlimit.h). */
#include "linewise/memlimit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#define PARTS_MAX 32

/* The number in file path, or INFINITY ("max", none, unreadable). */
static double read_limit(const char *path)
{
  FILE *f = fopen(path, "r");
  double v;
  const int got = f && fscanf(f, "%lf", &v) == 1 && v > 0.0;
  if (f) fclose(f);
  return got ? v : INFINITY;
}

/* The least of file in the group `group` ("/a/b/c") under base, each group
** above it, and the same with leading parts dropped. */
static double group_limit(const char *base, const char *group, const char *file)
{
  char parts[256], *part[PARTS_MAX], *save;
  snprintf(parts, sizeof parts, "%s", group);
  int n = 0;
  for (char *p = strtok_r(parts, "/\n", &save); p && n < PARTS_MAX; p = strtok_r(NULL, "/\n", &save)) part[n++] = p;
  double least = INFINITY;
  for (int from = 0; from <= n; from++)
    for (int to = n; to >= from; to--) {
      char path[1024];
      int used = snprintf(path, sizeof path, "%s", base);
      for (int k = from; k < to && used < (int)sizeof path; k++)
        used += snprintf(path + used, sizeof path - (size_t)used, "/%s", part[k]);
      if (used < (int)sizeof path) snprintf(path + used, sizeof path - (size_t)used, "/%s", file);
      least = fmin(least, read_limit(path));
    }
  return least;
}

double lw_memory_cgroup_limit(const char *text, const char *root)
{
  double least = INFINITY;
  char base[512];
  for (const char *line = text; line && *line; line = strchr(line, '\n') ? strchr(line, '\n') + 1 : NULL) {
    const char *c1 = strchr(line, ':'), *c2 = c1 ? strchr(c1 + 1, ':') : NULL, *eol = strchr(line, '\n');
    if (!c2 || (eol && c2 > eol)) continue;
    char group[256];
    snprintf(group, sizeof group, "%.*s", (int)(eol ? eol - c2 - 1 : (long)strlen(c2 + 1)), c2 + 1);
    if (c2 == c1 + 1) { /* v2: "0::/group", at the root or beside v1 as unified/ */
      snprintf(base, sizeof base, "%s", root);
      least = fmin(least, group_limit(base, group, "memory.max"));
      snprintf(base, sizeof base, "%s/unified", root);
      least = fmin(least, group_limit(base, group, "memory.max"));
    } else if (strstr(c1 + 1, "memory") && strstr(c1 + 1, "memory") < c2) {
      snprintf(base, sizeof base, "%s/memory", root); /* v1: "4:memory:/group" */
      least = fmin(least, group_limit(base, group, "memory.limit_in_bytes"));
    }
  }
  return least;
}

double lw_memory_limit(const char **by)
{
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  double limit = pages > 0 && page > 0 ? (double)pages * (double)page : INFINITY;
  *by = "this machine's memory";
  struct rlimit rl;
  if (!getrlimit(RLIMIT_AS, &rl) && rl.rlim_cur != RLIM_INFINITY && (double)rl.rlim_cur < limit) {
    limit = (double)rl.rlim_cur;
    *by = "this process's address space (ulimit -v)";
  }
  /* a batch job's or a container's group, and the groups above it (only
  ** the root's memory.max was read: a Slurm job's limit went unseen) */
  FILE *f = fopen("/proc/self/cgroup", "r");
  char text[4096];
  const size_t got = f ? fread(text, 1, sizeof text - 1, f) : 0;
  if (f) fclose(f);
  text[got] = '\0';
  const double cg = lw_memory_cgroup_limit(text, "/sys/fs/cgroup");
  if (cg < limit) {
    limit = cg;
    *by = "this process's cgroup (memory.max or memory.limit_in_bytes)";
  }
  return limit;
}
