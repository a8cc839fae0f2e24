/*
** particles.c -- the oriented-particle system: set-up, state, energies and
** moves (particles.h).
*/
#include "linewise/particles.h"

#include <gsl/gsl_math.h>
#include <gsl/gsl_randist.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/particles_grow.h"
#include "linewise/particles_io.h"
#include "linewise/particles_place.h"
#include "linewise/state.h"
#include "linewise/system.h"

const char *const lw_particles_move_names[LW_PMOVE_ALL] = {"translate", "rotate", "birth", "death"};

/* ---- set-up ------------------------------------------------------------- */

/* Widens [lo, hi] per axis to hold the box c +- h. */
static void box_add(double lo[3], double hi[3], const double c[3], const double h[3])
{
  for (int k = 0; k < 3; k++) {
    lo[k] = fmin(lo[k], c[k] - h[k]);
    hi[k] = fmax(hi[k], c[k] + h[k]);
  }
}

/* The grid's box: what the pattern, the points and a sphere boundary can
** reach at the start, padded by the range (it needs no more: particles
** beyond it fall into the edge cells). */
static void setup_box(lw_particles_setup *s)
{
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  const double o[3] = {0, 0, 0}, t = 4.0 * s->noise, half = 0.5 * s->size;
  if (s->count) {
    double h[3] = {half + t, half + t, (s->pattern == LW_PPATTERN_PLANE ? 0.0 : half) + t};
    box_add(lo, hi, o, h);
  }
  for (size_t i = 0; i < s->n_points; i++) box_add(lo, hi, s->point + 3 * i, o);
  if (s->boundary == LW_PBOUNDARY_SPHERE) {
    const double h[3] = {s->boundary_radius, s->boundary_radius, s->boundary_radius};
    box_add(lo, hi, o, h);
  }
  for (int k = 0; k < 3; k++) {
    s->lo[k] = lo[k] - s->pair.range;
    s->extent[k] = hi[k] - lo[k] + 2.0 * s->pair.range;
  }
}

/* "file:line" (or "default", "--set") of particles.<key> into buf. */
static void origin(const lw_params *p, const char *key, char *buf, size_t n)
{
  lw_params_origin(p, lw_params_find("particles", key), buf, n);
}

lw_particles_setup *lw_particles_setup_new(const lw_params *p, lw_error *err)
{
  lw_particles_setup *s = calloc(1, sizeof *s);
  if (!s) {
    lw_error_set(err, LW_ENOMEM, "out of memory for the particle set-up");
    return NULL;
  }
  const double alpha[LW_PTERM_PAIRS] = {p->pt_alpha_lj, p->pt_alpha_p, p->pt_alpha_n, p->pt_alpha_c};
  char where[LW_PATH_MAX + 32];
  lw_error e;
  if (lw_ppair_init(&s->pair, p->pt_r0, p->pt_range, p->pt_weight, p->pt_sigma, p->pt_sigma_normal, alpha, &e)) {
    origin(p, "sigma_normal", where, sizeof where);
    lw_error_set(err, LW_EINPUT, "%s: key 'particles.sigma_normal': %s", where, e.msg);
    goto fail;
  }
  s->gravity = p->pt_gravity;
  s->boundary = p->pt_boundary;
  s->boundary_z = p->pt_boundary_z;
  s->boundary_radius = p->pt_boundary_radius;
  s->alpha_b = p->pt_alpha_b;
  s->pattern = p->pt_pattern;
  s->count = (size_t)p->pt_count;
  s->size = p->pt_size > 0 ? p->pt_size : lw_particles_auto_size(p->pt_pattern, s->count, p->pt_r0);
  /* a size that packs the particles closer than r0/2 on average: an energy
  ** beyond any use (20,000 in a cube of side r0 started at 8.5e32) and, with
  ** every particle within range of every other, a set-up of days for 10^7.
  ** Only a new run places them: a run begun before the rule resumes. */
  const double packed = 0.5 * lw_particles_auto_size(p->pt_pattern, s->count, p->pt_r0);
  if (s->count && p->pt_size > 0 && p->pt_size < packed && !p->of_run) {
    const double scale = pow(10.0, 3.0 - floor(log10(packed))); /* 4 digits, rounded up: accepted as printed */
    origin(p, "size", where, sizeof where);
    lw_error_set(err, LW_EINPUT, "%s: key 'particles.size': %zu particles in a pattern of size %g lie closer than "
                 "r0/2 on average (the automatic size for them is %g); expected at least %g, or 0 (automatic)",
                 where, s->count, p->pt_size, 2.0 * packed, ceil(packed * scale) / scale);
    goto fail;
  }
  s->noise = p->pt_noise;
  s->normal_noise = p->pt_normal_noise * M_PI / 180.0;
  s->chem = p->pt_chem;
  s->birth = p->pt_birth;
  s->death = p->pt_death;
  s->max_count = (size_t)p->pt_max_count;
  if ((s->birth > 0.0) != (s->death > 0.0)) {
    const char *zero = s->birth > 0.0 ? "death" : "birth";
    origin(p, zero, where, sizeof where);
    lw_error_set(err, LW_EINPUT, "%s: key 'particles.%s': births and deaths are each other's reverse, so both or "
                 "neither: expected > 0 with particles.%s = %g", where, zero, s->birth > 0.0 ? "birth" : "death",
                 s->birth > 0.0 ? s->birth : s->death);
    goto fail;
  }
  if ((s->birth > 0.0 || s->death > 0.0) && !(p->pt_range >= LW_GROW_REACH)) {
    origin(p, "range", where, sizeof where);
    lw_error_set(err, LW_EINPUT, "%s: key 'particles.range': births and deaths find a particle's anchors within "
                 "%.4g r0 of it: expected range >= %.4g with particles.birth or death > 0, got %g", where,
                 LW_GROW_REACH, LW_GROW_REACH, p->pt_range);
    goto fail;
  }
  if (p->pt_points[0]) {
    char dir[LW_PATH_MAX], full[2 * LW_PATH_MAX + 2];
    lw_path_dir(dir, sizeof dir, p->file);
    lw_path_join(full, sizeof full, dir, p->pt_points);
    if (lw_particles_read_points(full, &s->n_points, &s->point, &s->point_normal, &s->point_pin, err)) {
      lw_params_blame(p, "particles", "points", err);
      goto fail;
    }
    /* has_normal becomes the pin flags: a given normal is pinned with its point */
    for (size_t i = 0; i < s->n_points; i++)
      s->point_pin[i] = p->pt_pinned ? (unsigned char)(LW_PIN_POSITION | (s->point_pin[i] ? LW_PIN_ORIENTATION : 0))
                                     : 0;
  }
  if (s->n_points + s->count == 0) {
    origin(p, "count", where, sizeof where);
    lw_error_set(err, LW_EINPUT, "%s: key 'particles.count': expected at least 1 particle (no points file either)",
                 where);
    goto fail;
  }
  if (s->n_points + s->count > UINT32_MAX / 2) {
    origin(p, "count", where, sizeof where);
    lw_error_set(err, LW_EINPUT, "%s: key 'particles.count': expected fewer than %u particles in all", where,
                 UINT32_MAX / 2);
    goto fail;
  }
  double az = p->pt_view_azimuth * M_PI / 180.0, el = p->pt_view_elevation * M_PI / 180.0;
  s->view[0] = cos(el) * cos(az);
  s->view[1] = cos(el) * sin(az);
  s->view[2] = sin(el);
  s->png_size = p->pt_png_size;
  s->disc = p->pt_disc * p->pt_r0;
  /* (a start above the cap is a state the chain leaves and never comes
  ** back to: allowed, but said, since it was kept without a word) */
  if (s->birth > 0.0 && s->n_points + s->count > s->max_count)
    snprintf(s->note, sizeof s->note, "the start's %zu particles are more than particles.max_count = %zu: no birth "
             "until deaths bring the count under it", s->n_points + s->count, s->max_count);
  setup_box(s);
  return s;
fail:
  lw_particles_setup_free(s);
  return NULL;
}

