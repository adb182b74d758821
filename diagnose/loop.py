"""`nodeforce diagnose`: from the residual to the missing effect, added, calibrated, and judged
on data the calibration did not see.

1. The record is split by time into a calibration window and a later validation window. The
   calibration window's first `BURN_IN_DAYS` are simulated but not scored: the warm-up of
   PHYSICS.md section 5 replays the first day, so the fast nodes start from that day's end
   rather than from the real day before, and a correct model misses the first day by tenths of
   a degree (0.74 C on average on the bundled data); scored, that transient is "explained" by
   forcing any large surface and hides the real fault.
2. Before: the building as described, simulated through its FMU; metrics on both windows (the
   calibration window is simulated on its own, as the calibration sees it; the validation window
   is the tail of a run over the whole record, so it starts from the state the past left).
3. The forcing search (`ga.locate`) on the calibration window localises nodes.
4. Candidates: the effects of the localised nodes' components, and of the air node's own
   equation (`model.effects.candidates`), each its own FMU with the effect's parameters, and,
   once calibrated, its own building file (`candidates/<effect>@<target>.json/.fmu`).
5. Each is calibrated on the calibration window (`diagnose.calibrate`), the candidates in
   parallel worker processes.
6. The chosen effect has the best validation error among those that beat the model without
   them on BIC (calibration window) and lower the validation J by more than noise could
   (`ga.parsimony.tolerance`); "none" if no candidate does. The calibration window alone never
   decides.
"""
import json
import math
import multiprocessing
import os
import sys
from concurrent.futures import ProcessPoolExecutor
from contextlib import nullcontext

import numpy as np
from tqdm import tqdm

from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.diagnose.calibrate import Candidate, calibrate, sensitivity
from nodeforce.diagnose.report import write_report
from nodeforce.fmu_build.build import build_fmu
from nodeforce.ga.locate import locate, output_node
from nodeforce.ga.parsimony import tolerance
from nodeforce.model import effects
from nodeforce.model.building import parse_building
from nodeforce.model.errors import InputError
from nodeforce.model.integrate import steps_per_day
from nodeforce.model.score import metrics, noise_level

BURN_IN_DAYS = 1


def split(case, fraction, source):
    """Row index k of the last calibration time: t_0..t_k calibrate, t_k+1..t_N validate."""
    n = len(case.times) - 1
    k = int(round(fraction * n))
    day = steps_per_day(case.dt)
    if k < (BURN_IN_DAYS + 1) * day or n - k < day:
        raise InputError(source, "time", f"{n} steps of {case.dt:g} s are too short to split {fraction:.0%} / "
                                          f"{1 - fraction:.0%} into a calibration window of {BURN_IN_DAYS + 1} days "
                                          f"and a validation window of a day at least")
    return k


def assess(task):
    """Calibrate one candidate effect and run it: a task for a worker process.

    Returns the calibrated parameters, what the data determine, the simulated air on the
    calibration window and over the whole record, and the Morris screening; writes the
    candidate's FMU and its building file, declared at the calibrated values, in `folder`.
    """
    building_data, effect, target, folder, calibration, case, air, seed, fmu_kind = task
    candidate = Candidate(building_data, effect, target, folder, fmu_kind)
    try:
        parameters, determined = calibrate(candidate, calibration, air)
        values = [parameters[p.name]["value"] for p in candidate.parameters]
        fitted = candidate.air(calibration, air, values)
        run = candidate.air(case, air, values)
        screening = sensitivity(candidate, calibration, air, seed=seed)
    finally:
        candidate.close()
    calibrated = effects.apply(building_data, effect, target, {name: p["value"] for name, p in parameters.items()})
    (folder / f"{candidate.label}.json").write_text(json.dumps(calibrated, indent=2) + "\n")
    return parameters, determined, fitted, run, screening


def bic(J, n, k):
    """Bayesian information criterion of a least-squares fit with k parameters on n residuals."""
    return n * math.log(J / n) + k * math.log(n)


