#define _XOPEN_SOURCE 700 /* realpath */
/*
** params.c -- the parameter table, the INI reader (inih), --set overrides,
** the echo of resolved parameters and the generated docs (params.h).
**
** inih does not report line numbers to the handler, so the file is fed to
** ini_parse_stream through a reader that counts the lines it hands out: the
** count at the moment the handler runs is the line of that key.
*/
#include "linewise/params.h"
#include "linewise/version.h"

#include <ctype.h>
#include <errno.h>
#include <ini.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "linewise/driver.h"
#include "linewise/image.h"
#include "linewise/number.h"
#include "linewise/output.h"
#include "linewise/plotter.h"
#include "linewise/quad.h"
#include "linewise/rundir.h"
#include "linewise/schedule.h"
#include "linewise/state.h"

#define OFF(f) offsetof(lw_params, f)
#define LW_PDF_SIDE_MAX 5080.0 /* mm: 14,400 points, the PDF reference's largest page */
#define NUM(sec, key, T, f, def, unit, lo, hi, open, help) \
  {sec, key, T, OFF(f), def, unit, lo, hi, open, NULL, help, 0, 0}
#define CHOICE(sec, key, f, def, choices, help) \
  {sec, key, LW_PT_CHOICE, OFF(f), def, "", 0, 0, 0, choices, help, 0, 0}
#define STRING(sec, key, f, def, unit, help) \
  {sec, key, LW_PT_STRING, OFF(f), def, unit, 0, 0, 0, NULL, help, sizeof ((lw_params *)0)->f, 0}
#define LIST(sec, key, f, def, unit, help) \
  {sec, key, LW_PT_STRING, OFF(f), def, unit, 0, 0, 0, NULL, help, sizeof ((lw_params *)0)->f, 1}

