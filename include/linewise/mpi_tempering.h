/*
** mpi_tempering.h -- parallel tempering over MPI processes: the hooks of
** anneal_net.h filled with Open MPI calls, and what the command line needs
** around them.  Only the MPI build (make mpi, bin/linewise-mpi) compiles
** src/mpi/mpi_tempering.c; nothing here names an MPI type.
**
** Traffic (docs/SCALING.md): after every sweep one reduction of the
** replicas' energy terms (a few words per replica); at an exchange, for
** each accepted swap between two processes, the two rungs' chain data
** (stream state, step sizes, counts; about 5 kB with the mt19937 stream);
** at a checkpoint, the text of the local rungs' sections gathered to
** process 0, which writes state.lw last.  The exchange decisions are drawn
** on every process from its copy of the one master stream, from the same
** energies, so they agree without a message.
**
** Failures: a failure on one process that the others can learn of at the
** next collective step (out of memory, a file that cannot be written) is
** agreed there, and every process returns the first failing process's
** error.  A process that dies, or an MPI call that fails, ends the job
** with a message naming the process (MPI_Abort); mpirun then stops the rest.
*/
#ifndef LINEWISE_MPI_TEMPERING_H
#define LINEWISE_MPI_TEMPERING_H

#include <signal.h>

#include "linewise/anneal_net.h"

#ifdef __cplusplus
extern "C" {
#endif

/* MPI_Init_thread and the hooks of this process; stop is the flag the
** signal handler sets (agreed between the processes after every sweep).
** NULL if MPI could not start (the message printed). */
lw_anneal_net *lw_mpi_init(int *argc, char ***argv, volatile sig_atomic_t *stop);

/* Collective: every process returns the status of the first process whose
** s is not LW_OK, with its message, or LW_OK; also agrees on the stop
** flag (net->stop_agreed). */
lw_status lw_mpi_agree(lw_anneal_net *net, lw_status s, lw_error *err);

/* Collective: process 0's text (n bytes, NUL-terminated) into every
** process's. */
void lw_mpi_share_text(lw_anneal_net *net, char *text, size_t n);

/* 1 if the last failure a hook or lw_mpi_agree returned was agreed (every
** process has it); a failure that was not must end the job (lw_mpi_abort). */
int lw_mpi_agreed(void);

/* Collective, at the end of a run or a stop: process 0 prints (unless
** quiet) the wall time per sweep and the time per sweep spent in the
** exchange steps' messages (the reduction after each sweep, the chain
** moves, the drift checks), the least over the processes and the most
** (with the wait for the slowest process); then, timed alone in a loop,
** one reduction and one chain move (the messages' own cost). */
struct lw_anneal;
void lw_mpi_report(lw_anneal_net *net, const struct lw_anneal *a, int quiet);

/* Ends the whole job at once with exit status code (a failure the other
** processes cannot learn of by themselves). */
void lw_mpi_abort(int code);

/* MPI_Finalize. */
void lw_mpi_finish(void);

#ifdef __cplusplus
}
#endif

#endif
