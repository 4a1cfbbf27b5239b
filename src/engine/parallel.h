/* Parallel loops that cost nothing when they run on one thread.  An
 * OpenMP construct enters the runtime even when its `if` clause is false
 * or one thread is allowed, and libgomp then allocates and frees a team of
 * one for it: a step of a few-tet fragment paid an allocation for each of
 * its loops.  CF_PARALLEL runs the statement under the pragma only when
 * `cond` holds and more than one thread is allowed, and as plain code on
 * this thread otherwise.  The loops give the same bits on any number of
 * threads (chunks.h, and each thread writes its own items), so which way
 * a loop runs never shows in the results.  Code inside may call
 * omp_get_num_threads() and omp_get_thread_num() (1 and 0 when plain). */
#ifndef COHFRAC_PARALLEL_H
#define COHFRAC_PARALLEL_H

#include <omp.h>

#define CF_PARALLEL(cond, pragma, ...)                                                             \
    do {                                                                                           \
        if ((cond) && omp_get_max_threads() > 1) {                                                 \
            _Pragma(pragma) __VA_ARGS__                                                            \
        } else {                                                                                   \
            __VA_ARGS__                                                                            \
        }                                                                                          \
    } while (0)

#endif
