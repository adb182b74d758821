"""What a record of correlated residuals can show: parameter uncertainty and changes of J.

A building model's residual is correlated over hours to days: the thermal mass remembers and
the weather repeats every day. n residuals then carry far fewer than n independent pieces of
information, and the textbook least-squares uncertainty s^2 (J^T J)^-1, or a change of J judged
against white noise, overstate what the data show. Both are replaced by Newey and West's heteroscedasticity and autocorrelation
consistent (HAC) estimate, Bartlett weights over a bandwidth of one day of steps
(statsmodels' `S_hac_simple`): with white residuals it gives the textbook values back.

Steps without a measurement contribute nothing; nothing is filled in.
"""
import numpy as np
from statsmodels.stats.sandwich_covariance import S_hac_simple

from nodeforce.model.integrate import steps_per_day


def bandwidth(dt):
    """Lags (steps) the HAC estimate sums over: one day of steps of dt s."""
    return steps_per_day(dt)


def parameter_covariance(jacobian, residuals, steps, lags):
    """HAC covariance of least-squares parameters, (J^T J)^-1 S (J^T J)^-1.

    Parameters
    ----------
    jacobian : (n, k) derivative of each residual with respect to each parameter (C per unit)
    residuals : (n,) residuals at the optimum (C)
    steps : (n,) time step index of each residual (several zones share a step)
    lags : bandwidth in steps

    Returns
    -------
    (k, k) covariance of the parameters (units squared)
    """
    jacobian, residuals = np.asarray(jacobian, dtype=float), np.asarray(residuals, dtype=float)
    steps = np.asarray(steps)
    # computed for the parameters in units that give every column unit length: the inverse's
    # relative cutoff then drops a direction the data leave undetermined, never a parameter whose
    # unit makes its column short (a capacity in J/K beside a conductance in W/K) or whose
    # column is exact rounding (a mass of no capacity's conductance); a zero column (a parameter
    # held) keeps its variance 0
    length = np.linalg.norm(jacobian, axis=0)
    unit = np.where(length > 0, length, 1.0)
    jacobian = jacobian / unit
    scores = np.zeros((steps.max() - steps.min() + 1, jacobian.shape[1]))
    # the zones' scores of one step are one moment of that step: their correlation is kept
    np.add.at(scores, steps - steps.min(), jacobian * residuals[:, None])
    bread = np.linalg.pinv(jacobian.T @ jacobian)
    return bread @ S_hac_simple(scores, nlags=lags) @ bread / np.outer(unit, unit)


def change_of_J(before, after, lags):
    """The fall of J = sum r^2 from `before` to `after` on one window, and its HAC standard
    deviation: how much of that fall the residuals' own correlated scatter could make.

    Parameters
    ----------
    before, after : (n_t, n_zones) residuals (C), NaN where not measured
    lags : bandwidth in steps

    Returns
    -------
    (fall of J, its standard deviation), both in C2
    """
    d = np.nansum(np.square(before), axis=1) - np.nansum(np.square(after), axis=1)
    d = d[np.isfinite(before).any(axis=1)]
    return float(d.sum()), float(np.sqrt(S_hac_simple(d - d.mean(), nlags=lags)[0, 0]))




def automatic_lags(series):
    """Andrews' (1991) data-driven bandwidth (steps) of the Bartlett HAC estimate of a series'
    long-run variance, from an AR(1) fitted to it: as many lags as its own autocorrelation asks
    for, none where it is white, many where it remembers. The paired difference of two forcings'
    squared residuals is often nearly white (the forcings remove the slow error and leave the
    sensor noise), and a fixed day of lags would then only cost power."""
    x = np.asarray(series, dtype=float)
    x = x - x.mean()
    n = len(x)
    rho = float(np.clip(x[1:] @ x[:-1] / (x @ x), -0.97, 0.97)) if x @ x > 0 else 0.0
    alpha = 4 * rho ** 2 / ((1 - rho) ** 2 * (1 + rho) ** 2)
    return int(min(1.1447 * (alpha * n) ** (1 / 3), n - 1))


def critical_value(lags, n):
    """One-sided 5 % critical value of the paired statistic fall / sd when sd is the Bartlett HAC
    estimate over `lags` of n steps: Kiefer and Vogelsang's fixed-b value (2005, their
    polynomial for the Bartlett kernel, b = (lags + 1) / n). A bandwidth of a day on a record of
    a week or two is a large share of it, and the estimate of sd then scatters enough to make
    the normal 1.645 reject a true equality far more often than it says (tests/test_significance.py)."""
    b = min((lags + 1) / n, 1.0)
    return 1.6449 + 2.1859 * b + 0.3142 * b ** 2 - 0.3427 * b ** 3


def worse(first, second):
    """Whether the data show `first` (residuals, C, (n_t, n_zones), NaN where not scored) fitting
    worse than `second` on the same steps: J(first) - J(second) beyond `critical_value` HAC
    standard deviations of that paired difference (a Diebold-Mariano test on squared errors,
    one-sided at 5 %, over the `automatic_lags` of that difference). One-sided: the question
    is always whether the preferred one (nearer the zone, physical, fewer parameters) is worse. Two models scored on one record share its noise, so their difference of J is
    far better determined than either J: this, not the noise of one J, says whether they can be
    told apart."""
    first, second = np.asarray(first, dtype=float), np.asarray(second, dtype=float)
    d = np.nansum(np.square(first), axis=1) - np.nansum(np.square(second), axis=1)
    d = d[np.isfinite(first).any(axis=1)]
    lags = automatic_lags(d)
    fall, sd = change_of_J(first, second, lags)
    return fall > critical_value(lags, len(d)) * sd
