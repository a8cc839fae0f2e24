/*
** sys_nurbs.c -- the D-NURBS system's row (sys_nurbs.h): at given weights
** the energy is quadratic, E = 1/2 P'K(w)P - f(w)'P, so a point move's dE
** is local (the band of K) and, with frozen weights, the dynamics is linear
** with a constant mass matrix.  Free weights (s = log w) make K, f and the
** mass matrix functions of the state: they are assembled again whenever
** the weights change.
*/
#include "linewise/sys_nurbs.h"

#include <cairo.h>
#include <errno.h>
#include <gsl/gsl_integration.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "linewise/driver.h"
#include "linewise/number.h"
#include "linewise/output.h"
#include "linewise/spline.h"

static const char *const move_names[2] = {"point", "weight"};
static const double move_unit[2] = {1.0, 1.0};
enum { K_POINT, K_WEIGHT };
static const char *const term_names[3] = {"elastic", "gravity", "weights"};
enum { T_ELASTIC, T_GRAVITY, T_WEIGHTS, N_TERMS };
_Static_assert(N_TERMS <= LW_SYSTEM_TERMS_MAX, "the curve's terms fit the run loop's arrays (system.h)");

#define SECTION "system nurbs"

/* ---- set-up --------------------------------------------------------------- */

static void setup_free(void *setup)
{
  lw_nurbs_setup *su = setup;
  if (!su) return;
  lw_nurbs_free(su->curve);
  lw_dnurbs_free(su->mat);
  free(su->pin);
  free(su->f);
  free(su->free_idx);
  free(su->s0);
  free(su);
}

/* The numbers in the text of [nurbs] key (malloc'ed; *n how many), blaming the key. */
static double *numbers(const lw_params *p, const char *key, const char *text, size_t *n, lw_error *err)
{
  int count = lw_number_list(text, p->of_run ? 1 : 2, NULL, 0);
  if (count < 0) {
    lw_error_set(err, LW_EINPUT, "expected numbers separated by blanks or commas, got '%.60s'%s", text,
                 lw_number_list_hint(count));
    lw_params_blame(p, "nurbs", key, err);
    return NULL;
  }
  double *v = malloc(((size_t)count + 1) * sizeof *v);
  if (!v) {
    lw_error_set(err, LW_ENOMEM, "out of memory for %d numbers", count);
    return NULL;
  }
  lw_number_list(text, 1, v, count);
  *n = (size_t)count;
  return v;
}

/* Appends v to the array *a of *n (capacity *cap). */
static int push(double **a, size_t *n, size_t *cap, double v)
{
  if (*n == *cap) {
    size_t c = *cap ? 2 * *cap : 64;
    double *b = realloc(*a, c * sizeof *b);
    if (!b) return 0;
    *a = b;
    *cap = c;
  }
  (*a)[(*n)++] = v;
  return 1;
}

/* The control points (and weights, if the lines have three numbers) of
** nurbs.file; messages name the file and line, blamed on the key. */
static lw_status read_file(const lw_params *p, double **P, size_t *np, double **w, size_t *nw, lw_error *err)
{
  char dir[LW_PATH_MAX], path[2 * LW_PATH_MAX + 2], *line = NULL;
  lw_path_dir(dir, sizeof dir, p->file);
  lw_path_join(path, sizeof path, dir, p->nb_file);
  if (lw_text_plain_file(path, err)) return lw_params_blame(p, "nurbs", "file", err);
  FILE *f = fopen(path, "r");
  if (!f) {
    lw_error_set(err, LW_EINPUT, "%s: cannot read: %s", path, strerror(errno));
    return lw_params_blame(p, "nurbs", "file", err);
  }
  size_t cap_p = 0, cap_w = 0, cap = 0;
  long lineno = 0, len;
  int per = 0;
  lw_status st = LW_OK;
  while ((len = lw_text_next_line(f, &line, &cap, &lineno)) >= 0) {
    line[strcspn(line, "#")] = '\0';
    double v[4];
    /* commas between the numbers too, as a spreadsheet's CSV writes them */
    int k = lw_number_list(line, 2, v, 4);
    if (k == 0) continue;
    if ((k != 2 && k != 3) || (per && k != per) || (k == 3 && !(v[2] > 0.0))) {
      char unseen[96]; /* (a minus sign or a no-break space: the file is found, so the key's blame says none) */
      lw_error_set(err, LW_EINPUT, "%s:%ld: expected %s, got '%.60s'%s", path, lineno,
                   per == 2 ? "'x y' like the lines before" : per == 3 ? "'x y w' (w > 0) like the lines before"
                                                                      : "'x y' or 'x y w' (w > 0)", line,
                   k <= -2 ? lw_number_list_hint(k) : lw_text_unseen_char(line, unseen, sizeof unseen));
      st = lw_params_blame(p, "nurbs", "file", err);
      break;
    }
    per = k;
    if (!push(P, np, &cap_p, v[0]) || !push(P, np, &cap_p, v[1]) || (k == 3 && !push(w, nw, &cap_w, v[2]))) {
      st = lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
      break;
    }
  }
  if (!st && len == -2) {
    if (errno == ENOMEM) st = lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
    else {
      lw_error_set(err, LW_EINPUT, "%s:%ld: %s", path, lineno + (ferror(f) != 0),
                   ferror(f) ? "cannot read" : LW_TEXT_NUL_LINE);
      st = lw_params_blame(p, "nurbs", "file", err);
    }
  }
  free(line);
  fclose(f);
  return st;
}

