"""The zone effects of docs/model.md section 7 (internal mass, heater lag, envelope factor) against
independent calculations, and both FMUs against the direct model with each of them."""
import copy
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.fmu_build.build import build_fmu
from nodeforce.model.building import MASS_EMISSIVITY, MASS_FILM, MASS_SOLAR_ABSORPTANCE, Exterior
from nodeforce.model.building_file import parse_building
from nodeforce.model.case import Case
from nodeforce.model.effects import EFFECTS
from nodeforce.model.errors import InputError
from nodeforce.model.hlc import heat_loss_coefficient
from nodeforce.model.integrate import simulate
from nodeforce.model.longwave import SIGMA
from nodeforce.model.network import assemble

from .test_hlc import layers_conductance, series
from .test_standalone import two_zones as cell_and_annex

RHO_C = 1.2 * 1005
VOLUME = 40.0


def light_room(**zone):
    """One zone whose only wall has no capacity (density 0) and no outside radiation: the wall is
    a conductance H_o from the air to the outdoor air, and the room's one capacity is its air."""
    return {
        "format": "nodal-building/1", "name": "light room", "site": {"latitude": 45.0, "longitude": 5.0},
        "materials": {"foam": {"conductivity": 0.04, "density": 0.0, "specific_heat": 1000.0}},
        "zones": [{"name": "room", "volume": VOLUME, "heat_input": "heater", **zone}],
        "components": [{"name": "wall", "area": 20.0, "tilt": 90.0, "azimuth": 180.0, "layers": [["foam", 0.1]],
                        "nodes": {"max_spacing": 1.0}, "inside": {"zone": "room", "h_conv": 3.0, "h_rad": 5.0},
                        "outside": {"type": "exterior", "h_conv": 20.0, "h_rad": 0.0, "solar_absorptance": 0.0}}],
    }


H_O = series(20.0 * 3.0, 20.0 * 0.04 / 0.1, 20.0 * 20.0)  # W/K: inside h_c, the foam, outside h_c


def run(building, Q, dt, n_steps, force_air=None):
    """Every node (C) at t_1..t_n after a step of the heat input to Q (W) at t_0+, from 0 C, the
    outdoors at 0 C; the air held at `force_air` (C) if given."""
    net = assemble(building)
    U = np.zeros((n_steps + 1, len(net.input_names)))
    U[:, net.input_names.index("heater")] = Q
    measured = np.full((n_steps + 1, net.n_nodes), np.nan)
    measured[0, :building.n_nodes - len(building.added_nodes)] = 0.0
    force = np.zeros(net.n_nodes, dtype=bool)
    if force_air is not None:
        air = building.zone("room").air_node - 1
        measured[:, air], force[air] = force_air, True
    return simulate(building, net, U, dt, measured, force, warmup_days=0)


def test_internal_mass_and_a_heater_step_give_the_two_time_constant_response():
    """Air C_a and mass C_m joined by H_m; the mass a face of A_m = H_m / MASS_FILM that exchanges
    G_r = A_m eps_m 4 sigma T_m^3 with the radiant node, which joins the wall's inside face by
    A h_rad; the wall (no capacity) joins the air by A h_c and 0 C outdoors by the foam and the
    outside film. The nodes without capacity reduced by hand (the radiant node in series, the
    wall's face a star of three turned into its triangle), x' = K x + b, whose exact solution from
    x(0) = 0 is x(t) = (I - e^(K t)) x_inf with x_inf = -K^-1 b (two time constants, the
    eigenvalues of K). Backward Euler at 10 s steps is within 0.2 % of it."""
    C_m, H_m, Q = 2e6, 150.0, 1000.0
    b = parse_building(light_room(internal_mass={"capacity": C_m, "conductance": H_m}))
    (mass,) = b.added_nodes
    assert mass == b.n_nodes and b.added_nodes[mass] == ("room", "internal mass")
    C_a = RHO_C * VOLUME
    G_r = H_m / MASS_FILM * MASS_EMISSIVITY * 4 * SIGMA * 293.15 ** 3
    to_face, g_out = series(G_r, 20.0 * 5.0), series(20.0 * 0.04 / 0.1, 20.0 * 20.0)
    star = to_face + 20.0 * 3.0 + g_out
    mass_air, mass_out, air_out = to_face * 60.0 / star, to_face * g_out / star, 60.0 * g_out / star
    H = H_m + mass_air
    K = np.array([[-(H + air_out) / C_a, H / C_a], [H / C_m, -(H + mass_out) / C_m]])
    x_inf = -np.linalg.solve(K, [Q / C_a, 0.0])
    assert x_inf[0] > x_inf[1] > 0  # in steady state the mass loses through the wall's face
    dt, n = 10.0, 6 * 360  # 6 h
    T = run(b, Q, dt, n)
    t = dt * np.arange(1, n + 1)
    exact = np.array([(np.eye(2) - expm(K * s)) @ x_inf for s in t])
    air = b.zone("room").air_node - 1
    assert np.abs(T[:, air] - exact[:, 0]).max() < 2e-3 * x_inf[0]
    assert np.abs(T[:, mass - 1] - exact[:, 1]).max() < 2e-3 * x_inf[0]
    # both time constants show: the air's fast rise (tau ~ 3 min) then the mass's slow one (hours)
    taus = sorted(-1 / np.linalg.eigvals(K).real)
    assert taus[0] < 600 < 3600 < taus[1]


