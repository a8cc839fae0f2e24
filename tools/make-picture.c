/*
** make-picture.c -- writes the example picture (params/picture.png) that the
** image scene draws: 600 x 800 pixels of procedural tone structure, so the
** repository holds no third-party images.
**
**     make-picture OUT.png [SCALE]
**
** SCALE (an integer, 1 to 8; default 1) draws the same picture SCALE times
** larger a side: `make bench` times a camera's picture with 5, 3000 x 4000.
**
** A vertical gradient background, a shaded sphere lit from the upper left
** with a soft shadow on the ground, a dark triangle, a ring and a bar: soft
** shading (isophotes the edge tangent flow follows), hard edges and large
** dark areas (where the splines gather).  Colours differ only to exercise
** the gray conversion.  Deterministic: the same bytes every time.
*/
#include <cairo.h>
#include <stdio.h>
#include <stdlib.h>

#define W 600
#define H 800
#define PI 3.14159265358979323846

int main(int argc, char **argv)
{
  const int scale = argc == 3 ? atoi(argv[2]) : 1;
  if (argc < 2 || argc > 3 || scale < 1 || scale > 8) {
    fprintf(stderr, "usage: make-picture OUT.png [SCALE: 1 to 8]\n");
    return 2;
  }
  cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W * scale, H * scale);
  cairo_t *cr = cairo_create(s);
  cairo_scale(cr, scale, scale);

  /* sky to ground */
  cairo_pattern_t *bg = cairo_pattern_create_linear(0, 0, 0, H);
  cairo_pattern_add_color_stop_rgb(bg, 0.0, 0.97, 0.97, 1.0);
  cairo_pattern_add_color_stop_rgb(bg, 0.62, 0.80, 0.80, 0.84);
  cairo_pattern_add_color_stop_rgb(bg, 0.621, 0.62, 0.60, 0.56);
  cairo_pattern_add_color_stop_rgb(bg, 1.0, 0.42, 0.40, 0.36);
  cairo_set_source(cr, bg);
  cairo_paint(cr);
  cairo_pattern_destroy(bg);

  /* the sphere's soft shadow on the ground */
  cairo_save(cr);
  cairo_translate(cr, 340, 560);
  cairo_scale(cr, 1.0, 0.28);
  cairo_pattern_t *sh = cairo_pattern_create_radial(0, 0, 0, 0, 0, 210);
  cairo_pattern_add_color_stop_rgba(sh, 0.0, 0.05, 0.05, 0.05, 0.85);
  cairo_pattern_add_color_stop_rgba(sh, 1.0, 0.05, 0.05, 0.05, 0.0);
  cairo_set_source(cr, sh);
  cairo_arc(cr, 0, 0, 210, 0, 2 * PI);
  cairo_fill(cr);
  cairo_pattern_destroy(sh);
  cairo_restore(cr);

  /* the sphere, lit from the upper left */
  cairo_pattern_t *sp = cairo_pattern_create_radial(240, 260, 10, 300, 340, 190);
  cairo_pattern_add_color_stop_rgb(sp, 0.0, 1.0, 0.96, 0.92);
  cairo_pattern_add_color_stop_rgb(sp, 0.5, 0.75, 0.45, 0.35);
  cairo_pattern_add_color_stop_rgb(sp, 1.0, 0.12, 0.05, 0.04);
  cairo_set_source(cr, sp);
  cairo_arc(cr, 300, 340, 190, 0, 2 * PI);
  cairo_fill(cr);
  cairo_pattern_destroy(sp);

  /* a dark triangle, a ring and a bar */
  cairo_set_source_rgb(cr, 0.08, 0.10, 0.16);
  cairo_move_to(cr, 40, 770);
  cairo_line_to(cr, 230, 770);
  cairo_line_to(cr, 120, 590);
  cairo_close_path(cr);
  cairo_fill(cr);
  cairo_set_line_width(cr, 22);
  cairo_set_source_rgb(cr, 0.15, 0.30, 0.12);
  cairo_arc(cr, 470, 690, 70, 0, 2 * PI);
  cairo_stroke(cr);
  cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
  cairo_rectangle(cr, 60, 60, 30, 300);
  cairo_fill(cr);

  cairo_destroy(cr);
  cairo_status_t st = cairo_surface_write_to_png(s, argv[1]);
  cairo_surface_destroy(s);
  if (st != CAIRO_STATUS_SUCCESS) {
    fprintf(stderr, "make-picture: %s: %s\n", argv[1], cairo_status_to_string(st));
    return 1;
  }
  return 0;
}
