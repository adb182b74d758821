"""The score of a simulation against the measured indoor air (PHYSICS.md section 6)."""
import numpy as np


def residuals(measured, simulated):
    """r_n = measured - simulated (C), only where a measurement exists."""
    r = np.asarray(measured, dtype=float) - np.asarray(simulated, dtype=float)
    return r[np.isfinite(r)]


def sum_of_squares(measured, simulated):
    """J = sum r_n^2 (C2, paper eq. 7-bis)."""
    r = residuals(measured, simulated)
    return float(r @ r)


def metrics(measured, simulated):
    """J (C2), RMSE, mean and standard deviation (C) of the residual, and its count n."""
    r = residuals(measured, simulated)
    return {"J": float(r @ r), "rmse": float(np.sqrt(np.mean(r ** 2))), "mean": float(r.mean()),
            "sd": float(r.std(ddof=1)) if len(r) > 1 else 0.0, "n": int(len(r))}


def noise_level(series):
    """Estimated sd (C) of white sensor noise on a smooth measured temperature.

    Second differences remove a signal that is locally linear; on white noise of sd sigma they
    have sd sigma*sqrt(6). The median absolute deviation keeps steps and outliers from
    inflating the estimate. Gaps (NaN) split the series; no value is filled in.
    """
    x = np.asarray(series, dtype=float)
    d2 = x[2:] - 2 * x[1:-1] + x[:-2]
    d2 = d2[np.isfinite(d2)]
    if len(d2) < 10:
        return None
    mad = np.median(np.abs(d2 - np.median(d2)))
    return float(mad / 0.6744897501960817 / np.sqrt(6.0))
