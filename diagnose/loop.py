"""`nodeforce diagnose`: from the residual to the missing effect, added, calibrated, and judged
on data the calibration did not see.

1. The record is split by time into a calibration window and a later validation window. The
   record's first days are a burn-in (docs/model.md: every measured node forced, not scored), so
   the walls start from what the sensors saw rather than from the warm-up's replay of the first
   day, which a record with real history does not match; the calibration window's scored steps
   are cut into blocks of whole days for the cross-validation (`diagnose.selection`).
2. Before: the building as described, simulated through its FMU; metrics on both windows, per
   objective zone and together.
3. The forcing search (`ga.locate`) on the calibration window: which nodes it locates, and per
   component the share of J above the noise its forcing removes (the evidence).
4. Rounds. Each calibrates every physical candidate (`diagnose.candidates.physical`: every zone
   effect of the objective zones, the component effects of the components the evidence ranks
   highest and of those no sensor sits in) on the direct model, the candidates in parallel
   worker processes, once on the whole calibration window and once per block left out
   (`diagnose.calibrate`); where none brings the error to the noise, the shapes the residual's
   statistics point at too (`diagnose.candidates.shapes`). One rule chooses
   (`diagnose.selection.decide`: blocked cross-validation, the one-standard-error rule, the
   objections of physics), against the model the earlier rounds made. Rounds go on while the
   error left is above the noise and a candidate passes. The validation window plays no part in
   any choice: its before and after are an honest estimate. The decision of every round, its
   margins, its cost and its reason go into report.json, which the report reads.
5. The chosen model is built as an FMU and written (`model_after.fmu`, `building_after.json`);
   every candidate's building file is written declaring its calibrated effect
   (`candidates/<effect>@<target>.json`, a later round's in `candidates/round<n>/`).
6. The residual of the first objective zone on the validation window, before and after, is
   described (`diagnose.residuals`): is it white, and which input or time of day does it follow.
7. Given the experiment's phases, every model is scored on each (`diagnose.phases`), and an
   added effect that makes a phase worse is flagged in the decision's reason.
"""
import json
import os
import sys
import time
from contextlib import nullcontext
from dataclasses import dataclass

import numpy as np
from tqdm import tqdm

from nodeforce import lifetime
from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.diagnose.calibrate import Candidate, calibrate, sensitivity
from nodeforce.diagnose.candidates import objection, physical, shaped_inputs, shapes
from nodeforce.diagnose.loss import heat_loss
from nodeforce.diagnose.report import write_report
from nodeforce.diagnose.phases import phase_errors, worsened
from nodeforce.diagnose.residuals import diagnostics as residual_diagnostics
from nodeforce.diagnose.selection import at_noise, block_J, blocks, decide, label
from nodeforce.fmu_build.build import build_fmu
from nodeforce.ga.locate import check_measured, locate
from nodeforce.model.effects import EFFECTS
from nodeforce.model.errors import InputError
from nodeforce.model.integrate import steps_per_day
from nodeforce.model.score import Noise

# Rounds of candidates at most: each adds one effect on top of the last, while the error left is
# above the noise and a candidate passes; a record rarely supports three undeclared effects.
MAX_ROUNDS = 3


def split(case, source, fraction=None, end=None):
    """Row index k of the last calibration time: t_0..t_k calibrate, t_k+1..t_N validate.

    Parameters
    ----------
    case : Case (its burn-in must fit in the calibration window, with a day to score)
    source : the measurement file, for errors
    fraction : the part of the record, by time, that calibrates
    end : pandas Timestamp, the last calibration time (the row at or before it)
    """
    n = len(case.times) - 1
    if end is not None:
        k = int(case.times.searchsorted(end, side="right")) - 1
        what = f"a calibration ending {end.isoformat()}"
    else:
        k = int(round(fraction * n))
        what = f"a split {fraction:.0%} / {1 - fraction:.0%}"
    day = steps_per_day(case.dt)
    if k < case.burn_in_steps + day or n - k < day:
        raise InputError(source, "time", f"{n} steps of {case.dt:g} s from {case.times[0].isoformat()}: {what} "
                                         f"leaves no calibration window of the burn-in plus a day, or no "
                                         f"validation window of a day")
    return k


