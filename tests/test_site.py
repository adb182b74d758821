"""The site a run computes at: an EPW recorded elsewhere than the building file's site moves the
run there, as EnergyPlus takes an EPW's LOCATION over the IDF's Site:Location; a CSV does not."""
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pyenergyplus
import pytest

from nodeforce.cli import main
from nodeforce.iotools.typical_year import convert_typical_year
from nodeforce.iotools.weather import read_weather
from nodeforce.model.building_file import parse_building
from nodeforce.model.case import prepare_case
from tests.conftest import DATA

CHICAGO = Path(pyenergyplus.__file__).parent / "data" / "weather" / "USA_IL_Chicago-OHare.Intl.AP.725300_TMY3.epw"
# its LOCATION line: Chicago Ohare Intl Ap, 41.98 N, -87.92 E, UTC-6, 201 m
LATITUDE, LONGITUDE, OFFSET, ELEVATION = 41.98, -87.92, -6.0, 201.0


@pytest.fixture(scope="module")
def chicago():
    return read_weather(CHICAGO)


def miami_cell(**site):
    """The bundled test cell, sited in Miami (25.8 N, -80.27 E, UTC-5, 2 m), its site edited."""
    data = json.loads((DATA / "testcell_miami.json").read_text())
    data["site"].update(site)
    return parse_building(data, source="testcell_miami.json")


def summer_day():
    """A day of weather rows (mid-hour, the EPW's standard time) around the June solstice, with
    nothing measured."""
    times = pd.date_range("2017-06-21T00:30-06:00", periods=24, freq="1h", name="time")
    frame = pd.DataFrame(index=times)
    frame.attrs["source"] = "m.csv"
    return frame


def cos_zenith(times, latitude, longitude):
    """cos of the sun's zenith (-) by hand: declination d = 23.45 sin(360 (284 + n) / 365) deg
    (Cooper), the equation of time E = 9.87 sin 2B - 7.53 cos B - 1.5 sin B min, B = 360 (n - 81)
    / 364 deg, solar time t_s = t_UTC + longitude / 15 h + E / 60 h (4 min a degree of
    longitude), hour angle w = 15 (t_s - 12) deg; cos z = sin(lat) sin(d) + cos(lat) cos(d) cos(w)."""
    utc = times.tz_convert("UTC")
    n = utc.day_of_year.to_numpy()
    d = np.radians(23.45 * np.sin(np.radians(360.0 * (284 + n) / 365.0)))
    b = np.radians(360.0 * (n - 81) / 364.0)
    e = 9.87 * np.sin(2 * b) - 7.53 * np.cos(b) - 1.5 * np.sin(b)
    solar = utc.hour + utc.minute / 60.0 + longitude / 15.0 + e / 60.0
    w = np.radians(15.0 * (solar - 12.0))
    lat = np.radians(latitude)
    return np.sin(lat) * np.sin(d) + np.cos(lat) * np.cos(d) * np.cos(w)


def test_the_sun_stands_where_the_epw_was_recorded(chicago):
    """The roof (horizontal, isotropic sky) gets dni cos z + dhi: the z the case computed is the
    one at the EPW's latitude and longitude, not at the building file's 7.65 deg of longitude (31
    min of solar time) and 6.2 deg of latitude away."""
    case = prepare_case(miami_cell(), chicago, summer_day())
    on_rows = chicago.reindex(case.times)
    roof = case.U[:, case.input_names.index("I_roof")]
    sunny = (on_rows["dni"] > 100).to_numpy() & (cos_zenith(case.times, LATITUDE, LONGITUDE) > 0.2)
    assert sunny.sum() >= 8
    computed = (roof - on_rows["dhi"].to_numpy())[sunny] / on_rows["dni"].to_numpy()[sunny]
    at_epw = cos_zenith(case.times, LATITUDE, LONGITUDE)[sunny]
    at_file = cos_zenith(case.times, 25.8, -80.27)[sunny]
    assert np.abs(computed - at_epw).max() < 0.01
    assert np.abs(at_file - at_epw).max() > 0.1  # the test tells the two sites apart


def test_the_clock_and_the_air_follow_the_epw(chicago):
    """The standard time becomes the EPW's (UTC-6, not Miami's UTC-5) and the air's density
    follows the pressure of the standard atmosphere, p(z) = 101325 (1 - 2.25577e-5 z)^5.2559 Pa,
    from 2 m up to 201 m; a zone that keeps the EPW's standard time keeps its name (its daylight
    saving rules)."""
    cell = miami_cell(air_density=1.2)
    site = prepare_case(cell, chicago, summer_day()).building.site
    p = lambda z: 101325.0 * (1.0 - 2.25577e-5 * z) ** 5.2559  # noqa: E731
    assert site["timezone"] == "Etc/GMT+6"
    assert site["air_density"] == pytest.approx(1.2 * p(201.0) / p(2.0), rel=1e-12)
    assert (site["latitude"], site["longitude"], site["altitude"]) == (LATITUDE, LONGITUDE, ELEVATION)
    same_clock = prepare_case(miami_cell(timezone="America/Chicago"), chicago, summer_day())
    assert same_clock.building.site["timezone"] == "America/Chicago"


