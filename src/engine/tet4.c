#include "tet4.h"

#include "chunks.h"
#include "lanes.h"
#include "linalg.h"
#include "parallel.h"

#include <omp.h>
#include <string.h>

/* Voigt slots (xx yy zz xy xz yz) of the plastic strain, as row and column. */
static const int VOIGT[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};

/* Crushing (docs/physics.md §2.1): perfect plasticity with the
 * Drucker-Prager yield surface q <= k + beta p (q = sqrt(3/2 s:s) the
 * equivalent stress of the deviator s, p = -tr(sig)/3 the pressure; von
 * Mises at sigma_c when beta = 0).  A trial stress sig outside it has its
 * deviator scaled back onto the surface at the same pressure (radial
 * return without dilatancy); the elastic strain eps loses, and the plastic
 * strain ep (Voigt, tensor shear; NULL: not kept) gains, the removed
 * deviator over 2 mu.  Returns the plastic work density sig : d ep >= 0
 * (J/m^3). */
static inline double crush(const cf_solid *s, double sig[9], double eps[9], double *ep)
{
    double m = (sig[0] + sig[4] + sig[8]) / 3, dev[9], ss = 0;
    for (int k = 0; k < 9; k++) {
        dev[k] = sig[k] - ((k % 4) == 0 ? m : 0);
        ss += dev[k] * dev[k];
    }
    double seq = sqrt(1.5 * ss), sc = fmax(0, s->crush_k - s->crush_beta * m);
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

/* The kernel below runs LANES tets side by side (lanes.h): every per-tet
 * number is a vector, so the core overlaps the lanes' long dependent chains
 * (the rotation's square roots and divisions).  Each lane does
 * exactly the operations of the scalar formulas (linalg.h: m3_mul,
 * polar_rotation, ...) in the same order: the bits are those of one tet at
 * a time (test_tet4.c compares them). */
typedef vd lane9[9];

static inline vd v_fabs(vd a) { return (vd)((vm)a & ~(vm)splat(-0.0)); } /* sign bit off */

/* fmax and fmin lane by lane: a NaN operand gives the other one. */
static inline vd v_fmax(vd a, vd b) { return pick((vm)(a >= b) | (vm)(b != b), a, b); }
static inline vd v_fmin(vd a, vd b) { return pick((vm)(a <= b) | (vm)(b != b), a, b); }

/* Whether any lane of the mask m is set. */
static inline int lanes_any(vm m)
{
    int any = 0;
    for (int l = 0; l < LANES; l++)
        any |= m[l] != 0;
    return any;
}

/* Whether any lane's stress sig lies outside crush's yield surface: its
 * test, the same operations lane by lane.  Most tets of a body in fracture
 * mode never crush, and a block whose four do not skips the return, which
 * goes lane by lane. */
static inline __attribute__((always_inline)) int lanes_yield(const cf_solid *s, vd sig[9])
{
    vd m = (sig[0] + sig[4] + sig[8]) / 3, ss = splat(0);
    for (int k = 0; k < 9; k++) {
        vd dev = sig[k] - ((k % 4) == 0 ? m : splat(0));
        ss += dev * dev;
    }
    vd seq = v_sqrt(1.5 * ss), sc = v_fmax(splat(0), s->crush_k - s->crush_beta * m);
    return lanes_any((vm)(seq > sc));
}

/* C = A B (m3_mul); C is neither A nor B, as in all three products. */
static inline void lanes_mul(lane9 A, lane9 B, lane9 C)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}

/* C = A^T B (m3_mul_tn). */
static inline void lanes_mul_tn(lane9 A, lane9 B, lane9 C)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[3 * i + j] = A[i] * B[j] + A[3 + i] * B[3 + j] + A[6 + i] * B[6 + j];
}

/* C = A B^T (m3_mul_nt). */
static inline void lanes_mul_nt(lane9 A, lane9 B, lane9 C)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[3 * i + j] = A[3 * i] * B[3 * j] + A[3 * i + 1] * B[3 * j + 1] +
                           A[3 * i + 2] * B[3 * j + 2];
}

