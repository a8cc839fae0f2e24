/*
** transdim.c -- proposal densities of the trans-dimensional moves
** (transdim.h).  Each draw and its log density are written side by side
** from one description of the kernel, so that the two cannot drift apart;
** a test integrates every density numerically.
*/
#include "linewise/transdim.h"

#include <gsl/gsl_math.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_sf_bessel.h>
#include <math.h>
#include <stdlib.h>

#include "linewise/init.h"

lw_status lw_td_init(lw_td *td, const lw_scene *sc, size_t birth_segments, double length, size_t max_segments,
                     double uniform, double spread, double sd)
{
  td->scene = sc;
  td->cum = NULL;
  td->uniform = uniform;
  td->dark_scale = 0.0;
  if (sc->image) {
    if (!(td->cum = lw_init_darkness(sc->image))) return LW_ENOMEM;
    const double total = td->cum[sc->image->height], a = sc->image_place.pixel;
    if (total > 0) {
      td->dark_scale = (1.0 - uniform) / (total * a * a);
    } else { /* a white picture: nothing to follow, as placement does */
      free(td->cum);
      td->cum = NULL;
    }
  }
  td->length = length;
  td->sigma_p = sd * length;
  td->sigma_v = sd * length / 3.0;
  td->birth_segments = birth_segments;
  td->max_segments = max_segments;
  td->spread = max_segments > 1 ? spread : 0.0; /* else no other count */
  return LW_OK;
}

void lw_td_clear(lw_td *td)
{
  free(td->cum);
  td->cum = NULL;
}

double lw_td_rest(const lw_td *td, double rest, size_t n_old, size_t n_new)
{
  const double r = (double)n_new * td->length + (rest - (double)n_old * td->length);
  return r > 0.0 ? r : NAN;
}

int lw_td_plain(const lw_td *td, size_t n, double rest)
{
  return rest == (double)n * td->length;
}

size_t lw_td_birth_size(const lw_td *td, gsl_rng *rng)
{
  if (td->spread <= 0.0 || gsl_rng_uniform(rng) >= td->spread) return td->birth_segments;
  const size_t n = 1 + gsl_rng_uniform_int(rng, td->max_segments - 1);
  return n >= td->birth_segments ? n + 1 : n;
}

double lw_td_size_log(const lw_td *td, size_t n)
{
  if (n == td->birth_segments) return log1p(-td->spread);
  if (n < 1 || n > td->max_segments || td->spread <= 0.0) return -INFINITY;
  return log(td->spread / (double)(td->max_segments - 1));
}

int lw_td_mortal(const lw_td *td, size_t n, double rest)
{
  return lw_td_size_log(td, n) > -INFINITY && lw_td_plain(td, n, rest);
}

/* log pi(x, y) (transdim.h): -inf off the page. */
static double log_first_point(const lw_td *td, double x, double y)
{
  const lw_scene *sc = td->scene;
  if (!(x >= 0.0 && x <= sc->width && y >= 0.0 && y <= sc->height)) return -INFINITY;
  const double lp = -log(sc->width * sc->height);
  if (!td->cum) return lp;
  const lw_image *img = sc->image;
  const lw_image_place *pl = &sc->image_place;
  const double fi = floor((x - pl->x0) / pl->pixel), fj = floor((y - pl->y0) / pl->pixel);
  double d = 0.0;
  if (fi >= 0 && fi < img->width && fj >= 0 && fj < img->height)
    d = 1.0 - img->tone[(size_t)fj * (size_t)img->width + (size_t)fi];
  /* as lw_init_dark_point, which never draws a pixel without darkness */
  if (!(d > 0.0)) d = 0.0;
  return log(td->uniform * exp(lp) + td->dark_scale * d);
}

/* log of the isotropic 2-D Gaussian density N(d; 0, s^2) at offset d. */
static double log_gauss2(double dx, double dy, double s)
{
  return -log(2.0 * M_PI * s * s) - 0.5 * (dx * dx + dy * dy) / (s * s);
}

/* The field's unit direction at (x, y) turned to agree with (ax, ay); the
** unit (ax, ay) where the field is off or vanishes; 0 if that is 0 too. */
static int direction(const lw_scene *sc, double x, double y, double ax, double ay, double *ux, double *uy)
{
  double fx = 0.0, fy = 0.0;
  if (sc->on[LW_TERM_FIELD]) lw_field_eval(&sc->field, x, y, &fx, &fy);
  double f = hypot(fx, fy);
  if (!(f > 0.0) || !isfinite(f)) {
    fx = ax;
    fy = ay;
    f = hypot(fx, fy);
    if (!(f > 0.0) || !isfinite(f)) {
      *ux = *uy = 0.0;
      return 0;
    }
  }
  double s = fx * ax + fy * ay < 0.0 ? -1.0 : 1.0;
  *ux = s * fx / f;
  *uy = s * fy / f;
  return 1;
}

/* The mean of the next node's point beyond `end`. */
static void next_point(const lw_node *end, int dir, double *x, double *y)
{
  *x = end->px + dir * 3.0 * end->vx;
  *y = end->py + dir * 3.0 * end->vy;
}

