"""The truth of a benchmark record: the building file discretised finer and simulated at the
minute from a long past, with its fault, read by the record's sensors (benchmarks/records.py
says why each choice)."""
import dataclasses
import functools
from pathlib import Path

import numpy as np
import pandas as pd
import pvlib

from nodeforce.runtime import tempdirs
from nodeforce.iotools.typical_year import convert_typical_year, relocate
from nodeforce.iotools.weather import read_weather
from nodeforce.model.building_file import load_building, parse_building
from nodeforce.model.case import prepare_case
from nodeforce.model.effects import EFFECTS
from nodeforce.model.integrate import simulate
from nodeforce.model.network import assemble
from nodeforce.model.solar import incident_irradiance, solar_position

ROOT = Path(__file__).resolve().parents[1]
TESTCELL = ROOT / "model" / "data" / "testcell.json"
TWINHOUSE = ROOT / "examples" / "twinhouse_n2" / "building.json"
PVLIB_DATA = Path(pvlib.__file__).parent / "data"
CLIMATES = {"miami": "12839.tm2", "greensboro": "723170TYA.CSV", "sandpoint": "703165TY.csv"}
CELLS = 2  # cells of the truth per stretch between two of the file's nodes or layer boundaries
FINE_STEP = 60.0  # s, the truth's step
# Days of weather the truth is simulated over before the record: the building's past, longer than
# any diagnosis reads (`Spec.before`). Its own start (the steady state of that weather's first day)
# is then forgotten: the test cell's slowest mode, its floor's (14.7 days), keeps e^-6 of it.
TRUTH_HISTORY_DAYS = 90
PAPER_SENSORS = (1, 7, 9, 16, 17, 23)  # the test cell's (Lauret et al., Table 1)
HEATER = 300.0  # W, the air-only records' PRBS heater
PRBS_SWITCH = 0.15  # probability the heater switches at a record step


@functools.lru_cache(maxsize=None)
def climate(name):
    """(site {latitude, longitude, altitude, timezone}, hourly weather) of a typical year pvlib bundles."""
    with tempdirs.folder("bench-weather") as tmp:
        csv = Path(tmp) / f"{name}.csv"
        site = convert_typical_year(PVLIB_DATA / CLIMATES[name], csv)
        weather = read_weather(csv)
    weather.attrs["source"] = f"{CLIMATES[name]} (pvlib)"
    return site, weather


def file_building(spec):
    """The building file the diagnosis reads: the test cell or the Twin House at the climate's
    site, declaring its ground temperature (the typical year's mean air) unless the spec says
    not; the air-only test cell with its heater declared and measured."""
    site, _ = climate(spec.climate)
    path = TESTCELL if spec.building == "testcell" else TWINHOUSE
    building = load_building(path)
    data = relocate(building.to_json(), site)
    if not spec.declares_ground:
        del data["site"]["ground_temperature"]
    if spec.sensors == "air":
        data["zones"][0]["heat_input"] = "Q_heat"
    return parse_building(data, source=f"{path.name} at {spec.climate}")


# the declared values of the parameters of the faults beyond the registry: no gain, no opening,
# an envelope as declared
BEYOND_NEUTRAL = {"Q": 0.0, "area": 0.0, "factor": 1.0}


def neutral(building, fault):
    """The fault's parameters as the file declares them."""
    if fault.effect in EFFECTS:
        return EFFECTS[fault.effect].read(building, fault.target)
    return {name: BEYOND_NEUTRAL[name] for name in fault.full if name in BEYOND_NEUTRAL}


def at_scale(building, spec, scale):
    """[{parameter: value}] of each of the spec's faults at `scale` (0: as declared, 1: its `full`)."""
    out = []
    for fault in grounded(spec).faults:
        base = neutral(building, fault)
        values = dict(fault.full)
        for name, full in fault.full.items():
            if name in base and name not in ("T_ground", "on", "off"):
                values[name] = base[name] + scale * (full - base[name])
        out.append(values)
    return out


