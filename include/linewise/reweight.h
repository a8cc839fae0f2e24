/*
** reweight.h -- multiple-histogram reweighting of a tempering run's
** energies: the mean energy and heat capacity at any temperature between
** the rungs, from every rung's samples at once (`linewise stats
** --reweight N`, docs/NUMERICS.md, "Reweighting between the rungs").
**
** Samples E_i (i < N) drawn at K inverse temperatures beta_k, N_k of them
** at each, estimate the dimensionless free energies f_k = -ln Z_k by the
** binless form of Ferrenberg and Swendsen's equations (1989; the energy-only
** case of Shirts and Chodera's MBAR, 2008):
**     f_k = -ln sum_i exp(-beta_k E_i) / D_i,   D_i = sum_m N_m exp(f_m - beta_m E_i),
** solved by Newton's method on the convex function they are the stationary
** point of (the equations' own iteration where a step fails), from the
** thermodynamic integral f_{k+1} = f_k + (beta_{k+1} - beta_k) (<E>_k +
** <E>_{k+1}) / 2, f_0 = 0.
** At any beta a sample then weighs w_i = exp(-beta E_i) / D_i, so
**     <E>(beta) = sum w_i E_i / sum w_i,   C(beta) = beta^2 (<E^2> - <E>^2).
** The equations assume independent samples: a rung's correlated rows are
** thinned to one every 2 tau first (trace.c), and the error bars come from
** resampling those (the bootstrap).  Sums run in logarithms, so no energy
** range overflows.
*/
#ifndef LINEWISE_REWEIGHT_H
#define LINEWISE_REWEIGHT_H

#include <stddef.h>
#include <stdio.h>

#include "linewise/error.h"
#include "linewise/trace.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LW_REWEIGHT_TOL 1e-10       /* the f_k's last change, at most */
#define LW_REWEIGHT_ITER 10000      /* iterations at most */
#define LW_REWEIGHT_BOOTSTRAP 32    /* resamples for the error bars */
#define LW_REWEIGHT_SAMPLES 20000   /* samples a rung at most, after thinning */
#define LW_REWEIGHT_BLOCK 4         /* samples of the most thinned rung a bootstrap block holds */
#define LW_REWEIGHT_BLOCKS 16       /* bootstrap blocks a run's rows hold at least */
#define LW_REWEIGHT_TEMPS_MAX 10000 /* temperatures a table, at most */
#define LW_REWEIGHT_OVERLAP_MIN 0.03 /* lw_reweight_overlap of neighbouring temperatures below which nothing
                                       between them is estimated */
#define LW_REWEIGHT_CONSISTENT 5.0 /* error bars by which a rung's own mean energy may differ from the
                                       reweighted one at its temperature before a warning says the rungs do
                                       not sample one system */
#define LW_REWEIGHT_CONSISTENT_MIN 20 /* samples a rung needs for that comparison (an error bar of fewer is
                                         itself too uncertain) */
#define LW_REWEIGHT_SWAP_MIN 0.05   /* neighbour exchange acceptance below which a warning says the
                                       rungs barely overlap */

/* The free energies f[K] (f[0] = 0) of the K states whose samples are
** E[first[k] .. first[k + 1] - 1] at inverse temperatures beta[k] (every
** state with a sample; first[K] = N), from the thermodynamic integral, or
** with warm = 1 from f as given (a solution for similar samples: a
** bootstrap resample's); log_den[N] (NULL: not asked) the samples' ln D_i
** up to one constant, what lw_reweight_at needs.  *iterations (NULL: not
** asked) the iterations taken.  LW_EINPUT when the iteration does not
** settle (states that share no energies; a warm solve still creeping by at
** most 1e-6 then is taken as it stands), LW_ENOMEM. */
lw_status lw_reweight_solve(const double *E, const size_t *first, const double *beta, int K, int warm, double *f,
                            double *log_den, int *iterations, lw_error *err);

/* The mean energy and heat capacity at inverse temperature b from the n
** samples and their ln D_i (from lw_reweight_solve): one exponential a
** sample. */
void lw_reweight_at(const double *E, size_t n, const double *log_den, double b, double *mean_energy,
                    double *heat_capacity);

/* How much the ensembles at inverse temperatures b1 and b2 overlap, from
** the n samples and their ln D_i: the integral of p1 p2 / (p1 + p2) over
** the energies, p the two laws, as sum_i w1_i w2_i / (w1_i + w2_i) of the
** normalised weights: 1/2 for one law, 0 for laws that share no energies,
** whatever either's sample count (0.22 for two normal laws 2 sd apart,
** 0.034 for 4). */
double lw_reweight_overlap(const double *E, size_t n, const double *log_den, double b1, double b2);

/* `linewise stats --reweight N`: the mean energy and heat capacity, with
** bootstrap error bars, at n_temps temperatures spaced geometrically from
** the coldest rung's to the hottest's, from every rung of the k runs at
** once (each run's stretch of rows by sel[r]; the format by sel[0].csv).
** Every (run, rung) is a state of its own, so runs whose ladders differ
** pool too.  Where two neighbouring temperatures overlap by under
** LW_REWEIGHT_OVERLAP_MIN (lw_reweight_overlap) the rows between them are
** left empty and each side is reweighted alone.  A table with its warnings
** (such a gap; a rung whose autocorrelation window did not close;
** neighbours that exchanged in under 5 % of their tries) or CSV lines.  LW_EINPUT naming the file for a trace without
** two rungs or with a rung whose temperature changes within the rows;
** LW_EUSAGE for n_temps outside 2 .. LW_REWEIGHT_TEMPS_MAX. */
lw_status lw_trace_reweight(const lw_trace *const *t, const char *const *path, const lw_trace_select *sel, int k,
                            int n_temps, FILE *out, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
