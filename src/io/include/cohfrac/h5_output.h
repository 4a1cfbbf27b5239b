/* cohfrac — HDF5 output (H5MD-style layout, docs/output.md), readable by h5py and
 * ParaView (through the XDMF sidecar written next to the file).
 *
 * Layout (all SI; every dataset chunked and extendable, flushed each frame so
 * a killed run leaves a readable file):
 *   /                      attrs creator, version, units="SI", up_axis="+z",
 *                          quaternion_order="wxyz", scene_name
 *   /parameters/scene      the resolved scene (Lua text), string
 *   /parameters/initial_lower[3], initial_upper[3] (m: the box around every
 *                          node at t = 0), total_mass (kg), initial_energy (J:
 *                          kinetic + strain at t = 0), max_initial_speed (m/s:
 *                          the fastest node at t = 0), max_obstacle_speed (m/s:
 *                          the fastest kinematic obstacle or prescribed node);
 *                          each with a `unit` attribute
 *   /particles/fragments/<field>/{step[T] int64, time[T] float64 s, value[T][N](...)}
 *       field   value shape   meaning                         fill
 *       id          [T][N]     fragment id, -1 when not alive   -1
 *       position    [T][N][3]  centre of mass, m                NaN
 *       orientation [T][N][4]  rest->current rotation (w,x,y,z) NaN
 *       velocity    [T][N][3]  COM velocity, m/s                NaN
 *       angular_velocity [T][N][3] rad/s                        NaN
 *       mode        [T][N]     0 rigid, 1 fracture, -1 not alive -1
 *     Column j is fragment id j for the whole file; N grows as fragments are born.
 *   /fragments/{parent[N] int32 (-1 for an initial body), birth_time[N] s,
 *               mass[N] kg, n_tets[N], inertia_principal[N][3] kg m^2,
 *               n_hulls[N] (convex hulls of its Bullet shape, 0 when it was
 *               born with none), hull_volume_error[N] (hull volume / tet
 *               volume - 1, NaN without hulls), decomposition_time[N] s}
 *   /observables/<name>/{step[T] int64, time[T] s, value[T] float64 with its
 *                          `unit` attribute (none for counts)}
 *   /handoffs/{time, fragment, direction (0 rigid->fracture, 1 fracture->rigid),
 *              momentum_error (relative), momentum_change[3] kg m/s and
 *              angular_momentum_change[3] kg m^2/s (after - before, about the
 *              origin), handoff_loss (J)}  one row per hand-off
 *   /cracks/{element, tets[2] int32 (input order: the two tets whose shared
 *            face it lies on), centroid[3] m, normal[3], area m^2, opening m,
 *            sliding m, failed, time s}  with output.cracks: one row per
 *            cohesive element per frame (rows of a frame share its time)
 *   /fracture_mode/{tet int32 (input order), corners[4 * 3] m, stress[6] Pa
 *            (Cauchy, xx yy zz yz xz xy), damage (0 intact .. 1 a free
 *            crack face), time s}  with output.fields: one row per tet of a
 *            fragment in fracture mode, at each frame that has one
 *   /mesh/rest/nodes[n][3] m, /mesh/rest/tets[nt][4] int32: the rest mesh as
 *                          placed at t = 0 (before node duplication), input tet order
 *   /mesh/tet_fragment/{step[K], time[K] s, value[K][nt] int32}: the fragment of
 *                          every tet, at each frame after fragments were born
 *   /surfaces/{triangles[M][3] int32 (on /mesh/rest/nodes, outward), crack[M]
 *              (1: a crack face, inside the rest mesh; 0: the body's surface)}
 *                          every fragment's boundary, written at its birth; a
 *                          fragment's rows are surface_first .. + surface_count
 *                          of its /fragments record, which also holds com_rest[3]
 *                          (m): the pose maps a rest node X to com + R (X - com_rest)
 *   /parameters/obstacle_{type (0 plane, 1 sphere, 2 box, 3 mesh), radius,
 *                          point, normal, center, half_extents, velocity}: the
 *                          obstacles at t = 0 (vectors flattened, [3 n])
 *   /h5md                  H5MD 1.1 metadata: attr version [1,1], author/ and
 *                          creator/ (attrs name, version), modules/units
 *   /particles/fragments/box  attrs dimension=3, boundary=["none"]*3 (H5MD)
 *   /xdmf/polyvertex[M] int32  written by cf_h5_close for the sidecar: the
 *                          alive columns of every frame, concatenated in order
 *
 * How the writer behaves (what a reader may rely on):
 *   - step and time of all six particle fields are hard links to the same two
 *     datasets.  Their length T is the number of complete frames; in a file
 *     left by a killed run a value dataset may hold one more, partial row, so
 *     read T = len(step).
 *   - N = max(1 + largest id ever written in a frame, number of fragment
 *     records); in every frame the columns of fragments not alive hold the
 *     fill value (NaN, -1 for id and mode), as do all frames before a birth.
 *   - Frames, fragment batches and hand-offs are flushed to disk at once;
 *     observable samples with the next of those or on close, so write a
 *     frame's observables before the frame.
 *   - No HDF5 file lock is held: another process (h5py) can open the file
 *     read-only while the run goes on and sees the state of the last flush.
 *   - Strings (attributes, the scene) are variable-length UTF-8.  No object
 *     timestamps are stored, so the same calls by the same user give the same
 *     bytes (/h5md/author's name is $USER).
 *   - The sidecar `<path minus .h5 or .hdf5>.xdmf` (".xdmf" appended to any
 *     other name) is XDMF 3: a temporal collection of Polyvertex grids, one
 *     per frame with at least one alive fragment, whose cells are the alive
 *     fragments' centres and whose node attributes are id, mode, velocity and
 *     angular_velocity, read as hyperslabs of the .h5 named by its base name
 *     (keep the two files side by side).  ParaView 5.11 opens it with its
 *     XDMF 3 readers (the default for .xdmf).
 *   - Invalid arguments (negative or repeated ids in a frame, fragment ids
 *     that are not the next ones, a parent that is not an earlier fragment,
 *     an observable name that is empty or holds '/') give CF_ERR_OUTPUT and
 *     write nothing.  HDF5's own error printing is off during every call
 *     (and restored after it); every HDF5 failure gives CF_ERR_OUTPUT with a
 *     message naming the file, what failed and HDF5's innermost reason.
 */