def test_the_heaters_capacity_delivers_a_step_as_a_first_order_response():
    """The air held at 0 C: C_h T_h' = Q - H_h T_h, so the heat delivered to the air,
    H_h T_h, is Q (1 - e^(-t H_h / C_h))."""
    C_h, H_h, Q = 4e4, 20.0, 800.0
    b = parse_building(light_room(heat_input_lag={"capacity": C_h, "conductance": H_h}))
    (heater,) = b.added_nodes
    dt, n = 5.0, 720  # an hour; the time constant is 2000 s
    T = run(b, Q, dt, n, force_air=0.0)
    delivered = H_h * T[:, heater - 1]
    t = dt * np.arange(1, n + 1)
    assert np.abs(delivered - Q * (1 - np.exp(-t * H_h / C_h))).max() < 2e-3 * Q
    # without the lag the air gets all of Q at once: the heater node is no longer in the way
    without = assemble(parse_building(light_room()))
    assert without.B[b.zone("room").air_node - 1, without.input_names.index("heater")] == 1.0


def test_a_heater_with_no_capacity_and_an_undeclared_mass_change_nothing():
    """The effects' neutral values (how a candidate's FMU starts) are the building as declared.
    (With a radiative fraction, a heater node splits its heat by the temperatures it sees, as
    docs/model.md section 7 says, which no capacity makes the declared fixed split.)"""
    for effect, f_r in (("internal_mass", 0.3), ("heat_input_lag", 0.0)):
        b = parse_building(light_room(heat_input_radiative_fraction=f_r))
        neutral = EFFECTS[effect].apply(b, "room", {})
        assert neutral.n_nodes == b.n_nodes + 1
        T = run(neutral, 500.0, 900.0, 96)
        assert np.abs(T[:, :b.n_nodes] - run(b, 500.0, 900.0, 96)).max() < 1e-9, effect


def test_an_envelope_factor_of_one_is_the_building_and_it_scales_the_materials_not_the_films(testcell_data):
    b = parse_building(testcell_data)
    one = assemble(EFFECTS["envelope_conductance"].apply(b, "cell", {"factor": 1.0}))
    declared = assemble(b)
    for name in ("C", "A", "B", "q"):
        assert np.array_equal(getattr(one, name), getattr(declared, name)), name
    # by hand: each exterior component's layers scaled by f (its materials f times as
    # conductive), its outside and inside coefficients as declared: the lead's hand sum of the
    # test cell (test_hlc) on a file whose exterior materials are edited
    f = 1.7
    data = copy.deepcopy(testcell_data)
    data["zones"][0]["air_change_rate"] = 0.4
    for c in data["components"]:
        if c["outside"]["type"] == "exterior":
            for layer in c["layers"]:
                layer[0] = scaled_material(data, layer[0], f)
    expected = heat_loss_coefficient(parse_building(data))
    with_air_change = parse_building({**testcell_data, "zones": [dict(testcell_data["zones"][0], air_change_rate=0.4)]})
    by_factor = EFFECTS["envelope_conductance"].apply(with_air_change, "cell", {"factor": f})
    assert heat_loss_coefficient(by_factor) == pytest.approx(expected, rel=1e-12)
    assert heat_loss_coefficient(by_factor) > heat_loss_coefficient(with_air_change)


def test_the_envelope_factor_leaves_the_outside_coefficients_in_the_matrices(testcell_data):
    """Each exterior face's outside node keeps A (h_ce + h_re) to the outdoors: its T_out and T_sky
    columns of B are the declared ones, and its diagonal moves by the change of its last layer's
    link alone (f - 1) A G_last."""
    b = parse_building(testcell_data)
    f = 2.5
    declared, scaled = assemble(b), assemble(EFFECTS["envelope_conductance"].apply(b, "cell", {"factor": f}))
    for name in ("T_out", "T_sky"):
        j = declared.input_names.index(name)
        assert np.array_equal(scaled.B[:, j], declared.B[:, j]), name
    for c in (c for c in b.components if isinstance(c.outside, Exterior)):
        e, previous = c.node_ids[-1] - 1, c.node_ids[-2] - 1
        g_last = declared.A[e, previous]  # A G of the link to the node before the outside one
        assert scaled.A[e, previous] == pytest.approx(f * g_last, rel=1e-12), c.name
        assert scaled.A[e, e] - declared.A[e, e] == pytest.approx(-(f - 1.0) * g_last, rel=1e-9), c.name


