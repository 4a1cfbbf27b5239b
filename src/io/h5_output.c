/* cohfrac — HDF5 output in an H5MD-style layout (docs/output.md), plus an XDMF 3
 * sidecar so ParaView can play the fragment centres back over time.
 *
 * The layout is documented in src/io/include/cohfrac/h5_output.h.  Choices made
 * here, and why:
 *   - Every dataset is chunked and extendable; the per-fragment series are
 *     [T][N](,k) with both T and N unlimited and an HDF5 fill value (NaN, or
 *     -1 for id and mode), so widening N fills past frames by itself.
 *   - The particle fields share one step and one time dataset through hard
 *     links (H5MD allows this), so one append per frame updates all of them.
 *   - Within a frame the values are written first and step/time last, and the
 *     file is flushed at the end: len(step) is the number of complete frames.
 *     HDF5 flushes its metadata entry by entry, so a run killed during a
 *     flush may leave one dataset a frame longer than another; the root
 *     attribute `frames`, written only once the flush has returned, is the
 *     count of whole frames even then.
 *   - The writer takes no HDF5 file lock, so another process (h5py, a
 *     monitoring script) can open the file read-only while the run goes on.
 *   - HDF5's automatic error printing is switched off for the duration of
 *     each call (and restored after); failures become CF_ERR_OUTPUT with a
 *     message naming the file, the step that failed and HDF5's own reason,
 *     or CF_ERR_NOMEM when that reason is a failed allocation.
 *   - The layout is written under a temporary name and renamed into place
 *     once flushed, so the output's name never holds a half-made file.
 *   - After a failed write the close first cuts every table back to what
 *     the last successful flush left, so a run that ends on an error leaves
 *     the same whole frames a SIGKILL at that flush would have.
 */
#define _POSIX_C_SOURCE 200809L

#include "cohfrac/version.h"
#include "cohfrac/h5_output.h"
#include "h5_quiet.h"

#include <hdf5.h>

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>


/* Chunk shapes.  Frames are flushed one at a time, and a flush rewrites every
 * chunk the frame touched, so the time extent of a chunk is kept small. */
#define FRAME_CHUNK_T 8
#define FRAME_CHUNK_N 32
#define ROW_CHUNK 256

/* One dataset family: a per-fragment field, a fragment record column or a
 * hand-off column. */
typedef struct column_def {
    const char *name;
    int ncomp;        /* 1: one value per row; k > 1: [..][k] */
    int integer;      /* int32 (fill -1) instead of float64 (fill NaN) */
    const char *unit; /* H5MD unit string, NULL when dimensionless */
} column_def;

enum { FLD_ID, FLD_POSITION, FLD_ORIENTATION, FLD_VELOCITY, FLD_ANGVEL, FLD_MODE, FLD_COUNT };
static const column_def FIELDS[FLD_COUNT] = {
    {"id", 1, 1, NULL},
    {"position", 3, 0, "m"},
    {"orientation", 4, 0, NULL},
    {"velocity", 3, 0, "m s-1"},
    {"angular_velocity", 3, 0, "rad s-1"},
    {"mode", 1, 1, NULL},
};

enum { FR_PARENT, FR_BIRTH, FR_MASS, FR_NTETS, FR_INERTIA, FR_NHULLS, FR_HULLERR, FR_DECOMP,
       FR_COMREST, FR_SURF_FIRST, FR_SURF_COUNT, FR_DEBRIS, FR_COUNT };
static const column_def FRAGMENT_COLUMNS[FR_COUNT] = {
    {"parent", 1, 1, NULL},
    {"birth_time", 1, 0, "s"},
    {"mass", 1, 0, "kg"},
    {"n_tets", 1, 1, NULL},
    {"inertia_principal", 3, 0, "kg m2"},
    {"n_hulls", 1, 1, NULL},
    {"hull_volume_error", 1, 0, NULL},
    {"decomposition_time", 1, 0, "s"},
    {"com_rest", 3, 0, "m"},
    {"surface_first", 1, 1, NULL},
    {"surface_count", 1, 1, NULL},
    {"debris", 1, 1, NULL},
};

/* Fragment surfaces: boundary triangles on /mesh/rest/nodes (outward
 * for the rest shape), 1 where the face is a crack face (inside the rest
 * mesh), 0 where it is the body's own surface. */
enum { SF_TRIANGLES, SF_CRACK, SF_COUNT };
static const column_def SURFACE_COLUMNS[SF_COUNT] = {
    {"triangles", 3, 1, NULL},
    {"crack", 1, 1, NULL},
};

/* "time" is last: it is appended last, so its length counts complete rows. */
enum { HO_FRAGMENT, HO_DIRECTION, HO_MOMERR, HO_DP, HO_DL, HO_LOSS, HO_TIME, HO_COUNT };
static const column_def HANDOFF_COLUMNS[HO_COUNT] = {
    {"fragment", 1, 1, NULL},
    {"direction", 1, 1, NULL},
    {"momentum_error", 1, 0, NULL},
    {"momentum_change", 3, 0, "kg m s-1"},
    {"angular_momentum_change", 3, 0, "kg m2 s-1"},
    {"handoff_loss", 1, 0, "J"},
    {"time", 1, 0, "s"},
};

/* "time" is last, as for the hand-offs. */
enum { CR_ELEMENT, CR_TETS, CR_CENTROID, CR_NORMAL, CR_AREA, CR_OPENING, CR_SLIDING, CR_FAILED,
       CR_TIME, CR_COUNT };
static const column_def CRACK_COLUMNS[CR_COUNT] = {
    {"element", 1, 1, NULL},
    {"tets", 2, 1, NULL},
    {"centroid", 3, 0, "m"},
    {"normal", 3, 0, NULL},
    {"area", 1, 0, "m2"},
    {"opening", 1, 0, "m"},
    {"sliding", 1, 0, "m"},
    {"failed", 1, 1, NULL},
    {"time", 1, 0, "s"},
};

/* The tets of fracture-mode fragments at each frame, "time" last again. */
enum { FT_TET, FT_CORNERS, FT_STRESS, FT_DAMAGE, FT_TIME, FT_COUNT };
static const column_def FRACTURE_COLUMNS[FT_COUNT] = {
    {"tet", 1, 1, NULL},
    {"corners", 12, 0, "m"},
    {"stress", 6, 0, "Pa"},
    {"damage", 1, 0, NULL},
    {"time", 1, 0, "s"},
};

/* An observable series kept open so that appending a sample costs three
 * small writes and no lookup in the file. */
typedef struct observable {
    char *name;
    hid_t step, time, value;
    hsize_t n;
    hsize_t flushed; /* samples on disk at the last flush */
} observable;

/* What the XDMF sidecar needs to know about one written frame. */
typedef struct frame_record {
    double time;
    hsize_t ncols;  /* width N of the value datasets when it was written */
    hsize_t first;  /* offset of its alive columns in the connectivity list */
    hsize_t count;  /* number of alive fragments */
    hsize_t ft_first, ft_count; /* its rows of /fracture_mode */
} frame_record;

struct cf_h5 {
    char *path;
    hid_t file;
    hid_t step, time; /* shared by every /particles/fragments field */
    hid_t value[FLD_COUNT];
    hid_t fragment[FR_COUNT];
    hid_t handoff[HO_COUNT];
    hid_t crack[CR_COUNT];   /* /cracks, created by the first cf_h5_add_cracks */
    hsize_t ncracks;
    hid_t ftet[FT_COUNT];    /* /fracture_mode, created by the first cf_h5_add_fracture_tets */
    hsize_t nftets;
    hid_t surface[SF_COUNT]; /* /surfaces */
    hsize_t nsurface;
    hid_t map_step, map_time, map_value; /* /mesh/tet_fragment, created on first use */
    hsize_t nmaps;
    /* Rows on disk at the last flush (frames, fragments and hand-offs are
     * counted only once flushed); `failed`: a write failed since then, and
     * the close puts every table back to these (see rollback). */
    hsize_t ncracks_flushed, nsurface_flushed, nmaps_flushed, nftets_flushed;
    int failed;
    hid_t obs_group;

    hsize_t nframes, ncols, nfragments, nhandoffs;

    frame_record *frames;
    size_t frames_cap;
    int *alive; /* alive columns of every frame, concatenated (XDMF topology) */
    size_t nalive, alive_cap;

    observable *obs;
    size_t nobs, obs_cap, obs_last;

    /* scratch reused by every frame */
    double *dbuf;
    size_t dbuf_cap;
    int *ibuf;
    size_t ibuf_cap;
};

/* ---- errors ------------------------------------------------------------ */

#define REASON_LEN 400

typedef struct h5_reason {
    char text[REASON_LEN];
    int memory; /* an allocation failed somewhere down the stack */
} h5_reason;

/* Walking upward, entry 0 is the innermost and most specific error (for a
 * failed create it carries errno's text).  HDF5 files a failed memory
 * allocation under minor H5E_NOSPACE ("no space available for
 * allocation"), or under H5E_CANTALLOC with a description that says memory
 * ("memory allocation failed for on disk image buffer"; H5E_CANTALLOC
 * alone also covers file space); a full disk comes as a write error with
 * errno's text instead. */
static herr_t walk_error(unsigned n, const H5E_error2_t *e, void *data)
{
    h5_reason *r = data;
    if (!e)
        return 0;
    if (n == 0 && e->desc)
        snprintf(r->text, REASON_LEN, "%s", e->desc);
    if (e->min_num == H5E_NOSPACE ||
        (e->min_num == H5E_CANTALLOC && e->desc && strstr(e->desc, "memory")))
        r->memory = 1;
    return 0;
}

/* Turn the current HDF5 error stack into a message: CF_ERR_NOMEM when an
 * allocation failed (HDF5 says so, or, when it could not even record its
 * error, errno says ENOMEM), CF_ERR_OUTPUT otherwise. */
static cf_status h5_fail(cf_error *err, const char *path, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static cf_status h5_fail(cf_error *err, const char *path, const char *fmt, ...)
{
    int saved_errno = errno;
    char what[256];
    h5_reason r = {"", 0};
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, walk_error, &r);
    H5Eclear2(H5E_DEFAULT);
    if (r.memory || (!r.text[0] && saved_errno == ENOMEM))
        return cf_error_set(err, CF_ERR_NOMEM, "output file '%s': out of memory %s%s%s%s", path,
                            what, r.text[0] ? " (HDF5: " : "", r.text, r.text[0] ? ")" : "");
    if (r.text[0])
        return cf_error_set(err, CF_ERR_OUTPUT, "output file '%s': %s failed (HDF5: %s)", path,
                            what, r.text);
    return cf_error_set(err, CF_ERR_OUTPUT, "output file '%s': %s failed", path, what);
}

/* H5Fflush, or its error.  HDF5 writes its metadata entry by entry: one
 * that runs out of memory part way may have written some and not the rest
 * (the superblock's end of file among them), and the file may then not
 * open; the message says so. */
