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


def test_a_case_s_kept_plan_runs_every_building_of_its_layout_as_a_fresh_simulation(real_case):
    # Case.run keeps a run's plan by layout: a building with another conductivity (the same layout)
    # must run on it as simulate runs it afresh, and one with a node more (an internal mass) on
    # its own; the plans are never pickled with the case
    import pickle
    from dataclasses import replace
    from nodeforce.model.effects import EFFECTS
    from nodeforce.model.integrate import simulate
    from nodeforce.model.network import assemble
    case = replace(real_case.with_steady_start(), burn_in_steps=24)
    size = len(pickle.dumps(case))
    cell = real_case.building
    zone = cell.zones[0].name
    door = EFFECTS["conductivity"].apply(cell, "door", {"factor": 2.0})
    massive = EFFECTS["internal_mass"].apply(cell, zone, {"C_m": 2e6, "H_m": 150.0})
    for building in (cell, door, massive, door, massive):
        fresh = simulate(building, assemble(building), case.U, case.dt, case.measured, burn_in_steps=case.burn_in_steps,
                         steady_start=True, substeps=case.substeps, history_steps=case.history_steps)
        assert np.array_equal(case.run(building), fresh)
    assert case.run(massive).shape[1] == case.run(cell).shape[1] + 1
    assert not np.array_equal(case.run(door), case.run(cell))
    assert len(pickle.dumps(case)) == size


def test_a_steady_start_begins_a_run_at_the_first_day_s_steady_state(testcell_data, weather):
    """Constant weather, no sun, and a 150 W gain in the test cell: with the steady start the
    run begins where the cell settles, the air at T_out + Q / HLC (the heat loss coefficient,
    `model.hlc`, an independent steady formulation); from 20 C and two days' warm-up instead,
    its 14.7-day floor still carries the start, kelvins away."""
    import copy
    from nodeforce.model.building_file import parse_building
    from nodeforce.model.hlc import heat_loss_coefficient
    data = copy.deepcopy(testcell_data)
    data["zones"][0]["internal_gain"] = 150.0
    building = parse_building(data)
    calm = weather.iloc[:24 * 4].copy()
    calm[["ghi", "dni", "dhi"]] = 0.0
    calm["T_out"] = 5.0
    calm["T_sky"] = 5.0
    air = f"T{building.zones[0].air_node}"
    expected = 5.0 + 150.0 / heat_loss_coefficient(building)
    steady = simulate_building(building, calm, steady_start=True)[air]
    assert steady.iloc[0] == pytest.approx(expected, abs=0.01)
    assert steady.iloc[-1] == pytest.approx(expected, abs=0.01)
    assert abs(simulate_building(building, calm)[air].iloc[0] - expected) > 1.0
