"""Effects with a shape in time: a gain with a daily profile (`daily_gain`), one on working days
only (`workday_gain`) and a gain proportional to an input column (`proportional_gain`), against calculations done without the code under test."""
import copy
import datetime
import json
import shutil

import numpy as np
import pandas as pd
import pytest

from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.fmu_build.build import build_fmu
from nodeforce.iotools.measurements import read_measurements
from nodeforce.iotools.weather import read_weather
from nodeforce.model.building import DAY_TERMS
from nodeforce.model.building_file import check_schema, parse_building
from nodeforce.model.case import clock_hours, prepare_case
from nodeforce.model.effects import EFFECTS
from nodeforce.model.errors import InputError
from nodeforce.model.integrate import simulate
from nodeforce.model.network import RHO_C_AIR, assemble
from nodeforce.cli import main

from .conftest import record_times

HARMONICS = {"cos1": -60.0, "sin1": -20.0, "cos2": 10.0, "sin2": 15.0, "cos3": 5.0, "sin3": -8.0,
             "cos4": 3.0, "sin4": 2.0}  # W
# one zone, one massless wall to a fixed 10 C: the air is the only capacity
VOLUME, AREA, H_IN, THICKNESS, K, H_OUT, T_BEYOND = 30.0, 20.0, 3.0, 0.1, 0.05, 25.0, 10.0


def one_zone(timezone, mean, daily):
    return {"format": "nodal-building/1", "name": "box",
            "site": {"latitude": 10.0, "longitude": 80.0, "timezone": timezone},
            "materials": {"board": {"conductivity": K, "density": 0.0, "specific_heat": 1000.0}},
            "zones": [{"name": "room", "volume": VOLUME, "internal_gain": mean, "daily_gain": daily}],
            "components": [{"name": "wall", "area": AREA, "tilt": 90.0, "azimuth": 180.0,
                            "layers": [["board", THICKNESS]], "nodes": {"max_spacing": 1.0},
                            "inside": {"zone": "room", "h_conv": H_IN, "h_rad": 5.0},
                            "outside": {"type": "boundary", "temperature": T_BEYOND, "h": H_OUT}}]}


def run(building, weather, measurements=None):
    case = prepare_case(building, weather, measurements)
    return case, simulate(building, assemble(building), case.U, case.dt, case.measured)


def test_daily_gain_gives_the_hand_computed_periodic_air_temperature(tmp_path):
    # Kolkata is UTC+05:30: the weather's UTC times are local times 5.5 h later
    dt, days = 900.0, 3
    times = pd.date_range("2001-06-10", periods=days * 96 + 1, freq="15min", tz="UTC")
    csv = tmp_path / "weather.csv"
    pd.DataFrame({"time": times.strftime("%Y-%m-%dT%H:%M:%S+00:00"), "T_out": 25.0}).to_csv(csv, index=False)
    building = parse_building(one_zone("Asia/Kolkata", 40.0, HARMONICS))
    case, T = run(building, read_weather(csv))
    air = T[:, building.zone("room").air_node - 1]

    # backward Euler on C dT/dt = -G (T - 10) + Q(t), inputs at the step's end, in its periodic regime:
    # each harmonic A e^{i w t} gives X e^{i w t} with X (G + C (1 - e^{-i w dt}) / dt) = A
    G = AREA / (1 / H_IN + THICKNESS / K + 1 / H_OUT)
    C = RHO_C_AIR * VOLUME
    utc_seconds = (times[1:] - times[0]).total_seconds().to_numpy()
    tau = ((utc_seconds + 5.5 * 3600) % 86400) / 3600  # local clock hours, by hand
    expected = np.full(len(tau), T_BEYOND + 40.0 / G)
    for h in range(1, 5):
        w = 2 * np.pi * h / 86400.0
        X = (HARMONICS[f"cos{h}"] - 1j * HARMONICS[f"sin{h}"]) / (G + C * (1 - np.exp(-1j * w * dt)) / dt)
        expected += np.real(X * np.exp(1j * 2 * np.pi * h * tau / 24))
    assert np.abs(air - expected).max() < 1e-9
    assert air.max() - air.min() > 10.0  # the profile moves the air by many kelvin
    # the basis the network reads is the local one (an hour off would move the phase by 15 degrees)
    assert np.allclose(case.U[1:, case.input_names.index("day_cos1")], np.cos(2 * np.pi * tau / 24), atol=1e-12)


def test_local_clock_follows_daylight_saving():
    # New York leaves EST (UTC-5) for EDT (UTC-4) at 07:00 UTC on 1 April 2001
    times = pd.date_range("2001-04-01 05:00", periods=5, freq="h", tz="UTC")
    assert list(clock_hours(times, "America/New_York", "b.json")) == [0.0, 1.0, 3.0, 4.0, 5.0]
    assert list(clock_hours(times, "Etc/GMT+5", "b.json")) == [0.0, 1.0, 2.0, 3.0, 4.0]


