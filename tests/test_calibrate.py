"""The cross-validation folds of a calibration (`diagnosis.calibrate.fold`): a fold is the fit
without one day, one Gauss-Newton step from the whole window's optimum; checked against fits
made afresh by scipy on the days it keeps; a fit that weighs a parameter's prior (the maximum a
posteriori fit) against a hand calculation and the fit without it; and a candidate on the inputs
alone, superposed, against its model simulated afresh."""
import copy
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest
from scipy.optimize import least_squares

from nodeforce.diagnosis.calibrate import (Candidate, Own, Penalised, Residuals, Superposition, calibrate, derived,
                                          fold, own_weights, solve, superposition_points, with_priors, within_ranges)
from nodeforce.diagnosis.policy import Policy
from nodeforce.diagnosis.selection import blocks
from nodeforce.model.building_file import parse_building
from nodeforce.model.case import measured_case, prepare_case
from nodeforce.model.effects import EFFECTS, Prior
from nodeforce.model.hlc import heat_loss_coefficient
from nodeforce.model.significance import parameter_covariance
from nodeforce.model.numerical import discretisation_error, reference_case
from nodeforce.model.score import Objective
from nodeforce.model.synth import pseudo_measurements
from tests.conftest import SENSORS, record_times

DAYS, PER_DAY = 4, 100


def fitted(residuals, x0, lows, highs):
    return least_squares(residuals, x0, bounds=(lows, highs), x_scale="jac", method="trf")


