/* Small dense linear algebra for 3-vectors, 3x3 matrices (row-major
 * double[9]) and quaternions (w,x,y,z).  Everything the solver needs and
 * nothing more: polar decomposition, symmetric eigen-decomposition, inverse. */
#ifndef COHFRAC_LINALG_H
#define COHFRAC_LINALG_H

#include <math.h>
#include <string.h>

static inline double v3_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline void v3_cross(const double a[3], const double b[3], double out[3])
{
    double c0 = a[1] * b[2] - a[2] * b[1], c1 = a[2] * b[0] - a[0] * b[2],
           c2 = a[0] * b[1] - a[1] * b[0];
    out[0] = c0, out[1] = c1, out[2] = c2;
}
static inline void v3_sub(const double a[3], const double b[3], double out[3])
{
    out[0] = a[0] - b[0], out[1] = a[1] - b[1], out[2] = a[2] - b[2];
}
static inline void v3_axpy(double s, const double a[3], double y[3])
{
    y[0] += s * a[0], y[1] += s * a[1], y[2] += s * a[2];
}
static inline double v3_norm(const double a[3]) { return sqrt(v3_dot(a, a)); }

/* out = A b */
static inline void m3_mulv(const double A[9], const double b[3], double out[3])
{
    double o0 = A[0] * b[0] + A[1] * b[1] + A[2] * b[2];
    double o1 = A[3] * b[0] + A[4] * b[1] + A[5] * b[2];
    double o2 = A[6] * b[0] + A[7] * b[1] + A[8] * b[2];
    out[0] = o0, out[1] = o1, out[2] = o2;
}
/* out = A^T b */
static inline void m3_tmulv(const double A[9], const double b[3], double out[3])
{
    double o0 = A[0] * b[0] + A[3] * b[1] + A[6] * b[2];
    double o1 = A[1] * b[0] + A[4] * b[1] + A[7] * b[2];
    double o2 = A[2] * b[0] + A[5] * b[1] + A[8] * b[2];
    out[0] = o0, out[1] = o1, out[2] = o2;
}

/* Bounding box of n points x[n][3]. */
void points_bbox(const double *x, int n, double lo[3], double hi[3]);

/* out = A B */
static inline void m3_mul(const double A[9], const double B[9], double out[9])
{
    double C[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
    memcpy(out, C, sizeof C);
}
/* out = A^T B */
static inline void m3_mul_tn(const double A[9], const double B[9], double out[9])
{
    double C[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[3 * i + j] = A[i] * B[j] + A[3 + i] * B[3 + j] + A[6 + i] * B[6 + j];
    memcpy(out, C, sizeof C);
}
/* out = A B^T */
static inline void m3_mul_nt(const double A[9], const double B[9], double out[9])
{
    double C[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[3 * i + j] = A[3 * i] * B[3 * j] + A[3 * i + 1] * B[3 * j + 1] + A[3 * i + 2] * B[3 * j + 2];
    memcpy(out, C, sizeof C);
}
static inline double m3_det(const double A[9])
{
    return A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
           A[2] * (A[3] * A[7] - A[4] * A[6]);
}
/* Inverse; returns the determinant (0 and out untouched when singular). */
double m3_inv(const double A[9], double out[9]);

static inline void m3_identity(double R[9])
{
    R[0] = R[4] = R[8] = 1, R[1] = R[2] = R[3] = R[5] = R[6] = R[7] = 0;
}

/* Quaternion (w,x,y,z) <-> rotation matrix; normalise in place. */
static inline void quat_to_mat(const double q[4], double R[9])
{
    double w = q[0], x = q[1], y = q[2], z = q[3];
    R[0] = 1 - 2 * (y * y + z * z), R[1] = 2 * (x * y - w * z), R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z), R[4] = 1 - 2 * (x * x + z * z), R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y), R[7] = 2 * (y * z + w * x), R[8] = 1 - 2 * (x * x + y * y);
}
static inline void quat_normalize(double q[4])
{
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (n == 0.0) {
        q[0] = 1, q[1] = q[2] = q[3] = 0;
        return;
    }
    for (int i = 0; i < 4; i++)
        q[i] /= n;
}

/* |q|^2 times the rotation of q/|q|, for a quaternion q of any length (the
 * homogeneous form of quat_to_mat: no normalisation needed). */
static inline void quat_to_mat_scaled(const double q[4], double R[9])
{
    double w = q[0], x = q[1], y = q[2], z = q[3];
    double ww = w * w, xx = x * x, yy = y * y, zz = z * z;
    R[0] = ww + xx - yy - zz, R[1] = 2 * (x * y - w * z), R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z), R[4] = ww - xx + yy - zz, R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y), R[7] = 2 * (y * z + w * x), R[8] = ww - xx - yy + zz;
}

