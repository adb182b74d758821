"""The cost of one fmi2GetReal call to the Python FMU, in a host that reads the outputs one
value per call (as the FMI Compliance Checker does) against one that reads them all in one call.

Each FMU runs its default experiment (a day of 900-s steps) in the project's C host
(tests/c_host/host.c, no Python in its process: the guard loads libpython), all N outputs read
after each step; the host times its own step loop. The standalone FMU is the reference.
Run: `.venv/bin/python benchmarks/bench_fmu_calls.py` (about a minute).
"""
import re
import statistics
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the C host's runner lives with the tests

from fmpy import read_model_description  # noqa: E402

from nodeforce.fmu_build.build import build_fmu  # noqa: E402
from nodeforce.model.building_file import load_building  # noqa: E402
from tests.test_standalone import python_host_environment, run_c_host  # noqa: E402

BUILDINGS = {"test cell": ROOT / "model" / "data" / "testcell_miami.json",
             "Twin House N2": ROOT / "examples" / "twinhouse_n2" / "building.json"}


def stepping(fmu, folder, one_by_one, repeats=3):
    """Median time (s) of the host's step loop over the FMU's default experiment."""
    md = read_model_description(str(fmu))
    experiment = md.defaultExperiment
    step, stop = float(experiment.stepSize), float(experiment.stopTime)
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    times = []
    for _ in range(repeats):
        done, _ = run_c_host(fmu, {"T_start[1]": 20.0}, {}, outputs, step, round(stop / step), folder,
                             env=python_host_environment(), one_by_one=one_by_one)
        if done.returncode:
            raise RuntimeError(done.stderr)
        times.append(float(re.search(r"stepping ([0-9.]+) s", done.stderr).group(1)))
    return statistics.median(times), len(outputs), round(stop / step)


def measure():
    """Each building's FMUs in the C host: {"tables": Markdown lines, "per_call_us": {building: {kind: us}}}."""
    tables = ["| building | FMU | outputs N | a step loop, one call for all | N calls | a call more |",
              "|---|---|---|---|---|---|"]
    figures = {}
    with tempfile.TemporaryDirectory(prefix="nodeforce_bench_") as tmp:
        for label, path in BUILDINGS.items():
            building = load_building(path)
            for kind in ("python", "standalone"):
                folder = Path(tmp) / f"{label}_{kind}".replace(" ", "_")
                folder.mkdir()
                fmu = build_fmu(building, folder / "model.fmu", kind=kind)
                together, n, n_steps = stepping(fmu, folder, one_by_one=False)
                apart, _, _ = stepping(fmu, folder, one_by_one=True)
                per_call = (apart - together) / (n_steps * (n - 1))
                figures.setdefault(label, {})[kind] = per_call * 1e6
                tables.append(f"| {label} | {kind} | {n} | {together:.3f} s | {apart:.3f} s | {per_call * 1e6:.2f} us |")
    return {"tables": tables, "per_call_us": figures}


def main():
    print("\n".join(measure()["tables"]))


if __name__ == "__main__":
    sys.exit(main())
