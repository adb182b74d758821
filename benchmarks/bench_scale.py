"""How does nodeforce scale to a full-size building (issue 20)?

Measures, in one run on one machine:

1. `--sizes`: against the number of nodes N (the test cell, 23 nodes, and generated offices of
   230 to 2,922 nodes, examples/office/make_building.py), the cost of one factorisation of the
   step matrix for a new forcing mask (the dense inverse and the condensed solver: blocks and a
   Schur complement on the zones' nodes, model.integrate), of one step (both), of one
   simulation of a new mask (2 days + a 2-day warm-up = 384 steps) through the direct model,
   the Python FMU and the standalone C FMU (the search's evaluators, ga.fitness), and the memory
   of the factors; the exponent b of a fit cost = a N^b over the offices; which evaluator is
   cheapest at each size; a plot of cost against N (`--plot`, default bench_scale.png).
2. `--search`: the full office (4 storeys of 8 offices, 1,730 nodes, 88 genes) with three
   undeclared faults in three zones of three storeys and 0.05 C of noise, 3 days scored after a
   1-day burn-in, the objective the 32 offices' air: `nodeforce locate` with 2 worker processes
   (the seeded search; at the end of the run, with `--paper-generations`, the paper's GA for that
   many generations), which nodes it finds, how many unique simulations, and the wall time; the
   forward-backward pass's own answer (`stepwise_nodes`) is in the same locate.json.
3. `--dask small|full`: the small office with two faults, or the full one with its three,
   located by 1 process, 2 processes and a Dask cluster started here on 127.0.0.1 (`dask scheduler` and `dask worker` processes), the same
   answer required, with the speed-up.

Every FMU, record and checkpoint goes to a fresh temporary directory, removed at the end. Run:

    nice -n 10 .venv/bin/python benchmarks/bench_scale.py --sizes --search --dask small --paper-generations 30
    nice -n 10 .venv/bin/python benchmarks/bench_scale.py --dask full    # its "2 processes" is --search, standalone
"""
import argparse
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from nodeforce.fmu_build.build import build_fmu
from nodeforce.ga.fitness import FmuFitness, ModelFitness
from nodeforce.iotools.weather import read_weather
from nodeforce.model.building_file import load_building
from nodeforce.model.case import prepare_case
from nodeforce.model.integrate import CondensedSolve, DenseSolve, ImplicitEuler, Partition
from nodeforce.model.network import assemble
from nodeforce.model.score import Objective
from nodeforce.model.synth import pseudo_measurements

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "examples" / "office"))
import make_building as office  # noqa: E402

SIZES = [(1, 1), (1, 2), (2, 2), (3, 3), (4, 4), (5, 6)]  # (storeys, offices a side)
FAULTS_FULL = ["conductivity@s0_N3_wallN:factor=4", "solar_absorptance@s2_S1_wallS:alpha=0.95",
               "conductivity@s3_S0_wallS:factor=4"]
FAULTS_SMALL = ["conductivity@s0_N1_wallN:factor=4", "solar_absorptance@s1_S0_wallS:alpha=0.95"]
START = "2001-01-15T00:00-05:00"
CLI = [sys.executable, "-m", "nodeforce.cli"]


def timed(function, repeats=1):
    """(median seconds, last result) of `repeats` calls."""
    times, result = [], None
    for _ in range(repeats):
        t = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - t)
    return float(np.median(times)), result


def nbytes(solve):
    """Bytes of a solver's factors."""
    if isinstance(solve, DenseSolve):
        return solve.inverse.nbytes
    return sum(a.nbytes for a in solve.II) + solve.schur_inverse.nbytes + sum(a.nbytes for a in solve.HI + solve.IH)