def diagnose(building_data, building, case, workdir, *, source="measurements", fraction=0.6, seed=0,
             workers=None, population=30, generations=400, fmu_kind="python"):
    """Run the whole loop; write the artifacts in `workdir`; return the report.json content."""
    air = output_node(building, case, source)
    k = split(case, fraction, source)
    calibration = case.window(0, k).unscored_start(air, BURN_IN_DAYS)
    measured = case.measured[1:, air - 1]
    scored = calibration.measured[1:, air - 1]
    sigma = noise_level(case.measured[:, air - 1])

    with FmuInstance(build_fmu(building_data, workdir / "model_before.fmu", source=building.source,
                               kind=fmu_kind)) as base:
        before_run = simulate_fmu(base, case, output_ids=[air])[:, 0]
        before_calibration = simulate_fmu(base, calibration, output_ids=[air])[:, 0]
    before = {"calibration": metrics(scored, before_calibration),
              "validation": metrics(measured[k:], before_run[k:])}

    convergence = []
    localization = locate(building_data, building, calibration, workdir, source=source, seed=seed,
                          workers=workers, population=population, generations=generations, fmu_kind=fmu_kind,
                          progress=lambda generation, total, J, unique: convergence.append((generation, J)))

    pairs = effects.candidates(building_data, localization["best_nodes"])
    (workdir / "candidates").mkdir(exist_ok=True)
    tasks = [(building_data, effect, target, workdir / "candidates", calibration, case, air, seed, fmu_kind)
             for effect, target in pairs]
    n_workers = min(workers or os.cpu_count(), len(tasks))
    with (ProcessPoolExecutor(n_workers, mp_context=multiprocessing.get_context("spawn"))
          if n_workers > 1 else nullcontext()) as pool:
        assessed = list(tqdm((pool.map if pool else map)(assess, tasks), total=len(tasks),
                             desc="calibrating candidate effects", unit="candidate",
                             disable=not sys.stderr.isatty()))
    results, runs, sensitivities = [], {}, {}
    for (effect, target), (parameters, determined, fitted, run, screening) in zip(pairs, assessed):
        label = f"{effect}@{target}"
        runs[label], sensitivities[label] = run, screening
        fit = metrics(scored, fitted)
        results.append({"effect": effect, "target": target, "parameters": parameters, "derived": determined,
                        "calibration": fit, "validation": metrics(measured[k:], run[k:]),
                        "bic": bic(fit["J"], fit["n"], len(parameters))})

    bic_before = bic(before["calibration"]["J"], before["calibration"]["n"], 0)
    margin = tolerance(before["validation"]["J"], sigma, before["validation"]["n"])
    better = [r for r in results if r["bic"] < bic_before
              and r["validation"]["J"] < before["validation"]["J"] - margin]
    chosen = min(better, key=lambda r: r["validation"]["rmse"]) if better else None

    if chosen:
        values = {name: p["value"] for name, p in chosen["parameters"].items()}
        data_after = effects.apply(building_data, chosen["effect"], chosen["target"], values)
        after_run = runs[f"{chosen['effect']}@{chosen['target']}"]
        after = {w: chosen[w] for w in ("calibration", "validation")}
        effect = {key: chosen[key] for key in ("effect", "target", "parameters", "derived")}
    else:
        data_after, after_run, after = building_data, before_run, before
        effect = {"effect": "none", "target": None, "parameters": {}}
    parse_building(data_after, source="building_after.json")
    (workdir / "building_after.json").write_text(json.dumps(data_after, indent=2) + "\n")
    fmu_after = build_fmu(data_after, workdir / "model_after.fmu", source="building_after.json", kind=fmu_kind)

    times = case.times
    report = {
        "period": {"calibration": [times[0].isoformat(), times[k].isoformat()],
                   "calibration_scored_from": times[case.steps(BURN_IN_DAYS) + 1].isoformat(),
                   "validation": [times[k + 1].isoformat(), times[-1].isoformat()]},
        "before": before,
        "localization": localization,
        "candidates": [{**r, "bic_baseline": bic_before} for r in results],
        "effect": effect,
        "after": after,
        "sensitivity": sensitivities,
        "noise_sigma": sigma,
        "artifacts": {"building_after": str(workdir / "building_after.json"), "fmu_after": str(fmu_after)},
    }
    series = {"times": times[1:], "measured": measured, "before": before_run, "after": after_run,
              "validation_start": times[k + 1], "convergence": convergence, "air_node": air}
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