def assess(task):
    """Calibrate one candidate effect, with its cross-validation folds, and run it: a task for a
    worker process.

    Returns the calibrated parameters, what the data determine, the simulated objective air over
    the whole record, the Morris screening, the folds and the simulations it took; writes the
    candidate's building file, declared at the calibrated values, in `folder`.
    """
    building, effect, target, folder, calibration, case, objective, masks, seed = task
    candidate = Candidate(building, effect, target)
    parameters, determined, folds = calibrate(candidate, calibration, objective, masks)
    values = [parameters[p.name]["value"] for p in candidate.parameters]
    run = candidate.nodes(case, objective.air_nodes, values)
    screening = sensitivity(candidate, calibration, objective, seed=seed)
    calibrated = EFFECTS[effect].apply(building, target, {name: p["value"] for name, p in parameters.items()})
    (folder / f"{candidate.label}.json").write_text(json.dumps(calibrated.to_json(), indent=2) + "\n")
    return parameters, determined, run, screening, folds, candidate.simulations


@dataclass
class Model:
    """A model of the loop: its building, its objective air simulated over the whole record
    (`run`) and its metrics."""
    building: object
    run: np.ndarray
    metrics: dict


def assess_all(model, pairs, calibration, case, objective, folder, seed, workers, masks):
    """Each (effect, target) added to `model`, calibrated on `calibration` (t_0..t_k) with a fold
    per block of `masks`, and run over `case`, in parallel worker processes (which end with this
    process: nodeforce.lifetime): the candidates' records, their `Model`s by label, their Morris
    screenings, and the simulations they took."""
    tasks = [(model.building, effect, target, folder, calibration, case, objective, masks, seed)
             for effect, target in pairs]
    n_workers = min(workers or os.cpu_count(), len(tasks))
    with (lifetime.worker_pool(n_workers) if n_workers > 1 else nullcontext()) as pool:
        assessed = list(tqdm((pool.map if pool else map)(assess, tasks), total=len(tasks),
                             desc="calibrating candidate effects", unit="candidate",
                             disable=not sys.stderr.isatty()))
    measured = objective.measured(case)
    k = len(calibration.times) - 1
    n = int(np.isfinite(measured[:k]).sum())
    results, models, sensitivities, simulations = [], {}, {}, 0
    for (effect, target), (parameters, determined, run, screening, folds, count) in zip(pairs, assessed):
        scores = [float(np.nansum(np.square(f["residuals"]))) for f in folds]
        result = {"effect": effect, "target": target, "parameters": parameters, "derived": determined,
                  "calibration": objective.metrics(measured[:k], run[:k]),
                  "validation": objective.metrics(measured[k:], run[k:]),
                  "cv": {"blocks": scores, "J": sum(scores), "n": n, "rmse": float(np.sqrt(sum(scores) / n)),
                         "folds": [f["values"] for f in folds]}}
        values = {name: p["value"] for name, p in parameters.items()}
        models[label(result)] = Model(EFFECTS[effect].apply(model.building, target, values), run,
                                      {w: result[w] for w in ("calibration", "validation")})
        results.append(result)
        sensitivities[label(result)] = screening
        simulations += count
    return results, models, sensitivities, simulations


