/* Small dense linear algebra for 3-vectors, 3x3 matrices (row-major
 * double[9]) and quaternions (w,x,y,z).  Everything the solver needs and
 * nothing more: polar decomposition, symmetric eigen-decomposition, inverse. */
#ifndef COHFRAC_LINALG_H
#define COHFRAC_LINALG_H

#include <math.h>

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

void m3_mul(const double A[9], const double B[9], double out[9]);
void m3_mul_tn(const double A[9], const double B[9], double out[9]); /* A^T B */
void m3_mul_nt(const double A[9], const double B[9], double out[9]); /* A B^T */
double m3_det(const double A[9]);
/* Inverse; returns the determinant (0 and out untouched when singular). */
double m3_inv(const double A[9], double out[9]);

/* Rotation part R of F = R S (polar decomposition), by the quaternion
 * iteration of Müller, Bender, Chentanez, Macklin 2016 ("A robust method to
 * extract the rotational part of deformations"); q is the warm start and is
 * updated (w,x,y,z).  Stops when the update angle falls below tol (rad).
 * Robust for inverted F (returns a proper rotation). */
void polar_rotation(const double F[9], double q[4], int max_iter, double tol, double R[9]);

/* Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi:
 * A = V diag(w) V^T, V's columns are the eigenvectors, det V = +1. */
void sym3_eigen(const double A[9], double w[3], double V[9]);

void quat_to_mat(const double q[4], double R[9]);
void mat_to_quat(const double R[9], double q[4]);
void quat_normalize(double q[4]);

#endif
