/*
** particles_io.h -- the particle system's files: the point file it may
** start from, and its own section of a checkpoint.
**
** Point file (particles.points): text, one particle per line,
**
**     x y z            or      x y z nx ny nz
**
** numbers separated by blanks or commas; '#' starts a comment, and a line
** that starts with "//" is one (a CloudCompare header); blank lines are
** skipped.  Or a PLY file (its first line "ply"; ply.h): the vertices' x y
** z and, where it has all three, nx ny nz.  The normal need not be unit but
** must have a length (it is normalised).  Errors name the file and line
** (or vertex) and say what was expected.
**
** Checkpoint section (the row's save / load): the system's own section of
** state.lw (ckpt.h), [system particles] or [system particles K],
**
**     count = N
**     particle = x y z qw qx qy qz pin      N lines: position, unit
**                                           quaternion, pin flags
**
** Numbers are written with 17 significant digits and read back to the same
** doubles.  The reader checks everything: the count, every number, every
** quaternion unit within 1e-9, pin flags 0..3, the particles inside the
** boundary and apart; messages name the file, line and section.  The
** running energies are the run loop's (by term name, checkpoint.h): a
** state read here has them summed afresh.
*/
#ifndef LINEWISE_PARTICLES_IO_H
#define LINEWISE_PARTICLES_IO_H

#include "linewise/ckpt.h"
#include "linewise/particles.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The largest coordinate a point file may give, in r0: the previews and
** the cell grid need a page that doubles can scale. */
#define LW_POINTS_COORD_MAX 1e9

/* Reads a point file: *n particles, positions (3n), unit normals (3n;
** (0, 0, 1) where a line has none) and has_normal (n), all malloc'ed.
** LW_EINPUT with "path:line: ..." for a bad line or an empty file. */
lw_status lw_particles_read_points(const char *path, size_t *n, double **x, double **normal,
                                   unsigned char **has_normal, lw_error *err);

/* Writes p as the section `section`. */
void lw_particles_put(lw_ckpt_writer *w, const char *section, const lw_particles *p);

/* Reads the section `section` of c (as read from its file); NULL and err
** set when it is missing or refused. */
lw_particles *lw_particles_get(const lw_particles_setup *s, lw_ckpt *c, const char *section, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
