"""Physics checks that do not use the model's own numbers: hand-computed networks, energy
conservation, limits."""
import copy
import json
from pathlib import Path

import numpy as np
import pytest

from nodeforce.model.building import Boundary, Exterior

from nodeforce.model.building_file import parse_building
from nodeforce.model.discretise import capacities, conductances
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble

TESTCELL = json.loads((Path(__file__).parents[1] / "model" / "data" / "testcell.json").read_text())


def two_wall_box(outside_floor):
    """One zone, a wall to the outdoors and a floor whose outside face is `outside_floor`."""
    return {
        "format": "nodal-building/1", "name": "box",
        "site": {"latitude": 0.0, "longitude": 0.0, "altitude": 0.0, "ground_albedo": 0.2},
        "materials": {"board": {"conductivity": 0.5, "density": 800.0, "specific_heat": 1000.0},
                      "slab": {"conductivity": 2.0, "density": 2000.0, "specific_heat": 900.0}},
        "zones": [{"name": "room", "volume": 30.0, "air_node": 5, "radiant_node": 6}],
        "components": [
            {"name": "wall", "area": 12.0, "tilt": 90.0, "azimuth": 180.0,
             "layers": [["board", 0.1]], "nodes": [{"id": 1, "depth": 0.0}, {"id": 2, "depth": 0.1}],
             "inside": {"zone": "room", "h_conv": 3.0, "h_rad": 5.0},
             "outside": {"type": "exterior", "h_conv": 16.0, "h_rad": 5.0, "solar_absorptance": 0.6}},
            {"name": "floor", "area": 10.0, "tilt": 180.0, "azimuth": 0.0,
             "layers": [["slab", 0.2]], "nodes": [{"id": 3, "depth": 0.0}, {"id": 4, "depth": 0.2}],
             "inside": {"zone": "room", "h_conv": 2.0, "h_rad": 5.0},
             "outside": outside_floor},
        ],
    }


def run_constant(building, inputs, days, dt=3600.0, T0=None):
    """Simulate with every input held constant; the air starts at T0 (C) if given."""
    net = assemble(building)
    n_rows = int(days * 86400 / dt) + 1
    U = np.tile([inputs.get(name, 0.0) for name in net.input_names], (n_rows, 1))
    measured = np.full((n_rows, net.n_nodes), np.nan)
    if T0 is not None:
        measured[0, building.zones[0].air_node - 1] = T0
    return net, U, simulate(building, net, U, dt, measured, warmup_days=0)


def test_r2c_component_is_one_resistance_and_two_half_capacities():
    b = parse_building(TESTCELL)
    door = b.component("door")  # 35 mm of wood, nodes at both faces
    assert conductances(door.layers, door.depths) == pytest.approx([0.23 / 0.035])
    assert capacities(door.layers, door.depths) == pytest.approx([600 * 1600 * 0.035 / 2] * 2)


def test_multilayer_discretisation_by_hand():
    floor = parse_building(TESTCELL).component("floor")
    # nodes at 0, 5, 10, 15, 20, 30, 40 cm; concrete 0-5, polystyrene 5-10, heavy concrete 10-40
    G = conductances(floor.layers, floor.depths)
    assert G == pytest.approx([1.4 / 0.05, 0.035 / 0.05, 1.75 / 0.05, 1.75 / 0.05, 1.75 / 0.1, 1.75 / 0.1])
    C = capacities(floor.layers, floor.depths)
    rc_concrete, rc_poly, rc_heavy = 2200 * 880, 25 * 1400, 2400 * 880
    assert C == pytest.approx([
        rc_concrete * 0.025,
        rc_concrete * 0.025 + rc_poly * 0.025,
        rc_poly * 0.025 + rc_heavy * 0.025,
        rc_heavy * 0.05,
        rc_heavy * 0.075,
        rc_heavy * 0.1,
        rc_heavy * 0.05,
    ])
    # the nodes' capacities add up to the whole floor's
    assert C.sum() == pytest.approx(rc_concrete * 0.05 + rc_poly * 0.05 + rc_heavy * 0.3)


