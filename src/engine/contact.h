/* Contact of fracture-mode nodes with rigid fragments (docs/physics.md §9): each node
 * is a point pushed out of the convex hulls of the Bullet bodies near its
 * fragment (penetration by Minkowski portal refinement in libccd), and the impulse
 * that push gives the node goes back to the body, so linear momentum is
 * conserved across the coupling (contact.c).
 *
 * Contact between fracture-mode fragments of different bodies
 * (contact_bodies.c): node-to-surface, each node of one fragment against
 * the deforming boundary of the other, both ways. */
#ifndef COHFRAC_CONTACT_H
#define COHFRAC_CONTACT_H

#include "arena.h"
#include "fragment.h"

typedef struct cff_mesh cff_mesh;

/* Whether boxes [lo0, hi0] and [lo1, hi1] (m) overlap, touching included;
 * lo = hi is a point. */
int cf_boxes_overlap(const double lo0[3], const double hi0[3], const double lo1[3],
                     const double hi1[3]);

/* Convex hulls of the rigid bodies near one fragment, in world coordinates
 * at the bodies' poses after the rigid step (they stay put while the
 * fragment is sub-cycled). */
typedef struct cf_hull_set {
    int n;             /* hulls */
    double *pts;       /* [start[n]][3] world vertices, m */
    int *start;        /* [n + 1] */
    double *lo, *hi;   /* [n][3] bounding box of each hull, m */
    double *center;    /* [n][3] centroid of each hull's vertices, m */
    int *frag;         /* [n] fragment owning the hull */
    double tolerance;  /* m, MPR tolerance */
} cf_hull_set;

/* Per-node impulse bookkeeping of one fragment during a rigid step. */
typedef struct cf_node_impulses {
    int n;             /* nodes of the fragment */
    int *frag;         /* [n] body fragment the node pushed, -1 none */
    double *J;         /* [n][3] impulse given to the node, N s */
    double *point;     /* [n][3] last contact point, m */
} cf_node_impulses;

/* The boundary of a fracture-mode fragment as a deforming triangle mesh:
 * the faces of its tets used by one of its tets only (crack faces opened by
 * node duplication included), outward, in an FCL hierarchy refitted to the
 * nodes' current positions before every query pass. */
typedef struct cf_frag_surface {
    cff_mesh *mesh;    /* NULL until first needed */
    int *node;         /* [nv] solid node of each surface vertex */
    int *slot;         /* [nv] its index in the fragment's node list */
    int *tri;          /* [ntri][3] surface vertices, counter-clockwise from outside */
    double *xv;        /* [nv][3] the vertices' current positions, m (refit scratch) */
    int nv, ntri;
    int built_nodes;   /* the fragment's node count when built: node
                          duplication changes the surface */
} cf_frag_surface;

/* What the contact of one fragment keeps between its steps, kept by the
 * contact module in a table keyed by fragment (cf_contact_caches), not in
 * the fragment record: the impulses its nodes gave rigid bodies, the
 * hulls of the rigid bodies near it, its boundary. */
typedef struct cf_contact_cache {
    cf_node_impulses push; /* fracture mode: impulses its nodes gave bodies */
    cf_hull_set near;      /* fracture mode: hulls of the rigid bodies near it
                              this rigid step */
    cf_frag_surface surface; /* fracture mode: its boundary, for contact with
                              other bodies' fragments */
} cf_contact_cache;

/* The table: v[0..cap), zeroed when grown. */
typedef struct cf_contact_caches {
    cf_contact_cache *v;
    int cap;
} cf_contact_caches;

/* Room for fragments 0..n-1 (new entries empty; pointers into the table do
 * not survive the call).  Returns 0, or -1 out of memory. */
int cf_contact_caches_reserve(cf_contact_caches *c, int n);

/* Frees what fragment fi's entry holds and leaves it empty. */
void cf_contact_cache_clear(cf_contact_caches *c, int fi);

/* Frees the table and every entry. */
void cf_contact_caches_free(cf_contact_caches *c);

/* What the contact stages read and write: the fragment table frag[0..n_frag)
 * with its caches, the solid and the Bullet world (NULL for the pbd rigid
 * backend). */
typedef struct cf_contact_ctx {
    cf_fragment *frag;
    cf_contact_cache *cache; /* [n_frag] */
    int n_frag;
    cf_solid *solid;
    cfb_world *bullet;
    cf_arena *arena;         /* the step's scratch (arena.h) */
} cf_contact_ctx;

/* The world box of every fragment's Bullet body, once per rigid step:
 * boxes[n_frag][6] = lo, hi (m); an empty box for fragments without a
 * rigid body. */
