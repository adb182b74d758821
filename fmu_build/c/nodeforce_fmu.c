/* A generic FMI 2.0 co-simulation slave stepping a nodal network (docs/model.md).

   The network is data, assembled by nodeforce in Python and shipped as resources/network.txt:
   C (J/K), A (W/K), B, q (W) and the coefficients P (W) of the products of two inputs (a shaded
   glazing's transmitted sun, P_k u_a u_b on node i) at the declared parameters p0 and, per set S
   of parameters that act together, a term multiplied by prod_{j in S} (p_j - p0_j): the
   network is affine in each parameter (the building's properties, an added effect's). Each
   term keeps its nonzeros only. This file only steps:
       (C/dt - A) T+ = (C/dt) T + B u + q + s(u),   s_i(u) = sum over products k on i of P_k u_a u_b,
   the rows of forced nodes (force[i] and T_forced[i] not NaN) replaced by T+_i = T_forced[i],
   with M factorised once per pattern of imposed nodes and step size: LU within the profile of
   M reordered by reverse Cuthill-McKee (profile.h), O(N) per step on a building's network.
   Where coefficients follow the state (docs/model.md section 3.6), each step adds their sources
   beyond the h0 of A, from T before it and its inputs (followed.h, the direct model's arithmetic):
   their nodes are data, and their values (areas, h0, ...) entries F of the block C, A, B, q, P,
   F that the parameters' terms set like any other.
   The state at the start is T_start. The inputs set before doStep(t, h) are those at t, their
   first derivatives (fmi2SetRealInputDerivatives; zero where none is set for this step) make
   them linear over the step: doStep takes k = ceil(h / max_step) steps of h / k, each with the
   inputs and T_forced at its end, u(t) + u'(t) tau; a forced node is imposed over the step
   where T_forced at t is not NaN.

   Value references and the calls refused: variables.h (shared with the Python FMU's guard). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2.h"
#include "followed.h"
#include "profile.h"
#include "resources.h"
#include "variables.h"

/* The binary needs glibc 2.14 at most (its documentation, fmu_build/description.py): pow and exp
   (followed.h) at their first versions, which every glibc's libm holds, not the GLIBC_2.29 ones
   glibc added when it dropped their SVID error handling (the same results where they are finite;
   tests/test_fmu_exchange.py reads the versions). */
#if defined(__x86_64__) && defined(__GLIBC__)
__asm__(".symver pow,pow@GLIBC_2.2.5");
__asm__(".symver exp,exp@GLIBC_2.2.5");
#endif

#define CACHED_PATTERNS 8
#define MAX_SUBSTEPS 10000000 /* the internal steps of one doStep, at most (variables.py's) */
#define FOLLOWED_KINDS 8
/* a row's values and nodes of each kind of followed coefficient (model/compiled.py's FOLLOWED),
   and which node of a row is an input's column (or -1) instead: a flow's and people's schedule */
static const int FOLLOWED_VALUES[FOLLOWED_KINDS] = {3, 6, 4, 5, 15, 2, 14, 6};
static const int FOLLOWED_NODES[FOLLOWED_KINDS] = {2, 1, 1, 2, 2, 2, 2, 3};
static const int FOLLOWED_COLUMN[FOLLOWED_KINDS] = {-1, -1, -1, -1, -1, -1, 1, 2};

typedef struct {
    double dt;
    unsigned char *imposed; /* N */
    Lu lu;
    int used;
} Factors;

typedef struct {
    int n, n_in, n_par, n_terms, n_products;
    int n_followed[FOLLOWED_KINDS]; /* each kind's count (followed.h's order) */
    int followed_columns[4];        /* the inputs T_out, wind speed and direction, T_sky (or -1) */
    int *followed_nodes;            /* each kind's nodes, FOLLOWED_NODES[k] a row, concatenated */
    double *p0;       /* n_par */
    double max_step;  /* s: max_step's start */
    int *product;     /* n_products x 3: node, input a, input b */
    long *term_start; /* n_terms + 1: where each term's nonzeros begin */
    long *par_start;  /* n_terms + 1: where each term's parameters begin */
    int *term_par;    /* the parameters multiplying each term, concatenated */
    long *index;      /* each term's nonzeros: index in the block C, A, B, q, P ... */
    double *value;    /* ... and value, concatenated */
} Network;

