"""Benchmark results: each run's figures in a dated JSON file under benchmarks/results/, from
which the docs' tables are made (`benchmarks/pages.py`).

A result is `{"benchmark", "command", "commit", "date", "machine", "python", ...figures}`: the
figures are the benchmark's own, with the Markdown tables the docs show under "tables".
"""
import datetime
import json
import os
import platform
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
# The folders whose files make a benchmark's figures: a change there is a change of what was run.
CODE = ("nodeforce", "runtime", "model", "fmu_build", "cosim", "ga", "diagnosis", "iotools", "benchmarks", "examples", "tests")


def cpu_model():
    """The processor's model name (Linux), else what `platform` knows."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def commit():
    """HEAD's short hash, "+changes" after it where tracked files of the `CODE` folders differ from
    it; "unknown" outside git."""
    def git(*args):
        return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()
    try:
        head = git("rev-parse", "--short=7", "HEAD")
        return head + ("+changes" if git("status", "--porcelain", "--untracked-files=no", "--", *CODE) else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def stamp(name, command):
    """What says where a run's figures come from, taken as it starts: the benchmark, its command,
    the commit, the date and the machine (its load: the processes ready to run, averaged over the
    minute before, on a machine of `os.cpu_count()` cores)."""
    return {"benchmark": name, "command": command, "commit": commit(), "date": datetime.date.today().isoformat(),
            "machine": f"{os.cpu_count()} cores, {cpu_model()}, {platform.system()}, load {os.getloadavg()[0]:.1f}",
            "python": platform.python_version()}


def save(stamped, figures, folder=RESULTS):
    """Write a run's figures with its `stamp` as `folder/NAME-YYYY-MM-DD.json` (a run of the same
    day replaces it); return the path."""
    result = {**stamped, **figures}
    name = result["benchmark"]
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}-{result['date']}.json"
    path.write_text(json.dumps(result, indent=1) + "\n")
    return path


def latest(name, folder=RESULTS):
    """The newest result of benchmark `name` (by the date in its file name), or None."""
    paths = sorted(folder.glob(f"{name}-????-??-??.json"))
    return json.loads(paths[-1].read_text()) if paths else None


def run_line(result):
    """The one line a page gives its run: command, commit, date and machine."""
    return (f"Run: `{result['command']}` on commit {result['commit']}, {result['date']}, "
            f"{result['machine']}, Python {result['python']}.")
