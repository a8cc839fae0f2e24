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

#ifdef __cplusplus
extern "C" {
#endif

#define LW_PATH_MAX 1024
#define LW_PARAM_MAX 256 /* capacity of lw_params.line; the table is checked against it */
#define LW_PARAMS_FILES_MAX 8 /* files a run reads as it starts, recorded in its scene.ini */
/* The largest text field (scene.polygon); buffers that hold any value are
** sized by it. */
#define LW_PARAM_TEXT_MAX 8192
/* A run's seed: 0 to 2^32 - 1, in anneal.seed, --seed and state.lw alike (a
** wider key alone would write states that resume refused). */
#define LW_SEED_MAX 4294967295.0

/* LW_PT_WHOLE: a whole number beyond int's range (the seed), held in a double. */
typedef enum { LW_PT_DOUBLE, LW_PT_INT, LW_PT_WHOLE, LW_PT_CHOICE, LW_PT_STRING } lw_param_type;

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
  int list;             /* text: a list of numbers, which may go on over indented lines */
} lw_param_def;

extern const lw_param_def lw_param_table[];
extern const size_t lw_param_count;

/* Choice indices (order of the choices strings in params.c). */
enum {
  LW_PAGE_CUSTOM, LW_PAGE_A4, LW_PAGE_A3, LW_PAGE_LETTER, LW_PAGE_A5, LW_PAGE_A6,
  LW_PAGE_A2, LW_PAGE_A1, LW_PAGE_A0, LW_PAGE_TABLOID, LW_PAGE_LEGAL
};
enum { LW_ORIENT_PORTRAIT, LW_ORIENT_LANDSCAPE, LW_ORIENT_AUTO };
enum { LW_BND_RECT, LW_BND_CIRCLE, LW_BND_POLYGON, LW_BND_MASK };
enum { LW_POT_CONSTANT, LW_POT_RAMP, LW_POT_RADIAL, LW_POT_IMAGE };
enum { LW_FLD_CONSTANT, LW_FLD_RADIAL, LW_FLD_VORTEX, LW_FLD_WAVES, LW_FLD_ETF, LW_FLD_GRADIENT, LW_FLD_FILE };
enum { LW_FFY_UP, LW_FFY_DOWN };
enum { LW_FFS_UNIT, LW_FFS_MAX, LW_FFS_NONE };
enum { LW_FFL_GRID, LW_FFL_POINTS };
enum { LW_MASK_NONE, LW_MASK_ALPHA, LW_MASK_IMAGE };
enum { LW_STRAIN_SPLINE, LW_STRAIN_SEGMENT };
enum { LW_FIELDMODE_AXIAL, LW_FIELDMODE_SIGNED };
enum { LW_LADDER_FIXED, LW_LADDER_EQUAL };
enum { LW_QUENCH_NONE, LW_QUENCH_BFGS };
enum { LW_PPATTERN_CLOUD, LW_PPATTERN_PLANE, LW_PPATTERN_SPHERE };
enum { LW_PWEIGHT_POLY, LW_PWEIGHT_GAUSS, LW_PWEIGHT_ANISO };
enum { LW_PBOUNDARY_NONE, LW_PBOUNDARY_PLANE, LW_PBOUNDARY_SPHERE };
enum { LW_PRESET_NONE, LW_PRESET_PHOTO };
enum { LW_PIN_NONE, LW_PIN_ENDS, LW_PIN_FIRST, LW_PIN_LAST };
enum { LW_INTEGRATOR_LEAPFROG, LW_INTEGRATOR_REVIEW };
enum { LW_LSRC_TONE, LW_LSRC_CMYK, LW_LSRC_PALETTE };
enum { LW_APART_ALL, LW_APART_PEN }; /* layers.apart */
enum { LW_GCODE_TRAVEL_RAPID, LW_GCODE_TRAVEL_FEED }; /* plot.gcode_travel */

