/* mpi_tempering.c -- the hooks of anneal_net.h over MPI (mpi_tempering.h). */
#define _GNU_SOURCE /* sched_getaffinity */
#include "linewise/mpi_tempering.h"

#include <mpi.h>
#include <omp.h>
#include <sched.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "linewise/anneal.h"
#include "linewise/checkpoint.h"
#include "linewise/state.h"

typedef struct {
  lw_anneal_net net;          /* first: the hooks get a pointer to it */
  volatile sig_atomic_t *stop;
  uint64_t *buf;              /* share()'s words */
  size_t buf_len;
  /* for lw_mpi_report: seconds inside the per-sweep steps' MPI calls, from
  ** the first share() on */
  double t_first, t_comm;
  long sweeps, moves;
} mpi_net;

static MPI_Comm comm = MPI_COMM_NULL;
static int my_rank;
static int agreed_failure; /* the last error returned came from an agreement */

int lw_mpi_agreed(void) { return agreed_failure; }

void lw_mpi_abort(int code) { MPI_Abort(comm != MPI_COMM_NULL ? comm : MPI_COMM_WORLD, code); }

void lw_mpi_finish(void)
{
  if (comm != MPI_COMM_NULL) MPI_Comm_free(&comm);
  MPI_Finalize();
}

/* Any MPI call that fails (a peer gone, the network down) ends the job:
** there is nothing to agree with any more.  state.lw is only ever replaced
** whole, so the directory resumes from the last checkpoint. */
static void on_mpi_error(MPI_Comm *c, int *code, ...)
{
  char what[MPI_MAX_ERROR_STRING] = "";
  int len = 0;
  MPI_Error_string(*code, what, &len);
  fprintf(stderr, "linewise: process %d: MPI failed (%s): another process died or the network failed; the run "
          "stops, and 'resume DIR' continues from the last checkpoint\n", my_rank, what);
  MPI_Abort(*c, 1);
}

/* Gives every process the error of the lowest failing rank first (or LW_OK
** if first == size). */
static lw_status adopt(int first, int size, lw_error *err)
{
  if (first >= size) return LW_OK;
  agreed_failure = 1;
  int code = err->code;
  MPI_Bcast(&code, 1, MPI_INT, first, comm);
  MPI_Bcast(err->msg, (int)sizeof err->msg, MPI_CHAR, first, comm);
  err->code = (lw_status)code;
  return err->code;
}

lw_status lw_mpi_agree(lw_anneal_net *net, lw_status s, lw_error *err)
{
  mpi_net *m = (mpi_net *)net;
  int mine[2] = {s ? net->rank : net->size, -(int)*m->stop}, all[2];
  MPI_Allreduce(mine, all, 2, MPI_INT, MPI_MIN, comm);
  net->stop_agreed = all[1] < 0;
  return adopt(all[0], net->size, err);
}

void lw_mpi_share_text(lw_anneal_net *net, char *text, size_t n)
{
  (void)net;
  MPI_Bcast(text, (int)n, MPI_CHAR, 0, comm);
  text[n - 1] = '\0';
}

static int rung_here(const lw_anneal *a, int k)
{
  int r = a->pt ? a->pt->at[k] : 0;
  return lw_anneal_net_owner(r, a->n_rep, a->net->size) == a->net->rank;
}

static int replica_here(const lw_anneal *a, int r)
{
  return lw_anneal_net_owner(r, a->n_rep, a->net->size) == a->net->rank;
}

/* One bitwise-or reduction of words where each process fills only its own
** slots: every value arrives bit for bit (signed zeros, infinities and
** NaNs included), which a sum would not promise.  Layout: a status per
** process, the stop flag, per replica its terms and total, the coldest
** rung's move counts (lw_move_stats, field by field). */
#define STATS_WORDS 6
/* Per replica its terms and total, in the slots of the replicas this
** process sweeps (the others stay 0 for the reduction). */
static void pack_terms(const lw_anneal *a, uint64_t *w)
{
  const lw_system_type *t = a->sys_type;
  const int nt = t->n_terms, per = nt + 1;
  double term[LW_SYSTEM_TERMS_MAX + 1];
  for (int r = 0; r < a->n_rep; r++)
    if (replica_here(a, r)) {
      t->terms(a->systems[r]->state, term);
      term[nt] = lw_system_total(a->systems[r]);
      memcpy(w + (size_t)r * (size_t)per, term, (size_t)per * sizeof *term);
    }
}

