/*
** gradient.h -- the derivatives of the energy with respect to every node's
** p and v: the forces of the dynamics driver and the gradient of the quench.
**
** They are the derivatives of the energy as linewise computes it (the
** quadrature sums of terms.h, the pair kernel of pair.h with its near
** field), not of the exact integrals: a minimiser and an integrator must see
** the same function the chain sees.
**
** A segment term's energy is a function of its samples r, r', r'' at the
** quadrature nodes (and, for the boundary, of the two end points).  Its
** gradient is given at the same level -- dE/dr, dE/dr', dE/dr'' per sample,
** with the coefficient applied -- and the chain rule through the basis
** tables of quad.h (r = sum pos[q][k] x_k, r' = sum d1[q][k] x_k, ...)
** takes it to the segment's nodes (p0, v0, p1, v1).  Terms stay pure
** functions of a segment's samples; only lw_segment_grad_nodes knows the
** basis.
**
** The gradient of a state is an array of lw_node, one per node, in the
** order of sp->node: (dE/dpx, dE/dpy, dE/dvx, dE/dvy).
*/
#ifndef LINEWISE_GRADIENT_H
#define LINEWISE_GRADIENT_H

#include "linewise/model.h"
#include "linewise/quad.h"
#include "linewise/scene.h"
#include "linewise/spline.h"

#ifdef __cplusplus
extern "C" {
#endif

/* lw_samples_grad, dE/d(sample values) of one segment, is declared in
** terms.h beside the term rows that fill it. */


/* Adds the gradient g of one segment, taken through the basis of q, to the
** gradients of its first node (ga) and its last node (gb). */
void lw_segment_grad_nodes(const lw_quad *q, const lw_samples_grad *g, lw_node *ga, lw_node *gb);

/* The gradient of the scene's energy at sp: grad (sp->n_nodes, overwritten)
** is the sum over the terms selected in term_mask (bit t for term t;
** LW_GRAD_ALL for every term that is on), and term[] (if not NULL) receives
** each selected term's energy as lw_energy_compute gives it (bitwise; 0 for
** the others).  Returns the total of
** the selected terms; +inf (grad then undefined) if a segment is irregular
** or a sample is outside the boundary.  LW_ENOMEM through err.  The user
** term has no gradient: a mask that selects it while it is on is an error
** (LW_EINPUT, naming the term).  The tone term's is that of its raster
** built afresh from sp (tone.h, lw_tone_sample_grad). */
#define LW_GRAD_ALL (~0u)
double lw_energy_gradient(const lw_scene *sc, const lw_splines *sp, unsigned term_mask, lw_node *grad,
                          double term[LW_TERM_COUNT], lw_error *err);

/* The pair term's part (pairgrad.c): adds the derivative of the pair energy
** (coefficient applied, near field included) to grad and returns that
** energy as lw_energy_compute gives it (0 when the term is off). */
double lw_pair_gradient(const lw_scene *sc, const lw_splines *sp, lw_node *grad, lw_error *err);

#ifdef __cplusplus
}
#endif

#endif
