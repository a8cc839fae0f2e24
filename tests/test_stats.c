/*
** test_stats.c -- the sampler is correct: the real chain (lw_chain proposing
** through lw_model) against exact statistical results.
**
**   1. acceptance of Gaussian point moves on a harmonic degree of freedom
**      against the closed forms, for several step sizes;
**   2. the sampled distribution of a small system against its Boltzmann
**      distribution (chi-square), with the step tuning frozen, and a wrong
**      temperature that the same test must reject;
**   3. a free worm-like chain (bending, strain holding its length) against
**      the 2-D Kratky-Porod results;
**   4. delayed acceptance against plain Metropolis, and its first stage
**      alone, which the same test must reject;
**   5. oriented particles (the particle system's row): heights under gravity
**      over a floor, and the normals of free and of co-normal pairs, against
**      their Boltzmann distributions, with a wrong temperature rejected.
**
** Seeds are fixed, so each test is deterministic; every tolerance is derived
** from the variance of the estimate and stated where it is used.  `make test`
** runs quick versions; `make test-long` (LW_LONG=1) runs longer ones with
** tighter statistics.  Derivations: docs/NUMERICS.md, "Statistical tests".
*/
#include <criterion/criterion.h>
#include <gsl/gsl_cdf.h>
#include <gsl/gsl_math.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "linewise/domains.h"
#include "linewise/mc.h"
#include "linewise/model.h"
#include "linewise/particles.h"
#include "linewise/sys_particles.h"
#include "linewise/scene.h"
#include "linewise/series.h"
#include "testutil.h"

/* ---- the harmonic well (a user term) ------------------------------------ */

/*
** E = 1/2 sum_q w_q [kx (x_q - cx)^2 + ky (y_q - cy)^2] per segment.  Each
** sample x_q is linear in every point coordinate, x_q = a_q p + (rest), so E
** is exactly quadratic in p: given all other coordinates, p is Gaussian with
** variance T / K, K = kx sum_q w_q a_q^2 (summed over the segments holding p),
** whatever the others are.  That is the harmonic degree of freedom of the
** acceptance test, exact to rounding (no quadrature error enters: the
** quadrature defines the energy).
*/
typedef struct {
  double kx, ky, cx, cy;
  double period; /* > 0: a well at every (cx, cy) + period (i, j), the nearest counts */
} well;

#define WELL_ROW 20 /* periodic wells: a page of WELL_ROW x WELL_ROW */

/* The offset of v from the nearest well centre c + period k. */
static double well_offset(double v, double c, double period)
{
  double d = v - c;
  return period > 0.0 ? d - period * round(d / period) : d;
}

static double well_energy(const lw_samples *s, const lw_quad *q, const void *data)
{
  const well *w = data;
  double e = 0.0;
  for (int i = 0; i < s->n; i++) {
    double dx = well_offset(s->x[i], w->cx, w->period), dy = well_offset(s->y[i], w->cy, w->period);
    e += q->w[i] * (w->kx * dx * dx + w->ky * dy * dy);
  }
  return 0.5 * e;
}

/* sum_q w_q c_q d_q for basis columns c, d of r (0: p0, 1: v0, 2: p1, 3: v1) */
static double basis_dot(const lw_quad *q, int c, int d)
{
  double s = 0.0;
  for (int i = 0; i < q->n; i++) s += q->w[i] * q->pos[i][c] * q->pos[i][d];
  return s;
}

/* A scene with nothing but the well (every built-in term off). */
static void well_scene(lw_scene *sc, const well *w)
{
  lw_params p;
  lw_params_defaults(&p);
  if (w->period > 0.0) p.width = p.height = WELL_ROW * w->period; /* the wells of unit_splines */
  /* The closed forms below are those of an untruncated Gaussian: the
  ** regularity check would cut off the states where a point crosses over
  ** its neighbour (a fold), which these unit segments in a wide well reach
  ** often, and so bias the very acceptance and distribution tested.  The
  ** worm-like chain test keeps it on. */
  p.min_speed = 0;
  p.regularity = 0;
  lw_error err;
  cr_assert_eq(lw_scene_init(sc, &p, &err), LW_OK, "%s", err.msg);
  cr_assert_eq(lw_scene_set_user_term(sc, 1.0, well_energy, w, &err), LW_OK, "%s", err.msg);
}

/* n one-segment straight splines of length 1 at the well's centre, or for
** a periodic well one at each of its centres, rows of WELL_ROW from (cx, cy). */
static lw_splines *unit_splines(size_t n, const well *w)
{
  size_t *segs = malloc(n * sizeof *segs);
  for (size_t i = 0; i < n; i++) segs[i] = 1;
  lw_splines *sp = lw_splines_new(n, segs, NULL);
  free(segs);
  cr_assert_not_null(sp);
  for (size_t i = 0; i < n; i++) {
    double x = w->cx + w->period * (double)(i % WELL_ROW), y = w->cy + w->period * (double)(i / WELL_ROW);
    lw_test_straight(sp, i, x - 0.5, y, x + 0.5, y);
  }
  return sp;
}

/* With domains (NULL: none): the chain's sweeps split as [anneal] domains
** = `domains` splits them (domains.h), on `threads` threads. */
static void split_chain(lw_chain *c, const char *domains, int threads)
{
  if (!domains) return;
  lw_params p;
  lw_params_defaults(&p);
  snprintf(p.domains, sizeof p.domains, "%s", domains);
  lw_error err;
  cr_assert_eq(lw_domains_attach(c, &p, 1, &err), LW_OK, "%s", err.msg);
  cr_assert_not_null(c->domains, "domains = %s did not split", domains);
  c->domains->threads = threads;
  c->domains->min_parallel = 0; /* these sweeps are small: split them anyway */
}

/* The wells of the domain cases: 400 splines 480 mm apart on a page of 20
** periods split 2 x 2 (many splines, so that a sweep is worth its threads) (a 3 x 3 lattice once shifted: the four sub-lattices
** hold 4, 2, 2 and 1 cells, so 4 threads have work).  Wide domains against
** the steps: a spline within a step of a boundary is rare (moves rejected
** for leaving their domain are about 0.1 % of proposals), since those
** proposals are left out of the acceptance, which biases it by about their
** share times the difference in acceptance they would have had. */
#define DOMAIN_PERIOD 480.0

static lw_chain *point_chain(lw_model *m, double step, unsigned long seed)
{
  double w[LW_MOVE_KINDS] = {1, 0, 0, 0}, st[LW_MOVE_KINDS] = {step, 1, 1, 0.1},
         tg[LW_MOVE_KINDS] = {0.44, 0.44, 0.3, 0.3};
  lw_error err;
  lw_chain *c = model_chain(m, w, st, tg, seed, &err);
  cr_assert_not_null(c, "%s", err.msg);
  c->temperature = 1.0;
  return c;
}

/* ---- 1. acceptance rates ------------------------------------------------- */

/*
** Metropolis with a symmetric Gaussian step of std s on a Gaussian target of
** std sigma, in d dimensions, at stationarity (docs/NUMERICS.md):
**   d = 1:  a = (2 / pi) atan(2 sigma / s)
**   d = 2:  a = 1 - s / sqrt(s^2 + 4 sigma^2)   (isotropic target and step)
** A point move steps x and y together.  With ky = 0 the energy does not see
** y, so the acceptance is that of the x step alone (d = 1); with kx = ky it
** is the isotropic d = 2 case.
*/
static double acceptance_exact(int d, double sigma, double s)
{
  return d == 1 ? M_2_PI * atan(2.0 * sigma / s) : 1.0 - s / sqrt(s * s + 4.0 * sigma * sigma);
}

