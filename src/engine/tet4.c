#include "tet4.h"

#include "linalg.h"

/* Deformation gradient F = Ds Dm^-1 of tet t at positions x. */
static inline void deformation_gradient(const cf_solid *s, int t, double F[9])
{
    const int *T = &s->tet[4 * t];
    const double *x0 = &s->x[3 * T[0]];
    double Ds[9];
    for (int j = 0; j < 3; j++) {
        const double *xj = &s->x[3 * T[j + 1]];
        for (int r = 0; r < 3; r++)
            Ds[3 * r + j] = xj[r] - x0[r];
    }
    m3_mul(Ds, &s->Dm_inv[9 * t], F);
}

/* Voigt slots (xx yy zz xy xz yz) of the plastic strain, as row and column. */
static const int VOIGT[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};

/* Crushing (docs/physics.md §2.1): von Mises perfect plasticity at the
 * compressive strength sigma_c.  A trial stress sig whose equivalent stress
 * sqrt(3/2 s:s) exceeds sigma_c has its deviator s scaled back onto the
 * yield surface (radial return); the elastic strain eps loses, and the
 * plastic strain ep (Voigt, tensor shear; NULL: not kept) gains, the
 * removed deviator over 2 mu.  Returns the plastic work density
 * sig : d ep >= 0 (J/m^3). */
static inline double crush(const cf_solid *s, double sig[9], double eps[9], double *ep)
{
    double p = (sig[0] + sig[4] + sig[8]) / 3, dev[9], ss = 0;
    for (int k = 0; k < 9; k++) {
        dev[k] = sig[k] - ((k % 4) == 0 ? p : 0);
        ss += dev[k] * dev[k];
    }
    double seq = sqrt(1.5 * ss), sc = s->mat.compressive_strength;
    if (!(seq > sc))
        return 0;
    double back = 1 - sc / seq; /* share of the deviator removed */
    for (int k = 0; k < 9; k++) {
        sig[k] -= back * dev[k];
        eps[k] -= back * dev[k] / (2 * s->mu);
    }
    for (int v = 0; ep && v < 6; v++)
        ep[v] += back * dev[3 * VOIGT[v][0] + VOIGT[v][1]] / (2 * s->mu);
    return (sc / seq) * back * ss / (2 * s->mu); /* (1 - back) s : back s / 2 mu */
}

/* Strain of A (symmetric part minus identity, less the plastic strain ep
 * when crushing) -> stress and strain energy density.  With ep, a trial
 * stress beyond sigma_c returns to the yield surface, and ep keeps the new
 * plastic strain when `update` (otherwise it is read only).  Returns the
 * plastic work density of the return (J/m^3; 0 without crushing). */
