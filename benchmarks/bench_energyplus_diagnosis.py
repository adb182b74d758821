"""Does the diagnosis name a change EnergyPlus simulated, and does its correction hold in EnergyPlus?

The records (`benchmarks/energyplus_records.py`, which says each choice and what a right answer
is per change): ASHRAE 140's light and heavy buildings under Chicago's spring, four weeks at
10 min, the zone air and three inside faces measured with 0.1 C of noise; EnergyPlus simulates
each with one change made only in the IDF it runs (air change x3, the walls' insulation x2 as
conductive, a furniture mass, the glass's solar transmittance x0.6, an office-hours gain of
300 W, the roof's solar absorptance 0.6 -> 0.9), or none.

Each record, under `--draws` noise draws: the unchanged IDF converted (`nodeforce.api.convert_idf`)
and diagnosed (`nodeforce.api.diagnose`, the command line's settings: GA population 30, 400
generations at most, seed 0, one worker, the sensors' noise given as the user would state it)
on the weather read from the same EPW, with the loop's own days of history before the record;
then EnergyPlus runs the diagnosis's `model_after.idf` and the unchanged IDF, and each is scored
(the zone air's RMSE) against the truth's later record, the same change two weeks after the
record ends. The judging and the tables are bench_diagnosis.py's (`first`, `right`, `held`,
`confusion`); its workers and its finished-record cache too: the results go to
`out/bench_energyplus_diagnosis/records/`, each with a digest of its spec and of the code, and a
rerun skips the finished ones. EnergyPlus needs the `energyplus` extra; it runs in temporary
folders, removed when a run ends, however it ends.

    make benchmark-energyplus                                   # every record, 3 draws, 2 workers
    python benchmarks/bench_energyplus_diagnosis.py --draws 1   # every record, one draw
    python benchmarks/bench_energyplus_diagnosis.py --only '600FF/*' --draws 1
    python benchmarks/bench_energyplus_diagnosis.py --report    # the tables from the records already run
"""
import argparse
import contextlib
import fnmatch
import io
import json
import math
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks import energyplus_records as records  # noqa: E402
from benchmarks.bench_diagnosis import (CODE_DIGEST, WITHIN, confusion, held, result_path, right, run,  # noqa: E402
                                        share)

OUT = ROOT / "out" / "bench_energyplus_diagnosis"
DOCS = ROOT / "docs" / "benchmark_energyplus.md"
COMMAND = "make benchmark-energyplus  # python benchmarks/bench_energyplus_diagnosis.py (3 draws, 2 workers)"
CRITERIA = {"right": 0.9, "clean_untouched": 0.95, "carried": 0.95}  # issue 74's "Done means"


def digest(name):
    return records.spec_digest(records.SPECS_BY_NAME[name], CODE_DIGEST)


def finished(path, name):
    """Whether `path` holds the result of this very record, made by this code."""
    try:
        return json.loads(path.read_text()).get("spec") == digest(name)
    except (OSError, ValueError):
        return False


def rmse(a, b):
    d = a.to_numpy(float) - b.to_numpy(float)
    return float(math.sqrt(float((d ** 2).mean())))


