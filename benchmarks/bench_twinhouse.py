"""Speed on a real house: one simulation of the Twin House N2 ground floor (261 nodes, about 5000
steps of 10 min) by the direct model, through the Python FMU and through the standalone FMU.

Needs `make twinhouse` to have converted the repository's data (examples/twinhouse_n2/data/) into
out/twinhouse/ (weather.csv, measurements.csv). Run: `.venv/bin/python benchmarks/bench_twinhouse.py`.
"""
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.fmu_build.build import build_fmu
from nodeforce.iotools.measurements import read_measurements
from nodeforce.iotools.weather import read_weather
from nodeforce.model.building_file import load_building
from nodeforce.model.case import prepare_case
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble
from nodeforce.model.score import Objective

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "out" / "twinhouse"


def timed(run, repeats=3):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = run()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


def main():
    if not (OUT / "measurements.csv").exists():
        print(f"{OUT / 'measurements.csv'} is missing: run `make twinhouse` first", file=sys.stderr)
        return 2
    building = load_building(ROOT / "examples" / "twinhouse_n2" / "building.json")
    case = prepare_case(building, read_weather(OUT / "weather.csv"),
                        read_measurements(OUT / "measurements.csv")).with_burn_in(3)
    objective = Objective.of(building, ["living"])
    network = assemble(building)
    steps = len(case.times) - 1 + 2 * 144
    print(f"Twin House N2: {building.n_nodes} nodes, {len(case.input_names)} inputs, {steps} steps incl. warm-up")
    t_direct, T = timed(lambda: simulate(building, network, case.U, case.dt, case.measured,
                                         burn_in_steps=case.burn_in_steps, substeps=case.substeps))
    print(f"direct model          {t_direct:7.2f} s  ({t_direct / steps * 1e6:6.0f} us/step)")
    with tempfile.TemporaryDirectory(prefix="nodeforce_bench_") as tmp:
        for kind in ("python", "standalone"):
            with FmuInstance(build_fmu(building, Path(tmp) / f"{kind}.fmu", kind=kind)) as instance:
                t, air = timed(lambda: simulate_fmu(instance, case, output_ids=objective.air_nodes))
            error = np.abs(air[:, 0] - T[:, objective.air_nodes[0] - 1]).max()
            print(f"{kind + ' FMU':<21} {t:7.2f} s  ({t / steps * 1e6:6.0f} us/step), "
                  f"living air within {error:.1e} C of the direct model")
    return 0


if __name__ == "__main__":
    sys.exit(main())
