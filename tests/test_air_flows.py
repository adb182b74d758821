"""Air flows that follow the temperatures and the wind, and ventilation controls (docs/model.md
section 3.6): EnergyPlus's A + B |dT| + C v + D v^2 by hand, the steady state of a followed flow
against the same flow held constant, each control's limit, and the same steps in numpy and C."""
import copy

import numpy as np
import pytest

from nodeforce.model import compiled
from nodeforce.model.building_file import parse_building
from nodeforce.model.errors import InputError
from nodeforce.model.integrate import simulate
from nodeforce.model.network import C_AIR, WIND_SPEED, assemble
from tests.test_convection import assert_python_fmu_steps_as_the_direct_model, windy_case

T_AIR, T_OUT, WIND = 20.0, -5.0, 5.0  # C, C, m/s at the station


def with_flow(data, **flow):
    """The test cell with one outdoor air flow of 300 m3/h and the fields `flow`."""
    data = copy.deepcopy(data)
    data["zones"][0]["ventilation"] = [{"name": "vent", "flow": 300.0, **flow}]
    return data


def at(network, T_air=T_AIR, T_out=T_OUT, wind=WIND):
    """(T, u): every node at T_air, the outdoors at T_out, the station's wind."""
    u = np.zeros(len(network.input_names))
    u[network.input_names.index("T_out")] = T_out
    if WIND_SPEED in network.input_names:
        u[network.input_names.index(WIND_SPEED)] = wind
    return np.full(network.n_nodes, T_air), u


def carried(building, network, T, u):
    """W the zone's air gets from its air flows: the step matrix's part and the lagged source's."""
    z = building.zones[0]
    air = z.air_node - 1
    g_infiltration = building.site["air_density"] * C_AIR * z.volume * z.air_change_rate / 3600.0
    t_out = u[network.input_names.index("T_out")]
    matrix = -network.A[air, air] - sum(network.A[air, j] for j in range(network.n_nodes) if j != air)
    # the air's row sums to minus the conductances to the inputs: here the air flows alone
    assert matrix == pytest.approx(network.B[air, network.input_names.index("T_out")], rel=1e-12)
    return (matrix - g_infiltration) * (t_out - T[0]) + network.convection.source(T, u)[air]


def test_a_flow_following_dt_and_the_wind_carries_its_design_times_the_terms(testcell_data):
    """By hand: 300 m3/h times 0.1 + 0.02 x 25 K + 0.224 v + 0.01 v^2 at v = 0.8 x 5 = 4 m/s, i.e.
    1.656, carries 1.656 x 300 / 3600 x rho x 1005 x (T_out - T_air) W."""
    building = parse_building(with_flow(testcell_data, terms=[0.1, 0.02, 0.224, 0.01], wind_factor=0.8))
    network = assemble(building)
    g = building.site["air_density"] * 1005.0 * 300.0 / 3600.0
    T, u = at(network)
    assert carried(building, network, T, u) == pytest.approx(1.656 * g * (T_OUT - T_AIR), rel=1e-12)
    # a negative sum is no flow, as EnergyPlus bounds it
    building = parse_building(with_flow(testcell_data, terms=[-2.0, 0.0, 0.1, 0.0]))
    network = assemble(building)
    assert carried(building, network, *at(network)) == pytest.approx(0.0, abs=1e-9)


def steady(network, u, iterations=200):
    """The temperatures at which A T + B u + q + the lagged source vanish (C), by fixed point."""
    T = np.full(network.n_nodes, 20.0)
    for _ in range(iterations):
        extra = network.convection.source(T, u) if network.convection is not None else 0.0
        T = np.linalg.solve(-network.A, network.B @ u + network.q + extra)
    return T


def test_a_followed_flow_s_steady_state_is_the_constant_flow_s(testcell_data):
    """Under constant weather the lag vanishes: the zone settles where a constant flow of 300 x
    (0.3 + 0.01 |dT| + 0.224 x 0.7 x 5) m3/h puts it, |dT| its own steady difference."""
    building = parse_building(with_flow(testcell_data, terms=[0.3, 0.01, 0.224, 0.0], wind_factor=0.7))
    network = assemble(building)
    T = steady(network, at(network)[1])
    air = building.zones[0].air_node - 1
    m = 0.3 + 0.01 * abs(T[air] - T_OUT) + 0.224 * 0.7 * WIND
    plain = with_flow(testcell_data)
    plain["zones"][0]["ventilation"][0]["flow"] = 300.0 * m
    plain_network = assemble(parse_building(plain))
    assert plain_network.convection is None
    T_plain = steady(plain_network, at(plain_network)[1], iterations=1)
    assert np.abs(T - T_plain).max() < 1e-9


@pytest.mark.parametrize("control, off, on", [
    ("minimum_indoor_temperature", 20.5, 20.0), ("maximum_indoor_temperature", 19.5, 20.0),
    ("delta_temperature", 25.5, 25.0), ("minimum_outdoor_temperature", -4.5, -5.0),
    ("maximum_outdoor_temperature", -5.5, -5.0), ("maximum_wind_speed", 3.5, 4.0)])
