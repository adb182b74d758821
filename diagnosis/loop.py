"""`nodeforce diagnose`: from the residual to the missing effect, added, calibrated, and judged
on data the calibration did not see.

1. The record is split by time into a calibration window and a later validation window. The
   record's first days are a burn-in (docs/model.md: every measured node forced, not scored), so
   the walls start from what the sensors saw rather than from the warm-up's replay of the first
   day, which a record with real history does not match; the calibration window's scored steps
   are cut into blocks of whole days for the cross-validation (`diagnosis.selection`); the
   windows, and the scores read on them, are `diagnosis.windows`.
2. Before: the building as described, simulated through its FMU; metrics on both windows, per
   objective zone and together.
3. The forcing search (`ga.locate`) on the calibration window: which nodes it locates, and per
   component the share of J above the noise its forcing removes (the evidence).
4. Rounds. Each calibrates every physical candidate (`diagnosis.candidates.physical`: every zone
   effect of the objective zones, the component effects of the components the evidence ranks
   highest and of those no sensor sits in) on the direct model, the candidates in the worker
   processes that ran the forcing search or on a Dask cluster's workers (`scheduler`), once
   on the whole calibration window and once per block left out
   (`diagnosis.calibrate`); where none brings the error to the noise, the shapes the residual's
   statistics point at too (`diagnosis.candidates.shapes`). One rule chooses
   (`diagnosis.selection.decide`: blocked cross-validation, the one-standard-error rule, the
   objections of physics), against the model the earlier rounds made. Rounds go on while the
   error left is above the noise, at the air or at a component's own sensors (a second fault
   the air no longer points at), and a candidate passes. Once they end, each earlier choice is
   chosen again, the model's other effects refitted together with every candidate (`revisit`):
   another may take its place. The validation window plays no part in any choice: its before
   and after are an honest estimate. The decision of every round, its margins, its cost and its
   reason go into report.json, which the report reads.
5. The chosen model is built as an FMU and written (`model_after.fmu`, `building_after.json`);
   every candidate's building file is written declaring its calibrated effect
   (`candidates/<effect>@<target>.json`, a later round's in `candidates/round<n>/`, a revisit's in
   `candidates/revisit<n>/`).
6. The residual of the first objective zone on the validation window, before and after, is
   described (`diagnosis.residuals`): is it white, and which input or time of day does it follow.
7. Given the experiment's phases, every model is scored on each (`diagnosis.phases`), and an
   added effect that makes a phase worse is flagged in the decision's reason.
8. Given later records of the building (`later`), which no stage above reads, the building as
   written and as corrected are scored on each as `nodeforce compare` scores them: whether the
   correction holds beyond the records it was fitted and chosen on.
"""
import json
import os
import sys
import time
from contextlib import nullcontext
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd
from tqdm import tqdm

from nodeforce.runtime import lifetime
from nodeforce.runtime.cluster import Cluster
from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.diagnosis.assess import RoundInputs, assess, protocols
from nodeforce.diagnosis.calibrate import Candidate
from nodeforce.diagnosis.candidates import physical, shaped_inputs, shapes
from nodeforce.diagnosis.compare import compare
from nodeforce.diagnosis.loss import heat_loss
from nodeforce.diagnosis.report import write_report
from nodeforce.diagnosis.phases import phase_errors, worsened
from nodeforce.diagnosis.residuals import diagnostics as residual_diagnostics
from nodeforce.diagnosis.policy import Policy
from nodeforce.diagnosis.result import (Baseline, CrossValidation, Diagnosis, Fit, LaterRecord, OwnSensors,
                                        RecordOutcome, SensorEvidence, added_effects, last_change)
from nodeforce.diagnosis.selection import decide, revisited
from nodeforce.diagnosis.sensitivity import sensitivity
from nodeforce.diagnosis.windows import Beside, Record, Windows, period
from nodeforce.fmu_build.build import build_fmu
from nodeforce.iotools.energyplus_corrections import idf_of, write_corrections
from nodeforce.ga.locate import Execution, SearchSettings, check_measured, evaluator_kind, locate
from nodeforce.model.case import local_times
from nodeforce.model.effects import EFFECTS, member_nodes
from nodeforce.model.errors import InputError
from nodeforce.model.score import Noise
from nodeforce.model.site import MOVED, at_site


