/* Runtime of eomgen's fast backend: the Cholesky factor and its triangular solves, which
 * forward_dynamics and constrained_forward_dynamics use (included in a generated `_fast.c`
 * that has either). Pure C99 on row-major double arrays; needs only <math.h>.
 *
 * Real C source, not a template: eomgen copies the text below the marker line into the module
 * (eomgen.codegen.backends.fast_backend.runtime_source), and tests/test_fast_runtime_c.py
 * compiles this file on its own with -Wall -Wextra -Werror and checks the factor. */
#include <math.h>

/* eomgen: the generated module holds the text below this line. */
/* Cholesky factor of the symmetric n x n matrix A (row-major), in place: A = L L^T with L in
 * A's lower triangle (the strict upper triangle is left as it was). Returns 0, or 2 when a
 * pivot is not above tol (A not positive definite, or numerically singular when tol > 0).
 * *dmax, *dmin: the largest and smallest L_ii. */
static int cholesky(double *A, int n, double tol, double *dmax, double *dmin)
{
    int i, j, k;
    *dmax = 0.0;
    *dmin = HUGE_VAL;
    for (j = 0; j < n; ++j) {
        double d = A[j * n + j];
        for (k = 0; k < j; ++k)
            d -= A[j * n + k] * A[j * n + k];
        if (!(d > tol))
            return 2;
        d = sqrt(d);
        A[j * n + j] = d;
        if (d > *dmax) *dmax = d;
        if (d < *dmin) *dmin = d;
        for (i = j + 1; i < n; ++i) {
            double s = A[i * n + j];
            for (k = 0; k < j; ++k)
                s -= A[i * n + k] * A[j * n + k];
            A[i * n + j] = s / d;
        }
    }
    return 0;
}

/* y <- L^-1 y (forward substitution), L the n x n Cholesky factor of cholesky(). */
static void solve_lower(const double *L, int n, double *y)
{
    int i, k;
    for (i = 0; i < n; ++i) {
        for (k = 0; k < i; ++k)
            y[i] -= L[i * n + k] * y[k];
        y[i] /= L[i * n + i];
    }
}

/* y <- L^-T y (back substitution), L the n x n Cholesky factor of cholesky(). */
static void solve_upper(const double *L, int n, double *y)
{
    int i, k;
    for (i = n - 1; i >= 0; --i) {
        double s = y[i];
        for (k = i + 1; k < n; ++k)
            s -= L[k * n + i] * y[k];
        y[i] = s / L[i * n + i];
    }
}