/* After the reduction: every replica's total, and the stand-ins' terms. */
static void unpack_terms(lw_anneal_net *net, lw_anneal *a, const uint64_t *w)
{
  const lw_system_type *t = a->sys_type;
  const int nt = t->n_terms, per = nt + 1;
  double term[LW_SYSTEM_TERMS_MAX + 1];
  for (int r = 0; r < a->n_rep; r++) {
    memcpy(term, w + (size_t)r * (size_t)per, (size_t)per * sizeof *term);
    net->energy[r] = term[nt];
    if (!replica_here(a, r)) t->set_terms(a->systems[r]->state, term);
  }
}

static lw_status share(lw_anneal_net *net, lw_anneal *a, int failed, lw_error *err)
{
  mpi_net *m = (mpi_net *)net;
  const lw_system_type *t = a->sys_type;
  int n = a->n_rep, nt = t->n_terms, nm = a->chain->n_moves, per = nt + 1;
  size_t len = (size_t)net->size + 1 + (size_t)n * (size_t)per + STATS_WORDS * (size_t)nm;
  if (len > m->buf_len) {
    uint64_t *b = realloc(m->buf, len * sizeof *b);
    /* every process needs the same length: failing here alone would leave
    ** the others waiting in the reduction */
    if (!b) {
      fprintf(stderr, "linewise: process %d: out of memory for %zu words of exchange data\n", net->rank, len);
      lw_mpi_abort(1);
    }
    m->buf = b;
    m->buf_len = len;
  }
  uint64_t *w = m->buf, *st = w + net->size + 1 + (size_t)n * (size_t)per;
  memset(w, 0, len * sizeof *w);
  if (failed) {
    lw_error_set(err, LW_ENOMEM, "process %d: out of memory growing a system's caches", net->rank);
    w[net->rank] = 1;
  }
  w[net->size] = *m->stop != 0;
  pack_terms(a, w + net->size + 1);
  if (rung_here(a, 0))
    for (int k = 0; k < nm; k++) {
      const lw_move_stats *s = &a->chain->stats[k];
      uint64_t v[STATS_WORDS] = {s->proposed, s->accepted, s->nan, s->irregular, s->crowded,
                                  s->outside};
      memcpy(st + STATS_WORDS * k, v, sizeof v);
    }
  double t0 = MPI_Wtime();
  if (!m->sweeps++) m->t_first = t0;
  MPI_Allreduce(MPI_IN_PLACE, w, (int)len, MPI_UINT64_T, MPI_BOR, comm);
  m->t_comm += MPI_Wtime() - t0;
  net->stop_agreed = w[net->size] != 0;
  unpack_terms(net, a, w + net->size + 1);
  if (!rung_here(a, 0))
    for (int k = 0; k < nm; k++) {
      lw_move_stats *s = &a->chain->stats[k];
      const uint64_t *v = st + STATS_WORDS * k;
      *s = (lw_move_stats){v[0], v[1], v[2], v[3], v[4], v[5]};
    }
  int first = net->size;
  for (int p = net->size - 1; p >= 0; p--)
    if (w[p]) first = p;
  return adopt(first, net->size, err);
}

/* ---- chain data ------------------------------------------------------- */

/* What a rung's chain carries from sweep to sweep besides its temperature
** (the same everywhere) and its system: the stream, the steps, the tuning
** window and the counts.  Raw bytes: every process runs the same binary. */
static size_t chain_bytes(const lw_chain *c)
{
  size_t nm = (size_t)c->n_moves;
  return gsl_rng_size(c->rng) + nm * (sizeof c->step[0] + 2 * sizeof c->win_prop[0] + sizeof c->stats[0]);
}

static void chain_pack(const lw_chain *c, unsigned char *b)
{
  size_t nm = (size_t)c->n_moves, rs = gsl_rng_size(c->rng);
  memcpy(b, gsl_rng_state(c->rng), rs);
  b += rs;
  memcpy(b, c->step, nm * sizeof c->step[0]);
  b += nm * sizeof c->step[0];
  memcpy(b, c->win_prop, nm * sizeof c->win_prop[0]);
  b += nm * sizeof c->win_prop[0];
  memcpy(b, c->win_acc, nm * sizeof c->win_acc[0]);
  b += nm * sizeof c->win_acc[0];
  memcpy(b, c->stats, nm * sizeof c->stats[0]);
}

