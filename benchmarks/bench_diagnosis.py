"""Does the diagnosis name the effect a record carries? A benchmark of many records (issue 27).

The records (`benchmarks/records.py`; their catalogue `benchmarks/catalogue.py`): the test cell under three typical years (pvlib's Miami,
Greensboro and Sand Point files), 5 to 21 days at 10 to 60 min, 0.05 to 0.3 C of noise, read by
the paper's sensors, by every node, or by the air alone with a PRBS heater; and the Twin House's
living room under Greensboro's winter with its own sensors. Each carries one fault (a few two) the building
file does not declare (every effect of the registry, a gain on a schedule, a gain through an
undeclared opening) at a subtle size (the file's validation RMSE 1.5 to 3 x the noise) or a
strong one, or none; the truth is a finer discretisation simulated at 1 min.

Each record, under `--draws` noise draws, is diagnosed by the loop through the public API
(`nodeforce.api.diagnose`, the command line's settings: GA population 30, 400 generations at
most, seed 0; one worker per diagnosis, the sensors' noise given as the user would state it), and
by the plain baseline (`benchmarks/baseline.py`). The results go, record by record, to
`out/bench_diagnosis/records/` (a rerun skips the finished ones); the tables and the issue's
criteria are printed and written to docs/benchmark_diagnosis.md and out/bench_diagnosis/results.json.

Run:

    make benchmark                                      # this and bench_search.py
    python benchmarks/bench_diagnosis.py                # every record, 3 draws, 2 workers
    python benchmarks/bench_diagnosis.py --quick        # 8 records, one draw
    python benchmarks/bench_diagnosis.py --only 'gso-jan/*' --draws 1
    python benchmarks/bench_diagnosis.py --report       # the tables from the records already run
    python benchmarks/bench_diagnosis.py --scheduler tcp://10.0.0.1:8786   # on a Dask cluster's workers,
        # started with this checkout on their PYTHONPATH (they import benchmarks.records)
"""
import argparse
import contextlib
import fnmatch
import hashlib
import io
import json
import math
import os
import statistics
import sys
import time
from collections import Counter, defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # `benchmarks.records` when run as a script

from tqdm import tqdm  # noqa: E402

from benchmarks.baseline import baseline  # noqa: E402
from benchmarks.catalogue import PLAN, SCENARIOS, SPECS, SPECS_BY_NAME, quick_specs  # noqa: E402
from benchmarks.records import later_record, later_spec, record  # noqa: E402
from nodeforce.model.case import HISTORY_DAYS  # noqa: E402

OUT = ROOT / "out" / "bench_diagnosis"
DOCS = ROOT / "docs" / "benchmark_diagnosis.md"
COMMAND = "make benchmark  # python benchmarks/bench_diagnosis.py (every record, 3 draws, 2 workers)"
WITHIN = 1.5  # x noise: a validation RMSE after that is "at the noise"
CRITERIA = {"right": 0.9, "right_subtle": 0.8, "within": 0.9, "stable": 0.9, "carried": 0.9, "both_found": 0.8}


def result_path(out, name, draw):
    return out / "records" / f"{name.replace('/', '__')}__draw{draw}.json"


# The code and data a result depends on: the package (the loop), the records, the baseline, the Twin House.
CODE = ("nodeforce", "model", "fmu_build", "cosim", "ga", "diagnosis", "iotools", "benchmarks", "examples")


def code_digest():
    """A digest of the source files in `CODE` (their paths and contents)."""
    digest = hashlib.sha1()
    for path in sorted(p for folder in CODE for p in (ROOT / folder).rglob("*") if p.suffix in (".py", ".c", ".h", ".json")):
        if not path.name.startswith("bench_"):  # the benchmarks' own scripts (this one's tables, the speed
            # measurements) make no result
            digest.update(str(path.relative_to(ROOT)).encode() + path.read_bytes())
    return digest.hexdigest()


def spec_digest(name, code=None):
    """A digest of everything that makes a result: the record's spec and the code that made and
    diagnosed it. A result is reused only when both are the same: a change of the loop runs every
    record again."""
    return hashlib.sha1((repr(SPECS_BY_NAME[name]) + (code or CODE_DIGEST)).encode()).hexdigest()[:12]


CODE_DIGEST = code_digest()