typedef struct {
    Network net;
    Layout layout; /* the value references of net's sizes */
    char *name;
    fmi2CallbackFunctions cb;
    int state, size, clock;
    double time; /* the current communication point (s) */
    double *values, *start_values;
    double *derivatives; /* n_in + n: d/dt of the inputs and of T_forced at the communication point */
    double *u;           /* n_in: the inputs at the end of a sub-step */
    double *C, *A, *B, *q, *P, *F; /* at the parameters' values; F the followed coefficients' */
    Followed followed;             /* its values in F */
    double *extra;                 /* N: their sources at a step */
    double *v, *work;
    unsigned char *imposed;
    Profile profile;
    long *b_start; int *b_column; double *b_value; /* B's nonzeros by row: a node has few inputs */
    Factors cache[CACHED_PATTERNS];
} Model;

static void log_error(Model *m, const char *format, ...) {
    char message[512];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    if (m->cb.logger) m->cb.logger(m->cb.componentEnvironment, m->name, fmi2Error, "logStatusError", "%s", message);
}

/* A get or set the standard forbids (variables.h), its reason logged: 1 when refused. */
static int refused(Model *m, const fmi2ValueReference vr[], size_t nvr, const double *values, int real, int setting) {
    char message[512];
    if (!refused2(&m->layout, vr, nvr, values, real, setting, m->state, m->time, message, sizeof message)) return 0;
    log_error(m, "%s", message);
    return 1;
}

/* ------------------------------------------------------------------ reading the network */
static int expect(FILE *f, const char *word) {
    char token[64];
    return fscanf(f, "%63s", token) == 1 && strcmp(token, word) == 0;
}

static int read_ints(FILE *f, int *x, int count) {
    int k;
    for (k = 0; k < count; k++)
        if (fscanf(f, "%d", &x[k]) != 1) return 0;
    return 1;
}

static int read_doubles(FILE *f, double *x, long count) {
    long k;
    for (k = 0; k < count; k++)
        if (fscanf(f, "%lf", &x[k]) != 1) return 0;
    return 1;
}

static int read_longs(FILE *f, long *x, long count) {
    long k;
    for (k = 0; k < count; k++)
        if (fscanf(f, "%ld", &x[k]) != 1) return 0;
    return 1;
}

/* The number of values (k < FOLLOWED_KINDS) or nodes of the followed coefficients. */
static long followed_size(const Network *net, const int *width) {
    long size = 0;
    int k;
    for (k = 0; k < FOLLOWED_KINDS; k++) size += (long)net->n_followed[k] * width[k];
    return size;
}

/* The size of the block C, A, B, q, P, F. */
static long term_size(const Network *net) {
    return (long)net->n * (2 + net->n + net->n_in) + net->n_products + followed_size(net, FOLLOWED_VALUES);
}

/* "followed" counts (FOLLOWED_KINDS), columns (4), nodes: each a node, or an input's column or -1
   where FOLLOWED_COLUMN says, and the columns a kind reads given. */
static int read_followed(Network *net, FILE *f) {
    long at = 0, size;
    int k, r, j;
    if (!expect(f, "followed") || !read_ints(f, net->n_followed, FOLLOWED_KINDS)
        || !read_ints(f, net->followed_columns, 4))
        return 0;
    for (k = 0; k < FOLLOWED_KINDS; k++)
        if (net->n_followed[k] < 0) return 0;
    for (j = 0; j < 4; j++)
        if (net->followed_columns[j] < -1 || net->followed_columns[j] >= net->n_in) return 0;
    if ((net->n_followed[1] > 0 || net->n_followed[2] > 0 || net->n_followed[6] > 0) && net->followed_columns[0] < 0)
        return 0;
    if (net->n_followed[1] > 0 && (net->followed_columns[1] < 0 || net->followed_columns[2] < 0)) return 0;
    if (net->n_followed[2] > 0 && net->followed_columns[3] < 0) return 0;
    size = followed_size(net, FOLLOWED_NODES);
    net->followed_nodes = calloc((size_t)size + 1, sizeof(int));
    if (!net->followed_nodes || !read_ints(f, net->followed_nodes, (int)size)) return 0;
    for (k = 0; k < FOLLOWED_KINDS; k++)
        for (r = 0; r < net->n_followed[k]; r++)
            for (j = 0; j < FOLLOWED_NODES[k]; j++, at++) {
                const int x = net->followed_nodes[at];
                if (j == FOLLOWED_COLUMN[k] ? x < -1 || x >= net->n_in : x < 0 || x >= net->n) return 0;
            }
    return 1;
}