def test_steady_state_equals_hand_computed_conductance_network():
    T_out, T_sky, T_ground = 30.0, 18.0, 12.0
    b = parse_building(two_wall_box({"type": "boundary", "temperature": T_ground, "h": 8.0}))
    _, _, T = run_constant(b, {"T_out": T_out, "T_sky": T_sky}, days=60)

    # By hand: the outside surface of the wall sees an equivalent temperature through h_e.
    F = 0.5  # vertical wall
    h_e = 16.0 + 5.0
    T_eq = (16.0 * T_out + 5.0 * (F * T_sky + (1 - F) * T_out)) / h_e
    G_wall = 12.0 / (1 / h_e + 0.1 / 0.5)
    G_floor = 10.0 / (1 / 8.0 + 0.2 / 2.0)
    # In steady state the air and radiant nodes only relay heat between the two surfaces.
    G_air = 1 / (1 / (12.0 * 3.0) + 1 / (10.0 * 2.0))
    G_rad = 1 / (1 / (12.0 * 5.0) + 1 / (10.0 * 5.0))
    Q = (T_eq - T_ground) / (1 / G_wall + 1 / (G_air + G_rad) + 1 / G_floor)
    # surface temperatures along the chain
    T_s1 = T_eq - Q / G_wall
    T_s2 = T_ground + Q / G_floor
    T_air = (12.0 * 3.0 * T_s1 + 10.0 * 2.0 * T_s2) / (12.0 * 3.0 + 10.0 * 2.0)
    T_rad = (12.0 * 5.0 * T_s1 + 10.0 * 5.0 * T_s2) / (12.0 * 5.0 + 10.0 * 5.0)

    final = T[-1]
    assert final[0] == pytest.approx(T_s1, abs=1e-6)
    assert final[2] == pytest.approx(T_s2, abs=1e-6)
    assert final[4] == pytest.approx(T_air, abs=1e-6)
    assert final[5] == pytest.approx(T_rad, abs=1e-6)
    # and the state is steady: the last two steps agree
    assert np.abs(T[-1] - T[-2]).max() < 1e-9


def boundary_heat_in(building, T, u):
    """Heat entering the building (W) through its outside faces, the air flows, the transmitted
    sun and the gains, written from docs/model.md section 3 term by term (flows between zones move
    heat inside the building and leave at the zone's temperature: only what enters from outside
    or leaves to it counts)."""
    rho_c = 1.2 * 1005
    Q = 0.0
    for c in building.components:
        e, out = T[c.node_ids[-1] - 1], c.outside
        if isinstance(out, Exterior):
            F = (1 + np.cos(np.radians(c.tilt))) / 2
            I = u[out.irradiance or f"I_{c.name}"]
            # the envelope factor scales the materials, not these outside coefficients
            Q += c.area * (out.h_conv * (u["T_out"] - e)
                           + out.h_rad * (F * (u["T_sky"] - e) + (1 - F) * (u["T_out"] - e))
                           + out.solar_absorptance * I)
        elif isinstance(out, Boundary):
            T_b = u[out.temperature] if isinstance(out.temperature, str) else out.temperature
            factor = building.boundary_factors.get(out.temperature, 1.0)
            Q += c.area * factor * out.h * (T_b - e)
        if c.solar_transmittance is not None:
            I = u[c.outside.irradiance or f"I_{c.name}"]
            s, f = (u[c.shading], building.zone(c.inside.zone).shading_transmittance) if c.shading else (1.0, 0.0)
            Q += c.solar_transmittance * c.area * I * (s + f * (1 - s))
    # Air: what enters from outside at its temperature, what leaves at the zone's. The flows
    # between zones enter one zone at the other's temperature and leave it at the same.
    for z in building.zones:
        air = T[z.air_node - 1]
        Q += rho_c * z.volume * z.air_change_rate / 3600 * (u["T_out"] - air)
        supplied = z.supply.flow * z.supply.flow_factor if z.supply else 0.0
        if z.supply is not None:
            T_sup = u[z.supply.temperature] if isinstance(z.supply.temperature, str) else z.supply.temperature
            Q += rho_c * supplied / 3600 * T_sup
        inflow = supplied + sum(f.flow for f in z.airflow_from)
        outflow = sum(f.flow for other in building.zones for f in other.airflow_from if f.zone == z.name)
        Q -= rho_c * (inflow - outflow) / 3600 * air  # the balance leaves the building from here
        # (an exchange both ways between two zones, air_exchange, moves heat inside the building only)
        for to, UA in z.thermal_bridges:
            factor = 1.0 if to == "outdoor" else building.boundary_factors.get(to, 1.0)
            Q += factor * UA * ((u["T_out"] if to == "outdoor" else u[to]) - air)
        Q += z.internal_gain + z.heat_input_factor * sum(u[name] for name in z.heat_input)
    return Q


