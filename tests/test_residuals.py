"""Residual diagnostics on synthetic series whose answer is known by construction."""
import json

import numpy as np
import pandas as pd
import pytest
from scipy.signal import lfilter

from nodeforce.diagnosis.residuals import diagnostics, lag_text, longest_run

STEP_HOURS = 0.25


def weather(seed, days=7):
    """Weather-like inputs at 15 min: an outdoor temperature (daily cycle and a slow random
    drift), two irradiances sharing their clouds, and a heater switched on and off."""
    times = pd.date_range("2013-09-01", periods=days * 96, freq="15min", tz="+01:00")
    rng = np.random.default_rng(seed)
    tau = (times.hour + times.minute / 60).to_numpy(float)

    def ar1(phi, sd):
        return lfilter([1.0], [1.0, -phi], rng.normal(0, sd * np.sqrt(1 - phi ** 2), len(times)))

    clouds = np.clip(0.7 + ar1(0.97, 0.3), 0.05, 1)
    inputs = {"T_out": 14 + 5 * np.sin(2 * np.pi * (tau - 9) / 24) + ar1(0.99, 1.5),
              "I_S": 700 * np.clip(np.sin(np.pi * (tau - 6) / 12), 0, None) * clouds,
              "I_W": 500 * np.clip(np.sin(np.pi * (tau - 11) / 8), 0, None) * clouds,
              "Q": 500.0 * (ar1(0.98, 1) > 0.3)}
    return times, tau, inputs, rng, ar1


def test_white_noise_is_white_and_follows_nothing():
    times, _, inputs, rng, _ = weather(0)
    d = diagnostics(times, rng.normal(0, 0.1, len(times)), inputs)
    assert d["white"] and d["ljung_box"]["p_value"] > 0.05
    assert d["follows"] == [] and not d["time_of_day"]["significant"]
    assert d["sentence"].startswith("No structure")
    assert d["n"] == len(times) and d["ljung_box"]["lag_hours"] == 24
    assert abs(d["acf"][0] - 1) < 1e-12 and max(abs(v) for v in d["acf"][1:]) < 3 * d["acf_bound"]
    assert json.loads(json.dumps(d)) == d  # report.json holds it as it is


def test_a_lagged_input_is_named_with_its_lag():
    times, _, inputs, rng, _ = weather(1)
    k = int(2 / STEP_HOURS)
    residual = np.full(len(times), np.nan)
    residual[k:] = 0.001 * inputs["I_S"][:-k]
    residual += rng.normal(0, 0.1, len(times))
    d = diagnostics(times, residual, inputs)
    assert not d["white"]
    assert d["follows"][0]["input"] == "I_S" and d["follows"][0]["lag_hours"] == 2.0
    assert d["follows"][0]["correlation"] > 0
    # the daily profile of the residual is the irradiance's: none is left for the clock
    assert not d["time_of_day"]["significant"] and d["time_of_day"]["beyond_inputs"][0] == "I_S"
    assert "follows I_S, 2 h later" in d["sentence"]
    # the first k steps have no residual: the run starts after them, nothing is filled in
    assert d["n"] == len(times) - k and d["run"]["start"] == times[k].isoformat()


def test_a_response_spread_over_hours_is_found():
    """A first-order response (1 h time constant) to the heater's switching. (The test is on the
    strongest lag: a response spread thinner over many lags, each below the bound, is missed.)"""
    times, _, inputs, rng, _ = weather(2)
    a = np.exp(-STEP_HOURS / 1)
    residual = 0.002 * lfilter([1 - a], [1, -a], inputs["Q"]) + rng.normal(0, 0.1, len(times))
    d = diagnostics(times, residual, inputs)
    assert d["follows"][0]["input"] == "Q" and d["follows"][0]["lag_hours"] <= 1
    assert d["sentence"].startswith("The residual follows Q")


def test_a_daily_profile_is_the_time_of_day():
    times, tau, inputs, _, ar1 = weather(3)
    bump = 0.3 * np.exp(-0.5 * ((tau - 14) / 2) ** 2)
    d = diagnostics(times, bump + ar1(0.9, 0.05), inputs)
    daily = d["time_of_day"]
    assert daily["significant"] and abs(daily["peak_hour"] - 14) <= 0.5
    # the bump as three harmonics of the day resolve it: least squares without noise
    harmonics = np.column_stack([np.ones(len(tau))] + [f(2 * np.pi * h * tau / 24) for h in (1, 2, 3)
                                                       for f in (np.cos, np.sin)])
    resolved = harmonics @ np.linalg.lstsq(harmonics, bump, rcond=None)[0]
    assert daily["amplitude"] == pytest.approx((resolved.max() - resolved.min()) / 2, abs=0.03)
    assert d["follows"] == []
    assert d["sentence"].startswith("The residual follows the time of day") 
    assert f"highest at {int(daily['peak_hour']):02d}:" in d["sentence"]


