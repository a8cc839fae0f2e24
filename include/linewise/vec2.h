/*
** vec2.h -- two doubles in one SSE2 register (GCC vector extensions), shared
** by the pair kernels' inner loops (walk.c, pairnear.c), and the choice of
** their four-wide AVX2 versions where the processor has AVX2.
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

/* The AVX2 kernels are compiled where the compiler can target AVX2 for one
** function (GCC and clang on x86-64) and run where the processor has it. */
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LW_VEC_HAVE_WIDE 1
#else
#define LW_VEC_HAVE_WIDE 0
#endif

/*
** Whether the pair kernels run four lanes at a time (AVX2): 1 where the
** processor has AVX2 and lw_vec_set_wide has not turned it off.  Either
** way the results are the same to the bit: a wide kernel computes each
** lane as the narrow one does (sqrt and division are correctly rounded, and
** no fused multiply-add is used) and folds its four lanes into the narrow
** kernel's two accumulators in the narrow kernel's order.
*/
int lw_vec_wide(void);

/* 0 keeps the narrow kernels even where AVX2 is there (tests and
** benchmarks compare the two); 1 restores the processor's choice. */
void lw_vec_set_wide(int on);

#endif
