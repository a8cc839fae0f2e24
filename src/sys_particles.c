/*
** sys_particles.c -- the oriented-particle system's row (sys_particles.h):
** the particle module behind the seam of system.h.  The module's API maps
** one-to-one onto the row (particles.h), so most members only convert
** between void pointers and the module's types.
*/
#include "linewise/sys_particles.h"

#include <errno.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_math.h>
#include <gsl/gsl_sort_double.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "linewise/output.h"
#include "linewise/particles_draw.h"
#include "linewise/particles_grow.h"
#include "linewise/particles_io.h"

/* steps are kept in lengths and radians; [moves] step_rotate is in degrees;
** births and deaths have none */
static const double move_unit[LW_PMOVE_ALL] = {1.0, M_PI / 180.0, 0.0, 0.0};

/* The coldest rung's section; [init] from and `linewise energy` read it. */
#define SECTION "system particles"

static void *setup_new(const lw_params *p, lw_error *err) { return lw_particles_setup_new(p, err); }

/* The poly weight meets 0 at R with slope 0 (the Lennard-Jones force's step
** there aside, which a quench crosses); the Gaussians have a kink at R, where
** a quench parks pairs and runs out its iterations (1000 particles under
** aniso: 2000 iterations, 6.5 s, where the stall rule stopped at 71 to 78),
** and a hard wall holds what it presses, whose gradient never falls (the
** sheet on a floor: its norm stays at sqrt(127)). */
static int smooth(const lw_params *p)
{
  return p->pt_weight == LW_PWEIGHT_POLY && (p->pt_boundary == LW_PBOUNDARY_NONE || p->pt_alpha_b > 0.0);
}

static void setup_free(void *setup) { lw_particles_setup_free(setup); }

static const char *note(const void *setup) { return ((const lw_particles_setup *)setup)->note; }

/* The particles of the state [init] from names, if any, else the set-up's placement. */
static void *state_new(const void *setup, const lw_params *p, unsigned long seed, lw_error *err)
{
  if (!p->from[0]) {
    const char *key;
    if (lw_particles_check_start(setup, &key, err)) {
      if (err->code == LW_EINPUT) lw_params_blame(p, "particles", key, err);
      return NULL;
    }
    lw_particles *pt = lw_particles_new(setup, seed, &key, err);
    if (!pt && key) lw_params_blame(p, "particles", key, err); /* no room for the pattern, or the points */
    return pt;
  }
  lw_state st;
  lw_particles *s = NULL;
  if (!lw_state_read(&st, p->from, err)) {
    s = lw_particles_get(setup, st.doc, SECTION, err);
    lw_state_clear(&st);
  }
  if (!s && err->code == LW_EINPUT) lw_params_blame(p, "init", "from", err);
  return s;
}

static void *state_copy(const void *state, lw_error *err) { return lw_particles_copy(state, err); }

static void state_free(void *state) { lw_particles_free(state); }

static void moves(const lw_params *p, double *weight, double *step, double *target)
{
  const double w[LW_PMOVE_ALL] = {p->mix_translate, p->mix_rotate, p->pt_birth, p->pt_death};
  const double st[LW_PMOVE_ALL] = {p->step_translate, p->step_rotate, 0.0, 0.0};
  for (int k = 0; k < lw_particles_row(p)->n_moves; k++) {
    weight[k] = w[k];
    step[k] = st[k] * move_unit[k];
    target[k] = p->target_spline;
  }
}

static size_t sweep_size(const void *state) { return lw_particles_sweep_size(state); }

/* With births a sweep is a fixed number of proposals, the start's count, as
** the splines' (sys_splines.c): a sweep as long as the state's count would
** look at the chain at times that depend on its state. */
static size_t sweep_size_grow(const void *state)
{
  const lw_particles_setup *s = ((const lw_particles *)state)->setup;
  return s->n_points + s->count;
}

static double step_max(const void *state, int kind)
{
  return kind < LW_PMOVE_KINDS ? lw_particles_step_max(state, kind) : 0.0;
}

static void *proposal_new(const void *state, lw_error *err) { return lw_particles_prop_new(state, err); }

static void proposal_free(void *prop) { lw_particles_prop_free(prop); }

/* An identity that is not a refusal is a move no particle is free to make
** (all pinned for it; a death with none loose): no proposal (system.h). */
static double none_free(const void *prop, double dE, int *forbidden)
{
  if (!*forbidden && ((const lw_particles_prop *)prop)->identity) *forbidden = LW_PROPOSE_NOTHING;
  return dE;
}