/* q /= |q|, the identity where |q| = 0 (quat_normalize); such a lane
 * divides by 1 and drops the result. */
static inline void lanes_quat_normalize(vd q[4])
{
    vd n = v_sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    vm zero = (vm)(n == splat(0.0));
    vd d = pick(zero, splat(1.0), n);
    for (int k = 0; k < 4; k++)
        q[k] = pick(zero, splat(k == 0), q[k] / d);
}

/* R of q (quat_to_mat). */
static inline void lanes_quat_to_mat(vd q[4], lane9 R)
{
    vd w = q[0], x = q[1], y = q[2], z = q[3];
    R[0] = 1 - 2 * (y * y + z * z), R[1] = 2 * (x * y - w * z), R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z), R[4] = 1 - 2 * (x * x + z * z), R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y), R[7] = 2 * (y * z + w * x), R[8] = 1 - 2 * (x * x + y * y);
}

/* |q|^2 R of q of any length (quat_to_mat_scaled). */
static inline void lanes_quat_to_mat_scaled(vd q[4], lane9 R)
{
    vd w = q[0], x = q[1], y = q[2], z = q[3], ww = w * w, xx = x * x, yy = y * y, zz = z * z;
    R[0] = ww + xx - yy - zz, R[1] = 2 * (x * y - w * z), R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z), R[4] = ww - xx + yy - zz, R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y), R[7] = 2 * (y * z + w * x), R[8] = ww - xx - yy + zz;
}

/* The rotation part R of F by the quaternion iteration (polar_rotation in
 * linalg.h: Müller, Bender, Chentanez, Macklin 2016), q the warm start,
 * updated.  All lanes evaluate the update until none still turns: a lane
 * whose update fell below tol keeps q, so evaluating it again gives the
 * same update and the same stop.  The turns leave q's length as it comes
 * (the update does not depend on it): one square root and normalisation at
 * the end, none per turn. */
static inline __attribute__((always_inline)) void lanes_polar_rotation(lane9 F, vd q[4],
                                                                       int max_iter, double tol,
                                                                       lane9 R)
{
    vm zero = (vm)(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] == splat(0.0));
    for (int k = 0; k < 4; k++)
        q[k] = pick(zero, splat(k == 0), q[k]);
    for (int it = 0; it < max_iter; it++) {
        lanes_quat_to_mat_scaled(q, R);
        vd om[3] = {splat(0), splat(0), splat(0)}, dot = splat(0);
        for (int c = 0; c < 3; c++) {
            vd r0 = R[c], r1 = R[3 + c], r2 = R[6 + c], f0 = F[c], f1 = F[3 + c], f2 = F[6 + c];
            om[0] += r1 * f2 - r2 * f1;
            om[1] += r2 * f0 - r0 * f2;
            om[2] += r0 * f1 - r1 * f0;
            dot += r0 * f0 + r1 * f1 + r2 * f2;
        }
        vd s = 1.0 / (v_fabs(dot) + 1e-9);
        for (int k = 0; k < 3; k++)
            om[k] *= s;
        vd angle2 = om[0] * om[0] + om[1] * om[1] + om[2] * om[2];
        vm turn = ~(vm)(angle2 < splat(tol * tol)); /* NaN turns, as in the scalar loop */
        if (!lanes_any(turn))
            break;
        /* q <- (1, omega/2) q where the lane turns (polar_turn); a finished
         * lane's result is dropped */
        vd h[3] = {0.5 * om[0], 0.5 * om[1], 0.5 * om[2]};
        vd nq[4] = {q[0] - h[0] * q[1] - h[1] * q[2] - h[2] * q[3],
                    q[1] + h[0] * q[0] + h[1] * q[3] - h[2] * q[2],
                    q[2] - h[0] * q[3] + h[1] * q[0] + h[2] * q[1],
                    q[3] + h[0] * q[2] - h[1] * q[1] + h[2] * q[0]};
        for (int k = 0; k < 4; k++)
            q[k] = pick(turn, nq[k], q[k]);
    }
    lanes_quat_normalize(q);
    lanes_quat_to_mat(q, R);
}