void lw_particles_setup_free(lw_particles_setup *s)
{
  if (!s) return;
  free(s->point);
  free(s->point_normal);
  free(s->point_pin);
  free(s);
}

/* ---- energies ----------------------------------------------------------- */

/* The per-particle terms of a particle at x into e[GRAVITY], e[BOUNDARY]
** (added); 1 if x is outside the boundary (forbidden). */
static int external(const lw_particles_setup *s, const double x[3], double e[LW_PTERM_COUNT])
{
  if (s->gravity != 0.0) e[LW_PTERM_GRAVITY] += s->gravity * x[2];
  if (s->boundary == LW_PBOUNDARY_NONE) return 0;
  double d = s->boundary == LW_PBOUNDARY_PLANE ? x[2] - s->boundary_z
                                               : s->boundary_radius - sqrt(lw_v3_dot(x, x));
  if (!(d > 0.0)) return 1;
  if (s->alpha_b != 0.0) e[LW_PTERM_BOUNDARY] += s->alpha_b / (d * d);
  return 0;
}

static const char *boundary_name(const lw_particles_setup *s)
{
  return s->boundary == LW_PBOUNDARY_PLANE ? "plane" : "sphere";
}

int lw_particles_outside(const lw_particles_setup *s, const double x[3])
{
  double e[LW_PTERM_COUNT] = {0};
  return external(s, x, e);
}

/* The cells a walk from x visits: x's cell c, the ranges lo..hi (its
** neighbours within the grid) and the squared gaps to them along each axis. */
typedef struct {
  int c[3], lo[3], hi[3];
  double gap[3][3];
} around;

static void cells_around(const lw_cellgrid *g, const double x[3], around *a)
{
  const double h = 1.0 / g->inv_h, o[3] = {g->x0, g->y0, g->z0};
  const int n[3] = {g->nx, g->ny, g->nz};
  lw_cellgrid_locate3(g, x[0], x[1], x[2], &a->c[0], &a->c[1], &a->c[2]);
  for (int k = 0; k < 3; k++) {
    lw_cellgrid_axis_gaps(o[k], h, a->c[k], x[k], a->gap[k]);
    a->lo[k] = a->c[k] > 0 ? a->c[k] - 1 : 0;
    a->hi[k] = a->c[k] + 1 < n[k] ? a->c[k] + 1 : n[k] - 1;
  }
}

/*
** The pair energies of a particle at x against its neighbours j != k with
** j >= from, added per term to ea (with normal na) and, when nb is not NULL,
** to eb (with normal nb): a rotation evaluates both orientations in one walk.
** Cells are visited in a fixed order (z, then y, then x, each ascending) and
** their entries in index order (grid.h), so the sum's order is a function
** of the positions alone.  Cells wholly beyond the range hold no pair and
** are skipped (with a margin for the rounding of the cell index).
*/
static void walk(const lw_particles *p, uint32_t k, uint32_t from, const double x[3], const double na[3],
                 const double nb[3], double ea[LW_PTERM_PAIRS], double eb[LW_PTERM_PAIRS])
{
  const lw_cellgrid *g = p->grid;
  const lw_ppair_ctx *c = &p->setup->pair;
  const double range2 = c->range2, skip2 = range2 * LW_CELLGRID_GAP_MARGIN;
  const double *nrm = p->nrm;
  around a;
  cells_around(g, x, &a);
  for (int zz = a.lo[2]; zz <= a.hi[2]; zz++)
    for (int yy = a.lo[1]; yy <= a.hi[1]; yy++) {
      double gyz = a.gap[2][zz - a.c[2] + 1] + a.gap[1][yy - a.c[1] + 1];
      if (gyz > skip2) continue;
      const lw_cell *row = g->cell + ((size_t)zz * (size_t)g->ny + (size_t)yy) * (size_t)g->nx;
      for (int xx = a.lo[0]; xx <= a.hi[0]; xx++) {
        if (gyz + a.gap[0][xx - a.c[0] + 1] > skip2) continue;
        const lw_cell *cell = row + xx;
        if (!cell->n) continue; /* an empty cell has no block: no pointer into it */
        const double *px = cell->x, *py = lw_cell_y(cell), *pz = lw_cell_z(cell);
        const uint32_t *id = lw_cell_idx(cell);
        for (uint32_t e = 0; e < cell->n; e++) {
          uint32_t j = id[e];
          if (j == k || j < from) continue;
          double r[3] = {px[e] - x[0], py[e] - x[1], pz[e] - x[2]};
          double d2 = lw_v3_dot(r, r);
          if (d2 >= range2) continue;
          lw_ppair_add(c, r, d2, na, nrm + 3 * (size_t)j, ea);
          if (nb) lw_ppair_add(c, r, d2, nb, nrm + 3 * (size_t)j, eb);
        }
      }
    }
}