#ifndef COHFRAC_H5_OUTPUT_H
#define COHFRAC_H5_OUTPUT_H

#include "cohfrac/error.h"
#include "cohfrac/world.h"

typedef struct cf_h5 cf_h5;

/* One fragment's state in a frame. */
typedef struct cf_frag_frame {
    int id;                  /* fragment id = column */
    int mode;                /* 0 rigid, 1 fracture */
    double com[3];           /* m */
    double quat[4];          /* w,x,y,z */
    double v[3];             /* m/s */
    double w[3];             /* rad/s */
} cf_frag_frame;

/* 1 when `path` is an HDF5 file that cohfrac wrote (root attribute
 * creator = "cohfrac"), 0 otherwise (absent, not HDF5, another writer's). */
int cf_h5_is_output(const char *path);

/* Create (truncate) `path` and write the root attributes and the scene text.
 * The parent directory is created if missing.  Also writes `<path minus .h5>.xdmf`
 * on close.  Error CF_ERR_OUTPUT names the path and the HDF5 reason; on any
 * error *out is NULL. */
cf_status cf_h5_open(const char *path, const char *scene_name, const char *scene_text,
                     cf_h5 **out, cf_error *err);

/* Append one frame holding `n` alive fragments (any order). Flushes. */
cf_status cf_h5_write_frame(cf_h5 *h, long step, double time, const cf_frag_frame *frags,
                            int n, cf_error *err);