/* The edge matrix [u1 - u0, u2 - u0, u3 - u0] (columns) of the nodal field
 * u (x or v, [n][3]) over tets t[0..LANES-1]: Ds of the positions, its rate
 * of the velocities. */
static inline __attribute__((always_inline)) void lanes_edges(const cf_solid *s, const double *u,
                                                              const int t[LANES], lane9 E)
{
    vd U[4][3]; /* the tets' nodes' values */
    for (int j = 0; j < 4; j++) {
        int node[LANES];
        for (int l = 0; l < LANES; l++)
            node[l] = s->tet[4 * t[l] + j];
        lanes_load(u, 3, node, U[j]);
    }
    for (int j = 0; j < 3; j++)
        for (int r = 0; r < 3; r++)
            E[3 * r + j] = U[j + 1][r] - U[0][r];
}

/* What one pass finds for LANES tets. */
typedef struct {
    lane9 Di;  /* inverse rest edge matrix: rows grad N1..N3, 1/m */
    lane9 F;   /* deformation gradient */
    lane9 R;   /* rotation to the world (identity for small strain) */
    lane9 sig; /* stress in the element frame, Pa */
    vd q[4];   /* the rotation's quaternion: the next warm start */
    vd ep[6];  /* plastic strain after this pass (crushing) */
    vd w;      /* strain energy density, J/m^3 */
    vd wp;     /* plastic work density of this pass, J/m^3 */
} tet_lanes;

/* Deformation gradient, rotation, element-frame stress (Hooke on the
 * strain less the plastic strain, then the return to the yield surface
 * when crushing) and energy densities of tets t[0..LANES-1] at the current
 * positions, from the warm starts s->rq and plastic strains s->ep, which
 * it reads only: the new ones are in L. */
static inline __attribute__((always_inline)) void tet_lanes_eval(const cf_solid *s,
                                                                 const int t[LANES],
                                                                 cf_elasticity kind, tet_lanes *L)
{
    lane9 Ds;
    lanes_edges(s, s->x, t, Ds);
    lanes_load(s->Dm_inv, 9, t, L->Di);
    lanes_mul(Ds, L->Di, L->F);
    lane9 S; /* the stretch whose symmetric part less I is the strain */
    if (kind == CF_ELASTICITY_COROTATIONAL) {
        lanes_load(s->rq, 4, t, L->q);
        lanes_polar_rotation(L->F, L->q, 10, 1e-7, L->R);
        lanes_mul_tn(L->R, L->F, S);
    } else {
        for (int k = 0; k < 9; k++)
            L->R[k] = splat((k % 4) == 0), S[k] = L->F[k];
    }
    /* Hooke (hooke's formulas) */
    lane9 eps;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            eps[3 * i + j] = 0.5 * (S[3 * i + j] + S[3 * j + i]) - (double)(i == j);
    L->wp = splat(0);
    if (s->ep) {
        lanes_load(s->ep, 6, t, L->ep);
        for (int v = 0; v < 6; v++) {
            int i = VOIGT[v][0], j = VOIGT[v][1];
            eps[3 * i + j] -= L->ep[v];
            if (i != j)
                eps[3 * j + i] -= L->ep[v];
        }
    }
    vd tr = eps[0] + eps[4] + eps[8];
    for (int k = 0; k < 9; k++)
        L->sig[k] = 2 * s->mu * eps[k] + ((k % 4) == 0 ? s->lambda * tr : splat(0));
    if (s->ep && lanes_yield(s, L->sig))
        for (int l = 0; l < LANES; l++) {
            double sg[9], e[9], ep[6];
            for (int k = 0; k < 9; k++)
                sg[k] = L->sig[k][l], e[k] = eps[k][l];
            for (int v = 0; v < 6; v++)
                ep[v] = L->ep[v][l];
            L->wp[l] = crush(s, sg, e, ep);
            for (int k = 0; k < 9; k++)
                L->sig[k][l] = sg[k], eps[k][l] = e[k];
            for (int v = 0; v < 6; v++)
                L->ep[v][l] = ep[v];
        }
    L->w = splat(0);
    for (int k = 0; k < 9; k++)
        L->w += 0.5 * L->sig[k] * eps[k];
}

