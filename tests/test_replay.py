"""report.json holds every input of the choice: each round's decision, recomputed from the report
alone with the policy (`diagnosis.policy.POLICY`, `diagnosis.selection.decide`), is the one the
loop made."""
import json
from dataclasses import replace

import pytest

import nodeforce
from nodeforce.diagnosis.result import Diagnosis
from tests.conftest import DATA

pytestmark = pytest.mark.slow  # diagnoses: not in `make check`


def check_replay(path):
    """Every round of the diagnosis report.json at `path` holds recomputed from the report alone:
    the same choice, band, suggestions, verdicts and reason; returns the diagnosis read."""
    read = Diagnosis.read(path)
    recorded = json.loads(path.read_text())["decision"]["rounds"]
    replayed = read.replay()
    assert read.rounds and len(replayed) == len(read.rounds)
    for again, written in zip(replayed, recorded):
        assert again.to_json() == {k: v for k, v in written.items() if k != "cost"}
    assert [a.label for a in read.added] == [r["chosen"] for r in recorded if r["chosen"]]
    return read


def test_the_demos_choice_is_recomputed_from_report_json_alone(tmp_path):
    building = nodeforce.read_building(DATA / "testcell_miami.json")
    case = nodeforce.measured_case(building, nodeforce.read_weather(DATA / "miami_tmy2.csv"),
                                   nodeforce.read_measurements(DATA / "demo_measurements.csv"), burn_in_days=1)
    made = nodeforce.diagnose(building, case, tmp_path, seed=0, workers=1)
    read = check_replay(tmp_path / "report.json")
    # what the loop returned is what it wrote
    assert read.to_json() == json.loads(json.dumps(made.to_json()))
    # a replay that could differ: with another noise the same records give another decision
    noisier = replace(read, rounds=[replace(r, inputs={**r.inputs, "floor_sd": 10 * r.inputs["floor_sd"]})
                                    for r in read.rounds])
    assert noisier.replay()[0].chosen is None and read.rounds[0].chosen is not None
