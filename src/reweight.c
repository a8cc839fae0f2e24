/* reweight.c -- multiple-histogram reweighting between tempering rungs
** (reweight.h). */
#include "linewise/reweight.h"

#include <gsl/gsl_linalg.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/mc.h"
#include "linewise/series.h"
#include "linewise/number.h"

/* Energies are taken about their mean, so the exponents stay near the
** spread of beta E rather than its size. */
static double mean_of(const double *E, size_t n)
{
  double m = 0.0;
  for (size_t i = 0; i < n; i++) m += (E[i] - m) / (double)(i + 1);
  return m;
}

/* A term of a sum of exponentials more than this below its largest (in
** the exponent) is under 1e-18 of the sum, beneath its last digit: its
** exp is not taken.  A sample at one rung of a ladder shares its energy
** with a few rungs about it, so at 128 rungs all but a handful of the
** K exponentials a sample and the n a rung went (2.5 minutes there). */
#define NEGLIGIBLE 41.5

/* ln sum_i exp(-b e_i - ln D_i). */
static double log_partition(const double *E, size_t n, double eref, const double *log_d, double b)
{
  double top = -INFINITY, s = 0.0;
  for (size_t i = 0; i < n; i++) {
    const double v = -b * (E[i] - eref) - log_d[i];
    if (v > top) top = v; /* (not fmax: a call into libm here) */
  }
  for (size_t i = 0; i < n; i++) {
    const double v = -b * (E[i] - eref) - log_d[i] - top;
    if (v > -NEGLIGIBLE) s += exp(v);
  }
  return top + log(s);
}

/* One pass over the samples at f (about eref): ln D_i into log_d, and the
** sums of W_ik = exp(f_k - beta_k e_i) / D_i, s[k] = sum_i W_ik and ww[k K
** + l] = sum_i W_ik W_il (w: K of scratch).  The equations hold where
** every s_k = 1; returns the largest |s_k - 1|. */
static double pass(const double *E, size_t n, double eref, const double *log_n, const double *f, const double *beta,
                   int K, double *log_d, double *s, double *ww, double *w)
{
  memset(s, 0, (size_t)K * sizeof *s);
  memset(ww, 0, (size_t)K * (size_t)K * sizeof *ww);
  for (size_t i = 0; i < n; i++) {
    /* ln D_i = ln sum_m N_m exp(f_m - beta_m e_i), by its largest term;
    ** W_ik = N_k exp(f_k - beta_k e_i) / D_i / N_k: the terms the sum took,
    ** over the sum (a second exp a rung before) */
    const double e = E[i] - eref;
    double top = -INFINITY, sum = 0.0;
    for (int k = 0; k < K; k++) {
      w[k] = log_n[k] + f[k] - beta[k] * e;
      if (w[k] > top) top = w[k];
    }
    int lo = K, hi = -1;
    for (int k = 0; k < K; k++)
      if (w[k] - top > -NEGLIGIBLE) {
        w[k] = exp(w[k] - top);
        sum += w[k];
        if (lo == K) lo = k;
        hi = k;
      } else {
        w[k] = 0.0;
      }
    log_d[i] = top + log(sum);
    for (int k = lo; k <= hi; k++) {
      w[k] /= sum * exp(log_n[k]);
      s[k] += w[k];
    }
    /* ww only steers Newton's step (the sums s, which the solution must
    ** meet, are whole): a sample weighs in at the rungs whose energies it
    ** shares, a run of neighbours on a ladder, and the products of the rest
    ** (0 within the run), under 1e-18 of its largest, change no step; the
    ** run's rows are whole, which the compiler takes two at a time */
    for (int a = lo; a <= hi; a++) {
      const double wa = w[a];
      double *row = ww + (size_t)a * (size_t)K;
#pragma omp simd
      for (int b = lo; b <= a; b++) row[b] += wa * w[b];
    }
  }
  double worst = 0.0;
  for (int k = 0; k < K; k++) worst = fmax(worst, fabs(s[k] - 1.0));
  return worst;
}

/* The Newton step of f_1 .. f_{K-1} (f_0 held) on the convex function
** sum_i ln D_i - sum_k N_k f_k, whose gradient is N_k (s_k - 1) and whose
** Hessian is N_k s_k delta_kl - N_k N_l ww_kl; 0 when the Hessian is not
** positive definite (states that share nothing). */
static int newton_step(const double *log_n, const double *s, const double *ww, int K, double *step)
{
  const size_t m = (size_t)K - 1;
  gsl_matrix *h = gsl_matrix_alloc(m, m);
  gsl_vector *g = gsl_vector_alloc(m), *x = gsl_vector_alloc(m);
  int ok = h && g && x;
  for (size_t a = 0; ok && a < m; a++) {
    double na = exp(log_n[a + 1]);
    gsl_vector_set(g, a, -na * (s[a + 1] - 1.0));
    for (size_t b = 0; b <= a; b++) {
      double v = -na * exp(log_n[b + 1]) * ww[(a + 1) * (size_t)K + b + 1] + (a == b ? na * s[a + 1] : 0.0);
      gsl_matrix_set(h, a, b, v);
      gsl_matrix_set(h, b, a, v);
    }
  }
  lw_gsl_off(); /* (on the bootstrap's threads too: error.h) */
  ok = ok && !gsl_linalg_cholesky_decomp1(h) && !gsl_linalg_cholesky_solve(h, g, x);
  lw_gsl_on();
  step[0] = 0.0;
  for (size_t a = 0; ok && a < m; a++) step[a + 1] = gsl_vector_get(x, a);
  gsl_matrix_free(h);
  gsl_vector_free(g);
  gsl_vector_free(x);
  return ok;
}

