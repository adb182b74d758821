"""`nodeforce convert` on every IDF the installed `energyplus` extra ships (pyenergyplus-lbnl's
DOE commercial reference buildings and ASHRAE 90.1 prototypes, pyenergyplus/data/model/*.idf):
each converted by the command a user runs, in its own process with a time limit; the table of
docs/energyplus.md (file, version, zones, components, lines not modelled, seconds, and the
refusal where one), in Markdown on stdout.

    python benchmarks/convert_corpus.py [OUT] [--timeout S]     (default out/convert_corpus, 60 s)
"""
import argparse
import json
import subprocess
import sys
import time
from pathlib import Path


def shipped_idfs():
    """The IDFs of the installed pyenergyplus package, sorted; [] without it."""
    try:
        import pyenergyplus
    except ImportError:
        return []
    return sorted((Path(pyenergyplus.__file__).parent / "data" / "model").glob("*.idf"))


def convert_one(idf, out, timeout):
    """(status, seconds, building JSON or None, stderr) of `nodeforce convert IDF -o OUT`."""
    nodeforce = Path(sys.executable).parent / "nodeforce"
    start = time.perf_counter()
    try:
        done = subprocess.run([str(nodeforce), "convert", str(idf), "-o", str(out)], capture_output=True, text=True,
                              timeout=timeout)
    except subprocess.TimeoutExpired:
        return "timeout", time.perf_counter() - start, None, ""
    seconds = time.perf_counter() - start
    data = json.loads(Path(out).read_text()) if done.returncode == 0 else None
    return {0: "converted", 2: "refused"}.get(done.returncode, f"exit {done.returncode}"), seconds, data, done.stderr


def main(out, timeout):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rows = ["| file | EnergyPlus | zones | components | not modelled | s | result |", "|---|---|---|---|---|---|---|"]
    for idf in shipped_idfs():
        status, seconds, data, stderr = convert_one(idf, out / f"{idf.stem}.json", timeout)
        if data is not None:
            version = data["description"].split("(EnergyPlus ")[1].split(")")[0]
            rows.append(f"| {idf.stem} | {version} | {len(data['zones'])} | {len(data['components'])} | "
                        f"{len(data['not_modelled'])} | {seconds:.1f} | {status} |")
        else:
            reason = stderr.strip().split(": ", 2)[-1] if stderr.strip() else status
            rows.append(f"| {idf.stem} | | | | | {seconds:.1f} | {status}: {reason} |")
    print("\n".join(rows))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default="out/convert_corpus")
    parser.add_argument("--timeout", type=float, default=60.0)
    args = parser.parse_args()
    main(args.out, args.timeout)
