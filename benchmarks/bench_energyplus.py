"""EnergyPlus as a second reference (issue 44, item 5): the same IDF run by EnergyPlus 25.2
(pyenergyplus-lbnl, an optional dependency: `pip install -e '.[energyplus]'`) and by nodeforce
(`nodeforce convert`, the direct model), free-floating over a Denver year: the ASHRAE 140 cases
made from examples/bestest/case600.idf, 610FF (600FF with case 610's overhang: 1 m deep along
the roof over the south windows, ASHRAE 140-2020 section 5.2.2.1.2) and
examples/multizone/three_zones.idf; per zone the hourly
air's RMSE and mean difference (nodeforce - EnergyPlus) and each program's minimum, maximum and
mean. docs/performance.md carries the table.

    python benchmarks/bench_energyplus.py [OUT] [--weather EPW] [--only MODEL ...]
                                                        (default out/bench_energyplus, every model)

The weather is, unless --weather names another EPW, the Denver TMY3 year the installed
pyenergyplus package ships (pyenergyplus/data/weather/USA_CO_Denver-Aurora-Buckley.AFB.724695_TMY3.epw),
found at run time.

An IDF is brought to 25.2 by copying every object by its field names into a 25.2 document
(idfkit; the fields 25.2 renamed mapped, its new ones left to their defaults) and replacing the
run's own objects (run period, simulation control, outputs, shadow calculation, costs) with a
free-floating year and the zones' mean air temperature, hourly.
"""
import argparse
import sys
from pathlib import Path

import idfkit
import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples" / "bestest"))
import cases  # noqa: E402

from nodeforce.api import convert_idf  # noqa: E402
from nodeforce.iotools.typical_year import convert_typical_year  # noqa: E402
from nodeforce.iotools.weather import read_weather  # noqa: E402
from nodeforce.model.case import simulate_building  # noqa: E402

PACKAGE_WEATHER = Path("data") / "weather" / "USA_CO_Denver-Aurora-Buckley.AFB.724695_TMY3.epw"
YEAR = 2017
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


def to_energyplus_25(doc):
    """A 25.2 document of the building of `doc`, free-floating, reporting the zones' mean air."""
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
    new.add("RunPeriod", "year", {"begin_month": 1, "begin_day_of_month": 1, "begin_year": YEAR, "end_month": 12,
                                  "end_day_of_month": 31, "end_year": YEAR,
                                  "use_weather_file_holidays_and_special_days": "No",
                                  "use_weather_file_daylight_saving_period": "No", "apply_weekend_holiday_rule": "No",
                                  "use_weather_file_rain_indicators": "No", "use_weather_file_snow_indicators": "No"})
    new.add("SimulationControl", "", {"do_zone_sizing_calculation": "No", "do_system_sizing_calculation": "No",
                                      "do_plant_sizing_calculation": "No", "run_simulation_for_sizing_periods": "No",
                                      "run_simulation_for_weather_file_run_periods": "Yes"})
    new.add("Output:Variable", "", {"key_value": "*", "variable_name": "Zone Mean Air Temperature",
                                    "reporting_frequency": "Hourly"})
    return new


def package_weather():
    """The Denver TMY3 EPW inside the installed pyenergyplus package."""
    import pyenergyplus
    return Path(pyenergyplus.__file__).parent / PACKAGE_WEATHER


def energyplus(doc, folder, epw):
    """{zone (upper case): hourly mean air (C), hour ending 01:00..24:00} of EnergyPlus 25.2's run."""
    folder.mkdir(parents=True, exist_ok=True)
    idf = folder / "model_25_2.idf"
    idfkit.save_idf(to_energyplus_25(doc), str(idf))
    return zone_air(idf, folder, epw)


def zone_air(idf, folder, epw):
    """{zone (upper case): hourly mean air (C), hour ending 01:00..24:00} of EnergyPlus run on the
    IDF at `idf` (its outputs in `folder`)."""
    from pyenergyplus.api import EnergyPlusAPI
    api = EnergyPlusAPI()
    state = api.state_manager.new_state()
    if api.runtime.run_energyplus(state, ["-w", str(epw), "-d", str(folder), "-r", str(idf)]) != 0:
        raise RuntimeError(f"EnergyPlus failed: {folder / 'eplusout.err'}")
    api.state_manager.delete_state(state)
    return read_zone_air(folder)


def read_zone_air(folder):
    """{zone (upper case): hourly mean air (C)} of the EnergyPlus run whose outputs are in `folder`."""
    table = pd.read_csv(folder / "eplusout.csv")
    return {c.split(":")[0].strip().upper(): table[c].to_numpy(float) for c in table.columns
            if "Zone Mean Air Temperature" in c}


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


def nodeforce(path, weather):
    """{zone (upper case): air (C) at 01:30..23:30 of the year} of the converted building."""
    building = convert_idf(path)
    T = simulate_building(building, weather)
    return {z.name.upper(): T[f"T{z.air_node}"].to_numpy(float) for z in building.zones}


def main(out, epw, only=None):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    convert_typical_year(epw, out / "weather.csv", year=YEAR)
    weather = read_weather(out / "weather.csv")
    rows = []
    for name, make in models().items():
        if only and name not in only:
            continue
        doc = make()
        idfkit.save_idf(doc, str(out / f"{name}.idf"))
        ours = nodeforce(out / f"{name}.idf", weather)
        theirs = energyplus(doc, out / name, epw)
        for zone, T in ours.items():
            # EnergyPlus's hour ending at k+1 h is the mean over the hour nodeforce samples at k+0.5 h
            E = theirs[zone][1:len(T) + 1]
            d = T - E
            rows.append({"model": name, "zone": zone, "rmse": np.sqrt(np.mean(d ** 2)), "mean_difference": d.mean(),
                         "nodeforce_min": T.min(), "nodeforce_max": T.max(), "nodeforce_mean": T.mean(),
                         "energyplus_min": E.min(), "energyplus_max": E.max(), "energyplus_mean": E.mean()})
            print(f"{name:12} {zone:12} RMSE {rows[-1]['rmse']:.2f} K, mean difference {d.mean():+.2f} K; "
                  f"nodeforce {T.min():.2f} / {T.max():.2f} / {T.mean():.2f}, "
                  f"EnergyPlus {E.min():.2f} / {E.max():.2f} / {E.mean():.2f} C")
    pd.DataFrame(rows).to_csv(out / "comparison.csv", index=False, float_format="%.3f")
    print(f"wrote {out / 'comparison.csv'}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", nargs="?", default=ROOT / "out" / "bench_energyplus", type=Path)
    parser.add_argument("--weather", type=Path, help="an EPW (default: pyenergyplus's Denver TMY3)")
    parser.add_argument("--only", nargs="+", choices=list(models()), help="run these models alone")
    args = parser.parse_args()
    try:
        epw = args.weather or package_weather()
    except ImportError:
        sys.exit(print("bench_energyplus needs EnergyPlus: pip install -e '.[energyplus]'", file=sys.stderr) or 2)
    if not epw.is_file():
        sys.exit(print(f"{epw}: no such weather file", file=sys.stderr) or 2)
    main(args.out, epw, args.only)
