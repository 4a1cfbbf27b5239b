/* The run's remaining wall time, from the cost of each mode measured as it
 * goes (docs/performance.md, "The ETA").
 *
 * The run is sampled every tenth of a second or so of wall time (kept a
 * quarter second apart at first, thinned as the history fills).  What is
 * left costs:
 *  - the fracture-mode spell now running: the simulated time it still
 *    runs (cf_eta_spell_left, with what the landing times of the landings
 *    under way leave) at the cost per tet and fracture step of the recent
 *    samples, at the tets in fracture mode now;
 *  - the long spells that the landings to come will start (a piece in
 *    flight that will land, cf_world_landings): each as long as its
 *    landing time, at the same cost per tet-step;
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

/* A landing (cf_world_landings): the spell it will start, or, under way,
 * holds. */
typedef struct cf_eta_landing {
    int under_way;        /* 1: its spell runs now */
    double t;             /* s simulated from now until it lands; under way,
                             minus the time since its spell began */
    double tets;          /* the fragment's tets */
    double hold;          /* s: its landing time (docs/physics.md §9) */
} cf_eta_landing;

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
 * does not decay; where the cracks are quiet, `held` (at least a quiet
 * time), or as long again as they have been quiet where it is not known.
 * `held`: s that the landings under way still hold it (the largest of
 * their landing times less the time since the spell began; negative once
 * over), -INFINITY when none is under way; the spell runs at least that
 * long.  At most rule.max_spell less what it ran; 0 with no spell.
 * *by_landing: 1 where the answer is what the landings hold it. */
double cf_eta_spell_left(const cf_eta *e, double held, int *by_landing);

/* Simulated time, s, of the spell a landing `l` to come will start: its
 * landing time, at least a quiet time, up to `t_left` (the end of the
 * run); 0 for a short one (CF_ETA_LONG quiet times or less: the rest's
 * rate holds those), one after the end, or one under way. */
double cf_eta_landing_spell(const cf_eta *e, const cf_eta_landing *l, double t_left);

/* Wall time, s, of the rest of the run: `t_left` s simulated, `tets` in
 * fracture mode now, the `n_landing` landings under way and to come
 * `landing` (may be NULL with 0), `frame_cost` s of wall for the frames
 * left.  0 before the first sample. */
double cf_eta_left(const cf_eta *e, double t_left, double tets, const cf_eta_landing *landing,
                   int n_landing, double frame_cost);

#endif
