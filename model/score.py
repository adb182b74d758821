"""The score of a simulation against the measured indoor air (docs/model.md section 6)."""
import math
from dataclasses import dataclass, replace

import numpy as np

from .errors import InputError
from .numerical import REFERENCE_STEP, REFINEMENT


def removed(J_unforced, J, J_noise):
    """The fraction of the error above the noise, J_unforced - J_noise, that a model (a forcing, a
    correction) of score J (C2) removes (1: all of it; 0 or less: none)."""
    above = J_unforced - J_noise
    return (J_unforced - J) / above if above > 0 else 0.0


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


# White noise gives second differences of lag-1 autocorrelation -2/3; a signal's curvature pulls
# it towards +1. Below this bound the noise dominates the second differences and is seen.
WHITE_LAG1 = -0.5


def _second_differences(series):
    x = np.asarray(series, dtype=float)
    return x[2:] - 2 * x[1:-1] + x[:-2]


def noise_level(series):
    """Estimated sd (C) of white sensor noise on a smooth measured temperature.

    Second differences remove a signal that is locally linear; on white noise of sd sigma they
    have sd sigma*sqrt(6). The median absolute deviation keeps steps and outliers from
    inflating the estimate. Gaps (NaN) split the series; no value is filled in. Where the
    signal's curvature dominates the second differences (`noise_visible` is False) this is an
    upper bound of the white noise, not an estimate.
    """
    d2 = _second_differences(series)
    d2 = d2[np.isfinite(d2)]
    if len(d2) < 10:
        return None
    mad = np.median(np.abs(d2 - np.median(d2)))
    return float(mad / 0.6744897501960817 / np.sqrt(6.0))


def second_difference_lag1(series):
    """Lag-1 autocorrelation of the second differences (-2/3 for white noise), None if too short."""
    d2 = _second_differences(series)
    pairs = np.isfinite(d2[1:]) & np.isfinite(d2[:-1])
    if pairs.sum() < 10:
        return None
    return float(np.corrcoef(d2[1:][pairs], d2[:-1][pairs])[0, 1])


@dataclass(frozen=True)
class Noise:
    """The sensor noise of the objective's measured air: its sd (C), None if unknown, and where
    that number comes from: the user's `--noise` (a sensor's stated accuracy), or second
    differences of the measurement, with their lag-1 autocorrelation telling whether the noise
    is visible in them at all (on real records of precise sensors the signal's curvature over
    one step outweighs the white noise, and the error that matters is slow). Beside it, the
    building file's own numerical error at the air (`numerical`, RMS in C, `model.numerical`):
    together they are what a right model of the file leaves (`floor_sd`, C)."""
    sigma: float | None
    given: bool = False
    lag1: float | None = None
    numerical: float | None = None

    def with_numerical(self, rms):
        """The noise with the file's numerical error `rms` (C) beside it."""
        return replace(self, numerical=float(rms))

    @property
    def floor_sd(self):
        """The sd (C) of what a model right but for its discretisation leaves, sqrt(sigma^2 +
        numerical^2): the J a right correction brings the error to is n floor^2; None if the
        noise is unknown."""
        if self.sigma is None:
            return None
        return math.hypot(self.sigma, self.numerical or 0.0)

    @classmethod
    def of(cls, measured_air, given=None):
        """From the user's sd `given` (C), else from the (N_t, k) measured air of the objective:
        the root mean square of each zone's second-difference estimate."""
        if given is not None:
            return cls(float(given), given=True)
        columns = np.atleast_2d(np.asarray(measured_air, dtype=float).T)
        sigmas = [s for s in map(noise_level, columns) if s is not None]
        lags = [r for r in map(second_difference_lag1, columns) if r is not None]
        return cls(float(np.sqrt(np.mean(np.square(sigmas)))) if sigmas else None,
                   lag1=max(lags) if lags else None)

    @classmethod
    def of_records(cls, measured_airs, given=None):
        """`of` the measured air of several records ((N_t, k) each), joined apart by a row of NaN
        so that no second difference spans two records."""
        gap = np.full((1, np.shape(measured_airs[0])[1]), np.nan)
        return cls.of(np.concatenate([x for m in measured_airs for x in (m, gap)][:-1]), given)

    @property
    def visible(self):
        """Whether sigma is the noise itself (given, or white noise dominating the differences)."""
        return self.given or (self.lag1 is not None and self.lag1 < WHITE_LAG1)

    def sentence(self):
        if self.given:
            return f"sensor noise of the air: sigma = {self.sigma:.3g} C, as given (--noise)"
        if self.sigma is None:
            return "sensor noise of the air: unknown (too few measured steps); give --noise"
        if self.visible:
            return (f"sensor noise of the air, estimated from its second differences: sigma = {self.sigma:.2g} C "
                    f"(they look like white noise: lag-1 autocorrelation {self.lag1:.2f}, -0.67 for white noise)")
        return (f"sensor noise of the air: not visible in the measurements, whose second differences follow the "
                f"signal's own curvature (lag-1 autocorrelation {self.lag1:.2f}, not the -0.67 of white noise): "
                f"{self.sigma:.2g} C is only an upper bound of the white part of the sensor error, and slow errors "
                f"(offsets, radiation, stratification) are not in it; give the sensors' accuracy with --noise. "
                f"The decisions allow for the residuals' correlation in time instead")

    def numerical_sentence(self):
        if self.numerical is None:
            return None
        return (f"numerical error of the building file at the air: {self.numerical:.2g} C RMS over the calibration "
                f"window (the file against itself {REFINEMENT} times finer in space and at steps of at most "
                f"{REFERENCE_STEP:g} s); the choices count it beside the noise, an error floor of "
                + (f"{self.floor_sd:.2g} C" if self.floor_sd is not None else "its own") + ": no correction of the physics "
                "is asked to explain it")

    def to_json(self):
        return {"sigma": self.sigma, "given": self.given, "lag1": self.lag1, "visible": self.visible,
                "numerical": self.numerical, "floor": self.floor_sd, "sentence": self.sentence(),
                "numerical_sentence": self.numerical_sentence()}

    @classmethod
    def of_json(cls, d):
        """The noise `to_json` wrote."""
        return cls(d["sigma"], d["given"], d["lag1"], d["numerical"])


@dataclass(frozen=True)
class Objective:
    """The zones whose measured air J sums (docs/model.md section 6), and their air nodes."""
    zones: tuple  # zone names
    air_nodes: tuple  # their air node ids, in the same order

    @classmethod
    def of(cls, building, names=None, source="--objective"):
        """The objective of `names` (zone names; default: the building's first zone)."""
        names = list(names) if names else [building.zones[0].name]
        known = [z.name for z in building.zones]
        for name in names:
            if name not in known:
                raise InputError(source, name, f"names no zone of {building.source} ({', '.join(known)})")
        return cls(tuple(names), tuple(building.zone(name).air_node for name in names))

    def measured(self, case):
        """(N_t, k) measured air (C) of the objective zones at t_1..t_N, NaN where not scored
        (missing, or in the burn-in)."""
        return case.scored([node - 1 for node in self.air_nodes])

    def J(self, measured, simulated):
        """J = sum over zones and scored steps of r^2 (C2)."""
        return sum_of_squares(measured, simulated)

    def metrics(self, measured, simulated):
        """`metrics` of all the objective's residuals together, and per zone under "zones"."""
        measured, simulated = np.asarray(measured, dtype=float), np.asarray(simulated, dtype=float)
        result = metrics(measured, simulated)
        result["zones"] = {zone: metrics(measured[:, k], simulated[:, k]) for k, zone in enumerate(self.zones)}
        return result
