/* The solid: every node, tet, facet and cohesive element of the scene's
 * bodies in one set of arrays (structure of arrays, SI units).
 *
 * Nodes grow by node duplication (docs/physics.md §5); tets never change count but
 * their node indices move to duplicated copies.  `tet0` keeps the original
 * vertex of every slot, so topology questions are asked on the reference
 * mesh.  Face k of a tet is the face opposite its node k, with the vertex
 * order of CF_TET_FACE[k] (outward normal for a positive tet). */
#ifndef COHFRAC_SOLID_H
#define COHFRAC_SOLID_H

#include <stdint.h>
#include "cohfrac/tetmesh.h"
#include "cohfrac/types.h"
#include "crack_grid.h"

extern const int CF_TET_FACE[4][3];

/* Loops over a fragment's nodes run on the threads from this many nodes on
 * (force scatter, bar building, the step's node loops); each node writes
 * only its own entries, so the thread count never changes a result. */
#define CF_NODES_PARALLEL_MIN 2048

/* One extrinsic cohesive element on facet (tet[0], face[0]) | (tet[1], face[1]).
 * Node pair i joins slot[0][i] of tet[0] with slot[1][i] of tet[1]; the
 * nodes are read through the tets so they follow later duplications. */
typedef struct cf_cohesive {
    int tet[2];
    int slot[2][3];
    double dn_max[3], dt_max[3]; /* PPR history: largest openings, m */
    unsigned char failed[3];     /* complete failure per node pair */
    /* Energy of the element (J): work absorbed so far, the trapezoid of each
     * pair's force over the change of its separation (the work the leapfrog
     * does, docs/physics.md §10); dissipated, the largest (work - elastic) so far,
     * elastic = sum of 1/2 T Delta A/3 over its pairs, so that it never
     * falls (unloading on the secant keeps it, the facing switch of the
     * compression penalty and the change of area move the difference into
     * stored); stored = work - dissipated. */
    double work, stored, dissipated;
    double strength;             /* its facet's strength / sigma_max */
    double last[3][2];           /* normal opening dn (m) and traction Tn (Pa) of each
                                    pair at the last evaluation */
    double f_last[3][3];         /* each pair's force on its side-A node at the last
                                    evaluation (minus it on side B), N */
    double d_last[3][3];         /* each pair's separation x_B - x_A then, m */
    unsigned char started[3];    /* `last`, f_last, d_last hold an evaluation of the pair */
} cf_cohesive;

/* Whether every node pair of ce has failed: a free crack face, which
 * joins its two tets no more and carries only the compression penalty. */
static inline int cf_cohesive_all_failed(const cf_cohesive *ce)
{
    return ce->failed[0] && ce->failed[1] && ce->failed[2];
}

