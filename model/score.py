"""The score of a simulation against the measured indoor air (PHYSICS.md section 6)."""
from dataclasses import dataclass

import numpy as np

from .errors import InputError


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


@dataclass(frozen=True)
class Objective:
    """The zones whose measured air J sums (PHYSICS.md section 6), and their air nodes."""
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
