/* The table of functions a cohesive law provides, so that a second law is
 * one file: its parameters (a struct of its own, at most
 * CF_LAW_PARAMS_MAX doubles) from the material, its scaling to a facet of
 * strength w sigma_max, its envelope under monotonic loading, and its
 * traction with history for one node pair.  The element code
 * (cohesive.c) calls nothing else.  Openings in m, tractions in Pa. */
#ifndef COHFRAC_COHESIVE_LAW_H
#define COHFRAC_COHESIVE_LAW_H

#include "cohfrac/types.h"

#include <stddef.h>

#define CF_LAW_PARAMS_MAX 16

typedef struct cf_cohesive_law {
    const char *name;
    size_t params_size; /* bytes, at most CF_LAW_PARAMS_MAX doubles */
    void (*init)(void *params, const cf_material *m);
    /* Strengths times w, fracture energies kept (material.strength). */
    void (*scale)(void *params, double w);
    /* Tractions at normal opening dn >= 0 and tangential opening dt >= 0
     * under monotonic loading. */
    void (*envelope)(const void *params, double dn, double dt, double *Tn, double *Tt);
    /* Traction with history for one node pair: updates the largest openings
     * so far and `failed`; a negative dn counts as zero opening (the element
     * code adds compression).  A failed pair carries no traction for good:
     * the element code does not call it again for that pair. */
    void (*traction)(const void *params, double dn, double dt, double *dn_max, double *dt_max,
                     unsigned char *failed, double *Tn, double *Tt);
} cf_cohesive_law;

/* The laws there are: one per file src/engine/cohesive_<law>.c, which
 * defines cf_law_<law>; CMake lists the files in CF_COHESIVE_LAWS, PPR
 * first.  material.cohesive_law picks one by its index in that list. */
#include "cohesive_laws.h"
#define CF_LAW_DECLARE_(law) extern const cf_cohesive_law cf_law_##law;
CF_COHESIVE_LAWS(CF_LAW_DECLARE_)
#undef CF_LAW_DECLARE_

/* The law of index i in CF_COHESIVE_LAWS (material.cohesive_law), NULL
 * outside it; its names in order, NULL after the last. */
const cf_cohesive_law *cf_cohesive_law_of(int i);
extern const char *const cf_cohesive_law_names[];

#endif
