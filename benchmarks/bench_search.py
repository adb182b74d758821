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
5. the search (`ga.locate.locate`, seed 0, os.cpu_count() workers) over the 21 non-algebraic
   nodes, twice: the default search (seeded, stopped at convergence) and the paper's
   (ga.search.PAPER: 30 x 400, pc 0.8, pm 0.03, every generation): evaluations, unique
   simulations, the generation it stopped at, wall time and the answer, against the targets
   (the default: the paper's best_nodes in at most 1,200 unique simulations, and less time than
   12,000 runs of the bare loop).

With --cases, 6. the same two searches on every verification case (door, inside convection,
roof, door and roof together; exact and with 0.1 C of noise) through `ga.fitness.ModelFitness`
(the direct model: the FMU's J within 1e-9 C, item 2 above, at a fifth of the cost), in this
process, with the generations at which the best J fell by more than the noise tolerance: the
measurement ga.search.PATIENCE is chosen from (README, "How the search decides").

The FMU and the search checkpoint go to a fresh temporary directory, so a run never resumes.
It uses only the project's public functions, and the verification cases of tests/test_locate.py.

Run:

    make benchmark                                   # .venv/bin/python benchmarks/bench_search.py
    python benchmarks/bench_search.py [--quick]      # --quick: no paper GA in item 5
    python benchmarks/bench_search.py --cases        # item 6 only (about 5 min on 2 cores)
"""
import argparse
import json
import math
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from nodeforce.fmu_build.build import build_fmu
from nodeforce.ga.fitness import FmuFitness, ModelFitness
from nodeforce.ga.locate import chromosome_nodes, locate
from nodeforce.ga.search import PAPER, PATIENCE, Execution, SearchSettings, search
from nodeforce.model.building_file import parse_building
from nodeforce.model.case import prepare_case
from nodeforce.model.integrate import initial_state, simulate, warmup_rows
from nodeforce.model.network import assemble
from nodeforce.model.score import Objective, noise_level
from nodeforce.model.synth import pseudo_measurements
from nodeforce.iotools.weather import read_weather

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the verification cases are the tests'
from tests.conftest import record_times  # noqa: E402
from tests.test_locate import EXPECTED, disturbed  # noqa: E402
from benchmarks.results import cpu_model  # noqa: E402

DATA = ROOT / "model" / "data"
DAYS, WARMUP_DAYS = 5, 2
OVERHEAD_TARGET_US = 10.0  # FMI overhead per step, the target
PAPER_BUDGET = 30 * 400  # evaluations the paper's GA asks for
UNIQUE_TARGET = PAPER_BUDGET // 10  # the default search's simulations, at most
MODES = {"paper": PAPER, "default": {}}


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


def the_case(fault="door", noise=0.0):
    """The test cell (Miami) and its case: every node measured on the cell with `fault`
    disturbed (tests/test_locate.py), with `noise` C of measurement noise."""
    data = json.loads((DATA / "testcell_miami.json").read_text())
    building = parse_building(data, source="testcell_miami.json")
    weather = read_weather(DATA / "miami_tmy2.csv")
    measurements = pseudo_measurements(disturbed(data, fault), weather, record_times(DAYS), list(range(1, 24)),
                                       noise_sd=noise, seed=7)
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


def significant_falls(history, J_start, tol):
    """Generations at which the best J fell by more than `tol` below the last such fall
    (J_start before the first generation: the seeded start's J, inf for the paper's)."""
    falls, ref = [], J_start
    for generation, J in history:
        if J < ref - tol:
            falls.append(generation)
            ref = J
    return falls


def run_search(mode, run):
    """One search; `run(settings, execution)` -> locate.json fields, with the mode's
    `SearchSettings` and an `Execution` whose progress is followed. Returns the row of the
    comparison table and the generations of significant falls."""
    history = []
    t0 = time.perf_counter()
    result = run(SearchSettings(seed=0, **MODES[mode]),
                 lambda **where: Execution(**where, progress=lambda g, total, J, unique: history.append((g, J))))
    seconds = time.perf_counter() - t0
    s = result["search"]
    J_start = math.inf if s.get("J_stepwise") is None else s["J_stepwise"]
    return result, seconds, significant_falls(history, J_start, s["tolerance"])


def table(rows):
    header = ("case", "mode", "evaluations", "unique", "stopped", "at gen", "seconds", "best_nodes",
              "significant falls at generation")
    rows = [header] + [tuple(str(c) for c in r) for r in rows]
    widths = [max(len(r[i]) for r in rows) for i in range(len(header))]
    for r in rows:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())


def row(case, mode, result, seconds, falls):
    s = result["search"]
    return (case, mode, s["evaluations"], s["unique_evaluations"], s["stopped"], s["stopped_at"],
            f"{seconds:.1f}", result["best_nodes"], ",".join(map(str, falls)) or "-")


def all_cases():
    """Item 6: paper vs default on every verification case, through the direct model."""
    rows, gaps, agree, within = [], [], True, True
    for fault in EXPECTED:
        for noise in (0.0, 0.1):
            data, building, case = the_case(fault, noise)
            objective = Objective.of(building)
            air = objective.air_nodes[0]
            nodes = chromosome_nodes(building, case, objective, "pseudo-measurements")
            factory = ModelFitness(building, case, nodes, objective, WARMUP_DAYS)
            noise_kw = dict(noise_sigma=noise_level(case.measured[:, air - 1]),
                            n_residuals=int(np.isfinite(case.measured[1:, air - 1]).sum()))
            name = f"{fault}, {'noisy' if noise else 'exact'}"
            answers = {}
            for mode in MODES:
                print(f"  {name}: {mode} ...", flush=True)
                result, seconds, falls = run_search(
                    mode, lambda settings, execution: search(factory, nodes, settings, execution(workers=1), **noise_kw))
                rows.append(row(name, mode, result, seconds, falls))
                answers[mode] = result["best_nodes"]
                gaps += [b - a for a, b in zip([0] + falls, falls)]
                if mode == "default":
                    within &= result["search"]["unique_evaluations"] <= UNIQUE_TARGET
            agree &= answers["paper"] == answers["default"]
    print()
    table(rows)
    print()
    print(f"default best_nodes == paper best_nodes on every case: {agree}")
    print(f"default search within {UNIQUE_TARGET:,} unique simulations on every case: {within}")
    print(f"generations from the start or a significant fall of J to the next: at most "
          f"{max(gaps, default=0)} (all: {sorted(gaps)}); patience {PATIENCE}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="item 5 without the paper's GA")
    parser.add_argument("--cases", action="store_true", help="item 6 only: paper vs default on every case")
    parser.add_argument("--repeats", type=int, default=20, help="timed runs of items 1 and 2")
    args = parser.parse_args(argv)
    print("nodeforce search benchmark")
    print(f"machine : {os.cpu_count()} CPUs (os.cpu_count()), {cpu_model()}")
    print(f"python  : {platform.python_version()} ({platform.python_implementation()}), numpy {np.__version__}")
    if args.cases:
        print("paper vs default search on every verification case (direct model, one process):", flush=True)
        all_cases()
        return 0
    print("\n".join(measure(args.quick, args.repeats)["tables"]))
    return 0


def measure(quick=True, repeats=20):
    """Items 1 to 5 (the paper's search in item 5 unless `quick`): {"tables": Markdown lines, and
    the figures}."""
    workers = os.cpu_count()
    print("preparing the case (pseudo-measurements, one year of spin-up) ...", flush=True)

    data, building, case = the_case()
    objective = Objective.of(building)
    nodes = chromosome_nodes(building, case, objective, "pseudo-measurements")
    n_rows = len(case.times)
    steps = len(warmup_rows(n_rows, case.dt, WARMUP_DAYS))
    # A fixed forcing mask, like a chromosome of the GA's random first population: every other
    # chromosome node (in chromosome order) forced.
    mask = tuple(i % 2 == 0 for i in range(len(nodes)))
    forced_ids = sorted(n for n, bit in zip(nodes, mask) if bit)
    force = np.zeros(building.n_nodes, dtype=bool)
    force[np.array(forced_ids) - 1] = True
    modes = ["default"] if quick else ["default", "paper"]

    with tempfile.TemporaryDirectory(prefix="nodeforce_bench_") as tmp:
        tmp = Path(tmp)

        # 1. direct model simulation
        network = assemble(building)
        T_direct = simulate(building, network, case.U, case.dt, case.measured, force=force, warmup_days=WARMUP_DAYS,
                            substeps=case.substeps)
        t_direct = median_time(lambda: simulate(building, network, case.U, case.dt, case.measured, force=force,
                                                warmup_days=WARMUP_DAYS, substeps=case.substeps), repeats)

        # 2. one FMU evaluation through the driver, evaluator built once
        (tmp / "fmu").mkdir()
        fmu = build_fmu(building, tmp / "fmu" / "model.fmu")
        evaluator = FmuFitness(fmu, case, nodes, objective, WARMUP_DAYS)()
        J_fmu = evaluator.J(mask)
        t_fmu = median_time(lambda: evaluator.J(mask), repeats)
        evaluator.close()
        J_direct = ModelFitness(building, case, nodes, objective, WARMUP_DAYS)().J(mask)

        # 4. the bare loop
        setup = bare_loop_setup(building, case, force)
        T_bare = bare_loop(*setup)[steps - (n_rows - 1):]
        bare_error = float(np.max(np.abs(T_bare - T_direct)))
        t_bare = median_time(lambda: bare_loop(*setup), max(5 * repeats, 100))

        # 5. the searches
        searches = {}
        for mode in modes:
            print(f"running the {mode} search ({workers} workers) ...", flush=True)
            (tmp / mode).mkdir()
            searches[mode] = run_search(mode, lambda settings, execution: locate(
                building, case, tmp / mode, objective, search=settings, execution=execution(workers=workers)).to_json())

    overhead_us = (t_fmu - t_direct) / steps * 1e6
    t_budget = PAPER_BUDGET * t_bare
    ms = lambda t: f"{t * 1e3:10.2f} ms"  # noqa: E731

    rows = [
        ("1. direct simulation (model.integrate.simulate)", ms(t_direct), f"median of {repeats}"),
        ("2. FMU evaluation (FmuFitness evaluator J)", ms(t_fmu), f"median of {repeats}"),
        ("   J through FMU / direct", f"{J_fmu:.6g} / {J_direct:.6g}", f"difference {abs(J_fmu - J_direct):.1e}"),
        ("3. FMU / direct", f"{t_fmu / t_direct:10.1f} x", ""),
        ("   FMI overhead per step", f"{overhead_us:10.1f} us", f"target <= {OVERHEAD_TARGET_US:g} us/step"),
        ("4. bare loop (Minv @ v, numpy), one run", ms(t_bare), f"{t_bare / steps * 1e6:.2f} us/step; "
                                                               f"max abs(T - direct) {bare_error:.1e} C"),
        ("   12,000 runs of the bare loop", f"{t_budget:10.2f} s", "the paper's 30 x 400"),
    ]
    for mode, (result, seconds, _) in searches.items():
        s = result["search"]
        rows.append((f"5. {mode} search: wall / 12,000 bare-loop runs", f"{seconds / t_budget:10.2f}",
                     "target < 1" if mode == "default" else ""))
        rows.append((f"   {mode}: unique simulations", f"{s['unique_evaluations']:10d}",
                     f"target <= {UNIQUE_TARGET:,}" if mode == "default" else ""))
    tables = [f"The case: {DAYS} days at {case.dt / 60:g} min = {n_rows - 1} steps + {WARMUP_DAYS}-day warm-up "
              f"= {steps} steps; {building.n_nodes} nodes, {len(nodes)} in the chromosome; the door disturbed; "
              f"items 1, 2 and 4 force nodes {','.join(map(str, forced_ids))}.", "",
              "| what | figure | note |", "|---|---|---|",
              *(f"| {label.strip()} | {value.strip()} | {note} |" for label, value, note in rows), "",
              f"Item 5, the search over {len(nodes)} nodes (`locate()`, its FMU's build included, {workers} workers, "
              "seed 0):", "",
              "| mode | evaluations | unique | stopped | at generation | seconds | best nodes |",
              "|---|---|---|---|---|---|---|"]
    for mode in modes:
        result, seconds, _ = searches[mode]
        s = result["search"]
        tables.append(f"| {mode} | {s['evaluations']} | {s['unique_evaluations']} | {s['stopped']} | "
                      f"{s['stopped_at']} | {seconds:.1f} | {result['best_nodes']} |")
    return {"tables": tables, "direct_ms": t_direct * 1e3, "fmu_ms": t_fmu * 1e3, "overhead_us_per_step": overhead_us,
            "bare_loop_ms": t_bare * 1e3,
            "searches": {mode: {"seconds": searches[mode][1], **searches[mode][0]["search"],
                                "best_nodes": searches[mode][0]["best_nodes"]} for mode in modes}}


if __name__ == "__main__":
    sys.exit(main())
