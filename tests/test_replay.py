"""report.json holds every input of the choice: each round's decision, recomputed from the report
alone with the policy (`diagnosis.policy.POLICY`, `diagnosis.selection.decide`), is the one the
loop made."""
import json

import pytest

import nodeforce
from nodeforce.diagnosis.selection import decide, label
from tests.conftest import DATA

pytestmark = pytest.mark.slow  # diagnoses: not in `make check`


def replayed(report):
    """Each round's (chosen label, decision record) recomputed from report.json's content alone:
    the round's candidates as written (their per-day J, their other sensors', what the building
    says of each), and what the round's decision read besides (`decision.rounds[i].inputs`: the
    model's per-day J, the noise, the distances of the admissible candidates' residuals)."""
    out = []
    for number, recorded in enumerate(report["decision"]["rounds"], start=1):
        tried = [c for c in report["candidates"] if c["round"] == number]
        given = recorded["inputs"]
        chosen, decision = decide(None, tried, given["blocks_before"], given["sigma"], given["n"],
                                  given["groups"], given["floor_sd"], given["distances"])
        out.append((label(chosen) if chosen else None, decision))
    return out


def check_replay(report):
    rounds = report["decision"]["rounds"]
    assert rounds and len(replayed(report)) == len(rounds)
    for (chosen, decision), recorded in zip(replayed(report), rounds):
        assert chosen == recorded["chosen"]
        assert decision["indistinct"] == recorded["indistinct"]
        assert decision["suggestions"] == recorded["suggestions"]
        assert decision["candidates"] == recorded["candidates"]
        assert decision["reason"] == recorded["reason"]
    added = [f"{e['effect']}@{e['target']}" for e in report["effects"]]
    assert added == [r["chosen"] for r in rounds if r["chosen"]]


def test_the_demos_choice_is_recomputed_from_report_json_alone(tmp_path):
    building = nodeforce.read_building(DATA / "testcell_miami.json")
    case = nodeforce.measured_case(building, nodeforce.read_weather(DATA / "miami_tmy2.csv"),
                                   nodeforce.read_measurements(DATA / "demo_measurements.csv"), burn_in_days=1)
    nodeforce.diagnose(building, case, tmp_path, seed=0, workers=1)
    report = json.loads((tmp_path / "report.json").read_text())
    check_replay(report)
    # a replay that could differ: with another noise the same records give another decision
    noisier = {**report, "decision": {**report["decision"], "rounds": [
        {**r, "inputs": {**r["inputs"], "floor_sd": 10 * r["inputs"]["floor_sd"]}} for r in report["decision"]["rounds"]]}}
    assert replayed(noisier)[0][0] != report["decision"]["rounds"][0]["chosen"]
