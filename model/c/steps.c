/* The direct model's runs of backward-Euler steps under one step matrix (model/integrate.py,
   `ImplicitEuler.run`), compiled where a C compiler is found (model/compiled.py):

       M T^k+1 = c T^k + v^k,   k = 0 .. L-1,

   M (N x N, given by its nonzeros) the step matrix C/dt - A with the forced nodes' rows unit rows,
   c (N) C/dt with the forced nodes' zeroed, v^k (L x N) each step's sources with the forced
   nodes' imposed temperatures in their place. M is factorised once, within its profile
   (profile.h, as the standalone FMU does), and each step is two triangular solves of O(N) on a
   building's network where the dense inverse's product is O(N^2). */
#include "profile.h"

#define EXPORT __attribute__((visibility("default")))

/* T (N): the temperatures before the first step, after the last on return; path (L x R): the
   temperatures of the nodes rows (R) after each step. Returns 1, or 0 where M is singular or
   memory runs out. */
EXPORT int nodeforce_steps(int n, long nonzeros, const int *row, const int *col, const double *value,
                           const double *c, long L, const double *v, double *T, int n_rows, const int *rows,
                           double *path) {
    Profile p = {NULL, NULL, NULL};
    Lu f = {NULL, NULL, NULL};
    int *a = malloc((2 * (size_t)nonzeros + 1) * sizeof(int)), *b = malloc((2 * (size_t)nonzeros + 1) * sizeof(int));
    int *position = malloc(((size_t)n + 1) * sizeof(int));
    double *y = malloc(((size_t)n + 1) * sizeof(double)), *x = malloc(((size_t)n + 1) * sizeof(double));
    long e, pairs = 0, s;
    int i, ok = 0;
    if (!a || !b || !position || !y || !x) goto done;
    /* the links of M's pattern both ways: a forced row's unit row keeps its column's links */
    for (e = 0; e < nonzeros; e++)
        if (row[e] != col[e]) {
            a[pairs] = row[e]; b[pairs++] = col[e];
            a[pairs] = col[e]; b[pairs++] = row[e];
        }
    if (!profile_order(&p, n, a, b, pairs) || !lu_alloc(&f, &p, n)) goto done;
    memset(f.lower, 0, (size_t)p.start[n] * sizeof(double));
    memset(f.upper, 0, (size_t)p.start[n] * sizeof(double));
    memset(f.diagonal, 0, (size_t)n * sizeof(double));
    for (i = 0; i < n; i++) position[p.order[i]] = i;
    for (e = 0; e < nonzeros; e++) {
        int r = position[row[e]], k = position[col[e]];
        if (r == k) f.diagonal[r] += value[e];
        else if (k < r) lu_row(f.lower, &p, r)[k] += value[e];
        else lu_row(f.upper, &p, k)[r] += value[e];
    }
    if (!profile_factor(&f, &p, n)) goto done;
    for (s = 0; s < L; s++) {
        const double *v_s = v + s * n;
        double *out = path + s * n_rows;
        /* a forced node's (c = 0) is its imposed temperature whatever T held before */
        for (i = 0; i < n; i++) x[i] = c[i] != 0.0 ? c[i] * T[i] + v_s[i] : v_s[i];
        profile_solve(&f, &p, x, y, n);
        memcpy(T, x, (size_t)n * sizeof(double));
        for (i = 0; i < n_rows; i++) out[i] = T[rows[i]];
    }
    ok = 1;
done:
    free(a); free(b); free(position); free(y); free(x);
    lu_free(&f);
    profile_free(&p);
    return ok;
}
