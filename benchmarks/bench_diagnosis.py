"""Does the diagnosis name the effect a record carries? A benchmark of many records.

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
`out/bench_diagnosis/records/` (a rerun skips the finished ones); the tables and the criteria
are printed. A run of the whole benchmark is kept in benchmarks/results/diagnosis-DATE.json
(`benchmarks.results`), from which docs/benchmark_diagnosis.md is made (`page`); a subset's
tables go to out/bench_diagnosis/summary.md.

Run:

    make benchmark                                      # this and bench_search.py
    python benchmarks/bench_diagnosis.py                # every record, 3 draws, 2 workers
    python benchmarks/bench_diagnosis.py --quick        # 8 records, one draw
    python benchmarks/bench_diagnosis.py --only 'gso-jan/*' --draws 1
    python benchmarks/bench_diagnosis.py --report       # the tables from the records already run
    python benchmarks/pages.py                          # the docs again from the latest results
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
from benchmarks import results as kept_results  # noqa: E402
from nodeforce.model.case import HISTORY_DAYS  # noqa: E402

OUT = ROOT / "out" / "bench_diagnosis"
DOCS = ROOT / "docs" / "benchmark_diagnosis.md"
COMMAND = "make benchmark  # python benchmarks/bench_diagnosis.py (every record, 3 draws, 2 workers)"
WITHIN = 1.5  # x noise: a validation RMSE after that is "at the noise"
CRITERIA = {"right": 0.9, "right_subtle": 0.8, "right_ground": 0.9, "clean_untouched": 0.95, "within": 0.9,
            "stable": 0.9, "carried": 0.9, "both_found": 0.8}
SHORT_HISTORY = 3.0  # days: a record read with at most this much weather before it has a short history


def result_path(out, name, draw):
    return out / "records" / f"{name.replace('/', '__')}__draw{draw}.json"


# The code and data a result depends on: the package (the loop), the records, the baseline, the Twin House.
CODE = ("nodeforce", "runtime", "model", "fmu_build", "cosim", "ga", "diagnosis", "iotools", "benchmarks", "examples")


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
            report = api.diagnose(r.building, case, tmp, objective=api.objective(r.building, r.zones),
                                  search=api.SearchSettings(population=population, generations=generations,
                                                            noise=r.spec.noise, seed=0),
                                  execution=api.Execution(workers=1),
                                  beside=api.Beside(later=[later])).to_json()
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
    cross-validated J before, the `kept` candidates of lowest cross-validated J with their test,
    and the start's test where it was a candidate (`diagnosis.selection.start_test`)."""
    tests = decision.get("candidates", {})
    best = sorted(tests, key=lambda k: -tests[k]["cv_fall"])[:kept]
    return {"chosen": decision.get("chosen"), "cv_J_before": decision.get("cv_J_before"),
            "needed_noise": decision.get("noise_margin"), "indistinct": decision.get("indistinct", []),
            "best": {k: {key: tests[k].get(key) for key in ("cv_fall", "cv_se", "needed", "passes", "objection", "evidence")}
                     for k in best},
            **({"start": decision["start"]} if decision.get("start") is not None else {})}


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


def run(tasks, workers, scheduler=None, job=diagnose_one):
    """Each task `job(task)` (a record's diagnosis, `diagnose_one` unless another benchmark's) in a
    worker process (2 by default), or on the workers of the Dask cluster at `scheduler`, with a
    progress bar; each result kept as it comes; the results as they came."""
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
                cluster.map(job, tasks, done=lambda i, result: arrived(tasks[i], result))
        else:
            with lifetime.worker_pool(min(workers, len(tasks))) as pool:
                futures = {pool.submit(job, t): t for t in tasks}
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


def per_draw(texts):
    """One text where every draw gives the same, else the draws' texts separated by " / "."""
    return texts[0] if len(set(texts)) == 1 else " / ".join(texts)