@dataclass
class Model:
    """A model of the loop: its building, its objective air simulated over each whole record
    (`runs`), its metrics on every record's windows together, and per record the building it
    runs under that record's protocol (None: `building`)."""
    building: object
    runs: list
    metrics: dict
    bases: list

    def adding(self, effect, target, values, runs, metrics, refitted=None):
        """The model with the effect at `values` added to its building and to every record's, and
        the effects it holds that were `refitted` with it ({label: {name: value}}) at their new values."""
        changes = [(effect, target, values)] + [(*label.split("@", 1), v) for label, v in (refitted or {}).items()]

        def changed(building):
            for e, t, v in changes:
                building = EFFECTS[e].apply(building, t, v)
            return building
        return Model(changed(self.building), runs, metrics, [None if b is None else changed(b) for b in self.bases])

    def without(self, effect, target, declared, windows, objective):
        """The model with `effect` on `target` back at the value of the building as `declared` (the
        file's, before any round), the others as they are, run over each record."""
        def reverted(building, original):
            return EFFECTS[effect].apply(building, target, EFFECTS[effect].read(original, target))
        bases = [None if b is None else reverted(b, declared.bases[i] or declared.building)
                 for i, b in enumerate(self.bases)]
        building = reverted(self.building, declared.building)
        runs = windows.nodes(building, bases, [objective.air_nodes] * len(windows.cases))
        return Model(building, runs, windows.metrics(objective, runs), bases)


def assess_all(inputs, pairs, folder, runner):
    """Each (effect, target) added to the model of the round's `inputs` (`assess.RoundInputs`),
    calibrated on every record's calibration window (t_0..t_k) with a fold per block, and run
    over each record, where `runner` runs tasks (this process, `lifetime.InProcess`; the
    command's `lifetime.Workers`; a Dask `runtime.cluster.Cluster`'s workers), each
    candidate's building file written in `folder`: their `Assessed`, in the order of `pairs`.
    The inputs' `sigma`, the sensors' noise (C), is what a component's own nodes are weighed
    against in its fit (`calibrate.own_weights`); their `beside`, the effects the model holds
    refitted together with each candidate, those of their parameters `held` kept as they are
    (`calibrate.Candidate`)."""
    with tqdm(total=len(pairs), desc="calibrating candidate effects", unit="candidate",
              disable=not sys.stderr.isatty()) as bar:
        assessed = runner.map_shared(assess, inputs, pairs, done=bar.update)
    for (effect, target), a in zip(pairs, assessed):
        (folder / f"{effect}@{target}.json").write_text(json.dumps(a.building, indent=2) + "\n")
    return list(assessed)


def fits_of(model, base, pairs, assessed, windows, inputs, number=1, on_top_of=()):
    """The candidates' `Fit`s and their `Model`s by label, from their `Assessed`: what each
    predicts of the air left out and of the other sensors over the blocks, each sensor weighted
    by the least misfit the model or any of these candidates leaves there
    (`Windows.sensor_weights`), and of its own component's sensors (`OwnSensors`); `base`: the
    model's other sensed nodes (`Windows.sensed_by`); `inputs`: the round's
    (`assess.RoundInputs`: its objective, the air sensors' noise `sigma`, C); `number`: the
    round; `on_top_of`: the labels of the effects `model` holds."""
    objective, sigma = inputs.objective, inputs.sigma
    n = windows.scored()
    sensed = {i for ids in windows.sensors for i in ids}
    weights = windows.sensor_weights([base] + [a.sensed for a in assessed], sigma)
    results, models = [], {}
    for (effect, target), a in zip(pairs, assessed):
        metrics = windows.metrics(objective, a.runs)
        sensor_blocks, sensor_residuals, readings, counted = windows.sensor_scores(a.sensed, weights)
        physics = windows.policy.facts(model.building, effect, target, sensed)
        fit = Fit(effect, target, a.parameters, a.determined, physics,
                  CrossValidation([float(np.nansum(np.square(f["residuals"]))) for f in a.folds], n,
                                  [f["values"] for f in a.folds],
                                  # each block's left-out residuals, in one order for every candidate
                                  np.concatenate([f["residuals"][np.isfinite(f["residuals"])] for f in a.folds])),
                  # the other sensors over the blocks, which no fit read
                  SensorEvidence([float(v) for v in sensor_blocks], readings, counted, sensor_residuals,
                                 own_sensors(model.building, target, windows, base, a.sensed)
                                 if physics["sensed"] else None),
                  metrics, number, tuple(on_top_of))
        models[fit.label] = model.adding(effect, target, fit.values, a.runs, metrics,
                                         {label: {name: p["value"] for name, p in refitted.items()}
                                          for label, refitted in (a.beside or {}).items()})
        results.append(fit)
    return results, models


def own_sensors(building, component, windows, base, sensed):
    """`OwnSensors` of a candidate on `component` (or a group of them, `model.effects.members`):
    its own sensors' J (C2) per block under the model (its other sensed nodes `base`) and under
    the candidate (`sensed`), unweighted, and the file's numerical error there
    (`Windows.own_numerical`)."""
    columns = windows.own_columns(set(member_nodes(building, component)))
    before, n = windows.own_J(base, columns)
    after, _ = windows.own_J(sensed, columns)
    return OwnSensors([float(v) for v in before], [float(v) for v in after], n, windows.own_numerical(columns))