void cf_body_boxes(const cf_contact_ctx *c, double *boxes);

/* Hulls of every rigid Bullet fragment whose box (from cf_body_boxes)
 * overlaps fragment fi's node box grown by `pad` m.  Returns 0, or -1 out
 * of memory. */
int cf_hull_set_gather(const cf_contact_ctx *c, int fi, double pad, const double *boxes,
                       cf_hull_set *hs);
void cf_hull_set_free(cf_hull_set *hs);

/* Push the predicted position p of a node at x out of every hull of hs
 * that contains p but not x, onto the hull face it crossed.  A
 * node already inside at the start of the step (a hull bridging a concave
 * crack face over its neighbour) is left alone rather than thrown out in
 * one step.  Returns the index of the last hull that pushed it, or -1. */
int cf_hull_set_project(const cf_hull_set *hs, const double x[3], double p[3]);

/* Make room for n nodes (new ones with no impulse).  0, or -1 out of memory. */
int cf_node_impulses_reserve(cf_node_impulses *ni, int n);

/* Node i gave impulse -dJ (N s) to body fragment `frag` at `point`.  A node
 * that pushes a second body in one rigid step hands it the whole sum. */
void cf_node_impulses_add(cf_node_impulses *ni, int i, int frag, const double dJ[3],
                          const double point[3]);
void cf_node_impulses_free(cf_node_impulses *ni);

/* Apply minus each node's accumulated impulse to the body it pushed, at its
 * contact point, add its size to the body fragment's `pushed`, and clear the
 * record (nodes[i]: the node id of record i).
 * A body's hull stays where the rigid step left it while the fracture-mode
 * nodes push it for the whole rigid step, as if it were a wall; a light
 * body would take the push of a heavy fragment for the whole step (measured:
 * a 60 g tet sent from 7.8 to 543 m/s).  So the impulses on one body are
 * scaled down together, where needed, until its velocity along their sum
 * is at most (1 + e) V, V the speed of the fastest node that pushed it and
 * e the material's restitution (a collision with a wall moving at V), and
 * the spin they give it holds at most 1/2 M ((1 + e) V)^2 of energy.  The
 * part of a node's impulse its body does not take is taken back from the
 * node's velocity, so that linear momentum is kept; the spin's bound is not
 * given back (angular momentum is not kept where it acts).  The energy the
 * bodies gained goes to *energy (J).  Returns 0, or -1 out of memory
 * (nothing applied). */
int cf_node_impulses_flush(const cf_contact_ctx *c, cf_node_impulses *ni, const int *nodes,
                           double *energy);

void cf_frag_surface_free(cf_frag_surface *fs);

/* Whether fracture-mode fragments of two initial bodies exist, so that
 * cf_body_contact has work: asked once per rigid step (sub-steps change no
 * fragment's mode). */
int cf_body_contact_needed(const cf_contact_ctx *c);

/* Contact between fracture-mode fragments of different initial bodies
 * (fragments of one body do not collide with each other, as in Bullet),
 * after every fracture sub-step of length h (s), with every fragment's
 * step done, in a rigid step for which cf_body_contact_needed holds.  For
 * each pair whose node boxes overlap, every node a of one
 * fragment found behind the other's surface (signed distance d < 0 to its
 * closest point q, on triangle (b0, b1, b2) with barycentric coordinates
 * l) is projected out with the surface, a PBD contact constraint
 * C = |q - x_a| >= 0 along u = (q - x_a)/|q - x_a| (Mueller et al. 2007):
 *   dx_a = w_a s u,  dx_bk = -l_k w_bk s u,  s = |d| / (w_a + sum l_k^2 w_bk),
 * w = 1/m (0 for prescribed nodes); each moved node's velocity changes by
 * dx/h.  The impulses m dx/h sum to zero and act along one line, so linear
 * and angular momentum are conserved to round-off.  The contact is
 * frictionless and perfectly plastic along u.  Limits: node-to-surface
 * only (edge-edge crossings go unseen); a node nearer a crack face of the
 * other fragment than its outer surface is taken as outside.
 * *removed gets the energy the pass removed (J): minus the leapfrog work
 * of its impulses, sum m dv . (v_start + v)/2 over the moved nodes (v_start
 * the velocity at the start of the step), which the position change turns
 * partly into strain energy; so that the energy ledger balances.  Returns
 * 0, or -1 out of memory or on an FCL error (a message in
 * cff_last_error(); "out of memory" is not set there). */
int cf_body_contact(const cf_contact_ctx *c, double h, double *removed);

#endif
