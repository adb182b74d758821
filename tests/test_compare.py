"""`nodeforce compare`: building files run on a record none was fitted on, scored as a direct
simulation scores them."""
import json

import numpy as np
import pytest

from nodeforce.cli import main
from nodeforce.model.building_file import parse_building
from nodeforce.model.case import measured_case
from nodeforce.model.effects import EFFECTS
from nodeforce.model.integrate import simulate
from nodeforce.model.network import RHO_C_AIR, assemble
from nodeforce.model.synth import pseudo_measurements
from tests.conftest import DATA, SENSORS, record_times


def direct_rmse(building, weather, measurements, start, end):
    """RMSE (C) of the cell's air of `building` against the measurements over the steps from
    `start` to `end`, simulated by the direct model from the weather's history with the first day
    a burn-in (every measured node forced, not scored), as docs/model.md section 5 says."""
    case = measured_case(building, weather, measurements, burn_in_days=1)
    h = case.history_steps
    T = simulate(building, assemble(building), case.U, case.dt, case.measured, burn_in_steps=case.burn_in_steps,
                 steady_start=True, substeps=case.substeps, history_steps=h)[h:]
    rows = (case.times[h + 1:] >= start) & (case.times[h + 1:] <= end)
    residual = (measurements["T23"].to_numpy()[1:] - T[:, 22])[rows]
    return float(np.sqrt(np.mean(residual ** 2)))


@pytest.mark.slow  # two FMUs built and run
def test_compare_scores_two_buildings_as_a_direct_simulation_does(tmp_path, testcell_data, testcell, weather):
    # the "real" cell has an air change of 1/h; one file is as written, one carries 0.5/h
    leaky = EFFECTS["infiltration"].apply(testcell, "cell", {"n": 0.5})
    (tmp_path / "written.json").write_text(json.dumps(testcell_data))
    (tmp_path / "leaky.json").write_text(json.dumps(leaky.to_json()))
    truth = EFFECTS["infiltration"].apply(testcell, "cell", {"n": 1.0})
    measurements = pseudo_measurements(truth, weather, record_times(3), SENSORS, noise_sd=0.1, seed=2,
                                       history_days=3)
    measurements.to_csv(tmp_path / "m.csv", date_format="%Y-%m-%dT%H:%M:%S%z")
    weather_csv = DATA / "miami_tmy2.csv"
    (tmp_path / "phases.csv").write_text("time,phase\n2001-06-10T00:00-05:00,first\n2001-06-12T00:00-05:00,second\n")
    assert main(["compare", str(tmp_path / "written.json"), str(tmp_path / "leaky.json"), "--weather",
                 str(weather_csv), "--measurements", str(tmp_path / "m.csv"), "--phases",
                 str(tmp_path / "phases.csv"), "-o", str(tmp_path / "out")]) == 0
    result = json.loads((tmp_path / "out" / "compare.json").read_text())
    assert result["objective"] == ["cell"] and len(result["models"]) == 2
    for model, building in zip(result["models"], (testcell, leaky)):
        start, end = result["scored_from"], result["record"][1]
        assert model["metrics"]["zones"]["cell"]["rmse"] == pytest.approx(
            direct_rmse(building, weather, measurements, start, end), abs=1e-6)
        second = model["phases"]["second"]
        assert second["rmse"] == pytest.approx(
            direct_rmse(building, weather, measurements, "2001-06-12T00:00-05:00", end), abs=1e-6)
        assert model["metrics"]["n"] == model["phases"]["first"]["n"] + second["n"] == 2 * 96
    # an air change of 0.5/h adds (rho c)_air V n / 3600 to the heat loss coefficient
    written, leaky_model = result["models"]
    assert leaky_model["heat_loss_coefficient"] - written["heat_loss_coefficient"] == pytest.approx(
        RHO_C_AIR * 22.5 * 0.5 / 3600)
    # the leaky file is nearer the truth
    assert leaky_model["metrics"]["rmse"] < written["metrics"]["rmse"]
    md = (tmp_path / "out" / "compare.md").read_text()
    assert "leaky.json" in md and "second" in md and (tmp_path / "out" / "compare.png").exists()


def test_compare_refuses_an_objective_zone_a_file_lacks(tmp_path, testcell_data, weather, capsys):
    (tmp_path / "b.json").write_text(json.dumps(testcell_data))
    measurements = pseudo_measurements(parse_building(testcell_data), weather, record_times(2), SENSORS)
    measurements.to_csv(tmp_path / "m.csv", date_format="%Y-%m-%dT%H:%M:%S%z")
    assert main(["compare", str(tmp_path / "b.json"), "--weather", str(DATA / "miami_tmy2.csv"), "--measurements",
                 str(tmp_path / "m.csv"), "--objective", "attic", "-o", str(tmp_path / "out")]) == 2
    assert "attic" in capsys.readouterr().err