static double propose(void *state, void *prop, int kind, double step, gsl_rng *rng, int *forbidden)
{
  *forbidden = 0;
  const double dE = kind >= LW_PMOVE_KINDS ? lw_particles_propose_grow(state, prop, kind, rng, forbidden)
                                           : lw_particles_propose(state, prop, kind, step, rng, forbidden);
  return none_free(prop, dE, forbidden);
}

static double log_ratio(const void *prop) { return ((const lw_particles_prop *)prop)->log_ratio; }

static lw_status commit(void *state, void *prop) { return lw_particles_commit(state, prop); }

static double total(const void *state) { return lw_particles_total(state); }

_Static_assert(LW_PTERM_COUNT <= LW_SYSTEM_TERMS_MAX, "the particle terms fit the run loop's arrays (system.h)");

static void terms(const void *state, double *term) { lw_particles_terms(state, term); }

static int term_on(const void *setup, int t) { return lw_particles_term_on(setup, t); }

static lw_status refresh(void *state) { return lw_particles_refresh(state, NULL); }

static double energy(const void *setup, const lw_state *st, const char *path, double *term, lw_error *err)
{
  lw_particles *p = lw_particles_get(setup, st->doc, SECTION, err);
  if (!p) return NAN;
  lw_particles_energy(p, term);
  lw_particles_free(p);
  double e = 0.0;
  for (int t = 0; t < LW_PTERM_COUNT; t++) e += term[t];
  return e;
}

/* Domains (domains.h): the page is the grid's box in x and y (particles
** beyond it sit in its edge cells, and in the edge domains, which reach to
** infinity); a move reads and writes within two cell sides of its box. */
static const char *split(const void *state, double page[4], double *reach)
{
  const lw_particles *p = state;
  const lw_particles_setup *s = p->setup;
  page[0] = s->lo[0];
  page[1] = s->lo[1];
  page[2] = s->lo[0] + s->extent[0];
  page[3] = s->lo[1] + s->extent[1];
  *reach = 2.0 / p->grid->inv_h;
  return NULL;
}

static size_t group(const void *state, size_t site, double box[4])
{
  const double *x = ((const lw_particles *)state)->x + 3 * site;
  box[0] = box[2] = x[0];
  box[1] = box[3] = x[1];
  return 1;
}

static double propose_in(void *state, void *prop, int kind, size_t site, double step, gsl_rng *rng, int *forbidden,
                         const double box[4])
{
  *forbidden = 0;
  return none_free(prop, lw_particles_propose_in(state, prop, kind, site, step, rng, forbidden, box), forbidden);
}

static lw_status commit_part(void *state, void *prop) { return lw_particles_commit_part(state, prop); }

static lw_status merge(void *state, void *prop)
{
  lw_particles_merge(state, prop);
  return LW_OK;
}

static size_t sites(const void *state) { return ((const lw_particles *)state)->n; }

static double domain_side(const void *state) { return 0.0; }

static size_t n_coords(const void *state) { return lw_particles_n_coords(state); }

static void get_coords(const void *state, double *x) { lw_particles_get_coords(state, x); }

static lw_status set_coords(void *state, const double *x, lw_error *err)
{
  return lw_particles_set_coords(state, x, err);
}

static double gradient(void *state, double *g, lw_error *err) { return lw_particles_gradient(state, g, err); }

/* A particle that x would take outside the boundary is held where it is, so
** that one particle at a wall does not shorten every other's step (system.h,
** lw_system_hold): its height at a floor (it may still slide and turn), its
** position at a sphere's wall. */
static size_t blocked(void *state, const double *x, unsigned char *held, const unsigned char *changed)
{
  const lw_particles *p = state;
  size_t parts = 0;
  for (size_t i = 0; i < p->n; i++) {
    const size_t c = LW_PARTICLE_COORDS * i;
    if (changed && !(changed[c] | changed[c + 1] | changed[c + 2])) continue;
    if (!lw_particles_outside(p->setup, x + c)) continue;
    if (p->setup->boundary == LW_PBOUNDARY_PLANE) held[c + 2] = 1;
    else memset(held + c, 1, 3);
    parts++;
  }
  return parts;
}

