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
    scores = np.zeros((steps.max() - steps.min() + 1, jacobian.shape[1]))
    # the zones' scores of one step are one moment of that step: their correlation is kept
    np.add.at(scores, steps - steps.min(), jacobian * residuals[:, None])
    bread = np.linalg.pinv(jacobian.T @ jacobian)
    return bread @ S_hac_simple(scores, nlags=lags) @ bread


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