@functools.lru_cache(maxsize=None)
def record_mean_air(spec):
    """The mean outdoor air temperature (C) over the record's span, the typical year linearly
    interpolated to the minute as the truth reads it."""
    _, hourly = climate(spec.climate)
    times = record_times(spec)
    grid = pd.date_range(times[0], times[-1], freq=f"{FINE_STEP:g}s", name="time")
    return float(minutely(cyclic(hourly[["T_out"]], times[0] - pd.Timedelta(hours=1)), grid)["T_out"].mean())


def grounded(spec):
    """The spec with its ground faults' T_ground in C: where the fault leaves it None, the
    record's mean outdoor air plus the spec's `ground_offset` (K)."""
    if spec.ground_offset is None:
        return spec
    T_ground = record_mean_air(spec) + spec.ground_offset
    faults = tuple(dataclasses.replace(f, full={**f.full, "T_ground": T_ground})
                   if "T_ground" in f.full and f.full["T_ground"] is None else f for f in spec.faults)
    return dataclasses.replace(spec, faults=faults, ground_offset=None)


def faulty(truth, spec, values):
    """(truth building with the spec's faults at `values` (`at_scale`), extra weather columns it
    reads {name: callable(times)})."""
    extra = {}
    for fault, v in zip(spec.faults, values):
        truth, more = with_fault(truth, fault, v, spec.objective or truth.zones[0].name)
        extra.update(more)
    return truth, extra


def with_fault(truth, fault, values, zone):
    """(truth with one fault at `values`, extra weather columns it reads); a scheduled gain goes
    to `zone`."""
    if fault.effect in EFFECTS:
        return EFFECTS[fault.effect].apply(truth, fault.target, values), {}
    if fault.effect == "scheduled_gain":
        def schedule(times, tz=truth.site["timezone"]):
            local = times.tz_convert(tz)
            hour = local.hour + local.minute / 60
            return np.where((hour >= values["on"]) & (hour < values["off"]), values["Q"], 0.0)

        def add(data):
            z = next(z for z in data["zones"] if z["name"] == zone)
            inputs = z.get("heat_input") or []
            z["heat_input"] = [*([inputs] if isinstance(inputs, str) else inputs), "Q_schedule"]
        return truth.edited(add), {"Q_schedule": schedule}
    if fault.effect == "opening":
        return opened(truth, fault.target, values["area"]), {}
    if fault.effect == "envelope_films":
        return with_envelope_films(truth, fault.target, values["factor"]), {}
    raise ValueError(f"unknown effect {fault.effect!r}")


def opened(building, wall, area):
    """The building with `area` m2 of the wall `wall` replaced by a 4 mm glazing (transmittance
    0.8, its sun to the zone's floor, the wall's surface coefficients): an opening the file does
    not have."""
    def change(data):
        raw = next(c for c in data["components"] if c["name"] == wall)
        raw["area"] -= area
        floor = next(c["name"] for c in data["components"] if c["tilt"] == 180 and c["inside"]["zone"] == raw["inside"]["zone"])
        data["materials"]["bench_glass"] = {"conductivity": 1.0, "density": 2500.0, "specific_heat": 750.0}
        ids = [n["id"] for c in data["components"] for n in c["nodes"]]
        ids += [i for z in data["zones"] for i in (z["air_node"], z["radiant_node"])]
        top = max(ids)
        outside = {k: v for k, v in raw["outside"].items() if k != "irradiance"}
        outside["solar_absorptance"] = 0.1
        data["components"].append({
            "name": f"{wall}_opening", "area": area, "tilt": raw["tilt"], "azimuth": raw["azimuth"],
            "layers": [["bench_glass", 0.004]],
            "nodes": [{"id": top + 1, "depth": 0.0}, {"id": top + 2, "depth": 0.004}],
            "inside": dict(raw["inside"]), "outside": outside,
            "solar_transmittance": 0.8, "transmitted_solar_to": floor})
    return building.edited(change)