lw_status lw_reweight_solve(const double *E, const size_t *first, const double *beta, int K, int warm, double *f,
                            double *log_den, int *iterations, lw_error *err)
{
  if (K < 1) return lw_error_set(err, LW_EINPUT, "no states to reweight");
  const size_t n = first[K];
  const size_t k1 = (size_t)K;
  double *log_d = malloc((n ? n : 1) * sizeof *log_d), *log_n = malloc(k1 * sizeof *log_n),
         *mean = malloc(k1 * sizeof *mean), *next = malloc(k1 * sizeof *next), *s_sum = malloc(k1 * sizeof *s_sum),
         *ww = malloc(k1 * k1 * sizeof *ww), *w = malloc(k1 * sizeof *w), *step = malloc(k1 * sizeof *step),
         *trial = malloc(k1 * sizeof *trial);
  int *order = malloc(k1 * sizeof *order);
  lw_status st = LW_OK;
  if (!log_d || !log_n || !mean || !next || !s_sum || !ww || !w || !step || !trial || !order) {
    st = lw_error_set(err, LW_ENOMEM, "out of memory reweighting %zu samples", n);
    goto done;
  }
  const double eref = mean_of(E, n);
  /* the start: the thermodynamic integral of <E> over beta, in beta's order */
  for (int k = 0; k < K; k++) {
    log_n[k] = log((double)(first[k + 1] - first[k]));
    mean[k] = mean_of(E + first[k], first[k + 1] - first[k]) - eref;
    order[k] = k;
  }
  for (int a = 1; a < K; a++)
    for (int b = a; b > 0 && beta[order[b]] < beta[order[b - 1]]; b--) {
      int tmp = order[b];
      order[b] = order[b - 1];
      order[b - 1] = tmp;
    }
  if (warm) { /* f as given, about eref */
    for (int k = 0; k < K; k++) f[k] -= (beta[k] - beta[0]) * eref;
  } else {
    f[order[0]] = 0.0;
    for (int a = 1; a < K; a++) {
      int p = order[a - 1], q = order[a];
      f[q] = f[p] + (beta[q] - beta[p]) * 0.5 * (mean[p] + mean[q]);
    }
    for (int k = K - 1; k >= 0; k--) f[k] -= f[0]; /* the constant: f_0 = 0, which Newton holds */
  }
  /* Newton's steps, halved until the equations are met better, else the
  ** self-consistent step (the equations' own iteration: slow where states
  ** overlap little, but never lost) */
  int it = 0;
  double worst = pass(E, n, eref, log_n, f, beta, K, log_d, s_sum, ww, w);
  /* settled where the free energies stand still, or where the equations
  ** hold and they barely move: equations met while the f move by whole
  ** units are rungs that barely constrain each other (a table of such f
  ** read C = 768734 +- 5.1e5), not a solution */
  for (double change = INFINITY; change > LW_REWEIGHT_TOL && (worst > LW_REWEIGHT_TOL || change > 1e-6); it++) {
    /* a resample's free energies need not be known to 1e-10 (their spread is
    ** what is sought): one that creeps at that level (blocks of few rows
    ** where the rungs barely overlap) is taken as it stands */
    if (it == LW_REWEIGHT_ITER && warm && change <= 1e-6) break;
    if (it == LW_REWEIGHT_ITER) {
      st = lw_error_set(err, LW_EINPUT, "reweighting did not settle in %d iterations (last change %.3g): the "
                        "rungs' energies barely overlap", LW_REWEIGHT_ITER, change);
      goto done;
    }
    for (int k = 0; k < K; k++) next[k] = -log_partition(E, n, eref, log_d, beta[k]);
    for (int k = K - 1; k >= 0; k--) next[k] -= next[0];
    int newton = K > 1 && newton_step(log_n, s_sum, ww, K, step);
    double t = 1.0, tried = INFINITY;
    for (; newton && t > 1e-3; t *= 0.5) {
      for (int k = 0; k < K; k++) trial[k] = f[k] + t * step[k];
      if ((tried = pass(E, n, eref, log_n, trial, beta, K, log_d, s_sum, ww, w)) < worst) break;
    }
    if (!(tried < worst)) memcpy(trial, next, (size_t)K * sizeof *trial);
    change = 0.0;
    for (int k = 0; k < K; k++) change = fmax(change, fabs(trial[k] - f[k]));
    memcpy(f, trial, (size_t)K * sizeof *f);
    worst = tried < worst ? tried : pass(E, n, eref, log_n, f, beta, K, log_d, s_sum, ww, w);
    if (!isfinite(change) || isnan(worst)) {
      st = lw_error_set(err, LW_EINPUT, "reweighting failed: the free energies are not finite (energies or "
                        "temperatures beyond what the sums can hold)");
      goto done;
    }
  }
  /* back from the energies about eref: f_k shifts by beta_k eref, and
  ** ln D_i by beta_0 eref, which no normalised weight sees */
  for (int k = K - 1; k >= 0; k--) f[k] += (beta[k] - beta[0]) * eref;
  if (log_den) memcpy(log_den, log_d, n * sizeof *log_den);
  if (iterations) *iterations = it;
done:
  free(log_d);
  free(log_n);
  free(mean);
  free(next);
  free(s_sum);
  free(ww);
  free(w);
  free(step);
  free(trial);
  free(order);
  return st;
}

void lw_reweight_at(const double *E, size_t n, const double *log_den, double b, double *mean_energy,
                    double *heat_capacity)
{
  const double eref = mean_of(E, n);
  /* the weights' sums in one pass, scaled by the largest weight so far */
  double top = -INFINITY, w = 0.0, m1 = 0.0, m2 = 0.0;
  for (size_t i = 0; i < n; i++) {
    double e = E[i] - eref, lw = -b * e - log_den[i];
    if (lw > top) {
      double scale = exp(top - lw);
      w *= scale;
      m1 *= scale;
      m2 *= scale;
      top = lw;
    }
    double wi = exp(lw - top);
    w += wi;
    m1 += wi * e;
    m2 += wi * e * e;
  }
  m1 /= w;
  *mean_energy = eref + m1;
  *heat_capacity = b * b * fmax(m2 / w - m1 * m1, 0.0);
}