def heated(testcell_data, heat_input, proportional=None):
    data = copy.deepcopy(testcell_data)
    data["zones"][0]["heat_input"] = heat_input
    if proportional:
        data["zones"][0]["proportional_gains"] = proportional
    return parse_building(data)


def test_proportional_gain_equals_the_scaled_column_as_a_heat_input(testcell_data, weather):
    w = weather.copy()
    hour = w.index.hour
    w["heater"] = np.where((hour >= 6) & (hour < 20), 400.0, 0.0) + 5.0 * (hour % 7)
    w_error = w.assign(heater_error=-0.2 * w["heater"])
    grid = pd.DataFrame(index=record_times(days=3))
    by_k = heated(testcell_data, "heater", {"heater": -0.2})
    by_column = heated(testcell_data, ["heater", "heater_error"])
    declared_only = heated(testcell_data, "heater")
    _, T_k = run(by_k, w, grid)
    _, T_column = run(by_column, w_error, grid)
    _, T_plain = run(declared_only, w, grid)
    assert np.abs(T_k - T_column).max() < 1e-9
    assert np.abs(T_k - T_plain).max() > 0.5  # a heater measured 20 % high matters
    # the effect writes the same field the file declares
    after = EFFECTS["proportional_gain"].apply(declared_only, "cell->heater", {"k": -0.2})
    assert after.zone("cell").proportional_gains == (("heater", -0.2),)


def test_proportional_gain_targets_every_heat_input_and_face_irradiance(testcell_data):
    building = heated(testcell_data, "heater")
    targets = EFFECTS["proportional_gain"].targets(building)
    faces = [c.irradiance_input for c in building.exterior_components]
    assert targets == [f"cell->{column}" for column in ["heater", *faces]]
    assert all(EFFECTS["proportional_gain"].points_at(building, t) == () for t in targets)


def test_daily_gain_reads_back_and_keeps_its_mean_in_internal_gain(testcell):
    values = {"mean": 62.5, **HARMONICS}
    after = EFFECTS["daily_gain"].apply(testcell, "cell", values)
    assert after.zone("cell").internal_gain == 62.5
    assert dict(after.zone("cell").daily_gain) == HARMONICS
    assert EFFECTS["daily_gain"].read(after, "cell") == values
    assert [p.name for p in EFFECTS["daily_gain"].parameters] == ["mean", *DAY_TERMS]


@pytest.mark.parametrize("effect,mean", [("daily_gain", 62.5), ("workday_gain", 120.0)])
def test_the_standalone_fmu_carries_the_gain_with_a_profile(tmp_path, testcell, real_case, effect, mean):
    shutil.which("cc") or pytest.fail("the standalone FMU needs a C compiler (cc)")
    values = {"mean": mean, **HARMONICS}
    fmu = build_fmu(testcell, tmp_path / "s.fmu", effect=(effect, "cell"), kind="standalone")
    after = EFFECTS[effect].apply(testcell, "cell", values)
    case = real_case.with_inputs(after)
    if effect == "workday_gain":  # Sunday to Thursday: both kinds of day
        assert 0 < case.U[1:, case.input_names.index("workday_mean")].mean() < 1
    with FmuInstance(fmu) as instance:
        T = simulate_fmu(instance, case, parameters={f"{effect}.{k}": v for k, v in values.items()})
    assert np.abs(T - simulate(after, assemble(after), case.U, case.dt, case.measured, substeps=case.substeps)).max() < 1e-9


def test_workday_gain_acts_on_the_working_days_of_the_local_calendar(tmp_path):
    """A workday gain's mean alone, on a room whose air is its only capacity, against backward
    Euler by hand (inputs at the step's end), the working days told by the local calendar
    (Kolkata, UTC+05:30) without pandas' time zones: from Friday 8 to Monday 11 June 2001."""
    dt, Q = 900.0, 400.0
    times = pd.date_range("2001-06-08", periods=4 * 96 + 1, freq="15min", tz="UTC")
    csv = tmp_path / "weather.csv"
    pd.DataFrame({"time": times.strftime("%Y-%m-%dT%H:%M:%S+00:00"), "T_out": 25.0}).to_csv(csv, index=False)
    data = one_zone("Asia/Kolkata", 0.0, {})
    del data["zones"][0]["daily_gain"]
    data["zones"][0]["workday_gain"] = {"mean": Q}
    building = parse_building(data)
    case, T = run(building, read_weather(csv))
    air = T[:, building.zone("room").air_node - 1]

    G = AREA / (1 / H_IN + THICKNESS / K + 1 / H_OUT)
    C = RHO_C_AIR * VOLUME
    local = [datetime.datetime(2001, 6, 8) + datetime.timedelta(seconds=900.0 * n, hours=5.5)
             for n in range(1, len(times))]
    on = np.array([t.weekday() < 5 for t in local], dtype=float)
    expected = [air[0]]
    for n in range(1, len(on)):
        expected.append((C / dt * expected[-1] + G * T_BEYOND + Q * on[n]) / (C / dt + G))
    assert np.abs(air - np.array(expected)).max() < 1e-9
    # the gain's steady rise on Friday afternoon, none by Sunday noon: the gain stops at local
    # midnight, 18:30 UTC, not at the UTC one
    assert air[np.argmax(on == 0) - 1] == pytest.approx(T_BEYOND + Q / G, abs=0.01)
    assert air[int((2 * 24 + 12 - 5.5) * 4) - 1] == pytest.approx(T_BEYOND, abs=1e-6)
    assert on[int(24 * 4 - 5.5 * 4)] == 0 and case.U[1:, case.input_names.index("workday_mean")].tolist() == on.tolist()


