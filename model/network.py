"""Assemble the nodal network `C dT/dt = A T + B u(t) + q + s(u)` (docs/model.md section 3, paper eq. 5).

Node i of the building file is row i-1, the nodes zone effects add (an internal mass, a
heater's capacity, docs/model.md section 7) after the building's own. The input vector u holds, in this order: `T_out`,
`T_sky` (C), the irradiance input of each exterior component (W/m2 on its outside face: its
`irradiance` column, else `I_<component>`), then the building's other named input columns (heat
inputs W, supply and boundary temperatures C, shading 0..1), then, where a zone declares a daily
gain, the time-of-day basis `day_cos1`, `day_sin1`, ... (no unit: cos and sin of 2 pi h tau / 24 h,
tau the site's local clock time, computed by `model.case`), whose weights are the gain's W. A
proportional gain k u adds k to an existing column of B. Constant sources (internal gains,
fixed boundary and supply temperatures) go to q (W) rather than to a constant input, so that u
holds only what varies in time. The transmitted solar of a shaded glazing, tau s(t) A I(t), is
the product of two inputs: `products` holds those terms, and `sources` adds them, so the
network stays linear in the temperatures and M is still factorised once per forcing mask.
Convective and outside long-wave coefficients that follow the state (docs/model.md section 3.6)
keep their declared value in A; the rest is `convection`, a source each step evaluates from the
temperatures at its start.
"""
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from .building import (DAY_TERMS, MASS_EMISSIVITY, MASS_SOLAR_ABSORPTANCE, WORKDAY_TERMS, Adiabatic, Boundary, Exterior,
                       InsideFace, Surface, mass_area)
from .building_file import gap_nodes, schema_default
from .convection import doe2_faces, iso15099_inside, lagged_excess, outside_cap, tarp_inside_faces, windward_faces
from .discretise import capacities, conductances
from .gains import people_sensible_heat
from .glazing import followed_gap_conductance, gap_coefficients
from .integrate import MAX_STEP
from .interior_sun import with_absorber
from .longwave import T_MEAN, enclosure_exchange, exterior_coefficient, pair_coefficient

AIR_DENSITY = schema_default("site", "air_density")  # kg/m3, a building file's default
C_AIR = 1005.0  # J/kg/K
RHO_C_AIR = AIR_DENSITY * C_AIR  # J/m3/K
# the weather's inputs an exterior face's convection reads: m/s at the station, deg from north
WIND_SPEED, WIND_DIRECTION = "wind_speed", "wind_direction"
# an air flow's numbers in `Convection.flows`
FLOW_FIELDS = ("g", "cap", "A", "B", "C", "D", "wind_factor", "minimum_indoor", "maximum_indoor", "delta",
               "minimum_outdoor", "maximum_outdoor", "maximum_wind", "outdoor")
# a flow that follows nothing: its whole part in the step matrix, its controls always hold
CONSTANT_TERMS, NO_CONTROLS = (1.0, 0.0, 0.0, 0.0), (-np.inf, np.inf, -np.inf, -np.inf, np.inf, np.inf)


def _between(q, a, b, flow):
    """Add `flow` (W) into nodes `a` and take it from nodes `b`: a lagged exchange between two
    nodes conserves the heat it moves."""
    np.add.at(q, a, flow)
    np.add.at(q, b, -flow)


