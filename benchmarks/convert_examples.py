"""`nodeforce convert` on every IDF of a folder of EnergyPlus's example files (an EnergyPlus
install's ExampleFiles/, or the repository's testfiles/) that describes a building envelope, then
`nodeforce simulate`'s model of each one that converts, free-floating over the first 31 days of an
EPW (January). Every file's row (version, zones, result, the refusal's reason, seconds, the zones'
coldest and warmest air) goes to OUT/examples.csv (converted as `nodeforce convert` converts, in two worker processes
without the command's start); the summary of docs/energyplus.md (the share converted, the
refusals by object type, the simulations) is printed in Markdown.

    python benchmarks/convert_examples.py FOLDER [--out OUT] [--weather EPW] [--timeout S] [--jobs N]

The weather defaults to the Golden, Colorado TMY3 EPW of the installed `energyplus` extra
(pyenergyplus/data/weather); without the extra and without --weather nothing is simulated.
"""
import argparse
import functools
import json
import re
import signal
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd

from nodeforce.iotools.energyplus import convert
from nodeforce.iotools.weather import read_weather
from nodeforce.model.building_file import load_building
from nodeforce.model.case import simulate_building
from nodeforce.model.errors import InputError

# A file describes a building envelope when it has a zone and a heat transfer surface
ZONE = re.compile(r"(?im)^\s*Zone\s*,")
SURFACE = re.compile(r"(?im)^\s*(BuildingSurface:Detailed|Wall:\w+|Floor:\w+|RoofCeiling:Detailed|Roof|Ceiling:\w+)\s*,")


def default_weather():
    """The extra's Golden, CO TMY3 EPW, or None without the extra."""
    try:
        import pyenergyplus
    except ImportError:
        return None
    path = Path(pyenergyplus.__file__).parent / "data" / "weather" / "USA_CO_Golden-NREL.724666_TMY3.epw"
    return path if path.exists() else None


def idf_text(idf):
    """The file's text without its comments."""
    return re.sub(r"!.*", "", Path(idf).read_text(encoding="utf-8", errors="replace"))


def idf_version(text):
    """The Version object's number, as written in the file."""
    found = re.search(r"(?i)\bVersion\s*,\s*([0-9.]+)\s*;", text)
    return found.group(1) if found else "?"


def describes_envelope(text):
    return bool(ZONE.search(text) and SURFACE.search(text))


# The weather a converted file is simulated over: its first days, January's (a year of each of the
# larger files, the 90.1 prototypes among them, made the corpus some two hours on two cores)
DAYS = 31


@functools.lru_cache(maxsize=1)
def weather_of(path):
    weather = read_weather(path)
    return weather[weather.index < weather.index[0] + pd.Timedelta(days=DAYS)]


def simulate_one(building, weather):
    """(status, coldest zone air, warmest zone air) of the converted building simulated free-floating
    over the weather's first DAYS days by the direct model (`nodeforce simulate`'s model, without its file of
    every node)."""
    try:
        loaded = load_building(building)
        T = simulate_building(loaded, weather_of(weather))
    except Exception as error:  # a row says what failed; the others go on
        return f"failed: {type(error).__name__}: {error}", None, None
    air = T[[f"T{z.air_node}" for z in loaded.zones]].to_numpy(float)
    if not np.isfinite(air).all():
        return "failed: a zone's air is not finite", None, None
    return "simulated", float(air.min()), float(air.max())


class Timeout(Exception):
    pass


def _alarm(*_):
    raise Timeout


def convert_in_process(idf, timeout):
    """(status, seconds, building data or None, refusal): `nodeforce convert`'s conversion in this
    worker, without the command's start (some 2 s a file), within `timeout` s."""
    signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(int(timeout))
    start = time.perf_counter()
    try:
        data, status, reason = convert(idf), "converted", ""
    except Timeout:
        data, status, reason = None, "timeout", f"no building file within {timeout:g} s"
    except InputError as error:  # the one-line refusal the command prints
        data, status, reason = None, "refused", str(error).removeprefix(f"{idf}: ")
    except Exception as error:  # a traceback the command would print: a defect, kept in the row
        data, status, reason = None, "failed", f"{type(error).__name__}: {error}"
    finally:
        signal.alarm(0)
    return status, time.perf_counter() - start, data, reason