static cf_status flush_file(cf_h5 *h, cf_error *err, const char *what)
{
    if (H5Fflush(h->file, H5F_SCOPE_LOCAL) >= 0) {
        for (size_t i = 0; i < h->nobs; ++i)
            h->obs[i].flushed = h->obs[i].n;
        h->ncracks_flushed = h->ncracks;
        h->nftets_flushed = h->nftets;
        h->nsurface_flushed = h->nsurface;
        h->nmaps_flushed = h->nmaps;
        h->failed = 0;
        return CF_OK;
    }
    cf_status st = h5_fail(err, h->path, "%s", what);
    if (st == CF_ERR_NOMEM && err) {
        size_t n = strlen(err->msg);
        snprintf(err->msg + n, sizeof err->msg - n,
                 "; HDF5 may have written part of its metadata, and the file may not open");
    }
    return st;
}

static cf_status no_memory(cf_error *err, const char *path)
{
    return cf_error_set(err, CF_ERR_NOMEM, "output file '%s': out of memory", path);
}

/* ---- small HDF5 helpers ------------------------------------------------ */

static hid_t file_type(const column_def *c)
{
    return c->integer ? H5T_STD_I32LE : H5T_IEEE_F64LE;
}

static hid_t mem_type(const column_def *c)
{
    return c->integer ? H5T_NATIVE_INT : H5T_NATIVE_DOUBLE;
}

/* Object modification times would make two identical runs differ byte for
 * byte, so they are not recorded. */
static hid_t untimed_plist(hid_t cls)
{
    hid_t p = H5Pcreate(cls);
    if (p >= 0 && H5Pset_obj_track_times(p, 0) < 0) {
        H5Pclose(p);
        return H5I_INVALID_HID;
    }
    return p;
}

static hid_t make_group(hid_t loc, const char *name)
{
    hid_t gcpl = untimed_plist(H5P_GROUP_CREATE);
    hid_t g = H5I_INVALID_HID;
    if (gcpl >= 0) {
        g = H5Gcreate2(loc, name, H5P_DEFAULT, gcpl, H5P_DEFAULT);
        H5Pclose(gcpl);
    }
    return g;
}

/* Variable-length UTF-8 strings read back as str in h5py. */
static hid_t string_type(void)
{
    hid_t t = H5Tcopy(H5T_C_S1);
    if (t >= 0 && (H5Tset_size(t, H5T_VARIABLE) < 0 || H5Tset_cset(t, H5T_CSET_UTF8) < 0)) {
        H5Tclose(t);
        return H5I_INVALID_HID;
    }
    return t;
}

/* Attribute of `n` strings (scalar when n == 0). */
static int write_strings_attr(hid_t loc, const char *name, const char *const *values, hsize_t n)
{
    hid_t t = string_type();
    hid_t s = n ? H5Screate_simple(1, &n, NULL) : H5Screate(H5S_SCALAR);
    hid_t a = H5I_INVALID_HID;
    int ok = t >= 0 && s >= 0;
    if (ok)
        ok = (a = H5Acreate2(loc, name, t, s, H5P_DEFAULT, H5P_DEFAULT)) >= 0 &&
             H5Awrite(a, t, values) >= 0;
    if (a >= 0)
        H5Aclose(a);
    if (s >= 0)
        H5Sclose(s);
    if (t >= 0)
        H5Tclose(t);
    return ok ? 0 : -1;
}

static int write_string_attr(hid_t loc, const char *name, const char *value)
{
    const char *v[1] = {value ? value : ""};
    return write_strings_attr(loc, name, v, 0);
}

static int write_ints_attr(hid_t loc, const char *name, const int *values, hsize_t n)
{
    hid_t s = H5Screate_simple(1, &n, NULL);
    hid_t a = H5I_INVALID_HID;
    int ok = s >= 0 &&
             (a = H5Acreate2(loc, name, H5T_STD_I32LE, s, H5P_DEFAULT, H5P_DEFAULT)) >= 0 &&
             H5Awrite(a, H5T_NATIVE_INT, values) >= 0;
    if (a >= 0)
        H5Aclose(a);
    if (s >= 0)
        H5Sclose(s);
    return ok ? 0 : -1;
}

/* The root attribute `frames` (int64, scalar): the frames the last finished
 * flush carried to disk.  HDF5 writes its metadata entry by entry, so a
 * process killed during a flush can leave one dataset a frame longer than
 * another; this count is written only after the flush has returned, so on
 * disk it never counts a frame whose rows are not all there. */
static int write_frames_attr(hid_t file, hsize_t frames, int create)
{
    int64_t v = (int64_t)frames;
    hid_t s = H5I_INVALID_HID, a;
    if (create) {
        s = H5Screate(H5S_SCALAR);
        a = s >= 0 ? H5Acreate_by_name(file, "/", "frames", H5T_STD_I64LE, s, H5P_DEFAULT,
                                       H5P_DEFAULT, H5P_DEFAULT)
                   : H5I_INVALID_HID;
    } else {
        a = H5Aopen_by_name(file, "/", "frames", H5P_DEFAULT, H5P_DEFAULT);
    }
    int ok = a >= 0 && H5Awrite(a, H5T_NATIVE_INT64, &v) >= 0;
    if (a >= 0)
        H5Aclose(a);
    if (s >= 0)
        H5Sclose(s);
    return ok ? 0 : -1;
}

static int write_string_dataset(hid_t loc, const char *name, const char *value)
{
    const char *v = value ? value : "";
    hid_t t = string_type();
    hid_t s = H5Screate(H5S_SCALAR);
    hid_t dcpl = untimed_plist(H5P_DATASET_CREATE);
    hid_t d = H5I_INVALID_HID;
    int ok = t >= 0 && s >= 0 && dcpl >= 0 &&
             (d = H5Dcreate2(loc, name, t, s, H5P_DEFAULT, dcpl, H5P_DEFAULT)) >= 0 &&
             H5Dwrite(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, &v) >= 0;
    if (d >= 0)
        H5Dclose(d);
    if (dcpl >= 0)
        H5Pclose(dcpl);
    if (s >= 0)
        H5Sclose(s);
    if (t >= 0)
        H5Tclose(t);
    return ok ? 0 : -1;
}

/* Chunked dataset that starts empty; `fill` (of `fill_type`) is what reads
 * back from any element never written, including after an extension. */
static hid_t create_extendable(hid_t loc, const char *name, hid_t ftype, int rank,
                               const hsize_t *dims, const hsize_t *maxdims, const hsize_t *chunk,
                               hid_t fill_type, const void *fill)
{
    hid_t space = H5Screate_simple(rank, dims, maxdims);
    hid_t dcpl = untimed_plist(H5P_DATASET_CREATE);
    hid_t d = H5I_INVALID_HID;
    if (space >= 0 && dcpl >= 0 && H5Pset_chunk(dcpl, rank, chunk) >= 0 &&
        (!fill || H5Pset_fill_value(dcpl, fill_type, fill) >= 0))
        d = H5Dcreate2(loc, name, ftype, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (dcpl >= 0)
        H5Pclose(dcpl);
    if (space >= 0)
        H5Sclose(space);
    return d;
}

/* A row-appendable column: [n] or [n][k]. */
static hid_t create_rows(hid_t loc, const char *name, hid_t ftype, int ncomp)
{
    hsize_t dims[2] = {0, (hsize_t)ncomp};
    hsize_t maxdims[2] = {H5S_UNLIMITED, (hsize_t)ncomp};
    hsize_t chunk[2] = {ROW_CHUNK, (hsize_t)ncomp};
    return create_extendable(loc, name, ftype, ncomp > 1 ? 2 : 1, dims, maxdims, chunk,
                             H5T_NATIVE_INT, NULL);
}

static int write_unit(hid_t obj, const char *unit)
{
    return unit ? write_string_attr(obj, "unit", unit) : 0;
}

/* Append `nrows` rows at `row0` to a rank-1 or rank-2 dataset. */
static int append_rows(hid_t d, hsize_t row0, hsize_t nrows, hid_t mtype, const void *buf)
{
    hsize_t dims[2] = {0, 1};
    hid_t fs = H5Dget_space(d);
    int rank = fs >= 0 ? H5Sget_simple_extent_ndims(fs) : -1;
    int ok = rank >= 1 && rank <= 2 && H5Sget_simple_extent_dims(fs, dims, NULL) >= 0;
    if (fs >= 0)
        H5Sclose(fs);
    if (!ok)
        return -1;
    dims[0] = row0 + nrows;
    if (H5Dset_extent(d, dims) < 0)
        return -1;
    hsize_t start[2] = {row0, 0};
    hsize_t count[2] = {nrows, rank > 1 ? dims[1] : 1};
    fs = H5Dget_space(d);
    hid_t ms = H5Screate_simple(rank, count, NULL);
    ok = fs >= 0 && ms >= 0 &&
         H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, NULL, count, NULL) >= 0 &&
         H5Dwrite(d, mtype, ms, fs, H5P_DEFAULT, buf) >= 0;
    if (ms >= 0)
        H5Sclose(ms);
    if (fs >= 0)
        H5Sclose(fs);
    return ok ? 0 : -1;
}

/* Write columns [col0, col0+width) of frame `row` of a [T][N](,k) dataset. */
static int write_frame_block(hid_t d, hsize_t row, hsize_t col0, hsize_t width, int ncomp,
                             hid_t mtype, const void *buf)
{
    hsize_t start[3] = {row, col0, 0};
    hsize_t count[3] = {1, width, (hsize_t)ncomp};
    hsize_t nmem = width * (hsize_t)ncomp;
    hid_t fs = H5Dget_space(d);
    hid_t ms = H5Screate_simple(1, &nmem, NULL);
    int ok = fs >= 0 && ms >= 0 &&
             H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, NULL, count, NULL) >= 0 &&
             H5Dwrite(d, mtype, ms, fs, H5P_DEFAULT, buf) >= 0;
    if (ms >= 0)
        H5Sclose(ms);
    if (fs >= 0)
        H5Sclose(fs);
    return ok ? 0 : -1;
}

static void close_dataset(hid_t *d, int *failed)
{
    if (*d >= 0 && H5Dclose(*d) < 0)
        *failed = 1;
    *d = H5I_INVALID_HID;
}

/* ---- memory ------------------------------------------------------------ */

/* Grow `*p` (elements of `size` bytes) to hold at least `need`. */
static int grow(void **p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap)
        return 0;
    size_t n = *cap ? *cap : 16;
    while (n < need)
        n *= 2;
    void *q = realloc(*p, n * size);
    if (!q)
        return -1;
    *p = q;
    *cap = n;
    return 0;
}

static int grow_scratch(cf_h5 *h, size_t nint, size_t ndbl)
{
    void *ip = h->ibuf, *dp = h->dbuf;
    int rc = grow(&ip, &h->ibuf_cap, nint, sizeof(int));
    h->ibuf = ip;
    if (rc == 0)
        rc = grow(&dp, &h->dbuf_cap, ndbl, sizeof(double));
    h->dbuf = dp;
    return rc;
}