def diagnose(building, case, objective, workdir, *, source="measurements", fraction=0.6, calibration_end=None,
             seed=0, workers=None, population=30, generations=400, fmu_kind="python", reference=None,
             noise=None, phases=None):
    """Run the whole loop; write the artifacts in `workdir`; return the report.json content.
    `reference` ({"label", "rmse": {phase: K}}), another model's error, is reported for scale;
    `noise` (C) is the air sensors' noise sd if the user knows it, else it is estimated;
    `phases` (iotools.phases.Phase records) are the experiment's phases, each model scored on each."""
    check_measured(objective, case, source)
    # what no sensor sets (every wall of an air-only record) starts from the steady state of the
    # first day, not at the air's temperature: a heavy component would carry that guess for weeks,
    # and the candidates' slow parameters would fit it
    case = case if case.steady_start else case.with_steady_start()
    k = split(case, source, fraction, calibration_end)
    # the forcing search and the candidates' fits read the calibration window, the choice its
    # days left out one at a time; the validation window only reports
    calibration = case.window(0, k)
    masks = blocks(k, case.burn_in_steps, case.dt, source)
    measured = objective.measured(case)
    scored = measured[:k]
    n = int(np.isfinite(scored).sum())
    noise = Noise.of(measured, noise)
    sigma = noise.sigma

    with FmuInstance(build_fmu(building, workdir / "model_before.fmu", kind=fmu_kind)) as base:
        before_run = simulate_fmu(base, case, output_ids=objective.air_nodes)
    before = {"calibration": objective.metrics(scored, before_run[:k]),
              "validation": objective.metrics(measured[k:], before_run[k:])}
    model = Model(building, before_run, before)

    convergence = []
    localization = locate(building, calibration, objective, workdir, source=source, seed=seed,
                          workers=workers, population=population, generations=generations, fmu_kind=fmu_kind,
                          noise=noise.sigma if noise.given else None,
                          progress=lambda generation, total, J, unique: convergence.append((generation, J)))

    folder = workdir / "candidates"
    folder.mkdir(exist_ok=True)

    def left_by(model):
        """What the model's residual on the calibration window follows (an input, the time of day)."""
        shaped = shaped_inputs(model.building)
        inputs = {name: values for name, values in zip(case.input_names, case.U[1:k + 1].T) if name in shaped}
        return residual_diagnostics(calibration.times[1:], scored[:, 0] - model.run[:k, 0], inputs)

    def assessed(model, pairs, number):
        # a later round's candidates, on top of the earlier choices, are building files of their own
        into = folder / f"round{number + 1}" if number else folder
        into.mkdir(exist_ok=True)
        return assess_all(model, pairs, calibration, case, objective, into, seed, workers, masks)

    added, rounds, results, runs, sensitivities = [], [], [], {}, {}
    for number in range(MAX_ROUNDS):
        base_blocks = block_J(scored - model.run[:k], masks)
        if number and at_noise(base_blocks.sum(), n, sigma):
            break  # the error left is the noise's
        done = {label(a) for a in added}
        started = time.perf_counter()
        pairs = [p for p in physical(model.building, localization["components"], objective.zones,
                                     case.measured_ids, localization["best_nodes"]) if "@".join(p) not in done]
        tried, models, screened, simulations = assessed(model, pairs, number)
        # shapes only where no physical candidate physics admits brings the error left to the
        # noise; the residual's statistics then choose which
        if not any(at_noise(r["cv"]["J"], n, sigma) and not objection(model.building, r["effect"], r["target"],
                                                                      r["parameters"], r["derived"]) for r in tried):
            pairs = [p for p in shapes(model.building, left_by(model), objective.zones) if "@".join(p) not in done]
            more, more_models, more_screened, more_simulations = assessed(model, pairs, number)
            tried, simulations = tried + more, simulations + more_simulations
            models.update(more_models)
            screened.update(more_screened)
        chosen, decision = decide(model.building, tried, base_blocks, sigma, n)
        decision["cost"] = {"candidates": len(tried), "simulations": simulations,
                            "seconds": round(time.perf_counter() - started, 1)}
        rounds.append(decision)
        on_top = {"on_top_of": [label(a) for a in added]} if added else {}
        results += [{**r, "round": number + 1, **on_top} for r in tried]
        runs.update({(key if not added else f"{key} (round {number + 1})"): m.run for key, m in models.items()})
        sensitivities.update(screened)
        if not chosen:
            break
        added.append(chosen)
        model = models[label(chosen)]

    left = left_by(model)
    decision = {**rounds[0], "chosen": label(added[-1]) if added else None,
                "reason": " ".join(f"Round {i + 1}: {d['reason']}" if len(rounds) > 1 else d["reason"]
                                   for i, d in enumerate(rounds)),
                "rounds": rounds, "structure_left": left["sentence"]}
    after_building, after_run, after = model.building, model.run, model.metrics
    effect = ({key: added[-1][key] for key in ("effect", "target", "parameters", "derived")} if added
              else {"effect": "none", "target": None, "parameters": {}})
    (workdir / "building_after.json").write_text(json.dumps(after_building.to_json(), indent=2) + "\n")
    fmu_after = build_fmu(after_building, workdir / "model_after.fmu", kind=fmu_kind)

    times = case.times
    by_phase = phase_errors(phases or (), times[1:], measured, {"before": before_run, **runs, "after": after_run})
    if by_phase and added:
        decision["worsened_phases"] = worsened(by_phase, "before", "after")
        if decision["worsened_phases"]:
            decision["reason"] += (" It lowers the total error but makes the phase " + "; ".join(
                f"{w['phase']} worse ({w['before']:.3f} C -> {w['after']:.3f} C)" for w in decision["worsened_phases"])
                + ", which the total hides.")
    validation = slice(k, None)
    residuals = {state: residual_diagnostics(times[1:][validation], measured[validation, 0] - run[validation, 0],
                                             {name: values[validation] for name, values in
                                              zip(case.input_names, case.U[1:].T)})
                 for state, run in (("before", before_run), ("after", after_run))}
    report = {
        "period": {"calibration": [times[0].isoformat(), times[k].isoformat()],
                   "calibration_scored_from": times[case.burn_in_steps + 1].isoformat(),
                   "validation": [times[k + 1].isoformat(), times[-1].isoformat()],
                   "blocks": [[times[1:k + 1][m][0].isoformat(), times[1:k + 1][m][-1].isoformat()] for m in masks],
                   "roles": {"calibration": "the forcing search and the candidates' fits read it; each of its "
                                            "blocks of whole days ('blocks') is left out of a fit in turn and "
                                            "predicted, and the choice is made on those predictions",
                             "validation": "reports before and after only; no part in any choice"}},
        "objective": list(objective.zones),
        "before": before,
        "localization": localization,
        "candidates": results,
        "effects": [{key: a[key] for key in ("effect", "target", "parameters")} for a in added],
        "decision": decision,
        "effect": effect,
        "after": after,
        "heat_loss_coefficient": heat_loss(building, after_building, added, results, sigma),
        "assumptions": list(case.assumptions),
        "residuals": residuals,
        "sensitivity": sensitivities,
        "noise_sigma": sigma,
        "noise": noise.to_json(),
        "node_names": {str(i): name for i, name in building.node_names().items()},
        "artifacts": {"building_after": str(workdir / "building_after.json"), "fmu_after": str(fmu_after)},
    }
    if reference:
        report["reference"] = reference
    if by_phase:
        report["phases"] = by_phase
    series = {"times": times[1:], "validation_start": times[k + 1], "scored_from": times[case.burn_in_steps + 1],
              "convergence": convergence,
              "zones": {zone: {"air_node": air, "measured": measured[:, j], "before": before_run[:, j],
                               "after": after_run[:, j]}
                        for j, (zone, air) in enumerate(zip(objective.zones, objective.air_nodes))},
              "inputs": dict(zip(case.input_names, case.U[1:].T))}
    plots = write_report(workdir, report, series)
    report["artifacts"]["plots"] = [str(p) for p in plots]
    report["artifacts"]["report"] = str(workdir / "report.md")
    (workdir / "report.json").write_text(json.dumps(report, indent=2, default=_plain) + "\n")
    return report


def _plain(value):
    """numpy scalars as plain JSON numbers."""
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON")
