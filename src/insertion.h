/* Extrinsic cohesive insertion and node duplication (DESIGN §3.3, §3.4). */
#ifndef COHFRAC_INSERTION_H
#define COHFRAC_INSERTION_H

#include "solid.h"

/* Growable list of node indices (a fracture-mode fragment's nodes). */
typedef struct cf_int_list {
    int n, cap;
    int *v;
} cf_int_list;

int cf_int_list_push(cf_int_list *l, int value); /* 0, or -1 out of memory */

/* Insertion criterion on the interior, uncracked facets of `tets` (in list
 * order, each facet seen from its lower tet), from the stresses s->sigma:
 * - CF_CRITERION_TRACTION: with the mean stress of the two tets and the
 *   current facet normal n, t = sigma n, sigma_n = n.t, tau = |t - sigma_n n|;
 *   the facet qualifies when sigma_n >= sigma_max or tau >= tau_max.
 * - CF_CRITERION_SOURCE (the source's rule, §6.6.2): the volume-averaged
 *   nodal maximum principal stress is >= 0.9 sigma_max at all three nodes.
 * Writes qualifying facet indices into `out` (capacity 4*nt) and returns
 * their number, or -1 when out of memory. */
int cf_insertion_candidates(const cf_solid *s, const int *tets, int nt, cf_criterion rule,
                            int *out);

/* Crack facet f: mark it, duplicate the nodes whose star it disconnects
 * (new copies are appended to `nodes`), re-lump the masses of the affected
 * nodes, and add a cohesive element.  Returns 0, or -1 when out of memory. */
int cf_crack_facet(cf_solid *s, int f, cf_int_list *nodes);

#endif
