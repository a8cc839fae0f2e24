/*
** fuzz_util.h -- what the fuzz harnesses share.  The readers take file
** paths, so each input is written to a file of this process first (one per
** process and role, rewritten for every input).  A broken property aborts,
** which libFuzzer reports as a crash and the corpus replay in `make test` as
** a crashed test.
*/
#ifndef LINEWISE_FUZZ_UTIL_H
#define LINEWISE_FUZZ_UTIL_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The path of this process's scratch file number `which` (0 or 1). */
static inline const char *lw_fuzz_path(int which, const char *ext)
{
  static char path[2][256];
  if (!path[which][0]) {
    const char *dir = getenv("TMPDIR");
    snprintf(path[which], sizeof path[which], "%s/lw-fuzz-%ld-%d%s", dir && *dir ? dir : "/tmp",
             (long)getpid(), which, ext);
  }
  return path[which];
}

/* Writes data to the scratch file; its path, or NULL if it cannot be written. */
static inline const char *lw_fuzz_file(const uint8_t *data, size_t size, int which, const char *ext)
{
  const char *path = lw_fuzz_path(which, ext);
  FILE *f = fopen(path, "wb");
  if (!f) return NULL;
  int ok = fwrite(data, 1, size, f) == size;
  if (fclose(f) || !ok) return NULL;
  return path;
}

/* Aborts with a message when a property does not hold. */
#define LW_FUZZ_CHECK(cond, ...)                                   \
  do {                                                              \
    if (!(cond)) {                                                  \
      fprintf(stderr, "fuzz property broken: %s: ", #cond);         \
      fprintf(stderr, __VA_ARGS__);                                 \
      fputc('\n', stderr);                                          \
      abort();                                                      \
    }                                                               \
  } while (0)

#endif
