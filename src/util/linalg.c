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