const lw_param_def lw_param_table[] = {
  STRING("scene", "system", system, "splines", "",
         "What is annealed: `splines` (cubic Bezier splines on the page), `particles` "
         "(oriented particles in 3-D, set up by the [particles] section; README, "
         "\"Oriented particles\") or `nurbs` (one D-NURBS curve, the [nurbs] section; "
         "docs/NURBS.md). docs/SYSTEMS.md."),
  STRING("scene", "driver", driver, "metropolis", "",
         "What moves the system: `metropolis` anneals it by Monte Carlo (the [anneal] schedule, "
         "[tempering] with replicas); `barker` is the same chain deciding by Barker's rule, "
         "e^x / (1 + e^x) with x = log q - dE / T (q a move's Hastings factor), instead of min(1, e^x), "
         "to compare acceptance rules "
         "(docs/NUMERICS.md, \"Acceptance rules\"); `dynamics` integrates its Lagrangian equations of "
         "motion (the [dynamics] section; docs/NUMERICS.md, \"Dynamics\"): a sweep is then "
         "`dynamics.steps_per_sweep` time steps and `anneal.sweeps` counts them."),
  CHOICE("scene", "preset", preset, "none", "none|photo",
         "Settings that fill every key the scene leaves unset: `photo` draws a picture as a "
         "tone of lines, sized from output.pen_width and the page rather than in fixed "
         "millimetres, so one scene works from A6 to A0 (docs/IMAGES.md, \"Photographs\", lists "
         "what it sets). Keys the scene or --set gives win."),
  CHOICE("scene", "page", page, "custom", "custom|a4|a3|letter|a5|a6|a2|a1|a0|tabloid|legal",
         "Page size: `custom` takes `width` and `height`; a6 is 105 x 148 mm, a5 148 x 210 mm, a4 210 x 297 mm, "
         "a3 297 x 420 mm, a2 420 x 594 mm, a1 594 x 841 mm, a0 841 x 1189 mm, letter 215.9 x 279.4 mm, "
         "legal 215.9 x 355.6 mm, tabloid 279.4 x 431.8 mm (portrait). A named page sets width and height; setting "
         "either as well is an error unless it agrees."),
  CHOICE("scene", "orientation", orientation, "portrait", "portrait|landscape|auto",
         "Orientation of a named page: landscape swaps its width and height; auto is landscape when the picture "
         "(`image`) is wider than tall, else portrait. The photo preset sets auto."),
  NUM("scene", "width", LW_PT_DOUBLE, width, "210", "mm", 1, 1e7, 0,
      "Page width (set by a named `page`); from 1 mm, as final.svg writes millimetres to 4 decimals."),
  NUM("scene", "height", LW_PT_DOUBLE, height, "297", "mm", 1, 1e7, 0,
      "Page height (set by a named `page`); from 1 mm, as the width."),
  CHOICE("scene", "boundary", boundary, "rect", "rect|circle|polygon|mask",
         "Shape of the frame `energy.boundary` keeps the lines inside (with it 0 they may leave, and "
         "what lies outside the page rectangle inset by `margin` is cut from the drawing; a circle, "
         "polygon or mask does not cut): the page rectangle inset by `margin`, "
         "the largest circle inside that rectangle, `polygon`, or `mask` (the inside of "
         "`mask`, by its signed distance transform; docs/IMAGES.md)."),
  NUM("scene", "margin", LW_PT_DOUBLE, margin, "10", "mm", 0, 1e7, 0,
      "Inset of the rect and circle boundaries from the page edge; the picture of `image` "
      "(and `mask_image`) is fitted into the page inset by it."),
  LIST("scene", "polygon", polygon, "", "mm",
       "Polygon boundary vertices as `x y x y ...` (at least 3 vertices; either orientation; a simple "
       "polygon, its edges meeting only at their shared vertices: a star is given by its outline). A "
       "long list goes on over indented lines (docs/FORMATS.md, \"Scene files\"), up to 8191 bytes, some 600 "
       "vertices; a detailed outline (a coast, lettering) is a picture: `boundary = mask`."),
  STRING("scene", "image", image, "", "path",
         "A picture (PNG, JPEG, GIF, BMP, binary PGM/PPM; gray or colour, with or without alpha) relative to "
         "the scene file. It is fitted into the page inset by `margin`, centred, aspect kept. "
         "Its tone feeds potential = image, field = etf and gradient, mask = alpha, and the "
         "placement of the splines (docs/IMAGES.md). Empty = none."),
  NUM("scene", "image_max_pixels", LW_PT_DOUBLE, image_max_pixels, "4e6", "pixels", 1, 1e9, 0,
      "Pictures with more pixels are box-filtered down to this many while they load (a note says so). "
      "Each pixel kept costs about 40 bytes in the set-up and 57 while the drawing is scored "
      "(docs/IMAGES.md, \"Memory\")."),
  NUM("scene", "image_width", LW_PT_INT, image_width, "0", "pixels", 0, 1e5, 0,
      "Resample the picture to this width, the height following the aspect ratio; 0 = as loaded. "
      "The resampled picture must still fit scene.image_max_pixels."),
  NUM("scene", "image_blur", LW_PT_DOUBLE, image_blur, "0", "mm", 0, 1e4, 0,
      "Standard deviation of a Gaussian blur of the tone, in millimetres on the page. 0 = none (as is "
      "any under a tenth of the picture's pixel)."),
  NUM("scene", "image_flatten", LW_PT_DOUBLE, image_flatten, "0", "mm", 0, 1e4, 0,
      "Flat-field correction, after the blur: the tone is divided by the paper's brightness "
      "about each pixel, the lightest tone within this radius on the page, smoothed, so that "
      "uneven light (a photographed page, a vignette) turns to white paper and only what is "
      "darker than its surroundings draws. Make it wider than the widest dark mark: a dark "
      "area wider than twice the radius turns light from its inside. 0 = off (docs/IMAGES.md)."),
  NUM("scene", "image_levels", LW_PT_DOUBLE, image_levels, "0", "", 0, 0.25, 0,
      "Auto levels, before the tone curve: the darkest and the lightest of this share of the "
      "picture's pixels turn black and white, the tones between stretched linearly (at most "
      "20 times), so that a dim or hazy picture uses the whole range. 0 = off; the photo "
      "preset sets 0.01."),
  NUM("scene", "image_levels_alpha", LW_PT_INT, image_levels_alpha, "1", "", 0, 1, 0,
      "A picture with transparency under image_levels: 1 = the levels and their stretch are of "
      "the picture under its alpha, composited over white paper again after (a half-transparent "
      "picture stays so); 0 = of the picture composited over white, as runs before 2026-12-06 "
      "(their darks went to one grey; a run of theirs, whose scene.ini has no line for this key, "
      "resumes so)."),
  NUM("scene", "image_levels_flat", LW_PT_INT, image_levels_flat, "2", "", 0, 2, 0,
      "image_levels on a flat colour: 1 = an end is left alone where one tone holds more than 5 % of the "
      "pixels with no more than 5 % beyond it (a graphic's lightest colour past whose anti-aliased edge or "
      "JPEG ringing the clip fell turned white whole); 2 = so, but an end left alone beside the other end's "
      "stretch that would crowd the picture's tones into less than a tenth of the range is stretched as any "
      "(a low-contrast elevation model's flat sea, its darkest, turned white with the whole picture under 1), "
      "as runs before 2026-12-07 did not; "
      "0 = only where the clip falls on such a tone, as runs before this key (a run of theirs, whose "
      "scene.ini has no line for this key, resumes so)."),
  NUM("scene", "image_gamma", LW_PT_DOUBLE, image_gamma, "1", "", 0, 100, LW_MIN_OPEN,
      "Tone curve t <- t^gamma (after `image_invert`): above 1 darkens the mid-tones."),
  NUM("scene", "image_contrast", LW_PT_DOUBLE, image_contrast, "1", "", 0, 100, 0,
      "Tone curve t <- 1/2 + contrast (t - 1/2), clipped to [0, 1] (after the gamma)."),
  NUM("scene", "image_invert", LW_PT_INT, image_invert, "0", "", 0, 1, 0,
      "1 = invert the tone first (t <- 1 - t): light parts of the picture get the ink."),
  CHOICE("scene", "potential", potential, "constant", "constant|ramp|radial|image",
         "Potential Phi read by the potential term: constant `potential_value`; ramp "
         "Phi = 1/2 + 1/2 (r-c).u/h from 0 to 1 across the page along `potential_angle`; "
         "radial Phi = |r-c|/h; image Phi = tone (0 black .. 1 white, 1 beyond the picture). "
         "Built only when [energy] potential is non-zero."),
  NUM("scene", "potential_value", LW_PT_DOUBLE, potential_value, "1", "", -1e12, 1e12, 0,
      "Phi of the constant potential."),
  NUM("scene", "potential_angle", LW_PT_DOUBLE, potential_angle, "0", "degrees", -360, 360, 0,
      "Direction in which the ramp potential rises (0 = +x, 90 = +y, down the page)."),
  NUM("scene", "potential_scale", LW_PT_DOUBLE, potential_scale, "0", "mm", 0, 1e7, 0,
      "h of the ramp and radial potentials; 0 = automatic (half the page extent along the ramp, "
      "(W |cos a| + H |sin a|) / 2 at potential_angle a; half the page diagonal for radial)."),
  NUM("scene", "potential_power", LW_PT_DOUBLE, potential_power, "1", "", 0, 100, LW_MIN_OPEN,
      "potential = image: Phi = tone^power. Above 1 the potential is near 0 everywhere but near white, "
      "so energy.potential > 0 costs line where the picture asks for none (stray lines in a white "
      "background) and little in the mid-tones. The photo preset sets 8, with potential = image and "
      "energy.potential = 7.14 pen widths (docs/IMAGES.md, \"White backgrounds\")."),
  NUM("scene", "potential_blur", LW_PT_DOUBLE, potential_blur, "0", "mm", 0, 1e4, 0,
      "potential = image: standard deviation of a Gaussian blur of Phi. Phi at the picture's own "
      "pixels can change between two quadrature nodes, and an annealer then puts the nodes where "
      "Phi is low and the line between them where it is high; blurred over about the nodes' "
      "spacing (segment_length / quadrature) it hides far less (docs/NUMERICS.md, \"The potential "
      "between the nodes\"). The photo preset sets 1.5 pen widths. 0 = none."),
  NUM("scene", "potential_paper", LW_PT_INT, potential_paper, "1", "", 0, 1, 0,
      "potential = image with potential_blur: 1 = the picture is blurred on white paper, so Phi rises to "
      "1 beyond its edge (no line lies off the picture for free); 0 = the blur continues the picture's "
      "edge pixels beyond it, as runs before 2026-12-06 did (a run of theirs, whose scene.ini has no "
      "line for this key, resumes so; docs/NUMERICS.md, \"The potential between the nodes\")."),
  NUM("scene", "potential_fine", LW_PT_INT, potential_fine, "1", "", 0, 1, 0,
      "potential = image: 1 = where a pixel is wider than 1 mm on the page, Phi lies on a finer grid "
      "(nodes no more than 1 mm apart), and the picture's edge pixels keep their tone out to its edge; "
      "0 = a node a pixel, Phi turning white from the edge pixels' centres, as runs before this key "
      "(a picture of one wide pixel was a pyramid; a run of theirs, whose scene.ini has no line for "
      "this key, resumes so; docs/IMAGES.md)."),
  CHOICE("scene", "field", field, "constant", "constant|radial|vortex|waves|etf|gradient|file",
         "Vector field v read by the field term (unit length): constant along `field_angle`, "
         "radial from the centre, vortex around it (v = (-(y - cy), x - cx) / r: clockwise as seen on "
         "the page, whose y points down; both fall to 0 within `field_core` of the centre), waves "
         "tangent to y = A sin(2 pi x / wavelength) (x from the page's left edge, y down the page), "
         "etf (the picture's edge tangent flow: along edges and isophotes; needs field_mode = axial) "
         "gradient (the picture's tone gradient, toward lighter tone) "
         "or file (a grid of vectors u v from `field_file`: docs/FORMATS.md, \"Field files\"). "
         "Built only when [energy] field is non-zero."),
  NUM("scene", "field_angle", LW_PT_DOUBLE, field_angle, "0", "degrees", -360, 360, 0,
      "Direction of the constant field, and of etf where the picture is flat (0 = +x, 90 = +y, down the page)."),
  NUM("scene", "field_sigma", LW_PT_DOUBLE, field_sigma, "2", "mm", 0, 1e4, 0,
      "etf: standard deviation of the Gaussian that smooths the structure tensor (the scale of "
      "the structures the flow follows). 0 = none."),
  NUM("scene", "field_flat", LW_PT_DOUBLE, field_flat, "0.01", "tone/mm", 0, 1e6, 0,
      "Tone gradient below which the picture counts as flat: etf turns toward `field_angle` there, "
      "gradient fades to 0."),
  NUM("scene", "field_wavelength", LW_PT_DOUBLE, field_wavelength, "50", "mm", 1e-3, 1e7, 0,
      "Wavelength of the waves field."),
  NUM("scene", "field_amplitude", LW_PT_DOUBLE, field_amplitude, "10", "mm", -1e7, 1e7, 0,
      "Amplitude A of the waves field."),
  NUM("scene", "field_core", LW_PT_DOUBLE, field_core, "-1", "mm", -1, 1e7, 0,
      "radial and vortex: radius of the core about the centre inside which the field's length falls "
      "smoothly to 0 (6u^5 - 15u^4 + 10u^3 of u = r / core), so that the quadrature resolves a segment "
      "passing the centre; -1 = init.segment_length; 0 = none, a unit field up to its centre, where "
      "8 nodes erred by up to 80 % of a segment's term (docs/NUMERICS.md, \"The field's centre\")."),
  NUM("scene", "center_x", LW_PT_DOUBLE, center_x, "-1", "mm", -1, 1e7, 0,
      "Centre of the radial and vortex presets and of the ramp; -1 = page centre (other values below 0 are "
      "refused)."),
  NUM("scene", "center_y", LW_PT_DOUBLE, center_y, "-1", "mm", -1, 1e7, 0,
      "See center_x."),
  STRING("scene", "field_file", field_file, "", "path",
         "field = file: the grid of vectors, relative to the scene file: NumPy .npy of shape (rows, columns, 2) "
         "or text, a row a line, u v for each node (docs/FORMATS.md, \"Field files\"). The grid covers the "
         "picture where the scene has one, else it is fitted into the page inset by `margin` as a picture of "
         "columns x rows pixels would be; a node is a pixel's centre. A cell that is NaN or infinite has no field."),
  CHOICE("scene", "field_file_y", field_file_y, "up", "up|down",
         "Which way field_file's rows and its v go: up, the first row at the bottom of the grid and v up the "
         "page (NumPy's meshgrid of increasing y, matplotlib's origin = 'lower'); down, the first row at the "
         "top and v down the page (a picture's rows, the page's y). In a list of points: the way its y "
         "column and v grow, up (north up, as GIS tools write them) or down the page."),
  CHOICE("scene", "field_file_scale", field_file_scale, "unit", "unit|max|none",
         "What field_file's lengths mean: unit, each vector made length 1 (the lines follow its direction "
         "alone, however weak the flow); max, all divided by the longest (a weak flow steers less); none, as "
         "given (the field term's weight times the file's units)."),
  CHOICE("scene", "field_file_layout", field_file_layout, "grid", "grid|points",
         "How field_file lays out its vectors: grid, a row of nodes a line, u v for each, on square cells; "
         "points, a text list of 'x y u v' a line (a header row's names choosing the columns: ParaView's or a "
         "spreadsheet's CSV, Tecplot's VARIABLES; gnuplot's blocks) sampling a regular grid, each node once, its "
         "cells as wide and tall as x and y space them."),
  CHOICE("scene", "mask", mask, "none", "none|alpha|image",
         "Where the inside of boundary = mask comes from: the alpha channel of `image` "
         "(opaque is inside), or the picture `mask_image` (opaque and dark is inside). "
         "Threshold 1/2; fitted into the page like `image`. Refused under another boundary."),
  STRING("scene", "mask_image", mask_image, "", "path",
         "The picture of mask = image, relative to the scene file."),
  NUM("init", "splines", LW_PT_INT, splines, "100", "", 0, 1e8, 0,
      "Number of splines placed at random inside the boundary (weighted by darkness when the "
      "scene has an image, along the field when the field term is on). 0 with `coverage` > 0: "
      "as many as the coverage asks for."),
  NUM("init", "coverage", LW_PT_DOUBLE, coverage, "0", "", 0, 100, 0,
      "Target ink coverage; needs splines = 0: splines = coverage * (sum of darkness (1 - tone) "
      "over the inside, mm^2) / (output.pen_width * segments * segment_length); without an "
      "image the darkness is 1. 0 = off."),
  NUM("init", "segments", LW_PT_INT, segments, "4", "", 1, 1e5, 0,
      "Cubic Bezier segments per spline."),
  NUM("init", "segment_length", LW_PT_DOUBLE, segment_length, "10", "mm", 1e-6, 1e7, 0,
      "Length of each segment; a spline's rest length L0 is segments * segment_length. At least a "
      "nanometre: the bending term's powers of shorter lengths leave the range of doubles."),
  STRING("init", "from", from, "", "path",
         "A state.lw to start from instead of random placement (relative to the scene file)."),
  NUM("energy", "strain", LW_PT_DOUBLE, strain, "0", "energy / mm", 0, 1e12, 0,
      "S: strain S L (L - L0)^2 / L0^2 keeps each spline's length near L0, L measured by the run's "
      "quadrature (energy.quadrature). 0 = off."),
  CHOICE("energy", "strain_mode", strain_mode, "spline", "spline|segment",
         "Strain per spline (L = whole length) or per segment (each segment against L0/n: the sum over "
         "segments of S l (l - L0/n)^2 / (L0/n)^2)."),
  NUM("energy", "bending", LW_PT_DOUBLE, bending, "0", "energy mm", 0, 1e12, 0,
      "B: bending B * integral of curvature^2 dl favours gentle curves. 0 = off."),
  NUM("energy", "potential", LW_PT_DOUBLE, potential_coef, "0", "energy / mm", -1e12, 1e12, 0,
      "Q: potential Q * integral of Phi dl draws lines to low Phi (dark tone). 0 = off."),
  NUM("energy", "field", LW_PT_DOUBLE, field_coef, "0", "energy / mm", -1e12, 1e12, 0,
      "P: field P * integral of r'.v dt (signed fields) or |r'.v| dt (axial), r' = dr/dt on each segment's "
      "t in [0, 1]: the line's length along v; negative P rewards alignment with v. 0 = off. It pays per "
      "millimetre of aligned line, so a |P| far above the strain and bending weights buys length: "
      "on a vortex with strain 20 and bending 2, P = -10 drew clean circles (alignment 0.9999), "
      "-100 longer crossing arcs (0.978)."),
  CHOICE("energy", "field_mode", field_mode, "axial", "axial|signed",
         "axial integrates |r'.v| (lines have no direction); signed integrates r'.v (lines run along v: the "
         "drawing's paths keep that direction only with output.order = none, which the plotter's order would "
         "turn where it saves travel)."),
  NUM("energy", "pair", LW_PT_DOUBLE, pair, "0", "energy / mm", 0, 1e12, 0,
      "C: pair repulsion C * double integral of dl dl / r between different splines, each pair of splines "
      "once (sum over i < j; none within one spline). 0 = off."),
  NUM("energy", "pair_cutoff", LW_PT_DOUBLE, pair_cutoff, "5", "mm", 0, 1e7, 0,
      "Pair interaction range; the kernel is shifted to 1/r - 1/rc so the energy is continuous. "
      "At least about two length elements (init.segment_length / pair nodes): the placed segments' "
      "widest gap between pair samples over 0.75, as every segment's gap must stay within 0.75 cutoffs. "
      "0 = no cutoff (all pairs; slow for large scenes)."),
  NUM("energy", "pair_near", LW_PT_DOUBLE, pair_near, "1.5", "element lengths", 0, 100, 0,
      "Near field: two segments with a pair of samples closer than this many length elements "
      "(the larger of the two; at most the cutoff) take the double integral over the exact curves, "
      "blended smoothly into the product rule (finite where curves touch or cross). "
      "0 = off (product rule only; infinite where samples coincide). Otherwise at least sqrt 2 times "
      "the pair rule's widest node spacing over its largest weight (1.431 at 8 nodes, 1.475 at 4, "
      "1.633 at 2, rounded up), where a crossing between samples is taken whole; less is refused "
      "(docs/ACCURACY.md, \"Near field\"), but in a run begun before 2026-12-05."),
  NUM("energy", "boundary", LW_PT_DOUBLE, boundary_coef, "0", "energy mm", 0, 1e12, 0,
      "R: boundary R * integral of 1/d^2 dl keeps lines inside (+infinity outside). 0 = off."),
  NUM("energy", "boundary_clearance", LW_PT_DOUBLE, boundary_clearance, "1.5", "length elements", 0, 100, 0,
      "With the boundary term on, a segment whose curve comes closer to the frame than this many of "
      "its own length elements (its length / nodes), anywhere between the nodes too, is forbidden "
      "(+infinity, like leaving the frame): closer, the nodes cannot resolve 1/d^2 and an end or a "
      "bulge at the frame would hide its energy. 1.5 keeps each segment's boundary integral at 8 "
      "nodes within 2e-4 (docs/ACCURACY.md; not across a corner's bisector, where the distance has a "
      "kink). The photo preset sets 0.5, so that lines reach a frame or a mask's outline. "
      "0 = the curve only has to stay inside."),
  NUM("energy", "min_speed", LW_PT_DOUBLE, min_speed, "0.4", "fraction of the mean speed", 0, 1, LW_MAX_OPEN,
      "Regularity: a segment whose speed |r'| falls anywhere below this fraction of its mean speed "
      "(its length) is forbidden (+infinity, like leaving the frame), whatever the node count: "
      "there it folds, and the quadrature cannot see its bending. With `regularity` it keeps the "
      "bending integral at 8 nodes within 1e-3 on every allowed segment (docs/ACCURACY.md). "
      "0 = no check."),
  NUM("energy", "regularity", LW_PT_DOUBLE, regularity, "2.6", "Bernstein ellipse parameter", 0, 1e6, 0,
      "Regularity: a segment whose bending integrand has a singularity (a complex zero of |r'|^2) "
      "inside the Bernstein ellipse of this parameter around it is forbidden; Gauss-Legendre's "
      "error falls like rho^-2n with it (docs/NUMERICS.md, docs/ACCURACY.md). 1 or less = no check."),
  NUM("energy", "parametrisation", LW_PT_DOUBLE, parametrisation, "0", "energy / mm", 0, 1e12, 0,
      "G: parametrisation G * integral of (|r'| - l)^2 dt / l per segment (l = its length) holds "
      "the handle lengths that leave a segment's shape unchanged (docs/NUMERICS.md). 0 = off."),
  NUM("energy", "quadrature", LW_PT_INT, quadrature, "8", "nodes", 2, 64, 0,
      "Gauss-Legendre nodes per segment for every integral but the pair and tone terms' where "
      "they have their own (`pair_quadrature`, `tone_quadrature`)."),
  NUM("energy", "pair_quadrature", LW_PT_INT, pair_quadrature, "0", "nodes", 0, 64, 0,
      "Gauss-Legendre nodes per segment for the pair term (its samples in the cell grid): 0 = the "
      "same as `quadrature`, else 2 to 64. Each of a segment's samples meets those of its neighbours, "
      "so the pair sum's cost per proposal grows up to the square of this number (measured: twice "
      "per doubling from 4 to 16 nodes, 3 times from 16 to 32); docs/ACCURACY.md shows what fewer "
      "nodes cost in accuracy."),
  NUM("energy", "tone_quadrature", LW_PT_INT, tone_quadrature, "0", "nodes", 0, 64, 0,
      "Gauss-Legendre nodes per segment for the tone term (the samples it splats): 0 = the "
      "same as `quadrature`, else 2 to 64. Its cost per proposal grows with this number; with samples 0.7 "
      "tone_blur apart (segment_length / nodes) an annealed photograph's tone energy was within "
      "6e-4 of 32 nodes' (docs/ACCURACY.md). The photo preset sets the fewest that are that "
      "close."),
  NUM("energy", "tone", LW_PT_DOUBLE, tone, "0", "energy / mm^2", 0, 1e12, 0,
      "T: tone T * sum over pixels of A (G * ink - tone_ink * G * darkness)^2: the lines, as ink "
      "of output.pen_width, blurred by a Gaussian G of `tone_blur` and compared pixel by pixel "
      "with the picture's darkness (1 - tone) blurred the same way (A = pixel area; the pixels "
      "are the picture's, or "
      "blocks of them up to tone_blur / 1.5 wide). Unlike the potential it saturates: "
      "lines stop gathering once a place is as dark as the picture. Needs scene.image "
      "(docs/NUMERICS.md). 0 = off."),
  NUM("energy", "tone_blur", LW_PT_DOUBLE, tone_blur, "1", "mm", 1e-6, 1e4, 0,
      "Standard deviation of the tone term's blur: the scale at which ink is averaged into tone. "
      "Keep it above the distance between quadrature samples (segment_length / quadrature) so "
      "a line reads as a line, not a row of dots. Its cost does not grow with the picture's "
      "resolution: the tone raster's pixels are blocks of the picture's up to tone_blur / 1.5 "
      "wide, fine enough for a blurred field (docs/NUMERICS.md)."),
  NUM("energy", "tone_ink", LW_PT_DOUBLE, tone_ink, "1", "", 0, 1, LW_MIN_OPEN,
      "The share of the paper that ink covers where the picture is black: the tone term's "
      "target, and the fidelity scores', is tone_ink * darkness. Below 1 the darks are drawn as "
      "dense lines rather than solid ink, so lines keep their own width apart (1/tone_ink pen "
      "widths at black)."),
  NUM("energy", "min_spacing", LW_PT_DOUBLE, min_spacing, "0", "mm", 0, 1e7, 0,
      "Least distance between the curves of different splines, a hard constraint: a move that "
      "brings more of its pair samples closer than this to another spline than it had, or whose "
      "curves come this close to more segments of other splines than they did, is refused "
      "(+infinity), so a drawing that keeps it never loses it (docs/NUMERICS.md, \"Spacing\"); "
      "the placement starts splines apart by it where it can (with moves.fixed_count = 0 it cuts a "
      "spline that finds no room to its clear segments). The quench and the massless flow "
      "keep it too (they hold a segment that a step could bring closer than this to another curve "
      "than it was; docs/NUMERICS.md, \"Dynamics\"). Needs the pair term (it looks in its cell "
      "grid) and at most pair_cutoff. Typically the pen width. 0 = off."),
  NUM("energy", "chem_spline", LW_PT_DOUBLE, chem_spline, "0", "energy", -1e12, 1e12, 0,
      "Chemical potential per spline: the energy a spline costs just by being there (term "
      "'chemical', with chem_length). With moves.fixed_count = 0 it sets how many lines the "
      "drawing gets; negative values reward lines (docs/NUMERICS.md, 'Trans-dimensional moves'). "
      "0 = none."),
  NUM("energy", "chem_length", LW_PT_DOUBLE, chem_length, "0", "energy / mm", -1e12, 1e12, 0,
      "Chemical potential per unit length: the energy a millimetre of line costs (a line "
      "tension; with moves.fixed_count = 0 it prices growth). 0 = none."),
  NUM("moves", "point", LW_PT_DOUBLE, mix_point, "0.5", "", 0, 1e6, 0,
      "Relative frequency of moves of one point p_k (Gaussian step in x and y)."),
  NUM("moves", "vector", LW_PT_DOUBLE, mix_vector, "0.4", "", 0, 1e6, 0,
      "Relative frequency of moves of one vector v_k."),
  NUM("moves", "translate", LW_PT_DOUBLE, mix_translate, "0.05", "", 0, 1e6, 0,
      "Relative frequency of whole-spline translations."),
  NUM("moves", "rotate", LW_PT_DOUBLE, mix_rotate, "0.05", "", 0, 1e6, 0,
      "Relative frequency of whole-spline rotations about the mean of its points."),
  NUM("moves", "step_point", LW_PT_DOUBLE, step_point, "0.5", "mm", 0, 1e7, LW_MIN_OPEN,
      "Initial step of a point move (tuned while tuning): the standard deviation of a Gaussian "
      "step for splines, the half side of a uniform square step for nurbs."),
  NUM("moves", "step_vector", LW_PT_DOUBLE, step_vector, "0.5", "mm", 0, 1e7, LW_MIN_OPEN,
      "Initial standard deviation of a vector move."),
  NUM("moves", "step_translate", LW_PT_DOUBLE, step_translate, "0.5", "mm", 0, 1e7, LW_MIN_OPEN,
      "Initial standard deviation of a translation."),
  NUM("moves", "step_rotate", LW_PT_DOUBLE, step_rotate, "2", "degrees", 0, 180, LW_MIN_OPEN,
      "Initial standard deviation of a rotation."),
  NUM("moves", "target", LW_PT_DOUBLE, target, "0.44", "", 0, 1, LW_MIN_OPEN | LW_MAX_OPEN,
      "Acceptance rate the point and vector steps tune toward, as a share of the smallest steps' "
      "acceptance: 1 under metropolis, 1/2 under barker (which so tunes to half of it; docs/NUMERICS.md, "
      "\"Acceptance rules\")."),
  NUM("moves", "target_spline", LW_PT_DOUBLE, target_spline, "0.3", "", 0, 1, LW_MIN_OPEN | LW_MAX_OPEN,
      "Acceptance rate the translation and rotation steps tune toward (a share of 1/2 under barker, "
      "as moves.target)."),
  NUM("moves", "tune_sweeps", LW_PT_INT, tune_sweeps, "10", "sweeps", 0, 1e9, 0,
      "Sweeps at the start of each temperature step during which steps adapt; afterwards "
      "they are frozen so sampling obeys detailed balance. 0 = never tune. A small system "
      "needs more (a sweep is as many proposals as it has nodes): a constant-temperature run "
      "says so, naming each move kind proposed 100 times or more whose acceptance ends under a "
      "quarter of its target, or whose rejections end under a quarter of the target's (a step "
      "below half its cap)."),
  NUM("moves", "fixed_count", LW_PT_INT, fixed_count, "1", "", 0, 1, 0,
      "1 keeps the number of splines and of their segments as placed; 0 adds the "
      "trans-dimensional moves birth, death, grow and shrink (reversible jump, "
      "docs/NUMERICS.md), so the chemical potential and the other terms decide how many lines "
      "a drawing needs. Splines system only."),
  NUM("moves", "birth", LW_PT_DOUBLE, mix_birth, "0.01", "", 0, 1e6, 0,
      "Relative frequency of births: a new spline of init.segments segments (another count "
      "with birth_spread) placed along the field, starting where the picture is dark "
      "(fixed_count = 0)."),
  NUM("moves", "birth_uniform", LW_PT_DOUBLE, birth_uniform, "0.1", "", 1e-3, 1, 0,
      "With a picture, the share of born splines whose first point is uniform on the page; the "
      "others start where placement starts a spline, by darkness. It keeps every point "
      "possible for a first node (fixed_count = 0; docs/NUMERICS.md)."),
  NUM("moves", "birth_spread", LW_PT_DOUBLE, birth_spread, "0", "", 0, 1, LW_MAX_OPEN,
      "The share of births whose segment count is drawn uniformly from 1 .. max_segments "
      "other than init.segments. With 0 a death removes only splines of init.segments "
      "segments (what a birth makes); above 0 it removes a spline of any count, so a short "
      "piece can leave without growing first (fixed_count = 0; docs/NUMERICS.md)."),
  NUM("moves", "prior_sd", LW_PT_DOUBLE, prior_sd, "0.25", "", 0, 1, LW_MIN_OPEN,
      "The spread of the prior that births and grows draw from and every move of a spline "
      "pays (fixed_count = 0): the standard deviation of a next node's point about 3 v beyond "
      "the last, in init.segment_length, its vector's a third of it. At 0.25, 97 to 99.7 % of the "
      "5-segment births of the photo preset break the regularity check (energy.min_speed, "
      "energy.regularity); 0.1 lowers that to 32 to 44 %, and trades tone for alignment "
      "(docs/NUMERICS.md, \"The prior's spread\")."),
  NUM("moves", "death", LW_PT_DOUBLE, mix_death, "0.01", "", 0, 1e6, 0,
      "Relative frequency of deaths: a spline chosen uniformly is removed (fixed_count = 0)."),
  NUM("moves", "grow", LW_PT_DOUBLE, mix_grow, "0.02", "", 0, 1e6, 0,
      "Relative frequency of grow moves: a segment added at either end of a spline, along the "
      "field (fixed_count = 0)."),
  NUM("moves", "shrink", LW_PT_DOUBLE, mix_shrink, "0.02", "", 0, 1e6, 0,
      "Relative frequency of shrink moves: the segment at either end of a spline removed "
      "(fixed_count = 0)."),
  NUM("moves", "max_segments", LW_PT_INT, max_segments, "16", "", 1, 1e5, 0,
      "Grow never makes a spline longer than this many segments (fixed_count = 0); shrink never "
      "below one. At least init.segments (the count placed and born splines start with); unset, "
      "it is 16 or init.segments where that is larger, and so is the 16 a run's scene.ini writes "
      "where it was unset."),
  NUM("moves", "split", LW_PT_DOUBLE, mix_split, "0", "", 0, 1e6, 0,
      "Relative frequency of splits: an inner segment of a spline of 3 or more segments removed, "
      "leaving two splines with the nodes as they were (fixed_count = 0; 0 = none)."),
  NUM("moves", "join", LW_PT_DOUBLE, mix_join, "0", "", 0, 1e6, 0,
      "Relative frequency of joins: an end of a spline and an end of another within join_radius "
      "linked by a new segment, one of the two reversed where their directions disagree; the "
      "partner is drawn by how well the new segment continues the first (fixed_count = 0; "
      "0 = none)."),
  NUM("moves", "join_radius", LW_PT_DOUBLE, join_radius, "2", "segment lengths", 0, 1e3, LW_MIN_OPEN,
      "Ends at most this far apart may join, in units of init.segment_length (a joined "
      "segment is about one long); a split cuts only segments whose end points are this close."),
  STRING("anneal", "schedule", schedule, "geometric", "",
         "Temperature schedule: constant, linear, geometric, logarithmic, adaptive or table "
         "(formulas in docs/SCHEDULES.md)."),
  NUM("anneal", "t_start", LW_PT_DOUBLE, t_start, "1", "energy", 0, 1e300, 0,
      "Temperature of the first step (above 0 for the geometric, logarithmic and adaptive "
      "schedules, which take ratios or logarithms). Under tempering, what the ladder is "
      "scaled by: rung k runs at t_k T / t_start, with the table schedule too, whose rows "
      "set T."),
  NUM("anneal", "t_end", LW_PT_DOUBLE, t_end, "0.01", "energy", 0, 1e300, 0,
      "Temperature of the last step (the floor of the adaptive schedule; above 0 where "
      "`t_start` must be)."),
  NUM("anneal", "sweeps", LW_PT_INT, sweeps, "1000", "sweeps", 0, 2e9, 0,
      "Sweeps in all; a sweep is as many proposals as the scene has nodes."),
  NUM("anneal", "steps", LW_PT_INT, steps, "20", "", 1, 1e9, 0,
      "Temperature steps; the sweeps are shared out evenly among them, and the moves' steps tune "
      "at the start of each (moves.tune_sweeps). With schedule = constant the default is 1: one "
      "temperature, tuned once, then frozen for the sampling."),
  NUM("anneal", "lambda", LW_PT_DOUBLE, lambda, "0.7", "", 0, 1e6, LW_MIN_OPEN,
      "Cooling rate of the adaptive schedule: T <- T exp(-lambda T / sigma_E)."),
  STRING("anneal", "table", table, "", "path",
         "Table schedule file: lines 'step temperature' (relative to the scene file)."),
  NUM("anneal", "seed", LW_PT_WHOLE, seed, "1", "", 0, LW_SEED_MAX, 0,
      "Seed of the random number generator; the same scene and seed give the same run."),
  NUM("anneal", "seed_version", LW_PT_INT, seed_version, "2", "", 1, 2, 0,
      "How the seed makes the seeds of the run's random streams. 2: distinct seeds never "
      "share a stream's numbers (docs/NUMERICS.md, \"Random numbers\"). 1: the way of runs "
      "begun before 2026-12-06, under which two seeds could draw the same numbers (89483 "
      "and 106945 drew the same chain, and without tempering ran the same run); a scene.ini "
      "that such a run wrote, lacking this key, takes 1, so that running it again draws that "
      "run's random numbers (and says so)."),
  NUM("anneal", "check_every", LW_PT_INT, check_every, "100", "sweeps", 1, 2e9, 0,
      "Sweeps between full recomputations of the energy (the drift check); splines are "
      "renumbered along a Hilbert curve of the page just before each, for locality in memory. "
      "The energy is also recomputed after any sweep that leaves it under 1/8 of its size since "
      "the last time, which replaces running totals that drifted by more than 1e-9 (a start far "
      "above the minimum: docs/NUMERICS.md)."),
  NUM("anneal", "delayed_acceptance", LW_PT_INT, delayed_acceptance, "1", "", 0, 1, 0,
      "1: a proposal is first tested on a cheap stand-in for the pair term's near field, and the "
      "near field is computed only for proposals that pass (delayed acceptance; the chain samples "
      "the same distribution, docs/NUMERICS.md); 0: plain Metropolis on the whole dE, for studies "
      "of acceptance rates. Nothing changes without a near field (energy.pair_near = 0)."),
  STRING("anneal", "domains", domains, "off", "",
         "Domain decomposition of each replica's sweeps (docs/NUMERICS.md, \"Domains\"): `off`; `N` "
         "(1 to 64), an N x N lattice of domains over the page, shifted at random each sweep, whose four "
         "sub-lattices are swept in turn, the domains of each in parallel (OpenMP); a spline moves in a "
         "sweep only where it falls inside one domain, and a count that would move fewer than a quarter "
         "of them a sweep is refused, as is one whose domains are not wider than twice the reach of a "
         "move; `auto`, domains "
         "of side max(2.5 reach, 16 init.segments init.segment_length) (particles: 2.5 reach, the page "
         "their grid's box in x and y), at most 64 a side, not split "
         "when fewer than 2 fit a side. The result depends on this key, never on the threads. docs/SCALING.md."),
  CHOICE("anneal", "quench", quench, "none", "none|bfgs",
         "After the last sweep: none, or bfgs, which takes the coldest replica to the nearest local "
         "minimum of its energy (limited-memory BFGS on the system's gradient, holding the parts a "
         "step would take through a wall; docs/ACCURACY.md; a D-NURBS curve's control points are "
         "solved for exactly first, and again between L-BFGS runs where its weights are free). "
         "The drawings and summary.json show the quenched state; state.lw keeps the annealed one, so "
         "a resumed or longer run continues the chain. Needs a system with a gradient (splines, nurbs, particles)."),
  NUM("anneal", "quench_tol", LW_PT_DOUBLE, quench_tol, "1e-6", "energy/mm", 0, 1e300, LW_MIN_OPEN,
      "The quench stops when the gradient's Euclidean norm falls to this."),
  NUM("anneal", "quench_iterations", LW_PT_INT, quench_iterations, "2000", "", 1, 1e9, 0,
      "The quench stops after this many minimiser iterations (or earlier when no step descends: "
      "the minimum to rounding)."),
  NUM("anneal", "quench_stall", LW_PT_DOUBLE, quench_stall, "0.05", "", 0, 1, 0,
      "The quench stops when its last 50 iterations removed less than this share of the energy it "
      "has removed so far while the gradient norm fell by less than a tenth over them (0: never; "
      "the particles' default under weight = poly with no hard wall, whose smooth energy the quench "
      "takes to quench_tol "
      "(a sphere of 100 in 0.1 s, a sheet of 1000 in 4 s), where this rule stopped the sphere 88 above "
      "its minimum). "
      "A picture's terms are bilinear in its pixels, so the gradient norm stops falling short of "
      "quench_tol and only this or quench_iterations ends the quench; on a smooth energy the norm "
      "keeps falling, and the quench goes on to quench_tol, unless the energy is badly conditioned "
      "as well (NURBS free weights from an annealed state stalled 1.5e-2 above the minimum, which "
      "0 reached in 1,900 iterations)."),
  NUM("tempering", "replicas", LW_PT_INT, replicas, "1", "", 1, 256, 0,
      "Replicas on the temperature ladder (parallel tempering, run by OpenMP threads). 1 = off. "
      "The coldest replica gives final.svg and state.lw."),
  NUM("tempering", "t_min", LW_PT_DOUBLE, t_min, "0.01", "energy", 0, 1e300, LW_MIN_OPEN,
      "Coldest temperature of the geometric ladder t_k = t_min (t_max/t_min)^(k/(R-1)). The whole "
      "ladder follows the schedule: at step b every rung is t_k * T(b) / anneal.t_start, so a "
      "constant schedule samples at the ladder itself."),
  NUM("tempering", "t_max", LW_PT_DOUBLE, t_max, "1", "energy", 0, 1e300, LW_MIN_OPEN,
      "Hottest temperature of the geometric ladder."),
  LIST("tempering", "ladder", ladder, "", "energy",
       "Explicit ladder `t0 t1 ...` (increasing, each above 0 and at most 1e300; overrides t_min and "
       "t_max; its length sets the replicas, and `replicas` may stay 1, as a run's scene.ini then keeps "
       "it; a long ladder goes on over indented lines). A run with ladder tuning writes its tuned ladder "
       "to ladder.ini for reuse."),
  STRING("tempering", "ladder_file", ladder_file, "", "path",
         "A file of the ladder instead of `ladder`, relative to the scene file: a `[tempering]` section "
         "with `ladder = ...` and nothing else, as a run's ladder.ini is. Read when a run starts; the "
         "run's scene.ini holds the ladder in the file's place, so a resume needs no file."),
  NUM("tempering", "exchange_every", LW_PT_INT, exchange_every, "1", "sweeps", 1, 2e9, 0,
      "Sweeps between exchange steps; steps alternate between even (0-1, 2-3, ...) and odd pairs."),
  CHOICE("tempering", "tune_ladder", tune_ladder, "fixed", "fixed|equal",
         "fixed keeps the ladder; equal moves the inner rungs toward equal swap acceptance during "
         "the first `ladder_sweeps` sweeps (then the ladder is frozen and swap statistics restart)."),
  NUM("tempering", "ladder_sweeps", LW_PT_INT, ladder_sweeps, "200", "sweeps", 0, 2e9, 0,
      "Warm-up sweeps of ladder tuning (tune_ladder = equal); fewer than anneal.sweeps, since the "
      "swap statistics and ladder.ini come after it. The ladder moves once every 40 exchange steps, so "
      "fewer than 40 x exchange_every sweeps leave it as given (noted)."),
  NUM("output", "checkpoint_every", LW_PT_INT, checkpoint_every, "100", "sweeps", 1, 2e9, 0,
      "Sweeps between checkpoints of state.lw (also written at the end and on SIGINT, SIGTERM, SIGHUP and "
      "SIGXCPU). Each is "
      "written whole and synced to disk: for a small system (sweeps of microseconds) that is most of the "
      "time, and the run says so at its end; thousands of sweeps between them suit a study."),
  NUM("output", "trace_every", LW_PT_INT, trace_every, "1", "sweeps", 1, 2e9, 0,
      "Sweeps per row of trace.csv."),
  NUM("output", "trace_exact", LW_PT_INT, trace_exact, "1", "", 0, 1, 0,
      "1 = trace.csv's numbers with every digit that reads back (%.15g, else %.17g); 0 = at 10 "
      "significant digits, as runs before 2026-12-07 (a run of theirs, whose scene.ini has no line "
      "for this key, resumes so; a new run of its scene.ini writes every digit). 10 digits round "
      "away a large energy's fluctuations at a low temperature, and its heat capacity with them; "
      "`linewise stats` says where."),
  NUM("output", "observables", LW_PT_INT, observables, "0", "", 0, 1, 0,
      "1 adds the system's observables to every row of trace.csv (columns obs_<name>: for splines "
      "the count and the means over the splines of length, squared end-to-end distance, squared "
      "radius of gyration and the cosine between the end tangents, for a D-NURBS curve the same of "
      "the curve; for particles the count, squared "
      "radius of gyration, rms distance from the best plane and the order of the normals; "
      "docs/FORMATS.md). `linewise stats DIR` gives their means with error bars."),
  NUM("output", "samples_every", LW_PT_INT, samples_every, "0", "sweeps", 0, 2e9, 0,
      "Sweeps between samples of the coldest replica's configuration, samples/sample-SSSSSS.csv: every "
      "degree of freedom with 17 digits (splines: spline,node,px,py,vx,vy; D-NURBS: point,x,y,w; "
      "particles: particle,x,y,z,qw,qx,qy,qz,pinned; docs/FORMATS.md), for studies of distributions "
      "and correlations. 0 = none."),
  NUM("output", "stats_from", LW_PT_INT, stats_from, "0", "sweeps", 0, 2e9, 0,
      "First sweep of the stretch of trace.csv whose statistics `linewise stats DIR` takes by default and "
      "summary.json reports for the observables (their means, standard errors and autocorrelation times): "
      "the end of a study's burn-in. 0 = the sweeps at the final temperature. Either way the sweeps whose "
      "steps were still tuning are left out."),
  NUM("output", "pen_width", LW_PT_DOUBLE, pen_width, "0.3", "mm", 0.001, 100, 0,
      "Stroke width of every pen in final.svg, the previews and the fidelity render: the pen's line width "
      "(from 0.001 mm: final.svg writes it to 4 decimals)."),
  NUM("output", "pens", LW_PT_INT, pens, "1", "", 1, 16, 0,
      "Pens, each an Inkscape layer of final.svg. With a target tone (else a potential) the "
      "splines are ranked by their mean tone (potential) and cut into equal runs, darkest "
      "(lowest) to pen 1; otherwise spline i goes to pen (i mod pens) + 1."),
  STRING("output", "pen_colors", pen_colors, "", "",
         "Colours of the pens as `#rrggbb` or `#rgb`, one per pen, separated by spaces; empty = all black."),
  CHOICE("output", "order", order, "2opt", "none|greedy|2opt",
         "Order of the paths of each pen in final.svg: index order, each path in its own direction (the "
         "plotter's joins link a path's end to another's start alone), greedy nearest neighbour from "
         "home (the page's top-left corner; its lower-left with gcode or hpgl and plot.turn = 0, the "
         "machine's origin), or greedy improved by 2-opt and Or-opt moves; paths may be reversed. Reduces pen-up "
         "travel (reported in summary.json)."),
  NUM("output", "png_scale", LW_PT_DOUBLE, png_scale, "4", "px/mm", 0, 100, LW_MIN_OPEN,
      "Pixels per millimetre of final.png and the frames (the long side is capped at 4096 px, and is "
      "at least 1 px)."),
  NUM("output", "pdf", LW_PT_INT, pdf, "0", "", 0, 1, 0,
      "1 = also write final.pdf, a vector PDF of the page (at most 5080 mm a side, as PDF allows)."),
  NUM("output", "hpgl", LW_PT_INT, hpgl, "0", "", 0, 1, 0,
      "1 = also write final.hpgl, the drawing in HP-GL for pen plotters that read no SVG (HP, Roland; a "
      "pen a carousel slot): the curves as chords within plot.tolerance, in plotter units of 0.025 mm "
      "from the page's lower-left corner (docs/FORMATS.md)."),
  NUM("output", "gcode", LW_PT_INT, gcode, "0", "", 0, 1, 0,
      "1 = also write final.gcode, the drawing in G-code for GRBL and other CNC-style plotters: the "
      "curves as chords within plot.tolerance, mm from the page's lower-left corner, the pen moved by "
      "plot.gcode_pen_up and plot.gcode_pen_down, a pause (M0) to change pens (docs/FORMATS.md)."),
  NUM("output", "preview_image", LW_PT_INT, preview_image, "0", "", 0, 1, 0,
      "1 = paint the source image's tone under the lines of final.png, final.pdf and the frames "
      "(at half strength). Needs an image."),
  NUM("output", "frames_every", LW_PT_INT, frames_every, "0", "sweeps", 0, 2e9, 0,
      "Sweeps between animation frames frames/frame-SSSSSS.png (SSSSSS = the sweep; the first, 000000, "
      "is the start, and the run's end has one, on the grid or not). A run whose frames still to come would take "
      "more than the disk has free (a warning) or over 1 GB, at the newest frame's size, says so as it starts; one "
      "whose frames or samples took over a third of its time, at its end. 0 = none."),
  NUM("output", "fidelity_sigma", LW_PT_DOUBLE, fidelity_sigma, "1", "mm", 1e-6, 1e4, 0,
      "Gaussian blur applied to both the rendered lines and the target (the ink asked for, "
      "energy.tone_ink * darkness) before the fidelity score (MSE, SSIM) compares them; about "
      "half the widest line spacing that should read as a flat tone (docs/FORMATS.md)."),
  STRING("output", "fidelity_reference", fidelity_reference, "", "path",
         "A picture to score the drawing against instead of the target (the picture after the "
         "scene's pipeline), relative to the scene file: taken as it loads (gray, composited over "
         "white; no blur, flattening, levels or tone curve) and fitted into the page inset by "
         "scene.margin like scene.image. Scores that stay comparable while the pipeline's keys "
         "change, or against a clean original of a photograph (docs/FORMATS.md). Empty = the target."),
  NUM("output", "field_preview", LW_PT_INT, field_preview, "0", "", 0, 1, 0,
      "1 = write field.png at the start of a run: the tone (white without an image) under "
      "short strokes along the field (needs the field term)."),
  NUM("plot", "join_distance", LW_PT_DOUBLE, join_distance, "1", "pen widths", 0, 1000, 0,
      "Strokes of one pen whose ends lie at most this far apart (in widths of the pen, with "
      "layers each its own `layers.pen_width`: a gap the ink closes anyway) and align within "
      "`join_angle` become one path, bridged by a short "
      "curve along both tangents: one pen lift fewer. 0 = no joining."),
  NUM("plot", "join_angle", LW_PT_DOUBLE, join_angle, "30", "degrees", 0, 180, 0,
      "Largest turn at a join: between the direction out of the one stroke's end and into the "
      "other's. 30 degrees reads as one bending line; 180 joins any two ends that are close. "
      "Below 180 the gap must also lead on from both ends (it may run back by at most a tenth "
      "of `join_distance`): strokes side by side, one starting behind where the other ends, "
      "are not bridged by a hook back over the ink."),
  NUM("plot", "crop", LW_PT_INT, crop, "1", "", 0, 1, 0,
      "1 = cut every path at the edge of the picture's rectangle (without a picture: the page "
      "inset by scene.margin) and keep the pieces inside, split exactly at the crossing; 0 = "
      "draw strokes as they lie, margins included (the run counts those that reach past the page's edge)."),
  NUM("plot", "min_length", LW_PT_DOUBLE, min_length, "3", "pen widths", 0, 1e6, 0,
      "Paths shorter than this (in widths of their pen, as for `join_distance`), after joining "
      "and cropping, are left "
      "out: below about three widths a stroke prints as a dot and costs a whole pen lift. 0 = "
      "keep all but those under 0.0001 mm, a point at the files' precision."),
  NUM("plot", "speed_down", LW_PT_DOUBLE, speed_down, "50", "mm/s", 0, 1e5, LW_MIN_OPEN,
      "Pen-down speed for the plot time estimate, and the speed final.hpgl (VS, in cm/s) and "
      "final.gcode (F, in mm/min) draw at. The default is an AxiDraw's at its default "
      "settings (speed_pendown 25 % of the 8.6979 in/s high-resolution limit, scaled by 1/110)."),
  NUM("plot", "speed_up", LW_PT_DOUBLE, speed_up, "150", "mm/s", 0, 1e5, LW_MIN_OPEN,
      "Pen-up (travel) speed for the plot time estimate; AxiDraw default speed_penup 75 %."),
  NUM("plot", "lift_time", LW_PT_DOUBLE, lift_time, "0.2", "s", 0, 1e3, 0,
      "Time of one pen lift and lowering for the plot time estimate; an AxiDraw's servo at its "
      "default rates (raise 75 %, lower 50 %, over 30 % of a 200 ms sweep) takes about 0.2 s."),
  NUM("plot", "tolerance", LW_PT_DOUBLE, plot_tolerance, "0.02", "mm", 1e-3, 10, 0,
      "Largest distance between a curve and the chords that stand for it in final.hpgl and "
      "final.gcode (straight moves only); HP-GL's 0.025 mm grid adds up to 0.018 mm. 0.02 mm is "
      "far below a pen's width; larger values make shorter files."),
  CHOICE("plot", "turn", plot_turn, "0", "0|90",
         "Quarter turn of the page in final.hpgl and final.gcode: 0 puts its lower-left corner at the "
         "machine's origin; 90 turns it counterclockwise, its top-left corner at the origin and its top "
         "edge along the machine's y axis, so a portrait page plots on paper loaded landscape (an HP "
         "7475A takes A4 and A3 so)."),
  NUM("plot", "bed_width", LW_PT_DOUBLE, plot_bed_w, "0", "mm", 0, 1e7, 0,
      "How far the plotter reaches along its x axis from its origin (after plot.turn): with "
      "output.hpgl or output.gcode a scene whose drawing area (the page inset by scene.margin; "
      "with a picture and plot.crop = 1, the picture's rectangle) "
      "reaches further is refused before the run, and the files are checked against it too "
      "(an HP 7475A clips at its hard-clip limits, a GRBL machine stops at its soft limits). "
      "0 = not checked."),
  NUM("plot", "bed_height", LW_PT_DOUBLE, plot_bed_h, "0", "mm", 0, 1e7, 0,
      "How far the plotter reaches along its y axis; as plot.bed_width. 0 = not checked."),
  CHOICE("plot", "gcode_travel", gcode_travel, "rapid", "rapid|feed",
         "The pen-up moves of final.gcode: `rapid` (G0, the machine's fastest) or `feed` (G1 at "
         "plot.speed_up), for machines whose rapids shake a lifted pen or outrun its servo."),
  STRING("plot", "gcode_pen_up", gcode_pen_up, "G0 Z5", "",
         "The G-code line that lifts the pen in final.gcode, written as it is: `G0 Z5` for a pen on the "
         "Z axis, `M5` or `M3 S30` for a servo on a GRBL fork. One line of printable ASCII, at most 79 "
         "characters (GRBL's line buffer), with no X or Y word (a move across the page, which the bed check "
         "would not see), G28, G30, G91 or G92, a program stop or end (M0, M1, M2, M30, M60), nor GRBL "
         "system command ($) outside a comment: refused. The file "
         "sets the feed of plot.speed_down before it (`G94 F...`), "
         "so a G1 here without an F of its own moves at that."),
  STRING("plot", "gcode_pen_down", gcode_pen_down, "G1 Z0 F500", "",
         "The G-code line that lowers the pen in final.gcode, written as it is (a feed it sets is "
         "replaced by plot.speed_down on the first drawing move); e.g. `M3 S90 G4 P0.2` for a servo "
         "that needs 0.2 s to settle. One line as plot.gcode_pen_up's."),
  STRING("layers", "names", ly_names, "", "",
         "Hatching layers or colour pens: one name a layer (ASCII letters, digits, `-`, `_`, `.`; it labels "
         "the pen's SVG layer, so no two alike), separated by blanks or commas (at most 16). Each "
         "layer is a pen of its own (one SVG group) with its own target, field, width and colour; "
         "each spline belongs to one, by its index, the layers getting splines in proportion to "
         "the ink of their targets. Under source = cmyk or palette a layer draws the ink of its colour: "
         "one named cyan, magenta, yellow or black (any case) must not have a colour plainly another ink's "
         "(refused). Needs output.pens = 1 (the layers are the pens). Empty = no "
         "layers: one target, one field, the pens of [output]. docs/IMAGES.md, \"Hatching layers "
         "and colour\"."),
  CHOICE("layers", "source", ly_source, "tone", "tone|cmyk|palette",
         "Each layer's target: `tone` = the picture's darkness through the layer's `tone_min` .. "
         "`tone_max`; `cmyk` = the cyan, magenta, yellow and black separation of the colour picture "
         "(4 layers, in that order; without layers.names they are named cyan, magenta, yellow and "
         "black); `palette` = the least-squares separation of the colour picture "
         "into the pens of `colors`, one a layer of `names` (docs/NUMERICS.md, \"Colour separation\")."),
  CHOICE("layers", "apart", ly_apart, "all", "all|pen",
         "Which lines the pair repulsion and energy.min_spacing keep apart: `all` = every line from "
         "every other; `pen` = each line from its own layer's only, so pens overlap and cross as "
         "inks do on paper and each layer may be as dense as one pen alone (what colour needs; "
         "the photo preset sets it). Without layers, every line is of one pen."),
  STRING("layers", "colors", ly_colors, "", "",
         "Pen colour of each layer, `#rrggbb` or `#rgb`; empty = black (tone) or cyan, magenta, "
         "yellow, black (cmyk). `palette` needs them: they are the pens the picture is separated into, "
         "and so are they under `cmyk` when given (real inks' colours separate into those inks; a "
         "redraw that recolours a run scores each pen against the new separation)."),
  STRING("layers", "turn", ly_turn, "", "degrees",
         "Each layer's field is the scene's field (scene.field) turned by this angle, e.g. `0 90` "
         "for cross-hatching along and across the flow. Empty = 0 for every layer."),
  STRING("layers", "tone_min", ly_tone_min, "", "",
         "source = tone: tone (0 black .. 1 white) at and below which a layer's target is full "
         "ink; one a layer, empty = 0 each."),
  STRING("layers", "tone_max", ly_tone_max, "", "",
         "source = tone: tone at and above which a layer's target is no ink (above tone_min); "
         "one a layer, empty = 1 each. The target falls linearly in between."),
  STRING("layers", "pen_width", ly_pen_width, "", "mm",
         "Pen width of each layer (its SVG stroke and its tone footprint); empty = output.pen_width each. "
         "The spacing (energy.min_spacing) and the close share stay of output.pen_width: a wider layer's "
         "strokes may run into each other's ink."),
  NUM("layers", "share_width", LW_PT_INT, ly_share_width, "1", "", 0, 1, 0,
      "1 = a layer's share of the splines is its ink over its pen width (a fine pen's layer gets more lines); "
      "0 = its ink alone, as runs before this key (a 0.2 mm pen drew 0.34 of a full tone beside a 0.8 mm "
      "pen's 0.52; a run of theirs, whose scene.ini has no line for this key, resumes so)."),
  NUM("particles", "count", LW_PT_INT, pt_count, "100", "", 0, 1e7, 0,
      "Particles placed by `pattern` (after those of `points`, if any)."),
  CHOICE("particles", "pattern", pt_pattern, "plane", "cloud|plane|sphere",
         "Initial placement: cloud = uniform in a cube (the part inside `boundary`) with random "
         "orientations; plane = a hexagonal patch in z = 0 with normals +z; sphere = a Fibonacci "
         "sphere around the origin with outward normals. Then `noise` and `normal_noise`; drawn "
         "from anneal.seed. A plane or sphere whose sites reach the boundary is refused, naming "
         "`size` or `boundary_z`."),
  NUM("particles", "size", LW_PT_DOUBLE, pt_size, "0", "length", 0, 1e9, 0,
      "Extent of the pattern: the cube's side, the patch's or the sphere's diameter. 0 = "
      "automatic: the extent `count` particles fill at the spacing r0 (docs/NUMERICS.md). Below half "
      "that (closer than r0/2 on average) a new run is refused; a run begun before 2026-12-05 resumes."),
  NUM("particles", "noise", LW_PT_DOUBLE, pt_noise, "0.05", "length", 0, 1e9, 0,
      "Standard deviation of the Gaussian noise added to each coordinate of a placed particle (not "
      "where it would push the particle past `boundary`: that one keeps its place)."),
  NUM("particles", "normal_noise", LW_PT_DOUBLE, pt_normal_noise, "5", "degrees", 0, 180, 0,
      "Standard deviation of the tilt of each placed orientation (a rotation about a uniform "
      "random axis)."),
  STRING("particles", "points", pt_points, "", "path",
         "Point file relative to the scene file: one particle per line as `x y z` or "
         "`x y z nx ny nz`, blanks or commas between (the normal need not be unit); `#` starts "
         "a comment, and so does `//` at a line's start. Or a PLY file "
         "(ASCII or binary; its vertices' x y z and nx ny nz, as a scanner or a run's final.ply "
         "writes them). These particles come first; without a normal a particle starts with "
         "normal +z. Empty = none."),
  NUM("particles", "pinned", LW_PT_INT, pt_pinned, "0", "", 0, 1, 0,
      "1 = the particles of `points` never move: their positions, and the orientations of "
      "those given with a normal (the others still turn). Moves pick free particles only."),
  NUM("particles", "r0", LW_PT_DOUBLE, pt_r0, "1", "length", 1e-6, 1e9, 0,
      "r0: the spacing where the Lennard-Jones potential is lowest."),
  NUM("particles", "range", LW_PT_DOUBLE, pt_range, "1.6", "r0", 1, 100, LW_MIN_OPEN,
      "Interaction range R in units of r0: pairs farther apart do not interact; the weighting "
      "function falls to 0 there and the Lennard-Jones potential is shifted to 0 there. 1.6 "
      "keeps the first shell of a hexagonal sheet and drops the second (sqrt 3)."),
  CHOICE("particles", "weight", pt_weight, "poly", "poly|gauss|aniso",
         "Distance weighting w of the co-planarity, co-normality and co-circularity terms: "
         "poly (1 - r^2/R^2)^3; gauss exp(-r^2 / 2 sigma^2); aniso the seed's "
         "exp(-(x^2+y^2)/2a^2 - z^2/2b^2) in each particle's frame, a = sigma, b = "
         "sigma_normal, averaged over the two ends; the Gaussians shifted by g_R to reach 0 at R "
         "and scaled by 1 / (1 - g_R) to stay 1 at 0 (docs/NUMERICS.md): continuous at R with a kink "
         "there (poly meets 0 with slope 0), so a quench may park pairs at R under them."),
  NUM("particles", "sigma", LW_PT_DOUBLE, pt_sigma, "1", "r0", 0, 100, LW_MIN_OPEN,
      "sigma_r of weight = gauss, and the in-plane a of weight = aniso."),
  NUM("particles", "sigma_normal", LW_PT_DOUBLE, pt_sigma_normal, "0.5", "r0", 0, 100, LW_MIN_OPEN,
      "The normal b of weight = aniso; at most `sigma`."),
  NUM("particles", "alpha_lj", LW_PT_DOUBLE, pt_alpha_lj, "1", "energy", 0, 1e12, 0,
      "alpha_LJ: depth of the Lennard-Jones potential (r0/r)^12 - 2 (r0/r)^6 (shifted to 0 at "
      "the range). 0 = off."),
  NUM("particles", "alpha_p", LW_PT_DOUBLE, pt_alpha_p, "1", "energy / length^2", 0, 1e12, 0,
      "alpha_P: co-planarity ((n_i.r_ij)^2 + (n_j.r_ij)^2) w per pair. 0 = off."),
  NUM("particles", "alpha_n", LW_PT_DOUBLE, pt_alpha_n, "1", "energy", 0, 1e12, 0,
      "alpha_N: co-normality |n_i - n_j|^2 w per pair. 0 = off."),
  NUM("particles", "alpha_c", LW_PT_DOUBLE, pt_alpha_c, "0", "energy / length^2", 0, 1e12, 0,
      "alpha_C: co-circularity ((n_i + n_j).r_ij)^2 w per pair, 0 on spheres and planes. 0 = off."),
  NUM("particles", "gravity", LW_PT_DOUBLE, pt_gravity, "0", "energy / length", -1e12, 1e12, 0,
      "Gravity: gravity * z per particle (pulls toward -z when positive). 0 = off."),
  CHOICE("particles", "boundary", pt_boundary, "none", "none|plane|sphere",
         "A wall: plane keeps particles above z = boundary_z (a floor), sphere inside the "
         "sphere of boundary_radius around the origin; beyond it a move is forbidden."),
  NUM("particles", "boundary_z", LW_PT_DOUBLE, pt_boundary_z, "0", "length", -1e9, 1e9, 0,
      "Height of the plane boundary."),
  NUM("particles", "boundary_radius", LW_PT_DOUBLE, pt_boundary_radius, "10", "length", 0, 1e9,
      LW_MIN_OPEN, "Radius of the sphere boundary."),
  NUM("particles", "alpha_b", LW_PT_DOUBLE, pt_alpha_b, "0", "energy length^2", 0, 1e12, 0,
      "alpha_B: soft wall alpha_B / d^2 per particle, d its distance to the boundary. 0 = a "
      "hard wall only."),
  NUM("particles", "view_azimuth", LW_PT_DOUBLE, pt_view_azimuth, "30", "degrees", -360, 360, 0,
      "Direction the preview final.png looks from: azimuth about +z from +x."),
  NUM("particles", "view_elevation", LW_PT_DOUBLE, pt_view_elevation, "30", "degrees", -90, 90, 0,
      "Elevation of the view direction above the xy plane (90 = from +z, looking down)."),
  NUM("particles", "png_size", LW_PT_INT, pt_png_size, "800", "pixels", 16, 4096, 0,
      "Width and height of final.png."),
  NUM("particles", "disc", LW_PT_DOUBLE, pt_disc, "0.5", "r0", 0, 100, LW_MIN_OPEN,
      "Radius of each particle's disc in final.png."),
  NUM("particles", "birth", LW_PT_DOUBLE, pt_birth, "0", "", 0, 1e6, 0,
      "Mix weight of births: a new free particle in the tangent plane of a random particle, "
      "0.75 to 1.25 r0 from it, its normal near that one's (the seed's growth of a surface; "
      "docs/NUMERICS.md, \"Births and deaths\"). 0 with death = 0: the count is fixed."),
  NUM("particles", "death", LW_PT_DOUBLE, pt_death, "0", "", 0, 1e6, 0,
      "Mix weight of deaths: a random free particle (pin flags 0) removed, the reverse of a birth."),
  NUM("particles", "chem", LW_PT_DOUBLE, pt_chem, "0", "energy", -1e12, 1e12, 0,
      "Energy of each particle, the term chem N (minus the chemical potential, against a "
      "density of one particle per r0^3): higher makes fewer. 0 = off."),
  NUM("particles", "max_count", LW_PT_INT, pt_max_count, "100000", "", 1, 1e7, 0,
      "Births stop at this many particles (a start above it is said before the run: no birth until deaths "
      "bring the count under it). With births or deaths the cell grid is sized for this many "
      "whatever the count (so that a resumed run adds in the same order): a start far above it runs slower."),
  NUM("dynamics", "rho", LW_PT_DOUBLE, dyn_rho, "1", "mass/mm", 0, 1e12, 0,
      "Line density rho of the kinetic energy (rho/2) int |dr/dt|^2 dl; for particles the mass of "
      "each, with the inertia of a ball of diameter r0. 0 = massless: the "
      "motion is the gradient flow D(x) dx/dt = -grad E of the damping (needs gamma > 0)."),
  NUM("dynamics", "gamma", LW_PT_DOUBLE, dyn_gamma, "0", "force s/mm^2", 0, 1e12, 0,
      "Rayleigh damping: a force -gamma dr/dt per mm of line (particles: per particle, and "
      "its rotation at the same rate). 0 = none (energy is conserved)."),
  NUM("dynamics", "dashpot", LW_PT_DOUBLE, dyn_dashpot, "0", "force s / length", 0, 1e12, 0,
      "Particles: a dashpot between neighbours, the force -dashpot w (v_i - v_j) on i, w the pair "
      "weight (the seed's beta_1): damps the particles' motion against each other, not a common "
      "translation. 0 = none. Needs rho > 0. docs/NUMERICS.md, \"Dampers between neighbours\"."),
  NUM("dynamics", "dashpot_angular", LW_PT_DOUBLE, dyn_dashpot_angular, "0", "energy s", 0, 1e12, 0,
      "Particles: the torque -dashpot_angular w (omega_i - omega_j) on i between neighbours (the "
      "seed's beta_3): damps their turning against each other. 0 = none. Needs rho > 0."),
  NUM("dynamics", "dt", LW_PT_DOUBLE, dyn_dt, "0.001", "s", 0, 1e6, LW_MIN_OPEN,
      "Time step of the integrator (massless: the first step tried; halved where the energy "
      "would not fall)."),
  NUM("dynamics", "steps_per_sweep", LW_PT_INT, dyn_steps_per_sweep, "1", "", 1, 1e9, 0,
      "Time steps per sweep of the run loop (trace, frames and checkpoints count sweeps)."),
  NUM("dynamics", "gravity_x", LW_PT_DOUBLE, dyn_gravity_x, "0", "mm/s^2", -1e12, 1e12, 0,
      "x of the gravity g acting on the line density: energy -rho int g.r dl along a spline (the "
      "load term), -int mu g.c du over a D-NURBS curve's parameter (docs/NUMERICS.md, \"D-NURBS\"); "
      "the particles' gravity is particles.gravity."),
  NUM("dynamics", "gravity_y", LW_PT_DOUBLE, dyn_gravity_y, "0", "mm/s^2", -1e12, 1e12, 0,
      "y of g (for splines y points down the page: 9810 is the Earth's gravity on a page held upright; "
      "a D-NURBS curve's y points up, as nurbs.points: there -9810, in its own length unit)."),
  NUM("dynamics", "force_x", LW_PT_DOUBLE, dyn_force_x, "0", "force/mm", -1e12, 1e12, 0,
      "x of a constant external force f per mm of line: energy -int f.r dl (the load term)."),
  NUM("dynamics", "force_y", LW_PT_DOUBLE, dyn_force_y, "0", "force/mm", -1e12, 1e12, 0,
      "y of the constant external force per mm."),
  CHOICE("dynamics", "pin", dyn_pin, "none", "none|ends|first|last",
         "End points held fixed: of both ends of every spline, the first node, the last node (a wire's "
         "are nurbs.fixed, the particles' particles.pinned)."),
  NUM("dynamics", "pin_vectors", LW_PT_INT, dyn_pin_vectors, "0", "", 0, 1, 0,
      "1 = a pinned node's vector is held too (a clamped end); 0 = it turns freely."),
  CHOICE("dynamics", "integrator", dyn_integrator, "leapfrog", "leapfrog|review",
         "`leapfrog`: the generalised leapfrog (order 2, symplectic). `review`: the implicit scheme of "
         "the D-NURBS review (its eqs. 90 and 104; backward in the stiffness, so it damps high "
         "frequencies; needs rho > 0, a constant mass matrix and a quadratic energy: the nurbs system "
         "with frozen weights, at any dt in one solve a step). docs/NUMERICS.md, \"D-NURBS\"."),
  NUM("nurbs", "order", LW_PT_INT, nb_order, "4", "", 2, 8, 0,
      "Order k of the NURBS curve (degree k - 1; 4 = cubic). docs/NURBS.md."),
  LIST("nurbs", "points", nb_points, "", "length",
       "The control points as numbers `x y x y ...` (y up; at least `order` points; coordinates within "
       "+-1e9; a long list goes on over indented lines)."),
  STRING("nurbs", "file", nb_file, "", "path",
         "A file of control points, one `x y` or `x y w` a line (blanks, commas or ', ' between the "
         "numbers, as CSV; `#` starts a comment), relative "
         "to the scene file; used instead of `points` and `weights` (which hold some 300 points "
         "over indented lines: a file suits a curve made by another program)."),
  LIST("nurbs", "weights", nb_weights, "", "",
       "One weight > 0 per control point, the largest at most 1e4 times the smallest (past that the "
       "matrices and final.svg's fit lose their digits); empty = all 1 (a polynomial spline)."),
  LIST("nurbs", "knots", nb_knots, "", "",
       "The open knot vector: n + k nondecreasing numbers, the first k equal and the last k "
       "equal; empty = uniform inner knots on [0, 1]."),
  NUM("nurbs", "elevate", LW_PT_INT, nb_elevate, "0", "", 0, 6, 0,
      "Raise the degree by this much before the run (degree elevation: each knot's multiplicity "
      "rises with it, so the curve and its continuity are unchanged; order + elevate <= 8). "
      "docs/NURBS.md, \"Refinement\"."),
  NUM("nurbs", "refine", LW_PT_INT, nb_refine, "1", "", 1, 1000, 0,
      "Cut every knot span into this many equal spans before the run, after `elevate` (knot "
      "insertion: the curve unchanged, more control points, the new knots simple; at most "
      "1,000,000 control points after). The energy "
      "is the curve's, so a finer curve is a finer Ritz approximation of the same wire. "
      "docs/NURBS.md, \"Refinement\"."),
  NUM("nurbs", "alpha", LW_PT_DOUBLE, nb_alpha, "1", "energy", 0, 1e12, 0,
      "Tension alpha of the energy 1/2 int alpha |c_u|^2 + beta |c_uu|^2 du (over the parameter u)."),
  NUM("nurbs", "beta", LW_PT_DOUBLE, nb_beta, "0", "energy", 0, 1e12, 0,
      "Rigidity beta of that energy."),
  NUM("nurbs", "gauss", LW_PT_INT, nb_gauss, "10", "", 1, 64, 0,
      "Gauss-Legendre points per knot span for the matrices M, D and K: at least as many in all as "
      "control points (fewer leave motions that the energy does not see), so at least 2 (a curve "
      "has fewer spans than points; 1 is read only in a run begun before 2026-12-05); `order` "
      "points make the matrices of a polynomial curve exact. A span whose weights differ takes them on "
      "each of its pieces toward its ends (nurbs.pieces; docs/NURBS.md)."),
  NUM("nurbs", "pieces", LW_PT_INT, nb_pieces, "2", "", 1, 2, 0,
      "How a knot span of weights apart is cut toward its ends for the quadrature: 2 = as far as the "
      "rational basis turns there: beside a knot of multiplicity m where p = k - m is under 3 (a clamped "
      "end: 1) h ((k - 1) q')^(-1/p), q' the ratio q of the span's weights but at least 2, for any q over "
      "1; elsewhere h q^(-1/3) from a ratio of 2; 1 = h q^(-1/3) at every knot, from a ratio of 2, as runs "
      "before 2026-12-07 (a run of theirs, whose scene.ini has no line for "
      "this key, resumes so): a light end point of weight 0.01 read 0.58 of the energy, an order 8 curve "
      "with an end weight of 0.5 99 % (docs/NURBS.md)."),
  NUM("nurbs", "fixed", LW_PT_INT, nb_fixed, "0", "", 0, 1e9, 0,
      "Control points held at each end (1 = the ends of the curve; 2 = its end tangents too). "
      "Monte Carlo and the dynamics move only the others. Gravity is the [dynamics] "
      "rho times gravity_x, gravity_y."),
  NUM("nurbs", "free_weights", LW_PT_INT, nb_free_weights, "0", "", 0, 1, 0,
      "1 = the weights move too, as coordinates s = log w (so they stay > 0; the held control "
      "points' weights are held, which fixes their common scale): the dynamics' mass matrix "
      "then depends on the curve, Monte Carlo adds the move kind `weight`. Needs fixed >= 1 "
      "and the leapfrog. 0 = frozen weights, a linear system. docs/NURBS.md, \"Free weights\"."),
  NUM("nurbs", "weight_inertia", LW_PT_DOUBLE, nb_weight_inertia, "0.1", "", 0, 1e12, 0,
      "Free weights: the inertia of each log weight s, per unit density, added to the mass "
      "matrix (T gains 1/2 rho weight_inertia sdot^2). A straight polynomial curve moves the "
      "same way under its weights as under its points, so without it the mass matrix is "
      "(nearly) singular there (docs/NUMERICS.md, \"Free weights\"). 0 = the review's kinetic energy alone."),
  NUM("nurbs", "weight_stiffness", LW_PT_DOUBLE, nb_weight_stiffness, "1000", "energy", 0, 1e12, 0,
      "Free weights: the term `weights` = 1/2 weight_stiffness sum (log w)^2, a spring that "
      "pulls every weight toward 1 (the review's reset to 1, made smooth and conservative). "
      "The elastic energy alone lowers as a weight goes to 0, so without it a weight can fall "
      "without bound (docs/NUMERICS.md, \"Free weights\"). 0 = off."),
  NUM("nurbs", "step_weight", LW_PT_DOUBLE, nb_step_weight, "0.05", "", 0, 10, LW_MIN_OPEN,
      "Initial half width of a `weight` move's uniform step in s = log w (free weights; tuned "
      "toward [moves] target like step_point)."),
  NUM("nurbs", "svg_tolerance", LW_PT_DOUBLE, nb_svg_tolerance, "1e-4", "length", 0, 1e6, LW_MIN_OPEN,
      "Largest distance of final.svg's cubic Beziers from a rational curve (a polynomial one of "
      "order <= 4 is exact); the largest found is reported in summary.json."),
  NUM("nurbs", "png_scale", LW_PT_DOUBLE, nb_png_scale, "50", "pixels/length", 0, 1e6, LW_MIN_OPEN,
      "Scale of final.png and the frames (final.png's long side at most 4096 pixels)."),
};
const size_t lw_param_count = sizeof lw_param_table / sizeof lw_param_table[0];

