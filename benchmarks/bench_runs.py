"""The cost of one simulation of a record as a diagnosis runs it (`model.case.Case.run`: the
history, the burn-in, the sub-steps), on a few of the benchmark's records (docs/performance.md,
"The diagnosis on one machine").

    python benchmarks/bench_runs.py                 # the records below
    python benchmarks/bench_runs.py mia-jun/door-s  # others

Each record's case and building as `benchmarks/records.py` makes them (draw 0); the median of
`RUNS` runs in this process after one not counted, every node returned (the call every version
of the code has). Run it in two checkouts to compare them.
"""
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1]))

from benchmarks.records import record  # noqa: E402

RECORDS = ("mia-jun/door-s", "gso-apr/gain-L", "twin-gso-feb/W8-L")
RUNS = 10


def timed(name):
    """(steps, median ms) of `Case.run` of the record's building on its case."""
    r = record(name, 0)
    case = r.case().with_inputs(r.building)
    case.run(r.building)
    seconds = []
    for _ in range(RUNS):
        started = time.perf_counter()
        case.run(r.building)
        seconds.append(time.perf_counter() - started)
    return (len(case.U) - 1) * case.substeps, 1e3 * statistics.median(seconds)


def main(names):
    print("| record | steps | Case.run (ms, median of %d) |" % RUNS)
    print("|---|---|---|")
    for name in names or RECORDS:
        steps, ms = timed(name)
        print(f"| {name} | {steps:,} | {ms:.1f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
