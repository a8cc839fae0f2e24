/*
** particles_draw.h -- the particle system's drawings: final.ply and final.png.
**
** final.ply is ASCII PLY 1.0 with one vertex element of double properties
** x y z nx ny nz (the normal is the particle's local z axis), which MeshLab
** and CloudCompare read as a point cloud with normals.  Doubles are written
** with 17 significant digits, so a run continued from the file starts where
** this one ended.
**
** final.png is an orthographic preview from the set-up's view direction v
** (particles.view_azimuth and view_elevation): screen axes e1 = z x v
** (normalised; y x v when looking along z) and e2 = v x e1, so +z points up
** on the screen when it can.  Each particle is a disc of radius `disc` in its
** tangent plane, i.e. an ellipse with semi-axes disc and disc |n.v| across
** the projected normal; discs are painted far to near (painter's algorithm,
** ties by index), shaded 0.35 + 0.65 |n.L| for a light L above and to the
** right of the viewer; discs seen from the front (n.v >= 0) are blue, from
** the back orange, pinned ones outlined in dark red.  The picture is
** png_size pixels square, the projected particles fitted with a margin; a
** frame (frame = 1) in a view fixed for the run instead: the set-up's grid
** box (the start's pattern and points, a sphere boundary) and a floor.
**
** Both files are written to "<path>.tmp" and renamed (output.h), so a reader
** never sees half a file.
*/
#ifndef LINEWISE_PARTICLES_DRAW_H
#define LINEWISE_PARTICLES_DRAW_H

#include "linewise/particles.h"

#ifdef __cplusplus
extern "C" {
#endif

lw_status lw_particles_write_ply(const lw_particles *p, const char *path, lw_error *err);
lw_status lw_particles_write_png(const lw_particles *p, const char *path, int frame, lw_error *err);

/* dir/final.ply and dir/final.png. */
lw_status lw_particles_draw(const lw_particles *p, const char *dir, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