/* Append fragment records (ids must be new and consecutive from 0). */
cf_status cf_h5_add_fragments(cf_h5 *h, const cf_frag_info *info, int n, cf_error *err);

/* Append a scalar observable sample, creating /observables/<name> on first use
 * with `unit` as its value's unit attribute (NULL: dimensionless).
 * Cheap (open datasets are kept); reaches the disk with the next flush. */
cf_status cf_h5_write_observable(cf_h5 *h, const char *name, const char *unit, long step,
                                 double time, double value, cf_error *err);

/* Write /parameters/<name>: `n` float64 values (a scalar when n = 1) with
 * a `unit` attribute (none when unit is NULL), once per name.  What a reader
 * needs beyond the scene text, e.g. the initial state's bounds.  A name that
 * is empty, holds '/' or exists already gives CF_ERR_OUTPUT. */
cf_status cf_h5_write_parameter(cf_h5 *h, const char *name, const double *v, int n,
                                const char *unit, cf_error *err);

/* Append the `n` tets of fracture-mode fragments at one frame to
 * /fracture_mode (created on the first call, even with n = 0): tet [n]
 * (input numbering, as /mesh/rest/tets), corners [n][4][3] m (deformed,
 * cf_world_tet_positions), stress [n][6] Pa (Cauchy, xx yy zz yz xz xy),
 * damage [n] (0-1, cf_world_fracture_tets) and the frame's time, s, on every
 * row.  Reaches the disk with the next flush (the frame's). */
cf_status cf_h5_add_fracture_tets(cf_h5 *h, int n, const int *tet, const double *corners,
                                  const double *stress, const double *damage, double time,
                                  cf_error *err);

/* Append `n` rows to /cracks (created on the first call, even with n = 0).
 * Reaches the disk with the next flush (the frame's). */
cf_status cf_h5_add_cracks(cf_h5 *h, const cf_crack_row *rows, int n, cf_error *err);

/* Geometry (docs/output.md).  The rest mesh once: /mesh/rest/nodes[n][3]
 * (m) and /mesh/rest/tets[nt][4] (0-based node indices, input tet order). */
cf_status cf_h5_write_rest_mesh(cf_h5 *h, const double *X, int n, const int *tets, int nt,
                                cf_error *err);

/* /visual: a finer surface that rides on the rest tets, for drawing
 * (src/io/visual.h): vertices [nv][3] (m, placed as /mesh/rest/nodes),
 * triangles [nt][3] and tet [nt] (the rest tet each triangle moves with).
 * Errors: CF_ERR_OUTPUT. */
cf_status cf_h5_write_visual(cf_h5 *h, const double *V, int nv, const int *tri, const int *tet,
                             int nt, cf_error *err);

/* Append m boundary triangles ([m][3] indices into /mesh/rest/nodes) and
 * their crack flags to /surfaces; *first gets the row of the first (a
 * fragment's surface_first).  Reaches the disk with the next flush. */
cf_status cf_h5_add_surfaces(cf_h5 *h, const int *tris, const int *crack, int m, int *first,
                             cf_error *err);

/* Append the fragment of every tet (input order, [nt]) at a topology
 * change to /mesh/tet_fragment/{step, time, value[K][nt]}. */
cf_status cf_h5_write_tet_fragments(cf_h5 *h, long step, double time, const int *map, int nt,
                                    cf_error *err);

/* Append one hand-off record. */
cf_status cf_h5_add_handoff(cf_h5 *h, const cf_handoff_record *r, cf_error *err);

/* Bytes of HDF5's metadata cache for the file now (H5Fget_mdc_size), for
 * the run summary's memory accounting; 0 for NULL. */
unsigned long long cf_h5_memory(const cf_h5 *h);

/* Flush, write /xdmf/polyvertex and the XDMF sidecar, close.  The handle is
 * freed even when an error is returned.  Safe on NULL. */
cf_status cf_h5_close(cf_h5 *h, cf_error *err);

#endif