_Static_assert(sizeof lw_param_table / sizeof lw_param_table[0] <= LW_PARAM_MAX,
               "lw_params.line too small for the table");

const lw_param_def *lw_params_find(const char *section, const char *key)
{
  for (size_t i = 0; i < lw_param_count; i++)
    if (!strcmp(lw_param_table[i].section, section) && !strcmp(lw_param_table[i].key, key))
      return &lw_param_table[i];
  return NULL;
}

static int section_known(const char *section)
{
  for (size_t i = 0; i < lw_param_count; i++)
    if (!strcmp(lw_param_table[i].section, section)) return 1;
  return 0;
}

int lw_params_edit_distance(const char *a, const char *b)
{
  size_t la = strlen(a), lb = strlen(b);
  int row[64];
  if (la >= 64 || lb >= 64) return INT_MAX / 2;
  for (size_t j = 0; j <= lb; j++) row[j] = (int)j;
  for (size_t i = 1; i <= la; i++) {
    int diag = row[0];
    row[0] = (int)i;
    for (size_t j = 1; j <= lb; j++) {
      int up = row[j], best = diag + (tolower((unsigned char)a[i - 1]) != tolower((unsigned char)b[j - 1]));
      if (up + 1 < best) best = up + 1;
      if (row[j - 1] + 1 < best) best = row[j - 1] + 1;
      row[j] = best;
      diag = up;
    }
  }
  return row[lb];
}

