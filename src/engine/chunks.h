/* Sums over a fragment's nodes or tets on the threads with the bits of no
 * particular thread count.  An OpenMP reduction adds each thread's part in
 * an order set by the number of threads, and floating-point addition is
 * not associative; here the items are cut into chunks by their count
 * alone, each chunk is summed in item order (on whichever thread), and the
 * chunks' sums are added in chunk order on one thread. */
#ifndef COHFRAC_CHUNKS_H
#define COHFRAC_CHUNKS_H

#define CF_CHUNK_MIN 1024 /* items per chunk at least: fewer items are one chunk,
                             the plain sum in item order */
#define CF_CHUNKS_MAX 64  /* chunks at most */
#define CF_SUMS_MAX 6     /* sums per call at most */

/* Adds the w terms of items i0..i1-1, in item order, into acc[0..w). */
typedef void cf_chunk_sum_fn(void *ctx, int i0, int i1, double *acc);

/* out[0..w) = the sums of the w terms over items [0, n), w <= CF_SUMS_MAX;
 * the chunks run on the threads when `threads` is set (sum must then be
 * safe to run on several at once), on the calling one otherwise: the same
 * bits either way. */
void cf_sum_chunks(int n, int w, int threads, cf_chunk_sum_fn *sum, void *ctx, double *out);

/* The items whose byte in `flag` is set, in order, into out (room for
 * all of them): of v[0..n) with v, flag[v[i]]; of lo..lo+n-1 without,
 * flag[i].  The chunks of cf_sum_chunks are counted, and then written,
 * on the threads when `threads` is set: the same list either way.
 * Returns how many. */
int cf_flagged_chunks(const int *v, int lo, int n, const unsigned char *flag, int threads,
                      int *out);

#endif
