/*
** vec2.h -- two doubles in one SSE2 register (GCC vector extensions), shared
** by the pair kernels' inner loops (walk.c, pairnear.c), and the choice of
** their four-wide AVX2 versions where the processor has AVX2 (and of the
** walk's eight-wide AVX-512 scan where it has that).
*/
#ifndef LINEWISE_VEC2_H
#define LINEWISE_VEC2_H

#include <math.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#ifdef __cplusplus
extern "C" {
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

/*
** The lanes the walk's scan runs at: 8 (AVX-512: F, DQ and VL) where the
** processor has them, the wide kernels are on and lw_vec_set_x8 has not
** turned them off; else 4 where lw_vec_wide; else 2.  The eight-lane scan
** takes two groups of four at a time and adds them to the accumulators in
** turn, so every width gives the same bits.
*/
enum { LW_VEC_2 = 2, LW_VEC_4 = 4, LW_VEC_8 = 8 };
int lw_vec_lanes(void);

/* The target of the functions that run where lw_vec_lanes() is LW_VEC_8. */
#define LW_VEC_X8_TARGET "avx2,avx512f,avx512dq,avx512vl"

/* 0 keeps the scan at four lanes even where AVX-512 is there (tests and
** benchmarks compare); 1 restores the processor's choice. */
void lw_vec_set_x8(int on);

#ifdef __cplusplus
}
#endif

#endif