def scaled_material(data, name, f):
    """The name of a copy of material `name` whose conductivity is f times (added to data)."""
    scaled = f"{name}_x{f}"
    data["materials"][scaled] = dict(data["materials"][name], conductivity=data["materials"][name]["conductivity"] * f)
    return scaled


def test_the_light_rooms_hlc_is_its_wall_and_the_envelope_factor_scales_the_wall_only():
    """One wall: air -- A h_c -- foam -- A h_ce -- outdoors, and beside A h_c the internal mass's
    face: air -- H_m -- its long-wave G_r -- the radiant node -- A h_rad -- the wall's face; the
    heater's node, all convective, loses nothing. The factor scales the foam alone:
    HLC = 1 / (1/(A h_c + path) + R / (A f) + 1/(A h_ce)), R = 0.1 m / 0.04 W/m/K."""
    H_m = 80.0
    b = parse_building(light_room(internal_mass={"capacity": 1e6, "conductance": H_m},
                                  heat_input_lag={"capacity": 1e4, "conductance": 30.0}))
    G_r = H_m / MASS_FILM * MASS_EMISSIVITY * 4 * SIGMA * 293.15 ** 3
    to_face = 20.0 * 3.0 + series(H_m, G_r, 20.0 * 5.0)
    assert heat_loss_coefficient(b) == pytest.approx(series(to_face, 20.0 * 0.04 / 0.1, 20.0 * 20.0), rel=1e-12)
    f = 0.6
    scaled = EFFECTS["envelope_conductance"].apply(b, "room", {"factor": f})
    assert heat_loss_coefficient(scaled) == pytest.approx(series(to_face, 20.0 * 0.04 * f / 0.1, 20.0 * 20.0),
                                                          rel=1e-12)


def test_added_nodes_are_numbered_after_the_last_named_and_never_measured(testcell_data):
    data = cell_and_annex(testcell_data)
    data["zones"][1]["internal_mass"] = {"capacity": 1e5, "conductance": 10.0}
    data["zones"][1]["heat_input_lag"] = {"capacity": 1e4, "conductance": 5.0}
    data["zones"][0]["internal_mass"] = {"capacity": 1e5, "conductance": 10.0}
    b = parse_building(data)
    assert b.added_nodes == {31: ("cell", "internal mass"), 32: ("annex", "internal mass"), 33: ("annex", "heater")}
    assert b.node_names()[33] == "annex heater"
    with pytest.raises(InputError, match=r"zones\[0\]: 'heat_input' is a required property \(with heat_input_lag\)"):
        parse_building({**data, "zones": [dict(data["zones"][0], heat_input_lag={"capacity": 1.0, "conductance": 1.0}),
                                          data["zones"][1]]})
    with pytest.raises(InputError, match=r"internal_mass\.conductance: 0 is less than or equal to the minimum of 0"):
        parse_building({**data, "zones": [dict(data["zones"][0], internal_mass={"capacity": 1.0, "conductance": 0}),
                                          data["zones"][1]]})


EFFECT_VALUES = [("internal_mass", {"C_m": 3e5, "H_m": 40.0}), ("heat_input_lag", {"C_h": 5e4, "H_h": 15.0}),
                 ("envelope_conductance", {"factor": 1.8})]


@pytest.mark.slow  # three effects, four FMU kinds
@pytest.mark.parametrize("kind", ["python", "standalone", "python-fmi3", "standalone-fmi3"])
def test_both_fmus_with_a_zone_effect_equal_the_direct_model(testcell_data, real_case, tmp_path, kind):
    """The annex (heated through Q_annex) with each effect at values other than its start: the
    FMU, its parameters set, gives the direct model of the building declaring those values; a
    standalone FMU refuses an effect its affine form cannot hold (the internal mass's face)."""
    b = parse_building(cell_and_annex(testcell_data))
    net = assemble(b)
    n_rows = 2 * 96 + 1
    rng = np.random.default_rng(5)
    U = np.column_stack([real_case.U[:n_rows, real_case.input_names.index(n)] if n in real_case.input_names
                         else rng.choice([0.0, 600.0], n_rows) for n in net.input_names])
    measured = np.full((n_rows, net.n_nodes), np.nan)
    measured[0, b.zone("annex").air_node - 1] = 18.0
    case = Case(real_case.times[:n_rows], 900.0, net.input_names, U, measured)
    for effect, values in EFFECT_VALUES:
        if kind.startswith("standalone") and EFFECTS[effect].not_standalone:  # refused, not built wrong
            with pytest.raises(ValueError, match=f"effect {effect}: .*use the Python FMU"):
                build_fmu(b, tmp_path / f"{effect}.fmu", effect=(effect, "annex"), kind=kind)
            continue
        fmu = build_fmu(b, tmp_path / f"{effect}.fmu", effect=(effect, "annex"), kind=kind)
        after = EFFECTS[effect].apply(b, "annex", values)
        full = np.full((n_rows, after.n_nodes), np.nan)
        full[:, :net.n_nodes] = measured
        expected = simulate(after, assemble(after, net.input_names), U, 900.0, full)
        with FmuInstance(fmu) as instance:  # the case of the FMU's building, the effect's node in it
            T = simulate_fmu(instance, replace(case, building=after), output_ids=range(1, after.n_nodes + 1),
                             parameters={f"{effect}.{k}": v for k, v in values.items()})
        assert np.abs(T - expected).max() < 1e-9, effect
        plain = simulate(b, net, U, 900.0, measured)
        assert np.abs(expected[:, :net.n_nodes] - plain).max() > 0.05, effect  # the effect does something