typedef struct cf_solid {
    cf_material mat;
    double lambda, mu;        /* Lamé, Pa */
    double crush_k, crush_beta; /* crushing yield q <= k + beta p (Pa, -; p the pressure,
                                   positive in compression): Drucker-Prager through the
                                   uniaxial compressive strength, docs/physics.md §2.1 */

    int n_nodes, cap_nodes;
    double *X;                /* [n][3] rest positions, m */
    double *x, *v, *f;        /* [n][3] position m, velocity m/s, force N */
    double *p;                /* [n][4] PBD prediction m (x y z) and, while the
                                 fragment is projected, 1/m in kg^-1 (slot 3): one
                                 32-byte row per node, 64-byte aligned, so that the
                                 bar sweep loads four bars' ends as whole rows */
    double *m;                /* [n] lumped mass, kg */
    double *vcap;             /* [n] scratch of the projection: the fastest bar
                                 neighbour's predicted speed, m/s */
    double *speed;            /* [n] scratch of the projection: |v| of the projected
                                 fragment's nodes, m/s (one square root per node
                                 instead of two per bar) */
    int *origin;              /* [n] original vertex of each copy */
    int *bc;                  /* [n] boundary condition of the node (scene index), -1 none */

    int n_verts0;             /* vertices of the input meshes */
    int n_tets;
    int *tet;                 /* [nt][4] current node of each slot */
    int *tet0;                /* [nt][4] original vertex of each slot */
    double *Dm_inv;           /* [nt][9] inverse rest edge matrix, 1/m */
    double *vol;              /* [nt] rest volume, m^3 */
    double *rq;               /* [nt][4] corotational rotation (warm start) */
    double *sigma;            /* [nt][9] Cauchy stress at the last check, Pa (fracture state) */
    unsigned char *hot;       /* [nt] may qualify for insertion at the last check
                                 (cf_stress_check; fracture state) */
    unsigned char *qualify;   /* [nt] scratch of the criterion: bit k, face k qualifies;
                                 all zero between checks (fracture state) */
    double *tf;               /* [nt][12] internal force on each slot, N */
    double *tw;               /* [nt] strain energy at the last force pass, J */
    double *ep;               /* [nt][6] plastic strain in the element frame (xx yy zz
                                 xy xz yz), only with crushing (mat.compressive_strength
                                 > 0), else NULL */
    double *wp;               /* [nt] plastic work dissipated since t = 0, J (crushing) */
    unsigned char *crushed;   /* [nt] crushed (cf_crush_tets): no stress, no force; only
                                 with mat.crushing_strain > 0, else NULL */
    int *tet_frag;            /* [nt] fragment id */

    int n_facets;
    int *facet;               /* [nf][4] tetA, faceA, tetB, faceB (tetB = -1 on the boundary) */
    int *tet_facet;           /* [nt][4] facet of face k */
    unsigned char *cracked;   /* [nf] */
    unsigned char *tet_open;  /* [nt] bit k: face k of the tet is an interior facet it
                                 owns (facet[4 f] == t), not cracked, and a candidate:
                                 the faces the criterion asks of it, without reading
                                 the facets (kept by cf_solid_update_open) */
    unsigned char *edge_cracks; /* [nt][6] the cracked facets holding each edge of the
                                 tet (corners 01 02 03 12 13 23): an edge's count,
                                 kept in every tet around it */
    double *crack_time;       /* [nf] s, when each cracked facet was inserted */
    unsigned *vert_cracks;    /* [n_verts0] times a facet on each original vertex was
                                 marked cracked (or unmarked): a version of the cracks
                                 around it */
    uint64_t *contact_key;    /* [nf] the growth rule's memo of how each facet meets
                                 the cracks: its vertices' versions (summed, + 1) when
                                 last found, 0 never */
    unsigned char *contact_kind; /* [nf] what was found (front, touch) */
    double *contact_until;    /* [nf] s, until when it holds */
    double nucleation_radius; /* m (material.nucleation_radius, l_ch when 0) */
    cf_crack_grid cracks;     /* rest centroids of the cracked facets, by place
                                 (crack_growth "fronts") */
    unsigned char *candidate; /* [nf] may crack (NULL: every interior facet) */
    float *strength;          /* [nf] facet strength / sigma_max (material.strength;
                                 NULL: 1 everywhere) */
    double strength_min;      /* the smallest of them (1 when uniform) */
    double strength_max;      /* the largest (1 when uniform) */
    float *vert_wmin;         /* [n_verts0] the smallest strength of the interior
                                 facets on each original vertex (INFINITY where
                                 none; NULL when uniform): below its threshold a
                                 nodal value passes no facet there */
    double front_K;           /* Pa m^1/2: K_IC = sqrt(E G_I) of a front's threshold
                                 (solver.front_threshold "toughness"), 0 off */
    int *nucleus;             /* [nf] with solver.front_threshold "crack": the facet
                                 that nucleated the crack a cracked facet belongs to
                                 (itself when it nucleated one); NULL otherwise */
    double front_floor_min;   /* Pa, with front_K: the lowest front threshold
                                 K_IC / sqrt(2 pi r) of any vertex ahead of any
                                 interior facet (INFINITY when off) */
    float *vert_front_active; /* [n_verts0] Pa, with front_K: the lowest front threshold
                                 over the interior facets with the vertex ahead of an
                                 edge a cracked facet holds (ever; INFINITY where none),
                                 the floor of its nodal value with the strength's
                                 (cf_insertion_init_front_floors); until then over
                                 every interior facet with the vertex ahead */
    unsigned char *vert_front_near; /* [n_verts0] with front_K: 1 where the vertex shares
                                 a tet with a vertex of a cracked facet (ever), the
                                 only vertices a front can have ahead; elsewhere the
                                 front floor does not apply (insertion.c) */
    float *tet_floor;         /* [nt] Pa, with front_K: a tet's own hot bound where no
                                 vertex of it is near a crack, the lowest strength
                                 threshold at its vertices (rounded down); 0 where one
                                 is, and before cf_insertion_init_front_floors */
    unsigned char *node_mark; /* [cap_nodes] scratch of the insertion check (the
                                 nodes of hot tets) and of a split (the nodes
                                 taken); all 0 between uses (fracture state) */
    double *nodal;            /* [cap_nodes] the source criterion's nodal values, Pa
                                 (fracture state) */
    double *nodal_stress;     /* [cap_nodes][6] the volume-mean stress behind each
                                 nodal value (xx yy zz xy xz yz), Pa */
    unsigned *nodal_check;    /* [cap_nodes] the check that last valued each node */
    unsigned check_stamp;     /* the last check's number (cf_insertion_candidates) */
    unsigned *vert_check;     /* [n_verts0] the check that last valued a copy of each
                                 original vertex */
    int *vert_node;           /* [n_verts0] that copy: the others of the check take
                                 its values (nodal_values) */
    int *piece;               /* [nt] scratch of the small-piece search: tets reached */
    unsigned *piece_mark;     /* [nt] the search's stamp of each tet reached */
    unsigned piece_stamp;     /* the last stamp used */
    int *vt_start, *vt_slot;  /* original vertex -> its slots 4 t + j in the tets that
                                 hold it (CSR, ascending t) */

    int n_coh, cap_coh;
    cf_cohesive *coh;
    double (*coh_fric)[3][3]; /* with material.crack_friction > 0, [cap_coh]: each element's
                                 pairs' Coulomb friction tractions while their faces are
                                 pressed together, Pa, in the sense of the tangential
                                 separation they resist (cohesive.h); else NULL */

    double dt_cfl;            /* s, docs/physics.md §3 */
    /* Mass scaling of the tets that set the step (docs/physics.md §3.2;
     * cf_solid_scale_mass):
     * [nt] each tet's density over the material's (NULL without scaling);
     * how many are scaled, the largest scale, and the mass they add and
     * the solid's whole mass with it, kg. */
    double *mass_scale;
    int n_mass_scaled;
    double mass_scale_max, mass_added, mass_total;
    /* Linear bulk viscosity (solver.bulk_viscosity, docs/physics.md §2.3;
     * NULL without): [nt] each tet's volumetric viscosity b1 rho_t c_t h_t,
     * Pa s; its volumetric strain rate at the last force pass, 1/s (0 in
     * rigid mode); the work the viscosity has taken from it, J. */
    double *bv_eta, *bv_rate, *bv_work;
} cf_solid;

