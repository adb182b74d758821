"""A record's start from the weather before it (the history, docs/model.md 5.6): how far back the
case reaches, that it invents nothing where an input is missing, that an hour's step over it
follows what a fine step follows, that the FMUs give the direct model's numbers, and that a
building with a real past is reproduced from its history where a steady start misses it."""
import numpy as np
import pandas as pd
import pytest

from nodeforce.cosim.fmi import FmuInstance
from nodeforce.cosim.run import simulate_fmu
from nodeforce.fmu_build.build import build_fmu
from nodeforce.model.case import HISTORY_DAYS, measured_case
from nodeforce.model.effects import EFFECTS
from nodeforce.model.integrate import HISTORY_STEP, simulate
from nodeforce.model.network import assemble
from nodeforce.model.synth import pseudo_measurements
from tests.conftest import record_times

AIR = 23
JUNE = "2001-06-10 00:00"


def air_record(building, weather, days=4, past=0.0, start=JUNE):
    """The test cell's air alone, measured every 15 min over `days` (no noise), the building
    having lived through `past` days of the weather before (0: in the periodic regime of its
    first day)."""
    return pseudo_measurements(building, weather, record_times(days, start), [AIR], history_days=past)


def cut(weather, start):
    out = weather[weather.index >= start]
    out.attrs = dict(weather.attrs)
    return out


def test_the_case_reaches_back_over_the_weather_before_the_first_measurement(testcell, weather):
    measured = air_record(testcell, weather)
    case = measured_case(testcell, weather, measured, burn_in_days=1)
    h = case.history_steps
    assert h * case.dt == HISTORY_DAYS * 86400  # the bundled weather holds a year
    assert case.start == measured.index[0] == case.times[0] + pd.Timedelta(days=HISTORY_DAYS)
    assert np.isnan(case.measured[:h, AIR - 1]).all() and np.isfinite(case.measured[h:, AIR - 1]).all()
    assert case.burn_in_steps == h + 96  # the burn-in's day follows the history
    assert case.steady_start  # nothing measured sets the history's first state
    # the steps scored are the record's after its burn-in, as without a history
    alone = measured_case(testcell, weather, measured, burn_in_days=1, history_days=0)
    assert alone.history_steps == 0 and alone.times[0] == measured.index[0]
    assert np.array_equal(np.isfinite(case.scored([AIR - 1]))[h:], np.isfinite(alone.scored([AIR - 1])))
    # a weather that starts 61.75 h before the record gives what it has, in whole history steps
    short = cut(weather, measured.index[0] - pd.Timedelta(hours=61.75))
    assert measured_case(testcell, short, measured).history_steps * case.dt == HISTORY_STEP * (61.75 * 3600 // HISTORY_STEP)


def test_the_case_says_how_much_of_its_start_the_record_still_carries(testcell, weather):
    """The share of the start's error left at the first measurement falls with the history as
    exp(-days / tau), tau the test cell's slowest mode (some two weeks: the floor above its
    adiabatic face); without a history the steady start's sentence gives tau alone."""
    import re
    measured = air_record(testcell, weather)
    said = {}
    for days in (5, 60):
        case = measured_case(testcell, cut(weather, measured.index[0] - pd.Timedelta(days=days)), measured)
        said[days] = float(re.search(r"(\d+)% of it is left at the first measurement", case.assumptions[-1]).group(1))
    tau = 5.0 / -np.log(said[5] / 100)
    assert 10.0 < tau < 20.0  # days
    assert said[60] == pytest.approx(100 * np.exp(-60.0 / tau), abs=1.0) and said[60] < 5 < 50 < said[5]
    steady = measured_case(testcell, weather, measured, history_days=0).with_steady_start()
    assert re.search(r"falls by a factor e in 1\d\.?\d* days", steady.assumptions[-1])


def test_the_history_stops_where_an_input_is_missing_and_nothing_is_filled_in(testcell, weather):
    measured = air_record(testcell, weather)
    holed = weather.copy()
    gap = measured.index[0] - pd.Timedelta(hours=30)
    holed.loc[abs(holed.index - gap) < pd.Timedelta(hours=3), "T_out"] = np.nan
    holed.attrs = dict(weather.attrs)
    case = measured_case(testcell, holed, measured)
    # it begins after the gap, a whole number of history steps before the record, every input a number
    assert gap < case.times[0] and case.history_steps * case.dt <= 30 * 3600
    assert (case.history_steps * case.dt) % HISTORY_STEP == 0
    assert np.isfinite(case.U).all()


def test_hours_steps_over_the_history_follow_the_records_step(testcell, weather):
    """The history in steps of hours against the same rows at the record's 5-min sub-steps: the
    air over the record, past its first six hours, within 0.02 C."""
    measured = air_record(testcell, weather, past=30)
    case = measured_case(testcell, weather, measured, history_days=30)
    h = case.history_steps
    coarse = case.run(testcell)
    fine = simulate(testcell, assemble(testcell), case.U, case.dt, case.measured, warmup_days=0,
                    burn_in_steps=case.burn_in_steps, steady_start=True, substeps=case.substeps)
    assert np.abs(coarse[h + 24:, AIR - 1] - fine[h + 24:, AIR - 1]).max() < 0.02
    # the two are not idle: the history moved the air by kelvins
    assert np.ptp(fine[:h, AIR - 1]) > 3.0


@pytest.mark.parametrize("kind", ["python", "standalone"])
def test_the_fmu_runs_the_history_as_the_direct_model_does(testcell, weather, kind, tmp_path):
    coupled = EFFECTS["ground_coupling"].apply(testcell, "floor", {"U": 1.0, "T_ground": 22.0})
    measured = pseudo_measurements(coupled, weather, record_times(3), [1, 9, AIR])
    case = measured_case(testcell, cut(weather, measured.index[0] - pd.Timedelta(days=5, minutes=30)), measured,
                         burn_in_days=1)
    assert case.history_steps * case.dt == 5 * 86400
    direct = case.run(testcell)
    force = np.zeros(testcell.n_nodes, dtype=bool)
    force[8] = True  # node 9 forced after the burn-in, as a search does
    forced = simulate(testcell, assemble(testcell), case.U, case.dt, case.measured, force, burn_in_steps=case.burn_in_steps,
                      steady_start=True, substeps=case.substeps, history_steps=case.history_steps)
    with FmuInstance(build_fmu(testcell, tmp_path / "cell.fmu", kind=kind)) as fmu:
        assert np.abs(simulate_fmu(fmu, case) - direct).max() < 1e-9
        assert np.abs(simulate_fmu(fmu, case, force) - forced).max() < 1e-9


def test_a_building_with_a_past_is_reproduced_from_its_history(testcell, weather):
    """The test cell after 90 days of real weather, its air alone measured: started from its
    first day's steady state, the file misses its own building by a tenth of a kelvin (a heavy,
    unmeasured floor carries the past); from 60 days of history, by the hourly steps' hundredth."""
    measured = air_record(testcell, weather, past=90)

    def rmse(case):
        T = case.run(testcell)[case.history_steps:]
        r = (measured[f"T{AIR}"].to_numpy()[1:] - T[:, AIR - 1])[96:]
        return float(np.sqrt(np.mean(r ** 2)))
    steady = measured_case(testcell, weather, measured, burn_in_days=1, history_days=0).with_steady_start()
    past = measured_case(testcell, weather, measured, burn_in_days=1, history_days=60)
    assert rmse(past) < 0.02 < 0.05 < rmse(steady)
