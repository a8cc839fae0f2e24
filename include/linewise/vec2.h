/*
** vec2.h -- two doubles in one SSE2 register (GCC vector extensions), shared
** by the pair kernels' inner loops (walk.c, pairnear.c).
*/
#ifndef LINEWISE_VEC2_H
#define LINEWISE_VEC2_H

#include <math.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

typedef double lw_v2d __attribute__((vector_size(16)));
/* What a comparison of two lw_v2d gives: all ones where true, 0 where false. */
typedef long long lw_v2l __attribute__((vector_size(16)));

/* Two square roots at once.  sqrt is correctly rounded in SSE2 and in C
** alike, so both branches give the same bits. */
static inline lw_v2d lw_vsqrt2(lw_v2d a)
{
#if defined(__SSE2__)
  return (lw_v2d)_mm_sqrt_pd((__m128d)a);
#else
  return (lw_v2d){sqrt(a[0]), sqrt(a[1])};
#endif
}

#endif