/* "; did you mean 'scene.image'?" for the parameter nearest to a name that
** is not one (a typo in the key, or a key in the wrong section), or "" when
** none is near enough to be what was meant. */
static void suggest_key(const char *section, const char *key, char *out, size_t n)
{
  const lw_param_def *hit = NULL;
  int best = 2 + (int)strlen(key) / 4; /* a suggestion is nearer than this */
  for (size_t i = 0; i < lw_param_count; i++) {
    const lw_param_def *d = &lw_param_table[i];
    int dist = lw_params_edit_distance(key, d->key) + (strcmp(section, d->section) != 0);
    if (dist < best) best = dist, hit = d;
  }
  if (hit) snprintf(out, n, "; did you mean '%s.%s'?", hit->section, hit->key);
  else if (n) out[0] = '\0';
}

/* The same for a section: "; did you mean [scene]?" or "". */
static void suggest_section(const char *section, char *out, size_t n)
{
  const char *hit = NULL;
  int best = 3; /* a suggestion is nearer than this */
  for (size_t i = 0; i < lw_param_count; i++) {
    int dist = lw_params_edit_distance(section, lw_param_table[i].section);
    if (dist < best) best = dist, hit = lw_param_table[i].section;
  }
  if (hit) snprintf(out, n, "; did you mean [%s]?", hit);
  else if (n) out[0] = '\0';
}

