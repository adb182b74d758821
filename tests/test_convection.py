"""Convective and outside long-wave coefficients that follow the state (docs/model.md section 3.6):
EnergyPlus's TARP, DOE-2 and exterior long-wave by hand, the lagged source's energy balance and
limit, and the same steps in numpy, in C and through the Python FMU."""
import copy

import numpy as np
import pytest

from nodeforce.model import compiled
from nodeforce.model.building_file import parse_building
from nodeforce.model.case import prepare_case
from nodeforce.model.convection import doe2_faces, tarp_inside_faces, windward_faces
from nodeforce.model.errors import InputError
from nodeforce.model.integrate import simulate
from nodeforce.model.longwave import SIGMA, enclosure_exchange, exterior_coefficient
from nodeforce.model.network import WIND_DIRECTION, WIND_SPEED, assemble


def followed(data, roughness=1.67, wind_factor=0.9):
    """The building with TARP inside every zone and DOE-2 and the long-wave that follows the face
    outside every exterior face."""
    data = radiating(data)
    for z in data["zones"]:
        z["inside_convection_algorithm"] = "tarp"
    for c in data["components"]:
        if c["outside"]["type"] == "exterior":
            c["outside"]["convection"] = {"algorithm": "doe2", "roughness": roughness, "wind_factor": wind_factor}
    return data


def radiating(data, emissivity=0.9):
    """The building with the outside long-wave following every exterior face's temperature."""
    data = copy.deepcopy(data)
    for c in data["components"]:
        if c["outside"]["type"] == "exterior":
            c["outside"]["longwave"] = {"emissivity": emissivity}
    return data


def windy(weather):
    """The weather with a wind that rises and falls and turns round the compass every 30 h."""
    w = weather.copy()
    hours = (w.index - w.index[0]).total_seconds().to_numpy() / 3600.0
    w[WIND_SPEED] = 3.0 + 2.5 * np.sin(2 * np.pi * hours / 17.0)
    w[WIND_DIRECTION] = (12.0 * hours) % 360.0
    return w


def windy_case(building, weather, days):
    """The `prepare_case` of `building` over a record of `days` (`record_times`) in the `windy`
    weather, two hours of it either side."""
    from tests.conftest import record_times
    times = record_times(days=days)
    w = windy(weather)
    w = w[(w.index >= times[0] - np.timedelta64(2, "h")) & (w.index <= times[-1] + np.timedelta64(2, "h"))]
    return prepare_case(building, w)


def assert_python_fmu_steps_as_the_direct_model(building, weather, path):
    """Two windy days of `building` through its Python FMU (at `path`) and the direct model: the
    same temperatures to 1e-9 K."""
    from nodeforce.cosim.fmi import FmuInstance
    from nodeforce.cosim.run import simulate_fmu
    from nodeforce.fmu_build.build import build_fmu
    case = windy_case(building, weather, days=2)
    direct = simulate(building, assemble(building), case.U, case.dt, case.measured, substeps=case.substeps)
    with FmuInstance(build_fmu(building, path)) as instance:
        through_fmu = simulate_fmu(instance, case)
    assert np.abs(through_fmu - direct).max() < 1e-9


def test_a_wall_4_K_warmer_than_the_air_gets_ashrae_s_vertical_coefficient():
    # Engineering Reference, ASHRAE vertical wall: h = 1.31 |dT|^(1/3) = 1.31 * 1.587401 = 2.079495
    assert tarp_inside_faces(4.0, 0.0) == pytest.approx(2.079495, abs=1e-6)
    assert tarp_inside_faces(-4.0, 0.0) == pytest.approx(2.079495, abs=1e-6)


def test_a_warm_floor_is_unstable_and_a_warm_ceiling_stable():
    # a floor 3 K warmer than the room looks up (cos_up 1): Walton's unstable
    # 9.482 |dT|^(1/3) / (7.238 - |cos|) = 9.482 * 1.44225 / 6.238 = 2.1922
    assert tarp_inside_faces(3.0, 1.0) == pytest.approx(2.1922, abs=1e-4)
    # a ceiling 3 K warmer looks down: the stable 1.810 |dT|^(1/3) / (1.382 + |cos|) = 1.0959
    assert tarp_inside_faces(3.0, -1.0) == pytest.approx(1.0959, abs=1e-4)
    # a face at the air's temperature keeps EnergyPlus's floor of 0.1 W/m2/K
    assert tarp_inside_faces(0.0, 1.0) == 0.1