/* resources/network.txt: "nodeforce-network/5", "sizes N N_IN N_PAR N_TERMS N_PRODUCTS
   N_PARAMETER_REFS N_NONZEROS", "p0 ...", "max_step S" (the start of max_step, s), "products (node a b) ...",
   "followed ..." (`read_followed`), then per term "term K j_1 .. j_K COUNT" and COUNT pairs
   "index value" (index into the block C, A, B, q, P, F), "end". */
static int read_network(Network *net, FILE *f) {
    long refs, nonzeros, k, count, at = 0, at_par = 0, size;
    int t, j;
    if (!expect(f, "nodeforce-network/5") || !expect(f, "sizes") || !read_ints(f, &net->n, 1)
        || !read_ints(f, &net->n_in, 1) || !read_ints(f, &net->n_par, 1) || !read_ints(f, &net->n_terms, 1)
        || !read_ints(f, &net->n_products, 1) || !read_longs(f, &refs, 1) || !read_longs(f, &nonzeros, 1)
        || net->n <= 0 || net->n_in < 0 || net->n_par < 0 || net->n_terms < 1 || net->n_products < 0 || refs < 0
        || nonzeros < 0)
        return 0;
    net->p0 = calloc((size_t)net->n_par + 1, sizeof(double));
    net->product = calloc((size_t)net->n_products * 3 + 1, sizeof(int));
    net->term_start = calloc((size_t)net->n_terms + 1, sizeof(long));
    net->par_start = calloc((size_t)net->n_terms + 1, sizeof(long));
    net->term_par = calloc((size_t)refs + 1, sizeof(int));
    net->index = calloc((size_t)nonzeros + 1, sizeof(long));
    net->value = calloc((size_t)nonzeros + 1, sizeof(double));
    if (!net->p0 || !net->product || !net->term_start || !net->par_start || !net->term_par || !net->index
        || !net->value)
        return 0;
    if (!expect(f, "p0") || !read_doubles(f, net->p0, net->n_par)) return 0;
    if (!expect(f, "max_step") || !read_doubles(f, &net->max_step, 1) || !(net->max_step > 0.0)) return 0;
    if (!expect(f, "products") || !read_ints(f, net->product, net->n_products * 3)) return 0;
    for (k = 0; k < net->n_products; k++) {
        const int *p = net->product + 3 * k;
        if (p[0] < 0 || p[0] >= net->n || p[1] < 0 || p[1] >= net->n_in || p[2] < 0 || p[2] >= net->n_in) return 0;
    }
    if (!read_followed(net, f)) return 0;
    size = term_size(net);
    for (t = 0; t < net->n_terms; t++) {
        int n_par;
        net->term_start[t] = at;
        net->par_start[t] = at_par;
        if (!expect(f, "term") || !read_ints(f, &n_par, 1) || n_par < 0 || at_par + n_par > refs
            || !read_ints(f, net->term_par + at_par, n_par) || !read_longs(f, &count, 1) || count < 0
            || at + count > nonzeros)
            return 0;
        for (j = 0; j < n_par; j++)
            if (net->term_par[at_par + j] < 0 || net->term_par[at_par + j] >= net->n_par) return 0;
        at_par += n_par;
        for (k = 0; k < count; k++, at++)
            if (!read_longs(f, &net->index[at], 1) || !read_doubles(f, &net->value[at], 1) || net->index[at] < 0
                || net->index[at] >= size)
                return 0;
    }
    net->term_start[net->n_terms] = at;
    net->par_start[net->n_terms] = at_par;
    return at == nonzeros && at_par == refs && expect(f, "end");
}

