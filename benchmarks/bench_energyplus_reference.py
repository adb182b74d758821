"""The converted reference buildings beside EnergyPlus, free-floating: each DOE reference / ASHRAE
90.1 prototype IDF named (pyenergyplus-lbnl's, the `energyplus` extra) converted by `nodeforce
convert` and simulated over its own city's TMY3 year, and run by EnergyPlus 25.2.0 (the engine
pyenergyplus-lbnl 26.1.0 ships) on the same EPW with only the objects the converter reads
(`iotools.energyplus.READ`, its holidays): no HVAC, no thermostat, no daylight saving. Both
programs take 6 steps an hour (the IDF's `Timestep` replaced), nodeforce on the EPW as
EnergyPlus reads it, at the EPW's site, interpolated onto them, started from the steady state of
the first day's mean conditions and two passes over that day, as EnergyPlus warms up on it
(repeating it until its zones converge). EnergyPlus's answer at 6 steps
carries its own step's error (`bench_energyplus` runs the ASHRAE 140 cases again at 60: up to 0.5
K on the light cases); a year of every building at 60 steps is out of this benchmark's reach. Per zone the air's RMSE
and mean difference (nodeforce - EnergyPlus) hourly (each program's mean of its hour's steps)
and at 10 min (each step's end), and each program's mean; per inside face (EnergyPlus's
"Surface Inside Face Temperature" beside the node of the same face, `energyplus_comparison`) the
hourly RMSE and mean difference, from the same EnergyPlus run (the faces are not reported at
each step: the largest buildings have some 1,400). OUT/comparison.csv holds the zones, both
steps, OUT/faces.csv the faces; the figure (--figure, default OUT/energyplus_reference.png)
each building's zones' and faces' hourly RMSE; docs/energyplus.md carries the table. A building
EnergyPlus does not run to its end is a row saying so, with EnergyPlus's own first severe
error, and the others go on.

    python benchmarks/bench_energyplus_reference.py [OUT] [--models NAME,...] [--workers N] [--figure PNG]
                                                     [--finite-differences CONSTRUCTION,...]
                                                     (default: every shipped IDF, one at a time)
"""
import argparse
import sys
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import idfkit
import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from bench_energyplus import compare, free_year, run_energyplus, ten_minutes, with_steps  # noqa: E402
from energyplus_comparison import FACE, ZONE_AIR, hourly_means, read_outputs  # noqa: E402
from convert_corpus import shipped_idfs  # noqa: E402

from nodeforce.api import convert_idf  # noqa: E402
from nodeforce.iotools.energyplus import READ  # noqa: E402
from nodeforce.iotools.weather import read_weather  # noqa: E402
from nodeforce.model.case import simulate_building  # noqa: E402

YEAR = 2017
# the zones' air at each step, the faces' hourly
OUTPUTS = {ZONE_AIR: "Timestep", FACE: "Hourly"}
KEEP = {k.upper() for k in READ} | {"RUNPERIODCONTROL:SPECIALDAYS", "TIMESTEP", "SITE:GROUNDTEMPERATURE:BUILDINGSURFACE"}


def weather_of(idf):
    """The package's TMY3 EPW of the model's city (Chicago for the 2004 buildings, Denver for 2019's)."""
    folder = idf.parent.parent / "weather"
    city = "Chicago-OHare" if "Chicago" in idf.stem else "Denver-Aurora"
    (epw,) = folder.glob(f"*{city}*.epw")
    return epw


def free_floating(idf, out, finite=()):
    """The IDF with only the objects the converter reads, 6 steps an hour, a free-floating year
    reporting the zones' mean air at each step and the faces' inside temperatures hourly; the
    constructions named in `finite` conducted by finite differences (EnergyPlus's
    ConductionFiniteDifference, which conserves the heat its conduction transfer functions may
    not)."""
    doc = with_steps(idfkit.load_idf(str(idf)))
    for obj in list(doc.all_objects):
        if obj.obj_type.upper() not in KEEP or obj.obj_type == "Version":
            if obj.obj_type != "Version":
                doc.removeidfobject(obj)
        elif obj.to_dict().get("frame_and_divider_name"):
            obj.frame_and_divider_name = ""  # a window's frame, which the converter does not read
    free_year(doc, OUTPUTS)
    # each construction's conduction transfer functions, listed in eplusout.eio (docs/energyplus.md)
    doc.add("Output:Constructions", "", {"details_type_1": "Constructions"})
    for construction in finite:
        doc.add("SurfaceProperty:HeatTransferAlgorithm:Construction", f"finite differences {construction}",
                {"algorithm": "ConductionFiniteDifference", "construction_name": construction})
    idfkit.save_idf(doc, str(out))
    return out