typedef struct {
  /* [scene] */
  char system[64];            /* a name from the system table (system.h) */
  int page;                   /* LW_PAGE_*: a named size sets width and height */
  int orientation;            /* LW_ORIENT_* of a named page */
  double width, height;       /* page, mm */
  int boundary;               /* LW_BND_* */
  double margin;              /* rect and circle inset from the page edge, mm */
  char polygon[LW_PARAM_TEXT_MAX]; /* "x y x y ..." mm, for boundary = polygon */
  char image[LW_PATH_MAX];    /* picture, relative to the scene file, or empty */
  double image_max_pixels;    /* downsampling budget, pixels */
  int image_width;            /* resample to this width, pixels; 0 = keep */
  double image_blur;          /* Gaussian sigma, mm on the page */
  double image_flatten;       /* radius of the paper's brightness, mm on the page; 0 = off */
  double image_gamma;         /* tone curve exponent */
  double image_contrast;      /* tone curve slope about 1/2 */
  double image_levels;        /* auto levels: share clipped at each end; 0 = off */
  int image_levels_alpha;     /* 1: the levels are of the picture under its alpha; 0: of the composite */
  int image_levels_flat;      /* 1: a flat colour with a thin tail beyond it keeps its end too */
  int image_invert;           /* 1 = t <- 1 - t first */
  int potential;              /* LW_POT_* */
  double potential_value;     /* constant Phi */
  double potential_angle;     /* ramp direction, degrees */
  double potential_scale;     /* ramp half extent / radial radius, mm; 0 = automatic */
  double potential_power;     /* potential = image: Phi = tone^power */
  double potential_blur;      /* potential = image: sigma of Phi's blur, mm; 0 = none */
  int potential_paper;        /* 1: the blur reads white paper beyond the picture; 0: its edge continued */
  int potential_fine;         /* 1: pixels wider than 1 mm read through a finer grid; 0: a node a pixel */
  int field;                  /* LW_FLD_* */
  double field_angle;         /* constant field direction (etf fallback), degrees */
  double field_sigma;         /* etf tensor smoothing, mm */
  double field_flat;          /* etf/gradient flatness threshold, tone per mm */
  double field_wavelength;    /* waves, mm */
  double field_amplitude;     /* waves, mm */
  double field_core;          /* radial, vortex: core radius, mm; -1 = init.segment_length */
  double center_x, center_y;  /* centre of radial/vortex presets, mm; -1 = page centre */
  char field_file[LW_PATH_MAX]; /* field = file: the grid's .npy or text file */
  int field_file_y;           /* LW_FFY_*: the file's rows and v from the bottom up, or from the top down */
  int field_file_scale;       /* LW_FFS_*: each vector made unit, all divided by the longest, or as given */
  int field_file_layout;      /* LW_FFL_*: a grid of u v, or a list of points x y u v */
  int mask;                   /* LW_MASK_* */
  char mask_image[LW_PATH_MAX]; /* picture of mask = image */
  char driver[64];            /* a name from the driver table (driver.h) */
  int preset;                 /* LW_PRESET_*: fills the keys a scene leaves unset */
  /* [init] */
  int splines;                /* number of splines; 0 with coverage > 0: from the coverage */
  double coverage;            /* target ink coverage (fraction of the inside) */
  int segments;               /* segments per spline */
  double segment_length;      /* mm */
  char from[LW_PATH_MAX];     /* a state.lw to start from, or empty */
  /* [energy] */
  double strain, bending, potential_coef, field_coef, pair, boundary_coef; /* S B Q P C R */
  int strain_mode;            /* LW_STRAIN_* */
  int field_mode;             /* LW_FIELDMODE_* */
  double pair_cutoff;         /* mm; 0 = none */
  double pair_near;           /* element lengths; 0 = off */
  double boundary_clearance;  /* boundary: least distance from the frame, in length elements */
  double min_speed;           /* regularity: fraction of the mean speed; 0 = none */
  double regularity;          /* regularity: Bernstein ellipse parameter; <= 1 = none */
  double parametrisation;     /* G, energy / mm; 0 = off */
  int quadrature;             /* nodes per segment */
  int pair_quadrature;        /* pair samples per segment; 0 = quadrature */
  int tone_quadrature;        /* tone samples per segment; 0 = quadrature */
  double tone;                /* T, energy / mm^2; 0 = off */
  double tone_blur;           /* sigma of the tone term's blur, mm */
  double tone_ink;            /* ink fraction the darkest tone asks for */
  double min_spacing;         /* least distance between curves of different splines, mm; 0 = none */
  double chem_spline;         /* chemical potential: energy per spline; 0 = none */
  double chem_length;         /* chemical potential: energy per mm of line; 0 = none */
  /* [moves] */
  double mix_point, mix_vector, mix_translate, mix_rotate; /* relative frequencies */
  double step_point, step_vector;  /* initial Gaussian step, mm */
  double step_translate;      /* initial rigid translation step, mm */
  double step_rotate;         /* initial rigid rotation step, degrees */
  double target;              /* acceptance the single-DOF steps tune toward */
  double target_spline;       /* acceptance the rigid steps tune toward */
  int tune_sweeps;            /* tuning sweeps at the start of each temperature */
  int fixed_count;            /* 1: no trans-dimensional moves (the count stays as placed) */
  double mix_birth, mix_death, mix_grow, mix_shrink; /* relative frequencies (fixed_count = 0) */
  double birth_uniform;       /* share of births placed uniformly rather than by darkness */
  double birth_spread;        /* share of births of a segment count other than init.segments */
  double prior_sd;            /* the prior's next-point deviation, in init.segment_length */
  int max_segments;           /* grow never makes a spline longer than this, segments */
  double mix_split, mix_join; /* relative frequencies of split and join (fixed_count = 0) */
  double join_radius;         /* ends closer than this join, in init.segment_length */
  /* [anneal] */
  char schedule[64];          /* a name from the schedule table */
  double t_start, t_end;      /* temperatures, energy units */
  int sweeps;                 /* sweeps in all (one sweep = one proposal per node) */
  int steps;                  /* temperature steps */
  double lambda;              /* adaptive cooling rate */
  char table[LW_PATH_MAX];    /* table schedule file */
  double seed;                /* RNG seed (a whole number, stored as double for the table) */
  int seed_version;           /* how the seed makes the streams' seeds (lw_stream_seed) */
  int check_every;            /* sweeps between drift checks */
  int delayed_acceptance;     /* 1: two-stage Metropolis where the row offers it (mc.h) */
  char domains[64];           /* off, auto or domains per side (domains.h) */
  int quench;                 /* LW_QUENCH_*: after the last sweep, to the nearest local minimum */
  double quench_tol;          /* stop at this gradient norm, energy/mm */
  int quench_iterations;      /* at most this many minimiser iterations */
  double quench_stall;        /* stop when the last 50 iterations removed less than this share */
  /* [tempering] */
  int replicas;               /* 1 = no tempering */
  double t_min, t_max;        /* geometric ladder, energy units */
  char ladder[6144];          /* explicit ladder "t0 t1 ...", overrides t_min/t_max: 256 rungs at 17 digits */
  char ladder_file[LW_PATH_MAX]; /* a file of the ladder (ladder.ini's form), read into ladder at a run's start */
  int exchange_every;         /* sweeps between exchange steps */
  int tune_ladder;            /* LW_LADDER_* */
  int ladder_sweeps;          /* warm-up sweeps of ladder tuning */
  /* [output] */
  int checkpoint_every;       /* sweeps between state.lw checkpoints */
  int trace_every;            /* sweeps per trace.csv row */
  int observables;            /* 1 = the system's observables in trace.csv */
  int trace_exact;            /* 1 = trace.csv's numbers read back exactly; 0 = at 10 digits (runs before) */
  int stats_from;             /* first sweep of the stretch the statistics take (0: the final temperature's) */
  int samples_every;          /* sweeps between samples/sample-SSSSSS.csv (0: none) */
  double pen_width;           /* stroke of every pen, mm */
  int pens;                   /* pens (Inkscape layers), 1..16 */
  char pen_colors[LW_PATH_MAX]; /* "#rrggbb ..." one per pen; empty = black */
  int order;                  /* lw_plot_order: none, greedy, 2opt */
  double png_scale;           /* preview pixels per mm */
  int pdf;                    /* 1 = write final.pdf */
  int hpgl, gcode;            /* 1 = write final.hpgl, final.gcode (plotter.h) */
  int preview_image;          /* 1 = tone under the previews */
  int frames_every;           /* sweeps between frames; 0 = none */
  double fidelity_sigma;      /* blur before the fidelity score, mm */
  char fidelity_reference[LW_PATH_MAX]; /* picture the score is against, or empty: the target */
  int field_preview;          /* 1 = write field.png */
  /* [plot] (strokes.h) */
  double join_distance;       /* pen widths; 0 = no joining */
  double join_angle;          /* degrees */
  int crop;                   /* 1 = crop to the picture's rectangle */
  double min_length;          /* pen widths; 0 = keep all */
  double speed_down, speed_up; /* plot time estimate, mm/s */
  double lift_time;           /* s per pen lift */
  double plot_tolerance;      /* chords of final.hpgl and final.gcode, mm */
  int plot_turn;              /* 1: final.hpgl and final.gcode turn the page a quarter turn */
  char gcode_pen_up[128], gcode_pen_down[128]; /* final.gcode's pen lines */
  double plot_bed_w, plot_bed_h; /* the machine's reach, mm (0: unchecked) */
  int gcode_travel;           /* LW_GCODE_TRAVEL_*: final.gcode's pen-up moves */
  /* [layers] (layers.h) */
  char ly_names[LW_PATH_MAX]; /* layer names; empty = no layers */
  int ly_source;              /* LW_LSRC_* */
  int ly_apart;               /* LW_APART_*: which lines keep apart */
  char ly_colors[LW_PATH_MAX]; /* a colour a layer, or empty */
  char ly_turn[LW_PATH_MAX];  /* degrees a layer, or empty */
  char ly_tone_min[LW_PATH_MAX], ly_tone_max[LW_PATH_MAX]; /* a tone a layer, or empty */
  char ly_pen_width[LW_PATH_MAX]; /* mm a layer, or empty */
  int ly_share_width;         /* a layer's share over its pen width (0: its ink alone, runs before) */
  /* [particles] (system = particles; particles.h) */
  int pt_count;               /* particles placed by the pattern */
  int pt_pattern;             /* LW_PPATTERN_* */
  double pt_size;             /* pattern extent (cube side, disc or sphere diameter), length; 0 = automatic */
  double pt_noise;            /* Gaussian noise of the placed positions, length */
  double pt_normal_noise;     /* Gaussian tilt of the placed normals, degrees */
  char pt_points[LW_PATH_MAX];/* point file "x y z [nx ny nz]" per line, or empty */
  int pt_pinned;              /* 1 = the points of the file are pinned */
  double pt_r0;               /* Lennard-Jones equilibrium spacing, length */
  double pt_range;            /* interaction range, units of r0 */
  int pt_weight;              /* LW_PWEIGHT_* */
  double pt_sigma;            /* gauss sigma_r and aniso a, units of r0 */
  double pt_sigma_normal;     /* aniso b (<= sigma), units of r0 */
  double pt_alpha_lj, pt_alpha_p, pt_alpha_n, pt_alpha_c; /* pair coefficients */
  double pt_gravity;          /* energy per length of height */
  int pt_boundary;            /* LW_PBOUNDARY_* */
  double pt_boundary_z;       /* plane boundary: particles stay above this height, length */
  double pt_boundary_radius;  /* sphere boundary: particles stay inside it (centre 0), length */
  double pt_alpha_b;          /* soft wall alpha_b / d^2, energy length^2; 0 = hard wall only */
  double pt_view_azimuth;     /* preview view direction, degrees */
  double pt_view_elevation;   /* degrees */
  int pt_png_size;            /* preview pixels per side */
  double pt_disc;             /* preview disc radius, units of r0 */
  double pt_birth, pt_death;  /* mix weights of births and deaths (0: the count is fixed) */
  double pt_chem;             /* energy per particle */
  int pt_max_count;           /* births stop at this count */
  /* [dynamics] (driver = dynamics; dynamics.h) */
  double dyn_rho;             /* line density, mass per mm; 0 = massless (gradient flow) */
  double dyn_gamma;           /* Rayleigh damping, force per (mm/s) per mm */
  double dyn_dashpot;         /* particles: damping of neighbours' relative velocity, force s / length */
  double dyn_dashpot_angular; /* particles: of their relative angular velocity, energy s */
  double dyn_dt;              /* time step, s */
  double dyn_gravity_x, dyn_gravity_y; /* g, mm/s^2 (y down the page) */
  double dyn_force_x, dyn_force_y;     /* constant force per mm of line */
  int dyn_pin;                /* LW_PIN_*: which end nodes are held */
  int dyn_pin_vectors;        /* 1 = a pinned node's vector is held too */
  int dyn_steps_per_sweep;    /* time steps per sweep of the run loop */
  int dyn_integrator;         /* LW_INTEGRATOR_* */
  /* [nurbs] (system = nurbs; sys_nurbs.h) */
  int nb_order;               /* k */
  char nb_points[4096];       /* "x y x y ..." */
  char nb_weights[4096];      /* "w w ...", empty = all 1 */
  char nb_knots[4096];        /* n + k knots, empty = open uniform */
  char nb_file[LW_PATH_MAX];  /* "x y [w]" a line instead of points/weights, or empty */
  int nb_elevate;             /* degree elevation before the run */
  int nb_refine;              /* each knot span cut into this many */
  double nb_alpha, nb_beta;   /* energy coefficients */
  int nb_gauss;               /* Gauss points per knot span */
  int nb_pieces;              /* a span's pieces: 2 by its knots, 1 as before 2026-12-07 */
  int nb_fixed;               /* control points held at each end */
  int nb_free_weights;        /* 1: the weights are coordinates (s = log w) */
  double nb_step_weight;      /* weight move's half width in s */
  double nb_weight_inertia;   /* free weights: added inertia of s per unit density */
  double nb_weight_stiffness; /* free weights: spring on log w, energy */
  double nb_svg_tolerance;    /* rational curves in final.svg, length */
  double nb_png_scale;        /* pixels per length */

  /* Where each value came from: the file and line (0 = default, -1 = --set,
  ** LW_PARAMS_SEED_OPTION = the run's --seed). */
  char file[LW_PATH_MAX];
  int line[LW_PARAM_MAX];
  int of_run;                 /* read from a run's scene.ini (lw_params_read_run) */
  int run_written;            /* and that file carries a run's header (LW_RUN_SCENE_HEADER) among the
                              ** comments above its first section: linewise wrote it, not a hand */
  int run_header;             /* the scene file carries that header there, whatever reads it */
  /* The files the run that wrote that scene.ini read as it started, by the
  ** hash of their bytes (lw_params_write_files), that running it again may
  ** tell one changed since. */
  int n_files;
  unsigned short file_key[LW_PARAMS_FILES_MAX];
  unsigned long long file_hash[LW_PARAMS_FILES_MAX];
  char run_build[64];         /* and the release and build that wrote it ("2026.12, build ..."), or "" */
  char run_libraries[256];    /* and the libraries it ran on (lw_version_libraries), or "" */
} lw_params;