@dataclass(frozen=True)
class Convection:
    """The convective and long-wave coefficients computed at every step (docs/model.md section
    3.6): the step matrix holds each face's declared h0, and the rest, from the temperatures
    before the step and the inputs at its end, is a source: inside, A phi (h(T_s - T_air) - h0)
    (T_air - T_s) on the face and its negative on the air (what one gains the other loses);
    outside, A (h(V, windward, T_e - T_out) - h0) (T_out - T_e) on the face; the outside's
    long-wave, A [(h_r(T_e, T_sky) - h_rad) F (T_sky - T_e) + (h_r(T_e, T_out) - h_rad) (1 - F)
    (T_out - T_e)] on the face.

    inside: ((face node, air node) int (n, 2), (A phi m2, h0 W/m2/K, cos_up) (n, 3)), cos_up the
    cosine of the face's normal into the air with the vertical; outside: (face node int (m,),
    (A m2, h0 W/m2/K, cos_up, azimuth deg, roughness multiplier R_f, wind factor V_z / V_met)
    (m, 6)); longwave: (face node int (k,), (A m2, h_rad W/m2/K, sky view F, emissivity) (k, 4));
    columns: the input indices of T_out, the wind speed and direction (-1 without an outside
    face) and T_sky. A window's (docs/model.md section 4.1) inside face under TARP takes ISO
    15099's coefficient, A phi (h_iso(T_s - T_air, T_air) - h0) (T_air - T_s) on the face and its
    negative on the air, windows: ((face node, air node) (w, 2), (A phi m2, h0 W/m2/K, height m,
    tilt deg, the site's pressure Pa) (w, 5)); each of its gaps A f (h_gap(T_a, T_b) - h0)
    (T_b - T_a) on the pane face a and its negative on b, gaps: ((a, b) (g, 2), (A f m2,
    h0 W/m2/K, thickness m, height m, eps, the gas's ten coefficients) (g, 15)), f the factors
    that scale the gap's link, eps = 1 / (1/e_1 + 1/e_2 - 1). A zone whose ScriptF exchange is
    followed: each pair of its faces (a, b) (p, 2), (A_a ScriptF_ab m2, G0 W/K) (p, 2), A_a ScriptF_ab
    (sigma (T_a^2 + T_b^2)(T_a + T_b) - G0) (T_b - T_a) on face a and its negative on b. A site
    whose air flows carry heat at the outdoor air's density, and each air flow that follows the
    state or the wind (docs/model.md section 3.6): per flow from outdoors (air node, its
    schedule's input column or -1) (f, 2), and (g W/K at the site's air_density, the excess's
    cap x_max, A, B 1/K, C s/m, D s2/m2, wind factor, minimum indoor C, maximum indoor C, delta K,
    minimum outdoor C, maximum outdoor C, maximum wind m/s, 1 at the outdoor air's density else 0)
    (f, 14) (`FLOW_FIELDS`), g s min(r m on - 1, x_max) (T_out - T_air) on the air, s the
    schedule's value (1 without), r = 293.15 / (T_out + 273.15) (1 at the site's density), m =
    max(0, A + B |T_air - T_out| + C v + D v^2) at v the wind factor times the station's, on 1
    while the controls hold, else 0 (`followed_flow`). People whose sensible heat is followed
    (docs/model.md section 3.4): per target node
    (target, air node, the schedule's input column or -1) (r, 3), (its share of the number n,
    activity M W, its share of the power P W, the slope k W/K on the air's row (0 on a radiant
    target's), T_ref C, the schedule's constant value) (r, 6), s (n S(M, T_air) - P - k (T_air -
    T_ref)) on the target, S EnergyPlus's bounded polynomial (`gains.people_sensible_heat`)."""
    inside_nodes: np.ndarray
    inside: np.ndarray
    outside_nodes: np.ndarray
    outside: np.ndarray
    longwave_nodes: np.ndarray
    longwave: np.ndarray
    columns: tuple
    window_nodes: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=int))
    windows: np.ndarray = field(default_factory=lambda: np.zeros((0, 5)))
    gap_nodes: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=int))
    gaps: np.ndarray = field(default_factory=lambda: np.zeros((0, 15)))
    pair_nodes: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=int))
    pairs: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    flow_nodes: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=int))
    flows: np.ndarray = field(default_factory=lambda: np.zeros((0, len(FLOW_FIELDS))))
    people_nodes: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), dtype=int))
    people: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))

    def source(self, T, u, capacity_rate=None):
        """(N,) W of the temperatures T (N,) before the step (C) and the inputs u at its end; the
        nodes' capacities over the sub-step C/dt (N,) W/K (`capacity_rate`, none where not given)
        cap each outside face's convective excess (`convection.outside_cap`)."""
        q = np.zeros(len(T))
        if len(self.inside):
            face, air = self.inside_nodes.T
            area, h0, cos_up = self.inside.T
            dT = T[air] - T[face]
            flow = area * lagged_excess(tarp_inside_faces(-dT, cos_up), h0) * dT
            _between(q, face, air, flow)
        if len(self.outside):
            t_out, speed, direction = (u[j] for j in self.columns[:3])
            area, h0, cos_up, azimuth, roughness, wind = self.outside.T
            dT = t_out - T[self.outside_nodes]
            h = doe2_faces(wind * speed, windward_faces(cos_up, azimuth, direction), -dT, cos_up, roughness)
            rate = 0.0 if capacity_rate is None else capacity_rate[self.outside_nodes]
            np.add.at(q, self.outside_nodes, area * lagged_excess(h, h0, outside_cap(h0, area, rate)) * dT)
        if len(self.longwave):
            t_out, t_sky = u[self.columns[0]], u[self.columns[3]]
            area, h0, F, emissivity = self.longwave.T
            T_e = T[self.longwave_nodes]
            sky = lagged_excess(exterior_coefficient(emissivity, T_e, t_sky), h0) * F * (t_sky - T_e)
            air = lagged_excess(exterior_coefficient(emissivity, T_e, t_out), h0) * (1.0 - F) * (t_out - T_e)
            np.add.at(q, self.longwave_nodes, area * (sky + air))
        if len(self.windows):
            face, air = self.window_nodes.T
            area, h0, height, tilt, pressure = self.windows.T
            dT = T[air] - T[face]
            flow = area * lagged_excess(iso15099_inside(-dT, T[air], height, tilt, pressure), h0) * dT
            _between(q, face, air, flow)
        if len(self.gaps):
            a, b = self.gap_nodes.T
            area, h0, thickness, height, emissivity = self.gaps[:, :5].T
            h = followed_gap_conductance(T[a], T[b], thickness, height, emissivity, self.gaps[:, 5:])
            flow = area * lagged_excess(h, h0) * (T[b] - T[a])
            _between(q, a, b, flow)
        if len(self.pairs):
            a, b = self.pair_nodes.T
            exchange, g0 = self.pairs.T
            flow = lagged_excess(exchange * pair_coefficient(T[a], T[b]), g0) * (T[b] - T[a])
            _between(q, a, b, flow)
        if len(self.flows):
            t_out = u[self.columns[0]]
            speed = u[self.columns[1]] if self.columns[1] >= 0 else 0.0
            air, column = self.flow_nodes.T
            share = np.where(column >= 0, u[np.maximum(column, 0)], 1.0)
            g, cap, terms, wind, limits, outdoor = np.split(self.flows, [1, 2, 6, 7, 13], axis=1)
            ratio = np.where(outdoor[:, 0] > 0, outdoor_density_ratio(t_out), 1.0)
            flow = followed_flow(terms.T, limits.T, T[air], t_out, wind[:, 0] * speed)
            excess = np.minimum(ratio * flow - 1.0, cap[:, 0])
            np.add.at(q, air, g[:, 0] * share * excess * (t_out - T[air]))
        if len(self.people):
            target, air, column = self.people_nodes.T
            number, activity, power, slope, reference, value = self.people.T
            share = np.where(column >= 0, u[np.maximum(column, 0)], value)
            sensible = number * people_sensible_heat(activity, T[air])
            np.add.at(q, target, share * (sensible - power - slope * (T[air] - reference)))
        return q


