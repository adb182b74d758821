"""EnergyPlus as a second reference (issue 44, item 5; issue 74, item 2): the same IDF run by
EnergyPlus 25.2.0 (the engine the pinned pyenergyplus-lbnl 26.1.0 ships, an optional dependency:
`pip install -e '.[energyplus]'`; it reports itself as 25.2.0 in eplusout.err) and by nodeforce
(`nodeforce convert`, the direct model), free-floating over a Denver year: the ASHRAE 140 cases
made from examples/bestest/case600.idf, 610FF (600FF with case 610's overhang: 1 m deep along
the roof over the south windows, ASHRAE 140-2020 section 5.2.2.1.2) and
examples/multizone/three_zones.idf, nodeforce started from the steady state of the first day's mean
conditions and two passes over that day, as EnergyPlus warms up on it. Every zone's air and every inside face (EnergyPlus's
"Surface Inside Face Temperature" beside the node of the same face, `energyplus_comparison`),
hourly and at 10-min steps, as RMSE and mean difference (nodeforce - EnergyPlus), with each
program's minimum, maximum and mean: OUT/comparison.csv, the Markdown table printed, and the
figure OUT/energyplus_faces.png (each zone's and face's RMSE; a week of the worst zone).
docs/performance.md carries the table and the figure.

    python benchmarks/bench_energyplus.py [OUT] [--weather EPW] [--only MODEL ...] [--figure PNG]
                                          [--sky-diffuse SKY]
                                                        (default out/bench_energyplus, every model)

--sky-diffuse replaces the site's `sky_diffuse` (docs/model.md section 4) in each converted
building, which `nodeforce convert` declares "energyplus" (docs/model.md section 10.1).

EnergyPlus also reports, at each step, each face's outside heat balance term by term (the
`OUTSIDE` variables of energyplus_comparison: its incident sun, beam, sky and ground diffuse apart,
its outside face's temperature, convective and long-wave coefficients, net long-wave and
conduction), in each model's OUT/<model>/eplusout.csv, to be set beside nodeforce's irradiance
inputs and outside nodes.

The weather is, unless --weather names another EPW, the Denver TMY3 year the installed
pyenergyplus package ships (pyenergyplus/data/weather/USA_CO_Denver-Aurora-Buckley.AFB.724695_TMY3.epw),
found at run time.

Both programs read the IDF with 6 time steps an hour (its `Timestep` replaced), nodeforce on the
EPW as EnergyPlus reads it, at its site, interpolated onto 10-min steps. Each program's hourly values are the means of the
hour's steps, as EnergyPlus's own hourly report averages them; its 10-min values, the state at
each step's end. The reference is EnergyPlus converged in time: it runs the IDF again at
`FINE_STEPS` an hour (`--fine-steps`; 0 takes its run at 6 an hour), its zones' air and inside
faces at each step, taken at the ends of the 10-min steps (`energyplus_comparison.at_steps`). Its answer at the
IDF's 6 steps an hour stands beside it, the air hourly: the error of EnergyPlus's own step (in
OUT/comparison.csv's step "EnergyPlus at 6/h beside itself at 60/h"), up to 0.5 K on the light
cases, which nodeforce is not asked to copy.

An IDF is brought to EnergyPlus 25.2 by copying every object by its field names into a 25.2
document (idfkit; the fields 25.2 renamed mapped, its new ones left to their defaults) and
replacing the run's own objects (run period, simulation control, outputs, shadow calculation,
costs) with a free-floating year, the sun's position and shading recomputed every day
(`SUN_UPDATE_DAYS`; EnergyPlus's default takes them for 20 days at once from their mean
declination), and the zones' mean air and faces' inside temperatures at each time step.
"""
import argparse
import sys
from pathlib import Path

import idfkit
import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples" / "bestest"))
sys.path.insert(0, str(ROOT / "benchmarks"))
import cases  # noqa: E402
from energyplus_comparison import (FACE, OUTSIDE, ZONE_AIR, at_steps, differences, face_nodes, hourly_means, paired,  # noqa: E402
                                   read_outputs)

