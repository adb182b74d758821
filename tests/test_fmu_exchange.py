"""What an importer's own run of the FMU gives: its default run (DefaultExperiment), and an
input file with gaps in a measurement, the same in FMPy and in a C host that applies input
files as Reference-FMUs' fmusim does (tests/c_host/host.c)."""
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu

from nodeforce.cosim.fmi import FmuInstance
from nodeforce.fmu_build import guard
from nodeforce.fmu_build.build import build_fmu
from nodeforce.model.building_file import parse_building
from nodeforce.model.integrate import simulate, substeps
from nodeforce.model.network import assemble
from tests.importers import run_fmpy
from tests.test_standalone import python_host_environment, run_c_host, scenario

DT = 900.0


@pytest.fixture(scope="module")
def fmus(tmp_path_factory, testcell_data):
    folder = tmp_path_factory.mktemp("exchange")
    building = parse_building(testcell_data)
    return {kind: build_fmu(building, folder / f"{kind}.fmu", kind=kind) for kind in ("python", "standalone")}


def test_the_default_run_is_a_day_of_900_s_steps_each_in_backward_euler_steps_of_max_step(fmus, testcell, tmp_path):
    fmu = fmus["standalone"]
    experiment = read_model_description(str(fmu)).defaultExperiment
    start, stop, step = (float(x) for x in (experiment.startTime, experiment.stopTime, experiment.stepSize))
    assert (start, stop, step) == (0.0, 86400.0, DT)
    outputs = [f"T[{i}]" for i in range(1, 24)]
    result = simulate_fmu(str(fmu), output=outputs)  # FMPy with nothing but the FMU
    assert np.array_equal(result["time"], np.arange(97) * DT)
    T = np.column_stack([result[name] for name in outputs])[1:]
    # the direct model: every input at its start value (0), nothing measured, 20 C everywhere
    network = assemble(testcell)
    direct = simulate(testcell, network, np.zeros((97, len(network.input_names))), DT, warmup_days=0,
                      substeps=substeps(DT))
    assert substeps(DT) == 3
    assert np.abs(T - direct).max() < 1e-9
    assert 20.0 - direct[-1, 22] > 5.0  # the day moves the model: a 1-s run would not
    done, in_c = run_c_host(fmu, {}, {}, outputs, step, round((stop - start) / step), tmp_path)
    assert done.returncode == 0, done.stderr
    assert np.abs(in_c - T).max() < 1e-9


def gap_file(fmu):
    """An input file of a day at 900 s: weather, and node 9's measurement with a gap of an
    hour and a lone missing sample (NaN)."""
    times = np.arange(97) * DT
    day = np.sin(2 * np.pi * times / 86400)
    names = [v.name for v in read_model_description(str(fmu)).modelVariables
             if v.causality == "input" and not v.name.startswith("T_forced[")]
    inputs = {name: np.maximum(0, 700 * day) if name.startswith("I_") else 24 + 6 * day - 8 * (name == "T_sky")
              for name in names}
    measured = 27 + 2 * np.cos(2 * np.pi * times / 86400)
    measured[[30, 31, 32, 33, 60]] = np.nan
    inputs["T_forced[9]"] = measured
    return times, inputs


def test_a_file_with_gaps_gives_the_same_outputs_in_fmpy_and_the_c_host(fmus, tmp_path):
    times, inputs = gap_file(fmus["standalone"])
    outputs = [f"T[{i}]" for i in range(1, 24)]
    signals = np.array(list(zip(times, *inputs.values())),
                       dtype=[("time", float)] + [(name, float) for name in inputs])
    in_fmpy = simulate_fmu(str(fmus["python"]), input=signals, start_values={"force[9]": True}, output=outputs)
    in_fmpy = np.column_stack([in_fmpy[name] for name in outputs])[1:]
    done, in_c = run_c_host(fmus["standalone"], {"force[9]": True}, inputs, outputs, DT, 96, tmp_path, times=times)
    assert done.returncode == 0, done.stderr
    assert np.abs(in_c - in_fmpy).max() < 1e-9
    # "not measured" is the held sample: the step from t_k takes the sample at t_k, and node 9
    # is computed over exactly the steps whose sample is NaN
    measured = inputs["T_forced[9]"][:96]
    have = np.isfinite(measured)
    assert np.array_equal(in_c[have, 8], measured[have])
    assert np.isfinite(in_c).all() and not np.isin(in_c[~have, 8], measured[have]).any()


def with_recorded_libpython(fmu, path, destination):
    """A copy of the Python FMU whose resources/guard.txt records `path` as the exporting
    machine's libpython, as an FMU exported elsewhere does."""
    with zipfile.ZipFile(fmu) as source, zipfile.ZipFile(destination, "w") as copied:
        for item in source.infolist():
            data = source.read(item)
            if item.filename == "resources/guard.txt":
                data = re.sub(rb"(?m)^libpython .*$", f"libpython {path}".encode(), data)
            copied.writestr(item, data)
    return destination


@pytest.mark.parametrize("where", ["python3 on PATH", "dynamic linker", "nowhere"])
def test_the_guard_finds_libpython_where_the_recorded_path_does_not_exist(fmus, tmp_path, where):
    recorded = Path(guard.libpython())
    name = "libpython3.99.so.1.0" if where != "dynamic linker" else recorded.name  # 3.99: no such Python
    fmu = with_recorded_libpython(fmus["python"], f"/nonexistent/{name}", tmp_path / "elsewhere.fmu")
    # PATH: the folder of this test's python3, or no folder at all
    path = str(Path(sys.executable).parent) if where == "python3 on PATH" else "/nonexistent"
    env = {k: v for k, v in python_host_environment().items() if k not in (guard.LIBPYTHON_VARIABLE, "CONDA_PREFIX")}
    parameters, inputs, outputs, _ = scenario(fmu)
    done, T = run_c_host(fmu, parameters, inputs, outputs, DT, 4, tmp_path, env=dict(env, PATH=path))
    if where == "nowhere":
        assert done.returncode == 1
        logged = [line for line in done.stderr.splitlines() if "libpython" in line]
        assert len(logged) == 1
        for attempt in (guard.LIBPYTHON_VARIABLE, f"/nonexistent/{name}", "python3 on PATH", f"{name} (",
                        f"/usr/local/lib/{name}"):
            assert attempt in logged[0]
    else:
        assert done.returncode == 0, done.stderr
        assert np.abs(T - run_fmpy(fmus["python"], parameters, inputs, outputs, DT, 4)).max() < 1e-9


def glibc_versions(library):
    """The glibc symbol versions (tuples) a shared library needs, read from `objdump -T`, and
    the libraries it names as needed (`objdump -p`)."""
    symbols = subprocess.run(["objdump", "-T", str(library)], capture_output=True, text=True, check=True).stdout
    headers = subprocess.run(["objdump", "-p", str(library)], capture_output=True, text=True, check=True).stdout
    versions = {tuple(int(x) for x in v.split(".")) for v in re.findall(r"\(GLIBC_([0-9.]+)\)", symbols)}
    return versions, set(re.findall(r"NEEDED\s+(\S+)", headers))


def test_the_python_fmu_needs_the_glibc_its_documentation_states(fmus, tmp_path):
    with zipfile.ZipFile(fmus["python"]) as fmu:
        page = fmu.read("documentation/index.html").decode()
        for name in ("NodalBuilding.so", "NodalBuilding.pythonfmu.so"):
            (tmp_path / name).write_bytes(fmu.read(f"binaries/linux64/{name}"))
    as_tuple = lambda text: tuple(int(x) for x in text.split("."))
    guard_needs, guard_libraries = glibc_versions(tmp_path / "NodalBuilding.so")
    pythonfmu_needs, _ = glibc_versions(tmp_path / "NodalBuilding.pythonfmu.so")
    # the guard asks for the dl* functions' first versions, which glibc older than 2.34 has in libdl
    assert max(guard_needs) == as_tuple(guard.GUARD_GLIBC) == (2, 2, 5)
    assert "libdl.so.2" in guard_libraries
    assert max(pythonfmu_needs) == as_tuple(guard.PYTHONFMU_GLIBC)
    assert f"glibc {guard.GUARD_GLIBC};" in page and f"needs glibc {guard.PYTHONFMU_GLIBC} " in page


@pytest.mark.parametrize("fmi", (2, 3))
def test_the_standalone_fmu_needs_the_glibc_its_documentation_states(testcell_data, tmp_path, fmi):
    """Its binary, the coefficients that follow the state stepped in it (pow and exp among their
    functions), needs glibc 2.14 at most, as documentation/index.html says."""
    from nodeforce.fmu_build.build import fmu_kind
    from tests.test_convection import followed
    fmu = build_fmu(parse_building(followed(testcell_data)), tmp_path / "model.fmu", kind=fmu_kind("standalone", fmi))
    with zipfile.ZipFile(fmu) as archive:
        page = archive.read("documentation/index.html").decode()
        binary, = (name for name in archive.namelist() if name.startswith("binaries/") and name.endswith(".so"))
        (tmp_path / "binary.so").write_bytes(archive.read(binary))
    needs, _ = glibc_versions(tmp_path / "binary.so")
    assert max(needs) == (2, 14)
    assert "symbols up to glibc 2.14" in page


def test_outputs_read_one_per_call_are_the_step_s_outputs(fmus, tmp_path):
    """The guard answers reads of outputs from its copy of the step's outputs: read one per
    call, after every step, in the C host, they are FMPy's (all in one call); restoring a state
    gives that state's outputs before any step."""
    fmu = fmus["python"]
    parameters, inputs, outputs, _ = scenario(fmu)
    reference = run_fmpy(fmu, parameters, inputs, outputs, DT, 24)
    done, T = run_c_host(fmu, parameters, inputs, outputs, DT, 24, tmp_path, env=python_host_environment(),
                         one_by_one=True)
    assert done.returncode == 0, done.stderr
    assert np.abs(T - reference).max() < 1e-9 and np.ptp(T[:, 22]) > 0.1
    with FmuInstance(fmu) as instance:
        slave, refs = instance.fmu, [instance.variables[name].valueReference for name in outputs]
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        slave.setReal([instance.variables["T_out"].valueReference], [35.0])
        slave.doStep(0.0, DT)
        state, first = slave.getFMUstate(), slave.getReal(refs)
        slave.doStep(DT, DT)
        second = [slave.getReal([vr])[0] for vr in refs]
        slave.setFMUstate(state)
        restored = [slave.getReal([vr])[0] for vr in refs]
        slave.freeFMUstate(state)
        slave.terminate()
    assert restored == first and second != first


def test_fmpy_applies_a_forced_nodes_measurement_at_every_step(fmus):
    """pyproject.toml's FMPy lower bound: a discrete input re-applied before each step, the
    sample of that step's start (FMPy 0.3.22 applied the first sample only, 0.3.21 each one a
    step late). A forced node fed 10, 20, 30, 40 C ends each step at that step's sample."""
    ramp = np.array([10.0, 20.0, 30.0, 40.0, 50.0])
    signals = np.array(list(zip(np.arange(5) * DT, ramp)), dtype=[("time", float), ("T_forced[9]", float)])
    result = simulate_fmu(str(fmus["standalone"]), input=signals, start_values={"force[9]": True},
                          output=["T[9]", "T[23]"], stop_time=4 * DT, output_interval=DT)
    assert np.array_equal(result["T[9]"][1:], ramp[:4])
    assert len(np.unique(np.round(result["T[23]"][1:], 9))) == 4  # the air follows: the node is not merely recorded


@pytest.mark.parametrize("kind", ["python", "standalone"])
@pytest.mark.parametrize("max_step", [0.0, 1e-5])
def test_a_step_max_step_cannot_cover_is_refused(fmus, kind, max_step):
    """max_step must be > 0, and a doStep of more than 1e7 internal steps is refused, not run."""
    with FmuInstance(fmus[kind]) as instance:
        with pytest.raises(Exception) as refused:
            instance.run(DT, {"max_step": max_step}, {}, [], np.zeros((1, 0)), ["T[23]"])
        assert "doStep" in str(refused.value) or "fmi2DoStep" in str(refused.value)
        # the instance runs again once max_step is one it can take
        assert np.isfinite(instance.run(DT, {}, {}, [], np.zeros((1, 0)), ["T[23]"])).all()