/* ---- open -------------------------------------------------------------- */

/* mkdir -p of everything before the last '/'. */
static cf_status make_parent_dirs(const char *path, cf_error *err)
{
    char *buf = strdup(path);
    if (!buf)
        return no_memory(err, path);
    cf_status st = CF_OK;
    for (char *p = buf + 1; *p && st == CF_OK; ++p) {
        if (*p != '/' || p[-1] == '/')
            continue;
        *p = '\0';
        if (mkdir(buf, 0777) != 0) {
            int e = errno;
            struct stat sb;
            /* EEXIST is the usual case; any error is fine if a directory is there. */
            if (stat(buf, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
                if (e == EEXIST)
                    st = cf_error_set(err, CF_ERR_OUTPUT,
                                      "output file '%s': cannot create directory '%s': a file "
                                      "that is not a directory is in the way",
                                      path, buf);
                else
                    st = cf_error_set(err, CF_ERR_OUTPUT,
                                      "output file '%s': cannot create directory '%s': %s", path,
                                      buf, strerror(e));
            }
        }
        *p = '/';
    }
    free(buf);
    return st;
}

static void init_handles(cf_h5 *h)
{
    h->file = h->step = h->time = h->obs_group = H5I_INVALID_HID;
    for (int i = 0; i < FLD_COUNT; ++i)
        h->value[i] = H5I_INVALID_HID;
    for (int i = 0; i < FR_COUNT; ++i)
        h->fragment[i] = H5I_INVALID_HID;
    for (int i = 0; i < HO_COUNT; ++i)
        h->handoff[i] = H5I_INVALID_HID;
    for (int i = 0; i < CR_COUNT; ++i)
        h->crack[i] = H5I_INVALID_HID;
    for (int i = 0; i < FT_COUNT; ++i)
        h->ftet[i] = H5I_INVALID_HID;
    for (int i = 0; i < SF_COUNT; ++i)
        h->surface[i] = H5I_INVALID_HID;
    h->map_step = h->map_time = h->map_value = H5I_INVALID_HID;
}

/* Close every HDF5 object and the file; returns -1 if any close failed. */
static int close_handles(cf_h5 *h)
{
    int failed = 0;
    for (size_t i = 0; i < h->nobs; ++i) {
        close_dataset(&h->obs[i].step, &failed);
        close_dataset(&h->obs[i].time, &failed);
        close_dataset(&h->obs[i].value, &failed);
    }
    for (int i = 0; i < FLD_COUNT; ++i)
        close_dataset(&h->value[i], &failed);
    for (int i = 0; i < FR_COUNT; ++i)
        close_dataset(&h->fragment[i], &failed);
    for (int i = 0; i < HO_COUNT; ++i)
        close_dataset(&h->handoff[i], &failed);
    for (int i = 0; i < CR_COUNT; ++i)
        close_dataset(&h->crack[i], &failed);
    for (int i = 0; i < FT_COUNT; ++i)
        close_dataset(&h->ftet[i], &failed);
    for (int i = 0; i < SF_COUNT; ++i)
        close_dataset(&h->surface[i], &failed);
    close_dataset(&h->map_step, &failed);
    close_dataset(&h->map_time, &failed);
    close_dataset(&h->map_value, &failed);
    close_dataset(&h->step, &failed);
    close_dataset(&h->time, &failed);
    if (h->obs_group >= 0 && H5Gclose(h->obs_group) < 0)
        failed = 1;
    h->obs_group = H5I_INVALID_HID;
    if (h->file >= 0 && H5Fclose(h->file) < 0)
        failed = 1;
    h->file = H5I_INVALID_HID;
    return failed ? -1 : 0;
}

static void free_handle(cf_h5 *h)
{
    for (size_t i = 0; i < h->nobs; ++i)
        free(h->obs[i].name);
    free(h->obs);
    free(h->frames);
    free(h->alive);
    free(h->dbuf);
    free(h->ibuf);
    free(h->path);
    free(h);
}

/* /h5md: the H5MD version, author and creator, and the units module that
 * the "unit" attributes belong to. */
static int write_h5md_group(hid_t file)
{
    static const int version[2] = {1, 1};
    static const int units_version[2] = {1, 0};
    const char *user = getenv("USER");
    hid_t g = make_group(file, "h5md");
    int ok = g >= 0 && write_ints_attr(g, "version", version, 2) == 0;
    hid_t sub = H5I_INVALID_HID;
    if (ok) {
        sub = make_group(g, "author");
        ok = sub >= 0 && write_string_attr(sub, "name", user && *user ? user : "unknown") == 0;
        if (sub >= 0)
            H5Gclose(sub);
    }
    if (ok) {
        sub = make_group(g, "creator");
        ok = sub >= 0 && write_string_attr(sub, "name", "cohfrac") == 0 &&
             write_string_attr(sub, "version", COHFRAC_VERSION_STRING) == 0;
        if (sub >= 0)
            H5Gclose(sub);
    }
    if (ok) {
        hid_t modules = make_group(g, "modules");
        sub = modules >= 0 ? make_group(modules, "units") : H5I_INVALID_HID;
        ok = sub >= 0 && write_ints_attr(sub, "version", units_version, 2) == 0 &&
             write_string_attr(sub, "system", "SI") == 0;
        if (sub >= 0)
            H5Gclose(sub);
        if (modules >= 0)
            H5Gclose(modules);
    }
    if (g >= 0)
        H5Gclose(g);
    return ok ? 0 : -1;
}

/* H5MD requires a box in every particles group; fragments fly free. */
static int write_box(hid_t frags)
{
    static const int dimension = 3;
    static const char *const boundary[3] = {"none", "none", "none"};
    hid_t box = make_group(frags, "box");
    int ok = box >= 0 && write_ints_attr(box, "dimension", &dimension, 1) == 0 &&
             write_strings_attr(box, "boundary", boundary, 3) == 0;
    if (box >= 0)
        H5Gclose(box);
    return ok ? 0 : -1;
}

/* One field group: step and time (created for the first field, hard links
 * to those for the others) and the [T][N](,k) value dataset. */
static int write_field_group(cf_h5 *h, hid_t frags, int f)
{
    static const double nan_fill = NAN;
    static const int minus_one = -1;
    const column_def *c = &FIELDS[f];
    hid_t g = make_group(frags, c->name);
    int ok = g >= 0;
    if (ok && f == 0) {
        hsize_t dims = 0, maxdims = H5S_UNLIMITED, chunk = ROW_CHUNK;
        h->step = create_extendable(g, "step", H5T_STD_I64LE, 1, &dims, &maxdims, &chunk,
                                    H5T_NATIVE_INT, NULL);
        h->time = create_extendable(g, "time", H5T_IEEE_F64LE, 1, &dims, &maxdims, &chunk,
                                    H5T_NATIVE_INT, NULL);
        ok = h->step >= 0 && h->time >= 0 && write_unit(h->time, "s") == 0;
    } else if (ok) {
        ok = H5Lcreate_hard(h->step, ".", g, "step", H5P_DEFAULT, H5P_DEFAULT) >= 0 &&
             H5Lcreate_hard(h->time, ".", g, "time", H5P_DEFAULT, H5P_DEFAULT) >= 0;
    }
    if (ok) {
        hsize_t k = (hsize_t)c->ncomp;
        hsize_t dims[3] = {0, 0, k};
        hsize_t maxdims[3] = {H5S_UNLIMITED, H5S_UNLIMITED, k};
        hsize_t chunk[3] = {FRAME_CHUNK_T, FRAME_CHUNK_N, k};
        const void *fill = c->integer ? (const void *)&minus_one : (const void *)&nan_fill;
        h->value[f] = create_extendable(g, "value", file_type(c), c->ncomp > 1 ? 3 : 2, dims,
                                        maxdims, chunk, mem_type(c), fill);
        ok = h->value[f] >= 0 && write_unit(h->value[f], c->unit) == 0;
    }
    if (g >= 0)
        H5Gclose(g);
    return ok ? 0 : -1;
}

static cf_status write_particles_group(cf_h5 *h, cf_error *err)
{
    hid_t particles = make_group(h->file, "particles");
    hid_t frags = particles >= 0 ? make_group(particles, "fragments") : H5I_INVALID_HID;
    cf_status st = CF_OK;
    if (frags < 0 || write_box(frags) < 0)
        st = h5_fail(err, h->path, "creating /particles/fragments");
    for (int f = 0; f < FLD_COUNT && st == CF_OK; ++f)
        if (write_field_group(h, frags, f) < 0)
            st = h5_fail(err, h->path, "creating /particles/fragments/%s", FIELDS[f].name);
    if (frags >= 0)
        H5Gclose(frags);
    if (particles >= 0)
        H5Gclose(particles);
    return st;
}

/* A group of row-appendable columns (/fragments, /handoffs, ...), its
 * datasets' ids in out; nothing to do once created (out[0] valid), so the
 * groups written only by some runs (/cracks, /fracture_mode) are created on
 * their first rows. */
static cf_status write_row_group(cf_h5 *h, const char *name, const column_def *cols, int ncols,
                                 hid_t *out, cf_error *err)
{
    if (out[0] >= 0)
        return CF_OK;
    hid_t g = make_group(h->file, name);
    int ok = g >= 0;
    for (int i = 0; i < ncols && ok; ++i) {
        out[i] = create_rows(g, cols[i].name, file_type(&cols[i]), cols[i].ncomp);
        ok = out[i] >= 0 && write_unit(out[i], cols[i].unit) == 0;
    }
    if (g >= 0)
        H5Gclose(g);
    return ok ? CF_OK : h5_fail(err, h->path, "creating /%s", name);
}

/* The file's layout, created as `file_name` (the output's temporary name). */
static cf_status build_layout(cf_h5 *h, const char *file_name, const char *scene_name,
                              const char *scene_text, cf_error *err)
{
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    if (fapl < 0)
        return h5_fail(err, h->path, "creating the file access properties");
#if H5_VERSION_GE(1, 12, 1) || (H5_VERS_MAJOR == 1 && H5_VERS_MINOR == 10 && H5_VERS_RELEASE >= 7)
    /* Without a lock another process can open the file read-only while the
     * run goes on (to watch progress); it sees the state of the last flush. */
    H5Pset_file_locking(fapl, 0, 1);
#endif
    h->file = H5Fcreate(file_name, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    H5Pclose(fapl);
    if (h->file < 0)
        return h5_fail(err, h->path, "creating the file");

    hid_t root = H5Gopen2(h->file, "/", H5P_DEFAULT);
    int ok = root >= 0 && write_string_attr(root, "creator", "cohfrac") == 0 &&
             write_string_attr(root, "version", COHFRAC_VERSION_STRING) == 0 &&
             write_string_attr(root, "units", "SI") == 0 &&
             write_string_attr(root, "up_axis", "+z") == 0 &&
             write_string_attr(root, "quaternion_order", "wxyz") == 0 &&
             write_string_attr(root, "scene_name", scene_name) == 0 &&
             write_frames_attr(h->file, 0, 1) == 0;
    if (root >= 0)
        H5Gclose(root);
    if (!ok)
        return h5_fail(err, h->path, "writing the root attributes");

    if (write_h5md_group(h->file) < 0)
        return h5_fail(err, h->path, "writing /h5md");

    hid_t params = make_group(h->file, "parameters");
    ok = params >= 0 && write_string_dataset(params, "scene", scene_text) == 0;
    if (params >= 0)
        H5Gclose(params);
    if (!ok)
        return h5_fail(err, h->path, "writing /parameters/scene");

    cf_status st = write_particles_group(h, err);
    if (st == CF_OK)
        st = write_row_group(h, "fragments", FRAGMENT_COLUMNS, FR_COUNT, h->fragment, err);
    if (st == CF_OK)
        st = write_row_group(h, "handoffs", HANDOFF_COLUMNS, HO_COUNT, h->handoff, err);
    if (st == CF_OK)
        st = write_row_group(h, "surfaces", SURFACE_COLUMNS, SF_COUNT, h->surface, err);
    if (st != CF_OK)
        return st;
    h->obs_group = make_group(h->file, "observables");
    if (h->obs_group < 0)
        return h5_fail(err, h->path, "creating /observables");
    return flush_file(h, err, "flushing the new file");
}

static int h5_init_once(void);

static cf_status open_impl(const char *path, const char *scene_name, const char *scene_text,
                           cf_h5 **out, cf_error *err)
{
    if (!out)
        return cf_error_set(err, CF_ERR_OUTPUT, "cf_h5_open: no place to return the handle");
    *out = NULL;
    if (!path || !*path)
        return cf_error_set(err, CF_ERR_OUTPUT, "cf_h5_open: the output path is empty");
    cf_status st = make_parent_dirs(path, err);
    if (st != CF_OK)
        return st;
    /* Say why a file cannot be created, before HDF5 says only that it failed. */
    struct stat sb;
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
        return cf_error_set(err, CF_ERR_OUTPUT,
                            "output file '%s' is a directory: give a file name, e.g. %s/out.h5",
                            path, path);
    if (stat(path, &sb) == 0 && access(path, W_OK) != 0)
        return cf_error_set(err, CF_ERR_OUTPUT, "output file '%s' cannot be written: %s", path,
                            strerror(errno));
    /* The layout is written under a temporary name beside the output and
     * moved into place once flushed: a process ended while HDF5 writes it
     * (SIGKILL; HDF5 itself calling exit() when out of memory) leaves no
     * half-written file under the output's name, and an earlier output
     * stays until the new one is whole.  A layout that fails (out of
     * memory, a full disk) leaves nothing. */
    cf_h5 *h = calloc(1, sizeof *h);
    if (!h)
        return no_memory(err, path);
    init_handles(h);
    h->path = strdup(path);
    size_t tmp_len = strlen(path) + 32;
    char *tmp = malloc(tmp_len);
    if (!h->path || !tmp) {
        free(tmp);
        free_handle(h);
        return no_memory(err, path);
    }
    snprintf(tmp, tmp_len, "%s.%ld.tmp", path, (long)getpid());
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) {
        st = cf_error_set(err, CF_ERR_OUTPUT, "output file '%s' cannot be created: %s", path,
                          strerror(errno));
        free(tmp);
        free_handle(h);
        return st;
    }
    close(fd);
    st = build_layout(h, tmp, scene_name, scene_text, err);
    if (st == CF_OK && rename(tmp, path) != 0)
        st = cf_error_set(err, CF_ERR_OUTPUT, "output file '%s': cannot move '%s' to it: %s",
                          path, tmp, strerror(errno));
    if (st != CF_OK) {
        close_handles(h);
        H5Eclear2(H5E_DEFAULT);
        unlink(tmp);
        free(tmp);
        free_handle(h);
        return st;
    }
    free(tmp);
    *out = h;
    return CF_OK;
}

cf_status cf_h5_open(const char *path, const char *scene_name, const char *scene_text,
                     cf_h5 **out, cf_error *err)
{
    quiet_state q;
    /* before any HDF5 call, quiet_begin's included */
    if (h5_init_once() < 0) {
        quiet_begin(&q);
        cf_status st = h5_fail(err, path, "starting HDF5");
        quiet_end(&q);
        return st;
    }
    quiet_begin(&q);
    cf_status st = open_impl(path, scene_name, scene_text, out, err);
    quiet_end(&q);
    return st;
}

/* ---- frames ------------------------------------------------------------ */

static const double *field_values(const cf_frag_frame *f, int field)
{
    switch (field) {
    case FLD_POSITION:
        return f->com;
    case FLD_ORIENTATION:
        return f->quat;
    case FLD_VELOCITY:
        return f->v;
    case FLD_ANGVEL:
        return f->w;
    default:
        return NULL;
    }
}

static cf_status write_frame_impl(cf_h5 *h, long step, double time, const cf_frag_frame *frags,
                                  int n, cf_error *err)
{
    if (!h)
        return cf_error_set(err, CF_ERR_OUTPUT, "cf_h5_write_frame: no output file is open");
    if (n < 0 || (n > 0 && !frags))
        return cf_error_set(err, CF_ERR_OUTPUT,
                            "output file '%s': frame at step %ld has an invalid fragment list "
                            "(n = %d)",
                            h->path, step, n);
    int lo = INT_MAX, hi = -1;
    for (int i = 0; i < n; ++i) {
        int id = frags[i].id;
        if (id < 0)
            return cf_error_set(err, CF_ERR_OUTPUT,
                                "output file '%s': frame at step %ld: fragment id %d is negative",
                                h->path, step, id);
        if (id < lo)
            lo = id;
        if (id > hi)
            hi = id;
    }
    /* Only the span [lo, hi] of alive ids is written (dead columns inside it
     * get the fill value); columns outside it are not touched at all. */
    size_t width = n > 0 ? (size_t)(hi - lo) + 1 : 0;
    void *fp = h->frames, *ap = h->alive;
    int grown = grow_scratch(h, 3 * width, 4 * width) == 0 &&
                grow(&fp, &h->frames_cap, (size_t)h->nframes + 1, sizeof(frame_record)) == 0;
    h->frames = fp;
    grown = grown && grow(&ap, &h->alive_cap, h->nalive + (size_t)n, sizeof(int)) == 0;
    h->alive = ap;
    if (!grown)
        return no_memory(err, h->path);

    int *col_id = h->ibuf, *col_mode = h->ibuf + width, *col_src = h->ibuf + 2 * width;
    for (size_t c = 0; c < width; ++c)
        col_id[c] = col_mode[c] = col_src[c] = -1;
    for (int i = 0; i < n; ++i) {
        size_t c = (size_t)(frags[i].id - lo);
        if (col_src[c] >= 0)
            return cf_error_set(err, CF_ERR_OUTPUT,
                                "output file '%s': frame at step %ld lists fragment %d twice",
                                h->path, step, frags[i].id);
        col_src[c] = i;
        col_id[c] = frags[i].id;
        col_mode[c] = frags[i].mode;
    }

    hsize_t T = h->nframes;
    hsize_t ncols = h->ncols;
    if (h->nfragments > ncols)
        ncols = h->nfragments;
    if (n > 0 && (hsize_t)hi + 1 > ncols)
        ncols = (hsize_t)hi + 1;

    for (int f = 0; f < FLD_COUNT; ++f) {
        const column_def *c = &FIELDS[f];
        hsize_t dims[3] = {T + 1, ncols, (hsize_t)c->ncomp};
        if (H5Dset_extent(h->value[f], dims) < 0)
            return h5_fail(err, h->path, "extending /particles/fragments/%s/value to %llu frames",
                           c->name, (unsigned long long)(T + 1));
        if (width == 0)
            continue;
        const void *buf = f == FLD_ID ? (const void *)col_id : (const void *)col_mode;
        if (!c->integer) {
            for (size_t col = 0; col < width; ++col) {
                const double *v = col_src[col] >= 0 ? field_values(&frags[col_src[col]], f) : NULL;
                for (int k = 0; k < c->ncomp; ++k)
                    h->dbuf[col * (size_t)c->ncomp + (size_t)k] = v ? v[k] : NAN;
            }
            buf = h->dbuf;
        }
        if (write_frame_block(h->value[f], T, (hsize_t)lo, (hsize_t)width, c->ncomp, mem_type(c),
                              buf) < 0)
            return h5_fail(err, h->path, "writing frame %llu of /particles/fragments/%s/value",
                           (unsigned long long)T, c->name);
    }
    /* step last: its length is the number of complete frames in a file
     * closed by the run (a killed run's file: the attribute `frames`). */
    int64_t step64 = (int64_t)step;
    if (append_rows(h->time, T, 1, H5T_NATIVE_DOUBLE, &time) < 0)
        return h5_fail(err, h->path, "appending to /particles/fragments/id/time");
    if (append_rows(h->step, T, 1, H5T_NATIVE_INT64, &step64) < 0)
        return h5_fail(err, h->path, "appending to /particles/fragments/id/step");
    char what[64];
    snprintf(what, sizeof what, "flushing frame %llu", (unsigned long long)T);
    cf_status st = flush_file(h, err, what);
    if (st != CF_OK)
        return st;
    /* Only now is the frame whole on disk; a second flush (the root's
     * header alone) lets a reader, or a file left by a killed run, count it. */
    if (write_frames_attr(h->file, T + 1, 0) < 0)
        return h5_fail(err, h->path, "counting frame %llu in the root attribute 'frames'",
                       (unsigned long long)T);
    snprintf(what, sizeof what, "flushing the count of frame %llu", (unsigned long long)T);
    st = flush_file(h, err, what);
    if (st != CF_OK)
        return st;

    frame_record *r = &h->frames[T];
    r->time = time;
    r->ncols = ncols;
    r->first = h->nalive;
    r->count = (hsize_t)n;
    /* Its /fracture_mode rows: those added since the frame before. */
    r->ft_first = T > 0 ? h->frames[T - 1].ft_first + h->frames[T - 1].ft_count : 0;
    r->ft_count = h->nftets - r->ft_first;
    for (size_t c = 0; c < width; ++c)
        if (col_src[c] >= 0)
            h->alive[h->nalive++] = lo + (int)c;
    h->nframes = T + 1;
    h->ncols = ncols;
    return CF_OK;
}

cf_status cf_h5_write_frame(cf_h5 *h, long step, double time, const cf_frag_frame *frags, int n,
                            cf_error *err)
{
    quiet_state q;
    quiet_begin(&q);
    cf_status st = write_frame_impl(h, step, time, frags, n, err);
    if (st != CF_OK && h)
        h->failed = 1;
    quiet_end(&q);
    return st;
}

/* ---- fragment records -------------------------------------------------- */

static cf_status add_fragments_impl(cf_h5 *h, const cf_frag_info *info, int n, cf_error *err)
{
    if (!h)
        return cf_error_set(err, CF_ERR_OUTPUT, "cf_h5_add_fragments: no output file is open");
    if (n < 0 || (n > 0 && !info))
        return cf_error_set(err, CF_ERR_OUTPUT,
                            "output file '%s': invalid fragment record list (n = %d)", h->path, n);
    if (n == 0)
        return CF_OK;
    size_t un = (size_t)n;
    if (grow_scratch(h, 7 * un, 10 * un) < 0)
        return no_memory(err, h->path);
    /* Rows are stored by id; the batch may list the new ids in any order. */
    long long base = (long long)h->nfragments;
    int *src = h->ibuf, *parent = h->ibuf + un, *ntets = h->ibuf + 2 * un;
    int *nhulls = h->ibuf + 3 * un, *sfirst = h->ibuf + 4 * un, *scount = h->ibuf + 5 * un;
    int *debris = h->ibuf + 6 * un;
    for (size_t i = 0; i < un; ++i)
        src[i] = -1;
    for (int i = 0; i < n; ++i) {
        long long id = info[i].id;
        if (id < base || id >= base + n || src[id - base] >= 0)
            return cf_error_set(err, CF_ERR_OUTPUT,
                                "output file '%s': fragment id %lld is not new: this batch must "
                                "hold ids %lld..%lld, each once",
                                h->path, id, base, base + n - 1);
        if (info[i].parent < -1 || info[i].parent >= info[i].id)
            return cf_error_set(err, CF_ERR_OUTPUT,
                                "output file '%s': fragment %d has parent %d; the parent must be "
                                "-1 or an earlier fragment",
                                h->path, info[i].id, info[i].parent);
        src[id - base] = i;
    }
    double *birth = h->dbuf, *mass = h->dbuf + un, *inertia = h->dbuf + 2 * un;
    double *hull_error = h->dbuf + 5 * un, *decomp = h->dbuf + 6 * un, *com = h->dbuf + 7 * un;
    for (size_t r = 0; r < un; ++r) {
        const cf_frag_info *fi = &info[src[r]];
        nhulls[r] = fi->n_hulls;
        hull_error[r] = fi->n_hulls > 0 ? fi->hull_volume_error : NAN;
        decomp[r] = fi->n_hulls > 0 ? fi->decomposition_time : NAN;
        parent[r] = fi->parent;
        ntets[r] = fi->n_tets;
        birth[r] = fi->birth_time;
        mass[r] = fi->mass;
        for (int k = 0; k < 3; ++k) {
            inertia[3 * r + (size_t)k] = fi->inertia_principal[k];
            com[3 * r + (size_t)k] = fi->com_rest[k];
        }
        sfirst[r] = fi->surface_first;
        scount[r] = fi->surface_count;
        debris[r] = fi->debris;
    }
    const void *bufs[FR_COUNT] = {parent, birth,      mass, ntets,  inertia, nhulls,
                                  hull_error, decomp, com,  sfirst, scount, debris};
    for (int c = 0; c < FR_COUNT; ++c)
        if (append_rows(h->fragment[c], h->nfragments, un, mem_type(&FRAGMENT_COLUMNS[c]),
                        bufs[c]) < 0)
            return h5_fail(err, h->path, "appending to /fragments/%s", FRAGMENT_COLUMNS[c].name);
    cf_status st = flush_file(h, err, "flushing /fragments");
    if (st != CF_OK)
        return st;
    h->nfragments += un;
    return CF_OK;
}

cf_status cf_h5_add_fragments(cf_h5 *h, const cf_frag_info *info, int n, cf_error *err)
{
    quiet_state q;
    quiet_begin(&q);
    cf_status st = add_fragments_impl(h, info, n, err);
    if (st != CF_OK && h)
        h->failed = 1;
    quiet_end(&q);
    return st;
}

/* ---- observables ------------------------------------------------------- */

static observable *find_observable(cf_h5 *h, const char *name)
{
    /* Callers write the same few names in the same order every frame, so
     * the entry after the last hit is usually the one. */
    for (size_t k = 0; k < h->nobs; ++k) {
        size_t i = (h->obs_last + 1 + k) % h->nobs;
        if (strcmp(h->obs[i].name, name) == 0) {
            h->obs_last = i;
            return &h->obs[i];
        }
    }
    return NULL;
}

static cf_status create_observable(cf_h5 *h, const char *name, const char *unit,
                                   observable **out, cf_error *err)
{
    void *p = h->obs;
    if (grow(&p, &h->obs_cap, h->nobs + 1, sizeof(observable)) < 0)
        return no_memory(err, h->path);
    h->obs = p;
    observable *o = &h->obs[h->nobs];
    o->name = strdup(name);
    if (!o->name)
        return no_memory(err, h->path);
    o->step = o->time = o->value = H5I_INVALID_HID;
    o->n = o->flushed = 0;
    hid_t g = make_group(h->obs_group, name);
    if (g >= 0) {
        o->step = create_rows(g, "step", H5T_STD_I64LE, 1);
        o->time = create_rows(g, "time", H5T_IEEE_F64LE, 1);
        o->value = create_rows(g, "value", H5T_IEEE_F64LE, 1);
        H5Gclose(g);
    }
    if (g < 0 || o->step < 0 || o->time < 0 || o->value < 0 || write_unit(o->time, "s") < 0 ||
        write_unit(o->value, unit) < 0) {
        int ignored = 0;
        close_dataset(&o->step, &ignored);
        close_dataset(&o->time, &ignored);
        close_dataset(&o->value, &ignored);
        free(o->name);
        cf_status st = h5_fail(err, h->path, "creating /observables/%s", name);
        /* No half-made series left in the file (a group without its value). */
        if (g >= 0)
            H5Ldelete(h->obs_group, name, H5P_DEFAULT);
        H5Eclear2(H5E_DEFAULT);
        return st;
    }
    h->obs_last = h->nobs++;
    *out = o;
    return CF_OK;
}

static cf_status write_observable_impl(cf_h5 *h, const char *name, const char *unit, long step,
                                       double time, double value, cf_error *err)
{
    if (!h)
        return cf_error_set(err, CF_ERR_OUTPUT, "cf_h5_write_observable: no output file is open");
    if (!name || !*name || strchr(name, '/') || strcmp(name, ".") == 0 ||
        strcmp(name, "..") == 0 || strlen(name) > 200)
        return cf_error_set(err, CF_ERR_OUTPUT,
                            "output file '%s': observable name '%s' is not usable (it must be "
                            "1-200 characters, without '/', and not '.' or '..')",
                            h->path, name ? name : "(null)");
    observable *o = find_observable(h, name);
    if (!o) {
        cf_status st = create_observable(h, name, unit, &o, err);
        if (st != CF_OK)
            return st;
    }
    /* step last, as for frames.  Samples reach the disk with the next flush
     * (the next frame, fragment batch, hand-off or close). */
    int64_t step64 = (int64_t)step;
    if (append_rows(o->value, o->n, 1, H5T_NATIVE_DOUBLE, &value) < 0 ||
        append_rows(o->time, o->n, 1, H5T_NATIVE_DOUBLE, &time) < 0 ||
        append_rows(o->step, o->n, 1, H5T_NATIVE_INT64, &step64) < 0)
        return h5_fail(err, h->path, "appending to /observables/%s", name);
    o->n++;
    return CF_OK;
}

cf_status cf_h5_write_observable(cf_h5 *h, const char *name, const char *unit, long step,
                                 double time, double value, cf_error *err)
{
    quiet_state q;
    quiet_begin(&q);
    cf_status st = write_observable_impl(h, name, unit, step, time, value, err);
    if (st != CF_OK && h)
        h->failed = 1;
    quiet_end(&q);
    return st;
}

/* ---- hand-offs --------------------------------------------------------- */

static cf_status write_parameter_impl(cf_h5 *h, const char *name, const double *v, int n,
                                     const char *unit, cf_error *err)
{
    if (!name || !*name || strchr(name, '/') || n < 1)
        return cf_error_set(err, CF_ERR_OUTPUT, "%s: parameter name '%s' is empty or holds '/'",
                            h->path, name ? name : "");
    hid_t params = H5Gopen2(h->file, "parameters", H5P_DEFAULT);
    if (params < 0)
        return h5_fail(err, h->path, "opening /parameters");
    if (H5Lexists(params, name, H5P_DEFAULT) > 0) {
        H5Gclose(params);
        return cf_error_set(err, CF_ERR_OUTPUT, "%s: /parameters/%s is written already", h->path,
                            name);
    }
    hsize_t dims[1] = {(hsize_t)n};
    hid_t space = n == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, dims, NULL);
    hid_t dcpl = untimed_plist(H5P_DATASET_CREATE);
    hid_t d = H5I_INVALID_HID;
    int ok = space >= 0 && dcpl >= 0 &&
             (d = H5Dcreate2(params, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl,
                             H5P_DEFAULT)) >= 0 &&
             H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) >= 0 &&
             write_unit(d, unit) == 0;
    if (d >= 0)
        H5Dclose(d);
    if (dcpl >= 0)
        H5Pclose(dcpl);
    if (space >= 0)
        H5Sclose(space);
    H5Gclose(params);
    return ok ? CF_OK : h5_fail(err, h->path, "writing /parameters/%s", name);
}