static void free_network(Network *net) {
    free(net->p0); free(net->product); free(net->term_start); free(net->par_start); free(net->term_par);
    free(net->index); free(net->value); free(net->followed_nodes);
}

/* ------------------------------------------------------------------ the numbers */
/* C, A, B, q, P at the parameters' current values, and B's nonzeros by row. */
static void network_at_parameters(Model *m) {
    const Network *net = &m->net;
    long size = term_size(net), k;
    int t, i, j;
    double *out = m->C; /* C, A, B, q, P are one contiguous block */
    memset(out, 0, (size_t)size * sizeof(double));
    for (t = 0; t < net->n_terms; t++) {
        double weight = 1.0;
        for (k = net->par_start[t]; k < net->par_start[t + 1]; k++)
            weight *= m->values[vr_parameters(&m->layout) + net->term_par[k]] - net->p0[net->term_par[k]];
        for (k = net->term_start[t]; k < net->term_start[t + 1]; k++) out[net->index[k]] += weight * net->value[k];
    }
    for (i = 0, k = 0; i < net->n; i++) {
        m->b_start[i] = k;
        for (j = 0; j < net->n_in; j++)
            if (m->B[(long)i * net->n_in + j] != 0.0) {
                m->b_column[k] = j;
                m->b_value[k++] = m->B[(long)i * net->n_in + j];
            }
    }
    m->b_start[net->n] = k;
}

/* The followed coefficients' nodes (the network's) and values (in F). */
static void followed_at(Model *m) {
    const Network *net = &m->net;
    Followed *f = &m->followed;
    const int **nodes[FOLLOWED_KINDS] = {&f->inside_nodes, &f->outside_nodes, &f->longwave_nodes, &f->window_nodes,
                                         &f->gap_nodes, &f->pair_nodes, &f->flow_nodes, &f->people_nodes};
    const double **values[FOLLOWED_KINDS] = {&f->inside, &f->outside, &f->longwave, &f->windows,
                                             &f->gaps, &f->pairs, &f->flows, &f->people};
    int *counts[FOLLOWED_KINDS] = {&f->n_inside, &f->n_outside, &f->n_longwave, &f->n_windows,
                                   &f->n_gaps, &f->n_pairs, &f->n_flows, &f->n_people};
    long at_node = 0, at_value = 0;
    int k;
    for (k = 0; k < FOLLOWED_KINDS; k++) {
        *counts[k] = net->n_followed[k];
        *nodes[k] = net->followed_nodes + at_node;
        *values[k] = m->F + at_value;
        at_node += (long)net->n_followed[k] * FOLLOWED_NODES[k];
        at_value += (long)net->n_followed[k] * FOLLOWED_VALUES[k];
    }
    f->columns = net->followed_columns;
}

/* The profile of M's links in any term of the network (so in M at any parameter values). */
static int order_network(Model *m) {
    const Network *net = &m->net;
    int n = net->n, ok;
    long k, pairs = 0, nonzeros = net->term_start[net->n_terms];
    int *a = calloc((size_t)2 * nonzeros + 1, sizeof(int)), *b = calloc((size_t)2 * nonzeros + 1, sizeof(int));
    if (!a || !b) { free(a); free(b); return 0; }
    /* the links: A's off-diagonal nonzeros in any term, both ways */
    for (k = 0; k < nonzeros; k++) {
        long offset = net->index[k] - n;
        if (offset < 0 || offset >= (long)n * n || offset / n == offset % n) continue;
        a[pairs] = (int)(offset / n); b[pairs++] = (int)(offset % n);
        a[pairs] = (int)(offset % n); b[pairs++] = (int)(offset / n);
    }
    ok = profile_order(&m->profile, n, a, b, pairs);
    free(a); free(b);
    return ok;
}

/* M_rc: the step matrix, a forced row the unit row. */
static double step_matrix(const Model *m, double dt, int r, int c) {
    int n = m->net.n;
    if (m->imposed[r]) return r == c;
    return (r == c ? m->C[r] / dt : 0.0) - m->A[(long)r * n + c];
}