/* Bounds of a symmetric 3x3 matrix's eigenvalues: every one lies in
 * [lo, hi].  Two bounds, the tighter taken: Gershgorin's discs, and the
 * deviator's, |lambda - q| <= sqrt(2/3 |A - q I|^2) with q the mean of the
 * diagonal (the deviator's eigenvalues sum to zero, so the largest of them
 * in magnitude is at most sqrt(2/3) times their norm; equality for a
 * uniaxial stress, which Gershgorin overestimates in a frame that is not
 * its own).  Both ends are widened by 1e-9 of the deviator bound's size
 * so that rounding cannot bring either inside an eigenvalue, or below the
 * largest one max_principal (insertion.c) finds.  The element-frame and
 * world-frame stresses are similar matrices, so these bound the world
 * stress's principal values too. */
static inline void principal_bounds(lane9 A, vd *lo, vd *hi)
{
    vd r0 = v_fabs(A[1]) + v_fabs(A[2]), r1 = v_fabs(A[1]) + v_fabs(A[5]),
       r2 = v_fabs(A[2]) + v_fabs(A[5]);
    vd g_hi = v_fmax(A[0] + r0, v_fmax(A[4] + r1, A[8] + r2));
    vd g_lo = v_fmin(A[0] - r0, v_fmin(A[4] - r1, A[8] - r2));
    vd q = (A[0] + A[4] + A[8]) / 3, d0 = A[0] - q, d1 = A[4] - q, d2 = A[8] - q;
    vd dev2 = d0 * d0 + d1 * d1 + d2 * d2 + 2 * (A[1] * A[1] + A[2] * A[2] + A[5] * A[5]);
    vd r = v_sqrt((2.0 / 3.0) * dev2), w = 1e-9 * (r + v_fabs(q));
    *hi = v_fmin(g_hi, q + r) + w;
    *lo = v_fmax(g_lo, q - r) - w;
}

double cf_tet4_max_principal_bound(const double A[9])
{
    lane9 a;
    for (int k = 0; k < 9; k++)
        a[k] = splat(A[k]);
    vd lo, hi;
    principal_bounds(a, &lo, &hi);
    return hi[0];
}

/* det F (m3_det) */
static inline vd lanes_det(lane9 A)
{
    return A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
           A[2] * (A[3] * A[7] - A[4] * A[6]);
}

/* tr(R^T A): with A = dF/dt the volumetric strain rate in the frame R
 * (1/s), zero for a rigid motion. */
static inline __attribute__((always_inline)) vd lanes_trace_tn(lane9 R, lane9 A)
{
    vd tr = splat(0);
    for (int k = 0; k < 9; k++)
        tr += R[k] * A[k];
    return tr;
}

/* Linear bulk viscosity (docs/physics.md §2.3): the pressure -eta D of the
 * volumetric strain rate D added to the first stress P of tets t (P += eta
 * D R, live lanes only), and its work over the step of length dt that
 * ended at these positions, booked per tet.  The leapfrog gives up
 * 1/2 (f' + f) . (x - x') to a force (§10); the nodes moved by dt v, v the
 * velocities this pass reads, so with f = -V eta D R grad N the viscosity
 * took 1/2 V eta dt (D' D_R' + D^2), D' the last pass's rate and D_R' this
 * motion's rate in the last pass's frame R' (the rotation's warm start). */
/* (always inlined, as every helper that takes a vector by value: the
 * kernel's clones for wider vector units would pass it otherwise than a
 * plain function takes it) */