def test_a_control_stops_the_flow_beyond_its_limit_and_not_at_it(testcell_data, control, off, on):
    """The air at 20 C, outdoors -5 C, the wind 0.8 x 5 = 4 m/s at the zone: beyond the limit the
    flow carries nothing (its step-matrix part cancelled), at it the whole flow."""
    for limit, expected in ((off, 0.0), (on, 1.0)):
        building = parse_building(with_flow(testcell_data, wind_factor=0.8, controls={control: limit}))
        network = assemble(building)
        g = building.site["air_density"] * 1005.0 * 300.0 / 3600.0
        assert carried(building, network, *at(network)) == pytest.approx(expected * g * (T_OUT - T_AIR), abs=1e-9)


def test_controls_that_never_hold_are_refused(testcell_data):
    data = with_flow(testcell_data, controls={"minimum_indoor_temperature": 30.0, "maximum_indoor_temperature": 25.0})
    with pytest.raises(InputError, match=r"zones\[0\]\.ventilation\[0\]\.controls\.minimum_indoor_temperature: "
                                         r"30 C is above the maximum_indoor_temperature"):
        parse_building(data)


def test_a_file_that_declares_neither_assembles_no_lagged_flow(testcell_data):
    building = parse_building(with_flow(testcell_data))
    assert assemble(building).convection is None and not building.followed_coefficients


def controlled_and_windy(data):
    """The test cell with an exhaust of 20 air changes an hour that runs only above 24 C indoors,
    and leaks of 0.5 an hour in proportion to the wind at the zone's height."""
    data = copy.deepcopy(data)
    volume = data["zones"][0]["volume"]
    data["zones"][0]["ventilation"] = [
        {"name": "exhaust", "flow": 20.0 * volume, "controls": {"minimum_indoor_temperature": 24.0}},
        {"name": "leaks", "flow": 0.5 * volume, "terms": [0.0, 0.0, 0.224, 0.0], "wind_factor": 0.6}]
    return data


def test_controlled_and_wind_flows_step_alike_in_c_and_numpy(testcell_data, weather, monkeypatch):
    """The exhaust and the leaks of `controlled_and_windy`: the air runs otherwise than with the
    flows constant, the same in C and in numpy (the standalone FMU's: tests/test_standalone.py)."""
    building = parse_building(controlled_and_windy(testcell_data))
    case = windy_case(building, weather, days=3)
    network = assemble(building)
    T = simulate(building, network, case.U, case.dt, substeps=case.substeps)
    air = building.zones[0].air_node - 1
    assert np.isfinite(T).all()
    assert T[:, air].min() < 24.0 < T[:, air].max()  # the exhaust switches
    if compiled.available():
        monkeypatch.setattr(compiled, "available", lambda: False)
        stepped = simulate(building, network, case.U, case.dt, substeps=case.substeps)
        assert np.abs(stepped - T).max() < 1e-10 * np.abs(T).max()


@pytest.mark.slow
def test_the_python_fmu_steps_followed_flows_as_the_direct_model(testcell_data, weather, tmp_path):
    building = parse_building(with_flow(testcell_data, terms=[0.2, 0.01, 0.224, 0.0], wind_factor=0.6,
                                        controls={"minimum_indoor_temperature": 24.0}))
    assert_python_fmu_steps_as_the_direct_model(building, weather, tmp_path / "flows.fmu")


def test_a_gale_through_a_large_flow_stays_bounded_by_its_cap(testcell_data, weather):
    """200 air changes an hour at C = 1 s/m in a wind of up to 5.5 m/s: up to 1,100 an hour, five
    times the step matrix's. Lagged in full, the air's error grows every sub-step (its excess
    beyond C_air/dt + g + G); capped at 1 + C_air / (300 s g), the air follows the outdoor air, as
    a flow of so many air changes makes it."""
    import dataclasses
    data = copy.deepcopy(testcell_data)
    volume = data["zones"][0]["volume"]
    data["zones"][0]["ventilation"] = [{"name": "gale", "flow": 200.0 * volume, "terms": [0.0, 0.0, 1.0, 0.0]}]
    building = parse_building(data)
    case = windy_case(building, weather, days=3)
    network = assemble(building)
    air = building.zones[0].air_node - 1
    T = simulate(building, network, case.U, case.dt, substeps=case.substeps)
    t_out = case.U[:, network.input_names.index("T_out")]
    assert np.abs(T[:, air] - t_out[-len(T):]).max() < 2.0
    flows = network.convection.flows.copy()
    flows[:, 1] = np.inf
    uncapped = dataclasses.replace(network, convection=dataclasses.replace(network.convection, flows=flows))
    with np.errstate(all="ignore"):
        T = simulate(building, uncapped, case.U, case.dt, substeps=case.substeps)
    assert not np.abs(T[:, air]).max() < 100.0
