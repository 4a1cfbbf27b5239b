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

/* The 4x4 transpose: r[i][j] <- r[j][i] (__builtin_shufflevector: GCC 12
 * and clang alike). */
static inline void lanes_transpose(vd r[4])
{
    vd t0 = __builtin_shufflevector(r[0], r[1], 0, 4, 2, 6),
       t1 = __builtin_shufflevector(r[0], r[1], 1, 5, 3, 7),
       t2 = __builtin_shufflevector(r[2], r[3], 0, 4, 2, 6),
       t3 = __builtin_shufflevector(r[2], r[3], 1, 5, 3, 7);
    r[0] = __builtin_shufflevector(t0, t2, 0, 1, 4, 5);
    r[1] = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
    r[2] = __builtin_shufflevector(t0, t2, 2, 3, 6, 7);
    r[3] = __builtin_shufflevector(t1, t3, 2, 3, 6, 7);
}

/* LANES doubles at any address (one unaligned vector load or store). */
typedef double vd_any
    __attribute__((vector_size(LANES * sizeof(double)), aligned(sizeof(double)), may_alias));

/* out[k] = (base[w row[0] + k], ..., base[w row[LANES-1] + k]) for k < w:
 * row row[l] of an array of rows of w doubles, lane by lane, as w vectors.
 * Each group of four columns is four whole-row loads straight into
 * registers and a transpose: no copy through memory, whose narrower stores
 * the wide loads after them could not take forwarded. */
static inline void lanes_load(const double *base, int w, const int row[LANES], vd *out)
{
    const double *p[LANES];
    for (int l = 0; l < LANES; l++)
        p[l] = base + (long)w * row[l];
    int k = 0;
    for (; k + LANES <= w; k += LANES) {
        vd r[4] = {*(const vd_any *)(p[0] + k), *(const vd_any *)(p[1] + k),
                   *(const vd_any *)(p[2] + k), *(const vd_any *)(p[3] + k)};
        lanes_transpose(r);
        out[k] = r[0], out[k + 1] = r[1], out[k + 2] = r[2], out[k + 3] = r[3];
    }
    for (; k < w; k++)
        out[k] = (vd){p[0][k], p[1][k], p[2][k], p[3][k]};
}

/* lanes_load's inverse for the first nl lanes: base[w row[l] + k] = in[k][l]. */
static inline void lanes_store(const vd *in, int w, double *base, const int row[LANES], int nl)
{
    double *p[LANES];
    for (int l = 0; l < LANES; l++)
        p[l] = base + (long)w * row[l];
    int k = 0;
    if (nl == LANES)
        for (; k + LANES <= w; k += LANES) {
            vd r[4] = {in[k], in[k + 1], in[k + 2], in[k + 3]};
            lanes_transpose(r);
            *(vd_any *)(p[0] + k) = r[0], *(vd_any *)(p[1] + k) = r[1];
            *(vd_any *)(p[2] + k) = r[2], *(vd_any *)(p[3] + k) = r[3];
        }
    for (; k < w; k++)
        for (int l = 0; l < nl; l++)
            p[l][k] = in[k][l];
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