static inline __attribute__((always_inline)) void bulk_viscosity(cf_solid *s, const int t[LANES],
                                                                 int n, tet_lanes *L,
                                                                 cf_elasticity kind, vd live,
                                                                 vd vol, double dt, lane9 P)
{
    vd eta, last;
    lanes_load(s->bv_eta, 1, t, &eta);
    lanes_load(s->bv_rate, 1, t, &last);
    eta *= live;
    lane9 Vs, Fdot; /* dF/dt from the nodes' velocities, as F from their positions */
    lanes_edges(s, s->v, t, Vs);
    lanes_mul(Vs, L->Di, Fdot);
    vd rate = lanes_trace_tn(L->R, Fdot), rate_then = rate;
    if (kind == CF_ELASTICITY_COROTATIONAL) { /* s->rq: the last pass's rotation */
        vd q[4];
        lane9 R0;
        lanes_load(s->rq, 4, t, q);
        lanes_quat_to_mat(q, R0);
        rate_then = lanes_trace_tn(R0, Fdot);
    }
    for (int k = 0; k < 9; k++)
        P[k] += eta * rate * L->R[k];
    vd work = 0.5 * vol * eta * dt * (last * rate_then + rate * rate);
    for (int l = 0; l < n; l++)
        s->bv_work[t[l]] += work[l], s->bv_rate[t[l]] = rate[l];
}

/* The skew part a plastic tet's stress needs for its forces to be the
 * gradient of its strain energy, added to P = R sigma (Pa).  The strain is
 * sym(U) - I - ep with U = R^T F, R the polar rotation, and
 * dW = sigma : dU; with R^T dF = dU + Omega U (Omega = R^T dR, skew),
 * P = R (sigma + A) gives P : dF = sigma : dU for every dF exactly when
 * (sigma + A) U is symmetric, i.e. A U + U A = U sigma - sigma U.  For a
 * skew A = [a]x and a symmetric U, A U + U A = [((tr U) I - U) a]x, so
 * a = ((tr U) I - U)^-1 c, with [c]x = U sigma - sigma U.  An elastic
 * sigma, a polynomial of U, commutes with it (A = 0); a plastic strain in
 * another direction does not, and without A the forces did work that
 * neither the strain energy nor the plastic work counts (about 1 % of
 * the crushing work of the plaster sphere drops), and held a moment:
 * P F^T = R (sigma U) R^T was not symmetric (docs/physics.md §2.1). */
static void plastic_spin(const double R[9], const double F[9], const double sig[9],
                         double dP[9])
{
    double S[9], U[9], US[9], SU[9], M[9], Mi[9], c[3], a[3];
    m3_mul_tn(R, F, S);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            U[3 * i + j] = 0.5 * (S[3 * i + j] + S[3 * j + i]);
    m3_mul(U, sig, US);
    m3_mul(sig, U, SU);
    c[0] = 0.5 * ((US[7] - SU[7]) - (US[5] - SU[5]));
    c[1] = 0.5 * ((US[2] - SU[2]) - (US[6] - SU[6]));
    c[2] = 0.5 * ((US[3] - SU[3]) - (US[1] - SU[1]));
    double tr = U[0] + U[4] + U[8];
    for (int k = 0; k < 9; k++)
        M[k] = ((k % 4) == 0 ? tr : 0) - U[k];
    if (!(m3_inv(M, Mi) > 0)) { /* a tet turned inside out: no spin to add */
        memset(dP, 0, 9 * sizeof(double));
        return;
    }
    m3_mulv(Mi, c, a);
    double A[9] = {0, -a[2], a[1], a[2], 0, -a[0], -a[1], a[0], 0};
    m3_mul(R, A, dP);
}

/* cf_tet4_forces for tets t[0..n-1], n <= LANES (the missing lanes repeat
 * the first tet and are dropped); counts inverted and hot tets. */
