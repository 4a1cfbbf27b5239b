/* cohfrac — hollow bodies: keep the tets within a few layers of the surface.
 *
 * The boundary of a Tet4 mesh is the set of faces used by exactly one tet;
 * its nodes are the boundary nodes.  Layer 1 is every tet with a boundary
 * node (which includes every tet with a boundary face); layer k+1 adds every
 * tet that shares a node with a tet of layers 1..k.  The other tets are
 * dropped, then the nodes no kept tet uses, and the rest are renumbered in
 * their old order (so node groups stay ascending).
 */
#include "cohfrac/mesh.h"
#include "cohfrac/tetmesh.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>

/* on_boundary[n] = 1 for every node of a face used by exactly one tet. */
static int mark_boundary_nodes(const cf_mesh *m, unsigned char *on_boundary)
{
    int *faces = malloc((size_t)(m->n_tets > 0 ? m->n_tets : 1) * 12 * sizeof(int));
    int n = faces ? cf_boundary_faces(m->tets, NULL, m->n_tets, faces) : -1;
    for (int i = 0; i < 3 * n; i++)
        on_boundary[faces[i]] = 1;
    free(faces);
    return n < 0 ? -1 : 0;
}

cf_status cf_mesh_hollow(cf_mesh *m, int layers, cf_error *err)
{
    unsigned char *marked = NULL, *keep = NULL;
    int *new_index = NULL, *tets = NULL;
    double *x = NULL;
    int n_keep = 0, n_nodes = 0;
    cf_status st = CF_OK;

    if (layers < 1)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "hollow: layers must be >= 1, got %d (0 keeps the solid)", layers);
    if (m->n_tets <= 0)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "hollow: the mesh has no tets, nothing would be kept");

    marked = calloc((size_t)m->n_nodes, 1);
    keep = calloc((size_t)m->n_tets, 1);
    new_index = malloc((size_t)m->n_nodes * sizeof *new_index);
    if (!marked || !keep || !new_index || mark_boundary_nodes(m, marked) != 0) {
        st = cf_error_set(err, CF_ERR_NOMEM, "hollow: out of memory for %d tets", m->n_tets);
        goto done;
    }

    /* Layer 1: tets with a boundary node; each further layer: tets with a
     * node of a tet kept so far. */
    for (int layer = 1; layer <= layers; layer++) {
        int grew = 0;
        if (layer > 1)
            for (int t = 0; t < m->n_tets; t++)
                if (keep[t])
                    for (int j = 0; j < 4; j++)
                        marked[m->tets[4 * t + j]] = 1;
        for (int t = 0; t < m->n_tets; t++) {
            if (keep[t])
                continue;
            for (int j = 0; j < 4; j++)
                if (marked[m->tets[4 * t + j]]) {
                    keep[t] = 1;
                    n_keep++;
                    grew = 1;
                    break;
                }
        }
        if (!grew || n_keep == m->n_tets)
            break;
    }
    if (n_keep == 0) {
        st = cf_error_set(err, CF_ERR_SCENE_VALUE,
                          "hollow: no tet within %d layer%s of the boundary, nothing would be kept",
                          layers, layers == 1 ? "" : "s");
        goto done;
    }
    if (n_keep == m->n_tets) {
        st = cf_error_set(err, CF_ERR_SCENE_VALUE,
                          "hollow: all %d tets lie within %d layer%s of the boundary, nothing "
                          "would be removed (use fewer layers, a finer mesh, or 0 for a solid)",
                          m->n_tets, layers, layers == 1 ? "" : "s");
        goto done;
    }

    /* Nodes the kept tets use, renumbered in their old order. */
    memset(marked, 0, (size_t)m->n_nodes);
    for (int t = 0; t < m->n_tets; t++)
        if (keep[t])
            for (int j = 0; j < 4; j++)
                marked[m->tets[4 * t + j]] = 1;
    for (int i = 0; i < m->n_nodes; i++)
        new_index[i] = marked[i] ? n_nodes++ : -1;

    x = malloc((size_t)n_nodes * 3 * sizeof *x);
    tets = malloc((size_t)n_keep * 4 * sizeof *tets);
    if (!x || !tets) {
        st = cf_error_set(err, CF_ERR_NOMEM, "hollow: out of memory for %d nodes", n_nodes);
        goto done;
    }
    for (int i = 0; i < m->n_nodes; i++)
        if (new_index[i] >= 0)
            memcpy(&x[3 * (size_t)new_index[i]], &m->x[3 * (size_t)i], 3 * sizeof *x);
    for (int t = 0, k = 0; t < m->n_tets; t++)
        if (keep[t]) {
            for (int j = 0; j < 4; j++)
                tets[4 * (size_t)k + (size_t)j] = new_index[m->tets[4 * t + j]];
            k++;
        }

    /* Groups: drop the removed nodes; the map is increasing, so each list
     * stays ascending.  Done in place (a list only shrinks). */
    for (int g = 0; g < m->n_groups; g++) {
        cf_mesh_group *grp = &m->groups[g];
        int n = 0;
        for (int i = 0; i < grp->n_nodes; i++)
            if (new_index[grp->nodes[i]] >= 0)
                grp->nodes[n++] = new_index[grp->nodes[i]];
        grp->n_nodes = n;
        if (n == 0) {
            free(grp->nodes);
            grp->nodes = NULL;
        }
    }

    free(m->x);
    free(m->tets);
    m->x = x;
    m->tets = tets;
    m->n_nodes = n_nodes;
    m->n_tets = n_keep;
    x = NULL;
    tets = NULL;

done:
    free(x);
    free(tets);
    free(marked);
    free(keep);
    free(new_index);
    return st;
}