/* The factors of M for this step size and pattern of imposed nodes (cached). */
static Factors *factors(Model *m, double dt) {
    int n = m->net.n, i, j, slot = 0;
    const Profile *p = &m->profile;
    Factors *f;
    for (i = 0; i < CACHED_PATTERNS; i++) {
        f = &m->cache[i];
        if (f->lu.lower && f->dt == dt && memcmp(f->imposed, m->imposed, (size_t)n) == 0) {
            f->used = ++m->clock;
            return f;
        }
        if (f->used < m->cache[slot].used) slot = i; /* the least recently used (unused: 0) */
    }
    f = &m->cache[slot];
    if (!f->lu.lower) {
        f->imposed = malloc((size_t)n);
        if (!lu_alloc(&f->lu, p, n) || !f->imposed) return NULL;
    }
    for (i = 0; i < n; i++) {
        int r = p->order[i];
        double *L_i = lu_row(f->lu.lower, p, i), *U_i = lu_row(f->lu.upper, p, i);
        for (j = p->first[i]; j < i; j++) {
            L_i[j] = step_matrix(m, dt, r, p->order[j]);
            U_i[j] = step_matrix(m, dt, p->order[j], r);
        }
        f->lu.diagonal[i] = step_matrix(m, dt, r, r);
    }
    f->dt = dt;
    memcpy(f->imposed, m->imposed, (size_t)n);
    f->used = ++m->clock;
    if (!profile_factor(&f->lu, p, n)) {
        f->dt = -1.0; /* never matches again */
        f->used = 0;
        return NULL;
    }
    return f;
}

static void forget_factors(Model *m) {
    int i;
    for (i = 0; i < CACHED_PATTERNS; i++) {
        m->cache[i].dt = -1.0;
        m->cache[i].used = 0;
    }
}

/* One doStep of h: k backward-Euler steps of h / k with the inputs and the imposed temperatures
   at each one's end. */
static fmi2Status step(Model *m, double h) {
    const Network *net = &m->net;
    int n = net->n, n_in = net->n_in, i, j, k, steps;
    const double *u0 = m->values + vr_inputs(&m->layout), *T_forced = m->values + vr_T_forced(&m->layout);
    const double *du = m->derivatives, *dT_forced = m->derivatives + n_in;
    double *T = m->values + vr_T(&m->layout), *u = m->u, dt, s;
    const int followed = followed_any(&m->followed);
    Factors *f;
    for (i = 0; i < n; i++) m->imposed[i] = m->values[vr_force(&m->layout) + i] != 0.0 && isfinite(T_forced[i]);
    if (h / m->values[vr_max_step(&m->layout)] > MAX_SUBSTEPS) {
        log_error(m, "doStep of %g s is more than %d steps of max_step = %g s: set max_step larger", h, MAX_SUBSTEPS,
                  m->values[vr_max_step(&m->layout)]);
        return fmi2Error;
    }
    steps = (int)ceil(h / m->values[vr_max_step(&m->layout)] - 1e-9);
    if (steps < 1) steps = 1;
    dt = h / steps;
    f = factors(m, dt);
    if (!f) {
        log_error(m, "the step matrix is singular (or memory ran out)");
        return fmi2Error;
    }
    for (j = 1; j <= steps; j++) {
        s = j * dt;
        for (k = 0; k < n_in; k++) u[k] = u0[k] + du[k] * s;
        for (i = 0; i < n; i++) { /* the sources */
            long k_b;
            m->v[i] = m->q[i];
            for (k_b = m->b_start[i]; k_b < m->b_start[i + 1]; k_b++) m->v[i] += m->b_value[k_b] * u[m->b_column[k_b]];
        }
        for (k = 0; k < net->n_products; k++) {
            const int *p = net->product + 3 * k;
            m->v[p[0]] += m->P[k] * u[p[1]] * u[p[2]];
        }
        if (followed) { /* from T before the step and its inputs */
            convection(&m->followed, n, T, u, m->C, 1.0 / dt, m->extra);
            for (i = 0; i < n; i++) m->v[i] += m->extra[i];
        }
        for (i = 0; i < n; i++)
            m->v[i] = m->imposed[i] ? T_forced[i] + dT_forced[i] * s : m->C[i] / dt * T[i] + m->v[i];
        profile_solve(&f->lu, &m->profile, m->v, m->work, n);
        for (i = 0; i < n; i++) T[i] = m->imposed[i] ? T_forced[i] + dT_forced[i] * s : m->v[i];
    }
    /* the next step's derivatives are set before it, or it holds its inputs */
    memset(m->derivatives, 0, sizeof(double) * (size_t)(n_in + n));
    return fmi2OK;
}

