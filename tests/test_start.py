"""The start as an unknown (model/start.py, docs/model.md 5.10): the slow modes a short history
leaves unknown, their free response, and their amplitudes fitted with a fit's parameters by
variable projection, against a start put off by a known amount, the decay physics gives the
mode, the prior the weather's spread and a history's length say, and two nearly collinear
modes that must not trade a model's error between them."""
import json
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from nodeforce.diagnosis.calibrate import Candidate, calibrate
from nodeforce.model.case import measured_case
from nodeforce.model.network import Network, assemble, slowest_time_constant
from nodeforce.model.score import Objective
from nodeforce.model.start import FORGOTTEN, drive_spread, fitted_start, free_response, modes, slow_modes
from nodeforce.model.synth import pseudo_measurements

DAY = 86400.0
NOISE = 0.1  # C


def april(building, weather, days=8):
    """The test cell's air measured every 15 min from 1 April (no noise: the runs replace it)."""
    times = pd.date_range("2001-04-01", periods=days * 96 + 1, freq="15min", tz="-05:00", name="time")
    return pseudo_measurements(building, weather, times, [building.zones[0].air_node])


def one_node(capacity, conductance):
    """A node of `capacity` J/K on the outdoor air through `conductance` W/K: one mode of
    tau = capacity / conductance, its steady state the outdoor air itself."""
    return Network(C=np.array([capacity]), A=np.array([[-conductance]]), B=np.array([[conductance]]),
                   q=np.zeros(1), input_names=("T_out",))


def test_the_prior_of_one_node_is_the_spread_of_the_outdoor_air_s_daily_means_over_tau(weather):
    """One node on the outdoor air (tau 5 days): each day's mean air holds it at that air, so
    the prior sd of its start is the sd of the daily means of the outdoor air over the first 5
    days of the weather read, times exp(-history / tau) (by hand, from the weather's own
    column resampled by pandas); a history of three time constants leaves no mode to fit."""
    tau = 5.0 * DAY
    network = one_node(tau * 10.0, 10.0)
    (found,), shapes = modes(network)
    assert found == pytest.approx(tau, rel=1e-12) and shapes[0, 0] == 1.0
    air = weather["T_out"].loc["2001-02-01":"2001-02-20"]
    hourly = air.resample("1h").mean().iloc[:20 * 24]
    U = hourly.to_numpy()[:, None]
    by_hand = hourly.resample("1D").mean().iloc[:5].std(ddof=1)
    assert drive_spread(network, shapes, U, 3600.0, [tau])[0] == pytest.approx(by_hand, rel=1e-9)
    for days in (0.0, 3.0):
        prior = slow_modes(network, days * DAY, U, 3600.0)
        assert prior.sd[0] == pytest.approx(by_hand * np.exp(-days * DAY / tau), rel=1e-9)
    assert len(slow_modes(network, FORGOTTEN * tau * 1.001, U, 3600.0).tau) == 0


def test_the_test_cell_has_one_slow_mode_its_floor_s_whose_start_a_short_history_leaves_unknown(testcell, weather):
    """The test cell's modes slower than a day: one, the building's slowest time constant (14.7
    days, `network.slowest_time_constant`), its prior sd shrinking as exp(-history / tau) over
    the same weather; none once the history has run for three of them. Past the burn-in its
    free response at the air falls by exp(-day / tau) a day, the mode's own decay, its faster
    modes long gone."""
    network = assemble(testcell)
    tau = slowest_time_constant(network)
    air = testcell.zones[0].air_node
    case = measured_case(testcell, weather, april(testcell, weather), burn_in_days=1, history_days=3)
    for days in (0.0, 3.0, 14.0):
        found = slow_modes(network, days * DAY, case.U, case.dt)
        assert len(found.tau) == 1
        assert found.tau[0] == pytest.approx(tau, rel=1e-9)
        assert found.sd[0] == pytest.approx(slow_modes(network, 0.0, case.U, case.dt).sd[0]
                                            * np.exp(-days * DAY / tau), rel=1e-9)
        assert np.abs(found.shapes).max() == pytest.approx(1.0)
    assert len(slow_modes(network, FORGOTTEN * tau * 1.001, case.U, case.dt).tau) == 0
    assert len(slow_modes(network, FORGOTTEN * tau * 0.999, case.U, case.dt).tau) == 1

    F, _ = free_response(case, testcell, [air])
    per_day = int(DAY / case.dt)
    late = F[-1 - 2 * per_day:, 0, 0]
    assert late[-1] / late[-1 - per_day] == pytest.approx(np.exp(-1.0 / (tau / DAY)), rel=2e-3)