static lw_nurbs *curve_of(const lw_params *p, lw_error *err)
{
  size_t np = 0, nw = 0, nk = 0, k = (size_t)p->nb_order;
  double *P = NULL, *w = NULL, *knot = NULL;
  lw_nurbs *c = NULL;
  if (p->nb_file[0]) {
    if (read_file(p, &P, &np, &w, &nw, err)) goto out;
  } else if (!(P = numbers(p, "points", p->nb_points, &np, err)) ||
             !(w = numbers(p, "weights", p->nb_weights, &nw, err))) {
    goto out;
  }
  size_t n = np / 2;
  if (np % 2 || n < k) {
    if (p->nb_file[0]) /* (its lines are checked one by one: too few of them, or none) */
      lw_error_set(err, LW_EINPUT, "%s holds %zu control point%s: expected lines 'x y' or 'x y w' of at least "
                   "order = %zu", p->nb_file, n, n == 1 ? "" : "s", k);
    else
      lw_error_set(err, LW_EINPUT, "expected x y pairs of at least order = %zu control points, got %zu numbers", k,
                   np);
    lw_params_blame(p, "nurbs", p->nb_file[0] ? "file" : "points", err);
    goto out;
  }
  if (nw && nw != n) {
    lw_error_set(err, LW_EINPUT, "expected one weight per control point (%zu), got %zu", n, nw);
    lw_params_blame(p, "nurbs", "weights", err);
    goto out;
  }
  /* the checks of 2026-12-05 leave a run's own values as they were */
  const int file = p->nb_file[0] != '\0', kept_w = lw_params_kept(p, "nurbs", file ? "file" : "weights"),
            kept_p = lw_params_kept(p, "nurbs", file ? "file" : "points");
  size_t lo = 0, hi = 0;
  for (size_t i = 0; i < nw; i++) {
    if (!(w[i] > 0.0)) {
      lw_error_set(err, LW_EINPUT, "weight %zu is %g: weights must be > 0 (they count from 0)", i, w[i]);
      lw_params_blame(p, "nurbs", file ? "file" : "weights", err);
      goto out;
    }
    lo = w[i] < w[lo] ? i : lo;
    hi = w[i] > w[hi] ? i : hi;
  }
  /* (1e200 ended in "a D-NURBS matrix ... is not positive definite", 1e-50
  ** in an unstable motion at any dt, 1e8 in a final.svg 0.29 from a curve
  ** of size 1: the matrices and the fit lose their digits) */
  if (nw && !kept_w && !(w[hi] <= LW_NURBS_WEIGHT_SPREAD * w[lo])) {
    lw_error_set(err, LW_EINPUT, "weights %zu (%.10g) and %zu (%.10g) are %.10g apart: expected at most a factor of "
                 "%g between the largest and the smallest (they count from 0)", hi, w[hi], lo, w[lo], w[hi] / w[lo],
                 LW_NURBS_WEIGHT_SPREAD);
    lw_params_blame(p, "nurbs", file ? "file" : "weights", err);
    goto out;
  }
  /* (a point at 1e100 drew for ever: final.svg's pieces could not get within
  ** svg_tolerance of a curve whose rounding alone is larger) */
  for (size_t i = 0; i < np && !kept_p; i++)
    if (!(fabs(P[i]) <= LW_STATE_COORD_MAX)) {
      lw_error_set(err, LW_EINPUT, "control point %zu has %c = %.10g: expected coordinates within +-%g (they count "
                   "from 0)", i / 2, i % 2 ? 'y' : 'x', P[i], LW_STATE_COORD_MAX);
      lw_params_blame(p, "nurbs", file ? "file" : "points", err);
      goto out;
    }
  if (!(knot = numbers(p, "knots", p->nb_knots, &nk, err))) goto out;
  if (!nk) {
    /* open uniform: k zeros, n - k inner knots, k ones */
    free(knot);
    if (!(knot = malloc((n + k) * sizeof *knot))) {
      lw_error_set(err, LW_ENOMEM, "out of memory");
      goto out;
    }
    for (size_t i = 0; i < n + k; i++)
      knot[i] = i < k ? 0.0 : i >= n ? 1.0 : (double)(i - k + 1) / (double)(n - k + 1);
    nk = n + k;
  }
  if (lw_nurbs_check_knots(p->nb_order, n, knot, nk, err) ||
      (!lw_params_kept(p, "nurbs", "knots") && lw_nurbs_check_knot_scale(p->nb_order, n, knot, err))) {
    lw_params_blame(p, "nurbs", "knots", err);
    goto out;
  }
  c = lw_nurbs_new(p->nb_order, n, knot, P, nw ? w : NULL, err);
  if (c && lw_nurbs_refine(c, p->nb_elevate, p->nb_refine, err)) {
    lw_params_blame(p, "nurbs", p->nb_order + p->nb_elevate > LW_NURBS_ORDER_MAX ? "elevate" : "refine", err);
    lw_nurbs_free(c);
    c = NULL;
  }
out:
  free(P), free(w), free(knot);
  return c;
}

lw_nurbs_setup *lw_nurbs_setup_new(const lw_params *p, lw_nurbs *curve, lw_error *err)
{
  if (!curve) return NULL;
  lw_nurbs_setup *su = calloc(1, sizeof *su);
  if (!su) {
    lw_nurbs_free(curve);
    lw_error_set(err, LW_ENOMEM, "out of memory for a scene");
    return NULL;
  }
  su->curve = curve;
  /* (a run begun before the key resumes on the pieces its energy had) */
  curve->pieces = p->run_written && !lw_params_line(p, "nurbs", "pieces") ? 1 : p->nb_pieces;
  size_t n = su->curve->n;
  if (2 * (size_t)p->nb_fixed > n) {
    lw_error_set(err, LW_EINPUT, "expected at most half of the %zu control points, got %d at each end", n,
                 p->nb_fixed);
    lw_params_blame(p, "nurbs", "fixed", err);
    goto fail;
  }
  /* free weights: the coordinates are s = log w, and the curve that K, M1
  ** and b are assembled on has w = exp(s) to the last bit, as every state */
  su->free_weights = p->nb_free_weights;
  if (su->free_weights && p->nb_fixed < 1) {
    lw_error_set(err, LW_EINPUT, "free weights need nurbs.fixed >= 1 (the held end weights fix the scale of the "
                 "weights, which leaves the curve unchanged), got fixed = 0");
    lw_params_blame(p, "nurbs", "free_weights", err);
    goto fail;
  }
  if (!(su->s0 = malloc(n * sizeof *su->s0))) {
    lw_error_set(err, LW_ENOMEM, "out of memory for a scene");
    goto fail;
  }
  for (size_t i = 0; i < n; i++) {
    su->s0[i] = log(curve->w[i]);
    if (su->free_weights) curve->w[i] = exp(su->s0[i]);
  }
  su->weight_inertia = p->nb_weight_inertia;
  su->weight_stiffness = p->nb_weight_stiffness;
  su->mug[0] = p->dyn_rho * p->dyn_gravity_x;
  su->mug[1] = p->dyn_rho * p->dyn_gravity_y;
  /* fewer Gauss points than control points leave the matrices singular:
  ** nurbs.gauss = 1 ran into a stability limit of 1e-9 s, blaming dt, and
  ** under Monte Carlo the energy would not see every motion */
  size_t spans = 0;
  for (size_t s = (size_t)curve->order - 1; s < n; s++) spans += curve->knot[s + 1] > curve->knot[s];
  if ((size_t)p->nb_gauss * spans < n && !lw_params_kept(p, "nurbs", "gauss")) {
    lw_error_set(err, LW_EINPUT, "expected at least %zu points a knot span: %zu spans of %zu control points, and "
                 "with fewer Gauss points than control points the quadrature of the energy (and of the mass, under "
                 "the dynamics) misses some motions, which then cost nothing (as many as the order, %d, make "
                 "the matrices exact)", (n + spans - 1) / spans, spans, n, curve->order);
    lw_params_blame(p, "nurbs", "gauss", err);
    goto fail;
  }
  if (!(su->mat = lw_dnurbs_new(su->curve, p->nb_alpha, p->nb_beta, p->nb_gauss, err))) goto fail;
  su->pin = calloc(n, 1);
  su->f = calloc(2 * n, sizeof *su->f);
  su->free_idx = calloc(n, sizeof *su->free_idx);
  if (!su->pin || !su->f || !su->free_idx) {
    lw_error_set(err, LW_ENOMEM, "out of memory for a scene");
    goto fail;
  }
  for (size_t i = 0; i < (size_t)p->nb_fixed; i++) su->pin[i] = su->pin[n - 1 - i] = 1;
  for (size_t i = 0; i < n; i++) {
    su->f[2 * i] = su->mug[0] * su->mat->b[i];
    su->f[2 * i + 1] = su->mug[1] * su->mat->b[i];
    if (!su->pin[i]) su->free_idx[su->n_free++] = i;
  }
  /* the frames' view: the control polygon's box, grown by half its larger side */
  double *v = su->view, *P = su->curve->P;
  v[0] = v[2] = P[0];
  v[1] = v[3] = P[1];
  for (size_t i = 1; i < n; i++) {
    v[0] = fmin(v[0], P[2 * i]), v[2] = fmax(v[2], P[2 * i]);
    v[1] = fmin(v[1], P[2 * i + 1]), v[3] = fmax(v[3], P[2 * i + 1]);
  }
  double grow = 0.5 * fmax(fmax(v[2] - v[0], v[3] - v[1]), 1e-9);
  v[0] -= grow, v[1] -= grow, v[2] += grow, v[3] += grow;
  su->step_max = v[2] - v[0];
  su->tolerance = p->nb_svg_tolerance;
  su->png_scale = p->nb_png_scale;
  return su;
fail:
  setup_free(su);
  return NULL;
}

static void *setup_new(const lw_params *p, lw_error *err) { return lw_nurbs_setup_new(p, curve_of(p, err), err); }

static const char *note(const void *setup) { return ""; }