static void chain_unpack(lw_chain *c, const unsigned char *b)
{
  size_t nm = (size_t)c->n_moves, rs = gsl_rng_size(c->rng);
  memcpy(gsl_rng_state(c->rng), b, rs);
  b += rs;
  memcpy(c->step, b, nm * sizeof c->step[0]);
  b += nm * sizeof c->step[0];
  memcpy(c->win_prop, b, nm * sizeof c->win_prop[0]);
  b += nm * sizeof c->win_prop[0];
  memcpy(c->win_acc, b, nm * sizeof c->win_acc[0]);
  b += nm * sizeof c->win_acc[0];
  memcpy(c->stats, b, nm * sizeof c->stats[0]);
}

/* The systems of rungs k and k+1 have swapped.  If they live on two
** processes A (the one now at k+1) and B, A swept rung k's chain and B
** rung k+1's, and each now needs the other's: one exchange of two small
** messages per such pair, in rung order on both sides. */
static void broadcast(lw_anneal_net *net, int root, double *v, int n)
{
  (void)net;
  MPI_Bcast(v, n, MPI_DOUBLE, root, comm);
}

static lw_status moved(lw_anneal_net *net, lw_anneal *a, const int *swapped, lw_error *err)
{
  int n = a->n_rep;
  size_t len = chain_bytes(a->chains[0]);
  unsigned char *out = NULL, *in = NULL;
  for (int k = 0; k + 1 < n; k++) {
    if (!swapped[k]) continue;
    int A = lw_anneal_net_owner(a->pt->at[k + 1], n, net->size), B = lw_anneal_net_owner(a->pt->at[k], n, net->size);
    if (A == B || (net->rank != A && net->rank != B)) continue;
    if (!out && (!(out = malloc(len)) || !(in = malloc(len)))) {
      fprintf(stderr, "linewise: process %d: out of memory for %zu bytes of chain data\n", net->rank, len);
      lw_mpi_abort(1);
    }
    int send = net->rank == A ? k : k + 1, recv = net->rank == A ? k + 1 : k, peer = net->rank == A ? B : A;
    chain_pack(a->chains[send], out);
    double t0 = MPI_Wtime();
    MPI_Sendrecv(out, (int)len, MPI_BYTE, peer, k, in, (int)len, MPI_BYTE, peer, k, comm, MPI_STATUS_IGNORE);
    ((mpi_net *)net)->t_comm += MPI_Wtime() - t0;
    ((mpi_net *)net)->moves++;
    chain_unpack(a->chains[recv], in);
  }
  free(out);
  free(in);
  return LW_OK;
}

/* After a recomputation from scratch the totals differ from the running
** ones in their last bits: the stand-ins take them too, so that what is
** read of another process's rungs before the next sweep (the summary
** after the last) is what the one-process run reads. */
static lw_status drift(lw_anneal_net *net, lw_anneal *a, lw_status s, lw_error *err)
{
  mpi_net *m = (mpi_net *)net;
  double t0 = MPI_Wtime();
  MPI_Allreduce(MPI_IN_PLACE, &a->max_drift, 1, MPI_DOUBLE, MPI_MAX, comm);
  s = lw_mpi_agree(net, s, err);
  if (!s && m->buf) {
    size_t len = (size_t)a->n_rep * (size_t)(a->sys_type->n_terms + 1);
    memset(m->buf, 0, len * sizeof *m->buf); /* share() sized it for more */
    pack_terms(a, m->buf);
    MPI_Allreduce(MPI_IN_PLACE, m->buf, (int)len, MPI_UINT64_T, MPI_BOR, comm);
    unpack_terms(net, a, m->buf);
  }
  m->t_comm += MPI_Wtime() - t0;
  return s;
}

static int cmp_double(const void *x, const void *y)
{
  double a = *(const double *)x, b = *(const double *)y;
  return (a > b) - (a < b);
}

/* The messages' own cost, away from the sweeps: seconds for one reduction
** of share()'s words and for one chain move (processes 0 and 1), each the
** median of a loop (a busy machine stretches some of them by whole time
** slices). */
enum { LOOPS = 201 };