/* Fills p with every default. */
void lw_params_defaults(lw_params *p);

/* Reads an INI scene file into p (defaults first). */
lw_status lw_params_read(lw_params *p, const char *path, lw_error *err);

/* The same without lw_params_resolve, for a caller that changes keys (--set)
** and then resolves: what the file says and a --set replaces is not checked
** on its own (a picture the file names need not exist when --set names
** another; the photo preset's orientation = auto would read its header).
** p is not to be used before lw_params_resolve (lw_anneal_start resolves
** its own copy). */
lw_status lw_params_read_unresolved(lw_params *p, const char *path, lw_error *err);

/* Reads a run directory's scene.ini, which holds every key the run's build
** knew, resolved.  A key it lacks is newer than the run, which ran with its
** default: a preset does not fill it (the photo preset's layers.apart = pen
** or image_levels would change the energy of a run begun before them).
** resolve 0: not resolved yet (a resume checks the run's hash first, and a
** picture replaced by one of another shape would fail the page's size). */
lw_status lw_params_read_run(lw_params *p, const char *path, int resolve, lw_error *err);

/* The most bytes text key d holds: its field's, and for a key that is not a
** list what fits on one line "key = value" of the INI reader, so that a
** run's scene.ini reads back (a list goes on over indented lines). */
size_t lw_params_text_cap(const lw_param_def *d);

