/* The direct model's runs of backward-Euler steps under one step matrix (model/integrate.py,
   `ImplicitEuler.run`), compiled where a C compiler is found (model/compiled.py):

       M T^k+1 = c T^k + v^k,   k = 0 .. L-1,

   M (N x N) the step matrix C/dt - A with the forced nodes' rows unit rows, c (N) C/dt with the
   forced nodes' zeroed, v^k (L x N) each step's sources with the forced nodes' imposed
   temperatures in their place. M comes factorised, P_r M P_c = L U in a fill-reducing order
   (model/compiled.py: a building's walls are chains hung on a few air and radiant nodes, which
   eliminated last leave L and U about as sparse as M), and each step is two sparse triangular
   solves: O(nonzeros of M) where the dense inverse's product is O(N^2). */
#include <stdlib.h>
#include <string.h>

#define EXPORT __attribute__((visibility("default")))

/* perm_r, perm_c (N): b goes to y[perm_r[i]] = b[i], the solution is x[i] = y[perm_c[i]]; L
   (unit diagonal) and U by columns as SuperLU gives them (ptr N + 1, row, val; each column's
   diagonal among its entries). T (N): the temperatures before the first step, after the last on
   return; path (L x R): the temperatures of the nodes rows (R) after each step. Returns 1, or 0
   where memory runs out or U has a zero on its diagonal. */
EXPORT int nodeforce_steps(int n, const int *perm_r, const int *perm_c, const int *l_ptr, const int *l_row,
                           const double *l_val, const int *u_ptr, const int *u_row, const double *u_val,
                           const double *c, long L, const double *v, double *T, int n_rows, const int *rows,
                           double *path) {
    double *y = malloc(((size_t)n + 1) * sizeof(double)), *inverse = malloc(((size_t)n + 1) * sizeof(double));
    long s;
    int i, j, k, ok = 0;
    if (!y || !inverse) goto done;
    for (j = 0; j < n; j++) {
        inverse[j] = 0.0;
        for (k = u_ptr[j]; k < u_ptr[j + 1]; k++)
            if (u_row[k] == j) inverse[j] = 1.0 / u_val[k];
        if (inverse[j] == 0.0) goto done;
    }
    for (s = 0; s < L; s++) {
        const double *v_s = v + s * n;
        double *out = path + s * n_rows;
        /* a forced node's (c = 0) is its imposed temperature whatever T held before */
        for (i = 0; i < n; i++) y[perm_r[i]] = c[i] != 0.0 ? c[i] * T[i] + v_s[i] : v_s[i];
        for (j = 0; j < n; j++) {
            const double y_j = y[j];
            for (k = l_ptr[j]; k < l_ptr[j + 1]; k++)
                if (l_row[k] > j) y[l_row[k]] -= l_val[k] * y_j;
        }
        for (j = n - 1; j >= 0; j--) {
            const double y_j = y[j] *= inverse[j];
            for (k = u_ptr[j]; k < u_ptr[j + 1]; k++)
                if (u_row[k] < j) y[u_row[k]] -= u_val[k] * y_j;
        }
        for (i = 0; i < n; i++) T[i] = y[perm_c[i]];
        for (i = 0; i < n_rows; i++) out[i] = T[rows[i]];
    }
    ok = 1;
done:
    free(y); free(inverse);
    return ok;
}
