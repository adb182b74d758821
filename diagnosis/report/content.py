"""What the report reads from report.json, in one place: metrics by state, window and zone,
the effect, the loop's decision (read, never re-derived), node names and the reference."""
from __future__ import annotations

from .formats import NA, time_text

WINDOWS = ("calibration", "validation")
# the windows whose METRICS report.json holds: the fits' and the choice's ("calibration"), the test's
SCORED = ("calibration", "validation")
STATES = ("before", "after")


def metrics(report, state, window, zone=None):
    """METRICS of `state` ('before', 'after' or a candidate dict) on `window`: of the objective,
    or of one zone; {} where absent."""
    source = report.get(state) if isinstance(state, str) else state
    m = (source or {}).get(window)
    m = m if isinstance(m, dict) else {}
    if zone is not None:
        m = (m.get("zones") or {}).get(zone)
    return m if isinstance(m, dict) else {}


def zones(report, series=None):
    """The objective's zones: report['objective'], else the zones of the series."""
    names = report.get("objective") or list(((series or {}).get("zones") or {}))
    return [str(z) for z in names]


def is_none_effect(effect):
    return not effect or effect.get("effect") in (None, "none")


def effect_name(effect, target):
    return f"{effect} on {target}" if target not in (None, "") else str(effect)


def effect_label(report):
    e = report.get("effect") or {}
    return "no effect" if is_none_effect(e) else effect_name(e.get("effect"), e.get("target"))


def candidate_key(candidate):
    """'effect@target', the key of the loop's decision and sensitivity."""
    return f"{candidate.get('effect')}@{candidate.get('target')}"


def decision(report):
    return report.get("decision") or {}


def round_decision(report, candidate):
    """The decision of the round a candidate was tried in (one tried on top of n effects: round
    n + 1), {} if not recorded."""
    d = decision(report)
    rounds = d.get("rounds") or [d]
    number = len(candidate.get("on_top_of") or [])
    return rounds[number] if number < len(rounds) else {}


def verdict(report, candidate):
    """The loop's {'cv_fall', 'cv_se', 'needed', 'passes', 'objection'} for a candidate ({} if not
    recorded), in the round it was tried in."""
    return (round_decision(report, candidate).get("candidates") or {}).get(candidate_key(candidate)) or {}


def is_chosen(report, candidate):
    """Whether the loop added this candidate, in the round it was tried in: the effect added in
    round n + 1 is the (n + 1)-th of `effects`."""
    number = len(candidate.get("on_top_of") or [])
    effect = report.get("effect")
    effects = report.get("effects") or ([] if is_none_effect(effect) else [effect])
    return number < len(effects) and candidate_key(effects[number]) == candidate_key(candidate)


def node_name(report, node):
    """'W9 at 0.34 m' for a node id, '' when the report names none."""
    return str((report.get("node_names") or {}).get(str(node), ""))


def reference(report):
    """(label, {phase or window: RMSE in K}) of the reference model, or None."""
    ref = report.get("reference")
    if not ref or not ref.get("rmse"):
        return None
    return str(ref.get("label") or "reference"), dict(ref["rmse"])


def scored_period_text(report, window):
    """The span the METRICS of `window` cover."""
    return period_text(report, window)


def period_text(report, window):
    span = (report.get("period") or {}).get(window)
    if not span or len(span) != 2:
        return NA
    return f"{time_text(span[0])} to {time_text(span[1])}"


def scored_from_note(report):
    """Where the calibration's scoring starts, after the burn-in ("" when the report does not say):
    the terminal and report.md say the same."""
    scored = (report.get("period") or {}).get("calibration_scored_from")
    return f" (residuals scored from {time_text(scored)}, after the burn-in)" if scored else ""


def window_text(report, window):
    """The span a window's metrics cover (`scored_period_text`) and, for the calibration, where its
    scoring starts."""
    return scored_period_text(report, window) + (scored_from_note(report) if window == "calibration" else "")
