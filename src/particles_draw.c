/* particles_draw.c -- final.ply and the cairo preview of the particles (particles_draw.h). */
#include "linewise/particles_draw.h"

#include <cairo.h>
#include <gsl/gsl_math.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/output.h"

lw_status lw_particles_write_ply(const lw_particles *p, const char *path, lw_error *err)
{
  char tmp[LW_OUTPUT_PATH_MAX];
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) return err ? err->code : LW_EIO;
  fprintf(f, "ply\nformat ascii 1.0\ncomment linewise oriented particles; the normal is each particle's local z axis\n"
             "element vertex %zu\nproperty double x\nproperty double y\nproperty double z\n"
             "property double nx\nproperty double ny\nproperty double nz\nend_header\n",
          p->n);
  for (size_t i = 0; i < p->n; i++) {
    const double *x = p->x + 3 * i, *n = p->nrm + 3 * i;
    /* every digit, so that a run continued from it starts where this one
    ** ended (9 put a particle quenched against a floor onto it: outside) */
    fprintf(f, "%.17g %.17g %.17g %.17g %.17g %.17g\n", x[0], x[1], x[2], n[0], n[1], n[2]);
  }
  return lw_output_commit(f, tmp, path, err);
}

static void normalise(double v[3])
{
  double s = 1.0 / sqrt(lw_v3_dot(v, v));
  for (int k = 0; k < 3; k++) v[k] *= s;
}

/* Screen axes for the view direction v (toward the viewer). */
static void screen_axes(const double v[3], double e1[3], double e2[3])
{
  const double z[3] = {0, 0, 1}, y[3] = {0, 1, 0};
  lw_v3_cross(fabs(v[2]) > 1.0 - 1e-9 ? y : z, v, e1);
  normalise(e1);
  lw_v3_cross(v, e1, e2);
}

typedef struct {
  double depth;
  size_t i;
} depth_key;

static int depth_cmp(const void *pa, const void *pb)
{
  const depth_key *a = pa, *b = pb;
  if (a->depth != b->depth) return a->depth < b->depth ? -1 : 1;
  return (a->i > b->i) - (a->i < b->i);
}

/* The frames' view, the same for every frame of a run (and of its
** resumes): the set-up's grid box, what the pattern, the points and a
** sphere boundary reach at the start (docs/NURBS.md's frames are fixed
** likewise), with a floor below.  Fitted to each state, a film showed
** neither the drape's fall into its bowl nor a sheet's growth in its
** sphere; particles that leave the box leave the picture. */
static void frame_box(const lw_particles_setup *s, double lo[3], double hi[3])
{
  for (int k = 0; k < 3; k++) lo[k] = s->lo[k], hi[k] = s->lo[k] + s->extent[k];
  if (s->boundary == LW_PBOUNDARY_PLANE) lo[2] = fmin(lo[2], s->boundary_z);
}