def test_two_nearly_collinear_modes_fit_one_direction_not_a_model_error_between_them():
    """The Twin House's two slow modes of 4.73 and 4.64 days, free responses correlated beyond
    0.999 over four days, and a residual that is no start at all (a model's error: a 0.5 K
    daily swing and a 0.3 K drift) with noise: fitted freely they take amplitudes of tens of
    kelvin and opposite signs; under `fitted_start` they are one direction, each amplitude
    within its prior's 2 sd, and equal to the one-column fit of that direction (an independent
    formulation: v the leading eigenvector of the scaled Gram matrix (F sd)'(F sd), f = F sd v,
    c = sd v (f'r) / (f'f + sigma^2))."""
    t = np.arange(1, 4 * 96 + 1) * 900.0
    F = np.exp(-t[:, None] / (np.array([4.73, 4.64]) * DAY))
    assert np.corrcoef(F.T)[0, 1] > 0.999
    error = 0.5 * np.sin(2 * np.pi * t / DAY) + 0.3 * t / t[-1]
    r = error + np.random.default_rng(0).normal(0.0, NOISE, len(t))
    free = np.linalg.lstsq(F, r, rcond=None)[0]
    assert np.abs(free).max() > 10.0 and free[0] * free[1] < 0  # what the start used to fit
    sd = np.array([1.5, 1.2])
    c, cov = fitted_start(F, r, sd, NOISE)
    assert np.all(np.abs(c) <= 2 * sd), c
    v = np.linalg.eigh((F * sd).T @ (F * sd))[1][:, -1]
    f = (F * sd) @ v
    assert c == pytest.approx(sd * v * (f @ r) / (f @ f + NOISE ** 2), rel=1e-9)
    assert np.all(np.sqrt(np.diag(cov)) <= sd + 1e-12)


@pytest.mark.parametrize("days", [3, 14])
def test_a_start_off_by_a_known_amount_along_the_slow_mode_is_fitted_within_two_sd(testcell, weather, days):
    """A test cell that started 2 K off along its slow mode (at the first measurement), its air
    measured with noise: fitted with an internal gain (truly 0), the start's amplitude comes back
    within 2 sd of 2 K, and the gain within 2 sd of 0. Nothing forced (no burn-in): the record is
    the same run as the model's, but for the start."""
    air = testcell.zones[0].air_node
    case = measured_case(testcell, weather, april(testcell, weather), burn_in_days=0,
                         history_days=days).with_steady_start()
    h = case.history_steps
    pattern = np.full_like(case.measured, np.nan)
    pattern[1 + h:, air - 1] = 0.0  # what is measured, where: the run reads no value of it
    case = replace(case, measured=pattern)
    slow = slow_modes(assemble(testcell), h * case.dt, case.U, case.dt)
    off = 2.0
    truth = case.run(testcell, [air - 1], start_offset=off * slow.shapes[:, 0] / slow.decay[0])[:, 0]
    measured = pattern.copy()
    measured[1 + h:, air - 1] = truth[h:] + np.random.default_rng(days).normal(0.0, NOISE, len(truth) - h)
    fitted, determined, _ = calibrate(Candidate(testcell, "internal_gain", "cell"), replace(case, measured=measured),
                                      Objective.of(testcell), sigma=NOISE, start=True)
    start, = [d for name, d in determined.items() if name.startswith("start_of_record_1")]
    assert abs(start["value"] - off) < 2 * start["std"] + 1e-3, start
    assert abs(fitted["Q"]["value"]) < 2 * fitted["Q"]["std"]
    assert determined["start_share_of_J"]["value"] > 0.5  # the start was most of what the file missed


def test_the_amplitude_s_posterior_sd_shrinks_with_the_history_and_stays_under_its_prior(testcell, weather):
    """The amplitude at the first measurement, on the same record read after 0, 3, 7 and 14
    days of history: its posterior sd (`fitted_start`) falls with the history, each under its
    prior's sd, and equals the hand formula sigma (F'F + sigma^2 / sd^2)^-1/2 of one mode."""
    air = testcell.zones[0].air_node
    measurements = april(testcell, weather)
    posterior = []
    for days in (0, 3, 7, 14):
        case = measured_case(testcell, weather, measurements, burn_in_days=1, history_days=days).with_steady_start()
        F, slow = free_response(case, testcell, [air])
        rows = F[case.burn_in_steps:, 0, :]
        c, cov = fitted_start(rows, np.zeros(len(rows)), slow.sd, NOISE)
        sd = float(np.sqrt(cov[0, 0]))
        assert sd < slow.sd[0]
        assert sd == pytest.approx(NOISE / np.sqrt(rows[:, 0] @ rows[:, 0] + (NOISE / slow.sd[0]) ** 2), rel=1e-10)
        assert c[0] == 0.0
        posterior.append(sd)
    assert np.all(np.diff(posterior) < 0), posterior