def diagnose(building, records, workdir, objective, *, search=SearchSettings(), execution=Execution(),
             beside=Beside(), policy=None):
    """Run the whole loop, its stages in order (`prepare`, `localise`, `rounds`, `write`); write the
    artifacts in `workdir`; return the `Diagnosis` (report.json is its `to_json()`).

    `records` is a Case (one record, its windows `Record`'s defaults) or a list of `Record`s of
    the same building, each with its own windows and phases: the
    fits minimise the sum of every record's calibration J, the choice reads every record's
    blocks, and a candidate that harms one record is refused (`selection.decide`). The forcing
    search reads every record's calibration window together, then, reported, each one's alone,
    under `search` (`ga.locate.SearchSettings`: its seed, which the rounds' screening reads too,
    its GA settings, the FMUs it drives, and `noise`, the air sensors' noise sd (C) if the user
    knows it, else it is estimated from every record's air). `execution` (`ga.locate.Execution`): the FMUs of the
    model before and after, run and written, and where the work runs: a Dask scheduler's workers
    (`runtime.cluster`; an unreachable one is an InputError before any work) or `workers`
    processes. `beside` (`windows.Beside`): its `reference` ({"label", "rmse": {phase: K}}),
    another model's error, is reported for scale; its `later`: `Record`s of the same building
    under the building file's protocol, read from their files (`nodeforce.read_record`), which
    nothing but the final comparison reads (`scored_later`): no fit, no choice, no
    cross-validation. `policy`: the `diagnosis.policy.Policy` every choice
    is made under (default `Policy()`), recorded in report.json. The loop runs the building at
    the site its records' weather gives (`run_site`); the files it writes back keep the
    building file's site."""
    policy = Policy() if policy is None else policy
    later = list(beside.later)
    if not isinstance(records, (list, tuple)):
        records = [Record(records, name="measurements")]
    names = [r.name for r in [*records, *later]]
    for r in [*records, *later]:
        if names.count(r.name) > 1:
            raise InputError(r.source, "name", f"two records are named {r.name!r}: each needs its own name")
        check_measured(objective, r.case, r.source)
    given, building = building, run_site(building, records)
    for r in later:
        if r.read_from is None or protocol(building, r) is not None:
            raise InputError(r.source, "later", f"record {r.name}: a later record is read from its files "
                                                f"(read_record) for the building diagnosed, {building.source}")
    bases = [protocol(building, r) for r in records]
    fmu_kind = evaluator_kind(execution.fmu_kind, [building, *filter(None, bases)])
    # one set of workers for the search and the rounds, started first: their imports overlap `prepare`
    count = execution.workers or os.cpu_count()
    with Cluster(execution.scheduler) if execution.scheduler is not None else \
            lifetime.worker_pool(count) if count > 1 else nullcontext(lifetime.InProcess()) as runner:
        prepared = prepare(building, records, bases, objective, workdir, fmu_kind, search.noise, policy)
        settings = replace(search, noise=prepared.noise.sigma if prepared.noise.given else None)
        located = localise(building, prepared, objective, workdir, settings, Execution(workers=runner))
        made = rounds(prepared, located.localization, objective, workdir, search.seed, runner)
    return write(building, prepared, located, made, objective, workdir, beside.reference, later, given)


def run_site(building, records):
    """`building` at the site its records' cases compute at (`model.site.run_building`: an EPW
    recorded elsewhere moves a case there); InputError naming a record whose weather was recorded
    at another site than the first's: one house, one site."""
    ran = [r for r in records if r.case.building is not None]
    if not ran:
        return building
    site = ran[0].case.building.site
    for r in ran[1:]:
        if any(r.case.building.site[name] != site[name] for name in MOVED):
            raise InputError(r.source, "weather", f"record {r.name}'s weather was recorded at another site than "
                                                  f"record {ran[0].name}'s: the records of one house share its site")
    return at_site(building, site)


def as_given(building, given):
    """The building file's JSON content of `building`, a model of the loop, with the site of
    `given`, the file the user gave: the loop ran at the weather's site, the file keeps its own."""
    data = building.to_json()
    data["site"] = given.to_json()["site"]
    return data


@dataclass
class Prepared:
    """What every stage reads (`prepare`): the records, their windows (with the file's numerical
    error), each record's protocol's building (`bases`, None: the building's), the model as
    described (its runs over each record and its metrics), the noise, the residuals the
    blocks score (`n`), the kind of the model's FMUs and the building's FMU."""
    records: list
    windows: Windows
    bases: list
    model: Model
    noise: Noise
    n: int
    fmu_kind: str  # the FMUs of the model before and after (`fmu_build.build.build_fmu`'s kinds)
    fmu: Path | None = None  # the building's own FMU (model_before.fmu), where a record is under its protocol

    @property
    def policy(self):
        """The `diagnosis.policy.Policy` every choice is made under (the windows')."""
        return self.windows.policy


@dataclass
class Located:
    """The forcing search on every record's calibration window together (`localization`,
    locate.json's content), on each record alone (`alone`, where there are several), and its best
    J per generation (`convergence`)."""
    localization: dict
    alone: list
    convergence: list


