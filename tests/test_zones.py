"""The zone terms of docs/model.md sections 1, 3 and 5 against independent calculations: air flows
between zones and supply air, radiative heat input, shading, thermal bridges, measured
irradiance columns and the burn-in."""
import numpy as np
import pandas as pd
import pytest

from nodeforce.iotools.weather import read_weather
from nodeforce.model.building_file import parse_building
from nodeforce.model.case import prepare_case
from nodeforce.model.integrate import forcing_schedule, simulate
from nodeforce.model.network import assemble

from .test_physics import boundary_heat_in

RHO_C = 1.2 * 1005


def wall(name, zone, area, outside, **extra):
    return {"name": name, "area": area, "tilt": 90.0, "azimuth": 180.0, "layers": [["board", 0.1]],
            "nodes": {"max_spacing": 1.0}, "inside": {"zone": zone, "h_conv": 3.0, "h_rad": 5.0},
            "outside": dict(outside), **extra}


def two_zones(**zone_b):
    """Zones A and B, each with one exterior wall; supply air into A flows on to B."""
    exterior = {"type": "exterior", "h_conv": 16.0, "h_rad": 5.0, "solar_absorptance": 0.6}
    return {
        "format": "nodal-building/1", "name": "two zones",
        "site": {"latitude": 45.0, "longitude": 5.0},
        "materials": {"board": {"conductivity": 0.5, "density": 800.0, "specific_heat": 1000.0}},
        "zones": [{"name": "A", "volume": 30.0, "supply": {"flow": 90.0, "temperature": 16.0}},
                  {"name": "B", "volume": 20.0, "airflow_from": [{"zone": "A", "flow": 90.0}], **zone_b}],
        "components": [wall("wA", "A", 12.0, exterior), wall("wB", "B", 8.0, exterior)],
    }


def steady(building, inputs, days=30, dt=3600.0):
    net = assemble(building)
    n_rows = int(days * 86400 / dt) + 1
    U = np.tile([inputs[name] for name in net.input_names], (n_rows, 1))
    T = simulate(building, net, U, dt, np.full((n_rows, net.n_nodes), np.nan), warmup_days=0)
    assert np.abs(T[-1] - T[-2]).max() < 1e-9  # steady
    return T[-1]


def test_two_zones_joined_by_air_flows_reach_the_hand_computed_steady_state():
    Q, f_r, T_out = 400.0, 0.3, 2.0
    b = parse_building(two_zones(heat_input="heater", heat_input_radiative_fraction=f_r))
    T = steady(b, {"T_out": T_out, "T_sky": T_out, "I_wA": 0.0, "I_wB": 0.0, "heater": Q})
    g = RHO_C * 90.0 / 3600  # W/K of the air flow
    # one surface per zone: the radiant node passes the radiative part of Q to it, nothing else
    def wall_out(area):  # surface to outdoor: 0.1 m of board, then h_conv + h_rad outside
        return 1 / (1 / (area * 0.5 / 0.1) + 1 / (area * (16.0 + 5.0)))
    UA_A = 1 / (1 / (12.0 * 3.0) + 1 / wall_out(12.0))
    T_A = (UA_A * T_out + g * 16.0) / (UA_A + g)
    # B: air  h A (T_s - T_B) + g (T_A - T_B) + (1 - f_r) Q = 0
    #    wall h A (T_B - T_s) + f_r Q + K (T_out - T_s) = 0
    h, K = 8.0 * 3.0, wall_out(8.0)
    M = np.array([[-(h + g), h], [h, -(h + K)]])
    T_B, T_s = np.linalg.solve(M, [-(g * T_A + (1 - f_r) * Q), -(f_r * Q + K * T_out)])
    A_air, B_air = b.zone("A").air_node - 1, b.zone("B").air_node - 1
    assert T[A_air] == pytest.approx(T_A, abs=1e-6)
    assert T[B_air] == pytest.approx(T_B, abs=1e-6)
    assert T[b.component("wB").node_ids[0] - 1] == pytest.approx(T_s, abs=1e-6)
    # the radiant node is above the surface by f_r Q / (h_rad A)
    assert T[b.zone("B").radiant_node - 1] - T_s == pytest.approx(f_r * Q / (5.0 * 8.0), abs=1e-6)