/* ------------------------------------------------------------------ FMI 2.0 */
FMI2_EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
FMI2_EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

FMI2_EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String categories[]) {
    (void)c; (void)on; (void)n; (void)categories;
    return fmi2OK;
}

static void free_model(Model *m) {
    int i;
    if (!m) return;
    for (i = 0; i < CACHED_PATTERNS; i++) {
        lu_free(&m->cache[i].lu); free(m->cache[i].imposed);
    }
    free_network(&m->net);
    free_names(&m->layout);
    free(m->name); free(m->values); free(m->start_values); free(m->derivatives); free(m->u); free(m->C); free(m->v); free(m->work);
    free(m->extra);
    free(m->imposed); profile_free(&m->profile);
    free(m->b_start); free(m->b_column); free(m->b_value);
    free(m);
}

FMI2_EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                                          const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                                          fmi2Boolean loggingOn) {
    Model *m = calloc(1, sizeof(Model));
    char *path;
    FILE *f;
    int ok, i;
    (void)guid; (void)visible; (void)loggingOn;
    if (!m || !functions) { free(m); return NULL; }
    memcpy((void *)&m->cb, functions, sizeof m->cb);
    m->name = malloc(strlen(name ? name : "") + 1);
    if (!m->name) { free_model(m); return NULL; }
    strcpy(m->name, name ? name : "");
    if (type != fmi2CoSimulation) {
        log_error(m, "this FMU supports co-simulation only");
        free_model(m);
        return NULL;
    }
    path = resources ? resource_path(resources, "network.txt") : NULL;
    f = path ? fopen(path, "r") : NULL;
    ok = f && read_network(&m->net, f);
    if (f) fclose(f);
    if (!ok) {
        log_error(m, "cannot read %s", path ? path : "the resources (no fmuResourceLocation)");
        free(path);
        free_model(m);
        return NULL;
    }
    free(path);
    m->layout.n = m->net.n;
    m->layout.n_in = m->net.n_in;
    m->layout.n_par = m->net.n_par;
    path = resource_path(resources, "names.txt");
    ok = read_names(&m->layout, path);
    free(path);
    if (!ok) free_names(&m->layout); /* messages then say "an input" */
    m->size = layout_size(&m->layout);
    m->values = calloc((size_t)m->size, sizeof(double));
    m->start_values = calloc((size_t)m->size, sizeof(double));
    m->derivatives = calloc((size_t)(m->net.n_in + m->net.n), sizeof(double));
    m->u = calloc((size_t)m->net.n_in + 1, sizeof(double));
    m->C = calloc((size_t)term_size(&m->net), sizeof(double));
    m->A = m->C + m->net.n;
    m->B = m->A + m->net.n * m->net.n;
    m->q = m->B + m->net.n * m->net.n_in;
    m->P = m->q + m->net.n;
    m->F = m->P + m->net.n_products;
    followed_at(m);
    m->v = calloc((size_t)m->net.n, sizeof(double));
    m->work = calloc((size_t)m->net.n, sizeof(double));
    m->extra = calloc((size_t)m->net.n, sizeof(double));
    m->b_start = calloc((size_t)m->net.n + 1, sizeof(long));
    m->b_column = calloc((size_t)m->net.n * m->net.n_in + 1, sizeof(int));
    m->b_value = calloc((size_t)m->net.n * m->net.n_in + 1, sizeof(double));
    m->imposed = calloc((size_t)m->net.n, 1);
    if (!m->values || !m->start_values || !m->derivatives || !m->u || !m->C || !m->v || !m->work || !m->extra || !m->imposed || !m->b_start || !m->b_column
        || !m->b_value || !order_network(m)) {
        free_model(m);
        return NULL;
    }
    for (i = 0; i < m->net.n; i++) {
        m->start_values[vr_T_start(&m->layout) + i] = 20.0;
        m->start_values[vr_T_forced(&m->layout) + i] = NAN;
        m->start_values[vr_T(&m->layout) + i] = 20.0;
    }
    for (i = 0; i < m->net.n_par; i++) m->start_values[vr_parameters(&m->layout) + i] = m->net.p0[i];
    m->start_values[vr_max_step(&m->layout)] = m->net.max_step;
    memcpy(m->values, m->start_values, (size_t)m->size * sizeof(double));
    forget_factors(m);
    m->state = INSTANTIATED;
    return m;
}

