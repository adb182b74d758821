"""A calibration by another tool: scipy's least squares over FMPy, through the FMU's parameters alone.

The paper's door case: the test cell's door is of wood that conducts 0.78 W/m/K where the
building file says 0.23, so the real door conducts 0.78 / 0.23 = 3.39 times what the model
does. nodeforce only prepares what any tool would be handed: the model as an FMU, the measurements
(made here from the "real" cell, 0.1 C of sensor noise) and, with `nodeforce inputs`, the FMU's
input table and start values. From there on this script knows nothing of nodeforce: it reads the
FMU's model description, sets `door.conductivity_factor` (a parameter of every FMU nodeforce
writes, bounded by its min and max), simulates with FMPy's `simulate_fmu` and its standard
co-simulation semantics and fits the measured air with `scipy.optimize.least_squares`.

What the run gives the FMU, as FMPy does for any FMU:
- before the step from t, the inputs of t, from the table as it is (no shift), and with
  `set_input_derivatives=True` their slopes, so that the FMU's internal steps (at most
  `max_step`, 5 min) see them linear within the communication step; FMPy's slope at a row is
  that of the segment before it unless the row is repeated (its mark of a change of slope), so
  the script gives FMPy each row twice (`--slopes-behind`: once); without derivatives the
  inputs are held over each step (`--no-derivatives`: a lag of half a step);
- the start values of the table's `.start.json`: `T_start[i]` from the measurements at t_0, and
  over the first day every sensor's node held at its measurement (`force[i]`, `T_forced[i]`,
  NaN after: a burn-in, so that the record, not the guess at t_0, sets the walls' state); the
  fit scores the days after it.

    python examples/calibrate_fmu.py -o OUT [--days 8] [--kind standalone|python] [--fit-until TIME]
                                     [--step S] [--no-derivatives] [--slopes-behind]

writes OUT/testcell.fmu, OUT/inputs.csv (and OUT/inputs.start.json) and OUT/measurements.csv,
fits the record up to TIME (default: all of it) at communication steps of S seconds (default
900, the record's), prints the estimate with its standard deviation and writes
OUT/estimate.json. `nodeforce diagnose model/data/testcell_miami.json --weather
model/data/miami_tmy2.csv --measurements OUT/measurements.csv --burn-in-days 1 -o DIAGNOSIS`
finds the same effect (docs/fmu.md gives both numbers; tests/test_calibrate_fmu.py checks this
script's against the real door).
"""
import argparse
import copy
import json
import sys
import tempfile
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description, simulate_fmu
from scipy.optimize import least_squares

DATA = Path(__file__).resolve().parents[1] / "model" / "data"
PARAMETER = "door.conductivity_factor"
AIR = 23  # the cell's air node
SENSORS = (1, 7, 9, 16, 17, 23)  # the paper's
BURN_IN = 96  # samples left out of the fit: the first day