@dataclass(frozen=True)
class Network:
    C: np.ndarray  # (N,) J/K, 0 on algebraic (radiant) nodes
    A: np.ndarray  # (N, N) W/K
    B: np.ndarray  # (N, n_inputs)
    q: np.ndarray  # (N,) W
    input_names: tuple  # names of the columns of B
    products: tuple = ()  # (node index, input a, input b, coefficient): coefficient u_a u_b W
    switched: tuple = ()  # (node index, input j, g): a conductance g u_j (W/K) from the node to T_out
    convection: Convection | None = None  # coefficients that follow the state, lagged a step

    @property
    def n_nodes(self):
        return len(self.C)

    @property
    def algebraic(self):
        """Boolean mask of the nodes with no capacity (radiant nodes)."""
        return self.C == 0.0

    def switched_diagonal(self, U):
        """(N,) or (n_rows, N): what the switched conductances g u_j add to the diagonal of -A (W/K)
        for one input vector or rows of inputs; None when the network has none."""
        if not self.switched:
            return None
        U = np.asarray(U, dtype=float)
        D = np.zeros(U.shape[:-1] + (self.n_nodes,))
        for node, j, g in self.switched:
            D[..., node] += g * U[..., j]
        return D

    def sources(self, U):
        """B u + q + the products of inputs (W), for one input vector u (n_inputs,) or for rows
        of inputs U (n_rows, n_inputs), which give (n_rows, N)."""
        terms, B, q = self.source_terms(U)
        return terms @ B.T + q

    def source_terms(self, U):
        """The sources as terms linear in their coefficients: (terms, B', q) with
        `sources(U) = terms B'^T + q`, the terms the inputs u then the products u_a u_b
        (n_inputs + n_products of them, W per unit of each), B' (N, that many) their
        coefficients."""
        U = np.asarray(U, dtype=float)
        if not self.products:
            return U, self.B, self.q
        a, b, B = self._product_terms
        return np.concatenate([U, U[..., a] * U[..., b]], axis=-1), B, self.q

    @property
    def source_coefficients(self):
        """B' of `source_terms`: B, with the products' coefficients as columns after the inputs'."""
        return self._product_terms[2] if self.products else self.B

    @cached_property
    def _product_terms(self):
        """The products' input indices a and b and B with their coefficients as columns, made
        once: the Python FMU reads `sources` at every step."""
        nodes, a, b, coefficients = (np.array(x) for x in zip(*self.products))
        products = np.zeros((self.n_nodes, len(self.products)))
        products[nodes, np.arange(len(nodes))] = coefficients
        return a, b, np.hstack([self.B, products])


class Coefficients:
    """A matrix's nonzero rows and columns and the dense block they cross: products with it cost
    what its nonzeros do (a parameter moves a few links of a network of hundreds of nodes)."""

    def __init__(self, matrix):
        self.shape = matrix.shape
        self.rows = np.flatnonzero(np.any(matrix != 0.0, axis=1))
        self.cols = np.flatnonzero(np.any(matrix != 0.0, axis=0))
        self.block = matrix[np.ix_(self.rows, self.cols)]

    def dense(self):
        out = np.zeros(self.shape)
        out[np.ix_(self.rows, self.cols)] = self.block
        return out

    def add_to(self, out, scale):
        """out += scale M, `out` of the matrix's shape."""
        out[np.ix_(self.rows, self.cols)] += scale * self.block

    def add_product(self, out, x, nodes):
        """out += x M^T on `nodes` for rows of vectors x (L, n): `out` (L, len(nodes)) holds the
        columns of `nodes` (sorted indices holding the rows), to which x[:, cols] block^T adds."""
        if len(self.rows):
            out[:, np.searchsorted(nodes, self.rows)] += x[:, self.cols] @ self.block.T


@dataclass(frozen=True)
class Derivative:
    """The derivative of a `Network`'s coefficients with respect to one parameter p (their units
    per unit of p): the capacities C (J/K), the conductances A (W/K), the sources' coefficients
    B' and q (W per unit of each source term, `Network.source_terms`) and the switched
    conductances, as the matrix G (W/K per unit of each input) whose product with the inputs is
    what they add to the diagonal of -A (`Network.switched_diagonal`)."""
    C: np.ndarray  # (N,)
    A: Coefficients
    B: Coefficients
    q: np.ndarray  # (N,)
    G: Coefficients

    @cached_property
    def reads(self):
        """The nodes whose temperatures `source` reads (indices)."""
        return np.union1d(np.union1d(np.flatnonzero(self.C), self.A.cols), self.G.rows)

    @cached_property
    def rows(self):
        """The nodes where `source` may be other than zero (indices)."""
        return np.union1d(np.union1d(self.reads, self.A.rows), np.union1d(self.B.rows, np.flatnonzero(self.q)))

    def close_to(self, other, rtol):
        """Whether `other` is this derivative to `rtol` of the largest entry of each coefficient."""
        def close(a, b):
            return np.abs(a - b).max(initial=0.0) <= rtol * max(np.abs(a).max(initial=0.0), np.abs(b).max(initial=0.0))
        return all(close(a, b) for a, b in ((self.C, other.C), (self.q, other.q), (self.A.dense(), other.A.dense()),
                                            (self.B.dense(), other.B.dense()), (self.G.dense(), other.G.dense())))

    def source(self, before, after, terms, inputs, dt, nodes):
        """(L, len(nodes)): what backward-Euler steps of dt (s) add to the right-hand side of the
        temperatures' derivatives (W per unit of p) on `nodes` (sorted indices holding `rows`),
        from each step's temperatures before and after (C, (L, N): only those it `reads`
        matter), source terms (`Network.source_terms`) and inputs: differentiating
        M T^n+1 = (C/dt) T^n + s^n+1, M = C/dt - A + diag(G u), gives
        M dT^n+1 = (C/dt) dT^n + (dC/dt) (T^n - T^n+1) + dA T^n+1 - (dG u) T^n+1 + dB' terms + dq
        (docs/model.md section 5.9). On the nodes the source can reach alone, a run of a house's
        steps forms a few columns of L x N rather than all."""
        out = (before[:, nodes] - after[:, nodes]) * (self.C[nodes] / dt) + self.q[nodes]
        self.A.add_product(out, after, nodes)
        self.B.add_product(out, terms, nodes)
        if len(self.G.rows):
            switched = np.zeros_like(out)
            self.G.add_product(switched, inputs, nodes)
            out -= switched * after[:, nodes]
        return out


