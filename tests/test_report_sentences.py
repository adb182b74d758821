"""Every sentence the report prints about a choice is true of the numbers report.json records:
each decision's reason read back, clause by clause, against its round's numbers
(`check_sentences`), written as a reading of report.json, not by calling the code that wrote the
sentence. The diagnoses' report.json are checked where they are made (tests/test_replay.py,
tests/test_revisit.py); here, decisions built by hand, including the ones a report once got
wrong: the best predictor refused, an effect that fails its own revisit."""
import re

import pytest

from nodeforce.diagnosis.result import CrossValidation, SensorEvidence
from nodeforce.diagnosis.selection import decide, revisited
from tests.test_decision import BASE, N, SIGMA, Baseline, POLICY, candidate, door, parameter

NUMBER = r"(-?[\d.]+(?:e[+-]?\d+)?)"


def sig(value):
    """A number as the report's sentences print it (three significant figures)."""
    return f"{value:.3g}"


def check_round(r):
    """Each sentence of one round's reason (report.json's `decision.rounds[i]`) against its numbers:
    the candidates that pass, the one that best predicts what no fit read, the fall of J, and,
    for a choice made again, whether the effect stays, is replaced or is removed."""
    reason, verdicts, chosen = r["reason"], r["candidates"], r["chosen"]
    passing = {label: v for label, v in verdicts.items() if v["passes"]}
    for said, of in re.findall(r"(\d+) of (\d+) candidates pass", reason):
        assert (int(said), int(of)) == (len(passing), len(verdicts)), reason
    for of in re.findall(r"[Nn]one of the (\d+) candidates", reason):
        assert int(of) == len(verdicts) and chosen is None, reason
        said = re.search(r"\((\d+) do, and physics or a record they harm refuses each\)", reason)
        assert (int(said[1]) if said else 0) == len(passing), reason
        assert all(v["objection"] for v in passing.values()), reason
    if chosen is not None:
        fall = re.search(rf"lowers the cross-validated J from {NUMBER} to {NUMBER} C2", reason)
        if fall:
            assert fall[1] == sig(r["cv_J_before"]), reason
            assert fall[2] == sig(r["cv_J_before"] - verdicts[chosen]["cv_fall"]), reason
        best = min(passing, key=lambda label: passing[label]["evidence"]) if passing else None
        if "among them it best predicts" in reason:
            assert passing[chosen]["evidence"] == passing[best]["evidence"], reason
            said = re.search(rf"among them it best predicts .*?; J {NUMBER} C2\)", reason)
            assert said[1] == sig(verdicts[chosen]["evidence"]), reason
        other = re.search(rf"among them (\S+) on (\S+) best predicts .*?; J {NUMBER} C2, against its {NUMBER} C2\)"
                          r"(, but is refused)?", reason)
        if other:
            label = f"{other[1]}@{other[2]}"
            assert label != chosen and passing[label]["evidence"] == passing[best]["evidence"], reason
            assert other[3] == sig(verdicts[label]["evidence"]) and other[4] == sig(verdicts[chosen]["evidence"])
            assert bool(other[5]) == bool(verdicts[label]["objection"]), reason
    replaces = r.get("replaces")
    if reason.endswith("it stays."):
        assert replaces is not None and chosen == replaces, reason
    took = re.search(r"it takes the place of (\S+) on (\S+)\.$", reason)
    if took:
        assert replaces == f"{took[1]}@{took[2]}" and chosen not in (None, replaces), reason
    removed = re.search(r"(\S+) on (\S+) is removed: (.*)$", reason)
    assert bool(removed) == bool(r.get("removed")), reason
    if removed:
        label = f"{removed[1]}@{removed[2]}"
        own, refit = verdicts[label], r["refit"]["cv"]["J"]
        assert label == replaces == r["removed"] and chosen is None, reason
        short = re.search(rf"its own cross-validated fall, {NUMBER} C2, is short of the {NUMBER} C2 it needs",
                          removed[3])
        if short:
            assert (short[1], short[2]) == (sig(own["cv_fall"]), sig(own["needed"])) and own["cv_fall"] <= own["needed"]
        else:
            assert own["passes"] and own["objection"] or own["other_days"] <= 0, reason
        J = re.search(rf"cross-validated J {NUMBER} C2, [\d.]+ C, against {NUMBER} C2 with it", removed[3])
        assert (J[1], J[2]) == (sig(refit), sig(refit - own["cv_fall"])), reason
        assert sig(r["cv_J_before"]) == sig(refit), reason  # the revisit read the model without it, refitted