def test_a_thermal_bridge_to_a_column_is_a_conductance_from_the_air():
    b0 = parse_building(two_zones())
    b1 = parse_building(two_zones(thermal_bridges={"T_attic": 7.0}))
    inputs = {"T_out": 5.0, "T_sky": 5.0, "I_wA": 0.0, "I_wB": 0.0, "T_attic": 40.0}
    net0, net1 = assemble(b0), assemble(b1)
    air = b1.zone("B").air_node - 1
    assert net1.A[air, air] - net0.A[air, air] == pytest.approx(-7.0)
    assert net1.B[air, net1.input_names.index("T_attic")] == pytest.approx(7.0)
    assert steady(b1, inputs)[air] > steady(b0, {k: v for k, v in inputs.items() if k != "T_attic"})[air]


def multizone_with_everything():
    data = two_zones(heat_input=["heater", "duct"], heat_input_radiative_fraction=0.3,
                     thermal_bridges={"outdoor": 2.0, "T_cellar": 3.0})
    data["zones"][0]["supply"]["temperature"] = "T_supply"
    data["materials"]["glass"] = {"conductivity": 1.0, "density": 2500.0, "specific_heat": 750.0}
    data["components"][0]["outside"]["irradiance"] = "I_south"
    data["components"].append(
        {"name": "window", "area": 3.0, "tilt": 90.0, "azimuth": 180.0, "layers": [["glass", 0.01]],
         "nodes": {"max_spacing": 1.0}, "inside": {"zone": "A", "h_conv": 3.0, "h_rad": 5.0},
         "outside": {"type": "exterior", "h_conv": 16.0, "h_rad": 5.0, "solar_absorptance": 0.1,
                     "irradiance": "I_south"},
         "solar_transmittance": 0.6, "transmitted_solar_to": "floor", "shading": "blind"})
    data["components"].append(
        {"name": "floor", "area": 10.0, "tilt": 180.0, "azimuth": 0.0, "layers": [["board", 0.2]],
         "nodes": {"max_spacing": 0.05}, "inside": {"zone": "A", "h_conv": 2.0, "h_rad": 5.0},
         "outside": {"type": "boundary", "temperature": "T_cellar", "h": 6.0}})
    data["components"].append(
        {"name": "partition", "area": 9.0, "tilt": 90.0, "azimuth": 90.0, "layers": [["board", 0.1]],
         "nodes": {"max_spacing": 0.05}, "inside": {"zone": "A", "h_conv": 2.5, "h_rad": 5.0},
         "outside": {"type": "zone", "zone": "B", "h_conv": 2.5, "h_rad": 5.0}})
    return parse_building(data)


def test_shading_radiative_input_and_flows_close_the_energy_balance_every_step():
    b = multizone_with_everything()
    net = assemble(b)
    assert set(net.input_names) == {"T_out", "T_sky", "I_south", "I_wB", "heater", "duct", "T_supply",
                                    "T_cellar", "blind"}
    dt, n_rows = 600.0, 2 * 144 + 1
    rng = np.random.default_rng(3)
    U = rng.uniform(0, 1, (n_rows, len(net.input_names)))
    scale = {"T_out": 30, "T_sky": 30, "I_south": 800, "I_wB": 500, "heater": 1500, "duct": -200,
             "T_supply": 25, "T_cellar": 20, "blind": 1}
    U *= np.array([scale[n] for n in net.input_names])
    measured = np.full((n_rows, net.n_nodes), np.nan)
    measured[0, :] = 20.0
    T = simulate(b, net, U, dt, measured, warmup_days=0, include_start=True)
    for n in range(1, n_rows):
        stored = np.sum(net.C * (T[n] - T[n - 1])) / dt
        heat_in = boundary_heat_in(b, T[n], dict(zip(net.input_names, U[n])))
        assert abs(stored - heat_in) <= 1e-7 * max(abs(stored), abs(heat_in), 1.0), n


