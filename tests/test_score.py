"""The score's pieces on their own: the noise estimate, the BIC, the objective over zones, the
initial state's interpolation in depth, and a window of a case."""
import math

import numpy as np
import pandas as pd
import pytest

from nodeforce.model.building_file import parse_building
from nodeforce.model.case import Case
from nodeforce.model.integrate import initial_state
from nodeforce.model.score import Noise, Objective, noise_level

from .test_zones import two_zones


def test_noise_level_recovers_white_noise_on_a_smooth_signal():
    t = np.arange(5000) * 600.0
    smooth = 20 + 3 * np.sin(2 * np.pi * t / 86400)
    noise = np.random.default_rng(0).normal(0, 0.2, len(t))
    assert noise_level(smooth + noise) == pytest.approx(0.2, rel=0.05)
    assert noise_level(smooth) < 0.01  # a smooth signal is (almost) no noise: its curvature only
    gappy = smooth + noise
    gappy[100:300] = np.nan  # gaps split the series; nothing is filled
    assert noise_level(gappy) == pytest.approx(0.2, rel=0.05)
    assert noise_level(np.full(8, 20.0)) is None  # too short to tell


def test_white_noise_is_seen_and_an_averaging_sensor_hides_it():
    t = np.arange(5000) * 600.0
    smooth = 20 + 3 * np.sin(2 * np.pi * t / 86400)
    rng = np.random.default_rng(1)
    white = Noise.of((smooth + rng.normal(0, 0.1, len(t)))[:, None])
    assert white.visible and white.sigma == pytest.approx(0.1, rel=0.05)
    assert white.lag1 == pytest.approx(-2 / 3, abs=0.03)  # the second differences of white noise
    # a precise sensor on a room whose air follows heater pulses through a 1 h lag: the signal's
    # curvature over a step outweighs the noise, which the estimate then only bounds from above
    pulses = np.where((t // 7200) % 3 == 0, 2.0, 0.0)
    air = np.empty_like(t)
    air[0] = 20.0
    for k in range(1, len(t)):
        air[k] = air[k - 1] + (20.0 + pulses[k] - air[k - 1]) * (1 - np.exp(-600.0 / 3600.0))
    hidden = Noise.of((air + rng.normal(0, 0.002, len(t)))[:, None])
    assert not hidden.visible and "not visible" in hidden.sentence() and hidden.sigma > 0.002
    given = Noise.of(air[:, None], given=0.1)
    assert given.visible and given.sigma == 0.1 and "as given" in given.sentence()


def test_the_twin_house_air_sensors_are_smooth_at_their_step():
    # 10-minute means of the living room's air: second differences dominated by the signal
    from .test_twinhouse import TABLE
    data = np.loadtxt(TABLE, comments="#", skiprows=2)
    noise = Noise.of(data[:, [5]])  # N2_living_AT_h125cm
    assert not noise.visible and noise.lag1 > -0.3


def test_objective_sums_zones_and_reports_each():
    b = parse_building(two_zones())
    objective = Objective.of(b, ["B", "A"])
    assert objective.air_nodes == (b.zone("B").air_node, b.zone("A").air_node)
    measured = np.array([[1.0, 2.0], [3.0, np.nan], [0.0, 1.0]])
    simulated = np.zeros((3, 2))
    m = objective.metrics(measured, simulated)
    assert m["J"] == pytest.approx(1 + 4 + 9 + 0 + 1) and m["n"] == 5
    assert m["zones"]["B"]["J"] == pytest.approx(10.0) and m["zones"]["A"]["n"] == 2
    assert objective.J(measured, simulated) == pytest.approx(15.0)
    assert Objective.of(b).zones == ("A",)  # the first zone by default
    with pytest.raises(Exception, match="names no zone"):
        Objective.of(b, ["attic"])


def test_initial_state_interpolates_in_depth_between_measured_nodes():
    data = two_zones()
    data["components"][0]["nodes"] = {"max_spacing": 0.025}  # wA: nodes at 0, 2.5, 5, 7.5, 10 cm
    b = parse_building(data)
    wall = np.array(b.component("wA").node_ids) - 1
    measured = np.full(b.n_nodes, np.nan)
    measured[wall[0]], measured[wall[-1]] = 22.0, 10.0
    measured[b.zone("A").air_node - 1] = 21.0
    T = initial_state(b, measured)
    assert T[wall] == pytest.approx([22.0, 19.0, 16.0, 13.0, 10.0])
    # only the inside measured: the nodes beyond take the nearest measured value
    measured[wall[-1]] = np.nan
    assert initial_state(b, measured)[wall] == pytest.approx([22.0] * 5)
    # nothing measured on a component: its zone's air; no air either: T_default
    wall_B = np.array(b.component("wB").node_ids) - 1
    assert initial_state(b, measured, T_default=17.0)[wall_B] == pytest.approx([17.0, 17.0])
    measured[b.zone("B").air_node - 1] = 19.5
    assert initial_state(b, measured)[wall_B] == pytest.approx([19.5, 19.5])


def test_a_window_of_a_case_keeps_its_rows_and_a_burn_in_at_its_start():
    times = pd.date_range("2013-08-27T00:00+01:00", periods=11, freq="1h")
    U = np.arange(22.0).reshape(11, 2)
    measured = np.arange(33.0).reshape(11, 3)
    case = Case(times, 3600.0, ("T_out", "T_sky"), U, measured).with_burn_in(2 / 24)
    head = case.window(0, 5)
    assert head.times.equals(times[:6]) and np.array_equal(head.U, U[:6]) and head.burn_in_steps == 2
    tail = case.window(4, 10)
    assert tail.times[0] == times[4] and np.array_equal(tail.measured, measured[4:]) and tail.burn_in_steps == 0
    # the burn-in is not scored
    scored = case.scored([1])
    assert np.isnan(scored[:2]).all() and np.array_equal(scored[2:, 0], measured[3:, 1])