/* Index of word in "a|b|c", or -1. */
static int choice_index_cased(const char *choices, const char *word, int fold)
{
  size_t n = strlen(word);
  int idx = 0;
  for (const char *c = choices; *c; idx++) {
    const char *bar = strchr(c, '|');
    size_t len = bar ? (size_t)(bar - c) : strlen(c);
    if (len == n && !(fold ? strncasecmp(c, word, n) : strncmp(c, word, n))) return idx;
    if (!bar) break;
    c = bar + 1;
  }
  return -1;
}

static int choice_index(const char *choices, const char *word) { return choice_index_cased(choices, word, 0); }

/* The idx-th word of "a|b|c" into buf. */
static void choice_name(const char *choices, int idx, char *buf, size_t n)
{
  const char *c = choices;
  for (int i = 0; i < idx && c; i++) {
    c = strchr(c, '|');
    if (c) c++;
  }
  size_t len = 0;
  if (c) {
    const char *bar = strchr(c, '|');
    len = bar ? (size_t)(bar - c) : strlen(c);
  }
  if (len >= n) len = n - 1;
  memcpy(buf, c ? c : "", len);
  buf[len] = '\0';
}

static void range_text(const lw_param_def *d, char *buf, size_t n)
{
  snprintf(buf, n, "%s %.10g and %s %.10g", (d->open & LW_MIN_OPEN) ? ">" : ">=", d->min,
           (d->open & LW_MAX_OPEN) ? "<" : "<=", d->max);
}

/* What fits on one line "key = value" of the INI reader. */
static size_t line_cap(const lw_param_def *d)
{
  return INI_MAX_LINE - 5 - strlen(d->key);
}

size_t lw_params_text_cap(const lw_param_def *d)
{
  size_t cap = d->list ? d->size - 1 : line_cap(d);
  return cap > d->size - 1 ? d->size - 1 : cap;
}

/* The bytes of list text s that go on its next line: up to a lone blank
** (one that the reader's joining gives back) at most soft bytes on, or the
** first one past that within hard; 0 where none is. */
static size_t list_chunk(const char *s, size_t soft, size_t hard)
{
  size_t len = strlen(s), best = 0;
  if (len <= soft) return len;
  for (size_t k = 1; k + 1 < len && k <= hard; k++) {
    /* (a line that goes on may not begin as a comment or a section does) */
    int lone = s[k] == ' ' && s[k - 1] != ' ' && s[k - 1] != '\t' && s[k + 1] != ' ' && s[k + 1] != '\t' &&
               !strchr(";#[", s[k + 1]);
    if (!lone) continue;
    if (k > soft && best) break;
    best = k;
    if (k > soft) break;
  }
  return best ? best : len <= hard ? len : 0;
}

#define LIST_LINE 96 /* a wrapped list's lines, to read in an editor */

int lw_params_write_list(FILE *f, const lw_param_def *d, const char *value)
{
  size_t hard = line_cap(d), len = strlen(value);
  if (len <= hard) {
    if (f) fprintf(f, "%s = %s\n", d->key, value);
    return 1;
  }
  /* the reader takes a line that goes on with '=' or ':' for a key (a
  ** fuzzed polygon's run wrote a scene.ini that read back as key 'scene.') */
  if (strpbrk(value, "=:")) return 0;
  for (int first = 1; *value; first = 0) {
    size_t n = list_chunk(value, LIST_LINE, hard);
    if (!n) return 0;
    if (f) fprintf(f, "%s%s%.*s\n", first ? d->key : "    ", first ? " = " : "", (int)n, value);
    value += n + (value[n] == ' ');
  }
  return 1;
}

/* Why a value a person typed is not d's, where it shows: quotes around it, a
** comment after it that the reader keeps ('#', or ';' with no blank
** before), a unit after a number, words for a switch; "" where none does. */
static void typed_hint(const lw_param_def *d, const char *text, char *hint, size_t n)
{
  const size_t len = strlen(text);
  const int numeric = d->type != LW_PT_CHOICE && d->type != LW_PT_STRING;
  size_t lead = 0; /* the longest start of text that is a number */
  double v;
  for (size_t k = len; k > 0 && !lead; k--)
    if (lw_number_parse_n(text, k, &v)) lead = k;
  size_t word = d->type == LW_PT_CHOICE ? strcspn(text, " \t#;") : lead; /* the value, as meant */
  const char *rest = text + word + strspn(text + word, " \t");
  *hint = '\0';
  if (len >= 2 && strchr("\"'", text[0]) && text[len - 1] == text[0])
    snprintf(hint, n, " (without the quotes)");
  else if (word && (*rest == '#' || *rest == ';'))
    snprintf(hint, n, " (the value alone: in a scene file a comment after it starts with ';' after a blank, "
             "'%.*s ; ...'; --set takes none)", (int)(word < 16 ? word : 16), text);
  else if (numeric && lead && *rest == '%' && d->max <= 1.0)
    snprintf(hint, n, " (a share, the number alone: %g for %.*s %%)", v / 100.0, (int)lead, text);
  else if (numeric && lead && (isalpha((unsigned char)*rest) || *rest == '%'))
    snprintf(hint, n, " (the number alone%s%s)", strlen(d->unit) > 1 ? ": it is in " : "",
             strlen(d->unit) > 1 ? d->unit : "");
  else if (numeric && !lead && d->type != LW_PT_DOUBLE && d->min == 0.0 && d->max == 1.0)
    snprintf(hint, n, " (0 = off, 1 = on)");
}

/* Parses text into the field of d; on failure writes what was expected. */
static int assign(lw_params *p, const lw_param_def *d, const char *text, char *expected, size_t n)
{
  char *base = (char *)p + d->offset;
  char range[128];
  switch (d->type) {
  case LW_PT_DOUBLE:
  case LW_PT_INT:
  case LW_PT_WHOLE: {
    double v;
    const int whole = d->type != LW_PT_DOUBLE;
    range_text(d, range, sizeof range);
    char hint[192];
    const int thousands = lw_number_separator_hint(text, whole, hint, sizeof hint);
    if (!lw_number_parse(text, &v) || thousands) {
      if (!hint[0]) typed_hint(d, text, hint, sizeof hint);
      snprintf(expected, n, "a %s %s%s", whole ? "whole number" : "number", range, hint);
      return 0;
    }
    if (whole && v != floor(v)) {
      snprintf(expected, n, "a whole number %s", range);
      return 0;
    }
    int lo_ok = (d->open & LW_MIN_OPEN) ? v > d->min : v >= d->min;
    int hi_ok = (d->open & LW_MAX_OPEN) ? v < d->max : v <= d->max;
    if (!lo_ok || !hi_ok) {
      snprintf(expected, n, "a value %s", range);
      return 0;
    }
    if (d->type == LW_PT_INT) *(int *)base = (int)v;
    else *(double *)base = v;
    return 1;
  }
  case LW_PT_CHOICE: {
    int idx = choice_index(d->choices, text);
    if (idx < 0) {
      /* (a page named as printed, "A4", was refused without a word of why) */
      const int folded = choice_index_cased(d->choices, text, 1);
      char word[64] = "", hint[192];
      if (folded >= 0) choice_name(d->choices, folded, word, sizeof word);
      typed_hint(d, text, hint, sizeof hint);
      snprintf(expected, n, "one of %s%s%s%s%s", d->choices, folded >= 0 ? " (in lower case: '" : "", word,
               folded >= 0 ? "')" : "", folded >= 0 ? "" : hint);
      return 0;
    }
    *(int *)base = idx;
    return 1;
  }
  case LW_PT_STRING: {
    /* Each text field has its own capacity (anneal.schedule is short), and
    ** "key = value" must fit on one line of the INI reader (read_line), or
    ** a list on indented lines, so that scene.ini, written back by a run,
    ** reads again. */
    size_t len = strlen(text), cap = lw_params_text_cap(d);
    /* a list longer than a line is written over lines at single blanks, so
    ** its runs of blanks and tabs become one blank, before its length is
    ** judged (a shorter one stays as given: a run's scene.ini of an earlier
    ** release reads the same) */
    char *merged = NULL;
    if (d->list && len > line_cap(d)) {
      if (!(merged = malloc(len + 1))) {
        snprintf(expected, n, "a list that fits in memory");
        return 0;
      }
      char *to = merged;
      for (const char *c = text; *c; c++)
        if ((*c != ' ' && *c != '\t') || (to > merged && to[-1] != ' ')) *to++ = *c == '\t' ? ' ' : *c;
      *to = '\0';
      text = merged;
      len = (size_t)(to - merged);
    }
    int ok = 0;
    if (len > cap)
      snprintf(expected, n, "at most %zu bytes (%s%s)", cap, d->list ? "the list's field" : "a scene line's",
               !strcmp(d->key, "polygon")  ? "; a detailed outline is a picture: boundary = mask"
               : !strcmp(d->unit, "path") ? "; a copy of the file at a shorter path"
                                           : "");
    else if (!lw_params_text_reads_back(text))
      snprintf(expected, n, "text without control characters, blanks at either end, or ';' at the "
                            "start or after a blank");
    else if (d->list && !lw_params_write_list(NULL, d, text)) {
      if (strpbrk(text, "=:"))
        snprintf(expected, n, "a list without '=' or ':' (one longer than a line goes on over lines, which cannot "
                 "hold them)");
      else snprintf(expected, n, "entries of at most %zu bytes each", line_cap(d));
    } else {
      strcpy(base, text);
      ok = 1;
    }
    free(merged);
    return ok;
  }
  }
  return 0;
}

void lw_params_defaults(lw_params *p)
{
  memset(p, 0, sizeof *p);
  char expected[512];
  for (size_t i = 0; i < lw_param_count; i++) assign(p, &lw_param_table[i], lw_param_table[i].def, expected, sizeof expected);
}

/* Whether p holds d's default. */
static int at_default(const lw_params *p, const lw_param_def *d)
{
  const char *base = (const char *)p + d->offset;
  double v;
  switch (d->type) {
  case LW_PT_DOUBLE:
  case LW_PT_WHOLE: return lw_number_parse(d->def, &v) && *(const double *)base == v;
  case LW_PT_INT: return lw_number_parse(d->def, &v) && *(const int *)base == (int)v;
  case LW_PT_CHOICE: return *(const int *)base == choice_index(d->choices, d->def);
  case LW_PT_STRING: return !strcmp(base, d->def);
  }
  return 0;
}

int lw_params_line(const lw_params *p, const char *section, const char *key)
{
  const lw_param_def *d = lw_params_find(section, key);
  if (!d) abort(); /* (a programming error, found by any test that reaches it) */
  return p->line[d - lw_param_table];
}

int lw_params_kept(const lw_params *p, const char *section, const char *key)
{
  const lw_param_def *d = lw_params_find(section, key);
  return d && p->of_run && p->line[d - lw_param_table] > 0;
}

int lw_params_given(const lw_params *p, const lw_param_def *d)
{
  const int line = p->line[d - lw_param_table];
  return line && !(p->of_run && line > 0) && !at_default(p, d);
}

int lw_params_named(const char *const *patterns, const lw_param_def *d)
{
  size_t n = strlen(d->section);
  for (; patterns && *patterns; patterns++) {
    const char *q = *patterns;
    if (strncmp(q, d->section, n) || q[n] != '.') continue;
    if (!strcmp(q + n + 1, "*") || !strcmp(q + n + 1, d->key)) return 1;
  }
  return 0;
}

static void value_text(const lw_params *p, const lw_param_def *d, char *buf, size_t n);