cf_status cf_h5_write_parameter(cf_h5 *h, const char *name, const double *v, int n,
                                const char *unit, cf_error *err)
{
    if (!h)
        return cf_error_set(err, CF_ERR_OUTPUT, "cf_h5_write_parameter: no file");
    quiet_state q;
    quiet_begin(&q);
    cf_status st = write_parameter_impl(h, name, v, n, unit, err);
    quiet_end(&q);
    return st;
}

static cf_status add_handoff_impl(cf_h5 *h, const cf_handoff_record *r, cf_error *err)
{
    if (!h)
        return cf_error_set(err, CF_ERR_OUTPUT, "cf_h5_add_handoff: no output file is open");
    if (!r)
        return cf_error_set(err, CF_ERR_OUTPUT, "output file '%s': no hand-off record given",
                            h->path);
    const void *bufs[HO_COUNT] = {&r->fragment,        &r->direction,
                                  &r->momentum_error,  r->momentum_change,
                                  r->angular_momentum_change, &r->handoff_loss,
                                  &r->time};
    for (int c = 0; c < HO_COUNT; ++c)
        if (append_rows(h->handoff[c], h->nhandoffs, 1, mem_type(&HANDOFF_COLUMNS[c]), bufs[c]) <
            0)
            return h5_fail(err, h->path, "appending to /handoffs/%s", HANDOFF_COLUMNS[c].name);
    cf_status st = flush_file(h, err, "flushing /handoffs");
    if (st != CF_OK)
        return st;
    h->nhandoffs++;
    return CF_OK;
}