def switched_matrix(network):
    """(N, n_inputs) G: the switched conductances g u_j (W/K) as `G u`."""
    G = np.zeros((network.n_nodes, len(network.input_names)))
    for node, j, g in network.switched:
        G[node, j] += g
    return G


def derivative(network, moved, h):
    """The `Derivative` (moved - network) / h of two networks of one building at parameter values
    h apart; None where they differ in shape (nodes, inputs, which inputs multiply, which
    conductances switch), which no derivative spans."""
    shape = (lambda n: (n.n_nodes, n.input_names, [(node, a, b) for node, a, b, _ in n.products],
                        [(node, j) for node, j, _ in n.switched]))
    if shape(network) != shape(moved):
        return None
    return Derivative(C=(moved.C - network.C) / h, A=Coefficients((moved.A - network.A) / h),
                      B=Coefficients((moved.source_coefficients - network.source_coefficients) / h),
                      q=(moved.q - network.q) / h,
                      G=Coefficients((switched_matrix(moved) - switched_matrix(network)) / h))


def moved(network, derivatives, steps):
    """The `Network` whose coefficients are `network`'s plus sum_i steps_i derivatives_i (each a
    `Derivative` with respect to one parameter, moved by steps_i in its units): for a network
    affine in its parameters, the network at other values without editing and assembling the
    building again. A step of 0 leaves the coefficients exactly as they were."""
    C, q, A = network.C.copy(), network.q.copy(), network.A.copy()
    B = network.source_coefficients.copy()
    G = np.zeros((network.n_nodes, len(network.input_names)))
    for d, s in zip(derivatives, steps):
        if s == 0.0:
            continue
        C += s * d.C
        q += s * d.q
        d.A.add_to(A, s)
        d.B.add_to(B, s)
        d.G.add_to(G, s)
    n = len(network.input_names)
    products = tuple((node, a, b, B[node, n + p]) for p, (node, a, b, _) in enumerate(network.products))
    # G sums the switched conductances of a node and input: its move goes to the first of them
    switched, seen = [], set()
    for node, j, g in network.switched:
        switched.append((node, j, g if (node, j) in seen else g + G[node, j]))
        seen.add((node, j))
    return Network(C=C, A=A, B=B[:, :n], q=q, input_names=network.input_names, products=products,
                   switched=tuple(switched), convection=network.convection)


def input_names(building):
    """The input vector's names, in the order of the columns of B."""
    irradiance = tuple(dict.fromkeys(c.irradiance_input for c in building.exterior_components))
    named = tuple(n for n in building.input_columns if n not in irradiance)
    transmitted = tuple(name for c in building.components for name, _ in c.sun_inputs if name != c.irradiance_input)
    transmitted += tuple(name for c in building.exterior_components for name, _ in c.absorbed_inputs)
    wind = (WIND_SPEED, WIND_DIRECTION) if building.reads_wind is not None else ()
    return (("T_out", "T_sky") + irradiance + named + clock_input_names(building) + transmitted
            + building.schedule_inputs + wind)


def clock_input_names(building):
    """The clock's inputs: the time-of-day basis (`day_<term>` of `DAY_TERMS`), shared by every
    zone with a daily gain, and the working days' (`workday_<term>` of `WORKDAY_TERMS`), shared by
    every zone with a workday gain; () when none declares either."""
    daily = tuple(day_input(t) for t in DAY_TERMS) if any(z.daily_gain for z in building.zones) else ()
    return daily + (tuple(workday_input(t) for t in WORKDAY_TERMS)
                    if any(z.workday_gain for z in building.zones) else ())


def day_input(term):
    """The input holding a daily gain's basis function `term` (e.g. "cos1" -> "day_cos1")."""
    return f"day_{term}"


def workday_input(term):
    """The input holding a workday gain's basis function `term` (e.g. "mean" -> "workday_mean")."""
    return f"workday_{term}"


def sky_view_factor(tilt):
    """F = (1 + cos(tilt)) / 2 for a tilt in degrees from horizontal (1 for a roof, 0.5 for a wall)."""
    return (1.0 + np.cos(np.radians(tilt))) / 2.0


def sky_fraction_energyplus(tilt):
    """The part of a face's long-wave exchange that is with the sky as EnergyPlus takes it
    (Engineering Reference, "External Longwave Radiation"): of its sky view
    F_sky = (1 + cos tilt) / 2 the part beta = sqrt((1 + cos tilt) / 2) is the sky and the rest the
    air near the horizon, F_sky beta; the ground, F_ground = (1 - cos tilt) / 2, is at the air's
    temperature. Both views are the tilt's alone: EnergyPlus reads a surface's View Factor to
    Ground for the sun the ground reflects, never for the long-wave exchange."""
    cos = np.cos(np.radians(tilt))
    return (1.0 + cos) / 2.0 * np.sqrt((1.0 + cos) / 2.0)