/* Inertia: a particle is a ball of mass rho and diameter r0, I = rho r0^2 / 10
** about every axis (the seed's isotropic tensor), so T = rho/2 |dx/dt|^2 +
** 2 I |dq/dt|^2: a constant diagonal mass, 4 I on each quaternion
** coordinate (particles.h).  A pinned part is held. */
typedef struct {
  size_t n;
  double *m;            /* n: the diagonal */
  unsigned char *held;  /* n */
  double mass, inertia; /* of a particle: rho, I */
  double dashpot, dashpot_angular; /* the pair dampers (dynamics.dashpot*) */
} pt_mass;

static void mass_free(void *mass)
{
  pt_mass *m = mass;
  if (!m) return;
  free(m->m);
  free(m->held);
  free(m);
}

static void *mass_new(const void *state, const lw_params *p, double density, lw_error *err)
{
  const lw_particles *s = state;
  pt_mass *m = calloc(1, sizeof *m);
  size_t n = lw_particles_n_coords(s);
  if (!m || !(m->m = malloc((n ? n : 1) * sizeof *m->m)) || !(m->held = malloc(n ? n : 1))) {
    mass_free(m);
    lw_error_set(err, LW_ENOMEM, "out of memory for the mass matrix of %zu particles", s->n);
    return NULL;
  }
  m->n = n;
  const double r0 = s->setup->pair.r0, inertia = 4.0 * density * r0 * r0 / 10.0;
  m->mass = density;
  m->inertia = inertia / 4.0;
  m->dashpot = p->dyn_dashpot;
  m->dashpot_angular = p->dyn_dashpot_angular;
  for (size_t i = 0; i < n; i++) {
    int rot = i % LW_PARTICLE_COORDS >= 3;
    m->m[i] = rot ? inertia : density;
    m->held[i] = (s->pin[i / LW_PARTICLE_COORDS] & (rot ? LW_PIN_ORIENTATION : LW_PIN_POSITION)) != 0;
  }
  return m;
}

static lw_status mass_at(void *mass, const double *x, lw_error *err) { return LW_OK; }

static void mass_solve(const void *mass, const double *b, double *v)
{
  const pt_mass *m = mass;
  for (size_t i = 0; i < m->n; i++) v[i] = m->held[i] ? 0.0 : b[i] / m->m[i];
}

static void mass_apply(const void *mass, const double *v, double *b)
{
  const pt_mass *m = mass;
  for (size_t i = 0; i < m->n; i++) b[i] = m->m[i] * v[i];
}

static void mass_dx(const void *mass, const double *x, const double *v, double *out)
{
  memset(out, 0, ((const pt_mass *)mass)->n * sizeof *out);
}

static int mass_pinned(const void *mass, size_t i) { return ((const pt_mass *)mass)->held[i]; }

/* The pair dampers (dynamics.dashpot and dashpot_angular; NUMERICS.md,
** "Dampers between neighbours").  Under the force -c w u on i and +c w u
** on j, u = v_i - v_j, the pair's relative velocity obeys du/dt = -c w k u
** with k = 1/m_i + 1/m_j (a held side adds 0), so over a time h it decays
** exactly by exp(-c w k h): an impulse (1 - exp(-c w k h)) u / k moves from
** i to j, keeping the pair's momentum, and the kinetic energy falls by
** (1 - exp(-2 c w k h)) |u|^2 / 2k.  The spins likewise, with the angular
** momentum L = I omega = (pi_q q^-1) / 2 and back pi_q = 2 L q.  Pairs are
** taken one at a time (Shardlow's splitting of dissipative particle
** dynamics), so no step can overshoot and none needs a solve. */
typedef struct {
  const lw_particles *p;
  const pt_mass *m;
  double *pi, h, taken;
} damp_ctx;

/* The impulse out[] that takes the relative velocity ui - uj of a pair with
** inverse masses ki, kj (0 for a held side) through time h of its decay at
** coefficient c and weight w, with the kinetic energy it takes added to the
** context; 0 when both sides are held. */
static int pair_impulse(damp_ctx *a, double c, double w, double ki, double kj, const double ui[3],
                        const double uj[3], double out[3])
{
  double k = ki + kj;
  if (!(k > 0.0)) return 0;
  double f = -expm1(-c * w * k * a->h), u2 = 0.0;
  for (int e = 0; e < 3; e++) {
    double u = ui[e] - uj[e];
    u2 += u * u;
    out[e] = f / k * u;
  }
  a->taken += 0.5 * u2 / k * f * (2.0 - f);
  return 1;
}

