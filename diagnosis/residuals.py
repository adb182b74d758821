"""Residual diagnostics: is what the model leaves white noise, and if not, what does it follow?

Pure functions on numpy arrays; statsmodels and scipy do the statistics. The residual r is
T_measured - T_simulated (K) on a regular time grid; NaN marks a step that is unscored or
unmeasured. Missing values are never filled: every statistic is computed on the longest run of
consecutive steps where the residual and every input are finite, and the result says which run.

- Whiteness: the Ljung-Box test of the residual's autocorrelation up to `max_lag_hours`
  (at most n/5 lags, beyond which the test loses its chi-squared distribution), at level ALPHA.
- Inputs: the cross-correlation of the residual, lagging, with each input at 0 up to
  `max_lag_hours`. Two autocorrelated series correlate by chance far beyond the band of white
  noise, so each input is first prewhitened (Box and Jenkins): an autoregression of the input,
  order by AIC, turns it into its innovations, and the same filter is applied to the residual.
  Without a relation, their cross-correlation at each lag is then about normal with sd
  1/sqrt(n) whatever the residual's own autocorrelation, and the lag of its peak is the lag of
  the input's effect. The bound is Bonferroni's over every lag and input tested, at family-wise
  level ALPHA / 2: a residual unrelated to the inputs names one with probability <= 2.5 %.
- Time of day: a regression of the residual on the first HARMONICS harmonics of the day, and on
  the inputs it follows at their lags (a daily profile those explain is not the clock's), with
  autoregressive errors (feasible GLS, statsmodels GLSAR, order by AIC); the harmonics' joint F
  test at level ALPHA / 2.
- Working days: where the run holds working and rest days, the same regression with the
  working-day indicator and its products with the harmonics beside them (a profile of the
  working days only, an office's gain); their joint F test at level ALPHA / 2.
"""
from __future__ import annotations

import functools
import math
import warnings

import numpy as np
import pandas as pd
from scipy.signal import lfilter
from scipy.stats import norm
from statsmodels.regression.linear_model import GLSAR
from statsmodels.stats.diagnostic import acorr_ljungbox
from statsmodels.tools.sm_exceptions import SingularMatrixWarning
from statsmodels.tsa.ar_model import AutoReg, ar_select_order
from statsmodels.tsa.stattools import acf, ccf

from nodeforce.model.building import WORKDAYS

ALPHA = 0.05
HARMONICS = 3  # of the day: a profile resolved to about 4 h
PREWHITEN_HOURS = 3.0  # the longest memory of an input's prewhitening filter
MIN_STEPS = 48  # a shorter run says nothing about correlations over hours


def longest_run(finite):
    """(start, stop) of the longest run of True in a boolean array (stop exclusive; (0, 0) if none)."""
    edges = np.diff(np.concatenate(([0], np.asarray(finite, dtype=np.int8), [0])))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    if len(starts) == 0:
        return 0, 0
    i = int(np.argmax(stops - starts))
    return int(starts[i]), int(stops[i])


def step_hours(times):
    """The time step (h) of a regular DatetimeIndex; ValueError if the grid is not regular."""
    steps = np.diff(pd.DatetimeIndex(times)) / pd.Timedelta(hours=1)
    if len(steps) == 0 or steps[0] <= 0 or np.any(steps != steps[0]):
        raise ValueError("residual diagnostics need times on a regular, increasing grid")
    return float(steps[0])


def _ar_filter(x, max_order):
    """The AR polynomial [1, -phi_1, ..., -phi_p] of x, order p <= max_order by AIC (p may be 0).
    An input's filter is the same for every residual diagnosed beside it (the model before and
    after, each round's): kept for the series (`_ar_filter_of`)."""
    return _ar_filter_of(np.ascontiguousarray(x, dtype=float).tobytes(), max_order)


@functools.lru_cache(maxsize=64)
def _ar_filter_of(data, max_order):
    x = np.frombuffer(data).copy()
    with warnings.catch_warnings():
        # A piecewise-constant input (heater pulses) is predicted almost exactly by its last
        # value: statsmodels warns of a near-singular fit, yet the filter it gives is right
        # (differencing: the innovations are the switches).
        warnings.simplefilter("ignore", (SingularMatrixWarning, RuntimeWarning))
        lags = ar_select_order(x, maxlag=max_order, ic="aic", trend="c").ar_lags
        phi = AutoReg(x, lags=max(lags), trend="c").fit().params[1:] if lags else []
    a = np.concatenate(([1.0], -np.asarray(phi)))
    a.setflags(write=False)  # shared by every caller
    return a