def test_workday_gain_reads_back_beside_the_constant_gain(testcell):
    values = {"mean": 120.0, **HARMONICS}
    after = EFFECTS["workday_gain"].apply(testcell, "cell", values)
    assert after.zone("cell").internal_gain == testcell.zone("cell").internal_gain
    assert dict(after.zone("cell").workday_gain) == values
    assert EFFECTS["workday_gain"].read(after, "cell") == values
    assert [p.name for p in EFFECTS["workday_gain"].parameters] == ["mean", *DAY_TERMS]


@pytest.mark.parametrize("change,field", [
    (lambda z: z.update(daily_gain={"cos5": 1.0}), "zones[0].daily_gain"),
    (lambda z: z.update(daily_gain={"cos1": "x"}), "zones[0].daily_gain.cos1"),
    (lambda z: z.update(workday_gain={"peak": 1.0}), "zones[0].workday_gain"),
    (lambda z: z.update(workday_gain={"mean": None}), "zones[0].workday_gain.mean"),
    (lambda z: z.update(proportional_gains={"heater": 0.5}), "zones[0].proportional_gains.heater"),
    (lambda z: z.update(proportional_gains={"I_roof": None}), "zones[0].proportional_gains.I_roof"),
])
def test_bad_shape_fields_are_refused_naming_the_field(testcell_data, change, field):
    data = copy.deepcopy(testcell_data)
    change(data["zones"][0])
    with pytest.raises(InputError) as refused:
        parse_building(data, source="cell.json")
    assert (refused.value.source, refused.value.field) == ("cell.json", field)


def test_the_schema_refuses_a_harmonic_the_model_does_not_have(testcell_data):
    data = copy.deepcopy(testcell_data)
    data["zones"][0]["daily_gain"] = {"cos5": 1.0}
    with pytest.raises(InputError, match="daily_gain"):
        check_schema(data, "cell.json")


def test_a_daily_gain_needs_a_real_timezone(testcell_data, weather):
    data = copy.deepcopy(testcell_data)
    data["site"]["timezone"] = "Mars/Olympus"
    data["zones"][0]["daily_gain"] = {"cos1": 10.0}
    with pytest.raises(InputError, match="site.timezone"):
        prepare_case(parse_building(data, source="cell.json"), weather, pd.DataFrame(index=record_times(days=1)))


def test_synth_adds_shaped_gains(tmp_path, testcell_data):
    from .conftest import DATA
    building = tmp_path / "cell.json"
    building.write_text(json.dumps(testcell_data))
    base = ["synth", str(building), "--weather", str(DATA / "miami_tmy2.csv"), "--start",
            "2001-06-10T00:00-05:00", "--days", "2", "--history-days", "0", "--noise", "0", "--sensors", "23"]
    out = {name: tmp_path / f"{name}.csv" for name in ("plain", "daily", "sun")}
    assert main(base + ["-o", str(out["plain"])]) == 0
    # a gain of +100 W at local noon and -100 W at midnight
    assert main(base + ["-o", str(out["daily"]), "--effect", "daily_gain@cell:cos1=-100,sin1=0"]) == 0
    assert main(base + ["-o", str(out["sun"]), "--effect", "proportional_gain@cell->I_window:k=0.5"]) == 0
    plain, daily, sun = (read_measurements(out[n])["T23"] for n in ("plain", "daily", "sun"))
    hour = plain.index.hour  # the record's times are local (-05:00, the site's Etc/GMT+5)
    day, night = (hour >= 10) & (hour < 16), (hour >= 22) | (hour < 4)
    assert (daily - plain)[day].mean() > 0.5 > -0.5 > (daily - plain)[night].mean()
    assert (sun - plain).min() > -1e-9 and (sun - plain)[day].mean() > (sun - plain)[night].mean() + 0.2
