/* system.c -- the table of system types (system.h). */
#include "linewise/system.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/number.h"
#include "linewise/sys_nurbs.h"
#include "linewise/sys_particles.h"
#include "linewise/sys_splines.h"

const lw_system_type *const lw_system_types[] = {&lw_system_splines, &lw_system_particles, &lw_system_nurbs, NULL};

const lw_system_type *lw_system_find(const char *name)
{
  for (int k = 0; lw_system_types[k]; k++)
    if (!strcmp(lw_system_types[k]->name, name)) return lw_system_types[k];
  return NULL;
}

static char names_buf[256];
static pthread_once_t names_once = PTHREAD_ONCE_INIT;

static void build_names(void)
{
  size_t n = 0;
  for (int k = 0; lw_system_types[k] && n < sizeof names_buf; k++)
    n += (size_t)snprintf(names_buf + n, sizeof names_buf - n, "%s%s", k ? ", " : "", lw_system_types[k]->name);
}

const char *lw_system_names(void)
{
  pthread_once(&names_once, build_names);
  return names_buf;
}

const lw_system_type *lw_system_of(const lw_params *p, lw_error *err)
{
  const lw_system_type *t = lw_system_find(p->system);
  if (!t) {
    char where[LW_PATH_MAX + 32], unseen[96];
    lw_params_origin(p, lw_params_find("scene", "system"), where, sizeof where);
    lw_error_set(err, LW_EINPUT, "%s: key 'scene.system': expected one of %s, got '%s'%s", where, lw_system_names(),
                 p->system, lw_text_unseen_char(p->system, unseen, sizeof unseen));
  }
  if (t && t->variant) t = t->variant(p);
  return t && lw_system_row_fits(t, err) ? t : NULL;
}

/* The first member a row lacks that the drivers call without asking, or
** that an optional member it has needs beside it (the domains call merge()
** after every split() sweep); NULL when none.  A row without energy()
** crashed `linewise energy` rather than being refused. */
static const char *row_missing(const lw_system_type *t)
{
#define LW_NEED(m) \
  if (!t->m) return #m
#define LW_NEED_WITH(have, m) \
  if (t->have && !t->m) return #m " beside " #have
  if (t->n_moves > 0 && !(t->move_names && t->move_unit)) return "move_names and move_unit";
  LW_NEED(term_names);
  LW_NEED(setup_new);
  LW_NEED(setup_free);
  LW_NEED(note);
  LW_NEED(state_new);
  LW_NEED(state_copy);
  LW_NEED(state_free);
  LW_NEED(moves);
  LW_NEED(sweep_size);
  LW_NEED(step_max);
  LW_NEED(proposal_new);
  LW_NEED(proposal_free);
  LW_NEED(propose);
  LW_NEED(commit);
  LW_NEED(total);
  LW_NEED(terms);
  LW_NEED(term_on);
  LW_NEED(refresh);
  LW_NEED(energy);
  LW_NEED(save);
  LW_NEED(load);
  LW_NEED(set_terms);
  LW_NEED(files);
  LW_NEED(draw);
  LW_NEED(summary);
  LW_NEED(describe);
  LW_NEED_WITH(defer, finish);
  LW_NEED_WITH(finish, defer);
  LW_NEED_WITH(split, group);
  LW_NEED_WITH(split, propose_in);
  LW_NEED_WITH(split, commit_part);
  LW_NEED_WITH(split, merge);
  LW_NEED_WITH(gradient, n_coords);
  LW_NEED_WITH(gradient, get_coords);
  LW_NEED_WITH(gradient, set_coords);
  LW_NEED_WITH(mass_new, gradient);
  LW_NEED_WITH(mass_new, mass_free);
  LW_NEED_WITH(mass_new, mass_at);
  LW_NEED_WITH(mass_new, mass_solve);
  LW_NEED_WITH(mass_new, mass_apply);
  LW_NEED_WITH(mass_new, mass_dx);
  LW_NEED_WITH(mass_new, mass_pinned);
  LW_NEED_WITH(mass_shift, mass_shift_solve);
  LW_NEED_WITH(mass_shift, mass_new);
  LW_NEED_WITH(damp_pairs, mass_new);
  if (t->n_observables > 0 && !(t->observable_names && t->observe)) return "observable_names and observe";
#undef LW_NEED
#undef LW_NEED_WITH
  return NULL;
}