def air_density_at(altitude, T=20.0):
    """Density of dry air (kg/m3) at an altitude (m) and a temperature (C): the standard
    atmosphere's pressure p = 101325 (1 - 2.25577e-5 z)^5.2559 Pa (as EnergyPlus takes its site's
    barometric pressure from its elevation), rho = p / (287.05 (T + 273.15))."""
    p = 101325.0 * (1.0 - 2.25577e-5 * altitude) ** 5.2559
    return p / (287.05 * (T + 273.15))


def outdoor_density_ratio(T_out, T_site=20.0):
    """rho(T_out) / rho_site = (T_site + 273.15) / (T_out + 273.15): the outdoor air's density over
    the site's air_density (taken at T_site C), both at the site's pressure (ideal gas), as
    EnergyPlus carries infiltration and ventilation at the outdoor air's density
    (ZoneEquipmentManager.cc, CalcAirFlowSimple)."""
    return (T_site + 273.15) / (np.asarray(T_out, dtype=float) + 273.15)


def followed_flow(terms, controls, T_air, T_out, v):
    """An air flow's part of its design flow (-) as EnergyPlus computes it at each step
    (Engineering Reference, "Infiltration/Ventilation"; ZoneEquipmentManager.cc, CalcAirFlowSimple):
    max(0, A + B |T_air - T_out| + C v + D v^2) while its controls hold, else 0.

    terms: (A -, B 1/K, C s/m, D s2/m2); controls: (minimum indoor C, maximum indoor C, delta K,
    minimum outdoor C, maximum outdoor C, maximum wind m/s), each an array or a number, -inf or inf
    where none; T_air, T_out (C); v the wind at the zone's height (m/s). The flow runs while T_air
    >= its minimum and <= its maximum, T_air - T_out >= delta, T_out within its limits and v <= its
    maximum, each limit taken as EnergyPlus takes it: off beyond it, on at it."""
    A, B, C, D = terms
    low, high, delta, out_low, out_high, fastest = controls
    on = ((T_air >= low) & (T_air <= high) & (T_air - T_out >= delta) & (T_out >= out_low) & (T_out <= out_high)
          & (v <= fastest))
    return np.maximum(A + B * np.abs(T_air - T_out) + C * v + D * v * v, 0.0) * on


def air_conductance(flow, density=AIR_DENSITY):
    """(rho c)_air V / 3600 (W/K) of an air flow V (m3/h) of air of a density (kg/m3)."""
    return density * C_AIR * flow / 3600.0