/* Paints the particles onto cr, a size x size picture: fitted to them, or
** in the frames' fixed view (frame_box). */
static void paint(cairo_t *cr, const lw_particles *p, const depth_key *order, int size, int fixed)
{
  const lw_particles_setup *s = p->setup;
  double e1[3], e2[3], light[3];
  screen_axes(s->view, e1, e2);
  for (int k = 0; k < 3; k++) light[k] = s->view[k] + 0.5 * e2[k] + 0.3 * e1[k];
  normalise(light);
  /* fit the projected particles (and their discs), or the box's corners, into the picture */
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY}, blo[3], bhi[3];
  if (fixed) frame_box(s, blo, bhi);
  const size_t points = fixed ? 8 : p->n;
  for (size_t i = 0; i < points; i++) {
    double corner[3];
    if (fixed)
      for (int k = 0; k < 3; k++) corner[k] = (i >> k) & 1 ? bhi[k] : blo[k];
    const double *x = fixed ? corner : p->x + 3 * i;
    double u = lw_v3_dot(x, e1), w = lw_v3_dot(x, e2);
    lo[0] = fmin(lo[0], u);
    hi[0] = fmax(hi[0], u);
    lo[1] = fmin(lo[1], w);
    hi[1] = fmax(hi[1], w);
  }
  double span = fmax(hi[0] - lo[0], hi[1] - lo[1]) + 2.0 * s->disc;
  double scale = 0.92 * size / span, cu = 0.5 * (lo[0] + hi[0]), cw = 0.5 * (lo[1] + hi[1]);
  cairo_set_line_width(cr, fmax(1.0, 0.04 * s->disc * scale));
  for (size_t o = 0; o < p->n; o++) {
    size_t i = order[o].i;
    const double *x = p->x + 3 * i, *n = p->nrm + 3 * i;
    double px = 0.5 * size + scale * (lw_v3_dot(x, e1) - cu), py = 0.5 * size - scale * (lw_v3_dot(x, e2) - cw);
    double nu = lw_v3_dot(n, e1), nw = lw_v3_dot(n, e2), nv = lw_v3_dot(n, s->view);
    /* the disc's long axis is across the projected normal; cairo's y runs down */
    double angle = hypot(nu, nw) > 1e-12 ? atan2(-nu, -nw) : 0.0;
    double shade = 0.35 + 0.65 * fabs(lw_v3_dot(n, light));
    cairo_save(cr);
    cairo_translate(cr, px, py);
    cairo_rotate(cr, angle);
    /* (a disc of 1e-200 mm made a matrix cairo cannot invert, and the run
    ** lost its preview and summary.json at the end: a thousandth of a
    ** pixel draws the same dot, its outline) */
    const double r = fmax(s->disc * scale, 1e-3);
    cairo_scale(cr, r, r * fmax(fabs(nv), 0.03));
    cairo_arc(cr, 0, 0, 1, 0, 2 * M_PI);
    cairo_restore(cr);
    if (nv >= 0) cairo_set_source_rgb(cr, 0.25 * shade, 0.55 * shade, 0.9 * shade);
    else cairo_set_source_rgb(cr, 0.9 * shade, 0.55 * shade, 0.25 * shade);
    cairo_fill_preserve(cr);
    if (p->pin[i]) cairo_set_source_rgb(cr, 0.6, 0.05, 0.05);
    else cairo_set_source_rgba(cr, 0, 0, 0, 0.35);
    cairo_stroke(cr);
  }
}

lw_status lw_particles_write_png(const lw_particles *p, const char *path, int frame, lw_error *err)
{
  const lw_particles_setup *s = p->setup;
  int size = s->png_size;
  depth_key *order = malloc((p->n ? p->n : 1) * sizeof *order);
  if (!order) return lw_error_set(err, LW_ENOMEM, "%s: out of memory for the preview", path);
  for (size_t i = 0; i < p->n; i++) order[i] = (depth_key){lw_v3_dot(p->x + 3 * i, s->view), i};
  qsort(order, p->n, sizeof *order, depth_cmp);
  cairo_surface_t *surf = lw_output_white_surface(size, size);
  cairo_t *cr = cairo_create(surf);
  lw_status st = LW_OK;
  if (cairo_status(cr)) {
    st = lw_error_set(err, LW_ENOMEM, "%s: cannot create a %d x %d picture", path, size, size);
    goto done;
  }
  paint(cr, p, order, size, frame);
  cairo_surface_flush(surf);
  if (cairo_status(cr)) {
    st = lw_error_set(err, LW_ERUN, "%s: drawing the preview failed: %s", path, cairo_status_to_string(cairo_status(cr)));
    goto done;
  }
  st = lw_output_png_surface(surf, path, err);
done:
  cairo_destroy(cr);
  cairo_surface_destroy(surf);
  free(order);
  return st;
}

lw_status lw_particles_draw(const lw_particles *p, const char *dir, lw_error *err)
{
  char path[LW_OUTPUT_PATH_MAX];
  if (snprintf(path, sizeof path, "%s/final.ply", dir) >= (int)sizeof path - 8)
    return lw_error_set(err, LW_EIO, "%s: path too long for the drawings", dir);
  lw_status s = lw_particles_write_ply(p, path, err);
  if (s) return s;
  snprintf(path, sizeof path, "%s/final.png", dir);
  return lw_particles_write_png(p, path, 0, err);
}
