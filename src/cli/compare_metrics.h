/* cohfrac compare: the metrics of two runs side by side (compare.h gives
 * their definitions), apart from the orchestration that runs and samples
 * them and writes the report (compare.c). */
#ifndef COHFRAC_COMPARE_METRICS_H
#define COHFRAC_COMPARE_METRICS_H

#include "compare.h"
#include "cohfrac/sim.h"

#include <stdint.h>

/* The alive fragments of one run at one sample, with an id -> index map. */
typedef struct snap {
    cf_fragment_state *f;
    int n, cap;
    int *index; /* [max id + 1]: position in f, -1 when not alive */
    int index_cap;
} snap;

typedef struct sample {
    double t;                    /* s */
    double com_dist, orient;     /* m, rad: mass-weighted over matched fragments */
    int nfrag[2];
    double com[2][3];            /* m, whole-body centre of mass per backend */
    double ref[3];               /* m, analytic centre of mass (NaN: none) */
    double ref_err[2];           /* m */
    double ke[2], p[2], l[2];    /* drifts (see compare.h) */
    double axis_angle[2];        /* rad, top's symmetry axis about L, wrapped */
} sample;

/* Everything the reference needs, fixed at t = 0. */
typedef struct reference {
    cf_compare_ref kind;
    double x0[3], v0[3], g[3];   /* m, m/s, m/s^2 */
    /* bounce */
    double n[3], e, t1, t2, x1[3], v1[3]; /* plane normal; restitution; contacts, s;
                                             state just after the first contact */
    /* symmetric top */
    int top;
    double omega_p;              /* rad/s */
    double Lhat[3], u1[3], u2[3];/* L direction and a basis of the plane normal to it */
    double e_sym[3];             /* rest frame */
} reference;

typedef struct totals {
    double M, E, P[3], L[3], com[3];
} totals;

/* Two principal moments agreeing within this (relative) make a symmetric top. */
#define TOP_TOLERANCE 1e-3
#define TWO_PI 6.283185307179586

/* |a - b|, m. */
double cf_cmp_dist(const double a[3], const double b[3]);

/* Angle of q_a^-1 q_b, rad, in [0, pi]. */
double cf_cmp_quat_angle(const double a[4], const double b[4]);

/* partner[i]: index in sb of the fragment of run b holding the most tets
 * of sa's fragment i (-1: none); shared[i]: how many.  keys: scratch
 * [tets]. */
void cf_cmp_match_fragments(const cf_sim *a, const cf_sim *b, const snap *sa, const snap *sb,
                            uint64_t *keys, int *partner, int *shared);

/* Mass, energy (kinetic minus gravity's potential), momenta and centre of
 * mass of a sample's fragments. */
void cf_cmp_sum_totals(const snap *s, const double g[3], totals *o);

/* The heaviest fragment of a sample, or -1 when none. */
int cf_cmp_heaviest(const snap *s);

/* The analytic reference (compare.h) decided from the scene and the state
 * at t = 0 (the Bullet run); its centre of mass at t (returns 0, x NaN,
 * past its validity). */
void cf_cmp_reference_setup(const cf_world_def *sc, cf_sim *sim, const snap *first,
                            reference *r);
int cf_cmp_reference_at(const reference *r, double t, double x[3]);

/* Wrapped angle (rad) of the top's symmetry axis about L. */
double cf_cmp_axis_angle(const reference *r, const cf_fragment_state *f);

/* Least-squares slope of the unwrapped angle series a[0..n) over the
 * samples' times; unwraps a in place. */
double cf_cmp_unwrap_slope(const sample *s, int n, double *a);

#endif
