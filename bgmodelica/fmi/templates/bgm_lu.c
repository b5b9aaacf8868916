/* The embedded solvers' linear algebra: the iteration matrix I - coef*J and its LU
 * factorisation with partial pivoting, inside the band of the Jacobian's structural pattern
 * (BGM_JAC_KL, BGM_JAC_KU from bgm_model_data.h; a test may define them on the command line).
 */
#include <math.h>

#ifndef BGM_JAC_KL
#include "bgm_core.h"
#endif

/* The Jacobian's bandwidths (bgm_model_data.h): nonzeros only where -KL <= j - i <= KU. With
   partial pivoting the factors stay inside KL rows below and KL + KU columns right of the
   diagonal, so the loops below touch only that band of the n x n row-major storage (all of it
   for a dense Jacobian, KL = KU = n - 1). */
#define BGM_BAND_LO(i) ((i) > BGM_JAC_KL ? (i) - BGM_JAC_KL : 0)
#define BGM_BAND_HI(i, n) ((i) + BGM_JAC_KL + BGM_JAC_KU < (n) ? (i) + BGM_JAC_KL + BGM_JAC_KU : (n) - 1)

/* m = I - coef * J inside the band (row-major m; J column-major, as generated) */
void bgm_iteration_matrix(double *m, const double *J, double coef, int n) {
    int i, j;
    for (i = 0; i < n; i++)
        for (j = BGM_BAND_LO(i); j <= BGM_BAND_HI(i, n); j++)
            m[i * n + j] = (i == j ? 1.0 : 0.0) - coef * J[i + j * n];
}

/* LU factorisation with partial pivoting of the band of the row-major n x n matrix a, in
   place (LAPACK's gbtrf scheme): at step k the pivot row is swapped with row k over the
   columns k.. only, and the multipliers stay where they were computed (column k, rows below),
   so the solve applies the interchanges and eliminations in the same order. */
int bgm_lu_factor(double *a, int *piv, int n) {
    int i, j, k;
    for (k = 0; k < n; k++) {
        int p = k, last_row = k + BGM_JAC_KL < n ? k + BGM_JAC_KL : n - 1;
        int last_col = BGM_BAND_HI(k, n);
        double amax = fabs(a[k * n + k]);
        for (i = k + 1; i <= last_row; i++)
            if (fabs(a[i * n + k]) > amax) {
                amax = fabs(a[i * n + k]);
                p = i;
            }
        piv[k] = p;
        if (amax == 0.0 || !isfinite(amax)) return 1;
        if (p != k)
            for (j = k; j <= last_col; j++) {
                double t = a[k * n + j];
                a[k * n + j] = a[p * n + j];
                a[p * n + j] = t;
            }
        for (i = k + 1; i <= last_row; i++) {
            double m = a[i * n + k] / a[k * n + k];
            a[i * n + k] = m;
            if (m != 0.0)
                for (j = k + 1; j <= last_col; j++) a[i * n + j] -= m * a[k * n + j];
        }
    }
    return 0;
}

void bgm_lu_solve(const double *a, const int *piv, int n, double *b) {
    int i, j, k;
    for (k = 0; k < n; k++) {
        int last_row = k + BGM_JAC_KL < n ? k + BGM_JAC_KL : n - 1;
        if (piv[k] != k) {
            double t = b[k];
            b[k] = b[piv[k]];
            b[piv[k]] = t;
        }
        for (i = k + 1; i <= last_row; i++) b[i] -= a[i * n + k] * b[k];
    }
    for (i = n - 1; i >= 0; i--) {
        int last_col = BGM_BAND_HI(i, n);
        for (j = i + 1; j <= last_col; j++) b[i] -= a[i * n + j] * b[j];
        b[i] /= a[i * n + i];
    }
}