/* ---- state ---------------------------------------------------------------- */

static void state_free(void *state)
{
  lw_nurbs_state *s = state;
  if (!s) return;
  lw_nurbs_free(s->c);
  lw_dnurbs_free(s->own);
  free(s->s);
  free(s->f);
  free(s);
}

/* K and f at the present weights (with free weights, from scratch: they
** depend on every weight near a changed one). */
static lw_status rebuild(lw_nurbs_state *s, lw_error *err)
{
  const lw_nurbs_setup *su = s->su;
  size_t n = s->c->n;
  if (s->own) {
    lw_status st = lw_dnurbs_assemble(s->own, s->c, err);
    if (st) return st;
    for (size_t i = 0; i < n; i++) {
      s->f[2 * i] = su->mug[0] * s->own->b[i];
      s->f[2 * i + 1] = su->mug[1] * s->own->b[i];
    }
  }
  return LW_OK;
}

/* The terms from scratch (the elastic one over differences, lw_band_energy). */
static lw_status recompute(lw_nurbs_state *s, lw_error *err)
{
  lw_status st = rebuild(s, err);
  if (st) return st;
  const size_t n = s->c->n;
  s->term[T_ELASTIC] = lw_band_energy(s->mat->K, n, s->mat->k, s->c->P);
  s->term[T_GRAVITY] = 0.0;
  for (size_t i = 0; i < 2 * n; i++) s->term[T_GRAVITY] -= s->f[i] * s->c->P[i];
  s->term[T_WEIGHTS] = 0.0;
  for (size_t i = 0; s->s && i < s->c->n; i++) s->term[T_WEIGHTS] += 0.5 * s->su->weight_stiffness * s->s[i] * s->s[i];
  return LW_OK;
}

/* A state on control points P (2 n numbers; NULL: the set-up's) and, with
** free weights, log weights lw (n; NULL: the set-up's). */
static lw_nurbs_state *state_at(const lw_nurbs_setup *su, const double *P, const double *lw, lw_error *err)
{
  size_t n = su->curve->n;
  lw_nurbs_state *s = calloc(1, sizeof *s);
  if (!s || !(s->c = lw_nurbs_copy(su->curve, err)) ||
      !(s->f = malloc(2 * n * sizeof *s->f)) ||
      (su->free_weights && (!(s->s = malloc(n * sizeof *s->s)) ||
                            !(s->own = lw_dnurbs_new(s->c, su->mat->alpha, su->mat->beta, su->mat->gauss, err))))) {
    state_free(s);
    lw_error_set(err, LW_ENOMEM, "out of memory for a NURBS state");
    return NULL;
  }
  s->su = su;
  s->mat = s->own ? s->own : su->mat;
  memcpy(s->f, su->f, 2 * n * sizeof *s->f);
  if (P) memcpy(s->c->P, P, 2 * n * sizeof *P);
  if (s->s) {
    memcpy(s->s, lw ? lw : su->s0, n * sizeof *s->s);
    for (size_t i = 0; i < n; i++) s->c->w[i] = exp(s->s[i]);
  }
  if (recompute(s, err)) {
    state_free(s);
    return NULL;
  }
  return s;
}

/* The control points (and log weights) of a saved state's section;
** messages name path. */
static lw_nurbs_state *state_get(const lw_nurbs_setup *su, lw_ckpt *doc, const char *section, lw_error *err)
{
  const char *path = lw_ckpt_path(doc);
  if (!lw_ckpt_has(doc, section))
    return lw_state_missing_section(doc, section, err), NULL;
  size_t n = su->curve->n, i = 0, j = 0, pos = 0;
  long count;
  if (lw_ckpt_whole(doc, section, "count", &count, 1, 1L << 53, 1, err) || lw_ckpt_single(doc, section, "count", err))
    return NULL;
  if (count != (long)n) {
    int at = 0;
    lw_ckpt_text(doc, section, "count", &at);
    return lw_error_set(err, LW_EINPUT, "%s:%d: [%s] count: %ld control points, but the scene's curve has %zu (its "
                        "points refined by nurbs.elevate and nurbs.refine): a state is read with the scene it was "
                        "run with", path, at, section, count, n), NULL;
  }
  double *P = malloc(3 * n * sizeof *P), *lw = P + 2 * n;
  if (!P) return lw_error_set(err, LW_ENOMEM, "out of memory"), NULL;
  const char *key, *val;
  int line;
  lw_nurbs_state *s = NULL;
  while (lw_ckpt_next(doc, section, &pos, &key, &val, &line)) {
    if (!strcmp(key, "count")) continue;
    double v[3];
    if (!strcmp(key, "log_weight")) {
      if (!su->free_weights || j == n || lw_number_list(val, 0, v, 2) != 1) {
        lw_error_set(err, LW_EINPUT, "%s:%d: [%s] log_weight: expected %s, got '%.80s'", path, line, section,
                     !su->free_weights ? "no log weights (nurbs.free_weights = 0 freezes the scene's weights)"
                     : j == n          ? "nothing (count is the number of control points)"
                                       : "one number, log w", val);
        goto out;
      }
      if (su->pin[j] && v[0] != su->s0[j]) {
        lw_error_set(err, LW_EINPUT, "%s:%d: [%s] log_weight: control point %zu is held by nurbs.fixed with log "
                     "weight %.17g, got %.17g", path, line, section, j, su->s0[j], v[0]);
        goto out;
      }
      lw[j++] = v[0];
      continue;
    }
    if (i == n || strcmp(key, "point") || lw_number_list(val, 0, v, 3) != 2) {
      lw_error_set(err, LW_EINPUT, "%s:%d: [%s] %s: expected %s, got '%s = %.80s'", path, line, section,
                   i == n ? "after the last point" : "point",
                   i == n ? "nothing (count is the number of control points)" : "'point = x y' (2 numbers)", key, val);
      goto out;
    }
    if (su->pin[i] && (v[0] != su->curve->P[2 * i] || v[1] != su->curve->P[2 * i + 1])) {
      lw_error_set(err, LW_EINPUT, "%s:%d: [%s] point: control point %zu is held by nurbs.fixed at (%.17g, %.17g), "
                   "got (%.17g, %.17g)", path, line, section, i, su->curve->P[2 * i], su->curve->P[2 * i + 1], v[0], v[1]);
      goto out;
    }
    P[2 * i] = v[0];
    P[2 * i + 1] = v[1];
    i++;
  }
  if (i < n || (j && j < n)) {
    lw_error_set(err, LW_EINPUT, "%s: [%s]: count = %zu, but %zu %s lines%s", path, section, n, i < n ? i : j,
                 i < n ? "point" : "log_weight", lw_ckpt_cut_hint(doc, section));
    goto out;
  }
  /* a state of a frozen-weight run starts free weights at the scene's */
  s = state_at(su, P, j ? lw : NULL, err);
out:
  free(P);
  return s;
}

static void *state_new(const void *setup, const lw_params *p, unsigned long seed, lw_error *err)
{
  if (!p->from[0]) return state_at(setup, NULL, NULL, err);
  lw_state st;
  lw_nurbs_state *s = NULL;
  if (!lw_state_read(&st, p->from, err)) {
    s = state_get(setup, st.doc, SECTION, err);
    lw_state_clear(&st);
  }
  if (!s && err->code == LW_EINPUT) lw_params_blame(p, "init", "from", err);
  return s;
}

static void *state_copy(const void *state, lw_error *err)
{
  const lw_nurbs_state *s = state;
  lw_nurbs_state *c = state_at(s->su, s->c->P, s->s, err);
  if (c) memcpy(c->term, s->term, sizeof c->term);
  return c;
}

/* ---- Monte Carlo ---------------------------------------------------------- */