static void damp_pair(void *ctx, size_t i, size_t j, const double r[3], double d2)
{
  damp_ctx *a = ctx;
  const lw_particles *p = a->p;
  const pt_mass *m = a->m;
  const double w = lw_ppair_weight(&p->setup->pair, d2, lw_v3_dot(p->nrm + 3 * i, r), lw_v3_dot(p->nrm + 3 * j, r));
  if (!(w > 0.0)) return;
  double *pi = a->pi + LW_PARTICLE_COORDS * i, *pj = a->pi + LW_PARTICLE_COORDS * j, d[3];
  if (m->dashpot > 0.0) {
    double ki = p->pin[i] & LW_PIN_POSITION ? 0.0 : 1.0 / m->mass;
    double kj = p->pin[j] & LW_PIN_POSITION ? 0.0 : 1.0 / m->mass;
    double vi[3] = {ki * pi[0], ki * pi[1], ki * pi[2]}, vj[3] = {kj * pj[0], kj * pj[1], kj * pj[2]};
    if (pair_impulse(a, m->dashpot, w, ki, kj, vi, vj, d))
      for (int e = 0; e < 3; e++) {
        if (ki > 0.0) pi[e] -= d[e];
        if (kj > 0.0) pj[e] += d[e];
      }
  }
  if (m->dashpot_angular > 0.0) {
    const double *qi = p->q + 4 * i, *qj = p->q + 4 * j;
    double ki = p->pin[i] & LW_PIN_ORIENTATION ? 0.0 : 1.0 / m->inertia;
    double kj = p->pin[j] & LW_PIN_ORIENTATION ? 0.0 : 1.0 / m->inertia;
    /* omega = L / I = (pi_q q^-1) / 2I: the vector part (pi_q is on q's tangent) */
    double ci[4] = {qi[0], -qi[1], -qi[2], -qi[3]}, cj[4] = {qj[0], -qj[1], -qj[2], -qj[3]}, li[4], lj[4];
    lw_quat_mul(pi + 3, ci, li);
    lw_quat_mul(pj + 3, cj, lj);
    double wi[3], wj[3];
    for (int e = 0; e < 3; e++) {
      wi[e] = 0.5 * ki * li[e + 1];
      wj[e] = 0.5 * kj * lj[e + 1];
    }
    if (pair_impulse(a, m->dashpot_angular, w, ki, kj, wi, wj, d)) {
      /* L_i -= D, L_j += D: pi_q by 2 D q */
      double dq[4] = {0.0, d[0], d[1], d[2]}, t[4];
      if (ki > 0.0) {
        lw_quat_mul(dq, qi, t);
        for (int e = 0; e < 4; e++) pi[3 + e] -= 2.0 * t[e];
      }
      if (kj > 0.0) {
        lw_quat_mul(dq, qj, t);
        for (int e = 0; e < 4; e++) pj[3 + e] += 2.0 * t[e];
      }
    }
  }
}

static double damp_pairs(const void *state, const void *mass, double h, int reverse, double *pi)
{
  damp_ctx a = {state, mass, pi, h, 0.0};
  if (a.m->dashpot > 0.0 || a.m->dashpot_angular > 0.0) lw_particles_each_pair(state, reverse, damp_pair, &a);
  return a.taken;
}

static void constrain(const void *state, const double *from, double *x, double *pi)
{
  lw_particles_constrain(state, from, x, pi);
}

static lw_status save(const void *state, lw_ckpt_writer *w, const char *section, lw_error *err)
{
  lw_particles_put(w, section, state);
  return LW_OK;
}

static void *load(const void *setup, lw_state *st, const char *section, const char *path, lw_error *err)
{
  return lw_particles_get(setup, st->doc, section, err);
}

static void set_terms(void *state, const double *term)
{
  memcpy(((lw_particles *)state)->term, term, LW_PTERM_COUNT * sizeof *term);
}

static lw_status draw(void *state, const lw_params *p, const char *dir, long sweep, lw_error *err)
{
  if (sweep == LW_DRAW_START) return LW_OK;
  if (sweep == LW_DRAW_FINAL) return lw_particles_draw(state, dir, err);
  char path[LW_PATH_MAX + 64];
  if (lw_output_subdir(dir, "frames", path, sizeof path, err)) return err->code;
  size_t n = strlen(path);
  snprintf(path + n, sizeof path - n, "/frame-%06ld.png", sweep);
  return lw_particles_write_png(state, path, 1, err);
}