lw_status lw_params_blame(const lw_params *p, const char *section, const char *key, lw_error *err)
{
  char where[LW_PATH_MAX + 32], msg[LW_ERROR_MSG];
  lw_params_origin(p, lw_params_find(section, key), where, sizeof where);
  snprintf(msg, sizeof msg, "%s", err->msg);
  /* a schedule's name or a file's path with a no-break space is refused
  ** after the reading, by the module the value names; a path that finds
  ** its file holds its bytes rightly (a Latin-1 name), whatever else is
  ** wrong ("delete it" followed "not an image") */
  char value[LW_PARAM_TEXT_MAX] = "", unseen[96];
  const lw_param_def *d = lw_params_find(section, key);
  struct stat sb;
  if (d) value_text(p, d, value, sizeof value);
  lw_text_unseen_char(value, unseen, sizeof unseen);
  /* a Windows path ("C:\Users\...\photo.jpg", "photos\a.png") named no file */
  if (!unseen[0] && d && d->unit && !strcmp(d->unit, "path") && strchr(value, '\\') && stat(value, &sb))
    snprintf(unseen, sizeof unseen, " ('\\' is a letter of a name here, not a folder's end: paths take '/')");
  return lw_error_set(err, err->code, "%s: key '%s.%s': %s%s", where, section, key, msg,
                      strstr(msg, "U+") || (value[0] && !stat(value, &sb)) ? "" : unseen);
}

#define LW_PARAMS_FILE_LINE "; file "
#define LW_PARAMS_WRITTEN_LINE "; written by linewise "
#define LW_PARAMS_LIBRARIES_LINE "; libraries "

static void read_file_line(lw_params *p, const char *text);

typedef struct {
  lw_params *p;
  FILE *f;
  int line;      /* lines handed to inih so far */
  lw_error *err;
  int failed;
  char *buf;     /* getline's buffer */
  size_t cap;
  const lw_param_def *list; /* the list key of the line before, which an indented line goes on */
  int content;   /* a line neither blank nor a comment has been read */
} reader_ctx;

/* An indented line without '=' or ':' after a list's line goes on with the list,
** joined by one blank (inih's own continuation would glue a typo's line
** onto any key above, and take an indented key = value as text). */
static int continue_list(reader_ctx *rc)
{
  const lw_param_def *d = rc->list;
  const char *h = rc->buf + strspn(rc->buf, " \t");
  rc->list = NULL;
  if (!d || h == rc->buf || strchr("\n;#[", *h)) return 0;
  size_t n = strcspn(h, "\n");
  for (const char *c = h; c < h + n; c++) /* an inline comment, as inih ends a value */
    if (*c == ';' && (c[-1] == ' ' || c[-1] == '\t')) {
      n = (size_t)(c - h);
      break;
    }
  while (n && (h[n - 1] == ' ' || h[n - 1] == '\t')) n--;
  if (memchr(h, '=', n) || memchr(h, ':', n)) return 0; /* (a key, whatever its comment holds) */
  /* (as the key's own line: a control character there was taken, and the
  ** run's scene.ini, which holds it, could not be read back) */
  for (const char *c = h; c < h + n; c++)
    if ((unsigned char)*c < 0x20 && *c != '\t') {
      lw_error_set(rc->err, LW_EINPUT, "%s:%d: key '%s.%s' goes on with a control character (byte %zu of the line): "
                   "expected text without control characters", rc->p->file, rc->line, d->section, d->key,
                   (size_t)(c - rc->buf) + 1);
      rc->failed = 1;
      return 1;
    }
  char *value = (char *)rc->p + d->offset;
  size_t len = strlen(value);
  if (len + 1 + n > lw_params_text_cap(d)) {
    lw_error_set(rc->err, LW_EINPUT, "%s:%d: key '%s.%s' goes on past %zu bytes: expected a shorter list",
                 rc->p->file, rc->line, d->section, d->key, lw_params_text_cap(d));
    rc->failed = 1;
    return 1;
  }
  snprintf(value + len, d->size - len, "%s%.*s", len ? " " : "", (int)n, h);
  if (!lw_params_write_list(NULL, d, value)) {
    if (strpbrk(value, "=:"))
      lw_error_set(rc->err, LW_EINPUT, "%s:%d: key '%s.%s' goes on over lines with '=' or ':' in it: expected a "
                   "list without them", rc->p->file, rc->line, d->section, d->key);
    else
      lw_error_set(rc->err, LW_EINPUT, "%s:%d: key '%s.%s' goes on with a part of over %zu bytes without a single "
                   "blank: expected entries with single blanks between them", rc->p->file, rc->line, d->section,
                   d->key, line_cap(d));
    rc->failed = 1;
    return 1;
  }
  rc->list = d;
  return 1;
}

/* inih holds num - 1 bytes of a line (INI_MAX_LINE - 1 with the newline)
** and would read the rest of a longer line as a line of its own, so a long
** line is an error here, with its true number. */
static char *read_line(char *str, int num, void *stream)
{
  reader_ctx *rc = stream;
  if (rc->failed) return NULL;
  errno = 0;
  ssize_t len = lw_text_getline(&rc->buf, &rc->cap, rc->f);
  if (len < 0) {
    /* glibc sets no stream error where getline cannot grow its buffer: the
    ** rest of the file read as its end, and the scene as defaults */
    if (errno == ENOMEM) {
      lw_error_set(rc->err, LW_ENOMEM, "%s:%d: out of memory reading the line", rc->p->file, rc->line + 1);
      rc->failed = 1;
    }
    return NULL;
  }
  rc->line++;
  /* a CRLF line end counts as LF: the limit is the text's (it refused a
  ** line of 198 characters from Windows that it took from Unix) */
  if (len >= 2 && rc->buf[len - 2] == '\r' && rc->buf[len - 1] == '\n') {
    rc->buf[len - 2] = '\n';
    rc->buf[--len] = '\0';
  }
  /* a CR inside the line: a file of CR line ends (old Mac OS) reads as
  ** one line, a comment or too long, and the scene silently empty */
  const char *cr = memchr(rc->buf, '\r', (size_t)len);
  if (cr && cr + 1 < rc->buf + len && cr[1] != '\n') {
    lw_error_set(rc->err, LW_EINPUT, "%s:%d: a CR inside the line (a file of CR line ends, as old Mac OS wrote): "
                 "expected LF or CRLF line ends", rc->p->file, rc->line);
    rc->failed = 1;
    return NULL;
  }
  /* (a byte order mark an editor put first is not the line's: it counted) */
  const size_t bom = rc->line == 1 && !strncmp(rc->buf, "\xEF\xBB\xBF", 3) ? 3 : 0;
  if (len - (ssize_t)bom >= num) {
    lw_error_set(rc->err, LW_EINPUT, "%s:%d: line longer than %d bytes (the limit of the INI reader; a letter "
                 "outside ASCII takes two or more)", rc->p->file, rc->line, num - 2);
    rc->failed = 1;
    return NULL;
  }
  /* A run's header among the comments above the first section: a published
  ** scene.ini with a line of notes added above it, or saved by an editor that
  ** puts a BOM first, is still that run's (its random numbers, its presets). */
  const char *text = rc->buf + bom;
  text += strspn(text, " \t");
  if (!rc->content && !strncmp(text, LW_RUN_SCENE_HEADER, strlen(LW_RUN_SCENE_HEADER))) {
    rc->p->run_written = rc->p->of_run;
    rc->p->run_header = 1;
  }
  if (!rc->content && rc->p->run_header) read_file_line(rc->p, text);
  if (*text && !strchr(";#\r\n", *text)) rc->content = 1;
  /* inih would end the value at a NUL byte and drop the rest unseen */
  if (memchr(rc->buf, '\0', (size_t)len)) {
    lw_error_set(rc->err, LW_EINPUT, "%s:%d: " LW_TEXT_NUL_LINE, rc->p->file, rc->line);
    rc->failed = 1;
    return NULL;
  }
  if (continue_list(rc)) {
    if (rc->failed) return NULL;
    memcpy(str, "\n", 2);
    return str;
  }
  /* a section header is checked where it stands: inih would take "[scene]]"
  ** or "[scene] x" as [scene], and an unknown section without keys unseen */
  const char *h = rc->buf + strspn(rc->buf, " \t");
  if (*h == '[') {
    size_t n = strcspn(h + 1, "]\r\n");
    const char *rest = h + 1 + n + (h[1 + n] == ']');
    rest += strspn(rest, " \t\r\n");
    char name[64], hint[96];
    snprintf(name, sizeof name, "%.*s", (int)(n < sizeof name ? n : sizeof name - 1), h + 1);
    if (h[1 + n] != ']' || (*rest && *rest != ';' && *rest != '#')) {
      lw_error_set(rc->err, LW_EINPUT, "%s:%d: expected a section header '[name]', got '%.*s'", rc->p->file, rc->line,
                   (int)strcspn(h, "\r\n"), h);
      rc->failed = 1;
      return NULL;
    }
    if (n >= sizeof name || !section_known(name)) {
      suggest_section(name, hint, sizeof hint);
      lw_error_set(rc->err, LW_EINPUT, "%s:%d: unknown section [%s]%s", rc->p->file, rc->line, name, hint);
      rc->failed = 1;
      return NULL;
    }
  }
  memcpy(str, rc->buf + bom, (size_t)len - bom + 1);
  return str;
}

static int on_key(void *user, const char *section, const char *key, const char *value)
{
  reader_ctx *rc = user;
  if (rc->failed) return 0;
  rc->failed = 1;
  char hint[96];
  if (!section[0]) { /* a key above every [section]: name the section it belongs to */
    suggest_key("", key, hint, sizeof hint);
    lw_error_set(rc->err, LW_EINPUT, "%s:%d: key '%s' comes before any [section]%s", rc->p->file, rc->line, key,
                 hint);
    return 0;
  }
  const lw_param_def *d = lw_params_find(section, key); /* the section is known: read_line checked it */
  if (!d) {
    /* (a no-break space inside the name prints like a blank: named, by
    ** its byte in the name as the message quotes it) */
    char unseen[96], name[512]; /* (a line holds 198 bytes) */
    snprintf(name, sizeof name, "%s.%s", section, key);
    suggest_key(section, key, hint, sizeof hint);
    lw_error_set(rc->err, LW_EINPUT, "%s:%d: key '%s.%s' is not a parameter%s (see `linewise params` or "
                 "docs/PARAMETERS.md)%s",
                 rc->p->file, rc->line, section, key, hint, lw_text_unseen_char(name, unseen, sizeof unseen));
    return 0;
  }
  int *line = &rc->p->line[d - lw_param_table];
  if (*line > 0) {
    lw_error_set(rc->err, LW_EINPUT, "%s:%d: key '%s.%s' repeated (first set on line %d)",
                 rc->p->file, rc->line, section, key, *line);
    return 0;
  }
  char expected[512], unseen[96];
  if (!assign(rc->p, d, value, expected, sizeof expected)) {
    lw_error_set(rc->err, LW_EINPUT, "%s:%d: key '%s.%s': expected %s, got '%s'%s",
                 rc->p->file, rc->line, section, key, expected, value,
                 lw_text_unseen_char(value, unseen, sizeof unseen));
    return 0;
  }
  *line = rc->line;
  rc->failed = 0;
  rc->list = d->list ? d : NULL;
  return 1;
}

static lw_status read_file(lw_params *p, const char *path, int of_run, int resolve, lw_error *err)
{
  lw_params_defaults(p);
  p->of_run = of_run;
  p->run_written = 0;
  p->run_header = 0;
  if (lw_number_locale_ok(err)) return err->code;
  /* a path cut to fit would name another file in every message */
  if (strlen(path) >= sizeof p->file)
    return lw_error_set(err, LW_EINPUT, "%.80s...: the scene file's path is %zu bytes; expected at most %zu",
                        path, strlen(path), sizeof p->file - 1);
  snprintf(p->file, sizeof p->file, "%s", path);
  struct stat sb;
  if (!stat(path, &sb) && S_ISDIR(sb.st_mode))
    return lw_error_set(err, LW_EINPUT, "%s: a folder, not a scene file: %s", path,
                        lw_rundir_holds_run(path) ? "it holds a run, which 'linewise resume' continues"
                                                  : "expected a scene file (.ini, as params/example.ini)");
  /* (a save that failed left a file of 0 bytes, which drew 100 random lines) */
  if (!of_run && !stat(path, &sb) && S_ISREG(sb.st_mode) && sb.st_size == 0)
    return lw_error_set(err, LW_EINPUT, "%s: empty (0 bytes): expected a scene file (a line '[scene]' alone "
                        "takes every default)", path);
  if (lw_text_plain_file(path, err)) return err->code;
  FILE *f = fopen(path, "r");
  if (!f) return lw_error_set(err, LW_EINPUT, "%s: cannot open scene file: %s", path, strerror(errno));
  /* a photo where the scene goes ("linewise run my-photo.jpg") was "a NUL
  ** byte inside the line (UTF-16 text ...)" */
  unsigned char head[512];
  const size_t got = fread(head, 1, sizeof head, f);
  int readable;
  const char *kind = lw_image_kind(head, got, &readable);
  /* (the two-letter marks of BMP and Netpbm begin text too: "BMx = 1" is a
  ** key; an SVG's XML prologue begins any XML or HTML: one without <svg near
  ** the start is not called a picture) */
  const unsigned char *nl = memchr(head, '\n', got);
  const size_t line = nl ? (size_t)(nl - head) : got;
  if (kind && (!strcmp(kind, "a BMP") || head[0] == 'P') && memchr(head, '=', line)) kind = NULL;
  int svg_tag = 0;
  for (size_t k = 0; k + 4 <= got && !svg_tag; k++) svg_tag = !memcmp(head + k, "<svg", 4);
  if (kind && !strcmp(kind, "an SVG") && !svg_tag) kind = "an XML or HTML";
  if (kind) {
    fclose(f);
    char word[LW_RUNDIR_WORD_MAX];
    if (readable)
      return lw_error_set(err, LW_EINPUT, "%s: %s picture, not a scene file: a scene draws it, e.g. 'linewise run "
                          "params/photo.ini --set scene.image=%s' (README, \"Pictures\")", path, kind,
                          lw_rundir_shell_word(path, word, sizeof word));
    return lw_error_set(err, LW_EINPUT, "%s: %s file, not a scene file (a scene file is text: '[section]' and 'key = "
                        "value' lines; README, \"Using it\")", path, kind);
  }
  rewind(f);
  /* inih's continuation lines off: an indented line without '=' would
  ** glue a typo onto any value above (an indented key = value is a key);
  ** only a list goes on (continue_list).  Debian's inih takes these as
  ** globals: set for this parse alone, under a lock, and put back, since
  ** a program that embeds the library may parse its own files with inih
  ** (they stayed set, and its continuation lines became errors). */
  static pthread_mutex_t inih_settings = PTHREAD_MUTEX_INITIALIZER;
  pthread_mutex_lock(&inih_settings);
  const bool multiline = ini_allow_multiline, stop_first = ini_stop_on_first_error;
  ini_allow_multiline = false;
  ini_stop_on_first_error = true;
  reader_ctx rc = {p, f, 0, err, 0, NULL, 0, NULL, 0};
  errno = 0;
  int r = ini_parse_stream(read_line, &rc, on_key, &rc);
  ini_allow_multiline = multiline;
  ini_stop_on_first_error = stop_first;
  pthread_mutex_unlock(&inih_settings);
  int read_error = ferror(f) ? (errno ? errno : EIO) : 0;
  fclose(f);
  /* the line's look-alike of '=', '[' or ';' (a Japanese input method's
  ** full-width forms), or a byte order mark inside the file (two files
  ** saved with one, joined), by name: the syntax error said no more */
  char unseen[96] = "";
  if (r > 0 && r == rc.line && rc.buf) {
    rc.buf[strcspn(rc.buf, "\r\n")] = '\0'; /* (its end was told to be deleted) */
    /* (a first line's byte order mark is read as none: it was blamed) */
    lw_text_unseen_char(rc.buf + (r == 1 && !strncmp(rc.buf, "\xEF\xBB\xBF", 3) ? 3 : 0), unseen, sizeof unseen);
  }
  free(rc.buf);
  if (rc.failed) return LW_EINPUT;
  /* a directory opens but does not read: the user named the wrong thing */
  if (read_error) return lw_error_set(err, LW_EINPUT, "%s: cannot read scene file: %s", path, strerror(read_error));
  if (r > 0)
    return lw_error_set(err, LW_EINPUT,
                        "%s:%d: syntax error: expected '[section]', 'key = value' or a comment%s", path, r, unseen);
  if (r < 0) return lw_error_set(err, LW_ENOMEM, "%s: out of memory while reading", path);
  return resolve ? lw_params_resolve(p, err) : LW_OK;
}

lw_status lw_params_read(lw_params *p, const char *path, lw_error *err) { return read_file(p, path, 0, 1, err); }

lw_status lw_params_read_unresolved(lw_params *p, const char *path, lw_error *err)
{
  return read_file(p, path, 0, 0, err);
}

lw_status lw_params_read_run(lw_params *p, const char *path, int resolve, lw_error *err)
{
  return read_file(p, path, 1, resolve, err);
}

/* Named page sizes in mm, portrait, in the order of the choices of
** scene.page (custom first, which has none). */
static const double page_mm[][2] = {{0, 0},       {210, 297},   {297, 420},     {215.9, 279.4},
                                    {148, 210},   {105, 148},   {420, 594},     {594, 841},
                                    {841, 1189}, {279.4, 431.8}, {215.9, 355.6}};
_Static_assert(sizeof page_mm / sizeof page_mm[0] == LW_PAGE_LEGAL + 1, "a size for every named page");