int lw_system_row_fits(const lw_system_type *t, lw_error *err)
{
  if (!(t->n_moves <= LW_MOVES_MAX && t->n_terms <= LW_SYSTEM_TERMS_MAX && t->n_observables <= LW_OBSERVABLES_MAX)) {
    lw_error_set(err, LW_EINPUT, "the %s system's row has %d move kinds, %d terms and %d observables; at most %d, %d "
                 "and %d fit (include/linewise/system.h)", t->name, t->n_moves, t->n_terms, t->n_observables,
                 LW_MOVES_MAX, LW_SYSTEM_TERMS_MAX, LW_OBSERVABLES_MAX);
    return 0;
  }
  const char *missing = row_missing(t);
  if (missing) {
    lw_error_set(err, LW_EINPUT, "the %s system's row has no %s (include/linewise/system.h says what it must hold)",
                 t->name, missing);
    return 0;
  }
  /* the drivers' own columns of trace.csv and members of summary.json's
  ** energy: a term of one of these names made a second "total" there */
  static const char *const taken[] = {"sweep", "time", "temperature", "total", "kinetic", "potential_energy"};
  for (int k = 0; k < t->n_terms; k++) {
    for (size_t j = 0; j < sizeof taken / sizeof *taken; j++)
      if (!strcmp(t->term_names[k], taken[j])) {
        lw_error_set(err, LW_EINPUT, "the %s system's term '%s' has the name of a column the drivers write "
                     "(include/linewise/system.h)", t->name, t->term_names[k]);
        return 0;
      }
    for (int j = 0; j < k; j++)
      if (!strcmp(t->term_names[k], t->term_names[j])) {
        lw_error_set(err, LW_EINPUT, "the %s system has two terms named '%s'", t->name, t->term_names[k]);
        return 0;
      }
  }
  return 1;
}

lw_system *lw_system_wrap(const lw_system_type *type, void *state, lw_error *err)
{
  if (!state) return NULL;
  lw_system *s = malloc(sizeof *s);
  if (!s) {
    type->state_free(state);
    lw_error_set(err, LW_ENOMEM, "out of memory for a system");
    return NULL;
  }
  s->type = type;
  s->state = state;
  return s;
}

void lw_system_free(lw_system *s)
{
  if (!s) return;
  s->type->state_free(s->state);
  free(s);
}

double lw_system_drift(const double *before, const double *after, int n)
{
  double was = 0.0, now = 0.0, size = 0.0;
  for (int t = 0; t < n; t++) {
    was += before[t];
    now += after[t];
    size += fabs(after[t]);
  }
  if (!isfinite(was) || !isfinite(now) || !isfinite(size)) return was == now ? 0.0 : INFINITY;
  return fabs(now - was) / fmax(size, 1.0);
}

static double dot(const double *u, const double *v, size_t n)
{
  double s = 0.0;
  for (size_t i = 0; i < n; i++) s += u[i] * v[i];
  return s;
}

double lw_system_hold(const lw_system_type *t, void *state, const double *x, const double *g, double *dir, double h,
                      double *x1, unsigned char *held, size_t n, long *holds)
{
  for (size_t i = 0; i < n; i++) x1[i] = x[i] + h * dir[i];
  double slope = dot(g, dir, n);
  /* the coordinates a round held back (NULL without room: every part asked) */
  unsigned char *changed = t->blocked ? malloc(n ? n : 1) : NULL;
  for (int r = 0; t->blocked && slope < 0.0; r++) {
    const size_t parts = t->blocked(state, x1, held, r && changed ? changed : NULL);
    if (!parts || r == LW_HOLD_ROUNDS) {
      free(changed);
      return parts ? 0.0 : slope;
    }
    *holds += (long)parts;
    for (size_t i = 0; i < n; i++) {
      if (changed) changed[i] = held[i] && dir[i] != 0.0;
      if (held[i]) dir[i] = 0.0;
    }
    slope = dot(g, dir, n);
    for (size_t i = 0; i < n; i++) x1[i] = x[i] + h * dir[i];
  }
  free(changed);
  return slope < 0.0 ? slope : 0.0;
}
