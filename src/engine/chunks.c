#include "chunks.h"

#include "parallel.h"

#include <string.h>

/* Items per chunk, and how many chunks, for n items. */
static long chunking(int n, int *count)
{
    long size = ((long)n + CF_CHUNKS_MAX - 1) / CF_CHUNKS_MAX;
    size = size < CF_CHUNK_MIN ? CF_CHUNK_MIN : size;
    *count = n > 0 ? (int)((n + size - 1) / size) : 0;
    return size;
}

/* One past the last item of chunk c. */
static int chunk_end(int c, long size, int n)
{
    long i1 = (c + 1) * size;
    return (int)(i1 < n ? i1 : n);
}

void cf_sum_chunks(int n, int w, int threads, cf_chunk_sum_fn *sum, void *ctx, double *out)
{
    int count;
    long size = chunking(n, &count);
    double part[CF_CHUNKS_MAX][CF_SUMS_MAX];
    memset(part, 0, sizeof part);
    CF_PARALLEL(threads && count > 1, "omp parallel for schedule(static)",
        for (int c = 0; c < count; c++)
            sum(ctx, (int)(c * size), chunk_end(c, size, n), part[c]););
    for (int k = 0; k < w; k++) {
        out[k] = 0;
        for (int c = 0; c < count; c++)
            out[k] += part[c][k];
    }
}

int cf_flagged_chunks(const int *v, int lo, int n, const unsigned char *flag, int threads,
                      int *out)
{
    int count, at[CF_CHUNKS_MAX + 1] = {0};
    long size = chunking(n, &count);
#define CF_ITEM_(i) (v ? v[i] : lo + (i))
    CF_PARALLEL(threads && count > 1, "omp parallel for schedule(static)",
        for (int c = 0; c < count; c++)
            for (int i = (int)(c * size); i < chunk_end(c, size, n); i++)
                at[c + 1] += flag[CF_ITEM_(i)] != 0;);
    for (int c = 0; c < count; c++)
        at[c + 1] += at[c];
    CF_PARALLEL(threads && count > 1, "omp parallel for schedule(static)",
        for (int c = 0; c < count; c++) {
            int k = at[c];
            for (int i = (int)(c * size); i < chunk_end(c, size, n); i++)
                if (flag[CF_ITEM_(i)])
                    out[k++] = CF_ITEM_(i);
        });
#undef CF_ITEM_
    return at[count];
}
