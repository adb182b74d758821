"""The door case of examples/calibrate_fmu.py calibrated by AixCaliBuHA, through the FMU alone.

AixCaliBuHA (pip install AixCaliBuHA==1.2.0; it needs pandas < 3, see docs/fmu.md) runs the
FMU through ebcpy's `FMU_API`, which calls FMPy's `simulate_fmu` with the inputs held over each
communication step (it passes no input derivatives). A held input lags by half a step, so the
communication step must be short: docs/fmu.md gives the recovered factor against the step.

    python examples/calibrate_fmu.py -o OUT            # nodeforce's part: OUT/testcell.fmu, inputs, measurements
    python examples/calibrate_aixcalibuha.py OUT [--step 60]

reads OUT/testcell.fmu, OUT/inputs.csv (with OUT/inputs.start.json) and OUT/measurements.csv
as any tool would, calibrates `door.conductivity_factor` on the measured air after the first
day (over which the table holds the sensors' nodes at their measurements), estimates its
standard deviation from the residuals' sensitivity, and writes OUT/estimate_aixcalibuha.json.
Everything AixCaliBuHA writes goes to a temporary folder, removed at the end.
"""
import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
from aixcalibuha import CalibrationClass, Calibrator, Goals, TunerParas
from ebcpy import FMU_API
from fmpy import read_model_description

PARAMETER = "door.conductivity_factor"
AIR = 23  # the cell's air node
BURN_IN = 86400.0  # s: the first day, whose air the fit does not score


def arguments(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("folder", type=Path, help="the output folder of examples/calibrate_fmu.py")
    p.add_argument("--step", type=float, default=60.0, help="the communication step (s), a divisor of 900")
    return p.parse_args(argv)


def read_files(folder):
    """(FMU path, inputs indexed by s, start values, the measured air indexed by s)."""
    inputs = pd.read_csv(folder / "inputs.csv", index_col="time")
    start = json.loads((folder / "inputs.start.json").read_text())
    measured = pd.read_csv(folder / "measurements.csv", index_col=0, parse_dates=True)
    air = measured[[f"T{AIR}"]].set_axis((measured.index - measured.index[0]).total_seconds().to_numpy())
    return folder / "testcell.fmu", inputs, start, air


def calibrate(folder, step):
    fmu, inputs, start, air = read_files(folder)
    variable = next(v for v in read_model_description(str(fmu)).modelVariables if v.name == PARAMETER)
    bounds = (float(variable.min), float(variable.max))
    stop = float(air.index[-1])
    interval = float(air.index[1] - air.index[0])
    if abs(round(interval / step) * step - interval) > 1e-9:
        raise SystemExit(f"--step {step:g}: not a divisor of the record's {interval:g} s")
    with tempfile.TemporaryDirectory(prefix="calibrate_aixcalibuha_") as work:
        sim_api = FMU_API(model_name=str(fmu), working_directory=work)
        try:
            sim_api.set_sim_setup({"start_time": 0.0, "stop_time": stop, "output_interval": step})
            sim_api.result_names = [f"T[{AIR}]"]
            # AixCaliBuHA compares the simulated and the measured air row by row and steps the FMU
            # at the measurements' interval: the measured air on the grid of the step, empty between
            # samples, and the fit's intervals the samples after the burn-in
            grid = np.arange(0.0, stop + step / 2, step)
            goals = Goals(meas_target_data=air.reindex(grid), variable_names={"air": [f"T{AIR}", f"T[{AIR}]"]},
                          statistical_measure="RMSE")
            tuner = TunerParas(names=[PARAMETER], initial_values=[1.0], bounds=[bounds])
            samples = [(t, t) for t in air.index if t >= BURN_IN]
            case = CalibrationClass(name="door", start_time=0.0, stop_time=stop, goals=goals, tuner_paras=tuner,
                                    relevant_intervals=samples, inputs=inputs)
            calibrator = Calibrator(working_directory=work, sim_api=sim_api, calibration_class=case,
                                    fixed_parameters=start, show_plot=False, create_tsd_plot=False,
                                    verbose_logging=False)
            # AixCaliBuHA optimises the parameters scaled to their bounds
            found = calibrator.calibrate(framework="scipy_minimize", method="L-BFGS-B",
                                         x0=np.asarray(tuner.scale(tuner.get_initial_values()), dtype=float))
            value = float(found[PARAMETER])
            std, rmse = uncertainty(sim_api, inputs, start, air, value)
        finally:
            sim_api.close()
    return {"value": value, "std": std, "bounds": bounds, "rmse": rmse, "step": step, "tool": "AixCaliBuHA"}


def uncertainty(sim_api, inputs, start, air, value, relative=1e-3):
    """The estimate's standard deviation from the scored residuals r and their sensitivity J to
    the parameter (a finite difference): sqrt(s2 / J'J), s2 = r'r / (n - 1); and the RMSE."""
    def residuals(x):
        result = sim_api.simulate(parameters={**start, PARAMETER: x}, inputs=inputs)
        simulated = result[f"T[{AIR}]"].reindex(air.index, method="nearest", tolerance=1e-6).to_numpy()
        scored = air.index.to_numpy() >= BURN_IN
        return (air[f"T{AIR}"].to_numpy() - simulated)[scored]
    r = residuals(value)
    J = (residuals(value * (1 + relative)) - r) / (value * relative)
    s2 = r @ r / (len(r) - 1)
    return float(np.sqrt(s2 / (J @ J))), float(np.sqrt(np.mean(r ** 2)))


def main(argv=None):
    args = arguments(argv)
    estimate = calibrate(args.folder, args.step)
    (args.folder / "estimate_aixcalibuha.json").write_text(json.dumps(estimate, indent=1) + "\n")
    print(f"{PARAMETER} = {estimate['value']:.3f} +- {estimate['std']:.3f} (the real door: {0.78 / 0.23:.3f}; "
          f"AixCaliBuHA, steps of {args.step:g} s, inputs held; air RMSE {estimate['rmse']:.3f} C)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