def size_case(folder, storeys, offices):
    """(building, case, objective, chromosome) of a generated office with 2 days of records."""
    path = office.write(folder, storeys, offices, 2)
    building = load_building(path)
    weather = read_weather(folder / "weather.csv")
    times = pd.date_range(START, periods=2 * 96 + 1, freq="900s", name="time")
    sensors = list(building.sensors.values())
    measured = pseudo_measurements(building, weather, times, sensors, noise_sd=0.05, seed=1, spinup_days=4)
    case = prepare_case(building, weather, measured)
    objective = Objective.of(building, [z.name for z in building.zones if z.heat_input])
    chromosome = [i for i in sensors if i not in objective.air_nodes]
    return building, case, objective, chromosome


def evaluator_cost(factory, k, repeats):
    """Median s of J for a new mask (one node forced, a different one each call)."""
    evaluator = factory()
    try:
        evaluator.J((False,) * k)  # builds what is built once per worker
        masks = iter([tuple(j == i for j in range(k)) for i in range(k)])
        return timed(lambda: evaluator.J(next(masks)), min(repeats, k))[0]
    finally:
        evaluator.close()


def bench_sizes(tmp, repeats, plot):
    rows = []
    buildings = [("testcell", None)] + [(f"office {s}x{o}", (s, o)) for s, o in SIZES]
    for name, size in buildings:
        folder = tmp / name.replace(" ", "_")
        folder.mkdir()
        if size is None:
            building = load_building(REPO / "model" / "data" / "testcell_miami.json")
            weather = read_weather(REPO / "model" / "data" / "miami_tmy2.csv")
            times = pd.date_range("2001-06-05T00:00-05:00", periods=2 * 96 + 1, freq="900s", name="time")
            sensors = [1, 7, 9, 16, 17, 23]
            case = prepare_case(building, weather, pseudo_measurements(building, weather, times, sensors, 0.05, 1,
                                                                       spinup_days=4))
            objective, chromosome = Objective.of(building), sensors[:-1]
        else:
            building, case, objective, chromosome = size_case(folder, *size)
        network = assemble(building)
        n = network.n_nodes
        stepper = ImplicitEuler(network, 900.0)
        M = stepper._M.copy()
        row = {"building": name, "N": n, "zones": len(building.zones), "genes": len(chromosome)}
        row["partition_s"], partition = timed(lambda: Partition(M))
        row["hubs"] = len(partition.hubs)
        row["factor_dense_s"], dense = timed(lambda: DenseSolve(M))
        unforced = np.zeros(n, dtype=bool)  # a mask's factorisation costs the same whichever nodes it forces
        row["factor_condensed_s"], condensed = timed(lambda: CondensedSolve(M, partition, unforced), 3)
        row["memory_dense_MB"], row["memory_condensed_MB"] = nbytes(dense) / 1e6, nbytes(condensed) / 1e6
        row["memory_A_MB"] = network.A.nbytes / 1e6
        v = np.random.default_rng(0).normal(size=n)
        row["step_dense_s"] = timed(lambda: dense(v), 50)[0]
        row["step_condensed_s"] = timed(lambda: condensed(v), 50)[0]
        k = len(chromosome)
        row["sim_direct_s"] = evaluator_cost(ModelFitness(building, case, chromosome, objective), k, repeats)
        for kind in ("python", "standalone"):
            t = time.perf_counter()
            fmu = build_fmu(building, folder / f"{kind}.fmu", kind=kind)
            row[f"export_{kind}_s"] = time.perf_counter() - t
            row[f"fmu_{kind}_MB"] = fmu.stat().st_size / 1e6 if hasattr(fmu, "stat") else Path(fmu).stat().st_size / 1e6
            row[f"sim_{kind}_s"] = evaluator_cost(FmuFitness(fmu, case, chromosome, objective), k, repeats)
        costs = {kind: row[f"sim_{kind}_s"] for kind in ("direct", "python", "standalone")}
        row["fastest"] = min(costs, key=costs.get)
        rows.append(row)
        print(json.dumps(row), flush=True)
        shutil.rmtree(folder)
    table = pd.DataFrame(rows)
    offices = table[table.building != "testcell"]
    exponents = {}
    for column in ("factor_dense_s", "factor_condensed_s", "step_dense_s", "step_condensed_s", "sim_direct_s",
                   "sim_python_s", "sim_standalone_s", "memory_dense_MB", "memory_condensed_MB"):
        exponents[column] = float(np.polyfit(np.log(offices.N), np.log(offices[column]), 1)[0])
    print("fitted exponent b of cost = a N^b over the offices:", json.dumps(exponents, indent=1))
    print(table.to_string(index=False))
    if plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
        for column, label in (("factor_dense_s", "factorisation, dense"), ("factor_condensed_s", "factorisation, condensed"),
                              ("step_dense_s", "step, dense"), ("step_condensed_s", "step, condensed")):
            axes[0].loglog(table.N, table[column], "o-", label=f"{label} (b = {exponents[column]:.2f})")
        for column, label in (("sim_direct_s", "direct"), ("sim_python_s", "Python FMU"),
                              ("sim_standalone_s", "standalone FMU")):
            axes[1].loglog(table.N, table[column], "o-", label=f"{label} (b = {exponents[column]:.2f})")
        axes[0].set(xlabel="nodes N", ylabel="s", title="one factorisation, one step")
        axes[1].set(xlabel="nodes N", ylabel="s", title="one simulation of a new mask (384 steps)")
        for ax in axes:
            ax.legend(fontsize=7)
            ax.grid(True, which="both", alpha=0.3)
        fig.tight_layout()
        fig.savefig(plot, dpi=110)
        print(f"wrote {plot}")
    return table, exponents


