/* slots.c -- ghost slots with a stack of free slots per segment count (slots.h). */
#include "linewise/slots.h"

#include <stdlib.h>
#include <string.h>

lw_slots *lw_slots_new(void)
{
  return calloc(1, sizeof(lw_slots));
}

void lw_slots_free(lw_slots *s)
{
  if (!s) return;
  for (size_t k = 0; k < s->n_free; k++) free(s->free[k].slot);
  free(s->free);
  free(s->ghost);
  free(s);
}

lw_status lw_slots_reserve(lw_slots *s, size_t n_slots, size_t n_seg, size_t more)
{
  if (n_slots > s->cap) {
    size_t c = s->cap + s->cap / 2 + 64;
    if (c < n_slots) c = n_slots;
    unsigned char *g = realloc(s->ghost, c);
    if (!g) return LW_ENOMEM;
    memset(g + s->cap, 0, c - s->cap);
    s->ghost = g;
    s->cap = c;
  }
  if (n_seg >= s->n_free) {
    lw_slot_stack *f = realloc(s->free, (n_seg + 1) * sizeof *f);
    if (!f) return LW_ENOMEM;
    memset(f + s->n_free, 0, (n_seg + 1 - s->n_free) * sizeof *f);
    s->free = f;
    s->n_free = n_seg + 1;
  }
  lw_slot_stack *st = &s->free[n_seg];
  if (st->n + more > st->cap) {
    size_t c = st->cap ? 2 * st->cap : 16;
    if (c < st->n + more) c = st->n + more;
    uint32_t *v = realloc(st->slot, c * sizeof *v);
    if (!v) return LW_ENOMEM;
    st->slot = v;
    st->cap = c;
  }
  return LW_OK;
}

void lw_slots_kill(lw_slots *s, size_t i, size_t n_seg)
{
  s->ghost[i] = 1;
  s->n_ghost++;
  lw_slot_stack *st = &s->free[n_seg];
  st->slot[st->n++] = (uint32_t)i;
}

long lw_slots_peek(const lw_slots *s, size_t n_seg, size_t depth)
{
  if (!s || n_seg >= s->n_free || s->free[n_seg].n <= depth) return -1;
  const lw_slot_stack *st = &s->free[n_seg];
  return (long)st->slot[st->n - 1 - depth];
}

void lw_slots_take(lw_slots *s, size_t n_seg)
{
  lw_slot_stack *st = &s->free[n_seg];
  s->ghost[st->slot[--st->n]] = 0;
  s->n_ghost--;
}

void lw_slots_clear(lw_slots *s, size_t n_slots)
{
  memset(s->ghost, 0, n_slots < s->cap ? n_slots : s->cap);
  for (size_t k = 0; k < s->n_free; k++) s->free[k].n = 0;
  s->n_ghost = 0;
}
