"""A window's panes as EnergyPlus solves them (docs/model.md section 4.1): ISO 15099's inside
coefficient and the gap's conductance by hand, a double-glazed window's steady pane temperatures
against its energy balance solved independently, the limit of no sun and one temperature, and
the same steps in numpy and in C."""

import numpy as np
import pytest
from scipy.optimize import fsolve

from nodeforce.model import compiled
from nodeforce.model.building_file import parse_building
from nodeforce.model.convection import iso15099_inside
from nodeforce.model.errors import InputError
from nodeforce.model.glazing import followed_gap_conductance, gap_coefficients
from nodeforce.model.integrate import simulate
from nodeforce.model.longwave import SIGMA
from nodeforce.model.network import assemble

GAP, GLASS, H0 = 0.0127, 0.003, 5.0  # m, m, W/m2/K: the gap's declared conductance
AREA, HEIGHT, SUPPLY = 2.0, 1.5, 30.0  # m2, m, m3/h
H_OUT, H_RAD_OUT, ALPHA_OUT, ALPHA_IN = 20.0, 4.0, 0.10, 0.05


def window_data(window=True):
    """A room whose one face is a south double-glazed window, its air held near 20 C by a supply."""
    data = {"format": "nodal-building/1", "name": "one window", "description": "tests/test_windows.py",
            "site": {"latitude": 40.0, "longitude": -105.0, "altitude": 0.0, "timezone": "Etc/GMT+7",
                     "ground_albedo": 0.2, "ground_temperature": 10.0},
            "materials": {"glass": {"conductivity": 1.0, "density": 2500.0, "specific_heat": 750.0},
                          "gap": {"conductivity": H0 * GAP, "density": 1.2, "specific_heat": 1005.0}},
            "zones": [{"name": "room", "volume": 30.0, "air_change_rate": 0.0, "internal_gain": 0.0,
                       "inside_convection_algorithm": "tarp", "supply": {"flow": SUPPLY, "temperature": 20.0}}],
            "components": [{"name": "window", "area": AREA, "tilt": 90.0, "azimuth": 180.0,
                            "layers": [["glass", GLASS], ["gap", GAP], ["glass", GLASS]], "nodes": {"max_spacing": 0.025},
                            "inside": {"zone": "room", "h_conv": 2.5, "h_rad": 5.0},
                            "outside": {"type": "exterior", "h_conv": H_OUT, "h_rad": H_RAD_OUT,
                                        "solar_absorptance": ALPHA_OUT},
                            "inner_solar_absorptance": ALPHA_IN}]}
    if window:
        data["components"][0]["window"] = {"height": HEIGHT, "gaps": [{"layer": 1, "emissivities": [0.84, 0.84]}]}
    return data


def steady(building, T_out, sun, steps=600, dt=300.0):
    """Every node after `steps` steps under constant weather: T_out (C) outside and as the sky,
    `sun` W/m2 on the window."""
    network = assemble(building)
    U = np.zeros((steps + 1, len(network.input_names)))
    U[:, network.input_names.index("T_out")] = U[:, network.input_names.index("T_sky")] = T_out
    U[:, network.input_names.index(building.components[0].irradiance_input)] = sun
    return simulate(building, network, U, dt, warmup_days=0)[-1]