double lw_td_next_draw(const lw_td *td, const lw_node *end, int dir, gsl_rng *rng, lw_node *out)
{
  double mx, my, ux, uy;
  next_point(end, dir, &mx, &my);
  out->px = mx + gsl_ran_gaussian_ziggurat(rng, td->sigma_p);
  out->py = my + gsl_ran_gaussian_ziggurat(rng, td->sigma_p);
  direction(td->scene, out->px, out->py, end->vx, end->vy, &ux, &uy);
  out->vx = td->length / 3.0 * ux + gsl_ran_gaussian_ziggurat(rng, td->sigma_v);
  out->vy = td->length / 3.0 * uy + gsl_ran_gaussian_ziggurat(rng, td->sigma_v);
  return lw_td_next_log(td, end, dir, out);
}

double lw_td_next_log(const lw_td *td, const lw_node *end, int dir, const lw_node *nd)
{
  double mx, my, ux, uy;
  next_point(end, dir, &mx, &my);
  direction(td->scene, nd->px, nd->py, end->vx, end->vy, &ux, &uy);
  const double r = td->length / 3.0;
  return log_gauss2(nd->px - mx, nd->py - my, td->sigma_p) +
         log_gauss2(nd->vx - r * ux, nd->vy - r * uy, td->sigma_v);
}

/* The first node's vector: along the field either way, or a ring. */
static int first_axis(const lw_td *td, const lw_node *n0, double *ux, double *uy)
{
  /* the field itself, not turned: (fx, fy) agrees with itself */
  double fx = 0.0, fy = 0.0;
  if (td->scene->on[LW_TERM_FIELD]) lw_field_eval(&td->scene->field, n0->px, n0->py, &fx, &fy);
  return direction(td->scene, n0->px, n0->py, fx, fy, ux, uy);
}

double lw_td_first_log(const lw_td *td, const lw_node *n0)
{
  const double r = td->length / 3.0, s = td->sigma_v;
  double ux, uy, lp = log_first_point(td, n0->px, n0->py);
  if (lp == -INFINITY) return lp;
  if (first_axis(td, n0, &ux, &uy)) {
    double a = log_gauss2(n0->vx - r * ux, n0->vy - r * uy, s), b = log_gauss2(n0->vx + r * ux, n0->vy + r * uy, s);
    double hi = fmax(a, b);
    return lp + hi + log(0.5 * (exp(a - hi) + exp(b - hi)));
  }
  /* a uniform angle: the ring density, I0 scaled so it cannot overflow */
  double v = hypot(n0->vx, n0->vy), z = v * r / (s * s);
  return lp - log(2.0 * M_PI * s * s) - 0.5 * (v - r) * (v - r) / (s * s) + log(gsl_sf_bessel_I0_scaled(z));
}

void lw_td_birth_draw(const lw_td *td, gsl_rng *rng, size_t n, lw_node *nd)
{
  const double r = td->length / 3.0;
  double ux, uy;
  if (td->cum && gsl_rng_uniform(rng) >= td->uniform) {
    lw_init_dark_point(td->scene, td->scene->image, td->cum, rng, &nd[0].px, &nd[0].py);
  } else {
    nd[0].px = gsl_rng_uniform(rng) * td->scene->width;
    nd[0].py = gsl_rng_uniform(rng) * td->scene->height;
  }
  if (first_axis(td, &nd[0], &ux, &uy)) {
    if (gsl_rng_uniform(rng) < 0.5) {
      ux = -ux;
      uy = -uy;
    }
  } else {
    double a = 2.0 * M_PI * gsl_rng_uniform(rng);
    ux = cos(a);
    uy = sin(a);
  }
  nd[0].vx = r * ux + gsl_ran_gaussian_ziggurat(rng, td->sigma_v);
  nd[0].vy = r * uy + gsl_ran_gaussian_ziggurat(rng, td->sigma_v);
  for (size_t k = 1; k <= n; k++) lw_td_next_draw(td, &nd[k - 1], 1, rng, &nd[k]);
}

double lw_td_prior(const lw_td *td, const lw_node *nd, size_t n)
{
  double lq = lw_td_first_log(td, &nd[0]);
  for (size_t k = 1; k < n; k++) lq += lw_td_next_log(td, &nd[k - 1], 1, &nd[k]);
  return lq;
}

/* The factors of the prior that node k of nd takes part in, with node k
** read from at. */
static double factors(const lw_td *td, const lw_node *nd, size_t n, size_t k, const lw_node *at)
{
  double f = k == 0 ? lw_td_first_log(td, at) : lw_td_next_log(td, &nd[k - 1], 1, at);
  if (k + 1 < n) f += lw_td_next_log(td, at, 1, &nd[k + 1]);
  return f;
}

double lw_td_prior_change(const lw_td *td, const lw_node *nd, size_t n, size_t k, const lw_node *to)
{
  return factors(td, nd, n, k, to) - factors(td, nd, n, k, &nd[k]);
}