def arguments(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("-o", "--output", required=True, type=Path)
    p.add_argument("--days", type=int, default=8)
    p.add_argument("--kind", choices=("standalone", "python"), default="standalone")
    p.add_argument("--fit-until", help="the last time (ISO 8601) of the record to fit; default: its end")
    p.add_argument("--step", type=float, default=900.0, help="the communication step (s), a divisor of 900")
    p.add_argument("--no-derivatives", action="store_true", help="hold the inputs over each step (FMPy's default)")
    p.add_argument("--slopes-behind", action="store_true",
                   help="give FMPy each row once: its derivative at a row is then the slope of the segment before it")
    p.add_argument("--seed", type=int, default=5)
    return p.parse_args(argv)


def door_case(folder, days, kind, seed):
    """nodeforce's part: the FMU of the building file, the measurements of the real cell, and
    `nodeforce inputs` of them with a day's burn-in. Returns the paths of the FMU, the input
    table and the measurements."""
    import pandas as pd

    import nodeforce
    from nodeforce.model.building_file import parse_building
    from nodeforce.model.synth import pseudo_measurements

    data = json.loads((DATA / "testcell_miami.json").read_text())
    real = copy.deepcopy(data)
    real["materials"]["wood"]["conductivity"] = 0.78
    weather = nodeforce.read_weather(DATA / "miami_tmy2.csv")
    times = pd.date_range("2001-06-10 00:00", periods=days * 96 + 1, freq="15min", tz="-05:00", name="time")
    measured = pseudo_measurements(parse_building(real), weather, times, SENSORS, noise_sd=0.1, seed=seed,
                                   history_days=7)
    folder.mkdir(parents=True, exist_ok=True)
    measured.to_csv(folder / "measurements.csv")
    building = nodeforce.read_building(DATA / "testcell_miami.json")
    fmu = nodeforce.write_fmu(building, folder / "testcell.fmu", standalone=kind == "standalone")
    table, start = nodeforce.fmu_inputs(building, weather, nodeforce.read_measurements(folder / "measurements.csv"),
                                        burn_in_days=1)
    nodeforce.write_fmu_inputs(folder / "inputs.csv", table, start)
    return fmu, folder / "inputs.csv", folder / "measurements.csv"


def calibrate(fmu, inputs_path, measurements_path, until=None, step=900.0, derivatives=True, ahead=True):
    """The outside tool: least squares of the measured air over `door.conductivity_factor`,
    through FMPy (an FMI 2.0 FMU). Returns {value, std, bounds, evaluations, rmse}."""
    import pandas as pd
    from fmpy.util import read_csv

    description = read_model_description(str(fmu))
    variable = next(v for v in description.modelVariables if v.name == PARAMETER)
    bounds = (float(variable.min), float(variable.max))
    table = read_csv(inputs_path)
    if derivatives and ahead:
        # FMPy's derivative at a row is the slope of the segment that ends there; at a repeated
        # time (its mark of a discontinuity) it takes the segment after: each row twice gives the
        # FMU the slope over the step ahead, the table unchanged
        table = np.repeat(table, 2)
    starts = json.loads(Path(inputs_path).with_suffix(".start.json").read_text())
    measured = pd.read_csv(measurements_path, index_col=0, parse_dates=True)
    seconds = (measured.index - measured.index[0]).total_seconds().to_numpy()
    if until is not None:
        seconds = seconds[measured.index <= pd.Timestamp(until)]
    air = measured[f"T{AIR}"].to_numpy()[1:len(seconds)]  # at t_1..t_N
    per_sample = round((seconds[1] - seconds[0]) / step)
    if abs(per_sample * step - (seconds[1] - seconds[0])) > 1e-9:
        raise SystemExit(f"--step {step:g}: not a divisor of the record's {seconds[1] - seconds[0]:g} s")
    scored = np.arange(len(air)) >= BURN_IN
    evaluations = []

    def residuals(x):
        result = simulate_fmu(unzipped, start_values={**starts, PARAMETER: float(x[0])}, input=table,
                              output=[f"T[{AIR}]"], output_interval=step, stop_time=seconds[-1],
                              fmi_type="CoSimulation", set_input_derivatives=derivatives)
        simulated = result[f"T[{AIR}]"][per_sample::per_sample]  # at t_1..t_N
        evaluations.append(float(x[0]))
        return (air - simulated)[scored]

    with tempfile.TemporaryDirectory(prefix="calibrate_fmu_") as unzipped:
        extract(str(fmu), unzipdir=unzipped)
        fit = least_squares(residuals, [1.0], bounds=bounds, diff_step=1e-4)
    s2 = fit.fun @ fit.fun / (len(fit.fun) - 1)
    std = float(np.sqrt(s2 * np.linalg.inv(fit.jac.T @ fit.jac)[0, 0]))
    return {"value": float(fit.x[0]), "std": std, "bounds": bounds, "evaluations": len(evaluations),
            "rmse": float(np.sqrt(np.mean(fit.fun ** 2))), "step": step, "derivatives": derivatives,
            "slopes": ("ahead" if ahead else "behind") if derivatives else None}


def main(argv=None):
    args = arguments(argv)
    fmu, inputs, measurements = door_case(args.output, args.days, args.kind, args.seed)
    estimate = calibrate(fmu, inputs, measurements, args.fit_until, args.step, not args.no_derivatives,
                         not args.slopes_behind)
    (args.output / "estimate.json").write_text(json.dumps(estimate, indent=1) + "\n")
    print(f"{PARAMETER} = {estimate['value']:.3f} +- {estimate['std']:.3f} "
          f"(the real door: {0.78 / 0.23:.3f}; {estimate['evaluations']} simulations, "
          f"air RMSE {estimate['rmse']:.3f} C; steps of {args.step:g} s, "
          f"{'input derivatives' if estimate['derivatives'] else 'inputs held'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