def test_a_vertical_window_5_K_cooler_than_the_air_by_hand():
    # T_f = 293.15 - 5 / 4 = 291.9 K; lambda = 2.873e-3 + 7.76e-5 * 291.9 = 0.02552444 W/m/K;
    # mu = 3.723e-6 + 4.94e-8 * 291.9 = 1.8142860e-5 kg/m/s; rho = 101325 / (287.05 * 291.9)
    # = 1.2092747 kg/m3; Ra = rho^2 * 1.5^3 * 9.81 * 1004.84 * 5 / (291.9 mu lambda) = 1.7995e9;
    # vertical: Nu = 0.56 Ra^(1/4) = 115.34, h = Nu lambda / 1.5 = 1.9627 W/m2/K
    lam, mu, rho = 0.02552444, 1.8142860e-5, 101325 / (287.05 * 291.9)
    ra = rho ** 2 * 1.5 ** 3 * 9.81 * 1004.84 * 5 / (291.9 * mu * lam)
    assert ra == pytest.approx(1.7995e9, rel=1e-4)
    assert iso15099_inside(-5.0, 20.0, 1.5, 90.0) == pytest.approx(0.56 * ra ** 0.25 * lam / 1.5, rel=1e-9)
    assert iso15099_inside(-5.0, 20.0, 1.5, 90.0) == pytest.approx(1.9627, abs=1e-4)


def test_a_warm_skylight_looks_down_on_the_room_and_is_stable():
    # a horizontal window (tilt 0) 5 K warmer than the air below: theta = 180 - 0, Nu = 0.58 Ra^(1/5)
    # at T_f = 293.15 + 1.25 = 294.4 K
    T_f = 294.4
    lam, mu, rho = 2.873e-3 + 7.76e-5 * T_f, 3.723e-6 + 4.94e-8 * T_f, 101325 / (287.05 * T_f)
    ra = rho ** 2 * 1.5 ** 3 * 9.81 * 1004.84 * 5 / (T_f * mu * lam)
    assert iso15099_inside(5.0, 20.0, 1.5, 0.0) == pytest.approx(0.58 * ra ** 0.2 * lam / 1.5, rel=1e-9)
    # and cooler than the air, the heat falls off it: theta 0, Nu = 0.13 Ra^(1/3), three times more
    assert iso15099_inside(-5.0, 20.0, 1.5, 0.0) > 2.5 * iso15099_inside(5.0, 20.0, 1.5, 0.0)


def test_a_gap_at_one_temperature_conducts_and_radiates_by_hand():
    # no difference across it: Ra = 0, Nu = 1, h = k / d + eps 4 sigma T^3; at 10 C air conducts
    # k = 2.873e-3 + 7.76e-5 * 283.15 = 0.02484544 W/m/K; eps = 1 / (1/0.84 + 1/0.84 - 1) = 0.724138
    eps = 1 / (2 / 0.84 - 1)
    hand = 0.02484544 / 0.0127 + eps * 4 * SIGMA * 283.15 ** 3
    assert followed_gap_conductance(10.0, 10.0, 0.0127, 1.5, eps, [gap_coefficients("air")]) == pytest.approx(hand,
                                                                                                              rel=1e-9)
    # 15 K across it, the radiation exactly: eps sigma (T1^4 - T2^4) / (T1 - T2), and convection
    # no less than conduction
    h = followed_gap_conductance(17.5, 2.5, 0.0127, 1.5, eps, [gap_coefficients("air")])
    radiation = eps * SIGMA * (290.65 ** 4 - 275.65 ** 4) / 15.0
    assert h - radiation >= (2.873e-3 + 7.76e-5 * 283.15) / 0.0127


def test_no_sun_and_one_temperature_leave_the_panes_at_it():
    T = steady(parse_building(window_data()), 20.0, 0.0)
    assert np.abs(T - 20.0).max() < 1e-10


