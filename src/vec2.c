/* vec2.c -- which width the pair kernels run at (vec2.h). */
#include "linewise/vec2.h"

#include <stdatomic.h>

/* -1 until first asked; then 0 or 1.  Threads that race on the first call
** all store the same answer (so for x8_state). */
static atomic_int wide_state = -1;
static atomic_int wide_off = 0;

static int processor_has_avx2(void)
{
#if LW_VEC_HAVE_WIDE
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") ? 1 : 0;
#else
  return 0;
#endif
}

int lw_vec_wide(void)
{
  if (atomic_load_explicit(&wide_off, memory_order_relaxed)) return 0;
  int s = atomic_load_explicit(&wide_state, memory_order_relaxed);
  if (s < 0) {
    s = processor_has_avx2();
    atomic_store_explicit(&wide_state, s, memory_order_relaxed);
  }
  return s;
}

void lw_vec_set_wide(int on) { atomic_store_explicit(&wide_off, on ? 0 : 1, memory_order_relaxed); }

static atomic_int x8_state = -1;
static atomic_int x8_off = 0;

static int processor_has_avx512(void)
{
#if LW_VEC_HAVE_WIDE
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
         __builtin_cpu_supports("avx512vl");
#else
  return 0;
#endif
}

int lw_vec_lanes(void)
{
  if (!lw_vec_wide()) return LW_VEC_2;
  if (atomic_load_explicit(&x8_off, memory_order_relaxed)) return LW_VEC_4;
  int s = atomic_load_explicit(&x8_state, memory_order_relaxed);
  if (s < 0) {
    s = processor_has_avx512();
    atomic_store_explicit(&x8_state, s, memory_order_relaxed);
  }
  return s ? LW_VEC_8 : LW_VEC_4;
}

void lw_vec_set_x8(int on) { atomic_store_explicit(&x8_off, on ? 0 : 1, memory_order_relaxed); }