def test_energy_balance_closes_every_step():
    data = copy.deepcopy(TESTCELL)
    data["zones"][0]["air_change_rate"] = 0.7
    data["zones"][0]["internal_gain"] = 150.0
    b = parse_building(data)
    net = assemble(b)
    dt, n_rows = 900.0, 2 * 96 + 1
    t = np.arange(n_rows) * dt
    rng = np.random.default_rng(1)
    U = np.zeros((n_rows, len(net.input_names)))
    U[:, 0] = 26 + 4 * np.sin(2 * np.pi * t / 86400)
    U[:, 1] = U[:, 0] - 12
    U[:, 2:] = np.clip(900 * np.sin(2 * np.pi * (t - 21600) / 86400), 0, None)[:, None] * rng.uniform(0.3, 1, 7)
    measured = np.full((n_rows, 23), np.nan)
    measured[0, 22] = 24.0
    T = simulate(b, net, U, dt, measured, warmup_days=0)
    T = np.vstack([np.full(23, 24.0), T])  # every node starts at the measured air temperature
    for n in range(1, n_rows):
        stored = np.sum(net.C * (T[n] - T[n - 1])) / dt
        u = dict(zip(net.input_names, U[n]))
        heat_in = boundary_heat_in(b, T[n], u)  # implicit Euler: the fluxes at t_n+1
        scale = max(abs(stored), abs(heat_in), 1.0)
        assert abs(stored - heat_in) <= 1e-6 * scale, n


@pytest.mark.parametrize("f", [0.0, 0.3, 1.0])
def test_a_closed_shading_lets_in_its_part_f_of_the_glazings_sun(f):
    """docs/model.md section 4's transmitted sun tau s A I, with the zone's shading_transmittance f:
    tau A I (s + f (1 - s)), by hand at a blind open, half drawn and closed; it lands on the
    receiving surface only, and f = 0 is the building as declared."""
    data = copy.deepcopy(TESTCELL)
    glazing = next(c for c in data["components"] if "solar_transmittance" in c)
    glazing["shading"] = "blind"
    data["zones"][0]["shading_transmittance"] = f
    b = parse_building(data)
    net = assemble(b)
    c = b.component(glazing["name"])
    receiver = b.component(c.transmitted_solar_to).node_ids[0] - 1
    for s in (1.0, 0.5, 0.0):
        u = dict.fromkeys(net.input_names, 0.0) | {c.irradiance_input: 500.0, "blind": s}
        sources = net.sources(np.array([u[name] for name in net.input_names]))
        hand = c.solar_transmittance * c.area * 500.0 * (s + f * (1 - s))
        assert sources[receiver] == pytest.approx(hand, rel=1e-12, abs=1e-12)
        others = np.delete(sources, [receiver, c.node_ids[-1] - 1])  # the glazing's own outside absorbs
        assert np.all(others == 0.0)