def test_a_roof_windward_at_5_m_s_gets_doe2_s_coefficient():
    # a Rough roof (R_f 1.67) 2 K colder than the air at a local wind of 5 m/s: stable natural
    # convection h_n = 1.810 * 2^(1/3) / 2.382 = 0.95737; MoWiTT windward a V^b = 3.26 * 5^0.89 =
    # 3.26 * 4.18874 = 13.6553; h = h_n + R_f (sqrt(h_n^2 + 13.6553^2) - h_n) = 0.95737 + 1.67 * 12.7314
    # = 22.2189
    windward = windward_faces(1.0, 0.0, 123.0)
    assert windward
    assert doe2_faces(5.0, windward, -2.0, 1.0, 1.67) == pytest.approx(22.2189, abs=1e-3)
    # the same roof leeward would take (3.55, 0.617): 3.55 * 5^0.617 = 9.5828
    leeward = 0.95737 + 1.67 * (np.hypot(0.95737, 3.55 * 5 ** 0.617) - 0.95737)
    assert doe2_faces(5.0, False, -2.0, 1.0, 1.67) == pytest.approx(leeward, abs=1e-3)


def outside_only(data, roughness=1.67, wind_factor=0.9):
    """The building with DOE-2 followed on every exterior face and nothing else followed."""
    data = copy.deepcopy(data)
    for c in data["components"]:
        if c["outside"]["type"] == "exterior":
            c["outside"]["convection"] = {"algorithm": "doe2", "roughness": roughness, "wind_factor": wind_factor}
    return data


def test_a_face_with_capacity_takes_doe2_whole_in_a_gale(testcell_data):
    """The test cell's east wall (5 mm of fibre cement outside, h0 16 W/m2/K) 2 K warmer than the
    air outside, a station wind of 12 m/s from the east, wind factor 0.9: natural convection
    1.31 x 2^(1/3) = 1.65050, MoWiTT windward 3.26 x 10.8^0.89 = 27.0996, h = 1.65050 + 1.67
    (sqrt(1.65050^2 + 27.0997^2) - 1.65050) = 44.2346. Its excess 28.23 is beyond h0, and within
    h0 + 2 C/(A dt) at 300-s sub-steps, C/A the face node's half of the wall's one cell, (2 x
    1500 x 1000 x 0.005 + 35 x 1400 x 0.06) / 2 = 8970 J/m2/K: 16 + 2 x 29.9 = 75.8 W/m2/K. The
    lagged source carries it whole; given no capacities, the excess is capped at h0."""
    building = parse_building(outside_only(testcell_data))
    network = assemble(building)
    wall = building.component("east_wall")
    face = wall.node_ids[-1] - 1
    columns = list(network.input_names)
    u = np.zeros(len(columns))
    u[columns.index("T_out")], u[columns.index(WIND_SPEED)], u[columns.index(WIND_DIRECTION)] = 18.0, 12.0, 90.0
    T = np.full(network.n_nodes, 20.0)
    k = list(network.convection.outside_nodes).index(face)
    area, h0 = network.convection.outside[k][:2]
    assert h0 == 16.0 and area == wall.area
    h = 44.2346
    rate = network.C / 300.0
    assert rate[face] / area == pytest.approx(8970.0 / 300.0, rel=1e-9)
    q = network.convection.source(T, u, rate)
    assert q[face] == pytest.approx(area * (h - h0) * (18.0 - 20.0), rel=1e-5)
    assert network.convection.source(T, u)[face] == pytest.approx(area * h0 * (18.0 - 20.0), rel=1e-12)


