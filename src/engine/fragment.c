/* The fragment record's helpers (fragment.h). */
#include "fragment.h"

#include "chunks.h"
#include "linalg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int cf_fragment_new(cf_fragment **frag, int *n, int *cap, int parent, double birth_time)
{
    if (*n == *cap) {
        int grown = *cap ? 2 * *cap : 16;
        cf_fragment *p = realloc(*frag, (size_t)grown * sizeof *p);
        if (!p)
            return -1;
        *frag = p, *cap = grown;
    }
    cf_fragment *f = &(*frag)[*n];
    memset(f, 0, sizeof *f);
    f->parent = parent;
    f->birth_time = birth_time;
    f->mode = CF_MODE_RIGID;
    f->body = -1;
    f->q_match[0] = 1;
    f->separated = -1;
    return (*n)++;
}

int cf_fragment_root(const cf_fragment *frag, int fi)
{
    while (frag[fi].parent >= 0)
        fi = frag[fi].parent;
    return fi;
}

static const double PI = 3.14159265358979323846;

/* Debris (docs/physics.md §9.2): a piece, not an initial body, of at most
 * solver.debris_tets tets (the mesh cannot resolve its breaking), or
 * whose sphere of equal volume is narrower than solver.debris_size.  A
 * property of the fragment's tets, so it holds from birth. */
int cf_fragment_is_debris(const cf_fragment *f, const cf_solver_settings *set)
{
    if (f->parent < 0)
        return 0;
    return f->nt <= set->debris_tets ||
           (set->debris_size > 0 && cbrt(6 * f->volume / PI) < set->debris_size);
}

double cf_min_piece_volume(const cf_solver_settings *set)
{
    double d = set->min_piece_size;
    return 0.5235987755982988 * d * d * d; /* pi d^3 / 6 */
}

int cf_fragment_cannot_split(const cf_fragment *f, const cf_solver_settings *set,
                             const cf_material *m)
{
    if (cf_fragment_is_debris(f, set))
        return 1;
    /* An initial body is the user's: it keeps its impact in fracture mode. */
    if (f->parent < 0 || set->crack_growth != CF_GROWTH_FRONTS || m->crushing_strain > 0)
        return 0;
    return f->nt < 2 * (set->min_piece_tets + 1) || f->volume < 2 * cf_min_piece_volume(set);
}

/* One with no uncracked interior facet has nothing left to break. */
int cf_fragment_can_break(const cf_fragment *f, const cf_solid *s, const cf_solver_settings *set)
{
    if (set->criterion == CF_CRITERION_NONE || cf_fragment_cannot_split(f, set, &s->mat))
        return 0;
    for (int i = 0; i < f->nt; i++)
        for (int k = 0; k < 4; k++) {
            int fc = s->tet_facet[4 * f->tets[i] + k];
            if (s->facet[4 * fc + 2] >= 0 && !s->cracked[fc])
                return 1;
        }
    return 0;
}

void cf_fragment_release(cf_fragment *f, int dead)
{
    free(f->contact), free(f->vn_pre), free(f->v_old), free(f->term), free(f->pairs);
    f->contact = NULL, f->vn_pre = f->v_old = f->term = NULL, f->pairs = NULL;
    f->scratch_cap = f->pairs_cap = 0;
    if (!dead)
        return;
    free(f->nodes.v), free(f->coh.v);
    f->nodes = (cf_int_list){0}, f->coh = (cf_int_list){0};
}

double cf_fragment_margin(const cf_fragment *f, const cf_material *m)
{
    return 1e-3 * cbrt(f->mass / m->rho);
}

/* Twice, as a corner's contact radius is smaller than the sphere's and the
 * time grows as R^(-1/5).  A slower landing is no impact and lasts longer,
 * but rigid mode would not call it one: a contact that outlasts this is
 * sustained (the fragment rolls, pivots or rests), and rigid mode takes it
 * (docs/physics.md §9). */
double cf_fragment_landing_time(const cf_fragment *f, const cf_material *m, double v)
{
    if (!(v > 0))
        return INFINITY;
    double R = cbrt(3 * f->volume / (4 * acos(-1.0))), E = m->E / (1 - m->nu * m->nu);
    double d = pow(15 * f->mass * v * v / (16 * E * sqrt(R)), 0.4);
    return 2 * 2.94 * d / v;
}

/* A ratio of crack areas, which refining the mesh leaves alone: on a large
 * ringing body the weakest of its many facets keep giving one at a time
 * long after its break has settled, and a count of none never comes. */
void cf_fragment_count_quiet(cf_fragment *f, int inserted, double growth)
{
    f->grown += inserted;
    if (f->grown > growth * f->coh.n)
        f->quiet = f->grown = 0;
    else
        f->quiet++;
}

/* Mass and centre of mass from the tets (identical to the lumped ones); the
 * inertia of the lumped masses, the solver's own discretisation, so that a
 * hand-off preserves linear and angular momentum and never adds kinetic
 * energy (the tet second moment of docs/physics.md §9 would give a single tet 1/5 of
 * its lumped inertia, and the rigid spin 5 times the energy). */
void cf_fragment_rest_props(cf_fragment *f, const cf_solid *s)
{
    cf_mass_props mp;
    double I[9];
    cf_tet_mass_props(s, f->tets, f->nt, s->X, &mp);
    f->mass = mp.mass;
    f->volume = 0;
    for (int i = 0; i < f->nt; i++)
        f->volume += s->vol[f->tets[i]];
    memcpy(f->com_rest, mp.com, sizeof mp.com);
    cf_nodes_inertia(s, f->nodes.v, f->nodes.n, s->X, mp.com, I);
    sym3_eigen(I, f->principal, f->Q);
}

