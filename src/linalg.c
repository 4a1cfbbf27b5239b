#include "linalg.h"

#include <string.h>

void points_bbox(const double *x, int n, double lo[3], double hi[3])
{
    for (int k = 0; k < 3; k++)
        lo[k] = INFINITY, hi[k] = -INFINITY;
    for (int i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], x[3 * i + k]);
            hi[k] = fmax(hi[k], x[3 * i + k]);
        }
}

void m3_mul(const double A[9], const double B[9], double out[9])
{
    double C[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
    memcpy(out, C, sizeof C);
}

void m3_mul_tn(const double A[9], const double B[9], double out[9])
{
    double C[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[3 * i + j] = A[i] * B[j] + A[3 + i] * B[3 + j] + A[6 + i] * B[6 + j];
    memcpy(out, C, sizeof C);
}

void m3_mul_nt(const double A[9], const double B[9], double out[9])
{
    double C[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[3 * i + j] = A[3 * i] * B[3 * j] + A[3 * i + 1] * B[3 * j + 1] + A[3 * i + 2] * B[3 * j + 2];
    memcpy(out, C, sizeof C);
}

double m3_det(const double A[9])
{
    return A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
           A[2] * (A[3] * A[7] - A[4] * A[6]);
}

double m3_inv(const double A[9], double out[9])
{
    double d = m3_det(A);
    if (d == 0.0)
        return 0.0;
    double id = 1.0 / d, C[9];
    C[0] = (A[4] * A[8] - A[5] * A[7]) * id;
    C[1] = (A[2] * A[7] - A[1] * A[8]) * id;
    C[2] = (A[1] * A[5] - A[2] * A[4]) * id;
    C[3] = (A[5] * A[6] - A[3] * A[8]) * id;
    C[4] = (A[0] * A[8] - A[2] * A[6]) * id;
    C[5] = (A[2] * A[3] - A[0] * A[5]) * id;
    C[6] = (A[3] * A[7] - A[4] * A[6]) * id;
    C[7] = (A[1] * A[6] - A[0] * A[7]) * id;
    C[8] = (A[0] * A[4] - A[1] * A[3]) * id;
    memcpy(out, C, sizeof C);
    return d;
}

void quat_normalize(double q[4])
{
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (n == 0.0) {
        q[0] = 1, q[1] = q[2] = q[3] = 0;
        return;
    }
    for (int i = 0; i < 4; i++)
        q[i] /= n;
}

void quat_to_mat(const double q[4], double R[9])
{
    double w = q[0], x = q[1], y = q[2], z = q[3];
    R[0] = 1 - 2 * (y * y + z * z), R[1] = 2 * (x * y - w * z), R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z), R[4] = 1 - 2 * (x * x + z * z), R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y), R[7] = 2 * (y * z + w * x), R[8] = 1 - 2 * (x * x + y * y);
}

void mat_to_quat(const double R[9], double q[4])
{
    double tr = R[0] + R[4] + R[8];
    if (tr > 0) {
        double s = sqrt(tr + 1.0) * 2;
        q[0] = 0.25 * s, q[1] = (R[7] - R[5]) / s, q[2] = (R[2] - R[6]) / s, q[3] = (R[3] - R[1]) / s;
    } else if (R[0] > R[4] && R[0] > R[8]) {
        double s = sqrt(1.0 + R[0] - R[4] - R[8]) * 2;
        q[0] = (R[7] - R[5]) / s, q[1] = 0.25 * s, q[2] = (R[1] + R[3]) / s, q[3] = (R[2] + R[6]) / s;
    } else if (R[4] > R[8]) {
        double s = sqrt(1.0 + R[4] - R[0] - R[8]) * 2;
        q[0] = (R[2] - R[6]) / s, q[1] = (R[1] + R[3]) / s, q[2] = 0.25 * s, q[3] = (R[5] + R[7]) / s;
    } else {
        double s = sqrt(1.0 + R[8] - R[0] - R[4]) * 2;
        q[0] = (R[3] - R[1]) / s, q[1] = (R[2] + R[6]) / s, q[2] = (R[5] + R[7]) / s, q[3] = 0.25 * s;
    }
    if (q[0] < 0)
        for (int i = 0; i < 4; i++)
            q[i] = -q[i];
    quat_normalize(q);
}

void polar_rotation(const double F[9], double q[4], int max_iter, double tol, double R[9])
{
    quat_normalize(q);
    for (int it = 0; it < max_iter; it++) {
        quat_to_mat(q, R);
        /* Columns of R and F; omega = sum r_i x f_i / (|sum r_i . f_i| + eps). */
        double om[3] = {0, 0, 0}, dotsum = 0;
        for (int c = 0; c < 3; c++) {
            double r[3] = {R[c], R[3 + c], R[6 + c]}, f[3] = {F[c], F[3 + c], F[6 + c]}, rf[3];
            v3_cross(r, f, rf);
            om[0] += rf[0], om[1] += rf[1], om[2] += rf[2];
            dotsum += v3_dot(r, f);
        }
        double s = 1.0 / (fabs(dotsum) + 1e-9);
        om[0] *= s, om[1] *= s, om[2] *= s;
        double angle = v3_norm(om);
        if (angle < tol)
            break;
        double half = 0.5 * angle, sh = sin(half) / angle;
        double dq[4] = {cos(half), om[0] * sh, om[1] * sh, om[2] * sh};
        /* q <- dq * q */
        double nq[4] = {dq[0] * q[0] - dq[1] * q[1] - dq[2] * q[2] - dq[3] * q[3],
                        dq[0] * q[1] + dq[1] * q[0] + dq[2] * q[3] - dq[3] * q[2],
                        dq[0] * q[2] - dq[1] * q[3] + dq[2] * q[0] + dq[3] * q[1],
                        dq[0] * q[3] + dq[1] * q[2] - dq[2] * q[1] + dq[3] * q[0]};
        memcpy(q, nq, sizeof nq);
        quat_normalize(q);
    }
    quat_to_mat(q, R);
}

void sym3_eigen(const double A[9], double w[3], double V[9])
{
    double a[9];
    memcpy(a, A, sizeof a);
    double v[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = a[1] * a[1] + a[2] * a[2] + a[5] * a[5];
        double diag = a[0] * a[0] + a[4] * a[4] + a[8] * a[8];
        if (off <= 1e-30 * diag || off == 0.0)
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                double apq = a[3 * p + q];
                if (apq == 0.0)
                    continue;
                double theta = (a[3 * q + q] - a[3 * p + p]) / (2 * apq);
                double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1));
                double c = 1 / sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < 3; k++) { /* A <- J^T A J */
                    double akp = a[3 * k + p], akq = a[3 * k + q];
                    a[3 * k + p] = c * akp - s * akq;
                    a[3 * k + q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) {
                    double apk = a[3 * p + k], aqk = a[3 * q + k];
                    a[3 * p + k] = c * apk - s * aqk;
                    a[3 * q + k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; k++) {
                    double vkp = v[3 * k + p], vkq = v[3 * k + q];
                    v[3 * k + p] = c * vkp - s * vkq;
                    v[3 * k + q] = s * vkp + c * vkq;
                }
            }
    }
    w[0] = a[0], w[1] = a[4], w[2] = a[8];
    if (m3_det(v) < 0)
        for (int k = 0; k < 3; k++)
            v[3 * k + 2] = -v[3 * k + 2];
    memcpy(V, v, sizeof v);
}