from nodeforce.api import convert_idf  # noqa: E402
from nodeforce.iotools.weather import read_weather  # noqa: E402
from nodeforce.model.case import simulate_building  # noqa: E402
from nodeforce.model.solar import SKY_MODELS  # noqa: E402
from nodeforce.model.weather import weather_on_grid  # noqa: E402

PACKAGE_WEATHER = Path("data") / "weather" / "USA_CO_Denver-Aurora-Buckley.AFB.724695_TMY3.epw"
YEAR = 2017
STEPS = 6  # time steps an hour, both programs: EnergyPlus reports each 10-min step
# EnergyPlus's steps an hour where its answer is taken as converged in time: beside it, its answer
# at STEPS and nodeforce's
FINE_STEPS = 60
SUN_UPDATE_DAYS = 1  # EnergyPlus's sun position and shading recomputed every day
EVERY_STEP = {variable: "Timestep" for variable in (ZONE_AIR, FACE, *OUTSIDE)}
# The run's own objects, replaced; HVAC and thermostats go too: both programs run free-floating
DROP = ("Version", "ShadowCalculation", "RunPeriod", "SimulationControl", "Sizing", "Output", "OutputControl",
        "LifeCycleCost", "ZoneHVAC", "ZoneControl", "ThermostatSetpoint", "NodeList", "OutdoorAir:Node")
RENAMED = {"zone_or_zonelist_name": "zone_or_zonelist_or_space_or_spacelist_name",
           "watts_per_zone_floor_area": "watts_per_floor_area",
           "power_per_zone_floor_area": "power_per_floor_area",
           "flow_per_zone_floor_area": "flow_rate_per_floor_area",
           "flow_rate_per_zone_floor_area": "flow_rate_per_floor_area",
           "people_per_zone_floor_area": "people_per_floor_area",
           "zone_floor_area_per_person": "floor_area_per_person"}


def free_year(doc, outputs):
    """Add to `doc` a free-floating year, run on the weather file alone, that reports each
    variable of `outputs` {variable: frequency ("Hourly", "Timestep")}: `EVERY_STEP`, the zones'
    mean air, the faces' inside temperatures and their outside terms at each step."""
    doc.add("RunPeriod", "year", {"begin_month": 1, "begin_day_of_month": 1, "begin_year": YEAR, "end_month": 12,
                                  "end_day_of_month": 31, "end_year": YEAR,
                                  "use_weather_file_holidays_and_special_days": "No",
                                  "use_weather_file_daylight_saving_period": "No", "apply_weekend_holiday_rule": "No",
                                  "use_weather_file_rain_indicators": "No", "use_weather_file_snow_indicators": "No"})
    doc.add("SimulationControl", "", {"do_zone_sizing_calculation": "No", "do_system_sizing_calculation": "No",
                                      "do_plant_sizing_calculation": "No", "run_simulation_for_sizing_periods": "No",
                                      "run_simulation_for_weather_file_run_periods": "Yes"})
    # the sun's position each day: by default EnergyPlus takes it for 20 days at once, from their
    # mean declination, up to 3.7 deg off the day's in spring, which alone moved the south
    # windows' sun by up to 16 W/m2 a day and the zone air's daily mean by up to 1.4 C
    doc.add("ShadowCalculation", "", {"shading_calculation_update_frequency_method": "Periodic",
                                      "shading_calculation_update_frequency": SUN_UPDATE_DAYS})
    for variable, frequency in outputs.items():
        doc.add("Output:Variable", "", {"key_value": "*", "variable_name": variable, "reporting_frequency": frequency})
    return doc