def test_a_closed_blind_lets_no_sun_through():
    b = multizone_with_everything()
    net = assemble(b)
    u = {name: 0.0 for name in net.input_names}
    u.update(I_south=600.0, blind=0.0)
    floor = b.component("floor").node_ids[0] - 1
    assert net.sources(np.array(list(u.values())))[floor] == 0.0
    u["blind"] = 0.5
    assert net.sources(np.array(list(u.values())))[floor] == pytest.approx(0.6 * 3.0 * 600.0 * 0.5)


def weather_csv(path, extra):
    times = pd.date_range("2013-08-21T00:00+01:00", periods=2 * 144 + 1, freq="10min")
    hours = (times - times[0]).total_seconds().to_numpy() / 3600
    sun = np.clip(700 * np.sin(2 * np.pi * (hours - 6) / 24), 0, None)
    frame = pd.DataFrame({"time": times.strftime("%Y-%m-%dT%H:%M:%S%z"), "T_out": 15 + 5 * np.sin(hours),
                          "ghi": sun, "dni": sun, "dhi": 0.2 * sun, **extra(sun)})
    frame.to_csv(path, index=False)
    return read_weather(path)


def test_an_irradiance_column_equals_the_same_values_given_as_I_component(tmp_path):
    def building(irradiance):
        data = two_zones()
        for c in data["components"]:
            if irradiance:
                c["outside"]["irradiance"] = "south_facade"
        return parse_building(data)
    shared = weather_csv(tmp_path / "a.csv", lambda sun: {"south_facade": 0.8 * sun})
    own = weather_csv(tmp_path / "b.csv", lambda sun: {"I_wA": 0.8 * sun, "I_wB": 0.8 * sun})
    T_shared = simulate_case(building(True), shared)
    T_own = simulate_case(building(False), own)
    # the same sources summed in another order (one column for two faces, or one each): equal to rounding
    assert np.abs(T_shared - T_own).max() < 1e-10
    # and the measured column is what the faces get, not the computed transposition
    T_computed = simulate_case(building(False), weather_csv(tmp_path / "c.csv", lambda sun: {}))
    assert np.abs(T_computed - T_own).max() > 0.01


def simulate_case(building, weather):
    case = prepare_case(building, weather)
    return simulate(building, assemble(building), case.U, case.dt, case.measured, warmup_days=1, substeps=case.substeps)


def test_the_burn_in_forces_every_measured_node_and_only_during_its_days():
    b = parse_building(two_zones())
    net = assemble(b)
    dt, n_rows, B = 3600.0, 4 * 24 + 1, 24
    U = np.tile([5.0, 5.0, 0.0, 0.0], (n_rows, 1))
    measured = np.full((n_rows, net.n_nodes), np.nan)
    measured_nodes = [b.zone("A").air_node - 1, b.component("wB").node_ids[0] - 1]
    measured[:, measured_nodes] = 30.0 + np.arange(n_rows)[:, None] % 7
    measured[5, measured_nodes[0]] = np.nan  # a gap in the burn-in: computed there
    schedule = forcing_schedule(np.zeros(net.n_nodes, dtype=bool), measured, B)
    assert schedule[1:B + 1, measured_nodes].sum() == 2 * B - 1
    assert not schedule[B + 1:].any() and not schedule[0].any()
    T = simulate(b, net, U, dt, measured, warmup_days=0, burn_in_steps=B)
    rows = np.arange(1, B + 1)
    have = np.isfinite(measured[rows][:, measured_nodes])
    assert np.array_equal(T[:B][:, measured_nodes][have], measured[rows][:, measured_nodes][have])
    # after the burn-in the nodes are computed: they fall towards the 5 C outside
    assert np.all(T[B:, measured_nodes] < measured[B + 1:, measured_nodes])
