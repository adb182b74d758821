"""A converted multi-zone EnergyPlus model end to end (issue 44, item 4): examples/multizone's
three zones, their interzone partitions, windows, scheduled gains and night ventilation,
through `nodeforce convert`; a record with an infiltration its file does not declare, in one
office only; the diagnosis finds it there."""
import json
from pathlib import Path

import pandas as pd
import pytest

from nodeforce.api import convert_idf
from nodeforce.diagnose.loop import diagnose
from nodeforce.iotools.typical_year import convert_typical_year
from nodeforce.iotools.weather import read_weather
from nodeforce.model.case import prepare_case
from nodeforce.model.effects import EFFECTS
from nodeforce.model.score import Objective
from nodeforce.model.synth import pseudo_measurements

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.slow


def test_three_zones_diagnosed_end_to_end(tmp_path):
    building = convert_idf(ROOT / "examples" / "multizone" / "three_zones.idf")
    convert_typical_year(ROOT / "examples" / "bestest" / "data" / "725650TYCST.epw", tmp_path / "w.csv", year=2017)
    weather = read_weather(tmp_path / "w.csv")
    truth = EFFECTS["infiltration"].apply(building, "EAST OFFICE", {"n": 1.2})
    airs = [z.air_node for z in building.zones]
    times = pd.date_range("2017-04-03 00:00", periods=5 * 24 + 1, freq="h", tz="-07:00", name="time")
    measured = pseudo_measurements(truth, weather, times, airs, noise_sd=0.05, seed=1, history_days=14)
    case = prepare_case(building, weather, measured, history_days=14).with_burn_in(1)
    objective = Objective.of(building, [z.name for z in building.zones])
    report = diagnose(building, case, objective, tmp_path / "out", seed=0, fmu_kind="python",
                      population=12, generations=10)
    after = json.loads((tmp_path / "out" / "building_after.json").read_text())
    east = next(z for z in after["zones"] if z["name"] == "EAST OFFICE")
    assert east["air_change_rate"] == pytest.approx(1.2, abs=0.05)
    for z in after["zones"]:
        if z["name"] != "EAST OFFICE":
            assert z["air_change_rate"] == pytest.approx(0.3)
    assert report["after"]["validation"]["rmse"] < report["before"]["validation"]["rmse"] / 3