def record_row(draws):
    """A record's row of the table "Every record": its diagnoses under each noise draw."""
    r = draws[0]

    def added(d):
        effects = ", ".join(f"{e}@{t}" for e, t in d["loop"]["effects"]) or "none"
        return (effects + ("" if right(d, "loop") else " (wrong)")
                + (" (a fault missed)" if len(d["faults"]) > 1 and not all_found(d) else ""))

    def base(d):
        b = d["baseline"]
        return f"{b['effect']}{'@' + b['target'] if b['target'] else ''}{'' if right(d, 'baseline') else ' (wrong)'}"

    def later(d):
        return (f"{d['later']['written'] / d['noise']:.2f}, {d['later']['corrected'] / d['noise']:.2f}"
                + ("" if held(d) else " (worse)"))

    after = per_draw([f"{d['loop']['hlc_after']:.1f}" if d["loop"]["hlc_after"] else "-" for d in draws])
    return (f"| {r['name']} | {r['before_ratio_noiseless']:.2f} | {per_draw([added(d) for d in draws])} | "
            f"{per_draw([format(d['loop']['after'] / d['noise'], '.2f') for d in draws])} | "
            f"{per_draw([later(d) for d in draws])} | {per_draw([base(d) for d in draws])} | "
            f"{r['hlc_truth']:.1f}, {after} | {per_draw([format(d['loop']['seconds'], '.0f') for d in draws])} |")


def summary(results, draws):
    """The tables and the criteria, as markdown lines; and the numbers."""
    ok = [r for r in results if "error" not in r]
    failed = [r for r in results if "error" in r]
    faulty = [r for r in ok if r["faults"]]
    pairs = [r for r in ok if len(r["faults"]) > 1]
    subtle = [r for r in ok if r["size"] == "subtle"]
    strong = [r for r in ok if r["size"] == "strong"]
    clean = [r for r in ok if not r["faults"]]
    # the records whose deep ground lies at an offset from their mean air; the faultless ones
    # read with a short history
    ground = [r for r in faulty if getattr(SPECS_BY_NAME.get(r["name"]), "ground_offset", None) is not None]
    short = [r for r in clean if r["name"] in SPECS_BY_NAME and SPECS_BY_NAME[r["name"]].before <= SHORT_HISTORY]
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
        "right_ground": share(right(r, "loop") for r in ground),
        "baseline_right_ground": share(right(r, "baseline") for r in ground),
        "right_or_tied": share(tied(r) for r in faulty), "right_or_tied_subtle": share(tied(r) for r in subtle),
        "baseline_right": share(right(r, "baseline") for r in faulty),
        "baseline_right_subtle": share(right(r, "baseline") for r in subtle),
        "clean_untouched": share(right(r, "loop") for r in clean),
        "baseline_clean_untouched": share(right(r, "baseline") for r in clean),
        "clean_short_untouched": share(right(r, "loop") for r in short),
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
        f"- {mark(numbers['right_ground'], CRITERIA['right_ground'])}: on {pct(numbers['right_ground'])} of the "
        "ground records, their deep ground 5 to 9 K either side of the record's mean outdoor air (>= 90 %); "
        f"the baseline {pct(numbers['baseline_right_ground'])}",
        f"- {mark(numbers['clean_untouched'], CRITERIA['clean_untouched'])}: nothing added to "
        f"{pct(numbers['clean_untouched'])} of the diagnoses of records without a fault (>= 95 %); the baseline "
        f"{pct(numbers['baseline_clean_untouched'])}",
        f"- {mark(numbers['clean_short_untouched'], CRITERIA['clean_untouched'])}: of those with at most "
        f"{SHORT_HISTORY:g} days of weather before the record, on {pct(numbers['clean_short_untouched'])} (>= 95 %)",
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
        "## The criteria", "", *criteria, "",
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
        "", "## Every record", "",
        "Each figure is given per noise draw (draw 0 first), once where every draw gives the same.", "",
        "| record | before/noise (noiseless) | loop: effects added | after/noise | later: written, corrected /noise "
        "| baseline | HLC truth, after (W/K) | s |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name in sorted({r["name"] for r in ok}):
        lines.append(record_row(sorted((r for r in ok if r["name"] == name), key=lambda r: r["draw"])))
    return lines, numbers


