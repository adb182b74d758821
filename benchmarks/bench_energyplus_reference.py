"""The converted reference buildings beside EnergyPlus, free-floating: each DOE reference / ASHRAE
90.1 prototype IDF named (pyenergyplus-lbnl's, the `energyplus` extra) converted by `nodeforce
convert` and simulated over its own city's TMY3 year, and run by EnergyPlus 25.2 on the same EPW
with only the objects the converter reads (`iotools.energyplus.READ`, its holidays): no HVAC, no
thermostat, no daylight saving. Per zone the hourly air's RMSE and mean
difference (nodeforce - EnergyPlus) and each program's mean; docs/energyplus.md carries the table.
A building EnergyPlus does not run to its end is a row saying so, with EnergyPlus's own first
severe error, and the others go on.

    python benchmarks/bench_energyplus_reference.py [OUT] [--models NAME,...]   (default: every shipped IDF)
"""
import argparse
import sys
from pathlib import Path

import idfkit
import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from bench_energyplus import nodeforce, read_zone_air, zone_air  # noqa: E402
from convert_corpus import shipped_idfs  # noqa: E402

from nodeforce.iotools.energyplus import READ  # noqa: E402
from nodeforce.iotools.typical_year import convert_typical_year  # noqa: E402
from nodeforce.iotools.weather import read_weather  # noqa: E402

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
    mean air hourly."""
    doc = idfkit.load_idf(str(idf))
    for obj in list(doc.all_objects):
        if obj.obj_type.upper() not in KEEP or obj.obj_type == "Version":
            if obj.obj_type != "Version":
                doc.removeidfobject(obj)
        elif obj.to_dict().get("frame_and_divider_name"):
            obj.frame_and_divider_name = ""  # a window's frame, which the converter does not read
    doc.add("RunPeriod", "year", {"begin_month": 1, "begin_day_of_month": 1, "begin_year": YEAR, "end_month": 12,
                                  "end_day_of_month": 31, "end_year": YEAR,
                                  "use_weather_file_holidays_and_special_days": "No",
                                  "use_weather_file_daylight_saving_period": "No", "apply_weekend_holiday_rule": "No",
                                  "use_weather_file_rain_indicators": "No", "use_weather_file_snow_indicators": "No"})
    doc.add("SimulationControl", "", {"do_zone_sizing_calculation": "No", "do_system_sizing_calculation": "No",
                                      "do_plant_sizing_calculation": "No", "run_simulation_for_sizing_periods": "No",
                                      "run_simulation_for_weather_file_run_periods": "Yes"})
    doc.add("Output:Variable", "", {"key_value": "*", "variable_name": "Zone Mean Air Temperature",
                                    "reporting_frequency": "Hourly"})
    idfkit.save_idf(doc, str(out))
    return out


def energyplus(idf, folder, epw):
    """{zone (upper case): hourly mean air (C), hour ending 01:00..24:00} of EnergyPlus's run; a run
    of the same free-floating IDF on the same EPW already in `folder` is read, not repeated
    (EnergyPlus's side does not change with nodeforce's code)."""
    folder.mkdir(parents=True, exist_ok=True)
    model = free_floating(idf, folder / "next.idf")
    ran = folder / "free_floating.idf"
    stamp = folder / "weather.txt"
    if (ran.exists() and ran.read_bytes() == model.read_bytes() and stamp.exists()
            and stamp.read_text() == str(epw) and (folder / "eplusout.csv").exists()):
        model.unlink()
        return read_zone_air(folder)
    model.replace(ran)
    stamp.unlink(missing_ok=True)
    result = zone_air(ran, folder, epw)
    stamp.write_text(str(epw))
    return result


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
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    idfs = {p.stem: p for p in shipped_idfs()}
    rows, failed = [], {}
    for number, name in enumerate(models, 1):
        print(f"[{number}/{len(models)}] {name}", file=sys.stderr, flush=True)
        idf = idfs[name]
        epw = weather_of(idf)
        if not (out / f"{epw.stem}.csv").exists():
            convert_typical_year(epw, out / f"{epw.stem}.csv", year=YEAR)
        ours = nodeforce(idf, read_weather(out / f"{epw.stem}.csv"))
        try:
            theirs = energyplus(idf, out / name, epw)
        except RuntimeError:
            failed[name] = severe_error(out / name)
            print(f"{name}: EnergyPlus stopped: {failed[name]}", flush=True)
            continue
        for zone, T in ours.items():
            # EnergyPlus's hour ending at k+1 h is the mean over the hour nodeforce samples at k+0.5 h
            E = theirs[zone][1:len(T) + 1]
            d = T - E
            rows.append({"model": name, "zone": zone, "rmse": np.sqrt(np.mean(d ** 2)), "mean_difference": d.mean(),
                         "nodeforce_mean": T.mean(), "energyplus_mean": E.mean()})
            print(f"{name} {zone}: RMSE {rows[-1]['rmse']:.2f} K, mean difference {d.mean():+.2f} K", flush=True)
    table = pd.DataFrame(rows)
    table.to_csv(out / "comparison.csv", index=False, float_format="%.3f")
    print("| model | zones | RMSE mean (K) | RMSE max (K) | mean difference (K) | nodeforce mean (C) | EnergyPlus mean (C) |")
    print("|---|---|---|---|---|---|---|")
    for name, g in table.groupby("model", sort=False):
        print(f"| {name} | {len(g)} | {g.rmse.mean():.2f} | {g.rmse.max():.2f} | {g.mean_difference.mean():+.2f} | "
              f"{g.nodeforce_mean.mean():.2f} | {g.energyplus_mean.mean():.2f} |")
    for name, message in failed.items():
        print(f"| {name} | EnergyPlus stopped: {message} | | | | | |")
    print(f"\nEvery zone: RMSE median {table.rmse.median():.2f} K, 90th percentile {table.rmse.quantile(0.9):.2f} K, "
          f"largest {table.rmse.max():.2f} K; mean difference median {table.mean_difference.median():+.2f} K "
          f"({len(table)} zones of {table.model.nunique()} buildings)")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default=ROOT / "out" / "bench_energyplus_reference", type=Path)
    parser.add_argument("--models", default=None, help="names of shipped IDFs (default: all)")
    args = parser.parse_args()
    main(args.out, args.models.split(",") if args.models else [p.stem for p in shipped_idfs()])