static cf_status add_cracks_impl(cf_h5 *h, const cf_crack_row *r, int n, cf_error *err)
{
    if (!h)
        return cf_error_set(err, CF_ERR_OUTPUT, "cf_h5_add_cracks: no output file is open");
    if (n < 0 || (n > 0 && !r))
        return cf_error_set(err, CF_ERR_OUTPUT, "output file '%s': bad crack rows", h->path);
    cf_status st = write_row_group(h, "cracks", CRACK_COLUMNS, CR_COUNT, h->crack, err);
    if (st != CF_OK || n == 0)
        return st;
    /* Column by column from the rows. */
    int *ibuf = malloc((size_t)n * 2 * sizeof(int));
    double *dbuf = malloc((size_t)n * 3 * sizeof(double));
    for (int c = 0; st == CF_OK && ibuf && dbuf && c < CR_COUNT; ++c) {
        for (int i = 0; i < n; ++i) {
            const cf_crack_row *q = &r[i];
            switch (c) {
            case CR_ELEMENT: ibuf[i] = q->element; break;
            case CR_TETS: memcpy(&ibuf[2 * i], q->tets, 2 * sizeof(int)); break;
            case CR_FAILED: ibuf[i] = q->failed; break;
            case CR_CENTROID: memcpy(&dbuf[3 * i], q->centroid, 3 * sizeof(double)); break;
            case CR_NORMAL: memcpy(&dbuf[3 * i], q->normal, 3 * sizeof(double)); break;
            case CR_AREA: dbuf[i] = q->area; break;
            case CR_OPENING: dbuf[i] = q->opening; break;
            case CR_SLIDING: dbuf[i] = q->sliding; break;
            default: dbuf[i] = q->time; break;
            }
        }
        const void *buf = CRACK_COLUMNS[c].integer ? (const void *)ibuf : (const void *)dbuf;
        if (append_rows(h->crack[c], h->ncracks, (hsize_t)n, mem_type(&CRACK_COLUMNS[c]), buf) < 0)
            st = h5_fail(err, h->path, "appending to /cracks/%s", CRACK_COLUMNS[c].name);
    }
    if (st == CF_OK && (!ibuf || !dbuf))
        st = no_memory(err, h->path);
    free(ibuf), free(dbuf);
    if (st == CF_OK)
        h->ncracks += (hsize_t)n;
    return st;
}

