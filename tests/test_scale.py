"""A building at scale (issue 20): the generated office and the solver that steps it.

The condensed solver (blocks and a Schur complement on the zones' nodes) must give the dense
inverse's numbers, and forcing must be the Dirichlet condition docs/model.md section 5 states,
checked against an independent formulation: the free nodes' own system with the forced
temperatures moved to the right-hand side. The generated office must pass the schema, close its
energy balance every step, and have the heat loss coefficient a hand calculation brackets.
"""
import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import jsonschema
import numpy as np
import pytest

from nodeforce.model.building import Boundary, Exterior

from nodeforce.model.building_file import load_building
from nodeforce.model.hlc import heat_loss_coefficient
from nodeforce.model.integrate import ImplicitEuler, simulate
from nodeforce.model.network import RHO_C_AIR, assemble
from tests.test_physics import boundary_heat_in

REPO = Path(__file__).resolve().parents[1]
SCHEMA = json.loads((REPO / "model" / "data" / "nodal-building.schema.json").read_text())


def _generator():
    spec = importlib.util.spec_from_file_location("office_make_building", REPO / "examples" / "office" / "make_building.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def office(tmp_path_factory):
    """The small office (two storeys), written by the generator: (folder, Building)."""
    out = tmp_path_factory.mktemp("office")
    path = _generator().write(out, **_generator().SMALL)
    return out, load_building(path)


BUILDINGS = [REPO / "model" / "data" / "testcell.json", REPO / "examples" / "twinhouse_n2" / "building.json"]


def _steppers(building):
    network = assemble(building)
    return network, ImplicitEuler(network, 900.0, condensed=False), ImplicitEuler(network, 900.0, condensed=True)


def _masks(network, rng):
    """No forcing, a zone's air and radiant nodes (hubs of the partition), and random sets."""
    n = network.n_nodes
    zone_nodes = np.zeros(n, dtype=bool)
    zone_nodes[np.flatnonzero(network.algebraic)[:2]] = True
    zone_nodes[np.argmax(network.C)] = True  # the largest capacity: a zone's air or a slab
    return [np.zeros(n, dtype=bool), zone_nodes, rng.random(n) < 0.05, rng.random(n) < 0.3]


def _check_condensed_equals_dense(building):
    network, dense, condensed = _steppers(building)
    rng = np.random.default_rng(4)
    for forced in _masks(network, rng):
        T = rng.normal(20.0, 5.0, network.n_nodes)
        source = rng.normal(0.0, 200.0, network.n_nodes)
        T_forced = rng.normal(20.0, 3.0, network.n_nodes)
        for _ in range(5):  # a few steps: the difference does not grow
            T_dense = dense.step(T, source, forced, T_forced)
            T_condensed = condensed.step(T, source, forced, T_forced)
            assert np.abs(T_dense - T_condensed).max() < 1e-9
            T = T_dense


@pytest.mark.parametrize("path", BUILDINGS, ids=["testcell", "twinhouse"])
def test_condensed_solver_equals_dense(path):
    _check_condensed_equals_dense(load_building(path))


def test_condensed_solver_equals_dense_on_the_generated_office(office):
    _, building = office
    assert building.n_nodes > 300  # where the condensed solver is the default
    _check_condensed_equals_dense(building)


def test_forcing_is_the_free_nodes_system_with_the_forced_temperatures_moved_right(office):
    """T_S = measured and M_FF T_F = v_F - M_FS T_S: an independent formulation of forcing."""
    _, building = office
    network, _, condensed = _steppers(building)
    rng = np.random.default_rng(5)
    M = np.diag(network.C / 900.0) - network.A
    for forced in _masks(network, rng)[1:]:
        T = rng.normal(20.0, 5.0, network.n_nodes)
        source = rng.normal(0.0, 200.0, network.n_nodes)
        T_forced = rng.normal(20.0, 3.0, network.n_nodes)
        v = network.C / 900.0 * T + source
        free = ~forced
        expected = T_forced.copy()
        expected[free] = np.linalg.solve(M[np.ix_(free, free)], v[free] - M[np.ix_(free, forced)] @ T_forced[forced])
        assert np.abs(condensed.step(T, source, forced, T_forced) - expected).max() < 1e-9


def test_generated_office_passes_the_schema_and_is_full_size(office):
    out, _ = office
    data = json.loads((out / "building.json").read_text())
    assert list(jsonschema.Draft202012Validator(SCHEMA).iter_errors(data)) == []
    full = _generator().building(**_generator().FULL)
    assert list(jsonschema.Draft202012Validator(SCHEMA).iter_errors(full)) == []
    # every zone's air is measured, and every facade of the plan has windows
    sensors = set(data["sensors"])
    assert {f"{z['name']}_air" for z in full["zones"]} <= set(full["sensors"])
    assert {c["azimuth"] for c in full["components"] if "solar_transmittance" in c} == {0.0, 90.0, 180.0, 270.0}
    assert len(sensors) < len(full["sensors"])


def test_generated_office_closes_its_energy_balance_every_step(office):
    out, building = office
    network = assemble(building)
    dt, n_rows = 900.0, 96 + 1
    t = np.arange(n_rows) * dt
    rng = np.random.default_rng(2)
    U = np.zeros((n_rows, len(network.input_names)))
    column = {name: j for j, name in enumerate(network.input_names)}
    U[:, column["T_out"]] = 26 + 4 * np.sin(2 * np.pi * t / 86400)
    U[:, column["T_sky"]] = U[:, column["T_out"]] - 12
    sun = np.clip(900 * np.sin(2 * np.pi * (t - 21600) / 86400), 0, None)
    for name, j in column.items():
        if name.startswith("I_"):
            U[:, j] = sun * rng.uniform(0.2, 1.0)
    U[:, column["heater"]] = np.where((t % 86400) < 43200, 400.0, 0.0)
    measured = np.full((n_rows, network.n_nodes), np.nan)
    T = simulate(building, network, U, dt, measured, warmup_days=0, include_start=True)
    for n in range(1, n_rows):
        stored = np.sum(network.C * (T[n] - T[n - 1])) / dt
        heat_in = boundary_heat_in(building, T[n], dict(zip(network.input_names, U[n])))
        assert abs(stored - heat_in) <= 1e-6 * max(abs(stored), abs(heat_in), 1.0), n


def _series_u(component, h_inside):
    """U (W/m2/K) from the air through the layers to the outside temperature, by hand."""
    out = component.outside
    h_out = out.h_conv + out.h_rad if isinstance(out, Exterior) else out.h
    layers = sum(thickness / material.conductivity for material, thickness in component.layers)
    return 1.0 / (1.0 / h_inside + layers + 1.0 / h_out)


def test_generated_office_heat_loss_coefficient_is_bracketed_by_hand(office):
    """HLC = the air's part (infiltration and supply, exact) + the envelope's, which lies between
    the components' series UA with the inside convective coefficient alone and with convection
    and radiation in parallel (the radiant node then at the air's temperature)."""
    _, building = office
    air = sum(RHO_C_AIR * (z.volume * z.air_change_rate + (z.supply.flow if z.supply else 0.0)) / 3600
              for z in building.zones)
    envelope = [c for c in building.components if isinstance(c.outside, (Exterior, Boundary))]
    low = sum(c.area * _series_u(c, c.inside.h_conv) for c in envelope)
    high = sum(c.area * _series_u(c, c.inside.h_conv + c.inside.h_rad) for c in envelope)
    hlc = heat_loss_coefficient(building)
    assert air + low < hlc < air + high
    assert high < 1.5 * low  # the bracket is a check, not a formality


@pytest.mark.slow
def test_small_office_two_faults_located(office, tmp_path):
    """Two undeclared faults in two zones of different storeys, 0.05 C of noise: the search over
    the eight offices' air finds the two walls' inside surfaces."""
    out, building = office
    sensors = (out / "sensors.txt").read_text().strip()
    measured = tmp_path / "measured.csv"
    run = [sys.executable, "-m", "nodeforce"]
    subprocess.run(run + ["synth", str(out / "building.json"), "--weather", str(out / "weather.csv"),
                          "--start", "2001-01-15T00:00-05:00", "--days", "3", "--sensors", sensors,
                          "--noise", "0.05", "--seed", "3", "--history-days", "0",
                          "--effect", "conductivity@s0_N1_wallN:factor=4",
                          "--effect", "solar_absorptance@s1_S0_wallS:alpha=0.95", "-o", str(measured)],
                   check=True, capture_output=True)
    offices = ",".join(z.name for z in building.zones if z.heat_input)
    subprocess.run(run + ["locate", str(out / "building.json"), "--weather", str(out / "weather.csv"),
                          "--measurements", str(measured), "-o", str(tmp_path / "locate"), "--objective", offices,
                          "--noise", "0.05", "--burn-in-days", "1", "--workers", "1", "--population", "10",
                          "--patience", "5", "--history-days", "0"],  # synthesised without a past, as told
                   check=True, capture_output=True)
    result = json.loads((tmp_path / "locate" / "locate.json").read_text())
    names = building.node_names()
    assert sorted(names[i] for i in result["best_nodes"]) == ["s0_N1_wallN at 0.000 m", "s1_S0_wallS at 0.000 m"]


@pytest.mark.parametrize("steady_start", [False, True], ids=["replay", "steady_start"])
def test_standalone_fmu_equals_the_direct_model_on_the_generated_office(office, tmp_path, steady_start):
    """The C FMU's profile LU after reverse Cuthill-McKee gives the direct model's numbers (the
    direct model steps the office with the condensed solver: two independent factorisations),
    a diagnosis' steady start (one step of 1e10 s) included."""
    from nodeforce.cosim.fmi import FmuInstance
    from nodeforce.cosim.run import simulate_fmu
    from nodeforce.fmu_build.build import build_fmu
    from nodeforce.iotools.weather import read_weather
    from nodeforce.model.case import prepare_case
    from nodeforce.model.synth import pseudo_measurements
    import pandas as pd
    out, building = office
    weather = read_weather(out / "weather.csv")
    times = pd.date_range("2001-01-15T00:00-05:00", periods=2 * 96 + 1, freq="900s", name="time")
    sensors = [int(i) for i in (out / "sensors.txt").read_text().split(",")]
    measured = pseudo_measurements(building, weather, times, sensors, noise_sd=0.1, seed=1, spinup_days=2)
    case = prepare_case(building, weather, measured).with_burn_in(0.5)
    case = case.with_steady_start() if steady_start else case
    force = np.zeros(building.n_nodes, dtype=bool)
    force[np.array(sensors[::3]) - 1] = True
    expected = simulate(building, assemble(building), case.U, case.dt, case.measured, force=force,
                        burn_in_steps=case.burn_in_steps, steady_start=steady_start, substeps=case.substeps)
    instance = FmuInstance(build_fmu(building, tmp_path / "office.fmu", kind="standalone"))
    try:
        assert np.abs(simulate_fmu(instance, case, force) - expected).max() < 1e-9
    finally:
        instance.close()


@pytest.mark.parametrize("steady_start", [False, True], ids=["replay", "steady_start"])
def test_standalone_fmu_equals_the_direct_model_on_the_twin_house(tmp_path, steady_start, twinhouse):
    """The Twin House (281 nodes: the direct model's dense inverse) through the C FMU's profile LU,
    on two days of random inputs, a third of its nodes forced to random measurements, some of
    them missing at three steps; with a diagnosis' steady start too (its one long step). Its
    coefficients that follow the state are stepped in C by both."""
    from nodeforce.cosim.fmi import FmuInstance
    from nodeforce.cosim.run import simulate_fmu
    from nodeforce.fmu_build.build import build_fmu
    from nodeforce.model.case import Case
    building = twinhouse
    network = assemble(building)
    rng = np.random.default_rng(6)
    n_rows = 2 * 96 + 1
    U = rng.uniform(0.0, 20.0, (n_rows, len(network.input_names)))
    measured = rng.normal(20.0, 2.0, (n_rows, network.n_nodes))
    measured[[20, 100, 150]] = np.where(rng.random(network.n_nodes) < 0.5, np.nan, measured[[20, 100, 150]])
    force = rng.random(network.n_nodes) < 0.3
    case = Case(times=None, dt=900.0, input_names=network.input_names, U=U, measured=measured, burn_in_steps=4,
                steady_start=steady_start, building=building)
    expected = simulate(building, network, U, 900.0, measured, force=force, burn_in_steps=4,
                        steady_start=steady_start)
    instance = FmuInstance(build_fmu(building, tmp_path / "twinhouse.fmu", kind="standalone"))
    try:
        assert np.abs(simulate_fmu(instance, case, force) - expected).max() < 1e-9
    finally:
        instance.close()