@dataclass
class Made:
    """What the rounds made: each round's `Decision`, every candidate tried (its `Fit`, as
    report.json keeps it), their runs by label, the Morris screening of each chosen effect, and
    the model they leave, and whether a round chose the start (`Decision.starts`): every fit
    after it estimates the records' start."""
    decisions: list
    results: list
    runs: dict
    sensitivities: dict
    model: Model
    started: bool = False

    @property
    def added(self):
        """The effects added, in order (their `Fit`s; `result.added_effects`)."""
        return added_effects(self.decisions)


def prepare(building, records, bases, objective, workdir, fmu_kind, noise, policy):
    """Stage 1: the records' windows, judged under `policy`; the building as described (each
    record's protocol's, `bases`: `protocol` of each record) built as an FMU and run over each
    record (`model_before.fmu`); the file's own numerical error beside it; the noise (C), `noise`
    if the user gave it."""
    windows = Windows.of(records, objective, policy)
    before_runs, fmus = [], {}  # {the record's protocol's index, None for the building's own: its FMU}
    for i, (case, base) in enumerate(zip(windows.cases, bases)):
        key = None if base is None else i
        if key not in fmus:
            name = "model_before.fmu" if base is None else f"model_before_{i + 1}.fmu"
            fmus[key] = build_fmu(base or building, workdir / name, kind=fmu_kind)
        with FmuInstance(fmus[key]) as fmu:
            before_runs.append(simulate_fmu(fmu, case, output_ids=objective.air_nodes))
    model = Model(building, before_runs, windows.metrics(objective, before_runs), bases)
    windows = windows.with_numerical(before_runs, windows.sensed_by(model), building, bases, objective)
    noise = Noise.of_records(windows.measured, noise).with_numerical(windows.numerical_rms())
    return Prepared(list(records), windows, bases, model, noise, windows.scored(), fmu_kind, fmus.get(None))


def localise(building, prepared, objective, workdir, search, execution):
    """Stage 2: the forcing search (`ga.locate`) on every record's calibration window together,
    a forcing applying to all; and on each record alone, reported: a record's own sensors
    (experiment 2's surfaces) may point where the records together do not."""
    windows, records, bases = prepared.windows, prepared.records, prepared.bases
    convergence = []
    followed = replace(execution, progress=lambda generation, total, J, unique: convergence.append((generation, J)))
    localization = locate(building, windows.calibrations, workdir, objective, search=search, execution=followed,
                          source=records[0].source, protocols=bases).to_json()
    alone = []
    for i, record in enumerate(records if len(records) > 1 else ()):
        into = workdir / "locate" / record.name
        into.mkdir(parents=True, exist_ok=True)
        alone.append(locate(building, [windows.calibrations[i]], into, objective, search=search, execution=execution,
                            source=record.source, protocols=[bases[i]]).to_json())
    return Located(localization, alone, convergence)


