"""A later record of the building, read for nothing but the final comparison: the diagnosis scores
the building as written and as corrected on it as `nodeforce compare` does, reports it on the
first screen and keeps it in report.json; a bad --later stops the command line at once."""
import json

import pandas as pd
import pytest

import nodeforce
from nodeforce.cli import main
from nodeforce.diagnosis.result import Diagnosis
from tests.conftest import DATA, SENSORS

WEATHER = DATA / "miami_tmy2.csv"
# the demo's fault (nodeforce.cli.DEMO_COMMAND): the floor coupled to a ground the file does not declare
FAULT = ("ground_coupling", "floor", {"U": 0.8, "T_ground": 24.0})
NOISE = 0.1  # C, the demo's


def later_measurements(path):
    """A week of the test cell's sensors with the demo's fault, starting two weeks after the
    demo's record ends (2001-06-24), with its noise and another draw of it."""
    building = nodeforce.read_building(DATA / "testcell_miami.json")
    times = pd.date_range("2001-07-08 00:00", periods=7 * 96 + 1, freq="15min", tz="-05:00", name="time")
    frame = nodeforce.synthesize(building, nodeforce.read_weather(WEATHER), times, SENSORS, effects=[FAULT],
                                 noise=nodeforce.SensorNoise(NOISE, seed=2), reading=nodeforce.Reading(history_days=7))
    frame.round(4).to_csv(path, date_format="%Y-%m-%dT%H:%M:%S%z")
    return path


@pytest.fixture(scope="module")
def diagnosed(tmp_path_factory):
    folder = tmp_path_factory.mktemp("later")
    building = nodeforce.read_building(DATA / "testcell_miami.json")
    record = nodeforce.read_record(building, WEATHER, DATA / "demo_measurements.csv",
                                   reading=nodeforce.Reading(burn_in_days=1))
    later = nodeforce.read_record(building, WEATHER, later_measurements(folder / "july.csv"),
                                  reading=nodeforce.Reading(burn_in_days=1))
    diagnosis = nodeforce.diagnose(building, [record], folder / "out", search=nodeforce.SearchSettings(seed=0),
                                   execution=nodeforce.Execution(workers=1),
                                   beside=nodeforce.Beside(later=[later]))
    return building, folder, diagnosis


@pytest.mark.slow
def test_the_later_record_is_scored_as_compare_scores_the_files_written(diagnosed):
    building, folder, diagnosis = diagnosed
    (later,) = diagnosis.later
    assert later.name == "july"
    # the independent path: the files read back and compared as `nodeforce compare` would
    weather, measured = nodeforce.read_weather(WEATHER), nodeforce.read_measurements(folder / "july.csv")
    objective = nodeforce.objective(building)
    models = []
    for name in ("written", "after"):
        b = building if name == "written" else nodeforce.read_building(folder / "out" / "building_after.json")
        models.append((name, b, nodeforce.measured_case(b, weather, measured, burn_in_days=1), objective))
    written, after = (m["metrics"] for m in nodeforce.compare(models).models)
    for ours, theirs in ((later.before, written), (later.after, after)):
        assert ours["rmse"] == pytest.approx(theirs["rmse"], rel=1e-9)
        assert ours["n"] == theirs["n"]
    # the demo's fault found in June holds in July, which no choice read: the error left is the noise's
    assert [(a.effect, a.target) for a in diagnosis.added][0] == ("ground_coupling", "floor")
    assert later.after["rmse"] < min(later.before["rmse"], 1.15 * NOISE)
    # nothing of July in the diagnosis's windows: every block and the validation end in June
    end = pd.Timestamp(diagnosis.period["validation"][1])
    assert end < pd.Timestamp(later.record[0])
    assert all(pd.Timestamp(last) <= end for _, last in diagnosis.period["blocks"])