def test_in_a_steady_gale_the_lagged_faces_stay_where_doe2_puts_them(testcell_data):
    """Constant weather, a station wind of 10 m/s from the east (the roof's excess about 22
    W/m2/K, beyond its h0 of 16): the network with each outside face's DOE-2 coefficient held at
    its own steady value (found by fixed point, an independent formulation without a lagged
    source) puts every node where the lagged steps, 300 s each, leave it, a day long."""
    from nodeforce.model.integrate import ImplicitEuler
    building = parse_building(outside_only(testcell_data))
    network = assemble(building)
    columns = list(network.input_names)
    u = np.zeros(len(columns))
    u[columns.index("T_out")], u[columns.index("T_sky")] = 5.0, -5.0
    u[columns.index(WIND_SPEED)], u[columns.index(WIND_DIRECTION)] = 10.0, 90.0

    data = copy.deepcopy(testcell_data)
    exterior = [c for c in data["components"] if c["outside"]["type"] == "exterior"]
    T = np.full(network.n_nodes, 10.0)
    for _ in range(50):
        for c in exterior:
            component = building.component(c["name"])
            cos_up = float(np.cos(np.radians(component.tilt)))
            windward = windward_faces(cos_up, component.azimuth, 90.0)
            c["outside"]["h_conv"] = float(doe2_faces(0.9 * 10.0, windward, T[component.node_ids[-1] - 1] - 5.0,
                                                      cos_up, 1.67))
        held = assemble(parse_building(data))
        T = np.linalg.solve(-held.A, held.sources(u[:len(held.input_names)]))
    assert roof_excess(building, T) > 16.0

    stepper = ImplicitEuler(network, 300.0)
    T_run, none = T.copy(), np.zeros(network.n_nodes, dtype=bool)
    for _ in range(12 * 24):
        T_run = stepper.step(T_run, network.sources(u), none, T_run, inputs=u)
    assert np.abs(T_run - T).max() < 1e-9


def test_in_a_gale_c_and_numpy_step_alike(testcell_data, monkeypatch):
    """A day of a 15 m/s wind turning round the compass, from 20 C: the compiled steps read the
    same cap as numpy's (the roof's excess beyond h0 + 2 C/(A dt) all day, the windward walls' beyond h0)."""
    building = parse_building(outside_only(testcell_data))
    network = assemble(building)
    columns = list(network.input_names)
    U = np.zeros((6 * 24 + 1, len(columns)))
    U[:, columns.index("T_out")], U[:, columns.index("T_sky")] = 5.0, -5.0
    U[:, columns.index(WIND_SPEED)] = 15.0
    U[:, columns.index(WIND_DIRECTION)] = np.linspace(0.0, 360.0, len(U))
    T = simulate(building, network, U, 600.0, warmup_days=0, substeps=2)
    if compiled.available():
        monkeypatch.setattr(compiled, "available", lambda: False)
        stepped = simulate(building, network, U, 600.0, warmup_days=0, substeps=2)
        assert np.abs(stepped - T).max() < 1e-10 * np.abs(T).max()
    # no sun, no gain: every node between the sky's -5 C and the start's 20 C (the maximum principle)
    assert T.min() > -5.0 and T.max() < 20.0


def roof_excess(building, T):
    """The roof's DOE-2 coefficient beyond its h0 at the temperatures T, in the steady gale above."""
    roof = building.component("roof")
    return float(doe2_faces(9.0, True, T[roof.node_ids[-1] - 1] - 5.0, 1.0, 1.67)) - roof.outside.h_conv


def test_a_wall_is_windward_where_the_wind_comes_from_within_90_degrees_of_its_normal():
    south = dict(cos_up=0.0, azimuth=180.0)
    assert windward_faces(direction=200.0, **south)
    assert windward_faces(direction=91.0, **south)
    assert not windward_faces(direction=0.0, **south)
    assert not windward_faces(direction=300.0, **south)
    # a north wall with the wind from 350 or 10 deg: across north, 10 and 20 deg from its normal
    assert windward_faces(0.0, 0.0, 350.0) and windward_faces(0.0, 0.0, 10.0)


