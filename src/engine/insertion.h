/* Extrinsic cohesive insertion and node duplication (docs/physics.md §5). */
#ifndef COHFRAC_INSERTION_H
#define COHFRAC_INSERTION_H

#include "solid.h"
#include "tet4.h"

/* Growable list of node indices (a fracture-mode fragment's nodes). */
typedef struct cf_int_list {
    int n, cap;
    int *v;
} cf_int_list;

int cf_int_list_push(cf_int_list *l, int value); /* 0, or -1 out of memory */
int cf_int_list_reserve(cf_int_list *l, int n);   /* room for n; 0, or -1 out of memory */

void cf_ints_sort(int *v, int n); /* v[0..n) ascending */

/* The tet-level bound of `rule` for cf_tet4_forces: s1 = 0.9 sigma_max
 * (source) or sigma_max (traction), tau = tau_max (traction only), each
 * times the weakest facet's strength factor (s->strength_min).  Both
 * rules need a principal or shear stress at or above these in at least one
 * tet next to the facet (the largest eigenvalue of a volume average is at
 * most the largest of the averaged ones), so facets away from hot tets are
 * never looked at.  With the toughness's floors (source), s1 is the lowest
 * front floor, and s1_tet = s->tet_floor raises it away from the cracks
 * (cf_insertion_init_front_floors). */
cf_stress_check cf_insertion_bound(const cf_solid *s, cf_criterion rule);

/* How a check chooses among the facets that meet the criterion
 * (docs/physics.md §5.1). */
typedef struct cf_growth {
    cf_crack_growth rule;  /* fronts, or all (the source's) */
    double front_speed;    /* m/s: the fastest a crack front may move (Rayleigh speed) */
    int min_piece_tets;    /* no insertion closes a piece of at most this many tets */
    double min_piece_volume; /* m^3: nor one of less volume (0: no bound) */
    double t;              /* s: now */
    int along_stress;      /* a front takes only a facet whose normal stress reaches its
                              threshold (solver.front_direction "stress"; criterion
                              source) */
    double max_kink;       /* rad: the most a front turns from the cracked facet on its
                              edge (solver.front_max_kink); 0: any */
    int split_plane;       /* a front facet's vertices on its crack are split along its
                              plane at once (solver.front_split "plane") */
    double split_reach;    /* m: the farthest a split's facet lies from the vertex it
                              parts (rest centroid; solver.front_split_reach); 0: any */
    int snap;              /* a front facet's vertex ahead moves onto the plane across
                              the largest principal stress (solver.front_snap "stress") */
} cf_growth;

/* Insertion criterion on the interior, uncracked facets of `tets` (a
 * fragment's whole list, ascending: the facets are found from the stars of
 * the hot tets' nodes, which hold no tet of another fragment; listed in tet
 * order, each facet seen from its lower tet), from the stresses s->sigma
 * and hot flags s->hot of the last check (n_hot of them set; 0 returns at
 * once):
 * - CF_CRITERION_TRACTION: with the mean stress of the two tets and the
 *   current facet normal n, t = sigma n, sigma_n = n.t, tau = |t - sigma_n n|;
 *   the facet qualifies when sigma_n >= sigma_max or tau >= tau_max.
 * (sigma_max and tau_max times the facet's s->strength factor throughout.)
 * - CF_CRITERION_SOURCE (the source's rule, §6.6.2): the volume-averaged
 *   nodal maximum principal stress is >= 0.9 sigma_max at all three nodes
 *   (computed only at nodes of hot tets, in s->nodal, s->node_mark); or,
 *   for a facet that shares an edge with a cracked facet, at its vertex off
 *   that edge, ahead of the crack's front (docs/physics.md §5.1).
 * g is the growth rule the candidates go to (cf_insertion_select): where
 * no rank it reads lies below a vertex's floor, the nodal values are exact
 * from that floor up only; NULL keeps them exact from the weakest facet's
 * threshold up.  The candidates are the same either way.
 * Writes the qualifying facet indices into `out` (emptied first) and
 * returns their number, or -1 when out of memory. */
