"""What the diagnosis makes, as typed records: a candidate's fit (`Fit`, with its cross-validation
and the other sensors' evidence), a round's decision (`Decision`, each candidate's `Verdict`), and
the whole diagnosis (`Diagnosis`), which reports itself (`summary()`, `to_json()`, `plots`).

report.json is `Diagnosis.to_json()`; `Diagnosis.read` gives back every input of each round's
choice from it (tests/test_replay.py recomputes the choices that way). What report.json leaves
out are the residuals themselves (a house's would make it gigabytes): each decision keeps what the
choice read of them, the distances of every two admissible candidates'.
"""
from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np

from nodeforce.diagnosis.estimate import ParameterEstimate, estimates, estimates_json
from nodeforce.diagnosis.policy import Policy
from nodeforce.model.score import Noise


@dataclass
class CrossValidation:
    """A candidate's blocked cross-validation (`diagnosis.selection`): J (C2) on each block left
    out of its fit, the residuals the blocks score (`n`), each fold's parameter values, and the
    left-out residuals themselves (C, every block's in one order; None when read back from
    report.json, which does not keep them)."""
    blocks: list
    n: int
    folds: list = field(default_factory=list)
    left_out: np.ndarray = None

    @property
    def J(self):
        """J (C2) over every block left out."""
        return float(sum(self.blocks))

    @property
    def rmse(self):
        """The root mean square (C) of the left-out residuals."""
        return float(np.sqrt(self.J / self.n))

    def to_json(self):
        return {"blocks": [float(b) for b in self.blocks], "J": self.J, "n": self.n, "rmse": self.rmse,
                "folds": self.folds}

    @classmethod
    def of_json(cls, d):
        return cls(d["blocks"], d["n"], d.get("folds", []))


@dataclass
class OwnSensors:
    """A component candidate's own sensors (the nodes of its component that are measured): their
    J (C2) per block under the model it would be added to (`before`) and under the candidate
    (`after`), unweighted, the readings (`n`), and the root mean square (C) of the file's own
    numerical error there (`numerical`), which with the noise is what a right model leaves."""
    before: list
    after: list
    n: int
    numerical: float

    def to_json(self):
        return asdict(self)


@dataclass
class SensorEvidence:
    """What a candidate fitted to the air alone predicts of the other sensors (a wall's surface, a
    neighbouring zone's air) over the blocks: their weighted J (C2) per block, the readings (`n`),
    what the noise counts of them (`n_weighted`, sum of the squared weights), the weighted
    residuals (C, None when read back from report.json), and for a component's candidate, its
    own sensors (`OwnSensors`, None for another)."""
    blocks: list = field(default_factory=list)
    n: int = 0
    n_weighted: float = 0.0
    residuals: np.ndarray = None
    own: OwnSensors = None

    @property
    def J(self):
        """The weighted J (C2) over every block."""
        return float(np.sum(self.blocks))

    def to_json(self):
        return {"blocks": [float(b) for b in self.blocks], "J": self.J, "n": self.n, "n_weighted": self.n_weighted,
                **({"own": self.own.to_json()} if self.own else {})}

    @classmethod
    def of_json(cls, d):
        return cls(d["blocks"], d["n"], d["n_weighted"], own=OwnSensors(**d["own"]) if d.get("own") else None)