def scenarios_table():
    """Markdown: the records' scenarios, each fault's size and where its ground lies."""
    def entry(scenario, text):
        fault, _, size = text.partition(" ")
        if not size:
            return fault
        spec = SPECS_BY_NAME[f"{scenario}/{fault}-{size}"]
        ground = [f"ground at {f.full['T_ground']:g} C" for f in spec.faults if f.full.get("T_ground") is not None]
        if spec.ground_offset is not None:
            ground.append(f"ground at the record's mean air {spec.ground_offset:+g} K")
        return f"{fault} ({', '.join([spec.size, *ground])})"

    lines = ["| scenario | building | climate (typical year) | start | days | step | noise | sensors | weather before | faults |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for name, s in SCENARIOS.items():
        faults = ", ".join(entry(name, text) for text in PLAN[name])
        sensors = {"paper": "the paper's (1, 7, 9, 16, 17, 23)", "all": "every node",
                   "air": "the air, PRBS heater 300 W", "own": "its own 10"}[s.sensors]
        building = f"{s.building}{' (' + s.objective + ')' if s.objective else ''}"
        building += "" if s.declares_ground else ", no ground temperature declared"
        lines.append(f"| {name} | {building} | {s.climate} | "
                     f"{s.start} | {s.days} | {s.step_min} min | {s.noise} C | {sensors} | {s.before:g} days | {faults} |")
    return "\n".join(lines)


def compact(result):
    """A diagnosis's result as a run keeps it (what `summary` reads): the loop's rounds reduced to
    the candidates each names as not told apart from its choice."""
    if "error" in result:
        return result
    loop = {k: v for k, v in result["loop"].items() if k not in ("reason", "rounds")}
    loop["rounds"] = [{"indistinct": d.get("indistinct", [])} for d in result["loop"].get("rounds", [])]
    return {**{k: v for k, v in result.items() if k not in ("spec", "values", "generation_seconds", "loop")},
            "loop": loop, "baseline": {k: result["baseline"][k] for k in ("effect", "target", "seconds")}}


def cost_line(results):
    """What a diagnosis took in the run, by building: the median and the range of its seconds."""
    ok = [r for r in results if "error" not in r]
    parts = []
    for building in sorted({SPECS_BY_NAME[r["name"]].building for r in ok if r["name"] in SPECS_BY_NAME}):
        seconds = sorted(r["loop"]["seconds"] for r in ok if SPECS_BY_NAME.get(r["name"]) and
                         SPECS_BY_NAME[r["name"]].building == building)
        base = sorted(r["baseline"]["seconds"] for r in ok if SPECS_BY_NAME.get(r["name"]) and
                      SPECS_BY_NAME[r["name"]].building == building)
        parts.append(f"{building}: {statistics.median(seconds):.0f} s a diagnosis ({seconds[0]:.0f} to "
                     f"{seconds[-1]:.0f} s), its baseline {statistics.median(base):.0f} s")
    return "; ".join(parts)


def page(run, subset=False):
    """docs/benchmark_diagnosis.md of a run as `benchmarks.results` keeps it."""
    lines, _ = summary(run["diagnoses"], run["draws"])
    return "\n".join([
        "# The diagnosis on many records", "",
        "Does the diagnosis name the effect a record carries, and does its correction hold on data no "
        "choice read? Each record is the benchmark's building with a fault its file does not declare "
        "(or none); the diagnosis runs on the file as written and is judged by the first effect it adds, "
        "the error left on the days it held out, and the corrected file on a later record.", "",
        *(["A subset of the records; `make benchmark` writes the whole benchmark's tables to "
           "docs/benchmark_diagnosis.md.", ""] if subset else []),
        "Made by", "", f"    {run['command']}", "",
        kept_results.run_line(run), "",
        f"{run['workers']} diagnoses at a time, {run['minutes']:.0f} min for the {len(run['diagnoses'])} "
        "diagnoses. The loop runs through the public API (`nodeforce.api.diagnose`) with the command line's "
        f"settings: GA population {run['population']}, at most {run['generations']} generations (stopped at "
        "convergence), its own calibrations, seed 0, one worker per diagnosis, the sensors' noise given as a "
        f"user states it. Time: {cost_line(run['diagnoses'])}. Finished records are kept in "
        "out/bench_diagnosis/records, each with a digest of its spec and of the code (the package, the records, "
        "the baseline, the examples): a rerun skips what is unchanged, a changed loop runs everything again.", "",
        "## The records", "",
        "Made by `benchmarks/records.py` (its docstring says why each choice). The truth is the building "
        "file discretised finer (every stretch between two of its nodes or layer boundaries cut in two) and "
        "simulated at 1 min from 90 days of history (the typical year read as cyclic), sampled at the "
        "record's step; the diagnosis reads the weather from some days before the record ('weather before' "
        "below: its history, docs/model.md 5.7), never the truth's whole past. The fault is an effect the "
        "file does not declare, applied with the registry's own `apply`; or a gain on a schedule (150 W from "
        "08:00 to 18:00 at scale 1); or a south opening (0.6 m2 of glazing at scale 1, its sun to the floor); "
        "or the envelope's materials and outside film coefficients both twice the file's ('envelope-films'; "
        "'envelope' is the registry's factor on the materials alone). A few records carry two faults, moved "
        "by one common scale. A fault's size is tuned by simulating, so that the file's validation RMSE is "
        "2.2 x the noise (subtle, accepted 1.5 to 3) or 6 x (strong, 4 to 9), never beyond its physical "
        "limits (a factor on a conductance within 0.1 to 10, a room's mean convective coefficient within 0.5 "
        "to 20 W/m2/K): where the limit comes first, the record is as large as physics lets it be. Gaussian "
        "noise is seeded by the record's name and draw. Without a fault the file is still not the truth: "
        "its coarser walls and the part of the truth's past the weather does not reach leave it 0.03 to "
        "0.09 C.", "",
        "A ground fault puts the floor on a ground at a stated temperature, or at a stated offset from the "
        "record's mean outdoor air (the typical year's over the record's days): 5 to 9 K above or below it in "
        "each season, the scenarios named '-ground'. Every file declares the site's ground temperature (the "
        "typical year's mean air) except where the table says not: there the diagnosis' prior on the deep "
        "ground (docs/model.md, section 7, ground_coupling) is the mean air of a year of weather before the "
        "record, or of the weeks it reads, with a wide sd. The scenarios 'gso-oct-h0', '-h3' and '-h7' are "
        "the same autumn week, measured by the air alone, read with 0, 3 or 7 days of weather before it: "
        "the month before was 6 K warmer, and the floor's slow mode, which no sensor's burn-in sets, "
        "starts where the steady state of the history's mean conditions puts it: the file's validation RMSE "
        "without a fault is 2.4 to 2.9 times the noise.", "",
        scenarios_table(), "",
        "A first effect is right when it is the record's fault with its target. An air change and a bridge "
        "to the outdoor air are one equation and count as one; a schedule is right as a daily gain; the south "
        "opening as a gain following the south wall's sun or as the south window's transmittance; the "
        "envelope's materials and films as the zone's envelope factor or its conductance to the outdoor air. "
        "On a record without a fault, adding nothing is right. On a record with two faults the first effect "
        "is right when it names either, and both are found when each is among the effects added. The "
        "baseline (`benchmarks/baseline.py`) fits each catalogue effect alone by least squares on the "
        "calibration window and keeps the best by BIC if it falls by more than 10.", "",
        *lines,
    ]) + "\n"


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
    given = [a for a in (sys.argv[1:] if argv is None else argv) if a != "--fresh"]
    if "--docs" in given:  # where the tables go, not how they were made
        del given[given.index("--docs"):given.index("--docs") + 2]
    stamped = kept_results.stamp("diagnosis", f"python benchmarks/bench_diagnosis.py {' '.join(given)}"
                                 if given else COMMAND)
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
    figures = {"draws": draws, "workers": "a Dask cluster's" if args.scheduler else args.workers,
               "population": args.population, "generations": args.generations, "minutes": elapsed / 60,
               "numbers": numbers, "diagnoses": [compact(r) for r in results]}
    if args.quick or args.only or args.report or draws != 3 or args.history_days != HISTORY_DAYS:
        # a subset, a rerun of the tables, one draw or another history: under out/, never the docs
        written = args.docs or args.out / "summary.md"
        written.write_text(page({**stamped, **figures}, subset=True))
    else:
        saved = kept_results.save(stamped, figures)
        written = args.docs or DOCS
        written.write_text(page(kept_results.latest("diagnosis")))
        print(f"kept: {saved}")
    print(f"written: {written}, {args.out / 'results.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
