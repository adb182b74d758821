"""model.significance against Monte Carlo: the spread, over many records, of what one record
gives, for residuals correlated in time as a building model's are (AR(1), one day ~ 144 steps)."""
import numpy as np
import pytest

from nodeforce.model.significance import bandwidth, change_of_J, critical_value, parameter_covariance, worse

N, PHI, LAGS = 2000, 0.97, 144


def ar1(rng, n, phi, sd, count):
    """`count` AR(1) series of n steps, stationary, innovations of sd `sd`."""
    e = rng.normal(0.0, sd, (count, n))
    x = np.empty_like(e)
    x[:, 0] = e[:, 0] / np.sqrt(1 - phi ** 2)
    for t in range(1, n):
        x[:, t] = phi * x[:, t - 1] + e[:, t]
    return x


def test_one_day_of_ten_minute_steps_is_the_bandwidth():
    assert bandwidth(600.0) == 144 and bandwidth(900.0) == 96


def test_the_uncertainty_of_a_fitted_offset_matches_its_spread_over_records():
    # least squares of a constant offset c on y_t = c + e_t: the Jacobian is -1 per residual,
    # c_hat is the mean; its true sd over records is the Monte Carlo spread
    rng = np.random.default_rng(1)
    records = ar1(rng, N, PHI, 0.02, 300)
    spread = records.mean(axis=1).std()
    sds, textbook = [], []
    for y in records[:40]:
        r = y - y.mean()
        sds.append(np.sqrt(parameter_covariance(-np.ones((N, 1)), r, np.arange(N), LAGS)[0, 0]))
        textbook.append(r.std(ddof=1) / np.sqrt(N))
    # the HAC estimate is near the true spread (Bartlett weights bias it low by a few tenths at
    # this correlation), the independent-residual one is several times too small
    assert 0.6 * spread < np.median(sds) < 1.2 * spread
    assert np.median(textbook) < 0.3 * spread


def test_with_white_residuals_it_is_the_textbook_uncertainty():
    # one record's HAC estimate scatters (by ~15 % at this bandwidth); over 30 records its
    # median is the textbook value s^2 (J^T J)^-1
    rng = np.random.default_rng(2)
    x = np.linspace(0.0, 1.0, N)
    jac = -np.column_stack([np.ones(N), x])
    ratios = []
    for r in rng.normal(0.0, 0.1, (30, N)):
        hac = parameter_covariance(jac, r, np.arange(N), LAGS)
        textbook = (r @ r) / (N - 2) * np.linalg.inv(jac.T @ jac)
        ratios.append(np.sqrt(np.diag(hac) / np.diag(textbook)))
    assert np.median(ratios, axis=0) == pytest.approx([1.0, 1.0], abs=0.1)


def test_a_parameter_s_unit_changes_its_variance_by_its_square_and_nothing_else():
    """A capacity in J/K beside a conductance in W/K: columns 1e9 apart in length. The
    covariance transforms as the units do, and a column of rounding (a parameter that acts on
    nothing) is unknown, not known exactly."""
    rng = np.random.default_rng(3)
    n = 2000
    J = np.column_stack([np.sin(np.arange(n) / 40.0), rng.normal(0.0, 1.0, n)])
    r = rng.normal(0.0, 0.1, n)
    cov = parameter_covariance(J, r, np.arange(n), 5)
    units = np.array([1.0, 1e-9])
    scaled = parameter_covariance(J * units, r, np.arange(n), 5)
    np.testing.assert_allclose(scaled, cov / np.outer(units, units), rtol=1e-9)
    rounding = np.column_stack([J[:, 0], rng.normal(0.0, 1e-17, n)])
    sd = np.sqrt(np.diag(parameter_covariance(rounding, r, np.arange(n), 5)))
    assert sd[1] > 1e12  # with the inverse's relative cutoff in the raw units, 0


def test_zones_of_one_step_are_one_moment():
    # two zones with the same residual at every step: summing their scores per step doubles
    # the score, so the HAC variance of their common offset is that of one zone's
    rng = np.random.default_rng(3)
    r = ar1(rng, N, PHI, 0.02, 1)[0]
    one = parameter_covariance(-np.ones((N, 1)), r, np.arange(N), LAGS)
    two = parameter_covariance(-np.ones((2 * N, 1)), np.repeat(r, 2), np.repeat(np.arange(N), 2), LAGS)
    assert two[0, 0] == pytest.approx(one[0, 0], rel=1e-12)


