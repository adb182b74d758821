"""`nodeforce convert` on every IDF of a folder of EnergyPlus's example files (an EnergyPlus
install's ExampleFiles/, or the repository's testfiles/), then `nodeforce simulate` of each one that
converts, free-floating over an EPW year: the table of docs/energyplus.md (file, version, zones,
result and the refusal's reason, the zones' coldest and warmest air over the year), in Markdown on
stdout, and the share converted.

    python benchmarks/convert_examples.py FOLDER [--out OUT] [--weather EPW] [--timeout S]

The weather defaults to the Golden, Colorado TMY3 EPW of the installed `energyplus` extra
(pyenergyplus/data/weather); without the extra and without --weather nothing is simulated.
"""
import argparse
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
from convert_corpus import convert_one  # noqa: E402


def default_weather():
    """The extra's Golden, CO TMY3 EPW, or None without the extra."""
    try:
        import pyenergyplus
    except ImportError:
        return None
    path = Path(pyenergyplus.__file__).parent / "data" / "weather" / "USA_CO_Golden-NREL.724666_TMY3.epw"
    return path if path.exists() else None


def idf_version(idf):
    """The Version object's number, as written in the file."""
    text = re.sub(r"!.*", "", Path(idf).read_text(encoding="utf-8", errors="replace"))
    found = re.search(r"(?i)\bVersion\s*,\s*([0-9.]+)\s*;", text)
    return found.group(1) if found else "?"


def simulate_one(building, weather, out, timeout):
    """(status, seconds, coldest zone air, warmest zone air) of `nodeforce simulate`."""
    nodeforce = Path(sys.executable).parent / "nodeforce"
    start = time.perf_counter()
    try:
        done = subprocess.run([str(nodeforce), "simulate", str(building), "--weather", str(weather), "-o", str(out)],
                              capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return "timeout", time.perf_counter() - start, None, None
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        return f"failed: {done.stderr.strip().splitlines()[-1] if done.stderr.strip() else done.returncode}", \
            seconds, None, None
    names = pd.read_csv(Path(out).with_suffix(".nodes.csv"))
    air = names.loc[names["name"].str.endswith(" air"), "column"].tolist()
    T = pd.read_csv(out, usecols=air).to_numpy()
    if not np.isfinite(T).all():
        return "failed: a zone's air is not finite", seconds, None, None
    return "simulated", seconds, float(T.min()), float(T.max())


def main(folder, out, weather, timeout):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    idfs = sorted(Path(folder).glob("*.idf"))
    rows = ["| file | EnergyPlus | zones | result | free-floating air, min to max (C) |", "|---|---|---|---|---|"]
    converted = simulated = 0
    for idf in idfs:
        status, seconds, data, stderr = convert_one(idf, out / f"{idf.stem}.json", timeout)
        if data is None:
            reason = stderr.strip().split(": ", 2)[-1] if stderr.strip() else status
            rows.append(f"| {idf.stem} | {idf_version(idf)} | | {status}: {reason} | |")
            continue
        converted += 1
        air = "not simulated (no weather)"
        if weather is not None:
            sim, _, low, high = simulate_one(out / f"{idf.stem}.json", weather, out / f"{idf.stem}.csv", timeout)
            simulated += sim == "simulated"
            air = f"{low:.1f} to {high:.1f}" if sim == "simulated" else sim
        rows.append(f"| {idf.stem} | {idf_version(idf)} | {len(data['zones'])} | {status} | {air} |")
    print("\n".join(rows))
    share = 100.0 * converted / len(idfs) if idfs else 0.0
    print(f"\n{converted} of {len(idfs)} converted ({share:.0f} %)"
          + (f"; {simulated} of {converted} simulated over {Path(weather).name}" if weather is not None else ""))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", help="a folder of EnergyPlus IDFs (ExampleFiles/ or testfiles/)")
    parser.add_argument("--out", default="out/convert_examples")
    parser.add_argument("--weather", default=None, help="an EPW (default: the extra's Golden, CO TMY3)")
    parser.add_argument("--timeout", type=float, default=120.0)
    args = parser.parse_args()
    main(args.folder, args.out, args.weather or default_weather(), args.timeout)
