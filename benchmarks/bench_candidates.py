"""What a diagnosis's candidates cost (docs/performance.md, "The candidates' cost"): benchmark
records (`benchmarks/records.py`, draw 0) diagnosed in this process alone (no worker pool, so
that a round's seconds are its candidates' processor time), each round's candidates,
simulations and seconds as its report.json gives them, beside the floor: one simulation of the
record as a calibration runs it (`Case.run` of the whole record, the median of 5) times the
runs a fit of k parameters cannot do without, 1 + k per candidate.

    python benchmarks/bench_candidates.py                     # the records below
    python benchmarks/bench_candidates.py twin-gso-feb/W8-L   # others

Run it in two checkouts to compare them (this file copied into the older).
"""
import contextlib
import io
import json
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1]))

from benchmarks.bench_runs import run_time  # noqa: E402
from benchmarks.records import record  # noqa: E402
from nodeforce import api  # noqa: E402

RECORDS = ("mia-jun/door-s", "gso-apr/gain-L", "twin-gso-feb/W8-L")


def measured(name):
    """(the diagnosis's wall seconds, its rounds' cost [{"candidates", "simulations",
    "seconds"}], the runs the rounds' fits cannot do without (sum of 1 + k), one simulation's
    seconds) of the record's draw 0."""
    r = record(name, 0)
    case = r.case()
    one = run_time(case, r.building, 5)
    with tempfile.TemporaryDirectory() as out, contextlib.redirect_stdout(io.StringIO()):
        started = time.perf_counter()
        api.diagnose(r.building, case, Path(out), objective=api.objective(r.building, r.zones),
                     search=api.SearchSettings(noise=r.spec.noise, seed=0), execution=api.Execution(workers=1))
        wall = time.perf_counter() - started
        report = json.loads((Path(out) / "report.json").read_text())
    rounds = [d["cost"] for d in report["decision"]["rounds"]]
    floor = sum(1 + len(c["parameters"]) for c in report["candidates"])
    return wall, rounds, floor, one


def main(names):
    print("| record | diagnosis (s) | rounds | candidates | simulations / candidate | s / candidate | "
          "one simulation (ms) | floor: (1 + k) simulations / candidate (s) | s / candidate over the floor |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name in names or RECORDS:
        wall, rounds, floor, one = measured(name)
        candidates = sum(c["candidates"] for c in rounds)
        simulations = sum(c["simulations"] for c in rounds)
        seconds = sum(c["seconds"] for c in rounds)
        print(f"| {name} | {wall:.1f} | {len(rounds)} | {candidates} | {simulations / candidates:.1f} | "
              f"{seconds / candidates:.3f} | {1e3 * one:.1f} | {floor / candidates * one:.3f} | "
              f"{seconds / (floor * one):.1f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