def rounds(prepared, localization, objective, workdir, seed, runner=lifetime.InProcess()):
    """Stage 3: rounds of candidates, `Policy.max_rounds` at most, each on top of the last,
    while the error left is above the noise and one is chosen (`selection.decide`); the
    candidates where `runner` runs tasks, which ran the forcing search (`assess_all`).

    Where a record's history leaves a slow mode's start unknown (`model.start`), the start is
    one more candidate of each round, until one chooses it (`selection.start_test`): that round
    adds no effect, and is not counted among the `max_rounds`; every fit after it, the model's
    cross-validated J included, fits the start with its parameters."""
    windows, n, noise, policy = prepared.windows, prepared.n, prepared.noise, prepared.policy
    folder = workdir / "candidates"
    folder.mkdir(exist_ok=True)
    measured_ids = sorted({i for case in windows.cases for i in case.measured_ids})
    model, decisions, results, runs, sensitivities = prepared.model, [], [], {}, {}
    start_chosen = False
    for number in range(policy.max_rounds + 1):
        if len(decisions) - start_chosen == policy.max_rounds:
            break
        starts = windows.starts(model.building, model.bases, objective.air_nodes)
        base_blocks = windows.block_J(model.runs, starts if start_chosen else None, noise.sigma)
        # the start as a candidate: the model's J with each record's start fitted on its other blocks
        start_blocks = (windows.block_J(model.runs, starts, noise.sigma)
                        if not start_chosen and any(len(modes.tau) for _, modes in starts) else None)
        air_at_noise = bool(number) and policy.at_noise(base_blocks.sum(), n, noise.floor_sd)
        base_sensed = windows.sensed_by(model)  # the round's model at the other sensors: one run per record
        if air_at_noise and not windows.disagreeing(model.building, base_sensed, noise.sigma):
            break  # the error left is the noise's, at the air and at every component's own sensors
        # every earlier round chose an effect or the start: a round without a choice ends them
        done = [d.chosen.label for d in decisions if d.chosen]
        started = time.perf_counter()
        # a later round's candidates, on top of the earlier choices, are building files of their own
        into = folder / f"round{number + 1}" if number else folder
        into.mkdir(exist_ok=True)
        pairs = [p for p in physical(model.building, localization["components"], objective.zones,
                                     measured_ids, policy, localization["best_nodes"]) if "@".join(p) not in done]
        inputs = RoundInputs.of(model, windows, objective, noise.sigma, seed, started=start_chosen)
        assessed = assess_all(inputs, pairs, into, runner)
        tried, models = fits_of(model, base_sensed, pairs, assessed, windows, inputs, number + 1, done)
        # shapes only where no physical candidate physics admits brings the error left to the
        # noise; the residual's statistics then choose which
        if not any(policy.at_noise(r.cv.J, n, noise.floor_sd) and not policy.objection_of(
                r.effect, r.parameters, r.derived, r.physics) for r in tried):
            more = [p for p in shapes(model.building, left_by(windows, model), objective.zones)
                    if "@".join(p) not in done]
            pairs, assessed = pairs + more, assessed + assess_all(inputs, more, into, runner)
            # every sensor's weight from the least misfit any candidate of the round leaves
            tried, models = fits_of(model, base_sensed, pairs, assessed, windows, inputs, number + 1, done)
        simulations = sum(a.simulations for a in assessed)
        # a round run for a component's own sensors alone: only they can make a candidate pass
        decision = decide(tried, Baseline(base_blocks, noise.sigma, n, windows.groups(), noise.floor_sd,
                                          air_at_noise=air_at_noise,
                                          start=None if start_blocks is None else [float(b) for b in start_blocks]),
                          policy)
        if decision.start is not None:
            decision.start.update(start_found(windows, model.runs, starts, noise.sigma))
        decision.cost = {"candidates": len(tried), "simulations": simulations,
                         "seconds": round(time.perf_counter() - started, 1)}
        decisions.append(decision)
        results += [lean(r) for r in tried]
        runs.update({(key if not number else f"{key} (round {number + 1})"): m.runs for key, m in models.items()})
        chosen = decision.chosen
        if decision.starts:
            start_chosen = True
            continue
        if not chosen:
            break
        sensitivities[chosen.label] = screened(model, chosen, windows, objective, seed)
        model = models[chosen.label]
    made = Made(decisions, results, runs, sensitivities, model, start_chosen)
    for fit in made.added[:-1]:
        made = revisit(prepared, made, fit, objective, folder, seed, runner)
    return made


def revisit(prepared, made, fit, objective, folder, seed, runner):
    """An effect an earlier round chose (`fit`), chosen again once the rounds end: it and the
    admissible candidates nearest it in its round (`Policy.revisited`), each calibrated with the
    other effects the model holds refitted together with it (their parameters that rest on their
    priors kept at their values: `resting_on_priors`), against the model without it, the others refitted together without it
    (`refitted_without`), by the rule of every round (`selection.decide`). Where another is
    chosen, it takes the effect's place, the others at their values refitted with it; where
    none is, the effect itself included, it is removed, the others at their values refitted
    without it; `made` with that decision.

    Forward selection adds the effect that best explains what is left; with two faults, the one
    that takes a share of both (a zone's envelope, which scales a faulty door too) wins the
    first round, and the second round, its parameters held, adds the door on top of it. Once
    the door is in the model, the first choice is no longer the one the data ask for: an air
    change with the door refitted may explain them as well or better, or nothing may be needed
    beside the door. Refitted alone, the other effects would keep the share of the revisited
    one they took on top of it; refitted together, each candidate is judged as the rounds
    judge, the model around it fitted anew, and against the model without it fitted anew too:
    a candidate's fall is then its own, not the others' refit (a 0.6 W gain beside a door
    refitted from 2.0 to its true 3.4 lowered J by 1.5 C2 against the door left at 2.0;
    tests/test_revisit.py). The last round's choice is not revisited: the earlier ones were
    refitted with it."""
    windows, n, noise, policy = prepared.windows, prepared.n, prepared.noise, prepared.policy
    number = len(made.decisions) + 1
    others = [a for a in made.added if a.label != fit.label]
    model = made.model.without(fit.effect, fit.target, prepared.model, windows, objective)
    chosen_in = next(d for d in made.decisions if d.chosen is not None and d.chosen.label == fit.label)
    tried_in = {r.label: r for r in made.results if r.round == chosen_in.chosen.round}
    nearest = sorted((v.evidence, label) for label, v in chosen_in.verdicts.items()
                     if v.passes and not v.objection and label in tried_in and label not in {a.label for a in others})
    labels = [fit.label] + [label for _, label in nearest if label != fit.label][:policy.revisited - 1]
    pairs = [(tried_in[label].effect, tried_in[label].target) for label in labels]
    started = time.perf_counter()
    into = folder / f"revisit{number}"
    into.mkdir(exist_ok=True)
    refit, kept, refitted, spent = refitted_without(model, others, windows, objective, noise.sigma, seed,
                                                    into / "without", runner, number, made.started)
    inputs = RoundInputs.of(kept, windows, objective, noise.sigma, seed, [(a.effect, a.target) for a in others],
                            {a.label: resting_on_priors(a) for a in others}, made.started)
    assessed = assess_all(inputs, pairs, into, runner)
    tried, models = fits_of(kept, windows.sensed_by(kept), pairs, assessed, windows, inputs, number,
                            [a.label for a in others])
    decision = decide(tried, Baseline(refit.cv.blocks, noise.sigma, n, windows.groups(), noise.floor_sd), policy)
    chosen = decision.chosen
    decision = revisited(decision, fit.label, [a.label for a in others],
                         refitted if chosen is None else assessed[[t.label for t in tried].index(chosen.label)].beside,
                         lean(refit))
    decision.cost = {"candidates": len(tried), "simulations": spent + sum(a.simulations for a in assessed),
                     "seconds": round(time.perf_counter() - started, 1)}
    runs = {**made.runs, **{f"{key} (revisit of {fit.label})": m.runs for key, m in models.items()}}
    made = Made(made.decisions + [decision], made.results + [lean(r) for r in tried], runs, made.sensitivities,
                made.model, made.started)
    if decision.removes:
        return replace(made, sensitivities={k: v for k, v in made.sensitivities.items() if k != fit.label},
                       model=kept)
    if not decision.changes_model:
        return made
    return replace(made, sensitivities={**made.sensitivities, chosen.label: screened(kept, chosen, windows, objective,
                                                                                     seed)},
                   model=models[chosen.label])