def assemble(building, names=None):
    """Build the `Network` of a validated `Building`, its inputs in the order of `names` (default
    `input_names(building)`), which must hold every input the building needs."""
    n = building.n_nodes
    needed = input_names(building)
    names = needed if names is None else tuple(names)
    missing = set(needed) - set(names)
    if missing:
        raise ValueError(f"the building needs inputs {sorted(missing)} that are not among {names}")
    col = {name: j for j, name in enumerate(names)}
    C = np.zeros(n)
    A = np.zeros((n, n))
    B = np.zeros((n, len(names)))
    q = np.zeros(n)
    products, switched, inside, outside, longwave, windows, gaps, pairs, flows, people = [], [], [], [], [], [], [], [], [], []

    def link(i, j, g):
        """A conductance g (W/K) between nodes i and j (0-based)."""
        A[i, i] -= g
        A[j, j] -= g
        A[i, j] += g
        A[j, i] += g

    def to_temperature(node, g, temperature):
        """A conductance g (W/K) from a node to a temperature: a number (C), an input column or a
        schedule of the file (a constant one a number)."""
        A[node, node] -= g
        schedule = building.schedules.get(temperature) if isinstance(temperature, str) else None
        if schedule is not None and schedule.is_constant:
            temperature = schedule.value
        if isinstance(temperature, str):
            B[node, col[temperature]] += g
        else:
            q[node] += g * temperature

    def to_zone(node, area, surface, cos_up, window=None, tilt=None):
        """The face's link to its zone's air and radiant node; a `window`'s inside face (of a
        component of `tilt` deg) under TARP takes ISO 15099's coefficient (docs/model.md 4.1)."""
        zone = building.zone(surface.zone)
        link(node, zone.air_node - 1, area * surface.h_conv * zone.convection_factor)
        if zone.inside_convection_algorithm == "tarp" and window is not None:
            windows.append(((node, zone.air_node - 1),
                            (area * zone.convection_factor, surface.h_conv, window.height, tilt, pressure)))
        elif zone.inside_convection_algorithm == "tarp":
            inside.append(((node, zone.air_node - 1), (area * zone.convection_factor, surface.h_conv, cos_up)))
        if zone.longwave == "radiant_node":
            link(node, zone.radiant_node - 1, area * surface.h_rad)

    # the site's pressure (Pa), which its air's density at 20 C gives (ISO 15099's inside convection)
    pressure = building.site.get("air_density", AIR_DENSITY) * 287.05 * 293.15
    # where the radiant part of a zone's gains goes: [(node, share)], its radiant node or its faces
    absorbers = {}
    for z in building.zones:
        if z.longwave == "radiant_node":
            absorbers[z.name] = [(z.radiant_node - 1, 1.0)]
            continue
        face_names, ids, *faces = building.enclosure(z.name)
        if z.internal_mass is not None and mass_area(z.internal_mass) > 0:
            # the internal mass is a face of the zone that sees every other (EnergyPlus's class)
            mass = (f"{z.name} internal mass", z.mass_node, mass_area(z.internal_mass), MASS_EMISSIVITY, 90.0, 0.0,
                    "internal_mass")
            face_names, ids, *faces = (known + (added,) for known, added in zip((face_names, ids, *faces), mass))
        G, shares = enclosure_exchange(face_names, *faces, declared=z.view_factors)
        nodes = np.array(ids) - 1
        for a, b in zip(*np.triu_indices(len(nodes), 1)):
            if G[a, b] != 0.0:
                link(nodes[a], nodes[b], G[a, b])
                if z.longwave_followed:  # G is A ScriptF 4 sigma T_m^3: its exchange factor apart
                    pairs.append(((nodes[a], nodes[b]), (G[a, b] / pair_coefficient(T_MEAN - 273.15,
                                                                                    T_MEAN - 273.15), G[a, b])))
        # the radiant node carries nothing: it reads the faces' mean radiant temperature,
        # sum A eps T_s / sum A eps (EnergyPlus's zone MRT), a row no other node reads
        radiant = z.radiant_node - 1
        A[radiant, nodes] += shares
        A[radiant, radiant] -= 1.0
        absorbers[z.name] = list(zip(nodes, shares))

    # the diffuse pool of each zone an internal mass takes its share of (its faces, once)
    pools = {z.name: building.interior_solar(z.name) for z in building.zones if z.internal_mass is not None}

    def absorbed(zone_name, receivers):
        """[(node, fraction)] of a split of the sun a zone's glazing lets in: each receiver's face
        in the zone (a partition's outer face where only that face is in it), and where the zone
        holds an internal mass and its faces declare their solar absorptances, the mass's share
        of the diffuse pool taken from them (`interior_sun.with_absorber`)."""
        def face(name):
            r = building.component(name)
            face_out = (r.inside.zone != zone_name and isinstance(r.outside, Surface) and r.outside.zone == zone_name)
            return (r.node_ids[-1] if face_out else r.node_ids[0]) - 1

        solar = pools.get(zone_name)
        if solar is None or not {n for n, _ in receivers} <= set(solar[0]):
            return [(face(name), fraction) for name, fraction in receivers]
        z, (names, *faces) = building.zone(zone_name), solar
        split = dict(receivers)
        shares, taken = with_absorber([split.get(n, 0.0) for n in names], *faces,
                                      mass_area(z.internal_mass) * MASS_SOLAR_ABSORPTANCE)
        return [(face(n), f) for n, f in zip(names, shares) if f] + [(z.mass_node - 1, taken)]

    for c in building.components:
        idx = [i - 1 for i in c.node_ids]
        e, out = idx[-1], c.outside
        # a zone's envelope factor is its envelope's materials conducting other than declared: it
        # scales the layers of what separates the zone from the outdoors or a boundary, not the
        # outside film coefficients (wind and sky are the `exterior`'s own physics). A boundary
        # column's factor scales what separates the building from that column, films included.
        materials = (building.zone(c.inside.zone).envelope_factor if isinstance(out, (Exterior, Boundary))
                     else 1.0)
        boundary = (building.boundary_factor(out.temperature)
                    if isinstance(out, Boundary) and isinstance(out.temperature, str) else 1.0)
        C[idx] += c.area * capacities(c.layers, c.depths) * c.capacity_factor
        G = conductances(c.layers, c.depths)
        for k, g in enumerate(G):
            link(idx[k], idx[k + 1], c.area * g * c.conductivity_factor * materials * boundary)
        if isinstance(out, InsideFace):
            # the outside face reads the inside face's temperature, as a boundary would hold it:
            # its own capacity and the heat its last layer draws from it in no balance
            C[e] = 0.0
            A[e, :] = 0.0
            A[e, e], A[e, idx[0]] = -1.0, 1.0
        for gap in () if c.window is None else c.window.gaps:
            # the gap's link holds its declared conductance; what the panes' temperatures add, the source
            a, b = gap_nodes(c.layers, c.depths, gap.layer)
            e1, e2 = gap.emissivities
            gaps.append(((idx[a], idx[b]), (c.area * c.conductivity_factor * materials * boundary, G[a],
                                            c.layers[gap.layer][1], c.window.height, 1.0 / (1.0 / e1 + 1.0 / e2 - 1.0),
                                            *gap_coefficients(gap.gas))))
        # the inside face's normal points into its zone, against the outside's
        cos_up = float(np.cos(np.radians(c.tilt)))
        to_zone(idx[0], c.area, c.inside, -cos_up, c.window, c.tilt)
        if isinstance(out, Exterior):
            F = sky_view_factor(c.tilt) if out.sky_view_factor is None else out.sky_view_factor
            v = out.convection
            if v is not None:
                outside.append((e, (c.area, out.h_conv, cos_up, c.azimuth, v.roughness, v.wind_factor)))
            A[e, e] -= c.area * (out.h_conv + out.h_rad)
            B[e, col["T_out"]] += c.area * (out.h_conv + out.h_rad * (1.0 - F))
            B[e, col["T_sky"]] += c.area * out.h_rad * F
            B[e, col[c.absorbed_input("outside")]] += c.area * out.solar_absorptance
            # a glazing's inner panes absorb part of the sun at the inside face (docs/model.md 4.1)
            B[idx[0], col[c.absorbed_input("inside")]] += c.area * c.inner_solar_absorptance
            if out.longwave_emissivity is not None:
                longwave.append((e, (c.area, out.h_rad, F, out.longwave_emissivity)))
        elif isinstance(out, Surface):
            to_zone(e, c.area, out, cos_up)
        elif isinstance(out, Boundary):
            to_temperature(e, c.area * out.h * boundary, out.temperature)
        else:
            assert isinstance(out, (Adiabatic, InsideFace))
        for sun_input, receivers in c.sun_inputs:
            sun = col[sun_input]
            for receiver, fraction in absorbed(c.inside.zone, receivers):
                transmitted = c.solar_transmittance * c.area * fraction
                if c.shading:
                    # tau A I (s + f (1 - s)): a closed shading (s = 0) still lets in the part f
                    f = building.zone(c.inside.zone).shading_transmittance
                    products.append((receiver, sun, col[c.shading], transmitted * (1.0 - f)))
                    B[receiver, sun] += transmitted * f
                else:
                    B[receiver, sun] += transmitted

    rho = building.site.get("air_density", AIR_DENSITY)
    outdoor = building.site.get("flow_density") == "outdoor"

    def from_outdoors(air, g, column=-1, flow=None, capacity=0.0):
        """An air flow of g W/K (at rho) from outdoors, by the schedule's input `column` (-1: none):
        its excess over g lagged where the site's flows carry heat at the outdoor air's density (a
        flow of 0 too, which an FMU parameter, an air change rate, may open) or the flow (a
        `Ventilation`) follows the state or the wind. Its excess is at most g (the project's bound
        for a lagged coefficient) plus, for a followed flow, its share `capacity` of its zone's
        air's capacity over the longest sub-step (W/K): an error e in the air then becomes
        (C/dt - x) e / (C/dt + g + G), less than e, whatever the flow."""
        if flow is not None and flow.followed and g:
            flows.append(((air, column), (g, 1.0 + capacity / g, *(flow.terms or CONSTANT_TERMS), flow.wind_factor,
                                          *(flow.controls or NO_CONTROLS), float(outdoor))))
        elif outdoor:
            flows.append(((air, column), (g, 1.0, *CONSTANT_TERMS, 0.0, *NO_CONTROLS, 1.0)))

    for z in building.zones:
        air, radiant = z.air_node - 1, absorbers[z.name]
        C[air] += rho * C_AIR * z.volume
        infiltration = air_conductance(z.volume * z.air_change_rate, rho)
        to_temperature(air, infiltration, "T_out")
        from_outdoors(air, infiltration)
        if z.supply is not None:
            to_temperature(air, air_conductance(z.supply.flow * z.supply.flow_factor, rho), z.supply.temperature)
        # each followed flow's share of the air's capacity over the longest sub-step (W/K)
        capacity = rho * C_AIR * z.volume / MAX_STEP / max(sum(v.followed for v in z.ventilation), 1)
        for v in z.ventilation:
            schedule = building.schedules.get(v.schedule) if v.schedule is not None else None
            if schedule is None or schedule.is_constant:
                g = air_conductance(v.flow * (1.0 if schedule is None else schedule.value), rho)
                to_temperature(air, g, "T_out")
                from_outdoors(air, g, flow=v, capacity=capacity)
            else:
                # g s(t) (T_out - T_air): the conductance follows the schedule (`Network.switched`),
                # its T_out term is a product of two inputs
                g = air_conductance(v.flow, rho)
                switched.append((air, col[v.schedule], g))
                products.append((air, col[v.schedule], col["T_out"], g))
                from_outdoors(air, g, col[v.schedule], v, capacity)
        for inflow in z.airflow_from:
            g = air_conductance(inflow.flow, rho)
            A[air, air] -= g
            A[air, building.zone(inflow.zone).air_node - 1] += g
        for other, flow in z.air_exchange:
            link(air, building.zone(other).air_node - 1, air_conductance(flow, rho))
        for to, UA in z.thermal_bridges:
            to_temperature(air, UA if to == "outdoor" else UA * building.boundary_factor(to),
                           "T_out" if to == "outdoor" else to)
        q[air] += z.internal_gain
        for gain in z.gains:
            # P s(t): the radiant fraction to the radiant node (or the faces), the rest to the air
            schedule = building.schedules.get(gain.schedule) if gain.schedule is not None else None
            for node, part in [(air, 1.0 - gain.radiant_fraction)] + [(r, gain.radiant_fraction * w) for r, w in radiant]:
                if schedule is None or schedule.is_constant:
                    q[node] += part * gain.power * (1.0 if schedule is None else schedule.value)
                else:
                    B[node, col[gain.schedule]] += part * gain.power
            if gain.people:
                # the followed sensible heat S(T_air) less the step matrix's linear part, on the air
                # and the radiant targets in the gain's split (the slope's part on the air alone)
                number, activity = gain.people
                column = -1 if schedule is None or schedule.is_constant else col[gain.schedule]
                value = 1.0 if schedule is None or not schedule.is_constant else schedule.value
                for node, part, slope in ([(air, 1.0 - gain.radiant_fraction, gain.temperature_slope)]
                                          + [(r, gain.radiant_fraction * w, 0.0) for r, w in radiant]):
                    people.append(((node, air, column), (part * number, activity, part * gain.power, slope,
                                                         gain.reference_temperature or 0.0, value)))
            if gain.temperature_slope:
                # s(t) k (T_air - T_ref), k <= 0: a conductance -k s(t) to T_ref, switched where s varies
                g = -gain.temperature_slope
                if schedule is None or schedule.is_constant:
                    to_temperature(air, g * (1.0 if schedule is None else schedule.value), gain.reference_temperature)
                else:
                    switched.append((air, col[gain.schedule], g))
                    B[air, col[gain.schedule]] += g * gain.reference_temperature
        for term, W in z.daily_gain:
            B[air, col[day_input(term)]] += W
        for term, W in z.workday_gain:
            B[air, col[workday_input(term)]] += W
        for column, k in z.proportional_gains:
            B[air, col[column]] += k
        if z.internal_mass is not None:
            mass = z.mass_node - 1
            C[mass] += z.internal_mass.capacity
            link(air, mass, z.internal_mass.conductance)
            if z.longwave == "radiant_node":
                link(mass, z.radiant_node - 1, mass_area(z.internal_mass) * MASS_EMISSIVITY
                     * pair_coefficient(T_MEAN - 273.15, T_MEAN - 273.15))
        f_r, gain = z.heat_input_radiative_fraction, z.heat_input_factor
        if z.heat_input_lag is not None:
            # the heater's node takes the heat input and gives it to the air and the radiant node
            # (or the faces) in the heat input's split (docs/model.md section 7)
            heater = z.heater_node - 1
            C[heater] += z.heat_input_lag.capacity
            link(heater, air, (1.0 - f_r) * z.heat_input_lag.conductance)
            for r, w in radiant:
                link(heater, r, f_r * z.heat_input_lag.conductance * w)
            for name in z.heat_input:
                B[heater, col[name]] += gain
        else:
            for name in z.heat_input:
                B[air, col[name]] += gain * (1.0 - f_r)
                for r, w in radiant:
                    B[r, col[name]] += gain * f_r * w
    convection = None
    if inside or outside or longwave or windows or gaps or pairs or flows or people:
        convection = Convection(
            inside_nodes=np.array([n for n, _ in inside], dtype=int).reshape(-1, 2),
            inside=np.array([v for _, v in inside], dtype=float).reshape(-1, 3),
            outside_nodes=np.array([n for n, _ in outside], dtype=int),
            outside=np.array([v for _, v in outside], dtype=float).reshape(-1, 6),
            longwave_nodes=np.array([n for n, _ in longwave], dtype=int),
            longwave=np.array([v for _, v in longwave], dtype=float).reshape(-1, 4),
            columns=tuple(col.get(name, -1) for name in ("T_out", WIND_SPEED, WIND_DIRECTION, "T_sky")),
            window_nodes=np.array([n for n, _ in windows], dtype=int).reshape(-1, 2),
            windows=np.array([v for _, v in windows], dtype=float).reshape(-1, 5),
            gap_nodes=np.array([n for n, _ in gaps], dtype=int).reshape(-1, 2),
            gaps=np.array([v for _, v in gaps], dtype=float).reshape(-1, 15),
            pair_nodes=np.array([n for n, _ in pairs], dtype=int).reshape(-1, 2),
            pairs=np.array([v for _, v in pairs], dtype=float).reshape(-1, 2),
            flow_nodes=np.array([n for n, _ in flows], dtype=int).reshape(-1, 2),
            flows=np.array([v for _, v in flows], dtype=float).reshape(-1, len(FLOW_FIELDS)),
            people_nodes=np.array([n for n, _ in people], dtype=int).reshape(-1, 3),
            people=np.array([v for _, v in people], dtype=float).reshape(-1, 6))
    return Network(C=C, A=A, B=B, q=q, input_names=names, products=tuple(products), switched=tuple(switched),
                   convection=convection)


