/* HDF5 prints its error stack to stderr by default; the engine reports its
 * own messages instead (the writer h5_output.c, the reader trajectory.c).
 * quiet_begin turns the printing off, quiet_end puts the caller's setting
 * back. */
#ifndef COHFRAC_H5_QUIET_H
#define COHFRAC_H5_QUIET_H

#include <hdf5.h>

typedef struct quiet_state {
    H5E_auto2_t fn;
    void *data;
} quiet_state;

static inline void quiet_begin(quiet_state *q)
{
    q->fn = NULL;
    q->data = NULL;
    if (H5Eget_auto2(H5E_DEFAULT, &q->fn, &q->data) < 0) {
        q->fn = NULL;
        q->data = NULL;
    }
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

static inline void quiet_end(const quiet_state *q)
{
    H5Eset_auto2(H5E_DEFAULT, q->fn, q->data);
}

/* The whole dataset `name` of an open file as `type` (elements of `size`
 * bytes; malloc'd, NULL when absent or unreadable); its rank and dimensions
 * into rank/dims (up to 3).  In trajectory.c. */
void *cf_h5_read_all(hid_t file, const char *name, hid_t type, size_t size, int *rank,
                     hsize_t dims[3]);

/* The whole frames of an open output, at most `rows` (the shortest
 * per-frame dataset the caller read): the root attribute `frames` where
 * the file has it (a run killed during a flush may leave one dataset a
 * row longer than another; docs/output.md), else `rows`.  In
 * trajectory.c. */
hsize_t cf_h5_whole_frames(hid_t file, hsize_t rows);

#endif