def refitted_without(model, kept, windows, objective, sigma, seed, into, runner, number, started=False):
    """The effects `kept` (`Fit`s) of `model`, which no longer holds the one a revisit removes,
    refitted together without it: the first calibrated as a candidate, the others beside it (a
    parameter that rests on its prior kept at its value: `resting_on_priors`), with its cross-validation, which is
    then that of the model left, the start fitted where `started`. Its `Fit`, the `Model` it makes,
    every kept effect's values ({label: {name: {"value", "std", ...}}}) and the simulations it took."""
    into.mkdir(exist_ok=True)
    first, beside = kept[0], kept[1:]
    inputs = RoundInputs.of(model, windows, objective, sigma, seed, [(a.effect, a.target) for a in beside],
                            {a.label: resting_on_priors(a) for a in beside}, started)
    pair = (first.effect, first.target)
    assessed = assess_all(inputs, [pair], into, runner)
    (refit,), models = fits_of(model, windows.sensed_by(model), [pair], assessed, windows, inputs, number,
                               [a.label for a in beside])
    values = {refit.label: assessed[0].parameters, **(assessed[0].beside or {})}
    return refit, models[refit.label], values, assessed[0].simulations


def lean(fit):
    """The `Fit` as the diagnosis keeps it, without its residuals (the decision keeps what the
    choice read of them, the distances of every two admissible candidates'): a house's rounds
    would hold gigabytes."""
    return replace(fit, cv=replace(fit.cv, left_out=None), sensors=replace(fit.sensors, residuals=None))


def screened(model, chosen, windows, objective, seed):
    """The Morris screening of the `chosen` effect's parameters on the `model` it is added to: a
    screening of every candidate would cost a quarter of a round's simulations."""
    candidate = Candidate(model.building, chosen.effect, chosen.target, protocols(model.bases, windows.calibrations))
    return sensitivity(candidate, windows.calibrations, objective, seed=seed)


def left_by(windows, model):
    """What the model's residual on the first record's calibration window follows (an input, the
    time of day)."""
    first, k0 = windows.each[0].case, windows.each[0].k
    shaped = shaped_inputs(model.building)
    inputs = {name: values for name, values in zip(first.input_names, first.U[1:k0 + 1].T) if name in shaped}
    return residual_diagnostics(on_site_clock(windows.each[0].calibration.times[1:], model.building),
                                windows.each[0].measured[:k0][:, 0] - model.runs[0][:k0, 0], inputs)


def on_site_clock(times, building):
    """`times` on the site's local clock and calendar, which the building's daily and workday
    gains follow (`model.case.local_times`)."""
    return local_times(pd.DatetimeIndex(times), building.site["timezone"], building.source)


def resting_on_priors(fit):
    """The names of a `Fit`'s parameters whose value rests on their prior: weighed with one, the
    data alone not fixing them (a ground's temperature where the data fix its flux only)."""
    return [name for name, p in fit.parameters.items() if p.prior and not p.identifiable]


def priors_stated(building, added):
    """The building with a sentence in its description for each parameter of an added effect
    (`Fit`s) that rests on its physical prior, the data not fixing it apart: a modeller reading the
    file learns which of its values the data did not fix and where they come from."""
    said = [f"{fit.effect} on {fit.target}: {name} = {fit.parameters[name].value:.4g} "
            f"{EFFECTS[fit.effect].parameter(name).unit}, the data weighed with its prior "
            f"({fit.parameters[name].prior}): the data fixed the effect, not {name} apart (nodeforce diagnose)."
            for fit in added for name in resting_on_priors(fit)]
    if not said:
        return building
    return building.edited(lambda data: data.update(description=" ".join([data.get("description", "")] + said).strip()))


