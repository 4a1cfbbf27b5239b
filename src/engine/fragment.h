/* The fragment record: a connected piece of the solid, in rigid or fracture
 * mode, and the helpers that read and write one fragment (docs/physics.md
 * §1, §9, §10).  Below the solver step, the contact and the hand-offs: it
 * calls none of them, and takes the solid, the Bullet world and the flows
 * it needs as arguments, never the world. */
#ifndef COHFRAC_FRAGMENT_H
#define COHFRAC_FRAGMENT_H

#include "cf_bullet.h"
#include "cohesive.h"
#include "decompose.h"
#include "insertion.h"
#include "pbd.h"
#include "pieces.h"
#include "solid.h"

/* Energy removed or put in by each mechanism since t = 0, J (docs/physics.md §4-§6;
 * the ledger balance is in cf_world_ledger). */
typedef struct cf_energy_flows {
    double boundary;   /* work of prescribed velocities */
    double obstacles;  /* work of moving obstacles (the energy contact with them put in) */
    double contact;    /* removed by obstacle contact: restitution, friction, and
                          the Bullet bodies' energy change beyond gravity's work */
    double pbd;        /* removed by the PBD/XPBD projection */
    double damping;    /* removed by global damping */
    double handoff;    /* non-rigid kinetic + strain + cohesive stored energy
                          dropped at fracture -> rigid hand-offs, less put_in */
    double put_in;     /* energy hand-offs put in (part of handoff): the strain
                          of pieces wedged between obstacles entering fracture
                          mode, and gravity's potential of pieces moved clear of
                          obstacles */
    double integration; /* changed by Bullet's integrator in bodies touching nothing */
} cf_energy_flows;

typedef enum { CF_MODE_DEAD = -1, CF_MODE_RIGID = 0, CF_MODE_FRACTURE = 1 } cf_mode;

typedef struct cf_fragment {
    int parent;              /* -1 for an initial body */
    double birth_time;       /* s */
    cf_mode mode;
    int *tets, nt;           /* ascending */
    cf_int_list nodes;
    /* Rest-shape mass properties: principal axes Q (columns), moments. */
    double mass, com_rest[3], Q[9], principal[3];
    double volume;           /* m^3, its tets' rest volume */
    int body;                /* Bullet body id, -1 when none */
    double q_match[4];       /* shape-matching warm start */
    /* In-house solver state (fracture mode, or pbd rigid mode). */
    cf_bars bars;
    cf_int_list coh;         /* its cohesive elements */
    long steps, quiet;       /* solver steps in this mode; steps its cracks have been
                                quiet (grown by at most solver.quiet_growth) */
    long grown;              /* elements inserted and tets crushed since quiet restarted */
    int separated;           /* its cohesive elements with every node pair failed at the
                                last split check; -1: not counted yet */
    double t_enter;          /* s, when fracture mode began */
    double e_enter;          /* J, its kinetic energy when fracture mode began */
    int *contact;            /* [nodes.n] obstacle in contact after the last projection, -1 */
    double *vn_pre;          /* [nodes.n] normal velocity before projection, m/s */
    double *v_old;           /* [nodes.n][3] velocity at the start of the step, m/s */
    double *term;            /* [nodes.n] per-node energy terms, J, summed in node order */
    int scratch_cap;
    cf_pair_force *pairs;    /* [3 pairs_cap] cohesive forces of a step (scratch) */
    int pairs_cap;           /* elements it has room for */
    /* Energy ledger state at the last force evaluation (in-house solver). */
    double e_kin;            /* J, 1/2 sum m v(n-1/2).v(n+1/2) (leapfrog estimate) */
    double e_strain;         /* J */
    double mx[3];            /* kg m, sum m x */
    /* What the last projection (bars, obstacles, prescribed nodes, friction
     * and restitution) did, booked into the world's flows when the next step
     * starts or the hand-off takes the fragment (cf_fragment_book_pending):
     * the projection of step n takes the state to n + 1, and e_kin is the
     * kinetic energy at step n. */
    cf_energy_flows pending;
    int n_inverted;          /* tets with det F <= 0 */
    /* Rigid mode with Bullet: the convex decomposition (principal frame). */
    cf_hulls hulls;
    double decompose_time;   /* s of wall time to decompose it */
    double pushed;           /* N s: impulse fracture-mode nodes gave its body
                                since the last rigid step (impact trigger) */
    double dv_enter;         /* m/s: the impact (contact impulse over mass) that
                                began its fracture-mode spell; 0 none */
    double dv_taken;         /* m/s: the strongest impact it has taken in fracture
                                mode and come back from whole; only a stronger
                                one sends it back (docs/physics.md §9) */
    double dv_sustained;     /* m/s: the impact in a rigid step at most of the
                                fixed contacts its landing time no longer holds,
                                (1 + e) times their fastest approach plus g dt,
                                at its last check; rigid mode takes them on
                                (world_step.c, impact_unfinished) */
} cf_fragment;

/* Appends a new fragment to the table frag[0..*n) of capacity *cap (grown
 * as needed: pointers into the table do not survive the call), in rigid
 * mode with no body.  parent: -1 for an initial body; birth_time s.
 * Returns its index, or -1 out of memory. */
int cf_fragment_new(cf_fragment **frag, int *n, int *cap, int parent, double birth_time);

/* The initial body fragment fi of the table frag descends from (its family:
 * fragments of one body do not collide with each other). */
