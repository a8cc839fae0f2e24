/*
** memlimit.h -- the memory this process may use: the machine's, its address
** space (ulimit -v), or its cgroup's limit (a batch job's, a container's),
** whichever is least.  A start refuses or notes against it (anneal.c).
*/
#ifndef LINEWISE_MEMLIMIT_H
#define LINEWISE_MEMLIMIT_H

#ifdef __cplusplus
extern "C" {
#endif

/* The least of the limits, in bytes (INFINITY where none is known), and in
** *by what sets it ("this machine's memory", ...). */
double lw_memory_limit(const char **by);

/* The least memory limit of the cgroups that /proc/self/cgroup's text
** names, read under root ("/sys/fs/cgroup"): cgroup v2's memory.max of the
** process's group and each group above it, v1's memory.limit_in_bytes
** likewise.  A group named from outside a container's namespace is also
** sought without its leading parts (the container sees its own group as
** the root).  INFINITY where none is set. */
double lw_memory_cgroup_limit(const char *cgroup_text, const char *root);

#ifdef __cplusplus
}
#endif

#endif
