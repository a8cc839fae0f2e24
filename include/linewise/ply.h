/*
** ply.h -- reads the vertices of a PLY file (the Stanford polygon format):
** scanners, meshing tools and linewise's own final.ply write it, so a point
** cloud or a finished particle run can start a particle scene
** (particles.points, particles_io.h).
**
** Read: "format ascii 1.0", "binary_little_endian 1.0" and
** "binary_big_endian 1.0"; the scalar types char/int8, uchar/uint8,
** short/int16, ushort/uint16, int/int32, uint/uint32, float/float32 and
** double/float64; list properties (skipped, in any element); other elements
** before or after the vertices (skipped: a mesh's faces).  Comments and
** obj_info lines are ignored.  An ASCII element instance is one line.
**
** Everything is checked: the header's lines (each error names the file and
** line and says what was expected), every value finite, a file that ends
** before its element counts do (naming the line or the instance; the
** vertices' memory grows as they come, so a count costs none before it is
** found out).  Lines end in LF or CR LF.
*/
#ifndef LINEWISE_PLY_H
#define LINEWISE_PLY_H

#include <stddef.h>
#include <stdio.h>

#include "linewise/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* At most this many vertices (particles.count's bound). */
#define LW_PLY_VERTICES_MAX 10000000

/* Whether f, at its start, holds a PLY file (its first line is "ply"); f is
** left at its start. */
int lw_ply_detect(FILE *f);

/* Reads the element "vertex" of the PLY file f (at its start; path names it
** in messages): *n vertices, and for each the n_names properties names[k]
** as doubles into *values (n * n_names, malloc'ed, vertex-major); a
** property the vertices lack reads 0 and leaves bit k of *found clear.
** LW_EINPUT naming the file and the line or vertex for a file that is not
** what the header says, or without vertices; LW_EIO; LW_ENOMEM. */
lw_status lw_ply_read_vertices(FILE *f, const char *path, const char *const *names, int n_names, size_t *n,
                               double **values, unsigned *found, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