def prewhitened_ccf(residual, x, max_lag, max_order):
    """Cross-correlation of the residual lagging the input x by 0..max_lag steps, both filtered by
    the input's prewhitening filter; and the number of filtered steps it rests on."""
    a = _ar_filter(x, max_order)
    p = len(a) - 1
    xf, rf = lfilter(a, [1.0], x)[p:], lfilter(a, [1.0], residual)[p:]
    return ccf(rf, xf, adjusted=False, fft=True, nlags=max_lag + 1), len(xf)


def daily_harmonics(times, harmonics=HARMONICS):
    """Columns cos, sin of 2 pi h tau / 24 h for h = 1..harmonics, tau the clock time (h) of `times`."""
    t = pd.DatetimeIndex(times)
    tau = (t.hour + t.minute / 60 + t.second / 3600).to_numpy(dtype=float)
    return np.column_stack([f(2 * np.pi * h * tau / 24) for h in range(1, harmonics + 1) for f in (np.cos, np.sin)])


def f_test_glsar(residual, regressors, columns, max_order):
    """The GLSAR regression of `residual` on the `regressors` (columns, stacked in order), its AR
    errors' order by AIC (<= max_order), and the joint F test of its coefficients `columns`:
    (the fit, the test, the order)."""
    exog = np.column_stack(regressors)
    first = GLSAR(residual, exog, rho=0).fit()
    order = max(ar_select_order(first.resid, maxlag=max_order, ic="aic", trend="n").ar_lags or [0])
    fit = GLSAR(residual, exog, rho=order).iterative_fit(maxiter=20) if order else first
    return fit, fit.f_test(np.eye(exog.shape[1])[columns]), order


def time_of_day(times, residual, regressors, max_order):
    """Whether the residual has a daily profile beyond what `regressors` (columns) explain.

    GLSAR regression on a constant, the daily harmonics and the regressors, AR errors of order
    by AIC (<= max_order). Returns the F test of the harmonics (statistic, p value), the
    profile's amplitude (K, half its peak to peak) and the clock hour of its maximum.
    """
    harmonic = daily_harmonics(times)
    columns = np.arange(1, 1 + harmonic.shape[1])
    fit, test, order = f_test_glsar(residual, [np.ones(len(residual)), harmonic] + list(regressors), columns,
                                    max_order)
    clock = pd.date_range("2000-01-01", periods=24 * 12, freq="5min")
    profile = daily_harmonics(clock) @ fit.params[columns]
    return {"F": float(np.squeeze(test.fvalue)), "p_value": float(test.pvalue),
            "amplitude": float((profile.max() - profile.min()) / 2),
            "peak_hour": float(np.argmax(profile) / 12), "ar_order": int(order)}


def working_days(times, residual, regressors, max_order):
    """Whether the residual differs between working and rest days beyond a profile every day
    shares and what `regressors` (columns) explain, or None where the run does not hold both kinds
    of day (`model.building.WORKDAYS` of `times`' own calendar).

    GLSAR regression on a constant, the daily harmonics, the working-day indicator and its
    products with the harmonics, and the regressors, AR errors of order by AIC (<= max_order).
    Returns the F test of the working-day columns (statistic, p value), the working and the rest
    days in the run (days), and the profile's mean on a working day beyond a rest day's (K)."""
    t = pd.DatetimeIndex(times)
    on = np.isin(t.day_of_week, WORKDAYS).astype(float)
    if on.all() or not on.any():
        return None
    harmonic = daily_harmonics(t)
    columns = np.arange(1 + harmonic.shape[1], 2 + 2 * harmonic.shape[1])
    fit, test, order = f_test_glsar(residual, [np.ones(len(residual)), harmonic, on, on[:, None] * harmonic]
                                    + list(regressors), columns, max_order)
    per_day = 24.0 / step_hours(t)
    return {"F": float(np.squeeze(test.fvalue)), "p_value": float(test.pvalue),
            "working_days": float(on.sum() / per_day), "rest_days": float((1 - on).sum() / per_day),
            "excess": float(fit.params[columns[0]]), "ar_order": int(order)}