typedef struct {
  int kind;
  size_t i;
  double d[2];  /* point: the step in x y; weight: d[0] the step in s */
  double de[N_TERMS];
  int nomem;           /* a weight move's Gauss table could not be had */
} nb_prop;

static void moves(const lw_params *p, double *weight, double *step, double *target)
{
  weight[K_POINT] = 1.0;
  step[K_POINT] = p->step_point;
  weight[K_WEIGHT] = p->nb_free_weights ? 1.0 : 0.0;
  step[K_WEIGHT] = p->nb_step_weight;
  target[K_POINT] = target[K_WEIGHT] = p->target;
}

static size_t sweep_size(const void *state) { return ((const lw_nurbs_state *)state)->su->n_free; }

/* a step in s of 2 multiplies a weight by up to e^2 */
static double step_max(const void *state, int kind)
{
  return kind == K_WEIGHT ? 2.0 : ((const lw_nurbs_state *)state)->su->step_max;
}

static void *proposal_new(const void *state, lw_error *err)
{
  nb_prop *p = calloc(1, sizeof *p);
  if (!p) lw_error_set(err, LW_ENOMEM, "out of memory");
  return p;
}

static void proposal_free(void *prop) { free(prop); }

/* dE of w_j exp(d): the energy of the k spans around j at both weights
** (the weight is put back: the state is unchanged). NaN when out of memory. */
static double propose_weight(lw_nurbs_state *s, nb_prop *q)
{
  const lw_nurbs_setup *su = s->su;
  const lw_dnurbs *m = s->mat;
  double e0[2], e1[2], w = s->c->w[q->i];
  lw_error err = {0};
  lw_dnurbs_energy_near(s->c, m->alpha, m->beta, su->mug, m->gauss, q->i, e0, &err);
  s->c->w[q->i] = exp(s->s[q->i] + q->d[0]);
  lw_dnurbs_energy_near(s->c, m->alpha, m->beta, su->mug, m->gauss, q->i, e1, &err);
  s->c->w[q->i] = w;
  q->nomem = err.code == LW_ENOMEM;
  if (err.code) return NAN;
  double s0 = s->s[q->i], s1 = s0 + q->d[0];
  q->de[T_ELASTIC] = e1[0] - e0[0];
  q->de[T_GRAVITY] = e1[1] - e0[1];
  q->de[T_WEIGHTS] = 0.5 * su->weight_stiffness * (s1 * s1 - s0 * s0);
  return q->de[T_ELASTIC] + q->de[T_GRAVITY] + q->de[T_WEIGHTS];
}

/* (K P)_i from the band, summed afresh: a running K P, updated by each
** move, carried the rounding of the moves so far, which a resumed run
** (K P from scratch) did not share, and its energies came out a few ulps
** apart.  K's rows sum to 0 (the basis sums to 1, so a translation costs
** nothing), so the row is summed over P_j - P_i: over P itself, terms of
** |K| |P| cancel to a force (at nurbs.refine = 200, K ~ 5e9 and P ~ 5, so
** 1e-5 of rounding in a row).  K(i, i + d) = K[i k + d],
** K(i, i - d) = K[(i - d) k + d]. */
static void band_row(const lw_dnurbs *m, const double *P, size_t i, double r[2])
{
  const size_t n = m->n, k = (size_t)m->k;
  const double x = P[2 * i], y = P[2 * i + 1];
  r[0] = r[1] = 0.0;
  for (size_t d = 1; d < k; d++) {
    if (i + d < n) {
      r[0] += m->K[i * k + d] * (P[2 * (i + d)] - x);
      r[1] += m->K[i * k + d] * (P[2 * (i + d) + 1] - y);
    }
    if (i >= d) {
      r[0] += m->K[(i - d) * k + d] * (P[2 * (i - d)] - x);
      r[1] += m->K[(i - d) * k + d] * (P[2 * (i - d) + 1] - y);
    }
  }
}

/* point: dE of P_i + d = (K P)_i . d + 1/2 K_ii |d|^2 - f_i . d, from the band. */
static double propose(void *state, void *prop, int kind, double step, gsl_rng *rng, int *forbidden)
{
  lw_nurbs_state *s = state;
  const lw_nurbs_setup *su = s->su;
  nb_prop *q = prop;
  *forbidden = 0;
  q->kind = kind;
  q->i = su->free_idx[gsl_rng_uniform_int(rng, su->n_free)];
  q->d[0] = step * (2.0 * gsl_rng_uniform(rng) - 1.0);
  if (kind == K_WEIGHT) {
    const double dE = propose_weight(s, q);
    if (q->nomem) *forbidden = LW_PROPOSE_NOMEM; /* (not a rejected move: the run stops) */
    return dE;
  }
  q->d[1] = step * (2.0 * gsl_rng_uniform(rng) - 1.0);
  size_t i = q->i;
  double kii = s->mat->K[i * (size_t)s->mat->k], kp[2];
  band_row(s->mat, s->c->P, i, kp);
  q->de[T_ELASTIC] = kp[0] * q->d[0] + kp[1] * q->d[1] + 0.5 * kii * (q->d[0] * q->d[0] + q->d[1] * q->d[1]);
  q->de[T_GRAVITY] = -(s->f[2 * i] * q->d[0] + s->f[2 * i + 1] * q->d[1]);
  q->de[T_WEIGHTS] = 0.0;
  return q->de[T_ELASTIC] + q->de[T_GRAVITY];
}

static lw_status commit(void *state, void *prop)
{
  lw_nurbs_state *s = state;
  const nb_prop *q = prop;
  size_t i = q->i;
  if (q->kind == K_WEIGHT) {
    /* K and f change over 2k - 1 control points: assembled again, O(n) */
    lw_error err = {0};
    double s0 = s->s[i];
    s->s[i] += q->d[0];
    s->c->w[i] = exp(s->s[i]);
    if (rebuild(s, &err)) {
      s->s[i] = s0;
      s->c->w[i] = exp(s0);
      rebuild(s, &err);
      return LW_ENOMEM;
    }
  } else {
    s->c->P[2 * i] += q->d[0];
    s->c->P[2 * i + 1] += q->d[1];
  }
  for (int t = 0; t < N_TERMS; t++) s->term[t] += q->de[t];
  return LW_OK;
}

/* ---- energies ------------------------------------------------------------- */

static double total(const void *state)
{
  const lw_nurbs_state *s = state;
  return s->term[T_ELASTIC] + s->term[T_GRAVITY] + s->term[T_WEIGHTS];
}

static void terms(const void *state, double *term) { memcpy(term, ((const lw_nurbs_state *)state)->term, N_TERMS * sizeof *term); }

static int term_on(const void *setup, int t)
{
  const lw_nurbs_setup *su = setup;
  if (t == T_ELASTIC) return 1;
  if (t == T_WEIGHTS) return su->free_weights && su->weight_stiffness > 0.0;
  for (size_t i = 0; i < 2 * su->curve->n; i++)
    if (su->f[i] != 0.0) return 1;
  return 0;
}

static lw_status refresh(void *state)
{
  lw_error err = {0};
  return recompute(state, &err) ? err.code : LW_OK;
}

static double energy(const void *setup, const lw_state *st, const char *path, double *term, lw_error *err)
{
  lw_nurbs_state *s = state_get(setup, st->doc, SECTION, err);
  if (!s) return NAN;
  memcpy(term, s->term, sizeof s->term);
  double e = total(s);
  state_free(s);
  return e;
}