def write(building, prepared, located, made, objective, workdir, reference, later=(), given=None):
    """Stage 4: the model the rounds leave written (`building_after.json`, `model_after.fmu`,
    each protocol's building, `model_after.idf` for a converted EnergyPlus model), scored on
    each later record (`scored_later`), the `Diagnosis`, written as report.json, report.md and
    the plots; returns it. The building files keep the site of the files given (`given`, the
    building's, default `building`; a record's own protocol's), where the loop ran at the
    weather's (`run_site`); the FMU is the model as run."""
    windows, records, model, added = prepared.windows, prepared.records, made.model, made.added
    fmu_kind, given = prepared.fmu_kind, building if given is None else given
    (workdir / "building_after.json").write_text(json.dumps(as_given(priors_stated(model.building, added), given),
                                                            indent=2) + "\n")
    fmu_after = build_fmu(model.building, workdir / "model_after.fmu", kind=fmu_kind)
    later = [scored_later(record, (building.source, building, prepared.fmu),
                          (workdir / "building_after.json", model.building, fmu_after), objective, fmu_kind)
             for record in later]
    # a record under another protocol: its own building as corrected, for `nodeforce compare`
    protocols_after = {i: workdir / f"building_after_record{i + 1}.json" for i, b in enumerate(model.bases) if b is not None}
    for i, path in protocols_after.items():
        path.write_text(json.dumps(as_given(model.bases[i], records[i].building or given), indent=2) + "\n")
    by_phase = phase_rows(prepared, made, objective)
    start = (start_found(windows, model.runs, windows.starts(model.building, model.bases, objective.air_nodes),
                         prepared.noise.sigma) if made.started else None)
    diagnosis = Diagnosis(
        objective=list(objective.zones), period=period(windows, 0), before=prepared.model.metrics,
        after=model.metrics, localization=located.localization, candidates=made.results, rounds=made.decisions,
        structure_left=left_by(windows, model)["sentence"],
        heat_loss=heat_loss(building, model.building, added, made.results, prepared.noise.sigma,
                            prepared.policy.yardstick, last_change(made.decisions)),
        residuals=validation_residuals(prepared, made), sensitivity=made.sensitivities, noise=prepared.noise,
        assumptions=list(dict.fromkeys(a for case in windows.cases for a in case.assumptions))
        + start_said(start, next((n for n, d in enumerate(made.decisions, 1) if d.starts), None)),
        node_names={str(i): name for i, name in building.node_names().items()},
        artifacts={"building_after": str(workdir / "building_after.json"), "fmu_after": str(fmu_after)},
        records=[RecordOutcome(r.name, str(r.source), period(windows, i),
                               windows.metrics(objective, prepared.model.runs, i),
                               windows.metrics(objective, model.runs, i), located.alone[i],
                               str(protocols_after[i]) if i in protocols_after else None)
                 for i, r in enumerate(records)] if len(records) > 1 else [],
        worsened_phases=worsened(by_phase, "before", "after") if by_phase and added else None,
        phases=by_phase or None, reference=reference or None, later=later, policy=prepared.policy, start=start)
    idf = idf_of(building)
    if idf is not None:  # a converted EnergyPlus model: its corrections written back into it
        diagnosis.energyplus = write_corrections(building, model.building, [(a.effect, a.target) for a in added],
                                                 idf, workdir / "model_after.idf")
        diagnosis.artifacts["idf_after"] = diagnosis.energyplus["idf_after"]
    plots = write_report(workdir, diagnosis.to_json(), plotted(prepared, located, made, objective))
    diagnosis.artifacts["plots"] = [str(p) for p in plots]
    diagnosis.artifacts["report"] = str(workdir / "report.md")
    diagnosis.write(workdir / "report.json")
    return diagnosis


def start_found(windows, runs, starts, sigma):
    """{"records": [...]}: what the start fitted to the model's `runs` (one (N_t, zones) per
    record) on each calibration window finds (`Windows.start_fitted`, `starts` the records'
    `Windows.starts`, sigma the noise's sd, C), for each record whose history leaves a slow mode
    unset: its name, each mode's time constant (days), its amplitude at the first measurement
    (K) with its posterior sd and its prior's (K), and the share of the window's J it takes
    out."""
    found = []
    for i, (w, run, (F, modes)) in enumerate(zip(windows.each, runs, starts)):
        if not len(modes.tau):
            continue
        residual = w.measured[:w.k] - run[:w.k]
        c, cov = windows.start_fitted(residual, starts, sigma, i)
        scored = np.isfinite(residual)
        J, left = np.sum(np.square(residual[scored])), np.sum(np.square((residual - F[:w.k] @ c)[scored]))
        found.append({"record": w.record.name or str(w.record.source),
                      "tau_days": [float(t / 86400) for t in modes.tau], "amplitude": [float(a) for a in c],
                      "sd": [float(v) for v in np.sqrt(np.diag(cov))],
                      "prior_sd": [float(v) for v in modes.sd], "share_of_J": float(1.0 - left / J) if J > 0 else 0.0})
    return {"records": found}


