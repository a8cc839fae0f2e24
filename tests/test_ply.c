/*
** test_ply.c -- the PLY reader (ply.h) and the particles' point files that
** go through it (particles_io.h): the three formats give the same values
** from files with other properties, lists and elements around the
** vertices; every refusal names the file and the line or vertex; a run's
** final.ply starts another run with the same particles.
*/
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "linewise/particles_io.h"
#include "linewise/ply.h"
#include "testutil.h"

static char dir[64];

static void make_dir(void) { cr_assert_eq(lw_test_dir_make(dir, "ply"), 0); }

static void remove_dir(void) { lw_test_dir_remove(dir); }

TestSuite(ply, .init = make_dir, .fini = remove_dir);

/* The three vertices every format below holds: x y z nx ny nz, each
** exactly representable as a float. */
static const double want[3][6] = {{1.5, -2.25, 0.125, 0, 0, 1}, {-3, 4.5, 7.75, 1, 0, 0}, {0.5, 0.5, -8, 0, -1, 0}};

/* Bytes of v as type size (1, 2, 4: integers; 'f' float, 'd' double) in
** the byte order big (1) or little (0). */
static void put(FILE *f, char type, double v, int big)
{
  unsigned char b[8];
  uint64_t u;
  int size;
  if (type == 'f') {
    float fl = (float)v;
    uint32_t u32;
    memcpy(&u32, &fl, 4);
    u = u32;
    size = 4;
  } else if (type == 'd') {
    memcpy(&u, &v, 8);
    size = 8;
  } else {
    u = (uint64_t)(int64_t)v;
    size = type - '0';
  }
  for (int k = 0; k < size; k++) b[big ? size - 1 - k : k] = (unsigned char)(u >> (8 * k));
  cr_assert_eq(fwrite(b, 1, (size_t)size, f), (size_t)size);
}

/* A binary file: a face element before the vertices (lists of uchar
** counts and int indices), vertices with x as float, y as double, z as
** float, an intensity (ushort) between, the normal as floats and a list
** at the end; another element after.  n_vertices of `want` are written
** (fewer than the header says: a file cut short). */
static void write_binary(const char *path, int big, int n_vertices)
{
  FILE *f = fopen(path, "wb");
  cr_assert_not_null(f);
  fprintf(f, "ply\nformat %s 1.0\ncomment made by test_ply.c\nelement face 2\n"
             "property list uchar int vertex_indices\nelement vertex 3\nproperty float x\nproperty double y\n"
             "property float z\nproperty ushort intensity\nproperty float nx\nproperty float ny\nproperty float nz\n"
             "property list uint8 float32 extra\nelement edge 1\nproperty int vertex1\nend_header\n",
          big ? "binary_big_endian" : "binary_little_endian");
  for (int k = 0; k < 2; k++) {
    put(f, '1', 3, big);
    for (int c = 0; c < 3; c++) put(f, '4', c, big);
  }
  for (int i = 0; i < n_vertices; i++) {
    put(f, 'f', want[i][0], big);
    put(f, 'd', want[i][1], big);
    put(f, 'f', want[i][2], big);
    put(f, '2', 1000 + i, big);
    for (int c = 3; c < 6; c++) put(f, 'f', want[i][c], big);
    put(f, '1', i, big);
    for (int c = 0; c < i; c++) put(f, 'f', 9.5, big);
  }
  if (n_vertices == 3) put(f, '4', 7, big);
  cr_assert_eq(fclose(f), 0);
}

static void write_ascii(const char *path)
{
  FILE *f = fopen(path, "w");
  cr_assert_not_null(f);
  fprintf(f, "ply\r\nformat ascii 1.0\r\nobj_info a scan\r\nelement vertex 3\r\nproperty float nx\r\n"
             "property float ny\r\nproperty float nz\r\nproperty list uchar int rings\r\nproperty double x\r\n"
             "property double y\r\nproperty double z\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\n"
             "end_header\r\n");
  static const char *const rings[3] = {"0", "1 5", "2 4 5"};
  for (int i = 0; i < 3; i++)
    fprintf(f, "%g %g %g %s %.17g %.17g %.17g\r\n", want[i][3], want[i][4], want[i][5], rings[i], want[i][0],
            want[i][1], want[i][2]);
  fprintf(f, "3 0 1 2\r\n");
  cr_assert_eq(fclose(f), 0);
}