@dataclass
class Fit:
    """One candidate effect calibrated on the calibration window (`diagnosis.calibrate`): its
    parameters ({name: `ParameterEstimate`}, made so from report.json's dicts), what the data determine
    besides (`derived`), what the building says of it (`physics`, `Policy.facts`), its metrics on
    both windows ({"calibration", "validation"}), its cross-validation, the other sensors'
    evidence, the round it was tried in and the effects it was added on top of (labels)."""
    effect: str
    target: str
    parameters: dict
    derived: dict
    physics: dict
    cv: CrossValidation
    sensors: SensorEvidence = field(default_factory=SensorEvidence)
    metrics: dict = field(default_factory=dict)
    round: int = 1
    on_top_of: tuple = ()

    def __post_init__(self):
        self.parameters = estimates(self.parameters)

    @property
    def label(self):
        """"effect@target", the key of the decision, the runs and the sensitivity."""
        return f"{self.effect}@{self.target}"

    @property
    def values(self):
        """{name: value} of the calibrated parameters."""
        return {name: p.value for name, p in self.parameters.items()}

    def evidence(self):
        """Per-block J (C2) the choice reads (`diagnosis.selection`): the objective air on each
        block left out of its fit and the other sensors' weighted J over the same blocks, which no
        fit read."""
        return np.asarray(self.cv.blocks, dtype=float) + np.asarray(self.sensors.blocks or 0.0, dtype=float)

    def residuals(self):
        """The residuals (C) the evidence is made of, the air's left out then the other sensors',
        None where not kept."""
        if self.cv.left_out is None:
            return None
        return np.concatenate([np.asarray(self.cv.left_out, dtype=float),
                               np.asarray(self.sensors.residuals if self.sensors.residuals is not None else [],
                                          dtype=float)])

    def effect_json(self, keys=("effect", "target", "parameters")):
        """The effect as report.json's `effects` and `effect` say it."""
        return {key: estimates_json(self.parameters) if key == "parameters" else getattr(self, key) for key in keys}

    def to_json(self):
        return {"effect": self.effect, "target": self.target, "parameters": estimates_json(self.parameters),
                "derived": self.derived,
                "physics": self.physics, **self.metrics, "cv": self.cv.to_json(), "sensors": self.sensors.to_json(),
                "round": self.round, **({"on_top_of": list(self.on_top_of)} if self.on_top_of else {})}

    @classmethod
    def of_json(cls, d):
        return cls(d["effect"], d["target"], d["parameters"], d["derived"], d["physics"],
                   CrossValidation.of_json(d["cv"]), SensorEvidence.of_json(d["sensors"]),
                   {w: d[w] for w in ("calibration", "validation") if w in d}, d["round"], tuple(d.get("on_top_of", ())))


@dataclass
class Verdict:
    """One candidate's test in a round (`diagnosis.selection.candidate_test`): its cross-validated
    fall of J (C2) and the fall's standard error, what it needs, what the days other than its best
    gain, its evidence (C2), whether it passes, the records it harms, the objection of physics
    (None if none), and its own sensors' test, whether it passes by them; for a candidate whose
    values are loose, how the choice weighed it (`selection.weigh_loose`: {"established": the
    parameter whose interval excludes no effect or None, "against": the label of the best
    candidate whose values are tight, "ahead": how much lower its
    evidence is (C2), "se": the standard error of that (C2), "needed" (C2), "admitted"})."""
    cv_fall: float
    cv_se: float
    needed: float
    other_days: float
    evidence: float
    passes: bool
    harms: list
    objection: str = None
    own: dict = None  # its own sensors' test (`selection.own_test`), None without
    passes_by_own: bool = False  # it passes on them (the air no worse than the noise's margin)
    weighed: dict = None  # its loose values weighed against what it predicts (`selection.weigh_loose`)

    def to_json(self):
        out = asdict(self)
        if self.weighed is None:  # a candidate whose values are tight, as before there was a weighing
            del out["weighed"]
        return out


@dataclass
class Baseline:
    """What a round's choice reads besides its candidates' fits (`diagnosis.selection.decide`),
    as a decision's `inputs` keep it in report.json: the per-block J (C2) of the model the
    candidates would be added to, the air sensors' noise sd (C; what a fixed pair's difference
    moves by, `selection.noise_difference`), the residuals the blocks score, the records the
    blocks come from (`selection.harmed`, where there are several), the sd (C) of what a right
    model of the file leaves, the noise and the file's own numerical error
    (`model.score.Noise.floor_sd`, the yardstick of a fall of J; sigma if None), the distance of
    every two admissible candidates' residuals ({label: {label: C}}, computed from the residuals
    if None), and whether the round runs only because a component's own sensors disagree, the
    air's error left being the noise's (`Policy.at_noise`): a candidate then passes on its own
    sensors alone; and the start as a candidate (`selection.start_test`), where a record's
    history leaves a slow mode's start unknown and no earlier round chose it: the per-block J
    (C2) of the model with each record's start fitted on its other blocks
    (`Windows.block_J`), None otherwise."""
    blocks_before: list
    sigma: float
    n: int
    groups: list = ()
    floor_sd: float = None
    distances: dict = None
    air_at_noise: bool = False
    start: list = None

    def to_json(self):
        return {"blocks_before": self.blocks_before, "sigma": self.sigma, "floor_sd": self.floor_sd, "n": self.n,
                "groups": self.groups, "distances": self.distances, "air_at_noise": self.air_at_noise,
                **({"start": self.start} if self.start is not None else {})}

    @classmethod
    def of_json(cls, d):
        return cls(d["blocks_before"], d["sigma"], d["n"], d["groups"], d["floor_sd"], d["distances"],
                   d.get("air_at_noise", False), d.get("start"))