static double median(double *t)
{
  qsort(t, LOOPS, sizeof *t, cmp_double);
  return t[LOOPS / 2];
}

static void message_cost(mpi_net *m, const lw_anneal *a, double *reduce, double *move)
{
  double t[LOOPS];
  size_t words = m->buf_len, bytes = chain_bytes(a->chains[0]);
  unsigned char *b = malloc(bytes), *c = malloc(bytes);
  int ok = b && c && m->buf, all = 0;
  MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, comm);
  *reduce = *move = 0.0;
  if (all) {
    MPI_Barrier(comm);
    for (int i = 0; i < LOOPS; i++) {
      double t0 = MPI_Wtime();
      MPI_Allreduce(MPI_IN_PLACE, m->buf, (int)words, MPI_UINT64_T, MPI_BOR, comm);
      t[i] = MPI_Wtime() - t0;
    }
    *reduce = median(t);
    memset(b, 0, bytes);
    MPI_Barrier(comm);
    if (m->net.rank < 2 && m->net.size > 1) {
      for (int i = 0; i < LOOPS; i++) {
        double t0 = MPI_Wtime();
        MPI_Sendrecv(b, (int)bytes, MPI_BYTE, 1 - m->net.rank, 0, c, (int)bytes, MPI_BYTE, 1 - m->net.rank, 0, comm,
                     MPI_STATUS_IGNORE);
        t[i] = MPI_Wtime() - t0;
      }
      *move = median(t);
    }
  }
  free(b);
  free(c);
}

void lw_mpi_report(lw_anneal_net *net, const lw_anneal *a, int quiet)
{
  mpi_net *m = (mpi_net *)net;
  double wall = m->sweeps ? MPI_Wtime() - m->t_first : 0.0, per = m->sweeps ? m->t_comm / (double)m->sweeps : 0.0;
  double lo = 0.0, hi = 0.0;
  long moves = 0;
  MPI_Reduce(&per, &lo, 1, MPI_DOUBLE, MPI_MIN, 0, comm);
  MPI_Reduce(&per, &hi, 1, MPI_DOUBLE, MPI_MAX, 0, comm);
  MPI_Reduce(&m->moves, &moves, 1, MPI_LONG, MPI_SUM, 0, comm);
  double reduce = 0.0, move = 0.0;
  if (m->sweeps >= 2) message_cost(m, a, &reduce, &move);
  if (quiet || net->rank || m->sweeps < 2) return;
  double sweep = wall / (double)(m->sweeps - 1); /* from the end of the first sweep */
  /* each move was counted by both of its processes */
  fprintf(stderr, "linewise: MPI: %d process%s, %d replicas, %d thread%s each: %.3f ms a sweep; exchange steps %.3f "
          "ms a sweep (%.1f %%) on the quickest process, %.3f ms (%.1f %%) on the one that waited longest; %.2f "
          "chain moves a sweep of %zu bytes; alone, one reduction of %zu words %.1f us, one chain move %.1f us\n",
          net->size, net->size == 1 ? "" : "es", a->n_rep, omp_get_max_threads(), omp_get_max_threads() == 1 ? "" : "s",
          1e3 * sweep, 1e3 * lo, 100.0 * lo / sweep, 1e3 * hi,
          100.0 * hi / sweep, (double)moves / 2.0 / (double)m->sweeps, chain_bytes(a->chains[0]), m->buf_len,
          1e6 * reduce, 1e6 * move);
}

/* ---- checkpoints ------------------------------------------------------ */

/* The sections of the local rungs as text, each record an int rung and two
** lengths (its [chain K] and [system K]) followed by the two texts. */
typedef struct {
  char *text;
  size_t len;
  FILE *f;
} blob;