static void read_points(const char *path, lw_status expect, const char *msg)
{
  size_t n;
  double *x, *nrm;
  unsigned char *has;
  lw_error err = {LW_OK, ""};
  lw_status s = lw_particles_read_points(path, &n, &x, &nrm, &has, &err);
  cr_assert_eq(s, expect, "%s: %s", path, err.msg);
  if (s) {
    cr_assert(strstr(err.msg, path), "the message does not name the file: %s", err.msg);
    cr_assert(strstr(err.msg, msg), "expected '%s' in: %s", msg, err.msg);
    cr_assert_null(x);
    return;
  }
  cr_assert_eq(n, 3);
  for (size_t i = 0; i < 3; i++) {
    cr_assert(has[i]);
    for (int c = 0; c < 3; c++) {
      cr_assert_eq(x[3 * i + c], want[i][c], "%s: vertex %zu coordinate %d", path, i, c);
      cr_assert_eq(nrm[3 * i + c], want[i][3 + c], "%s: vertex %zu normal %d", path, i, c);
    }
  }
  free(x);
  free(nrm);
  free(has);
}

Test(ply, the_three_formats_give_the_same_points_around_other_elements_and_lists)
{
  char path[128];
  const char *name[3] = {"le.ply", "be.ply", "ascii.ply"};
  for (int k = 0; k < 3; k++) {
    snprintf(path, sizeof path, "%s/%s", dir, name[k]);
    if (k < 2) write_binary(path, k, 3);
    else write_ascii(path);
    read_points(path, LW_OK, NULL);
  }
  /* blanks after the magic, as an editor leaves them (read as a text point
  ** file, and refused as one) */
  char *text = lw_test_slurp("%s", path);
  char *spaced = malloc(strlen(text) + 4);
  sprintf(spaced, "ply \t%s", text + 3);
  cr_assert_eq(lw_test_write_text(dir, "spaced.ply", spaced), 0);
  snprintf(path, sizeof path, "%s/spaced.ply", dir);
  read_points(path, LW_OK, NULL);
  free(spaced);
  free(text);
}