CF_LANE_CLONES static void tet_block(cf_solid *s, const int *tets, int n, cf_elasticity kind,
                      const cf_stress_check *check, double dt, int *inverted, int *hot)
{
    int t[LANES];
    for (int l = 0; l < LANES; l++)
        t[l] = tets[l < n ? l : 0];
    tet_lanes L;
    tet_lanes_eval(s, t, kind, &L);
    lane9 P, Pf, *G = &L.Di; /* P = R sigma, Pf with the viscosity; G: rows grad N1..N3 */
    lanes_mul(L.R, L.sig, P);
    vd vol = {s->vol[t[0]], s->vol[t[1]], s->vol[t[2]], s->vol[t[3]]}, v = -vol;
    vd live = splat(1); /* a crushed tet is powder: it carries nothing (§2.2) */
    if (s->crushed)
        for (int l = 0; l < LANES; l++)
            live[l] = !s->crushed[t[l]];
    for (int k = 0; k < 9; k++)
        Pf[k] = P[k];
    /* The plastic tets' spin (the check reads the symmetric sigma).  Small
     * strain needs none: with R = I, sigma : sym(dF) = sigma : dF. */
    if (s->ep && kind == CF_ELASTICITY_COROTATIONAL)
        for (int l = 0; l < n; l++) {
            if (!(L.ep[0][l] != 0 || L.ep[1][l] != 0 || L.ep[2][l] != 0 || L.ep[3][l] != 0 ||
                  L.ep[4][l] != 0 || L.ep[5][l] != 0))
                continue;
            double R[9], F[9], sg[9], dP[9];
            for (int k = 0; k < 9; k++)
                R[k] = L.R[k][l], F[k] = L.F[k][l], sg[k] = L.sig[k][l];
            plastic_spin(R, F, sg, dP);
            for (int k = 0; k < 9; k++)
                Pf[k][l] += dP[k];
        }
    if (s->bv_eta) /* a force, not a stress of the material: the check reads P */
        bulk_viscosity(s, t, n, &L, kind, live, vol, dt, Pf);
    vd f[12]; /* f_a = -V P grad N_a, grad N0 = -(grad N1 + grad N2 + grad N3) */
    for (int a = 0; a < 4; a++) {
        vd g[3];
        for (int c = 0; c < 3; c++)
            g[c] = a ? (*G)[3 * (a - 1) + c] : -((*G)[c] + (*G)[3 + c] + (*G)[6 + c]);
        for (int r = 0; r < 3; r++)
            f[3 * a + r] = v * (Pf[3 * r] * g[0] + Pf[3 * r + 1] * g[1] + Pf[3 * r + 2] * g[2]);
    }
    if (s->crushed) {
        for (int k = 0; k < 12; k++)
            f[k] *= live;
        for (int k = 0; k < 9; k++)
            P[k] *= live;
    }
    lanes_store(f, 12, s->tf, t, n);
    if (kind == CF_ELASTICITY_COROTATIONAL)
        lanes_store(L.q, 4, s->rq, t, n);
    if (s->ep)
        lanes_store(L.ep, 6, s->ep, t, n);
    vd w = L.w * vol * live, wp = L.wp * vol * live, det = lanes_det(L.F);
    vm is_hot = {0};
    if (check) {
        lane9 sigma;
        lanes_mul_nt(P, L.R, sigma); /* R sigma R^T */
        lanes_store(sigma, 9, s->sigma, t, n);
        vd lo, hi, s1 = splat(check->s1);
        principal_bounds(L.sig, &lo, &hi);
        if (check->s1_tet)
            for (int l = 0; l < LANES; l++)
                s1[l] = fmax(s1[l], check->s1_tet[t[l]]);
        is_hot = ((vm)(hi >= s1) | (vm)(0.5 * (hi - lo) >= splat(check->tau))) &
                 (vm)(live > 0);
    }
    for (int l = 0; l < n; l++) {
        int e = t[l];
        *inverted += det[l] <= 0 && live[l] > 0;
        s->tw[e] = w[l];
        if (s->ep)
            s->wp[e] += wp[l];
        if (check) {
            s->hot[e] = is_hot[l] != 0;
            *hot += s->hot[e];
        }
    }
}

int cf_tet4_forces(cf_solid *s, const int *tets, int nt, cf_elasticity kind,
                   const cf_stress_check *check, double dt, int *n_hot)
{
    int inverted = 0, hot = 0;
    /* Threads only for fragments large enough to repay the fork and join:
     * hundreds of few-tet fragments in fracture mode ran slower on 2
     * threads than on 1. */
    CF_PARALLEL(nt >= CF_TET4_PARALLEL_MIN,
                "omp parallel for schedule(static) reduction(+ : inverted, hot)",
        for (int i0 = 0; i0 < nt; i0 += LANES)
            tet_block(s, &tets[i0], nt - i0 < LANES ? nt - i0 : LANES, kind, check, dt,
                      &inverted, &hot););
    if (n_hot)
        *n_hot = hot;
    return inverted;
}