def diagnose_one(task):
    """EnergyPlus's truth of one record, its diagnosis, and EnergyPlus again on the later record."""
    name, draw, path, population, generations = task
    import idfkit
    from nodeforce import api
    from nodeforce.runtime import tempdirs
    spec = records.SPECS_BY_NAME[name]
    try:
        epw = records.package_weather()
        offset = records.utc_offset(epw)
        started = time.time()
        truth = records.simulate_energyplus(records.changed_document(spec), epw)
        original = records.simulate_energyplus(records.building_document(spec.building), epw)
        with tempdirs.folder("bench-energyplus-diagnosis") as tmp:
            tmp = Path(tmp)
            idfkit.save_idf(records.building_document(spec.building), str(tmp / "model.idf"))
            building = api.convert_idf(tmp / "model.idf", output=tmp / "building.json")
            columns = records.sensors(building)
            measured = records.noisy(records.sample(truth, "record", columns, offset), name, draw)
            later = records.noisy(records.sample(truth, "later", columns, offset), f"{name}+later", draw)
            records.write_measurements(measured, tmp / "measurements.csv")
            building, case = api.read_case(building, epw, tmp / "measurements.csv", api.Reading(burn_in_days=1))
            t = time.time()
            with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
                diagnosis = api.diagnose(building, case, tmp / "diagnosis",
                                         objective=api.objective(building, [records.ZONE]),
                                         search=api.SearchSettings(population=population, generations=generations,
                                                                   noise=records.NOISE, seed=0),
                                         execution=api.Execution(workers=1))
            seconds = time.time() - t
            report = diagnosis.to_json()
            written = diagnosis.energyplus
            corrected = records.simulate_energyplus(idfkit.load_idf(written["idf_after"]), epw)
        air = {c: k for c, k in columns.items() if k == records.ZONE}
        scored = {label: rmse(records.sample(steps, "later", air, offset).iloc[:, 0], later[list(air)[0]])
                  for label, steps in (("written", original), ("corrected", corrected))}
        return {
            "name": name, "draw": draw, "spec": digest(name), "fault": spec.label,
            "faults": [[list(a) for a in spec.answers]] if spec.answers else [], "noise": records.NOISE,
            "loop": {"effects": [[e["effect"], e["target"]] for e in report.get("effects", [])],
                     "before": report["before"]["validation"]["rmse"], "after": report["after"]["validation"]["rmse"],
                     "seconds": seconds, "reason": report.get("decision", {}).get("reason")},
            "idf_changes": [{k: str(v) for k, v in c.items()} for c in written["changes"]],
            "not_written": written["not_written"],
            # how far nodeforce's model is from EnergyPlus's on the unchanged IDF: the record's air
            "record_energyplus_vs_truth": rmse(records.sample(original, "record", air, offset).iloc[:, 0],
                                               measured[list(air)[0]]),
            "later": {"written": scored["written"], "corrected": scored["corrected"]},
            "total_seconds": time.time() - started,
        }
    except Exception as error:  # reported, not cached: a rerun tries it again
        return {"name": name, "draw": draw, "error": f"{type(error).__name__}: {error}"}


