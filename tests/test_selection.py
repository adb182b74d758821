"""The diagnosis on records like the ones it failed on (issue 27's table), each with one effect its
building file does not declare, in another climate, step, length, heater or sensor set than the
other tests: the complete physics is calibrated every round and one rule, blocked
cross-validation over whole days, chooses. Small records (a week, 10 to 30-minute steps) and
small search budgets; the truths are the registry's effects applied to the test cell."""
import json

import numpy as np
import pandas as pd
import pvlib
import pytest

from nodeforce.diagnosis.calibrate import Candidate, calibrate
from nodeforce.diagnosis.loop import diagnose
from nodeforce.ga.locate import Execution, SearchSettings
from nodeforce.iotools.typical_year import convert_typical_year, relocate
from nodeforce.iotools.weather import read_weather
from nodeforce.model.building_file import parse_building
from nodeforce.model.case import prepare_case
from nodeforce.model.effects import EFFECTS
from nodeforce.model.score import Objective
from nodeforce.model.synth import pseudo_measurements

from .conftest import SENSORS

pytestmark = pytest.mark.slow  # a diagnosis each

GREENSBORO = "723170TYA.CSV"  # pvlib's bundled TMY3 of Greensboro, NC


@pytest.fixture(scope="module")
def greensboro(testcell_data, tmp_path_factory):
    """The test cell moved to Greensboro, NC, and that typical year's weather (a climate the other
    tests never see: a cold, sunny winter)."""
    folder = tmp_path_factory.mktemp("greensboro")
    site = convert_typical_year(pvlib.__path__[0] + "/data/" + GREENSBORO, folder / "weather.csv", year=2001)
    return parse_building(relocate(testcell_data, site)), read_weather(folder / "weather.csv")


def heated_cell(testcell_data):
    """The test cell with a declared, measured heat input to its air."""
    return parse_building({**testcell_data, "zones": [dict(testcell_data["zones"][0], heat_input="Q_heat")]})


def prbs_weather(weather, start, days, power, step="30min", seed=11):
    """`weather` at `step` (linear between its hours) from two days before `start`, with a heater
    of `power` W switching at each step with probability 0.15 (a pseudo-random binary sequence)."""
    hours = weather.loc[pd.Timestamp(start) - pd.Timedelta(days=9):pd.Timestamp(start) + pd.Timedelta(days=days + 1)]
    grid = pd.date_range(hours.index[0], hours.index[-1], freq=step, name="time")
    fine = hours.reindex(hours.index.union(grid)).interpolate("time").reindex(grid)
    rng = np.random.default_rng(seed)
    fine["Q_heat"] = power * (np.cumsum(rng.random(len(fine)) < 0.15) % 2)
    fine.attrs = weather.attrs
    return fine


def record(building, weather, start, days, step, sensors=SENSORS, noise=0.1, effect=None, seed=5, history=7):
    """The case of `building` on a record of the building with `effect` ((id, target, values)) that
    its file does not declare: `days` from `start` at `step`, `sensors` with `noise` C of noise,
    `history` days of real weather before it.

    An air-only record starts in the periodic regime of its first day (no history): with nothing
    measured but the air, the state a week of real weather leaves in the heavy floor is not
    what the first day's steady state gives, and the true model itself then misses the record by
    0.4 C (initial-state estimation is another issue than the choice of an effect)."""
    truth = EFFECTS[effect[0]].apply(building, effect[1], effect[2]) if effect else building
    times = pd.date_range(start, periods=int(days * pd.Timedelta("1D") / pd.Timedelta(step)) + 1, freq=step,
                          name="time")
    measurements = pseudo_measurements(truth, weather, times, sensors, noise_sd=noise, seed=seed,
                                       history_days=history)
    return prepare_case(building, weather, measurements).with_burn_in(1)


def run(building, case, tmp_path, noise=None):
    return diagnose(building, case, tmp_path, Objective.of(building),
                    search=SearchSettings(seed=0, generations=30, noise=noise),
                    execution=Execution(workers=2)).to_json()


def added(report):
    return [(e["effect"], e["target"]) for e in report["effects"]]


def test_the_paper_s_floor_coupled_to_the_ground_is_calibrated_and_chosen(testcell, weather, tmp_path):
    """The paper's own finding: the floor coupled to the ground (U 3 W/m2/K, 24 C), its sensors, a
    week at 15 min. The forcing evidence ranks the floor first, its finding says what its numbers
    say, and the ground coupling is calibrated (whatever the localisation calls) and chosen."""
    case = record(testcell, weather, "2001-06-10 00:00-05:00", 7, "15min",
                  effect=("ground_coupling", "floor", {"U": 3.0, "T_ground": 24.0}))
    report = run(testcell, case, tmp_path)
    located = report["localization"]
    assert located["components"][0]["component"] == "floor" and located["components"][0]["share"] > 0.5
    # the evidence is in report.json, most first
    shares = [e["share"] for e in located["components"]]
    assert shares == sorted(shares, reverse=True)
    # ranked by J, not by id: each node's score no higher than the next one's
    scores = [located["node_scores"][str(i)] for i in located["ranked_nodes"]]
    assert scores == sorted(scores)
    if not located["best_nodes"]:
        assert "below the 50% needed" not in located["finding"] or not located["search"]["explains"]
    assert added(report)[:1] == [("ground_coupling", "floor")], report["decision"]["reason"]
    assert report["after"]["validation"]["rmse"] < 1.5 * 0.1 < report["before"]["validation"]["rmse"]
    # the rounds and their cost are reported
    cost = report["decision"]["rounds"][0]["cost"]
    assert cost["candidates"] >= 15 and cost["simulations"] > cost["candidates"] and cost["seconds"] > 0
    assert json.loads((tmp_path / "report.json").read_text())["decision"]["rounds"][0]["cost"] == cost


