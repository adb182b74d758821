"""A calibration by another tool: scipy's least squares over FMPy, through the FMU's parameters alone.

The paper's door case: the test cell's door is of wood that conducts 0.78 W/m/K where the
building file says 0.23, so the real door conducts 0.78 / 0.23 = 3.39 times what the model
does. nodeforce only prepares what any tool would be handed: the model as an FMU, the table of
its inputs, and the measurements (made here from the "real" cell, 0.1 C of sensor noise). From
there on this script knows nothing of nodeforce: it reads the FMU's model description, sets
`door.conductivity_factor` (a parameter of every FMU nodeforce writes, bounded by its min and
max), simulates with FMPy's `simulate_fmu` and fits the measured air with
`scipy.optimize.least_squares`.

What the FMU asks of a host, as any tool must give it:
- one doStep of h seconds is a backward-Euler step with the inputs set before it: the step from
  t takes the inputs of t + h, so the input table is given one step ahead;
- h of at most 5 min, as nodeforce steps it (docs/model.md, section 5.1): a record sampled
  every 15 min is stepped three times per sample, FMPy interpolating the inputs between samples
  (a heater's power, which nodeforce holds over the interval, would need a table that holds it);
- the state at the start is `T_start[i]`: the measured nodes at their measurement at t_0 and the
  rest, here, at the measured air's;
- a node i with `force[i]` set is held at the input `T_forced[i]` wherever that is not NaN.
Over the first day every sensor's node is held at its measurement (a burn-in: the record, not
the guess at t_0, sets the walls' state), then freed (NaN); the fit scores the days after it.

    python examples/calibrate_fmu.py -o OUT [--days 8] [--kind standalone|python] [--fit-until TIME]

writes OUT/testcell.fmu, OUT/inputs.csv and OUT/measurements.csv, fits the record up to TIME
(default: all of it), prints the estimate with its standard deviation and writes
OUT/estimate.json. `nodeforce diagnose model/data/testcell_miami.json --weather
model/data/miami_tmy2.csv --measurements OUT/measurements.csv --burn-in-days 1 -o DIAGNOSIS`
finds the same effect; fitted up to the end of that report's calibration window (the part of the
record its calibration reads), this script gives its value within its uncertainty
(tests/test_calibrate_fmu.py).
"""
import argparse
import copy
import json
import math
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
    p.add_argument("--seed", type=int, default=5)
    return p.parse_args(argv)


def door_case(folder, days, kind, seed):
    """nodeforce's part: the FMU of the building file, its inputs (t_0..t_N, one column per FMU
    input) and the measurements of the real cell. Returns their paths."""
    import pandas as pd

    import nodeforce
    from nodeforce.fmu_build.build import build_fmu
    from nodeforce.model.building import parse_building
    from nodeforce.model.synth import pseudo_measurements

    data = json.loads((DATA / "testcell_miami.json").read_text())
    real = copy.deepcopy(data)
    real["materials"]["wood"]["conductivity"] = 0.78
    weather = nodeforce.read_weather(DATA / "miami_tmy2.csv")
    times = pd.date_range("2001-06-10 00:00", periods=days * 96 + 1, freq="15min", tz="-05:00", name="time")
    measured = pseudo_measurements(parse_building(real), weather, times, SENSORS, noise_sd=0.1, seed=seed,
                                   history_days=7)
    building = parse_building(data)
    # the outside tool starts at the first measurement, from the sensors' values: no history
    case = nodeforce.measured_case(building, weather, measured, history_days=0)
    folder.mkdir(parents=True, exist_ok=True)
    fmu = build_fmu(building, folder / "testcell.fmu", kind=kind)
    pd.DataFrame(case.U, index=case.times, columns=case.input_names).to_csv(folder / "inputs.csv")
    measured.to_csv(folder / "measurements.csv")
    return fmu, folder / "inputs.csv", folder / "measurements.csv"