def test_the_start_is_fitted_without_the_block_a_fold_scores(testcell, weather):
    """A fold's left-out residual is scored with the start fitted on the other days: the first
    day left out, where the start shows most, the residual there is what the truth's start
    leaves once the rest of the window fixes it, far under the file's error there."""
    air = testcell.zones[0].air_node
    case = measured_case(testcell, weather, april(testcell, weather), burn_in_days=0,
                         history_days=3).with_steady_start()
    h = case.history_steps
    pattern = np.full_like(case.measured, np.nan)
    pattern[1 + h:, air - 1] = 0.0
    case = replace(case, measured=pattern)
    slow = slow_modes(assemble(testcell), h * case.dt, case.U, case.dt)
    truth = case.run(testcell, [air - 1], start_offset=2.0 * slow.shapes[:, 0] / slow.decay[0])[:, 0]
    measured = pattern.copy()
    measured[1 + h:, air - 1] = truth[h:] + np.random.default_rng(1).normal(0.0, NOISE, len(truth) - h)
    case = replace(case, measured=measured)
    first = np.zeros(len(case.times) - 1, dtype=bool)
    first[h:h + 96] = True
    _, _, (fold,) = calibrate(Candidate(testcell, "internal_gain", "cell"), case, Objective.of(testcell),
                              blocks=[first], sigma=NOISE, start=True)
    left = fold["residuals"][first, 0]
    file_error = (measured[1:, air - 1] - case.run(testcell, [air - 1])[:, 0])[first]
    assert np.sqrt(np.mean(left ** 2)) < 1.5 * NOISE < 0.5 * np.sqrt(np.mean(file_error ** 2))


@pytest.mark.slow  # a diagnosis: not in `make check`
def test_a_faultless_record_with_three_days_of_history_in_a_moving_season_adds_nothing(tmp_path):
    """The benchmark's test cell, its air alone measured (a PRBS heater) for 14 days from 10 March
    in Sandpoint, the truth with its real past, the weather read from 3 days before the record:
    under a policy that prefers the start (`Policy.prefer_start`), the first round chooses it, a
    candidate beside the effects, and nothing is added; the
    report's metrics are the file's runs as simulated (after equals before), and report.json
    states the floor's mode's start fitted to the model, within 2 sd of its prior (the weather's
    spread over the mode's 14.7 days, shrunk by the history), in the numbers its sentence says.
    With the start assumed, the loop added a heat input factor to this record."""
    from benchmarks.catalogue import Spec
    from benchmarks.records import record
    from nodeforce import api
    from nodeforce.diagnosis.policy import Policy
    spec = Spec(name="sdp-mar-air-h3/none", building="testcell", climate="sandpoint", start="03-10", days=14,
                step_min=30, noise=0.15, sensors="air", before=3)
    r = record(spec, 0)
    diagnosis = api.diagnose(r.building, r.case(), tmp_path, objective=api.objective(r.building, r.zones),
                             search=api.SearchSettings(generations=30, noise=r.spec.noise, seed=0),
                             execution=api.Execution(workers=1), policy=Policy(prefer_start=True))
    assert not diagnosis.added and diagnosis.rounds[0].starts, diagnosis.rounds[0].reason
    assert diagnosis.after["validation"]["rmse"] == diagnosis.before["validation"]["rmse"]
    written = json.loads((tmp_path / "report.json").read_text())
    (found,) = written["start"]["records"]
    (tau,), (amplitude,), (sd,), (prior,) = found["tau_days"], found["amplitude"], found["sd"], found["prior_sd"]
    assert tau == pytest.approx(14.7, abs=0.05) and abs(amplitude) < 2 * prior and sd < prior
    said, = [a for a in written["assumptions"] if a.startswith("Round 1 chose the start")]
    assert f"{amplitude:+.3g} +- {sd:.2g} K (prior sd {prior:.2g} K)" in said
    assert f"{found['share_of_J']:.0%} of the window's J" in said
