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
   h0 of M: the same arithmetic as model/convection.py's and model/longwave.py's, face by face. */
#include <math.h>
#include <stdlib.h>

#define EXPORT __attribute__((visibility("default")))
#define INSIDE_FLOOR 0.1 /* W/m2/K, model/convection.py */
#define SIGMA 5.670374419e-8 /* W/m2/K4, model/longwave.py */

/* TARP's natural convection (W/m2/K) at dT = T_s - T_air, cos_up the face's normal into the air
   with the vertical: ASHRAE's on a wall, else Walton's unstable where the heat rises off the face,
   else stable */
static double tarp_natural(double dT, double cos_up) {
    const double root = cbrt(fabs(dT)), c = fabs(cos_up);
    if (c < 1e-6) return 1.31 * root;
    return dT * cos_up > 0.0 ? 9.482 * root / (7.238 - c) : 1.810 * root / (1.382 + c);
}

/* An outside face's long-wave coefficient (W/m2/K) at emissivity eps toward T (C) from its own
   T_s (C): eps sigma (T_s^2 + T^2)(T_s + T) in K */
static double exterior_coefficient(double eps, double T_s, double T) {
    T_s += 273.15;
    T += 273.15;
    return eps * SIGMA * (T_s * T_s + T * T) * (T_s + T);
}

/* ISO 15099's inside coefficient (W/m2/K) of a window face at dT = T_s - T_air, the air at T_air
   (C), of height H (m) and tilt (deg), the site's pressure (Pa): model/convection.py's iso15099_inside */
static double iso15099(double dT, double T_air, double H, double tilt, double pressure) {
    const double T_f = T_air + 273.15 + 0.25 * dT, lambda = 2.873e-3 + 7.76e-5 * T_f, mu = 3.723e-6 + 4.94e-8 * T_f;
    const double rho = pressure / (287.05 * T_f), ra = rho * rho * H * H * H * 9.81 * 1004.84 * fabs(dT) / (T_f * mu * lambda);
    const double theta = dT > 0.0 ? 180.0 - tilt : tilt, sine_raw = sin(tilt * 3.14159265358979323846 / 180.0);
    const double sine = sine_raw > 1e-9 ? sine_raw : 1e-9;
    double nu, h;
    if (theta < 15.0) nu = 0.13 * cbrt(ra);
    else if (theta <= 90.0) {
        const double ra_cv = 2.5e5 * pow(exp(0.72 * theta) / sine, 0.2);
        nu = ra <= ra_cv ? 0.56 * pow(ra * sine, 0.25) : 0.13 * (cbrt(ra) - cbrt(ra_cv)) + 0.56 * pow(ra_cv * sine, 0.25);
    } else if (theta <= 179.0) {
        const double x = ra * sine;
        nu = 0.56 * pow(x < 1e5 ? 1e5 : x > 1e11 ? 1e11 : x, 0.25);
    } else nu = 0.58 * pow(ra < 1e11 ? ra : 1e11, 0.2);
    h = nu * lambda / H;
    return h > INSIDE_FLOOR ? h : INSIDE_FLOOR;
}

/* A gas gap's conductance (W/m2/K) between panes at T1, T2 (C): model/glazing.py's
   followed_gap_conductance; v = (thickness m, height m, eps, the gas's ten coefficients) */
static double gap_conductance(double T1, double T2, const double *v) {
    const double t1 = T1 + 273.15, t2 = T2 + 273.15, T = 0.5 * (t1 + t2), d = v[0], g = v[2];
    const double k = v[3] + v[4] * T + v[5] * T * T, mu = v[6] + v[7] * T + v[8] * T * T;
    const double cp = v[9] + v[10] * T + v[11] * T * T, rho = 101325 * v[12] / 1000 / (8.314462 * T);
    const double ra = rho * rho * d * d * d * 9.81 * cp * fabs(t1 - t2) / (mu * k * T);
    const double nu1 = ra > 5e4 ? 0.0673838 * pow(ra, 1.0 / 3.0)
                     : ra > 1e4 ? 0.028154 * pow(ra, 0.4134) : 1 + 1.7596678e-10 * pow(ra, 2.2984755);
    const double nu2 = 0.242 * pow(ra / (v[1] / d), 0.272);
    return (nu1 > nu2 ? nu1 : nu2) * k / d + g * SIGMA * (t1 * t1 + t2 * t2) * (t1 + t2);
}