static lw_status save(const void *state, lw_ckpt_writer *w, const char *section, lw_error *err)
{
  const lw_nurbs_state *s = state;
  lw_ckpt_section(w, section);
  lw_ckpt_put(w, "count", "%zu", s->c->n);
  for (size_t i = 0; i < s->c->n; i++) lw_ckpt_put(w, "point", "%.17g %.17g", s->c->P[2 * i], s->c->P[2 * i + 1]);
  for (size_t i = 0; s->s && i < s->c->n; i++) lw_ckpt_put(w, "log_weight", "%.17g", s->s[i]);
  return LW_OK;
}

static void *load(const void *setup, lw_state *st, const char *section, const char *path, lw_error *err)
{
  return state_get(setup, st->doc, section, err);
}

static void set_terms(void *state, const double *term) { memcpy(((lw_nurbs_state *)state)->term, term, N_TERMS * sizeof *term); }

/* ---- gradient and inertia ------------------------------------------------- */

/* Coordinates per control point: x y, and s = log w with free weights. */
static size_t per_point(const lw_nurbs_setup *su) { return su->free_weights ? 3 : 2; }

static size_t n_coords(const void *state)
{
  const lw_nurbs_state *s = state;
  return per_point(s->su) * s->c->n;
}

static void get_coords(const void *state, double *x)
{
  const lw_nurbs_state *s = state;
  size_t m = per_point(s->su);
  for (size_t i = 0; i < s->c->n; i++) {
    x[m * i] = s->c->P[2 * i];
    x[m * i + 1] = s->c->P[2 * i + 1];
    if (s->s) x[m * i + 2] = s->s[i];
  }
}

/* Moves curve c to x (m coordinates a point); LW_EINPUT for a coordinate
** that is not finite or a weight exp(s) outside the doubles' range. */
static lw_status curve_to(lw_nurbs *c, size_t m, const double *x, lw_error *err)
{
  for (size_t i = 0; i < m * c->n; i++)
    if (!isfinite(x[i])) return lw_error_set(err, LW_EINPUT, "coordinate %zu (control point %zu) is not finite", i, i / m);
  for (size_t i = 0; i < c->n; i++) {
    c->P[2 * i] = x[m * i];
    c->P[2 * i + 1] = x[m * i + 1];
    if (m == 3 && fabs(x[3 * i + 2]) > 700.0)
      return lw_error_set(err, LW_EINPUT, "the log weight of control point %zu is %g: the weights span more than "
                          "the doubles do", i, x[3 * i + 2]);
    if (m == 3) c->w[i] = exp(x[3 * i + 2]);
  }
  return LW_OK;
}

static lw_status set_coords(void *state, const double *x, lw_error *err)
{
  lw_nurbs_state *s = state;
  size_t m = per_point(s->su);
  lw_status st = curve_to(s->c, m, x, err);
  if (st) return st;
  for (size_t i = 0; s->s && i < s->c->n; i++) s->s[i] = x[3 * i + 2];
  return recompute(s, err);
}

/* dE/dP = K P - f; with free weights dE/ds_j too (dnurbs.h). */
static double gradient(void *state, double *g, lw_error *err)
{
  lw_nurbs_state *s = state;
  size_t n = s->c->n, m = per_point(s->su);
  for (size_t i = 0; i < n; i++) {
    double kp[2];
    band_row(s->mat, s->c->P, i, kp);
    for (size_t c = 0; c < 2; c++) g[m * i + c] = kp[c] - s->f[2 * i + c];
  }
  if (s->s) {
    const lw_dnurbs *d = s->mat;
    double *gs = malloc(n * sizeof *gs);
    if (!gs || lw_dnurbs_grad_s(s->c, d->alpha, d->beta, s->su->mug, d->gauss, gs, err)) {
      free(gs);
      if (!err->code) lw_error_set(err, LW_ENOMEM, "out of memory for the gradient");
      return NAN;
    }
    for (size_t i = 0; i < n; i++) g[3 * i + 2] = gs[i] + s->su->weight_stiffness * s->s[i];
    free(gs);
  }
  /* a held point (and its weight) is no coordinate that moves: its force is
  ** the support's, which the quench must not follow (system.h) */
  for (size_t i = 0; i < n; i++)
    if (s->su->pin[i]) memset(g + m * i, 0, m * sizeof *g);
  return total(s);
}

typedef struct {
  const lw_nurbs_setup *su;
  size_t n, k;      /* the band: rows and columns (3 n, 3 k with free weights) */
  double density;
  double *M, *L;    /* the mass matrix and its factor (held coordinates as identity) */
  double *S;        /* frozen weights: the factor of a M + b K (mass_shift), or NULL */
  unsigned char *pin;  /* n: held coordinates (free weights; else su->pin a point) */
  lw_nurbs *c;      /* free weights: the curve at the last x */
} nb_mass;

static void mass_free(void *mass)
{
  nb_mass *m = mass;
  if (!m) return;
  free(m->M);
  free(m->L);
  free(m->S);
  free(m->pin);
  lw_nurbs_free(m->c);
  free(m);
}

/* The highest angular frequency of the frozen-weight curve, omega^2 the
** largest eigenvalue of (K, rho M1) on the free points, by power iteration
** from the alternating vector (the highest mode alternates). Its Rayleigh
** quotients rise toward omega^2 from below, so a refusal on it is never
** wrong. L is the factor of rho M1 with the held points (mass_new). */
/* The spectral radius of one damped leapfrog step on a mode of frequency
** omega: each half kick decays the velocity by f = exp(-c dt / 2) (c = gamma
** / rho) as it kicks by (1 - f) / c (dynamics.c), so the step's matrix has
** trace 1 + f^2 - omega^2 dt (1 - f^2) / c and determinant f^2: stable while
** omega^2 dt^2 < 4 z coth z, z = c dt / 2 (2 / omega at c = 0, about
** 2 c / omega^2 where z >> 1). */
static double leapfrog_growth(double omega, double dt, double c)
{
  const double f2 = exp(-c * dt), kick = c > 0.0 ? -expm1(-c * dt) / c : dt;
  const double tr = 1.0 + f2 - omega * omega * dt * kick, disc = tr * tr - 4.0 * f2;
  return disc < 0.0 ? sqrt(f2) : 0.5 * (fabs(tr) + sqrt(disc));
}

/* The longest step whose growth stays at most 1 (one crossing: the growth's
** condition divided by dt rises with it), by bisection. */
static double leapfrog_limit(double omega, double c)
{
  double lo = 0.0, hi = 2.0 / omega;
  while (leapfrog_growth(omega, hi, c) <= 1.0 && hi < 1e300) lo = hi, hi *= 2.0;
  for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; it++) {
    const double mid = 0.5 * (lo + hi);
    if (leapfrog_growth(omega, mid, c) <= 1.0) lo = mid;
    else hi = mid;
  }
  return lo;
}

static double highest_omega(const lw_nurbs_setup *su, const double *M, const double *L, lw_error *err)
{
  const size_t n = su->mat->n;
  const int k = su->mat->k;
  double *v = malloc(3 * n * sizeof *v), *kv = v + n, *mv = v + 2 * n, rq = 0.0;
  if (!v) {
    lw_error_set(err, LW_ENOMEM, "out of memory");
    return NAN;
  }
  for (size_t i = 0; i < n; i++) v[i] = su->pin[i] ? 0.0 : i % 2 ? -1.0 : 1.0;
  for (int it = 0; it < 200; it++) {
    lw_band_apply_dim(su->mat->K, n, k, 1, v, kv);
    lw_band_apply_dim(M, n, k, 1, v, mv);
    double vkv = 0.0, vmv = 0.0, norm = 0.0;
    for (size_t i = 0; i < n; i++) vkv += v[i] * kv[i], vmv += v[i] * mv[i];
    if (!(vmv > 0.0)) break;
    rq = fmax(rq, vkv / vmv);
    lw_band_solve_dim(L, su->pin, n, k, 1, kv, v);
    for (size_t i = 0; i < n; i++) norm = fmax(norm, fabs(v[i]));
    if (!(norm > 0.0)) break;
    for (size_t i = 0; i < n; i++) v[i] /= norm;
  }
  free(v);
  return sqrt(rq);
}

