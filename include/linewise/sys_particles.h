/*
** sys_particles.h -- the oriented-particle system's row of the system table
** (system.h): the particle module (particles.h) behind the seam.
**
** Move kinds translate and rotate ([moves] translate / rotate weights,
** step_translate in lengths, step_rotate in degrees, both tuned toward
** target_spline: they move a whole body, as the spline system's translate
** and rotate do), and with particles.birth and death the kinds birth and
** death (particles_grow.h) in a second row.  Its part of state.lw is the particle module's section
** (particles_io.h); save and load are thin wrappers around it.
*/
#ifndef LINEWISE_SYS_PARTICLES_H
#define LINEWISE_SYS_PARTICLES_H

#include "linewise/particles.h"
#include "linewise/system.h"

#ifdef __cplusplus
extern "C" {
#endif

extern const lw_system_type lw_system_particles;
/* The same with births and deaths as move kinds 2 and 3 (particles.birth,
** particles.death), a sweep a fixed number of proposals; kinds 0 and 1 run
** in domains. */
extern const lw_system_type lw_system_particles_grow;

/* The row a scene's parameters call for. */
const lw_system_type *lw_particles_row(const lw_params *p);

#ifdef __cplusplus
}
#endif

#endif
