/*
** fuzz_split.h -- inputs that are several files: the parts are separated by
** lines "=====" and written into a run directory of this process under
** fixed names (scene.ini, state.lw, trace.csv, ...).
*/
#ifndef LINEWISE_FUZZ_SPLIT_H
#define LINEWISE_FUZZ_SPLIT_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* This process's run directory (created once); NULL if it cannot be. */
static inline const char *lw_fuzz_dir(void)
{
  static char dir[256];
  if (!dir[0]) {
    const char *t = getenv("TMPDIR");
    snprintf(dir, sizeof dir, "%s/lw-fuzz-dir-%ld", t && *t ? t : "/tmp", (long)getpid());
    if (mkdir(dir, 0700) && access(dir, W_OK)) return NULL;
  }
  return dir;
}

/* Writes part k of data (parts end at "\n=====\n") to dir/names[k] for
** every name; a file whose part is missing is removed.  1 on success. */
static inline int lw_fuzz_split(const uint8_t *data, size_t size, const char *dir, const char *const *names, int n)
{
  static const char sep[] = "\n=====\n";
  const uint8_t *p = data, *end = data + size;
  for (int k = 0; k < n; k++) {
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, names[k]);
    if (!p) {
      remove(path);
      continue;
    }
    const uint8_t *q = memmem(p, (size_t)(end - p), sep, sizeof sep - 1);
    size_t len = q ? (size_t)(q - p) + 1 : (size_t)(end - p);
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    int ok = fwrite(p, 1, len, f) == len;
    if (fclose(f) || !ok) return 0;
    p = q ? q + sizeof sep - 1 : NULL;
  }
  return 1;
}

#endif