double lw_reweight_overlap(const double *E, size_t n, const double *log_den, double b1, double b2)
{
  const double eref = mean_of(E, n);
  double top1 = -INFINITY, top2 = -INFINITY;
  for (size_t i = 0; i < n; i++) {
    double e = E[i] - eref;
    top1 = fmax(top1, -b1 * e - log_den[i]);
    top2 = fmax(top2, -b2 * e - log_den[i]);
  }
  double s1 = 0.0, s2 = 0.0;
  for (size_t i = 0; i < n; i++) {
    double e = E[i] - eref;
    s1 += exp(-b1 * e - log_den[i] - top1);
    s2 += exp(-b2 * e - log_den[i] - top2);
  }
  /* w1 w2 / (w1 + w2) of the normalised weights, from their logarithms:
  ** the smaller over 1 + the ratio (no 0 / 0 where both underflow) */
  const double n1 = top1 + log(s1), n2 = top2 + log(s2);
  double o = 0.0;
  for (size_t i = 0; i < n; i++) {
    double e = E[i] - eref, l1 = -b1 * e - log_den[i] - n1, l2 = -b2 * e - log_den[i] - n2;
    o += exp(fmin(l1, l2)) / (1.0 + exp(-fabs(l1 - l2)));
  }
  return o;
}

/* ---- a tempering run's trace ------------------------------------------- */

/* Every (run, rung) is a state: its rows' energies thinned to one every
** 2 tau (at least every row), so that they are about independent. */
typedef struct {
  int K;             /* states */
  double *E;         /* first[K] samples */
  size_t *first;     /* K + 1 */
  double *beta;      /* K */
  double *thin;      /* K: rows a sample stands for */
  int *run;          /* K: the trace each state came from */
  size_t *rows;      /* K: the rows its samples were thinned from */
  int open;          /* states whose autocorrelation window did not close */
  int rounded;       /* states whose energies are printed coarsely (lw_trace_rounded) */
  int n_swaps;        /* neighbour pairs with an exchange column: */
  double *swap;       /* their acceptance over the rows (NAN: none), */
  double *swap_b;     /* 2 each: their rungs' inverse temperatures, */
  int *swap_pair;     /* the pair's number in its run, */
  int *swap_run;      /* and the run */
} rw_states;

static void states_free(rw_states *s)
{
  free(s->E);
  free(s->first);
  free(s->beta);
  free(s->thin);
  free(s->run);
  free(s->rows);
  free(s->swap);
  free(s->swap_b);
  free(s->swap_pair);
  free(s->swap_run);
}

/* The mean of column col over the rows, empty fields skipped (NAN: none). */
static double column_mean(const lw_trace *t, const size_t *row, size_t n, int col)
{
  double m = 0.0;
  size_t c = 0;
  for (size_t i = 0; i < n; i++) {
    double v = t->v[row[i] * t->n_cols + (size_t)col];
    if (!isnan(v)) m += (v - m) / (double)++c;
  }
  return c ? m : NAN;
}