def test_a_steady_start_on_constant_conditions_is_the_steady_state():
    """The steady start's long step on constant conditions lands on the steady state solved by
    hand from the network (-A T = B u + q), whatever the start; the replay then keeps it."""
    b = parse_building(two_wall_box({"type": "boundary", "temperature": 12.0, "h": 4.0}))
    inputs = {"T_out": 0.0, "T_sky": -5.0, "I_wall": 200.0}
    net, U, T = run_constant(b, inputs, days=2, T0=30.0)
    steady = np.linalg.solve(-net.A, net.sources(U[0]))
    measured = np.full((U.shape[0], net.n_nodes), np.nan)
    measured[0, b.zones[0].air_node - 1] = 30.0  # a start far from it
    T = simulate(b, net, U, 3600.0, measured, warmup_days=0, include_start=True, steady_start=True)
    assert np.abs(T[0] - steady).max() < 1e-3
    assert np.abs(T[-1] - steady).max() < 1e-3
    assert np.abs(steady - 30.0).min() > 5.0  # and the start was not already there


def test_forced_node_equals_its_measurement_exactly():
    b = parse_building(TESTCELL)
    net = assemble(b)
    dt, n_rows = 900.0, 2 * 96 + 1
    U = np.zeros((n_rows, len(net.input_names)))
    U[:, 0], U[:, 1] = 28.0, 15.0
    measured = np.full((n_rows, 23), np.nan)
    measured[:, 6] = 20 + np.sin(np.arange(n_rows) / 7.0)  # door inside surface
    measured[40:45, 6] = np.nan  # missing: those steps compute node 7
    force = np.zeros(23, dtype=bool)
    force[6] = True
    T = simulate(b, net, U, dt, measured, force)
    have = np.isfinite(measured[1:, 6])
    assert np.array_equal(T[have, 6], measured[1:, 6][have])
    # where the measurement is missing the node is computed, not held or invented
    assert np.all(np.isfinite(T[~have, 6]))
    assert not np.any(np.isin(T[~have, 6], measured[1:, 6][have]))


def adiabatic_testcell():
    data = copy.deepcopy(TESTCELL)
    for c in data["components"]:
        c["outside"] = {"type": "adiabatic"}
        c.pop("solar_transmittance", None)
        c.pop("transmitted_solar_to", None)
    return parse_building(data)


def test_adiabatic_building_without_sun_keeps_its_temperature():
    b = adiabatic_testcell()
    _, _, T = run_constant(b, {"T_out": 35.0, "T_sky": 0.0}, days=3, dt=900.0, T0=23.0)
    assert np.abs(T - 23.0).max() < 1e-10


def test_adiabatic_building_conserves_heat_from_an_uneven_start():
    b = adiabatic_testcell()
    net = assemble(b)
    n_rows = 3 * 96 + 1
    U = np.zeros((n_rows, len(net.input_names)))
    measured = np.full((n_rows, 23), np.nan)
    measured[0, [0, 8, 16, 22]] = [30.0, 15.0, 22.0, 26.0]
    T = simulate(b, net, U, 900.0, measured, warmup_days=0)
    # the stored heat after the first step equals the stored heat at every later step
    stored = T @ net.C
    assert np.abs(stored - stored[0]).max() <= 1e-9 * np.abs(stored[0])
    # and the building tends to one uniform temperature
    assert T[-1].max() - T[-1].min() < T[0].max() - T[0].min()


def test_within_steps_interpolates_samples_and_holds_heat_inputs_by_hand():
    """Two samples of a temperature (10 -> 20 C) and a heater (0 -> 600 W), three sub-steps: the
    temperature at 1/3, 2/3 and the whole step, the heater's step value throughout; a missing end
    sample stays missing, a missing start sample leaves the end value."""
    from nodeforce.model.integrate import within_steps
    values = np.array([[10.0, 0.0, np.nan], [20.0, 600.0, 5.0], [20.0, 600.0, np.nan]])
    parts = within_steps(values, 3, held=[False, True, False])
    assert [p[1, 0] for p in parts] == pytest.approx([10 + 10 / 3, 10 + 20 / 3, 20.0])
    assert [p[1, 1] for p in parts] == [600.0, 600.0, 600.0]
    assert [p[1, 2] for p in parts] == [5.0, 5.0, 5.0]
    assert all(np.isnan(p[2, 2]) for p in parts)
    assert all(np.array_equal(p[0], values[0], equal_nan=True) for p in parts)