/* Mass of tet t, kg: rho V, times its mass scale. */
static inline double cf_tet_mass(const cf_solid *s, int t)
{
    return s->mat.rho * s->vol[t] * (s->mass_scale ? s->mass_scale[t] : 1.0);
}

/* Build the solid from meshes already placed in the world frame.
 * `tet_body` ([nt]) gives each tet's initial fragment id.
 * Errors: CF_ERR_MESH_INVERTED (tet index), CF_ERR_NOMEM. */
cf_status cf_solid_init(cf_solid *s, const cf_mesh *mesh, const cf_material *mat,
                        const int *tet_body, cf_error *err);
void cf_solid_free(cf_solid *s);

/* Mass scaling (docs/physics.md §3.2): every tet whose stable
 * step h / c_d lies below `floor` times the median tet's gets the density
 * that raises it to that, rho (floor dt_median / dt_t)^2, and its lumped
 * masses grow by as much; dt_cfl becomes the smallest step after scaling.
 * floor in (0, 1]; 0 does nothing.  Errors: CF_ERR_NOMEM. */
cf_status cf_solid_scale_mass(cf_solid *s, double floor, cf_error *err);

/* Linear bulk viscosity (docs/physics.md §2.3): each tet's volumetric
 * viscosity b1 rho_t c_t h_t (Pa s), rho_t its density (mass scaling
 * included), c_t its dilatational wave speed, h_t = 6 V / (face area) its
 * rest length of the stable step (§3).  After cf_solid_scale_mass.
 * b1 > 0 (dimensionless, the fraction of critical damping of the
 * highest dilatational mode).  Errors: CF_ERR_NOMEM. */
