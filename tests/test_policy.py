"""The policy is passed in and recorded: report.json carries every value of the `Policy` the
choices were made under, and `Diagnosis.replay` judges under that one, whatever the code's
default has become since."""
import dataclasses
import json
import pickle

from nodeforce.diagnosis.policy import Policy
from nodeforce.diagnosis.result import Baseline, CrossValidation, Diagnosis, Fit
from nodeforce.diagnosis.selection import decide
from nodeforce.model.building_file import parse_building
from nodeforce.model.score import Noise, Yardstick
from tests.conftest import DATA

CELL = parse_building(json.loads((DATA / "testcell_miami.json").read_text()))
N, SIGMA, BASE = 192, 0.1, [10.0, 10.0, 10.0, 10.0]


def door(policy):
    """The door's conductivity, leaving J of 2 C2 on each of four left-out days where the model
    leaves 10 (0.1 C of noise on 192 residuals)."""
    return Fit("conductivity", "door", {"factor": {"value": 3.0, "std": 0.2, "identifiable": True, "on_bound": False}},
               {}, policy.facts(CELL, "conductivity", "door"), CrossValidation([2.0, 2.4, 1.9, 2.3], N))


def test_the_policy_goes_through_json_and_pickle_unchanged():
    policy = Policy(top_components=5, yardstick=Yardstick(noise_sds=4.0))
    assert Policy.of_json(json.loads(json.dumps(policy.to_json()))) == policy
    assert pickle.loads(pickle.dumps(policy)) == policy  # as the workers receive it
    assert Policy.of_json({}) == Policy()  # a value a report does not hold is the default


def with_default(monkeypatch, name, value):
    """The code's `Policy()` with `name` at `value`, as if its default had been edited."""
    names = [f.name for f in dataclasses.fields(Policy)]
    defaults = list(Policy.__init__.__defaults__)
    defaults[names.index(name)] = value
    monkeypatch.setattr(Policy.__init__, "__defaults__", tuple(defaults))
    assert getattr(Policy(), name) == value


def test_a_report_replays_under_the_policy_it_was_made_with_after_the_code_s_default_changes(tmp_path, monkeypatch):
    made_under = Policy()
    fit = door(made_under)
    decision = decide([fit], Baseline(BASE, SIGMA, N), made_under)
    assert decision.chosen is not None
    diagnosis = Diagnosis(["cell"], {}, {}, {}, {}, [fit], [decision], "", {}, {}, {}, Noise(SIGMA, given=True), [], {}, {},
                          policy=made_under)
    diagnosis.write(tmp_path / "report.json")
    assert json.loads((tmp_path / "report.json").read_text())["policy"] == made_under.to_json()

    # the code's default yardstick changes: a fall must now beat a thousand sds of the noise's J
    with_default(monkeypatch, "yardstick", Yardstick(noise_sds=1000.0))
    read = Diagnosis.read(tmp_path / "report.json")
    assert read.policy == made_under != Policy()
    [again] = read.replay()
    assert again.to_json() == decision.to_json() and again.chosen.label == "conductivity@door"
    # judged under the new default, the same report would give another answer
    assert decide(read.candidates, Baseline.of_json(read.rounds[0].inputs), Policy()).chosen is None


def test_a_fits_parameters_are_estimates_written_as_report_json_wrote_them():
    """`Fit.parameters` are `ParameterEstimate`s, made from report.json's dicts and written back
    as they were, key for key and in order: an old report reads and replays unchanged."""
    from nodeforce.diagnosis.estimate import ParameterEstimate
    held = {"value": 24.0, "std": 0.5, "identifiable": False, "on_bound": False, "prior": "the site's ground temperature"}
    fitted = {"value": 0.8, "std": 0.1, "identifiable": True, "on_bound": True}
    fit = Fit("ground_coupling", "floor", {"U": fitted, "T_ground": held}, {}, {}, CrossValidation([1.0, 2.0], 96))
    assert fit.parameters["U"] == ParameterEstimate(0.8, 0.1, True, True)
    assert fit.parameters["T_ground"].prior == held["prior"] and fit.values == {"U": 0.8, "T_ground": 24.0}
    written = json.loads(json.dumps(fit.to_json()))
    assert written["parameters"] == {"U": fitted, "T_ground": held}
    assert [list(p) for p in written["parameters"].values()] == [list(fitted), list(held)]
    assert Fit.of_json(written) == fit and fit.effect_json()["parameters"] == written["parameters"]