def test_the_fall_of_J_is_exact_and_its_spread_matches_records():
    rng = np.random.default_rng(4)
    common = ar1(rng, N, PHI, 0.02, 300)
    before = common + 0.05  # a model off by 0.05 C, and the same model corrected
    falls = [change_of_J(b[:, None], a[:, None], LAGS) for b, a in zip(before, common)]
    for (fall, _), b, a in zip(falls, before, common):
        assert fall == pytest.approx(b @ b - a @ a)
    spread = np.std([f for f, _ in falls])
    assert 0.6 * spread < np.median([sd for _, sd in falls]) < 1.2 * spread


def test_unmeasured_steps_contribute_nothing():
    before = np.array([[1.0, np.nan], [2.0, 1.0], [np.nan, np.nan], [1.0, 1.0]])
    after = np.array([[0.5, np.nan], [1.0, 1.0], [np.nan, np.nan], [0.0, 0.0]])
    fall, _ = change_of_J(before, after, 1)
    assert fall == pytest.approx((1 - 0.25) + (5 - 2) + (2 - 0))


# The paired test of two forcings on one record (ga.parsimony): a week of 15-minute steps, a
# bandwidth of a day, residuals that share the record's slow error and each carry their own.
WEEK, DAY = 7 * 96, 96


def two_forcings(rng, count, offset=0.0):
    """`count` records of the residuals (C) of two forcings, (count, WEEK) each: both share the
    record's error (AR(1), sd 0.1 C), each adds its own of equal size (AR(1), sd 0.05 C), so
    neither fits better in expectation; the second is off by `offset` (C) as well."""
    shared = ar1(rng, WEEK, 0.95, 0.1 * np.sqrt(1 - 0.95 ** 2), count)
    own = ar1(rng, WEEK, 0.9, 0.05 * np.sqrt(1 - 0.9 ** 2), 2 * count)
    return shared + own[:count], shared + own[count:] + offset


def test_the_paired_test_of_two_equally_good_forcings_errs_at_its_nominal_rate():
    rng = np.random.default_rng(3)
    a, b = two_forcings(rng, 400)
    # nominal 5 % one-sided, each way; the Monte Carlo's own sd is 1.1 % (measured: 8.0 % and 5.75 %)
    assert 0.025 <= np.mean([worse(x[:, None], y[:, None]) for x, y in zip(a, b)]) <= 0.09
    assert 0.025 <= np.mean([worse(y[:, None], x[:, None]) for x, y in zip(a, b)]) <= 0.09
    # with the normal 1.645 and a fixed day of lags instead, a bandwidth of a day in a week
    # rejects far more often than it says: the fixed-b correction is needed
    naive = [np.divide(*change_of_J(x[:, None], y[:, None], DAY)) > 1.645 for x, y in zip(a[:200], b[:200])]
    assert np.mean(naive) > 0.08 and critical_value(DAY, WEEK) > 1.9


def test_the_paired_test_sees_what_the_noise_of_one_J_hides():
    # white sensor noise of sd 0.1 C, the noise the band of one J is made for; the second forcing
    # is off by 0.035 C: E[J_b - J_a] = n 0.035^2 = 0.82 C2, inside that band (3 sigma^2 sqrt(2 n)
    # = 1.1 C2), but the two share the noise, so the fall's sd is 2 0.035 0.1 sqrt(n) = 0.18 C2
    # and the paired test sees it nearly always
    rng = np.random.default_rng(4)
    a = rng.normal(0.0, 0.1, (100, WEEK))
    b = a + 0.035
    fall = (np.square(b) - np.square(a)).sum(axis=1)
    assert np.mean(fall) < 3 * 0.1 ** 2 * np.sqrt(2 * WEEK)
    assert np.mean([worse(y[:, None], x[:, None]) for x, y in zip(a, b)]) > 0.9
    assert not any(worse(x[:, None], y[:, None]) for x, y in zip(a, b))


def test_on_white_residuals_the_paired_sd_is_the_textbook_value():
    # r_a = c + e, r_b = -c + e with e white of sd s: r_a^2 - r_b^2 = 4 c e_t, so the fall of J
    # has sd 4 c s sqrt(n) (independent steps); the HAC estimate, averaged over records, gives it
    rng = np.random.default_rng(5)
    n, c, s = 100 * DAY, 0.05, 0.1
    variances = [change_of_J((c + e)[:, None], (-c + e)[:, None], DAY)[1] ** 2 for e in rng.normal(0, s, (30, n))]
    assert np.sqrt(np.mean(variances)) == pytest.approx(4 * c * s * np.sqrt(n), rel=0.03)