int cf_fragment_root(const cf_fragment *frag, int fi);

/* Whether fragment f is debris (docs/physics.md §9.2): 1 or 0. */
int cf_fragment_is_debris(const cf_fragment *f, const cf_solver_settings *set);

/* The least volume of a piece a crack may close (§5.1 rule 4), m^3: a
 * sphere of diameter solver.min_piece_size (0: no bound). */
double cf_min_piece_volume(const cf_solver_settings *set);

/* Whether fragment f cannot split any further (docs/physics.md §9.2): it
 * is debris, or it is a piece (not an initial body), cracks grow from
 * fronts, every piece a crack may close has more than min_piece_tets tets
 * and at least the volume of a sphere of min_piece_size (§5.1 rule 4),
 * and f has fewer than twice that on either count, with no crushing that
 * cuts tets free (crushing_strain of material m).  1 or 0. */
int cf_fragment_cannot_split(const cf_fragment *f, const cf_solver_settings *set,
                             const cf_material *m);

/* Whether an impact can break fragment f (an impact of one that cannot
 * leaves it in rigid mode): it can split (cf_fragment_cannot_split), its
 * solid s has a fracture criterion, and it has an uncracked interior
 * facet.  1 or 0. */
int cf_fragment_can_break(const cf_fragment *f, const cf_solid *s, const cf_solver_settings *set);

/* Frees fragment f's fracture-mode scratch (contact flags, velocities,
 * energy terms, cohesive pair forces), and with `dead` also its node and
 * cohesive element lists.  A rigid fragment needs no scratch until its
 * next entry makes it again, and a dead one nothing: the pieces of a
 * shattering body kept theirs to the end, 786 MiB of the 202,231-tet
 * drop's memory. */
void cf_fragment_release(cf_fragment *f, int dead);

/* Bullet collision margin of fragment f's convex hulls, m: 0.1 % of its
 * size, the cube root of its volume (mass over the density of material m;
 * Bullet's default 4 cm would hold a small fragment off the ground).
 * Bullet's shape is the hull grown by it, so its contacts begin that far
 * out. */
double cf_fragment_margin(const cf_fragment *f, const cf_material *m);

/* The longest a landing of fragment f at speed v (m/s; the impact
 * threshold) lasts, s: twice the contact time of an elastic sphere of its
 * mass and volume on a rigid floor of material m (Hertz; Johnson, Contact
 * Mechanics, 1985, §11.4): 2.94 d / v, d = (15 m v^2 / (16 E* sqrt(R)))^(2/5)
 * the deepest approach, E* = E / (1 - nu^2).  INFINITY for v <= 0. */
double cf_fragment_landing_time(const cf_fragment *f, const cf_material *m, double v);

/* Counts a fracture step of f in which `inserted` cohesive elements were
 * inserted or tets crushed into its quiet period (docs/physics.md §9): the
 * count f->quiet goes on while the insertions since it last restarted
 * (f->grown) are at most `growth` times f's cohesive elements, and
 * restarts, with f->grown, otherwise.  growth = 0: quiet means no
 * insertion. */
void cf_fragment_count_quiet(cf_fragment *f, int inserted, double growth);

/* Computes f's rest-shape mass properties from its tets and nodes on the
 * solid s: mass (kg), volume (m^3), centre of mass (m), principal axes Q and
 * moments (kg m^2). */
void cf_fragment_rest_props(cf_fragment *f, const cf_solid *s);

/* Centre of mass (m), rotation (rest -> current), velocity (m/s) and
 * angular velocity (rad/s) of fragment f, whatever its mode: of its body
 * in the Bullet world b, or of its nodes on s.  In fracture mode the
 * rotation is the shape matching's, warm-started from and written back to
 * f->q_match: the step's own calls.  cf_fragment_pose_peek leaves q_match
 * alone, so that reading a pose (output frames, queries) never changes a
 * run's bits. */
void cf_fragment_pose(cf_fragment *f, const cf_solid *s, const cfb_world *b, double com[3],
                      double R[9], double v[3], double w[3]);
void cf_fragment_pose_peek(const cf_fragment *f, const cf_solid *s, const cfb_world *b,
                           double com[3], double R[9], double v[3], double w[3]);

/* Books f's pending flows into `flow` and clears them. */
void cf_fragment_book_pending(cf_fragment *f, cf_energy_flows *flow);

/* The ledger state of f from its nodes now: its pending flows booked into
 * `flow`, then the exact kinetic energy, zero strain energy, sum m x. */
void cf_fragment_ledger_reset(cf_fragment *f, const cf_solid *s, cf_energy_flows *flow);

/* Angular momentum of f's Bullet body in state st about its centre of mass,
 * I w with I = Rb diag(principal) Rb^T, kg m^2/s. */
void cf_body_spin(const cf_fragment *f, const cfb_state *st, double Iw[3]);

/* Linear (kg m/s) and angular momentum (kg m^2/s, about the origin) of
 * f's Bullet body in state st: P = M v, L = M c x v + I w. */
void cf_body_momenta(const cf_fragment *f, const cfb_state *st, double P[3], double L[3]);

/* Kinetic energy of f's Bullet body in state st, J. */
double cf_body_kinetic_energy(const cf_fragment *f, const cfb_state *st);

/* The momenta of fragment f now: of its body in b, or of its nodes on s. */
void cf_fragment_momenta(const cf_fragment *f, const cf_solid *s, const cfb_world *b, double P[3],
                         double L[3]);

#endif