FMI2_EXPORT void fmi2FreeInstance(fmi2Component c) { free_model((Model *)c); }

FMI2_EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                                           fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    Model *m = c;
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    if (m->state != INSTANTIATED) {
        log_error(m, "fmi2SetupExperiment is allowed only after instantiation");
        return fmi2Error;
    }
    m->time = startTime;
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    Model *m = c;
    if (m->state != INSTANTIATED) {
        log_error(m, "fmi2EnterInitializationMode is allowed only after instantiation");
        return fmi2Error;
    }
    m->state = INITIALISATION;
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Model *m = c;
    if (m->state != INITIALISATION) {
        log_error(m, "fmi2ExitInitializationMode outside initialisation mode");
        return fmi2Error;
    }
    network_at_parameters(m);
    forget_factors(m);
    /* the start values alone set the state: what an importer applies as inputs at t_0 does not */
    memcpy(m->values + vr_T(&m->layout), m->values + vr_T_start(&m->layout), (size_t)m->net.n * sizeof(double));
    m->state = STEPPING;
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2Terminate(fmi2Component c) {
    ((Model *)c)->state = TERMINATED;
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2Reset(fmi2Component c) {
    Model *m = c;
    memcpy(m->values, m->start_values, (size_t)m->size * sizeof(double));
    memset(m->derivatives, 0, sizeof(double) * (size_t)(m->net.n_in + m->net.n));
    m->state = INSTANTIATED;
    m->time = 0.0;
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    Model *m = c;
    size_t k;
    if (refused(m, vr, nvr, NULL, 1, 0)) return fmi2Error;
    for (k = 0; k < nvr; k++) value[k] = m->values[vr[k]];
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    Model *m = c;
    size_t k;
    if (refused(m, vr, nvr, value, 1, 1)) return fmi2Error;
    for (k = 0; k < nvr; k++) m->values[vr[k]] = value[k];
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
    Model *m = c;
    size_t k;
    if (refused(m, vr, nvr, NULL, 0, 0)) return fmi2Error;
    for (k = 0; k < nvr; k++) value[k] = m->values[vr[k]] != 0.0;
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
    Model *m = c;
    size_t k;
    if (refused(m, vr, nvr, NULL, 0, 1)) return fmi2Error;
    for (k = 0; k < nvr; k++) m->values[vr[k]] = value[k] ? 1.0 : 0.0;
    return fmi2OK;
}

static fmi2Status no_such(Model *m, const char *what, size_t nvr) {
    char reason[256];
    if (!no_such_type(what, nvr, reason, sizeof reason)) return fmi2OK;
    log_error(m, "%s", reason);
    return fmi2Error;
}

FMI2_EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
    (void)vr; (void)value;
    return no_such(c, "Integer", nvr);
}
FMI2_EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
    (void)vr; (void)value;
    return no_such(c, "Integer", nvr);
}
FMI2_EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    (void)vr; (void)value;
    return no_such(c, "String", nvr);
}
FMI2_EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    (void)vr; (void)value;
    return no_such(c, "String", nvr);
}

