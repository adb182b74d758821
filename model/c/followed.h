/* The coefficients that follow the state (model/network.py, `Convection`; docs/model.md section
   3.6): each step's sources beyond the h0 of the step matrix, from the temperatures before the
   step and its inputs, face by face: the same arithmetic as model/convection.py's,
   model/longwave.py's, model/glazing.py's and model/gains.py's. Shared by the direct model's
   compiled steps (steps.c) and the standalone FMU (fmu_build/c/nodeforce_fmu.c). */
#ifndef NODEFORCE_FOLLOWED_H
#define NODEFORCE_FOLLOWED_H

#include <math.h>

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

/* model/convection.py's lagged_excess: h - h0, at most cap, so that the lag never grows an error */
static double capped_excess(double h, double h0, double cap) {
    return h - h0 < cap ? h - h0 : cap;
}

/* ... at most h0 */
static double excess(double h, double h0) {
    return capped_excess(h, h0, h0);
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

/* A `Convection`'s arrays, each kind's count, nodes and values as `convection` below reads them */
typedef struct {
    int n_inside, n_outside, n_longwave, n_windows, n_gaps, n_pairs, n_flows, n_people;
    const int *inside_nodes, *outside_nodes, *longwave_nodes, *window_nodes, *gap_nodes, *pair_nodes, *flow_nodes,
        *people_nodes, *columns;
    const double *inside, *outside, *longwave, *windows, *gaps, *pairs, *flows, *people;
} Followed;

/* Whether any coefficient of f follows the state */
static int followed_any(const Followed *f) {
    return f->n_inside > 0 || f->n_outside > 0 || f->n_longwave > 0 || f->n_windows > 0 || f->n_gaps > 0 ||
           f->n_pairs > 0 || f->n_flows > 0 || f->n_people > 0;
}

/* The lagged coefficients' sources (W) into q (N), from T (N) before the step and the step's
   inputs u; f holds: inside, per face, (face, air) and (A phi, h0, cos_up); outside, per face, its node
   and (A, h0, cos_up, azimuth, R_f, wind factor); long-wave, per face, its node and (A, h_rad,
   F, eps); columns: u's T_out, wind speed and direction, T_sky; windows, per window face, (face,
   air) and (A phi, h0, height, tilt, pressure); gaps, per gap, its two pane faces (a, b) and (A f, h0,
   thickness, height, eps, the gas's ten coefficients); pairs, per pair of faces of a followed ScriptF
   exchange, (a, b) and (A_a ScriptF_ab, G0); flows, per air flow from outdoors at the outdoor
   air's density or following the state or wind, (air node, its schedule's column of u or -1) and
   its 14 numbers (model/network.py's FLOW_FIELDS); people, per target of a
   followed people gain, (target, air node, its schedule's column or -1) and (share of the number,
   activity, share of the power, slope, T_ref, the schedule's constant value). The nodes'
   capacities times per_second, C/dt (W/K), cap an outside face's convective excess at
   h0 + 2 C/(A dt) (model/convection.py's outside_cap). */
static void convection(const Followed *f, int n, const double *T, const double *u, const double *capacity,
                       double per_second, double *q) {
    int k;
    for (k = 0; k < n; k++) q[k] = 0.0;
    for (k = 0; k < f->n_inside; k++) {
        const int face = f->inside_nodes[2 * k], air = f->inside_nodes[2 * k + 1];
        const double *v = f->inside + 3 * k, dT = T[air] - T[face];
        double h = tarp_natural(-dT, v[2]);
        if (h < INSIDE_FLOOR) h = INSIDE_FLOOR;
        q[face] += v[0] * excess(h, v[1]) * dT;
        q[air] -= v[0] * excess(h, v[1]) * dT;
    }
    for (k = 0; k < f->n_outside; k++) {
        const int face = f->outside_nodes[k];
        const double *v = f->outside + 6 * k, dT = u[f->columns[0]] - T[face];
        const double speed = u[f->columns[1]] * v[5] > 0.0 ? u[f->columns[1]] * v[5] : 0.0;
        const double h_n = tarp_natural(-dT, v[2]);
        double diff = fabs(u[f->columns[2]] - v[3]), forced;
        if (diff - 180.0 > 0.001) diff -= 360.0;
        forced = fabs(v[2]) >= 0.98 || fabs(diff) - 90.0 <= 0.001 ? 3.26 * pow(speed, 0.89) : 3.55 * pow(speed, 0.617);
        q[face] += v[0] * capped_excess(h_n + v[4] * (sqrt(h_n * h_n + forced * forced) - h_n), v[1],
                                        v[1] + 2.0 * capacity[face] * per_second / v[0]) * dT;
    }
    for (k = 0; k < f->n_longwave; k++) {
        const int face = f->longwave_nodes[k];
        const double *v = f->longwave + 4 * k, T_e = T[face], t_out = u[f->columns[0]], t_sky = u[f->columns[3]];
        const double sky = excess(exterior_coefficient(v[3], T_e, t_sky), v[1]) * v[2] * (t_sky - T_e);
        const double air = excess(exterior_coefficient(v[3], T_e, t_out), v[1]) * (1.0 - v[2]) * (t_out - T_e);
        q[face] += v[0] * (sky + air);
    }
    for (k = 0; k < f->n_windows; k++) {
        const int face = f->window_nodes[2 * k], air = f->window_nodes[2 * k + 1];
        const double *v = f->windows + 5 * k, dT = T[air] - T[face];
        const double flow = v[0] * excess(iso15099(-dT, T[air], v[2], v[3], v[4]), v[1]) * dT;
        q[face] += flow;
        q[air] -= flow;
    }
    for (k = 0; k < f->n_gaps; k++) {
        const int a = f->gap_nodes[2 * k], b = f->gap_nodes[2 * k + 1];
        const double *v = f->gaps + 15 * k;
        const double flow = v[0] * excess(gap_conductance(T[a], T[b], v + 2), v[1]) * (T[b] - T[a]);
        q[a] += flow;
        q[b] -= flow;
    }
    for (k = 0; k < f->n_pairs; k++) {
        const int a = f->pair_nodes[2 * k], b = f->pair_nodes[2 * k + 1];
        const double *v = f->pairs + 2 * k;
        const double flow = excess(v[0] * exterior_coefficient(1.0, T[a], T[b]), v[1]) * (T[b] - T[a]);
        q[a] += flow;
        q[b] -= flow;
    }
    for (k = 0; k < f->n_flows; k++) {
        /* model/network.py's outdoor_density_ratio, (20 + 273.15) / (T_out + 273.15), and
           followed_flow: v = (g, cap, A, B, C, D, wind factor, minimum and maximum indoor, delta,
           minimum and maximum outdoor, maximum wind, outdoor density or not) */
        const int air = f->flow_nodes[2 * k], column = f->flow_nodes[2 * k + 1];
        const double *v = f->flows + 14 * k, t_out = u[f->columns[0]], share = column >= 0 ? u[column] : 1.0;
        const double wind = v[6] * (f->columns[1] >= 0 ? u[f->columns[1]] : 0.0), T_air = T[air];
        const double ratio = v[13] > 0.0 ? (20.0 + 273.15) / (t_out + 273.15) : 1.0;
        const int on = T_air >= v[7] && T_air <= v[8] && T_air - t_out >= v[9] && t_out >= v[10] && t_out <= v[11] &&
                       wind <= v[12];
        double flow = v[2] + v[3] * fabs(T_air - t_out) + v[4] * wind + v[5] * wind * wind, x;
        flow = (flow > 0.0 ? flow : 0.0) * on;
        x = ratio * flow - 1.0;
        q[air] += v[0] * share * (x < v[1] ? x : v[1]) * (t_out - T_air);
    }
    for (k = 0; k < f->n_people; k++) {
        const int target = f->people_nodes[3 * k], air = f->people_nodes[3 * k + 1], column = f->people_nodes[3 * k + 2];
        const double *v = f->people + 6 * k, share = column >= 0 ? u[column] : v[5];
        q[target] += share * (v[0] * people_sensible(v[1], T[air]) - v[2] - v[3] * (T[air] - v[4]));
    }
}

#endif
