/*
** anneal_net.h -- the hooks through which a tempering run (anneal.h) is
** spread over several processes: the rungs are shared out, each process
** sweeps the replicas it owns, and the hooks carry what must be known
** everywhere.  The plain build never sets them (lw_anneal.net is NULL);
** the MPI build (mpi_tempering.h) fills them.  Nothing here names MPI.
**
** Every process holds every replica's system, but sweeps only its own
** (replica r belongs to process r * P / R, so R >= P).  The others are
** stand-ins: their splines stay as they were, and share() gives them the
** running energy terms of the real replica after every sweep and puts its
** total in energy[], so the exchange, the trace and the schedule read the
** same numbers on every process.
** Chains are by rung, as in the one-process run; when a swap moves a rung
** to a replica on another process, moved() brings the rung's chain data
** (stream state, step sizes, counts) with it.  The splines never travel
** between processes during the run.
*/
#ifndef LINEWISE_ANNEAL_NET_H
#define LINEWISE_ANNEAL_NET_H

#include "linewise/error.h"
#include "linewise/tempering.h"

#ifdef __cplusplus
extern "C" {
#endif

struct lw_anneal;

typedef struct lw_anneal_net lw_anneal_net;
struct lw_anneal_net {
  int rank, size;                /* this process, the number of processes */
  int stop_agreed;               /* a stop asked on any process, as of the last share() */
  double energy[LW_TEMPERING_MAX]; /* by replica: the total as of the last share() */
  /* After the local rungs swept (failed: one of them ran out of memory):
  ** energies of every rung and the coldest chain's counts everywhere,
  ** the stop request and any failure agreed (err: the failing process's). */
  lw_status (*share)(lw_anneal_net *net, struct lw_anneal *a, int failed, lw_error *err);
  /* After an exchange step swapped the systems between the chains of the
  ** pairs in swapped[]: the chain data of rungs that changed process. */
  lw_status (*moved)(lw_anneal_net *net, struct lw_anneal *a, const int *swapped, lw_error *err);
  /* After a drift check of the local replicas (s: its status): the largest
  ** drift and the status agreed. */
  lw_status (*drift)(lw_anneal_net *net, struct lw_anneal *a, lw_status s, lw_error *err);
  /* At a trace row, collectively: the n values v of process root (the one
  ** that sweeps the replica at rung 0: its observables), everywhere. */
  void (*broadcast)(lw_anneal_net *net, int root, double *v, int n);
  /* The whole checkpoint, collectively (replaces lw_checkpoint_write). */
  lw_status (*checkpoint)(lw_anneal_net *net, struct lw_anneal *a, lw_error *err);
};

/* The process that sweeps replica r of n on p processes (n >= p). */
static inline int lw_anneal_net_owner(int r, int n, int p) { return (int)((long long)r * p / n); }

#ifdef __cplusplus
}
#endif

#endif