def balance(T_out, sun):
    """The window's steady state solved as its own nonlinear balance: outer face T1, the outer
    pane's inner face T2, the inner pane's outer face T3, the inside face T4 and the air Ta (C)."""
    g = 1.0 / GLASS  # W/m2/K across a pane
    eps = 1 / (2 / 0.84 - 1)
    supply = 1.2 * 1005.0 * SUPPLY / 3600.0 / AREA  # W/m2/K of window, the building file's air
    pressure = 1.2 * 287.05 * 293.15  # Pa, where its air weighs 1.2 kg/m3 at 20 C

    def residual(x):
        T1, T2, T3, T4, Ta = x
        gap = followed_gap_conductance(T2, T3, GAP, HEIGHT, eps, [gap_coefficients("air")])[0]
        h_in = float(iso15099_inside(T4 - Ta, Ta, HEIGHT, 90.0, pressure))
        return [(H_OUT + H_RAD_OUT) * (T_out - T1) + ALPHA_OUT * sun + g * (T2 - T1),
                g * (T1 - T2) + gap * (T3 - T2),
                gap * (T2 - T3) + g * (T4 - T3),
                g * (T3 - T4) + h_in * (Ta - T4) + ALPHA_IN * sun,
                h_in * (T4 - Ta) + supply * (20.0 - Ta)]

    return fsolve(residual, [T_out, T_out, 20.0, 20.0, 20.0], xtol=1e-13)


@pytest.mark.parametrize("T_out, sun", [(-10.0, 0.0), (0.0, 600.0)])
def test_a_double_glazed_window_s_steady_panes_solve_its_balance(T_out, sun):
    building = parse_building(window_data())
    T = steady(building, T_out, sun)
    T1, T2, T3, T4, Ta = balance(T_out, sun)
    nodes = [i - 1 for i in building.components[0].node_ids]  # inside face first
    inner = nodes[0]
    assert T[nodes] == pytest.approx([T4, T3, T2, T1], abs=1e-6)
    assert T[building.zones[0].air_node - 1] == pytest.approx(Ta, abs=1e-6)
    # and the panes are not where the declared conductances put them
    fixed = steady(parse_building(window_data(window=False)), T_out, sun)
    assert abs(fixed[inner] - T[inner]) > 0.05


def test_the_window_steps_alike_in_c_and_numpy(monkeypatch):
    if not compiled.available():
        pytest.skip("no C compiler: the steps are numpy's alone")
    building = parse_building(window_data())
    network = assemble(building)
    hours = np.arange(0, 48, 300 / 3600)
    U = np.zeros((len(hours), len(network.input_names)))
    U[:, network.input_names.index("T_out")] = U[:, network.input_names.index("T_sky")] = 5 + 8 * np.sin(hours / 4)
    U[:, network.input_names.index(building.components[0].irradiance_input)] = np.maximum(0, 700 * np.sin(hours / 3.8))
    T = simulate(building, network, U, 300.0, warmup_days=0)
    monkeypatch.setattr(compiled, "available", lambda: False)
    stepped = simulate(building, network, U, 300.0, warmup_days=0)
    assert np.abs(stepped - T).max() < 1e-10 * np.abs(T).max()


def test_a_gap_with_a_node_within_is_refused():
    data = window_data()
    data["components"][0]["nodes"] = {"max_spacing": 0.005}
    with pytest.raises(InputError, match=r"components\[0\]\.window\.gaps\[0\]\.layer.*none within"):
        parse_building(data)


def test_what_one_pane_or_face_gains_the_other_or_the_air_loses():
    building = parse_building(window_data())
    network = assemble(building)
    T = 20.0 + 8.0 * np.random.default_rng(3).standard_normal(network.n_nodes)
    q = network.convection.source(T, np.zeros(len(network.input_names)))
    (a, b), (face, air) = network.convection.gap_nodes[0], network.convection.window_nodes[0]
    assert q[a] != 0.0 and q[face] != 0.0
    assert abs(q.sum()) < 1e-12 * np.abs(q).sum()
    eps = 1 / (2 / 0.84 - 1)
    h = followed_gap_conductance(T[a], T[b], GAP, HEIGHT, eps, [gap_coefficients("air")])[0]
    h_in = float(iso15099_inside(T[face] - T[air], T[air], HEIGHT, 90.0, 1.2 * 287.05 * 293.15))
    assert q[face] + q[a] == pytest.approx(AREA * (min(h_in - 2.5, 2.5) * (T[air] - T[face])
                                                   + min(h - H0, H0) * (T[b] - T[a])), rel=1e-9)