/*
** scene.preset = photo: lengths in pen widths w (the line's own scale), the
** domain lattice from the page.  Found on the bundled picture on A4 at
** w = 0.35 (docs/IMAGES.md, "Photographs"): segments of 8 w keep a line
** supple at the picture's detail; tone_ink 0.5 with coverage 0.4 draws black
** as lines two pen widths apart, so strokes keep apart (close_share under
** 10 %), and the hard min_spacing of one pen width keeps them from merging;
** the near field is off (the constraint keeps samples apart, and it costs
** most of a proposal).  Tried on four standard test photographs: the edge
** tangent flow at 4 w followed the grain of every texture and lines crossed
** (close share 0.10 to 0.17); at 10 w it follows forms.  Tone 80 against the
** field's -1 lets density follow tone (5, 10, 20, 40 raised SSIM on every
** picture; with the line the annealer chooses and scored against the ink
** asked for, 80 beat 40 on seven pictures, and 160 and 320 shortened the
** strokes in light tones).  The annealer chooses how much line
** (moves.fixed_count = 0): it starts from coverage 0.6 and grows and
** shrinks lines (weights 0.05) where the tone term pays for them; at the
** same CPU time this beat every fixed coverage from 0.4 to 0.8 on the
** bundled picture and on four test photographs (docs/IMAGES.md, "With the
** photo preset" and "On photographs").  No chemical potential: one that
** paid for line (-2.5 per mm, until 2026-12-03) darkened every light tone
** by about a tenth of ink, flattening the picture's contrast ("What the
** scores asked for").  Where the picture is white paper a line costs 2.5
** per mm at w = 0.35 (potential = image, Phi = tone^8, near 0 but near
** white; 7.14 w, since line length per area goes as 1 / w): without it the
** first thin line in white costs almost nothing (the tone term is
** quadratic in the ink) and the field's reward for aligned line drew stray
** lines across white backgrounds (docs/IMAGES.md, "White backgrounds").
** That Phi changes within a picture pixel, and the annealer put the nodes
** where it was low and the curves between them where it was high (1.4 to
** 7.6 % of it hidden from 6 nodes); blurred by 1.5 w, about the nodes'
** spacing, 0.03 to 0.11 % at the same scores (docs/NUMERICS.md, "The
** potential between the nodes").
** A tenth of the births draw another segment count, so
** that a death can take a short piece too: a piece that could leave only
** by growing first stayed where growing costs, in a colour pen's white
** (docs/NUMERICS.md, "Trans-dimensional moves").
*/
#define PHOTO_WHITE (2.5 / 0.35) /* what a millimetre of line costs on white paper, per pen width */
static const struct {
  const char *section, *key, *text; /* text, or NULL: pens * w */
  double pens;
} photo_preset[] = {
    {"scene", "field", "etf", 0},          {"scene", "field_sigma", NULL, 10},
    {"init", "splines", "0", 0},           {"init", "coverage", "0.6", 0},
    {"init", "segments", "5", 0},          {"init", "segment_length", NULL, 8},
    {"energy", "strain", "20", 0},         {"energy", "bending", "2", 0},
    {"energy", "field", "-1", 0},          {"energy", "field_mode", "axial", 0},
    {"energy", "tone", "80", 0},           {"energy", "tone_blur", NULL, 3},
    {"energy", "tone_ink", "0.5", 0},      {"energy", "pair", "0.01", 0},
    {"energy", "pair_cutoff", NULL, 3},    {"energy", "pair_near", "0", 0},
    {"energy", "min_spacing", NULL, 1},    {"energy", "quadrature", "6", 0},
    {"energy", "boundary", "0.2", 0},      {"energy", "boundary_clearance", "0.5", 0},
    {"anneal", "schedule", "geometric", 0},
    {"anneal", "t_start", "0.5", 0},       {"anneal", "t_end", "0.002", 0},
    {"anneal", "sweeps", "300", 0},        {"anneal", "steps", "5", 0},
    {"moves", "fixed_count", "0", 0},      {"moves", "grow", "0.05", 0},
    {"moves", "shrink", "0.05", 0},        {"scene", "image_levels", "0.01", 0},
    {"layers", "apart", "pen", 0},         {"scene", "potential", "image", 0},
    {"energy", "potential", NULL, PHOTO_WHITE}, {"scene", "potential_power", "8", 0},
    {"moves", "birth_spread", "0.1", 0},   {"scene", "potential_blur", NULL, 1.5},
};

/* Sets an unset key from text; the key stays unset (line 0), so a later
** resolve recomputes it from the pen width and page then current. */
static void preset_key(lw_params *p, const char *section, const char *key, const char *text)
{
  const lw_param_def *d = lw_params_find(section, key);
  char expected[512];
  if (d && !p->line[d - lw_param_table]) assign(p, d, text, expected, sizeof expected);
}

static void apply_preset(lw_params *p)
{
  if (p->preset != LW_PRESET_PHOTO || p->of_run) return;
  const double w = p->pen_width;
  char text[64];
  for (size_t k = 0; k < sizeof photo_preset / sizeof photo_preset[0]; k++) {
    const char *t = photo_preset[k].text;
    if (!t) {
      snprintf(text, sizeof text, "%.17g", photo_preset[k].pens * w);
      t = text;
    }
    preset_key(p, photo_preset[k].section, photo_preset[k].key, t);
  }
  /* the near field is off because the spacing keeps strokes apart: with
  ** energy.min_spacing = 0 they touch and cross, and the product rule alone
  ** read a photograph's annealed pair energy 11.6 % low */
  if (!(p->min_spacing > 0.0)) preset_key(p, "energy", "pair_near", lw_params_find("energy", "pair_near")->def);
  /* the tone's samples no closer than a line needs to read as a line,
  ** 0.7 tone_blur apart along a segment (4 nodes): on four photographs
  ** the anneal took 0.88 of the CPU time of 6 (the other terms' nodes) at
  ** the same scores, and its final tone energy was within 5.5e-4 of 32
  ** nodes' (docs/ACCURACY.md, "On the photo preset"); more than the other
  ** terms' where the blur is narrower (0 there left 6 nodes for a blur of
  ** 0.2 mm, whose tone energy then read 6 % high) */
  const double need = ceil(p->segment_length / (0.7 * p->tone_blur));
  const int nt = need < LW_QUAD_MIN ? LW_QUAD_MIN : need > LW_QUAD_MAX ? LW_QUAD_MAX : (int)need;
  snprintf(text, sizeof text, "%d", nt == p->quadrature ? 0 : nt);
  preset_key(p, "energy", "tone_quadrature", text);
  /* domains of 90 w: more than twice a move's reach (a spline of 40 w and
  ** the cutoff), and small enough that each of the four phases has work
  ** for every core where the picture's ink is uneven (3 a side on A4 used
  ** 1.3 of 2 cores, 6 a side 1.8; docs/IMAGES.md) */
  int n = (int)floor((fmin(p->width, p->height) - 2.0 * p->margin) / (90.0 * w));
  snprintf(text, sizeof text, "%d", n < 1 ? 1 : (n > 64 ? 64 : n));
  /* (the dynamics has no sweeps to split) */
  if (!lw_driver_is_motion(p)) preset_key(p, "anneal", "domains", n < 2 ? "off" : text);
}

/* Where a key's value came from: the file and line, --set, or the file's
** default.  A key the photo preset filled names the preset, and the pen
** widths it was sized from: a message about a blur of 150 mm then says why
** (output.pen_width = 50). */
void lw_params_origin(const lw_params *p, const lw_param_def *d, char *buf, size_t n)
{
  int line = p->line[d - lw_param_table];
  if (line > 0) {
    snprintf(buf, n, "%s:%d", p->file, line);
    return;
  }
  if (line < 0) {
    snprintf(buf, n, line == LW_PARAMS_SEED_OPTION ? "--seed" : "--set");
    return;
  }
  /* a default still names the file: a message about it may come of another
  ** key the file sets (tempering.t_max below its t_min); "not set" and the
  ** value, since the file has no line of it to find */
  if (p->file[0]) snprintf(buf, n, "%s (not set: the default, %s)", p->file, d->def[0] ? d->def : "empty");
  else snprintf(buf, n, "default");
  if (p->preset != LW_PRESET_PHOTO || p->of_run) return;
  /* where the preset was asked for, as a key's line (a scene's "preset =
  ** photo" without an image was refused as "scene.preset = photo: key
  ** 'scene.potential'", naming no file); none for a preset a program set */
  char at[LW_PATH_MAX + 32] = "", sized[64] = "";
  if (lw_params_line(p, "scene", "preset")) lw_params_origin(p, lw_params_find("scene", "preset"), at, sizeof at);
  int filled = 0;
  for (size_t k = 0; !filled && k < sizeof photo_preset / sizeof photo_preset[0]; k++)
    if (!strcmp(photo_preset[k].section, d->section) && !strcmp(photo_preset[k].key, d->key)) {
      filled = 1;
      if (!photo_preset[k].text)
        snprintf(sized, sizeof sized, "%g pen widths of %g mm", photo_preset[k].pens, p->pen_width);
    }
  /* and the two it works out from the page and the blur (apply_preset) */
  filled = filled || (!strcmp(d->section, "anneal") && !strcmp(d->key, "domains")) ||
           (!strcmp(d->section, "energy") && !strcmp(d->key, "tone_quadrature"));
  if (!filled) return;
  if (at[0]) snprintf(buf, n, "%s (scene.preset = photo%s%s)", at, sized[0] ? ", " : "", sized);
  else snprintf(buf, n, "scene.preset = photo%s%s%s", sized[0] ? " (" : "", sized, sized[0] ? ")" : "");
}

/* orientation = auto: the picture's header says which way it lies.  A
** scene without a picture is portrait. */
static lw_status landscape_picture(const lw_params *p, int *landscape, lw_error *err)
{
  *landscape = 0;
  if (!p->image[0]) return LW_OK;
  char dir[LW_PATH_MAX], full[2 * LW_PATH_MAX + 2];
  lw_path_dir(dir, sizeof dir, p->file);
  lw_path_join(full, sizeof full, dir, p->image);
  lw_image_info info;
  lw_error probe;
  /* the picture is what is wrong, so the message names its key: a preset's
  ** orientation = auto reads the header before the scene loads the picture */
  if (lw_image_probe(full, &info, &probe)) {
    *err = probe;
    return lw_params_blame(p, "scene", "image", err);
  }
  *landscape = info.width > info.height;
  return LW_OK;
}

/* A run writes its parameters back as INI (scene.ini, which resume reads),
** where a ';' at the start of a value or after a blank begins a comment and
** blanks at either end are trimmed: text like that would come back
** different. */
int lw_params_text_reads_back(const char *text)
{
  size_t len = strlen(text);
  int ok = !len || (text[0] != ';' && text[0] != ' ' && text[0] != '\t' && text[len - 1] != ' ' &&
                    text[len - 1] != '\t');
  for (const char *c = text; ok && *c; c++)
    ok = ((unsigned char)*c >= 0x20 || *c == '\t') && !((*c == ' ' || *c == '\t') && c[1] == ';');
  return ok;
}

lw_status lw_params_bed_check(const lw_params *p, const double box[4], const char *what, lw_error *err)
{
  if (!p->hpgl && !p->gcode) return LW_OK;
  char where[LW_PATH_MAX + 32], area[160];
  const char *bed_key[2] = {"bed_width", "bed_height"}, axis[2] = {'x', 'y'};
  const double bed[2] = {p->plot_bed_w, p->plot_bed_h};
  /* the box's far corner on the machine's axes (plotter.c: y up, or turned
  ** a quarter turn counterclockwise), under either turn */
  const double reach[2][2] = {{box[2], p->height - box[1]}, {box[3], box[2]}};
  const double *r = reach[p->plot_turn != 0], *other = reach[p->plot_turn == 0];
  /* the other turn, where it would fit */
  const int turn_fits = !(bed[0] > 0.0 && other[0] > bed[0]) && !(bed[1] > 0.0 && other[1] > bed[1]);
  if (what) snprintf(area, sizeof area, "%s", what);
  else snprintf(area, sizeof area, "the %g x %g mm page inset by scene.margin = %g", p->width, p->height, p->margin);
  for (int k = 0; k < 2; k++) {
    if (!(bed[k] > 0.0) || r[k] <= bed[k]) continue;
    lw_params_origin(p, lw_params_find("plot", bed_key[k]), where, sizeof where);
    return lw_error_set(err, LW_EINPUT,
                        "%s: key 'plot.%s' = %g mm: the drawing area (%s%s) reaches %c = %g mm on the machine; "
                        "expected a wider margin or a smaller page%s",
                        where, bed_key[k], bed[k], area, p->plot_turn ? ", turned by plot.turn" : "", axis[k], r[k],
                        !turn_fits      ? ""
                        : p->plot_turn ? ", or plot.turn = 0, which fits"
                                       : ", or plot.turn = 90, which fits");
  }
  return LW_OK;
}

/* The real path of file (its links followed) into real, where the file is
** not there yet too: the nearest folder above it that is there, and the
** names below it, which no link can lead out of (a missing subfolder was
** said outside).  0 where none can be given: a '..' below a missing folder
** could lead out once it is made, and a name right below the folder that
** is there but resolves not is a link that leads nowhere yet (a dangling
** link to a folder outside passed). */
static int real_path_ahead(char *file, char *real, size_t n)
{
  for (size_t cut = strlen(file);;) {
    const char keep = file[cut];
    file[cut] = '\0';
    const int found = realpath(cut ? file : "/", real) != NULL;
    file[cut] = keep;
    if (found) {
      if (!file[cut]) return 1;
      char next[2 * LW_PATH_MAX + 2];
      struct stat ls;
      snprintf(next, sizeof next, "%.*s", (int)(cut + 1 + strcspn(file + cut + 1, "/")), file);
      if (!lstat(next, &ls)) return 0;
      for (const char *c = file + cut; *c; c += strcspn(c + 1, "/") + 1)
        if (!strncmp(c, "/..", 3) && (c[3] == '/' || !c[3])) return 0;
      snprintf(real + strlen(real), n - strlen(real), "%s", file + cut);
      return 1;
    }
    while (cut > 0 && file[cut - 1] != '/') cut--;
    if (!cut--) return 0;
  }
}

/* Where the environment names LINEWISE_INPUT_ROOT (a service running
** others' scenes), every file a key names must lie inside that folder, its
** links followed, checked before any is opened: a scene could name any file
** the service could read, and a refusal quoted its first line (an API key
** of a .env file, /etc/shadow's first entry).  A file not there yet is
** judged by its folder. */
static lw_status inputs_confined(const lw_params *p, lw_error *err)
{
  const char *root_env = getenv("LINEWISE_INPUT_ROOT");
  char root[4096], dir[LW_PATH_MAX], joined[2 * LW_PATH_MAX + 2], real[4096 + LW_PATH_MAX], where[LW_PATH_MAX + 32];
  if (!root_env || !root_env[0]) return LW_OK;
  struct stat st;
  const int rooted = realpath(root_env, root) != NULL;
  if (!rooted || stat(root, &st) || !S_ISDIR(st.st_mode))
    return lw_error_set(err, LW_EUSAGE, "LINEWISE_INPUT_ROOT=%s: %s: expected the folder a scene's files must lie in",
                        root_env, rooted ? "not a folder" : strerror(errno));
  const size_t n = strlen(root);
  lw_path_dir(dir, sizeof dir, p->file);
  for (size_t i = 0; i < lw_param_count; i++) {
    const lw_param_def *d = &lw_param_table[i];
    const char *path = (const char *)p + d->offset;
    if (d->type != LW_PT_STRING || !d->unit || strcmp(d->unit, "path") || !path[0]) continue;
    lw_path_join(joined, sizeof joined, dir, path);
    if (!real_path_ahead(joined, real, sizeof real)) real[0] = '\0';
    if (real[0] && !strncmp(real, root, n) && (real[n] == '/' || (n == 1 && root[0] == '/'))) continue;
    lw_params_origin(p, d, where, sizeof where);
    return lw_error_set(err, LW_EINPUT, "%s: key '%s.%s': '%s' is not inside LINEWISE_INPUT_ROOT (%s), where this "
                        "linewise reads a scene's files; expected a file there", where, d->section, d->key, path, root);
  }
  return LW_OK;
}