static cf_status add_fracture_tets_impl(cf_h5 *h, int n, const int *tet, const double *corners,
                                        const double *stress, const double *damage, double time,
                                        cf_error *err)
{
    if (!h)
        return cf_error_set(err, CF_ERR_OUTPUT, "cf_h5_add_fracture_tets: no output file is open");
    if (n < 0 || (n > 0 && (!tet || !corners || !stress || !damage)))
        return cf_error_set(err, CF_ERR_OUTPUT, "output file '%s': bad fracture-mode rows",
                            h->path);
    cf_status st = write_row_group(h, "fracture_mode", FRACTURE_COLUMNS, FT_COUNT, h->ftet, err);
    if (st != CF_OK || n == 0)
        return st;
    double *times = malloc((size_t)n * sizeof *times);
    if (!times)
        return no_memory(err, h->path);
    for (int i = 0; i < n; i++)
        times[i] = time;
    const void *bufs[FT_COUNT] = {tet, corners, stress, damage, times};
    for (int c = 0; c < FT_COUNT && st == CF_OK; ++c)
        if (append_rows(h->ftet[c], h->nftets, (hsize_t)n, mem_type(&FRACTURE_COLUMNS[c]),
                        bufs[c]) < 0)
            st = h5_fail(err, h->path, "appending to /fracture_mode/%s", FRACTURE_COLUMNS[c].name);
    free(times);
    if (st == CF_OK)
        h->nftets += (hsize_t)n;
    return st;
}

cf_status cf_h5_add_fracture_tets(cf_h5 *h, int n, const int *tet, const double *corners,
                                  const double *stress, const double *damage, double time,
                                  cf_error *err)
{
    quiet_state q;
    quiet_begin(&q);
    cf_status st = add_fracture_tets_impl(h, n, tet, corners, stress, damage, time, err);
    if (st != CF_OK && h)
        h->failed = 1;
    quiet_end(&q);
    return st;
}

cf_status cf_h5_add_cracks(cf_h5 *h, const cf_crack_row *rows, int n, cf_error *err)
{
    quiet_state q;
    quiet_begin(&q);
    cf_status st = add_cracks_impl(h, rows, n, err);
    if (st != CF_OK && h)
        h->failed = 1;
    quiet_end(&q);
    return st;
}

cf_status cf_h5_add_handoff(cf_h5 *h, const cf_handoff_record *r, cf_error *err)
{
    quiet_state q;
    quiet_begin(&q);
    cf_status st = add_handoff_impl(h, r, err);
    if (st != CF_OK && h)
        h->failed = 1;
    quiet_end(&q);
    return st;
}

/* ---- recognising our own files ----------------------------------------- */

/* HDF5 closes what is still open when the process exits; after a failed
 * close (a full disk) that second attempt crashes inside HDF5 (SIGSEGV in
 * H5F__close_cb).  Every file this writer opens is closed by cf_h5_close,
 * so the exit-time clean-up is turned off before HDF5's first use.  Then
 * HDF5 is started (H5open): it allocates its tables on first use, and
 * when that fails every later call fails with a misleading reason ("not a
 * property list class").  Returns 0, or -1 when it could not start (its
 * error stack says why). */
static int h5_init_once(void)
{
    static int done = 0;
    if (!done) {
        done = 1;
        H5dont_atexit();
    }
    return H5open() < 0 ? -1 : 0;
}

int cf_h5_is_output(const char *path)
{
    if (h5_init_once() < 0) /* before any HDF5 call */
        return 0;
    quiet_state q;
    quiet_begin(&q);
    int ours = 0;
    if (H5Fis_hdf5(path) > 0) {
        hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
        if (f >= 0) {
            if (H5Aexists(f, "creator") > 0) {
                hid_t a = H5Aopen(f, "creator", H5P_DEFAULT);
                hid_t t = a >= 0 ? H5Aget_type(a) : H5I_INVALID_HID;
                char *v = NULL;
                hid_t mt = string_type(); /* as written: variable-length UTF-8 */
                if (t >= 0 && mt >= 0 && H5Tis_variable_str(t) > 0 && H5Aread(a, mt, &v) >= 0 &&
                    v) {
                    ours = strcmp(v, "cohfrac") == 0;
                    H5free_memory(v);
                }
                if (mt >= 0)
                    H5Tclose(mt);
                if (t >= 0)
                    H5Tclose(t);
                if (a >= 0)
                    H5Aclose(a);
            }
            H5Fclose(f);
        }
    }
    H5Eclear2(H5E_DEFAULT);
    quiet_end(&q);
    return ours;
}

/* ---- geometry ---------------------------------------------------------- */

static cf_status add_surfaces_impl(cf_h5 *h, const int *tris, const int *crack, int m, int *first,
                                   cf_error *err)
{
    if (!h || m < 0 || (m > 0 && (!tris || !crack)))
        return cf_error_set(err, CF_ERR_OUTPUT, "cf_h5_add_surfaces: bad arguments");
    *first = (int)h->nsurface;
    if (m == 0)
        return CF_OK;
    if (append_rows(h->surface[SF_TRIANGLES], h->nsurface, (hsize_t)m, H5T_NATIVE_INT, tris) < 0 ||
        append_rows(h->surface[SF_CRACK], h->nsurface, (hsize_t)m, H5T_NATIVE_INT, crack) < 0)
        return h5_fail(err, h->path, "appending to /surfaces");
    h->nsurface += (hsize_t)m;
    return CF_OK;
}

cf_status cf_h5_add_surfaces(cf_h5 *h, const int *tris, const int *crack, int m, int *first,
                             cf_error *err)
{
    quiet_state q;
    quiet_begin(&q);
    cf_status st = add_surfaces_impl(h, tris, crack, m, first, err);
    if (st != CF_OK && h)
        h->failed = 1;
    quiet_end(&q);
    return st;
}

static cf_status write_rest_mesh_impl(cf_h5 *h, const double *X, int n, const int *tets, int nt,
                                      cf_error *err)
{
    if (!h || n < 0 || nt < 0)
        return cf_error_set(err, CF_ERR_OUTPUT, "cf_h5_write_rest_mesh: bad arguments");
    hid_t mesh = make_group(h->file, "mesh");
    hid_t rest = mesh >= 0 ? make_group(mesh, "rest") : H5I_INVALID_HID;
    hid_t dn = rest >= 0 ? create_rows(rest, "nodes", H5T_IEEE_F64LE, 3) : H5I_INVALID_HID;
    hid_t dt = rest >= 0 ? create_rows(rest, "tets", H5T_STD_I32LE, 4) : H5I_INVALID_HID;
    int ok = dn >= 0 && dt >= 0 && write_unit(dn, "m") == 0 &&
             append_rows(dn, 0, (hsize_t)n, H5T_NATIVE_DOUBLE, X) == 0 &&
             append_rows(dt, 0, (hsize_t)nt, H5T_NATIVE_INT, tets) == 0;
    int ignored = 0;
    close_dataset(&dn, &ignored);
    close_dataset(&dt, &ignored);
    if (rest >= 0)
        H5Gclose(rest);
    if (mesh >= 0)
        H5Gclose(mesh);
    if (!ok)
        return h5_fail(err, h->path, "writing /mesh/rest");
    return flush_file(h, err, "flushing /mesh/rest");
}

cf_status cf_h5_write_rest_mesh(cf_h5 *h, const double *X, int n, const int *tets, int nt,
                                cf_error *err)
{
    quiet_state q;
    quiet_begin(&q);
    cf_status st = write_rest_mesh_impl(h, X, n, tets, nt, err);
    quiet_end(&q);
    return st;
}

static cf_status write_visual_impl(cf_h5 *h, const double *V, int nv, const int *tri,
                                   const int *tet, int nt, cf_error *err)
{
    hid_t g = make_group(h->file, "visual");
    hid_t dv = g >= 0 ? create_rows(g, "vertices", H5T_IEEE_F64LE, 3) : H5I_INVALID_HID;
    hid_t dt = g >= 0 ? create_rows(g, "triangles", H5T_STD_I32LE, 3) : H5I_INVALID_HID;
    hid_t de = g >= 0 ? create_rows(g, "tet", H5T_STD_I32LE, 1) : H5I_INVALID_HID;
    int ok = dv >= 0 && dt >= 0 && de >= 0 && write_unit(dv, "m") == 0 &&
             append_rows(dv, 0, (hsize_t)nv, H5T_NATIVE_DOUBLE, V) == 0 &&
             append_rows(dt, 0, (hsize_t)nt, H5T_NATIVE_INT, tri) == 0 &&
             append_rows(de, 0, (hsize_t)nt, H5T_NATIVE_INT, tet) == 0;
    int ignored = 0;
    close_dataset(&dv, &ignored);
    close_dataset(&dt, &ignored);
    close_dataset(&de, &ignored);
    if (g >= 0)
        H5Gclose(g);
    if (!ok)
        return h5_fail(err, h->path, "writing /visual");
    return flush_file(h, err, "flushing /visual");
}