/* Writes "key = value" for list key d as scene.ini holds it, over indented
** lines where it does not fit on one (f NULL: only checks); 0 where the
** text cannot be broken so (a part of more than a line without a single
** blank), which the reader refuses to take. */
int lw_params_write_list(FILE *f, const lw_param_def *d, const char *value);

/* Whether text, written as a value into a run's scene.ini, reads back the
** same: no control characters, no blanks at either end, no ';' at the start
** or after a blank (which begins a comment). */
int lw_params_text_reads_back(const char *text);

/* Settles what depends on several keys, once all are known: a named page
** sets width and height (an explicit width or height that disagrees is an
** error naming its line), and pen_colors must hold one colour per pen.
** lw_params_read calls it; call it again after overrides. */
lw_status lw_params_resolve(lw_params *p, lw_error *err);

/* Refuses (naming plot.bed_width or bed_height) a drawing area, box = x0 y0
** x1 y1 in page millimetres, that reaches past the machine's bed on its
** axes under plot.turn, where final.hpgl or final.gcode is written; what:
** the area in words, NULL for the page inset by scene.margin. */
lw_status lw_params_bed_check(const lw_params *p, const double box[4], const char *what, lw_error *err);

/* Applies one "section.key=value" override (call lw_params_resolve after
** the last one).  A relative path a key names is then found from the scene
** file's directory, as in the file; the command line's --set makes it
** absolute from the current directory first.  Messages say "--set". */
lw_status lw_params_set(lw_params *p, const char *assignment, lw_error *err);