static lw_status gather(const lw_trace *const *t, const char *const *path, const lw_trace_select *sel, int k,
                        rw_states *s, lw_error *err)
{
  memset(s, 0, sizeof *s);
  int energy[LW_TRACE_HEAT_MAX], temp[LW_TRACE_HEAT_MAX], rungs = 0;
  size_t cap = 0, most = 0; /* samples at most in all, rows at most of a run */
  lw_status st = LW_OK;
  for (int r = 0; r < k; r++) {
    int m = lw_trace_rungs(t[r], energy, temp, LW_TRACE_HEAT_MAX);
    rungs += m;
    cap += (size_t)m * t[r]->n_rows;
    if (t[r]->n_rows > most) most = t[r]->n_rows;
  }
  if (rungs < 2)
    return lw_error_set(err, LW_EINPUT, "%s: no tempering rungs (replicaK_energy columns): reweighting needs a "
                        "run with [tempering] replicas >= 2", path[0]);
  s->E = malloc((cap ? cap : 1) * sizeof *s->E);
  s->first = calloc((size_t)rungs + 1, sizeof *s->first);
  s->beta = malloc((size_t)rungs * sizeof *s->beta);
  s->thin = malloc((size_t)rungs * sizeof *s->thin);
  s->run = malloc((size_t)rungs * sizeof *s->run);
  s->rows = malloc((size_t)rungs * sizeof *s->rows);
  s->swap = malloc((size_t)rungs * sizeof *s->swap);
  s->swap_b = malloc(2 * (size_t)rungs * sizeof *s->swap_b);
  s->swap_pair = malloc((size_t)rungs * sizeof *s->swap_pair);
  s->swap_run = malloc((size_t)rungs * sizeof *s->swap_run);
  double *x = malloc((most ? most : 1) * sizeof *x);
  if (!s->E || !s->first || !s->beta || !s->thin || !s->run || !s->rows || !s->swap || !s->swap_b || !s->swap_pair ||
      !s->swap_run || !x) {
    st = lw_error_set(err, LW_ENOMEM, "out of memory reweighting %zu rows", cap);
    goto done;
  }
  for (int r = 0; r < k; r++) {
    size_t *row = NULL, n = 0, tuned = 0;
    if ((st = lw_trace_rows(t[r], path[r], &sel[r], &row, &n, &tuned, err))) goto done;
    int m = lw_trace_rungs(t[r], energy, temp, LW_TRACE_HEAT_MAX);
    for (int q = 0; q < m; q++) {
      const double T = t[r]->v[row[0] * t[r]->n_cols + (size_t)temp[q]];
      size_t c = 0;
      for (size_t i = 0; i < n; i++) {
        const double *v = t[r]->v + row[i] * t[r]->n_cols;
        if (v[temp[q]] != T) {
          st = lw_error_set(err, LW_EINPUT, "%s: rung %d's temperature changes within the rows (%g, then %g at "
                            "line %zu): reweighting needs fixed rungs (start after the ladder's tuning with --from)",
                            path[r], q, T, v[temp[q]], row[i] + 2);
          free(row);
          goto done;
        }
        if (!isnan(v[energy[q]])) x[c++] = v[energy[q]];
      }
      if (!(T > 0.0) || c < 2) {
        free(row);
        st = lw_error_set(err, LW_EINPUT, "%s: rung %d has %s", path[r], q, c < 2 ? "fewer than 2 energies in the "
                          "rows" : "no positive temperature");
        goto done;
      }
      size_t window;
      /* one every 2 tau, and no more than LW_REWEIGHT_SAMPLES a rung: beyond
      ** that the error bars are far below the trace's own scatter, and the
      ** solves' cost grows with the samples */
      const double tau = lw_series_tau(x, 1, c, &window);
      if (isnan(tau)) {
        free(row);
        st = lw_error_set(err, LW_ENOMEM, "%s: out of memory for the autocorrelation of rung %d", path[r], q);
        goto done;
      }
      /* (rounded, not raised: uncorrelated rows read a tau of 0.5 and a
      ** little noise, and every other one was thrown away) */
      size_t g = (size_t)lround(2.0 * fmax(tau, 0.5));
      if (c > g * LW_REWEIGHT_SAMPLES) g = (c + LW_REWEIGHT_SAMPLES - 1) / LW_REWEIGHT_SAMPLES;
      s->open += !window;
      s->rounded += lw_trace_rounded(x, c);
      size_t at = s->first[s->K];
      for (size_t i = 0; i < c; i += g) s->E[at++] = x[i];
      s->beta[s->K] = 1.0 / T;
      s->thin[s->K] = (double)g;
      s->run[s->K] = r;
      s->rows[s->K] = c;
      s->first[++s->K] = at;
    }
    /* the exchanges between neighbours: rungs that never swap share no
    ** energies (kept with the pair's temperatures: a pair across a gap is
    ** said by the gap) */
    for (int q = 0; q + 1 < m; q++) {
      char name[32];
      snprintf(name, sizeof name, "swap%d", q);
      int col = lw_trace_column(t[r], name);
      if (col < 0) break;
      s->swap[s->n_swaps] = column_mean(t[r], row, n, col);
      s->swap_b[2 * s->n_swaps] = s->beta[s->K - m + q];
      s->swap_b[2 * s->n_swaps + 1] = s->beta[s->K - m + q + 1];
      s->swap_run[s->n_swaps] = r;
      s->swap_pair[s->n_swaps++] = q;
    }
    free(row);
  }
done:
  free(x);
  if (st) states_free(s);
  return st;
}

/* One bootstrap resample of every state into Eb: circular blocks of rows
** drawn once for each trace and read by all its rungs alike.  The samples
** of one rung, thinned to one every 2 tau, still correlate (about e^-2 from
** one to the next), and the rungs of one trace correlate with each other
** (an exchange hands a configuration, and its energy, to the neighbour):
** drawn sample by sample and rung by rung, the resamples lost both and the
** error bars between the rungs came out 1.3 to 1.5 times too small
** (docs/NUMERICS.md, "Reweighting between the rungs"). */
static lw_status resample(const rw_states *s, int traces, gsl_rng *rng, double *Eb, lw_error *err)
{
  for (int r = 0; r < traces; r++) {
    size_t rows = 0, span = 1;
    for (int q = 0; q < s->K; q++)
      if (s->run[q] == r) {
        rows = s->rows[q] > rows ? s->rows[q] : rows;
        span = (size_t)s->thin[q] > span ? (size_t)s->thin[q] : span;
      }
    if (!rows) continue;
    /* LW_REWEIGHT_BLOCK samples of the slowest rung, but no fewer than
    ** LW_REWEIGHT_BLOCKS blocks in the rows (one block as long as the rows
    ** would draw the data back every time: error bars of 0), nor less than
    ** one sample of that rung */
    const size_t slowest = span;
    span *= LW_REWEIGHT_BLOCK;
    if (span > rows / LW_REWEIGHT_BLOCKS) span = rows / LW_REWEIGHT_BLOCKS;
    if (span < slowest) span = slowest < rows ? slowest : rows;
    /* enough blocks for every rung: each holds at least span / thin - 1
    ** of a rung's samples */
    size_t blocks = 0;
    for (int q = 0; q < s->K; q++)
      if (s->run[q] == r) {
        const size_t g = (size_t)s->thin[q], per = span / g > 1 ? span / g - 1 : 1;
        const size_t need = (s->first[q + 1] - s->first[q] + per - 1) / per;
        if (need > blocks) blocks = need;
      }
    size_t *start = malloc(blocks * sizeof *start);
    if (!start) return lw_error_set(err, LW_ENOMEM, "out of memory resampling %zu blocks", blocks);
    for (size_t b = 0; b < blocks; b++) start[b] = gsl_rng_uniform_int(rng, rows);
    for (int q = 0; q < s->K; q++) {
      if (s->run[q] != r) continue;
      const size_t a = s->first[q], m = s->first[q + 1] - a, g = (size_t)s->thin[q], n = s->rows[q];
      size_t got = 0;
      for (size_t b = 0; got < m; b = (b + 1) % blocks)
        for (size_t i = start[b] % n, left = span; left > 0 && got < m; i = (i + 1) % n, left--)
          if (i % g == 0 && i / g < m) Eb[a + got++] = s->E[a + i / g];
    }
    free(start);
  }
  return LW_OK;
}