def with_envelope_films(building, zone, factor):
    """The building whose zone `zone` loses through its envelope `factor` times as much in every
    part of the path: each component between the zone and the outdoors or a boundary has its
    layers' materials `factor` times as conductive (its own copies of them, so that the partitions
    sharing a material keep theirs) and its outside coefficients (h_conv and h_rad of an exterior
    face, h of a boundary face) `factor` times the file's. Not the registry's
    `envelope_conductance`, which scales the materials alone."""
    def change(data):
        for raw in data["components"]:
            outside = raw["outside"]
            if raw["inside"]["zone"] != zone or outside["type"] not in ("exterior", "boundary"):
                continue
            for layer in raw["layers"]:
                own = f"{layer[0]}@{raw['name']}"
                data["materials"][own] = {**data["materials"][layer[0]]}
                data["materials"][own]["conductivity"] *= factor
                layer[0] = own
            for key in ("h_conv", "h_rad", "h"):
                if key in outside:
                    outside[key] *= factor
    return building.edited(change)


def record_times(spec):
    """The record's time grid (tz-aware, the climate's local standard time)."""
    site, weather = climate(spec.climate)
    start = pd.Timestamp(f"{weather.index[0].year}-{spec.start}T00:00").tz_localize(weather.index.tz)
    return pd.date_range(start, periods=spec.days * 1440 // spec.step_min + 1, freq=f"{spec.step_min}min", name="time")


def fine_weather(spec, building, times, extra, days=TRUTH_HISTORY_DAYS):
    """The weather at 1 min from `days` (default `TRUTH_HISTORY_DAYS`) before `times` to its end:
    the typical year (`cyclic` where that reaches before its start) linearly interpolated, the
    columns the file reads (heat inputs held over each record step), and the truth's `extra`
    columns."""
    site, hourly = climate(spec.climate)
    start = times[0] - pd.Timedelta(days=days)
    hourly = cyclic(hourly, start - pd.Timedelta(hours=1))
    grid = pd.date_range(start, times[-1], freq=f"{FINE_STEP:g}s", name="time")
    fine = minutely(hourly, grid)
    for name, values in own_columns(spec, building, grid, fine).items():
        fine[name] = values
    for name, function in extra.items():
        fine[name] = function(grid)
    fine.attrs["source"] = f"{spec.name} weather"
    return fine


def minutely(hourly, grid):
    """The hourly frame linearly interpolated in time onto the finer `grid`."""
    return hourly.reindex(hourly.index.union(grid)).interpolate("time").reindex(grid)


def cyclic(hourly, start):
    """The typical year from `start` on: where `start` falls before its first row, its last
    rows, a year earlier, come before it, as a simulation program reads a typical year."""
    if start >= hourly.index[0]:
        return hourly
    period = hourly.index[-1] - hourly.index[0] + (hourly.index[1] - hourly.index[0])
    earlier = hourly[hourly.index - period >= start]
    earlier.index = earlier.index - period
    return pd.concat([earlier, hourly])


def read_by_diagnosis(spec, building, weather, times):
    """The weather the diagnosis reads: the truth's `weather` from `spec.before` days before
    `times`; where that reaches beyond the truth's past (a year of weather, whose mean the
    diagnosis reads as the deep ground's), the same typical year made as far back."""
    if spec.before > TRUTH_HISTORY_DAYS:
        weather = fine_weather(spec, building, times, {}, days=spec.before)
    out = weather[weather.index >= times[0] - pd.Timedelta(days=spec.before)]
    out.attrs = dict(weather.attrs)
    return out


def held(values_at_steps, coarse, grid):
    """Values on the record step grid `coarse`, held over each step (the step's end value over
    (t_k, t_k+1]) and read on the finer `grid`."""
    k = np.ceil(((grid - coarse[0]).total_seconds().to_numpy()) / (coarse[1] - coarse[0]).total_seconds() - 1e-9)
    return np.asarray(values_at_steps)[np.clip(k.astype(int), 0, len(coarse) - 1)]


def prbs(n, seed, power=HEATER, p=PRBS_SWITCH):
    """A pseudo-random binary heater sequence (W) of n steps: on/off, switching with probability p."""
    rng = np.random.default_rng(seed)
    return power * (np.cumsum(rng.random(n) < p) % 2)


def own_columns(spec, building, grid, fine):
    """{column: values on `grid`} the file's building reads beside the weather: the air-only
    test cell's heater; the Twin House's heaters (a PRBS in the objective room, constant in the
    others), supply, cellar and attic temperatures, measured irradiances and closed shading."""
    step = pd.Timedelta(minutes=spec.step_min)
    coarse = pd.date_range(grid[0], grid[-1], freq=step)
    seed = record_seed(spec.name, 99)
    columns = {}
    if spec.building == "testcell":
        if spec.sensors == "air":
            columns["Q_heat"] = held(prbs(len(coarse), seed), coarse, grid)
        return columns
    site = building.site
    position = solar_position(grid, site["latitude"], site["longitude"], site["altitude"])
    for face, azimuth in (("north", 0.0), ("east", 90.0), ("south", 180.0), ("west", 270.0)):
        columns[f"Solar_radiation_global_vertical_{face}"] = incident_irradiance(
            position, fine["ghi"].to_numpy(), fine["dni"].to_numpy(), fine["dhi"].to_numpy(), 90.0, azimuth,
            site["ground_albedo"])
    objective = spec.objective or building.zones[0].name
    for i, z in enumerate(building.zones):
        for name in z.heat_input:
            if z.name == objective and name == z.heat_input[0]:
                columns[name] = held(prbs(len(coarse), seed, power=500.0), coarse, grid)
            else:
                columns[name] = 0.0 if name == "HeatInputKitchen" else 150.0
    t_out = fine["T_out"].to_numpy()
    columns.update({"vent_SUA_corr_AT": 20.0, "cellar_AT": 15.0, "attic_east_AT": t_out + 3.0, "shading_south": 0.0})
    return {k: np.broadcast_to(np.asarray(v, dtype=float), (len(grid),)).copy()
            for k, v in columns.items() if k in building.input_columns}


def measured_nodes(spec, building):
    if spec.sensors == "paper":
        return list(PAPER_SENSORS)
    if spec.sensors == "air":
        return [building.zones[0].air_node]
    if spec.sensors == "own":
        return sorted(set(building.sensors.values()))
    radiant = {z.radiant_node for z in building.zones}
    return [i for i in range(1, building.own_nodes + 1) if i not in radiant]


def truth_record(truth, weather, times, nodes):
    """(len(times), len(nodes)) noiseless temperatures (C) of `nodes` of the truth at `times`,
    simulated at `FINE_STEP` over `weather`'s span (the history before `times` included),
    from the steady state of its first day."""
    empty = pd.DataFrame(index=weather.index)
    empty.attrs["source"] = "truth"
    case = prepare_case(truth, weather, empty)
    T = simulate(truth, assemble(truth), case.U, case.dt, warmup_days=1, include_start=True, steady_start=True,
                 outputs=np.array(nodes) - 1)
    return T[weather.index.get_indexer(times)]


def frame(values, times, nodes, source):
    out = pd.DataFrame(values, index=pd.DatetimeIndex(times, name="time"), columns=[f"T{i}" for i in nodes])
    out.attrs["source"] = source
    return out


def record_seed(name, draw):
    """The record's noise seed: its name and draw, independent of the order records are run in."""
    return int.from_bytes(name.encode(), "little") % 2 ** 31 * 7 + draw