/* One step of the polar iteration below: the update
 * omega = sum r_i x f_i / (|sum r_i . f_i| + eps) over the columns of F
 * and of R = quat_to_mat_scaled(q) (omega does not depend on the length of
 * q, which stays near 1: eps is for an F with no rotation part);
 * returns |omega|^2 (rad^2). */
static inline double polar_axis(const double F[9], const double q[4], double om[3])
{
    double R[9], dotsum = 0;
    quat_to_mat_scaled(q, R);
    om[0] = om[1] = om[2] = 0;
    for (int c = 0; c < 3; c++) {
        double r[3] = {R[c], R[3 + c], R[6 + c]}, f[3] = {F[c], F[3 + c], F[6 + c]}, rf[3];
        v3_cross(r, f, rf);
        om[0] += rf[0], om[1] += rf[1], om[2] += rf[2];
        dotsum += v3_dot(r, f);
    }
    double s = 1.0 / (fabs(dotsum) + 1e-9);
    om[0] *= s, om[1] *= s, om[2] *= s;
    return v3_dot(om, om);
}

/* q <- (1, omega/2) q: a turn about omega by 2 atan(|omega|/2), which is
 * |omega| less |omega|^3/12, where the paper turns by exactly |omega|
 * (q <- exp(omega/2) q).  The iteration stops at the same fixed point
 * (omega = 0, to within tol), and the update needs no sine or cosine.  The
 * length of q grows by sqrt(1 + |omega|^2/4) and is left so: the iteration
 * does not depend on it, and it is normalised once at the end. */
static inline void polar_turn(double q[4], const double om[3])
{
    double h[3] = {0.5 * om[0], 0.5 * om[1], 0.5 * om[2]};
    double nq[4] = {q[0] - h[0] * q[1] - h[1] * q[2] - h[2] * q[3],
                    q[1] + h[0] * q[0] + h[1] * q[3] - h[2] * q[2],
                    q[2] - h[0] * q[3] + h[1] * q[0] + h[2] * q[1],
                    q[3] + h[0] * q[2] - h[1] * q[1] + h[2] * q[0]};
    memcpy(q, nq, sizeof nq);
}

/* Rotation part R of F = R S (polar decomposition), by the quaternion
 * iteration of Müller, Bender, Chentanez, Macklin 2016 ("A robust method to
 * extract the rotational part of deformations"); q is the warm start (a
 * unit quaternion to rounding, such as the last answer; zero: the
 * identity) and is updated to a unit quaternion (w,x,y,z).  Stops when the
 * update angle falls below tol (rad).  Robust for inverted F (returns a
 * proper rotation). */
static inline void polar_rotation(const double F[9], double q[4], int max_iter, double tol, double R[9])
{
    if (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] == 0)
        q[0] = 1, q[1] = q[2] = q[3] = 0;
    for (int it = 0; it < max_iter; it++) {
        double om[3];
        if (polar_axis(F, q, om) < tol * tol)
            break;
        polar_turn(q, om);
    }
    quat_normalize(q);
    quat_to_mat(q, R);
}

/* Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi:
 * A = V diag(w) V^T, V's columns are the eigenvectors, det V = +1. */
void sym3_eigen(const double A[9], double w[3], double V[9]);

void mat_to_quat(const double R[9], double q[4]);

#endif
