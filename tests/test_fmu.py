"""The FMU gives the direct model's numbers and behaves as an FMI 2.0 co-simulation slave should."""
import copy
import sys
from dataclasses import replace

import numpy as np
import pytest
from fmpy.validation import validate_fmu

from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.fmu_build.build import build_fmu
from nodeforce.model.building_file import parse_building
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble


@pytest.fixture(scope="module")
def fmu(tmp_path_factory, testcell_data):
    return build_fmu(parse_building(testcell_data), tmp_path_factory.mktemp("fmu") / "testcell.fmu")


def forcing(*ids, n=23):
    mask = np.zeros(n, dtype=bool)
    mask[np.array(ids, dtype=int) - 1] = True
    return mask


@pytest.mark.parametrize("forced", [(), (7,), (1, 9, 17)])
def test_fmu_equals_direct_model_on_real_weather(fmu, testcell, real_case, forced):
    net = assemble(testcell)
    force = forcing(*forced)
    direct = simulate(testcell, net, real_case.U, real_case.dt, real_case.measured, force, substeps=real_case.substeps)
    with FmuInstance(fmu) as instance:
        through_fmu = simulate_fmu(instance, real_case, force)
    assert np.abs(through_fmu - direct).max() < 1e-9
    # the comparison is not between two idle models: the air swings with the weather
    assert np.ptp(direct[:, 22]) > 2.0


def test_a_steady_start_is_the_same_year_long_step_through_the_fmu(fmu, testcell, real_case):
    """A diagnosis' steady start (one long step at the first day's means) is a doStep like any
    other: the FMU gives the direct model's numbers, and they differ from the replay's alone."""
    # the air alone measured: the walls' state is the warm-up's to set
    air_only = np.where(np.arange(23) == 22, real_case.measured, np.nan)
    case = replace(real_case, measured=air_only).with_burn_in(1).with_steady_start()
    net = assemble(testcell)
    direct = simulate(testcell, net, case.U, case.dt, case.measured, burn_in_steps=case.burn_in_steps,
                      steady_start=True, substeps=case.substeps)
    with FmuInstance(fmu) as instance:
        through_fmu = simulate_fmu(instance, case)
    assert np.abs(through_fmu - direct).max() < 1e-9
    replay = simulate(testcell, net, case.U, case.dt, case.measured, burn_in_steps=case.burn_in_steps, substeps=case.substeps)
    assert np.abs(replay - direct).max() > 0.01


def test_fmpy_validate_finds_no_problem(fmu):
    assert validate_fmu(str(fmu)) == []


def test_reset_and_reuse_give_identical_results(fmu, real_case):
    with FmuInstance(fmu) as instance:
        first = simulate_fmu(instance, real_case, forcing(9))
        other = simulate_fmu(instance, real_case, forcing(1, 17))
        again = simulate_fmu(instance, real_case, forcing(9))
    assert np.array_equal(first, again)
    assert not np.array_equal(first, other)


OPEN = []


@pytest.fixture(autouse=True)
def close_instances():
    yield
    while OPEN:
        OPEN.pop().close()


def instantiate(path, name):
    """The FMPy slave of a new instance (closed after the test) and the value references."""
    instance = FmuInstance(path, instance_name=name)
    OPEN.append(instance)
    return instance.fmu, {n: v.valueReference for n, v in instance.variables.items()}


def start(slave, refs, T_start, forced=()):
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.setReal([refs[f"T_start[{i}]"] for i in range(1, 24)], [T_start] * 23)
    if forced:
        slave.setBoolean([refs[f"force[{i}]"] for i in forced], [True] * len(forced))
    slave.exitInitializationMode()


def step(slave, refs, k, T_forced=None):
    t = k * 900.0
    names = ["T_out", "T_sky", "I_roof"]
    values = [25 + 5 * np.sin(t / 13751), 12.0, max(0.0, 800 * np.sin(t / 13751))]
    if T_forced is not None:
        names.append("T_forced[9]")
        values.append(T_forced)
    slave.setReal([refs[n] for n in names], values)
    slave.doStep(currentCommunicationPoint=t, communicationStepSize=900.0)
    return slave.getReal([refs[f"T[{i}]"] for i in range(1, 24)])


def test_several_instances_at_once_do_not_interfere(fmu):
    a, refs = instantiate(fmu, "a")
    b, _ = instantiate(fmu, "b")
    start(a, refs, 18.0)
    start(b, refs, 30.0, forced=(9,))
    interleaved_a, interleaved_b = [], []
    for k in range(100):
        interleaved_a.append(step(a, refs, k))
        interleaved_b.append(step(b, refs, k, T_forced=27.0))
    alone, _ = instantiate(fmu, "alone")
    start(alone, refs, 18.0)
    sequential_a = [step(alone, refs, k) for k in range(100)]
    assert np.array_equal(interleaved_a, sequential_a)
    assert np.allclose(np.array(interleaved_b)[:, 8], 27.0)
    for slave in (a, b, alone):
        slave.terminate()


def test_get_and_set_fmu_state_replays_identically(fmu):
    slave, refs = instantiate(fmu, "state")
    start(slave, refs, 21.0)
    for k in range(40):
        step(slave, refs, k)
    state = slave.getFMUstate()
    first = [step(slave, refs, k) for k in range(40, 80)]
    slave.setFMUstate(state)
    replay = [step(slave, refs, k) for k in range(40, 80)]
    serialized = slave.serializeFMUstate(state)
    restored = slave.deSerializeFMUstate(serialized)
    slave.setFMUstate(restored)
    from_bytes = [step(slave, refs, k) for k in range(40, 80)]
    slave.freeFMUstate(state)
    slave.freeFMUstate(restored)
    slave.terminate()
    assert np.array_equal(first, replay)
    assert np.array_equal(first, from_bytes)


def test_two_different_fmus_in_one_process_run_their_own_model(tmp_path, testcell_data, real_case):
    leaky = copy.deepcopy(testcell_data)
    leaky["materials"]["wood"]["conductivity"] = 0.78  # the paper's disturbed door
    fmu_a = build_fmu(parse_building(testcell_data), tmp_path / "a.fmu")
    fmu_b = build_fmu(parse_building(leaky), tmp_path / "b.fmu")
    with FmuInstance(fmu_a) as a, FmuInstance(fmu_b) as b:
        out_a = simulate_fmu(a, real_case, output_ids=[23])
        out_b = simulate_fmu(b, real_case, output_ids=[23])
    for data, out in ((testcell_data, out_a), (leaky, out_b)):
        building = parse_building(data)
        direct = simulate(building, assemble(building), real_case.U, real_case.dt, real_case.measured, substeps=real_case.substeps)
        assert np.abs(out[:, 0] - direct[:, 22]).max() < 1e-9
    assert np.abs(out_a - out_b).max() > 0.01


def test_an_instance_leaves_sys_path_as_it_found_it(fmu, real_case):
    # pythonfmu prepends the FMU's resources folder, whose pythonfmu copy has no binaries: left
    # there, workers spawned later inherit it and build FMUs that cannot run
    before = list(sys.path)
    with FmuInstance(fmu) as instance:
        simulate_fmu(instance, real_case, output_ids=[23])
        assert sys.path == before