int cf_insertion_candidates(cf_solid *s, const int *tets, int nt, cf_criterion rule, int n_hot,
                            const cf_growth *g, cf_int_list *out);

/* With a front threshold from the toughness (s->vert_front_active), the
 * floors of the check from the cracks there are (docs/performance.md): a
 * front needs a cracked edge, so a vertex's nodal value need reach only
 * the lowest threshold of the fronts it has ahead now, or its strength's
 * (s->vert_front_active), and a tet with no vertex near a crack is hot
 * only near its vertices' strength (s->tet_floor, cf_stress_check's
 * s1_tet; s->vert_front_near).  cf_mark_cracked keeps them up as facets
 * crack.  The same candidates from fewer nodes; until this is called
 * every vertex takes its lowest front floor and every tet the solid's
 * bound. */
void cf_insertion_init_front_floors(cf_solid *s);

/* Set facet f's cracked flag (1 or 0), and move on the crack version of
 * its three original vertices, which the growth rule's memo keys on, and
 * the crack counts of its edges (s->edge_cracks): every change of a
 * facet's flag goes through here; with the toughness's floors, also those
 * (cf_insertion_init_front_floors). */
void cf_mark_cracked(cf_solid *s, int f, unsigned char cracked);

/* The facets of `cand` (cf_insertion_candidates) that a check inserts,
 * left in `cand` in ascending order; each is marked cracked, with its
 * insertion time.  CF_GROWTH_ALL keeps every one.  CF_GROWTH_FRONTS visits
 * them by falling ratio (how far each exceeds its strength; the lower facet
 * first among equals) and takes a facet when none of its two tets took one
 * before it in this check, when it either shares an edge with a crack facet
 * inserted at least d / front_speed before (a front) or touches no cracked
 * facet and lies farther than s->nucleation_radius / ratio^2 from every
 * one (a nucleus, the largest ratio around it), and when it closes no piece of at
 * most min_piece_tets tets.  With along_stress (criterion source) a front
 * ranks by its normal stress over its threshold instead, and is taken only
 * where that reaches 1 (docs/physics.md §5.1 rule 3).  With split_plane a
 * front also takes, in `cand` (which may grow past its length), the
 * facets that split its vertices on its crack along its plane
 * (solver.front_split "plane").  Returns how many, or
 * -1 out of memory (nothing marked; the crack grid may hold the centroids
 * of facets it refused). */
int cf_insertion_select(cf_solid *s, cf_int_list *cand, cf_criterion rule, const cf_growth *g);

/* Crack facet f: mark it, duplicate the nodes whose star it disconnects
 * (new copies are appended to `nodes`; each split node and its copies to
 * `touched`, for cf_bars_patch), re-lump the masses of the affected nodes,
 * and add a cohesive element.  Returns 0, or -1 when out of memory. */
int cf_crack_facet(cf_solid *s, int f, cf_int_list *nodes, cf_int_list *touched);

/* Crushing (docs/physics.md §2.2): every tet of `tets` not yet crushed
 * whose plastic work has reached crushing_strain * compressive_strength * V
 * is crushed: its uncracked interior facets are marked cracked at time t
 * (s) without cohesive elements and their nodes duplicated as by
 * cf_crack_facet, so that it comes free; its strain energy (s->tw, from
 * this step's force pass) moves to its plastic work, summed into
 * *released (J), and its force on its nodes (s->tf) is zeroed, as
 * cf_tet4_forces will keep it; each is appended to `crushed_tets`.
 * Returns how many tets were crushed (0 without crushing, s->crushed
 * NULL), or -1 when out of memory. */
int cf_crush_tets(cf_solid *s, const int *tets, int nt, double t, cf_int_list *nodes,
                  cf_int_list *touched, cf_int_list *crushed_tets, double *released);

#endif
