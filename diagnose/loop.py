"""`nodeforce diagnose`: from the residual to the missing effect, added, calibrated, and judged
on data the calibration did not see.

1. The record is split by time into a calibration window and a later validation window, and the
   calibration window again into a fitting window and a selection window (its last third, at
   least a day). The record's first days are a burn-in (docs/model.md section 5: every measured node
   forced, not scored), so the walls start from what the sensors saw rather than from the
   warm-up's replay of the first day, which a record with real history does not match.
2. Before: the building as described, simulated through its FMU; metrics on the three windows,
   per objective zone and together (the fitting window is simulated on its own, as the fits see
   it; the selection and validation windows are parts of a run over the whole record, so they
   start from the state the past left).
3. The forcing search (`ga.locate`) on the fitting window localises nodes.
4. Candidates (`diagnose.candidates`): the effects the localised nodes point at, and those of the
   objective zones' air equations, each its own FMU with the effect's parameters, and, once
   calibrated, its own building file (`candidates/<effect>@<target>.json/.fmu`).
5. Each is calibrated on the fitting window (`diagnose.calibrate`), the candidates in parallel
   worker processes.
6. The choice (`decide`) is made on the selection window alone: a candidate must beat the model
   without it on BIC (fitting window) and lower the selection window's J by more than the noise
   and its paired scatter; physics may refuse it (a suggestion then, with the reason); among
   the rest a physical effect, and fewer parameters, are preferred unless the data show them
   worse, pair by pair. "none" if no candidate is admitted. The validation window plays no part
   in any choice: its before and after are an honest estimate. The decision, its margins and
   its reason go into report.json, which the report reads.
7. The residual of the first objective zone on the validation window, before and after, is
   described (`diagnose.residuals`): is it white, and which input or time of day does it follow.
8. Given the experiment's phases, every model is scored on each (`diagnose.phases`), and an
   added effect that makes a phase worse is flagged in the decision's reason.
"""
import json
import math
import os
import sys
from contextlib import nullcontext
from dataclasses import dataclass

import numpy as np
from tqdm import tqdm

from nodeforce import lifetime
from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.diagnose.calibrate import Candidate, calibrate, sensitivity
from nodeforce.diagnose.candidates import (candidates, follow_up, is_shape, objection, preference,
                                           shaped_inputs)
from nodeforce.diagnose.loss import heat_loss
from nodeforce.diagnose.report import write_report
from nodeforce.diagnose.phases import phase_errors, worsened
from nodeforce.diagnose.residuals import diagnostics as residual_diagnostics
from nodeforce.model.significance import bandwidth, change_of_J, worse
from nodeforce.fmu_build.build import build_fmu
from nodeforce.ga.locate import check_measured, locate
from nodeforce.ga.parsimony import Z_NOISE, tolerance
from nodeforce.model.effects import EFFECTS, bridge_parts
from nodeforce.model.errors import InputError
from nodeforce.model.integrate import steps_per_day
from nodeforce.model.score import Noise


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


# The share of the calibration window's scored steps held out to choose among the candidates.
SELECTION_SHARE = 1 / 3


def selection_split(case, k, source):
    """Row index j of the last fitting time inside the calibration window t_0..t_k: the candidates
    are fitted on t_0..t_j and chosen on t_j+1..t_k (the selection window), a third of the scored
    calibration steps and at least a day, so that the window the report's "after" is measured on
    plays no part in the choice (docs/method.md)."""
    day = steps_per_day(case.dt)
    scored = k - case.burn_in_steps
    held = max(int(round(SELECTION_SHARE * scored)), day)
    if scored - held < day:
        raise InputError(source, "time", f"a calibration window of {scored} scored steps of {case.dt:g} s "
                                                 "leaves no fitting window of a day beside a selection window of a "
                                                 "day: give a longer calibration window")
    return k - held


