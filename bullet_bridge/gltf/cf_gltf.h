/* glTF 2.0 binary (.glb) writing through tinygltf (Debian libtinygltf-dev),
 * behind a C interface: one mesh per node (its outer surface and its crack
 * faces as two primitives), numbers in each node's extras, each node
 * animated by translation, rotation and scale keys.
 *
 * Coordinates as given (cohfrac writes SI metres, +z up; glTF's convention
 * is +y up, which the caller applies).  Rotations are unit quaternions in
 * glTF order (x, y, z, w). */
#ifndef COHFRAC_GLTF_H
#define COHFRAC_GLTF_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* One node: its mesh in the node's frame and its animation. */
typedef struct cfg_node {
    const char *name;
    int n_vertices;
    const float *positions;     /* [n_vertices][3] */
    int n_triangles;
    const unsigned *indices;    /* [n_triangles][3], counter-clockwise seen from outside */
    int n_inner;                /* the last n_inner triangles are crack faces: a primitive
                                   of their own with the inner material */
    float color[4];             /* base colour, linear RGBA */
    const char *const *extra_keys; /* [n_extras] names of the node's extras (numbers) */
    const double *extra_values; /* [n_extras] */
    int n_extras;
    int n_keys;                 /* animation keys (0: a still node) */
    const float *times;         /* [n_keys] s, increasing */
    const float *translation;   /* [n_keys][3] */
    const float *rotation;      /* [n_keys][4] x, y, z, w */
    const float *scale;         /* [n_keys] uniform scale (0 hides the node), step keys */
} cfg_node;

/* Write `nodes` as one scene with one animation named `animation` to
 * `path` (.glb: binary, buffers embedded).  Every node's outer surface has
 * its own material (its colour); crack faces share one material named
 * "crack" (rough, plaster white).  Returns 0, or -1 with a reason in
 * err[errlen]. */
int cfg_write_glb(const char *path, const cfg_node *nodes, int n_nodes, const char *animation,
                  char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif
