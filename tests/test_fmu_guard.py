"""The guard in front of the Python FMU's binary: one library for every model (compiled once per
process), and an export that still works, without it, on a machine without a C compiler."""
import copy
import zipfile

import numpy as np
from fmpy import read_model_description

from nodeforce.cosim.fmi import FmuInstance
from nodeforce.fmu_build import guard
from nodeforce.fmu_build.build import build_fmu
from nodeforce.model.building_file import parse_building
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble
from tests.importers import run_fmpy


def test_one_guard_binary_for_every_model(testcell_data, tmp_path):
    other = copy.deepcopy(testcell_data)
    other["zones"][0]["internal_gain"] = 10.0
    binaries = []
    for name, data in (("a", testcell_data), ("b", other)):
        path = build_fmu(parse_building(data), tmp_path / f"{name}.fmu")
        with zipfile.ZipFile(path) as fmu:
            binaries.append(fmu.read("binaries/linux64/NodalBuilding.so"))
            sizes = fmu.read("resources/guard.txt").decode().splitlines()[1]
            assert "binaries/linux64/NodalBuilding.pythonfmu.so" in fmu.namelist()
    assert binaries[0] == binaries[1] == guard.guard_binary()
    # the sizes the guard reads are the model description's: nodes, other inputs, the fixed Real
    # parameters but the N start values (the building's properties); max_step is the one tunable
    variables = read_model_description(str(path)).modelVariables
    inputs = [v.name for v in variables if v.causality == "input"]
    n = sum(name.startswith("T_forced[") for name in inputs)
    reals = sum(v.causality == "parameter" and v.type == "Real" and v.variability == "fixed" for v in variables)
    assert [v.name for v in variables if v.variability == "tunable"] == ["max_step"]
    assert sizes == f"sizes {n} {len(inputs) - n} {reals - n}" and n == 23 and reals - n == 27


def test_without_a_c_compiler_the_python_fmu_is_written_unguarded(testcell_data, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(guard, "find_compiler", lambda: None)
    guard.guard_binary.cache_clear()
    try:
        fmu = build_fmu(parse_building(testcell_data), tmp_path / "unguarded.fmu")
    finally:
        guard.guard_binary.cache_clear()
    warning = capsys.readouterr().err.strip().splitlines()
    assert len(warning) == 1 and "no C compiler" in warning[0] and "fmi2Error" in warning[0]
    with zipfile.ZipFile(fmu) as archive:
        names = archive.namelist()
        page = archive.read("documentation/index.html").decode()
    assert "resources/guard.txt" not in names and not any(n.endswith(".pythonfmu.so") for n in names)
    assert "without its guard" in page
    # pythonfmu refuses input derivatives: the model description says so, and nodeforce's driver
    # gives them to the slave as its values after the declared ones: the direct model, still
    description = read_model_description(str(fmu))
    assert description.coSimulation.canInterpolateInputs is False
    building = parse_building(testcell_data)
    U = np.column_stack([20 + 5 * np.sin(np.arange(97) / 10)] * 2 + [np.zeros(97)] * 7)
    direct = simulate(building, assemble(building), U, 900.0, warmup_days=0, substeps=3)
    with FmuInstance(fmu) as instance:
        through = instance.run(900.0, {}, {}, list(assemble(building).input_names), U[:-1],
                               [f"T[{i}]" for i in range(1, 24)], slopes=np.diff(U, axis=0) / 900.0)
    assert np.abs(through - direct).max() < 1e-9 and np.ptp(direct[:, 22]) > 1.0
    # pythonfmu's own binary runs it as before
    T = run_fmpy(fmu, {"T_start[23]": 22.0}, {}, ["T[23]"], 900.0, 4)
    assert np.isfinite(T).all()