@dataclass
class Decision:
    """One round's decision (`diagnosis.selection.decide`): the candidate chosen (None), the reason
    in words, the model's cross-validated J (C2) over its blocks, the noise's margin (C2), the
    standard errors asked, the suggestions physics refused, the candidates the data cannot tell
    from the chosen (labels), every candidate's verdict by label, what the steps read besides the
    candidates (`inputs`: the model's per-block J, sigma, floor_sd, n, groups, distances), and
    what the round cost. A decision made once the rounds end, on an effect an earlier round chose
    (`diagnosis.loop.revisit`), names it (`replaces`), and where another takes its place, the
    values the model's other effects take refitted with that one (`refitted`, {label: {name:
    {"value", "std", ...}}}), judged against `refit`, the fit of the model's other effects
    refitted together without it (the first with the others beside it: its cross-validation is
    the model's without it); where none is chosen, itself included, the effect is removed, the
    others at the values `refit` gave them, which `refitted` holds. Where the start was a
    candidate (`Baseline.start`), `start` holds its test (`selection.start_test`) and, once the
    loop has fitted it, its amplitudes (`diagnosis.loop.start_found`); where it is chosen
    (`starts`), no effect is added and the later rounds fit it with every candidate."""
    chosen: Fit
    reason: str
    cv_J_before: float
    blocks: int
    noise_margin: float
    standard_errors: float
    suggestions: list
    indistinct: list
    verdicts: dict
    inputs: dict
    cost: dict = None
    replaces: str = None
    refitted: dict = None
    refit: Fit = None
    start: dict = None

    @property
    def starts(self):
        """Whether the round chose the start, the records' slow modes' amplitudes, and no effect."""
        return bool(self.start and self.start["chosen"])

    @property
    def changes_model(self):
        """Whether the decision adds an effect to the model: a round's choice, or a revisit's that
        takes another's place."""
        return self.chosen is not None and self.chosen.label != self.replaces

    @property
    def removes(self):
        """Whether the decision removes the effect it revisits (`replaces`): no candidate, itself
        included, lowers the cross-validated J of the model without it by its margin, or physics
        refuses each that does."""
        return self.replaces is not None and self.chosen is None

    def to_json(self):
        return {"chosen": self.chosen.label if self.chosen else None, "reason": self.reason,
                "cv_J_before": self.cv_J_before, "blocks": self.blocks, "noise_margin": self.noise_margin,
                "standard_errors": self.standard_errors, "suggestions": self.suggestions,
                "indistinct": self.indistinct, "candidates": {k: v.to_json() for k, v in self.verdicts.items()},
                "inputs": self.inputs, **({"cost": self.cost} if self.cost is not None else {}),
                **({"replaces": self.replaces, "refitted": self.refitted, "refit": self.refit.to_json()}
                   if self.replaces else {}),
                **({"removed": self.replaces} if self.removes else {}),
                **({"start": self.start} if self.start is not None else {})}

    @classmethod
    def of_json(cls, d, chosen):
        """The decision report.json records, `chosen` its chosen candidate's `Fit` (None)."""
        return cls(chosen, d["reason"], d["cv_J_before"], d["blocks"], d["noise_margin"], d["standard_errors"],
                   d["suggestions"], d["indistinct"], {k: Verdict(**v) for k, v in d["candidates"].items()},
                   d["inputs"], d.get("cost"), d.get("replaces"), d.get("refitted"),
                   Fit.of_json(d["refit"]) if d.get("refit") else None, d.get("start"))


def added_effects(decisions):
    """The effects the `decisions` add, in order (their `Fit`s): each round's choice, where a
    later decision (`Decision.replaces`) put another in its place, that one, and the others with
    the values refitted with it; where a later decision removed one (`Decision.removes`), the
    others with the values refitted without it."""
    out = []
    for d in decisions:
        if d.replaces is None:
            out += [d.chosen] if d.changes_model else []
        elif d.changes_model or d.removes:
            out = [d.chosen if a.label == d.replaces else
                   replace(a, parameters={**a.parameters, **d.refitted.get(a.label, {})})
                   for a in out if not (d.removes and a.label == d.replaces)]
    return out