def test_a_face_at_minus_10_C_under_a_sky_at_minus_30_C_loses_less_than_the_10_C_linearisation():
    # eps sigma (T_s^4 - T_sky^4) / (T_s - T_sky) at 263.15 K and 243.15 K, eps 0.9:
    # (4.795275e9 - 3.495402e9) / 20 = 6.499365e7 K^3, times 0.9 * 5.670374e-8 = 3.31685 W/m2/K,
    # where 4 eps sigma (283.15 K)^3 = 4.63408
    assert exterior_coefficient(0.9, -10.0, -30.0) == pytest.approx(3.31685, abs=1e-5)
    assert 4 * 0.9 * SIGMA * 283.15 ** 3 == pytest.approx(4.63408, abs=1e-5)


def test_at_the_linearisation_s_10_C_the_coefficient_is_h_rad_and_leaves_no_source(testcell_data):
    h0 = 4 * 0.9 * SIGMA * 283.15 ** 3
    assert exterior_coefficient(0.9, 10.0, 10.0) == pytest.approx(h0, rel=1e-14)
    data = radiating(testcell_data)
    for c in data["components"]:
        if c["outside"]["type"] == "exterior":
            c["outside"]["h_rad"] = h0
    network = assemble(parse_building(data))
    u = np.zeros(len(network.input_names))
    u[network.input_names.index("T_sky")] = 10.0
    T = np.full(network.n_nodes, 10.0)
    # the face at 10 C, the air at 10 C and the sky at -20 C: the air's term vanishes (T_out =
    # T_e) and the sky's is A (h(10, -20) - h0) F (-20 - 10), h(10, -20) by its quotient form
    u[network.input_names.index("T_out")] = 10.0
    assert np.abs(network.convection.source(T, u)).max() < 1e-9
    u[network.input_names.index("T_sky")] = -20.0
    q = network.convection.source(T, u)
    face, (area, h_rad, F, eps) = network.convection.longwave_nodes[0], network.convection.longwave[0]
    h_sky = eps * SIGMA * (283.15 ** 4 - 253.15 ** 4) / 30.0
    assert q[face] == pytest.approx(area * (h_sky - h0) * F * (-30.0), rel=1e-12)
    assert q[face] > 0.0  # a colder sky takes less per kelvin than the linearisation at 10 C


def test_the_long_wave_that_follows_the_face_steps_alike_in_c_and_numpy(testcell_data, weather, monkeypatch):
    from tests.conftest import record_times
    building, plain = parse_building(radiating(testcell_data)), parse_building(testcell_data)
    times = record_times(days=3)
    w = weather[(weather.index >= times[0] - np.timedelta64(2, "h")) & (weather.index <= times[-1] + np.timedelta64(2, "h"))]
    case = prepare_case(building, w)
    network = assemble(building)
    assert network.input_names == assemble(plain).input_names  # the sky's input alone: no wind needed
    T = simulate(building, network, case.U, case.dt, substeps=case.substeps)
    constant = simulate(plain, assemble(plain), case.U, case.dt, substeps=case.substeps)
    faces = network.convection.longwave_nodes
    assert np.abs(T[:, faces] - constant[:, faces]).max() > 0.05
    if compiled.available():
        monkeypatch.setattr(compiled, "available", lambda: False)
        stepped = simulate(building, network, case.U, case.dt, substeps=case.substeps)
        assert np.abs(stepped - T).max() < 1e-10 * np.abs(T).max()


def test_what_the_faces_gain_the_air_loses(testcell_data):
    data = followed(testcell_data)
    for c in data["components"]:  # inside convection alone
        c["outside"].pop("convection", None)
        c["outside"].pop("longwave", None)
    building = parse_building(data)
    network = assemble(building)
    rng = np.random.default_rng(1)
    T = 20.0 + 5.0 * rng.standard_normal(network.n_nodes)
    q = network.convection.source(T, np.zeros(len(network.input_names)))
    air = building.zones[0].air_node - 1
    faces = network.convection.inside_nodes[:, 0]
    assert np.count_nonzero(q[faces]) == len(faces)
    assert q[air] == pytest.approx(-q[faces].sum(), rel=1e-12)
    assert abs(q.sum()) < 1e-12 * np.abs(q).sum()
    # each face's term is A (h(dT) - h0) (T_air - T_s) by TARP's formula
    k = 0
    face, (area, h0, cos_up) = faces[k], network.convection.inside[k]
    h = tarp_inside_faces(T[face] - T[air], cos_up)
    assert q[face] == pytest.approx(area * (h - h0) * (T[air] - T[face]), rel=1e-12)