def finished(path, name):
    """Whether `path` holds the result of this very record (not of an earlier spec of that name)."""
    try:
        return json.loads(path.read_text()).get("spec") == spec_digest(name)
    except (OSError, ValueError):
        return False


def diagnose_one(task):
    """Generate one record, diagnose it with the loop and the baseline; return the result."""
    name, draw, path, population, generations, history_days = task
    from nodeforce import api
    from nodeforce.runtime import tempdirs
    started = time.time()
    try:
        r = record(name, draw)
        case = r.case(history_days)
        later = later_of(r, history_days)
        generated = time.time() - started
        t = time.time()
        # the loop's own lines (its findings, the candidates' fits) would bury the progress bar
        with tempdirs.folder("bench-diagnosis") as tmp, contextlib.redirect_stdout(io.StringIO()), \
                contextlib.redirect_stderr(io.StringIO()):
            report = api.diagnose(r.building, case, tmp, objective=api.objective(r.building, r.zones), workers=1,
                                  population=population, generations=generations, noise=r.spec.noise,
                                  seed=0, later=[later]).to_json()
        seconds = time.time() - t
        scored, = report["later"]
        base = baseline(r.building, case.with_steady_start(), r.zones)
        hlc = report.get("heat_loss_coefficient") or {}
        result = {
            "name": name, "draw": draw, "spec": spec_digest(name), "fault": r.spec.label, "size": r.spec.size,
            "faults": [[list(a) for a in f.answers] for f in r.spec.faults], "noise": r.spec.noise, "scale": r.scale,
            "values": r.values, "before_ratio_noiseless": r.before_ratio,
            "loop": {"effects": [[e["effect"], e["target"]] for e in report.get("effects", [])],
                     "before": report["before"]["validation"]["rmse"], "after": report["after"]["validation"]["rmse"],
                     "hlc_before": hlc.get("before"), "hlc_after": hlc.get("after"), "seconds": seconds,
                     "numerical": report["noise"]["numerical"],
                     "reason": report.get("decision", {}).get("reason"),
                     "rounds": [rounded(d) for d in report.get("decision", {}).get("rounds", [])]},
            "baseline": {k: base[k] for k in ("effect", "target", "values", "delta_bic", "validation_rmse",
                                              "candidates", "seconds")},
            "hlc_truth": r.hlc_truth, "hlc_file": r.hlc_file, "generation_seconds": generated,
            "later": {"start": later_spec(r.spec).start,
                      "written": scored["before"]["rmse"], "corrected": scored["after"]["rmse"]},
        }
    except Exception as error:  # a record that fails is reported, not cached: a rerun tries it again
        return failed(task, error)
    return result


def later_of(r, history_days):
    """The record's later record (`records.later_record`) as the diagnosis reads one (`api.Record`,
    `later=`): no fit or choice reads it; the diagnosis scores the file as written and as
    corrected on it, as `nodeforce compare` does."""
    from nodeforce import api
    later = later_record(r)
    read_from = {"weather": later.weather, "measurements": later.measurements, "burn_in_days": later.spec.burn_in,
                 "history_days": history_days}
    return api.Record(later.case(history_days), later.spec.name, later.spec.name, read_from=read_from)


def held(r):
    """Whether the corrected file is no worse than the file as written on the later record, beyond
    `WITHIN` x the noise: a correction that holds beyond its record."""
    return r["later"]["corrected"] <= max(r["later"]["written"], WITHIN * r["noise"])


def failed(task, error):
    return {"name": task[0], "draw": task[1], "error": f"{type(error).__name__}: {error}"}


def keep(task, result):
    """Write a record's result where a rerun finds it (here, not on a cluster's worker: it may
    not share this file system); a failed one is not kept."""
    if "error" in result:
        return
    path = task[2]
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".part")
    tmp.write_text(json.dumps(result, indent=1) + "\n")
    os.replace(tmp, path)


def rounded(decision, kept=8):
    """A round's decision as the benchmark keeps it, to see which step chose what: the chosen, the
    cross-validated J before, and the `kept` candidates of lowest cross-validated J with their test."""
    tests = decision.get("candidates", {})
    best = sorted(tests, key=lambda k: -tests[k]["cv_fall"])[:kept]
    return {"chosen": decision.get("chosen"), "cv_J_before": decision.get("cv_J_before"),
            "needed_noise": decision.get("noise_margin"), "indistinct": decision.get("indistinct", []),
            "best": {k: {key: tests[k].get(key) for key in ("cv_fall", "cv_se", "needed", "passes", "objection", "evidence")}
                     for k in best}}