def level(r, rho):
    """The residual's mean (K), its standard deviation as the residual's lag-one autocorrelation
    rho makes it (an AR(1) residual's mean varies (1 + rho) / (1 - rho) times more than white
    noise's), and whether it is significant at level ALPHA."""
    rho = min(max(rho, 0.0), 0.999)
    sd = float(np.std(r, ddof=1) / math.sqrt(len(r)) * math.sqrt((1 + rho) / (1 - rho)))
    mean = float(np.mean(r))
    return {"mean": mean, "sd": sd, "significant": bool(abs(mean) > norm.isf(ALPHA / 2) * sd)}


def _lagged(x, lag, n):
    """x delayed by `lag` steps, the last n values (x[t - lag] for the last n t)."""
    return x[len(x) - n - lag:len(x) - lag]


def diagnostics(times, residual, inputs, max_lag_hours=24.0):
    """Residual diagnostics: whiteness, the inputs the residual follows, its daily profile.

    Parameters
    ----------
    times : DatetimeIndex, regular grid; the clock of the time of day and the calendar of the working
        days are those of its time zone
    residual : array (K), measured - simulated; NaN where not scored or not measured
    inputs : {name: array} the model's inputs on the same grid (any unit: correlations only)
    max_lag_hours : float (h), the longest lag examined, of the residual behind an input

    Returns
    -------
    dict, JSON-ready: "n" (steps used), "run" (where: start, end, n_total, n_finite), "step_hours",
    "ljung_box" {"lag", "statistic", "p_value"}, "white", "acf" (lags 0..max, per step) with
    "acf_bound" (95 % band of white noise), "level" {"mean", "sd", "significant"} (`level`), "follows" [{"input", "lag_hours", "correlation"}]
    strongest first (significant only), "strongest" (the largest prewhitened cross-correlation,
    significant or not, with its curve "ccf" over the lags and its "bound"), "skipped" {name:
    why}, "time_of_day" {"F", "p_value", "significant", "amplitude" (K), "peak_hour", ...},
    "working_days" {"F", "p_value", "significant", "working_days", "rest_days", "excess" (K), ...}
    (None where the run holds one kind of day: `working_days`) and "sentence".
    """
    times = pd.DatetimeIndex(times)
    r = np.asarray(residual, dtype=float)
    xs = {name: np.asarray(v, dtype=float) for name, v in inputs.items()}
    for name, x in [("residual", r)] + list(xs.items()):
        if x.shape != (len(times),):
            raise ValueError(f"{name}: {x.shape[0] if x.ndim else 0} values for {len(times)} times")
    dt = step_hours(times)
    finite = np.isfinite(r)
    start, stop = longest_run(finite & np.all([np.isfinite(x) for x in xs.values()] or [finite], axis=0))
    n = stop - start
    out = {"n": n, "step_hours": dt,
           "run": {"start": times[start].isoformat() if n else None,
                   "end": times[stop - 1].isoformat() if n else None,
                   "n_total": len(r), "n_finite": int(finite.sum()),
                   "rule": "longest run of consecutive steps where the residual and every input are measured"},
           "ljung_box": None, "white": None, "acf": [], "acf_bound": None, "level": None, "follows": [],
           "strongest": None,
           "skipped": {}, "time_of_day": None, "working_days": None}
    max_lag = min(int(round(max_lag_hours / dt)), n // 5)
    if n < MIN_STEPS or max_lag < 1:
        out["sentence"] = (f"Too few consecutive scored steps ({n}, at least {MIN_STEPS} needed) "
                           "for residual diagnostics.")
        return out
    t, r = times[start:stop], r[start:stop]
    xs = {name: x[start:stop] for name, x in xs.items()}
    max_order = max(1, min(int(round(PREWHITEN_HOURS / dt)), n // 10))

    lb = acorr_ljungbox(r, lags=[max_lag], return_df=True)
    p_white = float(lb["lb_pvalue"].iloc[0])
    out.update(ljung_box={"lag": max_lag, "lag_hours": max_lag * dt, "statistic": float(lb["lb_stat"].iloc[0]),
                          "p_value": p_white},
               white=bool(p_white >= ALPHA), acf=[float(v) for v in acf(r, nlags=max_lag, fft=True)],
               acf_bound=float(norm.isf(ALPHA / 2) / math.sqrt(n)))

    out["level"] = level(r, out["acf"][1])

    varying = {name: x for name, x in xs.items() if np.ptp(x) > 0}
    out["skipped"] = {name: "constant over the run" for name in xs if name not in varying}
    z = norm.isf(ALPHA / 2 / (2 * (max_lag + 1) * max(1, len(varying))))
    curves = []
    for name, x in varying.items():
        c, m = prewhitened_ccf(r, x, max_lag, max_order)
        k = int(np.argmax(np.abs(c)))
        curves.append({"input": name, "lag_hours": k * dt, "correlation": float(c[k]),
                       "bound": float(z / math.sqrt(m)), "ccf": [float(v) for v in c]})
    curves.sort(key=lambda e: -abs(e["correlation"]))
    out["follows"] = [{key: e[key] for key in ("input", "lag_hours", "correlation")}
                      for e in curves if abs(e["correlation"]) > e["bound"]]
    out["strongest"] = curves[0] if curves else None

    lags = {e["input"]: int(round(e["lag_hours"] / dt)) for e in out["follows"]}
    m = n - max(lags.values(), default=0)
    daily = time_of_day(t[n - m:], r[n - m:], [_lagged(xs[name], k, m) for name, k in lags.items()], max_order)
    daily["significant"] = bool(daily["p_value"] < ALPHA / 2)
    daily["beyond_inputs"] = list(lags)
    out["time_of_day"] = daily
    weekly = working_days(t[n - m:], r[n - m:], [_lagged(xs[name], k, m) for name, k in lags.items()], max_order)
    if weekly is not None:
        weekly["significant"] = bool(weekly["p_value"] < ALPHA / 2)
    out["working_days"] = weekly
    out["sentence"] = sentence(out)
    return out


def lag_text(hours):
    """'at the same time', '2 h later', '40 min later', '1 h 30 min later'."""
    minutes = int(round(hours * 60))
    if minutes == 0:
        return "at the same time"
    h, m = divmod(minutes, 60)
    return " ".join(part for part in (f"{h} h" if h else "", f"{m} min" if m else "") if part) + " later"


def sentence(d):
    """What the diagnostics found in a sentence, the strongest relation first, and where the
    working days differ, a second."""
    said = _first_sentence(d)
    weekly = d.get("working_days")
    if weekly and weekly["significant"]:
        p = "< 0.001" if weekly["p_value"] < 1e-3 else f"= {weekly['p_value']:.3f}"
        said += (f" It differs on the working days from the rest days (F test p {p}; their mean "
                 f"{weekly['excess']:+.2f} K beyond a rest day's).")
    return said


def _first_sentence(d):
    lb = d["ljung_box"]
    p = "< 0.001" if lb["p_value"] < 1e-3 else f"= {lb['p_value']:.3f}"
    whiteness = f"Ljung-Box p {p} over {lb['lag_hours']:g} h"
    daily = d["time_of_day"]
    clock = (f"a daily profile of amplitude {daily['amplitude']:.2f} K, highest at "
             f"{int(daily['peak_hour']):02d}:{int(round(daily['peak_hour'] % 1 * 60)) % 60:02d}")
    if d["follows"]:
        top = d["follows"][0]
        text = (f"The residual follows {top['input']}, {lag_text(top['lag_hours'])} "
                f"(prewhitened cross-correlation {top['correlation']:+.2f}")
        others = [e["input"] for e in d["follows"][1:4]]
        text += (f"; also {', '.join(others)})" if others else ")")
        return text + (f", with {clock} beyond it." if daily["significant"] else ".")
    if daily["significant"]:
        return f"The residual follows the time of day: {clock}; it follows none of the inputs ({whiteness})."
    if d["white"]:
        return f"No structure: the residual is white ({whiteness}) and follows none of the inputs nor the time of day."
    lag = min(len(d["acf"]) - 1, int(round(1 / d["step_hours"])))
    return (f"The residual is autocorrelated ({whiteness}; autocorrelation {d['acf'][lag]:.2f} at "
            f"{lag * d['step_hours']:g} h) but follows none of the inputs nor the time of day: a slow drift "
            "or an input the model does not have.")