def assess(task):
    """Calibrate one candidate effect and run it: a task for a worker process.

    Returns the calibrated parameters, what the data determine, the simulated objective air on
    the calibration window and over the whole record, and the Morris screening; writes the
    candidate's FMU and its building file, declared at the calibrated values, in `folder`.
    """
    building, effect, target, folder, calibration, case, objective, seed, fmu_kind = task
    candidate = Candidate(building, effect, target, folder, fmu_kind)
    try:
        parameters, determined = calibrate(candidate, calibration, objective)
        values = [parameters[p.name]["value"] for p in candidate.parameters]
        fitted = candidate.nodes(calibration, objective.air_nodes, values)
        run = candidate.nodes(case, objective.air_nodes, values)
        screening = sensitivity(candidate, calibration, objective, seed=seed)
    finally:
        candidate.close()
    calibrated = EFFECTS[effect].apply(building, target, {name: p["value"] for name, p in parameters.items()})
    (folder / f"{candidate.label}.json").write_text(json.dumps(calibrated.to_json(), indent=2) + "\n")
    return parameters, determined, fitted, run, screening


def bic(J, n, k):
    """Bayesian information criterion of a least-squares fit with k parameters on n residuals."""
    return n * math.log(J / n) + k * math.log(n)


def decide(building, results, before, sigma, selection_residuals, k_before=0):
    """The decision record: the chosen candidate (or None), each candidate's tests, the margins
    they were judged by, the candidates the data support but physics refuses (suggestions), and
    the reason in words. `before` holds the metrics of the model the candidates are added to, which
    has `k_before` fitted parameters; `selection_residuals` ({label: (n, zones) residual, C}) are
    each candidate's residuals on the selection window, for the paired comparisons.

    1. A candidate passes when it beats the model without it on BIC (fitting window) and lowers J
       on the selection window by more than the noise and Z_NOISE standard deviations of that
       paired fall.
    2. A candidate that passes but which physics refuses (`candidates.objection`: a parameter not
       identifiable or on a bound, a value outside physical limits, a gain the building file's
       description rules out) is not added; it is reported as a suggestion, with the reason.
    3. Among the admissible candidates that pass, the preferred (`candidates.preference`: a
       physical effect before a shape, fewer parameters before more) wins unless the data show it
       fitting the selection window worse than the best (`significance.worse`, paired): a shape,
       or a candidate with more parameters, must beat it by a significant margin.
    """
    bic_before = bic(before["calibration"]["J"], before["calibration"]["n"], k_before)
    J_before = before["selection"]["J"]
    margin = tolerance(J_before, sigma, before["selection"]["n"])
    tests = {}
    for r in results:
        # the fall must beat the sensor noise and the residuals' own correlated scatter
        needed = max(margin, Z_NOISE * r["selection_fall"]["sd"])
        objection = candidate_objection(building, r)
        tests[label(r)] = {"beats_bic": bool(r["bic"] < bic_before), "selection_margin": needed,
                           "beats_selection": bool(r["selection_fall"]["J"] > needed),
                           "objection": objection}
    passing = [r for r in results if tests[label(r)]["beats_bic"] and tests[label(r)]["beats_selection"]]
    admissible = [r for r in passing if not tests[label(r)]["objection"]]
    suggestions = [{"candidate": label(r), "reason": tests[label(r)]["objection"],
                    "selection_rmse": r["selection"]["rmse"]} for r in passing if tests[label(r)]["objection"]]
    chosen = None
    if admissible:
        best = min(admissible, key=lambda r: r["selection"]["J"])
        ranked = sorted(admissible, key=lambda r: (preference(r["effect"]), r["selection"]["J"]))
        chosen = next(r for r in ranked if r is best or not worse(selection_residuals[label(r)],
                                                                   selection_residuals[label(best)]))
    rmse_before = before["selection"]["rmse"]
    if chosen:
        what = (f"an unexplained heat source, acting {acting(chosen)} ({chosen['effect']} on {chosen['target']})"
                if is_shape(chosen["effect"]) else f"{chosen['effect']} on {chosen['target']}")
        passed = (f"of the {len(passing)} of {len(results)} candidates that beat the model without them on BIC "
                  f"({bic_before:.1f}) and lower the selection window's J ({J_before:.3g} C2) by more than the noise "
                  f"and the residuals' own correlated scatter could ({tests[label(chosen)]['selection_margin']:.3g} C2 "
                  "for it)")
        if chosen is best:
            reason = (f"{what[0].upper() + what[1:]} fits the selection window best ({chosen['selection']['rmse']:.3f} C, "
                      f"{rmse_before:.3f} C before) {passed}")
        else:
            reason = (f"{what[0].upper() + what[1:]} ({chosen['selection']['rmse']:.3f} C on the selection window, "
                      f"{rmse_before:.3f} C before) {passed}: {best['effect']} on {best['target']} fits it "
                      f"a little better ({best['selection']['rmse']:.3f} C) but not by a margin the paired test "
                      "can tell from the noise, and a physical effect with fewer parameters is preferred")
        if is_shape(chosen["effect"]):
            reason += "; no physical effect comes within the paired margin of it"
        reason += "."
    elif not results:
        reason = "No candidate effect was tried, so the model is left as it is."
    else:
        n_bic = sum(t["beats_bic"] for t in tests.values())
        n_sel = sum(t["beats_selection"] for t in tests.values())
        reason = (f"None of the {len(results)} candidates that physics admits both beats the model without them "
                  f"on BIC ({n_bic} do) and lowers the selection window's J by more than the noise and the "
                  f"residuals' own correlated scatter could ({n_sel} do): no effect is added.")
    if suggestions:
        reason += " Not added, though the data support them: " + "; ".join(
            f"{s['candidate']} ({s['reason']})" for s in suggestions) + "."
    return chosen, {"chosen": label(chosen) if chosen else None, "reason": reason,
                    "bic_baseline": bic_before, "selection_J_before": J_before, "selection_margin": margin,
                    "suggestions": suggestions, "candidates": tests}


