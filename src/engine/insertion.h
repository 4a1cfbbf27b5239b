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

void cf_ints_sort(int *v, int n); /* v[0..n) ascending */

/* The tet-level bound of `rule` for cf_tet4_forces: s1 = 0.9 sigma_max
 * (source) or sigma_max (traction), tau = tau_max (traction only), each
 * times the weakest facet's strength factor (s->strength_min).  Both
 * rules need a principal or shear stress at or above these in at least one
 * tet next to the facet (the largest eigenvalue of a volume average is at
 * most the largest of the averaged ones), so facets away from hot tets are
 * never looked at. */
cf_stress_check cf_insertion_bound(const cf_solid *s, cf_criterion rule);

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
 *   (computed only at nodes of hot tets, in s->nodal, s->node_mark).
 * Writes the qualifying facet indices into `out` (emptied first) and
 * returns their number, or -1 when out of memory. */
int cf_insertion_candidates(cf_solid *s, const int *tets, int nt, cf_criterion rule, int n_hot,
                            cf_int_list *out);

/* Crack facet f: mark it, duplicate the nodes whose star it disconnects
 * (new copies are appended to `nodes`; each split node and its copies to
 * `touched`, for cf_bars_patch), re-lump the masses of the affected nodes,
 * and add a cohesive element.  Returns 0, or -1 when out of memory. */
int cf_crack_facet(cf_solid *s, int f, cf_int_list *nodes, cf_int_list *touched);

#endif