/* What lw_params_run_hash saw of each key it hashed: the key's index in
** lw_param_table, 16 bits of the key's own hash, and the errno that stopped
** the reading of the file the key names (0 where read, or not a file). */
#define LW_PARAMS_SEED_OPTION (-2)

typedef struct lw_run_keys {
  size_t n;
  unsigned short index[LW_PARAM_MAX], hash[LW_PARAM_MAX];
  int unread[LW_PARAM_MAX];
} lw_run_keys;

/* A hash of the keys that steer a run (all but [plot] and the keys that
** only shape the final files), as scene.ini writes them: all of them, or of
** a run's own scene.ini those it holds (a later build knows more, and its
** defaults may differ).  state.lw keeps it, so that a resume refuses a
** scene.ini edited since.  With keys (the form since 2026-12-05, which
** state.lw marks by its scene_keys), a key that names a file counts by the
** file's bytes, not its name: a run whose picture moves resumes once the
** key names the new place, and one whose table was edited does not; a
** file the run never reads as it goes on (init.from, read at the start; a
** table or mask picture its settings leave idle) does not count.  keys NULL:
** the form before, by the names, for older files. */
unsigned long long lw_params_run_hash(const lw_params *p, lw_run_keys *keys);

/* Whether the file key d names is never read by the run as it goes on:
** init.from and tempering.ladder_file (read at the start only), a table
** under a schedule that reads none, a mask picture without mask = image.
** Such a file may move or
** change (lw_params_run_hash), and a run notes a table or mask picture so
** given as having no effect. */
int lw_params_file_idle(const lw_params *p, const lw_param_def *d);