static lw_status render(lw_anneal *a, blob *b, lw_error *err)
{
  b->text = NULL;
  b->len = 0;
  if (!(b->f = open_memstream(&b->text, &b->len)))
    return lw_error_set(err, LW_ENOMEM, "process %d: out of memory for a checkpoint", a->net->rank);
  lw_status s = LW_OK;
  int bad = 0;
  for (int k = 0; k < a->n_rep && !s; k++) {
    if (!rung_here(a, k)) continue;
    char *part[2] = {NULL, NULL};
    size_t plen[2] = {0, 0};
    for (int q = 0; q < 2 && !s; q++) {
      lw_ckpt_writer w = {.f = open_memstream(&part[q], &plen[q])};
      if (!w.f) bad = 1;
      else if (q == 0) lw_checkpoint_put_chain(&w, a, k, &bad);
      else s = lw_checkpoint_put_system(&w, a, k, err);
      if (w.f && (ferror(w.f) | fclose(w.f))) bad = 1;
    }
    if (!s && !bad) {
      uint64_t head[3] = {(uint64_t)k, plen[0], plen[1]};
      fwrite(head, sizeof head, 1, b->f);
      fwrite(part[0], 1, plen[0], b->f);
      fwrite(part[1], 1, plen[1], b->f);
    }
    free(part[0]);
    free(part[1]);
    if (!s && k >= 1) s = lw_checkpoint_write_replica(a, k, err);
  }
  if (ferror(b->f) | fclose(b->f)) bad = 1;
  b->f = NULL;
  if (!s && bad) s = lw_error_set(err, LW_ENOMEM, "process %d: out of memory writing a checkpoint", a->net->rank);
  return s;
}

/* Process 0: state.lw from its own parts and everyone's texts, in the order
** of lw_checkpoint_write, so the bytes are the same. */
static lw_status assemble(lw_anneal *a, const char *all, size_t total, long trace_bytes, lw_error *err)
{
  int n = a->n_rep;
  const char **chain = calloc((size_t)n, sizeof *chain), **sys = calloc((size_t)n, sizeof *sys);
  size_t *clen = calloc((size_t)n, sizeof *clen), *slen = calloc((size_t)n, sizeof *slen);
  lw_status s = LW_OK;
  if (!chain || !sys || !clen || !slen) s = lw_error_set(err, LW_ENOMEM, "out of memory writing a checkpoint");
  for (size_t at = 0; !s && at < total;) {
    uint64_t head[3];
    memcpy(head, all + at, sizeof head);
    at += sizeof head;
    chain[head[0]] = all + at;
    clen[head[0]] = head[1];
    sys[head[0]] = all + at + head[1];
    slen[head[0]] = head[2];
    at += head[1] + head[2];
  }
  for (int k = 0; !s && k < n; k++)
    if (!chain[k]) s = lw_error_set(err, LW_EIO, "checkpoint: no process sent rung %d", k);
  char path[LW_PATH_MAX + 32];
  lw_path_join(path, sizeof path, a->dir, "state.lw");
  lw_ckpt_writer w;
  if (!s && !(s = lw_ckpt_begin(&w, path, LW_STATE_HEADER, err))) {
    int bad = 0;
    w.no_sum = a->unsummed;
    lw_checkpoint_put_run(&w, a, trace_bytes);
    for (int k = 0; k < n; k++) fwrite(chain[k], 1, clen[k], w.f);
    lw_checkpoint_put_ensemble(&w, a, &bad);
    for (int k = 0; k < n; k++) fwrite(sys[k], 1, slen[k], w.f);
    if (bad) {
      lw_ckpt_abort(&w);
      s = lw_error_set(err, LW_ENOMEM, "out of memory writing a checkpoint");
    } else {
      s = lw_checkpoint_commit(&w, a, err);
    }
  }
  free(chain);
  free(sys);
  free(clen);
  free(slen);
  return s ? s : lw_checkpoint_write_timing(a, err);
}