cf_status cf_h5_write_visual(cf_h5 *h, const double *V, int nv, const int *tri, const int *tet,
                             int nt, cf_error *err)
{
    if (!h || nv < 0 || nt < 0)
        return cf_error_set(err, CF_ERR_OUTPUT, "cf_h5_write_visual: bad arguments");
    quiet_state q;
    quiet_begin(&q);
    cf_status st = write_visual_impl(h, V, nv, tri, tet, nt, err);
    quiet_end(&q);
    return st;
}

static cf_status write_tet_fragments_impl(cf_h5 *h, long step, double time, const int *map,
                                          int nt, cf_error *err)
{
    if (!h || nt < 1 || !map)
        return cf_error_set(err, CF_ERR_OUTPUT, "cf_h5_write_tet_fragments: bad arguments");
    if (h->map_value < 0) {
        hid_t g = H5Gopen2(h->file, "mesh", H5P_DEFAULT);
        hid_t m = g >= 0 ? make_group(g, "tet_fragment") : H5I_INVALID_HID;
        hsize_t dims[2] = {0, (hsize_t)nt}, maxdims[2] = {H5S_UNLIMITED, (hsize_t)nt};
        hsize_t chunk[2] = {1, (hsize_t)nt};
        int fill = -1;
        if (m >= 0) {
            h->map_step = create_rows(m, "step", H5T_STD_I64LE, 1);
            h->map_time = create_rows(m, "time", H5T_IEEE_F64LE, 1);
            h->map_value = create_extendable(m, "value", H5T_STD_I32LE, 2, dims, maxdims, chunk,
                                             H5T_NATIVE_INT, &fill);
            write_unit(h->map_time, "s");
            H5Gclose(m);
        }
        if (g >= 0)
            H5Gclose(g);
        if (h->map_step < 0 || h->map_time < 0 || h->map_value < 0)
            return h5_fail(err, h->path, "creating /mesh/tet_fragment");
    }
    int64_t step64 = step;
    if (append_rows(h->map_value, h->nmaps, 1, H5T_NATIVE_INT, map) < 0 ||
        append_rows(h->map_time, h->nmaps, 1, H5T_NATIVE_DOUBLE, &time) < 0 ||
        append_rows(h->map_step, h->nmaps, 1, H5T_NATIVE_INT64, &step64) < 0)
        return h5_fail(err, h->path, "appending to /mesh/tet_fragment");
    h->nmaps++;
    return CF_OK;
}

cf_status cf_h5_write_tet_fragments(cf_h5 *h, long step, double time, const int *map, int nt,
                                    cf_error *err)
{
    quiet_state q;
    quiet_begin(&q);
    cf_status st = write_tet_fragments_impl(h, step, time, map, nt, err);
    if (st != CF_OK && h)
        h->failed = 1;
    quiet_end(&q);
    return st;
}

/* ---- XDMF sidecar ------------------------------------------------------ */

/* `<path minus .h5>.xdmf`; `.hdf5` is stripped too, anything else kept. */
static char *sidecar_path(const char *path)
{
    size_t len = strlen(path), stem = len;
    if (len > 3 && strcmp(path + len - 3, ".h5") == 0)
        stem = len - 3;
    else if (len > 5 && strcmp(path + len - 5, ".hdf5") == 0)
        stem = len - 5;
    char *x = malloc(stem + sizeof ".xdmf");
    if (x) {
        memcpy(x, path, stem);
        memcpy(x + stem, ".xdmf", sizeof ".xdmf");
    }
    return x;
}

/* `s` with the five XML special characters escaped (malloc'd). */
static char *xml_escape(const char *s)
{
    char *out = malloc(6 * strlen(s) + 1);
    if (!out)
        return NULL;
    char *o = out;
    for (; *s; ++s) {
        const char *rep = NULL;
        switch (*s) {
        case '&':
            rep = "&amp;";
            break;
        case '<':
            rep = "&lt;";
            break;
        case '>':
            rep = "&gt;";
            break;
        case '"':
            rep = "&quot;";
            break;
        case '\'':
            rep = "&apos;";
            break;
        default:
            *o++ = *s;
        }
        if (rep) {
            size_t n = strlen(rep);
            memcpy(o, rep, n);
            o += n;
        }
    }
    *o = '\0';
    return out;
}

/* The largest number of /fracture_mode rows of one frame. */
static hsize_t max_fracture_rows(const cf_h5 *h)
{
    hsize_t m = 0;
    for (hsize_t t = 0; t < h->nframes; ++t)
        m = h->frames[t].ft_count > m ? h->frames[t].ft_count : m;
    return m;
}

/* Writes /xdmf/<name>, n int32 values; 0, or -1 when HDF5 failed (every
 * object it opened closed again). */
static int write_xdmf_ints(cf_h5 *h, const char *name, const int *v, hsize_t n)
{
    hid_t g = H5Lexists(h->file, "xdmf", H5P_DEFAULT) > 0 ? H5Gopen2(h->file, "xdmf", H5P_DEFAULT)
                                                          : make_group(h->file, "xdmf");
    hid_t s = H5Screate_simple(1, &n, NULL);
    hid_t dcpl = untimed_plist(H5P_DATASET_CREATE);
    hid_t d = H5I_INVALID_HID;
    int ok = g >= 0 && s >= 0 && dcpl >= 0 &&
             (d = H5Dcreate2(g, name, H5T_STD_I32LE, s, H5P_DEFAULT, dcpl, H5P_DEFAULT)) >= 0 &&
             H5Dwrite(d, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) >= 0;
    if (d >= 0)
        H5Dclose(d);
    if (dcpl >= 0)
        H5Pclose(dcpl);
    if (s >= 0)
        H5Sclose(s);
    if (g >= 0)
        H5Gclose(g);
    return ok ? 0 : -1;
}

/* /xdmf/tet_corners = 0, 1, ..., 4 M - 1 for the M rows of the largest
 * fracture-mode frame: each tet of /fracture_mode sits on its own four
 * corners, so a frame's tetrahedra are the first 4 n of these. */
static cf_status write_corner_index(cf_h5 *h, cf_error *err)
{
    hsize_t n = 4 * max_fracture_rows(h);
    if (n == 0)
        return CF_OK;
    int *idx = malloc((size_t)n * sizeof *idx);
    if (!idx)
        return no_memory(err, h->path);
    for (hsize_t i = 0; i < n; ++i)
        idx[i] = (int)i;
    int failed = write_xdmf_ints(h, "tet_corners", idx, n);
    free(idx);
    return failed ? h5_fail(err, h->path, "writing /xdmf/tet_corners") : CF_OK;
}

/* The XDMF topology cells of frame t are its alive columns; they are kept in
 * /xdmf/polyvertex so dead or unborn columns (NaN) are not drawn. */
static cf_status write_connectivity(cf_h5 *h, cf_error *err)
{
    if (h->nalive == 0)
        return CF_OK;
    if (write_xdmf_ints(h, "polyvertex", h->alive, (hsize_t)h->nalive) != 0)
        return h5_fail(err, h->path, "writing /xdmf/polyvertex");
    return write_corner_index(h, err);
}

/* Shortest "%g" text that reads back as exactly `v` (0.03, not
 * 0.029999999999999999). */
static void format_double(char *buf, size_t n, double v)
{
    for (int prec = 15; prec <= 17; ++prec) {
        snprintf(buf, n, "%.*g", prec, v);
        if (strtod(buf, NULL) == v)
            return;
    }
}

/* What every grid of the sidecar refers to. */
typedef struct xdmf_ctx {
    FILE *fp;
    const char *href;               /* XML-escaped base name of the .h5 */
    hsize_t dims[FLD_COUNT][2];     /* actual [T][N] of each value dataset */
} xdmf_ctx;

/* A DataItem reading frame t, columns [0, cols) of a [T][N](,k) dataset.
 * XDMF 3 takes the selection in the content itself,
 * "file:/dataset|start:stride:count:dataspace", which ParaView's XDMF 3
 * readers honour for geometry and attributes alike. */
static void put_frame_slab(const xdmf_ctx *x, hsize_t t, hsize_t cols, int field)
{
    const column_def *c = &FIELDS[field];
    FILE *fp = x->fp;
    unsigned long long T = (unsigned long long)x->dims[field][0];
    unsigned long long N = (unsigned long long)x->dims[field][1];
    unsigned long long tt = (unsigned long long)t, cc = (unsigned long long)cols;
    const char *type = c->integer ? "NumberType=\"Int\" Precision=\"4\""
                                  : "NumberType=\"Float\" Precision=\"8\"";
    if (c->ncomp > 1)
        fprintf(fp,
                "          <DataItem Dimensions=\"%llu %d\" %s Format=\"HDF\">%s:/particles/"
                "fragments/%s/value|%llu 0 0:1 1 1:1 %llu %d:%llu %llu %d</DataItem>\n",
                cc, c->ncomp, type, x->href, c->name, tt, cc, c->ncomp, T, N, c->ncomp);
    else
        fprintf(fp,
                "          <DataItem Dimensions=\"%llu\" %s Format=\"HDF\">%s:/particles/"
                "fragments/%s/value|%llu 0:1 1:1 %llu:%llu %llu</DataItem>\n",
                cc, type, x->href, c->name, tt, cc, T, N);
}

static void put_attribute(const xdmf_ctx *x, hsize_t t, hsize_t cols, int field)
{
    fprintf(x->fp, "        <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Node\">\n",
            FIELDS[field].name, FIELDS[field].ncomp == 3 ? "Vector" : "Scalar");
    put_frame_slab(x, t, cols, field);
    fputs("        </Attribute>\n", x->fp);
}

/* A DataItem reading rows [first, first + n) of /fracture_mode/<name>, a
 * [R][k] dataset (k = 1: [R]). */
static void put_fracture_slab(const xdmf_ctx *x, const char *name, int k, int integer,
                              hsize_t first, hsize_t n, hsize_t R)
{
    unsigned long long f = first, c = n, r = R;
    const char *type = integer ? "NumberType=\"Int\" Precision=\"4\""
                               : "NumberType=\"Float\" Precision=\"8\"";
    if (k > 1)
        fprintf(x->fp,
                "          <DataItem Dimensions=\"%llu %d\" %s Format=\"HDF\">%s:/fracture_mode/"
                "%s|%llu 0:1 1:%llu %d:%llu %d</DataItem>\n",
                c, k, type, x->href, name, f, c, k, r, k);
    else
        fprintf(x->fp,
                "          <DataItem Dimensions=\"%llu\" %s Format=\"HDF\">%s:/fracture_mode/"
                "%s|%llu:1:%llu:%llu</DataItem>\n",
                c, type, x->href, name, f, c, r);
}