def start_said(start, chosen_in):
    """A sentence per record of `start` (`start_found` of the model the rounds leave; None: the
    start was never chosen, nothing to say), chosen in round `chosen_in`."""
    if start is None:
        return []
    said = []
    for r in start["records"]:
        found = "; ".join(f"its {tau:.3g}-day mode {a:+.3g} +- {sd:.2g} K (prior sd {prior:.2g} K)"
                          for tau, a, sd, prior in zip(r["tau_days"], r["amplitude"], r["sd"], r["prior_sd"]))
        said.append(f"Round {chosen_in} chose the start its history leaves unknown (docs/model.md 5.10): fitted "
                    f"to the model as corrected on the calibration window of {r['record']}, at its first "
                    f"measurement, {found}; it takes {r['share_of_J']:.0%} of the window's J. The metrics given "
                    "are the runs' as the FMUs and `compare` simulate them, which start as the history does, "
                    "without it.")
    return said


def scored_later(record, written, corrected, objective, fmu_kind):
    """The later `record` scored as `nodeforce compare` scores it (`diagnosis.compare`): the
    building as written and as corrected, each (path, Building, its FMU or None: built), run
    through its FMU on the record's case prepared for it; their `LaterRecord`."""
    models, fmus = [], []
    for path, b, fmu in (written, corrected):
        case = record.case_for(b)
        models.append((path, case.building, case, objective))
        # a later weather recorded at another site runs the building there, through an FMU of its own
        fmus.append(fmu if case.building is b else None)
    result, _ = compare(models, fmu_kind=fmu_kind, fmus=fmus)
    before, after = (m["metrics"] for m in result["models"])
    return LaterRecord(record.name, str(record.source), result["record"], result["scored_from"], before, after)


def validation_residuals(prepared, made):
    """What the first objective zone's residual on the first record's validation window follows
    (`diagnosis.residuals`), before and after."""
    windows = prepared.windows
    first, k, measured = windows.each[0].case, windows.each[0].k, windows.each[0].measured
    validation = slice(k, None)
    return {state: residual_diagnostics(on_site_clock(first.times[1:][validation], prepared.model.building),
                                        measured[validation, 0] - run[0][validation, 0],
                                        {name: values[validation] for name, values in
                                         zip(first.input_names, first.U[1:].T)})
            for state, run in (("before", prepared.model.runs), ("after", made.model.runs))}


def phase_rows(prepared, made, objective):
    """Every model's error on every record's phases (`diagnosis.phases`), each phase named with its
    record's name where there are several."""
    windows, records, rows = prepared.windows, prepared.records, []
    for i, (record, case) in enumerate(zip(records, windows.cases)):
        runs = {"before": prepared.model.runs[i], **{key: r[i] for key, r in made.runs.items()},
                "after": made.model.runs[i]}
        rows += [{**row, "phase": f"{record.name}: {row['phase']}", "record": record.name} if len(records) > 1
                 else row for row in phase_errors(record.phases, case.times[1:], windows.measured[i], runs,
                                                  zones=objective.zones)]
    return rows


def plotted(prepared, located, made, objective):
    """The series the plots draw, from the first measurement: the weather's history before it is
    not the record."""
    windows = prepared.windows
    first, k, measured = windows.each[0].case, windows.each[0].k, windows.each[0].measured
    times, h = first.times, first.history_steps
    return {"times": times[h + 1:], "validation_start": times[k + 1], "scored_from": times[first.burn_in_steps + 1],
            "convergence": located.convergence,
            "zones": {zone: {"air_node": air, "measured": measured[h:, j], "before": prepared.model.runs[0][h:, j],
                             "after": made.model.runs[0][h:, j]}
                      for j, (zone, air) in enumerate(zip(objective.zones, objective.air_nodes))},
            "inputs": dict(zip(first.input_names, first.U[h + 1:].T))}


def protocol(building, record):
    """The record's own building (its protocol's), None where it is `building`; InputError naming
    its file where it is not the same house node for node."""
    other = record.building if record.building is not None else record.case.building
    if other is not None and record.case.building is not None:
        other = at_site(other, record.case.building.site)  # the record's file as its case ran it
    if other is None or other is building or other.to_json() == building.to_json():
        return None
    for what, of in (("zones", lambda b: [z.name for z in b.zones]),
                     ("components", lambda b: [c.name for c in b.components]),
                     ("nodes", lambda b: b.n_nodes)):
        if of(other) != of(building):
            raise InputError(other.source, what, f"record {record.name}'s building is not {building.source}'s house "
                                                 f"under another protocol: its {what} differ")
    return other