/* Every process writes the replica files of its rungs; their sections go
** to process 0, which writes state.lw last: a kill at any moment leaves
** the previous or the new state.lw, and resume reads nothing else. */
static lw_status checkpoint(lw_anneal_net *net, lw_anneal *a, lw_error *err)
{
  long trace_bytes = 0;
  blob b = {0};
  lw_status s = lw_checkpoint_sync_trace(a, &trace_bytes, err);
  if (!s) s = render(a, &b, err);
  if ((s = lw_mpi_agree(net, s, err))) {
    free(b.text);
    return s;
  }
  long long mine = (long long)b.len, *lens = NULL;
  int *counts = NULL, *displs = NULL;
  char *all = NULL;
  long long total = 0;
  if (net->rank == 0) {
    lens = malloc((size_t)net->size * sizeof *lens);
    counts = malloc((size_t)net->size * sizeof *counts);
    displs = malloc((size_t)net->size * sizeof *displs);
    if (!lens || !counts || !displs) {
      fprintf(stderr, "linewise: process 0: out of memory gathering a checkpoint\n");
      lw_mpi_abort(1);
    }
  }
  MPI_Gather(&mine, 1, MPI_LONG_LONG, lens, 1, MPI_LONG_LONG, 0, comm);
  if (net->rank == 0) {
    for (int p = 0; p < net->size; p++) {
      if (total + lens[p] > 0x7fffffffLL) {
        fprintf(stderr, "linewise: process 0: a checkpoint of over 2 GB cannot be gathered in one message\n");
        lw_mpi_abort(1);
      }
      displs[p] = (int)total;
      counts[p] = (int)lens[p];
      total += lens[p];
    }
    if (!(all = malloc(total ? (size_t)total : 1))) {
      fprintf(stderr, "linewise: process 0: out of memory gathering a checkpoint of %lld bytes\n", total);
      lw_mpi_abort(1);
    }
  }
  MPI_Gatherv(b.text, (int)b.len, MPI_CHAR, all, counts, displs, MPI_CHAR, 0, comm);
  free(b.text);
  if (net->rank == 0) s = assemble(a, all, (size_t)total, trace_bytes, err);
  free(all);
  free(lens);
  free(counts);
  free(displs);
  return lw_mpi_agree(net, s, err);
}

/* ---- set-up ----------------------------------------------------------- */

lw_anneal_net *lw_mpi_init(int *argc, char ***argv, volatile sig_atomic_t *stop)
{
  static mpi_net m;
  int provided = 0;
  /* the OpenMP threads of a process sweep its rungs; only the main thread
  ** calls MPI */
  if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
    fprintf(stderr, "linewise: MPI could not start\n");
    return NULL;
  }
  MPI_Comm_dup(MPI_COMM_WORLD, &comm);
  MPI_Errhandler h;
  MPI_Comm_create_errhandler(on_mpi_error, &h);
  MPI_Comm_set_errhandler(comm, h);
  MPI_Errhandler_free(&h);
  MPI_Comm_rank(comm, &my_rank);
  m.net.rank = my_rank;
  MPI_Comm_size(comm, &m.net.size);
  /* Threads: the cores a process may use shared among the node's processes
  ** that may use them too, unless OMP_NUM_THREADS or --threads says
  ** otherwise.  OpenMP's default (all of them in every process) oversubscribes
  ** P times, and spinning threads of one process then starve the others at
  ** each reduction.  A process mpirun bound to its own cores (Open MPI binds
  ** each to one core with two processes or fewer, `--map-by ...:pe=T` to T)
  ** shares them with none; unbound, inside a cpuset or a container smaller
  ** than the node, all share the set (the node's core count would give each
  ** all of it, and the whole node's divided would give bound ones too few). */
  MPI_Comm node;
  int on_node = 1, sharing = 0;
  cpu_set_t mine;
  CPU_ZERO(&mine);
  const int known = !sched_getaffinity(0, sizeof mine, &mine) && CPU_COUNT(&mine) > 0;
  if (MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node) == MPI_SUCCESS) {
    MPI_Comm_size(node, &on_node);
    unsigned char *all = malloc((size_t)on_node * sizeof mine);
    if (all && MPI_Allgather(&mine, (int)sizeof mine, MPI_BYTE, all, (int)sizeof mine, MPI_BYTE, node) == MPI_SUCCESS)
      for (int q = 0; q < on_node; q++) {
        cpu_set_t other, both;
        memcpy(&other, all + (size_t)q * sizeof mine, sizeof other);
        CPU_AND(&both, &other, &mine);
        sharing += CPU_COUNT(&both) > 0;
      }
    free(all);
    MPI_Comm_free(&node);
  }
  if (!known || sharing < 1) sharing = on_node;
  if (!getenv("OMP_NUM_THREADS")) {
    const int t = (known ? CPU_COUNT(&mine) : omp_get_num_procs()) / sharing;
    omp_set_num_threads(t > 0 ? t : 1);
  }
  m.net.share = share;
  m.net.moved = moved;
  m.net.drift = drift;
  m.net.checkpoint = checkpoint;
  m.net.broadcast = broadcast;
  m.stop = stop;
  return &m.net;
}
