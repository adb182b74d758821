"""How fast is the forcing search, and where does its time go?

Measures, in one run on one machine, on the paper's verification case (the bundled test cell in
Miami, 5 June days at 15 min = 480 steps plus a 2-day warm-up = 672 steps, pseudo-measurements
of every node from the cell with the door conductivity disturbed 0.23 -> 0.78 W/m/K):

1. one direct model simulation (`model.integrate.simulate`), median of repeated runs;
2. one FMU evaluation through the search's driver: an `ga.fitness.FmuFitness` evaluator is built
   once, as a search worker does, then `J(mask)` is timed repeatedly with one fixed forcing mask;
3. their ratio and the FMI overhead per step, (FMU evaluation - direct simulation) / steps
   (target: at most 10 us/step);
4. the bare numerical loop: backward Euler over the same inputs with a precomputed step inverse,
   `T = Minv @ (c_dt*T + source[k])` with the forced values written in, written here with no
   FMI and no model code; and population x generations (12,000) times it;
5. the paper's full GA (`ga.locate.locate`: population 30, generations 400, pc 0.8, pm 0.03,
   seed 0, os.cpu_count() workers) over the 21 non-algebraic nodes: wall time, evaluations,
   unique evaluations and the answer, against the targets (< 60 s on 2 cores, and less time
   than 12,000 runs of the bare loop).

The FMU and the search checkpoint go to a fresh temporary directory, so a run never resumes.
It uses only the project's public functions.

Run:

    make benchmark                                   # .venv/bin/python benchmarks/bench_search.py
    python benchmarks/bench_search.py [--quick]      # --quick: GA of 30 x 40, for a fast check
"""
import argparse
import copy
import json
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from nodeforce.fmu_build.build import build_fmu
from nodeforce.ga.fitness import FmuFitness
from nodeforce.ga.locate import chromosome_nodes, locate
from nodeforce.model.building import parse_building
from nodeforce.model.case import prepare_case
from nodeforce.model.integrate import initial_state, simulate, warmup_rows
from nodeforce.model.network import assemble
from nodeforce.model.score import Objective
from nodeforce.model.synth import pseudo_measurements
from nodeforce.iotools.weather import read_weather

DATA = Path(__file__).resolve().parents[1] / "model" / "data"
DAYS, WARMUP_DAYS = 5, 2
OVERHEAD_TARGET_US = 10.0  # FMI overhead per step, the target
GA_TARGET_S = 60.0  # the paper's full GA on 2 cores
PAPER_BUDGET = 30 * 400  # evaluations the paper's GA asks for


def machine():
    cpu = platform.processor()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return cpu or platform.machine()


