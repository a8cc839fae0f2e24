/*
** driver_barker.c -- a chain that takes a move with Barker's probability
** e^x / (1 + e^x), x = log q - dE / T, instead of Metropolis's min(1, e^x)
** (driver.h).  Its ratio at x and -x is e^x, so it keeps exp(-E/T) as
** Metropolis does, taking fewer moves (Peskun: at most as many, the chain's
** estimates at least as noisy); a scientist compares acceptance rules on
** one scene and seed with `--set scene.driver=barker`.
*/
#include "linewise/driver.h"

#include <math.h>

/* Written for either sign so that exp never overflows: at x = +inf it is 1,
** at -inf 0. */
static double barker_accept(double x) { return x >= 0.0 ? 1.0 / (1.0 + exp(-x)) : exp(x) / (1.0 + exp(x)); }

/* (delayed acceptance, whose second stage is Metropolis's, is left out by
** the rule itself: driver.h) */
const lw_driver_type lw_driver_barker = {"barker", LW_DRIVE_CHAIN, lw_driver_chain_keys, NULL, barker_accept};