/* Writes every parameter as an INI file that reads back to the same values;
** -1 where writing failed, or the locale writes decimal commas (setlocale's
** LC_NUMERIC: the file would not read back). */
int lw_params_write(const lw_params *p, FILE *f);

/* Comment lines for a run's scene.ini, below its header: the release, and
** each file the run reads as it starts (a picture, a start state, a table)
** as "; file section.key: fnv1a-64 <16 hex digits>".  Reading that
** scene.ini again keeps them (lw_params.file_hash). */
int lw_params_write_files(const lw_params *p, FILE *f);

/* The keys among p's recorded files whose bytes differ now or cannot be
** read (but those --set names), as "scene.image (PATH)" joined by ", " in
** buf; returns how many. */
int lw_params_files_changed(const lw_params *p, char *buf, size_t n);

/* Whether the scene gives key d a value of its own: from its file or
** --set, and other than the default.  Of a run's scene.ini, which writes
** every key, only --set counts. */
int lw_params_given(const lw_params *p, const lw_param_def *d);

/* Where section.key was read (p->line): > 0 its line in p->file, < 0 an
** option (--set, --seed), 0 nowhere (a run's scene.ini writes every key,
** so 0 there is a key of a later release).  section.key must be a key of
** the table: a name no key has aborts (a key renamed without its readers
** read another key's line). */
int lw_params_line(const lw_params *p, const char *section, const char *key);

