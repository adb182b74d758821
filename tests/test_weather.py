"""Weather files: checks, interpolation onto the measurement grid, typical-year conversion."""

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pvlib
import pytest

from nodeforce.model.errors import InputError
from nodeforce.model.solar import solar_position
from nodeforce.model.weather import weather_on_grid
from nodeforce.iotools.typical_year import convert_typical_year, main, relocate
from nodeforce.iotools.hourly import epw_site
from nodeforce.iotools.weather import TYPICAL_YEAR, read_weather
from nodeforce.model.weather import weather_on_grid

PVLIB_DATA = Path(pvlib.__file__).parent / "data"
MODEL_DATA = Path(__file__).resolve().parents[1] / "model" / "data"

GOOD = """time,T_out,ghi,dni,dhi,T_sky,I_roof
2024-06-01T00:00+02:00,18.5,0,0,0,5.0,0
2024-06-01T01:00+02:00,18.0,,0,0,4.5,0
2024-06-01T02:00+02:00,17.5,0,0,-2,4.0,0
"""


def write(tmp_path, text, name="weather.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_reads_a_good_file_with_gaps_left_missing(tmp_path):
    w = read_weather(write(tmp_path, GOOD))
    assert w.index.name == "time"
    assert w.index.tz is not None
    assert w.index[1] == pd.Timestamp("2024-05-31T23:00Z")
    assert list(w.columns) == ["T_out", "ghi", "dni", "dhi", "T_sky", "I_roof"]
    assert np.isnan(w["ghi"].iloc[1])
    assert w["T_out"].tolist() == [18.5, 18.0, 17.5]
    assert w["dhi"].iloc[2] == -2.0  # a night-time sensor offset is data, not an error


@pytest.mark.parametrize(
    "text, column",
    [
        (GOOD.replace(",T_out,", ",T_air,"), "T_out"),  # missing
        (GOOD.replace("2024-06-01T01:00+02:00", "2024-06-01T01:00"), "time"),  # naive
        (GOOD.replace("2024-06-01T01:00+02:00", "yesterday+02:00"), "time"),  # unparseable
        (GOOD.replace("2024-06-01T01:00+02:00", "2024-06-01T00:00+02:00"), "time"),  # duplicate
        (GOOD.replace("2024-06-01T02:00+02:00", "2024-05-31T23:00+02:00"), "time"),  # goes back
        (GOOD.replace("18.0,", "18,0,", 1), "file"),  # extra field
        (GOOD.replace("17.5,", "warm,"), "T_out"),  # non-numeric
        (GOOD.replace("18.5,", "291.6,").replace("18.0,", "291.1,").replace("17.5,", "290.6,"), "T_out"),
        (GOOD.replace("5.0,", "278.1,").replace("4.5,", "277.6,").replace("4.0,", "277.1,"), "T_sky"),
        (GOOD.replace(",-2,", ",-999,"), "dhi"),  # missing-value code
        (GOOD.replace("4.0,0\n", "4.0,-9999\n"), "I_roof"),
        (GOOD.replace("time,", "time,T_out,").replace("+02:00,", "+02:00,1,"), "T_out"),  # twice
        ("time,T_out,ghi,dni,dhi\n", "time"),  # no rows
    ],
)
def test_bad_weather_names_the_file_and_column(tmp_path, text, column):
    path = write(tmp_path, text)
    with pytest.raises(InputError) as caught:
        read_weather(path)
    assert caught.value.source == str(path)
    assert caught.value.field == column


def test_any_named_column_with_numbers_passes_the_reader(tmp_path):
    # which columns a building may use is checked where the building is known (tests/test_columns.py)
    text = "time,T_out,T_cellar,I_nowhere\n2024-06-01T00:00Z,18,12.5,40\n"
    w = read_weather(write(tmp_path, text))
    assert list(w.columns) == ["T_out", "T_cellar", "I_nowhere"] and w["T_cellar"].iloc[0] == 12.5


def test_negative_infrared_is_refused(tmp_path):
    text = "time,T_out,ghi,dni,dhi,ir_h\n2024-06-01T00:00Z,18,0,0,0,-5\n"
    with pytest.raises(InputError, match="ir_h"):
        read_weather(write(tmp_path, text))


def test_missing_file_is_an_input_error(tmp_path):
    with pytest.raises(InputError) as caught:
        read_weather(tmp_path / "nowhere.csv")
    assert caught.value.field == "file"


def test_mixed_offsets_are_one_instant_each(tmp_path):
    text = ("time,T_out,ghi,dni,dhi\n2024-03-31T01:30+01:00,1,0,0,0\n"
            "2024-03-31T03:30+02:00,2,0,0,0\n")
    w = read_weather(write(tmp_path, text))
    assert w.index[1] - w.index[0] == pd.Timedelta(hours=1)


def hourly(tmp_path, values, start="2024-06-01T00:00+00:00"):
    times = pd.date_range(start, periods=len(values), freq="1h")
    lines = ["time,T_out,ghi,dni,dhi"]
    lines += [f"{t.isoformat()},{'' if np.isnan(v) else v},0,0,0" for t, v in zip(times, values)]
    return write(tmp_path, "\n".join(lines) + "\n")


def test_quarter_hour_grid_reproduces_a_linear_function(tmp_path):
    hours = np.arange(6.0)
    w = read_weather(hourly(tmp_path, 2.0 + 0.7 * hours))
    grid = pd.date_range("2024-06-01T02:00+02:00", "2024-06-01T07:00+02:00", freq="15min")
    on_grid = weather_on_grid(w, grid)
    elapsed = (grid - pd.Timestamp("2024-06-01T00:00Z")).total_seconds().to_numpy() / 3600
    assert on_grid.index.equals(grid)
    assert np.allclose(on_grid["T_out"].to_numpy(), 2.0 + 0.7 * elapsed, rtol=0, atol=1e-12)


def test_missing_values_are_not_interpolated_across(tmp_path):
    w = read_weather(hourly(tmp_path, [10.0, np.nan, 12.0, 13.0]))
    grid = pd.date_range("2024-06-01T00:00Z", periods=13, freq="15min")
    t = weather_on_grid(w, grid)["T_out"].to_numpy()
    assert t[0] == 10.0 and t[8] == 12.0 and t[10] == 12.5 and t[12] == 13.0
    assert np.isnan(t[1:8]).all()


def test_absent_rows_are_a_gap_not_a_ramp(tmp_path):
    text = ("time,T_out,ghi,dni,dhi\n2024-06-01T00:00Z,10,0,0,0\n2024-06-01T01:00Z,11,0,0,0\n"
            "2024-06-01T05:00Z,15,0,0,0\n2024-06-01T06:00Z,16,0,0,0\n")
    w = read_weather(write(tmp_path, text))
    grid = pd.date_range("2024-06-01T00:30Z", periods=6, freq="1h")
    t = weather_on_grid(w, grid)["T_out"].to_numpy()
    assert t[0] == 10.5 and t[5] == 15.5
    assert np.isnan(t[1:5]).all()


def test_grid_outside_the_weather_names_the_file(tmp_path):
    path = hourly(tmp_path, [1.0, 2.0, 3.0])
    w = read_weather(path)
    late = pd.date_range("2024-06-01T01:00Z", "2024-06-01T03:00Z", freq="15min")
    with pytest.raises(InputError, match="does not cover") as caught:
        weather_on_grid(w, late)
    assert caught.value.source == str(path)


def epw(tmp_path, years, name="site.epw"):
    """A two-day EPW; `years` gives the year of each day (a typical year mixes them)."""
    header = ["LOCATION,Testville,XX,YYY,TMY3,123456,10.0,150.0,10.0,50.0"]
    header += ["DESIGN CONDITIONS,0", "TYPICAL/EXTREME PERIODS,0", "GROUND TEMPERATURES,0",
               "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0", "COMMENTS 1,", "COMMENTS 2,",
               "DATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31"]
    rows = []
    for d, (year, day) in enumerate(zip(years, (1, 2))):
        for hour in range(1, 25):
            n = 24 * d + hour
            ghi = 9999 if n == 30 else 100 + n
            temp = 99.9 if n == 40 else float(n)
            rows.append(",".join(str(v) for v in [
                year, 1, day, hour, 60, "?", temp, 5.0, 80, 101325, 0, 0, 300 + n, ghi, 200 + n,
                50 + n] + ["0"] * 19))
    path = tmp_path / name
    path.write_text("\n".join(header + rows) + "\n")
    return path


def test_an_epws_site_is_its_location_line(tmp_path):
    """LOCATION,Testville,XX,YYY,TMY3,123456,10.0,150.0,10.0,50.0: latitude, longitude, UTC+10
    (IANA's Etc/GMT-10) and 50 m; a line without them is refused, naming the file."""
    assert epw_site(epw(tmp_path, [2001, 2001])) == {
        "name": "Testville 123456", "latitude": 10.0, "longitude": 150.0, "utc_offset": 10.0,
        "timezone": "Etc/GMT-10", "altitude": 50.0}
    (tmp_path / "bad.epw").write_text("LOCATION,Testville,XX\n")
    with pytest.raises(InputError, match="LOCATION") as caught:
        epw_site(tmp_path / "bad.epw")
    assert caught.value.source == str(tmp_path / "bad.epw")


def test_epw_rows_every_half_hour_with_codes_as_missing(tmp_path):
    """Hour n of the file (1-based) ends at n:00: its readings (T_out = n, ir_h = 300 + n) there,
    its sun (ghi = 100 + n) at n - 0.5 h, and each between as the linear interpolation of its own
    neighbours, as EnergyPlus interpolates an EPW."""
    w = read_weather(epw(tmp_path, [2019, 2019]))
    assert len(w) == 95  # 48 middles and 47 ends: the sun after the last middle is not in the file
    # EPW hour 1 of 1 January (UTC+10) covers 00:00-01:00 local standard time.
    assert w.index[0] == pd.Timestamp("2019-01-01T00:30+10:00")
    assert w.index[1] == pd.Timestamp("2019-01-01T01:00+10:00")
    assert w["ghi"].iloc[0] == 101 and w["dni"].iloc[0] == 201 and w["dhi"].iloc[0] == 51
    assert w["ghi"].iloc[1] == 101.5  # the mean of hours 1 and 2's sun, at their meeting
    assert np.isnan(w["T_out"].iloc[0]) and np.isnan(w["ir_h"].iloc[0])  # the readings at 00:00 are before the file
    assert w["T_out"].iloc[1] == 1.0 and w["ir_h"].iloc[1] == 301  # the readings at 01:00
    assert w["T_out"].iloc[2] == 1.5 and w["ir_h"].iloc[2] == 301.5  # their mean at 01:30
    assert np.isnan(w["ghi"].iloc[57:60]).all() and w["ghi"].notna().sum() == 92  # 9999 is EPW's missing code
    assert np.isnan(w["T_out"].iloc[78:81]).all() and w["T_out"].notna().sum() == 91  # 99.9 is missing


def test_epw_wind_direction_turns_the_short_way_round_north(tmp_path):
    """Directions read 350 deg at 01:00 and 10 deg at 02:00: 0 deg between them, and at every
    time between the two as EnergyPlus interpolates them (20 deg an hour through north)."""
    path = epw(tmp_path, [2019, 2019])
    lines = path.read_text().splitlines()
    for k, direction in ((8, 350), (9, 10)):  # the rows of hours 1 and 2
        fields = lines[k].split(",")
        fields[20] = str(direction)
        lines[k] = ",".join(fields)
    path.write_text("\n".join(lines) + "\n")
    w = read_weather(path)
    assert w["wind_direction"].iloc[1] == 350 and w["wind_direction"].iloc[2] == 0.0
    times = pd.date_range("2019-01-01T01:00+10:00", "2019-01-01T02:00+10:00", freq="10min")
    expected = (350.0 + 20.0 * np.arange(7) / 6.0) % 360.0
    assert np.allclose(weather_on_grid(w, times)["wind_direction"].to_numpy(), expected)


def test_typical_year_epw_is_read_in_one_calendar_year_as_energyplus_reads_it(tmp_path):
    # two days whose rows say 2011 and 1997: EnergyPlus reads their months, days and hours
    path = epw(tmp_path, [2011, 1997])
    w = read_weather(path)
    assert w.attrs["typical_year"]
    assert w.index[0] == pd.Timestamp(f"{TYPICAL_YEAR}-01-01T00:30+10:00") and len(w) == 95
    assert w.index.is_monotonic_increasing and (w.index.year == TYPICAL_YEAR).all()
    assert w["T_out"].iloc[0] == (48.0 + 1.0) / 2  # the year wraps around: its first hour follows its last
    assert w["T_out"].iloc[2] == 1.5 and w["ghi"].iloc[0] == 101
    given = read_weather(path, year=2013)
    assert given.index[0] == pd.Timestamp("2013-01-01T00:30+10:00")
    assert np.array_equal(given.to_numpy(), w.to_numpy(), equal_nan=True)


def test_an_epw_read_in_a_year_equals_the_typical_year_converted_to_a_csv(tmp_path):
    path = epw(tmp_path, [2011, 1997])
    convert_typical_year(path, tmp_path / "w.csv", year=2003)
    converted = read_weather(tmp_path / "w.csv")
    read = read_weather(path, year=2003)
    assert read.index.equals(converted.index)
    assert np.allclose(read[converted.columns].to_numpy(), converted.to_numpy(), rtol=1e-5, equal_nan=True)


def test_an_actual_year_epw_keeps_its_year_unless_one_is_given(tmp_path):
    path = epw(tmp_path, [2019, 2019])
    assert read_weather(path).index[0].year == 2019 and not read_weather(path).attrs["typical_year"]
    assert read_weather(path, year=2021).index[0] == pd.Timestamp("2021-01-01T00:30+10:00")


def test_a_year_given_to_a_weather_csv_is_refused(tmp_path):
    path = hourly(tmp_path, [1.0, 2.0, 3.0])
    with pytest.raises(InputError, match="EPW") as caught:
        read_weather(path, year=2017)
    assert (caught.value.source, caught.value.field) == (str(path), "year")


def test_typical_year_epw_converts_with_infrared(tmp_path):
    dst = tmp_path / "out.csv"
    meta = convert_typical_year(epw(tmp_path, [2011, 1997]), dst, year=2003)
    assert meta["timezone"] == "Etc/GMT-10" and meta["utc_offset"] == 10.0
    assert (meta["latitude"], meta["longitude"], meta["altitude"]) == (10.0, 150.0, 50.0)
    w = read_weather(dst)
    assert w.index[0] == pd.Timestamp("2003-01-01T00:30+10:00")
    assert w["ir_h"].iloc[0] == (348 + 301) / 2 and w["ir_h"].iloc[1] == 301
    assert w["T_out"].iloc[0] == (48.0 + 1.0) / 2  # the year wraps around
    assert "ir_h" in dst.read_text().splitlines()[0]


def test_leap_year_is_refused(tmp_path):
    with pytest.raises(InputError, match="leap"):
        convert_typical_year(PVLIB_DATA / "12839.tm2", tmp_path / "x.csv", year=2004)


@pytest.fixture(scope="module")
def miami(tmp_path_factory):
    dst = tmp_path_factory.mktemp("tmy") / "miami.csv"
    meta = convert_typical_year(PVLIB_DATA / "12839.tm2", dst)
    return dst, meta


def test_tmy2_conversion_round_trips_over_a_whole_year(miami):
    dst, meta = miami
    w = read_weather(dst)
    assert len(w) == 8760
    assert w.index[0] == pd.Timestamp("2001-01-01T00:30-05:00")
    assert w.index[-1] == pd.Timestamp("2001-12-31T23:30-05:00")
    assert (np.diff(w.index.asi8) == np.diff(w.index.asi8)[0]).all()
    assert "ir_h" not in w  # TMY2 has no infrared: the model will use Swinbank
    assert w.notna().all().all()
    raw, _ = pvlib.iotools.read_tmy2(PVLIB_DATA / "12839.tm2")
    assert np.array_equal(w["ghi"].to_numpy(), raw["GHI"].to_numpy())
    assert np.array_equal(w["dni"].to_numpy(), raw["DNI"].to_numpy())
    dry = raw["DryBulb"].to_numpy() / 10  # tenths of a degree in TMY2
    assert np.allclose(w["T_out"].to_numpy()[1:], (dry[:-1] + dry[1:]) / 2)
    assert meta == {"name": "Miami, FL (TMY2 12839)", "latitude": 25.8,
                    "longitude": pytest.approx(-80.2667, abs=1e-4), "altitude": 2.0,
                    "utc_offset": -5.0, "timezone": "Etc/GMT+5",
                    "ground_temperature": pytest.approx(w["T_out"].mean(), abs=0.005)}


def test_mid_hour_stamps_centre_the_sun_on_solar_noon(miami):
    # Stamped at the end of its hour, irradiance would lag solar noon by 30 min (7.5 deg).
    dst, meta = miami
    w = read_weather(dst)
    position = solar_position(w.index, meta["latitude"], meta["longitude"], meta["altitude"])
    eot = position["equation_of_time"].to_numpy()
    angle = np.asarray(pvlib.solarposition.hour_angle(w.index, meta["longitude"], eot))
    angle = (angle + 180) % 360 - 180
    assert abs(np.sum(angle * w["ghi"]) / np.sum(w["ghi"])) < 2.5


def test_tmy3_conversion_is_one_increasing_year(tmp_path):
    dst = tmp_path / "greensboro.csv"
    meta = convert_typical_year(PVLIB_DATA / "723170TYA.CSV", dst, year=2001)
    w = read_weather(dst)
    assert len(w) == 8760 and w.index.is_monotonic_increasing
    assert w.index[0] == pd.Timestamp("2001-01-01T00:30-05:00")
    assert w.index[-1] == pd.Timestamp("2001-12-31T23:30-05:00")
    assert meta["latitude"] == 36.1 and meta["altitude"] == 273.0
    # the deep-ground estimate is the year's mean air, as read back from the file written (to its
    # 6 digits), between the coldest and the warmest month's
    assert meta["ground_temperature"] == pytest.approx(w["T_out"].mean(), abs=0.005)
    monthly = w["T_out"].groupby(w.index.month).mean()
    assert monthly.min() + 5.0 < meta["ground_temperature"] < monthly.max() - 5.0


def test_relocate_copies_and_replaces_the_site_only():
    building = {"name": "b", "site": {"latitude": 1.0, "longitude": 2.0, "altitude": 3.0,
                                      "timezone": "UTC", "ground_albedo": 0.3},
                "zones": [{"name": "z"}]}
    before = json.dumps(building)
    moved = relocate(building, {"latitude": 25.8, "longitude": -80.3, "altitude": 2.0,
                                "timezone": "Etc/GMT+5", "utc_offset": -5.0, "name": "Miami"})
    assert json.dumps(building) == before
    assert moved["site"] == {"latitude": 25.8, "longitude": -80.3, "altitude": 2.0,
                             "timezone": "Etc/GMT+5", "ground_albedo": 0.3}
    moved["zones"][0]["name"] = "changed"
    assert building["zones"][0]["name"] == "z"
    # a typical year's deep-ground estimate moves with the site
    grounded = relocate(building, {"latitude": 25.8, "longitude": -80.3, "altitude": 2.0, "timezone": "Etc/GMT+5",
                                   "ground_temperature": 24.3})
    assert grounded["site"]["ground_temperature"] == 24.3 and "ground_temperature" not in building["site"]


def test_command_line_reproduces_the_bundled_files(tmp_path):
    out, building_out = tmp_path / "m.csv", tmp_path / "b.json"
    status = main(["convert", str(PVLIB_DATA / "12839.tm2"), str(out),
                   "--building", str(MODEL_DATA / "testcell.json"), "--building-out", str(building_out)])
    assert status == 0
    assert out.read_text() == (MODEL_DATA / "miami_tmy2.csv").read_text()
    assert building_out.read_text() == (MODEL_DATA / "testcell_miami.json").read_text()
    original = json.loads((MODEL_DATA / "testcell.json").read_text())
    moved = json.loads(building_out.read_text())
    assert "Miami" in moved["name"]
    assert moved["site"]["latitude"] == 25.8 and moved["site"]["timezone"] == "Etc/GMT+5"
    assert {k: v for k, v in moved.items() if k not in ("name", "site")} == \
        {k: v for k, v in original.items() if k not in ("name", "site")}


def test_command_line_bad_source_exits_2(tmp_path, capsys):
    bad = write(tmp_path, "not a typical year", name="x.tm3")
    assert main(["convert", str(bad), str(tmp_path / "o.csv")]) == 2
    assert str(bad) in capsys.readouterr().err
