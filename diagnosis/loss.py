"""The heat loss coefficient in the diagnosis' report (docs/model.md section 8): as described, as
corrected with the standard deviation the calibration gives it, and whether the record fixes
how the loss splits among effects.

A record of the indoor air and the heating power fixes the building's total loss per kelvin far
better than where the heat goes: an air change and a factor on the envelope's conduction give
the same HLC and nearly the same air temperatures. When candidates that change the loss predict
the calibration window's days alike (cross-validated J within what the noise could change) and
agree on the HLC, the report says the split is not the record's.
"""
import math

from nodeforce.model.hlc import heat_loss_coefficient

HLC = "heat_loss_coefficient"
# An HLC moves when it differs from where its round started by more than AGREE_Z standard
# deviations; two HLCs agree when they differ by less than AGREE_RELATIVE of their mean and each
# is known to that fraction.
AGREE_Z = 2.0
AGREE_RELATIVE = 0.05


def heat_loss(before_building, after_building, added, results, sigma, yardstick, last=None):
    """report.json's `heat_loss_coefficient`: {"before", "after", "after_sd"} (W/K) and "split",
    a sentence where the data fix the HLC but not how it splits among effects (else None).

    Parameters
    ----------
    before_building, after_building : Building as described and as corrected
    added : the `Fit`s of the effects the loop added, in order (their `derived` holds the HLC of
        the model with the effect and its sd from the calibration's covariance)
    results : every candidate's `Fit`, each with the `round` it was tried in
    sigma : the air sensors' noise sd (C), which sets the change of J no test can tell apart
    yardstick : the `model.score.Yardstick` that says what change of J the noise could make
    last : the `Fit` whose model is `after_building` (`result.last_change`), default the last added
    """
    last = last or (added[-1] if added else None)
    out = {"before": heat_loss_coefficient(before_building), "after": heat_loss_coefficient(after_building),
           "after_sd": float(last.derived[HLC]["std"]) if last else 0.0, "split": None}
    rounds = [[r for r in results if r.round == number] for number in range(1, len(added) + 1)]
    starts = [{"value": out["before"], "std": 0.0}] + [a.derived[HLC] for a in added]
    for chosen, start, tried in zip(added, starts, rounds):
        alike = same_loss(chosen, tried, start, sigma, yardstick)
        if alike:
            hlc = chosen.derived[HLC]
            out["split"] = (f"The data fix the heat loss coefficient ({hlc['value']:.1f} ± {hlc['std']:.1f} W/K) "
                            f"but not how it splits among effects: "
                            + ", ".join(f"{r.effect} on {r.target} ({r.derived[HLC]['value']:.1f} W/K)"
                                        for r in alike)
                            + f" predict the left-out days as well as {chosen.effect} on {chosen.target} "
                              "with the same loss, so the split is the building file's, not the record's.")
    return out


def same_loss(chosen, tried, start, sigma, yardstick):
    """The other candidates of `chosen`'s round that change the loss from the round's `start`
    ({"value", "std"}, W/K) as the chosen does: the same HLC, each well determined, and a
    cross-validated J the chosen's does not beat by more than the noise could
    (`model.score.Yardstick.least_fall`).
    None of them when the chosen changes no loss (a gain, a mass)."""
    hlc = chosen.derived.get(HLC)
    if not hlc or not moves(hlc, start):
        return []
    J, n = chosen.cv.J, chosen.cv.n
    margin = yardstick.least_fall(J, sigma, n)
    return [r for r in tried if r.label != chosen.label and r.derived.get(HLC)
            and agree(hlc, r.derived[HLC]) and moves(r.derived[HLC], start)
            and r.cv.J - J <= margin]


def moves(a, start):
    """Whether an HLC ({"value", "std"}, W/K) differs from the `start` beyond its uncertainty."""
    return abs(a["value"] - start["value"]) > max(AGREE_Z * math.hypot(a["std"], start["std"]),
                                                  1e-9 * abs(start["value"]))


def agree(a, b):
    """Whether two HLCs ({"value", "std"}, W/K) are the same and each is fixed: within
    AGREE_RELATIVE of their mean, and each with a standard deviation under that fraction."""
    mean = (abs(a["value"]) + abs(b["value"])) / 2
    return (abs(a["value"] - b["value"]) <= AGREE_RELATIVE * mean
            and max(a["std"], b["std"]) <= AGREE_RELATIVE * mean)
