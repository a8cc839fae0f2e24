/*
** particles_io.h -- the particle system's files: the point file it may
** start from, and its own section of a checkpoint.
**
** Point file (particles.points): text, one particle per line,
**
**     x y z            or      x y z nx ny nz
**
** numbers separated by blanks; '#' starts a comment; blank lines are
** skipped.  The normal need not be unit but must have a length (it is
** normalised).  Errors name the file and line and say what was expected.
**
** Checkpoint section (save / load): the body of the system's named section,
** key = value lines then one data line per particle, written to a FILE or
** kept as the "particles" lines of an in-memory state.lw (state.h),
**
**     count = N
**     energy.lj = E            one line per term, in lw_pterm_names order:
**     energy.coplanarity = E   the running totals, so that a resumed run
**     ...                      adds to exactly the same numbers
**     x y z qw qx qy qz pin    N lines: position, unit quaternion, pin flags
**
** Numbers are written with %.17g and read back to the same doubles.  load
** checks everything it reads: the count, every number finite, every
** quaternion unit within 1e-9, pin flags 0..3, the particles inside the
** boundary and apart, and the totals within 1e-6 (relative to max(|E|, 1))
** of a recomputation; messages name the file and line.
*/
#ifndef LINEWISE_PARTICLES_IO_H
#define LINEWISE_PARTICLES_IO_H

#include <stdio.h>

#include "linewise/particles.h"
#include "linewise/state.h"

/* Reads a point file: *n particles, positions (3n), unit normals (3n;
** (0, 0, 1) where a line has none) and has_normal (n), all malloc'ed.
** LW_EINPUT with "path:line: ..." for a bad line or an empty file. */
lw_status lw_particles_read_points(const char *path, size_t *n, double **x, double **normal,
                                   unsigned char **has_normal, lw_error *err);

/* Writes the section body of p to f.  LW_EIO on a write error. */
lw_status lw_particles_save(const lw_particles *p, FILE *f, lw_error *err);

/* The same body as lines of an in-memory state (state.h): one extra line
** "particles <body line>" per line, in order.  LW_ENOMEM on failure. */
#define LW_PARTICLES_KEY "particles"
lw_status lw_particles_save_state(const lw_particles *p, lw_state *st, lw_error *err);

/* Reads a section body written by lw_particles_save from f: a state on set-up
** s.  path names the file in messages and *line is the line number before
** the body; it is advanced past every line read. */
lw_particles *lw_particles_load(const lw_particles_setup *s, FILE *f, const char *path, int *line, lw_error *err);

/* Reads the body from the "particles" lines of st (as read from path: the
** messages give their lines there). */
lw_particles *lw_particles_load_state(const lw_particles_setup *s, const lw_state *st, const char *path,
                                      lw_error *err);

#endif