def longest_first(tasks):
    """The tasks in decreasing order of a diagnosis's expected cost, its building's nodes times its
    record's days: the workers take them in that order, so that the last ones to finish are short
    and neither worker waits long for the other at the end (the Twin House's diagnoses, ten of
    the test cell's each, were the last four)."""
    from benchmarks.truth import file_building
    nodes = {}

    def cost(task):
        spec = SPECS_BY_NAME[task[0]]
        if spec.building not in nodes:
            nodes[spec.building] = file_building(spec).n_nodes
        return nodes[spec.building] * spec.days
    return sorted(tasks, key=cost, reverse=True)


def run(tasks, workers, scheduler=None):
    """Each task in a worker process (2 by default), or on the workers of the Dask cluster at
    `scheduler`, with a progress bar; each result kept as it comes; the results as they came."""
    from concurrent.futures import as_completed
    from nodeforce.runtime import lifetime
    from nodeforce.runtime.cluster import Cluster
    if not tasks:
        return []
    done = []
    with tqdm(total=len(tasks), desc="diagnosing records", unit="diagnosis") as bar:
        def arrived(task, result):
            if isinstance(result, BaseException):  # a record whose diagnosis killed its workers
                result = failed(task, result)
            keep(task, result)
            done.append(result)
            bar.set_postfix_str(result["name"] + (" FAILED" if "error" in result else ""))
            bar.update()

        if scheduler is not None:
            with Cluster(scheduler) as cluster:
                cluster.map(diagnose_one, tasks, done=lambda i, result: arrived(tasks[i], result))
        else:
            with lifetime.worker_pool(min(workers, len(tasks))) as pool:
                futures = {pool.submit(diagnose_one, t): t for t in tasks}
                for future in as_completed(futures):
                    arrived(futures[future], future.result())
    return done


# -- judging --------------------------------------------------------------------------------

def first(result, who):
    if who == "loop":
        effects = result["loop"]["effects"]
        return tuple(effects[0]) if effects else ("none", None)
    b = result["baseline"]
    return (b["effect"], b["target"])


def answers(result):
    """The (effect, target) pairs that name one of the record's faults."""
    return [tuple(a) for fault in result["faults"] for a in fault]


def right(result, who):
    """The first effect is one a fault of the record counts as right (target included); "none"
    for a record without fault."""
    found = first(result, who)
    return found[0] == "none" if not result["faults"] else found in answers(result)


def all_found(result):
    """Every fault of the record is named among the effects the loop added."""
    added = {tuple(e) for e in result["loop"]["effects"]}
    return all(added & {tuple(a) for a in fault} for fault in result["faults"])


def tied(result):
    """The first effect is right, or the record's fault is among the candidates the first round
    names as not told apart from it by the data (within one standard error: `indistinct`), the
    report then saying the fault may be either: what the data allow, beside what was chosen."""
    if right(result, "loop"):
        return True
    rounds = result["loop"].get("rounds") or []
    labels = {"@".join(map(str, a)) for a in answers(result)}
    return bool(rounds and result["loop"]["effects"] and labels & set(rounds[0].get("indistinct", [])))


def truth_label(result):
    return result["fault"]


def confusion(results, who="loop"):
    """Markdown: rows the fault in the record, columns the first effect added, and how many named
    the right target too."""
    if not results:
        return "(no diagnosis)"
    columns = sorted({first(r, who)[0] for r in results}, key=lambda c: (c != "none", c))
    rows = defaultdict(Counter)
    hits = Counter()
    for r in results:
        rows[truth_label(r)][first(r, who)[0]] += 1
        hits[truth_label(r)] += right(r, who)
    lines = ["| in the record \\ first added | " + " | ".join(columns) + " | right (target too) |",
             "|---|" + "---|" * (len(columns) + 1)]
    for label in sorted(rows, key=lambda x: (x != "none", x)):
        n = sum(rows[label].values())
        lines.append(f"| {label} | " + " | ".join(str(rows[label][c] or "") for c in columns)
                     + f" | {hits[label]}/{n} |")
    return "\n".join(lines)


def share(flags):
    flags = list(flags)
    return (sum(flags) / len(flags)) if flags else float("nan")


