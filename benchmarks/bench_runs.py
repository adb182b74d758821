"""The cost of one simulation of a record as a calibration runs it, on a few of the benchmark's
records (docs/performance.md, "The diagnosis on one machine"): the effect's edit of the building
file at the parameters' values (here a conductivity factor on the building's first component:
the file copied, changed, checked and read again), the run (`model.case.Case.run`: the
history, the burn-in, the sub-steps), and the run with the derivatives of every node with
respect to that factor beside it (`Case.run(derivatives=...)`, a calibration's run; "-" in a
checkout that has none).

    python benchmarks/bench_runs.py                 # the records below
    python benchmarks/bench_runs.py mia-jun/door-s  # others

Each record's case and building as `benchmarks/records.py` makes them (draw 0); the median of
`RUNS` runs in this process after one not counted, every node returned (the call every version
of the code has). Run it in two checkouts to compare them (this file copied into the older).
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1]))

from benchmarks.bench_search import median_time  # noqa: E402
from benchmarks.records import record  # noqa: E402
from nodeforce.model import network  # noqa: E402
from nodeforce.model.effects import EFFECTS  # noqa: E402

RECORDS = ("mia-jun/door-s", "gso-apr/gain-L", "twin-gso-feb/W8-L")
RUNS = 10


def run_time(case, building, runs=RUNS):
    """The median seconds of `runs` runs of `building` on `case` (`Case.run`, every node), after
    one not counted."""
    case = case.with_inputs(building)
    return median_time(lambda: case.run(building), runs)


def derivatives_time(case, building, component, runs=RUNS):
    """The median seconds of `runs` runs of `building` on `case` with the derivatives of every
    node with respect to `component`'s conductivity factor; None where the code has none."""
    if not hasattr(network, "derivative"):
        return None
    case = case.with_inputs(building)
    moved = network.assemble(EFFECTS["conductivity"].apply(building, component, {"factor": 1.1}))
    base = network.assemble(building)
    d = network.derivative(base, moved, 0.1)
    return median_time(lambda: case.run(building, network=base, derivatives=[d]), runs)


def timed(name):
    """(steps, median ms of the edit, median ms of `Case.run`, of it with one parameter's
    derivatives or None) of the record's building."""
    r = record(name, 0)
    case = r.case()
    first = r.building.components[0].name
    edit = median_time(lambda: EFFECTS["conductivity"].apply(r.building, first, {"factor": 1.1}), RUNS)
    with_derivatives = derivatives_time(case, r.building, first)
    return ((len(case.U) - 1) * case.substeps, 1e3 * edit, 1e3 * run_time(case, r.building),
            None if with_derivatives is None else 1e3 * with_derivatives)


def main(names):
    print("| record | steps | the edit (ms, median of %d) | Case.run (ms, median of %d) | with one parameter's "
          "derivatives (ms) |" % (RUNS, RUNS))
    print("|---|---|---|---|---|")
    for name in names or RECORDS:
        steps, edit, run, with_derivatives = timed(name)
        print(f"| {name} | {steps:,} | {edit:.2f} | {run:.1f} | "
              f"{'-' if with_derivatives is None else f'{with_derivatives:.1f}'} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