/* Neighbouring temperatures (states at one beta are one ensemble) whose
** samples overlap too little for anything between them: the weights there
** rest on the free energies' difference, which such samples do not fix (two
** rungs of disjoint energies gave a C of 94.7 +- 0.17 between two rungs of
** C = 1, the bootstrap as sure of it as of the rungs). */
typedef struct {
  double b_lo, b_hi, overlap;
} rw_gap;

/* The table being made: its temperatures, estimates and error sums, and
** what the parts the states fell into found. */
typedef struct {
  int n_temps, traces;
  double tlo, thi;
  double *est, *sum; /* 2 and 4 a temperature */
  rw_gap *gap;       /* K at most */
  int n_gaps, iterations;
  double lowest; /* overlap of neighbouring temperatures (NAN: one) */
  gsl_rng *rng;
  const double *betas; /* the whole's distinct inverse temperatures, ascending */
  int inconsistent; /* rungs whose own mean the reweighting does not give (check_rungs) */
  double worst_z, worst_t, worst_own, worst_se, worst_rw;
} rw_table;

static double table_temperature(const rw_table *tab, int j)
{
  const double x = (double)j / (tab->n_temps - 1), r = tab->thi / tab->tlo;
  /* (a ladder from 1e-300 to 1e300: the ratio overflowed, every temperature
  ** after the first inf; its logarithms do not) */
  if (r < INFINITY) return tab->tlo * pow(r, x);
  return j == 0 ? tab->tlo : j == tab->n_temps - 1 ? tab->thi : exp(log(tab->tlo) + (log(tab->thi) - log(tab->tlo)) * x);
}

/* The B resamples' estimates about est, summed: d and d^2 of the energy
** and the heat capacity at each temperature into sum[4 j ..]. */
static lw_status bootstrap(const rw_states *s, rw_table *tab, const double *f, int j0, int j1, lw_error *err)
{
  const int n_temps = tab->n_temps, traces = tab->traces;
  const double *est = tab->est;
  double *sum = tab->sum;
  gsl_rng *rng = tab->rng;
  const int K = s->K, B = LW_REWEIGHT_BOOTSTRAP;
  const size_t n = s->first[K];
  gsl_rng *at[LW_REWEIGHT_BOOTSTRAP] = {0};
  lw_status sts[LW_REWEIGHT_BOOTSTRAP] = {0}, st = LW_OK;
  double *res = malloc((size_t)B * (size_t)n_temps * 2 * sizeof *res), *scratch = malloc(n * sizeof *scratch);
  lw_error *errs = malloc((size_t)B * sizeof *errs); /* (4 kB each) */
  if (!res || !scratch || !errs) st = lw_error_set(err, LW_ENOMEM, "out of memory resampling %zu samples", n);
  for (int b = 0; !st && b < B; b++)
    if (!(at[b] = gsl_rng_clone(rng))) st = lw_error_set(err, LW_ENOMEM, "out of memory resampling");
    else st = resample(s, traces, rng, scratch, err); /* (to the next resample's draws) */
  free(scratch);
#pragma omp parallel if (!st)
  {
    double *eb = malloc(n * sizeof *eb), *fb = malloc((size_t)K * sizeof *fb), *log_den = malloc(n * sizeof *log_den);
#pragma omp for schedule(dynamic, 1)
    for (int b = 0; b < B; b++) {
      if (st) continue;
      if (!eb || !fb || !log_den) {
        sts[b] = lw_error_set(&errs[b], LW_ENOMEM, "out of memory reweighting %zu samples", n);
        continue;
      }
      if ((sts[b] = resample(s, traces, at[b], eb, &errs[b]))) continue;
      memcpy(fb, f, (size_t)K * sizeof *fb); /* the whole data's: close to a resample's */
      if ((sts[b] = lw_reweight_solve(eb, s->first, s->beta, K, 1, fb, log_den, NULL, &errs[b]))) continue;
      for (int j = j0; j <= j1; j++) {
        double *r = res + ((size_t)b * (size_t)n_temps + (size_t)j) * 2;
        lw_reweight_at(eb, n, log_den, 1.0 / table_temperature(tab, j), &r[0], &r[1]);
      }
    }
    free(eb);
    free(fb);
    free(log_den);
  }
  for (int b = 0; b < B && !st; b++) {
    if ((st = sts[b])) {
      if (err) *err = errs[b];
      break;
    }
    for (int j = j0; j <= j1; j++) {
      const double *r = res + ((size_t)b * (size_t)n_temps + (size_t)j) * 2;
      const double d[2] = {r[0] - est[2 * j], r[1] - est[2 * j + 1]}; /* about the estimate: no cancellation */
      for (int v = 0; v < 2; v++) {
        sum[4 * j + 2 * v] += d[v];
        sum[4 * j + 2 * v + 1] += d[v] * d[v];
      }
    }
  }
  for (int b = 0; b < B; b++) gsl_rng_free(at[b]);
  free(res);
  free(errs);
  return st;
}