static size_t pinned(const lw_particles *p)
{
  size_t k = 0;
  for (size_t i = 0; i < p->n; i++) k += p->pin[i] != 0;
  return k;
}

static void summary(const void *state, lw_json *j)
{
  const lw_particles *p = state;
  lw_json_key(j, "particles");
  lw_json_int(j, (long long)p->n);
  lw_json_key(j, "pinned");
  lw_json_int(j, (long long)pinned(p));
}

/* The eigenvalues of the symmetric 3 x 3 matrix m (destroyed), ascending;
** NaN when GSL's workspace cannot be had. */
static void eigenvalues3(double m[9], double ev[3])
{
  gsl_eigen_symm_workspace *w = gsl_eigen_symm_alloc(3);
  if (!w) {
    ev[0] = ev[1] = ev[2] = NAN;
    return;
  }
  gsl_matrix_view mv = gsl_matrix_view_array(m, 3, 3);
  gsl_vector_view vv = gsl_vector_view_array(ev, 3);
  gsl_eigen_symm(&mv.matrix, &vv.vector, w);
  gsl_eigen_symm_free(w);
  gsl_sort(ev, 1, 3);
}

/* The observables (docs/FORMATS.md, "trace.csv"): the count; the squared
** radius of gyration (the trace of the positions' covariance); the rms
** distance from the best plane through them (the root of its least
** eigenvalue); and the order of the normals, S = (3 lambda - 1) / 2 with
** lambda the greatest eigenvalue of the mean of n n^T: 1 when every normal
** is parallel or opposite to one axis, 0 for normals spread evenly. */
static const char *const observable_names[] = {"count", "rg2", "plane_rms", "normal_order"};

static void observe(const void *state, double *out)
{
  const lw_particles *p = state;
  out[0] = (double)p->n;
  if (!p->n) {
    out[1] = out[2] = out[3] = NAN;
    return;
  }
  double c[3] = {0.0, 0.0, 0.0}, cov[9] = {0.0}, nn[9] = {0.0}, ev[3];
  for (size_t i = 0; i < p->n; i++)
    for (int a = 0; a < 3; a++) c[a] += p->x[3 * i + a] / (double)p->n;
  for (size_t i = 0; i < p->n; i++) {
    const double *x = p->x + 3 * i, *n = p->nrm + 3 * i;
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++) {
        cov[3 * a + b] += (x[a] - c[a]) * (x[b] - c[b]) / (double)p->n;
        nn[3 * a + b] += n[a] * n[b] / (double)p->n;
      }
  }
  out[1] = cov[0] + cov[4] + cov[8];
  eigenvalues3(cov, ev);
  out[2] = sqrt(fmax(ev[0], 0.0));
  eigenvalues3(nn, ev);
  out[3] = 1.5 * ev[2] - 0.5;
}

/* A sample of the configuration (system.h): each particle's position,
** unit quaternion (its normal is the third column of the rotation) and pin. */
static void write_sample(const void *state, FILE *f)
{
  const lw_particles *p = state;
  fputs("particle,x,y,z,qw,qx,qy,qz,pinned\n", f);
  for (size_t i = 0; i < p->n; i++) {
    const double *x = p->x + 3 * i, *q = p->q + 4 * i;
    fprintf(f, "%zu,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d\n", i, x[0], x[1], x[2], q[0], q[1], q[2], q[3],
            p->pin[i] != 0);
  }
}

static void describe(const void *state, int what, char *buf, size_t n)
{
  const lw_particles *p = state;
  if (what == LW_DESCRIBE_SIZE) snprintf(buf, n, "%zu particles, %zu pinned", p->n, pinned(p));
  else if (what == LW_DESCRIBE_FORBIDDEN) snprintf(buf, n, "a particle on or past the boundary");
  else if (n) buf[0] = '\0';
}

/* The particles' load is particles.gravity and their pins particles.pinned,
** not the dynamics' keys; only they have dampers between neighbours; births
** and deaths are Monte Carlo's moves. */
static const char *const keys[] = {"init.from", "particles.*", NULL};
static const char *const keys_dynamics[] = {"dynamics.dashpot", "dynamics.dashpot_angular", NULL};
static const char *const keys_metropolis[] = {"moves.translate", "moves.rotate", "moves.step_translate",
                                              "moves.step_rotate", "moves.target_spline", "particles.birth",
                                              "particles.death", "particles.chem", "particles.max_count",
                                              "anneal.domains", NULL};

