/* The run's remaining wall time, from the cost of each mode measured as it
 * goes (docs/performance.md, "The ETA").
 *
 * The run is sampled every tenth of a second or so of wall time (kept a
 * quarter second apart at first, thinned as the history fills).  What is
 * left costs:
 *  - the fracture-mode spell now running: the simulated time it still
 *    runs (cf_eta_spell_left) at the cost per tet and fracture step of the
 *    recent samples, at the tets in fracture mode now;
 *  - the rest of the simulated time at the wall per simulated second
 *    measured outside long spells: the rigid steps, with the short spells
 *    of pieces that land again at the rate they came so far;
 *  - the frames left, at the wall per frame the caller measured.
 * Nothing here reads the world: the caller hands in the samples. */
#ifndef COHFRAC_ETA_H
#define COHFRAC_ETA_H

/* The run at one moment; every field is cumulative from the start. */
typedef struct cf_eta_sample {
    double wall;          /* s of the world's wall time (its stages summed) */
    double t;             /* s simulated */
    double fracture_wall; /* s of it in every stage but the rigid step */
    double tet_steps;     /* tets stepped in fracture mode, summed over steps */
    double cracks;        /* cohesive elements inserted so far */
    double spell;         /* s simulated since the longest spell now running
                             began; 0: no fragment in fracture mode */
} cf_eta_sample;

/* The rule that ends a spell (solver.quiet_steps, quiet_growth,
 * max_fracture_time; docs/physics.md §9). */
typedef struct cf_eta_rule {
    double dt;            /* s, the fracture-mode step */
    double quiet_time;    /* s: quiet_steps x the fracture-mode step */
    double quiet_growth;  /* crack growth over quiet_time that counts as none */
    double max_spell;     /* s, the longest a spell may run */
} cf_eta_rule;

#define CF_ETA_KEEP 128

typedef struct cf_eta {
    cf_eta_rule rule;
    cf_eta_sample s[CF_ETA_KEEP]; /* oldest first */
    int n;
    double spacing;               /* s of wall between the samples kept */
    double rest_wall, rest_t;     /* s of wall, s simulated, outside long spells */
    double pending_wall, pending_t; /* the spell now running's, until it ends */
} cf_eta;

void cf_eta_init(cf_eta *e, const cf_eta_rule *rule);

/* Adds a sample (wall and t not earlier than the last one's); one closer
 * than `spacing` of wall to the last one replaces it. */
void cf_eta_add(cf_eta *e, const cf_eta_sample *s);

/* Simulated time, s, that the spell now running still runs: the geometric
 * mean of as much again as it has run and the time to the end that the
 * crack growth's decay over its last half gives (the rate the quiet rule
 * takes for none, plus the quiet time); as much again where the growth
 * does not decay; as long again as the cracks have been quiet where a
 * landing or a crushing holds it.  At most rule.max_spell less what it
 * ran; 0 with no spell. */
double cf_eta_spell_left(const cf_eta *e);

/* Wall time, s, of the rest of the run: `t_left` s simulated, `tets` in
 * fracture mode now, `frame_cost` s of wall for the frames left.  0 before
 * the first sample. */
double cf_eta_left(const cf_eta *e, double t_left, double tets, double frame_cost);

#endif