def test_a_door_three_times_as_conductive_is_chosen_in_another_climate_and_step(greensboro, tmp_path):
    """The door three times as conductive as declared, a Greensboro winter at 10-minute steps: the
    exact correction is chosen, not refused by a test made on the model's own structured error."""
    building, weather = greensboro
    case = record(building, weather, "2001-01-15 00:00-05:00", 7, "10min",
                  effect=("conductivity", "door", {"factor": 3.0}))
    report = run(building, case, tmp_path)
    assert added(report)[:1] == [("conductivity", "door")], report["decision"]["reason"]
    factor = report["effects"][0]["parameters"]["factor"]
    assert abs(factor["value"] - 3.0) < max(0.3, 3 * factor["std"])
    assert report["after"]["validation"]["rmse"] < 1.5 * 0.1


def test_an_air_change_under_heavy_noise_is_chosen(greensboro, tmp_path):
    """An air change of 0.8/h that the file does not declare, the same winter, 0.2 C of noise on
    every sensor."""
    building, weather = greensboro
    case = record(building, weather, "2001-01-15 00:00-05:00", 7, "10min", noise=0.2,
                  effect=("infiltration", "cell", {"n": 0.8}))
    report = run(building, case, tmp_path)
    assert added(report)[:1] == [("infiltration", "cell")], report["decision"]["reason"]
    n = report["effects"][0]["parameters"]["n"]
    assert abs(n["value"] - 0.8) < max(0.2, 3 * n["std"])


def test_a_record_without_a_fault_gets_nothing(testcell, weather, tmp_path):
    """"None" stays "none": every physical candidate is calibrated, and none predicts the left-out
    days better than the noise could make it."""
    case = record(testcell, weather, "2001-06-10 00:00-05:00", 7, "15min")
    report = run(testcell, case, tmp_path)
    assert report["effect"]["effect"] == "none", report["decision"]["reason"]
    assert report["decision"]["rounds"][0]["cost"]["candidates"] >= 15
    assert report["after"] == report["before"]


def test_the_heater_s_own_capacity_with_the_air_alone_and_nothing_on_top(testcell_data, weather, tmp_path):
    """Air only, the heater's own capacity (1.2e5 J/K behind 15 W/K): its lag is chosen, and no
    envelope factor on top."""
    building = heated_cell(testcell_data)
    heated = prbs_weather(weather, "2001-06-10 00:00-05:00", 7, 500.0)
    case = record(building, heated, "2001-06-10 00:00-05:00", 7, "30min", sensors=[23], history=0,
                  effect=("heat_input_lag", "cell", {"C_h": 1.2e5, "H_h": 15.0}))
    report = run(building, case, tmp_path, noise=0.1)
    assert added(report) == [("heat_input_lag", "cell")], report["decision"]["reason"]
    assert report["after"]["validation"]["rmse"] < 1.5 * 0.1


def test_furniture_behind_a_small_conductance_with_the_air_alone(testcell_data, weather, tmp_path):
    """Air only, a 300 W heater switched at random, 4e5 J/K of furniture behind 25 W/K: the internal
    mass is calibrated every round (whatever the residual follows) and chosen first."""
    building = heated_cell(testcell_data)
    heated = prbs_weather(weather, "2001-06-10 00:00-05:00", 7, 300.0)
    case = record(building, heated, "2001-06-10 00:00-05:00", 7, "30min", sensors=[23], history=0,
                  effect=("internal_mass", "cell", {"C_m": 4e5, "H_m": 25.0}))
    report = run(building, case, tmp_path, noise=0.1)
    assert added(report)[:1] == [("internal_mass", "cell")], report["decision"]["reason"]
    assert report["after"]["validation"]["rmse"] < 1.5 * 0.1 < report["before"]["validation"]["rmse"]


def test_a_heater_declared_all_convective_has_its_radiative_share_calibrated(testcell_data, weather):
    """The file declares f_r = 0, the bound of the share's range: the calibration starts inside
    it (else its first step is scaled to nothing and the split is never calibrated) and finds
    the truth's 0.8."""
    building = heated_cell(testcell_data)
    heated = prbs_weather(weather, "2001-06-10 00:00-05:00", 5, 500.0)
    case = record(building, heated, "2001-06-10 00:00-05:00", 5, "30min", sensors=[23], history=0, noise=0.05,
                  effect=("heat_input_split", "cell", {"f_r": 0.8})).with_steady_start()
    assert EFFECTS["heat_input_split"].read(building, "cell")["f_r"] == 0.0
    found, _, _ = calibrate(Candidate(building, "heat_input_split", "cell"), case, Objective.of(building))
    assert found["f_r"]["value"] == pytest.approx(0.8, abs=0.05)
