"""The heat loss coefficient in the diagnosis' report (PHYSICS.md section 8): as described, as
corrected with the standard deviation the calibration gives it, and whether the record fixes
how the loss splits among effects.

A record of the indoor air and the heating power fixes the building's total loss per kelvin far
better than where the heat goes: an air change and a factor on the envelope's conduction give
the same HLC and nearly the same air temperatures. When candidates that change the loss fit the
validation window alike and agree on the HLC, the report says the split is not the record's.
"""
import math

from nodeforce.model.hlc import heat_loss_coefficient

HLC = "heat_loss_coefficient"
# Two HLCs agree when they differ by less than this many standard deviations of the difference,
# or by less than AGREE_RELATIVE of their mean (a calibration's sd may be tiny on a long record).
AGREE_Z = 2.0
AGREE_RELATIVE = 0.05


def heat_loss(before_building, after_building, added, results, decision):
    """report.json's `heat_loss_coefficient`: {"before", "after", "after_sd"} (W/K) and "split",
    a sentence where the data fix the HLC but not how it splits among effects (else None).

    Parameters
    ----------
    before_building, after_building : Building as described and as corrected
    added : the loop's chosen candidate records, in order (their "derived" holds the HLC of the
        model with the effect and its sd from the calibration's covariance)
    results : every candidate record; a follow-up's have "on_top_of"
    decision : the loop's decision record (its candidates' validation margins, and its follow-up's)
    """
    out = {"before": heat_loss_coefficient(before_building), "after": heat_loss_coefficient(after_building),
           "after_sd": float(added[-1]["derived"][HLC]["std"]) if added else 0.0, "split": None}
    rounds = [(decision, [r for r in results if "on_top_of" not in r])]
    if decision.get("follow_up"):
        rounds.append((decision["follow_up"], [r for r in results if "on_top_of" in r]))
    starts = [{"value": out["before"], "std": 0.0}] + [a["derived"][HLC] for a in added]
    for chosen, start, (judged, tried) in zip(added, starts, rounds):
        alike = same_loss(chosen, tried, judged, start)
        if alike:
            hlc = chosen["derived"][HLC]
            out["split"] = (f"The data fix the heat loss coefficient ({hlc['value']:.1f} ± {hlc['std']:.1f} W/K) "
                            f"but not how it splits among effects: "
                            + ", ".join(f"{r['effect']} on {r['target']} ({r['derived'][HLC]['value']:.1f} W/K)"
                                        for r in alike)
                            + f" fit the validation window as well as {chosen['effect']} on {chosen['target']} "
                              "with the same loss, so the split is the building file's, not the record's.")
    return out


def same_loss(chosen, tried, judged, start):
    """The other candidates of `chosen`'s round that change the loss from the round's `start`
    ({"value", "std"}, W/K) as the chosen does: the same HLC, and a validation J within the
    margin that judged the chosen. None when the chosen changes no loss (a gain, a mass)."""
    from nodeforce.diagnose.loop import label  # the decision's keys; loop imports this module
    hlc = chosen["derived"].get(HLC)
    if not hlc or not moves(hlc, start):
        return []
    margin = judged["candidates"][label(chosen)]["validation_margin"]
    return [r for r in tried if label(r) != label(chosen) and r["derived"].get(HLC)
            and agree(hlc, r["derived"][HLC]) and moves(r["derived"][HLC], start)
            and abs(r["validation"]["J"] - chosen["validation"]["J"]) <= margin]


def moves(a, start):
    """Whether an HLC ({"value", "std"}, W/K) differs from the `start` beyond its uncertainty."""
    return abs(a["value"] - start["value"]) > max(AGREE_Z * math.hypot(a["std"], start["std"]),
                                                  1e-9 * abs(start["value"]))


def agree(a, b):
    """Whether two HLCs ({"value", "std"}, W/K) are the same within their uncertainty."""
    difference = abs(a["value"] - b["value"])
    return (difference <= AGREE_Z * math.hypot(a["std"], b["std"])
            or difference <= AGREE_RELATIVE * (abs(a["value"]) + abs(b["value"])) / 2)