static void *mass_new(const void *state, const lw_params *p, double density, lw_error *err)
{
  const lw_nurbs_state *s = state;
  const lw_nurbs_setup *su = s->su;
  if (su->free_weights && p->dyn_integrator == LW_INTEGRATOR_REVIEW) {
    lw_error_set(err, LW_EINPUT, "the review's scheme takes a constant mass matrix; with nurbs.free_weights = 1 "
                 "use integrator = leapfrog");
    lw_params_blame(p, "dynamics", "integrator", err);
    return NULL;
  }
  nb_mass *m = calloc(1, sizeof *m);
  if (!m) goto nomem;
  m->su = su;
  m->density = density;
  m->n = su->mat->n;
  m->k = (size_t)su->mat->k;
  if (su->free_weights) {
    m->n *= 3;
    m->k *= 3;
    if (!(m->pin = malloc(m->n)) || !(m->c = lw_nurbs_copy(s->c, err))) goto nomem;
    for (size_t i = 0; i < m->n; i++) m->pin[i] = su->pin[i / 3];
  }
  if (!(m->M = malloc(m->n * m->k * sizeof *m->M)) || !(m->L = malloc(m->n * m->k * sizeof *m->L))) goto nomem;
  if (su->free_weights) return m; /* assembled by mass_at */
  for (size_t i = 0; i < m->n * m->k; i++) m->M[i] = density * su->mat->M1[i];
  if (lw_band_factor(m->M, su->pin, m->n, (int)m->k, m->L, err)) {
    mass_free(m);
    return NULL;
  }
  /* the undamped leapfrog is stable for omega_max dt < 2, a damped one
  ** while its step's growth (leapfrog_growth) stays below 1, which heavy
  ** damping puts far past that: refuse a step past it before anything is
  ** written (gamma = 0.1 ran on to t = 0.016 s first); the implicit motion
  ** and the massless flow are left to the run's own check of E + K */
  if (p->dyn_rho > 0.0 && p->dyn_integrator == LW_INTEGRATOR_LEAPFROG) {
    double omega = highest_omega(su, m->M, m->L, err), c = p->dyn_gamma / p->dyn_rho;
    if (isnan(omega) || (p->dyn_gamma == 0.0 ? omega * p->dyn_dt >= 2.0 : leapfrog_growth(omega, p->dyn_dt, c) > 1.0)) {
      if (!isnan(omega)) {
        const double limit = p->dyn_gamma == 0.0 ? 2.0 / omega : leapfrog_limit(omega, c);
        char what[64] = "2 / omega_max =";
        if (p->dyn_gamma != 0.0) snprintf(what, sizeof what, "at gamma = %g,", p->dyn_gamma);
        lw_error_set(err, LW_EINPUT, "%g s is past the leapfrog's stability limit %s %.3g s%s of this "
                     "curve (omega_max = %.4g /s, %zu control points): take dt <= %.2g, or integrator = review "
                     "(stable at any dt; it damps the high modes)", p->dyn_dt, what, limit,
                     p->dyn_gamma != 0.0 ? "," : "", omega, m->n, 0.9 * limit);
        lw_params_blame(p, "dynamics", "dt", err);
      }
      mass_free(m);
      return NULL;
    }
  }
  return m;
nomem:
  mass_free(m);
  lw_error_set(err, LW_ENOMEM, "out of memory for the mass matrix");
  return NULL;
}

/* frozen weights: the matrix is constant, factored once; free weights: it
** is assembled and factored again at x */
static lw_status mass_at(void *mass, const double *x, lw_error *err)
{
  nb_mass *m = mass;
  if (!m->c) return LW_OK;
  lw_status st = curve_to(m->c, 3, x, err);
  if (!st) st = lw_dnurbs_mass_s(m->c, m->su->mat->gauss, m->M, err);
  if (st) return st;
  for (size_t i = 2; i < m->n; i += 3) m->M[i * m->k] += m->su->weight_inertia;
  for (size_t i = 0; i < m->n * m->k; i++) m->M[i] *= m->density;
  return lw_band_factor(m->M, m->pin, m->n, (int)m->k, m->L, err);
}

static void mass_solve(const void *mass, const double *b, double *v)
{
  const nb_mass *m = mass;
  if (m->c)
    lw_band_solve_dim(m->L, m->pin, m->n, (int)m->k, 1, b, v);
  else
    lw_band_solve(m->L, m->su->pin, m->n, (int)m->k, b, v);
}

static void mass_apply(const void *mass, const double *v, double *b)
{
  const nb_mass *m = mass;
  lw_band_apply_dim(m->M, m->n, (int)m->k, m->c ? 1 : 2, v, b);
}

/* frozen weights: M is constant, so 0; free weights: dnurbs.h (NaN where
** the curve cannot be evaluated, so that the motion stops) */
static void mass_dx(const void *mass, const double *x, const double *v, double *out)
{
  const nb_mass *m = mass;
  size_t nc = m->c ? m->n : 2 * m->n;
  lw_error err = {0};
  if (!m->c) {
    memset(out, 0, nc * sizeof *out);
    return;
  }
  if (curve_to(m->c, 3, x, &err) || lw_dnurbs_mass_s_dx(m->c, m->su->mat->gauss, v, out, &err)) {
    for (size_t i = 0; i < nc; i++) out[i] = NAN;
    return;
  }
  for (size_t i = 0; i < nc; i++) out[i] *= m->density;
}

static int mass_pinned(const void *mass, size_t i)
{
  const nb_mass *m = mass;
  return m->c ? m->pin[i] : m->su->pin[i / 2];
}

/* Frozen weights make the energy quadratic with the constant Hessian K (the
** stiffness; gravity is linear), so a M + b K is a band like M. */
static lw_status mass_shift(void *mass, double a, double b, int *done, lw_error *err)
{
  nb_mass *m = mass;
  *done = 0;
  if (m->c) return LW_OK;
  double *A = malloc(m->n * m->k * sizeof *A);
  if (!A || (!m->S && !(m->S = malloc(m->n * m->k * sizeof *m->S)))) {
    free(A);
    return lw_error_set(err, LW_ENOMEM, "out of memory for the review scheme's matrix");
  }
  for (size_t i = 0; i < m->n * m->k; i++) A[i] = a * m->M[i] + b * m->su->mat->K[i];
  lw_status st = lw_band_factor(A, m->su->pin, m->n, (int)m->k, m->S, err);
  free(A);
  *done = st == LW_OK;
  return st;
}

static void mass_shift_solve(const void *mass, const double *b, double *v)
{
  const nb_mass *m = mass;
  lw_band_solve(m->S, m->su->pin, m->n, (int)m->k, b, v);
}