static int beta_order(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* s's betas, sorted, into b (K); returns how many differ. */
static int distinct_betas(const rw_states *s, double *b)
{
  memcpy(b, s->beta, (size_t)s->K * sizeof *b);
  qsort(b, (size_t)s->K, sizeof *b, beta_order);
  int m = 0;
  for (int q = 0; q < s->K; q++)
    if (!m || b[q] != b[m - 1]) b[m++] = b[q];
  return m;
}

/* The gaps between the m distinct betas b of s into gap; returns their
** count.  *lowest takes the lowest overlap met. */
static int gaps_of(const rw_states *s, const double *log_den, const double *b, int m, rw_gap *gap, double *lowest)
{
  int n = 0;
  for (int q = 1; q < m; q++) {
    double o = lw_reweight_overlap(s->E, s->first[s->K], log_den, b[q - 1], b[q]);
    if (!(o >= *lowest)) *lowest = o;
    if (!(o >= LW_REWEIGHT_OVERLAP_MIN)) gap[n++] = (rw_gap){b[q - 1], b[q], o};
  }
  return n;
}

static lw_status states_between(const rw_states *s, double lo, double hi, rw_states *c, lw_error *err);

/* The gaps between the m distinct betas b of s, each neighbouring two
** solved alone, into gap; returns their count, -1 out of memory (with
** err).  Two that do not settle either are a gap of overlap 0. */
static int gaps_by_pairs(const rw_states *s, const double *b, int m, rw_gap *gap, double *lowest, lw_error *err)
{
  int n = 0;
  for (int q = 1; q < m; q++) {
    rw_states c;
    double o = 0.0, *f = NULL, *log_den = NULL;
    lw_error pair_err;
    lw_status st = states_between(s, b[q - 1], b[q], &c, err);
    if (!st) {
      f = malloc((size_t)c.K * sizeof *f);
      log_den = malloc((c.first[c.K] ? c.first[c.K] : 1) * sizeof *log_den);
      if (!f || !log_den) st = lw_error_set(err, LW_ENOMEM, "out of memory reweighting %d rungs", c.K);
    }
    if (!st && !lw_reweight_solve(c.E, c.first, c.beta, c.K, 0, f, log_den, NULL, &pair_err))
      o = lw_reweight_overlap(c.E, c.first[c.K], log_den, b[q - 1], b[q]);
    states_free(&c);
    free(f);
    free(log_den);
    if (st) return -1;
    if (!(o >= *lowest)) *lowest = o;
    if (!(o >= LW_REWEIGHT_OVERLAP_MIN)) gap[n++] = (rw_gap){b[q - 1], b[q], o};
  }
  return n;
}

/* The states of s at betas lo .. hi into c (its own arrays, which the
** caller frees with states_free, whatever this returns). */
static lw_status states_between(const rw_states *s, double lo, double hi, rw_states *c, lw_error *err)
{
  memset(c, 0, sizeof *c);
  const size_t K = (size_t)s->K;
  c->E = malloc((s->first[K] ? s->first[K] : 1) * sizeof *c->E);
  c->first = calloc(K + 1, sizeof *c->first);
  c->beta = malloc(K * sizeof *c->beta);
  c->thin = malloc(K * sizeof *c->thin);
  c->run = malloc(K * sizeof *c->run);
  c->rows = malloc(K * sizeof *c->rows);
  if (!c->E || !c->first || !c->beta || !c->thin || !c->run || !c->rows) /* (the caller frees c) */
    return lw_error_set(err, LW_ENOMEM, "out of memory reweighting %zu samples", s->first[K]);
  for (int q = 0; q < s->K; q++) {
    if (s->beta[q] < lo || s->beta[q] > hi) continue;
    const size_t a = s->first[q], m = s->first[q + 1] - a, at = c->first[c->K];
    memcpy(c->E + at, s->E + a, m * sizeof *c->E);
    c->beta[c->K] = s->beta[q];
    c->thin[c->K] = s->thin[q];
    c->run[c->K] = s->run[q];
    c->rows[c->K] = s->rows[q];
    c->first[++c->K] = at + m;
  }
  return LW_OK;
}

/* Whether the states sample one system: each rung's own mean energy
** against the reweighted one at its temperature, which for rungs of one
** system's laws differ by about the rung's own error bar (its samples carry
** most of the weight there).  Rungs that do not (one stuck in a basin, or
** not yet in equilibrium) can overlap well in the solved laws, which mix
** them: a rung of 100 +- 0.1 beside one of 110 +- 10 read 98.65 at its own
** temperature, and C 15.6 for 0.01, with an overlap of 0.23.  The worst
** such rung, past LW_REWEIGHT_CONSISTENT of its error bars, goes to tab. */
static void check_rungs(const rw_states *s, const double *log_den, rw_table *tab)
{
  const size_t n = s->first[s->K];
  for (int q = 0; q < s->K && s->K > 1; q++) {
    const size_t a = s->first[q], m = s->first[q + 1] - a;
    /* an error bar from a few samples is itself far off (at 3 a rung, 14
    ** in 30 healthy traces warned): judged from LW_REWEIGHT_CONSISTENT_MIN */
    if (m < LW_REWEIGHT_CONSISTENT_MIN) continue;
    double mean = mean_of(s->E + a, m), ss = 0.0, e, c;
    for (size_t i = 0; i < m; i++) ss += (s->E[a + i] - mean) * (s->E[a + i] - mean);
    const double se = sqrt(ss / (double)(m - 1) / (double)m);
    lw_reweight_at(s->E, n, log_den, s->beta[q], &e, &c);
    /* a rung whose energy never changes (stuck) has no error bar: any
    ** difference past rounding is one (it was passed over, and a stuck rung
    ** read 53.77 for its 50) */
    const double d = fabs(e - mean), z = se > 0.0 ? d / se : d > 1e-9 * fabs(mean) ? INFINITY : 0.0;
    if (!(z > LW_REWEIGHT_CONSISTENT)) continue;
    tab->inconsistent++;
    if (!(z <= tab->worst_z)) {
      tab->worst_z = z;
      tab->worst_t = 1.0 / s->beta[q];
      tab->worst_own = mean;
      tab->worst_se = se;
      tab->worst_rw = e;
    }
  }
}

/* The table's rows at s's temperatures, from s's samples alone.  Where
** neighbouring temperatures of s overlap too little, s is split there (the
** gap noted) and each side reweighted alone: the free energies across a gap
** are not fixed by the samples, and through them a rung's own row took the
** other side's energies (<E> 299.3 for a rung of 300 +- 1). */
static lw_status reweight_part(const rw_states *s, rw_table *tab, lw_error *err)
{
  const int K = s->K;
  const size_t n = s->first[K];
  double *f = malloc((size_t)K * sizeof *f), *log_den = malloc(n * sizeof *log_den), *b = malloc(K * sizeof *b);
  rw_gap *gap = tab->gap + tab->n_gaps;
  lw_status st = LW_OK;
  int it = 0, m, gaps;
  if (!f || !log_den || !b) {
    st = lw_error_set(err, LW_ENOMEM, "out of memory reweighting %zu samples", n);
    goto done;
  }
  m = distinct_betas(s, b);
  lw_error whole;
  st = lw_reweight_solve(s->E, s->first, s->beta, K, 0, f, log_den, &it, &whole);
  if (st == LW_EINPUT && m > 1) {
    /* rungs that share nothing can keep the whole from settling (a ladder of
    ** four such rungs crept at 2e-10 for 10000 iterations): the neighbours
    ** are then measured two at a time, and a gap splits the part as ever */
    gaps = gaps_by_pairs(s, b, m, gap, &tab->lowest, err);
    if (gaps < 0) st = LW_ENOMEM;
    else if (gaps) st = LW_OK;
    else if (err) *err = whole;
    if (gaps <= 0) goto done;
  } else if (st) {
    if (err) *err = whole;
    goto done;
  } else {
    gaps = gaps_of(s, log_den, b, m, gap, &tab->lowest);
  }
  if (gaps) {
    tab->n_gaps += gaps;
    for (int g = 0; g <= gaps && !st; g++) {
      rw_states c;
      if (!(st = states_between(s, g ? gap[g - 1].b_hi : b[0], g < gaps ? gap[g].b_lo : b[m - 1], &c, err)))
        st = reweight_part(&c, tab, err);
      states_free(&c);
    }
    goto done;
  }
  tab->iterations += it; /* (of the solves whose estimates stand) */
  check_rungs(s, log_den, tab);
  /* the rows within the part's temperatures (at its ends, to rounding) */
  int j0 = tab->n_temps, j1 = -1;
  for (int j = 0; j < tab->n_temps; j++) {
    const double x = 1.0 / table_temperature(tab, j);
    if (x >= b[0] * (1 - 1e-9) && x <= b[m - 1] * (1 + 1e-9)) {
      if (j < j0) j0 = j;
      j1 = j;
      lw_reweight_at(s->E, n, log_den, x, &tab->est[2 * j], &tab->est[2 * j + 1]);
    }
  }
  /* the error bars: each state's samples drawn again with replacement, a
  ** fixed seed so that the output is the same every time: each part's own,
  ** where it begins in the whole's ladder (1 for the whole; drawn in turn
  ** from one, a part's error bars moved with the temperatures asked for,
  ** where a part before it had none and drew nothing: 1.26 or 0.84).  The
  ** generator's state at each resample is taken in turn (the draws of one
  ** after another), then the resamples are solved on the threads, each into
  ** its own slot, and summed in their order: the same bytes on any number
  ** of threads, and a 128-rung reweighting's 32 solves no longer one by one */
  int first = 0;
  while (tab->betas[first] != b[0]) first++;
  gsl_rng_set(tab->rng, 1 + (unsigned long)first);
  if (j0 <= j1) st = bootstrap(s, tab, f, j0, j1, err);
done:
  free(f);
  free(log_den);
  free(b);
  return st;
}

/* Whether row j lies in a gap. */
static int in_gap(const rw_table *tab, int j)
{
  const double x = 1.0 / table_temperature(tab, j);
  for (int g = 0; g < tab->n_gaps; g++)
    if (x > tab->gap[g].b_lo * (1 + 1e-9) && x < tab->gap[g].b_hi * (1 - 1e-9)) return 1;
  return 0;
}

static int gap_order(const void *a, const void *b)
{
  return beta_order(&((const rw_gap *)b)->b_lo, &((const rw_gap *)a)->b_lo);
}

lw_status lw_trace_reweight(const lw_trace *const *t, const char *const *path, const lw_trace_select *sel, int k,
                            int n_temps, FILE *out, lw_error *err)
{
  if (n_temps < 2 || n_temps > LW_REWEIGHT_TEMPS_MAX)
    return lw_error_set(err, LW_EUSAGE, "--reweight %d: expected 2 to %d temperatures", n_temps,
                        LW_REWEIGHT_TEMPS_MAX);
  rw_states s;
  lw_status st = gather(t, path, sel, k, &s, err);
  if (st) return st;
  const int K = s.K, B = LW_REWEIGHT_BOOTSTRAP;
  rw_table tab = {.n_temps = n_temps, .traces = k, .lowest = NAN, .worst_z = NAN};
  tab.est = calloc((size_t)n_temps * 2, sizeof *tab.est);
  tab.sum = calloc((size_t)n_temps * 4, sizeof *tab.sum);
  tab.gap = malloc((size_t)K * sizeof *tab.gap);
  tab.rng = lw_rng_new();
  double *betas = malloc((size_t)K * sizeof *betas);
  if (betas) distinct_betas(&s, betas);
  tab.betas = betas;
  if (!tab.est || !tab.sum || !tab.gap || !tab.rng || !betas) {
    st = lw_error_set(err, LW_ENOMEM, "out of memory reweighting %d rungs", K);
    goto done;
  }
  double blo = INFINITY, bhi = -INFINITY;
  for (int q = 0; q < K; q++) {
    blo = fmin(blo, s.beta[q]);
    bhi = fmax(bhi, s.beta[q]);
  }
  tab.tlo = 1.0 / bhi;
  tab.thi = 1.0 / blo;
  if ((st = reweight_part(&s, &tab, err))) goto done;
  qsort(tab.gap, (size_t)tab.n_gaps, sizeof *tab.gap, gap_order); /* the coldest first */
  if (sel[0].csv) {
    fputs("temperature,energy,energy_stderr,heat_capacity,heat_capacity_stderr\n", out);
  } else {
    double thin = 0.0;
    for (int q = 0; q < K; q++) thin = fmax(thin, s.thin[q]);
    char overlap[64] = ""; /* (none with one rung) */
    if (!isnan(tab.lowest)) snprintf(overlap, sizeof overlap, ", neighbouring rungs' overlap at least %.3g",
                                     tab.lowest);
    fprintf(out, "reweighted over %d rung%s from T = %.6g to %.6g: %zu samples (each rung's rows thinned to one "
            "every 2 tau, at most every %.0f), %d iterations, %d bootstrap resamples%s\n", K, K > 1 ? "s" : "",
            tab.tlo, tab.thi, s.first[K], thin, tab.iterations, B, overlap);
    fprintf(out, "%15s %17s %11s %15s %11s\n", "temperature", "energy", "stderr", "heat_capacity", "stderr");
  }
  for (int j = 0; j < n_temps; j++) {
    const double T = table_temperature(&tab, j), *est = tab.est + 2 * j, *sum = tab.sum + 4 * j;
    double se[2];
    for (int v = 0; v < 2; v++) {
      double m = sum[2 * v] / B;
      se[v] = sqrt(fmax(sum[2 * v + 1] / B - m * m, 0.0) * B / (B - 1));
    }
    /* (an estimate past the doubles at a ladder's extreme ends, 1e-300:
    ** "-nan" where the documented row is empty) */
    const int defined = isfinite(est[0]) && isfinite(est[1]) && isfinite(se[0]) && isfinite(se[1]);
    /* (the CSV's every digit: a row's T matched no T a script computed) */
    char c[5][32];
    if (sel[0].csv) {
      lw_number_format_exact(c[0], sizeof c[0], T);
      for (int v = 0; v < 2; v++) {
        lw_number_format_exact(c[1 + 2 * v], sizeof c[0], est[v]);
        lw_number_format_exact(c[2 + 2 * v], sizeof c[0], se[v]);
      }
    }
    if (in_gap(&tab, j) || !defined)
      sel[0].csv ? fprintf(out, "%s,,,,\n", c[0]) : fprintf(out, "%15.6g %17s %11s %15s %11s\n", T, "-", "-", "-", "-");
    else if (sel[0].csv)
      fprintf(out, "%s,%s,%s,%s,%s\n", c[0], c[1], c[2], c[3], c[4]);
    else
      fprintf(out, "%15.6g %17.10g %11.4g %15.6g %11.4g\n", T, est[0], se[0], est[1], se[1]);
  }
  /* below the table, or with --csv where the caller says (stderr) */
  FILE *apart = sel[0].csv ? sel[0].csv_warnings : out;
  for (int g = 0; apart && g < tab.n_gaps; g++)
    fprintf(apart, "warning: no estimate between T = %.6g and %.6g: the rungs there share almost no energies "
            "(overlap %.3g, under %g), and each side is reweighted alone (more rungs between them)\n",
            1.0 / tab.gap[g].b_hi, 1.0 / tab.gap[g].b_lo, isnan(tab.gap[g].overlap) ? 0.0 : tab.gap[g].overlap,
            LW_REWEIGHT_OVERLAP_MIN);
  if (apart && tab.inconsistent)
    fprintf(apart, "warning: %d rung%s own mean energy is not what the reweighting gives at %s temperature (the "
            "worst: T = %.6g, %.10g +- %.2g, reweighted %.10g): the rungs do not sample one system's laws (one not "
            "in equilibrium, or stuck in a basin; start later with --from, or run longer), and the table mixes "
            "them\n", tab.inconsistent, tab.inconsistent > 1 ? "s'" : "'s", tab.inconsistent > 1 ? "their" : "its",
            tab.worst_t, tab.worst_own, tab.worst_se, tab.worst_rw);
  if (apart && s.rounded)
    fprintf(apart, "warning: %d rung%s energies are printed to 10 digits (output.trace_exact = 0, as runs begun before "
            "2026-12-07), which is "
            "coarse against their spread: the rounding adds to their variance, and the heat capacities are too "
            "large (a new run writes every digit)\n", s.rounded, s.rounded > 1 ? "s'" : "'s");
  if (apart && s.open)
    fprintf(apart, "warning: %d rung%s autocorrelation window did not close: thinned by too little, the error "
            "bars are too small (a longer stretch is needed)\n", s.open, s.open > 1 ? "s'" : "'s");
  /* the pair that exchanged least, of those whose curve is printed (one
  ** across a gap named a curve of "-" rows, and hid the weak pairs) */
  int worst = -1;
  for (int i = 0; i < s.n_swaps; i++) {
    const double lo = fmin(s.swap_b[2 * i], s.swap_b[2 * i + 1]), hi = fmax(s.swap_b[2 * i], s.swap_b[2 * i + 1]);
    int across = 0;
    for (int g = 0; g < tab.n_gaps; g++)
      across |= tab.gap[g].b_lo >= lo * (1 - 1e-9) && tab.gap[g].b_hi <= hi * (1 + 1e-9);
    if (!across && !isnan(s.swap[i]) && (worst < 0 || s.swap[i] < s.swap[worst])) worst = i;
  }
  if (apart && worst >= 0 && s.swap[worst] < LW_REWEIGHT_SWAP_MIN)
    fprintf(apart, "warning: rungs %d and %d%s%s exchanged in %.3g of the tries: their energies barely overlap and "
            "the curve between them is unreliable (more rungs there)\n", s.swap_pair[worst], s.swap_pair[worst] + 1,
            k > 1 ? " of " : "", k > 1 ? path[s.swap_run[worst]] : "", s.swap[worst]);
done:
  if (st == LW_EINPUT && err && strncmp(err->msg, path[0], strlen(path[0]))) { /* the solver's, of this trace */
    char why[sizeof err->msg];
    snprintf(why, sizeof why, "%s", err->msg);
    lw_error_set(err, st, "%s: %s", path[0], why);
  }
  states_free(&s);
  free(tab.est);
  free(tab.sum);
  free(tab.gap);
  free(betas);
  gsl_rng_free(tab.rng);
  return st;
}
