/*
** params.h -- every scene parameter in one table that drives the INI reader,
** the --set overrides, the validation, the echo of resolved parameters and
** docs/PARAMETERS.md alike.
**
** A scene file is INI (read with inih): [section] headers and key = value
** lines; ';' or '#' start comments.  An unknown section or key, a repeated
** key, a value of the wrong type or outside its range is an error naming the
** file, the line and the key.
*/
#ifndef LINEWISE_PARAMS_H
#define LINEWISE_PARAMS_H

#include <stddef.h>
#include <stdio.h>

#include "linewise/error.h"

#define LW_PATH_MAX 1024
#define LW_PARAM_MAX 96  /* capacity of lw_params.line; the table is checked against it */

typedef enum { LW_PT_DOUBLE, LW_PT_INT, LW_PT_CHOICE, LW_PT_STRING } lw_param_type;

/* Range flags for numbers. */
#define LW_MIN_OPEN 1 /* value > min rather than >= min */
#define LW_MAX_OPEN 2

typedef struct {
  const char *section;
  const char *key;
  lw_param_type type;
  size_t offset;        /* into lw_params */
  const char *def;      /* default, as it would be written in a file */
  const char *unit;
  double min, max;      /* numbers: allowed range */
  int open;             /* LW_MIN_OPEN | LW_MAX_OPEN */
  const char *choices;  /* choice: "a|b|c"; stored as the index */
  const char *help;
  size_t size;          /* text: capacity of the field in lw_params, bytes */
} lw_param_def;

extern const lw_param_def lw_param_table[];
extern const size_t lw_param_count;

/* Choice indices (order of the choices strings in params.c). */
enum { LW_BND_RECT, LW_BND_CIRCLE, LW_BND_POLYGON };
enum { LW_POT_CONSTANT, LW_POT_RAMP, LW_POT_RADIAL };
enum { LW_FLD_CONSTANT, LW_FLD_RADIAL, LW_FLD_VORTEX, LW_FLD_WAVES };
enum { LW_STRAIN_SPLINE, LW_STRAIN_SEGMENT };
enum { LW_FIELDMODE_AXIAL, LW_FIELDMODE_SIGNED };

typedef struct {
  /* [scene] */
  double width, height;       /* page, mm */
  int boundary;               /* LW_BND_* */
  double margin;              /* rect and circle inset from the page edge, mm */
  char polygon[LW_PATH_MAX];  /* "x y x y ..." mm, for boundary = polygon */
  int potential;              /* LW_POT_* */
  double potential_value;     /* constant Phi */
  double potential_angle;     /* ramp direction, degrees */
  double potential_scale;     /* ramp half extent / radial radius, mm; 0 = automatic */
  int field;                  /* LW_FLD_* */
  double field_angle;         /* constant field direction, degrees */
  double field_wavelength;    /* waves, mm */
  double field_amplitude;     /* waves, mm */
  double center_x, center_y;  /* centre of radial/vortex presets, mm; -1 = page centre */
  /* [init] */
  int splines;                /* number of splines */
  int segments;               /* segments per spline */
  double segment_length;      /* mm */
  char from[LW_PATH_MAX];     /* a state.lw to start from, or empty */
  /* [energy] */
  double strain, bending, potential_coef, field_coef, pair, boundary_coef; /* S B Q P C R */
  int strain_mode;            /* LW_STRAIN_* */
  int field_mode;             /* LW_FIELDMODE_* */
  double pair_cutoff;         /* mm; 0 = none */
  double pair_near;           /* element lengths; 0 = off */
  int quadrature;             /* nodes per segment */
  /* [moves] */
  double mix_point, mix_vector, mix_translate, mix_rotate; /* relative frequencies */
  double step_point, step_vector;  /* initial Gaussian step, mm */
  double step_translate;      /* initial rigid translation step, mm */
  double step_rotate;         /* initial rigid rotation step, degrees */
  double target;              /* acceptance the single-DOF steps tune toward */
  double target_spline;       /* acceptance the rigid steps tune toward */
  int tune_sweeps;            /* tuning sweeps at the start of each temperature */
  /* [anneal] */
  char schedule[64];          /* a name from the schedule table */
  double t_start, t_end;      /* temperatures, energy units */
  int sweeps;                 /* sweeps in all (one sweep = one proposal per node) */
  int steps;                  /* temperature steps */
  double lambda;              /* adaptive cooling rate */
  char table[LW_PATH_MAX];    /* table schedule file */
  double seed;                /* RNG seed (a whole number, stored as double for the table) */
  int check_every;            /* sweeps between drift checks */
  /* [output] */
  int checkpoint_every;       /* sweeps between state.lw checkpoints */
  int trace_every;            /* sweeps per trace.csv row */
  double pen_width;           /* SVG/PNG stroke, mm */
  double png_scale;           /* preview pixels per mm */

  /* Where each value came from: the file and line (0 = default, -1 = --set). */
  char file[LW_PATH_MAX];
  int line[LW_PARAM_MAX];
} lw_params;

/* Fills p with every default. */
void lw_params_defaults(lw_params *p);

/* Reads an INI scene file into p (defaults first). */
lw_status lw_params_read(lw_params *p, const char *path, lw_error *err);

/* Applies one "section.key=value" override. */
lw_status lw_params_set(lw_params *p, const char *assignment, lw_error *err);

/* Writes every parameter as an INI file that reads back to the same values. */
int lw_params_write(const lw_params *p, FILE *f);

/* Writes the Markdown table of docs/PARAMETERS.md. */
void lw_params_write_doc(FILE *f);

/* The definition of section.key, or NULL. */
const lw_param_def *lw_params_find(const char *section, const char *key);

/* Where a parameter was set, for messages: "scene.ini:12", "--set" or "default". */
void lw_params_origin(const lw_params *p, const lw_param_def *d, char *buf, size_t n);

#endif
