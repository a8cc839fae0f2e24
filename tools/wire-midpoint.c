/*
** wire-midpoint.c -- the midpoint of a D-NURBS curve over time, for the
** figures of docs/NURBS.md (tools/wire-figures.gp; make wire-figures):
**
**     wire-midpoint SCENE.ini SECONDS [section.key=value ...]
**
** prints "t x y" of c(u_mid), u_mid the middle of the parameter range, at
** every time step of the scene's dynamics, from the scene's start at rest.
*/
#include <stdio.h>
#include <stdlib.h>

#include "linewise/dynamics.h"
#include "linewise/sys_nurbs.h"

static int fail(const lw_error *err)
{
  fprintf(stderr, "wire-midpoint: %s\n", err->msg);
  return 2;
}

int main(int argc, char **argv)
{
  if (argc < 3) {
    fprintf(stderr, "usage: wire-midpoint SCENE.ini SECONDS [section.key=value ...]\n");
    return 2;
  }
  static lw_params p;
  lw_error err = {0};
  if (lw_params_read(&p, argv[1], &err)) return fail(&err);
  for (int i = 3; i < argc; i++)
    if (lw_params_set(&p, argv[i], &err)) return fail(&err);
  if (lw_params_resolve(&p, &err)) return fail(&err);
  const lw_system_type *t = &lw_system_nurbs;
  void *su = t->setup_new(&p, &err);
  lw_nurbs_state *st = su ? t->state_new(su, &p, 0, &err) : NULL;
  lw_dynamics *d = st ? lw_dynamics_new(t, st, &p, &err) : NULL;
  if (!d) return fail(&err);
  double u = 0.5 * (lw_nurbs_u0(st->c) + lw_nurbs_u1(st->c)), end = atof(argv[2]);
  while (d->time <= end + 0.5 * d->dt) {
    double pt[2];
    lw_nurbs_eval(st->c, u, pt, NULL, NULL);
    printf("%.6f %.10g %.10g\n", d->time, pt[0], pt[1]);
    if (lw_dynamics_step(d, &err)) return fail(&err);
  }
  lw_dynamics_free(d);
  t->state_free(st);
  t->setup_free(su);
  return 0;
}