/* Fragment f's pose, its shape matching warm-started from (and leaving
 * its rotation in) q. */
static void pose_from(const cf_fragment *f, const cf_solid *s, const cfb_world *b, double q[4],
                      double com[3], double R[9], double v[3], double w[3])
{
    if (f->body >= 0) {
        cfb_state st;
        double Rb[9];
        cfb_get_state(b, f->body, &st);
        quat_to_mat(st.quat, Rb);
        m3_mul_nt(Rb, f->Q, R);
        memcpy(com, st.pos, sizeof st.pos);
        memcpy(v, st.v, sizeof st.v);
        memcpy(w, st.w, sizeof st.w);
        return;
    }
    cf_node_state ns;
    cf_nodes_state(s, f->nodes.v, f->nodes.n, q, &ns);
    memcpy(com, ns.com, sizeof ns.com);
    memcpy(R, ns.R, sizeof ns.R);
    memcpy(v, ns.v, sizeof ns.v);
    cf_nodes_angular_velocity(s, f->nodes.v, f->nodes.n, ns.com, ns.L, w);
}

void cf_fragment_pose(cf_fragment *f, const cf_solid *s, const cfb_world *b, double com[3],
                      double R[9], double v[3], double w[3])
{
    pose_from(f, s, b, f->q_match, com, R, v, w);
}

void cf_fragment_pose_peek(const cf_fragment *f, const cf_solid *s, const cfb_world *b,
                           double com[3], double R[9], double v[3], double w[3])
{
    double q[4];
    memcpy(q, f->q_match, sizeof q);
    pose_from(f, s, b, q, com, R, v, w);
}

void cf_fragment_book_pending(cf_fragment *f, cf_energy_flows *flow)
{
    cf_energy_flows *p = &f->pending;
    flow->boundary += p->boundary, flow->obstacles += p->obstacles;
    flow->contact += p->contact, flow->pbd += p->pbd;
    memset(p, 0, sizeof *p);
}

typedef struct {
    const cf_solid *s;
    const int *nodes;
} node_list;

/* The mass moment, sum m x, in the chunks the step's kinetic sums use
 * (fracture.c): the ledger's gravity work, the change of this sum, then
 * starts from the bits the step gives, not from M times the centre of
 * mass, which differs from them in the last bits (6e-12 J of work that
 * nothing did, at the first step of a resting plate). */
static void mass_moment_chunk(void *ctx, int i0, int i1, double *acc)
{
    const node_list *c = ctx;
    cf_nodes_mass_moment_add(c->s, c->nodes, i0, i1, acc);
}

void cf_fragment_ledger_reset(cf_fragment *f, const cf_solid *s, cf_energy_flows *flow)
{
    cf_fragment_book_pending(f, flow);
    cf_node_state ns;
    cf_nodes_momenta(s, f->nodes.v, f->nodes.n, &ns);
    f->e_kin = ns.ke;
    f->e_strain = 0;
    node_list c = {s, f->nodes.v};
    cf_sum_chunks(f->nodes.n, 3, 1, mass_moment_chunk, &c, f->mx);
}

void cf_body_spin(const cf_fragment *f, const cfb_state *st, double Iw[3])
{
    double Rb[9], wb[3];
    quat_to_mat(st->quat, Rb);
    m3_tmulv(Rb, st->w, wb);
    for (int k = 0; k < 3; k++)
        wb[k] *= f->principal[k];
    m3_mulv(Rb, wb, Iw);
}

void cf_body_momenta(const cf_fragment *f, const cfb_state *st, double P[3], double L[3])
{
    double Iw[3], c[3];
    cf_body_spin(f, st, Iw);
    v3_cross(st->pos, st->v, c);
    for (int k = 0; k < 3; k++) {
        P[k] = f->mass * st->v[k];
        L[k] = f->mass * c[k] + Iw[k];
    }
}

double cf_body_kinetic_energy(const cf_fragment *f, const cfb_state *st)
{
    double Rb[9], wb[3];
    quat_to_mat(st->quat, Rb);
    m3_tmulv(Rb, st->w, wb); /* body-frame angular velocity */
    double e = 0.5 * f->mass * v3_dot(st->v, st->v);
    for (int k = 0; k < 3; k++)
        e += 0.5 * f->principal[k] * wb[k] * wb[k];
    return e;
}

/* Linear and angular momentum about the origin, m v and x cross m v. */
static void momenta_chunk(void *ctx, int i0, int i1, double *acc)
{
    const node_list *c = ctx;
    const cf_solid *s = c->s;
    for (int i = i0; i < i1; i++) {
        int a = c->nodes[i];
        double x_v[3];
        v3_axpy(s->m[a], &s->v[3 * a], acc);
        v3_cross(&s->x[3 * a], &s->v[3 * a], x_v);
        v3_axpy(s->m[a], x_v, &acc[3]);
    }
}

void cf_fragment_momenta(const cf_fragment *f, const cf_solid *s, const cfb_world *b, double P[3],
                         double L[3])
{
    if (f->body >= 0) {
        cfb_state st;
        cfb_get_state(b, f->body, &st);
        cf_body_momenta(f, &st, P, L);
        return;
    }
    node_list c = {s, f->nodes.v};
    double PL[6];
    cf_sum_chunks(f->nodes.n, 6, 1, momenta_chunk, &c, PL);
    memcpy(P, PL, 3 * sizeof(double));
    memcpy(L, &PL[3], 3 * sizeof(double));
}
