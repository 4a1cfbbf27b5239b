/* cohfrac — independent cases spread over MPI ranks, for `cohfrac study`
 * and `cohfrac stability` started by an MPI launcher (`mpirun -np N`,
 * `srun`).  See docs/scale-out.md.
 *
 * Rank 0 plans and gathers: it hands out case indices one at a time, in
 * the order given (largest first), to whichever rank asks next, and runs
 * cases itself between serving requests (a coordinator thread answers the
 * other ranks).  Every rank runs one case at a time with its own threads.
 * A case's result is a fixed number of doubles; rank 0 receives them all.
 *
 * Built without MPI (cmake -DCOHFRAC_MPI=OFF, or libopenmpi-dev missing),
 * the size is always 1, and a run that an MPI launcher started as several
 * ranks is refused (cf_mpi_start). */
#ifndef COHFRAC_MPI_CASES_H
#define COHFRAC_MPI_CASES_H

#include "cohfrac/error.h"

/* Start MPI when this process is one of several ranks of an MPI launch
 * (the launcher's environment says so).  Returns the number of ranks (1:
 * not under MPI), or -1 with `err` set (CF_ERR_USAGE) when several ranks
 * were started but the build has no MPI, or MPI failed to start
 * (CF_ERR_EXTERNAL). */
int cf_mpi_start(int *argc, char ***argv, cf_error *err);

/* This process's rank (0 without MPI) and the number of ranks. */
int cf_mpi_rank(void);
int cf_mpi_size(void);

/* Ranks on this machine (shared memory), to share its cores; 1 without MPI. */
int cf_mpi_local_size(void);

/* End MPI (after the last case); a no-op without it. */
void cf_mpi_finish(void);

/* Run one case: fill result[0 .. len-1]. */
typedef void (*cf_case_run_fn)(int index, double *result, void *user);
/* Rank 0, once per finished case, one call at a time: `rank` ran it. */
typedef void (*cf_case_done_fn)(int index, const double *result, int rank, void *user);

/* Run the cases order[0 .. n-1] over all ranks (every rank calls this with
 * the same n, order and len).  On rank 0 results[len * index ...] is filled
 * for every index in `order` and `done` is called as each finishes; on the
 * other ranks `results` and `done` are not used.  Errors: CF_ERR_NOMEM,
 * CF_ERR_EXTERNAL (an MPI call or the coordinator thread failed). */
cf_status cf_mpi_cases(int n, const int *order, int len, double *results, cf_case_run_fn run,
                       cf_case_done_fn done, void *user, cf_error *err);

#endif
