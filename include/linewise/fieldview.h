/*
** fieldview.h -- field.png, a look at the vector field a scene's field term
** reads: the picture's tone (white without a picture) under short strokes
** along the field on a regular lattice, the length of a stroke showing the
** field's length (at most 1).  When the energy reads the field with its
** sign (field_mode = signed) each stroke has a dot at its head; an axial
** reading (and etf, which has no sign) shows none.
*/
#ifndef LINEWISE_FIELDVIEW_H
#define LINEWISE_FIELDVIEW_H

#include "linewise/error.h"
#include "linewise/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_FIELDVIEW_MAX_PX 2048  /* longest side, pixels */

/* Writes the preview of sc's field (which must be built: the field term on)
** to path atomically, at px_per_mm (lowered so the longer side is at most
** LW_FIELDVIEW_MAX_PX). */
lw_status lw_fieldview_png(const lw_scene *sc, double px_per_mm, const char *path, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
