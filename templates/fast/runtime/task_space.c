/* Runtime of eomgen's fast backend: the task-space (operational-space) quantities of one frame,
 * Lambda = (J M^-1 J^T + damping 1)^-1 and Jbar = M^-1 J^T Lambda, by Cholesky factors, which a
 * generated `_fast.c` exporting a task-space function includes after the Cholesky runtime
 * (cholesky.c). Pure C99 on row-major double arrays; the NumPy module's rules
 * (eomgen/runtime/task_space.py).
 *
 * Real C source, not a template: eomgen copies the text below the marker line into the module
 * (eomgen.codegen.backends.fast_backend.runtime_source), and tests/test_fast_runtime_c.py
 * compiles this file on its own with -Wall -Wextra -Werror. */
#include <math.h>
#include <string.h>
#include "cholesky.c"  /* compiled alone: the factor and the solves it uses */

/* eomgen: the generated module holds the text below this line. */
/* task_space_frame refuses, at damping 0, an A = J M^-1 J^T whose Cholesky pivot is not above
 * this times A's largest diagonal entry (cond(A) >~ 1e10: a kinematic singularity, or a
 * direction no joint moves the frame in). */
#define TASK_PIVOT_TOL 1e-10

/* Lambda (r x r) and, unless Jbar is NULL, Jbar (n x r) of the frame whose Jacobian rows are J
 * (r x n, r <= 6), given L, the Cholesky factor of M (cholesky(), in M's lower triangle):
 *   Z = L^-1 J^T (rows Z_i = L^-1 J_i^T),  A = Z^T Z + damping 1 = L_A L_A^T,
 *   W = L_A^-1,  Lambda = W^T W (symmetric to the last bit),  Jbar = L^-T Z Lambda.
 * Z (r x n), A (r x r) and v (n) are work space. Returns 0, or 3 when A is not (numerically)
 * positive definite. */
static int task_space_frame(const double *L, const double *J, int n, int r, double damping,
                            double *Z, double *A, double *v, double *Lam, double *Jbar)
{
    double W[36], dmax, dmin, tol = 0.0;
    int i, j, k;
    for (i = 0; i < r; ++i) {
        memcpy(Z + i * n, J + i * n, sizeof(double) * n);
        solve_lower(L, n, Z + i * n);
    }
    for (i = 0; i < r; ++i) {
        for (j = 0; j <= i; ++j) {
            double a = 0.0;
            for (k = 0; k < n; ++k)
                a += Z[i * n + k] * Z[j * n + k];
            A[i * r + j] = A[j * r + i] = a;
        }
    }
    for (i = 0; i < r; ++i) {
        A[i * r + i] += damping;
        if (!(damping > 0.0) && A[i * r + i] * TASK_PIVOT_TOL > tol)
            tol = A[i * r + i] * TASK_PIVOT_TOL;
    }
    if (cholesky(A, r, tol, &dmax, &dmin))
        return 3;
    for (j = 0; j < r; ++j) {  /* column j of W = L_A^-1, stored as W[j * r + ...] */
        for (i = 0; i < r; ++i)
            W[j * r + i] = i == j ? 1.0 : 0.0;
        solve_lower(A, r, W + j * r);
    }
    for (i = 0; i < r; ++i)
        for (j = 0; j <= i; ++j) {
            double s = 0.0;
            for (k = 0; k < r; ++k)
                s += W[i * r + k] * W[j * r + k];
            Lam[i * r + j] = Lam[j * r + i] = s;
        }
    if (Jbar == NULL)
        return 0;
    for (j = 0; j < r; ++j) {  /* column j of Jbar: L^-T (sum_i Z_i Lambda_ij) */
        for (k = 0; k < n; ++k) {
            double s = 0.0;
            for (i = 0; i < r; ++i)
                s += Z[i * n + k] * Lam[i * r + j];
            v[k] = s;
        }
        solve_upper(L, n, v);
        for (k = 0; k < n; ++k)
            Jbar[k * r + j] = v[k];
    }
    return 0;
}