def one_file(idf, version, out, weather, timeout):
    """The row of one IDF: its conversion, then its simulation where it converted."""
    status, seconds, data, reason = convert_in_process(idf, timeout)
    row = {"file": idf.stem, "version": version, "zones": None, "result": status, "reason": reason,
           "convert_s": round(seconds, 2), "simulation": "", "air_min": None, "air_max": None}
    if data is None:
        return row
    row["zones"] = len(data["zones"])
    if weather is not None:
        path = out / f"{idf.stem}.json"
        path.write_text(json.dumps(data))
        row["simulation"], row["air_min"], row["air_max"] = simulate_one(path, weather)
    return row


def refused_object(reason):
    """The object type a refusal names (its first word), or the reason's start."""
    return reason.split(" ", 1)[0].strip("'") if reason else "?"


def summary(table, others, weather):
    """The Markdown summary: the share converted, the refusals by object type, the simulations."""
    converted = table[table.result == "converted"]
    refused = table[table.result != "converted"]
    lines = [f"{len(converted)} of {len(table)} files that describe a building envelope converted "
             f"({100.0 * len(converted) / max(len(table), 1):.0f} %); {others} other files (plant loops, "
             "water heaters, weather bins: no zone or no surface) not counted.", ""]
    if len(refused):
        lines += ["| refused at | files | reason (one of them) |", "|---|---|---|"]
        for obj, group in refused.groupby(refused.reason.map(refused_object)):
            lines.append(f"| {obj} | {len(group)} | {group.reason.iloc[0]} ({group.file.iloc[0]}) |")
        lines.append("")
    if weather is not None:
        done = converted[converted.simulation == "simulated"]
        lines.append(f"{len(done)} of {len(converted)} simulated free-floating over the first {DAYS} days of {Path(weather).name}; "
                     f"zone air from {done.air_min.min():.1f} to {done.air_max.max():.1f} C; "
                     f"conversion {converted.convert_s.median():.1f} s median, {converted.convert_s.max():.1f} s "
                     "at most (in the worker, without the command's start).")
        failed = converted[converted.simulation != "simulated"]
        for _, row in failed.iterrows():
            lines.append(f"- {row.file}: {row.simulation}")
    return "\n".join(lines)


def main(folder, out, weather, timeout, jobs):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    texts = {idf: idf_text(idf) for idf in sorted(Path(folder).glob("*.idf"))}
    envelopes = [idf for idf, text in texts.items() if describes_envelope(text)]
    with ProcessPoolExecutor(jobs) as pool:
        futures = [pool.submit(one_file, idf, idf_version(texts[idf]), out, weather, timeout) for idf in envelopes]
        rows = []
        for number, future in enumerate(futures, 1):
            rows.append(future.result())
            print(f"[{number}/{len(futures)}] {rows[-1]['file']}: {rows[-1]['result']} {rows[-1]['simulation']}",
                  file=sys.stderr, flush=True)
    table = pd.DataFrame(rows)
    table.to_csv(out / "examples.csv", index=False)
    print(summary(table, len(texts) - len(envelopes), weather))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", help="a folder of EnergyPlus IDFs (ExampleFiles/ or testfiles/)")
    parser.add_argument("--out", default="out/convert_examples")
    parser.add_argument("--weather", default=None, help="an EPW (default: the extra's Golden, CO TMY3)")
    parser.add_argument("--timeout", type=float, default=120.0)
    parser.add_argument("--jobs", type=int, default=2, help="files converted and simulated at once")
    args = parser.parse_args()
    main(args.folder, args.out, args.weather or default_weather(), args.timeout, args.jobs)
