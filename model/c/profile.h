/* The step matrix M = C/dt - A (a forced row the unit row) factorised within its profile: shared
   by the standalone FMU (nodeforce_fmu.c) and the direct model's compiled steps (steps.c).

   M in the reverse Cuthill-McKee order of the network's links, and its profile (envelope): row
   and column i of the reordered M hold nonzeros from first[i] on only, so its LU factors (without
   pivoting: M is an M-matrix, a forced row a unit row) fill nothing outside it. A zone's chains
   of wall nodes keep the profile narrow: O(N) per step, not O(N^2). */
#ifndef NODEFORCE_PROFILE_H
#define NODEFORCE_PROFILE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    int *order;  /* N: old node at new position i */
    int *first;  /* N: first column of row i (new numbering) */
    long *start; /* N + 1: where row i begins in lower/upper */
} Profile;

typedef struct {
    double *lower, *upper; /* the profile: row i of L and column i of U, from column first[i] */
    double *diagonal;      /* N: U's */
} Lu;

static void profile_free(Profile *p) {
    free(p->order); free(p->first); free(p->start);
    p->order = p->first = NULL;
    p->start = NULL;
}

/* The profile of the links (a[e], b[e]), e < pairs, given both ways (a node's repeated links
   count once): reverse Cuthill-McKee from a node of least degree in each connected part. 0 when
   memory runs out. */
static int profile_order(Profile *p, int n, const int *a, const int *b, long pairs) {
    int i, j, head = 0, tail = 0, placed = 0;
    long e;
    int *degree = calloc((size_t)n + 1, sizeof(int)), *seen = calloc((size_t)n + 1, sizeof(int));
    int *position = calloc((size_t)n + 1, sizeof(int)), *queue = calloc((size_t)n + 1, sizeof(int));
    long *at = calloc((size_t)n + 1, sizeof(long));
    int *neighbour = NULL;
    p->order = calloc((size_t)n + 1, sizeof(int));
    p->first = calloc((size_t)n + 1, sizeof(int));
    p->start = calloc((size_t)n + 1, sizeof(long));
    if (!degree || !seen || !position || !queue || !at || !p->order || !p->first || !p->start) goto fail;
    for (e = 0; e < pairs; e++) degree[a[e]]++;
    for (i = 0; i < n; i++) at[i + 1] = at[i] + degree[i];
    neighbour = calloc((size_t)at[n] + 1, sizeof(int));
    if (!neighbour) goto fail;
    memset(degree, 0, (size_t)n * sizeof(int));
    for (e = 0; e < pairs; e++) { /* each neighbour once (a node has few) */
        long q;
        for (q = at[a[e]]; q < at[a[e]] + degree[a[e]] && neighbour[q] != b[e]; q++) {}
        if (q == at[a[e]] + degree[a[e]]) neighbour[at[a[e]] + degree[a[e]]++] = b[e];
    }
    while (placed < n) {
        int root = -1;
        for (i = 0; i < n; i++)
            if (!seen[i] && (root < 0 || degree[i] < degree[root])) root = i;
        seen[root] = 1;
        queue[tail++] = root;
        while (head < tail) {
            int node = queue[head++], from = tail;
            long k;
            for (k = at[node]; k < at[node] + degree[node]; k++)
                if (!seen[neighbour[k]]) { seen[neighbour[k]] = 1; queue[tail++] = neighbour[k]; }
            for (i = from + 1; i < tail; i++) /* the new neighbours by increasing degree */
                for (j = i; j > from && degree[queue[j]] < degree[queue[j - 1]]; j--) {
                    int swap = queue[j]; queue[j] = queue[j - 1]; queue[j - 1] = swap;
                }
        }
        placed = tail;
    }
    for (i = 0; i < n; i++) { p->order[i] = queue[n - 1 - i]; position[queue[n - 1 - i]] = i; }
    for (i = 0; i < n; i++) {
        int node = p->order[i];
        long k;
        p->first[i] = i;
        for (k = at[node]; k < at[node] + degree[node]; k++)
            if (position[neighbour[k]] < p->first[i]) p->first[i] = position[neighbour[k]];
        p->start[i + 1] = p->start[i] + (i - p->first[i]);
    }
    free(degree); free(seen); free(position); free(queue); free(at); free(neighbour);
    return 1;
fail:
    free(degree); free(seen); free(position); free(queue); free(at); free(neighbour);
    profile_free(p);
    return 0;
}

/* Room for the factors of a matrix of this profile; 0 when memory runs out. */
static int lu_alloc(Lu *f, const Profile *p, int n) {
    f->lower = malloc(((size_t)p->start[n] + 1) * sizeof(double));
    f->upper = malloc(((size_t)p->start[n] + 1) * sizeof(double));
    f->diagonal = malloc(((size_t)n + 1) * sizeof(double));
    return f->lower && f->upper && f->diagonal;
}

static void lu_free(Lu *f) {
    free(f->lower); free(f->upper); free(f->diagonal);
    f->lower = f->upper = f->diagonal = NULL;
}

/* Row i of L and column i of U (reordered), from column first[i]. */
static double *lu_row(double *values, const Profile *p, int i) { return values + p->start[i] - p->first[i]; }

/* LU of the reordered M, its entries already in f within the profile (Doolittle, L unit lower);
   0 if a pivot is zero. */
static int profile_factor(Lu *f, const Profile *p, int n) {
    int i, j, k;
    for (i = 0; i < n; i++) {
        double *L_i = lu_row(f->lower, p, i), *U_i = lu_row(f->upper, p, i);
        double d = f->diagonal[i];
        for (j = p->first[i]; j < i; j++) {
            const double *L_j = lu_row(f->lower, p, j), *U_j = lu_row(f->upper, p, j);
            double l = L_i[j], u = U_i[j];
            for (k = p->first[i] > p->first[j] ? p->first[i] : p->first[j]; k < j; k++) {
                l -= L_i[k] * U_j[k];
                u -= L_j[k] * U_i[k];
            }
            U_i[j] = u;
            L_i[j] = l / f->diagonal[j];
            d -= L_i[j] * U_i[j];
        }
        if (d == 0.0 || !isfinite(d)) return 0;
        f->diagonal[i] = d;
    }
    return 1;
}

/* Solve M x = b in place, b in the original numbering; y is scratch (N). */
static void profile_solve(const Lu *f, const Profile *p, double *b, double *y, int n) {
    int i, k;
    for (i = 0; i < n; i++) {
        const double *L_i = lu_row(f->lower, p, i);
        /* four sums: one is a chain of dependent additions, four keep the processor's units busy */
        double s0 = b[p->order[i]], s1 = 0.0, s2 = 0.0, s3 = 0.0;
        for (k = p->first[i]; k + 3 < i; k += 4) {
            s0 -= L_i[k] * y[k];
            s1 -= L_i[k + 1] * y[k + 1];
            s2 -= L_i[k + 2] * y[k + 2];
            s3 -= L_i[k + 3] * y[k + 3];
        }
        for (; k < i; k++) s0 -= L_i[k] * y[k];
        y[i] = s0 + ((s1 + s2) + s3);
    }
    for (i = n - 1; i >= 0; i--) {
        const double *U_i = lu_row(f->upper, p, i);
        double x = y[i] /= f->diagonal[i];
        for (k = p->first[i]; k < i; k++) y[k] -= U_i[k] * x;
    }
    for (i = 0; i < n; i++) b[p->order[i]] = y[i];
}

#endif
