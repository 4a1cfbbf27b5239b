#include "chunks.h"

#include "parallel.h"

#include <string.h>

void cf_sum_chunks(int n, int w, int threads, cf_chunk_sum_fn *sum, void *ctx, double *out)
{
    long size = ((long)n + CF_CHUNKS_MAX - 1) / CF_CHUNKS_MAX;
    size = size < CF_CHUNK_MIN ? CF_CHUNK_MIN : size;
    int count = n > 0 ? (int)((n + size - 1) / size) : 0;
    double part[CF_CHUNKS_MAX][CF_SUMS_MAX];
    memset(part, 0, sizeof part);
    CF_PARALLEL(threads && count > 1, "omp parallel for schedule(static)",
        for (int c = 0; c < count; c++) {
            long i1 = (c + 1) * size;
            sum(ctx, (int)(c * size), (int)(i1 < n ? i1 : n), part[c]);
        });
    for (int k = 0; k < w; k++) {
        out[k] = 0;
        for (int c = 0; c < count; c++)
            out[k] += part[c][k];
    }
}