def test_a_building_at_one_temperature_steps_as_with_constant_coefficients(testcell_data):
    """The limit: every face at the air's temperature and the outdoors' leaves no lagged source,
    and the building with the option steps as the one without (to the rounding of the solves,
    which leave the nodes 1e-14 K apart)."""
    plain, with_option = parse_building(testcell_data), parse_building(followed(testcell_data))
    n0, n1 = assemble(plain), assemble(with_option)
    L = 200
    U = np.zeros((L + 1, len(n1.input_names)))
    U[:, n1.input_names.index("T_out")] = U[:, n1.input_names.index("T_sky")] = 20.0
    U[:, n1.input_names.index(WIND_SPEED)] = 4.0
    U[:, n1.input_names.index(WIND_DIRECTION)] = 180.0
    T0 = simulate(plain, n0, U[:, :len(n0.input_names)], 300.0, warmup_days=0)
    T1 = simulate(with_option, n1, U, 300.0, warmup_days=0)
    assert np.abs(T1 - T0).max() < 1e-12
    assert np.abs(T1 - 20.0).max() < 1e-12


def test_the_coefficients_move_the_air_and_c_and_numpy_step_alike(testcell_data, weather, monkeypatch):
    building, plain = parse_building(followed(testcell_data)), parse_building(testcell_data)
    case = windy_case(building, weather, days=3)
    network = assemble(building)
    T = simulate(building, network, case.U, case.dt, substeps=case.substeps)
    constant = simulate(plain, assemble(plain), case.U[:, :-2], case.dt, substeps=case.substeps)
    air = building.zones[0].air_node - 1
    assert np.abs(T[:, air] - constant[:, air]).max() > 0.1
    if compiled.available():
        monkeypatch.setattr(compiled, "available", lambda: False)
        stepped = simulate(building, network, case.U, case.dt, substeps=case.substeps)
        assert np.abs(stepped - T).max() < 1e-10 * np.abs(T).max()


def test_the_weather_must_give_the_wind(testcell_data, weather):
    with pytest.raises(InputError, match="wind_speed|wind_direction"):
        prepare_case(parse_building(followed(testcell_data)), weather)


@pytest.mark.parametrize("kind, named", [("inside", "inside_convection_algorithm: zone cell's"),
                                         ("gaps", "window: component window's")])
def test_the_standalone_fmu_refuses_a_parameter_that_acts_on_a_followed_value_not_affinely(testcell_data,
                                                                                             monkeypatch, kind, named):
    """The standalone FMU sets the followed coefficients' values (A phi, A f, h0, ...) from its
    parameters as it does A's, affinely in each (tests/test_standalone.py); a network where a
    parameter acts on them otherwise (a stand-in: each face's A phi, or each gap's A f, squared,
    so that the zone's convection factor, or the window's conductivity factor, acts on it
    squared) is refused, the field declaring that coefficient named, not exported wrong."""
    from dataclasses import replace

    from nodeforce.fmu_build import standalone
    from tests.test_windows import window_data
    assembled = standalone.assemble

    def squared(building, *args):
        network = assembled(building, *args)
        values = getattr(network.convection, kind).copy()
        values[:, 0] **= 2
        return replace(network, convection=replace(network.convection, **{kind: values}))

    building = parse_building(followed(testcell_data) if kind == "inside" else window_data())
    standalone.network_terms(building, None)  # as assembled: affine
    monkeypatch.setattr(standalone, "assemble", squared)
    with pytest.raises(InputError, match=f"{named} coefficient follows .*not affinely.*Python FMU"):
        standalone.network_terms(building, None)