def summary(results, draws):
    """The criteria and the tables, as markdown lines; and the numbers."""
    ok = [r for r in results if "error" not in r]
    failed = [r for r in results if "error" in r]
    faulty = [r for r in ok if r["faults"]]
    clean = [r for r in ok if not r["faults"]]
    numbers = {"diagnoses": len(ok), "failed": len(failed),
               "right": share(right(r, "loop") for r in faulty),
               "clean_untouched": share(right(r, "loop") for r in clean),
               "carried": share(held(r) for r in ok),
               "seconds_median": statistics.median(r["loop"]["seconds"] for r in ok) if ok else float("nan")}
    pct = lambda x: "n/a" if math.isnan(x) else f"{100 * x:.0f} %"  # noqa: E731

    def mark(key):
        return "n/a" if math.isnan(numbers[key]) else "PASS" if numbers[key] >= CRITERIA[key] else "FAIL"
    lines = [
        f"{len(ok)} diagnoses of {len({r['name'] for r in ok})} records: "
        + ", ".join(f"draw {d} of {sum(r['draw'] == d for r in ok)}" for d in range(draws))
        + (f"; {len(failed)} failed: " + "; ".join(f"{r['name']} draw {r['draw']}: {r['error']}" for r in failed)
           if failed else ""), "",
        "## The criteria (issue 74)", "",
        f"- {mark('right')}: first effect right on {pct(numbers['right'])} of the diagnoses of changed records (>= 90 %)",
        f"- {mark('clean_untouched')}: nothing added on {pct(numbers['clean_untouched'])} of the diagnoses of "
        "unchanged records (>= 95 %)",
        f"- {mark('carried')}: on the later record, EnergyPlus with model_after.idf no worse than with the "
        f"original IDF beyond {WITHIN} x the noise on {pct(numbers['carried'])} (>= 95 %)", "",
        "## First effect added, every record", "", confusion(ok), "",
        "## Every record", "",
        f"Time per diagnosis: median {numbers['seconds_median']:.0f} s. "
        "Zone air RMSE in C. 'change (E+)' is EnergyPlus on the unchanged IDF against the record: the change's "
        "size as EnergyPlus sees it; "
        "'nodeforce before/after' the diagnosis's validation RMSE (its last 40 % of the record); 'later' "
        "EnergyPlus on the later record with the original IDF and with model_after.idf.", "",
        "| record | draw | effects added | change (E+) | nodeforce before, after | later: original, model_after "
        "| written into the IDF | s |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in sorted(ok, key=lambda r: (r["name"], r["draw"])):
        effects = ", ".join(f"{e}@{t}" for e, t in r["loop"]["effects"]) or "none"
        changes = (f"{len(r['idf_changes'])} fields or objects" if r["idf_changes"] else "-") + "".join(
            f"; not {n.split(':')[0]}" for n in r["not_written"])
        lines.append(
            f"| {r['name']} | {r['draw']} | {effects}{'' if right(r, 'loop') else ' (wrong)'} | "
            f"{r['record_energyplus_vs_truth']:.3f} | {r['loop']['before']:.3f}, {r['loop']['after']:.3f} | "
            f"{r['later']['written']:.3f}, {r['later']['corrected']:.3f}{'' if held(r) else ' (worse)'} | "
            f"{changes} | {r['loop']['seconds']:.0f} |")
    return lines, numbers


def page(lines, command):
    """docs/benchmark_energyplus.md: the records, the judging, the command and the tables."""
    doc = records.__doc__.split("\n\n")
    return "\n".join([
        "# The diagnosis judged against EnergyPlus", "",
        "Does the diagnosis name a change that EnergyPlus, not nodeforce, simulated, and does the correction "
        "it writes into the IDF (`model_after.idf`) hold when EnergyPlus runs it? Each record is an ASHRAE 140 "
        "building whose IDF EnergyPlus runs with one change the diagnosed IDF does not declare, or none; "
        "nodeforce converts the unchanged IDF and diagnoses it. Beside "
        "[benchmark_diagnosis.md](benchmark_diagnosis.md), whose truth is nodeforce's own physics, this one "
        "also carries every difference between the two programs on the same IDF "
        "([energyplus.md](energyplus.md#beside-energyplus-free-floating)).", "",
        "Made by", "", f"    {command}", "",
        "from the records `make benchmark-energyplus` finished (kept in out/bench_energyplus_diagnosis/records, "
        "each with a digest of its spec and of the code: a rerun skips what is unchanged; `--report` makes "
        "this page again from them). EnergyPlus is the `energyplus` extra's (pyenergyplus).", "",
        "## The records", "",
        "Made by `benchmarks/energyplus_records.py` (its docstring says each choice). " + " ".join(
            " ".join(line.strip() for line in part.splitlines()) for part in doc[1:2]), "",
        *("- " + " ".join(line.strip() for line in item.splitlines()).lstrip("- ")
          for item in doc[2].split("\n- ")), "",
        f"Here `START` is {records.START} ({records.YEAR}'s calendar), `DAYS` {records.DAYS}, `LATER_GAP_DAYS` "
        f"{records.LATER_GAP_DAYS}, `RUN_BEFORE_DAYS` {records.RUN_BEFORE_DAYS}, `ENERGYPLUS_STEPS` "
        f"{records.ENERGYPLUS_STEPS}, `STEP_MIN` {records.STEP_MIN} and `NOISE` {records.NOISE} C.", "",
        "Each record, under each noise draw, is diagnosed through the public API (`nodeforce.api.convert_idf`, "
        "`nodeforce.api.diagnose`) with the command line's settings: GA population 30, at most 400 generations, "
        "seed 0, one worker, the sensors' noise (0.1 C) given, one day of burn-in, the weather read from the "
        "same EPW with the loop's own days of history (docs/model.md 5.7). EnergyPlus then runs "
        "`model_after.idf` and the unchanged IDF over the later record, and each is scored by its zone air's "
        "RMSE against the truth's later record (noise included).", "",
        "A first effect is right when it names the change (`Change.answers`):", "",
        *("- " + " ".join(line.strip() for line in item.splitlines()).lstrip("- ")
          for item in doc[4].split("\n- ")), "",
        "On a record without a change, adding nothing is right. The correction holds when EnergyPlus with "
        f"`model_after.idf` is no worse than with the original IDF on the later record, beyond {WITHIN} x the "
        "noise (bench_diagnosis.py's `held`).", "",
        *lines,
    ]) + "\n"


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--only", help="records whose name matches this glob, e.g. '600FF/*'")
    p.add_argument("--draws", type=int, default=3)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--population", type=int, default=30)
    p.add_argument("--generations", type=int, default=400)
    p.add_argument("--out", type=Path, default=OUT)
    p.add_argument("--report", action="store_true", help="no diagnosis: the tables of the records already run")
    p.add_argument("--fresh", action="store_true", help="run every record again")
    p.add_argument("--docs", type=Path, help="the page written (default docs/benchmark_energyplus.md for every "
                                              "record under 3 draws, out/bench_energyplus_diagnosis/summary.md else)")
    args = p.parse_args(argv)
    try:
        records.package_weather()
    except ImportError:
        print("bench_energyplus_diagnosis needs EnergyPlus: pip install -e '.[energyplus]'", file=sys.stderr)
        return 2
    specs = [s for s in records.SPECS if not args.only or fnmatch.fnmatch(s.name, args.only)]
    # every record's first draw before any second: a run stopped early has the most records
    tasks = [(s.name, d, result_path(args.out, s.name, d), args.population, args.generations)
             for d in range(args.draws) for s in specs]
    unfinished = [t for t in tasks if args.fresh or not finished(t[2], t[0])]
    todo = [] if args.report else unfinished
    print(f"{len(specs)} records x {args.draws} draws: {len(tasks) - len(unfinished)} done before, {len(todo)} to run "
          f"on {args.workers} workers", flush=True)
    started = time.time()
    from nodeforce.runtime import lifetime, tempdirs
    # EnergyPlus works in temporary folders (`records.simulate_energyplus`), as the diagnoses do:
    # a signal stops the run through their `with` blocks, the workers remove theirs as they are
    # stopped, and those of a run killed outright go at the next run's start
    with lifetime.stop_on_signals():
        tempdirs.sweep()
        fresh = {(r["name"], r["draw"]): r for r in run(todo, args.workers, job=diagnose_one)}
    results = [fresh.get((t[0], t[1])) or (json.loads(t[2].read_text()) if finished(t[2], t[0]) else None)
               for t in tasks]
    results = [r for r in results if r is not None]
    lines, numbers = summary(results, args.draws)
    if todo:
        lines += ["", f"{(time.time() - started) / 60:.0f} min on {args.workers} workers for {len(todo)} diagnoses"]
    print("\n".join(lines))
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "results.json").write_text(json.dumps({"numbers": numbers, "results": results}, indent=1) + "\n")
    given = [a for a in (sys.argv[1:] if argv is None else argv) if a != "--fresh"]
    if "--docs" in given:  # where the page goes, not how it was made
        del given[given.index("--docs"):given.index("--docs") + 2]
    command = f"python benchmarks/bench_energyplus_diagnosis.py {' '.join(given)}" if given else COMMAND
    whole = not args.only and args.draws == 3
    written = args.docs or (DOCS if whole else args.out / "summary.md")
    written.write_text(page(lines, command))
    print(f"written: {written}, {args.out / 'results.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
