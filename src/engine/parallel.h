/* Parallel loops that cost nothing when they run on one thread.  An
 * OpenMP construct enters the runtime even when its `if` clause is false
 * or one thread is allowed, and libgomp then allocates and frees a team of
 * one for it: a step of a few-tet fragment paid an allocation for each of
 * its loops.  CF_PARALLEL runs the statement under the pragma only when
 * `cond` holds and more than one thread is allowed, and as plain code on
 * this thread otherwise.  The loops give the same bits on any number of
 * threads (chunks.h, and each thread writes its own items), so which way
 * a loop runs never shows in the results.  Code inside asks CF_TEAM_SIZE
 * and CF_TEAM_RANK for its team, 1 and 0 when it runs as plain code: a
 * fragment stepped on one thread of a team (cf_fracture_pass) runs its
 * loops plainly, where omp_get_num_threads() would still give that
 * team's size. */
#ifndef COHFRAC_PARALLEL_H
#define COHFRAC_PARALLEL_H

#include <omp.h>

#define CF_PARALLEL(cond, pragma, ...)                                                             \
    do {                                                                                           \
        if ((cond) && omp_get_max_threads() > 1) {                                                 \
            const int cf_team_ = 1; (void)cf_team_;                                                \
            _Pragma(pragma) __VA_ARGS__                                                            \
        } else {                                                                                   \
            const int cf_team_ = 0; (void)cf_team_;                                                \
            __VA_ARGS__                                                                            \
        }                                                                                          \
    } while (0)

/* Inside CF_PARALLEL's statement only (parallel.h's note). */
#define CF_TEAM_SIZE (cf_team_ ? omp_get_num_threads() : 1)
#define CF_TEAM_RANK (cf_team_ ? omp_get_thread_num() : 0)

#endif
