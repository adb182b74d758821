"""A choice made again once the rounds end (`diagnosis.loop.revisit`) on a real record: an effect
that no longer lowers the cross-validated J by its margin, the model's other effects refitted
with it, is removed, and the others are refitted without it."""
import pandas as pd
import pytest

from nodeforce.diagnosis.loop import Made, prepare, revisit
from nodeforce.diagnosis.policy import Policy
from nodeforce.diagnosis.result import CrossValidation, Decision, Fit, Verdict, added_effects
from nodeforce.diagnosis.windows import Record
from nodeforce.model.case import prepare_case
from nodeforce.model.effects import EFFECTS
from nodeforce.model.score import Objective
from nodeforce.model.synth import pseudo_measurements
from nodeforce.runtime.lifetime import InProcess
from tests.conftest import SENSORS
from tests.test_report_sentences import check_round

pytestmark = pytest.mark.slow  # calibrations on a simulated record: not in `make check`

NOISE = 0.1
DOOR = 0.78 / 0.23  # the paper's Table 2 door: wood of 0.78 W/m/K, not 0.23


def chosen(effect, target, values, number, policy, building):
    """A round's `Decision` choosing `effect` at `values` (its verdict passing), and its `Fit`."""
    fit = Fit(effect, target, {k: {"value": v, "std": 0.05 * abs(v), "identifiable": True, "on_bound": False}
                               for k, v in values.items()}, {}, policy.facts(building, effect, target),
              CrossValidation([1.0, 1.0], 1), round=number)
    verdict = Verdict(5.0, 0.5, 1.0, 2.0, 2.0, True, [])
    return fit, Decision(fit, "chosen.", 7.0, 2, 1.0, 1.0, [], [], {fit.label: verdict}, {})


def test_a_gain_the_door_explains_away_is_removed_and_the_door_refitted_alone_finds_the_truth(
        tmp_path, testcell, weather):
    # the truth: the door alone; the model the rounds made: a spurious 15 W gain, then the door
    truth = EFFECTS["conductivity"].apply(testcell, "door", {"factor": DOOR})
    times = pd.date_range("2001-06-10 00:00", periods=8 * 96 + 1, freq="15min", tz="-05:00", name="time")
    measured = pseudo_measurements(truth, weather, times, SENSORS, noise_sd=NOISE, seed=5, history_days=7)
    case = prepare_case(testcell, weather, measured).with_burn_in(1)
    objective, policy = Objective.of(testcell), Policy()
    prepared = prepare(testcell, [Record(case)], [None], objective, tmp_path, "python", NOISE, policy)
    gain, first = chosen("internal_gain", "cell", {"Q": 15.0}, 1, policy, testcell)
    door, second = chosen("conductivity", "door", {"factor": 2.0}, 2, policy, testcell)
    model = prepared.model.adding("internal_gain", "cell", gain.values, None, None)
    model = model.adding("conductivity", "door", door.values, None, None)
    runs = prepared.windows.nodes(model.building, model.bases, [objective.air_nodes])
    model = type(model)(model.building, runs, prepared.windows.metrics(objective, runs), model.bases)
    (tmp_path / "candidates").mkdir()
    made = revisit(prepared, Made([first, second], [gain, door], {}, {}, model), gain, objective,
                   tmp_path / "candidates", 0, InProcess())

    decision = made.decisions[-1]
    assert decision.removes and decision.chosen is None, decision.reason
    verdict = decision.verdicts[gain.label]
    assert not verdict.passes and "internal_gain on cell is removed" in decision.reason
    check_round(decision.to_json())
    # the door refitted without the gain finds the truth, which neither value before held
    kept, = added_effects(made.decisions)
    factor = kept.parameters["factor"]
    assert kept.label == door.label and abs(factor.value - DOOR) < 2 * factor.sd + 0.05 * DOOR
    assert EFFECTS["conductivity"].read(made.model.building, "door")["factor"] == pytest.approx(factor.value)
    # the gain is gone from the model the diagnosis leaves: the file's value again
    assert EFFECTS["internal_gain"].read(made.model.building, "cell") == EFFECTS["internal_gain"].read(testcell, "cell")
    # the decision read the model without it, refitted: the door alone's left-out days
    assert decision.cv_J_before == pytest.approx(decision.refit.cv.J)
    # the model left predicts the validation window, which nothing read, to what the noise and the
    # file's own numerical error leave
    assert made.model.metrics["validation"]["rmse"] < 1.2 * prepared.noise.floor_sd