void cf_tet4_stress(const cf_solid *s, int t, cf_elasticity kind, double sigma[9])
{
    int lanes[LANES] = {t, t, t, t};
    tet_lanes L;
    tet_lanes_eval(s, lanes, kind, &L);
    lane9 P, out;
    lanes_mul(L.R, L.sig, P);
    lanes_mul_nt(P, L.R, out);
    for (int k = 0; k < 9; k++)
        sigma[k] = out[k][0];
}

double cf_tet4_energy_now(const cf_solid *s, const int *tets, int nt, cf_elasticity kind)
{
    double e = 0;
    for (int i = 0; i < nt; i += LANES) {
        int t[LANES], n = nt - i < LANES ? nt - i : LANES;
        for (int l = 0; l < LANES; l++)
            t[l] = tets[i + (l < n ? l : 0)];
        tet_lanes L;
        tet_lanes_eval(s, t, kind, &L);
        for (int l = 0; l < n; l++)
            e += (L.w[l] + L.wp[l]) * s->vol[t[l]];
    }
    return e;
}

void cf_tet4_to_rigid(cf_solid *s, const int *tets, int nt)
{
    if (s->ep)
        for (int i = 0; i < nt; i++)
            memset(&s->ep[6 * tets[i]], 0, 6 * sizeof(double));
    if (s->bv_rate) /* at rest in rigid mode: the next spell's first pass has no last force */
        for (int i = 0; i < nt; i++)
            s->bv_rate[tets[i]] = 0;
}

void cf_tet4_scatter(cf_solid *s, const int *tets, int nt, const int *nodes, int nn,
                     const double g[3])
{
    int lo = 0, hi = -1; /* the fragment's node numbers span [lo, hi] */
    for (int i = 0; i < nn; i++) {
        lo = i == 0 || nodes[i] < lo ? nodes[i] : lo;
        hi = nodes[i] > hi ? nodes[i] : hi;
    }
    /* Each thread owns a run of node numbers and streams the whole tet
     * list, adding only at its own nodes: a node's sum never crosses a
     * thread, so it is the tet-order sum for any thread count.  With the
     * nodes and tets in space-filling-curve order (renumber.h) the owner
     * test is a long run of the same answer. */
    CF_PARALLEL(nt >= CF_TET4_PARALLEL_MIN, "omp parallel",
        {
            long span = (long)hi - lo + 1, nth = CF_TEAM_SIZE, me = CF_TEAM_RANK;
            int a0 = lo + (int)(span * me / nth), a1 = lo + (int)(span * (me + 1) / nth);
            for (int i = 0; i < nn; i++) {
                int a = nodes[i];
                if (a >= a0 && a < a1)
                    for (int k = 0; k < 3; k++)
                        s->f[3 * a + k] = s->m[a] * g[k];
            }
            for (int i = 0; i < nt; i++) {
                const int *tn = &s->tet[4 * tets[i]];
                const double *tf = &s->tf[12 * tets[i]];
                for (int j = 0; j < 4; j++) {
                    int a = tn[j];
                    if (a >= a0 && a < a1)
                        for (int k = 0; k < 3; k++)
                            s->f[3 * a + k] += tf[3 * j + k];
                }
            }
        });
}

typedef struct {
    const cf_solid *s;
    const int *tets;
} tet_list;

static void energy_chunk(void *ctx, int i0, int i1, double *acc)
{
    const tet_list *c = ctx;
    for (int i = i0; i < i1; i++)
        acc[0] += c->s->tw[c->tets[i]];
}

double cf_tet4_strain_energy(const cf_solid *s, const int *tets, int nt)
{
    tet_list c = {s, tets};
    double e;
    cf_sum_chunks(nt, 1, 1, energy_chunk, &c, &e); /* the same sum for any thread count */
    return e;
}