def median_time(fn, repeats, warmup=1):
    """Median wall time (s) of fn() over `repeats` calls, after `warmup` untimed calls."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def the_case():
    """The test cell (Miami) and its case: every node measured on the door-disturbed cell."""
    data = json.loads((DATA / "testcell_miami.json").read_text())
    building = parse_building(data, source="testcell_miami.json")
    weather = read_weather(DATA / "miami_tmy2.csv")
    disturbed = copy.deepcopy(data)
    disturbed["materials"]["wood"]["conductivity"] = 0.78
    times = pd.date_range("2001-06-10 00:00", periods=DAYS * 96 + 1, freq="15min", tz="-05:00", name="time")
    measurements = pseudo_measurements(parse_building(disturbed), weather, times, list(range(1, 24)))
    return data, building, prepare_case(building, weather, measurements)


def bare_loop_setup(building, case, force):
    """Everything the bare loop reads, computed before it runs: the step inverse, the sources
    and forced values of every step (warm-up included) and the initial state."""
    network = assemble(building)
    c_dt = network.C / case.dt
    forced = np.flatnonzero(force)
    M = np.diag(c_dt) - network.A
    M[forced] = 0.0
    M[forced, forced] = 1.0
    Minv = np.linalg.inv(M)
    rows = warmup_rows(len(case.times), case.dt, WARMUP_DAYS)
    source = network.sources(case.U)[rows]
    T_forced = case.measured[rows][:, forced]
    if not np.isfinite(T_forced).all():
        raise SystemExit("the bare loop expects every forced node measured at every step")
    T0 = initial_state(building, case.measured[0])
    return Minv, c_dt, source, forced, T_forced, T0


def bare_loop(Minv, c_dt, source, forced, T_forced, T0):
    """Backward Euler, one matrix-vector product a step; forced nodes written in."""
    T = T0
    out = np.empty_like(source)
    for k in range(len(source)):
        v = c_dt * T + source[k]
        v[forced] = T_forced[k]
        T = Minv @ v
        out[k] = T
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="GA of 30 x 40 instead of 30 x 400")
    parser.add_argument("--repeats", type=int, default=20, help="timed runs of items 1 and 2")
    args = parser.parse_args(argv)
    population, generations = (30, 40) if args.quick else (30, 400)
    workers = os.cpu_count()

    print("nodeforce search benchmark")
    print(f"machine : {workers} CPUs (os.cpu_count()), {machine()}")
    print(f"python  : {platform.python_version()} ({platform.python_implementation()}), numpy {np.__version__}")
    print("preparing the case (pseudo-measurements, one year of spin-up) ...", flush=True)

    data, building, case = the_case()
    objective = Objective.of(building)
    air = objective.air_nodes[0]
    nodes = chromosome_nodes(building, case, objective, "pseudo-measurements")
    n_rows = len(case.times)
    steps = len(warmup_rows(n_rows, case.dt, WARMUP_DAYS))
    # A fixed forcing mask, like a chromosome of the GA's random first population: every other
    # chromosome node (in chromosome order) forced.
    mask = tuple(i % 2 == 0 for i in range(len(nodes)))
    forced_ids = sorted(n for n, bit in zip(nodes, mask) if bit)
    force = np.zeros(building.n_nodes, dtype=bool)
    force[np.array(forced_ids) - 1] = True

    with tempfile.TemporaryDirectory(prefix="nodeforce_bench_") as tmp:
        tmp = Path(tmp)

        # 1. direct model simulation
        network = assemble(building)
        T_direct = simulate(building, network, case.U, case.dt, case.measured, force=force, warmup_days=WARMUP_DAYS)
        t_direct = median_time(lambda: simulate(building, network, case.U, case.dt, case.measured, force=force,
                                                warmup_days=WARMUP_DAYS), args.repeats)

        # 2. one FMU evaluation through the driver, evaluator built once
        (tmp / "fmu").mkdir()
        fmu = build_fmu(building, tmp / "fmu" / "model.fmu")
        evaluator = FmuFitness(fmu, case, nodes, objective, WARMUP_DAYS)()
        J_fmu = evaluator.J(mask)
        t_fmu = median_time(lambda: evaluator.J(mask), args.repeats)
        J_direct = float(np.sum((T_direct[:, air - 1] - case.measured[1:, air - 1]) ** 2))

        # 4. the bare loop
        setup = bare_loop_setup(building, case, force)
        T_bare = bare_loop(*setup)[steps - (n_rows - 1):]
        bare_error = float(np.max(np.abs(T_bare - T_direct)))
        t_bare = median_time(lambda: bare_loop(*setup), max(5 * args.repeats, 100))

        # 5. the GA
        print(f"running the GA ({population} x {generations}, {workers} workers) ...", flush=True)
        (tmp / "locate").mkdir()
        t0 = time.perf_counter()
        result = locate(building, case, objective, tmp / "locate", population=population, generations=generations,
                        pc=0.8, pm=0.03, seed=0, workers=workers)
        t_ga = time.perf_counter() - t0

    overhead_us = (t_fmu - t_direct) / steps * 1e6
    budget = population * generations
    t_budget = budget * t_bare
    s = result["search"]
    ms = lambda t: f"{t * 1e3:10.2f} ms"  # noqa: E731

    rows = [
        ("1. direct simulation (model.integrate.simulate)", ms(t_direct), f"median of {args.repeats}"),
        ("2. FMU evaluation (FmuFitness evaluator J)", ms(t_fmu), f"median of {args.repeats}"),
        ("   J through FMU / direct", f"{J_fmu:.6g} / {J_direct:.6g}", ""),
        ("3. FMU / direct", f"{t_fmu / t_direct:10.1f} x", ""),
        ("   FMI overhead per step", f"{overhead_us:10.1f} us", f"target <= {OVERHEAD_TARGET_US:g} us/step"),
        ("4. bare loop (Minv @ v, numpy), one run", ms(t_bare), f"{t_bare / steps * 1e6:.2f} us/step; "
                                                               f"max |T - direct| {bare_error:.1e} C"),
        ("   12,000 runs of the bare loop", f"{PAPER_BUDGET * t_bare:10.2f} s", "the paper's 30 x 400"),
        *([(f"   {budget:,} runs of the bare loop", f"{t_budget:10.2f} s", "this GA's population x generations")]
          if budget != PAPER_BUDGET else []),
        (f"5. GA {population} x {generations}, pc 0.8, pm 0.03, seed 0", f"{t_ga:10.2f} s",
         f"wall, locate() incl. FMU build; target < {GA_TARGET_S:g} s on 2 cores"),
        ("   of which search", f"{s['seconds']:10.2f} s", f"{workers} workers, method {s['method']}"),
        ("   evaluations / unique", f"{s['evaluations']} / {s['unique_evaluations']}",
         f"{t_ga / max(s['unique_evaluations'], 1) * 1e3:.1f} ms wall per unique"),
        ("   best_nodes", str(result["best_nodes"]), f"over {len(nodes)} nodes"),
        ("   ranked_nodes[:3]", str(result["ranked_nodes"][:3]), ""),
        (f"   GA wall / {budget:,} bare-loop runs", f"{t_ga / t_budget:10.2f}", "target < 1"),
    ]
    if args.quick:
        rows.append(("(--quick: GA of 30 x 40; the targets are for 30 x 400)", "", ""))
    width = max(len(r[0]) for r in rows)
    value_width = max(len(r[1]) for r in rows)
    print()
    print(f"case    : {DAYS} days at {case.dt / 60:g} min = {n_rows - 1} steps + {WARMUP_DAYS}-day warm-up "
          f"= {steps} steps; {building.n_nodes} nodes, {len(nodes)} in the chromosome")
    print(f"mask    : items 1, 2 and 4 force nodes {','.join(map(str, forced_ids))}")
    print()
    for label, value, note in rows:
        print(f"{label:<{width}}  {value:>{value_width}}  {note}".rstrip())
    return 0


if __name__ == "__main__":
    sys.exit(main())