def summary(results, draws):
    """The tables and the criteria, as markdown lines; and the numbers."""
    ok = [r for r in results if "error" not in r]
    failed = [r for r in results if "error" in r]
    faulty = [r for r in ok if r["faults"]]
    pairs = [r for r in ok if len(r["faults"]) > 1]
    subtle = [r for r in ok if r["size"] == "subtle"]
    strong = [r for r in ok if r["size"] == "strong"]
    clean = [r for r in ok if not r["faults"]]
    within = [r["loop"]["after"] <= WITHIN * r["noise"] for r in ok]
    hlc = [abs(r["loop"]["hlc_after"] - r["hlc_truth"]) / r["hlc_truth"] for r in ok if r["loop"]["hlc_after"]]
    hlc_file = [abs(r["hlc_file"] - r["hlc_truth"]) / r["hlc_truth"] for r in ok]
    seconds = [r["loop"]["seconds"] for r in ok]
    by_record = defaultdict(dict)
    for r in ok:
        by_record[r["name"]][r["draw"]] = first(r, "loop")
    complete = {name: d for name, d in by_record.items() if len(d) >= draws}
    stable = [len(set(d.values())) == 1 for d in complete.values()]
    missed = [r for r in ok if right(r, "baseline") and not right(r, "loop")]
    numbers = {
        "diagnoses": len(ok), "failed": len(failed), "records": len(by_record),
        "right": share(right(r, "loop") for r in faulty), "right_subtle": share(right(r, "loop") for r in subtle),
        "right_strong": share(right(r, "loop") for r in strong),
        "right_or_tied": share(tied(r) for r in faulty), "right_or_tied_subtle": share(tied(r) for r in subtle),
        "baseline_right": share(right(r, "baseline") for r in faulty),
        "baseline_right_subtle": share(right(r, "baseline") for r in subtle),
        "clean_untouched": share(right(r, "loop") for r in clean),
        "baseline_clean_untouched": share(right(r, "baseline") for r in clean),
        "within": share(within), "stable": share(stable) if draws > 1 else float("nan"),
        "carried": share(held(r) for r in ok), "both_found": share(all_found(r) for r in pairs),
        "stable_records": len(stable), "baseline_right_loop_wrong": len(missed),
        "hlc_error_median": statistics.median(hlc) if hlc else float("nan"),
        "hlc_error_file_median": statistics.median(hlc_file) if hlc_file else float("nan"),
        "seconds_mean": statistics.mean(seconds) if seconds else float("nan"),
        "seconds_max": max(seconds, default=float("nan")),
        "baseline_seconds_mean": statistics.mean(r["baseline"]["seconds"] for r in ok) if ok else float("nan"),
    }
    pct = lambda x: "n/a" if math.isnan(x) else f"{100 * x:.0f} %"  # noqa: E731
    def mark(value, least):
        return "n/a" if math.isnan(value) else "PASS" if value >= least else "FAIL"
    criteria = [
        f"- {mark(numbers['right'], CRITERIA['right'])}: first effect right (target included) on "
        f"{pct(numbers['right'])} of the diagnoses of faulty records (>= 90 %); the baseline {pct(numbers['baseline_right'])}",
        f"- {mark(numbers['right_subtle'], CRITERIA['right_subtle'])}: on {pct(numbers['right_subtle'])} of the "
        f"subtle ones (>= 80 %); the baseline {pct(numbers['baseline_right_subtle'])}",
        f"- (beside the criteria) the record's fault first, or named among the candidates the data cannot tell "
        f"from the first (within one standard error): {pct(numbers['right_or_tied'])} of the faulty records, "
        f"{pct(numbers['right_or_tied_subtle'])} of the subtle ones",
        f"- {mark(numbers['clean_untouched'], 1)}: nothing added to {pct(numbers['clean_untouched'])} of the "
        f"diagnoses of records without a fault (100 %); the baseline {pct(numbers['baseline_clean_untouched'])}",
        f"- {mark(numbers['within'], CRITERIA['within'])}: validation RMSE after within {WITHIN} x the noise on "
        f"{pct(numbers['within'])} (>= 90 %)",
        f"- {mark(numbers['carried'], CRITERIA['carried'])}: on the record's later record (the same building and "
        f"fault two to four weeks on, which no choice read), the corrected file no worse than the file as written "
        f"beyond {WITHIN} x the noise on {pct(numbers['carried'])} (>= 90 %)"
        + "".join(f"\n  - {r['name']} draw {r['draw']}: as written {r['later']['written']:.3f} C, as corrected "
                  f"{r['later']['corrected']:.3f} C" for r in ok if not held(r)),
        f"- {mark(numbers['both_found'], CRITERIA['both_found'])}: on the records with two faults, both named among "
        f"the effects added on {pct(numbers['both_found'])} (>= 80 %)"
        + "".join(f"\n  - {r['name']} draw {r['draw']}: added {', '.join('@'.join(e) for e in r['loop']['effects']) or 'none'}"
                  for r in pairs if not all_found(r)),
        f"- {'PASS' if numbers['baseline_right_loop_wrong'] == 0 else 'FAIL'}: the loop wrong where the baseline is right on "
        f"{numbers['baseline_right_loop_wrong']} diagnoses (0)"
        + "".join(f"\n  - {r['name']} draw {r['draw']}: baseline {first(r, 'baseline')}, loop {first(r, 'loop')}"
                  for r in missed),
        (f"- {mark(numbers['stable'], CRITERIA['stable'])}: the same first effect under {draws} noise draws on "
         f"{pct(numbers['stable'])} of {numbers['stable_records']} records (>= 90 %)") if draws > 1 else
        "- n/a: stability needs more than one draw (--draws)",
    ]
    lines = [
        f"{numbers['diagnoses']} diagnoses of {numbers['records']} records ({draws} draw(s) each)"
        + (f"; {numbers['failed']} failed: " + "; ".join(f"{r['name']} draw {r['draw']}: {r['error']}" for r in failed)
           if failed else ""),
        "",
        "## The issue's criteria", "", *criteria, "",
        "## First effect added by the loop, every record", "", confusion(ok), "",
        "### Subtle (validation RMSE before 1.5 to 3 x the noise)", "", confusion(subtle), "",
        "### Strong", "", confusion(strong), "",
        "## The baseline (each effect alone, least squares, BIC)", "", confusion(ok, "baseline"), "",
        "## Error left, heat loss, time", "",
        f"- validation RMSE after within {WITHIN} x the noise: {pct(numbers['within'])}",
        f"- HLC error |after - truth| / truth, median: {pct(numbers['hlc_error_median'])} "
        f"(the file as given: {pct(numbers['hlc_error_file_median'])})",
        f"- time per diagnosis: mean {numbers['seconds_mean']:.1f} s, max {numbers['seconds_max']:.1f} s; "
        f"the baseline {numbers['baseline_seconds_mean']:.1f} s",
        "", "## Every diagnosis", "",
        "| record | draw | before/noise (noiseless) | loop: effects added | after/noise | later: written, corrected /noise "
        "| baseline | HLC truth, after (W/K) | s |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in sorted(ok, key=lambda r: (r["name"], r["draw"])):
        added = ", ".join(f"{e}@{t}" for e, t in r["loop"]["effects"]) or "none"
        b = r["baseline"]
        after = r["loop"]["hlc_after"]
        lines.append(f"| {r['name']} | {r['draw']} | {r['before_ratio_noiseless']:.2f} | {added}"
                     f"{'' if right(r, 'loop') else ' (wrong)'}{' (a fault missed)' if len(r['faults']) > 1 and not all_found(r) else ''} | "
                     f"{r['loop']['after'] / r['noise']:.2f} | "
                     f"{r['later']['written'] / r['noise']:.2f}, {r['later']['corrected'] / r['noise']:.2f}"
                     f"{'' if held(r) else ' (worse)'} | "
                     f"{b['effect']}{'@' + b['target'] if b['target'] else ''}{'' if right(r, 'baseline') else ' (wrong)'} | "
                     f"{r['hlc_truth']:.1f}, {after if after is None else f'{after:.1f}'} | {r['loop']['seconds']:.0f} |")
    return lines, numbers


# What one diagnosis costs, measured in the draw 0 of commit ca616bd: the whole run is sized from it.
BUDGET = ("The budget, measured in the draw 0 of commit ca616bd on 2 cores, two diagnoses at a time (5 to 95 % "
          "of the records' times), the forcing search driving the standalone FMU (`search_fmu=\"auto\"`, the "
          "API's default as the command line's) and the runs of steps compiled where a C compiler is found: a "
          "test-cell diagnosis takes 5 to 10 s with the paper's sensors or the air alone and 10 to 19 s with "
          "every node measured (gso-jan and mia-dec, 23 forcing genes), its baseline 3 to 5 s, a Twin House "
          "diagnosis 41 to 56 s (its baseline 22 to 32 s), making a record's truth 1 to 5 s on the test cell "
          "and 12 to 19 s for the Twin House. Every record under one draw is then about 12 min on 2 workers. "
          "The GA and the calibrations keep the command line's defaults. Finished records are kept in "
          "out/bench_diagnosis/records, each with a digest of its spec and of the code (the package, the "
          "records, the baseline, the examples): a rerun skips what is unchanged, a changed loop runs "
          "everything again.")


def scenarios_table():
    """Markdown: the records' scenarios, with the file's error on each one's record without a fault."""
    lines = ["| scenario | building | climate (typical year) | start | days | step | noise | sensors | weather before | faults |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for name, s in SCENARIOS.items():
        faults = ", ".join(entry.replace(" s", " (subtle)").replace(" L", " (strong)") for entry in PLAN[name])
        sensors = {"paper": "the paper's (1, 7, 9, 16, 17, 23)", "all": "every node",
                   "air": "the air, PRBS heater 300 W", "own": "its own 10"}[s.sensors]
        lines.append(f"| {name} | {s.building}{' (' + s.objective + ')' if s.objective else ''} | {s.climate} | "
                     f"{s.start} | {s.days} | {s.step_min} min | {s.noise} C | {sensors} | {s.before:g} days | {faults} |")
    return "\n".join(lines)


def write_docs(path, lines, args, elapsed):
    subset = args.quick or args.only
    # the command that made the results: --report and --docs only write them again
    argv, skip = [], False
    for a in sys.argv[1:]:
        if skip or a in ("--report", "--docs") or a.startswith("--docs="):
            skip = a == "--docs"
            continue
        argv.append(a)
    command = COMMAND if not subset else f"python benchmarks/bench_diagnosis.py {' '.join(argv)}"
    timing = ("" if args.report else f": {elapsed / 60:.0f} min for the diagnoses run this time")
    header = [
        "# The diagnosis on many records (issue 27)", "",
        *(["A subset of the records; `make benchmark` writes the whole benchmark's tables here.", ""] if subset else []),
        "Made by", "", f"    {command}", "",
        f"on {'a Dask cluster' if args.scheduler else f'{os.cpu_count()} cores, {args.workers} workers'}{timing}. The loop runs through the public API (`nodeforce.api.diagnose`) with the command line's "
        f"settings: GA population {args.population}, at most {args.generations} generations (stopped at "
        "convergence), its own calibrations, seed 0, one worker per diagnosis, the sensors' noise given as "
        "a user states it.", "",
        BUDGET, "",
        "## The records", "",
        "Made by `benchmarks/records.py` (read its docstring for why each choice): the truth is the "
        "building file discretised finer (every stretch between two of its nodes or layer boundaries cut "
        "in two) and simulated at 1 min from 90 days of history (the typical year read as cyclic), sampled at "
        "the record's step, its inputs the same piecewise-linear weather and held heater powers the file's "
        "model reads; the diagnosis reads the weather from some days before the record ('weather before' "
        "below: its history, docs/model.md 5.7), never the truth's whole past; the fault is an "
        "effect the file does not declare, applied with the registry's own `apply`, or a gain on a "
        "schedule (150 W from 08:00 to 18:00 at scale 1), or a south opening (0.6 m2 of glazing at scale "
        "1, its sun to the floor), or the envelope's materials and outside film coefficients both twice the "
        "file's at scale 1 ('envelope-films'; 'envelope' is the registry's factor on the materials alone); a few records carry two faults together ('door+roof-alpha': a component whose inner surface a sensor reads and an effect no sensor reads), both moved by one common scale; its size is tuned by simulating so that the file's validation RMSE is "
        "2.2 x the noise (subtle, accepted 1.5 to 3) or 6 x (strong, 4 to 9); Gaussian noise, seeded by "
        "the record's name and draw. A fault is never scaled beyond its physical limits (a factor on a "
        "conductance within 0.1 to 10, a room's mean convective coefficient within 0.5 to 20 W/m2/K): where that limit comes before the "
        "size asked for, the record is as large as physics lets it be, its 'before/noise' below. Even "
        "without a fault the file is not the truth: its coarser walls and the part of the truth's past "
        "the weather does not reach leave it 0.03 to 0.09 C (it integrates every record in steps of at "
        "most 5 min, docs/model.md 5.1; at the record's own step, the error grew with the step, to 0.3 C "
        "at 60 min).", "",
        scenarios_table(), "",
        "A first effect is right when it is the record's fault with its target; an air change and a "
        "bridge to the outdoor air are one equation and count as one; a schedule is right as a daily "
        "gain; the south opening as a gain proportional to the south wall's sun or as the south "
        "window's transmittance; the envelope's materials and films as the zone's envelope factor or its "
        "conductance to the outdoor air (an air change, a bridge: with the films scaled as the layers, the "
        "share of the sun the envelope passes on is as declared, and only the sun tells them apart); on a "
        "record without a fault, adding nothing is right. On a record with two faults the first effect is right when it names either, and both are found when each is named among the effects added. The baseline "
        "(`benchmarks/baseline.py`) fits each catalogue effect alone by least squares to the objective "
        "air on the calibration window and keeps the best by BIC if it falls by more than 10.", "",
    ]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(header + lines) + "\n")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="8 records across the scenarios, one draw")
    p.add_argument("--only", help="records whose name matches this glob, e.g. 'mia-jun/*' or '*door*'")
    p.add_argument("--draws", type=int, help="noise draws per record (default 3; 1 with --quick)")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--scheduler", help="a Dask scheduler address, tcp://host:port: the diagnoses on its workers "
                                       "(started with this checkout on their PYTHONPATH) instead of --workers "
                                       "processes")
    p.add_argument("--population", type=int, default=30)
    p.add_argument("--generations", type=int, default=400)
    p.add_argument("--out", type=Path, default=OUT)
    p.add_argument("--docs", type=Path, help="the markdown written (default docs/benchmark_diagnosis.md for the "
                                              "whole benchmark, out/bench_diagnosis/summary.md for a subset)")
    p.add_argument("--report", action="store_true", help="no diagnosis: the tables of the records already run")
    p.add_argument("--fresh", action="store_true", help="run every record again (after a change of the loop)")
    p.add_argument("--list", action="store_true", help="list the records and exit")
    p.add_argument("--history-days", type=float, default=HISTORY_DAYS,
                   help="days of the weather before each record the loop and the baseline read at most (default "
                        "the loop's own, %(default)g, docs/model.md 5.7; 0: none), to measure what the history "
                        "does: give another --out, the records' digests do not hold it")
    args = p.parse_args(argv)
    specs = quick_specs() if args.quick else SPECS
    if args.only:
        specs = [s for s in specs if fnmatch.fnmatch(s.name, args.only) or args.only in s.name]
    if args.list:
        for s in specs:
            print(s.name, s.label, s.size, s.climate, f"{s.days} d", f"{s.step_min} min", s.noise, s.sensors)
        return 0
    draws = args.draws or (1 if args.quick else 3)
    tasks = [(s.name, d, result_path(args.out, s.name, d), args.population, args.generations, args.history_days)
             for s in specs for d in range(draws)]
    todo = [t for t in tasks if args.fresh or not finished(t[2], t[0])] if not args.report else []
    print(f"{len(specs)} records x {draws} draws: {len(tasks) - len(todo)} done before, {len(todo)} to run "
          f"on {args.scheduler or f'{args.workers} workers'}", flush=True)
    started = time.time()
    fresh = {(r["name"], r["draw"]): r for r in run(longest_first(todo), args.workers, args.scheduler)}
    elapsed = time.time() - started
    results = [fresh.get((t[0], t[1])) or (json.loads(t[2].read_text()) if finished(t[2], t[0]) else None)
               for t in tasks]
    results = [r for r in results if r is not None]
    lines, numbers = summary(results, draws)
    print("\n".join(lines))
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "results.json").write_text(json.dumps({"numbers": numbers, "results": results}, indent=1) + "\n")
    # a subset's tables stay under out/: the docs hold the whole benchmark's
    docs = args.docs or (DOCS if not (args.quick or args.only) else args.out / "summary.md")
    write_docs(docs, lines, args, elapsed)
    print(f"written: {docs}, {args.out / 'results.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
