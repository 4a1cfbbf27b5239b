/* cohfrac — the engine's Tet4 mesh type: what a body is made of.
 *
 * A cf_mesh is a linear tetrahedral (Tet4) mesh in SI units (metres).  Tets
 * are positively oriented: det[x1-x0, x2-x0, x3-x0] > 0 (docs/physics.md
 * §2).  The engine only takes meshes; loading, meshing and repairing them is
 * mesh preparation (cohfrac/mesh.h), which a program may replace by filling
 * a cf_mesh itself.
 */
#ifndef COHFRAC_TETMESH_H
#define COHFRAC_TETMESH_H

/* A named node set (a Gmsh physical group, any dimension): the nodes of
 * every element of the group, 0-based, ascending, no repeats.  A group named
 * in $PhysicalNames but without elements has n_nodes = 0, nodes = NULL.
 * Names longer than 63 characters are cut. */
typedef struct cf_mesh_group {
    char name[64];
    int dim;      /* 0 point, 1 curve, 2 surface, 3 volume */
    int n_nodes;
    int *nodes;   /* [n_nodes] */
} cf_mesh_group;

typedef struct cf_mesh {
    int n_nodes;
    int n_tets;
    double *x; /* [n_nodes][3] node positions, m */
    int *tets; /* [n_tets][4] 0-based node indices */
    int n_groups;
    cf_mesh_group *groups; /* [n_groups] named node sets (Gmsh files only) */
} cf_mesh;

/* Release the arrays and zero `m` (NULL or an empty mesh is fine). */
void cf_mesh_free(cf_mesh *m);

/* The boundary faces of a set of Tet4: the faces that no other tet of the
 * set uses (same three nodes), in the vertex order of CF_TET_FACE (outward
 * for a positive tet).  tet_nodes [.][4] node indices; list [nt] the tets
 * of the set, or NULL for tets 0..nt-1; faces gets [n][3] node indices and
 * needs room for 4 nt faces.  Returns n, or -1 out of memory. */
int cf_boundary_faces(const int *tet_nodes, const int *list, int nt, int *faces);

#endif