def to_energyplus_25(doc, outputs=EVERY_STEP):
    """A 25.2 document of the building of `doc`, free-floating, reporting `outputs` (`free_year`):
    by default the zones' mean air and the faces' inside temperatures at each time step."""
    new = idfkit.new_document(version=(25, 2, 0))
    for obj in list(new.all_objects):  # the defaults of a new document give way to the model's own
        if obj.obj_type != "Version":
            new.removeidfobject(obj)
    for obj in doc.all_objects:
        if obj.obj_type.startswith(DROP):
            continue
        fields = {k: v for k, v in obj.to_dict().items() if k != "name" and v not in (None, "")}
        if obj.obj_type == "Schedule:Year" and "schedule_week_name_1" in fields:
            k, weeks = 1, []
            while f"schedule_week_name_{k}" in fields:
                weeks.append({f: fields.pop(f"{f}_{k}") for f in ("schedule_week_name", "start_month", "start_day",
                                                                  "end_month", "end_day")})
                k += 1
            fields["schedule_weeks"] = weeks
        name = obj.name if "name" in obj.to_dict() else ""
        try:  # a field 25.2 renamed, where it did
            new.add(obj.obj_type, name, {RENAMED.get(k, k): v for k, v in fields.items()})
        except idfkit.exceptions.ValidationFailedError:
            new.add(obj.obj_type, name, fields)
    return free_year(new, outputs)


def with_steps(doc, steps=STEPS):
    """`doc` with `steps` time steps an hour in place of its own Timestep."""
    for obj in [o for o in doc.all_objects if o.obj_type == "Timestep"]:
        doc.removeidfobject(obj)
    doc.add("Timestep", "", {"number_of_timesteps_per_hour": steps})
    return doc


def package_weather():
    """The Denver TMY3 EPW inside the installed pyenergyplus package."""
    import pyenergyplus
    return Path(pyenergyplus.__file__).parent / PACKAGE_WEATHER


def run_energyplus(idf, folder, epw):
    """Run EnergyPlus on the IDF at `idf` and the weather `epw`, its outputs in `folder`;
    RuntimeError where it does not run to its end."""
    from pyenergyplus.api import EnergyPlusAPI
    api = EnergyPlusAPI()
    state = api.state_manager.new_state()
    code = api.runtime.run_energyplus(state, ["-w", str(epw), "-d", str(folder), "-r", str(idf)])
    api.state_manager.delete_state(state)
    if code != 0:
        raise RuntimeError(f"EnergyPlus failed: {folder / 'eplusout.err'}")


def case_610ff():
    """600FF with case 610's overhang: 1 m deep across the south wall's 8 m at the roof's 2.7 m."""
    doc = cases.case_600ff()
    doc.add("Shading:Building:Detailed", "CASE 610 OVERHANG", {"number_of_vertices": 4, "vertices": [
        {"vertex_x_coordinate": x, "vertex_y_coordinate": y, "vertex_z_coordinate": 2.7}
        for x, y in ((0, -1), (0, 0), (8, 0), (8, -1))]})
    return doc


def models():
    """{name: a function making the model's idfkit document}: the free-float cases, 610FF, three_zones."""
    out = dict(cases.CASES)
    out["610FF"] = case_610ff
    out["three_zones"] = lambda: idfkit.load_idf(str(ROOT / "examples" / "multizone" / "three_zones.idf"))
    return out


def ten_minutes(weather):
    """The weather linearly interpolated onto 10-min steps over its span, its site kept."""
    return weather_on_grid(weather, pd.date_range(weather.index[0], weather.index[-1], freq="10min"))


def compare(model, building, doc, ours, theirs, lag, step):
    """Rows of the comparison of nodeforce's nodes `ours` with EnergyPlus's (zone air, faces)
    `theirs`, paired at EnergyPlus's interval ends less `lag`; the faces nodeforce has no node
    for, listed."""
    air, faces = theirs
    nodes, unpaired = face_nodes(building, faces.columns, doc)
    series = [(z.name.upper(), "air", z.air_node, air[z.name.upper()]) for z in building.zones]
    # the zone a node faces: its component's inside zone, or for a partition's outer node the other
    faced = {c.node_ids[0]: c.inside.zone.upper() for c in building.components}
    faced.update({c.node_ids[-1]: c.outside.zone.upper() for c in building.components
                  if getattr(c.outside, "zone", None)})
    series += [(faced[node], face, node, faces[face]) for face, node in nodes.items()]
    ours_t, theirs_t = paired(ours[[f"T{n}" for _, _, n, _ in series]],
                              pd.concat([s for *_, s in series], axis=1, keys=range(len(series))), lag)
    rows = [row(model, zone, face, step, ours_t[f"T{node}"], theirs_t[k])
            for k, (zone, face, node, _) in enumerate(series)]
    return rows, unpaired