int lw_particles_site_energy(const lw_particles *p, uint32_t skip, const double x[3], const double n[3],
                             double e[LW_PTERM_COUNT])
{
  if (external(p->setup, x, e)) return 1;
  if (p->setup->pair.on) walk(p, skip, 0, x, n, NULL, e, NULL);
  return 0;
}

void lw_particles_energy(const lw_particles *p, double term[LW_PTERM_COUNT])
{
  for (int t = 0; t < LW_PTERM_COUNT; t++) term[t] = 0.0;
  const lw_particles_setup *s = p->setup;
  for (size_t i = 0; i < p->n; i++) {
    if (s->pair.on) walk(p, (uint32_t)i, (uint32_t)i + 1, p->x + 3 * i, p->nrm + 3 * i, NULL, term, NULL);
    if (external(s, p->x + 3 * i, term)) term[LW_PTERM_BOUNDARY] = INFINITY;
  }
  if (s->chem != 0.0) term[LW_PTERM_CHEM] = s->chem * (double)p->n;
}

/* ---- gradient ------------------------------------------------------------ */

/* The particles j closer than the range to x, in the walk's order (cells z,
** y, x, entries by index) or with reverse = 1 in exactly the opposite order:
** visit(ctx, i, j, x_j - x, d2) for j > i (after = 1: the pairs of particle
** i), else for j != i.  Inlined where it is called, so that the gradient's
** copy has its visitor inlined and its direction fixed (a call per pair
** cost it a tenth). */
typedef void pair_visitor(void *ctx, size_t i, size_t j, const double r[3], double d2);

static inline __attribute__((always_inline)) void around_point(const lw_particles *p, const double x[3], size_t i,
                                                               int after, int reverse, pair_visitor *visit, void *ctx)
{
  const lw_cellgrid *g = p->grid;
  const double range2 = p->setup->pair.range2, skip2 = range2 * LW_CELLGRID_GAP_MARGIN;
  const int step = reverse ? -1 : 1;
  around a;
  cells_around(g, x, &a);
  int first[3], last[3];
  for (int k = 0; k < 3; k++) {
    first[k] = reverse ? a.hi[k] : a.lo[k];
    last[k] = (reverse ? a.lo[k] : a.hi[k]) + step;
  }
  for (int zz = first[2]; zz != last[2]; zz += step)
    for (int yy = first[1]; yy != last[1]; yy += step)
      for (int xx = first[0]; xx != last[0]; xx += step) {
        if (a.gap[2][zz - a.c[2] + 1] + a.gap[1][yy - a.c[1] + 1] + a.gap[0][xx - a.c[0] + 1] > skip2) continue;
        const lw_cell *cell = g->cell + ((size_t)zz * (size_t)g->ny + (size_t)yy) * (size_t)g->nx + xx;
        if (!cell->n) continue;
        const double *px = cell->x, *py = lw_cell_y(cell), *pz = lw_cell_z(cell);
        const uint32_t *id = lw_cell_idx(cell);
        for (uint32_t m = 0; m < cell->n; m++) {
          uint32_t e = reverse ? cell->n - 1 - m : m;
          size_t j = id[e];
          if (after ? j <= i : j == i) continue;
          double r[3] = {px[e] - x[0], py[e] - x[1], pz[e] - x[2]};
          double d2 = lw_v3_dot(r, r);
          if (d2 >= range2) continue;
          visit(ctx, i, j, r, d2);
        }
      }
}

/* Every pair i < j in the order of lw_particles_energy, or its reverse. */
static inline __attribute__((always_inline)) void each_pair(const lw_particles *p, int reverse, pair_visitor *visit,
                                                            void *ctx)
{
  for (size_t n = 0; n < p->n; n++) {
    size_t i = reverse ? p->n - 1 - n : n;
    around_point(p, p->x + 3 * i, i, 1, reverse, visit, ctx);
  }
}

void lw_particles_near(const lw_particles *p, uint32_t skip, const double x[3], pair_visitor *visit, void *ctx)
{
  around_point(p, x, skip, 0, 0, visit, ctx);
}

/* dE/dx (3n) into gx and dE/dn (3n, each normal a free vector) into gn, of
** every term that is on, the pairs in the order of lw_particles_energy. */
typedef struct {
  const lw_particles *p;
  double *gx, *gn;
} grad_ctx;

static void grad_pair(void *ctx, size_t i, size_t j, const double r[3], double d2)
{
  grad_ctx *a = ctx;
  const double *nrm = a->p->nrm;
  double gr[3] = {0, 0, 0};
  lw_ppair_grad(&a->p->setup->pair, r, d2, nrm + 3 * i, nrm + 3 * j, gr, a->gn + 3 * i, a->gn + 3 * j);
  for (int k = 0; k < 3; k++) {
    a->gx[3 * i + k] -= gr[k];
    a->gx[3 * j + k] += gr[k];
  }
}

static void gradient_xn(const lw_particles *p, double *gx, double *gn)
{
  const lw_particles_setup *s = p->setup;
  memset(gx, 0, 3 * p->n * sizeof *gx);
  memset(gn, 0, 3 * p->n * sizeof *gn);
  /* a particle's pairs with later ones come before its own terms, as when
  ** each particle's were added in turn: the same sums */
  grad_ctx a = {p, gx, gn};
  if (s->pair.on) each_pair(p, 0, grad_pair, &a);
  for (size_t i = 0; i < p->n; i++) {
    const double *x = p->x + 3 * i;
    double *gxi = gx + 3 * i;
    gxi[2] += s->gravity;
    if (s->boundary == LW_PBOUNDARY_NONE || s->alpha_b == 0.0) continue;
    /* alpha_B / d^2: the slope -2 alpha_B / d^3 along grad d */
    if (s->boundary == LW_PBOUNDARY_PLANE) {
      double d = x[2] - s->boundary_z;
      gxi[2] -= 2.0 * s->alpha_b / (d * d * d);
    } else {
      double len = sqrt(lw_v3_dot(x, x)), d = s->boundary_radius - len;
      double f = len > 0.0 ? 2.0 * s->alpha_b / (d * d * d * len) : 0.0;
      for (int k = 0; k < 3; k++) gxi[k] += f * x[k];
    }
  }
}

size_t lw_particles_n_coords(const lw_particles *p) { return LW_PARTICLE_COORDS * p->n; }