def acting(result):
    """How a shape's heat source acts, in words: with a daily profile, or in proportion to an input."""
    values = {name: p["value"] for name, p in result["parameters"].items()}
    if result["effect"] == "daily_gain":
        amplitude = math.hypot(values.get("cos1", 0.0), values.get("sin1", 0.0))
        return (f"with a daily profile (mean {values['mean']:.3g} W, first harmonic {amplitude:.3g} W) to the air "
                f"of {result['target']}")
    zone, column = bridge_parts(result["target"])
    return f"in proportion to {column} (k = {values['k']:.3g}) to the air of {zone}"


def candidate_objection(building, result):
    """Why physics refuses a calibrated candidate (`candidates.objection`), or None."""
    return objection(building, result["effect"], result["target"], result["parameters"], result.get("derived"))


def label(result):
    return f"{result['effect']}@{result['target']}"


@dataclass
class Model:
    """A model of the loop: its building, its objective air simulated on the calibration window
    (`fitted`) and over the whole record (`run`), its metrics and fitted parameter count."""
    building: object
    fitted: np.ndarray
    run: np.ndarray
    metrics: dict
    k: int = 0


def assess_all(model, pairs, calibration, case, objective, folder, seed, workers, fmu_kind, k):
    """Each (effect, target) added to `model`, calibrated on `calibration` (the fitting window,
    t_0..t_j) and run, in parallel worker processes (which end with this process:
    nodeforce.lifetime): the candidates' records, their `Model`s by label, their Morris
    screenings, and their residuals on the selection window t_j+1..t_k."""
    tasks = [(model.building, effect, target, folder, calibration, case, objective, seed, fmu_kind)
             for effect, target in pairs]
    n_workers = min(workers or os.cpu_count(), len(tasks))
    with (lifetime.worker_pool(n_workers) if n_workers > 1 else nullcontext()) as pool:
        assessed = list(tqdm((pool.map if pool else map)(assess, tasks), total=len(tasks),
                             desc="calibrating candidate effects", unit="candidate",
                             disable=not sys.stderr.isatty()))
    scored, measured = objective.measured(calibration), objective.measured(case)
    j = len(calibration.times) - 1
    chosen_on = slice(j, k)
    results, models, sensitivities, selection = [], {}, {}, {}
    for (effect, target), (parameters, determined, fitted, run, screening) in zip(pairs, assessed):
        fit = objective.metrics(scored, fitted)
        left = measured[chosen_on] - run[chosen_on]
        fall, sd = change_of_J(measured[chosen_on] - model.run[chosen_on], left, bandwidth(case.dt))
        result = {"effect": effect, "target": target, "parameters": parameters, "derived": determined,
                  "calibration": fit, "selection": objective.metrics(measured[chosen_on], run[chosen_on]),
                  "validation": objective.metrics(measured[k:], run[k:]),
                  "selection_fall": {"J": fall, "sd": sd},
                  "bic": bic(fit["J"], fit["n"], model.k + len(parameters))}
        values = {name: p["value"] for name, p in parameters.items()}
        models[label(result)] = Model(EFFECTS[effect].apply(model.building, target, values), fitted, run,
                                      {w: result[w] for w in ("calibration", "selection", "validation")},
                                      model.k + len(parameters))
        results.append(result)
        sensitivities[label(result)] = screening
        selection[label(result)] = left
    return results, models, sensitivities, selection


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
    j = selection_split(case, k, source)
    # the forcing search and the candidates' fits read the calibration window's first part (the
    # fitting window), the choice its rest (the selection window); the validation window only reports
    fitting = case.window(0, j)
    measured = objective.measured(case)
    scored = objective.measured(fitting)
    noise = Noise.of(measured, noise)
    sigma = noise.sigma

    with FmuInstance(build_fmu(building, workdir / "model_before.fmu", kind=fmu_kind)) as base:
        before_run = simulate_fmu(base, case, output_ids=objective.air_nodes)
        before_fitting = simulate_fmu(base, fitting, output_ids=objective.air_nodes)
    before = {"calibration": objective.metrics(scored, before_fitting),
              "selection": objective.metrics(measured[j:k], before_run[j:k]),
              "validation": objective.metrics(measured[k:], before_run[k:])}
    model = Model(building, before_fitting, before_run, before)

    convergence = []
    localization = locate(building, fitting, objective, workdir, source=source, seed=seed,
                          workers=workers, population=population, generations=generations, fmu_kind=fmu_kind,
                          noise=noise.sigma if noise.given else None,
                          progress=lambda generation, total, J, unique: convergence.append((generation, J)))

    folder = workdir / "candidates"
    folder.mkdir(exist_ok=True)
    # What the model's residual follows (an input, the time of day) points at effects of that
    # shape, tried beside those the forcing search points at; after a choice, the residual left
    # is asked again, and what it points at is tried on top, by the same rules.
    def left_by(model):
        shaped = shaped_inputs(model.building)
        inputs = {name: values for name, values in zip(case.input_names, case.U[1:j + 1].T) if name in shaped}
        return residual_diagnostics(fitting.times[1:], scored[:, 0] - model.fitted[:, 0], inputs)

    pairs = candidates(building, localization["best_nodes"], objective.zones)
    pairs += [pair for pair in follow_up(building, left_by(model), objective.zones) if pair not in pairs]
    results, models, sensitivities, selection = assess_all(model, pairs, fitting, case, objective, folder, seed,
                                                           workers, fmu_kind, k)
    chosen, decision = decide(building, results, before, sigma, selection)
    runs = {key: m.run for key, m in models.items()}
    results = [{**r, "bic_baseline": decision["bic_baseline"]} for r in results]
    added = [chosen] if chosen else []
    model = models[label(chosen)] if chosen else model

    left = left_by(model)
    follow = [pair for pair in follow_up(model.building, left, objective.zones)
              if pair not in [(a["effect"], a["target"]) for a in added]]
    decision["structure_left"] = left["sentence"]
    if follow:
        more, more_models, more_sensitivities, more_selection = assess_all(model, follow, fitting, case, objective,
                                                                           folder, seed, workers, fmu_kind, k)
        then, follow_decision = decide(model.building, more, model.metrics, sigma, more_selection, model.k)
        results += [{**r, "on_top_of": [label(a) for a in added], "bic_baseline": follow_decision["bic_baseline"]}
                    for r in more]
        sensitivities.update(more_sensitivities)
        runs.update({key: m.run for key, m in more_models.items()})
        decision["follow_up"] = follow_decision  # its own candidates: one may repeat a first-round label
        decision["reason"] += (f" The residual left on the fitting window ({left['sentence']}) points at "
                               f"{', '.join(f'{e} on {t}' for e, t in follow)}: {follow_decision['reason']}")
        if then:
            added.append(then)
            model = more_models[label(then)]
            decision["chosen"] = label(then)

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
                   "fitting": [times[0].isoformat(), times[j].isoformat()],
                   "selection": [times[j + 1].isoformat(), times[k].isoformat()],
                   "validation": [times[k + 1].isoformat(), times[-1].isoformat()],
                   "roles": {"calibration": "the fitting and the selection windows together",
                             "fitting": "the forcing search and the candidates' fits (and BIC) read it; the "
                                        "'calibration' metrics are on it",
                             "selection": "the candidates are chosen on it (paired tests)",
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