def test_substeps_converge_to_the_exact_response_to_a_ramp_at_first_order():
    """A zone's air (C = rho c V) behind a massless wall (G) to a boundary whose temperature rises
    at r per hour: C T' = G (T_b - T) has the exact solution T = T_b(t) - r tau + (T_0 - T_b(0)
    + r tau) e^(-t/tau), tau = C / G. Backward Euler at the record's hour is off by O(dt); k
    sub-steps cut that error k-fold (first order), the boundary linear between samples."""
    data = {"format": "nodal-building/1", "name": "ramp", "site": {"latitude": 45.0, "longitude": 5.0},
            "materials": {"board": {"conductivity": 0.5, "density": 0.0, "specific_heat": 1000.0}},
            "zones": [{"name": "room", "volume": 30.0}],
            "components": [{"name": "wall", "area": 10.0, "tilt": 90.0, "azimuth": 180.0,
                            "layers": [["board", 0.1]], "nodes": {"max_spacing": 1.0},
                            "inside": {"zone": "room", "h_conv": 3.0, "h_rad": 5.0},
                            "outside": {"type": "boundary", "temperature": "T_b", "h": 25.0}}]}
    b = parse_building(data)
    net = assemble(b)
    dt, n, r = 3600.0, 12, 2.0  # s, steps, K/h
    t = np.arange(n + 1) * dt
    columns = {"T_out": 0.0, "T_sky": 0.0, "T_b": 20.0 + r * t / 3600}
    U = np.column_stack([np.broadcast_to(columns[name], n + 1) for name in net.input_names])
    G = 10.0 / (1 / 3.0 + 0.1 / 0.5 + 1 / 25.0)
    tau = net.C[b.zone("room").air_node - 1] / G
    exact = columns["T_b"][1:] - r * tau / 3600 + r * tau / 3600 * np.exp(-t[1:] / tau)
    errors = [np.abs(simulate(b, net, U, dt, warmup_days=0, substeps=k)[:, b.zone("room").air_node - 1]
                     - exact).max() for k in (1, 4, 16, 64)]
    assert errors[0] > 0.1  # the hour's step is visibly off
    assert errors[2] / errors[1] == pytest.approx(1 / 4, rel=0.15)
    assert errors[3] / errors[2] == pytest.approx(1 / 4, rel=0.15)
    assert errors[3] < 0.005


def test_a_component_s_slowest_time_constant_by_hand_and_from_its_free_decay():
    """One node of capacity C tied to the nodes held by g: tau = C / g. A whole floor's
    slowest time constant is the rate at which an error of its start dies away once every other
    node is held, here from the matrix exponential of the free decay (non-symmetric, no
    eigen-solver): after ten days the error's norm falls by exp(-day / tau) a day."""
    from scipy.linalg import expm

    from nodeforce.model.network import Network, slowest_time_constant
    C, g = 2.0e5, 4.0
    one = Network(C=np.array([C, 0.0]), A=np.array([[-g, g], [g, -g]]), B=np.zeros((2, 0)), q=np.zeros(2),
                  input_names=())
    assert slowest_time_constant(one, [0]) == pytest.approx(C / g, rel=1e-12)
    assert slowest_time_constant(one, [1]) == 0.0  # a node without capacity forgets at once

    building = parse_building(TESTCELL)
    network = assemble(building)
    floor = np.array(building.component("floor").node_ids) - 1
    tau = slowest_time_constant(network, floor)
    decay = network.A[np.ix_(floor, floor)] / network.C[floor][:, None]
    day = 86400.0
    error = expm(decay * 10 * day) @ np.linspace(1.0, -2.0, len(floor))
    assert np.linalg.norm(expm(decay * day) @ error) / np.linalg.norm(error) == pytest.approx(np.exp(-day / tau),
                                                                                            rel=1e-3)
    assert tau > 2 * day  # a heavy floor: the reason its own nodes wait
    assert slowest_time_constant(network, np.r_[floor, floor]) == tau  # a node listed twice counts once