void lw_particles_get_coords(const lw_particles *p, double *c)
{
  for (size_t i = 0; i < p->n; i++) {
    memcpy(c + LW_PARTICLE_COORDS * i, p->x + 3 * i, 3 * sizeof *c);
    memcpy(c + LW_PARTICLE_COORDS * i + 3, p->q + 4 * i, 4 * sizeof *c);
  }
}

lw_status lw_particles_set_coords(lw_particles *p, const double *c, lw_error *err)
{
  if (!p->qlen && !(p->qlen = malloc((p->n ? p->n : 1) * sizeof *p->qlen)))
    return lw_error_set(err, LW_ENOMEM, "out of memory for %zu particles", p->n);
  for (size_t i = 0; i < LW_PARTICLE_COORDS * p->n; i++)
    if (!isfinite(c[i]))
      return lw_error_set(err, LW_EINPUT, "particle %zu: a coordinate is not finite", i / LW_PARTICLE_COORDS);
  for (size_t i = 0; i < p->n; i++) {
    const double *ci = c + LW_PARTICLE_COORDS * i, *cq = ci + 3;
    double *x = p->x + 3 * i, *q = p->q + 4 * i;
    /* a pinned part stays as it is, to the bit (a driver's 0 * step may
    ** turn a -0 into +0) */
    if (!(p->pin[i] & LW_PIN_POSITION) && (ci[0] != x[0] || ci[1] != x[1] || ci[2] != x[2])) {
      if (lw_cellgrid_move3(p->grid, (uint32_t)i, ci[0], ci[1], ci[2]))
        return lw_error_set(err, LW_ENOMEM, "out of memory for the particle grid");
      memcpy(x, ci, 3 * sizeof *x);
    }
    double len = sqrt(cq[0] * cq[0] + cq[1] * cq[1] + cq[2] * cq[2] + cq[3] * cq[3]);
    if (!(len > 0.0)) return lw_error_set(err, LW_EINPUT, "particle %zu: a quaternion of length 0", i);
    /* a unit quaternion to rounding is kept as given, so that a driver's
    ** coordinates and the state (and a checkpoint of it) agree bit for bit */
    p->qlen[i] = fabs(len - 1.0) <= LW_PARTICLE_UNIT_TOL ? 1.0 : len;
    if ((p->pin[i] & LW_PIN_ORIENTATION) || !memcmp(q, cq, 4 * sizeof *q)) continue;
    memcpy(q, cq, 4 * sizeof *q);
    if (p->qlen[i] != 1.0) lw_quat_normalise(q);
    lw_quat_normal(q, p->nrm + 3 * i);
  }
  lw_particles_energy(p, p->term);
  return LW_OK;
}

double lw_particles_gradient(const lw_particles *p, double *g, lw_error *err)
{
  double e = lw_particles_total(p);
  if (!isfinite(e)) return e;
  double *gx = malloc(6 * (p->n ? p->n : 1) * sizeof *gx);
  if (!gx) {
    lw_error_set(err, LW_ENOMEM, "out of memory for the gradient of %zu particles", p->n);
    return NAN;
  }
  double *gn = gx + 3 * p->n;
  gradient_xn(p, gx, gn);
  for (size_t i = 0; i < p->n; i++) {
    double *gi = g + LW_PARTICLE_COORDS * i, *gq = gi + 3;
    const double *q = p->q + 4 * i, *n = gn + 3 * i;
    for (int k = 0; k < 3; k++) gi[k] = p->pin[i] & LW_PIN_POSITION ? 0.0 : gx[3 * i + k];
    /* through n(q) = (2 (xz + wy), 2 (yz - wx), 1 - 2 (x^2 + y^2)), then
    ** onto the sphere's tangent, since the energy sees q / |q| */
    gq[0] = 2.0 * (n[0] * q[2] - n[1] * q[1]);
    gq[1] = 2.0 * (n[0] * q[3] - n[1] * q[0] - 2.0 * n[2] * q[1]);
    gq[2] = 2.0 * (n[0] * q[0] + n[1] * q[3] - 2.0 * n[2] * q[2]);
    gq[3] = 2.0 * (n[0] * q[1] + n[1] * q[2]);
    double along = gq[0] * q[0] + gq[1] * q[1] + gq[2] * q[2] + gq[3] * q[3];
    double scale = p->pin[i] & LW_PIN_ORIENTATION ? 0.0 : 1.0 / (p->qlen ? p->qlen[i] : 1.0);
    for (int k = 0; k < 4; k++) gq[k] = (gq[k] - along * q[k]) * scale;
  }
  free(gx);
  return e;
}

void lw_particles_constrain(const lw_particles *p, const double *from, double *c, double *pi)
{
  for (size_t i = 0; i < p->n; i++) {
    if (p->pin[i] & LW_PIN_ORIENTATION) continue;
    const size_t o = LW_PARTICLE_COORDS * i + 3;
    const double *q = c ? c + o : from + o;
    if (c && from) {
      /* RATTLE: back along the start's q0 (the constraint's normal there),
      ** q - s q0 with |q - s q0| = 1: the root of s^2 - 2 b s + |q|^2 - 1
      ** nearer 0, in the form without cancellation */
      double *u = c + o;
      const double *q0 = from + o;
      double b = u[0] * q0[0] + u[1] * q0[1] + u[2] * q0[2] + u[3] * q0[3];
      double e = u[0] * u[0] + u[1] * u[1] + u[2] * u[2] + u[3] * u[3] - 1.0, disc = b * b - e;
      if (b > 0.0 && disc >= 0.0) {
        double sh = e / (b + sqrt(disc));
        for (int k = 0; k < 4; k++) u[k] -= sh * q0[k];
      } else {
        lw_quat_normalise(u); /* a turn of a quarter or more in one step: no such root */
      }
    } else if (c) {
      lw_quat_normalise(c + o);
    }
    if (!pi) continue;
    double *m = pi + o;
    double along = m[0] * q[0] + m[1] * q[1] + m[2] * q[2] + m[3] * q[3];
    for (int k = 0; k < 4; k++) m[k] -= along * q[k];
  }
}

void lw_particles_each_pair(const lw_particles *p, int reverse, pair_visitor *visit, void *ctx)
{
  each_pair(p, reverse, visit, ctx);
}