def test_the_assumption_names_both_sites(chicago):
    case = prepare_case(miami_cell(), chicago, summer_day())
    said = case.assumptions[0]
    assert said.startswith("The weather file's site (Chicago Ohare Intl Ap 725300")
    for text in ("latitude 41.98, longitude -87.92 deg, UTC-6 h, 201 m", "latitude 25.80, longitude -80.27 deg, "
                 "UTC-5 h, 2 m", "latitude, longitude, altitude and time zone differ"):
        assert text in said


def test_a_building_sited_at_the_epw_is_run_as_it_is(chicago):
    """Within 0.01 deg and 1 m, and on the same standard time, the building file's site stands:
    the same Building, nothing said."""
    cell = miami_cell(latitude=LATITUDE + 0.009, longitude=LONGITUDE - 0.009, altitude=ELEVATION + 0.9,
                      timezone="Etc/GMT+6")
    case = prepare_case(cell, chicago, summer_day())
    assert case.building is cell and case.assumptions == ()


def test_a_csv_weather_keeps_the_building_files_site(tmp_path, chicago):
    """The same Chicago year as a CSV carries no site: the Miami cell runs in Miami, its inputs
    those of the cell sited in Miami under no site at all, to the bit, and unlike the EPW's."""
    convert_typical_year(CHICAGO, tmp_path / "chicago.csv", year=2017)
    csv = read_weather(tmp_path / "chicago.csv")
    cell = miami_cell()
    from_csv = prepare_case(cell, csv, summer_day())
    no_site = chicago.copy()
    no_site.attrs = {"source": str(CHICAGO)}
    from_epw_without_site = prepare_case(cell, no_site, summer_day())
    assert from_csv.building is cell and from_csv.assumptions == ()
    roof = from_csv.input_names.index("I_roof")
    assert np.array_equal(from_csv.U[:, roof], from_epw_without_site.U[:, roof])
    moved = prepare_case(cell, chicago, summer_day())
    assert np.abs(moved.U[:, roof] - from_csv.U[:, roof]).max() > 50.0  # W/m2


def test_simulate_says_which_site_it_used(tmp_path, capsys):
    """The command line says the assumption once."""
    times = pd.date_range("2017-06-20T00:00-06:00", periods=2 * 96 + 1, freq="15min", name="time")
    pd.DataFrame({"T23": 25.0}, index=times).to_csv(tmp_path / "m.csv", date_format="%Y-%m-%dT%H:%M:%S%z")
    assert main(["simulate", str(DATA / "testcell_miami.json"), "--weather", str(CHICAGO), "--measurements",
                 str(tmp_path / "m.csv"), "--history-days", "0", "-o", str(tmp_path / "sim.csv")]) == 0
    said = [line for line in capsys.readouterr().out.splitlines() if line.startswith("assumed: The weather file's site")]
    assert len(said) == 1 and "Chicago Ohare Intl Ap 725300" in said[0]


def test_a_diagnosis_runs_at_its_records_site_and_writes_back_the_files(chicago):
    """The loop's building is the one its records' cases ran (`run_site`); what it writes back
    has the file's site, all else as run (`as_given`); records of one house at two sites are
    refused, naming the second."""
    from nodeforce.diagnosis.loop import as_given, run_site
    from nodeforce.diagnosis.windows import Record
    from nodeforce.model.errors import InputError
    cell = miami_cell()
    at_chicago = Record(prepare_case(cell, chicago, summer_day()), "a.csv", "a")
    ran = run_site(cell, [at_chicago])
    assert ran.to_json() == at_chicago.case.building.to_json() and ran.site["longitude"] == LONGITUDE
    back = as_given(ran, cell)
    assert back["site"] == json.loads((DATA / "testcell_miami.json").read_text())["site"]
    assert {k: v for k, v in back.items() if k != "site"} == {k: v for k, v in ran.to_json().items() if k != "site"}
    no_site = chicago.copy()
    no_site.attrs = {"source": "b.csv"}
    in_miami = Record(prepare_case(cell, no_site, summer_day()), "b.csv", "b")
    with pytest.raises(InputError, match="record b's weather was recorded at another site") as caught:
        run_site(cell, [at_chicago, in_miami])
    assert caught.value.source == "b.csv"
