/* Lanes: LANES doubles side by side as one GCC vector (vector extension),
 * for the kernels that run the same formulas on independent items (the
 * Tet4 force block, the PBD bars of one colour).  Each operation on a `vd`
 * is one vector instruction (two on SSE2), and IEEE arithmetic rounds each
 * lane alone: a lane gets exactly the bits of the scalar formula done in
 * the same order, at any vector width.  Fused multiply-add stays off
 * (-ffp-contract=off), so the scalar and vector builds agree. */
#ifndef COHFRAC_LANES_H
#define COHFRAC_LANES_H

#include <math.h>

#define LANES 4
/* The vectors never cross a call that is not inlined, so the ABI note
 * about passing them without AVX does not apply. */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
typedef double vd __attribute__((vector_size(LANES * sizeof(double))));
typedef long long vm __attribute__((vector_size(LANES * sizeof(double)))); /* lane masks */

static inline vd splat(double a) { return (vd){a, a, a, a}; }

/* m ? a : b, lane by lane (m: all ones or all zeros). */
static inline vd pick(vm m, vd a, vd b) { return (vd)(((vm)a & m) | ((vm)b & ~m)); }

static inline vd v_sqrt(vd a)
{
    for (int l = 0; l < LANES; l++)
        a[l] = sqrt(a[l]);
    return a;
}

/* With GCC on x86-64 a lane kernel is compiled twice, for AVX2 (four lanes
 * in one register) and for the baseline (two), and the loader picks the
 * one the processor runs: the same operations either way, so the same bits. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define CF_LANE_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define CF_LANE_CLONES
#endif

#endif