/* A second temporal collection: the deformed tets of fracture-mode
 * fragments at the frames that have them, with stress and damage. */
static void put_fracture_grids(const xdmf_ctx *x, const cf_h5 *h)
{
    hsize_t M = max_fracture_rows(h);
    if (M == 0)
        return;
    FILE *fp = x->fp;
    fputs("    <Grid Name=\"fracture_mode\" GridType=\"Collection\" "
          "CollectionType=\"Temporal\">\n",
          fp);
    for (hsize_t t = 0; t < h->nframes; ++t) {
        const frame_record *r = &h->frames[t];
        if (r->ft_count == 0)
            continue;
        unsigned long long n = r->ft_count;
        char time_text[32];
        format_double(time_text, sizeof time_text, r->time);
        fprintf(fp,
                "      <Grid Name=\"fracture_%06llu\" GridType=\"Uniform\">\n"
                "        <Time Value=\"%s\"/>\n"
                "        <Topology TopologyType=\"Tetrahedron\" NumberOfElements=\"%llu\">\n"
                "          <DataItem Dimensions=\"%llu 4\" NumberType=\"Int\" Precision=\"4\" "
                "Format=\"HDF\">%s:/xdmf/tet_corners|0:1:%llu:%llu</DataItem>\n"
                "        </Topology>\n"
                "        <Geometry GeometryType=\"XYZ\">\n",
                (unsigned long long)t, time_text, n, n, x->href, 4 * n,
                (unsigned long long)(4 * M));
        put_fracture_slab(x, "corners", 12, 0, r->ft_first, r->ft_count, h->nftets);
        fputs("        </Geometry>\n", fp);
        static const struct {
            const char *name, *type;
            int k, integer;
        } attrs[] = {{"tet", "Scalar", 1, 1}, {"stress", "Tensor6", 6, 0},
                     {"damage", "Scalar", 1, 0}};
        for (size_t a = 0; a < sizeof attrs / sizeof attrs[0]; ++a) {
            fprintf(fp, "        <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Cell\">\n",
                    attrs[a].name, attrs[a].type);
            put_fracture_slab(x, attrs[a].name, attrs[a].k, attrs[a].integer, r->ft_first,
                              r->ft_count, h->nftets);
            fputs("        </Attribute>\n", fp);
        }
        fputs("      </Grid>\n", fp);
    }
    fputs("    </Grid>\n", fp);
}

static void put_xdmf(const xdmf_ctx *x, const cf_h5 *h)
{
    FILE *fp = x->fp;
    fputs("<?xml version=\"1.0\" ?>\n"
          "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
          "  <Domain>\n"
          "    <Grid Name=\"fragments\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
          fp);
    unsigned long long M = (unsigned long long)h->nalive;
    for (hsize_t t = 0; t < h->nframes; ++t) {
        const frame_record *r = &h->frames[t];
        if (r->count == 0)
            continue; /* readers do not accept a grid without points */
        unsigned long long n = (unsigned long long)r->count;
        char time_text[32];
        format_double(time_text, sizeof time_text, r->time);
        fprintf(fp,
                "      <Grid Name=\"frame_%06llu\" GridType=\"Uniform\">\n"
                "        <Time Value=\"%s\"/>\n"
                "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%llu\" "
                "NodesPerElement=\"1\">\n"
                "          <DataItem Dimensions=\"%llu\" NumberType=\"Int\" Precision=\"4\" "
                "Format=\"HDF\">%s:/xdmf/polyvertex|%llu:1:%llu:%llu</DataItem>\n"
                "        </Topology>\n"
                "        <Geometry GeometryType=\"XYZ\">\n",
                (unsigned long long)t, time_text, n, n, x->href, (unsigned long long)r->first, n,
                M);
        put_frame_slab(x, t, r->ncols, FLD_POSITION);
        fputs("        </Geometry>\n", fp);
        put_attribute(x, t, r->ncols, FLD_ID);
        put_attribute(x, t, r->ncols, FLD_MODE);
        put_attribute(x, t, r->ncols, FLD_VELOCITY);
        put_attribute(x, t, r->ncols, FLD_ANGVEL);
        fputs("      </Grid>\n", fp);
    }
    fputs("    </Grid>\n", fp);
    put_fracture_grids(x, h);
    fputs("  </Domain>\n</Xdmf>\n", fp);
}

/* The sidecar is written under a temporary name and renamed, so a reader
 * never sees half of it. */
static cf_status write_xdmf(const cf_h5 *h, cf_error *err)
{
    xdmf_ctx x = {0};
    /* Read the extents back: after a failed frame they can exceed nframes. */
    for (int f = 0; f < FLD_COUNT; ++f) {
        hsize_t dims[3] = {0, 0, 0};
        hid_t s = H5Dget_space(h->value[f]);
        int ok = s >= 0 && H5Sget_simple_extent_dims(s, dims, NULL) >= 0;
        if (s >= 0)
            H5Sclose(s);
        if (!ok)
            return h5_fail(err, h->path, "reading the extent of /particles/fragments/%s/value",
                           FIELDS[f].name);
        x.dims[f][0] = dims[0];
        x.dims[f][1] = dims[1];
    }
    const char *slash = strrchr(h->path, '/');
    char *href = xml_escape(slash ? slash + 1 : h->path);
    char *xpath = sidecar_path(h->path);
    char *tmp = xpath ? malloc(strlen(xpath) + sizeof ".tmp") : NULL;
    cf_status st = CF_OK;
    if (!href || !tmp) {
        st = no_memory(err, h->path);
        goto done;
    }
    strcpy(tmp, xpath);
    strcat(tmp, ".tmp");
    x.href = href;
    x.fp = fopen(tmp, "w");
    if (!x.fp) {
        /* fopen allocates its FILE: ENOMEM is memory, not the disk. */
        st = errno == ENOMEM
                 ? cf_error_set(err, CF_ERR_NOMEM, "XDMF sidecar '%s': out of memory opening it", tmp)
                 : cf_error_set(err, CF_ERR_OUTPUT, "XDMF sidecar '%s': cannot create it: %s", tmp,
                                strerror(errno));
        goto done;
    }
    put_xdmf(&x, h);
    int write_failed = ferror(x.fp);
    if (fclose(x.fp) != 0 || write_failed) {
        st = cf_error_set(err, CF_ERR_OUTPUT, "XDMF sidecar '%s': writing it failed: %s", tmp,
                          strerror(errno));
        remove(tmp);
    } else if (rename(tmp, xpath) != 0) {
        st = cf_error_set(err, CF_ERR_OUTPUT, "XDMF sidecar '%s': cannot rename '%s' to it: %s",
                          xpath, tmp, strerror(errno));
        remove(tmp);
    }
done:
    free(tmp);
    free(xpath);
    free(href);
    return st;
}

/* ---- close ------------------------------------------------------------- */

unsigned long long cf_h5_memory(const cf_h5 *h)
{
    size_t max = 0, min_clean = 0, cur = 0;
    int entries = 0;
    if (!h || H5Fget_mdc_size(h->file, &max, &min_clean, &cur, &entries) < 0)
        return 0;
    return cur;
}

/* Cut dataset `d` back to `rows` rows when it holds more. */
static void trim_rows(hid_t d, hsize_t rows)
{
    if (d < 0)
        return;
    hsize_t dims[3] = {0, 0, 0};
    hid_t s = H5Dget_space(d);
    int rank = s >= 0 ? H5Sget_simple_extent_ndims(s) : -1;
    int ok = rank >= 1 && rank <= 3 && H5Sget_simple_extent_dims(s, dims, NULL) >= 0;
    if (s >= 0)
        H5Sclose(s);
    if (ok && dims[0] > rows) {
        dims[0] = rows;
        H5Dset_extent(d, dims);
    }
}

/* After a failed write (out of memory, a full disk) the tables hold part
 * of what was being written: the fields of a frame but not its step, the
 * observables of a frame that never came, some columns of a hand-off.  The
 * close flushes whatever is in them, so first every table goes back to
 * what the last successful flush left: the file is then as a SIGKILL at
 * that moment would have left it, every frame complete or absent. */
static void rollback(cf_h5 *h)
{
    for (int f = 0; f < FLD_COUNT; ++f)
        trim_rows(h->value[f], h->nframes);
    trim_rows(h->time, h->nframes);
    trim_rows(h->step, h->nframes);
    write_frames_attr(h->file, h->nframes, 0);
    for (int c = 0; c < FR_COUNT; ++c)
        trim_rows(h->fragment[c], h->nfragments);
    for (int c = 0; c < HO_COUNT; ++c)
        trim_rows(h->handoff[c], h->nhandoffs);
    for (int c = 0; c < CR_COUNT; ++c)
        trim_rows(h->crack[c], h->ncracks_flushed);
    h->ncracks = h->ncracks_flushed;
    for (int c = 0; c < FT_COUNT; ++c)
        trim_rows(h->ftet[c], h->nftets_flushed);
    h->nftets = h->nftets_flushed;
    for (int c = 0; c < SF_COUNT; ++c)
        trim_rows(h->surface[c], h->nsurface_flushed);
    h->nsurface = h->nsurface_flushed;
    trim_rows(h->map_step, h->nmaps_flushed);
    trim_rows(h->map_time, h->nmaps_flushed);
    trim_rows(h->map_value, h->nmaps_flushed);
    h->nmaps = h->nmaps_flushed;
    for (size_t i = 0; i < h->nobs; ++i) {
        observable *o = &h->obs[i];
        if (o->flushed == 0) { /* begun after the last flush: not there then */
            int ignored = 0;
            close_dataset(&o->step, &ignored);
            close_dataset(&o->time, &ignored);
            close_dataset(&o->value, &ignored);
            H5Ldelete(h->obs_group, o->name, H5P_DEFAULT);
        } else {
            trim_rows(o->step, o->flushed);
            trim_rows(o->time, o->flushed);
            trim_rows(o->value, o->flushed);
        }
        o->n = o->flushed;
    }
    H5Eclear2(H5E_DEFAULT);
}

cf_status cf_h5_close(cf_h5 *h, cf_error *err)
{
    if (!h)
        return CF_OK;
    quiet_state q;
    quiet_begin(&q);
    if (h->failed)
        rollback(h);
    cf_status st = flush_file(h, err, "flushing before close");
    if (st == CF_OK)
        st = write_connectivity(h, err);
    /* Everything on disk before the handles close: a close that runs out
     * of memory then has nothing left to write half-way. */
    if (st == CF_OK)
        st = flush_file(h, err, "flushing /xdmf");
    if (st == CF_OK)
        st = write_xdmf(h, err);
    if (close_handles(h) < 0 && st == CF_OK)
        st = h5_fail(err, h->path, "closing the file");
    H5Eclear2(H5E_DEFAULT);
    free_handle(h);
    quiet_end(&q);
    return st;
}