int lw_particles_term_on(const lw_particles_setup *s, int t)
{
  switch (t) {
  case LW_PTERM_GRAVITY: return s->gravity != 0.0;
  case LW_PTERM_BOUNDARY: return s->boundary != LW_PBOUNDARY_NONE && s->alpha_b != 0.0;
  case LW_PTERM_CHEM: return s->chem != 0.0;
  default: return t >= 0 && t < LW_PTERM_PAIRS && s->pair.alpha[t] != 0.0;
  }
}

void lw_particles_terms(const lw_particles *p, double term[LW_PTERM_COUNT])
{
  memcpy(term, p->term, sizeof p->term);
}

double lw_particles_total(const lw_particles *p)
{
  double e = 0.0;
  for (int t = 0; t < LW_PTERM_COUNT; t++) e += p->term[t];
  return e;
}

lw_status lw_particles_refresh(lw_particles *p, double *drift)
{
  double old = lw_particles_total(p);
  lw_particles_energy(p, p->term);
  double e = lw_particles_total(p);
  if (drift) *drift = fabs(e - old) / fmax(fabs(e), 1.0);
  return LW_OK;
}

/* ---- states ------------------------------------------------------------- */

void lw_particles_free(lw_particles *p)
{
  if (!p) return;
  free(p->x);
  free(p->q);
  free(p->nrm);
  free(p->pin);
  free(p->qlen);
  for (int m = 0; m < LW_PMOVE_KINDS; m++) free(p->movable[m]);
  free(p->loose);
  lw_cellgrid_free(p->grid);
  free(p);
}

static lw_particles *alloc_state(const lw_particles_setup *s, size_t n, lw_error *err)
{
  lw_particles *p = calloc(1, sizeof *p);
  if (!p) goto nomem;
  p->setup = s;
  p->n = n;
  size_t m = p->cap = n ? n : 1;
  p->x = malloc(3 * m * sizeof *p->x);
  p->q = malloc(4 * m * sizeof *p->q);
  p->nrm = malloc(3 * m * sizeof *p->nrm);
  p->pin = calloc(m, 1);
  for (int k = 0; k < LW_PMOVE_KINDS; k++) p->movable[k] = malloc(m * sizeof *p->movable[k]);
  p->loose = malloc(m * sizeof *p->loose);
  if (!p->x || !p->q || !p->nrm || !p->pin || !p->movable[0] || !p->movable[1] || !p->loose) goto nomem;
  return p;
nomem:
  lw_particles_free(p);
  lw_error_set(err, LW_ENOMEM, "out of memory for %zu particles", n);
  return NULL;
}

/* Normals, the free lists and the grid of a state whose x, q and pin are
** set. */
/* The free lists and n_sweep from the pin flags, in index order. */
static void list_free(lw_particles *p)
{
  p->n_sweep = p->n_movable[0] = p->n_movable[1] = p->n_loose = 0;
  for (size_t i = 0; i < p->n; i++) {
    if (!(p->pin[i] & LW_PIN_POSITION)) p->movable[LW_PMOVE_TRANSLATE][p->n_movable[LW_PMOVE_TRANSLATE]++] = (uint32_t)i;
    if (!(p->pin[i] & LW_PIN_ORIENTATION)) p->movable[LW_PMOVE_ROTATE][p->n_movable[LW_PMOVE_ROTATE]++] = (uint32_t)i;
    if ((p->pin[i] & (LW_PIN_POSITION | LW_PIN_ORIENTATION)) != (LW_PIN_POSITION | LW_PIN_ORIENTATION)) p->n_sweep++;
    if (!p->pin[i]) p->loose[p->n_loose++] = (uint32_t)i;
  }
}

static lw_status finish(lw_particles *p, lw_error *err)
{
  const lw_particles_setup *s = p->setup;
  for (size_t i = 0; i < p->n; i++) lw_quat_normal(p->q + 4 * i, p->nrm + 3 * i);
  list_free(p);
  /* with births the cells are those of max_count particles whatever the
  ** count, so that a resumed run walks them in the same order */
  size_t room = s->birth > 0.0 || s->death > 0.0 ? s->max_count : 0;
  p->grid = lw_cellgrid_new3_room(s->lo, s->extent, s->pair.range, p->n, room, err);
  if (!p->grid) return LW_ENOMEM;
  for (size_t i = 0; i < p->n; i++)
    if (lw_cellgrid_insert3(p->grid, (uint32_t)i, p->x[3 * i], p->x[3 * i + 1], p->x[3 * i + 2]))
      return lw_error_set(err, LW_ENOMEM, "out of memory for the particle grid");
  lw_cellgrid_fit(p->grid);
  return LW_OK;
}

lw_particles *lw_particles_new_from(const lw_particles_setup *s, size_t n, const double *x, const double *q,
                                    const unsigned char *pin, lw_error *err)
{
  for (size_t i = 0; i < n; i++) {
    const double *xi = x + 3 * i, *qi = q + 4 * i;
    if (!isfinite(xi[0]) || !isfinite(xi[1]) || !isfinite(xi[2]) || !isfinite(qi[0]) || !isfinite(qi[1]) ||
        !isfinite(qi[2]) || !isfinite(qi[3])) {
      lw_error_set(err, LW_EINPUT, "particle %zu: expected finite numbers", i);
      return NULL;
    }
    double nq = sqrt(qi[0] * qi[0] + qi[1] * qi[1] + qi[2] * qi[2] + qi[3] * qi[3]);
    if (!(fabs(nq - 1.0) <= 1e-9)) {
      lw_error_set(err, LW_EINPUT, "particle %zu: expected a unit quaternion, got length %.17g", i, nq);
      return NULL;
    }
    if (lw_particles_outside(s, xi)) {
      lw_error_set(err, LW_EINPUT, "particle %zu at (%g, %g, %g) is outside the %s boundary", i, xi[0], xi[1],
                   xi[2], boundary_name(s));
      return NULL;
    }
  }
  lw_particles *p = alloc_state(s, n, err);
  if (!p) return NULL;
  memcpy(p->x, x, 3 * n * sizeof *x);
  memcpy(p->q, q, 4 * n * sizeof *q);
  if (pin) memcpy(p->pin, pin, n);
  if (finish(p, err)) goto fail;
  lw_particles_energy(p, p->term);
  /* what makes each term infinite: the pair terms' particles on top of one
  ** another, the wall's one on it (alpha_b / d^2), the others sizes near
  ** what a double holds */
  static const char *const why[LW_PTERM_COUNT] = {
    [LW_PTERM_GRAVITY] = "a weight or height near what a double holds (particles.gravity)",
    [LW_PTERM_BOUNDARY] = "a particle (nearly) on the boundary (particles.boundary, particles.alpha_b)",
    [LW_PTERM_CHEM] = "a chemical potential near what a double holds (particles.chem)"};
  for (int t = 0; t < LW_PTERM_COUNT; t++)
    if (!isfinite(p->term[t])) {
      /* a pair term's: the closest two named (the search is of a failed
      ** start only, and of a count that a quadratic scan finishes in a
      ** second) */
      char pair[160] = "";
      size_t a = 0, b = 0;
      double best = INFINITY;
      for (size_t i = 0; !why[t] && n <= 20000 && i < n; i++)
        for (size_t j = i + 1; j < n; j++) {
          const double dx = x[3 * i] - x[3 * j], dy = x[3 * i + 1] - x[3 * j + 1], dz = x[3 * i + 2] - x[3 * j + 2];
          const double d2 = dx * dx + dy * dy + dz * dz;
          if (d2 < best) best = d2, a = i, b = j;
        }
      if (isfinite(best)) /* (hypot: 1e-300 apart squared is 0) */
        snprintf(pair, sizeof pair, " (particles %zu and %zu, counted from 1, are %.3g apart)", a + 1, b + 1,
                 hypot(hypot(x[3 * a] - x[3 * b], x[3 * a + 1] - x[3 * b + 1]), x[3 * a + 2] - x[3 * b + 2]));
      lw_error_set(err, LW_EINPUT, "the %s energy of the particles is not finite: %s%s", lw_pterm_names[t],
                   why[t] ? why[t] : "two of them (nearly) coincide, or particles.r0 is near what a double holds",
                   pair);
      goto fail;
    }
  return p;
fail:
  lw_particles_free(p);
  return NULL;
}