def test_a_mass_or_a_heater_may_hold_at_most_a_hundred_times_the_zones_air(testcell):
    """Beyond that a node is a reservoir at the record's first temperature, not a mass: the
    calibration's bound on C scales with the zone (the test cell's 22.5 m3: 2.71 MJ/K)."""
    (low, high), conductance = EFFECTS["internal_mass"].bounds(testcell, "cell")
    assert (low, high) == (0.0, pytest.approx(100 * RHO_C * 22.5))
    assert conductance == (EFFECTS["internal_mass"].parameter("H_m").low, EFFECTS["internal_mass"].parameter("H_m").high)
    assert EFFECTS["envelope_conductance"].bounds(testcell, "cell") == [(0.05, 20.0)]


def test_a_mass_in_case_600_takes_the_pools_share_of_the_sun_and_sees_the_room_as_a_small_grey_body():
    """Case 600 as converted, its faces' solar absorptances declared: a mass of H_m = 50 W/K shows
    A_m = 50 / MASS_FILM m2 of absorptance 0.7 (a = 0.7 A_m). The west window's direct sun that
    falls on no traced face goes by the pool alone, so the mass takes a / (S + a) of it, S = sum A
    (alpha + tau_out) summed by hand from the file's faces. A mass of 0.05 m2 exchanges long-wave
    with the room as a small grey body in a large enclosure: sum_j G_mj = A_m eps_m 4 sigma T^3,
    ScriptF's limit, to 1 %."""
    data = json.loads((Path(__file__).parents[1] / "examples" / "bestest" / "case600.json").read_text())
    zone = "CASE 600 ZONE"
    S = sum(c["area"] * (c["inside"]["solar_absorptance"] + c["inside"].get("diffuse_transmittance", 0.0))
            for c in data["components"])
    window = next(c for c in data["components"] if c["name"] == "SOUTH WINDOW WEST")
    b = EFFECTS["internal_mass"].apply(parse_building(data), zone, {"C_m": 1e6, "H_m": 50.0})
    a = 50.0 / MASS_FILM * MASS_SOLAR_ABSORPTANCE
    net = assemble(b)
    mass = b.zone(zone).mass_node - 1
    sun = net.input_names.index("Itb_SOUTH WINDOW WEST")
    assert net.B[mass, sun] == pytest.approx(window["solar_transmittance"] * window["area"] * a / (S + a), rel=1e-5)  # shares to 6 places
    assert net.B[:, sun].sum() < window["solar_transmittance"] * window["area"]  # the window lets some out

    small = EFFECTS["internal_mass"].apply(parse_building(data), zone, {"C_m": 1e5, "H_m": 0.05 * MASS_FILM})
    net = assemble(small)
    mass, faces = small.zone(zone).mass_node - 1, [i - 1 for i in small.facing(zone)]
    assert net.A[mass, faces].sum() == pytest.approx(0.05 * MASS_EMISSIVITY * 4 * SIGMA * 293.15 ** 3, rel=0.01)


def test_a_mass_of_no_capacity_in_case_600_is_the_building_as_declared():
    """Its face has no area: nothing in the ScriptF exchange, no share of the sun, and the
    network's rows of the building's own nodes are the declared ones."""
    data = json.loads((Path(__file__).parents[1] / "examples" / "bestest" / "case600.json").read_text())
    b = parse_building(data)
    neutral = EFFECTS["internal_mass"].apply(b, "CASE 600 ZONE", {})
    declared, net = assemble(b), assemble(neutral)
    n = b.n_nodes
    assert np.array_equal(net.A[:n, :n], declared.A[:n, :n] - np.diag(net.A[:n, n]))
    assert np.array_equal(net.B[:n], declared.B) and not net.B[n].any()