@pytest.mark.slow
@pytest.mark.parametrize("declare", [followed, lambda data: enclosed(ventilated(data))],
                         ids=["convection", "scriptf_and_flows"])
def test_the_python_fmu_steps_as_the_direct_model(testcell_data, weather, tmp_path, declare):
    assert_python_fmu_steps_as_the_direct_model(parse_building(declare(testcell_data)), weather,
                                                tmp_path / "followed.fmu")


# ---- ScriptF at the faces' temperatures, air flows at the outdoor air's density -----------------

def enclosed(data, followed_longwave=True):
    """The building whose zone exchanges long-wave radiation by ScriptF, at the faces' temperatures
    of each step where `followed_longwave`."""
    data = copy.deepcopy(data)
    for z in data["zones"]:
        z["longwave"] = "scriptf"
        z["longwave_followed"] = followed_longwave
    return data


def test_scriptf_followed_exchanges_sigma_t4_between_every_pair_of_faces(testcell_data):
    """The matrix's exchange linearised at 20 C and the lagged source together are each pair's
    A_i ScriptF_ij sigma (T_j^4 - T_i^4), the grey enclosure's exact exchange, face by face; what
    one face gains the others lose."""
    building = parse_building(enclosed(testcell_data))
    network = assemble(building)
    zone = building.zones[0].name
    names, ids, *faces = building.enclosure(zone)
    G, _ = enclosure_exchange(names, *faces)
    exchange = G / (4.0 * SIGMA * 293.15 ** 3)  # A_i ScriptF_ij, m2
    rng = np.random.default_rng(3)
    T = 5.0 + 12.0 * rng.standard_normal(network.n_nodes)
    q = network.convection.source(T, np.zeros(len(network.input_names)))
    nodes = np.array(ids) - 1
    K = T[nodes] + 273.15
    exact = (exchange * SIGMA * (K[None, :] ** 4 - K[:, None] ** 4)).sum(axis=1)
    linear = (G * (T[nodes][None, :] - T[nodes][:, None])).sum(axis=1)
    np.testing.assert_allclose(q[nodes], exact - linear, rtol=1e-9, atol=1e-9)
    assert abs(q.sum()) < 1e-9 * np.abs(q).max()


def test_scriptf_followed_leaves_no_source_at_20_C_and_less_exchange_when_cold(testcell_data):
    """At the linearisation's 20 C nothing is added; a window face at -15 C facing faces at -10 C
    gains (T_a^2 + T_b^2)(T_a + T_b) / (4 T_m^3) = (258.15^2 + 263.15^2) 521.3 / (4 x 293.15^3)
    = 0.703 of the rate linearised at 20 C."""
    building = parse_building(enclosed(testcell_data))
    network = assemble(building)
    u = np.zeros(len(network.input_names))
    assert np.abs(network.convection.source(np.full(network.n_nodes, 20.0), u)).max() < 1e-9
    pairs, (exchange, g0) = network.convection.pair_nodes, network.convection.pairs.T
    a = pairs[0, 0]
    T = np.full(network.n_nodes, -10.0)
    T[a] = -15.0
    linearised = 5.0 * g0[(pairs == a).any(axis=1)].sum()
    gained = linearised + network.convection.source(T, u)[a]
    assert gained == pytest.approx(0.703 * linearised, rel=1e-3)


def test_scriptf_followed_steps_alike_in_c_and_numpy_and_is_refused_without_scriptf(testcell_data, weather,
                                                                                        monkeypatch):
    from tests.conftest import record_times
    building, plain = parse_building(enclosed(testcell_data)), parse_building(enclosed(testcell_data, False))
    times = record_times(days=3)
    w = weather[(weather.index >= times[0] - np.timedelta64(2, "h")) & (weather.index <= times[-1] + np.timedelta64(2, "h"))]
    case = prepare_case(building, w)
    network = assemble(building)
    T = simulate(building, network, case.U, case.dt, substeps=case.substeps)
    linear = simulate(plain, assemble(plain), case.U, case.dt, substeps=case.substeps)
    faces = network.convection.pair_nodes.ravel()
    assert np.abs(T[:, faces] - linear[:, faces]).max() > 0.01
    if compiled.available():
        monkeypatch.setattr(compiled, "available", lambda: False)
        stepped = simulate(building, network, case.U, case.dt, substeps=case.substeps)
        assert np.abs(stepped - T).max() < 1e-10 * np.abs(T).max()
    data = enclosed(testcell_data)
    data["zones"][0]["longwave"] = "radiant_node"
    with pytest.raises(InputError, match=r"zones\[0\]\.longwave_followed.*scriptf"):
        parse_building(data)