def last_change(decisions):
    """The `Fit` of the last of the `decisions` that changed the model (a round's choice, one
    that took another's place, or the refit of the effects left where one was removed), whose
    `derived` are those of the model they leave; None."""
    changed = [d.refit if d.removes else d.chosen for d in decisions if d.changes_model or d.removes]
    return changed[-1] if changed else None


@dataclass
class RecordOutcome:
    """One record of a diagnosis of several: its name, measurement file, windows (`period`), the
    objective's metrics before and after on its windows, its own forcing search and, where it runs
    under its own protocol, its corrected building file."""
    name: str
    measurements: str
    period: dict
    before: dict
    after: dict
    localization: dict
    building_after: str = None

    def to_json(self):
        return {"name": self.name, "measurements": self.measurements, "period": self.period, "before": self.before,
                "after": self.after, "localization": self.localization,
                **({"building_after": self.building_after} if self.building_after else {})}

    @classmethod
    def of_json(cls, d):
        return cls(**d)


@dataclass
class LaterRecord:
    """A later record of the building, which no fit, choice or cross-validation read, scored after
    the rounds as `nodeforce compare` scores it (`diagnosis.compare`): its name, measurement
    file, span (`record`, [start, end]), the first time scored (after its burn-in), and the
    objective's metrics (`Objective.metrics`: RMSE, mean, sd, n, C, overall and per zone) of the
    building as written (`before`) and as corrected (`after`)."""
    name: str
    measurements: str
    record: list
    scored_from: str
    before: dict
    after: dict

    def to_json(self):
        return asdict(self)

    @classmethod
    def of_json(cls, d):
        return cls(**d)