def test_a_profile_of_the_working_days_alone_is_told_from_the_time_of_day():
    """An office's gain: a bump on Monday to Friday only (1 September 2013 is a Sunday), beside
    the same bump every day, which is the time of day's and not the working days'."""
    times, tau, inputs, _, ar1 = weather(4, days=14)
    working = np.isin(times.day_of_week, [0, 1, 2, 3, 4])
    bump = 0.3 * np.exp(-0.5 * ((tau - 14) / 2) ** 2)
    d = diagnostics(times, working * bump + ar1(0.9, 0.05), inputs)
    weekly = d["working_days"]
    assert weekly["significant"] and (weekly["working_days"], weekly["rest_days"]) == (10.0, 4.0)
    # its mean on a working day beyond a rest day's: the bump's daily mean, 0.3 x 2 sqrt(2 pi) / 24 K
    assert weekly["excess"] == pytest.approx(0.3 * 2 * np.sqrt(2 * np.pi) / 24, abs=0.02)
    assert "differs on the working days" in d["sentence"]
    every = diagnostics(times, bump + ar1(0.9, 0.05), inputs)
    assert every["time_of_day"]["significant"] and not every["working_days"]["significant"]
    assert "working days" not in every["sentence"]
    # Monday to Friday alone hold no rest day to tell them from: no test
    days = slice(96, 96 * 6)
    alone = diagnostics(times[days], (working * bump + ar1(0.9, 0.05))[days], {k: v[days] for k, v in inputs.items()})
    assert alone["working_days"] is None and alone["time_of_day"]["significant"]


@pytest.mark.parametrize("kind", ["white", "autocorrelated"])
def test_unrelated_residuals_name_no_input_nor_clock_beyond_the_level(kind):
    """Over 20 week-long records, a residual independent of the inputs (white, or a slow AR(1)
    that correlates with any slow input by chance) names an input or the clock, and the working
    days apart, at most as often as the level allows (alpha 5 % in all: 4 of 20 or more has
    probability < 2 %)."""
    false = weekly = 0
    for seed in range(20):
        times, _, inputs, rng, ar1 = weather(100 + seed)
        residual = rng.normal(0, 0.1, len(times)) if kind == "white" else ar1(0.97, 0.3)
        d = diagnostics(times, residual, inputs)
        false += bool(d["follows"]) or d["time_of_day"]["significant"]
        weekly += d["working_days"]["significant"]  # level 2.5 %: 4 of 20 or more has probability < 1 %
        if kind == "autocorrelated":
            assert not d["white"]
    assert false <= 3 and weekly <= 3


def test_gaps_are_not_filled_the_longest_run_is_used():
    times, _, inputs, rng, _ = weather(4)
    residual = rng.normal(0, 0.1, len(times))
    residual[100] = np.nan
    inputs["T_out"][400] = np.nan
    d = diagnostics(times, residual, inputs)
    assert longest_run(np.isfinite(residual) & np.isfinite(inputs["T_out"])) == (101, 400)
    assert d["n"] == 299 and d["run"]["n_finite"] == len(times) - 1
    assert d["run"]["start"] == times[101].isoformat() and d["run"]["end"] == times[399].isoformat()


def test_constant_inputs_are_reported_not_tested_and_short_runs_say_so():
    times, _, inputs, rng, _ = weather(5)
    inputs["T_ground"] = np.full(len(times), 10.0)
    d = diagnostics(times, rng.normal(0, 0.1, len(times)), inputs)
    assert d["skipped"] == {"T_ground": "constant over the run"}
    short = diagnostics(times[:30], rng.normal(0, 0.1, 30), {k: v[:30] for k, v in inputs.items()})
    assert short["white"] is None and short["sentence"].startswith("Too few")
    with pytest.raises(ValueError):
        diagnostics(times[[0, 1, 3]], np.zeros(3), {})


def test_lag_text():
    assert lag_text(0) == "at the same time"
    assert lag_text(2) == "2 h later" and lag_text(1.5) == "1 h 30 min later" and lag_text(1 / 6) == "10 min later"