def read_table(path, until=None):
    """(seconds from the first row, column names, values) of a CSV time table, up to `until`."""
    import pandas as pd
    table = pd.read_csv(path, index_col=0, parse_dates=True)
    if until is not None:
        table = table[table.index <= pd.Timestamp(until)]
    seconds = (table.index - table.index[0]).total_seconds().to_numpy()
    return seconds, list(table.columns), table.to_numpy(dtype=float)


def calibrate(fmu, inputs_path, measurements_path, until=None):
    """The outside tool: least squares of the measured air over `door.conductivity_factor`,
    through FMPy (an FMI 2.0 FMU). Returns {value, std, bounds, evaluations, rmse}."""
    description = read_model_description(str(fmu))
    variable = next(v for v in description.modelVariables if v.name == PARAMETER)
    bounds = (float(variable.min), float(variable.max))
    n_nodes = sum(v.name.startswith("T_start[") for v in description.modelVariables)
    t, names, U = read_table(inputs_path, until)
    _, measured_names, measured = read_table(measurements_path, until)
    dt = t[1] - t[0]
    k = math.ceil(dt / 300.0 - 1e-9)
    h = dt / k  # s, the step: at most 5 min
    column = dict(zip(measured_names, measured.T))
    # the burn-in: each sensor's node held at its measurement over the first day, then free
    held = {f"T_forced[{i}]": np.where(np.arange(len(t)) <= BURN_IN, column[f"T{i}"], np.nan) if i in SENSORS
            else np.full(len(t), np.nan) for i in range(1, n_nodes + 1)}
    names, U = names + list(held), np.column_stack([U, *held.values()])
    # the step from t takes the inputs of t + h: the table one step ahead
    table = np.array([tuple([time - h, *row]) for time, row in zip(t, U)],
                     dtype=[("time", float)] + [(name, float) for name in names])
    first = {f"T{i}": column[f"T{i}"][0] for i in SENSORS}
    starts = {**{f"T_start[{i}]": first.get(f"T{i}", first[f"T{AIR}"]) for i in range(1, n_nodes + 1)},
              **{f"force[{i}]": True for i in SENSORS}}
    air = column[f"T{AIR}"][1:]
    scored = np.arange(len(air)) >= BURN_IN
    evaluations = []

    def residuals(x):
        result = simulate_fmu(unzipped, start_values={**starts, PARAMETER: float(x[0])}, input=table,
                              output=[f"T[{AIR}]"], output_interval=h, stop_time=t[-1],
                              fmi_type="CoSimulation")
        simulated = result[f"T[{AIR}]"][k::k]  # at t_1..t_N, every k-th step (FMPy's CS step is the interval)
        evaluations.append(float(x[0]))
        return (air - simulated)[scored]

    with tempfile.TemporaryDirectory(prefix="calibrate_fmu_") as unzipped:
        extract(str(fmu), unzipdir=unzipped)
        fit = least_squares(residuals, [1.0], bounds=bounds, diff_step=1e-4)
    s2 = fit.fun @ fit.fun / (len(fit.fun) - 1)
    std = float(np.sqrt(s2 * np.linalg.inv(fit.jac.T @ fit.jac)[0, 0]))
    return {"value": float(fit.x[0]), "std": std, "bounds": bounds, "evaluations": len(evaluations),
            "rmse": float(np.sqrt(np.mean(fit.fun ** 2)))}


def main(argv=None):
    args = arguments(argv)
    fmu, inputs, measurements = door_case(args.output, args.days, args.kind, args.seed)
    estimate = calibrate(fmu, inputs, measurements, args.fit_until)
    (args.output / "estimate.json").write_text(json.dumps(estimate, indent=1) + "\n")
    print(f"{PARAMETER} = {estimate['value']:.3f} +- {estimate['std']:.3f} "
          f"(the real door: {0.78 / 0.23:.3f}; {estimate['evaluations']} simulations, "
          f"air RMSE {estimate['rmse']:.3f} C)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
