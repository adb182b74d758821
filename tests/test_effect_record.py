"""An effect is one record (`model.effects.Effect`): a toy effect added through its record alone,
no other file touched, is offered to a round, calibrated, judged, reported and written back into
the building file and the EnergyPlus model it was converted from."""
from pathlib import Path

import idfkit
import numpy as np
import pytest

from nodeforce.api import convert_idf
from nodeforce.diagnosis.calibrate import Candidate, calibrate
from nodeforce.diagnosis.candidates import physical
from nodeforce.diagnosis.policy import Policy
from nodeforce.diagnosis.result import Baseline, CrossValidation, Diagnosis, Fit
from nodeforce.diagnosis.selection import blocks, decide
from nodeforce.iotools.energyplus_corrections import write_corrections
from nodeforce.model.case import measured_case
from nodeforce.model.effects import EFFECTS, Effect, Parameter
from nodeforce.model.score import Noise, Objective
from nodeforce.model.synth import pseudo_measurements
from tests.conftest import record_times

CASE600 = Path(__file__).resolve().parents[1] / "examples" / "bestest" / "case600.idf"


def standby_loss():
    """A heater's standby loss the file forgot, P (W) to a zone's air: declared as the zone's
    constant gain, physics the network already has, and written back into an IDF as one."""
    def read(building, target):
        return {"P": float(building.zone(target).internal_gain)}

    def write(data, target, values):
        next(z for z in data["zones"] if z["name"] == target)["internal_gain"] = float(values["P"])
    return Effect("standby_loss", "a heater's standby loss to the air", (Parameter("P", "W", -2000.0, 2000.0),),
                  lambda b: [z.name for z in b.zones], read, write, lambda b, t: (), on_inputs=True,
                  offers=lambda b, zone: [zone], physical=lambda b, t: {"P": (0.0, np.inf)}, source=True,
                  energyplus=lambda writer, target: writer.internal_gain(target))


@pytest.fixture
def toy(monkeypatch):
    monkeypatch.setitem(EFFECTS, "standby_loss", standby_loss())
    return EFFECTS["standby_loss"]


def test_a_toy_effect_added_through_its_record_is_offered_calibrated_judged_reported_and_written_back(
        toy, testcell, weather, tmp_path):
    policy, air = Policy(), testcell.zones[0].air_node
    # offered: every round on the cell's air tries it
    assert ("standby_loss", "cell") in physical(testcell, [], ["cell"], [air], policy)

    # calibrated: the cell with 120 W more to its air than the file says, found on four days (its
    # start, a year of the weather before them, is not the case's own history: within 2 %)
    truth = toy.apply(testcell, "cell", {"P": 120.0})
    case = measured_case(testcell, weather, pseudo_measurements(truth, weather, record_times(4), [air]),
                         burn_in_days=1)
    objective, days = Objective.of(testcell), blocks(len(case.times) - 1, case.burn_in_steps, case.dt, policy)
    candidate = Candidate(testcell, "standby_loss", "cell")
    found, determined, folds = calibrate(candidate, case, objective, days, policy=policy)
    assert found["P"]["value"] == pytest.approx(120.0, rel=0.02) and found["P"]["identifiable"]

    # judged: each day left out predicted far better than by the file, a source within its limits
    declared = objective.measured(case) - candidate.nodes(case, [air], [0.0])
    base = [float(np.nansum(np.square(declared[mask]))) for mask in days]
    left = [f["residuals"] for f in folds]
    fit = Fit("standby_loss", "cell", found, determined, policy.facts(testcell, "standby_loss", "cell"),
              CrossValidation([float(np.nansum(np.square(r))) for r in left],
                              int(sum(np.isfinite(r).sum() for r in left))))
    decision = decide([fit], Baseline(base, 0.01, fit.cv.n), policy)
    assert decision.chosen is fit and "standby_loss on cell" in decision.reason.lower()
    sink = {"P": {"value": -80.0, "std": 2.0, "identifiable": True, "on_bound": False}}
    assert "a negative gain (a heat sink)" in policy.objection(testcell, "standby_loss", "cell", sink)

    # reported: report.json's effects and decision name it
    report = Diagnosis(["cell"], {}, {}, {}, {}, [fit], [decision], "", {}, {}, {}, Noise(0.01, given=True), [],
                       {}, {}, policy=policy).to_json()
    assert report["effects"] == [{"effect": "standby_loss", "target": "cell", "parameters": found}]
    assert report["decision"]["chosen"] == "standby_loss@cell"

    # written back: into the building file, and into the IDF a building was converted from
    after = toy.apply(testcell, "cell", fit.values)
    assert after.to_json()["zones"][0]["internal_gain"] == found["P"]["value"]
    before = convert_idf(CASE600, tmp_path / "600.json")
    corrected = toy.apply(before, "CASE 600 ZONE", {"P": 150.0})
    written = write_corrections(before, corrected, [("standby_loss", "CASE 600 ZONE")], CASE600,
                                tmp_path / "model_after.idf")
    assert written["not_written"] == []
    gain = idfkit.load_idf(str(tmp_path / "model_after.idf")).getobject("OTHEREQUIPMENT", "nodeforce gain CASE 600 ZONE")
    assert float(gain.design_level) == pytest.approx(150.0)


def test_an_effect_whose_record_says_no_energyplus_object_holds_it_is_said_so(monkeypatch, tmp_path):
    from dataclasses import replace
    monkeypatch.setitem(EFFECTS, "standby_loss", replace(standby_loss(), energyplus=None))
    before = convert_idf(CASE600, tmp_path / "600.json")
    corrected = EFFECTS["standby_loss"].apply(before, "CASE 600 ZONE", {"P": 150.0})
    written = write_corrections(before, corrected, [("standby_loss", "CASE 600 ZONE")], CASE600,
                                tmp_path / "model_after.idf")
    assert [line.split(":")[0] for line in written["not_written"]] == ["standby_loss on CASE 600 ZONE"]
