"""report.json holds every input of the choice: each round's decision, recomputed from the report
alone under the policy it records (`diagnosis.policy.Policy`, `diagnosis.selection.decide`), is the
one the loop made (tests/test_policy.py: after the code's default policy changes too)."""
import json
from dataclasses import replace

import pandas as pd
import pytest

import nodeforce
from nodeforce.diagnosis.result import Diagnosis
from tests.conftest import DATA, SENSORS
from tests.test_report_sentences import check_sentences

pytestmark = pytest.mark.slow  # diagnoses: not in `make check`


def check_replay(path):
    """Every round of the diagnosis report.json at `path` holds recomputed from the report alone:
    the same choice, band, suggestions, verdicts and reason, each sentence of it true of the
    numbers report.json records; returns the diagnosis read."""
    read = Diagnosis.read(path)
    report = json.loads(path.read_text())
    recorded = report["decision"]["rounds"]
    replayed = read.replay()
    assert read.rounds and len(replayed) == len(read.rounds)
    assert report["policy"] == read.policy.to_json()
    for again, written in zip(replayed, recorded):
        assert again.to_json() == {k: v for k, v in written.items() if k != "cost"}
    # the effects the decisions add (a round's choice, or one that took an earlier one's place)
    assert [a.effect_json() for a in read.added] == report["effects"]
    check_sentences(report)  # and what each round's reason says is true of its numbers
    return read


def test_the_demos_choice_is_recomputed_from_report_json_alone(tmp_path):
    building = nodeforce.read_building(DATA / "testcell_miami.json")
    case = nodeforce.measured_case(building, nodeforce.read_weather(DATA / "miami_tmy2.csv"),
                                   nodeforce.read_measurements(DATA / "demo_measurements.csv"), burn_in_days=1)
    made = nodeforce.diagnose(building, case, tmp_path, search=nodeforce.SearchSettings(seed=0),
                              execution=nodeforce.Execution(workers=1))
    read = check_replay(tmp_path / "report.json")
    # what the loop returned is what it wrote
    assert read.to_json() == json.loads(json.dumps(made.to_json()))
    # a replay that could differ: with thirty times the noise (3 C, more than the floor's own
    # sensors miss the file by) the same records give another decision
    noisier = replace(read, rounds=[replace(r, inputs={**r.inputs, "sigma": 30 * r.inputs["sigma"],
                                                       "floor_sd": 30 * r.inputs["floor_sd"]})
                                    for r in read.rounds])
    assert noisier.replay()[0].chosen is None and read.rounds[0].chosen is not None



def test_a_diagnosis_of_two_faults_is_recomputed_round_by_round_from_report_json_alone(tmp_path):
    """The test cell with two faults its file does not declare, the paper's door (wood of 0.78
    W/m/K, not 0.23) and 1.5 air changes an hour: the first round adds one, the error left is
    still above the noise, and the next round finds the other on top of it; every round's choice
    is recomputed from report.json."""
    building = nodeforce.read_building(DATA / "testcell_miami.json")
    weather = nodeforce.read_weather(DATA / "miami_tmy2.csv")
    times = pd.date_range("2001-06-10 00:00", periods=10 * 96 + 1, freq="15min", tz="-05:00", name="time")
    measured = nodeforce.synthesize(building, weather, times, SENSORS, noise=nodeforce.SensorNoise(0.1, seed=3),
                                    reading=nodeforce.Reading(history_days=7),
                                    effects=[("conductivity", "door", {"factor": 0.78 / 0.23}),
                                             ("infiltration", "cell", {"n": 1.5})])
    case = nodeforce.measured_case(building, weather, measured, burn_in_days=1)
    nodeforce.diagnose(building, case, tmp_path,
                       search=nodeforce.SearchSettings(seed=0, generations=30, noise=0.1),
                       execution=nodeforce.Execution(workers=1))
    read = check_replay(tmp_path / "report.json")
    assert sorted(a.label for a in read.added) == ["conductivity@door", "infiltration@cell"]
    assert all(c.on_top_of == (read.added[0].label,) for c in read.candidates if c.round == 2)


def test_a_benchmark_record_of_two_rounds_is_recomputed_from_report_json_alone(tmp_path):
    """The benchmark's Saint-Denis July, a window passing more sun than declared, under its third
    noise draw: the loop adds the window's transmittance, then, on top of it, the south wall's
    conductivity; both rounds' choices recomputed from report.json."""
    from benchmarks.records import record
    r = record("sdp-jul/opening-L", 2)
    nodeforce.diagnose(r.building, r.case(), tmp_path, objective=nodeforce.objective(r.building, r.zones),
                       search=nodeforce.SearchSettings(generations=30, noise=r.spec.noise, seed=0),
                       execution=nodeforce.Execution(workers=1))
    read = check_replay(tmp_path / "report.json")
    assert len(read.rounds) >= 2 and len(read.added) == 2

