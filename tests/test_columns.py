"""Input columns named as the building file names them (issue 12): read by that name through every
command, a column nobody refers to refused (a misspelt name is caught), `ghi`/`dni`/`dhi` needed
only where a face's irradiance is computed, measurement columns resolved to nodes."""
import copy
import json

import numpy as np
import pandas as pd
import pytest

from nodeforce.cli import main
from nodeforce.iotools.measurements import read_measurements
from nodeforce.iotools.timetable import write_time_table
from nodeforce.iotools.weather import read_weather
from nodeforce.model.building_file import parse_building
from nodeforce.model.case import prepare_case, simulate_building
from nodeforce.model.errors import InputError
from nodeforce.model.synth import pseudo_measurements
from tests.conftest import SENSORS, record_times


def named(testcell_data):
    """The test cell with a measured cellar under its floor and a measured heater in its air."""
    data = copy.deepcopy(testcell_data)
    data["zones"][0]["heat_input"] = "Q_heater"
    floor = next(c for c in data["components"] if c["name"] == "floor")
    floor["outside"] = {"type": "boundary", "temperature": "T_cellar", "h": 2.0}
    return data


def named_weather(weather, heater=400.0):
    """The bundled weather with the named columns and a measured irradiance on the roof."""
    w = weather.copy()
    hours = (w.index - w.index[0]).total_seconds().to_numpy() / 3600.0
    w["T_cellar"] = 18.0 + 2.0 * np.sin(2 * np.pi * hours / 24.0)
    w["Q_heater"] = np.where((hours % 24) < 8, heater, 0.0)
    w["I_roof"] = w["ghi"].clip(lower=0.0) * 0.9
    w.attrs["source"] = "named.csv"
    return w


@pytest.fixture(scope="module")
def files(tmp_path_factory, testcell_data, weather):
    d = tmp_path_factory.mktemp("named")
    data = named(testcell_data)
    building = d / "named.json"
    building.write_text(json.dumps(data))
    weather_csv = d / "weather.csv"
    write_time_table(named_weather(weather), weather_csv)
    # the building lived through the weather before its record, which the commands read as its history
    measurements = pseudo_measurements(parse_building(data, source=str(building)), read_weather(weather_csv),
                                       record_times(days=5), SENSORS, history_days=60)
    measured = d / "measured.csv"
    write_time_table(measurements, measured)
    return {"dir": d, "data": data, "building": str(building), "weather": str(weather_csv), "measurements": str(measured)}


def case_of(files, weather=None, measurements=None):
    building = parse_building(files["data"], source=files["building"])
    return building, prepare_case(building, weather if weather is not None else read_weather(files["weather"]),
                                  measurements)


def test_named_columns_are_the_inputs_by_their_names(files):
    building, case = case_of(files)
    raw = read_weather(files["weather"])
    for name in ("T_cellar", "Q_heater", "I_roof"):
        assert np.array_equal(case.U[:, case.input_names.index(name)], raw[name].to_numpy())


def test_the_named_heater_heats_the_air(files):
    building = parse_building(files["data"], source=files["building"])
    warm = simulate_building(building, read_weather(files["weather"]))
    cold_weather = read_weather(files["weather"]).assign(Q_heater=0.0)
    cold = simulate_building(building, cold_weather)
    # 400 W for 8 h a day into a 22.5 m3 cell: degrees, not hundredths
    assert (warm["T23"] - cold["T23"]).mean() > 1.0


@pytest.mark.parametrize("column, says", [
    ("Q_heatr", "nor one"),  # a misspelt heat input
    ("I_rooof", "names no exterior component"),  # a misspelt measured irradiance
    ("I_floor", "names no exterior component"),  # the floor is not exterior: its sun would be ignored
])
def test_a_column_nobody_refers_to_is_refused_by_name(files, column, says):
    weather = read_weather(files["weather"]).assign(**{column: 1.0})
    weather.attrs["source"] = files["weather"]
    with pytest.raises(InputError) as caught:
        case_of(files, weather)
    assert (caught.value.source, caught.value.field) == (files["weather"], column)
    assert says in caught.value.problem and "\n" not in str(caught.value)