/* A state: the state of the slave, its time, then every value. */
#define STATE_HEAD 2
FMI2_EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state) {
    Model *m = c;
    double *copy = *state ? *state : malloc((size_t)(m->size + STATE_HEAD) * sizeof(double));
    if (!copy) return fmi2Error;
    copy[0] = m->state;
    copy[1] = m->time;
    memcpy(copy + STATE_HEAD, m->values, (size_t)m->size * sizeof(double));
    *state = copy;
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    Model *m = c;
    const double *copy = state;
    if (!copy) return fmi2Error;
    m->state = (int)copy[0];
    m->time = copy[1];
    memcpy(m->values, copy + STATE_HEAD, (size_t)m->size * sizeof(double));
    if (m->state == STEPPING) { /* the network at the restored parameters */
        network_at_parameters(m);
        forget_factors(m);
    }
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) {
    (void)c;
    free(*state);
    *state = NULL;
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size) {
    (void)state;
    *size = (size_t)(((Model *)c)->size + STATE_HEAD) * sizeof(double);
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[], size_t size) {
    if (size < (size_t)(((Model *)c)->size + STATE_HEAD) * sizeof(double)) return fmi2Error;
    memcpy(bytes, state, (size_t)(((Model *)c)->size + STATE_HEAD) * sizeof(double));
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state) {
    Model *m = c;
    size_t need = (size_t)(m->size + STATE_HEAD) * sizeof(double);
    if (size != need) {
        log_error(m, "a serialized state of %lu bytes is not one of this FMU's (%lu)", (unsigned long)size, (unsigned long)need);
        return fmi2Error;
    }
    *state = malloc(need);
    if (!*state) return fmi2Error;
    memcpy(*state, bytes, need);
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                                    const fmi2ValueReference z[], size_t nz, const fmi2Real dv[],
                                                    fmi2Real dz[]) {
    (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz;
    log_error(c, "directional derivatives are not provided");
    return fmi2Error;
}

FMI2_EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                                   const fmi2Integer order[], const fmi2Real value[]) {
    Model *m = c;
    char message[512];
    size_t k;
    if (derivative_refusal(&m->layout, vr, nvr, order, value, m->state, m->time, message, sizeof message)) {
        log_error(m, "%s", message);
        return fmi2Error;
    }
    for (k = 0; k < nvr; k++) m->derivatives[(int)vr[k] - vr_inputs(&m->layout)] = value[k];
    return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                                    const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)nvr; (void)order; (void)value;
    log_error(c, "output derivatives are not provided");
    return fmi2Error;
}

FMI2_EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                                  fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    Model *m = c;
    char reason[256];
    fmi2Status status;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (step_refusal(m->state, communicationStepSize, reason, sizeof reason)) {
        log_error(m, "%s", reason);
        return fmi2Error;
    }
    if (!(m->values[vr_max_step(&m->layout)] > 0.0)) {
        log_error(m, "value reference %d (max_step) is %g s: it must be > 0", vr_max_step(&m->layout),
                  m->values[vr_max_step(&m->layout)]);
        return fmi2Error;
    }
    status = step(m, communicationStepSize);
    if (status == fmi2OK) m->time = currentCommunicationPoint + communicationStepSize;
    return status;
}

FMI2_EXPORT fmi2Status fmi2CancelStep(fmi2Component c) {
    log_error(c, "fmi2CancelStep: steps are never asynchronous here");
    return fmi2Error;
}

static fmi2Status no_status(Model *m) {
    log_error(m, "steps are never asynchronous here: no status to report");
    return fmi2Discard;
}

#define NO_STATUS(function, value_type)                                                          \
    FMI2_EXPORT fmi2Status function(fmi2Component c, const fmi2StatusKind s, value_type *value) { \
        (void)s; (void)value;                                                                    \
        return no_status(c);                                                                     \
    }
NO_STATUS(fmi2GetStatus, fmi2Status)
NO_STATUS(fmi2GetRealStatus, fmi2Real)
NO_STATUS(fmi2GetIntegerStatus, fmi2Integer)
NO_STATUS(fmi2GetBooleanStatus, fmi2Boolean)
NO_STATUS(fmi2GetStringStatus, fmi2String)