lw_status lw_params_resolve(lw_params *p, lw_error *err)
{
  char where[LW_PATH_MAX + 32], where_page[LW_PATH_MAX + 32];
  lw_status sc = inputs_confined(p, err);
  if (sc) return sc;
  /* a scene.ini that a run wrote before the key was one runs again as that
  ** run did (the hash of a resume's leaves the missing key out) */
  if (p->run_header && !lw_params_line(p, "anneal", "seed_version")) p->seed_version = 1;
  /* (a resume only: a new run of such a scene.ini writes every digit, its
  ** statistics whole; the resumed trace stays of one kind) */
  if (p->run_written && !lw_params_line(p, "output", "trace_exact")) p->trace_exact = 0;
  /* the driver decides the presets' keys below */
  if (!lw_driver_of(p, err)) return err->code;
  /* before the page is sized, which the orientation decides */
  if (p->preset == LW_PRESET_PHOTO) preset_key(p, "scene", "orientation", "auto");
  if (p->page != LW_PAGE_CUSTOM) {
    double w = page_mm[p->page][0], h = page_mm[p->page][1];
    int landscape = p->orientation == LW_ORIENT_LANDSCAPE;
    if (p->orientation == LW_ORIENT_AUTO) {
      lw_status st = landscape_picture(p, &landscape, err);
      if (st) return st;
    }
    if (landscape) {
      double t = w;
      w = h;
      h = t;
    }
    const lw_param_def *dp = lw_params_find("scene", "page");
    const char *names[2] = {"width", "height"};
    double *value[2] = {&p->width, &p->height}, want[2] = {w, h};
    for (int k = 0; k < 2; k++) {
      const lw_param_def *d = lw_params_find("scene", names[k]);
      /* An explicit size must agree: a resolved scene.ini carries both. */
      if (p->line[d - lw_param_table] && *value[k] != want[k]) {
        lw_params_origin(p, d, where, sizeof where);
        lw_params_origin(p, dp, where_page, sizeof where_page);
        char page_name[16];
        choice_name(dp->choices, p->page, page_name, sizeof page_name);
        /* under orientation = auto the size turns with each picture: the
        ** size this one turned it to would fail the next (a series loop),
        ** so where the given size is the page's other turn, that is named */
        const lw_param_def *dw = lw_params_find("scene", "width"), *dh = lw_params_find("scene", "height");
        const int gw = p->line[dw - lw_param_table] != 0, gh = p->line[dh - lw_param_table] != 0;
        const int other = (!gw || p->width == h) && (!gh || p->height == w);
        if (p->orientation == LW_ORIENT_AUTO && p->image[0] && other)
          return lw_error_set(err, LW_EINPUT,
                              "%s: key 'scene.%s' = %.12g mm conflicts with scene.page = %s (%g x %g mm, set at %s, "
                              "turned to the picture by scene.orientation = auto): expected no %s (the page sets "
                              "it, turned to each picture), or scene.orientation = %s to keep the page so",
                              where, names[k], *value[k], page_name, w, h, where_page, names[k],
                              landscape ? "portrait" : "landscape");
        /* the way out is the other key's: a size given over the file's page
        ** needs the page custom (it pointed at the width it refused) */
        char out[160];
        if (p->line[d - lw_param_table] < 0)
          snprintf(out, sizeof out, "for a size of your own, give --set scene.page=custom too");
        else
          snprintf(out, sizeof out, "over a size in the scene file, give --set scene.width=%g --set scene.height=%g "
                   "too", w, h);
        return lw_error_set(err, LW_EINPUT,
                            "%s: key 'scene.%s' = %.12g mm conflicts with scene.page = %s (%g x %g mm, set at %s): "
                            "expected %g or no %s (%s)",
                            where, names[k], *value[k], page_name, w, h, where_page, want[k], names[k], out);
      }
      *value[k] = want[k];
    }
  }
  /* The constant schedule has one temperature, so one step: its steps tune
  ** once, at the start, and stay frozen for the sampling (a step tunes
  ** again: moves.tune_sweeps), unless the scene sets anneal.steps.  The
  ** key is reset first, since an override may have changed the schedule. */
  const lw_param_def *steps = lw_params_find("anneal", "steps");
  const int steps_unset = !p->of_run && !p->line[steps - lw_param_table];
  char expected[64];
  if (steps_unset) assign(p, steps, steps->def, expected, sizeof expected);
  apply_preset(p);
  if (steps_unset && !strcmp(p->schedule, "constant")) assign(p, steps, "1", expected, sizeof expected);
  unsigned char rgb[LW_PLOT_PENS_MAX][3];
  /* (with layers the pens are theirs, which the scene says first) */
  if (p->pen_colors[0] && !p->ly_names[0] && lw_output_colors_parse(p->pen_colors, rgb, LW_PLOT_PENS_MAX) != p->pens) {
    lw_params_origin(p, lw_params_find("output", "pen_colors"), where, sizeof where);
    return lw_error_set(err, LW_EINPUT,
                        "%s: key 'output.pen_colors': expected %d colour%s '#rrggbb' or '#rgb' (one per pen), got '%s'",
                        where, p->pens, p->pens == 1 ? "" : "s", p->pen_colors);
  }
  /* A G-code sender takes a line as a command: an empty pen line would draw
  ** every travel, a byte past ASCII is refused by most controllers. */
  const char *pen_key[2] = {"gcode_pen_up", "gcode_pen_down"}, *pen_line[2] = {p->gcode_pen_up, p->gcode_pen_down};
  for (int k = 0; p->gcode && k < 2; k++) {
    const char *fault = lw_plotter_gcode_line_fault(pen_line[k]);
    if (!fault) continue;
    lw_params_origin(p, lw_params_find("plot", pen_key[k]), where, sizeof where);
    return lw_error_set(err, LW_EINPUT, "%s: key 'plot.%s' = '%s': %s (output.gcode = 1)", where, pen_key[k],
                        pen_line[k], fault);
  }
  /* a feed is written to the thousandth of a mm/min: below half of one it
  ** would be F0, which GRBL refuses (error 22) */
  const char *speed_key[2] = {"speed_down", "speed_up"};
  const double speed[2] = {p->speed_down, p->speed_up};
  for (int k = 0; p->gcode && k < 1 + (p->gcode_travel == 1); k++) {
    if (60.0 * speed[k] >= 0.0005) continue;
    lw_params_origin(p, lw_params_find("plot", speed_key[k]), where, sizeof where);
    return lw_error_set(err, LW_EINPUT, "%s: key 'plot.%s' = %g mm/s: final.gcode's feed (mm/min, to the thousandth) "
                        "would be F0, which GRBL refuses; expected more than 8.33e-06 mm/s (output.gcode = 1)", where,
                        speed_key[k], speed[k]);
  }
  /* With crop (the default) every stroke is cut inside the page inset by
  ** the margin, so that box decides, on the machine's axes, before a long
  ** anneal; the writers check the strokes themselves (plotter.h).  With a
  ** picture the crop is its rectangle, which the scene checks once it has
  ** placed it (the page's inset refused a landscape photo on A4 portrait
  ** that fitted the bed by 45 mm). */
  const double inset[4] = {p->margin, p->margin, p->width - p->margin, p->height - p->margin};
  lw_status st = p->crop && p->image[0] ? LW_OK : lw_params_bed_check(p, inset, NULL, err);
  if (st) return st;
  /* PDF readers take pages of at most 14,400 points a side (5080 mm), and
  ** cairo's PDF of a page of kilometres ran out of memory or crashed */
  if (p->pdf && (p->width > LW_PDF_SIDE_MAX || p->height > LW_PDF_SIDE_MAX)) {
    lw_params_origin(p, lw_params_find("output", "pdf"), where, sizeof where);
    return lw_error_set(err, LW_EINPUT, "%s: key 'output.pdf': a page of %g x %g mm; PDF pages are at most %g mm "
                        "a side (14,400 points): expected 0, or a smaller page", where, p->width, p->height,
                        LW_PDF_SIDE_MAX);
  }
  return LW_OK;
}

lw_status lw_params_set(lw_params *p, const char *assignment, lw_error *err)
{
  const char *dot = strchr(assignment, '.');
  const char *eq = strchr(assignment, '=');
  if (!dot || !eq || dot > eq) {
    /* a key without its section: the sections that have it ("pen_width=0.5"
    ** said only what was expected) */
    char hint[160] = "";
    const size_t lk = eq && (!dot || dot > eq) ? (size_t)(eq - assignment) : 0;
    for (size_t i = 0, n = 0; lk && i < lw_param_count && n + 40 < sizeof hint; i++)
      if (strlen(lw_param_table[i].key) == lk && !strncasecmp(lw_param_table[i].key, assignment, lk))
        n += (size_t)snprintf(hint + n, sizeof hint - n, "%s'%s.%s'", n ? " or " : " (did you mean ",
                              lw_param_table[i].section, lw_param_table[i].key);
    if (hint[0]) snprintf(hint + strlen(hint), sizeof hint - strlen(hint), "?)");
    return lw_error_set(err, LW_EUSAGE, "--set '%s': expected section.key=value%s", assignment, hint);
  }
  char section[64], key[64];
  size_t ls = (size_t)(dot - assignment), lk = (size_t)(eq - dot - 1);
  if (ls >= sizeof section || lk >= sizeof key)
    return lw_error_set(err, LW_EUSAGE, "--set '%s': name too long", assignment);
  memcpy(section, assignment, ls);
  section[ls] = '\0';
  memcpy(key, dot + 1, lk);
  key[lk] = '\0';
  const lw_param_def *d = lw_params_find(section, key);
  if (!d && (isblank((unsigned char)section[0]) || isblank((unsigned char)key[0]) ||
             (lk && isblank((unsigned char)key[lk - 1]))))
    return lw_error_set(err, LW_EUSAGE, "--set '%s': blanks around the name; expected section.key=value "
                        "without them", assignment);
  if (!d) {
    char hint[96], unseen[96], name[sizeof section + sizeof key];
    snprintf(name, sizeof name, "%s.%s", section, key);
    suggest_key(section, key, hint, sizeof hint);
    return lw_error_set(err, LW_EUSAGE,
                        "--set %s.%s: not a parameter%s (see `linewise params` or docs/PARAMETERS.md)%s", section, key,
                        hint, lw_text_unseen_char(name, unseen, sizeof unseen));
  }
  char expected[512], unseen[96];
  const char *v = eq + 1;
  const size_t lv = strlen(v);
  /* (a scene file's values lose their blanks; a tab showed as '?') */
  if (!assign(p, d, v, expected, sizeof expected))
    return lw_error_set(err, LW_EUSAGE, "--set: key '%s.%s': expected %s, got '%s'%s", section, key, expected, v,
                        lv && (isblank((unsigned char)v[0]) || isblank((unsigned char)v[lv - 1]))
                            ? " (a blank or tab before or after the value, which --set keeps: expected none)"
                            : lw_text_unseen_char(v, unseen, sizeof unseen));
  p->line[d - lw_param_table] = -1;
  return LW_OK;
}

static void value_text(const lw_params *p, const lw_param_def *d, char *buf, size_t n)
{
  const char *base = (const char *)p + d->offset;
  switch (d->type) {
  case LW_PT_DOUBLE:
  case LW_PT_WHOLE: snprintf(buf, n, "%.17g", *(const double *)base); break;
  case LW_PT_INT: snprintf(buf, n, "%d", *(const int *)base); break;
  case LW_PT_CHOICE: choice_name(d->choices, *(const int *)base, buf, n); break;
  case LW_PT_STRING: snprintf(buf, n, "%s", base); break;
  }
}

/* Keys that shape only the final files (and when they are written), which
** a person may change in a run's scene.ini before it resumes. */
static const char *const file_keys[] = {"plot.*", "output.pen_colors", "output.png_scale", "output.pdf",
                                        "output.hpgl", "output.gcode", "output.preview_image",
                                        "output.fidelity_sigma", "output.fidelity_reference", "output.field_preview",
                                        "output.order", "output.checkpoint_every", "output.frames_every",
                                        "output.samples_every", "output.stats_from", "nurbs.svg_tolerance",
                                        "nurbs.png_scale", "particles.view_azimuth", "particles.view_elevation",
                                        "particles.png_size", "particles.disc", "output.pens", NULL};

/* FNV-1a, 64 bits, of n bytes on from h. */
static unsigned long long fnv(unsigned long long h, const void *bytes, size_t n)
{
  const unsigned char *c = bytes;
  for (size_t i = 0; i < n; i++) h = (h ^ c[i]) * 0x100000001b3ULL;
  return h;
}

#define FNV_START 0xcbf29ce484222325ULL

/* The hash of a file's bytes as text ("file " and 16 hex digits), or of
** what stopped its reading ("unread", errno in *unread); a path that is no
** regular file (a pipe would be read dry, or block) by its name. */
static void file_text(const char *path, char *buf, size_t n, int *unread)
{
  struct stat st;
  *unread = 0;
  if (!stat(path, &st) && !S_ISREG(st.st_mode)) {
    snprintf(buf, n, "%s", path);
    return;
  }
  FILE *f = fopen(path, "rb");
  unsigned long long h = FNV_START;
  unsigned char block[65536];
  size_t got;
  if (f) {
    while ((got = fread(block, 1, sizeof block, f)) > 0) h = fnv(h, block, got);
    if (ferror(f)) *unread = errno ? errno : EIO;
    fclose(f);
  } else {
    *unread = errno;
  }
  if (*unread) snprintf(buf, n, "unread");
  else snprintf(buf, n, "file %016llx", h);
}

int lw_params_file_idle(const lw_params *p, const lw_param_def *d)
{
  if (!strcmp(d->section, "init") && !strcmp(d->key, "from")) return 1;
  /* read into tempering.ladder as a run starts (which scene.ini keeps), and
  ** the dynamics reads no ladder */
  if (!strcmp(d->section, "tempering") && !strcmp(d->key, "ladder_file")) return 1;
  if (!strcmp(d->section, "anneal") && !strcmp(d->key, "table")) {
    const lw_schedule_type *t = lw_driver_is_motion(p) ? NULL : lw_schedule_find(p->schedule);
    return !t || !(t->needs & LW_SCHEDULE_USES_TABLE);
  }
  if (!strcmp(d->section, "scene") && !strcmp(d->key, "field_file")) return p->field != LW_FLD_FILE;
  return !strcmp(d->section, "scene") && !strcmp(d->key, "mask_image") && p->mask != LW_MASK_IMAGE;
}

unsigned long long lw_params_run_hash(const lw_params *p, lw_run_keys *keys)
{
  unsigned long long h = FNV_START;
  char line[LW_PARAM_TEXT_MAX + 4200];
  if (keys) keys->n = 0;
  for (size_t i = 0; i < lw_param_count; i++) {
    const lw_param_def *d = &lw_param_table[i];
    if ((p->of_run && p->line[i] <= 0) || lw_params_named(file_keys, d)) continue;
    const int is_path = d->type == LW_PT_STRING && !strcmp(d->unit, "path");
    if (keys && is_path && lw_params_file_idle(p, d)) continue;
    int n = snprintf(line, sizeof line, "%s.%s=", d->section, d->key), unread = 0;
    const char *path = (const char *)p + d->offset;
    if (keys && is_path && path[0]) file_text(path, line + n, sizeof line - (size_t)n, &unread);
    else value_text(p, d, line + n, sizeof line - (size_t)n);
    size_t len = strlen(line);
    h = fnv(fnv(h, line, len), "\n", 1);
    if (keys) {
      keys->index[keys->n] = (unsigned short)i;
      keys->hash[keys->n] = (unsigned short)(fnv(FNV_START, line, len) & 0xffff);
      keys->unread[keys->n++] = unread;
    }
  }
  return h;
}

int lw_params_write(const lw_params *p, FILE *f)
{
  const char *section = "";
  char buf[LW_PARAM_TEXT_MAX];
  for (size_t i = 0; i < lw_param_count; i++) {
    const lw_param_def *d = &lw_param_table[i];
    if (strcmp(section, d->section)) {
      fprintf(f, "%s[%s]\n", i ? "\n" : "", d->section);
      section = d->section;
    }
    value_text(p, d, buf, sizeof buf);
    if (d->list) lw_params_write_list(f, d, buf);
    else fprintf(f, "%s = %s\n", d->key, buf);
  }
  /* (a comma locale wrote "t_end = 0,01" and 0: no scene reads it back) */
  lw_error comma;
  return ferror(f) || lw_number_locale_ok(&comma) ? -1 : 0;
}

/* The files a run reads as it starts: every key naming one, but a file its
** settings leave idle (init.from is read at the start, though the rest of
** the run never reads it again). */
static int file_read_at_start(const lw_params *p, const lw_param_def *d)
{
  const char *path = (const char *)p + d->offset;
  return d->type == LW_PT_STRING && !strcmp(d->unit, "path") && path[0] &&
         (!lw_params_file_idle(p, d) || (!strcmp(d->section, "init") && !strcmp(d->key, "from")));
}

/* The FNV-1a hash of a regular file's bytes into *h; nonzero where it is
** no regular file or cannot be read. */
static int file_hash(const char *path, unsigned long long *h)
{
  char text[32];
  int unread;
  file_text(path, text, sizeof text, &unread);
  return unread || strncmp(text, "file ", 5) || sscanf(text + 5, "%16llx", h) != 1;
}

int lw_params_write_files(const lw_params *p, FILE *f)
{
  fprintf(f, "%s%s, build %s\n", LW_PARAMS_WRITTEN_LINE, LW_VERSION, lw_version_build());
  char libs[sizeof p->run_libraries];
  lw_version_libraries(libs, sizeof libs);
  fprintf(f, "%s%s\n", LW_PARAMS_LIBRARIES_LINE, libs);
  for (size_t i = 0; i < lw_param_count; i++) {
    const lw_param_def *d = &lw_param_table[i];
    unsigned long long h;
    if (file_read_at_start(p, d) && !file_hash((const char *)p + d->offset, &h))
      fprintf(f, "%s%s.%s: fnv1a-64 %016llx\n", LW_PARAMS_FILE_LINE, d->section, d->key, h);
  }
  return ferror(f) ? -1 : 0;
}

/* A "; file section.key: fnv1a-64 HEX" line of a run's scene.ini kept in p
** (lw_params_write_files), its "; written by linewise" and "; libraries"
** lines; any other comment is the scene's own. */
static void read_file_line(lw_params *p, const char *text)
{
  char name[80];
  unsigned long long h;
  if (!strncmp(text, LW_PARAMS_WRITTEN_LINE, strlen(LW_PARAMS_WRITTEN_LINE))) {
    snprintf(p->run_build, sizeof p->run_build, "%.*s", (int)strcspn(text + strlen(LW_PARAMS_WRITTEN_LINE), "\r\n"),
             text + strlen(LW_PARAMS_WRITTEN_LINE));
    return;
  }
  if (!strncmp(text, LW_PARAMS_LIBRARIES_LINE, strlen(LW_PARAMS_LIBRARIES_LINE))) {
    snprintf(p->run_libraries, sizeof p->run_libraries, "%.*s",
             (int)strcspn(text + strlen(LW_PARAMS_LIBRARIES_LINE), "\r\n"), text + strlen(LW_PARAMS_LIBRARIES_LINE));
    return;
  }
  if (strncmp(text, LW_PARAMS_FILE_LINE, strlen(LW_PARAMS_FILE_LINE)) || p->n_files >= LW_PARAMS_FILES_MAX ||
      sscanf(text + strlen(LW_PARAMS_FILE_LINE), "%79[^:]: fnv1a-64 %16llx", name, &h) != 2)
    return;
  char *dot = strchr(name, '.');
  const lw_param_def *d = dot ? (*dot = '\0', lw_params_find(name, dot + 1)) : NULL;
  if (!d || d->type != LW_PT_STRING || strcmp(d->unit, "path")) return; /* (a line edited by hand) */
  p->file_key[p->n_files] = (unsigned short)(d - lw_param_table);
  p->file_hash[p->n_files++] = h;
}

int lw_params_files_changed(const lw_params *p, char *buf, size_t n)
{
  int changed = 0;
  size_t used = 0;
  if (n) buf[0] = '\0';
  for (int k = 0; k < p->n_files; k++) {
    const lw_param_def *d = &lw_param_table[p->file_key[k]];
    const char *path = (const char *)p + d->offset;
    unsigned long long h;
    /* a file given by --set is another on purpose (a sweep over pictures) */
    if (p->line[p->file_key[k]] == -1 || (path[0] && !file_hash(path, &h) && h == p->file_hash[k])) continue;
    if (used < n)
      used += (size_t)snprintf(buf + used, n - used, "%s%s.%s (%s)", changed ? ", " : "", d->section, d->key,
                               path[0] ? path : "now none");
    changed++;
  }
  return changed;
}

void lw_params_write_doc(FILE *f, void (*read_by)(const lw_param_def *d, char *buf, size_t n),
                         const char *(*values)(const lw_param_def *d))
{
  const char *section = "";
  char range[128], readers[256];
  for (size_t i = 0; i < lw_param_count; i++) {
    const lw_param_def *d = &lw_param_table[i];
    if (strcmp(section, d->section)) {
      fprintf(f, "\n## [%s]\n\n| key | type | default | unit | range | read by | meaning |\n"
                 "|---|---|---|---|---|---|---|\n", d->section);
      section = d->section;
    }
    static const char *const type_name[] = {"number", "integer", "integer", "choice", "text"};
    _Static_assert(LW_PT_STRING == 4, "type_name follows lw_param_type");
    const char *type = type_name[d->type], *words = d->type == LW_PT_STRING ? values(d) : NULL;
    if (d->type == LW_PT_CHOICE) snprintf(range, sizeof range, "%s", d->choices);
    else if (words) snprintf(range, sizeof range, "%s", words);
    else if (d->type == LW_PT_STRING) snprintf(range, sizeof range, "-");
    else range_text(d, range, sizeof range);
    char *to = range; /* '|' and ", " between words become '/' */
    for (const char *c = range; *c; c++) {
      if (*c == '|' || (*c == ',' && c[1] == ' ' && c++)) *to++ = '/';
      else *to++ = *c;
    }
    *to = '\0';
    read_by(d, readers, sizeof readers);
    fprintf(f, "| `%s` | %s | `%s` | %s | %s | %s | ", d->key, words ? "choice" : type, d->def,
            d->unit[0] ? d->unit : "-", range, readers);
    for (const char *c = d->help; *c; c++) {
      if (*c == '|') fputc('\\', f); /* a bare | would end the Markdown cell */
      fputc(*c, f);
    }
    fputs(" |\n", f);
  }
}