def energyplus(idf, folder, epw, finite=()):
    """(zone air at each step, inside faces hourly) (C, `energyplus_comparison.read_outputs`) of
    EnergyPlus's run; a run
    of the same free-floating IDF on the same EPW already in `folder` is read, not repeated
    (EnergyPlus's side does not change with nodeforce's code)."""
    folder.mkdir(parents=True, exist_ok=True)
    model = free_floating(idf, folder / "next.idf", finite)
    ran = folder / "free_floating.idf"
    stamp = folder / "weather.txt"
    if (ran.exists() and ran.read_bytes() == model.read_bytes() and stamp.exists()
            and stamp.read_text() == str(epw) and (folder / "eplusout.csv").exists()):
        model.unlink()
        return stepped(folder)
    model.replace(ran)
    stamp.unlink(missing_ok=True)
    run_energyplus(ran, folder, epw)
    stamp.write_text(str(epw))
    return stepped(folder)


def stepped(folder):
    """(zone air, inside faces) of the run in `folder`, each on the rows of its own reporting
    interval (`OUTPUTS`: the faces' rows are the hours' ends)."""
    air, faces = read_outputs(folder, YEAR)
    return air, faces.dropna(how="all")


def severe_error(folder):
    """EnergyPlus's first severe (or fatal) message of the run in `folder`, on one line."""
    lines = (folder / "eplusout.err").read_text(errors="replace").splitlines()
    start = next((k for k, line in enumerate(lines) if "** Severe  **" in line or "**  Fatal  **" in line), None)
    if start is None:
        return "no severe error written"
    message = [lines[start].split("**", 2)[-1].strip()]
    message += [line.split("~~~", 1)[-1].strip() for line in lines[start + 1:start + 3] if "~~~" in line]
    return " ".join(message)


def beside(name, idf, out, finite=()):
    """(rows, stopped): the building `name` (its IDF at `idf`, its city's EPW read as EnergyPlus reads
    it, at the EPW's site as EnergyPlus's run is) beside EnergyPlus, its zones' and
    faces' rows (`bench_energyplus.compare`), or where EnergyPlus does not run it to its end, no
    rows and its first severe error."""
    epw = weather_of(idf)
    building = convert_idf(idf)
    # started as EnergyPlus starts, from the first day repeated until the zones converge
    # (`bench_energyplus`'s comment)
    ours = simulate_building(building, ten_minutes(read_weather(epw, year=YEAR)), steady_start=True)
    try:
        air, faces = energyplus(idf, out / name, epw, finite)
    except RuntimeError:
        return [], {"model": name, "message": severe_error(out / name)}
    doc = idfkit.load_idf(str(idf))
    # each program's hourly means of its own steps, and the state at each step's end
    rows, unpaired = compare(name, building, doc, hourly_means(ours), (hourly_means(air), faces), "0min", "hourly")
    fine, _ = compare(name, building, doc, ours, (air, faces.iloc[:, :0]), "0min", "10 min")
    for face, why in unpaired.items():
        print(f"{name}: EnergyPlus's face {face} not compared: {why}", flush=True)
    return rows + fine, None