def row(model, zone, face, step, ours, theirs):
    """A row of the table: RMSE, mean difference (ours - theirs, K) and each series' range and mean."""
    T, E = np.asarray(ours, float), np.asarray(theirs, float)
    rmse, mean = differences(T, E)
    return {"model": model, "zone": zone, "face": face, "step": step, "rmse": rmse, "mean_difference": mean,
            "nodeforce_min": T.min(), "nodeforce_max": T.max(), "nodeforce_mean": T.mean(),
            "energyplus_min": E.min(), "energyplus_max": E.max(), "energyplus_mean": E.mean()}


def step_error_rows(model, building, theirs, converged, steps):
    """Rows of each zone's hourly air: EnergyPlus's at STEPS (`theirs`) beside its own at `steps`
    an hour (`converged`, in the nodeforce columns): how far EnergyPlus's answer at the IDF's
    steps is from the reference."""
    common = theirs.index.intersection(converged.index)
    return [row(model, z.name.upper(), "air", f"EnergyPlus at {STEPS}/h beside itself at {steps}/h",
                theirs.loc[common, z.name.upper()], converged.loc[common, z.name.upper()])
            for z in building.zones]


def markdown(table):
    """The Markdown table of every zone's air and face: RMSE / mean difference hourly and at 10 min."""
    wide = table.pivot_table(index=["model", "zone", "face"], columns="step", values=["rmse", "mean_difference"],
                             sort=False)
    lines = ["| model | zone | face | RMSE hourly (K) | mean difference hourly (K) | RMSE 10 min (K) | "
             "mean difference 10 min (K) |", "|---|---|---|---|---|---|---|"]
    for (model, zone, face), r in wide.iterrows():
        lines.append(f"| {model} | {zone} | {face} | {r['rmse', 'hourly']:.2f} | {r['mean_difference', 'hourly']:+.2f} "
                     f"| {r['rmse', '10 min']:.2f} | {r['mean_difference', '10 min']:+.2f} |")
    return "\n".join(lines)


def zone_markdown(table):
    """The Markdown table of each zone: its air's RMSE / mean difference hourly and at 10 min, its
    faces' median RMSE hourly and at 10 min, and its worst face hourly; where EnergyPlus also ran
    with small steps, its own air's hourly RMSE at STEPS beside that run (`step_error_rows`)."""
    own = [s for s in table.step.unique() if s not in ("hourly", "10 min")]
    lines = ["| model | zone | air RMSE hourly / 10 min (K) | air mean difference hourly / 10 min (K) | faces | "
             "face RMSE median hourly / 10 min (K) | worst face hourly (K) |"
             + "".join(f" air RMSE {s} (K) |" for s in own),
             "|---|---|---|---|---|---|---|" + "---|" * len(own)]
    for (model, zone), g in table.groupby(["model", "zone"], sort=False):
        air = g[g.face == "air"].set_index("step")
        faces = g[g.face != "air"]
        hourly = faces[faces.step == "hourly"]
        worst = hourly.loc[hourly.rmse.idxmax()]
        median = faces.groupby("step").rmse.median()
        lines.append(f"| {model} | {zone} | {air.rmse['hourly']:.2f} / {air.rmse['10 min']:.2f} | "
                     f"{air.mean_difference['hourly']:+.2f} / {air.mean_difference['10 min']:+.2f} | {len(hourly)} | "
                     f"{median['hourly']:.2f} / {median['10 min']:.2f} | {worst.rmse:.2f} ({worst.face}) |"
                     + "".join(f" {air.rmse[s]:.2f} |" for s in own))
    return "\n".join(lines)