/* The acceptance of point moves in d dimensions at step ratio * sigma
** against the closed form, N proposals in whole sweeps; wells of the given
** period, the sweeps split by `domains` on `threads` threads. */
static void acceptance_case(int d, double ratio, unsigned long seed, long N, double period, const char *domains,
                            int threads)
{
  const size_t n_spl = period > 0.0 ? 400 : 50;
  const int B = 50; /* batches for the error estimate */
  lw_scene sc;
  well w = {1.0, 0.0, period > 0.0 ? period / 2 : 100.0, period > 0.0 ? period / 2 : 100.0, period};
  well_scene(&sc, &w);
  /* kx such that the start point's x has conditional sigma 1 at T = 1;
  ** the end point's sigma follows from its own basis column (equal by
  ** the symmetry of the Gauss nodes, but computed, not assumed). */
  double k0 = basis_dot(&sc.quad, 0, 0), k1 = basis_dot(&sc.quad, 2, 2);
  w.kx = 1.0 / k0;
  w.ky = d == 1 ? 0.0 : w.kx;
  double sig0 = 1.0, sig1 = sqrt(k0 / k1);
  double s = ratio * sig0;
  /* half the proposals pick a start point, half an end point */
  double a = 0.5 * (acceptance_exact(d, sig0, s) + acceptance_exact(d, sig1, s));

  lw_model *m = lw_model_new(&sc, unit_splines(n_spl, &w), NULL);
  cr_assert_not_null(m);
  lw_chain *c = point_chain(m, s, seed);
  split_chain(c, domains, threads);
  for (int k = 0; k < 50; k++) lw_chain_sweep(c); /* reach stationarity */
  cr_assert_eq(c->step[LW_MOVE_POINT], s, "tuning is off: the step must not move");

  /* Batch means: successive proposals are correlated through the state,
  ** so the standard error of the rate comes from the scatter of B batch
  ** rates (batches of N/B = 4000+ proposals, ~40 per node, far longer
  ** than the correlation time of a node's acceptance), floored at the
  ** binomial value sqrt(a (1 - a) / N) that independent draws would give.
  ** Whole sweeps, as a run makes them: every node in order, forward or
  ** backward (mc.h), so the rate is that of the sweep order in use.  With
  ** domains a sweep proposes fewer moves (a spline on a domain boundary
  ** waits for the next sweep), so batches count proposals, and a move
  ** rejected for leaving its domain is not one of the Metropolis kernel's
  ** (docs/NUMERICS.md, "Domains"). */
  double sum = 0.0, sum2 = 0.0;
  long per = N / B, acc_all = 0, prop_all = 0;
  for (int b = 0; b < B; b++) {
    const lw_move_stats *st = &c->stats[LW_MOVE_POINT];
    unsigned long acc0 = st->accepted, prop0 = st->proposed - st->outside;
    long prop = 0;
    while (prop < per) {
      cr_assert_eq(lw_chain_sweep(c), LW_OK);
      prop = (long)(st->proposed - st->outside - prop0);
    }
    long acc = (long)(c->stats[LW_MOVE_POINT].accepted - acc0);
    double rb = (double)acc / (double)prop;
    sum += rb;
    sum2 += rb * rb;
    acc_all += acc;
    prop_all += prop;
  }
  double rate = (double)acc_all / (double)prop_all;
  double var_b = (sum2 - sum * sum / B) / (B - 1);
  double se = fmax(sqrt(var_b / B), sqrt(a * (1.0 - a) / (double)prop_all));
  cr_log_info("acceptance d=%d s/sigma=%.1f domains %s threads %d: %.5f exact %.5f se %.1e (outside %lu)", d, ratio,
              domains ? domains : "off", threads, rate, a, se, c->stats[LW_MOVE_POINT].outside);
  /* 5 standard errors: se is estimated from 50 batches, so a false failure
  ** has the probability of |t| > 5 at 49 degrees of freedom, 7.7e-6 (6e-7
  ** were se exact; the binomial floor only lowers it) */
  cr_assert(fabs(rate - a) <= 5.0 * se,
            "d=%d s/sigma=%.2f domains %s threads %d: acceptance %.5f, exact %.5f, standard error %.2g", d, ratio,
            domains ? domains : "off", threads, rate, a, se);
  cr_assert_eq(c->stats[LW_MOVE_POINT].nan, 0);
  model_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

Test(stats, point_move_acceptance_matches_the_gaussian_closed_forms)
{
  const long N = lw_test_long() ? 4000000 : 200000; /* proposals per step size */
  const double ratios[] = {0.3, 1.0, 2.4, 6.0}; /* s / sigma of the start points */
  for (int d = 1; d <= 2; d++)
    for (size_t r = 0; r < sizeof ratios / sizeof ratios[0]; r++)
      acceptance_case(d, ratios[r], 1000 + 10 * (unsigned long)d + r, N, 0.0, NULL, 1);
}

/* The same with the sweeps split into domains, on 1, 2 and 4 threads: the
** same seed gives the same chain on each, so the rate is checked on one and
** the chains compared through it. */
Test(stats, point_move_acceptance_with_domains_on_1_2_4_threads)
{
  const long N = lw_test_long() ? 4000000 : 200000;
  const double ratios[] = {1.0, 2.4};
  const int threads[] = {1, 2, 4};
  for (size_t r = 0; r < sizeof ratios / sizeof ratios[0]; r++)
    for (int k = 0; k < 3; k++) acceptance_case(2, ratios[r], 2000 + r, N, DOMAIN_PERIOD, "2", threads[k]);
}

/* ---- 2. the Boltzmann distribution (chi-square) -------------------------- */

/* Chi-square p-value of the samples against the distribution with CDF
** cdf(x, par) in nb bins of equal probability (expected count n / nb each). */
static double chisq_p(const double *x, size_t n, double (*cdf)(double, const double *), const double *par, int nb)
{
  long count[64] = {0};
  for (size_t i = 0; i < n; i++) {
    int b = (int)floor(cdf(x[i], par) * nb);
    count[b < 0 ? 0 : b >= nb ? nb - 1 : b]++;
  }
  double e = (double)n / nb, chi2 = 0.0;
  for (int b = 0; b < nb; b++) chi2 += (count[b] - e) * (count[b] - e) / e;
  return gsl_cdf_chisq_Q(chi2, nb - 1);
}

static double gaussian_cdf(double x, const double *par) { return gsl_cdf_ugaussian_P((x - par[0]) / par[1]); }

/* ... against N(mu, sd^2). */
static double gaussian_chisq_p(const double *x, size_t n, double mu, double sd, int nb)
{
  const double par[2] = {mu, sd};
  return chisq_p(x, n, gaussian_cdf, par, nb);
}

/*
** The small system: one-segment splines in the well (kx = ky), moved by
** point moves with tuned, then frozen, steps.  The two point x-coordinates
** of a spline are coupled through the samples: their joint density is
** exp(-(kx / 2T) (u - mu)^T M (u - mu)) with M_cd = sum_q w_q a_qc a_qd (a the
** basis columns of p0 and p1), mu solving M mu = sum_q w_q (cx - e_q) a_q
** where e_q carries the fixed vectors.  So p0.x is exactly Gaussian with
** variance (T / kx) (M^-1)_00 = (T / kx) M_11 / det M.
*/
/* The chi-square test on wells of the given period (p0.x of spline j is
** recorded from its own well's centre), the sweeps split by `domains` on
** `threads` threads. */
static void boltzmann_case(double period, const char *domains, int threads)
{
  const int longrun = lw_test_long();
  /* records of every spline; with domains 8 times the splines for an eighth
  ** of the sweeps, the same samples */
  const size_t n_spl = period > 0.0 ? 400 : 50, n_keep = (longrun ? 4000 : 400) * 50 / n_spl;
  const double T = 0.7;
  well w = {2.0, 2.0, period > 0.0 ? period / 2 : 60.0, period > 0.0 ? period / 2 : 40.0, period};
  lw_scene sc;
  well_scene(&sc, &w);
  lw_model *m = lw_model_new(&sc, unit_splines(n_spl, &w), NULL);
  lw_chain *c = point_chain(m, 3.0, 4242);
  split_chain(c, domains, threads);
  c->temperature = T;

  const lw_quad *q = &sc.quad;
  const lw_node *nd = m->sp->node; /* the vectors never move under point moves */
  double M00 = basis_dot(q, 0, 0), M01 = basis_dot(q, 0, 2), M11 = basis_dot(q, 2, 2);
  double b0 = 0.0, b1 = 0.0;
  for (int i = 0; i < q->n; i++) {
    double rest = w.cx - q->pos[i][1] * nd[0].vx - q->pos[i][3] * nd[1].vx;
    b0 += q->w[i] * rest * q->pos[i][0];
    b1 += q->w[i] * rest * q->pos[i][2];
  }
  double det = M00 * M11 - M01 * M01;
  double mu = (M11 * b0 - M01 * b1) / det, sd = sqrt(T / w.kx * M11 / det);

  /* tune, then freeze: sampling must use a fixed step (detailed balance) */
  c->tuning = 1;
  for (int k = 0; k < 200; k++) lw_chain_sweep(c);
  c->tuning = 0;
  double step = c->step[LW_MOVE_POINT];

  /* pilot run: the autocorrelation time of p0.x in sweeps */
  const size_t n_pilot = 2000 * 50 / n_spl;
  double *x = malloc(n_spl * (n_pilot > n_keep ? n_pilot : n_keep) * sizeof *x);
  for (size_t t = 0; t < n_pilot; t++) {
    lw_chain_sweep(c);
    for (size_t j = 0; j < n_spl; j++) x[j * n_pilot + t] = m->sp->node[m->sp->first[j]].px - period * (double)(j % WELL_ROW);
  }
  double tau = lw_series_tau(x, n_spl, n_pilot, NULL);
  cr_assert(tau > 0.5 && tau < 50, "autocorrelation time %.2f sweeps is implausible", tau);
  /* Records 3 tau apart: residual correlations inflate the chi-square's
  ** spread by about 1 + 2 sum_k exp(-3k) ~ 1.1, which at most takes the
  ** false-failure rate at 1e-3 to about 3e-3 (none in 100 seeds). */
  long thin = (long)ceil(3.0 * tau);
  for (size_t t = 0; t < n_keep; t++) {
    for (long k = 0; k < thin; k++) lw_chain_sweep(c);
    for (size_t j = 0; j < n_spl; j++) x[t * n_spl + j] = m->sp->node[m->sp->first[j]].px - period * (double)(j % WELL_ROW);
  }
  cr_assert_eq(c->step[LW_MOVE_POINT], step, "frozen step moved");
  size_t n = n_keep * n_spl;
  double p = gaussian_chisq_p(x, n, mu, sd, 20);
  /* Power: the same samples against the Boltzmann distribution of a 20%
  ** higher temperature (sd 9.5% wider), and against a mean off by 0.1
  ** standard deviations, must fail the same test.  The power checks are
  ** random too: the noncentrality n sum_b (p_b - 1/20)^2 * 20 over the 20
  ** bins of the 20,000 samples is 259 for the wider law and 197 for the
  ** shift (p_b the true law's share of bin b; the binning sees less than
  ** the 2 n e^2 and n d^2 of the whole sample), against the 43.8 of
  ** p = 1e-3 at 19 degrees of freedom, so each fails to reject at 6 sd of
  ** its spread or more.  (1.1 T and 0.05 sd, 73 and 49, passed 4 seeds in
  ** 100: a new random stream could fail them.) */
  double p_wrong_t = gaussian_chisq_p(x, n, mu, sd * sqrt(1.2), 20);
  double p_wrong_mu = gaussian_chisq_p(x, n, mu + 0.1 * sd, sd, 20);
  cr_log_info("chi-square (domains %s, %d threads): tau %.2f sweeps, thin %ld, %zu samples: p %.3g, wrong T p %.3g, "
              "wrong mean p %.3g", domains ? domains : "off", threads, tau, thin, n, p, p_wrong_t, p_wrong_mu);
  cr_assert(p > 1e-3, "p0.x does not follow its Boltzmann distribution: p = %.3g", p);
  cr_assert(p_wrong_t < 1e-3, "the test cannot tell T from 1.2 T: p = %.3g", p_wrong_t);
  cr_assert(p_wrong_mu < 1e-3, "the test cannot see a 0.1 sd shift: p = %.3g", p_wrong_mu);
  free(x);
  model_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

Test(stats, sampled_coordinates_follow_the_boltzmann_distribution)
{
  boltzmann_case(0.0, NULL, 1);
}

/* Split into domains, each phase a product of Metropolis kernels on
** disjoint domains (docs/NUMERICS.md, "Domains"), on 1, 2 and 4 threads. */
Test(stats, sampled_coordinates_follow_the_boltzmann_distribution_with_domains)
{
  const int threads[] = {1, 2, 4};
  for (int k = 0; k < 3; k++) boltzmann_case(DOMAIN_PERIOD, "2", threads[k]);
}

/* The vector and translate moves on their own: their proposals must be
** symmetric as the point move's is (a vector or translate step drawn 1.1
** times longer to the right kept every test green, shifting <v0.x> by 25
** standard errors and <p0.x> by 12 in a mutation tester's runs).  400
** splines in the wells of the domain cases, one kind of move: under vector
** moves the points stay, and (v0.x, v1.x) is Gaussian as (p0.x, p1.x) is
** under point moves (basis columns 1 and 3 for 0 and 2); under translate
** moves the spline keeps its shape, x_q = p0.x s_q + r_q with s_q the
** points' two basis columns summed, so p0.x is Gaussian with precision
** (kx / T) sum_q w_q s_q^2 about sum_q w_q s_q (cx - r_q) / sum_q w_q s_q^2.
** Beside the chi-square, the mean's z-score (records 3 tau apart, so their
** error bar is about sd / sqrt(n), inflated by the residual correlation's
** 1.1 at most): |z| < 5, and a shift of 0.02 sd must read z > 5 (160,000
** records of the vectors: 8 sd of the z-score; 400,000 of the translations,
** whose mutant above read z = -4.2 and chi-square p = 7e-4 on 160,000). */
/* v0.x of spline j, or p0.x from its well's centre (a row of wells) */
static double one_kind_value(const lw_model *m, int kind, size_t j, double period)
{
  const lw_node *a = &m->sp->node[m->sp->first[j]];
  return kind == LW_MOVE_VECTOR ? a->vx : a->px - period * (double)(j % WELL_ROW);
}

static void one_kind_case(int kind)
{
  const int longrun = lw_test_long();
  /* (the translate move's records come cheaper: tau 1.8 sweeps, where the
  ** vectors' is 10) */
  const size_t n_spl = 400, n_keep = (longrun ? 10 : 1) * (kind == LW_MOVE_TRANSLATE ? 1000 : 400);
  const double T = 0.7, period = DOMAIN_PERIOD;
  well w = {2.0, 2.0, period / 2, period / 2, period};
  lw_scene sc;
  well_scene(&sc, &w);
  lw_model *m = lw_model_new(&sc, unit_splines(n_spl, &w), NULL);
  double wt[LW_MOVE_KINDS] = {0}, st[LW_MOVE_KINDS] = {1, 1, 1, 0.1}, tg[LW_MOVE_KINDS] = {0.44, 0.44, 0.3, 0.3};
  wt[kind] = 1;
  lw_error err;
  lw_chain *c = model_chain(m, wt, st, tg, 4243 + (unsigned long)kind, &err);
  cr_assert_not_null(c, "%s", err.msg);
  c->temperature = T;
  const lw_quad *q = &sc.quad;
  const lw_node *nd = m->sp->node; /* spline 0, at the first well */
  double mu, sd;
  if (kind == LW_MOVE_VECTOR) {
    double M00 = basis_dot(q, 1, 1), M01 = basis_dot(q, 1, 3), M11 = basis_dot(q, 3, 3), b0 = 0.0, b1 = 0.0;
    for (int i = 0; i < q->n; i++) {
      double rest = w.cx - q->pos[i][0] * nd[0].px - q->pos[i][2] * nd[1].px;
      b0 += q->w[i] * rest * q->pos[i][1];
      b1 += q->w[i] * rest * q->pos[i][3];
    }
    double det = M00 * M11 - M01 * M01;
    mu = (M11 * b0 - M01 * b1) / det;
    sd = sqrt(T / w.kx * M11 / det);
  } else {
    double K = 0.0, b = 0.0, shape = nd[1].px - nd[0].px;
    for (int i = 0; i < q->n; i++) {
      double s = q->pos[i][0] + q->pos[i][2],
             r = shape * q->pos[i][2] + nd[0].vx * q->pos[i][1] + nd[1].vx * q->pos[i][3];
      K += q->w[i] * s * s;
      b += q->w[i] * s * (w.cx - r);
    }
    mu = b / K;
    sd = sqrt(T / (w.kx * K));
  }
  c->tuning = 1;
  for (int k = 0; k < 200; k++) lw_chain_sweep(c);
  c->tuning = 0;
  const size_t n_pilot = 250;
  double *x = malloc(n_spl * n_keep * sizeof *x);
for (size_t t = 0; t < n_pilot; t++) {
    lw_chain_sweep(c);
    for (size_t j = 0; j < n_spl; j++) x[j * n_pilot + t] = one_kind_value(m, kind, j, period);
  }
  double tau = lw_series_tau(x, n_spl, n_pilot, NULL);
  cr_assert(tau > 0.5 && tau < 50, "autocorrelation time %.2f sweeps is implausible", tau);
  long thin = (long)ceil(3.0 * tau);
  double sum = 0.0;
  for (size_t t = 0; t < n_keep; t++) {
    for (long k = 0; k < thin; k++) lw_chain_sweep(c);
    for (size_t j = 0; j < n_spl; j++) sum += x[t * n_spl + j] = one_kind_value(m, kind, j, period);
  }
  const size_t n = n_keep * n_spl;
  const double se = sd / sqrt((double)n), z = (sum / (double)n - mu) / se;
  double p = gaussian_chisq_p(x, n, mu, sd, 20), p_wrong_t = gaussian_chisq_p(x, n, mu, sd * sqrt(1.2), 20);
  cr_log_info("%s moves alone: tau %.2f sweeps, thin %ld, %zu samples: p %.3g (1.2 T: %.3g), mean %.6f against "
              "%.6f (z %.2f; a shift of 0.02 sd would read %.1f)", c->sys->type->move_names[kind], tau, thin, n, p,
              p_wrong_t, sum / (double)n, mu, z, 0.02 * sd / se);
  cr_assert(p > 1e-3, "%s moves: not the Boltzmann distribution, p = %.3g", c->sys->type->move_names[kind], p);
  cr_assert(p_wrong_t < 1e-3, "the test cannot tell T from 1.2 T: p = %.3g", p_wrong_t);
  cr_assert(fabs(z) < 5, "%s moves: the mean is %.2f error bars off", c->sys->type->move_names[kind], z);
  cr_assert(0.02 * sd / se > 5 * 1.1, "the mean's test cannot see a shift of 0.02 sd");
  free(x);
  model_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

Test(stats, vector_and_translate_moves_alone_follow_the_boltzmann_distribution)
{
  one_kind_case(LW_MOVE_VECTOR);
  one_kind_case(LW_MOVE_TRANSLATE);
}

/* ---- 3. the worm-like chain ----------------------------------------------- */

/*
** E = B int kappa^2 dl makes the tangent angle a random walk in arc length
** with variance 2 s / l_p, l_p = 4 B / T, so (docs/NUMERICS.md)
**     <cos(theta(s) - theta(0))> = exp(-s / l_p)
**     <R^2> = 2 l_p L [1 - (l_p / L)(1 - exp(-L / l_p))]        (Kratky-Porod, 2-D)
**
** The Bezier chain is this continuum chain seen at its nodes only if its
** parametrisation is held: for a straight segment the handle lengths |v|
** change nothing (any |v| up to the segment length gives the same line), so
** they roam freely, and every curved shape then costs more bending than the
** arc it approximates.  Left free they make the chain ~1.4 times stiffer at
** any resolution (measured; docs/NUMERICS.md).  The built-in parametrisation
** term G int (|r'| - l)^2 ds / l (l the segment's length) holds them, next to
** the per-segment strain that holds the length; only built-in terms run.
**
** Discretisation limits, measured at l0 / l_p = 0.05 to 0.2 with the
** parameters below: (a) node tangents decorrelate as a chain with l_p 3 to 4%
** longer at l0 / l_p <= 0.1 (8% at 0.2): the residual handle fluctuations;
** (b) R^2 exceeds Kratky-Porod by ~0.17 l0 / l_p: a cubic cannot carry the
** sub-segment wiggles of the continuum, which shorten R^2 at fixed L by up
** to l0 / (3 l_p).  The bounds used are 0 to 6% for (a) and 0.33 l0 / l_p
** plus the effect of (a) on R^2 for (b), each plus 4 standard errors.
*/
/* Whether l_p measured at a lag (standard error se) is what a chain of l_p
** = want gives: at least want and at most 6% more, the bias (a) above, each
** with 4 standard errors.  The band was two-sided, 6% either way, and a
** bending 13% weaker passed it: the bias is never negative (over 40 seeds
** l_p at lag 1 averaged 10.43 for 10, its standard error 0.107). */
static int wlc_band(double lp_d, double want, double se)
{
  return lp_d >= want - 4.0 * se && lp_d <= 1.06 * want + 4.0 * se;
}

static double kratky_porod(double lp, double L)
{
  return 2.0 * lp * L * (1.0 - lp / L * (1.0 - exp(-L / lp)));
}

/* Mean and standard error over n independent values. */
static void mean_se(const double *v, size_t n, double *mean, double *se)
{
  double s = 0.0, s2 = 0.0;
  for (size_t i = 0; i < n; i++) s += v[i];
  *mean = s / (double)n;
  for (size_t i = 0; i < n; i++) s2 += (v[i] - *mean) * (v[i] - *mean);
  *se = sqrt(s2 / (double)(n - 1) / (double)n);
}

Test(stats, free_chain_matches_the_worm_like_chain)
{
  const int longrun = lw_test_long();
  /* quick: 4 segments (L / l_p = 0.4); long: 8 (L / l_p = 0.8) with ten
  ** times the statistics.  Correlation times of the end-to-end tangent
  ** measured: ~180 sweeps at 4 segments, ~600 at 8, growing ~ n^3 with
  ** local moves (so 20 segments, L / l_p = 2, would need hours); burn-in is
  ** > 20 of them, the sampled run > 100 per chain. */
  const size_t n_seg = longrun ? 8 : 4, n_ch = 50;
  const long burn = longrun ? 20000 : 4000, sweeps = longrun ? 400000 : 20000, every = 5;
  const double T = 1.0, l0 = 1.0, lp = 10.0;
  lw_params p;
  lw_params_defaults(&p);
  p.width = p.height = 1000;
  p.bending = lp * T / 4.0;
  p.strain = 200.0 * T / l0; /* per segment: length sd ~ sqrt(T l0 / 2S) = 5% */
  p.strain_mode = LW_STRAIN_SEGMENT;
  p.parametrisation = 100.0 * T / l0; /* G l0 = 100 T: speed sd ~10% per sample */
  /* The regularity checks off: they are a hard wall in shape space, and the
  ** Kratky-Porod chain has none.  Measured here at their defaults (min_speed
  ** 0.4, regularity 2.6): 13 % of the proposals refused, nearly all by the
  ** ellipse test, and the tangents decorrelate as l_p = 10.97 +- 0.10 (lag
  ** 1) instead of 10.25 +- 0.08 without them; docs/NUMERICS.md. */
  p.min_speed = 0;
  p.regularity = 0;
  lw_scene sc;
  lw_error err;
  cr_assert_eq(lw_scene_init(&sc, &p, &err), LW_OK, "%s", err.msg);
  cr_assert(!sc.on[LW_TERM_USER] && sc.on[LW_TERM_PARAM], "built-in terms only");
  size_t *segs = malloc(n_ch * sizeof *segs);
  for (size_t i = 0; i < n_ch; i++) segs[i] = n_seg;
  lw_splines *sp = lw_splines_new(n_ch, segs, NULL);
  free(segs);
  for (size_t i = 0; i < n_ch; i++) lw_test_straight(sp, i, 500 - 0.5 * n_seg * l0, 500, 500 + 0.5 * n_seg * l0, 500);
  lw_model *m = lw_model_new(&sc, sp, &err);
  cr_assert_not_null(m, "%s", err.msg);
  double w[LW_MOVE_KINDS] = {1, 1, 0, 0}, st[LW_MOVE_KINDS] = {0.1, 0.1, 1, 0.1},
         tg[LW_MOVE_KINDS] = {0.44, 0.44, 0.3, 0.3};
  lw_chain *c = model_chain(m, w, st, tg, 31337, &err);
  c->temperature = T;
  c->tuning = 1;
  for (int k = 0; k < 200; k++) lw_chain_sweep(c);
  c->tuning = 0;
  for (long k = 0; k < burn; k++) lw_chain_sweep(c);

  /* per chain: time averages of cos at each lag, of R^2 and of L */
  const size_t nl = n_seg + 1;
  double *cosl = calloc(n_ch * nl, sizeof *cosl), *r2 = calloc(n_ch, sizeof *r2);
  double *arc = calloc(nl, sizeof *arc), L = 0.0, theta[64], s[64];
  long n_rec = 0;
  for (long k = 0; k < sweeps; k++) {
    lw_chain_sweep(c);
    if (k % every) continue;
    n_rec++;
    for (size_t i = 0; i < n_ch; i++) {
      const lw_node *nd = &m->sp->node[m->sp->first[i]];
      size_t g0 = lw_segment_index(m->sp, i, 0);
      s[0] = 0.0;
      for (size_t j = 0; j <= n_seg; j++) {
        theta[j] = atan2(nd[j].vy, nd[j].vx);
        if (j < n_seg) s[j + 1] = s[j] + m->seg_len[g0 + j];
      }
      for (size_t d = 1; d <= n_seg; d++) {
        double sum = 0.0;
        for (size_t j = 0; j + d <= n_seg; j++) {
          sum += cos(theta[j + d] - theta[j]);
          arc[d] += s[j + d] - s[j];
        }
        cosl[i * nl + d] += sum / (double)(n_seg + 1 - d);
      }
      double dx = nd[n_seg].px - nd[0].px, dy = nd[n_seg].py - nd[0].py;
      r2[i] += dx * dx + dy * dy;
      L += s[n_seg];
    }
  }
  /* Chains are independent: the scatter of their time averages gives honest
  ** standard errors whatever the autocorrelation within a chain. */
  double v[64], mean, se;
  L /= (double)(n_rec * n_ch);
  for (size_t d = 1; d <= n_seg; d++) {
    for (size_t i = 0; i < n_ch; i++) v[i] = cosl[i * nl + d] / (double)n_rec;
    mean_se(v, n_ch, &mean, &se);
    double sd_arc = arc[d] / (double)(n_rec * n_ch * (n_seg + 1 - d));
    /* l_p seen at this lag, and its standard error by the delta method */
    double lp_d = -sd_arc / log(mean), lp_se = sd_arc * se / (mean * log(mean) * log(mean));
    cr_log_info("wlc lag %zu: <cos> %.4f +- %.4f (exact %.4f), l_p %.3f +- %.3f", d, mean, se,
                exp(-sd_arc / lp), lp_d, lp_se);
    if (d == 1 || d == n_seg) {
      cr_assert(wlc_band(lp_d, lp, lp_se), "lag %zu: tangents decorrelate with l_p %.3f +- %.3f, expected %.3f to "
                "6%% more", d, lp_d, lp_se, lp);
    }
    /* power: a bending 10% weaker lies outside the band at lag 1 (measured
    ** over 40 seeds, the mean at lag 1 is 4.5 of its standard errors above
    ** that band) */
    if (d == 1) cr_assert(!wlc_band(lp_d, 0.9 * lp, lp_se), "no power to see l_p off by 10%%");
  }
  for (size_t i = 0; i < n_ch; i++) v[i] = r2[i] / (double)n_rec;
  mean_se(v, n_ch, &mean, &se);
  double kp = kratky_porod(lp, L);
  /* bias bound: sub-segment wiggles (0.33 l0 / l_p) plus a 6% longer l_p */
  double bias = 0.33 * l0 / lp + fabs(kratky_porod(1.06 * lp, L) / kp - 1.0);
  cr_log_info("wlc R^2 %.4f +- %.4f, Kratky-Porod %.4f (L %.4f): %+.4f, bound %.4f", mean, se, kp, L,
              mean / kp - 1.0, bias);
  /* one-sided, as the l_p band: both biases lengthen R^2, and a band of
  ** 4 % either way let a chain 30 % too flexible (R^2 5.1 % short) pass */
  cr_assert(mean / kp - 1.0 >= -4.0 * se / kp && mean / kp - 1.0 <= bias + 4.0 * se / kp,
            "<R^2> %.4f +- %.4f against Kratky-Porod %.4f, bias up to %+.4f", mean, se, kp, bias);
  const double kp_soft = kratky_porod(0.7 * lp, L);
  cr_assert(mean / kp_soft - 1.0 > bias + 4.0 * se / kp_soft, "no power to see l_p 30 %% short in <R^2>");
  free(cosl);
  free(r2);
  free(arc);
  model_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
}

/* ---- 4. delayed acceptance ------------------------------------------------ */

/* The first stage alone: what a chain samples if the second stage never
** refused (the commit still finishes the proposal, so the totals stay
** exact): the distribution of the stand-in, which the test must tell apart. */
static double stand_in_only(void *state, void *prop, int *nomem)
{
  (void)state;
  (void)prop;
  (void)nomem;
  return 0.0;
}

/* The time average of the pair energy of a chain of `sweeps` sweeps (after
** a quarter as many to settle) on four lines of 3 mm in a box of 6 mm at T =
** 0.05, C = 0.01: with the row's delayed acceptance as it is (mode 0),
** without it (1), or its first stage alone (2).  A near radius of 3
** elements makes most pairs near and the stand-in (which holds distances at
** 1.5 elements or more) a poor one, so the first stage alone is far off. */
static double da_mean(int mode, long sweeps, unsigned long seed, double *acc)
{
  lw_params p;
  lw_params_defaults(&p);
  p.width = p.height = 6;
  p.margin = 0.5;
  p.strain = 2;
  p.bending = 0.05;
  p.boundary_coef = 1;
  p.pair = 0.01;
  p.pair_cutoff = 2;
  p.pair_near = 3;
  lw_scene sc;
  lw_test_scene(&sc, &p);
  lw_model *m = lw_test_model_random(&sc, 4, 1, 3.0, seed);
  double w[LW_MOVE_KINDS] = {1, 1, 0, 0}, st[LW_MOVE_KINDS] = {0.25, 0.25, 1, 0.1},
         tg[LW_MOVE_KINDS] = {0.44, 0.44, 0.3, 0.3};
  lw_error err;
  lw_chain *c = model_chain(m, w, st, tg, seed, &err);
  cr_assert_not_null(c, "%s", err.msg);
  c->temperature = 0.05;
  c->tuning = 0;
  c->delayed = mode != 1;
  lw_system_type row = *c->sys->type;
  if (mode == 2) row.finish = stand_in_only;
  c->sys->type = &row;
  for (long k = 0; k < sweeps / 4; k++) lw_chain_sweep(c);
  double sum = 0.0;
  for (long k = 0; k < sweeps; k++) {
    lw_chain_sweep(c);
    sum += m->term[LW_TERM_PAIR];
  }
  *acc = (double)c->stats[0].accepted / (double)c->stats[0].proposed;
  model_chain_free(c);
  lw_model_free(m);
  lw_scene_clear(&sc);
  return sum / (double)sweeps;
}

/*
** Delayed acceptance (system.h, docs/NUMERICS.md) decides on a stand-in
** for the near field first and on the difference second; it must sample
** exp(-E/T) as plain Metropolis does.  Observable: the mean pair energy of
** four lines crowded into a box, where near pairs are frequent, from
** CHAINS independent chains per mode (the scatter of their time averages
** is an honest standard error whatever the autocorrelation).  Tolerance:
** 4 combined standard errors.  Power: the first stage alone (a chain that
** skipped the second) samples the stand-in's distribution, which lets lines
** come closer; the same test must tell it apart from plain Metropolis, by 3
** combined standard errors.  Its chains are erratic (one that jams triples
** the standard error of 12), so it runs three times as many: with 12, over
** 20 seeds it stood 1.9 to 11.3 standard errors off, and 4 were asked; with
** 36, over 13 seeds 5.9 to 12.8 (measured 2026-12-05).
*/
Test(stats, delayed_acceptance_samples_the_boltzmann_distribution, .timeout = 300)
{
  enum { CHAINS = 12, STAGE_CHAINS = 3 * CHAINS };
  const long sweeps = lw_test_long() ? 8000 : 1000;
  double mean[3], se[3];
  for (int mode = 0; mode < 3; mode++) {
    double v[STAGE_CHAINS], acc;
    const int n = mode == 2 ? STAGE_CHAINS : CHAINS;
    for (int k = 0; k < n; k++) v[k] = da_mean(mode, sweeps, 100 + (unsigned long)k, &acc);
    mean_se(v, (size_t)n, &mean[mode], &se[mode]);
    cr_log_info("delayed acceptance, mode %d: <E_pair> %.5f +- %.5f, acceptance %.3f", mode, mean[mode], se[mode],
                acc);
  }
  const double tol = 4.0 * hypot(se[0], se[1]);
  cr_assert(fabs(mean[0] - mean[1]) <= tol, "delayed %.5f +- %.5f, plain %.5f +- %.5f", mean[0], se[0], mean[1],
            se[1]);
  cr_log_info("delayed acceptance: the first stage alone is %.2f standard errors off",
              fabs(mean[2] - mean[1]) / hypot(se[2], se[1]));
  cr_assert(fabs(mean[2] - mean[1]) > 3.0 * hypot(se[2], se[1]),
            "no power: the first stage alone gives %.5f +- %.5f, plain %.5f +- %.5f", mean[2], se[2], mean[1], se[1]);
}

/* ---- 5. oriented particles ------------------------------------------------ */

/*
** The particle row through the same chain.  Two small systems with exact
** Boltzmann distributions:
**
**   heights: particles with no pair term, gravity g (energy g z) above a
**   hard floor at z0: each height above the floor is exponential with rate
**   g / T, each normal uniform on the sphere, so n_z is uniform on [-1, 1]
**   (Archimedes) whatever the rotate move's axis and angle law, as long as
**   its proposal is symmetric;
**
**   co-normal pairs: two particles held in place at distance d, normals
**   free, alpha_N w |n_i - n_j|^2 = 2 alpha_N w (1 - c) with c = n_i . n_j.
**   Under uniform orientations c is uniform on [-1, 1], so its Boltzmann
**   density is proportional to exp(kappa c), kappa = 2 alpha_N w / T.  The
**   pairs stand 10 r0 apart, beyond each other's range.
**
** Steps are tuned, then frozen; records are 3 autocorrelation times apart,
** as in section 2, and the same 1e-3 thresholds hold, with the power of each
** test shown on a wrong distribution.
*/
static double exponential_cdf(double z, const double *par) { return -expm1(-par[0] * z); }

static double uniform_cdf(double c, const double *par) { return 0.5 * (c + 1.0); }

static double tilted_cdf(double c, const double *par) { return expm1(par[0] * (c + 1.0)) / expm1(2.0 * par[0]); }

/* Tunes the chain's steps at temperature T for 200 sweeps and freezes them,
** then samples: record(p, t, x) writes the n_ser values of record t into x
** series-major (x[j * n + t] for a pilot of n records) or record-major.
** Returns the samples, n_keep records of n_ser, 3 tau apart. */
typedef void particle_record(const lw_particles *p, double *v);

static double *sample_particles(lw_chain *c, const lw_particles *p, particle_record *rec, size_t n_ser, size_t n_keep,
                                double *tau_out)
{
  c->tuning = 1;
  for (int k = 0; k < 200; k++) cr_assert_eq(lw_chain_sweep(c), LW_OK);
  c->tuning = 0;
  const size_t n_pilot = 2000;
  double *x = malloc(n_ser * (n_pilot > n_keep ? n_pilot : n_keep) * sizeof *x), *v = malloc(n_ser * sizeof *v);
  for (size_t t = 0; t < n_pilot; t++) {
    cr_assert_eq(lw_chain_sweep(c), LW_OK);
    rec(p, v);
    for (size_t j = 0; j < n_ser; j++) x[j * n_pilot + t] = v[j];
  }
  double tau = lw_series_tau(x, n_ser, n_pilot, NULL);
  cr_assert(tau > 0.5 && tau < 50, "autocorrelation time %.2f sweeps is implausible", tau);
  long thin = (long)ceil(3.0 * tau);
  for (size_t t = 0; t < n_keep; t++) {
    for (long k = 0; k < thin; k++) cr_assert_eq(lw_chain_sweep(c), LW_OK);
    rec(p, x + t * n_ser);
  }
  free(v);
  *tau_out = tau;
  return x;
}

static lw_params particle_scene(void)
{
  lw_params prm;
  lw_params_defaults(&prm);
  strcpy(prm.system, "particles");
  prm.pt_alpha_lj = prm.pt_alpha_p = prm.pt_alpha_n = prm.pt_alpha_c = 0;
  return prm;
}

#define FLOOR_Z (-1.0)

static void record_heights(const lw_particles *p, double *v)
{
  for (size_t i = 0; i < p->n; i++) v[i] = p->x[3 * i + 2] - FLOOR_Z;
}

static void record_normals(const lw_particles *p, double *v)
{
  for (size_t i = 0; i < p->n; i++) v[i] = p->nrm[3 * i + 2];
}

static void record_cosines(const lw_particles *p, double *v)
{
  for (size_t k = 0; k < p->n / 2; k++) {
    const double *a = p->nrm + 6 * k, *b = a + 3;
    v[k] = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  }
}

/* 100 particles, gravity 1 over a hard floor, T = 0.5: heights against the
** exponential of rate 2 (and, for power, of rate 2 / 1.1: T 10 % high) and
** n_z against the uniform law (power: against the tilt kappa = 0.1, a mean
** 0.033 higher). */
Test(stats, particle_heights_and_normals_follow_the_boltzmann_distribution)
{
  const int longrun = lw_test_long();
  const double T = 0.5, g = 1.0;
  lw_params prm = particle_scene();
  prm.pt_count = 100;
  prm.pt_gravity = g;
  prm.pt_boundary = LW_PBOUNDARY_PLANE;
  prm.pt_boundary_z = FLOOR_Z;
  prm.pt_alpha_b = 0;
  lw_error err;
  lw_particles_setup *s = lw_particles_setup_new(&prm, &err);
  cr_assert_not_null(s, "%s", err.msg);
  lw_particles *p = lw_particles_new(s, 17, NULL, &err);
  cr_assert_not_null(p, "%s", err.msg);
  lw_system *sys = lw_system_wrap(&lw_system_particles, p, &err);
  cr_assert_not_null(sys, "%s", err.msg);
  const double w[2] = {1, 1}, st[2] = {0.3, 0.5}, tg[2] = {0.44, 0.44};
  lw_chain *c = lw_chain_new(sys, w, st, tg, 99, &err);
  cr_assert_not_null(c, "%s", err.msg);
  c->temperature = T;
  const size_t n_keep = longrun ? 4000 : 400, n = n_keep * p->n;
  double tau_z, tau_n;
  double *z = sample_particles(c, p, record_heights, p->n, n_keep, &tau_z);
  double *nz = sample_particles(c, p, record_normals, p->n, n_keep, &tau_n);
  const double rate = g / T, rate_hot = g / (1.1 * T), tilt = 0.1;
  double pz = chisq_p(z, n, exponential_cdf, &rate, 20), pz_hot = chisq_p(z, n, exponential_cdf, &rate_hot, 20);
  double pn = chisq_p(nz, n, uniform_cdf, NULL, 20), pn_tilt = chisq_p(nz, n, tilted_cdf, &tilt, 20);
  cr_log_info("particles: heights tau %.2f sweeps, p %.3g (1.1 T: %.3g); n_z tau %.2f, p %.3g (tilted: %.3g); %zu "
              "samples each", tau_z, pz, pz_hot, tau_n, pn, pn_tilt, n);
  cr_assert(pz > 1e-3, "heights do not follow exp(-g z / T): p = %.3g", pz);
  cr_assert(pn > 1e-3, "normals are not uniform: p = %.3g", pn);
  cr_assert(pz_hot < 1e-3, "the test cannot tell T from 1.1 T: p = %.3g", pz_hot);
  cr_assert(pn_tilt < 1e-3, "the test cannot see a tilt of 0.1: p = %.3g", pn_tilt);
  free(z);
  free(nz);
  lw_chain_free(c);
  lw_system_free(sys);
  lw_particles_setup_free(s);
}

/* 40 pairs held 1 r0 apart (poly weight w = (1 - 1/1.6^2)^3), alpha_N = 1,
** T = 0.2: kappa = 10 w = 2.26, against kappa 2.26 / 1.1 for power. */
Test(stats, co_normal_pairs_follow_the_boltzmann_distribution)
{
  const int longrun = lw_test_long();
  const double T = 0.2, d = 1.0;
  lw_params prm = particle_scene();
  prm.pt_alpha_n = 1;
  lw_error err;
  lw_particles_setup *s = lw_particles_setup_new(&prm, &err);
  cr_assert_not_null(s, "%s", err.msg);
  enum { PAIRS = 40 };
  double x[6 * PAIRS] = {0}, q[8 * PAIRS] = {0};
  unsigned char pin[2 * PAIRS];
  for (int k = 0; k < 2 * PAIRS; k++) {
    x[3 * k] = 10.0 * (k / 2) + d * (k % 2);
    q[4 * k] = 1.0;
    pin[k] = LW_PIN_POSITION;
  }
  lw_particles *p = lw_particles_new_from(s, 2 * PAIRS, x, q, pin, &err);
  cr_assert_not_null(p, "%s", err.msg);
  lw_system *sys = lw_system_wrap(&lw_system_particles, p, &err);
  cr_assert_not_null(sys, "%s", err.msg);
  const double w[2] = {0, 1}, st[2] = {0.1, 0.5}, tg[2] = {0.44, 0.44};
  lw_chain *c = lw_chain_new(sys, w, st, tg, 7, &err);
  cr_assert_not_null(c, "%s", err.msg);
  c->temperature = T;
  const size_t n_keep = longrun ? 10000 : 1000, n = n_keep * PAIRS;
  double tau;
  double *cs = sample_particles(c, p, record_cosines, PAIRS, n_keep, &tau);
  const double wt = pow(1.0 - d * d / (1.6 * 1.6), 3.0), kappa = 2.0 * prm.pt_alpha_n * wt / T, hot = kappa / 1.1;
  double pc = chisq_p(cs, n, tilted_cdf, &kappa, 20), pc_hot = chisq_p(cs, n, tilted_cdf, &hot, 20);
  cr_log_info("co-normal pairs: kappa %.4f, tau %.2f sweeps, %zu samples: p %.3g (1.1 T: %.3g)", kappa, tau, n, pc,
              pc_hot);
  cr_assert(pc > 1e-3, "n_i . n_j does not follow exp(kappa c): p = %.3g", pc);
  cr_assert(pc_hot < 1e-3, "the test cannot tell T from 1.1 T: p = %.3g", pc_hot);
  free(cs);
  lw_chain_free(c);
  lw_system_free(sys);
  lw_particles_setup_free(s);
}

/* ---- 6. births and deaths of particles ------------------------------------ */

/*
** One particle held at the origin (normal +z, pinned), a second one born and
** killed in its tangent plane (particles_grow.h), turned by rotate moves,
** never translated, at most two particles: the chain moves between N = 1
** and N = 2.  With alpha_N the energy of the pair is 2 alpha_N w(r) (1 - c),
** c = n . z, so the exact Boltzmann weights against the reference measure
** dx / r0^3 times the rotation group's are
**
**     P(2) / P(1) = e^(-chem/T) int_S dx / r0^3 K(beta(r)),
**     K(beta) = (1/2) int e^(-beta (1 - c)) dc = (1 - e^(-2 beta)) / (2 beta),
**     beta(r) = 2 alpha_N w(r) / T,
**
** S the annulus 0.75 <= rho <= 1.25 r0 times the slab |h| <= 0.25 r0 that a
** birth reaches from the held particle, and given N = 2 the cosine c has the
** CDF int_S dx (e^(-beta (1 - c)) - e^(-2 beta)) / beta over int_S dx 2 K.
** chem is set so that P(2) = P(1).  A Hastings factor that left out the
** proposal's position density would move P(2) by vol(S) (1.57 r0^3), one
** that left out its normal density would bend c toward the proposal's.
** In r0's units nothing depends on r0: at r0 = 2 too P(2) = P(1) (a
** density counted in r0^3 twice put P(2) at 1/9).
*/
typedef struct {
  double alpha, T;
} grow_case;

/* int_S dx / r0^3 f(beta(r)) by the midpoint rule (the integrand is smooth
** on S; 400 x 200 cells give 1e-6 relative). */
static double over_spread(const grow_case *g, double (*f)(double beta, const double *par), const double *par)
{
  const int nr = 400, nh = 200;
  const double a = 0.75, b = 1.25, c = 0.25;
  double sum = 0.0;
  for (int i = 0; i < nr; i++) {
    double rho = a + (b - a) * (i + 0.5) / nr;
    for (int k = 0; k < nh; k++) {
      double h = -c + 2 * c * (k + 0.5) / nh, r2 = rho * rho + h * h, t = 1 - r2 / (1.6 * 1.6);
      sum += 2 * M_PI * rho * f(2 * g->alpha * t * t * t / g->T, par);
    }
  }
  return sum * (b - a) / nr * 2 * c / nh;
}

static double grow_k(double beta, const double *par) { return -expm1(-2 * beta) / (2 * beta); }

/* the CDF's numerator at c = par[0] */
static double grow_below(double beta, const double *par)
{
  return (exp(-beta * (1 - par[0])) - exp(-2 * beta)) / beta;
}

#define GROW_CDF_POINTS 401
static double grow_cdf_table[GROW_CDF_POINTS];

static double grow_cdf(double c, const double *par)
{
  double u = (c + 1) / 2 * (GROW_CDF_POINTS - 1);
  if (u <= 0) return 0;
  if (u >= GROW_CDF_POINTS - 1) return 1;
  int i = (int)u;
  return grow_cdf_table[i] + (u - i) * (grow_cdf_table[i + 1] - grow_cdf_table[i]);
}

static void births_and_deaths_at(double r0)
{
  const int longrun = lw_test_long();
  const grow_case g = {1.0, 0.2};
  const double K = over_spread(&g, grow_k, NULL), chem = g.T * log(K);
  double total = over_spread(&g, grow_k, NULL) * 2;
  for (int i = 0; i < GROW_CDF_POINTS; i++) {
    double c = -1 + 2.0 * i / (GROW_CDF_POINTS - 1);
    grow_cdf_table[i] = over_spread(&g, grow_below, &c) / total;
  }
  lw_params prm = particle_scene();
  prm.pt_alpha_n = g.alpha;
  prm.pt_count = 10; /* a sweep: 10 proposals */
  prm.pt_birth = prm.pt_death = 1;
  prm.pt_chem = chem;
  prm.pt_max_count = 2;
  prm.pt_r0 = r0;
  lw_error err;
  lw_particles_setup *s = lw_particles_setup_new(&prm, &err);
  cr_assert_not_null(s, "%s", err.msg);
  const double x[3] = {0, 0, 0}, q[4] = {1, 0, 0, 0};
  const unsigned char pin[1] = {LW_PIN_POSITION | LW_PIN_ORIENTATION};
  lw_particles *p = lw_particles_new_from(s, 1, x, q, pin, &err);
  cr_assert_not_null(p, "%s", err.msg);
  lw_system *sys = lw_system_wrap(&lw_system_particles_grow, p, &err);
  cr_assert_not_null(sys, "%s", err.msg);
  const double w[4] = {0, 1, 1, 1}, st[4] = {0.1, 0.5, 0, 0}, tg[4] = {0.44, 0.44, 0.44, 0.44};
  lw_chain *c = lw_chain_new(sys, w, st, tg, 11, &err);
  cr_assert_not_null(c, "%s", err.msg);
  c->temperature = g.T;
  c->tuning = 1;
  for (int k = 0; k < 300; k++) cr_assert_eq(lw_chain_sweep(c), LW_OK);
  c->tuning = 0;
  /* the occupation, a sweep apart, and the cosines of the born particle */
  const size_t n = longrun ? 400000 : 40000;
  double *occ = malloc(n * sizeof *occ), *cs = malloc(n * sizeof *cs);
  size_t n_cs = 0;
  for (size_t t = 0; t < n; t++) {
    cr_assert_eq(lw_chain_sweep(c), LW_OK);
    occ[t] = (double)(p->n - 1);
    if (p->n == 2) cs[n_cs++] = p->nrm[3 + 2];
  }
  double tau = lw_series_tau(occ, 1, n, NULL), f = 0;
  for (size_t t = 0; t < n; t++) f += occ[t];
  f /= (double)n;
  double sd = sqrt(0.25 * 2 * tau / (double)n);
  /* the cosines, thinned to about 3 tau of the occupation apart (a born
  ** particle's normal also turns by rotate moves while it lives) */
  size_t thin = (size_t)ceil(3 * tau), m = 0;
  for (size_t i = 0; i < n_cs; i += thin) cs[m++] = cs[i];
  double pc = chisq_p(cs, m, grow_cdf, NULL, 20);
  cr_log_info("births and deaths at r0 %g: K %.5f, chem %.5f; P(2) %.4f +- %.4f (tau %.2f sweeps, %zu sweeps), "
              "want 0.5; cosines: %zu samples, p %.3g; birth acceptance %.3f, death %.3f", r0, K, chem, f, sd, tau, n,
              m, pc,
              (double)c->stats[2].accepted / (double)c->stats[2].proposed,
              (double)c->stats[3].accepted / (double)c->stats[3].proposed);
  cr_assert_lt(fabs(f - 0.5), 4 * sd, "r0 %g: P(2) = %.4f, want 0.5 +- %.4f (4 sd)", r0, f, 4 * sd);
  cr_assert(pc > 1e-3, "r0 %g: the born particle's normals: p = %.3g", r0, pc);
  free(occ);
  free(cs);
  lw_chain_free(c);
  lw_system_free(sys);
  lw_particles_setup_free(s);
}

Test(stats, particle_births_and_deaths_follow_the_boltzmann_distribution)
{
  births_and_deaths_at(1.0);
  births_and_deaths_at(2.0);
}
