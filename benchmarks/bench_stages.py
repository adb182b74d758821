"""Where a diagnosis's time goes, stage by stage (docs/performance.md, "The search's own FMU"):
benchmark records (`benchmarks/records.py`, draw 0) diagnosed in this process alone as
`bench_diagnosis.py` diagnoses them (`api.diagnose`, one worker, the noise given; without their
later record), the wall seconds of each stage of `diagnosis.loop.diagnose` (`prepare`: the
windows and the model's run before; `localise`: the forcing search; `rounds`: the candidates
and the choices; `write`: the model after, the report and its plots).

    python benchmarks/bench_stages.py                    # the records below
    python benchmarks/bench_stages.py gso-jan/door-s     # others

Run it in two checkouts to compare them (this file copied into the older).
"""
import contextlib
import io
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1]))

from benchmarks.records import record  # noqa: E402
from nodeforce import api  # noqa: E402
from nodeforce.diagnosis import loop  # noqa: E402

RECORDS = ("mia-jun/door-s", "gso-jan/door-s")
STAGES = ("prepare", "localise", "rounds", "write")


def timed_stages(name):
    """({stage: wall seconds}, the whole diagnosis's wall seconds) of the record's draw 0."""
    seconds = {}
    originals = {stage: getattr(loop, stage) for stage in STAGES}

    def timing(stage):
        def run(*args, **kwargs):
            started = time.perf_counter()
            try:
                return originals[stage](*args, **kwargs)
            finally:
                seconds[stage] = seconds.get(stage, 0.0) + time.perf_counter() - started
        return run

    r = record(name, 0)
    case = r.case()
    try:
        for stage in STAGES:  # `diagnose` calls its stages by their module names
            setattr(loop, stage, timing(stage))
        with tempfile.TemporaryDirectory() as out, contextlib.redirect_stdout(io.StringIO()):
            started = time.perf_counter()
            api.diagnose(r.building, case, Path(out), objective=api.objective(r.building, r.zones),
                         search=api.SearchSettings(noise=r.spec.noise, seed=0),
                         execution=api.Execution(workers=1))
            whole = time.perf_counter() - started
    finally:
        for stage, original in originals.items():
            setattr(loop, stage, original)
    return seconds, whole


def measure(names=RECORDS):
    """Each record's stages: {"tables": Markdown lines, "seconds": {record: {stage: s, "diagnosis": s}}}."""
    tables = ["| record | " + " | ".join(f"{stage} (s)" for stage in STAGES) + " | diagnosis (s) |",
              "|---|" + "---|" * (len(STAGES) + 1)]
    figures = {}
    for name in names:
        seconds, whole = timed_stages(name)
        figures[name] = {**seconds, "diagnosis": whole}
        tables.append(f"| {name} | " + " | ".join(f"{seconds.get(stage, 0.0):.1f}" for stage in STAGES)
                      + f" | {whole:.1f} |")
    return {"tables": tables, "seconds": figures}


def main(names):
    print("\n".join(measure(names or RECORDS)["tables"]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