/* Whether section.key holds a run's own value: read from a run's scene.ini
** by resume or energy, not set over it with --set.  A check a later release
** adds leaves such a value as the run began with it. */
int lw_params_kept(const lw_params *p, const char *section, const char *key);

/* Whether patterns (NULL-terminated "section.key" or "section.*"; NULL:
** none) name key d. */
int lw_params_named(const char *const *patterns, const lw_param_def *d);

/* Writes the Markdown table of docs/PARAMETERS.md, with the scenes that read
** each key from read_by (lw_anneal_key_readers), and the words a text key
** takes from values ('|'- or ", "-separated, or NULL: any text;
** lw_anneal_key_values). */
void lw_params_write_doc(FILE *f, void (*read_by)(const lw_param_def *d, char *buf, size_t n),
                         const char *(*values)(const lw_param_def *d));

/* The definition of section.key, or NULL. */
const lw_param_def *lw_params_find(const char *section, const char *key);

/* Where a parameter was set, for messages: "scene.ini:12", "--set",
** "scene.ini:2 (scene.preset = photo)" for a key the preset filled (with the
** pen widths a length was sized from), "scene.ini (not set: the default,
** 1)", or "default" for parameters read from no file. */
void lw_params_origin(const lw_params *p, const lw_param_def *d, char *buf, size_t n);

/* Prefixes the message in err with where section.key was set and the key:
** input read on behalf of a key (a state, a point file) is reported as that
** key's error.  Returns err->code. */
lw_status lw_params_blame(const lw_params *p, const char *section, const char *key, lw_error *err);

/* Edit distance (insertions, deletions, substitutions) of two names, case
** aside (WIDTH had no suggestion, Width had), for "did you mean"; names of
** 64 bytes or more are far from everything. */
int lw_params_edit_distance(const char *a, const char *b);

#ifdef __cplusplus
}
#endif

#endif
