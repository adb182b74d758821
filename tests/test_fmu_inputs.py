"""`nodeforce inputs`: the FMU's input table of a record and its start values, as another tool
sets them (cosim.run.input_table, iotools.fmu_inputs): the direct model's inputs at each row, and
through the FMU at FMI's semantics (values at t, their slopes to the next row) the direct model."""
import json

import numpy as np
import pytest

from nodeforce.cli import main
from nodeforce.cosim.fmi import FmuInstance
from nodeforce.fmu_build.build import build_fmu
from nodeforce.iotools.fmu_inputs import read_fmu_inputs
from nodeforce.iotools.measurements import read_measurements
from nodeforce.iotools.weather import read_weather
from nodeforce.model.building_file import parse_building
from nodeforce.model.case import measured_case
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble
from tests.conftest import SENSORS
from tests.test_columns import files  # noqa: F401 (the fixture: the test cell with a heater and a cellar)


def written(files, tmp_path, *options):  # noqa: F811
    out = tmp_path / "inputs.csv"
    assert main(["inputs", files["building"], "--weather", files["weather"], "-o", str(out), *options]) == 0
    return read_fmu_inputs(out)


def the_case(files, burn_in_days=0.0, measured=True):  # noqa: F811
    building = parse_building(files["data"], source=files["building"])
    measurements = read_measurements(files["measurements"]) if measured else None
    return building, measured_case(building, read_weather(files["weather"]), measurements, burn_in_days,
                                   history_days=0)


def test_the_table_holds_the_direct_models_inputs_at_each_row(files, tmp_path):  # noqa: F811
    table, start = written(files, tmp_path, "--measurements", files["measurements"], "--force", "9",
                           "--burn-in-days", "1")
    building, case = the_case(files, 1.0)
    assert np.allclose(table.index, (case.times - case.times[0]).total_seconds(), rtol=0, atol=1e-9)
    names = list(case.input_names)
    heater = names.index("Q_heater")
    for k, name in enumerate(names):
        if k == heater:  # the power of the interval from t_n, which the record logs at t_n+1
            assert np.allclose(table[name].to_numpy()[:-1], case.U[1:, k], rtol=1e-15, atol=0)
            assert np.isnan(table[name].to_numpy()[-1])
        else:
            assert np.allclose(table[name].to_numpy(), case.U[:, k], rtol=1e-15, atol=0), name
    assert np.ptp(table["Q_heater"].to_numpy()[:-1]) == 400.0
    # node 9 forced throughout, the other sensors over the burn-in's steps only, at their sample of t_n
    B = case.burn_in_steps
    assert B == 96
    assert list(table.columns) == names + [f"T_forced[{i}]" for i in range(1, building.n_nodes + 1)]
    assert all(table[f"T_forced[{i}]"].isna().all() for i in range(1, building.n_nodes + 1) if i not in SENSORS)
    for i in SENSORS:
        column, measured = table[f"T_forced[{i}]"].to_numpy(), case.measured[:, i - 1]
        rows = slice(None) if i == 9 else slice(0, B)
        assert np.array_equal(column[rows], measured[rows], equal_nan=True)
        if i != 9:
            assert np.isnan(column[B:]).all()
    assert start == {**{f"T_start[{i}]": pytest.approx(v, abs=1e-12) for i, v in enumerate(case.start_state(), 1)},
                     **{f"force[{i}]": True for i in SENSORS}}
    assert start["T_start[9]"] == case.measured[0, 8]


def test_the_table_through_the_fmu_gives_the_direct_model(files, tmp_path):  # noqa: F811
    """An importer's run: before the step from t_n the table's row n and, for the sampled inputs,
    the slope to row n+1 (the heat input held); one doStep per row. The direct model of the same
    record without a warm-up gives the same temperatures."""
    table, start = written(files, tmp_path, "--measurements", files["measurements"])
    building, case = the_case(files)
    fmu = build_fmu(building, tmp_path / "named.fmu", kind="standalone")
    assert table.filter(like="T_forced[").isna().all().all() and not any(k.startswith("force[") for k in start)
    table = table[list(case.input_names)]
    names = list(table.columns)
    values = table.to_numpy()[:-1]
    slopes = np.diff(table.to_numpy(), axis=0) / case.dt
    slopes[:, names.index("Q_heater")] = 0.0
    outputs = [f"T[{i}]" for i in range(1, building.n_nodes + 1)]
    with FmuInstance(fmu) as instance:
        through = instance.run(case.dt, start, {}, names, values, outputs, slopes=slopes)
    direct = simulate(building, assemble(building), case.U, case.dt, case.measured, warmup_days=0,
                      substeps=case.substeps)
    assert case.substeps == 3
    assert np.abs(through - direct).max() < 1e-9
    assert np.ptp(direct[:, 22]) > 3.0


def test_forcing_without_measurements_is_refused(files, tmp_path, capsys):  # noqa: F811
    assert main(["inputs", files["building"], "--weather", files["weather"], "--force", "9",
                 "-o", str(tmp_path / "x.csv")]) == 2
    assert "--force" in capsys.readouterr().err
    assert not (tmp_path / "x.csv").exists()


def test_forcing_a_node_without_measurements_is_refused_naming_the_file(files, tmp_path, capsys):  # noqa: F811
    assert main(["inputs", files["building"], "--weather", files["weather"], "--measurements", files["measurements"],
                 "--force", "2", "-o", str(tmp_path / "x.csv")]) == 2
    error = capsys.readouterr().err
    assert files["measurements"] in error and "T2" in error and len(error.strip().splitlines()) == 1
