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


def fall(before, after):
    """The fall of J from per-block J `before` to `after` (C2) and its standard error from the
    per-block falls (blocks as the unit; 0 for one block, which has no scatter to measure)."""
    d = np.asarray(before, dtype=float) - np.asarray(after, dtype=float)
    return float(d.sum()), float(math.sqrt(len(d)) * d.std(ddof=1)) if len(d) > 1 else 0.0


@dataclass(frozen=True)
class Fall:
    """A fall of J block by block (C2), judged by `Yardstick.judge`: the fall, its standard error
    from the per-block falls, what it needs, and what the blocks other than its best gain."""
    fall: float
    se: float
    needed: float
    other_days: float

    @property
    def beats(self):
        """The pass rule: the fall beats what it needs, on more blocks than its best."""
        return self.fall > self.needed and self.other_days > 0

    @property
    def reversed(self):
        """The rule read the other way: J rises by more than the fall would need."""
        return self.fall < -self.needed


@dataclass(frozen=True)
class Yardstick:
    """The noise yardstick of a change of J, read by the forcing search's parsimony
    (`ga.parsimony`) and the diagnosis' choice (`diagnosis.policy.Policy.yardstick`) alike.

    With n residuals of independent noise of sd sigma, J of pure noise (sigma^2 times a chi-square
    with n degrees of freedom) has sd sigma^2 sqrt(2 n): a change of J smaller than `noise_sds`
    such sds could be noise alone (`noise_change`). Where the noise is unknown or nil, a tiny gain
    is not a fault: a fall must also exceed `least_fall_share` of the J it falls from
    (`least_fall`). A difference of J below `rounding_share` of it is the simulation's rounding.
    A fall judged block by block (`judge`) must also beat `standard_errors` standard errors of its
    scatter from block to block, on more blocks than its best."""
    # Standard deviations of J of pure noise a change of J must exceed to be more than noise
    # (dimensionless): three keep a record with no fault from gaining an effect.
    noise_sds: float = 3.0
    # The least fall of J worth a node or an effect, as a share of the J it falls from
    # (dimensionless).
    least_fall_share: float = 0.01
    # A difference of J below this share of J is the simulation's rounding (dimensionless).
    rounding_share: float = 1e-9
    # Standard errors of its block-to-block scatter a fall must exceed (dimensionless): one, not a
    # Student t quantile, since a real effect's size follows the weather from day to day.
    standard_errors: float = 1.0

    def noise_J(self, sd, n):
        """J (C2) of n residuals of noise of sd `sd` (C) alone, n sd^2; 0 if sd is unknown."""
        return 0.0 if sd is None else n * sd ** 2

    def noise_change(self, sd, n):
        """The change of J (C2) noise of sd `sd` (C) alone can make on n residuals,
        `noise_sds` sd^2 sqrt(2 n); 0 if sd is unknown."""
        return 0.0 if sd is None else self.noise_sds * sd ** 2 * math.sqrt(2 * n)

    def least_fall(self, J, sd, n):
        """The fall of J (C2) from a model of J `J` (C2) on n residuals that noise of sd `sd` (C)
        could make, at least `least_fall_share` of J."""
        return max(self.least_fall_share * J, self.noise_change(sd, n))

    def at_noise(self, J, n, sd):
        """Whether an error J (C2) on n residuals is what an error of sd `sd` (C) alone leaves."""
        return J <= self.noise_J(sd, n) + self.noise_change(sd, n)

    def rounding(self, J):
        """A difference of J (C2) below which two models differ by rounding, for a model of J `J`."""
        return self.rounding_share * J

    def judge(self, before, after, least):
        """The pass rule, the one place it is written: the `Fall` of per-block J `before` to
        `after` (C2), which needs max(`least`, `standard_errors` x its standard error) (C2), and
        what the blocks other than its best gain; `Fall.beats` says whether it passes,
        `Fall.reversed` whether J rises beyond it."""
        before, after = np.asarray(before, dtype=float), np.asarray(after, dtype=float)
        down, se = fall(before, after)
        others = down - float(np.max(before - after)) if before.size else down
        return Fall(down, se, max(least, self.standard_errors * se), others)


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