def summary(table):
    """One line a step and kind: the median and largest RMSE of the zones' air and of the faces."""
    lines = []
    for step, g in table.groupby("step", sort=False):
        air, faces = g[g.face == "air"], g[g.face != "air"]
        line = f"{step}: zone air RMSE median {air.rmse.median():.2f} K, largest {air.rmse.max():.2f} K ({len(air)} zones)"
        if len(faces):
            worst = faces.loc[faces.rmse.idxmax()]
            line += (f"; inside faces median {faces.rmse.median():.2f} K, largest {worst.rmse:.2f} K "
                     f"({worst.model} {worst.face}; {len(faces)} faces)")
        lines.append(line)
    return "\n".join(lines)


def figure(table, weeks, path):
    """Each zone's and face's RMSE as bars (hourly, 10 min), and a week of the worst zone's air at
    10-min steps in both programs."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    wide = table.pivot_table(index=["model", "zone", "face"], columns="step", values="rmse", sort=False)
    fig, (bars, week) = plt.subplots(2, 1, figsize=(13, 9), gridspec_kw={"height_ratios": [3, 2]})
    x = np.arange(len(wide))
    bars.bar(x - 0.2, wide["hourly"], 0.4, label="hourly")
    bars.bar(x + 0.2, wide["10 min"], 0.4, label="10 min")
    bars.set_xticks(x, [f"{m} {(z + ' air' if f == 'air' else f).lower()}" for m, z, f in wide.index], rotation=90,
                    fontsize=5)
    bars.set_ylabel("RMSE nodeforce - EnergyPlus (K)")
    bars.legend()
    air = table[(table.face == "air") & (table.step == "10 min")]
    worst = air.loc[air.rmse.idxmax()]
    (ours, theirs) = weeks[(worst.model, worst.zone)]
    week.plot(ours.index, ours.to_numpy(), label="nodeforce", lw=1)
    week.plot(theirs.index, theirs.to_numpy(), label="EnergyPlus", lw=1)
    week.set_ylabel("zone air (C)")
    week.set_title(f"{worst.model} {worst.zone.lower()}, the zone of the largest 10-min RMSE: the week of its "
                   "largest difference", fontsize=9)
    week.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def worst_week(ours, theirs):
    """The 7 days of two aligned series around their largest absolute difference."""
    at = (ours - theirs).abs().idxmax()
    start = max(ours.index[0], at - pd.Timedelta(days=3.5))
    span = slice(start, start + pd.Timedelta(days=7))
    return ours.loc[span], theirs.loc[span]


def declared(building, sky_diffuse):
    """The converted `building`, its site's `sky_diffuse` declared where one is given."""
    if sky_diffuse is None:
        return building
    return building.edited(lambda data: data["site"].__setitem__("sky_diffuse", sky_diffuse))