def test_a_fold_of_a_model_linear_in_its_parameters_is_the_fit_without_the_day():
    rng = np.random.default_rng(0)
    t = np.arange(DAYS * PER_DAY) / PER_DAY
    y = 2.0 + 0.5 * np.sin(2 * np.pi * t) + rng.normal(0.0, 0.1, t.size)

    def residuals(x):
        return y - (x[0] + x[1] * np.sin(2 * np.pi * t))
    lows, highs = np.array([-10.0, -10.0]), np.array([10.0, 10.0])
    fit = fitted(residuals, [0.0, 0.0], lows, highs)
    for day in range(DAYS):
        train = (t // 1).astype(int) != day
        alone = fitted(lambda x: residuals(x)[train], fit.x, lows, highs)
        np.testing.assert_allclose(fold(fit, train, lows, highs, residuals), alone.x, atol=1e-6)


def test_a_fold_along_a_valley_never_fits_its_own_days_worse_than_the_whole_window_s_optimum():
    # a ground coupling's heat flow, U (T_ground - T_face), with a face whose temperature hardly
    # moves: U and T_ground trade off along a curved valley, where the linearised step overshoots
    rng = np.random.default_rng(0)
    t = np.linspace(0.0, DAYS * 2 * np.pi, DAYS * PER_DAY)
    face = 20.0 + 0.02 * np.sin(t)
    y = 3.0 * (24.0 - face) + rng.normal(0.0, 0.5, t.size) + 0.8 * (t > (DAYS - 1) * 2 * np.pi)

    def residuals(x):
        return y - x[0] * (x[1] - face)
    lows, highs = np.array([0.0, -10.0]), np.array([20.0, 40.0])
    fit = fitted(residuals, [1.0, 20.0], lows, highs)
    overshoots = 0
    for day in range(DAYS):
        train = (t // (2 * np.pi)).astype(int) != day
        J = lambda x: float(np.sum(np.square(residuals(x)[train])))  # noqa: E731
        step = np.linalg.lstsq(fit.jac[train], -fit.fun[train], rcond=None)[0]
        overshoots += J(fit.x + step) > J(fit.x)
        x = fold(fit, train, lows, highs, residuals)
        assert J(x) <= J(fit.x) and np.all((lows <= x) & (x <= highs))
    assert overshoots >= 2  # the plain step would have scored those days with no fit at all


def test_a_component_s_loss_is_what_its_layers_add_to_the_heat_loss_coefficient(testcell):
    """The door's loss at a conductivity factor, as `derived` reports it, against the heat loss
    coefficient computed apart: the HLC less that of the door with its layers at the factor's
    lower bound; it saturates behind the surface coefficients; its sd is the slope times the
    factor's sd (a central difference, apart from the forward one `derived` takes)."""
    door = Candidate(testcell, "conductivity", "door")

    def hlc(factor):
        return heat_loss_coefficient(EFFECTS["conductivity"].apply(testcell, "door", {"factor": factor}))

    def loss(factor, sd=0.0):
        return derived(door, None, np.array([factor]), np.array([[sd ** 2]]))["component_loss"]

    assert loss(3.0)["value"] == pytest.approx(hlc(3.0) - hlc(0.05), rel=1e-9)
    assert loss(3.0)["value"] > loss(1.0)["value"] > 0.0
    # doubling the layers' conductance at ten times adds less than a third of what it adds at once
    assert loss(20.0)["value"] - loss(10.0)["value"] < (loss(2.0)["value"] - loss(1.0)["value"]) / 3
    slope = (hlc(7.2) - hlc(7.0)) / 0.2
    # the factor's sd, 2.4, combined with its range's as a uniform distribution (`within_ranges`)
    (low, high), = door.bounds
    sd = (1 / 2.4 ** 2 + 12 / (high - low) ** 2) ** -0.5
    assert loss(7.1, sd=2.4)["std"] == pytest.approx(abs(slope) * sd, rel=1e-3)
    # an adiabatic floor loses nothing whatever its layers conduct
    assert derived(Candidate(testcell, "conductivity", "floor"), None, np.array([3.0]),
                   np.array([[1.0]]))["component_loss"]["value"] == pytest.approx(0.0, abs=1e-9)


def test_a_ground_flux_s_spread_moves_the_face_with_the_parameters(testcell, weather):
    """Where U is large beside the floor's own conductance, the floor's underside follows
    T_ground, and the flux q = U (T_ground - T_face) hardly moves with T_ground. Its sd, as
    `derived` reports it, is the gradient's with the face simulated again (central differences
    here, apart from the forward ones `derived` takes), not the (T_ground - T_face, U) that holds
    the face still, which reads it several times larger."""
    case = measured_case(testcell, weather, pseudo_measurements(testcell, weather, record_times(3), SENSORS),
                         burn_in_days=1)
    coupled = Candidate(testcell, "ground_coupling", "floor")
    face = testcell.component("floor").node_ids[-1]

    def flux(x):
        return x[0] * (x[1] - float(np.mean(coupled.nodes(case, [face], x))))

    x, cov, h = np.array([8.0, 10.0]), np.diag([2.4, 0.5]) ** 2, 1e-3
    g = np.array([(flux(x + step) - flux(x - step)) / (2 * h) for step in h * np.eye(2)])
    within = within_ranges(cov, coupled.bounds)
    reported = derived(coupled, case, x, cov)["ground_heat_flux"]
    assert reported["value"] == pytest.approx(flux(x), rel=1e-9)
    assert reported["std"] == pytest.approx(np.sqrt(g @ within @ g), rel=1e-3)
    held = np.array([x[1] - float(np.mean(coupled.nodes(case, [face], x))), x[0]])
    assert 0.0 < g[1] < 0.5 * x[0]  # the face follows T_ground: far less than U per kelvin
    assert np.sqrt(held @ within @ held) > 3 * reported["std"]


def test_a_flux_the_data_fix_keeps_its_spread_where_the_valley_along_it_is_unbounded():
    """A ground coupling whose data fix only the flux q = U (T_ground - T_face): its information is
    g g' / sigma_q^2, g = (T_ground - T_face, U), singular along the valley. Combined with the
    ranges' uniform precision P (`within_ranges`), the flux's variance is, by Sherman-Morrison,
    sigma_q^2 a / (sigma_q^2 + a) with a = g' P^-1 g: at most sigma_q^2, whatever the valley; the
    linearised covariance alone, read by a gradient off the valley by 1e-3, gives tens of sigma_q."""
    bounds = [(0.0, 20.0), (-10.0, 40.0)]
    U, T_ground, T_face, sigma_q = 0.13, 4.2, 25.0, 0.15
    g = np.array([T_ground - T_face, U])
    across, along = g / np.linalg.norm(g), np.array([U, T_face - T_ground]) / np.linalg.norm(g)
    # the data alone: sigma_q across the valley, 1e4 along it (as the linearised fit gave there)
    cov = (sigma_q / np.linalg.norm(g)) ** 2 * np.outer(across, across) + 1e8 * np.outer(along, along)
    a = g @ np.diag([w ** 2 / 12.0 for w in (20.0, 50.0)]) @ g
    assert g @ within_ranges(cov, bounds) @ g == pytest.approx(sigma_q ** 2 * a / (sigma_q ** 2 + a), rel=1e-5)
    off = g + np.array([0.0, 1e-3])
    assert np.sqrt(off @ cov @ off) > 30 * sigma_q
    assert np.sqrt(off @ within_ranges(cov, bounds) @ off) < 1.01 * sigma_q
    # a covariance the data fix well: the sum of precisions, inverted directly, and barely changed
    tight = np.array([[0.01, 0.002], [0.002, 0.04]])
    combined = within_ranges(tight, bounds)
    assert combined == pytest.approx(
        np.linalg.inv(np.linalg.inv(tight) + np.diag([12 / 20.0 ** 2, 12 / 50.0 ** 2])), rel=1e-9)
    assert combined == pytest.approx(tight, rel=2e-3)


def test_a_fit_that_carries_the_files_numerical_error_finds_the_walls_of_the_file_and_of_the_continuum(testcell, weather):
    """The air of the test cell as its own network makes it, and as the continuum it discretises
    makes it (the file refined, `model.numerical.reference_case`), the west wall as declared
    (factor 1) and 1.5 times as conductive. Fitted alone, the wall's factor bends onto the
    continuum's difference from the file; carrying that difference as a share in [0, 1]
    (`numerical`), the fit finds the continuum's wall as it finds the network's, and each day
    left out is predicted to the rounding."""
    air = testcell.zones[0].air_node
    case = measured_case(testcell, weather, pseudo_measurements(testcell, weather, record_times(6), [air]),
                         burn_in_days=1)
    B = case.burn_in_steps
    error = discretisation_error(case, testcell, [air])
    days = blocks(len(case.times) - 1, B, case.dt, Policy())

    def fitted(T, numerical):
        measured = case.measured.copy()
        measured[1 + B:, air - 1] = T[B:, air - 1]  # the burn-in forces the air as both runs had it
        found, _, folds = calibrate(Candidate(testcell, "conductivity", "west_wall"), replace(case, measured=measured),
                                    Objective.of(testcell), days, numerical)
        return found["factor"]["value"], max(np.nanmax(np.abs(f["residuals"])) for f in folds)

    for factor in (1.0, 1.5):
        wall = EFFECTS["conductivity"].apply(testcell, "west_wall", {"factor": factor})
        network = case.with_inputs(wall).run(wall)
        fine, on_fine = reference_case(case, wall)
        continuum = on_fine.run(fine)
        for numerical in (None, [error]):
            found, left = fitted(network, numerical)
            assert found == pytest.approx(factor, abs=1e-4) and left < 1e-4
        found, _ = fitted(continuum, [error])
        # the error carried is the declared file's; the faulty wall's own differs a little
        assert found == pytest.approx(factor, abs=0.03 * factor)
    fine, on_fine = reference_case(case, testcell)
    continuum = on_fine.run(fine)
    found_alone, left_alone = fitted(continuum, None)
    found, left = fitted(continuum, [error])
    assert abs(found_alone - 1.0) > 3e-3 and found == pytest.approx(1.0, abs=1e-4)
    assert left < 1e-4 < left_alone


def residuals_of(r, slopes):
    """`Residuals` of a model whose residual at x is r(x), its Jacobian `slopes(x)`, no numerical
    error, every row weighing 1."""
    n = len(r(np.zeros(2)))
    return Residuals(r, slopes, np.zeros(n), np.ones(n))


def test_the_map_value_of_a_quadratic_J_is_the_precision_weighted_mean_of_the_data_and_the_prior():
    """One parameter p, y_t = p + noise of sd sigma on n steps: J (C2) is quadratic in p, the data's
    estimate the mean of y with variance sigma^2 / n. With a Gaussian prior (v, sd), the posterior's
    mode is the precision-weighted mean (mean(y) n / sigma^2 + v / sd^2) / (n / sigma^2 + 1 / sd^2),
    and its variance 1 / (n / sigma^2 + 1 / sd^2): the penalty is in J's units only if it is sigma^2
    ((p - v) / sd)^2. A second parameter the data do not see at all keeps its prior's value and
    sd."""
    rng = np.random.default_rng(3)
    n, sigma = 50, 0.3
    y = 21.0 + rng.normal(0.0, sigma, n)
    priors = {0: Prior(20.0, 0.05, "a hand prior"), 1: Prior(5.0, 2.0, "a prior of nothing the data see")}
    residuals = Penalised(residuals_of(lambda x: y - x[0], lambda x: np.column_stack([-np.ones(n), np.zeros(n)])),
                          priors, sigma)
    fit = solve(residuals, np.array([0.0, 0.0]), np.array([-50.0, -50.0]), np.array([50.0, 50.0]))
    data_precision, prior_precision = n / sigma ** 2, 1.0 / 0.05 ** 2
    expected = (y.mean() * data_precision + 20.0 * prior_precision) / (data_precision + prior_precision)
    assert fit.x[0] == pytest.approx(expected, abs=1e-6)
    assert fit.x[1] == pytest.approx(5.0, abs=1e-6)
    # the data's covariance, white noise of sd sigma: sigma^2 / n for p, nothing for the other
    posterior = with_priors(np.diag([sigma ** 2 / n, 0.0]), priors)
    assert posterior[0, 0] == pytest.approx(1.0 / (data_precision + prior_precision), rel=1e-9)
    assert posterior[1, 1] == pytest.approx(2.0 ** 2, rel=1e-9)


def test_the_posterior_covariance_is_the_inverse_of_the_data_precision_with_the_priors_added():
    """(cov^-1 + P)^-1 computed directly on a covariance of two correlated parameters and a third
    held (variance 0, no prior, kept at 0); no prior leaves the covariance as it is, to the bit."""
    cov = np.array([[4.0, 3.9, 0.0], [3.9, 4.0, 0.0], [0.0, 0.0, 0.0]])
    posterior = with_priors(cov, {1: Prior(0.0, 0.5, "")})
    direct = np.linalg.inv(np.linalg.inv(cov[:2, :2]) + np.diag([0.0, 1.0 / 0.5 ** 2]))
    assert np.allclose(posterior[:2, :2], direct, rtol=1e-9, atol=1e-12)
    assert posterior[2, 2] == 0.0
    assert with_priors(cov, {}) is cov


def test_where_the_data_fix_the_ground_the_map_fit_is_the_free_fit_to_within_its_spread():
    """A flux U (T - face(t)) whose face swings 5 K either side of 20 C over the record, so that
    the data fix U and T apart (T_ground to some 0.1 K): a prior 5 K off with sd 5 K moves the fit
    by less than the free fit's sd, and J by less than the noise can (sigma^2 sqrt(2 n))."""
    rng = np.random.default_rng(11)
    n, sigma = 400, 0.1
    t = np.linspace(0.0, 1.0, n)
    face = 20.0 + 5.0 * np.sin(2 * np.pi * 3 * t)
    y = 2.0 * (12.0 - face) + rng.normal(0.0, sigma, n)
    base = residuals_of(lambda x: y - x[0] * (x[1] - face),
                        lambda x: -np.column_stack([x[1] - face, np.full(n, x[0])]))
    lows, highs = np.array([0.0, -10.0]), np.array([20.0, 40.0])
    free = solve(base, np.array([1.0, 20.0]), lows, highs)
    cov = parameter_covariance(free.jac, free.fun, np.arange(n), 0)
    prior = Prior(17.0, 5.0, "5 K off")
    map_fit = solve(Penalised(base, {1: prior}, sigma), free.x, lows, highs)
    assert abs(free.x[1] - 12.0) < 3 * np.sqrt(cov[1, 1]) < 0.5  # the data fix T
    assert np.all(np.abs(map_fit.x - free.x) < np.sqrt(np.diag(cov)))
    J_free, J_map = np.sum(free.fun ** 2), np.sum(map_fit.fun[:n] ** 2)
    assert J_map - J_free < sigma ** 2 * np.sqrt(2 * n)



def test_a_component_s_own_surface_read_beside_the_air_moves_its_value_to_the_truth_where_another_fault_shares_the_air(
        testcell, weather):
    """A door 1.5 times as conductive and a window that lets in a tenth less sun, the air and the
    door's inside surface measured: the door's conductivity fitted to the air alone takes the
    window's error for the door's; read beside its own surface, it lands at least three times
    nearer the truth (the surface follows the air the window warms, so not on it). The surface
    weighs the noise's square over its mean square misfit at the air-alone fit: 1.5 C off, it
    weighs at most a hundredth, and pulls the fit less than the true surface does."""
    air, door = testcell.zones[0].air_node, testcell.component("door").node_ids[0]
    case = measured_case(testcell, weather, pseudo_measurements(testcell, weather, record_times(6), [air, door]),
                         burn_in_days=1)
    B = case.burn_in_steps
    truth = EFFECTS["conductivity"].apply(testcell, "door", {"factor": 1.5})
    truth = EFFECTS["solar_transmittance"].apply(truth, "window",
                                                 {"tau": 0.9 * testcell.component("window").solar_transmittance})
    T = case.with_inputs(truth).run(truth)
    measured = case.measured.copy()
    measured[1 + B:, [air - 1, door - 1]] = T[B:, [air - 1, door - 1]]
    objective = Objective.of(testcell)
    candidate = Candidate(testcell, "conductivity", "door")

    def with_offset(surface_offset):
        m = measured.copy()
        m[1 + B:, door - 1] += surface_offset
        return replace(case, measured=m)

    def fitted(surface_offset=0.0, own=True, memory=0.0):
        found, _, _ = calibrate(candidate, with_offset(surface_offset), objective,
                                own=Own([[door]], None, 0.1, memory) if own else None)
        return found["factor"]["value"]

    def weight(surface_offset):
        c = with_offset(surface_offset)
        at = np.hstack([objective.measured(c), c.scored([door - 1])])
        return own_weights(candidate, [c], [[air, door]], [at], [np.zeros_like(at)], [alone],
                           Own([[door]], None, 0.1, 0.0), Policy())[0][0]

    alone = fitted(own=False)
    assert abs(alone - 1.5) > 0.3  # the air alone is fooled by the window
    read = fitted()
    assert abs(read - 1.5) < abs(alone - 1.5) / 3
    assert weight(1.5) <= 0.01 < weight(0.0)
    assert abs(fitted(1.5) - alone) < abs(read - alone)
    # a surface read only once the component has forgotten its start: a memory as long as the
    # record leaves the air alone (to least squares' own tolerance: the run that carries the
    # door's column too rounds the air's otherwise)
    assert fitted(memory=6 * 86400.0) == pytest.approx(alone, rel=1e-3)


def test_effects_refitted_together_find_both_faults_where_one_held_at_an_earlier_round_s_value_does_not(
        testcell, weather):
    """An air change of 0.5 1/h and a door 2.5 times as conductive, the air measured: a model
    that holds the door at 1.2 (an earlier round's value) and fits the air change alone gives it
    the door's missing loss; fitted with the door refitted beside it (`Candidate`'s `beside`),
    both come back to the truth, the door's value named as the model's effect; held at its
    value (`held`), the door stays where it was, and the fit is the one alone."""
    air = testcell.zones[0].air_node
    case = measured_case(testcell, weather, pseudo_measurements(testcell, weather, record_times(4), [air]),
                         burn_in_days=1)
    truth = EFFECTS["conductivity"].apply(EFFECTS["infiltration"].apply(testcell, "cell", {"n": 0.5}), "door",
                                          {"factor": 2.5})
    measured = case.measured.copy()
    measured[1 + case.burn_in_steps:, air - 1] = case.with_inputs(truth).run(truth)[case.burn_in_steps:, air - 1]
    case = replace(case, measured=measured)
    model = EFFECTS["conductivity"].apply(testcell, "door", {"factor": 1.2})
    objective = Objective.of(testcell)

    alone, _, _ = calibrate(Candidate(model, "infiltration", "cell"), case, objective)
    together, _, _ = calibrate(Candidate(model, "infiltration", "cell", beside=[("conductivity", "door")]), case,
                               objective)
    held, _, _ = calibrate(Candidate(model, "infiltration", "cell", beside=[("conductivity", "door")],
                                     held={"conductivity@door": ["factor"]}), case, objective)
    assert alone["n"]["value"] - 0.5 > 0.05  # the door's share taken by the air change (0.57)
    assert together["n"]["value"] == pytest.approx(0.5, rel=1e-3)
    assert together["conductivity@door/factor"]["value"] == pytest.approx(2.5, rel=1e-3)
    assert held["conductivity@door/factor"]["value"] == 1.2
    assert held["n"]["value"] == pytest.approx(alone["n"]["value"], rel=1e-6)

# -- an effect on the inputs alone, superposed --------------------------------------------

@pytest.fixture(scope="module")
def equipped(testcell_data, weather):
    """The test cell with a measured heater (`Q_heat`, on and off) and a blind on its window
    (`blind`, drawn 9 to 17 h), so that every effect on the inputs has a target; its case, 3 days
    at 15 min with the paper's sensors (forced over a burn-in day), and the same cell whose heater
    has a node of its own (`heat_input_lag`)."""
    data = copy.deepcopy(testcell_data)
    data["zones"][0]["heat_input"] = "Q_heat"
    next(c for c in data["components"] if "solar_transmittance" in c)["shading"] = "blind"
    building = parse_building(data)
    hour = weather.index.tz_convert("-05:00").hour
    rng = np.random.default_rng(3)
    w = weather.assign(blind=np.where((hour >= 9) & (hour < 17), 0.0, 1.0),
                       Q_heat=500.0 * (np.cumsum(rng.random(len(weather)) < 0.2) % 2))
    w.attrs = weather.attrs
    times = pd.date_range("2001-06-10 00:00", periods=3 * 96 + 1, freq="15min", tz="-05:00", name="time")
    case = prepare_case(building, w, pseudo_measurements(building, w, times, SENSORS, noise_sd=0.1, seed=1))
    lagged = EFFECTS["heat_input_lag"].apply(building, "cell", {"C_h": 5e4, "H_h": 20.0})
    return building, case.with_burn_in(1), lagged


@pytest.mark.parametrize("effect", [e.id for e in EFFECTS.values() if e.on_inputs])
def test_an_effect_on_the_inputs_alone_is_its_runs_superposed_to_rounding(effect, equipped):
    """The temperatures of a candidate on the inputs alone, at random values of its parameters,
    from its 1 + k runs superposed, against the model with the effect at those values simulated
    afresh: equal to rounding, and the effect moves them by tenths of a degree at least."""
    building, case, _ = equipped
    target = EFFECTS[effect].targets(building)[0]
    candidate = Candidate(building, effect, target)
    ids = [23, 7, 9, 1]
    rng = np.random.default_rng(11)
    moved = 0.0
    for _ in range(3):
        x = [rng.uniform(low, high) for low, high in candidate.bounds]
        built = candidate.built(x)
        direct = case.with_inputs(built).run(built, np.array(ids) - 1)
        superposed = candidate.nodes(case, ids, x)
        assert np.abs(superposed - direct).max() < 1e-9
        moved = max(moved, np.abs(direct - case.with_inputs(building).run(building, np.array(ids) - 1)).max())
    assert candidate.simulations == 1 + len(candidate.parameters)  # the runs superposed, no more
    assert moved > 0.1


def test_a_split_of_the_heat_input_to_a_heater_node_is_simulated_not_superposed(equipped):
    """Where the zone's heater has a node of its own, the split sets its links' conductances:
    the step matrix moves with the parameter, and every value is a run of its own, as the model
    with the effect simulated afresh (its network moved along its derivative from the start's:
    the same to rounding)."""
    _, case, lagged = equipped
    candidate = Candidate(lagged, "heat_input_split", "cell")
    inputs = case.with_inputs(lagged)
    for f_r in (0.1, 0.5, 0.9):
        built = candidate.built([f_r])
        assert np.abs(candidate.nodes(inputs, [23], [f_r]) - inputs.run(built, [22])).max() < 1e-9
    assert candidate.simulations == 3


@pytest.mark.parametrize("effect", [e.id for e in EFFECTS.values() if e.on_inputs])
def test_a_superposed_effect_s_slopes_are_the_model_s_derivatives(effect, equipped):
    """The slopes a superposition reads (dT/dx_i, exact for a model affine in x), from its runs
    at the candidate's points, against central differences of the model simulated afresh at a
    point of their own: equal to 1e-6 of the slope's size."""
    building, case, _ = equipped
    target = EFFECTS[effect].targets(building)[0]
    candidate = Candidate(building, effect, target)
    ids = np.array([23, 9])

    def run(x):
        built = candidate.built(x)
        return case.with_inputs(built).run(built, ids - 1)
    reference, far = superposition_points(building, effect, target, candidate.bounds)
    superposed = Superposition(reference, far, [run(x) for x in [reference, *far]])
    x = np.array([low + 0.3 * (high - low) for low, high in candidate.bounds])
    for i, (low, high) in enumerate(candidate.bounds):
        h = 1e-3 * (high - low)
        plus, minus = x.copy(), x.copy()
        plus[i] += h
        minus[i] -= h
        central = (run(plus) - run(minus)) / (2 * h)
        slope = superposed.slopes[i]
        assert np.abs(slope).max() > 0.0
        assert np.abs(slope - central).max() <= 1e-6 * np.abs(slope).max()