def main(out, models, workers=1, finite=()):
    """Every building named in `models` beside EnergyPlus, `workers` at a time; OUT/comparison.csv
    (zones), faces.csv and stopped.csv (the buildings EnergyPlus does not run to their end)
    rewritten as each ends, so that a run cut short keeps what it did; then the table (`report`)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    idfs = {p.stem: p for p in shipped_idfs()}
    rows, failed = [], []
    with ProcessPoolExecutor(workers) as pool:
        jobs = {pool.submit(beside, name, idfs[name], out, finite): name for name in models}
        for number, job in enumerate(as_completed(jobs), 1):
            name = jobs[job]
            new, stopped = job.result()
            print(f"[{number}/{len(models)}] {name}", file=sys.stderr, flush=True)
            if stopped:
                failed.append(stopped)
                print(f"{name}: EnergyPlus stopped: {stopped['message']}", flush=True)
            for row in new:
                if row["face"] == "air":
                    print(f"{name} {row['zone']} {row['step']}: RMSE {row['rmse']:.2f} K, mean difference "
                          f"{row['mean_difference']:+.2f} K", flush=True)
            rows += new
            every = pd.DataFrame(rows, columns=list(rows[0]) if rows else ["face"])
            every[every.face == "air"].to_csv(out / "comparison.csv", index=False, float_format="%.3f")
            every[every.face != "air"].to_csv(out / "faces.csv", index=False, float_format="%.3f")
            pd.DataFrame(failed, columns=["model", "message"]).to_csv(out / "stopped.csv", index=False)
    report(out)


def report(out):
    """Print the Markdown table of the run in `out`: per building its zones' air (RMSE mean and
    largest hourly and at 10 min, mean difference, each program's mean) and its faces (hourly RMSE
    median and the worst), then the buildings EnergyPlus stopped on, and the medians over every
    zone and face."""
    zones, faces = pd.read_csv(out / "comparison.csv"), pd.read_csv(out / "faces.csv")
    hourly, fine = zones[zones.step == "hourly"], zones[zones.step == "10 min"]
    print("| model | zones | air RMSE mean hourly / 10 min (K) | air RMSE max hourly / 10 min (K) | mean difference (K) "
          "| nodeforce mean (C) | EnergyPlus mean (C) | faces | face RMSE median (K) | worst face (K) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, g in sorted(hourly.groupby("model", sort=False)):
        f, g10 = faces[faces.model == name], fine[fine.model == name]
        worst = f.loc[f.rmse.idxmax()]
        print(f"| {name} | {len(g)} | {g.rmse.mean():.2f} / {g10.rmse.mean():.2f} | {g.rmse.max():.2f} / "
              f"{g10.rmse.max():.2f} | {g.mean_difference.mean():+.2f} | {g.nodeforce_mean.mean():.2f} | "
              f"{g.energyplus_mean.mean():.2f} | {len(f)} | {f.rmse.median():.2f} | {worst.rmse:.2f} ({worst.face}) |")
    for _, row in pd.read_csv(out / "stopped.csv").iterrows():
        print(f"| {row.model} | EnergyPlus stopped: {row.message} | | | | | | | | |")
    print()
    for step, g in (("hourly", hourly), ("10 min", fine)):
        print(f"Every zone, {step}: RMSE median {g.rmse.median():.2f} K, 90th percentile {g.rmse.quantile(0.9):.2f} K, "
              f"largest {g.rmse.max():.2f} K; mean difference median {g.mean_difference.median():+.2f} K "
              f"({len(g)} zones of {g.model.nunique()} buildings)")
    print(f"Every inside face, hourly: RMSE median {faces.rmse.median():.2f} K, 90th percentile "
          f"{faces.rmse.quantile(0.9):.2f} K, largest {faces.rmse.max():.2f} K; mean difference median "
          f"{faces.mean_difference.median():+.2f} K ({len(faces)} faces)")


def figure(out, path):
    """Each building's zones' air and inside faces' hourly RMSE, as box plots on a log scale, the
    issue's targets (0.3 K for the median zone, 0.6 K for every zone) drawn across."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    zones, faces = pd.read_csv(out / "comparison.csv"), pd.read_csv(out / "faces.csv")
    zones = zones[zones.step == "hourly"]
    names = sorted(zones.model.unique())
    fig, ax = plt.subplots(figsize=(13, 6))
    x = np.arange(len(names))
    for shift, table, colour, label in ((-0.2, zones, "C0", "zone air"), (0.2, faces, "C1", "inside faces")):
        box = ax.boxplot([table[table.model == n].rmse for n in names], positions=x + shift, widths=0.35,
                         patch_artist=True, flierprops={"markersize": 2}, medianprops={"color": "k"})
        for patch in box["boxes"]:
            patch.set_facecolor(colour)
        ax.plot([], [], "s", color=colour, label=label)
    for level, style in ((0.3, ":"), (0.6, "--")):
        ax.axhline(level, color="k", ls=style, lw=0.8)
    ax.set_yscale("log")
    ax.set_xticks(x, [n.replace("ASHRAE901_", "").replace("RefBldg", "") for n in names], rotation=90, fontsize=7)
    ax.set_ylabel("hourly RMSE nodeforce - EnergyPlus (K)")
    ax.set_title("Reference buildings free-floating, a TMY3 year: each zone's air and inside face "
                 "(targets 0.3 K median zone, 0.6 K every zone)", fontsize=9)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default=ROOT / "out" / "bench_energyplus_reference", type=Path)
    parser.add_argument("--models", default=None, help="names of shipped IDFs (default: all)")
    parser.add_argument("--workers", type=int, default=1, help="buildings at a time (processes)")
    parser.add_argument("--figure", type=Path, help="the figure's path (default OUT/energyplus_reference.png)")
    parser.add_argument("--finite-differences", default="", metavar="CONSTRUCTION,...",
                        help="constructions EnergyPlus conducts by finite differences, not by its conduction "
                             "transfer functions")
    args = parser.parse_args()
    main(args.out, args.models.split(",") if args.models else [p.stem for p in shipped_idfs()], args.workers,
         [c for c in args.finite_differences.split(",") if c])
    figure(args.out, args.figure or args.out / "energyplus_reference.png")
