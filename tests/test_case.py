"""A measured case on one uniform grid: weather follows the measurements, nothing is invented."""
import numpy as np
import pandas as pd
import pytest

from nodeforce.model.case import prepare_case, simulate_building
from nodeforce.model.errors import InputError


def measurements(times, values=None):
    frame = pd.DataFrame({"T23": np.linspace(25, 27, len(times)) if values is None else values},
                         index=pd.DatetimeIndex(times, name="time"))
    frame.attrs["source"] = "m.csv"
    return frame


def test_weather_is_interpolated_onto_a_finer_measurement_grid(testcell, weather):
    times = pd.date_range("2001-06-10 00:30", periods=13, freq="10min", tz="-05:00")
    case = prepare_case(testcell, weather, measurements(times))
    assert case.dt == 600.0 and len(case.times) == 13
    hourly = weather["T_out"]
    # 01:30 is a weather sample; 01:00 lies halfway between 00:30 and 01:30
    t0030, t0130 = hourly.loc["2001-06-10 00:30-05:00"], hourly.loc["2001-06-10 01:30-05:00"]
    assert case.U[6, 0] == t0130
    assert case.U[3, 0] == pytest.approx((t0030 + t0130) / 2)


def test_absent_rows_are_missing_measurements_not_invented(testcell, weather):
    times = pd.date_range("2001-06-10", periods=20, freq="15min", tz="-05:00")
    kept = times.delete([5, 6, 7])
    case = prepare_case(testcell, weather, measurements(kept))
    assert len(case.times) == 20  # the grid is whole
    assert np.isnan(case.measured[5:8, 22]).all()
    assert np.isfinite(np.delete(case.measured[:, 22], [5, 6, 7])).all()


def test_a_time_off_the_grid_is_refused(testcell, weather):
    times = pd.date_range("2001-06-10", periods=20, freq="15min", tz="-05:00")
    odd = times.insert(4, times[3] + pd.Timedelta(minutes=7))
    with pytest.raises(InputError) as e:
        prepare_case(testcell, weather, measurements(odd))
    assert e.value.source == "m.csv" and e.value.field == "time" and "grid" in e.value.problem


def test_a_node_the_building_lacks_is_refused(testcell, weather):
    times = pd.date_range("2001-06-10", periods=8, freq="15min", tz="-05:00")
    frame = measurements(times).rename(columns={"T23": "T40"})
    with pytest.raises(InputError) as e:
        prepare_case(testcell, weather, frame)
    assert e.value.field == "T40" and "1..23" in e.value.problem


def test_the_plain_api_simulates_every_node_with_forcing(testcell, weather):
    times = pd.date_range("2001-06-10", periods=2 * 96 + 1, freq="15min", tz="-05:00")
    measured = measurements(times, 24 + np.sin(np.arange(len(times)) / 10.0)).rename(columns={"T23": "T9"})
    free = simulate_building(testcell, weather)
    forced = simulate_building(testcell, weather, measured, force=[9])
    assert list(forced.columns) == [f"T{i}" for i in range(1, 24)]
    assert forced.index.equals(times[1:])
    assert np.array_equal(forced["T9"].to_numpy(), measured["T9"].to_numpy()[1:])
    # without measurements the weather's own hourly grid is used
    assert len(free) == len(weather) - 1 and free.index[0] == weather.index[1]