/* model/convection.py's lagged_excess: h - h0, at most h0, so that the lag never grows an error */
static double excess(double h, double h0) {
    return h - h0 < h0 ? h - h0 : h0;
}

/* model/gains.py's people_sensible_heat: EnergyPlus's sensible heat of a person (W) at activity M
   (W) and air temperature T (C), its polynomial bounded by 0 and M (InternalHeatGains.cc) */
static double people_sensible(double M, double T) {
    static const double c[9] = {6.461927, 0.946892, 0.0000255737, 7.139322, -0.0627909, 0.0000589172, -0.198550,
                                0.000940018, -0.00000149532};
    double h = c[0] + c[1] * M + c[2] * M * M + T * (c[3] + c[4] * M + c[5] * M * M) + T * T * (c[6] + c[7] * M + c[8] * M * M);
    if (h < 0.0) h = 0.0;
    if (h > M) h = M;
    return h;
}

/* The lagged coefficients' sources (W) into q (N), from T (N) before the step and the step's
   inputs u: inside, per face, (face, air) and (A phi, h0, cos_up); outside, per face, its node
   and (A, h0, cos_up, azimuth, R_f, wind factor); long-wave, per face, its node and (A, h_rad,
   F, eps); columns: u's T_out, wind speed and direction, T_sky; windows, per window face, (face,
   air) and (A phi, h0, height, tilt, pressure); gaps, per gap, its two pane faces (a, b) and (A f, h0,
   thickness, height, eps, the gas's ten coefficients); pairs, per pair of faces of a followed ScriptF
   exchange, (a, b) and (A_a ScriptF_ab, G0); flows, per air flow from outdoors at the outdoor
   air's density or following the state or wind, (air node, its schedule's column of u or -1) and
   its 14 numbers (model/network.py's FLOW_FIELDS); people, per target of a
   followed people gain, (target, air node, its schedule's column or -1) and (share of the number,
   activity, share of the power, slope, T_ref, the schedule's constant value) */