static int place_outside(const void *setup, const double x[3]) { return lw_particles_outside(setup, x); }

/* A point and its place in the file, ordered by coordinates, x first. */
typedef struct {
  double x[3];
  size_t i;
} placed_point;

static int by_place(const void *a, const void *b)
{
  const placed_point *p = a, *q = b;
  for (int c = 0; c < 3; c++)
    if (p->x[c] != q->x[c]) return p->x[c] < q->x[c] ? -1 : 1;
  return (p->i > q->i) - (p->i < q->i);
}

lw_status lw_particles_check_start(const lw_particles_setup *s, const char **key, lw_error *err)
{
  *key = "points";
  for (size_t i = 0; i < s->n_points; i++) {
    const double *x = s->point + 3 * i;
    if (lw_particles_outside(s, x))
      return lw_error_set(err, LW_EINPUT, "point %zu at (%g, %g, %g) is outside the %s boundary: expected every "
                          "point inside it", i + 1, x[0], x[1], x[2], boundary_name(s));
  }
  /* a point given twice (a file joined with itself) has an infinite
  ** repulsion: name the two, which the energy cannot */
  placed_point *pt = malloc((s->n_points ? s->n_points : 1) * sizeof *pt);
  if (!pt) return lw_error_set(err, LW_ENOMEM, "out of memory for %zu points", s->n_points);
  for (size_t i = 0; i < s->n_points; i++) {
    memcpy(pt[i].x, s->point + 3 * i, sizeof pt[i].x);
    pt[i].i = i;
  }
  qsort(pt, s->n_points, sizeof *pt, by_place);
  for (size_t k = 1; k < s->n_points; k++)
    if (pt[k - 1].x[0] == pt[k].x[0] && pt[k - 1].x[1] == pt[k].x[1] && pt[k - 1].x[2] == pt[k].x[2]) {
      lw_status st = lw_error_set(err, LW_EINPUT, "points %zu and %zu are both at (%g, %g, %g): expected distinct "
                                  "points", pt[k - 1].i + 1, pt[k].i + 1, pt[k].x[0], pt[k].x[1], pt[k].x[2]);
      free(pt);
      return st;
    }
  free(pt);
  if (!s->count || s->boundary == LW_PBOUNDARY_NONE) return LW_OK;
  static const char *const name[] = {"cloud", "plane", "sphere"};
  *key = s->boundary == LW_PBOUNDARY_PLANE ? "boundary_z" : "size";
  if (s->pattern == LW_PPATTERN_CLOUD) {
    /* its places are drawn inside the boundary: only a cube wholly beyond a
    ** floor has none */
    if (s->boundary == LW_PBOUNDARY_SPHERE || 0.5 * s->size > s->boundary_z) return LW_OK;
    return lw_error_set(err, LW_EINPUT, "the cloud pattern (size %g) lies below z = %g: expected the floor below "
                        "that, got %g", s->size, 0.5 * s->size, s->boundary_z);
  }
  /* the lattice's sites before their noise (they need no generator) */
  double *x = malloc(7 * s->count * sizeof *x);
  if (!x) return lw_error_set(err, LW_ENOMEM, "out of memory for %zu particles", s->count);
  lw_status st = lw_particles_place(s->pattern, s->count, s->size, 0.0, 0.0, 0.0, 0, NULL, NULL, x, x + 3 * s->count,
                                    err);
  for (size_t i = 0; !st && i < s->count; i++)
    if (lw_particles_outside(s, x + 3 * i))
      st = lw_error_set(err, LW_EINPUT, "the %s pattern (size %g) puts a site at (%g, %g, %g), outside the %s "
                        "boundary: expected the pattern inside it", name[s->pattern], s->size, x[3 * i],
                        x[3 * i + 1], x[3 * i + 2], boundary_name(s));
  free(x);
  return st;
}

lw_particles *lw_particles_new(const lw_particles_setup *s, unsigned long seed, const char **key, lw_error *err)
{
  if (key) *key = NULL;
  size_t n = s->n_points + s->count;
  double *x = malloc(3 * n * sizeof *x), *q = malloc(4 * n * sizeof *q);
  unsigned char *pin = calloc(n, 1);
  lw_particles *p = NULL;
  if (!x || !q || !pin) {
    lw_error_set(err, LW_ENOMEM, "out of memory for %zu particles", n);
    goto out;
  }
  for (size_t i = 0; i < s->n_points; i++) {
    memcpy(x + 3 * i, s->point + 3 * i, 3 * sizeof *x);
    lw_quat_from_normal(s->point_normal + 3 * i, q + 4 * i);
    pin[i] = s->point_pin[i];
  }
  if (lw_particles_place(s->pattern, s->count, s->size, s->noise, s->normal_noise, 0.5 * s->pair.r0, seed,
                         place_outside, s, x + 3 * s->n_points, q + 4 * s->n_points, err)) {
    if (key && err && err->code == LW_EINPUT)
      *key = s->boundary == LW_PBOUNDARY_SPHERE ? "boundary_radius" : "boundary_z";
    goto out;
  }
  p = lw_particles_new_from(s, n, x, q, pin, err);
  /* (points alone: they are what the start is refused for, counted as read) */
  if (!p && key && err && err->code == LW_EINPUT && s->n_points && !s->count) *key = "points";
out:
  free(x);
  free(q);
  free(pin);
  return p;
}