def main(out, epw, only=None, figure_path=None, sky_diffuse=None, fine_steps=FINE_STEPS):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    # the EPW read as EnergyPlus reads it, its site the run's as EnergyPlus's is (the IDF's differs)
    fine = ten_minutes(read_weather(epw, year=YEAR))
    rows, weeks = [], {}
    for name, make in models().items():
        if only and name not in only:
            continue
        doc = with_steps(make())
        idfkit.save_idf(doc, str(out / f"{name}.idf"))
        building = declared(convert_idf(out / f"{name}.idf"), sky_diffuse)
        folder = out / name
        folder.mkdir(parents=True, exist_ok=True)
        idfkit.save_idf(to_energyplus_25(doc), str(folder / "model_25_2.idf"))
        run_energyplus(folder / "model_25_2.idf", folder, epw)
        air, faces = read_outputs(folder, YEAR)
        step_error = []
        if fine_steps:
            # EnergyPlus converged in time is the reference: at the IDF's steps its own answer is
            # off it by its step's error, which is not the building's physics
            small = folder / f"steps_{fine_steps}"
            small.mkdir(exist_ok=True)
            idfkit.save_idf(to_energyplus_25(with_steps(make(), fine_steps), {ZONE_AIR: "Timestep", FACE: "Timestep"}),
                            str(small / "model_25_2.idf"))
            run_energyplus(small / "model_25_2.idf", small, epw)
            coarse_air, (air, faces) = air, (at_steps(t, STEPS) for t in read_outputs(small, YEAR))
            step_error = step_error_rows(name, building, hourly_means(coarse_air), hourly_means(air), fine_steps)
        # EnergyPlus warms up by repeating the first day until its zones converge; the steady
        # start at that day's mean conditions, then the warm-up passes, is nodeforce's counterpart
        ours = simulate_building(building, fine, steady_start=True)
        # each program's hourly means of the states at the 10-min steps' ends, and those states
        new, unpaired = compare(name, building, doc, hourly_means(ours), (hourly_means(air), hourly_means(faces)),
                                "0min", "hourly")
        fine_rows, _ = compare(name, building, doc, ours, (air, faces), "0min", "10 min")
        fine_rows += step_error
        for face, why in unpaired.items():
            print(f"{name}: EnergyPlus's face {face} not compared: {why}")
        for z in building.zones:
            weeks[(name, z.name.upper())] = worst_week(*paired(ours[f"T{z.air_node}"], air[z.name.upper()], "0min"))
        for r in new + fine_rows:
            if r["face"] == "air":
                print(f"{name:12} {r['zone']:12} {r['step']:7} RMSE {r['rmse']:.2f} K, mean difference "
                      f"{r['mean_difference']:+.2f} K; nodeforce {r['nodeforce_min']:.2f} / "
                      f"{r['nodeforce_max']:.2f} / {r['nodeforce_mean']:.2f}, EnergyPlus "
                      f"{r['energyplus_min']:.2f} / {r['energyplus_max']:.2f} / {r['energyplus_mean']:.2f} C",
                      flush=True)
        rows += new + fine_rows
    table = pd.DataFrame(rows)
    table.to_csv(out / "comparison.csv", index=False, float_format="%.3f")
    figure(table, weeks, figure_path or out / "energyplus_faces.png")
    print(zone_markdown(table), markdown(table), summary(table), sep="\n\n")
    print(f"wrote {out / 'comparison.csv'} and {figure_path or out / 'energyplus_faces.png'}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default=ROOT / "out" / "bench_energyplus", type=Path)
    parser.add_argument("--weather", type=Path, help="an EPW (default: pyenergyplus's Denver TMY3)")
    parser.add_argument("--only", nargs="+", choices=list(models()), help="run these models alone")
    parser.add_argument("--figure", type=Path, help="where the figure goes (default: OUT/energyplus_faces.png)")
    parser.add_argument("--sky-diffuse", choices=SKY_MODELS, help="replace the site's sky_diffuse in each building")
    parser.add_argument("--fine-steps", type=int, default=FINE_STEPS,
                        help=f"EnergyPlus again at this many steps an hour, beside its answer at {STEPS} and "
                             f"nodeforce's (0: not run; default {FINE_STEPS})")
    args = parser.parse_args()
    try:
        epw = args.weather or package_weather()
    except ImportError:
        sys.exit(print("bench_energyplus needs EnergyPlus: pip install -e '.[energyplus]'", file=sys.stderr) or 2)
    if not epw.is_file():
        sys.exit(print(f"{epw}: no such weather file", file=sys.stderr) or 2)
    if args.fine_steps % STEPS:
        sys.exit(print(f"--fine-steps {args.fine_steps}: must be a multiple of {STEPS}, whose steps' ends it "
                       "reports", file=sys.stderr) or 2)
    main(args.out, epw, args.only, args.figure, args.sky_diffuse, args.fine_steps)
