"""The converted reference buildings beside EnergyPlus, free-floating: each DOE reference / ASHRAE
90.1 prototype IDF named (pyenergyplus-lbnl's, the `energyplus` extra) converted by `nodeforce
convert` and simulated over its own city's TMY3 year, and run by EnergyPlus 25.2.0 (the engine
pyenergyplus-lbnl 26.1.0 ships) on the same EPW with only the objects the converter reads
(`iotools.energyplus.READ`, its holidays): no HVAC, no thermostat, no daylight saving. Per zone
the hourly air's RMSE and mean difference (nodeforce - EnergyPlus) and each program's mean; per
inside face (EnergyPlus's "Surface Inside Face Temperature" beside the node of the same face,
`energyplus_comparison`) the hourly RMSE and mean difference, from the same EnergyPlus run.
OUT/comparison.csv holds the zones, OUT/faces.csv the faces; docs/energyplus.md carries the
table. A building EnergyPlus does not run to its end is a row saying so, with EnergyPlus's own
first severe error, and the others go on.

    python benchmarks/bench_energyplus_reference.py [OUT] [--models NAME,...]   (default: every shipped IDF)
"""
import argparse
import sys
from pathlib import Path

import idfkit
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from bench_energyplus import compare, free_year, run_energyplus  # noqa: E402
from energyplus_comparison import read_outputs  # noqa: E402
from convert_corpus import shipped_idfs  # noqa: E402

from nodeforce.api import convert_idf  # noqa: E402
from nodeforce.iotools.energyplus import READ  # noqa: E402
from nodeforce.iotools.typical_year import convert_typical_year  # noqa: E402
from nodeforce.iotools.weather import read_weather  # noqa: E402
from nodeforce.model.case import simulate_building  # noqa: E402

YEAR = 2017
KEEP = {k.upper() for k in READ} | {"RUNPERIODCONTROL:SPECIALDAYS", "TIMESTEP", "SITE:GROUNDTEMPERATURE:BUILDINGSURFACE"}


def weather_of(idf):
    """The package's TMY3 EPW of the model's city (Chicago for the 2004 buildings, Denver for 2019's)."""
    folder = idf.parent.parent / "weather"
    city = "Chicago-OHare" if "Chicago" in idf.stem else "Denver-Aurora"
    (epw,) = folder.glob(f"*{city}*.epw")
    return epw


def free_floating(idf, out):
    """The IDF with only the objects the converter reads, a free-floating year reporting the zones'
    mean air and the faces' inside temperatures hourly."""
    doc = idfkit.load_idf(str(idf))
    for obj in list(doc.all_objects):
        if obj.obj_type.upper() not in KEEP or obj.obj_type == "Version":
            if obj.obj_type != "Version":
                doc.removeidfobject(obj)
        elif obj.to_dict().get("frame_and_divider_name"):
            obj.frame_and_divider_name = ""  # a window's frame, which the converter does not read
    free_year(doc, "Hourly")
    idfkit.save_idf(doc, str(out))
    return out


def energyplus(idf, folder, epw):
    """(zone air, inside faces) hourly (C, `energyplus_comparison.read_outputs`) of EnergyPlus's run; a run
    of the same free-floating IDF on the same EPW already in `folder` is read, not repeated
    (EnergyPlus's side does not change with nodeforce's code)."""
    folder.mkdir(parents=True, exist_ok=True)
    model = free_floating(idf, folder / "next.idf")
    ran = folder / "free_floating.idf"
    stamp = folder / "weather.txt"
    if (ran.exists() and ran.read_bytes() == model.read_bytes() and stamp.exists()
            and stamp.read_text() == str(epw) and (folder / "eplusout.csv").exists()):
        model.unlink()
        return read_outputs(folder, YEAR)
    model.replace(ran)
    stamp.unlink(missing_ok=True)
    run_energyplus(ran, folder, epw)
    stamp.write_text(str(epw))
    return read_outputs(folder, YEAR)


def severe_error(folder):
    """EnergyPlus's first severe (or fatal) message of the run in `folder`, on one line."""
    lines = (folder / "eplusout.err").read_text(errors="replace").splitlines()
    start = next((k for k, line in enumerate(lines) if "** Severe  **" in line or "**  Fatal  **" in line), None)
    if start is None:
        return "no severe error written"
    message = [lines[start].split("**", 2)[-1].strip()]
    message += [line.split("~~~", 1)[-1].strip() for line in lines[start + 1:start + 3] if "~~~" in line]
    return " ".join(message)