/* At given weights the energy is quadratic in the control points,
** 1/2 P'K(w)P - f(w)'P (+ the weights' own term), so its minimum over them
** with the held points where they are is one banded solve: K_ff P_f = f_f -
** K_fh P_h (system.h). Frozen weights: the minimum. Free weights: the
** minimum at these weights, between which the quench's L-BFGS moves the
** weights too (its rounds). A K that is not positive definite on the free
** points (nothing held, alpha = 0 ...) has no unique minimum: left to the
** quench's own iterations. */
static lw_status minimize(void *state, lw_error *err)
{
  lw_nurbs_state *s = state;
  const lw_nurbs_setup *su = s->su;
  const size_t n = s->c->n;
  const int k = s->mat->k;
  double *L = malloc(n * (size_t)k * sizeof *L), *held = malloc(2 * n * sizeof *held),
         *r = malloc(2 * n * sizeof *r);
  lw_error e2 = {0};
  lw_status st = LW_OK;
  if (!L || !held || !r) {
    st = lw_error_set(err, LW_ENOMEM, "out of memory for the curve's minimum");
  } else if (lw_band_factor(s->mat->K, su->pin, n, k, L, &e2) == LW_OK) {
    for (size_t i = 0; i < 2 * n; i++) held[i] = su->pin[i / 2] ? s->c->P[i] : 0.0;
    lw_band_apply(s->mat->K, n, k, held, r);
    for (size_t i = 0; i < 2 * n; i++) r[i] = s->f[i] - r[i];
    lw_band_solve(L, su->pin, n, k, r, r);
    for (size_t i = 0; i < 2 * n; i++)
      if (!su->pin[i / 2]) s->c->P[i] = r[i];
    st = recompute(s, err);
  }
  free(L), free(held), free(r);
  return st;
}

/* ---- drawings ------------------------------------------------------------- */

typedef struct {
  FILE *f;
  cairo_t *cr;
  size_t count;
} bz_sink;

static void svg_bezier(const double B[8], void *ctx)
{
  bz_sink *k = ctx;
  if (!k->count++) fprintf(k->f, "M %.17g %.17g", B[0], -B[1]);
  fprintf(k->f, " C %.17g %.17g %.17g %.17g %.17g %.17g", B[2], -B[3], B[4], -B[5], B[6], -B[7]);
}

static void cairo_bezier(const double B[8], void *ctx)
{
  bz_sink *k = ctx;
  if (!k->count++) cairo_move_to(k->cr, B[0], B[1]);
  cairo_curve_to(k->cr, B[2], B[3], B[4], B[5], B[6], B[7]);
}

/* The box of the control polygon (the curve lies inside it). */
static void box_of(const lw_nurbs *c, double b[4])
{
  b[0] = b[2] = c->P[0];
  b[1] = b[3] = c->P[1];
  for (size_t i = 1; i < c->n; i++) {
    b[0] = fmin(b[0], c->P[2 * i]), b[2] = fmax(b[2], c->P[2 * i]);
    b[1] = fmin(b[1], c->P[2 * i + 1]), b[3] = fmax(b[3], c->P[2 * i + 1]);
  }
  double m = 0.05 * fmax(fmax(b[2] - b[0], b[3] - b[1]), 1e-9);
  b[0] -= m, b[1] -= m, b[2] += m, b[3] += m;
}

/* final.svg: y up in the curve's coordinates, so the page flips it. */
static lw_status write_svg(lw_nurbs_state *s, const char *path, lw_error *err)
{
  char tmp[LW_OUTPUT_PATH_MAX];
  FILE *f = lw_output_open_tmp(path, tmp, sizeof tmp, err);
  if (!f) return err->code;
  double b[4];
  box_of(s->c, b);
  double w = b[2] - b[0], h = b[3] - b[1];
  fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" "
          "viewBox=\"%.17g %.17g %.17g %.17g\">\n<path fill=\"none\" stroke=\"black\" stroke-width=\"%.6g\" d=\"",
          b[0], -b[3], w, h, 0.005 * fmax(w, h));
  bz_sink k = {f, NULL, 0};
  s->deviation = lw_nurbs_beziers(s->c, s->su->tolerance, svg_bezier, &k);
  s->beziers = k.count;
  fprintf(f, "\"/>\n</svg>\n");
  if (isnan(s->deviation)) {
    lw_output_abort(f, tmp);
    return lw_error_set(err, LW_ENOMEM, "%s: out of memory", path);
  }
  return lw_output_commit(f, tmp, path, err);
}

/* A PNG of the curve (black) and its control polygon (grey) in box b. */
static lw_status write_png(const lw_nurbs_state *s, const double b[4], const char *path, lw_error *err)
{
  /* the curve's box at png_scale, its long side capped as the splines'
  ** previews are: a curve that sagged far must still be drawn */
  lw_output_page box;
  lw_output_page_init(&box, b[2] - b[0], b[3] - b[1]);
  double scale;
  int W, H;
  if (!lw_output_png_size(&box, s->su->png_scale, &W, &H, &scale))
    return lw_error_set(err, LW_ERUN, "%s: the curve's box (%g to %g, %g to %g) cannot be drawn", path, b[0], b[2],
                        b[1], b[3]);
  cairo_surface_t *surf = lw_output_white_surface(W, H);
  cairo_t *cr = cairo_create(surf);
  cairo_translate(cr, 0, H);
  cairo_scale(cr, scale, -scale);
  cairo_translate(cr, -b[0], -b[1]);
  cairo_set_line_width(cr, 1.0 / scale);
  cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
  for (size_t i = 0; i < s->c->n; i++) {
    cairo_line_to(cr, s->c->P[2 * i], s->c->P[2 * i + 1]);
    cairo_rectangle(cr, s->c->P[2 * i] - 2 / scale, s->c->P[2 * i + 1] - 2 / scale, 4 / scale, 4 / scale);
    cairo_move_to(cr, s->c->P[2 * i], s->c->P[2 * i + 1]);
  }
  cairo_stroke(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 2.0 / scale);
  bz_sink k = {NULL, cr, 0};
  /* (NAN: out of memory, the curve not drawn, which final.png without it would hide) */
  const int drawn = !isnan(lw_nurbs_beziers(s->c, s->su->tolerance, cairo_bezier, &k));
  cairo_stroke(cr);
  cairo_surface_flush(surf);
  lw_status st = !drawn           ? lw_error_set(err, LW_ENOMEM, "%s: out of memory drawing the curve", path)
                 : cairo_status(cr) ? lw_error_set(err, LW_ERUN, "%s: drawing failed: %s", path,
                                                   cairo_status_to_string(cairo_status(cr)))
                                    : lw_output_png_surface(surf, path, err);
  cairo_destroy(cr);
  cairo_surface_destroy(surf);
  return st;
}

static lw_status draw(void *state, const lw_params *p, const char *dir, long sweep, lw_error *err)
{
  lw_nurbs_state *s = state;
  char path[LW_PATH_MAX + 64];
  if (sweep == LW_DRAW_START) return LW_OK;
  if (sweep == LW_DRAW_FINAL) {
    double b[4];
    box_of(s->c, b);
    lw_path_join(path, sizeof path, dir, "final.svg");
    lw_status st = write_svg(s, path, err);
    if (st) return st;
    lw_path_join(path, sizeof path, dir, "final.png");
    return write_png(s, b, path, err);
  }
  if (lw_output_subdir(dir, "frames", path, sizeof path, err)) return err->code;
  size_t n = strlen(path);
  snprintf(path + n, sizeof path - n, "/frame-%06ld.png", sweep);
  return write_png(s, s->su->view, path, err);
}

static void summary(const void *state, lw_json *j)
{
  const lw_nurbs_state *s = state;
  lw_json_key(j, "control_points");
  lw_json_int(j, (long long)s->c->n);
  lw_json_key(j, "order");
  lw_json_int(j, s->c->order);
  lw_json_key(j, "fixed");
  lw_json_int(j, (long long)(s->c->n - s->su->n_free));
  if (s->s) {
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < s->c->n; i++) lo = fmin(lo, s->c->w[i]), hi = fmax(hi, s->c->w[i]);
    lw_json_key(j, "weight_min");
    lw_json_number(j, lo);
    lw_json_key(j, "weight_max");
    lw_json_number(j, hi);
  }
  lw_json_key(j, "svg_beziers");
  lw_json_int(j, (long long)s->beziers);
  lw_json_key(j, "svg_max_deviation");
  lw_json_number(j, s->deviation);
}

