"""nodeforce's speed, in one run on one machine: the tables of docs/performance.md.

    python benchmarks/bench_speed.py            # about 5 min on 2 cores
    python benchmarks/bench_speed.py --scale    # and the cost against the number of nodes (some 10 min more)

1. `search`: the forcing search on the paper's verification case (`bench_search.py`, items 1 to 5,
   the paper's own search left out);
2. `stages`: where a test-cell diagnosis's time goes, stage by stage (`bench_stages.py`);
3. `fmu_calls`: an FMU's outputs read in one call or one call each, in a C host (`bench_fmu_calls.py`);
4. `scale`, with --scale: the cost of a factorisation, a step and a simulation against the number of
   nodes, the test cell to a 2,922-node office (`bench_scale.py --sizes`).

The run is kept in benchmarks/results/speed-DATE.json (`benchmarks.results`), from which
docs/performance.md's tables are made (`benchmarks/pages.py`).
"""
import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks import bench_fmu_calls, bench_search, bench_stages, results  # noqa: E402


def scale():
    from benchmarks.bench_scale import bench_sizes
    with tempfile.TemporaryDirectory(prefix="nodeforce_bench_") as tmp:
        table, exponents = bench_sizes(Path(tmp), repeats=3, plot=None)
    columns = ("building", "N", "factor_dense_s", "factor_condensed_s", "step_condensed_s", "sim_direct_s",
               "sim_python_s", "sim_standalone_s", "fastest")
    lines = ["| building | nodes N | factorisation, dense (s) | factorisation, condensed (s) | step, condensed (s) "
             "| simulation: direct (s) | Python FMU (s) | standalone FMU (s) | fastest |", "|---|" + "---|" * 8]
    lines += ["| " + " | ".join(f"{row[c]:.3g}" if isinstance(row[c], float) else str(row[c]) for c in columns) + " |"
              for row in table.to_dict("records")]
    lines += ["", "The exponent b of a fit cost = a N^b over the offices: "
              + ", ".join(f"{name} {b:.2f}" for name, b in exponents.items()) + "."]
    return {"tables": lines, "rows": table.to_dict("records"), "exponents": exponents}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scale", action="store_true", help="also the cost against the number of nodes")
    args = parser.parse_args(argv)
    parts = {"search": bench_search.measure, "stages": bench_stages.measure, "fmu_calls": bench_fmu_calls.measure}
    if args.scale:
        parts["scale"] = scale
    started = results.stamp("speed", "python benchmarks/bench_speed.py" + (" --scale" if args.scale else ""))
    figures = {}
    for name, measure in parts.items():
        print(f"{name} ...", flush=True)
        figures[name] = measure()
        print("\n".join(figures[name]["tables"]), flush=True)
    print(f"kept: {results.save(started, figures)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