cf_status cf_solid_init_bulk_viscosity(cf_solid *s, double b1, cf_error *err);

/* The facets (interior and boundary faces), each tet face's facet, the
 * crack flags and the stress of the checks: the fracture state, built only for a scene that may insert
 * cohesive elements (criterion other than "none").  Errors: CF_ERR_NOMEM. */
cf_status cf_solid_init_facets(cf_solid *s, cf_error *err);

/* Facet f's bit in s->tet_open, from what it is now: set where it is
 * interior, not cracked and a candidate (s->candidate NULL: every one).
 * Whoever changes s->cracked or s->candidate calls it. */
void cf_solid_update_open(cf_solid *s, int f);

/* A crack front's threshold from the toughness (solver.front_threshold
 * "toughness" or "crack", docs/physics.md §5.1): s->front_K = K_IC =
 * sqrt(E G_I) (Pa m^1/2), and each original vertex's lowest threshold as
 * the vertex ahead of a front (s->vert_front_active, their least
 * s->front_floor_min): the check's floors as if every front were there
 * (cf_insertion_init_front_floors sets them from the cracks).  "toughness"
 * (crack = 0): K_IC / sqrt(2 pi r), r (m) the vertex's rest distance from
 * the line of the opposite edge of an interior facet.  "crack" (crack =
 * 1): a penny crack's, cf_front_penny, at most as low as for a crack as
 * wide as the body (its rest bounding box's diagonal); allocates
 * s->nucleus, every facet its own.  After cf_solid_init_facets.  Errors:
 * CF_ERR_NOMEM. */
cf_status cf_solid_init_front_toughness(cf_solid *s, int crack, cf_error *err);

/* The far stress at which a penny crack of radius a is critical, Pa:
 * K_IC sqrt(pi) / (2 sqrt(a)) (K_I = 2 sigma sqrt(a / pi); Tada, Paris and
 * Irwin, The Stress Analysis of Cracks Handbook, 2000), a (m) the rest
 * distance from the centroid of facet `nucleus`, where the crack began,
 * to the midpoint of the front's edge, original vertices e0 and e1.  With
 * s->front_K set. */
double cf_front_penny(const cf_solid *s, int nucleus, int e0, int e1);

/* The field of a crack tip at the toughness, Pa: K_IC / sqrt(2 pi r) at the
 * vertex at corner j of face k of tet t as the vertex ahead of a front, r
 * (m) its rest distance from the line of the face's other two vertices
 * (the front's edge).  With s->front_K set. */
double cf_front_toughness(const cf_solid *s, int t, int k, int j);

/* Crack area, m^2: the rest area of every facet whose cohesive element has
 * failed completely (all three node pairs), one side counted. */
double cf_solid_crack_area(const cf_solid *s);

/* Append a copy of node n (same X, x, v, p; mass 0).  Returns the new index
 * or -1 when out of memory. */
int cf_solid_copy_node(cf_solid *s, int n);

/* F (row-major 3x3): the volume-weighted mean deformation gradient of the
 * tets round original vertex o.  Returns 1, or 0 (F unset) when a crack
 * parts its star (o has more than one copy). */
int cf_solid_star_gradient(const cf_solid *s, int o, double F[9]);

/* Move original vertex o, whose star no crack parts, to rest position
 * `to` (m), as universal meshes move a vertex onto a crack (Rangarajan and
 * Lew, IJNME 98:236, 2014; docs/physics.md §5.1): its current position
 * moves by F (the star's mean gradient, cf_solid_star_gradient) times the
 * same shift, so a uniform strain stays as it was; the star's tets take
 * their new rest shape (Dm_inv, vol), and its nodes their re-lumped
 * masses, each keeping its momentum (the star's volume, and the mass, do
 * not change).  Refused (returns 0, nothing changed) when a tet of the
 * star has a plastic strain (held in its old shape), would invert, or
 * would be lower (twice its inradius) than the step allows (dt_cfl) or
 * than least_h times its own height; 1 when moved. */
int cf_solid_move_vertex(cf_solid *s, int o, const double to[3], const double F[9],
                         double least_h);

#endif