def check_sentences(report):
    """Every round of a report.json's content (`check_round`), and its effects: none removed is
    among them."""
    for r in report["decision"]["rounds"]:
        check_round(r)
    removed = {r["removed"] for r in report["decision"]["rounds"] if r.get("removed")}
    assert not removed & {f"{e['effect']}@{e['target']}" for e in report["effects"]}


def with_sensors(fit, days):
    """The candidate with the other sensors' weighted J over the blocks (C2), 500 readings."""
    return type(fit)(fit.effect, fit.target, fit.parameters, fit.derived, fit.physics, fit.cv,
                     SensorEvidence(list(days), 500, 500.0))


def test_a_round_says_which_candidate_best_predicts_even_when_physics_refuses_it():
    # the window's sun predicts what no fit read far better (J 2.4 against 7.8 a day), but ends
    # on a bound of its range; the air change is chosen, and the report says both
    window = with_sensors(candidate("solar_transmittance", "window",
                                    {"tau": parameter(1.0, 0.01, on_bound=True)}, [1.0] * 4), [1.4] * 4)
    air = with_sensors(candidate("infiltration", "cell", {"n": parameter(0.8, 0.05)}, [3.0] * 4), [4.8] * 4)
    decision = decide([window, air], Baseline(BASE, SIGMA, N), POLICY)
    assert decision.chosen is air
    check_round(decision.to_json())
    assert "among them solar_transmittance on window best predicts" in decision.reason
    assert "but is refused" in decision.reason and "it best predicts" not in decision.reason


def test_a_round_that_chooses_the_best_predictor_says_so_and_its_numbers():
    air = with_sensors(candidate("infiltration", "cell", {"n": parameter(0.8, 0.05)}, [3.0] * 4), [4.8] * 4)
    wall = with_sensors(door([5.0] * 4), [6.0] * 4)
    decision = decide([air, wall], Baseline(BASE, SIGMA, N), POLICY)
    assert decision.chosen is air and "among them it best predicts" in decision.reason
    check_round(decision.to_json())


def test_a_revisit_that_keeps_or_removes_the_effect_says_it_in_the_numbers_it_records():
    envelope = candidate("envelope_conductance", "cell", {"factor": parameter(1.2, 0.05)}, [3.0, 3.0])
    refit = door([4.0, 4.0], factor=1.58)
    kept = revisited(decide([envelope], Baseline([4.0, 4.0], SIGMA, N), POLICY), envelope.label,
                     ["conductivity@door"], {}, refit)
    assert kept.reason.endswith("it stays.")
    check_round(kept.to_json())
    worse = type(envelope)(envelope.effect, envelope.target, envelope.parameters, {}, envelope.physics,
                           CrossValidation([5.0, 5.0], N))
    removal = revisited(decide([worse], Baseline([4.0, 4.0], SIGMA, N), POLICY), envelope.label,
                        ["conductivity@door"], {"conductivity@door": {"factor": parameter(1.58, 0.03)}}, refit)
    check_round(removal.to_json())
    # a sentence that said it stays, of the same numbers, is caught
    with pytest.raises(AssertionError):
        check_round({**removal.to_json(), "reason": removal.reason.split("; envelope_conductance on cell is")[0]
                     + "; it stays."})
