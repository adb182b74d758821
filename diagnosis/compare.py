"""`nodeforce compare`: building files run on one record none of them was fitted on.

A correction found by `diagnose` on one experiment is only worth what it does on another: the
house as written and as corrected are each simulated through their FMU on the same weather and
measurements (each reads the columns its own file names), and scored on the same steps: the
RMSE, mean and sd of each objective zone's air residual, overall and per phase of the
experiment, beside each model's heat loss coefficient (docs/model.md section 8). Where the record
measures heat fluxes at surfaces (the building's heat flux sensors), each model's flux through
that face is reported beside the reading: a check the fit never saw.
"""
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from nodeforce.runtime import tempdirs
from nodeforce.runtime.jsonfile import JsonFile
from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.diagnosis.report.figures import plot_comparison
from nodeforce.diagnosis.report.formats import fmt_sig, fmt_temp
from nodeforce.diagnosis.report.tables import markdown
from nodeforce.fmu_build.build import build_fmu
from nodeforce.ga.locate import check_measured
from nodeforce.model.errors import InputError
from nodeforce.model.hlc import heat_loss_coefficient
from nodeforce.model.network import assemble, face_heat_flux
from nodeforce.model.score import metrics


def run_model(building, case, output_ids, fmu_kind="python", fmu=None):
    """The nodes `output_ids` (C) at t_1..t_N of `building` simulated on `case` through its FMU:
    `fmu`, the building's own already built, or one built and removed in a temporary folder."""
    if fmu is None:
        with tempdirs.folder("compare") as tmp:
            fmu = build_fmu(building, Path(tmp) / "model.fmu", kind=fmu_kind)
            return run_model(building, case, output_ids, fmu=fmu)
    with FmuInstance(fmu) as instance:
        return simulate_fmu(instance, case, output_ids=output_ids)


def surface_fluxes(building, case, T):
    """Each heat flux sensor the record measures, its reading beside the model's: {sensor:
    {"component", "face", "measured_mean", "model_mean" (W/m2, positive into the component),
    and the residual's "rmse", "mean", "sd", "n"}} over the scored steps (after the burn-in).
    A check the diagnosis did not fit: nothing it calibrates reads a flux.

    T : (N_t, N) every node of `building` at t_1..t_N
    """
    network = assemble(building, case.input_names)
    out = {}
    for name, reading in case.fluxes.items():
        component, face = building.flux_sensors[name]
        model = face_heat_flux(building, network, T, case.U[1:], component, face)
        measured = reading[1:].copy()
        measured[:case.burn_in_steps] = np.nan
        have = np.isfinite(measured)
        if have.any():
            out[name] = {"component": component, "face": face, "measured_mean": float(measured[have].mean()),
                         "model_mean": float(model[have].mean()), **metrics(measured, model)}
    return out


@dataclass(frozen=True)
class Comparison(JsonFile):
    """Building files scored on one record (`compare`), the content of compare.json: the
    record's first and last times (`record`), the objective's zones, the first time scored
    (`scored_from`, after the burn-in), and per model (`models`, in order) its building, heat
    loss coefficient (W/K), the RMSE, mean and sd (C) of each objective zone's air residual
    (`metrics`), per phase (`phases`) and its surface heat fluxes beside the readings.
    `to_json()` is compare.json, `read(path)` reads one back, `summary()` is what
    `nodeforce compare` prints."""
    record: list
    objective: list
    scored_from: str
    models: list

    def summary(self):
        """One line per model and objective zone: its air's error and its heat loss coefficient."""
        return "\n".join(f"{m['building']}: {zone} air RMSE {z['rmse']:.3f} C (mean {z['mean']:+.3f}, sd {z['sd']:.3f}); "
                         f"heat loss coefficient {m['heat_loss_coefficient']:.1f} W/K"
                         for m in self.models for zone, z in m["metrics"]["zones"].items())


