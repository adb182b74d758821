"""How the report writes numbers, times and parameters (shared by its tables, figures and text).

Every number may be missing (None or NaN, e.g. J of a simulation that failed): it is written
"n/a". Temperatures differences are in C (K).
"""
from __future__ import annotations

import math

import pandas as pd

from nodeforce.model.effects import EFFECTS

NA = "n/a"


def num(x):
    """x as a finite float, or None (None, NaN, inf, non-numbers)."""
    if x is None or isinstance(x, bool):
        return None
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def fmt_sig(x, digits=4):
    """x with `digits` significant digits, without an exponent between 1e-4 and 1e6."""
    v = num(x)
    if v is None:
        return NA
    if v == 0:
        return "0"
    a = abs(v)
    if a >= 1e6 or a < 1e-4:
        return f"{v:.{digits - 1}e}"
    decimals = max(0, digits - 1 - math.floor(math.log10(a)))
    return f"{v:.{decimals}f}"


def fmt_temp(x, signed=False):
    """A temperature difference in C: 3 decimals (the sensors resolve 0.1 C at best)."""
    v = num(x)
    if v is None:
        return NA
    return f"{v:+.3f}" if signed else f"{v:.3f}"


def fmt_int(x):
    v = num(x)
    return NA if v is None else str(int(round(v)))


def fmt_search(v):
    return f"{v:g}" if isinstance(v, float) else str(v)


def fmt_value_std(value, std, pm="±"):
    """value ± std, the value to the precision of its std (2 significant digits of the std)."""
    v, s = num(value), num(std)
    if v is None:
        return NA
    if s is None:
        return f"{fmt_sig(v)} {pm} {NA}"
    if s == 0:
        return f"{fmt_sig(v)} {pm} 0"
    decimals = 1 - math.floor(math.log10(s))
    if decimals > 6 or abs(v) >= 1e6 or s >= 1e6:
        return f"{fmt_sig(v)} {pm} {fmt_sig(s, 2)}"
    if decimals < 0:  # a std of 10 or more: units, the std to 2 significant digits
        return f"{v:.0f} {pm} {round(s, decimals):.0f}"
    return f"{v:.{decimals}f} {pm} {s:.{decimals}f}"


def parameter_unit(effect_id, name):
    """The unit of parameter `name` of effect `effect_id`, from the effect registry ('' if none)."""
    effect = EFFECTS.get(effect_id)
    unit = next((p.unit for p in effect.parameters if p.name == name), "") if effect else ""
    return "" if unit == "-" else unit


def fmt_parameters(effect_id, parameters, pm="±"):
    """'U = 0.52 ± 0.03 W/m2/K, T_ground = 24 ± 9 C (not identifiable)', or 'T_ground = 22.1 ± 1.4 C
    (prior <the prior, stated>)' for a parameter weighed with its physical prior, its sd the
    posterior's; '' for no parameter."""
    parts = []
    for name, p in (parameters or {}).items():
        unit = parameter_unit(effect_id, name)
        text = f"{name} = {fmt_value_std(p.get('value'), p.get('std'), pm)}" + (f" {unit}" if unit else "")
        if p.get("prior"):
            text += f" (prior {p['prior']})"
        elif p.get("identifiable") is False:
            text += " (not identifiable)"
        parts.append(text)
    return ", ".join(parts)


def fmt_derived(derived, pm="±"):
    """['ground heat flux = -1.774 ± 0.047 W/m2', ...]: what the data determine."""
    return [f"{name.replace('_', ' ')} = {fmt_value_std(d.get('value'), d.get('std'), pm)} {d.get('unit', '')}".rstrip()
            for name, d in (derived or {}).items()]


def utc_offset(t):
    z = t.strftime("%z")  # +hhmm
    return f"UTC{z[:3]}:{z[3:]}" if z else "UTC"


def time_text(iso):
    """'2001-06-10 00:00 UTC-05:00' from an ISO 8601 string (kept as is when unreadable)."""
    try:
        t = pd.Timestamp(iso)
    except (TypeError, ValueError):
        return str(iso) if iso is not None else NA
    return t.strftime("%Y-%m-%d %H:%M") + (f" {utc_offset(t)}" if t.tzinfo is not None else "")
