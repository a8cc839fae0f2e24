/*
** test_memlimit.c -- the memory limit of a process's cgroups (memlimit.h):
** a nested group's limit and its parents', cgroup v1 and v2, and a group
** named from outside a container's namespace.
*/
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "linewise/memlimit.h"
#include "testutil.h"

static char root[64];

static void make_root(void)
{
  snprintf(root, sizeof root, "/tmp/lw_memlimit_XXXXXX");
  cr_assert_not_null(mkdtemp(root));
}

static void remove_root(void) { lw_test_sh("rm -rf %s", root); }

TestSuite(memlimit, .init = make_root, .fini = remove_root);

static void put(const char *path, const char *text)
{
  cr_assert_eq(lw_test_sh("mkdir -p \"$(dirname %s/%s)\" && printf '%s\\n' > %s/%s", root, path, text, root, path), 0);
}

/* cgroup v2: a Slurm job's group two levels down (only the root's
** memory.max was read, and the job's limit went unseen); "max" is none; the
** least of the group and those above it counts. */
Test(memlimit, a_nested_v2_group_and_those_above_it)
{
  put("memory.max", "max");
  put("slurm/memory.max", "max");
  put("slurm/job_7/memory.max", "150000000");
  put("slurm/job_7/step_0/memory.max", "max");
  cr_assert_eq(lw_memory_cgroup_limit("0::/slurm/job_7/step_0\n", root), 150000000.0);
  put("slurm/memory.max", "100000000");
  cr_assert_eq(lw_memory_cgroup_limit("0::/slurm/job_7/step_0\n", root), 100000000.0);
  cr_assert(isinf(lw_memory_cgroup_limit("0::/other\n", root)), "the root's max, slurm's not above it");
}

/* cgroup v1 (memory.limit_in_bytes), and a group the kernel names from
** outside the container ("/process_api/<id>/job" where the container's
** mount shows "job" at its root). */
Test(memlimit, a_v1_group_named_from_outside_the_container)
{
  put("memory/memory.limit_in_bytes", "9223372036854771712");
  put("memory/job/memory.limit_in_bytes", "157286400");
  const char *text = "5:devices:/\n4:memory:/process_api/e849f46f/job\n0::/\n";
  cr_assert_eq(lw_memory_cgroup_limit(text, root), 157286400.0);
  cr_assert_eq(lw_memory_cgroup_limit("4:memory:/\n", root), 9223372036854771712.0);
  cr_assert(isinf(lw_memory_cgroup_limit("3:cpuset:/job\n", root)), "no memory controller named");
}
