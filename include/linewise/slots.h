/*
** slots.h -- the ghost slots of trans-dimensional storage (model.h).
**
** A death leaves its spline where it is, as a ghost: its nodes keep their
** place in the contiguous arrays (spline.h), so no index behind it moves,
** but it has no energy, no pair samples and no part in any proposal.  A
** later spline of the same segment count takes the slot over in place; one
** with no ghost of its size is appended.  Either way a birth or a death
** costs O(its own segments), whatever the count.  The model compacts the
** ghosts away (lw_model_compact) at the end of every sweep, before anything
** reads the state: what checkpoints, outputs and drivers see is numbered
** 0 .. N-1 without holes, and the compaction keeps the order of the
** splines that stay, so it is a function of the state alone.
**
** Each segment count has its own stack of ghosts (last in, first out), so
** which slot a birth takes depends on the history of the sweep only, never
** on threads or timing.
*/
#ifndef LINEWISE_SLOTS_H
#define LINEWISE_SLOTS_H

#include <stddef.h>
#include <stdint.h>

#include "linewise/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  uint32_t *slot;
  size_t n, cap;
} lw_slot_stack;

typedef struct {
  unsigned char *ghost;  /* cap: 1 where spline slot i is a ghost */
  size_t cap;            /* room in ghost */
  size_t n_ghost;        /* how many are */
  lw_slot_stack *free;   /* n_free: the ghosts of each segment count */
  size_t n_free;
} lw_slots;

lw_slots *lw_slots_new(void);
void lw_slots_free(lw_slots *s);

/* Room for slots 0 .. n_slots-1 and for `more` more ghosts of n_seg
** segments, so that the lw_slots_kill calls that follow cannot fail.
** LW_ENOMEM leaves s as it was (only larger). */
lw_status lw_slots_reserve(lw_slots *s, size_t n_slots, size_t n_seg, size_t more);

/* 1 if slot i is a ghost (s may be NULL: no ghosts). */
static inline int lw_slots_ghost(const lw_slots *s, size_t i)
{
  return s && i < s->cap && s->ghost[i];
}

/* Slot i, of n_seg segments, becomes a ghost (after lw_slots_reserve). */
void lw_slots_kill(lw_slots *s, size_t i, size_t n_seg);

/* The ghost that a spline of n_seg segments would take after `depth`
** others of its count took theirs (0: the next one), or -1 if none. */
long lw_slots_peek(const lw_slots *s, size_t n_seg, size_t depth);

/* Takes that ghost: it is a live slot again. */
void lw_slots_take(lw_slots *s, size_t n_seg);

/* Forgets every ghost (after the compaction that removed them). */
void lw_slots_clear(lw_slots *s, size_t n_slots);

#ifdef __cplusplus
}
#endif

#endif
