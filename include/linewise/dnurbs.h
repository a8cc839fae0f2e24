/*
** dnurbs.h -- the D-NURBS matrices of a curve (Terzopoulos and Qin 1994;
** docs/NURBS.md, docs/NUMERICS.md "D-NURBS"), and what free weights add.
**
** With c(u) = sum_i R_i(u) P_i (the rational basis of nurbs.h, weights
** held), and integrals over the parameter u as in the review:
**
**     E_el = 1/2 int alpha |c_u|^2 + beta |c_uu|^2 du = 1/2 sum_xy P' K P
**     T    = 1/2 int mu |c_t|^2 du                 = 1/2 sum_xy Pdot' (mu M1) Pdot
**     E_g  = - int mu g . c du                     = - sum_i mu (g . P_i) b_i
**
** K = int alpha R' R'^T + beta R'' R''^T du, M1 = int R R^T du and
** b_i = int R_i du, by Gauss-Legendre quadrature on every knot span.  The
** 1/2 is the review's (its eq. 54): K p is the elastic force.  R_i and R_j
** overlap only when |i - j| < k, so K and M1 are banded with k - 1
** off-diagonals; the x and y coordinates share them.  Band storage is
** GSL's for its banded Cholesky: band[i * k + d] = A(i + d, i).
*/
#ifndef LINEWISE_DNURBS_H
#define LINEWISE_DNURBS_H

#include "linewise/nurbs.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  size_t n;     /* control points */
  int k;        /* order: the band has k columns */
  double alpha, beta;
  int gauss;    /* Gauss points a span */
  double *K;    /* n x k: stiffness */
  double *M1;   /* n x k: mass per unit density */
  double *b;    /* n: int R_i du */
} lw_dnurbs;

/* The matrices of curve c (its weights frozen) with `gauss` points a span. */
lw_dnurbs *lw_dnurbs_new(lw_nurbs *c, double alpha, double beta, int gauss, lw_error *err);

/* The pieces knot span s (knot[s] < knot[s + 1]) is integrated over, each
** with its own Gauss points: the span whole, or where its weights lie more
** than 2 apart cut at h/2, h/4, ... toward each end, as far as the rational
** basis's turn there (dnurbs.c).  Their count, at most LW_DNURBS_PIECES_MAX,
** and their ends into p0 and p1. */
#define LW_DNURBS_PIECES_MAX 60
int lw_dnurbs_span_pieces(const lw_nurbs *c, size_t s, double *p0, double *p1);
void lw_dnurbs_free(lw_dnurbs *d);

/* K, M1 and b again at c's present weights (free weights; d from c). */
lw_status lw_dnurbs_assemble(lw_dnurbs *d, lw_nurbs *c, lw_error *err);

/* The gradient gw (n) of E_el + E_g in the weights, with mug = mu g:
** dE/dw_j = int alpha c_u . q_j' + beta c_uu . q_j'' - mug . q_j du, where
** q_j = dc/dw_j = R_j (P_j - c) / w_j (docs/NUMERICS.md "Free weights").
** lw_dnurbs_grad_s: the same in s_j = log w_j, dE/ds_j = w_j dE/dw_j, the
** coordinates of nurbs.free_weights. */
lw_status lw_dnurbs_grad_w(lw_nurbs *c, double alpha, double beta, const double mug[2], int gauss, double *gw, lw_error *err);
lw_status lw_dnurbs_grad_s(lw_nurbs *c, double alpha, double beta, const double mug[2], int gauss, double *gs, lw_error *err);

/* term[0] elastic, term[1] gravity, integrated over the k knot spans where
** basis function j lives: all of E that a change of w_j changes. */
lw_status lw_dnurbs_energy_near(lw_nurbs *c, double alpha, double beta, const double mug[2], int gauss, size_t j,
                                double term[2], lw_error *err);

/* 1/2 P'KP for the band K (n rows of k) and the 2 n coordinates P, summed
** as -1/2 sum over i < j of K_ij |P_i - P_j|^2, equal since K's rows sum
** to 0 (the basis sums to 1).  Over P itself the terms of K's size (5e9 at
** nurbs.refine = 200) cancel to the energy (1,765), and 1/2 P'KP lost
** 1.5e-3 of it; over the differences, 1e-12. */
double lw_band_energy(const double *K, size_t n, int k, const double *P);

/* The mass matrix per unit density over the free-weight coordinates
** x = (x_i, y_i, s_i) of each control point, s_i = log w_i: M = int J'J du
** with J = dc/dx = [R_i e_x, R_i e_y, R_i (P_i - c)].  It depends on P and
** w.  Band of 3 n rows and 3 k columns (M must hold 9 n k numbers).
** lw_dnurbs_mass_s_dx: out (3 n) = d/dx (1/2 v' M(x) v) at fixed v. */
lw_status lw_dnurbs_mass_s(lw_nurbs *c, int gauss, double *M, lw_error *err);
lw_status lw_dnurbs_mass_s_dx(lw_nurbs *c, int gauss, const double *v, double *out, lw_error *err);

/* y = A x for a band A (n x k) on interleaved xy vectors (2 n); _dim on
** vectors of dim interleaved components sharing A (dim n numbers). */
void lw_band_apply(const double *A, size_t n, int k, const double *x, double *y);
void lw_band_apply_dim(const double *A, size_t n, int k, int dim, const double *x, double *y);

/* Factors the band A (n x k) into L (same size) with the coordinates where
** pin[i] != 0 (i a control point) held: identity rows and columns.
** LW_EINPUT when it is not positive definite. */
lw_status lw_band_factor(const double *A, const unsigned char *pin, size_t n, int k, double *L, lw_error *err);

/* x = A^-1 r on interleaved xy vectors, 0 at held points (L from
** lw_band_factor; r and x may be the same array). */
void lw_band_solve(const double *L, const unsigned char *pin, size_t n, int k, const double *r, double *x);
void lw_band_solve_dim(const double *L, const unsigned char *pin, size_t n, int k, int dim, const double *r, double *x);

#ifdef __cplusplus
}
#endif

#endif