/* Keys the scene's other settings leave idle (system.h). */
static int idle(const lw_params *p, lw_idle_rule rule[LW_IDLE_RULES_MAX])
{
  static const char *const births[] = {"particles.max_count", NULL}, *const sigma[] = {"particles.sigma", NULL},
                           *const sigma_normal[] = {"particles.sigma_normal", NULL},
                           *const plane[] = {"particles.boundary_z", NULL},
                           *const sphere[] = {"particles.boundary_radius", NULL},
                           *const wall[] = {"particles.alpha_b", NULL}, *const pinned[] = {"particles.pinned", NULL};
  int n = 0;
  rule[n++] = (lw_idle_rule){births, p->pt_birth == 0.0 && p->pt_death == 0.0, "no particles.birth or death"};
  rule[n++] = (lw_idle_rule){sigma, p->pt_weight == LW_PWEIGHT_POLY, "particles.weight = poly"};
  rule[n++] = (lw_idle_rule){sigma_normal, p->pt_weight != LW_PWEIGHT_ANISO, "particles.weight is not aniso"};
  rule[n++] = (lw_idle_rule){plane, p->pt_boundary != LW_PBOUNDARY_PLANE, "particles.boundary is not plane"};
  rule[n++] = (lw_idle_rule){sphere, p->pt_boundary != LW_PBOUNDARY_SPHERE, "particles.boundary is not sphere"};
  rule[n++] = (lw_idle_rule){wall, p->pt_boundary == LW_PBOUNDARY_NONE, "particles.boundary = none"};
  rule[n++] = (lw_idle_rule){pinned, !p->pt_points[0], "no particles.points"};
  return n;
}

/* The rows differ only in their move kinds (sys_particles.h). */
#define PARTICLES_ROW \
    .quench_converges = smooth, \
    .keys = keys, \
    .keys_dynamics = keys_dynamics, \
    .keys_metropolis = keys_metropolis, \
    .n_observables = (int)(sizeof observable_names / sizeof observable_names[0]), \
    .observable_names = observable_names, \
    .observe = observe, \
    .write_sample = write_sample, \
    .move_names = lw_particles_move_names, \
    .move_unit = move_unit, \
    .n_terms = LW_PTERM_COUNT, \
    .term_names = lw_pterm_names, \
    .setup_new = setup_new, \
    .setup_free = setup_free, \
    .note = note, \
    .state_new = state_new, \
    .state_copy = state_copy, \
    .state_free = state_free, \
    .moves = moves, \
    .step_max = step_max, \
    .proposal_new = proposal_new, \
    .proposal_free = proposal_free, \
    .propose = propose, \
    .commit = commit, \
    .total = total, \
    .terms = terms, \
    .term_on = term_on, \
    .refresh = refresh, \
    .energy = energy, \
    .save = save, \
    .load = load, \
    .set_terms = set_terms, \
    .variant = lw_particles_row, \
    .idle = idle, \
    .files = "final.ply, final.png", \
    .draw = draw, \
    .summary = summary, \
    .describe = describe, \
    .n_coords = n_coords, \
    .get_coords = get_coords, \
    .set_coords = set_coords, \
    .gradient = gradient, \
    .blocked = blocked, \
    .mass_new = mass_new, \
    .mass_free = mass_free, \
    .mass_at = mass_at, \
    .mass_solve = mass_solve, \
    .mass_apply = mass_apply, \
    .mass_dx = mass_dx, \
    .mass_pinned = mass_pinned, \
    .constrain = constrain, \
    .damp_pairs = damp_pairs, \
    .split = split, \
    .group = group, \
    .propose_in = propose_in, \
    .commit_part = commit_part, \
    .merge = merge, \
    .sites = sites, \
    .domain_side = domain_side,

const lw_system_type lw_system_particles = {
    .name = "particles",
    .n_moves = LW_PMOVE_KINDS,
    .sweep_size = sweep_size,
    PARTICLES_ROW
};

/* The same system with births and deaths (particles_grow.h). */
const lw_system_type lw_system_particles_grow = {
    .name = "particles",
    .n_moves = LW_PMOVE_ALL,
    .sweep_size = sweep_size_grow,
    .log_ratio = log_ratio,
    .n_domain_moves = LW_PMOVE_KINDS,
    PARTICLES_ROW
};

const lw_system_type *lw_particles_row(const lw_params *p)
{
  return p->pt_birth > 0.0 || p->pt_death > 0.0 ? &lw_system_particles_grow : &lw_system_particles;
}