static void convection(int n, const double *T, const double *u, int n_inside, const int *inside_nodes,
                       const double *inside, int n_outside, const int *outside_nodes, const double *outside,
                       int n_longwave, const int *longwave_nodes, const double *longwave, const int *columns,
                       int n_windows, const int *window_nodes, const double *windows, int n_gaps,
                       const int *gap_nodes, const double *gaps, int n_pairs, const int *pair_nodes,
                       const double *pairs, int n_flows, const int *flow_nodes, const double *flows,
                       int n_people, const int *people_nodes, const double *people, double *q) {
    int k;
    for (k = 0; k < n; k++) q[k] = 0.0;
    for (k = 0; k < n_inside; k++) {
        const int face = inside_nodes[2 * k], air = inside_nodes[2 * k + 1];
        const double *v = inside + 3 * k, dT = T[air] - T[face];
        double h = tarp_natural(-dT, v[2]);
        if (h < INSIDE_FLOOR) h = INSIDE_FLOOR;
        q[face] += v[0] * excess(h, v[1]) * dT;
        q[air] -= v[0] * excess(h, v[1]) * dT;
    }
    for (k = 0; k < n_outside; k++) {
        const int face = outside_nodes[k];
        const double *v = outside + 6 * k, dT = u[columns[0]] - T[face];
        const double speed = u[columns[1]] * v[5] > 0.0 ? u[columns[1]] * v[5] : 0.0;
        const double h_n = tarp_natural(-dT, v[2]);
        double diff = fabs(u[columns[2]] - v[3]), forced;
        if (diff - 180.0 > 0.001) diff -= 360.0;
        forced = fabs(v[2]) >= 0.98 || fabs(diff) - 90.0 <= 0.001 ? 3.26 * pow(speed, 0.89) : 3.55 * pow(speed, 0.617);
        q[face] += v[0] * excess(h_n + v[4] * (sqrt(h_n * h_n + forced * forced) - h_n), v[1]) * dT;
    }
    for (k = 0; k < n_longwave; k++) {
        const int face = longwave_nodes[k];
        const double *v = longwave + 4 * k, T_e = T[face], t_out = u[columns[0]], t_sky = u[columns[3]];
        const double sky = excess(exterior_coefficient(v[3], T_e, t_sky), v[1]) * v[2] * (t_sky - T_e);
        const double air = excess(exterior_coefficient(v[3], T_e, t_out), v[1]) * (1.0 - v[2]) * (t_out - T_e);
        q[face] += v[0] * (sky + air);
    }
    for (k = 0; k < n_windows; k++) {
        const int face = window_nodes[2 * k], air = window_nodes[2 * k + 1];
        const double *v = windows + 5 * k, dT = T[air] - T[face];
        const double flow = v[0] * excess(iso15099(-dT, T[air], v[2], v[3], v[4]), v[1]) * dT;
        q[face] += flow;
        q[air] -= flow;
    }
    for (k = 0; k < n_gaps; k++) {
        const int a = gap_nodes[2 * k], b = gap_nodes[2 * k + 1];
        const double *v = gaps + 15 * k;
        const double flow = v[0] * excess(gap_conductance(T[a], T[b], v + 2), v[1]) * (T[b] - T[a]);
        q[a] += flow;
        q[b] -= flow;
    }
    for (k = 0; k < n_pairs; k++) {
        const int a = pair_nodes[2 * k], b = pair_nodes[2 * k + 1];
        const double *v = pairs + 2 * k;
        const double flow = excess(v[0] * exterior_coefficient(1.0, T[a], T[b]), v[1]) * (T[b] - T[a]);
        q[a] += flow;
        q[b] -= flow;
    }
    for (k = 0; k < n_flows; k++) {
        /* model/network.py's outdoor_density_ratio, (20 + 273.15) / (T_out + 273.15), and
           followed_flow: v = (g, cap, A, B, C, D, wind factor, minimum and maximum indoor, delta,
           minimum and maximum outdoor, maximum wind, outdoor density or not) */
        const int air = flow_nodes[2 * k], column = flow_nodes[2 * k + 1];
        const double *v = flows + 14 * k, t_out = u[columns[0]], share = column >= 0 ? u[column] : 1.0;
        const double wind = v[6] * (columns[1] >= 0 ? u[columns[1]] : 0.0), T_air = T[air];
        const double ratio = v[13] > 0.0 ? (20.0 + 273.15) / (t_out + 273.15) : 1.0;
        const int on = T_air >= v[7] && T_air <= v[8] && T_air - t_out >= v[9] && t_out >= v[10] && t_out <= v[11] &&
                       wind <= v[12];
        double flow = v[2] + v[3] * fabs(T_air - t_out) + v[4] * wind + v[5] * wind * wind, x;
        flow = (flow > 0.0 ? flow : 0.0) * on;
        x = ratio * flow - 1.0;
        q[air] += v[0] * share * (x < v[1] ? x : v[1]) * (t_out - T_air);
    }
    for (k = 0; k < n_people; k++) {
        const int target = people_nodes[3 * k], air = people_nodes[3 * k + 1], column = people_nodes[3 * k + 2];
        const double *v = people + 6 * k, share = column >= 0 ? u[column] : v[5];
        q[target] += share * (v[0] * people_sensible(v[1], T[air]) - v[2] - v[3] * (T[air] - v[4]));
    }
}

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
    const int lagged = n_inside > 0 || n_outside > 0 || n_longwave > 0 || n_windows > 0 || n_gaps > 0 || n_pairs > 0 ||
                       n_flows > 0 || n_people > 0;
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
            convection(n, T, t_s, n_inside, inside_nodes, inside, n_outside, outside_nodes, outside, n_longwave,
                       longwave_nodes, longwave, columns, n_windows, window_nodes, windows, n_gaps, gap_nodes, gaps,
                       n_pairs, pair_nodes, pairs, n_flows, flow_nodes, flows, n_people, people_nodes, people, extra);
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