def face_heat_flux(building, network, T, U, component, face):
    """Heat flux density (W/m2) through a component's face into the component, as a heat flux
    sensor on that face reads it.

    It is what the face's node receives from outside the component: its net heat (A T + B u + q
    + products, W) less what its neighbours in the component give it, over the area. On the
    inside face that is the exchange with the zone's air and radiant node and the sun the face
    absorbs; on an exterior face the outdoor air, sky and sun; on a boundary face the boundary.

    Parameters
    ----------
    building : Building; network : its `Network`
    T : (n_rows, N) node temperatures (C), all nodes
    U : (n_rows, n_inputs) inputs at the same times, in `network.input_names` order
    component : its name; face : "inside" or "outside"

    Returns
    -------
    (n_rows,) W/m2, positive into the component
    """
    c = building.component(component)
    own = [i - 1 for i in c.node_ids]
    node = own[0] if face == "inside" else own[-1]
    T = np.asarray(T, dtype=float)
    net = T @ network.A[node] + network.sources(U)[:, node]
    within = sum(network.A[node, j] * (T[:, j] - T[:, node]) for j in own if j != node)
    return (net - within) / c.area


def capacity_reduced(network, nodes):
    """(c, a, K, follow) of the nodes `nodes` (0-based) with every other node and every input
    held: those with capacity `c` and those without `a` (indices), the conductances among `c`
    with `a` eliminated, K = K_cc - K_ca K_aa^-1 K_ac (W/K, K = -A), and how `a` follow `c` at
    once, T_a = follow T_c, follow = -K_aa^-1 K_ac."""
    has = network.C[nodes] > 0.0
    c, a = nodes[has], nodes[~has]
    K = -network.A[np.ix_(c, c)]
    follow = np.zeros((0, len(c)))
    if len(a):
        follow = -np.linalg.solve(network.A[np.ix_(a, a)], network.A[np.ix_(a, c)])
        K = K - network.A[np.ix_(c, a)] @ follow
    return c, a, K, follow