@pytest.mark.slow
def test_the_later_record_is_on_the_first_screen_and_read_back(diagnosed):
    _, folder, diagnosis = diagnosed
    later = diagnosis.later[0]
    line = (f"Later record july: RMSE {later.before['rmse']:.3f} as written -> {later.after['rmse']:.3f} C as "
            "corrected (no choice read it).")
    screen = diagnosis.summary().split("\n\n")[0].splitlines()
    assert line in screen and len(screen) <= 8
    md = (folder / "out" / "report.md").read_text(encoding="utf-8")
    assert f"**Later record july:** RMSE {later.before['rmse']:.3f}" in md.split("\n\n")[1]
    read = Diagnosis.read(folder / "out" / "report.json")
    assert read.later == diagnosis.later
    assert json.loads((folder / "out" / "report.json").read_text())["later"][0]["name"] == "july"


def test_a_bad_later_record_is_a_one_line_error_naming_it(tmp_path, capsys):
    base = ["diagnose", str(DATA / "testcell_miami.json"), "--weather", str(WEATHER), "--measurements",
            str(DATA / "demo_measurements.csv"), "-o", str(tmp_path / "out")]
    for later, said in ((f"weather={WEATHER},name=july", "--later: measurements: missing"),
                        (f"weather={WEATHER},measurements={tmp_path / 'july.csv'}", f"{tmp_path / 'july.csv'}: file"),
                        (f"weather={WEATHER},measurements={DATA / 'demo_measurements.csv'},phases=p.csv",
                         "--later: phases: no such field")):
        assert main(base + ["--later", later]) == 2
        err = capsys.readouterr().err.strip()
        assert "\n" not in err and said in err
    assert not (tmp_path / "out").exists()  # refused before any work


def later_of(name, before, after):
    """A later record as report.json keeps it, its overall RMSE (C) as written and as corrected."""
    return {"name": name, "measurements": f"{name}.csv", "record": ["2001-07-08T00:00:00-05:00",
                                                                  "2001-07-15T00:00:00-05:00"],
            "scored_from": "2001-07-09T00:15:00-05:00", "before": {"rmse": before}, "after": {"rmse": after}}


def test_several_later_records_take_one_line_and_the_screen_stays_in_ten_lines():
    from nodeforce.diagnosis.report.summary import FIRST_SCREEN_LINES, first_screen
    from tests.test_report import synthetic
    report, _ = synthetic()
    report["heat_loss_coefficient"] = {"before": 60.04, "after": 64.1, "after_sd": 1.23, "split": None}
    report["later"] = [later_of("july", 0.2084, 0.1201), later_of("august", 0.31, 0.2996)]
    # three effects, the most rounds the policy runs, each with what the data determine of it
    door = report["candidates"][0]["parameters"]
    report["effects"] = [{"effect": "conductivity", "target": target, "parameters": door}
                         for target in ("door", "roof", "floor")]
    report["effect"] = {**report["effects"][-1], "derived": {}}
    screen = first_screen(report)
    assert len(screen) <= FIRST_SCREEN_LINES - 2
    assert ("Later records: july 0.208 -> 0.120 C, august 0.310 -> 0.300 C (RMSE as written -> as corrected; "
            "no choice read them).") in screen
    # what the data determine of the three, on one line where a line each would overflow
    (determine,) = [line for line in screen if line.startswith("The data determine")]
    assert determine.count("factor = 1.873 +- 0.031") == 3
    # without the later records the three keep a line each
    del report["later"]
    assert sum(line.startswith("The data determine for conductivity") for line in first_screen(report)) == 3


def test_a_later_record_not_read_from_its_files_is_refused_before_any_work(tmp_path):
    """The building as corrected needs the record's case prepared anew (measured_case of its
    files), which a Record made from a case alone cannot give."""
    building = nodeforce.read_building(DATA / "testcell_miami.json")
    record = nodeforce.read_record(building, WEATHER, DATA / "demo_measurements.csv",
                                   reading=nodeforce.Reading(burn_in_days=1))
    bare = nodeforce.Record(record.case, "july.csv", "july")
    with pytest.raises(nodeforce.InputError, match="july.csv: later: record july: .*read_record"):
        nodeforce.diagnose(building, [record], tmp_path / "out", beside=nodeforce.Beside(later=[bare]))
    assert not any((tmp_path / "out").iterdir())