def office_records(folder, size, faults, days):
    """Write the office and its record with `faults`; return (folder, objective zones)."""
    office.write(folder, **size)
    sensors = (folder / "sensors.txt").read_text().strip()
    effects = [a for fault in faults for a in ("--effect", fault)]
    subprocess.run(CLI + ["synth", str(folder / "building.json"), "--weather", str(folder / "weather.csv"),
                          "--start", START, "--days", str(days), "--sensors", sensors, "--noise", "0.05",
                          "--seed", "3", "--history-days", "0", *effects, "-o", str(folder / "measured.csv")],
                   check=True, capture_output=True)
    data = json.loads((folder / "building.json").read_text())
    return ",".join(z["name"] for z in data["zones"] if z.get("heat_input"))


def locate(folder, objective, out, *extra):
    """Run `nodeforce locate`; return (locate.json, wall s)."""
    t = time.perf_counter()
    subprocess.run(CLI + ["locate", str(folder / "building.json"), "--weather", str(folder / "weather.csv"),
                          "--measurements", str(folder / "measured.csv"), "-o", str(out), "--objective", objective,
                          "--noise", "0.05", "--burn-in-days", "1", *extra], check=True, capture_output=True)
    return json.loads((out / "locate.json").read_text()), time.perf_counter() - t


def summary(result, seconds, names):
    s = result["search"]
    return {"best_nodes": result["best_nodes"], "named": [names[i] for i in result["best_nodes"]],
            "stepwise_nodes": s.get("stepwise_nodes"), "J_unforced": result["J_unforced"], "J_best": result["J_best"],
            "J_noise": s["J_noise"], "unique_simulations": s["unique_evaluations"], "stopped_at": s["stopped_at"],
            "wall_s": round(seconds, 1)}