@dataclass
class Diagnosis:
    """A whole diagnosis (`nodeforce.diagnose`).

    objective : the objective's zone names
    period : the first record's windows and blocks (`diagnosis.windows.period`)
    before, after : the objective's metrics ({"calibration", "validation"}, each per zone too) of
        the building as described and as corrected, every record's windows together
    localization : the forcing search's result on every record's calibration window (locate.json)
    candidates : every candidate tried, every round's (`Fit`)
    rounds : each round's `Decision`
    structure_left : what the residual left after the last round follows, in words
    heat_loss : the heat loss coefficient as described and as corrected (`diagnosis.loss`)
    residuals : the validation residual's statistics before and after (`diagnosis.residuals`)
    sensitivity : the Morris screening of each added effect's parameters, by label
    noise : the air sensors' noise and the file's numerical error (`model.score.Noise`)
    assumptions, node_names : what the cases assumed; the building's node names by id
    artifacts : the files written (paths)
    records : each record's outcome, where there are several (`RecordOutcome`)
    worsened_phases, phases : the phases an added effect makes worse; every model's error per phase
    reference : another model's error, for scale; energyplus : the corrections written back
    later : each later record's score as written and as corrected (`LaterRecord`), read by nothing else
    policy : the `diagnosis.policy.Policy` the choices were made under (report.json's `policy`);
        a report without one was made under the default
    start : where a round chose the start, what it is fitted to the model as corrected
        (`diagnosis.loop.start_found`), None otherwise
    """
    objective: list
    period: dict
    before: dict
    after: dict
    localization: dict
    candidates: list
    rounds: list
    structure_left: str
    heat_loss: dict
    residuals: dict
    sensitivity: dict
    noise: Noise
    assumptions: list
    node_names: dict
    artifacts: dict
    records: list = ()
    worsened_phases: list = None
    phases: list = None
    reference: dict = None
    energyplus: dict = None
    later: list = ()
    policy: Policy = field(default_factory=Policy)
    start: dict = None

    @property
    def added(self):
        """The effects added, in order (their `Fit`s: `added_effects`)."""
        return added_effects(self.rounds)

    @property
    def plots(self):
        """The PNG figures written beside report.json."""
        return [Path(p) for p in self.artifacts.get("plots", ())]

    def decision_json(self):
        """report.json's `decision`: the first round's record with the last effect chosen, every
        round's reason, the rounds, what is left and the phases made worse."""
        rounds = [d.to_json() for d in self.rounds]
        added = self.added
        out = {**rounds[0], "chosen": added[-1].label if added else None,
               "reason": " ".join((f"Round {i + 1}: " if d.replaces is None else "Once the rounds end, ") + d.reason
                                  if len(rounds) > 1 else d.reason
                                  for i, d in enumerate(self.rounds)),
               "rounds": rounds, "structure_left": self.structure_left}
        if self.worsened_phases is not None:
            out["worsened_phases"] = self.worsened_phases
            if self.worsened_phases:
                out["reason"] += (" It lowers the total error but makes the phase " + "; ".join(
                    f"{w['phase']} worse ({w['before']:.3f} C -> {w['after']:.3f} C)" for w in self.worsened_phases)
                    + ", which the total hides.")
        return out

    def to_json(self):
        """report.json's content."""
        added = self.added
        out = {"period": self.period, "objective": list(self.objective), "before": self.before,
               "localization": self.localization, "candidates": [c.to_json() for c in self.candidates],
               "effects": [a.effect_json() for a in added], "decision": self.decision_json(),
               "effect": (added[-1].effect_json(("effect", "target", "parameters", "derived")) if added
                          else {"effect": "none", "target": None, "parameters": {}}),
               "after": self.after, "heat_loss_coefficient": self.heat_loss, "assumptions": list(self.assumptions),
               "residuals": self.residuals, "sensitivity": self.sensitivity, "noise_sigma": self.noise.sigma,
               "noise": self.noise.to_json(), "node_names": self.node_names, "artifacts": self.artifacts,
               "policy": self.policy.to_json()}
        if self.records:
            out["records"] = [r.to_json() for r in self.records]
        if self.later:
            out["later"] = [r.to_json() for r in self.later]
        for key in ("reference", "energyplus", "phases", "start"):
            if getattr(self, key):
                out[key] = getattr(self, key)
        return out

    def summary(self):
        """The first screen: where the fault is, what was added and what the data determine of
        it, the error before and after on the validation window, the heat loss coefficient, what
        is left."""
        from nodeforce.diagnosis.report import terminal_summary  # the report reads report.json's content
        return terminal_summary(self.to_json())

    def write(self, path):
        """Write report.json."""
        Path(path).write_text(json.dumps(self.to_json(), indent=2, default=_plain) + "\n")

    def replay(self):
        """Each round's `Decision` recomputed from what the diagnosis holds alone, under the policy
        it was made with (`policy`, `diagnosis.selection.decide`): the round's candidates' fits
        and what its decision read besides (`Decision.inputs`). On a diagnosis read from
        report.json it is the check that the report holds every input of the choice, whatever
        the code's default policy has become since."""
        from nodeforce.diagnosis.selection import decide, revisited  # the choice reads these records
        out = []
        for number, recorded in enumerate(self.rounds, start=1):
            tried = [c for c in self.candidates if c.round == number]
            decision = decide(tried, Baseline.of_json(recorded.inputs), self.policy)
            if recorded.replaces:  # a choice made again, the others refitted with each candidate
                decision = revisited(decision, recorded.replaces, list(tried[0].on_top_of), recorded.refitted,
                                     recorded.refit)
            if decision.start is not None and recorded.start and "records" in recorded.start:
                # the amplitudes the loop fitted are said beside the start's test, not read by the choice
                decision.start["records"] = recorded.start["records"]
            out.append(decision)
        return out

    @classmethod
    def read(cls, path):
        """The diagnosis a report.json holds: every input of each round's choice but the residuals
        themselves (each decision keeps their distances)."""
        d = json.loads(Path(path).read_text())
        candidates = [Fit.of_json(c) for c in d["candidates"]]
        by_round = {(c.round, c.label): c for c in candidates}
        rounds = [Decision.of_json(r, by_round.get((number, r["chosen"])))
                  for number, r in enumerate(d["decision"]["rounds"], start=1)]
        return cls(d["objective"], d["period"], d["before"], d["after"], d["localization"], candidates, rounds,
                   d["decision"]["structure_left"], d["heat_loss_coefficient"], d["residuals"], d["sensitivity"],
                   Noise.of_json(d["noise"]), d["assumptions"], d["node_names"], d["artifacts"],
                   [RecordOutcome.of_json(r) for r in d.get("records", ())], d["decision"].get("worsened_phases"),
                   d.get("phases"), d.get("reference"), d.get("energyplus"),
                   [LaterRecord.of_json(r) for r in d.get("later", ())],
                   Policy.of_json(d["policy"]) if "policy" in d else Policy(), d.get("start"))


def _plain(value):
    """numpy scalars as plain JSON numbers."""
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON")