def slowest_time_constant(network, nodes=None):
    """The slowest time constant (s) of the nodes `nodes` (0-based, each once however often it is
    listed; default every node) with every other node and every input held: the time in which an
    error of their starting temperatures falls by a factor e, whatever its shape through them (a
    heavy floor's deep nodes started where the measurements do not say; a whole building started
    where its weather's past does not say). Those of them without capacity follow the others at
    once.

    It is 1 / lambda_min of C^-1 K on the nodes with capacity, K = -A restricted to `nodes` (its
    diagonal holds their conductances to the nodes held) with those without capacity
    eliminated, K_cc - K_ca K_aa^-1 K_ac; computed as the symmetric C^-1/2 K C^-1/2 where K is
    symmetric (conduction; an air flow from zone to zone is not)."""
    nodes = np.arange(network.n_nodes) if nodes is None else np.asarray(list(dict.fromkeys(nodes)), dtype=int)
    c, _, K, _ = capacity_reduced(network, nodes)
    if len(c) == 0:
        return 0.0
    root = np.sqrt(network.C[c])
    scaled = K / np.outer(root, root)
    rates = np.linalg.eigvalsh(scaled) if np.allclose(scaled, scaled.T) else np.linalg.eigvals(scaled).real
    return float(1.0 / rates.min())