def bench_search(tmp, fmu, paper_generations):
    """The seeded search on the full office; with `paper_generations` then the paper's GA."""
    folder = tmp / "full"
    if not folder.exists():
        objective = office_records(folder, office.FULL, FAULTS_FULL, 4)
        (folder / "objective.txt").write_text(objective)
    objective = (folder / "objective.txt").read_text()
    names = load_building(folder / "building.json").node_names()
    faulty = sorted(f.split("@")[1].split(":")[0] for f in FAULTS_FULL)
    print(f"full office: faults in {faulty}", flush=True)
    if not paper_generations:
        result, seconds = locate(folder, objective, tmp / "seeded", "--workers", "2", "--fmu", fmu)
        print("seeded search:", json.dumps(summary(result, seconds, names)), flush=True)
    else:
        result, seconds = locate(folder, objective, tmp / "paper", "--workers", "2", "--fmu", fmu, "--paper",
                                 "--generations", str(paper_generations))
        print(f"paper's GA, {paper_generations} generations:", json.dumps(summary(result, seconds, names)), flush=True)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def bench_dask(tmp, fmu, which):
    """1 process, 2 processes and a Dask cluster of 2 workers on the small or the full office."""
    size, faults, days = (office.FULL, FAULTS_FULL, 4) if which == "full" else (office.SMALL, FAULTS_SMALL, 3)
    folder = tmp / f"dask_{which}"
    objective = office_records(folder, size, faults, days)
    names = load_building(folder / "building.json").node_names()
    runs = {}
    for label, extra in (("1 process", ["--workers", "1"]), ("2 processes", ["--workers", "2"])):
        result, seconds = locate(folder, objective, folder / label.replace(" ", "_"), "--fmu", fmu, *extra)
        runs[label] = summary(result, seconds, names)
        print(label, json.dumps(runs[label]), flush=True)
    port = free_port()
    bin_dir = Path(sys.executable).parent
    processes = [subprocess.Popen([str(bin_dir / "dask"), "scheduler", "--host", "127.0.0.1", "--port", str(port),
                                   "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                  start_new_session=True, env={**os.environ, "DASK_TEMPORARY_DIRECTORY": str(folder)})]
    try:
        time.sleep(3)
        address = f"tcp://127.0.0.1:{port}"
        processes += [subprocess.Popen([str(bin_dir / "dask"), "worker", address, "--nworkers", "1", "--nthreads", "1",
                                        "--host", "127.0.0.1", "--no-dashboard", "--local-directory", str(folder / f"dw{i}")],
                                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
                      for i in range(2)]
        time.sleep(6)
        result, seconds = locate(folder, objective, folder / "dask", "--fmu", fmu, "--scheduler", address)
        runs["dask, 2 workers"] = summary(result, seconds, names)
        print("dask, 2 workers", json.dumps(runs["dask, 2 workers"]), flush=True)
    finally:
        for p in processes:
            os.killpg(p.pid, signal.SIGTERM)
            p.wait(timeout=30)
    answers = {label: (r["best_nodes"], r["unique_simulations"]) for label, r in runs.items()}
    print("same answer everywhere:", len(set(map(str, answers.values()))) == 1,
          "speed-up 2 processes:", round(runs["1 process"]["wall_s"] / runs["2 processes"]["wall_s"], 2),
          "dask:", round(runs["1 process"]["wall_s"] / runs["dask, 2 workers"]["wall_s"], 2))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", action="store_true", help="item 1: cost against N")
    parser.add_argument("--search", action="store_true", help="item 2: the full office's three faults")
    parser.add_argument("--dask", choices=("small", "full"), help="item 3 on this office: 1 process, 2 processes, "
                                                                   "a Dask cluster")
    parser.add_argument("--repeats", type=int, default=3, help="timed simulations per evaluator and size")
    parser.add_argument("--plot", default="bench_scale.png", help="the plot of item 1")
    parser.add_argument("--fmu", default="auto", help="the evaluator of items 2 and 3 (locate --fmu)")
    parser.add_argument("--paper-generations", type=int, default=0, help="also run the paper's GA that long")
    args = parser.parse_args(argv)
    print(f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}", flush=True)
    tmp = Path(tempfile.mkdtemp(prefix="nodeforce_bench_scale_"))
    try:
        if args.sizes:
            bench_sizes(tmp, args.repeats, args.plot)
        if args.search:
            bench_search(tmp, args.fmu, 0)
        if args.dask:
            bench_dask(tmp, args.fmu, args.dask)
        if args.paper_generations:  # last: the longest, and the least needed
            bench_search(tmp, args.fmu, args.paper_generations)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