def ventilated(data, flow_density="outdoor"):
    """The building with a night ventilation of 300 m3/h by a schedule (1 from 18:00 to 07:00),
    its air flows carrying heat at `flow_density`."""
    data = copy.deepcopy(data)
    data["site"]["flow_density"] = flow_density
    data["schedules"] = {"night": {"days": {"d": [[7, 1.0], [18, 0.0], [24, 1.0]]},
                                   "periods": [{"through": "12-31", "week": ["d"] * 7}]}}
    data["zones"][0]["ventilation"] = [{"name": "vent", "flow": 300.0, "schedule": "night"}]
    return data


def test_air_flows_carry_heat_at_the_outdoor_air_s_density(testcell_data):
    """By hand: air at 20 C in a zone of infiltration n V and 300 m3/h of ventilation, outdoors at
    -20 C: the flows carry (n V + 300) / 3600 x rho(-20 C) x 1005 x (T_out - T_air) W, rho(-20 C) =
    p / (287.05 x 253.15) at the site's pressure p = air_density x 287.05 x 293.15; the matrix
    carries the part at the site's air_density, the source the rest. With the schedule at 0 only
    the infiltration's; at 20 C outdoors nothing."""
    building = parse_building(ventilated(testcell_data))
    network = assemble(building)
    z = building.zones[0]
    air = z.air_node - 1
    rho_site = building.site["air_density"]
    rho_out = rho_site * 287.05 * 293.15 / (287.05 * 253.15)
    u = np.zeros(len(network.input_names))
    u[network.input_names.index("T_out")] = -20.0
    u[network.input_names.index("night")] = 1.0
    T = np.full(network.n_nodes, 20.0)
    V = z.volume * z.air_change_rate + 300.0
    carried = V / 3600.0 * 1005.0 * (-40.0)
    assert network.convection.source(T, u)[air] == pytest.approx(carried * (rho_out - rho_site), rel=1e-12)
    u[network.input_names.index("night")] = 0.0
    V = z.volume * z.air_change_rate
    assert network.convection.source(T, u)[air] == pytest.approx(V / 3600 * 1005 * (-40) * (rho_out - rho_site),
                                                                   rel=1e-12)
    u[network.input_names.index("T_out")] = 20.0
    assert network.convection.source(T, u)[air] == 0.0
    assert "flow_density" not in parse_building(testcell_data).site  # undeclared: the site's density


def test_air_flows_at_the_outdoor_density_step_alike_in_c_and_numpy(testcell_data, weather, monkeypatch):
    from tests.conftest import record_times
    building = parse_building(ventilated(testcell_data))
    plain = parse_building(ventilated(testcell_data, "site"))
    times = record_times(days=3)
    w = weather[(weather.index >= times[0] - np.timedelta64(2, "h")) & (weather.index <= times[-1] + np.timedelta64(2, "h"))]
    case = prepare_case(building, w)
    network = assemble(building)
    assert assemble(plain).convection is None
    T = simulate(building, network, case.U, case.dt, substeps=case.substeps)
    site = simulate(plain, assemble(plain), case.U, case.dt, substeps=case.substeps)
    air = building.zones[0].air_node - 1
    assert np.abs(T[:, air] - site[:, air]).max() > 0.01
    if compiled.available():
        monkeypatch.setattr(compiled, "available", lambda: False)
        stepped = simulate(building, network, case.U, case.dt, substeps=case.substeps)
        assert np.abs(stepped - T).max() < 1e-10 * np.abs(T).max()
