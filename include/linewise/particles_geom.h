/*
** particles_geom.h -- 3-vectors and unit quaternions for the particle system
** (particles.h), as small inline functions.
**
** A quaternion is stored as q[4] = {w, x, y, z} (scalar first), the seed's
** q = (a sin(theta/2), cos(theta/2)) for a rotation by theta about the unit
** axis a.  It maps the particle's local frame to the world frame:
** v_world = q v_local q^-1.  The particle normal is the image of the local
** z axis, the third column of the rotation matrix:
**
**     n = (2 (x z + w y),  2 (y z - w x),  1 - 2 (x^2 + y^2)).
**
** Only the normal enters any energy (particles_pair.h), so the spin about n
** is a free angle that no term sees; the rotate move still turns it.
*/
#ifndef LINEWISE_PARTICLES_GEOM_H
#define LINEWISE_PARTICLES_GEOM_H

#include <math.h>

#ifdef __cplusplus
extern "C" {
#endif

static inline double lw_v3_dot(const double a[3], const double b[3])
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void lw_v3_cross(const double a[3], const double b[3], double c[3])
{
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

/* The normal (local z axis) of the unit quaternion q. */
static inline void lw_quat_normal(const double q[4], double n[3])
{
  n[0] = 2.0 * (q[1] * q[3] + q[0] * q[2]);
  n[1] = 2.0 * (q[2] * q[3] - q[0] * q[1]);
  n[2] = 1.0 - 2.0 * (q[1] * q[1] + q[2] * q[2]);
}

/* c = a b (apply b, then a).  c may not alias a or b. */
static inline void lw_quat_mul(const double a[4], const double b[4], double c[4])
{
  c[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
  c[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
  c[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
  c[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
}

/* The rotation by angle (radians) about the unit axis a. */
static inline void lw_quat_axis_angle(const double a[3], double angle, double q[4])
{
  double s = sin(0.5 * angle);
  q[0] = cos(0.5 * angle);
  q[1] = a[0] * s;
  q[2] = a[1] * s;
  q[3] = a[2] * s;
}

/* Scales q to unit length: products of unit quaternions drift from 1 by a
** few ulps each; renormalising after every product keeps |q| - 1 at
** rounding level for any number of moves. */
static inline void lw_quat_normalise(double q[4])
{
  double s = 1.0 / sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (int k = 0; k < 4; k++) q[k] *= s;
}

/* A unit quaternion whose normal is the unit vector n: the shortest arc
** from +z to n (for n = -z, a half turn about x). */
static inline void lw_quat_from_normal(const double n[3], double q[4])
{
  if (n[2] < -1.0 + 1e-12) {
    q[0] = 0.0;
    q[1] = 1.0;
    q[2] = 0.0;
    q[3] = 0.0;
    return;
  }
  /* half-way quaternion between z and n: (1 + z.n, z x n), normalised */
  q[0] = 1.0 + n[2];
  q[1] = -n[1];
  q[2] = n[0];
  q[3] = 0.0;
  lw_quat_normalise(q);
}

/* v rotated by the unit quaternion q (v may alias out). */
static inline void lw_quat_rotate(const double q[4], const double v[3], double out[3])
{
  /* v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z) */
  double u[3] = {q[1], q[2], q[3]}, t[3], s[3];
  lw_v3_cross(u, v, t);
  for (int k = 0; k < 3; k++) t[k] *= 2.0;
  lw_v3_cross(u, t, s);
  for (int k = 0; k < 3; k++) out[k] = v[k] + q[0] * t[k] + s[k];
}

#ifdef __cplusplus
}
#endif

#endif