def test_a_whole_building_s_slowest_time_constant_from_its_free_decay_through_the_integrator():
    """Every node free, the radiant node, without capacity, following the others at once: the
    difference of two runs that start apart under the same inputs, stepped by the model's own
    implicit Euler (no eigen-solver, the algebraic node solved with the others at each step),
    falls by exp(-day / tau) a day once the faster modes have died away."""
    from nodeforce.model.integrate import ImplicitEuler, Sources
    from nodeforce.model.network import slowest_time_constant
    network = assemble(parse_building(TESTCELL))
    n, dt, day = network.n_nodes, 600.0, 86400.0
    assert (network.C == 0.0).any()
    tau = slowest_time_constant(network)
    sources = Sources(*network.source_terms(np.zeros((int(60 * day / dt), len(network.input_names)))))
    stepper, free = ImplicitEuler(network, dt), np.zeros(n, dtype=bool)
    apart = np.linalg.norm(stepper.run(np.full(n, 20.0), sources, free)[0]
                           - stepper.run(np.linspace(10.0, 30.0, n), sources, free)[0], axis=1)
    assert apart[-1] / apart[-1 - int(day / dt)] == pytest.approx(np.exp(-day / tau), rel=1e-3)
    # slower than the floor alone, its neighbours held: free, they follow it
    floor = np.array(parse_building(TESTCELL).component("floor").node_ids) - 1
    assert tau >= slowest_time_constant(network, floor)


def test_a_layer_whose_outside_face_is_held_at_its_inside_face_stores_as_half_of_it_with_an_adiabatic_back():
    """EnergyPlus's InternalMass (`inside_face`): the outside face at the inside face's
    temperature and the heat that crosses it counted nowhere. The slab's middle is then a plane of
    symmetry, so a 0.1 m board in four elements is a 0.05 m board in two with an adiabatic back:
    every node of the half and the air alike to rounding, the room heated by a step, the mass
    taking its sun and long-wave through the floor's face."""
    def box(thickness, outside):
        data = two_wall_box({"type": "adiabatic"})
        depths = [0.0, 0.025, 0.05, 0.075, 0.1][:round(thickness / 0.025) + 1]
        data["components"].append({"name": "mass", "area": 8.0, "tilt": 90.0, "azimuth": 0.0,
                                   "layers": [["board", thickness]],
                                   "nodes": [{"id": 7 + k, "depth": d} for k, d in enumerate(depths)],
                                   "inside": {"zone": "room", "h_conv": 2.5, "h_rad": 5.0}, "outside": outside})
        return parse_building(data)

    held, half = box(0.1, {"type": "inside_face"}), box(0.05, {"type": "adiabatic"})
    assert held.component("mass").depths == (0.0, 0.025, 0.05, 0.075, 0.1)
    inputs = {"T_out": 0.0, "T_sky": -5.0, "I_wall": 200.0}
    _, _, T_held = run_constant(held, inputs, days=3, dt=600.0, T0=20.0)
    _, _, T_half = run_constant(half, inputs, days=3, dt=600.0, T0=20.0)
    kept = [i - 1 for i in range(1, 7)] + [i - 1 for i in half.component("mass").node_ids]
    assert np.abs(T_held[:, kept] - T_half[:, kept]).max() < 1e-9
    # the outside face reads the inside face's temperature
    s, e = (i - 1 for i in held.component("mass").node_ids[::4])
    assert np.abs(T_held[:, e] - T_held[:, s]).max() < 1e-12
    # and the mass does something: a free-floating room cools otherwise without it
    assert np.abs(T_held[:, 4] - run_constant(parse_building(two_wall_box({"type": "adiabatic"})), inputs, 3,
                                              600.0, 20.0)[2][:, 4]).max() > 0.1