lw_particles *lw_particles_copy(const lw_particles *src, lw_error *err)
{
  lw_particles *p = alloc_state(src->setup, src->n, err);
  if (!p) return NULL;
  memcpy(p->x, src->x, 3 * src->n * sizeof *p->x);
  memcpy(p->q, src->q, 4 * src->n * sizeof *p->q);
  memcpy(p->pin, src->pin, src->n);
  if (finish(p, err)) {
    lw_particles_free(p);
    return NULL;
  }
  memcpy(p->term, src->term, sizeof p->term);
  return p;
}

/* ---- moves -------------------------------------------------------------- */

size_t lw_particles_sweep_size(const lw_particles *p)
{
  return p->n_sweep;
}

double lw_particles_step_max(const lw_particles *p, int kind)
{
  const double *e = p->setup->extent;
  return kind == LW_PMOVE_ROTATE ? M_PI : sqrt(lw_v3_dot(e, e));
}

lw_particles_prop *lw_particles_prop_new(const lw_particles *p, lw_error *err)
{
  lw_particles_prop *pr = calloc(1, sizeof *pr);
  if (!pr) lw_error_set(err, LW_ENOMEM, "out of memory for a particle proposal");
  return pr;
}

void lw_particles_prop_free(lw_particles_prop *pr)
{
  free(pr);
}

double lw_particles_evaluate(const lw_particles *p, lw_particles_prop *pr, uint32_t k, const double x[3],
                             const double q[4], int *forbidden)
{
  const lw_particles_setup *s = p->setup;
  const double *xo = p->x + 3 * (size_t)k, *no = p->nrm + 3 * (size_t)k;
  pr->identity = 0;
  pr->log_ratio = 0.0;
  pr->k = k;
  memcpy(pr->x, x, sizeof pr->x);
  memcpy(pr->q, q, sizeof pr->q);
  lw_quat_normal(q, pr->n);
  if (forbidden) *forbidden = 0;
  /* a degenerate draw (an infinite step) never reaches the state: NaN, rejected */
  if (!isfinite(x[0] + x[1] + x[2]) || !isfinite(pr->n[0] + pr->n[1] + pr->n[2])) {
    for (int t = 0; t < LW_PTERM_COUNT; t++) pr->dterm[t] = NAN;
    return pr->dE = NAN;
  }
  double e_new[LW_PTERM_COUNT] = {0}, e_old[LW_PTERM_COUNT] = {0};
  int moved = x[0] != xo[0] || x[1] != xo[1] || x[2] != xo[2];
  if (moved) {
    if (external(s, x, e_new)) {
      for (int t = 0; t < LW_PTERM_COUNT; t++) pr->dterm[t] = 0.0;
      pr->dterm[LW_PTERM_BOUNDARY] = INFINITY;
      if (forbidden) *forbidden = LW_PROPOSE_IRREGULAR;
      return pr->dE = INFINITY;
    }
    external(s, xo, e_old);
  }
  /* a turn leaves every distance, so without a weighted term it changes nothing */
  if (s->pair.on && (moved || s->pair.weighted)) {
    if (moved) {
      walk(p, k, 0, xo, no, NULL, e_old, NULL);
      walk(p, k, 0, x, pr->n, NULL, e_new, NULL);
    } else {
      walk(p, k, 0, xo, no, pr->n, e_old, e_new);
    }
  }
  double dE = 0.0;
  for (int t = 0; t < LW_PTERM_COUNT; t++) {
    pr->dterm[t] = e_new[t] - e_old[t];
    dE += pr->dterm[t];
  }
  return pr->dE = dE;
}

/* The identity: a symmetric proposal that changes nothing. */
static double identity(lw_particles_prop *pr)
{
  pr->identity = 1;
  pr->log_ratio = 0.0;
  for (int t = 0; t < LW_PTERM_COUNT; t++) pr->dterm[t] = 0.0;
  return pr->dE = 0.0;
}

/* Draws the new position x and quaternion q of a move of kind `kind` of
** particle k. */
static void draw_move(const lw_particles *p, uint32_t k, int kind, double step, gsl_rng *rng, double x[3], double q[4])
{
  memcpy(x, p->x + 3 * (size_t)k, 3 * sizeof *x);
  memcpy(q, p->q + 4 * (size_t)k, 4 * sizeof *q);
  if (kind == LW_PMOVE_TRANSLATE) {
    for (int c = 0; c < 3; c++) x[c] += gsl_ran_gaussian_ziggurat(rng, step);
  } else {
    double axis[3], dq[4];
    gsl_ran_dir_3d(rng, &axis[0], &axis[1], &axis[2]);
    lw_quat_axis_angle(axis, gsl_ran_gaussian_ziggurat(rng, step), dq);
    lw_quat_mul(dq, p->q + 4 * (size_t)k, q);
    lw_quat_normalise(q);
  }
}

double lw_particles_propose(const lw_particles *p, lw_particles_prop *pr, int kind, double step, gsl_rng *rng,
                            int *forbidden)
{
  pr->kind = kind;
  if (forbidden) *forbidden = 0;
  size_t m = p->n_movable[kind];
  if (m == 0) return identity(pr);
  uint32_t k = p->movable[kind][gsl_rng_uniform_int(rng, m)];
  double x[3], q[4];
  draw_move(p, k, kind, step, rng, x, q);
  return lw_particles_evaluate(p, pr, k, x, q, forbidden);
}

