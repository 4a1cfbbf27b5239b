#include "pieces.h"

#include "linalg.h"

#include <stdlib.h>
#include <string.h>

static int find(int *parent, int i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

static void join(int *parent, int i, int j)
{
    int a = find(parent, i), b = find(parent, j);
    if (a != b) /* the lower list position is the root */
        parent[a > b ? a : b] = a < b ? a : b;
}

/* Position of tet t in the ascending list tets[0..nt). */
static int position_of(const int *tets, int nt, int t)
{
    int lo = 0, hi = nt - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (tets[mid] < t)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

int cf_label_components(const cf_solid *s, const int *tets, int nt, int *comp)
{
    return cf_label_pieces(s, tets, nt, NULL, 0, comp);
}

int cf_label_pieces(const cf_solid *s, const int *tets, int nt, const int *coh, int ncoh,
                    int *comp)
{
    int *parent = malloc((size_t)nt * sizeof(int));
    int *owner = malloc((size_t)s->n_nodes * sizeof(int));
    if (!parent || !owner) {
        free(parent), free(owner);
        return -1;
    }
    for (int i = 0; i < nt; i++)
        parent[i] = i;
    for (int i = 0; i < nt; i++)
        for (int j = 0; j < 4; j++)
            owner[s->tet[4 * tets[i] + j]] = -1;
    for (int i = 0; i < nt; i++)
        for (int j = 0; j < 4; j++) {
            int n = s->tet[4 * tets[i] + j];
            if (owner[n] < 0)
                owner[n] = i;
            else
                join(parent, i, owner[n]);
        }
    for (int e = 0; e < ncoh; e++) {
        const cf_cohesive *ce = &s->coh[coh[e]];
        if (!cf_cohesive_all_failed(ce))
            join(parent, position_of(tets, nt, ce->tet[0]), position_of(tets, nt, ce->tet[1]));
    }
    int k = 0;
    for (int i = 0; i < nt; i++) {
        int r = find(parent, i);
        comp[i] = (r == i) ? k++ : comp[r];
    }
    free(parent), free(owner);
    return k;
}

void cf_tet_mass_props(const cf_solid *s, const int *tets, int nt, const double *pos,
                       cf_mass_props *mp)
{
    memset(mp, 0, sizeof *mp);
    for (int i = 0; i < nt; i++) {
        double m = cf_tet_mass(s, tets[i]);
        mp->mass += m;
        for (int j = 0; j < 4; j++)
            v3_axpy(0.25 * m, &pos[3 * s->tet[4 * tets[i] + j]], mp->com);
    }
    if (mp->mass <= 0)
        return;
    for (int c = 0; c < 3; c++)
        mp->com[c] /= mp->mass;
    double C[9] = {0};
    for (int i = 0; i < nt; i++) {
        double m = cf_tet_mass(s, tets[i]), r[4][3], sum[3] = {0, 0, 0};
        for (int j = 0; j < 4; j++) {
            v3_sub(&pos[3 * s->tet[4 * tets[i] + j]], mp->com, r[j]);
            v3_axpy(1.0, r[j], sum);
        }
        for (int p = 0; p < 3; p++)
            for (int q = 0; q < 3; q++) {
                double acc = sum[p] * sum[q];
                for (int j = 0; j < 4; j++)
                    acc += r[j][p] * r[j][q];
                C[3 * p + q] += m / 20.0 * acc;
            }
    }
    double tr = C[0] + C[4] + C[8];
    for (int k = 0; k < 9; k++)
        mp->inertia[k] = ((k % 4) == 0 ? tr : 0) - C[k];
}

void cf_nodes_mass_moment_add(const cf_solid *s, const int *nodes, int i0, int i1, double mx[3])
{
    for (int i = i0; i < i1; i++)
        v3_axpy(s->m[nodes[i]], &s->x[3 * nodes[i]], mx);
}

void cf_nodes_momenta(const cf_solid *s, const int *nodes, int nn, cf_node_state *st)
{
    memset(st, 0, sizeof *st);
    double P[3] = {0, 0, 0};
    for (int i = 0; i < nn; i++) {
        int a = nodes[i];
        double m = s->m[a];
        st->M += m;
        v3_axpy(m, &s->x[3 * a], st->com);
        v3_axpy(m, &s->v[3 * a], P);
        st->ke += 0.5 * m * v3_dot(&s->v[3 * a], &s->v[3 * a]);
    }
    if (st->M <= 0)
        return;
    for (int c = 0; c < 3; c++)
        st->com[c] /= st->M, st->v[c] = P[c] / st->M;
    for (int i = 0; i < nn; i++) {
        int a = nodes[i];
        double r[3], rv[3];
        v3_sub(&s->x[3 * a], st->com, r);
        v3_cross(r, &s->v[3 * a], rv);
        v3_axpy(s->m[a], rv, st->L);
    }
}

void cf_nodes_state(const cf_solid *s, const int *nodes, int nn, double q[4], cf_node_state *st)
{
    cf_nodes_momenta(s, nodes, nn, st);
    if (st->M <= 0)
        return;
    double Xc[3] = {0, 0, 0}, A[9] = {0};
    for (int i = 0; i < nn; i++)
        v3_axpy(s->m[nodes[i]] / st->M, &s->X[3 * nodes[i]], Xc);
    for (int i = 0; i < nn; i++) {
        int a = nodes[i];
        double r[3], R0[3];
        v3_sub(&s->x[3 * a], st->com, r);
        v3_sub(&s->X[3 * a], Xc, R0);
        for (int p = 0; p < 3; p++)
            for (int k = 0; k < 3; k++)
                A[3 * p + k] += s->m[a] * r[p] * R0[k];
    }
    double fro = 0; /* scale-free iteration: its epsilon assumes |A| ~ 1 */
    for (int k = 0; k < 9; k++)
        fro += A[k] * A[k];
    fro = sqrt(fro);
    for (int k = 0; k < 9 && fro > 0; k++)
        A[k] /= fro;
    polar_rotation(A, q, 100, 1e-14, st->R);
}

void cf_nodes_inertia(const cf_solid *s, const int *nodes, int nn, const double *pos,
                      const double com[3], double I[9])
{
    for (int k = 0; k < 9; k++)
        I[k] = 0;
    for (int i = 0; i < nn; i++) {
        int a = nodes[i];
        double r[3];
        v3_sub(&pos[3 * a], com, r);
        double r2 = v3_dot(r, r);
        for (int p = 0; p < 3; p++)
            for (int q = 0; q < 3; q++)
                I[3 * p + q] += s->m[a] * ((p == q) * r2 - r[p] * r[q]);
    }
}

void cf_nodes_angular_velocity(const cf_solid *s, const int *nodes, int nn, const double com[3],
                               const double L[3], double w[3])
{
    double I[9], Iinv[9];
    cf_nodes_inertia(s, nodes, nn, s->x, com, I);
    w[0] = w[1] = w[2] = 0;
    if (m3_inv(I, Iinv) != 0)
        m3_mulv(Iinv, L, w);
}

void cf_global_damping(cf_solid *s, const int *nodes, int nn, double k)
{
    cf_node_state st;
    cf_nodes_momenta(s, nodes, nn, &st);
    if (st.M <= 0)
        return;
    double w[3];
    cf_nodes_angular_velocity(s, nodes, nn, st.com, st.L, w);
    for (int i = 0; i < nn; i++) {
        int a = nodes[i];
        double r[3], wr[3];
        v3_sub(&s->x[3 * a], st.com, r);
        v3_cross(w, r, wr);
        for (int c = 0; c < 3; c++)
            s->v[3 * a + c] += k * (st.v[c] + wr[c] - s->v[3 * a + c]);
    }
}