def compare(models, phases=(), fmu_kind="python", fmus=None):
    """Score each model on its record; return the content of compare.json and the series to plot.

    Parameters
    ----------
    models : [(path, Building, Case, Objective)]: each building with the record prepared for it
        (its burn-in set) and its objective; the records must share their times and the
        objectives their zone names
    phases : iotools.phases.Phase records, each model scored on each
    fmus : each model's FMU of `fmu_kind` where one is built already, else None (built here)
    """
    path0, _, case0, objective0 = models[0]
    for path, _, case, objective in models:
        if objective.zones != objective0.zones:
            raise InputError(path, "--objective", f"zones {', '.join(objective.zones)} differ from those of "
                                                  f"{path0} ({', '.join(objective0.zones)})")
        if not case.times.equals(case0.times) or case.burn_in_steps != case0.burn_in_steps:
            raise InputError(path, "time", f"its record does not have the times of {path0}'s")
        check_measured(objective, case, path)
    times = case0.times[1:]
    result = {"record": [case0.start.isoformat(), case0.times[-1].isoformat()],
              "objective": list(objective0.zones),
              "scored_from": case0.times[case0.burn_in_steps + 1].isoformat(), "models": []}
    # plotted from the first measurement: the weather's history before it is not the record
    h = case0.history_steps
    series = {"times": times[h:], "scored_from": case0.times[case0.burn_in_steps + 1], "measured": None, "runs": []}
    for (path, building, case, objective), fmu in zip(models, fmus or [None] * len(models)):
        measured = objective.measured(case)
        if case.fluxes:
            T = run_model(building, case, range(1, building.n_nodes + 1), fmu_kind, fmu)
            simulated = T[:, [i - 1 for i in objective.air_nodes]]
        else:
            simulated = run_model(building, case, objective.air_nodes, fmu_kind, fmu)
        by_phase = {}
        for phase in phases:
            inside = np.asarray(phase.mask(times))
            if np.isfinite(measured[inside]).any():
                by_phase[phase.name] = objective.metrics(measured[inside], simulated[inside])
        result["models"].append({"building": str(path), "heat_loss_coefficient": heat_loss_coefficient(building),
                                 "metrics": objective.metrics(measured, simulated), "phases": by_phase,
                                 "surface_heat_flux": surface_fluxes(building, case, T) if case.fluxes else {}})
        series["measured"] = measured[h:]
        series["runs"].append(simulated[h:])
    return result, series


def write_compare(out, result, series):
    """compare.json, the plot and compare.md in `out`; returns their paths."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    plot = plot_comparison(out / "compare.png", result, series)
    (out / "compare.json").write_text(json.dumps(result, indent=2) + "\n")
    (out / "compare.md").write_text(compare_markdown(result, plot.name))
    return out / "compare.json", out / "compare.md", plot


def compare_markdown(result, plot_name):
    """The comparison as a human reads it: per model, its heat loss coefficient and its error per
    objective zone, then the RMSE per phase."""
    names = [Path(m["building"]).name for m in result["models"]]
    zones = result["objective"]
    rows = []
    for name, m in zip(names, result["models"]):
        for zone in zones:
            z = m["metrics"]["zones"][zone]
            rows.append([name, fmt_sig(m["heat_loss_coefficient"]), zone, fmt_temp(z["rmse"]),
                         fmt_temp(z["mean"], True), fmt_temp(z["sd"]), z["n"]])
        if len(zones) > 1:
            a = m["metrics"]
            rows.append([name, fmt_sig(m["heat_loss_coefficient"]), "all", fmt_temp(a["rmse"]),
                         fmt_temp(a["mean"], True), fmt_temp(a["sd"]), a["n"]])
    md = ["# nodeforce comparison", "",
          f"Each building file simulated on the record {result['record'][0]} to {result['record'][1]}, none of "
          f"them fitted on it; residuals (measured - simulated) scored from {result['scored_from']}, after the "
          "burn-in.", "",
          markdown(["building", "heat loss coefficient (W/K)", "zone", "RMSE (C)", "mean (C)", "sd (C)", "n"], rows),
          ""]
    phases = list(dict.fromkeys(p for m in result["models"] for p in m["phases"]))
    if phases:
        md += ["## RMSE per phase (C, all objective zones)", "",
               markdown(["phase", *names], [[p, *(fmt_temp((m["phases"].get(p) or {}).get("rmse"))
                                                    for m in result["models"])] for p in phases]), ""]
    fluxes = [(name, sensor, m["surface_heat_flux"][sensor]) for name, m in zip(names, result["models"])
              for sensor in m.get("surface_heat_flux", {})]
    if fluxes:
        md += ["## Surface heat flux (W/m2, positive into the component): measured beside the model's", "",
               "A check the diagnosis did not fit: no calibration reads a heat flux.", "",
               markdown(["building", "sensor", "face", "measured mean", "model mean", "RMSE", "mean residual", "n"],
                        [[name, sensor, f"{f['component']} {f['face']}", f"{f['measured_mean']:.2f}",
                          f"{f['model_mean']:.2f}", f"{f['rmse']:.2f}", f"{f['mean']:+.2f}", f["n"]]
                         for name, sensor, f in fluxes]), ""]
    md += [f"![measured and simulated air]({plot_name})", ""]
    return "\n".join(md)