/* Each bad file and what its one message must say. */
Test(ply, every_refusal_names_the_file_and_where)
{
  static const struct {
    const char *text, *msg;
  } bad[] = {
      {"ply\nformat binary_middle_endian 1.0\nend_header\n", ":2: expected the format ascii"},
      {"ply\nformat ascii 2.0\nend_header\n", ":2: expected 'format ascii 1.0'"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n0\n", ":4: expected a property type"},
      {"ply\nformat ascii 1.0\nproperty float x\nend_header\n", ":3: expected an element before its properties"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", ":4: expected 'end_header'"},
      {"ply\nformat ascii 1.0\nelement vertex 2\nend_header\n", "expected properties for the element 'vertex'"},
      {"ply\nformat ascii 1.0\nelement vertex 20000000\nproperty float x\nend_header\n", ":3: expected at most 10000000"},
      {"ply\nformat ascii 1.0\nelement face 1\nproperty float x\nend_header\n1\n", "expected an element 'vertex'"},
      {"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
       "end_header\n1 2 3\n4 5\n", ":9: expected property 3 of vertex 1"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
       "end_header\n1 2 3 4\n", ":8: expected 3 values for vertex 0"},
      {"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
       "end_header\n1 2 3\n", "expected 2 vertex lines, the file ends after 1"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
       "end_header\n1 nan 3\n", ":8: expected property 2 of vertex 0 as a finite number"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float z\nend_header\n1 3\n",
       "expected the vertex property 'y'"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
       "property float nx\nend_header\n1 2 3 1\n", "expected the vertex property 'ny'"},
      {"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
       "property float nx\nproperty float ny\nproperty float nz\nend_header\n1 2 3 0 0 1\n1 2 3 0 0 0\n",
       ": vertex 1: expected a normal nx ny nz with a direction"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\nproperty float y\n"
       "property float z\nend_header\n1 5 2 3\n", "expected the vertex property 'x'"},
      {"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nend_header\n", "expected at least one vertex"},
      /* told a PLY file by its magic in any case: refused as PLY, not read
      ** as a text point file ("expected 'x y z'") */
      {"PLY\nformat ascii 1.0\nend_header\n", ":1: expected the PLY magic line 'ply', got 'PLY'"},
      /* blanks past the first bytes still a PLY file's (26 read it as text) */
      {"ply                          \nformat ascii 2.0\nend_header\n", ":2: expected 'format ascii 1.0'"},
  };
  char path[128];
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    snprintf(path, sizeof path, "bad%zu.ply", k);
    cr_assert_eq(lw_test_write_text(dir, path, bad[k].text), 0);
    snprintf(path, sizeof path, "%s/bad%zu.ply", dir, k);
    read_points(path, LW_EINPUT, bad[k].msg);
  }
  /* a NUL byte in a header or an ASCII line: UTF-16 named ("got ''") */
  snprintf(path, sizeof path, "%s/nul.ply", dir);
  FILE *z = fopen(path, "wb");
  fwrite("ply\nformat ascii 1.0\nelem\0ent vertex 1\n", 1, 39, z);
  fclose(z);
  read_points(path, LW_EINPUT, ":3: a NUL byte inside the line (UTF-16 text");
  /* binary: cut short inside the last vertex, and a value that is not finite */
  snprintf(path, sizeof path, "%s/cut.ply", dir);
  write_binary(path, 0, 2);
  read_points(path, LW_EINPUT, "vertex 2: the file ends inside it (the header says 3)");
  /* cut inside the last vertex's list (its last property): items are read,
  ** not skipped by a seek that would pass the end without a word */
  write_binary(path, 1, 3);
  FILE *g = fopen(path, "rb+");
  fseek(g, 0, SEEK_END);
  long size = ftell(g);
  fclose(g);
  cr_assert_eq(truncate(path, size - 8), 0); /* the edge element and one of vertex 2's two list items */
  read_points(path, LW_EINPUT, "vertex 2: the file ends inside it (the header says 3)");
  FILE *f = fopen(path, "wb");
  fprintf(f, "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty double x\nproperty float y\n"
             "property float z\nend_header\n");
  put(f, 'd', 1, 1);
  put(f, 'f', INFINITY, 1);
  put(f, 'f', 0, 1);
  fclose(f);
  read_points(path, LW_EINPUT, "vertex 0: expected a finite y, got inf");
}

/* The scan of a run's final.ply (nine digits a number) starts another run
** with the same particles: counted, and each within the printed rounding. */
Test(ply, a_runs_final_ply_starts_the_next_run)
{
  cr_assert_eq(lw_test_sh("%s run %s/params/particles-sheet.ini --out %s/a --quiet --set anneal.sweeps=20", lw_test_bin(),
                          lw_test_root(), dir), 0);
  cr_assert_eq(lw_test_sh("%s run %s/params/particles-sheet.ini --out %s/b --quiet --set anneal.sweeps=0 "
                          "--set particles.count=0 --set particles.points=%s/a/final.ply", lw_test_bin(),
                          lw_test_root(), dir, dir), 0);
  char path[128];
  snprintf(path, sizeof path, "%s/a/final.ply", dir);
  size_t n;
  double *x, *nrm;
  unsigned char *has;
  lw_error err;
  cr_assert_eq(lw_particles_read_points(path, &n, &x, &nrm, &has, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(n, 127);
  snprintf(path, sizeof path, "%s/b/state.lw", dir);
  FILE *f = fopen(path, "r");
  cr_assert_not_null(f);
  char line[512];
  size_t i = 0;
  while (fgets(line, sizeof line, f)) {
    double p[3];
    if (sscanf(line, "particle = %lf %lf %lf", &p[0], &p[1], &p[2]) != 3) continue;
    cr_assert_lt(i, n);
    for (int c = 0; c < 3; c++)
      cr_assert_lt(fabs(p[c] - x[3 * i + c]), 1e-8 * (1 + fabs(p[c])), "particle %zu, coordinate %d", i, c);
    i++;
  }
  fclose(f);
  cr_assert_eq(i, n);
  free(x);
  free(nrm);
  free(has);
}