def main(out, models):
    """Every building named in `models` beside EnergyPlus; OUT/comparison.csv (zones), faces.csv and
    stopped.csv (the buildings EnergyPlus does not run to their end) rewritten after each, so that
    a run cut short keeps what it did; then the table (`report`)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    idfs = {p.stem: p for p in shipped_idfs()}
    rows, failed = [], []
    for number, name in enumerate(models, 1):
        print(f"[{number}/{len(models)}] {name}", file=sys.stderr, flush=True)
        idf = idfs[name]
        epw = weather_of(idf)
        if not (out / f"{epw.stem}.csv").exists():
            convert_typical_year(epw, out / f"{epw.stem}.csv", year=YEAR)
        building = convert_idf(idf)
        ours = simulate_building(building, read_weather(out / f"{epw.stem}.csv"))
        try:
            theirs = energyplus(idf, out / name, epw)
        except RuntimeError:
            failed.append({"model": name, "message": severe_error(out / name)})
            print(f"{name}: EnergyPlus stopped: {failed[-1]['message']}", flush=True)
        else:
            # EnergyPlus's hour ending at k+1 h is the mean over the hour nodeforce samples at k+0.5 h
            new, unpaired = compare(name, building, idfkit.load_idf(str(idf)), ours, theirs, "30min", "hourly")
            rows += new
            for face, why in unpaired.items():
                print(f"{name}: EnergyPlus's face {face} not compared: {why}", flush=True)
            for row in new:
                if row["face"] == "air":
                    print(f"{name} {row['zone']}: RMSE {row['rmse']:.2f} K, mean difference "
                          f"{row['mean_difference']:+.2f} K", flush=True)
        every = pd.DataFrame(rows, columns=list(rows[0]) if rows else ["face"])
        every[every.face == "air"].to_csv(out / "comparison.csv", index=False, float_format="%.3f")
        every[every.face != "air"].to_csv(out / "faces.csv", index=False, float_format="%.3f")
        pd.DataFrame(failed, columns=["model", "message"]).to_csv(out / "stopped.csv", index=False)
    report(out)


def report(out):
    """Print the Markdown table of the run in `out`: per building its zones' air (RMSE mean and
    largest, mean difference, each program's mean) and its faces (RMSE median and the worst), then
    the buildings EnergyPlus stopped on, and the medians over every zone and face."""
    table, faces = pd.read_csv(out / "comparison.csv"), pd.read_csv(out / "faces.csv")
    print("| model | zones | RMSE mean (K) | RMSE max (K) | mean difference (K) | nodeforce mean (C) | EnergyPlus mean (C) "
          "| faces | face RMSE median (K) | worst face (K) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, g in sorted(table.groupby("model", sort=False)):
        f = faces[faces.model == name]
        worst = f.loc[f.rmse.idxmax()]
        print(f"| {name} | {len(g)} | {g.rmse.mean():.2f} | {g.rmse.max():.2f} | {g.mean_difference.mean():+.2f} | "
              f"{g.nodeforce_mean.mean():.2f} | {g.energyplus_mean.mean():.2f} | {len(f)} | {f.rmse.median():.2f} | "
              f"{worst.rmse:.2f} ({worst.face}) |")
    for _, row in pd.read_csv(out / "stopped.csv").iterrows():
        print(f"| {row.model} | EnergyPlus stopped: {row.message} | | | | | | | | |")
    print(f"\nEvery zone: RMSE median {table.rmse.median():.2f} K, 90th percentile {table.rmse.quantile(0.9):.2f} K, "
          f"largest {table.rmse.max():.2f} K; mean difference median {table.mean_difference.median():+.2f} K "
          f"({len(table)} zones of {table.model.nunique()} buildings)")
    print(f"Every inside face: RMSE median {faces.rmse.median():.2f} K, 90th percentile {faces.rmse.quantile(0.9):.2f} K, "
          f"largest {faces.rmse.max():.2f} K; mean difference median {faces.mean_difference.median():+.2f} K "
          f"({len(faces)} faces)")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default=ROOT / "out" / "bench_energyplus_reference", type=Path)
    parser.add_argument("--models", default=None, help="names of shipped IDFs (default: all)")
    args = parser.parse_args()
    main(args.out, args.models.split(",") if args.models else [p.stem for p in shipped_idfs()])
