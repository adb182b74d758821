/* The direct model's runs of backward-Euler steps under one step matrix (model/integrate.py,
   `ImplicitEuler.run`), compiled where a C compiler is found (model/compiled.py):

       M T^k+1 = c T^k + B t^k + q,   k = 0 .. L-1,

   M (N x N) the step matrix C/dt - A with the forced nodes' rows unit rows, c (N) C/dt, and each
   step's sources formed here from their terms t^k (L x m: the inputs and their products) and the
   few nonzeros of B (N x m), never as an L x N array; a forced node's right-hand side is its
   imposed temperature instead. M is factorised M = L U in a minimum-degree order of its nodes,
   on the pattern that order fills in (model/compiled.py: `Pattern`, made once per pattern of
   links): a building's walls are chains hung on a few air and radiant nodes, which that order
   eliminates last, so L and U hold about as many entries as M. No pivoting: M is an M-matrix
   (its diagonal the node's capacity over the step and conductances, at least the sum of its
   row's links), and a forced row a unit row. Each step is then two sparse triangular solves,
   O(entries), where a product with the dense inverse is O(N^2).

   Where a building's convective or outside long-wave coefficients follow its state
   (model/network.py, `Convection`; docs/model.md section 3.6), each step adds to its sources
   what the coefficients computed from the temperatures before it and its inputs give beyond the
   h0 of M (followed.h, which the standalone FMU steps too). */
#include <math.h>
#include <stdlib.h>

#include "followed.h"

#define EXPORT __attribute__((visibility("default")))
/* order (N): the node of each position of the elimination order; lower_ptr/lower_col (N + 1,
   and columns): each row's entries of L left of the diagonal, in increasing column;
   upper_ptr/upper_col: each row's entries of U right of it, in increasing column. M's
   nonzeros (value) are added into the factors' storage at slot: [diagonal (N) | L's | U's].
   terms (L x m), source_ptr/source_col/source_value (N + 1, and entries): each node's nonzeros
   of B, by term; q (N). forced (n_forced): the nodes imposed at every step, imposed (L x
   n_forced) their temperatures. T (N): the temperatures before the first step, after the last
   on return; path (L x R): the temperatures of the nodes rows (R) after each step. Returns 1, or
   0 where a pivot is zero (M singular) or memory runs out. n_inside ... columns: the lagged
   coefficients (`convection`), u each step's first columns of terms (the inputs). */
EXPORT int nodeforce_steps(int n, const int *order, const int *lower_ptr, const int *lower_col,
                           const int *upper_ptr, const int *upper_col, long nonzeros, const int *slot,
                           const double *value, const double *c, long L, int m, const double *terms,
                           const int *source_ptr, const int *source_col, const double *source_value,
                           const double *q, int n_forced, const int *forced, const double *imposed, double *T,
                           int n_rows, const int *rows, double *path, int n_inside, const int *inside_nodes,
                           const double *inside, int n_outside, const int *outside_nodes, const double *outside,
                           int n_longwave, const int *longwave_nodes, const double *longwave, const int *columns,
                           int n_windows, const int *window_nodes, const double *windows, int n_gaps,
                           const int *gap_nodes, const double *gaps, int n_pairs, const int *pair_nodes,
                           const double *pairs, int n_flows, const int *flow_nodes, const double *flows,
                           int n_people, const int *people_nodes, const double *people) {
    long entries = (long)n + lower_ptr[n] + upper_ptr[n], s, e;
    double *f = calloc((size_t)entries + 1, sizeof(double)), *w = calloc((size_t)n + 1, sizeof(double));
    double *y = malloc(((size_t)n + 1) * sizeof(double));
    int *position = malloc(((size_t)n + 1) * sizeof(int));
    const Followed followed = {n_inside, n_outside, n_longwave, n_windows, n_gaps, n_pairs, n_flows, n_people,
                               inside_nodes, outside_nodes, longwave_nodes, window_nodes, gap_nodes, pair_nodes,
                               flow_nodes, people_nodes, columns, inside, outside, longwave, windows, gaps, pairs,
                               flows, people};
    const int lagged = followed_any(&followed);
    double *extra = calloc((size_t)n + 1, sizeof(double));
    double *diagonal = f, *lower = f + n, *upper = f + n + lower_ptr[n];
    int i, p, k, ok = 0;
    if (!f || !w || !y || !position || !extra) goto done;
    for (e = 0; e < nonzeros; e++) f[slot[e]] += value[e];
    /* row by row (Doolittle): row i less its multiples of the rows above it that L says */
    for (i = 0; i < n; i++) {
        for (p = lower_ptr[i]; p < lower_ptr[i + 1]; p++) w[lower_col[p]] = lower[p];
        for (p = upper_ptr[i]; p < upper_ptr[i + 1]; p++) w[upper_col[p]] = upper[p];
        w[i] = diagonal[i];
        for (p = lower_ptr[i]; p < lower_ptr[i + 1]; p++) {
            const int j = lower_col[p];
            const double l = w[j] /= diagonal[j];
            for (k = upper_ptr[j]; k < upper_ptr[j + 1]; k++) w[upper_col[k]] -= l * upper[k];
        }
        for (p = lower_ptr[i]; p < lower_ptr[i + 1]; p++) { lower[p] = w[lower_col[p]]; w[lower_col[p]] = 0.0; }
        for (p = upper_ptr[i]; p < upper_ptr[i + 1]; p++) { upper[p] = w[upper_col[p]]; w[upper_col[p]] = 0.0; }
        diagonal[i] = w[i];
        w[i] = 0.0;
        if (diagonal[i] == 0.0) goto done;
    }
    for (i = 0; i < n; i++) { w[i] = 1.0 / diagonal[i]; position[order[i]] = i; }
    for (s = 0; s < L; s++) {
        const double *t_s = terms + s * m;
        double *out = path + s * n_rows;
        if (lagged)
            convection(&followed, n, T, t_s, c, 1.0, extra);
        for (i = 0; i < n; i++) {
            const int node = order[i];
            double sum = q[node] + extra[node];
            for (p = source_ptr[node]; p < source_ptr[node + 1]; p++) sum += source_value[p] * t_s[source_col[p]];
            /* a node without capacity (c = 0) has no past to carry, whatever T held */
            y[i] = c[node] != 0.0 ? c[node] * T[node] + sum : sum;
        }
        for (k = 0; k < n_forced; k++) y[position[forced[k]]] = imposed[s * n_forced + k];
        for (i = 0; i < n; i++) {
            double sum = y[i];
            for (p = lower_ptr[i]; p < lower_ptr[i + 1]; p++) sum -= lower[p] * y[lower_col[p]];
            y[i] = sum;
        }
        for (i = n - 1; i >= 0; i--) {
            double sum = y[i];
            for (p = upper_ptr[i]; p < upper_ptr[i + 1]; p++) sum -= upper[p] * y[upper_col[p]];
            y[i] = sum * w[i];
        }
        for (i = 0; i < n; i++) T[order[i]] = y[i];
        for (i = 0; i < n_rows; i++) out[i] = T[rows[i]];
    }
    ok = 1;
done:
    free(f); free(w); free(y); free(position); free(extra);
    return ok;
}