def test_dni_is_needed_only_where_a_face_irradiance_is_computed(files, testcell):
    weather = read_weather(files["weather"])
    measured_sun = {f"I_{c.name}": weather["ghi"].clip(lower=0.0) * (k + 1) / 10
                    for k, c in enumerate(testcell.exterior_components)}
    everything = weather.drop(columns=["ghi", "dni", "dhi"]).assign(**measured_sun)
    everything.attrs["source"] = "all_measured.csv"
    building, case = case_of(files, everything)
    for name, values in measured_sun.items():
        assert np.array_equal(case.U[:, case.input_names.index(name)], values.to_numpy())
    one_computed = everything.drop(columns="I_door")
    one_computed.attrs["source"] = "one_computed.csv"
    with pytest.raises(InputError) as caught:
        case_of(files, one_computed)
    assert caught.value.source == "one_computed.csv" and caught.value.field == "ghi"
    assert "door" in caught.value.problem


@pytest.mark.parametrize("column, says", [("Tair", "names no node"), ("T0", "names no node"),
                                          ("T01", "names no node"), ("T40", "1..23")])
def test_a_measurement_column_that_names_no_node_is_refused(files, column, says):
    times = record_times(days=1)[:8]
    frame = pd.DataFrame({column: np.full(len(times), 20.0)}, index=times)
    frame.attrs["source"] = "m.csv"
    with pytest.raises(InputError) as caught:
        case_of(files, measurements=frame)
    assert (caught.value.source, caught.value.field) == ("m.csv", column)
    assert says in caught.value.problem


@pytest.mark.slow  # processes, a cluster or a whole diagnosis: not in `make check`
def test_named_columns_through_simulate_locate_and_diagnose(files, capsys):
    common = [files["building"], "--weather", files["weather"], "--measurements", files["measurements"]]
    sim = files["dir"] / "sim.csv"
    assert main(["simulate", *common, "-o", str(sim)]) == 0
    measured = read_measurements(files["measurements"])
    building = parse_building(files["data"], source=files["building"])
    direct = simulate_building(building, read_weather(files["weather"]), measured)
    through_fmu = pd.read_csv(sim)
    assert np.abs(through_fmu.iloc[:, 1:].to_numpy() - direct.to_numpy()).max() < 1e-9
    # the measurements come from this building and weather: what is left is the history's start
    # and steps' hundredths, where a heater or cellar read wrong would leave degrees
    residual = through_fmu["T23"].to_numpy() - measured["T23"].to_numpy()[1:]
    assert np.sqrt(np.mean(residual ** 2)) < 0.1

    assert main(["locate", *common, "-o", str(files["dir"] / "locate"), "--workers", "1"]) == 0
    located = json.loads((files["dir"] / "locate" / "locate.json").read_text())
    assert located["J_unforced"] == pytest.approx(np.sum(residual ** 2), rel=1e-6)

    assert main(["diagnose", *common, "-o", str(files["dir"] / "diagnose"), "--workers", "1"]) == 0
    report = json.loads((files["dir"] / "diagnose" / "report.json").read_text())
    assert report["before"]["validation"]["rmse"] < 0.1
    capsys.readouterr()

    misspelt = files["dir"] / "misspelt.csv"
    misspelt.write_text(open(files["weather"]).read().replace("Q_heater", "Q_heatr"))
    for command, extra in (("simulate", []), ("locate", ["-o", str(files["dir"] / "l2")]),
                           ("diagnose", ["-o", str(files["dir"] / "d2")])):
        assert main([command, files["building"], "--weather", str(misspelt), "--measurements",
                     files["measurements"], *extra]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith(f"nodeforce: {misspelt}: Q_heatr: neither a standard weather column") and "\n" not in err