/* The observables of the one curve (docs/FORMATS.md, "trace.csv"), as the
** splines' are of each spline: its length, the squared distance between its
** ends, its squared radius of gyration along the arc, 1/L integral of
** |r - r_cm|^2 dl, and the cosine between its end tangents; the integrals
** by an 8-point Gauss rule on every piece of a knot span that the energy's
** quadrature takes (lw_dnurbs_span_pieces: a light end point's turn). */
static const char *const observable_names[] = {"length", "end2", "rg2", "end_cos"};

static void observe(const void *state, double *out)
{
  const lw_nurbs *c = ((const lw_nurbs_state *)state)->c;
  const size_t k = (size_t)c->order, nq = 8;
  gsl_integration_glfixed_table *gl = gsl_integration_glfixed_table_alloc(nq);
  if (!gl) {
    out[0] = out[1] = out[2] = out[3] = NAN;
    return;
  }
  double p0[2], t0[2], p1[2], t1[2], pt[2], d[2];
  lw_nurbs_eval(c, lw_nurbs_u0(c), p0, t0, NULL);
  lw_nurbs_eval(c, lw_nurbs_u1(c), p1, t1, NULL);
  lw_arc_moments m = {0.0, 0.0, 0.0, 0.0};
  for (size_t sp = k - 1; sp < c->n; sp++) {
    if (!(c->knot[sp + 1] > c->knot[sp])) continue; /* a repeated knot: no span */
    double a[LW_DNURBS_PIECES_MAX], b[LW_DNURBS_PIECES_MAX];
    const int pieces = lw_dnurbs_span_pieces(c, sp, a, b);
    for (int piece = 0; piece < pieces; piece++)
      for (size_t q = 0; q < nq; q++) {
        double u, wq;
        gsl_integration_glfixed_point(a[piece], b[piece], q, &u, &wq, gl);
        lw_nurbs_eval(c, u, pt, d, NULL);
        lw_arc_moments_add(&m, pt[0] - p0[0], pt[1] - p0[1], wq * hypot(d[0], d[1]));
      }
  }
  gsl_integration_glfixed_table_free(gl);
  lw_spline_shape sh;
  lw_shape_finish(&m, p1[0] - p0[0], p1[1] - p0[1], t0, t1, &sh);
  out[0] = sh.length;
  out[1] = sh.end2;
  out[2] = sh.rg2;
  out[3] = sh.end_cos;
}

/* A sample of the configuration (system.h): the control points and weights
** (the knots are the scene's and never move). */
static void write_sample(const void *state, FILE *f)
{
  const lw_nurbs *c = ((const lw_nurbs_state *)state)->c;
  fputs("point,x,y,w\n", f);
  for (size_t i = 0; i < c->n; i++)
    fprintf(f, "%zu,%.17g,%.17g,%.17g\n", i, c->P[2 * i], c->P[2 * i + 1], c->w[i]);
}

static void describe(const void *state, int what, char *buf, size_t n)
{
  const lw_nurbs_state *s = state;
  if (what == LW_DESCRIBE_SIZE)
    snprintf(buf, n, "a NURBS curve of order %d, %zu control points, %zu free%s", s->c->order, s->c->n, s->su->n_free,
             s->s ? ", free weights" : "");
  else if (what == LW_DESCRIBE_FORBIDDEN)
    snprintf(buf, n, "an energy that is not finite");
  else if (what == LW_DESCRIBE_LOST) {
    /* (weights 1e8 apart drew 0.29 from a curve of size 1, and only this
    ** number said so; a warning, so under --quiet too) */
    if (s->deviation > s->su->tolerance)
      snprintf(buf, n, "final.svg lies up to %.3g from the curve, more than nurbs.svg_tolerance (%g): the fit's depth, "
               "or the curve's rounding (its size), stopped it there", s->deviation, s->su->tolerance);
    else if (n)
      buf[0] = '\0';
  } else
    snprintf(buf, n, "linewise: final.svg: %zu cubic Beziers, at most %.3g from the curve%s\n", s->beziers,
             s->deviation, lw_nurbs_polynomial(s->c) && s->c->order <= 4 ? " (exact)" : "");
}

/* The wire's load acts on Monte Carlo too; its ends are held by
** nurbs.fixed, not the dynamics' pins. */
static const char *const keys[] = {"init.from", "nurbs.*", "dynamics.rho", "dynamics.gravity_x", "dynamics.gravity_y",
                                   NULL};
static const char *const keys_dynamics[] = {"nurbs.weight_inertia", NULL};
static const char *const keys_metropolis[] = {"moves.step_point", "moves.target", "nurbs.step_weight", NULL};

/* Keys the scene's other settings leave idle (system.h). */
static int idle(const lw_params *p, lw_idle_rule rule[LW_IDLE_RULES_MAX])
{
  static const char *const seed[] = {"anneal.seed", "anneal.seed_version", NULL},
                           *const inline_points[] = {"nurbs.points", "nurbs.weights", NULL},
                           *const weights[] = {"nurbs.weight_inertia", "nurbs.weight_stiffness", "nurbs.step_weight",
                                               NULL};
  /* (a seed sweep of the wire: identical runs, which stats took for agreeing seeds) */
  rule[0] = (lw_idle_rule){seed, lw_driver_is_motion(p) && !p->from[0],
                           "the D-NURBS dynamics draws no random number"};
  rule[1] = (lw_idle_rule){inline_points, p->nb_file[0] != '\0', "nurbs.file gives the points and weights"};
  rule[2] = (lw_idle_rule){weights, !p->nb_free_weights, "nurbs.free_weights = 0"};
  return 3;
}

/* "lower dynamics.dt" sent the user the wrong way here: no dt helps weights
** without a mass of their own (docs/NUMERICS.md, "Free weights"). */
static const char *motion_advice(const lw_params *p)
{
  if (p->nb_free_weights && p->nb_weight_inertia == 0.0 && p->dyn_rho > 0.0)
    return "but nurbs.weight_inertia = 0 leaves the free weights without a mass of their own, and no dt takes a "
           "step so: give it > 0 (default 0.1; docs/NURBS.md)";
  return NULL;
}

const lw_system_type lw_system_nurbs = {
    .idle = idle,
    .motion_advice = motion_advice,
    .name = "nurbs",
    .keys = keys,
    .keys_dynamics = keys_dynamics,
    .keys_metropolis = keys_metropolis,
    .n_moves = 2,
    .move_names = move_names,
    .move_unit = move_unit,
    .n_terms = N_TERMS,
    .term_names = term_names,
    .setup_new = setup_new,
    .setup_free = setup_free,
    .note = note,
    .state_new = state_new,
    .state_copy = state_copy,
    .state_free = state_free,
    .moves = moves,
    .sweep_size = sweep_size,
    .step_max = step_max,
    .proposal_new = proposal_new,
    .proposal_free = proposal_free,
    .propose = propose,
    .commit = commit,
    .total = total,
    .terms = terms,
    .term_on = term_on,
    .refresh = refresh,
    .energy = energy,
    .save = save,
    .load = load,
    .set_terms = set_terms,
    .n_coords = n_coords,
    .get_coords = get_coords,
    .set_coords = set_coords,
    .gradient = gradient,
    .minimize = minimize,
    .mass_new = mass_new,
    .mass_free = mass_free,
    .mass_at = mass_at,
    .mass_solve = mass_solve,
    .mass_apply = mass_apply,
    .mass_dx = mass_dx,
    .mass_pinned = mass_pinned,
    .mass_shift = mass_shift,
    .mass_shift_solve = mass_shift_solve,
    .files = "final.svg, final.png",
    .draw = draw,
    .summary = summary,
    .describe = describe,
    .n_observables = (int)(sizeof observable_names / sizeof observable_names[0]),
    .observable_names = observable_names,
    .observe = observe,
    .write_sample = write_sample,
};