double lw_particles_propose_in(const lw_particles *p, lw_particles_prop *pr, int kind, size_t site, double step,
                               gsl_rng *rng, int *forbidden, const double box[4])
{
  pr->kind = kind;
  if (forbidden) *forbidden = 0;
  if (p->pin[site] & (kind == LW_PMOVE_TRANSLATE ? LW_PIN_POSITION : LW_PIN_ORIENTATION)) return identity(pr);
  double x[3], q[4];
  draw_move(p, (uint32_t)site, kind, step, rng, x, q);
  /* a step that is not finite goes on to evaluate, which rejects it as NaN */
  if (isfinite(x[0] + x[1]) && !(x[0] >= box[0] && x[1] >= box[1] && x[0] <= box[2] && x[1] <= box[3])) {
    identity(pr); /* refused: never committed */
    if (forbidden) *forbidden = LW_PROPOSE_OUTSIDE;
    return pr->dE = INFINITY;
  }
  return lw_particles_evaluate(p, pr, (uint32_t)site, x, q, forbidden);
}

/* The state's part of a commit: the particle, its normal and its cell. */
static lw_status commit_move(lw_particles *p, const lw_particles_prop *pr)
{
  size_t k = pr->k;
  double *x = p->x + 3 * k;
  if ((x[0] != pr->x[0] || x[1] != pr->x[1] || x[2] != pr->x[2]) &&
      lw_cellgrid_move3(p->grid, pr->k, pr->x[0], pr->x[1], pr->x[2]))
    return LW_ENOMEM;
  memcpy(x, pr->x, sizeof pr->x);
  memcpy(p->q + 4 * k, pr->q, sizeof pr->q);
  memcpy(p->nrm + 3 * k, pr->n, sizeof pr->n);
  return LW_OK;
}

lw_status lw_particles_commit_part(lw_particles *p, lw_particles_prop *pr)
{
  if (pr->identity) return LW_OK;
  if (commit_move(p, pr)) return LW_ENOMEM;
  for (int t = 0; t < LW_PTERM_COUNT; t++) pr->acc[t] += pr->dterm[t];
  return LW_OK;
}

void lw_particles_merge(lw_particles *p, lw_particles_prop *pr)
{
  for (int t = 0; t < LW_PTERM_COUNT; t++) {
    p->term[t] += pr->acc[t];
    pr->acc[t] = 0.0;
  }
}

/* Room for one more particle in every array (the state unchanged when
** memory runs out). */
static lw_status grow(lw_particles *p)
{
  if (p->n < p->cap) return LW_OK;
  size_t c = 2 * p->cap;
  double *x = realloc(p->x, 3 * c * sizeof *x);
  if (x) p->x = x;
  double *q = x ? realloc(p->q, 4 * c * sizeof *q) : NULL;
  if (q) p->q = q;
  double *nrm = q ? realloc(p->nrm, 3 * c * sizeof *nrm) : NULL;
  if (nrm) p->nrm = nrm;
  unsigned char *pin = nrm ? realloc(p->pin, c) : NULL;
  if (pin) p->pin = pin;
  uint32_t *lists[LW_PMOVE_KINDS + 1] = {NULL, NULL, NULL};
  int ok = pin != NULL;
  for (int k = 0; ok && k <= LW_PMOVE_KINDS; k++) {
    uint32_t **l = k < LW_PMOVE_KINDS ? &p->movable[k] : &p->loose;
    if ((lists[k] = realloc(*l, c * sizeof **l))) *l = lists[k];
    else ok = 0;
  }
  double *qlen = ok && p->qlen ? realloc(p->qlen, c * sizeof *qlen) : NULL;
  if (qlen) p->qlen = qlen;
  if (!ok || (p->qlen && !qlen)) return LW_ENOMEM;
  p->cap = c;
  return LW_OK;
}

/* A free particle at the end (a birth). */
static lw_status append(lw_particles *p, const lw_particles_prop *pr)
{
  size_t k = p->n;
  if (grow(p) || lw_cellgrid_reserve(p->grid, k + 1)) return LW_ENOMEM;
  lw_cellgrid_extend(p->grid, 1);
  if (lw_cellgrid_insert3(p->grid, (uint32_t)k, pr->x[0], pr->x[1], pr->x[2])) {
    lw_cellgrid_truncate(p->grid, k);
    return LW_ENOMEM;
  }
  memcpy(p->x + 3 * k, pr->x, sizeof pr->x);
  memcpy(p->q + 4 * k, pr->q, sizeof pr->q);
  memcpy(p->nrm + 3 * k, pr->n, sizeof pr->n);
  p->pin[k] = 0;
  if (p->qlen) p->qlen[k] = 1.0;
  p->movable[LW_PMOVE_TRANSLATE][p->n_movable[LW_PMOVE_TRANSLATE]++] = (uint32_t)k;
  p->movable[LW_PMOVE_ROTATE][p->n_movable[LW_PMOVE_ROTATE]++] = (uint32_t)k;
  p->loose[p->n_loose++] = (uint32_t)k;
  p->n_sweep++;
  p->n = k + 1;
  return LW_OK;
}

/* Particle k taken out (a death): the last one takes its index, so the
** arrays stay dense and a state is a function of its particles in order. */
static lw_status take_out(lw_particles *p, size_t k)
{
  size_t last = p->n - 1;
  if (k != last) {
    /* k to the last one's place first: a move that fails changes nothing */
    const double *xl = p->x + 3 * last;
    if (lw_cellgrid_move3(p->grid, (uint32_t)k, xl[0], xl[1], xl[2])) return LW_ENOMEM;
    memcpy(p->x + 3 * k, xl, 3 * sizeof *p->x);
    memcpy(p->q + 4 * k, p->q + 4 * last, 4 * sizeof *p->q);
    memcpy(p->nrm + 3 * k, p->nrm + 3 * last, 3 * sizeof *p->nrm);
    p->pin[k] = p->pin[last];
    if (p->qlen) p->qlen[k] = p->qlen[last];
  }
  lw_cellgrid_remove(p->grid, (uint32_t)last);
  lw_cellgrid_truncate(p->grid, last);
  p->n = last;
  list_free(p);
  return LW_OK;
}

lw_status lw_particles_commit(lw_particles *p, const lw_particles_prop *pr)
{
  if (pr->identity) return LW_OK;
  lw_status s = pr->kind == LW_PMOVE_BIRTH ? append(p, pr) : pr->kind == LW_PMOVE_DEATH ? take_out(p, pr->k)
                                                                                          : commit_move(p, pr);
  if (s) return LW_ENOMEM;
  for (int t = 0; t < LW_PTERM_COUNT; t++) p->term[t] += pr->dterm[t];
  return LW_OK;
}
