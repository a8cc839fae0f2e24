/*
** pairgrad.c -- the pair term's gradient (gradient.h).  PLACEHOLDER: the
** pair gradient is built on its own branch; this file only lets the rest
** of the gradient build and refuse a pair term clearly until that lands,
** and is replaced at the merge.
*/
#include "linewise/gradient.h"

#include <math.h>

double lw_pair_gradient(const lw_scene *sc, const lw_splines *sp, lw_node *grad, lw_error *err)
{
  (void)sc;
  (void)sp;
  (void)grad;
  lw_error_set(err, LW_EINPUT, "pair gradient: not built yet");
  return NAN;
}
