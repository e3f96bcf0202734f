/* Runtime of eomgen's fast backend: the constrained forward dynamics (the KKT system of rigid
 * contacts) solved by Cholesky factors, which a generated `_fast.c` exporting
 * constrained_forward_dynamics includes after the Cholesky runtime (cholesky.c). Pure C99 on
 * row-major double arrays.
 *
 * Real C source, not a template: eomgen copies the text below the marker line into the module
 * (eomgen.codegen.backends.fast_backend.runtime_source), and tests/test_fast_runtime_c.py
 * compiles this file on its own with -Wall -Wextra -Werror. */
#include <math.h>
#include <string.h>
#include "cholesky.c"  /* compiled alone: the factor and the solves it uses */

/* eomgen: the generated module holds the text below this line. */
/* constrained_solve refuses, at damping 0, an A = J_c M^-1 J_c^T whose Cholesky pivot is not
 * above this times A's largest diagonal entry (cond(A) >~ 1e10: contact rows dependent to
 * about 1e-5, e.g. redundant contacts or a direction no joint moves). */
#define CONTACT_PIVOT_TOL 1e-10

/* qdd (n) and F (nc) of M qdd + h = tau + J_c^T F_c with J_c qdd + J_c-dot qd = 0, given M
 * (n x n, overwritten by its factor), h = C qd + g (bias), tau, J_c (nc x n) and J_c-dot qd
 * (drift), by Cholesky factors only (the range-space form of the KKT system):
 *   M = L L^T,  w = L^-1 (tau - h),  Z = L^-1 J_c^T (so Z^T Z = J_c M^-1 J_c^T),
 *   A = Z^T Z + damping 1 = L_A L_A^T,  F_c = A^-1 (-J_c-dot qd - Z^T w)  (Z^T w = J_c a,
 *   a = M^-1 (tau - h)),  qdd = L^-T (w + Z F_c) = a + M^-1 J_c^T F_c.
 * Z (nc x n) and A (nc x nc) are work space. Returns 0, 1 when M, h, tau, J_c or J_c-dot qd is
 * not finite, 2 when M is not positive definite, 3 when A is not (numerically) positive
 * definite. */
static int constrained_solve(double *M, const double *bias, const double *tau, const double *J,
                             const double *drift, double damping, int n, int nc, double *Z,
                             double *A, double *qdd, double *F)
{
    double dmax, dmin, tol = 0.0;
    int i, j, k;
    for (i = 0; i < n; ++i) {
        qdd[i] = tau[i] - bias[i];
        if (!isfinite(qdd[i]))
            return 1;
        for (j = 0; j < n; ++j)
            if (!isfinite(M[i * n + j]))
                return 1;
    }
    for (i = 0; i < nc; ++i) {
        if (!isfinite(drift[i]))
            return 1;
        for (j = 0; j < n; ++j)
            if (!isfinite(J[i * n + j]))
                return 1;
    }
    if (cholesky(M, n, 0.0, &dmax, &dmin))
        return 2;
    solve_lower(M, n, qdd);  /* w */
    for (i = 0; i < nc; ++i) {  /* row i of Z^T: L^-1 (row i of J_c)^T */
        memcpy(Z + i * n, J + i * n, sizeof(double) * n);
        solve_lower(M, n, Z + i * n);
    }
    for (i = 0; i < nc; ++i) {
        double s = -drift[i];
        for (k = 0; k < n; ++k)
            s -= Z[i * n + k] * qdd[k];
        F[i] = s;
        for (j = 0; j <= i; ++j) {
            double a = 0.0;
            for (k = 0; k < n; ++k)
                a += Z[i * n + k] * Z[j * n + k];
            A[i * nc + j] = A[j * nc + i] = a;
        }
        A[i * nc + i] += damping;
        if (!(damping > 0.0) && A[i * nc + i] * CONTACT_PIVOT_TOL > tol)
            tol = A[i * nc + i] * CONTACT_PIVOT_TOL;
    }
    if (cholesky(A, nc, tol, &dmax, &dmin))
        return 3;
    solve_lower(A, nc, F);
    solve_upper(A, nc, F);
    for (i = 0; i < nc; ++i)  /* w + Z F_c */
        for (k = 0; k < n; ++k)
            qdd[k] += Z[i * n + k] * F[i];
    solve_upper(M, n, qdd);
    return 0;
}