static inline double hooke(const cf_solid *s, const double A[9], double *ep, int update,
                           double sig[9], double *energy_density)
{
    double eps[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            eps[3 * i + j] = 0.5 * (A[3 * i + j] + A[3 * j + i]) - (i == j);
    if (ep)
        for (int v = 0; v < 6; v++) {
            int i = VOIGT[v][0], j = VOIGT[v][1];
            eps[3 * i + j] -= ep[v];
            if (i != j)
                eps[3 * j + i] -= ep[v];
        }
    double tr = eps[0] + eps[4] + eps[8];
    for (int k = 0; k < 9; k++)
        sig[k] = 2 * s->mu * eps[k] + ((k % 4) == 0 ? s->lambda * tr : 0);
    double wp = ep ? crush(s, sig, eps, update ? ep : NULL) : 0;
    double w = 0;
    for (int k = 0; k < 9; k++)
        w += 0.5 * sig[k] * eps[k];
    *energy_density = w;
    return wp;
}

/* Tets whose rotations are found side by side.  The rotation iteration is
 * one long dependent chain per tet (square roots, divisions, a sine and a
 * cosine), so a core running one tet at a time mostly waits on it; running
 * LANES independent chains phase by phase lets it overlap them.  Each lane
 * does exactly the operations of polar_rotation (linalg.h) in the same
 * order, so the bits are those of one tet at a time. */
#define LANES 4

/* polar_rotation for the first n lanes: q[l] the warm start (updated), R[l]
 * the rotation, at most max_iter updates, stop below tol (rad). */
static void polar_rotation_lanes(double F[LANES][9], double q[LANES][4], int n,
                                 int max_iter, double tol, double R[LANES][9])
{
    int active[LANES];
    for (int l = 0; l < n; l++) {
        quat_normalize(q[l]);
        active[l] = 1;
    }
    for (int it = 0; it < max_iter; it++) {
        double om[LANES][3], angle[LANES];
        int left = 0;
        for (int l = 0; l < n; l++) {
            if (!active[l])
                continue;
            angle[l] = polar_axis(F[l], q[l], R[l], om[l]);
            if (angle[l] < tol)
                active[l] = 0; /* R[l] already holds q[l] */
            left += active[l];
        }
        if (!left)
            return;
        for (int l = 0; l < n; l++)
            if (active[l])
                polar_turn(q[l], om[l], angle[l]);
    }
    for (int l = 0; l < n; l++)
        if (active[l])
            quat_to_mat(q[l], R[l]);
}

/* Stress in the element frame of tet t from the deformation gradient F and
 * its rotation R to the world, and the strain energy density; with
 * crushing, `update` moves the tet's plastic strain.  Returns the plastic
 * work density of this pass (hooke). */
static inline double element_stress(const cf_solid *s, int t, const double F[9],
                                    cf_elasticity kind, const double R[9], int update,
                                    double sig[9], double *w)
{
    double *ep = s->ep ? &s->ep[6 * t] : NULL;
    if (kind == CF_ELASTICITY_COROTATIONAL) {
        double S[9];
        m3_mul_tn(R, F, S);
        return hooke(s, S, ep, update, sig, w);
    }
    return hooke(s, F, ep, update, sig, w);
}

/* The rotations of tets t[0..n-1] (n <= LANES) at deformation gradients F,
 * from and into the warm starts s->rq; the identity for small strain.  A
 * rotation error theta leaves a strain error O(theta^2 + theta eps): 1e-7
 * rad is far below any cracking strain. */
static void element_rotations(cf_solid *s, const int *t, int n, double F[LANES][9],
                              cf_elasticity kind, double R[LANES][9])
{
    if (kind != CF_ELASTICITY_COROTATIONAL) {
        for (int l = 0; l < n; l++)
            m3_identity(R[l]);
        return;
    }
    double q[LANES][4];
    for (int l = 0; l < n; l++)
        memcpy(q[l], &s->rq[4 * t[l]], sizeof q[l]);
    polar_rotation_lanes(F, q, n, 10, 1e-7, R);
    for (int l = 0; l < n; l++)
        memcpy(&s->rq[4 * t[l]], q[l], sizeof q[l]);
}

/* Gershgorin bounds of a symmetric 3x3 matrix's eigenvalues: every one
 * lies in [lo, hi].  The element-frame and world-frame stresses are similar
 * matrices, so these bound the world stress's principal values too. */
static inline void gershgorin(const double A[9], double *lo, double *hi)
{
    double r0 = fabs(A[1]) + fabs(A[2]), r1 = fabs(A[1]) + fabs(A[5]),
           r2 = fabs(A[2]) + fabs(A[5]);
    *hi = fmax(A[0] + r0, fmax(A[4] + r1, A[8] + r2));
    *lo = fmin(A[0] - r0, fmin(A[4] - r1, A[8] - r2));
}

int cf_tet4_forces(cf_solid *s, const int *tets, int nt, cf_elasticity kind,
                   const cf_stress_check *check, int *n_hot)
{
    int inverted = 0, hot = 0;
    /* Threads only for fragments large enough to repay the fork and join:
     * hundreds of few-tet fragments in fracture mode ran slower on 2
     * threads than on 1. */
#pragma omp parallel for schedule(static) reduction(+ : inverted, hot) if (nt >= CF_TET4_PARALLEL_MIN)
    for (int i0 = 0; i0 < nt; i0 += LANES) {
        int n = nt - i0 < LANES ? nt - i0 : LANES;
        const int *t = &tets[i0];
        double F[LANES][9], R[LANES][9];
        for (int l = 0; l < n; l++) {
            deformation_gradient(s, t[l], F[l]);
            inverted += m3_det(F[l]) <= 0;
        }
        element_rotations(s, t, n, F, kind, R);
        for (int l = 0; l < n; l++) {
            double sig[9], P[9], g[4][3], w;
            double wp = element_stress(s, t[l], F[l], kind, R[l], 1, sig, &w);
            s->tw[t[l]] = w * s->vol[t[l]];
            if (s->wp)
                s->wp[t[l]] += wp * s->vol[t[l]];
            m3_mul(R[l], sig, P); /* f_i = -V R sigma grad N_i */
            cf_tet4_gradients(s, t[l], g);
            double *tf = &s->tf[12 * t[l]];
            for (int a = 0; a < 4; a++) {
                double fa[3];
                m3_mulv(P, g[a], fa);
                for (int c = 0; c < 3; c++)
                    tf[3 * a + c] = -s->vol[t[l]] * fa[c];
            }
            if (check) {
                double lo, hi;
                m3_mul_nt(P, R[l], &s->sigma[9 * t[l]]); /* R sigma R^T */
                gershgorin(sig, &lo, &hi);
                s->hot[t[l]] = hi >= check->s1 || 0.5 * (hi - lo) >= check->tau;
                hot += s->hot[t[l]];
            }
        }
    }
    if (n_hot)
        *n_hot = hot;
    return inverted;
}

void cf_tet4_stress(const cf_solid *s, int t, cf_elasticity kind, double sigma[9])
{
    double F[9], R[9], sig[9], P[9], w, q[4];
    for (int k = 0; k < 4; k++)
        q[k] = s->rq[4 * t + k];
    deformation_gradient(s, t, F);
    if (kind == CF_ELASTICITY_COROTATIONAL)
        polar_rotation(F, q, 10, 1e-7, R);
    else
        m3_identity(R);
    element_stress(s, t, F, kind, R, 0, sig, &w);
    m3_mul(R, sig, P);
    m3_mul_nt(P, R, sigma);
}

void cf_tet4_drop_plastic_strain(cf_solid *s, const int *tets, int nt)
{
    if (s->ep)
        for (int i = 0; i < nt; i++)
            memset(&s->ep[6 * tets[i]], 0, 6 * sizeof(double));
}

void cf_tet4_gather(cf_solid *s, const int *nodes, int nn, const double g[3])
{
#pragma omp parallel for schedule(static) if (nn >= CF_NODES_PARALLEL_MIN)
    for (int i = 0; i < nn; i++) {
        int a = nodes[i], o = s->origin[a];
        double *fa = &s->f[3 * a];
        for (int k = 0; k < 3; k++)
            fa[k] = s->m[a] * g[k];
        for (int j = s->vt_start[o]; j < s->vt_start[o + 1]; j++) {
            int slot = s->vt_slot[j];
            if (s->tet[slot] == a)
                v3_axpy(1.0, &s->tf[3 * slot], fa);
        }
    }
}

double cf_tet4_strain_energy(const cf_solid *s, const int *tets, int nt)
{
    double e = 0;
    for (int i = 0; i < nt; i++) /* list order: the same sum for any thread count */
        e += s->tw[tets[i]];
    return e;
}
